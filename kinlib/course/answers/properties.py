"""Open-ended answers graded by the property asked (the grader's side, trusted process), never by one design's value.

A ``property`` answer (kind "property:<name>" in the grader; declared by ``properties`` in the solution cell's
metadata, see :func:`kinlib.course.schema.grading_kind`) crosses the kernel boundary as a JSON expression tree
(:func:`kinlib.course.grader.in_kernel.probe.expr_tree`), rebuilt here by :func:`from_tree` from a whitelist (never ``eval``),
with bounded size, so a hostile tree cannot run code or exhaust the grader. :data:`PROPERTIES` maps each
property to its decision, ``(ok, message)``; the message talks about the student's own answer only.

:func:`exact_ranks` compares constant exact subspaces exactly (:func:`kinlib.course.answers.compare.compare_subspace`).

* ``nonsingular`` (problem 5.5): the student's redesigned robot (a ``SerialChain``: the judge computes its J from
  its screw axes) or its task Jacobian J has det(J Jᵀ) ≠ 0 for every joint value, proved exactly by
  :func:`kinlib.singularities.singular_configurations` (trigonometric normal forms, :mod:`kinlib.trigsign`
  proofs of non-vanishing). A bare value of det(J Jᵀ) belongs to no robot and is refused.

The same judges serve the workbook self-check (:func:`kinlib.course.workbook.selfcheck.verdict`, spec
``property|nonsingular|-``) and the grader (:func:`kinlib.course.compare.compare_property`).
"""

from __future__ import annotations

import math

__all__ = [
    "from_tree",
    "exact_ranks",
    "nonsingular",
    "judge",
    "PROPERTIES",
    "MAX_TERMS_ESTIMATE",
    "MAX_ROBOT_JOINTS",
    "judge_value",
    "property_spec",
]

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


_NOT_A_ROBOT = (
    "{name} is a number or an expression: give your redesigned robot itself (a kinlib SerialChain, e.g. "
    "SerialChain(screws, M)) or its task Jacobian J (rows ω_z, v_x, v_y) as a Matrix; a value of det(J Jᵀ) "
    "alone does not say which robot it belongs to"
)
MAX_ROBOT_JOINTS = 6  # a redesign with more joints is not decided here (the proof's cost grows fast)


def _matrix(tree, syms: dict, budget: list, name: str):
    """A matrix rebuilt from its tree, or a message (str) saying why not."""
    import sympy as sp

    if len(tree) < 3 or not all(isinstance(x, int) and 0 < x <= 12 for x in tree[1:3]):
        return f"{name} could not be read (malformed matrix)"
    r, c = tree[1], tree[2]
    if len(tree) != 3 + r * c:
        return f"{name} could not be read (malformed matrix)"
    return sp.Matrix(r, c, [from_tree(x, syms, budget) for x in tree[3:]])


def _robot_task_jacobian(S, name: str):
    """The task rows (ω_z, v_x, v_y) of the space Jacobian of the planar robot with screw axes S (6×n), or a
    message (str) saying why the robot cannot be judged: not planar, not valid screws, too many joints."""
    import sympy as sp

    from kinlib.jacobians import jacobian_space

    if S.cols > MAX_ROBOT_JOINTS:
        return f"{name}: a robot of {S.cols} joints is more than this check decides (at most {MAX_ROBOT_JOINTS})"
    off_plane = [i + 1 for i in range(S.cols) if any(sp.simplify(S[k, i]) != 0 for k in (0, 1, 5))]
    if off_plane:
        return (
            f"{name}: joint(s) {', '.join(map(str, off_plane))} move the tool out of the plane (a planar robot's "
            "revolute axes are along z and its slides lie in the xy-plane: screw rows ω_x, ω_y, v_z are 0)"
        )
    thetas = [sp.Symbol(f"theta{i + 1}", real=True) for i in range(S.cols)]
    try:
        Js = jacobian_space(S, thetas)
    except (ValueError, TypeError) as exc:
        return f"{name}: its screw axes are not valid ({str(exc)[:160]})"
    return Js[2:5, :]


def _judge_task_jacobian(J, syms: dict, name: str, what: str) -> tuple[bool, str]:
    import sympy as sp

    r, c = J.shape
    if r == 6:
        return False, f"{name}: give the task rows (ω_z, v_x, v_y) of J, a 3×{c} matrix (task_rows(J, 'planar'))"
    if r > c:
        return False, f"{what} is 0 everywhere: your J has more rows ({r}) than columns ({c}): J Jᵀ is singular"
    if any(_terms_estimate(e) > MAX_TERMS_ESTIMATE for e in J):
        return False, f"{what} is too large to decide exactly: simplify J (kinlib.trig_simplify) and try again"
    positive = {v for v in syms.values() if v.is_positive} | {s for s in J.free_symbols if s.is_positive}
    if any(sp.fraction(sp.together(e))[1].free_symbols - positive for e in J):
        return False, f"{what} could not be decided exactly: J has fractions in the joint variables"
    ok, msg = _never_zero(J, what)
    return (True, "det(J Jᵀ) ≠ 0 for every joint value: proved") if ok else (False, msg)


