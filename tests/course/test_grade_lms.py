"""Gradescope, PrairieLearn and Canvas outputs (kinlib.course.lms.bundles), checked against the platforms' documented fields.

The validators below are written from the platforms' documentation, not from kinlib's output:

* Gradescope, Autograder Specifications (https://gradescope-autograders.readthedocs.io/en/latest/specs/):
  ``results.json`` has ``score`` (required unless every test has one), optional ``execution_time``,
  ``output``, ``output_format``, ``visibility``, ``stdout_visibility``, ``extra_data``, ``tests``; a test
  has optional ``score``, ``max_score``, ``status`` (passed | failed), ``name``, ``number``, ``output``,
  ``tags``, ``visibility``, ``extra_data``; visibility is visible | hidden | after_due_date | after_published.
* PrairieLearn, External Grading (https://prairielearn.readthedocs.io/en/latest/externalGrading/):
  ``/grade/results/results.json``, at most 1 MB; ``gradable`` (bool, default true); when gradable, ``score``
  is required, a number in [0, 1]; when not, ``format_errors`` (a string or a list of strings); tests have
  ``name``, ``description``, ``points``, ``max_points``, ``message``, ``output`` (and ``images``).

The bundles are tested where they run (see "where they run" below): each set up by its own ``setup.sh`` in an
empty simulated container (never the development environment), then its own entry point (``run_autograder``,
``run.sh``) on the six lesson notebooks answered, untouched, partly wrong, and hostile (reading the key, leaving a
daemon that rewrites results.json), the student's kernels running as the unprivileged user.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import time
import zipfile
from numbers import Real
from pathlib import Path

import pytest

import workflow_fixture as wf
from kinlib.course.grader import credit, report
from kinlib.course.lms import bundles as lms

GS_VIS = {"visible", "hidden", "after_due_date", "after_published"}
GS_TOP = {
    "score",
    "execution_time",
    "output",
    "output_format",
    "test_output_format",
    "test_name_format",
    "visibility",
    "stdout_visibility",
    "extra_data",
    "tests",
    "leaderboard",
}
GS_TEST = {
    "score",
    "max_score",
    "status",
    "name",
    "name_format",
    "number",
    "output",
    "output_format",
    "tags",
    "visibility",
    "extra_data",
}


def _num(x) -> bool:
    return isinstance(x, Real) and not isinstance(x, bool)


def validate_gradescope(d) -> list[str]:
    """Problems with a Gradescope results.json (empty when valid), plus our own requirements: every test
    has name, score, max_score, output and visibility, with 0 ≤ score ≤ max_score."""
    errs = []
    if not isinstance(d, dict):
        return ["results.json is not a JSON object"]
    errs += [f"unknown top-level key {k!r}" for k in d if k not in GS_TOP]
    tests = d.get("tests", [])
    if not isinstance(tests, list):
        return errs + ["tests is not a list"]
    if "score" not in d and not (tests and all("score" in t for t in tests if isinstance(t, dict))):
        errs.append("score is required unless every test has one")
    if "score" in d and not _num(d["score"]):
        errs.append("score is not a number")
    if "execution_time" in d and not _num(d["execution_time"]):
        errs.append("execution_time is not a number")
    for k in ("output",):
        if k in d and not isinstance(d[k], str):
            errs.append(f"{k} is not a string")
    for k in ("visibility", "stdout_visibility"):
        if k in d and d[k] not in GS_VIS:
            errs.append(f"{k} {d[k]!r} is not one of {sorted(GS_VIS)}")
    for i, t in enumerate(tests):
        if not isinstance(t, dict):
            errs.append(f"tests[{i}] is not an object")
            continue
        errs += [f"tests[{i}]: unknown key {k!r}" for k in t if k not in GS_TEST]
        for k in ("name", "score", "max_score", "output", "visibility"):
            if k not in t:
                errs.append(f"tests[{i}]: no {k}")
        for k in ("score", "max_score"):
            if k in t and not _num(t[k]):
                errs.append(f"tests[{i}].{k} is not a number")
        for k in ("name", "number", "output"):
            if k in t and not isinstance(t[k], str):
                errs.append(f"tests[{i}].{k} is not a string")
        if "status" in t and t["status"] not in ("passed", "failed"):
            errs.append(f"tests[{i}].status {t['status']!r}")
        if "visibility" in t and t["visibility"] not in GS_VIS:
            errs.append(f"tests[{i}].visibility {t['visibility']!r}")
        if "tags" in t and not (isinstance(t["tags"], list) and all(isinstance(x, str) for x in t["tags"])):
            errs.append(f"tests[{i}].tags is not a list of strings")
        if _num(t.get("score")) and _num(t.get("max_score")) and not 0 <= t["score"] <= t["max_score"] + 1e-9:
            errs.append(f"tests[{i}]: score {t['score']} outside [0, {t['max_score']}]")
    if _num(d.get("score")) and tests and abs(d["score"] - sum(t.get("score", 0) for t in tests)) > 1e-6:
        errs.append("score is not the sum of the tests' scores")
    return errs


def validate_prairielearn(d, size: int = 0) -> list[str]:
    """Problems with a PrairieLearn results.json (empty when valid)."""
    errs = []
    if size > 1_000_000:
        errs.append(f"results.json is {size} bytes, over 1 MB")
    if not isinstance(d, dict):
        return errs + ["results.json is not a JSON object"]
    gradable = d.get("gradable", True)
    if not isinstance(gradable, bool):
        errs.append("gradable is not a boolean")
    if gradable:
        if "score" not in d:
            errs.append("a gradable result needs a score")
        elif not (_num(d["score"]) and 0.0 <= d["score"] <= 1.0):
            errs.append(f"score {d['score']!r} is not a number in [0, 1]")
    else:
        fe = d.get("format_errors")
        if fe is not None and not (
            isinstance(fe, str) or (isinstance(fe, list) and all(isinstance(x, str) for x in fe))
        ):
            errs.append("format_errors is neither a string nor a list of strings")
    for k in ("message", "output"):
        if k in d and not isinstance(d[k], str):
            errs.append(f"{k} is not a string")
    for i, t in enumerate(d.get("tests", [])):
        if not isinstance(t, dict):
            errs.append(f"tests[{i}] is not an object")
            continue
        for k in ("name", "description", "message", "output"):
            if k in t and not isinstance(t[k], str):
                errs.append(f"tests[{i}].{k} is not a string")
        for k in ("points", "max_points"):
            if k in t and not _num(t[k]):
                errs.append(f"tests[{i}].{k} is not a number")
        if _num(t.get("points")) and _num(t.get("max_points")) and not 0 <= t["points"] <= t["max_points"] + 1e-9:
            errs.append(f"tests[{i}]: points outside [0, max_points]")
    return errs


def test_the_validators_reject_what_the_specs_forbid():
    assert validate_gradescope({"tests": [{"name": "x", "max_score": 1, "output": "", "visibility": "visible"}]})
    assert validate_gradescope({"score": 1, "tests": [], "stdout_visibility": "public"})
    assert validate_gradescope({"score": "1"})
    assert validate_prairielearn({"gradable": True}) == ["a gradable result needs a score"]
    assert validate_prairielearn({"score": 1.5})
    assert validate_prairielearn({"gradable": False, "format_errors": 3})
    assert not validate_prairielearn({"gradable": False, "format_errors": ["not a notebook"]})


# ----------------------------------------------------------------------------------------- formats, no kernel


def _scored(sid, verdicts):
    from dataclasses import asdict

    from kinlib.course import schema

    parts = [asdict(p) for p in schema.parse_parts(wf.solution())]
    rows = [
        {
            "submission": f"{sid}.ipynb",
            "notebook": wf.NB_ID,
            "part": "1.1",
            "status": "fail",
            "points": 0.0,
            "max_points": 6.0,
            "message": "a: wrong",
            "answers": [{"answer": n, "status": s} for n, s in verdicts.items()],
        },
        {
            "submission": f"{sid}.ipynb",
            "notebook": wf.NB_ID,
            "part": "1.3",
            "status": "pass",
            "points": 5.0,
            "max_points": 5.0,
            "message": "",
        },
    ]
    res = {"submission": f"{sid}.ipynb", "path": f"/c/{sid}.ipynb", "notebook": wf.NB_ID, "title": "W", "rows": rows}
    return credit.score_parts(res, parts)


@pytest.mark.parametrize("visibility", sorted(GS_VIS))
def test_gradescope_results_validate(visibility):
    res = _scored("ann", {"a": "fail", "b": "pass", "c": "pass"})
    g = lms.gradescope_results([res], visibility=visibility, seconds=3.4)
    assert validate_gradescope(g) == []
    assert g["score"] == 3 + 3 and [t["max_score"] for t in g["tests"]] == [6.0, 3.0]  # manual items not included
    assert "1.2 drawing (4 points)" in g["output"] and "1.3 explanation (2 points)" in g["output"]
    assert "✗ a: 0 / 3" in g["tests"][0]["output"]
    assert validate_gradescope(lms.gradescope_results([])) == []
    with pytest.raises(ValueError, match="visibility"):
        lms.gradescope_results([res], visibility="public")


def test_prairielearn_results_validate_and_score_in_0_1():
    res = _scored("ann", {"a": "fail", "b": "pass", "c": "pass"})
    p = lms.prairielearn_results([res])
    assert validate_prairielearn(p) == [] and p["gradable"] is True
    assert p["score"] == pytest.approx(6 / 9)
    bad = {
        "submission": "x.ipynb",
        "notebook": "",
        "rows": [{"part": "-", "status": "error", "points": 0, "max_points": 0, "message": "not a notebook: not JSON"}],
    }
    q = lms.prairielearn_results([bad])
    assert (
        validate_prairielearn(q) == [] and q["gradable"] is False and q["format_errors"] == ["not a notebook: not JSON"]
    )


def test_canvas_csv_points_possible_pending_and_roster(tmp_path):
    out = tmp_path / "class"
    report.write_outputs(out, [_scored(s, dict.fromkeys("abc", "pass")) for s in ("111", "222")])
    (out / "overrides.csv").write_text("student_id,part,score,comment\n111,1.2,4,\n111,1.3/explanation,1,\n")
    w = lms.canvas_csv(out, "PS4 (1234)", tmp_path / "c.csv")
    lines = (tmp_path / "c.csv").read_text().splitlines()
    assert lines[0] == "Student,ID,SIS User ID,SIS Login ID,Section,PS4 (1234)"
    assert lines[1] == "Points Possible,,,,,15"
    assert lines[2] == ",111,,,,14"  # 6 + 3 automatic, 4 + 1 by override
    assert lines[3] == ",222,,,," and any("222" in x and "pending" in x for x in w)  # pending: blank
    lms.canvas_csv(out, "PS4", tmp_path / "c2.csv", include_pending=True)
    assert (tmp_path / "c2.csv").read_text().splitlines()[3] == ",222,,,,9"
    roster = tmp_path / "export.csv"
    roster.write_text(
        "Student,ID,SIS User ID,SIS Login ID,Section,PS4\n"
        "    Points Possible,,,,,15\n"
        '"Lee, Ann",111,S-111,alee,Sec 1,\n'
    )
    w = lms.canvas_csv(out, "PS4", tmp_path / "c3.csv", roster=roster)
    assert (tmp_path / "c3.csv").read_text().splitlines()[2] == '"Lee, Ann",111,S-111,alee,Sec 1,14'
    assert any("222: not in the roster" in x for x in w)


# ----------------------------------------------------------------------------------------- where they run
#
# Each bundle is set up by its own setup.sh in an EMPTY environment and run by its own entry point, in a simulated
# container: bubblewrap, as root, with the system read-only (as an image would be), a writable copy of /etc (setup.sh
# creates the student's user there), a PID namespace of its own (as a container has: "every process of the student's
# user" means those of this container), a private /tmp, and a scratch folder at /autograder (Gradescope) or at
# /grade and /opt/kinlib (PrairieLearn: the grading image's folder). Nothing of the development environment is
# visible to the bundle but the system Python it builds its venv from; pip downloads (PyPI, this machine's pip
# configuration) are cached in PIP_CACHE_DIR (default ~/.cache/pip) across runs. The bundles are built without
# the sandbox (Docker's default seccomp blocks bubblewrap), so the student's kernels run as the unprivileged user.

NOTEBOOKS = Path(__file__).resolve().parents[2] / "notebooks"
STUDENT = "kinlib-student"
SIM_PATH = "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"


def _bwrap_works() -> bool:
    if not shutil.which("bwrap") or os.geteuid() != 0:
        return False
    r = subprocess.run(
        ["bwrap", "--ro-bind", "/", "/", "--unshare-pid", "--proc", "/proc", "true"], capture_output=True
    )
    return r.returncode == 0


needs_bwrap = pytest.mark.skipif(not _bwrap_works(), reason="bubblewrap cannot run here as root")


def _pip_cache() -> str:
    d = os.environ.get("PIP_CACHE_DIR") or os.path.expanduser("~/.cache/pip")
    os.makedirs(d, exist_ok=True)
    return os.path.realpath(d)


class Container:
    """A simulated platform container (see above) over ``scratch``; ``mounts`` = {container path: scratch subfolder}."""

    def __init__(self, scratch: Path, mounts: dict):
        self.scratch, self.mounts = scratch, mounts
        shutil.copytree("/etc", scratch / "etc", symlinks=True, ignore_dangling_symlinks=True)
        for sub in mounts.values():
            (scratch / sub).mkdir(parents=True, exist_ok=True)

    def run(self, script: str, timeout: float = 900) -> subprocess.CompletedProcess:
        cmd = ["bwrap"]
        for d in sorted(os.listdir("/")):
            p = "/" + d
            if d in ("proc", "dev", "tmp", "sys", "etc", "opt", "autograder", "grade") or not os.path.exists(p):
                continue
            cmd += ["--symlink", os.readlink(p), p] if os.path.islink(p) else ["--ro-bind", p, p]
        cmd += ["--bind", str(self.scratch / "etc"), "/etc", "--tmpfs", "/opt"]
        for d in sorted(os.listdir("/opt")):  # pip's local indexes (this machine's pip.conf) stay visible
            cmd += ["--ro-bind", f"/opt/{d}", f"/opt/{d}"]
        cmd += ["--dev", "/dev", "--unshare-pid", "--proc", "/proc", "--perms", "1777", "--tmpfs", "/tmp"]
        cmd += ["--bind", _pip_cache(), _pip_cache()]
        env = {"PATH": SIM_PATH, "HOME": "/tmp", "LANG": "C.UTF-8", "PIP_CACHE_DIR": _pip_cache()}
        # this machine's pip configuration (its local indexes and wheel folder, as a platform's image has its own
        # mirror settings): the user's pip.conf is not under the container's HOME, so it is named by
        # PIP_CONFIG_FILE, and pip's own environment settings pass through. Without it pip fetched every package
        # from PyPI in each set-up (85 s wall for 13 s CPU).
        user_conf = Path.home() / ".config" / "pip" / "pip.conf"
        if user_conf.is_file():
            cmd += ["--ro-bind", str(user_conf), "/etc/pip-user.conf"]
            env["PIP_CONFIG_FILE"] = "/etc/pip-user.conf"
        env.update({k: v for k, v in os.environ.items() if k.startswith("PIP_") and k not in ("PIP_CACHE_DIR",)})
        for inside, sub in self.mounts.items():
            cmd += ["--bind", str(self.scratch / sub), inside]
        cmd += ["--die-with-parent", "--clearenv", "--chdir", "/"]
        for k, v in env.items():
            cmd += ["--setenv", k, v]
        return subprocess.run([*cmd, "bash", "-c", script], capture_output=True, text=True, timeout=timeout)


#: after the entry point: every process of the student's user still alive in the container, and what leaked
AFTER = f"""
rc=$?
echo "EXIT $rc"
uid=$(id -u {STUDENT})
for d in /proc/[0-9]*; do
  if [ "$(stat -c %u "$d" 2>/dev/null)" = "$uid" ] && ! grep -q '^State:.*Z' "$d/status" 2>/dev/null; then
    echo "ALIVE ${{d#/proc/}} $(tr '\\0' ' ' < "$d/cmdline")"
  fi
