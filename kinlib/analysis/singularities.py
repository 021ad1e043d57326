"""Singular configurations, rank, and the directions a robot can and cannot move.

A Jacobian J (m×n, any of space / body / geometric: singularities do not depend on the choice) loses
rank where

* det J = 0 (square J),
* det(J Jᵀ) = 0 (m < n, more joints than task dimensions),
* det(Jᵀ J) = 0 (m > n, fewer joints than task dimensions).

``task_rows`` picks a task space's rows first (rows are [ω; v] = wx wy wz vx vy vz; for the geometric
Jacobian the last three are ṗ). ``singular_configurations`` solves det = 0 in closed form, as whole
periodic families; ``rank_at``, ``column_space`` and ``left_null_space`` give exact answers *at* a
configuration (SymPy's ``Matrix.rank()`` on the symbolic J gives only the generic rank and hides the drop).

How the singular set is found exactly: sin θ_i, cos θ_i are replaced by polynomial variables s_i, c_i,
each entry is reduced modulo s_i² + c_i² − 1 (:class:`kinlib.trigpoly.TrigRing`), and the k×k minors of
J (k = min(m, n); for square J only det J) are taken in that polynomial ring by Laplace expansion along
the rows, each smaller minor shared by every column set that contains it (no division; Σ minors² =
det(J Jᵀ) or det(Jᵀ J) by Cauchy–Binet, so rank J < k ⇔ all minors vanish). With G
their gcd and q_i = minor_i / G, the singular set is {G = 0} ∪ {all q_i = 0}. The factors of G that
involve a single joint are solved on one period [0, 2π) and written as families {b + p k : k ∈ ℤ}
(prismatic joint values enter polynomially and are solved over ℝ); the common zeros of the q_i are
solved joint by joint where their factors allow it, else given as Σ q_i² = 0. Factors that cannot
vanish are dropped only with a proof (:mod:`kinlib.trigsign`). A time budget bounds the work: past it
the answer says it is incomplete (``SingularSet.complete``) and names the numeric search
:func:`find_singularities`.

**Numeric search** (:func:`find_singularities`, below) for singular configurations of any serial chain with numeric link lengths.

:func:`find_singularities` looks for configurations where the smallest singular value σ_k of the
Jacobian (k = min(m, n)) is below a tolerance: seeded random starts, each improved by Newton steps
on σ_k(θ) toward 0,

    θ ← θ − σ_k g / ‖g‖²,   g_j = ∂σ_k/∂θ_j = u_kᵀ (∂J/∂θ_j) v_k,

where J = U Σ Vᵀ, u_k, v_k are the singular vectors of σ_k and ∂J/∂θ_j is a central finite difference
(every start and every difference in one batch through the chain's generated code). Steps are halved
until σ_k decreases. It is the numeric companion of the exact
:func:`kinlib.singularities.singular_configurations`: it works on any arm (7 joints too), finds
points (not families) and proves nothing, but each point it returns has σ_k < tol, checked at the end.
"""

from __future__ import annotations

import itertools
import numbers
import warnings
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
import sympy as sp

from .._backend import as_jacobian, describe, exact_number, is_symbolic, joint_symbols
from ..exact.budget import OutOfTime, budget_seconds, clock, report, run
from ..exact.linalg import column_space, evaluate_at, left_null_space, rank_at
from ..exact.trigpoly import NotTrigPolynomial, TrigRing, angles_in
from ..exact.trigsign import generator_kinds, proves_nonzero
from .taskspace import ROW_NAMES, task_rows

__all__ = [
    "ROW_NAMES",
    "task_rows",
    "singular_configurations",
    "SingularSet",
    "IncompleteResultWarning",
    "representatives",
    "rank_at",
    "column_space",
    "left_null_space",
    "evaluate_at",
    "trig_simplify",
    "periodic_family",
    "K",
    "find_singularities",
    "SingularPoints",
]

#: The integer that indexes a periodic family of joint values, {b + p·k : k ∈ ℤ}.
K = sp.Symbol("k", integer=True)

_TWO_PI = 2 * sp.pi


# ----------------------------------------------------------------------------------------------
# input checks
# ----------------------------------------------------------------------------------------------
def _check_params(J: sp.Matrix, thetas, params) -> tuple[sp.Symbol, ...]:
    """Symbols of J other than the joints must be parameters: given in ``params`` or declared positive."""
    extra = J.free_symbols - set(thetas)
    if params is not None:
        if isinstance(params, sp.Symbol):
            params = (params,)
        params = tuple(params)
        if not all(isinstance(p, sp.Symbol) for p in params):
            raise TypeError(f"params must hold SymPy symbols, got {describe(list(params))}")
        extra -= set(params)
        bad = sorted(extra, key=str)
    else:
        bad = sorted((s for s in extra if not s.is_positive), key=str)
    if bad:
        raise ValueError(
            f"J contains the symbol(s) {', '.join(map(str, bad))}, which are not among the joints "
            f"thetas=({', '.join(map(str, thetas))}); parameters must be positive symbols (link lengths) "
            f"or listed in params="
        )
    return tuple(sorted(J.free_symbols - set(thetas), key=str))


