"""What the Jacobian is for (issue 48), as generated: the textbook facts each function must
hold, checked on the generated numpy module (and the C where the float build matters) against
numpy's SVD, central differences and closed-loop simulation. `jacgen verify` compares every
backend with jacgen/checking/reference.py on every shipped robot."""

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.inputs.robot_file import load_robot, parse_robot
from conftest import ROOT, generated_module

USES = ("fk", "jacobian", "manipulability", "velocity_ik", "link_poses", "link_velocities", "velocity_ellipsoid",
        "condition_number", "manipulability_gradient", "velocity_ik_nullspace", "resolved_rate")


@pytest.fixture(scope="module")
def panda(generated):
    return generated(load_robot(ROOT / "robots/panda.yaml"), ("python", "c"), functions=USES)


@pytest.fixture(scope="module")
def ur5(generated):
    return generated(load_robot(ROOT / "robots/ur5.yaml"), ("python",), functions=USES)


def test_singular_values_keep_every_digit_where_the_eigenvalue_method_loses_half(generated):
    """The planar 2R near stretched out (q2 = 1e-8) and stretched out: the linear block's
    singular values are ~2, ~5e-9 and 0. The generated SVD agrees with numpy's to 1e-12
    (1 + reach) there; sqrt(eig(J J^T)) misses the small one by far more."""
    code = generated(load_robot(ROOT / "robots/planar_2r.yaml"), ("python",), functions=("velocity_ellipsoid",))
    reach = code.robot.reach
    for q2 in (1e-8, 0.0):
        q = np.array([0.4, q2])
        jacobian = reference.jacobian(code.robot, q)
        _, s_v, _, s_w = code.python.velocity_ellipsoid(q)
        for block, values in ((jacobian[:3], s_v), (jacobian[3:], s_w)):
            exact = np.concatenate([np.linalg.svd(block, compute_uv=False), [0.0]])
            assert np.max(np.abs(values - exact)) < 1e-12 * (1 + reach)
        if q2:
            assert 1e-9 < s_v[1] < 1e-8
            squared = np.sqrt(np.abs(np.linalg.eigvalsh(jacobian[:3] @ jacobian[:3].T)))[::-1]
            assert np.abs(squared[1] - s_v[1]) > 1e-10  # the eigenvalue method: not even 1e-10


def test_velocity_and_force_ellipsoids_are_reciprocal(panda):
    """Unit joint rates move the tool by at most s_i along u_i (J^T u_i has length s_i), and the
    force f = u_i / s_i along the same axis needs unit joint torque |J^T f| = 1: the force
    ellipsoid has the axes U and the semi-axes 1/s."""
    q = np.random.default_rng(4).uniform(-1.5, 1.5, size=(50, 7))
    U, s, _, _ = panda.python.velocity_ellipsoid(q)
    linear = reference.jacobian(panda.robot, q)[:, :3]
    along = np.swapaxes(linear, -1, -2) @ U  # column i: J^T u_i
    assert np.allclose(np.linalg.norm(along, axis=-2), s, atol=1e-12)
    assert np.allclose(np.linalg.norm(along / s[:, None, :], axis=-2), 1.0, atol=1e-12)  # J^T (u_i / s_i)
    assert np.allclose(np.swapaxes(U, -1, -2) @ U, np.eye(3), atol=1e-13)
    assert np.allclose(np.linalg.det(U), 1.0, atol=1e-13)
    assert (np.diff(s, axis=-1) <= 0).all()


def test_manipulability_gradient_against_central_differences(panda, ur5):
    for code in (panda, ur5):
        rng = np.random.default_rng(5)
        q = rng.uniform(-1.5, 1.5, size=(40, code.robot.dof))
        step = 1e-6
        differences = np.stack([(code.python.manipulability(q + step * e) - code.python.manipulability(q - step * e))
                                / (2 * step) for e in np.eye(code.robot.dof)], -1)
        assert np.max(np.abs(code.python.manipulability_gradient(q) - differences)) < 1e-8


def test_manipulability_gradient_is_finite_and_zero_at_a_singularity(ur5):
    q = np.array([0.3, -1.1, 1.4, -0.6, 0.0, 0.8])  # wrist singular: det J = 0
    assert ur5.python.manipulability(q) == 0.0
    assert (ur5.python.manipulability_gradient(q) == 0.0).all()
    near = ur5.python.manipulability_gradient(q + [0, 0, 0, 0, 1e-9, 0])
    assert np.isfinite(near).all() and abs(near[4]) > 1e-3  # |w| grows linearly off the singularity


