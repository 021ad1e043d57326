"""An answer described for the comparison, on the trusted side: its values at the grader's secret points.

The grader rebuilds each answer from the data a kernel exported (:mod:`.wire`) and describes it here, in its
own process, exactly as it describes the reference answer: :func:`describe` looks the kind up in the table of
kinds (:data:`kinlib.course.answers.kinds.KINDS`) and applies that kind's description (shape, symbols and values
at the points for ``expr``, ``subspace``, ``property``; members per point for ``set``; the plain value for
``choice``). The comparers (:mod:`.compare`) read these descriptions. The points, the seed and the reference
never leave the grader. Non-finite values are described as ``None`` (cannot be evaluated): a wrong answer.

The reference side: :func:`normalize_reference` (each kind's reference form) and :func:`dump_reference` (the
answer key as ``srepr`` text, instructor side only).
"""

import sympy as sp

from . import kinds
from .choice import describe_choice
from .expr import describe_expr, exact_equal
from .properties import describe_property
from .sets import MAX_SET_MEMBERS, describe_set
from .subspace import describe_subspace

__all__ = [
    "describe",
    "describe_expr",
    "describe_set",
    "describe_choice",
    "describe_subspace",
    "describe_property",
    "normalize_reference",
    "dump_reference",
    "exact_equal",
    "DESCRIBE",
    "MAX_SET_MEMBERS",
]

DESCRIBE = {name: k.describe for name, k in kinds.KINDS.items()}


def describe(kind, value, points, seed=0):
    """The answer ``value`` of kind ``kind`` described for the comparison (other kinds: as ``expr``).

    >>> describe("choice", 3, [])["value"]
    3
    """
    return kinds.lookup(kind)[0].describe(value, points, seed)


def normalize_reference(kind, value):
    """The reference value as something ``srepr`` round-trips (instructor side only): the kind's own reference form.

    >>> normalize_reference("set", [0, 1]), normalize_reference("expr", [1, 2]).shape
    ({0, 1}, (2, 1))
    >>> from kinlib.robots import planar_rpp
    >>> normalize_reference("property:nonsingular", planar_rpp()).shape   # a robot: its screw axes
    (6, 3)
    """
    return kinds.lookup(kind)[0].reference(value)


def _symbols(obj) -> set:
    """Every free symbol of a reference value (a SymPy object, or dicts and lists of them)."""
    syms = set()
    stack = [obj]
    while stack:
        o = stack.pop()
        if isinstance(o, dict):
            stack += list(o.values())
        elif isinstance(o, (list, tuple)):
            stack += list(o)
        else:
            syms |= set(getattr(o, "free_symbols", set()) or set())
    return syms


def dump_reference(ns, kinds_of):
    """{name: {"kind", "srepr", "symbols": {name: {"positive": bool}}} | {"kind", "choice"} | {"error"}}
    for the reference answers ``kinds_of`` = {name: kind} found in ``ns``.

    >>> dump_reference({"n": 2, "ok": True}, {"n": "choice", "ok": "expr", "x": "expr"})["ok"]
    {'choice': {'tag': 'choice', 'type': 'bool', 'value': True}, 'kind': 'choice'}
    """
    out = {}
    for name, kind in kinds_of.items():
        if name not in ns:
            out[name] = {"error": f"{name} is not defined after the solution notebook ran"}
            continue
        try:
            kind = kinds.resolve(kind, ns[name])
            if kind == "choice":
                out[name] = {"choice": describe_choice(ns[name]), "kind": kind}
                continue
            obj = normalize_reference(kind, ns[name])
            text = sp.srepr(obj)
            syms = _symbols(obj)
            out[name] = {
                "kind": kind,
                "srepr": text,
                "symbols": {s.name: {"positive": bool(s.is_positive)} for s in syms if isinstance(s, sp.Symbol)},
            }
        except Exception as exc:  # noqa: BLE001
            out[name] = {"error": f"{type(exc).__name__}: {exc}"[:500]}
    return out
