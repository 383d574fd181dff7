"""Benchmark: what the Jacobian is for (issue 48), jacgen's C beside Pinocchio's C++ and Eigen in
one harness, then NAME_native's batches beside the Robotics Toolbox.

    PYTHONPATH=. python bench/bench_jacobian_uses.py [--calls 200000] [--rounds 7] [--rows 1000000]

(Pinocchio's C++ needs Eigen's headers in the venv: `pip install cmeel-eigen`.)

One C++ program (common.py's harness: -O2, one call per iteration, the joint vector changing
every call, results into a sink) linked with jacgen's generated C (double, its own
translation unit) times, per robot and round, after a warm-up round:

- ours: `NAME_fk`, `NAME_link_poses`, `NAME_link_velocities`, `NAME_velocity_ellipsoid`,
  `NAME_condition_number`, `NAME_manipulability_gradient`, `NAME_velocity_ik`,
  `NAME_velocity_ik_nullspace` and `NAME_resolved_rate` (q_dot, mu_dot, z fixed per loop;
  the target a pose of the arm; gain 30, damping 0);
- Pinocchio (models from the DH table, `pinocchio_from_dh`): link_poses is forwardKinematics
  + updateFramePlacements (every joint's and frame's placement); link_velocities is
  forwardKinematics with v, then getVelocity of every joint (LOCAL_WORLD_ALIGNED);
- Pinocchio + Eigen: velocity_ellipsoid is computeFrameJacobian (LOCAL_WORLD_ALIGNED) and
  Eigen::JacobiSVD of its linear and angular 3 x n blocks (U and the singular values);
  condition_number is the same Jacobian, position rows divided by CHARACTERISTIC_LENGTH,
  and JacobiSVD's singular values (sigma_max / sigma_min). Fixed-size Eigen matrices: no
  allocation in the loop.

The table gives medians over the rounds in ns per call and the ratios the issue bounds
(resolved_rate / velocity_ik, link_poses / fk). Then NAME_native (built from `--lang native`
in a temporary folder by `jacgen.building.load_native`) on `--rows` configurations
uniform within the limits: condition_number and manipulability_gradient as one batch each
(its gufunc: SIMD kernels over every usable processor), median of `--batch-rounds`; beside
them, for scale, rtb's `manipulability(q, method="invcondition")` and `jacobm(q)` per call
on its DH Panda, timed over RTB_CALLS calls.
"""

import argparse
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import common
from jacgen.building import load_native

ROBOTS = ("puma560", "ur5", "panda")
OURS = ("fk", "link_poses", "link_velocities", "velocity_ellipsoid", "condition_number", "manipulability_gradient",
        "velocity_ik", "velocity_ik_nullspace", "resolved_rate")
PEERS = ("pinocchio link_poses", "pinocchio link_velocities", "pinocchio+eigen velocity_ellipsoid",
         "pinocchio+eigen condition_number")
GAIN = 30.0
RTB_CALLS = 2_000
NATIVE_ROBOT = "panda"


def our_loops(robot) -> list[common.Loop]:
    """jacgen's generated functions, each in a loop of its own."""
    name, n, upper = robot.name, robot.dof, robot.name.upper()
    inputs = (f"double qd[{n}], z[{n}], mu[{upper}_TASK_DIM], gain[{upper}_TASK_DIM], target[16], qdot[{n}]; "
              f"for (int j = 0; j < {n}; ++j) {{ qd[j] = 0.5 - 0.1 * j; z[j] = 0.2 - 0.05 * j; }} "
              f"for (int j = 0; j < {upper}_TASK_DIM; ++j) {{ mu[j] = 0.1 * (j + 1); gain[j] = {GAIN}; }} "
              f"{{ double q0[{n}]; for (int j = 0; j < {n}; ++j) q0[j] = 0.35 + 0.1 * j; {name}_fk(q0, target); }} "
              "int status = 0;")
    calls = {
        "fk": ("fk(q, T);", "T[3]", "double T[16];"),
        "link_poses": ("link_poses(q, P);", f"P[{16 * n - 13}]", f"double P[{16 * n}];"),
        "link_velocities": ("link_velocities(q, qd, V);", f"V[{6 * n - 1}]", f"double V[{6 * n}];"),
        "velocity_ellipsoid": ("velocity_ellipsoid(q, Uv, sv, Uw, sw);", "Uv[0] + sv[2] + Uw[8] + sw[2]",
                               "double Uv[9], sv[3], Uw[9], sw[3];"),
        "condition_number": ("condition_number(q)", "kappa", "double kappa;"),
        "manipulability_gradient": ("manipulability_gradient(q, dw);", f"dw[{n - 1}]", f"double dw[{n}];"),
        "velocity_ik": ("velocity_ik(q, mu, 0.0, qdot)", f"qdot[{n - 1}] + status", ""),
        "velocity_ik_nullspace": ("velocity_ik_nullspace(q, mu, z, 0.0, qdot)", f"qdot[{n - 1}] + status", ""),
        "resolved_rate": ("resolved_rate(q, target, mu, gain, z, 0.0, qdot)", f"qdot[{n - 1}] + status", ""),
    }
    assigned = {"condition_number": "kappa = ", "velocity_ik": "status = ", "velocity_ik_nullspace": "status = ",
                "resolved_rate": "status = "}
    loops = []
    for function in OURS:
        call, sink, outputs = calls[function]
        statement = f"{assigned.get(function, '')}{name}_{call}{'' if call.endswith(';') else ';'}"
        loops.append(common.Loop(name, f"ours {function}", n, statement, sink, setup=f"{outputs} {inputs}"))
    return loops


