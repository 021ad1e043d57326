"""The ``kinlib`` command: ``kinlib handouts ...``, ``kinlib grade ...``, ``kinlib --version``.

    kinlib handouts notebooks --out build/handouts [--jobs 2] [--timeout 120] [--no-verify] [--only 05] [--fresh]
    kinlib execute notebooks [--timeout 600]      (run notebooks in place, saving widget state: make notebooks)
    kinlib grade SUBMISSIONS... --out build/grades [--jobs 2] [--timeout 300] [--cell-timeout 60]
                 [--id-pattern REGEX] [--root DIR] [--overrides FILE] [--fresh]
                 [--memory 2G] [--processes 256] [--disk 512M] [--batch-timeout S]
    kinlib grade gradescope --out autograder.zip [--only 05] [--visibility visible] [--no-sandbox]
    kinlib grade prairielearn --out build/prairielearn [--only 05]
    kinlib grade canvas build/grades --assignment "Problem Set 4" --out canvas.csv [--roster export.csv]

(``gradescope``, ``prairielearn`` and ``canvas`` right after ``grade`` are platforms, :mod:`kinlib.course.lms.bundles`;
a submissions folder with one of those names is given as ``./gradescope``.)

The console script (``kinlib = "kinlib.course.cli:main"``); ``python -m kinlib.course`` is the same.
Usage errors exit with status 2 and a one-line message; the subcommands are imported only when run.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

__all__ = ["main", "build_parser"]

PROG = "kinlib"


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line on stderr (then exit status 2)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a whole number: {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text}")
    return value


def _size(text: str) -> int:
    from .grader.isolation.limits import parse_size

    try:
        return parse_size(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split())


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``kinlib`` command and its subcommands.

    >>> build_parser().parse_args(["grade", "subs", "--out", "o", "--jobs", "3"]).jobs
    3
    >>> build_parser().parse_args(["handouts", "notebooks", "--only", "05"]).only
    ['05']
    """
    from kinlib import __version__

    ap = _Parser(prog=PROG, description="kinlib course tools: handouts for the notebooks, and grading.")
    ap.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", required=True)

    h = sub.add_parser(
        "handouts",
        help="HTML handouts, student workbooks and an index, from the notebooks",
        description="HTML handouts (problems, solutions), student workbooks and an index, "
        "from the executed notebooks; every page works offline.",
    )
    h.add_argument("notebooks", type=Path, help="folder with the NN_*.ipynb notebooks")
    h.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default build/handouts, or build/handouts-students with --audience students)",
    )
    h.add_argument(
        "--audience",
        choices=("all", "students"),
        default="all",
        help="all: problems, solutions and workbooks (for instructors); students: no solution page, PDF or "
        "notebook anywhere (the folder to publish to students)",
    )
    h.add_argument("--vendor", type=Path, default=None, help="cache of npm packages (default: OUT/../vendor)")
    h.add_argument("--jobs", type=int, default=2, help="notebooks executed at once (default 2)")
    h.add_argument("--timeout", type=int, default=120, help="seconds allowed per cell (default 120)")
    h.add_argument(
        "--no-verify", dest="verify", action="store_false", help="do not run the workbooks after writing them"
    )
    h.add_argument("--only", nargs="*", help="only notebooks whose name starts with these (e.g. 05)")
    h.add_argument(
        "--no-site", dest="site", action="store_false", help="do not build the in-browser site (OUT/lite, JupyterLite)"
    )
    h.add_argument("--no-pdf", dest="pdfs", action="store_false", help="do not print the PDFs (OUT/pdf, chromium)")
    h.add_argument(
        "--fresh",
        action="store_true",
        help="build everything again (default: reuse each section, the site and each PDF whose inputs did not change)",
    )
    h.add_argument(
        "--reuse-from",
        type=Path,
        default=None,
        help="with --audience students: a full build of the same notebooks (e.g. build/handouts) whose current "
        "sections and PDFs are copied instead of made again (never a solution)",
    )
    h.add_argument("--serve", action="store_true", help="then serve OUT on http://127.0.0.1:PORT/ (Ctrl-C stops)")
    h.add_argument("--port", type=int, default=8000, help="port for --serve (default 8000; loopback only)")
    h.set_defaults(run=_handouts, parser=h)

    x = sub.add_parser(
        "execute",
        help="run notebooks top to bottom and save them in place, with their widget state",
        description="Run each notebook in a fresh kernel and save it in place with its outputs and widget "
        "state (deterministic ids), so that it opens with pictures; a failing notebook is left unchanged.",
    )
    x.add_argument("paths", nargs="+", type=Path, help="notebooks, or folders (their NN_*.ipynb)")
    x.add_argument("--timeout", type=_positive_float, default=600.0, help="seconds allowed per cell (default 600)")
    x.set_defaults(run=_execute, parser=x)

    g = sub.add_parser(
        "grade",
        help="grade completed workbooks against the solution notebooks",
        description="Grade completed kinlib workbooks against the solution notebooks: writes "
        "OUT/grades.csv and OUT/feedback/<submission>.md.",
    )
    g.add_argument(
        "submissions",
        nargs="*",
        help="submission notebooks, or folders (every .ipynb inside); none: only rewrite OUT's class files "
        "(after editing the overrides)",
    )
    g.add_argument("--out", required=True, type=Path, help="output folder (grades.csv, feedback/)")
    g.add_argument(
        "--timeout", type=_positive_float, default=300.0, help="seconds allowed per submission (default 300)"
    )
    g.add_argument("--cell-timeout", type=_positive_float, default=60.0, help="seconds allowed per cell (default 60)")
    g.add_argument(
        "--jobs",
        type=_positive_int,
        default=min(2, os.cpu_count() or 1),
        help="submissions graded at once (default: 2 or the number of cores)",
    )
    g.add_argument(
        "--notebooks",
        type=Path,
        default=None,
        help="folder of solution notebooks (default: the repository's notebooks/)",
    )
    g.add_argument(
        "--cache",
        type=Path,
        default=None,
        help="reference cache folder (default: build/grade-cache next to the notebooks folder)",
    )
    g.add_argument("--quiet", action="store_true", help="print only the summary table")
    g.add_argument(
        "--no-sandbox",
        action="store_true",
        help="run student code WITHOUT the bubblewrap sandbox (said in every feedback page and the summary)",
    )
    g.add_argument(
        "--secret",
        type=Path,
        default=None,
        help="grader secret file (default ~/.config/kinlib/grader-secret, created on first use, mode 0600)",
    )
    _add_class_options(g)
    g.add_argument(
        "--root",
        type=Path,
        default=None,
        help="the submissions root student ids are read relative to, for files given by themselves "
        "(default: the folder given, or the one remembered in OUT/class.json)",
    )
    g.add_argument("--memory", type=_size, default="2G", help="memory per submission, all its processes (default 2G)")
    g.add_argument("--processes", type=_positive_int, default=256, help="processes per submission (default 256)")
    g.add_argument(
        "--disk",
        type=_size,
        default="512M",
        help="bytes a submission may write in all, /tmp and /dev/shm included (default 512M)",
    )
    g.add_argument(
        "--batch-timeout",
        type=_positive_float,
        default=None,
        help="seconds for the whole batch; submissions not graded by then are reported as infrastructure "
        "(default: no limit beyond each submission's)",
    )
    g.add_argument(
        "--variants",
        type=Path,
        default=None,
        metavar="KEY.json",
        help="per-student variants: the signed key (kinlib handouts --variants); each submission is judged against "
        "the variant of its student id (its file/folder name, --id-pattern; never the notebook's metadata); a key "
        "that does not verify with --secret is refused",
    )
    g.add_argument(
        "--fresh",
        action="store_true",
        help="forget the results kept in OUT (default: merge, so grading one student replaces only their rows)",
    )
    g.set_defaults(run=_grade, parser=g)
    return ap


