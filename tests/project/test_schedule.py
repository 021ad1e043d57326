"""The suite's schedule under pytest-xdist (tests/conftest.py: ``_SPLIT``, ``_SECONDS``, ``_schedule``): the table of
heavy groups names groups that exist, and the order keeps its two promises (longest first; no group that needs the
real handouts build before the build had a head start)."""

import ast

import pytest

import conftest

ROOT = conftest.ROOT


def _functions(path) -> set:
    tree = ast.parse((ROOT / path).read_text())
    return {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}


@pytest.mark.parametrize("group", sorted(conftest._SECONDS))
def test_every_timed_group_exists(group):
    path, _, part = group.partition("::")
    assert (ROOT / path).is_file(), f"{path} (tests/conftest.py _SECONDS) is gone: rename or drop its entry"
    if part:
        assert path in conftest._SPLIT, f"{group}: {path} is not split (_SPLIT)"
        assert part == "lab" or part in _functions(path), f"{group}: no such part"


def test_longest_first_and_the_build_waits_for_its_head_start():
    groups = ["tests/a.py", *conftest._SECONDS]  # collection order: an untimed group first
    held = {"tests/course/test_lite.py", "tests/course/test_print.py", "tests/pictures/test_browser.py"}
    order = conftest._schedule(groups, held, 2)
    assert sorted(order) == sorted(groups)
    free = [g for g in order if g not in held]
    assert [conftest._SECONDS.get(g, 1) for g in free] == sorted(
        (conftest._SECONDS.get(g, 1) for g in free), reverse=True
    )
    first_held = min(order.index(g) for g in held)
    ahead = sum(conftest._SECONDS.get(g, 1) for g in order[:first_held])
    assert ahead >= conftest._BUILD_HEADSTART * 2
    assert order[-1] == "tests/a.py"  # untimed groups last (they count 1 s)


def test_the_schedule_examples_in_conftest_hold():
    """conftest.py is not collected for doctests: its examples (``_schedule``'s) are run here, so a refreshed
    ``_SECONDS`` table that changes them fails the suite instead of leaving a false example."""
    import doctest

    res = doctest.testmod(conftest, verbose=False)
    assert res.attempted >= 2 and res.failed == 0, res