done
cat /tmp/kinlib-leak-* 2>/dev/null | sed 's/^/LEAK /'
exit 0
"""


def untouched(nb: dict, keep: tuple = ()) -> dict:
    """The workbook a student is given (as make handouts makes it, nothing run): each solution code cell a stub
    naming its answers, no check cells; parts in ``keep`` keep the solution's code (a student who answered them)."""
    nb = json.loads(json.dumps(nb))
    cells = []
    for c in nb["cells"]:
        tags = c["metadata"].get("tags", [])
        if "check" in tags:
            continue
        if c["cell_type"] == "code":
            c["outputs"], c["execution_count"] = [], None
            meta = c["metadata"].get("kinlib", {})
            if "solution" in tags and meta.get("part") not in keep and keep != "all":
                names = meta.get("answers", [])
                c["source"] = "\n".join(f"{n} = ...  # TODO" for n in names) or "# your work here"
        cells.append(c)
    nb["cells"] = cells
    return nb


def _parts(nb: dict) -> list[str]:
    return list(
        dict.fromkeys(
            c["metadata"]["kinlib"]["part"]
            for c in nb["cells"]
            if "solution" in c["metadata"].get("tags", []) and c["metadata"].get("kinlib", {}).get("answers")
        )
    )


def _hostile(mark: str, results: str, key: str) -> str:
    """A student's last cell: read the key and the references, and leave a daemon that keeps rewriting results.json
    with full marks and reports what it could reach (in /tmp, which the check after the run reads)."""
    daemon = (
        "import json, os, time\n"
        f"leak = '/tmp/kinlib-leak-{mark}'\n"
        "def note(s):\n"
        "    with open(leak, 'a') as f: f.write(s + '\\n')\n"
        "note('daemon started as uid %d' % os.getuid())\n"
        "t = time.time()\n"
        "while time.time() - t < 600:\n"
        "    try:\n"
        f"        with open({results!r}, 'w') as f: json.dump({{'score': 1e6, 'gradable': True, 'tests': []}}, f)\n"
        "        note('rewrote results.json')\n"
        "    except OSError:\n"
        "        pass\n"
        "    time.sleep(0.2)\n"
    )
    return (
        "import os, subprocess, sys\n"
        f"for p in [{key!r}, {key.replace('grader-secret', 'references.json')!r}]:\n"
        "    try:\n"
        f"        open('/tmp/kinlib-leak-{mark}', 'a').write('read ' + p + ': ' + open(p).read()[:40] + '\\n')\n"
        "    except OSError:\n"
        "        pass\n"
        f"subprocess.Popen([sys.executable, '-c', {daemon!r}], start_new_session=True, stdin=subprocess.DEVNULL,\n"
        "                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
        # the cell ends only once the daemon runs: on a loaded machine the grader could otherwise end the kernel
        # (and its user's processes) before the daemon's Python has started, and the check would see no daemon
        f"import time\nleak, t = '/tmp/kinlib-leak-{mark}', time.time()\n"
        "while time.time() - t < 60 and not (os.path.exists(leak) and 'daemon started' in open(leak).read()):\n"
        "    time.sleep(0.05)\n"
    )


