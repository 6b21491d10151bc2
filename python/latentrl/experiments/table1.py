"""Table I of the paper (Sec. IV-A/B, Fig. 5): how well PCA and a GPLVM (d = 2) represent the
bimanual constraint, in end-effector space (hand positions, 4.1) and in joint space (two
planar 2-link arms, 4.2).

Per trial and for each space and method:

- **reconstruction**: encode then decode `n_test` fresh constraint-satisfying postures; the
  RMSE (×10²) over all coordinates. In joint space the table's figure is the error of the
  reconstructed *hand positions* (forward kinematics of the decoded posture, metres), as the
  paper's caption reads; the joint-angle error (radians) is reported beside it.
- **constraint**: sample the latent space uniformly over the bounding box of the fitted
  latent points widened by `latent_margin` of its width per side, decode, and count the
  samples whose hands keep the grip within `tolerance` (Fig. 5).

Run it with `run_table1(Table1Preset())` or `latentrl run table1 --out DIR`.
"""

from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import multiprocessing
import os
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np

from latentrl._persistence import atomic_write
from latentrl._native import arms_fk
from latentrl.datasets import arm_postures, bimanual_pairs, grip_error
from latentrl.experiments.presets import describe
from latentrl.run_settings import check_floats, check_ints, check_run_fields
from latentrl.results import environment, write_json
from latentrl.machine import worker_threads
from latentrl.task import run_default

SPACES = ("end_effector", "joint")
METHODS = ("PCA", "GPLVM")
CONSTRAINT_TESTS: tuple[Literal["distance"], Literal["vector"]] = ("distance", "vector")

PAPER: dict[str, dict[str, dict[str, tuple[float, float]]]] = {
    "end_effector": {
        "PCA": {"recon": (0.05, 0.01), "constraint": (100.00, 0.00)},
        "GPLVM": {"recon": (0.24, 0.18), "constraint": (94.50, 5.61)},
    },
    "joint": {
        "PCA": {"recon": (3.25, 0.41), "constraint": (4.92, 0.81)},
        "GPLVM": {"recon": (0.80, 0.70), "constraint": (61.03, 6.16)},
    },
}
"""The paper's Table I: mean and s.d. over 20 trials (reconstruction RMSE ×10², constraint %)."""


