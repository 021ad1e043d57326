"""Judging that cannot leave a worker changed or run long, by a process that holds no secret (issue 31, items 6-7).

* An answer whose judging runs past its time limit ends the process that judged it (SIGKILL; a fresh one judges
  the next answer), never an exception raised into SymPy that code can swallow.
* Big numbers are refused before SymPy computes with them (a Float with a huge exponent inside sin, nested powers).
* The judge process gets the reference and the points, never the grader secret; it runs in the sandbox (or as the
  student's user) and can neither read the secret nor write the reference cache or the output folder.
* The batch's workers get no secret either: the supervisor chooses the points.
* A kernel's malformed (signed) message or a full disk is flagged, never a silent "internal error".

Tests do not depend on timing: every limit is generous, and what is asserted is the outcome.
"""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp

from kinlib.course.answers import wire
from kinlib.course.grader import grade, judging, steps
from kinlib.course.grader.in_kernel import export as ex
from kinlib.course.grader.isolation import kernel
from kinlib.course.grader.isolation.sandbox import Sandbox, check
from kinlib.course.grader.judge import Verdict
from kinlib.course.grader.refdata import Reference, reference_answers
from kinlib.course.lms.bundles import gradescope_results

th1, th2 = sp.symbols("theta1 theta2")
L = sp.Symbol("L", positive=True)
J = sp.Matrix([[-L * sp.sin(th1), sp.cos(th1 + th2)], [L * sp.cos(th1), 1]])
POINTS = [{"theta1": 0.3, "theta2": -1.1, "L": 1.3}, {"theta1": 1.2, "theta2": 2.0, "L": 0.8}]
POINTS += [{"theta1": -2.0, "theta2": 0.4, "L": 1.7}] * 3
SANDBOXED = check()[0]


def _ref(**answers) -> Reference:
    kinds = {n: k for n, (_, k) in answers.items()}
    entry = reference_answers({n: ex.exported(v) for n, (v, _) in answers.items()}, kinds)
    return Reference("t", "t", "p", "0" * 64, [], entry)


# a stand-in judge process (tests only): ready at once, answers "pass" to every answer but one named "hang",
# on which it never answers (as a SymPy loop holding the GIL would not)
FAKE = r"""
import json, os, struct, sys, time
def send(o):
    b = json.dumps(o).encode(); os.write(1, struct.pack(">I", len(b)) + b)
def recv():
    h = sys.stdin.buffer.read(4)
    if len(h) < 4: sys.exit(0)
    return json.loads(sys.stdin.buffer.read(struct.unpack(">I", h)[0]))
recv(); send({"ready": True})
while True:
    m = recv()
    while m.get("name") == "hang":
        pass
    send({"status": "pass", "message": "", "exact": "", "wants_exact": False})
"""


def test_an_answer_past_its_limit_kills_the_judge_and_a_fresh_one_takes_the_next():
    jp = judging.JudgeProcess(_ref(), POINTS, 1, argv=[sys.executable, "-c", FAKE])
    try:
        first = jp.judge("a", "expr", {"tree": ["int", "1"]}, seconds=60)
        pid = jp.proc.pid
        hung = jp.judge("hang", "expr", {"tree": ["int", "1"]}, seconds=1)
        assert (first.status, hung.status, jp.kills) == ("pass", "fail", 1)
        assert "too large to grade" in hung.message
        assert not Path(f"/proc/{pid}").exists() or "Z" in Path(f"/proc/{pid}/stat").read_text().split()[2]
        after = jp.judge("b", "expr", {"tree": ["int", "1"]}, seconds=60)  # a new process judges the next one
        assert after.status == "pass" and jp.starts == 2 and jp.proc.pid != pid
    finally:
        jp.close()


def test_a_judge_that_cannot_start_is_an_infrastructure_error_not_a_wrong_answer(monkeypatch):
    monkeypatch.setattr(judging, "START_SECONDS", 30)
    jp = judging.JudgeProcess(_ref(), POINTS, 1, argv=[sys.executable, "-c", "import sys; sys.exit(3)"])
    v = jp.judge("a", "expr", {"tree": ["int", "1"]}, seconds=5)
    assert v.status == "error" and "infrastructure" in v.message and jp.starts == 2


