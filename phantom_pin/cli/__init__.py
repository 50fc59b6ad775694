"""The ``phantom-pin`` command line: one module per concern (model, device, identification),
the shared options and helpers in common, the parser and main() in app."""

from phantom_pin.cli.app import main

__all__ = ["main"]
