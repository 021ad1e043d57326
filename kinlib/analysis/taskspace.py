"""Task spaces: which rows of a Jacobian a task uses.

A Jacobian's six rows are, in the textbook's [ω; v] order, ``wx wy wz vx vy vz``; for the problem set's
geometric Jacobian J = blockdiag(R, R) J_b the last three are the tool-point velocity ṗ (aliases
``px py pz``). A task space is a choice of rows: a planar arm moving a tool in the plane uses (ṗ_x, ṗ_y);
one that also orients it uses (ω_z, ṗ_x, ṗ_y). Singularities, manipulability and the explorer widgets are
all about the chosen rows, so they share this one parser:

* names ``wx wy wz vx vy vz``, with aliases ``px py pz`` and ``ωx``, ``ω_x`` …, in any case;
* indices 0…5, or negative from the end (−1 = the last row);
* presets (:data:`PRESETS`): ``planar`` (ω_z, ṗ_x, ṗ_y), ``xy`` (ṗ_x, ṗ_y), ``linear`` = ``position``
  (ṗ_x, ṗ_y, ṗ_z), ``angular`` (ω_x, ω_y, ω_z), ``all``.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np
import sympy as sp

from .._backend import as_jacobian, describe, is_symbolic

__all__ = [
    "ROW_NAMES",
    "ROW_LABELS",
    "ROW_TEX",
    "PRESETS",
    "task_row_indices",
    "task_rows",
    "is_planar",
    "default_task_rows",
    "rows_label",
]

#: Names of the six rows of a Jacobian in the textbook's [ω; v] order (for the geometric J, v is ṗ).
ROW_NAMES = ("wx", "wy", "wz", "vx", "vy", "vz")
#: The rows as plain text, for the geometric Jacobian [ω_s; ṗ].
ROW_LABELS = ("ω_x", "ω_y", "ω_z", "ṗ_x", "ṗ_y", "ṗ_z")
#: The rows as LaTeX (figure text).
ROW_TEX = (r"$\omega_x$", r"$\omega_y$", r"$\omega_z$", r"$\dot p_x$", r"$\dot p_y$", r"$\dot p_z$")
#: Named task spaces.
PRESETS = {
    "planar": ("wz", "vx", "vy"),
    "xy": ("vx", "vy"),
    "linear": ("vx", "vy", "vz"),
    "position": ("vx", "vy", "vz"),
    "angular": ("wx", "wy", "wz"),
    "all": ROW_NAMES,
}
_ALIASES = {
    "px": "vx",
    "py": "vy",
    "pz": "vz",
    "ωx": "wx",
    "ωy": "wy",
    "ωz": "wz",
    "ω_x": "wx",
    "ω_y": "wy",
    "ω_z": "wz",
    "w_x": "wx",
    "w_y": "wy",
    "w_z": "wz",
    "v_x": "vx",
    "v_y": "vy",
    "v_z": "vz",
    "p_x": "vx",
    "p_y": "vy",
    "p_z": "vz",
}
_HINT = f"row names {', '.join(ROW_NAMES)} (ṗ aliases px, py, pz), indices, or a preset among {', '.join(PRESETS)}"


def _one_row(r: Any, m: int) -> int:
    if isinstance(r, (bool, np.bool_)):
        raise TypeError(f"rows must be {_HINT}; got the bool {r!r}")
    if isinstance(r, (numbers.Integral, np.integer)):
        i = int(r)
        if not -m <= i < m:
            raise ValueError(
                f"rows: index {i} is out of range for a Jacobian with {m} rows (indices −{m}…{m - 1}); got {i}"
            )
        return i % m
    if isinstance(r, str):
        key = r.strip().lower()
        key = _ALIASES.get(key, key)
        if key in ROW_NAMES:
            if m != 6:
                raise ValueError(
                    f"rows: the row name {r!r} needs a Jacobian J with 6 rows ([ω; v]), got J with {m} "
                    f"rows; use indices"
                )
            return ROW_NAMES.index(key)
        raise ValueError(f"rows: unknown row; use {_HINT}; got {r!r}")
    raise TypeError(f"rows must be {_HINT}; got {describe(r)}")


def task_row_indices(rows: Any, default: Any = None, m: int = 6) -> tuple[int, ...]:
    """Row indices (0-based, in the order given) of a task space of an m-row Jacobian.

    ``rows``: a preset name, one row name or index, or a sequence of them; ``None`` means ``default``
    (itself a rows spec; ``None`` = all rows). Names need m = 6. Repeated rows and empty selections are refused.

    >>> task_row_indices("planar"), task_row_indices(["px", "py"]), task_row_indices("ω_z")
    ((2, 3, 4), (3, 4), (2,))
    >>> task_row_indices([-3, -2]), task_row_indices(None, default="xy"), task_row_indices(None)
    ((3, 4), (3, 4), (0, 1, 2, 3, 4, 5))
    """
    if isinstance(m, bool) or not isinstance(m, (numbers.Integral, np.integer)) or m < 1:
        raise ValueError(f"m must be the number of rows of the Jacobian (≥ 1), got {describe(m)}")
    m = int(m)
    if rows is None:
        if default is None:
            return tuple(range(m))
        return task_row_indices(default, None, m)
    if isinstance(rows, np.ndarray) and rows.ndim == 0:
        raise TypeError(
            f"rows must be {_HINT}; got a 0-d array {rows!r}: pass the value itself ({rows.item()!r}) or a list"
        )
    if isinstance(rows, str):
        key = rows.strip().lower()
        if key in PRESETS:
            if m != 6:
                raise ValueError(
                    f"rows: the preset {rows!r} needs a Jacobian J with 6 rows ([ω; v]), got J with "
                    f"{m} rows; use indices"
                )
            rows = PRESETS[key]
        else:
            rows = (rows,)
    elif isinstance(rows, (numbers.Integral, np.integer)) and not isinstance(rows, (bool, np.bool_)):
        rows = (rows,)
    if isinstance(rows, (bytes, dict, set, frozenset)) or not isinstance(rows, (Sequence, np.ndarray)):
        raise TypeError(f"rows must be {_HINT}; got {describe(rows)}")
    idx = tuple(_one_row(r, m) for r in (rows.tolist() if isinstance(rows, np.ndarray) else rows))
    if not idx:
        raise ValueError("rows must name at least one row, got an empty sequence")
    if len(set(idx)) != len(idx):
        raise ValueError(f"rows must not repeat a row, got {describe(rows)} (rows {list(idx)})")
    return idx


def task_rows(J: Any, rows: Any):
    """The rows of J for a task space: ``task_rows(J, "planar")`` = rows (ω_z, ṗ_x, ṗ_y).

    ``rows`` as in :func:`task_row_indices` (here it is required: None is refused). J is a SymPy Matrix (exact rows out), a numeric m×n matrix, or a
    numeric batch (N, m, n) (gives (N, k, n)). Names and presets need J with 6 rows ([ω; v] order).

    >>> import sympy as sp
    >>> t = sp.Symbol("theta1", real=True)
    >>> J = sp.Matrix([0, 0, 1, -sp.sin(t), sp.cos(t), 0])
    >>> task_rows(J, "xy").T
    Matrix([[-sin(theta1), cos(theta1)]])
    >>> import numpy as np
    >>> task_rows(np.zeros((10, 6, 2)), "planar").shape
    (10, 3, 2)
    """
    if rows is None:
        raise TypeError(f"rows must be {_HINT}; got None")
    if isinstance(J, np.ndarray) and J.ndim == 3 and not is_symbolic(J):
        if J.dtype.kind not in "fiu":
            raise TypeError(f"J must be a real matrix or a batch (N, m, n) of real matrices, got {describe(J)}")
        return np.asarray(J, dtype=float)[:, list(task_row_indices(rows, None, J.shape[1])), :]
    J = as_jacobian(J)
    idx = list(task_row_indices(rows, None, J.shape[0]))
    if isinstance(J, sp.MatrixBase):
        return J.extract(idx, list(range(J.cols)))
    return J[idx, :]


def is_planar(chain: Any) -> bool:
    """True when every revolute axis is along ±z_s and every prismatic axis lies in the xy-plane (rows ω_x,
    ω_y and v_z of every screw axis are zero): the chain moves in the xy-plane.

    >>> from kinlib.robots import planar_2r, ur5
    >>> is_planar(planar_2r()), is_planar(ur5())
    (True, False)
    """
    S = getattr(chain, "screws", None)
    if not isinstance(S, sp.MatrixBase) or S.rows != 6:
        raise TypeError(f"chain must be a kinlib SerialChain (e.g. kinlib.robots.planar_2r()), got {describe(chain)}")
    return all(S[r, i] == 0 for r in (0, 1, 5) for i in range(S.cols))


def default_task_rows(chain: Any) -> tuple[int, ...]:
    """The task space of an arm when none is named: the rows its joints can serve.

    A planar arm with three or more joints positions and orients its tool in the plane: (ω_z, ṗ_x, ṗ_y); with
    one or two joints it positions it: (ṗ_x, ṗ_y). A spatial arm with six or more joints: all six rows; with
    fewer: the tool position (ṗ_x, ṗ_y, ṗ_z). (All six rows of a 2R arm have rank 2 everywhere, so testing
    them would never show its stretched-out singularity.)

    >>> from kinlib.robots import planar_2r, ur5
    >>> default_task_rows(planar_2r()), default_task_rows(ur5())
    ((3, 4), (0, 1, 2, 3, 4, 5))
    """
    n = chain.screws.cols if isinstance(getattr(chain, "screws", None), sp.MatrixBase) else None
    if is_planar(chain):
        return task_row_indices("planar" if n >= 3 else "xy")
    return task_row_indices("all" if n >= 6 else "position")


def rows_label(rows: Any, tex: bool = False) -> str:
    """The rows as text: "ṗ_x, ṗ_y" (``tex=True``: LaTeX for figures).

    >>> rows_label("xy"), rows_label([2], tex=True)
    ('ṗ_x, ṗ_y', '$\\\\omega_z$')
    """
    return ", ".join((ROW_TEX if tex else ROW_LABELS)[r] for r in task_row_indices(rows))
