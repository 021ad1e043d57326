"""The package's structure: layers, no import cycles, no reaching into other modules' private names, a light
math core, simple functions, and docstring examples.

kinlib is laid out by job (issue 32), in layers that import one way (a layer imports only itself and the
layers listed under it in ``ALLOWED``):

- the **core** (NumPy, SymPy and mpmath only), bottom up:
  ``kinlib._backend`` (input conversion and checks, used by every folder);
  the engine, ``kinlib.exact`` (exact decisions, 60-digit fallback, time budgets) and ``kinlib.fast``
  (generated and compiled code), which do not import each other;
  ``kinlib.kinematics`` (the textbook's rigid motions, screws, product of exponentials, Jacobians, chains, robots);
  ``kinlib.analysis`` (task rows, singularities, manipulability, velocity);
  ``kinlib`` itself (``__init__``: the user's names, re-exported from the folders);
- the **picture** layer: ``kinlib.plotting`` (matplotlib) and ``kinlib.widgets`` (ipywidgets), on the core;
- the **course** layer: ``kinlib.course`` (handouts, self-checks, grading; Jupyter), on both.

A module's size is not capped: a function's complexity is (ruff's C901, mccabe, in pyproject.toml). Everything
here is read from the source with ``ast`` (no kinlib module is imported in this process), except the tests that
import kinlib in a subprocess and the test of the old module paths.
"""

from __future__ import annotations

import ast
import functools
import importlib.metadata as md
import json
import os
import subprocess
import sys
import textwrap
from collections import defaultdict
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PKG = "kinlib"
PKG_DIR = ROOT / PKG
HEAVY = ("matplotlib", "ipywidgets", "nbformat", "nbclient", "nbconvert", "jupyter_client", "IPython")
CORE_DEPS = ("numpy", "sympy", "mpmath")  # pyproject.toml's `dependencies`


# ---------------------------------------------------------------------------------------------------------
# the package's modules, from the source tree


