"""Named mistakes: the known ways a right answer goes wrong, each with the transform that undoes it.

Shared by the instructor checker (:func:`kinlib.course.answers.expr.compare_expr`, which compares numbers) and
the workbook self-check (:mod:`kinlib.course.workbook.selfcheck`, which compares salted fingerprints): both take
the student's answer, undo one known mistake (or two of the simple ones) and ask "is *this* the right
answer?". The first yes names the mistake. Each :class:`Mistake` has

- ``name``: a short id (``"negated"``, ``"transposed"``, ``"vw-order"``, ``"columns"``, ``"rows"``,
  ``"degrees"``, ``"complement"``, ``"zero-based"``);
- ``says``: the student-facing words that complete "<answer> ...", e.g. "is transposed (rows and columns
  swapped)"; they name the mistake and never show a value of the answer;
- ``candidates(A)``: the candidate right answers, as ``(detail, array)`` pairs, for the student's values
  ``A`` (an array whose last two axes are rows and columns; NumPy numbers or SymPy numbers in an object
  array: the transforms only move, negate and scale entries).

Angle sets (:data:`SET_MISTAKES`) undo a mistake point by point (:func:`map_set`), choices
(:data:`CHOICE_MISTAKES`) value by value; :func:`trig_degrees` rewrites degrees written inside sin/cos.

*What it tells the student.* A self-check that says "your matrix is the transpose of the answer" tells
only that the transpose of what they typed is right; the student could have typed the transpose and
asked the plain self-check the same question. So the named mistakes add no information beyond saving
tries, and the messages hold no numbers of the answer (tests/course/test_selfcheck.py checks this).

>>> import numpy as np
>>> R = np.arange(6.0).reshape(1, 2, 3)       # one sample point, a 2×3 matrix
>>> found = search(-R, lambda X: X.shape == R.shape and np.allclose(X, R))
>>> found.name, found.says
('negated', 'has the wrong sign (every entry is negated)')
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import sympy as sp

__all__ = [
    "Mistake",
    "Found",
    "MATRIX_MISTAKES",
    "SUBSPACE_MISTAKES",
    "SET_MISTAKES",
    "CHOICE_MISTAKES",
    "CONCEPT_MISTAKES",
    "SYMBOLIC_MISTAKES",
    "FRAME_MISTAKES",
    "SQUARE_MISTAKES",
    "invariants_for",
    "Invariant",
    "jacobian_like",
    "is_force_name",
    "SET_VARIABLE",
    "ROUNDED",
    "DECIMALS",
    "FLOAT_RTOL",
    "PRODUCT_ORDER",
    "ROUNDED_RTOL",
    "exact_value",
    "exact_values",
    "concept_says",
    "search",
    "map_set",
    "trig_degrees",
    "shape_says",
    "DEGREE_CONSTANTS",
]

DEGREE_CONSTANTS = frozenset(
    {15, 30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 180, 210, 225, 240, 270, 300, 315, 330, 360}
)


@dataclass(frozen=True)
class Mistake:
    """A known mistake: its id, what to tell the student, and the candidate right answers it suggests.

    >>> MATRIX_MISTAKES[1].name, MATRIX_MISTAKES[1].message()
    ('transposed', 'is transposed (rows and columns swapped)')
    """

    name: str
    says: str
    candidates: Callable[..., Iterator]
    simple: bool = True  # may be combined with another simple mistake

    def message(self, detail: str = "") -> str:
        """The student-facing words, with the detail (e.g. which columns moved) when there is one."""
        return self.says.format(detail=detail) if "{detail}" in self.says else self.says


@dataclass(frozen=True)
class Found:
    """The mistake(s) found: ``name`` ("transposed" or "transposed+negated") and ``says``.

    >>> Found("negated", "has the wrong sign (every entry is negated)").name
    'negated'
    """

    name: str
    says: str


# ----------------------------------------------------------------------------- matrices and expressions


def _rows(A, order):
    return A[..., list(order), :]


def _cols(A, order):
    return A[..., :, list(order)]


def _scale(A, exact, approx):
    """A times a constant: SymPy's 30-digit value for object arrays (self-check), a float otherwise."""
    return A * (sp.Float(exact.evalf(40), 40) if A.dtype == object else approx)


