"""C code generation: a self-contained C99 header of a configuration's dynamics for 1 kHz
servo loops (phantom-pin codegen). Needs SymPy (the ``codegen`` extra)."""

from phantom_pin.codegen.generate import header, is_identifier
from phantom_pin.codegen.write import write_header

__all__ = ["header", "is_identifier", "write_header"]
