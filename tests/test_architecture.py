"""The shape ARCHITECTURE.md promises (issue #16): no import circles in the package (lazy imports
included), pure Rust crates that know no Python, latent_core that knows no plant, and one
definition per task rule (no URDF parsing or kinematics in Python)."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "latentrl"


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports() -> dict[str, set[str]]:
    """Module → the latentrl modules it imports anywhere in its body (lazy imports too)."""
    modules = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in modules.items():
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                targets = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            found |= {t for t in targets if t in modules and t != name}
        graph[name] = found - {"latentrl"}  # the package root re-exports; it is imported by all
    return graph


def test_no_module_imports_itself_through_others():
    graph = imports()
    state: dict[str, int] = {}
    cycles: list[list[str]] = []

    def visit(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in graph[node]:
            if state.get(nxt) == 1:
                cycles.append(path[path.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt, [*path, nxt])
        state[node] = 2

    for node in graph:
        if node not in state:
            visit(node, [node])
    assert not cycles, f"import circles: {cycles}"


def test_pure_crates_know_no_python_and_latent_core_no_plant():
    for crate in ("latent_core", "sim"):
        manifest = (ROOT / "crates" / crate / "Cargo.toml").read_text()
        assert "pyo3" not in manifest and "numpy" not in manifest, crate
    core = (ROOT / "crates" / "latent_core" / "Cargo.toml").read_text()
    assert not re.search(r"^sim", core, re.M), "latent_core depends on sim"


def test_the_package_parses_no_urdf():
    for path in PACKAGE.rglob("*.py"):
        text = path.read_text()
        assert "xml.etree" not in text and "ElementTree" not in text, f"{path} parses XML"


def rust_imports(src: Path) -> dict[str, set[str]]:
    """Top-level module of a crate → the crate's top-level modules its code names (`crate::x`)."""
    graph: dict[str, set[str]] = {}
    for path in src.rglob("*.rs"):
        top = path.relative_to(src).parts[0].removesuffix(".rs")
        code = "\n".join(line for line in path.read_text().splitlines() if not line.lstrip().startswith("//"))
        graph.setdefault(top, set()).update(set(re.findall(r"crate::(\w+)", code)) - {top})
    return graph


def test_no_rust_module_circles():
    for crate in ("latent_core", "sim", "latentrl_py"):
        graph = rust_imports(ROOT / "crates" / crate / "src")

        def reaches(start: str, goal: str) -> bool:
            seen, todo = set(), [start]
            while todo:
                for nxt in graph.get(todo.pop(), ()):  # noqa: B023 (called in the loop)
                    if nxt == goal:
                        return True
                    if nxt not in seen:
                        seen.add(nxt)
                        todo.append(nxt)
            return False

        circles = sorted({tuple(sorted((a, b))) for a in graph for b in graph[a] if reaches(b, a)})
        assert not circles, f"{crate}: modules that import each other: {circles}"


def test_importing_latentrl_imports_no_scipy_nor_gymnasium():
    """Issue #39, item 5: `import latentrl` loaded SciPy (0.33 s of its 0.65 s CPU) for fits it
    had not started; SciPy now loads at the first fit, Gymnasium (0.05 s) when it is imported,
    which registers the environments then (benches measure the time itself)."""
    import subprocess
    import sys

    code = ("import sys, latentrl; print(sorted({m.split('.')[0] for m in sys.modules} & {'scipy', 'gymnasium'}))\n"
            "import gymnasium; print('latentrl/TwoArms-v0' in gymnasium.registry)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert done.stdout.split() == ["[]", "True"]


TASK_MATHS = {"norm", "hypot", "sqrt", "sin", "cos", "tan", "arcsin", "arccos", "arctan", "arctan2", "atan2", "cross", "dist"}
"""Calls that kinematics, distances to a target or obstacle tests need (`np.linalg.norm`, `np.hypot`,
`math.dist`, trigonometry, cross products); `x ** 0.5` counts as `sqrt`."""

TASK_GEOMETRY = {"reach_radius", "position", "obstacles", "half_extents", "obstacle_centre", "obstacle_radius",
                 "drop_tolerance", "floor", "constraints", "tolerance"}
"""Task keys (subscripts or attributes) that a success, reach or collision test compares against."""

NOT_TASK_RULES = {
    ("check.py", "survey_findings"): "reads reach_radius for its message; distances and reached points "
                                      "are the native survey's",
    ("check.py", "encoder_finding"): "a distance in latent space (encode ∘ decode round trip), in learner steps",
    ("datasets.py", "arm_hands"): "the demo generator's sampling region (shoulder→hand distance), which the plant "
                                  "never applies",
    ("envs/latent_space.py", "LatentSpaceWrapper.__init__"): "a PCA model's default latent box, ±3 s.d. of its components",
    ("gplvm.py", "GPLVM._fit"): "the PCA initialisation scaled by its first s.d.",
    ("physics_check.py", "servo_error"): "the servos' tracking error against the rest poses",
    ("physics_check.py", "physics_error"): "the distance between two physics settings' tracks, against the "
                                           "task's physics.tolerance",
    ("render.py", "<module>"): "the unit ring the renderer draws",
    ("render.py", "draw_room_3d"): "obstacles and floor clipped to the drawn view",
    ("experiments/fallcheck.py", "_rms_max"): "RMS and max tracking error of the fall check's joints",
    ("experiments/table1.py", "_evaluate"): "Table I's reconstruction RMS and the share of native grip errors "
                                            "within the table's tolerance",
}
"""Functions that use `TASK_MATHS`, or read `TASK_GEOMETRY` and compare, for something that is not a
task rule: each says what it computes instead."""


def scoped_nodes(tree: ast.AST) -> dict[str, list[ast.AST]]:
    """Innermost function or class ("Class.method", "<module>") → the nodes written in its body."""
    scopes: dict[str, list[ast.AST]] = {}

    def walk(node: ast.AST, scope: str) -> None:
        for child in ast.iter_child_nodes(node):
            inner = scope
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                inner = f"{scope}.{child.name}" if scope != "<module>" else child.name
            scopes.setdefault(inner, []).append(child)
            walk(child, inner)

    walk(tree, "<module>")
    return scopes


def task_rule_suspects(package: Path = PACKAGE) -> dict[tuple[str, str], str]:
    """(module path, function) → what it does that task rules need: a `TASK_MATHS` call, or a
    `TASK_GEOMETRY` read in a function that also compares with <, <=, > or >= (`_reference.py`, the
    NumPy oracle of the native rules, left out)."""
    order = (ast.Lt, ast.LtE, ast.Gt, ast.GtE)
    found: dict[tuple[str, str], str] = {}
    for path in sorted(package.rglob("*.py")):
        if path.name == "_reference.py":
            continue
        for scope, nodes in scoped_nodes(ast.parse(path.read_text())).items():
            maths, keys, compares = set(), set(), False
            for node in nodes:
                if isinstance(node, ast.Call):
                    func = node.func
                    name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
                    maths |= {name} & TASK_MATHS
                elif isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
                    if isinstance(node.right, ast.Constant) and node.right.value == 0.5:
                        maths.add("sqrt")
                elif isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant):
                    keys |= {node.slice.value} & TASK_GEOMETRY
                elif isinstance(node, ast.Attribute):
                    keys |= {node.attr} & TASK_GEOMETRY
                elif isinstance(node, ast.Compare):
                    compares |= any(isinstance(op, order) for op in node.ops)
            if maths or (keys and compares):
                uses = sorted(maths) + ([f"compares {sorted(keys)}"] if keys and compares else [])
                found[(path.relative_to(package).as_posix(), scope)] = ", ".join(uses)
    return found


