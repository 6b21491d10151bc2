"""Exp 3 in a latent space of D dimensions (issue #18's candidate "a 3-D latent space"):

    python latent_dim.py D [trials] [episodes] [test_episodes]

fits the back-constrained GPLVM with D components to the shipped lift demos (as `exp3.fit` does
with 2), trains the full preset's learner in it on the same seeds (`train_latent_policy`, seed
0; D = 3 gives 20³ RBFs and 18 actions: axes and diagonals of each pair) and prints the frozen
tests' success (reached h*, ended by the step limit) and endings, and the obstacle endings and
reach rate of the last twelfth of training.
"""
import sys

from latentrl import GPLVM, train_latent_policy
from latentrl.envs import shipped_demos
from latentrl.experiments.exp3 import Exp3Preset
from latentrl.task import end_reasons

d = int(sys.argv[1])
given = [int(a) for a in sys.argv[2:5]]
trials, episodes, tests = given + [2, 1500, 100][len(given):]
preset = Exp3Preset()
model = GPLVM(n_components=d, max_iter=preset.gplvm_max_iter, random_state=preset.seed,
              encoder=preset.encoder).fit(shipped_demos("humanoid_lift"))
policy = train_latent_policy(model, "humanoid_lift", preset="paper", trials=trials, episodes=episodes,
                             test_episodes=tests)
ends, reached = policy.test_ends, policy.test_reached
late = policy.ends[:, -max(1, episodes // 12):]
names = end_reasons()
print(f"d = {d} (GPLVM nll {model.nll_:.3f}), {trials} trials × {episodes} episodes, {tests} tests each:")
print(f"  frozen test success {int(((ends == 0) & reached).sum())} of {ends.size}; endings",
      {names[c]: int((ends == c).sum()) for c in range(len(names)) if (ends == c).any()})
print(f"  last {late.shape[1]} training episodes: obstacle {100 * (late == 1).mean():.1f} %, reached h* "
      f"{100 * policy.reached[:, -late.shape[1]:].mean():.1f} %")
