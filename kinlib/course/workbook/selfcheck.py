"""Self-checks for student workbooks: is an answer right, without revealing it.

At build time (``kinlib handouts``) each reference answer is turned into a *fingerprint*:
the answer evaluated at fixed sample values of its symbols (the same values for a symbol of the same
name, whatever its assumptions), rounded to 8 significant digits and hashed (SHA-256). The sample values
cover the domains the grader's secret points are drawn from (:func:`kinlib.course.answers.kinds.draw_points`:
joint angles over a whole turn, one sample in each fifth, lengths in (0.5, 2), the reference's signed symbols
across 0), so the two judges agree: |det J| for det J, a signed manipulability, fail at home as in the grade
(tests/answer_table.py is the table both must agree on). The workbook holds only the fingerprint; the student's
answer is fingerprinted the same way when the self-check cell runs, so a right answer in any equivalent form
(simplified or not, exact, or decimals within the grader's tolerance: with a note) passes::

    from kinlib.course.workbook.selfcheck import check
    check("2.2", Js="matrix|6x3|3f0c1b9e5a7d2c44")

Kinds of answer (``kinds`` in the solution cell's ``kinlib`` metadata; the forms each accepts are
those of the kind modules of :mod:`kinlib.course.answers`, the normalisers the grader uses too):

- default / ``"expr"``: a SymPy Matrix, expression or number, compared as a function of its symbols;
- ``"choice"``: an int, string or tuple of them (joint numbers 1-based; order and repeats ignored);
- ``"set"``: a SymPy Set (or Python set/list of values, a number, a dict {symbol: Set} or a list of
  those dicts), compared through its points in [-2π, 2π] taken modulo 2π (angles), intervals by their
  end points;
- ``"subspace"``: a Matrix whose columns span a subspace, compared through its orthogonal projector;
- ``"property:<p>"``: the student's own design (5.5) judged as the grader does (:mod:`..answers.properties`).

A wrong answer is tried against the known mistakes of :mod:`kinlib.course.answers.mistakes` (transposed, wrong
sign, [v; ω] order, columns swapped, degrees, wrong shape, ...; the instructor checker uses the same):
each undone version of the student's answer is fingerprinted too, and a match names the mistake ("it is
transposed"), never the answer.

In a workbook, ``%load_ext kinlib.course.workbook.selfcheck`` adds the cell magic ``%%needs NAME...``
(:mod:`kinlib.course.workbook.needs`): the cell runs only once the names it uses from the student's answers are
filled in, and if it fails while their self-check has not passed, says "fix the answer above first".
"""

from __future__ import annotations

import contextvars
import hashlib
import itertools
import json
import math
import sys

import numpy as np
import sympy as sp

from ..answers import mistakes
from ..answers.base import is_bool, is_unanswered, symbol_notes
from ..answers.choice import choice_key, choice_value
from ..answers.expr import to_sympy
from ..answers.kinds import FORMS, is_angle_name, symbol_domain
from ..answers.properties import property_spec, property_verdict
from ..answers.sets import set_conditions, to_set, var_name
from ..schema import KINDS
from .needs import answer_status, last_results, needs

__all__ = [
    "check",
    "verdict",
    "fingerprint",
    "describe_answer",
    "emit_fingerprints",
    "Unanswered",
    "CannotCheck",
    "WrongForm",
    "KINDS",
    "FINGERPRINT_MARK",
    "last_results",
    "sample_value",
    "load_ipython_extension",
]

FINGERPRINT_MARK = "KINLIB-SELFCHECK "  # starts the line emit_fingerprints prints (read by the handouts)
SAMPLE_POINTS = 5  # configurations at which an answer's symbols are sampled (one per fifth of each domain)
_DIGITS = 8  # significant digits kept of every sampled value
_ZERO = 1e-10  # |x| below this counts as 0
_PROJ_DECIMALS = 6  # decimals kept of a subspace's projector


class Unanswered(Exception):
    """The answer variable is missing or still ``...``.

    :func:`fingerprint` raises it; :func:`check` says "not answered yet" instead:

    >>> fingerprint(...)
    Traceback (most recent call last):
        ...
    kinlib.course.workbook.selfcheck.Unanswered: the value is missing or ...
    >>> check("1.1", _namespace={}, J=fingerprint(sp.eye(2), salt="1.1:J"))
    part 1.1 · J: … not answered yet: replace the ... in `J = ...` above with your answer (a 2×2 matrix)
    """


class CannotCheck(Exception):
    """The answer is of a form the self-check cannot fingerprint (message says why).

    :func:`fingerprint` raises it, e.g. for an undefined function that does not evaluate to a number;
    :func:`verdict` (and so :func:`check`, with "?") reports it as an error:

    >>> f = sp.Function("f")(sp.Symbol("t"))
    >>> fingerprint(f)
    Traceback (most recent call last):
        ...
    kinlib.course.workbook.selfcheck.CannotCheck: it does not evaluate to a number (Cannot convert expression to float)
    >>> verdict(f, fingerprint(sp.Symbol("t")))
    ('error', 'cannot check it automatically: it does not evaluate to a number (Cannot convert expression to float)')
    """


