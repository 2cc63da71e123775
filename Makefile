# Fresh-machine entry points: `make demo`, `make test`, `make bench`.
PY     ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
FMUS   := build/fmus/.built
SOURCES := $(shell find plant estimator controller fmus -name '*.py' 2>/dev/null)

.PHONY: all install fmus demo test bench clean

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

demo: $(FMUS)
	rm -rf results/li2023_pd
	$(BIN)/ftcsim run scenarios/li2023_pd.toml --out results/li2023_pd

test: $(FMUS)
	$(BIN)/python -m pytest -q

bench: $(FMUS)
	$(BIN)/python benchmarks/bench_master.py

clean:
	rm -rf build results
