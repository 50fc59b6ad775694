"""``phantom-pin``: the parser, the options every command shares, and main()."""

from __future__ import annotations

import argparse
import os
import sys

from phantom_pin.cli import codegen, device, feel, identification, model, openhaptics, ros2
from phantom_pin.cli.common import Parser, add_model_options, merge_model_options
from phantom_pin.exceptions import PhantomPinError

DESCRIPTION = """The PHANToM arms' model: info, check, fk, ik, dynamics, urdf, srdf, mjcf, links, show,
simulate, feel, excite, identify, codegen, openhaptics-sim, ros2. --model NAME or --config DIR chooses the
configuration, --params FILE and --set KEY=VALUE override its numbers; they go before or after the command."""
#: The dests of the model options given after the command end with this.
AFTER = "_after_command"


def parser() -> argparse.ArgumentParser:
    """The phantom-pin parser: the shared options, then one subparser per command."""
    top = Parser(prog="phantom-pin", description=DESCRIPTION)
    add_model_options(top)
    top.add_argument("--quiet", "-q", action="store_true",
                     help="no progress bar on stderr (shown on a terminal when work takes over 2 s)")
    sub = top.add_subparsers(dest="command", required=True, parser_class=Parser)
    for concern in (model, device, feel, identification, codegen, openhaptics, ros2):
        concern.add_parsers(sub)
    for command in sub.choices.values():  # the model options and --quiet after the command too
        add_model_options(command, AFTER)
        command.add_argument("--quiet", "-q", action="store_true", default=argparse.SUPPRESS,
                             help="no progress bar on stderr")
    return top


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code: 0 ok, 1 check failed, 2 bad input or
    an unwritable file (one line on stderr), 130 interrupted by Ctrl-C (128 + SIGINT, one
    line; ``show`` alone ends on Ctrl-C with 0, its normal stop), 141 output pipe closed by
    its reader (128 + SIGPIPE, silent, as ``yes | head``)."""
    options: dict[str, str] = {}
    try:
        args = parser().parse_args(argv)
        merge_model_options(args, AFTER)
        options = getattr(args, "options", None) or {}
        code = args.run(args)
        sys.stdout.flush()  # a closed pipe raises here, not at exit
        return code
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit either
        return 141
    except KeyboardInterrupt:
        print("phantom-pin: interrupted", file=sys.stderr)
        return 130
    except (PhantomPinError, ValueError, OSError) as error:
        if isinstance(error, PhantomPinError) and error.argument is not None:
            message = f"{options.get(error.argument, error.argument)}: {error.detail}"
        elif isinstance(error, OSError) and error.filename:
            message = f"{error.filename}: {error.strerror}"
        else:
            message = str(error)
        print(f"phantom-pin: error: {' '.join(message.split())}", file=sys.stderr)
        return 2
