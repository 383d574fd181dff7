"""Benchmark: second-order kinematics, jacgen's C beside Pinocchio's C++ in one harness.

    PYTHONPATH=. python bench/bench_second_order.py [--calls 200000] [--rounds 7] [--sizes 2,3,4,6,8,10,12,16,24] [--repeats 3]

One C++ program (common.py's harness, compiled as C++ with its flags, -O2, against
Pinocchio from the `pin` wheel; Eigen's headers come from `pip install cmeel-eigen`) linked
with jacgen's generated C (double, compiled as C with the same flags, its own translation
unit), times per robot and per round, after a warm-up round, in the same loop (the joint
vector changes every call, q_dot is fixed, results go to a sink):

- ours fk_jacobian: `NAME_fk_jacobian(q, T, J)`;
- ours fk_jacobian_dot: `NAME_fk_jacobian_dot(q, q_dot, T, J, a)` (T, J and J' q_dot);
- pinocchio fk_jacobian: forwardKinematics + computeFrameJacobian (LOCAL_WORLD_ALIGNED);
- pinocchio dot: forwardKinematics + computeJointJacobiansTimeVariation, then the frame's
  J and J' (getFrameJacobian, getFrameJacobianTimeVariation, LOCAL_WORLD_ALIGNED) and J' q_dot.

The Pinocchio models are built from the robot files (`pinocchio_from_dh`, from the test
suite through common.py), so both sides compute the same numbers; the table shows medians
over the rounds in ns per call, then the operation counts. Then the mean operation count of
bias_acceleration over random arms of each size (`random_arm_text`, the test suite's seeded
arms) and its log-log slope against the joint count.
"""

import argparse
import tempfile
from pathlib import Path

import common
from common import random_arm_text
from jacgen.emission.generator import Generator, matrix
from jacgen.inputs.robot_file import parse_robot

ROBOTS = ("puma560", "ur5", "panda")
VARIANTS = ("ours fk_jacobian", "ours fk_jacobian_dot", "pinocchio fk_jacobian", "pinocchio dot")
VELOCITY = "double qd[{n}]; for (int j = 0; j < {n}; ++j) qd[j] = 0.5 - 0.1 * (double)j;"  # q_dot, every call


def dot_loops(robot) -> list[common.Loop]:
    """jacgen's fk_jacobian_dot, and Pinocchio's J, J' and J' q_dot of the tool frame."""
    name, n, model, velocity = robot.name, robot.dof, f"model_{robot.name}", VELOCITY.format(n=robot.dof)
    ours = common.Loop(name, VARIANTS[1], n, f"{name}_fk_jacobian_dot(q, qd, T, J, a);",
                       f"T[3] + J[{6 * n - 1}] + a[5]", setup=f"double T[16], J[{6 * n}], a[6]; {velocity}")
    pinocchio = common.Loop(
        name, VARIANTS[3], n,
        f"for (int j = 0; j < {n}; ++j) x[j] = q[j]; "
        f"pinocchio::forwardKinematics({model}, data, x); "
        f"pinocchio::computeJointJacobiansTimeVariation({model}, data, x, v); "
        f"pinocchio::updateFramePlacement({model}, data, frame); "
        f"pinocchio::getFrameJacobian({model}, data, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jp); "
        f"pinocchio::getFrameJacobianTimeVariation({model}, data, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jdp); "
        "const Eigen::VectorXd acc = Jdp * v;",
        f"data.oMf[frame].translation()[0] + Jp(5, {n - 1}) + acc[5]",
        setup=f"{common.pinocchio_setup(robot)} pinocchio::Data::Matrix6x Jdp = Jp; Eigen::VectorXd v({n}); "
              f"{velocity} for (int j = 0; j < {n}; ++j) v[j] = qd[j];")
    return [ours, pinocchio]


def native_table(calls: int, rounds: int) -> None:
    robots = [common.shipped(name) for name in ROBOTS]
    with tempfile.TemporaryDirectory(prefix="jacgen-bench-") as temporary:
        folder = Path(temporary)
        sources = [common.generate(robot, folder) / f"{robot.name}.c" for robot in robots]
        loops = []
        for robot in robots:
            loops += [common.fk_jacobian_loop(robot, VARIANTS[0]),
                      common.pinocchio_fk_jacobian_loop(robot, VARIANTS[2]), *dot_loops(robot)]
        models, setup, arguments = common.pinocchio_models(robots, folder)
        header = "\n".join([models] + [f'#include "{robot.name}.h"' for robot in robots])
        program = common.build(folder, "harness", common.harness(loops, header, setup), sources, "c++",
                               common.PINOCCHIO_OPTIONS, common.PINOCCHIO_LIBRARIES)
        median = common.run_loops(program, calls, rounds, *arguments)
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
    print(f"random arms (revolute and prismatic, both conventions, {repeats} per size): mean operation counts")
    print(f"{'n':>3} {'bias_acceleration':>18} {'jacobian':>9} {'ratio':>6} {'bias per joint':>15}")
    counts = []
    for n in sizes:
        bias = jacobian = 0
        for repeat in range(repeats):
            robot = parse_robot(random_arm_text(1000 * n + repeat, dof=n).encode(), f"arm{n}.yaml")
            generator = Generator(robot)
            bias += generator.second_order_functions()[2].body.operation_count / repeats
            jacobian += generator.function("jacobian", "", matrix("J", generator.jacobian)).body.operation_count / repeats
        counts.append((n, bias, jacobian))
        print(f"{n:3d} {bias:18.0f} {jacobian:9.0f} {bias / jacobian:6.2f} {bias / n:15.0f}")
    for label, rows in (("all sizes", counts), ("from 8 joints up", [c for c in counts if c[0] >= 8])):
        if len(rows) > 1:
            sizes_, biases, jacobians = zip(*rows)
            print(f"log-log slope against n, {label}: bias_acceleration {common.slope(sizes_, biases):.2f}, "
                  f"jacobian {common.slope(sizes_, jacobians):.2f}")


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
