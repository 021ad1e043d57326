"""An arm moving along a path through a singular configuration (problem 5.2's "watch it happen"), played in the
browser by the same front end as the explorer (:mod:`kinlib.widgets.frontend`): the arm, the velocity ellipses
with the task's orientation held and with every joint free, the blocked direction, the banner by the course's
one rule (exactly singular where a closed-form condition holds, "near" by :data:`kinlib.manipulability.NEAR_SINGULAR`)
and, beside the drawing, the manipulability along the path with a marker at the step shown. Play/pause, one step
back or forward, and a step slider (arrow keys, Home/End) scrub the path; an ``aria-live`` sentence says the step
and the state after a step (and, while it plays, whenever the state changes). Nothing is computed in the kernel
after it is built; the output carries a static ``image/png`` (the arm at the first step and w along the path,
drawn once by :mod:`kinlib.plotting`) for a viewer that runs no script, and prints whole in the PDF (the player's
buttons give way). HTML hooks: ``.kinlib-animation`` (its root; ``root.kinlib.go(k)`` shows step k), ``.kinlib-step``
(the step slider), ``.kinlib-play``, ``.kinlib-prev``, ``.kinlib-next``, ``.kinlib-cursor`` (the marker on the w chart),
and the explorer's ``.kinlib-status``, ``.kinlib-held``, ``.kinlib-live``, ``.kinlib-joint``, ``.kinlib-tool``.

>>> import numpy as np
>>> from kinlib.robots import planar_offset_3r
>>> path = [[np.pi / 4, t, np.pi / 4] for t in (-1.0, -np.pi / 4, -0.7, 0.0)]
>>> anim = animate_singularity(planar_offset_3r(1), path)
>>> anim.states, np.round(anim.values, 3)
(['regular', 'singular', 'near', 'regular'], array([0.301, 0.   , 0.121, 1.   ]))
"""

from __future__ import annotations

import base64
import io

import numpy as np

from .._backend import describe
from ..analysis.manipulability import manipulability_values, measure_label
from ..analysis.taskspace import rows_label, task_rows
from ..plotting.common import checked_numeric
from .explorer import Explorer

__all__ = ["animate_singularity", "SingularityAnimation"]


