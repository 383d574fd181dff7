"""The reference's link frames and dexterity functions (issue 48) against independent truths:
Pinocchio's frame placements and velocities, Robotics Toolbox's manipulability and `jacobm`,
central differences, closed forms of the planar 2R arm, scipy's rotation vectors; and the
checks `jacgen verify` runs on them (`dexterity_checks`), fed right and wrong answers."""

import math
import warnings
from fractions import Fraction

import numpy as np
import pytest
from numpy.testing import assert_allclose

from jacgen.checking import reference
from jacgen.checking.dexterity_checks import characteristic_length, dexterity_results, ellipsoid_error
from jacgen.inputs.robot_file import parse_robot

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    rtb = pytest.importorskip("roboticstoolbox")
    pin = pytest.importorskip("pinocchio")
    from scipy.spatial.transform import Rotation

from support.pinocchio_chain import pinocchio_from_dh, robot_of, samples  # noqa: E402

ROBOT_NAMES = ("ur5", "panda", "puma560", "stanford", "scara", "planar_3r", "rexarm", "iiwa", "kr5")
# rtb's models of the shipped arms whose fk and jacob0 equal ours (tests/test_external_libraries.py)
RTB_MODELS = {"ur5": lambda: rtb.models.DH.UR5(), "panda": lambda: rtb.models.DH.Panda(),
              "puma560": lambda: rtb.models.DH.Puma560(), "stanford": lambda: rtb.models.DH.Stanford()}
ATOL = 1e-9
# A 2-joint arm with a three-component task: Js is tall (m > n).
TALL_ARM = b"""name: tall
convention: standard
joints:
  - {type: revolute, a: 0.3, alpha: 1.5707963267948966, d: 0.2, offset: 0}
  - {type: revolute, a: 0.25, alpha: 0, d: 0, offset: 0}
task: [x, y, z]
"""

# A 4-joint arm with the task z and the three angles.
WRIST_ARM = b"""name: wrist
convention: standard
joints:
  - {type: prismatic, a: 0, alpha: 0, theta: 0, offset: 0.1, limits: [0, 0.5]}
  - {type: revolute, a: 0, alpha: 1.5707963267948966, d: 0.2, offset: 0}
  - {type: revolute, a: 0, alpha: -1.5707963267948966, d: 0, offset: 0}
  - {type: revolute, a: 0, alpha: 0, d: 0.1, offset: 0}
task: [z, roll, pitch, yaw]
"""