class WrongForm(Exception):
    """The answer has the wrong type or shape (message says what was expected).

    :func:`fingerprint` raises it; :func:`check` reports it as a wrong form:

    >>> fingerprint([[1, 2], [3]])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
        ...
    kinlib.course.workbook.selfcheck.WrongForm: it should be a SymPy Matrix, expression or number, yours is a list of ...
    >>> check("1.1", _namespace={"J": sp.eye(3)}, J=fingerprint(sp.eye(2), salt="1.1:J"))
    part 1.1 · J: ✗ wrong form: it should be a 2×2 matrix, yours is a 3×3 matrix (J Jᵀ is task × task, Jᵀ J joints × joints: the product in the other order?)
    """


# ---------------------------------------------------------------------------------------------------
# Sample values: fixed exact rationals per (symbol name, sample index), over the domains the grader's secret
# points are drawn from (kinlib.course.answers.kinds.symbol_domain): joint angles over a whole turn, one sample
# in each fifth of (-π, π) (so |sin θ| and sin θ, a signed manipulability, differ at some sample), lengths in
# (0.5, 2), the reference's other signed symbols (forces, velocities; named in the spec) across 0.

_SIGNED: contextvars.ContextVar = contextvars.ContextVar("kinlib_selfcheck_signed", default=frozenset())


def sample_value(name: str, k: int, signed: bool = False) -> sp.Rational:
    """The value given to every symbol called ``name`` at sample configuration ``k`` (of :data:`SAMPLE_POINTS`):
    in the grader's domain for that symbol (:func:`kinlib.course.answers.kinds.symbol_domain`), one sample in each
    fifth of it (the fifths in an order fixed per name).

    >>> v = [sample_value("theta1", k) for k in range(SAMPLE_POINTS)]
    >>> v[0] == sample_value("theta1", 0), all(-sp.pi < x < sp.pi for x in v), sorted(int((x + sp.pi) // (2 * sp.pi / 5)) for x in v)
    (True, True, [0, 1, 2, 3, 4])
    >>> all(sp.Rational(1, 2) < sample_value("L", k) < 2 for k in range(5)), min(sample_value("F_x", k, True) for k in range(5)) < 0
    (True, True)
    """
    h = hashlib.sha256(f"kinlib-selfcheck-v2:{name}:{k}".encode()).digest()
    u = 0.1 + 0.8 * (int.from_bytes(h[:4], "big") / 2**32)  # where in its fifth: away from the fifth's ends
    order = sorted(
        range(SAMPLE_POINTS), key=lambda j: hashlib.sha256(f"kinlib-selfcheck-bin:{name}:{j}".encode()).digest()
    )
    _, (lo, hi) = symbol_domain(name, positive=not signed and not is_angle_name(name))
    x = lo + (order[k % SAMPLE_POINTS] + u) * (hi - lo) / SAMPLE_POINTS
    return sp.Rational(round(x * 1_000_000), 1_000_000)


def _point(expr, k: int) -> dict:
    syms = getattr(expr, "free_symbols", set())
    signed = _SIGNED.get()
    return {s: sample_value(s.name, k, s.name in signed) for s in syms if isinstance(s, sp.Symbol)}


def _fmt(z) -> str:
    """A number as a stable string of 8 significant digits ('0' for |x| < 1e-10)."""
    try:
        z = complex(z)
    except (TypeError, ValueError) as e:
        raise CannotCheck(f"it does not evaluate to a number ({e})") from None
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return "nan"
    re = 0.0 if abs(z.real) < _ZERO else z.real
    im = 0.0 if abs(z.imag) < _ZERO else z.imag
    s = "0" if re == 0.0 else f"{re:.{_DIGITS - 1}e}"
    if im != 0.0:
        s += f"{im:+.{_DIGITS - 1}e}j"
    return s


def _evaluate(x, k: int):
    """``x`` (SymPy object) with its symbols at sample point ``k``, evaluated to 30 digits.

    Evaluated with mpmath at 30 digits through ``lambdify`` (with common subexpressions shared):
    ~40× faster than ``evalf`` on an unsimplified Jacobian; ``evalf`` is the fallback.
    """
    pt = _point(x, k)
    if pt and isinstance(x, (sp.Expr, sp.MatrixBase)):
        try:
            return _evaluate_mpmath(x, pt)
        except Exception:  # anything lambdify cannot print: the slow, general route
            pass
    y = x.subs(pt) if pt else x
    return y.evalf(30) if hasattr(y, "evalf") else y


def _evaluate_mpmath(x, pt: dict):
    from kinlib.exact.field import mp_context

    mpmath = mp_context()  # this thread's own mpmath context: the global precision is never changed
    syms = sorted(pt, key=lambda s: s.name)
    entries = list(x) if isinstance(x, sp.MatrixBase) else [x]
    names = {n: getattr(mpmath, n) for n in dir(mpmath) if not n.startswith("_")}
    f = sp.lambdify(syms, entries, modules=[{**names, "mpmath": mpmath}, "mpmath"], cse=True)
    with mpmath.workdps(30):
        vals = f(*[mpmath.mpf(pt[s].p) / pt[s].q for s in syms])
        out = [
            sp.Float(v, 30)
            if isinstance(v, mpmath.mpf)
            else sp.Float(mpmath.re(v), 30) + sp.I * sp.Float(mpmath.im(v), 30)
            if isinstance(v, mpmath.mpc)
            else sp.sympify(v).evalf(30)
            for v in vals
        ]
    return sp.Matrix(x.rows, x.cols, out) if isinstance(x, sp.MatrixBase) else out[0]


