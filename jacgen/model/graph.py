"""The value graph: the generated code's expressions as interned nodes (`node.py`: what a
node is, and its value in numbers).

A node is built once per graph (one per robot): equal values are the same object, so a
node's identity is its value, hashing is free and a shared subexpression is one node however
many functions read it. The closed-form IK, its limits and `ik_nearest` (`ik.py`,
`subproblems.py`, `ik_limits.py`) and the inverse differential kinematics (`differential.py`)
build on the graph, with nodes' arithmetic and the graph's functions; the chain, the
Jacobians and the singularity functions are still built in sympy, and `Graph.convert` takes
their values over once each, every constant subexpression folded to one number (integers and
rationals stay exact, exponents too). The lowering (`lowering.py`: CSE, constants, the
operation count) and the printers work on the graph alone.

A sum's terms and a product's factors are ordered by when they were built (a*b and b*a are
one node), with the number first, so the output does not depend on hashing; a sum or product
is evaluated as sympy's would be (numbers combined, equal terms and bases collected).
"""

import math
import operator
from fractions import Fraction

import numpy
import sympy
from sympy.logic.boolalg import Boolean

from jacgen.model.node import (ADD, AND, CALL, FINITE, FOLDED_DIGITS, MUL, NOT, NUMBER, OR, POW, RELATION, RELATIONS,
                               SELECT, SYMBOL, TOLERANCE_VALUES, TRUTH, Folded, Node, evaluate, negative_coefficient,
                               number_of)

REVERSED = {">=": "<=", ">": "<", "<=": ">=", "<": ">", "==": "==", "!=": "!="}
NEGATED = {">=": "<", ">": "<=", "<=": ">", "<": ">=", "==": "!=", "!=": "=="}
# sympy's function of each call whose name is not sympy's own, to fold a call of numbers.
SYMPY_CALLS = {"Floor": sympy.floor, "Ceiling": sympy.ceiling}
BOOLEANS = {sympy.And: AND, sympy.Or: OR, sympy.Not: NOT}  # in sympy's values taken over


