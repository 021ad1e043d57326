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

import math
from collections.abc import Callable
from dataclasses import dataclass

from . import choice, expr, properties, sets, subspace
from .base import is_bool

__all__ = [
    "Kind",
    "KINDS",
    "NAMES",
    "FORMS",
    "lookup",
    "resolve",
    "ANGLE_PREFIXES",
    "is_angle_name",
    "symbol_domain",
    "draw_points",
]

# Where the symbols of an answer are evaluated: the one rule for the grader's secret points
# (kinlib.course.grader.grade.make_points) and the self-check's public ones (kinlib.course.workbook.selfcheck),
# so that a wrong answer cannot be right at home and wrong in the grade (|sin θ| for sin θ, a signed
# manipulability): joint angles over a whole turn, across every sign change; lengths (positive symbols) in
# (0.5, 2); other signed quantities (forces, velocities) on both sides of 0.
ANGLE_PREFIXES = ("theta", "q", "phi", "alpha", "beta", "gamma")
DOMAINS = {"angle": (-math.pi, math.pi), "positive": (0.5, 2.0), "signed": (-1.5, 1.5)}


def is_angle_name(name: str) -> bool:
    """Whether a symbol of this name is a joint angle (evaluated over a whole turn).

    >>> is_angle_name("theta2"), is_angle_name("thetadot1"), is_angle_name("L1")
    (True, True, False)
    """
    return str(name).startswith(ANGLE_PREFIXES)


def symbol_domain(name: str, positive: bool) -> tuple[str, tuple[float, float]]:
    """The domain a symbol is evaluated over by both judges: ``("positive", (0.5, 2))`` for a symbol the reference
    declares positive (a length), ``("angle", (-π, π))`` for a joint angle's name, else ``("signed", (-1.5, 1.5))``.

    >>> symbol_domain("L", True)[0], symbol_domain("theta1", False)[0], symbol_domain("F_x", False)
    ('positive', 'angle', ('signed', (-1.5, 1.5)))
    """
    key = "positive" if positive else "angle" if is_angle_name(name) else "signed"
    return key, DOMAINS[key]


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
    reference: Callable  # the reference value -> what the answer key keeps (the wire format round-trips it)
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


NAMES = ("default", *KINDS)  # the kind names a solution notebook may declare ("default" is "expr")
# the self-check's spec forms (kinlib.course.workbook.selfcheck.fingerprint) -> the kind that judges them
FORMS = {"matrix": "expr", "scalar": "expr", "bool": "expr", "choice": "choice", "set": "set", "subspace": "subspace"}


def draw_points(symbols: dict, seed: int, n: int) -> list[dict]:
    """``n`` points {symbol name: value}, each symbol over its :func:`symbol_domain` (``symbols``: {name:
    {"positive": bool}}), *stratified*: each symbol has one value in each n-th of its domain, in an order drawn per
    symbol, so that a sign change half a turn wide always holds a point (|sin θ| is never right by luck). The
    grader's secret points (:func:`kinlib.course.grader.grade.make_points`); the same seed gives the same points.

    >>> pts = draw_points({"theta1": {}, "L": {"positive": True}}, seed=7, n=5)
    >>> sorted(int((p["theta1"] + math.pi) // (2 * math.pi / 5)) for p in pts)
    [0, 1, 2, 3, 4]
    >>> pts == draw_points({"theta1": {}, "L": {"positive": True}}, seed=7, n=5)
    True
    """
    import random

    rng = random.Random(seed)
    pts: list[dict] = [{} for _ in range(n)]
    for name in sorted(symbols):
        _, (lo, hi) = symbol_domain(name, bool(symbols[name].get("positive")))
        order = list(range(n))
        rng.shuffle(order)
        for k in range(n):
            pts[k][name] = lo + (order[k] + rng.uniform(0.02, 0.98)) * (hi - lo) / n
    return pts


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