def _discover() -> dict[str, Path]:
    """{module name: file} for every module under kinlib/ (packages by their __init__.py)."""
    mods: dict[str, Path] = {}
    for path in sorted(PKG_DIR.rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("").parts
        if "__pycache__" in rel:
            continue
        if any(not (ROOT.joinpath(*rel[:i]) / "__init__.py").is_file() for i in range(1, len(rel))):
            continue  # inside a folder that is not a package
        if rel[-1] == "__init__":
            mods[".".join(rel[:-1])] = path
        else:
            mods.setdefault(".".join(rel), path)  # a package kinlib/x/ wins over a stray kinlib/x.py
    return mods


MODULES = _discover()


#: the core's folders, each a layer of its own (kinlib/*.py holds only __init__ and _backend)
CORE_FOLDERS = ("exact", "fast", "kinematics", "analysis")
CORE_LAYERS = {"base", *CORE_FOLDERS, "api"}


def layer(module: str) -> str:
    """base (kinlib._backend), exact, fast, kinematics, analysis, api (kinlib itself), plotting, widgets or course."""
    parts = module.split(".")
    top = parts[1] if len(parts) > 1 else ""
    if not top:
        return "api"
    if top in ("course", "plotting", *CORE_FOLDERS):
        return top
    if top.startswith("widgets"):
        return "widgets"
    return "base"


# which layers each layer may import (itself included): the engine under the textbook's kinematics, analysis
# over both, the user's names (kinlib) over the whole core, pictures over the core, the course over all
_ENGINE = {"base", "exact", "fast"}
ALLOWED = {
    "base": {"base"},
    "exact": {"base", "exact"},
    "fast": {"base", "fast"},
    "kinematics": _ENGINE | {"kinematics"},
    "analysis": _ENGINE | {"kinematics", "analysis"},
    "api": CORE_LAYERS,
    "plotting": CORE_LAYERS | {"plotting", "widgets"},
    "widgets": CORE_LAYERS | {"plotting", "widgets"},
    "course": CORE_LAYERS | {"plotting", "widgets", "course"},
}


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _rel(path: Path) -> str:
    return str(path.relative_to(ROOT))


# ---------------------------------------------------------------------------------------------------------
# the import graph, with ast


@dataclass
class Edge:
    src: str
    dst: str
    line: int
    runtime: bool  # False inside `if TYPE_CHECKING:`

    def where(self) -> str:
        return f"{_rel(MODULES[self.src])}:{self.line}"


@dataclass
class Scan:
    edges: list[Edge] = field(default_factory=list)
    private: list[str] = field(default_factory=list)  # "file:line: what"
    external: list[tuple[str, str, int]] = field(default_factory=list)  # (module, top-level package, line)


def _package_of(module: str) -> str:
    return module if MODULES[module].name == "__init__.py" else module.rpartition(".")[0]


def _resolve_from(module: str, node: ast.ImportFrom) -> str | None:
    """The absolute module name ``from X import ...`` refers to (None when it is not inside kinlib)."""
    if node.level == 0:
        base = node.module or ""
    else:
        pkg = _package_of(module).split(".")
        if node.level - 1 >= len(pkg):
            return None
        base = ".".join(pkg[: len(pkg) - (node.level - 1)])
        if node.module:
            base = f"{base}.{node.module}"
    return base if base == PKG or base.startswith(PKG + ".") else None


def _nearest_module(name: str) -> str | None:
    """``name`` if it is a kinlib module, else its closest enclosing kinlib module (a.b.c -> a.b)."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


class _Visitor(ast.NodeVisitor):
    def __init__(self, module: str, scan: Scan):
        self.module, self.scan = module, scan
        self.aliases: dict[str, str] = {}  # local name -> kinlib module it is bound to
        self.type_checking = 0
        self.file = _rel(MODULES[module])

    def _edge(self, dst: str, line: int):
        if dst != self.module:
            self.scan.edges.append(Edge(self.module, dst, line, runtime=self.type_checking == 0))

    def visit_If(self, node: ast.If):
        test = node.test
        tc = (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
            isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING"
        )
        if tc:
            self.type_checking += 1
            for stmt in node.body:
                self.visit(stmt)
            self.type_checking -= 1
            for stmt in node.orelse:
                self.visit(stmt)
        else:
            self.generic_visit(node)

    def visit_Import(self, node: ast.Import):
        for alias in node.names:
            if not (alias.name == PKG or alias.name.startswith(PKG + ".")):
                self.scan.external.append((self.module, alias.name.partition(".")[0], node.lineno))
                continue
            target = _nearest_module(alias.name)
            if target:
                self._edge(target, node.lineno)
            if alias.asname:  # import kinlib.plotting as P  ->  P is kinlib.plotting
                if alias.name in MODULES:
                    self.aliases[alias.asname] = alias.name
            else:  # import kinlib.plotting  ->  binds `kinlib`
                self.aliases[alias.name.partition(".")[0]] = PKG

    def visit_ImportFrom(self, node: ast.ImportFrom):
        base = _resolve_from(self.module, node)
        if base is None:
            if node.level == 0 and node.module:
                self.scan.external.append((self.module, node.module.partition(".")[0], node.lineno))
            return
        base_mod = _nearest_module(base)
        for alias in node.names:
            if alias.name == "*":
                if base_mod:
                    self._edge(base_mod, node.lineno)
                continue
            sub = f"{base}.{alias.name}"
            if sub in MODULES:  # from . import plotting: a module, whatever its name
                self._edge(sub, node.lineno)
                self.aliases[alias.asname or alias.name] = sub
                continue
            if base_mod:
                self._edge(base_mod, node.lineno)
            if _is_private(alias.name) and base_mod != self.module:
                self.scan.private.append(f"{self.file}:{node.lineno}: from {base} import {alias.name}")

    def visit_Call(self, node: ast.Call):
        # importlib.import_module("kinlib.x") with a constant name
        f = node.func
        name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""
        if (
            name == "import_module"
            and node.args
            and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)
        ):
            target = node.args[0].value
            if target.startswith("."):  # relative to the `package` argument: __package__, or __name__ of a package
                anchor = node.args[1] if len(node.args) > 1 else None
                is_pkg = MODULES[self.module].name == "__init__.py"
                if isinstance(anchor, ast.Name) and (
                    anchor.id == "__package__" or (anchor.id == "__name__" and is_pkg)
                ):
                    up = len(target) - len(target.lstrip("."))
                    pkg = _package_of(self.module).split(".")
                    target = ".".join([*pkg[: len(pkg) - (up - 1)], target.lstrip(".")]) if up <= len(pkg) else None
                else:
                    target = None
            if target and (target == PKG or target.startswith(PKG + ".")):
                dst = _nearest_module(target)
                if dst:
                    self._edge(dst, node.lineno)
        self.generic_visit(node)

    def visit_Attribute(self, node: ast.Attribute):
        # P._as_q where P is a kinlib module: walk the chain from its root name
        chain: list[str] = []
        cur: ast.AST = node
        while isinstance(cur, ast.Attribute):
            chain.append(cur.attr)
            cur = cur.value
        if isinstance(cur, ast.Name) and cur.id in self.aliases:
            mod = self.aliases[cur.id]
            for attr in reversed(chain):
                if f"{mod}.{attr}" in MODULES:
                    mod = f"{mod}.{attr}"
                    continue
                if _is_private(attr) and mod != self.module:
                    self.scan.private.append(f"{self.file}:{node.lineno}: {mod}.{attr} (as {cur.id}.{attr})")
                break
            return  # the whole chain is handled; do not visit its inner Attribute nodes again
        self.generic_visit(node)


@functools.cache
def _scan() -> Scan:
    scan = Scan()
    for module, path in MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        # a first pass binds the module aliases anywhere in the file (imports inside functions too),
        # the second records the edges and checks every use
        pre = _Visitor(module, Scan())
        pre.visit(tree)
        v = _Visitor(module, scan)
        v.aliases = dict(pre.aliases)
        v.visit(tree)
    return scan


def _cycles(edges: list[Edge]) -> list[tuple[list[str], list[str]]]:
    """(the modules, one cycle a -> b -> ... -> a) of each strongly connected component with more than one
    module (Tarjan), the cycle being a shortest one through the component's first module."""
    graph: dict[str, set[str]] = defaultdict(set)
    for e in edges:
        graph[e.src].add(e.dst)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    comps: list[list[str]] = []
    counter = [0]

    def strong(v: str):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(MODULES) + 1000))
    for v in sorted(MODULES):
        if v not in index:
            strong(v)
    cycles = []
    for comp in comps:  # shortest cycle through the component's first module, by BFS inside it
        members, start = set(comp), comp[0]
        prev: dict[str, str] = {}
        frontier, found = [start], None
        while frontier and not found:
            nxt = []
            for v in frontier:
                for w in sorted(graph[v] & members):
                    if w == start:
                        found = v
                        break
                    if w not in prev:
                        prev[w] = v
                        nxt.append(w)
                if found:
                    break
            frontier = nxt
        path = [found]
        while path[-1] != start:
            path.append(prev[path[-1]])
        cycles.append((comp, [*reversed(path), start]))
    return cycles


