"""What every kind's self-check shares: the public sample points, values rounded to 8 digits, salted hashes.

The workbook self-check (:mod:`kinlib.course.workbook.selfcheck`) never holds an answer, only its *fingerprint*:
the answer evaluated at fixed public sample values of its symbols, rounded and hashed. Each kind module
(:mod:`.expr`, :mod:`.subspace`, :mod:`.sets`, :mod:`.choice`, :mod:`.properties`) turns an answer of its kind into
its canonical form with these (``home_canon``) and judges a student's answer against a fingerprint
(``home_verdict``); the table of kinds (:mod:`.kinds`) dispatches, as it does for the grader.

The sample values cover the domains the grader's secret points are drawn from
(:func:`kinlib.course.answers.base.symbol_domain`): joint angles over a whole turn, one sample in each fifth,
lengths in (0.5, 2), the reference's signed symbols (forces, velocities; named in the spec) across 0.

It imports only the standard library, NumPy, SymPy and kinlib's core (it runs in the student's notebook and in
JupyterLite).
"""

from __future__ import annotations

import contextvars
import hashlib
import json
import math

import numpy as np
import sympy as sp

from .base import is_angle_name, symbol_domain

__all__ = [
    "Unanswered",
    "CannotCheck",
    "WrongForm",
    "SAMPLE_POINTS",
    "ZERO",
    "SIGNED",
    "sample_value",
    "sample_point",
    "fmt",
    "evaluate",
    "sampled",
    "canon_sampled",
    "digest",
    "sym_hash",
    "hint_hash",
    "symbols_of",
    "shape_words",
    "Judge",
]

SAMPLE_POINTS = 5  # configurations at which an answer's symbols are sampled (one per fifth of each domain)
DIGITS = 8  # significant digits kept of every sampled value
ZERO = 1e-10  # |x| below this counts as 0


class Unanswered(Exception):
    """The answer variable is missing or still ``...``.

    >>> str(Unanswered("the value is missing or ..."))
    'the value is missing or ...'
    """


class CannotCheck(Exception):
    """The answer is of a form the self-check cannot fingerprint (message says why).

    >>> fmt(sp.Symbol("t"))
    Traceback (most recent call last):
    ...
    kinlib.course.answers.fingerprints.CannotCheck: it does not evaluate to a number (Cannot convert expression to float)
    """


class WrongForm(Exception):
    """The answer has the wrong type or shape (message says what was expected).

    >>> issubclass(WrongForm, Exception)
    True
    """


#: the signed symbols (not lengths, not angles) of the answer being fingerprinted or judged: sampled across 0
SIGNED: contextvars.ContextVar = contextvars.ContextVar("kinlib_selfcheck_signed", default=frozenset())