def test_a_reply_is_data_only_a_known_status_is_kept():
    bad = FAKE.replace('{"status": "pass"', '{"status": "pwned", "x": "y"} or {"status": "pass"')
    jp = judging.JudgeProcess(_ref(), POINTS, 1, argv=[sys.executable, "-c", bad])
    try:
        assert jp.judge("a", "expr", {"tree": ["int", "1"]}, seconds=60).status == "error"
    finally:
        jp.close()


@pytest.mark.parametrize(
    "tree, words",
    [
        (["sin", ["Mul", ["Float", "1e1000000", 53], ["Symbol", "theta1", {}]]], "too large"),  # π to 3.3 Mbit
        (["Mul", ["Float", "1e1000", 53], ["Float", "1e1000", 53]], "too large"),  # folded as it is built
        (["Pow", ["Pow", ["Integer", "9" * 900], ["Integer", "90"]], ["Integer", "90"]], "too large"),
        (["Float", "1e-1000000", 53], "too large"),
    ],
)
def test_big_numbers_are_refused_before_sympy_computes_with_them(tree, words):
    with pytest.raises(wire.WireError, match=words):
        wire.load(tree)


def test_numbers_of_ordinary_size_still_read():
    assert wire.load(["Float", "1e300", 53]) == sp.Float("1e300", precision=53)
    assert wire.load(["Pow", ["Integer", "10"], ["Integer", "100"]]) == 10**100


def _hostile_answers():
    """The trees the issue found hostile, as a kernel would export them."""
    n = sp.Symbol("n", integer=True)
    sets = [{th2: sp.ImageSet(sp.Lambda(n, 2 * n * sp.pi + sp.Rational(k, 41)), sp.Integers)} for k in range(45)]
    f = sp.Function("f")
    return {
        "huge_float": ex.exported(sp.sin(sp.Float("1e300") * th1) * sp.Float("1e300")),
        "imagesets": ex.exported(sets),
        "undefined": ex.exported(sp.Matrix(6, 6, lambda i, j: f(th1 + i) ** (j + 1))),
        "nested": {"tree": ["Pow", ["Pow", ["Symbol", "theta1", {}], ["Integer", "99"]], ["Integer", "99"]]},
    }


@pytest.mark.slow
@pytest.mark.parametrize("sandboxed", [False, True] if SANDBOXED else [False])
def test_hostile_trees_are_judged_or_refused_and_the_next_answer_is_judged_right(sandboxed):
    """In one judge process: each hostile tree is judged or refused (a fail; never a pass, an error or a hang past
    its limit: the process is killed), and a right answer after them is still right."""
    ref = _ref(
        J=(J, "expr"), S=({th2: sp.ImageSet(sp.Lambda(sp.Symbol("n"), sp.Symbol("n") * sp.pi), sp.Integers)}, "set")
    )
    jp = judging.JudgeProcess(ref, POINTS, 1, sandbox=Sandbox() if sandboxed else None)
    try:
        for name, tree in _hostile_answers().items():
            kind = "set" if name == "imagesets" else "expr"
            v = jp.judge("S" if kind == "set" else "J", kind, tree, seconds=3)
            assert v.status == "fail", (name, v)
        right = jp.judge("J", "expr", ex.exported(J), seconds=120)
        assert right.status == "pass", right
        if not sandboxed:  # its memory, open files and writes are bounded (in the sandbox: the same command)
            limits = Path(f"/proc/{jp.proc.pid}/limits").read_text().splitlines()
            row = {line[:26].strip(): line[26:].split() for line in limits[1:]}
            assert row["Max address space"][0] == str(judging.MEMORY_BYTES)
            assert row["Max open files"][0] == str(judging.MAX_FILES) and row["Max file size"][0] == "0"
    finally:
        jp.close()


# ----------------------------------------------------------------------------------------- no secret, nothing written

PROBE = r"""
import json, os, struct, sys
out = {}
for key, path in json.loads(sys.argv[1]).items():
    try:
        if key.startswith("write"):
            with open(path, "w") as f:
                f.write("x")
        else:
            with open(path, "rb") as f:
                f.read(1)
        out[key] = True
    except OSError as exc:
        out[key] = False
print(json.dumps(out))
"""


