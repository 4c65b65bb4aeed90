# tubesweep — one-command set-up. Needs only Rust (cargo), Python 3.9+ and pip.
#   make demo       build, run the built-in examples, write pictures to out/demo
#   make test       build, run cargo and pytest suites
#   make bench      benchmarks against scikit-fmm, potpourri3d, pygeodesic (installs them)
#   make reproduce  every table and figure of the paper into out/reproduce
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
DEPS   := $(VENV)/.deps-installed
BUILT  := $(VENV)/.built
RUST_SOURCES := $(shell find crates -name '*.rs' -o -name Cargo.toml) Cargo.toml pyproject.toml

.PHONY: all build demo test test-rust test-python bench reproduce reproduce-quick clean help

all: build

help:
	@sed -n '2,6p' Makefile

$(PY):
	$(PYTHON) -m venv $(VENV)

$(DEPS): pyproject.toml | $(PY)
	$(PIP) install -q --upgrade pip
	$(PIP) install -q "maturin>=1.5,<2" "numpy>=1.22" scipy matplotlib scikit-image meshio trimesh tqdm pytest scikit-fmm pygeodesic potpourri3d geographiclib "dask>=2023.1" "distributed>=2023.1" "cloudpickle>=2"
	@touch $@

$(BUILT): $(DEPS) $(RUST_SOURCES)
	VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH $(VENV)/bin/maturin develop --release -q
	@touch $@

build: $(BUILT)

demo: build
	$(PY) -m tubesweep demo --out out/demo

test: build test-rust test-python

test-rust:
	cargo test --release -p tubesweep-core
	# the kernel-stats counters' test, on its own (its totals are process-wide)
	cargo test --release -p tubesweep-core --features kernel-stats kernel_stats::

test-python: build
	$(PY) -m pytest -q

bench: build
	$(PIP) install -q potpourri3d pygeodesic scikit-fmm geographiclib
	$(PY) benches/run.py
	# issue 7's other targets: the sphere at N = 1001 and 2001, and the kernel's updates per
	# second per core and 2-core speed-up
	$(PY) benches/run.py --scale
	$(PY) benches/microbench.py --sizes 101,201,401 --schemes godunov --repeats 5
	# issue 33: many sources on one surface (solve_many, Dask, the peers per source, the 1000 x 1000 matrix)
	$(PY) benches/many_sources.py

reproduce: build
	$(PY) -m tubesweep reproduce all --out out/reproduce

reproduce-quick: build
	$(PY) -m tubesweep reproduce all --quick --out out/reproduce-quick

clean:
	rm -rf target out $(VENV) python/tubesweep/*.so
