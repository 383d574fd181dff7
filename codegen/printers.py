"""Expression printers: sympy's own, overriding only how numbers are written.

Constants are folded first (`fold_constants`), so every number that is not an integer
is a single Float, printed as the shortest decimal that reads back as the same double.
"""

import sympy
from sympy.printing.numpy import NumPyPrinter


def fold_constants(expr: sympy.Expr) -> sympy.Expr:
    """Replace constant subexpressions (2159/5000, sqrt(2)/2, pi/4) by one Float each.

    Integers stay integers and exponents stay exact, so x**(1/2) still prints as sqrt(x).
    """
    if expr.is_number:
        return expr if expr.is_Integer else sympy.Float(expr.evalf(30), 30)
    if expr.is_Atom:
        return expr
    if expr.is_Pow:
        return sympy.Pow(fold_constants(expr.base), expr.exp)
    return expr.func(*(fold_constants(arg) for arg in expr.args))


def float_literal(value: sympy.Expr) -> str:
    """Shortest decimal that reads back as the nearest double to `value`."""
    return repr(float(value))


class PythonPrinter(NumPyPrinter):
    """numpy code over batched inputs."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False})

    def _print_Float(self, expr):
        return float_literal(expr)
