"""Forward-mode derivatives on the value graph: how values move, to first order, along a few
directions of the symbols they read. The calibrated fast path's certificate
(`general6r_target.nominal_branches`) bounds with them how far each margin of the nominal arm's
closed form moves when the target pose moves within the two arms' mismatch.
"""

from typing import Callable

import sympy

from jacgen.model.graph import Graph
from jacgen.model.node import ADD, BOOLEAN_KINDS, CALL, MUL, NUMBER, POW, SELECT, SYMBOL, Node

Tangent = tuple  # one Node per direction, None where the value does not move along it


class Tangents:
    """The tangents of values on `graph` along as many directions as a seed has: `seeds` gives
    those of the symbols that move (the inputs), `value_of` the definition of a named symbol
    (None for an input), and every derivative of a definition is named with `name`."""

    def __init__(self, graph: Graph, name: Callable[[Node], Node], value_of: Callable[[sympy.Symbol], Node | None],
                 seeds: dict[Node, Tangent]):
        self.graph, self.name, self.value_of = graph, name, value_of
        self.directions = len(next(iter(seeds.values())))
        self._done: dict[Node, Tangent] = dict(seeds)

    def of(self, node: Node) -> Tangent:
        """The tangent of `node` (its derivative along each direction)."""
        stack = [node]
        while stack:  # post-order, without recursion: chains are thousands of values deep
            top = stack[-1]
            if top in self._done:
                stack.pop()
                continue
            waiting = [arg for arg in self._reads(top) if arg not in self._done]
            if waiting:
                stack.extend(waiting)
                continue
            stack.pop()
            self._done[top] = self._rule(top)
        return self._done[node]

    def _reads(self, node: Node) -> tuple[Node, ...]:
        if node.kind == SYMBOL:
            value = self.value_of(node.value)
            return () if value is None else (value,)
        if node.kind in BOOLEAN_KINDS or node.kind == NUMBER:
            return ()
        if node.kind == SELECT:
            return node.args[1::2] + node.args[-1:]
        return node.args

    def _rule(self, node: Node) -> Tangent:
        g, none = self.graph, (None,) * self.directions
        if node.kind in BOOLEAN_KINDS or node.kind == NUMBER:
            return none
        if node.kind == SYMBOL:
            value = self.value_of(node.value)
            return none if value is None else tuple(d and self.name(d) for d in self._done[value])
        args = [self._done[arg] if arg.kind not in BOOLEAN_KINDS else None for arg in node.args]
        if node.kind == ADD:
            return tuple(_sum(g, [t[k] for t in args]) for k in range(self.directions))
        if node.kind == MUL:
            factors = node.args
            return tuple(_sum(g, [g.mul(*factors[:i], *factors[i + 1:], t[k]) for i, t in enumerate(args)
                                  if t[k] is not None]) for k in range(self.directions))
        if node.kind == POW:
            base, exponent = node.args
            slope = g.value(exponent.value) * g.power(base, exponent.value - 1)
            return tuple(d and slope * d for d in args[0])
        if node.kind == SELECT:
            conditions, values = node.args[:-1:2], node.args[1::2] + node.args[-1:]
            tangents = [self._done[value] for value in values]
            return tuple(None if all(t[k] is None for t in tangents) else
                         g.select(*(x for c, t in zip(conditions, tangents) for x in (c, _or_zero(g, t[k]))),
                                  _or_zero(g, tangents[-1][k])) for k in range(self.directions))
        if node.kind == CALL:
            return self._call(node, args)
        raise ValueError(f"no tangent for a {node.kind}")

    def _call(self, node: Node, args: list[Tangent]) -> Tangent:
        g, name, x = self.graph, node.value, node.args[0]
        if name in ("Floor", "Ceiling"):
            return (None,) * self.directions
        if name == "sin":
            slope = g.call("cos", x)
        elif name == "cos":
            slope = -g.call("sin", x)
        elif name == "Abs":
            slope = g.select(g.relation(">=", x, g.number(0)), g.number(1), g.number(-1))
        elif name == "atan2":  # atan2(y, x): (x dy - y dx) / (x^2 + y^2)
            y, x = node.args
            inverse = 1 / (x * x + y * y)
            turned = [_sum(g, [dy and x * dy, dx and -(y * dx)]) for dy, dx in zip(*args)]
            return tuple(t and t * inverse for t in turned)
        else:
            raise ValueError(f"no tangent for {name}")
        return tuple(d and slope * d for d in args[0])


def _sum(g: Graph, terms: list) -> Node | None:
    terms = [t for t in terms if t is not None]
    return g.add(*terms) if terms else None


def _or_zero(g: Graph, value: Node | None) -> Node:
    return g.number(0) if value is None else value