# ----------------------------------------------------------------------------------------------
# display form (the normal form modulo sin² + cos² = 1 is kinlib.trigpoly's)
# ----------------------------------------------------------------------------------------------
def trig_simplify(e: Any, thetas: Sequence[sp.Symbol] | None = None):
    """A display form: expand the trig functions, reduce with sin² + cos² = 1, then trigsimp and factor.

    Works entry-wise on matrices. Much faster than ``sp.simplify`` on product-of-exponentials output.

    >>> from kinlib.robots import planar_2r
    >>> J = task_rows(planar_2r().jacobian_geometric(), ["vx", "vy"])   # the 2R arm's rows ṗ_x, ṗ_y
    >>> J.det()
    L1*L2*sin(theta1)**2*sin(theta2) + L1*L2*sin(theta2)*cos(theta1)**2
    >>> trig_simplify(J.det())
    L1*L2*sin(theta2)
    """
    if isinstance(e, sp.MatrixBase):
        return e.applyfunc(lambda x: trig_simplify(x, thetas))
    e = sp.sympify(e)
    if not isinstance(e, sp.Expr):
        raise TypeError(f"e must be a SymPy expression or Matrix, got {describe(e)}")
    angles = angles_in([e], set(thetas) if thetas is not None else None)
    if not angles:
        if e.free_symbols:
            return sp.factor(e)
        if e.is_number and not e.has(sp.Float):  # exact rewriting only (never nsimplify: it guesses from floats)
            e = sp.radsimp(e)
            return sp.trigsimp(e) if e.has(sp.sin, sp.cos) else e
        return e
    try:
        ring = TrigRing([e], angles, opaque=True)
        p = ring.to_expr(ring.normal_form(e), trig=False)  # in s_i, c_i: factored as a polynomial
    except NotTrigPolynomial:  # sin/cos under a root or in a denominator: trigsimp alone
        return sp.factor_terms(sp.trigsimp(e))
    return sp.factor_terms(sp.trigsimp(ring.to_trig(sp.factor(p))))


# ----------------------------------------------------------------------------------------------
# singular configurations
# ----------------------------------------------------------------------------------------------
def periodic_family(points: Sequence) -> sp.Set:
    """{b + p k : k ∈ ℤ}: the angles ≡ one of ``points`` (exact, one period [0, 2π)) modulo 2π, written with
    period π when the points come in pairs π apart (sin θ = 0 → {kπ}); bases in (−π/2, π/2] or (−π, π].

    >>> import sympy as sp
    >>> periodic_family([0, sp.pi])   # sin θ = 0 on [0, 2π): θ = kπ
    ImageSet(Lambda(k, pi*k), Integers)
    >>> periodic_family([3 * sp.pi / 4, 7 * sp.pi / 4]), periodic_family([sp.pi / 2])
    (ImageSet(Lambda(k, pi*k - pi/4), Integers), ImageSet(Lambda(k, 2*pi*k + pi/2), Integers))
    """
    if isinstance(points, (str, bytes)) or not isinstance(points, (Sequence, set, frozenset, sp.FiniteSet)):
        raise TypeError(f"points must be a sequence of real numbers, got {describe(points)}")
    points = [exact_number(p, "points") for p in points]  # a float means the decimal typed, never a guess
    if not points or not all(p.is_number and p.is_real for p in points):
        raise ValueError(f"points must be real numbers, got {points}")
    points = [p - _TWO_PI * sp.floor(p / _TWO_PI) for p in points]
    pts = sorted(set(points), key=lambda x: float(x))
    modpi = all(any(sp.simplify((p + sp.pi) % _TWO_PI - q) == 0 for q in pts) for p in pts)
    if modpi:
        period = sp.pi
        bases = [p for p in pts if float(p) < float(sp.pi) - 1e-12]
        bases = [b - sp.pi if float(b) > float(sp.pi) / 2 + 1e-12 else b for b in bases]
    else:
        period = _TWO_PI
        bases = [p - _TWO_PI if float(p) > float(sp.pi) + 1e-12 else p for p in pts]
    bases = sorted(bases, key=lambda x: float(x))
    sets = [sp.ImageSet(sp.Lambda(K, b + period * K), sp.Integers) for b in bases]
    return sets[0] if len(sets) == 1 else sp.Union(*sets, evaluate=False)


def _solve_single(g: sp.Expr, joint: sp.Symbol, revolute: bool) -> sp.Set | None:
    """The real zeros of g(joint) as a Set, or None when they have no closed form."""
    try:
        if revolute:
            sol = sp.solveset(g, joint, sp.Interval.Ropen(0, _TWO_PI))
            if sol is sp.S.EmptySet:
                return sol
            if isinstance(sol, sp.FiniteSet) and all(p.is_real and p.is_number for p in sol):
                return periodic_family(list(sol))
            return None
        sol = sp.solveset(g, joint, sp.S.Reals)
        if sol is sp.S.EmptySet or isinstance(sol, sp.FiniteSet):
            return sol
        return None
    except (NotImplementedError, ValueError, TypeError):
        return None


