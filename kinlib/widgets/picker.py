"""The configuration picker (problem 4.1): named configurations chosen with buttons (ipywidgets); the figure
shows the arm with each joint's velocity arrow at the tool (column i of J_ṗ of the **geometric Jacobian**
J = blockdiag(R, R) J_b, rows [ω_s; ṗ]) and a bar chart of the chosen row's joint contributions. A button press
draws the (few) configurations' figure once with matplotlib (:mod:`kinlib.plotting`) and sends it as a PNG data
URL; the picker also carries a static ``image/png`` for viewers without a widget manager.
"""

from __future__ import annotations

import html
from collections.abc import Mapping

import ipywidgets as W
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from .._backend import describe
from ..manipulability import strongest_joints
from ..plotting import JOINT_COLORS, draw_chain, draw_joint_velocities
from ..plotting.common import as_configuration, checked_numeric, theta_tex
from ..taskspace import ROW_LABELS, ROW_TEX, is_planar, task_row_indices
from .render import data_url, display_bundle, render_png

__all__ = ["config_picker", "ConfigPicker"]


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
        # each button as wide as its label (ipywidgets' fixed 148 px cut "(a) θ = (−π/8, π/4, π/8)" short)
        self.buttons = W.ToggleButtons(
            options=list(self.configs), value=name0, description="configuration", style={"button_width": "auto"}
        )
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
