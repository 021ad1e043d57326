"""kinlib.plotting: drawings match the kinematics (checked against finite differences of T(θ), NumPy's SVD
and the modern_robotics package), artists move in place, bad input is refused clearly."""

import math
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import modern_robotics as mr  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import sympy as sp  # noqa: E402

from kinlib import plotting as P  # noqa: E402
from kinlib import robots  # noqa: E402

ROBOTS = {
    "cart_pole": lambda: robots.cart_pole(1, 1),
    "planar_offset_3r": lambda: robots.planar_offset_3r(1),
    "spatial_rppr": lambda: robots.spatial_rppr(1, 1),
    "planar_3r": lambda: robots.planar_3r(1, 1, 1),
    "planar_rpp": lambda: robots.planar_rpp(1),
    "ur5": lambda: robots.ur5(),
}
PLANAR = {"cart_pole", "planar_offset_3r", "planar_3r", "planar_rpp"}


@pytest.fixture(scope="module")
def chains():
    return {k: f() for k, f in ROBOTS.items()}


def q_of(chain, seed=1):
    return np.random.default_rng(seed).uniform(-1.2, 1.2, chain.n)


def tool_position(chain, q):
    """p(θ) from the modern_robotics package (independent of kinlib)."""
    M = np.array(chain.M, dtype=float)
    S = np.array(chain.screws, dtype=float)
    return mr.FKinSpace(M, S, np.asarray(q, float))[:3, 3]


def pdot_fd(chain, q, qdot, h=1e-6):
    """ṗ by central differences of the modern_robotics forward kinematics."""
    q, qdot = np.asarray(q, float), np.asarray(qdot, float)
    return (tool_position(chain, q + h * qdot) - tool_position(chain, q - h * qdot)) / (2 * h)


def line_points(line):
    if hasattr(line, "get_data_3d"):
        return np.array(line.get_data_3d())
    return np.array(line.get_data())


