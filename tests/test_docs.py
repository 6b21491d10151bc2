"""The documentation generated from the native definitions is current, and the repository cites
no document it does not hold."""

import re
import subprocess
from pathlib import Path

from latentrl.task import schema_markdown

DOCS = Path(__file__).resolve().parents[1] / "docs"


def test_the_task_key_tables_are_the_native_schema():
    text = (DOCS / "tasks.md").read_text()
    block = re.search(r"<!-- keys:begin -->\n(.*)<!-- keys:end -->", text, re.S)
    assert block is not None, "docs/tasks.md lost its key markers"
    assert block.group(1).strip() == schema_markdown().strip(), (
        "docs/tasks.md is out of date: regenerate its keys with latentrl.task.schema_markdown()"
    )
    assert "### `[run]`" in block.group(1), "docs/tasks.md lost the [run] table (trials, episodes, encoder, …)"


# The design notes kept beside the repository (in a sibling folder), which files used to cite by
# name: what the code needs of them is in docs/method.md, docs/pitfalls.md and benches/README.md
# ("Peer figures"). The names are spelt in pieces so that this file does not cite them itself.
NOTES = ("SP" "EC", "PIT" "FALLS", "PE" "ERS")
OUTSIDE = re.compile(r"\b(" + "|".join(NOTES) + r")\b|\bSTY" r"LE\.md|\.\./" r"shared\b")


def test_no_tracked_file_cites_a_document_outside_the_repository():
    root = Path(__file__).resolve().parents[1]
    files = subprocess.run(["git", "ls-files", "-z"], cwd=root, capture_output=True, check=True).stdout
    found = []
    for name in files.decode().split("\0"):
        path = root / name
        if not name or not path.is_file() or name.startswith("runs/"):  # runs/: recorded results
            continue
        try:
            text = path.read_text()
        except UnicodeDecodeError:
            continue  # binary files (figures, NPZ) cite nothing
        found += [f"{name}:{n}: {line.strip()}" for n, line in enumerate(text.splitlines(), 1)
                  if OUTSIDE.search(line)]
    assert not found, "cites a document that is not in the repository:\n" + "\n".join(found)


def test_the_readmes_sweep_is_a_sweep():
    """The README's sweep used a bare `[grid]` of task keys, which `latentrl sweep` refuses."""
    import tomllib

    from latentrl.experiments.sweep import Sweep

    text = (DOCS.parent / "README.md").read_text()
    block = re.search(r"## Sweeps and Ray.*?```toml\n(.*?)```", text, re.S)
    assert block is not None, "the README lost its sweep example"
    sweep = Sweep.from_mapping(tomllib.loads(block.group(1)), "README.md")
    assert len(sweep.expand()) == 4
