"""What a singularity costs: the joint rates a fixed tool velocity needs as the arm approaches a singular
configuration, exact inverse beside damped least squares (DLS), and the tracking error DLS accepts instead.

For task rows J (square, m = n) and a fixed task velocity V, the exact joint rates are θ̇ = J⁻¹V
(:func:`kinlib.velocity.inverse_velocity`): with σ_min → 0 at the singularity, ‖θ̇‖ grows like 1/σ_min when
V has a component along the direction the arm is losing. Damped least squares
θ̇_λ = Jᵀ(J Jᵀ + λ²I)⁻¹V (:func:`kinlib.velocity.damped_least_squares`) keeps ‖θ̇_λ‖ ≤ ‖V‖/(2λ) everywhere and
pays with a velocity error ‖J θ̇_λ − V‖ that is small far from the singularity and tends to the whole component
of V along the lost direction at it.

>>> from kinlib.robots import planar_offset_3r
>>> cost = plot_singularity_cost(planar_offset_3r(1), 2, [np.pi / 4, -np.pi / 4, np.pi / 4], [0, 0.1, 0.1],
...                              offsets=np.logspace(-3, 0, 4))
>>> bool(np.all(np.diff(cost.rates_exact) < 0)), bool(np.all(cost.rates_dls <= cost.bound + 1e-12))
(True, True)
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from .._backend import describe
from ..analysis.taskspace import default_task_rows, rows_label, task_row_indices, task_rows
from ..analysis.velocity import SingularityWarning, damped_least_squares, inverse_velocity
from .common import as_configuration, checked_numeric

__all__ = ["CostPlot", "plot_singularity_cost"]


@dataclass
class CostPlot:
    """Result of :func:`plot_singularity_cost`. ``offsets`` δ (distance of the joint from its singular value),
    ``rates_exact`` ‖J⁻¹V‖, ``rates_dls`` ‖θ̇_λ‖, ``error_dls`` ‖J θ̇_λ − V‖ (one per offset), ``bound`` the DLS
    bound ‖V‖/(2λ), ``damping`` λ, ``fig`` and ``axes`` (rates, error).

    >>> from kinlib.robots import planar_offset_3r
    >>> c = plot_singularity_cost(planar_offset_3r(1), 2, [0.0, -np.pi / 4, 0.0], [0, 0.1, 0], offsets=[1e-3, 1e-1])
    >>> type(c).__name__, c.damping, bool(c.rates_exact[0] > 10 * c.rates_exact[1])
    ('CostPlot', 0.05, True)
    """

    offsets: np.ndarray
    rates_exact: np.ndarray
    rates_dls: np.ndarray
    error_dls: np.ndarray
    bound: float
    damping: float
    fig: Any = field(repr=False, default=None)
    axes: Any = field(repr=False, default=None)


def plot_singularity_cost(
    chain,
    joint: int,
    q_singular,
    V,
    *,
    offsets=None,
    rows=None,
    damping: float = 0.05,
    params=None,
    axes=None,
    figsize=(10.5, 3.8),
) -> CostPlot:
    """Two panels (log scales) for the numeric ``chain`` at the configurations q_singular + δ e_joint (joint
    1-based; δ over ``offsets``, default 10⁻⁴…1): left, the joint-rate norm ‖θ̇‖ needed for the fixed task
    velocity ``V`` (in the task ``rows`` of the geometric Jacobian, default the chain's task space) by the exact
    inverse and by damped least squares with ``damping`` λ, with the DLS bound ‖V‖/(2λ); right, the velocity
    error ‖J θ̇_λ − V‖ DLS accepts. The task rows must be square (as many rows as joints). Legends sit beside the
    axes, never over the curves.

    >>> from kinlib.robots import planar_offset_3r
    >>> c = plot_singularity_cost(planar_offset_3r(1), 2, [0.0, -np.pi / 4, 0.0], [0, 0, 0.1], offsets=[1e-2, 1e-1])
    >>> c.rates_exact.shape, round(c.bound, 6)
    ((2,), 1.0)
    """
    chain = checked_numeric(chain, params)
    if not isinstance(joint, (int, np.integer)) or not 1 <= joint <= chain.n:
        raise ValueError(f"joint must be a joint number 1…{chain.n}, got {describe(joint)}")
    q0 = as_configuration(chain, q_singular, "q_singular")
    r = task_row_indices(rows, default=default_task_rows(chain))
    if len(r) != chain.n:
        raise ValueError(f"the task rows must be square: {len(r)} rows ({rows_label(r)}) for {chain.n} joints")
    v = np.asarray(V, dtype=float).reshape(-1)
    if v.shape != (len(r),) or not np.all(np.isfinite(v)) or not np.any(v):
        raise ValueError(f"V must be a nonzero task velocity of {len(r)} numbers ({rows_label(r)}), got {describe(V)}")
    if not (isinstance(damping, (int, float)) and np.isfinite(damping) and damping > 0):
        raise ValueError(f"damping must be a positive number, got {describe(damping)}")
    d = np.logspace(-4, 0, 41) if offsets is None else np.asarray(offsets, dtype=float).reshape(-1)
    if d.size < 2 or not np.all(d > 0):
        raise ValueError(f"offsets must be at least two positive numbers, got {describe(offsets)}")
    d = np.sort(d)
    Q = np.repeat(q0[None], d.size, axis=0)
    Q[:, joint - 1] += d
    J = task_rows(chain.jacobian_geometric(Q), r)
    Vb = np.repeat(v[None], d.size, axis=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SingularityWarning)  # near the singularity on purpose
        exact = inverse_velocity(J, Vb)
    dls = damped_least_squares(J, Vb, float(damping))
    err = np.linalg.norm(np.einsum("kij,kj->ki", J, dls) - Vb, axis=1)
    out = CostPlot(
        offsets=d,
        rates_exact=np.linalg.norm(exact, axis=1),
        rates_dls=np.linalg.norm(dls, axis=1),
        error_dls=err,
        bound=float(np.linalg.norm(v) / (2 * damping)),
        damping=float(damping),
    )
    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=figsize, layout="constrained")
    else:
        fig = axes[0].figure
    a1, a2 = axes
    name = f"θ{joint}"
    a1.loglog(d, out.rates_exact, lw=2, color="tab:red", label="exact: ‖J⁻¹V‖")
    a1.loglog(d, out.rates_dls, lw=2, color="tab:blue", label=f"damped least squares, λ = {damping:g}")
    a1.axhline(out.bound, color="tab:blue", ls=":", lw=1.2, label="DLS bound ‖V‖/(2λ)")
    a1.set_xlabel(f"distance from the singular value, |{name} − {name}*| (rad)")
    a1.set_ylabel("joint rates ‖θ̇‖ (rad/s)")
    a1.set_title("joint rates for the same tool velocity V", fontsize=10)
    a2.loglog(d, np.maximum(out.error_dls, 1e-300), lw=2, color="tab:blue", label="DLS error ‖J θ̇ − V‖")
    a2.axhline(np.linalg.norm(v), color="0.4", ls="--", lw=1, label="‖V‖")
    a2.set_xlabel(f"|{name} − {name}*| (rad)")
    a2.set_ylabel("velocity error (per s)")
    a2.set_title("what damped least squares gives up", fontsize=10)
    for ax in (a1, a2):
        ax.invert_xaxis()  # read left to right: approaching the singular configuration
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.22), fontsize=8, ncol=1, frameon=False)
    out.fig, out.axes = fig, (a1, a2)
    return out
