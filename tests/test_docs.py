"""The documentation generated from the native definitions is current."""

import re
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
