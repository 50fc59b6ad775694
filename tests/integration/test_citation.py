"""CITATION.cff is valid Citation File Format 1.2.0 and names what the project's other files say.

The schema, tests/data/cff-1.2.0-schema.json, is the format's own (citation-file-format/
citation-file-format, tag 1.2.0, commit 396f738; CC-BY-4.0), validated by jsonschema's Draft 7
validator with its format checker (dates, URLs)."""

import json
import re
from pathlib import Path

import jsonschema
import yaml

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = json.loads((Path(__file__).parents[1] / "data" / "cff-1.2.0-schema.json").read_text(encoding="utf-8"))


def _citation() -> dict:
    return yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))


def _errors(document: dict) -> list[str]:
    validator = jsonschema.Draft7Validator(SCHEMA, format_checker=jsonschema.Draft7Validator.FORMAT_CHECKER)
    return [error.message for error in validator.iter_errors(document)]


def test_the_schema_is_cff_1_2_0_and_refuses_what_the_format_refuses():
    """The vendored schema is the format's 1.2.0 (its $id) and rejects a file without the four
    required keys, with an unknown key, or with a reference lacking authors."""
    assert SCHEMA["$id"] == "https://citation-file-format.github.io/1.2.0/schema.json"
    assert set(SCHEMA["required"]) == {"authors", "cff-version", "message", "title"}
    citation = _citation()
    for key in SCHEMA["required"]:
        assert _errors({k: v for k, v in citation.items() if k != key}), key
    assert _errors({**citation, "autors": citation["authors"]})
    report = {k: v for k, v in citation["references"][0].items() if k != "authors"}
    assert _errors({**citation, "references": [report]})


def test_citation_cff_is_valid_and_agrees_with_the_package():
    """No schema error; its licence is pyproject's and package.xml's; it cites the
    report by the title docs/errata.md gives as the source."""
    citation = _citation()
    assert _errors(citation) == []
    assert citation["cff-version"] == "1.2.0"
    # [project]'s licence line (tomllib is Python 3.11+; the package supports 3.10); the version
    # is tests/test_version.py's, with every other
    declared = re.search(r'^license = "([^"]+)"$', (ROOT / "pyproject.toml").read_text(encoding="utf-8"), re.M)
    assert declared is not None and citation["license"] == declared.group(1)
    package = (ROOT / "robots" / "phantom_description" / "package.xml").read_text(encoding="utf-8")
    assert f"<license>{citation['license']}</license>" in package
    source = re.search(r'^Source: "([^"]+)"', (ROOT / "docs" / "errata.md").read_text(encoding="utf-8"), re.M)
    assert source is not None
    report, = [r for r in citation["references"] if r["type"] == "report"]
    assert report["title"] == source.group(1)
