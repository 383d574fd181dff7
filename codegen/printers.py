"""Expression printers: sympy's own (numpy, C99, and a small CasADi one), each override documented.

Constants are folded first (`fold_constants`), so every number that is not an integer
is a single Float, printed as the shortest decimal that reads back as the same double
(the same float, in float C builds).
"""

import numpy
import sympy
from sympy.codegen import ast
from sympy.printing.c import C99CodePrinter
from sympy.printing.codeprinter import CodePrinter
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import AbstractPythonCodePrinter, _print_known_const, _print_known_func


def fold_constants(expr: sympy.Expr, _folded: dict | None = None) -> sympy.Expr:
    """Replace constant subexpressions (2159/5000, sqrt(2)/2, pi/4) by one Float each.

    Integers stay integers and exponents stay exact, so x**(1/2) still prints as sqrt(x).
    Shared subtrees are folded once (the DH chain is a DAG far smaller than its tree).
    """
    folded = {} if _folded is None else _folded
    if expr not in folded:
        if expr.is_number:
            folded[expr] = expr if expr.is_Integer else sympy.Float(expr.evalf(30), 30)
        elif expr.is_Atom:
            folded[expr] = expr
        elif expr.is_Pow:
            folded[expr] = sympy.Pow(fold_constants(expr.base, folded), expr.exp)
        else:
            folded[expr] = expr.func(*(fold_constants(arg, folded) for arg in expr.args))
    return folded[expr]


def float_literal(value: sympy.Expr) -> str:
    """Shortest decimal that reads back as the nearest double to `value`."""
    return repr(float(value))


class PythonPrinter(NumPyPrinter):
    """numpy code over batched inputs."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False})

    def _print_Float(self, expr):
        return float_literal(expr)


C_REAL_TYPES = {"double": ast.float64, "float": ast.float32}
_FLOAT_MAX = float(numpy.finfo(numpy.float32).max)


class _Power(sympy.Function):
    """`base**n` for a small integer n >= 2, printed in C as `(base*base*...)` rather than `pow()`.

    sympy's `create_expand_pow_optimization` does the same with an `UnevaluatedExpr`, which
    is not commutative, so its reciprocals print as `y*1.0/(x*x)` instead of `y/(x*x)`.
    """


def expand_integer_powers(expr: sympy.Expr, limit: int = 8) -> sympy.Expr:
    """x**2 -> _Power(x, 2), x**-3 -> 1/_Power(x, 3) (up to `limit`); other powers unchanged."""
    return expr.replace(lambda e: e.is_Pow and e.exp.is_Integer and 2 <= abs(e.exp) <= limit,
                        lambda e: _Power(e.base, abs(e.exp)) ** sympy.sign(e.exp))


class CPrinter(C99CodePrinter):
    """C99 for `double` or `float` builds.

    sympy's printer with `real` aliased to the build's type prints the type's functions
    (`sinf`, `atan2f`) and literal suffix (`F`), so a float build has no double promotion;
    unsupported nodes raise (`strict`). Overrides: literals, integer powers (`x*x`, never
    `pow()`), and `x**(-1/2)`. Constants are folded again at printing (sympy recreates
    `sqrt(2)` from `sqrt(2*x**2)` after CSE), and no math macro is printed: `M_SQRT2` and
    `M_PI` are POSIX, not C99.
    """

    def __init__(self, real: str):
        if real not in C_REAL_TYPES:
            raise ValueError(f"real must be one of {', '.join(C_REAL_TYPES)}, got {real!r}")
        self.real = real
        super().__init__({"type_aliases": {ast.real: C_REAL_TYPES[real]}, "strict": True, "math_macros": {}})

    def doprint(self, expr, assign_to=None):
        return super().doprint(expand_integer_powers(fold_constants(expr)), assign_to)

    def _print_Float(self, expr):
        """Shortest literal that reads back as the nearest value of the build's type."""
        if self.real == "float":
            if not abs(float(expr)) <= _FLOAT_MAX:
                raise ValueError(f"constant {float(expr)!r} is out of the range of float")
            return str(numpy.float32(float(expr))) + "F"
        return float_literal(expr)

    def _print__Power(self, expr):
        base, exponent = expr.args
        factor = self.parenthesize(base, PRECEDENCE["Mul"], strict=True)
        return "(" + "*".join([factor] * int(exponent)) + ")"

    def _print_Pow(self, expr):
        """`1.0/sqrt(x)` rather than sympy's `pow(x, -1.0/2.0)`."""
        if expr.exp == -sympy.S.Half:
            return f"{self._print(sympy.Float(1))}/{self._print(sympy.sqrt(expr.base))}"
        return super()._print_Pow(expr)


class CasadiPrinter(AbstractPythonCodePrinter):
    """Python building CasADi SX expressions: `casadi.cos(q1)`, `casadi.sqrt(t3)`.

    Only the functions CasADi has are known; anything else (Piecewise, Min, relations...)
    raises instead of printing Python that would not build an expression graph.
    """

    _module = "casadi"
    _kf = {name: f"casadi.{function}" for name, function in {
        "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
        "atan2": "atan2", "sinh": "sinh", "cosh": "cosh", "tanh": "tanh", "asinh": "asinh",
        "acosh": "acosh", "atanh": "atanh", "exp": "exp", "log": "log", "Abs": "fabs",
        "sign": "sign", "floor": "floor", "ceiling": "ceil", "erf": "erf",
    }.items()}
    _kc = {"Pi": "casadi.pi"}

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False, "strict": True})

    def _print_Float(self, expr):
        return float_literal(expr)

    def _print_Pow(self, expr, rational=False):
        return self._hprint_Pow(expr, rational=rational, sqrt="casadi.sqrt")

    _print_Piecewise = CodePrinter._print_not_supported
    _print_ITE = CodePrinter._print_not_supported
    _print_Relational = CodePrinter._print_not_supported
    _print_Mod = CodePrinter._print_not_supported
    _print_Sum = CodePrinter._print_not_supported


for _name in CasadiPrinter._kf:
    setattr(CasadiPrinter, f"_print_{_name}", _print_known_func)
for _name in CasadiPrinter._kc:
    setattr(CasadiPrinter, f"_print_{_name}", _print_known_const)
