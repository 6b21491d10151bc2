"""Reproduce the paper's Table I (PCA vs GPLVM: reconstruction error and constraint share, in
end-effector and joint space) with the default preset, print it beside the paper's numbers and
write results/table1/{table1.json,table1.md}.

    python examples/table1.py [--trials N] [--out DIR] [--quick]
"""

import argparse
import dataclasses

from latentrl.experiments.table1 import Table1Preset, run_table1


def main() -> None:
    """Runs the preset chosen on the command line and prints the result."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=None, help="trials (paper and default: 20)")
    parser.add_argument("--out", default="results/table1", help="results directory")
    parser.add_argument(
        "--quick", action="store_true", help="small test and latent samples, no variants"
    )
    args = parser.parse_args()

    preset = Table1Preset.quick() if args.quick else Table1Preset()
    if args.trials is not None:
        preset = dataclasses.replace(preset, trials=args.trials)
    result = run_table1(preset, out_dir=args.out)  # prints the table
    print(f"wrote {args.out}/table1.json and table1.md in {result['wall_time_s']:.1f} s")


if __name__ == "__main__":  # worker processes re-import this file
    main()
