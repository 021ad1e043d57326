"""The view of a drawing: new axes, equal-scale limits fitted to what is drawn, π ticks, and the pieces of
label placement (screen coordinates, candidate spots, free room).

The state of an automatic view (the points it is fitted to, what labels must avoid, the chain whose labels
to move) is a :class:`ViewState`: an invisible artist on the axes, so it lives and dies with the figure.

>>> import matplotlib.pyplot as plt
>>> ax = new_axes(planar=True)
>>> pi_ticks(ax.xaxis, 0, 3.1416); [t.get_text() for t in ax.xaxis.get_ticklabels()]
['0', 'π/2', 'π']
"""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
import sympy as sp
from matplotlib.artist import Artist

from .common import is_3d

__all__ = [
    "new_axes",
    "pi_ticks",
    "legend_beside",
    "fit_view",
    "ViewState",
    "view_state",
    "include",
    "workspace_points",
    "to_pixels",
    "pick_spot",
    "data_per_pixel",
    "segment_samples",
    "LABEL_DIRECTIONS_2D",
    "LABEL_DIRECTIONS_3D",
]


def new_axes(planar: bool, ax=None, figsize=None):
    """``ax`` itself, or a new pyplot figure with 2-D (equal aspect) or 3-D axes.

    >>> type(new_axes(planar=False)).__name__
    'Axes3D'
    """
    if ax is not None:
        return ax
    if planar:
        fig, ax = plt.subplots(figsize=figsize or (5.5, 5))
    else:
        fig = plt.figure(figsize=figsize or (6, 5.5))
        ax = fig.add_subplot(projection="3d")
    return ax


def legend_beside(ax, where: str = "right", **kwargs):
    """A legend outside the axes, so it never covers the drawing: to the ``"right"`` of the axes (top-aligned)
    or ``"below"`` them (centred, under the x label); other keywords go to ``ax.legend``. ``tight_layout`` and
    constrained layout make room for it.

    >>> import matplotlib.pyplot as plt
    >>> fig, ax = plt.subplots(); _ = ax.plot([0, 1], [0, 1], label="arm")
    >>> legend_beside(ax).get_bbox_to_anchor().bounds == legend_beside(ax).get_bbox_to_anchor().bounds
    True
    """
    spots = {"right": ("upper left", (1.02, 1.0)), "below": ("upper center", (0.5, -0.14))}
    if where not in spots:
        raise ValueError(f"where must be 'right' or 'below', got {where!r}")
    loc, anchor = spots[where]
    kwargs.setdefault("fontsize", 8)
    kwargs.setdefault("borderaxespad", 0.0)
    return ax.legend(loc=loc, bbox_to_anchor=anchor, **kwargs)


def pi_ticks(axis, lo: float, hi: float, step_fraction: int = 2):
    """Ticks at multiples of π/step_fraction on a matplotlib Axis (``ax.xaxis``), labelled −π, −π/2, 0, …

    >>> ax = new_axes(planar=True)
    >>> pi_ticks(ax.yaxis, -3.1416, 0, 4); [t.get_text() for t in ax.yaxis.get_ticklabels()]
    ['−π', '−3π/4', '−π/2', '−π/4', '0']
    """
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


def fit_view(ax, pts, margin: float = 0.08, min_frac: float = 0.4):
    """Limits around the points pts (3, k) with equal scaling on every axis: a box of the points' own
    proportions (each side at least ``min_frac`` of the longest, so a flat arm still gets some depth),
    padded by ``margin`` × the longest side. 3-D: ``set_box_aspect`` to the box's sides.

    >>> ax = new_axes(planar=True)
    >>> fit_view(ax, np.array([[0, 2], [0, 1], [0, 0]]), margin=0.0)
    >>> [float(v) for v in ax.get_xlim() + ax.get_ylim()]
    [0.0, 2.0, 0.0, 1.0]
    """
    pts = np.asarray(pts, float)
    d = 3 if is_3d(ax) else 2
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


