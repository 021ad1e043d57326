"""The artists of a drawn chain and its velocities; each ``update(q, ...)`` moves its matplotlib artists in
place (no re-creation), so a slider redraws quickly. Made by the ``draw_*`` functions of
:mod:`kinlib.plotting.drawing`.

>>> from kinlib.robots import planar_offset_3r
>>> from kinlib.plotting import draw_chain
>>> art = draw_chain(planar_offset_3r(1), [0, 0.5, -0.5]); type(art).__name__
'ChainArtist'
"""

from __future__ import annotations

import numpy as np

from ..analysis.manipulability import velocity_ellipsoid
from .common import FRAME_COLORS, JOINT_COLORS, as_configuration, is_3d, theta_tex
from .primitives import Arrows, add_line, add_segments, add_text, move_text, perpendicular, set_line, set_segments
from .view import (
    LABEL_DIRECTIONS_2D,
    LABEL_DIRECTIONS_3D,
    data_per_pixel,
    include,
    pick_spot,
    segment_samples,
    to_pixels,
    view_state,
)

__all__ = ["ChainArtist", "VelocityArtist", "JointVelocitiesArtist", "EllipseArtist", "ellipse_outline"]


class ChainArtist:
    """The matplotlib artists of one drawn chain; ``update(q)`` moves them to a new configuration.

    What is drawn is the forward kinematics (every point from the product of exponentials, via
    ``chain.skeleton(q)`` and J_s(θ)): with T_k = e^{[S1]θ1} ⋯ e^{[Sk]θk} and p_i joint i's point at home,
    joint i sits at T_{i−1}(p_i) (where the links before it carry it) and the tool origin at T(θ) = T_n M.
    A prismatic joint i is a *track* fixed to the link before it, through T_{i−1}(p_i) along its current
    axis v_i (the v part of column i of J_s), spanning the joint's range, and a *slider* (the link after it,
    e.g. the cart of the cart-pole) at T_i(p_i) = T_{i−1}(p_i) + θ_i v_i, where the next link starts; the
    link line is broken along the track (the slide is shown by the slider's place on the track).

    Attributes: ``ax``, ``chain`` (numeric), ``q``, ``planar``, ``scale`` (a length for frame arrows),
    ``links`` (Line through the drawn points, NaN where it breaks at a slide), ``revolute`` (joint markers),
    ``prismatic`` (tracks), ``sliders`` (rectangles in 2-D, square markers in 3-D), ``axes_lines``,
    ``frame_s``/``frame_b`` (arrow sets), ``labels`` (Text θi per joint, placed where they overlap
    neither each other nor the links: at the end of the joint's axis in 3-D, beside the joint in 2-D),
    ``annotations`` (extra Text, e.g. the screw axes of :func:`~kinlib.plotting.draw_home`), ``tool``
    (tool-origin marker).

    >>> from kinlib.robots import planar_offset_3r
    >>> from kinlib.plotting import draw_chain
    >>> art = draw_chain(planar_offset_3r(1), [0, 0, 0])
    >>> art.update([0.5, 0.2, 0.1]).q
    array([0.5, 0.2, 0.1])
    """

    AXIS_HALF = 0.35  # half-length of a drawn joint axis, × scale
    FRAME = 0.22  # length of a frame arrow, × scale

    def __init__(
        self,
        ax,
        chain,
        q,
        *,
        planar,
        frames=True,
        axes=True,
        labels=True,
        color="0.25",
        scale=None,
        lw=4.0,
        fontsize=9,
        ranges=None,
    ):
        self.ax, self.chain, self.planar = ax, chain, planar
        self.three_d = is_3d(ax)
        self.q = q
        self.scale = scale
        self.fontsize = fontsize
        self.kinds = chain.joint_types
        self.rev = [i for i, k in enumerate(self.kinds) if k == "R"]
        self.pri = [i for i, k in enumerate(self.kinds) if k == "P"]
        self.ranges = ranges
        sk, T, Js = self._kin(q)
        self._geom = (sk, T, Js)
        path = self.link_path(sk, Js, q)
        self.links = add_line(ax, path, color=color, lw=lw, solid_capstyle="round", zorder=2, marker="", label="links")
        self.base = add_line(ax, sk[:, :1], color="k", marker="s", ms=9, ls="", zorder=3)
        self.tool = add_line(ax, sk[:, -1:], color="k", marker="o", ms=4, ls="", zorder=5)
        rp = sk[:, [i + 1 for i in self.rev]]
        self.revolute = add_line(
            ax,
            rp,
            ls="",
            marker="o",
            ms=12 if not self.three_d else 10,
            mfc="white",
            mec="k",
            mew=1.8,
            zorder=4,
            label="revolute joint",
        )
        self.revolute_dot = add_line(ax, rp, ls="", marker=".", ms=5, color="k", zorder=5) if not self.three_d else None
        self.prismatic = self.sliders = None
        if self.pri:
            self.prismatic = add_segments(
                ax,
                self._rails(sk, Js, q),
                colors="tab:gray",
                linewidths=3,
                alpha=0.7,
                zorder=1.5,
                capstyle="butt",
                label="prismatic joint (track)",
            )
            if self.three_d:
                self.sliders = add_line(
                    ax, self.slider_points(sk, Js, q), ls="", marker="s", ms=11, mfc="0.55", mec="k", zorder=3
                )
            else:
                from matplotlib.collections import PolyCollection

                self.sliders = PolyCollection(
                    self._slider_boxes(sk, Js, q), facecolors="0.6", edgecolors="k", linewidths=1.2, zorder=3
                )
                ax.add_collection(self.sliders)
        self.axes_lines = None
        if axes and (self.three_d or self.pri):
            self.axes_lines = add_segments(
                ax,
                self.axis_segments(sk, Js),
                colors="0.45",
                linewidths=1.0,
                linestyles="--",
                zorder=1,
                label="joint axes",
            )
        self.frame_s = self.frame_b = None
        self.frame_texts = []
        if frames:
            d = 3 if self.three_d else 2
            L = self.FRAME * scale
            E = np.eye(3)[:d, :d] * L
            cols = FRAME_COLORS[:d]
            # thinner and lighter than the velocity arrows drawn on top, so the two are not confused
            thin = dict(head=0.3, width=0.006, lw=1.6, alpha=0.75)
            self.frame_s = Arrows(ax, np.zeros((d, d)), E, cols, zorder=3, **thin)
            self.frame_b = Arrows(ax, np.tile(T[:d, 3], (d, 1)), (T[:d, :d] * L).T, cols, zorder=3, **thin)
            self.frame_texts = [
                add_text(ax, np.zeros(3), r"$\{s\}$", fontsize=fontsize - 1, ha="center", va="center", zorder=7),
                add_text(ax, T[:3, 3], r"$\{b\}$", fontsize=fontsize - 1, ha="center", va="center", zorder=7),
            ]
        self.labels = []
        if labels:
            for i in range(chain.n):
                self.labels.append(
                    add_text(
                        ax,
                        sk[:, i + 1],
                        theta_tex(i + 1),
                        fontsize=fontsize,
                        color=JOINT_COLORS[i % 10],
                        ha="center",
                        va="center",
                        zorder=7,
                    )
                )
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

    def _unit_axis(self, Js, i):
        v = Js[3:, i]
        return v / (np.linalg.norm(v) or 1.0)

    def _rails(self, sk, Js, q):
        """The tracks of the prismatic joints: through T_{i−1}(p_i) along v_i, over the joint's range (and
        the current value and 0, if outside it), a little beyond."""
        h = 0.08 * self.scale
        segs = []
        for i in self.pri:
            v, p, n = self._unit_axis(Js, i), sk[:, i + 1], float(np.linalg.norm(Js[3:, i])) or 1.0
            lo, hi = self.ranges[i] if self.ranges is not None else (0.0, 0.0)
            lo, hi = min(lo, q[i], 0.0) * n - h, max(hi, q[i], 0.0) * n + h
            segs.append([p + lo * v, p + hi * v])
        return segs

    def slider_points(self, sk, Js, q) -> np.ndarray:
        """Where each prismatic joint's slider is (3, #P): T_i(p_i) = T_{i−1}(p_i) + θ_i v_i."""
        return np.column_stack([sk[:, i + 1] + q[i] * Js[3:, i] for i in self.pri]) if self.pri else np.zeros((3, 0))

    def _slider_boxes(self, sk, Js, q):
        """2-D rectangles (0.2 × 0.12 scale) centred on the sliders, aligned with their tracks."""
        a, b = 0.1 * self.scale, 0.06 * self.scale
        out = []
        for k, i in enumerate(self.pri):
            c = self.slider_points(sk, Js, q)[:2, k]
            u = self._unit_axis(Js, i)[:2]
            u = u / (np.linalg.norm(u) or 1.0)
            w = np.array([-u[1], u[0]])
            out.append(np.array([c - a * u - b * w, c + a * u - b * w, c + a * u + b * w, c - a * u + b * w]))
        return out

    def link_path(self, sk, Js, q) -> np.ndarray:
        """The points the link line runs through (3, k): base, each joint T_{i−1}(p_i) — for a prismatic
        joint followed by a break (a NaN column) and its slider T_i(p_i) — then the tool origin."""
        cols = [sk[:, 0]]
        nan = np.full(3, np.nan)
        for i, kind in enumerate(self.kinds):
            cols.append(sk[:, i + 1])
            if kind == "P":
                cols += [nan, sk[:, i + 1] + q[i] * Js[3:, i]]
        cols.append(sk[:, -1])
        return np.column_stack(cols)

    def _link_pieces(self, sk, Js, q) -> list:
        """The unbroken pieces of the link line (each 3 × m)."""
        P = self.link_path(sk, Js, q)
        pieces = np.split(P, np.flatnonzero(np.isnan(P[0])), axis=1)
        return [piece[:, ~np.isnan(piece[0])] for piece in pieces]

    def axis_segments(self, sk, Js) -> list:
        """The drawn joint axes [[a, b], ...] at the skeleton sk with the space Jacobian Js (2-D: revolute
        axes leave the page and are drawn as ⊙ instead)."""
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
        pts = [sk, self.slider_points(sk, Js, self.q)] + [np.column_stack(r) for r in self._rails(sk, Js, self.q)]
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
            off = np.array([[r], [r], [0]])
            pts.append(np.hstack([sk[:, 1:-1] + off, sk[:, 1:-1] - off]))
        return np.hstack(pts)

    # -- labels ---------------------------------------------------------------------------------------
    def place_labels(self, keep: bool = False):
        """Put θ1…θn, {s} and {b} where they overlap neither each other nor the links (in screen space).

        Candidates per joint, in order of preference: the two ends of its drawn axis (3-D, prismatic), then
        directions around the joint; the first candidate far enough from the labels already placed and
        from the drawing wins (else the one with the most room). ``keep`` (as ``update`` does): each label's
        previous spot is tried first, so labels stay put while they fit. Moves the Text artists only."""
        if not self.labels and not self.frame_texts:
            return
        sk, T, Js = self._geom
        ax = self.ax
        A = self._axis_dirs(Js)
        h = (self.AXIS_HALF + 0.08) * self.scale
        px = self.fontsize * ax.figure.dpi / 72.0  # the font size in pixels
        per_px = data_per_pixel(ax)
        r = min(2.2 * px * per_px, 0.3 * self.scale)  # beside a joint: about two font sizes
        dirs = LABEL_DIRECTIONS_3D if self.three_d else LABEL_DIRECTIONS_2D
        items = []  # (text, candidate points (3, m))
        for i, t in enumerate(self.labels):
            p = sk[:, i + 1 : i + 2]
            cands = []
            if self.three_d or self.kinds[i] == "P":
                a = A[:, i : i + 1]
                cands += [p + h * a, p - h * a, p + 1.45 * h * a, p - 1.45 * h * a]
            cands += [p + r * dirs.T, p + 1.6 * r * dirs.T]
            items.append((t, np.hstack(cands)))
        if self.frame_texts:
            fd = np.vstack([-dirs[0], -dirs[1:]]) if not self.three_d else dirs[::-1]
            ring = np.hstack([0.8 * r * fd.T, 1.3 * r * fd.T, 1.9 * r * fd.T])
            items.append((self.frame_texts[0], ring))
            items.append((self.frame_texts[1], T[:3, 3:4] + ring))
        L = self.FRAME * self.scale
        obstacles = [segment_samples(piece) for piece in self._link_pieces(sk, Js, self.q)]
        if self.frame_s is not None:
            t = np.linspace(0.3, 1.0, 5)
            for o, R in ((np.zeros((3, 1)), np.eye(3)), (T[:3, 3:4], T[:3, :3])):
                for k in range(3 if self.three_d else 2):
                    obstacles.append(o + L * np.outer(R[:, k], t))
        for a, b in self._rails(sk, Js, self.q) + (self.axis_segments(sk, Js) if self.axes_lines is not None else []):
            obstacles.append(segment_samples(np.column_stack([a, b]), 9))
        state = view_state(ax)
        if state is not None and state.chain is self:
            obstacles.append(state.obstacles)
        # one projection for every point (obstacles and all candidates): 3-D projections are costly
        obs = np.hstack(obstacles)
        sizes = [C.shape[1] for _, C in items]
        allp = to_pixels(ax, np.hstack([obs] + [C for _, C in items]))
        O, cuts = allp[: obs.shape[1]], np.cumsum([obs.shape[1]] + sizes)
        need_lab, need_obs = 2.0 * px, 1.4 * px
        placed = np.zeros((0, 2))
        prev = getattr(self, "_label_picks", None) if keep else None
        picks = []
        for j, (t, C) in enumerate(items):
            Cp = allp[cuts[j] : cuts[j + 1]]
            # keep=True (update): the spot chosen last time first (labels stay put while they fit; quicker)
            k = pick_spot(
                Cp, O, placed, need_lab, need_obs, prefer=prev[j] if prev and len(prev) == len(items) else None
            )
            picks.append(k)
            move_text(t, C[:, k])
            placed = np.vstack([placed, Cp[k]])
        self._label_picks = picks

    # -- update ---------------------------------------------------------------------------------------
    def update(self, q):
        """Move every artist to configuration q (no artist is re-created)."""
        q = as_configuration(self.chain, q)
        self.q = q
        sk, T, Js = self._kin(q)
        self._geom = (sk, T, Js)
        set_line(self.links, self.link_path(sk, Js, q))
        set_line(self.tool, sk[:, -1:])
        rp = sk[:, [i + 1 for i in self.rev]]
        set_line(self.revolute, rp)
        if self.revolute_dot is not None:
            set_line(self.revolute_dot, rp)
        if self.prismatic is not None:
            set_segments(self.prismatic, self._rails(sk, Js, q), self.three_d)
            if self.three_d:
                set_line(self.sliders, self.slider_points(sk, Js, q))
            else:
                self.sliders.set_verts(self._slider_boxes(sk, Js, q))
        if self.axes_lines is not None:
            set_segments(self.axes_lines, self.axis_segments(sk, Js), self.three_d)
        if self.frame_b is not None:
            d = 3 if self.three_d else 2
            L = self.FRAME * self.scale
            self.frame_b.set(np.tile(T[:d, 3], (d, 1)), (T[:d, :d] * L).T)
        self.place_labels(keep=True)
        return self

    @property
    def artists(self) -> list:
        """The artists that ``update`` moves (for blitting); {s} and the base stay put."""
        out = [self.links, self.revolute, self.tool]
        out += [a for a in (self.revolute_dot, self.prismatic, self.sliders, self.axes_lines) if a is not None]
        if self.frame_b is not None:
            out += [self.frame_b.artist, *self.frame_texts]
        return out + list(self.labels)

    @property
    def tool_position(self) -> np.ndarray:
        """The drawn tool origin p (3,)."""
        return self.chain.fk(self.q)[:3, 3]


