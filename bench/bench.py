#!/usr/bin/env python
"""kinlib's benchmark (``make bench``): one run, one table of figures, ratios and targets.

    python bench/bench.py [--out build/bench.md] [--reps 7] [--batch 100000] [--quick]

Results are checked before they are timed: for every robot and quantity the benchmark asserts that
kinlib's numbers equal modern-robotics' and Pinocchio's (``np.allclose``; Pinocchio's rows [v; ω]
reordered to [ω; v]; reference frame WORLD = space Jacobian, LOCAL = body Jacobian,
LOCAL_WORLD_ALIGNED = the geometric Jacobian [ṗ; ω]) and that a batch equals the single calls.

Every figure is the median of repeated ``timeit`` runs. Sections: numeric kinematics (single and
batched FK, J_s, J_b, geometric J) for the UR5 and the problem set's robots against modern-robotics
and Pinocchio; the first numeric call (code generation) of a 7-joint arm; symbolic build, display
simplification and the UR5's singular set; exact rank and spans at configurations of 6-joint arms; the
singular set of a 6×7 J, the numeric singularity search and a symbolic condition number; each notebook's
execution; one slider move in each explorer; in JupyterLab (Debian's chromium) each notebook's Run All
Cells and 20 slider moves per explorer, key press to new picture; the instructor checker's throughput;
``import kinlib``. Missing pieces (Pinocchio, a notebook, a module, chromium) are reported as "not
available", never skipped silently. ``--quick`` (tests) uses a tiny batch and skips notebooks, explorers,
the browser and the checker.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import timeit
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402
import sympy as sp  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import kinlib  # noqa: E402
from kinlib import robots  # noqa: E402

# --- targets (issue 7) -------------------------------------------------------------------------
T_SINGLE = 3e-6  # one numeric UR5 Jacobian / FK
T_SPEEDUP_MR = 80.0  # J_s: at least 80x modern-robotics
T_BATCH = 200e-9  # per configuration, batch of 100,000
T_SYM_BUILD = 0.1
T_DISPLAY = 3.0
T_SINGULAR = 5.0
T_NOTEBOOK = 10.0
T_EXPLORER_BUILD = 3.0  # building an explorer in the kernel (once per cell)
T_LAB_RUN_ALL = 8.0  # Run All Cells of a notebook in JupyterLab (issue 13)
T_SLIDER = 0.016  # key press on a slider → the frame that shows the new picture, median of 20 moves (issue 23)
T_LITE_FIRST = 30.0  # JupyterLite: opening workbook 05 and running all → its first picture (issue 15)
T_IMPORT = 0.6
T_FIRST_CALL = 2.0  # first numeric call (code generation) of any chain of <= 7 joints
T_EXACT_RANK = 30.0  # exact rank / column space / left null space at a configuration of a 6-joint arm
T_SINGULAR_POSE = 5.0  # the same at a textbook singular pose with mixed rational·π angles, exact (issue 32)
T_SINGULAR_7 = 60.0  # singular set of a 6×7 Jacobian: an answer or a clear "out of reach"
T_COND_2R = 2.0  # symbolic condition number of a planar 2R

QUANTITIES = [
    ("fk", "FK T(θ)"),
    ("js", "space Jacobian J_s"),
    ("jb", "body Jacobian J_b"),
    ("jg", "geometric Jacobian [ω_s; ṗ]"),
]
METHOD = {"fk": "fk", "js": "jacobian_space", "jb": "jacobian_body", "jg": "jacobian_geometric"}

NA = "not available"


# --- formatting ----------------------------------------------------------------------------------
def fmt_t(s: float | None) -> str:
    if s is None:
        return "—"
    if s < 1e-6:
        return f"{s * 1e9:.0f} ns"
    if s < 1e-3:
        return f"{s * 1e6:.2f} µs"
    if s < 1:
        return f"{s * 1e3:.1f} ms"
    return f"{s:.2f} s"


def fmt_x(r: float | None) -> str:
    if r is None:
        return "—"
    return f"{r:.0f}×" if r >= 10 else f"{r:.2f}×"


class Targets:
    """Collects every target check, for the per-row status and the summary."""

    def __init__(self):
        self.items: list[tuple[str, bool, str]] = []

    def upper(self, what: str, value: float | None, limit: float, fmt=fmt_t) -> str:
        if value is None:
            self.items.append((what, False, f"{NA} (target ≤ {fmt(limit)})"))
            return NA
        ok = value <= limit
        msg = "met" if ok else f"**missed** by {100 * (value / limit - 1):.0f}% ({fmt(value)} > {fmt(limit)})"
        self.items.append((what, ok, msg))
        return msg

    def lower(self, what: str, value: float | None, limit: float, fmt=fmt_x) -> str:
        if value is None:
            self.items.append((what, False, f"{NA} (target ≥ {fmt(limit)})"))
            return NA
        ok = value >= limit
        msg = "met" if ok else f"**missed** by {100 * (1 - value / limit):.0f}% ({fmt(value)} < {fmt(limit)})"
        self.items.append((what, ok, msg))
        return msg


def table(header: list[str], rows: list[list[str]]) -> list[str]:
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


# --- timing --------------------------------------------------------------------------------------
def CLOCK() -> float:
    """In-process timings use this thread's CPU time plus that of the child processes that have ended (kinlib's
    budgeted exact work runs in a forked child, kinlib.budget): on a shared machine it is what the code costs
    (wall time also counts the time other processes hold the core); subprocess timings are wall time."""
    import resource

    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.thread_time() + ru.ru_utime + ru.ru_stime


def per_call(fn, reps: int, budget: float = 0.02, best: bool = False):
    """Median over ``reps`` timeit runs of the time per call (each run lasts about ``budget`` s);
    with ``best``, (median, fastest run)."""
    number = 1
    while True:
        t = timeit.timeit(fn, number=number, timer=CLOCK)
        if t >= budget or number >= 1 << 20:
            break
        number = max(number * 2, int(number * budget / max(t, 1e-9) * 1.1))
    times = timeit.repeat(fn, number=number, repeat=max(reps, 1), timer=CLOCK)
    med = statistics.median(times) / number
    return (med, min(times) / number) if best else med


def once(fn, reps: int, best: bool = False):
    """Median over ``reps`` single runs of a slow call; with ``best``, (median, fastest)."""
    times = []
    for _ in range(max(reps, 1)):
        t0 = CLOCK()
        fn()
        times.append(CLOCK() - t0)
    med = statistics.median(times)
    return (med, min(times)) if best else med


# --- machine ---------------------------------------------------------------------------------------
def _version(dist: str) -> str:
    from importlib import metadata

    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return NA


def machine() -> list[str]:
    cpu = platform.processor() or NA
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else NA
    rows = [
        ["CPU", cpu],
        ["cores", str(os.cpu_count())],
        ["load average at start (1, 5, 15 min)", load],
        ["OS", platform.platform()],
        ["Python", platform.python_version()],
        ["numpy", np.__version__],
        ["sympy", sp.__version__],
        ["kinlib", kinlib.__version__],
        ["modern-robotics", _version("modern_robotics")],
        ["pin (Pinocchio)", _version("pin")],
        ["date", datetime.datetime.now().astimezone().isoformat(timespec="seconds")],
    ]
    return table(["machine", ""], rows)


# --- reference implementations -------------------------------------------------------------------
def numeric_robots() -> list:
    """The UR5 (book's lengths) and the problem set's robots with numeric lengths."""
    return [
        robots.ur5(),
        robots.planar_offset_3r(1),
        robots.spatial_rppr(1, 1),
        robots.cart_pole(1, 1),
        robots.planar_3r(1, 1, 1),
        robots.planar_rpp(1),
    ]


class MR:
    """modern-robotics on the chain's numeric M, S_i and B_i."""

    def __init__(self, chain):
        import modern_robotics as mr

        self.mr = mr
        self.M = np.array(chain.M, dtype=float)
        self.S = np.array(chain.screws, dtype=float)
        self.B = np.array(chain.body_screws, dtype=float)

    def geometric(self, q):
        mr = self.mr
        T = mr.FKinSpace(self.M, self.S, q)
        Jb = mr.JacobianBody(self.B, q)
        R = T[:3, :3]
        return np.vstack([R @ Jb[:3], R @ Jb[3:]])

    def fn(self, what):
        mr = self.mr
        return {
            "fk": lambda q: mr.FKinSpace(self.M, self.S, q),
            "js": lambda q: mr.JacobianSpace(self.S, q),
            "jb": lambda q: mr.JacobianBody(self.B, q),
            "jg": self.geometric,
        }[what]


class Pin:
    """The same chain built in Pinocchio: joint i at its home point (axes as in the book), a tool frame at M."""

    def __init__(self, chain):
        import pinocchio as pin

        self.pin = pin
        S = np.array(chain.screws, dtype=float)
        pts = np.array(chain.joint_points, dtype=float)
        M = np.array(chain.M, dtype=float)
        model = pin.Model()
        parent, prev = 0, np.zeros(3)
        for i, kind in enumerate(chain.joint_types):
            w, v = S[:3, i], S[3:, i]
            if kind == "R":
                p = pts[:, i] if np.allclose(-np.cross(w, pts[:, i]), v) else np.cross(w, v)
                joint = pin.JointModelRevoluteUnaligned(w / np.linalg.norm(w))
            else:
                assert np.isclose(np.linalg.norm(v), 1.0), "prismatic screw axes must be unit vectors"
                p = pts[:, i]
                joint = pin.JointModelPrismaticUnaligned(v)
            parent = model.addJoint(parent, joint, pin.SE3(np.eye(3), p - prev), f"joint{i + 1}")
            prev = p
        self.fid = model.addFrame(
            pin.Frame("tool", parent, pin.SE3(M[:3, :3], M[:3, 3] - prev), pin.FrameType.OP_FRAME)
        )
        self.model, self.data = model, model.createData()

    def raw(self, what):
        """The timed call (Pinocchio's own conventions, no reordering)."""
        pin, m, d, f = self.pin, self.model, self.data, self.fid
        if what == "fk":

            def fk(q):
                pin.framesForwardKinematics(m, d, q)
                return d.oMf[f].homogeneous

            return fk
        ref = {
            "js": pin.ReferenceFrame.WORLD,
            "jb": pin.ReferenceFrame.LOCAL,
            "jg": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
        }[what]
        return lambda q: pin.computeFrameJacobian(m, d, q, f, ref)

    def book(self, what):
        """The same in the book's conventions: rows [v; ω] -> [ω; v]."""
        f = self.raw(what)
        if what == "fk":
            return lambda q: np.array(f(q))
        return lambda q: np.asarray(f(q))[[3, 4, 5, 0, 1, 2]]


def _loop(f, Q, shape):
    out = np.empty((len(Q),) + shape)
    for i, q in enumerate(Q):
        out[i] = f(q)
    return out


# --- sections --------------------------------------------------------------------------------------
def numeric_section(args, targets: Targets) -> list[str]:
    try:
        import pinocchio  # noqa: F401

        have_pin = True
        pin_note = f"Pinocchio {_version('pin')}: a Python loop over `computeFrameJacobian` for a batch."
    except ImportError:
        have_pin = False
        pin_note = '**Pinocchio (`pin`) is not installed: its columns say "not available"** (`make bench` installs it).'
    rng = np.random.default_rng(2024)
    lines = [
        "## Numeric kinematics (float arrays, fast path)",
        "",
        f"kinlib: `SerialChain` methods with q a float array of shape (n,), or (N, n) for a batch of "
        f"N = {args.batch:,}; kinlib's column gives the median (the fastest run in parentheses: the machine "
        f"may be shared, the median is what the targets are checked against). modern-robotics 1.1.1: `FKinSpace`, `JacobianSpace`, `JacobianBody` (geometric: "
        f"blockdiag(R, R)·J_b), a Python loop for a batch. {pin_note} Times per configuration; "
        f"× = how many times faster kinlib is. Checked first: kinlib = modern-robotics = Pinocchio "
        f"(np.allclose, 20 random configurations, and batch = single calls). kinlib's single calls run the "
        f"compiled C of `kinlib.native` (compiled before timing with `compile_native()`; otherwise after 1000 calls).",
        "",
    ]
    rows = []
    for chain in numeric_robots():
        n = chain.n
        native = compile_chain(chain)  # the single call's compiled C, as after a chain's first 1000 calls
        mrr = MR(chain)
        pinr = Pin(chain) if have_pin else None
        Qcheck = rng.uniform(-np.pi, np.pi, (20, n))
        Q = rng.uniform(-np.pi, np.pi, (args.batch, n))
        q = Qcheck[0].copy()
        is_ur5 = chain.name == "ur5"
        for what, label in QUANTITIES:
            kin = getattr(chain, METHOD[what])
            # right before fast
            batch = kin(Qcheck)
            for k, qk in enumerate(Qcheck):
                single = kin(qk)
                ref = mrr.fn(what)(qk)
                assert np.allclose(single, ref, atol=1e-9), f"{chain.name} {what}: kinlib != modern-robotics at {qk}"
                assert np.allclose(batch[k], single, atol=1e-12), f"{chain.name} {what}: batch != single at {qk}"
                if pinr is not None:
                    assert np.allclose(single, pinr.book(what)(qk), atol=1e-9), (
                        f"{chain.name} {what}: kinlib != Pinocchio at {qk}"
                    )
            shape = batch.shape[1:]
            t_k, t_k_best = per_call(lambda: kin(q), args.reps, best=True)
            t_m = per_call(lambda: mrr.fn(what)(q), max(3, args.reps // 2))
            t_p = per_call(lambda: pinr.raw(what)(q), args.reps) if pinr else None
            kin(Q)  # compile/warm
            tb_k, tb_k_best = (t / args.batch for t in once(lambda: kin(Q), max(3, args.reps // 2), best=True))
            Qm = Q[: args.mr_batch]
            tb_m = once(lambda: _loop(mrr.fn(what), Qm, shape), 3) / len(Qm)
            Qp = Q[: args.pin_batch]
            tb_p = once(lambda: _loop(pinr.raw(what), Qp, shape), 3) / len(Qp) if pinr else None
            name = f"{chain.name} (n={n})"
            s_single = s_batch = "—"
            if is_ur5:
                s_single = targets.upper(f"UR5 {label}, one configuration", t_k, T_SINGLE)
                if what == "js":
                    s_single = f"{s_single}; ≥ 80× mr: " + targets.lower(
                        "UR5 J_s speed-up over modern-robotics", t_m / t_k, T_SPEEDUP_MR
                    )
                s_batch = targets.upper(f"UR5 {label}, batched, per configuration", tb_k, T_BATCH)
            tgt_s = ("≤ 3 µs, ≥ 80× mr" if what == "js" else "≤ 3 µs") if is_ur5 else "—"
            tgt_b = "≤ 200 ns" if is_ur5 else "—"
            rows.append(
                [
                    name,
                    label,
                    "single",
                    f"{fmt_t(t_k)} ({fmt_t(t_k_best)})",
                    fmt_t(t_m),
                    fmt_x(t_m / t_k),
                    fmt_t(t_p) if pinr else NA,
                    fmt_x(t_p / t_k) if pinr else NA,
                    tgt_s,
                    s_single,
                ]
            )
            rows.append(
                [
                    name,
                    label,
                    f"batch {args.batch:,}",
                    f"{fmt_t(tb_k)} ({fmt_t(tb_k_best)})",
                    fmt_t(tb_m),
                    fmt_x(tb_m / tb_k),
                    fmt_t(tb_p) if pinr else NA,
                    fmt_x(tb_p / tb_k) if pinr else NA,
                    tgt_b,
                    s_batch,
                ]
            )
    lines += table(
        [
            "robot",
            "quantity",
            "call",
            "kinlib (best)",
            "modern-robotics",
            "× vs mr",
            "Pinocchio",
            "× vs pin",
            "target",
            "status",
        ],
        rows,
    )
    lines += [
        "",
        f"Batched reference loops ran over the first {args.mr_batch:,} (modern-robotics) and "
        f"{args.pin_batch:,} (Pinocchio) configurations of the same batch. kinlib's single call ran: {native}.",
    ]
    return lines


_SINGULAR_SCRIPT = r"""
import json, sys, time
t0 = time.perf_counter()
from kinlib import robots
try:
    from kinlib.singularities import singular_configurations
except ImportError:
    print(json.dumps({"missing": True})); sys.exit()
ur5 = robots.ur5()
J = ur5.jacobian_space()
t = time.thread_time()
res = singular_configurations(J, ur5.thetas)
dt = time.thread_time() - t
print(json.dumps({"seconds": dt, "result": str(res), "count": len(res)}))
"""


def symbolic_section(args, targets: Targets) -> list[str]:
    lines = ["## Symbolic (exact SymPy)", ""]
    rows = []

    # build: a fresh chain each time, with SymPy's cache cleared (nothing remembered)
    def build():
        sp.core.cache.clear_cache()
        r = robots.ur5()
        t0 = CLOCK()
        J = r.jacobian_space()
        return CLOCK() - t0, J

    build()  # warm-up: imports inside SymPy
    tb = statistics.median(build()[0] for _ in range(max(3, args.reps)))
    rows.append(
        [
            "UR5 J_s built (fresh chain, SymPy cache cleared)",
            fmt_t(tb),
            "≤ 0.1 s",
            targets.upper("UR5 symbolic J_s build", tb, T_SYM_BUILD),
        ]
    )
    try:
        from kinlib.display import simplify_for_display
    except ImportError:
        simplify_for_display = None
    if simplify_for_display is not None:
        times = []
        for _ in range(1 if args.quick else 3):
            _, J = build()
            t0 = CLOCK()
            D = simplify_for_display(J)
            times.append(CLOCK() - t0)
        td = statistics.median(times)
        qv = {t: 0.1 * (i + 1) for i, t in enumerate(robots.ur5().thetas)}
        assert np.allclose(np.array(D.subs(qv).evalf(), float), np.array(J.subs(qv).evalf(), float), atol=1e-12)
        rows.append(
            [
                "UR5 J_s shown simplified (`kinlib.display.simplify_for_display`)",
                fmt_t(td),
                "≤ 3 s",
                targets.upper("UR5 J_s display simplification", td, T_DISPLAY),
            ]
        )
    else:
        rows.append(
            ["UR5 J_s shown simplified", NA, "≤ 3 s", targets.upper("UR5 J_s display simplification", None, T_DISPLAY)]
        )
    # singular set, in a subprocess with a time limit
    try:
        p = subprocess.run(
            [sys.executable, "-c", _SINGULAR_SCRIPT],
            capture_output=True,
            text=True,
            timeout=args.singular_timeout,
            cwd=ROOT,
        )
        out = json.loads(p.stdout.strip().splitlines()[-1]) if p.returncode == 0 and p.stdout.strip() else None
        if out is None:
            rows.append(
                [
                    "UR5 singular set (`singular_configurations(J_s, θ)`)",
                    f"error: {p.stderr.strip()[-200:]}",
                    "≤ 5 s",
                    targets.upper("UR5 singular set", None, T_SINGULAR),
                ]
            )
        elif out.get("missing"):
            rows.append(
                [
                    "UR5 singular set",
                    NA + " (kinlib.singularities missing)",
                    "≤ 5 s",
                    targets.upper("UR5 singular set", None, T_SINGULAR),
                ]
            )
        else:
            rows.append(
                [
                    f"UR5 singular set (`singular_configurations(J_s, θ)`: {out['count']} conditions)",
                    fmt_t(out["seconds"]),
                    "≤ 5 s",
                    targets.upper("UR5 singular set", out["seconds"], T_SINGULAR),
                ]
            )
            lines += [f"UR5 singular set found: `{out['result']}`", ""]
    except subprocess.TimeoutExpired:
        rows.append(
            [
                "UR5 singular set",
                f"> {args.singular_timeout:.0f} s (stopped)",
                "≤ 5 s",
                targets.upper("UR5 singular set", float(args.singular_timeout), T_SINGULAR),
            ]
        )
    return lines + table(["what", "time", "target", "status"], rows)


_BAXTER_H = 1.57079632679  # the URDF's own digits: not π/2, so no rotation entry is zero (a dense arm)
BAXTER_LEFT_ARM = [  # baxter_description: left_arm_mount, then s0 ... w2
    ("fixed", (0.024645, 0.219645, 0.118588), (0, 0, 0.7854), None),
    ("revolute", (0.055695, 0, 0.011038), (0, 0, 0), (0, 0, 1)),
    ("revolute", (0.069, 0, 0.27035), (-_BAXTER_H, 0, 0), (0, 0, 1)),
    ("revolute", (0.102, 0, 0), (_BAXTER_H, 0, _BAXTER_H), (0, 0, 1)),
    ("revolute", (0.069, 0, 0.26242), (-_BAXTER_H, -_BAXTER_H, 0), (0, 0, 1)),
    ("revolute", (0.10359, 0, 0), (_BAXTER_H, 0, _BAXTER_H), (0, 0, 1)),
    ("revolute", (0.01, 0, 0.2707), (-_BAXTER_H, -_BAXTER_H, 0), (0, 0, 1)),
    ("revolute", (0.115975, 0, 0), (_BAXTER_H, 0, _BAXTER_H), (0, 0, 1)),
]
BAXTER_TOOL = ((0, 0, 0.27175), (0, 0, 0))


def first_call_section(args, targets: Targets) -> list[str]:
    lines = [
        "## First numeric call of a 7-joint chain (code generation)",
        "",
        "A fresh chain built with `robots.from_urdf_joints` from the Baxter left arm's URDF placements "
        "(SymPy's cache cleared), timed from the first call with floats to its result.",
        "",
    ]
    if not hasattr(robots, "from_urdf_joints"):
        return lines + [NA + " (robots.from_urdf_joints missing)"]
    q = np.zeros(7)

    def first(methods):
        sp.core.cache.clear_cache()
        chain = robots.from_urdf_joints(BAXTER_LEFT_ARM, BAXTER_TOOL, name="baxter_left")
        t0 = CLOCK()
        for m in methods:
            getattr(chain, m)(q)
        return CLOCK() - t0

    first(["fk"])  # warm-up
    rows = []
    for label, methods in (
        ("T(θ)", ["fk"]),
        ("J_s", ["jacobian_space"]),
        ("J_b", ["jacobian_body"]),
        ("geometric J", ["jacobian_geometric"]),
        ("all four", ["fk", "jacobian_space", "jacobian_body", "jacobian_geometric"]),
    ):
        t = statistics.median(first(methods) for _ in range(max(3, min(args.reps, 5))))
        rows.append(
            [
                f"Baxter 7R arm from URDF placements: first call of {label}",
                fmt_t(t),
                "≤ 2 s",
                targets.upper(f"first numeric call, 7-joint arm, {label}", t, T_FIRST_CALL),
            ]
        )
    rows += _compile_rows()
    return lines + table(["what", "CPU time (median)", "target", "status"], rows)


_LOAD_SCRIPT = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1])
from bench import BAXTER_LEFT_ARM, BAXTER_TOOL
from kinlib import robots
c = robots.from_urdf_joints(BAXTER_LEFT_ARM, BAXTER_TOOL, name="baxter_left").numeric_code("jg")
t = time.perf_counter()
ok = c.compile_native()
print(json.dumps({"seconds": time.perf_counter() - t, "ok": ok, "status": c.native_status}))
"""


def _compile_rows() -> list[list[str]]:
    """The compiled C (kinlib.native) of the Baxter arm's geometric J: compiled in an empty cache (wall time and the
    compiler's CPU time: it runs in a subprocess), then loaded from that cache by a new process."""
    old = os.environ.get("KINLIB_CACHE")
    with tempfile.TemporaryDirectory() as d:
        os.environ["KINLIB_CACHE"] = d
        try:
            c = robots.from_urdf_joints(BAXTER_LEFT_ARM, BAXTER_TOOL, name="baxter_left").numeric_code("jg")
            t0, c0 = time.perf_counter(), os.times()
            ok = c.compile_native()
            wall, c1 = time.perf_counter() - t0, os.times()
            cc = c1.children_user + c1.children_system - c0.children_user - c0.children_system
            p = subprocess.run(
                [sys.executable, "-c", _LOAD_SCRIPT, str(ROOT / "bench")], capture_output=True, text=True, cwd=ROOT
            )
            load = json.loads(p.stdout.strip().splitlines()[-1]) if p.returncode == 0 and p.stdout.strip() else None
        finally:
            if old is None:
                os.environ.pop("KINLIB_CACHE", None)
            else:
                os.environ["KINLIB_CACHE"] = old
    status = "" if ok else f" ({c.native_status})"
    return [
        [
            f"Baxter geometric J compiled to C, empty cache{status} (wall time; the C compiler's CPU time)",
            f"{fmt_t(wall)} wall; cc {fmt_t(cc)}",
            "— (background, after 1000 calls)",
            "—",
        ],
        [
            "the same loaded from the cache by a new process (wall time)",
            fmt_t(load["seconds"]) if load else f"error: {p.stderr.strip()[-200:]}",
            "—",
            load["status"][:60] if load else NA,
        ],
    ]


def _rtb_own_models(args) -> str:
    """One sentence: the Robotics Toolbox's own Panda and iiwa14 models (rtb-data), ets.jacob0 timed in this run."""
    import contextlib
    import io

    import roboticstoolbox as rtb

    q = np.random.default_rng(3).uniform(-np.pi, np.pi, 7)
    parts = []
    for label, make, end in (
        ("Panda (`models.Panda`, to panda_hand)", rtb.models.Panda, "panda_hand"),
        ("LBR iiwa 14 R820 (`models.LBR`, to tool0)", rtb.models.LBR, "tool0"),
    ):
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                ets = make().ets(end=end)
            assert ets.n == 7 and np.asarray(ets.jacob0(q)).shape == (6, 7)
            parts.append(f"{label} {fmt_t(per_call(lambda: ets.jacob0(q), args.reps))}")
        except Exception as e:  # a model RTB cannot build here is reported, not skipped silently
            parts.append(f"{label}: {NA} ({type(e).__name__})")
    return (
        "The Robotics Toolbox's own models of these arms (from rtb-data; timing only, their frames differ from the "
        "URDFs above), `ets.jacob0(q)` in this run: " + "; ".join(parts) + ". Its UR5 (`models.UR5`) fetches "
        "example-robot-data from GitHub at run time (no network here): not timed; the same-file rows above are the "
        "like-for-like comparison."
    )


T_URDF_VS_PIN = 2.0  # a URDF arm's single-call geometric J: at most 2× Pinocchio's time (issue 25)
T_URDF_VS_RTB = 1.0  # ... and ahead of the Robotics Toolbox's compiled ETS (kinlib ÷ RTB < 1)


def compile_chain(chain, whats=("fk", "js", "jb", "jg")) -> str:
    """Compile the chain's generated code to C now (``compile_native``; otherwise it happens in the background
    after 1000 calls, in the middle of a measurement); its status, e.g. 'C (...)' or 'Python: <why>'."""
    status = ""
    for w in whats:
        c = chain.numeric_code(w)
        c.compile_native()
        status = c.native_status
    return status


def _ratio_cell(a, b):
    return fmt_x(a / b) if a and b else NA


def urdf_section(args, targets: Targets) -> list[str]:
    """Real arms from their URDFs (bench/urdf_arms.py): geometric J, kinlib against Pinocchio and the Robotics
    Toolbox, single call and batched."""
    from urdf_arms import ARMS, PinArm, RtbArm, kinlib_chain  # bench/ is this script's folder, first on sys.path

    try:
        import pinocchio  # noqa: F401

        have_pin = True
    except ImportError:
        have_pin = False
    try:
        import roboticstoolbox  # noqa: F401

        have_rtb = True
    except ImportError:
        have_rtb = False
    lines = [
        "## Real arms from URDF (geometric J: single call and batched)",
        "",
        "Each arm's URDF read by the three libraries (`bench/urdf_arms.py`): kinlib through `robots.from_urdf_joints` "
        "(its generated code: the URDF's placements folded into floats; the single call is the compiled C of "
        "`kinlib.native`, the Python code of the same expressions beside it), Pinocchio through `buildModelFromXML` "
        "reduced to the same joints, `computeFrameJacobian(..., LOCAL_WORLD_ALIGNED)` at the tip frame, the "
        f"Robotics Toolbox {_version('roboticstoolbox-python')} through `Robot.URDF` on the same file, the compiled "
        "ETS of its base-to-tip path: `ets.jacob0(q)`. Checked first: kinlib = Pinocchio = RTB (rows reordered, "
        "np.allclose at 20 random configurations). "
        + ("" if have_pin else '**Pinocchio (`pin`) is not installed: its columns say "not available"**. ')
        + ("" if have_rtb else '**The Robotics Toolbox is not installed: its columns say "not available"**. ')
        + "All timed in this run (medians; the fastest run in parentheses); ratios of medians (and of fastest runs), "
        "< 1: kinlib is "
        f"faster. Batched: kinlib's batch call on N = {args.batch:,} configurations against Python loops over "
        f"{args.pin_batch:,} (Pinocchio, RTB), per configuration.",
        "",
    ]
    rng = np.random.default_rng(7)
    rows, brows, status = [], [], ""
    for name, source, get_xml, tip in ARMS:
        xml = get_xml()
        if xml is None:
            rows.append([name, source] + [NA] * 8)
            targets.upper(f"{name} URDF geometric J ÷ Pinocchio's", None, T_URDF_VS_PIN, fmt=fmt_x)
            targets.upper(f"{name} URDF geometric J ÷ RTB's", None, T_URDF_VS_RTB, fmt=fmt_x)
            continue
        chain = kinlib_chain(name, xml, tip)
        pa = PinArm(xml, tip) if have_pin else None
        ra = RtbArm(xml, tip) if have_rtb else None
        Q = rng.uniform(-np.pi, np.pi, (20, chain.n))
        python_single = chain.numeric_code("jg")._single
        for qk in Q:
            if pa is not None:
                assert np.allclose(chain.jacobian_geometric(qk), pa.book(qk), atol=1e-9), f"{name}: kinlib != Pinocchio"
            if ra is not None:
                assert np.allclose(chain.jacobian_geometric(qk), ra.book(qk), atol=1e-9), f"{name}: kinlib != RTB"
        status = compile_chain(chain, ("jg",))
        for qk in Q:
            assert np.allclose(chain.jacobian_geometric(qk), python_single(list(qk)), rtol=0, atol=1e-15)
        q = Q[0].copy()
        t_py = per_call(lambda: python_single(q.tolist()), args.reps)
        t_k, t_best = per_call(lambda: chain.jacobian_geometric(q), args.reps, best=True)
        t_p, p_best = per_call(lambda: pa.geometric(q), args.reps, best=True) if pa is not None else (None, None)
        t_r, r_best = per_call(lambda: ra.geometric(q), args.reps, best=True) if ra is not None else (None, None)
        rp = t_k / t_p if t_p else None
        rr = t_k / t_r if t_r else None
        rows.append(
            [
                f"{name} (n={chain.n})",
                source,
                f"{fmt_t(t_k)} ({fmt_t(t_best)})",
                fmt_t(t_py),
                f"{fmt_t(t_p)} ({fmt_t(p_best)})" if t_p else NA,
                f"{fmt_t(t_r)} ({fmt_t(r_best)})" if t_r else NA,
                f"{fmt_x(rp)} ({fmt_x(t_best / p_best)})" if rp else NA,
                f"{fmt_x(rr)} ({fmt_x(t_best / r_best)})" if rr else NA,
                targets.upper(f"{name} URDF geometric J ÷ Pinocchio's", rp, T_URDF_VS_PIN, fmt=fmt_x),
                targets.upper(f"{name} URDF geometric J ÷ RTB's", rr, T_URDF_VS_RTB, fmt=fmt_x),
            ]
        )
        Qb = rng.uniform(-np.pi, np.pi, (args.batch, chain.n))
        chain.jacobian_geometric(Qb[:10])  # generate the batched code
        tb_k = once(lambda: chain.jacobian_geometric(Qb), max(3, args.reps // 2)) / len(Qb)
        Ql = Qb[: args.pin_batch]
        tb_p = once(lambda: _loop(pa.geometric, Ql, (6, chain.n)), 3) / len(Ql) if pa is not None else None
        tb_r = once(lambda: _loop(ra.geometric, Ql, (6, chain.n)), 3) / len(Ql) if ra is not None else None
        brows.append(
            [
                f"{name}, n={chain.n}",
                fmt_t(tb_k),
                fmt_t(tb_p) if tb_p else NA,
                fmt_t(tb_r) if tb_r else NA,
                _ratio_cell(tb_k, tb_p),
                _ratio_cell(tb_k, tb_r),
            ]
        )
    lines += table(
        [
            "arm",
            "URDF",
            "kinlib C (best)",
            "kinlib Python code",
            "Pinocchio (best)",
            "RTB (best)",
            "kinlib ÷ Pinocchio (best ÷ best)",
            "kinlib ÷ RTB (best ÷ best)",
            "≤ 2× Pinocchio",
            "< 1× RTB",
        ],
        rows,
    )
    lines += ["", f"kinlib's single call ran: {status or NA}."]
    if have_rtb:
        lines += ["", _rtb_own_models(args)]
    lines += ["", "Batched, per configuration:", ""]
    lines += table(["arm", "kinlib batch", "Pinocchio loop", "RTB loop", "kinlib ÷ Pinocchio", "kinlib ÷ RTB"], brows)
    # the numeric free function against modern-robotics and the chain's generated code
    import modern_robotics as mr

    ur5 = robots.ur5()
    S = np.array(ur5.screws, dtype=float)
    q = rng.uniform(-np.pi, np.pi, 6)
    assert np.allclose(kinlib.jacobian_space(S, q), mr.JacobianSpace(S, q), atol=1e-12)
    t_free = per_call(lambda: kinlib.jacobian_space(S, q), args.reps)
    t_mr = per_call(lambda: mr.JacobianSpace(S, q), max(3, args.reps // 2))
    compile_chain(ur5, ("js",))
    t_chain = per_call(lambda: ur5.jacobian_space(q), args.reps)
    lines += [
        "",
        "The numeric free function `kinlib.jacobian_space(S, q)` (UR5, no generated code, no SymPy) against "
        "modern-robotics' `JacobianSpace` and the chain's generated code `ur5.jacobian_space(q)`:",
        "",
    ]
    lines += table(
        ["call", "time", "× vs mr"],
        [
            ["kinlib.jacobian_space(S, q)", fmt_t(t_free), fmt_x(t_mr / t_free)],
            ["mr.JacobianSpace(S, q)", fmt_t(t_mr), "1×"],
            ["ur5.jacobian_space(q) (generated code, compiled C)", fmt_t(t_chain), fmt_x(t_mr / t_chain)],
        ],
    )
    return lines


def exact_section(args, targets: Targets) -> list[str]:
    """Exact rank, column space and left null space at configurations of 6-joint arms (kinlib.exact)."""
    from kinlib.exact import column_space, left_null_space, rank_at

    lines = [
        "## Exact analysis at a configuration (6-joint arms)",
        "",
        "`rank_at`, `column_space` and `left_null_space` of the 6×6 J at one configuration: proved exactly "
        "(or, beyond the exact budget, 60-digit numerics, flagged).",
        "",
    ]
    stanford = robots.stanford()
    R = sp.Rational
    cases = [
        ("Stanford RRPRRR", stanford, "J_s", (1, 2, 3, 4, 5, 6)),
        ("Stanford RRPRRR (wrist θ5 = 0)", stanford, "J_s", (1, 2, R(1, 3), 4, 0, 6)),
        ("UR5 geometric J (elbow θ3 = 0)", robots.ur5(), "J", (R(1, 2), 10, 0, 1, 3, 2)),
        ("UR5 geometric J", robots.ur5(), "J", (1, 1, 1, 1, 1, 1)),
    ]
    rows = []
    for label, chain, which, q in cases if not args.quick else cases[:2]:
        J = chain.jacobian_space() if which == "J_s" else chain.jacobian_geometric()
        sp.core.cache.clear_cache()
        t0 = CLOCK()
        r = rank_at(J, q, chain.thetas)
        t1 = CLOCK()
        C = column_space(J, q, chain.thetas)
        t2 = CLOCK()
        N = left_null_space(J, q, chain.thetas)
        t3 = CLOCK()
        assert C.shape[1] == r and N.shape[1] == 6 - r
        worst = max(t1 - t0, t2 - t1, t3 - t2)
        rows.append(
            [
                f"{label} at θ = {tuple(q)}: rank {r!r}",
                fmt_t(t1 - t0),
                fmt_t(t2 - t1),
                fmt_t(t3 - t2),
                "≤ 30 s each",
                targets.upper(f"exact analysis, {label}", worst, T_EXACT_RANK),
            ]
        )
    return lines + table(["what", "rank_at", "column_space", "left_null_space", "target", "status"], rows)


def singular_poses_section(args, targets: Targets) -> list[str]:
    """Exact rank and bases at the textbook's singular poses with mixed rational·π angles (issue 32, item 2):
    each call's CPU seconds and whether the answer is exact (``Rank.exact``; the bases: no Floats, no warning)."""
    import warnings

    from kinlib.exact import NumericFallbackWarning, column_space, left_null_space, rank_at
    from kinlib.manipulability import velocity_ellipsoid

    def ellipsoid(J, q, thetas):  # the default rows ("linear"), J at the pose; exact when its rank is ≤ 1
        return velocity_ellipsoid(J.subs(dict(zip(thetas, q))))

    R, pi = sp.Rational, sp.pi
    h = [3 * pi / 11, 2 * pi / 7, 5 * pi / 13, 3 * pi / 11, 2 * pi / 7, R(1, 3)]
    no_offsets = robots.puma560(R(2, 5), 0, 0, R(2, 5))
    cases = [
        ("UR5 elbow θ3 = π", robots.ur5(), [h[0], h[1], pi, h[2], h[3], h[4]]),
        ("UR5 wrist θ5 = 0", robots.ur5(), [h[0], h[1], h[2], h[3], 0, h[4]]),
        ("UR5 elbow and wrist", robots.ur5(), [h[0], h[1], 0, h[2], pi, h[5]]),
        ("UR5 θ3 = π + 10⁻⁷⁰ (R07: full rank)", robots.ur5(), [R(1, 2), 2 * pi / 7, pi + R(1, 10**70), 3, h[3], 1]),
        ("PUMA 560 wrist θ5 = π", robots.puma560(), [h[0], h[1], h[2], h[3], pi, h[5]]),
        ("PUMA (no offsets) elbow θ3 = π/2", no_offsets, [h[0], h[1], pi / 2, h[2], h[3], h[4]]),
        ("PUMA (no offsets) shoulder θ3 = π/2 − 2θ2", no_offsets, [h[0], h[1], pi / 2 - 2 * h[1], h[2], h[3], h[5]]),
    ]
    lines = [
        "## Exact analysis at singular poses (issue 32)",
        "",
        "`rank_at`, `column_space`, `left_null_space`, `velocity_ellipsoid` (linear rows) of the space Jacobian at elbow, wrist and shoulder "
        "singularities with mixed rational·π angles (2π/7, 3π/11, 5π/13, 1/3: their number field has degree in the "
        "hundreds). CPU seconds per call (`CLOCK`: this thread's and its ended children's, so a budgeted call's forked "
        "child is counted; SymPy's cache cleared before each pose) and whether "
        "the answer is exact. Before issue 32 each call spent its whole 60 s budget, then answered in 60-digit "
        "numerics.",
        "",
    ]
    rows = []
    for label, chain, q in cases if not args.quick else cases[:2]:
        J = chain.jacobian_space()
        sp.core.cache.clear_cache()
        cells, worst, exact = [], 0.0, True
        for fn in (rank_at, column_space, left_null_space, ellipsoid):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                t0 = CLOCK()
                out = fn(J, q, chain.thetas)
                dt = CLOCK() - t0
            if fn is rank_at:
                ok, r = bool(out.exact), out
            elif fn is ellipsoid:  # exact, or the stated-precision answer with its warning (both are right)
                fell = any(issubclass(w.category, NumericFallbackWarning) for w in caught)
                cells.append(f"{fmt_t(dt)} ({'60 digits, warned' if fell else 'exact'})")
                worst = max(worst, dt)
                continue
            else:
                ok = not any(e.has(sp.Float) for e in out)
            ok = ok and not any(issubclass(w.category, NumericFallbackWarning) for w in caught)
            exact &= ok
            worst = max(worst, dt)
            cells.append(f"{fmt_t(dt)} ({'exact' if ok else 'NOT exact'})")
        status = targets.upper(f"singular pose, {label}", worst if exact else None, T_SINGULAR_POSE)
        rows.append([f"{label}: rank {int(r)}", *cells, f"≤ {fmt_t(T_SINGULAR_POSE)} each, exact", status])
    header = ["pose", "rank_at", "column_space", "left_null_space", "velocity_ellipsoid", "target", "status"]
    return lines + table(header, rows)


_SINGULAR7_SCRIPT = r"""
import json, sys, time, warnings
import numpy as np, sympy as sp
from kinlib import SerialChain
from kinlib.singularities import singular_configurations
from kinlib.singular_search import find_singularities
R = sp.Rational
# a Franka-like 7R arm (Panda's axis layout and DH lengths, in metres, at its zero pose)
d1, d3, d5, a4, a7 = R(333, 1000), R(316, 1000), R(384, 1000), R(825, 10000), R(88, 1000)
z3, z5 = d1 + d3, d1 + d3 + d5
axes = [((0, 0, 1), (0, 0, d1)), ((0, 1, 0), (0, 0, d1)), ((0, 0, 1), (0, 0, z3)), ((0, -1, 0), (a4, 0, z3)),
        ((0, 0, 1), (0, 0, z5)), ((0, -1, 0), (0, 0, z5)), ((0, 0, -1), (a7, 0, z5))]
S = [[*sp.Matrix(w), *(-sp.Matrix(w).cross(sp.Matrix(q)))] for w, q in axes]
arm = SerialChain(sp.Matrix([[1, 0, 0, a7], [0, -1, 0, 0], [0, 0, -1, z5 - R(107, 1000)], [0, 0, 0, 1]]),
                  sp.Matrix(S).T, name="franka_like")
J = arm.jacobian_space()
t = time.thread_time()
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    res = singular_configurations(J, arm.thetas)
dt = time.thread_time() - t
arm.jacobian_geometric(np.zeros(7))          # code generation, not timed below
t = time.thread_time()
found = find_singularities(arm)
ds = time.thread_time() - t
print(json.dumps({"seconds": dt, "complete": bool(res.complete), "count": len(res),
                  "ops": [int(sp.count_ops(c)) for c in res if not isinstance(c, dict)],
                  "search": ds, "points": len(found[0]), "sigma": float(np.max(found[1])) if len(found[1]) else None}))
"""


def analysis_section(args, targets: Targets) -> list[str]:
    """The 6×7 singular set, the numeric search on the same arm, and a symbolic condition number."""
    lines = ["## Singular sets of a redundant arm, the numeric search, symbolic conditioning", ""]
    rows = []
    try:
        p = subprocess.run(
            [sys.executable, "-c", _SINGULAR7_SCRIPT],
            capture_output=True,
            text=True,
            timeout=max(args.singular_timeout, 90),
            cwd=ROOT,
        )
        out = json.loads(p.stdout.strip().splitlines()[-1]) if p.returncode == 0 and p.stdout.strip() else None
    except subprocess.TimeoutExpired:
        out, p = None, None
    if out is None:
        why = "timed out" if p is None else f"error: {p.stderr.strip()[-200:]}"
        rows.append(
            [
                "Franka-like 7R: `singular_configurations` of the 6×7 J_s",
                why,
                "≤ 60 s",
                targets.upper("6×7 singular set", None, T_SINGULAR_7),
            ]
        )
        rows.append(["Franka-like 7R: `find_singularities`", why, "—", "—"])
    else:
        kind = ("complete" if out["complete"] else "partial (says so)") + f", {out['count']} condition(s)"
        rows.append(
            [
                f"Franka-like 7R: `singular_configurations` of the 6×7 J_s ({kind})",
                fmt_t(out["seconds"]),
                "≤ 60 s",
                targets.upper("6×7 singular set", out["seconds"], T_SINGULAR_7),
            ]
        )
        rows.append(
            [
                f"Franka-like 7R: `find_singularities` ({out['points']} configurations, σ_min ≤ {out['sigma']:.1e})",
                fmt_t(out["search"]),
                "—",
                "reported",
            ]
        )
    from kinlib.manipulability import condition_number, isotropy

    L1, L2 = sp.symbols("L1 L2", positive=True)
    r2 = kinlib.SerialChain(
        sp.Matrix([[1, 0, 0, L1 + L2], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]),
        [[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, -L1, 0]],
        name="planar_2r",
    )
    Jt = kinlib.task_rows(r2.jacobian_geometric(), ["vx", "vy"])

    def cond():
        sp.core.cache.clear_cache()
        t0 = CLOCK()
        k = condition_number(Jt)
        iso = isotropy(Jt)
        return CLOCK() - t0, k, iso

    tc, k, _ = min(cond() for _ in range(1 if args.quick else 3))
    rows.append(
        [
            f"planar 2R (L1, L2 symbolic): symbolic condition number and isotropy ({sp.count_ops(k)} operations)",
            fmt_t(tc),
            "≤ 2 s",
            targets.upper("symbolic condition number, planar 2R", tc, T_COND_2R),
        ]
    )
    return lines + table(["what", "time", "target", "status"], rows) + ["", f"κ(θ) = `{k}`"]


def notebook_section(args, targets: Targets) -> list[str]:
    lines = ["## Notebooks (executed with nbclient in a temporary copy, kernel start included)", ""]
    expected = [
        "01_properties_of_jacobians",
        "02_planar_robot_jacobian",
        "03_spatial_robot_jacobian",
        "04_interpreting_the_jacobian",
        "05_singularities_planar",
        "06_singularities_spatial",
    ]
    present = {p.stem: p for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))}
    names = expected + [s for s in present if s not in expected]
    rows = []
    if args.quick:
        return lines + ["skipped (--quick)"]
    import nbformat
    from nbclient import NotebookClient

    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp) / "notebooks"
        shutil.copytree(ROOT / "notebooks", work)
        for stem in names:
            if stem not in present:
                rows.append([stem, NA, "≤ 10 s", targets.upper(f"notebook {stem}", None, T_NOTEBOOK)])
                continue
            path = work / present[stem].name
            nb = nbformat.read(path, as_version=4)
            client = NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(work)}})
            t0 = time.perf_counter()
            try:
                client.execute()
                dt = time.perf_counter() - t0
                nbformat.write(nb, path)
                rows.append([stem, fmt_t(dt), "≤ 10 s", targets.upper(f"notebook {stem}", dt, T_NOTEBOOK)])
            except Exception as exc:  # a failing notebook is a result too
                dt = time.perf_counter() - t0
                msg = str(exc).strip().splitlines()[-1][:120] if str(exc).strip() else type(exc).__name__
                targets.items.append((f"notebook {stem}", False, f"error after {fmt_t(dt)}"))
                rows.append([stem, f"error after {fmt_t(dt)}: {type(exc).__name__}: {msg}", "≤ 10 s", "**error**"])
    return lines + table(["notebook", "execution time", "target", "status"], rows)


def explorer_section(args, targets: Targets) -> list[str]:
    """The kernel's only part of an explorer: building it (code generation, the closed-form singular set, the
    view, the static PNG) once per cell; a slider move runs in the browser (the browser sections)."""
    lines = [
        "## Explorers, kernel side (`kinlib.widgets.explorer(chain)` and its display bundle, once per cell; "
        "slider moves run in the browser: see below)",
        "",
    ]
    if args.quick:
        return lines + ["skipped (--quick)"]
    try:
        from kinlib import widgets
    except ImportError as exc:
        targets.upper("explorer build", None, T_EXPLORER_BUILD)
        return lines + [f"{NA} (kinlib.widgets: {exc})"]
    rows = []
    for chain in numeric_robots():
        try:
            t0 = time.perf_counter()
            widgets.explorer(chain)._repr_mimebundle_()
            t = time.perf_counter() - t0
            status = targets.upper(f"explorer build {chain.name}", t, T_EXPLORER_BUILD)
            rows.append([chain.name, fmt_t(t), "≤ 3 s", status])
        except Exception as exc:
            targets.items.append((f"explorer build {chain.name}", False, "error"))
            rows.append([chain.name, f"error: {type(exc).__name__}: {str(exc)[:100]}", "≤ 3 s", "**error**"])
    return lines + table(["explorer", "build + display bundle (first, fresh chain)", "target", "status"], rows)


def _slider_times(labdriver, area, moves: int, key_pair=("ArrowRight", "ArrowLeft")) -> list[float]:
    """``moves`` key presses on θ1 of the explorer in ``area``, each timed key → the frame that shows it (ms)."""
    labdriver.wait_picture(area)
    _slider, handle, _readout = labdriver.slider(area, "θ1")
    handle.focus()
    return [labdriver.move_slider(area, handle, key_pair[k % 2]) for k in range(moves)]


def static_section(args, targets: Targets) -> list[str]:
    """The explorer of notebook 05's solutions page (as `make handouts` writes it), opened from disk: no kernel,
    network blocked; 20 key presses on θ1, key → the frame that shows the redrawn picture (page clock)."""
    lines = [
        "## On a static page (solutions 05 and 04 as `make handouts` writes them, opened from disk: no kernel)",
        "",
        f"Slider: a key press on the focused θ1 slider, {args.moves} moves (→ ← alternating), from the keydown to the "
        "animation frame that paints the redrawn SVG, page clock; the same for the 05 animation's step slider and "
        "the 04 picker's buttons (arrow keys between them).",
        "",
    ]
    if args.quick:
        return lines + ["skipped (--quick)"]
    labdriver, missing = _browser_driver()
    if missing:
        targets.upper("slider (static page)", None, T_SLIDER)
        return lines + [f"{NA} ({missing})"]
    from kinlib.course.publish import handouts
    from kinlib.course.publish.pages import build_assets

    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "handouts"
        nb = ROOT / "notebooks" / "05_singularities_planar.ipynb"
        urls = build_assets(out / "assets", ROOT / "build" / "vendor")
        handouts.build_one(nb, out, urls, 300, False, log=lambda s: None)
        with labdriver.chromium() as b:
            page = b.new_page(viewport={"width": 1400, "height": 1000})
            page.route("**/*", lambda r: r.continue_() if r.request.url.startswith("file:") else r.abort())
            page.goto((out / "solutions" / f"{nb.stem}.html").as_uri())
            page.wait_for_selector(".kinlib-explorer .kinlib-arm")
            areas = page.locator(".jp-OutputArea-output").filter(has=page.locator(".kinlib-explorer"))
            for i in range(areas.count()):
                ms = _slider_times(labdriver, areas.nth(i), args.moves)
                med = statistics.median(ms) / 1000
                status = targets.upper(f"slider 05 explorer {i + 1} (static page)", med, T_SLIDER)
                rows.append([f"05 explorer {i + 1}", fmt_t(min(ms) / 1000), fmt_t(med), fmt_t(max(ms) / 1000)])
                rows[-1] += ["≤ 16 ms", status]
            # the animation's step slider (05) and the picker's buttons (04): the same key → painted frame
            anim = page.locator(".jp-OutputArea-output").filter(has=page.locator(".kinlib-animation")).first
            rows.append(_key_row(labdriver, targets, "05 animation step", anim, "input.kinlib-step", args.moves))
            nb4 = ROOT / "notebooks" / "04_interpreting_the_jacobian.ipynb"
            handouts.build_one(nb4, out, urls, 300, False, log=lambda s: None)
            page.goto((out / "solutions" / f"{nb4.stem}.html").as_uri())
            page.wait_for_selector(".kinlib-picker .kinlib-arm")
            pick = page.locator(".jp-OutputArea-output").filter(has=page.locator(".kinlib-picker")).first
            rows.append(_key_row(labdriver, targets, "04 picker button", pick, "button[aria-pressed=true]", args.moves))
            page.close()
    return lines + table(["explorer", "min", "median", "max", "target (median)", "status"], rows)


def _key_row(labdriver, targets, what: str, area, control: str, moves: int) -> list[str]:
    """``moves`` key presses (→ ← alternating) on ``control`` in ``area``, key → the frame that paints it."""
    labdriver.wait_picture(area)
    handle = area.locator(control)
    ms = [labdriver.move_slider(area, handle, ("ArrowRight", "ArrowLeft")[k % 2]) for k in range(moves)]
    med = statistics.median(ms) / 1000
    status = targets.upper(f"{what} (static page)", med, T_SLIDER)
    return [what, fmt_t(min(ms) / 1000), fmt_t(med), fmt_t(max(ms) / 1000), "≤ 16 ms", status]


_GRADE_RUN = """
import json, os, sys, time
from kinlib.course.grader.grade import grade_batch
subs, notebooks, cache, out = sys.argv[1:5]
t0, c0 = time.monotonic(), time.process_time()
s = grade_batch([subs], out, jobs=2, notebooks=notebooks, cache=cache, log=None)
print(json.dumps({"n": s["n"], "seconds": s["seconds"], "reference_seconds": s["reference_seconds"],
                  "cpu": sum(r.get("cpu_seconds", 0) for r in s["results"]) + time.process_time() - c0,
                  "sandbox": s["sandbox"], "infrastructure": s["infrastructure_errors"],
                  "rows": [r["status"] for r in s["rows"]]}))
"""
T_GRADE_200 = 8 * 60.0  # 200 workbooks, 2 cores, sandbox on


def _browser_driver():
    """(tests/labdriver.py, None) when playwright and Debian's chromium are there, else (None, why not)."""
    sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "course")]  # labdriver; test_lite (time to first result)
    try:
        import playwright  # noqa: F401

        import labdriver
    except ImportError as exc:
        return None, str(exc)
    if not Path(labdriver.CHROMIUM).exists():
        return None, f"{labdriver.CHROMIUM} is missing: `make chromium`"
    return labdriver, None


