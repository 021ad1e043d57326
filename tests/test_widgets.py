"""kinlib.widgets: the explorer and the configuration picker react to their controls and say the right
thing about singular configurations (known independently: problem 5.1's θ2 = −π/4, the UR5 at home)."""

import math

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import modern_robotics as mr  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from kinlib import robots, widgets, widgets_render  # noqa: E402

PNG = b"\x89PNG"


@pytest.fixture(scope="module")
def r3():
    return robots.planar_offset_3r(1)


def tool_position(chain, q):
    return mr.FKinSpace(np.array(chain.M, float), np.array(chain.screws, float), np.asarray(q, float))[:3, 3]


def pdot_fd(chain, q, qdot, h=1e-6):
    """ṗ by central differences of the modern_robotics forward kinematics."""
    q, qdot = np.asarray(q, float), np.asarray(qdot, float)
    return (tool_position(chain, q + h * qdot) - tool_position(chain, q - h * qdot)) / (2 * h)


@pytest.mark.parametrize(
    "make",
    [
        lambda: robots.cart_pole(1, 1),
        lambda: robots.planar_offset_3r(1),
        lambda: robots.spatial_rppr(1, 1),
        lambda: robots.planar_3r(1, 1, 1),
        lambda: robots.planar_rpp(1),
        lambda: robots.ur5(),
    ],
)
def test_explorer_builds_for_every_robot(make):
    chain = make()
    ex = widgets.explorer(chain)
    assert len(ex.sliders) == chain.n and len(ex.rate_sliders) == chain.n
    assert bytes(ex.picture).startswith(PNG)
    for i, s in enumerate(ex.sliders):
        assert s.description.startswith(f"θ{i + 1} (")
        assert ("rad" in s.description) == (chain.joint_types[i] == "R")
    q = np.linspace(0.1, 0.4, chain.n)
    ex.update(q)
    d = 2 if ex.planar else 3
    np.testing.assert_allclose(ex.arm.tool_position, tool_position(chain, q), atol=1e-9)
    assert ex.velocity.velocity.shape == (d,)


def test_status_at_a_singular_and_a_regular_configuration(r3):
    ex = widgets.explorer(r3, q=[0.3, math.pi / 4, 0.2])
    assert ex.state == "regular"
    assert "singular" not in ex.status.value.lower()
    img = bytes(ex.picture)
    # a slider move (as in the browser) to θ2 = −π/4: problem 5.1's singular configuration
    ex.sliders[1].value = -math.pi / 4
    assert ex.state == "singular"
    assert "SINGULAR configuration" in ex.status.value
    assert ex.info["rank"] == 2 and abs(ex.info["det"]) < 1e-9
    assert bytes(ex.picture) != img
    # close to it, but not at it
    ex.sliders[1].value = -math.pi / 4 + 0.05
    assert ex.state == "near" and "near a singular configuration" in ex.status.value
    # the other family θ2 = 3π/4, reached through update()
    ex.update([1.0, 3 * math.pi / 4, -2.0])
    assert ex.state == "singular"
    ex.update([1.0, 0.0, -2.0])
    assert ex.state == "regular" and "singular" not in ex.status.value.lower()


def test_slider_step_reaches_the_singular_value(r3):
    ex = widgets.explorer(r3)
    s = ex.sliders[1]
    k = round((-math.pi / 4 - s.min) / s.step)
    s.value = s.min + k * s.step  # what a slider at an integer number of steps reports
    assert ex.state == "singular"


def test_explorer_readout_matches_the_kinematics(r3):
    q, qdot = [0.2, -0.7, 0.5], [0.5, -1.0, 0.25]
    ex = widgets.explorer(r3, q=q, qdot=qdot)
    pdot = pdot_fd(r3, q, qdot)
    np.testing.assert_allclose(ex.velocity.velocity, pdot[:2], atol=1e-6)
    J = mr.JacobianSpace(np.array(r3.screws, float), np.array(q))[[2, 3, 4]]
    assert ex.info["det"] == pytest.approx(np.linalg.det(J), abs=1e-9)
    assert ex.info["manipulability"] == pytest.approx(abs(np.linalg.det(J)), abs=1e-9)
    assert f"<span class='kinlib-det'>{ex.info['det']:+.4g}</span>" in ex.readout.value
    # the rate sliders drive the arrow
    arrow = ex.velocity.artist
    ex.rate_sliders[0].value = 2.0
    assert ex.velocity.artist is arrow
    qd = [2.0, -1.0, 0.25]
    pdot = pdot_fd(r3, q, qd)
    np.testing.assert_allclose(ex.velocity.velocity, pdot[:2], atol=1e-6)