# ---------------------------------------------------------------------------------------------------
# Canonical forms, one per kind.

_FORM_WORDS = {
    "array": "an array with more than 2 dimensions",
    "empty": "an empty list",
    "ragged": "a list of vectors of different lengths",
}


def _as_sympy_value(value, vectors: bool = False):
    """The answer as a SymPy Matrix or expression (:func:`kinlib.course.answers.expr.to_sympy`), or WrongForm."""
    tag, v = to_sympy(value, vectors=vectors)
    if v is not None:
        return v
    what = _FORM_WORDS.get(tag, f"a {type(value).__name__}")
    raise WrongForm(f"it should be a SymPy Matrix, expression or number, yours is {what}")


def _shape_of(v) -> str:
    return f"{v.shape[0]}x{v.shape[1]}" if isinstance(v, sp.MatrixBase) else ""


def _default_value(value, shape: str | None = None):
    """The answer as a SymPy Matrix or expression with the expected ``shape`` ("rxc", "" for a scalar,
    "dict"; None: any), or, for a yes/no or dict answer, its finished canonical form (a tuple)."""
    if is_bool(value):  # a yes/no answer
        return "bool", "", [str(bool(value))]
    if isinstance(value, dict) or shape == "dict":  # e.g. {configuration name: row of J}
        if not isinstance(value, dict):
            raise WrongForm(f"it should be a dict, yours is a {type(value).__name__}")
        items = sorted(value.items(), key=lambda kv: str(kv[0]))
        return "matrix", "dict", [[str(k), list(_canon_default(v)[1:])] for k, v in items]
    v = _as_sympy_value(value)
    if isinstance(v, sp.MatrixBase):
        mine = _shape_of(v)
        if shape == "" and v.shape == (1, 1):  # a 1x1 Matrix for a scalar answer
            v, mine = v[0, 0], ""
        elif shape not in (None, mine):
            raise WrongForm(f"it should be {_shape_words(shape)}, yours is {_shape_words(mine)}")
    elif shape:
        raise WrongForm(f"it should be {_shape_words(shape)}, yours is {_shape_words('')}")
    if not isinstance(v, (sp.MatrixBase, sp.Expr)):
        raise WrongForm(f"it should be a SymPy Matrix, expression or number, yours is {type(v).__name__}")
    return v


_SAMPLED: dict = {}  # (value, signed symbols) -> its samples: a self-check cell run again, the mistakes tried
_SAMPLED_MAX = 64


def _sampled(v):
    """``v`` (Matrix or expression) at the sample points: an object array (points, rows, columns); remembered for
    the last :data:`_SAMPLED_MAX` values (each is evaluated once however many candidates and checks use it)."""
    try:
        key = (sp.ImmutableMatrix(v) if isinstance(v, sp.MatrixBase) else v, _SIGNED.get())
        hash(key)
    except Exception:  # noqa: BLE001  (an object SymPy cannot hash: not remembered)
        return _sampled_now(v)
    if key not in _SAMPLED:
        if len(_SAMPLED) >= _SAMPLED_MAX:
            _SAMPLED.pop(next(iter(_SAMPLED)))
        _SAMPLED[key] = _sampled_now(v)
    return _SAMPLED[key].copy()


def _sampled_now(v):
    if isinstance(v, sp.MatrixBase):
        return np.array([_evaluate(v, k).tolist() for k in range(SAMPLE_POINTS)], dtype=object).reshape(
            SAMPLE_POINTS, *v.shape
        )
    return np.array([_evaluate(v, k) for k in range(SAMPLE_POINTS)], dtype=object).reshape(SAMPLE_POINTS, 1, 1)


def _canon_sampled(arr, scalar: bool) -> tuple:
    """(form, shape, canonical values) of sampled values ``arr`` (a scalar: 1×1 entries)."""
    if scalar:
        return "scalar", "", [_fmt(arr[k, 0, 0]) for k in range(arr.shape[0])]
    return "matrix", f"{arr.shape[1]}x{arr.shape[2]}", [[_fmt(e) for e in arr[k].ravel()] for k in range(arr.shape[0])]


def _canon_default(value, shape: str | None = None):
    v = _default_value(value, shape)
    if isinstance(v, tuple):
        return v
    return _canon_sampled(_sampled(v), not isinstance(v, sp.MatrixBase))


def _choice_canon(x):
    """A choice value as :func:`kinlib.course.answers.choice.choice_key` gives it (the grader's definition too)."""
    try:
        return choice_key(x)
    except TypeError as e:
        raise WrongForm(str(e)) from None


def _canon_choice(value):
    return "choice", "", _choice_canon(choice_value(value))


