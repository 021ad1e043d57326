"""Smoke test of the benchmark script (bench/bench.py): it runs and writes the table. No timing assertions."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
def test_bench_quick_writes_table(tmp_path):
    out = tmp_path / "bench.md"
    p = subprocess.run(
        [
            sys.executable,
            str(ROOT / "bench" / "bench.py"),
            "--quick",
            "--reps",
            "1",
            "--singular-timeout",
            "120",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=ROOT,
    )
    assert p.returncode == 0, p.stderr[-2000:]
    text = out.read_text(encoding="utf-8")
    assert text == p.stdout.rstrip("\n") or text in p.stdout
    for needle in [
        "# kinlib benchmark",
        "| CPU |",
        "| Python |",
        "| numpy |",
        "| sympy |",
        "| date |",
        "## Targets",
        "## Numeric kinematics",
        "| robot | quantity | call | kinlib (best) | modern-robotics",
        "## Symbolic",
        "UR5 J_s built",
        "## Real arms from URDF (geometric J: single call and batched)",
        "kinlib ÷ RTB",
        "compiled to C, empty cache",
        "loaded from the cache by a new process",
        "kinlib.jacobian_space(S, q)",
        "## First numeric call of a 7-joint chain",
        "## Exact analysis at a configuration",
        "## Singular sets of a redundant arm",
        "symbolic condition number and isotropy",
        "## Notebooks",
        "## Explorers",
        "## In the browser",
        "## Instructor checker",
        "import kinlib",
    ]:
        assert needle in text, needle
    # every robot and quantity has a single and a batched row, each with a figure for kinlib
    for robot in ["ur5", "planar_offset_3r", "spatial_rppr", "cart_pole", "planar_3r", "planar_rpp"]:
        for quantity in ["FK T(θ)", "space Jacobian J_s", "body Jacobian J_b", "geometric Jacobian"]:
            rows = [r for r in text.splitlines() if r.startswith(f"| {robot} (") and quantity in r]
            assert len(rows) == 2, (robot, quantity, rows)
            for r in rows:
                kinlib_cell = r.split("|")[4].strip()
                assert kinlib_cell.endswith(("ns)", "µs)", "ms)")), r
    # targets are reported as met or missed (with by how much), never silently
    for r in text.splitlines():
        if r.startswith("| ur5 (n=6)"):
            assert "met" in r or "missed" in r, r
    assert "missed by" not in text or "%" in text


def test_bench_helpers():
    sys.path.insert(0, str(ROOT / "bench"))
    try:
        import bench
    finally:
        sys.path.pop(0)
    assert bench.fmt_t(2.5e-6) == "2.50 µs" and bench.fmt_t(180e-9) == "180 ns" and bench.fmt_t(1.5) == "1.50 s"
    t = bench.Targets()
    assert t.upper("a", 2e-6, 3e-6) == "met"
    assert "missed** by 50%" in t.upper("b", 4.5e-6, 3e-6)
    assert "missed** by 50%" in t.lower("c", 40.0, 80.0)
    assert t.upper("d", None, 1.0) == bench.NA
    assert [ok for _, ok, _ in t.items] == [True, False, False, False]
