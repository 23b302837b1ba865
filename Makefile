# bayesfo: two commands for a newcomer, `make demo` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DOCS_STAMP := $(VENV)/.docs-stamp
DEMO_OUT ?= demo-output
# The default suite runs its test files on two processes (pytest-xdist; one file stays on one
# process, so its module fixtures are computed once). XDIST= runs them in this process.
XDIST ?= -n 2 --dist loadfile

.PHONY: help venv test test-unit test-slow test-all test-plain demo bench docs clean

help:
	@echo "make demo       create $(VENV), install bayesfo, run a model comparison on bundled data"
	@echo "make test       create $(VENV), install bayesfo, run the default test suite"
	@echo "make test-unit  the unit tier alone (tests/unit: no sampling, under a minute)"
	@echo "make test-slow  the long validation runs (thesis tables in full, GPL reference data)"
	@echo "make test-plain a plain 'pip install .' (no extras) in its own venv runs each command"
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
	MPLBACKEND=Agg $(BIN)/python -m pytest -m "not slow" -q --durations=15 $(XDIST)

test-unit: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m "not slow" -q --durations=10 tests/unit

test-slow: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m slow -q

test-all: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

# A user's plain install: no extras (no dask, no test tools), then the commands that write
# results, on bundled data, with figures.
PLAIN_VENV ?= .venv-plain
PLAIN_OUT  ?= $(PLAIN_VENV)/runs
test-plain:
	rm -rf $(PLAIN_VENV)
	$(PYTHON) -m venv $(PLAIN_VENV)
	$(PLAIN_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(PLAIN_VENV)/bin/python -m pip install --quiet .
	$(PLAIN_VENV)/bin/python -c "import importlib.util as u, sys; sys.exit(u.find_spec('dask') is not None)" \
		|| { echo "test-plain: dask is installed, so this is no plain install"; exit 1; }
	mkdir -p $(PLAIN_OUT)
	MPLBACKEND=Agg $(PLAIN_VENV)/bin/bayesfo compare examples/data/adhesive_468mp/Tp020C.csv \
		--structures zener,voigt --out $(PLAIN_OUT)/compare
	MPLBACKEND=Agg $(PLAIN_VENV)/bin/bayesfo mastercurve examples/data/adhesive_468mp/Tp0[0-2]0C.csv \
		examples/data/adhesive_468mp/Tp030C.csv --structures zener --law free --out $(PLAIN_OUT)/master
	$(PLAIN_VENV)/bin/bayesfo predict $(PLAIN_OUT)/compare --quantity relaxation_modulus --time 1e-3:1e2:5
	$(PLAIN_VENV)/bin/bayesfo predict $(PLAIN_OUT)/master --quantity storage --omega 1:10:3 \
		--temperature 15
	$(PLAIN_VENV)/bin/bayesfo export $(PLAIN_OUT)/master --format abaqus --out $(PLAIN_OUT)/deck.inp
	@echo "test-plain: compare, mastercurve, predict and export ran on a plain install"

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
	rm -rf $(VENV) $(PLAIN_VENV) build *.egg-info $(DEMO_OUT)