def _edge_at(src: str, dst: str) -> str:
    lines = sorted({e.line for e in _scan().edges if e.src == src and e.dst == dst})
    return f"{_rel(MODULES[src])}:{','.join(map(str, lines))}"


# ---------------------------------------------------------------------------------------------------------
# the tests


def test_modules_found():
    assert PKG in MODULES and f"{PKG}.kinematics.rigid" in MODULES, sorted(MODULES)


def test_no_import_cycles():
    cycles = _cycles([e for e in _scan().edges if e.runtime])
    msg = []
    for comp, c in cycles:
        steps = "\n".join(f"      {a} -> {b}   ({_edge_at(a, b)})" for a, b in zip(c, c[1:]))
        msg.append(
            f"  {len(comp)} modules import each other: {', '.join(comp)}\n    for example {' -> '.join(c)}:\n{steps}"
        )
    assert not cycles, (
        f"{len(cycles)} import cycle(s) (imports inside functions count too; break each by moving "
        "the shared code down a layer or into its own module):\n" + "\n".join(msg)
    )


def test_no_private_names_from_other_modules():
    assert not _scan().private, (
        f"{len(_scan().private)} use(s) of another kinlib module's private (_name) names; make the name public "
        "(no underscore, documented) in the module that owns it, or move the code:\n  " + "\n  ".join(_scan().private)
    )


