"""kinlib.widgets: the explorer computed in the browser (kinlib/widgets/explorer.js with the functions kinlib
generates) draws the arm where the forward kinematics puts it and says the right thing about singular
configurations — checked against independent computation (modern_robotics, NumPy SVD, the closed-form
singular set), numerically with Node (when installed) and drawn in Chromium (``browser`` mark); the
configuration picker (problem 4.1) reacts to its buttons."""

import json
import math
import shutil
import subprocess

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import modern_robotics as mr  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import sympy as sp  # noqa: E402

from kinlib import robots, widgets  # noqa: E402
from kinlib.manipulability import NEAR_SINGULAR, peak_manipulability, singularity_state  # noqa: E402
from kinlib.taskspace import task_rows  # noqa: E402

PNG = b"\x89PNG"
NODE = shutil.which("node")

#: every robot of kinlib.robots, with numbers for its lengths, and its explorer's keywords (as the notebooks)
ROBOTS = {
    "cart_pole": (lambda: robots.cart_pole(1, sp.Rational(1, 2)), {"rows": ("vx", "vy")}),
    "planar_2r": (lambda: robots.planar_2r(1, sp.Rational(3, 4)), {}),
    "planar_3r": (lambda: robots.planar_3r(1, 1, 1), {}),
    "planar_offset_3r": (lambda: robots.planar_offset_3r(1), {}),
    "planar_rpp": (lambda: robots.planar_rpp(1), {}),
    "spatial_rppr": (lambda: robots.spatial_rppr(1, sp.Rational(3, 5)), {"rows": "all"}),
    "ur5": (lambda: robots.ur5(), {}),
}


def test_every_robot_is_covered():
    made = {n for n in dir(robots) if callable(getattr(robots, n)) and not n.startswith("_")}
    makers = {n for n in made if n not in ("SerialChain", "describe", "exact_number", "from_urdf_joints", "length")}
    assert makers <= set(ROBOTS), makers - set(ROBOTS)


@pytest.fixture(scope="module")
def r3():
    return robots.planar_offset_3r(1)


def tool_position(chain, q):
    return mr.FKinSpace(np.array(chain.M, float), np.array(chain.screws, float), np.asarray(q, float))[:3, 3]


def _configs(ex, k, seed):
    rng = np.random.default_rng(seed)
    lo = np.array([r[0] for r in ex.ranges])
    hi = np.array([r[1] for r in ex.ranges])
    return lo + (hi - lo) * rng.random((k, ex.chain.n))


# --- kernel side: what the explorer sends ---------------------------------------------------------------
def test_the_05_explorer_knows_the_closed_form_singular_set(r3):
    """Problem 5.1: det J ∝ sin(θ2 + π/4): the family θ2 = −π/4 + kπ, exactly as singular_configurations says."""
    ex = widgets.explorer(r3, q=[math.pi / 6, math.pi / 6, -math.pi / 3])
    assert ex.conditions == [{"families": {"1": {"offset": -math.pi / 4, "period": math.pi}}}] and ex.complete
    assert ex.state != "singular"
    assert ex.update([0.3, -math.pi / 4, 0.2]).state == "singular"
    assert ex.update([0.3, 3 * math.pi / 4, 0.2]).state == "singular"
    assert ex.update([0.3, -math.pi / 4 + 1e-6, 0.2]).state == "near"  # a float off the family: near, not singular


def test_several_joint_families_need_all_joints():
    """planar 3R, task (ṗ_x, ṗ_y): singular only when θ2 and θ3 are both multiples of π (stretched and folded)."""
    ex = widgets.explorer(robots.planar_3r(1, 1, 1), rows=("vx", "vy"), q=[0.2, 0.0, 0.5])
    assert {tuple(sorted(c["families"])) for c in ex.conditions} == {("1", "2")}
    assert ex.state != "singular" and ex.update([0.2, 0.0, math.pi]).state == "singular"


