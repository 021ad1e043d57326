"""What every answer kind shares: "not answered", yes/no, type names, and the numeric equality of values.

The kind modules (:mod:`.expr`, :mod:`.subspace`, :mod:`.sets`, :mod:`.choice`, :mod:`.properties`; their table
is :mod:`.kinds`) build on these. A description of an answer (a kind's ``describe``) is a dict with a ``tag``:
the kind's own tags, or one of :data:`NOT_ANSWERED`'s, which every comparer reads the same way
(:func:`not_answered`). Values at points travel as ``[re, im]`` pairs (``None``: not a finite number);
:func:`close` is the one numeric equality: never true for a non-finite value.

It imports only the standard library, NumPy and SymPy (it runs in the student's notebook too).
"""

from __future__ import annotations

import math
import numbers
import random

import numpy as np
import sympy as sp

__all__ = [
    "is_unanswered",
    "is_bool",
    "as_sympy",
    "type_name",
    "close",
    "values_array",
    "to_complex",
    "subs_for",
    "extra_value",
    "not_answered",
    "symbol_notes",
    "fmt_shape",
    "NOT_ANSWERED",
    "ANGLE_PREFIXES",
    "DOMAINS",
    "is_angle_name",
    "symbol_domain",
    "RTOL",
    "ATOL",
]

RTOL, ATOL = 1e-6, 1e-8

# Where the symbols of an answer are evaluated: the one rule for the grader's secret points
# (kinlib.course.grader.grade.make_points) and the self-check's public ones (kinlib.course.workbook.selfcheck),
# so that a wrong answer cannot be right at home and wrong in the grade (|sin θ| for sin θ, a signed
# manipulability): joint angles over a whole turn, across every sign change; lengths (positive symbols) in
# (0.5, 2); other signed quantities (forces, velocities) on both sides of 0.
ANGLE_PREFIXES = ("theta", "q", "phi", "alpha", "beta", "gamma")
DOMAINS = {"angle": (-math.pi, math.pi), "positive": (0.5, 2.0), "signed": (-1.5, 1.5)}


def is_angle_name(name: str) -> bool:
    """Whether a symbol of this name is a joint angle (evaluated over a whole turn).

    >>> is_angle_name("theta2"), is_angle_name("thetadot1"), is_angle_name("L1")
    (True, True, False)
    """
    return str(name).startswith(ANGLE_PREFIXES)


def symbol_domain(name: str, positive: bool) -> tuple[str, tuple[float, float]]:
    """The domain a symbol is evaluated over by both judges: ``("positive", (0.5, 2))`` for a symbol the reference
    declares positive (a length), ``("angle", (-π, π))`` for a joint angle's name, else ``("signed", (-1.5, 1.5))``.

    >>> symbol_domain("L", True)[0], symbol_domain("theta1", False)[0], symbol_domain("F_x", False)
    ('positive', 'angle', ('signed', (-1.5, 1.5)))
    """
    key = "positive" if positive else "angle" if is_angle_name(name) else "signed"
    return key, DOMAINS[key]


NOT_ANSWERED = {
    "missing": "is not defined after your notebook ran (never assigned, deleted, or its cell failed)",
    "ellipsis": "is still `...`: not answered yet",
    "none": "is None",
    "bool": "is True/False (an equation sp.Eq(...) or a comparison?); expected a SymPy expression or matrix",
    "empty": "is an empty list",
    "ragged": "is a list of vectors of different lengths",
    "array": "is an array with more than 2 dimensions",
    "probe-error": "could not be read",
    "too-large": "is too large to grade",
    "unreadable": "could not be read as an answer",
}


def is_unanswered(value) -> bool:
    """True for an answer not given yet: ``...`` (the workbook's stub) or ``None``.

    >>> is_unanswered(...), is_unanswered(None), is_unanswered(0)
    (True, True, False)
    """
    return value is Ellipsis or value is None


def is_bool(value) -> bool:
    """True for a yes/no answer: Python, NumPy or SymPy True/False.

    >>> is_bool(True), is_bool(np.bool_(False)), is_bool(sp.true), is_bool(1)
    (True, True, True, False)
    """
    return isinstance(value, (bool, np.bool_)) or value is sp.true or value is sp.false


def as_sympy(value):
    """``value`` as a SymPy object **without parsing anything**: SymPy objects as they are (a matrix as an
    immutable one), Python and NumPy numbers and bools converted (``sympify(strict=True)``), tuples and lists
    as SymPy ``Tuple`` s of the same; anything else, above all a string (which ``sympify`` would parse, i.e.
    ``eval``), raises TypeError. Every conversion of a container's entries on the trusted side goes through it.

    >>> as_sympy(np.float64(0.5)), as_sympy((1, sp.pi)), as_sympy(sp.Symbol("x"))
    (0.500000000000000, (1, pi), x)
    >>> as_sympy("__import__('os').system('id')")
    Traceback (most recent call last):
    ...
    TypeError: expected a number or SymPy value, not a str
    """
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, sp.MatrixBase):
        return value.as_immutable()
    if isinstance(value, (bool, np.bool_, numbers.Number, np.number)) and not isinstance(value, (str, bytes)):
        try:
            return sp.sympify(value.item() if isinstance(value, np.generic) else value, strict=True)
        except (sp.SympifyError, TypeError, ValueError) as exc:
            raise TypeError(f"expected a number or SymPy value, not a {type(value).__name__}") from exc
    if isinstance(value, (tuple, list)):
        return sp.Tuple(*[as_sympy(v) for v in value])
    raise TypeError(f"expected a number or SymPy value, not a {type(value).__name__}")


