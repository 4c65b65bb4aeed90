# tubesweep — one-command set-up. Needs only Rust (cargo), Python 3.9+ and pip.
#   make demo       build, run the built-in examples, write pictures to out/demo
#   make test       build, lint, run cargo and pytest suites (installs the test dependencies)
#   make lint       cargo fmt --check, clippy -D warnings, ruff, mypy, the import-cycle check
#   make docs       the user guide, API reference and gallery as HTML in out/site
#   make bench      benchmarks against scikit-fmm, potpourri3d, pygeodesic (installs them)
#   make reproduce  every table and figure of the paper into out/reproduce
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip
DEPS   := $(VENV)/.deps-runtime
TEST_DEPS_DONE  := $(VENV)/.deps-test
DOCS_DEPS_DONE  := $(VENV)/.deps-docs
LINT_DEPS_DONE  := $(VENV)/.deps-lint
BUILT  := $(VENV)/.built
# what the package needs at run time with its plot, mesh and progress extras (pyproject.toml)
RUNTIME_DEPS := "maturin>=1.5,<2" "numpy>=1.22" "matplotlib>=3.5" "scipy>=1.8" "scikit-image>=0.19" \
                "meshio>=5" "trimesh>=3.9" "tqdm>=4"
# pyproject.toml's test, bench and docs extras
TEST_DEPS  := "pytest>=7" "hypothesis>=6" scikit-fmm pygeodesic potpourri3d geographiclib "dask>=2023.1" "distributed>=2023.1" \
              "cloudpickle>=2"
BENCH_DEPS := potpourri3d pygeodesic scikit-fmm geographiclib
# pyproject.toml's lint extra, pinned so that every run checks the same rules
LINT_DEPS  := "ruff==0.17.6" "mypy==2.4.1"
DOCS_DEPS  := "mkdocs>=1.6,<2" "mkdocs-material>=9,<10" "mkdocstrings[python]>=0.26" "griffe-inherited-docstrings>=1.1"
# pip's notes on extras that do not apply ("Ignoring ...: markers") and on what is already there
export PIP_QUIET := 1
export PIP_DISABLE_PIP_VERSION_CHECK := 1
RUST_SOURCES := $(shell find crates -name '*.rs' -o -name Cargo.toml) Cargo.toml pyproject.toml

.PHONY: all build demo test lint test-rust test-python docs bench reproduce reproduce-quick clean help

all: build

help:
	@sed -n '2,8p' Makefile

$(PY):
	$(PYTHON) -m venv $(VENV)

$(DEPS): pyproject.toml | $(PY)
	@echo "installing the runtime dependencies into $(VENV)"
	@$(PIP) install -q --upgrade pip
	@$(PIP) install -q $(RUNTIME_DEPS)
	@touch $@

$(TEST_DEPS_DONE): pyproject.toml | $(PY)
	@echo "installing the test dependencies into $(VENV)"
	@$(PIP) install -q $(TEST_DEPS)
	@touch $@

$(LINT_DEPS_DONE): pyproject.toml | $(PY)
	@echo "installing the linters into $(VENV)"
	@$(PIP) install -q $(LINT_DEPS)
	@touch $@

$(DOCS_DEPS_DONE): pyproject.toml | $(PY)
	@echo "installing the documentation tools into $(VENV)"
	@$(PIP) install -q $(DOCS_DEPS)
	@touch $@

$(BUILT): $(DEPS) $(RUST_SOURCES)
	@echo "building tubesweep (release; the first build takes a few minutes)"
	@VIRTUAL_ENV=$(abspath $(VENV)) PATH=$(abspath $(VENV))/bin:$$PATH $(VENV)/bin/maturin develop --release -q
	@touch $@

build: $(BUILT)

demo: build
	$(PY) -m tubesweep demo --out out/demo

test: build lint test-rust test-python

# mypy reads numpy's types from the runtime dependencies
lint: $(LINT_DEPS_DONE) $(DEPS)
	cargo fmt --all --check
	cargo clippy --workspace --all-targets -- -D warnings
	$(VENV)/bin/ruff check python tests benches tools examples mkdocs_hooks.py
	$(VENV)/bin/ruff format --check python tests benches tools examples mkdocs_hooks.py
	$(VENV)/bin/mypy
	$(PY) tools/import_cycles.py

test-rust:
	cargo test --release -p tubesweep-core
	# the kernel-stats counters' test, on its own (its totals are process-wide)
	cargo test --release -p tubesweep-core --features kernel-stats kernel_stats::

# the tests build the documentation site in strict mode too (tests/test_docs.py), so they need mkdocs
test-python: build $(TEST_DEPS_DONE) $(DOCS_DEPS_DONE)
	$(PY) -m pytest -q

docs: build $(DOCS_DEPS_DONE)
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict -q
	@echo "wrote out/site/index.html"

bench: build
	$(PIP) install -q $(BENCH_DEPS)
	$(PY) benches/run.py
	# issue 7's other targets: the sphere at N = 1001 and 2001, and the kernel's updates per
	# second per core and 2-core speed-up
	$(PY) benches/run.py --scale
	$(PY) benches/microbench.py --sizes 101,201,401 --schemes godunov --repeats 5
	# issue 33: many sources on one surface (solve_many, Dask, the peers per source, the 1000 x 1000 matrix)
	$(PY) benches/many_sources.py
	# issue 31: travel_time order=1 against order=2 in the box, cubic against multilinear evaluation
	$(PY) benches/box_order2.py
	# issue 31's cost targets: order=2 / order=1 time and memory per band node on the closed library surfaces
	$(PY) benches/order2_cost.py --surfaces sphere,ellipsoid,torus,rounded-cube
	# issue 32: the upwind solver for the moving medium and metrics against LxF and isotropic Godunov
	$(PY) benches/upwind.py
	cargo run --release -q -p tubesweep-core --example upwind_cost
	# the cost per node update against the isotropic Godunov update: same band, threads and sweep mode
	cargo run --release -q -p tubesweep-core --example upwind_sweep -- 101 1
	cargo run --release -q -p tubesweep-core --example upwind_sweep -- 161 1
	# issue 35: the default thread count against threads=1 and all cores, quiet and with cores kept busy
	$(PY) benches/under_load.py
	# issue 45: point clouds against potpourri3d's PointCloudHeatSolver (docs/point-clouds.md)
	$(PY) benches/point_clouds.py
	# issue 47: warm re-solves on a moving surface, the growing sphere, ts.evolve against front tracking
	$(PY) benches/moving_surfaces.py --n 121 --steps 20 --rounds 3
	$(PY) benches/moving_surfaces.py --growth --n 121 --steps 20
	$(PY) benches/moving_axisymmetric.py --sizes 41,61,81
	# issue 45 part 2: meshes at second order against the heat method and MMP
	$(PY) benches/mesh_order2.py

reproduce: build
	$(PY) -m tubesweep reproduce all --out out/reproduce

reproduce-quick: build
	$(PY) -m tubesweep reproduce all --quick --out out/reproduce-quick

clean:
	rm -rf target out $(VENV) python/tubesweep/*.so
