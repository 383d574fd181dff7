"""Expression printers: sympy's own (numpy, C99, and a small CasADi one), each override documented.

Constants are folded first (`fold_constants`), so every number that is not an integer
is a single Float, printed as the shortest decimal that reads back as the same double
(the same float, in float C builds). The IK's tolerances EPS and TINY are replaced by the
numbers of the build's real type.
"""

import numpy
import sympy
from sympy.codegen import ast
from sympy.printing.c import C99CodePrinter
from sympy.printing.codeprinter import CodePrinter
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE
from sympy.printing.pycode import AbstractPythonCodePrinter, _print_known_const, _print_known_func

from .subproblems import TOLERANCES


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
            base = fold_constants(expr.base, folded)
            folded[expr] = expr if base is expr.base else sympy.Pow(base, expr.exp)
        else:  # rebuilt only when an argument changed: a rebuild evaluates (Piecewise, floor, relations)
            args = tuple(fold_constants(arg, folded) for arg in expr.args)
            changed = any(new is not old and new != old for new, old in zip(args, expr.args))
            folded[expr] = expr.func(*args) if changed else expr
    return folded[expr]


def float_literal(value: sympy.Expr) -> str:
    """Shortest decimal that reads back as the nearest double to `value`."""
    return repr(float(value))


def _selects(printer, expr, select: str, real_array: str = "{}") -> str:
    """`select(condition, value, otherwise)` nested for each pair of a Piecewise; when both
    sides are numbers, the value as `real_array`."""
    (value, condition), *rest = expr.args
    otherwise = rest[0][0] if len(rest) == 1 and rest[0][1] == sympy.true else sympy.Piecewise(*rest)
    first = printer._print(value)
    if value.is_number and otherwise.is_number:
        first = real_array.format(first)
    return f"{select}({printer._print(condition)}, {first}, {printer._print(otherwise)})"


class PythonPrinter(NumPyPrinter):
    """Python over the array API namespace `xp` of the inputs (numpy, JAX, PyTorch), batched.

    Functions take their standard names (`xp.atan2`, not numpy's `arctan2`). A select is
    `xp.where`, both sides computed (the generated function ignores numpy's floating-point
    warnings of the side not taken). A select of two numbers makes the first an array of the
    function's `dtype`: otherwise PyTorch makes it float32, and numpy an integer array that
    turns float32 arithmetic into float64 (the context makes statuses integers again).
    """

    _module = "xp"
    _kf = {name: f"xp.{function}" for name, function in {
        "sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
        "atan2": "atan2", "exp": "exp", "log": "log", "sqrt": "sqrt", "Abs": "abs", "sign": "sign",
        "floor": "floor", "ceiling": "ceil", "Floor": "floor",
    }.items()}

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False, "order": "none"})
        self._kf = dict(type(self)._kf)  # NumPyPrinter merges in Python's math names

    def doprint(self, expr, assign_to=None):
        return super().doprint(expr.xreplace(TOLERANCES["double"]), assign_to)

    def _print_Float(self, expr):
        return float_literal(expr)

    def _print_Piecewise(self, expr):
        return _selects(self, expr, "xp.where", "xp.asarray({}, dtype=dtype)")

    def _print_And(self, expr):
        return " & ".join(self.parenthesize(a, PRECEDENCE["BitwiseAnd"] + 1) for a in expr.args)

    def _print_Or(self, expr):
        return " | ".join(self.parenthesize(a, PRECEDENCE["BitwiseOr"] + 1) for a in expr.args)

    def _print_IsFinite(self, expr):
        return f"xp.isfinite({self._print(expr.args[0])})"

    _print_Floor = _print_known_func


C_REAL_TYPES = {"double": ast.float64, "float": ast.float32}
_FLOAT_MAX = float(numpy.finfo(numpy.float32).max)


class _Power(sympy.Function):
    """`base**n` for a small n >= 3/2, integer or half-integer, printed in C as
    `(base*base*...)`, with `sqrt(base)*` in front for a half, rather than `pow()`.

    sympy's `create_expand_pow_optimization` does the same with an `UnevaluatedExpr`, which
    is not commutative, so its reciprocals print as `y*1.0/(x*x)` instead of `y/(x*x)`.
    """


