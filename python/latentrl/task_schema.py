"""The task file's keys as the native side defines them (`crates/sim/src/task/config.rs`): the
schema, the `[run]` table's settings and their one check, key paths, what changed in a task since
a run recorded it, and the Markdown tables of docs/tasks.md."""

from __future__ import annotations

import json
from collections.abc import Mapping
from functools import cache
from typing import Any

from latentrl import _native


@cache
def schema() -> tuple[dict[str, Any], ...]:
    """Every key of a task file: `{key, doc, rule, kind, default}` (the native definitions)."""
    return tuple(_native.task_schema())


@cache
def run_settings() -> dict[str, dict[str, Any]]:
    """The keys of the `[run]` table by name (`trials`, `encoder`, …): `{key, doc, rule, kind,
    default}` (the native `RunConfig`: trials, episodes, seed, GPLVM fit, encoder, latent box)."""
    return {e["key"].removeprefix("run."): e for e in schema() if e["key"].startswith("run.")}


def run_default(name: str) -> Any:
    """The default of the run setting `name` (`run_settings`)."""
    return run_settings()[name]["default"]


def encoders() -> tuple[str, ...]:
    """The encoders a latent RL run can use (the choices of `run.encoder`; docs/encoders.md)."""
    return tuple(run_settings()["encoder"]["kind"].split(" | "))


def check_run(settings: Mapping[str, Any]) -> dict[str, Any]:
    """`settings` (run settings by name, a part of them) checked by the `[run]` table's rules:
    every run setting's effective value, or a ValueError naming `run.<key>` and its rule."""
    checked: dict[str, Any] = _native.run_config(dict(settings))
    return checked


def by_path(entry: Mapping[str, Any]) -> bool:
    """Whether a schema key can be set by its dotted path (`learner.alpha`): a key of a table,
    not one of each list item (`constraints[].kind`) or of each named entry (`servo.joints.NAME.kp`)."""
    key = entry["key"]
    return "." in key and "[]" not in key and "NAME" not in key


def key_paths(table: Any) -> Any:
    """A nested table (``{"learner": {"alpha": 0.5}}``) as key paths (``{"learner.alpha": 0.5}``);
    anything but a mapping unchanged."""
    if not isinstance(table, Mapping):
        return table
    out: dict[str, Any] = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            out.update({f"{key}.{k}": v for k, v in key_paths(value).items()})
        else:
            out[key] = value
    return out


def ran_with(recorded: Mapping[str, Any]) -> dict[str, Any]:
    """The task a run recorded (`Task.to_dict()` then) by key path, with every settable key the
    record lacks (added since) at its default: the behaviour before the key existed."""
    return {**{e["key"]: e["default"] for e in schema() if by_path(e)}, **key_paths(recorded)}


def changed_since(recorded: Mapping[str, Any], now: Mapping[str, Any]) -> dict[str, Any]:
    """The keys (by path) whose value in the task a run recorded (`ran_with`) differs from the
    task `now`'s, with the recorded values."""
    given, ran, now = key_paths(recorded), ran_with(recorded), key_paths(now)
    return {k: v for k, v in ran.items() if (k in now and now[k] != v) or (k in given and k not in now)}


def schema_markdown() -> str:
    """The keys of a task file as Markdown tables, one per table (docs/tasks.md embeds it)."""
    sections: dict[str, list[dict[str, Any]]] = {}
    for entry in schema():
        table = entry["key"].rpartition(".")[0]
        sections.setdefault(table, []).append(entry)
    out = []
    for table, entries in sections.items():
        out.append(f"### `[{table}]`" if table else "### top level")
        out.append("")
        out.append("| key | type | default | rule | meaning |")
        out.append("|---|---|---|---|---|")
        for e in entries:
            name = e["key"].rpartition(".")[2]
            rule = "" if e["rule"] == "any value" else e["rule"]
            table_kind = "table" in e["kind"]
            default = "(below)" if table_kind else f"`{json.dumps(e['default'], allow_nan=True)}`"
            cells = [f"`{name}`", e["kind"], default, rule, e["doc"]]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        out.append("")
    return "\n".join(out)

