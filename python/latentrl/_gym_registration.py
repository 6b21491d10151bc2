"""latentrl's Gymnasium environments (`latentrl.envs`) registered as soon as Gymnasium is loaded:
at once if it is, else right after its first import. So `import latentrl` registers them as
`import ale_py` does without loading Gymnasium (0.05 s of CPU) where no environment is made
(the `latentrl` command)."""

from __future__ import annotations

import importlib
import sys
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from importlib.machinery import ModuleSpec
    from types import ModuleType


class _AfterGymnasium:
    """A `sys.meta_path` finder: the other finders find Gymnasium; once its module has run, it
    imports `latentrl.envs` (which registers the environments) and leaves `sys.meta_path`."""

    def find_spec(self, name: str, path: Any, target: ModuleType | None = None) -> ModuleSpec | None:
        if name != "gymnasium":
            return None
        for finder in [f for f in sys.meta_path if f is not self and hasattr(f, "find_spec")]:
            spec: ModuleSpec | None = finder.find_spec(name, path, target)
            if spec is not None:
                break
        else:
            return None
        if spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        run = spec.loader.exec_module

        def run_then_register(module: ModuleType) -> None:
            run(module)
            if self in sys.meta_path:
                sys.meta_path.remove(self)
            importlib.import_module("latentrl.envs")

        spec.loader.exec_module = run_then_register  # type: ignore[method-assign]
        return spec


def register_when_gymnasium_loads() -> None:
    """Registers the environments now if Gymnasium is loaded, else once it is."""
    if "gymnasium" in sys.modules:
        importlib.import_module("latentrl.envs")
    elif not any(isinstance(f, _AfterGymnasium) for f in sys.meta_path):
        sys.meta_path.insert(0, _AfterGymnasium())
