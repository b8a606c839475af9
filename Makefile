# hsgeo — every target bootstraps the virtual environment from the pinned lock if needed.
# `make help` lists the targets.
SHELL := /bin/bash
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.hsgeo-installed
# One BLAS thread: on the 2-core machines we build on, multi-threaded OpenBLAS was 5-10x slower
# than one thread on the small dense solves of our adjustments (GUIDE §9; `make bench` measures it).
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1
# glibc malloc keeps freed memory instead of returning it to the system: the large arrays an
# adjustment allocates in every iteration then reuse pages instead of having fresh ones zeroed by
# the kernel (≈ 1 s of system time, 10-20 % of the full-size pushbroom solve; `make bench`).
export GLIBC_TUNABLES ?= glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967296
export PYDEVD_DISABLE_FILE_VALIDATION := 1

.DEFAULT_GOAL := help
.PHONY: help venv proj-data data test test-fast book book-student check-book check-wheel browser bench lint clean lock dist

help: ## list the targets
	@grep -hE '^[a-zA-Z_-]+:.*## ' $(MAKEFILE_LIST) | awk 'BEGIN {FS = ":.*## "}; {printf "  make %-10s %s\n", $$1, $$2}'

$(STAMP): requirements.lock pyproject.toml
	@command -v $(PYTHON) >/dev/null || { echo "error: $(PYTHON) not found; hsgeo needs Python 3.11 (set PYTHON=...)"; exit 1; }
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements.lock
	$(PY) -m pip install --quiet --disable-pip-version-check --no-deps -e .
	$(PY) -m ipykernel install --sys-prefix --name python3 >/dev/null
	touch $(STAMP)

venv: $(STAMP) proj-data ## create .venv from requirements.lock and install hsgeo (about 1 min)

# PROJ's geoid grids (EGM96 `egm96_15.gtx`) for DSMs with orthometric heights: Debian's proj-data,
# installed as root when missing (hsgeo.crs.use_system_proj_grids points pyproj at /usr/share/proj).
PROJ_GRID := /usr/share/proj/egm96_15.gtx
proj-data: ## install Debian's proj-data (PROJ's geoid grids: EGM96) if missing (apt-get, as root)
	@if [ -f $(PROJ_GRID) ]; then echo "proj-data: $(PROJ_GRID)"; \
	elif [ "$$(id -u)" = 0 ]; then \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends proj-data; \
	elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then \
	  sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends proj-data; \
	else echo "warning: $(PROJ_GRID) not found: DSMs with orthometric heights (EGM96) need Debian's proj-data (apt-get install proj-data, as root)"; fi

data: $(STAMP) ## regenerate data_synthetic/generated from the scenario TOMLs and verify the SHA-256 manifest
	$(PY) -m hsgeo.cli data --verify

# The suite runs on TEST_WORKERS processes (pytest-xdist; `make test TEST_WORKERS=0` runs it in
# this one). `--dist loadfile` gives each process whole files: a module's shared fixtures (one
# simulated campaign, one reproduction) are computed once, and the chapters run in the book's
# order in one process, so the scoreboard reads the records of the chapters before it. The
# compiled kernels (numba, cache=True) are cached beside the sources (__pycache__) and shared by
# every process; on a fresh clone each kernel is compiled once, by the first process that needs it
# (tests/compile_lock.py), and the costliest files begin first (tests/conftest.py).
# `--durations=40` prints the 40 slowest tests at the end: where the suite's time goes (issue 41).
TEST_WORKERS ?= 2
TEST_XDIST = $(if $(filter 0,$(TEST_WORKERS)),,-n $(TEST_WORKERS) --dist loadfile)

test: $(STAMP) proj-data ## the docstrings' examples (doctest) and the whole test suite, chapters included
	$(PY) -m hsgeo.cli data --verify
	$(PY) -m pytest -q -p no:cacheprovider --doctest-modules src/hsgeo
	$(PY) -m pytest -q $(TEST_XDIST) --durations=40 tests

test-fast: $(STAMP) proj-data ## the test suite without the chapter executions and slow Monte Carlo tests
	$(PY) -m pytest -q $(TEST_XDIST) -m "not slow" --ignore=tests/test_chapters.py tests

# The execution cache is keyed on each chapter's code only: when the library or the scenarios
# change, the cached outputs would be stale, so the cache is dropped then.
# (not data_synthetic/generated: the chapters rewrite files there, same bytes, new mtime)
book/_build/.library-stamp: $(shell find src/hsgeo data_synthetic -path data_synthetic/generated -prune -o \( -name '*.py' -o -name '*.toml' \) -print) requirements.lock
	rm -rf book/_build/.jupyter_cache book/_build/reproduce
	mkdir -p book/_build && touch $@

# The chapters record their `hsgeo reproduce` results here; the scoreboard page reads them.
book: export HSGEO_RECORD_DIR := $(CURDIR)/book/_build/reproduce

