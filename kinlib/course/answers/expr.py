"""The ``expr`` kind: a SymPy expression, matrix or number, judged as a function of its symbols.

* **normalise** (:func:`to_sympy`): SymPy matrices; NumPy arrays (0-d: a number, 1-D: a column, 2-D: the
  matrix); a flat list/tuple of numbers (a column); a list of vectors (column or row matrices, 1-D arrays: one
  vector per *column*, the screw-list convention); a list of lists (the rows); SymPy expressions, Python and
  NumPy numbers, anything ``sympify(strict=True)`` accepts (e.g. mpmath numbers). A dict with string keys is
  judged entry by entry. Yes/no and strings are choices (:mod:`.choice`), sets of configurations sets
  (:mod:`.sets`): :func:`kinlib.course.answers.kinds.resolve` moves them there.
* **wire form** (what :func:`kinlib.course.answers.wire.load` gives it from a kernel): ``Matrix``, SymPy
  expression trees, numbers, ``ndarray``, lists and tuples of those, ``dict``.
* **describe** (:func:`describe_expr`, in the grader, at the secret points): type, shape, symbols and values.
* **compare** (:func:`compare_expr`): same shape, same values at the points (:func:`~.base.close`); a wrong
  answer is diagnosed by the named mistakes of :mod:`.mistakes` (the self-check's too), never by a value.
* **reference** (:func:`reference_expr`) and the advisory exact check (:func:`exact_equal`).
"""

from __future__ import annotations

import math
import numbers
import re

import numpy as np
import sympy as sp

from . import fingerprints as fp
from . import mistakes
from .base import (
    as_sympy,
    close,
    extra_value,
    fmt_shape,
    is_bool,
    not_answered,
    subs_for,
    symbol_notes,
    to_complex,
    type_name,
    values_array,
)

__all__ = [
    "to_sympy",
    "describe_expr",
    "compare_expr",
    "reference_expr",
    "exact_equal",
    "as_sympy_value",
    "home_canon",
    "home_verdict",
    "home_hints",
    "stub_words",
]


def _is_vector(x) -> bool:
    if isinstance(x, sp.MatrixBase):
        return 1 in x.shape
    if isinstance(x, np.ndarray):
        return x.ndim == 1 or (x.ndim == 2 and 1 in x.shape)
    return False


def _flat(x) -> list:
    if isinstance(x, sp.MatrixBase):
        return list(x)
    return list(np.asarray(x, dtype=object).ravel())


def _is_matrix_like(x) -> bool:
    return isinstance(x, sp.MatrixBase) or (isinstance(x, np.ndarray) and x.ndim in (1, 2))


def _from_sequence(items: list, vectors: bool):
    """:func:`to_sympy` of a list or tuple: columns side by side, rows, or a column of numbers. Entries are
    converted by :func:`~.base.as_sympy` (a string, or anything else that is not a number or SymPy value, makes
    the answer "other": it is never parsed)."""
    if not items:
        return "empty", None
    try:
        if all(_is_vector(v) for v in items) or (
            vectors
            and all(
                isinstance(v, (list, tuple, sp.Tuple)) and not any(isinstance(e, (list, tuple)) for e in v)
                for v in items
            )
        ):
            cols = [sp.Matrix([_scalar(e) for e in _flat(v)]) for v in items]
            if len({c.shape for c in cols}) != 1:
                return "ragged", None
            return "matrix", sp.Matrix.hstack(*cols)
        if vectors and all(_is_matrix_like(v) for v in items):
            try:
                return "matrix", sp.Matrix.hstack(*[_matrix_of(v) for v in items])
            except (ValueError, sp.ShapeError, IndexError):  # blocks of different heights
                return "ragged", None
        if all(isinstance(v, (list, tuple, sp.Tuple)) for v in items):
            rows = [[_scalar(e) for e in row] for row in items]
            if len({len(r) for r in rows}) != 1:
                return "ragged", None
            return "matrix", sp.Matrix(rows)
        return "matrix", sp.Matrix([_scalar(e) for e in items])
    except TypeError:  # an entry that is not a number or SymPy value (a string, a dict, None...)
        return "other", None
    except (ValueError, sp.ShapeError, IndexError):
        return "ragged", None


