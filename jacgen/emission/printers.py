"""Expression printers: one walk over a lowered Body's nodes, with the rules of each language.

A Body holds few kinds of node: sums, products, powers, the math functions, selects, comparisons, and/or/not, `isfinite`. `Printer` walks them once each (the
text of a node is kept for every later reader of it) and prints the arguments of sums and
products in the order sympy stores them, which it sorts by structure, never by hash: the
text is deterministic and nothing is re-sorted or rebuilt while printing. Each language
is a subclass that says how a function, a literal, a power, a select and the logic read.

Every number that is not a small integer (EXACT_INTEGER), and every subexpression of the IK's tolerances alone
(EPS, TINY, RANK, replaced by the numbers of the build's real type), prints as one literal:
the shortest decimal that reads back as the same value of that type.
"""

import sympy

from jacgen.emission.lowering import Body, is_boolean
from jacgen.model.nodes import TOLERANCE_SYMBOLS, TOLERANCES, Select

# Integers up to this size print as integer literals (exact in float and double, and an `int`
# in C); larger ones as floating literals, which cannot overflow an integer type.
EXACT_INTEGER = 2**24

# Binding strength of what a node prints as: an operand binding more loosely than its
# operator is parenthesised.
ATOM, POWER, PRODUCT, SUM, RELATION, AND, OR = 1000, 60, 50, 40, 35, 30, 20