def test_null_space_motion_changes_no_task_velocity(panda):
    rng = np.random.default_rng(6)
    q, mu_dot, z = rng.uniform(-1.5, 1.5, size=(30, 7)), rng.normal(size=(30, 6)), rng.normal(size=(30, 7))
    with_z, status = panda.python.velocity_ik_nullspace(q, mu_dot, z)
    without, _ = panda.python.velocity_ik(q, mu_dot)
    jacobian = reference.jacobian(panda.robot, q)
    assert (status == 0).all()
    assert np.max(np.abs(np.einsum("kij,kj->ki", jacobian, with_z) - mu_dot)) < 1e-9
    assert np.max(np.abs(np.einsum("kij,kj->ki", jacobian, with_z - without))) < 1e-9  # self-motion only
    moved = with_z - without  # = (I - J^+ J) z, the projection of z
    projector = np.eye(7) - np.linalg.pinv(jacobian) @ jacobian
    # one solve of J J^T: rounding times the square of J's condition number (3e-9 at kappa 3.5e3)
    bound = 1e-14 * np.linalg.cond(jacobian) ** 2 * (1 + np.abs(z).max(axis=1))
    assert (np.abs(moved - np.einsum("kij,kj->ki", projector, z)).max(axis=1) < bound).all()
    same = np.abs(panda.python.velocity_ik_nullspace(q, mu_dot, 0 * z)[0] - without).max(axis=1)
    assert (same < 1e-14 * np.linalg.cond(jacobian) ** 2 * (1 + np.abs(without).max(axis=1))).all()


def test_null_space_of_a_square_jacobian_is_zero(ur5):
    q = np.array([0.3, -1.1, 1.4, -0.6, 0.7, 0.8])
    mu_dot, z = np.arange(6.0), np.ones(6)
    assert np.array_equal(ur5.python.velocity_ik_nullspace(q, mu_dot, z)[0], ur5.python.velocity_ik(q, mu_dot)[0])


def test_non_finite_input_gives_status_2(panda):
    q = np.zeros(7)
    for bad in ({"z": [np.nan] + [0] * 6}, {"mu_dot": [np.inf] + [0] * 5}):
        arguments = {"q": q, "mu_dot": np.zeros(6), "z": np.zeros(7)} | bad
        q_dot, status = panda.python.velocity_ik_nullspace(**arguments)
        assert status == 2 and (q_dot == 0).all()
    q_dot, status = panda.python.resolved_rate(q, np.eye(4), np.zeros(6), np.nan, np.zeros(7))
    assert status == 2 and (q_dot == 0).all()
    assert np.isnan(panda.python.condition_number([np.nan] * 7))


def _simulate(code, q, target, dt=1e-3, steps=400, gain=20.0, z=None):
    """q += dt q_dot under resolved_rate toward target(t) (a pose and its twist); the pose errors."""
    errors = []
    for k in range(steps):
        pose, twist = target(k * dt)
        q_dot, status = code.python.resolved_rate(q, pose, twist, gain, np.zeros(7) if z is None else z(q))
        assert status == 0
        q = q + dt * q_dot
        reached = reference.fk(code.robot, q)
        errors.append(np.linalg.norm(reached[:3, 3] - target((k + 1) * dt)[0][:3, 3]))
    return np.array(errors), q


def test_resolved_rate_converges_at_the_rate_the_gain_sets(panda):
    q0 = np.array([0.0, -0.4, 0.0, -2.2, 0.0, 1.9, 0.8])
    goal = reference.fk(panda.robot, q0 + 0.05)
    errors, _ = _simulate(panda, q0, lambda t: (goal, np.zeros(6)), gain=20.0)
    # e' = -K e: after t the error is e0 exp(-K t); Euler steps of dt give (1 - K dt)^k.
    ratio = errors[299] / errors[99]
    assert ratio == pytest.approx((1 - 20.0 * 1e-3) ** 200, rel=0.02)


def test_resolved_rate_follows_a_moving_target_with_feedforward(panda):
    q0 = np.array([0.0, -0.4, 0.0, -2.2, 0.0, 1.9, 0.8])
    start = reference.fk(panda.robot, q0)
    speed = np.array([0.1, -0.05, 0.08])

    def target(t):
        pose = start.copy()
        pose[:3, 3] += speed * t
        return pose, np.concatenate([speed, np.zeros(3)])

    errors, _ = _simulate(panda, q0, target, gain=50.0)
    assert errors.max() < 1e-5  # first-order Euler error only: no lag
    lagging, _ = _simulate(panda, q0, lambda t: (target(t)[0], np.zeros(6)), gain=50.0)
    assert lagging[-1] > 1e-3  # without the feedforward, the error settles at |v| / K


def test_gain_is_a_number_or_one_per_component(panda):
    q = np.array([0.0, -0.4, 0.0, -2.2, 0.0, 1.9, 0.8])
    goal = reference.fk(panda.robot, q + 0.01)
    one = panda.python.resolved_rate(q, goal, np.zeros(6), 3.0, np.zeros(7))[0]
    each = panda.python.resolved_rate(q, goal, np.zeros(6), np.full(6, 3.0), np.zeros(7))[0]
    assert np.array_equal(one, each)
    with pytest.raises(ValueError):
        panda.python.resolved_rate(q, goal, np.zeros(6), np.ones(5), np.zeros(7))


