"""Resolved-rate control of a 7-axis arm, with and without null-space motion (README §4,
"Resolved-rate control with null-space motion"): the Panda's tool follows a circle at 1 kHz through the generated
numpy module generated/panda/panda.py, as `jacgen generate robots/panda.yaml` writes it.

    python examples/resolved_rate.py [--seconds 4] [--plot docs/resolved_rate.png]

Each tick, q_dot = resolved_rate(q, target, target_rate, gain, z): the circle's pose (its
orientation held) is the target, its twist [v; 0] the feedforward, and q += dt q_dot. The
Panda has one joint more than its six-component task, so z moves it without moving the tool:
once with z = 0, once with z = k manipulability_gradient(q), which climbs the manipulability
along the self-motion. Both runs are one batch of two rows. It prints the largest tracking
error and the manipulability at the start and the end of each run, and plots both over time.
"""

import argparse

import numpy as np

import jacgen

# rad, within the limits. Not a symmetric pose: where q1 = q3 = q5 = 0 the manipulability is
# stationary along the self-motion, and z would do nothing.
START = np.array([0.5, -0.5, 1.5, -1.8, -0.5, 1.4, 0.785])
TICK = 1e-3  # s: the 1 kHz control loop
RADIUS, PERIOD = 0.1, 4.0  # m, s: the circle, in the world x-y plane through the tool's start
GAIN = 30.0  # 1/s: the task error decays as exp(-GAIN t)
NULL_SPACE_GAINS = (0.0, 20.0)  # k of z = k manipulability_gradient(q), one run each


def load(name: str = "panda"):
    """The generated numpy module of a robot (built once, then cached)."""
    return jacgen.arm(name)


def circle(start: np.ndarray, t: float) -> tuple[np.ndarray, np.ndarray]:
    """The target at time t and its twist [v; w]: the tool's pose `start` with its position
    moved round the circle whose centre is RADIUS along world x from it (angle 0 at the
    start), its orientation held (w = 0)."""
    angle = 2 * np.pi * t / PERIOD
    speed = 2 * np.pi * RADIUS / PERIOD
    pose = start.copy()
    pose[:3, 3] += RADIUS * np.array([1 - np.cos(angle), -np.sin(angle), 0])
    return pose, np.array([speed * np.sin(angle), -speed * np.cos(angle), 0, 0, 0, 0])


def simulate(panda, seconds: float, null_space_gains=NULL_SPACE_GAINS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The control loop from START, one run per null-space gain, the runs as one batch: the
    times t_k = k TICK, q at each (steps + 1, runs, 7), and the targets (steps + 1, 4, 4)."""
    steps = round(seconds / TICK)
    k = np.asarray(null_space_gains, dtype=float)[:, None]
    start = np.asarray(panda.fk(START))
    q = np.tile(START, (len(k), 1))
    trajectory, targets = [q], [start]
    for step in range(steps):
        target, target_rate = circle(start, step * TICK)
        q_dot, status = panda.resolved_rate(q, target, target_rate, GAIN, k * panda.manipulability_gradient(q))
        if (status != panda.VELOCITY_IK_OK).any():
            raise RuntimeError(f"resolved_rate: status {status} at t = {step * TICK:.3f} s")
        q = q + TICK * q_dot
        trajectory.append(q)
        targets.append(circle(start, (step + 1) * TICK)[0])
    return TICK * np.arange(steps + 1), np.array(trajectory), np.array(targets)


def tracking_error(panda, trajectory: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """The distance from the tool to its target (m), per time and run."""
    reached = np.asarray(panda.fk(trajectory))[..., :3, 3]
    return np.linalg.norm(reached - targets[:, None, :3, 3], axis=-1)


def plot(path: str, times, errors, manipulability, null_space_gains=NULL_SPACE_GAINS) -> None:
    """The tracking error (log scale) and the manipulability over time, one line per run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True, constrained_layout=True)
    for run, k in enumerate(null_space_gains):
        label = "z = 0" if k == 0 else f"z = {k:g} · manipulability_gradient(q)"
        top.semilogy(times[1:], errors[1:, run], label=label)
        bottom.plot(times, manipulability[:, run], label=label)
    top.set_ylabel("tracking error (m)")
    top.set_title(f"Panda: resolved-rate control at 1 kHz, a circle of {RADIUS:g} m in {PERIOD:g} s, gain {GAIN:g}/s")
    bottom.set_ylabel("manipulability")
    bottom.set_xlabel("time (s)")
    for axes in (top, bottom):
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(loc="best")
    figure.savefig(path, dpi=100)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=PERIOD, help="simulated time (default: one circle)")
    parser.add_argument("--plot", metavar="FILE.png", help="plot the tracking error and the manipulability")
    arguments = parser.parse_args()
    panda = load()
    times, trajectory, targets = simulate(panda, arguments.seconds)
    errors = tracking_error(panda, trajectory, targets)
    manipulability = np.asarray(panda.manipulability(trajectory))
    for run, k in enumerate(NULL_SPACE_GAINS):
        print(f"k = {k:4g}: largest tracking error {errors[:, run].max():.1e} m, manipulability "
              f"{manipulability[0, run]:.4f} -> {manipulability[-1, run]:.4f}")
    if arguments.plot:
        plot(arguments.plot, times, errors, manipulability)


if __name__ == "__main__":
    main()
