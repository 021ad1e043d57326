"""Notebooks 01–04 (issue 30): statements true for the task they are applied to, nothing graded given away,
and one exercise per section on a robot the notebook has not shown (1.4, 2.5, 3.5, 4.2).

Every fact is computed here independently of the notebooks' own cells (modern_robotics, plane geometry,
matrices typed by hand); the new parts' answer keys are read from the notebooks' solution cells and judged
by the workbook self-check and by the instructor checker's comparison, with a right answer typed by hand,
another valid form of it, and wrong answers.
"""

from __future__ import annotations

import functools
import math
import pathlib

import matplotlib

matplotlib.use("Agg")

import modern_robotics as mr  # noqa: E402
import nbformat  # noqa: E402
import numpy as np  # noqa: E402
import sympy as sp  # noqa: E402

from kinlib.course.answers.compare import compare  # noqa: E402
from kinlib.course.answers.describe import describe  # noqa: E402
from kinlib.course.grader.grade import make_points  # noqa: E402
from kinlib.course.workbook.selfcheck import fingerprint, verdict  # noqa: E402

NB_DIR = pathlib.Path(__file__).resolve().parents[2] / "notebooks"
STEMS = {
    "01": "01_properties_of_jacobians",
    "02": "02_planar_robot_jacobian",
    "03": "03_spatial_robot_jacobian",
    "04": "04_interpreting_the_jacobian",
}
sin, cos, sqrt, pi = sp.sin, sp.cos, sp.sqrt, sp.pi
th1, th2, th3 = sp.symbols("theta1 theta2 theta3", real=True)


def _read(key):
    return nbformat.read(NB_DIR / f"{STEMS[key]}.ipynb", as_version=4)


def _cells(key):
    return {c.get("id"): c for c in _read(key).cells}


def _order(key):
    return [c.get("id") for c in _read(key).cells]


@functools.cache
def answers(key):
    """The notebook's namespace after its setup, given, figure and solution cells (no widgets, no checks)."""
    import matplotlib.pyplot as plt

    ns = {"display": lambda *a, **k: None}
    for cell in _read(key).cells:
        tags = cell.metadata.get("tags", [])
        if cell.cell_type != "code" or "check" in tags or "nbval-ignore-output" in tags:
            continue
        exec(compile(cell.source, f"{key}:{cell.id}", "exec"), ns)
        plt.close("all")
    return ns


def _selfcheck(part, name, key, value, kind="default"):
    salt = f"{part}:{name}"
    return verdict(value, fingerprint(key, kind, salt), salt)[0]


def _checker(kind, key, value):
    """The instructor checker's verdict (describe both at random points, compare)."""
    syms = {}
    for obj in (key, value):
        for s in getattr(sp.sympify(obj) if not isinstance(obj, (tuple, int)) else sp.Integer(0), "free_symbols", ()):
            syms[s.name] = {"positive": bool(s.is_positive)}
    pts = make_points(syms, seed=11, n=5)
    return compare(kind, describe(kind, value, pts), describe(kind, key, pts), "answer")[0]


def _judged(part, name, key, value, kind="expr"):
    """(self-check status, checker says ok) for ``value`` against the key; the two must agree."""
    status = _selfcheck(part, name, key, value, "default" if kind == "expr" else kind)
    ok = _checker(kind, key, value)
    assert (status == "correct") == ok, (part, name, value, status, ok)
    return status


def _rot(a):
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


# ============================================================================================== notebook 01
def test_01_predicts_come_before_what_they_ask_about_and_steps_are_hints():
    order, cells = _order("01"), _cells("01")
    # 1.1: the predict comes before det J is computed and explained
    assert order.index("predict-1-1") < order.index("sol-1-1-det") < order.index("ans-1-1-det")
    # 1.3: the predict about θ5 = 0 comes before the text that explains which axes are parallel
    assert order.index("predict-1-3") < order.index("ur5-why") < order.index("sol-1-3-ur5")
    assert "parallel to axis 4" not in cells["ur5-text"].source and "parallel to axis 4" in cells["ur5-why"].source
    for cid in ("s3-1-2", "s4-1-2"):
        assert "hint" in cells[cid].metadata["tags"] and cells[cid].metadata["jupyter"]["source_hidden"]
    # the predict's answer states 1.1's answer: the workbook keeps it folded behind the part's self-check
    assert cells["predict-answer-1-1"].metadata["kinlib"]["part"] == "1.1"
    assert r"\pm\pi/2" not in cells["predict-1-1"].source and "vertical" not in cells["predict-1-1"].source