# --- imports -------------------------------------------------------------------------------------
def test_import_kinlib_does_not_import_plotting_or_widgets():
    code = (
        "import sys, kinlib; bad = [m for m in ('kinlib.plotting', 'kinlib.widgets', 'matplotlib', "
        "'ipywidgets') if m in sys.modules]; assert not bad, bad"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_import_plotting_does_not_import_ipywidgets():
    code = "import sys, kinlib.plotting; assert 'ipywidgets' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True, env={"MPLBACKEND": "Agg", "PATH": ""})


# --- draw_chain ------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(ROBOTS))
def test_draw_chain_every_robot(chains, name):
    chain = chains[name]
    q = q_of(chain)
    art = P.draw_chain(chain, q)
    assert P.is_planar(chain) == (name in PLANAR)
    assert hasattr(art.ax, "get_zlim") == (name not in PLANAR)
    pts = line_points(art.links)
    d = 2 if name in PLANAR else 3
    # the drawn tool point is p(θ) of the independent forward kinematics
    np.testing.assert_allclose(pts[:, -1], tool_position(chain, q)[:d], atol=1e-9)
    np.testing.assert_allclose(art.tool_position, tool_position(chain, q), atol=1e-9)
    assert len(art.labels) == chain.n
    art.ax.figure.canvas.draw()


@pytest.mark.parametrize("name", list(ROBOTS))
def test_update_moves_the_same_artists(chains, name):
    chain = chains[name]
    art = P.draw_chain(chain, np.zeros(chain.n))
    before = [id(a) for a in art.artists]
    n_children = len(art.ax.get_children())
    q = q_of(chain, 7)
    art.update(q)
    assert [id(a) for a in art.artists] == before
    assert len(art.ax.get_children()) == n_children
    d = 2 if name in PLANAR else 3
    np.testing.assert_allclose(line_points(art.links)[:, -1], tool_position(chain, q)[:d], atol=1e-9)
    pts = line_points(art.links)  # the skeleton, with (NaN break, slider) after each prismatic joint's point
    nan = np.flatnonzero(np.isnan(pts[0]))
    keep = np.setdiff1d(np.arange(pts.shape[1]), np.r_[nan, nan + 1])
    np.testing.assert_allclose(pts[:, keep], chain.skeleton(q)[:d], atol=1e-12)


def test_tool_frame_arrows_are_the_columns_of_R():
    chain = robots.spatial_rppr(1, 1)
    q = [0.4, 0.3, -0.2, 0.9]
    art = P.draw_chain(chain, q)
    T = mr.FKinSpace(np.array(chain.M, float), np.array(chain.screws, float), np.array(q))
    segs = art.frame_b.segments(np.tile(T[:3, 3], (3, 1)), (T[:3, :3] * 0.22 * art.scale).T)[0]
    shafts = [np.subtract(*segs[3 * k][::-1]) for k in range(3)]  # tip − tail
    for k in range(3):
        np.testing.assert_allclose(shafts[k] / np.linalg.norm(shafts[k]), T[:3, k], atol=1e-12)


def test_joint_axes_follow_the_space_jacobian():
    chain = robots.spatial_rppr(1, 1)
    q = [0.7, 0.2, 0.3, -0.4]
    art = P.draw_chain(chain, q)
    Js = mr.JacobianSpace(np.array(chain.screws, float), np.array(q))
    segs = art.axis_segments(chain.skeleton(q), chain.jacobian_space(q))
    for i, (a, b) in enumerate(segs):
        d = (b - a) / np.linalg.norm(b - a)
        axis = Js[:3, i] if chain.joint_types[i] == "R" else Js[3:, i]
        np.testing.assert_allclose(abs(d @ axis), np.linalg.norm(axis), atol=1e-12)


def test_planar_projection_and_axes_mismatch():
    chain = robots.ur5()
    fig, ax = plt.subplots()
    art = P.draw_chain(chain, np.zeros(6), ax)  # 2-D axes given: the xy projection
    assert not hasattr(art.ax, "get_zlim")
    with pytest.raises(ValueError, match="planar"):
        P.draw_chain(chain, np.zeros(6), ax, planar=False)


def test_symbolic_parameters_need_numbers():
    r = robots.planar_offset_3r()
    with pytest.raises(ValueError, match=r"\bL\b"):  # the error names the symbolic parameter
        P.draw_chain(r, [0, 0, 0])
    art = P.draw_chain(r, [0.1, 0.2, 0.3], params={"L": 2})
    np.testing.assert_allclose(art.tool_position, tool_position(r.subs(L=2), [0.1, 0.2, 0.3]), atol=1e-12)
    # the numeric chain is SerialChain.numeric's, cached on the chain: drawing twice substitutes once
    assert P.draw_chain(r, [0, 0, 0], params={"L": 2}).chain is art.chain is r.numeric({"L": 2})
    with pytest.raises(ValueError, match="H"):
        P.draw_chain(r, [0, 0, 0], params={"H": 1})
    with pytest.raises((ValueError, TypeError)):
        P.draw_chain(r, [0, 0, 0], params={"L": sp.Symbol("a")})


@pytest.mark.parametrize(
    "q, err",
    [
        ([0, 0], ValueError),
        ([0, 0, 0, 0], ValueError),
        ("abc", TypeError),
        ([0, sp.Symbol("x"), 0], TypeError),
        ([0, np.nan, 0], ValueError),
        (np.zeros((2, 3)), ValueError),
    ],
)
def test_bad_configuration(q, err):
    with pytest.raises(err, match="q"):
        P.draw_chain(robots.planar_offset_3r(1), q)


def test_exact_configuration_accepted():
    r = robots.planar_offset_3r(1)
    art = P.draw_chain(r, [sp.pi / 4, -sp.pi / 4, sp.pi / 4])
    np.testing.assert_allclose(art.q, [math.pi / 4, -math.pi / 4, math.pi / 4])


def test_not_a_chain():
    with pytest.raises(TypeError, match="SerialChain"):
        P.draw_chain(np.eye(4), [0])


def test_draw_home_annotates_screw_axes():
    art = P.draw_home(robots.planar_offset_3r(), params={"L": 1})
    texts = [t.get_text() for t in art.annotations]
    assert any("q = (2·L, L, 0)" in t for t in texts), texts
    assert [t.get_text() for t in art.labels] == [r"$\theta_{1}$", r"$\theta_{2}$", r"$\theta_{3}$"]
    art3 = P.draw_home(robots.spatial_rppr(), params={"L1": 1, "L2": 1})
    texts = [t.get_text() for t in art3.annotations]
    assert any("v = (0, 0, 1)" in t for t in texts) and any("L1 + L2" in t for t in texts), texts
    # the screw axes come from the chain itself: θ4 is the revolute joint about x through (L2, 0, L1 + L2)
    assert texts[3].startswith("θ4: ω = (1, 0, 0)")
    art3.ax.figure.canvas.draw()


def _label_pixels(art):
    art.ax.figure.canvas.draw()
    texts = art.labels + art.frame_texts
    if hasattr(art.ax, "get_zlim"):  # a 3-D text's anchor, through matplotlib's own projection
        from mpl_toolkits.mplot3d import proj3d

        X = np.array([t.get_position_3d() for t in texts]).T
        x, y, _ = proj3d.proj_transform(X[0], X[1], X[2], art.ax.get_proj())
        return art.ax.transData.transform(np.column_stack([x, y])), texts
    return np.array([t.get_window_extent().get_points().mean(axis=0) for t in texts]), texts


@pytest.mark.parametrize("name", list(ROBOTS))
@pytest.mark.parametrize("home", [True, False])
def test_labels_do_not_overlap(chains, name, home):
    """θ1…θn, {s} and {b} keep at least about a font size apart on screen (the UR5's joints 1, 2 and
    joints 5, 6 nearly coincide; the RPPR's joints 1, 2 share the z axis)."""
    chain = chains[name]
    art = P.draw_home(chain) if home else P.draw_chain(chain, q_of(chain, 3))
    xy, texts = _label_pixels(art)
    px = art.fontsize * art.ax.figure.dpi / 72
    d = np.linalg.norm(xy[:, None] - xy[None], axis=2) + np.eye(len(xy)) * 1e9
    assert d.min() > 1.2 * px, [t.get_text() for t in texts]
    # every label is inside the view
    box = art.ax.get_window_extent()
    assert all(box.x0 <= x <= box.x1 and box.y0 <= y <= box.y1 for x, y in xy)


@pytest.mark.parametrize("name", ["spatial_rppr", "ur5"])
def test_3d_view_is_tight_and_equal_aspect(chains, name):
    chain = chains[name]
    q = q_of(chain, 5)
    art = P.draw_chain(chain, q)
    ax = art.ax
    lims = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    sides = lims[:, 1] - lims[:, 0]
    # equal scale on every axis: the drawn box has the proportions of the data box
    np.testing.assert_allclose(
        np.array(ax.get_box_aspect()) / np.max(ax.get_box_aspect()), sides / sides.max(), rtol=1e-9
    )
    # the whole skeleton is inside, and the box is not much larger than the drawing (frames, axes, margin)
    sk = chain.skeleton(q)
    assert np.all(sk >= lims[:, :1] - 1e-12) and np.all(sk <= lims[:, 1:] + 1e-12)
    extent = sk.max(axis=1) - sk.min(axis=1)
    assert sides.max() < extent.max() + 2.2 * art.scale
    # the workspace view (used with sliders) holds every pose in the joint ranges
    ws = P.draw_chain(chain, q, view="workspace").ax
    wl = np.array([ws.get_xlim(), ws.get_ylim(), ws.get_zlim()])
    Q = np.random.default_rng(11).uniform(-np.pi, np.pi, (200, chain.n))
    Q[:, [i for i, k in enumerate(chain.joint_types) if k == "P"]] *= 0.1
    pts = np.moveaxis(chain.skeleton(Q), 1, 0).reshape(3, -1)
    assert np.all(pts >= wl[:, :1] - 0.05) and np.all(pts <= wl[:, 1:] + 0.05)


def test_arrows_drawn_later_stay_in_view():
    chain = robots.planar_offset_3r(1)
    q = [np.pi / 6, -np.pi / 4, np.pi / 3]
    art = P.draw_chain(chain, q)
    v = P.draw_velocity(art.ax, chain, q, [3.0, 2.0, 1.0])
    tip = art.tool_position[:2] + v.velocity
    (x0, x1), (y0, y1) = art.ax.get_xlim(), art.ax.get_ylim()
    assert x0 < tip[0] < x1 and y0 < tip[1] < y1
    # explicit limits are respected
    art = P.draw_chain(chain, q, limits=[[-1, 1], [-1, 1]])
    P.draw_velocity(art.ax, chain, q, [3.0, 2.0, 1.0])
    assert art.ax.get_xlim() == (-1, 1)
    with pytest.raises(ValueError, match="view must be"):
        P.draw_chain(chain, q, view="tight")
    with pytest.raises(ValueError, match="limits must be"):
        P.draw_chain(chain, q, limits=[[-1, 1]])


# --- velocities ----------------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(ROBOTS))
def test_velocity_arrow_is_pdot(chains, name):
    chain = chains[name]
    q, qdot = q_of(chain, 2), q_of(chain, 3)
    art = P.draw_chain(chain, q)
    v = P.draw_velocity(art.ax, chain, q, qdot, scale=0.5)
    d = 2 if name in PLANAR else 3
    np.testing.assert_allclose(v.velocity, pdot_fd(chain, q, qdot)[:d], atol=1e-6)
    obj = v.artist
    q2, qd2 = q_of(chain, 4), q_of(chain, 5)
    v.update(q2, qd2)
    assert v.artist is obj
    np.testing.assert_allclose(v.velocity, pdot_fd(chain, q2, qd2)[:d], atol=1e-6)
    if d == 2:  # the quiver holds the scaled arrow at the tool
        np.testing.assert_allclose(obj.get_offsets()[0], tool_position(chain, q2)[:2], atol=1e-9)
        np.testing.assert_allclose([obj.U[0], obj.V[0]], 0.5 * v.velocity, atol=1e-9)


def test_joint_velocity_arrows_are_columns():
    chain = robots.planar_3r(1, 1, 1)
    q = [-math.pi / 8, math.pi / 4, math.pi / 8]
    art = P.draw_chain(chain, q)
    jv = P.draw_joint_velocities(art.ax, chain, q)
    for i in range(3):
        np.testing.assert_allclose(jv.columns[i], pdot_fd(chain, q, np.eye(3)[i])[:2], atol=1e-6)
    # problem 4.1, first configuration: ṗ_x contributions ≈ (−0.707, −1.09, −0.707) per unit L
    np.testing.assert_allclose(jv.columns[:, 0], [-0.7071, -1.0898, -0.7071], atol=1e-4)
    obj = jv.arrows.artist
    jv.update([0.1, 0.2, 0.3])
    assert jv.arrows.artist is obj
    np.testing.assert_allclose(jv.columns[1], pdot_fd(chain, [0.1, 0.2, 0.3], [0, 1, 0])[:2], atol=1e-6)
    with pytest.raises(ValueError, match="rows"):
        P.draw_joint_velocities(art.ax, chain, q, rows=("vx", "vy", "vz"))


# --- ellipse -------------------------------------------------------------------------------------
def test_ellipse_axes_are_singular_values_and_curve_is_the_image_of_the_unit_circle():
    chain = robots.planar_offset_3r(1)
    q = np.array([0.3, 0.6, -0.4])
    art = P.draw_chain(chain, q)
    e = P.draw_velocity_ellipse(art.ax, chain, q, scale=1.0)
    J = mr.JacobianSpace(np.array(chain.screws, float), q)
    p = tool_position(chain, q)
    # geometric ṗ rows: v_s + ω_s × p (independent of kinlib)
    Jp = J[3:5] + np.array([[0, 0, -p[1]], [0, 0, p[0]]]) @ J[:3]
    np.testing.assert_allclose(e.semi_axes, np.linalg.svd(Jp, compute_uv=False), atol=1e-12)
    pts = line_points(e.curves[0])[:2].T - p[:2]
    # each drawn point x = Jp θ̇ with ‖θ̇‖ = 1; the least-norm θ̇ of a boundary point has norm 1
    norms = np.linalg.norm(np.linalg.pinv(Jp) @ pts.T, axis=0)
    np.testing.assert_allclose(norms, 1.0, atol=1e-9)
    np.testing.assert_allclose(e.manipulability, math.sqrt(np.linalg.det(Jp @ Jp.T)), atol=1e-12)


def test_ellipse_collapses_to_a_segment_when_the_rows_lose_rank():
    chain = robots.planar_3r(1, 1, 1)
    q = np.zeros(3)  # outstretched: ṗ_x = 0 for every θ̇
    art = P.draw_chain(chain, q)
    e = P.draw_velocity_ellipse(art.ax, chain, q)
    curve = e.curves[0]
    assert e.semi_axes[1] < 1e-12
    e.update([0.2, 0.8, -0.3])
    assert e.curves[0] is curve and e.semi_axes[1] > 0.1
    e.update([0.5, 0, 0])
    pts = line_points(curve)[:2].T - tool_position(chain, [0.5, 0, 0])[:2]
    # all points on one line through the tool: rank 1
    assert np.linalg.matrix_rank(pts, tol=1e-9) == 1


def test_ellipsoid_in_3d():
    chain = robots.ur5()
    q = q_of(chain, 9)
    art = P.draw_chain(chain, q)
    e = P.draw_velocity_ellipse(art.ax, chain, q)
    Jg = chain.jacobian_geometric(q)
    assert len(e.curves) == 3
    Jv = np.column_stack([pdot_fd(chain, q, np.eye(6)[i]) for i in range(6)])
    np.testing.assert_allclose(e.semi_axes, np.linalg.svd(Jv, compute_uv=False), atol=1e-6)
    np.testing.assert_allclose(Jg[3:], Jv, atol=1e-6)
    art.ax.figure.canvas.draw()


# every row spec that plotting or singularities accepted before (one parser now: kinlib.taskspace)
ROW_SPECS = [
    ("planar", (2, 3, 4)),
    ("angular", (0, 1, 2)),
    ("linear", (3, 4, 5)),
    ("position", (3, 4, 5)),
    ("xy", (3, 4)),
    ("all", (0, 1, 2, 3, 4, 5)),
    ("PLANAR", (2, 3, 4)),
    (("vx", "py"), (3, 4)),
    (("px", "py", "pz"), (3, 4, 5)),
    (("ωz", "vx", "vy"), (2, 3, 4)),
    (("ω_z", "px", "py"), (2, 3, 4)),
    ((-3, -2), (3, 4)),
    ((-1, 0), (5, 0)),
    ((4, "vx"), (4, 3)),
    ("wz", (2,)),
    (5, (5,)),
    (np.array([3, 4]), (3, 4)),
]


@pytest.mark.parametrize("spec, idx", ROW_SPECS)
def test_rows_the_union_of_the_old_specs(spec, idx):
    assert P.task_row_indices(spec) == idx
    assert P.ROW_NAMES == ("wx", "wy", "wz", "vx", "vy", "vz")


def test_rows_through_the_plotting_api():
    """The same rows by name, alias, preset or (negative) index give the same pictures."""
    chain = robots.planar_offset_3r(1)
    q, qdot = [0.3, -0.4, 0.8], [0.5, 1.0, -0.2]
    art = P.draw_chain(chain, q)
    ref = P.draw_velocity(art.ax, chain, q, qdot, rows=(3, 4)).velocity
    for spec in ("xy", ("px", "py"), ("v_x", "p_y"), (-3, -2)):
        np.testing.assert_allclose(P.draw_velocity(art.ax, chain, q, qdot, rows=spec).velocity, ref, atol=1e-15)
    ref = P.plot_manipulability_curve(chain, 2, rows=(2, 3, 4), num=31).values
    for spec in ("planar", ("ωz", "px", "py"), ("ω_z", "vx", "vy"), (-4, -3, -2), None):
        np.testing.assert_allclose(P.plot_manipulability_curve(chain, 2, rows=spec, num=31).values, ref, atol=1e-15)
    ur5 = robots.ur5()
    m = P.plot_manipulability_map(ur5, (2, 3), rows="position", num=11)
    np.testing.assert_allclose(
        P.plot_manipulability_map(ur5, (2, 3), rows=("px", "py", "pz"), num=11).values, m.values, atol=1e-15
    )
    np.testing.assert_allclose(
        P.plot_manipulability_map(ur5, (2, 3), rows=[-3, -2, -1], num=11).values, m.values, atol=1e-15
    )
    plt.close("all")


def test_rows_refused():
    with pytest.raises(ValueError, match=r"unknown row.*'vw'"):
        P.task_row_indices(("vx", "vw"))
    with pytest.raises(ValueError, match="repeat"):
        P.task_row_indices(("vx", 3))
    with pytest.raises(ValueError, match="repeat"):
        P.task_row_indices(("vx", -3))
    with pytest.raises(ValueError, match="range"):
        P.task_row_indices((7,))
    with pytest.raises(TypeError, match="rows"):
        P.task_row_indices((True,))
    with pytest.raises(ValueError, match="rows"):
        P.plot_manipulability_curve(robots.planar_3r(1, 1, 1), 1, rows="nope")


def test_default_rows_are_the_task_space_of_the_arm():
    """Planar ≥ 3 joints: (ω_z, ṗ_x, ṗ_y); planar ≤ 2: (ṗ_x, ṗ_y); spatial ≥ 6: all; spatial < 6: ṗ."""
    for chain, rows in (
        (robots.planar_3r(1, 1, 1), (2, 3, 4)),
        (robots.planar_2r(1, 1), (3, 4)),
        (robots.ur5(), (0, 1, 2, 3, 4, 5)),
        (robots.spatial_rppr(1, 1), (3, 4, 5)),
    ):
        c = P.plot_manipulability_curve(chain, 2, num=5)
        np.testing.assert_allclose(c.values, P.plot_manipulability_curve(chain, 2, rows=rows, num=5).values)
    # the 2R arm's stretched-out singularity θ2 = 0 shows with its default rows (all six rows never lose rank 2)
    c = P.plot_manipulability_curve(robots.planar_2r(1, 1), 2, lim=(-1, 1), num=21)
    assert c.values[10] < 1e-12 and c.values.min() == c.values[10]
    plt.close("all")


# --- directions ----------------------------------------------------------------------------------
def test_draw_directions_problem_5_3():
    fig, ax = plt.subplots()
    s = math.sqrt(2) / 2
    col = sp.Matrix([[1, 0], [0, sp.sqrt(2) / 2], [0, -sp.sqrt(2) / 2]])  # columns (ω_z, ṗ_x, ṗ_y)
    arts = P.draw_directions(ax, (1, 2), col[:, 1:], labels=["can move"], components=(1, 2))
    np.testing.assert_allclose(arts[0]._posA_posB, [(1, 2), (1 + s, 2 - s)], atol=1e-12)
    arts = P.draw_directions(ax, (1, 2), [[0, 1, 1]], components=(1, 2), length=1.0, both_ways=True, linestyles=["--"])
    np.testing.assert_allclose(arts[0]._posA_posB, [(1 - s, 2 - s), (1 + s, 2 + s)], atol=1e-12)
    with pytest.raises(ValueError, match="2 entries"):
        P.draw_directions(ax, (0, 0), [[0, 1, 1]])
    fig.canvas.draw()


# --- manipulability ------------------------------------------------------------------------------
def _mr_planar_manipulability(chain, Q):
    """√det(J Jᵀ) of the rows (ω_z, v_x, v_y) of the modern_robotics space Jacobian (same det as the
    geometric rows (ω_z, ṗ_x, ṗ_y): they differ by a unimodular shear)."""
    S = np.array(chain.screws, float)
    out = []
    for q in Q:
        J = mr.JacobianSpace(S, q)[[2, 3, 4]]
        out.append(math.sqrt(max(np.linalg.det(J @ J.T), 0.0)))
    return np.array(out)


def test_manipulability_curve_problem_5_4():
    chain = robots.planar_offset_3r(1)
    c = P.plot_manipulability_curve(chain, 2, rows="planar")
    Q = np.zeros((c.x.size, 3))
    Q[:, 1] = c.x
    np.testing.assert_allclose(c.values, _mr_planar_manipulability(chain, Q), atol=1e-9)
    # the peak at θ2 = π/4 (and −3π/4), the zeros at θ2 = −π/4 and 3π/4
    peaks = c.x[c.values >= c.values.max() - 1e-9]
    np.testing.assert_allclose(sorted(peaks), [-3 * math.pi / 4, math.pi / 4], atol=1e-9)
    zeros = c.markers[1].get_xdata()
    np.testing.assert_allclose(sorted(zeros), [-math.pi / 4, 3 * math.pi / 4], atol=1e-6)
    assert c.joint == 2
    # same curve through a SymPy joint symbol; L = 2 scales by L²
    c2 = P.plot_manipulability_curve(robots.planar_offset_3r(), chain.thetas[1], params={"L": 2}, num=c.x.size)
    np.testing.assert_allclose(c2.values, 4 * c.values, atol=1e-9)


def test_manipulability_curve_bad_input():
    chain = robots.planar_offset_3r(1)
    with pytest.raises(ValueError, match="joint number 1..3"):
        P.plot_manipulability_curve(chain, 0)
    with pytest.raises(ValueError, match="measure"):
        P.plot_manipulability_curve(chain, 1, measure="nope")
    with pytest.raises(ValueError, match="square"):
        P.plot_manipulability_curve(chain, 1, rows="xy", measure="det")
    with pytest.raises(ValueError, match="q_fixed"):
        P.plot_manipulability_curve(chain, 1, q_fixed=[0, 0])


def test_manipulability_measures_against_numpy():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(50, 3, 4))
    np.testing.assert_allclose(P.manipulability_values(J), np.sqrt(np.linalg.det(J @ J.transpose(0, 2, 1))))
    Jt = J.transpose(0, 2, 1)  # 4×3: fewer joints than rows
    np.testing.assert_allclose(P.manipulability_values(Jt), np.sqrt(np.linalg.det(J @ Jt)))
    s = np.linalg.svd(J, compute_uv=False)
    np.testing.assert_allclose(P.manipulability_values(J, "inverse_condition"), s[:, -1] / s[:, 0])


