"""Benchmark: jacgen's closed-form C ik (every branch) beside EAIK and ik-geo.

    PYTHONPATH=. python bench/bench_ik.py [--targets 2000] [--rounds 7]

For the UR5 and the Puma 560, the same random reachable poses (fk of random joint vectors
inside the limits) are solved by (every branch: the arms are generated without their joint
limits, which EAIK and ik-geo do not apply):

- "C native": the generated `NAME_ik` (double) called in a native loop by common.py's
  harness and flags (-O2; the generated file in its own translation unit);
- "C via ctypes": the same C as a shared library called from Python, one call per pose;
- "EAIK": `eaik.IK_DH.DhRobot(...).IK(T)` from Python (its C++ solver through pybind11);
- "ik-geo": `ik_geo.Robot.three_parallel_two_intersecting` / `spherical_two_parallel`
  `.get_ik(R, t)` from Python (its Rust solver through PyO3).

Every solver returns all branches; the table gives microseconds per pose (median over
rounds after a warm-up round), the real solutions found (EAIK and ik-geo also return least-squares candidates,
not counted) and each time over the C-via-ctypes one. The derivation time of every shipped
robot's closed form (structure detection and exact constants, `jacgen.ik.closed_form`) is
printed first.

A second table has the general 6R solver (class general_6r) on the shipped Jaco, Manocha-Canny
arm and calibrated UR5, the calibrated Puma 560 and KR5 of tests/data/calibrated/, the UR5 and
Puma 560 perturbed at random there (twists by up to 5e-3 rad, lengths by up to 0.5 mm), and the
7-axis Sawyer and calibrated Panda with joint 7 free (at its generating value), on random
poses (fk of uniform joint vectors): the C `NAME_ik` in a native loop (for a
calibrated arm: with its fast path, with the eigenproblem alone, and the nominal arm's own
closed form as the yardstick; and the native module's `ik_branches` on the batch, one thread: the
same C built as `jacgen.arm(..., backend="native")` builds it, vectorised for this machine, so that
the fast path's 8 Newton rows run in vector lanes), the batched numpy `ik_branches` (all poses in
one call), and ssik 8.2.0
(`ssik.Manipulator.from_dh(...).solve`, its C++ path, when installed; its `prepare` takes
30-60 s per arm and is not timed). Per solver: microseconds per pose, the mean number of
solutions, the rate at which the generating configuration is among them, the rate of
solutions that miss the target by more than 1e-8, and how often the count equals ssik's.
"""

import argparse
import ctypes
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from eaik.IK_DH import DhRobot
from ik_geo import Robot as IkGeoRobot

import common
import jacgen
from common import kinematic_chain, without_limits
from jacgen.checking import reference
from jacgen.checking.c_library import CLibrary
from jacgen.emission.generator import Generator
from jacgen.solvers.ik import closed_form
from jacgen.solvers.model import Model
from jacgen.inputs.robot_file import load_robot

ROBOTS = {"ur5": IkGeoRobot.three_parallel_two_intersecting, "puma560": IkGeoRobot.spherical_two_parallel}
GENERAL = ("jaco", "manocha_canny", "ur5_calibrated", "puma560_calibrated", "kr5_calibrated", "ur5_perturbed",
           "puma560_perturbed", "sawyer", "panda_calibrated")


def per_pose(solve, targets, rounds: int) -> tuple[float, int]:
    """Median microseconds per pose of `solve(T) -> count` called from Python, and the count."""
    timing = common.timed(lambda: sum(solve(T) for T in targets), rounds)
    return timing.seconds * 1e6 / len(targets), timing.result


