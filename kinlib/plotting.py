"""Pictures of serial chains and their Jacobians (matplotlib; imported on demand, never by ``import kinlib``).

Every drawing is computed from the chain's numeric kinematics at a configuration q:

* the links through ``chain.skeleton(q)`` (base origin, each joint point, tool origin),
* the tool frame {b} from ``chain.fk(q)`` = T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M,
* the current joint axes from the columns of the space Jacobian J_s(θ) (revolute: ω_i; prismatic: v_i),
* velocities from the **geometric Jacobian** J(θ) = blockdiag(R, R) J_b, rows [ω_s; ṗ]
  (ṗ = velocity of the tool origin in {s}).

Chains with symbolic link lengths cannot be drawn: give numbers first with ``chain.subs(L=1)``, or pass
``params={"L": 1}`` to any function here (the substituted chain is cached per chain and values).

Planar chains (every revolute axis along z_s, every prismatic axis in the xy-plane) are drawn in 2-D,
the others in 3-D.  Each ``draw_*`` function returns an artist object whose ``update(q, ...)`` moves the
existing matplotlib artists (no re-creation), so a slider can redraw quickly.

Functions (each returns an object to update or inspect):

* ``draw_chain(chain, q, ax=None, *, planar=None, frames=True, axes=True, labels=True, params=None,
  ranges=None, limits=None, view=None, ...)`` → :class:`ChainArtist` (``.update(q)``, ``.tool_position``,
  ``.artists``). The view has equal scales on every axis and fits the pose (``view="pose"``, default) or
  every pose in the joint ranges (``view="workspace"``, default when ``ranges`` is given, for sliders);
  arrows drawn later by the functions below enlarge an automatic view. The labels θ1…θn, {s}, {b} are
  placed where they overlap neither each other nor the drawing (3-D: at the ends of the joint axes);
  ``draw_home(chain, ...)``: θ = 0 with each joint's screw axis listed beside the picture (symbols kept);
* ``draw_velocity(ax, chain, q, qdot, *, rows=None, scale=1)`` → :class:`VelocityArtist` (``.velocity`` = ṗ);
  ``draw_joint_velocities(ax, chain, q, *, rows=None, joints=None, scale=1)`` → :class:`JointVelocitiesArtist`;
* ``draw_velocity_ellipse(ax, chain, q, *, rows=None, scale=1)`` → :class:`EllipseArtist` (``.semi_axes``);
  ``draw_ellipse(ax, center, lengths, axes)`` for a given (σ, U);
* ``draw_directions(ax, origin, vectors, labels, *, components=None, length=None, both_ways=False)``;
* ``plot_joint_contributions(ax, values, *, title=None)`` (bar chart of one row of J);
* ``plot_manipulability_curve(chain, joint, q_fixed=None, *, rows=None, measure="yoshikawa")`` → :class:`CurvePlot`;
  ``plot_manipulability_map(chain, joints=(1, 2), q_fixed=None, *, rows=None, singular=True)`` → :class:`MapPlot`;
* ``sweep(chain, joint, values, q_fixed=None)`` and ``animate_singularity(chain, path)`` → FuncAnimation
  (``.to_jshtml()`` plays in a static page).

Joints are numbered as in the book, 1…n (``joint=2`` is θ2).  Task rows are named
``'wx','wy','wz','vx','vy','vz'`` (indices 0…5 of [ω_s; ṗ]); presets ``"planar"`` = (ω_z, ṗ_x, ṗ_y),
``"linear"`` = (ṗ_x, ṗ_y, ṗ_z), ``"angular"``, ``"all"``.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np
import sympy as sp
import matplotlib
import matplotlib.pyplot as plt
from matplotlib import animation as _animation
from matplotlib.collections import LineCollection

from ._backend import describe
from .chains import SerialChain

__all__ = [
    "is_planar", "numeric_chain", "task_row_indices", "default_ranges", "manipulability_values",
    "draw_chain", "draw_home", "ChainArtist",
    "draw_velocity", "VelocityArtist", "draw_joint_velocities", "JointVelocitiesArtist",
    "draw_velocity_ellipse", "EllipseArtist", "draw_ellipse", "draw_directions", "plot_joint_contributions",
    "plot_manipulability_curve", "plot_manipulability_map", "sweep", "animate_singularity",
    "new_axes", "pi_ticks",
]

ROW_NAMES = ("wx", "wy", "wz", "vx", "vy", "vz")
ROW_LABELS = ("ω_x", "ω_y", "ω_z", "ṗ_x", "ṗ_y", "ṗ_z")
ROW_TEX = (r"$\omega_x$", r"$\omega_y$", r"$\omega_z$", r"$\dot p_x$", r"$\dot p_y$", r"$\dot p_z$")
_ROW_ALIASES = {"px": "vx", "py": "vy", "pz": "vz"}
_PRESETS = {"planar": ("wz", "vx", "vy"), "linear": ("vx", "vy", "vz"), "position": ("vx", "vy", "vz"),
            "angular": ("wx", "wy", "wz"), "all": ROW_NAMES, "xy": ("vx", "vy")}
JOINT_COLORS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink",
                "tab:olive", "tab:cyan", "tab:gray")
FRAME_COLORS = ("tab:red", "tab:green", "tab:blue")


# ---------------------------------------------------------------------------------------------------
# input checks and small helpers
# ---------------------------------------------------------------------------------------------------
def _check_chain(chain, name="chain") -> SerialChain:
    if not isinstance(chain, SerialChain):
        raise TypeError(f"{name} must be a kinlib SerialChain (e.g. kinlib.robots.planar_offset_3r(1)), "
                        f"got {describe(chain)}")
    return chain


_SUBS_CACHE: dict = {}


def numeric_chain(chain, params: Mapping | None = None) -> SerialChain:
    """The chain with numbers for its link lengths: ``chain`` itself when it has none left, else
    ``chain.subs(params)`` (cached); a ValueError when symbolic parameters remain."""
    chain = _check_chain(chain)
    if params:
        if not isinstance(params, Mapping):
            raise TypeError(f"params must be a dict of parameter values like {{'L': 1}}, got {describe(params)}")
        key = (id(chain), tuple(sorted((str(k), str(v)) for k, v in params.items())))
        hit = _SUBS_CACHE.get(key)
        if hit is not None and hit[0] is chain:
            chain = hit[1]
        else:
            names = {str(p): p for p in chain.params}
            table = {}
            for k, v in params.items():
                if str(k) not in names:
                    raise ValueError(f"params: {chain.name} has no parameter {str(k)!r}; its parameters are "
                                     f"{sorted(names) or 'none'}")
                if isinstance(v, sp.Basic) and v.free_symbols:
                    raise ValueError(f"params[{str(k)!r}] must be a number, got {describe(v)}")
                table[names[str(k)]] = v
            sub = chain.subs(table)
            _SUBS_CACHE[key] = (chain, sub)
            chain = sub
    if chain.params:
        p = ", ".join(map(str, chain.params))
        raise ValueError(
            f"cannot draw {chain.name}: it has symbolic parameters {p}; give them numbers first, e.g. "
            f"chain.subs({chain.params[0]}=1), or pass params={{'{chain.params[0]}': 1}}")
    return chain


def _as_q(chain: SerialChain, q, name: str = "q") -> np.ndarray:
    """One numeric configuration of ``chain`` as a float array of shape (n,)."""
    if q is None:
        return np.zeros(chain.n)
    if isinstance(q, (str, bytes)):
        raise TypeError(f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)}")
    if isinstance(q, sp.MatrixBase):
        q = list(q)
    if isinstance(q, (numbers.Number, sp.Basic)) and chain.n == 1:
        q = [q]
    try:
        arr = np.asarray(q, dtype=object).reshape(-1) if not isinstance(q, np.ndarray) else q.reshape(-1)
    except Exception:
        raise TypeError(f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)}") from None
    if np.ndim(q) > 1 and not (isinstance(q, np.ndarray) and q.ndim == 2 and 1 in q.shape):
        raise ValueError(f"{name} must hold {chain.n} joint values for {chain.name} (one configuration), "
                         f"got {describe(q)}")
    if arr.size != chain.n:
        raise ValueError(f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)} "
                         f"with {arr.size} entries")
    out = np.empty(chain.n)
    for i, v in enumerate(arr):
        if isinstance(v, (bool, str, bytes)):
            raise TypeError(f"{name}[{i}] must be a real number, got {describe(v)}")
        try:
            out[i] = float(v)
        except (TypeError, ValueError):
            raise TypeError(f"{name}[{i}] must be a real number (a numeric configuration), got {describe(v)}") from None
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name} must hold finite numbers, got {out}")
    return out


def is_planar(chain) -> bool:
    """True when every revolute axis is along ±z_s and every prismatic axis lies in the xy-plane
    (rows ω_x, ω_y and v_z of every screw axis are zero): the chain moves in the xy-plane."""
    S = _check_chain(chain).screws
    return all(S[r, i] == 0 for r in (0, 1, 5) for i in range(S.shape[1]))


def task_row_indices(rows, default=None) -> tuple[int, ...]:
    """Row indices of [ω_s; ṗ] from names ('wx','wy','wz','vx','vy','vz', also 'px','py','pz'),
    indices 0…5, or a preset ('planar', 'linear', 'angular', 'all', 'xy')."""
    if rows is None:
        rows = default if default is not None else "all"
    if isinstance(rows, str):
        key = rows.lower()
        if key in _PRESETS:
            rows = _PRESETS[key]
        else:
            rows = (rows,)
    elif isinstance(rows, numbers.Integral):
        rows = (rows,)
    out = []
    try:
        items = list(rows)
    except TypeError:
        raise TypeError(f"rows must be row names like ('vx', 'vy'), indices 0-5 or a preset "
                        f"{sorted(_PRESETS)}, got {describe(rows)}") from None
    for r in items:
        if isinstance(r, str):
            k = _ROW_ALIASES.get(r.lower(), r.lower())
            if k not in ROW_NAMES:
                raise ValueError(f"rows: unknown row {r!r}; use names {ROW_NAMES}, indices 0-5 or a preset "
                                 f"{sorted(_PRESETS)}")
            out.append(ROW_NAMES.index(k))
        elif isinstance(r, numbers.Integral) and not isinstance(r, bool) and 0 <= int(r) < 6:
            out.append(int(r))
        else:
            raise ValueError(f"rows: {r!r} is not a row name {ROW_NAMES} or an index 0-5")
    if not out:
        raise ValueError("rows must name at least one row of [ω_s; ṗ]")
    if len(set(out)) != len(out):
        raise ValueError(f"rows must not repeat a row, got {describe(rows)}")
    return tuple(out)


def _default_task_rows(chain) -> tuple[int, ...]:
    """(ω_z, ṗ_x, ṗ_y) for a planar chain, all six rows otherwise."""
    return task_row_indices("planar" if is_planar(chain) else "all")


def _rows_label(rows, tex=False) -> str:
    return ", ".join((ROW_TEX if tex else ROW_LABELS)[r] for r in rows)


def _theta_tex(i: int, dot: bool = False) -> str:
    r"""$\theta_i$ or $\dot\theta_i$ (i is 1-based) for figure text."""
    return f"$\\dot{{\\theta}}_{{{i}}}$" if dot else f"$\\theta_{{{i}}}$"


def _joint_index(chain, joint, name="joint") -> int:
    """0-based index from a 1-based joint number, a joint symbol or its name ('theta2')."""
    if isinstance(joint, sp.Symbol):
        if joint in chain.thetas:
            return chain.thetas.index(joint)
        raise ValueError(f"{name}: {joint} is not a joint of {chain.name} (joints {chain.thetas})")
    if isinstance(joint, str):
        for i, t in enumerate(chain.thetas):
            if str(t) == joint:
                return i
        raise ValueError(f"{name}: {joint!r} is not a joint of {chain.name} (joints {tuple(map(str, chain.thetas))})")
    if isinstance(joint, numbers.Integral) and not isinstance(joint, bool):
        if 1 <= joint <= chain.n:
            return int(joint) - 1
        raise ValueError(f"{name} must be a joint number 1..{chain.n} (as in θ1..θ{chain.n}) for {chain.name}, got {joint}")
    raise TypeError(f"{name} must be a joint number 1..{chain.n}, a joint symbol or its name, got {describe(joint)}")


def _reach(chain) -> float:
    """Sum of the link lengths at home (distance between consecutive skeleton points)."""
    sk = chain.skeleton(np.zeros(chain.n))
    d = float(np.sum(np.linalg.norm(np.diff(sk, axis=1), axis=0)))
    return d if d > 1e-9 else 1.0


def default_ranges(chain, ranges=None, params=None) -> list[tuple[float, float]]:
    """Joint ranges: revolute (−π, π), prismatic ±(half the home reach); ``ranges`` overrides per joint
    (a list of (lo, hi) or a dict {joint number/symbol/name: (lo, hi)})."""
    chain = numeric_chain(chain, params)
    half = 0.5 * _reach(chain)
    out = [(-math.pi, math.pi) if k == "R" else (-half, half) for k in chain.joint_types]
    if ranges is None:
        return out
    items = ranges.items() if isinstance(ranges, Mapping) else enumerate(ranges, start=1)
    if not isinstance(ranges, Mapping) and len(list(ranges)) != chain.n:
        raise ValueError(f"ranges must give {chain.n} (lo, hi) pairs or a dict by joint, got {describe(ranges)}")
    for j, r in items:
        i = _joint_index(chain, j, "ranges key")
        try:
            lo, hi = (float(v) for v in r)
        except Exception:
            raise TypeError(f"ranges[{j!r}] must be a pair (lo, hi) of numbers, got {describe(r)}") from None
        if not hi > lo:
            raise ValueError(f"ranges[{j!r}] must have lo < hi, got {(lo, hi)}")
        out[i] = (lo, hi)
    return out


def _is3d(ax) -> bool:
    return hasattr(ax, "get_zlim")


def new_axes(planar: bool, ax=None, figsize=None):
    """``ax`` itself, or a new pyplot figure with 2-D (equal aspect) or 3-D axes."""
    if ax is not None:
        return ax
    if planar:
        fig, ax = plt.subplots(figsize=figsize or (5.5, 5))
    else:
        fig = plt.figure(figsize=figsize or (6, 5.5))
        ax = fig.add_subplot(projection="3d")
    return ax


def _manipulability_private(J: np.ndarray) -> np.ndarray:
    """Yoshikawa's √det(J Jᵀ) (√det(Jᵀ J) when fewer joints than rows) for a batch (..., m, n):
    the product of the min(m, n) singular values."""
    return np.prod(np.linalg.svd(J, compute_uv=False), axis=-1)


def _manipulability(J: np.ndarray) -> np.ndarray:
    try:  # the shared implementation, when present
        from .manipulability import manipulability as shared
    except Exception:  # pragma: no cover - module not written yet
        return _manipulability_private(J)
    try:
        return np.asarray(shared(J), dtype=float)
    except Exception:  # pragma: no cover - fall back on any incompatibility
        return _manipulability_private(J)


_MEASURES = ("yoshikawa", "det", "inverse_condition", "min_singular_value")


def manipulability_values(J: np.ndarray, measure: str | Callable = "yoshikawa") -> np.ndarray:
    """A manipulability measure of task Jacobians J (m×n or a batch (N, m, n)):

    * ``'yoshikawa'``: √det(J Jᵀ) (√det(Jᵀ J) when n < m);
    * ``'det'``: det J (square J only; signed, so its zero contour is the singular set);
    * ``'inverse_condition'``: σ_min/σ_max (1 = isotropic, 0 = singular);
    * ``'min_singular_value'``: σ_min;
    * a callable taking the batch (N, m, n) and returning N values.
    """
    J = np.asarray(J, dtype=float)
    if callable(measure):
        return np.asarray(measure(J), dtype=float)
    if measure == "yoshikawa":
        return _manipulability(J)
    if measure == "det":
        if J.shape[-1] != J.shape[-2]:
            raise ValueError(f"measure='det' needs a square task Jacobian, got rows×joints = {J.shape[-2:]}; "
                             f"use measure='yoshikawa' or choose as many rows as joints")
        return np.linalg.det(J)
    if measure in ("inverse_condition", "min_singular_value"):
        s = np.linalg.svd(J, compute_uv=False)
        if measure == "min_singular_value":
            return s[..., -1]
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(s[..., 0] > 0, s[..., -1] / s[..., 0], 0.0)
    raise ValueError(f"measure must be one of {_MEASURES} or a callable, got {measure!r}")


_MEASURE_LABEL = {"yoshikawa": "√det(J Jᵀ)", "det": "det J", "inverse_condition": "σ_min / σ_max",
                  "min_singular_value": "σ_min"}


def _measure_label(measure, m, n) -> str:
    if measure == "yoshikawa" and n < m:
        return "√det(Jᵀ J)"
    return _MEASURE_LABEL.get(measure, getattr(measure, "__name__", "measure"))


def pi_ticks(axis, lo: float, hi: float, step_fraction: int = 2):
    """Ticks at multiples of π/step_fraction on a matplotlib Axis (``ax.xaxis``), labelled −π, −π/2, 0, …"""
    step = math.pi / step_fraction
    k0, k1 = math.ceil(lo / step - 1e-9), math.floor(hi / step + 1e-9)
    ticks, labels = [], []
    for k in range(k0, k1 + 1):
        fr = sp.Rational(k, step_fraction)
        if fr == 0:
            s = "0"
        else:
            num, den = abs(fr.p), fr.q
            s = ("−" if fr < 0 else "") + ("" if num == 1 else str(num)) + "π" + ("" if den == 1 else f"/{den}")
        ticks.append(k * step)
        labels.append(s)
    axis.set_ticks(ticks)
    axis.set_ticklabels(labels)


# ---------------------------------------------------------------------------------------------------
# arrows that can be moved (2-D: quiver; 3-D: line segments with a two-stroke head)
# ---------------------------------------------------------------------------------------------------
def _perp(v: np.ndarray) -> np.ndarray:
    a = np.array([0.0, 0.0, 1.0]) if abs(v[2]) < 0.9 * np.linalg.norm(v) else np.array([1.0, 0.0, 0.0])
    p = a - v * (a @ v) / (v @ v)
    return p / np.linalg.norm(p)


class _Arrows:
    """k arrows from origins (k, d) along vectors (k, d), d = 2 (2-D axes) or 3 (3-D axes)."""

    def __init__(self, ax, origins, vectors, colors, *, width=None, head=0.25, zorder=4, label=None,
                 linestyle="-", alpha=1.0, lw=2.0):
        self.ax = ax
        self.three_d = _is3d(ax)
        self.head = head
        o, v = np.atleast_2d(np.asarray(origins, float)), np.atleast_2d(np.asarray(vectors, float))
        self.k = v.shape[0]
        colors = list(colors) if not isinstance(colors, str) else [colors] * self.k
        self.colors = colors
        if self.three_d:
            from mpl_toolkits.mplot3d.art3d import Line3DCollection
            segs, cols = self._segments(o, v)
            self.artist = Line3DCollection(segs, colors=cols, linewidths=lw, zorder=zorder, label=label,
                                           linestyles=linestyle, alpha=alpha)
            ax.add_collection3d(self.artist)
        else:
            kw = dict(angles="xy", scale_units="xy", scale=1, color=colors, zorder=zorder, label=label,
                      alpha=alpha, width=width or 0.012, headwidth=3.5, headlength=4.5, headaxislength=4)
            self.artist = ax.quiver(o[:, 0], o[:, 1], v[:, 0], v[:, 1], **kw)

    def _segments(self, o, v):
        segs, cols = [], []
        for i in range(v.shape[0]):
            a, d = o[i], v[i]
            L = float(np.linalg.norm(d))
            c = self.colors[i % len(self.colors)]
            segs.append([a, a + d])
            cols.append(c)
            if L > 1e-12:
                u = d / L
                p = _perp(d)
                h = self.head * L
                tip = a + d
                for sgn in (1, -1):
                    segs.append([tip, tip - h * u + sgn * 0.5 * h * p])
                    cols.append(c)
            else:
                segs += [[a, a], [a, a]]
                cols += [c, c]
        return segs, cols

    def set(self, origins, vectors):
        o, v = np.atleast_2d(np.asarray(origins, float)), np.atleast_2d(np.asarray(vectors, float))
        if self.three_d:
            segs, _ = self._segments(o, v)
            self.artist.set_segments(segs)
        else:
            self.artist.set_offsets(o[:, :2])
            self.artist.set_UVC(v[:, 0], v[:, 1])

    def remove(self):
        self.artist.remove()


def _text(ax, p, s, **kw):
    if _is3d(ax):
        return ax.text(p[0], p[1], p[2], s, **kw)
    return ax.text(p[0], p[1], s, **kw)


def _move_text(t, p):
    if hasattr(t, "set_position_3d"):
        t.set_position_3d((p[0], p[1], p[2]))
    else:
        t.set_position((p[0], p[1]))


def _line(ax, pts, **kw):
    """A Line2D/Line3D through the columns of pts (3×k)."""
    if _is3d(ax):
        return ax.plot(pts[0], pts[1], pts[2], **kw)[0]
    return ax.plot(pts[0], pts[1], **kw)[0]


def _set_line(line, pts):
    if hasattr(line, "set_data_3d"):
        line.set_data_3d(pts[0], pts[1], pts[2])
    else:
        line.set_data(pts[0], pts[1])


def _segs_collection(ax, segs, **kw):
    if _is3d(ax):
        from mpl_toolkits.mplot3d.art3d import Line3DCollection
        c = Line3DCollection(segs, **kw)
        ax.add_collection3d(c)
        return c
    c = LineCollection([np.asarray(s)[:, :2] for s in segs], **kw)
    ax.add_collection(c)
    return c


def _set_segs(c, segs, three_d):
    c.set_segments(segs if three_d else [np.asarray(s)[:, :2] for s in segs])


# ---------------------------------------------------------------------------------------------------
# the chain
# ---------------------------------------------------------------------------------------------------
def _workspace_points(chain, ranges, q=None, samples=400):
    """The skeleton points (3, N·(n+2)) of a deterministic sample of the joint ranges (and home, q)."""
    rng = np.random.default_rng(0)
    lo = np.array([r[0] for r in ranges])
    hi = np.array([r[1] for r in ranges])
    Q = lo + (hi - lo) * rng.random((samples, chain.n))
    extra = [np.zeros(chain.n)] + ([q] if q is not None else [])
    Q = np.vstack([Q, np.array(extra)])
    return np.moveaxis(chain.skeleton(Q), 1, 0).reshape(3, -1)


# --- the view: equal aspect, tight around what is drawn ---------------------------------------------
def _fit_view(ax, pts, margin=0.08, min_frac=0.4):
    """Limits around the points pts (3, k) with equal scaling on every axis: a box of the points' own
    proportions (each side at least ``min_frac`` of the longest, so a flat arm still gets some depth),
    padded by ``margin`` × the longest side. 3-D: ``set_box_aspect`` to the box's sides."""
    pts = np.asarray(pts, float)
    d = 3 if _is3d(ax) else 2
    P = pts[:d]
    lo, hi = P.min(axis=1), P.max(axis=1)
    ext = hi - lo
    m = max(float(ext.max()), 1e-6)
    ext = np.maximum(ext, min_frac * m)
    c = 0.5 * (lo + hi)
    half = 0.5 * ext + margin * m
    ax.set_xlim(c[0] - half[0], c[0] + half[0])
    ax.set_ylim(c[1] - half[1], c[1] + half[1])
    if d == 3:
        ax.set_zlim(c[2] - half[2], c[2] + half[2])
        ax.set_box_aspect(tuple(2 * half), zoom=0.95)
    else:
        ax.set_aspect("equal", adjustable="box")


