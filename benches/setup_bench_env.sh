#!/usr/bin/env bash
# Creates benches/.venv-bench: the peers GPy, MuJoCo and Pinocchio (never runtime dependencies of
# latentrl), matplotlib (bench_accuracy.py's figures) and a release wheel of latentrl built from
# this tree, in a venv of their own so the peers' pins cannot touch the project's .venv.
# Idempotent; re-run after changing Rust code to refresh the wheel.
#
#   bash benches/setup_bench_env.sh && benches/.venv-bench/bin/python benches/bench_gp.py
#   benches/.venv-bench/bin/python benches/bench_sim.py
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3.11}
VENV=benches/.venv-bench
MATURIN=${MATURIN:-.venv/bin/maturin}   # from `make build`; any maturin>=1.9 works

if [ ! -x "$VENV/bin/python" ]; then
    "$PYTHON" -m venv "$VENV"
    "$VENV/bin/python" -m pip install --quiet --upgrade pip
fi
"$VENV/bin/python" -m pip install --quiet "GPy>=1.13" "mujoco>=3.13" "pin>=3" threadpoolctl "matplotlib>=3.8"

if [ ! -x "$MATURIN" ]; then
    echo "setup_bench_env: $MATURIN not found; run 'make build' first or set MATURIN" >&2
    exit 1
fi
WHEELS=$(mktemp -d)
trap 'rm -rf "$WHEELS"' EXIT
# Same profile and features as `make build`, so cargo reuses the release artefacts.
"$MATURIN" build --release --quiet -o "$WHEELS"
"$VENV/bin/python" -m pip install --quiet --force-reinstall --no-deps "$WHEELS"/latentrl-*.whl
"$VENV/bin/python" -m pip install --quiet "$WHEELS"/latentrl-*.whl   # its dependencies, pins kept
"$VENV/bin/python" -c "import GPy, mujoco, numpy, latentrl; print('bench env: GPy', GPy.__version__, 'MuJoCo', mujoco.__version__, 'numpy', numpy.__version__, 'latentrl', latentrl.__version__)"
