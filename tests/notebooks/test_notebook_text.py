"""What a student reads in the notebooks is typeset mathematics, not formulas written as text.

Every notebook ``notebooks/0*.ipynb`` is scanned, cell by cell, for three things:

1. **Markdown cells.** Code spans (`` `...` ``) and fenced code blocks are code and are skipped. The rest is
   split into math (``$...$``, ``$$...$$``; ``\\$`` is a literal dollar) and text, and

   * the ``$`` delimiters must balance, inline math must not start or end with a space, must not run over a
     blank line, and must not sit inside a ``>`` quote over several lines (JupyterLab takes math out *before*
     the markdown is parsed, so the ``>`` of the next line would end up inside the formula);
   * **text** (outside math) holds no raw TeX: no backslash command (``\\theta``), no ``_{`` or ``^{``, no
     subscript or power written with ``_``/``^`` after a letter (``J_s``, ``x^2``);
   * **anywhere** (text and math) holds no Unicode that writes a formula as text: Greek letters,
     sub/superscript characters (``θ₁``, ``Jᵀ``, ``T⁻¹``), combining accents (``θ̇``, ``ṗ``), and the math
     operators ``× − √ ‖ ∂ ⋯ ≤ ≥ ≠ ≈ ∝ ∈ ⊙ ℝ ℤ ∞ ∑`` (the whole Mathematical Operators block U+2200–U+22FF).
     Typographic characters stay allowed in text: ``· – — … ° → ▶ ✓`` and quotes;
   * **math** holds no ``*`` (markdown emphasis; write ``\\ast`` or ``\\cdot``), no raw ``<``/``>`` (HTML; write
     ``\\lt``, ``\\gt``, ``\\le``, ``\\ge``), its braces ``{}`` balance, and no ``[`` follows ``\\\\`` or
     ``\\begin{...}`` (TeX reads it as an option: ``\\begin{aligned}[V_s]`` loses ``[V_s]``; write ``{[V_s]}``).

2. **text/latex outputs** (SymPy's ``$\\displaystyle ...$``): balanced braces, none of the Unicode above, and no
   symbol whose name fakes an operation: a transpose and a factor in one superscript (``J^{TJ}``, ``J^{T J}``),
   a superscript or subscript with a parenthesis in it (``\\det(J^{T J)}``, ``J_{s(\\theta)}``) or a superscript
   printed before a subscript (``S^{T}_{1}``, SymPy's rendering of a symbol named ``S_1^T``). The same patterns
   are refused inside the markdown's math.

3. **Code cells**: a name given to ``Symbol``/``symbols``/``Function``/``MatrixSymbol`` is a name, not a
   formula: no space, ``^ ( ) / | = + - *``, no spacing command (``\\,``) and no TeX command other than Greek
   letters, accents and font commands. Write products and operators as expressions (``J.T * J``) or display
   them with ``IPython.display.Math``.

The self-tests at the end show that the scanner catches the raw fragments the issue found
(``Ad_{e^{[S₁]θ₁}}S₂``, ``J_{s(θ)}``, ``det(JJ^{T)}``, ``J^{TJ}``) and leaves correct text alone.
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("0*.ipynb"))

# --- the character rule -------------------------------------------------------------------------------

_GREEK = "\u0370-\u03ff\u1f00-\u1fff"
_SUB_SUPER = "\u2070-\u209f\u1d2c-\u1d6a\u1d9b-\u1dbf\u00b2\u00b3\u00b9"  # ⁰-⁹ ₀-₉ ⁻ ᵀ ᵢ ² ³ ¹ ...
_COMBINING = "\u0300-\u036f\u20d0-\u20ff"  # θ̇ ṗ (combining dot above / diaeresis / arrows)
_OPERATORS = "\u2200-\u22ff\u2a00-\u2aff\u00d7\u00f7\u2016\u2102\u2115\u211a\u211d\u2124"  # ∂ ∈ ≤ − √ × ‖ ℝ ℤ ...
_PRECOMPOSED_DOTS = "ȦȧḂḃĊċḊḋĖėḞḟĠġḢḣİṀṁṄṅȮȯṖṗṘṙṠṡṪṫẆẇẊẋẎẏŻżẍẅ"
FORMULA_CHARS = re.compile(f"[{_GREEK}{_SUB_SUPER}{_COMBINING}{_OPERATORS}{_PRECOMPOSED_DOTS}]")

# --- raw TeX in text ----------------------------------------------------------------------------------

_RAW_TEX = [
    (re.compile(r"\\[A-Za-z]+"), "a TeX command outside $...$"),
    (re.compile(r"[_^]\{"), "a TeX sub/superscript outside $...$"),
    (re.compile(r"(?<![\w\\])[A-Za-z]+_[A-Za-z0-9]"), "a subscript written as text (x_s) outside $...$"),
    (re.compile(r"[A-Za-z0-9)\]]\^[A-Za-z0-9({\[]"), "a power written as text (x^2) outside $...$"),
]

_FENCE = re.compile(r"^```.*?^```", re.S | re.M)
_CODE_SPAN = re.compile(r"(`+)(.+?)\1", re.S)


def _strip_code(md: str) -> str:
    md = _FENCE.sub(" ", md)
    return _CODE_SPAN.sub(" ", md)


def split_math(md: str) -> tuple[list[tuple[bool, str]], list[str]]:
    """Split markdown (code removed) into (is_math, piece) pieces; return them and the delimiter problems."""
    pieces: list[tuple[bool, str]] = []
    problems: list[str] = []
    i, start, n = 0, 0, len(md)
    while i < n:
        ch = md[i]
        if ch == "\\" and i + 1 < n:
            i += 2
            continue
        if ch != "$":
            i += 1
            continue
        display = md.startswith("$$", i)
        opener = "$$" if display else "$"
        j = i + len(opener)
        while j < n:
            if md[j] == "\\":
                j += 2
                continue
            if md.startswith(opener, j) and (display or not md.startswith("$$", j)):
                break
            if not display and md[j] == "$":  # "$$" inside inline math
                break
            j += 1
        if j >= n or not md.startswith(opener, j):
            problems.append(f"unbalanced {opener} at …{md[max(0, i - 20) : i + 30]!r}")
            pieces.append((False, md[start:]))
            return pieces, problems
        pieces.append((False, md[start:i]))
        body = md[i + len(opener) : j]
        pieces.append((True, body))
        if not display and (body[:1].isspace() or body[-1:].isspace()):
            problems.append(f"inline math starts or ends with a space: ${body}$")
        if not body.strip():
            problems.append("empty math")
        if "\n\n" in body or re.search(r"\n[ \t]*\n", body):
            problems.append(f"math runs over a blank line: {opener}{body[:40]}…")
        if re.search(r"\n[ \t]*>", body):
            problems.append(f"math over several lines of a > quote: {opener}{body[:40]}…")
        i = start = j + len(opener)
    pieces.append((False, md[start:]))
    return pieces, problems


def _braces_balance(tex: str) -> bool:
    depth = 0
    for tok in re.findall(r"\\.|[{}]", tex):
        if tok == "{":
            depth += 1
        elif tok == "}":
            depth -= 1
            if depth < 0:
                return False
    return depth == 0


_FAKED_OUTPUT = [
    (re.compile(r"\^\{[^{}]*[()][^{}]*\}"), "a superscript with a parenthesis in it (a faked product)"),
    (re.compile(r"_\{[^{}]*[()][^{}]*\}"), "a subscript with a parenthesis (a faked function value)"),
    (re.compile(r"\^\{T\s*[A-Za-z\\]"), "a transpose followed by a factor in one superscript (J^{TJ})"),
    (re.compile(r"\^\{[^{}]*\}_\{"), "a superscript printed before a subscript (a symbol named like S_1^T)"),
]


def scan_markdown(md: str) -> list[str]:
    """Problems in one markdown cell's source (see the module docstring for the rule)."""
    found: list[str] = []
    text = _strip_code(md)
    pieces, problems = split_math(text)
    found += problems
    for is_math, piece in pieces:
        for m in FORMULA_CHARS.finditer(piece):
            where = "math" if is_math else "text"
            found.append(f"Unicode formula character {m.group()!r} in {where}: …{_around(piece, m)}…")
        if is_math:
            if "*" in piece:
                found.append(f"'*' inside math (write \\ast or \\cdot): ${piece}$")
            if re.search(r"[<>]", piece):
                found.append(f"raw < or > inside math (write \\lt, \\gt, \\le, \\ge): ${piece}$")
            if not _braces_balance(piece):
                found.append(f"unbalanced braces inside math: ${piece}$")
            if re.search(r"(\\\\|\\begin\{[a-z]*\})\s*\[", piece):
                found.append(
                    f"'[' right after \\\\ or \\begin{{...}} is read as an option (write {{[...]}}): ${piece}$"
                )
            for pattern, what in _FAKED_OUTPUT:
                found += [f"{what}: {m.group()!r}" for m in pattern.finditer(piece)]
        else:
            for pattern, what in _RAW_TEX:
                for m in pattern.finditer(piece):
                    found.append(f"{what}: …{_around(piece, m)}…")
    return found


