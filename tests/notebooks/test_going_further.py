"""Notebook 07 (exercises beyond the problem set) is graded and self-checked like the others (issue 21, item 7).

For every answer of 7.1–7.5 the workbook self-check (:mod:`kinlib.course.workbook.selfcheck`: a fingerprint of the
reference, the student's value checked against it) and the grader (:func:`kinlib.course.answers.describe.describe` of the value exported from the kernel, then
:func:`kinlib.course.answers.compare.compare`, both sides through a JSON round trip as across the kernel boundary) are
fed the right answer, other valid forms of it, and wrong answers (the mistakes a student makes).

The references are written here by hand, independently of kinlib and of the notebook's code: the 2R Jacobian
from plane geometry, the isotropy condition L1 = √2 L2, cos θ2 = −L2/L1 derived on paper, the collinear-joints
sets, τ = Jᵀ F with J written out, the SCARA's columns from its joint points. The test also checks that the
notebook declares these answers, with these kinds, in these parts.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import sympy as sp

from helpers import angle_family as family
from helpers import assert_graded_right_and_wrong
from kinlib.course import schema

ROOT = Path(__file__).resolve().parents[2]
NB = ROOT / "notebooks" / "07_going_further.ipynb"
pi = sp.pi
t1, t2, t3, t4 = sp.symbols("theta1:5", real=True)
L1, L2, L, a, h = sp.symbols("L1 L2 L a h", positive=True)
b, c, Fx, Fy = sp.symbols("b c F_x F_y", real=True)
POINTS = [
    {
        "theta1": 0.3,
        "theta2": -1.1,
        "theta3": 2.0,
        "theta4": 0.4,
        "L1": 1.3,
        "L2": 0.7,
        "L": 1.2,
        "a": 0.9,
        "b": -0.4,
        "c": 1.7,
        "h": 0.8,
        "F_x": 0.6,
        "F_y": -1.4,
    },
    {
        "theta1": -2.0,
        "theta2": 0.7,
        "theta3": -0.5,
        "theta4": 2.5,
        "L1": 0.8,
        "L2": 1.9,
        "L": 0.6,
        "a": 1.4,
        "b": 1.1,
        "c": -0.3,
        "h": 1.5,
        "F_x": -0.9,
        "F_y": 0.2,
    },
]


# by hand: the 2R arm, ṗ = J_v θ̇ with p = (L1 c1 + L2 c12, L1 s1 + L2 s12)
s1, c1, s12, c12 = sp.sin(t1), sp.cos(t1), sp.sin(t1 + t2), sp.cos(t1 + t2)
JV = sp.Matrix([[-L1 * s1 - L2 * s12, -L2 * s12], [L1 * c1 + L2 * c12, L2 * c12]])
# the cart-pole: p = (θ1 + L cos θ2, h + L sin θ2)
JCP = sp.Matrix([[1, -L * sp.sin(t2)], [0, L * sp.cos(t2)]])
SIG2 = [1 + 1 / sp.sqrt(2), 1 - 1 / sp.sqrt(2)]  # σ² of JCP at θ2 = π/4, L = 1: trace 2, det 1/2
# the SCARA: revolute joints at (0, 0) and (a1, 0) rotated, slide down, roll; tool on the roll axis at (a1 + a2) out
A1, A2 = sp.Rational(7, 20), sp.Rational(3, 10)
px, py = A1 * c1 + A2 * c12, A1 * s1 + A2 * s12
J_SCARA = sp.Matrix(
    [
        [0, 0, 0, 0],
        [0, 0, 0, 0],
        [1, 1, 0, 1],
        [-py, -A2 * s12, 0, 0],
        [px, A2 * c12, 0, 0],
        [0, 0, -1, 0],
    ]
)
J2R_AT = sp.Matrix([[-A2, -A2], [A1, 0]])  # (ṗx, ṗy) of the SCARA at θ = (0, π/2, ...), by hand


def _semi_axes(J, descending=True):
    ev = sorted(((J * J.T).eigenvals(multiple=True)), key=lambda e: float(e), reverse=descending)
    return sp.Matrix([sp.sqrt(e) for e in ev])


# 7.6, the P-R-R arm (issue 30): the columns from the rule, a slide (0, u_x, u_y), a revolute joint at its current
# point (x, y): (1, y, −x); joint 2 at (θ1, 0), joint 3 at (θ1 + L c2, L s2)
J_PRR = sp.Matrix([[0, 1, 1], [1, 0, L * sp.sin(t2)], [0, -t1, -t1 - L * sp.cos(t2)]])
S_PRR = sp.Matrix([[0, 0, 0, 1, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0]]).T

# name: (part, kind, right, [other valid forms], {wrong label: value})
CASES = {
    "A_v": (
        "7.1",
        "expr",
        JV * JV.T,
        [sp.expand(JV * JV.T), (JV * JV.T).applyfunc(lambda e: sp.simplify(e))],
        {"Jᵀ J": JV.T * JV, "negated": -JV * JV.T, "J_v alone": JV},
    ),
    "length_ratio": (
        "7.1",
        "expr",
        sp.sqrt(2),
        [2 / sp.sqrt(2), sp.Float(2**0.5, 20)],
        {"L2/L1": 1 / sp.sqrt(2), "2": 2},
    ),
    "isotropic_configs": (
        "7.1",
        "set",
        {t2: family(3 * pi / 4, -3 * pi / 4)},
        [{t2: family(5 * pi / 4, 3 * pi / 4)}, {t2: sp.FiniteSet(3 * pi / 4, 5 * pi / 4, -3 * pi / 4, -5 * pi / 4)}],
        {"one of the two": {t2: family(3 * pi / 4)}, "period π": {t2: family(3 * pi / 4, period=pi)}},
    ),
    "singular_4r": (
        "7.2",
        "set",
        {t2: family(0, period=pi), t3: family(0, period=pi)},
        [{t2: family(0, pi), t3: family(pi, 0)}],
        {"θ2 only": {t2: family(0, period=pi)}, "stretched only": {t2: family(0), t3: family(0)}},
    ),
    "removes_all": ("7.2", "choice", False, [sp.false], {"True": True}),
    "detJ_general": (
        "7.3",
        "expr",
        a * (b * sp.sin(t2) + c * sp.cos(t2)),
        [sp.expand(a * b * sp.sin(t2) + a * c * sp.cos(t2) + 0 * t1)],
        {"negated": -a * (b * sp.sin(t2) + c * sp.cos(t2)), "cos ↔ sin": a * (b * sp.cos(t2) + c * sp.sin(t2))},
    ),
    "lengths_can_remove": ("7.3", "choice", False, [sp.false], {"True": True}),
    "tau": (
        "7.4",
        "expr",
        JCP.T * sp.Matrix([Fx, Fy]),
        [sp.Matrix([Fx, L * (Fy * sp.cos(t2) - Fx * sp.sin(t2))])],
        {"J F": JCP * sp.Matrix([Fx, Fy]), "a row": (JCP.T * sp.Matrix([Fx, Fy])).T},
    ),
    "free_force": (
        "7.4",
        "subspace",
        sp.Matrix([0, 1]),
        [sp.Matrix([0, -5]), [[0, 2]]],
        {"horizontal": sp.Matrix([1, 0])},
    ),
    "force_semi_axes": (
        "7.4",
        "expr",
        sp.Matrix([1 / sp.sqrt(SIG2[0]), 1 / sp.sqrt(SIG2[1])]),
        [sp.Matrix([sp.Float(float(1 / sp.sqrt(SIG2[0])), 15), sp.Float(float(1 / sp.sqrt(SIG2[1])), 15)])],
        {
            "velocity axes σ": sp.Matrix([sp.sqrt(SIG2[1]), sp.sqrt(SIG2[0])]),
            "descending": sp.Matrix([1 / sp.sqrt(SIG2[1]), 1 / sp.sqrt(SIG2[0])]),
        },
    ),
    "J_scara": (
        "7.5",
        "expr",
        J_SCARA,
        [J_SCARA.applyfunc(sp.expand_trig)],
        {"[v; ω] order": J_SCARA[3:, :].col_join(J_SCARA[:3, :]), "slide up": J_SCARA.subs({J_SCARA[5, 2]: 1})},
    ),
    "S_76": (
        "7.6",
        "expr",
        S_PRR,
        [sp.Matrix.hstack(S_PRR[:, 0], S_PRR[:, 1], S_PRR[:, 2])],
        {
            "v = +ω × q": S_PRR.subs(L, -L),
            "the slide as a rotation": sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0]]).T,
        },
    ),
    "detJ_76": (
        "7.6",
        "expr",
        J_PRR.det(),
        [L * sp.cos(t2), L * sp.sin(t2 + pi / 2)],
        {
            "columns (1, −y, x)": sp.Matrix([[0, 1, 1], [1, 0, -L * sp.sin(t2)], [0, t1, t1 + L * sp.cos(t2)]]).det(),
            "sin": L * sp.sin(t2),
        },
    ),
    "singular_76": (
        "7.6",
        "set",
        {t2: family(pi / 2, period=pi)},
        [{t2: family(pi / 2, -pi / 2)}, [{t2: family(-pi / 2, period=pi)}]],
        {
            "stretched (the collinear rule)": {t2: family(0, period=pi)},
            "none": [],
            "one member": {t2: sp.FiniteSet(pi / 2)},
        },
    ),
    "scara_singular": (
        "7.5",
        "set",
        {t2: family(0, period=pi)},
        [{t2: family(0, pi)}, {t2: sp.FiniteSet(0, pi, -pi, 2 * pi, -2 * pi)}],
        {"stretched only": {t2: family(0)}, "θ3": {t3: family(0, period=pi)}},
    ),
    "scara_semi_axes": (
        "7.5",
        "expr",
        _semi_axes(J2R_AT),
        [sp.Matrix([sp.Float(float(x), 15) for x in _semi_axes(J2R_AT)])],
        {"ascending": _semi_axes(J2R_AT, descending=False), "squared": _semi_axes(J2R_AT).applyfunc(lambda x: x**2)},
    ),
}


def test_the_notebook_declares_these_answers():
    nb = json.loads(NB.read_text())
    assert schema.notebook_id(nb) == "07_going_further"
    assert schema.notebook_sections(nb) == ["7.1", "7.2", "7.3", "7.4", "7.5", "7.6"]
    declared = {(p.part, n, p.kinds[n]) for p in schema.parse_parts(nb) for n in p.answers}
    assert declared == {(part, n, kind) for n, (part, kind, *_rest) in CASES.items()}
    groups = {(pid, n, kind) for g in schema.answer_groups(nb) for pid, n, kind, _ in g.answers}
    assert groups == declared  # the self-checks are made from the same answers


@pytest.mark.parametrize("name", sorted(CASES))
def test_selfcheck_and_grader_on_right_other_valid_and_wrong_answers(name):
    assert_graded_right_and_wrong(name, CASES[name], POINTS)
