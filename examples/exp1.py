"""Experiment 1 (paper Fig. 4) on the paper's parameters: 25 trials × 5000 episodes × 500 steps.

    python examples/exp1.py [--quick] [--out results/exp1]
"""

import argparse
from pathlib import Path

from latentrl.experiments.exp1 import Exp1Preset
from latentrl.experiments import run_experiment


def main() -> None:
    """Runs the preset chosen on the command line and prints the result."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="the 5-second smoke-test preset")
    parser.add_argument("--out", type=Path, default=Path("results/exp1"))
    args = parser.parse_args()
    meta = run_experiment("exp1", Exp1Preset.quick() if args.quick else Exp1Preset(), args.out)
    for learner, trials in meta["trials"].items():
        last = [t["mean_return_last"] for t in trials.values()]
        reached = [t["reached_last"] for t in trials.values()]
        print(f"{learner}: mean return of the last 10 % of episodes {sum(last) / len(last):.1f}, "
              f"reached the target in {100 * sum(reached) / len(reached):.1f} % of them")
    print(f"figures and results in {args.out}")


if __name__ == "__main__":  # worker processes re-import this file
    main()
