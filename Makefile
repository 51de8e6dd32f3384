# Two commands do all the set-up: `make run` and `make test` (see README.md).
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.ballbat-installed
CORES ?= 2

.PHONY: install bytecode run test test-lab test-all test-slurm test-report test-citation validate-crate study study-robustness report bench lint lock clean

# Create the virtual environment and install the pinned stack plus ballbat (editable).
$(STAMP): pyproject.toml requirements.lock
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -r requirements.lock
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
	touch $(STAMP)

install: $(STAMP)

# ballbat's bytecode, compiled where it is stale, as pip compiles a regular install: an editable
# install leaves it to the first import, which writes nothing where PYTHONDONTWRITEBYTECODE is
# set (as on this machine and in many containers), so every Snakemake job compiled the package
# again (about 0.3 s a job; make test 290 -> 272 s).
bytecode: install
	$(BIN)/python -m compileall -q src

run: bytecode
	$(BIN)/snakemake -c$(CORES)

# The suite on $(CORES) processes (pytest-xdist), each test module on one, in the order of
# tests/conftest.py (FIRST); the shared workflow runs are built once, by whichever process needs
# them first. `make test` runs the package's tests and those of the default run; the tests of the
# lab run (a lab's datasets, scenarios and studies in one folder, its outputs, faults and reruns:
# marker `lab`, tests/conftest.py) are `make test-lab`, and the report in a real browser (marker
# `browser`) is `make test-report`'s; `make test-all` runs all of them in one session,
# and `pytest` alone runs everything in one process. CI runs test, then test-lab, on the same
# shared runs (BALLBAT_TEST_SHARED_RUNS, .ci/run).
# Bytecode is written during the tests even where PYTHONDONTWRITEBYTECODE is set (as on this machine):
# pytest then keeps its rewritten test modules (about 4 s of CPU a process to redo), and the jobs
# of a run with its own copy of the package compile it once, not once a job.
PYTEST_XDIST := -n $(CORES) --dist loadscope --no-loadscope-reorder
PYTEST := PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest

test: bytecode
	$(PYTEST) $(PYTEST_XDIST) -m "not lab and not browser"

test-lab: bytecode
	$(PYTEST) $(PYTEST_XDIST) -m lab

test-all: bytecode
	$(PYTEST) $(PYTEST_XDIST)

# The default workflow through a real single-node SLURM set up on this machine (Debian's
# packages; root needed), compared byte for byte with a local run; the daemons are stopped after.
# The executor plugin lives in its own environment: imported by every Snakemake start, it asks
# SLURM for its status commands, which costs seconds wherever SLURM is installed but not running.
SLURM_VENV ?= .venv-slurm
$(SLURM_VENV)/.installed: pyproject.toml requirements.lock requirements-slurm.lock
	test -x $(SLURM_VENV)/bin/python || $(PYTHON) -m venv $(SLURM_VENV)
	$(SLURM_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements.lock -r requirements-slurm.lock
	$(SLURM_VENV)/bin/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
	touch $@

test-slurm: $(SLURM_VENV)/.installed
	BIN=$(CURDIR)/$(SLURM_VENV)/bin tests/slurm/run.sh

# Replicate studies (config `studies`: calibration and design; docs/studies.md), then the
# report with their figures. Not part of `make run`.
study: bytecode
	$(BIN)/snakemake -c$(CORES) all studies
	$(BIN)/snakemake -c$(CORES) --report results/report.html all studies

# The studies marked on_request (config `studies.robustness`: a grid over tracking noise, impacts
# per bat and contact time with drawn calibration; 24 min on 2 free cores, docs/studies.md), with
# those of `make study`, then the report with every study's figures.
study-robustness: bytecode
	$(BIN)/snakemake -c$(CORES) all studies studies_on_request
	$(BIN)/snakemake -c$(CORES) --report results/report.html all studies studies_on_request

# The last run's Provenance Run Crate (results/ro-crate-metadata.json) against roc-validator's
# provenance-run-crate-0.5 profile, offline (its cache seeded from tests/data/jsonld/).
validate-crate: install
	$(BIN)/python tests/validate_crate.py results

# CITATION.cff through `cffconvert --validate`. cffconvert pins jsonschema 3 (the workflow needs 4),
# so it lives in an environment of its own, like the SLURM plugin.
CFF_VENV ?= .venv-cff
$(CFF_VENV)/.installed: requirements-cff.lock
	test -x $(CFF_VENV)/bin/python || $(PYTHON) -m venv $(CFF_VENV)
	$(CFF_VENV)/bin/python -m pip install --quiet --disable-pip-version-check -r requirements-cff.lock
	touch $@

test-citation: $(CFF_VENV)/.installed
	$(CFF_VENV)/bin/cffconvert --validate -i CITATION.cff

report: run
	$(BIN)/snakemake -c$(CORES) --report results/report.html

# The report in a real browser: Debian's chromium (installed if missing; root needed), the
# default run's report (make report), then tests/workflow/test_report_browser.py opens it headless,
# 1400 px wide: figures load, a caption and the front page show the fitted numbers.
# Screenshot of the front page: results/report-front.png.
test-report: report
	command -v chromium >/dev/null || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null; }
	BALLBAT_REPORT_ROOT=$(CURDIR) BALLBAT_REQUIRE_BROWSER=1 $(BIN)/python -m pytest tests/workflow/test_report_browser.py

# With the package's bytecode, as `make run` has it: a no-op rerun would otherwise compile the
# modules the Snakefile imports at every start (where PYTHONDONTWRITEBYTECODE is set).
bench: bytecode
	$(BIN)/python bench/bench_workflow.py
	$(BIN)/python bench/bench_stronge.py
	$(BIN)/python bench/bench_flight.py
	$(BIN)/python bench/profile_study.py 40 --plain
	$(BIN)/python bench/bench_study.py

# Habits enforced (CI runs this): ruff (pycodestyle, pyflakes, docstrings, RUF), the format
# of Python and rule files, and Snakemake's own linter. Type hints: tests/test_lint.py.
lint: install
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/snakefmt --check --line-length 120 .
	$(BIN)/snakemake --lint

# Re-pin the stack after changing pyproject.toml's dependencies (and the rules' conda file with it).
lock: install
	$(BIN)/python -m pip freeze --exclude-editable | grep -v '^ballbat' > requirements.lock
	$(BIN)/python workflow/envs/make_env.py

clean:
	rm -rf results .snakemake