def _normalize_expr(e: sp.Expr) -> sp.Expr:
    """A condition 'e = 0' written with a positive leading coefficient and no constant factor."""
    e = sp.factor_terms(e)
    c, rest = e.as_coeff_Mul()
    if c.is_number and c != 0:
        e = rest
    if e.could_extract_minus_sign():
        e = -e
    return e


class SingularSet(list):
    """The answer of :func:`singular_configurations`: a list of conditions, plus

    * ``complete`` (bool): True when the conditions are *all* the singular configurations (then ``[]``
      means there is none); False when a closed form was out of reach (time budget, size), and the list
      holds only what was found, maybe nothing;
    * ``note`` (str): how the answer was obtained, and for an incomplete one what is missing and the
      numeric alternative (:func:`find_singularities`).

    It is a plain list otherwise: ``conds == []``, ``conds[0]``, ``len(conds)`` work as before, and it prints
    as a list (so SymPy's notebook printing typesets it); an incomplete answer is announced by an
    :class:`IncompleteResultWarning` carrying the note when it is made. An incomplete answer equals no list
    (``==`` is False even against the same conditions): "no singular configuration" can only be read off a
    complete one, so a test or a caller that compares with ``[]`` cannot mistake giving up for an answer.

    >>> import sympy as sp
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r()
    >>> conds = singular_configurations(task_rows(r.jacobian_geometric(), ["vx", "vy"]), r.thetas)
    >>> conds, conds.complete, conds.note   # det J = L1 L2 sin θ2: stretched out or folded
    ([{theta2: ImageSet(Lambda(k, pi*k), Integers)}], True, 'from the factors of det J')
    >>> conds[0] == {r.thetas[1]: periodic_family([0, sp.pi])}   # a plain list otherwise
    True
    >>> SingularSet([], complete=False) == [], SingularSet([], complete=False) != []
    (False, True)
    """

    __hash__ = None  # a list: unhashable

    def __init__(self, conditions=(), complete: bool = True, note: str = ""):
        super().__init__(conditions)
        self.complete = bool(complete)
        self.note = note

    def __eq__(self, other):
        if not self.complete or (isinstance(other, SingularSet) and not other.complete):
            return False  # what was found is not the answer: it equals nothing, itself included
        return list.__eq__(self, other)

    def __ne__(self, other):
        return not self == other


class IncompleteResultWarning(UserWarning):
    """A closed-form answer was out of reach: the result is partial (its ``note`` says what is missing).

    >>> import warnings
    >>> from kinlib.robots import planar_2r
    >>> r = planar_2r()
    >>> J = task_rows(r.jacobian_geometric(), ["vx", "vy"])
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     conds = singular_configurations(J, r.thetas, time_budget=0)   # no time for det J at all
    >>> caught[0].category.__name__, conds, conds.complete
    ('IncompleteResultWarning', [], False)
    """


class _OutOfTime(Exception):
    pass


_MAX_PRODUCT = 2_000_000  # term pairs in one polynomial product (about a second of pure-Python arithmetic)


def _mul(a, b, deadline: float):
    if clock() > deadline or len(a.terms()) * len(b.terms()) > _MAX_PRODUCT:
        raise _OutOfTime
    return a * b


def _minors(rows: list, ring, deadline: float, reduce: bool) -> list:
    """All maximal minors of a k×n matrix (k ≤ n) of ring elements, in combinations() order: Laplace expansion
    along the rows, sharing the minors of the first r rows among the column sets (Σ_r C(n, r)·r products of
    an entry by a smaller minor, no division: each minor is built once and never divided, where elimination
    multiplies two large intermediates and divides them exactly, one column set at a time). Every
    intermediate is itself a minor, so nothing swells beyond the answer. ``reduce=False``: the minors as
    plain polynomials in s_i, c_i (factors such as sin θ3 stay visible); ``reduce=True``: each reduced modulo
    s_i² + c_i² − 1 as it is made (smaller, but a factor may then hide inside a bigger one). The clock and
    the sizes are checked before each product."""
    k, n = len(rows), len(rows[0])
    R = ring.ring
    prev = {(): R.one}
    for r in range(k):
        cur = {}
        for S in itertools.combinations(range(n), r + 1):
            acc = R.zero
            for idx, j in enumerate(S):
                a, sub = rows[r][j], prev.get(S[:idx] + S[idx + 1 :])
                if a and sub:
                    term = _mul(a, sub, deadline)
                    acc = acc + term if (r + idx) % 2 == 0 else acc - term
            cur[S] = ring.reduce(acc) if reduce else acc
        prev = cur
    return [prev[S] for S in itertools.combinations(range(n), k)]


