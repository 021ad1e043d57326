"""Notebooks 01–03 (problem-set sections 1–3): their structure, and their computed answers pinned.

The answers are taken from the notebooks themselves (their setup, given and solution cells are run
in-process, without figures, widgets or check cells) and compared with matrices typed by hand from
the robots' geometry and with the ``modern_robotics`` package, never with kinlib's own output.

Where the printed solutions (``/work/shared/problem-set-4.md``) disagree with the computation, the
computed result is pinned here and the notebook shows a visible note:

* 1.1, eq. (4) prints ``p_y = L θ̇2 cos θ2``: the left side is the velocity ṗ_y, not the position p_y;
  eq. (5) (the 2×2 J) is right, and it is the ṗ rows of the cart-pole's 6×2 geometric Jacobian.
* 2.2, 2.3, 2.4 (eqs. 18, 20 and the 2.4 answer) print rows 1–3 with four entries (``0 0 0 0``,
  ``1 1 1 1``) for a three-joint robot: the Jacobians are 6×3 with rows (0,0,0), (0,0,0), (1,1,1).
Everything else printed in sections 1–3 agrees with the computation.
"""

from __future__ import annotations

import functools
import pathlib
import re

import matplotlib

matplotlib.use("Agg")

import modern_robotics as mr  # noqa: E402
import nbformat  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import sympy as sp  # noqa: E402

import kinlib  # noqa: E402
from helpers import assert_sym_equal  # noqa: E402

NB_DIR = pathlib.Path(__file__).resolve().parents[2] / "notebooks"
NOTEBOOKS = {
    "01_properties_of_jacobians": ["1.1", "1.2", "1.3", "1.4"],
    "02_planar_robot_jacobian": ["2.1", "2.2", "2.3", "2.4", "2.5"],
    "03_spatial_robot_jacobian": ["3.1", "3.2", "3.3", "3.4", "3.5"],
}
sin, cos, sqrt, pi = sp.sin, sp.cos, sp.sqrt, sp.pi


def _read(stem):
    return nbformat.read(NB_DIR / f"{stem}.ipynb", as_version=4)


@functools.cache
def answers(stem):
    """The notebook's namespace after its setup, given and solution cells (no figures, widgets, checks)."""
    ns = {"display": lambda *a, **k: None}
    for cell in _read(stem).cells:
        tags = cell.metadata.get("tags", [])
        if cell.cell_type != "code" or "check" in tags or "nbval-ignore-output" in tags:
            continue
        if "solution" not in tags and ("plotting." in cell.source or "plt." in cell.source):
            continue  # a figure
        exec(compile(cell.source, f"{stem}:{cell.id}", "exec"), ns)
    return ns


def _num(expr, subs):
    return np.array(sp.Matrix(expr).subs(subs).evalf(), dtype=float)


# --------------------------------------------------------------------------------------------
# structure (what handouts and the instructor checker rely on)
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("stem", sorted(NOTEBOOKS))
def test_notebook_structure(stem):
    nb = _read(stem)
    meta = nb.metadata["kinlib"]
    assert meta["notebook"] == stem and meta["sections"] == NOTEBOOKS[stem] and meta["title"]
    questions, solutions = set(), {}
    for cell in nb.cells:
        tags = set(cell.metadata.get("tags", []))
        assert not {"check", "solution"} <= tags, f"{cell.id}: both check and solution"
        if "question" in tags:
            assert cell.cell_type == "markdown"
            m = re.search(r"\*\*(\d\.\d) \((\d+) points?\)\.\*\*", cell.source)
            assert m, f"{cell.id}: a question states its part and points"
            questions.add(m.group(1))
        if "check" in tags:
            assert "# NBVAL_CHECK_OUTPUT" in cell.source
            text = "".join(o.get("text", "") for o in cell.outputs if o.output_type == "stream")
            assert text.strip().endswith("✓") and len(text.strip().splitlines()) == 1, f"{cell.id}: {text!r}"
        if cell.cell_type == "code" and "solution" in tags:
            k = cell.metadata["kinlib"]
            assert k["part"] in NOTEBOOKS[stem]
            assert all(a.isidentifier() for a in k["answers"])
            solutions.setdefault(k["part"], []).extend(k["answers"])
        if cell.cell_type == "code" and "widgets.explorer" in cell.source:
            assert "nbval-ignore-output" in tags
        if cell.cell_type == "code":
            assert cell.execution_count is not None, f"{cell.id} was not executed"
            assert not [o for o in cell.outputs if o.output_type == "error"], f"{cell.id} raised"
    assert questions == set(NOTEBOOKS[stem]) == set(solutions)
    assert all(solutions[p] for p in solutions), "every part names at least one answer"
    assert any("widgets.explorer" in c.source for c in nb.cells), "an explorer per notebook"


def test_printed_discrepancies_are_shown():
    md = {stem: "\n".join(c.source for c in _read(stem).cells if c.cell_type == "markdown") for stem in NOTEBOOKS}
    assert "Equation (4)" in md["01_properties_of_jacobians"] and r"\dot p_y" in md["01_properties_of_jacobians"]
    assert "four entries" in md["02_planar_robot_jacobian"] and r"6\times 3" in md["02_planar_robot_jacobian"]