@pytest.mark.skipif(not SANDBOXED, reason="bubblewrap cannot run here")
def test_the_judge_process_cannot_read_the_secret_nor_write_the_cache_or_outputs(tmp_path):
    """The judge process's own command (its limits: no file written at all) in the batch's sandbox, which hides
    the notebooks, cache, outputs and secret: a probe in its place reads and writes nothing of the grader's."""
    out, cache, secret = tmp_path / "out", tmp_path / "cache", tmp_path / "secret"
    out.mkdir(), cache.mkdir()
    secret.write_text("k" * 64)
    sb = Sandbox(hidden=[str(out), str(cache), str(secret)])
    tries = {"read_secret": str(secret), "write_cache": str(cache / "x.json"), "write_out": str(out / "grades.csv")}
    tries["write_tmp"] = "/tmp/x"  # its own private /tmp: RLIMIT_FSIZE 0 refuses even that
    argv = judging.judge_command(main=f"exec({PROBE!r})")
    cmd = sb.command([*argv, json.dumps(tries)], cwd="/tmp", rw=[], env=sb.environment({}))
    p = subprocess.run(cmd, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=300, check=False)
    got = json.loads(p.stdout or "{}")
    assert got == {"read_secret": False, "write_cache": False, "write_out": False, "write_tmp": False}
    assert list(out.iterdir()) == [] and list(cache.iterdir()) == []


def test_the_judge_process_is_sent_no_secret():
    jp = judging.JudgeProcess(_ref(J=(J, "expr")), POINTS, 7)
    assert set(jp.init) == {"ref", "points", "seed"}


def test_batch_workers_get_points_from_the_supervisor_never_the_secret(tmp_path, monkeypatch):
    """grade_batch with two jobs: what each worker is sent (its init and its tasks) holds the points the supervisor
    chose with the secret, and no byte of the secret."""
    key = os.urandom(32).hex().encode()
    ref = _ref(J=(J, "expr"))
    ref.notebook, ref.parts = "t", [{"part": "1.1", "points": 5.0, "answers": ["J"], "kinds": {"J": "expr"}}]
    subs = tmp_path / "subs"
    subs.mkdir()
    for who in ("ann", "bob"):
        nb = {"cells": [], "metadata": {"kinlib": {"notebook": "t"}}, "nbformat": 4, "nbformat_minor": 5}
        (subs / f"{who}.ipynb").write_text(json.dumps(nb) + " " * (who == "bob"))
    monkeypatch.setattr(grade, "load_references", lambda *a, **k: {"t": ref})
    monkeypatch.setattr(grade, "_batch_sandbox", lambda hidden, s: None)
    sent = {}

    def fake_run(tasks, jobs, init, fail, task_limit, **kw):
        sent["init"], sent["tasks"] = init, tasks
        return [fail(t, "not run in this test") for t in tasks]

    monkeypatch.setattr(grade.batch, "run", fake_run)
    grade.grade_batch([subs], tmp_path / "out", jobs=2, secret=key, cache=None, log=None, sandbox=False)
    blob = pickle.dumps((sent["init"], sent["tasks"]))
    assert key not in blob and key.decode() not in repr(sent) and "secret" not in sent["init"]
    assert str(tmp_path / "out") not in repr(sent)  # nor where the outputs go: the supervisor writes them
    plans = [t["plan"] for t in sent["tasks"]]
    assert all(len(p["points"]) >= 5 for p in plans) and plans[0]["seed"] != plans[1]["seed"]
    data = (subs / "ann.ipynb").read_bytes()
    assert (plans[0]["seed"], plans[0]["points"]) == grade._points(ref, key, data)


def test_a_worker_grades_with_the_points_it_is_given_and_refuses_a_changed_file(tmp_path):
    nb = {"cells": [], "metadata": {"kinlib": {"notebook": "t"}}, "nbformat": 4, "nbformat_minor": 5}
    p = tmp_path / "ann.ipynb"
    p.write_text(json.dumps(nb))
    ref = _ref(J=(J, "expr"))
    ref.notebook, ref.parts = "t", [{"part": "1.1", "points": 5.0, "answers": ["J"], "kinds": {"J": "expr"}}]
    plan = grade.plan(p, {"t": ref}, b"k" * 32)
    p.write_text(json.dumps(nb) + "\n")  # changed after the supervisor chose its points
    res = grade.grade_submission(p, {"t": ref}, sandbox=False, plan=plan)
    assert res["infrastructure"] and res["rows"][0]["message"].startswith("not graded: infrastructure")


# ----------------------------------------------------------------------------------------- spoiled rows


