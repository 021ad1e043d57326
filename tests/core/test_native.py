"""The compiled C path of the single call (kinlib.native, issue 25): the same numbers as the Python code of the
same cse'd pieces, for every arm of kinlib.robots and three real URDF arms, against modern_robotics and finite
differences; the same argument checks; the cache (shared by processes, written atomically) and the fallbacks.

Compiled once per test session into a temporary cache (``KINLIB_CACHE``); no test asserts a time."""

from __future__ import annotations

import os
import sys
import threading
from pathlib import Path

import modern_robotics as mr
import numpy as np
import pytest
import sympy as sp

from kinlib import native, robots
from kinlib.codegen import CompiledMatrix

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import urdf_arms  # noqa: E402  (bench/urdf_arms.py: the iiwa14's URDF, the Panda's and UR5's joint tables)

WHAT = ("fk", "js", "jb", "jg")


@pytest.fixture(scope="session", autouse=True)
def private_cache(tmp_path_factory):
    """Every compile of this module goes into a temporary cache; KINLIB_COMPILE=0 in the environment skips."""
    if os.environ.get("KINLIB_COMPILE", "1").strip() in ("0", "no", "false", "off"):
        pytest.skip("KINLIB_COMPILE=0: the compiled path is switched off")
    old = os.environ.get("KINLIB_CACHE")
    os.environ["KINLIB_CACHE"] = str(tmp_path_factory.mktemp("kinlib-cache"))
    argv, why = native.toolchain()
    assert argv is not None, f"no C toolchain ({why}): `make setup` installs gcc where it is missing"
    yield Path(os.environ["KINLIB_CACHE"])
    if old is None:
        os.environ.pop("KINLIB_CACHE", None)
    else:
        os.environ["KINLIB_CACHE"] = old


def _arms():
    arms = [
        robots.ur5(),
        robots.planar_2r(1, 1),
        robots.planar_3r(1, 0.5, 0.25),
        robots.planar_offset_3r(1),
        robots.spatial_rppr(1, 2),
        robots.cart_pole(1, 0.5),
        robots.planar_rpp(1),
    ]
    arms.append(robots.from_urdf_joints(urdf_arms.urdf_joints(urdf_arms.IIWA14_URDF, "iiwa_link_ee")[0], name="iiwa14"))
    arms.append(robots.from_urdf_joints(urdf_arms.PANDA_JOINTS, name="panda"))
    arms.append(robots.from_urdf_joints(urdf_arms.UR5_JOINTS, name="ur5_urdf"))
    return arms


ARMS = _arms()


def _compiled(chain, what):
    c = chain.numeric_code(what)
    assert c.compile_native(), c.native_status
    assert c.native_status.startswith("C"), c.native_status
    return c


@pytest.mark.parametrize("chain", ARMS, ids=lambda c: c.name)
def test_compiled_equals_the_python_code_and_the_references(chain):
    rng = np.random.default_rng(sum(map(ord, chain.name)))
    n = chain.n
    Q = rng.uniform(-np.pi, np.pi, (25, n))
    # the UR5 and the iiwa14: all four quantities; the others: the geometric J (a compile costs ≈ 0.3 s)
    whats = WHAT if chain.name in ("ur5", "iiwa14") else ("jg",)
    python = {w: [chain.numeric_code(w)._single(list(q)) for q in Q] for w in whats}  # before compiling
    for w in whats:
        _compiled(chain, w)
    M = np.array(chain.M, dtype=float)
    S = np.array(chain.screws, dtype=float)
    B = np.array(chain.body_screws, dtype=float)
    for k, q in enumerate(Q):
        got = {
            w: getattr(
                chain, {"fk": "fk", "js": "jacobian_space", "jb": "jacobian_body", "jg": "jacobian_geometric"}[w]
            )(q)
            for w in whats
        }
        for w in whats:
            assert got[w].dtype == np.float64 and got[w].shape == python[w][k].shape
            # the same operations in the same order in IEEE doubles, the same libm: the Python code's floats exactly
            np.testing.assert_array_equal(got[w], python[w][k])
        T = mr.FKinSpace(M, S, q)
        Jb = mr.JacobianBody(B, q)
        Jg = np.vstack([T[:3, :3] @ Jb[:3], T[:3, :3] @ Jb[3:]])
        np.testing.assert_allclose(got["jg"], Jg, atol=1e-12)
        if "fk" in got:
            np.testing.assert_allclose(got["fk"], T, atol=1e-12)
            np.testing.assert_allclose(got["js"], mr.JacobianSpace(S, q), atol=1e-12)
            np.testing.assert_allclose(got["jb"], Jb, atol=1e-12)
    # finite differences of the tool position (central, h = 1e-6) give the geometric J's rows ṗ
    q, h = Q[0], 1e-6
    fd = np.column_stack(
        [(mr.FKinSpace(M, S, q + h * e)[:3, 3] - mr.FKinSpace(M, S, q - h * e)[:3, 3]) / (2 * h) for e in np.eye(n)]
    )
    np.testing.assert_allclose(chain.jacobian_geometric(q)[3:], fd, atol=1e-7)
    # every way of giving a plain joint vector reaches the compiled code, with the same floats
    c = chain.numeric_code("jg")
    ref = c._fast(Q[1])
    assert ref is not None
    for q in (list(Q[1]), tuple(Q[1]), [np.float64(v) for v in Q[1]], np.repeat(Q[1], 2)[::2]):
        out = c._fast(q)
        assert out is not None and np.array_equal(out, ref), type(q)
    assert np.array_equal(c._fast([0] * n), c._fast(np.zeros(n)))  # ints are numbers


