# bayesfo: two commands for a newcomer, `make demo` and `make test`.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-stamp
DEMO_OUT ?= demo-output

.PHONY: help venv test test-slow test-all demo bench clean

help:
	@echo "make demo       create $(VENV), install bayesfo, run a model comparison on bundled data"
	@echo "make test       create $(VENV), install bayesfo, run the default test suite"
	@echo "make test-slow  the long validation runs (thesis tables in full, GPL reference data)"
	@echo "make bench      run the benchmarks in benchmarks/"

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	@touch $(STAMP)

venv: $(STAMP)

test: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m "not slow" -q

test-slow: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -m slow -q

test-all: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python -m pytest -q

demo: $(STAMP)
	MPLBACKEND=Agg $(BIN)/python examples/demo.py --out $(DEMO_OUT)

bench: $(STAMP)
	@for f in benchmarks/bench_*.py; do echo "== $$f"; $(BIN)/python $$f || exit 1; done

clean:
	rm -rf $(VENV) build *.egg-info $(DEMO_OUT)
