"""The learner-step rule's quantities for zoo robots: at each candidate step (`derive.STEPS`, in
RBF spacings) how many steps the target region spans and how many moves 95 % of the admissible
starts need to reach it (`latentrl check`'s survey, GPLVM fitted as `latentrl train` fits), with
the fit's latent points and with them evenly spaced (`GPLVM(spacing="even")`).

    python examples/zoo/survey_steps.py panda_bins iiwa_tray
"""

from __future__ import annotations

import sys
from pathlib import Path

from latentrl import GPLVM, Task, load_demos
from latentrl.derive import STEPS, applied, moves95, region_span, servo_gains, survey_at_step
from latentrl.run_settings import TrainPreset, latent_box

HERE = Path(__file__).resolve().parent

for robot in sys.argv[1:] or sorted(p.parent.name for p in HERE.glob("*/task.toml")):
    task = Task.load(HERE / robot / "task.toml")
    demos = load_demos(HERE / robot / "demos.csv", expected_joints=task.joint_names).postures
    preset = TrainPreset()
    if not any(key.startswith("servo.") for key in task.given):
        task = applied(task, servo_gains(task, demos))
    for spacing in ("fit", "even"):  # the likelihood's latent points, then evenly spaced (GPLVM.spacing)
        model = GPLVM(n_components=2, random_state=0, max_iter=preset.gplvm_max_iter, encoder=preset.encoder,
                      spacing=spacing).fit(demos)
        low, high = latent_box(model.Z_, preset.latent_margin)
        for step in STEPS:
            survey = survey_at_step(task.replace({"learner.step": step}), model, low, high, demos)
            print(f"{robot:14s} {spacing:4s} step {step:<6g} region spans {region_span(survey):5.1f} steps; "
                  f"95 % of starts need {moves95(survey)} moves", flush=True)
