"""The architecture holds: a flat public namespace, data flowing one way (no import cycles),
the engine independent of its applications, and engine functions short enough to read."""
import ast
from pathlib import Path

import pytest

import nonsmooth_rod as nr

pytestmark = pytest.mark.no_compiled_loop  # runs no compiled loop: scheduled first (tests/conftest.py)

PACKAGE = Path(nr.__file__).resolve().parent
PUBLIC = ["simulate", "Scene", "RigidBody", "Line", "DiskOnLine", "PointOnLine", "DiskOnDisk", "ContactLaw",
          "solve", "SimulationResult", "Status", "ContactState", "StopAtImpact", "InputError"]
APPLICATIONS = ("rod", "toys", "commands", "cli")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """Every nonsmooth_rod module `path` imports, at any depth (lazy imports count too)."""
    module = _module_name(path)
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.startswith("nonsmooth_rod"):
                found.add(target)
                found.update(f"{target}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith("nonsmooth_rod"))
    return found


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {name: {t for t in _imports(path) if t in files and t != name} for name, path in files.items()}


def test_the_public_names_are_at_the_root():
    for name in PUBLIC:
        assert hasattr(nr, name), name
    assert set(PUBLIC) <= set(nr.__all__)


def test_no_module_imports_another_in_a_circle():
    graph = _graph()
    # a package's __init__ re-exporting its own modules is not a cycle of ideas: drop edges parent → child
    for name, targets in graph.items():
        graph[name] = {t for t in targets if not t.startswith(name + ".")}
    state, stack, cycles = {}, [], []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                cycles.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = "done"

    for node in sorted(graph):
        if node not in state:
            visit(node)
    assert cycles == []


def test_the_engine_does_not_import_its_applications():
    graph = _graph()
    engine = [m for m in graph if "." in m and m.split(".")[1] not in APPLICATIONS]
    for module in engine:
        bad = [t for t in graph[module] if "." in t and t.split(".")[1] in APPLICATIONS]
        assert bad == [], (module, bad)


@pytest.mark.parametrize("folder", ["model", "solvers", "integrators", "driver.py", "results.py"])
def test_engine_functions_are_short(folder):
    paths = [PACKAGE / folder] if folder.endswith(".py") else sorted((PACKAGE / folder).rglob("*.py"))
    long = []
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > 60:
                    long.append(f"{path.name}:{node.name} ({length} lines)")
    assert long == []
