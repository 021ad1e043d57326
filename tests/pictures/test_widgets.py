"""kinlib.widgets: the explorer computed in the browser (kinlib/widgets/explorer.js with the functions kinlib
generates) draws the arm where the forward kinematics puts it and says the right thing about singular
configurations — checked against independent computation (modern_robotics, NumPy SVD, the closed-form
singular set), numerically with Node (when installed) and drawn in Chromium (``browser`` mark); the animation
of a path (5.2) draws the arm where fk puts it and says what the near rule says at every step; the configuration
picker (problem 4.1) draws the configuration each button names."""

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

from kinlib import plotting, robots, widgets  # noqa: E402
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
    "puma560": (lambda: robots.puma560(), {}),
    "stanford": (lambda: robots.stanford(), {}),
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


def _path_05(chain, n=6):
    """Notebook 05's sweep: θ1 = θ3 = π/4, θ2 through −π/4, 2n + 1 steps denser near the middle."""
    steps = np.arange(-n, n + 1)
    return plotting.sweep(
        chain, 2, -np.pi / 4 + 0.78 * np.sign(steps) * (steps / n) ** 2, q_fixed=[np.pi / 4, 0, np.pi / 4]
    )


CONFIGS_4_1 = {  # problem 4.1 (its rows: ṗ_x, ṗ_x, ṗ_y)
    "θ = (−π/8, π/4, π/8)": ([-math.pi / 8, math.pi / 4, math.pi / 8], "vx"),
    "θ = (3π/4, −π/4, 0)": ([3 * math.pi / 4, -math.pi / 4, 0], "vx"),
    "θ = (π/2, −π/8, −π/2)": ([math.pi / 2, -math.pi / 8, -math.pi / 2], "vy"),
}


def _picker_4_1():
    return widgets.config_picker(robots.planar_3r(1, 1, 1), {k: q for k, (q, _) in CONFIGS_4_1.items()},
                                 rows={k: r for k, (_, r) in CONFIGS_4_1.items()})  # fmt: skip


@pytest.mark.parametrize("what", ["explorer", "animation", "picker"])
def test_display_bundle_carries_the_front_end_and_a_static_picture(r3, what):
    import base64
    import io

    from PIL import Image

    obj = {"explorer": lambda: widgets.explorer(r3), "animation": lambda: widgets.animate_singularity(r3, _path_05(r3)),
           "picker": _picker_4_1}[what]()  # fmt: skip
    b = obj._repr_mimebundle_()
    assert set(b) == {"application/javascript", "image/png", "text/plain"}
    png = base64.b64decode(b["image/png"])
    assert png.startswith(PNG) and min(Image.open(io.BytesIO(png)).size) > 150
    js = b["application/javascript"]
    entry = {"explorer": "kinlibExplorer", "animation": "kinlibAnimation", "picker": "kinlibPicker"}[what]
    assert "function skel(q)" in js and "function jg(q)" in js and f"window.{entry}(host, S);" in js
    assert "</script" not in js.lower()  # safe inside a page's <script>
    assert {"explorer": "explorer of planar_offset_3r", "animation": "1 singular, 4 near",
            "picker": "configuration picker for planar_3r"}[what] in b["text/plain"]  # fmt: skip


def test_output_is_deterministic(r3):
    assert widgets.explorer(r3).javascript == widgets.explorer(r3).javascript


def test_importing_widgets_leaves_pyplot_figures_alone(r3):
    n = len(plt.get_fignums())
    widgets.explorer(r3)._repr_mimebundle_()
    widgets.config_picker(robots.planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]})._repr_mimebundle_()
    widgets.animate_singularity(r3, [[0, 0, 0], [0, 0.1, 0]])._repr_mimebundle_()
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


# --- the animation of a path (5.2), in Chromium: fk at every step, the rule's banner, the keyboard --------------
_READ_STEP = """() => {
  const root = document.querySelector('.kinlib-animation'), X = root.kinlib;
  const pick = sel => Array.from(root.querySelectorAll(sel)).map(e => [+e.getAttribute('data-x'), +e.getAttribute('data-y'),
    +e.getAttribute('data-z'), e.tagName === 'circle' ? +e.getAttribute('cx') : +e.getAttribute('x') + 6,
    e.tagName === 'circle' ? +e.getAttribute('cy') : +e.getAttribute('y') + 6]);
  const tool = root.querySelector('.kinlib-tool'), d = tool.getAttribute('d').match(/[-0-9.]+/g).map(Number);
  return {step: +root.getAttribute('data-step'), input: +root.querySelector('.kinlib-step').value,
          cursor: +root.querySelector('.kinlib-cursor').getAttribute('data-step'),
          joints: pick('.kinlib-joint'), tool: [+tool.getAttribute('data-x'), +tool.getAttribute('data-y'),
          +tool.getAttribute('data-z'), d[2], d[1]], state: root.querySelector('.kinlib-status').getAttribute('data-state'),
          banner: root.querySelector('.kinlib-status').textContent, held: root.querySelector('.kinlib-held').textContent,
          blocked: root.querySelectorAll('.kinlib-blocked').length, live: root.querySelector('.kinlib-live').textContent,
          view: X.S.view, k: X.S.k, px0: X.S.px0, py0: X.S.py0, states: X.states};
}"""