def _negated(A):
    yield ("" if A.shape[-2:] == (1, 1) else " (every entry is negated)"), -A


def _transposed(A):
    if A.shape[-1] > 1 or A.shape[-2] > 1:
        yield "", np.swapaxes(A, -1, -2)


def _vw_order(A):
    r = A.shape[-2]
    if r == 6:  # [v; ω] -> [ω; v]
        yield "6", _rows(A, (3, 4, 5, 0, 1, 2))
    elif r == 3:  # planar task rows (v_x, v_y, ω_z) -> (ω_z, v_x, v_y)
        yield "3", _rows(A, (2, 0, 1))


def _permutations(n: int, exhaustive: bool):
    """Non-identity permutations of n items, fewest moved first (all of them for small n)."""
    if n < 2:
        return []
    if n <= (6 if exhaustive else 4):
        perms = [p for p in itertools.permutations(range(n)) if list(p) != list(range(n))]
    else:  # two items swapped
        perms = []
        for i, j in itertools.combinations(range(n), 2):
            p = list(range(n))
            p[i], p[j] = j, i
            perms.append(tuple(p))
    return sorted(perms, key=lambda p: (sum(i != j for i, j in enumerate(p)), p))


def _moved(perm, what):
    return ", ".join(f"your {what} {i + 1} is {what} {j + 1}" for i, j in enumerate(perm) if i != j)


def _columns(A, exhaustive=False):
    for p in _permutations(A.shape[-1], exhaustive):  # student column i is the answer's column p[i]
        yield _moved(p, "column"), _cols(A, np.argsort(p))


def _rows_perm(A, exhaustive=False):
    for p in _permutations(A.shape[-2], exhaustive):
        yield _moved(p, "row"), _rows(A, np.argsort(p))


def _degrees(A):
    yield "", _scale(A, sp.pi / 180, math.pi / 180)


_VW_SAYS = {
    "6": "has the rows in [v; ω] order: the textbook stacks angular first, [ω; v] (rows 1–3 angular, rows 4–6 linear)",
    "3": "has the rows in (v_x, v_y, ω_z) order: the planar task rows are (ω_z, v_x, v_y), angular first",
}


class _VwMistake(Mistake):
    def message(self, detail: str = "") -> str:
        return _VW_SAYS.get(detail, _VW_SAYS["6"])


MATRIX_MISTAKES = (
    Mistake("negated", "has the wrong sign{detail}", _negated),
    Mistake("transposed", "is transposed (rows and columns swapped)", _transposed),
    _VwMistake("vw-order", "", _vw_order),
    Mistake("columns", "has its columns swapped: {detail} (column i belongs to joint i)", _columns, simple=False),
    Mistake("rows", "has its rows swapped: {detail}", _rows_perm, simple=False),
    Mistake(
        "degrees",
        "looks like it is in degrees: SymPy and NumPy angles are radians (multiply degrees by sp.pi/180)",
        _degrees,
    ),
)


def search(A, matches: Callable, mistakes=MATRIX_MISTAKES, pairs: bool = True, exhaustive: bool = False):
    """The first mistake whose undoing makes ``A`` right (``matches(candidate)`` is True), or None.

    Single mistakes first, in the order of ``mistakes``; then, with ``pairs``, two simple ones (e.g.
    transposed and negated). ``exhaustive`` tries every permutation of up to 6 rows or columns (the
    checker compares numbers: cheap), else up to 4 and then only two swapped (the self-check hashes).

    >>> R = np.array([[[1.0, 2.0], [3.0, 4.0]]])
    >>> search(-R.transpose(0, 2, 1), lambda X: np.allclose(X, R)).name
    'negated+transposed'
    >>> search(R + 1, lambda X: np.allclose(X, R)) is None
    True
    """

    def cands(m, X):
        if m.name in ("columns", "rows"):
            return m.candidates(X, exhaustive=exhaustive)
        return m.candidates(X)

    for m in mistakes:
        for detail, C in cands(m, A):
            if matches(C):
                return Found(m.name, m.message(detail))
    if not pairs:
        return None
    simple = [m for m in mistakes if m.simple]
    for a, b in itertools.combinations(simple, 2):
        for da, X in cands(a, A):
            for db, C in cands(b, X):
                if matches(C):
                    return Found(f"{a.name}+{b.name}", f"{a.message(da)}, and {b.message(db)}")
    return None