@pytest.fixture(scope="module")
def six(tmp_path_factory, grader_reference_cache):
    """The six lesson notebooks (one consistent copy while others edit them), their references computed once per
    run: the run's signed reference cache and secret (tests/conftest.py), which the xdist workers share (the
    Gradescope and PrairieLearn tests run on both at once: conftest's ``_SPLIT``) with the other grading tests
    (the cache is keyed by each notebook's bytes, so this copy hits the same entries)."""
    if len(sorted(NOTEBOOKS.glob("0[1-6]_*.ipynb"))) != 6:
        pytest.skip("the six lesson notebooks are not all there")
    d = tmp_path_factory.mktemp("six")
    nbs = d / "notebooks"
    nbs.mkdir()
    for p in sorted(NOTEBOOKS.glob("0[1-6]_*.ipynb")):
        shutil.copy(p, nbs / p.name)
    secret = Path(os.environ["KINLIB_GRADER_SECRET"])  # the run's (conftest's ``_grader_secret``)
    kw = dict(notebooks=nbs, cache=grader_reference_cache, secret=secret, sandbox=False, timeout=240, cell_timeout=120)
    return {"dir": d, "kw": kw, "nbs": {p.stem: json.loads(p.read_text()) for p in sorted(nbs.glob("*.ipynb"))}}


