"""The lowering core against sympy: its operation count on the value graph against `count_ops`
(the reference every report and bench quotes), its common-subexpression elimination against
`cse`, each on the sympy expression of the same structure (`support.graph_sympy`)."""

import math
import re

import pytest
import sympy
from sympy.core.parameters import distribute

from jacgen.emission.generator import Generator
from jacgen.model.graph import Graph
from jacgen.model.node import AND, OR, Node, evaluate
from jacgen.emission.cse import _reusing_temporaries, eliminate_common
from jacgen.emission.lowering import Lowering
from jacgen.emission.operation_count import operation_count
from jacgen.inputs.robot_file import load_robot, parse_robot
from conftest import ROOT
from support.graph_sympy import kernel_count_ops, to_sympy
from support.random_arms import random_arm_text

x, y, z, w = sympy.symbols("x y z w", real=True)
SHAPES = [
    -x, -x - y, -x + y, x - y, -(x + y) * z, -2 * x * y, 0.5 * x / (y * z), 1 / x, -1 / x, x**-2 * y, 1 / sympy.sqrt(x),
    x ** sympy.Rational(3, 2), sympy.Rational(-3, 4) * x, x / 3, -sympy.sin(x) ** 2 / (1 + y), sympy.true,
]


def _logic_shapes(g: Graph) -> list[Node]:
    """A select of a conjunction, a disjunction with a negation: built on the graph, as the solvers build them."""
    X, Y, Z, W = (g.symbol(s) for s in (x, y, z, w))
    zero, one = g.number(0), g.number(1)
    both = g.logic(AND, g.relation(">=", X, zero), g.relation("<", Y, one))
    return [g.select(g.logic(AND, both, g.finite(Z)), X * Y, -W),
            g.logic(OR, both, g.negation(g.finite(Z - W)))]


@pytest.mark.parametrize("expr", SHAPES, ids=str)
def test_counts_as_count_ops(expr):
    node = Graph().convert(expr)
    assert operation_count([node]) == sympy.count_ops(to_sympy(node))


def test_logic_counts_as_count_ops():
    for node in _logic_shapes(Graph()):
        assert operation_count([node]) == sympy.count_ops(to_sympy(node))


@pytest.mark.parametrize("source", ["ur5", "stanford", "planar_2r", 3, 5])
def test_every_body_counts_as_count_ops(source):
    """Every generated function of shipped and random arms (prismatic joints, symbolic lengths),
    and no temporary is a copy of another (t34 = t33)."""
    robot = load_robot(ROOT / "robots" / f"{source}.yaml") if isinstance(source, str) \
        else parse_robot(random_arm_text(source).encode(), f"arm{source}.yaml")
    for function in Generator(robot).functions():
        body = function.body
        expressions = [e for _, e in body.definitions] + list(body.outputs)
        assert body.operation_count == (sympy.count_ops([to_sympy(e) for e in expressions])
                                        + kernel_count_ops(expressions)), function.name
        assert not [s for s, e in body.definitions if s in body.names and e.kind == "symbol"], function.name


def _dh_chain_jacobian(joints: int) -> list[sympy.Expr]:
    """The position Jacobian of a plain DH chain, written out (shared products, sums with
    negative terms, the shapes CSE works on)."""
    q = sympy.symbols(f"q1:{joints + 1}", real=True)
    transform = sympy.eye(4)
    for k, angle in enumerate(q):
        a, d, alpha = sympy.Rational(k + 2, 7), sympy.Rational(1, k + 3), sympy.pi / (k + 2)
        ct, st, ca, sa = sympy.cos(angle), sympy.sin(angle), sympy.cos(alpha), sympy.sin(alpha)
        transform = transform * sympy.Matrix([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                                              [0, sa, ca, d], [0, 0, 0, 1]])
    position = transform[:3, 3]
    return list(position.jacobian(q)) + list(transform[:3, :3])


COMMON = [x * y + z, -x * y - z, sympy.sin(x * y + z), x + y + z, x + y + w, 1 - x - y - w, 2 * x * y * z, -3 * x * y * w]


