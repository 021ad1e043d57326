"""The platforms a class already uses, when it outgrows one machine: Gradescope, PrairieLearn, Canvas.

Everything here reuses the one grading core (:func:`kinlib.course.grader.grade.grade_submission`, scored by
:mod:`kinlib.course.grader.credit`): only the packaging around it and the results' format differ.

* ``kinlib grade gradescope --out autograder.zip`` writes a Gradescope autograder (Autograder
  Specifications, https://gradescope-autograders.readthedocs.io/en/latest/specs/): ``setup.sh`` and
  ``run_autograder`` at the root of the zip, plus the bundle: a copy of the ``kinlib`` package
  (``kinlib-src/``), what the container must install (``requirements.txt``: the distributions of every module
  the notebooks and kinlib's grading code import, read from that code by :mod:`kinlib.course.lms.environment`,
  pinned by ``constraints.txt``, the repository's ``environment.txt``; ``imports.txt``: the modules
  ``setup.sh`` checks), the reference answers as data (``references.json``, computed here by the instructor's
  grader), a grader secret derived for this zip (never the instructor's own) and ``config.json``.
  ``setup.sh`` (run once, as root, when Gradescope builds the image) makes ``/autograder/venv`` and the
  unprivileged user ``kinlib-student``. Gradescope runs each submission in its own
  container: ``/autograder/submission/`` (the student's files), ``/autograder/source/`` (the zip),
  ``/autograder/results/results.json`` (written by ``run_autograder``: ``score``, ``output``,
  ``execution_time``, ``stdout_visibility`` and ``tests`` [{``name``, ``number``, ``score``, ``max_score``,
  ``status``, ``output``, ``visibility``}], one test per automatically graded part; visibility is one of
  ``visible``, ``hidden``, ``after_due_date``, ``after_published``). Use a Gradescope base image with
  Python ≥ 3.11 (Ubuntu 24.04).
* ``kinlib grade prairielearn --out DIR [--image NAME]`` writes ``DIR/serverFilesCourse/kinlib_grader/``
  (``run.sh``, the references, the key, ``config.json``), ``DIR/image/`` (the grading image: ``Dockerfile``,
  the same ``setup.sh``, requirements and kinlib; no answers and no key, since images are public on Docker Hub)
  and ``DIR/info-externalGradingOptions.json`` (External Grading,
  https://prairielearn.readthedocs.io/en/latest/externalGrading/), which names the image: build and push it
  (``docker build -t NAME DIR/image``). The student's files are in
  ``/grade/student/``, the results go to ``/grade/results/results.json`` (created by ``run.sh``):
  ``gradable``, ``score`` in [0, 1], ``message``, ``output``, ``tests`` [{``name``, ``description``,
  ``points``, ``max_points``, ``message``, ``output``}]; a file that is not a notebook is ``gradable:
  false`` with ``format_errors``.
* ``kinlib grade canvas OUT --assignment NAME --out canvas.csv`` writes a Canvas gradebook import file from a
  class folder (``kinlib grade ... --out OUT``): columns ``Student, ID, SIS User ID, SIS Login ID, Section``
  then the assignment, a ``Points Possible`` row first (Canvas: Grades → Import). The student id goes to
  ``--id-column`` (default ``ID``: the Canvas user id, which Canvas's submission downloads carry in their
  file names, ``doejane_12345_678_ps4.ipynb``; grade them with
  ``--id-pattern '[^/_]+_(?:LATE_|late_)?(?P<id>\\d+)_\\d+_[^/]*$'``) or is looked up in ``--roster`` (a
  Canvas gradebook export). Students with manual parts still pending are left blank (ungraded in Canvas)
  unless ``--include-pending``.

Per-student variants (issue 33): ``--variants KEY.json`` puts the signed key (:mod:`kinlib.course.variants.key`,
verified with the instructor's secret, then signed again with the bundle's derived secret; only the bundle's
notebooks, the roster reduced to ids) into the bundle as ``variants-key.json``; each submission is judged against
the variant of the platform's student id (:func:`kinlib.course.grader.grade.variant_plan`: a wrong answer right
for another variant says "this looks like another variant's answer"; a student not on the roster is not graded).
The student id, and how much it can be trusted:

* **Gradescope** gives it: ``/autograder/submission_metadata.json`` ``users[0]`` (the submitter; in a group
  submission its first member). The roster id is matched against that user's ``sid`` (the course roster's Student
  ID, when the course has them), else their ``email``: build the roster with one or the other.
* **PrairieLearn gives an external grader no student identity.** The grading job's files are the student's files
  (``/grade/student``), the question's tests and ``/grade/data/data.json``, the ``data`` dict of ``server.py``'s
  ``grade()`` (``params``, ``correct_answers``, ``submitted_answers``, ``raw_submitted_answers``, ``variant_seed``,
  ``options``, ...: no user, no uid). So the id is what the student gives: the value of the question's element
  ``<pl-string-input answers-name="kinlib_student_id">`` (``submitted_answers`` in data.json), else the submitted
  notebook's file name (``ada.ipynb`` → ``ada``) when that is on the roster. Either is the student's own claim:
  a student who types a classmate's id is graded against that classmate's variant (and gets the classmate's
  numbers right only by copying them). The results' message says which id was graded ("graded as student …"),
  so the instructor can compare it with PrairieLearn's own record of who submitted (the assessment's
  submissions download has each submission's UID beside its submitted answers).

Work graded by hand (``manual`` items, e.g. 5.2's drawing) is not part of the platforms' automatic score:
the results' output lists it; grade it with the platform's own manual grading. Within the container the
student's kernel runs in the sandbox when the bundle asks for it and bubblewrap can run there. Otherwise (a zip
built with ``--no-sandbox``, or Docker's default seccomp profile blocking bubblewrap) it runs as the unprivileged
user ``kinlib-student`` (:mod:`kinlib.course.grader.isolation.unprivileged`): before any kernel starts, the
bundle (key, references), the submission and the results folder are made root's alone and checked unreadable by
that user; after each kernel and before the results are written every process of that user is ended; every
result says how the code ran. For testing, the roots are ``--root`` (or ``KINLIB_AUTOGRADER_ROOT`` /
``KINLIB_GRADE_ROOT``), default ``/autograder`` and ``/grade``.
"""

