"""The wheel users install: built from this tree (hatchling, no network), it holds the package
with its py.typed marker (PEP 561: mypy and pyright read our annotations) and the description
package's files, and its version is the project's."""

import re
import subprocess
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_the_wheel_ships_py_typed_and_the_description(tmp_path):
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
                            "-w", str(tmp_path), str(ROOT)], capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stderr
    (wheel,) = tmp_path.glob("phantom_pin-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "phantom_pin/py.typed" in names
    version = re.search(r'^version = "([^"]+)"$', (ROOT / "pyproject.toml").read_text(), re.MULTILINE).group(1)
    assert wheel.name.startswith(f"phantom_pin-{version}-")
    shipped = {str(p.relative_to(ROOT / "robots")) for p in (ROOT / "robots").rglob("*") if p.is_file()}
    assert {f"phantom_pin/robots/{p}" for p in shipped} <= names
    assert {f"phantom_pin/{p.relative_to(ROOT / 'phantom_pin')}" for p in (ROOT / "phantom_pin").rglob("*.py")} <= names