@pytest.mark.browser
def test_animation_draws_fk_and_the_rule_at_every_step(chromium, r3, tmp_path):
    """Notebook 05's path, stepped with the keyboard only (the step slider's arrow keys): at every step the drawn
    joints and tool (read back from the SVG) are the skeleton and modern_robotics' FKinSpace, at pixels under one
    scale; the banner is what kinlib.nearsingular says (w < NEAR_SINGULAR · w_max, w_max = √2 L² exactly), the
    singular step shows the collapsed held ellipse and the blocked direction, the aria-live sentence names the step
    and the state; the buttons step (back from the first wraps to the last) and play/pause."""
    path = _path_05(r3)
    anim = widgets.animate_singularity(r3, path, velocity_scale=0.35)
    rule = list(singularity_state(task_rows(r3.jacobian_geometric(path), "planar"), math.sqrt(2)))
    assert rule.count("singular") == 1 and rule.count("near") == 4 and anim.states == rule
    page, errors = page_with(chromium, [anim], tmp_path)
    try:
        page.locator("input.kinlib-step").focus()
        for k, q in enumerate(path):
            if k:
                page.keyboard.press("ArrowRight")
            got = page.evaluate(_READ_STEP)
            assert got["step"] == got["input"] == got["cursor"] == k
            assert got["states"] == rule
            world = np.array([j[:3] for j in got["joints"]]).T
            np.testing.assert_allclose(world, r3.skeleton(q)[:, 1:-1], atol=1e-9)
            np.testing.assert_allclose(got["tool"][:3], tool_position(r3, q), atol=1e-9)
            v, s = got["view"], got["k"]
            for p in got["joints"] + [got["tool"]]:
                assert abs(p[3] - (got["px0"] + (p[0] - v["x0"]) * s)) < 0.01
                assert abs(p[4] - (got["py0"] - (p[1] - v["y0"]) * s)) < 0.01
            assert got["state"] == rule[k], (k, got["state"], rule[k])
            assert got["live"].startswith(f"Step {k + 1} of {len(path)}")
            held = [float(x) for x in got["held"].split(",")]
            if rule[k] == "singular":
                assert min(held) == 0 < max(held) and got["blocked"] == 1
                assert "SINGULAR" in got["banner"] and "Singular configuration" in got["live"]
                assert "cannot move along" in got["live"]
            else:
                assert min(held) > 0 and ("Near a singular" in got["live"]) == (rule[k] == "near")
        page.keyboard.press("Home")
        assert page.evaluate(_READ_STEP)["step"] == 0
        page.locator("button.kinlib-prev").click()  # back from the first: the last
        assert page.evaluate(_READ_STEP)["step"] == len(path) - 1
        page.locator("button.kinlib-next").click()
        assert page.evaluate(_READ_STEP)["step"] == 0
        play = page.locator("button.kinlib-play")
        play.click()
        assert play.get_attribute("aria-pressed") == "true"
        page.wait_for_function("() => +document.querySelector('.kinlib-animation').getAttribute('data-step') >= 2",
                               timeout=60000)  # fmt: skip
        play.press("Enter")  # pause, from the keyboard
        assert play.get_attribute("aria-pressed") == "false"
        at = page.evaluate(_READ_STEP)["step"]
        page.wait_for_timeout(3 * anim.interval)
        assert page.evaluate(_READ_STEP)["step"] == at, "still playing after pause"
        assert not errors, errors
    finally:
        page.close()


# --- the configuration picker (problem 4.1) -----------------------------------------------------------
_READ_PICK = """() => {
  const root = document.querySelector('.kinlib-picker'), X = root.kinlib;
  const attrs = (sel, names) => Array.from(root.querySelectorAll(sel)).map(e => names.map(n => +e.getAttribute(n)));
  return {name: root.getAttribute('data-config'),
          pressed: Array.from(root.querySelectorAll('button.kinlib-config')).filter(b => b.getAttribute('aria-pressed') === 'true').map(b => b.getAttribute('data-name')),
          focused: document.activeElement.getAttribute('data-name'),
          joints: attrs('.kinlib-joint', ['data-x', 'data-y', 'data-z']), tool: attrs('.kinlib-tool', ['data-x', 'data-y', 'data-z'])[0],
          arrows: attrs('.kinlib-jvel', ['data-x', 'data-y']), bars: attrs('.kinlib-bar', ['data-value']).map(b => b[0]),
          best: root.querySelector('.kinlib-best').textContent, live: root.querySelector('.kinlib-live').textContent};
}"""