def test_explorer_updates_artists_in_place(r3):
    ex = widgets.explorer(r3)
    ids = [id(a) for a in ex.arm.artists + ex.ellipse.artists + ex.velocity.artists]
    children = len(ex.ax.get_children())
    for v in (0.3, 0.6, -1.0):
        ex.sliders[2].value = v
    assert [id(a) for a in ex.arm.artists + ex.ellipse.artists + ex.velocity.artists] == ids
    assert len(ex.ax.get_children()) == children
    np.testing.assert_allclose(ex.q, [0, 0, -1.0])
    # the cached-background picture equals a full redraw of the same state
    import io

    from PIL import Image

    fast = np.asarray(Image.open(io.BytesIO(ex.picture)).convert("RGB"), float)  # 8-bit (palette) PNG
    for a in ex._blit.artists:
        a.set_animated(False)
    full = np.asarray(Image.open(io.BytesIO(widgets_render.render_png(ex.fig))).convert("RGB"), float)
    assert fast.shape == full.shape
    assert np.mean(np.any(np.abs(fast - full) > 40, axis=-1)) < 0.01  # equal up to the palette's rounding


def test_ur5_home_is_singular():
    ex = widgets.explorer(robots.ur5(), rate_sliders=False)
    assert ex.rate_sliders == []
    assert ex.state == "singular"  # θ5 = 0: the wrist singularity of the UR5
    ex.update([0.1, -0.6, 1.2, 0.3, 0.8, 0.2])
    assert ex.state != "singular"


def test_explorer_bad_input(r3):
    with pytest.raises(ValueError, match=r"symbolic.*\bL\b"):  # names the parameter without a number
        widgets.explorer(robots.planar_offset_3r())
    with pytest.raises(ValueError, match="q must hold 3"):
        widgets.explorer(r3, q=[0, 0])
    ex = widgets.explorer(r3)
    with pytest.raises(ValueError, match="q must hold 3"):
        ex.update([0, 0, 0, 0])
    with pytest.raises(ValueError, match="qdot"):
        ex.update(qdot=[1])
    with pytest.raises(ValueError, match="lo < hi"):
        widgets.explorer(r3, ranges={2: (1, -1)})
    ex = widgets.explorer(robots.planar_offset_3r(), params={"L": 1}, ranges={2: (-1, 1)})
    assert (ex.sliders[1].min, ex.sliders[1].max) == (-1, 1)


CONFIGS = {
    "θ = (−π/8, π/4, π/8)": [-math.pi / 8, math.pi / 4, math.pi / 8],
    "θ = (3π/4, −π/4, 0)": [3 * math.pi / 4, -math.pi / 4, 0],
    "θ = (π/2, −π/8, −π/2)": [math.pi / 2, -math.pi / 8, -math.pi / 2],
}


def test_config_picker_problem_4_1():
    chain = robots.planar_3r(1, 1, 1)
    names = list(CONFIGS)
    cp = widgets.config_picker(chain, CONFIGS, rows={names[0]: "vx", names[1]: "vx", names[2]: "vy"})
    expected_best = {names[0]: (2,), names[1]: (1,), names[2]: (1, 2)}  # problem 4.1 (a tie in the third)
    h = 1e-6
    for name in names:
        cp.buttons.value = name  # as a click does
        q = np.array(CONFIGS[name])
        row = 0 if cp.rows[name] == 3 else 1
        fd = [(tool_position(chain, q + h * e) - tool_position(chain, q - h * e))[row] / (2 * h) for e in np.eye(3)]
        np.testing.assert_allclose(cp.contributions, fd, atol=1e-6)
        np.testing.assert_allclose([b.get_height() for b in cp.bars], fd, atol=1e-6)
        assert cp.best == expected_best[name]
        assert cp.name == name and bytes(cp.picture).startswith(PNG)
    assert "tie between joints 1 and 2" in cp.table.value
    cp.select(names[0])
    assert cp.buttons.value == names[0] and "joint 2" in cp.table.value