def _include(ax, pts):
    """Grow an automatic kinlib view (one set by draw_chain without ``limits``) so that the points
    (3, k) or (2, k), e.g. a velocity arrow's tip, are inside it; labels are placed again around them."""
    view = getattr(ax, "_kinlib_view", None)
    if view is None:
        return
    pts = np.asarray(pts, float)
    if pts.shape[0] == 2:
        pts = np.vstack([pts, np.zeros(pts.shape[1])])
    pts = pts[:, np.all(np.isfinite(pts), axis=0)]
    view["obstacles"] = np.hstack([view["obstacles"], pts])
    if view["fit"]:
        view["points"] = np.hstack([view["points"], pts])
        _fit_view(ax, view["points"], view["margin"])
    art = view.get("chain")
    if art is not None:
        art.place_labels()


_DIRS3 = np.array([[0, -1, 1], [0, 1, 1], [1, 0, 1], [-1, 0, 1], [0, -1, -1], [0, 1, -1], [1, 0, -1],
                   [-1, 0, -1], [1, 1, 0], [-1, -1, 0], [1, -1, 0], [-1, 1, 0], [0, 0, 1], [0, 0, -1]], float)
_DIRS3 /= np.linalg.norm(_DIRS3, axis=1)[:, None]
_DIRS2 = np.array([[-1, 1, 0], [1, 1, 0], [-1, -1, 0], [1, -1, 0], [0, 1, 0], [0, -1, 0], [-1, 0, 0],
                   [1, 0, 0]], float)
