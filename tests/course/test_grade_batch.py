"""A class is never stopped by one file or one dead worker (issue 22, items 2-5): hostile files, identity,
clean outputs, supervised workers, and per-submission limits with bounded bombs.

Each attack of the issue is reproduced and must gain nothing (its own rows say what was wrong), stop nothing
(every other submission is graded and the outputs are written) and leave nothing running. The tests without a
kernel come first; the ones that grade in real kernels are marked slow.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import mistune
import pytest

from kinlib.course.grader import batch, grade, intake, report
from kinlib.course.grader.isolation import limits
from kinlib.course.grader.secret import load_secret
from kinlib.course.lms.bundles import canvas_csv

FIX = Path(__file__).resolve().parents[1] / "fixtures" / "grade"
REF = FIX / "notebooks" / "90_grade_fixture.ipynb"
WB = FIX / "workbooks" / "90_grade_fixture.ipynb"
PARTS = ["1.1", "1.2", "1.3", "1.4", "1.5"]
MARK = "kg" + os.urandom(4).hex()  # 10 characters: fits a process's comm (15)


def _code(src):
    return {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}


def _workbook(end=()) -> dict:
    wb = json.loads(WB.read_text())
    wb["cells"] += [_code(s) for s in end]
    return wb


def _read(p):
    with open(p, newline="", encoding="utf-8") as f:
        return list(csv.reader(f))


def _marked() -> list[int]:
    """PIDs of live processes named MARK (every process a bomb starts names itself so)."""
    found = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                if Path(f"/proc/{d}/comm").read_text().strip() == MARK:
                    found.append(int(d))
            except OSError:
                pass
    return found


def _children() -> list[int]:
    """Live (not zombie) direct children of this process."""
    live = []
    for pid in batch._children():  # noqa: SLF001  (the supervisor's own helper: direct children from /proc)
        try:
            if Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z":
                live.append(pid)
        except (OSError, IndexError):
            pass
    return live


class _Alarm:
    """Fail (instead of hanging the run) if the block takes longer than a generous ``seconds``."""

    def __init__(self, seconds):
        self.seconds = seconds

    def __enter__(self):
        def boom(*a):
            raise TimeoutError(f"still running after {self.seconds} s: the batch hangs")

        self.old = signal.signal(signal.SIGALRM, boom)
        signal.alarm(self.seconds)

    def __exit__(self, *exc):
        signal.alarm(0)
        signal.signal(signal.SIGALRM, self.old)


# ----------------------------------------------------------------------------------------- reading files


def test_deep_json_is_a_row_not_a_recursion_error(tmp_path):
    p = tmp_path / "deep.ipynb"
    p.write_text('{"metadata": {"kinlib": {"notebook": ' + "[" * 100_000 + "]" * 100_000 + '}}, "cells": []}')
    data, nb, problem = intake.read_notebook(p)
    assert nb is None and "nested" in problem and "deep" in problem
    # the depth scanner against Python's own parser on shallow text, brackets inside strings included
    for text in ['{"a": "[[[{{", "b": [[1], {"c": "\\"]"}]}', "[]", '"x"', '[["\\\\"], "\\\\\\"["]']:
        assert intake.json_depth(text.encode()) == _depth(json.loads(text)), text


def _depth(obj) -> int:
    if isinstance(obj, (list, dict)):
        items = obj.values() if isinstance(obj, dict) else obj
        return 1 + max((_depth(x) for x in items), default=0)
    return 0


@pytest.mark.parametrize(
    "nb, words",
    [
        ({"nbformat": "4", "cells": []}, "nbformat is '4' (a str)"),
        ({"nbformat": True, "cells": []}, "nbformat is 'True' (a bool)"),
        ({"nbformat": 3, "cells": []}, "only version-4"),
        ({"nbformat": 4, "cells": {}}, "no list of cells"),
        ({"nbformat": 4, "cells": [{"cell_type": "code", "source": [1]}]}, "cell 1: its source is not text"),
        ({"nbformat": 4, "cells": [{"cell_type": 7}]}, "cell 1: its cell_type is not text"),
        ({"nbformat": 4, "metadata": [], "cells": []}, "its metadata is not an object"),
        ([1, 2], "a JSON list, not an object"),
    ],
)
def test_mistyped_notebooks_are_rows(tmp_path, nb, words):
    p = tmp_path / "x.ipynb"
    p.write_text(json.dumps(nb))
    _, got, problem = intake.read_notebook(p)
    assert got is None and words in problem


def test_links_fifos_and_folders_are_refused_one_by_one(tmp_path):
    root = tmp_path / "subs"
    root.mkdir()
    (root / "ok.ipynb").write_text("{}")
    (root / "link.ipynb").symlink_to(Path(sys.prefix) / "pyvenv.cfg")  # a link into the environment
    os.mkfifo(root / "fifo.ipynb")
    (root / "dir.ipynb").mkdir()
    (root / "linked").symlink_to(tmp_path)  # a linked folder is not walked
    with _Alarm(60):
        subs = {s.relpath: s.refused for s in intake.find_submissions([root])}
        assert set(subs) == {"ok.ipynb", "link.ipynb", "fifo.ipynb"}  # a folder named *.ipynb is walked, not read
        assert subs["ok.ipynb"] == "" and "symbolic link" in subs["link.ipynb"] and "FIFO" in subs["fifo.ipynb"]
        # reading refuses them too, by the open descriptor (a FIFO never blocks, a link is not followed)
        assert "FIFO" in intake.read_notebook(root / "fifo.ipynb")[2]
        assert "symbolic link" in intake.read_notebook(root / "link.ipynb")[2]


def test_a_class_of_hostile_files_is_graded_row_by_row(tmp_path):
    d = tmp_path / "subs"
    d.mkdir()
    (d / "deep.ipynb").write_text('{"metadata": ' + "[" * 100_000 + "]" * 100_000 + ', "cells": []}')
    (d / "string.ipynb").write_text('{"nbformat": "4", "cells": []}')
    (d / "latin1.ipynb").write_bytes(b'{"cells": [], "x": "\xe9"}')
    with open(d / "huge.ipynb", "wb") as f:
        f.truncate(intake.MAX_SUBMISSION_BYTES + 1)  # sparse: costs nothing to make
    os.mkfifo(d / "fifo.ipynb")
    (d / "env.ipynb").symlink_to(Path(sys.prefix) / "pyvenv.cfg")  # a link into the environment
    out = tmp_path / "out"
    with _Alarm(300):
        summary = grade.grade_batch(
            [d], out, jobs=2, notebooks=FIX / "notebooks", cache=tmp_path / "c", log=None
        )  # the sandbox on: a link no longer makes the whole batch refuse
    got = {r["relpath"]: r["rows"] for r in summary["results"]}
    want = {
        "deep.ipynb": "nested 100001 levels deep",
        "string.ipynb": "nbformat is '4' (a str)",
        "latin1.ipynb": "not JSON",
        "huge.ipynb": "larger than 50 MB",
        "fifo.ipynb": "a FIFO",
        "env.ipynb": "a symbolic link",
    }
    assert set(got) == set(want)
    for name, words in want.items():
        (row,) = got[name]
        assert row["status"] == "error" and words in row["message"], (name, row["message"])
    assert {r[1] for r in _read(out / "grades.csv")[1:]} == set(want)
    assert len(list((out / "feedback").iterdir())) == len(want) and summary["infrastructure_errors"] == 0
    assert _children() == []


# ----------------------------------------------------------------------------------------- identity


def _res(relpath, verdict="pass", nb="90_grade_fixture"):
    rows = [
        {"submission": relpath, "notebook": nb, "part": p, "status": verdict, "message": ""}
        | {"points": 5.0 if verdict == "pass" else 0.0}
        | {"max_points": 5.0}
        for p in ("1.1", "1.2")
    ]
    return {"submission": relpath, "relpath": relpath, "path": f"/class/{relpath}", "notebook": nb, "rows": rows}


def test_a_nested_folder_never_becomes_another_student(tmp_path):
    pattern = r"([^/]+)/[^/]+$"
    w = report.write_outputs(tmp_path, [_res("bob/02.ipynb"), _res("aaron/bob/02.ipynb", "fail")], id_pattern=pattern)
    rows = _read(tmp_path / "grades.csv")
    ids = {r[0]: r[11] for r in rows[1:]}  # student id: total
    assert ids == {"bob": "10", "aaron/bob/02": "0"}  # bob keeps his grade; the nested file is named by its path
    assert any("aaron/bob/02.ipynb does not fit --id-pattern" in x for x in w)


def test_unicode_and_case_ids_are_kept_and_never_collide(tmp_path):
    names = ["王伟", "李娜", "josé", "josè", "Ann", "ann"]
    report.write_outputs(tmp_path, [_res(f"{n}/ps4.ipynb") for n in names], id_pattern=r"([^/]+)/")
    ids = [r[0] for r in _read(tmp_path / "grades.csv")[1:]]
    assert sorted(set(ids)) == sorted(names)
    files = sorted(p.name for p in (tmp_path / "feedback").iterdir())
    assert len(files) == len(names) and len({f.lower() for f in files}) == len(names)  # even on a case-blind disk
    assert all(f.isascii() for f in files)
    # regrading one of them touches nobody else's results, rows or page
    before = {p.name: p.read_bytes() for p in (tmp_path / "results").iterdir()}
    fb_before = {p.name: p.read_bytes() for p in (tmp_path / "feedback").iterdir()}
    report.write_outputs(tmp_path, [_res("josè/ps4.ipynb", "fail")])  # the pattern is remembered
    after = {p.name: p.read_bytes() for p in (tmp_path / "results").iterdir()}
    changed = {k for k in after if after[k] != before.get(k)}
    assert set(after) == set(before) and len(changed) == 1
    assert json.loads(after[changed.pop()])["relpath"] == "josè/ps4.ipynb"
    fb_after = {p.name: p.read_bytes() for p in (tmp_path / "feedback").iterdir()}
    assert len({k for k in fb_after if fb_after[k] != fb_before[k]}) == 1
    totals = {r[0]: r[1] for r in _read(tmp_path / "totals.csv")[1:]}
    assert totals == dict.fromkeys(names, "10") | {"josè": "0"}


def test_a_file_graded_again_alone_is_read_relative_to_the_remembered_root(tmp_path):
    subs = tmp_path / "subs"
    (subs / "ann").mkdir(parents=True)
    (subs / "ann" / "ps4.ipynb").write_text("{}")
    out = tmp_path / "out"
    report.write_outputs(out, [], roots=intake.find_submissions([subs]))
    (s,) = intake.find_submissions([subs / "ann" / "ps4.ipynb"], root=report.remembered_root(out))
    assert (s.relpath, s.root) == ("ann/ps4.ipynb", str(subs))
    (s,) = intake.find_submissions([subs / "ann" / "ps4.ipynb"])  # nothing remembered: its own folder
    assert s.relpath == "ps4.ipynb"


# ----------------------------------------------------------------------------------------- clean outputs

HOSTILE = {
    '=HYPERLINK("evil.example","x")': "=",
    "+1+cmd": "+",
    "-2+3": "-",
    "@SUM(A1)": "@",
    "\tTAB": "\t",
    "\rCR\rx": "\r",
}


def test_csv_cells_a_spreadsheet_would_run_are_neutralised_everywhere(tmp_path):
    results = []
    for name in HOSTILE:
        r = _res(f"{name}/ps4.ipynb")
        r["rows"][0]["message"] = name
        results.append(r)
    report.write_outputs(tmp_path, results, id_pattern=r"(?P<id>[^/]+)/")
    canvas_csv(tmp_path, "=PS4", tmp_path / "canvas.csv")
    for f in ("grades.csv", "totals.csv", "canvas.csv"):
        for row in _read(tmp_path / f):
            for cell in row:
                assert cell[:1] not in ("=", "+", "@", "\t", "\r"), (f, cell)
                assert not cell.startswith("-") or _number(cell), (f, cell)
    ids = {r[0] for r in _read(tmp_path / "grades.csv")[1:]}
    assert ids == {"'" + n for n in HOSTILE}  # shown as written, behind the quote
    # numbers stay numbers, negative ones too; a lone "-" (a whole-file error row's part) stays as it is
    assert report.csv_text([[-1.5, 0.0, "-", "x"]]) == "-1.5,0,-,x\n"


def _number(text) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


def test_control_characters_never_reach_the_terminal():
    res = _res("ann/ps4.ipynb")
    res["submission"] = "evil\x1b]0;pwned\x07\x1b[2J\r\u202eann.ipynb"
    res["notebook"] = "nb\x1b[31m"
    for r in res["rows"]:
        r["notebook"] = res["notebook"]
    text = report.summary_table([res], 1.0, 0.0, 2)
    assert not any(ch in text for ch in "\x1b\x07\r\u202e")
    assert "evil\\x1b]0;pwned\\x07" in text


def test_feedback_escapes_everything_a_student_wrote():
    attack = (
        '<img src=x onerror="alert(1)"> <script>alert(2)</script> [click](javascript:alert(3)) '
        "![t](http://evil.example/p.png) http://evil.example www.evil.example ann@evil.example "
        "<http://evil.example> `code` **bold** | a | b |\n# heading"
    )
    res = _res(attack + ".ipynb", "fail", nb=attack)
    for r in res["rows"]:
        r["message"] = attack
    res["title"] = attack
    res["notes"] = [attack]
    res["restored"] = [attack, "ok_name"]
    res["cells"] = [{"index": 0, "status": "error", "ename": attack, "evalue": attack, "part": "1.1"}]
    page = report.feedback_markdown(res)
    html = mistune.create_markdown(plugins=["table", "url", "strikethrough"])(page)
    for bad in ("<img", "<script", "<a ", "href=", "<strong>bold", "<h1>heading", "<code>code"):
        assert bad not in html, bad
    assert "<table>" in html and html.count("<tr>") == 1 + len(res["rows"])  # the student's pipes split no cell


# ----------------------------------------------------------------------------------------- supervised workers


def test_a_worker_that_cannot_start_never_blocks_the_batch(tmp_path):
    tasks = [{"i": k} for k in range(5)]
    got = []
    with _Alarm(120):
        results = batch.run(
            tasks,
            2,
            {},
            lambda task, why: {"i": task["i"], "why": why},
            60,
            worker_cmd=[sys.executable, "-c", "import sys; sys.exit(3)"],
            on_result=lambda i, r: got.append(i),
        )
    assert [r["i"] for r in results] == list(range(5)) and sorted(got) == list(range(5))
    assert all("no grading worker could start" in r["why"] and "exit status 3" in r["why"] for r in results)
    assert _children() == []


def test_a_worker_that_never_answers_is_given_up(tmp_path):
    with _Alarm(120):
        results = batch.run(
            [{"i": 0}],
            1,
            {},
            lambda task, why: {"why": why},
            60,
            start_timeout=1,  # tried MAX_START_FAILURES times: the shortest limit keeps the test from waiting
            worker_cmd=[sys.executable, "-c", "import time; time.sleep(600)"],
        )
    assert "no grading worker could start" in results[0]["why"] and "sent nothing in 1 s" in results[0]["why"]
    assert _children() == []


def _batch_dir(tmp_path, slow: dict, plain: int = 2) -> Path:
    d = tmp_path / "subs"
    d.mkdir()
    for k in range(plain):
        (d / f"s{k}.ipynb").write_text(json.dumps(_workbook()))
    for name, seconds in slow.items():
        (d / f"{name}.ipynb").write_text(json.dumps(_workbook(end=[f"import time\ntime.sleep({seconds})"])))
    return d


def _killer(target: str, times: int, subs, after: float = 1.0):
    """An on_event hook: SIGKILL the worker that starts grading ``target``, its first ``times`` times."""
    seen = {"kills": 0, "pids": []}

    def on_event(kind, pid, i):
        if kind == "start" and subs[i].relpath == target and seen["kills"] < times:
            seen["kills"] += 1
            seen["pids"].append(pid)
            threading.Timer(after, lambda: _kill(pid)).start()

    return on_event, seen


def _kill(pid):
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


@pytest.mark.slow
@pytest.mark.parametrize("kills", [1, 2])
def test_a_worker_killed_mid_batch_loses_nothing(tmp_path, kills, grader_reference_cache):
    d = _batch_dir(tmp_path, {"victim": 4})
    subs = intake.find_submissions([d])
    hook, seen = _killer("victim.ipynb", kills, subs, after=2.0)
    out = tmp_path / "out"
    with _Alarm(900):
        summary = grade.grade_batch(
            [d], out, jobs=2, timeout=120, cell_timeout=60, notebooks=FIX / "notebooks",
            cache=grader_reference_cache, log=None, on_event=hook,
        )  # fmt: skip
    assert seen["kills"] == kills
    left = [m for m in Path("/proc/self/mountinfo").read_text().split() if "kinlib-grade-" in m]
    assert not [m for m in left if any(f"kinlib-grade-{pid}-" in m for pid in seen["pids"])], left
    res = {r["relpath"]: r for r in summary["results"]}
    assert set(res) == {"s0.ipynb", "s1.ipynb", "victim.ipynb"}
    for name in ("s0.ipynb", "s1.ipynb"):  # the others are graded as usual
        assert [r["status"] for r in res[name]["rows"]] == ["fail"] * len(PARTS) and not res[name].get("infrastructure")
    victim = res["victim.ipynb"]
    if kills == 1:  # retried once, on a fresh worker: graded
        assert not victim.get("infrastructure") and [r["status"] for r in victim["rows"]] == ["fail"] * len(PARTS)
    else:  # killed twice: an infrastructure row per part, never 0 points silently
        assert "died" in victim["infrastructure"] and "twice" in victim["infrastructure"]
        assert [r["part"] for r in victim["rows"]] == PARTS
        assert all(r["message"].startswith("not graded: infrastructure") for r in victim["rows"])
        assert summary["infrastructure_errors"] == 1
    grades = _read(out / "grades.csv")
    assert {r[1] for r in grades[1:]} == set(res) and len(list((out / "feedback").iterdir())) == 3
    assert _children() == []


# a worker silent this long is stuck: 3 heartbeat periods (batch.BEAT_SECONDS), short enough not to keep the test
# waiting, long enough that a live worker on a loaded machine is never taken for a stuck one
BEAT_LIMIT = 3 * batch.BEAT_SECONDS


@pytest.mark.slow
def test_a_stopped_worker_is_noticed_by_its_heartbeat(tmp_path, grader_reference_cache):
    d = _batch_dir(tmp_path, {"victim": BEAT_LIMIT}, plain=0)  # the next worker grades it for longer than the limit
    subs = intake.find_submissions([d])
    refs = grade.load_references(FIX / "notebooks", grader_reference_cache, None, log=None, secret=load_secret())
    stopped = []

    def on_event(kind, pid, i):
        if kind == "start" and not stopped:
            stopped.append(pid)
            os.kill(pid, signal.SIGSTOP)

    init = {"refs": {k: grade.asdict(v) for k, v in refs.items()}, "timeout": 60, "cell_timeout": 30}
    init["handler"] = "kinlib.course.grader.grade:worker_handler"
    init.update(sandbox=grade.Sandbox(), limits=None)  # no secret: the supervisor chooses the points (grade.plan)
    tasks = [{"i": 0, "path": str(subs[0].path), "name": "victim", "relpath": "victim.ipynb", "root": str(d)}]
    tasks[0]["plan"] = grade.plan(subs[0].path, refs, b"k" * 32)
    events = []
    with _Alarm(600):
        (res,) = batch.Supervisor(
            2, init, lambda t, why: {"why": why}, 600, beat_limit=BEAT_LIMIT,
            on_event=lambda *a: (events.append(a[0]), on_event(*a)),
        ).run(tasks)  # fmt: skip
    assert "stuck" in events and "retry" in events
    assert [r["status"] for r in res["rows"]] == ["fail"] * len(PARTS)  # graded by the next worker
    assert _children() == []


# ----------------------------------------------------------------------------------------- limits


def test_an_enclosure_leaves_no_cgroup_mount_or_folder():
    with limits.Enclosure(limits.Limits(), "t") as e:
        folder, groups = e.folder, list(e.cgroups)
        if e.tmpfs:
            assert folder in Path("/proc/self/mountinfo").read_text()
            assert os.statvfs(folder).f_blocks * os.statvfs(folder).f_frsize == limits.Limits().disk_bytes
    assert not os.path.exists(folder) and folder not in Path("/proc/self/mountinfo").read_text()
    assert not any(g.exists() for g in groups)


def test_without_cgroups_the_enclosure_falls_back_to_rlimits(monkeypatch):
    monkeypatch.setitem(limits._SUPPORT, "res", ("", "no writable cgroup"))  # noqa: SLF001  (a machine without)
    with limits.Enclosure(limits.Limits(processes=100), "t") as e:
        assert e.kind == "" and e.cgroups == [] and e.wrap(["python"]) == ["python"]
        assert e.rlimits()["nproc"] == 100 and "rlimits only" in e.describe() and e.reached() == []


def test_the_cgroup_v2_path_on_a_fake_cgroup_filesystem(tmp_path, monkeypatch):
    """This machine has cgroup v1; the v2 path runs here against a folder standing in for /sys/fs/cgroup (the
    grader in /grader.slice/me): the grader's base cgroup with memory and pids delegated, one cgroup per
    submission with memory.max, memory.swap.max and pids.max, a launcher that joins it before exec, the limits
    reached read from memory.events and pids.events, cgroup.kill written, the folder removed."""
    root = tmp_path / "cgroup"
    (root / "grader.slice" / "me").mkdir(parents=True)
    (root / "cgroup.controllers").write_text("cpu memory pids\n")
    (root / "cgroup.subtree_control").write_text("memory pids\n")
    (root / "grader.slice" / "cgroup.subtree_control").write_text("memory pids\n")
    monkeypatch.setattr(limits, "_CG2", root)
    monkeypatch.setattr(limits, "_own_cgroup", lambda ctl: "/grader.slice/me" if ctl == "" else None)
    monkeypatch.delitem(limits._SUPPORT, "res", raising=False)  # noqa: SLF001  (checked once per process)
    monkeypatch.setattr(limits.atexit, "register", lambda f: f)  # no release() of the fake at exit
    kind, base = limits.cgroup_support()
    assert (kind, base) == ("v2", root / "grader.slice" / f"kinlib-grade-{os.getpid()}")
    assert (base / "cgroup.subtree_control").read_text() == "+memory +pids"
    lim = limits.Limits(memory_bytes=2**30, processes=64)
    with limits.Enclosure(lim, "ann/02 é") as e:
        (c,) = e.cgroups
        assert e.kind == "v2" and c.parent == base and "cgroup v2" in e.describe()
        assert [(c / f).read_text() for f in ("memory.max", "memory.swap.max", "pids.max")] == [str(2**30), "0", "64"]
        assert e.rlimits() == {"as": 2**30 + 2 * 2**30, "fsize": lim.disk_bytes, "nofile": lim.files}  # no nproc
        ran = subprocess.run(e.wrap([sys.executable, "-c", "import os; print(os.getpid())"]), capture_output=True)
        assert (c / "cgroup.procs").read_text().split() == ran.stdout.decode().split()  # joined, then exec'd
        (c / "memory.events").write_text("low 0\nhigh 0\nmax 7\noom 2\noom_kill 2\n")
        (c / "pids.events").write_text("max 5\n")
        reached = " ".join(e.reached())
        assert "more than 1 GiB in all; 2 process(es) killed" in reached and "64 at once; 5 new" in reached
        (c / "cgroup.procs").write_text("")  # the launcher has exited (its PID must not be killed again)
        (c / "cgroup.kill").write_text("0")
        assert e.kill() == [] and (c / "cgroup.kill").read_text() == "1"
        for f in c.iterdir():  # cgroupfs removes a cgroup's files with it; a plain folder needs them gone first
            f.unlink()
    assert not c.exists()


BOMBS = {
    # each names its processes MARK, so that the test can look for survivors
    "fork": (
        "import ctypes, os, time\n"
        f"ctypes.CDLL(None).prctl(15, b'{MARK}', 0, 0, 0)\n"
        "made = refused = 0\n"
        "for _ in range(300):\n"
        "    try:\n"
        "        if os.fork() == 0:\n"
        "            time.sleep(600)\n"
        "            os._exit(0)\n"
        "        made += 1\n"
        "    except OSError:\n"
        "        refused += 1\n"
        "print(made, refused)"
    ),
    "memory": (
        "import ctypes\n"
        f"ctypes.CDLL(None).prctl(15, b'{MARK}', 0, 0, 0)\n"
        "hog = []\n"
        "for _ in range(48):  # 3 GiB in 64 MiB steps, every page touched\n"
        "    hog.append(b'x' * (64 << 20))"
    ),
    "disk": (
        "import os\n"
        "block = b'x' * (8 << 20)\n"
        "for target in ('big.bin', '/dev/shm/big.bin', '/tmp/big.bin'):\n"
        "    try:\n"
        "        with open(target, 'wb') as f:\n"
        "            for _ in range(75):  # 600 MiB\n"
        "                f.write(block)\n"
        "    except OSError as e:\n"
        "        print(target, e)\n"
        "try:\n"
        "    open('/dev/evil', 'w')\n"
        "except OSError as e:\n"
        "    print('/dev', e)"
    ),
}


@pytest.mark.slow
@pytest.mark.skipif(limits.cgroup_support()[0] == "", reason="no writable cgroup here (not root)")
def test_bounded_bombs_are_stopped_reported_and_leave_nothing(tmp_path, grader_reference_cache):
    d = tmp_path / "subs"
    d.mkdir()
    for name, src in BOMBS.items():
        (d / f"{name}.ipynb").write_text(json.dumps(_workbook(end=[src])))
    out = tmp_path / "out"
    with _Alarm(900):
        summary = grade.grade_batch(
            [d], out, jobs=2, timeout=180, cell_timeout=90, notebooks=FIX / "notebooks",
            cache=grader_reference_cache, log=None,
        )  # fmt: skip
    res = {Path(r["relpath"]).stem: r for r in summary["results"]}
    for name, words in (("fork", "processes: more than 256"), ("memory", "memory: the submission's processes"),
                        ("disk", "disk: more than 512 MiB written")):  # fmt: skip
        rows = {r["part"]: r for r in res[name]["rows"]}
        assert rows["limits"]["status"] == "error" and words in rows["limits"]["message"], (name, rows["limits"])
        assert [rows[p]["status"] for p in PARTS] == ["fail"] * len(PARTS)  # graded all the same
        assert not res[name].get("infrastructure")
    disk_cell = res["disk"]["cells"][-1]
    assert disk_cell["status"] == "ok"  # every write failed inside the cell: no space, /dev read-only
    assert _marked() == [] and _children() == []
    grades = _read(out / "grades.csv")
    assert sum(1 for r in grades if r[3] == "limits") == 3
