"""Benchmark: second-order kinematics, jacgen's C beside Pinocchio's C++ in one harness.

    PYTHONPATH=. python bench/bench_second_order.py [--calls 200000] [--rounds 7] [--sizes 2,3,4,6,8,10,12,16,24] [--repeats 3]

One C++ program, compiled with -O2 against Pinocchio (from the `pin` wheel) and linked with
jacgen's generated C (double, compiled as C with -O2, its own translation unit), times per
robot and per round, in the same loop (the joint vector changes every call, results go to
a sink):

- ours fk_jacobian: `NAME_fk_jacobian(q, T, J)`;
- ours fk_jacobian_dot: `NAME_fk_jacobian_dot(q, q_dot, T, J, a)` (T, J and J' q_dot);
- pinocchio fk_jacobian: forwardKinematics + computeFrameJacobian (LOCAL_WORLD_ALIGNED);
- pinocchio dot: forwardKinematics + computeJointJacobiansTimeVariation, then the frame's
  J and J' (getFrameJacobian, getFrameJacobianTimeVariation, LOCAL_WORLD_ALIGNED) and J' q_dot.

The Pinocchio models are built from the robot files (tests/test_external_libraries.py), so
both sides compute the same numbers; the table shows medians over the rounds in ns per
call, then the operation counts. Then the mean operation count of bias_acceleration over
random arms of each size (tests/random_arms.py) and its log-log slope against the joint count.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "bench"), str(ROOT / "tests")]

from bench_peers import PINOCCHIO_DEFINITIONS, PREFIX  # noqa: E402
from bench_scaling import slope  # noqa: E402
from jacgen.functions import Generator  # noqa: E402
from jacgen.render import render_robot, write_files  # noqa: E402
from jacgen.robot import load_robot, parse_robot  # noqa: E402

ROBOTS = ("puma560", "ur5", "panda")
VARIANTS = ("ours fk_jacobian", "ours fk_jacobian_dot", "pinocchio fk_jacobian", "pinocchio dot")

HARNESS = """
#include <pinocchio/multibody.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/serialization.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
extern "C" {
%(declarations)s
}

template <class F> static double time_per_call(long calls, int n, F body)
{
    double q[32], qd[32];
    for (int j = 0; j < n; ++j) qd[j] = 0.5 - 0.1 * j;
    const auto t0 = std::chrono::steady_clock::now();
    for (long i = 0; i < calls; ++i) {
        const double step = (double)(i & 1023) * 1e-6;
        for (int j = 0; j < n; ++j) q[j] = 0.3 + 0.1 * j + step * (double)(j + 1);
        body(q, qd);
    }
    const auto t1 = std::chrono::steady_clock::now();
    return std::chrono::duration<double, std::nano>(t1 - t0).count() / (double)calls;
}

int main(int argc, char **argv)
{
    const long calls = std::atol(argv[1]);
    const int rounds = std::atoi(argv[2]);
    volatile double sink = 0;
    double T[16], J[6 * 32], a[6];
    for (int round = 0; round < rounds; ++round) {
%(robots)s
    }
    return sink != sink;
}
"""

ROBOT = """
        {
            pinocchio::Model model;
            model.loadFromBinary(argv[%(index)d]);
            pinocchio::Data data(model);
            const pinocchio::FrameIndex frame = model.getFrameId("tool");
            const int n = %(dof)d;
            Eigen::VectorXd q(n), v(n);
            pinocchio::Data::Matrix6x Jp = pinocchio::Data::Matrix6x::Zero(6, n), Jdp = Jp;
            std::printf("%(name)s ours_fk_jacobian %%d %%.3f\\n", round, time_per_call(calls, n, [&](double *x, double *) {
                %(name)s_fk_jacobian(x, T, J); sink = sink + T[3] + J[6 * n - 1]; }));
            std::printf("%(name)s ours_fk_jacobian_dot %%d %%.3f\\n", round, time_per_call(calls, n, [&](double *x, double *xd) {
                %(name)s_fk_jacobian_dot(x, xd, T, J, a); sink = sink + T[3] + J[6 * n - 1] + a[5]; }));
            std::printf("%(name)s pinocchio_fk_jacobian %%d %%.3f\\n", round, time_per_call(calls, n, [&](double *x, double *) {
                for (int j = 0; j < n; ++j) q[j] = x[j];
                pinocchio::forwardKinematics(model, data, q);
                pinocchio::computeFrameJacobian(model, data, q, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jp);
                sink = sink + data.oMf[frame].translation()[0] + Jp(5, n - 1); }));
            std::printf("%(name)s pinocchio_dot %%d %%.3f\\n", round, time_per_call(calls, n, [&](double *x, double *xd) {
                for (int j = 0; j < n; ++j) { q[j] = x[j]; v[j] = xd[j]; }
                pinocchio::forwardKinematics(model, data, q);
                pinocchio::computeJointJacobiansTimeVariation(model, data, q, v);
                pinocchio::updateFramePlacement(model, data, frame);
                pinocchio::getFrameJacobian(model, data, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jp);
                pinocchio::getFrameJacobianTimeVariation(model, data, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jdp);
                const Eigen::VectorXd acc = Jdp * v;
                sink = sink + data.oMf[frame].translation()[0] + Jp(5, n - 1) + acc[5]; }));
        }