book: $(STAMP) book/_build/.library-stamp ## execute every chapter and render the HTML book to book/_build/html (offline; ~15 min on 2 cores from an empty cache)
	$(PY) -m hsgeo.cli data --verify
	@# cached outputs are only valid for the size they were computed at (the cache keys on code only)
	@if [ "$$(cat book/_build/.scale 2>/dev/null)" != "$${HSGEO_SCALE:-full}" ]; then \
	  rm -rf book/_build/.jupyter_cache; echo "$${HSGEO_SCALE:-full}" > book/_build/.scale; fi
	rm -rf book/_build/html book/_build/.doctrees book/_build/jupyter_execute
	$(VENV)/bin/jupyter-book build book -W -n --keep-going

# The student edition: the same book without the exercises' solutions (removed by
# book/_ext/hsgeo_book.py when HSGEO_STUDENT=1). It is built in its own
# directory but executes from `make book`'s cache, so after `make book` it takes minutes.
book-student: export HSGEO_RECORD_DIR := $(CURDIR)/book/_build/reproduce

book-student: $(STAMP) book/_build/.library-stamp ## the book without the exercises' solutions, to book/_build/html-student (reuses the cache of `make book`)
	$(PY) -m hsgeo.cli data --verify
	rm -rf book/_build/student book/_build/html-student
	HSGEO_STUDENT=1 HSGEO_JUPYTER_CACHE="$(CURDIR)/book/_build/.jupyter_cache" \
	  $(VENV)/bin/jupyter-book build book -W -n --keep-going --path-output book/_build/student
	mv book/_build/student/_build/html book/_build/html-student
	rm -rf book/_build/student
	@echo "student edition: book/_build/html-student/index.html"

# `make check-book` opens every built page in a real headless browser, offline: Debian's chromium,
# driven by Playwright's Python API (pinned in requirements.lock) through `executable_path`;
# Playwright's own browser download is not used. The book is built first if it is missing or older
# than its sources.
CHROMIUM ?= $(shell command -v chromium || command -v chromium-browser)
BOOK_SOURCES := $(shell find book -path book/_build -prune -o -type f -print) $(shell find src/hsgeo -name '*.py')

browser: ## install Debian's chromium (apt-get, as root) if it is missing; `make check-book` needs it
	@if [ -n "$(CHROMIUM)" ]; then echo "browser: $(CHROMIUM)"; \
	elif [ "$$(id -u)" = 0 ]; then \
	  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium; \
	elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then \
	  sudo apt-get update -qq && sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium; \
	else echo "error: chromium not found; install it as root (apt-get install chromium) or set CHROMIUM=/path/to/chrome"; exit 1; fi

book/_build/html/index.html: $(BOOK_SOURCES)
	$(MAKE) book

book/_build/html-student/index.html: book/_build/html/index.html
	$(MAKE) book-student

check-book: $(STAMP) browser book/_build/html/index.html book/_build/html-student/index.html ## open every page of the built book (and the student edition's files) in headless chromium, offline, and check them (builds both first if needed)
	HSGEO_CHECK_BOOK=1 HSGEO_CHROMIUM="$$(command -v chromium || command -v chromium-browser || echo $(CHROMIUM))" \
	  $(PY) -m pytest -q -p no:cacheprovider -m book tests/book \
	  --junitxml=book/_build/check-book.junit.xml  # read by bench/issue40_audit.py

bench: $(STAMP) ## run the benchmarks, results as JSON in bench/results/ (installs requirements-bench.lock: pycolmap/Ceres)
	$(PY) -m pip install --quiet --disable-pip-version-check -r requirements-bench.lock
	$(PY) bench/run.py

# The wheel is built with the environment's own setuptools (no build isolation, so nothing is
# downloaded); `pip install dist/hsgeo-*.whl` then installs the library and the `hsgeo` command.
dist: $(STAMP) ## build the hsgeo wheel into dist/ (pip wheel, offline)
	rm -rf dist build
	$(PY) -m pip wheel --quiet --disable-pip-version-check --no-deps --no-build-isolation -w dist .
	@ls dist/*.whl

# The wheel installed alone (issue 42): a fresh venv outside the repository, the wheel with its
# dependencies from the package index (at requirements.lock's versions), and the README's
# commands run from an empty folder (.ci/check_wheel.sh; a few minutes).
check-wheel: dist ## install the wheel into a fresh venv and run the README's commands from an empty folder
	PYTHON=$(PYTHON) .ci/check_wheel.sh

lint: $(STAMP) ## ruff check and format check, the import contracts of the layout (GUIDE §2), no dead names (vulture)
	$(VENV)/bin/ruff check src tests bench
	$(VENV)/bin/ruff format --check src tests bench
	$(VENV)/bin/lint-imports --no-cache
	$(VENV)/bin/vulture src/hsgeo vulture_whitelist.py --min-confidence 60

lock: ## re-resolve the environment from pyproject.toml and rewrite requirements.lock
	rm -rf $(VENV)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e ".[book,dev]"
	$(PY) -m pip freeze --exclude-editable | grep -v '^hsgeo' > requirements.lock

clean: ## remove the book build, caches and generated large files (keeps .venv)
	rm -rf book/_build .pytest_cache .ruff_cache
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
