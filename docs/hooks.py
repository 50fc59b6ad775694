"""MkDocs hooks (mkdocs.yml `hooks:`): the pages generated at build time.

- cli.md: `<!-- cli-reference -->` becomes the reference of every `phantom-pin` command, generated
  from the argparse parser itself (phantom_pin.cli.app.parser), so it cannot fall behind it;
- index.md: `<!-- readme -->` becomes README.md, its links made the site's;
- changelog.md: `<!-- changelog -->` becomes CHANGELOG.md;
- models.md: `<!-- model: NAME -->` becomes that model's section of the description package's
  README (its numbers' sources and how it differs from a plain import) and every line of its
  YAML that says ESTIMATE, with file and line: read from where they live, never copied.

tests/integration/test_docs_site.py imports this file to check that every subcommand and option appears.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
CLI_MARKER, CHANGELOG_MARKER, README_MARKER = "<!-- cli-reference -->", "<!-- changelog -->", "<!-- readme -->"
DESCRIPTION = ROOT / "robots" / "phantom_description"
MODEL_MARKER = re.compile(r"<!-- model: (\w+) -->")


def _cell(text: str) -> str:
    """``text`` as one Markdown table cell: one line, pipes escaped."""
    return " ".join(text.split()).replace("|", "\\|")


def _own(parser: argparse.ArgumentParser, skip: set[str]) -> list[argparse.Action]:
    """``parser``'s arguments but its help, its subcommands and the options named in ``skip``."""
    return [a for a in parser._actions if a.help != argparse.SUPPRESS and not isinstance(a, argparse._HelpAction)
            and not isinstance(a, argparse._SubParsersAction) and not set(a.option_strings) & skip]


def _usage(parser: argparse.ArgumentParser, skip: set[str]) -> str:
    """The parser's usage line without the options named in ``skip``, unwrapped."""
    formatter = parser._get_formatter()
    formatter.add_usage(None, _own(parser, skip), parser._mutually_exclusive_groups)
    return " ".join(formatter.format_help().removeprefix("usage:").split())


def _options(parser: argparse.ArgumentParser, skip: set[str]) -> list[str]:
    """The table rows of ``parser``'s arguments (not its subcommands), but the options in ``skip``."""
    formatter = parser._get_formatter()
    rows = []
    for action in _own(parser, skip):
        names = ", ".join(f"`{name}`" for name in action.option_strings) or f"`{action.metavar or action.dest}`"
        argument = formatter._format_args(action, action.dest.upper()) if action.nargs != 0 else ""
        default = action.default if action.default not in (None, False, argparse.SUPPRESS) else ""
        choices = ", ".join(f"`{c}`" for c in action.choices) if action.choices else ""
        text = formatter._expand_help(action) if action.help else ""
        rows.append(f"| {names} | {_cell(f'`{argument}`' if argument else '')} | {_cell(choices)} | "
                    f"{_cell(f'`{default}`' if default != '' else '')} | {_cell(text)} |")
    return rows


HEADER = ["| option | argument | choices | default | what |", "|---|---|---|---|---|"]


def commands(top: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Every subcommand's parser of ``top``, by name, in the parser's order."""
    action = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def shared_options(top: argparse.ArgumentParser) -> set[str]:
    """The option strings given before the subcommand (and after it too), but -h."""
    return {s for a in top._actions if not isinstance(a, argparse._HelpAction) for s in a.option_strings}


def cli_reference(top: argparse.ArgumentParser | None = None) -> str:
    """The Markdown reference of ``top`` (default: phantom-pin's parser): its shared options, then
    every subcommand with its usage, description and options."""
    if top is None:
        from phantom_pin.cli.app import parser

        top = parser()
    helps = {a.dest: a.help for a in next(a for a in top._actions
                                          if isinstance(a, argparse._SubParsersAction))._choices_actions}
    lines = ["## Shared options", "", "Before or after the subcommand, for every command.", "",
             *HEADER, *_options(top, set()), ""]
    for name, command in commands(top).items():
        lines += [f"## `{name}`", ""]
        if helps.get(name):
            lines += [_cell(helps[name] or ""), ""]
        lines += ["```text", _usage(command, shared_options(top)), "```", ""]
        if command.description:
            lines += [" ".join(command.description.split()), ""]
        rows = _options(command, shared_options(top))
        lines += [*HEADER, *rows, ""] if rows else ["No options of its own.", ""]
    return "\n".join(lines)


def model_section(name: str) -> str:
    """Model ``name``'s section of robots/phantom_description/README.md (without its heading and
    picture) and the ESTIMATE lines of its config folder's YAML, as Markdown."""
    readme = (DESCRIPTION / "README.md").read_text(encoding="utf-8")
    start = readme.index(f"\n### `{name}`")
    section = readme[start:].split("\n", 2)[2].split("\n#")[0]
    lines = [line for line in section.splitlines() if not line.startswith("![")]
    text = "\n".join(lines).strip().replace("../../docs/", "").replace("(../", "(")
    estimates = []
    for path in sorted((DESCRIPTION / "config" / name).glob("*.yaml")):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if "ESTIMATE" in line:
                estimates.append(f"| `{path.name}:{number}` | `{_cell(line.strip())}` |")
    return "\n".join([text, "", f"Every line of `config/{name}/` that says ESTIMATE:", "",
                      "| file:line | the line |", "|---|---|", *estimates, ""])


def readme() -> str:
    """README.md with its links into docs/ made the site's (DEVELOPERS.md is no page of it)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for old, new in (("](docs/)", "](index.md)"), ("](docs/", "]("), ("](CHANGELOG.md)", "](changelog.md)"),
                     ("[DEVELOPERS.md](DEVELOPERS.md)", "DEVELOPERS.md (in the repository)"),
                     ("`docs/api.md`", "[API reference](api.md)")):
        text = text.replace(old, new)
    return text


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Fill the generated parts of index.md, cli.md, models.md and changelog.md."""
    if README_MARKER in markdown:
        markdown = markdown.replace(README_MARKER, readme())
    if CLI_MARKER in markdown:
        markdown = markdown.replace(CLI_MARKER, cli_reference())
    markdown = MODEL_MARKER.sub(lambda match: model_section(match[1]), markdown)
    if CHANGELOG_MARKER in markdown:
        markdown = markdown.replace(CHANGELOG_MARKER, (ROOT / "CHANGELOG.md").read_text(encoding="utf-8"))
    return markdown