def browser_section(args, targets: Targets) -> list[str]:
    """JupyterLab in Debian's chromium, started as `make lab` does (tests/labdriver.py): per notebook, Run All
    Cells (command → the kernel's last reply), then 20 key presses on each explorer's θ1 slider, each timed
    from the key press to the load of the new picture (page clock)."""
    lines = [
        "## In the browser (JupyterLab in Debian's chromium, as `make lab` starts it; wall time)",
        "",
        "Run-all: Run → Run All Cells on the notebook as committed, until the kernel's last reply (beside it the "
        "kernel's own busy time: the rest is the browser). Slider: a key press on the focused θ1 handle of each "
        f"explorer until the animation frame that paints its redrawn picture, {args.moves} moves (→ ← alternating), page clock.",
        "",
    ]
    if args.quick:
        return lines + ["skipped (--quick)"]
    labdriver, missing = _browser_driver()
    if missing:
        targets.upper("run-all in JupyterLab", None, T_LAB_RUN_ALL)
        return lines + [f"{NA} ({missing})"]
    stems = [p.stem for p in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))]
    run_rows, slider_rows = [], []
    with tempfile.TemporaryDirectory() as tmp, labdriver.jupyterlab(Path(tmp)) as url, labdriver.chromium() as b:
        for stem in stems:
            page = None
            try:
                page, _watch = labdriver.open_notebook(b, url, stem)
                wall, kernel = labdriver.run_all(page, details=True)
                status = targets.upper(f"run-all {stem} (JupyterLab)", wall, T_LAB_RUN_ALL)
                run_rows.append([stem, fmt_t(wall), fmt_t(kernel), "≤ 8 s", status])
                for i, area in enumerate(labdriver.explorers(page)):
                    ms = _slider_times(labdriver, area, args.moves)
                    med = statistics.median(ms) / 1000
                    status = targets.upper(f"slider {stem} explorer {i + 1} (JupyterLab)", med, T_SLIDER)
                    slider_rows.append(
                        [f"{stem} explorer {i + 1}", fmt_t(min(ms) / 1000), fmt_t(med), fmt_t(max(ms) / 1000)]
                        + ["≤ 16 ms", status]
                    )
            except Exception as exc:  # a failing notebook is a result too
                msg = " ".join(str(exc).split())[:160]
                targets.items.append((f"JupyterLab {stem}", False, "error"))
                run_rows.append([stem, f"error: {type(exc).__name__}: {msg}", "—", "≤ 8 s", "**error**"])
            finally:
                if page is not None:
                    labdriver.close_notebook(page)
    return (
        lines
        + table(["notebook", "run-all (JupyterLab)", "kernel busy", "target", "status"], run_rows)
        + [""]
        + table(["explorer", "min", "median", "max", "target (median)", "status"], slider_rows)
    )