@dataclass(frozen=True)
class Table1Preset:
    """Table I: PCA vs GPLVM (d = 2) reconstruction error and constraint share, both spaces."""

    trials: int = 20
    """Independent trials, each with fresh demonstrations and test postures (paper: 20)."""
    seed: int = run_default("seed")
    """Base seed; trial t draws from numpy's SeedSequence([seed, t])."""
    n_demos_ee: int = 50
    """Demonstrated hand pairs in end-effector space (ours: the paper's count is illegible)."""
    n_demos_joint: int = 123
    """Demonstrated joint-space postures (paper: 123)."""
    n_test: int = 1000
    """Fresh constraint-satisfying postures for the reconstruction error (paper: 1000)."""
    n_latent_samples: int = 2000
    """Uniform latent samples for the constraint share (ours: the paper does not say)."""
    tolerance: float = 0.005
    """A decoded posture keeps the grip if its grip error is ≤ this, metres (paper: 0.005)."""
    constraint_test: str = "distance"
    """'distance': |‖h_R − h_L‖ − 0.1| (paper, Fig. 5); 'vector': ‖h_R − h_L − (0.1, 0)‖."""
    latent_margin: float = 0.25
    """Latent box: bounding box of the fitted latent points ± this share of its width per side."""
    ee_noise: float = 0.003
    """S.d. of noise on each demonstrated hand coordinate, metres (ours: 'slightly noisy')."""
    joint_noise: float = 0.005
    """S.d. of noise on each demonstrated joint angle, radians (ours: 'slightly noisy')."""
    n_components: int = 2
    """Latent dimension d of PCA and the GPLVM (paper: 2)."""
    gplvm_max_iter: int = run_default("gplvm_max_iter")
    """L-BFGS-B iteration cap of the GPLVM fit."""
    gplvm_noise_floor: float = 1e-6
    """Lower bound on the GPLVM's white-noise variance θ3."""
    gplvm_latent_prior: bool = False
    """Unit-Gaussian prior on the GPLVM latent points (Lawrence's toolbox); off as in Eq. 1."""
    encoder: str = run_default("encoder")
    """GPLVM encoder of the reconstruction: "gp" (out-of-sample GP, paper), "projection" or
    "back_constrained" (the GPLVM fitted with Z = g(X)); docs/encoders.md."""
    variants: bool = True
    """Also run the variants that move the numbers (docs/method.md §Table I): margin, test, demos,
    θ3 floor."""
    variant_margins: tuple[float, ...] = (0.0, 0.1, 0.25)
    """Latent margins evaluated for the variants table (same fits, no extra cost)."""
    variant_noise_floor: float = 1e-4
    """θ3 floor of the noise-floor variant fits."""
    workers: int = 0
    """Worker processes over trials; 0 = one per rayon thread (RAYON_NUM_THREADS, else one per
    CPU; at most `trials`), 1 = in this process. The results do not depend on it."""

    @classmethod
    def quick(cls) -> Table1Preset:
        """The smoke-test preset: 2 trials, small test and latent samples, no variants."""
        return dataclasses.replace(
            cls(), trials=2, n_test=200, n_latent_samples=500, variants=False
        )

    def validate(self) -> None:
        """ValueError naming the first field with an impossible value."""
        check_run_fields(self, ("trials", "seed", "gplvm_max_iter", "encoder", "latent_margin"))
        check_ints(self, ("n_demos_ee", "n_demos_joint", "n_test", "n_latent_samples"))
        if not isinstance(self.n_components, int) or not 1 <= self.n_components < 4:
            raise ValueError(
                f"n_components must be 1, 2 or 3 (the data is 4-D), got {self.n_components!r}"
            )
        check_floats(self, ("tolerance", "gplvm_noise_floor", "variant_noise_floor"), positive=True)
        check_floats(self, ("ee_noise", "joint_noise"), positive=False)
        for i, margin in enumerate(self.variant_margins):
            if not (np.isfinite(margin) and margin >= 0):
                raise ValueError(f"variant_margins[{i}] must be a finite number >= 0, got {margin!r}")
        if self.constraint_test not in CONSTRAINT_TESTS:
            raise ValueError(
                f"constraint_test must be one of {CONSTRAINT_TESTS}, got {self.constraint_test!r}"
            )
        if self.encoder == "back_constrained" and self.gplvm_latent_prior:
            raise ValueError("encoder: 'back_constrained' takes no gplvm_latent_prior (Z = g(X) has no prior)")
        check_ints(self, ("workers",), minimum=0)

    def margins(self) -> tuple[float, ...]:
        """Every latent margin evaluated: the table's and, with `variants`, the variants'."""
        extra = self.variant_margins if self.variants else ()
        return tuple(sorted({float(self.latent_margin), *map(float, extra)}))

    def fit_configs(self) -> dict[str, dict[str, float]]:
        """The demonstration/fit settings of each fit: 'main' and, with `variants`, the others."""
        main = {
            "ee_noise": self.ee_noise,
            "joint_noise": self.joint_noise,
            "noise_floor": self.gplvm_noise_floor,
        }
        configs = {"main": main}
        if self.variants:
            exact = {**main, "ee_noise": 0.0, "joint_noise": 0.0}
            configs["exact_demos"] = exact
            configs["noise_floor"] = {**main, "noise_floor": self.variant_noise_floor}
            configs["exact_demos_noise_floor"] = {**exact, "noise_floor": self.variant_noise_floor}
        return configs


# ---------------------------------------------------------------------------------------------
# One trial


def _margin_key(margin: float) -> str:
    return f"{margin:g}"


def _evaluate(
    model: Any,
    latent: np.ndarray,
    test: np.ndarray,
    unit: np.ndarray,
    joint: bool,
    preset: Table1Preset,
) -> dict[str, Any]:
    """Reconstruction error and constraint shares of one fitted model (PCA or GPLVM)."""
    recon = model.inverse_transform(model._encode(test))
    hands_true = arms_fk(test) if joint else test
    hands_recon = arms_fk(recon) if joint else recon
    out: dict[str, Any] = {
        "recon": 100.0 * float(np.sqrt(np.mean((hands_recon - hands_true) ** 2))),
        "recon_joint": 100.0 * float(np.sqrt(np.mean((recon - test) ** 2))) if joint else None,
        "constraint": {},
    }
    low, high = latent.min(axis=0), latent.max(axis=0)
    width = high - low
    for margin in preset.margins():
        samples = (low - margin * width) + unit * (width * (1 + 2 * margin))
        decoded = model.inverse_transform(samples)
        hands = arms_fk(decoded) if joint else decoded
        out["constraint"][_margin_key(margin)] = {
            test_name: 100.0 * float(np.mean(grip_error(hands, test=test_name) <= preset.tolerance))
            for test_name in CONSTRAINT_TESTS
        }
    return out