def _angle_point(p, k):
    """A point of a set, modulo 2π, as a stable string (tuples component-wise)."""
    if isinstance(p, (sp.Tuple, tuple)):
        return "(" + ",".join(_angle_point(q, k) for q in p) + ")"
    p = sp.sympify(p)
    pt = _point(p, k)
    if pt:
        p = p.subs(pt)
    if p.is_number and p.is_real is not False:
        p = sp.Mod(p, 2 * sp.pi)
        s = _fmt(p.evalf(30))
        return "0" if s == _fmt(2 * math.pi) else s
    return _fmt(p.evalf(30))


def _canon_one_set(s, k, fmap=None):
    try:
        s = to_set(s)
    except TypeError as e:
        raise WrongForm(str(e).replace("a set should be", "it should be")) from None
    if fmap is not None:  # a mistake undone (mistakes.SET_MISTAKES)
        s = fmap(s)
    pt = _point(s, k)
    if pt:
        s = s.subs(pt)
    if not isinstance(s, sp.FiniteSet):
        window = sp.Interval(-2 * sp.pi, 2 * sp.pi)
        s = sp.Intersection(s, window)
        if isinstance(s, sp.Intersection) or isinstance(s, sp.ConditionSet):
            raise CannotCheck("SymPy cannot list this set's points in [-2π, 2π]")
    parts = s.args if isinstance(s, sp.Union) else (s,)
    out = set()
    for part in parts:
        if isinstance(part, sp.FiniteSet):
            out.update(_angle_point(p, k) for p in part)
        elif isinstance(part, sp.Interval):
            out.add(
                f"I{'(' if part.left_open else '['}{_fmt(part.start.evalf(30))},"
                f"{_fmt(part.end.evalf(30))}{')' if part.right_open else ']'}"
            )
        elif part is sp.S.EmptySet:
            pass
        else:
            raise CannotCheck(f"SymPy cannot list the points of {type(part).__name__} in [-2π, 2π]")
    return sorted(out)


def _canon_condition(cond: list, fmap=None, keys: dict | None = None) -> list:
    """A condition {variable: Set} canonical per sample point; keys by their untypeset name (θ_2 is theta2, as
    the grader reads them, :func:`kinlib.course.answers.sets.var_name`), ``keys`` renaming some."""
    keys = keys or {}
    return [
        [keys.get(var_name(key), var_name(key))] + [_canon_one_set(s, k, fmap) for k in range(SAMPLE_POINTS)]
        for key, s in sorted(cond, key=lambda kv: keys.get(var_name(kv[0]), var_name(kv[0])))
    ]


_EMPTY = [[] for _ in range(SAMPLE_POINTS)]


def _canon_set(value, fmap=None, keys=None):
    """A dict {symbol: Set} is shape "dict", a list of several such dicts (a union) "union", the rest ""; a set
    with no member (an empty Set, ``[]``, a condition that no value meets) is the empty bare set, whatever its
    form: an empty answer is judged by being empty, never told "it should be a dict"."""
    conds = set_conditions(value)
    if conds is None:
        raise WrongForm(f"it should be a SymPy Set (or a dict {{symbol: Set}}), yours is a {type(value).__name__}")
    if len(conds) == 1 and conds[0] and conds[0][0][0] is None:
        return "set", "", [_canon_one_set(conds[0][0][1], k, fmap) for k in range(SAMPLE_POINTS)]
    canon = [_canon_condition(c, fmap, keys) for c in conds]
    live = [c for c in canon if not any(all(not pts for pts in entry[1:]) for entry in c)]
    if not live:
        return "set", "", _EMPTY
    if len(conds) == 1:
        return "set", "dict", canon[0]
    return "set", "union", sorted(canon, key=json.dumps)


# the joint variables a one-variable condition may be re-keyed to (a bare set for a dict, the right set on the
# wrong variable): the names the course uses
_JOINT_NAMES = [f"{p}{i}" for p in ("theta", "q") for i in range(1, 8)]


def _subspace_value(value, shape=None):
    v = _as_sympy_value(value, vectors=True)  # a list of spanning vectors: side by side
    if not isinstance(v, sp.MatrixBase):
        raise WrongForm("it should be a Matrix whose columns span the subspace")
    m = str(v.shape[0])
    if shape not in (None, m):
        raise WrongForm(f"its columns should be {shape}-vectors, yours are {m}-vectors")
    return v


def _subspace_sampled(v) -> np.ndarray:
    """The spanning vectors at the sample points, as floats (points, m, vectors)."""
    out = []
    for k in range(SAMPLE_POINTS):
        try:
            A = np.array(_evaluate(v, k).tolist(), dtype=complex).reshape(v.shape)
        except TypeError as e:
            raise CannotCheck(f"it does not evaluate to numbers ({e})") from None
        if np.abs(A.imag).max(initial=0.0) > _ZERO:
            raise CannotCheck("it has complex entries")
        out.append(A.real)
    return np.array(out).reshape(SAMPLE_POINTS, *v.shape)


def _canon_spans(As) -> tuple:
    """(form, ambient dimension, canonical projectors) of the spans of the arrays ``As`` (one per point)."""
    pts = []
    for A in As:
        if A.size == 0 or np.abs(A).max() < _ZERO:
            P = np.zeros((A.shape[0], A.shape[0]))
        else:
            U, s, _ = np.linalg.svd(A)
            r = int((s > 1e-9 * max(1.0, s[0])).sum())
            Q = U[:, :r]
            P = Q @ Q.T
        P = np.round(P, _PROJ_DECIMALS) + 0.0
        pts.append([f"{x:.{_PROJ_DECIMALS}f}" for x in P.ravel()])
    return "subspace", str(As[0].shape[0]), pts


