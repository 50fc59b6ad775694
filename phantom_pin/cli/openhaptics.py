"""``phantom-pin openhaptics-sim build DIR``: the libHD stand-in (phantom_pin.interfaces.openhaptics)."""

from __future__ import annotations

import argparse

from phantom_pin.cli.common import source


def build(args: argparse.Namespace) -> int:
    """Write DIR/include/HD/*.h and DIR/lib/libHD.so for --model or --config; nothing is written on
    failure, nor over a file without --force."""
    from phantom_pin.interfaces.openhaptics import build as build_stand_in
    target = build_stand_in(args.directory, source(args), force=args.force, argument="DIR", force_hint="--force")
    print(f"wrote {target / 'include' / 'HD' / 'hd.h'} and {target / 'lib' / 'libHD.so'}: build with "
          f"gcc -I {target / 'include'} prog.c -L {target / 'lib'} -lHD, run with LD_LIBRARY_PATH={target / 'lib'}")
    return 0


def add_parsers(sub: argparse._SubParsersAction) -> None:
    """openhaptics-sim."""
    command = sub.add_parser("openhaptics-sim", help="a stand-in for OpenHaptics' libHD that runs HDAPI programs "
                                                     "(C, pyOpenHaptics) against the simulated device")
    command.add_argument("action", choices=("build",),
                         help="build: write DIR/include/HD/hd.h (and what it includes) and DIR/lib/libHD.so (gcc)")
    command.add_argument("directory", metavar="DIR", help="the folder to write include/ and lib/ into")
    command.add_argument("--force", "-f", action="store_true", help="overwrite existing files")
    command.set_defaults(run=build, options={"directory": "DIR"})
