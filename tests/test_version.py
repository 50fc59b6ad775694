"""One version everywhere: pyproject.toml, the installed distribution, phantom_pin.__version__,
the description's package.xml, the newest entry of both changelogs and CITATION.cff."""

import re
import xml.etree.ElementTree as ET
from importlib.metadata import version
from pathlib import Path

import yaml

import phantom_pin
from phantom_pin._paths import DESCRIPTION_DIR

ROOT = Path(__file__).resolve().parent.parent


def _newest(changelog: Path) -> str:
    return re.search(r"^## (\d+\.\d+\.\d+)", changelog.read_text(), re.MULTILINE).group(1)


def test_one_version_everywhere():
    # [project]'s version line (tomllib is Python 3.11+; the package supports 3.10)
    declared = re.search(r'^version = "([^"]+)"$', (ROOT / "pyproject.toml").read_text(), re.MULTILINE).group(1)
    found = {"installed": version("phantom_pin"), "__version__": phantom_pin.__version__,
             "package.xml": ET.parse(DESCRIPTION_DIR / "package.xml").getroot().findtext("version"),
             "CHANGELOG.md": _newest(ROOT / "CHANGELOG.md"),
             "description CHANGELOG.md": _newest(DESCRIPTION_DIR / "CHANGELOG.md"),
             "CITATION.cff": yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))["version"]}
    assert found == dict.fromkeys(found, declared)