def _add_class_options(p) -> None:
    p.add_argument(
        "--id-pattern",
        default=None,
        metavar="REGEX",
        help="student id: this pattern matched from the start of the submission's path relative to the "
        "submissions root (group 'id', else group 1); a path it does not fit keeps that path as its id; "
        r"default: the path without .ipynb. E.g. one folder per student: '([^/]+)/[^/]+$'",
    )
    p.add_argument(
        "--overrides",
        type=Path,
        default=None,
        help="instructor's overrides, CSV or TOML: student_id, part (5.2, 4.1/joint_c, 5.2/drawing), score, "
        "comment (default: OUT/overrides.toml or OUT/overrides.csv if present)",
    )


_LMS = ("gradescope", "prairielearn", "canvas")


def build_lms_parser() -> argparse.ArgumentParser:
    """The parser of ``kinlib grade gradescope|prairielearn|canvas`` (:mod:`kinlib.course.lms.bundles`).

    >>> a = build_lms_parser().parse_args(["gradescope", "--out", "ag.zip", "--only", "05"])
    >>> a.platform, a.only, a.visibility
    ('gradescope', ['05'], 'visible')
    >>> build_lms_parser().parse_args(["canvas", "build/grades", "--assignment", "PS4", "--out", "c.csv"]).id_column
    'ID'
    """
    from .lms.bundles import VISIBILITIES

    ap = _Parser(prog=f"{PROG} grade", description="Grading on the platforms a class already uses.")
    sub = ap.add_subparsers(dest="platform", metavar="PLATFORM", required=True)
    for name, what in (
        ("gradescope", "a Gradescope autograder.zip (setup.sh, run_autograder, the references as data)"),
        ("prairielearn", "a PrairieLearn external grader: OUT/serverFilesCourse/kinlib_grader/ and info.json options"),
    ):
        b = sub.add_parser(name, help=what, description=f"Write {what}; the same grading core runs inside.")
        b.add_argument("--out", required=True, type=Path, help="the zip (gradescope) or folder (prairielearn)")
        b.add_argument("--notebooks", type=Path, default=None, help="folder of solution notebooks")
        b.add_argument("--cache", type=Path, default=None, help="reference cache folder")
        b.add_argument("--only", nargs="*", help="only notebooks whose name starts with these (e.g. 05)")
        b.add_argument("--timeout", type=_positive_float, default=300.0, help="seconds per submission")
        b.add_argument("--cell-timeout", type=_positive_float, default=60.0, help="seconds per cell")
        b.add_argument("--secret", type=Path, default=None, help="the instructor's grader secret file")
        b.add_argument(
            "--no-sandbox",
            action="store_true",
            help="run student code without bubblewrap inside the platform's container (every result says so)",
        )
        b.add_argument(
            "--variants",
            type=Path,
            default=None,
            metavar="KEY.json",
            help="per-student variants: the signed key goes into the bundle; each submission is judged against the "
            + (
                "variant of the platform's student id (submission_metadata.json users[0]: sid, else email)"
                if name == "gradescope"
                else "variant of the id in the submitted file's name (PrairieLearn tells an external grader no "
                "student identity: see kinlib.course.lms.bundles)"
            ),
        )
        if name == "gradescope":
            b.add_argument("--visibility", choices=VISIBILITIES, default="visible", help="of every test")
        else:
            b.add_argument(
                "--image",
                default=None,
                help="the grading image's Docker Hub name (build it from OUT/image/; default kinlib/grader:VERSION)",
            )
        b.set_defaults(run=_lms_bundle, parser=b)
    c = sub.add_parser(
        "canvas",
        help="a Canvas gradebook import CSV from a class folder",
        description="Write a Canvas gradebook import CSV (Student, ID, SIS User ID, SIS Login ID, Section, "
        "the assignment; a Points Possible row) from the class folder of kinlib grade --out.",
    )
    c.add_argument("grades", type=Path, help="the class folder (kinlib grade --out)")
    c.add_argument("--assignment", required=True, help="the Canvas assignment's column name")
    c.add_argument("--out", required=True, type=Path, help="the CSV to write")
    c.add_argument("--id-column", default="ID", choices=["Student", "ID", "SIS User ID", "SIS Login ID"])
    c.add_argument("--roster", type=Path, default=None, help="a Canvas gradebook export, to fill names/sections")
    c.add_argument("--overrides", type=Path, default=None, help="overrides file (default: the class folder's)")
    c.add_argument("--include-pending", action="store_true", help="upload totals with manual parts pending")
    c.add_argument("--points-possible", type=_positive_float, default=None, help="(default: from the notebooks)")
    c.set_defaults(run=_lms_canvas, parser=c)
    return ap


