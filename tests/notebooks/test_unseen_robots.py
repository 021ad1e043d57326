"""The unseen-robot exercises of 05 and 06 (issue 30, "practice that transfers": parts 5.6 and 6.3; 7.6 is in
test_going_further.py) are graded and self-checked like the others.

For every answer the workbook self-check (a fingerprint of the reference, the student's value checked against it)
and the grader (describe of the value exported from the kernel, then compare, both sides through a JSON round trip)
are fed the right answer, other valid forms of it, and wrong answers (the mistakes a student makes on paper).

The references are written here by hand, independently of kinlib and of the notebooks' code:
5.6, the 3R with joints at (0, 0), (L, 0), (L, L) and the tool at (2L, L): S_i = [ẑ; −ẑ × q_i], det J = L² cos θ2
(the cross product of joint 2's and joint 3's current points); 6.3, the polar R-R-P arm: p in spherical coordinates,
det J_v = r² cos θ2 with r = L + θ3, and the full J of rank 3 everywhere.
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
pi = sp.pi
t1, t2, t3 = sp.symbols("theta1:4", real=True)
L = sp.Symbol("L", positive=True)
POINTS = [
    {"theta1": 0.3, "theta2": -1.1, "theta3": 2.0, "L": 1.2},
    {"theta1": -2.0, "theta2": 0.7, "theta3": -0.5, "L": 0.6},
]


def homog(x, y, z):
    return sp.Matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def revolute(w, q):
    w, q = sp.Matrix(w), sp.Matrix(q)
    return list(w) + list(-w.cross(q))


# by hand, 5.6: the joint points at home, then det J = x2 y3 − y2 x3 of the current points
Q2 = sp.Matrix([L * sp.cos(t1), L * sp.sin(t1)])
Q3 = Q2 + L * sp.Matrix([-sp.sin(t1 + t2), sp.cos(t1 + t2)])
DET_56 = sp.expand(Q2[0] * Q3[1] - Q2[1] * Q3[0])
S_56 = sp.Matrix([revolute([0, 0, 1], [0, 0, 0]), revolute([0, 0, 1], [L, 0, 0]), revolute([0, 0, 1], [L, L, 0])]).T
# 6.3: the shoulder about −y through (0, 0, L), the slide along x
S_63 = sp.Matrix([revolute([0, 0, 1], [0, 0, 0]), revolute([0, -1, 0], [0, 0, L]), [0, 0, 0, 1, 0, 0]]).T
R = L + t3
P_63 = sp.Matrix([0, 0, L]) + R * sp.Matrix([sp.cos(t2) * sp.cos(t1), sp.cos(t2) * sp.sin(t1), sp.sin(t2)])
DET_63 = sp.Matrix.hstack(*[P_63.diff(t) for t in (t1, t2, t3)]).det()

CASES = {
    # name: (part, kind, right, [other valid forms], {wrong: value})
    "M_56": (
        "5.6",
        "expr",
        homog(2 * L, L, 0),
        [homog(L + L, L, 0)],
        {"tool at (2L, 0)": homog(2 * L, 0, 0), "tool at (3L, L)": homog(3 * L, L, 0)},
    ),
    "S_56": (
        "5.6",
        "expr",
        S_56,
        [sp.Matrix.hstack(*[S_56[:, i] for i in range(3)])],
        {
            "v = +ω × q": sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, L, 0], [0, 0, 1, -L, L, 0]]).T,
            "joint 3 at (2L, L) (05's arm)": sp.Matrix(
                [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L, 0], [0, 0, 1, L, -2 * L, 0]]
            ).T,
        },
    ),
    "detJ_56": (
        "5.6",
        "expr",
        L**2 * sp.cos(t2),
        [DET_56, L**2 * sp.sin(t2 + pi / 2)],
        {"sin instead of cos": L**2 * sp.sin(t2), "sign": -(L**2) * sp.cos(t2), "one L": L * sp.cos(t2)},
    ),
    "singular_56": (
        "5.6",
        "set",
        {t2: family(pi / 2, period=pi)},
        [{t2: family(pi / 2, 3 * pi / 2)}, {t2: family(-pi / 2, period=pi)}, [{t2: family(pi / 2, period=pi)}]],
        {
            "stretched instead": {t2: family(0, period=pi)},
            "one member only": {t2: sp.FiniteSet(pi / 2)},
            "the wrong joint": {t1: family(pi / 2, period=pi)},
            "none": [],
        },
    ),
    "M_63": ("6.3", "expr", homog(L, 0, L), [homog(L, 0, 2 * L - L)], {"tool at (L, 0, 0)": homog(L, 0, 0)}),
    "S_63": (
        "6.3",
        "expr",
        S_63,
        [sp.Matrix([[0, 0, 1, 0, 0, 0], [0, -1, 0, L, 0, 0], [0, 0, 0, 1, 0, 0]]).T],
        {
            "v = +ω × q": sp.Matrix([[0, 0, 1, 0, 0, 0], [0, -1, 0, -L, 0, 0], [0, 0, 0, 1, 0, 0]]).T,
            "the slide as a rotation": sp.Matrix([[0, 0, 1, 0, 0, 0], [0, -1, 0, L, 0, 0], [1, 0, 0, 0, 0, 0]]).T,
        },
    ),
    "detJv_63": (
        "6.3",
        "expr",
        (L + t3) ** 2 * sp.cos(t2),
        [DET_63, (L**2 + 2 * L * t3 + t3**2) * sp.cos(t2)],
        {"r instead of r²": (L + t3) * sp.cos(t2), "slide forgotten": L**2 * sp.cos(t2), "sin": R**2 * sp.sin(t2)},
    ),
    "singular_63": (
        "6.3",
        "set",
        [{t2: family(pi / 2, period=pi)}, {t3: sp.FiniteSet(-L)}],
        [[{t3: sp.FiniteSet(-L)}, {t2: family(pi / 2, 3 * pi / 2)}]],
        {
            "the arm vertical only": [{t2: family(pi / 2, period=pi)}],
            "the slide only": [{t3: sp.FiniteSet(-L)}],
            "θ3 = 0": [{t2: family(pi / 2, period=pi)}, {t3: sp.FiniteSet(0)}],
            "none (the whole twist's answer)": [],
        },
    ),
    "rank_full_63": ("6.3", "expr", sp.Integer(3), [3], {"the position task's": sp.Integer(2), "1": sp.Integer(1)}),
}


def test_the_hand_references_are_what_the_notebook_says():
    assert sp.simplify(DET_56 - L**2 * sp.cos(t2)) == 0
    assert sp.simplify(DET_63 - (L + t3) ** 2 * sp.cos(t2)) == 0


@pytest.mark.parametrize(
    "stem, part", [("05_singularities_planar", "5.6"), ("06_singularities_spatial", "6.3")], ids=["5.6", "6.3"]
)
def test_the_notebooks_declare_these_answers(stem, part):
    nb = json.loads((ROOT / "notebooks" / f"{stem}.ipynb").read_text())
    assert schema.notebook_sections(nb)[-1] == part
    declared = {(p.part, n, p.kinds[n]) for p in schema.parse_parts(nb) for n in p.answers if p.part == part}
    assert declared == {(pt, n, kind) for n, (pt, kind, *_rest) in CASES.items() if pt == part}
    groups = {(pid, n, kind) for g in schema.answer_groups(nb) for pid, n, kind, _ in g.answers if pid == part}
    assert groups == declared
    question = next(
        c for c in nb["cells"] if "question" in schema.cell_tags(c) and f"**{part} (" in schema.cell_source(c)
    )
    assert schema.points_in(schema.cell_source(question)) == 5


@pytest.mark.parametrize("name", sorted(CASES))
def test_selfcheck_and_grader_on_right_other_valid_and_wrong_answers(name):
    assert_graded_right_and_wrong(name, CASES[name], POINTS)
