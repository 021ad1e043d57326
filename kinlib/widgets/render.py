"""PNG pictures for the configuration picker (:mod:`kinlib.widgets.picker`): a matplotlib Figure off pyplot
encoded once per button press, sent as a data URL, and the display bundle that carries a static ``image/png``
beside the live widget view (what a notebook shows without a widget manager). The explorers draw in the
browser (:mod:`kinlib.widgets.explorer`): no frame pipeline is left here.

>>> from matplotlib.backends.backend_agg import FigureCanvasAgg
>>> fig = Figure(figsize=(2, 2), dpi=50); _ = FigureCanvasAgg(fig); _ = fig.add_subplot()
>>> render_png(fig)[1:4]
b'PNG'
"""

from __future__ import annotations

import base64
import io

from matplotlib.figure import Figure

__all__ = ["data_url", "render_png", "display_bundle"]


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


def render_png(fig: Figure) -> bytes:
    """Draw the whole figure with Agg and encode it as PNG (full colour).

    >>> from matplotlib.backends.backend_agg import FigureCanvasAgg
    >>> fig = Figure(figsize=(1, 1), dpi=40); _ = FigureCanvasAgg(fig)
    >>> render_png(fig)[1:4]
    b'PNG'
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    return buf.getvalue()


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
