"""The general 6R solver's per-robot part (`jacgen.general6r`): Raghavan & Roth's 14
equations hold at the configurations of random arms (poses from the numpy reference), and
their elimination (the 24 x 24 eigenproblem in tan(theta3 / 2)) finds the configuration's
theta3 among its real roots, up to 16 of them on the Manocha-Canny arm."""

import math

import numpy as np
import pytest
import sympy

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


def _numeric(matrix: sympy.Matrix) -> np.ndarray:
    return np.array(matrix.evalf(30).tolist(), dtype=float)


class Solver:
    """The equations of one robot evaluated at a target (numpy), and their elimination."""

    def __init__(self, robot):
        self.robot = robot
        head, links, tail = general6r.chain_form(robot)
        self.head_inverse, self.tail_inverse = np.linalg.inv(_numeric(head)), np.linalg.inv(_numeric(tail))
        self.eq = general6r.equations(links)
        arguments = (*self.eq.n, *self.eq.m)
        self.matrices = [sympy.lambdify(arguments, list(m), "math") for m in (self.eq.p0, self.eq.ps, self.eq.pc, self.eq.q)]
        self.offsets = np.array([joint.offset.approx for joint in robot.joints])

    def evaluated(self, pose: np.ndarray) -> list[np.ndarray]:
        n_matrix = self.head_inverse @ pose @ self.tail_inverse
        values = (*n_matrix[:3, 2], *n_matrix[:3, 3])
        return [np.array(f(*values)).reshape(14, -1) for f in self.matrices]

    def tan_half_theta3(self, pose: np.ndarray) -> np.ndarray:
        """The real roots x3 = tan(theta3 / 2) of det((S0 + x S1 + x^2 S2)) = 0, by the companion matrix."""
        p0, ps, pc, q = self.evaluated(pose)
        left_null = np.linalg.svd(q)[0][:, 8:].T  # 6 x 14: the combinations free of theta1, theta2
        s0, ss, sc = left_null @ p0, left_null @ ps, left_null @ pc
        # s3 = 2x / (1 + x^2), c3 = (1 - x^2) / (1 + x^2), times 1 + x^2; then v45 in x4, x5 likewise.
        m2, m1, m0 = (_twelve(m) for m in (s0 - sc, 2 * ss, s0 + sc))
        companion = np.zeros((24, 24))
        companion[:12, 12:] = np.eye(12)
        companion[12:, :12], companion[12:, 12:] = -np.linalg.solve(m2, m0), -np.linalg.solve(m2, m1)
        roots = np.linalg.eigvals(companion)
        return np.sort(roots[np.abs(roots.imag) < 1e-8 * np.maximum(1, np.abs(roots))].real)


# (sin, cos, 1) times (1 + x^2) as coefficients of (1, x, x^2)
_HALF_ANGLE = {"s": (0, 2, 0), "c": (1, 0, -1), "1": (1, 0, 1)}


def _twelve(six_by_nine: np.ndarray) -> np.ndarray:
    """The six equations in the monomials x4^i x5^j (i, j <= 2), and the same times x4: 12 x 12."""
    basis = np.zeros((9, 9))
    for k, (f4, f5) in enumerate(("ss", "sc", "cs", "cc", "s1", "c1", "1s", "1c", "11")):
        basis[k] = np.outer(_HALF_ANGLE[f4], _HALF_ANGLE[f5]).ravel()
    expanded = six_by_nine @ basis
    out = np.zeros((12, 12))
    out[:6, :9], out[6:, 3:] = expanded, expanded
    return out


def _six_revolute_arms():
    seeds = [s for s in range(200) if "symbolic" not in random_arm_text(s, dof=6, revolute_only=True)][:6]
    return [pytest.param(random_arm_text(s, dof=6, revolute_only=True, radians=r), id=f"seed{s}{'rad' if r else ''}")
            for s in seeds for r in (False, True)]


@pytest.mark.parametrize("text", _six_revolute_arms())
def test_fourteen_equations_hold_on_random_arms(text):
    solver = Solver(parse_robot(text.encode(), "arm.yaml"))
    rng = np.random.default_rng(7)
    for q in rng.uniform(-math.pi, math.pi, (5, 6)):
        theta = q + solver.offsets
        p0, ps, pc, qm = solver.evaluated(reference.fk(solver.robot, q))
        s, c = np.sin(theta), np.cos(theta)
        v45 = np.array([s[3] * s[4], s[3] * c[4], c[3] * s[4], c[3] * c[4], s[3], c[3], s[4], c[4], 1])
        v12 = np.array([s[0] * s[1], s[0] * c[1], c[0] * s[1], c[0] * c[1], s[0], c[0], s[1], c[1]])
        residual = (p0 + s[2] * ps + c[2] * pc) @ v45 - qm @ v12
        scale = 1 + np.abs(qm).sum(1) + np.abs(p0).sum(1)
        assert np.abs(residual / scale).max() < 1e-12


def test_both_conventions_are_covered():
    texts = [p.values[0] for p in _six_revolute_arms()]
    assert any("convention: standard" in t for t in texts) and any("convention: modified" in t for t in texts)


def test_elimination_recovers_theta3_up_to_sixteen_roots():
    solver = Solver(parse_robot(MANOCHA_CANNY.encode(), "manocha_canny.yaml"))
    rng = np.random.default_rng(3)
    counts = []
    for q in rng.uniform(-math.pi, math.pi, (200, 6)):
        roots = solver.tan_half_theta3(reference.fk(solver.robot, q))
        x3 = math.tan(q[2] / 2)
        assert np.abs(roots - x3).min() < 1e-7 * (1 + abs(x3))
        counts.append(len(roots))
    assert set(counts) <= {2, 4, 6, 8, 10, 12, 14, 16} and max(counts) == 16


def test_rejects_what_it_cannot_solve():
    prismatic = random_arm_text(next(s for s in range(100) if "prismatic" in random_arm_text(s, dof=6)), dof=6)
    with pytest.raises(ValueError, match="six revolute joints"):
        general6r.chain_form(parse_robot(prismatic.encode(), "arm.yaml"))
