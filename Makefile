# Set-up is automatic: each target creates (or reuses) .venv and installs the package.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
QUICK ?=
JOBS ?= 2

.PHONY: test docs reproduce lint benchmarks stress peers clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	@echo "installing phaseimpact into $(VENV) (first run ~1-2 min; later runs skip this)"
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --progress-bar on -e ".[test]"
	touch $(STAMP)

test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -q

# The documentation site (mkdocs.yml, docs/) into site/; --strict: any warning fails the build
# (make test builds it too, strict, in tests/test_docs.py, and runs every code block of its pages and the README).
MKDOCS = NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict
docs: $(STAMP)
	$(MKDOCS)

# Time stamps in archives come from SOURCE_DATE_EPOCH, by default the last commit of the code that
# makes them (studies/run_all.py asks git; outside a checkout, e.g. from `git archive` or a ZIP, they
# are the time of the run). A regenerated file replaces a committed one only when its content differs
# beyond the tolerance README.md states, so a clean checkout stays clean on any machine;
# QUICK=1 previews go to figures/preview/ (git-ignored), never over figures/.
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