def test_config_picker_bad_input():
    chain = robots.planar_3r(1, 1, 1)
    with pytest.raises(TypeError, match="configs"):
        widgets.config_picker(chain, {})
    with pytest.raises(ValueError, match="configs"):
        widgets.config_picker(chain, {"a": [0, 0]})
    with pytest.raises(ValueError, match="missing"):
        widgets.config_picker(chain, {"a": [0, 0, 0], "b": [1, 1, 1]}, rows={"a": "vx"})
    with pytest.raises(ValueError, match="one row"):
        widgets.config_picker(chain, {"a": [0, 0, 0]}, rows=("vx", "vy"))
    cp = widgets.config_picker(chain, {"a": [0, 0, 0]})
    with pytest.raises(ValueError, match="unknown configuration"):
        cp.select("b")


def test_the_image_widget_carries_the_picture_as_a_data_url(r3):
    """The browser gets a data URL (decoded in the page; a Blob URL costs a round trip through the browser
    process): it must decode to exactly the rendered picture, for PNG and JPEG explorers and the picker."""
    import base64

    for ex, mime in ((widgets.explorer(r3), "png"), (widgets.explorer(r3, image_format="jpeg"), "jpeg")):
        ex.sliders[0].value = 0.4
        assert ex.image.format == "url"
        head, _, body = bytes(ex.image.value).partition(b",")
        assert head == f"data:image/{mime};base64".encode()
        assert base64.b64decode(body, validate=True) == bytes(ex.picture)
    cp = widgets.config_picker(r3, {"a": [0, 0, 0], "b": [0.3, 0.2, 0.1]}, rows="vx")
    cp.select("b")
    head, _, body = bytes(cp.image.value).partition(b",")
    assert head == b"data:image/png;base64" and base64.b64decode(body) == bytes(cp.picture)
    assert bytes(cp.picture).startswith(PNG)


def test_jpeg_pictures_and_bad_format(r3):
    ex = widgets.explorer(r3, image_format="jpeg")
    assert bytes(ex.picture).startswith(b"\xff\xd8") and ex.picture_format == "jpeg"
    with pytest.raises(ValueError, match="image_format"):
        widgets.explorer(r3, image_format="gif")


def test_importing_widgets_leaves_pyplot_figures_alone(r3):
    n = len(plt.get_fignums())
    widgets.explorer(r3)
    widgets.config_picker(robots.planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]})
    assert len(plt.get_fignums()) == n  # no extra static copy under the inline backend


# --- the task space of the arm (kinlib.taskspace.default_task_rows) --------------------------------
def test_2r_explorer_sees_the_stretched_out_singularity():
    """A student's 2R arm: its task space is (ṗ_x, ṗ_y); at θ2 = 0 (stretched out) they lose rank.
    (All six rows of J have rank 2 everywhere, so testing them called this configuration regular.)"""
    chain = robots.planar_2r(1, 1)
    ex = widgets.explorer(chain, q=[0.4, 0.0])
    assert ex.rows == (3, 4)
    assert ex.state == "singular" and "SINGULAR configuration" in ex.status.value
    assert ex.info["rank"] == 1 and ex.info["full_rank"] == 2
    # independently: det of the ṗ rows from modern_robotics' forward kinematics is L1 L2 sin θ2
    assert ex.info["det"] == pytest.approx(math.sin(0.0), abs=1e-12)
    ex.update([0.4, 1.0])
    assert ex.state == "regular" and "singular" not in ex.status.value.lower()
    assert ex.info["det"] == pytest.approx(math.sin(1.0), abs=1e-9)
    ex.sliders[1].value = 0.0  # a slider move back to the stretched-out arm
    assert ex.state == "singular"
    assert "task rows of J: (ṗ_x, ṗ_y)" in ex.readout.value