def test_01_students_text_gives_no_graded_answer():
    cells = _cells("01")
    assert "six joints, rank 6" not in cells["objectives"].source
    s = cells["summary"].metadata["kinlib"]
    assert set(s["reveals"]) == {"1.1", "1.3"}
    for leak in ("both singular", "six joints"):
        assert leak in cells["summary"].source and leak not in s["students"], leak
    assert "hanging" not in s["students"]
    e = cells["exp-1-1-text"].metadata["kinlib"]
    assert e["reveals"] == ["1.1"] and "readout" not in e["students"] and "singular" not in e["students"]
    assert "reads 0" not in e["students"] and cells["exp-1-1"].metadata["kinlib"]["reveals"] == ["1.1"]


def test_01_cart_pole_columns_have_units_and_det_zeros_do_not_depend_on_them():
    """Column 1 (prismatic) is in m/s per m/s, column 2 (revolute) in m/s per rad/s: measuring the cart in cm
    scales column 1 and so changes the velocity ellipse (the ratio of singular values), not where det J = 0."""
    text = _cells("01")["exp-1-1-text"].source
    assert "m/s per m/s" in text and "m/s per rad/s" in text and r"\lVert\dot\theta\rVert \le 1" in text
    L = 1.0

    def J(t2, k=1.0):  # k: tip metres per unit of θ1 (1 for metres, 0.01 for centimetres)
        return np.array([[k, -L * math.sin(t2)], [0.0, L * math.cos(t2)]])

    for t2 in (0.3, 1.0, 2.5):
        s_m, s_cm = np.linalg.svd(J(t2), compute_uv=False), np.linalg.svd(J(t2, 0.01), compute_uv=False)
        assert abs(s_m[1] / s_m[0] - s_cm[1] / s_cm[0]) > 1e-3  # another ellipse
        assert np.linalg.det(J(t2)) != 0 and np.linalg.det(J(t2, 0.01)) != 0
    for t2 in (math.pi / 2, -math.pi / 2):
        assert abs(np.linalg.det(J(t2))) < 1e-15 and abs(np.linalg.det(J(t2, 0.01))) < 1e-15