class ViewState(Artist):
    """How kinlib set up the view of one axes (an invisible artist added to it, so it goes with the figure):

    ``fit`` (True: limits fitted automatically, grown by :func:`include`), ``points`` (3, k) the view is
    fitted to, ``margin``, ``obstacles`` (3, k) that labels keep clear of (arrows drawn after the chain),
    ``chain`` (the ChainArtist whose labels :func:`include` places again).

    >>> ax = new_axes(planar=True)
    >>> state = ViewState.attach(ax, fit=False); view_state(ax) is state, state.get_visible()
    (True, False)
    """

    def __init__(self, *, fit: bool, points=None, margin: float = 0.0, chain=None):
        super().__init__()
        self.fit, self.points, self.margin, self.chain = fit, points, margin, chain
        self.obstacles = np.zeros((3, 0))
        self.set_visible(False)

    @classmethod
    def attach(cls, ax, **kwargs) -> ViewState:
        """A new state for ``ax`` (replacing an older one)."""
        old = view_state(ax)
        if old is not None:
            old.remove()
        state = cls(**kwargs)
        ax.add_artist(state)
        return state

    def draw(self, renderer):  # nothing to draw: it only holds the view's state
        pass


def view_state(ax) -> ViewState | None:
    """The :class:`ViewState` of ``ax``, or None when kinlib did not set up its view.

    >>> view_state(new_axes(planar=True)) is None
    True
    """
    return next((a for a in ax.get_children() if isinstance(a, ViewState)), None)


def include(ax, pts):
    """Grow an automatic kinlib view (one set by draw_chain without ``limits``) so that the points
    (3, k) or (2, k), e.g. a velocity arrow's tip, are inside it; labels are placed again around them.

    >>> ax = new_axes(planar=True)
    >>> state = ViewState.attach(ax, fit=True, points=np.zeros((3, 1)), margin=0.0)
    >>> include(ax, np.array([[2.0], [1.0]])); [float(v) for v in ax.get_xlim()]
    [0.0, 2.0]
    """
    state = view_state(ax)
    if state is None:
        return
    pts = np.asarray(pts, float)
    if pts.shape[0] == 2:
        pts = np.vstack([pts, np.zeros(pts.shape[1])])
    pts = pts[:, np.all(np.isfinite(pts), axis=0)]
    state.obstacles = np.hstack([state.obstacles, pts])
    if state.fit:
        state.points = np.hstack([state.points, pts])
        fit_view(ax, state.points, state.margin)
    if state.chain is not None:
        state.chain.place_labels()


def workspace_points(chain, ranges, q=None, samples: int = 400) -> np.ndarray:
    """The skeleton points (3, N·(n+2)) of a deterministic sample of the joint ranges (and home, q).

    >>> from kinlib.robots import planar_3r
    >>> workspace_points(planar_3r(1, 1, 1), [(-1, 1)] * 3, samples=10).shape
    (3, 55)
    """
    rng = np.random.default_rng(0)
    lo = np.array([r[0] for r in ranges])
    hi = np.array([r[1] for r in ranges])
    Q = lo + (hi - lo) * rng.random((samples, chain.n))
    extra = [np.zeros(chain.n)] + ([q] if q is not None else [])
    Q = np.vstack([Q, np.array(extra)])
    return np.moveaxis(chain.skeleton(Q), 1, 0).reshape(3, -1)


# --- label placement -------------------------------------------------------------------------------------
#: Unit directions around a point where a label may go, in order of preference (3-D, then 2-D).
LABEL_DIRECTIONS_3D = np.array(
    [
        [0, -1, 1],
        [0, 1, 1],
        [1, 0, 1],
        [-1, 0, 1],
        [0, -1, -1],
        [0, 1, -1],
        [1, 0, -1],
        [-1, 0, -1],
        [1, 1, 0],
        [-1, -1, 0],
        [1, -1, 0],
        [-1, 1, 0],
        [0, 0, 1],
        [0, 0, -1],
    ],
    float,
)
LABEL_DIRECTIONS_3D /= np.linalg.norm(LABEL_DIRECTIONS_3D, axis=1)[:, None]
LABEL_DIRECTIONS_2D = np.array(
    [[-1, 1, 0], [1, 1, 0], [-1, -1, 0], [1, -1, 0], [0, 1, 0], [0, -1, 0], [-1, 0, 0], [1, 0, 0]], float
)
LABEL_DIRECTIONS_2D /= np.linalg.norm(LABEL_DIRECTIONS_2D, axis=1)[:, None]


