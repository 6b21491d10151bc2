"""A run's folder read back as one object, `RunFolder` (docs/method.md §Results layout): its
preset, recorded task, inputs and fit, its arrays and its model, each read once, with the checks
that a run resumed, replayed, plotted or rolled out is the run it says it is (issue #38). The
files' layout is `latentrl.results`."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from latentrl._files import read_bounded
from latentrl._persistence import MAX_NPZ_BYTES, read_npz
from latentrl.experiments.presets import describe
from latentrl.results import (
    MODEL_FILE,
    PER_EPISODE,
    PRESET_KEY,
    array_key,
    as_saved,
    finished_trials,
    gplvm_info,
    read_json,
    read_results,
    remove_stale_temporaries,
)
from latentrl.task import changed_since, end_reasons, ran_with

if TYPE_CHECKING:  # the GPLVM (and SciPy) load with the first run read back, not with `--help`
    from latentrl.gplvm import GPLVM


class RunFolder:
    """The results directory of a run (docs/method.md §Results layout) read back: results.json
    (the preset, the recorded task, input digests and fit), returns.npz and gplvm.npz, each read
    once when first asked for (a folder written since is read by a new `RunFolder`). It owns
    the checks that a run continued (`previous`, `check_continued`), replayed, plotted or rolled
    out (`check_inputs`, `check_fit`) is the run it says it is; each error names the file or the
    input that differs."""

    def __init__(self, path: Path | str) -> None:
        self.path = Path(path)
        self._results: dict[str, Any] | None = None
        self._arrays: dict[str, np.ndarray] | None = None
        self._model: tuple[GPLVM, dict[str, np.ndarray]] | None = None

    @property
    def results_path(self) -> Path:
        """results.json: the preset, the setup's facts, the per-trial summaries."""
        return self.path / "results.json"

    @property
    def arrays_path(self) -> Path:
        """returns.npz: the per-episode and per-trial arrays (`PER_EPISODE`, `PER_TRIAL`)."""
        return self.path / "returns.npz"

    @property
    def model_path(self) -> Path:
        """gplvm.npz: the GPLVM the trials learnt in (`MODEL_FILE`)."""
        return self.path / MODEL_FILE

    @property
    def report_path(self) -> Path:
        """report.json: the verdict `latentrl train` made on policy.npz, with that file's digest."""
        return self.path / "report.json"

    def policy_digest(self) -> str:
        """SHA-256 of policy.npz's bytes: the policy a report.json was written for."""
        import hashlib  # OpenSSL: loaded by a run read back, not by `import latentrl`

        return hashlib.sha256(read_bounded(self.path / "policy.npz", MAX_NPZ_BYTES, "a policy file")).hexdigest()

    def saved_report(self) -> dict[str, Any] | None:
        """report.json where it was written for the policy.npz there now (its `policy_sha256`);
        None if there is none, or it is older than that policy (a resumed run, a report of an
        earlier version without the digest): then the verdict is made anew."""
        if not self.report_path.is_file():
            return None
        report = read_json(self.report_path)
        return report if report.get("policy_sha256") == self.policy_digest() else None

    def holds_run(self) -> bool:
        """Whether a run saved its results here (results.json exists)."""
        return self.results_path.exists()

    def results(self) -> dict[str, Any]:
        """results.json (`read_results`: its errors name the file and the field)."""
        if self._results is None:
            self._results = read_results(self.results_path)
        return self._results

    def preset(self) -> dict[str, Any]:
        """The preset results.json records (its fields and `name`), {} if none."""
        return dict(self.results().get("preset") or {})

    def recorded_task(self) -> dict[str, Any] | None:
        """The effective task the trials ran with (`Task.to_dict`), None where none was recorded."""
        task: dict[str, Any] | None = self.results().get("setup", {}).get("task")
        return task

    def recorded_inputs(self) -> dict[str, str]:
        """The SHA-256 of each input the run was made from, by name ("task file", "urdf", "demos",
        "model"); {} for a run that recorded none."""
        return dict(self.results().get("setup", {}).get("inputs") or {})

    def arrays(self) -> dict[str, np.ndarray]:
        """Every array of returns.npz: a ValueError naming the file if it is not readable or an
        array (but the preset's JSON) holds anything but numbers."""
        if self._arrays is None:
            path = self.arrays_path
            try:
                arrays = read_npz(path)
            except ValueError as err:
                raise ValueError(f"{path}: {err}") from None
            for key, value in arrays.items():
                if key != PRESET_KEY and value.dtype.kind not in "biuf":
                    raise ValueError(f"{path}: {key} holds {value.dtype} values, expected numbers")
            self._arrays = arrays
        return self._arrays

    def finished(self) -> tuple[dict[str, np.ndarray], dict[str, int]]:
        """`finished_trials` of the arrays (its errors name the file)."""
        try:
            return finished_trials(self.arrays())
        except ValueError as err:
            raise ValueError(f"{self.arrays_path}: {err}") from None

    def model(self) -> GPLVM | None:
        """The GPLVM saved in gplvm.npz, None if the run has none (saved before models were kept)."""
        saved = self._saved_model()
        return None if saved is None else saved[0]

    def model_arrays(self) -> dict[str, np.ndarray] | None:
        """gplvm.npz's arrays as read (what the run's "model" digest covers), None without one."""
        saved = self._saved_model()
        return None if saved is None else saved[1]

    def _saved_model(self) -> tuple[GPLVM, dict[str, np.ndarray]] | None:
        """gplvm.npz read once: the GPLVM and the arrays it was made from."""
        if self._model is None:
            if not self.model_path.exists():
                return None
            from latentrl.gplvm import GPLVM

            try:
                arrays = read_npz(self.model_path)
            except ValueError as err:
                raise ValueError(f"{self.model_path}: {err}") from err
            self._model = GPLVM._from_arrays(arrays, str(self.model_path)), arrays
        return self._model

    def previous(self, preset: Any) -> tuple[dict[str, np.ndarray], dict[str, Any] | None]:
        """Arrays and metadata of an earlier run of `preset` in this folder,
        ({}, None) if there is none; a ValueError if the folder holds a run of another preset, or
        one whose results.json was edited after its trials ran. Temporary files a killed write
        left are removed first."""
        for path in (self.results_path, self.arrays_path):
            remove_stale_temporaries(path)
        if not self.results_path.exists():
            return {}, None
        meta = self.results()
        self.check_preset(preset)
        if not self.arrays_path.exists():
            return {}, None
        arrays = self.arrays()
        recorded = self.recorded_task()
        self._check_saved_run(preset, arrays, ran_with(recorded) if recorded is not None else {})
        return arrays, meta

    def check_preset(self, preset: Any) -> None:
        """The run saved here is of `preset`; a ValueError naming each field and task key that
        differs otherwise (a field the record lacks counts at its default: `with_defaults`). Reads
        results.json only: `train --resume` asks before its fit."""
        recorded = self.recorded_task()
        ran = ran_with(recorded) if recorded is not None else {}
        changes = edits(with_defaults(self.preset(), preset), as_saved(describe(preset)), ran, "in the run", "now")
        if changes:
            raise ValueError(f"{self.path} holds a run of a different preset ({changes}); choose another --out "
                             "or delete it (only a run of the same preset is continued)")

    def _check_saved_run(self, preset: Any, arrays: Mapping[str, np.ndarray], ran: Mapping[str, Any]) -> None:
        """The arrays of a run being continued were computed with `preset`; a ValueError naming the
        edited fields otherwise (mixing would be silently wrong)."""
        if PRESET_KEY in arrays:
            saved = with_defaults(saved_preset(self.arrays_path, arrays[PRESET_KEY]), preset)
            now = as_saved(describe(preset))
            changes = edits(saved, now, ran, "in returns.npz", "in results.json")
            if changes:
                raise ValueError(f"{self.path}/results.json was edited after its trials ran ({changes}); resume refuses "
                                 "to mix the two: restore the file, or start a new run with --out")

    def check_continued(self, meta: Mapping[str, Any], learners: Iterable[str], info: Mapping[str, Any],
                        arrays: Mapping[str, np.ndarray]) -> None:
        """A continued run's trials ran with the task the setup (its `learners` by name and its
        recorded `info`) builds and its per-episode arrays have the preset's shapes (its model fit is
        checked where the setup reads it back: `check_fit`) and with the inputs it recorded
        (`check_inputs`: first, since a changed input can change settings derived from it)."""
        check_inputs(meta.get("setup", {}).get("inputs") or {}, info.get("inputs") or {}, self.path)
        recorded = meta.get("setup", {}).get("task")
        keys = sorted(changed_since(recorded, as_saved(info.get("task")) or {})) if recorded is not None else []
        if keys:
            raise ValueError(f"{self.path}: its trials ran with another task ({', '.join(keys)} differ); resume "
                             "refuses to mix the two: start a new run with --out")
        want = (meta["preset"]["trials"], meta["preset"]["episodes"])
        for name in learners:
            for what in PER_EPISODE:
                key = array_key(name, what)
                if key not in arrays:
                    raise ValueError(f"{self.path}/returns.npz: {key} is missing; restore the file, or start a new "
                                     "run with --out")
                if arrays[key].shape != want:
                    raise ValueError(f"{self.path}/returns.npz: {key} has shape {arrays[key].shape}, the preset asks "
                                     f"for {want} (trials, episodes); it belongs to another run")
                codes = len(end_reasons())
                if what == "ends" and not np.isin(arrays[key], np.arange(-1, codes)).all():
                    raise ValueError(f"{self.path}/returns.npz: {key} holds values other than end codes "
                                     f"(integers in -1..{codes - 1}); restore the file, or start a new run with --out")

    def check_inputs(self, now: Mapping[str, str]) -> None:
        """`check_inputs` of the digests the run recorded against `now`'s."""
        check_inputs(self.recorded_inputs(), now, self.path)

    def check_fit(self, model: GPLVM, *, kept: bool) -> None:
        """`model` (the saved gplvm.npz's if `kept`, else a refit) is the fit results.json records
        (`gplvm_info`); a ValueError naming the source otherwise."""
        saved, now = self.results().get("setup", {}).get("gplvm"), as_saved(gplvm_info(model))
        if saved is not None and saved != now:
            source = f"{self.model_path} (nll {now['nll']})" if kept else (
                f"the GPLVM refitted on this machine (nll {now['nll']}; the run has no {MODEL_FILE}, and another CPU "
                "or BLAS can fit another latent space)")
            raise ValueError(f"{source} is not the one the saved trials used (nll {saved.get('nll')}, "
                             f"{self.results_path}); refusing to mix them: restore the run's files, or start a new "
                             "run with --out")


