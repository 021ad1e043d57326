"""One API, two backends: decide SymPy or NumPy from the arguments, and check them.

A SymPy object anywhere in the arguments (a Symbol, an expression, a Matrix) selects the exact
backend: results are SymPy Matrices with no floats introduced. Plain numbers (ints, floats, NumPy
arrays) select the numeric backend: results are NumPy float arrays.

Every check raises ``ValueError``/``TypeError`` naming the argument, the expected shape or
property, and what was given.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np
import sympy as sp

__all__ = [
    "is_symbolic",
    "as_matrix",
    "as_vector",
    "as_screw_list",
    "as_thetas",
    "describe",
    "exact_number",
    "check_real_finite",
    "real_array",
    "exact_floats",
    "joint_symbols",
    "as_scalar",
    "as_jacobian",
    "numeric_jacobian",
    "numeric_vectors",
    "exact_jacobian",
    "nested_shape",
]


def describe(x: Any) -> str:
    """A short description of ``x`` for error messages."""
    if isinstance(x, sp.MatrixBase):
        return f"a SymPy Matrix of shape {x.shape}"
    if isinstance(x, np.ndarray):
        return f"an array of shape {x.shape} and dtype {x.dtype}"
    if isinstance(x, (str, bytes)):
        return f"the string {x!r}"
    if isinstance(x, (list, tuple)):
        try:
            shape = np.shape(np.asarray(x, dtype=object))
        except Exception:  # ragged
            shape = f"ragged, length {len(x)}"
        return f"a {type(x).__name__} of shape {shape}"
    r = repr(x)
    return f"{type(x).__name__} {r[:60]}"


def exact_number(x: Any, name: str) -> sp.Expr:
    """The exact SymPy number a student meant by ``x``: the one place numbers become exact.

    ints → Integer; floats (Python or NumPy) → the decimal of their shortest repr (0.1 → 1/10,
    0.425 → 17/40, 2.0 → 2, 1e-3 → 1/1000), never the float's binary expansion and never a guess
    such as nsimplify; ``fractions.Fraction`` and ``decimal.Decimal`` → the Rational they hold;
    SymPy Floats likewise by their shortest decimal; other SymPy numbers and expressions unchanged.
    Refused with a message naming ``name``: bool, str/bytes, None, complex numbers (also SymPy's
    ``I`` and anything with a nonzero imaginary part), NaN and ±inf (also SymPy's ``nan``, ``oo``, ``zoo``).
    """
    import decimal
    import fractions

    if isinstance(x, (bool, np.bool_)):
        raise TypeError(f"{name} must be a real number, got the bool {x!r}")
    if isinstance(x, (str, bytes)) or x is None:
        raise TypeError(f"{name} must be a real number or a SymPy expression, got {describe(x)}")
    if isinstance(x, (complex, np.complexfloating)):
        raise TypeError(f"{name} must be a real number, got the complex number {x!r}")
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float):
        if not np.isfinite(x):
            raise ValueError(f"{name} must be a finite real number, got {x!r}")
        return sp.Integer(int(x)) if x.is_integer() else sp.Rational(repr(x))
    if isinstance(x, int):
        return sp.Integer(x)
    if isinstance(x, fractions.Fraction):
        return sp.Rational(x.numerator, x.denominator)
    if isinstance(x, decimal.Decimal):
        if not x.is_finite():
            raise ValueError(f"{name} must be a finite real number, got {x!r}")
        return sp.Rational(str(x))
    if isinstance(x, sp.Basic):
        if not isinstance(x, sp.Expr):
            raise TypeError(f"{name} must be a real number or a SymPy expression, got {describe(x)}")
        if isinstance(x, sp.Float):
            return exact_number(float(x), name) if x.is_finite else exact_number(float("nan"), name)
        check_real_finite(x, name)
        return x
    raise TypeError(f"{name} must be a real number or a SymPy expression, got {describe(x)}")


def check_real_finite(e: sp.Expr, name: str, symbols: bool = True) -> sp.Expr:
    """Refuse a SymPy expression that is not real and finite (I, nan, oo, zoo, a non-real symbol).

    Every public function refuses symbols not declared real through this one check (the README's promise);
    ``symbols=False`` skips that test, for kinlib's own intermediate expressions only.

    >>> check_real_finite(sp.Symbol("L", positive=True) + 1, "L")
    L + 1
    >>> check_real_finite(sp.I, "q")
    Traceback (most recent call last):
    ...
    ValueError: q must be real and finite, got I
    """
    if e.is_Atom:
        if isinstance(e, _NOT_FINITE_TYPES):
            raise ValueError(f"{name} must be real and finite, got {e}")
        if symbols and e.is_Symbol and e.is_real is not True:
            raise ValueError(
                f"{name} must be real: the symbol {e} is not declared real "
                f"(use sp.Symbol({str(e)!r}, real=True) or positive=True), got {e}"
            )
        return e
    if e.atoms(*_NOT_FINITE_TYPES):  # one traversal: I, nan, oo, -oo, zoo anywhere
        raise ValueError(f"{name} must be real and finite, got {str(e)[:200]}")
    bad = sorted((s for s in e.free_symbols if s.is_real is not True), key=str) if symbols else []
    if bad:
        raise ValueError(
            f"{name} must be real: the symbol(s) {', '.join(map(str, bad))} are not declared real "
            f"(use sp.Symbol(..., real=True) or positive=True), got {str(e)[:200]}"
        )
    if e.is_number and e.is_real is False:
        raise ValueError(f"{name} must be real, got {str(e)[:200]}")
    return e


_NOT_FINITE = (sp.nan, sp.zoo, sp.oo, -sp.oo, sp.I)
_NOT_FINITE_TYPES = tuple(type(x) for x in _NOT_FINITE)


def exact_floats(e: sp.Expr, name: str) -> sp.Expr:
    """``e`` with every SymPy Float inside it replaced by the exact decimal it prints as (0.5·L → L/2).

    >>> exact_floats(sp.Float(0.1) * sp.Symbol("L", positive=True), "M")
    L/10
    """
    if not e.has(sp.Float):
        return e
    return e.xreplace({f: exact_number(f, name) for f in e.atoms(sp.Float)})


def is_symbolic(*args: Any) -> bool:
    """True when any argument holds a SymPy object (Symbol, expression or Matrix)."""
    for a in args:
        if isinstance(a, sp.Basic) or isinstance(a, sp.MatrixBase):
            return True
        if isinstance(a, np.ndarray):
            if a.dtype == object and any(isinstance(e, sp.Basic) for e in a.flat):
                return True
        elif isinstance(a, (list, tuple)):
            if is_symbolic(*a):
                return True
    return False


def _check_scalar(e: Any, name: str, symbolic: bool, real_symbols: bool = True):
    """One entry: exact (symbolic) or a finite real number (numeric); refused with a message naming ``name``.

    Symbolic: numbers become exact (:func:`exact_number`: 0.1 → 1/10), Floats inside expressions too, and
    expressions must be finite and free of I (:func:`check_real_finite`), every symbol declared real (the
    README's promise: one check for every public function; ``real_symbols=False`` only for kinlib's own
    intermediate expressions). Numeric: real, finite numbers only.
    """
    if isinstance(e, (str, bytes)):
        raise TypeError(f"{name} must hold numbers or SymPy expressions, got {describe(e)}")
    if isinstance(e, (bool, np.bool_)):
        raise TypeError(f"{name} must hold numbers or SymPy expressions, got the bool {e!r}")
    if symbolic:
        if isinstance(e, sp.Basic):
            if not isinstance(e, sp.Expr):
                raise TypeError(f"{name} must hold SymPy expressions, got {describe(e)}")
            if isinstance(e, sp.Float):
                return exact_number(e, name)
            return check_real_finite(exact_floats(e, name), name, real_symbols)
        if isinstance(e, (numbers.Number, np.number)):
            return exact_number(e, name)
        raise TypeError(f"{name} must hold numbers or SymPy expressions, got {describe(e)}")
    if isinstance(e, (complex, np.complexfloating)):
        raise TypeError(f"{name} must hold real numbers, got the complex number {e!r}")
    if isinstance(e, (numbers.Real, np.integer, np.floating)):
        if isinstance(e, (float, np.floating)) and not np.isfinite(e):
            raise ValueError(f"{name} must hold finite real numbers, got {e!r}")
        if not isinstance(e, (float, np.floating, np.integer)):
            within_float_range(e, name)
        return e
    raise TypeError(f"{name} must hold real numbers, got {describe(e)}")


def within_float_range(e, name: str) -> float:
    """``float(e)`` of a real number, or a ValueError naming ``name`` for one beyond the float range (a Python int
    such as 10**400, a Fraction): numbers select the float backend, where it cannot be represented.

    >>> within_float_range(10**400, "v")
    Traceback (most recent call last):
    ...
    ValueError: v must hold numbers within the float range (|x| < 1.8e308), got an int of 401 digits; for exact work pass SymPy numbers (sp.Integer(...))
    """
    try:
        v = float(e)  # an int raises OverflowError; a SymPy Integer gives inf
        if math.isinf(v) and not isinstance(e, (float, np.floating, sp.Float)):
            raise OverflowError
        return v
    except OverflowError:
        what = f"an int of {len(str(abs(int(e))))} digits" if isinstance(e, (int, sp.Integer)) else describe(e)
        raise ValueError(
            f"{name} must hold numbers within the float range (|x| < 1.8e308), got {what}; "
            "for exact work pass SymPy numbers (sp.Integer(...))"
        ) from None


def nested_shape(x: Any, name: str) -> tuple[int, ...]:
    """The shape of a (nested) list/tuple/array of entries; a ragged one is refused with a ValueError naming ``name``.

    >>> nested_shape([[1, 2], [3, 4]], "J")
    (2, 2)
    >>> nested_shape([[1, 2], [3]], "J")
    Traceback (most recent call last):
    ...
    ValueError: J must be rectangular (every row the same length), got a ragged list: entries of shapes (2,), (1,)
    """
    if isinstance(x, np.ndarray):
        return x.shape
    if isinstance(x, sp.MatrixBase):
        return x.shape
    if not isinstance(x, (list, tuple)):
        return ()
    subs = [nested_shape(e, name) for e in x]
    if subs and any(s != subs[0] for s in subs):
        shapes = ", ".join(str(s) for s in subs[:8]) + (", …" if len(subs) > 8 else "")
        raise ValueError(
            f"{name} must be rectangular (every row the same length), got a ragged {type(x).__name__}: "
            f"entries of shapes {shapes}"
        )
    return (len(x),) + (subs[0] if subs else ())


def as_matrix(
    x: Any,
    name: str,
    shape: tuple[int | None, int | None] | None = None,
    symbolic: bool | None = None,
    real_symbols: bool = True,
):
    """``x`` as a 2-D SymPy Matrix (symbolic) or float array (numeric), shape-checked.

    ``shape`` entries of ``None`` accept any size along that axis.
    """
    if symbolic is None:
        symbolic = is_symbolic(x)
    if isinstance(x, (str, bytes)) or x is None or isinstance(x, numbers.Number):
        raise TypeError(f"{name} must be a matrix of shape {_fmt_shape(shape)}, got {describe(x)}")
    if isinstance(x, sp.MatrixBase):
        rows = [[x[i, j] for j in range(x.cols)] for i in range(x.rows)]
        got_shape = x.shape
    else:
        nested_shape(x, name)  # a ragged list is named as such
        try:
            arr = np.asarray(x, dtype=object)
        except Exception:
            raise TypeError(f"{name} must be a matrix of shape {_fmt_shape(shape)}, got {describe(x)}") from None
        if arr.ndim != 2:
            raise ValueError(f"{name} must be a matrix of shape {_fmt_shape(shape)}, got {describe(x)}")
        rows = arr.tolist()
        got_shape = arr.shape
    if shape is not None:
        for want, got in zip(shape, got_shape):
            if want is not None and want != got:
                raise ValueError(f"{name} must be a matrix of shape {_fmt_shape(shape)}, got {describe(x)}")
    rows = [[_check_scalar(e, name, symbolic, real_symbols) for e in row] for row in rows]
    if symbolic:
        return sp.Matrix(rows) if rows else sp.zeros(*got_shape)
    return np.array(rows, dtype=float).reshape(got_shape)


def as_vector(x: Any, name: str, length: int | None = None, symbolic: bool | None = None, real_symbols: bool = True):
    """``x`` as a column: SymPy Matrix (k×1) when symbolic, 1-D float array otherwise.

    Accepts a flat sequence, a 1-D array, or a column/row matrix.
    """
    if symbolic is None:
        symbolic = is_symbolic(x)
    want = f"a vector of length {length}" if length is not None else "a vector"
    if isinstance(x, (str, bytes)) or x is None or isinstance(x, (numbers.Number, sp.Basic)):
        raise TypeError(f"{name} must be {want}, got {describe(x)}")
    if isinstance(x, sp.MatrixBase):
        if 1 not in x.shape:
            raise ValueError(f"{name} must be {want}, got {describe(x)}")
        items = list(x)
    else:
        nested_shape(x, name)
        try:
            arr = np.asarray(x, dtype=object)
        except Exception:
            raise TypeError(f"{name} must be {want}, got {describe(x)}") from None
        if arr.ndim == 2 and 1 in arr.shape:
            arr = arr.reshape(-1)
        if arr.ndim != 1:
            raise ValueError(f"{name} must be {want}, got {describe(x)}")
        items = arr.tolist()
    if length is not None and len(items) != length:
        raise ValueError(f"{name} must be {want}, got {describe(x)} with {len(items)} entries")
    items = [_check_scalar(e, name, symbolic, real_symbols) for e in items]
    if symbolic:
        return sp.Matrix(items)
    return np.array(items, dtype=float)


def as_screw_list(Slist: Any, name: str = "Slist", symbolic: bool | None = None, real_symbols: bool = True):
    """A screw list as a 6×n matrix: accepts 6×n (one screw per column) or a sequence of n 6-vectors."""
    if symbolic is None:
        symbolic = is_symbolic(Slist)
    want = "a 6×n matrix (one screw axis [ω; v] per column) or a sequence of n 6-vectors"
    if isinstance(Slist, (str, bytes)) or Slist is None or isinstance(Slist, (numbers.Number, sp.Basic)):
        raise TypeError(f"{name} must be {want}, got {describe(Slist)}")
    if isinstance(Slist, sp.MatrixBase):
        if Slist.rows != 6:
            raise ValueError(f"{name} must be {want}, got {describe(Slist)}")
        return as_matrix(Slist, name, (6, None), symbolic, real_symbols)
    if isinstance(Slist, np.ndarray) and Slist.ndim == 2:
        if Slist.shape[0] != 6:
            raise ValueError(f"{name} must be {want}, got {describe(Slist)}")
        return as_matrix(Slist, name, (6, None), symbolic, real_symbols)
    if isinstance(Slist, (list, tuple)):
        if len(Slist) == 0:
            raise ValueError(f"{name} must be {want}, got an empty {type(Slist).__name__}")
        cols = [as_vector(s, f"{name}[{i}]", 6, symbolic, real_symbols) for i, s in enumerate(Slist)]
        if symbolic:
            return sp.Matrix.hstack(*cols)
        return np.column_stack(cols)
    if isinstance(Slist, np.ndarray) and Slist.ndim == 1 and Slist.shape == (6,):
        return as_matrix(Slist.reshape(6, 1), name, (6, 1), symbolic, real_symbols)
    raise TypeError(f"{name} must be {want}, got {describe(Slist)}")


def as_thetas(thetas: Any, n: int, name: str = "thetas", symbolic: bool | None = None, real_symbols: bool = True):
    """n joint values (numbers or SymPy expressions) as a flat list (symbolic) or float array."""
    if symbolic is None:
        symbolic = is_symbolic(thetas)
    if isinstance(thetas, (numbers.Number, sp.Basic)) and not isinstance(thetas, bool) and n == 1:
        thetas = [thetas]
    v = as_vector(thetas, name, n, symbolic, real_symbols)
    return list(v) if symbolic else v


def _fmt_shape(shape) -> str:
    if shape is None:
        return "(any)"
    return "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"


def real_array(x, name: str, want: str) -> np.ndarray:
    """``x`` as a float array after refusing str/bytes/None/bool/complex entries and NaN/±inf.

    ``want`` describes the expected value for the error message (e.g. "a 3×3 rotation matrix").
    Shapes are checked by the caller.
    """
    if isinstance(x, (str, bytes)) or x is None or isinstance(x, (bool, np.bool_, numbers.Number)):
        raise TypeError(f"{name} must be {want}, got {describe(x)}")
    if isinstance(x, (list, tuple)):  # NumPy would turn [True, 2.0] into [1.0, 2.0]: look at the entries first
        stack = [x]
        while stack:
            for e in stack.pop():
                if isinstance(e, (list, tuple, np.ndarray)):
                    stack.append(e)
                elif (
                    isinstance(e, (bool, np.bool_, str, bytes, complex, np.complexfloating))
                    or e is None
                    or not isinstance(e, (numbers.Real, np.integer, np.floating))
                ):
                    raise TypeError(f"{name} must hold real numbers, got an entry {describe(e)} in {describe(x)}")
    try:
        a = np.asarray(x)
    except Exception:
        raise TypeError(f"{name} must be {want}, got {describe(x)}") from None
    if a.dtype.kind == "b":
        raise TypeError(f"{name} must hold real numbers, got booleans ({describe(x)})")
    if a.dtype.kind == "c":
        raise TypeError(f"{name} must hold real numbers, got complex numbers ({describe(x)})")
    if a.dtype.kind not in "iuf":
        for e in a.reshape(-1):
            if (
                isinstance(e, (str, bytes, bool, np.bool_, complex, np.complexfloating))
                or e is None
                or not isinstance(e, (numbers.Real, np.integer, np.floating))
            ):
                raise TypeError(f"{name} must hold real numbers, got an entry {describe(e)}")
            within_float_range(e, name)
        a = a.astype(float)
    a = a.astype(float, copy=False)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must hold finite real numbers, got NaN or ±inf in {describe(x)}")
    return a


def joint_symbols(thetas: Any, n: int | None = None, name: str = "thetas", per: str = "one per joint") -> tuple:
    """The joint variables: ``n`` (any number when None) distinct SymPy symbols declared real.

    A single Symbol or a SymPy column is accepted as a sequence. Refused with a message naming ``name``:
    strings, non-symbols, the wrong count, repeats, symbols without ``real=True`` (joint values are real).
    """
    if isinstance(thetas, sp.Symbol):
        thetas = (thetas,)
    if isinstance(thetas, sp.MatrixBase):
        thetas = list(thetas)
    count = f"{n} " if n is not None else ""
    if isinstance(thetas, np.ndarray) and thetas.ndim == 0:
        raise TypeError(
            f"{name} must be a sequence of {count}SymPy symbols ({per}), got a 0-d array {thetas!r}: "
            f"give a list such as [theta1, theta2]"
        )
    if isinstance(thetas, (str, bytes)) or not isinstance(thetas, (list, tuple, np.ndarray)):
        raise TypeError(f"{name} must be a sequence of {count}SymPy symbols ({per}), got {describe(thetas)}")
    thetas = tuple(thetas)
    if not all(isinstance(t, sp.Symbol) for t in thetas):
        raise TypeError(
            f"{name} must be a sequence of {count}SymPy symbols ({per}), got {describe(list(thetas))}: "
            f"{', '.join(map(repr, thetas))[:120]}"
        )
    if n is not None and len(thetas) != n:
        raise ValueError(
            f"{name} must be {count}SymPy symbols ({per}), got {describe(list(thetas))}: "
            f"{', '.join(map(repr, thetas))[:120]}"
        )
    if len(set(thetas)) != len(thetas):
        raise ValueError(f"{name} must hold distinct symbols, got {', '.join(map(str, thetas))}")
    for i, t in enumerate(thetas):
        if t.is_real is not True:
            raise ValueError(
                f"{name}[{i}] must be a real symbol (sp.Symbol({str(t)!r}, real=True)): joint values "
                f"are real, got the symbol {t} with no real assumption (declared real) in "
                f"{name} = ({', '.join(map(str, thetas))})"
            )
    return thetas


def as_scalar(x, name: str, symbolic: bool):
    """A joint value / pitch: exact (symbolic; 0.1 → 1/10) or a finite float; anything else refused."""
    if symbolic:
        if isinstance(x, sp.Basic) and not isinstance(x, sp.Float):
            if not isinstance(x, sp.Expr):
                raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}")
            return check_real_finite(exact_floats(x, name), name)
        return exact_number(x, name)
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Real, np.integer, np.floating)):
        if isinstance(x, (complex, np.complexfloating)):
            raise TypeError(f"{name} must be a real number, got the complex number {x!r}")
        raise TypeError(f"{name} must be a number or a SymPy expression, got {describe(x)}")
    x = within_float_range(x, name)
    if not math.isfinite(x):
        raise ValueError(f"{name} must be a finite real number, got {x!r}")
    return x


def as_jacobian(J: Any, name: str = "J", symbolic: bool | None = None):
    """J as a 2-D SymPy Matrix (symbolic) or float array; a clear error for anything else."""
    if not isinstance(J, (sp.MatrixBase, np.ndarray, list, tuple)):
        raise TypeError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    if isinstance(J, np.ndarray) and J.ndim != 2:
        raise ValueError(f"{name} must be a matrix (m×n Jacobian), got {describe(J)}")
    return as_matrix(J, name, None, symbolic)


def numeric_jacobian(J: Any, name: str = "J") -> np.ndarray:
    """J as floats, shape (m, n) or a batch (N, m, n), m, n ≥ 1; refuses non-real entries and NaN/±inf."""
    A = real_array(J, name, "a Jacobian (m, n) or a batch (N, m, n) of real numbers")
    if A.ndim not in (2, 3) or 0 in A.shape:
        raise ValueError(f"{name} must be a Jacobian (m, n) or a batch (N, m, n) with m, n ≥ 1, got {describe(J)}")
    return A


def numeric_vectors(x: Any, name: str, m: int, what: str) -> np.ndarray:
    """x as floats, one vector (m,) or a batch (N, m), matching a Jacobian; ``what`` names it in errors."""
    a = real_array(x, name, f"{what} of length {m} (or a batch (N, {m}))")
    if a.ndim not in (1, 2) or a.shape[-1] != m:
        raise ValueError(f"{name} must be {what} of length {m} (or a batch (N, {m})) to match J, got {describe(x)}")
    return a


def exact_jacobian(J: Any, name: str = "J") -> sp.Matrix:
    """J as a SymPy Matrix with at least one row and one column; floats become the decimals typed."""
    M = as_matrix(J, name, None, True)
    if M.rows == 0 or M.cols == 0:
        raise ValueError(f"{name} must have at least one row and one column, got {describe(M)}")
    return M.applyfunc(lambda e: exact_number(e, name))  # Floats → the decimal typed; refuses I, nan, oo
