"""The lowering core: named values and straight-line code over named temporaries.

The algorithms (`kinematics`, `subproblems`, `ik`, `differential`) name every intermediate
value with `Lowering.name`, so that no expression they build grows with the chain; a
function's outputs are then lowered to a `Body` on the value graph (`graph.py`): the named
values and trig symbols they read, common-subexpression elimination, temporaries numbered in
a fixed order (the output does not depend on hashing). Every printer turns a Body into its
language.
"""

import heapq
from collections import Counter
from fractions import Fraction
from dataclasses import dataclass
from functools import cached_property

import sympy
from sympy.simplify.cse_main import Unevaluated, match_common_args

from jacgen.model.graph import (ADD, AND, FINITE, MUL, NOT, NUMBER, OR, POW, RELATION, SELECT, SYMBOL, TRUTH, CALL,
                                   TOLERANCE_VALUES, Graph, Node, evaluate, negative_coefficient)
from jacgen.inputs import names


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


class Lowering:
    """The named values of one robot (trig symbols defined first, by `define`), the value graph
    they are lowered on, and the Bodies lowered from them, each once per outputs and bindings."""

    def __init__(self):
        self.definitions: list[tuple[sympy.Symbol, Node]] = []  # in an order that defines before use
        self.graph = Graph()
        self._names: dict[object, sympy.Symbol] = {}  # named values, by `_key`
        self._named_symbols: set[sympy.Symbol] = set()
        self._negations: dict[Node, Node | None] = {}  # eliminate_common's, shared by every lowering
        self._lowered: dict[tuple, Body] = {}

    def define(self, symbol: sympy.Symbol, value: sympy.Expr):
        """A symbol of the generated code (a joint's cos) and its value, taken onto the graph
        now: nodes are ordered by when they were built (`graph._order`), so every value is
        built in the algorithms' order, never in the order a set iterates."""
        self.definitions.append((symbol, self.graph.convert(value)))

    def name(self, value: sympy.Expr) -> sympy.Expr:
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
        self._names[key] = symbol
        self._named_symbols.add(symbol)
        return graph.symbol(symbol)

    def lower(self, outputs: list[sympy.Basic], bindings: dict | None = None) -> Body:
        """`_lower`, once per outputs and bindings (jacobian_det's determinant is lowered to
        compare its two forms, then again as a function)."""
        key = (tuple(outputs), tuple((bindings or {}).items()))
        if key not in self._lowered:
            self._lowered[key] = self._lower(outputs, bindings or {})
        return self._lowered[key]

    def _lower(self, outputs: list[sympy.Basic], bindings: dict) -> Body:
        """The outputs as straight-line code: the trig symbols and named values they need,
        then temporaries (t0, t1, ...) after common-subexpression elimination, in an order
        that defines before use."""
        graph = self.graph
        values = dict(self.definitions)
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
        # A named value that CSE found elsewhere too is its temporary, and a temporary that the
        # reuse pass found equal to another is that one: read it, not a copy of it.
        shared = {symbol for symbol, _ in replacements}
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


def eliminate_common(graph: Graph, exprs: list[Node], symbols, negations: dict) -> tuple[list, list[Node]]:
    """sympy's `cse(exprs, symbols, order="none")` (its opt_cse, then tree_cse) on the graph,
    with the same temporaries: a sum or product with more negative terms is shared with its
    negation, x**-n is 1/x**n, sums and products that share two or more terms share their
    sum or product (sympy's own `match_common_args`, which reads nothing but `args`), and
    every node reached twice becomes a temporary. The sign of a sum is decided from its
    terms' numbers (sympy compares sort keys of whole expressions), what is rebuilt keeps its
    order and is evaluated only where something in it can combine (`_rebuilt`), and
    `negations` keeps each node's negation for the robot's other functions.

    Returns [(temporary symbol, value)] and the expressions over them.

    One function, longer than most, because it follows sympy's cse_main step by step (opt_cse's
    passes, then tree_cse's walk): read side by side with it, a difference is a choice."""
    rewritten: dict = {}  # node -> the form tree_cse walks (sympy's opt_subs)
    adds, muls = {}, {}  # candidates for common arguments, in the order first met
    seen = set()
    power = lambda base, exponent: graph.node(POW, (base, exponent))  # noqa: E731
    minus_one = graph.number(sympy.S.NegativeOne)

    def find_rewrites(node):
        if not node.args or node in seen:
            return
        seen.add(node)
        for arg in node.args:
            find_rewrites(arg)
        if node.kind in (ADD, MUL):
            if node not in negations:
                negations[node] = _negation(graph, node)
            negated = negations[node]
            if negated is not None and negated.args:
                rewritten[node] = Unevaluated(graph.mul, (graph.minus_one, negated))
                seen.add(negated)
                node = negated
            if node.kind in (ADD, MUL) and len(node.args) > 1:
                (adds if node.kind == ADD else muls)[node] = None
        elif node.kind == POW and node.args[1].value < 0:
            base, exponent = node.args[0], -node.args[1].value
            rewritten[node] = Unevaluated(power, (base if exponent == 1 else power(base, graph.number(exponent)),
                                                  minus_one))

    for expr in exprs:
        find_rewrites(expr)
    match_common_args(graph.add, list(adds), rewritten)
    match_common_args(graph.mul, list(muls), rewritten)

    repeated, reached = set(), set()

    def find_repeated(node):
        if not isinstance(node, Unevaluated) and not node.args:
            return
        if node in reached:
            repeated.add(node)
            return
        reached.add(node)
        for arg in rewritten.get(node, node).args:
            find_repeated(arg)

    for expr in exprs:
        find_repeated(expr)

    replacements, named = [], {}

    def rebuild(node):
        if not isinstance(node, Unevaluated) and not node.args:
            return node
        if node in named:
            return named[node]
        form = rewritten.get(node, node)
        args = [rebuild(arg) for arg in form.args]
        if isinstance(form, Unevaluated):
            new = form.func(*args)
        elif all(new is old for new, old in zip(args, form.args)):
            new = form
        else:
            new = _rebuilt(graph, form, args)
        if node in repeated:
            symbol = next(symbols)
            named[node] = graph.symbol(symbol)
            replacements.append((symbol, new))
            return named[node]
        return new

    outputs = [rebuild(expr) for expr in exprs]
    return _reusing_temporaries(graph, replacements, outputs)