def _maximal_minors(entries: list, shape: tuple[int, int], ring, deadline: float) -> list:
    """The k×k minors of J (k = min(m, n)): rank J < k ⇔ all of them vanish. First as plain polynomials in
    s_i, c_i (factors stay visible); when those grow too large, reduced modulo s_i² + c_i² − 1 at every
    step (:func:`_minors`)."""
    m, n = shape
    rows = [entries[i * n : (i + 1) * n] for i in range(m)]
    if m > n:
        rows = [list(c) for c in zip(*rows)]
        m, n = n, m
    start = clock()
    raw_deadline = min(deadline, start + max(1.0, (deadline - start) / 8))
    try:
        return _minors(rows, ring, raw_deadline, reduce=False)
    except _OutOfTime:
        if clock() > deadline:
            raise
    return _minors(rows, ring, deadline, reduce=True)


def _cheap_points(g_expr: sp.Expr, joint: sp.Symbol, revolute: bool):
    """Exact zeros of a single-variable factor on one period, as (point, value of sin, value of cos) with
    rational sin and cos (kπ/2, π − atan(3/4) ...; exact simplification, never a guess), or rational
    prismatic values as (point, point, None); None when the zeros are of another kind."""
    sol = _solve_single(g_expr, joint, revolute)
    if sol is None:
        return None
    if sol is sp.S.EmptySet:
        return []
    pts = list(sol) if isinstance(sol, sp.FiniteSet) else representatives(sol)
    out = []
    for p in pts:
        if revolute:
            sv, cv = (sp.simplify(sp.expand_trig(f(p))) for f in (sp.sin, sp.cos))
            if not (sv.is_Rational and cv.is_Rational):
                return None
            out.append((p, sv, cv))
        else:
            if not p.is_Rational:
                return None
            out.append((p, p, None))
    return out


def _solve_system(qs: list, ring, ctx: dict, depth: int = 0):
    """All common zeros of the ring elements qs as a list of {joint: set of points (one period)}, each a
    conjunction; None when it cannot be done this way (a factor with several joints or awkward zeros)."""
    if clock() > ctx["deadline"] or depth > len(ctx["thetas"]):
        return None
    qs = [q for q in qs if q]
    if not qs:
        return [{}]
    if any(q.is_ground or proves_nonzero(ring, q, ctx["kinds"]) for q in qs):
        return []
    best = None
    for q in sorted(qs, key=lambda q: len(q.terms())):
        _, facs = q.factor_list()
        branches = []
        for f, _m in facs:
            joints = ring.depends_on(f) & ctx["joint_set"]
            if not joints:
                if proves_nonzero(ring, f, ctx["kinds"]):
                    continue
                branches = None
                break
            if len(joints) != 1 or ring.depends_on(f) - ctx["joint_set"]:
                branches = None
                break
            (j,) = joints
            pts = _cheap_points(ring.to_expr(f), j, j in ctx["revolute"])
            if pts is None:
                branches = None
                break
            branches += [(j, *p) for p in pts]
        if branches is not None:
            best = branches
            break
    if best is None:
        return None
    by_point: dict = {}
    for j, p, sv, cv in best:
        if j in ctx["revolute"]:
            i = ring.angles.index(j)
            subs = [
                (ring.gens[i], ring.domain.from_sympy(sv)),
                (ring.gens[len(ring.angles) + i], ring.domain.from_sympy(cv)),
            ]
        else:
            subs = [(ring.gens[2 * len(ring.angles) + ring.variables.index(j)], ring.domain.from_sympy(p))]
        sub = _solve_system([q.subs(subs) for q in qs], ring, ctx, depth + 1)
        if sub is None:
            return None
        for s in sub:
            key = (j, tuple(sorted(((k, tuple(sorted(v, key=float))) for k, v in s.items()), key=str)))
            by_point.setdefault(key, set()).add(p)
    out = []
    for (j, rest), pts in by_point.items():
        d = {k: set(v) for k, v in rest}
        d[j] = pts
        out.append(d)
    return out


def _factor_conditions(G, ring, ctx: dict, add) -> None:
    """The conditions 'f = 0' for the factors f of G that can vanish (impossible ones dropped with proof)."""
    _, factors = G.factor_list()
    for f, _mult in factors:
        _, sub = ring.reduce(f).factor_list()
        for g, _m in sub:
            if g.is_ground or proves_nonzero(ring, g, ctx["kinds"]):
                continue
            joints = ring.depends_on(g) & ctx["joint_set"]
            if len(joints) == 1:
                (j,) = joints
                sol = _solve_single(ring.to_expr(g), j, j in ctx["revolute"])
                if sol is sp.S.EmptySet:
                    continue
                if sol is not None:
                    add({j: sol})
                    continue
            add(_display_condition(g, ring, ctx["deadline"]))


def _display_condition(p, ring, deadline: float) -> sp.Expr:
    """'p = 0' for display: factored in sin/cos, angle sums folded (trigsimp) when small and time allows."""
    expr = ring.to_trig(sp.factor(ring.to_expr(p, trig=False))) if len(p.terms()) < 200 else ring.to_expr(p)
    if sp.count_ops(expr) < 150 and clock() < deadline:
        expr = sp.trigsimp(expr)
    return _normalize_expr(expr)