_DIRS2 /= np.linalg.norm(_DIRS2, axis=1)[:, None]


def _to_pixels(ax, P):
    """Display coordinates (k, 2) of the points P (3, k) in ax (through the 3-D projection if any)."""
    if _is3d(ax):
        from mpl_toolkits.mplot3d import proj3d
        x, y, _ = proj3d.proj_transform(P[0], P[1], P[2], ax.get_proj())
        return ax.transData.transform(np.column_stack([x, y]))
    return ax.transData.transform(P[:2].T)


def _pick(Cp, O, placed, need_lab, need_obs) -> int:
    """Index of the first candidate (pixels, (m, 2)) at least need_lab from the labels already placed and
    need_obs from the obstacles O (pixels, (k, 2)); else the candidate with the most room."""
    d_obs = (np.min(np.linalg.norm(Cp[:, None, :] - O[None, :, :], axis=2), axis=1) if len(O)
             else np.full(len(Cp), np.inf))
    d_lab = (np.min(np.linalg.norm(Cp[:, None, :] - placed[None, :, :], axis=2), axis=1)
             if len(placed) else np.full(len(Cp), np.inf))
    ok = np.flatnonzero((d_lab >= need_lab) & (d_obs >= need_obs))
    return int(ok[0]) if ok.size else int(np.argmax(np.minimum(d_lab, 2.0 * d_obs)))


def _data_per_pixel(ax) -> float:
    """Data length per pixel on screen (3-D: along the least foreshortened of the box's edges)."""
    if not _is3d(ax):
        return float(np.diff(ax.get_xlim())[0]) / max(ax.bbox.width, 1.0)
    lims = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    c = lims[:, :1]
    ends = np.repeat(c, 6, axis=1)
    for k in range(3):
        ends[k, 2 * k], ends[k, 2 * k + 1] = lims[k]
    px = _to_pixels(ax, ends)
    pix = np.linalg.norm(px[0::2] - px[1::2], axis=1)
    return float(np.min((lims[:, 1] - lims[:, 0]) / np.maximum(pix, 1e-9)))


def _segment_samples(pts, k=16):
    """Points along the polyline through the columns of pts (3, m), k per segment."""
    if pts.shape[1] < 2:
        return pts
    t = np.linspace(0.0, 1.0, k)[None, :, None]
    a, b = pts[:, :-1].T[:, None, :], pts[:, 1:].T[:, None, :]
    return (a + t * (b - a)).reshape(-1, 3).T


