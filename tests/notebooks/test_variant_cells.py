"""The instructor notebooks declare their variants (issue 33, item 1): 04's 4.1 (the three configurations (a), (b), (c))
and 05's 5.3 (the configuration θ) vary per student.

For every notebook that declares variants (``metadata.kinlib.variants``):

* the spec parses, the original values are among the choices, and every parameter can take more than one value;
* the variant cell is ``assignment_source(spec, spec.original)``, and every ``variant_markdown`` renders with the original
  values to exactly the cell's text (so the notebook the instructor runs is the one the build varies);
* another variant (``spec.apply``) rewrites the variant cell and the question text, and the workbook made from it
  states the variant's numbers and not the original's;
* no code cell of the varying parts that the workbook keeps (not solution, not check) writes the original numbers
  itself: they come from the variant cell.

The oracles here are written independently of ``kinlib.course.variants.spec``'s writers: the original numbers as code
are matched by a regular expression built from the fractions, and as text by the figures' "−π/8" form.
"""

from __future__ import annotations

import re
from fractions import Fraction
from pathlib import Path

import nbformat
import pytest

from kinlib.course import schema
from kinlib.course.publish import handouts
from kinlib.course.variants import spec as vs

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
# the notebooks that must declare variants, and the names of their parameters (issue 33, item 1)
EXPECTED = {
    "04_interpreting_the_jacobian": {"theta_a", "theta_b", "theta_c"},
    "05_singularities_planar": {"q53"},
}


def _read(path):
    return nbformat.read(path, as_version=4)


def _varying():
    out = []
    for p in NOTEBOOKS:
        nb = _read(p)
        if vs.Spec.from_notebook(nb) is not None:
            out.append(p)
    return out


VARYING = _varying()


def _spec(path):
    nb = _read(path)
    return nb, vs.Spec.from_notebook(nb)


def _templates(nb):
    return {
        i: schema.cell_meta(c)["variant_markdown"]
        for i, c in enumerate(nb.cells)
        if "variant_markdown" in schema.cell_meta(c)
    }


def _other(spec):
    """A variant that differs from the original in every element that has another choice."""
    values = {}
    for p in spec.params:
        orig = spec.original[p.name] if p.vector else [spec.original[p.name]]
        new = [next((c for c in choices if c != o), o) for choices, o in zip(p.choices, orig)]
        values[p.name] = new if p.vector else new[0]
    return values


def _workbook(nb):
    groups = schema.answer_groups(nb)
    fps = {(idx, name): {"spec": "none||", "describe": ""} for g in groups for _, name, _, idx in g.answers}
    return handouts.make_workbook(nb, groups, fps)


def _code_pattern(kind: str, text: str) -> str:
    """A number as code may write it: ``-pi / 8``, ``3*np.pi/4``, ``0``, ``Rational(1, 4)``, ``0.25``."""
    f = Fraction(text)
    if f == 0:
        return r"(?<![\w.])0(?:\.0*)?(?![\w.])"
    sign = r"-\s*" if f < 0 else r"(?<!-)(?<!-\s)"
    p, q = abs(f.numerator), f.denominator
    if kind == "angle":
        body = r"(?:(?:np|sp|numpy|sympy|math)\.)?pi"
        if p != 1:
            body = rf"{p}\s*\*\s*{body}"
        if q != 1:
            body += rf"\s*/\s*{q}(?![\d.])"
        return sign + body
    if q == 1:
        return sign + rf"(?<![\w.]){p}(?:\.0*)?(?![\w.])"
    return sign + rf"(?:Rational\(\s*{p}\s*,\s*{q}\s*\)|(?<![\w.]){p}\s*/\s*{q}(?![\d.])|{float(Fraction(p, q))})"


def _text_form(kind: str, text: str) -> str:
    """A number as the figures' titles write it: ``−π/8``, ``3π/4``, ``0``."""
    f = Fraction(text)
    if f == 0:
        return "0"
    p, q = abs(f.numerator), f.denominator
    body = (("" if p == 1 else str(p)) + "π") if kind == "angle" else str(p)
    return ("−" if f < 0 else "") + body + (f"/{q}" if q != 1 else "")