# --------------------------------------------------------------------------------------------
# section 1
# --------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_1_1_cart_pole():
    ns = answers("01_properties_of_jacobians")
    L, h, th1, th2 = ns["L"], ns["h"], ns["th1"], ns["th2"]
    assert_sym_equal(ns["J"], sp.Matrix([[1, -L * sin(th2)], [0, L * cos(th2)]]), "1.1 J (eq. 5)")
    # eq. (4) corrected: the second row of ṗ is the velocity L cos θ2 θ̇2, which is not p_y
    t, th2_t = ns["t"], ns["theta2_t"]
    assert sp.simplify(ns["pdot_t"][1] - L * cos(th2_t) * th2_t.diff(t)) == 0
    assert sp.simplify(ns["pdot_t"][1] - ns["p_t"][1]) != 0
    assert_sym_equal(ns["detJ"], L * cos(th2), "1.1 det J")
    assert ns["detJ_zeros"] == sp.FiniteSet(-pi / 2, pi / 2)
    # independent: finite differences of modern_robotics' FKinSpace for the cart-pole typed by hand
    Lv, hv, q0, eps = 0.9, 0.4, np.array([0.2, 0.7]), 1e-6
    M = np.array([[1, 0, 0, Lv], [0, 1, 0, hv], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    S = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 1, hv, 0, 0]], dtype=float).T
    fd = np.column_stack(
        [(mr.FKinSpace(M, S, q0 + e) - mr.FKinSpace(M, S, q0 - e))[:2, 3] / (2 * eps) for e in np.eye(2) * eps]
    )
    assert np.allclose(_num(ns["J"], {L: Lv, h: hv, th1: q0[0], th2: q0[1]}), fd, atol=1e-8)


@pytest.mark.slow
def test_1_2_space_jacobian_of_the_3r_arm():
    ns = answers("01_properties_of_jacobians")
    H, L1, L2 = ns["H"], ns["L1"], ns["L2"]
    t1, t2, t3 = ns["th"]
    Js = ns["Js"]
    assert Js.shape == (6, 3) and Js.free_symbols <= {H, L1, L2, t1, t2, t3}
    # independent: modern_robotics' JacobianSpace on the arm's axes typed by hand (H = 1.1, L1 = 0.8)
    Hv, L1v = 1.1, 0.8
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 1, 0, -Hv, 0, 0], [0, 1, 0, -Hv, 0, L1v]], dtype=float).T
    for q in ([0.3, -0.4, 0.9], [2.0, 1.0, -1.5]):
        got = _num(Js, {H: Hv, L1: L1v, L2: 0.5, t1: q[0], t2: q[1], t3: q[2]})
        assert np.allclose(got, mr.JacobianSpace(S, np.array(q)))


@pytest.mark.slow
def test_1_3_invertibility():
    ns = answers("01_properties_of_jacobians")
    assert (ns["n_required"], ns["rank_required"]) == (6, 6)
    ranks = [Jq.rank(simplify=True) for Jq in ns["Js_poses"].values()]
    assert ranks == [6, 5, 5]


# --------------------------------------------------------------------------------------------
# section 2 (the printed Jacobians show four entries in rows 1-3: they are 6×3)
# --------------------------------------------------------------------------------------------
def _planar_expected(L, t1, t2, t3):
    r2 = sqrt(2)
    c1, s1 = cos(t1), sin(t1)
    c123, s123 = cos(t1 + t2 + t3), sin(t1 + t2 + t3)
    a, b = r2 * sin(t1 + t2 + pi / 4), r2 * cos(t1 + t2 + pi / 4)
    top = [[0, 0, 0], [0, 0, 0], [1, 1, 1]]
    Js = sp.Matrix(top + [[0, L * s1, L * s1 + L * a], [0, -L * c1, -L * c1 - L * b], [0, 0, 0]])
    Jb = sp.Matrix(
        top
        + [
            [L * sin(t2 + t3) - L * r2 * cos(t3 + pi / 4), -L * r2 * cos(t3 + pi / 4), 0],
            [L * cos(t2 + t3) + L * r2 * sin(t3 + pi / 4) + L, L * r2 * sin(t3 + pi / 4) + L, L],
            [0, 0, 0],
        ]
    )
    J = sp.Matrix(
        top
        + [
            [-L * s123 - L * s1 - L * a, -L * s123 - L * a, -L * s123],
            [L * c123 + L * c1 + L * b, L * c123 + L * b, L * c123],
            [0, 0, 0],
        ]
    )
    return Js, Jb, J


