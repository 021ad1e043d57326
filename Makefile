# kinlib: every target sets up .venv from environment.txt first (when missing or out of date).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check
STAMP  := $(VENV)/.installed
NOTEBOOKS := $(sort $(wildcard notebooks/[0-9][0-9]_*.ipynb))
PYTEST_ARGS ?=
# Parallel tests (pytest-xdist): 2 workers by default; every test file is a group run whole by one worker, the
# browser modules are one group together (--dist loadgroup; tests/conftest.py); the real handouts are built once
# per run under a file lock. Measured on this 2-core machine, shared (issue 24): tests/core (3 files) +
# tests/notebooks, serial 163 s wall / 80 s CPU vs -n 2 92–108 s wall / 93–95 s CPU. `make test TEST_JOBS=1`: no xdist.
TEST_JOBS ?= 2
# Which tests test-fast runs: the folder of the layer you changed (tests/core, tests/pictures, tests/course,
# tests/notebooks, tests/project), e.g. `make test-fast TESTS=tests/core`. Default: all of them.
TESTS ?= tests
XDIST := $(if $(filter-out 1,$(TEST_JOBS)),-n $(TEST_JOBS) --dist loadgroup)

.PHONY: all setup lab-extensions lint format test test-fast lab lab-students notebooks handouts grade bench lock chromium webkit poppler bubblewrap compiler clean

all: test

setup: $(STAMP) lab-extensions

# The JupyterLite kernel's front end (jupyterlite-pyodide-kernel installs it into .venv/share/jupyter/labextensions)
# runs only inside JupyterLite: in JupyterLab (`make lab`) it fails to load ("Shared module @jupyterlite/server
# doesn't exist in shared scope default", a console error on every page) and JupyterLab loads every extension in its
# path, disabled or not. It is moved out of that path to where the site's build reads it
# (kinlib.course.publish.lite.kernel_extension); again after pip reinstalls it.
LITE_LABEXT := $(VENV)/share/jupyter/labextensions/@jupyterlite/pyodide-kernel-extension
LITE_LABEXT_KEPT := $(VENV)/share/kinlib/lite-labextensions/@jupyterlite/pyodide-kernel-extension
lab-extensions: $(STAMP)
	@if [ -d $(LITE_LABEXT) ]; then rm -rf $(LITE_LABEXT_KEPT) && mkdir -p $(dir $(LITE_LABEXT_KEPT)) \
	    && mv $(LITE_LABEXT) $(LITE_LABEXT_KEPT) && echo "lab-extensions: the JupyterLite kernel's extension moved out of JupyterLab's path"; fi

# The exact pins, then kinlib itself as an editable install without dependencies (that is what puts the
# `kinlib` console script into .venv/bin). Re-run when the pins or pyproject.toml change.
# pip prints one line per package (progress); its download bars are off (they flood a CI log).
$(STAMP): environment.txt pyproject.toml
	@echo "setup: .venv from environment.txt ($$(grep -c '==' environment.txt) pinned packages; about a minute with a warm pip cache)"
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip
	@{ $(PIP) install --progress-bar off -r environment.txt; echo $$? > $(VENV)/.pip-status; } \
	    | grep --line-buffered -E '^(Collecting|Installing collected|Successfully)' | cut -c1-100; \
	    test "$$(cat $(VENV)/.pip-status)" = 0 || { echo "setup: pip could not install environment.txt (above)"; exit 1; }
	$(PIP) install --quiet --no-deps --no-build-isolation -e .
	@touch $@

# Lint and format check (ruff, configured in pyproject.toml: kinlib/, tests/, bench/; never the notebooks).
# `make format` applies ruff's safe fixes and formats in place.
lint: $(STAMP)
	$(VENV)/bin/ruff check
	$(VENV)/bin/ruff format --check

format: $(STAMP)
	$(VENV)/bin/ruff check --fix
	$(VENV)/bin/ruff format

# Debian's chromium for the browser tests (never a downloaded browser build).
chromium:
	@command -v chromium >/dev/null 2>&1 || { \
	  echo "installing Debian's chromium for the browser tests"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq chromium >/dev/null; }

# The second browser engine of the browser tests: Debian's WebKitGTK, driven from Debian's python3 (GObject
# introspection) under Xvfb (tests/webkit_run.py, tests/course/test_second_engine.py).
webkit:
	@{ command -v xvfb-run >/dev/null 2>&1 && /usr/bin/python3 -c "import gi; gi.require_version('WebKit2', '4.1')" 2>/dev/null; } || { \
	  echo "installing Debian's WebKitGTK, python3-gi and xvfb for the second-engine tests"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq gir1.2-webkit2-4.1 python3-gi xvfb >/dev/null; }

# Debian's poppler-utils (pdftotext, pdfinfo, pdftoppm): tests/course/test_print.py reads the handout PDFs with them.
poppler:
	@command -v pdftotext >/dev/null 2>&1 || { \
	  echo "installing Debian's poppler-utils for the PDF tests"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq poppler-utils >/dev/null; }