def test_a_malformed_signed_message_is_skipped_not_an_error():
    for msg in ({"parent_header": [1]}, {"parent_header": "x"}, [1], None, {"parent_header": {"msg_id": 1}}):
        assert kernel._message_of(lambda timeout, m=msg: m, "m1", 0.1) is None
    res = kernel.CellResult(0, "ok")
    k = kernel.Kernel(cwd=".", conn_dir=".")

    class KC:
        def get_iopub_msg(self, timeout):
            return {"parent_header": {"msg_id": "m1"}, "msg_type": "stream", "content": [1]}

        def get_shell_msg(self, timeout):
            return {"parent_header": {"msg_id": "m1"}, "content": "junk"}

    k.kc = KC()
    assert k._take_output("m1", res, 0.1) is False and res.status == "ok"
    assert k._take_reply("m1", res, 0.1) is True and res.status == "error"  # the cell's reply made no sense


class _Run:
    def __init__(self, tmp, tmpfs):
        self.tmp, self.enclosure = tmp, type("E", (), {"tmpfs": tmpfs})()


def test_an_answer_lost_to_a_full_shared_disk_is_flagged_not_failed(tmp_path):
    g = steps.Grading(_Run(str(tmp_path), False), "ann", "t", None, [], [], 0, {}, {})
    v = steps._unread(g, "J", {"kernel_error": "raised OSError: [Errno 28] No space left on device"})
    assert v.status == "error" and "infrastructure" in v.message and g.out["infrastructure"]
    # on the submission's own size-limited disk, it filled it itself: a fail that says so
    g = steps.Grading(_Run(str(tmp_path), True), "ann", "t", None, [], [], 0, {}, {})
    v = steps._unread(g, "J", {"kernel_error": "raised OSError: [Errno 28] No space left on device"})
    assert v.status == "fail" and "disk space" in v.message and "infrastructure" not in g.out


def test_a_checker_bug_is_flagged_as_infrastructure(tmp_path, monkeypatch):
    nb = {"cells": [], "metadata": {"kinlib": {"notebook": "t"}}, "nbformat": 4, "nbformat_minor": 5}
    p = tmp_path / "ann.ipynb"
    p.write_text(json.dumps(nb))
    ref = _ref(J=(J, "expr"))
    ref.notebook, ref.parts = "t", [{"part": "1.1", "points": 5.0, "answers": ["J"], "kinds": {"J": "expr"}}]

    def boom(g):
        raise AttributeError("'list' object has no attribute 'get'")

    monkeypatch.setattr(grade, "run_steps", boom)
    res = grade.grade_submission(p, {"t": ref}, sandbox=False, secret=b"k" * 32)
    assert "internal error in the checker" in res["infrastructure"]
    assert res["rows"][0]["status"] == "error" and res["rows"][0]["message"].startswith("not graded: infrastructure")


def test_a_malformed_tree_is_not_blamed_on_the_reference():
    from kinlib.course.grader.judge import judge_answer

    ref = _ref(J=(J, "expr"))
    for tree in (["Matrix", 2, 2, ["int", "1"]], ["NoSuchNode"], {"x": 1}, ["Pow", ["int", "2"]]):
        v = judge_answer("J", "expr", {"tree": tree}, ref, POINTS, 1)
        assert v.status in ("fail", "error") and "reference" not in v.message, (tree, v)


# ----------------------------------------------------------------------------------------- Gradescope's score


def test_a_gradescope_score_never_exceeds_the_maximum():
    rows = [
        {"part": "1.1", "status": "pass", "points": 1000.0, "max_points": 5.0, "message": "", "kind": "auto"},
        {"part": "1.2", "status": "fail", "points": -7.0, "max_points": 5.0, "message": "", "kind": "auto"},
        {"part": "1.3", "status": "pass", "points": float("nan"), "max_points": 5.0, "message": "", "kind": "auto"},
    ]
    g = gradescope_results([{"submission": "ann.ipynb", "notebook": "t", "rows": rows}])
    assert [t["score"] for t in g["tests"]] == [5.0, 0.0, 0.0]
    assert g["score"] == 5.0 <= sum(t["max_score"] for t in g["tests"])


def test_verdict_fields_are_what_the_rows_read():
    assert Verdict("J", "fail", "m").as_dict() == {"answer": "J", "status": "fail", "message": "m"}


# ----------------------------------------------------------------------------------------- a batch with a victim

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "grade"
SOLUTION = FIX / "notebooks" / "90_grade_fixture.ipynb"

