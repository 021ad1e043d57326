"""The README's Python examples run as written (in order, one namespace), and say what they claim."""

from __future__ import annotations

import re
from pathlib import Path

import sympy as sp

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_blocks_run():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)
    assert len(blocks) >= 3
    ns: dict = {}
    for block in blocks:
        exec(compile(block, str(README), "exec"), ns)
    # the claims written beside the calls
    J, arm = ns["J"], ns["arm"]
    t1, t2 = arm.thetas
    assert ns["rank_at"](J, {t1: 10, t2: 0}) == 1
    assert ns["rank_at"](J, {t1: sp.Rational(1, 2), t2: sp.Rational(1, 2)}) == 2
    N = ns["left_null_space"](J, {t1: 3, t2: 0})
    assert N.shape == (2, 1) and sp.simplify(N[1] - sp.tan(3)) == 0
    assert ns["robots"].planar_offset_3r().subs(L=0.1).M[0, 3] == sp.Rational(3, 10)
    assert arm.M[0, 3] == 2 and isinstance(arm.M[0, 3], sp.Integer)
