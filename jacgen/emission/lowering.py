"""The lowering core: named values and straight-line code over named temporaries.

The algorithms (`kinematics`, `subproblems`, `ik`, `differential`) name every intermediate
value with `Lowering.name`, so that no expression they build grows with the chain; a
function's outputs are then lowered to a `Body`: the named values and trig symbols they read,
common-subexpression elimination, constants folded, temporaries numbered in a fixed order
(the output does not depend on hashing). Every printer turns a Body into its language.
"""

import heapq
from dataclasses import dataclass
from functools import cached_property

import sympy
from sympy.core.operations import LatticeOp
from sympy.core.parameters import distribute
from sympy.logic.boolalg import Boolean, BooleanFunction
from sympy.simplify.cse_main import Unevaluated, match_common_args

from jacgen.inputs import names
from jacgen.model.nodes import TOLERANCES


@dataclass(frozen=True)
class Body:
    """Straight-line code: definitions in order, then the outputs (selects, no branches)."""

    read: frozenset  # the input symbols the body reads
    definitions: tuple[tuple[sympy.Symbol, sympy.Expr], ...]
    outputs: tuple[sympy.Expr, ...]  # row-major
    names: dict[sympy.Symbol, str]  # the temporaries' printed names (t0, t1, ...), in definition order

    def name(self, symbol: sympy.Symbol) -> str:
        """The printed name of a defined symbol."""
        return self.names.get(symbol, symbol.name)

    @cached_property
    def operation_count(self) -> int:
        return operation_count([e for _, e in self.definitions] + list(self.outputs))


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
        else:  # rebuilt only when an argument changed
            args = tuple(fold_constants(arg, folded) for arg in expr.args)
            changed = any(new is not old and new != old for new, old in zip(args, expr.args))
            folded[expr] = expr.func(*args) if changed else expr
    return folded[expr]


def operation_count(exprs) -> int:
    """sympy's `count_ops` of `exprs`, the figure every report and bench shows, by its rules
    (quirks included: a sum under a product's -1 adds no operations), counted once per node
    and without building the negations and fractions that count_ops builds for each.

    Its rules are one table in one function, in count_ops' order, so that a test can hold
    the two equal rule by rule (tests/test_lowering.py)."""
    counts: dict[sympy.Basic, int] = {}

    def count(expr) -> int:  # count_ops' walk of an expression
        if expr not in counts:
            if expr.is_Rational:
                counts[expr] = 0 if expr is sympy.S.One else (expr.p < 0) + (expr.q != 1)
            elif expr.is_Mul:
                negative = _negative_coefficient(expr)
                counts[expr] = negative + _unsigned(_negated(expr) if negative else expr)
            elif expr.is_Add:
                terms = expr.args
                negatives = [_negative_coefficient(term) for term in terms]
                counts[expr] = (len(terms) - 1 + all(negatives)
                                + sum(count(_negated(t) if n else t) for t, n in zip(terms, negatives)))
            elif expr.is_Pow and expr.exp is sympy.S.NegativeOne:
                counts[expr] = 1 + count(expr.base)
            else:
                counts[expr] = _fallthrough(expr)
        return counts[expr]

    def _fallthrough(expr) -> int:
        own = len(expr.args) - 1 if expr.is_Mul or isinstance(expr, LatticeOp) else \
            int(bool(expr.args) and (expr.is_Pow or expr.is_Function))
        return own + (0 if expr.is_Symbol else sum(count(arg) for arg in expr.args))

    def _unsigned(expr) -> int:  # a product without its sign, as numerator / denominator
        numerator, denominator = [], []
        for factor in sympy.Mul.make_args(expr):
            if factor.is_Pow and factor.exp.is_negative:
                denominator.append(factor.base if factor.exp is sympy.S.NegativeOne else (factor.base, -factor.exp))
            elif factor.is_Rational and not factor.is_integer:
                numerator += [sympy.Integer(factor.p)] * (factor.p != 1)
                denominator.append(sympy.Integer(factor.q))
            else:
                numerator.append(factor)
        numerator = [f for f in numerator if f is not sympy.S.One]
        if all(f.is_Integer for f in numerator):  # 1/d, 2/d
            return 1 + group(denominator)
        if denominator:
            integer = all(isinstance(f, sympy.Integer) for f in denominator)
            return (0 if integer else group(denominator)) + 1 + group(numerator)
        return _fallthrough(expr)

    def group(factors) -> int:  # the product of `factors`
        total = len(factors) - 1 if len(factors) > 1 else 0
        for factor in factors:
            if isinstance(factor, tuple):  # base ** positive exponent
                base, exponent = factor
                total += 1 + count(base) + count(exponent)
            else:
                total += count(factor)
        return total

    def top(expr) -> int:  # count_ops of a truth value: one per function, whatever its arguments
        if isinstance(expr, sympy.Expr) and not expr.is_Relational:
            return count(expr)
        if isinstance(expr, (sympy.core.relational.Relational, BooleanFunction)):
            return 1 + sum(top(arg) for arg in expr.args)
        if expr.args:
            raise TypeError(f"no operation count for {type(expr).__name__}")
        return 0

    return sum(top(expr) for expr in exprs)


