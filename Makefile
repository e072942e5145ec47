# twolink-pin: the two commands of the quick start.
#   make demo   creates .venv, installs the package, runs the main job into out/
#   make test   installs the test extras (and headless Chromium), runs ruff and the whole suite,
#               which builds the documentation site in strict mode and executes the tutorial
#   make docs   installs the docs extra, builds the site into site/ (strict: any warning fails)
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
OUT ?= out
TEST_WORKERS ?= 2

.PHONY: demo test docs lint bench clean

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

demo: $(VENV)/.installed
	$(BIN)/twolink-pin report --out $(OUT)

# tests/test_docs.py runs the same strict build as `make docs` (into a temporary folder),
# on the tutorial that tests/test_tutorial.py has just executed on a fresh kernel.
# Which tests share a worker and which start first: pyproject.toml's addopts
# (--dist loadgroup --no-loadscope-reorder) and tests/conftest.py.
test: $(VENV)/.installed-test
	$(BIN)/ruff check .
	$(BIN)/python -m pytest -n $(TEST_WORKERS)

docs: $(VENV)/.installed-docs
	NO_MKDOCS_2_WARNING=1 $(BIN)/python -m mkdocs build --strict -d site

lint: $(VENV)/.installed-test
	$(BIN)/python -m pip install -q -e '.[dev]'
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy twolink_pin

bench: $(VENV)/.installed
	$(BIN)/python scripts/benchmark.py

clean:
	rm -rf $(VENV) $(OUT) site .pytest_cache .ruff_cache .hypothesis
