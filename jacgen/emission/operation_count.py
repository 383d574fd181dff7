"""The operation count of straight-line code: sympy's `count_ops` rules on the value graph, the
figure the reports and benches give for a function, and what the Generator compares to choose
between two forms of a value (jacobian_det). Counted on the nodes, once each, so that a lowered
`Body` is never turned back into sympy to be counted.
"""

from fractions import Fraction

import sympy

from jacgen.model.node import (ADD, AND, CALL, FINITE, MUL, NOT, NUMBER, OR, POW, RELATION, REPEAT, SELECT, TRUTH, Node,
                               negative_coefficient)


def operation_count(nodes) -> int:
    """sympy's `count_ops` of `nodes`, the figure every report and bench shows, by its rules
    (quirks included: a sum under a product's -1 adds no operations), counted once per node.

    Its rules are one table in one function, in count_ops' order, so that a test can hold
    the two equal rule by rule (tests/test_lowering.py)."""
    counts: dict[Node, int] = {}

    def count(node: Node) -> int:  # count_ops' walk of an expression
        if node not in counts:
            if node.kind == NUMBER:
                counts[node] = _number_count(node.value)
            elif node.kind == MUL:
                counts[node] = 1 + unsigned(_negated(node)) if negative_coefficient(node) else unsigned(node.args)
            elif node.kind == ADD:
                terms = node.args
                negatives = [negative_coefficient(term) for term in terms]
                counts[node] = (len(terms) - 1 + all(negatives)
                                + sum(negated_count(t) if n else count(t) for t, n in zip(terms, negatives)))
            elif node.kind == POW and node.args[1].value == -1:
                counts[node] = 1 + count(node.args[0])
            elif node.kind == REPEAT:  # its state, then its kernel's step, so many times
                kernel, runs = node.value
                counts[node] = sum(map(count, node.args)) + runs * kernel.body.operation_count
            else:
                counts[node] = fallthrough(node)
        return counts[node]

    def negated_count(term: Node) -> int:  # count of -term, for a term with a negative number
        if term.kind == NUMBER:
            return _number_count(-term.value)
        factors = _negated(term)
        return count(factors[0]) if len(factors) == 1 else unsigned(factors)

    def fallthrough(node: Node) -> int:
        own = len(node.args) - 1 if node.kind in (MUL, AND, OR) else \
            int(bool(node.args) and node.kind in (POW, CALL, SELECT, NOT, FINITE))
        return own + sum(count(arg) for arg in node.args)

    def unsigned(factors) -> int:  # a product without its sign, as numerator / denominator
        numerator, denominator = [], []
        for factor in factors:
            if factor.kind == POW and factor.args[1].value < 0:
                base, exponent = factor.args[0], factor.args[1].value
                denominator.append(base if exponent == -1 else (base, -exponent))
            else:
                numerator.append(factor)
        numerator = [f for f in numerator if not (f.kind == NUMBER and _is_integer(f.value) and f.value == 1)]
        if all(f.kind == NUMBER and _is_integer(f.value) for f in numerator):  # 1/d, 2/d
            return 1 + group(denominator)
        if denominator:
            integer = all(not isinstance(f, tuple) and f.kind == NUMBER and _is_integer(f.value) for f in denominator)
            return (0 if integer else group(denominator)) + 1 + group(numerator)
        return fallthrough(factors[0]) if len(factors) == 1 else len(factors) - 1 + sum(map(count, factors))

    def group(factors) -> int:  # the product of `factors`
        total = len(factors) - 1 if len(factors) > 1 else 0
        for factor in factors:
            if isinstance(factor, tuple):  # base ** positive exponent
                base, exponent = factor
                total += 1 + count(base) + _number_count(exponent)
            else:
                total += count(factor)
        return total

    def top(node: Node) -> int:  # count_ops of a truth value: one per function, whatever its arguments
        if node.kind in (RELATION, AND, OR, NOT, FINITE):
            return 1 + sum(top(arg) for arg in node.args)
        return 0 if node.kind == TRUTH else count(node)

    return sum(top(node) for node in nodes)


def _is_integer(value) -> bool:
    return isinstance(value, (int, sympy.Integer))


def _number_count(value) -> int:
    """count_ops of a number: a folded constant (sympy's Float) none, a rational its sign and its division."""
    if isinstance(value, Fraction) or value == 1:
        return 0
    return int(bool(value < 0)) + (getattr(value, "q", 1) != 1)


def _negated(product: Node) -> list[Node]:
    """The factors of -product, for a product with a negative number (-1 dropped)."""
    coefficient, *rest = product.args
    return rest if coefficient.value == -1 else [Node(NUMBER, (), -coefficient.value), *rest]
