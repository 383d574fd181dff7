"""Second-order kinematics (contract §2): jacobian_dot, bias_acceleration, task_jacobian_dot,
hessian and fk_jacobian_dot of every shipped robot against Pinocchio, on the DH chain that
tests/support/pinocchio_chain.py builds from the robot file (test_external_libraries checks its
fk and Jacobians), and against the complex-step reference."""

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot

from conftest import ROBOT_NAMES, ROOT
from support.pinocchio_chain import pinocchio_from_dh, robot_of, samples

ATOL = 1e-9


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def rates(name):
    return np.random.default_rng(7).normal(size=samples(name).shape)


def pinocchio_second_order(name):
    """Pinocchio's J' of the tool frame (LOCAL_WORLD_ALIGNED: world axes at the tool origin,
    the rows of our world Jacobian) and our hessian from its joint kinematic Hessian.

    getJointKinematicHessian is for the last joint's frame; the tool frame sits r away on the
    same body, so Jv_tool = Jv_joint - [r]x Jw and, since r turns with the body
    (dr/dq_k = Jw_k x r), d Jv_tool/dq_k = dJv_joint/dq_k - [r]x dJw/dq_k - [Jw_k x r]x Jw.
    Pinocchio 3/4's Python binding hands its (6, n, n) tensor over as the column-major buffer
    under a C-order shape: H(r, c, k) = d J(r, c) / d q_k is recovered by reshaping in F order.
    """
    robot = robot_of(name)
    model = pinocchio_from_dh(robot)
    data = model.createData()
    tool = model.getFrameId("tool")
    joint = model.frames[tool].parentJoint
    jacobian_dots, hessians = [], []
    for q, q_dot in zip(samples(name), rates(name)):
        pin.computeJointJacobiansTimeVariation(model, data, q, q_dot)
        pin.updateFramePlacements(model, data)
        jacobian_dots.append(pin.getFrameJacobianTimeVariation(model, data, tool, pin.LOCAL_WORLD_ALIGNED).copy())
        pin.computeJointJacobians(model, data, q)
        pin.computeJointKinematicHessians(model, data, q)
        pin.updateFramePlacements(model, data)
        tensor = pin.getJointKinematicHessian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
        joint_hessian = np.transpose(np.reshape(tensor.ravel(order="C"), tensor.shape, order="F"), (2, 0, 1))
        J = pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)
        r = data.oMf[tool].translation - data.oMi[joint].translation
        hessians.append([np.vstack([layer[:3] - skew(r) @ layer[3:] - skew(np.cross(J[3:, k], r)) @ J[3:], layer[3:]])
                         for k, layer in enumerate(joint_hessian)])
    return np.array(jacobian_dots), np.array(hessians)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_numpy_against_pinocchio(name, generated):
    module, qs, q_dots = generated.committed(name).python, samples(name), rates(name)
    jacobian_dot, hessian = pinocchio_second_order(name)
    assert_allclose(module.jacobian_dot(qs, q_dots), jacobian_dot, atol=ATOL, rtol=0)
    assert_allclose(module.bias_acceleration(qs, q_dots), np.einsum("krc,kc->kr", jacobian_dot, q_dots), atol=ATOL, rtol=0)
    assert_allclose(module.hessian(qs), hessian, atol=ATOL, rtol=0)
    T, J, a = module.fk_jacobian_dot(qs, q_dots)
    assert_allclose(T, module.fk(qs), atol=1e-12, rtol=0)
    assert_allclose(J, module.jacobian(qs), atol=1e-12, rtol=0)
    assert_allclose(a, module.bias_acceleration(qs, q_dots), atol=1e-12, rtol=0)
    assert module.hessian(qs[0]).shape == (robot_of(name).dof, 6, robot_of(name).dof)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_numpy_task_jacobian_dot_against_reference(name, generated):
    """The reference differentiates its own Euler-rate form of the task Jacobian by complex step."""
    robot, module = robot_of(name), generated.committed(name).python
    for q, q_dot in zip(samples(name), rates(name)):
        rotation = reference.fk(robot, q)[:3, :3]
        if np.hypot(rotation[0, 0], rotation[1, 0]) < 0.05 and set(robot.task) & {"roll", "pitch", "yaw"}:
            continue  # the Euler-angle rates are singular at cos(pitch) = 0
        assert_allclose(module.task_jacobian_dot(q, q_dot), reference.task_jacobian_dot(robot, q, q_dot),
                        atol=ATOL, rtol=0)


def test_task_jacobian_dot_is_the_rate_of_task_jacobian(generated):
    """mu'' = J_a q'' + J_a' q': along a path q(t) = q0 + t v + t^2 w / 2, the second difference
    of mu equals J_a(q0) w + J_a'(q0, v) v."""
    module = generated.committed("stanford").python
    rng = np.random.default_rng(3)
    q0, v, w = rng.uniform(-1, 1, 6), rng.normal(size=6), rng.normal(size=6)
    h = 1e-4
    path = [module.task(q0 + t * v + t * t * w / 2) for t in (-h, 0, h)]
    second = (path[0] - 2 * path[1] + path[2]) / h**2
    assert_allclose(module.task_jacobian(q0) @ w + module.task_jacobian_dot(q0, v) @ v, second, atol=1e-6)


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda"])
def test_c_double_against_pinocchio(name, generated):
    robot = robot_of(name)
    library = generated.committed(name).library("jacobian_dot", "hessian", "fk_jacobian_dot")
    qs, q_dots, n = samples(name), rates(name), robot.dof
    jacobian_dot, hessian = pinocchio_second_order(name)
    assert_allclose(library.evaluate("jacobian_dot", qs, q_dots).reshape(-1, 6, n), jacobian_dot, atol=ATOL, rtol=0)
    assert_allclose(library.evaluate("hessian", qs).reshape(-1, n, 6, n), hessian, atol=ATOL, rtol=0)
    fused = library.evaluate("fk_jacobian_dot", qs, q_dots)
    assert_allclose(fused[:, 16 + 6 * n:], np.einsum("krc,kc->kr", jacobian_dot, q_dots), atol=ATOL, rtol=0)


def test_symbolic_parameters_are_arguments(generated):
    """With a2 and d3 runtime parameters, jacobian_dot and hessian at given values equal the
    reference of the arm with those values written in."""
    text = (ROOT / "robots" / "puma560.yaml").read_text()
    symbolic = text.replace("  a2: 0.4318 ", "  a2: {value: 0.4318, symbolic: true} ").replace(
        "  d3: 0.15005 ", "  d3: {value: 0.15005, symbolic: true} ")
    assert symbolic.count("symbolic: true") == 2
    module = generated(parse_robot(symbolic.encode(), "puma560.yaml")).python
    moved = parse_robot(text.replace("  a2: 0.4318 ", "  a2: 0.5 ").replace("  d3: 0.15005 ", "  d3: 0.1 ").encode())
    for q, q_dot in zip(samples("puma560")[:20], rates("puma560")[:20]):
        assert_allclose(module.jacobian_dot(q, q_dot, a2=0.5, d3=0.1), reference.jacobian_dot(moved, q, q_dot),
                        atol=ATOL, rtol=0)
        assert_allclose(module.hessian(q, a2=0.5, d3=0.1), reference.hessian(moved, q), atol=ATOL, rtol=0)