def test_the_c_and_python_printers_print_the_same_operations():
    """Equal expressions, token for token (C's 1.0/x is Python's 1/x): the reason the floats agree."""
    chain = ARMS[-3]  # the iiwa14
    c = chain.numeric_code("jg")
    src = c._native.source()
    assert f"PyInit_{c._native._prepare()[1]}(void)" in src
    body = src[src.index("static void kernel") : src.index("/* 1:")]
    c_lines = [ln.split(" = ", 1)[1].rstrip(";") for ln in body.splitlines() if "const double _x" in ln]
    py_lines = [ln.split(" = ", 1)[1] for ln in c._single_source.splitlines() if ln.lstrip().startswith("_x")]
    assert c_lines and [ln.replace("1.0/", "1/") for ln in c_lines] == py_lines


def test_what_is_not_a_plain_joint_vector_goes_to_the_checked_path():
    ur5 = robots.ur5()
    c = _compiled(ur5, "jg")
    for bad in (
        [float("nan")] + [0.0] * 5,
        [0.0] * 5 + [float("inf")],
        [True] * 6,
        [0.0] * 5,
        ["0"] * 6,
        [sp.pi] * 6,
        [2**2000] + [0] * 5,
        np.zeros((2, 6)),
        np.zeros(6, dtype=">f8"),
        np.zeros(6, dtype=np.float32),
        np.array(0.0),
        memoryview(np.zeros(6)),
        0.5,
        None,
    ):
        assert c._fast(bad) is None, bad
    # and the public call still names the argument
    with pytest.raises(ValueError, match="q must hold 6 finite"):
        ur5.jacobian_geometric([float("nan")] + [0.0] * 5)
    with pytest.raises(TypeError, match="q must hold 6 real"):
        ur5.jacobian_geometric([True] * 6)
    with pytest.raises(ValueError, match=r"q must have shape \(6,\)"):
        ur5.jacobian_geometric([0.0] * 5)
    assert ur5.jacobian_geometric(np.zeros((3, 6))).shape == (3, 6, 6)  # a batch: the NumPy code
    assert isinstance(ur5.jacobian_geometric([0, sp.pi / 2, 0, 0, 0, 0]), sp.MatrixBase)  # exact values: SymPy
    assert np.array_equal(ur5.jacobian_geometric(np.zeros(6, dtype=">f8")), ur5.jacobian_geometric(np.zeros(6)))


def test_cache_is_shared_and_written_atomically(private_cache):
    x0, q0 = sp.symbols("_x0 _q0")
    pieces = ([(x0, sp.sin(q0))], [x0, 3 * x0 + 1], 1, (1, 2), "cache test")
    first = native.NativeSingle(*pieces)
    assert first.build() and "compiled into" in first.status
    _, module, path = first._prepare()
    assert path.parent == private_cache / "compiled" and path.is_file()
    # another process (simulated: this process forgets the module) loads the file instead of compiling
    native._loaded.pop(module)
    again = native.NativeSingle(*pieces)
    assert again.build() and again.status.startswith("C (loaded from")
    # processes compiling the same key at once: each writes a temporary name and os.replace-s it into place
    argv, _ = native.toolchain()
    src = again.source()
    stale = path.parent / ".build-stale"  # left by a process that ended while compiling: removed after an hour
    stale.mkdir()
    os.utime(stale, (0, 0))
    errors = []

    def compile_once():
        try:
            native._compile(argv, src, path)
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=compile_once) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert not errors and path.is_file()
    assert sorted(p.name for p in path.parent.iterdir() if p.name.startswith(".build-")) == []  # no leftovers
    assert again.fn([0.5]).tolist() == [[np.sin(0.5), 3 * np.sin(0.5) + 1]]
    # a file others can write is never loaded
    os.chmod(path, 0o666)
    native._loaded.pop(module)
    third = native.NativeSingle(*pieces)
    try:
        assert not native._safe(path)
        assert third.build() and "compiled into" in third.status  # compiled afresh, with safe permissions
    finally:
        os.chmod(path, 0o755)


