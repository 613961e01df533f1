# Set-up is automatic: each target creates (or reuses) .venv and installs the package.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
QUICK ?=
JOBS ?= 2

.PHONY: test reproduce lint benchmarks stress peers clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -q

reproduce: $(STAMP)
	$(BIN)/python studies/run_all.py $(if $(QUICK),--quick) --jobs $(JOBS)

lint: $(STAMP)
	$(BIN)/ruff check .

benchmarks: $(STAMP)
	$(BIN)/python benchmarks/run_all.py $(if $(QUICK),--quick)

stress: $(STAMP)
	$(BIN)/python benchmarks/stress.py $(if $(QUICK),--quick)

peers: $(STAMP)  # heyoka comparison, in its own .venv-peers (downloads ~100 MB)
	$(BIN)/python benchmarks/peers.py

clean:
	rm -rf $(VENV) .pytest_cache build *.egg-info
