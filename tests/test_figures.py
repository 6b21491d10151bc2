"""What a run's figures say (helper-33's review): a training curve over trials the stopping rule
ended at different episodes, and a value map before learning, where V is w₀ everywhere."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from latentrl import GPLVM, Task  # noqa: E402
from latentrl.datasets import arm_postures  # noqa: E402
from latentrl.plots import latent_value_panel, learning_curves  # noqa: E402
from latentrl.run_settings import latent_box  # noqa: E402


def test_a_mean_over_trials_stops_where_the_first_trial_stopped():
    """Averaged over the trials still running, the curve jumped at each stop and its band
    narrowed (the snake's: 75.6 → 81.4 at episode 901, one trial alone from 1801)."""
    returns = np.array([[1.0, 2, 3, 4, 5, 6], [1, 2, 5, np.nan, np.nan, np.nan]])
    fig, ax = plt.subplots()
    learning_curves(ax, {"latent": returns})
    mean, *trials = ax.lines
    assert list(mean.get_xdata()) == [1, 2, 3] and list(mean.get_ydata()) == [1, 2, 4]
    assert [len(t.get_xdata()) for t in trials] == [6, 6]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == [
        "latent: mean ± s.d. of 2 trials", "latent: each trial, to where it stopped"]
    fig, ax = plt.subplots()
    learning_curves(ax, {"latent": returns[:, :3]})
    assert len(ax.lines) == 1, "every trial ran every episode: the mean alone"
    plt.close("all")


def test_a_value_map_before_learning_says_v_is_the_same_everywhere():
    """V = w₀ at every point was drawn as bands of rounding noise over a colour scale of
    1e-14; it is one colour now, labelled with its value and what V is."""
    model = GPLVM(max_iter=20, random_state=0).fit(arm_postures(40, np.random.default_rng(0)))
    low, high = latent_box(model.Z_, 0.1)
    learner = Task.shipped("two_arms").to_dict()["learner"]
    fig, ax = plt.subplots()
    latent_value_panel(ax, None, low, high, model, learner=learner, grid=20)
    assert [t.get_text() for t in ax.texts] == [f"V = {learner['initial_weight']:g} everywhere"]
    assert fig.axes[1].get_ylabel() == f"V: expected discounted return (γ = {learner['gamma']:g})"
    assert "demos (latent points)" in [t.get_text() for t in ax.get_legend().get_texts()]
    plt.close("all")
