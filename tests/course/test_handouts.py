"""``kinlib handouts`` (kinlib.course.publish.handouts) and the workbook self-checks (kinlib.course.workbook.selfcheck).

The end-to-end tests build the fixture notebook ``tests/fixtures/handouts/01_fixture_jacobians.ipynb``
(every answer kind, a solution markdown cell, check cells, a figure, a widget, an animation, a cell that
reads an answer) once per session. The npm packages are cached in build/vendor (fetched once).
"""

from __future__ import annotations

import ast
import copy
import re
from pathlib import Path

import nbformat
import numpy as np
import pytest
import sympy as sp
from IPython.core.inputtransformer2 import TransformerManager

from kinlib import robots
from kinlib.course import schema
from kinlib.course.cli import main
from kinlib.course.publish import handouts
from kinlib.course.publish.analysis import cell_names
from kinlib.course.workbook import selfcheck
from kinlib.course.workbook.selfcheck import fingerprint, verdict

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "tests" / "fixtures" / "handouts"
VENDOR = ROOT / "build" / "vendor"
STEM = "01_fixture_jacobians"


# ---------------------------------------------------------------------------------------------------
# selfcheck: fingerprints identify answers up to equivalence, and nothing else


def _v(value, ref, kind="default", salt="1.1:x"):
    return verdict(value, fingerprint(ref, kind, salt=salt), salt=salt)[0]


def test_equivalent_forms_pass():
    r = robots.planar_offset_3r()
    Js = r.jacobian_space()
    assert _v(sp.simplify(Js), Js) == "correct"
    assert _v(Js.expand(trig=True), Js) == "correct"
    # symbols of the same names but other assumptions, as a student may make them
    t1, t2, t3, L = sp.symbols("theta1 theta2 theta3 L")
    plain = Js.subs(dict(zip(r.thetas + r.params, (t1, t2, t3, L))))
    assert _v(plain, Js) == "correct"
    # numbers: floats vs exact, NumPy vs SymPy, 1x1 matrix for a scalar
    assert _v(0.7071067811865476, sp.sqrt(2) / 2) == "correct"
    assert _v(np.float64(np.sqrt(2) / 2), sp.sqrt(2) / 2) == "correct"
    assert _v(sp.Matrix([[sp.sqrt(2) / 2]]), sp.sqrt(2) / 2) == "correct"
    r1 = r.subs(L=1)
    q = [0.1, -0.7, 0.4]
    assert _v(r1.jacobian_space(q), Js.subs(dict(zip(r.thetas + r.params, q + [1])))) == "correct"


def test_wrong_answers_fail_with_a_reason():
    r = robots.planar_offset_3r()
    Js, Jb = r.jacobian_space(), r.jacobian_body()
    status, msg = verdict(Jb, fingerprint(Js))
    assert status == "incorrect" and "differ" in msg
    status, msg = verdict(Js.T, fingerprint(Js))
    assert status == "incorrect" and "6×3" in msg and "3×6" in msg
    status, msg = verdict(sp.Symbol("x"), fingerprint(Js))
    assert status == "incorrect" and "6×3" in msg
    assert verdict("J", fingerprint(Js))[0] == "incorrect"
    assert verdict(..., fingerprint(Js))[0] == "unanswered"
    assert verdict(None, fingerprint(Js))[0] == "unanswered"
    # an extra symbol that does not cancel is wrong; one that cancels is fine
    x = sp.Symbol("x")
    assert _v(Js + x * sp.ones(6, 3), Js) == "incorrect"
    assert _v(Js + x * sp.ones(6, 3) - x * sp.ones(6, 3), Js) == "correct"