def _write_submission(folder: Path, notebooks: dict):
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    for name, nb in notebooks.items():
        (folder / f"{name}.ipynb").write_text(json.dumps(nb))


def _totals(d: dict, key_points: str, key_max: str) -> tuple[float, float]:
    return sum(t[key_points] for t in d["tests"]), sum(t[key_max] for t in d["tests"])


def _check_after(r, mark):
    assert "EXIT 0" in r.stdout, r.stdout[-3000:] + r.stderr[-3000:]
    assert "ALIVE" not in r.stdout, r.stdout  # no process of the student's user outlived the entry point
    leaks = [line for line in r.stdout.splitlines() if line.startswith("LEAK")]
    assert leaks and all("daemon started" in x for x in leaks), leaks  # it ran, it read nothing, rewrote nothing
    assert all(" as uid 0" not in x for x in leaks), leaks  # as the student's user, never root


def _check_compiled(site: Path):
    """setup.sh byte-compiled what a kernel imports (the kernels run with -B, as a user who cannot write the venv:
    a module without its .pyc would be compiled again in each), the bundle's kinlib too; the test suites left out."""
    for mod in (
        "sympy/core/basic",
        "sympy/matrices/dense",
        "numpy/linalg/_linalg",
        "kinlib/kinematics/poe",
        "kinlib/kinematics/jacobians",
        "kinlib/exact/budget",
    ):
        folder, name = (site / mod).parent, (site / mod).name
        assert (folder / f"{name}.py").is_file() and list((folder / "__pycache__").glob(f"{name}.*.pyc")), mod
    assert (site / "sympy" / "core" / "tests").is_dir() and not list(
        (site / "sympy" / "core" / "tests").glob("__pycache__/*.pyc")
    )