def _canon_subspace(value, shape=None):
    return _canon_spans(_subspace_sampled(_subspace_value(value, shape)))


_CANON = {
    "default": _canon_default,
    "expr": _canon_default,
    "choice": _canon_choice,
    "set": _canon_set,
    "subspace": _canon_subspace,
}


def _shape_words(shape: str) -> str:
    if shape == "dict":
        return "a dict"
    if not shape:
        return "a single expression or number (not a matrix)"
    r, c = shape.split("x")
    return f"a {r}×{c} matrix"


def _hash(kind, canon, salt: str = "") -> str:
    text = json.dumps([kind, canon], separators=(",", ":"))
    return hashlib.sha256(f"kinlib-selfcheck-v2:{salt}:{text}".encode()).hexdigest()[:16]


def _symbols_of(value) -> set:
    """The SymPy symbols in an answer (SymPy objects, and dicts, lists, tuples, sets and arrays of them)."""
    out, stack = set(), [value]
    while stack:
        o = stack.pop()
        if isinstance(o, dict):
            stack += list(o.keys()) + list(o.values())
        elif isinstance(o, (list, tuple, set, frozenset)):
            stack += list(o)
        elif isinstance(o, np.ndarray) and o.dtype == object:
            stack += o.ravel().tolist()
        elif isinstance(o, (sp.Basic, sp.MatrixBase)):
            out |= {x for x in o.free_symbols if isinstance(x, sp.Symbol)}
    return out


def _sym_hash(names, salt: str) -> str:
    return _hash("symbols", sorted(set(names)), salt)[:8]


def fingerprint(value, kind: str = "default", salt: str = "") -> str:
    """The spec string of ``value``: ``"<form>|<shape>|<hash>"``, and for an answer with symbols
    ``"|<symbols' hash>|<signed symbols>"`` (no information about the value itself).

    ``form`` is matrix/scalar/bool/choice/set/subspace; ``shape`` is ``"6x3"`` for a matrix, the ambient
    dimension for a subspace, ``"dict"`` for a dict of sets (``"union"`` for a list of them). ``salt``
    (the workbooks use ``"part:name"``) makes equal answers to different questions hash differently. The
    symbols' hash lets the self-check say, as the grader does, that an answer misses a variable ("did you
    substitute L = 1?") or is a constant; the signed symbols (not lengths, not joint angles: forces, velocities)
    are sampled on both sides of 0, as the grader's points are (:func:`sample_value`).

    >>> fingerprint(sp.Matrix([[1, 2, 3]]), salt="1.1:v")[:11]
    'matrix|1x3|'
    >>> fingerprint((2, 1), "choice") == fingerprint([1, 2, 2], "choice")
    True
    >>> fingerprint(sp.Symbol("F_x", real=True) * sp.Symbol("L", positive=True), salt="7.4:tau").split("|")[4]
    'F_x'
    """
    if is_unanswered(value):
        raise Unanswered("the value is missing or ...")
    if str(kind).startswith("property:"):
        return property_spec(value, kind.partition(":")[2])
    if kind not in _CANON:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    syms = _symbols_of(value) if kind in ("default", "expr", "subspace") else set()
    signed = sorted(x.name for x in syms if not x.is_positive and not is_angle_name(x.name))
    token = _SIGNED.set(frozenset(signed))
    try:
        form, shape, canon = _CANON[kind](value)
    finally:
        _SIGNED.reset(token)
    spec = f"{form}|{shape}|{_hash(form, canon, salt)}"
    if syms:
        spec += f"|{_sym_hash([x.name for x in syms], salt)}|{','.join(signed)}"
    return spec


def describe_answer(value, kind: str = "default") -> str:
    """A short description of the form of an answer (for the workbook's stub), e.g. 'a 6×3 Matrix'.

    >>> describe_answer(sp.zeros(6, 3)), describe_answer(3, "choice"), describe_answer({sp.Symbol("t"): {0}}, "set")
    ('a 6×3 Matrix', 'a joint number or a tuple of joint numbers (1-based)', 'a dict {symbol: SymPy Set}')
    >>> describe_answer(False, "choice"), describe_answer([{sp.Symbol("t"): {0}}], "set")
    ('True or False', 'a list of dicts {symbol: SymPy Set}, one per condition ([] for none)')
    """
    if str(kind).startswith("property:"):
        return "your robot itself (a kinlib SerialChain: its screw axes and M)"
    if is_bool(value):  # before "choice": a True/False answer is no joint number
        return "True or False"
    if kind == "choice":
        return "a joint number or a tuple of joint numbers (1-based)" if not isinstance(value, str) else "a string"
    if kind == "set":
        if isinstance(value, dict):
            return "a dict {symbol: SymPy Set}"
        if isinstance(value, (list, tuple)) and all(isinstance(v, dict) for v in value):
            return "a list of dicts {symbol: SymPy Set}, one per condition ([] for none)"
        return "a SymPy Set"
    if kind == "subspace":
        try:
            return f"a Matrix whose columns span the subspace ({_as_sympy_value(value, True).shape[0]}-vectors)"
        except Exception:  # noqa: BLE001
            return "a Matrix whose columns span the subspace"
    try:
        v = None if isinstance(value, dict) else _as_sympy_value(value)
    except WrongForm:
        return "a value"
    if isinstance(value, dict):
        return "a dict {" + ", ".join(map(str, value)) + ": ...}"
    if isinstance(v, sp.MatrixBase):
        return f"a {v.shape[0]}×{v.shape[1]} Matrix"
    return "a SymPy expression or a number"  # the same words for both: whether it is constant is a hint