def _scalar(e):
    """A matrix entry: a number or SymPy value (:func:`~.base.as_sympy`, never parsed); a list or tuple there is
    a ragged answer (ValueError), anything else TypeError."""
    if isinstance(e, (list, tuple, sp.MatrixBase)):
        raise ValueError("a matrix entry that is itself a list or matrix")
    return as_sympy(e)


def _matrix_of(v):
    """A SymPy Matrix of a SymPy matrix or a 1-D/2-D NumPy array, its entries by :func:`~.base.as_sympy`."""
    if isinstance(v, sp.MatrixBase):
        return sp.Matrix(v)
    if v.ndim == 1:
        return sp.Matrix([_scalar(e) for e in v.tolist()])
    return sp.Matrix([[_scalar(e) for e in row] for row in v.tolist()])


def to_sympy(value, vectors: bool = False):
    """``(tag, obj)``: ``obj`` a SymPy Matrix or scalar expression, or None with ``tag`` saying why not.

    Tags: ``matrix``, ``scalar``; and, with ``obj`` None: ``ellipsis``, ``none``, ``bool``, ``empty``
    (an empty list), ``ragged`` (vectors of different lengths), ``array`` (more than 2 dimensions),
    ``other``. With ``vectors=True`` (subspaces) a list of lists, or of matrices, is a list of spanning
    vectors (or blocks of them) put side by side.

    >>> to_sympy([1, 2])
    ('matrix', Matrix([
    [1],
    [2]]))
    >>> to_sympy([sp.Matrix([1, 0]), np.array([0, 1]), sp.Matrix([[2, 3]])])[1].shape   # one vector per column
    (2, 3)
    >>> to_sympy([[1, 2, 3], [4, 5, 6]])[1].shape, to_sympy([[1, 2, 3], [4, 5, 6]], vectors=True)[1].shape
    ((2, 3), (3, 2))
    >>> to_sympy(np.float64(0.5)), to_sympy(...), to_sympy("J"), to_sympy([])
    (('scalar', 0.500000000000000), ('ellipsis', None), ('other', None), ('empty', None))
    """
    if value is Ellipsis:
        return "ellipsis", None
    if value is None:
        return "none", None
    if is_bool(value):
        return "bool", None
    if isinstance(value, sp.MatrixBase):
        return "matrix", sp.Matrix(value)
    if isinstance(value, np.ndarray):
        if value.ndim == 0:
            return to_sympy(value.item())
        if value.ndim in (1, 2):
            try:
                return "matrix", _matrix_of(value)
            except TypeError:  # an entry that is not a number or SymPy value (a string...): never parsed
                return "other", None
            except (ValueError, sp.ShapeError, IndexError):
                return "ragged", None
        return "array", None
    if isinstance(value, (sp.Tuple, list, tuple)):
        return _from_sequence(list(value), vectors)
    if isinstance(value, sp.Expr):
        return "scalar", value
    if isinstance(value, sp.Basic):
        return "other", None
    if isinstance(value, (numbers.Number, np.number)):
        return "scalar", as_sympy(value)
    if isinstance(value, (str, bytes, dict, set, frozenset)):
        return "other", None
    try:  # mpmath numbers, objects with a _sympy_ method, ...
        v = sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError, ValueError, AttributeError):
        return "other", None
    if isinstance(v, sp.MatrixBase):
        return "matrix", sp.Matrix(v)
    return ("scalar", v) if isinstance(v, sp.Expr) else ("other", None)


def _shape(obj):
    return list(obj.shape) if isinstance(obj, sp.MatrixBase) else []


def _degrees_hint(obj):
    trig = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
    for f in obj.atoms(*trig) if hasattr(obj, "atoms") else ():
        for n in f.args[0].atoms(sp.Number):
            try:
                if abs(n) in mistakes.DEGREE_CONSTANTS:
                    return True
            except TypeError:
                pass
    return False