class Printer:
    """The rules every language shares: numbers, sums, products, function calls."""

    functions: dict[str, str]  # sympy's class name -> the function printed
    one = "1"  # the numerator of a reciprocal

    def __init__(self, real: str = "double"):
        self.tolerances = TOLERANCES[real]
        self._printed: dict[sympy.Basic, tuple[str, int]] = {}
        self._constants: dict[sympy.Basic, bool] = {}
        self._names: dict[sympy.Symbol, str] = {}  # the temporaries of the Body being printed

    def doprint(self, expr: sympy.Basic) -> str:
        return self._print(expr)[0]

    def body(self, body: Body) -> tuple[list[str], list[str]]:
        """The texts of a Body's definitions and outputs, its temporaries by their names."""
        self._names, self._printed = body.names, {}
        try:
            return [self.doprint(value) for _, value in body.definitions], [self.doprint(e) for e in body.outputs]
        finally:
            self._names, self._printed = {}, {}

    def _print(self, expr: sympy.Basic) -> tuple[str, int]:
        """(text, binding strength), once per node."""
        printed = self._printed.get(expr)
        if printed is None:
            printed = self._printed[expr] = self._node(expr)
        return printed

    def _operand(self, expr: sympy.Basic, strength: int) -> str:
        """The text of `expr`, in parentheses when it binds more loosely than `strength`."""
        text, binding = self._print(expr)
        return f"({text})" if binding < strength else text

    def _node(self, expr: sympy.Basic) -> tuple[str, int]:
        if expr.is_Symbol and expr not in TOLERANCE_SYMBOLS:
            return self._names.get(expr, expr.name), ATOM
        if expr.is_Integer and abs(expr) <= EXACT_INTEGER:
            return str(expr), SUM if expr < 0 else ATOM
        constant = self._constant(expr)
        if is_boolean(expr):
            if constant:
                expr = expr.xreplace(self.tolerances)
                return self.truth(bool(expr)), ATOM
            return self._boolean(expr)
        if constant:
            text = self.literal(float(expr.xreplace(self.tolerances)))
            return text, SUM if text.startswith("-") else ATOM
        if expr.is_Add:
            return self._sum(expr.args), SUM
        if expr.is_Mul:
            return self._product(expr.args)
        if expr.is_Pow:
            return self._power(expr.base, expr.exp)
        if isinstance(expr, Select):
            return self._select(expr.pairs, expr.args[-1]), ATOM
        name = type(expr).__name__
        if name not in self.functions:
            raise ValueError(f"unsupported in {type(self).__name__}: {name} ({expr})")
        return f"{self.functions[name]}({', '.join(self._print(arg)[0] for arg in expr.args)})", ATOM

    def _constant(self, expr: sympy.Basic) -> bool:
        """Whether `expr` reads nothing but numbers and tolerances, once per node."""
        constant = self._constants.get(expr)
        if constant is None:
            if expr.is_Symbol:
                constant = expr in TOLERANCE_SYMBOLS
            else:
                constant = expr.is_Atom or all(self._constant(arg) for arg in expr.args)
            self._constants[expr] = constant
        return constant

    def _sum(self, terms) -> str:
        text = []
        for term in terms:
            term_text = self._operand(term, SUM)
            if term_text.startswith("-"):
                text += ["-", term_text[1:]]
            else:
                text += ["+", term_text]
        return " ".join(text[1:]) if text[0] == "+" else "-" + " ".join(text[1:])

    def _product(self, factors) -> tuple[str, int]:
        """`-a*b/(c*d)`: a leading negative coefficient as the sign, powers with a negative
        exponent as the denominator."""
        sign, numerator, denominator = "", [], []
        for factor in sorted(factors, key=lambda factor: not self._constant(factor)):  # numbers first
            if factor.is_Pow and factor.exp.is_Rational and factor.exp < 0 and not self._constant(factor):
                denominator.append(self._power(factor.base, -factor.exp))
                continue
            number = self._constant(factor)
            text = self._print(factor)[0] if number else self._operand(factor, PRODUCT)
            if number and text.startswith("-"):
                sign, text = "-", text[1:]
            if text != "1":
                numerator.append(text)
        text = "*".join(numerator) or "1"
        if len(denominator) == 1:
            base, binding = denominator[0]
            text += "/" + (f"({base})" if binding <= PRODUCT else base)
        elif denominator:
            text += "/(" + "*".join(f"({t})" if b < PRODUCT else t for t, b in denominator) + ")"
        return sign + text, SUM if sign else PRODUCT

    def _power(self, base: sympy.Expr, exponent: sympy.Rational) -> tuple[str, int]:
        if exponent == 1:
            return self._print(base)
        if exponent == sympy.S.Half:
            return f"{self.functions['sqrt']}({self.doprint(base)})", ATOM
        if exponent < 0:
            text, binding = self._power(base, -exponent)
            return f"{self.one}/" + (f"({text})" if binding <= PRODUCT else text), PRODUCT
        return self.power(base, exponent)

    def _select(self, pairs, otherwise) -> str:
        """Nested selects, one per condition."""
        (condition, value), *rest = pairs
        other = self._select(rest, otherwise) if rest else self.doprint(otherwise)
        numbers = value.is_number and not rest and otherwise.is_number
        return self.select(self.doprint(condition), self.doprint(value), other, numbers)

    def _boolean(self, expr) -> tuple[str, int]:
        name = type(expr).__name__
        if name in ("And", "Or"):
            return self.logic(name, expr.args), AND if name == "And" else OR
        if name == "Not":
            return self.negation(expr.args[0]), ATOM
        if name == "IsFinite":
            return self.finite(self.doprint(expr.args[0])), ATOM
        if isinstance(expr, sympy.core.relational.Relational):
            return self.relation(self.doprint(expr.lhs), expr.rel_op, self.doprint(expr.rhs))
        raise ValueError(f"unsupported in {type(self).__name__}: {name} ({expr})")

    # What each language says.
    def literal(self, value: float) -> str:
        return repr(value)

    def truth(self, value: bool) -> str:
        return repr(value)

    def power(self, base: sympy.Expr, exponent: sympy.Rational) -> tuple[str, int]:
        power = str(exponent) if exponent.is_Integer else repr(float(exponent))
        return f"{self._operand(base, POWER + 1)}**{power}", POWER

    def relation(self, lhs: str, operator: str, rhs: str) -> tuple[str, int]:
        return f"({lhs} {operator} {rhs})", ATOM

    def select(self, condition: str, value: str, otherwise: str, numbers: bool) -> str:
        raise NotImplementedError

    def logic(self, name: str, operands) -> str:
        raise NotImplementedError

    def negation(self, operand) -> str:
        raise NotImplementedError

    def finite(self, text: str) -> str:
        raise NotImplementedError


# The functions the expressions use, by sympy's name, and their name in C99's math.h (numpy
# and CasADi use the same names, numpy's absolute value aside).
MATH_FUNCTIONS = {"sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
                  "atan2": "atan2", "exp": "exp", "log": "log", "sqrt": "sqrt", "Abs": "fabs", "Floor": "floor",
                  "Ceiling": "ceil"}
