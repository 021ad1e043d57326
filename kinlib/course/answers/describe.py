"""An answer described for the comparison, on the trusted side: its values at the grader's secret points.

The grader rebuilds each answer from the data a kernel exported (:mod:`.wire`) and describes it here, in its
own process, exactly as it describes the reference answer: :func:`describe` looks the kind up in the table of
kinds (:data:`kinlib.course.answers.kinds.KINDS`) and applies that kind's description (shape, symbols and values
at the points for ``expr``, ``subspace``, ``property``; members per point for ``set``; the plain value for
``choice``). The comparers (:mod:`.compare`) read these descriptions. The points, the seed and the reference
never leave the grader. Non-finite values are described as ``None`` (cannot be evaluated): a wrong answer.

The reference side: :func:`normalize_reference` (each kind's reference form) and :func:`dump_reference` (the
answer key as trees of the one wire format, :mod:`.wire`; instructor side only).
"""

import sympy as sp

from . import kinds, wire
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
    "same_reference",
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
    """The reference value as something the wire format round-trips (instructor side only): the kind's own reference form.

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


def same_reference(a, b) -> bool:
    """Structural equality of two reference values (SymPy objects, or dicts and lists of them); a matrix
    equals its immutable copy, an ImageSet's bound Dummy may be another one (each read makes a fresh one).

    >>> n = sp.Dummy("n")
    >>> same_reference(sp.ImageSet(sp.Lambda(n, n * sp.pi), sp.S.Integers), wire.load(wire.dump(sp.ImageSet(
    ...     sp.Lambda(n, n * sp.pi), sp.S.Integers)))), same_reference({"a": sp.Integer(1)}, {"a": 1})
    (True, False)
    """
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_reference(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(map(same_reference, a, b))
    if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase):
        return a == b
    return type(a) is type(b) and (a == b or _undummied(a) == _undummied(b))


def _undummied(e):
    """``e`` with its Dummies (an ImageSet's bound variable: a fresh one each time it is read) replaced, in order
    of appearance, by symbols named for their place, so two reads of one tree compare equal."""
    if not isinstance(e, sp.Basic):
        return e
    seen = []
    for x in sp.preorder_traversal(e):
        if isinstance(x, sp.Dummy) and x not in seen:
            seen.append(x)
    return e.xreplace({d: sp.Symbol(f"_dummy{i}_{d.name}", **d.assumptions0) for i, d in enumerate(seen)})


def dump_reference(ns, kinds_of):
    """{name: {"kind", "tree", "symbols": {name: {"positive": bool}}} | {"kind", "choice"} | {"error"}}
    for the reference answers ``kinds_of`` = {name: kind} found in ``ns``: each value in the one wire format
    (:func:`kinlib.course.answers.wire.dump`, read back by :func:`~kinlib.course.answers.wire.load`).

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
            tree = wire.dump(obj, max_nodes=10 * wire.MAX_NODES)
            if not same_reference(
                wire.load(tree, max_nodes=10 * wire.MAX_NODES), obj
            ):  # kept only if it reads back as is
                raise ValueError("the reference does not read back exactly from the wire format")
            syms = _symbols(obj)
            out[name] = {
                "kind": kind,
                "tree": tree,
                "symbols": {s.name: {"positive": bool(s.is_positive)} for s in syms if isinstance(s, sp.Symbol)},
            }
        except Exception as exc:  # noqa: BLE001
            out[name] = {"error": f"{type(exc).__name__}: {exc}"[:500]}
    return out
