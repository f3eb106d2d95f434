# Two commands on a fresh machine with only python3 and make:
#   make run    set up .venv from the pinned lock, run the standard suite, write reports/<run-id>/
#               (with --repeat-check: disagreeing pairs asked again in a fresh worker;
#               ARGS="--timer instructions" also counts the timed cases' instructions)
#               (make run-deep: the deep tier, cases/ and cases-deep/)
#   make test   set up .venv, then lint, type-check, build the docs and run the tests
#               (make test-long: all tests)
# make docs builds the site (docs/, mkdocs.yml) into build/site/; make docs-figures RUN=DIR
# [BENCH=docs/bench.json] rewrites docs/generated/ and README's generated blocks from a run.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
BUNDLE := $(VENV)/.plotly-bundle

.PHONY: run run-deep test test-long lint venv clean browser valgrind docs docs-figures cli-page

$(STAMP): requirements.lock pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --disable-pip-version-check -r requirements.lock
	$(BIN)/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
	touch $(STAMP)

# plotly's cartesian partial bundle for the report (npm registry, checked against its pinned SHA-512).
$(BUNDLE): $(STAMP) crosscheck/report/bundle.py
	$(BIN)/python -m crosscheck.report.bundle
	touch $(BUNDLE)

venv: $(STAMP) $(BUNDLE)

run: $(STAMP) $(BUNDLE) valgrind
	$(BIN)/crosscheck run --repeat-check $(ARGS)

# The deep tier (cases/ and cases-deep/: finer time steps, minute-long gases, strength-3
# designs); ARGS="--scheduler tcp://host:8786" sends it to a Dask cluster.
run-deep: $(STAMP) $(BUNDLE) valgrind
	$(BIN)/crosscheck run --deep --repeat-check $(ARGS)

lint: $(STAMP) $(BUNDLE)
	$(BIN)/ruff check crosscheck adapters reference_impl tests tools
	$(BIN)/mypy
	$(BIN)/lint-imports

# $(call debian,PACKAGE,WHAT FOR,WITHOUT IT): install a Debian package when its command is
# missing and we can (as root, with apt-get); else say what is skipped without it.
debian = @command -v $(1) >/dev/null 2>&1 || { \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing Debian's $(1) for $(2)"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $(1) >/dev/null; \
	  else echo "$(1) not found: $(3) (install Debian's $(1))"; fi; }

# The report's browser test drives Debian's chromium.
browser:
	$(call debian,chromium,the browser test,the browser test will be skipped)

# The instruction timer (crosscheck run --timer instructions) and its tests count under valgrind.
valgrind:
	$(call debian,valgrind,the instruction timer,--timer instructions is refused and its tests are skipped)

# The site: the CLI page checked against the parser (make cli-page rewrites it), then a strict
# build (a broken link, a missing page or snippet fails it).  NO_MKDOCS_2_WARNING: Material's notice about its end of
# life (the versions are pinned in the lock) is not printed on every build.
docs: $(STAMP)
	$(BIN)/python -m tools.cli_page --check
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict --site-dir build/site

cli-page: $(STAMP)
	$(BIN)/python -m tools.cli_page

# Every measured figure the docs state, from one stored run (and the bench's bench.json).
docs-figures: $(STAMP)
	@if [ -z "$(RUN)" ]; then \
	  echo "usage: make docs-figures RUN=<run folder> [BENCH=docs/bench.json]" >&2; exit 2; fi
	$(BIN)/python -m tools.docs_figures "$(RUN)" $(if $(BENCH),--bench "$(BENCH)")

# Two pytest workers (pytest-xdist), a whole test file each at a time, in the files' order: a
# module's fixtures are made once, and the whole suite's run (tests/conftest.py puts its file
# first) overlaps the other files.  PYTEST_ARGS="-n 0" runs in one process.
PARALLEL := -n 2 --dist loadfile --no-loadscope-reorder

test: lint browser valgrind docs
	$(BIN)/python -m pytest -m "not slow" $(PARALLEL) $(PYTEST_ARGS)

# Nightly-style: everything, including the tests marked slow (a 100,000-case run).
test-long: lint browser valgrind docs
	$(BIN)/python -m pytest $(PARALLEL) $(PYTEST_ARGS)

clean:
	rm -rf $(VENV) .mypy_cache .pytest_cache .ruff_cache build
