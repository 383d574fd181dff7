"""The lowering core's operation count: sympy's `count_ops` (the reference every report and
bench quotes), counted by jacgen without building count_ops' intermediate expressions."""

import pytest
import sympy

from jacgen.functions import Generator
from jacgen.lowering import operation_count
from jacgen.robot import load_robot, parse_robot
from jacgen.subproblems import AtLeast, Below, IsFinite, Select
from conftest import ROOT
from random_arms import random_arm_text

x, y, z, w = sympy.symbols("x y z w", real=True)
SHAPES = [
    -x, -x - y, -x + y, x - y, -(x + y) * z, -2 * x * y, 0.5 * x / (y * z), 1 / x, -1 / x, x**-2 * y, 1 / sympy.sqrt(x),
    x ** sympy.Rational(3, 2), sympy.Rational(-3, 4) * x, x / 3, -sympy.sin(x) ** 2 / (1 + y),
    Select(sympy.And(AtLeast(x, 0), Below(y, 1), IsFinite(z)), x * y, -w),
    sympy.Or(sympy.And(AtLeast(x, 0), Below(y, 1)), sympy.Not(IsFinite(z - w))), sympy.true,
]


@pytest.mark.parametrize("expr", SHAPES, ids=str)
def test_counts_as_count_ops(expr):
    assert operation_count([expr]) == sympy.count_ops(expr)


@pytest.mark.parametrize("source", ["ur5", "stanford", "planar_2r", 3, 5])
def test_every_body_counts_as_count_ops(source):
    """Every generated function of shipped and random arms (prismatic joints, symbolic lengths)."""
    robot = load_robot(ROOT / "robots" / f"{source}.yaml") if isinstance(source, str) \
        else parse_robot(random_arm_text(source).encode(), f"arm{source}.yaml")
    for function in Generator(robot).functions():
        body = function.body
        expressions = [e for _, e in body.definitions] + list(body.outputs)
        assert body.operation_count == sympy.count_ops(expressions), function.name
