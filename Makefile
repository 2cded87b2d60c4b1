# Two commands for a newcomer: `make demo` and `make test` (both set up .venv first).
# The set-up installs the locked versions (requirements/*.txt, exact versions with hashes, Python 3.11 on
# Linux x86-64) with uv, itself installed hash-checked by pip: `make demo` what the product runs
# (requirements/run.txt), `make test` also the test tools (requirements/test.txt, the same versions); both
# byte-compile everything in the venv (compileall: what an earlier step or another tool installed too), since
# a machine with PYTHONDONTWRITEBYTECODE would otherwise compile numpy, scipy & co. in every process: +2-4 s
# for each `startrack solve` or `navsim` call and each process of the suite (measured, issue 32).
# `make lock` regenerates the locks from pyproject.toml's ranges (README).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
UV := $(VENV)/bin/uv
RUN_STAMP := $(VENV)/.installed-run
TEST_STAMP := $(VENV)/.installed-test
PYTEST_ARGS ?=
# The suite runs on this many processes (pytest-xdist; a module's tests stay together, so its fixtures are built
# once) sharing one cache folder, the kernels compiled ahead once by the first of them (tests/conftest.py): 5.6 min
# on a fresh 2-core machine (12.5-14.3 min on a slower one). TEST_WORKERS=0 runs it in this process.
TEST_WORKERS ?= 2
LOCK := $(UV) pip compile --quiet --generate-hashes --python-version 3.11 --python-platform x86_64-unknown-linux-gnu
INSTALL := $(UV) pip install --quiet --python $(PY) --require-hashes

.PHONY: setup setup-run demo test test-all bench lock clean

setup: $(TEST_STAMP)

setup-run: $(RUN_STAMP)

# The venv without pip when $(PYTHON) has pip to install uv into it (4 s less: no pip to install and compile).
$(UV): requirements/bootstrap.txt
	if $(PYTHON) -m pip --version > /dev/null 2>&1; then \
	    test -x $(PY) || $(PYTHON) -m venv --without-pip $(VENV); \
	    $(PYTHON) -m pip --python $(PY) install --quiet --disable-pip-version-check --require-hashes --no-deps -r requirements/bootstrap.txt; \
	else \
	    test -x $(PY) || $(PYTHON) -m venv $(VENV); \
	    $(PY) -m pip install --quiet --disable-pip-version-check --require-hashes --no-deps -r requirements/bootstrap.txt; \
	fi
	touch $(UV)

$(RUN_STAMP): pyproject.toml requirements/run.txt $(UV)
	$(INSTALL) -r requirements/run.txt
	$(UV) pip install --quiet --python $(PY) --no-deps --no-build-isolation -e .
	$(PY) -m compileall -q -j 0 $(VENV)/lib startrack navsim > /dev/null
	touch $(RUN_STAMP)

$(TEST_STAMP): requirements/test.txt $(RUN_STAMP)
	$(INSTALL) -r requirements/test.txt
	$(PY) -m compileall -q -j 0 $(VENV)/lib startrack navsim > /dev/null
	touch $(TEST_STAMP)

demo: setup-run
	$(VENV)/bin/navsim run scenarios/demo.toml --out reports/out/demo --report reports/out/demo.pdf

test: setup
	$(PY) -m pytest -n $(TEST_WORKERS) --dist loadscope $(PYTEST_ARGS)

# The full suite including the slow statistical tests.
test-all: setup
	$(PY) -m pytest -m "" -n $(TEST_WORKERS) --dist loadscope $(PYTEST_ARGS)

bench: setup
	sh benchmarks/peers/setup_venvs.sh $(PYTHON)
	$(INSTALL) --compile-bytecode -r requirements/bench.txt
	$(PY) benchmarks/run_all.py

# Regenerate the locks from pyproject.toml's ranges (newest versions that satisfy them), then `make setup`;
# the run and bench locks take the test lock's versions of what they share.
lock: $(UV)
	$(LOCK) pyproject.toml requirements/build.in --extra test -o requirements/test.txt
	$(LOCK) pyproject.toml requirements/build.in -c requirements/test.txt -o requirements/run.txt
	$(LOCK) pyproject.toml requirements/build.in --extra test --extra bench -c requirements/test.txt -o requirements/bench.txt
	$(LOCK) requirements/bootstrap.in -o requirements/bootstrap.txt

clean:
	rm -rf $(VENV) .cache .pytest_cache .hypothesis reports/out benchmarks/.venv-cedar benchmarks/.venv-tetra3rs benchmarks/.venv-basilisk benchmarks/work
