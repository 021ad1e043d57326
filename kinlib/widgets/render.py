"""Rendering for the explorers (:mod:`kinlib.widgets`): a matplotlib Figure off pyplot, drawn with Agg,
its static part cached (blitting), encoded as PNG or JPEG; and the display bundle that carries a static
``image/png`` of the picture beside the live widget view (what a notebook shows without a widget manager).

>>> fig, ax = new_figure((2, 2), 50, False)
>>> render_png(fig)[1:4]
b'PNG'
"""

from __future__ import annotations

import base64
import io
from collections.abc import Sequence

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

__all__ = ["data_url", "encode_canvas", "make_palette", "render_png", "Blitter", "new_figure", "display_bundle"]


def data_url(data: bytes, fmt: str = "png") -> bytes:
    """``data:image/<fmt>;base64,…`` (as bytes): the value of an ``ipywidgets.Image(format="url")``.
    The explorers send their pictures this way: the browser decodes a data URL in the page itself, while the
    Blob URL that ``format="png"`` makes is resolved through Chromium's browser process, ≈ 10 ms more from
    the new picture's arrival to its load event on every slider move (measured in JupyterLab, bench/bench.py).

    >>> data_url(b"GIF89a", "png")[:22], data_url(b"GIF89a", "png")[22:]
    (b'data:image/png;base64,', b'R0lGODlh')
    """
    if fmt not in ("png", "jpeg"):
        raise ValueError(f"fmt must be 'png' or 'jpeg', got {fmt!r}")
    return b"data:image/" + fmt.encode() + b";base64," + base64.b64encode(bytes(data))


def encode_canvas(canvas, fmt: str = "png", palette=None) -> bytes:
    """The canvas as PNG (RGB, fast zlib level 1) or JPEG (quality 90, slightly soft lines). With
    ``palette`` (a Pillow "P" image, see :func:`make_palette`) the PNG is 8-bit indexed: each pixel mapped
    to its nearest palette colour without dithering — about 10× faster to encode than RGB (Pillow filters
    RGB rows adaptively, the most of the time) and half the bytes.

    >>> fig, ax = new_figure((1, 1), 40, False)
    >>> fig.canvas.draw(); encode_canvas(fig.canvas, "jpeg")[6:10]   # a JFIF header
    b'JFIF'
    """
    from PIL import Image

    w, h = canvas.get_width_height(physical=True)
    im = Image.frombuffer("RGBA", (w, h), canvas.buffer_rgba(), "raw", "RGBA", 0, 1).convert("RGB")
    buf = io.BytesIO()
    if fmt == "jpeg":
        im.save(buf, format="jpeg", quality=90)
    elif palette is not None:
        im.quantize(palette=palette, dither=Image.Dither.NONE).save(buf, format="png", compress_level=1)
    else:
        im.save(buf, format="png", compress_level=1)
    return buf.getvalue()


def make_palette(canvas, colors: Sequence = ()):
    """A 256-colour palette (Pillow "P" image) for :func:`encode_canvas`: median cut over the picture on the
    canvas and swatches of ``colors`` blended with white at several opacities (so colours drawn later and
    their antialiased edges have near matches).

    >>> fig, ax = new_figure((1, 1), 40, False)
    >>> fig.canvas.draw(); make_palette(fig.canvas, ["tab:red"]).mode
    'P'
    """
    import numpy as np
    from matplotlib.colors import to_rgb
    from PIL import Image

    w, h = canvas.get_width_height(physical=True)
    img = np.asarray(canvas.buffer_rgba())[:, :, :3].reshape(-1, 3)
    sw = [np.asarray(to_rgb(c)) for c in colors] + [np.zeros(3), np.full(3, 0.5)]
    blends = [255 * (a * c + (1 - a)) for c in sw for a in (1.0, 0.8, 0.6, 0.4, 0.25, 0.12)]
    swatch = np.repeat(np.asarray(blends, float).round().astype(np.uint8), 400, axis=0)  # weight: 400 pixels each
    px = np.vstack([img, swatch])
    pal = Image.fromarray(px[None, :, :]).quantize(colors=256, method=Image.Quantize.MEDIANCUT)
    # the pure colours (white paper, black text, each artist's colour) exactly: median cut gives box averages,
    # and Pillow maps a pixel to the entry nearest the corner of its cell in a 6-bit colour cache (up to 3
    # levels off), so every entry within 10 levels of a pure colour becomes that colour: then no other
    # entry can be nearer and the pure colours come out exact
    P = np.asarray(pal.getpalette()[: 3 * 256], float).reshape(-1, 3)
    keys = [np.full(3, 255.0), np.zeros(3)] + [np.round(255 * c) for c in sw]
    for k in keys:
        near = np.max(np.abs(P - k), axis=1) <= 10
        near[int(np.argmin(np.sum((P - k) ** 2, axis=1)))] = True
        P[near] = k
    pal.putpalette(P.astype(np.uint8).reshape(-1).tolist())
    return pal


