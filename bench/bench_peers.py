"""Benchmark: jacgen's fk + jacobian beside CasADi, Pinocchio and the Robotics Toolbox.

    PYTHONPATH=. python bench/bench_peers.py [--calls 1000000] [--rounds 5] [--pinocchio-cpp]

One run prints, for puma560, ur5 and panda, the time of one call computing the tool pose T
and the world-frame geometric Jacobian J, and its ratio to jacgen's C:

- native, in one harness (common.py's: built with -O2, `--calls` calls per measurement,
  the joint vector changed on every call, outputs summed into a volatile sink; rounds
  interleave robots and implementations): "jacgen C" is `NAME_fk_jacobian(q, T, J)`
  (double); "casadi C" and "casadi cse C" are CasADi's generated C for the same DH table
  (`common.casadi_fk_jacobian`), as built and after `casadi.cse`;
- called from Python, one configuration per call (Pinocchio 20,000 calls per measurement,
  the others 2,000): "pinocchio py" is `forwardKinematics` + `computeFrameJacobian(...,
  LOCAL_WORLD_ALIGNED)` on a `pinocchio.Model` built from the DH table by the test suite's
  `pinocchio_from_dh`; "rtb py" is `fkine(q)` + `jacob0(q)` of `rtb.models.DH.*`; "jacgen py"
  is the generated numpy module's `fk_jacobian(q)`. Rounds interleave robots and libraries.
  These times include the Python call overhead (argument conversion, allocating results),
  which for Pinocchio is most of the time: they are what a Python user pays per call, not a
  like-for-like comparison with the native C.
- batch: the generated numpy `fk_jacobian(q)` on one array of 10^6 ur5 configurations
  (shape (1000000, 6)): total seconds (goal < 1 s) and ns per configuration.
- `--pinocchio-cpp` (off by default and kept out of CI: compiling against Pinocchio's
  headers takes about a minute and needs `cmeel-eigen` in the venv): "pinocchio C++" times
  `forwardKinematics` + `computeFrameJacobian` natively in the same harness, then compiled
  as C++ (same flags), on the same models, saved by Python with `Model.saveToBinary` and
  loaded by the harness.

Every figure is the median of `--rounds` rounds after a warm-up round (common.py's timer
policy). Before timing, each peer's T and J are checked against jacgen's at one
configuration (1e-9).
"""

import argparse
import tempfile
import warnings
from pathlib import Path

import numpy as np

import common
from common import pinocchio_from_dh

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import pinocchio as pin
    import roboticstoolbox as rtb

ROBOTS = ("puma560", "ur5", "panda")
RTB_MODELS = {"puma560": rtb.models.DH.Puma560, "ur5": rtb.models.DH.UR5, "panda": rtb.models.DH.Panda}
PYTHON_CALLS = {"pinocchio py": 20_000, "rtb py": 2_000, "jacgen py": 2_000}
BATCH = 1_000_000


# -- native ------------------------------------------------------------------------------------
def native_times(robots, folder: Path, calls: int, rounds: int, pinocchio_cpp: bool) -> dict[tuple[str, str], float]:
    """{(robot, label): median ns per call} of jacgen's C, CasADi's C and, with `pinocchio_cpp`,
    Pinocchio's C++, in one harness."""
    sources, loops = [], []
    for robot in robots:
        sources.append(common.generate(robot, folder) / f"{robot.name}.c")
        loops.append(common.fk_jacobian_loop(robot, "jacgen C"))
        for variant, function in common.casadi_variants(robot).items():
            sources.append(common.casadi_c(function, folder))
            loops.append(common.casadi_loop(robot, function, variant.replace("_", " ") + " C"))
    header = "\n".join(f'#include "{robot.name}.h"' for robot in robots)
    if not pinocchio_cpp:
        program = common.build(folder, "harness", common.harness(loops, header), sources)
        return common.run_loops(program, calls, rounds)
    models, setup, arguments = common.pinocchio_models(robots, folder)
    loops += [common.pinocchio_fk_jacobian_loop(robot, "pinocchio C++") for robot in robots]
    program = common.build(folder, "harness", common.harness(loops, f"{models}\n{header}", setup), sources, "c++",
                           common.PINOCCHIO_OPTIONS, common.PINOCCHIO_LIBRARIES)
    return common.run_loops(program, calls, rounds, *arguments)