def _lambdified_values(obj, entries, points, seed):
    """Values at ``points`` through a NumPy lambdify (complex128), or None to fall back to evalf."""
    if not points:
        return []
    syms = sorted((s for s in obj.free_symbols if isinstance(s, sp.Symbol)), key=lambda s: s.name)
    if any(not isinstance(s, sp.Symbol) for s in obj.free_symbols) or obj.atoms(sp.core.function.AppliedUndef):
        return None
    try:
        f = sp.lambdify(syms, entries, modules="numpy", cse=True)
        out = []
        for p in points:
            args = [np.complex128(p[s.name] if s.name in p else extra_value(seed, s.name)) for s in syms]
            with np.errstate(all="ignore"):
                vals = [complex(v) for v in f(*args)]
            if not all(math.isfinite(v.real) and math.isfinite(v.imag) for v in vals):
                return None
            out.append([[v.real, v.imag] for v in vals])
        return out
    except Exception:  # noqa: BLE001
        return None


def describe_expr(value, points, seed=0, vectors=False):
    """Matrix/expression answer: type, shape, symbols and values at ``points`` (dicts name -> float).
    ``vectors``: a list of lists is a list of spanning vectors (subspaces; see :func:`to_sympy`).

    >>> d = describe_expr(sp.Matrix([sp.Symbol("x"), 1]), [{"x": 2.0}])
    >>> d["tag"], d["shape"], d["symbols"], d["values"]
    ('matrix', [2, 1], ['x'], [[[2.0, 0.0], [1.0, 0.0]]])
    """
    if isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {
            "tag": "dict",
            "type": "dict",
            "items": {str(k): describe_expr(v, points, seed, vectors) for k, v in value.items()},
        }
    tag, obj = to_sympy(value, vectors=vectors)
    out = {"tag": tag, "type": type_name(value)}
    if obj is None:
        return out
    syms = sorted({s.name for s in obj.free_symbols if isinstance(s, sp.Symbol)})
    out.update(
        shape=_shape(obj),
        symbols=syms,
        has_float=bool(obj.atoms(sp.Float)),
        degrees=_degrees_hint(obj),
        undefined=sorted({str(f.func) for f in obj.atoms(sp.core.function.AppliedUndef)}),
    )
    out["values"] = _values(obj, points, seed)
    variants = {}
    for m in mistakes.SYMBOLIC_MISTAKES[1:]:  # (degrees: the "degrees" flag above)
        undone = m.undo(obj)
        if undone is not None:
            variants[m.name] = _values(undone, points, seed)
    if variants:
        out["variants"] = variants
    return out


def _values(obj, points, seed):
    """``obj``'s entries at ``points`` as ``[re, im]`` pairs (None: not a finite number)."""
    entries = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    fast = _lambdified_values(obj, entries, points, seed)
    if fast is not None:
        return fast
    values = []
    for p in points:
        subs = subs_for(obj, p, seed)
        row = []
        for e in entries:
            try:
                row.append(to_complex(e.xreplace(subs)))
            except Exception:
                row.append(None)
        values.append(row)
    return values


def _entries(idx, shape):
    cols = shape[1] if len(shape) == 2 else 1
    return ", ".join(f"({i // cols + 1},{i % cols + 1})" for i in idx[:6]) + (" …" if len(idx) > 6 else "")


