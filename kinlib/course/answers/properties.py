"""Open-ended answers graded by the property asked (the grader's side, trusted process), never by one design's value.

A ``property`` answer (kind "property:<name>" in the grader; declared by ``properties`` in the solution cell's
metadata, see :func:`kinlib.course.schema.grading_kind`) crosses the kernel boundary as a JSON expression tree
(:func:`kinlib.course.grader.in_kernel.probe.expr_tree`), rebuilt here by :func:`from_tree` from a whitelist (never ``eval``),
with bounded size, so a hostile tree cannot run code or exhaust the grader. :data:`PROPERTIES` maps each
property to its decision, ``(ok, message)``; the message talks about the student's own answer only.

:func:`exact_ranks` compares constant exact subspaces exactly (:func:`kinlib.course.answers.compare.compare_subspace`).

* ``nonsingular`` (problem 5.5): det(J Jᵀ) of the student's redesign (or its task Jacobian J) is nonzero for
  every joint value, proved exactly by :func:`kinlib.singularities.singular_configurations` (trigonometric
  normal forms, :mod:`kinlib.trigsign` proofs of non-vanishing).
"""

from __future__ import annotations

import math

__all__ = ["from_tree", "exact_ranks", "nonsingular", "PROPERTIES", "MAX_TERMS_ESTIMATE"]

MAX_TERMS_ESTIMATE = 50_000  # a bound on the terms of det(J Jᵀ) expanded (see _terms_estimate)


def from_tree(t, syms: dict | None = None, budget: list | None = None):
    """Rebuild a student's expression from its JSON tree (``probe.expr_tree``) by a whitelist, never ``eval``:
    numbers (at most 60 digits), symbols (real, or positive as declared), π, +, ×, powers with small exact
    exponents, sin/cos/tan. Anything else raises ValueError. ``syms`` collects the symbols made (one per name and
    assumption), ``budget`` ([nodes left]) bounds the size.

    >>> from_tree(["add", ["rat", "1", "2"], ["fn", "cos", ["sym", "theta1", False]]])
    cos(theta1) + 1/2
    >>> from_tree(["call", "__import__", "os"])
    Traceback (most recent call last):
    ...
    ValueError: 'call' is not supported here
    """
    import sympy as sp

    syms = {} if syms is None else syms
    budget = [20_000] if budget is None else budget
    budget[0] -= 1
    if budget[0] < 0:
        raise ValueError("the expression is too large")
    if not isinstance(t, list) or not t or not isinstance(t[0], str):
        raise ValueError("malformed expression")
    op, args = t[0], t[1:]

    def digits(x):
        if not isinstance(x, str) or not 0 < len(x) <= 60 or not x.lstrip("-").isdigit():
            raise ValueError("malformed number")
        return int(x)

    if op == "int" and len(args) == 1:
        return sp.Integer(digits(args[0]))
    if op == "rat" and len(args) == 2:
        q = digits(args[1])
        if q == 0:
            raise ValueError("malformed number")
        return sp.Rational(digits(args[0]), q)
    if op == "float" and len(args) == 1 and isinstance(args[0], str) and len(args[0]) <= 40:
        x = float(args[0])
        if not math.isfinite(x):
            raise ValueError("not a finite number")
        return sp.Rational(x)  # its exact binary value (as kinlib.trigpoly takes floats)
    if op == "pi" and not args:
        return sp.pi
    if op == "sym" and len(args) == 2 and isinstance(args[0], str) and 0 < len(args[0]) <= 40:
        key = (args[0], bool(args[1]))
        if key not in syms:
            syms[key] = sp.Symbol(args[0], positive=True) if args[1] else sp.Symbol(args[0], real=True)
        return syms[key]
    if op in ("add", "mul") and args:
        parts = [from_tree(a, syms, budget) for a in args]
        return sp.Add(*parts) if op == "add" else sp.Mul(*parts)
    if op == "pow" and len(args) == 2:
        base, exp = from_tree(args[0], syms, budget), from_tree(args[1], syms, budget)
        if not (exp.is_Rational and abs(exp.p) <= 12 and exp.q <= 2):
            raise ValueError("a power that is not a small whole number or half")
        return sp.Pow(base, exp)
    if op == "fn" and len(args) == 2 and args[0] in ("sin", "cos", "tan"):
        return getattr(sp, args[0])(from_tree(args[1], syms, budget))
    raise ValueError(f"{op!r} is not supported here")


