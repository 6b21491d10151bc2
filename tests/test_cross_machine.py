"""Same seed across CPUs (issue #21), measured where it ends: an RL run from a saved GPLVM is
bit-identical on this CPU and under `qemu-x86_64 -cpu Haswell` (AVX2, no AVX-512: glibc's and
NumPy's kernels change), while the GPLVM fit itself follows the OpenBLAS kernel. Slow (`make
test-all`); needs Debian's qemu-user."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(shutil.which("qemu-x86_64") is None, reason="needs qemu-x86_64 (Debian's qemu-user)"),
]

ROOT = Path(__file__).resolve().parents[1]
FIT = """
import hashlib, sys
import numpy as np
from latentrl import GPLVM
from latentrl.datasets import arm_postures
m = GPLVM(random_state=0, max_iter=200).fit(arm_postures(123, np.random.default_rng(0)))
print(hashlib.sha256(m.Z_.tobytes()).hexdigest())
if len(sys.argv) > 1:
    m.save(sys.argv[1])
"""
RL = """
import hashlib, sys
from latentrl import GPLVM, train_latent_policy
p = train_latent_policy(GPLVM.load(sys.argv[1]), "two_arms", trials=1, episodes=4, test_episodes=2,
                        overrides={"episode.max_steps": 100}, progress=False)
print(hashlib.sha256(p.returns.tobytes() + p.weights.tobytes() + p.test_returns.tobytes()).hexdigest())
"""


def python(code: str, *args: str, cpu: str | None = None, env: dict[str, str] | None = None) -> str:
    """`code` run by this venv's interpreter, natively or under qemu with `cpu`; its stdout."""
    command = [sys.executable, "-c", code, *args]
    if cpu is not None:
        real = os.path.realpath(sys.executable)  # qemu runs the ELF binary, not the venv's symlink
        site = next(p for p in sys.path if p.endswith("site-packages"))
        prelude = f"import site, sys; site.addsitedir({site!r}); sys.path.insert(0, {str(ROOT / 'python')!r}); "
        command = ["qemu-x86_64", "-cpu", cpu, real, "-c", prelude + code, *args]
    out = subprocess.run(command, capture_output=True, text=True, timeout=900, env={**os.environ, **(env or {})})
    assert out.returncode == 0, out.stderr[-2000:]
    return out.stdout.strip().splitlines()[-1]


def test_an_rl_run_from_a_saved_model_is_bit_identical_on_an_avx2_cpu(tmp_path):
    model = str(tmp_path / "model.npz")
    python(FIT, model)
    assert python(RL, model) == python(RL, model, cpu="Haswell")


def test_the_gplvm_fit_follows_the_openblas_kernel():
    """Documented, not promised away: the emulated Haswell fit equals the native fit with
    OpenBLAS's Haswell kernel; another kernel gives other latent points."""
    haswell = python(FIT, env={"OPENBLAS_CORETYPE": "Haswell"})
    assert python(FIT, cpu="Haswell") == haswell
    assert python(FIT, env={"OPENBLAS_CORETYPE": "Sandybridge"}) != haswell
