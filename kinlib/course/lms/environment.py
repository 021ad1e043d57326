"""What a grading container must install: derived once, from the code that runs there, pinned by environment.txt.

Two kinds of code run in an LMS container: the student's workbooks (whatever their code cells import: numpy, sympy,
modern_robotics, ...) and kinlib itself (the grader, and the parts of kinlib the workbooks import). The
requirements are therefore read from that code, not written by hand:

* the top-level modules imported by the solution notebooks' code cells (``import x``, ``from x import y``; IPython
  magics and shell lines skipped) and by kinlib's own modules except :mod:`kinlib.course.publish` (handouts, site,
  PDFs: the instructor's machine only), less the standard library and kinlib;
* plus :data:`KERNEL`, the kernel program the grader starts by name (never imported in code);
* each mapped to the distribution that provides it in the instructor's environment (the one the references were
  computed in) and pinned to the version environment.txt names (or, failing that, the installed one).

The bundle's ``setup.sh`` installs ``requirements.txt`` with ``-c constraints.txt`` and then checks that every
module in ``imports.txt`` imports.

>>> sorted(code_imports("import numpy as np\\nfrom sympy import Matrix\\n%matplotlib inline\\nimport os, kinlib.poe"))
['kinlib', 'numpy', 'os', 'sympy']
"""

from __future__ import annotations

import ast
import importlib.metadata
import json
import re
import sys
from pathlib import Path

__all__ = ["KERNEL", "code_imports", "notebook_imports", "kinlib_imports", "requirements"]

KERNEL = ("ipykernel",)  # started by name (python -c "from ipykernel import kernelapp ..."), never imported by kinlib
_SKIP = ("kinlib", "__future__")


def code_imports(source: str) -> set[str]:
    """Top-level module names imported by ``source`` (Python; lines starting with ``%`` or ``!`` skipped; code
    that does not parse imports nothing).

    >>> sorted(code_imports("def f():\\n    from mpl_toolkits.mplot3d import Axes3D\\n!pip install x"))
    ['mpl_toolkits']
    >>> code_imports("this is not Python")
    set()
    """
    text = "\n".join(line for line in source.splitlines() if not line.lstrip().startswith(("%", "!")))
    try:
        tree = ast.parse(text)
    except SyntaxError:
        return set()
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module.split(".")[0])
    return found


def notebook_imports(paths) -> dict[str, list[str]]:
    """{module: [notebook file names]} for the third-party modules the notebooks ``paths`` import.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = Path(d) / "05.ipynb"
    ...     _ = p.write_text(json.dumps({"cells": [{"cell_type": "code", "source": ["import sympy as sp\\n", "import os"]}]}))
    ...     notebook_imports([p])
    {'sympy': ['05.ipynb']}
    """
    out: dict = {}
    for p in paths:
        nb = json.loads(Path(p).read_text(encoding="utf-8"))
        for c in nb.get("cells", []):
            if c.get("cell_type") == "code":
                src = c.get("source", "")
                for m in code_imports("".join(src) if isinstance(src, list) else src):
                    out.setdefault(m, []).append(Path(p).name)
    return {m: sorted(set(v)) for m, v in out.items() if _third_party(m)}


def kinlib_imports() -> dict[str, list[str]]:
    """{module: [kinlib files]} for the third-party modules kinlib's own code imports, publish/ excluded.

    >>> found = kinlib_imports()
    >>> "jupyter_client" in found and "numpy" in found, "playwright" in found
    (True, False)
    """
    import kinlib

    root = Path(kinlib.__file__).resolve().parent
    out: dict = {}
    for p in sorted(root.rglob("*.py")):
        rel = p.relative_to(root).as_posix()
        if rel.startswith("course/publish/"):
            continue
        for m in code_imports(p.read_text(encoding="utf-8")):
            if _third_party(m):
                out.setdefault(m, []).append(rel)
    return out


def _third_party(module: str) -> bool:
    return module not in _SKIP and module not in sys.stdlib_module_names


def _pins(constraints: Path | None) -> dict[str, str]:
    pins = {}
    if constraints is not None and constraints.is_file():
        for line in constraints.read_text().splitlines():
            m = re.match(r"\s*([A-Za-z0-9_.\-]+)\s*==\s*([^\s;#]+)", line)
            if m:
                pins[_norm(m.group(1))] = m.group(2)
    return pins


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def requirements(notebooks, constraints: Path | None = None) -> tuple[list[str], list[str]]:
    """(requirement lines ``name==version``, module names to check) for grading ``notebooks`` (paths).

    A module no installed distribution provides raises ValueError naming who imports it (tests/course/test_grade_lms.py);
    the lesson notebooks need modern_robotics (their independent check) and the grader's kernel:

    >>> nbs = sorted(Path(__file__).resolve().parents[3].joinpath("notebooks").glob("0*.ipynb"))
    >>> reqs, modules = requirements(nbs)
    >>> "modern_robotics" in modules, any(r.startswith("ipykernel==") for r in reqs)
    (True, True)
    """
    wanted: dict = {}
    for src in (notebook_imports(notebooks), kinlib_imports(), {k: ["the grader's kernel"] for k in KERNEL}):
        for m, who in src.items():
            wanted.setdefault(m, []).extend(who)
    provided = importlib.metadata.packages_distributions()
    pins = _pins(constraints)
    lines: dict = {}
    for m, who in sorted(wanted.items()):
        dists = provided.get(m)
        if not dists:
            raise ValueError(
                f"{m} (imported by {', '.join(sorted(set(who))[:3])}) is not installed here: "
                "install it in the environment the bundle is built in (make setup)"
            )
        for d in dists:
            key = _norm(d)
            version = pins.get(key) or importlib.metadata.version(d)
            lines[key] = f"{d}=={version}"
    return sorted(lines.values(), key=str.lower), sorted(wanted)