def exact_ranks(stu_tree, ref_tree):
    """(rank A, rank B, rank [A B]) computed exactly for two constant exact matrices given as expression trees
    (``probe.expr_tree``; both sides must have one), or None (then the spans are compared numerically): when
    a tree is missing or malformed, has symbols, or SymPy cannot decide whether a pivot is zero. Equal spans ⇔
    rank A = rank B = rank [A B].

    >>> col = lambda *xs: ["matrix", len(xs), 1, *[["int", str(x)] for x in xs]]
    >>> exact_ranks(col(1, 0, 10**30), col(0, 0, 1)), exact_ranks(col(1, 0), ["sym", "x", False])
    ((1, 1, 2), None)
    """
    import sympy as sp

    if not (isinstance(stu_tree, list) and isinstance(ref_tree, list)):
        return None
    mats = []
    try:
        for t in (stu_tree, ref_tree):
            if t[:1] != ["matrix"] or len(t) < 3 or not all(isinstance(x, int) and 0 < x <= 12 for x in t[1:3]):
                return None
            if len(t) != 3 + t[1] * t[2]:
                return None
            budget = [600]
            M = sp.Matrix(t[1], t[2], [from_tree(x, {}, budget) for x in t[3:]])
            if M.free_symbols:
                return None
            mats.append(M)
    except (ValueError, TypeError, RecursionError):
        return None
    A, B = mats
    if A.rows != B.rows:
        return None
    unsure = []

    def iszero(x):
        z = sp.sympify(x).equals(0)
        if z is None:
            unsure.append(x)
        return bool(z)

    ranks = tuple(M.rank(iszerofunc=iszero) for M in (A, B, A.row_join(B)))
    return None if unsure else ranks


def _terms_estimate(e) -> float:
    """A crude bound on the number of terms of e expanded as a polynomial in sines and cosines."""
    if e.is_Atom:
        return 1.0
    if e.is_Add:
        return sum(_terms_estimate(a) for a in e.args)
    if e.is_Mul:
        return math.prod(_terms_estimate(a) for a in e.args)
    if e.is_Pow:
        k = int(abs(e.exp)) if e.exp.is_Integer else 1
        return min(_terms_estimate(e.base) ** max(k, 1), 1e300)
    # sin/cos/tan of a sum of integer multiples of angles: expanded by kinlib.trigpoly.single_angle_form
    arg = e.args[0]
    weight = sum(abs(int(c)) if c.is_Integer else 1 for c, _ in (a.as_coeff_Mul() for a in arg.as_ordered_terms()))
    return min(float(2 ** min(weight, 1000)), 1e300)


def _where(conds) -> str:
    """Singular conditions as text: one-joint families merged (θ2 = 0, π (+ 2πk)), others as given."""
    import sympy as sp

    from kinlib.singularities import representatives

    merged: dict = {}
    texts = []
    for c in conds:
        if isinstance(c, dict) and len(c) == 1:
            ((v, S),) = c.items()
            try:
                reps = representatives(S) if isinstance(S, (sp.ImageSet, sp.Union)) else None
            except (TypeError, ValueError):
                reps = None
            if reps:
                merged.setdefault(v, []).extend(r for r in reps if r not in merged.get(v, []))
                continue
        if isinstance(c, dict):
            texts.append(" and ".join(f"{v} ∈ {sp.sstr(S)}" for v, S in c.items()))
        else:
            texts.append(f"{sp.sstr(c)} = 0")
    for v, reps in merged.items():
        reps = sorted(reps, key=float)
        texts.insert(0, f"{v} = {', '.join(sp.sstr(x) for x in reps[:6])} (+ 2πk)")
    return "; or ".join(texts[:3])


