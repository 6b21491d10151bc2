"""Issue #41's 22 stock URDFs of pybullet 3.2.7's pybullet_data through `latentrl urdf-info`, without
and with `--balance-inertia`, and 2 s of physics for each one that loads: docs/robots.md's table.

    pip download --no-deps -d /tmp/pb pybullet==3.2.7
    unzip -q /tmp/pb/pybullet-3.2.7-*.whl 'pybullet_data/*' -d /tmp
    python examples/stock_urdfs.py /tmp/pybullet_data

(pybullet_data is not committed, and nothing here installs pybullet.)
"""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from latentrl._native import Sim

STOCK = ["a1/a1", "aliengo/aliengo", "biped/biped2d_pybullet", "franka_panda/panda",
         "gripper/wsg50_one_motor_gripper_left_finger", "humanoid/humanoid", "husky/husky", "kuka_iiwa/model",
         "kuka_iiwa/model_free_base", "laikago/laikago", "laikago/laikago_toes_zup", "mini_cheetah/mini_cheetah",
         "cartpole", "pendulum5", "pr2_gripper", "r2d2", "quadruped/microtaur/microtaur", "quadruped/minitaur",
         "quadruped/spirit40", "racecar/racecar", "xarm/xarm6_robot", "xarm/xarm6_with_gripper"]


def urdf_info(path: Path, *flags: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "latentrl", "urdf-info", "--json", *flags, str(path)],
                          capture_output=True, text=True)


def repairs(warnings: list[str]) -> list[str]:
    """The warnings of one file, summarised by kind."""
    inertia = [w.split('"')[1] for w in warnings if w.startswith("link ")]
    spherical = [w for w in warnings if "spherical, loaded as" in w]
    optenv = [w for w in warnings if "$(optenv" in w]
    geometry = sorted({w.split(":")[0] for w in warnings if "inside <geometry>" in w})
    ranges = [w for w in warnings if "without <limit lower upper>" in w]
    out = []
    if inertia:
        out.append(f"inertia of {len(inertia)} link(s) balanced ({', '.join(inertia)})")
    if spherical:
        out.append(f"{len(spherical)} spherical joints as 3 continuous each")
    if optenv:
        out.append(f"{len(optenv)} `$(optenv …)` read as their defaults ({optenv[0].split(',')[0]})")
    if geometry:
        out.append(f"`<material>` inside `<geometry>` ignored ({', '.join(geometry)})")
    if ranges:
        out.append(f"{len(ranges)} revolute joints without a range as continuous")
    return out


def cell(path: Path, *flags: str) -> tuple[str, bool]:
    out = urdf_info(path, *flags)
    if out.returncode:
        message = out.stderr.strip().splitlines()[-1].removeprefix("latentrl: error: ")
        message = message.replace(f"malformed URDF ({path}): ", "")
        if len(message) > 160:
            message = message[:160] + " …"
        return "refused: `" + message.replace("`", "").replace("|", "\\|") + "`", False
    info = json.loads(out.stdout)
    actuated = sum(j["mimic"] is None for j in info["joints"])
    text = f"loads: {len(info['links'])} links, {actuated} actuated joints"
    return "; ".join([text, *repairs(info["warnings"])]), True


def steps_finitely(path: Path) -> bool:
    sim = Sim(path, balance_inertia=True)
    sim.step(480)  # 2 s, root fixed, servos holding the start
    return bool(np.isfinite(sim.joint_positions()).all())


def main(data: Path) -> None:
    print("| file | as written | with `--balance-inertia` | 2 s of physics |")
    print("|---|---|---|---|")
    loaded = 0
    for name in [*STOCK, "kuka_iiwa/kuka_with_gripper.sdf"]:
        path = data / (name if name.endswith(".sdf") else f"{name}.urdf")
        plain, _ = cell(path)
        balanced, ok = cell(path, "--balance-inertia")
        physics = ("finite" if steps_finitely(path) else "NaN") if ok else "–"
        loaded += ok and name in STOCK
        same = balanced if balanced != plain else "same"
        print(f"| `{path.relative_to(data)}` | {plain} | {same} | {physics} |")
    print(f"\n{loaded} of {len(STOCK)} URDFs load with --balance-inertia.")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