def test_layers():
    bad = sorted(
        {
            f"{e.src} ({layer(e.src)}) imports {e.dst} ({layer(e.dst)}) at {e.where()}"
            for e in _scan().edges
            if layer(e.dst) not in ALLOWED[layer(e.src)]
        }
    )
    assert not bad, (
        "layer violations (_backend < exact, fast < kinematics < analysis < kinlib < plotting/widgets < course; "
        "a layer imports only from itself and the layers below it, see ALLOWED):\n  " + "\n  ".join(bad)
    )


def test_core_is_laid_out_by_job():
    """kinlib/*.py is only the package and _backend: every other core module lives in the folder of its job,
    and each folder says in its docstring what it holds and what it builds on."""
    flat = sorted(m for m in MODULES if layer(m) == "base" and m != f"{PKG}._backend")
    assert not flat, f"core modules outside the folders {CORE_FOLDERS} (put each in the folder of its job): {flat}"
    for folder in CORE_FOLDERS:
        init = MODULES[f"{PKG}.{folder}"]
        assert "builds on" in (ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or "").lower(), (
            f"{_rel(init)}'s docstring says what {folder} holds and which layers it builds on"
        )


def test_old_module_paths_are_the_new_modules():
    """Every module of the flat layout (kinlib.poe, kinlib.native, ...) still imports, as the same module object
    as its new home (so monkeypatching either name patches the real module); kinlib.exact, now the engine's
    package, still has the old module's names."""
    import importlib

    import kinlib

    assert set(kinlib.MOVED) | {"exact"} == set(OLD_MODULES)
    for old, new in kinlib.MOVED.items():
        real = importlib.import_module(f"{PKG}.{new}")
        assert importlib.import_module(f"{PKG}.{old}") is real and getattr(kinlib, old) is real, old
        assert set(getattr(real, "__all__", ())) <= set(dir(real)), old
    import kinlib.exact
    import kinlib.exact.linalg

    for name in kinlib.exact.linalg.__all__:
        assert getattr(kinlib.exact, name) is getattr(kinlib.exact.linalg, name), name
    for name in kinlib.__all__:
        assert hasattr(kinlib, name), name


#: the core's modules before the layout by job (issue 32): each must still import
OLD_MODULES = (
    "rigid screws poe jacobians chains robots taskspace singularities singular_search nearsingular manipulability "
    "velocity exact exact_rank exactfield trigpoly trigsign fallback display budget tape codegen native"
).split()


#: kinlib.course laid out by where its code runs: each folder a package whose docstring says where
COURSE_PACKAGES = {
    "kinlib.course": "the schema and the `kinlib` command",
    "kinlib.course.publish": "the instructor's machine: handouts, pages, PDFs, the in-browser site",
    "kinlib.course.workbook": "the student's own notebook: self-checks",
    "kinlib.course.answers": "what an answer is, when two are the same (self-check and grader)",
    "kinlib.course.grader": "the trusted host",
    "kinlib.course.grader.in_kernel": "sent as text into the untrusted student kernel",
    "kinlib.course.grader.isolation": "the student kernel and its sandbox",
    "kinlib.course.lms": "the LMS bundles",
    "kinlib.course.variants": "the instructor's machine and the grader: per-student variants, proved and keyed",
}
#: the code kinlib.course.grader.isolation.kernel sends as source text into a student kernel
SHIPPED_TO_KERNEL = {
    "kinlib.course.grader.in_kernel.export",
    "kinlib.course.grader.in_kernel.guard",
}