def test_01_full_jacobians_share_rank_row_subsets_do_not():
    """The full 6×n J_s, J_b and J = blockdiag(R, R) J_b have one rank (random arms, modern_robotics); the
    (v_x, v_y) rows of J_s of a planar 2R arm have det 0 everywhere, the ṗ rows of J and J_b L1 L2 sin θ2;
    the planar triple (ω_z, v_x, v_y) of J_s and (ω_z, ṗ_x, ṗ_y) of J have the same determinant."""
    rng = np.random.default_rng(30)
    for _ in range(20):
        n = int(rng.integers(2, 5))
        S = np.column_stack(
            [
                np.r_[a / np.linalg.norm(a), -np.cross(a / np.linalg.norm(a), rng.normal(size=3))]
                for a in rng.normal(size=(n, 3))
            ]
        )
        M = mr.RpToTrans(mr.MatrixExp3(mr.VecToso3(rng.normal(size=3))), rng.normal(size=3))
        B = mr.Adjoint(mr.TransInv(M)) @ S
        q = rng.normal(size=n)
        if rng.random() < 0.5:
            S[:, -1] = S[:, 0]  # a repeated axis: rank-deficient at every θ
            B = mr.Adjoint(mr.TransInv(M)) @ S
        T = mr.FKinSpace(M, S, q)
        Js, Jb = mr.JacobianSpace(S, q), mr.JacobianBody(B, q)
        R = T[:3, :3]
        Jg = np.block([[R, np.zeros((3, 3))], [np.zeros((3, 3)), R]]) @ Jb
        ranks = {np.linalg.matrix_rank(X, tol=1e-9) for X in (Js, Jb, Jg)}
        assert len(ranks) == 1
    L1, L2 = 0.9, 0.6
    S2r = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0]], dtype=float).T
    M2r = np.array([[1, 0, 0, L1 + L2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    B2r = mr.Adjoint(mr.TransInv(M2r)) @ S2r
    for q in rng.uniform(-3, 3, size=(10, 2)):
        Js, Jb, T = mr.JacobianSpace(S2r, q), mr.JacobianBody(B2r, q), mr.FKinSpace(M2r, S2r, q)
        p = T[:3, 3]
        pdot = Js[3:] + np.cross(Js[:3].T, p).T  # ṗ = v_s + ω_s × p: the geometric J's ṗ rows
        assert abs(np.linalg.det(Js[3:5])) < 1e-12
        assert np.isclose(np.linalg.det(pdot[:2]), L1 * L2 * math.sin(q[1]))
        assert np.isclose(abs(np.linalg.det(Jb[3:5])), abs(L1 * L2 * math.sin(q[1])))
    S3r = np.array([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0], [0, 0, 1, 0, -L1 - L2, 0]], dtype=float).T
    M3r = np.array([[1, 0, 0, L1 + L2 + 0.4], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    for q in rng.uniform(-3, 3, size=(10, 3)):
        Js, p = mr.JacobianSpace(S3r, q), mr.FKinSpace(M3r, S3r, q)[:3, 3]
        pdot = Js[3:] + np.cross(Js[:3].T, p).T
        assert np.isclose(np.linalg.det(Js[[2, 3, 4]]), np.linalg.det(np.vstack([Js[2], pdot[:2]])))
    text = _cells("01")["ans-1-3"].source
    assert "subset of rows" in text and r"(v_x, v_y)" in text


def test_01_ur5_view_shows_the_pitch_axes_slanting():
    """At matplotlib's default view (elev 30°, azim −60°) an axis along y_s projects on screen at some angle;
    the notebook's view must draw the pitch axes (along y_s) far from vertical and far from the vertical axes."""
    import matplotlib.pyplot as plt

    ns = dict(answers("01"))
    ns["plt"] = plt
    src = _cells("01")["fig-1-3-ur5"].source.replace("plt.show()", "")
    exec(compile(src, "01:fig-1-3-ur5", "exec"), ns)
    fig = ns["fig"]
    fig.canvas.draw()
    from mpl_toolkits.mplot3d import proj3d

    for ax in fig.axes:
        M = ax.get_proj()

        def screen(v, M=M, ax=ax):
            x, y, _ = proj3d.proj_transform(*v, M)
            return np.array(ax.transData.transform((x, y)))

        o = screen((0.3, 0.0, 0.2))
        dy, dz = screen((0.3, 0.1, 0.2)) - o, screen((0.3, 0.0, 0.3)) - o
        ang = lambda u, w: math.degrees(math.acos(abs(u @ w) / np.linalg.norm(u) / np.linalg.norm(w)))  # noqa: E731
        assert ang(dy, np.array([0.0, 1.0])) > 30 and ang(dy, dz) > 30
    plt.close(fig)


def test_1_4_offset_rp_arm_key_and_verdicts():
    ns = answers("01")
    d = sp.Symbol("d", positive=True)
    M = sp.Matrix([[1, 0, 0, 0], [0, 1, 0, d], [0, 0, 1, 0], [0, 0, 0, 1]])
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, 1, 0, 0]]).T
    J = sp.Matrix([[-d * cos(th1) - th2 * sin(th1), cos(th1)], [-d * sin(th1) + th2 * cos(th1), sin(th1)]])
    assert ns["M_rp"] == M and ns["S_rp"] == S and sp.simplify(ns["J_rp"] - J) == sp.zeros(2, 2)
    assert sp.simplify(ns["detJ_rp"] + th2) == 0 and ns["detJ_rp_zero"] == 0
    # independent: the tool position from plane geometry, differentiated numerically
    dv = 0.7
    for q in ([0.4, -0.3], [2.0, 1.1]):
        p = lambda a, b: _rot(a) @ np.array([b, dv])  # noqa: E731
        fd = np.column_stack(
            [(p(q[0] + 1e-6, q[1]) - p(q[0] - 1e-6, q[1])) / 2e-6, (p(q[0], q[1] + 1e-6) - p(q[0], q[1] - 1e-6)) / 2e-6]
        )
        got = np.array(J.subs({d: dv, th1: q[0], th2: q[1]}), dtype=float)
        assert np.allclose(got, fd, atol=1e-8) and np.isclose(np.linalg.det(fd), -q[1], atol=1e-7)
    # right, other valid forms, wrong
    assert _judged("1.4", "M_rp", ns["M_rp"], M) == "correct"
    assert _judged("1.4", "S_rp", ns["S_rp"], S) == "correct"
    assert _judged("1.4", "S_rp", ns["S_rp"], sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, -1, 0, 0]]).T) != "correct"
    assert _judged("1.4", "S_rp", ns["S_rp"], sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 1, 0]]).T) != "correct"
    assert _judged("1.4", "M_rp", ns["M_rp"], sp.eye(4)) != "correct"  # the tool is not at the origin
    other_J = sp.Matrix(
        [
            [-sqrt(d**2 + th2**2) * sin(th1 + sp.atan2(d, th2)), cos(th1)],
            [sqrt(d**2 + th2**2) * cos(th1 + sp.atan2(d, th2)), sin(th1)],
        ]
    )  # polar form: r, φ
    assert _judged("1.4", "J_rp", ns["J_rp"], other_J) == "correct"
    assert _judged("1.4", "J_rp", ns["J_rp"], J) == "correct"
    assert _judged("1.4", "J_rp", ns["J_rp"], J.T) != "correct"
    assert _judged("1.4", "J_rp", ns["J_rp"], J.subs(d, 0)) != "correct"  # forgot the offset
    assert _judged("1.4", "detJ_rp", ns["detJ_rp"], -th2 * (sin(th1) ** 2 + cos(th1) ** 2)) == "correct"
    assert _judged("1.4", "detJ_rp", ns["detJ_rp"], th2) != "correct"
    assert _judged("1.4", "detJ_rp", ns["detJ_rp"], -th2 - d) != "correct"
    assert _judged("1.4", "detJ_rp_zero", ns["detJ_rp_zero"], sp.Integer(0)) == "correct"
    assert _judged("1.4", "detJ_rp_zero", ns["detJ_rp_zero"], 0.0) == "correct"
    assert _judged("1.4", "detJ_rp_zero", ns["detJ_rp_zero"], -d) != "correct"  # "the tool on joint 1's axis"