class ChainArtist:
    """The matplotlib artists of one drawn chain; ``update(q)`` moves them to a new configuration.

    Attributes: ``ax``, ``chain`` (numeric), ``q``, ``planar``, ``scale`` (a length for frame arrows),
    ``links`` (Line through the skeleton), ``revolute``/``prismatic`` (joint markers), ``axes_lines``,
    ``frame_s``/``frame_b`` (arrow sets), ``labels`` (Text θi per joint, placed where they overlap
    neither each other nor the links: at the end of the joint's axis in 3-D, beside the joint in 2-D),
    ``annotations`` (extra Text, e.g. the screw axes of :func:`draw_home`), ``tool`` (tool-origin marker).
    """

    AXIS_HALF = 0.35    # half-length of a drawn joint axis, × scale
    FRAME = 0.22        # length of a frame arrow, × scale

    def __init__(self, ax, chain, q, *, planar, frames=True, axes=True, labels=True, color="0.25",
                 scale=None, lw=4.0, fontsize=9):
        self.ax, self.chain, self.planar = ax, chain, planar
        self.three_d = _is3d(ax)
        self.q = q
        self.scale = scale
        self.fontsize = fontsize
        self.kinds = chain.joint_types
        self.rev = [i for i, k in enumerate(self.kinds) if k == "R"]
        self.pri = [i for i, k in enumerate(self.kinds) if k == "P"]
        sk, T, Js = self._kin(q)
        self._geom = (sk, T, Js)
        self.links = _line(ax, sk, color=color, lw=lw, solid_capstyle="round", zorder=2,
                           marker="", label="links")
        self.base = _line(ax, sk[:, :1], color="k", marker="s", ms=9, ls="", zorder=3)
        self.tool = _line(ax, sk[:, -1:], color="k", marker="o", ms=4, ls="", zorder=5)
        rp = sk[:, [i + 1 for i in self.rev]]
        self.revolute = _line(ax, rp, ls="", marker="o", ms=12 if not self.three_d else 10, mfc="white", mec="k",
                              mew=1.8, zorder=4, label="revolute joint")
        self.revolute_dot = (_line(ax, rp, ls="", marker=".", ms=5, color="k", zorder=5)
                             if not self.three_d else None)
        self.prismatic = _segs_collection(ax, self._rails(sk, Js), colors="tab:gray", linewidths=9,
                                          alpha=0.6, zorder=3, capstyle="butt", label="prismatic joint") \
            if self.pri else None
        self.axes_lines = None
        if axes and (self.three_d or self.pri):
            self.axes_lines = _segs_collection(ax, self._axis_segments(sk, Js), colors="0.45", linewidths=1.0,
                                               linestyles="--", zorder=1, label="joint axes")
        self.frame_s = self.frame_b = None
        self.frame_texts = []
        if frames:
            d = 3 if self.three_d else 2
            L = self.FRAME * scale
            E = np.eye(3)[:d, :d] * L
            cols = FRAME_COLORS[:d]
            # thinner and lighter than the velocity arrows drawn on top, so the two are not confused
            thin = dict(head=0.3, width=0.006, lw=1.6, alpha=0.75)
            self.frame_s = _Arrows(ax, np.zeros((d, d)), E, cols, zorder=3, **thin)
            self.frame_b = _Arrows(ax, np.tile(T[:d, 3], (d, 1)), (T[:d, :d] * L).T, cols, zorder=3, **thin)
            self.frame_texts = [_text(ax, np.zeros(3), r"$\{s\}$", fontsize=fontsize - 1, ha="center", va="center",
                                      zorder=7),
                                _text(ax, T[:3, 3], r"$\{b\}$", fontsize=fontsize - 1, ha="center", va="center",
                                      zorder=7)]
        self.labels = []
        if labels:
            for i in range(chain.n):
                self.labels.append(_text(ax, sk[:, i + 1], _theta_tex(i + 1), fontsize=fontsize,
                                         color=JOINT_COLORS[i % 10], ha="center", va="center", zorder=7))
        self.annotations = []
        self.place_labels()

    # -- geometry -----------------------------------------------------------------------------------
    def _kin(self, q):
        c = self.chain
        return c.skeleton(q), c.fk(q), c.jacobian_space(q)

    def _axis_dirs(self, Js):
        """Unit joint axes (3, n): ω_i for revolute, v_i for prismatic joints (columns of J_s)."""
        A = np.where(np.array([k == "R" for k in self.kinds])[None, :], Js[:3], Js[3:])
        return A / np.maximum(np.linalg.norm(A, axis=0), 1e-12)

    def _rails(self, sk, Js):
        h = 0.12 * self.scale
        segs = []
        for i in self.pri:
            v = Js[3:, i]
            v = v / (np.linalg.norm(v) or 1.0)
            p = sk[:, i + 1]
            segs.append([p - h * v, p + h * v])
        return segs

    def _axis_segments(self, sk, Js):
        h = self.AXIS_HALF * self.scale
        segs = []
        for i, k in enumerate(self.kinds):
            if k == "R" and not self.three_d:
                continue  # out of the page: drawn as ⊙
            a = Js[:3, i] if k == "R" else Js[3:, i]
            a = a / (np.linalg.norm(a) or 1.0)
            p = sk[:, i + 1]
            segs.append([p - h * a, p + h * a])
        return segs

    def extent_points(self) -> np.ndarray:
        """Every point the drawing reaches (3, k): skeleton, frame-arrow tips, ends of the joint axes."""
        sk, T, Js = self._geom
        pts = [sk]
        L = self.FRAME * self.scale
        if self.frame_s is not None:
            pts += [np.eye(3) * L, T[:3, 3:4] + T[:3, :3] * L]
        h = (self.AXIS_HALF + 0.12) * self.scale
        A = self._axis_dirs(Js)
        if self.three_d or self.pri:
            for i, k in enumerate(self.kinds):
                if k == "P" or self.three_d:
                    pts.append(sk[:, [i + 1, i + 1]] + np.outer(A[:, i], [h, -h]))
        if not self.three_d:  # room for the labels beside the joints
            r = 0.2 * self.scale
            pts.append(np.hstack([sk[:, 1:-1] + np.array([[r], [r], [0]]), sk[:, 1:-1] - np.array([[r], [r], [0]])]))
        return np.hstack(pts)

    # -- labels ---------------------------------------------------------------------------------------
    def place_labels(self):
        """Put θ1…θn, {s} and {b} where they overlap neither each other nor the links (in screen space).

        Candidates per joint, in order of preference: the two ends of its drawn axis (3-D, prismatic), then
        directions around the joint; the first candidate far enough from the labels already placed and
        from the drawing wins (else the one with the most room). Moves the Text artists only."""
        if not self.labels and not self.frame_texts:
            return
        sk, T, Js = self._geom
        ax = self.ax
        A = self._axis_dirs(Js)
        h = (self.AXIS_HALF + 0.08) * self.scale
        px = self.fontsize * ax.figure.dpi / 72.0               # the font size in pixels
        per_px = _data_per_pixel(ax)
        r = min(2.2 * px * per_px, 0.3 * self.scale)             # beside a joint: about two font sizes
        dirs = _DIRS3 if self.three_d else _DIRS2
        items = []  # (text, candidate points (3, m))
        for i, t in enumerate(self.labels):
            p = sk[:, i + 1:i + 2]
            cands = []
            if self.three_d or self.kinds[i] == "P":
                a = A[:, i:i + 1]
                cands += [p + h * a, p - h * a, p + 1.45 * h * a, p - 1.45 * h * a]
            cands += [p + r * dirs.T, p + 1.6 * r * dirs.T]
            items.append((t, np.hstack(cands)))
        if self.frame_texts:
            fd = np.vstack([-dirs[0], -dirs[1:]]) if not self.three_d else dirs[::-1]
            ring = np.hstack([0.8 * r * fd.T, 1.3 * r * fd.T, 1.9 * r * fd.T])
            items.append((self.frame_texts[0], ring))
            items.append((self.frame_texts[1], T[:3, 3:4] + ring))
        L = self.FRAME * self.scale
        obstacles = [_segment_samples(sk)]
        if self.frame_s is not None:
            t = np.linspace(0.3, 1.0, 5)
            for o, R in ((np.zeros((3, 1)), np.eye(3)), (T[:3, 3:4], T[:3, :3])):
                for k in range(3 if self.three_d else 2):
                    obstacles.append(o + L * np.outer(R[:, k], t))
        for a, b in (self._rails(sk, Js) + (self._axis_segments(sk, Js) if self.axes_lines is not None else [])):
            obstacles.append(_segment_samples(np.column_stack([a, b]), 9))
        view = getattr(ax, "_kinlib_view", None)
        if view is not None and view.get("chain") is self:
            obstacles.append(view["obstacles"])
        O = _to_pixels(ax, np.hstack(obstacles))
        px = self.fontsize * ax.figure.dpi / 72.0
        need_lab, need_obs = 2.0 * px, 1.4 * px
        placed = np.zeros((0, 2))
        for t, C in items:
            Cp = _to_pixels(ax, C)
            k = _pick(Cp, O, placed, need_lab, need_obs)
            _move_text(t, C[:, k])
            placed = np.vstack([placed, Cp[k]])

    # -- update ---------------------------------------------------------------------------------------
    def update(self, q):
        """Move every artist to configuration q (no artist is re-created)."""
        q = _as_q(self.chain, q)
        self.q = q
        sk, T, Js = self._kin(q)
        self._geom = (sk, T, Js)
        _set_line(self.links, sk)
        _set_line(self.tool, sk[:, -1:])
        rp = sk[:, [i + 1 for i in self.rev]]
        _set_line(self.revolute, rp)
        if self.revolute_dot is not None:
            _set_line(self.revolute_dot, rp)
        if self.prismatic is not None:
            _set_segs(self.prismatic, self._rails(sk, Js), self.three_d)
        if self.axes_lines is not None:
            _set_segs(self.axes_lines, self._axis_segments(sk, Js), self.three_d)
        if self.frame_b is not None:
            d = 3 if self.three_d else 2
            L = self.FRAME * self.scale
            self.frame_b.set(np.tile(T[:d, 3], (d, 1)), (T[:d, :d] * L).T)
        self.place_labels()
        return self

    @property
    def artists(self) -> list:
        """The artists that ``update`` moves (for blitting); {s} and the base stay put."""
        out = [self.links, self.revolute, self.tool]
        out += [a for a in (self.revolute_dot, self.prismatic, self.axes_lines) if a is not None]
        if self.frame_b is not None:
            out += [self.frame_b.artist, *self.frame_texts]
        return out + list(self.labels)

    @property
    def tool_position(self) -> np.ndarray:
        """The drawn tool origin p (3,)."""
        return self.chain.fk(self.q)[:3, 3]


