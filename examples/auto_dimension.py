"""What `GPLVM(n_components="auto")` picks (docs/encoders.md): on synthetic manifolds of known
dimension d = 1, 2, 3 (uniform points through a random tanh network into 8 joints, noise 0.01;
seeds 4–11, not those the threshold was looked at with, 0–3) and on the shipped demo sets.

    python examples/auto_dimension.py
"""
import numpy as np

from latentrl import GPLVM
from latentrl.datasets import arm_postures
from latentrl.demos import load_demos
from latentrl.experiments.exp3 import demos_path


def manifold(d, n, joints, seed):
    rng = np.random.default_rng(seed)
    t = rng.uniform(-1, 1, (n, d))
    hidden = rng.standard_normal((d, 12))
    out = rng.standard_normal((12, joints)) / np.sqrt(12)
    return np.tanh(1.5 * t @ hidden) @ out + 0.01 * rng.standard_normal((n, joints))


hits = 0
for d in (1, 2, 3):
    for seed in range(4, 12):
        model = GPLVM(n_components="auto", max_components=4, random_state=0).fit(manifold(d, 80, 8, seed))
        hits += model.n_components_ == d
        print(f"d = {d}, seed {seed}: picks {model.n_components_}, relative relevances "
              f"{np.round(model.relevance_ / model.relevance_[0], 3).tolist()}")
print(f"picked the generating d in {hits} of 24")
for name, X, k in (("arms (Exp 2, 123 postures, 4 joints)", arm_postures(123, np.random.default_rng(0)), 3),
                   ("humanoid lift (the paper's 7 demos, 19 joints)", load_demos(demos_path()).postures, 5)):
    model = GPLVM(n_components="auto", max_components=k, random_state=0).fit(X)
    print(f"{name}: picks {model.n_components_} (paper: 2), relative relevances "
          f"{np.round(model.relevance_ / model.relevance_[0], 3).tolist()}")