def test_hot_calls_compile_in_the_background():
    x = sp.Symbol("x", real=True)
    c = CompiledMatrix(sp.Matrix([[sp.cos(x), x]]), [x])
    assert c._fast is None and c.native_status == "Python (not compiled yet)"
    for _ in range(native.HOT_CALLS - 1):
        c([0.25])
    assert c._fast is None  # the first HOT_CALLS - 1 calls never compile
    c([0.25])
    for _ in range(600):  # the background thread compiles (or loads) it; a generous guard against a hang
        if c._fast is not None:
            break
        threading.Event().wait(0.1)
    assert c._fast is not None, c.native_status
    assert c([0.25]).tolist() == [[np.cos(0.25), 0.25]]


def test_without_a_compiler_the_python_code_answers(monkeypatch):
    x = sp.Symbol("x", real=True)
    monkeypatch.setenv("KINLIB_COMPILE", "0")
    c = CompiledMatrix(sp.Matrix([[sp.sin(x)]]), [x])
    assert c.compile_native() is False and c.native_status == "Python: KINLIB_COMPILE=0"
    monkeypatch.setenv("KINLIB_COMPILE", "1")
    monkeypatch.setenv("CC", "kinlib-test-no-such-compiler")
    import shutil

    monkeypatch.setattr(shutil, "which", lambda name: None)
    c = CompiledMatrix(sp.Matrix([[sp.sin(x)]]), [x])
    assert c.compile_native() is False and "no C compiler" in c.native_status
    assert float(c([0.5])[0, 0]) == float(np.sin(0.5))
    monkeypatch.setattr(sys, "platform", "emscripten")
    assert native.toolchain() == (None, "no C compiler in the browser (Pyodide)")


def test_the_joint_tables_are_the_urdf_files():
    """bench/urdf_arms.py's Panda and UR5 tables (used above without the bench extra) are what its reader gets from
    example-robot-data's files, when that package is installed (make bench installs it)."""
    tables = {"panda": urdf_arms.PANDA_JOINTS, "ur5": urdf_arms.UR5_JOINTS}
    for name, _, get_xml, tip in urdf_arms.ARMS:
        xml = get_xml()
        if name in tables:
            if xml is None:
                pytest.skip("example-robot-data is not installed (the bench extra)")
            assert urdf_arms.urdf_joints(xml, tip)[0] == tables[name]


# --- the cache is untrusted input; the compiler cannot block (issue 32) ----------------------------------------
_BUILD = r"""
import sympy as sp
from kinlib import native
x0, q0 = sp.symbols("_x0 _q0")
ns = native.NativeSingle([(x0, sp.cos(q0))], [x0, 2 * x0 - 1], 1, (1, 2), "truncation test")
assert ns.build(), ns.status
assert ns.fn([0.5]).tolist() == [[float(sp.cos(0.5)), 2 * float(sp.cos(0.5)) - 1]]
print(ns._prepare()[2])
print(ns.status)
"""