def sample_value(name: str, k: int, signed: bool = False) -> sp.Rational:
    """The value given to every symbol called ``name`` at sample configuration ``k`` (of :data:`SAMPLE_POINTS`):
    in the grader's domain for that symbol (:func:`kinlib.course.answers.base.symbol_domain`), one sample in each
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


def sample_point(expr, k: int) -> dict:
    """{symbol: its sample value at configuration ``k``} for ``expr``'s symbols.

    >>> sample_point(sp.Integer(1), 0)
    {}
    """
    syms = getattr(expr, "free_symbols", set())
    signed = SIGNED.get()
    return {s: sample_value(s.name, k, s.name in signed) for s in syms if isinstance(s, sp.Symbol)}


def fmt(z) -> str:
    """A number as a stable string of 8 significant digits ('0' for |x| < 1e-10).

    >>> fmt(sp.pi), fmt(1e-12), fmt(1 + 2j)
    ('3.1415927e+00', '0', '1.0000000e+00+2.0000000e+00j')
    """
    try:
        z = complex(z)
    except (TypeError, ValueError) as e:
        raise CannotCheck(f"it does not evaluate to a number ({e})") from None
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return "nan"
    re = 0.0 if abs(z.real) < ZERO else z.real
    im = 0.0 if abs(z.imag) < ZERO else z.imag
    s = "0" if re == 0.0 else f"{re:.{DIGITS - 1}e}"
    if im != 0.0:
        s += f"{im:+.{DIGITS - 1}e}j"
    return s


def evaluate(x, k: int):
    """``x`` (SymPy object) with its symbols at sample point ``k``, evaluated to 30 digits.

    Evaluated with mpmath at 30 digits through ``lambdify`` (with common subexpressions shared):
    ~40× faster than ``evalf`` on an unsimplified Jacobian; ``evalf`` is the fallback.

    >>> evaluate(sp.Integer(2), 0)
    2.00000000000000000000000000000
    """
    pt = sample_point(x, k)
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


_SAMPLED: dict = {}  # (value, signed symbols) -> its samples: a self-check cell run again, the mistakes tried
_SAMPLED_MAX = 64


def sampled(v):
    """``v`` (Matrix or expression) at the sample points: an object array (points, rows, columns); remembered for
    the last 64 values (each is evaluated once however many candidates and checks use it).

    >>> sampled(sp.Matrix([[1, 2]])).shape
    (5, 1, 2)
    """
    try:
        key = (sp.ImmutableMatrix(v) if isinstance(v, sp.MatrixBase) else v, SIGNED.get())
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
        return np.array([evaluate(v, k).tolist() for k in range(SAMPLE_POINTS)], dtype=object).reshape(
            SAMPLE_POINTS, *v.shape
        )
    return np.array([evaluate(v, k) for k in range(SAMPLE_POINTS)], dtype=object).reshape(SAMPLE_POINTS, 1, 1)


def canon_sampled(arr, scalar: bool) -> tuple:
    """(form, shape, canonical values) of sampled values ``arr`` (a scalar: 1×1 entries).

    >>> canon_sampled(sampled(sp.Integer(3)), True)[:2]
    ('scalar', '')
    """
    if scalar:
        return "scalar", "", [fmt(arr[k, 0, 0]) for k in range(arr.shape[0])]
    return "matrix", f"{arr.shape[1]}x{arr.shape[2]}", [[fmt(e) for e in arr[k].ravel()] for k in range(arr.shape[0])]


def digest(form, canon, salt: str = "") -> str:
    """The salted hash (16 hex digits) of a canonical form: what a workbook holds of an answer.

    >>> len(digest("scalar", ["1"], "1.1:x")), digest("scalar", ["1"], "1.1:x") == digest("scalar", ["1"], "1.2:x")
    (16, False)
    """
    text = json.dumps([form, canon], separators=(",", ":"))
    return hashlib.sha256(f"kinlib-selfcheck-v2:{salt}:{text}".encode()).hexdigest()[:16]


def hint_hash(name: str, canon, salt: str) -> str:
    """The salted hash (8 hex digits) of an invariant of the right answer (a kind's ``home_hints``), kept in the
    spec so that a typical wrong answer sharing it can be named (never the answer itself).

    >>> hint_hash("frame", [["1"]], "s") != hint_hash("linear-rows", [["1"]], "s")
    True
    """
    return digest(f"hint:{name}", canon, salt)[:8]


def sym_hash(names, salt: str) -> str:
    """The salted hash (8 hex digits) of a set of symbol names.

    >>> sym_hash(["L", "theta1"], "s") == sym_hash(["theta1", "L", "L"], "s")
    True
    """
    return digest("symbols", sorted(set(names)), salt)[:8]


def symbols_of(value) -> set:
    """The SymPy symbols in an answer (SymPy objects, and dicts, lists, tuples, sets and arrays of them).

    >>> sorted(s.name for s in symbols_of({"a": [sp.Symbol("x"), (sp.Symbol("y"),)]}))
    ['x', 'y']
    """
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


def shape_words(shape: str) -> str:
    """A spec's shape in words: "a 6×3 matrix", "a dict", "a single expression or number (not a matrix)".

    >>> shape_words("6x3"), shape_words("")
    ('a 6×3 matrix', 'a single expression or number (not a matrix)')
    """
    if shape == "dict":
        return "a dict"
    if not shape:
        return "a single expression or number (not a matrix)"
    r, c = shape.split("x")
    return f"a {r}×{c} matrix"


class Judge:
    """One self-check question: the spec's form, shape and digest, the salt, and the symbols' hash; ``right(canon)``
    is whether a canonical form hashes to the spec's digest (the only way the self-check knows the answer).

    >>> j = Judge("scalar", "", digest("scalar", ["1"], "s"), "s")
    >>> j.right(["1"]), j.right(["2"]), j.named("has the wrong sign")
    (True, False, ('incorrect', 'not right yet: it has the wrong sign'))
    """

    def __init__(
        self, form: str, shape: str, digest_: str, salt: str = "", symhash: str | None = None, hints: dict | None = None
    ):
        self.form, self.shape, self.digest, self.salt, self.symhash = form, shape, digest_, salt, symhash
        self.hints = dict(hints or {})  # {invariant's name: hint_hash of the right answer's}

    def right(self, canon, form: str | None = None) -> bool:
        return digest(self.form if form is None else form, canon, self.salt) == self.digest

    def hint_right(self, name: str, canon) -> bool:
        """Whether ``canon`` is the right answer's invariant ``name`` (False when the spec holds none)."""
        return name in self.hints and hint_hash(name, canon, self.salt) == self.hints[name]

    @staticmethod
    def named(says: str) -> tuple[str, str]:
        return "incorrect", f"not right yet: it {says}"
