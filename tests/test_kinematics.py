"""The symbolic core against itself (two derivations of the Jacobian) and the reference."""

import numpy as np
import pytest
import sympy

from jacgen import Kinematics
from jacgen.model import kinematics
from jacgen.checking import reference
from jacgen.emission.generator import Generator
from jacgen.model.node import evaluate

from conftest import ROBOT_NAMES, random_configurations, robot

# The readable matrices (expanded, trig sums collapsed) of arms with at most 6 joints and twists
# that are multiples of 90 degrees: the Jaco's 60 degrees or a calibrated arm's twists expand into
# sums of hundreds of terms (a minute of sympy); the emitted chain of every arm is tested below.
SMALL_ROBOTS = [name for name in ROBOT_NAMES if robot(name).dof <= 6
                and all(float(joint.alpha.exact / sympy.pi * 2).is_integer() for joint in robot(name).joints)]


def vanishes(matrix: sympy.Matrix, q) -> bool:
    """Whether every entry of `matrix` is identically zero in the joint angles q: the sines and
    cosines of joint sums expanded, then each angle written through t = tan(q/2) (cos = (1 -
    t^2)/(1 + t^2), sin = 2t/(1 + t^2)), a rational function that cancels to 0 exactly when the
    entry is zero. sympy.trigsimp decided planar_3r's in 4 s or in 122 s by the hash seed."""
    half_angle = {}
    for angle, t in zip(q, sympy.symbols(f"t1:{len(q) + 1}")):
        half_angle[sympy.cos(angle)] = (1 - t**2) / (1 + t**2)
        half_angle[sympy.sin(angle)] = 2 * t / (1 + t**2)
    return all(sympy.cancel(sympy.expand_trig(entry).xreplace(half_angle)) == 0 for entry in matrix)


def numeric(matrix: sympy.Matrix, symbols):
    function = sympy.lambdify(symbols, matrix, "numpy")
    return lambda values: np.array(function(*values), dtype=float)


@pytest.mark.parametrize("name", SMALL_ROBOTS)
def test_readable_matrices_match_reference(name):
    arm = robot(name)
    kin = Kinematics(arm)
    fk, jacobian, jacobian_tool = (numeric(m, kin.q) for m in (kin.fk, kin.jacobian, kin.jacobian_tool))
    for q in random_configurations(arm, 20, seed=1):
        np.testing.assert_allclose(fk(q), reference.fk(arm, q), atol=1e-12, rtol=0)
        np.testing.assert_allclose(jacobian(q), reference.jacobian(arm, q), atol=1e-12, rtol=0)
        np.testing.assert_allclose(jacobian_tool(q), reference.jacobian_tool(arm, q), atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_column_formula_agrees_with_velocity_propagation(name):
    """Two independent derivations of the tool-frame Jacobian, on the emitted (trig-symbol) chain."""
    arm = robot(name)
    generator = Generator(arm)
    by_columns = kinematics.tool_frame(generator.jacobian, generator.chain.tool)
    by_propagation = kinematics.propagated_jacobian_tool(arm, lambda i: generator.cos_sin((i,)), generator.q)
    symbols = [s for s, _ in generator.lowering.definitions] + list(generator.q)
    by_columns, by_propagation = numeric(by_columns, symbols), numeric(by_propagation, symbols)
    for q in random_configurations(arm, 10, seed=2):
        known = dict(zip(generator.q, q))
        for symbol, value in generator.lowering.definitions:  # in order: sums after their terms
            known[symbol] = evaluate(value, known)
        values = [known[s] for s in symbols]
        np.testing.assert_allclose(by_columns(values), by_propagation(values), atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", ["planar_2r", "planar_3r", "scara", "rexarm"])
def test_two_derivations_are_symbolically_equal(name):
    kin = Kinematics(robot(name))
    by_columns = kinematics.tool_frame(kin.jacobian, kin.fk)
    assert vanishes(by_columns - kin.jacobian_tool, kin.q)


@pytest.mark.parametrize("name", ["planar_2r", "planar_3r", "scara", "rexarm", "puma560", "stanford", "ur5"])
def test_linear_rows_are_the_derivative_of_the_position(name):
    kin = Kinematics(robot(name))
    derivative = kin.fk[:3, 3].jacobian(kin.q)
    difference = (derivative - kin.jacobian[:3, :]).applyfunc(kinematics.simplify_trig)
    assert difference.applyfunc(sympy.trigsimp) == sympy.zeros(3, kin.robot.dof)


def test_planar_2r_closed_form():
    """Spong's planar 2R: x = l1 c1 + l2 c12, and the Jacobian the textbook writes."""
    kin = Kinematics(robot("planar_2r"))
    q1, q2 = kin.q
    l1 = l2 = 1
    assert sympy.simplify(kin.fk[0, 3] - (l1 * sympy.cos(q1) + l2 * sympy.cos(q1 + q2))) == 0
    expected = sympy.Matrix([[-l1 * sympy.sin(q1) - l2 * sympy.sin(q1 + q2), -l2 * sympy.sin(q1 + q2)],
                             [l1 * sympy.cos(q1) + l2 * sympy.cos(q1 + q2), l2 * sympy.cos(q1 + q2)]])
    assert (kin.task_jacobian - expected).applyfunc(sympy.simplify) == sympy.zeros(2, 2)


def test_parallel_axes_share_one_rotation():
    """UR5's three parallel pitch joints: the emitted fk computes cos(q2+q3+q4) once, from products."""
    generator = Generator(robot("ur5"))
    names = {str(symbol) for symbol, _ in generator.lowering.definitions}
    assert {"c23", "s23", "c234", "s234"} <= names
