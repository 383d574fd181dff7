"""A node of the value graph (`graph.py`): its kinds, its numbers (exact, or folded from
sympy's floats and irrationals), the Node with the arithmetic that builds on its graph, and its
value in floats or numpy arrays (`evaluate`), with which the graph decides comparisons of
constants and the analysis and the tests read a node's number.
"""

import math
import operator
from dataclasses import dataclass
from fractions import Fraction

from jacgen.model.tolerance_symbols import TOLERANCE_SYMBOLS, TOLERANCES

# The kinds of node. A number's value is an int, a Fraction (an exact rational, as sympy's
# Rational), a Folded (a constant folded from sympy's floats and irrationals, see Folded) or, as
# a power's exponent, a sympy Rational; a symbol's is its sympy Symbol; a call's the function's
# name (sympy's class name: sin, atan2, Abs, Floor, ...); a relation's its operator (">=", ...).
# Every number but a small integer prints as a literal of the build's real type.
NUMBER, SYMBOL, TRUTH = "number", "symbol", "truth"
ADD, MUL, POW, CALL, SELECT = "add", "mul", "pow", "call", "select"
RELATION, AND, OR, NOT, FINITE = "relation", "and", "or", "not", "finite"
# A repeated body (`Kernel`): a REPEAT's value is (kernel, count), its args the state it starts
# from; a PART's value is an index into the final state of its one arg, a REPEAT.
REPEAT, PART = "repeat", "part"
FOLDED_DIGITS = 30
BOOLEAN_KINDS = frozenset((TRUTH, RELATION, AND, OR, NOT, FINITE))

RELATIONS = {">=": operator.ge, ">": operator.gt, "<=": operator.le, "<": operator.lt, "==": operator.eq,
             "!=": operator.ne}
# The functions `evaluate` calls, by call name, and how it adds (in floats: fsum, rounded once).
MATH = {"sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos, "atan": math.atan,
        "atan2": math.atan2, "exp": math.exp, "log": math.log, "Abs": abs, "Floor": math.floor, "Ceiling": math.ceil,
        ADD: math.fsum}


class Folded(Fraction):
    """A constant folded from sympy's floats and irrationals (2159/5000 * sqrt(2), pi / 4): its
    value to FOLDED_DIGITS digits, held exactly, so that constants added or multiplied together
    round once, when printed. Arithmetic with one stays folded, as with sympy's Float: 0.5 * 2
    is 1.0, not the integer 1."""

    __slots__ = ()


def number_of(value, folded: bool):
    """The result of arithmetic on numbers: Folded if an operand was, else exact (an integer as an int)."""
    if folded:
        return Folded(value)
    return int(value) if isinstance(value, Fraction) and value.denominator == 1 else value


class Node:
    """One value of the graph; build it with `Graph.node` (or the constructors), never directly.
    Arithmetic with another node or a number builds on the node's graph (`Graph.add`, `mul`,
    `power`), so an algorithm written with + - * / ** runs on nodes as on sympy values."""

    __slots__ = ("kind", "args", "value", "graph", "index", "_free")

    # Graph: jacgen.model.graph's, which imports this module (so it is not imported here).
    def __init__(self, kind: str, args: tuple, value, graph: "Graph | None" = None, index: int = 0):  # noqa: F821
        self.kind, self.args, self.value, self.graph, self.index, self._free = kind, args, value, graph, index, None

    def __add__(self, other):
        return self.graph.add(self, self.graph.value(other))

    def __radd__(self, other):
        return self.graph.add(self.graph.value(other), self)

    def __sub__(self, other):
        return self.graph.add(self, self.graph.negate(self.graph.value(other)))

    def __rsub__(self, other):
        return self.graph.add(self.graph.value(other), self.graph.negate(self))

    def __mul__(self, other):
        return self.graph.mul(self, self.graph.value(other))

    def __rmul__(self, other):
        return self.graph.mul(self.graph.value(other), self)

    def __neg__(self):
        return self.graph.negate(self)

    def __truediv__(self, other):
        return self.graph.mul(self, self.graph.power(self.graph.value(other), -1))

    def __rtruediv__(self, other):
        return self.graph.mul(self.graph.value(other), self.graph.power(self, -1))

    def __pow__(self, exponent):
        return self.graph.power(self, exponent)

    @property
    def free_symbols(self) -> frozenset:
        """The sympy Symbols the value reads (the tolerances included)."""
        if self._free is None:
            if self.kind == SYMBOL:
                self._free = frozenset((self.value,))
            else:
                self._free = frozenset().union(*(arg.free_symbols for arg in self.args))
        return self._free

    @property
    def constant(self) -> bool:
        """Whether the value reads nothing but numbers and the tolerances."""
        return self.free_symbols <= TOLERANCE_SYMBOLS

    @property
    def boolean(self) -> bool:
        """A truth value (an `int` in C, a bool array in numpy)."""
        return self.kind in BOOLEAN_KINDS

    def contains(self, kind: str, _seen: set | None = None) -> bool:
        """Whether a node of `kind` is among this one and those it reads."""
        seen = set() if _seen is None else _seen
        seen.add(self)
        return self.kind == kind or any(arg.contains(kind, seen) for arg in self.args if arg not in seen)

    def __repr__(self):
        return f"{self.kind}({self.value!r}, {len(self.args)} args)" if self.args else f"{self.kind}({self.value!r})"