def _part_spans(nb, parts):
    """The cells of each varying part: from its question to the next question or ``#``/``##`` heading."""
    spans = []
    questions = [i for i, c in enumerate(nb.cells) if "question" in schema.cell_tags(c)]
    for i in questions:
        if not re.match(r"\*\*(\d+\.\d+) ", nb.cells[i].source) or nb.cells[i].source[2:].split(" ")[0] not in parts:
            continue
        end = next((j for j in questions if j > i), len(nb.cells))
        head = next(
            (
                j
                for j in range(i + 1, end)
                if nb.cells[j].cell_type == "markdown" and re.match(r"#{1,2} ", nb.cells[j].source)
            ),
            end,
        )
        spans.append(range(i, head))
    return spans


def test_the_notebooks_that_vary_declare_it():
    declared = {p.stem: {q.name for q in _spec(p)[1].params} for p in VARYING}
    for stem, names in EXPECTED.items():
        assert declared.get(stem) == names, stem


@pytest.mark.parametrize("path", VARYING, ids=[p.stem for p in VARYING])
def test_spec_and_cells_read_as_the_original(path):
    nb, spec = _spec(path)
    vs.check_values(spec, spec.original, "original")
    for p in spec.params:
        assert p.domain(spec.original[p.name]), p.name
        assert any(len(c) > 1 for c in p.choices), f"{p.name} never varies"
    assert spec.size > 1
    assert set(spec.parts) <= set(schema.notebook_sections(nb)) and spec.parts
    # the variant cell: one code cell, exactly what the original values write
    idx = vs.variant_cell_index(nb)
    assert idx is not None
    assert nb.cells[idx].source == vs.assignment_source(spec, spec.original)
    assert not {"solution", "check"} & set(schema.cell_tags(nb.cells[idx]))
    # the markdown: every template renders to its cell's text, names only parameters, and the questions have one
    templates = _templates(nb)
    assert templates
    for i, t in templates.items():
        assert nb.cells[i].cell_type == "markdown"
        assert "{{" in t
        assert vs.render_markdown(t, spec, spec.original) == nb.cells[i].source, f"cell {i}"
    for part in spec.parts:
        q = [i for i, c in enumerate(nb.cells) if "question" in schema.cell_tags(c) and f"**{part} (" in c.source]
        assert q and all(i in templates for i in q), part
    assert vs.mismatches(nb, spec) == []


@pytest.mark.parametrize("path", VARYING, ids=[p.stem for p in VARYING])
def test_another_variant_rewrites_the_question_and_the_variant_cell(path):
    nb, spec = _spec(path)
    values = _other(spec)
    assert values != spec.original
    out = vs.apply(nb, spec, values)
    idx = vs.variant_cell_index(nb)
    assert out.cells[idx].source == vs.assignment_source(spec, values) != nb.cells[idx].source
    for i in _templates(nb):
        assert out.cells[i].source != nb.cells[i].source, f"cell {i}"
    # the workbook of that variant: its variant cell and its question text carry the variant's numbers only
    wb, wb0 = _workbook(out), _workbook(nb)
    by_id, by_id0 = {c.get("id"): c for c in wb.cells}, {c.get("id"): c for c in wb0.cells}
    vid = nb.cells[idx].get("id")

    # (the workbook trims the imports a student's cell does not use: compare the assignments)
    def assignments(src):
        return [line for line in src.splitlines() if not line.startswith(("from ", "import "))]

    assert assignments(by_id[vid].source) == assignments(vs.assignment_source(spec, values))
    assert assignments(by_id0[vid].source) == assignments(vs.assignment_source(spec, spec.original))
    questions = [c for c in wb.cells if "question" in schema.cell_tags(c)]
    changed = [c for c in questions if c.source != by_id0[c.get("id")].source]
    assert changed, "no question of the workbook changed with the variant"
    for p in spec.params:
        shown = vs.render_markdown("{{" + p.name + "}}", spec, values)
        original = vs.render_markdown("{{" + p.name + "}}", spec, spec.original)
        assert any(shown in c.source for c in questions), p.name
        assert not [c.get("id") for c in wb.cells if c.cell_type == "markdown" and original in c.source], p.name