def shape_says(yours: tuple, expected: tuple) -> str:
    """Words for a wrong shape (the "wrong shape" mistake), naming a transposed shape as such.

    >>> shape_says((3, 6), (6, 3))
    'is transposed: yours is 3×6, expected 6×3 (one column per joint)'
    >>> shape_says((4, 1), (2, 2))
    'has the wrong shape: yours is 4×1, expected 2×2'
    """

    def words(s):
        return "a scalar" if not s else "×".join(map(str, s))

    if len(yours) == 2 and tuple(yours)[::-1] == tuple(expected):
        tail = " (one column per joint)" if expected[0] == 6 else ""
        return f"is transposed: yours is {words(yours)}, expected {words(expected)}{tail}"
    return f"has the wrong shape: yours is {words(yours)}, expected {words(expected)}"


def trig_degrees(expr):
    """``expr`` with degree constants inside sin/cos/tan (``sin(θ + 45)``) turned into radians, or None
    when it has none (the "degrees inside trig" mistake, for SymPy answers).

    >>> t = sp.Symbol("theta")
    >>> trig_degrees(sp.sin(t + 45))
    sin(theta + pi/4)
    >>> trig_degrees(sp.sin(t + sp.pi / 4)) is None
    True
    """
    trig = (sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc)
    if not hasattr(expr, "atoms"):
        return None
    changed = False

    def fix(arg):
        nonlocal changed
        reps = {}
        for n in arg.atoms(sp.Number):
            try:
                if abs(n) in DEGREE_CONSTANTS:
                    reps[n] = n * sp.pi / 180
            except TypeError:
                pass
        if reps:
            changed = True
            return arg.xreplace(reps)
        return arg

    out = expr.replace(lambda e: isinstance(e, trig), lambda e: e.func(fix(e.args[0])))
    return out if changed else None


# ----------------------------------------------------------------------------- subspaces (numeric bases)


def _complement(A):
    """Orthonormal bases of the orthogonal complements of the spans of A[k] (float arrays (P, m, n))."""
    out = []
    for B in A:
        m = B.shape[0]
        if B.size == 0 or np.abs(B).max() < 1e-12:
            out.append(np.eye(m))
            continue
        U, s, _ = np.linalg.svd(B)
        r = int((s > 1e-9 * max(1.0, s[0])).sum())
        out.append(U[:, r:] if r < m else np.zeros((m, 1)))
    return out


def _sub_complement(A):
    yield "", _complement(A)


def _sub_rows_as_vectors(A):
    yield "", np.swapaxes(A, -1, -2)


SUBSPACE_MISTAKES = (
    Mistake("vectors-as-rows", "gives the vectors as rows: put one vector per column", _sub_rows_as_vectors),
    _VwMistake("vw-order", "", _vw_order),
    Mistake(
        "complement",
        "spans the orthogonal complement of the asked subspace (the directions asked for and the others swapped?)",
        _sub_complement,
    ),
)


# ----------------------------------------------------------------------------- sets of angles and choices


def map_set(s, f):
    """The set ``{f(x) : x in s}`` for a SymPy set of angles (finite, intervals, image sets, unions).

    >>> map_set(sp.FiniteSet(45, 135), lambda x: x * sp.pi / 180)
    {pi/4, 3*pi/4}
    >>> n = sp.Symbol("n", integer=True)
    >>> map_set(sp.ImageSet(sp.Lambda(n, 180 * n + 135), sp.Integers), lambda x: x * sp.pi / 180)
    ImageSet(Lambda(n, pi*n + 3*pi/4), Integers)
    """
    if s is sp.S.EmptySet:
        return s
    if isinstance(s, sp.FiniteSet):
        return sp.FiniteSet(*[sp.Tuple(*map(f, p)) if isinstance(p, (sp.Tuple, tuple)) else f(p) for p in s])
    if isinstance(s, sp.Union):
        return sp.Union(*[map_set(a, f) for a in s.args])
    if isinstance(s, sp.Interval):
        a, b = sorted([f(s.start), f(s.end)], key=lambda x: float(x) if x.is_number else 0.0)
        return sp.Interval(a, b)
    if isinstance(s, sp.ImageSet):
        lam = s.lamda
        return sp.ImageSet(sp.Lambda(lam.variables, sp.expand(f(lam.expr))), *s.base_sets)
    x = sp.Dummy("x")
    return sp.imageset(sp.Lambda(x, f(x)), s)