@pytest.mark.slow
def test_section_2_answers():
    ns = answers("02_planar_robot_jacobian")
    L, t1, t2, t3 = ns["L"], ns["th1"], ns["th2"], ns["th3"]
    assert ns["M"] == sp.Matrix([[1, 0, 0, 3 * L], [0, 1, 0, L], [0, 0, 1, 0], [0, 0, 0, 1]])
    assert [list(ns[k]) for k in ("S1", "S2", "S3")] == [
        [0, 0, 1, 0, 0, 0],
        [0, 0, 1, 0, -L, 0],
        [0, 0, 1, L, -2 * L, 0],
    ]
    Js, Jb, J = _planar_expected(L, t1, t2, t3)
    for name, expected in (("Js", Js), ("Jb", Jb), ("J", J)):
        assert ns[name].shape == (6, 3), f"{name} is 6×3 (the printed rows 1-3 have four entries)"
        assert_sym_equal(ns[name], expected, f"2.x {name}")
    # independent: modern_robotics at L = 0.7
    M = np.array([[1, 0, 0, 2.1], [0, 1, 0, 0.7], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -0.7, 0], [0, 0, 1, 0.7, -1.4, 0]]).T
    q = np.array([0.4, -0.9, 1.3])
    subs = {L: 0.7, t1: q[0], t2: q[1], t3: q[2]}
    T = mr.FKinSpace(M, S, q)
    assert np.allclose(_num(ns["T"], subs), T)
    assert np.allclose(_num(ns["Js"], subs), mr.JacobianSpace(S, q))
    assert np.allclose(_num(ns["Jb"], subs), mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q))
    R = T[:3, :3]
    assert np.allclose(
        _num(ns["J"], subs),
        np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]]) @ mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q),
    )


# --------------------------------------------------------------------------------------------
# section 3 (every printed answer agrees)
# --------------------------------------------------------------------------------------------
@pytest.mark.slow
def test_section_3_answers():
    ns = answers("03_spatial_robot_jacobian")
    L1, L2 = ns["L1"], ns["L2"]
    t1, t2, t3, t4 = ns["th1"], ns["th2"], ns["th3"], ns["th4"]
    c1, s1, c4, s4 = cos(t1), sin(t1), cos(t4), sin(t4)
    H = L1 + L2
    assert_sym_equal(
        ns["T"],
        sp.Matrix(
            [
                [c1, -c4 * s1, s1 * s4, (L2 + t3) * c1],
                [s1, c1 * c4, -c1 * s4, (L2 + t3) * s1],
                [0, s4, c4, H + t2],
                [0, 0, 0, 1],
            ]
        ),
        "3.1 T",
    )
    assert_sym_equal(
        ns["Js"],
        sp.Matrix(
            [
                [0, 0, 0, c1],
                [0, 0, 0, s1],
                [1, 0, 0, 0],
                [0, 0, c1, -(H + t2) * s1],
                [0, 0, s1, (H + t2) * c1],
                [0, 1, 0, 0],
            ]
        ),
        "3.2 J_s",
    )
    assert_sym_equal(
        ns["Jb"],
        sp.Matrix(
            [
                [0, 0, 0, 1],
                [s4, 0, 0, 0],
                [c4, 0, 0, 0],
                [0, 0, 1, 0],
                [(L2 + t3) * c4, s4, 0, 0],
                [-(L2 + t3) * s4, c4, 0, 0],
            ]
        ),
        "3.3 J_b",
    )
    assert_sym_equal(
        ns["J"],
        sp.Matrix(
            [
                [0, 0, 0, c1],
                [0, 0, 0, s1],
                [1, 0, 0, 0],
                [-(L2 + t3) * s1, 0, c1, 0],
                [(L2 + t3) * c1, 0, s1, 0],
                [0, 1, 0, 0],
            ]
        ),
        "3.4 J",
    )
    # independent: modern_robotics at L1 = 1, L2 = 0.6
    M = np.array([[1, 0, 0, 0.6], [0, 1, 0, 0], [0, 0, 1, 1.6], [0, 0, 0, 1.0]])
    S = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 1], [0, 0, 0, 1, 0, 0], [1, 0, 0, 0, 1.6, 0]], dtype=float).T
    q = np.array([0.4, 0.3, -0.2, 1.3])
    subs = {L1: 1, L2: 0.6, t1: q[0], t2: q[1], t3: q[2], t4: q[3]}
    assert np.allclose(_num(ns["Js"], subs), mr.JacobianSpace(S, q))
    assert np.allclose(_num(ns["Jb"], subs), mr.JacobianBody(mr.Adjoint(mr.TransInv(M)) @ S, q))


# --------------------------------------------------------------------------------------------
# problem 1.2 needs T(θ(t)): trans_inv and adjoint accept joint values written as functions of time
# --------------------------------------------------------------------------------------------
def test_trans_inv_and_adjoint_of_time_dependent_transform():
    t = sp.Symbol("t", real=True)
    q = sp.Function("q", real=True)(t)
    T = kinlib.exp6(sp.Matrix([0, 0, 1, 0, -1, 0]), q)
    assert sp.simplify(kinlib.trans_inv(T) * T - sp.eye(4)) == sp.zeros(4)
    assert kinlib.adjoint(T).shape == (6, 6)
    with pytest.raises(ValueError):
        kinlib.trans_inv(sp.Matrix([[2 * sp.cos(q), 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]))