def run_trial(preset: Table1Preset, trial: int) -> dict[str, Any]:
    """Every fit, space and method of trial `trial`; deterministic given (seed, trial)."""
    from latentrl.gplvm import GPLVM
    from latentrl.pca import PCA

    started = time.perf_counter()
    seeds = np.random.SeedSequence([preset.seed, trial]).spawn(6)
    demo_seed = {"end_effector": seeds[0], "joint": seeds[1]}
    test = {
        "end_effector": bimanual_pairs(preset.n_test, np.random.default_rng(seeds[2])),
        "joint": arm_postures(preset.n_test, np.random.default_rng(seeds[3])),
    }
    unit = np.random.default_rng(seeds[4]).uniform(
        size=(preset.n_latent_samples, preset.n_components)
    )
    gplvm_seed = int(seeds[5].generate_state(1)[0])

    fits: dict[str, Any] = {}
    for label, config in preset.fit_configs().items():
        fits[label] = {}
        for space in SPACES:
            joint = space == "joint"
            # Same seed for every fit config: exact and noisy demos share their hand positions.
            rng = np.random.default_rng(demo_seed[space])
            if joint:
                demos = arm_postures(preset.n_demos_joint, rng, noise=config["joint_noise"])
            else:
                demos = bimanual_pairs(preset.n_demos_ee, rng, noise=config["ee_noise"])
            pca = PCA(preset.n_components).fit(demos)
            t0 = time.perf_counter()
            gplvm = GPLVM(
                preset.n_components,
                max_iter=preset.gplvm_max_iter,
                noise_floor=config["noise_floor"],
                latent_prior=preset.gplvm_latent_prior,
                random_state=gplvm_seed,
                encoder=preset.encoder,
            ).fit(demos)
            fit_seconds = time.perf_counter() - t0
            fits[label][space] = {
                "PCA": _evaluate(pca, pca._encode(demos), test[space], unit, joint, preset),
                "GPLVM": {
                    **_evaluate(gplvm, gplvm.Z_, test[space], unit, joint, preset),
                    "fit": {
                        "nll": float(gplvm.nll_),
                        "n_iter": int(gplvm.n_iter_),
                        "converged": bool(gplvm.converged_),
                        "theta": [float(t) for t in gplvm.theta_],
                        "jitter": float(getattr(gplvm, "jitter_", 0.0)),
                        "seconds": fit_seconds,
                    },
                },
            }
    return {"trial": trial, "seconds": time.perf_counter() - started, "fits": fits}


# ---------------------------------------------------------------------------------------------
# Summary and reports


def _mean_sd(values: list[float]) -> dict[str, float]:
    array = np.asarray(values, dtype=float)
    return {"mean": float(array.mean()), "sd": float(array.std(ddof=1)) if len(array) > 1 else 0.0}


def summarise(preset: Table1Preset, trials: list[dict[str, Any]]) -> dict[str, Any]:
    """Mean ± s.d. over trials of every recorded figure, keyed like the per-trial values."""
    summary: dict[str, Any] = {}
    for label in preset.fit_configs():
        summary[label] = {}
        for space in SPACES:
            summary[label][space] = {}
            for method in METHODS:
                rows = [t["fits"][label][space][method] for t in trials]
                entry: dict[str, Any] = {"recon": _mean_sd([r["recon"] for r in rows])}
                if space == "joint":
                    entry["recon_joint"] = _mean_sd([r["recon_joint"] for r in rows])
                entry["constraint"] = {
                    m: {k: _mean_sd([r["constraint"][m][k] for r in rows]) for k in CONSTRAINT_TESTS}
                    for m in rows[0]["constraint"]
                }
                if method == "GPLVM":
                    entry["converged_share"] = float(np.mean([r["fit"]["converged"] for r in rows]))
                    entry["n_iter"] = _mean_sd([r["fit"]["n_iter"] for r in rows])
                    entry["fit_seconds"] = _mean_sd([r["fit"]["seconds"] for r in rows])
                summary[label][space][method] = entry
    return summary