# what the hostile submission's cells set each answer to (after the solution's own cell for it)
HOSTILE = {
    # a Float past the decoder's magnitude cap inside sin (1e1000000 took 134 s in the grader before; in a kernel
    # its export alone goes past the export's time limit, so a smaller one shows the cap)
    "Js": "Js = sp.Matrix(6, 3, lambda i, j: sp.sin(sp.Mul(sp.Float('1e2000'), th1, evaluate=False), evaluate=False))",
    "detJ": "detJ = ((th2**99)**99)**99",  # nested powers
    "moves": "_f = sp.Function('f')\nmoves = sp.Matrix(3, 3, lambda i, j: _f(th1 + i) ** (j + 1))",
    "singular": (
        "_n = sp.Symbol('n', integer=True)\n"  # 45 ImageSets: 47 s against 3 s before
        "singular = [{th2: sp.ImageSet(sp.Lambda(_n, 2*_n*sp.pi + sp.Rational(k, 41)), sp.Integers)}"
        " for k in range(45)]"
    ),
}
# one signed IOPub message with parent_header = [1] (0/20 "internal error in the checker" before), then a flood
# of IOPub messages that goes on while the grader exports the answers
PROTOCOL = (
    "import threading\n"
    "_k = get_ipython().kernel\n"
    "_m = _k.session.msg('stream', {'name': 'stdout', 'text': 'hi'})\n"
    "_m['parent_header'] = [1]\n"
    "_k.session.send(_k.iopub_socket, _m)\n"
    "def _flood():\n"
    "    while True:\n"
    "        _k.session.send(_k.iopub_socket, 'stream', {'name': 'stdout', 'text': 'x' * 1000})\n"
    "threading.Thread(target=_flood, daemon=True).start()\n"
)


def _hostile_notebook() -> dict:
    nb = json.loads(SOLUTION.read_text())
    cells = []
    for c in nb["cells"]:
        cells.append(c)
        for name in (c.get("metadata", {}).get("kinlib", {}) or {}).get("answers", []):
            if name in HOSTILE:
                src = HOSTILE[name]
                cells.append(
                    {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}
                )
    cells.append({"cell_type": "code", "metadata": {}, "source": PROTOCOL, "outputs": [], "execution_count": None})
    nb["cells"] = cells
    return nb


@pytest.mark.slow
def test_hostile_trees_and_an_iopub_flood_in_a_batch_leave_the_victim_graded_right(tmp_path, grader_reference_cache):
    """Two workers: a submission with every hostile tree of the issue and a protocol attack, and a victim (the
    solution itself). The hostile answers are judged or refused (fails, never errors, infrastructure or
    'internal error'), its right answers still score, and the victim gets full marks."""
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "hostile.ipynb").write_text(json.dumps(_hostile_notebook()))
    (subs / "victim.ipynb").write_bytes(SOLUTION.read_bytes())
    summary = grade.grade_batch(
        [subs], tmp_path / "out", jobs=2, timeout=600, cell_timeout=120, notebooks=FIX / "notebooks",
        cache=grader_reference_cache, log=None, batch_timeout=3000,
    )  # fmt: skip
    res = {r["relpath"]: r for r in summary["results"]}
    assert summary["infrastructure_errors"] == 0, [r.get("infrastructure") for r in res.values()]
    victim = res["victim.ipynb"]["rows"]
    assert [r["status"] for r in victim] == ["pass"] * 5 and all(r["points"] == r["max_points"] for r in victim)
    hostile = {r["part"]: r for r in res["hostile.ipynb"]["rows"]}
    got = [(hostile[p]["status"], hostile[p]["message"][:200]) for p in ("1.1", "1.2", "1.3", "1.4")]
    assert [g[0] for g in got] == ["fail"] * 4, got
    assert "too large" in got[1][1], got  # the nested power: refused by the decoder's caps
    assert hostile["1.5"]["status"] == "pass"  # its untouched answers are graded as usual
    text = json.dumps(res["hostile.ipynb"]["rows"])
    assert "internal error" not in text and "reference could not" not in text


# a submission that prints 100 MB and displays 100 MB (each one IOPub message), then is graded as usual
FLOOD = (
    "from IPython.display import display\n"
    "print('x' * 100_000_000)\n"
    "display({'text/plain': 'y' * 100_000_000}, raw=True)\n"
)
WORKER_HWM_BOUND = 250 * 2**20  # a worker's peak RSS: ~90 MiB measured with the cap, 376 MiB without


