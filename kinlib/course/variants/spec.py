"""A variant is data: which numbers of a notebook vary, over what, and how they are written into it.

The instructor's notebook declares its variants in ``metadata.kinlib.variants``::

    {"params": {"theta_a": {"type": "angle", "choices": [["-1/8", "1/8"], ["1/4"], ["1/8", "0"]]},
                "L_fig": {"type": "number", "choices": ["1/4", "1/2"]}},
     "original": {"theta_a": ["-1/8", "1/4", "1/8"], "L_fig": "1/4"},
     "parts": ["4.1"]}

A value is an exact rational written ``"p"`` or ``"p/q"``; an ``angle`` is that many π. A vector parameter has one
list of choices per element. ``original`` is the instructor's own numbers (the solution pages show them).

Two kinds of cells carry the numbers, both written from the values, never evaluated:

- the **variant cell**, the code cell with ``"kinlib": {"variant": true}``, whose whole source is
  :func:`assignment_source` (``theta_a = [-pi / 8, pi / 4, pi / 8]``);
- markdown cells with ``"kinlib": {"variant_markdown": "... $\\theta = {{theta_a}}$ ..."}``: the text with
  ``{{name}}`` or ``{{name[i]}}`` where a number stands (:func:`render_markdown`).

In the instructor's notebook both must read exactly as the original values write them (a test checks it), so the
notebook the instructor runs is the notebook the build varies.

>>> spec = Spec.from_metadata({"params": {"q": {"type": "angle", "choices": [["1/4", "-1/4"], ["0", "1/2"]]},
...                                       "L": {"type": "number", "choices": ["1", "3/2"]}},
...                            "original": {"q": ["1/4", "0"], "L": "1"}})
>>> spec.size
8
>>> print(assignment_source(spec, {"q": ["-1/4", "1/2"], "L": "3/2"}), end="")
# The numbers of this problem set: the course's build writes each student's own here.
from sympy import pi, Rational
q = [-pi / 4, pi / 2]
L = Rational(3, 2)
>>> render_markdown(r"At $\\theta = {{q}}$ with $L = {{L}}$ ($\\theta_1 = {{q[0]}}$)", spec, spec.original)
'At $\\\\theta = (\\\\pi/4, 0)$ with $L = 1$ ($\\\\theta_1 = \\\\pi/4$)'
"""

from __future__ import annotations

import copy
import json
import keyword
import re
from dataclasses import dataclass, field
from fractions import Fraction

__all__ = [
    "Param",
    "Spec",
    "TYPES",
    "assignment_source",
    "render_markdown",
    "apply",
    "variant_cell_index",
    "canonical",
    "check_values",
    "mismatches",
    "value",
]

TYPES = ("angle", "number")
_NUMBER = re.compile(r"-?\d{1,6}(/[1-9]\d{0,5})?\Z")
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,40}\Z")
_PLACEHOLDER = re.compile(r"\{\{([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d{1,2})\])?\}\}")
MAX_CHOICES = 64  # per element
MAX_ELEMENTS = 12  # per vector
HEADER = "# The numbers of this problem set: the course's build writes each student's own here."


def _fraction(text, where: str) -> Fraction:
    if not isinstance(text, str) or not _NUMBER.match(text):
        raise ValueError(f"{where}: expected an exact number written 'p' or 'p/q', got {text!r}")
    return Fraction(text)


@dataclass(frozen=True)
class Param:
    """One varying number or vector: its type and the choices of each element (a scalar has one element).

    >>> p = Param("q", "angle", (("1/4", "-1/4"), ("0",)), True)
    >>> p.domain(["-1/4", "0"]), p.domain(["1/2", "0"]), p.domain("1/4")
    (True, False, False)
    """

    name: str
    type: str
    choices: tuple  # of tuples of str, one per element
    vector: bool

    def domain(self, values) -> bool:
        """True when ``values`` (this parameter's JSON value) is one of its draws."""
        got = values if self.vector else [values]
        if not isinstance(got, list) or len(got) != len(self.choices):
            return False
        return all(isinstance(v, str) and v in c for v, c in zip(got, self.choices))


