# Two commands for a newcomer: `make demo` and `make test` (both set up .venv first).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=

.PHONY: setup demo test test-all bench clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: setup
	$(VENV)/bin/navsim run scenarios/demo.toml --out reports/out/demo --report reports/out/demo.pdf

test: setup
	$(PY) -m pytest $(PYTEST_ARGS)

# The full suite including the slow statistical tests.
test-all: setup
	$(PY) -m pytest -m "" $(PYTEST_ARGS)

bench: setup
	sh benchmarks/peers/setup_venvs.sh $(PYTHON)
	$(PY) -m pip install --quiet -e '.[test,bench]'
	$(PY) benchmarks/run_all.py

clean:
	rm -rf $(VENV) .cache .pytest_cache .hypothesis reports/out benchmarks/.venv-cedar benchmarks/.venv-tetra3rs benchmarks/work
