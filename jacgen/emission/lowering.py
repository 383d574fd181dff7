"""The lowering core: named values and straight-line code over named temporaries.

The algorithms (`kinematics`, `subproblems`, `ik`, `differential`) name every intermediate
value with `Lowering.name`, so that no expression they build grows with the chain; a
function's outputs are then lowered to a `Body` on the value graph (`graph.py`): the named
values and trig symbols they read, common-subexpression elimination (`cse.py`), temporaries
numbered in a fixed order (the output does not depend on hashing). A body that runs a fixed
number of times (`repeated`), or that several places compute on other values (`called`), is a
kernel, lowered once and run by REPEAT nodes. Every printer turns a Body into its language;
`operation_count.py` counts it.
"""

import heapq
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Callable

import sympy

from jacgen.emission.cse import eliminate_common
from jacgen.emission.operation_count import operation_count
from jacgen.inputs import names
from jacgen.model.graph import Graph
from jacgen.model.tolerance_symbols import TOLERANCE_SYMBOLS
from jacgen.model.node import (ADD, MUL, PART, REPEAT, SYMBOL, TOLERANCE_VALUES, Kernel, Node, evaluate,
                               negative_coefficient)


@dataclass(frozen=True)
class Body:
    """Straight-line code: definitions in order, then the outputs (selects, no branches)."""

    read: frozenset  # the input symbols the body reads
    definitions: tuple[tuple[sympy.Symbol, Node], ...]
    outputs: tuple[Node, ...]  # row-major
    names: dict[sympy.Symbol, str]  # the temporaries' printed names (t0, t1, ...), in definition order

    def name(self, symbol: sympy.Symbol) -> str:
        """The printed name of a defined symbol."""
        return self.names.get(symbol, symbol.name)

    @cached_property
    def operation_count(self) -> int:
        return operation_count([e for _, e in self.definitions] + list(self.outputs))


