"""Input checks and small shared pieces of the picture layer: a numeric chain, one configuration as floats,
joint ranges, colours and the θ labels.

>>> from kinlib.robots import planar_offset_3r
>>> chain = checked_numeric(planar_offset_3r(), {"L": 1})
>>> as_configuration(chain, [0, 0.5, -0.5])
array([ 0. ,  0.5, -0.5])
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Mapping

import numpy as np
import sympy as sp

from .._backend import describe
from ..kinematics.chains import SerialChain

__all__ = [
    "JOINT_COLORS",
    "FRAME_COLORS",
    "check_chain",
    "checked_numeric",
    "as_configuration",
    "reach",
    "default_ranges",
    "theta_tex",
    "is_3d",
]

#: One colour per joint (joint i uses JOINT_COLORS[(i - 1) % 10]).
JOINT_COLORS = (
    "tab:blue",
    "tab:orange",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:brown",
    "tab:pink",
    "tab:olive",
    "tab:cyan",
    "tab:gray",
)
#: Colours of a frame's x, y, z arrows.
FRAME_COLORS = ("tab:red", "tab:green", "tab:blue")


def check_chain(chain, name: str = "chain") -> SerialChain:
    """``chain`` itself when it is a kinlib SerialChain, else a TypeError that says what to pass.

    >>> check_chain([1, 2])
    Traceback (most recent call last):
    ...
    TypeError: chain must be a kinlib SerialChain (e.g. kinlib.robots.planar_offset_3r(1)), got a list of shape (2,)
    """
    if not isinstance(chain, SerialChain):
        raise TypeError(
            f"{name} must be a kinlib SerialChain (e.g. kinlib.robots.planar_offset_3r(1)), got {describe(chain)}"
        )
    return chain


def checked_numeric(chain, params: Mapping | None = None) -> SerialChain:
    """``chain.numeric(params)`` after checking that ``chain`` is a SerialChain: the chain with numbers for
    its link lengths (a ValueError naming the parameters when symbols remain).

    >>> from kinlib.robots import planar_offset_3r
    >>> checked_numeric(planar_offset_3r(), {"L": 2}).params
    ()
    """
    return check_chain(chain).numeric(params)


def as_configuration(chain: SerialChain, q, name: str = "q") -> np.ndarray:
    """One numeric configuration of ``chain`` as a float array of shape (n,) (zeros for None).

    >>> from kinlib.robots import planar_offset_3r
    >>> import sympy as sp
    >>> as_configuration(planar_offset_3r(1), [sp.pi / 2, 0, 1])
    array([1.57079633, 0.        , 1.        ])
    """
    if q is None:
        return np.zeros(chain.n)
    if isinstance(q, (str, bytes)):
        raise TypeError(f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)}")
    if isinstance(q, sp.MatrixBase):
        q = list(q)
    if isinstance(q, (numbers.Number, sp.Basic)) and chain.n == 1:
        q = [q]
    try:
        arr = np.asarray(q, dtype=object).reshape(-1) if not isinstance(q, np.ndarray) else q.reshape(-1)
    except Exception:
        raise TypeError(f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)}") from None
    if np.ndim(q) > 1 and not (isinstance(q, np.ndarray) and q.ndim == 2 and 1 in q.shape):
        raise ValueError(
            f"{name} must hold {chain.n} joint values for {chain.name} (one configuration), got {describe(q)}"
        )
    if arr.size != chain.n:
        raise ValueError(
            f"{name} must hold {chain.n} joint values for {chain.name}, got {describe(q)} with {arr.size} entries"
        )
    out = np.empty(chain.n)
    for i, v in enumerate(arr):
        if isinstance(v, (bool, str, bytes)):
            raise TypeError(f"{name}[{i}] must be a real number, got {describe(v)}")
        try:
            out[i] = float(v)
        except (TypeError, ValueError):
            raise TypeError(f"{name}[{i}] must be a real number (a numeric configuration), got {describe(v)}") from None
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name} must hold finite numbers, got {out}")
    return out


def reach(chain: SerialChain) -> float:
    """Sum of the link lengths at home (distance between consecutive skeleton points; 1 if all are 0).

    >>> from kinlib.robots import planar_3r
    >>> reach(planar_3r(1, 1, 1))
    3.0
    """
    sk = chain.skeleton(np.zeros(chain.n))
    d = float(np.sum(np.linalg.norm(np.diff(sk, axis=1), axis=0)))
    return d if d > 1e-9 else 1.0


def default_ranges(chain, ranges=None) -> list[tuple[float, float]]:
    """Joint ranges: revolute (−π, π), prismatic ±(half the home reach); ``ranges`` overrides per joint
    (a list of (lo, hi) or a dict {joint number/symbol/name: (lo, hi)}). ``chain`` must be numeric.

    >>> from kinlib.robots import planar_rpp
    >>> [tuple(round(x, 3) for x in r) for r in default_ranges(planar_rpp(1), {3: (0, 1)})]
    [(-3.142, 3.142), (-0.5, 0.5), (0.0, 1.0)]
    """
    chain = check_chain(chain)
    half = 0.5 * reach(chain)
    out = [(-math.pi, math.pi) if k == "R" else (-half, half) for k in chain.joint_types]
    if ranges is None:
        return out
    items = ranges.items() if isinstance(ranges, Mapping) else enumerate(ranges, start=1)
    if not isinstance(ranges, Mapping) and len(list(ranges)) != chain.n:
        raise ValueError(f"ranges must give {chain.n} (lo, hi) pairs or a dict by joint, got {describe(ranges)}")
    for j, r in items:
        i = chain.joint_index(j, "ranges key")
        try:
            lo, hi = (float(v) for v in r)
        except Exception:
            raise TypeError(f"ranges[{j!r}] must be a pair (lo, hi) of numbers, got {describe(r)}") from None
        if not hi > lo:
            raise ValueError(f"ranges[{j!r}] must have lo < hi, got {(lo, hi)}")
        out[i] = (lo, hi)
    return out


def theta_tex(i: int, dot: bool = False) -> str:
    r"""$\theta_i$ or $\dot\theta_i$ (i is 1-based) for figure text.

    >>> theta_tex(2), theta_tex(3, dot=True)
    ('$\\theta_{2}$', '$\\dot{\\theta}_{3}$')
    """
    return f"$\\dot{{\\theta}}_{{{i}}}$" if dot else f"$\\theta_{{{i}}}$"


def is_3d(ax) -> bool:
    """True for 3-D matplotlib axes.

    >>> import matplotlib.pyplot as plt
    >>> is_3d(plt.figure().add_subplot(projection="3d")), is_3d(plt.figure().add_subplot())
    (True, False)
    """
    return hasattr(ax, "get_zlim")
