"""Interactive pictures (the pictures layer, beside :mod:`kinlib.plotting`): ``from kinlib import widgets``.

* :func:`explorer` — a slider per joint, the arm, ṗ = J θ̇, the velocity ellipses, det J, manipulability,
  σ_min/σ_max and the singular set on the sliders, computed in the browser from JavaScript that kinlib
  generates from the chain's expressions (:mod:`kinlib.widgets.explorer`: why, and how it is shown in
  JupyterLab, JupyterLite, the static pages and the PDF);
* :func:`config_picker` — named configurations (problem 4.1) and each joint's contribution to a row of J.
"""

from .explorer import FRONT_END, Explorer, classify_families, explorer
from .picker import ConfigPicker, config_picker

__all__ = ["explorer", "Explorer", "config_picker", "ConfigPicker", "classify_families", "FRONT_END"]