@dataclass(frozen=True)
class Spec:
    """A notebook's variants: its parameters (in the order written), the original values, the parts they touch.

    >>> spec = Spec.from_metadata({"params": {"L": {"type": "number", "choices": ["1", "2", "3"]}},
    ...                            "original": {"L": "1"}, "parts": ["2.1"]})
    >>> spec.size, spec.param("L").choices, spec.parts
    (3, (('1', '2', '3'),), ('2.1',))
    """

    params: tuple  # of Param
    original: dict = field(hash=False)
    parts: tuple = ()

    @property
    def size(self) -> int:
        """How many different variants the choices allow."""
        n = 1
        for p in self.params:
            for c in p.choices:
                n *= len(c)
        return n

    @staticmethod
    def from_metadata(meta) -> Spec:
        """The spec from ``metadata.kinlib.variants``; ValueError naming the field when it is malformed.

        >>> Spec.from_metadata({"params": {"q": {"type": "angle", "choices": ["1/4", "x"]}}, "original": {"q": "1/4"}})
        Traceback (most recent call last):
            ...
        ValueError: variants.params.q.choices[1]: expected an exact number written 'p' or 'p/q', got 'x'
        """
        if not isinstance(meta, dict) or not isinstance(meta.get("params"), dict) or not meta["params"]:
            raise ValueError("variants: expected {'params': {name: {...}}, 'original': {...}}")
        params = tuple(_param(name, p) for name, p in meta["params"].items())
        original = meta.get("original")
        if not isinstance(original, dict) or set(original) != {p.name for p in params}:
            raise ValueError("variants.original: expected a value for every parameter and nothing else")
        spec = Spec(params, original, tuple(str(x) for x in meta.get("parts", ())))
        check_values(spec, original, "variants.original")
        return spec

    @staticmethod
    def from_notebook(nb) -> Spec | None:
        """The notebook's spec, or None when it declares no variants."""
        meta = (nb.get("metadata") or {}).get("kinlib") or {}
        return Spec.from_metadata(meta["variants"]) if meta.get("variants") else None

    def param(self, name: str) -> Param:
        for p in self.params:
            if p.name == name:
                return p
        raise KeyError(name)


def _param(name, p) -> Param:
    where = f"variants.params.{name}"
    if not isinstance(name, str) or not _NAME.match(name) or keyword.iskeyword(name):
        raise ValueError(f"{where}: a parameter's name must be a Python identifier")
    if not isinstance(p, dict) or p.get("type") not in TYPES:
        raise ValueError(f"{where}.type: expected one of {', '.join(TYPES)}")
    choices = p.get("choices")
    if not isinstance(choices, list) or not choices:
        raise ValueError(f"{where}.choices: expected a non-empty list")
    vector = isinstance(choices[0], list)
    elements = choices if vector else [choices]
    if len(elements) > MAX_ELEMENTS:
        raise ValueError(f"{where}.choices: at most {MAX_ELEMENTS} elements")
    for i, c in enumerate(elements):
        w = f"{where}.choices" + (f"[{i}]" if vector else "")
        if not isinstance(c, list) or not c or len(c) > MAX_CHOICES or len(set(c)) != len(c):
            raise ValueError(f"{w}: expected 1 to {MAX_CHOICES} different values")
        for j, v in enumerate(c):
            _fraction(v, f"{w}[{j}]")
    return Param(name, p["type"], tuple(tuple(c) for c in elements), vector)


def check_values(spec: Spec, values, where: str = "values") -> None:
    """ValueError unless ``values`` gives every parameter one of its draws (and nothing else).

    >>> spec = Spec.from_metadata({"params": {"L": {"type": "number", "choices": ["1", "2"]}}, "original": {"L": "1"}})
    >>> check_values(spec, {"L": "2", "x": "1"})
    Traceback (most recent call last):
        ...
    ValueError: values: expected a value for every parameter and nothing else
    """
    if not isinstance(values, dict) or set(values) != {p.name for p in spec.params}:
        raise ValueError(f"{where}: expected a value for every parameter and nothing else")
    for p in spec.params:
        if not p.domain(values[p.name]):
            raise ValueError(f"{where}.{p.name}: {values[p.name]!r} is not one of the parameter's choices")