def _reusing_temporaries(graph: Graph, replacements: list, outputs: list[Node]) -> tuple[list, list[Node]]:
    """Sums and products read the temporaries CSE made where that costs fewer operations:
    `match_common_args` is greedy and leaves some (0.07*c2*s5*t2 beside t6 = c2*s5). A sum
    holding all of a temporary's terms reads it, the largest first; a product is written out
    to its factors (product temporaries without a number expanded: s2*s3*c5*t4, t4 = c3*c4)
    and covered by the largest temporaries that fit (t12*c3*s3, t12 = s2*c4*c5), if that has
    fewer factors. A product temporary reads only smaller ones, so none reads itself."""
    values = {graph.symbol(symbol): value for symbol, value in replacements}
    sums = {}  # a first term -> the sum temporaries starting with it: (symbol, terms)
    written: dict[Node, Counter] = {}  # a product temporary without a number -> its factors written out
    leaves: dict[Node, Counter] = {}  # any other factor -> itself (a power: its base, so many times)

    def written_out(node: Node) -> Counter:
        value = values.get(node)
        if value is not None and value.kind == MUL and value.args[0].kind != NUMBER:
            if node not in written:
                written[node] = sum((written_out(factor) for factor in value.args), Counter())
            return written[node]
        if node not in leaves:
            power = node.kind == POW and node.args[1].value.is_integer and node.args[1].value > 0
            leaves[node] = Counter({node.args[0]: int(node.args[1].value)} if power else {node: 1})
        return leaves[node]

    for symbol, value in values.items():
        if value.kind == ADD:
            sums.setdefault(value.args[0], []).append((symbol, frozenset(value.args)))
        elif value.kind == MUL and value.args[0].kind != NUMBER:
            written_out(symbol)
    products = {}  # a factor -> the product temporaries written out with it
    for symbol, counter in written.items():
        products.setdefault(min(counter, key=lambda n: n.index), []).append(symbol)
    sizes = {t: sum(counter.values()) for t, counter in written.items()}
    done: dict[Node, Node] = {}

    def covered(node: Node, own: Node | None) -> Node:
        number = node.args[:1] if node.args[0].kind == NUMBER else ()
        left = Counter()
        for factor in node.args[len(number):]:
            left.update(written_out(factor))
        candidates = {t for factor in left for t in products.get(factor, ())
                      if t is not own and (own not in sizes or (sizes[t], t.index) < (sizes[own], own.index))}
        if not candidates:
            return node
        used = []
        for t in sorted(candidates, key=lambda t: (-sizes[t], t.index)):
            while all(left[f] >= k for f, k in written[t].items()):
                left -= written[t]
                used.append(t)
        factors = used + [base if k == 1 else graph.power(base, k) for base, k in left.items()]
        cost = lambda fs: len(fs) + sum(f.kind == POW for f in fs)  # noqa: E731
        return graph.mul(*number, *factors) if used and cost(factors) < cost(node.args[len(number):]) else node

    def reusing(node: Node, own: Node | None = None) -> Node:
        if not node.args:
            return node
        if own is None and node in done:
            return done[node]
        args = [reusing(arg) if arg.args else arg for arg in node.args]
        new = node if all(a is b for a, b in zip(args, node.args)) else _rebuilt(graph, node, args)
        if new.kind == MUL and products:
            new = covered(new, own)
        elif new.kind == ADD and sums:
            terms, used = set(new.args), []
            for symbol, parts in sorted({c for term in new.args for c in sums.get(term, ())},
                                        key=lambda c: (-len(c[1]), c[0].index)):
                if symbol is not own and parts < frozenset(new.args) and parts <= terms:
                    terms -= parts
                    used.append(symbol)
            if used:
                new = graph.add(*(term for term in new.args if term in terms), *used)
        if own is None:
            done[node] = new
        return new

    replacements = [(symbol, reusing(value, graph.symbol(symbol))) for symbol, value in replacements]
    return replacements, [reusing(expr) for expr in outputs]


def _negation(graph: Graph, node: Node) -> Node | None:
    """-node when sympy's cse would share node with it (`could_extract_minus_sign`): a
    product with a negative number or a sum with more such terms than others, else None.
    (On a tie sympy compares the sort keys of the sum and its negation; without distribution
    the negation is -1 times the sum, whose key is the larger: never.)"""
    if node.kind == MUL:
        return graph.negate(node) if negative_coefficient(node) else None
    if 2 * sum(map(negative_coefficient, node.args)) <= len(node.args):
        return None
    return graph.node(ADD, tuple(graph.negate(term) for term in node.args))


def _rebuilt(graph: Graph, form: Node, args: list[Node]) -> Node:
    """form with new arguments: a call or select of temporaries as it is (one of numbers was
    folded before); anything else as its kind evaluates (`Graph.rebuilt`), so that a sum whose
    terms became the same temporary, x - x, is 0."""
    if form.kind in (CALL, SELECT):
        return graph.node(form.kind, tuple(args), form.value)
    return graph.rebuilt(form, tuple(args))
