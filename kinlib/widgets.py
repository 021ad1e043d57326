"""Interactive explorers (ipywidgets; imported on demand: ``from kinlib import widgets``).

How the picture updates: each widget owns one matplotlib ``Figure`` that is *not* registered with
pyplot (so the inline backend never prints a second, static copy). A slider move moves the existing
artists (``ChainArtist.update`` etc., no figure rebuilt), renders the figure once with Agg and puts the
PNG, as a data URL, into an ``ipywidgets.Image(format="url")`` (a data URL loads ≈ 10 ms sooner than the Blob URL
of ``format="png"`` in Chromium). This works with the plain inline backend in JupyterLab, Notebook and
VS Code (no ipympl needed), and the last picture is kept in the saved widget state.

Velocities come from the **geometric Jacobian** J(θ) = blockdiag(R, R) J_b, rows [ω_s; ṗ].
Singularity test: the task rows J_r (m×n) of J at θ, by default the arm's task space
(:func:`kinlib.taskspace.default_task_rows`: (ω_z, ṗ_x, ṗ_y) for a planar arm with ≥ 3 joints, (ṗ_x, ṗ_y)
with fewer; all six rows for a spatial arm with ≥ 6 joints, (ṗ_x, ṗ_y, ṗ_z) with fewer); with
σ_max ≥ … ≥ σ_min its min(m, n) singular values and w = √det(J_r J_rᵀ) (√det(J_rᵀ J_r) when fewer joints
than rows) the manipulability (both from :mod:`kinlib.manipulability`), the configuration is called

* ``"singular"`` when the rank of J_r (the singular values above ``tol`` · σ_max, default 10⁻⁶) is below
  min(m, n): J_r loses rank,
* ``"near"`` when w < ``near`` · w_max (the course's one rule, :data:`kinlib.manipulability.NEAR_SINGULAR`
  = 0.1, decided by :func:`kinlib.manipulability.singularity_state`; w_max = the largest w over a fixed sample
  of the slider ranges, :func:`kinlib.manipulability.peak_manipulability`: a relative, unit-free threshold),
* ``"regular"`` otherwise.

What the picture shows agrees with the status: when the task has orientation rows besides the drawn ṗ
rows (planar: (ω_z, ṗ_x, ṗ_y)), the main (green) ellipse is the tool velocities reachable **with the
orientation held**, {ṗ = J_ṗ θ̇ : J_ω θ̇ = 0, ‖θ̇‖ ≤ 1} (:func:`kinlib.manipulability.velocity_ellipsoid` with
``hold``): since rank J_r = rank J_ω + rank(J_ṗ N) (N a basis of null(J_ω)), it collapses to a segment
exactly at the singular configurations where J_ω keeps its rank; the ellipse of ṗ with every joint free
(which need not flatten) is a light dashed outline. At and near a singularity a red dashed line through the
tool marks the direction it cannot move (the thin axis of the main ellipse: its left null direction). The
readout's det J is exactly "0" when the rank test says singular. HTML hooks (for browser tests): the status
is ``<div class='kinlib-status' data-state='singular|near|regular'>``, the readout holds
``<span class='kinlib-det'>`` and ``<span class='kinlib-held'>`` (the held ellipse's semi-axes). Displayed,
an explorer also carries a static ``image/png`` (:func:`kinlib.widgets_render.display_bundle`).

Speed: the static part of the figure (axes, grid, ticks, legend, {s}) is rendered once and cached;
a slider move restores it, draws only the moving artists (blitting with Agg) and encodes an 8-bit PNG
(palette made once; :class:`kinlib.widgets_render.Blitter`); labels keep their spots while they fit.

>>> from kinlib.robots import planar_2r
>>> ex = explorer(planar_2r(1, 1), q=[0.3, 0.0])
>>> ex.state, ex.update([0.3, 1.0]).state
('singular', 'regular')
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping

import ipywidgets as W
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ._backend import describe
from .manipulability import (
    NEAR_SINGULAR,
    SINGULAR_RTOL,
    manipulability_values,
    peak_manipulability,
    singular_values,
    singularity_state,
    strongest_joints,
)
from .plotting import (
    JOINT_COLORS,
    default_ranges,
    draw_chain,
    draw_joint_velocities,
    draw_velocity,
    draw_velocity_ellipses,
)
from .plotting.common import as_configuration, checked_numeric, theta_tex
from .plotting.primitives import add_line, set_line
from .taskspace import ROW_LABELS, ROW_TEX, default_task_rows, is_planar, rows_label, task_row_indices, task_rows
from .widgets_render import Blitter, data_url, display_bundle, new_figure, render_png

__all__ = [
    "explorer",
    "Explorer",
    "config_picker",
    "ConfigPicker",
    "classify",
    "weakest_direction",
    "format_det",
    "format_lengths",
]


def classify(
    J_rows: np.ndarray, tol: float = SINGULAR_RTOL, near: float = NEAR_SINGULAR, w_max: float | None = None
) -> dict:
    """Numbers for the readout of task rows J_r (m×n), from :mod:`kinlib.manipulability`: ``rank`` (the
    singular values above tol · σ_max), ``full_rank`` = min(m, n), ``det`` (square only), ``manipulability``
    w (√det(J Jᵀ), or √det(Jᵀ J) when n < m), ``ratio`` σ_min/σ_max, ``relative`` = w / w_max and ``state``:
    'singular' when rank < min(m, n), 'near' when w / w_max < near (w_max: the largest w over the joint
    ranges; :func:`kinlib.manipulability.singularity_state`; without w_max only 'singular' or 'regular'),
    else 'regular'.

    >>> import numpy as np
    >>> info = classify(np.array([[1.0, 1.0], [0.0, 0.0]]))
    >>> info["state"], info["rank"], info["full_rank"]
    ('singular', 1, 2)
    >>> classify(np.eye(2))["state"]
    'regular'
    """
    J = np.asarray(J_rows, float)
    s = singular_values(J)
    smax = float(s[0])
    full = min(J.shape)
    rank = int(np.sum(s > tol * smax)) if smax > 0 else 0
    ratio = float(manipulability_values(J, "inverse_condition"))
    w = float(manipulability_values(J, "yoshikawa"))
    rel = w / w_max if w_max else None
    if rank < full:
        state = "singular"
    else:
        state = singularity_state(J, w_max, near, tol) if w_max else "regular"
        state = "regular" if state == "singular" else state  # the rank test above decides singular
    return {
        "rank": rank,
        "full_rank": full,
        "det": float(manipulability_values(J, "det")) if J.shape[0] == J.shape[1] else None,
        "manipulability": w,
        "ratio": ratio,
        "relative": rel,
        "state": state,
    }


def weakest_direction(lengths, directions) -> tuple[np.ndarray, float]:
    """(u, ratio): the unit direction u in which the ellipsoid with semi-axes ``lengths`` (k,) along the unit
    columns of ``directions`` (m×k) is thinnest, and σ_min/σ_max (0 when k < m: then u is orthogonal to
    every column, a direction the map never reaches). At a singular configuration u spans the left null
    space of the map: the direction the tool cannot move.

    >>> u, r = weakest_direction(np.array([2.0, 0.0]), np.eye(2)); u.tolist(), r
    ([0.0, 1.0], 0.0)
    """
    s, U = np.asarray(lengths, float).reshape(-1), np.asarray(directions, float)
    m, k = U.shape
    if k < m:
        Q = np.linalg.svd(U, full_matrices=True)[0] if k else np.eye(m)
        return Q[:, k], 0.0
    i = int(np.argmin(s))
    top = float(s.max())
    return U[:, i], (float(s[i]) / top if top > 0 else 0.0)


def format_det(det: float, singular: bool) -> str:
    """det J for the readout: exactly "0" when the rank test says singular (never +0.0000 or −0.0000),
    else signed with 4 significant digits.

    >>> format_det(-3.2e-17, True), format_det(0.70710678, False), format_det(-1.5e-5, False)
    ('0', '+0.7071', '-1.5e-05')
    """
    return "0" if singular else f"{det:+.4g}"


def format_lengths(lengths, tol: float = 1e-6) -> str:
    """Semi-axes for the readout, 3 significant digits; those below ``tol`` · the largest are exactly "0".

    >>> format_lengths([2.7909, 1.0283]), format_lengths([1.7155, 4e-17])
    ('2.79, 1.03', '1.72, 0')
    """
    s = np.asarray(lengths, float).reshape(-1)
    top = float(s.max()) if s.size else 0.0
    return ", ".join("0" if x <= tol * top or x == 0 else f"{x:.3g}" for x in s) if s.size else "0"


def _slider_label(chain, i: int, rate: bool = False) -> str:
    k = chain.joint_types[i]
    base = f"θ{i + 1}"
    if rate:
        return f"θ̇{i + 1} ({'rad/s' if k == 'R' else 'len/s'})"
    return f"{base} ({'rad' if k == 'R' else 'len'})"


class Explorer(W.VBox):
    """A slider per joint (θ_i in rad for revolute, length units for prismatic joints), optional sliders
    for the joint rates θ̇_i, and one figure: the arm at θ, the end-effector velocity ṗ = J_ṗ θ̇ as an
    arrow, the velocity ellipse, with a readout of det J_r (square task rows) or √det(J_r J_rᵀ), the
    ratio σ_min/σ_max and a plain-words status.

    When the task rows include orientation rows besides the drawn ṗ rows, the main ellipse is ṗ with those
    rows held (``held_ellipse``, ``hold`` = their indices) and ``ellipse`` (ṗ, all joints free) a dashed
    outline; ``cannot_move`` (a red dashed line, ``cannot_move_direction`` its unit vector or None) shows
    where the tool cannot move, at and near a singular configuration (see the module text).

    State for tests and scripts: ``sliders``, ``rate_sliders``, ``status`` (HTML widget: contains
    "singular" exactly when at or near a singular configuration; ``<div class='kinlib-status'
    data-state=…>``), ``readout`` (HTML, with ``kinlib-det`` and ``kinlib-held`` spans), ``image``
    (the Image widget; its value is a data URL of ``picture``, the rendered PNG or JPEG), ``fig``/``ax``, ``arm``/``velocity``/``ellipse``/``held_ellipse`` artists, ``q``,
    ``qdot``, ``info`` (the last :func:`classify` result), ``update(q=None, qdot=None)``.

    >>> from kinlib.robots import planar_offset_3r
    >>> ex = Explorer(planar_offset_3r(1), q=[0.3, 0.7, 0.2])
    >>> ex.rows, ex.state
    ((2, 3, 4), 'regular')
    """

    # the options grouped by what they set: configuration, task space, drawing, readout, image
    # fmt: off
    def __init__(self, chain, *, q=None, qdot=None, params=None, ranges=None, step=None, continuous_update=True,
                 rows=None, ellipse_rows=None, tol=SINGULAR_RTOL, near=NEAR_SINGULAR,
                 show_ellipse=True, show_velocity=True, rate_sliders=True, velocity_scale=0.5, title=None,
                 show_maximum=True, figsize=(5.2, 5.0), dpi=80, image_format="png"):
        # fmt: on
        if image_format not in ("png", "jpeg"):
            raise ValueError(f"image_format must be 'png' or 'jpeg', got {image_format!r}")
        chain = checked_numeric(chain, params)
        self.chain = chain
        n = chain.n
        self.rows = task_row_indices(rows, default=default_task_rows(chain))
        self.tol, self.near = float(tol), float(near)
        self.show_maximum = bool(show_maximum)  # False: no w_max in the text (a problem may ask for it)
        self.ranges = default_ranges(chain, ranges)
        q0 = as_configuration(chain, q)
        qd0 = as_configuration(chain, qdot, "qdot") if qdot is not None else np.ones(n)
        for i, (lo, hi) in enumerate(self.ranges):
            q0[i] = min(max(q0[i], lo), hi)
        self.q, self.qdot = q0, qd0
        self.planar = is_planar(chain)
        self.fig, self.ax = new_figure(figsize, dpi, not self.planar)
        self.arm = draw_chain(chain, q0, self.ax, ranges=self.ranges, title=title or chain.name)
        ell_rows = task_row_indices(ellipse_rows) if ellipse_rows is not None else ((3, 4) if self.planar else (3, 4, 5))
        self.ellipse_rows = ell_rows
        self.held_ellipse = self.ellipse = self.cannot_move = self.cannot_move_direction = None
        self.hold = ()
        if show_ellipse:  # the ṗ ellipse with the task's orientation held (it flattens where the task is singular)
            ells = draw_velocity_ellipses(
                self.ax, chain, q0, task=self.rows, rows=ell_rows, scale=velocity_scale,
                label_suffix=f" (×{velocity_scale:g})",
            )  # fmt: skip
            self.held_ellipse, self.ellipse, self.hold = ells
        main = self.held_ellipse or self.ellipse
        if main is not None:
            d = len(ell_rows)
            self.cannot_move = add_line(
                self.ax, np.zeros((3, 2)), color="tab:red", lw=2.0, ls=(0, (4, 2)), zorder=6,
                label="tool cannot move" + (f" ({rows_label(self.hold, tex=True)} held)" if self.hold else ""),
            )  # fmt: skip
            self._cannot_len = 1.15 * velocity_scale * max(float(np.max(main.semi_axes)), 1e-9) if d else 0.0
            self._cannot_len = max(self._cannot_len, 0.25 * self.arm.scale)
        self.velocity = (
            draw_velocity(
                self.ax, chain, q0, qd0, scale=velocity_scale, label=rf"$\dot p = J\,\dot\theta$ (×{velocity_scale:g})"
            )
            if show_velocity
            else None
        )
        if show_ellipse or show_velocity:
            self.ax.legend(loc="upper left", fontsize=7, framealpha=0.8)
        self.fig.tight_layout()

        self.sliders = []
        for i, (lo, hi) in enumerate(self.ranges):
            st = step if step is not None else (math.pi / 180 if chain.joint_types[i] == "R" else (hi - lo) / 200)
            self.sliders.append(
                W.FloatSlider(
                    value=q0[i],
                    min=lo,
                    max=hi,
                    step=st,
                    description=_slider_label(chain, i),
                    readout_format=".3f",
                    continuous_update=continuous_update,
                    style={"description_width": "70px"},
                    layout=W.Layout(width="330px"),
                )
            )
        self.rate_sliders = []
        if rate_sliders and show_velocity:
            for i in range(n):
                self.rate_sliders.append(
                    W.FloatSlider(
                        value=qd0[i],
                        min=-2.0,
                        max=2.0,
                        step=0.05,
                        description=_slider_label(chain, i, rate=True),
                        readout_format=".2f",
                        continuous_update=continuous_update,
                        style={"description_width": "70px"},
                        layout=W.Layout(width="330px"),
                    )
                )
        moving = (
            self.arm.artists
            + (self.ellipse.artists if self.ellipse is not None else [])
            + (self.held_ellipse.artists if self.held_ellipse is not None else [])
            + ([self.cannot_move] if self.cannot_move is not None else [])
            + (self.velocity.artists if self.velocity is not None else [])
        )
        self._blit = Blitter(self.fig, moving, image_format)
        self.w_max = self._max_manipulability()
        self.status = W.HTML(value="")
        self.readout = W.HTML(value="")
        self.picture_format, self.picture = image_format, b""  # the encoded picture; the widget shows it as a data URL
        self.image = W.Image(format="url", layout=W.Layout(width=f"{int(figsize[0] * dpi)}px"))
        self._hold = False
        for s in self.sliders + self.rate_sliders:
            s.observe(self._on_change, names="value")
        controls = [W.HTML("<b>joint positions</b>"), *self.sliders]
        if self.rate_sliders:
            controls += [W.HTML("<b>joint rates</b> (for the ṗ arrow)"), *self.rate_sliders]
        controls += [self.readout, self.status]
        super().__init__([W.HBox([W.VBox(controls, layout=W.Layout(width="350px")), self.image])])
        self.refresh()

    # -- reactions ----------------------------------------------------------------------------------
    def _on_change(self, change):
        if not self._hold:
            self.refresh()

    def update(self, q=None, qdot=None):
        """Set the sliders (joint values ``q``, rates ``qdot``) and redraw once."""
        self._hold = True
        try:
            if q is not None:
                for s, v in zip(self.sliders, as_configuration(self.chain, q)):
                    s.value = float(v)
            if qdot is not None:
                qd = as_configuration(self.chain, qdot, "qdot")
                if self.rate_sliders:
                    for s, v in zip(self.rate_sliders, qd):
                        s.value = float(v)
                else:
                    self.qdot = qd
        finally:
            self._hold = False
        self.refresh()
        return self

    def refresh(self):
        """Read the sliders, move the artists, update the readout and re-render the picture."""
        q = np.array([s.value for s in self.sliders], float)
        if self.rate_sliders:
            self.qdot = np.array([s.value for s in self.rate_sliders], float)
        self.q = q
        self.arm.update(q)
        Jg = self.chain.jacobian_geometric(q)
        p = self.arm.tool_position
        if self.ellipse is not None:
            self.ellipse.update(q, Jg, p)
        if self.held_ellipse is not None:
            self.held_ellipse.update(q, Jg, p)
        if self.velocity is not None:
            self.velocity.update(q, self.qdot)
        self.info = info = classify(task_rows(Jg, self.rows), self.tol, self.near, self.w_max)
        self._show_cannot_move(info, p)
        for w, v in ((self.readout, self._readout_html(info)), (self.status, self._status_html(info))):
            if w.value != v:  # an unchanged text sends no message to the browser
                w.value = v
        self.picture = self._blit.render()
        self.image.value = data_url(self.picture, self.picture_format)

    def _show_cannot_move(self, info, p):
        """The red dashed line through the tool along the direction it cannot move (the smallest axis u_min of
        the main ellipse — with the orientation held, if the task has orientation rows — i.e. the left-null
        direction of that map within the ṗ space), shown when the state is 'singular' or 'near' and that
        ellipse is thin (σ_min < 0.35 σ_max): the flattening is in ṗ, not only in the held rows."""
        if self.cannot_move is None:
            return
        main = self.held_ellipse or self.ellipse
        u, ratio = weakest_direction(main.semi_axes, main.directions)
        show = info["state"] in ("singular", "near") and ratio < 0.35
        self.cannot_move.set_visible(show)
        if show:
            d = u.size
            c = p[:d]
            seg = np.column_stack([c - self._cannot_len * u, c + self._cannot_len * u])
            set_line(self.cannot_move, np.vstack([seg, np.zeros((3 - d, 2))]))
        self.cannot_move_direction = u if show else None

    def _max_manipulability(self) -> float:
        """The largest √det(J_r J_rᵀ) over a fixed sample of the slider ranges (the reference for "near")."""
        return peak_manipulability(self.chain, self.rows, self.ranges, extra=self.q)

    def _readout_html(self, info) -> str:
        esc = html.escape
        rows = rows_label(self.rows)
        lines = [esc(f"task rows of J: ({rows})")]
        if info["det"] is not None:
            det = format_det(info["det"], info["state"] == "singular")
            lines.append(f"det J = <span class='kinlib-det'>{det}</span>")
        m, n = len(self.rows), self.chain.n
        sing = info["state"] == "singular"  # the rank test decides: then w, σ_min/σ_max and det are exactly 0
        w = "0" if sing else f"{info['manipulability']:.4f}"
        lines.append(esc(f"manipulability {'√det(JᵀJ)' if n < m else '√det(JJᵀ)'} = {w}"))
        if self.show_maximum:
            share = "0" if sing else f"{100 * info['relative']:.1f}"
            lines.append(esc(f"  = {share}% of its maximum {self.w_max:.4f}"))
        ratio = "0" if sing else f"{info['ratio']:.4f}"
        lines.append(esc(f"σ_min/σ_max = {ratio}, rank {info['rank']} of {info['full_rank']}"))
        if self.held_ellipse is not None:
            held = format_lengths(self.held_ellipse.semi_axes, self.tol)
            lines.append(
                esc(f"ṗ ellipse, {rows_label(self.hold)} held: semi-axes ")
                + f"<span class='kinlib-held'>{esc(held)}</span>"
            )
            lines.append(esc(f"ṗ ellipse, all joints free: {format_lengths(self.ellipse.semi_axes, self.tol)}"))
        elif self.ellipse is not None:
            lines.append(esc(f"velocity ellipse semi-axes: {format_lengths(self.ellipse.semi_axes, self.tol)}"))
        if self.velocity is not None:
            v = self.velocity.velocity
            lines.append(esc("ṗ = (" + ", ".join(f"{x:+.3f}" for x in v) + ")"))
        return "<div class='kinlib-readout' style='font-family:monospace;font-size:12px'>" + "<br>".join(lines) + "</div>"

    def _status_html(self, info) -> str:
        if info["state"] == "singular":
            where = (
                f"with {rows_label(self.hold)} held the ṗ ellipse is "
                + ("a segment" if self.planar else "flat")
                + ": the tool cannot move along the red dashed line"
                if self.held_ellipse is not None and self.cannot_move_direction is not None
                else "some end-effector velocities are impossible here"
            )
            msg, color = (
                f"SINGULAR configuration: J loses rank (rank {info['rank']} of {info['full_rank']}); {where}",
                "#b00020",
            )
        elif info["state"] == "near":
            share = f" (manipulability {100 * info['relative']:.1f}% of its maximum)" if self.show_maximum else ""
            msg, color = f"near a singular configuration{share}: some directions need large joint rates", "#b36b00"
        else:
            msg, color = f"regular configuration: full rank {info['rank']}", "#1b5e20"
        return (
            f"<div class='kinlib-status' data-state='{info['state']}'>"
            f"<b style='color:{color}'>{html.escape(msg)}</b></div>"
        )

    @property
    def state(self) -> str:
        """'singular', 'near' or 'regular' at the current sliders."""
        return self.info["state"]

    def _repr_mimebundle_(self, **kwargs):
        """The live widget view, plus a static ``image/png`` of the current picture and a one-line text
        (see :func:`kinlib.widgets_render.display_bundle`): a notebook opened without a widget manager shows
        the picture, not ``Explorer(children=…``."""
        png = self.picture if self.picture_format == "png" else render_png(self.fig)
        q = ", ".join(f"{x:.3f}" for x in self.q)
        text = f"explorer of {self.chain.name} at θ = ({q}): {self.state} configuration (run the cell for sliders)"
        return display_bundle(super()._repr_mimebundle_(**kwargs), png, text)


def explorer(chain, **kwargs) -> Explorer:
    """An :class:`Explorer` for ``chain``: display it as the last expression of a cell.

    Keywords: ``q``/``qdot`` (initial joint values/rates; rates default to 1), ``rows`` (task rows for
    det J, manipulability and the status; default (ω_z, ṗ_x, ṗ_y) planar, all six otherwise), ``ranges``
    (slider ranges, list or {joint number: (lo, hi)}; default ±π and ±half the reach for prismatic
    joints), ``show_ellipse``, ``show_velocity``, ``rate_sliders``, ``ellipse_rows``, ``velocity_scale``
    (display factor of the ṗ arrow and the ellipse, 0.5), ``tol``/``near`` (status thresholds),
    ``show_maximum`` (False: the text never states the largest manipulability, e.g. in a problem that asks for it),
    ``params`` ({"L": 1} for a symbolic chain), ``figsize``, ``dpi``, ``step`` (slider step; π/180 for
    angles so that multiples of 1° such as −π/4 are reachable), ``continuous_update``, ``title``,
    ``image_format`` ('png' or the faster 'jpeg').

    >>> from kinlib.robots import planar_2r
    >>> ex = explorer(planar_2r(1, 1), q=[0.5, 0.0])   # stretched out: (ṗ_x, ṗ_y) lose rank
    >>> ex.rows, ex.state, ex.info["rank"]
    ((3, 4), 'singular', 1)
    """
    return Explorer(chain, **kwargs)


class ConfigPicker(W.VBox):
    """Named configurations (problem 4.1): buttons choose one; the figure shows the arm with each joint's
    velocity arrow at the tool (column i of J_ṗ, i.e. ṗ for θ̇_i = 1) and a bar chart of the chosen
    row's joint contributions J[row, i]; the table below names the joint with the largest |J[row, i]|
    (ties within 10⁻⁹ relative are reported as ties).

    ``rows``: one row for all configurations ('vx', 'vy', …) or a dict {name: row}.
    State: ``buttons``, ``table`` (HTML), ``image`` (its value a data URL of the PNG ``picture``), ``contributions`` (n values of the current row),
    ``best`` (1-based joints with the largest |contribution|, from
    :func:`kinlib.manipulability.strongest_joints`), ``select(name)``.

    >>> from kinlib.robots import planar_3r
    >>> import math
    >>> cp = ConfigPicker(planar_3r(1, 1, 1), {"home": [0, 0, 0], "c": [math.pi / 2, -math.pi / 8, -math.pi / 2]},
    ...                   rows="vy")
    >>> cp.best, cp.select("c").best   # problem 4.1 (c): joints 1 and 2 tie
    ((1,), (1, 2))
    """

    def __init__(
        self, chain, configs: Mapping, *, rows="vx", params=None, scale=1.0, figsize=(9.5, 4.3), dpi=80, title=None
    ):
        chain = checked_numeric(chain, params)
        self.chain = chain
        if not isinstance(configs, Mapping) or not configs:
            raise TypeError(f"configs must be a non-empty dict {{name: q}}, got {describe(configs)}")
        self.configs = {str(k): as_configuration(chain, v, f"configs[{k!r}]") for k, v in configs.items()}
        if isinstance(rows, Mapping):
            missing = set(self.configs) - set(map(str, rows))
            if missing:
                raise ValueError(f"rows must give a row for every configuration; missing {sorted(missing)}")
            self.rows = {str(k): self._one_row(v) for k, v in rows.items()}
        else:
            r = self._one_row(rows)
            self.rows = dict.fromkeys(self.configs, r)
        planar = is_planar(chain)
        self.fig = Figure(figsize=figsize, dpi=dpi)
        FigureCanvasAgg(self.fig)
        self.ax = self.fig.add_subplot(1, 2, 1, projection=None if planar else "3d")
        self.ax_bar = self.fig.add_subplot(1, 2, 2)
        name0 = next(iter(self.configs))
        q0 = self.configs[name0]
        # the view: every configuration's skeleton and its joint-velocity arrow tips, padded
        pts = []
        for qq in self.configs.values():
            sk = chain.skeleton(qq)
            J = chain.jacobian_geometric(qq)
            pts += [sk, sk[:, -1:] + scale * J[3:, :]]
        pts = np.hstack(pts)
        d = 2 if planar else 3
        c = 0.5 * (pts.min(1) + pts.max(1))[:d]
        h = 0.5 * float(np.max(pts.max(1) - pts.min(1))) * 1.15 + 1e-9
        self.arm = draw_chain(chain, q0, self.ax, limits=np.stack([c - h, c + h], axis=1), title=title or chain.name)
        self.arrows = draw_joint_velocities(self.ax, chain, q0, scale=scale)
        n = chain.n
        self.bars = self.ax_bar.bar(np.arange(1, n + 1), np.zeros(n), color=[JOINT_COLORS[i % 10] for i in range(n)])
        self.bar_texts = [self.ax_bar.text(i + 1, 0, "", ha="center", va="bottom", fontsize=9) for i in range(n)]
        self.ax_bar.axhline(0, color="k", lw=0.8)
        self.ax_bar.set_xticks(np.arange(1, n + 1), [theta_tex(i + 1, dot=True) for i in range(n)])
        self.ax_bar.grid(True, axis="y", lw=0.4, alpha=0.5)
        # a common y-range over all configurations, so bars compare across them
        vals = [chain.jacobian_geometric(qq)[self.rows[k]] for k, qq in self.configs.items()]
        top = max(float(np.max(np.abs(v))) for v in vals) or 1.0
        self.ax_bar.set_ylim(-1.2 * top, 1.2 * top)
        self.fig.tight_layout()
        self.buttons = W.ToggleButtons(options=list(self.configs), value=name0, description="configuration")
        self.table = W.HTML()
        self.picture = b""  # the PNG; the widget shows it as a data URL
        self.image = W.Image(format="url", layout=W.Layout(width=f"{int(figsize[0] * dpi)}px"))
        self.buttons.observe(lambda ch: self.select(ch["new"]), names="value")
        super().__init__([self.buttons, self.image, self.table])
        self.select(name0)

    def _repr_mimebundle_(self, **kwargs):
        """The live widget view, plus a static ``image/png`` of the current picture and a one-line text."""
        text = f"configuration picker for {self.chain.name}: {self.name} (run the cell for the buttons)"
        return display_bundle(super()._repr_mimebundle_(**kwargs), self.picture, text)

    @staticmethod
    def _one_row(r) -> int:
        idx = task_row_indices(r)
        if len(idx) != 1:
            raise ValueError(f"rows must name one row per configuration (e.g. 'vx'), got {describe(r)}")
        return idx[0]

    def select(self, name: str):
        """Show configuration ``name``."""
        if name not in self.configs:
            raise ValueError(f"unknown configuration {name!r}; choose from {list(self.configs)}")
        if self.buttons.value != name:
            self.buttons.value = name  # the observer calls select again
            return self
        q, row = self.configs[name], self.rows[name]
        self.name = name
        self.arm.update(q)
        self.arrows.update(q)
        c = self.chain.jacobian_geometric(q)[row]
        self.contributions = c
        for b, t, v in zip(self.bars, self.bar_texts, c):
            b.set_height(v)
            t.set_position((t.get_position()[0], v))
            t.set_va("bottom" if v >= 0 else "top")
            t.set_text(f"{v:+.3f}")
        lab = ROW_LABELS[row]
        self.ax_bar.set_title(f"{name}: {ROW_TEX[row]} for each " + r"$\dot\theta_i = 1$", fontsize=10)
        best = strongest_joints(c)
        self.best = best if isinstance(best, tuple) else (best,)
        cells = "".join(
            f"<td style='padding:0 8px'>{'<b>' if i + 1 in self.best else ''}{v:+.4f}"
            f"{'</b>' if i + 1 in self.best else ''}</td>"
            for i, v in enumerate(c)
        )
        heads = "".join(f"<th style='padding:0 8px'>θ̇{i + 1}</th>" for i in range(len(c)))
        who = (
            f"joint {self.best[0]}"
            if len(self.best) == 1
            else "a tie between joints " + " and ".join(map(str, self.best))
        )
        self.table.value = (
            f"<table><tr><th>{html.escape(lab)} per unit rate</th>{heads}</tr>"
            f"<tr><td>θ = ({', '.join(f'{x:.4f}' for x in q)})</td>{cells}</tr></table>"
            f"<div>largest |{html.escape(lab)}|: {who}</div>"
        )
        self.picture = render_png(self.fig)
        self.image.value = data_url(self.picture)
        return self


def config_picker(chain, configs: Mapping, **kwargs) -> ConfigPicker:
    """A :class:`ConfigPicker` (keywords: rows, params, scale, figsize, dpi, title).

    >>> from kinlib.robots import planar_3r
    >>> config_picker(planar_3r(1, 1, 1), {"a": [0.1, 0.2, 0.3]}).contributions.shape
    (3,)
    """
    return ConfigPicker(chain, configs, **kwargs)
