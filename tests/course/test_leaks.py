"""Nothing graded given away (issue 30): every graded answer of the answer key, searched for in every students' file.

The answer key is the grader's: :func:`kinlib.course.grader.refdata.load_references` runs each solution notebook in
the grader's own kernel and reads every graded answer as data (SymPy trees, choices), as ``make grade`` does. The
students' files are what ``make handouts AUDIENCE=students`` publishes (``build/handouts-students``, built once per
run under a file lock, reused section by section when a ``make handouts AUDIENCE=students`` made it just before;
``KINLIB_STUDENTS_HANDOUTS_DIR`` tests an existing build): the index, the problem pages and the cheat sheet (their
HTML, scripts included: a student can read the explorers' data), the PDFs (their text, by ``pdftotext``), the
workbooks (every string in the notebook: sources, outputs, metadata), and the JupyterLite site's files (the notebooks
it serves and its contents listings).

Each answer is turned into the forms a student would recognise (:func:`forms`): its LaTeX and SymPy text, simplified
and expanded (det J = √2 L² sin(θ2 + π/4) and L²(sin θ2 + cos θ2)); a set of angles as "θ2 = −π/4", "θ2 = 3π/4" in
LaTeX, SymPy, Unicode, decimals (−0.785) and degrees (−45°); a number as its decimals; a rank, a joint count, a
chosen joint or an empty singular set in the words the notebooks use ("rank 4", "six joints", "joints 1 and 2 tie",
"no singular configuration"). Text is compared after one normalisation (:func:`normalise`: LaTeX, Unicode and
SymPy spellings of the same formula become one string), and decimals by value (any number written in a file that
rounds to the answer, to the digits it is written with, at least three significant ones).

Strong forms (a whole formula, a set written with its variable, a matrix) are searched in every file; weak ones
(a bare number, a word like "rank 2", a joint number) only in the files of the answer's own notebook (its problem
page and PDF, its workbook and the site's copy of it), where they would answer that part and not a statement about
another robot. A hit is allowed only by :data:`ALLOWED` (value, file and reason: what the question itself gives).
The test fails listing every hit: the part, the answer, the form, the file and the text around it.
"""

from __future__ import annotations

import html
import json
import math
import os
import re
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest
import sympy as sp

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "build" / "handouts-students"

# ---------------------------------------------------------------------------------------------------
# One spelling for a formula


_SUB = str.maketrans("₀₁₂₃₄₅₆₇₈₉", "0123456789")
_UNICODE = [("−", "-"), ("–", "-"), ("π", "pi"), ("θ", "theta"), ("√", "sqrt"), ("·", ""), ("⋅", ""), ("ᵀ", "^t"),
            ("²", "^2"), ("³", "^3"), ("°", "deg"), ("×", "x"), ("\u2009", ""), ("\u00a0", ""), ("ṗ", "pdot"),
            ("ω", "omega"), ("θ̇", "thetadot")]  # fmt: skip
_TEX_DROP = re.compile(r"\\(left|right|middle|big|Big|bigg|displaystyle|quad|qquad|mathrm|operatorname|text|,|;|!|:| )")
_TAG = re.compile(r"</?[a-zA-Z][^<>]*>")  # HTML tags (θ<sub>2</sub>), not a comparison "a < b"
_FRAC = re.compile(r"\\[dt]?frac\{([^{}]*)\}\{([^{}]*)\}")
_SQRT = re.compile(r"\\sqrt\{([^{}]*)\}")


def normalise(text: str) -> str:
    """One spelling of a formula for LaTeX, Unicode, HTML and SymPy text: no tags, no spaces, parentheses or braces, lower case,
    ``\\frac{a}{b}`` → ``a/b``, ``**`` → ``^``, ``\\theta_{2}``/``θ₂``/``theta_2`` → ``theta2``, ``π`` → ``pi``, ``°`` → ``deg``.

    >>> a = normalise(r"\\sqrt{2} L^{2} \\sin{\\left(\\theta_{2} + \\frac{\\pi}{4} \\right)}")
    >>> a == normalise("sqrt(2)*L**2*sin(theta2 + pi/4)") == normalise("√2 L² sin(θ₂ + π/4)")
    True
    """
    t = html.unescape(_TAG.sub("", text)).translate(_SUB)
    for a, b in _UNICODE:
        t = t.replace(a, b)
    t = _TEX_DROP.sub("", t)
    for _ in range(4):  # nested fractions and roots, from the inside
        t = _FRAC.sub(r"(\1)/(\2)", t)
        t = _SQRT.sub(r"sqrt(\1)", t)
    t = re.sub(r"\\(cdot|ast|times)", "", t)
    t = re.sub(r"_\{?(\d+)\}?", r"\1", t)  # theta_{2}, theta_2
    t = t.replace("\\", "").replace("**", "^").replace("*", "")
    t = re.sub(r"[\s(){}]", "", t)
    return t.lower()


