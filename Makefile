# Fresh-machine entry points: `make demo`, `make test`, `make bench`.
PY     ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
FMUS   := build/fmus/.built
FMUS3  := build/fmus/fmi3/.built
SOURCES := $(shell find plant estimator controller diagnosis fmus papers arena orchestrator/interop/basilisk -name '*.py' 2>/dev/null) $(wildcard fmus/native/*/*)
JOBS   ?= 2

# Python caches bytecode for make's commands even where the environment sets PYTHONDONTWRITEBYTECODE
# (the .pyc files go to __pycache__ folders of .venv and of the project, both ignored by git):
# without it every process compiles the ~3000 modules it imports again, 11 s per pytest worker.
unexport PYTHONDONTWRITEBYTECODE

.PHONY: all install fmus fmus3 fmus-both warm demo test test-long lint bench clean

all: fmus

# uv installs in seconds what pip takes over a minute for; pip if uv cannot be had
$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q 'uv>=0.5' && $(BIN)/uv pip install -q --python $(BIN)/python -e '.[test,basilisk]' \
		|| $(BIN)/pip install -q --no-compile -e '.[test,basilisk]'
	touch $(STAMP)

install: $(STAMP)

$(FMUS): $(STAMP) $(SOURCES)
	$(BIN)/ftcsim build --out build/fmus -q
	touch $(FMUS)

fmus: $(FMUS)

$(FMUS3): $(STAMP) $(SOURCES)
	$(BIN)/ftcsim build --fmi 3 --out build/fmus/fmi3 -q
	touch $(FMUS3)

fmus3: $(FMUS3)

# FMI 2.0 then 3.0: the second build reads the blocks' import probes the first kept (fmus/runtime.py)
fmus-both:
	$(MAKE) --no-print-directory $(FMUS)
	$(MAKE) --no-print-directory $(FMUS3)

# compile and cache the numba kernels (plant/kernels) once, before the test workers need them (37 s
# of CPU on a cold cache; in two halves 46 s, as both compile the kernels they share)
warm: $(STAMP)
	$(BIN)/python -m orchestrator.tools.warm

# every paper's demo scenarios (Paper.demo in papers/*/paper.py), then each paper's report, on every core;
# the kernels compile beside the FMU build (orchestrator/tools/demo.py; -v there shows the solvers' logs)
demo: $(STAMP)
	$(MAKE) --no-print-directory -j2 warm fmus
	$(BIN)/python -m orchestrator.tools.demo --out results

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/lint-imports --no-cache

# the kernel cache beside the FMI 2.0 and 3.0 builds and lint, then the whole suite
test: $(STAMP)
	$(MAKE) --no-print-directory -j2 warm fmus-both lint
	$(BIN)/python -m pytest -q -n $(JOBS) --dist worksteal -m "not long"

# the integration tests of minutes (tests/conftest.py: LONG): docs executed, Dask clusters, the arena
test-long: $(STAMP)
	$(MAKE) --no-print-directory -j2 warm fmus-both
	$(BIN)/python -m pytest -q -n $(JOBS) --dist worksteal -m long

bench: $(FMUS)
	$(BIN)/python benchmarks/bench_master.py
	$(BIN)/python benchmarks/bench_interop.py
	$(BIN)/python benchmarks/bench_kernels.py --repeat 1
	$(BIN)/python benchmarks/bench_designs.py
	$(BIN)/python benchmarks/bench_step_policies.py
	$(BIN)/python benchmarks/bench_campaigns.py
	$(BIN)/python benchmarks/bench_zhang2019.py --loop-seconds 3 --out build/bench/zhang2019.json
	$(BIN)/python benchmarks/bench_xu2024.py --skip-designs --workers 2 --mc-runs 200 --out build/bench/xu2024.json
	rm -rf build/bench/arena-full  # the full shipped arena from nothing: about an hour on 2 cores
	$(BIN)/python benchmarks/bench_arena.py --full --workers 2 --out build/bench/arena.json

clean:
	rm -rf build