@dataclass(frozen=True, eq=False)
class Kernel:
    """A body that runs a fixed number of times, or that several places call: one step,
    straight-line code (`body`, a lowered Body) from the state (`state`, symbols its body
    reads) to the next state, or a call's results (its outputs). A REPEAT node runs it from a
    starting state; every backend prints it once per file, as a loop (`Lowering.repeated`,
    `Lowering.called` and `Lowering.kernel` build it)."""

    name: str
    summary: str  # what one step does, for the reader of the generated code
    state: tuple  # sympy Symbols
    body: object  # lowering.Body


def is_zero(node: Node) -> bool:
    """The exact number 0 (a structural zero of a matrix)."""
    return node.kind == NUMBER and node.value == 0 and not isinstance(node.value, Folded)


def negative_coefficient(node: Node) -> bool:
    """A negative number, or a product whose number is negative."""
    coefficient = node.args[0] if node.kind == MUL else node
    return coefficient.kind == NUMBER and coefficient.value < 0


# -- numbers ----------------------------------------------------------------------------------------
TOLERANCE_VALUES = {real: {symbol: float(value) for symbol, value in numbers.items()}
                    for real, numbers in TOLERANCES.items()}


def _power(base, exponent):
    """base ** exponent as IEEE arithmetic has it (C's pow): 0 to a negative power is inf."""
    if isinstance(base, float) and base == 0 and isinstance(exponent, (int, float)) and exponent < 0:
        return math.copysign(math.inf, base) if float(exponent).is_integer() and int(exponent) % 2 else math.inf
    return base ** exponent


def evaluate(node: Node, values: dict, functions: dict = MATH, _done: dict | None = None):
    """The value of `node`, `values` giving each symbol's: in floats (truth values as bools),
    or with `functions` of another library (numpy's, over arrays: arithmetic and calls only)."""
    done = {} if _done is None else _done
    if node in done:
        return done[node]
    kind, args = node.kind, node.args
    if kind == NUMBER:
        result = float(node.value)
    elif kind == SYMBOL:
        result = values[node.value]
    elif kind == TRUTH:
        result = node.value
    elif kind == REPEAT:
        kernel, count = node.value
        result = [evaluate(arg, values, functions, done) for arg in args]
        for _ in range(count):
            step, step_done = dict(values) | dict(zip(kernel.state, result)), {}
            for symbol, value in kernel.body.definitions:
                step[symbol] = evaluate(value, step, functions, step_done)
            result = [evaluate(output, step, functions, step_done) for output in kernel.body.outputs]
    elif kind == PART:
        result = evaluate(args[0], values, functions, done)[node.value]
    elif kind == SELECT:  # the value chosen only: a side not taken may divide by 0
        chosen = next((value for condition, value in zip(args[:-1:2], args[1:-1:2])
                       if evaluate(condition, values, functions, done)), args[-1])
        result = evaluate(chosen, values, functions, done)
    else:
        operands = [evaluate(arg, values, functions, done) for arg in args]
        if kind == ADD:
            result = functions[ADD](operands)
        elif kind == MUL:
            result = math.prod(operands)
        elif kind == POW:
            result = _power(*operands)
        elif kind == CALL:
            result = functions[node.value](*operands)
        elif kind == RELATION:
            result = RELATIONS[node.value](*operands)
        elif kind == AND:
            result = all(operands)
        elif kind == OR:
            result = any(operands)
        elif kind == NOT:
            result = not operands[0]
        else:  # FINITE
            result = math.isfinite(operands[0])
    done[node] = result
    return result