def _pm(stat: dict[str, float], digits: int = 2) -> str:
    return f"{stat['mean']:.{digits}f} ± {stat['sd']:.{digits}f}"


def _paper(values: tuple[float, float]) -> str:
    return f"{values[0]:.2f} ± {values[1]:.2f}"


SPACE_NAMES = {"end_effector": "end-effector", "joint": "joint space"}


def format_table(result: dict[str, Any]) -> str:
    """Markdown: Table I ours beside the paper's, the values used, and the variants tables."""
    preset = result["preset"]
    main = result["summary"]["main"]
    margin, test = _margin_key(preset["latent_margin"]), preset["constraint_test"]
    lines: list[str] = [
        f"## Table I — ours (mean ± s.d. over {preset['trials']} trials) beside the paper's (20 trials)",
        "",
        "| space | method | recon. RMSE ×10² | paper | joint RMSE ×10² (rad) | constraint % | paper |",
        "|---|---|---|---|---|---|---|",
    ]
    for space in SPACES:
        for method in METHODS:
            entry = main[space][method]
            joint = _pm(entry["recon_joint"]) if "recon_joint" in entry else "–"
            paper = PAPER[space][method]
            cells = [
                SPACE_NAMES[space],
                method,
                _pm(entry["recon"]),
                _paper(paper["recon"]),
                joint,
                _pm(entry["constraint"][margin][test]),
                _paper(paper["constraint"]),
            ]
            lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        " ".join(
            [
                f"Values used: demos {preset['n_demos_ee']} (end-effector) /",
                f"{preset['n_demos_joint']} (joint); demo noise {preset['ee_noise']} m /",
                f"{preset['joint_noise']} rad; test postures {preset['n_test']};",
                f"latent samples {preset['n_latent_samples']} uniform over the latent bounding box",
                f"± {100 * preset['latent_margin']:g} % per side; constraint test '{test}'",
                f"within {preset['tolerance']} m; GPLVM d = {preset['n_components']},",
                f"θ3 ≥ {preset['gplvm_noise_floor']:g}, L-BFGS-B ≤ {preset['gplvm_max_iter']} iterations,",
                f"encoder '{preset.get('encoder', preset.get('encode_method'))}'.",
                "Joint-space reconstruction: hand positions via FK, metres.",
            ]
        ),
        "",
        "GPLVM fits (main): "
        + "; ".join(
            f"{SPACE_NAMES[s]} converged {100 * main[s]['GPLVM']['converged_share']:.0f} %, "
            f"{main[s]['GPLVM']['n_iter']['mean']:.0f} iterations, "
            f"{main[s]['GPLVM']['fit_seconds']['mean']:.2f} s"
            for s in SPACES
        ),
    ]
    if result.get("variants"):
        lines += ["", "### What moves the numbers (constraint %, mean ± s.d.)", ""]
        lines += [
            "| demos / fit | margin | test | ee PCA | ee GPLVM | joint PCA | joint GPLVM |",
            "|---|---|---|---|---|---|---|",
        ]
        for row in result["variants"]["constraint"]:
            row_cells = " | ".join(_pm(row[f"{s}/{m}"], 1) for s in SPACES for m in METHODS)
            lines.append(f"| {row['fit']} | {row['margin']} | {row['test']} | {row_cells} |")
        lines += [
            "",
            "### Reconstruction RMSE ×10² by demos / fit (joint space: hands, metres)",
            "",
        ]
        lines += [
            "| demos / fit | ee PCA | ee GPLVM | joint PCA | joint GPLVM | joint GPLVM (rad) |",
            "|---|---|---|---|---|---|",
        ]
        for row in result["variants"]["recon"]:
            row_cells = " | ".join(_pm(row[f"{s}/{m}"]) for s in SPACES for m in METHODS)
            lines.append(f"| {row['fit']} | {row_cells} | {_pm(row['joint/GPLVM/rad'])} |")
    lines += [
        "",
        f"Wall time {result['wall_time_s']:.1f} s with {result['workers']} worker process(es).",
    ]
    return "\n".join(lines) + "\n"


FIT_NAMES = {
    "main": "noisy (main)",
    "exact_demos": "exact",
    "noise_floor": "noisy, θ3 ≥ {floor:g}",
    "exact_demos_noise_floor": "exact, θ3 ≥ {floor:g}",
}