# ---------------------------------------------------------------------------------------------------
# The student's side.


def _parse_spec(spec: str):
    """(form, shape, digest, symbols' hash or None, signed symbols) of a spec (3 fields: an answer without
    symbols, or a spec made before the symbols were recorded)."""
    fields = spec.split("|") if isinstance(spec, str) else []
    if len(fields) == 3:
        return (*fields, None, frozenset())
    if len(fields) == 5:
        form, shape, digest, symhash, signed = fields
        return form, shape, digest, symhash, frozenset(x for x in signed.split(",") if x)
    raise ValueError(f"a self-check spec looks like 'matrix|6x3|<16 hex digits>', got {spec!r}")


_FORM_KIND = {form: ("default" if k == "expr" else k) for form, k in FORMS.items()}


def verdict(value, spec: str, salt: str = "") -> tuple[str, str]:
    """``(status, message)`` for an answer against a spec; status is correct/incorrect/unanswered/error.

    A wrong answer is tried against the known mistakes (:mod:`kinlib.course.answers.mistakes`: the same as the
    instructor checker's): the message names the mistake, never the answer.

    >>> spec = fingerprint(sp.Rational(1, 2), salt="1.1:x")
    >>> verdict(sp.Rational(1, 2), spec, salt="1.1:x"), verdict(..., spec, salt="1.1:x")[0]
    (('correct', 'correct'), 'unanswered')
    >>> verdict(-sp.Rational(1, 2), spec, salt="1.1:x")
    ('incorrect', 'not right yet: it has the wrong sign')
    >>> verdict(0.5, spec, salt="1.1:x")[1]
    'correct; note: it contains decimals (floats): exact values (sp.Rational, sp.sqrt, sp.pi) are safer'
    """
    form, shape, digest, symhash, signed = _parse_spec(spec)
    if is_unanswered(value):
        return "unanswered", "not answered yet"
    if form == "none":
        return "error", "this answer has no automatic self-check: compare it with the worked solution"
    if form == "property":  # judged by the property asked, on the student's own design (answers.properties)
        return property_verdict(shape, value)
    kind = _FORM_KIND.get(form)
    if kind is None:
        raise ValueError(f"unknown answer form {form!r} in spec {spec!r}")
    token = _SIGNED.set(signed)
    try:
        return _verdict(kind, value, form, shape, digest, salt, symhash)
    except WrongForm as e:
        return "incorrect", f"wrong form: {e}"
    except CannotCheck as e:
        return "error", f"cannot check it automatically: {e}"
    except Exception as e:  # anything the student's object throws while being evaluated
        return "error", f"could not evaluate your answer ({type(e).__name__}: {e})"
    finally:
        _SIGNED.reset(token)


_HOW = {
    "default": "its values differ from the answer's at sample values of its symbols",
    "subspace": "it spans a different subspace",
    "set": "it holds different points",
    "choice": "that is not the right choice",
}


def _verdict(kind, value, form, shape, digest, salt, symhash=None):
    def right(canon, mine_form=form):
        return _hash(mine_form, canon, salt) == digest

    def named(says):
        return "incorrect", f"not right yet: it {says}"

    if kind == "default":
        return _verdict_expr(value, form, shape, right, salt, symhash)
    if kind == "subspace":
        try:
            v = _subspace_value(value, shape)
        except WrongForm:
            v = _subspace_value(value)
            found = _subspace_mistake(_subspace_sampled(v), shape, right)
            if found is None:
                raise
            return named(found)
        arr = _subspace_sampled(v)
        if right(_canon_spans(arr)[2]):
            return "correct", "correct"
        found = _subspace_mistake(arr, shape, right)
        return named(found) if found else ("incorrect", f"not right yet: {_HOW[kind]}")
    if kind == "set":
        return _verdict_set(value, shape, right, named)
    _, _, canon = _canon_choice(value)
    if right(canon):
        return "correct", "correct"
    cv = choice_value(value)
    if isinstance(cv, int) and not isinstance(cv, bool) and cv in (0, 1) and right(_choice_canon(bool(cv))):
        return "correct", "correct"  # 0 / 1 for a yes/no answer: False / True (as the grader reads it)
    for m in mistakes.CHOICE_MISTAKES:
        try:
            if right(_choice_canon(next(m.candidates(cv))[1])):
                return "incorrect", f"not right yet: that {m.message()}"
        except WrongForm:
            continue
    return "incorrect", f"not right yet: {_HOW[kind]}"