def _lms_bundle(args) -> int:
    from .lms import bundles as lms

    kw = dict(
        notebooks=args.notebooks,
        only=args.only,
        cache=args.cache if args.cache else "default",
        secret=args.secret,
        sandbox=not args.no_sandbox,
        timeout=args.timeout,
        cell_timeout=args.cell_timeout,
        log=lambda s: print(s, flush=True),
        variants=args.variants,
    )
    try:
        if args.platform == "gradescope":
            path = lms.gradescope_zip(args.out, visibility=args.visibility, **kw)
        else:
            path = lms.prairielearn_dir(args.out, image=args.image, **kw)
    except (RuntimeError, ValueError, OSError) as exc:
        print(f"{PROG} grade {args.platform}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    print(f"wrote {path}")
    return 0


def _lms_canvas(args) -> int:
    from .lms.bundles import canvas_csv

    try:
        warnings = canvas_csv(
            args.grades,
            args.assignment,
            args.out,
            id_column=args.id_column,
            roster=args.roster,
            include_pending=args.include_pending,
            overrides=args.overrides,
            points_possible=args.points_possible,
        )
    except (ValueError, OSError) as exc:
        print(f"{PROG} grade canvas: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    for w in warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(f"wrote {args.out}")
    return 0


def _execute(args) -> int:
    from .publish.execute import execute_all

    try:
        failures = execute_all(args.paths, timeout=args.timeout, log=lambda s: print(s, flush=True))
    except FileNotFoundError as exc:
        args.parser.error(str(exc))
    for f in failures:
        print(f"{PROG} execute: FAILED: {f}", file=sys.stderr)
    return 1 if failures else 0


def _handouts(args) -> int:
    from .publish.handouts import NotebookFailed, build

    if args.out is None:
        args.out = Path("build/handouts-students" if args.audience == "students" else "build/handouts")
    try:
        build(
            args.notebooks,
            args.out,
            vendor=args.vendor,
            jobs=args.jobs,
            timeout=args.timeout,
            verify=args.verify,
            only=args.only,
            site=args.site,
            pdfs=args.pdfs,
            fresh=args.fresh,
            audience=args.audience,
            reuse_from=args.reuse_from,
            log=lambda s: print(s, flush=True),
        )
    except NotebookFailed as e:  # names the notebook and the cell, with the cell's first lines
        print(f"{PROG} handouts: FAILED: {e}", file=sys.stderr)
        return 1
    except (RuntimeError, FileNotFoundError, ValueError) as e:
        print(f"{PROG} handouts: error: {_one_line(e)}", file=sys.stderr)
        return 2
    if args.serve:  # a local look at the site: loopback only; any static web host serves the folder as well
        from .publish.lite import serve

        serve(args.out, args.port)
    return 0


def _grade(args) -> int:
    from .grader.grade import SandboxUnavailable, grade_batch
    from .grader.intake import find_submissions
    from .grader.isolation.limits import Limits
    from .grader.report import summary_table

    if not args.submissions:
        return _rewrite_class_files(args)
    try:
        subs = find_submissions(args.submissions)  # usage errors now; grade_batch finds them again (ids: their roots)
    except FileNotFoundError as exc:
        args.parser.error(str(exc))
    if args.notebooks is not None and not args.notebooks.is_dir():
        args.parser.error(f"--notebooks {args.notebooks} is not a folder")
    if not subs:
        print(f"{PROG} grade: no .ipynb submissions found", file=sys.stderr)
    log = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    from .grader import credit, report

    if args.id_pattern is not None:
        try:
            re.compile(args.id_pattern)
        except re.error as exc:
            args.parser.error(f"--id-pattern {args.id_pattern!r} is not a regular expression: {exc}")
    overrides = args.overrides or report.default_overrides(args.out)
    try:
        overrides = credit.load_overrides(overrides) if overrides is not None else []
    except (ValueError, OSError) as exc:
        print(f"{PROG} grade: overrides: {_one_line(exc)}", file=sys.stderr)
        return 2
    try:
        summary = grade_batch(
            args.submissions,
            args.out,
            jobs=args.jobs,
            timeout=args.timeout,
            cell_timeout=args.cell_timeout,
            notebooks=args.notebooks,
            cache=args.cache if args.cache else "default",
            log=log,
            sandbox=not args.no_sandbox,
            secret=args.secret,
            id_pattern=args.id_pattern,
            overrides=overrides,
            merge=not args.fresh,
            root=args.root,
            batch_timeout=args.batch_timeout,
            limits=Limits(memory_bytes=args.memory, processes=args.processes, disk_bytes=args.disk),
            variants=args.variants,
        )
    except (SandboxUnavailable, ValueError) as exc:  # no sandbox here, or an unsafe/unreadable secret file
        print(f"{PROG} grade: {_one_line(exc)}", file=sys.stderr)
        return 2
    if args.quiet:
        print(summary_table(summary["results"], summary["seconds"], summary["reference_seconds"], args.jobs))
    print(f"wrote {args.out / 'grades.csv'} and {len(summary['results'])} feedback file(s) in {args.out / 'feedback'}")
    if summary.get("infrastructure_errors"):
        print(
            f"{PROG} grade: {summary['infrastructure_errors']} submission(s) not graded: infrastructure "
            "(a kernel could not start); run them again",
            file=sys.stderr,
        )
        return 1
    return 0


def _rewrite_class_files(args) -> int:
    """``kinlib grade --out OUT`` without submissions: grades.csv, totals.csv and feedback again from the
    results kept in OUT, with the overrides as they are now."""
    from .grader import report

    if not report.load_results(args.out):
        args.parser.error(f"no submissions given, and no graded results kept in {args.out / 'results'}")
    try:
        warnings = report.write_outputs(
            args.out,
            [],
            id_pattern=args.id_pattern,
            overrides=args.overrides,
            log=lambda s: print(s, flush=True),
        )
    except (ValueError, OSError) as exc:
        print(f"{PROG} grade: overrides: {_one_line(exc)}", file=sys.stderr)
        return 2
    print(f"rewrote {args.out / 'grades.csv'}, totals.csv and feedback/ ({len(warnings)} override warning(s))")
    return 0


def main(argv=None) -> int:
    """Run the ``kinlib`` command with ``argv`` (default: the command line); returns the exit status.

    ``kinlib handouts`` returns 0, 1 when a notebook fails (named with its cell) or 2 for another error;
    ``kinlib grade`` returns 0 when the batch ran (whatever the grades), 1 when some submission could not be
    graded for an infrastructure failure (a kernel that would not start), 2 without a usable sandbox (unless
    ``--no-sandbox``) or secret. Usage errors raise
    SystemExit(2) after a one-line message, ``--help`` and ``--version`` SystemExit(0).

    >>> try:
    ...     main(["--version"])
    ... except SystemExit as e:
    ...     print("exit status", e.code)     # doctest: +ELLIPSIS
    kinlib ...
    exit status 0
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    if len(argv) >= 2 and argv[0] == "grade" and argv[1] in _LMS:  # kinlib grade gradescope|prairielearn|canvas
        args = build_lms_parser().parse_args(argv[1:])
        args.command = f"grade {args.platform}"
    else:
        args = build_parser().parse_args(argv)
    try:
        return args.run(args)
    except ImportError as exc:  # kinlib installed without its course extra
        missing = getattr(exc, "name", None) or _one_line(exc)
        print(
            f"{PROG} {args.command}: needs the course tools (missing {missing}); "
            f"install them with: pip install 'kinlib[course]'",
            file=sys.stderr,
        )
        return 2
