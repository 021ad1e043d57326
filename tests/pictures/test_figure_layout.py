"""Figures a student can trust (issue 21, item 8): no legend box covers the drawn arm, an ellipse or an arrow.

Every static figure the notebooks draw is drawn again here: each notebook's code cells run in order in one
namespace with matplotlib's Agg backend (the explorers and the animation, which are not static figures, and
the check cells, which draw nothing, are skipped), and every figure a cell leaves (``plt.show()`` or the
cell's end) is measured. After ``canvas.draw()``, each legend's box (its renderer window extent) is tested
against the drawn content of every axes of the figure in display coordinates: the paths of lines, patches
(the arm's links, the ellipses, the arrows) and line collections (3-D arms and arrows, contours), and the
markers of marker-only lines and scatter plots. A path that enters the box, or a marker inside it, is an
overlap. Legend handles are not content, images and filled maps are background.

The measuring itself is tested first on figures whose answer is known (a legend put on a line, an arrow, an
ellipse; one put beside the axes).
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.collections import LineCollection, PathCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Ellipse, FancyArrowPatch  # noqa: E402
from matplotlib.path import Path as MPath  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("0[1-7]_*.ipynb"))
SKIP_CELL = ("widgets.", "animate_singularity(", "config_picker(")


def _content(ax):
    """(label, kind, display path or points) for every drawn line, patch and collection of ``ax``."""
    out = []
    for a in ax.lines:
        if not a.get_visible():
            continue
        xy = a.get_transform().transform(np.asarray(a.get_xydata(), float).reshape(-1, 2))
        xy = xy[np.all(np.isfinite(xy), axis=1)]
        if not len(xy):
            continue
        kind = "points" if a.get_linestyle() in ("None", "", " ", "none") else "path"
        out.append((a.get_label(), kind, xy if kind == "points" else MPath(xy)))
        if kind == "path" and a.get_marker() not in (None, "None", "", " ", "none"):
            out.append((a.get_label(), "points", xy))
    for p in ax.patches:
        if p.get_visible():
            out.append((p.get_label() or type(p).__name__, "patch", p.get_transform().transform_path(p.get_path())))
    for c in ax.collections:
        if not c.get_visible():
            continue
        if isinstance(c, PathCollection) and len(c.get_offsets()):
            xy = c.get_offset_transform().transform(np.asarray(c.get_offsets(), float))
            out.append((c.get_label() or "scatter", "points", xy))
        elif isinstance(c, LineCollection) or type(c).__name__ in ("ContourSet", "QuadContourSet"):
            t = c.get_transform()
            for path in c.get_paths():
                if len(path.vertices):
                    out.append((c.get_label() or type(c).__name__, "path", t.transform_path(path)))
    return out


def legend_overlaps(fig) -> list[str]:
    """The drawn artists any legend box of ``fig`` overlaps (empty: none)."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None] + list(fig.legends)
    found = []
    for leg in legends:
        if not leg.get_visible():
            continue
        box = leg.get_window_extent(renderer).expanded(0.98, 0.98)  # a pixel of anti-aliasing tolerated
        for ax in fig.axes:
            for label, kind, geom in _content(ax):
                if kind == "points":
                    x, y = geom[:, 0], geom[:, 1]
                    hit = bool(np.any((x >= box.x0) & (x <= box.x1) & (y >= box.y0) & (y <= box.y1)))
                else:
                    hit = geom.intersects_bbox(box, filled=(kind == "patch"))
                if hit:
                    found.append(f"legend {[t.get_text()[:30] for t in leg.get_texts()][:3]} covers {label!r}")
    return found


# --- the measure, on figures with a known answer -------------------------------------------------------------


def _arm(ax):
    ax.plot([0, 1, 2], [0, 0.5, 0.2], lw=4, label="arm")
    ax.add_patch(Ellipse((1.5, 0.8), 0.8, 0.3, fill=False, label="ellipse"))
    ax.add_patch(FancyArrowPatch((0.2, 0.9), (0.9, 0.95), arrowstyle="-|>", mutation_scale=12, label="arrow"))
    ax.set_xlim(-0.2, 2.2)
    ax.set_ylim(-0.2, 1.2)