class VelocityArtist:
    """The end-effector velocity arrow ṗ = J_ṗ(θ) θ̇ at the tool origin; ``update(q, qdot)``;
    ``velocity`` holds ṗ (before the display ``scale``).

    >>> from kinlib.robots import planar_3r
    >>> from kinlib.plotting import draw_chain, draw_velocity
    >>> chain = planar_3r(1, 1, 1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> draw_velocity(art.ax, chain, [0, 0, 0], [1, 0, 0]).update(qdot=[0, 0, 2]).velocity
    array([0., 2.])
    """

    def __init__(self, ax, chain, q, qdot, rows, scale, color, label):
        self.ax, self.chain, self.rows, self.scale = ax, chain, rows, scale
        self.q, self.qdot = q, qdot
        p, v = self._compute(q, qdot)
        self.arrows = Arrows(ax, p[None], v[None] * scale, [color], label=label, zorder=6, head=0.22, width=0.014)
        self.velocity = v
        include(ax, p[:, None] + np.outer(scale * v, np.linspace(0.2, 1.05, 6)))

    def _compute(self, q, qdot):
        J = self.chain.jacobian_geometric(q)
        p = self.chain.fk(q)[:3, 3]
        v = J[list(self.rows)] @ qdot
        return p[: len(self.rows)], v

    def update(self, q=None, qdot=None):
        """Move the arrow to configuration ``q`` and joint rates ``qdot`` (either kept when None)."""
        q = self.q if q is None else as_configuration(self.chain, q)
        qdot = self.qdot if qdot is None else as_configuration(self.chain, qdot, "qdot")
        self.q, self.qdot = q, qdot
        p, v = self._compute(q, qdot)
        self.velocity = v
        self.arrows.set(p[None], v[None] * self.scale)
        return self

    @property
    def artist(self):
        """The matplotlib artist of the arrow."""
        return self.arrows.artist

    @property
    def artists(self) -> list:
        """The artists that ``update`` moves (for blitting)."""
        return [self.arrows.artist]


