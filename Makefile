# The two commands of the README: `make book` and `make test`.
# Both create the virtual environment .venv from requirements.txt on first use.
# Override the interpreter used to create it with, e.g., `make test PYTHON=python3.12`.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
# Reinstall when the pins or the package metadata change, or when the package's __init__.py
# appears (an editable install made before it existed maps `uio_teach` as a namespace package).
STAMP  := $(VENV)/.installed

# Tools started by pytest (jupyter-book, the kernel) come from the environment.
export PATH := $(abspath $(BIN)):$(PATH)

.DEFAULT_GOAL := help
.PHONY: help venv book book-instructor test lint clean

help:
	@echo "make book   build the HTML book into _build/html (warnings are errors)"
	@echo "make book-instructor  the instructor edition (lab solutions, tutors' notes)"
	@echo "            into _build/instructor/_build/html"
	@echo "make test   lint, then run every test (package, chapters, book build, browser)"
	@echo "make venv   create or update $(VENV) from requirements.txt"
	@echo "make lint   ruff check and ruff format --check"
	@echo "make clean  remove build outputs and caches (keeps $(VENV))"

$(STAMP): requirements.txt pyproject.toml setup.py $(wildcard uio_teach/__init__.py)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --disable-pip-version-check -q -r requirements.txt
	$(BIN)/python -m pip install --disable-pip-version-check -q -e . --no-deps
	@touch $@

venv: $(STAMP)

book: $(STAMP)
	$(BIN)/jupyter-book build . -W -n --keep-going
	@echo "The book is in $(CURDIR)/_build/html/index.html"

# The instructor edition: the same pages with the lab solutions and the tutors' notes
# (_ext/editions.py); its own output folder and execution cache.
book-instructor: $(STAMP)
	UIO_TEACH_EDITION=instructor $(BIN)/jupyter-book build . -W -n --keep-going \
		--path-output _build/instructor
	@echo "The instructor edition is in $(CURDIR)/_build/instructor/_build/html/index.html"

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

test: lint
	$(BIN)/pytest

clean:
	rm -rf _build .pytest_cache .hypothesis .ruff_cache build *.egg-info
