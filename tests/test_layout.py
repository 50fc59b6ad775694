"""The tests' shape: tests/ mirrors the package, one test file per module with logic
(phantom_pin/<a>/<b>.py: tests/<a>/test_<b>.py; the root's phantom_pin/_x.py: tests/test_x.py),
and no test file imports another (what they share is in helpers.py, conftest.py's fixtures and
the references package; pytest imports test files by path, --import-mode=importlib, so
tests/cli/test_feel.py and tests/device/test_feel.py are two modules).

Read from the files (pathlib and ast), as tests/test_imports.py reads the package."""

import ast
from pathlib import Path

import phantom_pin

PACKAGE = Path(phantom_pin.__file__).resolve().parent
TESTS = Path(__file__).resolve().parent

#: The modules with no mirrored test file, each with its reason (module paths under phantom_pin/;
#: a package's __init__.py and __main__.py need none: they hand names on, tests/test_api.py and
#: the command line's tests run them).
EXEMPT = {
    "_paths.py": "constants alone (where the description folder and the driver profiles are)",
    "report/appendix.py": "the appendix's printed torques, the reference report/test_closed_form.py checks against",
}
#: The subpackages another change restructures.
EXEMPT_PACKAGES: dict[str, str] = {}
#: The test folders whose files may still import one another, for the same reason.
EXEMPT_IMPORTS: dict[str, str] = {}


def _modules() -> list[Path]:
    """Every module of the package but the __init__ and __main__ files, relative to it."""
    return [path.relative_to(PACKAGE) for path in sorted(PACKAGE.rglob("*.py"))
            if path.name not in ("__init__.py", "__main__.py")]


def mirror(module: Path) -> Path:
    """The test file of a module (relative to tests/): test_<name>.py in the module's folder (the
    leading underscore of a private module left off)."""
    return module.parent / f"test_{module.stem.lstrip('_')}.py"


def _test_files() -> list[Path]:
    return sorted(path for path in TESTS.rglob("test_*.py"))


def test_every_module_has_its_mirrored_test_file():
    exempt = {module for module in _modules() if module.as_posix() in EXEMPT or module.parts[0] in EXEMPT_PACKAGES}
    missing = [f"phantom_pin/{module.as_posix()}: tests/{mirror(module).as_posix()}"
               for module in _modules() if module not in exempt and not (TESTS / mirror(module)).is_file()]
    assert not missing, missing
    stale = [name for name in EXEMPT if not (PACKAGE / name).is_file() or (TESTS / mirror(Path(name))).is_file()]
    assert not stale, f"exempt but gone or mirrored: {stale}"


def _imported(path: Path) -> set[str]:
    """The top-level names of the modules a file imports, anywhere in it."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names |= {alias.name.partition(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            names.add(node.module.partition(".")[0])
    return names


def test_no_test_file_imports_another():
    """A test file imports helpers, conftest or references, never a test_*.py (nor a conftest
    module by name: its fixtures come by pytest)."""
    tests = {path.stem for path in _test_files()}
    wrong = {path.relative_to(TESTS).as_posix(): sorted(_imported(path) & (tests | {"conftest"}))
             for path in sorted(TESTS.rglob("*.py"))
             if path.relative_to(TESTS).parts[0] not in EXEMPT_IMPORTS}
    wrong = {path: names for path, names in wrong.items() if names}
    assert not wrong, wrong
