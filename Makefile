# Interplay: `make demo` and `make test` each install everything they need into .venv first.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Numba's OpenMP layer and OpenBLAS threads collapse when the other core is busy (DESIGN.md).
export NUMBA_THREADING_LAYER ?= workqueue
export OPENBLAS_NUM_THREADS ?= 1

.PHONY: demo test test-all bench clean

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[test,bench]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/interplay compare basketball --out out/basketball

test: $(STAMP)
	$(BIN)/pytest -q

test-all: $(STAMP)
	$(BIN)/pytest -q -m ""

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_basketball.py --out out/bench

clean:
	rm -rf $(VENV) out .pytest_cache build src/*.egg-info