@pytest.mark.parametrize("exprs", [SHAPES[:-1] + COMMON,
                                   _dh_chain_jacobian(3), _dh_chain_jacobian(4)], ids=["shapes", "dh3", "dh4"])
def test_eliminate_common_as_sympy_cse(exprs):
    """eliminate_common does at least as well as sympy's cse: no more operations than sympy's
    cse of the same expressions, as sympy writes them and as the graph does (its sums and
    products ordered by when their terms were built), and the same values (at a point)."""
    graph = Graph()
    nodes = [graph.convert(e) for e in exprs]
    replacements, reduced = eliminate_common(graph, nodes, sympy.numbered_symbols("_r", real=True), {})
    ours = operation_count([v for _, v in replacements] + reduced)
    with distribute(False):
        for written in (exprs, [to_sympy(node) for node in nodes]):
            theirs = sympy.cse(written, sympy.numbered_symbols("_s", real=True), order="none")
            assert ours <= sympy.count_ops([v for _, v in theirs[0]] + theirs[1])
    point = {s: 0.1 + 0.37 * k for k, s in enumerate(sorted(set().union(*(e.free_symbols for e in exprs)), key=str))}
    values = dict(point)
    for symbol, value in replacements:
        values[symbol] = evaluate(value, values)
    for node, expected in zip(reduced, exprs):
        assert evaluate(node, values) == pytest.approx(float(sympy.N(expected.subs(point), 30)), rel=1e-12, abs=1e-12)


def test_calls_of_numbers_fold_exactly():
    """A call of numbers is one number, for every function the printers know (floor and ceiling
    are sympy's floor and ceiling): the IK wraps constant angles too."""
    g = Graph()
    assert g.call("Floor", g.value(sympy.Rational(7, 2))).value == 3
    assert g.call("Ceiling", g.value(-2.5)).value == -2
    assert g.call("Abs", g.number(-3)).value == 3
    assert float(g.call("atan2", g.number(1), g.number(1)).value) == pytest.approx(0.7853981633974483, abs=0)


def test_products_and_sums_read_the_temporaries_they_hold():
    """CSE's greedy matching leaves some products holding every factor of a temporary
    (manocha_canny's 0.07*c2*s5*s4**2 beside t = c2*s5): they read it, also through the product
    temporaries they read (a*c*e*r1 with r1 = c*d holds r2 = a*d*e), and sums read the
    temporaries whose terms they hold, with the same values."""
    g = Graph()
    a, b, c, d, e = (g.symbol(s) for s in sympy.symbols("a b c d e", real=True))
    r = sympy.symbols("r0:4", real=True)
    r0, r1, r2, r3 = map(g.symbol, r)
    replacements = [(r[0], a * b), (r[1], c * d), (r[2], a * d * e), (r[3], a + b + c)]
    outputs = [0.5 * a * b * c**2, a * c * e * r1, a + b + c + e, b * d]
    reused, reduced = _reusing_temporaries(g, replacements, outputs)
    assert reduced == [0.5 * r0 * c**2, r2 * c**2, r3 + e, b * d]
    assert reused == replacements
    values = {s: 0.3 + 0.29 * k for k, s in enumerate(sympy.symbols("a b c d e", real=True))}
    for symbol, value in replacements:
        values[symbol] = evaluate(value, values)
    for before, after in zip(outputs, reduced):
        assert evaluate(after, values) == pytest.approx(evaluate(before, values), rel=1e-15)


def test_a_value_and_its_negation_are_named_once():
    """c - a*b built either way (the product negated as a whole, or its factor) is one named
    value, and a*b - c is minus it: the solvers' Householder steps build both."""
    lowering = Lowering()
    g = lowering.graph
    a, b, c = (g.symbol(s) for s in sympy.symbols("a b c", real=True))
    first = lowering.name_node(c + (-a) * b)
    assert lowering.name_node(c - a * b) is first
    assert lowering.name_node(a * b - c) is g.negate(first)
    assert len(lowering.definitions) == 1


