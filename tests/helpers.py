"""Shared helpers for the kinlib tests.

* :func:`assert_sym_equal` – two SymPy matrices/expressions are equal as functions of their symbols
  (a numeric spot check at random points first, for a readable failure, then an exact proof by
  simplification).
* :func:`random_arm` – a random open chain (revolute and prismatic joints, random axes and points)
  built with plain NumPy/modern_robotics, *not* with kinlib, so it can serve as an independent input.
* :data:`FAST` – hypothesis settings for quick, reproducible property tests.
"""

from __future__ import annotations

import random

import numpy as np
import sympy as sp

try:  # hypothesis is in environment.txt; keep conftest importable without it
    from hypothesis import HealthCheck, settings

    FAST = settings(
        max_examples=25, deadline=None, derandomize=True, database=None, suppress_health_check=[HealthCheck.too_slow]
    )
except ImportError:  # pragma: no cover
    FAST = None


# --------------------------------------------------------------------------------------------
# symbolic equality
# --------------------------------------------------------------------------------------------
def _sample_value(sym: sp.Symbol, rng: random.Random) -> sp.Rational:
    """A random exact value respecting the symbol's sign assumptions."""
    x = sp.Rational(rng.randint(300, 1700), 1000)
    if sym.is_positive or sym.is_nonnegative:
        return x
    return x if rng.random() < 0.5 else -x


def _as_matrix(x) -> sp.Matrix:
    if isinstance(x, sp.MatrixBase):
        return sp.Matrix(x)
    if isinstance(x, (list, tuple, np.ndarray)):
        return sp.Matrix(x)
    return sp.Matrix([[sp.sympify(x)]])


def _trig_poly_is_zero(e: sp.Expr):
    """Decide e == 0 for a polynomial in sin/cos of sums of symbols (and other symbols, radicals).

    expand_trig reduces every sin/cos to sin θ_i, cos θ_i of single symbols; with s_i, c_i for them
    the question is whether the numerator lies in the ideal (s_i² + c_i² − 1), whose generators are
    a Gröbner basis (coprime leading terms s_i²): the remainder of the division is 0 iff e ≡ 0.
    Returns True/False, or None when e is not of that form.
    """
    e = sp.expand(sp.expand_trig(sp.expand(e)))
    trig = e.atoms(sp.sin, sp.cos)
    args = {f.args[0] for f in trig}
    if not all(a.is_Symbol for a in args):
        return None
    args = sorted(args, key=str)
    s = {a: sp.Dummy(f"s_{a}") for a in args}
    c = {a: sp.Dummy(f"c_{a}") for a in args}
    rep = {sp.sin(a): s[a] for a in args}
    rep.update({sp.cos(a): c[a] for a in args})
    p = e.xreplace(rep)
    if p.has(sp.sin, sp.cos, sp.tan, sp.exp):
        return None
    num = sp.expand(sp.together(p).as_numer_denom()[0])
    if num == 0:
        return True
    if not args:
        return None
    others = sorted(num.free_symbols - set(s.values()) - set(c.values()), key=str)
    gens = [s[a] for a in args] + [c[a] for a in args] + others
    try:
        _, rem = sp.reduced(num, [s[a] ** 2 + c[a] ** 2 - 1 for a in args], *gens, order="lex")
    except Exception:
        return None
    return sp.expand(rem) == 0


def _is_zero_exact(e: sp.Expr) -> bool:
    """Prove e == 0: the trig-polynomial decision above, else simplification routes."""
    e = sp.sympify(e)
    if e == 0:
        return True
    decided = _trig_poly_is_zero(e)
    if decided is not None:
        return decided
    for attempt in (
        lambda x: sp.simplify(sp.expand_trig(x)),
        lambda x: sp.expand(sp.expand_trig(sp.expand(x))),
        lambda x: sp.simplify(sp.expand(sp.expand_trig(sp.expand(x)))),
        lambda x: sp.trigsimp(sp.expand(sp.expand_trig(x))),
        lambda x: sp.simplify(x.rewrite(sp.exp)),
    ):
        try:
            if attempt(e) == 0:
                return True
        except Exception:  # pragma: no cover - a route that fails is just not a proof
            continue
    return False


def assert_sym_equal(a, b, label: str = "", *, spot_checks: int = 3, tol: float = 1e-9) -> None:
    """Assert that ``a`` and ``b`` (SymPy matrices or expressions) are identically equal.

    First a numeric spot check at ``spot_checks`` random exact points (positive symbols get positive
    values), so a wrong entry is reported with numbers; then each entry of a − b is simplified to 0.
    """
    A, B = _as_matrix(a), _as_matrix(b)
    assert A.shape == B.shape, f"{label}: shapes differ, {A.shape} vs {B.shape}"
    D = A - B
    syms = sorted(D.free_symbols, key=str)
    rng = random.Random(20240611)
    for _ in range(spot_checks):
        vals = {s: _sample_value(s, rng) for s in syms}
        # Floats (30 digits) evaluate sin/cos as the expression is rebuilt: far faster than evalf of rationals
        Dn = np.array(D.xreplace({k: sp.Float(v, 30) for k, v in vals.items()}).evalf(30).tolist(), dtype=complex)
        bad = np.argwhere(np.abs(Dn) > tol)
        if bad.size:
            i, j = bad[0]
            raise AssertionError(
                f"{label}: entry ({i}, {j}) differs at {vals}:\n  got      {A[i, j]}\n  expected {B[i, j]}\n"
                f"  difference {Dn[i, j]:.6g}"
            )
    for i in range(D.rows):
        for j in range(D.cols):
            assert _is_zero_exact(D[i, j]), (
                f"{label}: entry ({i}, {j}) not proved equal by simplification:\n"
                f"  got      {A[i, j]}\n  expected {B[i, j]}"
            )