@pytest.mark.parametrize("path", VARYING, ids=[p.stem for p in VARYING])
def test_no_kept_code_cell_of_a_varying_part_writes_the_original_numbers(path):
    nb, spec = _spec(path)
    idx = vs.variant_cell_index(nb)
    kept_ids = {c.get("id") for c in _workbook(nb).cells}
    spans = _part_spans(nb, spec.parts)
    assert spans and all(len(s) > 1 for s in spans)
    cells = {i for s in spans for i in s} | set(range(idx, idx + 3))
    code, text = [], []
    for p in spec.params:
        raw = spec.original[p.name] if p.vector else [spec.original[p.name]]
        if p.vector:  # a lone scalar (π/4) is too common to search for; a vector is the configuration itself
            code.append((p.name, re.compile(r"\s*,\s*".join(_code_pattern(p.type, x) for x in raw))))
        text.append((p.name, "(" + ", ".join(_text_form(p.type, x) for x in raw) + ")"))
    # the oracle finds the numbers where they are written: in the variant cell itself
    assert all(rx.search(nb.cells[idx].source) for _, rx in code)
    checked = 0
    for i in sorted(cells):
        c = nb.cells[i]
        if i == idx or c.cell_type != "code" or c.get("id") not in kept_ids:
            continue
        if {"solution", "check"} & set(schema.cell_tags(c)):
            continue
        checked += 1
        for name, rx in code:
            assert not rx.search(c.source), f"cell {i} writes {name}'s original numbers: {rx.search(c.source)[0]!r}"
        for name, t in text:
            assert t not in c.source, f"cell {i} writes {name}'s original numbers as text: {t!r}"
    assert checked
    # the numbers flow from the variant cell: some kept code cell after it uses each name
    later = [c.source for c in nb.cells[idx + 1 :] if c.cell_type == "code" and c.get("id") in kept_ids]
    for p in spec.params:
        assert any(re.search(rf"\b{p.name}\b", s) for s in later), p.name


def test_the_code_oracle_finds_what_it_must():
    rx = re.compile(r"\s*,\s*".join(_code_pattern("angle", x) for x in ("-1/8", "1/4", "3/4", "0")))
    for s in ("[-pi / 8, pi / 4, 3 * pi / 4, 0]", "(-np.pi/8, sp.pi/4, 3*np.pi/4, 0.0)"):
        assert rx.search(s), s
    for s in ("[pi / 8, pi / 4, 3 * pi / 4, 0]", "[-pi / 8, pi / 4, 3 * pi / 40, 0]", "[-pi / 8, pi / 4, pi / 4, 0]"):
        assert not rx.search(s), s
    assert _text_form("angle", "-3/8") == "−3π/8" and _text_form("angle", "1") == "π"


@pytest.mark.slow
@pytest.mark.parametrize("path", VARYING, ids=[p.stem for p in VARYING])
def test_the_notebook_runs_for_another_variant(path, tmp_path):
    """Every cell runs for a variant that differs from the original everywhere it can: the checks compare the
    printed numbers only at the printed configuration, and an independent computation at every one (a check that
    failed for other numbers would make the build reject every draw)."""
    nb, spec = _spec(path)
    values = _other(spec)
    out = tmp_path / path.name
    nbformat.write(vs.apply(nb, spec, values), out)
    executed, _groups, fps = handouts.execute_notebook(out, timeout=600)
    errors = [
        o for c in executed.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.output_type == "error"
    ]
    assert not errors
    printed = [
        "".join(o.get("text", ""))
        for c in executed.cells
        if "check" in schema.cell_tags(c)
        for o in c.get("outputs", [])
        if o.output_type == "stream"
    ]
    assert any("this variant" in t for t in printed), printed
    assert fps