from __future__ import annotations

import csv
import json
import math
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
import zipfile
from dataclasses import asdict
from pathlib import Path

from ..grader import credit, report
from ..grader.isolation import unprivileged
from . import environment
from .scripts import DOCKERFILE, GS_VENV, PL_IMAGE, PL_VENV, RUN_AUTOGRADER, RUN_PL, SETUP_SH

__all__ = [
    "VISIBILITIES",
    "build_bundle",
    "gradescope_zip",
    "prairielearn_dir",
    "gradescope_results",
    "prairielearn_results",
    "run_platform",
    "canvas_csv",
    "main",
]

VISIBILITIES = ("visible", "hidden", "after_due_date", "after_published")
_ROOTS = {"gradescope": ("KINLIB_AUTOGRADER_ROOT", "/autograder"), "prairielearn": ("KINLIB_GRADE_ROOT", "/grade")}

# ----------------------------------------------------------------------------------------- the bundle


def _copy_package(dest: Path) -> None:
    import kinlib

    pkg = Path(kinlib.__file__).resolve().parent
    shutil.copytree(pkg, dest / "kinlib", ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    repo = pkg.parent
    for name in ("pyproject.toml", "README.md"):
        if (repo / name).is_file():
            shutil.copy(repo / name, dest / name)


def build_bundle(
    dest,
    notebooks=None,
    only=None,
    cache="default",
    secret=None,
    sandbox: bool = True,
    visibility: str = "visible",
    timeout: float = 300.0,
    cell_timeout: float = 60.0,
    log=None,
    variants=None,
) -> dict:
    """Write the grader bundle into the folder ``dest``; returns its ``config.json`` as a dict.

    The references are computed here (the solution notebooks run in the instructor's grader) and kept as
    data; the bundle's secret is HMAC(instructor secret, "platform", random nonce), so the platform never
    holds the instructor's own secret. ``variants``: the per-student variants key (verified with the instructor's
    secret, then written into the bundle signed with the bundle's). Runs the solution notebooks (seconds), hence
    not run here:

    >>> cfg = build_bundle("/tmp/bundle", only=["05"])  # doctest: +SKIP
    >>> sorted(cfg)  # doctest: +SKIP
    ['cell_timeout', 'notebooks', 'points', 'sandbox', 'timeout', 'visibility']
    """
    from ..grader import grade
    from ..grader import secret as secret_mod

    if visibility not in VISIBILITIES:
        raise ValueError(f"visibility must be one of {', '.join(VISIBILITIES)}, got {visibility!r}")
    log = log or (lambda s: None)
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    notebooks = Path(notebooks) if notebooks else grade.default_notebooks()
    ids = None
    if only:
        ids = {p.stem for p in notebooks.glob("*.ipynb") if any(p.name.startswith(o) for o in only)}
        if not ids:
            raise ValueError(f"no notebook in {notebooks} starts with {', '.join(only)}")
    if cache == "default":
        cache = notebooks.resolve().parent / "build" / "grade-cache"
    master = secret_mod.load_secret(secret)
    vkey = grade.read_variants_key(variants, master) if variants is not None else None  # refused before any work
    refs = grade.load_references(notebooks, Path(cache) if cache else None, ids, log=log, secret=master)
    broken = {k: r.error for k, r in refs.items() if r.error}
    if broken:
        raise RuntimeError("broken references: " + "; ".join(f"{k}: {e}" for k, e in broken.items()))
    if not refs:
        raise ValueError(f"no solution notebooks (with a kinlib.notebook id) in {notebooks}")
    (dest / "references.json").write_text(json.dumps({k: asdict(v) for k, v in sorted(refs.items())}))
    derived = secret_mod.sign(master, "platform", os.urandom(16).hex().encode())
    key = dest / "grader-secret"
    key.write_text(derived + "\n")
    key.chmod(0o600)
    if vkey is not None:
        _bundle_key(dest / VARIANTS_KEY, vkey, set(refs), derived.encode(), log)
    _copy_package(dest / "kinlib-src")
    env = Path(grade.__file__).resolve().parents[3] / "environment.txt"
    if env.is_file():
        shutil.copy(env, dest / "constraints.txt")
    else:
        (dest / "constraints.txt").write_text("")
    used = sorted(p for p in notebooks.glob("*.ipynb") if ids is None or p.stem in ids)
    reqs, modules = environment.requirements(used, dest / "constraints.txt")
    (dest / "requirements.txt").write_text("".join(r + "\n" for r in reqs))
    (dest / "imports.txt").write_text("".join(m + "\n" for m in modules))
    points = {}
    for k, r in refs.items():
        auto = sum(sum(credit.answer_max(p).values()) for p in r.parts)
        manual = sum(sum(credit.manual_items(p).values()) for p in r.parts)
        points[k] = {"auto": float(auto), "manual": float(manual)}
    import kinlib

    cfg = {
        "kinlib": kinlib.__version__,
        "student_user": unprivileged.DEFAULT_NAME,
        "notebooks": sorted(refs),
        "points": points,
        "sandbox": bool(sandbox),
        "visibility": visibility,
        "timeout": float(timeout),
        "cell_timeout": float(cell_timeout),
    }
    if vkey is not None:
        cfg["variants"] = VARIANTS_KEY
    (dest / "config.json").write_text(json.dumps(cfg, indent=1, sort_keys=True) + "\n")
    log(f"bundle: {len(refs)} notebook(s): {', '.join(sorted(refs))}")
    return cfg


VARIANTS_KEY = "variants-key.json"


def _bundle_key(path: Path, vkey, notebooks: set, secret: bytes, log) -> None:
    """The variants key of the bundle's notebooks, the roster reduced to ids, signed with the bundle's secret."""
    from dataclasses import replace

    from ..variants.key import write_key

    nbs = {k: v for k, v in vkey.notebooks.items() if k in notebooks}
    roster = [{"id": s["id"], "name": "", "email": ""} for s in vkey.roster]
    write_key(path, replace(vkey, notebooks=nbs, roster=roster), secret)
    path.chmod(0o600)
    students = len({s for nk in nbs.values() for s in nk.students})
    log(f"bundle: per-student variants of {', '.join(sorted(nbs)) or 'no notebook'} ({students} students)")


def platform_student(platform: str, root: Path, students: set, files=()) -> tuple[str, str]:
    """(student id, where it came from) of the submission being graded: Gradescope's submitter
    (``submission_metadata.json`` users[0]: ``sid`` if on the roster, else ``email``); PrairieLearn's element value
    ``kinlib_student_id`` (data.json ``submitted_answers``), else a submitted file's name on the roster (PrairieLearn
    tells an external grader no identity: the student's claim). ("", why) when there is none.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = (Path(d) / "submission_metadata.json").write_text(json.dumps({"users": [{"email": "a@x.edu", "sid": "S1"}]}))
    ...     platform_student("gradescope", Path(d), {"a@x.edu"}), platform_student("gradescope", Path(d), {"S1"})
    (('a@x.edu', "Gradescope's submitter (email)"), ('S1', "Gradescope's submitter (sid)"))
    >>> platform_student("prairielearn", Path("/nonexistent"), {"ada"}, [Path("ada.ipynb")])
    ('ada', 'the submitted file name ada.ipynb')
    """

    def read(p):
        try:
            with open(p, "rb") as f:
                d = json.loads(f.read(2**22))
            return d if isinstance(d, dict) else {}
        except (OSError, ValueError):
            return {}

    if platform == "gradescope":
        users = read(root / "submission_metadata.json").get("users")
        user = users[0] if isinstance(users, list) and users and isinstance(users[0], dict) else {}
        ids = [(str(user[k]), k) for k in ("sid", "email") if isinstance(user.get(k), (str, int)) and str(user[k])]
        for sid, k in ids:
            if sid in students:
                return sid, f"Gradescope's submitter ({k})"
        if ids:
            return ids[0][0], f"Gradescope's submitter ({ids[0][1]})"
        return "", "Gradescope's submission_metadata.json names no submitter"
    answers = read(root / "data" / "data.json").get("submitted_answers")
    typed = answers.get("kinlib_student_id") if isinstance(answers, dict) else None
    if isinstance(typed, str) and typed.strip():
        return typed.strip()[:64], "the id typed in the question (kinlib_student_id)"
    for f in files:
        if Path(f).stem in students:
            return Path(f).stem, f"the submitted file name {Path(f).name}"
    return "", "no student id: the question has no kinlib_student_id answer and no file is named by a roster id"


def _exe(path: Path, text: str) -> None:
    path.write_text(text)
    path.chmod(path.stat().st_mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)


def gradescope_zip(out, **kw) -> Path:
    """Write Gradescope's ``autograder.zip``: ``setup.sh``, ``run_autograder`` and the bundle at its root.

    >>> gradescope_zip("build/autograder.zip", only=["05"])  # runs the solution notebooks  # doctest: +SKIP
    """
    out = Path(out)
    with tempfile.TemporaryDirectory(prefix="kinlib-gs-") as d:
        root = Path(d)
        cfg = build_bundle(root, **kw)
        _exe(root / "setup.sh", _setup_sh(GS_VENV, cfg))
        _exe(root / "run_autograder", RUN_AUTOGRADER)
        out.parent.mkdir(parents=True, exist_ok=True)
        tmp = out.with_name(out.name + ".part")
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            for p in sorted(root.rglob("*")):
                if p.is_file():
                    info = zipfile.ZipInfo.from_file(p, p.relative_to(root).as_posix())
                    with open(p, "rb") as f:
                        z.writestr(info, f.read(), zipfile.ZIP_DEFLATED)
        os.replace(tmp, out)
    return out


def _setup_sh(venv: str, cfg: dict) -> str:
    return (
        SETUP_SH.replace("@VENV@", venv)
        .replace("@USER@", cfg["student_user"])
        .replace("@SANDBOX@", "1" if cfg["sandbox"] else "0")
    )


#: what the grading image needs (moved out of the PrairieLearn bundle: no answers, no key in the image)
_IMAGE_FILES = ("kinlib-src", "constraints.txt", "requirements.txt", "imports.txt")


def prairielearn_dir(out, image: str | None = None, **kw) -> Path:
    """Write ``out/serverFilesCourse/kinlib_grader/`` (``run.sh``, the references, the key, ``config.json``),
    ``out/image/`` (the grading image: ``Dockerfile``, ``setup.sh``, requirements and kinlib; no answers, no key)
    and the ``externalGradingOptions`` to put in each question's ``info.json``
    (``out/info-externalGradingOptions.json``, naming ``image``: build and push it, ``out/image/Dockerfile`` says
    how).

    >>> prairielearn_dir("build/prairielearn", only=["05"])  # runs the solution notebooks  # doctest: +SKIP
    """
    import kinlib

    out = Path(out)
    here = out / "serverFilesCourse" / "kinlib_grader"
    img = out / "image"
    for d in (here, img):
        if d.exists():
            shutil.rmtree(d)
    cfg = build_bundle(here, **kw)
    img.mkdir(parents=True)
    for name in _IMAGE_FILES:
        shutil.move(here / name, img / name)
    image = image or PL_IMAGE.format(version=kinlib.__version__)
    _exe(img / "setup.sh", _setup_sh(PL_VENV, cfg))
    (img / "Dockerfile").write_text(DOCKERFILE.replace("@VENV@", PL_VENV).replace("@IMAGE@", image))
    _exe(here / "run.sh", RUN_PL.replace("@VENV@", PL_VENV))
    opts = {
        "externalGradingOptions": {
            "enabled": True,
            "image": image,
            "serverFilesCourse": ["kinlib_grader/"],
            "entrypoint": "/grade/serverFilesCourse/kinlib_grader/run.sh",
            "timeout": int(min(600, cfg["timeout"] + 60)),
        }
    }
    (out / "info-externalGradingOptions.json").write_text(json.dumps(opts, indent=2) + "\n")
    return out


# ----------------------------------------------------------------------------------------- results formats


def _row_output(r: dict) -> str:
    lines = [r.get("message", "")] if r.get("message") else []
    for a in r.get("answers") or []:
        mark = "✓" if a["status"] == "pass" else "✗"
        lines.append(f"{mark} {a['answer']}: {a['points']:g} / {a['max_points']:g}")
    return "\n".join(lines)


def _manual_note(results: list) -> str:
    items = [
        f"{r['part']} {r.get('answer', '')}".strip() + f" ({r['max_points']:g} points)"
        for res in results
        for r in res["rows"]
        if r.get("kind") == "manual"
    ]
    return ("Graded by hand, not included in this score: " + ", ".join(items) + ".") if items else ""


def _auto_rows(results: list):
    multi = len({res.get("notebook") for res in results}) > 1
    for res in results:
        for r in res["rows"]:
            if r.get("kind") != "manual":
                name = f"{res.get('notebook')} {r['part']}" if multi and res.get("notebook") else str(r["part"])
                yield res, r, name


def _summary(results: list, sandbox: bool) -> str:
    lines = []
    for res in results:
        t = credit.result_totals([r for r in res["rows"] if r.get("kind") != "manual"])
        lines.append(
            f"{res.get('title') or res.get('notebook') or res['submission']}: "
            f"{t['points']:g} / {t['max_points']:g} points (automatic)"
        )
    note = _manual_note(results)
    if note:
        lines.append(note)
    if not sandbox:
        lines.append("Graded without the sandbox (--no-sandbox).")
    return "\n".join(lines)


def _points(x, top: float) -> float:
    """``x`` as points in [0, ``top``] (0 for anything that is not a finite number).

    >>> _points(1000, 5.0), _points(-3, 5.0), _points(float("nan"), 5.0), _points("7", 5.0), _points(2.5, 5.0)
    (5.0, 0.0, 0.0, 0.0, 2.5)
    """
    if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
        return 0.0
    return float(min(max(x, 0.0), top))


def _clamped(res: dict) -> dict:
    """A result whose rows' points are in [0, their maximum] (:func:`_points`)."""
    rows = []
    for r in res.get("rows", []):
        top = _points(r.get("max_points"), math.inf)
        rows.append(dict(r, points=_points(r.get("points"), top), max_points=top))
    return dict(res, rows=rows)


def gradescope_results(results: list, visibility: str = "visible", sandbox: bool = True, seconds: float = 0.0) -> dict:
    """Gradescope's ``results.json`` for graded results (one test per automatically graded part).

    >>> res = {"submission": "ann.ipynb", "notebook": "05", "rows": [
    ...     {"part": "5.1", "status": "fail", "points": 2.0, "max_points": 5.0, "message": "s: wrong", "kind": "auto"},
    ...     {"part": "5.2", "answer": "drawing", "kind": "manual", "status": "pending", "points": 0.0,
    ...      "max_points": 5.0, "message": ""}]}
    >>> g = gradescope_results([res])
    >>> g["score"], [(t["name"], t["score"], t["max_score"], t["status"]) for t in g["tests"]]
    (2.0, [('5.1', 2.0, 5.0, 'failed')])
    """
    if visibility not in VISIBILITIES:
        raise ValueError(f"visibility must be one of {', '.join(VISIBILITIES)}, got {visibility!r}")
    results = [_clamped(res) for res in results]  # the tests and the summary: the same points, never over the top
    tests = []
    for _, r, name in _auto_rows(results):
        top = _points(r.get("max_points"), math.inf)
        tests.append(
            {
                "name": name,
                "number": str(r["part"]),
                "score": _points(r.get("points"), top),  # in [0, max_score], whatever a row claims
                "max_score": top,
                "status": "passed" if r["status"] == "pass" else "failed",
                "output": _row_output(r),
                "visibility": visibility,
            }
        )
    if not results:
        out = "No .ipynb notebook was found in your submission: upload your completed workbook."
    else:
        out = _summary(results, sandbox)
    return {
        "score": round(sum(t["score"] for t in tests), 6),
        "execution_time": int(round(seconds)),
        "output": out,
        "stdout_visibility": "hidden",
        "tests": tests,
    }


def prairielearn_results(results: list, sandbox: bool = True) -> dict:
    """PrairieLearn's ``results.json``: ``score`` = automatic points / their maximum, in [0, 1].

    >>> res = {"submission": "ann.ipynb", "notebook": "05", "rows": [
    ...     {"part": "5.1", "status": "fail", "points": 2.0, "max_points": 5.0, "message": "s: wrong", "kind": "auto"}]}
    >>> p = prairielearn_results([res])
    >>> p["gradable"], p["score"], p["tests"][0]["points"], p["tests"][0]["max_points"]
    (True, 0.4, 2.0, 5.0)
    >>> prairielearn_results([])["gradable"]
    False
    """
    bad = [r["message"] for res in results for r in res["rows"] if r["part"] == "-"]
    if not results or (bad and len(bad) == sum(len(res["rows"]) for res in results)):
        errs = bad or ["No .ipynb notebook was found in your submission: upload your completed workbook."]
        return {"gradable": False, "format_errors": errs, "message": errs[0], "tests": []}
    tests = []
    for _, r, name in _auto_rows(results):
        tests.append(
            {
                "name": name,
                "description": f"part {r['part']}",
                "points": float(r.get("points") or 0),
                "max_points": float(r.get("max_points") or 0),
                "message": r.get("message", ""),
                "output": _row_output(r),
            }
        )
    mx = sum(t["max_points"] for t in tests)
    score = sum(t["points"] for t in tests) / mx if mx else 0.0
    return {
        "gradable": True,
        "score": min(1.0, max(0.0, round(score, 6))),
        "message": _summary(results, sandbox),
        "output": _summary(results, sandbox),
        "tests": tests,
    }


# ----------------------------------------------------------------------------------------- inside the platform


def _load_refs(bundle: Path) -> dict:
    from ..grader.grade import Reference

    data = json.loads((bundle / "references.json").read_text())
    return {k: Reference(**v) for k, v in data.items()}


def _grade(path: Path, refs: dict, cfg: dict, bundle: Path, user=None, variants=None, student: str = "") -> dict:
    import inspect

    from ..grader import grade

    kw = {
        "cell_timeout": cfg.get("cell_timeout", 60.0),
        "total_timeout": cfg.get("timeout", 300.0),
        "display_name": path.name,
    }
    params = inspect.signature(grade.grade_submission).parameters
    if "secret" in params:
        kw["secret"] = (bundle / "grader-secret").read_bytes().strip()
    if "sandbox" in params:
        kw["sandbox"] = user is None and bool(cfg.get("sandbox", True))
    if user is not None:
        kw["user"] = user
    if variants is not None:
        kw.update(variants=variants, student=student)
    res = grade.grade_submission(path, refs, **kw)
    ref = refs.get(res.get("notebook"))
    if ref is not None and res.get("credit") != "scored":
        credit.score_parts(res, ref.parts)
    res.setdefault("sandbox", user is None and bool(cfg.get("sandbox", True)))
    return res


def _layout(platform: str, root: Path, bundle) -> tuple[Path, Path, Path]:
    """(bundle, submission folder, results file) of the platform's layout under ``root``."""
    if platform == "gradescope":
        return Path(bundle) if bundle else root / "source", root / "submission", root / "results" / "results.json"
    here = Path(bundle) if bundle else root / "serverFilesCourse" / "kinlib_grader"
    return here, root / "student", root / "results" / "results.json"


def _student_user(cfg: dict):
    """The user the student's kernels run as: None in the sandbox (bubblewrap runs here and the bundle asks for
    it), else the bundle's unprivileged user (UnprivilegedUnavailable if the grader cannot switch to it)."""
    if cfg.get("sandbox", True):
        from ..grader.isolation import sandbox

        if sandbox.check()[0]:
            return None
    return unprivileged.StudentUser.require(cfg.get("student_user", unprivileged.DEFAULT_NAME))


def _lock_down(root: Path, bundle: Path, subdir: Path, dest: Path, user) -> None:
    """Root's files out of the student's user's reach: the bundle (key, references), the submission and the
    results folder only root's (the platform's root folder traversable, not listable); then checked as the user."""
    root.chmod(0o711)
    dest.parent.mkdir(parents=True, exist_ok=True)
    for d in (bundle, subdir, dest.parent, bundle.parent if bundle.parent != root else bundle):
        if d.is_dir() and not d.is_symlink():
            os.chown(d, 0, 0)
            d.chmod(0o700)
    probe = "import sys\nfor p in sys.argv[1:]:\n    try:\n        open(p, 'rb').read(1); print(p)\n    except OSError:\n        pass"
    secret = [bundle / "grader-secret", bundle / "references.json", bundle / "config.json", bundle / VARIANTS_KEY]
    r = subprocess.run(
        [sys.executable, "-I", "-S", "-c", probe, *map(str, secret)],
        capture_output=True,
        text=True,
        cwd="/",
        env={"PATH": "/usr/bin:/bin"},
        timeout=60,
        **user.popen_kwargs(),
    )
    if r.returncode != 0 or r.stdout.strip():
        raise RuntimeError(f"the student's user {user.name} can read {r.stdout.split() or r.stderr[-200:]}")


def run_platform(platform: str, root=None, bundle=None) -> dict:
    """Grade the submission in the platform's layout and write its results file; returns the results dict.

    ``platform`` is "gradescope" (``ROOT/submission`` → ``ROOT/results/results.json``, ROOT default
    ``/autograder``) or "prairielearn" (``ROOT/student`` → ``ROOT/results/results.json``, ROOT ``/grade``).
    Without bubblewrap the student's kernels run as the bundle's unprivileged user (root's files locked away from
    it first), and every process of that user is ended before the results are written.
    tests/course/test_grade_lms.py runs it in a simulated container; a platform it does not know:

    >>> run_platform("moodle")
    Traceback (most recent call last):
    ...
    ValueError: platform must be gradescope or prairielearn, got 'moodle'
    """
    from ..grader.grade import find_submissions

    if platform not in _ROOTS:
        raise ValueError(f"platform must be gradescope or prairielearn, got {platform!r}")
    env, default = _ROOTS[platform]
    root = Path(root or os.environ.get(env) or default)
    bundle, subdir, dest = _layout(platform, root, bundle)
    t0 = time.monotonic()
    import kinlib

    cfg = json.loads((bundle / "config.json").read_text())
    print(f"kinlib {kinlib.__version__} from {Path(kinlib.__file__).parent}", flush=True)  # the instructor's log
    if cfg.get("kinlib", kinlib.__version__) != kinlib.__version__:
        raise RuntimeError(
            f"the bundle was built by kinlib {cfg['kinlib']} but this environment has kinlib {kinlib.__version__}: "
            "rebuild the grading image (setup.sh) from the same bundle"
        )
    refs = _load_refs(bundle)
    user = _student_user(cfg)
    if user is not None:
        _lock_down(root, bundle, subdir, dest, user)
    subs = find_submissions([subdir]) if subdir.is_dir() else []
    vkey, student, whence = _variants(platform, root, bundle, cfg, subs)
    try:
        results = [_grade(p, refs, cfg, bundle, user, vkey, student) for p in subs]
    finally:
        left = user.end_all() if user is not None else []
    if left:
        raise RuntimeError(f"processes {left} of the student's user {user.name} could not be ended")
    broken = [res["infrastructure"] for res in results if res.get("infrastructure")]
    if broken:  # the platform's machine, not the student: report a failed run, never a grade of 0
        raise RuntimeError(broken[0])
    for res in results:
        print(report.summary_table([res], res.get("seconds", 0.0), 0.0, 1), flush=True)
    sandboxed = user is None and cfg.get("sandbox", True)
    if platform == "gradescope":
        out = gradescope_results(results, cfg.get("visibility", "visible"), sandboxed, time.monotonic() - t0)
    else:
        out = prairielearn_results(results, sandboxed)
    if user is not None:
        note = f"The code ran as the unprivileged user {user.name} (no bubblewrap in this container)."
        out["output" if platform == "gradescope" else "message"] += "\n" + note
    if vkey is not None and results:
        note = f"Graded against the numbers of student {student!r} ({whence})." if student else whence
        out["output" if platform == "gradescope" else "message"] += "\n" + report.printable(note)
    report.atomic_write(dest, json.dumps(out, indent=1, ensure_ascii=False) + "\n")
    return out


def _variants(platform: str, root: Path, bundle: Path, cfg: dict, subs: list):
    """(variants Key or None, student id, where the id came from) for this run; a bundle key that does not verify
    with the bundle's secret stops the run (never graded against the original's answers)."""
    if not cfg.get("variants"):
        return None, "", ""
    from ..variants.key import read_key

    vkey = read_key(bundle / VARIANTS_KEY, (bundle / "grader-secret").read_bytes().strip())
    if vkey is None:
        raise RuntimeError(f"the bundle's {VARIANTS_KEY} does not verify with its secret: build the bundle again")
    students = {s for nk in vkey.notebooks.values() for s in nk.students}
    student, whence = platform_student(platform, root, students, list(subs))
    print(f"variants: graded as student {student!r} ({whence})", flush=True)
    return vkey, student, whence


# ----------------------------------------------------------------------------------------- Canvas


CANVAS_IDENTITY = ["Student", "ID", "SIS User ID", "SIS Login ID", "Section"]


def canvas_csv(
    grades,
    assignment: str,
    out,
    id_column: str = "ID",
    roster=None,
    include_pending: bool = False,
    overrides=None,
    points_possible=None,
) -> list[str]:
    """Write a Canvas gradebook import CSV from the class folder ``grades`` (``kinlib grade --out``);
    returns warnings (students pending, students not in the roster).

    One assignment column: each student's total over their notebooks (overrides applied); the
    ``Points Possible`` row is the sum over the class's notebooks of each notebook's maximum (or
    ``points_possible``).

    >>> import tempfile
    >>> res = {"student_id": "12345", "submission": "a.ipynb", "notebook": "05", "rows": [
    ...     {"part": "5.1", "status": "pass", "points": 5.0, "max_points": 5.0, "message": ""}]}
    >>> with tempfile.TemporaryDirectory() as d:
    ...     _ = report.write_outputs(Path(d), [dict(res, path="/x/12345.ipynb")])
    ...     _ = canvas_csv(Path(d), "Problem Set 4", Path(d) / "canvas.csv")
    ...     print((Path(d) / "canvas.csv").read_text(), end="")
    Student,ID,SIS User ID,SIS Login ID,Section,Problem Set 4
    Points Possible,,,,,5
    ,12345,,,,5
    """
    if id_column not in CANVAS_IDENTITY[:4]:
        raise ValueError(f"id_column must be one of {', '.join(CANVAS_IDENTITY[:4])}, got {id_column!r}")
    grades = Path(grades)
    results = report.load_results(grades)
    if not results:
        raise FileNotFoundError(f"no graded results in {grades / 'results'} (run kinlib grade --out {grades} first)")
    if overrides is None:
        overrides = report.default_overrides(grades)
    if overrides is not None and not isinstance(overrides, list):
        overrides = credit.load_overrides(overrides)
    warnings = credit.apply_overrides(results, overrides or [])
    totals = report.student_totals(results)
    per_nb: dict = {}
    for res in results:
        if res.get("notebook"):
            mx = sum(r.get("max_points", 0) for r in res["rows"])
            per_nb[res["notebook"]] = max(per_nb.get(res["notebook"], 0), mx)
    possible = float(points_possible) if points_possible is not None else sum(per_nb.values())
    ident: dict = {}
    if roster is not None:
        with open(roster, newline="", encoding="utf-8-sig") as f:
            for row in csv.DictReader(f):
                for col in CANVAS_IDENTITY[:4]:
                    v = (row.get(col) or "").strip()
                    if v and v != "Points Possible":
                        ident.setdefault(v, {c: (row.get(c) or "").strip() for c in CANVAS_IDENTITY})
    rows = [CANVAS_IDENTITY + [assignment], ["Points Possible", "", "", "", ""] + [possible]]
    for sid in sorted(totals):
        t = totals[sid]
        who = ident.get(sid)
        if roster is not None and who is None:
            warnings.append(f"{sid}: not in the roster {roster}; left out")
            continue
        who = who or dict.fromkeys(CANVAS_IDENTITY, "") | {id_column: sid}
        score = t["points"]  # a number: report.csv_text keeps it one
        if t["pending"] and not include_pending:
            warnings.append(f"{sid}: pending {' '.join(t['pending'])}: left blank (ungraded in Canvas)")
            score = ""
        rows.append([who[c] for c in CANVAS_IDENTITY] + [score])
    report.atomic_write(Path(out), report.csv_text(rows))  # text cells neutralised (OWASP's rule)
    return warnings


# ----------------------------------------------------------------------------------------- entry point


def main(argv=None) -> int:
    """``python -m kinlib.course.lms.bundles run gradescope|prairielearn [--root R] [--bundle B]`` (inside the platform).

    Always writes a results file: a failure of the grader becomes an error result (and exit status 1).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:  # no grader bundle there
    ...     main(["run", "prairielearn", "--root", d])
    ...     json.loads((Path(d) / "results" / "results.json").read_text())["gradable"]
    1
    False
    """
    import argparse

    ap = argparse.ArgumentParser(prog="python -m kinlib.course.lms.bundles")
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("platform", choices=sorted(_ROOTS))
    r.add_argument("--root", type=Path, default=None)
    r.add_argument("--bundle", type=Path, default=None)
    args = ap.parse_args(argv)
    try:
        run_platform(args.platform, args.root, args.bundle)
    except Exception as exc:  # noqa: BLE001  the platform must get a results file whatever happens
        env, default = _ROOTS[args.platform]
        root = Path(args.root or os.environ.get(env) or default)
        msg = f"the autograder failed: {type(exc).__name__}: {exc}"
        if "bwrap" in msg or "sandbox" in msg:
            msg += (
                " (the platform's container cannot run bubblewrap: build the bundle again with --no-sandbox; "
                "each submission already runs in a container of its own)"
            )
        print(msg, file=sys.stderr)
        out = (
            {"score": 0.0, "output": msg, "tests": [], "stdout_visibility": "hidden"}
            if args.platform == "gradescope"
            else {"gradable": False, "format_errors": [msg], "message": msg, "tests": []}
        )
        dest = root / "results" / "results.json"
        dest.parent.mkdir(parents=True, exist_ok=True)
        dest.write_text(json.dumps(out, indent=1) + "\n")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
