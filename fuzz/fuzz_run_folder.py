"""atheris fuzzing of the run-folder readers (issue #38): results.json, returns.npz, gplvm.npz
and policy.npz of a tiny `latentrl train` run and rollout.json, rollout.npz of its rollout, read
by every reader of each (`RunFolder`, `train --resume`'s checks, `replay`'s reading and
`LatentPolicy.load`: tests/run_folder_readers.py). Every input must be read or refused with a
ValueError / OSError naming the file; any other exception, or NaN where the run stored numbers,
is a crash atheris reports.

    .venv/bin/pip install atheris
    mkdir -p fuzz/corpus/run_folder fuzz/artifacts
    .venv/bin/python fuzz/fuzz_run_folder.py fuzz/corpus/run_folder -max_total_time=180 -artifact_prefix=fuzz/artifacts/

(`make fuzz-py` runs it after fuzz_demos_models.py.) The run folder is made once at start (~5 s).
An input whose first byte is even drives the mutations of tests/run_folder_readers.py (a JSON
value deleted, retyped, nested or odd; an NPZ array dropped, renamed, retyped, reshaped or given
odd values; cut or flipped bytes) through Hypothesis (`fuzz_one_input`); an odd first byte
replaces the file its second byte picks with the remaining bytes. FUZZ_DRAW=1 also computes what
`replay` draws (the latent path and the links' poses: ~0.5 s an input).
"""

import os
import sys
import tempfile
from pathlib import Path

import atheris

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

with atheris.instrument_imports():
    import latentrl.experiments.run_folder  # noqa: F401
    import latentrl.results  # noqa: F401
    import latentrl.replay  # noqa: F401
    import latentrl.train  # noqa: F401

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from run_folder_readers import FILES, json_mutations, make_folder, npz_mutations, read_file  # noqa: E402
from run_folder_readers import read_mutated  # noqa: E402

ROOT = make_folder(Path(tempfile.mkdtemp(prefix="latentrl-fuzz-run-folder-")))
ORIGINAL = {name: (ROOT / name).read_bytes() for name in FILES}
DRAW = os.environ.get("FUZZ_DRAW") == "1"
for _name in FILES:
    read_file(ROOT, _name, draw=DRAW)  # the intact folder reads


def read(name: str, mutated: bytes) -> None:
    read_mutated(ROOT, name, mutated, ORIGINAL[name], draw=DRAW)


@settings(database=None, deadline=None, suppress_health_check=list(HealthCheck))
@given(data=st.data(), name=st.sampled_from(FILES))
def structured(data: st.DataObject, name: str) -> None:
    blob = ORIGINAL[name]
    read(name, data.draw(json_mutations(blob.decode()) if name.endswith(".json") else npz_mutations(blob)))


def one_input(data: bytes) -> None:
    if len(data) < 2:
        return
    if data[0] % 2 == 0:
        structured.hypothesis.fuzz_one_input(data[1:])
    else:
        read(FILES[data[1] % len(FILES)], data[2:])


if __name__ == "__main__":
    atheris.Setup(sys.argv, one_input)
    atheris.Fuzz()
