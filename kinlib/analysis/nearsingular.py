"""The course's one rule for "near a singular configuration" (used by the explorers, the animation of 5.2 and the
notebooks' text; re-exported by :mod:`kinlib.manipulability`, where the measures live).

>>> import numpy as np
>>> singularity_state(np.diag([1.0, 0.05]), 1.0), singularity_state(np.eye(2), 1.0)
('near', 'regular')
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._backend import describe, numeric_jacobian
from .taskspace import task_rows

__all__ = ["NEAR_SINGULAR", "SINGULAR_RTOL", "singularity_state", "near_singular", "peak_manipulability"]


def _volume(A: np.ndarray) -> np.ndarray:
    """w = √det(J Jᵀ) (√det(Jᵀ J) with fewer joints than rows) = the product of J's singular values (batched)."""
    return np.prod(np.linalg.svd(A, compute_uv=False), axis=-1)


# ----------------------------------------------------------------------------------------------
# "near a singular configuration": the one rule of the course
# ----------------------------------------------------------------------------------------------
#: A configuration is **near a singular configuration** when its manipulability w = √det(J Jᵀ) of the task
#: rows (√det(Jᵀ J) with fewer joints than rows) is below ``NEAR_SINGULAR`` times w_max, the largest w of the
#: same arm and rows over its joint ranges: w < 0.1 · w_max. The explorers, the animation and the notebooks
#: all use this rule (:func:`singularity_state`); nowhere else in kinlib or the notebooks is "near" decided.
#:
#: Why w / w_max and not σ_min / σ_max: the rows of J mix units (ω in rad/s, ṗ in m/s per rad/s of joint
#: rate), so σ_min / σ_max compares an angular with a linear speed and changes with the unit of length (for the
#: planar 3R of problem 5 with L = 1 it stays ≤ 0.074 on a whole sweep, where w is still 70 % of w_max).
#: Rescaling every length by c scales the v rows by c, i.e. J → D J with D = diag(1, …, c, …) constant, so
#: w → |det D| w at *every* configuration (n ≥ m: det(D J Jᵀ D) = det(D)² det(J Jᵀ)) and the ratio w / w_max
#: does not depend on the unit. (With fewer joints than rows, det(Jᵀ D² J) is not a constant multiple of
#: det(Jᵀ J): there the ratio is unit-free only when the rows have one unit.)
NEAR_SINGULAR = 0.1

#: The rank test: a singular value at most ``SINGULAR_RTOL`` · σ_max counts as 0 (floating-point round-off of a
#: singular configuration computed in double precision is ≈ 10⁻¹⁶ · σ_max).
SINGULAR_RTOL = 1e-6


def singularity_state(J: Any, w_max: float, near: float = NEAR_SINGULAR, rtol: float = SINGULAR_RTOL):
    """'singular', 'near' or 'regular' for numeric task rows J (m×n; a batch (N, m, n) gives an array of N
    states): 'singular' when J loses rank (a singular value ≤ ``rtol`` · σ_max, or J = 0), 'near' when
    w < ``near`` · ``w_max`` (the rule :data:`NEAR_SINGULAR`; w_max: the largest w of the same arm and rows,
    e.g. from :func:`peak_manipulability`), else 'regular'.

    >>> import numpy as np
    >>> J = lambda t: np.array([[1.0, 1.0, 1.0], [0.0, np.sin(1), np.sin(1) + np.sqrt(2) * np.sin(1 + t)],
    ...                         [0.0, -np.cos(1), -np.cos(1) - np.sqrt(2) * np.cos(1 + t)]])
    >>> [str(singularity_state(J(t), np.sqrt(2))) for t in (0.0, np.pi / 4, 0.05, -0.8)]   # w/w_max = |sin t|
    ['singular', 'regular', 'near', 'regular']
    """
    if not (isinstance(w_max, (int, float, np.floating, np.integer)) and np.isfinite(w_max) and w_max > 0):
        raise ValueError(f"w_max must be a positive number (the largest manipulability), got {describe(w_max)}")
    if not (0 < float(near) < 1):
        raise ValueError(f"near must be a number in (0, 1), got {describe(near)}")
    A = numeric_jacobian(J)
    s = np.linalg.svd(A, compute_uv=False)
    singular = s[..., -1] <= rtol * s[..., 0]
    w = _volume(A)
    out = np.where(singular, "singular", np.where(w < float(near) * float(w_max), "near", "regular"))
    return str(out) if out.ndim == 0 else out


def near_singular(J: Any, w_max: float, near: float = NEAR_SINGULAR):
    """True at or near a singular configuration: w < ``near`` · ``w_max`` (:data:`NEAR_SINGULAR`), a singular
    configuration included (w = 0). A batch (N, m, n) gives N booleans.

    >>> import numpy as np
    >>> bool(near_singular(np.diag([1.0, 0.05]), 1.0)), bool(near_singular(np.eye(2), 1.0))
    (True, False)
    """
    state = singularity_state(J, w_max, near)
    return state != "regular" if isinstance(state, str) else np.asarray(state) != "regular"


def peak_manipulability(chain: Any, rows: Any, ranges: Any = None, samples: int = 4000, seed: int = 0, extra=None):
    """w_max: the largest √det(J Jᵀ) of the task ``rows`` of the geometric Jacobian of a numeric ``chain``
    over ``samples`` configurations drawn (fixed ``seed``) from ``ranges`` (a (lo, hi) pair per joint; default
    a turn (−π, π) for every joint), and the configurations ``extra`` (N×n) if given: the reference of the
    "near" rule (:data:`NEAR_SINGULAR`).

    >>> from kinlib.robots import planar_offset_3r
    >>> round(peak_manipulability(planar_offset_3r(1), "planar"), 3)      # √2 L², exactly
    1.414
    """
    n = int(chain.n)
    lo_hi = np.array([(-np.pi, np.pi)] * n if ranges is None else ranges, dtype=float)
    if lo_hi.shape != (n, 2) or not np.all(np.isfinite(lo_hi)):
        raise ValueError(f"ranges must be {n} (lo, hi) pairs of numbers, got {describe(ranges)}")
    if not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples must be a positive int, got {describe(samples)}")
    rng = np.random.default_rng(seed)
    Q = lo_hi[:, 0] + (lo_hi[:, 1] - lo_hi[:, 0]) * rng.random((samples, n))
    if extra is not None:
        Q = np.vstack([Q, np.asarray(extra, float).reshape(-1, n)])
    return float(np.max(_volume(task_rows(chain.jacobian_geometric(Q), rows))))