@pytest.mark.slow
@needs_bwrap
def test_gradescope_bundle_set_up_by_its_own_setup_sh(tmp_path, six):
    zpath = lms.gradescope_zip(tmp_path / "autograder.zip", visibility="after_published", **six["kw"])
    z = zipfile.ZipFile(zpath)
    names = z.namelist()
    assert {"setup.sh", "run_autograder", "config.json", "references.json", "grader-secret"} <= set(names)
    assert {"requirements.txt", "imports.txt", "constraints.txt"} <= set(names) and not any(
        "__pycache__" in n for n in names
    )
    assert "modern_robotics" in z.read("imports.txt").decode().split()  # the workbooks import it
    assert six["kw"]["secret"].read_bytes().strip() not in z.read("grader-secret")
    box = Container(tmp_path, {"/autograder": "ag"})
    z.extractall(tmp_path / "ag" / "source")
    for f in ("run_autograder", "setup.sh"):
        (tmp_path / "ag" / "source" / f).chmod(0o755)
    # Gradescope: setup.sh once (building the image), run_autograder copied to /autograder
    r = box.run("bash /autograder/source/setup.sh && cp /autograder/source/run_autograder /autograder/")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    site = tmp_path / "ag" / "venv" / "lib" / "python3.11" / "site-packages"
    assert not (site / "kinlib" / "__init__.py").is_symlink()
    _check_compiled(site)
    sub, res = tmp_path / "ag" / "submission", tmp_path / "ag" / "results" / "results.json"
    nbs = six["nbs"]

    def grade(notebooks, after=""):
        _write_submission(sub, notebooks)
        r = box.run("/autograder/run_autograder" + after)
        d = json.loads(res.read_text())
        assert validate_gradescope(d) == [], d
        return r, d

    # the six correct workbooks: full marks; kinlib is the bundle's own, installed in the venv setup.sh made
    r, d = grade({k: untouched(nb, keep="all") for k, nb in nbs.items()})
    assert r.returncode == 0, r.stderr[-3000:]
    assert "from /autograder/venv/lib/" in r.stdout
    got, top = _totals(d, "score", "max_score")
    assert top > 50 and got == top == d["score"], [t for t in d["tests"] if t["score"] < t["max_score"]]
    assert {t["visibility"] for t in d["tests"]} == {"after_published"}
    assert f"unprivileged user {STUDENT}" in d["output"] and "without the sandbox" in d["output"]
    # the six untouched workbooks: zero
    r, d = grade({k: untouched(nb) for k, nb in nbs.items()})
    assert d["score"] == 0 and _totals(d, "score", "max_score")[1] == top
    # wrong: one notebook answered but its first part; a hostile one: unanswered, reads the key, leaves a daemon
    first = next(iter(nbs))
    mark = os.urandom(4).hex()
    bad = untouched(nbs[first], keep=tuple(_parts(nbs[first])[1:]))
    attack = untouched(nbs[first])
    attack["cells"].append(
        _code_cell(_hostile(mark, "/autograder/results/results.json", "/autograder/source/grader-secret"))
    )
    # ... graded by a bundle that asks for the sandbox, in a container where bubblewrap cannot run (as Docker's
    # seccomp would have it): the kernels run as the student's user all the same
    cfg_path = tmp_path / "ag" / "source" / "config.json"
    cfg_path.write_text(json.dumps(json.loads(cfg_path.read_text()) | {"sandbox": True}))
    r, d = grade({"wrong": bad}, AFTER)
    assert f"unprivileged user {STUDENT}" in d["output"], d["output"]
    mine = d["tests"]
    assert 0 < d["score"] < sum(t["max_score"] for t in mine) and mine[0]["score"] == 0, mine
    r, d = grade({"hostile": attack}, AFTER)
    assert d["score"] == 0 and validate_gradescope(d) == [], d
    _check_after(r, mark)
    # no notebook in the submission: still a valid results file, score 0
    r, d = grade({})
    assert r.returncode == 0 and d["score"] == 0 and "No .ipynb" in d["output"]
    # issue 31's end-to-end attack: answers made of strings that run if sympified, hostile symbol and function
    # names, in a workbook graded by the bundle; nothing runs on the trusted side (root, who alone can write
    # /autograder), the score stays within the maximum and nothing of the key is printed
    from kinlib.course.answers import wire

    pwned = f"/autograder/pwned-{mark}"
    code = f"__import__('os').system('touch {pwned}') or 0"
    names = [n for c in nbs[first]["cells"] for n in c["metadata"].get("kinlib", {}).get("answers", [])]
    evil = untouched(nbs[first])
    evil["cells"].append(
        _code_cell(
            "import numpy as np, sympy as sp\n"
            f"_c = {code!r}\n"
            "_x = sp.Symbol('x')\n"
            "_vals = [[_c], [[_c, 1]], {'a': _c}, {_x: {(_c, 0)}}, np.array([_c], dtype=object), sp.Symbol(_c),\n"
            '         sp.Function("f\') or " + _c + " or (\'")(_x), _c]\n'
            f"for _i, _n in enumerate({names!r}):\n"
            "    globals()[_n] = _vals[_i % len(_vals)]\n"
        )
    )
    r, d = grade({"evil": evil}, AFTER)
    assert not (tmp_path / "ag" / f"pwned-{mark}").exists(), "code from the submission ran in the grader"
    assert 0 <= d["score"] <= sum(t["max_score"] for t in d["tests"]) and d["score"] == 0, d
    assert all(0 <= t["score"] <= t["max_score"] for t in d["tests"]), d["tests"]
    shown = r.stdout + r.stderr + json.dumps(d)
    assert six["kw"]["secret"].read_bytes().strip().decode() not in shown
    for ref in json.loads(z.read("references.json")).values():
        for a in ref["answers"].values():
            if "tree" in a:
                value = str(wire.load(a["tree"], max_nodes=10 * wire.MAX_NODES))
                assert len(value) < 8 or value not in shown, value[:80]
    # per-student variants (issue 33), in the same image: a bundle with a key; the student id is Gradescope's
    # submitter (submission_metadata.json users[0]: its sid, here the roster id; its email is not on the roster)
    vzip = _variants_bundle(tmp_path, six, lambda **kw: lms.gradescope_zip(tmp_path / "variants.zip", **kw))
    assert "variants-key.json" in zipfile.ZipFile(vzip).namelist()
    src = tmp_path / "ag" / "source"
    shutil.rmtree(src)
    zipfile.ZipFile(vzip).extractall(src)
    meta = tmp_path / "ag" / "submission_metadata.json"

    def grade_as(sid, notebooks):
        user = {"email": f"{sid}@example.edu", "id": 1234, "name": "A Student", "sid": sid}
        meta.write_text(json.dumps({"id": 1, "users": [user], "previous_submissions": []}))
        r, d = grade(notebooks)
        assert r.returncode == 0, r.stderr[-3000:]
        return (*_totals(d, "score", "max_score"), d)

    _check_variants(grade_as, lambda sid: sid)


