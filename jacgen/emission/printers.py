"""Expression printers: one walk over a lowered Body's nodes, with the rules of each language.

A Body is nodes of the value graph (`graph.py`): sums, products, powers, the math functions,
selects, comparisons, and/or/not, `isfinite`, and the runs of a kernel (a repeated body, which
the backends define once per file as a function that loops) and the entries of their state.
`Printer` walks them once each (the text of a
node is kept for every later reader of it) and prints the arguments of sums and products in
the order the graph keeps them, never by hash: the text is deterministic and nothing is
re-sorted or rebuilt while printing. Each language is a subclass that says how a function,
a literal, a power, a select and the logic read.

Every number that is not a small integer (EXACT_INTEGER), and every subexpression of the IK's
tolerances alone (EPS, TINY, RANK, replaced by the numbers of the build's real type), prints
as one literal: the shortest decimal that reads back as the same value of that type.
"""

import sympy

from jacgen.model import node as kinds
from jacgen.model.node import TOLERANCE_VALUES, Node, evaluate
from jacgen.emission.lowering import Body
from jacgen.model.tolerance_symbols import TOLERANCE_SYMBOLS

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
        self.tolerances = TOLERANCE_VALUES[real]
        self._printed: dict[Node, tuple[str, int]] = {}
        self._names: dict[sympy.Symbol, str] = {}  # the temporaries of the Body being printed

    def doprint(self, node: Node) -> str:
        return self._print(node)[0]

    def body(self, body: Body) -> tuple[list[str], list[str]]:
        """The texts of a Body's definitions and outputs, its temporaries by their names."""
        self._names, self._printed = body.names, {}
        try:
            return [self.doprint(value) for _, value in body.definitions], [self.doprint(e) for e in body.outputs]
        finally:
            self._names, self._printed = {}, {}

    def _print(self, node: Node) -> tuple[str, int]:
        """(text, binding strength), once per node."""
        printed = self._printed.get(node)
        if printed is None:
            printed = self._printed[node] = self._node(node)
        return printed

    def _operand(self, node: Node, strength: int) -> str:
        """The text of `node`, in parentheses when it binds more loosely than `strength`."""
        text, binding = self._print(node)
        return f"({text})" if binding < strength else text

    def _node(self, node: Node) -> tuple[str, int]:
        kind = node.kind
        if kind == kinds.SYMBOL and node.value not in TOLERANCE_SYMBOLS:
            return self._names.get(node.value, node.value.name), ATOM
        if kind == kinds.REPEAT:
            kernel, count = node.value
            return self.repeat(kernel.name, count, [self._state(arg) for arg in node.args]), ATOM
        if kind == kinds.PART and not node.constant:
            return self.part(self._print(node.args[0])[0], node.value), ATOM
        if kind == kinds.NUMBER and isinstance(node.value, int) and abs(node.value) <= EXACT_INTEGER:
            return str(node.value), SUM if node.value < 0 else ATOM
        if node.boolean:
            if node.constant:
                return self.truth(bool(evaluate(node, self.tolerances))), ATOM
            return self._boolean(node)
        if node.constant:
            text = self.literal(float(evaluate(node, self.tolerances)))
            return text, SUM if text.startswith("-") else ATOM
        if kind == kinds.ADD:
            return self._sum(node.args), SUM
        if kind == kinds.MUL:
            return self._product(node.args)
        if kind == kinds.POW:
            return self._power(node.args[0], node.args[1].value)
        if kind == kinds.SELECT:
            return self._select(list(zip(node.args[:-1:2], node.args[1:-1:2])), node.args[-1]), ATOM
        if kind != kinds.CALL or node.value not in self.functions:
            raise ValueError(f"unsupported in {type(self).__name__}: {node.value}")
        return f"{self.functions[node.value]}({', '.join(self._print(arg)[0] for arg in node.args)})", ATOM

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
        for factor in sorted(factors, key=lambda factor: not factor.constant):  # numbers first
            if factor.kind == kinds.POW and factor.args[1].value < 0 and not factor.constant:
                denominator.append(self._power(factor.args[0], -factor.args[1].value))
                continue
            number = factor.constant
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

    def _power(self, base: Node, exponent) -> tuple[str, int]:
        """base ** exponent (a sympy Rational)."""
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
        numbers = value.kind == kinds.NUMBER and not rest and otherwise.kind == kinds.NUMBER
        return self.select(self.doprint(condition), self.doprint(value), other, numbers)

    def _boolean(self, node: Node) -> tuple[str, int]:
        if node.kind in (kinds.AND, kinds.OR):
            return self.logic("And" if node.kind == kinds.AND else "Or", node.args), \
                AND if node.kind == kinds.AND else OR
        if node.kind == kinds.NOT:
            return self.negation(node.args[0]), ATOM
        if node.kind == kinds.FINITE:
            return self.finite(self.doprint(node.args[0])), ATOM
        if node.kind == kinds.RELATION:
            return self.relation(self.doprint(node.args[0]), node.value, self.doprint(node.args[1]))
        raise ValueError(f"unsupported in {type(self).__name__}: {node.kind}")

    def _state(self, node: Node) -> str:
        """An entry of a kernel's starting state."""
        return self.doprint(node)

    def number(self, value) -> str:
        """The literal of a template's constant (REACHED squared, 10)."""
        return self.literal(float(value))

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

    def repeat(self, kernel: str, count: int, state: list[str]) -> str:
        """The final state of `count` runs of `kernel` from `state`."""
        return f"_{kernel}({count}, ({', '.join(state)},))"

    def part(self, state: str, index: int) -> str:
        return f"{state}[{index}]"


# The functions the expressions use, by sympy's name, and their name in C99's math.h (numpy
# and CasADi use the same names, numpy's absolute value aside).
MATH_FUNCTIONS = {"sin": "sin", "cos": "cos", "tan": "tan", "asin": "asin", "acos": "acos", "atan": "atan",
                  "atan2": "atan2", "exp": "exp", "log": "log", "sqrt": "sqrt", "Abs": "fabs", "Floor": "floor",
                  "Ceiling": "ceil"}
