"""Numeric search for singular configurations of any serial chain with numeric link lengths.

:func:`find_singularities` looks for configurations where the smallest singular value σ_k of the
Jacobian (k = min(m, n)) is below a tolerance: seeded random starts, each improved by Newton steps
on σ_k(θ) toward 0,

    θ ← θ − σ_k g / ‖g‖²,   g_j = ∂σ_k/∂θ_j = u_kᵀ (∂J/∂θ_j) v_k,

where J = U Σ Vᵀ, u_k, v_k are the singular vectors of σ_k and ∂J/∂θ_j is a central finite difference
(every start and every difference in one batch through the chain's generated code). Steps are halved
until σ_k decreases. It is the numeric companion of the exact
:func:`kinlib.singularities.singular_configurations`: it works on any arm (7 joints too), finds
points (not families) and proves nothing, but each point it returns has σ_k < tol, checked at the end.
"""

from __future__ import annotations

import numbers
from typing import Any, NamedTuple

import numpy as np

from .._backend import describe
from .taskspace import task_rows

__all__ = ["find_singularities", "SingularPoints"]


class SingularPoints(NamedTuple):
    """The configurations found (rows of ``q``, shape (K, n)) and σ_min there (``sigma``, shape (K,)).

    >>> from kinlib import robots
    >>> pts = find_singularities(robots.planar_3r(1, 1, 1), ["vx", "vy"], samples=20)
    >>> pts.q.shape[1], len(pts.q) == len(pts.sigma), bool(np.all(pts.sigma < 1e-6))
    (3, True, True)
    """

    q: np.ndarray
    sigma: np.ndarray


def _positive_number(x: Any, name: str) -> float:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Real, np.floating, np.integer)):
        raise TypeError(f"{name} must be a positive number, got {describe(x)}")
    x = float(x)
    if not np.isfinite(x) or x <= 0:
        raise ValueError(f"{name} must be a positive finite number, got {x!r}")
    return x


def _count(x: Any, name: str, minimum: int = 1) -> int:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (numbers.Integral, np.integer)):
        raise TypeError(f"{name} must be an integer, got {describe(x)}")
    if int(x) < minimum:
        raise ValueError(f"{name} must be at least {minimum}, got {int(x)}")
    return int(x)


def _smallest(J: np.ndarray):
    """σ_k, u_k, v_k of each J in a batch (N, m, n), k = min(m, n)."""
    U, s, Vt = np.linalg.svd(J)
    k = min(J.shape[1:]) - 1
    return s[:, k], U[:, :, k], Vt[:, k, :]