# ---------------------------------------------------------------------------------------------------
# The answer key and its forms


@dataclass(frozen=True)
class Form:
    """A way a student would recognise answer ``name`` of ``part``: ``text`` (normalised, found as a substring),
    ``regex`` (on the normalised text), or ``number`` (a value found as a written decimal); ``strong`` forms are
    searched in every file, the others in the files of ``notebook``."""

    notebook: str
    part: str
    name: str
    label: str
    text: str = ""
    regex: str = ""
    number: float | None = None
    strong: bool = True


def _num(v):
    try:
        f = complex(sp.N(v, 30))
    except (TypeError, ValueError):
        return None
    return f.real if abs(f.imag) < 1e-12 and math.isfinite(f.real) else None


def _angle_texts(v) -> list[tuple[str, str]]:
    """How an angle ``v`` (exact, radians) is written: LaTeX, SymPy, decimals, degrees (label, text)."""
    out = [("LaTeX", sp.latex(v)), ("SymPy", str(v))]
    f = _num(v)
    if f is not None and f != 0:
        out += [("decimal", f"{f:.3f}"), ("decimal", f"{f:.2f}")]
        deg = math.degrees(f)
        out += [("degrees", f"{deg:g}°"), ("degrees", f"{deg:.1f}°")]
    return out


def _members(S, lo=-math.pi - 1e-9, hi=math.pi + 1e-9) -> list:
    """The members of a set of angles in [−π, π] (an ImageSet over the integers, a Union, a FiniteSet)."""
    if isinstance(S, sp.Union):
        return [m for a in S.args for m in _members(a, lo, hi)]
    if isinstance(S, sp.FiniteSet):
        return list(S)
    if isinstance(S, sp.ImageSet) and len(S.lamda.variables) == 1:
        k = S.lamda.variables[0]
        return [S.lamda.expr.subs(k, j) for j in range(-4, 5) if lo <= float(S.lamda.expr.subs(k, j)) <= hi]
    return []


def _expr_variants(v) -> list:
    """The value and the spellings the notebooks display: kinlib's display form (with and without phase shifts),
    and for a scalar also simplified, trig-expanded and factored."""
    from kinlib.display import simplify_for_display

    out = [v]
    ways = [simplify_for_display, lambda e: simplify_for_display(e, phase_shifts=True)]
    if not isinstance(v, sp.MatrixBase):
        ways += [
            sp.simplify,
            lambda e: sp.expand(sp.expand_trig(e)),
            lambda e: sp.factor(sp.expand(sp.expand_trig(e))),
        ]
    for f in ways:
        try:
            w = f(v)
        except Exception:  # noqa: BLE001 (a spelling SymPy cannot make is no spelling)
            continue
        if w not in out:
            out.append(w)
    return out


#: words in which the notebooks state an answer that is a small number, a choice or a set with no member (weak
#: forms, searched in the answer's own notebook): (part, answer name) -> [(label, regex on the normalised text)]
WORDS = {
    ("1.1", "detJ_zeros"): [
        (
            "the pole vertical is singular",
            r"(upright|hanging|vertical)[^.]{0,60}singular|singular[^.]{0,60}(upright|hanging|vertical)",
        )
    ],
    ("1.3", "n_required"): [("six joints", r"(six|6)joints"), ("n = 6", r"(?<![a-z])n=6(?!\d)")],
    # a rank in words; not an explorer's readout of the rank where it stands ("full rank 6", "rank 6 of 6")
    ("1.3", "rank_required"): [("rank 6", r"(?<!full)rank=?6(?!\d|of)")],
    ("5.3", "rank53"): [("rank 2", r"(?<!full)rank=?2(?!\d|of)"), ("rank 2 < 3", r"ranks?is2")],
    ("6.1", "rank_J"): [("rank 4", r"(?<!full)rank=?4(?!\d|of)"), ("keeps rank", r"keeps?rank|neverdrops?rank")],
    ("6.1", "singular_set"): [
        ("no singular configuration", r"nosingular(configuration|ity|ities)"),
        ("never singular", r"neversingular|notsingularanywhere|nowheresingular"),
    ],
    ("4.1", "joint_a"): [("joint 2 largest", r"(actuate|largest|maximi[sz]e|strongest)[^.]{0,40}(joint2|secondjoint)")],
    ("4.1", "joint_b"): [
        ("joint 1 largest", r"(actuate|largest|maximi[sz]e|strongest)[^.]{0,40}(joint1(?!\d)|firstjoint)")
    ],
    ("4.1", "joint_c"): [
        ("joints 1 and 2 tie", r"(joints?1and2|firstandsecondjoints?|1and2)[^.]{0,20}ti(e|ed)|tiebetweenjoints1and2")
    ],
    ("5.3", "can_move"): [("a line at −45°", r"(line|direction|along)[^.]{0,40}-45deg")],
    ("5.3", "cannot_move"): [("cannot move at 45°", r"(cannot|can'?t|not)move[^.]{0,60}(45deg|1,1)")],
    ("7.2", "removes_all"): [("does not remove all", r"(doesnot|doesn'?t|cannot|can'?t)remove(all|every)")],
    ("7.3", "lengths_can_remove"): [("no lengths remove", r"nochoiceoflengths|nolengths")],
}