def scan_latex_output(tex: str) -> list[str]:
    """Problems in one text/latex output (SymPy's ``$\\displaystyle ...$``)."""
    found: list[str] = []
    body = tex.strip()
    if not (body.startswith("$") and body.endswith("$")):
        found.append(f"text/latex output not in $...$: {body[:40]!r}")
    if not _braces_balance(body):
        found.append(f"unbalanced braces: {body[:60]!r}")
    for m in FORMULA_CHARS.finditer(body):
        found.append(f"Unicode formula character {m.group()!r}: …{_around(body, m)}…")
    for pattern, what in _FAKED_OUTPUT:
        for m in pattern.finditer(body):
            found.append(f"{what}: {m.group()!r}")
    return found


_NAME_CALLS = {"Symbol", "symbols", "Function", "MatrixSymbol", "Dummy"}
_NAME_COMMANDS = re.compile(
    r"\\(?:alpha|beta|gamma|delta|epsilon|varepsilon|zeta|eta|theta|vartheta|iota|kappa|lambda|mu|nu|xi|pi|rho|"
    r"sigma|tau|upsilon|phi|varphi|chi|psi|omega|Gamma|Delta|Theta|Lambda|Xi|Pi|Sigma|Phi|Psi|Omega|"
    r"dot|ddot|hat|bar|tilde|vec|mathrm|mathbf|mathcal|mathit|boldsymbol)(?![A-Za-z])"
)