class Graph:
    """The interned nodes of one robot, and sympy's values taken over once each."""

    def __init__(self):
        self._nodes: dict[tuple, Node] = {}
        self._converted: dict[sympy.Basic, Node] = {}
        self.true, self.false = self.node(TRUTH, (), True), self.node(TRUTH, (), False)
        self.minus_one = self.number(-1)

    def node(self, kind: str, args: tuple = (), value=None) -> Node:
        """The node of `kind`, `args` and `value`, built on first use (args as given: no evaluation)."""
        key = (kind, value, type(value), args)
        node = self._nodes.get(key)
        if node is None:
            node = self._nodes[key] = Node(kind, args, value, self, len(self._nodes))
        return node

    def number(self, value) -> Node:
        return self.node(NUMBER, (), value)

    def symbol(self, symbol: sympy.Symbol) -> Node:
        return self.node(SYMBOL, (), symbol)

    def truth(self, value: bool) -> Node:
        return self.true if value else self.false

    def value(self, value) -> Node:
        """A node, a Python number (a float as its exact binary value) or a sympy value as a node."""
        if isinstance(value, Node):
            return value
        if isinstance(value, bool):
            return self.truth(value)
        if isinstance(value, int):
            return self.number(value)
        if isinstance(value, float):
            return self.number(Folded(value))
        if isinstance(value, Fraction):
            return self.number(number_of(value, isinstance(value, Folded)))
        return self.convert(value)

    def values(self, values):
        """`values` (a sympy Matrix or nested lists) as an array of nodes, for + - * @ and .T."""
        values = values.tolist() if isinstance(values, sympy.MatrixBase) else values
        return elementwise(self.value, numpy.array(values, dtype=object))

    # -- the functions an algorithm calls ---------------------------------------------------------
    def power(self, base: Node, exponent) -> Node:
        """base ** exponent (a rational): a number's folded; an integer power of a product is
        the product of its factors' powers, and of a power, one power; the square root of an
        even power of x is a power of |x| (as sympy's, every symbol being real)."""
        exponent = sympy.Rational(exponent)
        if exponent == 1:
            return base
        if base.kind == NUMBER and not (base.value == 0 and exponent < 0):
            return self._number_power(base.value, exponent)
        if exponent.q == 1 and base.kind == MUL:
            return self.mul(*(self.power(factor, exponent) for factor in base.args))
        if base.kind == POW and (exponent.q == 1 or (exponent == sympy.S.Half and base.args[1].value % 2 == 0)):
            if exponent.q == 1:
                return self.power(base.args[0], base.args[1].value * exponent)
            return self.power(self.call("Abs", base.args[0]), base.args[1].value / 2)  # sqrt(x^2) = |x|, x real
        return self.node(POW, (base, self.number(exponent)))

    def _number_power(self, base, exponent: sympy.Rational) -> Node:
        """A number to a rational power, exactly (Folded if the base is)."""
        if exponent.q == 1:
            return self.number(number_of(Fraction(base) ** int(exponent), isinstance(base, Folded)))
        root = self.convert(sympy.Rational(Fraction(base).numerator, Fraction(base).denominator) ** exponent)
        return self.number(number_of(root.value, isinstance(base, Folded)))

    def sqrt(self, value: Node) -> Node:
        return self.power(value, sympy.S.Half)

    def call(self, name: str, *args: Node) -> Node:
        """name(args) of MATH's functions: of numbers, folded exactly by sympy; |-x| is |x|."""
        if all(arg.kind == NUMBER for arg in args):
            folded = SYMPY_CALLS.get(name) or getattr(sympy, name)
            return self.convert(folded(*(sympy.Rational(arg.value) for arg in args)))
        if name == "Abs" and negative_coefficient(args[0]):  # |-x| = |x|
            return self.node(CALL, (self.negate(args[0]),), name)
        return self.node(CALL, args, name)

    def negation(self, condition: Node) -> Node:
        """not condition: a truth value flipped, a comparison reversed, else a Not node."""
        if condition.kind == TRUTH:
            return self.truth(not condition.value)
        if condition.kind == RELATION:
            return self.relation(NEGATED[condition.value], *condition.args)
        if condition.kind == NOT:
            return condition.args[0]
        return self.node(NOT, (condition,))

    def finite(self, value: Node) -> Node:
        return self.node(FINITE, (value,))

    # -- sympy's values, once each ------------------------------------------------------------------
    def convert(self, expr: sympy.Basic) -> Node:
        """`expr` as a node, its constant subexpressions (2159/5000, sqrt(2)/2, pi/4) folded to
        one number each: integers stay integers, exponents exact, so x**(1/2) prints as sqrt(x)."""
        if isinstance(expr, Node):
            return expr
        node = self._converted.get(expr)
        if node is None:
            node = self._converted[expr] = self._convert(expr)
        return node

    def _convert(self, expr: sympy.Basic) -> Node:
        if expr.is_Symbol:
            return self.symbol(expr)
        if isinstance(expr, Boolean) and not isinstance(expr, sympy.Expr):
            if expr is sympy.true or expr is sympy.false:
                return self.truth(bool(expr))
            if expr.is_Relational:
                return self.node(RELATION, (self.convert(expr.lhs), self.convert(expr.rhs)), expr.rel_op)
            kind = BOOLEANS.get(type(expr))
            if kind is None:
                raise ValueError(f"unsupported in generated code: {type(expr).__name__} ({expr})")
            return self.node(kind, tuple(self.convert(arg) for arg in expr.args))
        if expr.is_number:
            if expr.is_Rational:
                return self.number(number_of(Fraction(int(expr.p), int(expr.q)), False))
            return self.number(Folded(str(expr.evalf(FOLDED_DIGITS))))
        if expr.is_Pow:
            if not expr.exp.is_Rational:
                raise ValueError(f"unsupported in generated code: a power to {expr.exp}")
            return self.node(POW, (self.convert(expr.base), self.number(expr.exp)))
        if expr.is_Add or expr.is_Mul:  # numbers folded one by one, then added or multiplied exactly
            args = [self.convert(arg) for arg in expr.args]
            return self.add(*args) if expr.is_Add else self.mul(*args)
        args = tuple(self.convert(arg) for arg in expr.args)
        if isinstance(expr, sympy.Function):
            return self.node(CALL, args, type(expr).__name__)
        raise ValueError(f"unsupported in generated code: {type(expr).__name__} ({expr})")

    # -- building, with sympy's evaluation where values combine ---------------------------------------
    def add(self, *terms: Node) -> Node:
        """The sum: nested sums flattened, numbers added, equal terms collected (x + 2x = 3x)."""
        numbers, collected = [], {}
        for term in _flattened(ADD, terms):
            if term.kind == NUMBER:
                numbers.append(term.value)
                continue
            coefficient, rest = self._split(term)
            collected.setdefault(rest, []).append(coefficient)
        number = _combined(sum, numbers) if numbers else 0
        collected = {rest: coefficients[0] if len(coefficients) == 1 else _combined(sum, coefficients)
                     for rest, coefficients in collected.items()}
        parts = [rest if c == 1 else self.mul(self.number(c), rest) for rest, c in collected.items() if c != 0]
        parts.sort(key=_order)
        if number != 0:
            parts.insert(0, self.number(number))
        if not parts:
            return self.number(number)
        return parts[0] if len(parts) == 1 else self.node(ADD, tuple(parts))

    def _split(self, term: Node) -> tuple:
        """(number, the rest) of a term: 3*x*y is (3, x*y)."""
        if term.kind == MUL and term.args[0].kind == NUMBER:
            rest = term.args[1:]
            return term.args[0].value, rest[0] if len(rest) == 1 else self.node(MUL, rest)
        return 1, term

    def mul(self, *factors: Node, distribute: bool = False) -> Node:
        """The product: nested products flattened, numbers multiplied, equal bases collected;
        with `distribute`, a number times one sum is the sum of its terms times the number
        (sympy's `distribute`, on where a constant is substituted, off where the algorithms
        build and CSE shares a - b with b - a)."""
        numbers, collected = [], {}
        for factor in _flattened(MUL, factors):
            if factor.kind == NUMBER:
                numbers.append(factor.value)
                continue
            base, exponent = (factor.args[0], factor.args[1].value) if factor.kind == POW else (factor, 1)
            collected[base] = collected.get(base, 0) + exponent
        number = (numbers[0] if len(numbers) == 1 else _combined(math.prod, numbers)) if numbers else 1
        if number == 0:
            return self.number(number)
        parts = sorted((base if e == 1 else self.node(POW, (base, self.number(sympy.Rational(e))))
                        for base, e in collected.items() if e != 0), key=_order)
        if distribute and number != 1 and len(parts) == 1 and parts[0].kind == ADD:
            return self.add(*(self.mul(self.number(number), term) for term in parts[0].args))
        if number != 1 or not parts:
            parts.insert(0, self.number(number))
        return parts[0] if len(parts) == 1 else self.node(MUL, tuple(parts))

    def negate(self, node: Node) -> Node:
        """-node: a number negated, a product's number negated (-1 dropped), else -1 * node."""
        if node.kind == NUMBER:
            return self.number(_combined(operator.neg, node.value))
        if node.kind == MUL and node.args[0].kind == NUMBER:
            coefficient, *rest = node.args
            if coefficient.value == -1:
                return rest[0] if len(rest) == 1 else self.node(MUL, tuple(rest))
            return self.node(MUL, (self.number(_combined(operator.neg, coefficient.value)), *rest))
        return self.node(MUL, (self.minus_one, node))

    def select(self, *args: Node) -> Node:
        """A select (args: condition, value, ..., otherwise: the value of the first condition that
        holds, every value computed), evaluated: false pairs dropped, a true one ends the list, a select in the
        otherwise position joined, one value for every case is that value."""
        *pairs, otherwise = args
        pairs = list(zip(pairs[::2], pairs[1::2]))
        if otherwise.kind == SELECT:
            pairs += list(zip(otherwise.args[:-1:2], otherwise.args[1:-1:2]))
            otherwise = otherwise.args[-1]
        kept = []
        for condition, value in pairs:
            if condition is self.true:
                otherwise = value
                break
            if condition is not self.false:
                kept.append((condition, value))
        if all(value is otherwise for _, value in kept):
            return otherwise
        return self.node(SELECT, (*(arg for pair in kept for arg in pair), otherwise))

    def relation(self, operator_: str, lhs: Node, rhs: Node) -> Node:
        """lhs `operator_` rhs, decided where both sides are the same value, or constants whose
        comparison holds, or fails, in every real type."""
        if lhs is rhs:
            return self.truth(operator_ in (">=", "<=", "=="))
        if rhs.kind == NUMBER and rhs.value == 0 and lhs.kind == MUL and lhs.args[0].value == -1:
            return self.relation(REVERSED[operator_], self.negate(lhs), rhs)  # -x >= 0 is x <= 0
        if lhs.constant and rhs.constant:
            truths = {RELATIONS[operator_](evaluate(lhs, numbers), evaluate(rhs, numbers))
                      for numbers in TOLERANCE_VALUES.values()}
            if len(truths) == 1:
                return self.truth(truths.pop())
        return self.node(RELATION, (lhs, rhs), operator_)

    def logic(self, kind: str, *operands: Node) -> Node:
        """And, Or: nested ones flattened, a deciding truth value decides, the others dropped."""
        deciding = self.false if kind == AND else self.true
        kept = []
        for operand in _flattened(kind, operands):
            if operand is deciding:
                return deciding
            if operand.kind != TRUTH and operand not in kept:
                kept.append(operand)
        if not kept:
            return self.truth(kind == AND)
        return kept[0] if len(kept) == 1 else self.node(kind, tuple(kept))

    def rebuilt(self, node: Node, args: tuple, distribute: bool = False) -> Node:
        """`node` of new arguments, evaluated as its kind's constructor evaluates."""
        kind = node.kind
        if kind == ADD:
            return self.add(*args)
        if kind == MUL:
            return self.mul(*args, distribute=distribute)
        if kind == POW and args[0].kind == NUMBER and not (args[0].value == 0 and args[1].value < 0):  # 1/0 stays
            return self._number_power(args[0].value, args[1].value)
        if kind == SELECT:
            return self.select(*args)
        if kind == RELATION:
            return self.relation(node.value, *args)
        if kind in (AND, OR):
            return self.logic(kind, *args)
        if kind == NOT and args[0].kind == TRUTH:
            return self.truth(not args[0].value)
        return self.node(kind, args, node.value)

    def settled(self, node: Node, _done: dict | None = None) -> Node:
        """A constant rebuilt by the evaluating constructors: its comparisons decided where every
        real type agrees, the selects on them resolved, its numbers combined."""
        done = {} if _done is None else _done
        if node not in done:
            args = tuple(self.settled(arg, done) for arg in node.args)
            done[node] = self.rebuilt(node, args, distribute=True) if node.args else node
        return done[node]

    def substitute(self, node: Node, values: dict, distribute: bool, _done: dict | None = None) -> Node:
        """`node` with the symbols of `values` (sympy Symbol -> Node) replaced, evaluated again
        (with `distribute`, numbers distributed over sums)."""
        done = {} if _done is None else _done
        if node not in done:
            if node.kind == SYMBOL:
                done[node] = values.get(node.value, node)
            elif node.free_symbols.isdisjoint(values):
                done[node] = node
            else:
                args = tuple(self.substitute(arg, values, distribute, done) for arg in node.args)
                done[node] = self.rebuilt(node, args, distribute)
        return done[node]


def elementwise(function, values: numpy.ndarray) -> numpy.ndarray:
    """function applied to every entry of an array of values (naming a vector of nodes)."""
    return numpy.vectorize(function, otypes=[object])(values)


def _combined(operation, values):
    """operation(values) of numbers (a sum, a product of a list; a negation of one), Folded if
    one of them was."""
    folded = any(isinstance(v, Folded) for v in values) if isinstance(values, list) else isinstance(values, Folded)
    return number_of(operation(values), folded)


def _order(node: Node) -> int:
    """The order of a sum's terms and a product's factors: as their values were first built
    (the base's, for a power), so that a*b and b*a are one node, whatever the order written."""
    return node.args[0].index if node.kind == POW or (node.kind == MUL and node.args[0].kind == NUMBER
                                                      and len(node.args) == 2) else node.index


def _flattened(kind: str, nodes) -> list[Node]:
    flat = []
    for node in nodes:
        if node.kind == kind:
            flat.extend(node.args)
        else:
            flat.append(node)
    return flat