# Debian's bubblewrap: the sandbox every student kernel runs in (kinlib.course.grader.isolation.sandbox); `kinlib grade`
# refuses to grade without it unless given --no-sandbox.
bubblewrap:
	@command -v bwrap >/dev/null 2>&1 || { \
	  echo "installing Debian's bubblewrap for the grader's sandbox"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq bubblewrap >/dev/null; }

# A C compiler for kinlib's compiled single calls (kinlib/native.py; without one kinlib runs its Python code) and
# their tests (tests/core/test_native.py): Debian's gcc where no cc is found. Python.h comes with pyenv's Python
# (a Debian python3 would need python3-dev).
compiler:
	@command -v cc >/dev/null 2>&1 || command -v gcc >/dev/null 2>&1 || { \
	  echo "installing Debian's gcc for kinlib's compiled code"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq gcc libc6-dev >/dev/null; }
	@$(PYTHON) -c "import sysconfig, os, sys; h = os.path.join(sysconfig.get_paths()['include'], 'Python.h'); sys.exit(0 if os.path.isfile(h) else 1)" \
	  || echo "note: no Python.h for $(PYTHON): kinlib's compiled path is off (install the Python headers, e.g. python3-dev)"

# The whole suite: lint, then unit and property tests, browser tests, and nbval over every notebook.
test: $(STAMP) lab-extensions lint chromium webkit poppler bubblewrap compiler
	$(PY) -m pytest tests $(NOTEBOOKS) --nbval-lax --nbval-current-env \
	    --nbval-sanitize-with notebooks/sanitize.cfg -p no:cacheprovider --durations=15 $(XDIST) $(PYTEST_ARGS)

# Quick loop while developing: no browser, no notebooks, no slow tests, no lint (`make lint` for that).
test-fast: $(STAMP) bubblewrap compiler
	$(PY) -m pytest $(TESTS) -m "not browser and not slow" -p no:cacheprovider $(XDIST) $(PYTEST_ARGS)

# JupyterLab on notebooks/ (as root, e.g. in a container, it needs --allow-root). Extra options: make lab LAB_ARGS=--no-browser
# The course notebooks are trusted first (JupyterLab draws saved widgets only in trusted notebooks; otherwise
# it shows their text or static image), and notebooks/.lab-settings/overrides.json is used (widget state saved with
# the notebook, so a saved notebook reopens with its pictures).
LAB_ARGS ?=
lab: $(STAMP) lab-extensions
	@$(VENV)/bin/jupyter trust $(NOTEBOOKS) >/dev/null
	$(VENV)/bin/jupyter lab --notebook-dir=notebooks --LabApp.app_settings_dir=$(CURDIR)/notebooks/.lab-settings \
	    $(if $(filter 0,$(shell id -u)),--allow-root) $(LAB_ARGS)

# Students start here: JupyterLab on the student workbooks (stubs and self-checks, no solution), never on the
# solution notebooks. The workbooks are made by the students' handouts build (build/handouts-students/workbooks, made
# first if missing: no site, no PDFs) and copied into WORKBOOKS_DIR, a folder of the student's own outside the
# repository (default ~/kinlib-workbooks): a workbook already there is never overwritten (it holds the student's
# work), so a later build or `make clean` loses nothing. Extra options as for lab: LAB_ARGS=--no-browser.
WORKBOOKS_DIR ?= $(HOME)/kinlib-workbooks
STUDENT_WORKBOOKS := build/handouts-students/workbooks
lab-students: $(STAMP) lab-extensions
	@ls $(STUDENT_WORKBOOKS)/[0-9][0-9]_*.ipynb >/dev/null 2>&1 || \
	    $(VENV)/bin/kinlib handouts notebooks --out build/handouts-students --audience students --no-site --no-pdf
	@mkdir -p "$(WORKBOOKS_DIR)" && for f in $(STUDENT_WORKBOOKS)/[0-9][0-9]_*.ipynb; do \
	    test -e "$(WORKBOOKS_DIR)/$$(basename $$f)" || cp "$$f" "$(WORKBOOKS_DIR)/"; done
	@echo "lab-students: your workbooks are in $(WORKBOOKS_DIR) (your edits are saved there)"
	$(VENV)/bin/jupyter lab --notebook-dir="$(WORKBOOKS_DIR)" --LabApp.app_settings_dir=$(CURDIR)/notebooks/.lab-settings \
	    $(if $(filter 0,$(shell id -u)),--allow-root) $(LAB_ARGS)

# Execute notebooks in place (fresh kernel each, outputs + widget state, stable ids): after editing a
# notebook, `make notebooks` (all) or `make notebooks NB=notebooks/05_singularities_planar.ipynb`.
NB ?= $(NOTEBOOKS)
notebooks: $(STAMP)
	$(VENV)/bin/kinlib execute $(NB)

