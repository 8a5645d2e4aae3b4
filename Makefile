# The two commands of the README: `make book` and `make test`; `make check` is the quick loop.
# Each creates the virtual environment .venv from the lock, requirements.txt, on first use.
# Override the interpreter used to create it with, e.g., `make test PYTHON=python3.12`.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
# Reinstall when the pins or the package metadata change, or when the package's __init__.py
# appears (an editable install made before it existed maps `uio_teach` as a namespace package).
STAMP  := $(VENV)/.installed

# Tools started by pytest (jupyter-book, the kernel) come from the environment.
export PATH := $(abspath $(BIN)):$(PATH)
# Python's compiled files are written, whatever the environment says: pytest keeps the test
# modules it has rewritten there, which makes collecting the tests several times faster.
unexport PYTHONDONTWRITEBYTECODE
# The tests run on every core (pytest-xdist; tests/conftest.py keeps the tests that share a
# costly fixture, such as the one book build, on one worker); `make test JOBS=0` runs them all
# in one process.
JOBS ?= auto

.DEFAULT_GOAL := help
.PHONY: help venv book book-instructor book-selfstudy pdf pdf-instructor test test-slow lint clean

# What `make check` leaves to `make test`: tests that start a Jupyter kernel, drive a browser,
# build the book or the wheel, start any other process, or take long (the markers each test
# module declares; tests/conftest.py lists them and fails a test that starts one undeclared).
QUICK := not kernel and not browser and not book and not wheel and not subprocess and not slow

help:
	@echo "make book   build the HTML book into _build/html (warnings are errors)"
	@echo "make book-instructor  the instructor edition (lab solutions, tutors' notes)"
	@echo "make book-selfstudy   the self-study edition (solutions folded, shown on request)"
	@echo "            into _build/instructor/_build/html"
	@echo "make pdf    the book, with every page and the whole book printed as tagged PDFs"
	@echo "            into _build/pdf (and linked from the pages); make pdf-instructor:"
	@echo "            the instructor edition's, into _build/instructor/_build/pdf"
	@echo "make test   lint, then every test but the slow set (package, chapters, book, browser)"
	@echo "make test-slow  the slow set (CI runs it after make test; make test-all: both)"
	@echo "make check  lint, then the quick tests: no kernel, browser, book, wheel or process"
	@echo "make venv   create or update $(VENV) from the lock, requirements.txt"
	@echo "make lint   ruff check and ruff format --check"
	@echo "make lock   regenerate requirements.txt from requirements.in (pip-tools)"
	@echo "make bench  run the benchmarks; write benchmarks/RESULTS.md and the README table"
	@echo "make clean  remove build outputs and caches (keeps $(VENV))"

$(STAMP): requirements.txt pyproject.toml setup.py $(wildcard uio_teach/__init__.py)
	@test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --disable-pip-version-check -q -r requirements.txt
	$(BIN)/python -m pip install --disable-pip-version-check -q -e . --no-deps --no-build-isolation
	@touch $@

venv: $(STAMP)

# _ext/run_chapters.py first executes the chapters that changed, as many at a time as there
# are cores, into the cache the build reads; the build alone gives the same pages, slower.
book: $(STAMP)
	$(BIN)/python _ext/run_chapters.py
	$(BIN)/jupyter-book build . -W -n --keep-going
	@echo "The book is in $(CURDIR)/_build/html/index.html"

# The instructor edition: the same pages with the lab solutions and the tutors' notes
# (_ext/editions.py); its own output folder and execution cache.
book-instructor: $(STAMP)
	$(BIN)/python _ext/run_chapters.py --cache _build/instructor/_build/.jupyter_cache
	UIO_TEACH_EDITION=instructor $(BIN)/jupyter-book build . -W -n --keep-going \
		--path-output _build/instructor
	@echo "The instructor edition is in $(CURDIR)/_build/instructor/_build/html/index.html"

# the student edition with each lab solution folded behind "Show a worked solution (after you
# tried)", for those who learn alone; the class edition (make book) stays as it is
book-selfstudy: $(STAMP)
	$(BIN)/python _ext/run_chapters.py --cache _build/selfstudy/_build/.jupyter_cache
	UIO_TEACH_EDITION=selfstudy $(BIN)/jupyter-book build . -W -n --keep-going \
		--path-output _build/selfstudy
	@echo "The self-study edition is in $(CURDIR)/_build/selfstudy/_build/html/index.html"

# The printed book (_ext/downloads.py, _ext/pdf_print.py): the book built with UIO_TEACH_PDF=1,
# whose pages then link their PDFs, and once written every page printed as a tagged PDF by
# Debian's Chromium, as many at a time as there are cores, into _build/pdf (uio-teach.pdf: the
# whole book) and the site's _pdf/. `make book` afterwards rewrites the pages without the links
# and takes _pdf/ out of the site: a page links a PDF only when its build printed it.
pdf: $(STAMP)
	$(BIN)/python _ext/run_chapters.py
	UIO_TEACH_PDF=1 $(BIN)/jupyter-book build . -W -n --keep-going
	@echo "The PDFs are in $(CURDIR)/_build/pdf; the book linking them in $(CURDIR)/_build/html"

pdf-instructor: $(STAMP)
	$(BIN)/python _ext/run_chapters.py --cache _build/instructor/_build/.jupyter_cache
	UIO_TEACH_EDITION=instructor UIO_TEACH_PDF=1 $(BIN)/jupyter-book build . -W -n \
		--keep-going --path-output _build/instructor
	@echo "The PDFs are in $(CURDIR)/_build/instructor/_build/pdf"

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# `make test` leaves the tests marked `slow` to `make test-slow`; CI (.ci/run) runs both.
test: lint
	$(BIN)/pytest -m "not slow" -n $(JOBS) --dist loadgroup --no-loadscope-reorder

test-slow: $(STAMP)
	$(BIN)/pytest -m slow -n $(JOBS) --dist loadgroup --no-loadscope-reorder

test-all: lint
	$(BIN)/pytest -n $(JOBS) --dist loadgroup --no-loadscope-reorder

.PHONY: check lock bench test-all

check: lint
	$(BIN)/pytest -q -m "$(QUICK)" -n $(JOBS) --dist loadgroup --no-loadscope-reorder

# The lock: every package, direct (requirements.in) or not, at one version with its hashes.
# After changing a pin in requirements.in run `make lock`; `make lock LOCK_FLAGS=--upgrade`
# also moves the indirect dependencies to their newest versions.
lock: $(STAMP)
	CUSTOM_COMPILE_COMMAND="make lock" $(BIN)/python -m piptools compile --quiet \
		--generate-hashes --allow-unsafe --strip-extras --no-emit-index-url \
		--no-emit-find-links --no-emit-trusted-host $(LOCK_FLAGS) -o requirements.txt requirements.in

bench: $(STAMP)
	$(BIN)/python benchmarks/report.py

clean:
	rm -rf _build .pytest_cache .hypothesis .ruff_cache build *.egg-info
