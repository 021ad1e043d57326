"""build_key on the real notebooks (04's 4.1, 05's 5.3): every kept variant checked against an independent oracle
(NumPy on the arm drawn by hand), a draw that must be rejected, redrawn, and a second build that runs no kernel.

Slow (two notebooks executed, then their variants re-run): about a minute on an idle machine.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from kinlib.course.answers import wire
from kinlib.course.variants import draw as drawmod
from kinlib.course.variants import key as keymod
from kinlib.course.variants import replay
from kinlib.course.variants.spec import Spec, value

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
SECRET = b"variants-test-secret-0123456789abcdef"
N04, N05 = "04_interpreting_the_jacobian", "05_singularities_planar"

pytestmark = pytest.mark.slow


def _spec(nid):
    return Spec.from_notebook(json.loads((NOTEBOOKS / f"{nid}.ipynb").read_bytes()))


def _floats(spec, values, name):
    return [float(v) for v in value(spec.param(name), values[name])]


def _winners(q, row):
    """4.1 by hand: the planar 3R arm with unit links; joint i at q_i, the tool at p; a revolute joint moves the
    tool at ẑ × (p − q_i) per rad/s. The joints whose |entry| is largest (ties within 1e-9)."""
    angles = np.cumsum(q)
    pts = np.vstack([[0.0, 0.0], np.cumsum(np.c_[np.cos(angles), np.sin(angles)], axis=0)])
    p, joints = pts[3], pts[:3]
    entries = np.array([-(p[1] - j[1]) if row == 0 else (p[0] - j[0]) for j in joints])
    mags = np.abs(entries)
    return tuple(int(i) + 1 for i in np.flatnonzero(mags >= mags.max() - 1e-9))


def _task_rows_05(q):
    """05's task rows (ω_z, v_x, v_y) of J_s by hand: joints at (0, 0), (L, 0) and (2L, L) at home (L = 1);
    column i is (1, y_i, −x_i) at the current joint point."""
    c1, s1 = np.cos(q[0]), np.sin(q[0])
    j2 = np.array([c1, s1])
    a12 = q[0] + q[1]
    j3 = j2 + np.array([np.cos(a12) - np.sin(a12), np.sin(a12) + np.cos(a12)])  # (L, L) turned by θ1 + θ2
    return np.array([[1, 1, 1], [0, j2[1], j3[1]], [0, -j2[0], -j3[0]]], dtype=float)


def _load(answer):
    return wire.load(answer["tree"], max_nodes=10 * wire.MAX_NODES)


def _rejected_first(spec, nid, n=400):
    """A student id whose first draw of 04 has a tie in (a) or (b), or none in (c): the proof must reject it."""
    for i in range(n):
        sid = f"r{i}"
        v = drawmod.draw(SECRET, sid, nid, spec)
        forms = [len(_winners(_floats(spec, v, f"theta_{k}"), row)) for k, row in (("a", 0), ("b", 0), ("c", 1))]
        if forms != [1, 1, 2]:
            return sid
    raise AssertionError("no student with a rejected first draw among 400")


@pytest.fixture(scope="module")
def built():
    spec04 = _spec(N04)
    roster = [keymod.Student(f"s{i}") for i in range(6)] + [keymod.Student(_rejected_first(spec04, N04))]
    logs: list = []
    key = keymod.build_key(NOTEBOOKS, roster, SECRET, only=["04", "05"], log=logs.append)
    return key, roster, logs


def test_every_kept_variant_of_4_1_has_the_original_winners_form_by_an_independent_oracle(built):
    key, roster, _ = built
    spec = _spec(N04)
    nk = key.notebooks[N04]
    for s in roster:
        attempt = sum(r["student"] == s.id for r in nk.rejections)
        values = drawmod.draw(SECRET, s.id, N04, spec, attempt)
        vk = nk.students[s.id]
        assert vk == drawmod.variant_key(values) and nk.variants[vk].values == values
        answers = nk.variants[vk].answers
        for k, row, form in (("a", 0, 1), ("b", 0, 1), ("c", 1, 2)):
            want = _winners(_floats(spec, values, f"theta_{k}"), row)
            assert len(want) == form, (s.id, k, want)
            got = answers[f"joint_{k}"]["choice"]["value"]
            assert (tuple(sorted(got)) if isinstance(got, list) else (got,)) == want, (s.id, k)


def test_a_draw_with_a_tie_where_the_original_has_one_winner_is_rejected_and_redrawn(built):
    key, roster, logs = built
    nk = key.notebooks[N04]
    victim = roster[-1].id
    mine = [r for r in nk.rejections if r["student"] == victim]
    assert mine and mine[0]["attempt"] == 0
    assert any(w in mine[0]["why"] for w in ("a tie of", "one winner here"))
    assert nk.students[victim] not in {r["variant"] for r in mine}
    stats = key.stats()[N04]
    assert stats["rejected"] == len(nk.rejections) >= 1 and stats["drawn"] == len(roster) + stats["rejected"]
    assert any(f"{stats['rejected']} of {stats['drawn']} draws rejected" in line for line in logs)


def test_every_kept_variant_of_5_3_is_singular_with_the_right_directions(built):
    key, roster, _ = built
    spec = _spec(N05)
    nk = key.notebooks[N05]
    for s in roster:
        values = nk.variants[nk.students[s.id]].values
        q = _floats(spec, values, "q53")
        J = _task_rows_05(q)
        answers = nk.variants[nk.students[s.id]].answers
        assert int(_load(answers["rank53"])) == np.linalg.matrix_rank(J, tol=1e-9) == 2
        can = np.array(_load(answers["can_move"]).evalf(30), dtype=float)
        cannot = np.array(_load(answers["cannot_move"]).evalf(30), dtype=float)
        assert np.linalg.matrix_rank(np.hstack([J, can]), tol=1e-9) == 2 == np.linalg.matrix_rank(can, tol=1e-9)
        assert cannot.shape[1] == 1 and np.allclose(J.T @ cannot, 0, atol=1e-12)
        # every other answer of 05 (5.1, 5.4, ...) is the original's: only 5.3 varies
        assert sp.sympify(_load(answers["w_max"])) == sp.sqrt(2) * sp.Symbol("L", positive=True) ** 2


def test_a_second_build_with_the_same_notebooks_runs_no_kernel(built, monkeypatch):
    key, roster, _ = built

    def no_kernel(*a, **k):
        raise AssertionError("a kernel was started for proofs the previous key holds")

    monkeypatch.setattr(replay, "Session", no_kernel)
    again = keymod.build_key(NOTEBOOKS, roster, SECRET, only=["04", "05"], previous=key, log=lambda *_: None)
    for nid in (N04, N05):
        assert again.notebooks[nid].students == key.notebooks[nid].students


def test_proofs_made_with_other_code_are_not_lent(built, monkeypatch):
    """A key whose proofs were made by other kinlib code (another engine, other proof rules) lends nothing: the
    notebook's variants are proved again (here the kernel that would prove them refuses, so the build stops)."""
    import copy

    key, roster, _ = built
    old = copy.deepcopy(key)
    for nk in old.notebooks.values():
        nk.code = "0" * 64

    def no_kernel(*a, **k):
        raise RuntimeError("proving again")

    monkeypatch.setattr(replay, "Session", no_kernel)
    with pytest.raises(RuntimeError, match="proving again"):
        keymod.build_key(NOTEBOOKS, roster, SECRET, only=["05"], previous=old, log=lambda *_: None)