def rtb_model(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return RTB_MODELS[name]()


def regular_samples(robot, qs, ratio=1e-2):
    """The configurations whose Js has smallest / largest singular value above `ratio`."""
    values = np.linalg.svd(reference.singularity_jacobian(robot, qs), compute_uv=False)
    return qs[values[:, -1] > ratio * values[:, 0]]


def planar_2r_singular_values(q2, a1=1.0, a2=1.0):
    """The singular values of the planar 2R arm's 2 x 2 position Jacobian: s1^2 + s2^2 = |J|_F^2
    = a1^2 + 2 a2^2 + 2 a1 a2 cos q2 and s1 s2 = |det J| = a1 a2 |sin q2|."""
    frobenius = a1**2 + 2 * a2**2 + 2 * a1 * a2 * math.cos(q2)
    det = a1 * a2 * abs(math.sin(q2))
    root = math.sqrt(frobenius**2 - 4 * det**2)
    return math.sqrt((frobenius + root) / 2), 2 * det / math.sqrt(2 * (frobenius + root))


# -- link frames against Pinocchio ----------------------------------------------------------
@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_link_poses_and_velocities_against_pinocchio(name):
    robot = robot_of(name)
    model = pinocchio_from_dh(robot)
    data = model.createData()
    frames = [model.getFrameId(f"link_{i}") for i in range(1, robot.dof + 1)]
    qs = samples(name)[:50]
    q_dots = np.random.default_rng(5).normal(size=qs.shape)
    poses, velocities = reference.link_poses(robot, qs), reference.link_velocities(robot, qs, q_dots)
    assert poses.shape == (len(qs), robot.dof, 4, 4) and velocities.shape == (len(qs), robot.dof, 6)
    for q, q_dot, pose, velocity in zip(qs, q_dots, poses, velocities):
        pin.forwardKinematics(model, data, q, q_dot)
        pin.updateFramePlacements(model, data)
        assert_allclose(pose, [data.oMf[frame].homogeneous for frame in frames], atol=ATOL, rtol=0)
        assert_allclose(velocity, [pin.getFrameVelocity(model, data, frame, pin.LOCAL_WORLD_ALIGNED).vector
                                   for frame in frames], atol=ATOL, rtol=0)
    # the last link frame carries the tool: its velocity at the tool's origin is J q_dot
    tool_offset = reference.fk(robot, qs)[:, :3, 3] - poses[:, -1, :3, 3]
    at_tool = velocities[:, -1, :3] + np.cross(velocities[:, -1, 3:], tool_offset)
    assert_allclose(at_tool, (reference.jacobian(robot, qs) @ q_dots[..., None])[..., :3, 0], atol=ATOL, rtol=0)


# -- the velocity ellipsoid -------------------------------------------------------------------
def test_velocity_ellipsoid_of_the_planar_2r_arm_in_closed_form():
    robot = robot_of("planar_2r")
    for q2 in (0.3, 1.0, 2.5, -1.2, 1e-8):
        U_v, s_v, U_w, s_w = reference.velocity_ellipsoid(robot, np.array([0.7, q2]))
        assert_allclose(s_v, [*planar_2r_singular_values(q2), 0.0], atol=1e-15, rtol=0)
        assert_allclose(s_w, [math.sqrt(2), 0.0, 0.0], atol=1e-15, rtol=0)
        assert_allclose(abs(U_v[2, 2]), 1.0, atol=1e-15)  # the plane's normal takes the zero value
        assert_allclose(abs(U_w[2, 0]), 1.0, atol=1e-15)  # the angular rates are all about z
        for U in (U_v, U_w):
            assert_allclose(U.T @ U, np.eye(3), atol=1e-15)
            assert np.linalg.det(U) == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("name", sorted(RTB_MODELS))
def test_velocity_ellipsoid_against_robotics_toolbox(name):
    """rtb's Yoshikawa manipulability of the linear and angular rows is the product of their
    singular values, and U diag(s^2) U^T is J J^T of rtb's jacob0."""
    robot, model = robot_of(name), rtb_model(name)
    qs = samples(name)[:50]
    U_v, s_v, U_w, s_w = reference.velocity_ellipsoid(robot, qs)
    for k, q in enumerate(qs):
        J = model.jacob0(q)
        assert np.prod(s_v[k]) == pytest.approx(model.manipulability(q, axes="trans"), abs=ATOL)
        assert np.prod(s_w[k]) == pytest.approx(model.manipulability(q, axes="rot"), abs=ATOL)
        assert_allclose(U_v[k] * s_v[k] ** 2 @ U_v[k].T, J[:3] @ J[:3].T, atol=ATOL, rtol=0)
        assert_allclose(U_w[k] * s_w[k] ** 2 @ U_w[k].T, J[3:] @ J[3:].T, atol=ATOL, rtol=0)
    assert (np.diff(s_v, axis=1) <= 0).all() and (np.diff(s_w, axis=1) <= 0).all()
    assert_allclose(np.linalg.det(U_v), 1.0, atol=1e-14)
    assert_allclose(np.linalg.det(U_w), 1.0, atol=1e-14)


def rational_rotation(first, second):
    """An exact rotation: Rz by the angle of the Pythagorean triple `first`, then Rx by `second`."""
    (a, b, c), (d, e, f) = first, second
    z = [[Fraction(a, c), Fraction(-b, c), 0], [Fraction(b, c), Fraction(a, c), 0], [0, 0, 1]]
    x = [[1, 0, 0], [0, Fraction(d, f), Fraction(-e, f)], [0, Fraction(e, f), Fraction(d, f)]]
    return [[sum(z[i][k] * x[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def test_eigenvalues_of_j_jt_lose_half_the_digits_of_a_small_singular_value():
    """Why the ellipsoid is an SVD: A = U diag(2, 1, 1e-8) V^T, built exactly from rational
    orthogonal factors and rounded once, has singular values within |A - fl(A)| ~ 1e-16 of those
    (Weyl). The SVD finds the smallest to ~1e-16; sqrt(eigvalsh(A A^T)) only to ~1e-8, since
    A A^T's eigenvalue 1e-16 is below its rounding (eps |A|^2 ~ 1e-15)."""
    U, V = rational_rotation((3, 4, 5), (5, 12, 13)), rational_rotation((8, 15, 17), (7, 24, 25))
    values = [Fraction(2), Fraction(1), Fraction(1, 10**8)]
    exact = [[sum(U[i][k] * values[k] * V[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
    A = np.array(exact, dtype=float)
    truth = np.array([float(v) for v in values])
    by_svd = np.linalg.svd(A, compute_uv=False)
    by_eigenvalues = np.sqrt(np.clip(np.linalg.eigvalsh(A @ A.T)[::-1], 0, None))
    assert np.max(np.abs(by_svd - truth)) < 1e-15
    assert abs(by_eigenvalues[2] - truth[2]) > 1e-10


def test_ellipsoid_check_accepts_any_signs_and_refuses_the_eigenvalue_method():
    """verify's check of velocity_ellipsoid: the reference with two columns' signs flipped (U
    stays a rotation) passes at 1e-15; singular values from the eigenvalues of J J^T fail near
    the planar arm's singularity (q2 = 1e-8: s_v = (2, 5e-9, 0))."""
    robot = robot_of("planar_2r")
    qs = np.array([[0.7, 1e-8], [0.2, 1.3], [-1.0, 2.9]])
    U_v, s_v, U_w, s_w = reference.velocity_ellipsoid(robot, qs)
    flipped = U_v * [-1, -1, 1], U_w * [1, -1, -1]
    assert ellipsoid_error(robot, (flipped[0], s_v, flipped[1], s_w), qs) < 1e-15
    J = reference.jacobian(robot, qs)
    by_eigenvalues = np.sqrt(np.clip(np.linalg.eigvalsh(J[:, :3] @ np.swapaxes(J[:, :3], 1, 2))[:, ::-1], 0, None))
    assert ellipsoid_error(robot, (U_v, by_eigenvalues, U_w, s_w), qs) > 1e-9
    wrong = U_v.copy()
    wrong[:, :, [0, 1]] = wrong[:, :, [1, 0]] * [1, -1]  # the first two axes exchanged: still a rotation
    assert ellipsoid_error(robot, (wrong, s_v, U_w, s_w), qs) > 0.1


# -- the condition number ---------------------------------------------------------------------
def test_condition_number_of_the_planar_2r_arm_in_closed_form():
    robot = robot_of("planar_2r")
    for q2 in (0.3, 1.0, 2.5, -1.2):
        s1, s2 = planar_2r_singular_values(q2)
        for length in (1.0, 2.0, 0.5):  # both rows are positions: the length cancels
            assert reference.condition_number(robot, np.array([0.4, q2]), length) == pytest.approx(s1 / s2, rel=1e-13)
    assert reference.condition_number(robot, np.array([0.0, 0.0]), 1.0) == math.inf  # J = [[0, 0], [2, 1]]


@pytest.mark.parametrize("name", sorted(RTB_MODELS))
def test_condition_number_against_robotics_toolbox(name):
    """rtb's inverse condition number of jacob0, at L = 1 (rtb scales no rows)."""
    robot, model = robot_of(name), rtb_model(name)
    qs = samples(name)[:50]
    kappa = reference.condition_number(robot, qs, 1.0)
    assert_allclose(1 / kappa, [model.manipulability(q, method="invcondition", axes="all") for q in qs],
                    atol=ATOL, rtol=0)


def test_condition_number_divides_the_position_rows_by_the_length():
    robot, length = robot_of("ur5"), 0.8
    qs = samples("ur5")[:20]
    js = reference.singularity_jacobian(robot, qs)
    js[:, :3] /= length
    values = np.linalg.svd(js, compute_uv=False)
    assert_allclose(reference.condition_number(robot, qs, length), values[:, 0] / values[:, -1], rtol=1e-12)
    assert characteristic_length(robot_of("planar_2r")) == 1.0  # positions only: L cancels, and is 1


# -- the gradient of the manipulability ---------------------------------------------------------
@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_manipulability_gradient_against_central_differences(name):
    """Fourth-order central differences (step 1e-3) of reference.manipulability, at samples away
    from singularities (where |sigma_min| has a kink within the stencil)."""
    robot = robot_of(name)
    qs = regular_samples(robot, samples(name))
    h = 1e-3

    def at(offset):
        return reference.manipulability(robot, qs + offset)

    differences = np.stack([(8 * (at(h * e) - at(-h * e)) - (at(2 * h * e) - at(-2 * h * e))) / (12 * h)
                            for e in np.eye(robot.dof)], -1)
    gradient = reference.manipulability_gradient(robot, qs)
    assert gradient.shape == qs.shape
    assert_allclose(gradient, differences, atol=1e-8 * (1 + np.abs(gradient).max()), rtol=0)


def test_manipulability_gradient_of_a_tall_js():
    robot = parse_robot(TALL_ARM)
    qs = regular_samples(robot, np.random.default_rng(6).uniform(-3, 3, size=(50, 2)))
    h = 1e-6
    differences = np.stack([(reference.manipulability(robot, qs + h * e) - reference.manipulability(robot, qs - h * e))
                            / (2 * h) for e in np.eye(2)], -1)
    assert_allclose(reference.manipulability_gradient(robot, qs), differences, atol=1e-8, rtol=0)


def test_manipulability_gradient_of_the_planar_2r_arm_in_closed_form():
    """w = a1 a2 |sin q2|: dw/dq1 = 0, dw/dq2 = a1 a2 cos q2 sign(sin q2); 0 where w = 0 exactly."""
    robot = robot_of("planar_2r")
    for q in ([0.3, 1.1], [2.0, -0.4], [-1.0, 2.8]):
        assert_allclose(reference.manipulability_gradient(robot, np.array(q)),
                        [0.0, math.cos(q[1]) * math.copysign(1, math.sin(q[1]))], atol=1e-14)
    assert_allclose(reference.manipulability_gradient(robot, np.array([0.0, 0.0])), [0.0, 0.0])


@pytest.mark.parametrize("name", sorted(RTB_MODELS))
def test_manipulability_gradient_against_robotics_toolbox(name):
    """rtb's jacobm: the gradient of sqrt(det(J J^T)) of jacob0, from its own Hessian."""
    robot, model = robot_of(name), rtb_model(name)
    qs = regular_samples(robot, samples(name)[:50])
    theirs = np.array([model.jacobm(q, axes="all").ravel() for q in qs])
    assert_allclose(reference.manipulability_gradient(robot, qs), theirs, atol=ATOL, rtol=0)


# -- the task error ---------------------------------------------------------------------------
def test_rotation_vector_against_scipy():
    rng = np.random.default_rng(7)
    vectors = rng.normal(size=(200, 3))
    angles = np.concatenate([rng.uniform(0, math.pi, 150), [1e-9, 1e-5, math.pi / 2, math.pi - 1e-7,
                                                           math.pi - 1e-3] * 10])
    vectors *= (angles / np.linalg.norm(vectors, axis=1))[:, None]
    rotations = Rotation.from_rotvec(vectors).as_matrix()
    assert_allclose(reference.rotation_vector(rotations), vectors, atol=1e-12, rtol=0)


def test_task_error_of_a_pose_and_of_a_task_vector():
    ur5, rexarm = robot_of("ur5"), robot_of("rexarm")
    q = samples("ur5")[:20]
    moved = q + 0.05 * np.random.default_rng(8).normal(size=q.shape)
    error = reference.task_error(ur5, q, reference.fk(ur5, moved))
    assert_allclose(error[:, :3], reference.fk(ur5, moved)[:, :3, 3] - reference.fk(ur5, q)[:, :3, 3], atol=1e-15)
    turn = reference.fk(ur5, moved)[:, :3, :3] @ np.swapaxes(reference.fk(ur5, q)[:, :3, :3], 1, 2)
    assert_allclose(error[:, 3:], Rotation.from_matrix(turn).as_rotvec(), atol=1e-12)
    q = samples("rexarm")[:20]
    target = reference.task(rexarm, q) + [0.01, -0.02, 0.0, 2 * math.pi + 0.1]  # pitch a turn and 0.1 away
    assert_allclose(reference.task_error(rexarm, q, target), np.tile([0.01, -0.02, 0.0, 0.1], (20, 1)), atol=1e-12)

    wrist = parse_robot(WRIST_ARM)  # all three angles, Js's rows the angular velocity's: a rotation vector
    q = np.random.default_rng(9).uniform(-2, 2, size=(20, 4))
    moved = q + 0.05 * np.random.default_rng(10).normal(size=q.shape)
    error = reference.task_error(wrist, q, reference.task(wrist, moved))
    assert_allclose(error[:, 0], reference.fk(wrist, moved)[:, 2, 3] - reference.fk(wrist, q)[:, 2, 3], atol=1e-15)
    turn = reference.fk(wrist, moved)[:, :3, :3] @ np.swapaxes(reference.fk(wrist, q)[:, :3, :3], 1, 2)
    assert_allclose(error[:, 1:], Rotation.from_matrix(turn).as_rotvec(), atol=1e-12)


# -- verify's checks, fed right and wrong answers ------------------------------------------------
class ContractInNumpy:
    """A backend answering the contract's null-space solvers and dexterity functions from numpy
    (np.linalg.pinv and the reference), or with one of them made wrong."""

    names = ("numpy",)
    signatures = dict.fromkeys(("velocity_ellipsoid", "condition_number", "manipulability_gradient",
                                "velocity_ik_nullspace", "resolved_rate"))

    def __init__(self, robot, wrong=""):
        self.robot, self.wrong = robot, wrong

    def has(self, backend, name):
        return True

    def call(self, backend, name, q, *arguments):
        robot = self.robot
        if name == "velocity_ellipsoid":
            return reference.velocity_ellipsoid(robot, q)
        if name == "condition_number":
            length = characteristic_length(robot) * (2 if self.wrong == name else 1)
            return (reference.condition_number(robot, q, length),)
        if name == "manipulability_gradient":
            return (reference.manipulability_gradient(robot, q) * (1.001 if self.wrong == name else 1),)
        if name == "resolved_rate":
            target, rate, gain, z, damping = arguments
            arguments = (rate + gain * reference.task_error(robot, q, target), z, damping)
        mu_dot, z, _ = arguments
        js = reference.singularity_jacobian(robot, q)
        inverse = np.linalg.pinv(js)
        projected = z - np.einsum("kij,kj->ki", inverse @ js, z)
        q_dot = np.einsum("kij,kj->ki", inverse, mu_dot) + (0 if self.wrong == name else projected)
        return q_dot, np.zeros(len(q), dtype=int)


@pytest.mark.parametrize("name", ["panda", "ur5", "rexarm", "planar_3r"])
def test_dexterity_checks_pass_the_contract_and_catch_each_wrong_function(name):
    robot = robot_of(name)
    q = samples(name)[:40]
    ratios = np.linalg.svd(reference.singularity_jacobian(robot, q), compute_uv=False)
    regular = ratios[:, -1] > 1e-3 * ratios[:, 0]
    tolerances = {"numpy": 1e-9 * (1 + robot.reach)}

    def errors(wrong=""):
        rows = dexterity_results(robot, ContractInNumpy(robot, wrong), q, np.ones(len(q), dtype=bool), regular,
                                 tolerances, tolerances)
        return {row.function: row.errors["numpy"] for row in rows}

    right = errors()
    assert set(right) == set(ContractInNumpy.signatures)
    assert max(right.values()) < 1e-12, right
    redundant = robot.dof > len(robot.task)  # the null-space term is 0 for a square Js
    for wrong in ("condition_number", "manipulability_gradient") + (("velocity_ik_nullspace", "resolved_rate")
                                                                    if redundant else ()):
        assert errors(wrong)[wrong] > 1e-6, wrong