def assert_no_floats(M, label: str = "") -> None:
    """``M`` is a SymPy object with no Float atoms (exact)."""
    assert isinstance(M, (sp.MatrixBase, sp.Basic)), f"{label}: expected a SymPy object, got {type(M).__name__}"
    floats = M.atoms(sp.Float)
    assert not floats, f"{label}: Float atoms {sorted(floats)[:5]} in an exact result"


# --------------------------------------------------------------------------------------------
# random arms, built without kinlib
# --------------------------------------------------------------------------------------------
def _unit(v):
    return v / np.linalg.norm(v)


def random_transform(rng: np.random.Generator) -> np.ndarray:
    """A random T ∈ SE(3) from the modern_robotics exponential of a random twist."""
    import modern_robotics as mr

    return mr.MatrixExp6(mr.VecTose3(rng.normal(size=6)))


def random_arm(rng: np.random.Generator, n: int, kinds: str | None = None):
    """(M, Slist 6×n, kinds) for a random chain: 'R' joints ω unit through a random point q
    (S = [ω; −ω × q]), 'P' joints S = [0; v] with v unit; M a random transform."""
    if kinds is None:
        kinds = "".join(rng.choice(["R", "R", "P"], size=n))
    assert len(kinds) == n
    cols = []
    for k in kinds:
        if k == "R":
            w = _unit(rng.normal(size=3))
            q = rng.uniform(-1.0, 1.0, size=3)
            cols.append(np.concatenate([w, -np.cross(w, q)]))
        else:
            cols.append(np.concatenate([np.zeros(3), _unit(rng.normal(size=3))]))
    return random_transform(rng), np.column_stack(cols), kinds


def random_thetas(rng: np.random.Generator, kinds: str, size=None) -> np.ndarray:
    """Joint values: angles in (−π, π) for 'R', displacements in (−1, 1) for 'P'; shape (n,) or (size, n)."""
    shape = (len(kinds),) if size is None else (size, len(kinds))
    th = rng.uniform(-np.pi, np.pi, size=shape)
    pr = np.array([k == "P" for k in kinds])
    th[..., pr] = rng.uniform(-1.0, 1.0, size=shape)[..., pr]
    return th


# --------------------------------------------------------------------------------------------
# the unseen-robot exercises (issue 30, "practice that transfers"): right, other-valid and wrong answers
# --------------------------------------------------------------------------------------------
_K = sp.Symbol("k", integer=True)


def angle_family(*offsets, period=2 * sp.pi) -> sp.Set:
    """The angles offset + period·k (k any integer), one ImageSet per offset: a `set` answer written by hand."""
    return sp.Union(*[sp.ImageSet(sp.Lambda(_K, o + period * _K), sp.Integers) for o in offsets])


def crossed(value):
    """The value as the grader sees it: exported in the kernel, sent as JSON, read by the whitelist parser."""
    import json

    from kinlib.course.answers import wire
    from kinlib.course.grader.in_kernel.export import export

    return wire.load(json.loads(json.dumps(export(value))))


def grader_verdict(kind, student, reference, name, points):
    """(ok, message) of the instructor's grader: describe both sides at `points`, through JSON, then compare."""
    import json

    from kinlib.course.answers import compare, describe

    stu = json.loads(json.dumps(describe.describe(kind, crossed(student), points, 0)))
    ref = json.loads(json.dumps(describe.describe(kind, crossed(reference), points, 0)))
    return compare.compare(kind, stu, ref, name)


def assert_graded_right_and_wrong(name, case, points) -> None:
    """Feed the workbook self-check and the grader the right answer, its other valid forms and the wrong ones.

    `case` is (part, kind, right, [other valid forms], {label: wrong value}); the self-check is salted by
    "part:name" as the workbook's is. Every right form must pass both, every wrong one fail both.
    """
    from kinlib.course.workbook.selfcheck import fingerprint, verdict

    part, kind, right, others, wrong = case
    sc_kind = "default" if kind == "expr" else kind
    salt = f"{part}:{name}"
    spec = fingerprint(right, sc_kind, salt=salt)
    for value in [right, *others]:
        status, msg = verdict(value, spec, salt=salt)
        assert status == "correct", (name, value, msg)
        ok, msg = grader_verdict(kind, value, right, name, points)
        assert ok, (name, value, msg)
    for label, value in wrong.items():
        status, msg = verdict(value, spec, salt=salt)
        assert status == "incorrect", (name, label, status, msg)
        ok, msg = grader_verdict(kind, value, right, name, points)
        assert not ok, (name, label, msg)