# ============================================================================================== notebook 04
def _planar_3r_points(q, L=(1, 1, 1)):
    """Joint points q1, q2, q3 and the tool p of the planar 3R arm, exact, from plane geometry."""
    pts, a, x, y = [], 0, sp.Integer(0), sp.Integer(0)
    for qi, Li in zip(q, L):
        pts.append((x, y))
        a = a + qi
        x, y = x + Li * cos(a), y + Li * sin(a)
    return pts, (x, y)


def test_04_ties_are_equal_distances_same_x_or_mirrored():
    """|ṗ_y| from joint i is |p_x − q_i,x| (per rad/s): at θ = (0, π/2, π/6), L = 1, the joints are at x = 0, 1, 1 and
    the tool at x = 1/2: all three tie, although joint 1's x differs from the others'."""
    from kinlib.manipulability import strongest_joints

    q = [sp.Integer(0), pi / 2, pi / 6]
    pts, (px, py) = _planar_3r_points(q)
    dists = [sp.nsimplify(sp.simplify(px - qx)) for qx, _ in pts]
    assert dists == [sp.Rational(1, 2), -sp.Rational(1, 2), -sp.Rational(1, 2)]
    assert pts[0][0] != pts[1][0]  # not "the same x"
    ns = answers("04")
    row = [sp.simplify(v) for v in ns["evaluate_at"](ns["Jp_equal"], q, ns["arm"].thetas)[1, :]]
    assert row == dists and strongest_joints(sp.Matrix([row])) == (1, 2, 3)
    # the rule on random configurations: equal |entries| exactly when the distances are equal in size
    rng = np.random.default_rng(7)
    Jp = ns["Jp"].subs({ns["L1"]: 1, ns["L2"]: 1, ns["L3"]: 1})
    f = sp.lambdify(ns["arm"].thetas, Jp[1, :])
    for qn in rng.uniform(-3, 3, size=(20, 3)):
        pts, (pxn, _) = _planar_3r_points([float(v) for v in qn])
        assert np.allclose(np.abs(np.array(f(*qn), dtype=float).ravel()), [abs(float(pxn - qx)) for qx, _ in pts])
    text = _cells("04")["summary"].source
    assert r"|p_x - q_{1,x}| = |p_x - q_{2,x}|" in text and "mirrored" in text and r"(0, \pi/2, \pi/6)" in text
    assert "same $x$ (for" not in text


