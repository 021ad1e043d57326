"""The scripts a bundle carries, as templates (``@VENV@``, ``@USER@``, ``@SANDBOX@``, ``@IMAGE@`` filled in by
:mod:`kinlib.course.lms.bundles`): one ``setup.sh`` for Gradescope's image and PrairieLearn's, the two platforms'
entry points, and PrairieLearn's ``Dockerfile``.

>>> "useradd" in SETUP_SH and "@VENV@" in RUN_PL
True
"""

SETUP_SH = r"""#!/usr/bin/env bash
# Builds the grading environment once, as root: Gradescope runs it when it builds the autograder's image,
# PrairieLearn's image runs it from its Dockerfile. It makes a Python venv with exactly what the workbooks and the
# grader import (requirements.txt, pinned by constraints.txt; derived from the code by kinlib.course.lms.environment)
# plus this bundle's own copy of kinlib, and the unprivileged user the student's kernels run as where bubblewrap
# cannot (Docker's default seccomp profile blocks its namespaces).
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
VENV="${KINLIB_VENV:-@VENV@}"
STUDENT="${KINLIB_STUDENT_USER:-@USER@}"
PY="${KINLIB_SETUP_PYTHON:-python3}"
need=()
"$PY" -c 'import sys, venv, ensurepip; sys.exit(sys.version_info < (3, 11))' 2>/dev/null || need+=(python3 python3-venv)
command -v useradd >/dev/null || need+=(passwd)
[ "@SANDBOX@" = 1 ] && ! command -v bwrap >/dev/null && need+=(bubblewrap)
if [ "${#need[@]}" -gt 0 ]; then
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${need[@]}"
  PY=python3
fi
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' || {
  echo "kinlib needs Python >= 3.11: choose a base image with Ubuntu 24.04 (or python:3.11)" >&2; exit 1; }
"$PY" -m venv "$VENV"
pip=("$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-compile)
"${pip[@]}" -r "$HERE/requirements.txt" -c "$HERE/constraints.txt"
"${pip[@]}" --no-deps "$HERE/kinlib-src"
# byte-compiled once, here, as root: the student's kernels run with -B as a user who cannot write the venv, so a module
# without its .pyc would be compiled again in every kernel. The distributions' own test suites (a fifth of the code,
# never imported by a kernel) are left out, and the work is spread over the cores (pip would compile file by file).
compile=("$VENV/bin/python" -m compileall -q -x '/tests/' "$VENV/lib")
"${compile[@]}" -j 0 >/dev/null 2>&1 || "${compile[@]}" >/dev/null || echo "some files did not byte-compile" >&2
# every module the workbooks and the grader import must import now, not in a student's grade
"$VENV/bin/python" -I -c 'import importlib, sys; [importlib.import_module(m) for m in sys.argv[1:]]' \
  kinlib $(cat "$HERE/imports.txt")
id -u "$STUDENT" >/dev/null 2>&1 || useradd --system --user-group --no-create-home --home-dir /nonexistent \
  --shell /usr/sbin/nologin "$STUDENT"
echo "kinlib grading environment ready: $VENV (student user $STUDENT)"
"""

RUN_AUTOGRADER = r"""#!/usr/bin/env bash
# Gradescope runs this for every submission, as root: /autograder/submission -> /autograder/results/results.json
ROOT="${KINLIB_AUTOGRADER_ROOT:-/autograder}"
PY="${KINLIB_PYTHON:-$ROOT/venv/bin/python}"
cd "$ROOT"
if [ ! -x "$PY" ]; then
  mkdir -p "$ROOT/results"
  echo '{"score": 0, "output": "the autograder is broken: its environment is missing (setup.sh did not run)", "tests": []}' \
    > "$ROOT/results/results.json"
  exit 1
fi
exec "$PY" -I -m kinlib.course.lms.bundles run gradescope --root "$ROOT" --bundle "$ROOT/source"
"""

RUN_PL = r"""#!/usr/bin/env bash
# PrairieLearn's entrypoint, as root in the course's image (image/Dockerfile): /grade/student -> /grade/results/results.json
ROOT="${KINLIB_GRADE_ROOT:-/grade}"
HERE="$ROOT/serverFilesCourse/kinlib_grader"
PY="${KINLIB_PYTHON:-@VENV@/bin/python}"
mkdir -p "$ROOT/results"
if [ ! -x "$PY" ]; then
  echo '{"gradable": false, "format_errors": ["the grader image has no kinlib environment: build it from image/Dockerfile and name it in externalGradingOptions.image"], "tests": []}' \
    > "$ROOT/results/results.json"
  exit 1
fi
exec "$PY" -I -m kinlib.course.lms.bundles run prairielearn --root "$ROOT" --bundle "$HERE"
"""

DOCKERFILE = """# PrairieLearn's grading image for this bundle (External Grading runs a course's own image from Docker Hub):
#   docker build -t @IMAGE@ . && docker push @IMAGE@      (in this folder; then sync the course's Docker images)
# This folder holds no answers and no key: those stay in serverFilesCourse/kinlib_grader/.
FROM python:3.11-slim-bookworm
COPY . /opt/kinlib/image
RUN KINLIB_VENV=@VENV@ bash /opt/kinlib/image/setup.sh && rm -rf /root/.cache
"""

GS_VENV = "/autograder/venv"
PL_VENV = "/opt/kinlib/venv"
PL_IMAGE = "kinlib/grader:{version}"  # a placeholder name: push the image to your own Docker Hub account