def draw_chain(chain, q=None, ax=None, *, planar=None, frames=True, axes=True, labels=True, params=None,
               ranges=None, limits=None, view=None, color="0.25", title=None, figsize=None,
               fontsize=9) -> ChainArtist:
    """Draw ``chain`` at the numeric configuration ``q`` (zeros by default) and return a :class:`ChainArtist`.

    Links join ``chain.skeleton(q)`` (base, joint points, tool origin); revolute joints are circles
    (⊙ in 2-D: the axis leaves the page), prismatic joints grey rails along their axis v_i; ``axes``
    adds the current joint axes (dashed, from the columns of J_s(θ)); ``frames`` the space frame {s}
    and the tool frame {b} = T(θ) with x (red), y (green), z (blue) arrows; ``labels`` θ1…θn (placed
    clear of each other and of the links; ``fontsize``).

    ``planar``: 2-D drawing (the xy-plane) when True; default: 2-D exactly when :func:`is_planar`.
    ``params``: numbers for symbolic link lengths (``{"L": 1}``); without them a chain with symbolic
    parameters raises ValueError.

    The view has equal scales on all axes (lengths and angles look right) and is fitted to
    ``view="pose"``: what is drawn now (the default; arrows drawn later with :func:`draw_velocity` & co.
    enlarge it), or ``view="workspace"``: every pose in the joint ranges (the default when ``ranges`` is
    given, e.g. for sliders: the arm never leaves the picture). ``ranges``: joint ranges (see
    :func:`default_ranges`); ``limits``: an explicit box [[xmin, xmax], [ymin, ymax](, [zmin, zmax])].
    """
    chain = numeric_chain(chain, params)
    q = _as_q(chain, q)
    if ax is not None and planar is None:
        planar = not _is3d(ax)
    if planar is None:
        planar = is_planar(chain)
    if view is None:
        view = "workspace" if ranges is not None else "pose"
    if view not in ("pose", "workspace"):
        raise ValueError(f"view must be 'pose' or 'workspace', got {view!r}")
    ax = new_axes(planar, ax, figsize)
    if planar == _is3d(ax):
        raise ValueError(f"ax is a {'3-D' if _is3d(ax) else '2-D'} axes but planar={planar}")
    if not planar:
        ax.computed_zorder = False  # keep the labels above the links and markers (zorder, not depth, decides)
    rngs = default_ranges(chain, ranges)
    W = _workspace_points(chain, rngs, q)
    size = float(np.max(W.max(axis=1) - W.min(axis=1)))
    scale = max(_reach(chain), 1e-6)
    scale = min(scale, size) if size > 0 else scale
    art = ChainArtist(ax, chain, q, planar=planar, frames=frames, axes=axes, labels=labels, color=color,
                      scale=scale, fontsize=fontsize)
    if limits is not None:
        lim = np.asarray(limits, float)
        if lim.shape != ((2, 2) if planar else (3, 2)):
            raise ValueError(f"limits must be {'[[xmin, xmax], [ymin, ymax]]' if planar else '[[xmin, xmax], [ymin, ymax], [zmin, zmax]]'}, "
                             f"got {describe(limits)}")
        ax.set_xlim(*lim[0])
        ax.set_ylim(*lim[1])
        if planar:
            ax.set_aspect("equal", adjustable="box")
        else:
            ax.set_zlim(*lim[2])
            ax.set_box_aspect(tuple(lim[:, 1] - lim[:, 0]), zoom=0.95)
        ax._kinlib_view = {"fit": False, "points": None, "margin": 0.0, "obstacles": np.zeros((3, 0)), "chain": art}
    else:
        pts = art.extent_points() if view == "pose" else np.hstack([W, art.extent_points()])
        margin = 0.06 if view == "pose" else 0.03
        _fit_view(ax, pts, margin)
        ax._kinlib_view = {"fit": True, "points": pts, "margin": margin, "obstacles": np.zeros((3, 0)), "chain": art}
    if planar:
        ax.set_xlabel("x_s")
        ax.set_ylabel("y_s")
        ax.grid(True, lw=0.4, alpha=0.5)
    else:
        from matplotlib.ticker import MaxNLocator
        for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis.set_major_locator(MaxNLocator(4))
        ax.tick_params(labelsize=7, pad=0)
        ax.set_xlabel("x_s", labelpad=-2)
        ax.set_ylabel("y_s", labelpad=-2)
        ax.set_zlabel("z_s", labelpad=-2)
    ax.set_title(title if title is not None else chain.name)
    art.place_labels()
    return art


def _fmt_expr(e) -> str:
    """A label for a number or expression: SymPy as it is, floats to 4 significant digits (never a guessed
    closed form)."""
    if not isinstance(e, sp.Basic):
        x = float(e)
        return str(int(x)) if x.is_integer() else f"{x:.4g}"
    return sp.sstr(e).replace("**", "^").replace("*", "·")


def _fmt_vec(v) -> str:
    return "(" + ", ".join(_fmt_expr(x) for x in v) + ")"


def draw_home(chain, ax=None, *, params=None, annotate=True, frames=True, title=None, figsize=None,
              fontsize=8) -> ChainArtist:
    """The chain at home (θ = 0), its joint axes drawn and labelled θ1…θn, and beside the picture each
    joint's screw axis S_i: revolute ``θi: ω=(…), q=(…)`` (axis direction and a point on it), prismatic
    ``θi: v=(…)``, in the chain's own symbols when it has symbolic link lengths (``params`` gives the
    numbers used for the drawing itself). The screw-axis texts are ``.annotations`` of the result."""
    sym_chain = _check_chain(chain)
    num = numeric_chain(sym_chain, params)
    n = num.n
    own_figure = ax is None
    if own_figure and figsize is None:
        figsize = (9, 5) if is_planar(num) else (9.5, 6)
    art = draw_chain(num, np.zeros(n), ax, frames=frames, axes=True, labels=True,
                     title=title if title is not None else f"{sym_chain.name} at home (θ = 0)",
                     figsize=figsize, fontsize=fontsize + 1)
    if annotate:
        from matplotlib.lines import Line2D
        S = sym_chain.screws
        handles, texts = [], []
        for i, k in enumerate(sym_chain.joint_types):
            if k == "R":
                s = f"θ{i + 1}: ω = {_fmt_vec(S[:3, i])}\n      q = {_fmt_vec(sym_chain.joint_points[:, i])}"
            else:
                s = f"θ{i + 1}: v = {_fmt_vec(S[3:, i])}"
            c = JOINT_COLORS[i % 10]
            handles.append(Line2D([], [], ls="", marker="o" if k == "R" else "s", mfc="white" if k == "R" else c,
                                  mec=c, mew=1.8, ms=7))
            texts.append(s)
        leg = art.ax.legend(handles, texts, loc="center left", bbox_to_anchor=(1.02, 0.5), fontsize=fontsize,
                            title="screw axes at θ = 0\n(revolute: axis ω through q;\n prismatic: direction v)",
                            title_fontsize=fontsize, frameon=True, labelspacing=0.9, handletextpad=0.4,
                            alignment="left")
        for t, i in zip(leg.get_texts(), range(n)):
            t.set_color(JOINT_COLORS[i % 10])
        art.legend = leg
        art.annotations = list(leg.get_texts())
        if own_figure:
            art.ax.figure.subplots_adjust(left=0.0 if not art.planar else 0.1, right=0.62)
        art.place_labels()
    return art


# ---------------------------------------------------------------------------------------------------
# velocities
# ---------------------------------------------------------------------------------------------------
def _vel_rows(ax, rows):
    if rows is None:
        return (3, 4, 5) if _is3d(ax) else (3, 4)
    r = task_row_indices(rows)
    d = 3 if _is3d(ax) else 2
    if len(r) != d:
        raise ValueError(f"rows must name {d} rows for {'3-D' if d == 3 else '2-D'} axes "
                         f"(e.g. {('vx', 'vy', 'vz') if d == 3 else ('vx', 'vy')}), got {describe(rows)}")
    return r


class VelocityArtist:
    """The end-effector velocity arrow ṗ = J_ṗ(θ) θ̇ at the tool origin; ``update(q, qdot)``."""

    def __init__(self, ax, chain, q, qdot, rows, scale, color, label):
        self.ax, self.chain, self.rows, self.scale = ax, chain, rows, scale
        self.q, self.qdot = q, qdot
        p, v = self._compute(q, qdot)
        self.arrows = _Arrows(ax, p[None], v[None] * scale, [color], label=label, zorder=6, head=0.22,
                              width=0.014)
        self.velocity = v
        _include(ax, p[:, None] + np.outer(scale * v, np.linspace(0.2, 1.05, 6)))

    def _compute(self, q, qdot):
        J = self.chain.jacobian_geometric(q)
        p = self.chain.fk(q)[:3, 3]
        v = J[list(self.rows)] @ qdot
        d = len(self.rows)
        return p[:d], v

    def update(self, q=None, qdot=None):
        q = self.q if q is None else _as_q(self.chain, q)
        qdot = self.qdot if qdot is None else _as_q(self.chain, qdot, "qdot")
        self.q, self.qdot = q, qdot
        p, v = self._compute(q, qdot)
        self.velocity = v
        self.arrows.set(p[None], v[None] * self.scale)
        return self

    @property
    def artist(self):
        return self.arrows.artist

    @property
    def artists(self) -> list:
        return [self.arrows.artist]


