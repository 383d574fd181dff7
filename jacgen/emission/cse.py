"""Common-subexpression elimination on the value graph: sympy's `cse` step by step (opt_cse's
rewrites and shared arguments, then tree_cse's repeated nodes), with the same temporaries, and
a pass that reuses temporaries inside the products match_common_args leaves. `lowering.py`
runs it on every function's outputs.
"""

from collections import Counter

import sympy
from sympy.simplify.cse_main import Unevaluated, match_common_args

from jacgen.model.graph import Graph
from jacgen.model.node import ADD, CALL, MUL, NUMBER, PART, POW, REPEAT, SELECT, Node, negative_coefficient


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
        if node in repeated or isinstance(node, Node) and node.kind == REPEAT:  # a statement in C
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
    folded before), a kernel's run or an entry of its state too; anything else as its kind
    evaluates (`Graph.rebuilt`), so that a sum whose terms became the same temporary, x - x, is 0."""
    if form.kind in (CALL, SELECT, REPEAT, PART):
        return graph.node(form.kind, tuple(args), form.value)
    return graph.rebuilt(form, tuple(args))
