"""The ``property:<p>`` kind: an open-ended answer graded by the property asked, never by one design's value.

A ``property`` answer (kind "property:<name>" in the grader; declared by ``properties`` in the solution cell's
metadata, see :func:`kinlib.course.schema.grading_kind`) is the student's own design (problem 5.5: "your redesign
has no singular configuration").

* **normalise** (:func:`property_answer`): a robot (any object with a 6×n ``screws`` matrix, a kinlib
  ``SerialChain``, found by duck typing: :func:`robot_screws`), its task Jacobian as a matrix, or an expression,
  as its exact tree (:func:`kinlib.course.answers.wire.exact_dump`: the wire format's exact subset).
* **wire form**: ``robot`` (only its screw axes cross the kernel boundary), ``Matrix``, SymPy expressions.
* **describe** (:func:`describe_property`): the exact tree (and, for a matrix or an expression, its values).
* **compare** (:func:`compare_property` → :func:`judge`): :data:`PROPERTIES` maps each property to its decision,
  ``(ok, message)``, on the tree read back by the wire format's parser (:func:`~.wire.exact_load`, never ``eval``); the
  message talks about the student's own answer only. The reference is not used (:func:`reference_property`).

* ``nonsingular`` (problem 5.5): the student's redesigned robot (the judge computes its J from its screw axes)
  has det(J Jᵀ) ≠ 0 for every joint value, proved exactly by
  :func:`kinlib.singularities.singular_configurations` (trigonometric normal forms, :mod:`kinlib.trigsign`
  proofs of non-vanishing). A bare value of det(J Jᵀ), or a bare matrix (``sp.eye(3)``: any constant invertible
  matrix), belongs to no robot and is refused, saying so; a failing design is told it has singular
  configurations, never where (its singular set may be another part's answer: 5.1's, 7.2's).

The same judges serve the workbook self-check (:func:`kinlib.course.workbook.selfcheck.verdict`, spec
``property|nonsingular|-``: :func:`property_spec`, :func:`property_verdict`) and the grader.
"""

from __future__ import annotations

import math
import numbers

import numpy as np
import sympy as sp

from .base import not_answered, type_name
from .expr import describe_expr, to_sympy
from .wire import exact_dump, exact_load

__all__ = [
    "robot_screws",
    "property_answer",
    "describe_property",
    "compare_property",
    "reference_property",
    "nonsingular",
    "judge",
    "PROPERTIES",
    "MAX_TERMS_ESTIMATE",
    "MAX_ROBOT_JOINTS",
    "judge_value",
    "property_spec",
    "property_verdict",
    "home_spec",
    "home_verdict",
    "stub_words",
]

MAX_TERMS_ESTIMATE = 50_000  # a bound on the terms of det(J Jᵀ) expanded (see _terms_estimate)


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


def _never_zero(M, what: str):
    """(True, None) when det M ≠ 0 for every real value of M's non-positive symbols (its joint values) is
    proved by :func:`kinlib.singularities.singular_configurations` (no condition, complete); else
    (False, message). For a non-square M (m < n) the rank test is det(M Mᵀ) (Cauchy–Binet)."""
    from kinlib.analysis.singularities import singular_configurations

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
    if conds:  # where, never: the original robot's singular set is 5.1's answer, the 4R arm's 7.2's
        return False, (
            f"{what} is 0 at some joint values: your design still has singular configurations (find them with "
            "kinlib.singular_configurations on your robot's task Jacobian)"
        )
    if not conds.complete:
        return False, f"{what} could not be proved nonzero within the time limit (an instructor will check it)"
    return True, None


_NOT_A_ROBOT = (
    "{name} is a number or an expression: the answer is your redesigned robot itself, a kinlib SerialChain (its "
    "screw axes and M: SerialChain(screws, M)); a value of det(J Jᵀ) alone belongs to no robot"
)
_A_MATRIX = (
    "{name} is a matrix: the answer is your redesigned robot itself, a kinlib SerialChain (its screw axes and M: "
    "SerialChain(screws, M)); a matrix (a Jacobian, sp.eye(3)) alone belongs to no robot: the judge computes J "
    "from your robot's screw axes"
)
MAX_ROBOT_JOINTS = 6  # a redesign with more joints is not decided here (the proof's cost grows fast)


