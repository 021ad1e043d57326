"""Every docstring example in kinlib runs and prints what it says (doctest): every module of the package,
the subpackages (kinlib.plotting, kinlib.course, ...) included, found by walking the source tree."""

from __future__ import annotations

import doctest
import importlib
import sys
from pathlib import Path

import pytest

PACKAGE_DIR = Path(__file__).resolve().parents[2] / "kinlib"


def _module_names() -> list[str]:
    """Every module under kinlib/ (by file, without importing anything); ``__main__`` modules are scripts."""
    names = []
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        parts = path.relative_to(PACKAGE_DIR.parent).with_suffix("").parts
        if "__pycache__" in parts or parts[-1] == "__main__":
            continue
        if any(not (PACKAGE_DIR.parent.joinpath(*parts[:i]) / "__init__.py").is_file() for i in range(1, len(parts))):
            continue  # a folder that is not a package (no __init__.py)
        names.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return names


MODULES = _module_names()


@pytest.fixture
def agg(monkeypatch):
    """Drawings render off screen: matplotlib's Agg backend (no display, no window)."""
    monkeypatch.setenv("MPLBACKEND", "Agg")
    if "matplotlib" in sys.modules:
        sys.modules["matplotlib"].use("Agg")


def test_modules_found():
    assert "kinlib" in MODULES and "kinlib.kinematics.rigid" in MODULES and len(MODULES) > 10, MODULES


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name, agg):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} docstring examples of {name} failed"