def saved_preset(path: Path, value: np.ndarray) -> dict[str, Any]:
    """The preset that returns.npz at `path` records (`PRESET_KEY`: a JSON object in a string
    array), or a ValueError naming the file (issue #38: a mangled one was a JSONDecodeError that
    named no file, or a TypeError)."""
    try:
        saved = json.loads(str(value)) if value.dtype.kind == "U" and value.ndim == 0 else None
    except (ValueError, RecursionError):
        saved = None
    if not isinstance(saved, dict) or not isinstance(saved.get("task") or {}, dict):
        raise ValueError(f"{path}: {PRESET_KEY} is not the JSON object of a preset (got {value.dtype} of shape "
                         f"{value.shape}); restore the file, or start a new run with --out")
    return saved


def with_defaults(saved: Mapping[str, Any], preset: Any) -> dict[str, Any]:
    """A preset a run recorded, each field of `preset`'s class that the record lacks at the class's
    default when the record is of that class: a field added since, the behaviour before it
    existed (as `task.ran_with` completes the recorded task)."""
    if saved.get("name") != type(preset).__name__:
        return dict(saved)
    fields = dataclasses.fields(preset)
    defaults = {f.name: f.default for f in fields if f.default is not dataclasses.MISSING}
    defaults |= {f.name: f.default_factory() for f in fields if f.default_factory is not dataclasses.MISSING}
    return {**as_saved(defaults), **saved}


