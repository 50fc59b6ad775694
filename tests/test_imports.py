"""The package's shape: no import cycle between its modules, counting function-local imports
(which would only hide one), every module imports in a fresh interpreter, leaves first, and
every module and function stays a size and a complexity a reader can follow.

The graph is read from the source (ast), one edge per ``import phantom_pin.x`` or ``from
phantom_pin.x import y`` (to phantom_pin.x.y where y is a module), wherever it stands in the
file, a package's __init__ included (it hands its modules' names on: edges to them)."""

import ast
import functools
import subprocess
import sys
from graphlib import CycleError, TopologicalSorter
from pathlib import Path

from radon.complexity import cc_visit

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
    return {target for target in found if target in MODULES and target != name}


@functools.cache
def graph() -> dict[str, set[str]]:
    """Each module's imports of the package's modules (parsed when a test first asks)."""
    return {name: _imports(name, path) for name, path in MODULES.items()}


def test_the_import_graph_has_no_cycle():
    """Before: dynamics.loader <-> dynamics.model, identification.base <-> structures and
    identification.io <-> estimation, each hidden by a function-local import."""
    try:
        order = list(TopologicalSorter(graph()).static_order())
    except CycleError as error:
        raise AssertionError(f"import cycle: {' -> '.join(error.args[1])}") from None
    assert set(order) == set(MODULES)


#: Every module's layer (DEVELOPERS.md, "Map of the package"), by the longest matching prefix
#: of its name after ``phantom_pin.``: a module imports from its own layer or below only.
LAYERS = {"exceptions": 0, "_validation": 0, "_blas": 0, "_paths": 0, "_integration": 0, "_progress": 0, "_moved": 0,
          "description.inertial": 0, "report": 1, "config": 2, "description": 3, "dynamics": 4,
          "interfaces.conventions": 4, "interfaces.profiles": 4, "device": 5, "dynamics.verification": 5,
          "viewer.plots": 5, "identification": 6.4, "interfaces.forces": 6, "codegen": 6, "viewer": 6,
          "robot_descriptions": 6, "interfaces": 7, "cli": 8, "": 9,
          # identification's stages, in order within its layer (its __init__ hands on all four: 6.4)
          "identification.data": 6.1, "identification.structure": 6.2, "identification.fitting": 6.3,
          "identification.verdict": 6.4}


def _layer(name: str) -> float | None:
    """The layer of a module, None where LAYERS names none."""
    short = name.removeprefix("phantom_pin").removeprefix(".")
    keys = [key for key in LAYERS if short == key or (key and short.startswith(key + "."))]
    return LAYERS[max(keys, key=len)] if keys else None


def test_every_module_has_a_layer_and_the_layers_point_down():
    """Every module (each package's __init__ too) is in LAYERS, and imports nothing above its
    layer: the model (report, config, description, dynamics) neither the device nor the
    identification, nor the ROS 2 node nor the command line."""
    assert not [name for name in MODULES if _layer(name) is None]
    wrong = [f"{name} ({_layer(name)}) -> {target} ({_layer(target)})" for name, targets in graph().items()
             for target in targets if (_layer(target) or 0) > (_layer(name) or 0)]
    assert not wrong, wrong


def test_the_internal_modules_are_private():
    """The internal helpers have a leading underscore and no public package hands them on."""
    internal = {name for name in MODULES if name.rpartition(".")[2].startswith("_") and not
                name.endswith("__init__") and name.rpartition(".")[2] != "__main__"}
    assert {"phantom_pin._validation", "phantom_pin._paths", "phantom_pin._integration",
            "phantom_pin._progress"} <= internal
    import importlib
    for name in MODULES:
        exported = getattr(importlib.import_module(name), "__all__", ())
        assert not [n for n in exported if n.startswith("_") and not n.endswith("__")], name


def test_every_module_imports_in_a_fresh_interpreter_leaves_first():
    order = list(TopologicalSorter(graph()).static_order())
    script = f"import importlib\nfor name in {order!r}:\n    importlib.import_module(name)\n"
    result = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr


#: The sizes a reader can follow (issue 40's aim): lines of a module, lines of a function or method.
MODULE_LINES, FUNCTION_LINES = 500, 80


def test_every_module_and_function_stays_readable():
    """No module over MODULE_LINES lines, no function or method over FUNCTION_LINES (its def to
    its last line, docstring included), read from the source with ast."""
    lines = {name: len(path.read_text().splitlines()) for name, path in MODULES.items()}
    long_modules = {name: n for name, n in lines.items() if n > MODULE_LINES}
    long_functions = {f"{name}.{node.name}": node.end_lineno - node.lineno + 1
                      for name, path in MODULES.items() for node in ast.walk(ast.parse(path.read_text()))
                      if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
                      and node.end_lineno - node.lineno + 1 > FUNCTION_LINES}
    assert not long_modules and not long_functions, (long_modules, long_functions)


#: The cyclomatic complexity a reader can follow (issue 51, item 6): radon's, as ruff's mccabe
#: caps it in pyproject.toml.
COMPLEXITY = 15


def _functions(blocks):
    """radon's functions and methods among ``blocks``, nested ones included (a class's own
    figure is its methods' average, no function's)."""
    for block in blocks:
        if hasattr(block, "methods"):
            yield from _functions(block.methods + block.inner_classes)
        else:
            yield block
            yield from _functions(block.closures)


def test_no_function_is_above_the_complexity_cap():
    """No function or method above COMPLEXITY by radon (radon.complexity.cc_visit over every module)."""
    complex_functions = {f"{name}.{block.fullname}:{block.lineno}": block.complexity
                         for name, path in MODULES.items() for block in _functions(cc_visit(path.read_text()))
                         if block.complexity > COMPLEXITY}
    assert not complex_functions, complex_functions