def _verdict_set(value, shape, right, named):
    _, mine_shape, canon = _canon_set(value)
    if right(canon):
        return "correct", "correct"
    conds = set_conditions(value)
    one_var = conds is not None and len(conds) == 1 and len(conds[0]) == 1
    if mine_shape == "dict" and shape == "" and one_var:  # {θ2: S} for a bare S: the grader reads it as S
        if right([_canon_one_set(conds[0][0][1], k) for k in range(SAMPLE_POINTS)]):
            return "correct", "correct"
    if mine_shape == "" and shape == "dict" and canon is not _EMPTY:  # a bare S for {θk: S}: the grader too
        bare = [[(sp.Symbol(v), conds[0][0][1])] for v in _JOINT_NAMES]
        if any(right(_canon_condition(c)) for c in bare):
            return "correct", "correct"
    if mine_shape == "dict" and one_var:  # the right set on the wrong variable (mistakes.SET_VARIABLE)
        mine = var_name(conds[0][0][0])
        for v in _JOINT_NAMES:
            if v != mine and right(_canon_condition(conds[0], keys={mine: v})):
                return named(mistakes.SET_VARIABLE.says)
    if canon is not _EMPTY and mine_shape != shape and (mine_shape, shape) not in (("dict", ""), ("", "dict")):
        want = {"dict": "a dict {symbol: Set}", "union": "a list of dicts {symbol: Set}"}.get(shape, "a single Set")
        raise WrongForm(f"it should be {want}")
    for m in mistakes.SET_MISTAKES:
        try:
            if right(_canon_set(value, lambda s, m=m: next(m.candidates(s))[1])[2]):
                return named(m.message())
        except Exception:  # noqa: BLE001  SymPy may not map this set: not that mistake
            continue
    return "incorrect", f"not right yet: {_HOW['set']}"


def _floats(v) -> list:
    return sorted(v.atoms(sp.Float), key=float) if isinstance(v, (sp.Basic, sp.MatrixBase)) else []


_DECIMALS_NOTE = "it contains decimals (floats): exact values (sp.Rational, sp.sqrt, sp.pi) are safer"


def _verdict_expr(value, form, shape, right, salt, symhash):
    def named(says):
        return "incorrect", f"not right yet: it {says}"

    try:
        v = _default_value(value, shape)
    except WrongForm as e:
        found = _default_mistake(value, form, shape, right)
        if found is None:
            mine = _shape_of(_as_sympy_value(value)) if not isinstance(value, dict) and not is_bool(value) else ""
            if "x" in mine and "x" in shape and len(set(mine.split("x"))) == 1 == len(set(shape.split("x"))):
                raise WrongForm(f"{e} ({mistakes.PRODUCT_ORDER})") from None  # n×n for m×m: JᵀJ for JJᵀ?
            raise
        yours = _shape_words(_shape_of(_as_sympy_value(value)))
        return "incorrect", f"wrong form: it {found}: yours is {yours}, it should be {_shape_words(shape)}"
    if isinstance(v, tuple):  # yes/no, dict
        mine_form, _, canon = v
        return ("correct", "correct") if right(canon, mine_form) else ("incorrect", f"not right yet: {_HOW['default']}")
    arr = _sampled(v)
    mine_form, _, canon = _canon_sampled(arr, not isinstance(v, sp.MatrixBase))
    floats = _floats(v)
    if right(canon, mine_form):
        return ("correct", f"correct; note: {_DECIMALS_NOTE}") if floats else ("correct", "correct")
    if floats:  # rounded decimals: right once made exact? (the grader passes them within 1e-6, so do we)
        exact, err = mistakes.exact_values(v)
        if exact is not None and right(_canon_sampled(_sampled(exact), not isinstance(v, sp.MatrixBase))[2]):
            if err <= mistakes.FLOAT_RTOL:
                return "correct", f"correct; note: {_DECIMALS_NOTE}"
            return named(mistakes.ROUNDED.says)
    notes = _symbol_notes(v, salt, symhash)
    found = _default_mistake(v, form, shape, right, arr)
    if found is None:
        found = mistakes.concept_says(
            salt.rpartition(":")[2], constant=not _symbols_of(v), ref_constant=symhash is None
        )
    said = "; ".join(notes + ([found] if found else []))
    if floats:
        said = "; ".join(x for x in (said, mistakes.DECIMALS.says) if x)
    return named(said) if said else ("incorrect", f"not right yet: {_HOW['default']}")


# names the course's answers are written in: what a missing or extra variable is searched among
_COURSE_SYMBOLS = ("L", "L1", "L2", "L3", "H", "a", "b", "c", "x", "F_x", "F_y") + tuple(
    f"{p}{i}" for p in ("theta", "thetadot") for i in range(1, 7)
)


def _symbol_notes(v, salt, symhash) -> list:
    """The grader's words (:func:`kinlib.course.answers.base.symbol_notes`) on a missing or extra variable,
    found by the symbols' hash in the spec: the reference's symbols among the student's and the course's."""
    mine = sorted({x.name for x in _symbols_of(v)})
    want = symhash if symhash is not None else _sym_hash([], salt)
    if _sym_hash(mine, salt) == want:
        return []
    pool = sorted(set(_COURSE_SYMBOLS) - set(mine))
    for drop in itertools.chain([()], itertools.combinations(mine, 1), itertools.combinations(mine, 2)):
        kept = [m for m in mine if m not in drop]
        for k in range(0, 4):
            for add in itertools.combinations(pool, k):
                if _sym_hash(kept + list(add), salt) == want:
                    return symbol_notes({"symbols": mine}, {"symbols": kept + list(add)})
    if not mine:
        return ["is a constant, but the answer depends on the problem's variables"]
    return []