def singular_configurations(
    J: Any, thetas: Sequence[sp.Symbol], params: Sequence[sp.Symbol] | None = None, *, time_budget: float = 40.0
) -> SingularSet:
    """Where J(θ) loses rank, in closed form: a list of conditions (``[]``: no singular configuration).

    J (m×n) has full rank k = min(m, n) unless every k×k minor vanishes (for square J: det J = 0; in
    general Σ minors² = det(J Jᵀ) or det(Jᵀ J), Cauchy–Binet). With G = gcd of the minors and q_i =
    minor_i / G, the singular set is {G = 0} ∪ {all q_i = 0}. Each condition is

    * ``{θ_i: S}``: joint i in the SymPy Set S, the whole periodic family, e.g.
      ``{theta2: ImageSet(Lambda(k, pi*k - pi/4), Integers)}`` (θ2 = −π/4 + kπ); for a prismatic
      joint a FiniteSet of values. A dict with several joints means all of them at once
      (planar 3R's ṗ rows: ``{θ2: {kπ}, θ3: {kπ}}``);
    * an expression that must vanish, where a factor involves several joints (the UR5's shoulder
      singularity), written back in sin/cos; a sum of squares when it stands for "all q_i = 0";
    * an expression in the parameters only (e.g. ``L1 - L2``): when the link lengths make it vanish,
      *every* configuration is singular.

    Conditions that cannot vanish are dropped only with a proof (:mod:`kinlib.trigsign`: a positive
    constant plus squares, positive lengths, bounds |sin|, |cos| ≤ 1); so every returned condition does
    make J drop rank, and every rank drop is covered. The answer is a :class:`SingularSet` (a list):
    ``.complete`` is False when the closed form was out of reach within ``time_budget`` seconds (None: no
    limit; enforced inside SymPy's own work too, see :mod:`kinlib.budget`) (then
    use :func:`find_singularities` on a numeric chain), ``.note`` says how.

    ``thetas``: the n joint symbols, one per column of J. A joint need not appear in J (a space Jacobian
    never depends on the last joint). Every other symbol in J is a parameter: it must be declared
    positive (the link lengths of :mod:`kinlib.robots` are) or be listed in ``params`` (then any real).

    >>> from kinlib import robots
    >>> r = robots.planar_3r()
    >>> singular_configurations(task_rows(r.jacobian_space(), "planar"), r.thetas)
    [{theta2: ImageSet(Lambda(k, pi*k), Integers)}]
    >>> conds = singular_configurations(task_rows(r.jacobian_geometric(), ["vx", "vy"]), r.thetas)
    >>> conds, conds.complete           # tool position only: stretched *and* folded at once
    ([{theta2: ImageSet(Lambda(k, pi*k), Integers), theta3: ImageSet(Lambda(k, pi*k), Integers)}], True)
    """
    t0 = clock()
    if not is_symbolic(J):
        raise TypeError(f"J must be a symbolic Jacobian (a SymPy Matrix in the joint symbols), got {describe(J)}")
    J = as_jacobian(J, "J", True)
    thetas = joint_symbols(thetas, J.cols, per="one per column of J")
    _check_params(J, thetas, params)
    if J.rows == 0 or J.cols == 0:
        raise ValueError(f"J must have at least one row and one column, got {describe(J)}")
    seconds = budget_seconds(time_budget)  # None: no limit
    deadline = t0 + seconds if seconds is not None else float("inf")
    joint_set = set(thetas)

    def parameter_atom(a: sp.Expr) -> bool:  # √L, 1/L: allowed; anything else with a joint or a trig function: not
        return not (a.free_symbols & joint_set) and not a.has(sp.sin, sp.cos, sp.tan)

    def bad_entry(e):
        return ValueError(
            "J must be polynomial in sin θ_i, cos θ_i of the revolute joints and in the "
            f"prismatic joint values (after expanding); got the entry {e}"
        )

    conditions: list = []

    def key(c):
        if isinstance(c, dict):
            return (0, tuple(sorted(thetas.index(j) for j in c)), str(c))
        return (1 if c.free_symbols & joint_set else 2, 0, str(c))

    def out_of_reach(stage: str, stacklevel: int = 3):
        note = (
            f"closed form out of reach within time_budget={time_budget} s ({stage}); the conditions listed "
            "(maybe none) are singular, others may be missing. For a numeric search use "
            "kinlib.find_singularities(chain) on a chain with numeric lengths."
        )
        warnings.warn(f"singular_configurations: {note}", IncompleteResultWarning, stacklevel=stacklevel)
        return SingularSet(sorted(conditions, key=key), complete=False, note=note)

    k = min(J.shape)
    what = "det J" if J.rows == J.cols else f"the {k}×{k} minors of J"
    left = None if seconds is None else max(0.0, deadline - clock())

    def work():  # in a process ended when the budget runs out (kinlib.budget.run); each condition found is
        # reported at once, so the caller keeps them; the work's own deadline counts the clock of where it runs
        here = float("inf") if left is None else clock() + left
        return _singular_set(
            J, thetas, here, parameter_atom, bad_entry, _Reported(conditions), key, lambda st: out_of_reach(st, 4), what
        )

    try:
        return run(left, "singular_configurations", work, progress=conditions.append)
    except OutOfTime:
        return out_of_reach(f"computing {what}" if not conditions else "after the first conditions")


