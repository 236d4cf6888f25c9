# Interplay: `make demo` and `make test` each install everything they need into .venv first.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Numba's OpenMP layer and OpenBLAS threads collapse when the other core is busy (DESIGN.md).
export NUMBA_THREADING_LAYER ?= workqueue
export OPENBLAS_NUM_THREADS ?= 1

.PHONY: clean-numba demo test test-all bench bench-sweep bench-cloth clean sysdeps browser fuzz

# The preview renderer needs Mesa's EGL driver (headless OpenGL on the CPU); the slow browser
# tests need Chromium. apt runs only when something is missing, and only as root.
APT := DEBIAN_FRONTEND=noninteractive apt-get
sysdeps:
	@if ldconfig -p | grep -q libEGL_mesa && ldconfig -p | grep -q 'libGL.so.1 ' \
		&& ls /usr/lib/*/dri/swrast_dri.so >/dev/null 2>&1; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
		$(APT) update -q && $(APT) install -y -q libegl1 libegl-mesa0 libgl1-mesa-dri libgl1; \
	else echo "note: Mesa EGL missing; install libegl1 libegl-mesa0 libgl1-mesa-dri (as root) or use --no-video"; fi

browser:
	@if command -v chromium >/dev/null; then :; \
	elif [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
		$(APT) update -q && $(APT) install -y -q chromium; \
	else echo "note: no chromium; the slow browser tests will be skipped"; fi

$(STAMP): pyproject.toml | sysdeps
	$(PY) -m venv $(VENV)
	$(BIN)/pip install -q --upgrade pip
	$(BIN)/pip install -q -e '.[test,bench,viewer]'
	@echo "compiling every scene's kernels once, so that no first run waits for them:"
	$(BIN)/interplay warm
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/interplay compare basketball --out out/basketball
	@echo "report: out/basketball/report.html"

test: $(STAMP)
	$(BIN)/pytest -q

# the slow tests include the Ray executor's: Ray (~240 MB, ~11 s to install here) only for them
test-all: $(STAMP) browser
	$(BIN)/pip install -q -e '.[cluster]'
	$(BIN)/pytest -q -m ""

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_basketball.py --out out/bench

# a wedge of 8 runs on 1 and 2 local workers and on a local Ray cluster; ~5 min
bench-sweep: $(STAMP)
	$(BIN)/pip install -q -e '.[cluster]'
	$(BIN)/python benchmarks/bench_sweep.py --out out/bench

# the cloth drape against MuJoCo and NVIDIA Newton (installed here: ~480 MB); ~30-60 min
bench-cloth: $(STAMP)
	$(BIN)/pip install -q -e '.[peers]'
	$(BIN)/python benchmarks/bench_cloth.py --out out/bench

clean:
	rm -rf $(VENV) out .pytest_cache build src/*.egg-info

# Numba's cache (kernel edits do not need this: the cache folder is keyed by every kernel's
# source, src/interplay/kernels/__init__.py); for a first run on an empty cache
clean-numba:
	find src -name '*.nbi' -delete -o -name '*.nbc' -delete

# hostile-input fuzzing of every surface (docs/robustness.md): ~5,000 cases, 15-60 min
fuzz: $(STAMP)
	$(BIN)/python benchmarks/fuzz.py --out out/bench
