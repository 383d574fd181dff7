"""jacgen's CasADi functions inside optimisation problems, solved by ipopt (README, "Optimisation
with CasADi"): ur5's generated/ur5/ur5_casadi.py, as `jacgen generate robots/ur5.yaml` writes it.

    python examples/casadi_opti.py

1. IK as least squares on `fk`'s pose error, warm-started by `ik_nearest` (the closed form,
   every branch: the one nearest a seed) at a nearby pose;
2. a 20-knot trajectory to a pose, the tool's speed bounded through `jacobian(q)` at every
   step, `manipulability` a secondary cost that keeps it away from singularities;
3. the most manipulable configuration within joint bounds.
Each prints its time and how far its answer is from what it asked for.
"""

import time

import casadi
import numpy as np

import jacgen

QUIET = {"print_time": False}


def load(name: str = "ur5"):
    """The generated CasADi module of a robot (built once, then cached)."""
    return jacgen.arm(name, backend="casadi")


def pose_error(robot, q, target):
    """The rows of fk(q) - target that a pose has: 12 numbers, zero when q reaches the target."""
    return casadi.vec(robot.fk(q)[:3, :] - target[:3, :])


def pose_residual(robot, q, target):
    """Six numbers, zero where fk(q) is the target: the position error and the vector of the
    rotation error's skew part (independent near the target, as equality constraints need; the
    twelve of pose_error are not)."""
    T = robot.fk(q)
    skew = target[:3, :3].T @ T[:3, :3]
    skew = skew - skew.T
    return casadi.vertcat(T[:3, 3] - target[:3, 3], skew[2, 1], skew[0, 2], skew[1, 0])


def least_squares_ik(robot, target: np.ndarray, nearby: np.ndarray, seed: np.ndarray) -> tuple[np.ndarray, dict]:
    """q minimising |fk(q) - target|^2, warm-started by the closed-form solution nearest `seed`
    of a `nearby` pose (the last control cycle's target, say, or the nominal arm's pose of a
    calibrated one): ik_nearest."""
    opti = casadi.Opti()
    q = opti.variable(robot.DOF)
    opti.minimize(casadi.sumsqr(pose_error(robot, q, target)))
    start, status = robot.ik_nearest(nearby, seed, np.ones(robot.DOF))
    opti.set_initial(q, start if int(status) == 0 else seed)  # 0: a solution found (IK_NEAREST_OK)
    opti.solver("ipopt", QUIET, {"print_level": 0, "sb": "yes", "tol": 1e-14})
    solution = opti.solve()
    return np.asarray(solution.value(q)).ravel(), solution.stats()


def trajectory(robot, q_start: np.ndarray, target: np.ndarray, knots: int = 20, duration: float = 3.0,
               speed: float = 0.1, weight: float = 1e-3) -> tuple[np.ndarray, dict]:
    """Knots q_0 = q_start, ..., q_{knots-1} reaching `target`, minimising the joints' squared
    steps minus `weight` times the manipulability at each knot, with the tool's linear speed,
    J_v(q_k) (q_{k+1} - q_k) / dt, at most `speed` at every step. Warm start: the straight line
    in joint space to the closed-form solution nearest q_start."""
    dt = duration / (knots - 1)
    opti = casadi.Opti()
    q = opti.variable(robot.DOF, knots)
    opti.subject_to(q[:, 0] == q_start)
    opti.subject_to(pose_residual(robot, q[:, -1], target) == 0)
    cost = 0
    for k in range(knots - 1):
        step = q[:, k + 1] - q[:, k]
        velocity = robot.jacobian(q[:, k])[:3, :] @ step / dt
        opti.subject_to(casadi.sumsqr(velocity) <= speed ** 2)
        cost += casadi.sumsqr(step) - weight * robot.manipulability(q[:, k + 1])
    opti.minimize(cost)
    end, _ = robot.ik_nearest(target, q_start, np.ones(robot.DOF))
    opti.set_initial(q, np.linspace(q_start, np.asarray(end).ravel(), knots).T)
    opti.solver("ipopt", QUIET, {"print_level": 0, "sb": "yes", "tol": 1e-10})
    solution = opti.solve()
    return np.asarray(solution.value(q)), solution.stats()


def most_manipulable(robot, lower: np.ndarray, upper: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, dict]:
    """The configuration within [lower, upper] of the largest manipulability, from `start`."""
    opti = casadi.Opti()
    q = opti.variable(robot.DOF)
    opti.minimize(-robot.manipulability(q))
    opti.subject_to(opti.bounded(lower, q, upper))
    opti.set_initial(q, start)
    opti.solver("ipopt", QUIET, {"print_level": 0, "sb": "yes", "tol": 1e-12})
    solution = opti.solve()
    return np.asarray(solution.value(q)).ravel(), solution.stats()


def timed(solve, *arguments):
    start = time.perf_counter()
    answer, stats = solve(*arguments)
    return answer, stats, time.perf_counter() - start


def main():
    ur5 = load("ur5")
    q_goal = np.array([0.4, -1.1, 1.3, -0.9, -1.4, 0.3])
    target = np.asarray(ur5.fk(q_goal))
    nearby = np.asarray(ur5.fk(q_goal + 0.05))
    q, stats, seconds = timed(least_squares_ik, ur5, target, nearby, q_goal + 0.2)
    print(f"least-squares ik: {stats['return_status']} in {seconds * 1e3:.0f} ms, "
          f"{stats['iter_count']} iterations, pose error {np.abs(np.asarray(ur5.fk(q)) - target).max():.1e}")
    q_start = np.array([0.0, -1.5, 1.5, -1.5, -1.5, 0.0])
    path, stats, seconds = timed(trajectory, ur5, q_start, target)
    speeds = [np.linalg.norm(np.asarray(ur5.jacobian(path[:, k]))[:3] @ (path[:, k + 1] - path[:, k])) / (3.0 / 19)
              for k in range(path.shape[1] - 1)]
    print(f"trajectory: {stats['return_status']} in {seconds * 1e3:.0f} ms, end pose error "
          f"{np.abs(np.asarray(ur5.fk(path[:, -1])) - target).max():.1e}, fastest tool speed {max(speeds):.3f} m/s")
    lower, upper = q_start - 0.5, q_start + 0.5
    q, stats, seconds = timed(most_manipulable, ur5, lower, upper, q_start)
    print(f"most manipulable: {stats['return_status']} in {seconds * 1e3:.0f} ms, manipulability "
          f"{float(ur5.manipulability(q)):.4f} (start {float(ur5.manipulability(q_start)):.4f})")


if __name__ == "__main__":
    main()