def test_kinds_sets_subspaces_choices():
    th = sp.Symbol("theta2", real=True)
    n = sp.Dummy("n")
    every_pi = sp.ImageSet(sp.Lambda(n, n * sp.pi), sp.Integers)
    assert _v(sp.FiniteSet(0, sp.pi), every_pi, "set") == "correct"
    assert _v(sp.solveset(sp.sin(th), th, sp.S.Reals), every_pi, "set") == "correct"
    assert _v(sp.FiniteSet(0), every_pi, "set") == "incorrect"
    assert _v({th: sp.FiniteSet(-sp.pi, 0)}, {th: every_pi}, "set") == "correct"
    assert _v(sp.FiniteSet(0, sp.pi), {th: every_pi}, "set") == "incorrect"  # a dict was asked for
    A = sp.Matrix([[1, 0], [0, 1], [0, 0]])
    assert _v(sp.Matrix([[1, 1], [1, -1], [0, 0]]), A, "subspace") == "correct"
    assert _v([sp.Matrix([2, 0, 0]), sp.Matrix([0, 3, 0]), sp.Matrix([1, 1, 0])], A, "subspace") == "correct"
    assert _v(sp.Matrix([1, 0, 0]), A, "subspace") == "incorrect"
    assert verdict(sp.Matrix([1, 0]), fingerprint(A, "subspace"))[0] == "incorrect"  # wrong ambient dim
    assert _v((3, 1), (1, 3), "choice") == "correct"
    assert _v(3, (3,), "choice") == "correct"
    assert _v(2, 3, "choice") == "incorrect"


def test_fingerprints_reveal_nothing_and_are_salted():
    spec = fingerprint(sp.Integer(6), salt="1.3:n")
    form, shape, digest = spec.split("|")
    assert (form, shape) == ("scalar", "") and re.fullmatch(r"[0-9a-f]{16}", digest)
    assert fingerprint(sp.Integer(6), salt="1.3:n") != fingerprint(sp.Integer(6), salt="1.3:rank")
    assert verdict(6, spec, salt="1.3:n")[0] == "correct"
    assert verdict(6, spec, salt="1.3:rank")[0] == "incorrect"


def test_check_prints_a_line_per_answer(capsys):
    Js = robots.planar_offset_3r().jacobian_space()
    spec = fingerprint(Js, salt="2.2:Js")
    spec2 = fingerprint(sp.Integer(3), "choice", salt="2.2:k")
    selfcheck.check("2.2", _namespace={"Js": Js, "k": ...}, Js=spec, k=spec2)
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("part 2.2 · Js: ✓")
    assert out[1].startswith("part 2.2 · k: …") and "not answered yet" in out[1]
    selfcheck.check("2.2", _namespace={}, Js=spec)
    assert "not answered yet" in capsys.readouterr().out
    selfcheck.check("2.2", _namespace={"Js": Js.T}, Js=spec)
    assert "✗ wrong form" in capsys.readouterr().out
    assert selfcheck.last_results["2.2"] == {"Js": "incorrect"}


# ---------------------------------------------------------------------------------------------------
# the job, end to end on the fixture notebook


@pytest.fixture(scope="module")
def built(fixture_handouts):
    """(folder, entry, log) of the fixture's handouts: built once per run (tests/conftest.py, shared with
    tests/pictures/test_browser.py) with jobs=1, verify=False, site=False, pdfs=False."""
    return fixture_handouts


def _solution_cells(nb):
    return [c for c in nb.cells if "solution" in c.metadata.get("tags", [])]


def test_pages_link_only_what_was_built(built):
    """Built without the site and the PDFs (site=False, pdfs=False): no page and not the index links to them
    (every relative link of every page resolves to a file of the build)."""
    import re

    out, _entry, _log = built
    assert not (out / "lite").exists() and not (out / "pdf").exists()
    pages = [out / "index.html", *(out / "problems").glob("*.html"), *(out / "solutions").glob("*.html")]
    for page in pages:
        for href in re.findall(r'<a href="([^"#:]+)"', page.read_text(encoding="utf-8")):
            target = (page.parent / href.split("?")[0]).resolve()
            assert target.is_file(), f"{page.relative_to(out)} links {href}, which was not built"


def test_writes_every_handout_and_the_index(built):
    out, entry, log = built
    for rel in (
        f"solutions/{STEM}.html",
        f"problems/{STEM}.html",
        f"workbooks/{STEM}.ipynb",
        "index.html",
        "assets/require.js",
        "assets/widgets/embed-amd.js",
        "assets/mathjax/MathJax.js",
        "assets/mathjax/config/kinlib.js",
        "assets/font-awesome/css/font-awesome.min.css",
    ):
        assert (out / rel).is_file(), rel
    index = (out / "index.html").read_text()
    for kind in ("problems", "solutions"):
        assert f'href="{kind}/{STEM}.html"' in index
    assert f'href="workbooks/{STEM}.ipynb"' in index
    assert "Fixture: Jacobians of a planar robot" in index
    assert any(STEM in line and "done in" in line for line in log)  # progress: notebook and time


