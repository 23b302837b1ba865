# bayesfo: two commands for a newcomer, `make demo` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DOCS_STAMP := $(VENV)/.docs-stamp
DEMO_OUT ?= demo-output

.PHONY: help venv test test-unit test-slow test-all demo bench docs clean

help:
	@echo "make demo       create $(VENV), install bayesfo, run a model comparison on bundled data"
	@echo "make test       create $(VENV), install bayesfo, run the default test suite"
	@echo "make test-unit  the unit tier alone (tests/unit: no sampling, under a minute)"
	@echo "make test-slow  the long validation runs (thesis tables in full, GPL reference data)"
	@echo "make bench      run the benchmarks in benchmarks/"
	@echo "make docs       build the documentation site into docs/_build/html (index.html)"

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	@touch $(STAMP)

venv: $(STAMP)

test: $(STAMP)
	$(BIN)/ruff check bayesfo tests benchmarks examples
	MPLBACKEND=Agg $(BIN)/python -m pytest -m "not slow" -q --durations=15

test-unit: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m "not slow" -q --durations=10 tests/unit

test-slow: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m slow -q

test-all: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

DEMO_DATA ?= examples/data/adhesive_468mp/Tp020C.csv
DEMO_STRUCTURES ?= voigt,zener,maxwell,fractional_kelvin_voigt,voigt-int,zener-int,maxwell-int

demo: $(STAMP)
	@echo "Comparing $(DEMO_STRUCTURES) on $(DEMO_DATA) (3M 468MP adhesive, 20 C, storage and loss modulus)"
	MPLBACKEND=Agg $(BIN)/bayesfo compare $(DEMO_DATA) --structures $(DEMO_STRUCTURES) --out $(DEMO_OUT)
	@echo "Open $(DEMO_OUT)/report.html first (verdict, ranking, figures); all numbers in $(DEMO_OUT)/summary.json"

bench: $(STAMP)
	@for f in benchmarks/bench_*.py; do echo "== $$f"; $(BIN)/python $$f || exit 1; done

$(DOCS_STAMP): pyproject.toml $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	@touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	rm -rf docs/api/generated   # regenerated from the docstrings: no page of a removed name stays
	MPLBACKEND=Agg $(BIN)/sphinx-build -W --keep-going -b html docs docs/_build/html
	@echo "Open docs/_build/html/index.html"

clean:
	rm -rf $(VENV) build *.egg-info $(DEMO_OUT)
