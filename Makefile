# Fresh-machine entry points: `make demo`, `make test`, `make bench`.
PY     ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
FMUS   := build/fmus/.built
SOURCES := $(shell find plant estimator controller fmus papers -name '*.py' 2>/dev/null)
JOBS   ?= 2

.PHONY: all install fmus demo test lint bench clean

all: fmus

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q -e '.[test]'
	touch $(STAMP)

install: $(STAMP)

$(FMUS): $(STAMP) $(SOURCES)
	$(BIN)/ftcsim build --out build/fmus
	touch $(FMUS)

fmus: $(FMUS)

# every paper's demo scenarios (Paper.demo in papers/*/paper.py), then each paper's report
demo: $(FMUS)
	$(BIN)/python -m orchestrator.demo --out results

lint: $(STAMP)
	$(BIN)/ruff check .

test: $(FMUS) lint
	$(BIN)/python -m pytest -q -n $(JOBS)

bench: $(FMUS)
	$(BIN)/python benchmarks/bench_master.py
	$(BIN)/python benchmarks/bench_interop.py
	$(BIN)/python benchmarks/bench_designs.py
	$(BIN)/python benchmarks/bench_step_policies.py
	$(BIN)/python benchmarks/bench_campaigns.py

clean:
	rm -rf build
