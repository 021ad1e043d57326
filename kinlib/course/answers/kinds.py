"""The table of answer kinds: for each kind, its module's normaliser, description, comparer and reference form.

One module per kind holds everything that kind means (:mod:`.expr`, :mod:`.subspace`, :mod:`.sets`,
:mod:`.choice`, :mod:`.properties`); this table is how the rest of kinlib reaches it, by the kind's name as the
solution notebooks declare it (``kinds`` / ``properties`` in a solution cell's metadata,
:func:`kinlib.course.schema.grading_kind`):

============  ==========================  ==========================================================
kind          module                      "the same answer"
============  ==========================  ==========================================================
``expr``      :mod:`.expr`                same shape and values at the points (also "default")
``subspace``  :mod:`.subspace`            same span, whatever the basis and its scaling
``set``       :mod:`.sets`                same members (angles modulo 2π)
``choice``    :mod:`.choice`              same items, as a set (``True`` is not joint 1)
``property``  :mod:`.properties`          the property asked holds (``property:nonsingular``)
============  ==========================  ==========================================================

The grader (:mod:`kinlib.course.grader.judge`, through :func:`kinlib.course.answers.describe.describe` and
:func:`kinlib.course.answers.compare.compare`) and the workbook self-check
(:mod:`kinlib.course.workbook.selfcheck`, through the same normalisers and :func:`.choice.choice_key`) use it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from . import choice, expr, properties, sets, subspace
from .base import is_bool

__all__ = ["Kind", "KINDS", "lookup", "resolve"]


@dataclass(frozen=True)
class Kind:
    """One kind of answer: what its functions are, and how many secret points it is evaluated at.

    >>> KINDS["set"].points, KINDS["choice"].compare.__module__
    (2, 'kinlib.course.answers.choice')
    """

    name: str  # the kind's name in the solution notebooks' metadata
    normalise: Callable  # value -> its normal form (a SymPy object, plain data, or a tag saying why not)
    describe: Callable  # (value, points, seed) -> description, in the grader (values at the secret points)
    compare: Callable  # (student's description, reference's, name[, argument]) -> (ok, message)
    reference: Callable  # the reference value -> what the answer key keeps (srepr round-trips it)
    points: int = 5  # secret points the answer is evaluated at (0: none, the value alone)


def _subspace_normal(value):
    return expr.to_sympy(value, vectors=True)


KINDS = {
    "expr": Kind("expr", expr.to_sympy, expr.describe_expr, expr.compare_expr, expr.reference_expr),
    "subspace": Kind(
        "subspace",
        _subspace_normal,
        subspace.describe_subspace,
        subspace.compare_subspace,
        subspace.reference_subspace,
    ),
    "set": Kind("set", sets.set_conditions, sets.describe_set, sets.compare_set, sets.reference_set, points=2),
    "choice": Kind(
        "choice", choice.choice_value, choice.describe_choice, choice.compare_choice, choice.reference_choice, 0
    ),
    "property": Kind(
        "property",
        properties.property_answer,
        properties.describe_property,
        properties.compare_property,
        properties.reference_property,
    ),
}


def lookup(kind: str) -> tuple[Kind, str]:
    """The :class:`Kind` of a kind's name and its argument (``"property:nonsingular"`` → the property kind and
    "nonsingular"); "default" and names not in the table are ``expr``.

    >>> [(k.name, arg) for k, arg in map(lookup, ("property:nonsingular", "set", "default"))]
    [('property', 'nonsingular'), ('set', ''), ('expr', '')]
    """
    base, _, arg = str(kind).partition(":")
    return KINDS.get(base, KINDS["expr"]), arg


def resolve(kind: str, value) -> str:
    """The kind a reference answer is judged as: an ``expr`` answer that is a set of configurations is a ``set``,
    a yes/no or a string a ``choice``; any other kind as declared.

    >>> import sympy as sp
    >>> resolve("expr", [{sp.Symbol("t"): {0}}]), resolve("expr", True), resolve("expr", 2), resolve("set", 1)
    ('set', 'choice', 'expr', 'set')
    """
    if kind == "expr" and sets.looks_like_set(value):
        return "set"
    if kind == "expr" and (is_bool(value) or isinstance(value, str)):
        return "choice"
    return kind
