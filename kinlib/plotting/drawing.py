"""Draw a chain at a configuration, its home position with the screw axes, and its velocities: the tool
velocity ṗ, each joint's column of J, the velocity ellipse (or any ellipse given by lengths and directions).

>>> from kinlib.robots import planar_offset_3r
>>> chain = planar_offset_3r(1)
>>> art = draw_chain(chain, [0, 0.5, -0.5]); type(art).__name__
'ChainArtist'
>>> type(draw_velocity(art.ax, chain, [0, 0.5, -0.5], [1, 0, 0])).__name__
'VelocityArtist'
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import sympy as sp

from .._backend import describe
from ..analysis.taskspace import default_task_rows, is_planar, rows_label, task_row_indices
from .artists import ChainArtist, EllipseArtist, JointVelocitiesArtist, VelocityArtist, ellipse_outline
from .common import (
    JOINT_COLORS,
    as_configuration,
    check_chain,
    checked_numeric,
    default_ranges,
    is_3d,
    reach,
    theta_tex,
)
from .primitives import add_segments
from .view import ViewState, fit_view, include, new_axes, workspace_points

__all__ = ["draw_chain", "draw_home", "draw_velocity", "draw_joint_velocities", "draw_velocity_ellipse", "draw_ellipse"]


def draw_chain(
    chain,
    q=None,
    ax=None,
    *,
    planar=None,
    frames=True,
    axes=True,
    labels=True,
    params=None,
    ranges=None,
    limits=None,
    view=None,
    color="0.25",
    title=None,
    figsize=None,
    fontsize=9,
) -> ChainArtist:
    """Draw ``chain`` at the numeric configuration ``q`` (zeros by default) and return a :class:`ChainArtist`.

    Links join ``chain.skeleton(q)`` (base, joint points, tool origin); revolute joints are circles
    (⊙ in 2-D: the axis leaves the page), prismatic joints a grey track along their axis v_i (over the
    joint's range) with a slider at T_i(p_i) = T_{i−1}(p_i) + θ_i v_i carrying the next link (the cart of
    the cart-pole; see :class:`~kinlib.plotting.artists.ChainArtist`); ``axes``
    adds the current joint axes (dashed, from the columns of J_s(θ)); ``frames`` the space frame {s}
    and the tool frame {b} = T(θ) with x (red), y (green), z (blue) arrows; ``labels`` θ1…θn (placed
    clear of each other and of the links; ``fontsize``).

    ``planar``: 2-D drawing (the xy-plane) when True; default: 2-D exactly when the chain is planar
    (:func:`kinlib.taskspace.is_planar`). ``params``: numbers for symbolic link lengths (``{"L": 1}``);
    without them a chain with symbolic parameters raises ValueError.

    The view has equal scales on all axes (lengths and angles look right) and is fitted to
    ``view="pose"``: what is drawn now (the default; arrows drawn later with :func:`draw_velocity` & co.
    enlarge it), or ``view="workspace"``: every pose in the joint ranges (the default when ``ranges`` is
    given, e.g. for sliders: the arm never leaves the picture). ``ranges``: joint ranges (see
    :func:`default_ranges`); ``limits``: an explicit box [[xmin, xmax], [ymin, ymax](, [zmin, zmax])].

    >>> from kinlib.robots import ur5
    >>> art = draw_chain(ur5(), [0, -1, 1, 0, 1, 0], labels=False)
    >>> art.planar, len(art.labels)
    (False, 0)
    """
    chain = checked_numeric(chain, params)
    q = as_configuration(chain, q)
    if ax is not None and planar is None:
        planar = not is_3d(ax)
    if planar is None:
        planar = is_planar(chain)
    if view is None:
        view = "workspace" if ranges is not None else "pose"
    if view not in ("pose", "workspace"):
        raise ValueError(f"view must be 'pose' or 'workspace', got {view!r}")
    ax = new_axes(planar, ax, figsize)
    if planar == is_3d(ax):
        raise ValueError(f"ax is a {'3-D' if is_3d(ax) else '2-D'} axes but planar={planar}")
    if not planar:
        ax.computed_zorder = False  # keep the labels above the links and markers (zorder, not depth, decides)
    rngs = default_ranges(chain, ranges)
    W = workspace_points(chain, rngs, q)
    size = float(np.max(W.max(axis=1) - W.min(axis=1)))
    scale = max(reach(chain), 1e-6)
    scale = min(scale, size) if size > 0 else scale
    style = dict(frames=frames, axes=axes, labels=labels, color=color, fontsize=fontsize)
    art = ChainArtist(ax, chain, q, planar=planar, scale=scale, ranges=rngs, **style)
    if limits is not None:
        lim = np.asarray(limits, float)
        if lim.shape != ((2, 2) if planar else (3, 2)):
            box = "[[xmin, xmax], [ymin, ymax]]" if planar else "[[xmin, xmax], [ymin, ymax], [zmin, zmax]]"
            raise ValueError(f"limits must be {box}, got {describe(limits)}")
        ax.set_xlim(*lim[0])
        ax.set_ylim(*lim[1])
        if planar:
            ax.set_aspect("equal", adjustable="box")
        else:
            ax.set_zlim(*lim[2])
            ax.set_box_aspect(tuple(lim[:, 1] - lim[:, 0]), zoom=0.95)
        ViewState.attach(ax, fit=False, chain=art)
    else:
        pts = art.extent_points() if view == "pose" else np.hstack([W, art.extent_points()])
        margin = 0.06 if view == "pose" else 0.03
        fit_view(ax, pts, margin)
        ViewState.attach(ax, fit=True, points=pts, margin=margin, chain=art)
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


def draw_home(
    chain, ax=None, *, params=None, annotate=True, frames=True, title=None, figsize=None, fontsize=8
) -> ChainArtist:
    """The chain at home (θ = 0), its joint axes drawn and labelled θ1…θn, and beside the picture each
    joint's screw axis S_i: revolute ``θi: ω=(…), q=(…)`` (axis direction and a point on it), prismatic
    ``θi: v=(…)``, in the chain's own symbols when it has symbolic link lengths (``params`` gives the
    numbers used for the drawing itself). The screw-axis texts are ``.annotations`` of the result.

    >>> from kinlib.robots import planar_offset_3r
    >>> art = draw_home(planar_offset_3r(), params={"L": 1})
    >>> art.annotations[1].get_text().splitlines()[0]
    'θ2: ω = (0, 0, 1)'
    """
    sym_chain = check_chain(chain)
    num = checked_numeric(sym_chain, params)
    n = num.n
    own_figure = ax is None
    if own_figure and figsize is None:
        figsize = (9, 5) if is_planar(num) else (9.5, 6)
    art = draw_chain(
        num,
        np.zeros(n),
        ax,
        frames=frames,
        axes=True,
        labels=True,
        title=title if title is not None else f"{sym_chain.name} at home (θ = 0)",
        figsize=figsize,
        fontsize=fontsize + 1,
    )
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
            handles.append(
                Line2D(
                    [], [], ls="", marker="o" if k == "R" else "s", mfc="white" if k == "R" else c, mec=c, mew=1.8, ms=7
                )
            )
            texts.append(s)
        leg = art.ax.legend(
            handles,
            texts,
            loc="center left",
            bbox_to_anchor=(1.02, 0.5),
            fontsize=fontsize,
            title="screw axes at θ = 0\n(revolute: axis ω through q;\n prismatic: direction v)",
            title_fontsize=fontsize,
            frameon=True,
            labelspacing=0.9,
            handletextpad=0.4,
            alignment="left",
        )
        for t, i in zip(leg.get_texts(), range(n)):
            t.set_color(JOINT_COLORS[i % 10])
        art.legend = leg
        art.annotations = list(leg.get_texts())
        if own_figure:
            art.ax.figure.subplots_adjust(left=0.0 if not art.planar else 0.1, right=0.62)
        art.place_labels()
    return art


def _velocity_rows(ax, rows) -> tuple[int, ...]:
    """The rows drawn as a vector on ``ax``: ṗ_x, ṗ_y (2-D) or ṗ_x, ṗ_y, ṗ_z (3-D) unless given."""
    if rows is None:
        return (3, 4, 5) if is_3d(ax) else (3, 4)
    r = task_row_indices(rows)
    d = 3 if is_3d(ax) else 2
    if len(r) != d:
        raise ValueError(
            f"rows must name {d} rows for {'3-D' if d == 3 else '2-D'} axes "
            f"(e.g. {('vx', 'vy', 'vz') if d == 3 else ('vx', 'vy')}), got {describe(rows)}"
        )
    return r


def draw_velocity(
    ax, chain, q, qdot, *, rows=None, scale=1.0, color="tab:purple", label=r"$\dot p = J\,\dot\theta$", params=None
) -> VelocityArtist:
    """Arrow of the tool-origin velocity ṗ = J_ṗ(θ) θ̇ (rows ṗ_x, ṗ_y(, ṗ_z) of the geometric Jacobian),
    drawn from the tool origin and multiplied by ``scale`` for display. ``.velocity`` holds ṗ.

    >>> from kinlib.robots import planar_3r
    >>> chain = planar_3r(1, 1, 1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> draw_velocity(art.ax, chain, [0, 0, 0], [1, 0, 0], rows="xy").velocity
    array([0., 3.])
    """
    chain = checked_numeric(chain, params)
    q, qdot = as_configuration(chain, q), as_configuration(chain, qdot, "qdot")
    return VelocityArtist(ax, chain, q, qdot, _velocity_rows(ax, rows), scale, color, label)


def draw_joint_velocities(
    ax, chain, q, *, rows=None, joints=None, scale=1.0, colors=None, labels=True, params=None
) -> JointVelocitiesArtist:
    """Each joint's contribution to ṗ at the tool origin: the arrow J_ṗ[:, i] (θ̇_i = 1, the others 0),
    colour-coded per joint and labelled ``θ̇i``. ``joints``: joint numbers (1-based) to draw (all by default).
    ``.columns`` holds the drawn vectors (k, d).

    >>> from kinlib.robots import planar_3r
    >>> chain = planar_3r(1, 1, 1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> draw_joint_velocities(art.ax, chain, [0, 0, 0], joints=[3]).columns + 0.0
    array([[0., 1.]])
    """
    chain = checked_numeric(chain, params)
    q = as_configuration(chain, q)
    r = _velocity_rows(ax, rows)
    idx = list(range(chain.n)) if joints is None else [chain.joint_index(j, "joints") for j in joints]
    cols = list(colors) if colors is not None else [JOINT_COLORS[i % 10] for i in idx]
    labs = [theta_tex(i + 1, dot=True) for i in idx] if labels is True else (list(labels) if labels else None)
    return JointVelocitiesArtist(ax, chain, q, r, scale, cols, labs, idx)


def draw_velocity_ellipse(
    ax,
    chain,
    q,
    *,
    rows=None,
    scale=1.0,
    color="tab:green",
    axes_lines=True,
    label="velocity ellipse",
    fill=True,
    params=None,
    hold=None,
    lw=1.8,
    ls="-",
    alpha=1.0,
) -> EllipseArtist:
    """The velocity ellipse at the tool origin: {J_r θ̇ : ‖θ̇‖ = 1} for the rows r of the geometric
    Jacobian (default ṗ_x, ṗ_y on 2-D axes; ṗ_x, ṗ_y, ṗ_z on 3-D axes, drawn as its three principal
    ellipses). Semi-axes σ_i u_i from the SVD J_r = U Σ Vᵀ; a segment at a singular configuration.
    The i-th chosen row is drawn along the axes' i-th coordinate, so use other rows knowingly.
    ``hold``: rows kept at zero, e.g. ``("wz",)``: {J_r θ̇ : J_h θ̇ = 0, ‖θ̇‖ ≤ 1}, the velocities reachable
    with the orientation held (:func:`kinlib.manipulability.velocity_ellipsoid`); it collapses to a
    segment exactly where the rows (hold + drawn) lose rank. ``lw``, ``ls``, ``alpha``: the outline's style.

    >>> from kinlib.robots import planar_rpp
    >>> chain = planar_rpp(1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> np.round(draw_velocity_ellipse(art.ax, chain, [0, 0, 0]).semi_axes, 6)
    array([1.414214, 1.      ])
    >>> np.round(draw_velocity_ellipse(art.ax, chain, [0, 0, 0], hold="wz").semi_axes, 6)   # θ̇1 = 0: the slides
    array([1., 1.])
    """
    chain = checked_numeric(chain, params)
    q = as_configuration(chain, q)
    r = _velocity_rows(ax, rows)
    h = task_row_indices(hold) if hold is not None else None
    if h is not None and set(h) & set(r):
        raise ValueError(f"hold must not share a row with the drawn rows {r}, got {describe(hold)}")
    return EllipseArtist(ax, chain, q, r, scale, color, axes_lines, label, fill, h, lw, ls, alpha)


class VelocityEllipses(NamedTuple):
    """What :func:`draw_velocity_ellipses` drew: ``held`` (the ṗ ellipse with the task's orientation rows held,
    or None), ``free`` (the ṗ ellipse with every joint free) and ``hold`` (the held row indices, maybe empty)."""

    held: EllipseArtist | None
    free: EllipseArtist
    hold: tuple

    @property
    def main(self) -> EllipseArtist:
        """The ellipse that flattens at the task's singular configurations: ``held`` if any, else ``free``."""
        return self.held if self.held is not None else self.free

    @property
    def artists(self) -> list:
        """Every matplotlib artist of both ellipses (for blitting and animation)."""
        return [*(self.held.artists if self.held is not None else []), *self.free.artists]

    def update(self, q, J=None, p=None) -> None:
        """Recompute both at configuration ``q`` (``J``: the geometric Jacobian there, ``p``: the tool position)."""
        for e in (self.held, self.free):
            if e is not None:
                e.update(q, J, p)


def draw_velocity_ellipses(ax, chain, q, *, task=None, rows=None, scale=1.0, label_suffix="", params=None):
    """The velocity ellipses that show a task's singularities: when the task rows ``task`` (default
    :func:`kinlib.taskspace.default_task_rows`) contain the drawn ṗ rows ``rows`` and some orientation
    rows ω, the ellipse {ṗ_r : ω_task = 0, ‖θ̇‖ ≤ 1} with those orientation rows **held** (it collapses to a
    segment exactly where the task's Jacobian rows lose rank), filled, and the ellipse of ṗ with every joint
    free as a light dashed outline (it need not flatten there); otherwise only the plain velocity ellipse.
    ``label_suffix`` is appended to both legend labels (e.g. the drawing scale).

    >>> from kinlib.robots import planar_offset_3r
    >>> chain = planar_offset_3r(1)
    >>> art = draw_chain(chain, [0, -np.pi / 4, 0])
    >>> ells = draw_velocity_ellipses(art.ax, chain, [0, -np.pi / 4, 0])
    >>> ells.hold, np.round(ells.held.semi_axes, 6) + 0.0, ells.main is ells.held
    ((2,), array([1.715462, 0.      ]), True)
    """
    chain = checked_numeric(chain, params)
    r = _velocity_rows(ax, rows)
    t = task_row_indices(task, default=default_task_rows(chain))
    hold = tuple(k for k in t if k < 3) if set(r) <= set(t) else ()
    if not hold:
        free = draw_velocity_ellipse(ax, chain, q, rows=r, scale=scale, label=f"velocity ellipse{label_suffix}")
        return VelocityEllipses(None, free, ())
    held = draw_velocity_ellipse(
        ax, chain, q, rows=r, scale=scale, hold=hold, color="tab:green",
        label=rf"$\dot p$ with {rows_label(hold, tex=True)} held{label_suffix}",
    )  # fmt: skip
    free = draw_velocity_ellipse(
        ax, chain, q, rows=r, scale=scale, color="0.45", fill=False, axes_lines=False, lw=1.1, ls="--", alpha=0.8,
        label=rf"$\dot p$, all joints free{label_suffix}",
    )  # fmt: skip
    return VelocityEllipses(held, free, hold)


def draw_ellipse(
    ax, center, lengths, axes, *, color="tab:green", label=None, scale=1.0, fill=True, axes_lines=True, lw=1.8
) -> list:
    """An ellipse (2-D) or the three principal ellipses of an ellipsoid (3-D) centred at ``center``, with
    semi-axis lengths ``lengths`` along the unit directions ``axes`` (columns), e.g. the output
    ``(σ, U)`` of ``kinlib.manipulability.velocity_ellipsoid``. Zero lengths give a segment.
    Returns the list of drawn artists.

    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots()
    >>> [type(a).__name__ for a in draw_ellipse(ax, (0, 0), [2, 1], np.eye(2))]
    ['Line2D', 'Polygon', 'LineCollection']
    """
    d = 3 if is_3d(ax) else 2
    c = np.asarray([float(x) for x in center], float)[:d]
    if c.shape != (d,):
        raise ValueError(f"center must have {d} entries for {'3-D' if d == 3 else '2-D'} axes, got {describe(center)}")
    lengths = np.asarray([float(x) for x in np.ravel(np.asarray(lengths, dtype=object))], float)
    U = np.asarray(sp.Matrix(axes).evalf() if isinstance(axes, sp.MatrixBase) else axes, float)
    if U.ndim != 2 or U.shape[0] != d or U.shape[1] != lengths.size or lengths.size > d:
        raise ValueError(
            f"axes must be a {d}×k matrix of unit directions (columns) matching the {lengths.size} "
            f"lengths, got {describe(axes)}"
        )
    curves, segments = ellipse_outline(c, lengths, U, scale)
    out = []
    for k, cv in enumerate(curves):
        if d == 2:
            out.append(ax.plot(cv[0], cv[1], color=color, lw=lw, zorder=5, label=label)[0])
            if fill:
                out.append(ax.fill(cv[0], cv[1], color=color, alpha=0.12, zorder=1)[0])
        else:
            out.append(ax.plot(cv[0], cv[1], cv[2], color=color, lw=lw, label=label if k == 0 else None)[0])
    if axes_lines:
        out.append(add_segments(ax, segments, colors=color, linewidths=1.0, linestyles=":", zorder=5))
    include(ax, np.hstack(curves))
    return out
