"""kinlib.taskspace: the one task-row parser, against an independent spelling of each row.

Every way of naming a row (name, ṗ alias, ω alias, index, negative index) must pick the same row of J, for
SymPy, NumPy and batched J; presets are the textbook's task spaces; the default task space is the one the
arm's joints can serve (a 2R arm: its position rows, where the stretched-out singularity shows).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from kinlib import robots
from kinlib.taskspace import default_task_rows, rows_label, task_row_indices, task_rows

# each row's spellings, written out here (row r of [ω; v]: ω_x, ω_y, ω_z, then v_x, v_y, v_z = ṗ for J)
SPELLINGS = {
    0: ["wx", "WX", "ωx", "ω_x", "w_x", 0, -6, np.int64(0)],
    1: ["wy", "ωy", "ω_y", 1, -5],
    2: ["wz", "ωz", "ω_z", 2, -4],
    3: ["vx", "px", "p_x", "v_x", 3, -3],
    4: ["vy", "py", "p_y", "PY", 4, -2],
    5: ["vz", "pz", "p_z", 5, -1, np.int32(5)],
}


@st.composite
def row_specs(draw):
    rows = draw(st.lists(st.integers(0, 5), min_size=1, max_size=6, unique=True))
    return rows, [draw(st.sampled_from(SPELLINGS[r])) for r in rows]


@settings(max_examples=60, deadline=None, derandomize=True)
@given(row_specs(), st.integers(1, 7))
def test_every_spelling_picks_the_same_rows(spec, n):
    rows, spelled = spec
    rng = np.random.default_rng(len(rows) * 10 + n)
    J = rng.normal(size=(6, n))
    assert task_row_indices(spelled) == tuple(rows)
    np.testing.assert_array_equal(task_rows(J, spelled), J[rows, :])
    S = sp.Matrix(6, n, lambda i, j: sp.Symbol(f"j{i}{j}", real=True))
    assert task_rows(S, spelled) == sp.Matrix([[S[r, j] for j in range(n)] for r in rows])
    batch = rng.normal(size=(4, 6, n))
    np.testing.assert_array_equal(task_rows(batch, spelled), batch[:, rows, :])


@pytest.mark.parametrize(
    "preset, rows",
    [("planar", [2, 3, 4]), ("xy", [3, 4]), ("linear", [3, 4, 5]), ("position", [3, 4, 5]),
     ("angular", [0, 1, 2]), ("all", [0, 1, 2, 3, 4, 5]), ("Planar", [2, 3, 4])],
)  # fmt: skip
def test_presets(preset, rows):
    assert task_row_indices(preset) == tuple(rows)


@pytest.mark.parametrize(
    "rows, exc, words",
    [
        (["vx", "vx"], ValueError, "repeat"),
        (["vx", 3], ValueError, "repeat"),
        ([], ValueError, "at least one"),
        (["vq"], ValueError, "unknown row"),
        ([6], ValueError, "out of range"),
        ([-7], ValueError, "out of range"),
        ([True], TypeError, "bool"),
        ([1.0], TypeError, "got"),
        ({"vx"}, TypeError, "got"),
        (b"vx", TypeError, "got"),
        (None, TypeError, "got None"),
    ],
)
def test_refused_with_what_was_given(rows, exc, words):
    with pytest.raises(exc, match=words):
        task_rows(np.zeros((6, 2)), rows)


def test_names_need_six_rows_and_indices_do_not():
    J = np.arange(6.0).reshape(3, 2)
    np.testing.assert_array_equal(task_rows(J, [-1, 0]), J[[2, 0]])
    with pytest.raises(ValueError, match="J with 6 rows.*got J with 3"):
        task_rows(J, ["vx"])
    with pytest.raises(ValueError, match="J with 6 rows"):
        task_rows(J, "planar")


def test_default_task_space_is_what_the_joints_can_serve():
    """A 2R arm tests its position rows: rank 1 when stretched out, where all six rows still have rank 2."""
    arm = robots.planar_2r(1, 1)
    rows = default_task_rows(arm)
    assert rows == (3, 4) and rows_label(rows) == "ṗ_x, ṗ_y"
    J = arm.jacobian_geometric([0.4, 0.0])
    assert np.linalg.matrix_rank(task_rows(J, rows)) == 1 and np.linalg.matrix_rank(J) == 2
    assert default_task_rows(robots.planar_3r(1, 1, 1)) == (2, 3, 4)
    assert default_task_rows(robots.planar_rpp(1)) == (2, 3, 4)
    assert default_task_rows(robots.ur5()) == (0, 1, 2, 3, 4, 5)
    assert default_task_rows(robots.spatial_rppr(1, 1)) == (3, 4, 5)
    with pytest.raises(TypeError, match="SerialChain"):
        default_task_rows(np.eye(6))