def test_course_is_laid_out_by_where_its_code_runs():
    """The course layer's packages are exactly the folders above; each says in its docstring what runs there
    and imports nothing."""
    packages = {m for m, p in MODULES.items() if layer(m) == "course" and p.name == "__init__.py"}
    assert packages == set(COURSE_PACKAGES)
    for m in packages:
        tree = ast.parse(MODULES[m].read_text())
        assert ast.get_docstring(tree), f"{_rel(MODULES[m])} has no docstring"
        assert not [n for n in tree.body if isinstance(n, (ast.Import, ast.ImportFrom))], f"{m} imports"


def test_code_sent_into_the_kernel_imports_only_what_the_kernel_has():
    """What the grader ships as text into a student kernel is all of grader/in_kernel (nothing else: answers
    are judged outside the kernel), and imports only the standard library, SymPy, NumPy, mpmath and itself: in the kernel there is
    no kinlib to import from."""
    in_kernel = {m for m in MODULES if m.startswith("kinlib.course.grader.in_kernel.")}
    assert in_kernel == SHIPPED_TO_KERNEL
    from kinlib.course.grader.isolation.kernel import IN_KERNEL_MODULES

    assert {f"kinlib.course.grader.in_kernel.{n}" for n in IN_KERNEL_MODULES} == SHIPPED_TO_KERNEL
    scan = _scan()
    allowed = set(sys.stdlib_module_names) | set(CORE_DEPS) | {"__future__"}
    bad = [f"{_rel(MODULES[m])}:{line}: {top}" for m, top, line in scan.external if m in SHIPPED_TO_KERNEL]
    bad = [b for b in bad if b.rpartition(": ")[2] not in allowed]
    bad += [
        f"{e.where()}: {e.dst}" for e in scan.edges if e.src in SHIPPED_TO_KERNEL and e.dst not in SHIPPED_TO_KERNEL
    ]
    assert not bad, "code sent into the kernel imports beyond itself and its libraries:\n  " + "\n  ".join(bad)


def test_core_needs_only_numpy_and_sympy():
    """Core modules import the standard library, numpy, sympy and mpmath only, at import time or later."""
    allowed = set(sys.stdlib_module_names) | set(CORE_DEPS) | {"__future__"}
    bad = sorted(
        {
            f"{_rel(MODULES[m])}:{line}: {top}"
            for m, top, line in _scan().external
            if layer(m) in CORE_LAYERS and top not in allowed
        }
    )
    assert not bad, "core modules import packages beyond numpy, sympy and mpmath:\n  " + "\n  ".join(bad)


#: the grader path (the trusted host and what decides an answer): no function longer than this, its docstring aside
MAX_FUNCTION_LINES = 60
GRADER_PATH = ("kinlib.course.grader", "kinlib.course.answers")


def test_grader_path_functions_are_small():
    """Every function (and method) in kinlib/course/grader/** and kinlib/course/answers/** has at most
    MAX_FUNCTION_LINES lines of code (its docstring, doctests included, not counted): one submission is graded as
    named steps, each small (issue 22; nbgrader's autograde converters are the model)."""
    long, seen = [], 0
    for m, p in MODULES.items():
        if not m.startswith(GRADER_PATH):
            continue
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                seen += 1
                n = node.end_lineno - node.lineno + 1
                doc = node.body[0]
                if (
                    isinstance(doc, ast.Expr)
                    and isinstance(doc.value, ast.Constant)
                    and isinstance(doc.value.value, str)
                ):
                    n -= doc.end_lineno - doc.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long.append(f"{_rel(p)}:{node.lineno} {node.name}: {n} lines")
    assert seen > 100, seen  # the folders were found and read
    assert not long, f"functions over {MAX_FUNCTION_LINES} lines in the grader path (split them):\n  " + "\n  ".join(
        long
    )


