"""A value-graph node (jacgen.model.graph) as the sympy expression of the same structure,
built without evaluation, so that sympy's own `count_ops` and `cse` can be the reference for
the graph's operation count and common-subexpression elimination."""

from fractions import Fraction

import sympy
from sympy.logic.boolalg import BooleanFunction

from jacgen.model import graph
from jacgen.model import node as kinds


class Select(sympy.Function):
    """A select, as sympy counts it: a function of its conditions and values."""


class IsFinite(BooleanFunction):
    """isfinite(x), as sympy counts it: a function of x."""


CALLS = {"Floor": sympy.floor, "Ceiling": sympy.ceiling}
RELATIONS = {">=": sympy.Ge, ">": sympy.Gt, "<=": sympy.Le, "<": sympy.Lt, "==": sympy.Eq, "!=": sympy.Ne}


def to_sympy(node: kinds.Node, _done: dict | None = None) -> sympy.Basic:
    done = {} if _done is None else _done
    if node in done:
        return done[node]
    kind, value = node.kind, node.value
    args = [to_sympy(arg, done) for arg in node.args]
    if kind == kinds.NUMBER:
        result = sympy.Float(float(value)) if isinstance(value, Fraction) else sympy.sympify(value)
    elif kind == kinds.SYMBOL:
        result = value
    elif kind == kinds.TRUTH:
        result = sympy.true if value else sympy.false
    elif kind == kinds.ADD:
        result = sympy.Add(*args, evaluate=False)
    elif kind == kinds.MUL:
        result = sympy.Mul(*args, evaluate=False)
    elif kind == kinds.POW:
        result = sympy.Pow(*args, evaluate=False)
    elif kind == kinds.CALL:
        result = (CALLS[value] if value in CALLS else getattr(sympy, value))(*args, evaluate=False)
    elif kind == kinds.SELECT:
        result = Select(*args, evaluate=False)
    elif kind == kinds.RELATION:
        result = RELATIONS[value](*args, evaluate=False)
    elif kind == kinds.FINITE:
        result = IsFinite(*args)
    elif kind == kinds.REPEAT:  # the state it starts from (its kernel's runs: `kernel_count_ops`)
        result = sympy.Tuple(*args)
    elif kind == kinds.PART:  # an entry of a state: no operation
        result = sympy.Symbol(f"part{value}_of_{args[0]}")
    else:
        result = {kinds.AND: sympy.And, kinds.OR: sympy.Or, kinds.NOT: sympy.Not}[kind](*args, evaluate=False)
    done[node] = result
    return result


def kernel_count_ops(expressions) -> int:
    """sympy's count_ops of the kernels' runs in `expressions` (each REPEAT: its count times its
    step's lowered definitions and outputs), which `to_sympy` leaves out."""
    total, seen = 0, set()

    def walk(node):
        nonlocal total
        if node in seen:
            return
        seen.add(node)
        if node.kind == kinds.REPEAT:
            kernel, count = node.value
            step = [value for _, value in kernel.body.definitions] + list(kernel.body.outputs)
            total += count * (sympy.count_ops([to_sympy(e) for e in step]) + kernel_count_ops(step))
        for arg in node.args:
            walk(arg)

    for expression in expressions:
        walk(expression)
    return total


def printed(printer, expr: sympy.Basic) -> str:
    """What `printer` prints for a sympy expression, taken onto a graph of its own."""
    return printer.doprint(graph.Graph().convert(expr))