# Not a set mistake: "each value is minus a right one". Another part's answer is often the negation of this
# one's (5.4's maximisers are 5.1's singular angles negated, modulo 2π), and naming it would state one part's
# answer in the feedback on another: a negated set is just "not the right set".
SET_MISTAKES = (
    Mistake(
        "degrees",
        "looks like degrees: angles are radians (multiply degrees by sp.pi/180)",
        lambda s: iter([("", map_set(s, lambda x: x * sp.pi / 180))]),
    ),
)
SET_VARIABLE = Mistake(  # the right set on the wrong variable (both judges re-key a one-variable condition)
    "variable",
    "holds the right values, but as a condition on another joint variable: which joint does the condition restrict?",
    lambda s: iter(()),
)


def _plus_one(x):
    if isinstance(x, list):
        return [_plus_one(e) for e in x]
    return x + 1 if isinstance(x, int) and not isinstance(x, bool) else x


# ----------------------------------------------------------------------------- the course's conceptual mistakes
# Each names a mistake the course is about, in words that hold no value of any answer (of this part or another):
# tests/course/test_grade_verdicts.py renders them for every answer of the table and scans them.


def _reciprocal(A):
    vals = np.asarray(A)
    try:
        nonzero = bool(np.all(np.abs(vals.astype(complex)) > 1e-12))
    except (TypeError, ValueError):
        nonzero = all(x != 0 for x in vals.ravel())
    if nonzero:
        yield "", (1 / A if vals.dtype != object else np.vectorize(lambda x: 1 / x, otypes=[object])(A))


def _sign_patterns(A):
    """A scalar answer negated at some of the points only (not all, not none): |·| missing or extra."""
    P = A.shape[0]
    if A.shape[-2:] != (1, 1) or P < 2 or P > 8:
        return
    for signs in itertools.product((1, -1), repeat=P):
        if len(set(signs)) == 2:
            yield "", A * np.array(signs, dtype=A.dtype).reshape(P, 1, 1)


CONCEPT_MISTAKES = (
    Mistake(
        "branch",
        "has the right size but the wrong sign at some configurations: an absolute value |·| missing or extra? "
        "(det J is signed; the manipulability √det(J Jᵀ) is never negative)",
        _sign_patterns,
    ),
    Mistake(
        "reciprocal",
        "is upside down (the reciprocal of the answer, entry by entry): a ratio of lengths taken the wrong way up, or "
        "the velocity ellipse's semi-axes σ for the force ellipse's 1/σ?",
        _reciprocal,
    ),
)


@dataclass(frozen=True)
class SymbolicMistake:
    """A mistake undone on the answer itself (a SymPy expression or matrix), before it is evaluated:
    ``undo(value)`` is the candidate right answer, or None when the mistake cannot be in it."""

    name: str
    says: str
    undo: Callable


def _swap_lengths(v):
    by_name = {s.name: s for s in getattr(v, "free_symbols", ()) if isinstance(s, sp.Symbol)}
    if "L1" in by_name and "L2" in by_name:
        return v.xreplace({by_name["L1"]: by_name["L2"], by_name["L2"]: by_name["L1"]})
    return None


def is_force_name(name: str) -> bool:
    """Whether a symbol of this name is a force component (F_x, Fy, f_z, F): what a statics answer maps.

    >>> [is_force_name(n) for n in ("F_x", "Fy", "f_z", "F", "F1", "theta1", "L")]
    [True, True, True, True, True, False, False]
    """
    return re.fullmatch(r"[Ff](_?[xyz0-9])?", str(name)) is not None


_FORCE_MAP_NODES = 2000  # nodes of an answer beyond which τ = J F is not looked for


def _larger_than(v, n: int) -> bool:
    count = 0
    for e in v:
        for _ in sp.preorder_traversal(e):
            count += 1
            if count > n:
                return True
    return False