class JointVelocitiesArtist:
    """One arrow per joint at the tool origin: column i of the geometric Jacobian's ṗ rows (ṗ for θ̇_i = 1);
    ``columns`` (k, d) holds the drawn vectors (before ``scale``); ``update(q)``.

    >>> from kinlib.robots import planar_3r
    >>> from kinlib.plotting import draw_chain, draw_joint_velocities
    >>> chain = planar_3r(1, 1, 1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> draw_joint_velocities(art.ax, chain, [0, 0, 0]).columns + 0.0
    array([[0., 3.],
           [0., 2.],
           [0., 1.]])
    """

    def __init__(self, ax, chain, q, rows, scale, colors, labels, joints):
        self.ax, self.chain, self.rows, self.scale, self.joints = ax, chain, rows, scale, joints
        self.q = q
        p, V = self._compute(q)
        self.columns = V
        self.arrows = Arrows(ax, np.tile(p, (len(joints), 1)), V * scale, colors, zorder=6, head=0.2, width=0.01)
        self.texts = []
        if labels:
            for k in range(len(joints)):
                self.texts.append(
                    add_text(ax, p, labels[k], color=colors[k], fontsize=9, ha="center", va="center", zorder=8)
                )
        include(
            ax, np.hstack([p[:, None] + np.outer(scale * V[k], np.linspace(0.2, 1.25, 7)) for k in range(len(joints))])
        )
        self._place(p, V)
        self._show_labels(V)

    def _place(self, p, V):
        """Each label beyond its arrow's tip, or beside it when that spot is on another arrow or label."""
        if not self.texts:
            return
        ax = self.ax
        d = len(p)
        px = 9 * ax.figure.dpi / 72.0
        step = 1.3 * px * data_per_pixel(ax)
        V = V * self.scale
        P3 = (lambda X: np.vstack([X, np.zeros((3 - d, X.shape[1]))])) if d == 2 else (lambda X: X)
        t = np.linspace(0.15, 1.0, 12)
        O = to_pixels(ax, P3(np.hstack([p[:, None] + np.outer(v, t) for v in V])))
        placed = np.zeros((0, 2))
        for txt, v in zip(self.texts, V):
            nv = np.linalg.norm(v)
            u = v / nv if nv > 0 else np.eye(d)[0]
            w = np.array([-u[1], u[0]]) if d == 2 else perpendicular(u)
            tip = p + v
            C = np.column_stack(
                [
                    tip + step * u,
                    tip + step * w,
                    tip - step * w,
                    tip + step * (u + w),
                    tip + step * (u - w),
                    tip + 2 * step * u,
                ]
            )
            Cp = to_pixels(ax, P3(C))
            k = pick_spot(Cp, O, placed, 1.6 * px, 0.9 * px)
            move_text(txt, P3(C[:, k : k + 1])[:, 0])
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
        """Move the arrows and their labels to configuration ``q``."""
        q = as_configuration(self.chain, q)
        self.q = q
        p, V = self._compute(q)
        self.columns = V
        self.arrows.set(np.tile(p, (len(self.joints), 1)), V * self.scale)
        self._place(p, V)
        self._show_labels(V)
        return self

    @property
    def artists(self) -> list:
        """The artists that ``update`` moves (for blitting)."""
        return [self.arrows.artist, *self.texts]


