"""One rule for "near a singular configuration" (issue 21): stated once, unit-free, used everywhere.

The rule is :data:`kinlib.manipulability.NEAR_SINGULAR` (w < 0.1 · w_max, w = √det(J Jᵀ) of the task rows, w_max
the largest w of the same arm and rows), decided by :func:`kinlib.manipulability.singularity_state`. The tests:

* the source of kinlib and the notebooks' code holds no second threshold for "near" (a literal compared with, or
  given as, a ``near`` value, or with σ_min/σ_max), and the constant is defined once;
* the rule is unit-free: rescaling every length of an arm leaves every state unchanged (σ_min/σ_max does not);
* the animation's status line and the explorer's banner say what the rule says, on configurations chosen at
  singular, near and regular distances (the oracle: w / w_max = |sin(θ2 + π/4)| of problem 5, derived by hand).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from kinlib import robots
from kinlib.manipulability import NEAR_SINGULAR, peak_manipulability, singularity_state
from kinlib.taskspace import task_rows

ROOT = Path(__file__).resolve().parents[2]

# a number given to or compared with a "near" name, or σ_min/σ_max ("inverse_condition", "ratio") compared with a
# literal: each would be a second rule
_SECOND_RULE = [
    re.compile(r"\bnear\w*\s*(?:=|<=?|>=?)\s*\d*\.\d+"),
    re.compile(r"\d*\.\d+\s*(?:<=?|>=?)\s*\w*near\w*"),
    re.compile(r"(?:inverse_condition|\bic\b|\bratio\b)[^\n#]{0,40}?<\s*0?\.\d+"),
]


def _sources():
    for path in sorted((ROOT / "kinlib").rglob("*.py")):
        yield path.relative_to(ROOT), path.read_text()
    for path in sorted((ROOT / "notebooks").glob("0*.ipynb")):
        nb = json.loads(path.read_text())
        code = "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code")
        yield path.relative_to(ROOT), code


def _code_lines(text):
    for k, line in enumerate(text.splitlines(), 1):
        stripped = line.split("#", 1)[0]
        if stripped.strip():
            yield k, stripped


def _uses_the_rule(line: str) -> bool:
    """A line that acts on the rule's own verdict (e.g. the explorer draws the 'cannot move' line when the state
    is near or singular *and* the ṗ ellipse, whose axes share one unit, is thin): a drawing choice, not a rule."""
    return bool(re.search(r"state\W*\]?\s*in\s*\(", line))


def test_no_second_near_threshold_in_kinlib_or_the_notebooks():
    found = []
    for path, text in _sources():
        for k, line in _code_lines(text):
            if any(rx.search(line) for rx in _SECOND_RULE) and not _uses_the_rule(line):
                found.append(f"{path}:{k}: {line.strip()}")
    assert not found, "a second 'near a singular configuration' rule:\n" + "\n".join(found)
    defs = [
        f"{path}:{k}"
        for path, text in _sources()
        for k, line in _code_lines(text)
        if re.match(r"\s*NEAR_SINGULAR\s*=", line)
    ]
    assert len(defs) == 1 and defs[0].startswith("kinlib/analysis/manipulability.py:"), defs


def test_the_scanner_catches_second_rules():
    bad = ["near=0.2", "if ic[k] < 0.1:", "state = 'near' if ratio < 0.05 else 'regular'", "0.1 > near_w"]
    assert all(any(rx.search(line) for rx in _SECOND_RULE) and not _uses_the_rule(line) for line in bad)
    assert _uses_the_rule('show = info["state"] in ("singular", "near") and ratio < 0.35')
    good = ["near=NEAR_SINGULAR", "state = singularity_state(J, w_max)", "near: float = NEAR_SINGULAR"]
    assert not any(any(rx.search(line) for rx in _SECOND_RULE) for line in good)


def _offsets():
    """θ2 − (−π/4) at singular (0), near (|sin δ| < 0.1) and regular distances."""
    return np.array([0.0, 0.02, -0.07, 0.0995, 0.1005, -0.3, 0.8, 1.5])


def test_states_follow_the_stated_rule_and_are_unit_free():
    th = -np.pi / 4 + _offsets()
    expect = [
        "singular" if abs(np.sin(d)) < 1e-12 else "near" if abs(np.sin(d)) < NEAR_SINGULAR else "regular"
        for d in _offsets()
    ]
    for L in (1.0, 1000.0, 0.001):  # metres, millimetres, kilometres: the same arm
        chain = robots.planar_offset_3r(L)
        Q = np.column_stack([np.full_like(th, 0.3), th, np.full_like(th, -1.1)])
        J = task_rows(chain.jacobian_geometric(Q), "planar")
        w_max = np.sqrt(2) * L**2  # by hand: w = √2 L² |sin(θ2 + π/4)| (problem 5.4)
        assert list(singularity_state(J, w_max)) == expect, L
        assert np.isclose(peak_manipulability(chain, "planar"), w_max, rtol=1e-3)
        s = np.linalg.svd(J, compute_uv=False)
        ratios = s[:, -1] / s[:, 0]
        if L == 1.0:
            ratios_1 = ratios
        else:  # σ_min/σ_max changes with the unit of length: not a rule a course can state once
            assert not np.allclose(ratios, ratios_1, rtol=0.1)


@pytest.mark.filterwarnings("ignore::UserWarning")
def test_animation_and_explorer_say_what_the_rule_says():
    from kinlib import widgets

    chain = robots.planar_offset_3r(1)
    th = -np.pi / 4 + _offsets()
    Q = np.column_stack([np.full_like(th, np.pi / 4), th, np.full_like(th, np.pi / 4)])
    rule = list(singularity_state(task_rows(chain.jacobian_geometric(Q), "planar"), np.sqrt(2)))
    anim = widgets.animate_singularity(chain, Q)  # its banner along the path (the browser shows these states)
    assert anim.states == rule, (anim.states, rule)
    ex = widgets.explorer(chain, q=Q[0])
    for q, state in zip(Q, rule):
        ex.update(q)
        assert ex.state == state, (q, state, ex.state)