def test_default_rows_follow_the_arm():
    assert widgets.explorer(robots.planar_offset_3r(1)).rows == (2, 3, 4)  # planar, 3 joints
    assert widgets.explorer(robots.cart_pole(1, 1)).rows == (3, 4)  # planar, 2 joints
    assert widgets.explorer(robots.spatial_rppr(1, 1)).rows == (3, 4, 5)  # spatial, 4 joints
    assert widgets.explorer(robots.ur5(), rate_sliders=False).rows == tuple(range(6))
    assert widgets.explorer(robots.planar_2r(1, 1), rows="planar").rows == (2, 3, 4)  # asked for: as given


def test_classify_is_rank_below_min_m_n():
    rng = np.random.default_rng(5)
    for m, n in ((2, 3), (3, 3), (6, 4), (3, 2)):
        A = rng.normal(size=(m, n))
        assert widgets.classify(A)["state"] != "singular"
        U, s, Vt = np.linalg.svd(A, full_matrices=False)
        s[-1] = 0.0  # one rank less than min(m, n)
        info = widgets.classify((U * s) @ Vt)
        assert info["state"] == "singular" and info["rank"] == min(m, n) - 1 == info["full_rank"] - 1
        assert info["manipulability"] == pytest.approx(0.0, abs=1e-12)
        assert (info["det"] is None) == (m != n)
    # a tall J (n < m) of full column rank is regular: w = √det(JᵀJ) > 0
    info = widgets.classify(np.vstack([np.eye(2), np.zeros((4, 2))]))
    assert info["state"] == "regular" and info["manipulability"] == pytest.approx(1.0)


# --- explorers show what the banner says; pictures on open (issue 13, items 3 and 5) ------------------------
def _span(html_text, cls):
    import re

    m = re.search(rf"<span class='{cls}'>([^<]*)</span>", html_text)
    return None if m is None else m.group(1)


def _geometric_J_mr(chain, q):
    S, M = np.array(chain.screws, float), np.array(chain.M, float)
    Js = mr.JacobianSpace(S, np.asarray(q, float))
    p = mr.FKinSpace(M, S, np.asarray(q, float))[:3, 3]
    return np.vstack([Js[:3], Js[3:] - np.cross(p, Js[:3].T).T])


def _held_map(chain, q):
    """J_ṗ N with N an orthonormal basis of null(J_ωz), by QR (independent of kinlib's SVD)."""
    J = _geometric_J_mr(chain, q)
    Q, _ = np.linalg.qr(J[[2]].T, mode="complete")
    return J[[3, 4]] @ Q[:, 1:]


def test_explorer_at_a_singular_configuration_of_notebook_05(r3):
    q = [math.pi / 6, -math.pi / 4, -math.pi / 3]
    ex = widgets.explorer(r3, q=[math.pi / 6, math.pi / 6, -math.pi / 3], show_maximum=False)
    assert "data-state='regular'" in ex.status.value and not ex.cannot_move.get_visible()
    ex.update(q)
    assert ex.state == "singular" and "class='kinlib-status' data-state='singular'" in ex.status.value
    assert _span(ex.readout.value, "kinlib-det") == "0"
    s = np.linalg.svd(_held_map(r3, q), compute_uv=False)
    assert s[1] < 1e-12
    assert _span(ex.readout.value, "kinlib-held") == f"{s[0]:.3g}, 0"
    np.testing.assert_allclose(ex.held_ellipse.semi_axes, s, atol=1e-12)
    # the free ṗ ellipse stays fat, as a second outline
    assert ex.ellipse.semi_axes == pytest.approx([2.79, 1.03], abs=0.01)
    # the red dashed line: the direction the tool cannot move with ω_z held (uᵀ J_ṗ N = 0)
    assert ex.cannot_move.get_visible()
    u = ex.cannot_move_direction
    assert np.linalg.norm(u @ _held_map(r3, q)) < 1e-9
    x, y = ex.cannot_move.get_data()
    d = np.array([x[1] - x[0], y[1] - y[0]])
    assert abs(d[0] * u[1] - d[1] * u[0]) < 1e-9 * np.linalg.norm(d)  # drawn along u
    tool = mr.FKinSpace(np.array(r3.M, float), np.array(r3.screws, float), np.array(q))[:2, 3]
    np.testing.assert_allclose([np.mean(x), np.mean(y)], tool, atol=1e-12)  # through the tool
    # near, not at, the singularity: still drawn, and det is a signed number
    ex.update([math.pi / 6, -math.pi / 4 + 0.03, -math.pi / 3])
    assert ex.state == "near" and ex.cannot_move.get_visible() and "data-state='near'" in ex.status.value
    det = _span(ex.readout.value, "kinlib-det")
    assert det[0] in "+-" and float(det) == pytest.approx(ex.info["det"], rel=1e-3)
    legend = [t.get_text() for t in ex.ax.get_legend().get_texts()]
    assert any("held" in t for t in legend) and any("all joints free" in t for t in legend)
    assert any("cannot move" in t for t in legend)