def test_manipulability_map_draws_the_singular_set():
    chain = robots.planar_offset_3r(1)
    m = P.plot_manipulability_map(chain, (1, 2), num=91)
    assert m.values.shape == (91, 91)
    X, Y = np.meshgrid(m.x, m.y)
    Q = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    np.testing.assert_allclose(m.values.ravel(), _mr_planar_manipulability(chain, Q), atol=1e-9)
    assert m.singular, "no singular contour drawn"
    ys = np.vstack([p.vertices for p in m.singular[0].get_paths()])[:, 1]
    # every contour point lies on θ2 = −π/4 or θ2 = 3π/4 (problem 5.1)
    d = np.minimum(abs(ys + math.pi / 4), abs(ys - 3 * math.pi / 4))
    assert d.max() < 1e-3
    # given curves instead, and the non-square case
    m2 = P.plot_manipulability_map(chain, (1, 2), num=31, singular={"θ2 = −π/4": ([-3, 3], [-math.pi / 4] * 2)})
    assert m2.singular[0].get_label() == "θ2 = −π/4"
    m3 = P.plot_manipulability_map(robots.planar_3r(1, 1, 1), (2, 3), rows="xy", num=61)
    assert m3.singular
    with pytest.raises(ValueError, match="different"):
        P.plot_manipulability_map(chain, (2, 2))
    with pytest.raises(ValueError, match="two joint numbers"):
        P.plot_manipulability_map(chain, 2)
    m.ax.figure.canvas.draw()


