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

import base64
import io
import re
import struct
import uuid

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation

from .._backend import describe
from ..manipulability import manipulability_values, measure_label, peak_manipulability, singularity_state
from ..taskspace import default_task_rows, is_planar, rows_label, task_row_indices, task_rows
from .common import checked_numeric, default_ranges
from .drawing import draw_chain, draw_velocity_ellipses

__all__ = ["animate_singularity", "SingularityAnimation", "first_frame_html"]

_FRAME0 = re.compile(r'frames\[0\] = "(data:image/(png|jpeg);base64,(?:[^"\\]|\\.|\\\n)*)"')
_START = re.compile(r"setTimeout\(function\(\) \{\s*(anim\w+ = new Animation\([^;]*\);)\s*\}, 0\);")
_FONT_AWESOME = re.compile(r"<link[^>]*font-awesome[^>]*>")


def _player_html(frames: list, fps: float, mode: str) -> str:
    """matplotlib's jshtml player (its HTMLWriter template) around PNG frames given as bytes."""
    from matplotlib._animation_data import DISPLAY_TEMPLATE, JS_INCLUDE, STYLE_INCLUDE

    fill = "\n" + "".join(
        f'  frames[{i}] = "data:image/png;base64,{base64.b64encode(f).decode("ascii")}"\n' for i, f in enumerate(frames)
    )
    modes = dict(once_checked="", loop_checked="", reflect_checked="")
    modes[mode + "_checked"] = "checked"
    return (
        JS_INCLUDE
        + STYLE_INCLUDE
        + DISPLAY_TEMPLATE.format(
            id=uuid.uuid4().hex, Nframes=len(frames), fill_frames=fill, interval=int(1000 // fps), **modes
        )
    )


def first_frame_html(html: str) -> str:
    """matplotlib's ``to_jshtml()`` player made to show frame 0 at once: the ``<img>`` starts with frame 0
    as its ``src`` and its pixel size (no blank, zero-height picture before the script runs, nor when
    scripts do not run: an untrusted notebook, a static page), and the player starts once its
    ``<img>`` is in the page (JupyterLab may render an output before attaching it; matplotlib's
    ``setTimeout(…, 0)`` then finds no element and the player stays blank until clicked; the new start
    statement begins with ";" as the line before it, ``frames[N-1] = "…"``, has none).
    Unchanged if the HTML is not in the expected form.

    >>> first_frame_html('<img id="_anim_imgX">')   # no frames: unchanged
    '<img id="_anim_imgX">'
    """
    m = _FRAME0.search(html)
    if m is None:
        return html
    src = m.group(1).replace("\\\n", "")
    size = ""
    try:
        head = base64.b64decode(src.split(",", 1)[1][:64] + "==")
        if head[:8] == b"\x89PNG\r\n\x1a\n":
            w, h = struct.unpack(">II", head[16:24])
            size = f' width="{w}" height="{h}"'
    except (ValueError, struct.error):
        pass
    html = re.sub(r'<img id="(_anim_img\w+)">', lambda k: f'<img id="{k.group(1)}" src="{src}"{size}>', html, count=1)
    return _START.sub(
        lambda k: (
            ";(function start(tries) {\n"
            "        if (!document.getElementById(img_id) && tries < 600) { setTimeout(function() { start(tries + 1); }, 50);"
            " return; }\n        " + k.group(1) + "\n    })(0);"
        ),
        html,
        count=1,
    )


class SingularityAnimation(FuncAnimation):
    """The FuncAnimation made by :func:`animate_singularity`: ``to_jshtml()`` shows frame 0 at once
    (:func:`first_frame_html`), and displayed as a cell's value it gives the player (``text/html``, without
    the Font Awesome link to a CDN: JupyterLab ships the icons), a static ``image/png`` of frame 0 and a
    line of ``text/plain``. ``values``: the manipulability per step.

    >>> from kinlib.robots import planar_2r
    >>> anim = animate_singularity(planar_2r(1, 1), [[0.0, 0.5], [0.0, 0.0]])
    >>> sorted(anim._repr_mimebundle_())
    ['image/png', 'text/html', 'text/plain']
    """

    _writing = False
    _html = None

    def to_jshtml(self, fps=None, embed_frames=True, default_mode=None):
        """matplotlib's player (same template), its frames drawn by blitting (the static background drawn
        once, then per frame only the moving artists), frame 0 shown at once (:func:`first_frame_html`)."""
        if self._html is None:
            frames = self.render_frames() if embed_frames else None
            if frames is None:
                self._writing = True
                try:
                    html = super().to_jshtml(fps, embed_frames, default_mode)
                finally:
                    self._writing = False
            else:
                html = _player_html(
                    frames, fps or 1000 / self._interval, default_mode or ("loop" if self._repeat else "once")
                )
            self._html = first_frame_html(html)
        return self._html

    def render_frames(self) -> list[bytes] | None:
        """Every frame as PNG bytes: the figure without the moving artists (``movers``) drawn once, then per
        frame that background restored and only the movers drawn (None when the canvas cannot blit)."""
        fig, movers = self._fig, [a for a in getattr(self, "movers", []) if a is not None]
        canvas = fig.canvas
        if not hasattr(canvas, "copy_from_bbox"):  # plt.close(fig) left a bare FigureCanvasBase: Agg still draws it
            from matplotlib.backends.backend_agg import FigureCanvasAgg

            canvas = FigureCanvasAgg(fig)
        if not movers or not hasattr(canvas, "copy_from_bbox") or not hasattr(canvas, "buffer_rgba"):
            return None
        from PIL import Image

        for a in movers:
            a.set_animated(True)
        frames = []
        try:
            canvas.draw()
            background = canvas.copy_from_bbox(fig.bbox)
            for k in range(self.n_frames):
                canvas.restore_region(background)
                self.frame_function(k)
                renderer = canvas.get_renderer()
                for a in movers:
                    if hasattr(a, "do_3d_projection") and hasattr(a, "set_segments"):
                        a.do_3d_projection()
                    a.draw(renderer)
                w, h = canvas.get_width_height(physical=True)
                im = Image.frombuffer("RGBA", (w, h), canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
                buf = io.BytesIO()
                im.save(buf, format="png", compress_level=1)
                frames.append(buf.getvalue())
        finally:
            for a in movers:
                a.set_animated(False)
            self.frame_function(0)
        return frames

    def _post_draw(self, framedata, blit):
        # while matplotlib writes the HTML itself (a canvas that cannot blit), each frame is drawn by the
        # writer's savefig right after: skip the extra full canvas draw per frame
        if not self._writing:
            super()._post_draw(framedata, blit)

    def _repr_mimebundle_(self, include=None, exclude=None):
        html = _FONT_AWESOME.sub("", self.to_jshtml())
        m = _FRAME0.search(html)
        out = {"text/html": html, "text/plain": self.summary}
        if m is not None and m.group(2) == "png":
            out["image/png"] = m.group(1).replace("\\\n", "").split(",", 1)[1]
        return out


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
) -> SingularityAnimation:
    """A FuncAnimation of ``chain`` following ``path`` (N×n configurations, e.g. from :func:`sweep`):
    left, the arm with its velocity ellipse (collapsing to a segment at a singular configuration: when the
    task ``rows`` hold orientation rows besides the drawn ṗ rows, the ellipse of ṗ with those held, as
    ``velocity_ellipsoid(J, rows, hold)``, with the all-joints ṗ ellipse as a light dashed outline) and a
    status line; right, the manipulability √det(J Jᵀ) of the task ``rows`` (default: the chain's task space,
    :func:`kinlib.taskspace.default_task_rows`) along the path with a moving marker. ``.values`` holds the
    manipulability per step. Play it in a static page with ``anim.to_jshtml()`` (``IPython.display.HTML``),
    or make it a cell's value (:class:`SingularityAnimation`: the player showing frame 0 at once, and a static
    image/png of frame 0 for a notebook opened without running it). Its figure is closed in pyplot (no second,
    static copy below the cell); the player still draws it.

    >>> from kinlib.robots import planar_offset_3r
    >>> anim = animate_singularity(planar_offset_3r(1), np.zeros((3, 3)))
    >>> type(anim).__name__, anim.values.shape
    ('SingularityAnimation', (3,))
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
    e_rows = task_row_indices(ellipse_rows) if ellipse_rows is not None else ((3, 4) if planar else (3, 4, 5))
    ells = draw_velocity_ellipses(ax, chain, P[0], task=r, rows=e_rows, scale=velocity_scale)
    if ells.hold:
        ax.legend(loc="lower right", fontsize=7, framealpha=0.8)
    J = task_rows(chain.jacobian_geometric(P), r)
    w = manipulability_values(J, "yoshikawa")
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

    # one "near" rule for the course (kinlib.manipulability.NEAR_SINGULAR): w < 0.1 w_max of the same arm
    states = singularity_state(J, peak_manipulability(chain, r, default_ranges(chain), extra=P))
    words = {"singular": "SINGULAR configuration", "near": "near a singular configuration", "regular": ""}

    def status(k):
        return words[str(states[k])]

    def frame(k):
        arm.update(P[k])
        ells.update(P[k])
        mark.set_data([k], [w[k]])
        txt.set_text(f"{w_label} = {w[k]:.3f}   {status(k)}")
        txt.set_color("tab:red" if status(k) else "k")
        return []

    frame(0)
    anim = SingularityAnimation(fig, frame, frames=P.shape[0], interval=interval, blit=False)
    anim.values = w
    anim.frame_function, anim.n_frames = frame, P.shape[0]
    anim.movers = [*arm.artists, *ells.artists, mark, txt]
    anim.summary = f"animation of {chain.name} along a path of {P.shape[0]} configurations (frame 0 shown)"
    plt.close(fig)  # shown by its player only: an inline backend would print a second, static copy of frame 0
    return anim