def lite_section(args, targets: Targets) -> list[str]:
    """The in-browser site (JupyterLite on Pyodide, `make handouts` → build/handouts/lite): workbook 05 opened in
    Debian's chromium from a loopback server with every other request blocked, Run All as soon as the kernel is
    ready, until its first picture (page clock from the page load; tests/course/test_lite.py time_to_first_result)."""
    lines = [
        "## In the browser with nothing installed (JupyterLite site of `make handouts`)",
        "",
        "Time to first result: open workbook 05 of the site (served on loopback, every other request blocked), "
        "Run All as soon as the kernel is ready, until the first picture is drawn; page clock from the page load. "
        "Three fresh pages (each a cold Pyodide start: nothing kept between them); in the third, after Run All, "
        "key presses on θ1 of the explorer, each from the keydown to the frame that paints the redrawn picture.",
        "",
    ]
    if args.quick:
        return lines + ["skipped (--quick)"]
    labdriver, missing = _browser_driver()
    try:
        import test_lite

        from kinlib.course.publish import handouts, lite
        from kinlib.course.publish.pages import build_assets
    except ImportError as exc:
        missing = missing or str(exc)
    if missing:
        targets.upper("JupyterLite: time to first result", None, T_LITE_FIRST)
        return lines + [f"{NA} ({missing})"]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "handouts"
        t0 = time.perf_counter()
        try:
            nb = ROOT / "notebooks" / "05_singularities_planar.ipynb"
            urls = build_assets(out / "assets", ROOT / "build" / "vendor")
            handouts.build_one(nb, out, urls, 300, False, log=lambda s: None)
            lite.build_lite(out, sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")), log=lambda s: None)
        except Exception as exc:  # a failed build is a result too (e.g. no network for the first download)
            targets.upper("JupyterLite: time to first result", None, T_LITE_FIRST)
            return lines + [f"site build failed: {type(exc).__name__}: {' '.join(str(exc).split())[:200]}"]
        built = time.perf_counter() - t0
        size = sum(p.stat().st_size for p in (out / "lite").rglob("*") if p.is_file())
        with labdriver.chromium() as browser:
            times = [test_lite.time_to_first_result(out, browser) for _ in range(2)]
            t, ms = test_lite.time_to_first_result(out, browser, moves=args.moves)
            times.append(t)
    med = statistics.median(times)
    status = targets.upper("JupyterLite: time to first result (median of 3)", med, T_LITE_FIRST)
    smed = statistics.median(ms) / 1000
    sstatus = targets.upper("slider 05 explorer 1 (JupyterLite)", smed, T_SLIDER)
    return lines + table(
        ["what", "min", "median", "max", "target (median)", "status"],
        [
            ["workbook 05: page load → first picture", fmt_t(min(times)), fmt_t(med), fmt_t(max(times)), "≤ 30 s"]
            + [status],
            [f"workbook 05 explorer: key → the frame that shows it ({len(ms)} moves)", fmt_t(min(ms) / 1000)]
            + [fmt_t(smed), fmt_t(max(ms) / 1000), "≤ 16 ms", sstatus],
            [f"site build (notebook 05's workbook + site, warm cache), {size / 1e6:.0f} MB", "—", fmt_t(built), "—"]
            + ["—", "(reported)"],
        ],
    )


def grader_section(args, targets: Targets) -> list[str]:
    """``kinlib grade`` with the sandbox on: a batch of copies of the solution notebooks (every cell runs, as in
    a completed workbook), its wall time here, and 200 workbooks extrapolated two ways: from this wall time
    (this machine, loaded as it is now) and from the CPU time used (kernels included) on 2 idle cores."""
    lines = ["## Instructor checker (`kinlib grade`, sandboxed)", ""]
    if args.quick:
        return lines + ["skipped (--quick)"]
    if not (ROOT / "kinlib" / "course" / "grader" / "grade.py").exists():
        return lines + [f"{NA} (kinlib.course.grader.grade missing)"]
    sols = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
    if not sols:
        return lines + [f"{NA} (no solution notebook to grade)"]
    copies = max(2, int(args.grade_copies))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        nbs, warm, subs = tmp / "notebooks", tmp / "warm", tmp / "subs"
        for d in (nbs, warm, subs):
            d.mkdir()
        for sol in sols:  # one consistent version of the notebooks, and their references cached by a warm-up run
            shutil.copy(sol, nbs / sol.name)
            shutil.copy(sol, warm / sol.name)
        for i in range(copies):
            shutil.copy(nbs / sols[i % len(sols)].name, subs / f"student_{i + 1:03d}.ipynb")
        env = dict(os.environ, KINLIB_GRADER_SECRET=str(tmp / "secret"))
        runs = []
        try:
            for src, out in ((warm, "out0"), (subs, "out")):
                p = subprocess.run(
                    [sys.executable, "-c", _GRADE_RUN, str(src), str(nbs), str(tmp / "cache"), str(tmp / out)],
                    capture_output=True,
                    text=True,
                    timeout=args.grade_timeout,
                    cwd=ROOT,
                    env=env,
                )
                if p.returncode != 0:
                    return lines + [f"error (exit {p.returncode}): `{p.stderr.strip()[-300:]}`"]
                runs.append(json.loads(p.stdout.strip().splitlines()[-1]))
        except subprocess.TimeoutExpired:
            return lines + [f"did not finish in {args.grade_timeout:.0f} s"]
    first, r = runs
    graded = r["seconds"] - r["reference_seconds"]
    per_wall, per_cpu = graded / r["n"], r["cpu"] / r["n"]
    est_here = 200 * per_wall
    est_idle = 200 * per_cpu / 2  # two kernels at once on two idle cores
    counts = {st: r["rows"].count(st) for st in sorted(set(r["rows"]))}
    statuses = ", ".join(f"{n} {st}" for st, n in counts.items())  # solutions: all pass, manual parts pending
    rows = [
        [f"{len(sols)} notebooks, references not yet cached", fmt_t(first["seconds"]), "—", "—"],
        [
            f"{r['n']} workbooks (copies of the {len(sols)} solutions), --jobs 2",
            fmt_t(r["seconds"]),
            f"{fmt_t(per_wall)} wall, {fmt_t(per_cpu)} CPU each; rows: {statuses}; "
            f"{r['infrastructure']} infrastructure errors; sandbox {'on' if r['sandbox'] else 'OFF'}",
            "—",
        ],
    ]
    if r["n"] >= 200:  # the target's batch itself: its wall time is the measurement (the estimate is shown too)
        rows += [
            [
                f"{r['n']} workbooks, measured (load as reported below)",
                fmt_t(r["seconds"]),
                "≤ 8 min",
                targets.upper("grade 200 workbooks, sandboxed, 2 cores", r["seconds"], T_GRADE_200),
            ],
            ["200 workbooks on 2 idle cores, from the CPU time used", fmt_t(est_idle), "≤ 8 min", "(reported)"],
        ]
    else:
        rows += [
            ["200 workbooks, from the wall time here (load as measured)", fmt_t(est_here), "≤ 8 min", "(reported)"],
            [
                "200 workbooks on 2 idle cores, from the CPU time used",
                fmt_t(est_idle),
                "≤ 8 min",
                targets.upper("grade 200 workbooks, sandboxed, 2 cores", est_idle, T_GRADE_200),
            ],
        ]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return (
        lines
        + table(["batch", "wall time", "per workbook", "target"], rows)
        + [
            "",
            f"Load average during the run: {load:.1f} on {os.cpu_count()} cores (a shared machine: the wall-time "
            "figures are indicative; the CPU-time estimate does not depend on the load).",
        ]
    )


def import_section(args, targets: Targets) -> list[str]:
    code = "import time; t = time.perf_counter(); import kinlib; print(time.perf_counter() - t, time.process_time())"
    times = []
    for _ in range(max(5, args.reps)):
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd="/")
        times.append([float(x) for x in p.stdout.split()])
    wall = statistics.median(t[0] for t in times)
    cpu = statistics.median(t[1] for t in times)  # CPU time of the whole process up to the end of the import
    return ["## `import kinlib` (fresh interpreter, median of several)", ""] + table(
        ["what", "wall time", "CPU time (interpreter start included)", "target", "status (CPU time)"],
        [["import kinlib", fmt_t(wall), fmt_t(cpu), "≤ 0.6 s", targets.upper("import kinlib", cpu, T_IMPORT)]],
    )