def forms(notebook: str, part: str, name: str, ans: dict) -> list[Form]:
    """Every form of the graded answer ``name`` (the grader's reference ``ans``: a wire tree or a choice)."""
    from kinlib.course.answers import wire

    out = [Form(notebook, part, name, label, regex=rx, strong=False) for label, rx in WORDS.get((part, name), [])]
    if "choice" in ans:
        return out
    value = wire.load(ans["tree"], max_nodes=10 * wire.MAX_NODES)

    def strong(label, text, min_len=10):
        t = normalise(text)
        if len(t) >= min_len:
            out.append(Form(notebook, part, name, label, text=t))

    def weak_text(label, text, min_len=4):
        t = normalise(text)
        if len(t) >= min_len:
            out.append(Form(notebook, part, name, label, text=t, strong=False))

    def as_set(S, sym=None, alone=True):
        if alone:  # "kπ − π/4, k ∈ ℤ" (one joint's set is the answer; another robot's may be spelled alike)
            weak_text("the set (LaTeX)", sp.latex(S), 10)
            weak_text("the set (SymPy)", str(S), 10)
        for m in _members(S):
            for label, t in _angle_texts(m):
                if sym is not None:  # "θ2 = −π/4" in every spelling (θ2 of this notebook's robot)
                    rx = r"(?<![0-9])" + re.escape(normalise(f"{sym} = {t}")) + r"(?![0-9a-z/.^])"
                    out.append(Form(notebook, part, name, f"{sym} = {m} ({label})", regex=rx, strong=False))
            f = _num(m)
            if f is not None and f != 0:
                out.append(Form(notebook, part, name, f"{m} as a decimal", number=f, strong=False))

    if isinstance(value, dict):
        for sym, S in value.items():
            as_set(S, sym, len(value) == 1)
        strong("the set with its variable (SymPy)", str(value))  # {theta2: ImageSet(...)}
        strong("the set with its variable (LaTeX)", sp.latex(value))
    elif isinstance(value, (list, tuple)):  # several families, or no singular configuration at all
        for d in value:
            if isinstance(d, dict):
                for sym, S in d.items():
                    as_set(S, sym, len(value) == 1 and len(d) == 1)
                strong("a family with its variables (SymPy)", str(d))
        if value:
            strong("the families (SymPy)", str(value))
    elif isinstance(value, sp.Set):
        as_set(value)
    elif isinstance(value, sp.MatrixBase):
        for w in _expr_variants(value):
            strong("the matrix (LaTeX)", sp.latex(w), 14)
            strong("the matrix (SymPy)", str(w), 14)
            if 1 in w.shape:  # a column or row vector, as a tuple
                entries = ", ".join(str(x) for x in w)
                weak_text("the vector as a tuple", f"({entries})", 8)
                strong("the vector (LaTeX row)", sp.latex(w.T if w.shape[1] == 1 else w), 14)
    elif isinstance(value, sp.Expr):
        f = _num(value)
        if f is not None:  # a number: its decimals (and its exact spelling if it is not just a small integer)
            if not (value.is_Integer and abs(int(value)) < 100):
                strong(f"{name} (LaTeX)", sp.latex(value), 6)
                out.append(Form(notebook, part, name, f"{value} as a decimal", number=f, strong=False))
            strong(f"{name} = {value}", f"{name} = {value}", 4)
        else:
            for w in _expr_variants(value):
                strong("the expression (LaTeX)", sp.latex(w))
                strong("the expression (SymPy)", str(w))
    unique = {}
    for f in out:  # one form per spelling (a LaTeX and a SymPy text often normalise alike)
        unique.setdefault((f.text, f.regex, f.number), f)
    return list(unique.values())