def canonical(values) -> str:
    """The values as canonical JSON (names sorted): what the key and the draw's name hash.

    >>> canonical({"q": ["1/4", "0"], "L": "1"})
    '{"L":"1","q":["1/4","0"]}'
    """
    return json.dumps(values, sort_keys=True, separators=(",", ":"))


def value(param: Param, raw):
    """The SymPy value of one parameter (an angle is that many π; a vector a list).

    >>> value(Param("q", "angle", (("1/4",), ("-2",)), True), ["1/4", "-2"])
    [pi/4, -2*pi]
    """
    import sympy as sp

    def one(text):
        f = _fraction(text, param.name)
        r = sp.Rational(f.numerator, f.denominator)
        return r * sp.pi if param.type == "angle" else r

    return [one(v) for v in raw] if param.vector else one(raw)


# ---------------------------------------------------------------------------------------------------
# Writing the numbers: Python for the variant cell, LaTeX for the markdown


def _python(kind: str, text: str) -> str:
    f = Fraction(text)
    p, q = f.numerator, f.denominator
    if kind == "number":
        return str(p) if q == 1 else f"Rational({p}, {q})"
    if p == 0:
        return "0"
    sign, p = ("-" if p < 0 else ""), abs(p)
    body = "pi" if p == 1 else f"{p} * pi"
    return f"{sign}{body}" + (f" / {q}" if q != 1 else "")


def _latex(kind: str, text: str) -> str:
    f = Fraction(text)
    p, q = f.numerator, f.denominator
    if kind == "number":
        return str(p) if q == 1 else f"{p}/{q}"
    if p == 0:
        return "0"
    sign, p = ("-" if p < 0 else ""), abs(p)
    return sign + ("" if p == 1 else str(p)) + r"\pi" + (f"/{q}" if q != 1 else "")


def assignment_source(spec: Spec, values) -> str:
    """The variant cell's source for ``values`` (checked against the spec first).

    >>> spec = Spec.from_metadata({"params": {"q": {"type": "angle", "choices": [["1/4", "-3/4"], ["0", "1"]]}},
    ...                            "original": {"q": ["1/4", "0"]}})
    >>> assignment_source(spec, {"q": ["-3/4", "1"]}).splitlines()[-1]
    'q = [-3 * pi / 4, pi]'
    >>> assignment_source(spec, {"q": ["1/2", "0"]})
    Traceback (most recent call last):
        ...
    ValueError: values.q: ['1/2', '0'] is not one of the parameter's choices
    """
    check_values(spec, values)
    lines = [HEADER, "from sympy import pi, Rational"]
    for p in spec.params:
        v = values[p.name]
        code = "[" + ", ".join(_python(p.type, x) for x in v) + "]" if p.vector else _python(p.type, v)
        lines.append(f"{p.name} = {code}")
    return "\n".join(lines) + "\n"


def render_markdown(template: str, spec: Spec, values) -> str:
    """``template`` with each ``{{name}}`` / ``{{name[i]}}`` replaced by the value's LaTeX (no ``$``).

    >>> spec = Spec.from_metadata({"params": {"q": {"type": "angle", "choices": [["1/4"], ["0"]]}},
    ...                            "original": {"q": ["1/4", "0"]}})
    >>> render_markdown("{{p}}", spec, spec.original)
    Traceback (most recent call last):
        ...
    ValueError: variant_markdown: {{p}} names no parameter
    """
    check_values(spec, values)
    names = {p.name: p for p in spec.params}

    def sub(m):
        name, idx = m.group(1), m.group(2)
        if name not in names:
            raise ValueError(f"variant_markdown: {m.group(0)} names no parameter")
        p, v = names[name], values[name]
        if idx is not None:
            if not p.vector or int(idx) >= len(v):
                raise ValueError(f"variant_markdown: {m.group(0)} is not an element of {name}")
            return _latex(p.type, v[int(idx)])
        return "(" + ", ".join(_latex(p.type, x) for x in v) + ")" if p.vector else _latex(p.type, v)

    return _PLACEHOLDER.sub(sub, template)