def test_task_rules_only_in_rust():
    """Issue #39, item 3: kinematics, success, distances to targets and obstacle geometry are asked
    of the native task (`TaskPlant`, `latent_survey`, `arms_fk`, `grip_error`), not recomputed.
    An AST scan cannot prove it; it catches the operations such code needs, outside a short list
    of functions that use them for something else."""
    suspects = task_rule_suspects()
    unexplained = {where: uses for where, uses in suspects.items() if where not in NOT_TASK_RULES}
    assert not unexplained, f"task rules computed in Python (ask the native task, or explain in NOT_TASK_RULES): " \
                            f"{unexplained}"
    stale = sorted(set(NOT_TASK_RULES) - set(suspects))
    assert not stale, f"NOT_TASK_RULES entries that no longer use task maths: {stale}"


ABOVE_EXPERIMENTS = {
    "latentrl": "re-exports `train_latent_policy` (documented as `latentrl.train_latent_policy`), which lives with "
                "its experiment, loaded when first asked for (`__getattr__`)",
    "latentrl.__main__": "`python -m latentrl`: the command",
    "latentrl.cli": "the `latentrl` command's entry point: parses, then runs the subcommand (`cli_commands`)",
    "latentrl.cli_parser": "the command's flags: `run NAME`'s are its experiment's preset fields and task keys, "
                           "found through the registry when that subcommand is used",
    "latentrl.cli_commands": "the subcommands: dispatch to the experiments by name through the registry, and run "
                             "`train`, `rollout`, `report`, `plot`, `sweep` on their run folders",
    "latentrl.saved_runs": "a run folder read back as its experiment's name and preset (the registry's presets)",
    "latentrl.replay": "`latentrl replay`: videos of a run folder's episodes, as the experiment that wrote it stored them",
}
"""The modules above the experiments (the command and the package root's lazy re-export): the only
ones outside `latentrl.experiments` that may import it."""


def test_imports_point_from_experiments_to_the_public_api():
    """Issue #39, item 4: commands → experiments → public API → `_native`. No public module imports
    an experiment or a command, no experiment imports a command; lazy imports count (an import
    inside a function is still a dependency). Circles: `test_no_module_imports_itself_through_others`."""
    graph = imports()
    assert set(ABOVE_EXPERIMENTS) <= set(graph), f"ABOVE_EXPERIMENTS names modules that do not exist: {set(ABOVE_EXPERIMENTS) - set(graph)}"

    def layer(module: str) -> int:
        return 2 if module in ABOVE_EXPERIMENTS else 1 if module.startswith("latentrl.experiments") else 0

    upward = {
        module: sorted(t for t in targets if layer(t) > layer(module))
        for module, targets in graph.items()
        if any(layer(t) > layer(module) for t in targets)
    }
    assert not upward, f"modules that import a layer above their own: {upward}"
    root = sorted(t for t in graph["latentrl"] if layer(t) == 1)
    assert root == ["latentrl.experiments.training"], f"the package root imports experiments: {root}"


def test_experiments_stay_at_most_13_modules():
    """Issue #39, item 4: the orchestration layer is small enough to read (it had 20 modules)."""
    modules = sorted(p.name for p in (PACKAGE / "experiments").glob("*.py"))
    assert len(modules) <= 13, modules