def draw_velocity(ax, chain, q, qdot, *, rows=None, scale=1.0, color="tab:purple", label=r"$\dot p = J\,\dot\theta$",
                  params=None) -> VelocityArtist:
    """Arrow of the tool-origin velocity ṗ = J_ṗ(θ) θ̇ (rows ṗ_x, ṗ_y(, ṗ_z) of the geometric Jacobian),
    drawn from the tool origin and multiplied by ``scale`` for display. ``.velocity`` holds ṗ."""
    chain = numeric_chain(chain, params)
    q, qdot = _as_q(chain, q), _as_q(chain, qdot, "qdot")
    return VelocityArtist(ax, chain, q, qdot, _vel_rows(ax, rows), scale, color, label)


draw_twist_arrow = draw_velocity


class JointVelocitiesArtist:
    """One arrow per joint at the tool origin: column i of the geometric Jacobian's ṗ rows (ṗ for θ̇_i = 1)."""

    def __init__(self, ax, chain, q, rows, scale, colors, labels, joints):
        self.ax, self.chain, self.rows, self.scale, self.joints = ax, chain, rows, scale, joints
        self.q = q
        p, V = self._compute(q)
        self.columns = V
        self.arrows = _Arrows(ax, np.tile(p, (len(joints), 1)), V * scale, colors, zorder=6, head=0.2,
                              width=0.01)
        self.texts = []
        if labels:
            for k, i in enumerate(joints):
                self.texts.append(_text(ax, p, labels[k], color=colors[k], fontsize=9, ha="center", va="center",
                                        zorder=8))
        _include(ax, np.hstack([p[:, None] + np.outer(scale * V[k], np.linspace(0.2, 1.25, 7))
                                for k in range(len(joints))]))
        self._place(p, V)
        self._show_labels(V)

    def _place(self, p, V):
        """Each label beyond its arrow's tip, or beside it when that spot is on another arrow or label."""
        if not self.texts:
            return
        ax = self.ax
        d = len(p)
        px = 9 * ax.figure.dpi / 72.0
        step = 1.3 * px * _data_per_pixel(ax)
        V = V * self.scale
        P3 = (lambda X: np.vstack([X, np.zeros((3 - d, X.shape[1]))])) if d == 2 else (lambda X: X)
        t = np.linspace(0.15, 1.0, 12)
        O = _to_pixels(ax, P3(np.hstack([p[:, None] + np.outer(v, t) for v in V])))
        placed = np.zeros((0, 2))
        for txt, v in zip(self.texts, V):
            nv = np.linalg.norm(v)
            u = v / nv if nv > 0 else np.eye(d)[0]
            w = np.array([-u[1], u[0]]) if d == 2 else _perp(u)
            tip = p + v
            C = np.column_stack([tip + step * u, tip + step * w, tip - step * w, tip + step * (u + w),
                                 tip + step * (u - w), tip + 2 * step * u])
            Cp = _to_pixels(ax, P3(C))
            k = _pick(Cp, O, placed, 1.6 * px, 0.9 * px)
            _move_text(txt, P3(C[:, k:k + 1])[:, 0])
            placed = np.vstack([placed, Cp[k]])

    def _show_labels(self, V):
        """Hide the label of an arrow too short to carry one (< 8 % of the longest): they would pile up."""
        n = np.linalg.norm(V, axis=1)
        for t, nk in zip(self.texts, n):
            t.set_visible(bool(nk > 0.08 * max(n.max(), 1e-300)))

    def _compute(self, q):
        J = self.chain.jacobian_geometric(q)
        p = self.chain.fk(q)[:3, 3][: len(self.rows)]
        V = J[np.ix_(list(self.rows), list(self.joints))].T  # (k, d)
        return p, V

    def update(self, q):
        q = _as_q(self.chain, q)
        self.q = q
        p, V = self._compute(q)
        self.columns = V
        self.arrows.set(np.tile(p, (len(self.joints), 1)), V * self.scale)
        self._place(p, V)
        self._show_labels(V)
        return self

    @property
    def artists(self) -> list:
        return [self.arrows.artist, *self.texts]


def draw_joint_velocities(ax, chain, q, *, rows=None, joints=None, scale=1.0, colors=None, labels=True,
                          params=None) -> JointVelocitiesArtist:
    """Each joint's contribution to ṗ at the tool origin: the arrow J_ṗ[:, i] (θ̇_i = 1, the others 0),
    colour-coded per joint and labelled ``θ̇i``. ``joints``: joint numbers (1-based) to draw (all by default).
    ``.columns`` holds the drawn vectors (k, d)."""
    chain = numeric_chain(chain, params)
    q = _as_q(chain, q)
    r = _vel_rows(ax, rows)
    idx = list(range(chain.n)) if joints is None else [_joint_index(chain, j, "joints") for j in joints]
    cols = list(colors) if colors is not None else [JOINT_COLORS[i % 10] for i in idx]
    labs = [_theta_tex(i + 1, dot=True) for i in idx] if labels is True else (list(labels) if labels else None)
    return JointVelocitiesArtist(ax, chain, q, r, scale, cols, labs, idx)


# ---------------------------------------------------------------------------------------------------
# the velocity ellipse
# ---------------------------------------------------------------------------------------------------
class EllipseArtist:
    """The image of the unit ball ‖θ̇‖ ≤ 1 under the chosen rows of J(θ), centred at the tool origin.

    ``semi_axes`` (the singular values σ_i of the rows, largest first, before ``scale``) and
    ``directions`` (the unit left singular vectors as columns) describe it; at a singular configuration
    a semi-axis is 0 and the ellipse is drawn as a segment. ``update(q)``.
    """

    _T = np.linspace(0.0, 2 * np.pi, 97)

    def __init__(self, ax, chain, q, rows, scale, color, axes_lines, label, fill):
        self.ax, self.chain, self.rows, self.scale = ax, chain, rows, scale
        self.three_d = _is3d(ax)
        self.q = q
        c, curves, axes = self._compute(q)
        self.curves = [_line(ax, cv, color=color, lw=1.8, zorder=5, label=label if k == 0 else None)
                       for k, cv in enumerate(curves)]
        self.fill = None
        if fill and not self.three_d:
            self.fill = ax.fill(curves[0][0], curves[0][1], color=color, alpha=0.12, zorder=1)[0]
        self.axes = _segs_collection(ax, axes, colors=color, linewidths=1.0, linestyles=":", zorder=5) \
            if axes_lines else None
        _include(ax, np.hstack(curves))

    def _compute(self, q):
        J = self.chain.jacobian_geometric(q)[list(self.rows)]
        U, s, _ = np.linalg.svd(J)
        m = len(self.rows)
        sig = np.zeros(m)
        sig[: len(s)] = s
        self.semi_axes, self.directions = sig, U
        p = self.chain.fk(q)[:3, 3]
        c = p[:m] if m == 2 else p
        A = U * (sig * self.scale)  # columns: scaled semi-axes
        ct, st = np.cos(self._T), np.sin(self._T)
        if m == 2:
            curves = [(c[:, None] + A @ np.vstack([ct, st]))]
            axes = [[c - A[:, k], c + A[:, k]] for k in range(2)]
            curves = [np.vstack([cv, np.zeros(cv.shape[1])]) for cv in curves]
            axes = [[np.r_[a, 0.0], np.r_[b, 0.0]] for a, b in axes]
        else:
            curves = [c[:, None] + A[:, [i, j]] @ np.vstack([ct, st]) for i, j in ((0, 1), (1, 2), (0, 2))]
            axes = [[c - A[:, k], c + A[:, k]] for k in range(3)]
        return c, curves, axes

    def update(self, q):
        q = _as_q(self.chain, q)
        self.q = q
        c, curves, axes = self._compute(q)
        for ln, cv in zip(self.curves, curves):
            _set_line(ln, cv)
        if self.fill is not None:
            self.fill.set_xy(curves[0][:2].T)
        if self.axes is not None:
            _set_segs(self.axes, axes, self.three_d)
        return self

    @property
    def artists(self) -> list:
        return [a for a in (self.fill, *self.curves, self.axes) if a is not None]

    @property
    def manipulability(self) -> float:
        """Product of the semi-axes: √det(J Jᵀ) of the drawn rows (the ellipse's area/π in 2-D)."""
        return float(np.prod(self.semi_axes))


def draw_velocity_ellipse(ax, chain, q, *, rows=None, scale=1.0, color="tab:green", axes_lines=True,
                          label="velocity ellipse", fill=True, params=None) -> EllipseArtist:
    """The velocity ellipse at the tool origin: {J_r θ̇ : ‖θ̇‖ = 1} for the rows r of the geometric
    Jacobian (default ṗ_x, ṗ_y on 2-D axes; ṗ_x, ṗ_y, ṗ_z on 3-D axes, drawn as its three principal
    ellipses). Semi-axes σ_i u_i from the SVD J_r = U Σ Vᵀ; a segment at a singular configuration.
    The i-th chosen row is drawn along the axes' i-th coordinate, so use other rows knowingly."""
    chain = numeric_chain(chain, params)
    q = _as_q(chain, q)
    return EllipseArtist(ax, chain, q, _vel_rows(ax, rows), scale, color, axes_lines, label, fill)