# ---------------------------------------------------------------------------------------------------
# What a student can read


def _strings(obj, acc):
    if isinstance(obj, str):
        acc.append(obj)
    elif isinstance(obj, dict):
        for v in obj.values():
            _strings(v, acc)
    elif isinstance(obj, list):
        for v in obj:
            _strings(v, acc)
    return acc


_STYLE = re.compile(r"<style[^>]*>.*?</style>", re.S)


def students_files(out: Path) -> dict:
    """{relative path: its text} for every file of a students' build a student reads."""
    files = {}
    for p in sorted(out.rglob("*")):
        rel = p.relative_to(out).as_posix()
        if not p.is_file() or rel.startswith(("assets/", ".")) or "/." in rel:
            continue
        if p.suffix == ".html" and not rel.startswith("lite/"):  # (its style sheets are no reading)
            files[rel] = _STYLE.sub("", p.read_text(encoding="utf-8", errors="replace"))
        elif p.suffix == ".pdf":
            r = subprocess.run(["pdftotext", "-layout", str(p), "-"], capture_output=True, text=True, check=True)
            files[rel] = r.stdout
        elif p.suffix == ".ipynb" or (rel.startswith("lite/api/") and p.suffix == ".json"):
            try:
                files[rel] = "\n".join(_strings(json.loads(p.read_text(encoding="utf-8")), []))
            except ValueError:
                files[rel] = p.read_text(encoding="utf-8", errors="replace")
        elif rel.startswith("lite/files/"):
            files[rel] = p.read_text(encoding="utf-8", errors="replace")
    return files


def _notebook_of(rel: str, stems: list) -> str | None:
    return next((s for s in stems if s in rel), None)


_NUMBER = re.compile(r"(?<![\w.])-?\d+\.\d+")


def _decimal_hit(f: float, text: str):
    """The first number written in ``text`` (normalised) with at least three significant digits that rounds to ``f``."""
    for m in _NUMBER.finditer(text):
        s = m.group(0)
        digits = len(s.replace("-", "").replace(".", "").lstrip("0"))
        decimals = len(s.split(".")[1])
        if digits >= 3 and abs(float(s) - f) <= 0.5 * 10**-decimals + 1e-12:
            return m
    return None


#: characters that, next to a match, make it a piece of a larger formula or list rather than the answer itself
_JOINED = {"expression": set("+-/^0123456789abcdefghijklmnopqrstuvwxyz_"), "tuple": set(",.0123456789-")}


def _standalone(text: str, f: Form):
    """The span of the first occurrence of ``f.text`` in ``text`` that stands alone: an expression not a term of a
    longer sum or product (``p = θ1 + L cos θ2`` does not state det J = L cos θ2), a tuple not a run inside a longer
    list of numbers (a URDF joint table); other forms at their first occurrence."""
    joined = next((chars for key, chars in _JOINED.items() if key in f.label), None)
    i = text.find(f.text)
    while i >= 0:
        j = i + len(f.text)
        before, after = text[i - 1 : i], text[j : j + 1]
        if joined is None or not (
            before in joined or (after in joined and after not in "0123456789abcdefghijklmnopqrstuvwxyz")
        ):
            return i, j
        i = text.find(f.text, i + 1)
    return None


@dataclass(frozen=True)
class Hit:
    form: Form
    file: str
    context: str

    def __str__(self):
        f = self.form
        return f"{f.part} {f.name} [{f.label}] in {self.file}: …{self.context}…"


def find_hits(all_forms: list, files: dict, stems: list) -> list[Hit]:
    hits = []
    for rel, raw in files.items():
        text = normalise(raw)
        own = _notebook_of(rel, stems)  # None: the index, the cheat sheet (about every notebook)
        for f in all_forms:
            if not f.strong and own is not None and own != f.notebook:
                continue
            if f.text:
                m = _standalone(text, f)
            elif f.regex:
                r = re.search(f.regex, text)
                m = r.span() if r else None
            else:
                r = _decimal_hit(f.number, text)
                m = r.span() if r else None
            if m is None:
                continue
            hit = Hit(f, rel, text[max(0, m[0] - 50) : m[1] + 50])
            if not allowed(hit):
                hits.append(hit)
    return hits