def _negative_coefficient(expr: sympy.Expr) -> bool:
    coefficient = expr.args[0] if expr.is_Mul else expr
    return bool(coefficient.is_Number and coefficient.is_extended_negative)


def _negated(expr: sympy.Expr) -> sympy.Expr:
    """-expr of a number or of a product with a negative coefficient, without sympy's flattening."""
    if not expr.is_Mul:
        return -expr
    coefficient, *rest = expr.args
    if coefficient is sympy.S.NegativeOne:
        return rest[0] if len(rest) == 1 else sympy.Mul._from_args(rest)
    return sympy.Mul._from_args((-coefficient, *rest))


def is_boolean(value: sympy.Basic) -> bool:
    """A truth value (a comparison, And, Or, ...): an `int` in C, a bool array in numpy."""
    return isinstance(value, Boolean) and not isinstance(value, sympy.Expr)


class Lowering:
    """The named values of one robot (trig symbols defined first, by `define`) and the Bodies
    lowered from them, each once per outputs and bindings."""

    def __init__(self):
        self.definitions: list[tuple[sympy.Symbol, sympy.Expr]] = []  # in an order that defines before use
        self._names: dict[sympy.Expr, sympy.Symbol] = {}  # named values (see `name`)
        self._folded: dict[sympy.Expr, sympy.Expr] = {}  # fold_constants' results, shared by every lowering
        self._negations: dict[sympy.Expr, sympy.Expr | None] = {}  # eliminate_common's, likewise
        self._lowered: dict[tuple, Body] = {}

    def define(self, symbol: sympy.Symbol, value: sympy.Expr):
        """A symbol of the generated code (a joint's cos) and its value."""
        self.definitions.append((symbol, value))

    def name(self, value: sympy.Expr) -> sympy.Expr:
        """`value` as a symbol of its own (an atom, a number or a product of atoms stays as it
        is; -x is named as x). The chain names its rotations, steps and levers, so that every
        expression CSE sees has a bounded size: written out, sympy flattens the nested sums
        and each lever would repeat the rest of the chain."""
        if value.is_Atom or (value.is_Mul and all(arg.is_Atom for arg in value.args)):
            return value
        if value in self._names:
            return self._names[value]
        negated = sympy.Add(*(-term for term in value.args)) if value.is_Add else -value
        if negated in self._names:
            return -self._names[negated]
        if _mostly_negative(value):
            return -self.name(negated)
        symbol = sympy.Symbol(f"{names.INTERNAL_PREFIX}n{len(self.definitions)}", real=True)
        self.definitions.append((symbol, value))
        self._names[value] = symbol
        return symbol

    def lower(self, outputs: list[sympy.Basic], bindings: dict | None = None) -> Body:
        """`_lower`, once per outputs and bindings (jacobian_det's determinant is lowered to
        compare its two forms, then again as a function)."""
        key = (tuple(outputs), tuple((bindings or {}).items()))
        if key not in self._lowered:
            self._lowered[key] = self._lower(outputs, bindings)
        return self._lowered[key]

    def _lower(self, outputs: list[sympy.Basic], bindings: dict | None = None) -> Body:
        """The outputs as straight-line code: the trig symbols and named values they need,
        then temporaries (t0, t1, ...) after common-subexpression elimination, in an order
        that defines before use."""
        bindings = bindings or {}
        values = dict(self.definitions) | bindings
        needed, frontier = set(), set().union(*(e.free_symbols for e in outputs))
        while frontier:
            symbol = frontier.pop()
            if symbol in values and symbol not in needed:
                needed.add(symbol)
                frontier |= values[symbol].free_symbols
        named_symbols = set(self._names.values())
        fold = lambda value: fold_constants(value, self._folded)  # noqa: E731
        trig = [(s, fold(v)) for s, v in self.definitions
                if s in needed and s not in named_symbols and s not in bindings]
        named = [(s, v) for s, v in self.definitions if s in needed and s in named_symbols]
        with distribute(False):
            replacements, reduced = eliminate_common([fold(v) for _, v in named] + [fold(e) for e in outputs],
                                                     sympy.numbered_symbols(f"{names.INTERNAL_PREFIX}r", real=True), self._negations)
        bound = [(s, fold(v)) for s, v in bindings.items() if s in needed]
        definitions = _in_dependency_order(bound + trig + list(zip((s for s, _ in named), reduced)) + replacements)
        definitions, reduced = _without_constants(definitions, reduced[len(named):])
        # The temporaries are named when printed: renaming them here would rebuild every expression.
        temporaries = [symbol for symbol, _ in definitions if symbol.name.startswith(names.INTERNAL_PREFIX)]
        read = set().union(*(e.free_symbols for _, e in definitions), *(e.free_symbols for e in reduced))
        return Body(frozenset(read - {symbol for symbol, _ in definitions}), tuple(definitions), tuple(reduced),
                    {symbol: f"t{k}" for k, symbol in enumerate(temporaries)})


