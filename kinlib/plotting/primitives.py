"""Drawing primitives that work the same on 2-D and 3-D axes and can be moved in place: arrows, lines
through points, line segments, text.

Points are columns (3, k) or rows (k, d); on 2-D axes the z coordinate is dropped.

>>> from kinlib.plotting.view import new_axes
>>> ax = new_axes(planar=True)
>>> arrows = Arrows(ax, [[0, 0]], [[1, 1]], "tab:blue"); arrows.set([[1, 0]], [[0, 2]])
>>> type(arrows.artist).__name__
'Quiver'
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection

from .common import is_3d

__all__ = ["perpendicular", "Arrows", "add_text", "move_text", "add_line", "set_line", "add_segments", "set_segments"]


def perpendicular(v: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to the 3-vector v.

    >>> perpendicular(np.array([1.0, 0, 0]))
    array([0., 0., 1.])
    """
    a = np.array([0.0, 0.0, 1.0]) if abs(v[2]) < 0.9 * np.linalg.norm(v) else np.array([1.0, 0.0, 0.0])
    p = a - v * (a @ v) / (v @ v)
    return p / np.linalg.norm(p)


class Arrows:
    """k arrows from origins (k, d) along vectors (k, d), d = 2 (2-D axes: a quiver) or 3 (3-D axes: line
    segments with a two-stroke head); ``set(origins, vectors)`` moves them, ``artist`` is the matplotlib artist.

    >>> from kinlib.plotting.view import new_axes
    >>> a = Arrows(new_axes(planar=False), np.zeros((1, 3)), [[0, 0, 1]], ["k"])
    >>> type(a.artist).__name__   # the shaft and two head strokes of each arrow
    'Line3DCollection'
    """

    def __init__(
        self,
        ax,
        origins,
        vectors,
        colors,
        *,
        width=None,
        head=0.25,
        zorder=4,
        label=None,
        linestyle="-",
        alpha=1.0,
        lw=2.0,
    ):
        self.ax = ax
        self.three_d = is_3d(ax)
        self.head = head
        o, v = np.atleast_2d(np.asarray(origins, float)), np.atleast_2d(np.asarray(vectors, float))
        self.k = v.shape[0]
        colors = list(colors) if not isinstance(colors, str) else [colors] * self.k
        self.colors = colors
        if self.three_d:
            from mpl_toolkits.mplot3d.art3d import Line3DCollection

            segs, cols = self.segments(o, v)
            self.artist = Line3DCollection(
                segs, colors=cols, linewidths=lw, zorder=zorder, label=label, linestyles=linestyle, alpha=alpha
            )
            ax.add_collection3d(self.artist)
        else:
            kw = dict(
                angles="xy",
                scale_units="xy",
                scale=1,
                color=colors,
                zorder=zorder,
                label=label,
                alpha=alpha,
                width=width or 0.012,
                headwidth=3.5,
                headlength=4.5,
                headaxislength=4,
            )
            self.artist = ax.quiver(o[:, 0], o[:, 1], v[:, 0], v[:, 1], **kw)

    def segments(self, o, v):
        """The 3-D line segments (shaft, two head strokes per arrow) and their colours."""
        segs, cols = [], []
        for i in range(v.shape[0]):
            a, d = o[i], v[i]
            L = float(np.linalg.norm(d))
            c = self.colors[i % len(self.colors)]
            segs.append([a, a + d])
            cols.append(c)
            if L > 1e-12:
                u = d / L
                p = perpendicular(d)
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
        """Move the arrows to new origins and vectors (same count)."""
        o, v = np.atleast_2d(np.asarray(origins, float)), np.atleast_2d(np.asarray(vectors, float))
        if self.three_d:
            segs, _ = self.segments(o, v)
            self.artist.set_segments(segs)
        else:
            self.artist.set_offsets(o[:, :2])
            self.artist.set_UVC(v[:, 0], v[:, 1])


def add_text(ax, p, s, **kw):
    """A Text at the point p (2 or 3 entries; 3-D axes use all three).

    >>> from kinlib.plotting.view import new_axes
    >>> add_text(new_axes(planar=True), [1, 2, 0], "p").get_position()
    (1, 2)
    """
    if is_3d(ax):
        return ax.text(p[0], p[1], p[2], s, **kw)
    return ax.text(p[0], p[1], s, **kw)


def move_text(t, p):
    """Move the Text t (2-D or 3-D) to the point p.

    >>> from kinlib.plotting.view import new_axes
    >>> t = add_text(new_axes(planar=True), [0, 0], "p"); move_text(t, [3, 4]); t.get_position()
    (3, 4)
    """
    if hasattr(t, "set_position_3d"):
        t.set_position_3d((p[0], p[1], p[2]))
    else:
        t.set_position((p[0], p[1]))


def add_line(ax, pts, **kw):
    """A Line2D/Line3D through the columns of pts (3×k).

    >>> from kinlib.plotting.view import new_axes
    >>> add_line(new_axes(planar=True), np.array([[0, 1], [0, 1], [0, 0]])).get_xydata().tolist()
    [[0.0, 0.0], [1.0, 1.0]]
    """
    if is_3d(ax):
        return ax.plot(pts[0], pts[1], pts[2], **kw)[0]
    return ax.plot(pts[0], pts[1], **kw)[0]


def set_line(line, pts):
    """Move a line made by :func:`add_line` to the columns of pts (3×k).

    >>> from kinlib.plotting.view import new_axes
    >>> line = add_line(new_axes(planar=True), np.zeros((3, 2)))
    >>> set_line(line, np.array([[1, 2], [3, 4], [0, 0]])); line.get_xdata().tolist()
    [1, 2]
    """
    if hasattr(line, "set_data_3d"):
        line.set_data_3d(pts[0], pts[1], pts[2])
    else:
        line.set_data(pts[0], pts[1])


def add_segments(ax, segs, **kw):
    """A LineCollection (Line3DCollection on 3-D axes) of the segments [[a, b], ...] (3-D points).

    >>> from kinlib.plotting.view import new_axes
    >>> len(add_segments(new_axes(planar=True), [[np.zeros(3), np.ones(3)]]).get_segments())
    1
    """
    if is_3d(ax):
        from mpl_toolkits.mplot3d.art3d import Line3DCollection

        c = Line3DCollection(segs, **kw)
        ax.add_collection3d(c)
        return c
    c = LineCollection([np.asarray(s)[:, :2] for s in segs], **kw)
    ax.add_collection(c)
    return c


def set_segments(c, segs, three_d: bool):
    """Move a collection made by :func:`add_segments` to new segments (3-D points).

    >>> from kinlib.plotting.view import new_axes
    >>> c = add_segments(new_axes(planar=True), [[np.zeros(3), np.ones(3)]])
    >>> set_segments(c, [[np.ones(3), 2 * np.ones(3)]], False); c.get_segments()[0].tolist()
    [[1.0, 1.0], [2.0, 2.0]]
    """
    c.set_segments(segs if three_d else [np.asarray(s)[:, :2] for s in segs])
