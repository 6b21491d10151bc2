"""atheris fuzzing of the Python-side parsers (issue #21): demonstration files (CSV, JSON, NPZ)
and saved models (NPZ). Every input must load or raise ValueError / OSError (the API's error
types, InvalidInputError included); any other exception is a crash atheris reports.

    .venv/bin/pip install atheris
    .venv/bin/python fuzz/fuzz_demos_models.py fuzz/corpus/demos -max_total_time=180

(`make fuzz-py` does both.) The first input byte picks the format, the rest is the file.
"""

import sys
import tempfile
from pathlib import Path

import atheris

with atheris.instrument_imports():
    from latentrl import GPLVM, PCA, load_demos

#: What the first byte picks: a demo file of each format, or a saved model of each kind.
FORMATS = ("csv", "json", "npz", "gplvm", "pca")


def one_input(data: bytes) -> None:
    if not data:
        return
    kind = FORMATS[data[0] % len(FORMATS)]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / f"input.{kind if kind in ('csv', 'json') else 'npz'}"
        path.write_bytes(data[1:])
        try:
            if kind == "gplvm":
                GPLVM.load(path)
            elif kind == "pca":
                PCA.load(path)
            else:
                load_demos(path)
        except (ValueError, OSError):
            pass


if __name__ == "__main__":
    atheris.Setup(sys.argv, one_input)
    atheris.Fuzz()
