# Each user-facing target sets itself up: a fresh clone needs only `make prove` or `make test`.
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: prove test test-slow lint bench mutants clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,lint]'
	touch $(STAMP)

prove: $(STAMP)
	$(VENV)/bin/cfmpa prove --audit build/audit

# Two pytest workers, a test file each at a time (a module's fixtures are built once): the suite
# is CPU-bound, so two cores take about half the time (docs/contributing.md). TEST_WORKERS=0 runs
# it in one process.
TEST_WORKERS ?= 2
test: $(STAMP)
	$(PY) -m pytest $(if $(filter 0,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile)

test-slow: $(STAMP)
	$(PY) -m pytest -m slow

# ruff and mypy as configured in pyproject.toml. mypy reads the installed package names
# (spec/ is cfmpa.spec, ...): build/typecheck/cfmpa links the folders into that tree.
TYPECHECK := build/typecheck/cfmpa
lint: $(STAMP)
	$(VENV)/bin/ruff check .
	rm -rf $(TYPECHECK) && mkdir -p $(TYPECHECK)
	for f in cfmpa/*; do ln -s ../../../$$f $(TYPECHECK)/; done
	for d in spec impl proofs runs report scenarios; do ln -s ../../../$$d $(TYPECHECK)/$$d; done
	$(VENV)/bin/mypy

bench: $(STAMP)
	$(PY) bench/run.py --prove

# Seeded source mutations of a copy of the packages: which of prove, contracts, tests catch each.
mutants: $(STAMP)
	$(VENV)/bin/cfmpa mutants --json build/mutants.json

clean:
	rm -rf build .pytest_cache