def solvers(robot, library, ik_geo_factory):
    """Functions pose -> number of real solutions, for each solver called from Python."""
    function = library[f"{robot.name}_ik"]
    function.argtypes, function.restype = [ctypes.c_void_p, ctypes.c_void_p], ctypes.c_int
    out = np.zeros(8 * robot.dof)
    address = out.ctypes.data

    def ours(T):  # T: a C-contiguous float64 4x4 array, passed by address
        return function(T.ctypes.data, address)

    alpha, a, d = (np.array([getattr(joint, key).approx for joint in robot.joints]) for key in ("alpha", "a", "d"))
    eaik = DhRobot(alpha, a, d)

    def theirs_eaik(T):
        return int(np.count_nonzero(~np.asarray(eaik.IK(T).is_LS, dtype=bool)))

    H, P, tool_rotation = kinematic_chain(robot)
    geo = ik_geo_factory(H, P)

    def theirs_ik_geo(T):  # ik-geo takes R as a list of columns, and the tool rotation as identity
        return sum(not least_squares for _, least_squares in geo.get_ik((T[:3, :3] @ tool_rotation.T).T, T[:3, 3]))

    return {"C via ctypes": ours, "EAIK": theirs_eaik, "ik-geo": theirs_ik_geo}


def _ssik_solver(robot):
    """ssik's solver for the arm as (target -> solutions as jacgen's q), None without ssik."""
    try:
        import ssik
    except ImportError:
        return None
    alpha, a, d, offset = (np.array([getattr(joint, key).approx for joint in robot.joints])
                           for key in ("alpha", "a", "d", "offset"))
    arm = ssik.Manipulator.from_dh(alpha, a, d)
    arm.prepare()
    head = np.linalg.inv(reference._pose(robot.base))  # ssik's chain starts at frame 0, without a base
    tool = np.linalg.inv(reference._pose(robot.tool))

    def solve(T):
        return [common.wrapped(np.asarray(s.q) - offset) for s in arm.solve(head @ T @ tool, respect_limits=False)]
    return solve


def _general_arm(name: str):
    """A shipped arm, or one of the calibrated arms of tests/data/calibrated/."""
    return load_robot(common.robot_path(name))


def valid_rows(library: CLibrary, T: np.ndarray, free: tuple) -> np.ndarray:
    """The solutions of NAME_ik_branches at T, inside the joint limits or not (as numpy's and
    ssik's are counted)."""
    branches, valid, _ = library.call("ik_branches", T, *free)
    return branches[valid.astype(bool)]