def _force_map_transposed(v):
    """``Aᵀ F`` for an answer ``A F`` linear in the force components F with a square A (τ = J F for Jᵀ F), else
    None."""
    if not isinstance(v, sp.MatrixBase) or v.shape[1] != 1:
        return None
    forces = sorted(
        (s for s in v.free_symbols if isinstance(s, sp.Symbol) and is_force_name(s.name)), key=lambda s: s.name
    )
    if len(forces) != v.shape[0] or len(forces) < 2 or _larger_than(v, _FORCE_MAP_NODES):
        return None  # (a large answer is not expanded: this runs on the grader's side too)
    F = sp.Matrix(forces)
    A = v.jacobian(F)
    if A.free_symbols & set(forces) or sp.expand(v - A * F) != sp.zeros(*v.shape):
        return None  # not linear in the forces (or a constant term)
    return A.T * F


SYMBOLIC_MISTAKES = (
    SymbolicMistake(
        "degrees",
        "uses degrees inside sin/cos (e.g. sin(θ + 45)): angles are radians: multiply degrees by sp.pi/180",
        trig_degrees,
    ),
    SymbolicMistake("lengths", "has L1 and L2 swapped: which link is L1?", _swap_lengths),
    SymbolicMistake(
        "force-map",
        "maps the force with the matrix itself where its transpose belongs: joint torques from a tip force are "
        "τ = Jᵀ F (the transpose of J), not J F",
        _force_map_transposed,
    ),
)


# ----------------------------------------------------------------------------- which Jacobian (6-row matrices)
# Not undone but recognised: an answer whose invariant equals the reference's. The grader compares the invariant
# of the student's values with the reference's; the self-check compares hashes (the spec carries the reference's,
# kinlib.course.answers.expr.home_hints).


@dataclass(frozen=True)
class Invariant:
    """A property the right answer shares with a typical wrong one: ``of(A)`` for values ``A`` (points, rows,
    columns); equal invariants and unequal answers name the mistake.

    >>> J = np.arange(12.0).reshape(1, 6, 2)
    >>> [i.name for i in FRAME_MISTAKES if np.allclose(i.of(J), i.of(J * [[1], [1], [1], [0], [0], [0]]))]
    ['linear-rows']
    """

    name: str
    says: str
    of: Callable


def _angular_rows(A):
    return np.asarray(A, dtype=complex)[:, :3, :]


def _frame_gram(A):
    """The Gram matrix of the columns' angular and linear parts side by side: the same for J and R J per block."""
    A = np.asarray(A, dtype=complex)
    B = np.concatenate([A[:, :3, :], A[:, 3:, :]], axis=2)
    return np.einsum("pij,pik->pjk", B, B)


def _spectrum(A):
    """The eigenvalues of each symmetric A[k], ascending ((points, n, 1)); NaN where A[k] is not symmetric."""
    A = np.asarray(A, dtype=complex)
    out = np.full(A.shape[:2] + (1,), np.nan)
    for k, X in enumerate(A):
        if np.allclose(X, X.T, rtol=1e-9, atol=1e-12) and np.all(np.abs(X.imag) < 1e-12):
            out[k, :, 0] = np.linalg.eigvalsh(X.real)
    return out


def jacobian_like(shape) -> bool:
    """Whether an answer of this shape may be a Jacobian (or screw list) of twists: 6 rows, 2 columns or more.

    >>> jacobian_like((6, 3)), jacobian_like((6, 1)), jacobian_like((3, 3))
    (True, False, False)
    """
    return len(shape) == 2 and shape[0] == 6 and shape[1] >= 2


FRAME_MISTAKES = (
    Invariant(
        "frame",
        "is right up to a rotation of the axes its columns are written in: the geometric J = blockdiag(R, R) J_b is "
        "in the space frame's axes, the body Jacobian J_b in the end-effector frame's: which one is asked?",
        _frame_gram,
    ),
    Invariant(
        "linear-rows",
        "has the right angular rows (1–3) but not the linear rows (4–6): the Jacobians differ in their linear part "
        "(J_s: v_s, the velocity of the body point at the space origin; the geometric J: ṗ, the velocity of the "
        "end-effector's origin; J_b: v_b, in the end-effector frame): which one is asked?",
        _angular_rows,
    ),
)
SQUARE_MISTAKES = (  # a symmetric square answer (J Jᵀ, Jᵀ J of a square J: the same shape either way)
    Invariant(
        "product-order",
        "has the right eigenvalues but is not the matrix asked: J Jᵀ and Jᵀ J share their eigenvalues: "
        "the product in the other order?",
        _spectrum,
    ),
)