class Lowering:
    """The named values of one robot (trig symbols defined first, by `define`), the value graph
    they are lowered on, and the Bodies lowered from them, each once per outputs and bindings."""

    def __init__(self):
        self.definitions: list[tuple[sympy.Symbol, Node]] = []  # in an order that defines before use
        self.graph = Graph()
        self._names: dict[object, sympy.Symbol] = {}  # named values, by `_key`
        self._named_symbols: set[sympy.Symbol] = set()
        self._values: dict[sympy.Symbol, Node] = {}  # each defined symbol's value
        self._negations: dict[Node, Node | None] = {}  # eliminate_common's, shared by every lowering
        self._lowered: dict[tuple, Body] = {}
        self._kernels: dict[str, Kernel] = {}

    def define(self, symbol: sympy.Symbol, value: sympy.Expr):
        """A symbol of the generated code (a joint's cos) and its value, taken onto the graph
        now: nodes are ordered by when they were built (`graph._order`), so every value is
        built in the algorithms' order, never in the order a set iterates."""
        self.definitions.append((symbol, self.graph.convert(value)))
        self._values[symbol] = self.definitions[-1][1]

    def value_of(self, symbol: sympy.Symbol) -> Node | None:
        """The value a symbol is defined as, None for an input."""
        return self._values.get(symbol)

    def named(self, value: sympy.Expr) -> sympy.Expr:
        """`name_node` for a sympy value (the chain's), as a sympy value: its symbol, or minus it.
        A product of sympy's atoms stays as it is; an exact irrational constant (cos(pi/180)) is
        no atom, so its products are named (computed once, not folded into every reader)."""
        if value.is_Atom or (value.is_Mul and all(arg.is_Atom for arg in value.args)):
            return value
        node = self._named(self.graph.convert(value), _mostly_negative(value))
        return node.value if node.kind == SYMBOL else -node.args[1].value

    def name_node(self, value) -> Node:
        """`value` (a node, or a number or sympy value taken onto the graph) as a symbol of its
        own, or minus it: a leaf, or a product of leaves, stays as it is. The algorithms name
        every intermediate value, so that every expression they build has a bounded size:
        written out, sums flatten into their readers and each lever of the chain would repeat
        the rest of the chain."""
        node = self.graph.value(value)
        if not node.args or (node.kind == MUL and all(not arg.args for arg in node.args)):
            return node
        terms = node.args if node.kind == ADD else (node,)
        return self._named(node, 2 * sum(map(negative_coefficient, terms)) > len(terms))

    def _named(self, node: Node, mostly_negative: bool) -> Node:
        """The symbol of `node`'s value, defined on first use, or minus it: a sum is known by its
        terms, whatever their order, and one with mostly negative terms is named as its negation."""
        graph, key = self.graph, _key(self.graph, node)
        if key in self._names:
            return graph.symbol(self._names[key])
        negated = graph.node(ADD, tuple(map(graph.negate, node.args))) if node.kind == ADD else graph.negate(node)
        if _key(graph, negated) in self._names:
            return graph.negate(graph.symbol(self._names[_key(graph, negated)]))
        if mostly_negative:
            return graph.negate(self._named(negated, False))
        symbol = sympy.Symbol(f"{names.INTERNAL_PREFIX}n{len(self.definitions)}", real=True)
        self.definitions.append((symbol, node))
        self._values[symbol] = node
        self._names[key] = symbol
        self._named_symbols.add(symbol)
        return graph.symbol(symbol)

    def repeated(self, name: str, summary: str, count: int, step: Callable[[list[Node]], list[Node]],
                 state: list[Node]) -> list[Node]:
        """The state after `count` runs of `step` (a function of the state's nodes, naming its
        values with `name_node`, to the next state's) from `state`: one REPEAT of the kernel
        `name`, built on its first use, and read by PART nodes. A body run once, or on a
        constant state, is built in place (folded, for constants)."""
        graph = self.graph
        state = [graph.value(value) for value in state]
        if count <= 1 or all(value.constant for value in state):
            for _ in range(count):
                state = [graph.value(value) for value in step(state)]
            return state
        return self._run(name, summary, count, step, state)

    def called(self, name: str, summary: str, step: Callable[[list[Node]], list[Node]],
               arguments: list[Node]) -> list[Node]:
        """`step`'s outputs from `arguments`, as one run of the kernel `name`: a body that several
        functions, or one function twice, compute on other values (a solve of one size), written
        once in each file and called. Its outputs need not be as many as its arguments."""
        return self._run(name, summary, 1, step, [self.graph.value(value) for value in arguments])

    def _run(self, name: str, summary: str, count: int, step: Callable, state: list[Node]) -> list[Node]:
        kernel = self._kernels.get(name)
        if kernel is None:
            symbols = [sympy.Symbol(f"{names.INTERNAL_PREFIX}w{k}", real=True) for k in range(len(state))]
            kernel = self.kernel(name, summary, symbols,
                                 lambda: step([self.graph.symbol(symbol) for symbol in symbols]))
        return self.run(kernel, count, state)

    def kernel(self, name: str, summary: str, inputs: list[sympy.Symbol], outputs: Callable[[], list]) -> Kernel:
        """The kernel `name`: the values `outputs()` builds, a function of the symbols `inputs`
        (and of the tolerances), built and lowered on first use; its inputs are printed w0, w1, ..."""
        if name not in self._kernels:
            body = self.lower(outputs(), inputs=frozenset(inputs))
            outer = body.read - set(inputs) - TOLERANCE_SYMBOLS
            if outer:
                raise ValueError(f"kernel {name}'s step reads {sorted(map(str, outer))} besides its state")
            body = replace(body, names=body.names | {symbol: f"w{k}" for k, symbol in enumerate(inputs)})
            self._kernels[name] = Kernel(name, summary, tuple(inputs), body)
        return self._kernels[name]

    def run(self, kernel: Kernel, count: int, state: list) -> list[Node]:
        """The outputs of `count` runs of `kernel` from `state` (nodes or numbers): a REPEAT,
        read by PART nodes."""
        state = [self.graph.value(value) for value in state]
        if len(kernel.state) != len(state) or (count > 1 and len(kernel.body.outputs) != len(state)):
            raise ValueError(f"kernel {kernel.name} maps {len(kernel.state)} values to {len(kernel.body.outputs)}, "
                             f"given {len(state)} to run {count} times")
        repeat = self.graph.node(REPEAT, tuple(state), (kernel, count))
        return [self.graph.node(PART, (repeat,), k) for k in range(len(kernel.body.outputs))]

    def lower(self, outputs: list[sympy.Basic], bindings: dict | None = None, inputs: frozenset = frozenset()
              ) -> Body:
        """`_lower`, once per outputs, bindings and inputs (jacobian_det's determinant is lowered
        to compare its two forms, then again as a function)."""
        key = (tuple(outputs), tuple((bindings or {}).items()), inputs)
        if key not in self._lowered:
            self._lowered[key] = self._lower(outputs, bindings or {}, inputs)
        return self._lowered[key]

    def _lower(self, outputs: list[sympy.Basic], bindings: dict, inputs: frozenset) -> Body:
        """The outputs as straight-line code: the trig symbols and named values they need,
        then temporaries (t0, t1, ...) after common-subexpression elimination, in an order
        that defines before use. Defined symbols among `inputs` (a kernel's: a joint's cos) are
        read as they are."""
        graph = self.graph
        values = {symbol: value for symbol, value in self.definitions if symbol not in inputs}
        values.update((symbol, graph.convert(value)) for symbol, value in bindings.items())
        outputs = [graph.value(e) for e in outputs]
        needed, frontier = set(), set().union(*(e.free_symbols for e in outputs))
        while frontier:
            symbol = frontier.pop()
            if symbol in values and symbol not in needed:
                needed.add(symbol)
                frontier |= values[symbol].free_symbols
        # Constants (a subproblem's scale of a constant vector) go into their readers before CSE,
        # so that their numbers fold with the readers' own; CSE's temporaries that are constants, after.
        ordered = [(s, values[s]) for s in bindings if s in needed] + [(s, v) for s, v in self.definitions
                                                                       if s in needed and s not in bindings]
        definitions, outputs = _without_constants(graph, _in_dependency_order(ordered), outputs, distribute=False)
        named = [(s, v) for s, v in definitions if s in self._named_symbols]
        replacements, reduced = eliminate_common(graph, [v for _, v in named] + outputs,
                                                 sympy.numbered_symbols(f"{names.INTERNAL_PREFIX}r", real=True),
                                                 self._negations)
        named, reduced = list(zip((s for s, _ in named), reduced)), reduced[len(named):]
        # A named value that CSE found elsewhere too is its temporary, a temporary that the
        # reuse pass found equal to another is that one, and a named value that folded to
        # another (a QR column whose first entry is 0): read it, not a copy of it.
        shared = {symbol for symbol, _ in replacements} | {symbol for symbol, _ in named}
        copies = {s: v for s, v in named + replacements if v.kind == SYMBOL and v.value in shared}
        for s, v in copies.items():
            while v.value in copies:
                v = copies[s] = copies[v.value]
        definitions = [(s, v) for s, v in definitions if s not in self._named_symbols] + named + replacements
        if copies:
            definitions = [(s, graph.substitute(v, copies, False)) for s, v in definitions if s not in copies]
            reduced = [graph.substitute(e, copies, False) for e in reduced]
        definitions = _in_dependency_order(definitions)
        definitions, reduced = _without_constants(graph, definitions, reduced, distribute=True)
        temporaries = [symbol for symbol, _ in definitions if symbol.name.startswith(names.INTERNAL_PREFIX)]
        read = set().union(*(e.free_symbols for _, e in definitions), *(e.free_symbols for e in reduced))
        return Body(frozenset(read - {symbol for symbol, _ in definitions}), tuple(definitions), tuple(reduced),
                    {symbol: f"t{k}" for k, symbol in enumerate(temporaries)})


