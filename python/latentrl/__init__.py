"""latentrl: reinforcement learning in the latent space of demonstrated postures."""

import sys as _sys
from typing import TYPE_CHECKING as _TYPE_CHECKING, Any as _Any


def _started_as_cli() -> bool:
    """Whether this process is the `latentrl` command (`latentrl …` or `python -m latentrl …`)."""
    argv = _sys.orig_argv
    module = argv[argv.index("-m") + 1:][:1] if "-m" in argv else []
    return _sys.argv[0].rsplit("/", 1)[-1] == "latentrl" or module == ["latentrl"]


try:
    from latentrl._estimator import NotFittedError
    from latentrl._native import (
        GpMap,
        InternalError,
        InvalidInputError,
        LatentrlError,
        NumericalError,
        __version__,
    )
    from latentrl.demos import Demonstrations, load_demos, save_demos
    from latentrl.gplvm import GPLVM
    from latentrl.pca import PCA
    from latentrl.task import Task
    from latentrl.train import LatentPolicy

    from latentrl._gym_registration import register_when_gymnasium_loads

    register_when_gymnasium_loads()  # the Gymnasium environments, as ale_py does
except BaseException as err:
    # Ctrl-C while the command still imports (its first ~0.3 s): the command's own message and
    # exit code, not the interpreter's traceback (or the native module's "initialization failed").
    # A program that imports latentrl gets its KeyboardInterrupt as ever.
    if (isinstance(err, KeyboardInterrupt) or isinstance(err.__context__, KeyboardInterrupt)) and _started_as_cli():
        print("latentrl: interrupted; nothing was written", file=_sys.stderr)
        raise SystemExit(130) from None
    raise

if _TYPE_CHECKING:
    from latentrl.experiments.training import train_latent_policy


def __getattr__(name: str) -> _Any:
    """`train_latent_policy`, `latentrl train`'s run in memory, loaded when first asked for: it
    lives with its experiment, and no public module imports the experiments (ARCHITECTURE.md);
    `envs`, the Gymnasium environments, loaded (with Gymnasium) when first asked for."""
    if name == "train_latent_policy":
        from latentrl.experiments.training import train_latent_policy

        return train_latent_policy
    if name == "envs":
        import latentrl.envs

        return latentrl.envs
    raise AttributeError(f"module 'latentrl' has no attribute {name!r}")


__all__ = [
    "GPLVM",
    "PCA",
    "Task",
    "Demonstrations",
    "GpMap",
    "LatentPolicy",
    "InternalError",
    "InvalidInputError",
    "LatentrlError",
    "NotFittedError",
    "NumericalError",
    "__version__",
    "load_demos",
    "save_demos",
    "train_latent_policy",
]