_LIGHT_IMPORT = textwrap.dedent("""
    import json, pkgutil, sys
    from pathlib import Path

    HEAVY = {heavy!r}
    def loaded():
        return sorted({{m for m in HEAVY for k in sys.modules if k == m or k.startswith(m + ".")}})

    import kinlib
    root = Path(kinlib.__file__).parent
    culprits = {{}}
    if loaded():
        culprits["kinlib"] = loaded()

    def core(path, prefix):  # every module below path, skipping the picture and course layers (no import)
        for info in pkgutil.iter_modules([str(path)], prefix):
            top = info.name.split(".")[1]
            if top in ("plotting", "course") or top.startswith("widgets") or info.name.endswith(".__main__"):
                continue
            yield info.name
            if info.ispkg:
                yield from core(path / info.name.rpartition(".")[2], info.name + ".")

    names = list(core(root, "kinlib."))
    for name in names:
        before = set(loaded())
        __import__(name)
        new = sorted(set(loaded()) - before)
        if new:
            culprits[name] = new
    print(json.dumps({{"modules": names, "culprits": culprits}}))
""")


def test_core_imports_no_plotting_or_jupyter():
    """``import kinlib`` and every core module load none of matplotlib, ipywidgets or Jupyter."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONSTARTUP"}
    r = subprocess.run(
        [sys.executable, "-c", _LIGHT_IMPORT.format(heavy=HEAVY)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, f"importing the core failed:\n{r.stderr[-3000:]}"
    out = json.loads(r.stdout.strip().splitlines()[-1])
    assert len(out["modules"]) > 5, out["modules"]
    assert not out["culprits"], (
        "the math core loads heavy packages (module -> what its import loaded first):\n  "
        + "\n  ".join(f"{m}: {', '.join(v)}" for m, v in out["culprits"].items())
    )


def _dist_tops(name: str) -> set[Path]:
    """The top-level files and folders a distribution installed into site-packages (package, .libs, dist-info)."""
    dist = md.distribution(name)
    tops = set()
    for f in dist.files or []:
        parts = Path(f).parts
        if parts and parts[0] != ".." and parts[0] != "__pycache__":
            tops.add(Path(dist.locate_file(parts[0])))
    return tops


@pytest.mark.slow
def test_core_runs_with_numpy_and_sympy_only(tmp_path):
    """A bare venv (no system site-packages) with only numpy, sympy and mpmath: kinlib installs and computes.

    The packages are linked from this venv (a .pth file points at a folder of symlinks), kinlib is installed
    with pip --no-index --no-deps --no-build-isolation, setuptools (the build backend) is visible to pip only.
    Nothing is downloaded.
    """
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    site = Path(
        subprocess.run(
            [py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
            check=True,
            capture_output=True,
            text=True,
        ).stdout.strip()
    )

    def link(names, into: Path) -> Path:
        into.mkdir()
        for name in names:
            try:
                tops = _dist_tops(name)
            except md.PackageNotFoundError:
                pytest.skip(f"{name} is not installed in this interpreter ({sys.prefix})")
            for top in tops:
                (into / top.name).symlink_to(top)
        return into

    deps = link(CORE_DEPS, tmp_path / "deps")
    (site / "core_deps.pth").write_text(f"{deps}\n")
    backend = link(["setuptools"], tmp_path / "backend")  # the build backend, for pip's build step only
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PIP_", "PYTHON"))}
    env |= {"PIP_NO_INDEX": "1", "PIP_DISABLE_PIP_VERSION_CHECK": "1", "PYTHONPATH": str(backend)}
    pip = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "--python",
            str(py),
            "install",
            "--no-index",
            "--no-deps",
            "--no-build-isolation",
            "-e",
            str(ROOT),
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert pip.returncode == 0, f"pip install -e failed offline:\n{pip.stdout[-2000:]}\n{pip.stderr[-3000:]}"

    env.pop("PYTHONPATH")
    run = subprocess.run(
        [
            py,
            "-c",
            "import kinlib; J = kinlib.robots.ur5().jacobian_space([0.1]*6); print(type(J).__name__, J.dtype); print(J)",
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, f"kinlib with numpy and sympy only:\n{run.stderr[-3000:]}"
    head, *rows = run.stdout.strip().splitlines()
    assert head == "ndarray float64", run.stdout
    assert len(rows) == 6 and all(len(r.strip(" []").split()) == 6 for r in rows), f"not a 6×6 array:\n{run.stdout}"
    where = subprocess.run(
        [py, "-c", "import kinlib; print(kinlib.__file__)"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert Path(where.stdout.strip()).resolve() == (PKG_DIR / "__init__.py").resolve()
    for heavy in ("matplotlib", "ipywidgets", "nbformat"):
        r = subprocess.run([py, "-c", f"import {heavy}"], cwd=tmp_path, env=env, capture_output=True, text=True)
        assert r.returncode != 0 and "ModuleNotFoundError" in r.stderr, f"{heavy} is importable in the bare venv"


# ---------------------------------------------------------------------------------------------------------
# docstring examples


def _public_api(module: str) -> tuple[list[str], list[str]]:
    """(public functions and classes defined in ``module``, those whose docstring has no ``>>>`` example)."""
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    defs: dict[str, ast.AST] = {}
    exported: list[str] | None = None

    def collect(body):
        nonlocal exported
        for node in body:
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                defs[node.name] = node
            elif isinstance(node, (ast.If, ast.Try)):
                collect(node.body)
                collect(getattr(node, "orelse", []))
                for h in getattr(node, "handlers", []):
                    collect(h.body)
            elif isinstance(node, (ast.Assign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets) and node.value is not None:
                    try:
                        exported = [str(x) for x in ast.literal_eval(node.value)]
                    except ValueError:
                        pass

    collect(tree.body)
    if exported is not None:
        public = [n for n in exported if n in defs]  # re-exports are checked where they are defined
    else:
        public = [n for n in defs if not n.startswith("_")]
    missing = [n for n in public if ">>>" not in (ast.get_docstring(defs[n]) or "")]
    return public, missing


def _is_private_module(module: str) -> bool:
    return any(part.startswith("_") and not part.startswith("__") for part in module.split("."))


def missing_examples() -> dict[str, list[str]]:
    """{module: [public names without a >>> example]} (private modules such as kinlib._backend excluded)."""
    out = {}
    for module in sorted(MODULES):
        if _is_private_module(module):
            continue
        _, missing = _public_api(module)
        if missing:
            out[module] = missing
    return out


def test_public_api_has_examples():
    missing = missing_examples()
    total = sum(map(len, missing.values()))
    assert not missing, (
        f"{total} public functions/classes have no `>>>` example in their docstring "
        "(tests/project/test_doctests.py runs them):\n  "
        + "\n  ".join(f"{m} ({len(v)}): {', '.join(v)}" for m, v in missing.items())
    )


def test_no_name_shadows_its_module():
    """`import kinlib.manipulability as m` gives the module (a function named like its module once hid it)."""
    import importlib
    import types

    import kinlib

    for name in MODULES:
        if name.count(".") != 1 or name.rsplit(".", 1)[1].startswith("_"):
            continue
        module = importlib.import_module(name)
        attr = getattr(kinlib, name.rsplit(".", 1)[1])
        assert isinstance(attr, types.ModuleType) and attr is module, f"kinlib.{name.rsplit('.', 1)[1]} is {attr!r}"
    import kinlib.manipulability as m

    assert callable(m.isotropy) and callable(m.manipulability)