"""


def native_table(calls: int, rounds: int) -> None:
    from test_external_libraries import pinocchio_from_dh

    robots = [load_robot(ROOT / "robots" / f"{name}.yaml") for name in ROBOTS]
    with tempfile.TemporaryDirectory(prefix="jacgen-bench-") as temporary:
        folder = Path(temporary)
        sources, declarations, blocks, arguments = [], [], [], []
        for index, robot in enumerate(robots):
            write_files(render_robot(robot, ("c",), "double"), folder)
            sources.append(folder / robot.name / f"{robot.name}.c")
            declarations.append(f'#include "{folder / robot.name / robot.name}.h"')
            pinocchio_from_dh(robot).saveToBinary(str(folder / f"{robot.name}.pin"))
            arguments.append(str(folder / f"{robot.name}.pin"))
            blocks.append(ROBOT % {"index": 3 + index, "dof": robot.dof, "name": robot.name})
        objects = []
        for source in sources:
            objects.append(source.with_suffix(".o"))
            subprocess.run(["gcc", "-std=c99", "-O2", "-c", "-o", str(objects[-1]), str(source)], check=True)
        (folder / "harness.cpp").write_text(HARNESS % {"declarations": "\n".join(declarations),
                                                       "robots": "".join(blocks)})
        include, lib = PREFIX / "include", PREFIX / "lib"
        subprocess.run(["g++", "-std=c++17", "-O2", "-DNDEBUG", *PINOCCHIO_DEFINITIONS, f"-I{include}",
                        f"-I{include / 'eigen3'}", "-o", str(folder / "harness"), str(folder / "harness.cpp"),
                        *map(str, objects), f"-L{lib}", f"-Wl,-rpath,{lib}", "-lpinocchio_default",
                        "-lboost_serialization", "-lm"], check=True)
        output = subprocess.run([str(folder / "harness"), str(calls), str(rounds), *arguments],
                                check=True, capture_output=True, text=True).stdout
    times: dict[tuple[str, str], list[float]] = {}
    for line in output.splitlines():
        name, variant, _, nanoseconds = line.split()
        times.setdefault((name, variant.replace("_", " ", 1)), []).append(float(nanoseconds))
    median = {key: statistics.median(values) for key, values in times.items()}
    print(f"ns per call, median of {rounds} rounds of {calls} calls (one C++ harness, -O2)")
    print(f"{'robot':8} " + " ".join(f"{v:>22}" for v in VARIANTS) + f" {'dot / fk_jac':>12} {'ours / pin dot':>14}")
    for robot in robots:
        m = [median[(robot.name, variant)] for variant in VARIANTS]
        print(f"{robot.name:8} " + " ".join(f"{x:22.1f}" for x in m) + f" {m[1] / m[0]:12.2f} {m[1] / m[3]:14.2f}")
    print("operation counts (count_ops of the generated bodies):")
    for robot in robots:
        operations = {f.name: f.body.operation_count for f in Generator(robot).functions()}
        print(f"  {robot.name:8} fk_jacobian {operations['fk_jacobian']:5d}  fk_jacobian_dot "
              f"{operations['fk_jacobian_dot']:5d}  bias_acceleration {operations['bias_acceleration']:5d}  "
              f"jacobian_dot {operations['jacobian_dot']:5d}  hessian {operations['hessian']:5d}")


def scaling_table(sizes: list[int], repeats: int) -> None:
    """bias_acceleration's operation count beside the jacobian's, on the same random arms: the
    Jacobian is linear in n (bench_scaling: slope 0.94 up to 32 joints), and bias_acceleration
    adds O(1) per joint to it; small arms have more zero terms, so per-joint counts grow
    until about 8 joints."""
    from random_arms import random_arm_text

    print(f"random arms (revolute and prismatic, both conventions, {repeats} per size): mean operation counts")
    print(f"{'n':>3} {'bias_acceleration':>18} {'jacobian':>9} {'ratio':>6} {'bias per joint':>15}")
    counts = []
    for n in sizes:
        bias = jacobian = 0
        for repeat in range(repeats):
            robot = parse_robot(random_arm_text(1000 * n + repeat, dof=n).encode(), f"arm{n}.yaml")
            generator = Generator(robot)
            bias += generator.second_order_functions()[2].body.operation_count / repeats
            jacobian += generator.function("jacobian", "", ("J", generator.jacobian)).body.operation_count / repeats
        counts.append((n, bias, jacobian))
        print(f"{n:3d} {bias:18.0f} {jacobian:9.0f} {bias / jacobian:6.2f} {bias / n:15.0f}")
    for label, rows in (("all sizes", counts), ("from 8 joints up", [c for c in counts if c[0] >= 8])):
        if len(rows) > 1:
            sizes_, biases, jacobians = zip(*rows)
            print(f"log-log slope against n, {label}: bias_acceleration {slope(sizes_, biases):.2f}, "
                  f"jacobian {slope(sizes_, jacobians):.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=200_000)
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--sizes", default="2,3,4,6,8,10,12,16,24")
    parser.add_argument("--repeats", type=int, default=3, help="random arms per size")
    parser.add_argument("--scaling-only", action="store_true", help="skip the native timings")
    arguments = parser.parse_args()
    if not arguments.scaling_only:
        native_table(arguments.calls, arguments.rounds)
    scaling_table([int(size) for size in arguments.sizes.split(",")], arguments.repeats)


if __name__ == "__main__":
    main()