def test_a_kernel_runs_as_its_step_written_out():
    """A REPEAT's value (`evaluate`) and its lowered Body are the step applied `count` times,
    as Python runs the same step on floats; a run on constants is folded where it is built."""
    lowering = Lowering()
    g = lowering.graph

    def step(state):  # a rotation by the angle of (3, 4), and a sum
        a, b, c = state
        return [lowering.name_node(0.6 * a - 0.8 * b), lowering.name_node(0.8 * a + 0.6 * b),
                lowering.name_node(c + a * b)]

    X, Y = g.symbol(x), g.symbol(y)
    final = lowering.repeated("turn", "a turn", 5, step, [X, Y, X + Y])
    values = {x: 0.3, y: -1.7}
    a, b, c = values[x], values[y], values[x] + values[y]
    for _ in range(5):
        a, b, c = 0.6 * a - 0.8 * b, 0.8 * a + 0.6 * b, c + a * b
    assert [evaluate(e, values) for e in final] == pytest.approx([a, b, c], rel=1e-14)
    body = lowering.lower(final)
    assert [e.kind for _, e in body.definitions].count("repeat") == 1
    kernel = next(e.value[0] for _, e in body.definitions if e.kind == "repeat")
    assert body.operation_count == 1 + 5 * kernel.body.operation_count  # x + y, then five runs
    folded = lowering.repeated("turn", "a turn", 5, step, [g.number(1), g.number(0), g.number(0)])
    assert all(e.kind == "number" for e in folded)
    assert float(folded[0].value) == pytest.approx(turned_unit_vector(5)[0], rel=1e-14)


def turned_unit_vector(count: int) -> tuple:
    """(cos, sin) of count times the angle of (3, 4): the rotation's first column after count runs."""
    angle = count * math.atan2(0.8, 0.6)
    return math.cos(angle), math.sin(angle)


def test_a_called_kernel_is_one_body_for_every_caller():
    """`called`: one kernel for the same step on two sets of values, each run's value (and its
    Body's) the step's on those values, with fewer outputs than inputs."""
    lowering = Lowering()
    g = lowering.graph

    def step(values):  # the length and the product of a 2-vector
        a, b = values
        return [lowering.name_node(g.sqrt(a * a + b * b)), lowering.name_node(a * b)]

    X, Y = g.symbol(x), g.symbol(y)
    first = lowering.called("measure", "a measure", step, [X, Y])
    second = lowering.called("measure", "a measure", step, [X + Y, X - Y])
    body = lowering.lower(first[:1] + second)
    runs = [e for _, e in body.definitions if e.kind == "repeat"]
    assert len(runs) == 2 and runs[0].value[0] is runs[1].value[0] and len(runs[0].value[0].body.outputs) == 2
    values = {x: 0.3, y: -1.7}
    assert [evaluate(e, values) for e in (*first, *second)] == pytest.approx(
        [math.hypot(0.3, -1.7), 0.3 * -1.7, math.hypot(-1.4, 2.0), -1.4 * 2.0], rel=1e-14)
    with pytest.raises(ValueError, match="maps 2 values to 2, given 3"):
        lowering.called("measure", "a measure", step, [X, Y, X])


def test_each_kernel_is_defined_once_and_loops():
    """ur5.c defines each Jacobi sweep, the round of the 6 x 6 one, the Gram solve (of
    ik_numeric_step, and of velocity_solve: velocity_ik's, which velocity_ik_nullspace and
    resolved_rate call too) and ik_nearest's step over the branches once, as a loop on a state it changes in place, and its functions call
    them: they are not written out."""
    text = (ROOT / "generated" / "ur5" / "ur5.c").read_text()
    for kernel, calls in (("jacgen_jacobi6_rows", 1), ("jacgen_jacobi6_rows_round", 1), ("jacgen_jacobi3_columns_2", 1),
                          ("jacgen_symmetric_solve6", 2),
                          ("jacgen_velocity_solve", 3), ("jacgen_nearer_branch", 8)):
        assert text.count(f"static void {kernel}(int count, {kernel}_state *state)") == 1
        assert len(re.findall(rf"    {kernel}\((\d+), &t\d+\);", text)) == calls, kernel
    assert text.count("for (int run = 0; run < count; run++)") == 6
    assert len(text) < 210_000  # 458 KB with the sweeps written out, 286 KB with the solves