def _source(cell) -> str:
    s = cell.get("source", "")
    return "".join(s) if isinstance(s, list) else s


def variant_cell_index(nb) -> int | None:
    """Index of the notebook's variant cell (``"kinlib": {"variant": true}``); ValueError if there are several.

    >>> variant_cell_index({"cells": [{"cell_type": "markdown", "metadata": {}},
    ...                               {"cell_type": "code", "metadata": {"kinlib": {"variant": True}}}]})
    1
    """
    found = [
        i
        for i, c in enumerate(nb["cells"])
        if c.get("cell_type") == "code" and ((c.get("metadata") or {}).get("kinlib") or {}).get("variant") is True
    ]
    if len(found) > 1:
        raise ValueError(f"variants: {len(found)} variant cells (cells {found}); a notebook has one")
    return found[0] if found else None


def apply(nb, spec: Spec, values):
    """A deep copy of ``nb`` with the variant cell and every ``variant_markdown`` cell written for ``values``; the
    spec itself is left out of the copy (a student's file needs no domain, and the grader never reads it).

    >>> meta = {"params": {"L": {"type": "number", "choices": ["1", "2"]}}, "original": {"L": "1"}}
    >>> nb = {"metadata": {"kinlib": {"variants": meta}}, "cells": [
    ...     {"cell_type": "code", "metadata": {"kinlib": {"variant": True}}, "source": ""},
    ...     {"cell_type": "markdown", "metadata": {"kinlib": {"variant_markdown": "$L = {{L}}$"}}, "source": "$L = 1$"}]}
    >>> out = apply(nb, Spec.from_notebook(nb), {"L": "2"})
    >>> out["cells"][0]["source"].splitlines()[-1], out["cells"][1]["source"], out["metadata"]["kinlib"]
    ('L = 2', '$L = 2$', {})
    """
    out = copy.deepcopy(nb)
    idx = variant_cell_index(out)
    if idx is None:
        raise ValueError("variants: the notebook declares variants but has no variant cell")
    out["cells"][idx]["source"] = assignment_source(spec, values)
    for c in out["cells"]:
        template = ((c.get("metadata") or {}).get("kinlib") or {}).get("variant_markdown")
        if c.get("cell_type") == "markdown" and isinstance(template, str):
            c["source"] = render_markdown(template, spec, values)
    kin = (out.get("metadata") or {}).get("kinlib")
    if isinstance(kin, dict):
        kin.pop("variants", None)
    return out


def mismatches(nb, spec: Spec) -> list[str]:
    """Where the instructor's notebook does not read as its original values write it (empty: consistent).

    >>> meta = {"params": {"L": {"type": "number", "choices": ["1", "2"]}}, "original": {"L": "1"}}
    >>> nb = {"metadata": {"kinlib": {"variants": meta}}, "cells": [
    ...     {"cell_type": "code", "metadata": {"kinlib": {"variant": True}}, "source": "L = 1"}]}
    >>> mismatches(nb, Spec.from_notebook(nb))
    ['cell 0: the variant cell is not assignment_source(original)']
    """
    bad = []
    idx = variant_cell_index(nb)
    if idx is None:
        return ["no variant cell"]
    if _source(nb["cells"][idx]) != assignment_source(spec, spec.original):
        bad.append(f"cell {idx}: the variant cell is not assignment_source(original)")
    for i, c in enumerate(nb["cells"]):
        template = ((c.get("metadata") or {}).get("kinlib") or {}).get("variant_markdown")
        if isinstance(template, str) and render_markdown(template, spec, spec.original) != _source(c):
            bad.append(f"cell {i}: variant_markdown with the original values is not the cell's text")
    return bad