def _trig_ring(J: sp.Matrix, thetas, parameter_atom, bad_entry):
    """The ring of J's entries (s_i = sin θ_i, c_i = cos θ_i, prismatic θ_j, parameters) and J as given or,
    when that is not a trigonometric polynomial (θ next to sin θ, unexpanded products), J expanded: terms
    such as θ·(…) − θ·(…) from a screw's unexpanded entries cancel then. Refused only if both fail."""
    for attempt, M in enumerate((J, None)):
        if M is None:
            M = J.applyfunc(lambda e: sp.expand(sp.cancel(e)) if e.has(*thetas) else e)
        try:
            ring = TrigRing(list(M), thetas, opaque=parameter_atom)
        except NotTrigPolynomial:
            if attempt == 0:
                continue
            for e in M:
                try:
                    TrigRing([e], thetas, opaque=parameter_atom)
                except NotTrigPolynomial:
                    raise bad_entry(e) from None
            raise
        mixed = set(ring.found) & set(ring.variables)  # θ sin θ is not a trigonometric polynomial
        if not mixed:
            return ring, M
        if attempt == 1:
            raise bad_entry(next(e for e in M if mixed & set(TrigRing([e], thetas, opaque=parameter_atom).variables)))
    raise AssertionError  # pragma: no cover


class _Reported(list):
    """The conditions found so far: each one added is handed to the caller at once (kinlib.budget.report), whose
    progress callback adds it to ``found`` (the list the caller's partial answer is made from)."""

    def __init__(self, found: list):
        super().__init__(found)

    def append(self, cond):
        super().append(cond)
        report(cond)


def _singular_set(J, thetas, deadline, parameter_atom, bad_entry, conditions, key, out_of_reach, what):
    joint_set = set(thetas)
    ring, J = _trig_ring(J, thetas, parameter_atom, bad_entry)
    revolute = set(ring.found)  # joints inside sin/cos; the others enter polynomially
    ctx = {
        "deadline": deadline,
        "thetas": thetas,
        "joint_set": joint_set,
        "revolute": revolute,
        "kinds": generator_kinds(ring),
    }

    def add(cond):
        if cond not in conditions:
            conditions.append(cond)

    Jp = [ring.normal_form(e) for e in J]
    try:
        minors = _maximal_minors(Jp, J.shape, ring, deadline)
    except _OutOfTime:
        return out_of_reach(f"computing {what}")
    minors = [q for q in minors if ring.reduce(q)]
    if not minors:
        raise ValueError(
            "J never has full rank (its rank-test determinant is identically zero): every configuration is singular"
        )
    try:
        G = minors[0]
        for q in minors[1:]:
            if G.is_ground:
                break
            G = G.gcd(q)
            if clock() > deadline:
                raise _OutOfTime
    except _OutOfTime:
        return out_of_reach(f"the gcd of {what}")
    except Exception:  # noqa: BLE001  (a gcd SymPy cannot take, e.g. over an algebraic domain: no common part)
        G = ring.ring.one
    _factor_conditions(G, ring, ctx, add)
    if clock() > deadline:
        return out_of_reach(f"factoring {what}")
    note = f"from the factors of {'det J' if J.rows == J.cols else 'the gcd of ' + what}"
    qs = []
    for q in minors:
        q = ring.reduce(q.exquo(G) if not G.is_ground else q)
        if not any(q == p or q == -p for p in qs):
            qs.append(q)
    if qs and not any(q.is_ground for q in qs) and not any(proves_nonzero(ring, q, ctx["kinds"]) for q in qs):
        # lower-dimensional part: all q_i = 0 together
        total = sum(len(q.terms()) for q in qs)
        S = None
        if sum(len(q.terms()) ** 2 for q in qs) <= 1_000_000:  # Σ q_i² > 0 proved: no common zero
            S = ring.reduce(sum((q * q for q in qs), ring.ring.zero))
        if S is not None and proves_nonzero(ring, S, ctx["kinds"]):
            pass
        else:
            sol = _solve_system(qs, ring, ctx)
            if sol is not None:
                for d in sol:
                    add(
                        {
                            j: periodic_family(sorted(v, key=float)) if j in revolute else sp.FiniteSet(*v)
                            for j, v in sorted(d.items(), key=lambda kv: thetas.index(kv[0]))
                        }
                    )
                note += "; where all of them vanish together: solved joint by joint"
            elif clock() > deadline:
                return out_of_reach("the common zeros of the minors")
            elif total <= 2000:
                add(sp.Add(*[_display_condition(q, ring, deadline) ** 2 for q in qs]))
                note += "; the sum of squares is zero exactly where the minors (divided by their gcd) vanish together"
            else:
                return out_of_reach("the common zeros of the minors are too large for a closed form")
    return SingularSet(sorted(conditions, key=key), complete=True, note=note)