def _never_zero(M, what: str):
    """(True, None) when det M ≠ 0 for every real value of M's non-positive symbols (its joint values) is
    proved by :func:`kinlib.singularities.singular_configurations` (no condition, complete); else
    (False, message). For a non-square M (m < n) the rank test is det(M Mᵀ) (Cauchy–Binet)."""
    import sympy as sp

    from kinlib.singularities import singular_configurations

    variables = sorted((s for s in M.free_symbols if not s.is_positive), key=lambda s: s.name)
    if len(variables) > M.cols:
        return False, f"{what} could not be decided (more joint variables than joints)"
    thetas = variables + [sp.Symbol(f"_joint{k}", real=True) for k in range(M.cols - len(variables))]
    try:
        conds = singular_configurations(M, thetas, time_budget=8.0)
    except ValueError as exc:
        if "never has full rank" in str(exc):
            return False, f"{what} is 0 for every θ: every configuration of your design is singular"
        return False, (
            f"{what} could not be decided exactly: give it as a polynomial in the sines and cosines of the "
            "joint angles and in the joint values (no θ·sin θ, √θ, exp …)"
        )
    if conds:
        return False, f"{what} = 0 where {_where(conds)}: your design still has singular configurations"
    if not conds.complete:
        return False, f"{what} could not be proved nonzero within the time limit (an instructor will check it)"
    return True, None


def nonsingular(stu: dict, name: str) -> tuple[bool, str]:
    """det(J Jᵀ) ≠ 0 for every joint value, decided exactly: the answer is det(J Jᵀ) itself (a scalar) or the
    task Jacobian J. Proofs by :func:`kinlib.singularities.singular_configurations` (on J, or on the diagonal
    matrix diag(det(J Jᵀ), 1, …) whose determinant it is): no condition and complete ⇔ never 0.

    >>> nonsingular({"tree": ["add", ["int", "2"], ["fn", "sin", ["sym", "theta1", False]]]}, "d")
    (True, 'det(J Jᵀ) ≠ 0 for every joint value: proved')
    >>> nonsingular({"tree": ["fn", "sin", ["sym", "theta1", False]]}, "d")[1]
    'd: det(J Jᵀ) = 0 where theta1 = 0, pi (+ 2πk): your design still has singular configurations'
    """
    import sympy as sp

    syms: dict = {}
    tree = stu["tree"]
    what = f"{name}: det(J Jᵀ)"
    if isinstance(tree, list) and tree[:1] == ["matrix"]:
        if len(tree) < 3 or not all(isinstance(x, int) and 0 < x <= 12 for x in tree[1:3]):
            return False, f"{name} could not be read (malformed matrix)"
        r, c = tree[1], tree[2]
        if len(tree) != 3 + r * c:
            return False, f"{name} could not be read (malformed matrix)"
        budget = [20_000]
        J = sp.Matrix(r, c, [from_tree(x, syms, budget) for x in tree[3:]])
        if r > c:
            return False, f"{what} is 0 everywhere: your J has more rows ({r}) than columns ({c}): J Jᵀ is singular"
        if any(_terms_estimate(e) > MAX_TERMS_ESTIMATE for e in J):
            return False, f"{what} is too large to decide exactly: simplify J (kinlib.trig_simplify) and try again"
        if any(sp.fraction(sp.together(e))[1].free_symbols - {v for v in syms.values() if v.is_positive} for e in J):
            return False, f"{what} could not be decided exactly: J has fractions in the joint variables"
        ok, msg = _never_zero(J, what)
        return (True, "det(J Jᵀ) ≠ 0 for every joint value: proved") if ok else (False, msg)
    D = from_tree(tree, syms, [20_000])
    if _terms_estimate(D) > 4 * MAX_TERMS_ESTIMATE:
        return False, f"{what} is too large to decide exactly: simplify it (kinlib.trig_simplify) and try again"
    num, den = sp.fraction(sp.together(D))
    for part, label in ((num, what), (den, f"{what} has a denominator that")):
        if part.free_symbols - {v for v in syms.values() if v.is_positive}:
            nv = len([s for s in part.free_symbols if not s.is_positive])
            ok, msg = _never_zero(sp.diag(part, *[1] * (nv - 1)), label)
            if not ok:
                return False, msg
        elif part == 0:
            return False, f"{what} is 0 for every θ: every configuration of your design is singular"
    # nonzero on a connected set of values, hence of one sign: one value tells which
    at = {s: (sp.Integer(1) if s.is_positive else sp.Rational(1, 3)) for s in D.free_symbols}
    val = sp.N((num / den).xreplace(at), 30)
    if val.is_real and val < 0:
        return False, f"{what} is negative for every θ, but det(J Jᵀ) ≥ 0 for every matrix J: check it"
    return True, "det(J Jᵀ) ≠ 0 for every joint value: proved"


PROPERTIES = {"nonsingular": nonsingular}
