"""Measures the zoo: for every robot folder (or the ones named) runs `latentrl check`, `latentrl
train` (extra flags passed through, e.g. --quick) and `latentrl rollout --episodes 20`, one at a
time, and writes the numbers as JSON and a Markdown table (the README's table).

    python examples/zoo/measure.py --quick                      # all robots, quick training
    python examples/zoo/measure.py snake_planar --quick --out /tmp/zoo
    python examples/zoo/measure.py -- --episodes 500            # flags after -- go to train

Results: OUT/ROBOT/ (the run and its rollout), OUT/zoo.json, OUT/zoo.md.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROBOTS = ("snake_planar", "bimanual_box", "ur_reach", "panda_bins", "iiwa_tray", "biped_pick")


def robots() -> list[str]:
    """The zoo's robot folders (a task.toml and a demos.csv), the listed ones first."""
    found = {p.parent.name for p in HERE.glob("*/task.toml") if (p.parent / "demos.csv").exists()}
    return [r for r in ROBOTS if r in found] + sorted(found - set(ROBOTS))


def latentrl(*args: str) -> tuple[int, str, float]:
    """Runs `python -m latentrl ARGS`: (exit code, stdout, wall seconds)."""
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "latentrl", *args], capture_output=True, text=True)
    wall = time.perf_counter() - t
    if proc.returncode not in (0, 3):
        sys.stderr.write(proc.stdout + proc.stderr)
    return proc.returncode, proc.stdout, wall


def measure(robot: str, out: Path, train_flags: list[str], episodes: int) -> dict[str, Any]:
    task, demos = HERE / robot / "task.toml", HERE / robot / "demos.csv"
    row: dict[str, Any] = {"robot": robot, "demos": len(demos.read_text().splitlines()) - 1}
    from latentrl import Task

    row["joints"] = len(Task.load(task).joint_names)
    rc, stdout, wall = latentrl("check", str(task), "--demos", str(demos), "--json", "--no-progress")
    report = json.loads(stdout) if rc in (0, 3) else {"verdict": f"error (exit {rc})", "findings": []}
    row["check"] = {"exit": rc, "seconds": round(wall, 2), "verdict": report["verdict"],
                    "findings": {f["name"]: f["verdict"] for f in report["findings"]}}
    run = out / robot
    rc, _, wall = latentrl("train", str(task), "--demos", str(demos), "--out", str(run), "--no-progress",
                           *train_flags)
    row["train"] = {"exit": rc, "seconds": round(wall, 1), "flags": train_flags}
    if rc != 0:
        return row
    rc, _, wall = latentrl("rollout", str(run), "--out", str(run / "rollout"), "--episodes", str(episodes),
                           "--no-progress")
    row["rollout_seconds"] = round(wall, 1)
    if rc == 0:
        result = json.loads((run / "rollout" / "rollout.json").read_text())
        row["rollout"] = {k: {"success": result[k]["success"], "reached_any_step": result[k]["reached_any_step"],
                              "mean_return": result[k]["mean_return"], "ends": result[k]["ends"]}
                          for k in ("greedy", "softmax", "random")}
    return row


def pct(x: Any) -> str:
    return "–" if x is None else f"{100 * x:.0f} %"


def markdown(rows: list[dict[str, Any]]) -> str:
    lines = ["| robot | joints | demos | check (exit) | findings not ok | train s | reached: greedy / softmax / random "
             "| mean return: greedy / softmax / random |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        c = r["check"]
        odd = ", ".join(f"{k}: {v}" for k, v in c["findings"].items() if v != "ok") or "none"
        ro = r.get("rollout")
        reached = " / ".join(pct(ro[k]["reached_any_step"]) for k in ("greedy", "softmax", "random")) if ro else "–"
        ret = " / ".join(f"{ro[k]['mean_return']:.1f}" for k in ("greedy", "softmax", "random")) if ro else "–"
        lines.append(f"| {r['robot']} | {r['joints']} | {r['demos']} | {c['verdict']} ({c['exit']}) | {odd} "
                     f"| {r['train']['seconds']} | {reached} | {ret} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    argv = sys.argv[1:]
    passthrough: list[str] = []
    if "--" in argv:
        i = argv.index("--")
        argv, passthrough = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("robots", nargs="*", help="robot folders (default: all)")
    ap.add_argument("--out", type=Path, default=Path("/tmp/zoo"), help="where runs and tables go")
    ap.add_argument("--quick", action="store_true", help="pass --quick to train")
    ap.add_argument("--episodes", type=int, default=20, help="rollout episodes per trial")
    args = ap.parse_args(argv)
    names = args.robots or robots()
    flags = (["--quick"] if args.quick else []) + passthrough
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in names:
        row = measure(name, args.out, flags, args.episodes)
        rows.append(row)
        print(json.dumps(row), flush=True)
    (args.out / "zoo.json").write_text(json.dumps(rows, indent=1) + "\n")
    table = markdown(rows)
    (args.out / "zoo.md").write_text(table)
    print(table)


if __name__ == "__main__":
    main()