#: Hits that are not leaks: the value is given in the question itself. (part, answer, form label regex, file regex,
#: context regex (normalised text around the hit), why).
ALLOWED: list[tuple[str, str, str, str, str, str]] = [
    (
        "1.1", "detJ", r"expression", r"01_", r"p_x=theta1\+lcostheta2",
        "1.1 gives the cart-pole's tool position p_x = θ1 + L cos θ2 (the problem set's eq. 1) to differentiate; "
        "det J = L cos θ2 is spelled like its second term, but the question states no determinant",
    ),
    (
        "1.1", "detJ_zeros", r"decimal", r"01_", r'"q0":',
        "the UR5 explorer of 1.3 starts at the textbook's configuration (0, −π/4, π/2, −π/4, π/2, 0): its joint values "
        "are the given pose, not the cart-pole's singular angles",
    ),
    (
        "7.6", "singular_76", r"theta2 = pi/2", r"07_", r"poleupright\$?theta2=pi/2",
        "7.4's question gives the cart-pole's configuration, the pole upright at θ2 = π/2: the question's own data, "
        "about another robot than 7.6's slide-and-2R arm",
    ),
    (
        "7.5", "scara_singular", r"the set", r"07_", r"singularconfigurations:\[theta3:imageset",
        "the own-arm cell after 7.5 prints the singular set of its default elbow arm (waist, shoulder, elbow): its "
        "elbow θ3 ∈ {kπ} is that arm's, spelled like a set of the SCARA's θ2 but about another joint and robot",
    ),
    *(
        (part, name, r"theta2 = (0|pi) ", r"07_", r"armstretched\$?theta2=0\$?,folded\$?theta2=pi",
         "7.1's predict question offers the 2R arm stretched (θ2 = 0) or folded (θ2 = π) as choices for a circular "
         "ellipse: the question's own words, about the 2R arm, not 7.2's 4R or 7.5's SCARA")
        for part, name in (("7.2", "singular_4r"), ("7.5", "scara_singular"))
    ),
]  # fmt: skip


def allowed(hit: Hit) -> bool:
    f = hit.form
    for part, name, label, file, context, _why in ALLOWED:
        if (
            part == f.part
            and name == f.name
            and re.search(label, f.label)
            and re.search(file, hit.file)
            and re.search(context, hit.context)
        ):
            return True
    return False


# ---------------------------------------------------------------------------------------------------
# The fixtures: the answer key and the students' build


@pytest.fixture(scope="module")
def answer_key(grader_reference_cache):
    """[(notebook, part, answer name, reference)] of every graded answer of notebooks/ (the grader's answer key)."""
    from kinlib.course.grader.refdata import load_references
    from kinlib.course.grader.secret import load_secret

    refs = load_references(ROOT / "notebooks", grader_reference_cache, secret=load_secret(), jobs=2)
    key = []
    for nid, ref in sorted(refs.items()):
        assert not ref.error, f"{nid}: the answer key could not be built: {ref.error}"
        for p in ref.parts:
            for name in p["answers"]:
                key.append((nid, p["part"], name, ref.answers[name]))
    return key


def _lock(path: Path):
    import fcntl

    path.parent.mkdir(parents=True, exist_ok=True)
    f = open(path, "a+")
    fcntl.flock(f, fcntl.LOCK_EX)
    return f


@pytest.fixture(scope="module")
def students_build(real_handouts) -> Path:
    """``make handouts AUDIENCE=students`` (its code and options: pages, site, PDFs, workbooks run) into
    build/handouts-students, once per run (a file lock; a build current for the notebooks and kinlib is reused).
    As ``make handouts AUDIENCE=students`` after ``make handouts``, it takes the sections and PDFs that the run's
    full build (``real_handouts``, tests/conftest.py) made from the same inputs (``reuse_from``: the same bytes,
    never a solution) instead of executing and printing them again; the site is its own. (A fixture argument, so
    that conftest's schedule hands this module out after the build has had its head start.)"""
    if os.environ.get("KINLIB_STUDENTS_HANDOUTS_DIR"):
        return Path(os.environ["KINLIB_STUDENTS_HANDOUTS_DIR"]).resolve()
    from kinlib.course.publish import handouts

    if shutil.which("pdftotext") is None:
        pytest.fail("pdftotext is missing: `make poppler` installs it")
    with _lock(ROOT / "build" / ".handouts-students.lock"):
        handouts.build(
            ROOT / "notebooks",
            OUT,
            vendor=ROOT / "build" / "vendor",
            jobs=2,
            audience="students",
            reuse_from=real_handouts,
            log=lambda s: None,
        )
    return OUT