def test_rpp_is_never_singular():
    m = P.plot_manipulability_map(robots.planar_rpp(1), (1, 2), num=41)
    np.testing.assert_allclose(m.values, 1.0, atol=1e-12)  # problem 5.5: det(J Jᵀ) = 1
    assert not m.singular


# --- the path of an animation (the animation itself plays in the browser: tests/pictures/test_widgets.py) ------
def test_sweep_and_the_animation_of_it():
    from kinlib import widgets

    chain = robots.planar_offset_3r(1)
    path = P.sweep(chain, 2, np.linspace(0, -math.pi / 2, 5), q_fixed=[0.3, 0, 0.2])
    assert path.shape == (5, 3) and np.all(path[:, 0] == 0.3)
    anim = widgets.animate_singularity(chain, path)
    np.testing.assert_allclose(anim.values, _mr_planar_manipulability(chain, path), atol=1e-9)
    assert anim.values[2] < 1e-9 and anim.states[2] == "singular"  # θ2 = −π/4
    with pytest.raises(ValueError, match="path"):
        widgets.animate_singularity(chain, np.zeros((5, 2)))


def test_ellipse_outline_matches_an_independent_svd():
    """Both ellipse drawings (EllipseArtist for a chain, draw_ellipse for given (σ, U)) draw the outline
    c + U diag(σ) (cos t, sin t) with σ, U from NumPy's SVD of J_ṗ built from modern_robotics."""
    chain = robots.planar_offset_3r(1)
    q = np.array([0.5, -0.3, 1.1])
    S = np.array(chain.screws, float)
    p = tool_position(chain, q)
    Js = mr.JacobianSpace(S, q)
    Jp = Js[3:5] + np.array([[0, 0, -p[1]], [0, 0, p[0]]]) @ Js[:3]  # ṗ = v_s + ω_s × p
    U, sig, _ = np.linalg.svd(Jp)
    art = P.draw_chain(chain, q)
    e = P.draw_velocity_ellipse(art.ax, chain, q, scale=0.5)
    np.testing.assert_allclose(e.semi_axes, sig, atol=1e-12)
    np.testing.assert_allclose(np.abs(e.directions.T @ U), np.eye(2), atol=1e-9)  # same axes up to sign
    pts = line_points(e.curves[0])[:2] - p[:2, None]
    local = U.T @ pts / (0.5 * sig[:, None])  # coordinates along the principal axes / semi-axes
    np.testing.assert_allclose(np.sum(local**2, axis=0), 1.0, atol=1e-9)
    # the principal axes drawn: ± 0.5 σ_i u_i about the tool
    ends = np.array([np.asarray(s)[1] - p[:2] for s in e.axes.get_segments()])
    np.testing.assert_allclose(np.abs(ends @ U), 0.5 * np.diag(sig), atol=1e-9)
    # draw_ellipse with the same (σ, U) draws the very same points
    arts = P.draw_ellipse(art.ax, p[:2], sig, U, scale=0.5)
    np.testing.assert_allclose(np.abs(U.T @ (np.array(arts[0].get_data()) - p[:2, None])), np.abs(U.T @ pts), atol=1e-9)
    # 3-D: the three principal ellipses of the UR5's ṗ ellipsoid
    ur5 = robots.ur5()
    q6 = q_of(ur5, 4)
    Jv = np.column_stack([pdot_fd(ur5, q6, np.eye(6)[i]) for i in range(6)])
    U3, s3, _ = np.linalg.svd(Jv)
    e3 = P.draw_velocity_ellipse(P.draw_chain(ur5, q6).ax, ur5, q6)
    np.testing.assert_allclose(e3.semi_axes, s3, atol=1e-6)
    c3 = tool_position(ur5, q6)
    for curve, (i, j) in zip(e3.curves, ((0, 1), (1, 2), (0, 2))):
        local = U3.T @ (line_points(curve) - c3[:, None])
        np.testing.assert_allclose((local[i] / s3[i]) ** 2 + (local[j] / s3[j]) ** 2, 1.0, atol=1e-5)
    plt.close("all")