@pytest.mark.browser
def test_picker_buttons_draw_the_configurations_they_name(chromium, tmp_path):
    """Problem 4.1 in Chromium, from the keyboard (Tab to the buttons, arrow keys between them) and the mouse: each
    button shows the configuration it names — joints and tool (read back from the SVG) at the skeleton and fk,
    each joint's arrow the column of J_ṗ (finite differences of modern_robotics' FKinSpace), the bars the chosen
    row, the largest named as problem 4.1 says (a tie between joints 1 and 2 in (c))."""
    chain = robots.planar_3r(1, 1, 1)
    cp = _picker_4_1()
    names = list(CONFIGS_4_1)
    best = ["largest |ṗ_x|: joint 2", "largest |ṗ_x|: joint 1", "largest |ṗ_y|: a tie between joints 1 and 2"]
    page, errors = page_with(chromium, [cp], tmp_path)
    h = 1e-6
    try:
        page.keyboard.press("Tab")  # the first control of the page: the first configuration's button
        for k, name in enumerate(names):
            if k:
                page.keyboard.press("ArrowRight")
            got = page.evaluate(_READ_PICK)
            assert got["name"] == name and got["pressed"] == [name] and got["focused"] == name
            q, row = np.array(CONFIGS_4_1[name][0]), CONFIGS_4_1[name][1]
            np.testing.assert_allclose(np.array(got["joints"]).T, chain.skeleton(q)[:, 1:-1], atol=1e-9)
            np.testing.assert_allclose(got["tool"], tool_position(chain, q), atol=1e-9)
            fd = np.array(
                [(tool_position(chain, q + h * e) - tool_position(chain, q - h * e)) / (2 * h) for e in np.eye(3)]
            )
            np.testing.assert_allclose(got["arrows"], fd[:, :2], atol=1e-6)
            np.testing.assert_allclose(got["bars"], fd[:, 0 if row == "vx" else 1], atol=1e-6)
            assert got["best"] == best[k] and name in got["live"]
            assert cp.select(name).best == {0: (2,), 1: (1,), 2: (1, 2)}[k]  # the kernel's copy agrees
        page.locator("button.kinlib-config").first.click()
        assert page.evaluate(_READ_PICK)["name"] == names[0]
        assert not errors, errors
    finally:
        page.close()


def test_config_picker_problem_4_1():
    """The kernel's copy: contributions are the row of J_ṗ (finite differences of FKinSpace), the largest named."""
    chain = robots.planar_3r(1, 1, 1)
    cp = _picker_4_1()
    expected_best = dict(zip(CONFIGS_4_1, [(2,), (1,), (1, 2)]))  # problem 4.1 (a tie in the third)
    h = 1e-6
    for name, (q, row) in CONFIGS_4_1.items():
        cp.select(name)
        q = np.array(q)
        r = 0 if row == "vx" else 1
        fd = [(tool_position(chain, q + h * e) - tool_position(chain, q - h * e))[r] / (2 * h) for e in np.eye(3)]
        np.testing.assert_allclose(cp.contributions, fd, atol=1e-6)
        assert cp.best == expected_best[name] and cp.name == name
    assert "tie between joints 1 and 2" in cp.table
    assert cp.spec["start"] == 2 and "joint 2" in cp.select(list(CONFIGS_4_1)[0]).table


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
    with pytest.raises(ValueError, match="scale"):
        widgets.config_picker(chain, {"a": [0, 0, 0]}, scale=-1)
    with pytest.raises(TypeError, match="unexpected"):
        widgets.config_picker(chain, {"a": [0, 0, 0]}, colour="red")
    cp = widgets.config_picker(chain, {"a": [0, 0, 0]})
    with pytest.raises(ValueError, match="unknown configuration"):
        cp.select("b")


