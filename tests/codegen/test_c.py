"""codegen.c: the C text of a function built from SymPy expressions, compiled strictly as C99 and
C++17 by gcc (helpers.build) and run through ctypes, against the same expressions evaluated in
Python's math module (1e-15 relative: straight-line double arithmetic both sides); the printer's
small powers as products, and the function's comment block."""

import ctypes
import math

import numpy as np
import pytest
import sympy as sp

from helpers import build
from phantom_pin.codegen import c

X, Y, Z, U = sp.symbols("x y z u")
OUTPUTS = [sp.sin(X) ** 2 * sp.cos(Y) + X**3 / (1 + Z**2), sp.sqrt(1 + Y**2) * sp.sin(X) ** 2 - Z**9,
           sp.Float("0.12345678901234567") * sp.cos(Y) * Z]
SHIM = """#include "model.h"
void run(const double *q, const double *unused, double *out) { demo(q, unused, out); }
"""


def _python(x, y, z):
    return [math.sin(x) ** 2 * math.cos(y) + x**3 / (1 + z**2), math.sqrt(1 + y**2) * math.sin(x) ** 2 - z**9,
            0.12345678901234567 * math.cos(y) * z]


def test_the_c_text_compiles_and_computes_the_expressions(tmp_path):
    """body() of three outputs of q = (x, y, z) and an unused array: compiled with -Werror (an
    unused argument would warn: it is voided), run on seeded inputs, equal to the expressions in
    Python within 1e-15 relative (1e-15 absolute near 0)."""
    text = c.body([(f"out[{k}]", e) for k, e in enumerate(OUTPUTS)], [("q", [X, Y, Z]), ("unused", [U])])
    assert "(void)unused;" in text and "const double x = q[0];" in text
    header = "#include <math.h>\n" + c.function("A demo.\n\nSecond paragraph.",
                                                 "demo(const double q[3], const double unused[1], double out[3])",
                                                 text)
    library = build(header, tmp_path, shim=SHIM)
    pointer = ctypes.POINTER(ctypes.c_double)
    for q in np.random.default_rng(12).uniform(-2, 2, (20, 3)):
        q = np.ascontiguousarray(q)
        out, unused = np.empty(3), np.zeros(1)
        library.run(q.ctypes.data_as(pointer), unused.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
        np.testing.assert_allclose(out, _python(*q), rtol=1e-15, atol=1e-15)


def test_small_powers_are_products_and_literals_keep_17_digits():
    """x^2..x^8 print as products (gcc inlines them), x^9 and x^-2 through pow; the literal keeps
    its 17 significant digits; the function's comment is a C block, its empty lines ' *'."""
    printer = c.Printer({"precision": 17})
    assert printer.doprint(X**2) == "(x*x)" and printer.doprint(X**8) == "(" + "*".join("x" * 8) + ")"
    assert printer.doprint((X + 1) ** 3) == "((x + 1)*(x + 1)*(x + 1))"
    assert printer.doprint(X**9) == "pow(x, 9)" and "pow" in printer.doprint(X**-2)
    assert "0.12345678901234567" in printer.doprint(sp.Float("0.12345678901234567", 17) * X)
    text = c.function("first\n\nsecond", "f(void)", "    return;")
    assert text == "/*\n * first\n *\n * second\n */\nstatic inline void f(void)\n{\n    return;\n}\n"


@pytest.mark.parametrize("power", [2, 5, 8])
def test_a_product_power_equals_pow(power):
    """The products evaluate as Python's x**n (the same value within 4 ulp: n - 1 roundings)."""
    printed = c.Printer({"precision": 17}).doprint(X**power)
    for x in (0.3, -1.7, 2.5):
        assert eval(printed, {"x": x}) == pytest.approx(x**power, rel=4 * power * 2.2e-16)