def bad_symbol_name(name: str, call: str = "Symbol") -> str | None:
    """Why ``name`` fakes a formula, or None if it is a plain (possibly TeX-decorated) name."""
    names = re.split(r"[\s,]+", name.strip()) if call == "symbols" else [name]
    for one in names:
        one = re.sub(r"(\\[A-Za-z]+)\s+", r"\1{}", one)  # the space that ends a command: \dot p
        if re.search(r"[\s^()/|=+\-*]", one):
            return f"{one!r} contains a space or one of ^ ( ) / | = + - *"
        rest = _NAME_COMMANDS.sub("", one)
        if "\\" in rest:
            return f"{one!r} contains a TeX command that is not a letter, accent or font (an operator or a space)"
    return None


def scan_code(source: str) -> list[str]:
    """Symbol/Function names in a code cell that fake products, transposes, determinants, ... ."""
    lines = [ln for ln in source.splitlines() if not ln.lstrip().startswith(("%", "!"))]
    try:
        tree = ast.parse("\n".join(lines))
    except SyntaxError:
        return []
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or not node.args:
            continue
        func = node.func
        fname = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
        arg = node.args[0]
        if fname in _NAME_CALLS and isinstance(arg, ast.Constant) and isinstance(arg.value, str):
            why = bad_symbol_name(arg.value, fname)
            if why:
                found.append(f"{fname}({arg.value!r}): {why}")
    return found


def _around(s: str, m: re.Match) -> str:
    return s[max(0, m.start() - 15) : m.end() + 15].replace("\n", " ")


def scan_notebook(path: Path) -> list[str]:
    nb = json.loads(path.read_text(encoding="utf-8"))
    found = []
    for k, cell in enumerate(nb["cells"]):
        src = "".join(cell["source"])
        tag = f"{path.name} cell {k} ({cell.get('id')})"
        if cell["cell_type"] == "markdown":
            found += [f"{tag}: {p}" for p in scan_markdown(src)]
        elif cell["cell_type"] == "code":
            found += [f"{tag}: {p}" for p in scan_code(src)]
            for out in cell.get("outputs", []):
                tex = out.get("data", {}).get("text/latex")
                if tex is not None:
                    tex = "".join(tex)
                    found += [f"{tag} output: {p}" for p in scan_latex_output(tex)]
    return found


# --- the notebooks ------------------------------------------------------------------------------------