def render_png(fig: Figure) -> bytes:
    """Draw the whole figure with Agg and encode it as PNG (full colour).

    >>> fig, ax = new_figure((1, 1), 40, False)
    >>> render_png(fig)[1:4]
    b'PNG'
    """
    fig.canvas.draw()
    return encode_canvas(fig.canvas)


class Blitter:
    """Render a figure whose static part (axes, grid, ticks, legend, {s}) is drawn once and cached;
    each render restores that background and draws only the moving artists, then encodes a PNG — 8-bit,
    with the palette made at the first render from the picture and the colours of the moving artists
    (and ``colors``: those of artists shown later) — or a JPEG (``fmt="jpeg"``).

    >>> fig, ax = new_figure((1, 1), 40, False)
    >>> Blitter(fig, ax.plot([0, 1], [0, 1], color="tab:red")).render()[1:4]
    b'PNG'
    """

    def __init__(self, fig: Figure, artists: Sequence, fmt: str = "png", colors: Sequence = ()):
        self.fig, self.artists, self.fmt = fig, [a for a in artists if a is not None], fmt
        for a in self.artists:
            a.set_animated(True)
        self.background = None
        self.colors = list(colors)
        self.palette = None

    def render(self) -> bytes:
        canvas = self.fig.canvas
        if self.background is None:
            canvas.draw()  # animated artists are skipped
            self.background = canvas.copy_from_bbox(self.fig.bbox)
        else:
            canvas.restore_region(self.background)
        renderer = canvas.get_renderer()
        for a in self.artists:
            if hasattr(a, "do_3d_projection") and hasattr(a, "set_segments"):
                a.do_3d_projection()
            a.draw(renderer)
        if self.fmt == "png" and self.palette is None:
            self.palette = make_palette(canvas, self.colors + _artist_colors(self.artists))
        return encode_canvas(canvas, self.fmt, self.palette)


def _artist_colors(artists) -> list:
    """Every colour the artists draw with (lines, markers, collections, texts), as RGB rows."""
    from matplotlib.colors import to_rgba_array

    out = []
    for a in artists:
        for get in ("get_color", "get_facecolor", "get_edgecolor", "get_markerfacecolor", "get_markeredgecolor"):
            if hasattr(a, get):
                try:
                    out += [tuple(c[:3]) for c in to_rgba_array(getattr(a, get)())]
                except (ValueError, TypeError):
                    continue
    return out


def new_figure(figsize, dpi, three_d: bool):
    """A Figure with an Agg canvas, not registered with pyplot, and its one (2-D or 3-D) axes.

    >>> fig, ax = new_figure((2, 2), 50, True); type(fig.canvas).__name__, ax.name
    ('FigureCanvasAgg', '3d')
    """
    fig = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot(projection="3d" if three_d else None)


def display_bundle(bundle: dict, png: bytes, text: str) -> dict:
    """A widget's display bundle with a static picture: ``image/png`` (base64) of the current figure and a
    readable ``text/plain`` beside the ``application/vnd.jupyter.widget-view+json`` view.

    JupyterLab picks the widget view (its renderer is ranked first but marked unsafe) in a trusted notebook
    with a live kernel or saved widget state; in an untrusted notebook (freshly opened) only safe renderers
    are allowed, so it shows the PNG instead of the text; nbconvert and GitHub show the PNG too.

    >>> b = display_bundle({"text/plain": "Explorer(children=..."}, b"PNG", "an explorer")
    >>> sorted(b), b["text/plain"]
    (['image/png', 'text/plain'], 'an explorer')
    """
    out = dict(bundle)
    out["image/png"] = base64.b64encode(png).decode("ascii")
    out["text/plain"] = text
    return out