def invariants_for(shape) -> tuple:
    """The invariants (:class:`Invariant`) that name a mistake in an answer of this shape (rows, columns): which
    Jacobian for 6 rows, the product's order for a square matrix.

    >>> [i.name for i in invariants_for((6, 3))], [i.name for i in invariants_for((2, 2))], invariants_for((1, 1))
    (['frame', 'linear-rows'], ['product-order'], ())
    """
    if jacobian_like(shape):
        return FRAME_MISTAKES
    if len(shape) == 2 and shape[0] == shape[1] >= 2:
        return SQUARE_MISTAKES
    return ()


ROUNDED_RTOL = 5e-3  # decimals this close to the answer (3 significant digits) are "right up to rounding"
PRODUCT_ORDER = "J Jᵀ is task × task, Jᵀ J joints × joints: the product in the other order?"
FLOAT_RTOL = 5e-7  # decimals this close to exact values pass, with a note (the grader's RTOL is 1e-6 on values)
ROUNDED = Mistake(
    "rounded",
    "is right up to rounding: its decimals are rounded; use exact values (sp.sqrt, sp.pi, sp.Rational)",
    lambda v: iter(()),
)
DECIMALS = Mistake(
    "decimals",
    "contains decimals (floats): if they are rounded values, write them exactly (sp.sqrt(2), sp.pi, sp.Rational)",
    lambda v: iter(()),
)
_EXACT_BASES = (sp.Integer(1), sp.pi, sp.sqrt(2), sp.sqrt(3), sp.sqrt(6), 1 / sp.pi)


def exact_value(f: float, rtol: float = 5e-3):
    """The simplest exact value p/q·c (c ∈ 1, π, √2, √3, √6, 1/π; q ≤ 12) within ``rtol`` of ``f``, or None:
    what a rounded decimal in an answer stood for.

    >>> exact_value(0.707), exact_value(2.356), exact_value(0.333), exact_value(0.1234567)
    (sqrt(2)/2, 3*pi/4, 1/3, None)
    """
    f = float(f)
    if f == 0 or not math.isfinite(f):
        return sp.Integer(0) if f == 0 else None
    best = None
    for c in _EXACT_BASES:
        cv = float(c)
        for q in range(1, 13):
            p = round(f * q / cv)
            if p == 0 or abs(p) > 1000:
                continue
            err = abs(p * cv / q - f) / abs(f)
            if err <= rtol and (best is None or err < best[0] - 1e-12):
                best = (err, sp.Rational(p, q) * c)
        if best is not None and best[0] < 1e-9:
            break
    return None if best is None else best[1]


def exact_values(v):
    """``(v with each Float replaced by its exact value, the largest relative rounding error)``, or
    ``(None, inf)`` when some decimal stands for no simple exact value.

    >>> exact_values(sp.Float(0.7071068) * sp.Symbol("x"))
    (sqrt(2)*x/2, ...)
    """
    reps, err = {}, 0.0
    for f in v.atoms(sp.Float):
        e = exact_value(float(f))
        if e is None:
            return None, math.inf
        reps[f] = e
        if e != 0:
            err = max(err, abs(float(f) - float(e)) / abs(float(e)))
    return v.xreplace(reps), err


def concept_says(name: str, constant: bool, ref_constant: bool) -> str:
    """Words for a wrong constant answer (a rank, a count, a ratio): about constants, never a value.

    >>> concept_says("rank53", True, True)
    'is not the rank asked: the rank at the configuration the question gives, not the generic rank (the largest rank, reached almost everywhere)'
    """
    if not (constant and ref_constant):
        return ""
    if "rank" in name.lower():
        return (
            "is not the rank asked: the rank at the configuration the question gives, not the generic rank "
            "(the largest rank, reached almost everywhere)"
        )
    return "is a constant, and not the right one"


CHOICE_MISTAKES = (
    Mistake(
        "zero-based",
        "counts joints from 0: joints are numbered from 1 (the first joint is 1)",
        lambda c: iter([("", _plus_one(c))]),
    ),
)