def _workers_peak(stop, peak) -> None:
    """Poll every grader worker process (``kinlib.course.grader.batch --worker``) for its VmHWM (its peak RSS)."""
    import re
    import time

    while not stop.is_set():
        for pid in (p for p in os.listdir("/proc") if p.isdigit()):
            try:
                cmd = Path(f"/proc/{pid}/cmdline").read_bytes()
                if b"kinlib.course.grader.batch" not in cmd or b"--worker" not in cmd:
                    continue
                m = re.search(r"VmHWM:\s+(\d+) kB", Path(f"/proc/{pid}/status").read_text())
            except OSError:
                continue
            if m:
                peak[pid] = max(peak.get(pid, 0), int(m.group(1)) * 1024)
        time.sleep(0.2)


@pytest.mark.slow
def test_an_iopub_flood_is_dropped_and_flagged_with_the_graders_memory_bounded(tmp_path, grader_reference_cache):
    """200 MB of output (two messages of 100 MB) from one submission, a victim beside it: the grader's workers
    never hold it (ZeroMQ refuses a message over kernel.MAX_MESSAGE_BYTES: without the cap a worker peaked at
    ~+290 MB per 100 MB message), the flood is flagged, both are graded right."""
    import threading

    nb = json.loads(SOLUTION.read_text())
    nb["cells"].append({"cell_type": "code", "metadata": {}, "source": FLOOD, "outputs": [], "execution_count": None})
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "flood.ipynb").write_text(json.dumps(nb))
    (subs / "victim.ipynb").write_bytes(SOLUTION.read_bytes())
    stop, peak = threading.Event(), {}
    watcher = threading.Thread(target=_workers_peak, args=(stop, peak), daemon=True)
    watcher.start()
    try:
        summary = grade.grade_batch(
            [subs], tmp_path / "out", jobs=2, timeout=600, cell_timeout=300, notebooks=FIX / "notebooks",
            cache=grader_reference_cache, log=None, batch_timeout=3000,
        )  # fmt: skip
    finally:
        stop.set()
        watcher.join()
    res = {r["relpath"]: r for r in summary["results"]}
    assert summary["infrastructure_errors"] == 0
    for name in ("flood.ipynb", "victim.ipynb"):
        rows = res[name]["rows"]
        assert [r["status"] for r in rows] == ["pass"] * 5 and all(r["points"] == r["max_points"] for r in rows), rows
    assert peak, "no worker process seen"
    print("worker peaks (MiB):", {p: v // 2**20 for p, v in peak.items()})
    assert max(peak.values()) < WORKER_HWM_BOUND, {p: v // 2**20 for p, v in peak.items()}
    assert res["flood.ipynb"]["output_dropped"] >= 1 and res["victim.ipynb"]["output_dropped"] == 0
    assert "over the grader's size cap" in Path(res["flood.ipynb"]["feedback"]).read_text()


# ----------------------------------------------------------------------------------------- kernels' own limits


def test_each_kernel_process_has_a_cap_on_open_files(tmp_path):
    from kinlib.course.grader.isolation.limits import Enclosure, Limits

    with Enclosure(Limits(files=200), "t") as enc:
        code = kernel.Kernel(cwd=str(tmp_path), conn_dir=str(tmp_path), enclosure=enc)._kernel_argv("c.json")[4]
    assert "_lim(resource.RLIMIT_NOFILE, 200)" in code
    code = kernel.Kernel(cwd=str(tmp_path), conn_dir=str(tmp_path))._kernel_argv("c.json")[4]
    assert f"_lim(resource.RLIMIT_NOFILE, {kernel.MAX_FILES})" in code
    # the launcher's code really sets it: run it up to the kernel's import
    launcher = code.split("from ipykernel")[0] + "import resource; print(resource.getrlimit(resource.RLIMIT_NOFILE))"
    out = subprocess.run([sys.executable, "-c", launcher], capture_output=True, text=True, timeout=120).stdout
    assert out.strip() == f"({kernel.MAX_FILES}, {kernel.MAX_FILES})"


def test_without_the_sandbox_each_kernel_has_its_own_compiled_code_cache(tmp_path):
    envs = []
    for who in ("ann", "bob"):
        d = tmp_path / who
        d.mkdir()
        _, env, _, _ = kernel.Kernel(cwd=str(d), conn_dir=str(d))._isolate(["python"])
        envs.append(env["KINLIB_CACHE"])
        assert envs[-1].startswith(str(d) + os.sep)  # in the submission's own folder, removed with it
    assert envs[0] != envs[1]