def representatives(family: sp.Set, lo=0, hi=2 * sp.pi) -> list:
    """The members of a family of joint values in [lo, hi) (sorted, exact): e.g. θ2 = −π/4 + kπ → [3π/4, 7π/4].

    >>> import sympy as sp
    >>> representatives(periodic_family([3 * sp.pi / 4, 7 * sp.pi / 4]))   # θ = −π/4 + kπ in [0, 2π)
    [3*pi/4, 7*pi/4]
    >>> representatives(periodic_family([0, sp.pi]), -sp.pi, sp.pi)
    [-pi, 0]
    """
    lo, hi = sp.sympify(lo), sp.sympify(hi)
    if not isinstance(family, sp.Set):
        raise TypeError(f"family must be a SymPy Set, got {describe(family)}")
    if not (lo.is_number and hi.is_number and float(lo) < float(hi)):
        raise ValueError(f"need numbers lo < hi, got lo={lo}, hi={hi}")
    out = []
    parts = family.args if isinstance(family, sp.Union) else (family,)
    for part in parts:
        if isinstance(part, sp.FiniteSet):
            out += [p for p in part if p.is_number and float(lo) <= float(p) < float(hi)]
        elif isinstance(part, sp.ImageSet) and part.base_sets == (sp.S.Integers,):
            lam = part.lamda
            (k,) = lam.variables
            expr = lam.expr
            b, p = expr.subs(k, 0), sp.expand(expr - expr.subs(k, 0)).coeff(k)
            if not (b.is_number and p.is_number and p != 0) or sp.expand(b + p * k - expr) != 0:
                raise ValueError(f"family must be {{b + p k}} with numbers b, p; got {part}")
            k0 = int(np.floor(float((lo - b) / p))) - 1
            k1 = int(np.ceil(float((hi - b) / p))) + 1
            for kk in range(min(k0, k1), max(k0, k1) + 1):
                v = b + p * kk
                if float(lo) - 1e-12 <= float(v) < float(hi) - 1e-12:
                    out.append(v)
        elif part is sp.S.EmptySet:
            continue
        else:
            raise ValueError(
                f"family must be a FiniteSet, an ImageSet over the integers or a Union of them; got {part}"
            )
    return sorted(set(out), key=lambda v: float(v))


# ---------------------------------------------------------------------------------------------------
# numeric search (any arm; finds points, proves nothing)
# ---------------------------------------------------------------------------------------------------


class SingularPoints(NamedTuple):
    """The configurations found (rows of ``q``, shape (K, n)) and σ_min there (``sigma``, shape (K,)).

    >>> from kinlib import robots
    >>> pts = find_singularities(robots.planar_3r(1, 1, 1), ["vx", "vy"], samples=20)
    >>> pts.q.shape[1], len(pts.q) == len(pts.sigma), bool(np.all(pts.sigma < 1e-6))
    (3, True, True)
    """

    q: np.ndarray
    sigma: np.ndarray


def _positive_number(x: Any, name: str) -> float:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Real, np.floating, np.integer)):
        raise TypeError(f"{name} must be a positive number, got {describe(x)}")
    x = float(x)
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {x!r}")
    return x


def _count(x: Any, name: str, minimum: int = 1) -> int:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {describe(x)}")
    if int(x) < minimum:
        raise ValueError(f"{name} must be at least {minimum}, got {int(x)}")
    return int(x)


def _smallest(J: np.ndarray):
    """σ_k, u_k, v_k of each J in a batch (N, m, n), k = min(m, n)."""
    U, s, Vt = np.linalg.svd(J)
    k = min(J.shape[1:]) - 1
    return s[:, k], U[:, :, k], Vt[:, k, :]