def draw_ellipse(ax, center, lengths, axes, *, color="tab:green", label=None, scale=1.0, fill=True,
                 axes_lines=True, lw=1.8):
    """An ellipse (2-D) or the three principal ellipses of an ellipsoid (3-D) centred at ``center``, with
    semi-axis lengths ``lengths`` along the unit directions ``axes`` (columns), e.g. the output
    ``(σ, U)`` of ``kinlib.manipulability.velocity_ellipsoid``. Zero lengths give a segment.
    Returns the list of drawn artists."""
    d = 3 if _is3d(ax) else 2
    c = np.asarray([float(x) for x in center], float)[:d]
    if c.shape != (d,):
        raise ValueError(f"center must have {d} entries for {'3-D' if d == 3 else '2-D'} axes, got {describe(center)}")
    lengths = np.asarray([float(x) for x in np.ravel(np.asarray(lengths, dtype=object))], float)
    U = np.asarray(sp.Matrix(axes).evalf() if isinstance(axes, sp.MatrixBase) else axes, float)
    if U.ndim != 2 or U.shape[0] != d or U.shape[1] != lengths.size or lengths.size > d:
        raise ValueError(f"axes must be a {d}×k matrix of unit directions (columns) matching the {lengths.size} "
                         f"lengths, got {describe(axes)}")
    A = np.zeros((d, d))
    A[:, : lengths.size] = U * (lengths * scale)
    t = np.linspace(0.0, 2 * np.pi, 97)
    ct, st = np.cos(t), np.sin(t)
    out = []
    pairs = ((0, 1),) if d == 2 else ((0, 1), (1, 2), (0, 2))
    for k, (i, j) in enumerate(pairs):
        cv = c[:, None] + A[:, [i, j]] @ np.vstack([ct, st])
        if d == 2:
            out.append(ax.plot(cv[0], cv[1], color=color, lw=lw, zorder=5, label=label)[0])
            if fill:
                out.append(ax.fill(cv[0], cv[1], color=color, alpha=0.12, zorder=1)[0])
        else:
            out.append(ax.plot(cv[0], cv[1], cv[2], color=color, lw=lw, label=label if k == 0 else None)[0])
    if axes_lines:
        segs = [[np.r_[c - A[:, k], [0.0] * (3 - d)], np.r_[c + A[:, k], [0.0] * (3 - d)]] for k in range(d)]
        out.append(_segs_collection(ax, segs, colors=color, linewidths=1.0, linestyles=":", zorder=5))
    _include(ax, np.column_stack([c[:, None] + A, c[:, None] - A]))
    return out


def plot_joint_contributions(ax, values, *, title=None, ylabel=None, labels=None, colors=None,
                             highlight=True, fmt="{:+.3f}"):
    """A bar chart of one task row's joint contributions J[row, i] (what θ̇_i = 1 alone gives), one bar
    per joint in its colour, the value written on each bar; ``highlight`` outlines the joint(s) with the
    largest |value| (ties within 10⁻⁹ relative all outlined). Returns the BarContainer."""
    try:
        v = np.asarray([float(x) for x in (list(values) if not isinstance(values, np.ndarray) else values.ravel())],
                       float)
    except (TypeError, ValueError):
        raise TypeError(f"values must be numbers (one per joint), got {describe(values)}") from None
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"values must be a non-empty vector, got {describe(values)}")
    n = v.size
    x = np.arange(1, n + 1)
    colors = list(colors) if colors is not None else [JOINT_COLORS[i % 10] for i in range(n)]
    bars = ax.bar(x, v, color=colors)
    a = np.abs(v)
    if highlight and a.max() > 0:
        for i in np.flatnonzero(a >= a.max() - 1e-9 * a.max()):
            bars[i].set_edgecolor("k")
            bars[i].set_linewidth(2.5)
    best = set(np.flatnonzero(a >= a.max() - 1e-9 * a.max()).tolist()) if a.max() > 0 else set()
    for i, (xi, vi) in enumerate(zip(x, v)):
        ax.text(xi, vi, fmt.format(vi), ha="center", va="bottom" if vi >= 0 else "top", fontsize=9,
                fontweight="bold" if (highlight and i in best) else "normal")
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xticks(x, labels if labels is not None else [_theta_tex(i + 1, dot=True) for i in range(n)])
    top = float(a.max()) or 1.0
    lo, hi = min(0.0, float(v.min())), max(0.0, float(v.max()))
    ax.set_ylim(lo - 0.2 * top, hi + 0.2 * top)
    ax.grid(True, axis="y", lw=0.4, alpha=0.5)
    if title:
        ax.set_title(title, fontsize=10)
    if ylabel:
        ax.set_ylabel(ylabel)
    return bars


# ---------------------------------------------------------------------------------------------------
# directions (column space, left null space)
# ---------------------------------------------------------------------------------------------------
def _beyond(v) -> dict:
    """Text alignment that puts a label just past the head of an arrow along v (not on top of it)."""
    n = float(np.linalg.norm(v[:2])) or 1.0
    ux, uy = v[0] / n, v[1] / n
    return dict(ha="left" if ux > 0.35 else "right" if ux < -0.35 else "center",
                va="bottom" if uy > 0.35 else "top" if uy < -0.35 else "center")


def draw_directions(ax, origin, vectors, labels=None, *, colors=None, components=None, length=None,
                    both_ways=False, linestyles=None, fontsize=9, lw=2.0):
    """Arrows from ``origin`` along each vector (a list of vectors, or a matrix whose *columns* are the
    vectors, e.g. a column-space basis). ``components``: which entries of each vector to draw (e.g. (1, 2)
    for the ṗ_x, ṗ_y part of a (ω_z, ṗ_x, ṗ_y) vector); ``length``: rescale each arrow to this length;
    ``both_ways``: a double-headed arrow (a direction, not a sense); ``linestyles``: e.g. ['-', '--'] to
    tell "can move" from "cannot move". Returns the list of FancyArrowPatch (2-D) or arrow artists (3-D)."""
    d = 3 if _is3d(ax) else 2
    if isinstance(vectors, sp.MatrixBase) or (isinstance(vectors, np.ndarray) and vectors.ndim == 2):
        M = np.asarray(sp.Matrix(vectors).evalf() if isinstance(vectors, sp.MatrixBase) else vectors, float)
        vecs = [M[:, j] for j in range(M.shape[1])]
    else:
        try:
            vecs = [np.asarray(sp.Matrix(v).evalf() if isinstance(v, sp.MatrixBase) else
                               [float(x) for x in v], float).reshape(-1) for v in vectors]
        except (TypeError, ValueError):
            raise TypeError(f"vectors must be a matrix (one vector per column) or a list of numeric vectors, "
                            f"got {describe(vectors)}") from None
    if components is not None:
        comp = list(components)
        vecs = [v[comp] for v in vecs]
    for k, v in enumerate(vecs):
        if v.shape != (d,):
            raise ValueError(f"vectors[{k}] must have {d} entries for {'3-D' if d == 3 else '2-D'} axes "
                             f"(use components= to pick them), got {v.shape[0]}")
    o = np.asarray([float(x) for x in origin], float)
    if o.shape != (d,):
        raise ValueError(f"origin must have {d} entries, got {describe(origin)}")
    if length is not None:
        vecs = [v * (length / np.linalg.norm(v)) if np.linalg.norm(v) > 0 else v for v in vecs]
    k = len(vecs)
    colors = list(colors) if colors is not None else ["tab:blue", "tab:red", "tab:green", "tab:orange"][:k] * (1 + k // 4)
    linestyles = list(linestyles) if linestyles is not None else ["-"] * k
    labels = list(labels) if labels is not None else [None] * k
    out = []
    if d == 2:
        from matplotlib.patches import FancyArrowPatch
        for v, c, ls, lab in zip(vecs, colors, linestyles, labels):
            start = o - v if both_ways else o
            a = FancyArrowPatch(start, o + v, arrowstyle="<|-|>" if both_ways else "-|>", mutation_scale=16,
                                color=c, lw=lw, linestyle=ls, zorder=7, label=lab)
            ax.add_patch(a)
            out.append(a)
            if lab:
                al = _beyond(v)
                off = ({"left": 4, "right": -4, "center": 0}[al["ha"]], {"bottom": 4, "top": -4, "center": 0}[al["va"]])
                out.append(ax.annotate(lab, xy=tuple(o + v), xytext=off, textcoords="offset points", color=c,
                                       fontsize=fontsize, zorder=8, **al))
    else:
        for v, c, ls, lab in zip(vecs, colors, linestyles, labels):
            arr = _Arrows(ax, o[None], v[None], [c], linestyle=ls, lw=lw, zorder=7, label=lab)
            out.append(arr.artist)
            if both_ways:
                out.append(_Arrows(ax, o[None], -v[None], [c], linestyle=ls, lw=lw, zorder=7).artist)
            if lab:
                out.append(_text(ax, o + v, lab, color=c, fontsize=fontsize, zorder=8, **_beyond(v[:2])))
    ends = [o + 1.2 * v for v in vecs] + ([o - v for v in vecs] if both_ways else []) + [o]
    _include(ax, np.column_stack(ends))
    return out


# ---------------------------------------------------------------------------------------------------
# manipulability over one or two joints
# ---------------------------------------------------------------------------------------------------
@dataclass
class CurvePlot:
    """Result of :func:`plot_manipulability_curve`: ``x`` (joint values), ``values`` (the measure)."""
    ax: Any
    line: Any
    x: np.ndarray
    values: np.ndarray
    joint: int
    markers: list = field(default_factory=list)


@dataclass
class MapPlot:
    """Result of :func:`plot_manipulability_map`: grid ``x`` (joint i), ``y`` (joint j), ``values[y, x]``."""
    ax: Any
    image: Any
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray
    joints: tuple
    singular: list = field(default_factory=list)


def _task_J(chain, Q, rows):
    J = chain.jacobian_geometric(Q)
    return J[:, list(rows), :]


def plot_manipulability_curve(chain, joint, q_fixed=None, *, rows=None, measure="yoshikawa", lim=None,
                              num=721, ax=None, mark_max=True, mark_zero=True, params=None,
                              label=None) -> CurvePlot:
    """The manipulability measure (see :func:`manipulability_values`) of the task rows of the geometric
    Jacobian as joint ``joint`` (1-based) sweeps ``lim`` (default its range), the others fixed at
    ``q_fixed`` (zeros). Default rows: (ω_z, ṗ_x, ṗ_y) for a planar chain, all six otherwise.
    Marks the maxima and the zeros (singular configurations) found on the grid."""
    chain = numeric_chain(chain, params)
    i = _joint_index(chain, joint)
    q0 = _as_q(chain, q_fixed, "q_fixed")
    r = task_row_indices(rows) if rows is not None else _default_task_rows(chain)
    lo, hi = lim if lim is not None else default_ranges(chain)[i]
    x = np.linspace(lo, hi, num)
    Q = np.tile(q0, (num, 1))
    Q[:, i] = x
    J = _task_J(chain, Q, r)
    vals = manipulability_values(J, measure)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3.5))
    m, n = len(r), chain.n
    ylabel = _measure_label(measure, m, n)
    line, = ax.plot(x, vals, lw=2, label=label or ylabel)
    ax.set_xlabel(_theta_tex(i + 1) + (" (rad)" if chain.joint_types[i] == "R" else ""))
    ax.set_ylabel(ylabel)
    ax.set_title(f"{chain.name}: {ylabel} of rows ({_rows_label(r, True)}) over {_theta_tex(i + 1)}")
    ax.grid(True, lw=0.4, alpha=0.5)
    if chain.joint_types[i] == "R" and hi - lo >= math.pi / 2:
        pi_ticks(ax.xaxis, lo, hi, 4 if hi - lo <= 2 * math.pi + 1e-9 else 2)
    marks = []
    top = float(np.max(np.abs(vals))) or 1.0
    if mark_max:
        k = np.flatnonzero(vals >= vals.max() - 1e-9 * top)
        marks.append(ax.plot(x[k], vals[k], "v", color="tab:green", ms=8, label="maximum")[0])
    if mark_zero:
        k = np.flatnonzero(np.abs(vals) <= 1e-9 * top)
        s = np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)  # sign changes (measure='det')
        xs = np.r_[x[k], x[s] - vals[s] * (x[s + 1] - x[s]) / (vals[s + 1] - vals[s])]
        if xs.size:
            marks.append(ax.plot(xs, np.zeros_like(xs), "o", color="tab:red", ms=7, label="singular")[0])
    return CurvePlot(ax, line, x, vals, i + 1, marks)


