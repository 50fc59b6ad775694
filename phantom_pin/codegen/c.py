"""The C text of a generated header: SymPy's C99 printer as the header wants it, a function's
body of straight-line assignments after common-subexpression elimination, and a function with
its comment."""

from __future__ import annotations

from typing import Any

try:
    import sympy as sp
    from sympy.printing.c import C99CodePrinter
except ImportError:  # pragma: no cover - the codegen extra
    sp = None
    C99CodePrinter = object


class Printer(C99CodePrinter):
    """SymPy's C99 printer with small integer powers as products (gcc inlines pow(x, 2)
    alone) and literals with 17 digits."""

    def _print_Pow(self, expr: Any) -> str:
        if expr.exp.is_Integer and 2 <= expr.exp <= 8:  # libm's pow is a call, not inlined
            base = self.parenthesize(expr.base, 100)
            return "(" + "*".join([base] * int(expr.exp)) + ")"
        return super()._print_Pow(expr)


def body(outputs: list[tuple[str, Any]], inputs: list[tuple[str, list[Any]]]) -> str:
    """C statements: the used inputs unpacked, the common subexpressions, the outputs."""
    printer = Printer({"precision": 17})
    exprs = [e for _, e in outputs]
    temps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), order="none")
    used = set().union(*(e.free_symbols for e in exprs))
    lines = []
    for array, symbols in inputs:
        taken = [(i, s) for i, s in enumerate(symbols) if s in used]
        if not taken:
            lines.append(f"    (void){array};")
        for i, s in taken:
            lines.append(f"    const double {s} = {array}[{i}];")
    for symbol, expr in temps:
        lines.append(f"    const double {symbol} = {printer.doprint(expr)};")
    for (target, _), expr in zip(outputs, reduced):
        lines.append(f"    {target} = {printer.doprint(expr)};")
    return "\n".join(lines)


def function(comment: str, signature: str, body: str) -> str:
    text = "\n".join(" * " + line if line else " *" for line in comment.strip().splitlines())
    return f"/*\n{text}\n */\nstatic inline void {signature}\n{{\n{body}\n}}\n"


ASSUMES = "Assumes finite input: no checks, no allocation, no global state."
