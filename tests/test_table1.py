"""Table I runner on tiny presets: the expected shape of the result and the files it writes."""

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from latentrl.experiments.table1 import PAPER, Table1Preset, run_table1

TINY = Table1Preset(trials=2, n_test=200, n_latent_samples=500, variant_margins=(0.0,), workers=1)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("table1")
    return run_table1(TINY, out, progress=False), out


def test_joint_space_gplvm_beats_pca(tiny_run):
    result, _ = tiny_run
    main = result["summary"]["main"]
    margin, test = "0.25", "distance"
    joint = main["joint"]
    assert (
        joint["GPLVM"]["constraint"][margin][test]["mean"]
        > joint["PCA"]["constraint"][margin][test]["mean"] + 30
    )
    assert joint["PCA"]["constraint"][margin][test]["mean"] < 15
    assert joint["GPLVM"]["recon"]["mean"] < 0.5 * joint["PCA"]["recon"]["mean"]
    assert joint["GPLVM"]["recon_joint"]["mean"] < joint["PCA"]["recon_joint"]["mean"]
    for trial in result["trials"]:  # the ordering holds in every trial, not just on average
        t = trial["fits"]["main"]["joint"]
        assert t["GPLVM"]["constraint"][margin][test] > t["PCA"]["constraint"][margin][test]
        assert t["GPLVM"]["recon"] < t["PCA"]["recon"]


def test_end_effector_pca_is_nearly_exact(tiny_run):
    result, _ = tiny_run
    ee = result["summary"]["main"]["end_effector"]
    assert ee["PCA"]["recon"]["mean"] < 0.2  # ×10²: under 2 mm with 3 mm demo noise
    assert ee["PCA"]["constraint"]["0.25"]["distance"]["mean"] > 95
    exact = result["summary"]["exact_demos"]["end_effector"]
    assert exact["PCA"]["recon"]["mean"] < 1e-9  # exact linear data: exact reconstruction
    assert exact["PCA"]["constraint"]["0.25"]["vector"]["mean"] == 100.0


def test_files_exist_and_parse(tiny_run):
    _, out = tiny_run
    payload = json.loads((Path(out) / "table1.json").read_text())
    assert payload["preset"]["trials"] == 2 and payload["preset"]["name"] == "Table1Preset"
    assert len(payload["trials"]) == 2
    assert payload["paper"]["joint"]["GPLVM"]["constraint"] == list(
        PAPER["joint"]["GPLVM"]["constraint"]
    )
    assert set(payload["summary"]) == {
        "main",
        "exact_demos",
        "noise_floor",
        "exact_demos_noise_floor",
    }
    assert payload["environment"]["versions"]["numpy"]
    assert {row["margin"] for row in payload["variants"]["constraint"]} == {"0 %", "25 %"}
    for trial in payload["trials"]:
        fit = trial["fits"]["main"]["joint"]["GPLVM"]["fit"]
        assert fit["n_iter"] >= 1 and len(fit["theta"]) == 3
    md = (Path(out) / "table1.md").read_text()
    assert md.startswith("# Table I") and "61.03 ± 6.16" in md and "What moves the numbers" in md
    assert not list(Path(out).glob("*.tmp"))


def test_workers_do_not_change_results():
    preset = dataclasses.replace(
        TINY, n_test=50, n_latent_samples=100, variants=False, gplvm_max_iter=200
    )
    serial = run_table1(preset, progress=False)
    parallel = run_table1(dataclasses.replace(preset, workers=2), progress=False)

    def strip(trials):
        for t in trials:
            t.pop("seconds")
            for spaces in t["fits"].values():
                for methods in spaces.values():
                    methods["GPLVM"]["fit"].pop("seconds")
        return trials

    assert parallel["workers"] == 2
    assert strip(serial["trials"]) == strip(parallel["trials"])


@pytest.mark.parametrize(
    ("field", "value", "message"),
    [
        ("trials", 0, "trials"),
        ("constraint_test", "angle", "constraint_test"),
        ("latent_margin", -0.1, "latent_margin"),
        ("tolerance", 0.0, "tolerance"),
        ("encoder", "nearest", "run: encoder: unknown variant `nearest`, expected one of `gp`, `projection`"),
        ("variant_margins", (0.0, float("nan")), r"variant_margins\[1\]"),
    ],
)
def test_bad_preset(field, value, message):
    with pytest.raises(ValueError, match=message):
        run_table1(dataclasses.replace(TINY, **{field: value}), progress=False)


def test_the_back_constrained_encoder_takes_no_latent_prior():
    with pytest.raises(ValueError, match="encoder: 'back_constrained' takes no gplvm_latent_prior"):
        dataclasses.replace(TINY, encoder="back_constrained", gplvm_latent_prior=True).validate()


def test_example_script_runs(tmp_path):
    script = Path(__file__).resolve().parents[1] / "examples" / "table1.py"
    done = subprocess.run(
        [sys.executable, str(script), "--quick", "--trials", "1", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        check=True,
    )
    assert "Table I" in done.stdout and (tmp_path / "table1.json").exists()


def test_the_encoder_is_a_flag_of_table1(tiny_run):
    """`encoder="back_constrained"` fits Z = g(X) and reconstructs through it: finite errors,
    not the gp encoder's; recorded in the preset."""
    gp, _ = tiny_run
    tiny = dataclasses.replace(TINY, trials=1, variants=False, encoder="back_constrained")
    bc = run_table1(tiny, progress=False)
    joint = bc["trials"][0]["fits"]["main"]["joint"]["GPLVM"]
    assert np.isfinite(joint["recon"]) and joint["recon"] != gp["trials"][0]["fits"]["main"]["joint"]["GPLVM"]["recon"]
    assert bc["preset"]["encoder"] == "back_constrained"