def to_pixels(ax, P) -> np.ndarray:
    """Display coordinates (k, 2) of the points P (3, k) in ax (through the 3-D projection if any).

    >>> ax = new_axes(planar=True)
    >>> to_pixels(ax, np.zeros((3, 2))).shape
    (2, 2)
    """
    if is_3d(ax):
        from mpl_toolkits.mplot3d import proj3d

        x, y, _ = proj3d.proj_transform(P[0], P[1], P[2], ax.get_proj())
        return ax.transData.transform(np.column_stack([x, y]))
    return ax.transData.transform(P[:2].T)


def _min_dist(A, B) -> np.ndarray:
    """For each row of A (m, 2): the distance to the nearest row of B (k, 2) (inf when B is empty)."""
    if not len(B):
        return np.full(len(A), np.inf)
    dx = A[:, None, 0] - B[None, :, 0]
    dy = A[:, None, 1] - B[None, :, 1]
    return np.sqrt(np.min(dx * dx + dy * dy, axis=1))


def pick_spot(Cp, O, placed, need_lab: float, need_obs: float, prefer: int | None = None) -> int:
    """Index of the first candidate (pixels, (m, 2)) at least need_lab from the labels already placed and
    need_obs from the obstacles O (pixels, (k, 2)); else the candidate with the most room. ``prefer``: a
    candidate tried first (kept if it fits: e.g. last frame's choice, so labels do not jump).

    >>> pick_spot(np.array([[0.0, 0], [10, 0]]), np.array([[1.0, 0]]), np.zeros((0, 2)), 5, 5)
    1
    >>> pick_spot(np.array([[20.0, 0], [10, 0]]), np.array([[1.0, 0]]), np.zeros((0, 2)), 5, 5, prefer=1)
    1
    """
    if prefer is not None and 0 <= prefer < len(Cp):
        c = Cp[prefer : prefer + 1]
        if _min_dist(c, placed)[0] >= need_lab and _min_dist(c, O)[0] >= need_obs:
            return int(prefer)
    d_obs = _min_dist(Cp, O)
    d_lab = _min_dist(Cp, placed)
    ok = np.flatnonzero((d_lab >= need_lab) & (d_obs >= need_obs))
    return int(ok[0]) if ok.size else int(np.argmax(np.minimum(d_lab, 2.0 * d_obs)))


def data_per_pixel(ax) -> float:
    """Data length per pixel on screen (3-D: along the least foreshortened of the box's edges).

    >>> ax = new_axes(planar=True)
    >>> bool(data_per_pixel(ax) > 0)
    True
    """
    if not is_3d(ax):
        return float(np.diff(ax.get_xlim())[0]) / max(ax.bbox.width, 1.0)
    lims = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    c = lims[:, :1]
    ends = np.repeat(c, 6, axis=1)
    for k in range(3):
        ends[k, 2 * k], ends[k, 2 * k + 1] = lims[k]
    px = to_pixels(ax, ends)
    pix = np.linalg.norm(px[0::2] - px[1::2], axis=1)
    return float(np.min((lims[:, 1] - lims[:, 0]) / np.maximum(pix, 1e-9)))


def segment_samples(pts, k: int = 16) -> np.ndarray:
    """Points along the polyline through the columns of pts (3, m), k per segment.

    >>> segment_samples(np.array([[0.0, 1.0], [0, 0], [0, 0]]), k=3)[0]
    array([0. , 0.5, 1. ])
    """
    if pts.shape[1] < 2:
        return pts
    t = np.linspace(0.0, 1.0, k)[None, :, None]
    a, b = pts[:, :-1].T[:, None, :], pts[:, 1:].T[:, None, :]
    return (a + t * (b - a)).reshape(-1, 3).T