def test_det_is_never_a_signed_zero(r3):
    ex = widgets.explorer(r3, q=[0.0, -math.pi / 4, math.pi / 4])
    assert ex.state == "singular" and _span(ex.readout.value, "kinlib-det") == "0"
    assert "+0.0000" not in ex.readout.value and "-0.0000" not in ex.readout.value
    assert "√det(JJᵀ) = 0<" in ex.readout.value and "σ_min/σ_max = 0," in ex.readout.value


def test_explorer_without_orientation_rows_has_no_held_ellipse():
    import sympy as sp

    cp = robots.cart_pole(L=1, h=sp.Rational(1, 2))
    ex = widgets.explorer(cp, q=[0.0, math.pi / 3], qdot=[0.3, 1.0], rows=("vx", "vy"))
    assert ex.held_ellipse is None and _span(ex.readout.value, "kinlib-held") is None
    ex.update([0.7, math.pi / 3])
    c = ex.arm.sliders.get_paths()[0].vertices[:4].mean(axis=0)
    np.testing.assert_allclose(c, [0.7, 0.0], atol=1e-12)  # the cart moved with θ1


def test_spatial_explorer_holds_the_angular_rows():
    ur5 = robots.ur5()
    q = [0.3, -1.0, 1.2, 0.2, 1.0, 0.1]
    ex = widgets.explorer(ur5, q=q)
    assert ex.hold == (0, 1, 2)
    J = _geometric_J_mr(ur5, q)
    Q, _ = np.linalg.qr(J[:3].T, mode="complete")
    s = np.linalg.svd(J[3:] @ Q[:, 3:], compute_uv=False)
    np.testing.assert_allclose(ex.held_ellipse.semi_axes, s, rtol=1e-9)


def test_display_bundles_carry_a_static_picture(r3):
    import base64
    import io

    from PIL import Image

    ex = widgets.explorer(r3, q=[0.3, 0.5, -0.2])
    b = ex._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in b
    assert not b["text/plain"].startswith("Explorer(") and r3.name in b["text/plain"]
    im = Image.open(io.BytesIO(base64.b64decode(b["image/png"])))
    assert im.format == "PNG" and im.size == Image.open(io.BytesIO(ex.picture)).size
    cp = widgets.config_picker(r3, {"a": [0.1, 0.2, 0.3]})
    b = cp._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in b and not b["text/plain"].startswith("ConfigPicker(")
    assert Image.open(io.BytesIO(base64.b64decode(b["image/png"]))).format == "PNG"


def test_indexed_png_keeps_the_picture(r3):
    """The 8-bit PNG of a slider move is the full-colour picture to within the palette's rounding."""
    import io

    from PIL import Image

    ex = widgets.explorer(r3, q=[0.3, -0.6, 0.4])
    ex.update([0.5, -0.7, 0.2])
    fast = np.asarray(Image.open(io.BytesIO(ex.picture)).convert("RGB"), float)
    for a in ex._blit.artists:
        a.set_animated(False)
    full = np.asarray(Image.open(io.BytesIO(widgets_render.render_png(ex.fig))).convert("RGB"), float)
    assert fast.shape == full.shape
    white = np.all(full == 255, axis=2)
    assert white.mean() > 0.5 and np.all(fast[white] == 255)  # the paper stays exactly white
    assert np.mean(np.abs(fast - full)) < 2.0 and np.percentile(np.abs(fast - full).max(axis=2), 99) < 40