def ellipse_outline(center, lengths, axes, scale: float = 1.0, samples: int = 97):
    """The outline of the ellipse (2-D center) or the three principal ellipses of the ellipsoid (3-D center)
    with semi-axis lengths ``lengths`` (k,) along the unit directions ``axes`` (d, k) (columns), k ≤ d,
    each length × ``scale``; missing or zero lengths flatten it (a segment at a singular configuration).

    Returns (curves, segments): the curves as (3, samples) point arrays (z = 0 in 2-D), one in 2-D and three
    in 3-D (planes of axes 1-2, 2-3, 1-3), and the d principal axes as segments [[c − a_i, c + a_i], ...].

    >>> curves, segs = ellipse_outline([0, 0], [2.0, 1.0], np.eye(2), samples=5)
    >>> np.round(curves[0], 12)
    array([[ 2.,  0., -2., -0.,  2.],
           [ 0.,  1.,  0., -1., -0.],
           [ 0.,  0.,  0.,  0.,  0.]])
    """
    c = np.asarray(center, float)
    d = c.size
    lengths = np.asarray(lengths, float).reshape(-1)
    U = np.asarray(axes, float).reshape(d, lengths.size)
    A = np.zeros((d, d))
    A[:, : lengths.size] = U * (lengths * scale)  # columns: the scaled semi-axes
    t = np.linspace(0.0, 2 * np.pi, samples)
    circle = np.vstack([np.cos(t), np.sin(t)])
    pairs = ((0, 1),) if d == 2 else ((0, 1), (1, 2), (0, 2))
    pad = np.zeros((3 - d, samples))
    curves = [np.vstack([c[:, None] + A[:, [i, j]] @ circle, pad]) for i, j in pairs]
    z = [0.0] * (3 - d)
    segments = [[np.r_[c - A[:, k], z], np.r_[c + A[:, k], z]] for k in range(d)]
    return curves, segments


