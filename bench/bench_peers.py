"""Benchmark: jacgen's fk + jacobian beside CasADi, Pinocchio and the Robotics Toolbox.

    PYTHONPATH=. python bench/bench_peers.py [--calls 1000000] [--rounds 5] [--pinocchio-cpp]

One run prints, for puma560, ur5 and panda, the time of one call computing the tool pose T
and the world-frame geometric Jacobian J, and its ratio to jacgen's C:

- native, in one C harness compiled with gcc -O2 (built by `bench_fk_jacobian.harness`,
  `--calls` calls per measurement, the joint vector changed on every call, outputs summed
  into a volatile sink; rounds interleave robots and implementations):
  "jacgen C" is `NAME_fk_jacobian(q, T, J)` (double); "casadi C" and "casadi cse C" are
  CasADi's generated C for the same DH table (`bench_fk_jacobian.casadi_fk_jacobian`),
  as built and after `casadi.cse` (the harness also times bench_fk_jacobian's other
  variants, fk alone, jacobian alone and the trig floor; they are not shown here);
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
  `forwardKinematics` + `computeFrameJacobian` natively (-O2 -DNDEBUG) on the same models,
  saved by Python with `Model.saveToBinary` and loaded by the C++ harness.

Every figure is the median of `--rounds` rounds. Before timing, each peer's T and J are
checked against jacgen's at one configuration (1e-9).
"""

import argparse
import importlib.util
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench"), str(ROOT / "tests")]

from bench_fk_jacobian import native_times  # noqa: E402
from jacgen.render import render_robot, write_files  # noqa: E402
from jacgen.robot import load_robot  # noqa: E402

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    import pinocchio as pin  # noqa: E402
    import roboticstoolbox as rtb  # noqa: E402
    from test_external_libraries import pinocchio_from_dh  # noqa: E402