class SingularityAnimation(Explorer):
    """The animation made by :func:`animate_singularity` (an :class:`~kinlib.widgets.Explorer` without
    sliders, driven along ``path``): ``path`` (N×n), ``values`` (the manipulability √det(J Jᵀ) of the task
    ``rows`` at each step), ``states`` (each step's 'singular', 'near' or 'regular', by the explorer's rules,
    which the browser applies too), ``interval`` (ms per step while playing; ``dwell`` ms on a singular step; it stops
    at the last step unless ``loop``), ``spec``/``javascript`` (what the
    browser gets).

    >>> from kinlib.robots import planar_2r
    >>> anim = animate_singularity(planar_2r(1, 1), [[0.0, 0.5], [0.0, 0.0]])
    >>> sorted(anim._repr_mimebundle_()), anim.states
    (['application/javascript', 'image/png', 'text/plain'], ['regular', 'singular'])
    """

    entry = "animation"

    # fmt: off
    def __init__(self, chain, path, *, rows=None, ellipse_rows=None, params=None, interval=700, dwell=2500, loop=False,
                 velocity_scale=0.5, title=None, size=420, singular_budget=None, figsize=None, dpi=None):
        # fmt: on
        del figsize, dpi  # the matplotlib animation's keywords: accepted, no meaning here
        chain = checked_numeric(chain, params)
        P = np.asarray(path, float) if _is_numeric(path) else None
        if P is None or P.ndim != 2 or P.shape[1] != chain.n or P.shape[0] < 2 or not np.all(np.isfinite(P)):
            raise ValueError(
                f"path must be an array of shape (N, {chain.n}) with N ≥ 2 configurations of "
                f"{chain.name}, got {describe(path)}"
            )
        if not isinstance(interval, (int, float)) or isinstance(interval, bool) or not 10 <= interval <= 10000:
            raise ValueError(f"interval must be a number of milliseconds in [10, 10000], got {describe(interval)}")
        if not isinstance(dwell, (int, float)) or isinstance(dwell, bool) or not 0 <= dwell <= 60000:
            raise ValueError(f"dwell must be a number of milliseconds in [0, 60000], got {describe(dwell)}")
        if not isinstance(loop, bool):
            raise TypeError(f"loop must be True or False, got {describe(loop)}")
        self.path = P
        super().__init__(
            chain, q=P[0], rows=rows, ellipse_rows=ellipse_rows, velocity_scale=velocity_scale, size=size,
            title=title or f"{chain.name} along the path", show_velocity=False, rate_sliders=False,
            singular_budget=singular_budget,
        )  # fmt: skip
        self.q = P[0].copy()  # not clipped to the slider ranges: there are none
        self.interval = float(interval)
        self.spec["view"] = self._view(P, float(velocity_scale))  # the path, not every configuration
        J = task_rows(chain.jacobian_geometric(P), self.rows)
        self.values = manipulability_values(J, "yoshikawa")
        self.states = [self.update(q).state for q in P]
        self.update(P[0])
        self.spec.update(
            path=P.tolist(), interval=self.interval, dwell=float(dwell), loop=loop, wLabel=measure_label("yoshikawa", len(self.rows), chain.n),
            rowsLabel=rows_label(self.rows),
        )  # fmt: skip

    def _sample(self, N: int = 2000) -> np.ndarray:
        """The explorer's sample of the joint ranges and the whole path: w_max (the near rule's reference) is
        the largest manipulability over both, as :func:`~kinlib.manipulability.peak_manipulability` with ``extra``."""
        return np.vstack([super()._sample(N), self.path])

    def _static_png(self) -> bytes:
        """The arm at the first step with its ellipses, beside w along the path (for viewers that run no script)."""
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        from ..plotting import draw_chain, draw_velocity_ellipses

        fig = Figure(figsize=(8, 3.6) if self.answers else (4.4, 3.6), dpi=60)
        FigureCanvasAgg(fig)
        ax = fig.add_subplot(1, 2 if self.answers else 1, 1, projection=None if self.planar else "3d")
        lo, hi = self.path.min(axis=0), self.path.max(axis=0)
        draw_chain(self.chain, self.path[0], ax, ranges=[(a - 1e-6, b + 1e-6) for a, b in zip(lo, hi)],
                   labels=True, title=self.spec["title"])  # fmt: skip
        draw_velocity_ellipses(ax, self.chain, self.path[0], task=self.rows, rows=self.ellipse_rows,
                               scale=self.spec["velScale"])  # fmt: skip
        if not self.answers:  # the students' version: no manipulability along the path (it shows the singular step)
            fig.tight_layout()
            buf = io.BytesIO()
            fig.savefig(buf, format="png")
            return buf.getvalue()
        ax2 = fig.add_subplot(1, 2, 2)
        ax2.plot(np.arange(len(self.values)), self.values, lw=2)
        ax2.plot([0], [self.values[0]], "o", color="tab:red", ms=8)
        ax2.set_xlabel("step along the path")
        ax2.set_ylabel(self.spec["wLabel"])
        ax2.set_title(f"manipulability, rows ({rows_label(self.rows, tex=True)})", fontsize=10)
        ax2.grid(True, lw=0.4, alpha=0.5)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        return buf.getvalue()

    def _repr_mimebundle_(self, **kwargs):
        counts = f"{self.states.count('singular')} singular, {self.states.count('near')} near; " if self.answers else ""
        text = (
            f"animation of {self.chain.name} along a path of {len(self.path)} configurations "
            f"({counts}run the cell to play it)"
        )
        return {
            "application/javascript": self.javascript,
            "image/png": base64.b64encode(self._static_png()).decode("ascii"),
            "text/plain": text,
        }


def _is_numeric(path) -> bool:
    try:
        np.asarray(path, float)
    except (TypeError, ValueError):
        return False
    return True


def animate_singularity(chain, path, **kwargs) -> SingularityAnimation:
    """A :class:`SingularityAnimation` of ``chain`` following ``path`` (N×n configurations, e.g. from
    :func:`kinlib.plotting.sweep`); display it as the last expression of a cell. Keywords: ``rows`` (task rows of
    the manipulability and the state; default the chain's task space), ``ellipse_rows``, ``velocity_scale`` (display
    factor of the ellipses, 0.5), ``interval`` (ms per step when playing, 700: a pace a student can follow),
    ``dwell`` (ms the player stays on a singular step, 2500), ``loop`` (False: playing stops at the last step),
    ``title``, ``size`` (the drawing
    in pixels), ``params``, ``singular_budget``; ``figsize`` and ``dpi`` are accepted and ignored.

    >>> from kinlib.robots import planar_2r
    >>> animate_singularity(planar_2r(1, 1), [[0.0, 0.4], [0.0, 0.2], [0.0, 0.0]]).states
    ['regular', 'regular', 'singular']
    """
    return SingularityAnimation(chain, path, **kwargs)
