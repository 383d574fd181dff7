"""Benchmark: closed-form ik of 7-axis arms with a free joint, beside frankik, EAIK and ik_numeric.

    PYTHONPATH=. python bench/bench_free_joint_ik.py [--targets 10000] [--rounds 5]

Panda (joint 7 free) and iiwa (joint 3 free), each on the same random poses for every
solver: fk of random joint vectors inside the limits, with the free joint at one value
(Panda q7 = pi/4, frankik's default; iiwa q3 = 0.3), since EAIK locks a joint when its
robot is built. The Panda has no hand here: frankik's ik takes the flange pose.

- "C native": the generated `NAME_ik(T, q_free, q)` (double) in a native loop (the
  harness of bench_ik.py);
- "C via ctypes": the same library called from Python, one call per pose, the pose copied
  into a buffer whose address is taken once (`T.ctypes.data` per call would cost 2 us);
- "numpy batch": the generated Python `ik(T, q_free)` on all poses at once (time per pose);
- "frankik" (Panda): `frankik.ik_full(T, q, q7)`, He & Liu's solver (up to 4 solutions);
- "EAIK": `eaik.IK_HP.HPRobot(H, P, fixed_axes=[(k, value)]).IK(T)`, real solutions only;
- "ik_numeric" (iiwa): the generated C `NAME_ik_numeric`, 100 steps at most, started
  0.1 rad from the configuration on every joint (a tracking controller's seed).

Columns: microseconds per call (median over rounds), mean solutions returned per pose,
mean of them with every joint inside the limits (modulo 2 pi), the share of poses whose
original configuration is among the solutions (every joint within 1e-6 rad, modulo 2 pi),
and the share of returned solutions that miss the target by more than 1e-8 (largest
entry of the 4x4 difference, jacgen.reference fk). ik-geo has no locked-joint option and
is not run.
"""

import argparse
import ctypes
import statistics
import sys
import tempfile
import time
from pathlib import Path

import frankik
import numpy as np
from eaik.IK_HP import HPRobot

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "bench"))

from bench_ik import native  # noqa: E402
from conftest import import_file  # noqa: E402
from jacgen import reference  # noqa: E402
from jacgen.compile import CLibrary, compile_shared  # noqa: E402
from jacgen.render import render_robot, write_files  # noqa: E402
from jacgen.robot import load_robot, parse_robot  # noqa: E402
from test_ik import kinematic_chain  # noqa: E402

MISS = 1e-8
FREE_VALUE = {"panda": np.pi / 4, "iiwa": 0.3}


def panda_flange():
    """The shipped Panda without its hand: the flange pose is what frankik's ik takes."""
    text = (ROOT / "robots" / "panda.yaml").read_text()
    return parse_robot(text.replace("tool: {xyz: [0, 0, 0.103], rpy: [0, 0, -45]}", "").encode(), "panda.yaml")


def wrapped(difference: np.ndarray) -> np.ndarray:
    return np.abs((difference + np.pi) % (2 * np.pi) - np.pi)


def quality(robot, q: np.ndarray, targets: np.ndarray, solutions: list[np.ndarray]) -> tuple[float, float, float, float]:
    """Mean solutions, mean within limits (mod 2 pi), recovery rate and miss rate."""
    lower, upper = np.array([joint.limits for joint in robot.joints]).T
    returned = inside = recovered = missed = 0
    for row, target, found in zip(q, targets, solutions):
        found = np.asarray(found, dtype=float).reshape(-1, robot.dof)
        returned += len(found)
        shifted = lower + (found - lower) % (2 * np.pi)  # the lowest equivalent at or above the lower limit
        inside += int(np.sum(np.all(shifted <= upper, axis=1)))
        recovered += bool(len(found)) and wrapped(found - row).max(axis=1).min() < 1e-6
        missed += sum(np.abs(reference.fk(robot, x) - target).max() > MISS for x in found)
    count = len(q)
    return returned / count, inside / count, recovered / count, missed / max(returned, 1)


def timed(call, arguments, rounds: int) -> float:
    """Median microseconds per call of call(*argument) over the list of arguments."""
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        for argument in arguments:
            call(*argument)
        times.append((time.perf_counter() - start) * 1e6 / len(arguments))
    return statistics.median(times)


