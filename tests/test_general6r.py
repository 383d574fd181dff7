"""The general 6R solver's per-robot part (`jacgen.general6r`): Raghavan & Roth's 14
equations hold, for every split of the loop, at the configurations of random arms (poses from
the numpy reference); the split and shift chosen by conditioning, solved as the textbook does
(24 x 24 companion eigenproblem, back-substitution, two Newton steps on the reference), recover
the configuration of every pose of the Jaco, the Manocha-Canny arm, a calibrated UR5 and random
arms, with up to 16 solutions, and find every solution a multi-start search finds."""

import functools
import math

import numpy as np
import pytest
import roboticstoolbox as rtb
import sympy
from scipy.optimize import least_squares

from jacgen import general6r, reference
from jacgen.robot import parse_robot
from random_arms import random_arm_text

MANOCHA_CANNY = """
name: manocha_canny
convention: standard
angle_unit: deg
joints:
  - {type: revolute, a: 0.3, alpha: 90, d: 0}
  - {type: revolute, a: 1, alpha: 1, d: 0}
  - {type: revolute, a: 0, alpha: 90, d: 0.2}
  - {type: revolute, a: 1.5, alpha: 1, d: 0}
  - {type: revolute, a: 0, alpha: 90, d: 0}
  - {type: revolute, a: 0, alpha: 1, d: 0}
task: [x, y, z, roll, pitch, yaw]
"""

# rtb's Jaco (DH/Jaco.py): its first joint is flipped (theta1 = -q1): Rz(-q) Tz(D1) Rx(90) is
# Rx(180) Rz(q) Tz(-D1) Rx(-90), so a base Rx(180) and that row keep q1 the vendor's.
JACO = """
name: jaco
convention: standard
angle_unit: deg
parameters: {D1: 0.2755, D2: 0.4100, D3: 0.2073, D4: 0.0743, D5: 0.0743, D6: 0.1687, e2: 0.0098}
base: {xyz: [0, 0, 0], rpy: [180, 0, 0]}
joints:
  - {type: revolute, a: 0, alpha: -90, d: "-D1"}
  - {type: revolute, a: D2, alpha: 180, d: 0, offset: -90}
  - {type: revolute, a: 0, alpha: 90, d: "-e2", offset: 90}
  - {type: revolute, a: 0, alpha: 60, d: "-(D3 + D4/sqrt(3))"}
  - {type: revolute, a: 0, alpha: 60, d: "-(D4 + D5)/sqrt(3)", offset: -180}
  - {type: revolute, a: 0, alpha: 180, d: "-(D5/sqrt(3) + D6)", offset: 100}
task: [x, y, z, roll, pitch, yaw]
"""

# UR5 (robots/ur5.yaml) with each twist off by 1e-3 rad and each length by 0.1 mm.
UR5_CALIBRATED = """
name: ur5_calibrated
convention: standard
joints:
  - {type: revolute, a: 0.0001, alpha: 1.5717963, d: 0.089359}
  - {type: revolute, a: -0.4251, alpha: -0.001, d: 0.0001}
  - {type: revolute, a: -0.3921, alpha: 0.001, d: -0.0001}
  - {type: revolute, a: -0.0001, alpha: 1.5697963, d: 0.10925}
  - {type: revolute, a: 0.0001, alpha: -1.5697963, d: 0.09455}
  - {type: revolute, a: 0.0001, alpha: 0.001, d: 0.0824}
task: [x, y, z, roll, pitch, yaw]
"""


def _robot(text: str):
    return parse_robot(text.encode(), "arm.yaml")


def _numeric(matrix: sympy.Matrix) -> np.ndarray:
    return np.array(matrix.evalf(30).tolist(), dtype=float)


