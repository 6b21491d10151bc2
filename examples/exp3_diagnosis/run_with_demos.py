"""Exp 3 with another demo file, and its frozen tests split by start height (docs/exp3.md):

    python run_with_demos.py shipped|DEMOS.csv OUT quick|full [field=JSON ...]
    python run_with_demos.py shipped runs/m full trials=2 episodes=1500 test_episodes=100
"""
import json
import sys
from pathlib import Path
import numpy as np
from latentrl.experiments import exp3
from latentrl.run_settings import with_overrides
from latentrl.experiments import run_experiment

demos, out, which = sys.argv[1], sys.argv[2], sys.argv[3]
if demos != "shipped":
    exp3.demos_path = lambda heel=False, p=Path(demos).resolve(): p
preset = exp3.Exp3Preset.quick() if which == "quick" else exp3.Exp3Preset()
over = {}
for kv in sys.argv[4:]:
    k, v = kv.split("=")
    over[k] = json.loads(v)
preset = with_overrides(preset, over)
run_experiment("exp3", preset, out, progress=False)
with np.load(Path(out) / "returns.npz") as npz:
    ends, reached = npz["latent_test_end"], npz["latent_test_reached"]
    hz = npz["latent_test_start_hands"][..., [2, 5]].max(-1)
    ok = (ends == 0) & reached
    floor = hz <= 0.10
    train_end = npz["latent_end"]
    last = train_end[:, -max(1, train_end.shape[1] // 12):]
    print(f"{out}: test success {ok.mean():.2f} ({ok.sum()}/{ok.size}); floor-level starts {floor.sum()} "
          f"success {ok[floor].mean() if floor.any() else float('nan'):.2f}; test ends {np.bincount(ends.ravel(), minlength=5)}; "
          f"last-1/12 training obstacle {np.mean(last == 1):.2f}, reached {npz['latent_reached'][:, -last.shape[1]:].mean():.2f}")
