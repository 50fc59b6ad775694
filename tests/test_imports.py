"""The package's import graph: no cycle between its modules, counting function-local imports
(which would only hide one), and every module imports in a fresh interpreter, leaves first.

The graph is read from the source (ast), one edge per ``import phantom_pin.x`` or ``from
phantom_pin.x import y`` (to phantom_pin.x.y where y is a module), wherever it stands in the
file. A package's own __init__ re-exporting its modules is not an edge of its modules."""

import ast
import subprocess
import sys
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

import phantom_pin

PACKAGE = Path(phantom_pin.__file__).resolve().parent


def _name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_name(path): path for path in sorted(PACKAGE.rglob("*.py"))}


def _imports(name: str, path: Path) -> set[str]:
    """The phantom_pin modules ``name`` imports anywhere in its file."""
    found = set()
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names if alias.name.startswith("phantom_pin")}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from . import x
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            if not base.startswith("phantom_pin"):
                continue
            for alias in node.names:
                found.add(f"{base}.{alias.name}" if f"{base}.{alias.name}" in MODULES else base)
    # a package's __init__ imports its own modules to re-export them: not an edge of theirs
    return {target for target in found if target in MODULES and target != name
            and not (path.name == "__init__.py" and target.startswith(name + "."))
            and not (name.startswith(target + ".") and MODULES[target].name == "__init__.py")}


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def test_the_import_graph_has_no_cycle():
    """Before: dynamics.loader <-> dynamics.model, identification.base <-> structures and
    identification.io <-> estimation, each hidden by a function-local import."""
    try:
        order = list(TopologicalSorter(GRAPH).static_order())
    except CycleError as error:
        raise AssertionError(f"import cycle: {' -> '.join(error.args[1])}") from None
    assert set(order) == set(MODULES)


def test_the_layers_point_down():
    """The model layer (config, description, dynamics, report) imports neither the device, the
    identification nor the command line; the device not the identification."""
    upper = {"phantom_pin.config": ("device", "identification", "cli", "dynamics", "description", "viewer"),
             "phantom_pin.description": ("device", "identification", "cli", "dynamics", "viewer"),
             "phantom_pin.dynamics": ("device", "identification", "cli", "viewer"),
             "phantom_pin.report": ("device", "identification", "cli", "viewer"),
             "phantom_pin.device": ("identification", "cli", "viewer")}
    wrong = [f"{name} -> {target}" for name, targets in GRAPH.items() for target in targets
             for layer, above in upper.items() if name.startswith(layer)
             and any(target.startswith(f"phantom_pin.{a}") for a in above)]
    assert not wrong


def test_every_module_imports_in_a_fresh_interpreter_leaves_first():
    order = list(TopologicalSorter(GRAPH).static_order())
    script = f"import importlib\nfor name in {order!r}:\n    importlib.import_module(name)\n"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
