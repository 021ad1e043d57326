"""The drawings are the kinematics (issue 13, item 2): for every robot in ``kinlib.robots`` the drawn joints,
sliders and tool, read back from the matplotlib artists, sit where the product of exponentials puts them.

Oracle: ``modern_robotics.FKinSpace`` (independent of kinlib): with T_k = e^{[S1]θ1} ⋯ e^{[Sk]θk},
joint i is drawn at T_{i−1}(p_i) (p_i its home point), the slider of a prismatic joint at T_i(p_i), the
tool origin at FKinSpace(M, S, θ) and the tool frame's axes are its rotation's columns.
"""

from __future__ import annotations

import inspect

import matplotlib
import numpy as np
import pytest
import sympy as sp

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import modern_robotics as mr  # noqa: E402

from kinlib import robots  # noqa: E402
from kinlib.chains import SerialChain  # noqa: E402
from kinlib.plotting import draw_chain  # noqa: E402

RNG_SEED = 20261123
N_CONFIGS = 12


def _urdf_arm():
    """A URDF-built arm with a prismatic joint between two revolute ones (not a function of lengths)."""
    return robots.from_urdf_joints(
        [
            ("revolute", (0, 0, 0.1), (0, 0, 0), (0, 0, 1)),
            ("prismatic", (0.3, 0, 0), (0, 0, 0), (1, 0, 0)),
            ("revolute", (0.2, 0, 0), (sp.pi / 2, 0, 0), (0, 0, 1)),
        ],
        tool=((0, 0, 0.25), (0, 0, 0)),
        name="urdf_rpr",
    )


def _all_robots():
    """Every robot function of kinlib.robots (found by introspection: public callables returning a
    SerialChain when called with numeric lengths), with random exact lengths, plus a URDF-built arm."""
    rng = np.random.default_rng(RNG_SEED)
    out = []
    for name in robots.__all__:
        f = getattr(robots, name)
        if name in ("length", "from_urdf_joints") or not callable(f):
            continue
        params = inspect.signature(f).parameters
        lengths = [sp.Rational(int(rng.integers(3, 20)), 10) for _ in params]
        chain = f(*lengths)
        assert isinstance(chain, SerialChain), name
        out.append(pytest.param(chain, id=name))
    out.append(pytest.param(_urdf_arm(), id="from_urdf_joints"))
    return out


ROBOTS = _all_robots()


def test_every_robot_function_is_covered():
    names = {p.id for p in ROBOTS}
    funcs = {n for n in robots.__all__ if callable(getattr(robots, n)) and n != "length"}
    assert funcs <= names
    assert {"cart_pole", "planar_rpp", "spatial_rppr", "ur5"} <= names


def _oracle(chain, q):
    """(joint points T_{i−1}(p_i) (3, n), slider points T_i(p_i) of prismatic joints (3, #P), T(θ)) by
    modern_robotics."""
    S = np.array(chain.screws, dtype=float)
    M = np.array(chain.M, dtype=float)
    P = np.array(chain.joint_points, dtype=float)
    joints, sliders = [], []
    for i in range(chain.n):
        T_before = mr.FKinSpace(np.eye(4), S[:, :i], q[:i]) if i else np.eye(4)
        joints.append(T_before[:3, :3] @ P[:, i] + T_before[:3, 3])
        if chain.joint_types[i] == "P":
            T_after = mr.FKinSpace(np.eye(4), S[:, : i + 1], q[: i + 1])
            sliders.append(T_after[:3, :3] @ P[:, i] + T_after[:3, 3])
    T = mr.FKinSpace(M, S, q)
    return np.array(joints).T, (np.array(sliders).T if sliders else np.zeros((3, 0))), T


def _line_points(line, three_d: bool) -> np.ndarray:
    if three_d:
        return np.array(line.get_data_3d(), float)
    x, y = line.get_data()
    return np.vstack([np.asarray(x, float), np.asarray(y, float), np.zeros(len(x))])


def _drawn(art):
    """What the artists show: link polyline (3, k) with NaN breaks, revolute markers, slider centres, tool."""
    three_d = art.three_d
    links = _line_points(art.links, three_d)
    rev = _line_points(art.revolute, three_d)
    tool = _line_points(art.tool, three_d)[:, 0]
    if art.sliders is None:
        sliders = np.zeros((3, 0))
    elif three_d:
        sliders = _line_points(art.sliders, True)
    else:
        c = [p.vertices[:4].mean(axis=0) for p in art.sliders.get_paths()]
        sliders = np.vstack([np.array(c).T, np.zeros(len(c))])
    return links, rev, sliders, tool


def _random_q(chain, rng):
    return np.array([rng.uniform(-np.pi, np.pi) if k == "R" else rng.uniform(-1.5, 1.5) for k in chain.joint_types])