def _default_mistake(v, form, shape, right, arr=None):
    """The words naming the known mistake that makes ``v`` right, or None."""
    if isinstance(v, dict) or is_bool(v) or shape == "dict" or form not in ("matrix", "scalar"):
        return None
    if not isinstance(v, (sp.MatrixBase, sp.Expr)):
        v = _as_sympy_value(v)
    if isinstance(v, sp.MatrixBase) and v.shape == (1, 1) and shape == "":
        v = v[0, 0]
    want = tuple(int(x) for x in shape.split("x")) if shape else (1, 1)

    def matches(X):
        return X.shape[1:] == want and right(_canon_sampled(X, shape == "")[2])

    arr = _sampled(v) if arr is None else arr
    found = mistakes.search(arr, matches)
    if found is None:
        found = mistakes.search(arr, matches, mistakes.CONCEPT_MISTAKES, pairs=False)
    if found is not None:
        return found.says
    for m in mistakes.SYMBOLIC_MISTAKES:
        fixed = m.undo(v)
        if fixed is not None and matches(_sampled(fixed)):
            return m.says
    return None


def _subspace_mistake(arr, shape, right):
    m = int(shape)

    def matches(As):
        return all(A.shape[0] == m for A in As) and right(_canon_spans(As)[2])

    found = mistakes.search(arr, matches, mistakes.SUBSPACE_MISTAKES, pairs=False)
    return found.says if found is not None else None


def check(part: str, /, _namespace: dict | None = None, **specs: str) -> None:
    """Print for each answer variable of ``part`` whether it is right; never shows the answer.

    ``specs`` maps variable names to fingerprints made at build time; the variables are looked up
    in the caller's globals (the notebook), so a missing variable reads as "not answered yet".

    >>> check("1.1", _namespace={"x": sp.Rational(1, 2)}, x=fingerprint(sp.Rational(1, 2), salt="1.1:x"))
    part 1.1 · x: ✓ correct
    """
    ns = _namespace if _namespace is not None else sys._getframe(1).f_globals
    results = {}
    for name, spec in specs.items():
        value = ns.get(name, Ellipsis)
        status, message = verdict(value, spec, salt=f"{part}:{name}")
        results[name] = status
        mark = {"correct": "✓", "incorrect": "✗", "unanswered": "…", "error": "?"}[status]
        if status == "unanswered":
            form, shape = _parse_spec(spec)[:2]
            what = (
                _shape_words(shape)
                if form in ("matrix", "scalar")
                else "your robot itself, a kinlib SerialChain"
                if form == "property"
                else ("see the question" if form == "none" else "True or False" if form == "bool" else f"a {form}")
            )
            message = f"not answered yet: replace the ... in `{name} = ...` above with your answer ({what})"
        print(f"part {part} · {name}: {mark} {message}")
    last_results[part] = results


# ---------------------------------------------------------------------------------------------------
# Build side: used by kinlib.course.publish.handouts inside the kernel, right after a part's solution cells ran.


def emit_fingerprints(specs: dict, ns: dict) -> None:
    """Print one line, ``FINGERPRINT_MARK`` and the JSON {name: {"spec", "describe"} | {"error"}}, for
    the answers ``specs`` = {name: (kind, part)} found in the namespace ``ns``.

    >>> emit_fingerprints({"n": ("choice", "1.2")}, {})
    KINLIB-SELFCHECK {"n": {"error": "the solution cells did not define n"}}
    """
    out = {}
    for name, (kind, part) in specs.items():
        if name not in ns:
            out[name] = {"error": f"the solution cells did not define {name}"}
            continue
        try:
            out[name] = {
                "spec": fingerprint(ns[name], kind, salt=f"{part}:{name}"),
                "describe": describe_answer(ns[name], kind),
            }
        except Exception as e:
            out[name] = {"error": f"{type(e).__name__}: {e}"}
    print(FINGERPRINT_MARK + json.dumps(out))


# ---------------------------------------------------------------------------------------------------
# The workbook extension


def load_ipython_extension(ip) -> None:
    """``%load_ext kinlib.course.workbook.selfcheck``: registers the ``%%needs NAME...`` cell magic
    (:func:`kinlib.course.workbook.needs.needs`: skips a cell until its answers are filled in, and turns an error in
    it into "fix the answer above first" while the self-check has not passed them).

    IPython calls it with the shell; any object with ``register_magic_function`` does here:

    >>> class Shell:
    ...     def register_magic_function(self, func, magic_kind, magic_name):
    ...         print(magic_kind, magic_name)
    >>> load_ipython_extension(Shell())
    cell needs
    """

    def _needs(line: str, cell: str):
        return needs(line, cell, ip, status=answer_status)

    ip.register_magic_function(_needs, magic_kind="cell", magic_name="needs")
