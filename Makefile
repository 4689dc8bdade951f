# Each target bootstraps its own virtual environment from PyPI.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test bench clean venv docs

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[all,test]'
	touch $(STAMP)

venv: $(STAMP)

demo: $(STAMP)
	$(BIN)/qzs paper --out results/paper --overwrite

# The suite on every core, at most 4 processes (pytest-xdist), a test module's tests in one
# process (their module fixtures computed once): 275 s on 2 cores where one took 504 s.
# The documentation run as written (-m docs_run, tests/test_docs_run.py) is `make docs`'s.
test: $(STAMP)
	$(BIN)/python -m pytest -q -n auto --maxprocesses 4 --dist loadscope -m "not docs_run"

# The documentation site (docs/conf.py): the closed-form tests first, whose records become
# docs/validation.md's tables; then every command and snippet of README.md and the pages, run
# in page order in one fresh folder (pytest -m docs_run: minutes, so not in `make test`);
# then Sphinx with warnings as errors, executing the tutorials and the gallery; then every
# internal link of the built pages. Always a clean build.
DOCS_STAMP := $(VENV)/.installed-docs
DOCS_OUT := docs/_build

$(DOCS_STAMP): pyproject.toml $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[all,docs]'
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	@start=$$(date +%s); set -e; \
	rm -rf $(DOCS_OUT) docs/api/generated docs/api/qzs*.rst docs/gallery; \
	mkdir -p $(DOCS_OUT); \
	echo "docs: the validation tests (pytest -m validation)"; \
	QZS_VALIDATION_OUT=$(CURDIR)/$(DOCS_OUT)/validation.jsonl \
		$(BIN)/python -m pytest -q -m validation -p no:cacheprovider; \
	echo "docs: the pages run as written (pytest -m docs_run)"; \
	QZS_DOCS_RUN_OUT=$(CURDIR)/$(DOCS_OUT)/docs-run.jsonl \
		$(BIN)/python -m pytest -q -m docs_run -p no:cacheprovider tests/test_docs_run.py; \
	echo "docs: sphinx-build"; \
	QZS_VALIDATION_OUT=$(CURDIR)/$(DOCS_OUT)/validation.jsonl \
		$(BIN)/python -m sphinx -W --keep-going -q -b html -j 1 docs $(DOCS_OUT)/html; \
	$(BIN)/python docs/check_links.py $(DOCS_OUT)/html; \
	echo "docs: $(DOCS_OUT)/html/index.html, built in $$(( $$(date +%s) - start )) s"

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_simulate.py

clean:
	rm -rf $(VENV) results build src/*.egg-info .mypy_cache
