"""pytest configuration and fixtures. Shared test helpers live in tests/helpers.py (import them from there)."""

import sys

import numpy as np
import pytest

# tests/fixtures holds input notebooks and scripts for the handouts and grading tests, not tests:
# keep `pytest --nbval-lax tests` from collecting them.
collect_ignore = ["fixtures"]


@pytest.fixture(autouse=True, scope="session")
def _grader_secret(tmp_path_factory):
    """The grader's secret (kinlib.course.grader.secret) for the whole run: a temporary file, never the tester's
    ~/.config/kinlib/grader-secret (subprocesses inherit it through the environment)."""
    import os

    old = os.environ.get("KINLIB_GRADER_SECRET")
    os.environ["KINLIB_GRADER_SECRET"] = str(tmp_path_factory.mktemp("grader-secret") / "grader-secret")
    yield
    if old is None:
        os.environ.pop("KINLIB_GRADER_SECRET", None)
    else:
        os.environ["KINLIB_GRADER_SECRET"] = old


@pytest.fixture
def rng():
    """A NumPy generator with a fixed seed (reproducible random configurations)."""
    return np.random.default_rng(1234)


@pytest.fixture(autouse=True)
def _close_figures():
    """Close every matplotlib figure after each test (when a test has imported pyplot)."""
    yield
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close("all")
