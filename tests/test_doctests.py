"""Every docstring example in the math core runs and prints what it says (doctest)."""
from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import kinlib

# the math core: numpy + sympy only (the picture and course layers have their own tests)
CORE = sorted(m.name for m in pkgutil.iter_modules(kinlib.__path__)
              if m.name not in {"plotting", "widgets", "handouts", "selfcheck", "grade", "course"}
              and not m.name.startswith("_grade"))


@pytest.mark.parametrize("name", CORE)
def test_docstring_examples(name):
    module = importlib.import_module(f"kinlib.{name}")
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} docstring examples of kinlib.{name} failed"
