# Each target bootstraps .venv from scratch if it is missing, then runs.
# `make demo` installs the package alone (its runtime dependencies); `make test` and
# `make dev` add what the tests need (the `test` extra); `make bench` runs the benchmarks.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
TEST_STAMP := $(VENV)/.installed-test
SOURCES := pyproject.toml setup.py $(wildcard */__init__.py)

.PHONY: demo dev test bench clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): $(SOURCES) | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e .
	touch $(STAMP)

$(TEST_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(TEST_STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/appdyn demo

dev: $(TEST_STAMP)

test: $(TEST_STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

bench: $(STAMP)
	MPLBACKEND=Agg $(BIN)/appdyn bench --readme

clean:
	rm -rf $(VENV) build *.egg-info