def test_pages_load_nothing_from_the_network(built):
    out, _, _ = built
    for page in [out / "index.html", *sorted(out.glob("*/*.html"))]:
        text = page.read_text()
        remote = re.findall(r"""(?:src|href)\s*=\s*["'](?:https?:)?//[^"']+""", text)
        assert not remote, f"{page.name} loads {remote[:3]}"
        for url in re.findall(r"""src=["'](\.\./assets/[^"'?]+)""", text):
            assert (page.parent / url).resolve().is_file(), url


def test_solutions_page_has_everything(built):
    out, entry, _ = built
    text = (out / "solutions" / f"{STEM}.html").read_text()
    assert "LEAK-MARKDOWN-1.1" in text and "LEAK-CHECK-OUTPUT" in text
    assert "Js = r.jacobian_space()" in _visible(text)
    assert "application/vnd.jupyter.widget-state+json" in text
    assert "../assets/mathjax/MathJax.js?config=" in text and "../assets/widgets/embed-amd.js" in text
    assert "window.kinlibAnimation(host, S);" in text  # the animation (kinlib.widgets), drawn by its own script


def test_problems_leak_no_solution(built):
    out, entry, _ = built
    text = (out / "problems" / f"{STEM}.html").read_text()
    visible = _visible(text)
    executed = entry["executed"]
    assert "LEAK-" not in text
    assert "NBVAL_CHECK_OUTPUT" not in text
    for c in executed.cells:
        tags = set(c.metadata.get("tags", []))
        if tags & {"solution", "check"}:
            for line in c.source.splitlines():  # no line of a solution or check cell's source
                if len(line.strip()) >= 12:
                    assert line.strip() not in visible, line
            for o in c.get("outputs", []):  # no output of theirs (answer values, check lines)
                for mime in ("text/latex", "text/plain"):
                    v = o.get("data", {}).get(mime)
                    if v and len(v) >= 12:
                        assert html_escape(v) not in text and v not in visible, v[:80]
    # the answer values computed independently
    r = robots.planar_offset_3r()
    for value in (sp.simplify(r.jacobian_space()),):
        assert sp.latex(value) not in text
    # no prompt numbers that betray removed cells
    assert not re.search(r"In&nbsp;\[\s*\d+\]|Out\[\s*\d+\]|In\s*\[\d+\]:", text)
    # questions, narrative, the figure, the widget and the animation stay
    assert "1.4 (3 points)" in text and "planar offset 3R at home" in text
    assert text.count("data:image/png;base64") >= 2
    assert "widget-view+json" in text and "anim" in text
    # an output computed from an answer (J_home.shape) is not shown
    assert "(6, 3)" not in text and "\\left( 6, \\  3\\right)" not in text


def test_cells_that_reveal_a_graded_answer_show_their_students_version(built):
    """Issue 30, ``"kinlib": {"reveals": [...]}``: the solutions keep the cells as they are; the problems and the
    workbook show a markdown cell's ``students`` text or leave it out, and an explorer's students' version (made in
    the kernel: no closed-form singular set, no w_max, no state in its data or text; the workbook wraps the call
    in ``without_answers``, and the workbook runs: test_workbook_runs_top_to_bottom_unanswered)."""
    import json

    out, entry, _ = built
    solutions = (out / "solutions" / f"{STEM}.html").read_text()
    problems = (out / "problems" / f"{STEM}.html").read_text()
    workbook = (out / "workbooks" / f"{STEM}.ipynb").read_text()
    assert "LEAK-REVEALS-MD" in solutions and "LEAK-REVEALS-DROPPED" in solutions
    for text in (problems, workbook):
        assert "LEAK-REVEALS" not in text and "Where does det J vanish? That is part 1.3" in text
    assert "kinlib_students_outputs" not in solutions + problems + workbook  # build-internal

    def explorer_output(nb):
        (cell,) = [c for c in nb.cells if "widgets.explorer(r1" in c.source]
        return cell, {k: v for o in cell.get("outputs", []) for k, v in o.get("data", {}).items()}

    def spec(js):
        return json.loads(re.search(r"\nvar S = (\{.*\});\nS\.skel", js).group(1))

    _, full = explorer_output(entry["executed"])
    s_full = spec(full["application/javascript"])
    assert s_full["conditions"] and s_full["wMax"] > 0 and "function c0" not in full["application/javascript"]
    _, shown = explorer_output(entry["problems"])
    js = shown["application/javascript"]
    s_students = spec(js)
    assert s_students["answers"] is False and s_students["conditions"] == [] and s_students["wMax"] == 0
    assert s_students["showMaximum"] is False and s_students["complete"] is False
    assert '"period"' not in json.dumps(s_students) and repr(s_full["wMax"]) not in js
    assert "configuration" not in shown["text/plain"] and shown["image/png"]
    assert '"answers":false' in problems  # the page shows that output
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    (cell,) = [c for c in wb.cells if "widgets.explorer(r1" in c.source]
    assert "without_answers(widgets.explorer(r1, q=[0.3, 0.7, 0.2]))" in cell.source
    assert cell.source.startswith("from kinlib.widgets import without_answers")