def test_near_rule_is_the_course_rule(r3):
    """The explorer's "near" is kinlib.manipulability.singularity_state's: w < NEAR_SINGULAR · w_max, with w_max
    the arm's largest manipulability over the slider ranges (within the sample: at most, never above it)."""
    ex = widgets.explorer(r3)
    w_max = peak_manipulability(r3, ex.rows, ex.ranges)
    assert w_max * (1 - 1e-3) <= ex.w_max <= np.sqrt(2) + 1e-12  # √2 L² exactly for this arm (L = 1)
    for q in [*_configs(ex, 20, 1), [0.3, -np.pi / 4 + 0.05, 0.2]]:
        ex.update(q)
        J = task_rows(r3.jacobian_geometric(q), ex.rows)
        expected = singularity_state(J, ex.w_max)
        if ex.state != "singular":
            assert ex.state == expected
        assert (ex.state == "near") == (np.prod(np.linalg.svd(J, compute_uv=False)) < NEAR_SINGULAR * ex.w_max)


def test_near_rule_is_unit_aware():
    """Lengths in mm instead of m: the same w / w_max (the rule has no unit)."""
    q = [0.3, 0.9, -0.4]
    r_m, r_mm = robots.planar_offset_3r(1), robots.planar_offset_3r(1000)
    a = widgets.explorer(r_m, q=q).info["w_ratio"]
    b = widgets.explorer(r_mm, q=q).info["w_ratio"]
    assert abs(a - b) < 1e-12


def test_bad_input(r3):
    with pytest.raises(ValueError, match="L"):
        widgets.explorer(robots.planar_offset_3r())
    with pytest.raises(ValueError, match="q"):
        widgets.explorer(r3, q=[0, 0])
    with pytest.raises(ValueError, match="ranges"):
        widgets.explorer(r3, ranges={2: (1, -1)})
    with pytest.raises(ValueError, match="size"):
        widgets.explorer(r3, size=10)
    with pytest.raises(TypeError, match="unexpected"):
        widgets.explorer(r3, colour="red")


def test_display_bundle_carries_the_front_end_and_a_static_picture(r3):
    import base64

    b = widgets.explorer(r3)._repr_mimebundle_()
    assert set(b) == {"application/javascript", "image/png", "text/plain"}
    assert base64.b64decode(b["image/png"]).startswith(PNG)
    js = b["application/javascript"]
    assert "function skel(q)" in js and "function jg(q)" in js and "kinlibExplorer" in js
    assert "</script" not in js.lower()  # safe inside a page's <script>
    assert "explorer of planar_offset_3r" in b["text/plain"]


def test_output_is_deterministic(r3):
    assert widgets.explorer(r3).javascript == widgets.explorer(r3).javascript


def test_importing_widgets_leaves_pyplot_figures_alone(r3):
    n = len(plt.get_fignums())
    widgets.explorer(r3)._repr_mimebundle_()
    widgets.config_picker(robots.planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]})
    assert len(plt.get_fignums()) == n


# --- the generated JavaScript, run by Node: the same numbers as NumPy ---------------------------------
_NODE_RUN = """
global.window = global; global.element = {}; global.performance = {now: () => 0};
const fs = require('fs');
const src = fs.readFileSync(process.argv[2], 'utf8');
const job = JSON.parse(fs.readFileSync(process.argv[3], 'utf8'));
const results = [];
global.kinlibExplorer_capture = null;
window.kinlibExplorer = null;
eval(src.replace('window.kinlibExplorer(host, S);', 'global.kinlibExplorer_capture = S;'));
const S = global.kinlibExplorer_capture, M = window.kinlibExplorerMath;
for (const q of job.qs) {
  const st = M.compute(S, q, S.qd0);
  results.push({pts: st.pts, J: st.J, s: st.s, det: st.det, state: st.state, wRatio: st.wRatio, w: st.w,
                held: st.held ? st.held.s : null, free: st.free.s, marks: q.map((_, j) => M.marksFor(S, q, j))});
}
process.stdout.write(JSON.stringify(results));
"""