def test_04_check_of_c_follows_its_explanation_not_the_picker():
    order = _order("04")
    assert order.index("04-021") + 1 == order.index("04-023") < order.index("04-022")
    assert "solution" in _cells("04")["04-021b"].metadata["tags"]


def test_4_2_gantry_arm_key_and_verdicts():
    from kinlib.manipulability import strongest_joints

    ns = answers("04")
    L = sp.Symbol("L", positive=True)
    # typed by hand: a slide along x_s (column (1, 0)), then ẑ × (p − q_i) for the two revolute joints
    q2 = (th1, 0)
    q3 = (th1 + 2 * L * cos(th2), 2 * L * sin(th2))
    p = (q3[0] + L * cos(th2 + th3), q3[1] + L * sin(th2 + th3))
    Jp = sp.Matrix([[1, -(p[1] - q2[1]), -(p[1] - q3[1])], [0, p[0] - q2[0], p[0] - q3[0]]])
    assert sp.simplify(ns["Jp_gantry"] - Jp) == sp.zeros(2, 3)
    at = {th1: sp.Rational(1, 2), th2: 2 * pi / 3, th3: -pi / 3}
    row_y, row_x = Jp[1, :].subs(at), Jp[0, :].subs(at).subs(L, sp.Rational(1, 4))
    assert [sp.simplify(v) for v in row_y] == [0, -L / 2, L / 2]
    assert strongest_joints(row_y / L) == (2, 3) and strongest_joints(row_x) == 1
    assert strongest_joints(Jp[0, :].subs(at).subs(L, 1)) == 2  # the slide-vs-turn comparison depends on units
    # independent: modern_robotics with the screw axes typed by hand (L = 1/4)
    Lv = 0.25
    S = np.array([[0, 0, 0, 1, 0, 0], [0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -2 * Lv, 0]], dtype=float).T
    M = np.array([[1, 0, 0, 3 * Lv], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
    qn = np.array([0.5, 2 * math.pi / 3, -math.pi / 3])
    Js, pn = mr.JacobianSpace(S, qn), mr.FKinSpace(M, S, qn)[:3, 3]
    pdot = Js[3:] + np.cross(Js[:3].T, pn).T
    assert np.allclose(pdot[:2], np.array(Jp.subs(at).subs(L, Lv), dtype=float))
    assert (ns["joint_for_pdot_y"], ns["joint_for_pdot_x"]) == ((2, 3), 1)
    # right, other valid, wrong
    assert _judged("4.2", "Jp_gantry", ns["Jp_gantry"], Jp) == "correct"
    other = sp.Matrix(
        [
            [1, -2 * L * sin(th2) - L * sin(th2 + th3), -L * (sin(th2) * cos(th3) + cos(th2) * sin(th3))],
            [0, 2 * L * cos(th2) + L * cos(th2 + th3), L * (cos(th2) * cos(th3) - sin(th2) * sin(th3))],
        ]
    )
    assert _judged("4.2", "Jp_gantry", ns["Jp_gantry"], other) == "correct"
    assert _judged("4.2", "Jp_gantry", ns["Jp_gantry"], Jp.subs(L, 1)) != "correct"
    assert _judged("4.2", "Jp_gantry", ns["Jp_gantry"], Jp[:, [1, 0, 2]]) != "correct"
    wrong_units = Jp.copy()
    wrong_units[0, 0] = 0  # "a slide does not turn anything": the prismatic column forgotten
    assert _judged("4.2", "Jp_gantry", ns["Jp_gantry"], wrong_units) != "correct"
    for name, right, others, wrongs in (
        ("joint_for_pdot_y", (2, 3), [(3, 2), [2, 3]], [2, 3, (1, 2, 3), (1, 3)]),
        ("joint_for_pdot_x", 1, [(1,)], [2, (1, 2), 3]),
    ):
        key = ns[name]
        assert _judged("4.2", name, key, right, "choice") == "correct"
        for v in others:
            assert _judged("4.2", name, key, v, "choice") == "correct", v
        for v in wrongs:
            assert _judged("4.2", name, key, v, "choice") != "correct", v


# ============================================================================================== notebook 02
def test_02_students_text_and_figure():
    cells = _cells("02")
    assert cells["predict-answer-2-2"].metadata["kinlib"]["part"] == "2.2"
    e = cells["exp-text"].metadata["kinlib"]
    assert e["reveals"] == ["5.1"] and cells["explorer"].metadata["kinlib"]["reveals"] == ["5.1", "5.4"]
    assert "determinant" not in e["students"] and "singular" not in e["students"]
    assert "frames=False" in cells["fig-columns"].source  # no θ̇3 arrow on top of {b}'s y axis
    assert "subset of their rows" in cells["summary"].source


def test_2_5_lift_with_an_arm_key_and_verdicts():
    ns = answers("02")
    a, L = sp.Symbol("a", positive=True), sp.Symbol("L", positive=True)
    M = sp.Matrix([[1, 0, 0, a + L], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    S = sp.Matrix([[0, 0, 0, 0, 1, 0], [0, 0, 1, 0, -a, 0]]).T
    Js = sp.Matrix([[0, 0, 0, 0, 1, 0], [0, 0, 1, th1, -a, 0]]).T
    J = sp.Matrix([[0, 0, 0, 0, 1, 0], [0, 0, 1, -L * sin(th2), L * cos(th2), 0]]).T
    assert ns["M_pr"] == M and ns["S_pr"] == S
    assert sp.simplify(ns["Js_pr"] - Js) == sp.zeros(6, 2) and sp.simplify(ns["J_pr"] - J) == sp.zeros(6, 2)
    # independent: modern_robotics with the axes typed by hand; ṗ = v_s + ω_s × p
    av, Lv = 0.6, 0.9
    Sn, Mn = np.array(S.subs(a, av), dtype=float), np.array(M.subs({a: av, L: Lv}), dtype=float)
    for q in ([0.5, -1.1], [-0.3, 2.4]):
        q = np.array(q)
        Jsn, p = mr.JacobianSpace(Sn, q), mr.FKinSpace(Mn, Sn, q)[:3, 3]
        assert np.allclose(Jsn, np.array(Js.subs({a: av, th1: q[0], th2: q[1]}), dtype=float))
        Jg = np.vstack([Jsn[:3], Jsn[3:] + np.cross(Jsn[:3].T, p).T])
        assert np.allclose(Jg, np.array(J.subs({L: Lv, th1: q[0], th2: q[1]}), dtype=float))
    assert _judged("2.5", "M_pr", ns["M_pr"], M) == "correct"
    assert _judged("2.5", "M_pr", ns["M_pr"], M.subs(a, 0)) != "correct"
    assert _judged("2.5", "S_pr", ns["S_pr"], S) == "correct"
    assert _judged("2.5", "S_pr", ns["S_pr"], S.subs(a, -a)) != "correct"  # v = ω × q: the sign
    assert _judged("2.5", "Js_pr", ns["Js_pr"], Js) == "correct"
    assert _judged("2.5", "Js_pr", ns["Js_pr"], S) != "correct"  # joint 2's axis not raised by the lift
    assert _judged("2.5", "Js_pr", ns["Js_pr"], J) != "correct"  # the tool's velocity is not the v of J_s
    other = J.copy()
    other[3, 1], other[4, 1] = -L * cos(th2 - pi / 2), L * sin(th2 + pi / 2)
    assert _judged("2.5", "J_pr", ns["J_pr"], other) == "correct"
    assert _judged("2.5", "J_pr", ns["J_pr"], J) == "correct"
    assert _judged("2.5", "J_pr", ns["J_pr"], Js) != "correct"
    assert _judged("2.5", "J_pr", ns["J_pr"], J[[3, 4, 5, 0, 1, 2], :]) != "correct"  # [v; ω] order


# ============================================================================================== notebook 03
def test_03_students_text_and_figures():
    cells = _cells("03")
    assert cells["predict-answer-3-4"].metadata["kinlib"]["part"] == "3.4"
    s = cells["summary"].metadata["kinlib"]
    assert set(s["reveals"]) >= {"3.3", "3.4"} and "(1, 0, 0, 0, 0, 0)" not in s["students"]
    assert "(1, 0, 0, 0, 0, 0)" in cells["summary"].source
    e = cells["exp-text"].metadata["kinlib"]
    assert e["reveals"] == ["3.4"] and "vanishes" not in e["students"]
    assert set(cells["explorer"].metadata["kinlib"]["reveals"]) >= {"6.1", "6.2"}
    assert "frames=False" in cells["fig-columns"].source and "view_init" in cells["fig-columns"].source


def test_03_labels_sit_next_to_their_joints():
    """Each θi label of the 3-D pictures is drawn within 0.4 (data units, reach about 2) of its joint."""
    import matplotlib.pyplot as plt

    ns = dict(answers("03"))
    ns["plt"] = plt
    for cid in ("fig-home", "fig-columns", "fig-3-5"):
        src = _cells("03")[cid].source.replace("plt.show()", "")
        exec(compile(src, f"03:{cid}", "exec"), ns)
        art, sk = ns["art"], ns["sk"]
        for i, t in enumerate(art.labels):
            x, y, z = t.get_position_3d()
            assert np.linalg.norm(np.array([x, y, z], dtype=float) - sk[:, i + 1]) < 0.4, (cid, i)
        plt.close("all")


def test_3_5_spherical_rrp_arm_key_and_verdicts():
    ns = answers("03")
    H, L = sp.symbols("H L", positive=True)
    c1, s1, c2, s2 = cos(th1), sin(th1), cos(th2), sin(th2)
    M = sp.Matrix([[1, 0, 0, L], [0, 1, 0, 0], [0, 0, 1, H], [0, 0, 0, 1]])
    S = sp.Matrix([[0, 0, 1, 0, 0, 0], [0, 1, 0, -H, 0, 0], [0, 0, 0, 1, 0, 0]]).T
    Js = sp.Matrix([[0, 0, 1, 0, 0, 0], [-s1, c1, 0, -H * c1, -H * s1, 0], [0, 0, 0, c1 * c2, s1 * c2, -s2]]).T
    r = L + th3
    J = sp.Matrix(
        [
            [0, 0, 1, -r * s1 * c2, r * c1 * c2, 0],
            [-s1, c1, 0, -r * c1 * s2, -r * s1 * s2, -r * c2],
            [0, 0, 0, c1 * c2, s1 * c2, -s2],
        ]
    ).T
    assert ns["M_rrp"] == M and ns["S_rrp"] == S
    assert sp.simplify(ns["Js_rrp"] - Js) == sp.zeros(6, 3) and sp.simplify(ns["J_rrp"] - J) == sp.zeros(6, 3)
    # independent: modern_robotics with the axes typed by hand
    Hv, Lv = 1.1, 0.7
    Sn, Mn = np.array(S.subs(H, Hv), dtype=float), np.array(M.subs({H: Hv, L: Lv}), dtype=float)
    for q in ([0.4, -0.7, 0.25], [2.1, 1.2, -0.4]):
        q = np.array(q)
        Jsn, p = mr.JacobianSpace(Sn, q), mr.FKinSpace(Mn, Sn, q)[:3, 3]
        sub = {H: Hv, L: Lv, th1: q[0], th2: q[1], th3: q[2]}
        assert np.allclose(Jsn, np.array(Js.subs(sub), dtype=float))
        assert np.allclose(np.vstack([Jsn[:3], Jsn[3:] + np.cross(Jsn[:3].T, p).T]), np.array(J.subs(sub), dtype=float))
    assert _judged("3.5", "M_rrp", ns["M_rrp"], M) == "correct"
    assert _judged("3.5", "S_rrp", ns["S_rrp"], S) == "correct"
    wrong_S = S.copy()
    wrong_S[3, 1] = H  # v = +ω × q: the sign
    assert _judged("3.5", "S_rrp", ns["S_rrp"], wrong_S) != "correct"
    assert _judged("3.5", "Js_rrp", ns["Js_rrp"], Js) == "correct"
    assert _judged("3.5", "Js_rrp", ns["Js_rrp"], Js.applyfunc(lambda e: sp.expand_trig(e))) == "correct"
    assert _judged("3.5", "Js_rrp", ns["Js_rrp"], S) != "correct"  # the axes not moved
    assert _judged("3.5", "Js_rrp", ns["Js_rrp"], J) != "correct"
    other_J = J.copy()
    other_J[3, 0] = -r * sin(th1) * sin(th2 + pi / 2)  # c2 written as sin(θ2 + π/2)
    assert _judged("3.5", "J_rrp", ns["J_rrp"], other_J) == "correct"
    assert _judged("3.5", "J_rrp", ns["J_rrp"], J) == "correct"
    assert _judged("3.5", "J_rrp", ns["J_rrp"], J.subs(th3, 0)) != "correct"  # forgot the slide in the radius
    assert _judged("3.5", "J_rrp", ns["J_rrp"], Js) != "correct"