# Main batch job: HTML handouts (problems + solutions), student workbooks, index -> build/handouts/
# make handouts AUDIENCE=students -> build/handouts-students/: the same without any solution (page, PDF or
# notebook), the folder to publish to students; build/handouts/ is the instructors' (it has the solutions).
# Incremental: a section, the site or a PDF whose inputs did not change is reused (the log says so); the students'
# build takes the sections and PDFs that are current in build/handouts (the same bytes; never a solution).
# `make handouts ONLY=05` builds one section (ONLY="02 05": several); `make handouts FRESH=1` builds everything again.
# `make handouts VARIANTS=roster.csv`: every student their own numbers (issue 33): pages and workbooks per student
# under $(HANDOUTS_OUT)/students/<token>/, and beside it build/variants/ (the signed key for `kinlib grade
# --variants build/variants/key.json`, report.txt, links.csv with each student's page, answers/ per student).
AUDIENCE ?= all
ONLY ?=
FRESH ?=
VARIANTS ?=
HANDOUTS_OUT := $(if $(filter students,$(AUDIENCE)),build/handouts-students,build/handouts)
handouts: $(STAMP) chromium
	$(VENV)/bin/kinlib handouts notebooks --out $(HANDOUTS_OUT) --audience $(AUDIENCE) $(if $(ONLY),--only $(ONLY)) $(if $(FRESH),--fresh) \
	    $(if $(VARIANTS),--variants $(VARIANTS)) \
	    $(if $(filter students,$(AUDIENCE)),$(if $(wildcard build/handouts/index.html),--reuse-from build/handouts))

# A local look at build/handouts (the pages, the PDFs and the in-browser notebooks, lite/) on
# http://127.0.0.1:$(PORT)/ (loopback only; Ctrl-C stops); builds the handouts first if they are not there.
# `make site AUDIENCE=students`: the students' site (build/handouts-students), as they will see it.
# To publish, copy the folder to any static web host: no server-side Python.
.PHONY: site
PORT ?= 8000
site: $(STAMP)
	@test -f $(HANDOUTS_OUT)/index.html -a -f $(HANDOUTS_OUT)/lite/jupyter-lite.json || $(MAKE) handouts AUDIENCE=$(AUDIENCE)
	$(VENV)/bin/python -c "from kinlib.course.publish.lite import serve; serve('$(HANDOUTS_OUT)', $(PORT))"

# Grade a class: make grade SUBMISSIONS=path/to/folder [JOBS=2] [OUT=build/grades]
SUBMISSIONS ?= submissions
OUT ?= build/grades
JOBS ?= 2
grade: $(STAMP) bubblewrap
	$(VENV)/bin/kinlib grade $(SUBMISSIONS) --out $(OUT) --jobs $(JOBS)

# Benchmark against modern-robotics (and Pinocchio, example-robot-data's URDFs and the Robotics Toolbox, installed here as
# the optional bench extra). One section: make bench BENCH_ARGS='--only urdf' (names: python bench/bench.py --help).
BENCH_ARGS ?=
bench: $(STAMP) bubblewrap chromium compiler
	@$(PY) -c "import pinocchio, roboticstoolbox, importlib.metadata as m; m.distribution('example-robot-data')" 2>/dev/null \
	    || $(PIP) install --quiet -e '.[bench]' \
	    || echo "pin (Pinocchio), example-robot-data or roboticstoolbox-python could not be installed: the table will say so"
	$(PY) bench/bench.py --out build/bench.md $(BENCH_ARGS)

# Regenerate environment.txt from pyproject.toml: a clean temporary venv, pip install -e '.[dev]'
# (every extra but bench), pip freeze. Today's pins are kept (-c environment.txt) so notebook outputs do
# not change; only new requirements get new pins. `make lock UPGRADE=1` re-resolves everything to the newest.
LOCK_VENV := build/lock-venv
UPGRADE ?=
lock:
	rm -rf $(LOCK_VENV) && mkdir -p build
	$(PYTHON) -m venv $(LOCK_VENV)
	$(LOCK_VENV)/bin/python -m pip install --quiet --disable-pip-version-check --upgrade pip
	grep -v '^-e ' environment.txt > $(LOCK_VENV)/constraints.txt
	$(LOCK_VENV)/bin/python -m pip install --quiet --disable-pip-version-check \
	    $(if $(UPGRADE),,-c $(LOCK_VENV)/constraints.txt) -e '.[dev]'
	$(LOCK_VENV)/bin/python -m pip freeze --disable-pip-version-check --exclude-editable --all > $(LOCK_VENV)/freeze.txt
	{ echo "# GENERATED by 'make lock' from pyproject.toml (dependencies + every extra but bench): do not edit by hand."; \
	  echo "# The exact pins of the whole environment: 'make setup' installs them into .venv, then kinlib itself"; \
	  echo "# (pip install --no-deps -e .). Change requirements in pyproject.toml and run 'make lock';"; \
	  echo "# 'make lock UPGRADE=1' moves every pin to the newest version allowed (notebook outputs may change)."; \
	  grep -v '^pip==' $(LOCK_VENV)/freeze.txt; } > $(LOCK_VENV)/environment.txt
	mv $(LOCK_VENV)/environment.txt environment.txt
	rm -rf $(LOCK_VENV)

clean:
	rm -rf build .pytest_cache .hypothesis .ruff_cache
