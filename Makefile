# kinlib: every target sets up .venv from environment.txt first (when missing or out of date).
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
NOTEBOOKS := $(sort $(wildcard notebooks/[0-9][0-9]_*.ipynb))
PYTEST_ARGS ?=

.PHONY: all setup test test-fast lab handouts grade bench chromium clean

all: test

setup: $(STAMP)

$(STAMP): environment.txt pyproject.toml
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check --upgrade pip
	$(PY) -m pip install --quiet --disable-pip-version-check -r environment.txt
	@touch $@

# Debian's chromium for the browser tests (never a downloaded browser build).
chromium:
	@command -v chromium >/dev/null 2>&1 || { \
	  echo "installing Debian's chromium for the browser tests"; \
	  if [ "$$(id -u)" = 0 ]; then SUDO=; else SUDO=sudo; fi; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq chromium >/dev/null; }

# The whole suite: unit and property tests, browser tests, and nbval over every notebook.
test: $(STAMP) chromium
	$(PY) -m pytest tests $(NOTEBOOKS) --nbval-lax --nbval-current-env \
	    --nbval-sanitize-with notebooks/sanitize.cfg -p no:cacheprovider $(PYTEST_ARGS)

# Quick loop while developing: no browser, no notebooks.
test-fast: $(STAMP)
	$(PY) -m pytest tests -m "not browser and not slow" -p no:cacheprovider $(PYTEST_ARGS)

# JupyterLab on notebooks/ (as root, e.g. in a container, it needs --allow-root). Extra options: make lab LAB_ARGS=--no-browser
LAB_ARGS ?=
lab: $(STAMP)
	$(VENV)/bin/jupyter lab --notebook-dir=notebooks $(if $(filter 0,$(shell id -u)),--allow-root) $(LAB_ARGS)

# Main batch job: HTML handouts (problems + solutions), student workbooks, index -> build/handouts/
handouts: $(STAMP)
	$(PY) -m kinlib.handouts notebooks --out build/handouts

# Grade a class: make grade SUBMISSIONS=path/to/folder [JOBS=2] [OUT=build/grades]
SUBMISSIONS ?= submissions
OUT ?= build/grades
JOBS ?= 2
grade: $(STAMP)
	$(PY) -m kinlib.grade $(SUBMISSIONS) --out $(OUT) --jobs $(JOBS)

# Benchmark against modern-robotics (and Pinocchio, installed here as an optional extra).
bench: $(STAMP)
	@$(PY) -c "import pinocchio" 2>/dev/null || $(PY) -m pip install --quiet --disable-pip-version-check -e '.[bench]' \
	    || echo "pin (Pinocchio) could not be installed: the table will say so"
	$(PY) bench/bench.py --out build/bench.md

clean:
	rm -rf build .pytest_cache .hypothesis
