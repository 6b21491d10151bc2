"""Issue #18's figures of an Exp 3 results directory (docs/exp3.md, Results):

    python summary.py runs/exp3-full

frozen-test success from uniform starts and from floor-level starts (both hands ≤ 0.10 m; a
test succeeds when it reached h* and ended by the step limit), test endings, obstacle endings
in the last 500 training episodes, return and reach rate early and late, and the style count of
the successful training episodes (`exp3.episode_styles`).
"""
import sys
from pathlib import Path

import numpy as np

from latentrl.saved_runs import saved_run
from latentrl.experiments import exp3
from latentrl.experiments.run_folder import RunFolder
from latentrl.task import end_reasons

out = Path(sys.argv[1])
folder = RunFolder(out)
meta = folder.results()
_, preset = saved_run(out)
arrays = folder.arrays()
done = arrays["latent_test_end"][:, -1] >= 0  # finished trials only (a run may be unfinished)
a = {k: v[done] for k, v in arrays.items() if v.ndim and v.shape[0] == len(done)}
ends, reached = a["latent_test_end"], a["latent_test_reached"]
ok = (ends == 0) & reached
floor = a["latent_test_start_hands"][..., [2, 5]].max(-1) <= exp3.FLOOR_LEVEL
names = end_reasons()
print(f"{out}: {ok.shape[0]} of {len(done)} trials finished, wall {meta['wall_time_s'] / 60:.1f} min")
print(f"frozen tests: {ok.sum()} of {ok.size} succeed ({100 * ok.mean():.1f} %); per trial "
      f"{np.round(100 * ok.mean(1), 1).tolist()} %")
print(f"floor-level starts: {floor.sum()}, succeed {ok[floor].sum()} ({100 * ok[floor].mean():.1f} %); per trial "
      f"{[f'{int(ok[t][floor[t]].sum())}/{int(floor[t].sum())}' for t in range(len(ok))]}")
print("test endings:", {names[c]: int((ends == c).sum()) for c in range(len(names)) if (ends == c).any()})
train_end, train_reached, returns = a["latent_end"], a["latent_reached"], a["latent"]
last = train_end[:, -500:]
print(f"obstacle endings, last 500 training episodes: {100 * (last == 1).mean():.1f} % (per trial "
      f"{np.round(100 * (last == 1).mean(1), 1).tolist()}); first 500: {100 * (train_end[:, :500] == 1).mean():.1f} %")
print(f"return, episodes 1-500 -> last 500: {returns[:, :500].mean():.1f} -> {returns[:, -500:].mean():.1f}; "
      f"reached h*: {100 * train_reached[:, :500].mean():.0f} -> {100 * train_reached[:, -500:].mean():.0f} %")
fitted = exp3.fit(preset, out)
style = exp3.episode_styles(a["latent_mean_state"], fitted.model.Z_)
good = (train_end == 0) & train_reached
for k, name in enumerate(exp3.STYLES):
    print(f"style {name}: {int((good & (style == k)).sum())} successful training episodes "
          f"(last 500: {int((good & (style == k))[:, -500:].sum())})")