def _variants(preset: Table1Preset, summary: dict[str, Any]) -> dict[str, list[dict[str, Any]]]:
    """Long-format rows of the variants tables from the summary."""
    constraint, recon = [], []
    for label in preset.fit_configs():
        name = FIT_NAMES[label].format(floor=preset.variant_noise_floor)
        for margin in preset.margins():
            for test in CONSTRAINT_TESTS:
                if label != "main" and test != preset.constraint_test:
                    continue
                row: dict[str, Any] = {"fit": name, "margin": f"{100 * margin:g} %", "test": test}
                for s in SPACES:
                    for m in METHODS:
                        row[f"{s}/{m}"] = summary[label][s][m]["constraint"][_margin_key(margin)][
                            test
                        ]
                constraint.append(row)
        rrow: dict[str, Any] = {"fit": name}
        for s in SPACES:
            for m in METHODS:
                rrow[f"{s}/{m}"] = summary[label][s][m]["recon"]
        rrow["joint/GPLVM/rad"] = summary[label]["joint"]["GPLVM"]["recon_joint"]
        recon.append(rrow)
    return {"constraint": constraint, "recon": recon}


# ---------------------------------------------------------------------------------------------
# Runner


THREAD_VARIABLES = (
    "RAYON_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "OMP_NUM_THREADS",
    "MKL_NUM_THREADS",
)
"""Thread-count variables set to 1 for worker processes: the workers already fill the cores, and
OpenBLAS threads spinning in two processes on two cores slow a run down ~2x (measured)."""


@contextmanager
def _single_threaded_children() -> Iterator[None]:
    """Sets THREAD_VARIABLES to 1 while worker processes are spawned (they inherit the
    environment at start-up, before NumPy loads), then restores this process's values."""
    saved = {key: os.environ.get(key) for key in THREAD_VARIABLES}
    os.environ.update(dict.fromkeys(THREAD_VARIABLES, "1"))
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _n_workers(preset: Table1Preset) -> int:
    if preset.workers:
        return min(preset.workers, preset.trials)
    return max(1, min(worker_threads(), preset.trials))


def run_table1(
    preset: Table1Preset | None = None,
    out_dir: str | os.PathLike[str] | None = None,
    progress: bool = True,
) -> dict[str, Any]:
    """Runs Table I for `preset`, prints the table beside the paper's and, if `out_dir` is given,
    writes `table1.json` (preset, environment, per-trial values, summary) and `table1.md` there,
    atomically. Returns the JSON payload as a dict."""
    preset = Table1Preset() if preset is None else preset
    preset.validate()
    started = time.perf_counter()
    workers = _n_workers(preset)
    trials: list[dict[str, Any]] = []
    bar = _progress(preset.trials, progress)
    if workers == 1:
        for t in range(preset.trials):
            trials.append(run_trial(preset, t))
            bar.update(1)
    else:
        # spawn, not fork: a forked child inherits a broken rayon pool from the parent.
        context = multiprocessing.get_context("spawn")
        with cf.ProcessPoolExecutor(workers, mp_context=context) as pool:
            with _single_threaded_children():
                futures = [pool.submit(run_trial, preset, t) for t in range(preset.trials)]
            for future in cf.as_completed(futures):
                future.result()
                bar.update(1)
            trials = [f.result() for f in futures]
    bar.close()

    summary = summarise(preset, trials)
    result: dict[str, Any] = {
        "experiment": "table1",
        "preset": describe(preset),
        "environment": environment(),
        "paper": PAPER,
        "workers": workers,
        "wall_time_s": time.perf_counter() - started,
        "summary": summary,
        "variants": _variants(preset, summary) if preset.variants else None,
        "trials": trials,
    }
    table = format_table(result)
    print(table)
    if out_dir is not None:
        out = Path(out_dir)
        write_json(out / "table1.json", result)
        atomic_write(out / "table1.md", lambda f: f.write(("# Table I\n\n" + table).encode()))
    return result


class _NoBar:
    def update(self, n: int) -> None:
        pass

    def close(self) -> None:
        pass


def _progress(total: int, enabled: bool) -> Any:
    if not enabled:
        return _NoBar()
    from latentrl.progress import progress_bar

    return progress_bar(total=total, desc="Table I trials", unit="trial")