def peer_loops(robot, length: float) -> list[common.Loop]:
    """Pinocchio's link poses and velocities; Pinocchio's Jacobian with Eigen's JacobiSVD."""
    name, n, model = robot.name, robot.dof, f"model_{robot.name}"
    place = f"for (int j = 0; j < {n}; ++j) x[j] = q[j]; "
    setup = common.pinocchio_setup(robot)
    block = f"Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, {n}>"
    full = f"Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, {n}>"
    jacobian = place + (f"pinocchio::computeFrameJacobian({model}, data, x, frame, pinocchio::LOCAL_WORLD_ALIGNED, "
                        "Jp); ")
    return [
        common.Loop(name, PEERS[0], n, place + f"pinocchio::forwardKinematics({model}, data, x); "
                    f"pinocchio::updateFramePlacements({model}, data);",
                    f"data.oMi[{n}].translation()[0] + data.oMf[frame].translation()[0]", setup=setup),
        common.Loop(name, PEERS[1], n, place + f"pinocchio::forwardKinematics({model}, data, x, v); double s = 0; "
                    f"for (int j = 1; j <= {n}; ++j) "
                    f"s += pinocchio::getVelocity({model}, data, j, pinocchio::LOCAL_WORLD_ALIGNED).linear()[0];",
                    "s", setup=f"{setup} Eigen::VectorXd v({n}); for (int j = 0; j < {n}; ++j) v[j] = 0.5 - 0.1 * j;"),
        common.Loop(name, PEERS[2], n, jacobian + f"const {block} Jv = Jp.topRows<3>(), Jw = Jp.bottomRows<3>(); "
                    "linear.compute(Jv, Eigen::ComputeFullU); angular.compute(Jw, Eigen::ComputeFullU);",
                    "linear.matrixU()(0, 0) + linear.singularValues()[2] + angular.matrixU()(2, 2) "
                    "+ angular.singularValues()[2]",
                    setup=f"{setup} Eigen::JacobiSVD<{block}> linear({3}, {n}, Eigen::ComputeFullU), "
                          f"angular({3}, {n}, Eigen::ComputeFullU);"),
        common.Loop(name, PEERS[3], n, jacobian + f"{full} scaled = Jp; scaled.topRows<3>() /= {length!r}; "
                    "svd.compute(scaled); const auto &s = svd.singularValues();",
                    f"s[0] / s[{min(6, n) - 1}]", setup=f"{setup} Eigen::JacobiSVD<{full}> svd(6, {n});"),
    ]


def characteristic_length(robot, folder: Path) -> float:
    """NAME_CHARACTERISTIC_LENGTH of the generated header."""
    for line in (folder / robot.name / f"{robot.name}.h").read_text().splitlines():
        if line.startswith(f"#define {robot.name.upper()}_CHARACTERISTIC_LENGTH "):
            return float(line.split()[2])
    raise SystemExit(f"{robot.name}.h defines no CHARACTERISTIC_LENGTH")