def _node(ex, qs, tmp_path):
    (tmp_path / "run.js").write_text(_NODE_RUN)
    (tmp_path / "ex.js").write_text(ex.javascript)
    (tmp_path / "job.json").write_text(json.dumps({"qs": [list(map(float, q)) for q in qs]}))
    out = subprocess.run(
        [NODE, str(tmp_path / "run.js"), str(tmp_path / "ex.js"), str(tmp_path / "job.json")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.skipif(NODE is None, reason="node is not installed")
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_generated_javascript_equals_numpy(name, tmp_path):
    """At random configurations: the skeleton, J, σ's, det, manipulability and the state computed by the
    browser code equal NumPy's (SVD) and modern_robotics' forward kinematics."""
    make, kw = ROBOTS[name]
    chain = make()
    ex = widgets.explorer(chain, **kw)
    qs = _configs(ex, 12, 7)
    for q, got in zip(qs, _node(ex, qs, tmp_path)):
        pts = np.array(got["pts"]).T
        np.testing.assert_allclose(pts, chain.skeleton(q), atol=1e-9)
        np.testing.assert_allclose(pts[:, -1], tool_position(chain, q), atol=1e-9)
        J = chain.jacobian_geometric(q)
        np.testing.assert_allclose(np.array(got["J"]).reshape(6, chain.n), J, atol=1e-9)
        Jr = task_rows(J, ex.rows)
        s = np.linalg.svd(Jr, compute_uv=False)
        np.testing.assert_allclose(got["s"], s, atol=1e-7 * max(1.0, s[0]))
        np.testing.assert_allclose(got["w"], np.prod(s), atol=1e-7 * max(1.0, s[0]) ** len(s))
        if Jr.shape[0] == Jr.shape[1]:
            np.testing.assert_allclose(got["det"], np.linalg.det(Jr), atol=1e-8 * max(1.0, s[0]) ** len(s))
        ex.update(q)
        assert got["state"] == ex.state
        assert abs(got["wRatio"] - ex.info["w_ratio"]) < 1e-7


@pytest.mark.skipif(NODE is None, reason="node is not installed")
def test_slider_marks_are_the_closed_form_families(r3, tmp_path):
    """The 05 robot: θ2's track is marked at −π/4 + kπ in [−π, π] (−π/4 and 3π/4), whatever θ1 and θ3; the
    other tracks carry no mark (the family does not involve them)."""
    ex = widgets.explorer(r3)
    qs = _configs(ex, 5, 3)
    for got in _node(ex, qs, tmp_path):
        assert got["marks"][0] == [] and got["marks"][2] == []
        np.testing.assert_allclose(got["marks"][1], [-math.pi / 4, 3 * math.pi / 4], atol=1e-15)


@pytest.mark.skipif(NODE is None, reason="node is not installed")
def test_expression_conditions_are_marked_where_they_vanish(tmp_path):
    """The UR5 (closed form asked for): the shoulder condition f(θ2, θ3, θ4) = 0 is marked on θ2's track at
    roots of f found by bisection; f vanishes there."""
    ur5 = robots.ur5()
    ex = widgets.explorer(ur5, singular_budget=60.0)
    k = next(c for c in ex.conditions if "expr" in c)
    q = np.array([0.1, 0.4, -0.8, 0.3, 1.1, 0.2])
    got = _node(ex, [q], tmp_path)[0]
    assert got["marks"][1], "no mark on θ2's track"
    f = ex._exprs[k["expr"]]
    for x in got["marks"][1]:
        qq = q.copy()
        qq[1] = x
        assert abs(f(qq)[0, 0]) < 1e-9 * k["scale"]


# --- drawn in Chromium: what is drawn is where fk says ------------------------------------------------
@pytest.fixture(scope="module")
def chromium():
    from pathlib import Path

    if not Path("/usr/bin/chromium").exists():
        pytest.skip("chromium is not installed")
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path="/usr/bin/chromium", args=["--no-sandbox"])
        yield b
        b.close()


def page_with(browser, exs, tmp_path):
    body = "".join(
        f'<div class="out"><script>var element = document.currentScript.parentNode;\n{ex.javascript}</script></div>'
        for ex in exs
    )
    path = tmp_path / "explorers.html"
    path.write_text(f"<!doctype html><html><head><meta charset='utf-8'></head><body>{body}</body></html>")
    page = browser.new_page(viewport={"width": 1100, "height": 900})
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.route("**/*", lambda route: route.continue_() if route.request.url.startswith("file:") else route.abort())
    page.goto(path.as_uri())
    return page, errors


_READ_BACK = """([q]) => {
  const root = document.querySelector('.kinlib-explorer'), X = root.kinlib;
  X.set(q);
  const pick = sel => Array.from(root.querySelectorAll(sel)).map(e => ({
    x: +e.getAttribute('data-x'), y: +e.getAttribute('data-y'), z: +e.getAttribute('data-z'),
    cx: e.tagName === 'circle' ? +e.getAttribute('cx') : +e.getAttribute('x') + 6,
    cy: e.tagName === 'circle' ? +e.getAttribute('cy') : +e.getAttribute('y') + 6}));
  const tool = root.querySelector('.kinlib-tool');
  const d = tool.getAttribute('d').match(/[-0-9.]+/g).map(Number);
  return {joints: pick('.kinlib-joint'), tool: {x: +tool.getAttribute('data-x'), y: +tool.getAttribute('data-y'),
          z: +tool.getAttribute('data-z'), cx: d[2], cy: d[1]}, state: X.st.state,
          view: X.S.view, k: X.S.k, px0: X.S.px0, py0: X.S.py0};
}"""


@pytest.mark.browser
@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_drawn_joints_and_tool_are_at_fk(chromium, name, tmp_path):
    """Read back from the SVG at random configurations: each joint's and the tool's world coordinates equal
    the skeleton and modern_robotics' FKinSpace; in 2-D their pixel positions are those points under one
    scale for x and y (equal axes, no stretching), and the SVG is shown at the size it is drawn."""
    make, kw = ROBOTS[name]
    chain = make()
    ex = widgets.explorer(chain, **kw)
    page, errors = page_with(chromium, [ex], tmp_path)
    try:
        box = page.locator("svg.kinlib-picture").bounding_box()
        assert abs(box["width"] - ex.spec["size"]) < 1 and abs(box["height"] - ex.spec["size"]) < 1
        for q in _configs(ex, 6, 11):
            got = page.evaluate(_READ_BACK, [q.tolist()])
            sk = chain.skeleton(q)
            world = np.array([[j["x"], j["y"], j["z"]] for j in got["joints"]]).T
            np.testing.assert_allclose(world, sk[:, 1:-1], atol=1e-9)
            t = got["tool"]
            np.testing.assert_allclose([t["x"], t["y"], t["z"]], tool_position(chain, q), atol=1e-9)
            if ex.planar:
                v, k = got["view"], got["k"]
                for p, w in zip(got["joints"] + [t], list(sk[:, 1:-1].T) + [sk[:, -1]]):
                    assert abs(p["cx"] - (got["px0"] + (w[0] - v["x0"]) * k)) < 0.01
                    assert abs(p["cy"] - (got["py0"] - (w[1] - v["y0"]) * k)) < 0.01
            assert got["state"] == ex.update(q).state
        assert not errors, errors
    finally:
        page.close()


@pytest.mark.browser
def test_keyboard_moves_a_slider_and_the_live_text_says_so(chromium, r3, tmp_path):
    """θ2 of the 05 robot to −π/4 with the arrow keys only: singular banner, det J 0, a collapsed held
    ellipse, the blocked direction drawn, and the aria-live text says it in words."""
    ex = widgets.explorer(r3, q=[math.pi / 6, math.pi / 6, -math.pi / 3])
    page, errors = page_with(chromium, [ex], tmp_path)
    try:
        s = page.locator("input.kinlib-slider[data-joint='2']")
        s.focus()
        for _ in range(75):  # π/6 → −π/4: 75 steps of π/180
            page.keyboard.press("ArrowLeft")
        root = page.locator(".kinlib-explorer")
        assert root.locator(".kinlib-status").get_attribute("data-state") == "singular"
        assert root.locator(".kinlib-det").inner_text() == "0"
        held = [float(x) for x in root.locator(".kinlib-held").inner_text().split(",")]
        assert min(held) == 0 and max(held) > 0
        assert root.locator(".kinlib-blocked").count() == 1
        live = root.locator(".kinlib-live")
        assert live.get_attribute("aria-live") == "polite"
        text = live.inner_text()
        assert "Singular configuration" in text and "cannot move along" in text and "Singular values" in text
        assert "θ2 = -0.785 rad (-45.0°)" in s.get_attribute("aria-valuetext")
        assert not errors, errors
    finally:
        page.close()


# --- the configuration picker (problem 4.1) -----------------------------------------------------------
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
    assert cp.buttons.style.button_width == "auto"  # buttons as wide as their labels (a fixed width cut them)


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
