"""pytest configuration and fixtures. Shared test helpers live in tests/helpers.py (import them from there)."""

import sys

import numpy as np
import pytest

# tests/fixtures holds input notebooks and scripts for the handouts and grading tests, not tests:
# keep `pytest --nbval-lax tests` from collecting them.
collect_ignore = ["fixtures"]


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