ROBOTS = ("puma560", "ur5", "panda")
RTB_MODELS = {"puma560": rtb.models.DH.Puma560, "ur5": rtb.models.DH.UR5, "panda": rtb.models.DH.Panda}
NATIVE = {"jacgen C": "ours", "casadi C": "casadi", "casadi cse C": "casadi_cse"}
PYTHON_CALLS = {"pinocchio py": 20_000, "rtb py": 2_000, "jacgen py": 2_000}
BATCH = 1_000_000
PREFIX = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
# INTERFACE_COMPILE_DEFINITIONS of the wheel's pinocchio::pinocchio_headers CMake target.
PINOCCHIO_DEFINITIONS = ("-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                         "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12")


# -- called from Python ------------------------------------------------------------------------
def load_generated(robot, folder: Path):
    """jacgen's generated numpy module for `robot`, rendered into `folder` and imported."""
    write_files(render_robot(robot, ("python",), "double"), folder)
    path = folder / robot.name / f"{robot.name}.py"
    spec = importlib.util.spec_from_file_location(f"bench_{robot.name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.fk_jacobian


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


def time_per_call(function, qs) -> float:
    """ns per call of `function` over the rows of `qs`."""
    start = time.perf_counter()
    for q in qs:
        function(q)
    return (time.perf_counter() - start) * 1e9 / len(qs)


def python_times(peers, rounds: int) -> dict[tuple[str, str], float]:
    """Median ns per call, {(robot, label): ns}, of peers {robot: (dof, {label: function})}.

    Every round times every robot and library once.
    """
    times: dict[tuple[str, str], list[float]] = {}
    samples = {(name, label): configurations(dof, count)
               for name, (dof, _) in peers.items() for label, count in PYTHON_CALLS.items()}
    for _ in range(rounds):
        for name, (_, functions) in peers.items():
            for label, function in functions.items():
                times.setdefault((name, label), []).append(time_per_call(function, samples[(name, label)]))
    return {key: statistics.median(values) for key, values in times.items()}


def batch_seconds(fk_jacobian, qs, rounds: int) -> float:
    """Median seconds of one call of the generated `fk_jacobian` on the whole batch `qs`."""
    seconds = []
    for _ in range(rounds):
        start = time.perf_counter()
        fk_jacobian(qs)
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)


def check_agreement(name, functions, q):
    """Every peer's T and J equal jacgen's at q: the timings compare the same numbers."""
    T, J = functions["jacgen py"](q)
    for label, function in functions.items():
        theirs = function(q)
        for mine, other in zip((T, J), theirs):
            assert np.allclose(mine, np.asarray(other), atol=1e-9), f"{name}: {label} disagrees with jacgen"


# -- optional: Pinocchio from C++ ----------------------------------------------------------------
PINOCCHIO_CPP = """
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/serialization.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>

int main(int argc, char **argv)
{
    const long calls = std::atol(argv[1]);
    const int rounds = std::atoi(argv[2]);
    const int robots = (argc - 3) / 2;
    std::vector<pinocchio::Model> models(robots);
    for (int r = 0; r < robots; ++r) models[r].loadFromBinary(argv[3 + 2 * r + 1]);
    volatile double global_sink = 0;
    for (int round = 0; round < rounds; ++round) {
        for (int r = 0; r < robots; ++r) {
            const pinocchio::Model &model = models[r];
            pinocchio::Data data(model);
            const pinocchio::FrameIndex frame = model.getFrameId("tool");
            Eigen::VectorXd q0(model.nq), q(model.nq);
            for (int j = 0; j < model.nq; ++j) q0[j] = 0.3 + 0.1 * j;
            pinocchio::Data::Matrix6x J = pinocchio::Data::Matrix6x::Zero(6, model.nv);
            double sink = 0;
            const auto t0 = std::chrono::steady_clock::now();
            for (long i = 0; i < calls; ++i) {
                const double step = (double)(i & 1023) * 1e-6;
                for (int j = 0; j < model.nq; ++j) q[j] = q0[j] + step * (double)(j + 1);
                pinocchio::forwardKinematics(model, data, q);
                pinocchio::computeFrameJacobian(model, data, q, frame, pinocchio::LOCAL_WORLD_ALIGNED, J);
                sink += data.oMf[frame].translation()[0] + J(5, model.nv - 1);
            }
            const auto t1 = std::chrono::steady_clock::now();
            global_sink = global_sink + sink;
            std::printf("%s %d %.3f\\n", argv[3 + 2 * r], round,
                        std::chrono::duration<double, std::nano>(t1 - t0).count() / (double)calls);
        }
    }
    return global_sink != global_sink;
}
"""


def pinocchio_cpp_times(models, folder: Path, calls: int, rounds: int) -> dict[tuple[str, str], float]:
    """Median ns per call of Pinocchio in C++, {(robot, "pinocchio C++"): ns}."""
    arguments = []
    for name, model in models.items():
        model.saveToBinary(str(folder / f"{name}.pin"))
        arguments += [name, str(folder / f"{name}.pin")]
    (folder / "pinocchio.cpp").write_text(PINOCCHIO_CPP)
    include, lib = PREFIX / "include", PREFIX / "lib"
    subprocess.run(["g++", "-std=c++17", "-O2", "-DNDEBUG", *PINOCCHIO_DEFINITIONS,
                    f"-I{include}", f"-I{include / 'eigen3'}",
                    "-o", str(folder / "pinocchio"), str(folder / "pinocchio.cpp"), f"-L{lib}", f"-Wl,-rpath,{lib}",
                    "-lpinocchio_default", "-lboost_serialization"], check=True)
    output = subprocess.run([str(folder / "pinocchio"), str(calls), str(rounds), *arguments],
                            check=True, capture_output=True, text=True).stdout
    times: dict[tuple[str, str], list[float]] = {}
    for line in output.splitlines():
        name, _, nanoseconds = line.split()
        times.setdefault((name, "pinocchio C++"), []).append(float(nanoseconds))
    return {key: statistics.median(values) for key, values in times.items()}


# -- the table ---------------------------------------------------------------------------------
def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=1_000_000, help="native calls per measurement")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--pinocchio-cpp", action="store_true", help="also time Pinocchio natively (slow build)")
    arguments = parser.parse_args()
    robots = [load_robot(ROOT / "robots" / f"{name}.yaml") for name in ROBOTS]
    models = {robot.name: pinocchio_from_dh(robot) for robot in robots}
    with tempfile.TemporaryDirectory(prefix="jacgen-peers-") as temporary:
        folder = Path(temporary)
        native = native_times(robots, folder, arguments.calls, arguments.rounds)
        median = {(robot.name, label): native[(robot.name, variant)] for robot in robots
                  for label, variant in NATIVE.items()}
        columns = list(NATIVE)
        if arguments.pinocchio_cpp:
            median |= pinocchio_cpp_times(models, folder, arguments.calls, arguments.rounds)
            columns.append("pinocchio C++")
        peers = {}
        for robot in robots:
            functions = python_peers(robot, load_generated(robot, folder / "python"), models[robot.name])
            check_agreement(robot.name, functions, configurations(robot.dof, 1, seed=1)[0])
            peers[robot.name] = (robot.dof, functions)
        median |= python_times(peers, arguments.rounds)
        columns += list(PYTHON_CALLS)
        seconds = batch_seconds(peers["ur5"][1]["jacgen py"], configurations(6, BATCH), arguments.rounds)
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
