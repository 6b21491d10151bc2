"""One table of our costs against the peers' (issue #20), read from the JSON the benches wrote in
benches/results/ (no timing here): rapier against MuJoCo per physics step (bench_sim.py) and
at equal accuracy (bench_accuracy.py), our GPLVM against GPy (bench_gp.py). `make bench` prints
it last; each row names its source, the goal where an issue set one and whether it is met.

    python benches/ratio_table.py [RESULTS_DIR]
"""

import json
import sys
from pathlib import Path

#: Goals of issue #20: CPU time per simulated second at the tolerance, ours / MuJoCo's (none set
#: for the tutorial's glass arm).
GOALS = {"arms": 1.5, "humanoid": 2.0, "glass_arm": None}


def load(results: Path, name: str) -> dict | None:
    path = results / f"{name}.json"
    return json.loads(path.read_text()) if path.exists() else None


def rows(results: Path) -> list[tuple[str, str, str, str]]:
    """(what, ours, peer's, ratio and goal) per line of the table."""
    out = []
    sim = load(results, "bench_sim")
    if sim is not None:
        for plant, ours in (("arms", "rapier_it2"), ("humanoid", "rapier_it1_pgs4")):
            case = sim["cases"][plant]["rows"]
            for peer in ("mujoco_implicitfast", "mujoco_discrete"):
                a, b = case[ours]["us_per_step"], case[peer]["us_per_step"]
                out.append((f"{plant}: physics step at dt 1/240 (bench_sim)", f"{a:.1f} µs ({ours})",
                            f"{b:.1f} µs ({peer})", f"{a / b:.2f}×"))
    accuracy = load(results, "bench_accuracy")
    if accuracy is not None:
        for plant, goal in GOALS.items():
            case = accuracy["cases"].get(plant)
            if case is None:
                continue
            if case["tolerance_m"] is None:
                out.append((f"{plant} (bench_accuracy)", "its task file declares no physics.tolerance", "–", "–"))
                continue
            # the tolerance the plant's task file declares, as bench_accuracy names it ("1 mm")
            tolerance = f"{1e3 * case['tolerance_m']:g} mm"
            what = f"{plant}: CPU per simulated s within {tolerance} (bench_accuracy)"
            best = case["cheapest_within"].get(tolerance, {})
            ours, peer = best.get("rapier_own"), best.get("mujoco_own")
            if ours is None or peer is None:
                out.append((what, "none within" if ours is None else ours["setting"],
                            "none within" if peer is None else peer["setting"],
                            "–" if goal is None else f"– (goal ≤ {goal}×)"))
                continue
            ratio = ours["ms_per_simulated_s"] / peer["ms_per_simulated_s"]
            verdict = "" if goal is None else f" (goal ≤ {goal}×: {'met' if ratio <= goal else 'missed'})"
            out.append((what, f"{ours['ms_per_simulated_s']:.2f} ms ({ours['setting']})",
                        f"{peer['ms_per_simulated_s']:.2f} ms ({peer['setting']})", f"{ratio:.2f}×{verdict}"))
    gp = load(results, "bench_gp")
    if gp is not None:
        for case, values in gp["cases"].items():
            r = values["ratios"]
            for what, key in (("GPLVM fit", "fit_gpy_over_latentrl_GPLVM"),
                              ("one-point decode, mean + variance", "decode_one_gpy_over_inverse_transform_variance")):
                out.append((f"{case}: {what} (bench_gp)", "latentrl", "GPy", f"{1 / r[key]:.3f}× ({r[key]:.1f}× faster)"))
    return out


def main() -> None:
    results = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "results"
    table = rows(results)
    if not table:
        sys.exit(f"ratio_table: no bench results in {results} (run `make bench`)")
    print("| what | ours | peer | ours / peer |\n|---|---|---|---|")
    for line in table:
        print("| " + " | ".join(line) + " |")


if __name__ == "__main__":
    main()
