"""An animation of a chain moving through a singular configuration: the arm with its velocity ellipse and a
status line, beside the manipulability along the path (plays in a static page via ``to_jshtml()``).

>>> import numpy as np
>>> from kinlib.robots import planar_3r
>>> from kinlib.plotting import sweep
>>> anim = animate_singularity(planar_3r(1, 1, 1), sweep(planar_3r(1, 1, 1), 2, [0.5, 0.0]))
>>> np.round(anim.values, 3)
array([0.479, 0.   ])
>>> html = anim.to_jshtml(); "<img" in html or "frames[" in html
True
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation

from .._backend import describe
from ..manipulability import manipulability_values, measure_label
from ..taskspace import default_task_rows, is_planar, rows_label, task_row_indices, task_rows
from .common import checked_numeric
from .drawing import draw_chain, draw_velocity_ellipse

__all__ = ["animate_singularity"]


def animate_singularity(
    chain,
    path,
    *,
    rows=None,
    ellipse_rows=None,
    params=None,
    interval=100,
    velocity_scale=0.5,
    figsize=(9, 4.2),
    dpi=72,
    title=None,
) -> FuncAnimation:
    """A FuncAnimation of ``chain`` following ``path`` (N×n configurations, e.g. from :func:`sweep`):
    left, the arm with its velocity ellipse (collapsing to a segment at a singular configuration) and a
    status line; right, the manipulability √det(J Jᵀ) of the task ``rows`` (default: the chain's task space,
    :func:`kinlib.taskspace.default_task_rows`) along the path with a moving marker. ``.values`` holds the
    manipulability per step. Play it in a static page with ``anim.to_jshtml()`` (``IPython.display.HTML``).

    >>> from kinlib.robots import planar_offset_3r
    >>> anim = animate_singularity(planar_offset_3r(1), np.zeros((3, 3)))
    >>> type(anim).__name__, anim.values.shape
    ('FuncAnimation', (3,))
    >>> html = anim.to_jshtml()   # plays in a static page
    """
    chain = checked_numeric(chain, params)
    P = np.asarray(path, float)
    if P.ndim != 2 or P.shape[1] != chain.n or P.shape[0] < 2:
        raise ValueError(
            f"path must be an array of shape (N, {chain.n}) with N ≥ 2 configurations of "
            f"{chain.name}, got {describe(path)}"
        )
    r = task_row_indices(rows, default=default_task_rows(chain))
    planar = is_planar(chain)
    fig = plt.figure(figsize=figsize, dpi=dpi)
    ax = fig.add_subplot(1, 2, 1, projection=None if planar else "3d")
    ax2 = fig.add_subplot(1, 2, 2)
    lo, hi = P.min(axis=0), P.max(axis=0)
    arm = draw_chain(
        chain,
        P[0],
        ax,
        ranges=[(a - 1e-6, b + 1e-6) for a, b in zip(lo, hi)],
        labels=True,
        title=title or f"{chain.name} along the path",
    )
    ell = draw_velocity_ellipse(ax, chain, P[0], rows=ellipse_rows, scale=velocity_scale)
    J = task_rows(chain.jacobian_geometric(P), r)
    w = manipulability_values(J, "yoshikawa")
    ic = manipulability_values(J, "inverse_condition")
    w_label = measure_label("yoshikawa", len(r), chain.n)
    s = np.arange(P.shape[0])
    ax2.plot(s, w, lw=2)
    ax2.set_xlabel("step along the path")
    ax2.set_ylabel(w_label)
    ax2.set_title(f"manipulability, rows ({rows_label(r, tex=True)})", fontsize=10)
    ax2.grid(True, lw=0.4, alpha=0.5)
    (mark,) = ax2.plot([0], [w[0]], "o", color="tab:red", ms=8)
    txt = (
        ax.text2D(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
        if not planar
        else ax.text(
            0.02,
            0.97,
            "",
            transform=ax.transAxes,
            va="top",
            fontsize=9,
            bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.8),
            zorder=9,
        )
    )
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
        txt.set_text(f"{w_label} = {w[k]:.3f}   {status(k)}")
        txt.set_color("tab:red" if status(k) else "k")
        return []

    frame(0)
    anim = FuncAnimation(fig, frame, frames=P.shape[0], interval=interval, blit=False)
    anim.values = w
    return anim