def native_table(calls: int, rounds: int) -> None:
    robots = [common.shipped(name) for name in ROBOTS]
    with tempfile.TemporaryDirectory(prefix="jacgen-bench-") as temporary:
        folder = Path(temporary)
        sources = [common.generate(robot, folder) / f"{robot.name}.c" for robot in robots]
        loops = []
        for robot in robots:
            loops += our_loops(robot) + peer_loops(robot, characteristic_length(robot, folder))
        models, setup, arguments = common.pinocchio_models(robots, folder)
        header = "\n".join([models, "#include <Eigen/SVD>"] + [f'#include "{robot.name}.h"' for robot in robots])
        program = common.build(folder, "harness", common.harness(loops, header, setup), sources, "c++",
                               common.PINOCCHIO_OPTIONS, common.PINOCCHIO_LIBRARIES)
        median = common.run_loops(program, calls, rounds, *arguments)
    print(f"ns per call (C, double, x86, gcc -O2), median of {rounds} rounds of {calls} calls, one C++ harness")
    peers = {"link_poses": PEERS[0], "link_velocities": PEERS[1], "velocity_ellipsoid": PEERS[2],
             "condition_number": PEERS[3]}
    names = [robot.name for robot in robots]
    width = max(map(len, PEERS))
    print(f"{'function':36} " + " ".join(f"{name:>9}" for name in names) + f"   {'peer, same harness':{width}} "
          + " ".join(f"{name:>9}" for name in names))
    for function in OURS:
        ours = " ".join(f"{median[(name, f'ours {function}')]:9.1f}" for name in names)
        peer = peers.get(function)
        theirs = " ".join(f"{median[(name, peer)]:9.1f}" for name in names) if peer else ""
        print(f"{function:36} {ours}   {peer or '':{width}} {theirs}")
    for label, top, bottom in (("resolved_rate / velocity_ik", "resolved_rate", "velocity_ik"),
                               ("velocity_ik_nullspace / velocity_ik", "velocity_ik_nullspace", "velocity_ik"),
                               ("link_poses / fk", "link_poses", "fk")):
        ratios = " ".join(f"{median[(name, f'ours {top}')] / median[(name, f'ours {bottom}')]:9.2f}" for name in names)
        print(f"{label:36} {ratios}")
    for function, peer in peers.items():
        ratios = " ".join(f"{median[(name, f'ours {function}')] / median[(name, peer)]:9.2f}" for name in names)
        print(f"{'ours / peer ' + function:36} {ratios}")


def batch_table(rows: int, rounds: int) -> None:
    """NAME_native's condition_number and manipulability_gradient on `rows` configurations."""
    robot = common.shipped(NATIVE_ROBOT)
    limits = np.array([joint.limits for joint in robot.joints], dtype=float)
    q = np.random.default_rng(48).uniform(limits[:, 0], limits[:, 1], (rows, robot.dof))
    with tempfile.TemporaryDirectory(prefix="jacgen-bench-") as temporary:
        start = time.perf_counter()
        native = load_native(common.generate(robot, Path(temporary), ("native",)), robot.name)
        print(f"\n{robot.name}_native: built in {time.perf_counter() - start:.0f} s, SIMD {native.SIMD}, "
              f"{len(os.sched_getaffinity(0))} usable processors")
        times = common.median_times({"condition_number": lambda: native.condition_number(q),
                                     "manipulability_gradient": lambda: native.manipulability_gradient(q)}, rounds)
    for function, timing in times.items():
        print(f"  {function:24} {rows:,} rows: {timing.seconds:.3f} s ({timing.seconds / rows * 1e9:.0f} ns per row)")
    rtb = common.optional("roboticstoolbox")
    if rtb is None:
        return
    panda = rtb.models.DH.Panda()
    sample = list(q[:RTB_CALLS])
    for label, function in (("manipulability(invcondition)", lambda x: panda.manipulability(x, method="invcondition")),
                            ("jacobm", panda.jacobm)):
        seconds = common.per_call(function, [(x,) for x in sample], 3)
        print(f"  rtb DH Panda {label:28} {seconds * 1e6:8.1f} us per call: "
              f"{seconds * rows:.0f} s for {rows:,} (scaled from {RTB_CALLS} calls)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--calls", type=int, default=200_000, help="native calls per measurement")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--rows", type=int, default=1_000_000, help="NAME_native's batch")
    parser.add_argument("--batch-rounds", type=int, default=5)
    arguments = parser.parse_args()
    native_table(arguments.calls, arguments.rounds)
    batch_table(arguments.rows, arguments.batch_rounds)


if __name__ == "__main__":
    main()