def kinlib_owned(v) -> bool:
    """v is a kinlib object, or a dict/list/tuple holding one (one level deep)."""

    def own(x):
        return type(x).__module__.startswith("kinlib")

    if isinstance(v, dict):
        return any(own(x) for x in list(v.values()) + list(v.keys()))
    if isinstance(v, (list, tuple)):
        return any(own(x) for x in v)
    return own(v)


def test_no_state_on_the_axes_and_released_with_the_figure():
    import gc
    import weakref

    chain = robots.planar_offset_3r(1)
    q = [0.3, 0.4, -0.2]
    for planar in (True, False):
        fig = plt.figure()
        ax = fig.add_subplot(projection=None if planar else "3d")
        art = P.draw_chain(chain, q, ax, planar=planar)
        P.draw_velocity(ax, chain, q, [1, 0, 0], rows=None)
        P.draw_joint_velocities(ax, chain, q)
        P.draw_velocity_ellipse(ax, chain, q)
        fig.canvas.draw()
        # no attribute of the axes (or figure) is kinlib's: by name or by what it holds
        for obj in (ax, fig):
            assert not [k for k in vars(obj) if "kinlib" in k.lower()]
            # (the artists drawn on the axes, ``_children``, include the invisible ViewState: that is the point)
            assert not [k for k, v in vars(obj).items() if k != "_children" and kinlib_owned(v)]
        # the view's state is an (invisible) artist of the axes, so it goes with the figure
        ref = weakref.ref(ax)
        del art, ax, obj
        plt.close(fig)
        del fig
        gc.collect()
        assert ref() is None


