"""The CasADi backend: casadi.Function objects that match jacgen.reference, and whose
symbolic derivatives agree with the generated Jacobians."""

import casadi
import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose

from jacgen.checking import reference
from jacgen.emission.backends.casadi import CasadiPrinter
from jacgen.model.graph import Graph
from jacgen.model.node import AND
from jacgen.inputs.robot_file import load_robot
from jacgen.checking.dexterity_checks import CHECKED_HERE
from jacgen.checking.verify import compare

from conftest import random_configurations, robot as shipped_robot
from support.graph_sympy import printed
from support.robot_texts import PARAMETRIC

SAMPLES = 25


def _code(generated, name):
    """The shipped robot's CasADi and numpy code, generated once in this module."""
    return generated(shipped_robot(name), ("casadi", "python"))


def _as_list(result):
    """A casadi.Function returns one DM, or a tuple of them for several outputs."""
    return result if isinstance(result, tuple) else (result,)


# One shipped robot of each IK class. Every shipped robot's CasADi functions are compared with
# the reference by `jacgen verify` in tests/test_shipped_robots.py.
ONE_OF_EACH_CLASS = ["planar_2r", "scara", "rexarm", "puma560", "ur5", "stanford", "panda", "jaco"]


@pytest.mark.parametrize("name", ONE_OF_EACH_CLASS)
def test_functions_match_reference(name, generated):
    """Every function's name, inputs and output shapes; its values against jacgen.reference,
    or, where the reference lacks it (manipulability...), against the generated numpy module,
    which prints the same expressions another way."""
    code = _code(generated, name)
    robot, functions, module, numpy_module = code.robot, code.generator.without_loops(), code.casadi, code.python
    names = [f.name for f in functions]
    assert list(module.functions()) == names + ["ik"] * ("ik_branches" in names) + ["ik_numeric"]
    q = random_configurations(robot, SAMPLES, seed=5)
    # ik, velocity_ik: test_ik_contract; the SVDs and the gradient: verify's own checks (CHECKED_HERE), below
    for function in [f for f in functions if [a.name for a in f.arguments] == ["q"] and f.name not in CHECKED_HERE]:
        generated_function = module.functions()[function.name]
        assert isinstance(generated_function, casadi.Function) and generated_function.name() == function.name
        assert generated_function.name_in() == ["q"] and generated_function.size_in(0) == (robot.dof, 1)
        assert [generated_function.size_out(k) for k in range(len(function.outputs))] == [
            (output.rows, output.cols) for output in function.outputs]
        value = np.array([np.concatenate([np.asarray(result).ravel() for result in _as_list(generated_function(row))])
                          for row in q])
        if all(hasattr(reference, output.result_of or function.name) for output in function.outputs):
            expected = np.array([np.concatenate([np.ravel(getattr(reference, output.result_of or function.name)(robot, row))
                                                 for output in function.outputs]) for row in q])
        else:
            expected = np.reshape(getattr(numpy_module, function.name)(q), value.shape)
        error, _ = compare(robot, function, value, expected, q)
        assert error <= 1e-9, (function.name, error)
    for name_checked in CHECKED_HERE:  # the same numbers as the numpy module, which verify compares
        found = _as_list(module.functions()[name_checked](q[0]))
        expected = getattr(numpy_module, name_checked)(q[0])
        for a, b in zip(found, expected if isinstance(expected, tuple) else (expected,)):
            assert_allclose(np.reshape(np.asarray(a), np.shape(b)), b, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ["puma560", "stanford", "panda", "scara"])
def test_derivative_of_fk_position_is_the_linear_jacobian(name, generated):
    code = _code(generated, name)
    robot, module = code.robot, code.casadi
    q = casadi.SX.sym("q", robot.dof)
    derivative = casadi.Function("d", [q], [casadi.jacobian(module.fk(q)[0:3, 3], q)])
    for row in random_configurations(robot, 10, seed=6):
        linear = np.asarray(module.jacobian(row))[:3]
        assert_allclose(np.asarray(derivative(row)), linear, atol=1e-12)
        assert_allclose(linear, reference.jacobian(robot, row)[:3], atol=1e-12)


def test_runtime_parameters_are_input_p(tmp_path, generated):
    path = tmp_path / "lifted.yaml"
    path.write_text(PARAMETRIC)
    robot = load_robot(path)
    module = generated(robot, ("casadi",)).casadi
    assert module.PARAMETERS == {"height": 0.25, "shift": -0.1}
    moved_path = tmp_path / "moved.yaml"
    moved_path.write_text(PARAMETRIC.replace("height: {value: 0.25, symbolic: true}", "height: 0.75"))
    moved = load_robot(moved_path)
    for row in random_configurations(robot, 10, seed=7):
        assert module.fk.name_in() == ["q", "p"]
        assert_allclose(np.asarray(module.fk(row, [0.25, -0.1])), reference.fk(robot, row), atol=1e-12)
        assert_allclose(np.asarray(module.fk(row, [0.75, -0.1])), reference.fk(moved, row), atol=1e-12)
        assert_allclose(np.asarray(module.jacobian(row, [0.75, -0.1])), reference.jacobian(moved, row), atol=1e-12)


def test_printer():
    x, y = sympy.symbols("x y", real=True)
    printer = CasadiPrinter()
    assert printed(printer, sympy.atan2(x, sympy.sqrt(y)) + 0.4318 / x**2) == \
        "0.4318/x**2 + casadi.atan2(x, casadi.sqrt(y))"  # terms in sympy's stored order
    g = Graph()
    X, Y = g.symbol(x), g.symbol(y)
    assert printer.doprint(g.select(g.logic(AND, g.relation(">", X, g.number(0)), g.relation("<=", Y, g.number(1))),
                                    X, Y)) == "casadi.if_else(casadi.logic_and((x > 0), (y <= 1)), x, y)"
    for unsupported in (sympy.gamma(x), sympy.Mod(x, y), sympy.Max(x, y)):
        with pytest.raises(Exception, match="[Uu]nsupported|not supported"):
            printed(printer, unsupported)