def html_escape(s):
    import html

    return html.escape(s, quote=False)


def _visible(page: str) -> str:
    """The page's text with the tags (syntax highlighting) removed."""
    import html

    return html.unescape(re.sub(r"<[^>]+>", "", page))


def test_problem_widget_state_is_pruned(built):
    _, entry, _ = built
    key = "application/vnd.jupyter.widget-state+json"
    state = entry["problems"].metadata["widgets"][key]["state"]
    full = entry["executed"].metadata["widgets"][key]["state"]
    assert set(state) <= set(full) and state
    shown = {
        o["data"]["application/vnd.jupyter.widget-view+json"]["model_id"]
        for c in entry["problems"].cells
        for o in c.get("outputs", [])
        if "application/vnd.jupyter.widget-view+json" in o.get("data", {})
    }
    assert shown <= set(state)


def test_workbook_is_a_valid_student_notebook(built):
    out, entry, _ = built
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    nbformat.validate(wb)
    text = (out / "workbooks" / f"{STEM}.ipynb").read_text()
    assert "LEAK-" not in text and "NBVAL_CHECK_OUTPUT" not in text and "r.jacobian_space()" not in text
    assert "widgets" not in wb.metadata
    for c in wb.cells:
        if c.cell_type == "code":
            assert c.outputs == [] and c.execution_count is None
            ast.parse(TransformerManager().transform_cell(c.source))  # every cell parses
    source = nbformat.read(FIXTURES / f"{STEM}.ipynb", as_version=4)
    src_sol, wb_sol = _solution_cells(source), _solution_cells(wb)
    assert len(src_sol) == len(wb_sol)
    for a, b in zip(src_sol, wb_sol):
        assert b.metadata.get("kinlib") == a.metadata.get("kinlib")  # metadata kept for the grader
        if a.cell_type == "code":
            for name in a.metadata["kinlib"]["answers"]:
                assert re.search(
                    rf"^{name} = \.\.\.  # TODO: .*\(part {a.metadata['kinlib']['part']}\)$", b.source, re.M
                ), b.source
    assert "the space Jacobian J_s(θ), a 6×3 Matrix" in text  # 'describe' metadata + auto
    checks = [c for c in wb.cells if "selfcheck" in c.metadata.get("tags", [])]
    assert len(checks) == 4  # 3 check cells + 1.2 without one
    assert all("check(" in c.source for c in checks)
    assert not [c for c in wb.cells if "check" in c.metadata.get("tags", [])]
    assert "LEAK-NARRATIVE" not in text
    assert any(c.source.startswith("%%needs Js") for c in wb.cells)


def _run(wb, tmp_path):
    p = tmp_path / f"{STEM}.ipynb"
    nbformat.write(wb, p)
    return handouts.run_workbook(p)


def _selfcheck_lines(nb):
    lines = []
    for c in nb.cells:
        if "selfcheck" in c.metadata.get("tags", []):
            for o in c.outputs:
                lines += [ln for ln in o.get("text", "").splitlines() if ln.startswith("part ")]
    return lines


def _stream(nb):
    return "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.outputs)