def _code_cell(src):
    return {"cell_type": "code", "metadata": {}, "source": src, "outputs": [], "execution_count": None}


def _variants_bundle(tmp_path, six, build):
    """A bundle of the variants fixture (tests/variants_fixture.py) with its key (issue 33), built by ``build``
    (gradescope_zip or prairielearn_dir) with the run's secret, for the image the test already set up."""
    import variants_fixture as vf
    from kinlib.course.grader.secret import load_secret

    nbs = tmp_path / "variants-notebooks"
    nbs.mkdir()
    (nbs / f"{vf.NID}.ipynb").write_text(json.dumps(vf.notebook()))
    key = vf.make_key(load_secret(six["kw"]["secret"]), tmp_path / "variants-key.json")
    return build(**(six["kw"] | {"notebooks": nbs, "variants": key}))


def _check_variants(grade, sid_of):
    """Issue 33's grading checks in a platform: each student's own workbook full marks; ada's right workbook
    handed in as bob's zero, flagged; bob's untouched workbook zero, not flagged (``grade(sid, notebooks)`` ->
    (score, its maximum, results); ``sid_of``: what the platform is told)."""
    import variants_fixture as vf

    for sid in ("ada", "bob"):
        got, top, d = grade(sid_of(sid), {"ps": vf.notebook(vf.STUDENTS[sid])})
        assert got == top > 0 and vf.FLAG not in json.dumps(d), d
    got, top, d = grade(sid_of("bob"), {"ps": vf.notebook(vf.STUDENTS["ada"])})
    assert got == 0 and top > 0, d
    assert all(vf.FLAG in t["output"] or vf.FLAG in t.get("message", "") for t in d["tests"]), d["tests"]
    assert "'bob'" in json.dumps(d)  # the results say which student's numbers were graded
    got, top, d = grade(sid_of("bob"), {"ps": vf.notebook(5, r="r = ...", s="s = ...")})
    assert got == 0 and top > 0 and vf.FLAG not in json.dumps(d), d