def _check(art, chain, q, d):
    joints, sliders, T = _oracle(chain, q)
    links, rev, sl, tool = _drawn(art)
    tol = dict(atol=1e-9, rtol=0)
    R = [i for i, k in enumerate(chain.joint_types) if k == "R"]
    np.testing.assert_allclose(rev[:d], joints[:d, R], **tol, err_msg="revolute joints")
    np.testing.assert_allclose(sl[:d], sliders[:d], **tol, err_msg="sliders of prismatic joints")
    np.testing.assert_allclose(tool[:d], T[:d, 3], **tol, err_msg="tool origin")
    # the link line: base, then per joint its point (a prismatic joint: a break, then its slider), then the tool
    expected = [np.zeros(3)]
    k = 0
    for i, kind in enumerate(chain.joint_types):
        expected.append(joints[:, i])
        if kind == "P":
            expected += [np.full(3, np.nan), sliders[:, k]]
            k += 1
    expected.append(T[:3, 3])
    E = np.array(expected).T
    assert links.shape == E.shape
    np.testing.assert_allclose(links[:d], E[:d], **tol, err_msg="link line")
    # prismatic tracks: fixed to the link before the joint, through T_{i-1}(p_i), along the current axis v_i,
    # with the slider on the track
    if chain.joint_types.count("P"):
        segs = art.prismatic.get_segments() if not art.three_d else None
        for k, i in enumerate(i for i, kind in enumerate(chain.joint_types) if kind == "P"):
            T_before = mr.FKinSpace(np.eye(4), np.array(chain.screws, float)[:, :i], q[:i]) if i else np.eye(4)
            v = T_before[:3, :3] @ np.array(chain.screws[3:, i], float).reshape(3)
            assert np.allclose(sliders[:, k] - joints[:, i], q[i] * v, atol=1e-9)
            if segs is not None:
                a, b = segs[k]
                along = np.cross(np.r_[b - a, 0], np.r_[sliders[:2, k] - a, 0])[2]
                assert abs(along) < 1e-9 * max(1.0, np.linalg.norm(b - a))  # the slider lies on its track
    # the tool frame {b}: arrows along the columns of R(θ)
    if not art.three_d and art.frame_b is not None:
        qv = art.frame_b.artist
        np.testing.assert_allclose(qv.get_offsets()[0], T[:2, 3], **tol)
        U = np.column_stack([qv.U, qv.V])
        np.testing.assert_allclose(U / np.linalg.norm(U, axis=1, keepdims=True), T[:2, :2].T, atol=1e-9)


@pytest.mark.parametrize("chain", ROBOTS)
def test_drawn_joints_and_tool_are_the_forward_kinematics(chain):
    rng = np.random.default_rng(RNG_SEED)
    q0 = _random_q(chain, rng)
    art = draw_chain(chain, q0, labels=False)
    d = 2 if art.planar else 3
    try:
        _check(art, chain, q0, d)
        for _ in range(N_CONFIGS):  # a slider moves the same artists: update must keep them right
            q = _random_q(chain, rng)
            art.update(q)
            _check(art, chain, q, d)
    finally:
        plt.close(art.ax.figure)


@pytest.mark.parametrize("theta1", [-0.8, 0.0, 0.5, 1.3])
def test_cart_pole_is_a_cart_on_a_track_moving_with_theta1(theta1):
    """The cart (slider) sits at x = θ1 on the track y = 0, the pole pivots at (θ1, h) above it; no link runs
    from the base to the pivot (the old drawing's diagonal strut)."""
    L, h = 1.0, 0.5
    chain = robots.cart_pole(L=1, h=sp.Rational(1, 2))
    theta2 = np.pi / 3
    art = draw_chain(chain, [theta1, theta2])
    try:
        links, rev, sliders, tool = _drawn(art)
        np.testing.assert_allclose(sliders[:2, 0], [theta1, 0.0], atol=1e-12)
        np.testing.assert_allclose(rev[:2, 0], [theta1, h], atol=1e-12)
        np.testing.assert_allclose(tool[:2], [theta1 + L * np.cos(theta2), h + L * np.sin(theta2)], atol=1e-12)
        # every drawn link segment is either on the track (y = 0) or starts at the cart or the pivot
        pts = links[:2].T
        for a, b in zip(pts[:-1], pts[1:]):
            if np.isnan(a).any() or np.isnan(b).any() or np.allclose(a, b):
                continue
            on_track = abs(a[1]) < 1e-12 and abs(b[1]) < 1e-12
            from_cart = np.allclose(a, [theta1, 0.0]) or np.allclose(a, [theta1, h])
            assert on_track or from_cart, f"segment {a} → {b} is not part of the cart-pole"
        # the track is horizontal, through the base, and covers the cart
        (a, b) = art.prismatic.get_segments()[0]
        assert abs(a[1]) < 1e-12 and abs(b[1]) < 1e-12 and min(a[0], b[0]) < theta1 < max(a[0], b[0])
    finally:
        plt.close(art.ax.figure)