def nonsingular(stu: dict, name: str) -> tuple[bool, str]:
    """The student's own redesign has no singular configuration: det(J Jᵀ) ≠ 0 for every joint value, decided
    exactly for **their robot**. The answer (:func:`kinlib.course.answers.normalise.property_answer`) is the robot (tag
    "robot": its space screw axes, 6×n; the judge computes J_s from them, :func:`kinlib.jacobians.jacobian_space`,
    and takes its task rows ω_z, v_x, v_y; the robot must be planar) or its task Jacobian J (a 3×n matrix). A
    number or expression alone (a claimed det(J Jᵀ), e.g. 1) is refused: it belongs to no robot. Proofs by
    :func:`kinlib.singularities.singular_configurations` on J: no condition and complete ⇔ never singular.

    >>> rpp = ["matrix", 6, 3, *[["int", str(x)] for x in (0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0)]]
    >>> nonsingular({"tag": "robot", "tree": rpp}, "redesign")
    (True, 'det(J Jᵀ) ≠ 0 for every joint value: proved')
    >>> nonsingular({"tag": "scalar", "tree": ["int", "1"]}, "redesign")[0]
    False
    """
    syms: dict = {}
    tree = stu.get("tree")
    tag = stu.get("tag")
    what = f"{name}: det(J Jᵀ)"
    if not isinstance(tree, list) or tree[:1] != ["matrix"]:
        return False, _NOT_A_ROBOT.format(name=name)
    M = _matrix(tree, syms, [20_000], name)
    if isinstance(M, str):
        return False, M
    if tag == "robot":
        if M.rows != 6:
            return False, f"{name}: a robot's screw axes are 6-vectors, got {M.rows} rows"
        J = _robot_task_jacobian(M, name)
        if isinstance(J, str):
            return False, J
        return _judge_task_jacobian(J, syms, name, f"{name}: det(J Jᵀ) of your robot")
    return _judge_task_jacobian(M, syms, name, what)


PROPERTIES = {"nonsingular": nonsingular}


def judge(prop: str, stu: dict, name: str) -> tuple[bool, str]:
    """``(ok, message)``: the property ``prop`` of :data:`PROPERTIES` judged on the answer description ``stu``
    (:func:`kinlib.course.answers.normalise.property_answer`); never raises.

    >>> judge("nonsingular", {"tag": "ellipsis"}, "redesign")
    (False, 'redesign is not answered yet')
    """
    if stu.get("tag") in ("ellipsis", "none"):
        return False, f"{name} is not answered yet"
    if prop not in PROPERTIES:
        return False, f"{name} could not be judged (unknown property {prop!r}: a problem in the solution notebook)"
    if "tree" not in stu:
        if stu.get("tag") in ("matrix", "scalar", "robot"):
            why = stu.get("tree_error") or "no expression"
            return False, f"{name} could not be read exactly ({why}): use SymPy numbers, symbols, sin and cos"
        return False, _NOT_A_ROBOT.format(name=name).replace("is a number or an expression", f"is a {stu.get('type')}")
    try:
        return PROPERTIES[prop](stu, name)
    except (ValueError, TypeError, RecursionError) as exc:
        return False, f"{name} could not be read exactly ({str(exc)[:120]})"


def judge_value(prop: str, value, name: str) -> tuple[bool, str]:
    """:func:`judge` on a value itself (the workbook self-check's side, in the student's kernel), described by
    :func:`kinlib.course.answers.normalise.property_answer` exactly as the grader's kernel describes it.

    >>> judge_value("nonsingular", 1, "redesign")[0]
    False
    """
    from .normalise import property_answer

    return judge(prop, property_answer(value), name)


def property_spec(value, prop: str) -> str:
    """The self-check spec of an answer judged by a property (kind "property:<p>"): ``"property|<p>|-"``; it holds
    nothing of the reference answer, which must have the property itself (else ValueError: a problem in the
    solution notebook).

    >>> from kinlib.robots import planar_rpp
    >>> property_spec(planar_rpp(), "nonsingular")
    'property|nonsingular|-'
    """
    ok, msg = judge_value(prop, value, "the reference answer")
    if not ok:
        raise ValueError(f"the solution's own answer fails its property {prop!r}: {msg}")
    return f"property|{prop}|-"


def property_verdict(prop: str, value) -> tuple[str, str]:
    """The workbook self-check's ``(status, message)`` for a property answer: correct or incorrect, by
    :func:`judge_value` (the grader's judgement); the message talks about the student's own design only.

    >>> property_verdict("nonsingular", 2)[0]
    'incorrect'
    """
    ok, message = judge_value(prop, value, "your answer")
    return ("correct", f"correct: {message}") if ok else ("incorrect", f"not right yet: {message}")
