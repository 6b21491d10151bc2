"""The figures docs/exp2.md gives for an Experiment 2 results directory (paper preset):

    python examples/exp2_summary.py runs/exp2-paper

mean return of the first and last 500 episodes (mean ± s.d. over trials, range), reach and pass
rates of the last 500, the first episode whose running reach rate (window 500) is ≥ 90 %,
endings over all and the last 500 episodes, RL steps, wall time and peak memory.
"""
import sys
from pathlib import Path

import numpy as np

from latentrl.experiments.run_folder import RunFolder
from latentrl.experiments.sweep import episodes_to_threshold
from latentrl.task import end_reasons

WINDOW = 500
out = Path(sys.argv[1])
folder = RunFolder(out)
meta, a = folder.results(), folder.arrays()
returns, ends, reached, passed = a["latent"], a["latent_end"], a["latent_reached"], a["latent_passed"]
done = ends[:, -1] >= 0
returns, ends, reached, passed = returns[done], ends[done], reached[done], passed[done]
first, last = returns[:, :WINDOW].mean(1), returns[:, -WINDOW:].mean(1)
print(f"{out}: {done.sum()} of {len(done)} trials; {int(a['latent_steps'][done].sum()):,} RL steps; wall "
      f"{meta['wall_time_s']:.0f} s; peak RSS {meta.get('peak_rss_mib', float('nan')):.0f} MiB")
for name, r in (("first", first), ("last", last)):
    print(f"mean return, {name} {WINDOW}: {r.mean():.1f} ± {r.std(ddof=1):.1f} ({r.min():.0f}-{r.max():.0f})")
late = reached[:, -WINDOW:].mean(1)
print(f"reached h*, last {WINDOW}: {100 * late.mean():.1f} % ({100 * late.min():.1f}-{100 * late.max():.1f} per trial)")
onset = episodes_to_threshold(reached.astype(float), 0.9, WINDOW)  # -1: never
print(f"first episode with running reach (window {WINDOW}) >= 90 %: {onset.tolist()} "
      f"(median {np.median(onset[onset >= 0]):.0f})")
p = passed[:, -WINDOW:].mean(1)
print(f"passed, last {WINDOW}: {100 * p.min():.1f}-{100 * p.max():.1f} % per trial")
names = end_reasons()
for label, e in (("all episodes", ends), (f"last {WINDOW}", ends[:, -WINDOW:])):
    print(f"endings, {label}:", {names[c]: f"{100 * (e == c).mean():.2f} %" for c in range(len(names)) if (e == c).any()})
print("drops per trial:", (ends == names.index("drop")).sum(1).tolist())