def type_name(value) -> str:
    """The type of ``value`` as students know it (``Matrix``'s module spelled out, builtins bare; an object that
    crossed from a kernel as its type name only, :class:`kinlib.course.answers.wire.Other`, by that name).

    >>> type_name(3), type_name(sp.Integer(3))
    ('int', 'sympy.core.numbers.Integer')
    """
    if type(value).__name__ == "Other" and isinstance(getattr(value, "type_name", None), str):
        return value.type_name
    t = type(value)
    return f"{t.__module__}.{t.__qualname__}" if t.__module__ not in ("builtins",) else t.__qualname__


def close(a, b) -> bool:
    """Equal within RTOL/ATOL, entry by entry; never for a non-finite value (|inf - x| <= inf is not equality).

    >>> close(np.array([1.0]), np.array([1.0 + 1e-9])), close(np.array([np.inf]), np.array([1.0]))
    (True, False)
    """
    a, b = np.asarray(a), np.asarray(b)
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        return False
    return bool(np.all(np.abs(a - b) <= ATOL + RTOL * np.maximum(np.abs(a), np.abs(b))))


def values_array(values) -> np.ndarray:
    """``[[ [re, im] | None per entry ] per point]`` as a complex array (points, entries), NaN for None.

    >>> v = values_array([[[1.0, 0.0], None]])
    >>> v.shape, complex(v[0, 0]), bool(np.isnan(v[0, 1]))
    ((1, 2), (1+0j), True)
    """
    out = np.full((len(values), len(values[0]) if values else 0), np.nan + 0j, dtype=complex)
    for i, row in enumerate(values):
        for j, v in enumerate(row):
            if v is not None:
                out[i, j] = complex(float(v[0]), float(v[1]))
    return out


def to_complex(e):
    """A SymPy number (or expression that evaluates to one) as ``[re, im]``; None when it is not a finite number.

    >>> to_complex(sp.sqrt(-4)), to_complex(sp.oo), to_complex(sp.Symbol("x"))
    ([0.0, 2.0], None, None)
    """
    e = as_sympy(e)
    if not e.is_number:
        e = e.evalf(20)
        if not e.is_number:
            return None
    c = complex(e.evalf(20))
    if not (math.isfinite(c.real) and math.isfinite(c.imag)):
        return None
    return [c.real, c.imag]


def extra_value(seed, name: str) -> float:
    """The value a symbol the reference does not have (no point names it) takes: fixed per seed and name.

    >>> extra_value(1, "y") == extra_value(1, "y") and 0.5 <= extra_value(1, "y") <= 2.0
    True
    """
    return random.Random(f"{seed}:{name}").uniform(0.5, 2.0)


def subs_for(obj, point: dict, seed) -> dict:
    """{symbol: Float} putting ``obj``'s symbols at ``point`` (by name; others at :func:`extra_value`).

    >>> subs_for(sp.Symbol("x") + 1, {"x": 0.5}, 0)
    {x: 0.50000000000000000000}
    """
    subs = {}
    for s in getattr(obj, "free_symbols", set()):
        if isinstance(s, sp.Symbol):
            v = point.get(s.name)
            subs[s] = sp.Float(v if v is not None else extra_value(seed, s.name), 20)
    return subs


def not_answered(desc: dict) -> str | None:
    """The words for a description that is not an answer (its tag one of :data:`NOT_ANSWERED`), or None.

    >>> not_answered({"tag": "too-large", "error": "more than 100000 nodes"}), not_answered({"tag": "matrix"})
    ('is too large to grade (more than 100000 nodes)', None)
    """
    tag = desc.get("tag")
    if tag in NOT_ANSWERED:
        msg = NOT_ANSWERED[tag]
        if tag in ("probe-error", "too-large", "unreadable") and desc.get("error"):
            msg += f" ({desc['error']})"
        return msg
    return None


def symbol_notes(stu: dict, ref: dict) -> list[str]:
    """What the student's symbols tell about their answer: a missing or an extra variable (names only of the
    student's own symbols and of the problem's, never a value).

    >>> symbol_notes({"symbols": ["theta1"]}, {"symbols": ["L", "theta1"]})
    ['does not depend on L (a missing variable: did you substitute a number?)']
    """
    rs, ss = set(ref.get("symbols", [])), set(stu.get("symbols", []))
    notes = []
    missing, extra = sorted(rs - ss), sorted(ss - rs)
    if missing and not ss:
        notes.append(f"is a constant, but the answer depends on {', '.join(sorted(rs))}")
    elif missing:
        notes.append(f"does not depend on {', '.join(missing)} (a missing variable: did you substitute a number?)")
    if extra:
        known = ", ".join(sorted(rs)) or "no symbols"
        notes.append(f"uses {', '.join(extra)}, which the problem does not (the answer is in terms of {known})")
    return notes


def fmt_shape(shape) -> str:
    """A shape for a message: "6×3", or "a scalar".

    >>> fmt_shape([6, 3]), fmt_shape([])
    ('6×3', 'a scalar')
    """
    return "a scalar" if not shape else "×".join(str(s) for s in shape)