def test_there_are_notebooks():
    assert len(NOTEBOOKS) >= 6, NOTEBOOKS


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_math_is_typeset(path):
    problems = scan_notebook(path)
    assert not problems, f"{len(problems)} problem(s):\n" + "\n".join(problems)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebooks_typeset_many_formulas(path):
    """The notebooks do typeset: every notebook has many $...$ formulas (the issue found none)."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    n_math = sum(
        sum(is_math for is_math, _ in split_math(_strip_code("".join(c["source"])))[0])
        for c in nb["cells"]
        if c["cell_type"] == "markdown"
    )
    assert n_math >= 20, f"only {n_math} formulas in {path.name}"


# --- the scanner catches what it should, and nothing else ------------------------------------------------

ISSUE_FRAGMENTS = [
    "why the space Jacobian J_s has the columns S₁, Ad_{e^{[S₁]θ₁}}S₂, …",
    "display(J_{s(θ)})",
    "so det(JJ^{T)} = 1",
    "the Jacobian $J$ with Jᵀ J",
    "velocity ṗ = J θ̇",
    "joint θ₂ = −π/4",
    "a 6×3 matrix",
    "T⁻¹",
    "the ⊙ axis",
    "p_x = θ1 + L cos θ2",
    "\\det J = 0",
    "x^2 + y^2",
]


@pytest.mark.parametrize("bad", ISSUE_FRAGMENTS)
def test_scanner_catches_formulas_written_as_text(bad):
    assert scan_markdown(bad), bad


@pytest.mark.parametrize(
    "bad",
    [
        "an odd $x dollar",
        "$$\\begin{aligned} a &= b \\\\ c &= d \\end{aligned}",
        "$ x$ starts with a space",
        "$a * b$ is emphasis bait",
        "$a<b$ is an HTML tag",
        "$\\det(JJ^{T)}$ is unbalanced",
        "> $$\\begin{aligned} a &= b \\\\\n> c &= d \\end{aligned}$$",
        "math $\\theta_1 = θ₁$ with Unicode inside",
        "$$\\begin{aligned}\n[V_s] &= \\dot T T^{-1} \\end{aligned}$$",
        "$\\begin{bmatrix} R & 0 \\\\ [p]R & R \\end{bmatrix}$",
    ],
)
def test_scanner_catches_bad_math(bad):
    assert scan_markdown(bad), bad


@pytest.mark.parametrize(
    "good",
    [
        "## 1.1 · The cart-pole: geometric Jacobian $J = [\\omega_s; \\dot p]$",
        "The tool velocity $\\dot p = J\\dot\\theta$ for $\\dot\\theta = (0.3, 1)$; press ▶ to play ✓.",
        "$$\\begin{aligned} \\dot T &= [S_1]\\dot\\theta_1 T \\\\ &\\quad + \\dots \\end{aligned}$$",
        "It costs \\$5 — and `is_identically_zero(J_s)` is code, as is `θ₁`.",
        "```python\nJ_s = kinlib.jacobian_space(S, θ)\n```",
        "a line at $-45^\\circ$, the 45° line, $J^T J$, $\\det(J^T J) \\ne 0$, $a \\lt b$",
        "**$\\theta_2 = -\\pi/4 + k\\pi$** (bold math) and *an aside*",
    ],
)
def test_scanner_passes_correct_text(good):
    assert scan_markdown(good) == [], scan_markdown(good)


@pytest.mark.parametrize(
    "bad",
    [
        "$\\displaystyle J^{TJ} = 1$",
        "$\\displaystyle J^{T J} = 1$",
        "$\\displaystyle \\det(J^{T J)} = 1$",
        "$\\displaystyle \\det(JJ^{T)} = 1$",
        "$\\displaystyle J_{s(\\theta)} = 1$",
        "$\\displaystyle S^{T}_{1} = 1$",
        "$\\displaystyle θ = 1$",
    ],
)
def test_scanner_catches_faked_outputs(bad):
    assert scan_latex_output(bad), bad


def test_scanner_passes_sympy_products():
    import sympy as sp

    J = sp.MatrixSymbol("J", 6, 4)
    for expr in (J.T * J, sp.Symbol("\\dot{p}"), sp.Function("theta1")(sp.Symbol("t")), sp.Symbol("J_s")):
        assert scan_latex_output(f"$\\displaystyle {sp.latex(expr)}$") == [], sp.latex(expr)
    assert scan_latex_output("$\\displaystyle \\det(J^T J) = L_{2}^{2} + 1$") == []


@pytest.mark.parametrize(
    "code",
    [
        'sp.Symbol("J^TJ")',
        'sp.Symbol("J^T J")',
        'sp.Symbol(r"\\det(J J^T)")',
        'Symbol("det(J^TJ)")',
        'sp.Symbol(r"\\det J")',
        'sp.Symbol(r"V \\cdot V")',
        'sp.Symbol(r"\\mathrm{range}\\,J_s")',
        'sp.Symbol(r"J_s(\\theta)")',
        'sp.Symbol("S_1^T")',
        'sp.symbols("a b^T")',
    ],
)
def test_scanner_catches_faked_symbol_names(code):
    assert scan_code(code), code


def test_scanner_passes_plain_symbol_names():
    code = (
        'sp.symbols("H L1 L2", positive=True); sp.symbols("alpha1:5"); sp.Symbol(r"\\dot{p}"); sp.Symbol(r"J_{\\dot p}"); '
        'sp.Function("theta1", real=True); sp.Symbol(r"\\dot\\theta_{\\mathrm{null}}"); sp.MatrixSymbol("J", 6, 4)'
    )
    assert scan_code(code) == []