class EllipseArtist:
    """The image of the unit ball ‖θ̇‖ ≤ 1 under the chosen rows of J(θ), centred at the tool origin.

    ``semi_axes`` (σ_i of the rows, largest first, before ``scale``) and ``directions`` (the unit left
    singular vectors as columns), both from :func:`kinlib.manipulability.velocity_ellipsoid`, describe it; at
    a singular configuration a semi-axis is 0 and the ellipse is drawn as a segment. ``update(q)``.
    ``hold``: rows kept at zero (e.g. (2,) = ω_z): the ellipse {J_r θ̇ : J_h θ̇ = 0, ‖θ̇‖ ≤ 1} instead
    (``velocity_ellipsoid(J, rows, hold)``), e.g. the tool velocities reachable with the orientation held.

    >>> from kinlib.robots import planar_3r
    >>> from kinlib.plotting import draw_chain, draw_velocity_ellipse
    >>> chain = planar_3r(1, 1, 1)
    >>> art = draw_chain(chain, [0, 0, 0])
    >>> np.round(draw_velocity_ellipse(art.ax, chain, [0, 0, 0]).semi_axes, 4)
    array([3.7417, 0.    ])
    """

    def __init__(self, ax, chain, q, rows, scale, color, axes_lines, label, fill, hold=None, lw=1.8, ls="-", alpha=1.0):
        self.ax, self.chain, self.rows, self.scale = ax, chain, rows, scale
        self.hold = tuple(hold) if hold else None
        self.three_d = is_3d(ax)
        self.q = q
        curves, axes = self._compute(q)
        self.curves = [
            add_line(ax, cv, color=color, lw=lw, ls=ls, alpha=alpha, zorder=5, label=label if k == 0 else None)
            for k, cv in enumerate(curves)
        ]
        self.fill = None
        if fill and not self.three_d:
            self.fill = ax.fill(curves[0][0], curves[0][1], color=color, alpha=0.12, zorder=1)[0]
        self.axes = (
            add_segments(ax, axes, colors=color, linewidths=1.0, linestyles=":", zorder=5) if axes_lines else None
        )
        include(ax, np.hstack(curves))

    def _compute(self, q, J=None, p=None):
        J = self.chain.jacobian_geometric(q) if J is None else J
        if self.hold:
            self.semi_axes, self.directions = velocity_ellipsoid(J, list(self.rows), self.hold)
        else:
            self.semi_axes, self.directions = velocity_ellipsoid(J[list(self.rows)])
        p = self.chain.fk(q)[:3, 3] if p is None else p
        return ellipse_outline(p[: len(self.rows)], self.semi_axes, self.directions, self.scale)

    def update(self, q, J=None, p=None):
        """Move the ellipse to configuration ``q`` (``J``, ``p``: the geometric Jacobian and the tool origin
        there, when the caller has them already)."""
        q = as_configuration(self.chain, q)
        self.q = q
        curves, axes = self._compute(q, J, p)
        for ln, cv in zip(self.curves, curves):
            set_line(ln, cv)
        if self.fill is not None:
            self.fill.set_xy(curves[0][:2].T)
        if self.axes is not None:
            set_segments(self.axes, axes, self.three_d)
        return self

    @property
    def artists(self) -> list:
        """The artists that ``update`` moves (for blitting)."""
        return [a for a in (self.fill, *self.curves, self.axes) if a is not None]

    @property
    def manipulability(self) -> float:
        """Product of the semi-axes: √det(J Jᵀ) of the drawn rows (the ellipse's area/π in 2-D)."""
        return float(np.prod(self.semi_axes))