@pytest.mark.slow
@needs_bwrap
def test_prairielearn_bundle_in_its_own_image(tmp_path, six):
    out = lms.prairielearn_dir(tmp_path / "pl", image="someone/kinlib-grader:1", **six["kw"])
    opts = json.loads((out / "info-externalGradingOptions.json").read_text())["externalGradingOptions"]
    assert opts["entrypoint"] == "/grade/serverFilesCourse/kinlib_grader/run.sh" and opts["timeout"] <= 600
    assert (
        opts["image"] == "someone/kinlib-grader:1"
        and "someone/kinlib-grader:1" in (out / "image" / "Dockerfile").read_text()
    )
    image = sorted(p.name for p in (out / "image").iterdir())
    assert "grader-secret" not in image and "references.json" not in image and "setup.sh" in image
    box = Container(tmp_path, {"/grade": "grade", "/opt/kinlib": "opt-kinlib"})
    # the image: what its Dockerfile does (COPY . /opt/kinlib/image; RUN setup.sh)
    shutil.copytree(out / "image", tmp_path / "opt-kinlib" / "image")
    r = box.run("KINLIB_VENV=/opt/kinlib/venv bash /opt/kinlib/image/setup.sh")
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-3000:]
    _check_compiled(tmp_path / "opt-kinlib" / "venv" / "lib" / "python3.11" / "site-packages")
    shutil.copytree(out / "serverFilesCourse", tmp_path / "grade" / "serverFilesCourse")
    sub, res = tmp_path / "grade" / "student", tmp_path / "grade" / "results" / "results.json"
    nbs = six["nbs"]

    def grade(notebooks, after=""):
        _write_submission(sub, notebooks)
        r = box.run("/grade/serverFilesCourse/kinlib_grader/run.sh" + after)
        d = json.loads(res.read_text())
        assert validate_prairielearn(d, res.stat().st_size) == [], d
        return r, d

    r, d = grade({k: untouched(nb, keep="all") for k, nb in nbs.items()})
    assert r.returncode == 0, r.stderr[-3000:]
    assert d["gradable"] is True and d["score"] == 1.0, [t for t in d["tests"] if t["points"] < t["max_points"]]
    r, d = grade({k: untouched(nb) for k, nb in nbs.items()})
    assert d["gradable"] is True and d["score"] == 0.0
    first = next(iter(nbs))
    mark = os.urandom(4).hex()
    attack = untouched(nbs[first])
    key = "/grade/serverFilesCourse/kinlib_grader/grader-secret"
    attack["cells"].append(_code_cell(_hostile(mark, "/grade/results/results.json", key)))
    r, d = grade({"hostile": attack}, AFTER)
    assert d["gradable"] is True and d["score"] == 0.0, d
    _check_after(r, mark)
    # a file that is not a notebook: not gradable, with a format error
    sub.joinpath("w.ipynb").write_text("print('hello')")
    for p in sub.glob("hostile*"):
        p.unlink()
    r = box.run("/grade/serverFilesCourse/kinlib_grader/run.sh")
    d = json.loads(res.read_text())
    assert r.returncode == 0 and validate_prairielearn(d) == [] and d["gradable"] is False
    assert "not JSON" in d["format_errors"][0]
    # per-student variants (issue 33), in the same image. PrairieLearn tells an external grader no student identity
    # (data.json is server.py's data: params, submitted answers, ...): the id is the question's kinlib_student_id
    # element value (data.json submitted_answers), else the submitted file's name; the student's own claim
    vout = _variants_bundle(tmp_path, six, lambda **kw: lms.prairielearn_dir(tmp_path / "variants-pl", **kw))
    assert (vout / "serverFilesCourse" / "kinlib_grader" / "variants-key.json").is_file()
    assert not (vout / "image" / "variants-key.json").exists()
    shutil.rmtree(tmp_path / "grade" / "serverFilesCourse")
    shutil.copytree(vout / "serverFilesCourse", tmp_path / "grade" / "serverFilesCourse")
    data = tmp_path / "grade" / "data" / "data.json"
    data.parent.mkdir(parents=True, exist_ok=True)

    def grade_as(sid, notebooks):
        if sid is None:
            data.unlink(missing_ok=True)
        else:
            data.write_text(json.dumps({"params": {}, "submitted_answers": {"kinlib_student_id": sid}}))
        r, d = grade(notebooks)
        assert r.returncode == 0 and d["gradable"] is True, (r.stderr[-3000:], d)
        return (*_totals(d, "points", "max_points"), d)

    _check_variants(grade_as, lambda sid: sid)
    # no element value: the file's name, when it is a roster id
    import variants_fixture as vf

    got, top, d = grade_as(None, {"bob": vf.notebook(vf.STUDENTS["bob"])})
    assert got == top > 0 and "file name bob.ipynb" in d["message"], d