def find_singularities(
    chain,
    rows: Any = None,
    *,
    tol: float = 1e-6,
    seed: int = 0,
    samples: int = 200,
    max_iter: int = 60,
    limits: Any = None,
) -> SingularPoints:
    """Configurations of ``chain`` where σ_min(J(θ)) < ``tol``: a numeric search (see the module docstring).

    J is the **geometric** Jacobian [ω_s; ṗ] (``chain.jacobian_geometric``), all six rows by default; with
    all six rows its rank is that of J_s and J_b (J = [[I, 0], [−[p], I]] J_s), so the singular
    configurations are the same. ``rows`` picks task rows as in :func:`kinlib.taskspace.task_rows`
    (e.g. ``["vx", "vy"]`` for a planar arm's tool position ṗ): rows of the geometric J.

    ``samples`` seeded random starts (``numpy.random.default_rng(seed)``: same seed, same output), revolute
    joints uniform in [−π, π), prismatic ones in ``limits`` (default ±(1 + |p_home|)); ``limits`` may give
    (lo, hi) per joint. Returns :class:`SingularPoints` ``(q, sigma)``: the distinct configurations found
    (revolute values wrapped to (−π, π], duplicates within 1e-3 merged), sorted, with σ_min at each
    (every one < tol). Needs numeric link lengths (``chain.subs(L=1)``).

    >>> from kinlib import robots
    >>> q, sigma = find_singularities(robots.planar_3r(1, 1, 1), ["vx", "vy"], samples=40)
    >>> bool(np.all(sigma < 1e-6)) and bool(np.allclose(np.sin(q[:, 1]) * np.sin(q[:, 2]), 0, atol=1e-5))
    True
    """
    from ..kinematics.chains import SerialChain

    if not isinstance(chain, SerialChain):
        raise TypeError(f"chain must be a kinlib SerialChain, got {describe(chain)}")
    if chain.params:
        raise ValueError(
            f"chain must have numeric link lengths; {chain.name} has the parameters "
            f"{', '.join(map(str, chain.params))}: use chain.subs({chain.params[0]}=...) first"
        )
    tol = _positive_number(tol, "tol")
    samples = _count(samples, "samples")
    max_iter = _count(max_iter, "max_iter", 0)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (numbers.Integral, np.integer)):
        raise TypeError(f"seed must be an integer, got {describe(seed)}")
    n = chain.n
    revolute = np.array([t == "R" for t in chain.joint_types])
    home = np.asarray(np.array(chain.M[:3, 3], dtype=float)).ravel()
    reach = 1.0 + float(np.linalg.norm(home))
    lo = np.where(revolute, -np.pi, -reach)
    hi = np.where(revolute, np.pi, reach)
    if limits is not None:
        try:
            lim = np.asarray(limits, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"limits must be (lo, hi) per joint, shape ({n}, 2), got {describe(limits)}") from None
        if lim.shape != (n, 2) or not np.all(np.isfinite(lim)) or np.any(lim[:, 0] >= lim[:, 1]):
            raise ValueError(
                f"limits must be finite (lo, hi) with lo < hi for each of the {n} joints, "
                f"shape ({n}, 2), got {describe(limits)}"
            )
        lo, hi = lim[:, 0], lim[:, 1]

    def jac(Q):
        Jb = chain.jacobian_geometric(np.ascontiguousarray(Q, dtype=float))
        return Jb if rows is None else task_rows(Jb, rows)

    if rows is not None:
        jac(np.zeros((1, n)))  # check rows early: a clear error from task_rows
    rng = np.random.default_rng(int(seed))
    Q = lo + (hi - lo) * rng.random((samples, n))
    h = 1e-6
    eye = np.eye(n) * h
    active = np.ones(samples, bool)
    sig = _smallest(jac(Q))[0]
    for _ in range(max_iter):
        idx = np.flatnonzero(active & (sig > tol * 1e-3))
        if idx.size == 0:
            break
        P = Q[idx]
        s, u, v = _smallest(jac(P))
        shifted = np.concatenate([P[:, None, :] + eye[None], P[:, None, :] - eye[None]], axis=1).reshape(-1, n)
        dJ = jac(shifted)
        dJ = dJ.reshape(idx.size, 2, n, *dJ.shape[1:])  # (N, ±, joint j, m, n)
        dJ = (dJ[:, 0] - dJ[:, 1]) / (2 * h)  # (N, n_j, m, n)
        g = np.einsum("pm,pjmn,pn->pj", u, dJ, v)
        gg = np.sum(g * g, axis=1)
        ok = gg > 1e-300
        step = -(s / np.where(ok, gg, 1.0))[:, None] * g
        norm = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, 0.5 / np.maximum(norm, 1e-300))[:, None]
        alphas = np.array([1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125])
        trial = P[:, None, :] + alphas[None, :, None] * step[:, None, :]
        st = _smallest(jac(trial.reshape(-1, n)))[0].reshape(idx.size, alphas.size)
        best = np.argmin(st, axis=1)
        better = (st[np.arange(idx.size), best] < s) & ok
        Q[idx[better]] = trial[np.flatnonzero(better), best[better]]
        sig[idx] = np.where(better, st[np.arange(idx.size), best], s)
        active[idx[~better]] = False
    Q = np.where(revolute, (Q + np.pi) % (2 * np.pi) - np.pi, Q)
    Q = np.where(revolute & np.isclose(Q, -np.pi, atol=1e-12), np.pi, Q)
    keep = sig < tol
    Q, sig = Q[keep], sig[keep]
    order = np.lexsort(np.round(Q, 6).T[::-1])
    Q, sig = Q[order], sig[order]
    chosen: list[int] = []
    for i in range(len(Q)):
        d = Q[chosen] - Q[i] if chosen else np.zeros((0, n))
        d = np.where(revolute, (d + np.pi) % (2 * np.pi) - np.pi, d)
        if not chosen or np.min(np.linalg.norm(d, axis=1)) > 1e-3:
            chosen.append(i)
    return SingularPoints(Q[chosen], sig[chosen])
