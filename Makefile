# twolink-pin: the two commands of the quick start.
#   make demo   creates .venv, installs the package, runs the main job into out/ (another folder:
#               make demo TWOLINK_PIN_DEMO_OUT=DIR; a plain OUT in the environment is not ours to read)
#   make check  the edit-test loop: ruff, the format check, mypy and every test that needs no
#               browser, Dask cluster, docs/tutorial/report build and is not marked slow
#   make test   installs the test extras (and headless Chromium), runs the same checks and the whole
#               suite, which builds the documentation site in strict mode and executes the tutorial
#   make docs   installs the docs extra, builds the site into site/ (strict: any warning fails)
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
TWOLINK_PIN_DEMO_OUT ?= out
TEST_WORKERS ?= 2
CHECK_MARKERS ?= not browser and not slow and not cluster and not docs and not report

.PHONY: demo check test docs lint static bench clean bytecode

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install -q -e .
	touch $@

$(VENV)/.installed-test: pyproject.toml $(VENV)/.installed scripts/install_browser.sh
	$(BIN)/python -m pip install -q -e '.[test]'
	bash scripts/install_browser.sh
	touch $@

$(VENV)/.installed-docs: pyproject.toml $(VENV)/.installed
	$(BIN)/python -m pip install -q -e '.[docs]'
	touch $@

# The package's bytecode, written once (and again for a changed file): an editable install has none,
# and with PYTHONDONTWRITEBYTECODE set (as on our CI machines) every process — each report worker,
# each CLI call of the tests — would compile every module it imports (~0.2 s a process).
bytecode: $(VENV)/.installed
	$(BIN)/python -m compileall -q twolink_pin

demo: bytecode
	$(BIN)/twolink-pin report --out $(TWOLINK_PIN_DEMO_OUT)

# tests/test_docs.py runs the same strict build as `make docs` (into a temporary folder),
# on the tutorial that tests/test_tutorial.py has just executed on a fresh kernel.
# Which tests share a worker and which start first: pyproject.toml's addopts
# (--dist loadgroup --no-loadscope-reorder) and tests/conftest.py.
# ruff, the format check and mypy: the first step of check, test and lint
static: $(VENV)/.installed-test bytecode
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy twolink_pin

test: static
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

# the markers: pyproject.toml; which files carry cluster, docs, report: tests/conftest.py (MARKS)
check: static
	$(BIN)/python -m pytest -n $(TEST_WORKERS) -m "$(CHECK_MARKERS)"

docs: $(VENV)/.installed-docs
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict -d site

lint: static

bench: bytecode
	$(BIN)/python scripts/benchmark.py

# the report folder only as far as its marker says the report wrote it (a file of yours stays)
clean:
	$(PYTHON) scripts/clean_report.py $(TWOLINK_PIN_DEMO_OUT)
	rm -rf $(VENV) site .pytest_cache .ruff_cache .hypothesis