def test_a_damaged_cached_module_is_rebuilt_and_the_process_lives(tmp_path):
    """A .so cut to 10-75 % of its size (dlopen of it kills the process with SIGBUS), one byte altered, its digest
    missing or damaged: each is rebuilt by the next process, never loaded. Every process is a child: one that
    loaded a damaged file would die (returncode -7) and fail the test, not kill this test process."""
    import subprocess

    env = {**os.environ, "KINLIB_CACHE": str(tmp_path / "cache")}

    def next_process() -> tuple[Path, str]:
        p = subprocess.run([sys.executable, "-c", _BUILD], capture_output=True, text=True, env=env, timeout=600)
        assert p.returncode == 0, (p.returncode, p.stdout, p.stderr[-2000:])
        path, status = p.stdout.strip().splitlines()[-2:]
        return Path(path), status

    path, status = next_process()
    assert status.startswith("C (compiled into"), status
    assert next_process()[1].startswith("C (loaded from"), "a sound module is loaded, not compiled again"
    good = path.read_bytes()
    digest = native._digest_path(path)
    damages = [("cut to 10 %", lambda: path.write_bytes(good[: len(good) // 10]))]
    damages += [("cut to 50 %", lambda: path.write_bytes(good[: len(good) // 2]))]
    damages += [("cut to 75 %", lambda: path.write_bytes(good[: 3 * len(good) // 4]))]
    damages += [("one byte altered", lambda: path.write_bytes(good[:999] + bytes([good[999] ^ 0xFF]) + good[1000:]))]
    damages += [("its digest missing", digest.unlink), ("its digest cut", lambda: digest.write_text("ab12"))]
    for what, damage in damages:
        damage()
        _, status = next_process()
        assert status.startswith("C (compiled into") and "failed its check and was rebuilt" in status, (what, status)
        assert native._verified(path), what


def test_a_cache_folder_others_can_write_is_not_used(tmp_path, monkeypatch):
    root = tmp_path / "shared-cache"
    (root / "compiled").mkdir(parents=True)
    os.chmod(root / "compiled", 0o777)
    monkeypatch.setenv("KINLIB_CACHE", str(root))
    x = sp.Symbol("x", real=True)
    c = CompiledMatrix(sp.Matrix([[sp.sin(x)]]), [x])
    assert c.compile_native() is False
    assert "can be written by others" in c.native_status and "compiled" in c.native_status
    assert float(c([0.5])[0, 0]) == float(np.sin(0.5))  # the Python code answers
    assert list((root / "compiled").iterdir()) == []  # nothing written there
    os.chmod(root / "compiled", 0o700)
    os.chmod(root, 0o775)  # the parent group-writable: refused too (the group could swap the folder)
    c = CompiledMatrix(sp.Matrix([[sp.sin(x)]]), [x])
    assert c.compile_native() is False and "can be written by others" in c.native_status


def _fake_compiler(tmp_path, body: str) -> Path:
    cc = tmp_path / "slowcc"
    cc.write_text("#!/bin/sh\n" + body)
    cc.chmod(0o755)
    return cc


def _ended(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(") ")[1].startswith("Z")  # a zombie waiting for init to reap it: ended
    except FileNotFoundError:
        return True


def _wait_ended(pidfile: Path) -> None:
    """Every pid written to ``pidfile`` has ended (polled for up to 30 s: the kill is immediate, reaping by init is not)."""
    pids = [int(p) for p in pidfile.read_text().split()]
    assert pids
    for _ in range(300):
        if all(_ended(p) for p in pids):
            return
        threading.Event().wait(0.1)
    raise AssertionError(f"still running: {[p for p in pids if not _ended(p)]}")


def test_a_compiler_that_hangs_is_ended_with_its_children(tmp_path, monkeypatch):
    """A compiler that never finishes (and started a child that would outlive it) is killed with its whole process
    group after COMPILE_SECONDS; compile_native() returns False with the reason, and the Python code answers. The
    limit is set to 1 s here; nothing asserts how long anything took."""
    pids = tmp_path / "pids"
    cc = _fake_compiler(
        tmp_path,
        f'if [ "$1" = --version ]; then echo fake-cc 1.0; exit 0; fi\nsleep 600 &\necho $! >> {pids}\necho $$ >> {pids}\nwait\n',
    )
    monkeypatch.setenv("CC", str(cc))
    monkeypatch.setenv("KINLIB_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(native, "COMPILE_SECONDS", 1.0)
    monkeypatch.setattr(native, "_toolchain_cache", {})
    x = sp.Symbol("x", real=True)
    c = CompiledMatrix(sp.Matrix([[sp.tan(x)]]), [x])
    assert c.compile_native() is False
    assert "did not finish in 1 s" in c.native_status, c.native_status
    _wait_ended(pids)
    assert float(c([0.5])[0, 0]) == float(np.tan(0.5))


def test_a_compiler_whose_version_probe_hangs_is_not_used(tmp_path, monkeypatch):
    pids = tmp_path / "pids"
    cc = _fake_compiler(tmp_path, f"sleep 600 &\necho $! >> {pids}\nwait\n")
    monkeypatch.setenv("CC", str(cc))
    monkeypatch.setattr(native, "PROBE_SECONDS", 1.0)
    monkeypatch.setattr(native, "_toolchain_cache", {})
    monkeypatch.setattr("sysconfig.get_config_var", lambda name: None)  # no fallback to the real compiler
    monkeypatch.setattr("shutil.which", lambda name: str(cc) if name == str(cc) else None)
    argv, why = native.toolchain()
    assert argv is None and "did not answer --version" in why and "did not finish in 1 s" in why, why
    _wait_ended(pids)
