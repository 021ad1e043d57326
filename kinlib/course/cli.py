"""The ``kinlib`` command: ``kinlib handouts ...``, ``kinlib grade ...``, ``kinlib --version``.

    kinlib handouts notebooks --out build/handouts [--jobs 2] [--timeout 120] [--no-verify] [--only 05]
    kinlib grade SUBMISSIONS... --out build/grades [--jobs 2] [--timeout 300] [--cell-timeout 60]

The console script (``kinlib = "kinlib.course.cli:main"``); ``python -m kinlib.course`` is the same.
Usage errors exit with status 2 and a one-line message; the subcommands are imported only when run.
"""

from __future__ import annotations

import argparse
import os
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
    h.add_argument("--out", type=Path, default=Path("build/handouts"), help="output folder (default build/handouts)")
    h.add_argument("--vendor", type=Path, default=None, help="cache of npm packages (default: OUT/../vendor)")
    h.add_argument("--jobs", type=int, default=2, help="notebooks executed at once (default 2)")
    h.add_argument("--timeout", type=int, default=120, help="seconds allowed per cell (default 120)")
    h.add_argument(
        "--no-verify", dest="verify", action="store_false", help="do not run the workbooks after writing them"
    )
    h.add_argument("--only", nargs="*", help="only notebooks whose name starts with these (e.g. 05)")
    h.set_defaults(run=_handouts, parser=h)

    g = sub.add_parser(
        "grade",
        help="grade completed workbooks against the solution notebooks",
        description="Grade completed kinlib workbooks against the solution notebooks: writes "
        "OUT/grades.csv and OUT/feedback/<submission>.md.",
    )
    g.add_argument("submissions", nargs="+", help="submission notebooks, or folders (every .ipynb inside)")
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
    g.set_defaults(run=_grade, parser=g)
    return ap


def _handouts(args) -> int:
    from .handouts import NotebookFailed, build

    try:
        build(
            args.notebooks,
            args.out,
            vendor=args.vendor,
            jobs=args.jobs,
            timeout=args.timeout,
            verify=args.verify,
            only=args.only,
            log=lambda s: print(s, flush=True),
        )
    except NotebookFailed as e:  # names the notebook and the cell, with the cell's first lines
        print(f"{PROG} handouts: FAILED: {e}", file=sys.stderr)
        return 1
    except (RuntimeError, FileNotFoundError, ValueError) as e:
        print(f"{PROG} handouts: error: {_one_line(e)}", file=sys.stderr)
        return 2
    return 0


def _grade(args) -> int:
    from .grade import find_submissions, grade_batch
    from .report import summary_table

    try:
        subs = find_submissions(args.submissions)
    except FileNotFoundError as exc:
        args.parser.error(str(exc))
    if args.notebooks is not None and not args.notebooks.is_dir():
        args.parser.error(f"--notebooks {args.notebooks} is not a folder")
    if not subs:
        print(f"{PROG} grade: no .ipynb submissions found", file=sys.stderr)
    log = (lambda s: None) if args.quiet else (lambda s: print(s, flush=True))
    summary = grade_batch(
        subs,
        args.out,
        jobs=args.jobs,
        timeout=args.timeout,
        cell_timeout=args.cell_timeout,
        notebooks=args.notebooks,
        cache=args.cache if args.cache else "default",
        log=log,
    )
    if args.quiet:
        print(summary_table(summary["results"], summary["seconds"], summary["reference_seconds"], args.jobs))
    print(f"wrote {args.out / 'grades.csv'} and {len(summary['results'])} feedback file(s) in {args.out / 'feedback'}")
    return 0


def main(argv=None) -> int:
    """Run the ``kinlib`` command with ``argv`` (default: the command line); returns the exit status.

    ``kinlib handouts`` returns 0, 1 when a notebook fails (named with its cell) or 2 for another error;
    ``kinlib grade`` returns 0 whenever the batch ran, whatever the grades. Usage errors raise
    SystemExit(2) after a one-line message, ``--help`` and ``--version`` SystemExit(0).

    >>> try:
    ...     main(["--version"])
    ... except SystemExit as e:
    ...     print("exit status", e.code)     # doctest: +ELLIPSIS
    kinlib ...
    exit status 0
    """
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