def _matrix(tree, name: str):
    """A matrix read back from its exact tree (:func:`~.wire.exact_load`), or a message (str) saying why not."""
    if len(tree) < 3 or not all(isinstance(x, int) and 0 < x <= 12 for x in tree[1:3]):
        return f"{name} could not be read (malformed matrix)"
    M = exact_load(tree)
    return M if isinstance(M, sp.MatrixBase) else f"{name} could not be read (malformed matrix)"


def _robot_task_jacobian(S, name: str):
    """The task rows (ω_z, v_x, v_y) of the space Jacobian of the planar robot with screw axes S (6×n), or a
    message (str) saying why the robot cannot be judged: not planar, not valid screws, too many joints."""
    from kinlib.kinematics.jacobians import jacobian_space

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
    exactly for **their robot**. The answer (:func:`property_answer`) is the robot (tag
    "robot": its space screw axes, 6×n; the judge computes J_s from them, :func:`kinlib.jacobians.jacobian_space`,
    and takes its task rows ω_z, v_x, v_y; the robot must be planar). A matrix, number or expression alone (a
    claimed J or det(J Jᵀ), e.g. sp.eye(3) or 1) is refused: it belongs to no robot. Proofs by
    :func:`kinlib.singularities.singular_configurations` on J: no condition and complete ⇔ never singular.

    >>> rpp = ["Matrix", 6, 3, *[["Integer", str(x)] for x in (0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0)]]
    >>> nonsingular({"tag": "robot", "tree": rpp}, "redesign")
    (True, 'det(J Jᵀ) ≠ 0 for every joint value: proved')
    >>> nonsingular({"tag": "scalar", "tree": ["Integer", "1"]}, "redesign")[0]
    False
    """
    tree = stu.get("tree")
    tag = stu.get("tag")
    if not isinstance(tree, list) or tree[:1] != ["Matrix"]:
        return False, _NOT_A_ROBOT.format(name=name)
    M = _matrix(tree, name)
    if isinstance(M, str):
        return False, M
    if tag != "robot":  # a bare matrix (sp.eye(3): any constant invertible matrix) is no robot
        return False, _A_MATRIX.format(name=name)
    if M.rows != 6:
        return False, f"{name}: a robot's screw axes are 6-vectors, got {M.rows} rows"
    J = _robot_task_jacobian(M, name)
    if isinstance(J, str):
        return False, J
    return _judge_task_jacobian(J, {s.name: s for s in M.free_symbols}, name, f"{name}: det(J Jᵀ) of your robot")


PROPERTIES = {"nonsingular": nonsingular}


def judge(prop: str, stu: dict, name: str) -> tuple[bool, str]:
    """``(ok, message)``: the property ``prop`` of :data:`PROPERTIES` judged on the answer description ``stu``
    (:func:`property_answer`); never raises.

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
    :func:`property_answer` exactly as the grader's kernel describes it.

    >>> judge_value("nonsingular", 1, "redesign")[0]
    False
    """
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


def robot_screws(value):
    """The space screw axes (a 6×n SymPy Matrix, one per column) of a robot answer, or None when ``value`` is
    not a robot: any object, not itself a matrix, number, container or SymPy object, whose ``screws``
    attribute is a 6×n matrix (a kinlib ``SerialChain``; duck typing, never an import of kinlib).

    >>> class Arm:
    ...     screws = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]]).T
    >>> robot_screws(Arm()).shape, robot_screws(sp.eye(6)), robot_screws([1, 2])
    ((6, 2), None, None)
    """
    if isinstance(value, (sp.Basic, sp.MatrixBase, np.ndarray, list, tuple, dict, set, str, bytes, numbers.Number)):
        return None
    try:
        screws = getattr(value, "screws", None)
    except Exception:  # noqa: BLE001  (a property that raises: not a robot)
        return None
    if screws is None:
        return None
    tag, S = to_sympy(screws)
    if tag != "matrix" or S.rows != 6 or not 1 <= S.cols <= 12:
        return None
    return S


def property_answer(value) -> dict:
    """An answer judged by a property of the student's own design (problem 5.5: "your redesign has no singular
    configuration") as plain JSON data for the judge (:mod:`kinlib.course.answers.properties`): ``{"tag": "robot",
    "tree": …}`` for a robot (its screw axes, :func:`robot_screws`), ``{"tag": "matrix"|"scalar", "tree": …}``
    for a matrix (its task Jacobian) or an expression, with the exact tree (:func:`~.wire.exact_dump`); ``tree_error`` says
    why there is none; other tags as :func:`to_sympy`.

    >>> property_answer(sp.Matrix([[1, 0], [0, 1]]))["tree"][:3]
    ['Matrix', 2, 2]
    >>> property_answer(...)["tag"], property_answer("robot")["tag"]
    ('ellipsis', 'other')
    """
    S = robot_screws(value)
    if S is not None:
        tag, obj = "robot", S
    else:
        tag, obj = to_sympy(value)
    out = {"tag": tag, "type": type_name(value)}
    if obj is not None:
        try:
            out["tree"] = exact_dump(obj)
        except Exception as exc:  # noqa: BLE001  (any failure is reported, not raised)
            out["tree_error"] = str(exc)[:200]
    return out


def describe_property(value, points, seed=0):
    """An answer graded by a property (``kind`` "property:<name>"): a robot as its screw axes' exact tree
    (:func:`property_answer`), anything else described as an expression plus its exact expression tree
    (:func:`~.wire.exact_dump`), for the grader's proof.

    >>> describe_property(sp.Rational(1, 2), [{}])["tree"]
    ['Rational', '1', '2']
    """
    prop = property_answer(value)  # a robot (its screw axes), a matrix or an expression, as a tree
    if prop["tag"] == "robot":
        return prop
    out = describe_expr(value, points, seed)
    out.update({k: v for k, v in prop.items() if k in ("tree", "tree_error")})
    return out


def compare_property(stu: dict, ref: dict, name: str, prop: str = "nonsingular") -> tuple[bool, str]:
    """An open-ended answer graded by the property asked, never by one design's value (the reference is not
    used): :func:`kinlib.course.answers.properties.judge`. ``prop``: "nonsingular": the answer is the student's own
    redesigned robot, whose det(J Jᵀ) must be nonzero for every joint value, proved
    exactly (kinlib.singularities); a bare value of det(J Jᵀ) belongs to no robot and fails.

    >>> compare_property({"tag": "scalar", "tree": ["Integer", "1"]}, {}, "d")[0]
    False
    >>> col = lambda *xs: [["Integer", str(x)] for x in xs]
    >>> three_r = col(0, 0, 0, 0, 0, 0, 1, 1, 1, 0, 0, 0, 0, -1, -2, 0, 0, 0)   # joints at x = 0, 1, 2
    >>> compare_property({"tag": "robot", "tree": ["Matrix", 6, 3, *three_r]}, {}, "d")[1][:58]
    'd: det(J Jᵀ) of your robot is 0 at some joint values: your'
    >>> compare_property({"tag": "matrix", "tree": ["Matrix", 1, 1, ["Integer", "1"]]}, {}, "d")[1][:42]
    'd is a matrix: the answer is your redesign'
    """
    na = not_answered(stu)
    if na:
        return False, f"{name} {na}"
    return judge(prop, stu, name)


def reference_property(value):
    """The reference value of a property answer, kept as data only (the property alone judges): a robot's screw
    axes, or the value as a SymPy object (0 when it is none).

    >>> from kinlib.robots import planar_rpp
    >>> reference_property(planar_rpp()).shape, reference_property("x")
    ((6, 3), 0)
    """
    screws = robot_screws(value)
    if screws is not None:
        return screws
    obj = to_sympy(value)[1]
    return obj if obj is not None else sp.Integer(0)


# ----------------------------------------------------------------------------------------- the self-check
# The workbook's side of the kind (kinlib.course.workbook.selfcheck): the spec names the property only
# (property_spec), and the student's own design is judged by it, as the grader judges it (property_verdict).


def home_spec(value, prop: str, salt: str = "") -> str:
    """The self-check spec of a ``property:<prop>`` answer (:func:`property_spec`; ``salt`` unused: it holds no
    value to salt).

    >>> from kinlib.robots import planar_rpp
    >>> home_spec(planar_rpp(), "nonsingular")
    'property|nonsingular|-'
    """
    return property_spec(value, prop)


def home_verdict(value, judge) -> tuple[str, str]:
    """The self-check's ``(status, message)``: :func:`property_verdict` of the property the spec names (``judge``:
    a :class:`kinlib.course.answers.fingerprints.Judge`, its shape the property).

    >>> from kinlib.course.answers.fingerprints import Judge
    >>> home_verdict(2, Judge("property", "nonsingular", "-"))[0]
    'incorrect'
    """
    return property_verdict(judge.shape, value)


def stub_words(value) -> str:
    """What a property answer is, for the workbook's stub.

    >>> stub_words(None)
    'your robot itself (a kinlib SerialChain: its screw axes and M)'
    """
    return "your robot itself (a kinlib SerialChain: its screw axes and M)"