def test_workbook_runs_top_to_bottom_unanswered(built, tmp_path):
    out, _, _ = built
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    ran = _run(wb, tmp_path)
    lines = _selfcheck_lines(ran)
    assert len(lines) == 5 and all("not answered yet" in ln for ln in lines), lines
    assert "skipped: this cell uses Js" in _stream(ran)


def _solution_setup(source) -> str:
    """The imports and helper functions of the notebook's own cells (the workbook leaves out those only
    the solutions use): a student pasting the solutions needs them too."""
    parts = []
    for c in source.cells:
        if c.cell_type != "code" or {"solution", "check"} & set(c.metadata.get("tags", [])):
            continue
        try:
            tree = ast.parse(c.source)
        except SyntaxError:
            continue
        for node in tree.body:
            if isinstance(node, (ast.ImportFrom, ast.FunctionDef)):
                parts.append(ast.get_source_segment(c.source, node))
    return "\n".join(parts) + "\n"


def _paste_solutions(wb, source, edit=None):
    wb = copy.deepcopy(wb)
    src = [c for c in _solution_cells(source) if c.cell_type == "code"]
    dst = [c for c in _solution_cells(wb) if c.cell_type == "code"]
    for k, (a, b) in enumerate(zip(src, dst)):
        b.source = (_solution_setup(source) if k == 0 else "") + (edit(a.source) if edit else a.source)
    return wb


def test_workbook_with_the_solutions_passes(built, tmp_path):
    out, _, _ = built
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    source = nbformat.read(FIXTURES / f"{STEM}.ipynb", as_version=4)
    ran = _run(_paste_solutions(wb, source), tmp_path)
    lines = _selfcheck_lines(ran)
    assert len(lines) == 5 and all("✓ correct" in ln for ln in lines), lines
    assert "skipped" not in _stream(ran)


def test_workbook_with_wrong_answers_fails(built, tmp_path):
    out, _, _ = built
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    source = nbformat.read(FIXTURES / f"{STEM}.ipynb", as_version=4)
    wrong = _paste_solutions(
        wb,
        source,
        edit=lambda s: s.replace("r.jacobian_space()", "r.jacobian_body()").replace("fastest = 3", "fastest = 2"),
    )
    lines = _selfcheck_lines(_run(wrong, tmp_path))
    assert any(ln.startswith("part 1.1 · Js: ✗") for ln in lines), lines
    assert any(ln.startswith("part 1.2 · fastest: ✗") for ln in lines), lines
    assert any(ln.startswith("part 1.4 · span: ") for ln in lines)


def _setup_cell(nb):
    return next(c for c in nb.cells if c.cell_type == "code" and "workbook-setup" not in c.metadata.get("tags", []))


def test_workbook_setup_imports_only_what_the_student_starts_with(built):
    out, _, _ = built
    wb = nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)
    setup = _setup_cell(wb).source
    assert "from kinlib import robots" in setup and "r = robots.planar_offset_3r()" in setup
    assert "import sympy as sp" in setup and "import kinlib" in setup
    # the solving call of 1.4 and the helper only the check cells use are not there
    assert "column_space" not in setup and "same_matrix" not in setup
    text = (out / "workbooks" / f"{STEM}.ipynb").read_text()
    assert "column_space" not in text and "same_matrix" not in text
    ast.parse(setup)


def test_problems_show_only_the_students_setup(built):
    out, entry, _ = built
    visible = _visible((out / "problems" / f"{STEM}.html").read_text())
    assert "column_space" not in visible and "same_matrix" not in visible
    assert "from kinlib import robots" in visible  # the setup itself is still shown
    setup = _setup_cell(entry["problems"]).source
    assert setup == _setup_cell(nbformat.read(out / "workbooks" / f"{STEM}.ipynb", as_version=4)).source


def test_a_failing_notebook_is_named_with_its_cell(tmp_path, capsys):
    nbs = tmp_path / "nbs"
    nbs.mkdir()
    nb = nbformat.v4.new_notebook(
        cells=[
            nbformat.v4.new_code_cell("x = 1"),
            nbformat.v4.new_markdown_cell("text"),
            nbformat.v4.new_code_cell("y = x +\n"),
        ]
    )
    nb.cells[2].metadata["tags"] = ["solution"]
    nb.cells[2].metadata["kinlib"] = {"part": "9.9", "answers": ["y"]}
    nbformat.write(nb, nbs / "07_broken.ipynb")
    code = main(["handouts", str(nbs), "--out", str(tmp_path / "out"), "--vendor", str(VENDOR), "--jobs", "1"])
    err = capsys.readouterr().err
    assert code == 1
    assert "07_broken.ipynb" in err and "cell 2" in err and "part 9.9" in err and "SyntaxError" in err