# --- main ------------------------------------------------------------------------------------------
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--out", type=Path, default=ROOT / "build" / "bench.md", help="markdown report (default build/bench.md)"
    )
    ap.add_argument("--reps", type=int, default=7, help="timeit repetitions (median taken; default 7)")
    ap.add_argument("--batch", type=int, default=100_000, help="configurations in a batch (default 100000)")
    ap.add_argument("--mr-batch", type=int, default=200, help="configurations in modern-robotics' batch loop")
    ap.add_argument("--pin-batch", type=int, default=10_000, help="configurations in Pinocchio's batch loop")
    ap.add_argument("--singular-timeout", type=float, default=60.0)
    ap.add_argument("--grade-timeout", type=float, default=1800.0)
    ap.add_argument(
        "--grade-copies", type=int, default=200, help="workbooks in the grading batch (default 200: the target's size)"
    )
    ap.add_argument("--moves", type=int, default=20, help="slider moves per explorer in the browser (default 20)")
    ap.add_argument("--quick", action="store_true", help="tiny batch; skip notebooks, explorers and the checker")
    ap.add_argument(
        "--only",
        default="",
        help="comma-separated sections to run, e.g. --only urdf,numeric (names: numeric, urdf, first_call, symbolic, "
        "exact, singular-poses, analysis, notebook, explorer, browser, static, lite, grader, import; default: all)",
    )
    args = ap.parse_args(argv)
    if args.quick:
        args.batch = min(args.batch, 2000)
        args.mr_batch = min(args.mr_batch, 20)
        args.pin_batch = min(args.pin_batch, 200)
    args.mr_batch = min(args.mr_batch, args.batch)
    args.pin_batch = min(args.pin_batch, args.batch)

    t_start = time.perf_counter()
    targets = Targets()
    head = machine()
    sections = []
    for fn in (
        numeric_section,
        urdf_section,
        first_call_section,
        symbolic_section,
        exact_section,
        singular_poses_section,
        analysis_section,
        notebook_section,
        explorer_section,
        browser_section,
        static_section,
        lite_section,
        grader_section,
        import_section,
    ):
        if args.only and fn.__name__.removesuffix("_section") not in args.only.replace("-", "_").split(","):
            continue
        t0 = time.perf_counter()
        sections.append(fn(args, targets))
        print(f"[bench] {fn.__name__}: {time.perf_counter() - t0:.1f} s", file=sys.stderr, flush=True)
    met = [t for t in targets.items if t[1]]
    missed = [t for t in targets.items if not t[1]]
    summary = ["## Targets", "", f"{len(met)} of {len(targets.items)} targets met."]
    if missed:
        summary += ["", "Missed or not measured:", ""] + [f"- {w}: {m}" for w, _, m in missed]
    total = time.perf_counter() - t_start
    doc = (
        [
            "# kinlib benchmark",
            "",
            f"`python bench/bench.py` ({'--quick, ' if args.quick else ''}"
            f"medians of {args.reps} timeit runs; whole run {total:.0f} s). In-process figures are this "
            f"thread's CPU time (`time.thread_time`: on a shared machine, what the code costs, while wall time "
            f"also counts the time other processes hold the core); notebook executions and the checker are "
            f"wall time (they run kernels in other processes).",
            "",
        ]
        + head
        + [""]
        + summary
        + [""]
    )
    for s in sections:
        doc += s + [""]
    text = "\n".join(doc)
    print(text)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(text, encoding="utf-8")
    print(f"[bench] wrote {args.out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