def _mostly_negative(value: sympy.Expr) -> bool:
    """A product with a negative coefficient, or a sum with more such terms than others (sympy's
    `could_extract_minus_sign` decides ties by sorting, which costs more than naming saves)."""
    terms = value.args if value.is_Add else (value,)
    negative = sum(bool((term.args[0] if term.is_Mul else term).is_extended_negative) for term in terms
                   if term.is_Number or term.is_Mul and term.args[0].is_Number)
    return 2 * negative > len(terms)


def _without_constants(definitions: list[tuple[sympy.Symbol, sympy.Expr]], outputs: list[sympy.Basic]):
    """The definitions that are constants (numbers, truth values, the IK's tolerances) put
    into their readers, which sympy then folds: a select on a condition that is always false
    is its other side, and the definitions no longer read are dropped. A comparison of
    tolerances and numbers is decided when it holds, or fails, in every real type."""
    constants, kept = {}, []
    for symbol, value in definitions:
        if not constants.keys().isdisjoint(value.free_symbols):
            value = value.xreplace(constants)
        if is_boolean(value) and value.free_symbols and value.free_symbols <= TOLERANCES["double"].keys():
            truths = {value.xreplace(numbers) for numbers in TOLERANCES.values()}
            value = truths.pop() if len(truths) == 1 else value
        if value.free_symbols <= TOLERANCES["double"].keys():
            constants[symbol] = value
        else:
            kept.append((symbol, value))
    outputs = [e.xreplace(constants) if not constants.keys().isdisjoint(e.free_symbols) else e for e in outputs]
    # A folded select may leave the terms of its other side unread: those go too.
    read = set().union(*(e.free_symbols for e in outputs))
    for symbol, value in reversed(kept):
        if symbol in read:
            read |= value.free_symbols
    return [(symbol, value) for symbol, value in kept if symbol in read], outputs


def _in_dependency_order(definitions: list[tuple[sympy.Symbol, sympy.Expr]]) -> list[tuple[sympy.Symbol, sympy.Expr]]:
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