def run(robot, count: int, rounds: int, folder: Path) -> list[tuple[str, float, tuple]]:
    rng = np.random.default_rng(7)
    limits = np.array([joint.limits for joint in robot.joints])
    free, value = robot.free_joint, FREE_VALUE[robot.name]
    q = rng.uniform(limits[:, 0], limits[:, 1], (count, robot.dof))
    q[:, free] = value
    targets = reference.fk(robot, q)
    frees = q[:, free]

    write_files(render_robot(robot, ("c", "python")), folder)
    source = folder / robot.name / f"{robot.name}.c"
    library = CLibrary(compile_shared([source], folder / f"lib{robot.name}.so", ("-O2",)), robot, [], "double")
    module = import_file(folder / robot.name / f"{robot.name}.py", f"bench_{robot.name}")
    rows = []

    micros, _ = native(robot, source, targets, rounds, folder, frees)
    function = library._library[f"{robot.name}_ik"]
    function.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p]
    pose, out = np.zeros((4, 4)), np.zeros(8 * robot.dof)  # buffers a caller reuses: their addresses once
    pose_address, out_address = pose.ctypes.data, out.ctypes.data

    def call(T, angle):
        pose[...] = T
        return function(pose_address, angle, out_address)
    ctypes_micros = timed(call, list(zip(targets, frees)), rounds)
    ours = [library.ik(T, 8, None, angle) for T, angle in zip(targets, frees)]
    measured = quality(robot, q, targets, ours)
    rows += [("C native", micros, measured), ("C via ctypes", ctypes_micros, measured)]

    batch_times = []
    for _ in range(rounds):
        start = time.perf_counter()
        branches, valid = module.ik(targets, frees)
        batch_times.append((time.perf_counter() - start) * 1e6 / count)
    rows.append(("numpy batch", statistics.median(batch_times),
                 quality(robot, q, targets, [b[v] for b, v in zip(branches, valid)])))

    if robot.name == "panda":
        def solve_frankik(T, row, angle):
            return frankik.ik_full(T, row, angle)
        arguments = list(zip(targets, q, frees))
        found = [[x for x in solve_frankik(*argument) if np.all(np.isfinite(x))] for argument in arguments]
        rows.append(("frankik", timed(solve_frankik, arguments, rounds), quality(robot, q, targets, found)))

    H, P, tool_rotation = kinematic_chain(robot)
    eaik = HPRobot(H, P, fixed_axes=[(free, value)])
    local = [np.ascontiguousarray(np.block([[T[:3, :3] @ tool_rotation.T, T[:3, 3:]], [np.zeros((1, 3)), 1]]))
             for T in targets]
    solved = [eaik.IK(T) for T in local]
    found = [np.array(s.Q)[~np.asarray(s.is_LS, dtype=bool)] for s in solved]
    rows.append(("EAIK", timed(eaik.IK, [(T,) for T in local], rounds), quality(robot, q, targets, found)))

    if robot.name == "iiwa":
        starts = q + 0.1 * rng.choice([-1.0, 1.0], size=q.shape)
        runs = [library.ik_numeric(T, start, 100, 1e-12) for T, start in zip(targets, starts)]
        found = [[x] if status == 0 else [] for x, status in runs]
        rows.append(("ik_numeric", timed(lambda T, start: library.ik_numeric(T, start, 100, 1e-12),
                                         list(zip(targets, starts)), rounds),
                     quality(robot, q, targets, found)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=10_000)
    parser.add_argument("--rounds", type=int, default=5)
    arguments = parser.parse_args()
    robots = [panda_flange(), load_robot(ROOT / "robots" / "iiwa.yaml")]
    print(f"{arguments.targets} random in-limit poses per robot, median of {arguments.rounds} rounds")
    print(f"{'robot':6s} {'solver':13s} {'us/call':>9s} {'solutions':>10s} {'in limits':>10s} "
          f"{'recovered':>10s} {'misses':>9s}")
    with tempfile.TemporaryDirectory() as temporary:
        for robot in robots:
            for label, micros, (returned, inside, recovered, missed) in run(robot, arguments.targets,
                                                                             arguments.rounds, Path(temporary)):
                print(f"{robot.name:6s} {label:13s} {micros:9.3f} {returned:10.3f} {inside:10.3f} "
                      f"{100 * recovered:9.3f}% {100 * missed:8.4f}%")


if __name__ == "__main__":
    main()