def test_draw_ellipse_from_lengths_and_axes():
    fig, ax = plt.subplots()
    U = np.array([[math.cos(0.3), -math.sin(0.3)], [math.sin(0.3), math.cos(0.3)]])
    arts = P.draw_ellipse(ax, (1, 2), [2.0, 0.5], U, label="e")
    pts = np.array(arts[0].get_data()).T - [1, 2]
    local = pts @ U  # coordinates along the axes
    np.testing.assert_allclose((local[:, 0] / 2.0) ** 2 + (local[:, 1] / 0.5) ** 2, 1.0, atol=1e-12)
    with pytest.raises(ValueError, match="axes"):
        P.draw_ellipse(ax, (0, 0), [1, 1, 1], np.eye(3))
    ax3 = plt.figure().add_subplot(projection="3d")
    assert len(P.draw_ellipse(ax3, (0, 0, 0), [1, 0.5, 0], np.eye(3))) == 4


def test_plot_joint_contributions_marks_ties():
    fig, ax = plt.subplots()
    v = [1.30656296, 1.30656296, 0.92387953]  # problem 4.1 (c): joints 1 and 2 tie
    bars = P.plot_joint_contributions(ax, [sp.Float(x) for x in v], title="ṗ_y")
    np.testing.assert_allclose([b.get_height() for b in bars], v)
    assert [b.get_linewidth() for b in bars][:2] == [2.5, 2.5] and bars[2].get_linewidth() != 2.5
    with pytest.raises(TypeError, match="values"):
        P.plot_joint_contributions(ax, ["a"])