def test_animation_bad_input(r3):
    with pytest.raises(ValueError, match="path"):
        widgets.animate_singularity(r3, [[0, 0, 0]])
    with pytest.raises(ValueError, match="path"):
        widgets.animate_singularity(r3, [["a", 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match="path"):
        widgets.animate_singularity(r3, [[np.nan, 0, 0], [0, 0, 0]])
    with pytest.raises(ValueError, match="interval"):
        widgets.animate_singularity(r3, np.zeros((2, 3)), interval=0)


# --- the students' version (issue 30: kinlib.widgets.without_answers) ---------------------------------------------
def test_students_version_sends_nothing_that_answers_a_part(r3):
    """The 05 explorer's students' version: its script holds no closed-form singular set (no family offsets, no
    generated condition), no largest manipulability (5.4: √2 L² here), and its text no state; the original is
    unchanged. The animation's and the picker's students' versions likewise; anything else is refused."""
    ex = widgets.explorer(r3, q=[0.3, -math.pi / 4, 0.2])
    st = widgets.without_answers(ex)
    js, full = st.javascript, ex.javascript
    assert ex.spec["conditions"] and '"offset":-0.785398' in full and "1.41421" in full  # what the solutions show
    assert '"conditions":[]' in js and '"offset"' not in js and "1.41421" not in js and "function c0" not in js
    assert '"answers":false' in js and "singular" not in st._repr_mimebundle_()["text/plain"]
    assert ex.spec["conditions"] and ex.answers and "singular" in ex._repr_mimebundle_()["text/plain"]
    anim = widgets.animate_singularity(r3, _path_05(r3))
    sa = widgets.without_answers(anim)
    assert "singular" not in sa._repr_mimebundle_()["text/plain"] and '"conditions":[]' in sa.javascript
    assert "1.41421" not in sa.javascript and "1 singular" in anim._repr_mimebundle_()["text/plain"]
    sp_ = widgets.without_answers(_picker_4_1())
    assert '"answers":false' in sp_.javascript
    with pytest.raises(TypeError, match="without_answers"):
        widgets.without_answers(r3)


_READ_STUDENTS = """() => {
  const root = document.querySelector('.kinlib-explorer');
  return {status: root.querySelector('.kinlib-status').textContent, state: root.getAttribute('data-state'),
          marks: root.querySelectorAll('.kinlib-mark').length, det: root.querySelectorAll('.kinlib-det').length,
          blocked: root.querySelectorAll('.kinlib-blocked').length, readout: root.querySelector('.kinlib-readout').textContent,
          legend: root.querySelector('.kinlib-legend').textContent, live: root.querySelector('.kinlib-live').textContent,
          held: root.querySelector('.kinlib-held').textContent,
          desc: Array.from(root.querySelectorAll('.kinlib-sr')).map(e => e.textContent).join(' ')};
}"""


@pytest.mark.browser
def test_students_explorer_marks_nothing_at_the_singular_configuration(chromium, r3, tmp_path):
    """The students' version of the 05 explorer, moved with the keyboard onto θ2 = −π/4 (5.1's answer): the held
    ellipse collapses as the arm does, but no mark on a track, no banner, no det J / w / σ / rank readout, no blocked
    direction, no "singular" in the live sentence, the slider descriptions or the legend."""
    ex = widgets.without_answers(widgets.explorer(r3, q=[math.pi / 6, math.pi / 6, -math.pi / 3], show_maximum=False))
    page, errors = page_with(chromium, [ex], tmp_path)
    try:
        s = page.locator("input.kinlib-slider[data-joint='2']")
        s.focus()
        for _ in range(75):  # π/6 → −π/4
            page.keyboard.press("ArrowLeft")
        got = page.evaluate(_READ_STUDENTS)
        held = [float(x) for x in got["held"].split(",")]
        assert min(held) == 0 < max(held)  # the picture still shows what happens
        assert got["marks"] == got["det"] == got["blocked"] == 0 and got["status"] == ""
        assert got["state"] == "unmarked"
        for key in ("readout", "legend", "live", "desc"):
            low = got[key].lower()
            assert "singular" not in low and "det" not in low and "rank" not in low and "σ" not in low, (key, got[key])
        assert not errors, errors
    finally:
        page.close()


@pytest.mark.browser
def test_animation_plays_once_at_a_pace_and_stays_on_the_singular_step(chromium, r3, tmp_path):
    """5.2's animation: by default it stops at the last step (no endless loop), spends `dwell` on the singular
    step (longer than a step) and has a step of at least half a second. Asserted on the spec and on what the
    player does (the step it stops on), never on how long the machine took."""
    anim = widgets.animate_singularity(r3, _path_05(r3))
    assert anim.spec["loop"] is False and anim.spec["interval"] >= 500 and anim.spec["dwell"] > anim.spec["interval"]
    fast = widgets.animate_singularity(r3, _path_05(r3), interval=10, dwell=10)  # the behaviour, quickly
    page, errors = page_with(chromium, [fast], tmp_path)
    try:
        page.locator("button.kinlib-play").click()
        page.wait_for_function("() => document.querySelector('button.kinlib-play').getAttribute('aria-pressed') === 'false'",
                               timeout=60000)  # fmt: skip
        assert page.evaluate(_READ_STEP)["step"] == len(fast.path) - 1  # stopped at the end, not looping
        assert not errors, errors
    finally:
        page.close()