# -- called from Python ------------------------------------------------------------------------
def python_peers(robot, fk_jacobian, model):
    """{label: function of q returning (T, J)} for the implementations called from Python."""
    data, frame = model.createData(), model.getFrameId("tool")
    toolbox = RTB_MODELS[robot.name]()

    def pinocchio(q):
        pin.forwardKinematics(model, data, q)
        J = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        return data.oMf[frame].homogeneous, J

    def toolbox_call(q):
        return toolbox.fkine(q).A, toolbox.jacob0(q)

    return {"pinocchio py": pinocchio, "rtb py": toolbox_call, "jacgen py": fk_jacobian}


def configurations(dof: int, count: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-np.pi, np.pi, (count, dof))


def python_times(peers, rounds: int) -> dict[tuple[str, str], float]:
    """Median ns per call, {(robot, label): ns}, of peers {robot: (dof, {label: function})};
    every round times every robot and library once."""
    samples = {(name, label): configurations(dof, count)
               for name, (dof, _) in peers.items() for label, count in PYTHON_CALLS.items()}
    runs = {(name, label): common.each(function, [(q,) for q in samples[(name, label)]])
            for name, (_, functions) in peers.items() for label, function in functions.items()}
    return {key: timing.seconds * 1e9 / len(samples[key]) for key, timing in common.median_times(runs, rounds).items()}


def check_agreement(name, functions, q):
    """Every peer's T and J equal jacgen's at q: the timings compare the same numbers."""
    T, J = functions["jacgen py"](q)
    for label, function in functions.items():
        theirs = function(q)
        for mine, other in zip((T, J), theirs):
            assert np.allclose(mine, np.asarray(other), atol=1e-9), f"{name}: {label} disagrees with jacgen"


# -- the table ---------------------------------------------------------------------------------
def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=1_000_000, help="native calls per measurement")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--pinocchio-cpp", action="store_true", help="also time Pinocchio natively (slow build)")
    arguments = parser.parse_args()
    robots = [common.shipped(name) for name in ROBOTS]
    columns = ["jacgen C", "casadi C", "casadi cse C"] + ["pinocchio C++"] * arguments.pinocchio_cpp
    with tempfile.TemporaryDirectory(prefix="jacgen-peers-") as temporary:
        folder = Path(temporary)
        median = native_times(robots, folder, arguments.calls, arguments.rounds, arguments.pinocchio_cpp)
        peers = {}
        for robot in robots:
            module = common.load_module(common.generate(robot, folder / "python", ("python",)) / f"{robot.name}.py")
            functions = python_peers(robot, module.fk_jacobian, pinocchio_from_dh(robot))
            check_agreement(robot.name, functions, configurations(robot.dof, 1, seed=1)[0])
            peers[robot.name] = (robot.dof, functions)
        median |= python_times(peers, arguments.rounds)
        columns += list(PYTHON_CALLS)
        batch = configurations(6, BATCH)
        seconds = common.timed(lambda: peers["ur5"][1]["jacgen py"](batch), arguments.rounds).seconds
    print(f"median of {arguments.rounds} interleaved rounds; native: {arguments.calls} calls per measurement, gcc -O2,"
          f" double; python: {', '.join(f'{label} {count}' for label, count in PYTHON_CALLS.items())} calls")
    ns = [["ns per call"] + columns] + [[robot.name] + [f"{median[(robot.name, label)]:.1f}" for label in columns]
                                        for robot in robots]
    ratios = [["/ jacgen C"] + columns] + [
        [robot.name] + [f"{median[(robot.name, label)] / median[(robot.name, columns[0])]:.2f}" for label in columns]
        for robot in robots]
    for table in (ns, ratios):
        widths = [max(len(row[c]) for row in table) for c in range(len(table[0]))]
        for row in table:
            print("  ".join(cell.rjust(width) for cell, width in zip(row, widths)))
    print(f"jacgen py batch fk_jacobian, ur5, {BATCH} configurations: {seconds:.3f} s total (goal < 1 s), "
          f"{seconds * 1e9 / BATCH:.1f} ns per configuration")


if __name__ == "__main__":
    main()
