# latentrl: every target sets itself up from a clean clone (venv, deps, native build).
PYTHON ?= python3.11
VENV := .venv
PY := $(VENV)/bin/python
export CARGO_TARGET_DIR ?= $(CURDIR)/target

.PHONY: help demo test test-all bench lint build clean
.DEFAULT_GOAL := help

help: ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | sed 's/:.*## /\t/'

$(VENV)/.deps: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "maturin>=1.9,<2" numpy scipy matplotlib tqdm gymnasium pytest pytest-timeout hypothesis mypy
	touch $@

$(VENV)/.built: $(VENV)/.deps Cargo.toml Cargo.lock $(shell find crates python -name '*.rs' -o -name '*.toml' -o -name '*.py' 2>/dev/null)
	VIRTUAL_ENV=$(CURDIR)/$(VENV) $(VENV)/bin/maturin develop --release --quiet
	touch $@

build: $(VENV)/.built ## create the venv, install deps, build the native module

demo: build ## reproduce Table I and Experiment 1 (Fig. 4) on defaults into results/
	$(PY) -m latentrl run table1 --out results/table1
	$(PY) -m latentrl run exp1 --out results/exp1

test: lint ## clippy, stub check, Rust tests (pure crates and the binding's panic guard) and the default pytest run
	cargo test --quiet
	cargo test --quiet -p latentrl_py --lib
	$(PY) -m pytest -q

test-all: lint ## everything, slow reproductions included
	cargo test --quiet
	cargo test --quiet -p latentrl_py --lib
	$(PY) -m pytest -q -m ''

bench: build ## criterion benches, the NumPy loop and GPy comparisons (JSON in benches/results/)
	cargo bench -p latent_core -p sim
	$(PY) benches/bench_td.py
	bash benches/setup_bench_env.sh
	benches/.venv-bench/bin/python benches/bench_gp.py

lint: build ## rustfmt, clippy (warnings are errors) and the native stubs against the module
	cargo fmt --all --check
	cargo clippy --quiet --workspace --all-targets -- -D warnings
	$(PY) -m mypy.stubtest latentrl._native

clean: ## remove the venv and build outputs
	rm -rf $(VENV) target