def test_link_poses_end_at_the_tool_and_velocities_match_the_jacobian(panda):
    rng = np.random.default_rng(7)
    q, q_dot = rng.uniform(-1.5, 1.5, size=(20, 7)), rng.normal(size=(20, 7))
    frames = panda.python.link_poses(q)
    tool = np.linalg.inv(frames[:, -1]) @ reference.fk(panda.robot, q)
    assert np.allclose(tool, reference._pose(panda.robot.tool), atol=1e-12)
    velocities = panda.python.link_velocities(q, q_dot)
    twist = np.einsum("kij,kj->ki", reference.jacobian(panda.robot, q), q_dot)  # of the tool point
    lever = reference.fk(panda.robot, q)[:, :3, 3] - frames[:, -1, :3, 3]
    assert np.allclose(velocities[:, -1, 3:], twist[:, 3:], atol=1e-12)
    assert np.allclose(velocities[:, -1, :3] + np.cross(velocities[:, -1, 3:], lever), twist[:, :3], atol=1e-12)


def test_c_agrees_with_the_svd_in_double_and_float(panda):
    q = np.random.default_rng(8).uniform(-1.5, 1.5, size=(20, 7)).astype(np.float32).astype(float)
    library = panda.library("velocity_ellipsoid")
    for row in q:
        _, s_v, _, s_w = library.call("velocity_ellipsoid", row)
        jacobian = reference.jacobian(panda.robot, row)
        assert np.max(np.abs(np.concatenate([s_v, s_w]) - np.concatenate(
            [np.linalg.svd(jacobian[:3], compute_uv=False), np.linalg.svd(jacobian[3:], compute_uv=False)]))) < 1e-12


def test_planar_2r_condition_number_is_1_at_its_isotropic_configuration(generated):
    text = b"""name: iso2r
convention: standard
joints:
  - {name: shoulder, type: revolute, a: 1.4142135623730951, alpha: 0, d: 0}
  - {name: elbow, type: revolute, a: 1.0, alpha: 0, d: 0}
task: [x, y]
"""
    code = generated(parse_robot(text, "iso2r.yaml"), ("python",), functions=("condition_number",))
    kappa = code.python.condition_number(np.array([[0.3, 3 * np.pi / 4], [1.0, -3 * np.pi / 4], [0.3, 1.0]]))
    assert kappa[:2] == pytest.approx(1.0, abs=1e-12)
    assert kappa[2] > 1.5
    assert code.python.condition_number([0.3, 0.0]) == np.inf  # stretched out: singular


NEW = {"link_poses": lambda q, rng: (q,), "link_velocities": lambda q, rng: (q, rng.normal(size=q.shape)),
       "velocity_ellipsoid": lambda q, rng: (q,), "condition_number": lambda q, rng: (q,),
       "manipulability_gradient": lambda q, rng: (q,),
       "velocity_ik_nullspace": lambda q, rng: (q, rng.normal(size=(len(q), 6)), rng.normal(size=q.shape)),
       "resolved_rate": lambda q, rng: (q, np.tile(np.eye(4), (len(q), 1, 1)), rng.normal(size=(len(q), 6)),
                                        np.full((len(q), 6), 2.0), rng.normal(size=q.shape))}


@pytest.mark.parametrize("lib", ["jax", "torch"])
def test_jax_and_pytorch_give_numpy_numbers_and_gradients(lib):
    """Each new function on JAX arrays (eager, jit, vmap) and PyTorch tensors gives NAME.py's numpy
    numbers; autodiff of manipulability equals the generated manipulability_gradient, and of
    condition_number central differences."""
    module, rng = generated_module("panda"), np.random.default_rng(9)
    q = rng.uniform(-1.5, 1.5, size=(8, 7))
    if lib == "jax":
        jax = pytest.importorskip("jax")
        jax.config.update("jax_enable_x64", True)  # float64, as numpy
        to, back, transforms = jax.numpy.asarray, np.asarray, (lambda f: f, jax.jit, jax.vmap)
    else:
        torch = pytest.importorskip("torch")
        to, back, transforms = torch.from_numpy, lambda t: t.detach().numpy(), (lambda f: f,)
    for function, arguments in NEW.items():
        given = arguments(q, rng)
        expected = getattr(module, function)(*given)
        expected = expected if isinstance(expected, tuple) else (expected,)
        for transform in transforms:
            found = transform(getattr(module, function))(*map(to, given))
            for a, b in zip(expected, found if isinstance(found, tuple) else (found,)):
                np.testing.assert_allclose(back(b), a, atol=1e-9, rtol=1e-9, err_msg=function)
    for row in q[:3]:
        if lib == "jax":
            gradient = np.asarray(jax.grad(module.manipulability)(jax.numpy.asarray(row)))
            kappa = np.asarray(jax.grad(module.condition_number)(jax.numpy.asarray(row)))
        else:
            x = torch.tensor(row, requires_grad=True)
            module.manipulability(x).backward()
            gradient = x.grad.numpy()
            y = torch.tensor(row, requires_grad=True)
            module.condition_number(y).backward()
            kappa = y.grad.numpy()
        np.testing.assert_allclose(gradient, module.manipulability_gradient(row), atol=1e-10)
        differences = np.array([(module.condition_number(row + 1e-6 * e) - module.condition_number(row - 1e-6 * e))
                                / 2e-6 for e in np.eye(7)])
        np.testing.assert_allclose(kappa, differences, rtol=1e-5, atol=1e-6)