def general_table(targets_count: int, rounds: int, folder: Path) -> None:
    """The general 6R solver beside ssik (see the module docstring)."""
    print(f"\ngeneral 6R solver, {targets_count} random poses; us per pose (median of {rounds} rounds); "
          "recovered = the generating configuration among the solutions; off = solutions missing by > 1e-8")
    print(f"{'robot':19s} {'solver':32s} {'us/pose':>9s} {'mean sol':>9s} {'recovered':>10s} {'off':>8s} "
          f"{'= ssik count':>12s}")
    for name in GENERAL:
        robot = _general_arm(name)
        code = common.generate(robot, folder, ("c", "python"))
        library = CLibrary(common.shared_library(code / f"{name}.c"), robot,
                           Generator(robot, selection=("ik_branches",)).signatures(), "double")
        module = common.load_module(code / f"{name}.py")
        q = np.random.default_rng(5).uniform(-np.pi, np.pi, (targets_count, robot.dof))
        targets = reference.fk(robot, q)
        form = Model(robot).closed_form
        frees = None if form.free is None else q[:, form.free]  # a 7R arm: the free joint's angle
        free = (lambda k: ()) if frees is None else (lambda k: (frees[k],))
        rows = {}
        micros, _ = common.native_ik(robot, code / f"{name}.c", targets, rounds, folder, frees)
        fast = form.fast_path
        label = "C native, fast path" if fast else "C native"
        rows[label] = (micros, [valid_rows(library, T, free(k)) for k, T in enumerate(targets)])
        if fast:
            alone = replace(robot, name=f"{name}_eigen", nearest_class=False)
            source = common.generate(alone, folder) / f"{alone.name}.c"
            alone_library = CLibrary(common.shared_library(source), alone,
                                     Generator(alone, selection=("ik_branches",)).signatures(), "double")
            micros, _ = common.native_ik(alone, source, targets, rounds, folder, frees)
            rows["C native, eigenproblem only"] = (micros, [valid_rows(alone_library, T, free(k))
                                                            for k, T in enumerate(targets)])
            nominal = replace(fast.nominal.robot, name=f"{name}_nominal")
            source = common.generate(nominal, folder) / f"{nominal.name}.c"
            micros, _ = common.native_ik(nominal, source, targets, rounds, folder, frees)
            rows["C native, nominal arm's closed form"] = (micros, None)
            native = jacgen.arm(common.robot_path(name), backend="native", functions="ik_branches", cache_folder=folder)
            timing = common.timed(lambda: native.ik_branches(targets, *([] if frees is None else [frees]), threads=1),
                                  rounds)
            branches, valid, _ = timing.result
            rows[f"native module ({native.SIMD}), fast path"] = (timing.seconds * 1e6 / len(targets),
                                                               [b[v] for b, v in zip(branches, valid)])
            decided = module._fast_branches(targets, *([] if frees is None else [frees]))[2].mean()
            print(f"{name:19s} the fast path decides {decided:.1%} of the poses; the rest go to the eigenproblem")
        batch = common.timed(lambda: module.ik_branches(targets, *([] if frees is None else [frees])), rounds)
        branches, valid, _ = batch.result
        rows["numpy batched"] = (batch.seconds * 1e6 / len(targets), [b[v] for b, v in zip(branches, valid)])
        ssik_solve = _ssik_solver(robot) if robot.dof == 6 else None
        if ssik_solve is not None:
            timing = common.timed(lambda: [ssik_solve(T) for T in targets], rounds)
            rows["ssik"] = (timing.seconds * 1e6 / len(targets), timing.result)
        for label, (micros, found) in rows.items():
            if found is None:  # the nominal arm's own solutions, not this arm's: its time only
                print(f"{name:19s} {label:32s} {micros:9.2f}")
                continue
            mean, recovered, off = common.ik_quality(robot, q, targets, found)
            same = (f"{np.mean([len(a) == len(b) for a, b in zip(found, rows['ssik'][1])]):12.1%}"
                    if "ssik" in rows else f"{'-':>12s}")
            print(f"{name:19s} {label:32s} {micros:9.2f} {mean:9.2f} {recovered:10.1%} {off:8.2%} {same}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--targets", type=int, default=2000)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--general-targets", type=int, default=500)
    arguments = parser.parse_args()

    print("derivation of the closed form (structure detection + exact constants):")
    for path in sorted((common.ROOT / "robots").glob("*.yaml")):
        robot = common.shipped(path.stem)
        start = time.perf_counter()
        form = closed_form(robot)
        print(f"  {robot.name:10s} {1e3 * (time.perf_counter() - start):7.1f} ms  {form.solver if form else '-'}")

    rows = []
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        for name, ik_geo_factory in ROBOTS.items():
            shipped = common.shipped(name)
            robot = without_limits(shipped)  # every branch, as EAIK and ik-geo return them
            source = common.generate(robot, folder) / f"{name}.c"
            library = ctypes.CDLL(str(common.shared_library(source)))
            rng = np.random.default_rng(1)
            limits = np.array([joint.limits for joint in shipped.joints])
            q = rng.uniform(limits[:, 0], limits[:, 1], (arguments.targets, robot.dof))
            targets = reference.fk(robot, q)
            results = {"C native": common.native_ik(robot, source, targets, arguments.rounds, folder)}
            for label, solve in solvers(robot, library, ik_geo_factory).items():
                results[label] = per_pose(solve, targets, arguments.rounds)
            rows.append((name, results))

        general_table(arguments.general_targets, 3, folder)

    print(f"\nus per pose (all branches), median of {arguments.rounds} rounds over {arguments.targets} poses;"
          " ratio = time / C via ctypes")
    print(f"{'robot':8s} {'solver':13s} {'us/pose':>9s} {'solutions':>10s} {'ratio':>7s}")
    for name, results in rows:
        base = results["C via ctypes"][0]
        for label, (micros, found) in results.items():
            print(f"{name:8s} {label:13s} {micros:9.3f} {found:10d} {micros / base:7.2f}")


if __name__ == "__main__":
    main()
