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
	$(PY) -m pip install --quiet "maturin>=1.9,<2" numpy scipy matplotlib tqdm pytest pytest-timeout hypothesis
	touch $@

$(VENV)/.built: $(VENV)/.deps Cargo.toml Cargo.lock $(shell find crates python -name '*.rs' -o -name '*.toml' -o -name '*.py' 2>/dev/null)
	VIRTUAL_ENV=$(CURDIR)/$(VENV) $(VENV)/bin/maturin develop --release --quiet
	touch $@

build: $(VENV)/.built ## create the venv, install deps, build the native module

demo: build ## reproduce Table I (paper) on defaults and print it
	$(PY) -m latentrl run table1 --out results/table1

test: build ## Rust tests (pure crates) and the default pytest run
	cargo test --quiet
	$(PY) -m pytest -q

test-all: build ## everything, slow reproductions included
	cargo test --quiet
	$(PY) -m pytest -q -m ''

bench: build ## criterion benches and the Python peer comparison (JSON in benches/results/)
	cargo bench -p latent_core
	$(PY) benches/bench_gp.py

clean: ## remove the venv and build outputs
	rm -rf $(VENV) target