def test_answer_groups_of_the_fixture():
    nb = nbformat.read(FIXTURES / f"{STEM}.ipynb", as_version=4)
    groups = schema.answer_groups(nb)
    assert [[(p, n, k) for p, n, k, _ in g.answers] for g in groups] == [
        [("1.1", "Js", "expr")],
        [("1.2", "fastest", "choice")],
        [("1.3", "detJ", "expr"), ("1.3", "singular", "set")],
        [("1.4", "span", "subspace")],
    ]
    assert [g.check_cell is not None for g in groups] == [True, False, True, True]


def test_names_read_before_bound():
    free, bound = cell_names(
        "for name, pose in poses.items():\n    print(name)\nJ = J.subs(a)\nf = lambda t: t + w\n%matplotlib inline\n"
    )
    assert {"poses", "J", "a", "w"} <= free and not {"name", "pose", "t"} & free
    assert {"name", "pose", "J", "f"} <= bound


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")), ids=lambda p: p.stem)
def test_real_notebooks_have_the_structure(path):
    """Every real notebook parses into answer groups, and every answer kind is one selfcheck knows: a kind of
    selfcheck.KINDS, or a property the judges know (5.5: ``property:nonsingular``)."""
    from kinlib.course.answers.properties import PROPERTIES

    nb = nbformat.read(path, as_version=4)
    meta = nb.metadata.get("kinlib", {})
    assert meta.get("notebook") == path.stem and meta.get("title")
    for g in schema.answer_groups(nb):
        for part, name, kind, _ in g.answers:
            known = kind in selfcheck.KINDS or (kind.startswith("property:") and kind.split(":", 1)[1] in PROPERTIES)
            assert part and name.isidentifier() and known, (part, name, kind)


@pytest.mark.slow
@pytest.mark.parametrize("stem", [p.stem for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))])
def test_real_workbook_with_the_solutions_passes(stem, tmp_path, real_handouts):
    """The real workbook, with the notebook's solution cells pasted back, passes every self-check. The workbook is
    the one the run's handouts build made (tests/conftest.py ``real_handouts``: handouts.make_workbook from the
    notebook executed there), so the notebook is not executed again here."""
    source = nbformat.read(ROOT / "notebooks" / f"{stem}.ipynb", as_version=4)
    groups = schema.answer_groups(source)
    wb = nbformat.read(real_handouts / "workbooks" / f"{stem}.ipynb", as_version=4)
    nbformat.validate(wb)
    p = tmp_path / f"{stem}.ipynb"
    nbformat.write(_paste_solutions(wb, source), p)
    lines = _selfcheck_lines(handouts.run_workbook(p))
    n_answers = sum(len(g.answers) for g in groups)
    assert len(lines) == n_answers
    bad = [ln for ln in lines if "✓ correct" not in ln and "no automatic self-check" not in ln]
    assert not bad, bad


def test_a_second_build_executes_nothing_and_changes_no_file(built, monkeypatch):
    """`make handouts` twice in a row: the second build reuses the section (kinlib.course.publish.incremental)."""
    out, first, _log = built
    pages = sorted(p for p in out.rglob("*") if p.is_file() and p.name != "index.html" and "assets" not in p.parts)
    before = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in pages}

    def no_kernel(*a, **k):
        raise AssertionError("a reused section must not be executed")

    monkeypatch.setattr(handouts, "execute_notebook", no_kernel)
    log: list = []
    again = handouts.build(FIXTURES, out, vendor=VENDOR, jobs=1, verify=False, site=False, pdfs=False, log=log.append)
    assert any(f"{STEM}: reused" in line for line in log)
    assert {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in pages} == before
    assert again[0]["title"] == first["title"] and again[0]["sections"] == first["sections"]
    assert again[0]["executed"].cells == first["executed"].cells
    assert again[0]["problems"].cells == first["problems"].cells
