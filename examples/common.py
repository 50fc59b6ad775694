"""Shared by the examples: the --out/--force arguments, safe output paths, one-line errors."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # headless: figures go to files

from phantom_pin import PhantomPinError  # noqa: E402
from phantom_pin._validation import output_path  # noqa: E402


def parser(description: str) -> argparse.ArgumentParser:
    """An argument parser with --out DIR (default ./example_output) and --force."""
    result = argparse.ArgumentParser(description=description)
    result.add_argument("--out", type=Path, default=Path("example_output"),
                        help="folder for the figures (created if missing)")
    result.add_argument("--force", action="store_true", help="overwrite existing files")
    return result


def output(args: argparse.Namespace, name: str) -> Path:
    """``args.out / name``; refuses an existing file unless --force."""
    args.out.mkdir(parents=True, exist_ok=True)
    return output_path(args.out / name, args.force, "--out", "--force")


def run(main: Callable[[list[str] | None], None]) -> None:
    """Run an example's main; a PhantomPinError becomes one line and exit code 2."""
    try:
        main(None)
    except PhantomPinError as error:
        print(f"{Path(sys.argv[0]).name}: error: {error}", file=sys.stderr)
        sys.exit(2)
