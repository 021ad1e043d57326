"""The grader's sandbox and key (kinlib.course.grader.isolation.sandbox, secret, refdata, wire): each attack of issue 14 kept.

A batch of hostile submissions (an unanswered workbook plus one attack cell from tests/fixtures/grade/attacks)
is graded once, sandboxed, two at a time. Each attack must gain nothing (every part still fails, and the
attack cell saw nothing it looked for) and leave nothing behind (no process of the batch alive afterwards,
grades.csv and the feedback unchanged, no file written outside the scratch folder). Controls show the attacks
are real: the same solution-reading cell passes everything without the sandbox, and an answer built to agree
at the public (file-hash) points passes when the grader uses those points.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import re
import shutil
import socket
import sys
import threading
import time
from pathlib import Path

import pytest

from kinlib.course.answers import describe, wire
from kinlib.course.cli import main
from kinlib.course.grader import grade, refdata
from kinlib.course.grader.isolation import sandbox
from kinlib.course.grader.isolation.kernel import Kernel
from kinlib.course.grader.refdata import reference_description
from kinlib.course.grader.secret import evaluation_seed, load_secret, sign

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "grade"
REF = FIX / "notebooks" / "90_grade_fixture.ipynb"
WB = FIX / "workbooks" / "90_grade_fixture.ipynb"
ATTACKS = FIX / "attacks"
PARTS = ["1.1", "1.2", "1.3", "1.4", "1.5"]
MARK = "g1" + os.urandom(6).hex()
ROOT = Path(__file__).resolve().parents[2]


def _load(p):
    return json.loads(Path(p).read_text())


def _code(src):
    return {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}


def _workbook(end=(), replace=None) -> dict:
    """The unanswered workbook, with ``replace`` = {part: source} for some answer cells and cells ``end`` appended."""
    wb = _load(WB)
    for c in wb["cells"]:
        part = c["metadata"].get("kinlib", {}).get("part")
        if replace and part in replace and "solution" in c["metadata"].get("tags", []):
            c["source"] = replace[part]
    wb["cells"] += [_code(s) for s in end]
    return wb


def _attack(name, **subs) -> str:
    src = (ATTACKS / f"{name}.py").read_text().replace("@MARK@", MARK)
    for k, v in subs.items():
        src = src.replace(f"@{k}@", str(v))
    return src


def _marked_processes() -> list[int]:
    """PIDs of live processes whose command line carries this run's MARK (the daemon attack's)."""
    found = []
    for d in os.listdir("/proc"):
        if d.isdigit() and int(d) != os.getpid():
            try:
                with open(f"/proc/{d}/cmdline", "rb") as f:
                    if MARK.encode() in f.read():
                        found.append(int(d))
            except OSError:
                pass
    return found


def _outside_files() -> list[Path]:
    import kinlib

    return [
        Path(kinlib.__file__).parent / f"pwned-{MARK}.txt",
        Path(sys.prefix) / f"pwned-{MARK}.txt",
        Path(f"/tmp/pwned-{MARK}.txt"),
        Path(f"/etc/pwned-{MARK}.txt"),
        Path(f"/pwned-{MARK}.txt"),
        Path(f"/tmp/kinlib-attack-{MARK}.alive"),
        Path(os.path.expanduser("~")) / f"pwned-{MARK}.txt",
    ]


class _Listener:
    """A TCP server on the host's loopback that records every connection (the network attack's target)."""

    def __init__(self):
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(5)
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.connections = 0
        self.stop = False
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        while not self.stop:
            try:
                conn, _ = self.sock.accept()
                self.connections += 1
                conn.close()
            except OSError:
                pass

    def close(self):
        self.stop = True
        self.thread.join(5)
        self.sock.close()


def _cleanup():
    for pid in _marked_processes():
        try:
            os.kill(pid, 9)
        except OSError:
            pass
    for p in _outside_files():
        p.unlink(missing_ok=True)


@pytest.fixture(scope="module")
def attacked(tmp_path_factory, grader_reference_cache):
    ok, why = sandbox.check()
    assert ok, f"the grader's sandbox does not work here: {why} (make test installs bubblewrap)"
    d = tmp_path_factory.mktemp("attacks")
    listener = _Listener()
    names = ["read_solutions", "eval_cache", "daemon", "network", "write_outside"]
    for name in names:
        nb = _workbook(end=[_attack(name, PORT=listener.port)])
        (d / f"{name}.ipynb").write_text(json.dumps(nb))
    out = tmp_path_factory.mktemp("attack-grades")
    try:
        summary = grade.grade_batch(
            [d], out, jobs=2, timeout=180, cell_timeout=60, notebooks=FIX / "notebooks", cache=grader_reference_cache,
            log=None,
        )  # fmt: skip
        snapshot = {p: p.read_bytes() for p in [out / "grades.csv", *sorted((out / "feedback").glob("*.md"))]}
        ended = time.monotonic()
        survivors = _marked_processes()  # the daemon's command line carries MARK: none alive, none can rewrite
        if survivors:
            time.sleep(3)  # let it show what it would do (rewrite the files): the tests report it
        res = {Path(r["submission"]).stem: r for r in summary["results"]}
        yield {
            "summary": summary,
            "res": res,
            "out": out,
            "snapshot": snapshot,
            "ended": ended,
            "listener": listener,
            "survivors": survivors + [p for p in _marked_processes() if p not in survivors],
            "outside": [p for p in _outside_files() if p.exists()],
        }
    finally:
        listener.close()
        _cleanup()


def _statuses(res):
    return {r["part"]: r["status"] for r in res["rows"]}


def _last_cell(res):
    return res["cells"][-1]


# ---------------------------------------------------------------------------------------- attacks in a batch


@pytest.mark.slow
def test_the_batch_ran_sandboxed_without_infrastructure_errors(attacked):
    s = attacked["summary"]
    assert s["sandbox"] and s["infrastructure_errors"] == 0
    assert all(r["sandbox"] and r.get("namespaces") for r in s["results"])


@pytest.mark.slow
def test_reading_the_solution_notebooks_gains_nothing(attacked):
    r = attacked["res"]["read_solutions"]
    assert _statuses(r) == dict.fromkeys(PARTS, "fail"), r["rows"]
    cell = _last_cell(r)
    assert cell["ename"] == "FileNotFoundError", cell  # the attack ran and found no notebook folder
    assert "notebooks" not in cell["evalue"] and "tests" not in cell["evalue"]


@pytest.mark.slow
def test_evaluating_the_cache_gains_nothing(attacked):
    r = attacked["res"]["eval_cache"]
    assert _statuses(r) == dict.fromkeys(PARTS, "fail"), r["rows"]
    assert _last_cell(r)["ename"] == "FileNotFoundError", _last_cell(r)


@pytest.mark.slow
def test_a_daemon_does_not_outlive_the_batch_nor_rewrite_results(attacked):
    r = attacked["res"]["daemon"]
    assert _last_cell(r)["status"] == "ok"  # the daemon was started
    assert _statuses(r) == dict.fromkeys(PARTS, "fail")
    assert attacked["survivors"] == [] and _marked_processes() == []
    for p, data in attacked["snapshot"].items():
        assert p.read_bytes() == data, f"{p.name} changed after the batch"
    assert "pwned" not in (attacked["out"] / "grades.csv").read_text()
    assert not Path(f"/tmp/kinlib-attack-{MARK}.alive").exists()  # its /tmp was the sandbox's own


@pytest.mark.slow
def test_no_network_from_the_kernel(attacked):
    cell = _last_cell(attacked["res"]["network"])
    assert cell["ename"] == "RuntimeError" and "connected" not in cell["evalue"], cell
    assert attacked["listener"].connections == 0


@pytest.mark.slow
def test_no_writes_outside_the_scratch_folder(attacked):
    cell = _last_cell(attacked["res"]["write_outside"])
    assert cell["ename"] == "RuntimeError", cell
    written = [x for x in cell["evalue"].split("; ") if x.endswith(": written")]
    assert all(x.startswith("/tmp/") for x in written), written  # only the sandbox's private tmpfs
    assert attacked["outside"] == []


# ---------------------------------------------------------------------------------------- controls


@pytest.mark.slow
def test_control_without_the_sandbox_reading_the_solutions_passes(tmp_path, grader_reference_cache):
    """The solution-reading attack is real: without the sandbox it scores everything (and the result says so)."""
    refs = grade.load_references(FIX / "notebooks", grader_reference_cache, secret=load_secret())
    sub = tmp_path / "read_solutions.ipynb"
    sub.write_text(json.dumps(_workbook(end=[_attack("read_solutions")])))
    res = grade.grade_submission(sub, refs, cell_timeout=60, sandbox=False)
    assert _statuses(res) == dict.fromkeys(PARTS, "pass"), res["rows"]
    assert res["sandbox"] is False and "WITHOUT the sandbox" in res["notes"][0]


def _right_detj_source() -> str:
    ref = _load(REF)
    cell = next(c for c in ref["cells"] if c["metadata"].get("kinlib", {}).get("part") == "1.2")
    lines = "".join(cell["source"]).replace("detJ = ", "right = ").splitlines()
    return "\n".join(x for x in lines if x.strip() != "detJ")  # no bare display line


def _points_attack(symbols: dict) -> str:
    """Part 1.2 answered wrong everywhere but at the points a public seed (the file's SHA-256) would give."""
    return (
        _right_detj_source()
        + "\nimport hashlib, pathlib\nfrom kinlib.course.grader.grade import make_points\n"
        + "data = next(pathlib.Path.cwd().glob('*.ipynb')).read_bytes()\n"
        + "pts = make_points("
        + repr(symbols)
        + ", int(hashlib.sha256(data).hexdigest()[:15], 16), 5)\n"
        + "detJ = right + L * sp.Mul(*[(th2 - sp.Rational(p['theta2'])) for p in pts])\n"
    )


@pytest.mark.slow
def test_evaluation_points_depend_on_the_secret_not_the_file_alone(tmp_path, monkeypatch, grader_reference_cache):
    key = load_secret()
    data = WB.read_bytes()
    public = int(hashlib.sha256(data).hexdigest()[:15], 16)
    assert evaluation_seed(key, data) != public
    assert evaluation_seed(key, data) != evaluation_seed(os.urandom(32).hex().encode(), data)
    refs = grade.load_references(FIX / "notebooks", grader_reference_cache, secret=key)
    ref = refs["90_grade_fixture"]
    symbols = {n: v for a in ref.answers.values() for n, v in a.get("symbols", {}).items()}
    sub = tmp_path / "points.ipynb"
    sub.write_text(json.dumps(_workbook(replace={"1.2": _points_attack(symbols)})))
    honest = grade.grade_submission(sub, refs, cell_timeout=60, secret=key)
    assert _statuses(honest)["1.2"] == "fail", honest["rows"]
    # control: had the points been the public function of the file, the wrong answer would have passed
    monkeypatch.setattr(grade, "evaluation_seed", lambda k, d: int(hashlib.sha256(d).hexdigest()[:15], 16))
    fooled = grade.grade_submission(sub, refs, cell_timeout=60, secret=key)
    assert _statuses(fooled)["1.2"] == "pass", fooled["rows"]


# ---------------------------------------------------------------------------------------- the key as data


def _no_dummies(answers) -> str:
    return re.sub(r'(\["Dummy", "[^"]*", \{[^}]*\}, )\d+', r"\1", json.dumps(answers, sort_keys=True))


@pytest.mark.slow
def test_a_poisoned_cache_is_rejected_and_nothing_runs_in_the_grader(tmp_path, grader_reference_cache):
    key = load_secret()
    fresh = grade.load_references(FIX / "notebooks", grader_reference_cache, secret=key)["90_grade_fixture"]
    cache = tmp_path / "cache"  # a copy of the run's cache, poisoned here
    cache.mkdir()
    for f in grader_reference_cache.glob("90_grade_fixture-*.json"):
        shutil.copy(f, cache)
    (cfile,) = cache.glob("*.json")
    marker = tmp_path / "payload-ran"
    payload = f"__import__('os').system('touch {marker}')"
    good = json.loads(cfile.read_text())

    def poisoned(mac, answer=None):
        d = copy.deepcopy(good)
        d["reference"]["answers"]["Js"] = answer or {"kind": "expr", "tree": ["sin", ["str", payload]], "symbols": {}}
        d["mac"] = mac(d["reference"])
        cfile.write_text(json.dumps(d))

    canonical = lambda r: json.dumps(r, sort_keys=True, separators=(",", ":"), ensure_ascii=True).encode()
    for forge in (
        lambda r: good["mac"],  # edited, old tag kept
        lambda r: hashlib.sha256(canonical(r)).hexdigest(),  # a tag without the secret
        lambda r: sign(os.urandom(32).hex().encode(), "kinlib-reference-cache", canonical(r)),  # another secret
    ):
        poisoned(forge)
        logs = []
        ref = grade.load_references(FIX / "notebooks", cache, secret=key, log=logs.append)["90_grade_fixture"]
        assert _no_dummies(ref.answers) == _no_dummies(fresh.answers) and "does not verify" in " ".join(logs)
        assert not marker.exists()
    # even a correctly signed payload (a leaked secret), or an older version's srepr text, is data that the one
    # parser refuses: the cache is rebuilt, nothing runs
    signed = lambda r: sign(key, "kinlib-reference-cache", canonical(r))
    for answer in (None, {"kind": "expr", "srepr": payload, "symbols": {}}):
        poisoned(signed, answer)
        ref = grade.load_references(FIX / "notebooks", cache, secret=key)["90_grade_fixture"]
        assert _no_dummies(ref.answers) == _no_dummies(fresh.answers)
        assert "tree" in ref.answers["Js"] and "srepr" not in ref.answers["Js"]
        assert not marker.exists()
    bad = grade.Reference("n", "t", "p", "0", [], {"Js": {"kind": "expr", "tree": ["sin", ["str", payload]]}})
    with pytest.raises(wire.WireError, match="takes SymPy values"):
        reference_description(bad, "Js", "expr", [{"L": 1.0, "theta1": 0.1, "theta2": 0.2, "theta3": 0.3}], 0)
    assert not marker.exists()


CODE = '__import__("os").system("true")'


@pytest.mark.parametrize(
    "tree",
    [
        ["str", CODE],
        ["Matrix", 1, 1, ["str", CODE]],  # SymPy would sympify (eval) this
        ["Tuple", ["str", "x"]],
        ["Symbol", "x').__class__", {}],
        ["Symbol", "__class__", {}],
        ["Float", "1e5; import os", 53],
        ["Symbol", "x", {"a": 1}],
        ["UndefinedFunction", "exec", ["Symbol", "x", {}]],
        ["Add", ["list", ["Integer", "1"]]],
        ["Lambda", ["str", "x"], ["str", CODE]],
        ["call", "__import__", "os"],
        "Integer(1)",  # an older cache's srepr text
    ],
)
def test_a_reference_tree_is_read_as_data_never_evaluated(tree):
    """A cache entry that is not a tree the one parser reads is refused: the cache is not in format (rebuilt)."""
    ref = grade.Reference("n", "t", "p", "0", [], {"a": {"kind": "expr", "tree": tree, "symbols": {}}})
    with pytest.raises(wire.WireError):
        refdata.reference_value(ref, "a")
    assert not refdata.in_format(ref)


def test_reference_values_round_trip_exactly_through_the_wire_format():
    """The answer key keeps each reference as a wire tree (describe.dump_reference) only when it reads back
    structurally equal; every form the course's answers take does (the real key: test_the_real_answer_key_...)."""
    import sympy as sp

    th, n = sp.Symbol("theta2", real=True), sp.Dummy("n", integer=True)
    L = sp.Symbol("L", positive=True)
    for obj in [
        sp.Matrix([[sp.cos(th), sp.Rational(-1, 2)], [sp.pi, sp.Float(0.25)]]),
        sp.ImmutableMatrix([[L * sp.Float("0.1", 200), sp.sqrt(2) * L**2 * sp.Abs(sp.sin(th + sp.pi / 4))]]),
        {th: sp.ImageSet(sp.Lambda(n, sp.pi / 2 + n * sp.pi), sp.S.Integers)},
        sp.Union(sp.ImageSet(sp.Lambda(n, 2 * n * sp.pi + sp.pi / 4), sp.S.Integers), sp.FiniteSet(0, sp.pi)),
        [{th: sp.FiniteSet(0, sp.pi)}, {th: sp.Interval(0, 1, True)}],
        sp.S.EmptySet,
        sp.ConditionSet(th, sp.Eq(sp.sin(th), 0), sp.S.Reals),
        sp.Function("f")(th) + sp.oo * sp.I,
        {"case_a": sp.Matrix([[1, th]]), "case_b": sp.Integer(0)},  # answers keyed by name (4.1)
        sp.FiniteSet(sp.ImmutableMatrix([1, 2])),
    ]:
        assert describe.same_reference(wire.load(wire.dump(obj)), obj), obj
    kinds = {"J": "expr", "S": "set", "cases": "expr"}
    ns = {"J": sp.Matrix([[L * sp.cos(th)]]), "S": {th: sp.ImageSet(sp.Lambda(n, n * sp.pi), sp.S.Integers)}}
    ns["cases"] = {"a": sp.Matrix([[1, th]]), "b": 0}
    dumped = describe.dump_reference(ns, kinds)
    ref = grade.Reference("n", "t", "p", "0", [], dumped)
    for name in kinds:
        assert set(dumped[name]) == {"kind", "tree", "symbols"}, dumped[name]
        want = describe.normalize_reference(kinds[name], ns[name])
        assert describe.same_reference(refdata.reference_value(ref, name), want), name


@pytest.mark.slow
def test_the_real_answer_key_round_trips_through_the_wire_format(grader_reference_cache):
    """Every reference answer of every solution notebook is kept (dump_reference keeps one only when its wire tree
    reads back structurally equal to the solution's value, else the answer is an error) and reads back."""
    refs = grade.load_references(ROOT / "notebooks", grader_reference_cache, secret=load_secret(), jobs=2)
    assert refs
    for nid, ref in refs.items():
        assert not ref.error, (nid, ref.error)
        for name, a in ref.answers.items():
            assert "error" not in a and "srepr" not in a, (nid, name, a)
            if "tree" in a:
                value = refdata.reference_value(ref, name)
                assert describe.same_reference(wire.load(wire.dump(value)), value), (nid, name)


def test_the_secret_file_is_private_and_refused_when_not(tmp_path):
    p = tmp_path / "dir" / "grader-secret"
    key = load_secret(p)
    assert oct(p.stat().st_mode & 0o777) == "0o600" and load_secret(p) == key
    p.chmod(0o644)
    with pytest.raises(ValueError, match="chmod 600"):
        load_secret(p)


# ---------------------------------------------------------------------------------------- sandbox policy


def test_the_sandbox_refuses_to_expose_a_hidden_folder():
    import kinlib

    sb = sandbox.Sandbox(hidden=[str(Path(kinlib.__file__).parent / "course")])
    with pytest.raises(sandbox.SandboxUnavailable, match="would expose"):
        sb.command(["true"], cwd="/tmp", rw=[], env={})
    argv = sandbox.Sandbox(hidden=[str(ROOT / "notebooks"), str(FIX)]).command(["true"], cwd="/tmp", rw=[], env={})
    binds = {argv[i + 1] for i, a in enumerate(argv) if a in ("--ro-bind", "--bind")}
    assert not any(str(ROOT / x) in binds for x in ("notebooks", "tests", "build", ""))
    assert {"--unshare-all", "--die-with-parent", "--clearenv"} <= set(argv)


def test_no_sandbox_must_be_asked_for(tmp_path, monkeypatch, capsys):
    bad = tmp_path / "x.ipynb"
    bad.write_text("{ not json")
    monkeypatch.setattr(grade, "check", lambda: (False, "bubblewrap (bwrap) is not installed"))
    with pytest.raises(grade.SandboxUnavailable, match="--no-sandbox"):
        grade.grade_batch([bad], tmp_path / "o", notebooks=FIX / "notebooks", cache=None, log=None)
    args = ["grade", str(bad), "--out", str(tmp_path / "o"), "--notebooks", str(FIX / "notebooks")]
    args += ["--cache", str(tmp_path / "cache")]
    assert main(args) == 2
    assert "--no-sandbox" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()
    assert main(args + ["--no-sandbox"]) == 0
    out = capsys.readouterr().out
    assert "without the sandbox" in out.lower()
    (fb,) = (tmp_path / "o" / "feedback").glob("*.md")
    assert "without the sandbox" in fb.read_text().lower()


# ---------------------------------------------------------------------------------------- start-up and liveness


class _FlakySandbox(sandbox.Sandbox):
    """A sandbox whose first ``fail`` starts fail (the process exits at once), like a loaded machine's worst case."""

    fail = 1
    calls = 0

    def command(self, argv, cwd, rw, env, info_fd=None):
        if info_fd is None:  # not a kernel: the submission's judge process (judging.JudgeProcess)
            return super().command(argv, cwd, rw, env, info_fd)
        type(self).calls += 1
        if type(self).calls <= self.fail:
            return [sys.executable, "-c", "import sys; sys.exit(3)"]
        return super().command(argv, cwd, rw, env, info_fd)


@pytest.mark.slow
def test_a_failed_kernel_start_is_retried(tmp_path):
    _FlakySandbox.calls, _FlakySandbox.fail = 0, 1
    k = Kernel(cwd=str(tmp_path), conn_dir=str(tmp_path), sandbox=_FlakySandbox())
    try:
        k.start()
        assert k.start_failures == 1 and k.alive()
        assert k.run("x = 6 * 7", timeout=60).status == "ok"
        record = k.record
    finally:
        k.kill()
    assert record is not None and sandbox.namespace_processes([record]) == []


def test_a_kernel_that_never_starts_is_an_infrastructure_error(tmp_path, monkeypatch, capsys):
    _FlakySandbox.calls, _FlakySandbox.fail = 0, 10**6
    sub = tmp_path / "s.ipynb"
    sub.write_text(json.dumps(_workbook()))
    parts = [{"part": p, "points": 5.0, "answers": [f"a{k}"], "kinds": {f"a{k}": "expr"}} for k, p in enumerate(PARTS)]
    answers = {f"a{k}": {"kind": "expr", "tree": ["Integer", "1"], "symbols": {}} for k in range(len(PARTS))}
    refs = {"90_grade_fixture": grade.Reference("90_grade_fixture", "t", "p", "0" * 64, parts, answers)}
    res = grade.grade_submission(sub, refs, sandbox=_FlakySandbox())
    assert {r["status"] for r in res["rows"]} == {"error"}
    assert all(r["message"].startswith("not graded: infrastructure") for r in res["rows"]), res["rows"]
    assert res["infrastructure"] and _FlakySandbox.calls == 3
    # the command line says so with a nonzero exit status (never 0 points silently)
    monkeypatch.setattr(grade, "Sandbox", _FlakySandbox)
    monkeypatch.setattr(grade, "load_references", lambda *a, **k: refs)
    args = ["grade", str(sub), "--out", str(tmp_path / "o"), "--notebooks", str(FIX / "notebooks"), "--jobs", "1"]
    assert main(args) == 1
    assert "infrastructure" in capsys.readouterr().err


class _SlowSandbox(sandbox.Sandbox):
    """A sandbox that takes seconds to come up (as on a machine with both cores busy)."""

    def command(self, argv, cwd, rw, env, info_fd=None):
        return ["sh", "-c", 'sleep 6; exec "$@"', "sh"] + super().command(argv, cwd, rw, env, info_fd)


@pytest.mark.slow
def test_a_slow_kernel_start_is_waited_for_not_judged_dead(tmp_path):
    k = Kernel(cwd=str(tmp_path), conn_dir=str(tmp_path), sandbox=_SlowSandbox())
    try:
        k.start()
        assert k.start_failures == 0 and k.alive()
        assert k.run("import os; x = os.getpid()", timeout=60).status == "ok"
    finally:
        k.kill()
    assert sandbox.namespace_processes([k.record]) == []


@pytest.mark.skipif(not sandbox.check()[0], reason="bubblewrap cannot run here")
def test_an_environment_under_tmp_stays_visible(tmp_path, monkeypatch):
    """The private /tmp must not cover what is bound read-only: a checkout (its .venv and kinlib) in a
    ``mktemp -d`` folder, as CI's fresh clone can be. Here a folder under the host's /tmp stands in for it."""
    env_dir = tmp_path / "fresh" / ".venv"
    env_dir.mkdir(parents=True)
    (env_dir / "marker").write_text("visible")
    real = sandbox.system_binds
    monkeypatch.setattr(sandbox, "system_binds", lambda: real() + ["--ro-bind", str(env_dir), str(env_dir)])
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    argv = sandbox.Sandbox().command(
        [os.path.realpath(sys.executable), "-I", "-c", f"print(open({str(env_dir / 'marker')!r}).read())"],
        cwd=str(scratch),
        rw=[str(scratch)],
        env=sandbox.Sandbox().environment({}),
    )
    import subprocess

    p = subprocess.run(argv, capture_output=True, text=True, timeout=60)
    assert p.returncode == 0 and p.stdout.strip() == "visible", p.stderr
