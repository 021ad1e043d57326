"""Interactive pictures (the pictures layer, beside :mod:`kinlib.plotting`): ``from kinlib import widgets``.

Every one is drawn and recomputed in the browser, from JavaScript that kinlib generates from the chain's
expressions, by one front end (:mod:`kinlib.widgets.frontend`; why, and how it is shown in JupyterLab,
JupyterLite, the static pages and the PDF: :mod:`kinlib.widgets.explorer`):

* :func:`explorer` — a slider per joint, the arm, ṗ = J θ̇, the velocity ellipses, det J, manipulability,
  σ_min/σ_max and the singular set on the sliders;
* :func:`animate_singularity` — the arm along a path through a singular configuration (problem 5.2), played
  and scrubbed step by step, beside the manipulability along the path;
* :func:`config_picker` — named configurations (problem 4.1) and each joint's contribution to a row of J;
* :func:`without_answers` — the students' version of any of them: nothing that answers a graded part (the
  singular set on the sliders, the state, det J, the manipulability and its maximum) is shown or sent.
"""

from .animation import SingularityAnimation, animate_singularity
from .explorer import FRONT_END, Explorer, classify_families, explorer, without_answers
from .picker import ConfigPicker, config_picker

__all__ = [
    "explorer",
    "Explorer",
    "animate_singularity",
    "SingularityAnimation",
    "config_picker",
    "ConfigPicker",
    "classify_families",
    "without_answers",
    "FRONT_END",
]
