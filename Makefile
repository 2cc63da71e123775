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

DEMO_RUNS := li2023_pd li2023_fasmc li2023_aismc li2023_pd_fe li2023_fasmc_weak

# paper 000, section 5: every controller on the same faulty flexible spacecraft, then the report
demo: $(FMUS)
	@for s in $(DEMO_RUNS); do $(BIN)/ftcsim run scenarios/$$s.toml --out results/$$s || exit $$?; done
	$(BIN)/ftcsim report $(foreach s,$(filter-out li2023_pd,$(DEMO_RUNS)),results/$(s)) --out results/report
	@cat results/report/report.md

test: $(FMUS)
	$(BIN)/python -m pytest -q

bench: $(FMUS)
	$(BIN)/python benchmarks/bench_master.py
	$(BIN)/python benchmarks/bench_interop.py
	$(BIN)/python benchmarks/bench_designs.py

clean:
	rm -rf build results
