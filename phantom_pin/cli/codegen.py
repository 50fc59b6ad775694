"""``phantom-pin codegen``: the C99 header of a configuration's dynamics (phantom_pin.codegen)."""

from __future__ import annotations

import argparse

from phantom_pin._progress import Progress
from phantom_pin.cli.common import Once, output, overrides, source


def codegen(args: argparse.Namespace) -> int:
    """Write the header of --model or --config with --params and --set, its functions named
    --prefix; nothing is written on failure, nor over a file without --force."""
    from phantom_pin.codegen import header, write_header  # sympy is only needed here
    target = output(args)
    bar = Progress("codegen", 1.0, enabled=False if args.quiet else None)
    try:
        text = header(source(args), prefix=args.prefix, overrides=overrides(args), progress=bar.update,
                      argument="--config" if args.config is not None else "--model")
    finally:
        bar.close()
    write_header(text, target, force=args.force, name="--output", force_hint="--force")
    print(f"wrote {target}")
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """codegen."""
    command = sub.add_parser("codegen", help="write a self-contained C99 header (gravity, inverse dynamics, "
                                             "M, Coriolis, tip position, Jacobian, J^T F) for a servo loop")
    command.add_argument("--output", "-o", required=True, action=Once, help="the header to write, e.g. touch.h")
    command.add_argument("--prefix", default="phantom", help="the C name of every function (default phantom)")
    command.add_argument("--force", "-f", action="store_true", help="overwrite an existing file")
    command.set_defaults(run=codegen, options={"prefix": "--prefix"})