def edited_fields(saved: Mapping[str, Any], now: Mapping[str, Any], ran: Mapping[str, Any]) -> list[str]:
    """The preset fields that differ between `saved` and `now`, and the task keys (by path,
    ``learner.alpha``) its `task` overrides differ in. A task override that only restores what
    the trials ran with (`ran`: `task.ran_with` of the recorded task, empty if none was recorded)
    is not an edit: `saved_runs.saved_run` adds those when a shipped task changed since."""
    edited = [k for k in set(saved) | set(now) if k != "task" and saved.get(k) != now.get(k)]
    before, after = saved.get("task") or {}, now.get("task") or {}
    restored = {k for k in set(after) - set(before) if k in ran and ran[k] == after[k]}
    edited += [k for k in set(before) | set(after) if before.get(k) != after.get(k) and k not in restored]
    return sorted(edited)


def edits(saved: Mapping[str, Any], now: Mapping[str, Any], ran: Mapping[str, Any], was: str, is_: str) -> str:
    """The `edited_fields` as the user wrote them, "episodes: 150 in the run, 200 now" (a task
    override by its key path; one not given: "not given"), joined by "; "; "" if none. A preset
    of another kind (`name`, e.g. an Exp 1 run resumed by `train`) is named alone."""
    def value(preset: Mapping[str, Any], key: str) -> str:
        holder = preset if key in preset else preset.get("task") or {}
        return repr(holder[key]) if key in holder else "not given"

    edited = edited_fields(saved, now, ran)
    return "; ".join(f"{k}: {value(saved, k)} {was}, {value(now, k)} {is_}"
                     for k in (["name"] if "name" in edited else edited))


def check_inputs(recorded: Mapping[str, str], now: Mapping[str, str], out: Path) -> None:
    """ValueError naming the first input (task file, URDF, demos, model) whose SHA-256 the run
    recorded and that now differs: a run is continued, replayed, rolled out or plotted only with
    what it was made from."""
    for name, digest in recorded.items():
        if name in now and now[name] != digest:
            raise ValueError(f"{out}: its {name} changed since the run (sha256 {digest[:12]}… ≠ {now[name][:12]}…); "
                             "the run is refused rather than mixed with it: restore it, or start a new run with --out")