def compare_expr(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """Matrices and expressions as functions of the symbols: same shape, same values at the points.

    >>> ref = {"shape": [1, 2], "symbols": [], "values": [[[1.0, 0.0], [2.0, 0.0]]]}
    >>> compare_expr(dict(ref, tag="matrix"), ref, "v")
    (True, '')
    >>> compare_expr(dict(ref, tag="matrix", shape=[2, 1]), ref, "v")
    (False, 'v is transposed: yours is 2×1, expected 1×2')
    """
    na = not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if ref.get("tag") == "dict":
        return _compare_dict(stu, ref, name)
    if stu.get("tag") not in ("matrix", "scalar"):
        if str(stu.get("type", "")).endswith("Equality"):
            return False, f"{name} is an equation (sp.Eq): assign the expression or matrix itself"
        return False, f"{name} is a {stu.get('type')}; expected a SymPy expression or Matrix"
    rshape, sshape = list(ref["shape"]), list(stu["shape"])
    if rshape in ([1, 1], []) and sshape in ([1, 1], []):
        rshape = sshape
    if sshape != rshape:
        if len(sshape) == 2 and sshape[::-1] == rshape:
            return False, (
                f"{name} is transposed: yours is {fmt_shape(sshape)}, expected "
                f"{fmt_shape(rshape)}" + (" (one column per joint)" if rshape[0] == 6 else "")
            )
        square = len(sshape) == 2 == len(rshape) and sshape[0] == sshape[1] and rshape[0] == rshape[1]
        hint = f" ({mistakes.PRODUCT_ORDER})" if square else ""
        return False, f"{name} has the wrong shape: yours is {fmt_shape(sshape)}, expected {fmt_shape(rshape)}{hint}"
    if stu.get("undefined"):
        return False, f"{name} contains undefined functions {', '.join(stu['undefined'])}"
    S, R = values_array(stu["values"]), values_array(ref["values"])
    if S.shape != R.shape:
        return False, f"{name} could not be compared (malformed values)"
    if not np.isfinite(S).all():  # NaN (None: not a number) or inf
        return False, f"{name} could not be evaluated at some joint values (division by zero, or undefined symbols?)"
    notes = symbol_notes(stu, ref)
    if close(S, R):
        extra = []
        if stu.get("has_float") and not ref.get("has_float"):
            extra.append("contains decimals: use exact values (sp.pi, sp.sqrt, sp.Rational)")
        return True, "; ".join(extra)
    if stu.get("has_float"):
        if close_within(S, R, mistakes.ROUNDED_RTOL):
            return False, f"{name} " + "; ".join(notes + [mistakes.ROUNDED.says])
        return False, f"{name} " + "; ".join(notes + [_no_key(_diagnose(S, R, rshape, stu)), mistakes.DECIMALS.says])
    return False, f"{name} " + "; ".join(notes + [_no_key(_diagnose(S, R, rshape, stu, name, ref))])


def _compare_dict(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """A dict of answers (e.g. {configuration: row of J}): the same keys, each entry compared."""
    if stu.get("tag") != "dict":
        return False, f"{name} is a {stu.get('type')}; expected a dict with keys {', '.join(ref['items'])}"
    if set(stu["items"]) != set(ref["items"]):
        missing, extra = (
            sorted(set(ref["items"]) - set(stu["items"])),
            sorted(set(stu["items"]) - set(ref["items"])),
        )
        what = [f"no key {', '.join(map(repr, missing))}"] if missing else []
        what += [f"keys {', '.join(map(repr, extra))} that are not asked for"] if extra else []
        return False, f"{name} has " + " and ".join(what)
    msgs = [compare_expr(stu["items"][k], ref["items"][k], f"{name}[{k!r}]") for k in ref["items"]]
    return all(ok for ok, _ in msgs), "; ".join(m for _, m in msgs if m)


_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_LEAKS = [
    (re.compile(rf"\s*\({_NUM}\s*times the answer\)"), ""),
    (re.compile(rf"\bis {_NUM} times the answer"), "is within 1% of the answer"),
    (re.compile(rf"\b{_NUM} times the answer"), "a constant times the answer"),
]


def _no_key(msg: str) -> str:
    """A diagnosis without numbers that give the reference away: "off by a constant factor (0.5 times the
    answer)" tells the student the answer is theirs / 0.5, so the factor is dropped.

    >>> _no_key("is off by a constant factor (0.5 times the answer)")
    'is off by a constant factor'
    >>> _no_key("is 0.997 times the answer: rounded decimals?")
    'is within 1% of the answer: rounded decimals?'
    """
    for rx, rep in _LEAKS:
        msg = rx.sub(rep, msg)
    return msg


def close_within(S, R, rtol) -> bool:
    """S and R equal within a relative tolerance (finite values only)."""
    if not (np.isfinite(S).all() and np.isfinite(R).all()):
        return False
    return bool(np.all(np.abs(S - R) <= 1e-9 + rtol * np.maximum(np.abs(S), np.abs(R))))


def _diagnose(S, R, shape, stu, name="", ref=None) -> str:
    """What is wrong with values S (points × entries) against R: a named mistake of
    :mod:`kinlib.course.answers.mistakes` (the self-check's too), else which entries differ; never a value."""
    P = S.shape[0]
    r, c = (shape + [1, 1])[:2] if len(shape) == 2 else (1, 1)
    S3, R3 = S.reshape(P, r, c), R.reshape(P, r, c)

    def matches(X):
        return X.shape == R3.shape and close(X, R3)

    found = mistakes.search(S3, matches, exhaustive=True)
    if found is None:
        found = mistakes.search(S3, matches, mistakes.CONCEPT_MISTAKES, pairs=False)
    if found is not None:
        return found.says
    for m in mistakes.SYMBOLIC_MISTAKES:
        alt = (stu.get("variants") or {}).get(m.name)
        if alt is not None:
            try:
                if close(values_array(alt).reshape(R.shape), R):
                    return m.says
            except (ValueError, TypeError, IndexError):
                pass
    for inv in mistakes.invariants_for((r, c)):  # which Jacobian; the product's order
        if close(inv.of(S3), inv.of(R3)):
            return inv.says
    said = mistakes.concept_says(name, constant=not stu.get("symbols"), ref_constant=not (ref or {}).get("symbols"))
    if said:
        return said
    neg = [k for k in range(S.shape[1]) if close(S[:, k], -R[:, k]) and not close(S[:, k], R[:, k])]
    bad = [k for k in range(S.shape[1]) if not close(S[:, k], R[:, k])]
    if neg and len(neg) == len(bad):
        return f"has the wrong sign in entries {_entries(neg, shape)}"
    if np.all(np.abs(S) < 1e-12):
        return "is zero everywhere"
    ratio = _const_ratio(S, R)
    if ratio is not None:
        if abs(abs(ratio) - 180 / math.pi) < 1e-6 * 180 / math.pi or abs(abs(ratio) - math.pi / 180) < 1e-9:
            return "looks like it is in degrees: SymPy and NumPy angles are radians (multiply degrees by sp.pi/180)"
        if abs(ratio - 1) < 1e-2:
            return "is close to the answer but not equal: rounded decimals? Use exact values (sp.sqrt(2), sp.pi)"
        return "is off by a constant factor (a factor missing or extra, e.g. a length or ½?)"
    if stu.get("degrees"):
        return "looks like it uses degrees inside sin/cos (e.g. sin(θ + 45)): angles are radians: multiply degrees by sp.pi/180"
    if S.shape[1] > 1:
        return f"differs in entries {_entries(bad, shape)}"
    return "has the wrong value"


def _const_ratio(S, R):
    mask = np.abs(R) > 1e-6
    if not mask.any() or np.any(np.abs(S[~mask]) > 1e-6):
        return None
    q = S[mask] / R[mask]
    if np.allclose(q, q.flat[0], rtol=1e-6, atol=0) and abs(q.flat[0].imag) < 1e-9:
        return float(q.flat[0].real)
    return None


def reference_expr(value):
    """The reference value of an ``expr`` answer as something the wire format round-trips (a dict entry by entry).

    >>> reference_expr([1, 2]).shape, reference_expr({"a": 1})
    ((2, 1), {'a': 1})
    """
    if isinstance(value, dict) and value and all(isinstance(k, (str, int)) for k in value):
        return {str(k): reference_expr(v) for k, v in value.items()}
    tag, obj = to_sympy(value)
    if obj is None:
        raise TypeError(f"reference answer of kind 'expr' is {tag} ({type_name(value)})")
    return obj


def exact_equal(value, ref, budget=5.0):
    """'equal' when value - reference simplifies to exactly zero, else 'not proved' (advisory only).

    >>> x = sp.Symbol("x")
    >>> exact_equal(sp.sin(x)**2 + sp.cos(x)**2, sp.Integer(1)), exact_equal(x, sp.Integer(1))
    ('equal', 'not proved')
    """
    import time

    t0 = time.monotonic()
    tag, obj = to_sympy(value)
    if obj is None:
        return "not sympy"
    ref_syms = {s.name: s for s in ref.free_symbols if isinstance(s, sp.Symbol)}
    obj = obj.xreplace(
        {s: ref_syms[s.name] for s in obj.free_symbols if isinstance(s, sp.Symbol) and s.name in ref_syms}
    )
    a = list(obj) if isinstance(obj, sp.MatrixBase) else [obj]
    b = list(ref) if isinstance(ref, sp.MatrixBase) else [ref]
    if len(a) != len(b):
        return "not proved"
    for x, y in zip(a, b):
        d = as_sympy(x - y)
        if d == 0:
            continue
        d = sp.expand(sp.expand_trig(d))
        if d == 0:
            continue
        if time.monotonic() - t0 < budget and sp.count_ops(d) < 400 and sp.simplify(d) == 0:
            continue
        return "not proved"
    return "equal"


# ----------------------------------------------------------------------------------------- the self-check
# The workbook's side of the kind (kinlib.course.workbook.selfcheck): the answer's canonical form at the public
# sample points (home_canon), hashed into the workbook's spec, and the verdict on a student's answer against it
# (home_verdict), naming the same mistakes in the same words as compare_expr.

_FORM_WORDS = {
    "array": "an array with more than 2 dimensions",
    "empty": "an empty list",
    "ragged": "a list of vectors of different lengths",
}


def as_sympy_value(value, vectors: bool = False):
    """The answer as a SymPy Matrix or expression (:func:`to_sympy`), or :class:`~.fingerprints.WrongForm`.

    >>> as_sympy_value([1, 2]).shape
    (2, 1)
    >>> as_sympy_value("J")
    Traceback (most recent call last):
    ...
    kinlib.course.answers.fingerprints.WrongForm: it should be a SymPy Matrix, expression or number, yours is a str
    """
    tag, v = to_sympy(value, vectors=vectors)
    if v is not None:
        return v
    what = _FORM_WORDS.get(tag, f"a {type(value).__name__}")
    raise fp.WrongForm(f"it should be a SymPy Matrix, expression or number, yours is {what}")


def _shape_of(v) -> str:
    return f"{v.shape[0]}x{v.shape[1]}" if isinstance(v, sp.MatrixBase) else ""


def _home_value(value, shape: str | None = None):
    """The answer as a SymPy Matrix or expression with the expected ``shape`` ("rxc", "" for a scalar,
    "dict"; None: any), or, for a yes/no or dict answer, its finished canonical form (a tuple)."""
    if is_bool(value):  # a yes/no answer
        return "bool", "", [str(bool(value))]
    if isinstance(value, dict) or shape == "dict":  # e.g. {configuration name: row of J}
        if not isinstance(value, dict):
            raise fp.WrongForm(f"it should be a dict, yours is a {type(value).__name__}")
        items = sorted(value.items(), key=lambda kv: str(kv[0]))
        return "matrix", "dict", [[str(k), list(home_canon(v)[1:])] for k, v in items]
    v = as_sympy_value(value)
    if isinstance(v, sp.MatrixBase):
        mine = _shape_of(v)
        if shape == "" and v.shape == (1, 1):  # a 1x1 Matrix for a scalar answer
            v, mine = v[0, 0], ""
        elif shape not in (None, mine):
            raise fp.WrongForm(f"it should be {fp.shape_words(shape)}, yours is {fp.shape_words(mine)}")
    elif shape:
        raise fp.WrongForm(f"it should be {fp.shape_words(shape)}, yours is {fp.shape_words('')}")
    if not isinstance(v, (sp.MatrixBase, sp.Expr)):
        raise fp.WrongForm(f"it should be a SymPy Matrix, expression or number, yours is {type(v).__name__}")
    return v


def home_canon(value, shape: str | None = None) -> tuple:
    """``(form, shape, canonical values)`` of an ``expr`` answer at the public sample points: form ``matrix``,
    ``scalar`` or ``bool`` (a dict of answers: shape ``dict``).

    >>> home_canon(sp.Matrix([[1, 2]]))[:2], home_canon(True)
    (('matrix', '1x2'), ('bool', '', ['True']))
    """
    v = _home_value(value, shape)
    if isinstance(v, tuple):
        return v
    return fp.canon_sampled(fp.sampled(v), not isinstance(v, sp.MatrixBase))


def _floats(v) -> list:
    return sorted(v.atoms(sp.Float), key=float) if isinstance(v, (sp.Basic, sp.MatrixBase)) else []


DECIMALS_NOTE = "it contains decimals (floats): exact values (sp.Rational, sp.sqrt, sp.pi) are safer"
HOME_DIFFERS = "its values differ from the answer's at sample values of its symbols"


def home_verdict(value, judge: fp.Judge) -> tuple[str, str]:
    """The self-check's ``(status, message)`` on an ``expr`` answer against the spec in ``judge``: right, right up
    to decimals (with a note), or the named mistake (:mod:`.mistakes`, the grader's words), never a value.

    >>> j = fp.Judge("scalar", "", fp.digest("scalar", home_canon(2)[2]))
    >>> home_verdict(2, j), home_verdict(-2, j)
    (('correct', 'correct'), ('incorrect', 'not right yet: it has the wrong sign'))
    """
    form, shape, right, named = judge.form, judge.shape, judge.right, judge.named
    try:
        v = _home_value(value, shape)
    except fp.WrongForm as e:
        found = _home_mistake(value, form, shape, right)
        if found is None:
            mine = _shape_of(as_sympy_value(value)) if not isinstance(value, dict) and not is_bool(value) else ""
            if "x" in mine and "x" in shape and len(set(mine.split("x"))) == 1 == len(set(shape.split("x"))):
                raise fp.WrongForm(f"{e} ({mistakes.PRODUCT_ORDER})") from None  # n×n for m×m: JᵀJ for JJᵀ?
            raise
        yours = fp.shape_words(_shape_of(as_sympy_value(value)))
        return "incorrect", f"wrong form: it {found}: yours is {yours}, it should be {fp.shape_words(shape)}"
    if isinstance(v, tuple):  # yes/no, dict
        mine_form, _, canon = v
        return ("correct", "correct") if right(canon, mine_form) else ("incorrect", f"not right yet: {HOME_DIFFERS}")
    arr = fp.sampled(v)
    mine_form, _, canon = fp.canon_sampled(arr, not isinstance(v, sp.MatrixBase))
    floats = _floats(v)
    if right(canon, mine_form):
        return ("correct", f"correct; note: {DECIMALS_NOTE}") if floats else ("correct", "correct")
    if floats:  # rounded decimals: right once made exact? (the grader passes them within 1e-6, so do we)
        exact, err = mistakes.exact_values(v)
        if exact is not None and right(fp.canon_sampled(fp.sampled(exact), not isinstance(v, sp.MatrixBase))[2]):
            if err <= mistakes.FLOAT_RTOL:
                return "correct", f"correct; note: {DECIMALS_NOTE}"
            return named(mistakes.ROUNDED.says)
    notes = _home_symbol_notes(v, judge.salt, judge.symhash)
    found = _home_mistake(v, form, shape, right, arr)
    if found is None:  # which Jacobian; the product's order (the spec's hints)
        invs = mistakes.invariants_for(arr.shape[1:])
        found = next((i.says for i in invs if judge.hint_right(i.name, _hint(i, arr))), None)
    if found is None:
        found = mistakes.concept_says(
            judge.salt.rpartition(":")[2], constant=not fp.symbols_of(v), ref_constant=judge.symhash is None
        )
    said = "; ".join(notes + ([found] if found else []))
    if floats:
        said = "; ".join(x for x in (said, mistakes.DECIMALS.says) if x)
    return named(said) if said else ("incorrect", f"not right yet: {HOME_DIFFERS}")


# names the course's answers are written in: what a missing or extra variable is searched among
COURSE_SYMBOLS = ("L", "L1", "L2", "L3", "H", "a", "b", "c", "x", "F_x", "F_y") + tuple(
    f"{p}{i}" for p in ("theta", "thetadot") for i in range(1, 7)
)


def _home_symbol_notes(v, salt, symhash) -> list:
    """The grader's words (:func:`~.base.symbol_notes`) on a missing or extra variable, found by the symbols' hash
    in the spec: the reference's symbols among the student's and the course's."""
    import itertools

    mine = sorted({x.name for x in fp.symbols_of(v)})
    want = symhash if symhash is not None else fp.sym_hash([], salt)
    if fp.sym_hash(mine, salt) == want:
        return []
    pool = sorted(set(COURSE_SYMBOLS) - set(mine))
    for drop in itertools.chain([()], itertools.combinations(mine, 1), itertools.combinations(mine, 2)):
        kept = [m for m in mine if m not in drop]
        for k in range(0, 4):
            for add in itertools.combinations(pool, k):
                if fp.sym_hash(kept + list(add), salt) == want:
                    return symbol_notes({"symbols": mine}, {"symbols": kept + list(add)})
    if not mine:
        return ["is a constant, but the answer depends on the problem's variables"]
    return []


def _home_mistake(v, form, shape, right, arr=None):
    """The words naming the known mistake that makes ``v`` right, or None."""
    if isinstance(v, dict) or is_bool(v) or shape == "dict" or form not in ("matrix", "scalar"):
        return None
    if not isinstance(v, (sp.MatrixBase, sp.Expr)):
        v = as_sympy_value(v)
    if isinstance(v, sp.MatrixBase) and v.shape == (1, 1) and shape == "":
        v = v[0, 0]
    want = tuple(int(x) for x in shape.split("x")) if shape else (1, 1)

    def matches(X):
        return X.shape[1:] == want and right(fp.canon_sampled(X, shape == "")[2])

    arr = fp.sampled(v) if arr is None else arr
    found = mistakes.search(arr, matches)
    if found is None:
        found = mistakes.search(arr, matches, mistakes.CONCEPT_MISTAKES, pairs=False)
    if found is not None:
        return found.says
    for m in mistakes.SYMBOLIC_MISTAKES:
        fixed = m.undo(v)
        if fixed is not None and matches(fp.sampled(fixed)):
            return m.says
    return None


def _hint(inv, arr) -> list:
    return fp.canon_sampled(inv.of(arr), False)[2]


def home_hints(value) -> dict:
    """{invariant's name: its canonical form} of a right answer that may be a Jacobian (6 rows, 2 columns or
    more) or is a symmetric square matrix: what the spec keeps, hashed, so that the self-check can tell, as the
    grader does, the right angular rows with the wrong linear ones, the right Jacobian in another frame's axes, or
    J Jᵀ for Jᵀ J (:func:`~.mistakes.invariants_for`); {} for any other answer.

    >>> sorted(home_hints(sp.ones(6, 2))), sorted(home_hints(sp.ones(3, 3))), home_hints(sp.Matrix([[1, 2], [0, 1]]))
    (['frame', 'linear-rows'], ['product-order'], {})
    """
    try:
        v = _home_value(value)
    except fp.WrongForm:
        return {}
    if not isinstance(v, sp.MatrixBase) or not mistakes.invariants_for(v.shape):
        return {}
    arr = fp.sampled(v)
    hints = {inv.name: inv.of(arr) for inv in mistakes.invariants_for(v.shape)}
    return {n: fp.canon_sampled(x, False)[2] for n, x in hints.items() if np.isfinite(x).all()}


def stub_words(value) -> str:
    """What an ``expr`` answer is, for the workbook's stub (never whether it is constant: that is a hint).

    >>> stub_words(sp.zeros(6, 3)), stub_words(sp.Integer(3)), stub_words({"a": 1})
    ('a 6×3 Matrix', 'a SymPy expression or a number', 'a dict {a: ...}')
    """
    if is_bool(value):
        return "True or False"
    if isinstance(value, dict):
        return "a dict {" + ", ".join(map(str, value)) + ": ...}"
    try:
        v = as_sympy_value(value)
    except fp.WrongForm:
        return "a value"
    if isinstance(v, sp.MatrixBase):
        return f"a {v.shape[0]}×{v.shape[1]} Matrix"
    return "a SymPy expression or a number"  # the same words for both: whether it is constant is a hint
