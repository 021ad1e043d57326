"""Pictures of serial chains and their Jacobians (matplotlib; imported on demand, never by ``import kinlib``).

Every drawing is computed from the chain's numeric kinematics at a configuration q:

* the links through ``chain.skeleton(q)`` (base origin, each joint point, tool origin),
* the tool frame {b} from ``chain.fk(q)`` = T(θ) = e^{[S1]θ1} ⋯ e^{[Sn]θn} M,
* the current joint axes from the columns of the space Jacobian J_s(θ) (revolute: ω_i; prismatic: v_i),
* velocities from the **geometric Jacobian** J(θ) = blockdiag(R, R) J_b, rows [ω_s; ṗ]
  (ṗ = velocity of the tool origin in {s}).

Chains with symbolic link lengths cannot be drawn: give numbers first with ``chain.subs(L=1)``, or pass
``params={"L": 1}`` to any function here (``chain.numeric(params)``, cached on the chain).

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
* ``draw_velocity_ellipse(ax, chain, q, *, rows=None, scale=1, hold=None)`` → :class:`EllipseArtist`
  (``.semi_axes``; ``hold=("wz",)``: the ellipse with those rows held at zero, e.g. the orientation);
  ``draw_velocity_ellipses(ax, chain, q, *, task=None, rows=None, scale=1)`` → :class:`VelocityEllipses`
  (the task's held-orientation ellipse, which flattens at its singularities, and the all-joints ṗ outline);
  ``draw_ellipse(ax, center, lengths, axes)`` for a given (σ, U);
* ``draw_directions(ax, origin, vectors, labels, *, components=None, length=None, both_ways=False)``;
* ``plot_joint_contributions(ax, values, *, title=None)`` (bar chart of one row of J);
* ``plot_manipulability_curve(chain, joint, q_fixed=None, *, rows=None, measure="yoshikawa")`` → :class:`CurvePlot`;
  ``plot_manipulability_map(chain, joints=(1, 2), q_fixed=None, *, rows=None, singular=True)`` → :class:`MapPlot`;
* ``plot_singularity_cost(chain, joint, q_singular, V, *, offsets=None, damping=0.05)`` → :class:`CostPlot`
  (what a singularity costs: ‖J⁻¹V‖ beside damped least squares and its velocity error, log scales);
* ``legend_beside(ax, where="right")``: a legend outside the axes (never over the drawing);
* ``sweep(chain, joint, values, q_fixed=None)``: a path through the joint space (the animation of such a path
  plays in the browser: :func:`kinlib.widgets.animate_singularity`).

Joints are numbered as in the book, 1…n (``joint=2`` is θ2).  Task rows are those of
:mod:`kinlib.taskspace`: names ``'wx','wy','wz','vx','vy','vz'`` (indices 0…5 of [ω_s; ṗ]) and presets
such as ``"planar"`` = (ω_z, ṗ_x, ṗ_y) or ``"linear"`` = (ṗ_x, ṗ_y, ṗ_z); by default a chain's task space
(:func:`kinlib.taskspace.default_task_rows`). The measures are those of :mod:`kinlib.manipulability`.

Modules: :mod:`~kinlib.plotting.common` (input checks, colours), :mod:`~kinlib.plotting.view` (axes, view
fitting, label placement), :mod:`~kinlib.plotting.primitives` (movable arrows, lines, text),
:mod:`~kinlib.plotting.artists` (the artist classes), :mod:`~kinlib.plotting.drawing` (the ``draw_*``
functions), :mod:`~kinlib.plotting.plots` (bar charts, directions, manipulability curve and map, sweeps),
:mod:`~kinlib.plotting.cost`.

>>> import kinlib.plotting as P
>>> from kinlib.robots import planar_offset_3r
>>> art = P.draw_chain(planar_offset_3r(1), [0, 0.5, -0.5]); type(art).__name__
'ChainArtist'
"""

from __future__ import annotations

from ..analysis.manipulability import manipulability_values
from ..analysis.taskspace import ROW_LABELS, ROW_NAMES, ROW_TEX, is_planar, task_row_indices
from .artists import ChainArtist, EllipseArtist, JointVelocitiesArtist, VelocityArtist
from .common import FRAME_COLORS, JOINT_COLORS, default_ranges
from .cost import CostPlot, plot_singularity_cost
from .drawing import (
    VelocityEllipses,
    draw_chain,
    draw_ellipse,
    draw_home,
    draw_joint_velocities,
    draw_velocity,
    draw_velocity_ellipse,
    draw_velocity_ellipses,
)
from .plots import (
    CurvePlot,
    MapPlot,
    draw_directions,
    held_span,
    plot_joint_contributions,
    plot_manipulability_curve,
    plot_manipulability_map,
    sweep,
)
from .view import legend_beside, new_axes, pi_ticks

__all__ = [
    "is_planar",
    "task_row_indices",
    "default_ranges",
    "manipulability_values",
    "draw_chain",
    "draw_home",
    "ChainArtist",
    "draw_velocity",
    "VelocityArtist",
    "draw_joint_velocities",
    "JointVelocitiesArtist",
    "draw_velocity_ellipse",
    "draw_velocity_ellipses",
    "VelocityEllipses",
    "EllipseArtist",
    "draw_ellipse",
    "draw_directions",
    "held_span",
    "plot_singularity_cost",
    "CostPlot",
    "plot_joint_contributions",
    "plot_manipulability_curve",
    "plot_manipulability_map",
    "CurvePlot",
    "MapPlot",
    "sweep",
    "new_axes",
    "legend_beside",
    "pi_ticks",
    "ROW_NAMES",
    "ROW_LABELS",
    "ROW_TEX",
    "JOINT_COLORS",
    "FRAME_COLORS",
]


def __getattr__(name: str):
    """Names that moved: the 5.2 animation now plays in the browser front end (``kinlib.widgets``); an old
    notebook that asks ``kinlib.plotting`` for it is told where it went instead of a bare AttributeError.

    >>> import kinlib.plotting as P
    >>> P.animate_singularity
    Traceback (most recent call last):
    ...
    AttributeError: kinlib.plotting.animate_singularity moved: use kinlib.widgets.animate_singularity(chain, path) (same arguments; it plays in the browser)
    """
    if name == "animate_singularity":
        raise AttributeError(
            "kinlib.plotting.animate_singularity moved: use kinlib.widgets.animate_singularity(chain, path) "
            "(same arguments; it plays in the browser)"
        )
    raise AttributeError(f"module 'kinlib.plotting' has no attribute {name!r}")
