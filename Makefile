# Two commands do all the set-up: `make run` (the viewer on the bundled default mesh)
# and `make test` (the test suite). Both create and fill .venv on first use.
VENV ?= .venv
PYTHON ?= python3
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: run test lint format bench docs clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[dev]"
	touch $(STAMP)

run: $(STAMP)
	$(PY) -m modalviewer

test: $(STAMP)
	QT_QPA_PLATFORM=offscreen $(PY) -m pytest -q -n 2 --dist worksteal
	$(PY) -m ruff check modalviewer tests benchmarks scripts examples docs/_ext
	$(PY) -m ruff format --check modalviewer tests benchmarks scripts examples docs/_ext

lint: $(STAMP)
	$(PY) -m ruff check modalviewer tests benchmarks scripts examples docs/_ext

format: $(STAMP)
	$(PY) -m ruff format modalviewer tests benchmarks

bench: $(STAMP)
	$(PY) -m benchmarks.run --sizes 10k 50k 130k --baseline-max-unknowns 200000 --few 12 50
	$(PY) -m benchmarks.growth

$(DOCS_STAMP): $(STAMP)
	$(PY) -m pip install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

# The HTML documentation in docs/_build/html; warnings are errors.
docs: $(DOCS_STAMP)
	$(VENV)/bin/sphinx-build -W --keep-going -b html docs docs/_build/html

clean:
	rm -rf $(VENV)