def kernels_of(bodies) -> list[Kernel]:
    """The kernels the bodies run, each once, in the order first run, a kernel after those its
    own step runs (so that each is defined before use)."""
    found = {}

    def visit(body: Body):
        for _, value in body.definitions:
            if value.kind == REPEAT and value.value[0] not in found:
                visit(value.value[0].body)
                found[value.value[0]] = None

    for body in bodies:
        visit(body)
    return list(found)


def _key(graph: Graph, node: Node):
    """What names a value on the graph: a sum by its set of terms; a negated product, -1*(a*b)
    as `Graph.negate` builds it, as the product -1*a*b."""
    if node.kind == ADD:
        return ADD, frozenset(_flat(graph, term) for term in node.args)
    return _flat(graph, node)


def _flat(graph: Graph, node: Node) -> Node:
    return graph.mul(*node.args) if node.kind == MUL and any(arg.kind == MUL for arg in node.args) else node


def _mostly_negative(value: sympy.Expr) -> bool:
    """A product with a negative coefficient, or a sum with more such terms than others, by the
    terms of sympy's value (an exact irrational coefficient, -cos(pi/180), counts as none)."""
    terms = value.args if value.is_Add else (value,)
    negative = sum(bool((term.args[0] if term.is_Mul else term).is_extended_negative) for term in terms
                   if term.is_Number or term.is_Mul and term.args[0].is_Number)
    return 2 * negative > len(terms)


