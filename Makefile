# Each target bootstraps .venv from scratch if it is missing, then runs.
# `make demo` installs the package alone (its runtime dependencies); `make test` and
# `make dev` add what the tests need (the `test` extra); `make test` runs every test (CI),
# `make quick` all but the `slow` ones (pytest -m "not slow", a few minutes); JOBS=auto (or
# a number) spreads either over that many processes (pytest-xdist); `make docs` adds the
# `docs` extra and builds the site (warnings are errors) into docs/_build/html; `make bench`
# runs the benchmarks and rewrites the tables of docs/performance.md.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
DOCS_STAMP := $(VENV)/.installed-docs
# pytest-xdist workers for `make test`/`make quick` (empty: one process)
JOBS ?=
XDIST := $(if $(JOBS),-n $(JOBS),)
SOURCES := pyproject.toml setup.py $(wildcard */__init__.py)

.PHONY: demo dev test quick docs bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(SOURCES) | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e .
	touch $(STAMP)

$(TEST_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(TEST_STAMP)

$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/appdyn demo

dev: $(TEST_STAMP)

test: $(TEST_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q $(XDIST)

quick: $(TEST_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q -m "not slow" $(XDIST)

docs: $(DOCS_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m sphinx -b html -W --keep-going -j 2 docs docs/_build/html

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/appdyn bench --docs

clean:
	rm -rf $(VENV) build *.egg-info docs/_build docs/api docs/auto_examples
