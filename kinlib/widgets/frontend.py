"""The browser front end of every kinlib picture that moves — the explorer, the animation of a path and the
configuration picker — assembled into one self-contained ``application/javascript`` output.

The JavaScript lives beside this file: ``core.js`` (shared: the numbers from the generated ``skel(q)`` and
``jg(q)``, the drawing of the arm, its ellipses and the blocked direction, the banner by the course's one near
rule, the words of the ``aria-live`` sentence, the styles) and one file per picture (``explorer.js``,
``animation.js``, ``picker.js``). :func:`script` puts the shared part, the picture's part, the functions that
kinlib generated for the chain (SymPy's JavaScript printer on the CSE'd expressions the NumPy code comes from)
and the picture's spec together, and calls ``window.<entry>(host, S)`` on the output's element (JupyterLab and
JupyterLite pass it as ``element``; a static page's ``<script>`` finds its parent). Why this mechanism and not a
widget framework: :mod:`kinlib.widgets.explorer`.

>>> js = script("explorer", ["function skel(q) { return []; }", "function jg(q) { return []; }"], {"n": 0})
>>> "window.kinlibFront" in js and js.rstrip().endswith("})();") and "window.kinlibExplorer(host, S);" in js
True
"""

from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

__all__ = ["script", "source", "ENTRIES", "square_view"]

_DIR = Path(__file__).parent

#: the pictures and the function each file defines on ``window``
ENTRIES = {"explorer": "kinlibExplorer", "animation": "kinlibAnimation", "picker": "kinlibPicker"}


@lru_cache(maxsize=8)
def source(name: str) -> str:
    """The text of ``kinlib/widgets/<name>.js`` (``core``, or one of :data:`ENTRIES`).

    >>> "window.kinlibFront" in source("core")
    True
    """
    if name != "core" and name not in ENTRIES:
        raise ValueError(f"name must be 'core' or one of {sorted(ENTRIES)}, got {name!r}")
    return (_DIR / f"{name}.js").read_text(encoding="utf-8")


def script(entry: str, funcs: list[str], spec: dict, conditions: int = 0) -> str:
    """The output for the picture ``entry`` (a key of :data:`ENTRIES`): the shared front end, the picture's
    part, the generated functions ``funcs`` (``skel``, ``jg`` and ``c0`` … ``c{conditions-1}``, the closed-form
    singular conditions) and ``spec`` (JSON; ``<`` escaped, so that the text is safe inside ``<script>``).

    >>> js = script("picker", ["function skel(q) { return []; }", "function jg(q) { return []; }"], {"a": "</script>"})
    >>> "window.kinlibPicker(host, S);" in js and "</script>" not in js
    True
    """
    if entry not in ENTRIES:
        raise ValueError(f"entry must be one of {sorted(ENTRIES)}, got {entry!r}")
    text = json.dumps(spec, ensure_ascii=False, separators=(",", ":")).replace("<", "\\u003c")
    fns = ",".join(f"c{k}" for k in range(conditions))
    return (
        source("core")
        + "\n"
        + source(entry)
        + "\n(function () {\n"
        + "\n".join(funcs)
        + f"\nvar S = {text};\nS.skel = skel; S.jg = jg; S.condFns = [{fns}];\n"
        + f"window.__kinlibN = (window.__kinlibN || 0) + 1; S.id = 'kinlib-{entry}-' + window.__kinlibN;\n"
        + "var host = (typeof element !== 'undefined' && element) ? (element.jquery ? element[0] : element) : document.currentScript.parentNode;\n"
        + f"window.{ENTRIES[entry]}(host, S);\n}})();\n"
    )


def square_view(points, planar: bool, margin: float = 0.0) -> dict:
    """The drawing's extent around ``points`` (3×N, world units) plus ``margin`` on every side: planar, a square
    {x0, x1, y0, y1, tick} (equal axes; ``tick`` a round grid step, about six per side); spatial, a ball {c, r}
    (centre lifted to the floor z = 0 at least) and the first view angles {az, el}.

    >>> v = square_view(np.array([[0.0, 2.0], [0.0, 1.0], [0.0, 0.0]]), True); (round(v["x1"] - v["x0"], 6), v["tick"])
    (2.16, 0.5)
    """
    pts = np.asarray(points, float).reshape(3, -1)
    lo, hi = pts.min(axis=1) - margin, pts.max(axis=1) + margin
    c = 0.5 * (lo + hi)
    if planar:
        half = 0.5 * float(max(hi[0] - lo[0], hi[1] - lo[1])) * 1.08 + 1e-9
        raw = 2 * half / 6
        mag = 10 ** math.floor(math.log10(raw))
        tick = min((m * mag for m in (1, 2, 2.5, 5, 10) if m * mag >= raw), default=10 * mag)
        x, y = float(c[0]), float(c[1])
        return {"x0": x - half, "x1": x + half, "y0": y - half, "y1": y + half, "tick": tick}
    c[2] = max(c[2], 0.0)
    r = float(np.max(np.linalg.norm(pts - c[:, None], axis=0))) + margin
    return {"c": c.tolist(), "r": r, "az": 0.6, "el": 0.45}