@pytest.mark.parametrize("what", ["arm", "ellipse", "arrow"])
def test_a_legend_on_the_drawing_is_found(what):
    fig, ax = plt.subplots(figsize=(4, 3))
    _arm(ax)
    spot = {"arm": (1.0, 0.5), "ellipse": (1.5, 0.8), "arrow": (0.55, 0.93)}[what]
    ax.legend(
        handles=[Line2D([], [], label="a legend entry")], loc="center", bbox_to_anchor=spot, bbox_transform=ax.transData
    )
    found = legend_overlaps(fig)
    plt.close(fig)
    assert any(what in f or (what == "arm" and "'arm'" in f) for f in found), found


def test_a_legend_beside_the_axes_overlaps_nothing():
    fig, ax = plt.subplots(figsize=(5, 3))
    _arm(ax)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.tight_layout()
    assert legend_overlaps(fig) == []
    plt.close(fig)


# --- every static figure of the notebooks ----------------------------------------------------------------------


def _figures_of(path: Path):
    """Run the notebook's code cells (see the module text) and yield (cell id, figure) for each figure left."""
    nb = json.loads(path.read_text())
    ns: dict = {"display": lambda *a, **k: None, "__name__": "__main__"}
    shown: list = []

    def show(*_a, **_k):
        shown.extend(plt.figure(n) for n in plt.get_fignums())

    real_show = plt.show
    plt.show = show
    try:
        for cell in nb["cells"]:
            if cell["cell_type"] != "code":
                continue
            src = "".join(cell["source"])
            tags = cell["metadata"].get("tags", [])
            if "check" in tags or any(s in src for s in SKIP_CELL):
                continue
            lines = [ln for ln in src.splitlines() if not ln.lstrip().startswith(("%", "!"))]
            exec(compile("\n".join(lines), f"{path.name}:{cell.get('id')}", "exec"), ns)  # noqa: S102
            show()
            seen = set()
            for fig in shown:
                if id(fig) not in seen:
                    seen.add(id(fig))
                    yield cell.get("id"), fig
            shown.clear()
            plt.close("all")
    finally:
        plt.show = real_show
        plt.close("all")


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem[:2])
def test_no_legend_covers_the_drawing_in_any_notebook_figure(path):
    problems, count = [], 0
    for cid, fig in _figures_of(path):
        count += 1
        problems += [f"{path.name} cell {cid}: {f}" for f in legend_overlaps(fig)]
    assert count >= 1, f"{path.name} drew no static figure"
    assert not problems, "\n".join(problems)


# --- 5.3's directions: any basis gives the same arrows, and "can" never lies on "cannot" ---------------------------


@pytest.mark.parametrize(
    "basis",
    [
        [[1, 0], [0, 1], [0, -1]],  # the printed (48), up to scale
        [[0, 1], [1, 0], [-1, 0]],  # its columns swapped: drew no arrow before
        [[2, 1], [3, 0], [-3, 0]],  # mixed columns, other lengths
        [[1, 1, 0], [0, 1, 1], [0, -1, -1]],  # three spanning columns
    ],
)
def test_5_3_arrows_from_any_basis_and_never_on_top_of_each_other(basis):
    from kinlib.plotting import draw_directions, held_span

    fig, ax = plt.subplots()
    can = draw_directions(ax, (0, 0), np.array(basis, float), hold=(0,), components=(1, 2), both_ways=True)
    assert len(draw_directions(ax, (0, 0), np.array([[0.0], [1.0], [1.0]]), components=(1, 2))) == 1
    arrows = [a for a in can if isinstance(a, FancyArrowPatch)]
    assert len(arrows) == 1  # one translation is possible with the orientation held: the −45° line
    u, w = held_span(np.array(basis, float), (0,))[1:, 0], np.array([1.0, 1.0]) / np.sqrt(2)
    assert np.isclose(abs(u @ np.array([1, -1]) / np.sqrt(2)), 1.0)
    assert abs(u @ w) < 1e-12  # perpendicular: they cannot sit on top of each other
    plt.close(fig)
