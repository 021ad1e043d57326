"""The ``subspace`` kind: a matrix whose columns span a subspace, judged by its span, whatever the basis.

* **normalise**: :func:`kinlib.course.answers.expr.to_sympy` with ``vectors=True``: a list of lists, or of
  matrices, is the list of spanning vectors (or blocks of them), side by side.
* **wire form**: as :mod:`.expr` (``Matrix``, ``ndarray``, lists of vectors).
* **describe** (:func:`describe_subspace`): the spanning vectors' values at the secret points; a constant exact
  matrix also as its exact tree (:func:`kinlib.course.answers.wire.exact_dump`), compared exactly.
* **compare** (:func:`compare_subspace`): each column normalised first (no scaling of a basis matters), then
  orthonormal bases of one dimension with principal angles ~0 between them, at every point; constant exact
  bases by exact ranks (:func:`exact_ranks`).
* **reference** (:func:`reference_subspace`).
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from . import fingerprints as fp
from . import mistakes
from .base import as_sympy, not_answered, symbol_notes, type_name, values_array
from .expr import as_sympy_value, describe_expr, to_sympy
from .wire import exact_dump, exact_load

__all__ = [
    "describe_subspace",
    "compare_subspace",
    "reference_subspace",
    "exact_tree",
    "exact_ranks",
    "SUBSPACE_TOL",
    "home_canon",
    "home_verdict",
    "stub_words",
]

SUBSPACE_TOL = 1e-7  # rank cut-off on singular values of unit columns; largest principal angle (sine)


def exact_tree(obj):
    """The exact tree of a spanning matrix (for a constant exact one: compared exactly), or None.

    >>> exact_tree([[1, 0], [0, 1]])[:3], exact_tree("not a matrix")
    (['Matrix', 2, 2], None)
    """
    try:
        return exact_dump(to_sympy(obj, vectors=True)[1], max_nodes=600)
    except Exception:  # noqa: BLE001  (compared numerically then)
        return None


def describe_subspace(value, points, seed=0):
    """Subspace answer: a matrix whose columns span it (a list of lists: the spanning vectors); a constant
    exact matrix also as its exact tree (``tree``), so the grader can compare spans exactly.

    >>> d = describe_subspace([[1, 0], [0, 1]], [{}])
    >>> d["shape"], d["tree"][:3]
    ([2, 2], ['Matrix', 2, 2])
    """
    out = describe_expr(value, points, seed, vectors=True)
    if out.get("tag") == "matrix" and not out.get("symbols") and not out.get("has_float"):
        tree = exact_tree(value)
        if tree is not None:
            out["tree"] = tree
    return out


def reference_subspace(value):
    """The reference value of a ``subspace`` answer as a SymPy Matrix (its spanning vectors side by side).

    >>> reference_subspace([[1, 0, 0], [0, 1, 0]]).shape
    (3, 2)
    """
    tag, obj = to_sympy(value, vectors=True)
    if obj is None:
        raise TypeError(f"reference answer of kind 'subspace' is {tag} ({type_name(value)})")
    return obj


def exact_ranks(stu_tree, ref_tree):
    """(rank A, rank B, rank [A B]) computed exactly for two constant exact matrices given as exact trees
    (:func:`exact_tree`; both sides must have one), or None (then the spans are compared numerically): when
    a tree is missing or malformed, has symbols, or SymPy cannot decide whether a pivot is zero. Equal spans ⇔
    rank A = rank B = rank [A B].

    >>> exact_ranks(exact_tree([[1, 0, 10**30], [0, 0, 1]]), exact_tree([[0, 0, 1]])), exact_ranks(None, None)
    ((2, 1, 2), None)
    """
    import sympy as sp

    mats = []
    for t in (stu_tree, ref_tree):
        if not isinstance(t, list) or t[:1] != ["Matrix"]:
            return None
        try:
            M = exact_load(t, max_nodes=600)
        except (ValueError, TypeError, RecursionError):
            return None
        if not isinstance(M, sp.MatrixBase) or M.free_symbols or not (0 < M.rows <= 12 and 0 < M.cols <= 12):
            return None
        mats.append(M)
    A, B = mats
    if A.rows != B.rows:
        return None
    unsure = []

    def iszero(x):
        z = as_sympy(x).equals(0)
        if z is None:
            unsure.append(x)
        return bool(z)

    ranks = tuple(M.rank(iszerofunc=iszero) for M in (A, B, A.row_join(B)))
    return None if unsure else ranks


def _orthonormal(A):
    """An orthonormal basis (columns) of the span of A's columns, whatever their scaling.

    Each column is scaled to length 1 first (a column 10¹² or 10⁻¹² times another counts the same), columns
    that are zero (or round-off beside the largest: below 10⁻¹³ of it) dropped; the rank is the number of
    singular values of the unit columns above ``SUBSPACE_TOL`` (the largest is ≥ 1).
    """
    if A.size == 0:
        return A[:, :0]
    norms = np.linalg.norm(A, axis=0)
    top = norms.max()
    if not np.isfinite(top) or top == 0:
        return A[:, :0]
    keep = norms > 1e-13 * top
    U = A[:, keep] / norms[keep]
    u, s, _ = np.linalg.svd(U, full_matrices=False)
    return u[:, : int(np.sum(s > SUBSPACE_TOL * s[0]))]


def _same_span(QA, QB):
    """Largest principal angle between two subspaces of one dimension (orthonormal bases) is ~0."""
    if QA.shape[1] != QB.shape[1]:
        return False
    if QA.shape[1] == 0:
        return True
    resid = QA - QB @ (QB.conj().T @ QA)
    return float(np.linalg.norm(resid, 2)) < 1e-6


def _as_matrix_shape(shape):
    shape = list(shape) or [1, 1]
    return [shape[0], 1] if len(shape) == 1 else shape


def _wrong_dimension(name, rank, sshape, note=""):
    dep = f" ({sshape[1]} columns, {rank} independent)" if sshape[1] != rank else ""
    return False, f"{name} spans a {rank}-dimensional space{dep}, not the right dimension" + (
        f"; {note}" if note else ""
    )


def _wrong_span(name, notes=()):
    return False, (
        f"{name} spans a space of the right dimension but not the right one (some of your directions "
        "are not in the answer's span)" + (f"; {'; '.join(notes)}" if notes else "")
    )


def _same_columns_note(sshape, rshape) -> str:
    return "" if sshape[1] == rshape[1] else f"same span (you gave {sshape[1]} columns)"


def _compare_exact(stu, ref, name, sshape, rshape):
    """(ok, message) by exact ranks for two constant exact bases, or None (then compared numerically)."""
    exact = exact_ranks(stu.get("tree"), ref.get("tree"))
    if exact is None:
        return None
    ra, rb, rab = exact
    if ra != rb:
        return _wrong_dimension(name, ra, sshape)
    if rab != rb:
        return _wrong_span(name)
    return True, _same_columns_note(sshape, rshape)


def _compare_numeric(S, R, name, sshape, rshape, notes):
    """(ok, message) by principal angles between orthonormal bases, at every point."""
    for p in range(S.shape[0]):
        QA = _orthonormal(S[p].reshape(sshape))
        QB = _orthonormal(R[p].reshape(rshape))
        if QA.shape[1] != QB.shape[1]:
            return _wrong_dimension(name, QA.shape[1], sshape, notes[0] if notes else "")
        if not _same_span(QA, QB):
            return _wrong_span(name, notes)
    return True, _same_columns_note(sshape, rshape)


def compare_subspace(stu: dict, ref: dict, name: str) -> tuple[bool, str]:
    """A subspace by its span, at every point: orthonormal bases of both (each column normalised first,
    so no scaling of a basis matters) of one dimension, and principal angles ~0 between them.

    >>> ref = {"shape": [2, 1], "symbols": [], "values": [[[1.0, 0.0], [0.0, 0.0]]]}
    >>> compare_subspace(dict(ref, tag="matrix", values=[[[3e12, 0.0], [0.0, 0.0]]]), ref, "s")
    (True, '')
    >>> compare_subspace(dict(ref, tag="matrix", values=[[[1e12, 0.0], [1e12, 0.0]]]), ref, "s")[0]
    False
    """
    na = not_answered(stu)
    if na:
        return False, f"{name} {na}"
    if stu.get("tag") not in ("matrix", "scalar"):
        return False, f"{name} is a {stu.get('type')}; expected a Matrix whose columns span the subspace"
    rshape, sshape = _as_matrix_shape(ref["shape"]), _as_matrix_shape(stu["shape"])
    S, R = values_array(stu["values"]), values_array(ref["values"])
    if S.shape[0] != R.shape[0]:
        return False, f"{name} could not be compared (malformed values)"
    if np.isnan(S).any() or not np.isfinite(S).all():
        return False, f"{name} could not be evaluated at some values of the symbols"
    if sshape[0] != rshape[0]:
        if sshape[1] == rshape[0]:
            return False, (
                f"{name} gives the vectors as rows ({sshape[0]}×{sshape[1]}): put one vector per column "
                f"({rshape[0]} rows)"
            )
        return False, f"{name} has vectors of length {sshape[0]}; expected {rshape[0]}"
    exact = _compare_exact(stu, ref, name, sshape, rshape)
    if exact is not None:
        return exact
    return _compare_numeric(S, R, name, sshape, rshape, symbol_notes(stu, ref))


# ----------------------------------------------------------------------------------------- the self-check
# The workbook's side of the kind (kinlib.course.workbook.selfcheck): the orthogonal projector onto the span at
# the public sample points (home_canon), and the verdict against the spec (home_verdict), naming the mistakes of
# mistakes.SUBSPACE_MISTAKES as the grader does.

_PROJ_DECIMALS = 6  # decimals kept of a subspace's projector
HOME_DIFFERS = "it spans a different subspace"


def _home_value(value, shape=None):
    v = as_sympy_value(value, vectors=True)  # a list of spanning vectors: side by side
    if not isinstance(v, sp.MatrixBase):
        raise fp.WrongForm("it should be a Matrix whose columns span the subspace")
    m = str(v.shape[0])
    if shape not in (None, m):
        raise fp.WrongForm(f"its columns should be {shape}-vectors, yours are {m}-vectors")
    return v


def _home_sampled(v) -> np.ndarray:
    """The spanning vectors at the sample points, as floats (points, m, vectors)."""
    out = []
    for k in range(fp.SAMPLE_POINTS):
        try:
            A = np.array(fp.evaluate(v, k).tolist(), dtype=complex).reshape(v.shape)
        except TypeError as e:
            raise fp.CannotCheck(f"it does not evaluate to numbers ({e})") from None
        if np.abs(A.imag).max(initial=0.0) > fp.ZERO:
            raise fp.CannotCheck("it has complex entries")
        out.append(A.real)
    return np.array(out).reshape(fp.SAMPLE_POINTS, *v.shape)


def _canon_spans(As) -> tuple:
    """(form, ambient dimension, canonical projectors) of the spans of the arrays ``As`` (one per point)."""
    pts = []
    for A in As:
        if A.size == 0 or np.abs(A).max() < fp.ZERO:
            P = np.zeros((A.shape[0], A.shape[0]))
        else:
            U, s, _ = np.linalg.svd(A)
            r = int((s > 1e-9 * max(1.0, s[0])).sum())
            Q = U[:, :r]
            P = Q @ Q.T
        P = np.round(P, _PROJ_DECIMALS) + 0.0
        pts.append([f"{x:.{_PROJ_DECIMALS}f}" for x in P.ravel()])
    return "subspace", str(As[0].shape[0]), pts


def home_canon(value, shape=None) -> tuple:
    """``("subspace", ambient dimension, canonical projectors)`` of a ``subspace`` answer at the sample points.

    >>> home_canon([[1, 0, 0]])[:2], home_canon([[2, 0, 0]]) == home_canon(sp.Matrix([1, 0, 0]))
    (('subspace', '3'), True)
    """
    return _canon_spans(_home_sampled(_home_value(value, shape)))


def _home_mistake(arr, shape, right):
    m = int(shape)

    def matches(As):
        return all(A.shape[0] == m for A in As) and right(_canon_spans(As)[2])

    found = mistakes.search(arr, matches, mistakes.SUBSPACE_MISTAKES, pairs=False)
    return found.says if found is not None else None


def home_verdict(value, judge: fp.Judge) -> tuple[str, str]:
    """The self-check's ``(status, message)`` on a ``subspace`` answer against the spec in ``judge``.

    >>> j = fp.Judge("subspace", "3", fp.digest("subspace", home_canon([[1, 0, 0]])[2]))
    >>> home_verdict(sp.Matrix([5, 0, 0]), j), home_verdict([[0, 1, 0]], j)
    (('correct', 'correct'), ('incorrect', 'not right yet: it spans a different subspace'))
    """
    shape, right, named = judge.shape, judge.right, judge.named
    try:
        v = _home_value(value, shape)
    except fp.WrongForm:
        v = _home_value(value)
        found = _home_mistake(_home_sampled(v), shape, right)
        if found is None:
            raise
        return named(found)
    arr = _home_sampled(v)
    if right(_canon_spans(arr)[2]):
        return "correct", "correct"
    found = _home_mistake(arr, shape, right)
    return named(found) if found else ("incorrect", f"not right yet: {HOME_DIFFERS}")


def stub_words(value) -> str:
    """What a ``subspace`` answer is, for the workbook's stub.

    >>> stub_words(sp.Matrix([1, 0, 0]))
    'a Matrix whose columns span the subspace (3-vectors)'
    """
    try:
        return f"a Matrix whose columns span the subspace ({as_sympy_value(value, True).shape[0]}-vectors)"
    except Exception:  # noqa: BLE001
        return "a Matrix whose columns span the subspace"
