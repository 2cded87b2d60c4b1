# Two commands for a newcomer: `make demo` and `make test` (both set up .venv first).
# The set-up installs the locked versions (requirements/*.txt, exact versions with hashes, Python 3.11 on
# Linux x86-64) with uv, itself installed hash-checked by pip, byte-compiled at install (a machine with
# PYTHONDONTWRITEBYTECODE would otherwise compile every module of scipy & co. in every process: +3.5 s);
# `make lock` regenerates the locks from pyproject.toml's ranges (README).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
UV := $(VENV)/bin/uv
STAMP := $(VENV)/.installed
PYTEST_ARGS ?=
LOCK := $(UV) pip compile --quiet --generate-hashes --python-version 3.11 --python-platform x86_64-unknown-linux-gnu

.PHONY: setup demo test test-all bench lock clean

setup: $(STAMP)

$(UV): requirements/bootstrap.txt
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check --require-hashes --no-deps -r requirements/bootstrap.txt
	touch $(UV)

$(STAMP): pyproject.toml requirements/test.txt $(UV)
	$(UV) pip install --quiet --python $(PY) --compile-bytecode --require-hashes -r requirements/test.txt
	$(UV) pip install --quiet --python $(PY) --no-deps --no-build-isolation -e .
	$(PY) -m compileall -q startrack navsim > /dev/null
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
	$(UV) pip install --quiet --python $(PY) --compile-bytecode --require-hashes -r requirements/bench.txt
	$(PY) benchmarks/run_all.py

# Regenerate the locks from pyproject.toml's ranges (newest versions that satisfy them), then `make setup`.
lock: $(UV)
	$(LOCK) pyproject.toml requirements/build.in --extra test -o requirements/test.txt
	$(LOCK) pyproject.toml requirements/build.in --extra test --extra bench -o requirements/bench.txt
	$(LOCK) requirements/bootstrap.in -o requirements/bootstrap.txt

clean:
	rm -rf $(VENV) .cache .pytest_cache .hypothesis reports/out benchmarks/.venv-cedar benchmarks/.venv-tetra3rs benchmarks/work
