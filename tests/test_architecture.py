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


def test_importing_latentrl_imports_no_scipy():
    """Issue #39, item 5: `import latentrl` loaded SciPy (0.33 s of its 0.65 s CPU) for fits it
    had not started; SciPy now loads at the first fit (benches measure the time itself)."""
    import subprocess
    import sys

    code = "import sys, latentrl; print(sorted({m.split('.')[0] for m in sys.modules} & {'scipy'}))"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert done.stdout.strip() == "[]"
