# The two commands of the README: `make demo` (main job) and `make test` (the test suite).
# Both create their own virtual environment in .venv from the base Python and install what they use.
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: demo test venv lint siconos clean

venv: $(STAMP)

$(STAMP): pyproject.toml Makefile
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,cad]'
	touch $(STAMP)

demo: $(STAMP)
	$(VENV)/bin/clearbench demo

lint: $(STAMP)
	$(PY) -m ruff check .

test: $(STAMP) lint
	$(PY) -m pytest -m "not slow"

clean:
	rm -rf $(VENV) build *.egg-info