# ---------------------------------------------------------------------------------------------------
# The tests


def test_normalise_makes_one_spelling_of_each_form():
    th = sp.Symbol("theta2")
    e = sp.sqrt(2) * sp.Symbol("L") ** 2 * sp.sin(th + sp.pi / 4)
    assert normalise(sp.latex(e)) == normalise(str(e)) == normalise("√2 L² sin(θ₂ + π/4)")
    assert normalise(r"\theta_{2} = - \frac{\pi}{4}") == normalise("θ2 = −π/4") == normalise("theta2 = -pi/4")
    assert normalise(r"\frac{3 \pi}{4}") == normalise("3*pi/4") == normalise("3π/4")
    assert _decimal_hit(-math.pi / 4, normalise("q0: [0.5, -0.7853981633974483]"))
    assert _decimal_hit(-math.pi / 4, normalise("θ2 = -0.785 rad"))
    assert not _decimal_hit(-math.pi / 4, normalise("x = -0.78, y = 1.785"))  # 2 digits; another number


def test_forms_of_a_set_and_an_expression():
    """The forms of 5.1's answers, and that they find the sentences issue 30 quoted from the students' site."""
    th2, L = sp.Symbol("theta2", real=True), sp.Symbol("L", positive=True)
    k = sp.Symbol("k", integer=True)
    S = {th2: sp.ImageSet(sp.Lambda(k, sp.pi * k - sp.pi / 4), sp.Integers)}
    det = sp.sqrt(2) * L**2 * sp.sin(th2 + sp.pi / 4)
    from kinlib.course.answers import wire

    fs = forms("05", "5.1", "singular_configs", {"tree": wire.dump(S)})
    fs += forms("05", "5.1", "detJ", {"tree": wire.dump(det)})
    found = find_hits(fs, {"05/problems.html": "the mistake misses the drop at θ<sub>2</sub>=&minus;π/4"}, ["05"])
    assert {h.form.name for h in found} == {"singular_configs"}
    found = find_hits(fs, {"05.html": r"$$\det J = \sqrt{2}\,L^2 \sin\left(\theta_2 + \frac{\pi}{4}\right)$$"}, ["05"])
    assert {h.form.name for h in found} == {"detJ"}
    found = find_hits(fs, {"05.html": "det J = L²(sin θ₂ + cos θ₂)"}, ["05"])
    assert {h.form.name for h in found} == {"detJ"}
    assert not find_hits(fs, {"05.html": "Let θ = (π/4, −π/4, π/4): is it singular?"}, ["05"])  # 5.3's question


@pytest.mark.slow
def test_no_students_file_states_a_graded_answer(answer_key, students_build):
    """Every graded answer of the answer key, in every form above, in every file of the students' build: no hit
    outside :data:`ALLOWED`. The failure lists each hit (part, answer, form, file, the text around it)."""
    stems = sorted(p.stem for p in (ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    assert not (students_build / "solutions").exists(), "a students' build has no solutions"
    files = students_files(students_build)
    kinds = {rel.split("/")[0] for rel in files}
    assert {"problems", "workbooks", "pdf", "lite"} <= kinds | {"lite" if any("lite/" in r for r in files) else ""}
    assert any(r.startswith("lite/files/") and r.endswith(".ipynb") for r in files), "the site's notebooks"
    all_forms = [f for nid, part, name, ans in answer_key for f in forms(nid, part, name, ans)]
    searched = sorted({(f.part, f.name) for f in all_forms})
    assert len(searched) >= 30, searched
    hits = find_hits(all_forms, files, stems)
    grouped: dict = {}
    for h in hits:  # one line per answer, form and passage, with every file it is in
        grouped.setdefault((h.form.part, h.form.name, h.form.label, h.context), []).append(h.file)
    report = "\n".join(
        f"- {part} {name} [{label}]: …{context}…\n    in {', '.join(fs)}"
        for (part, name, label, context), fs in sorted(grouped.items())
    )
    if hits:
        pytest.fail(
            f"{len(hits)} graded answer(s) stated in the students' files ({len(files)} files searched for "
            f"{len(searched)} answers in {len(all_forms)} forms):\n{report}"
        )