def find_singularities(
    chain,
    rows: Any = None,
    *,
    tol: float = 1e-6,
    seed: int = 0,
    samples: int = 200,
    max_iter: int = 60,
    limits: Any = None,
) -> SingularPoints:
    """Configurations of ``chain`` where σ_min(J(θ)) < ``tol``: a numeric search (see the module docstring).

    J is the **geometric** Jacobian [ω_s; ṗ] (``chain.jacobian_geometric``), all six rows by default; with
    all six rows its rank is that of J_s and J_b (J = [[I, 0], [−[p], I]] J_s), so the singular
    configurations are the same. ``rows`` picks task rows as in :func:`kinlib.taskspace.task_rows`
    (e.g. ``["vx", "vy"]`` for a planar arm's tool position ṗ): rows of the geometric J.

    ``samples`` seeded random starts (``numpy.random.default_rng(seed)``: same seed, same output), revolute
    joints uniform in [−π, π), prismatic ones in ``limits`` (default ±(1 + |p_home|)); ``limits`` may give
    (lo, hi) per joint. Returns :class:`SingularPoints` ``(q, sigma)``: the distinct configurations found
    (revolute values wrapped to (−π, π], duplicates within 1e-3 merged), sorted, with σ_min at each
    (every one < tol). Needs numeric link lengths (``chain.subs(L=1)``).

    >>> from kinlib import robots
    >>> q, sigma = find_singularities(robots.planar_3r(1, 1, 1), ["vx", "vy"], samples=40)
    >>> bool(np.all(sigma < 1e-6)) and bool(np.allclose(np.sin(q[:, 1]) * np.sin(q[:, 2]), 0, atol=1e-5))
    True
    """
    from ..kinematics.chains import SerialChain

    if not isinstance(chain, SerialChain):
        raise TypeError(f"chain must be a kinlib SerialChain, got {describe(chain)}")
    if chain.params:
        raise ValueError(
            f"chain must have numeric link lengths; {chain.name} has the parameters "
            f"{', '.join(map(str, chain.params))}: use chain.subs({chain.params[0]}=...) first"
        )
    tol = _positive_number(tol, "tol")
    samples = _count(samples, "samples")
    max_iter = _count(max_iter, "max_iter", 0)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (numbers.Integral, np.integer)):
        raise TypeError(f"seed must be an integer, got {describe(seed)}")
    n = chain.n
    revolute = np.array([t == "R" for t in chain.joint_types])
    home = np.asarray(np.array(chain.M[:3, 3], dtype=float)).ravel()
    reach = 1.0 + float(np.linalg.norm(home))
    lo = np.where(revolute, -np.pi, -reach)
    hi = np.where(revolute, np.pi, reach)
    if limits is not None:
        try:
            lim = np.asarray(limits, dtype=float)
        except (TypeError, ValueError):
            raise TypeError(f"limits must be (lo, hi) per joint, shape ({n}, 2), got {describe(limits)}") from None
        if lim.shape != (n, 2) or not np.all(np.isfinite(lim)) or np.any(lim[:, 0] >= lim[:, 1]):
            raise ValueError(
                f"limits must be finite (lo, hi) with lo < hi for each of the {n} joints, "
                f"shape ({n}, 2), got {describe(limits)}"
            )
        lo, hi = lim[:, 0], lim[:, 1]

    def jac(Q):
        Jb = chain.jacobian_geometric(np.ascontiguousarray(Q, dtype=float))
        return Jb if rows is None else task_rows(Jb, rows)

    if rows is not None:
        jac(np.zeros((1, n)))  # check rows early: a clear error from task_rows
    rng = np.random.default_rng(int(seed))
    Q = lo + (hi - lo) * rng.random((samples, n))
    h = 1e-6
    eye = np.eye(n) * h
    active = np.ones(samples, bool)
    sig = _smallest(jac(Q))[0]
    for _ in range(max_iter):
        idx = np.flatnonzero(active & (sig > tol * 1e-3))
        if idx.size == 0:
            break
        P = Q[idx]
        s, u, v = _smallest(jac(P))
        shifted = np.concatenate([P[:, None, :] + eye[None], P[:, None, :] - eye[None]], axis=1).reshape(-1, n)
        dJ = jac(shifted)
        dJ = dJ.reshape(idx.size, 2, n, *dJ.shape[1:])  # (N, ±, joint j, m, n)
        dJ = (dJ[:, 0] - dJ[:, 1]) / (2 * h)  # (N, n_j, m, n)
        g = np.einsum("pm,pjmn,pn->pj", u, dJ, v)
        gg = np.sum(g * g, axis=1)
        ok = gg > 1e-300
        step = -(s / np.where(ok, gg, 1.0))[:, None] * g
        norm = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, 0.5 / np.maximum(norm, 1e-300))[:, None]
        alphas = np.array([1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125])
        trial = P[:, None, :] + alphas[None, :, None] * step[:, None, :]
        st = _smallest(jac(trial.reshape(-1, n)))[0].reshape(idx.size, alphas.size)
        best = np.argmin(st, axis=1)
        better = (st[np.arange(idx.size), best] < s) & ok
        Q[idx[better]] = trial[np.flatnonzero(better), best[better]]
        sig[idx] = np.where(better, st[np.arange(idx.size), best], s)
        active[idx[~better]] = False
    Q = np.where(revolute, (Q + np.pi) % (2 * np.pi) - np.pi, Q)
    Q = np.where(revolute & np.isclose(Q, -np.pi, atol=1e-12), np.pi, Q)
    keep = sig < tol
    Q, sig = Q[keep], sig[keep]
    order = np.lexsort(np.round(Q, 6).T[::-1])
    Q, sig = Q[order], sig[order]
    chosen: list[int] = []
    for i in range(len(Q)):
        d = Q[chosen] - Q[i] if chosen else np.zeros((0, n))
        d = np.where(revolute, (d + np.pi) % (2 * np.pi) - np.pi, d)
        if not chosen or np.min(np.linalg.norm(d, axis=1)) > 1e-3:
            chosen.append(i)
    return SingularPoints(Q[chosen], sig[chosen])
