# latentrl: every target sets itself up from a clean clone (venv, deps, native build).
# Python 3.11 or newer: python3.11 where it is on the PATH, else python3 (checked before the venv is made).
PYTHON ?= $(shell command -v python3.11 2>/dev/null || command -v python3 2>/dev/null || echo python3.11)
VENV := .venv
PY := $(VENV)/bin/python
export CARGO_TARGET_DIR ?= $(CURDIR)/target

INSTALL_VENV := target/install-check-venv

.PHONY: help demo test test-all bench figures docs lint build wheel install-check fuzz fuzz-py clean
.DEFAULT_GOAL := help

help: ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | sed 's/:.*## /\t/'

$(VENV)/.deps: pyproject.toml
	@$(PYTHON) -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null || { echo "latentrl needs Python 3.11 or newer: '$(PYTHON)' is missing or older (give one: make PYTHON=/path/to/python3.11 ...)"; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet "maturin>=1.9,<2" numpy scipy matplotlib "imageio>=2.31" "imageio-ffmpeg>=0.5" "moviepy>=2" "rerun-sdk>=0.23" tqdm threadpoolctl gymnasium pytest pytest-timeout hypothesis mypy scipy-stubs types-tqdm "ruff>=0.17,<0.18" scikit-learn pandas "ray>=2.9" "pyarrow>=14" "h5py>=3.10" "rosbags>=0.10"
	touch $@

# The old extension is unlinked first: maturin would overwrite it in place, under the feet of a
# run still using it; unlinked, that run keeps its copy.
$(VENV)/.built: $(VENV)/.deps Cargo.toml Cargo.lock $(shell find crates python -name '*.rs' -o -name '*.toml' -o -name '*.py' 2>/dev/null)
	rm -f python/latentrl/_native.*.so
	VIRTUAL_ENV="$(CURDIR)/$(VENV)" $(VENV)/bin/maturin develop --release --quiet
	touch $@

build: $(VENV)/.built ## create the venv, install deps, build the native module

demo: build ## reproduce Table I and Experiment 1 (Fig. 4) on defaults into results/
	$(PY) -m latentrl run table1 --out results/table1
	$(PY) -m latentrl run exp1 --out results/exp1

test: lint ## clippy, stub check, Rust tests (pure crates and the binding's panic guard), the default pytest run, install check
	cargo test --quiet
	cargo test --quiet -p latentrl_py --lib
	$(PY) -m pytest -q
	$(MAKE) --no-print-directory install-check
	$(MAKE) --no-print-directory docs

# The [sb3] extra's package, installed by name: `pip install -e ".[sb3]"` would rebuild the native module.
$(VENV)/.sb3: $(VENV)/.deps
	$(PY) -m pip install --quiet "stable-baselines3>=2.3"
	touch $@

# The [docs] extra's packages, installed by name like the [sb3] extra's above.
$(VENV)/.docs: $(VENV)/.deps
	$(PY) -m pip install --quiet "mkdocs>=1.6" "mkdocstrings[python]>=1.0"
	touch $@

docs: build $(VENV)/.docs ## the documentation site into target/site/ (MkDocs, warnings are errors: broken links, anchors, references)
	$(PY) -m mkdocs build --strict --site-dir target/site

test-all: lint $(VENV)/.sb3 ## everything, slow reproductions and the SB3 example included (installs the [sb3] extra, ≈ 3 GB)
	cargo test --quiet
	cargo test --quiet -p latentrl_py --lib
	$(PY) -m pytest -q -m ''

bench: build ## criterion benches, the NumPy loop, GPy, MuJoCo and Pinocchio comparisons (JSON in benches/results/)
	cargo bench -p latent_core -p sim
	$(PY) benches/bench_td.py
	$(PY) benches/bench_startup.py
	bash benches/setup_bench_env.sh
	benches/.venv-bench/bin/python benches/bench_gp.py
	benches/.venv-bench/bin/python benches/bench_sim.py
	benches/.venv-bench/bin/python benches/bench_urdf.py
	benches/.venv-bench/bin/python benches/bench_accuracy.py
	$(PY) benches/ratio_table.py

figures: build ## the README's two GIFs: quick Exp 2 and Exp 3 runs into results/, then latentrl replay of a frozen test episode of each
	$(PY) -m latentrl run exp2 --quick --no-progress --out results/exp2-quick
	$(PY) -m latentrl run exp3 --quick --no-progress --out results/exp3-quick
	$(PY) -m latentrl replay results/exp2-quick --test 0 --out docs/figures/exp2-quick-pass.gif --width 640 --fps 10 --max-frames 100
	$(PY) -m latentrl replay results/exp3-quick --test 2 --out docs/figures/exp3-quick-lift.gif --width 640 --fps 10 --max-frames 101

lint: build ## rustfmt, clippy (warnings are errors), ruff, the native stubs against the module, mypy --strict
	cargo fmt --all --check
	cargo clippy --quiet --workspace --all-targets -- -D warnings
	$(PY) -m ruff check python tests examples benches
	$(PY) -m mypy.stubtest latentrl._native
	$(PY) -m mypy --strict python/latentrl

WHEELS := target/wheels
# What a user without Rust has: the venv's own bin and the system's, no ~/.cargo/bin (quoted: a
# checkout's path may hold spaces, as every $(CURDIR) in a recipe here).
NO_RUST_PATH = "$(CURDIR)/$(INSTALL_VENV)/bin":/usr/bin:/bin

wheel: build ## the abi3 wheel (one for every CPython >= 3.11, manylinux) and the sdist, into target/wheels/
	rm -rf $(WHEELS)
	$(VENV)/bin/maturin build --release --quiet -o $(WHEELS)
	$(VENV)/bin/maturin sdist -o $(WHEELS) > /dev/null
	tar -tzf $(WHEELS)/latentrl-*.tar.gz | grep -q 'crates/latent_core/src/lib.rs'

install-check: wheel ## the wheel into a fresh venv on a PATH without cargo or rustc, then used from outside the tree, without and with the [plot] extra
	rm -rf $(INSTALL_VENV)
	$(PYTHON) -m venv $(INSTALL_VENV)
	PATH=$(NO_RUST_PATH) sh -c '! command -v cargo && ! command -v rustc'
	PATH=$(NO_RUST_PATH) $(INSTALL_VENV)/bin/python -m pip install --quiet --upgrade pip
	PATH=$(NO_RUST_PATH) $(INSTALL_VENV)/bin/python -m pip install --quiet --only-binary latentrl $(WHEELS)/latentrl-*abi3*.whl
	cd $(INSTALL_VENV) && bin/python -c "import sys, latentrl; sys.exit(latentrl.__file__.startswith('$(CURDIR)/python'))"
	cd $(INSTALL_VENV) && bin/python -c "import sys, latentrl._native as n; sys.exit(not n.__file__.endswith('.abi3.so'))"
	cd $(INSTALL_VENV) && PATH=$(NO_RUST_PATH) bin/python -m latentrl info > /dev/null
	cd $(INSTALL_VENV) && bin/python -c "import importlib.util, sys; sys.exit(importlib.util.find_spec('matplotlib') is not None)"
	cd $(INSTALL_VENV) && PATH=$(NO_RUST_PATH) bin/python "$(CURDIR)/tests/core_without_matplotlib.py"
	PATH=$(NO_RUST_PATH) $(INSTALL_VENV)/bin/python -m pip install --quiet "latentrl[plot]"
	cd $(INSTALL_VENV) && PATH=$(NO_RUST_PATH) bin/latentrl run exp2 --quick --no-progress --trials 1 --episodes 2 --episode.max-steps 10 \
		--test-episodes 1 --fig5-samples 50 --gplvm-max-iter 20 --out run
	cd $(INSTALL_VENV) && test -s run/results.json && test -s run/fig6a.png && echo "install-check: the abi3 wheel installs and runs without Rust"

FUZZ_TARGET ?= urdf_parse
FUZZ_SECONDS ?= 180
# Seeds and dictionary per target: the shipped URDFs for the URDF targets, the test arm's meshes for mesh_parse.
FUZZ_SEEDS = $(if $(filter mesh_parse,$(FUZZ_TARGET)),tests/robots/arm7_description/meshes/collision,python/latentrl/data)
FUZZ_DICT = $(if $(filter mesh_parse,$(FUZZ_TARGET)),,-dict=fuzz/urdf.dict)

fuzz: ## cargo fuzz the URDF parser + physics, or the mesh reader, for FUZZ_SECONDS (180) s; FUZZ_TARGET=urdf_parse|urdf_numbers|mesh_parse; installs cargo-fuzz if missing
	@command -v cargo-fuzz > /dev/null || cargo install --locked cargo-fuzz
	mkdir -p fuzz/corpus/$(FUZZ_TARGET)
	RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="$(CURDIR)/fuzz/target" nice -n 10 cargo fuzz run --sanitizer none $(FUZZ_TARGET) \
		fuzz/corpus/$(FUZZ_TARGET) $(FUZZ_SEEDS) -- -max_total_time=$(FUZZ_SECONDS) -timeout=10 $(FUZZ_DICT) \
		-print_final_stats=1

fuzz-py: build ## atheris on the demo-file, saved-model and run-folder readers for FUZZ_SECONDS (180) s each; installs atheris if missing
	@$(PY) -c "import atheris" 2> /dev/null || $(PY) -m pip install --quiet atheris
	mkdir -p fuzz/corpus/demos fuzz/corpus/run_folder fuzz/artifacts
	nice -n 10 $(PY) fuzz/fuzz_demos_models.py fuzz/corpus/demos -max_total_time=$(FUZZ_SECONDS) -print_final_stats=1
	nice -n 10 $(PY) fuzz/fuzz_run_folder.py fuzz/corpus/run_folder -max_total_time=$(FUZZ_SECONDS) \
		-artifact_prefix=fuzz/artifacts/ -print_final_stats=1

clean: ## remove the venv and build outputs
	rm -rf $(VENV) target