def eliminate_common(exprs: list[sympy.Basic], symbols, negations: dict) -> tuple[list, list]:
    """sympy's `cse(exprs, symbols, order="none")` (its opt_cse, then tree_cse) at a fraction
    of its cost, with the same temporaries: a sum or product with more negative terms is
    shared with its negation, x**-n is 1/x**n, sums and products that share two or more terms
    share their sum or product (sympy's own `match_common_args`), and every node reached twice
    becomes a temporary. What costs less: the sign of a sum is decided from its terms'
    coefficients (sympy compares sort keys of whole expressions), products are not rebuilt to
    split commutative factors (all are), arguments keep their stored order, what is rebuilt
    is not evaluated again where nothing in it can combine (`_rebuilt`), and `negations`
    keeps each node's negation for the robot's other functions.

    One function, longer than most, because it follows sympy's cse_main step by step (opt_cse's
    passes, then tree_cse's walk): read side by side with it, a difference is a choice."""
    rewritten: dict = {}  # node -> the form tree_cse walks (sympy's opt_subs)
    adds, muls = {}, {}  # candidates for common arguments, in the order first met
    seen = set()

    def find_rewrites(expr):
        if not isinstance(expr, sympy.Basic) or expr.is_Atom or expr in seen:
            return
        seen.add(expr)
        for arg in expr.args:
            find_rewrites(arg)
        if expr.is_Add or expr.is_Mul:
            if expr not in negations:
                negations[expr] = _negation(expr)
            negated = negations[expr]
            if negated is not None and not negated.is_Atom:
                rewritten[expr] = Unevaluated(sympy.Mul, (sympy.S.NegativeOne, negated))
                seen.add(negated)
                expr = negated
            if (expr.is_Add or expr.is_Mul) and len(expr.args) > 1:
                (adds if expr.is_Add else muls)[expr] = None
        elif expr.is_Pow and _negative_coefficient(expr.exp):
            rewritten[expr] = Unevaluated(sympy.Pow, (sympy.Pow(expr.base, -expr.exp), -1))

    for expr in exprs:
        find_rewrites(expr)
    match_common_args(sympy.Add, list(adds), rewritten)
    match_common_args(sympy.Mul, list(muls), rewritten)

    repeated, reached = set(), set()

    def find_repeated(expr):
        if not isinstance(expr, Unevaluated) and (not isinstance(expr, sympy.Basic) or expr.is_Atom):
            return
        if expr in reached:
            repeated.add(expr)
            return
        reached.add(expr)
        for arg in rewritten.get(expr, expr).args:
            find_repeated(arg)

    for expr in exprs:
        find_repeated(expr)

    replacements, named = [], {}

    def rebuild(expr):
        if not isinstance(expr, Unevaluated) and (not isinstance(expr, sympy.Basic) or not expr.args):
            return expr
        if expr in named:
            return named[expr]
        form = rewritten.get(expr, expr)
        args = [rebuild(arg) for arg in form.args]
        if isinstance(form, Unevaluated):
            new = form.func(*args)
        elif all(new is old for new, old in zip(args, form.args)):
            new = form
        else:
            new = _rebuilt(form, args)
        if expr in repeated:
            symbol = next(symbols)
            named[expr] = symbol
            replacements.append((symbol, new))
            return symbol
        return new

    return replacements, [rebuild(expr) for expr in exprs]


def _negation(expr: sympy.Expr) -> sympy.Expr | None:
    """-expr when sympy's cse would share expr with it (`could_extract_minus_sign`): a
    product with a negative coefficient or a sum with more such terms than others, else None.
    (On a tie sympy compares the sort keys of the sum and its negation; without distribution
    the negation is -1 times the sum, whose key is the larger: never.)"""
    if expr.is_Mul:
        return _negated(expr) if _negative_coefficient(expr) else None
    if 2 * sum(map(_negative_coefficient, expr.args)) <= len(expr.args):
        return None
    return sympy.Add(*(-term for term in expr.args))


def _rebuilt(form: sympy.Basic, args: list) -> sympy.Basic:
    """form with new arguments, without evaluating what cannot change: a function of
    temporaries (a function of numbers was folded before), or a sum or product whose
    arguments cannot combine (no repeats, no nested sum or product of its kind, no number
    after the first). Anything else by sympy's constructor."""
    if isinstance(form, sympy.Function):
        return form.func(*args, evaluate=False)
    if (form.is_Add or form.is_Mul) and len(set(args)) == len(args) and not any(
            arg.func is form.func or (k and arg.is_Number) for k, arg in enumerate(args)):
        return form.func._from_args(args)
    return form.func(*args)
