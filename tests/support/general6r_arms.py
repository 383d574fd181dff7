"""Support of the general 6R tests (tests/test_general6r.py, tests/test_c_runtime.py): the
arms of issue 22; the whole elimination of `jacgen.general6r` carried out in numpy, with a
kernel argument so that the C kernel's roots go through the same completion; and an independent
count of solutions, by a multi-start Levenberg-Marquardt search on the numpy reference."""

import functools
import math

import numpy as np
import sympy

from jacgen.solvers import general6r, general6r_plan
from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot

from .ik import wrapped

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


def robot_of(text: str):
    return parse_robot(text.encode(), "arm.yaml")


def numeric(matrix: sympy.Matrix) -> np.ndarray:
    return np.array(matrix.evalf(30).tolist(), dtype=float)


def _rz(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


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
        self.plan = general6r_plan.elimination(robot)
        self.head_inverse, self.tail_inverse = np.linalg.inv(numeric(head)), np.linalg.inv(numeric(tail))
        self.links = [general6r.chain_product([link], np.zeros((1, 2)))[0] for link in links]
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
            q = wrapped(q)
            if np.abs(reference.fk(self.robot, q) - pose).max() < 1e-9 and \
                    all(np.abs(wrapped(s - q)).max() > 1e-6 for s in solutions):
                solutions.append(q)
        return solutions


ARMS = {"manocha_canny": MANOCHA_CANNY, "jaco": JACO, "ur5_calibrated": UR5_CALIBRATED}


@functools.cache
def solver_of(name: str) -> Solver:
    return Solver(robot_of(ARMS[name]))


def multi_start(robot, pose: np.ndarray, starts: int, rng, iterations: int = 150) -> list[np.ndarray]:
    """Solutions found by Levenberg-Marquardt on the reference fk from random starts, every
    start at once. The residual is fk's top three rows minus the pose's; its Jacobian comes
    from the reference's geometric Jacobian: d R / d q_i = [w_i]x R, d p / d q_i = v_i."""
    q = rng.uniform(-math.pi, math.pi, (starts, 6))
    damping = np.full(starts, 1e-3)

    reached = reference.fk(robot, q)
    for _ in range(iterations):
        error = (reached - pose)[:, :3].reshape(starts, 12)
        geometric = reference.jacobian(robot, q)
        angular = np.swapaxes(geometric[:, 3:], 1, 2)  # (starts, joint, 3)
        turned = np.cross(angular[:, :, None, :], np.swapaxes(reached[:, :3, :3], 1, 2)[:, None])  # [joint, column, row]
        jacobian = np.concatenate([np.swapaxes(turned, 2, 3), geometric[:, None, :3].transpose(0, 3, 2, 1)],
                                  axis=3).reshape(starts, 6, 12).transpose(0, 2, 1)
        normal = np.swapaxes(jacobian, 1, 2) @ jacobian + damping[:, None, None] * np.eye(6)
        trial = q - np.linalg.solve(normal, (np.swapaxes(jacobian, 1, 2) @ error[..., None]))[..., 0]
        trial_reached = reference.fk(robot, trial)
        better = ((trial_reached - pose)[:, :3] ** 2).sum((1, 2)) < (error**2).sum(1)
        q, reached = np.where(better[:, None], trial, q), np.where(better[:, None, None], trial_reached, reached)
        damping = np.where(better, damping / 3, damping * 4).clip(1e-12, 1e6)
    found = []
    for q in wrapped(q):
        if np.abs(reference.fk(robot, q) - pose).max() < 1e-9 and all(np.abs(wrapped(s - q)).max() > 1e-6 for s in found):
            found.append(q)
    return found
