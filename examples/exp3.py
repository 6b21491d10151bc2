"""Experiment 3 (paper Fig. 7b–e, 8) on the paper's scale: the simulated humanoid lifts an object,
4 trials × 6000 episodes × ≤ 200 steps (≤ 4.8 M physics-simulated RL steps: ≈ 1 h on 2 cores, docs/exp3.md).

    python examples/exp3.py [--quick] [--out results/exp3]
"""

import argparse
from pathlib import Path

from latentrl.experiments.exp3 import Exp3Preset
from latentrl.experiments import run_experiment


def main() -> None:
    """Runs the preset chosen on the command line and prints the result."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="the ~1-minute smoke-test preset")
    parser.add_argument("--out", type=Path, default=Path("results/exp3"))
    args = parser.parse_args()
    meta = run_experiment("exp3", Exp3Preset.quick() if args.quick else Exp3Preset(), args.out)
    trials = list(meta["trials"]["latent"].values())
    last = [t["mean_return_last"] for t in trials]
    print(f"mean return of the last 10 % of episodes {sum(last) / len(last):.1f}")
    ends = {k: sum(t["ends"][k] for t in trials) for k in ("timeout", "obstacle", "box_exit", "drop", "fall")}
    print(f"episode endings over all trials: {ends}")
    print(f"figures and results in {args.out}")


if __name__ == "__main__":  # worker processes re-import this file
    main()