def test_the_platform_commands(tmp_path, capsys):
    from kinlib.course.cli import main

    out = tmp_path / "class"
    report.write_outputs(out, [_scored("111", dict.fromkeys("abc", "pass"))])
    assert main(["grade", "canvas", str(out), "--assignment", "PS4", "--out", str(tmp_path / "c.csv")]) == 0
    assert "111 pending" in capsys.readouterr().err.replace(":", "")
    assert (tmp_path / "c.csv").read_text().splitlines()[2] == ",111,,,,"
    assert main(["grade", "canvas", str(tmp_path / "empty"), "--assignment", "PS4", "--out", "x.csv"]) == 2
    for bad in (["grade", "gradescope", "--out", "a.zip", "--visibility", "public"], ["grade", "canvas", str(out)]):
        with pytest.raises(SystemExit) as e:
            main(bad)
        assert e.value.code == 2
    args = ["--notebooks", str(tmp_path), "--secret", str(tmp_path / "s")]
    assert main(["grade", "prairielearn", "--out", str(tmp_path / "pl"), *args]) == 2
    assert "no solution notebooks" in capsys.readouterr().err


# ----------------------------------------------------------------------------------------- the parts, quickly


def test_requirements_come_from_what_the_notebooks_and_kinlib_import(tmp_path):
    from kinlib.course.lms import environment

    nbs = sorted(NOTEBOOKS.glob("0[1-6]_*.ipynb"))
    reqs, modules = environment.requirements(nbs, NOTEBOOKS.parent / "environment.txt")
    names = {r.split("==")[0].lower().replace("_", "-") for r in reqs}
    # what the workbooks import (modern_robotics was the one missing), what kinlib needs, and the kernel
    assert {"modern-robotics", "numpy", "sympy", "matplotlib", "jupyter-client", "ipykernel"} <= names
    assert "playwright" not in names and "jupyterlite-core" not in names  # handout tools stay on the instructor's side
    assert all("==" in r for r in reqs) and "modern_robotics" in modules
    pins = dict(line.split("==") for line in (NOTEBOOKS.parent / "environment.txt").read_text().split() if "==" in line)
    assert all(pins.get(r.split("==")[0], r.split("==")[1]) == r.split("==")[1] for r in reqs)  # environment.txt's
    nb = wf.solution()
    nb["cells"].append(
        {"cell_type": "code", "metadata": {}, "source": "import surely_not_a_module_kinlib", "outputs": []}
    )
    (tmp_path / "x.ipynb").write_text(json.dumps(nb))
    with pytest.raises(ValueError, match="surely_not_a_module_kinlib .imported by x.ipynb. is not installed"):
        environment.requirements([tmp_path / "x.ipynb"])


@pytest.mark.skipif(os.geteuid() != 0, reason="switching users needs root")
def test_every_process_of_the_student_user_is_ended(tmp_path):
    """Processes of an unused uid (no account needed: Popen switches by number), one a daemon in a session of its own
    that keeps forking: end_all leaves none, and give() makes a folder that user's alone."""
    from kinlib.course.grader.isolation.unprivileged import StudentUser

    uid = 61000 + int.from_bytes(os.urandom(2), "big") % 3000
    user = StudentUser("test-student", uid, uid)
    assert user.processes() == []
    forker = (
        "import os, subprocess, sys, time\n"
        "subprocess.Popen([sys.executable, '-c', 'import os, time\\nwhile True:\\n    if os.fork() == 0: time.sleep(60)\\n"
        "    time.sleep(0.05)'], start_new_session=True)\n"
        "time.sleep(60)\n"
    )
    procs = [subprocess.Popen(["/usr/bin/python3", "-c", forker], cwd="/", **user.popen_kwargs()) for _ in range(2)]
    try:
        deadline = time.monotonic() + 60  # a condition, not a fixed wait: a loaded machine starts them late
        while len(user.processes()) < 6 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(user.processes()) >= 6
        assert user.end_all() == [] and user.processes() == []
    finally:
        for p in procs:
            p.kill()
            p.wait()
    (tmp_path / "w" / "sub").mkdir(parents=True)
    (tmp_path / "w" / "sub" / "f").write_text("x")
    user.give(tmp_path / "w")
    assert {(p.stat().st_uid, p.stat().st_gid) for p in [tmp_path / "w", *(tmp_path / "w").rglob("*")]} == {(uid, uid)}
    assert (tmp_path / "w").stat().st_mode & 0o777 == 0o700
