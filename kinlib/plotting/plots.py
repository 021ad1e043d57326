"""Plots of what the Jacobian says: one row's joint contributions (bar chart), directions (column space,
left null space), the manipulability over one joint (curve) or two (map with the singular set), and paths
that sweep one joint.

The numbers come from the math core: task rows from :mod:`kinlib.taskspace`, the measures and the
strongest joints from :mod:`kinlib.manipulability`.

>>> from kinlib.robots import planar_offset_3r
>>> c = plot_manipulability_curve(planar_offset_3r(1), 2, num=9)
>>> c.values.shape
(9,)
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import sympy as sp

from .._backend import describe
from ..analysis.manipulability import manipulability_values, measure_label, strongest_joints
from ..analysis.taskspace import default_task_rows, rows_label, task_row_indices, task_rows
from .common import JOINT_COLORS, as_configuration, checked_numeric, default_ranges, is_3d, theta_tex
from .primitives import Arrows, add_text
from .view import include, pi_ticks

__all__ = [
    "plot_joint_contributions",
    "draw_directions",
    "held_span",
    "CurvePlot",
    "MapPlot",
    "plot_manipulability_curve",
    "plot_manipulability_map",
    "sweep",
]


def plot_joint_contributions(
    ax, values, *, title=None, ylabel=None, labels=None, colors=None, highlight=True, fmt="{:+.3f}"
):
    """A bar chart of one task row's joint contributions J[row, i] (what θ̇_i = 1 alone gives), one bar
    per joint in its colour, the value written on each bar; ``highlight`` outlines the joint(s) with the
    largest |value| (:func:`kinlib.manipulability.strongest_joints`: ties within 10⁻⁹ relative all
    outlined). Returns the BarContainer.

    >>> fig, ax = plt.subplots()
    >>> bars = plot_joint_contributions(ax, [0.5, -1.0, 1.0])
    >>> [b.get_linewidth() for b in bars]
    [1.0, 2.5, 2.5]
    """
    try:
        v = np.asarray(
            [float(x) for x in (list(values) if not isinstance(values, np.ndarray) else values.ravel())], float
        )
    except (TypeError, ValueError):
        raise TypeError(f"values must be numbers (one per joint), got {describe(values)}") from None
    if v.ndim != 1 or v.size == 0:
        raise ValueError(f"values must be a non-empty vector, got {describe(values)}")
    n = v.size
    x = np.arange(1, n + 1)
    colors = list(colors) if colors is not None else [JOINT_COLORS[i % 10] for i in range(n)]
    bars = ax.bar(x, v, color=colors)
    a = np.abs(v)
    best = set()
    if a.max() > 0:
        b = strongest_joints(v)
        best = {j - 1 for j in (b if isinstance(b, tuple) else (b,))}
    if highlight:
        for i in sorted(best):
            bars[i].set_edgecolor("k")
            bars[i].set_linewidth(2.5)
    for i, (xi, vi) in enumerate(zip(x, v)):
        ax.text(
            xi,
            vi,
            fmt.format(vi),
            ha="center",
            va="bottom" if vi >= 0 else "top",
            fontsize=9,
            fontweight="bold" if (highlight and i in best) else "normal",
        )
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xticks(x, labels if labels is not None else [theta_tex(i + 1, dot=True) for i in range(n)])
    top = float(a.max()) or 1.0
    lo, hi = min(0.0, float(v.min())), max(0.0, float(v.max()))
    ax.set_ylim(lo - 0.2 * top, hi + 0.2 * top)
    ax.grid(True, axis="y", lw=0.4, alpha=0.5)
    if title:
        ax.set_title(title, fontsize=10)
    if ylabel:
        ax.set_ylabel(ylabel)
    return bars


# --- directions (column space, left null space) -----------------------------------------------------------
def _beyond(v) -> dict:
    """Text alignment that puts a label just past the head of an arrow along v (not on top of it)."""
    n = float(np.linalg.norm(v[:2])) or 1.0
    ux, uy = v[0] / n, v[1] / n
    return dict(
        ha="left" if ux > 0.35 else "right" if ux < -0.35 else "center",
        va="bottom" if uy > 0.35 else "top" if uy < -0.35 else "center",
    )


def draw_directions(
    ax,
    origin,
    vectors,
    labels=None,
    *,
    colors=None,
    components=None,
    length=None,
    both_ways=False,
    linestyles=None,
    fontsize=9,
    lw=2.0,
    hold=None,
) -> list:
    """Arrows from ``origin`` along each vector (a list of vectors, or a matrix whose *columns* are the
    vectors, e.g. a column-space basis). ``components``: which entries of each vector to draw (e.g. (1, 2)
    for the ṗ_x, ṗ_y part of a (ω_z, ṗ_x, ṗ_y) vector); ``hold``: entries held at zero (e.g. (0,), the
    orientation rate ω_z): the vectors are first replaced by an orthonormal basis of the part of their span
    with those entries 0 (:func:`held_span`), so any basis of the same span gives the same arrows, and the
    arrows are the motions possible with the orientation held; ``length``: rescale each arrow to this length;
    ``both_ways``: a double-headed arrow (a direction, not a sense); ``linestyles``: e.g. ['-', '--'] to
    tell "can move" from "cannot move". Returns the list of FancyArrowPatch (2-D) or arrow artists (3-D).

    >>> fig, ax = plt.subplots()
    >>> arts = draw_directions(ax, (0, 0), [[0, 3, 4]], ["can move"], components=(1, 2), length=1)
    >>> [type(a).__name__ for a in arts]
    ['FancyArrowPatch', 'Annotation']
    >>> len(draw_directions(ax, (0, 0), np.array([[0.0, 1.0], [1.0, 0.0], [-1.0, 0.0]]), hold=(0,), components=(1, 2)))
    1
    """
    d = 3 if is_3d(ax) else 2
    if isinstance(vectors, sp.MatrixBase) or (isinstance(vectors, np.ndarray) and vectors.ndim == 2):
        M = np.asarray(sp.Matrix(vectors).evalf() if isinstance(vectors, sp.MatrixBase) else vectors, float)
        vecs = [M[:, j] for j in range(M.shape[1])]
    else:
        try:
            vecs = [
                np.asarray(
                    sp.Matrix(v).evalf() if isinstance(v, sp.MatrixBase) else [float(x) for x in v], float
                ).reshape(-1)
                for v in vectors
            ]
        except (TypeError, ValueError):
            raise TypeError(
                f"vectors must be a matrix (one vector per column) or a list of numeric vectors, "
                f"got {describe(vectors)}"
            ) from None
    if hold is not None:
        vecs = list(held_span(np.column_stack(vecs), hold).T)
        if labels is not None:
            labels = list(labels)[: len(vecs)]
    if components is not None:
        comp = list(components)
        vecs = [v[comp] for v in vecs]
    for k, v in enumerate(vecs):
        if v.shape != (d,):
            raise ValueError(
                f"vectors[{k}] must have {d} entries for {'3-D' if d == 3 else '2-D'} axes "
                f"(use components= to pick them), got {v.shape[0]}"
            )
    o = np.asarray([float(x) for x in origin], float)
    if o.shape != (d,):
        raise ValueError(f"origin must have {d} entries, got {describe(origin)}")
    if length is not None:
        vecs = [v * (length / np.linalg.norm(v)) if np.linalg.norm(v) > 0 else v for v in vecs]
    k = len(vecs)
    colors = (
        list(colors) if colors is not None else ["tab:blue", "tab:red", "tab:green", "tab:orange"][:k] * (1 + k // 4)
    )
    linestyles = list(linestyles) if linestyles is not None else ["-"] * k
    labels = list(labels) if labels is not None else [None] * k
    out = []
    if d == 2:
        from matplotlib.patches import FancyArrowPatch

        for v, c, ls, lab in zip(vecs, colors, linestyles, labels):
            start = o - v if both_ways else o
            a = FancyArrowPatch(
                start,
                o + v,
                arrowstyle="<|-|>" if both_ways else "-|>",
                mutation_scale=16,
                color=c,
                lw=lw,
                linestyle=ls,
                zorder=7,
                label=lab,
            )
            ax.add_patch(a)
            out.append(a)
            if lab:
                al = _beyond(v)
                off = ({"left": 4, "right": -4, "center": 0}[al["ha"]], {"bottom": 4, "top": -4, "center": 0}[al["va"]])
                out.append(
                    ax.annotate(
                        lab,
                        xy=tuple(o + v),
                        xytext=off,
                        textcoords="offset points",
                        color=c,
                        fontsize=fontsize,
                        zorder=8,
                        **al,
                    )
                )
    else:
        for v, c, ls, lab in zip(vecs, colors, linestyles, labels):
            arr = Arrows(ax, o[None], v[None], [c], linestyle=ls, lw=lw, zorder=7, label=lab)
            out.append(arr.artist)
            if both_ways:
                out.append(Arrows(ax, o[None], -v[None], [c], linestyle=ls, lw=lw, zorder=7).artist)
            if lab:
                out.append(add_text(ax, o + v, lab, color=c, fontsize=fontsize, zorder=8, **_beyond(v[:2])))
    ends = [o + 1.2 * v for v in vecs] + ([o - v for v in vecs] if both_ways else []) + [o]
    include(ax, np.column_stack(ends))
    return out


def held_span(vectors, hold, tol: float = 1e-9) -> np.ndarray:
    """An orthonormal basis (columns) of {x ∈ span(vectors) : x[i] = 0 for i in ``hold``}: the directions of a
    span that keep the held entries at zero (e.g. the tool translations of range J with ω_z = 0). Any basis of
    the same span gives the same subspace; the basis is ordered by its first nonzero entry's index.

    >>> held_span(np.array([[1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]), (0,)).round(6).T.tolist()
    [[0.0, 0.707107, -0.707107]]
    >>> held_span(np.array([[0.0, 1.0], [1.0, 0.0], [-1.0, 0.0]]), (0,)).round(6).T.tolist()   # columns swapped
    [[0.0, 0.707107, -0.707107]]
    """
    A = np.asarray(vectors, float)
    if A.ndim != 2:
        raise ValueError(f"vectors must be a matrix (one vector per column), got {describe(vectors)}")
    hold = [int(i) for i in hold]
    if any(not 0 <= i < A.shape[0] for i in hold):
        raise ValueError(f"hold must list entries 0…{A.shape[0] - 1}, got {describe(hold)}")
    U, s, _ = np.linalg.svd(A, full_matrices=False)
    B = U[:, s > tol * max(s[0] if s.size else 0.0, 1.0)]  # orthonormal basis of the span
    if not B.size:
        return np.zeros((A.shape[0], 0))
    _, s2, Vt = np.linalg.svd(B[hold, :]) if hold else (None, np.zeros(0), np.eye(B.shape[1]))
    rank = int(np.sum(s2 > tol))
    N = Vt[rank:].T  # combinations of B with the held entries 0
    H = B @ N
    if not H.size:
        return H
    Q, _ = np.linalg.qr(H)
    Q = Q[:, : H.shape[1]]
    # a canonical orthonormal basis of the subspace: the rows of its projector, reduced
    P = Q @ Q.T
    cols = []
    for j in range(P.shape[0]):
        v = P[:, j] - sum((c @ P[:, j]) * c for c in cols)
        if np.linalg.norm(v) > 1e-6:
            v = v / np.linalg.norm(v)
            cols.append(v * (1 if v[np.flatnonzero(np.abs(v) > 1e-9)[0]] > 0 else -1))
        if len(cols) == Q.shape[1]:
            break
    return np.column_stack(cols)


# --- manipulability over one or two joints ----------------------------------------------------------------
@dataclass
class CurvePlot:
    """Result of :func:`plot_manipulability_curve`: ``x`` (joint values), ``values`` (the measure),
    ``joint`` (1-based), ``line`` and ``markers`` (maxima, zeros).

    >>> from kinlib.robots import planar_3r
    >>> plot_manipulability_curve(planar_3r(1, 1, 1), 2, num=5).joint
    2
    """

    ax: Any
    line: Any
    x: np.ndarray
    values: np.ndarray
    joint: int
    markers: list = field(default_factory=list)


@dataclass
class MapPlot:
    """Result of :func:`plot_manipulability_map`: grid ``x`` (joint i), ``y`` (joint j), ``values[y, x]``,
    ``joints`` (1-based), ``image`` and ``singular`` (the drawn singular set).

    >>> from kinlib.robots import planar_3r
    >>> plot_manipulability_map(planar_3r(1, 1, 1), (2, 3), num=5).values.shape
    (5, 5)
    """

    ax: Any
    image: Any
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray
    joints: tuple
    singular: list = field(default_factory=list)


def plot_manipulability_curve(
    chain,
    joint,
    q_fixed=None,
    *,
    rows=None,
    measure="yoshikawa",
    lim=None,
    num=721,
    ax=None,
    mark_max=True,
    mark_zero=True,
    params=None,
    label=None,
) -> CurvePlot:
    """The manipulability measure (see :func:`kinlib.manipulability.manipulability_values`) of the task rows
    of the geometric Jacobian as joint ``joint`` (1-based) sweeps ``lim`` (default its range), the others fixed
    at ``q_fixed`` (zeros). Default rows: the chain's task space (:func:`kinlib.taskspace.default_task_rows`).
    Marks the maxima and the zeros (singular configurations) found on the grid.

    >>> from kinlib.robots import planar_3r
    >>> c = plot_manipulability_curve(planar_3r(1, 1, 1), 2, rows="xy", lim=(0, 3.1416), num=3)
    >>> np.round(c.values, 3)
    array([0.   , 2.236, 0.   ])
    """
    chain = checked_numeric(chain, params)
    i = chain.joint_index(joint)
    q0 = as_configuration(chain, q_fixed, "q_fixed")
    r = task_row_indices(rows, default=default_task_rows(chain))
    lo, hi = lim if lim is not None else default_ranges(chain)[i]
    x = np.linspace(lo, hi, num)
    Q = np.tile(q0, (num, 1))
    Q[:, i] = x
    vals = manipulability_values(task_rows(chain.jacobian_geometric(Q), r), measure)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3.5))
    ylabel = measure_label(measure, len(r), chain.n)
    (line,) = ax.plot(x, vals, lw=2, label=label or ylabel)
    ax.set_xlabel(theta_tex(i + 1) + (" (rad)" if chain.joint_types[i] == "R" else ""))
    ax.set_ylabel(ylabel)
    ax.set_title(f"{chain.name}: {ylabel} of rows ({rows_label(r, tex=True)}) over {theta_tex(i + 1)}")
    ax.grid(True, lw=0.4, alpha=0.5)
    if chain.joint_types[i] == "R" and hi - lo >= math.pi / 2:
        pi_ticks(ax.xaxis, lo, hi, 4 if hi - lo <= 2 * math.pi + 1e-9 else 2)
    marks = []
    top = float(np.max(np.abs(vals))) or 1.0
    if mark_max:
        k = np.flatnonzero(vals >= vals.max() - 1e-9 * top)
        marks.append(ax.plot(x[k], vals[k], "v", color="tab:green", ms=8, label="maximum")[0])
    if mark_zero:
        k = np.flatnonzero(np.abs(vals) <= 1e-9 * top)
        s = np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)  # sign changes (measure='det')
        xs = np.r_[x[k], x[s] - vals[s] * (x[s + 1] - x[s]) / (vals[s + 1] - vals[s])]
        if xs.size:
            marks.append(ax.plot(xs, np.zeros_like(xs), "o", color="tab:red", ms=7, label="singular")[0])
    return CurvePlot(ax, line, x, vals, i + 1, marks)


def plot_manipulability_map(
    chain,
    joints=(1, 2),
    q_fixed=None,
    *,
    rows=None,
    measure="yoshikawa",
    lims=None,
    num=181,
    ax=None,
    singular=True,
    params=None,
    cmap="viridis",
    colorbar=True,
) -> MapPlot:
    """Heat map of a manipulability measure over two joints ``joints`` = (i, j) (1-based), the others
    fixed at ``q_fixed``, with the singular set drawn in red. Default rows as for
    :func:`plot_manipulability_curve`.

    ``singular``: True draws the zero contour of det J (square task rows; exact sign change) or, for
    non-square rows, the contour σ_min/σ_max = 10⁻³ hugging the set where the rank drops; False draws
    nothing; or a list of curves ``[(xs, ys), ...]`` / a dict ``{label: (xs, ys)}`` (e.g. from the exact
    singular set) drawn as given.

    >>> from kinlib.robots import planar_offset_3r
    >>> m = plot_manipulability_map(planar_offset_3r(1), (1, 2), num=31)
    >>> len(m.singular) > 0    # θ2 = −π/4 and 3π/4 (problem 5.1)
    True
    """
    chain = checked_numeric(chain, params)
    if not isinstance(joints, (tuple, list)) or len(joints) != 2:
        raise ValueError(f"joints must be two joint numbers (i, j), got {describe(joints)}")
    i, j = (chain.joint_index(k, "joints") for k in joints)
    if i == j:
        raise ValueError(f"joints must be two different joints, got {joints}")
    q0 = as_configuration(chain, q_fixed, "q_fixed")
    r = task_row_indices(rows, default=default_task_rows(chain))
    rngs = default_ranges(chain)
    (xlo, xhi), (ylo, yhi) = lims if lims is not None else (rngs[i], rngs[j])
    x, y = np.linspace(xlo, xhi, num), np.linspace(ylo, yhi, num)
    X, Y = np.meshgrid(x, y)
    Q = np.tile(q0, (X.size, 1))
    Q[:, i], Q[:, j] = X.ravel(), Y.ravel()
    J = task_rows(chain.jacobian_geometric(Q), r)
    vals = manipulability_values(J, measure).reshape(X.shape)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 5))
    m, n = len(r), chain.n
    label = measure_label(measure, m, n)
    im = ax.pcolormesh(X, Y, vals, shading="auto", cmap=cmap)
    if colorbar:
        ax.figure.colorbar(im, ax=ax, label=label)
    sing = []
    if singular is True:
        if m == n:
            D = manipulability_values(J, "det").reshape(X.shape)
            if np.nanmin(D) < 0 < np.nanmax(D):
                sing.append(ax.contour(X, Y, D, levels=[0.0], colors="red", linewidths=2))
        else:
            ic = manipulability_values(J, "inverse_condition").reshape(X.shape)
            if np.nanmin(ic) < 1e-3:
                sing.append(ax.contour(X, Y, ic, levels=[1e-3], colors="red", linewidths=2))
        if sing:
            ax.plot([], [], color="red", lw=2, label="singular set")
    elif singular:
        items = singular.items() if isinstance(singular, Mapping) else [(None, c) for c in singular]
        for k, (lab, (xs, ys)) in enumerate(items):
            sing.append(
                ax.plot(xs, ys, color="red", lw=2, label=lab if lab else ("singular set" if k == 0 else None))[0]
            )
    ax.set_xlim(xlo, xhi)
    ax.set_ylim(ylo, yhi)
    ax.set_xlabel(theta_tex(i + 1))
    ax.set_ylabel(theta_tex(j + 1))
    for k, (lo, hi), axis in ((i, (xlo, xhi), ax.xaxis), (j, (ylo, yhi), ax.yaxis)):
        if chain.joint_types[k] == "R" and hi - lo >= math.pi / 2:
            pi_ticks(axis, lo, hi, 2)
    # the singular set is named in the title, not in a legend box that would sit on the map's curves
    note = "\nred: the singular set" if sing else ""
    ax.set_title(f"{chain.name}: {label} of rows ({rows_label(r, tex=True)}){note}")
    return MapPlot(ax, im, x, y, vals, (i + 1, j + 1), sing)


def sweep(chain, joint, values, q_fixed=None, params=None) -> np.ndarray:
    """A path (N, n): joint ``joint`` (1-based) takes ``values``, the others stay at ``q_fixed`` (zeros).

    >>> from kinlib.robots import planar_3r
    >>> sweep(planar_3r(1, 1, 1), 2, [0.0, 0.5], q_fixed=[1, 0, 0])
    array([[1. , 0. , 0. ],
           [1. , 0.5, 0. ]])
    """
    chain = checked_numeric(chain, params)
    i = chain.joint_index(joint)
    q0 = as_configuration(chain, q_fixed, "q_fixed")
    v = np.asarray(values, float).reshape(-1)
    Q = np.tile(q0, (v.size, 1))
    Q[:, i] = v
    return Q