def expand_integer_powers(expr: sympy.Expr, limit: int = 8) -> sympy.Expr:
    """x**2 -> _Power(x, 2), x**-3 -> 1/_Power(x, 3), x**(-3/2) -> 1/_Power(x, 3/2) (up to
    `limit`); other powers unchanged."""
    return expr.replace(lambda e: e.is_Pow and e.exp.is_Rational and e.exp.q in (1, 2)
                        and sympy.Rational(3, 2) <= abs(e.exp) <= limit,
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
        self._folded = {}  # one fold per shared subtree across everything this printer prints
        super().__init__({"type_aliases": {ast.real: C_REAL_TYPES[real]}, "strict": True, "math_macros": {},
                          "order": "none", "user_functions": {"Floor": "floor"}})

    _print_Floor = C99CodePrinter._print_math_func

    def doprint(self, expr, assign_to=None):
        folded = fold_constants(expr.xreplace(TOLERANCES[self.real]), self._folded)
        return super().doprint(expand_integer_powers(folded), assign_to)

    def _print_BooleanTrue(self, expr):
        return "1"

    def _print_BooleanFalse(self, expr):
        return "0"

    def _print_Or(self, expr):
        """Every operand that is not an atom in parentheses (gcc's -Wparentheses)."""
        return " || ".join(self._print(a) if a.is_Atom else f"({self._print(a)})" for a in expr.args)

    def _print_Piecewise(self, expr):
        """`(condition ? value : otherwise)` on one line."""
        (value, condition), *rest = expr.args
        otherwise = rest[0][0] if len(rest) == 1 and rest[0][1] == sympy.true else sympy.Piecewise(*rest)
        return f"({self._print(condition)} ? {self._print(value)} : {self._print(otherwise)})"

    def _print_IsFinite(self, expr):
        return f"isfinite({self._print(expr.args[0])})"

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
        root = [self._print(sympy.sqrt(base))] if not exponent.is_Integer else []
        return "(" + "*".join(root + [factor] * int(exponent)) + ")"

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
        "sign": "sign", "floor": "floor", "ceiling": "ceil", "erf": "erf", "Floor": "floor",
    }.items()}
    _kc = {"Pi": "casadi.pi"}

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "allow_unknown_functions": False, "strict": True,
                          "order": "none"})

    def _print_Float(self, expr):
        return float_literal(expr)

    def doprint(self, expr, assign_to=None):
        return super().doprint(expr.xreplace(TOLERANCES["double"]), assign_to)

    def _print_Pow(self, expr, rational=False):
        return self._hprint_Pow(expr, rational=rational, sqrt="casadi.sqrt")

    def _print_Piecewise(self, expr):
        return _selects(self, expr, "casadi.if_else")

    def _print_Relational(self, expr):
        return f"({self._print(expr.lhs)} {expr.rel_op} {self._print(expr.rhs)})"

    def _print_And(self, expr):
        return self._logic("casadi.logic_and", expr.args)

    def _print_Or(self, expr):
        return self._logic("casadi.logic_or", expr.args)

    def _logic(self, function: str, args) -> str:
        text = self._print(args[0])
        for arg in args[1:]:
            text = f"{function}({text}, {self._print(arg)})"
        return text

    def _print_Not(self, expr):
        return f"casadi.logic_not({self._print(expr.args[0])})"

    def _print_IsFinite(self, expr):
        """NaN < inf is false, as is inf < inf."""
        return f"(casadi.fabs({self._print(expr.args[0])}) < casadi.inf)"

    _print_ITE = CodePrinter._print_not_supported
    _print_Mod = CodePrinter._print_not_supported
    _print_Sum = CodePrinter._print_not_supported


for _name in CasadiPrinter._kf:
    setattr(CasadiPrinter, f"_print_{_name}", _print_known_func)
for _name in CasadiPrinter._kc:
    setattr(CasadiPrinter, f"_print_{_name}", _print_known_const)