def _rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _wrapped(a: np.ndarray) -> np.ndarray:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _pose_error(target: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Position error and the rotation vector of target R^T (small angles)."""
    e = target[:3, :3] @ pose[:3, :3].T
    return np.concatenate([target[:3, 3] - pose[:3, 3], 0.5 * np.array([e[2, 1] - e[1, 2], e[0, 2] - e[2, 0],
                                                                      e[1, 0] - e[0, 1]])])


class Solver:
    """The elimination of `general6r` carried out in numpy, as the generated code is to do it."""

    def __init__(self, robot):
        self.robot = robot
        head, links, tail = general6r.chain_form(robot)
        self.plan = general6r.elimination(robot)
        self.head_inverse, self.tail_inverse = np.linalg.inv(_numeric(head)), np.linalg.inv(_numeric(tail))
        self.links = [general6r._numeric_chain([link], np.zeros((1, 2)))[0] for link in links]
        self.offsets = np.array([joint.offset.approx for joint in robot.joints])

    def equations_at(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """P0, Ps, Pc (3 x 14 x 9, the hidden angle's shift applied), Q (14 x 8) and N at a pose."""
        split = self.plan.equations.split
        n = self.head_inverse @ pose @ self.tail_inverse
        v = np.linalg.inv(n) if split.target_inverted else n
        p0, ps, pc, q = self.plan.equations.evaluated(np.concatenate([v[:3, :3].ravel(), v[:3, 3]]))
        return np.array([p0, *general6r.shifted(ps, pc, self.plan.shift)]), q[:, :8], n

    @staticmethod
    def roots(p: np.ndarray, q: np.ndarray):
        """Per real eigenvalue: the loop angles of a (less the shift), b, c, g, h."""
        p0, ps, pc = p
        orthogonal, r = np.linalg.qr(q, mode="complete")
        left_null = orthogonal[:, 8:].T
        s0, ss, sc = left_null @ p0, left_null @ ps, left_null @ pc
        m2, m1, m0 = (general6r.half_angle(m) for m in (s0 - sc, 2 * ss, s0 + sc))
        companion = np.zeros((24, 24))
        companion[:12, 12:] = np.eye(12)
        companion[12:, :12], companion[12:, 12:] = -np.linalg.solve(m2, m0), -np.linalg.solve(m2, m1)
        values, vectors = np.linalg.eig(companion)
        for k in np.flatnonzero(np.abs(values.imag) <= 1e-5 * (1 + np.abs(values))):
            w = vectors[:12, k]
            w = (w * np.exp(-1j * np.angle(w[np.argmax(np.abs(w))]))).real  # x_b^i x_c^j at 3 i + j
            a = 2 * math.atan(values[k].real)
            c = 2 * math.atan2(*max(((w[i + 1], w[i]) for i in (0, 1, 3, 4, 6, 7, 9, 10)), key=lambda pair: math.hypot(*pair)))
            b = 2 * math.atan2(*max(((w[i + 3], w[i]) for i in range(9)), key=lambda pair: math.hypot(*pair)))
            sb, cb, s_c, cc = math.sin(b), math.cos(b), math.sin(c), math.cos(c)
            v_bc = np.array([sb * s_c, sb * cc, cb * s_c, cb * cc, sb, cb, s_c, cc, 1])
            v_gh = np.linalg.solve(r[:8], orthogonal[:, :8].T @ ((p0 + math.sin(a) * ps + math.cos(a) * pc) @ v_bc))
            yield a, b, c, math.atan2(v_gh[4], v_gh[5]), math.atan2(v_gh[6], v_gh[7])

    def solve(self, pose: np.ndarray, roots=None) -> list[np.ndarray]:
        """Every solution reaching `pose` to 1e-9, each once, wrapped to (-pi, pi]; `roots` is
        the kernel (default: numpy's)."""
        split = self.plan.equations.split
        solutions = []
        p, q, n = self.equations_at(pose)
        for angles in (roots or self.roots)(p, q):
            theta = np.zeros(6)
            angles = (angles[0] + self.plan.shift, *angles[1:])
            for position, angle in zip((*split.triple, *split.pair), angles):
                theta[split.joint(position)] = -angle if split.backwards else angle
            free = split.joint(split.free)  # Z_free = (Z1 C1 .. up to it)^-1 N (C_free .. Z6)^-1
            before, after = np.eye(4), (self.links[free] if free < 5 else np.eye(4))
            for i in range(free):
                before = before @ _rz(theta[i]) @ self.links[i]
            for i in range(free + 1, 6):
                after = after @ _rz(theta[i]) @ (self.links[i] if i < 5 else np.eye(4))
            z = np.linalg.inv(before) @ n @ np.linalg.inv(after)
            theta[free] = math.atan2(z[1, 0], z[0, 0])
            q = theta - self.offsets
            for _ in range(2):  # Newton on the pose
                q = q + np.linalg.lstsq(reference.jacobian(self.robot, q), _pose_error(pose, reference.fk(self.robot, q)),
                                        rcond=None)[0]
            q = _wrapped(q)
            if np.abs(reference.fk(self.robot, q) - pose).max() < 1e-9 and \
                    all(np.abs(_wrapped(s - q)).max() > 1e-6 for s in solutions):
                solutions.append(q)
        return solutions


def _six_revolute_arms():
    seeds = [s for s in range(200) if "symbolic" not in random_arm_text(s, dof=6, revolute_only=True)][:4]
    return [pytest.param(random_arm_text(s, dof=6, revolute_only=True, radians=s % 2 == 1), id=f"seed{s}")
            for s in seeds]


@pytest.mark.parametrize("text", _six_revolute_arms())
def test_fourteen_equations_hold_for_every_split(text):
    robot = _robot(text)
    head, links, tail = general6r.chain_form(robot)
    head_inverse, tail_inverse = np.linalg.inv(_numeric(head)), np.linalg.inv(_numeric(tail))
    theta = np.random.default_rng(7).uniform(-math.pi, math.pi, (4, 6))
    offsets = np.array([joint.offset.approx for joint in robot.joints])
    poses = [head_inverse @ reference.fk(robot, t - offsets) @ tail_inverse for t in theta]
    for split in general6r.SPLITS:
        equations = general6r.equations(links, split)
        for t, n in zip(theta, poses):
            v = np.linalg.inv(n) if split.target_inverted else n
            p0, ps, pc, q = equations.evaluated(np.concatenate([v[:3, :3].ravel(), v[:3, 3]]))
            loop = [(-1 if split.backwards else 1) * t[split.joint(k)] for k in range(6)]
            (a, b, c), (g, h) = split.triple, split.pair
            products = lambda x, y: np.array([math.sin(loop[x]) * math.sin(loop[y]), math.sin(loop[x]) * math.cos(loop[y]),  # noqa: E731
                                             math.cos(loop[x]) * math.sin(loop[y]), math.cos(loop[x]) * math.cos(loop[y]),
                                             math.sin(loop[x]), math.cos(loop[x]), math.sin(loop[y]), math.cos(loop[y]), 1])
            residual = (p0 + math.sin(loop[a]) * ps + math.cos(loop[a]) * pc) @ products(b, c) - q @ products(g, h)
            assert np.abs(residual).max() < 1e-12 * (1 + np.abs(q).max() + np.abs(p0).max()), split


def test_both_conventions_are_covered():
    texts = [p.values[0] for p in _six_revolute_arms()]
    assert any("convention: standard" in t for t in texts) and any("convention: modified" in t for t in texts)


def test_jaco_file_is_the_toolbox_jaco():
    robot, jaco = _robot(JACO), rtb.models.DH.Jaco()
    for q in np.random.default_rng(1).uniform(-math.pi, math.pi, (20, 6)):
        assert np.abs(reference.fk(robot, q) - jaco.fkine(q).A).max() < 1e-14


def test_the_textbook_split_is_singular_for_the_jaco_and_the_chosen_one_is_not():
    """Cut after q6 with tan(q3/2) hidden (Raghavan & Roth's), the Jaco's matrix polynomial is
    singular for every x; the split chosen is well conditioned."""
    robot = _robot(JACO)
    assert general6r.elimination(robot).condition < 1e4
    head, links, tail = general6r.chain_form(robot)
    textbook = general6r.equations(links, general6r.Split(backwards=False, free=5))
    theta = np.random.default_rng(2).uniform(-math.pi, math.pi, (1, 6))
    n = general6r._numeric_chain(links, theta)[0]
    p0, ps, pc, q = textbook.evaluated(np.concatenate([n[:3, :3].ravel(), n[:3, 3]]))
    left_null = np.linalg.svd(q[:, :8])[0][:, 8:].T
    x = 0.37
    s = left_null @ (p0 + 2 * x / (1 + x * x) * ps + (1 - x * x) / (1 + x * x) * pc)
    assert np.linalg.cond(general6r.half_angle(s)) > 1e14


ARMS = {"manocha_canny": MANOCHA_CANNY, "jaco": JACO, "ur5_calibrated": UR5_CALIBRATED}


@functools.cache
def _solver(name: str) -> Solver:
    return Solver(_robot(ARMS[name]))


@pytest.mark.parametrize("name", ARMS)
def test_every_pose_gives_back_its_configuration(name):
    solver = _solver(name)
    robot, counts = solver.robot, []
    for q in np.random.default_rng(11).uniform(-math.pi, math.pi, (100, 6)):
        solutions = solver.solve(reference.fk(robot, q))
        assert min(np.abs(_wrapped(s - q)).max() for s in solutions) < 1e-8
        counts.append(len(solutions))
    assert set(counts) <= set(range(2, 17, 2))
    if name == "manocha_canny":
        assert max(counts) == 16


@pytest.mark.parametrize("text", _six_revolute_arms())
def test_random_arms_give_back_their_configurations(text):
    robot = _robot(text)
    solver = Solver(robot)
    for q in np.random.default_rng(5).uniform(-math.pi, math.pi, (40, 6)):
        solutions = solver.solve(reference.fk(robot, q))
        assert min(np.abs(_wrapped(s - q)).max() for s in solutions) < 1e-8


def _multi_start(robot, pose: np.ndarray, starts: int, rng) -> list[np.ndarray]:
    """Solutions found by Levenberg-Marquardt on the reference fk from random starts."""
    found = []
    for start in rng.uniform(-math.pi, math.pi, (starts, 6)):
        result = least_squares(lambda q: (reference.fk(robot, q) - pose)[:3].ravel(), start, method="lm")
        q = _wrapped(result.x)
        if np.abs(reference.fk(robot, q) - pose).max() < 1e-9 and all(np.abs(_wrapped(s - q)).max() > 1e-6 for s in found):
            found.append(q)
    return found


@pytest.mark.parametrize("name", ARMS)
def test_finds_every_solution_a_multi_start_search_finds(name):
    solver, rng = _solver(name), np.random.default_rng(4)
    robot = solver.robot
    for q in rng.uniform(-math.pi, math.pi, (2, 6)):
        pose = reference.fk(robot, q)
        ours, theirs = solver.solve(pose), _multi_start(robot, pose, 100, rng)
        assert len(theirs) >= 2
        for s in theirs:
            assert min(np.abs(_wrapped(s - o)).max() for o in ours) < 1e-6
        assert len(ours) >= len(theirs)


def test_rejects_what_it_cannot_solve():
    prismatic = random_arm_text(next(s for s in range(100) if "prismatic" in random_arm_text(s, dof=6)), dof=6)
    with pytest.raises(ValueError, match="six revolute joints"):
        general6r.chain_form(_robot(prismatic))
