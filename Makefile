# Set-up is automatic: each target creates (or reuses) .venv and installs the package.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
QUICK ?=
JOBS ?= 2
TEST_JOBS ?= 2

.PHONY: test test-sdist test-numba-range docs reproduce lint benchmarks stress peers clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	@echo "installing phaseimpact into $(VENV) (first run ~1-2 min; later runs skip this)"
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --progress-bar on -e ".[test]"
	touch $(STAMP)

# The engine is compiled into its cache once, in one process (seconds when it is warm), so that the
# TEST_JOBS pytest-xdist workers never compile the same kernels cold side by side. Each worker runs whole
# files (loadfile: a module fixture is made once), in tests/conftest.py's order: the long poles first.
test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/phaseimpact warmup
	$(BIN)/python -m pytest -q -n $(TEST_JOBS) --dist loadfile --no-loadscope-reorder

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
	$(BIN)/python -m phaseimpact warmup
	$(BIN)/python studies/run_all.py $(if $(QUICK),--quick) --jobs $(JOBS)

# The engine's tests on the oldest and the newest numba pyproject.toml allows (numba>=0.59,<0.69),
# each in a throwaway .venv-numba-<end> (git-ignored; `make clean` removes them) with the NumPy that
# numba supports, and its own NUMBA_CACHE_DIR (a first compile in each, and one more for the cold
# session of test_precompile.py, which checks the hooks bit for bit; the slow test that compiles
# an edited copy twice is left to `make test`). Raise the cap in
# pyproject.toml only after this passes with the new numba as the newest end.
NUMBA_OLDEST := "numba==0.59.0" "numpy<1.27"
NUMBA_NEWEST := "numba<0.69"
NUMBA_RANGE_TESTS ?= tests/test_integrate.py tests/test_laws.py tests/test_cache.py tests/test_precompile.py \
	tests/test_imports.py tests/test_allocations.py

.venv-numba-%/.installed: pyproject.toml
	$(PYTHON) -m venv .venv-numba-$*
	.venv-numba-$*/bin/python -m pip install --quiet --upgrade pip
	.venv-numba-$*/bin/python -m pip install --quiet $(NUMBA_$(shell echo $* | tr a-z A-Z)) -e . pytest hypothesis
	touch $@

# The whole quick subset of the suite and the docs build, run from an unpacked sdist (make test runs a
# sample of it: every test file, and every quick test of the files that read figures, studies and docs).
test-sdist: $(STAMP)
	PHASEIMPACT_SDIST_ALL=1 $(BIN)/python -m pytest -q tests/test_packaging.py -k sdist_has_every

test-numba-range: .venv-numba-oldest/.installed .venv-numba-newest/.installed
	@for end in oldest newest; do \
		echo "== numba $$(.venv-numba-$$end/bin/python -c 'import numba, numpy; print(numba.__version__, "with numpy", numpy.__version__)') ($$end allowed)"; \
		NUMBA_CACHE_DIR=$$PWD/.venv-numba-$$end/numba-cache .venv-numba-$$end/bin/python -m pytest -q \
			-o cache_dir=.venv-numba-$$end/pytest-cache -m "not slow" $(NUMBA_RANGE_TESTS) || exit 1; \
		NUMBA_CACHE_DIR=$$PWD/.venv-numba-$$end/numba-cache .venv-numba-$$end/bin/python -m pytest -q \
			-o cache_dir=.venv-numba-$$end/pytest-cache tests/test_cuda.py -k "ptx or call_policy" || exit 1; \
	done

lint: $(STAMP)
	$(BIN)/ruff check .

benchmarks: $(STAMP)
	$(BIN)/python benchmarks/run_all.py $(if $(QUICK),--quick)

stress: $(STAMP)
	$(BIN)/python benchmarks/stress.py $(if $(QUICK),--quick)

peers: $(STAMP)  # heyoka comparison, in its own .venv-peers (downloads ~100 MB)
	$(BIN)/python benchmarks/peers.py

clean:
	rm -rf $(VENV) .venv-numba-oldest .venv-numba-newest .pytest_cache build *.egg-info
