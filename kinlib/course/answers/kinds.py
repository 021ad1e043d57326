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
from .base import ANGLE_PREFIXES, is_angle_name, is_bool, symbol_domain

__all__ = [
    "Kind",
    "KINDS",
    "NAMES",
    "FORMS",
    "lookup",
    "find",
    "resolve",
    "ANGLE_PREFIXES",
    "is_angle_name",
    "symbol_domain",
    "draw_points",
]


@dataclass(frozen=True)
class Kind:
    """One kind of answer: what its functions are, for the grader and for the workbook self-check, and how many
    secret points it is evaluated at.

    >>> KINDS["set"].points, KINDS["choice"].compare.__module__, KINDS["subspace"].forms
    (2, 'kinlib.course.answers.choice', ('subspace',))
    """

    name: str  # the kind's name in the solution notebooks' metadata
    normalise: Callable  # value -> its normal form (a SymPy object, plain data, or a tag saying why not)
    describe: Callable  # (value, points, seed) -> description, in the grader (values at the secret points)
    compare: Callable  # (student's description, reference's, name[, argument]) -> (ok, message)
    reference: Callable  # the reference value -> what the answer key keeps (the wire format round-trips it)
    points: int = 5  # secret points the answer is evaluated at (0: none, the value alone)
    # the workbook self-check (kinlib.course.workbook.selfcheck), at the public sample points:
    home_canon: Callable | None = None  # value -> (form, shape, canonical form), hashed into the spec
    home_verdict: Callable | None = None  # (value, fingerprints.Judge) -> (status, message)
    stub: Callable | None = None  # value -> what the answer is, in words, for the workbook's stub
    forms: tuple = ()  # the spec forms home_canon gives (a spec's form -> the kind that judges it)
    symbols: bool = False  # whether the spec records the answer's symbols (a missing variable, signed symbols)
    home_spec: Callable | None = None  # (value, argument, salt) -> spec, for a kind not judged by a hash
    home_hints: Callable | None = None  # value -> {invariant: canonical form}: hashed into the spec (mistakes)


def _subspace_normal(value):
    return expr.to_sympy(value, vectors=True)


KINDS = {
    "expr": Kind(
        "expr",
        expr.to_sympy,
        expr.describe_expr,
        expr.compare_expr,
        expr.reference_expr,
        home_canon=expr.home_canon,
        home_verdict=expr.home_verdict,
        home_hints=expr.home_hints,
        stub=expr.stub_words,
        forms=("matrix", "scalar", "bool"),
        symbols=True,
    ),
    "subspace": Kind(
        "subspace",
        _subspace_normal,
        subspace.describe_subspace,
        subspace.compare_subspace,
        subspace.reference_subspace,
        home_canon=subspace.home_canon,
        home_verdict=subspace.home_verdict,
        stub=subspace.stub_words,
        forms=("subspace",),
        symbols=True,
    ),
    "set": Kind(
        "set",
        sets.set_conditions,
        sets.describe_set,
        sets.compare_set,
        sets.reference_set,
        points=2,
        home_canon=sets.home_canon,
        home_verdict=sets.home_verdict,
        stub=sets.stub_words,
        forms=("set",),
    ),
    "choice": Kind(
        "choice",
        choice.choice_value,
        choice.describe_choice,
        choice.compare_choice,
        choice.reference_choice,
        0,
        home_canon=choice.home_canon,
        home_verdict=choice.home_verdict,
        stub=choice.stub_words,
        forms=("choice",),
    ),
    "property": Kind(
        "property",
        properties.property_answer,
        properties.describe_property,
        properties.compare_property,
        properties.reference_property,
        home_verdict=properties.home_verdict,
        stub=properties.stub_words,
        forms=("property",),
        home_spec=properties.home_spec,
    ),
}


NAMES = ("default", *KINDS)  # the kind names a solution notebook may declare ("default" is "expr")
# the self-check's spec forms (kinlib.course.workbook.selfcheck.fingerprint) -> the kind that judges them
FORMS = {form: name for name, k in KINDS.items() for form in k.forms}


def draw_points(symbols: dict, seed: int, n: int) -> list[dict]:
    """``n`` points {symbol name: value}, each symbol over its :func:`symbol_domain` (``symbols``: {name:
    {"positive": bool}}), *stratified*: each symbol has one value in each n-th of its domain, in an order drawn per
    symbol, so that a sign change half a turn wide always holds a point (|sin θ| is never right by luck). The
    grader's secret points (:func:`kinlib.course.grader.grade.make_points`); the same seed gives the same points.

    >>> import math
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


def find(kind: str) -> tuple[Kind, str]:
    """The :class:`Kind` a solution notebook's kind name declares and its argument ("default" is ``expr``);
    ValueError for a name not in the table (:func:`lookup` reads such a name as ``expr``).

    >>> find("property:nonsingular")[0].name, find("default")[0].name
    ('property', 'expr')
    """
    base, _, arg = str(kind).partition(":")
    base = "expr" if base == "default" else base
    if base not in KINDS or bool(arg) != (KINDS[base].home_spec is not None):
        raise ValueError(f"kind must be one of {NAMES} (or property:<p>), got {kind!r}")
    return KINDS[base], arg


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