def plot_manipulability_map(chain, joints=(1, 2), q_fixed=None, *, rows=None, measure="yoshikawa", lims=None,
                            num=181, ax=None, singular=True, params=None, cmap="viridis",
                            colorbar=True) -> MapPlot:
    """Heat map of a manipulability measure over two joints ``joints`` = (i, j) (1-based), the others
    fixed at ``q_fixed``, with the singular set drawn in red.

    ``singular``: True draws the zero contour of det J (square task rows; exact sign change) or, for
    non-square rows, the contour σ_min/σ_max = 10⁻³ hugging the set where the rank drops; False draws
    nothing; or a list of curves ``[(xs, ys), ...]`` / a dict ``{label: (xs, ys)}`` (e.g. from the exact
    singular set) drawn as given."""
    chain = numeric_chain(chain, params)
    if not isinstance(joints, (tuple, list)) or len(joints) != 2:
        raise ValueError(f"joints must be two joint numbers (i, j), got {describe(joints)}")
    i, j = (_joint_index(chain, k, "joints") for k in joints)
    if i == j:
        raise ValueError(f"joints must be two different joints, got {joints}")
    q0 = _as_q(chain, q_fixed, "q_fixed")
    r = task_row_indices(rows) if rows is not None else _default_task_rows(chain)
    rngs = default_ranges(chain)
    (xlo, xhi), (ylo, yhi) = lims if lims is not None else (rngs[i], rngs[j])
    x, y = np.linspace(xlo, xhi, num), np.linspace(ylo, yhi, num)
    X, Y = np.meshgrid(x, y)
    Q = np.tile(q0, (X.size, 1))
    Q[:, i], Q[:, j] = X.ravel(), Y.ravel()
    J = _task_J(chain, Q, r)
    vals = manipulability_values(J, measure).reshape(X.shape)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5))
    m, n = len(r), chain.n
    label = _measure_label(measure, m, n)
    im = ax.pcolormesh(X, Y, vals, shading="auto", cmap=cmap)
    if colorbar:
        ax.figure.colorbar(im, ax=ax, label=label)
    sing = []
    if singular is True:
        if m == n:
            D = np.linalg.det(J).reshape(X.shape)
            if np.nanmin(D) < 0 < np.nanmax(D):
                sing.append(ax.contour(X, Y, D, levels=[0.0], colors="red", linewidths=2))
        else:
            ic = manipulability_values(J, "inverse_condition").reshape(X.shape)
            if np.nanmin(ic) < 1e-3:
                sing.append(ax.contour(X, Y, ic, levels=[1e-3], colors="red", linewidths=2))
        if sing:
            ax.plot([], [], color="red", lw=2, label="singular set")
    elif singular:
        items = singular.items() if isinstance(singular, Mapping) else [(None, c) for c in singular]
        for k, (lab, (xs, ys)) in enumerate(items):
            sing.append(ax.plot(xs, ys, color="red", lw=2, label=lab if lab else ("singular set" if k == 0 else None))[0])
    if sing:
        ax.legend(loc="upper right", fontsize=8)
    ax.set_xlim(xlo, xhi)
    ax.set_ylim(ylo, yhi)
    ax.set_xlabel(_theta_tex(i + 1))
    ax.set_ylabel(_theta_tex(j + 1))
    for k, (lo, hi), axis in ((i, (xlo, xhi), ax.xaxis), (j, (ylo, yhi), ax.yaxis)):
        if chain.joint_types[k] == "R" and hi - lo >= math.pi / 2:
            pi_ticks(axis, lo, hi, 2)
    ax.set_title(f"{chain.name}: {label} of rows ({_rows_label(r, True)})")
    return MapPlot(ax, im, x, y, vals, (i + 1, j + 1), sing)


# ---------------------------------------------------------------------------------------------------
# animation
# ---------------------------------------------------------------------------------------------------
def sweep(chain, joint, values, q_fixed=None, params=None) -> np.ndarray:
    """A path (N, n): joint ``joint`` (1-based) takes ``values``, the others stay at ``q_fixed`` (zeros)."""
    chain = numeric_chain(chain, params)
    i = _joint_index(chain, joint)
    q0 = _as_q(chain, q_fixed, "q_fixed")
    v = np.asarray(values, float).reshape(-1)
    Q = np.tile(q0, (v.size, 1))
    Q[:, i] = v
    return Q


def animate_singularity(chain, path, *, rows=None, ellipse_rows=None, params=None, interval=100,
                        velocity_scale=0.5, figsize=(9, 4.2), dpi=72, title=None):
    """A FuncAnimation of ``chain`` following ``path`` (N×n configurations, e.g. from :func:`sweep`):
    left, the arm with its velocity ellipse (collapsing to a segment at a singular configuration) and a
    status line; right, the manipulability √det(J Jᵀ) of the task ``rows`` along the path with a moving
    marker. Play it in a static page with ``anim.to_jshtml()`` (``IPython.display.HTML``)."""
    chain = numeric_chain(chain, params)
    P = np.asarray(path, float)
    if P.ndim != 2 or P.shape[1] != chain.n or P.shape[0] < 2:
        raise ValueError(f"path must be an array of shape (N, {chain.n}) with N ≥ 2 configurations of "
                         f"{chain.name}, got {describe(path)}")
    r = task_row_indices(rows) if rows is not None else _default_task_rows(chain)
    planar = is_planar(chain)
    fig = plt.figure(figsize=figsize, dpi=dpi)
    ax = fig.add_subplot(1, 2, 1, projection=None if planar else "3d")
    ax2 = fig.add_subplot(1, 2, 2)
    lo, hi = P.min(axis=0), P.max(axis=0)
    rngs = [(min(a, b), max(a, b)) for a, b in zip(lo, hi)]
    arm = draw_chain(chain, P[0], ax, ranges=[(a - 1e-6, b + 1e-6) for a, b in rngs], labels=True,
                     title=title or f"{chain.name} along the path")
    ell = draw_velocity_ellipse(ax, chain, P[0], rows=ellipse_rows, scale=velocity_scale)
    J = _task_J(chain, P, r)
    w = manipulability_values(J, "yoshikawa")
    ic = manipulability_values(J, "inverse_condition")
    s = np.arange(P.shape[0])
    ax2.plot(s, w, lw=2)
    ax2.set_xlabel("step along the path")
    ax2.set_ylabel(_measure_label("yoshikawa", len(r), chain.n))
    ax2.set_title(f"manipulability, rows ({_rows_label(r, True)})", fontsize=10)
    ax2.grid(True, lw=0.4, alpha=0.5)
    mark, = ax2.plot([0], [w[0]], "o", color="tab:red", ms=8)
    txt = ax.text2D(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9) if not planar else \
        ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9,
                bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8), zorder=9)
    fig.tight_layout()

    def status(k):
        if ic[k] < 1e-6:
            return "SINGULAR configuration"
        if ic[k] < 0.1:
            return "near a singular configuration"
        return ""

    def frame(k):
        arm.update(P[k])
        ell.update(P[k])
        mark.set_data([k], [w[k]])
        txt.set_text(f"{_measure_label('yoshikawa', len(r), chain.n)} = {w[k]:.3f}   {status(k)}")
        txt.set_color("tab:red" if status(k) else "k")
        return []

    frame(0)
    anim = _animation.FuncAnimation(fig, frame, frames=P.shape[0], interval=interval, blit=False)
    anim.values = w
    return anim