def _without_constants(graph: Graph, definitions: list[tuple[sympy.Symbol, Node]], outputs: list[Node],
                       distribute: bool):
    """The definitions that are constants (numbers, truth values, the IK's tolerances) put
    into their readers, which are evaluated again: a select on a condition that is always false
    is its other side, and the definitions no longer read are dropped. A comparison of
    tolerances and numbers is decided when it holds, or fails, in every real type."""
    constants, kept = {}, []
    for symbol, value in definitions:
        if not value.free_symbols.isdisjoint(constants):
            value = graph.substitute(value, constants, distribute)
        if value.boolean and value.free_symbols and value.constant:
            truths = {evaluate(value, numbers) for numbers in TOLERANCE_VALUES.values()}
            value = graph.truth(truths.pop()) if len(truths) == 1 else value
        if value.constant:
            constants[symbol] = graph.settled(value)
        else:
            kept.append((symbol, value))
    outputs = [graph.substitute(e, constants, distribute) if not e.free_symbols.isdisjoint(constants) else e for e in outputs]
    # A folded select may leave the terms of its other side unread: those go too.
    read = set().union(*(e.free_symbols for e in outputs))
    for symbol, value in reversed(kept):
        if symbol in read:
            read |= value.free_symbols
    return [(symbol, value) for symbol, value in kept if symbol in read], outputs


def _in_dependency_order(definitions: list[tuple[sympy.Symbol, Node]]) -> list[tuple[sympy.Symbol, Node]]:
    """Each definition after those it reads; among the ready ones, the earliest listed first
    (so the order is fixed, whatever the hashing)."""
    index = {symbol: k for k, (symbol, _) in enumerate(definitions)}
    readers: dict[int, list[int]] = {k: [] for k in range(len(definitions))}
    waiting = []
    for k, (_, value) in enumerate(definitions):
        reads = {index[s] for s in value.free_symbols if s in index}
        waiting.append(len(reads))
        for j in reads:
            readers[j].append(k)
    ready = [k for k, count in enumerate(waiting) if count == 0]
    heapq.heapify(ready)
    ordered = []
    while ready:
        k = heapq.heappop(ready)
        ordered.append(definitions[k])
        for reader in readers[k]:
            waiting[reader] -= 1
            if waiting[reader] == 0:
                heapq.heappush(ready, reader)
    return ordered
