"""Benchmark: closed-form ik of 7-axis arms with a free joint, beside frankik, EAIK and ik_numeric.

    PYTHONPATH=. python bench/bench_free_joint_ik.py [--targets 10000] [--rounds 5]

Panda (joint 7 free) and iiwa (joint 3 free), each on the same random poses for every
solver: fk of random joint vectors inside the limits, with the free joint at one value
(Panda q7 = pi/4, frankik's default; iiwa q3 = 0.3), since EAIK locks a joint when its
robot is built. The Panda has no hand here: frankik's ik takes the flange pose.

- "C native": the generated `NAME_ik(T, q_free, q)` (double) in a native loop
  (`common.native_ik`, as in bench_ik.py);
- "C via ctypes": the same library called from Python, one call per pose, the pose copied
  into a buffer whose address is taken once (`T.ctypes.data` per call would cost 2 us);
- "numpy batch": the generated Python `ik(T, q_free)` on all poses at once (time per pose);
- "frankik" (Panda): `frankik.ik_full(T, q, q7)`, He & Liu's solver (up to 4 solutions);
- "EAIK": `eaik.IK_HP.HPRobot(H, P, fixed_axes=[(k, value)]).IK(T)`, real solutions only;
- "ik_numeric" (iiwa): the generated C `NAME_ik_numeric`, 100 steps at most, started
  0.1 rad from the configuration on every joint (a tracking controller's seed).

Columns: microseconds per call (median over rounds, after a warm-up round), mean
solutions returned per pose, mean of them with every joint inside the limits (modulo
2 pi), the share of poses whose original configuration is among the solutions (every joint
within 1e-6 rad, modulo 2 pi), and the share of returned solutions that miss the target by
more than 1e-8 (largest entry of the 4x4 difference, jacgen.reference fk;
`common.ik_quality`). ik-geo has no locked-joint option and is not run.
"""

import argparse
import ctypes
import tempfile
from pathlib import Path

import frankik
import numpy as np
from eaik.IK_HP import HPRobot

import common
from common import kinematic_chain
from jacgen.checking import reference
from jacgen.checking.c_library import CLibrary
from jacgen.emission.generator import Generator
from jacgen.inputs.robot_file import parse_robot

FREE_VALUE = {"panda": np.pi / 4, "iiwa": 0.3}


def panda_flange():
    """The shipped Panda without its hand: the flange pose is what frankik's ik takes."""
    text = (common.ROOT / "robots" / "panda.yaml").read_text()
    return parse_robot(text.replace("tool: {xyz: [0, 0, 0.103], rpy: [0, 0, -45]}", "").encode(), "panda.yaml")


def quality(robot, q: np.ndarray, targets: np.ndarray, solutions: list) -> tuple[float, float, float, float]:
    """Mean solutions, mean within limits (mod 2 pi), recovery rate and miss rate."""
    lower, upper = np.array([joint.limits for joint in robot.joints]).T
    inside = 0
    for found in solutions:
        shifted = lower + (np.reshape(found, (-1, robot.dof)) - lower) % (2 * np.pi)  # the lowest equivalent >= lower
        inside += int(np.sum(np.all(shifted <= upper, axis=1)))
    returned, recovered, missed = common.ik_quality(robot, q, targets, solutions)
    return returned, inside / len(q), recovered, missed


def run(robot, count: int, rounds: int, folder: Path) -> list[tuple[str, float, tuple]]:
    rng = np.random.default_rng(7)
    limits = np.array([joint.limits for joint in robot.joints])
    free, value = robot.free_joint, FREE_VALUE[robot.name]
    q = rng.uniform(limits[:, 0], limits[:, 1], (count, robot.dof))
    q[:, free] = value
    targets = reference.fk(robot, q)
    frees = q[:, free]

    code = common.generate(robot, folder, ("c", "python"))
    source = code / f"{robot.name}.c"
    library = CLibrary(common.shared_library(source), robot,
                       Generator(robot, selection=("ik", "ik_numeric")).signatures(), "double")
    module = common.load_module(code / f"{robot.name}.py")
    rows = []

    micros, _ = common.native_ik(robot, source, targets, rounds, folder, frees)
    function = library._library[f"{robot.name}_ik"]
    function.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_void_p]
    pose, out = np.zeros((4, 4)), np.zeros(8 * robot.dof)  # buffers a caller reuses: their addresses once
    pose_address, out_address = pose.ctypes.data, out.ctypes.data

    def call(T, angle):
        pose[...] = T
        return function(pose_address, angle, out_address)
    ctypes_micros = common.per_call(call, list(zip(targets, frees)), rounds) * 1e6
    ours = [q[:count] for q, count in (library.call("ik", T, angle) for T, angle in zip(targets, frees))]
    measured = quality(robot, q, targets, ours)
    rows += [("C native", micros, measured), ("C via ctypes", ctypes_micros, measured)]

    batch = common.timed(lambda: module.ik(targets, frees), rounds)
    branches, valid = batch.result
    rows.append(("numpy batch", batch.seconds * 1e6 / count,
                 quality(robot, q, targets, [b[v] for b, v in zip(branches, valid)])))

    if robot.name == "panda":
        def solve_frankik(T, row, angle):
            return frankik.ik_full(T, row, angle)
        arguments = list(zip(targets, q, frees))
        found = [[x for x in solve_frankik(*argument) if np.all(np.isfinite(x))] for argument in arguments]
        rows.append(("frankik", common.per_call(solve_frankik, arguments, rounds) * 1e6,
                     quality(robot, q, targets, found)))

    H, P, tool_rotation = kinematic_chain(robot)
    eaik = HPRobot(H, P, fixed_axes=[(free, value)])
    local = [np.ascontiguousarray(np.block([[T[:3, :3] @ tool_rotation.T, T[:3, 3:]], [np.zeros((1, 3)), 1]]))
             for T in targets]
    solved = [eaik.IK(T) for T in local]
    found = [np.array(s.Q)[~np.asarray(s.is_LS, dtype=bool)] for s in solved]
    rows.append(("EAIK", common.per_call(eaik.IK, [(T,) for T in local], rounds) * 1e6,
                 quality(robot, q, targets, found)))

    if robot.name == "iiwa":
        starts = q + 0.1 * rng.choice([-1.0, 1.0], size=q.shape)
        runs = [library.call("ik_numeric", T, start, 100, 1e-12) for T, start in zip(targets, starts)]
        found = [[x] if status == 0 else [] for x, status in runs]
        rows.append(("ik_numeric", common.per_call(lambda T, start: library.call("ik_numeric", T, start, 100, 1e-12),
                                                   list(zip(targets, starts)), rounds) * 1e6,
                     quality(robot, q, targets, found)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=10_000)
    parser.add_argument("--rounds", type=int, default=5)
    arguments = parser.parse_args()
    robots = [panda_flange(), common.shipped("iiwa")]
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
