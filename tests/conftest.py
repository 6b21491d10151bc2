"""Hypothesis profiles: `fast` (default) and `thorough`, picked by HYPOTHESIS_PROFILE; the quick
runs of an experiment's tests (`quick_run`, `control_run`), shared by its module's tests."""

import os

import pytest
from hypothesis import settings

settings.register_profile("fast", max_examples=20, deadline=None)
settings.register_profile("thorough", max_examples=500, deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "fast"))


def _experiment_run(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory, what: str, preset_of):
    """The test module's experiment (its `EXPERIMENT`) run from its quick preset as `preset_of`
    makes it, into a fresh folder: (folder, results metadata)."""
    from latentrl.experiments import experiments, run_experiment

    name = request.module.EXPERIMENT
    out = tmp_path_factory.mktemp(f"{name}_{what}")
    return out, run_experiment(name, preset_of(experiments()[name].preset.quick()), out, progress=False)


@pytest.fixture(scope="module")
def quick_run(request, tmp_path_factory):
    """The module's experiment run with its quick preset: (folder, results metadata)."""
    return _experiment_run(request, tmp_path_factory, "quick", lambda preset: preset)


@pytest.fixture(scope="module")
def control_run(request, tmp_path_factory):
    """The same run with the non-learning control (`learning.control`: α = 1e-12): its folder."""
    from learning import control

    return _experiment_run(request, tmp_path_factory, "control", control)[0]
