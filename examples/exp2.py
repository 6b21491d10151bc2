"""Experiment 2 (paper Fig. 5, 6) on the paper's parameters: two simulated planar arms,
25 trials × 5000 episodes × 1000 steps (≈ 125 M physics-simulated RL steps: hours).

    python examples/exp2.py [--quick] [--out results/exp2]
"""

import argparse
from pathlib import Path

from latentrl.experiments.exp2 import Exp2Preset
from latentrl.experiments import run_experiment


def main() -> None:
    """Runs the preset chosen on the command line and prints the result."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="the ~1.5-minute smoke-test preset")
    parser.add_argument("--out", type=Path, default=Path("results/exp2"))
    args = parser.parse_args()
    meta = run_experiment("exp2", Exp2Preset.quick() if args.quick else Exp2Preset(), args.out)
    trials = meta["trials"]["latent"].values()
    last = [t["mean_return_last"] for t in trials]
    print(f"mean return of the last 10 % of episodes {sum(last) / len(last):.1f}")
    if all("test_success" in t for t in trials):
        success = [t["test_success"] for t in trials]
        print(f"frozen test episodes from below the wall: success {100 * sum(success) / len(success):.1f} %")
    print(f"figures and results in {args.out}")


if __name__ == "__main__":  # worker processes re-import this file
    main()
