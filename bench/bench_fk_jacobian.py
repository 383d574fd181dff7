"""Benchmark: jacgen's C fk + jacobian (double) beside CasADi's generated C and a trig floor.

    PYTHONPATH=. python bench/bench_fk_jacobian.py [--calls 1000000] [--rounds 7]

For each robot, three implementations of the same numbers are linked into one C harness
(common.py's, built with its flags: -O2), each in its own translation unit (no inlining
across them):

- ours: `NAME_fk_jacobian(q, T, J)`, fk and jacobian lowered together (one CSE, each sine
  and cosine once); "ours fk", "ours jac" and "separate" time `NAME_fk`, `NAME_jacobian` and
  the two called one after the other;
- casadi: one CasADi function returning T and J, built from the robot's DH table as SX
  (`common.casadi_fk_jacobian`: link transforms multiplied out, Jacobian by the column
  formula, constant sines and cosines exact), then written out by `casadi.CodeGenerator`;
  once as built ("casadi") and once after `casadi.cse` ("casadi cse");
- floor: a straight-line function that only computes the sine and cosine of every joint.

The harness loops natively (`--calls` calls per measurement); the joint vector changes on
every call so that nothing can be hoisted out of the loop, and outputs are summed into a
sink so that nothing is dead. After a warm-up round, rounds interleave all robots and
implementations in one process; the table shows medians.

Operation counts: ours is sympy's `count_ops` of the generated bodies (`Body.operation_count`,
trig definitions included, each sin/cos one operation); CasADi's is the number of
instructions of the SX function that are operations (`Function.instruction_id` other than
input, output and constant), each sin/cos one operation as well.
"""

import argparse
import tempfile
from pathlib import Path

import casadi
import numpy as np

import common
from jacgen.checking import reference
from jacgen.emission.generator import Generator

ROBOTS = ("puma560", "ur5", "panda")
VARIANTS = ("ours", "ours_fk", "ours_jac", "separate", "casadi", "casadi_cse", "floor")
NOT_OPERATIONS = {casadi.OP_INPUT, casadi.OP_OUTPUT, casadi.OP_CONST}


def casadi_operations(function: casadi.Function) -> int:
    return sum(function.instruction_id(k) not in NOT_OPERATIONS for k in range(function.n_instructions()))


def floor_source(robot) -> str:
    """The sine and cosine of every revolute joint angle, straight-line.

    The angles are read into locals first (as the generated code does): `out` may alias `q`,
    so sin(q[i]) after a store to out could not share a sincos() call with cos(q[i]).
    """
    lines = []
    for i, joint in enumerate(robot.joints):
        if joint.revolute:
            offset = f" + {joint.offset.approx!r}" if joint.offset.approx else ""
            lines += [f"    const double a{i} = q[{i}]{offset};"]
    for i, joint in enumerate(robot.joints):
        if joint.revolute:
            lines += [f"    out[{2 * i}] = cos(a{i});", f"    out[{2 * i + 1}] = sin(a{i});"]
    return "#include <math.h>\nvoid floor_{0}(const double *q, double *out)\n{{\n{1}\n}}\n".format(
        robot.name, "\n".join(lines))


def loops(robot, casadi_functions) -> list[common.Loop]:
    """The timed loops of one robot, in the order of VARIANTS."""
    name, dof = robot.name, robot.dof
    both = f"double T[16], J[{6 * dof}];"
    found = {
        "ours": common.fk_jacobian_loop(robot, "ours"),
        "ours_fk": common.Loop(name, "ours_fk", dof, f"{name}_fk(q, T);", "T[3]", setup="double T[16];"),
        "ours_jac": common.Loop(name, "ours_jac", dof, f"{name}_jacobian(q, J);", f"J[{6 * dof - 1}]",
                                setup=f"double J[{6 * dof}];"),
        "separate": common.Loop(name, "separate", dof, f"{name}_fk(q, T); {name}_jacobian(q, J);",
                                f"T[3] + J[{6 * dof - 1}]", setup=both),
        "floor": common.Loop(name, "floor", dof, f"floor_{name}(q, trig);", f"trig[0] + trig[{2 * dof - 1}]",
                             setup=f"double trig[{2 * dof}];",
                             declare=f"void floor_{name}(const double *q, double *out);"),
    }
    found |= {variant: common.casadi_loop(robot, function, variant) for variant, function in casadi_functions.items()}
    return [found[variant] for variant in VARIANTS]


def native_times(robots, folder: Path, calls: int, rounds: int) -> dict[tuple[str, str], float]:
    """Build the harness with every variant in `folder`, run it: {(robot, variant): median ns}."""
    sources, timed = [], []
    for robot in robots:
        code = common.generate(robot, folder)
        functions = common.casadi_variants(robot)
        sources += [common.casadi_c(function, folder) for function in functions.values()]
        (folder / f"floor_{robot.name}.c").write_text(floor_source(robot))
        sources += [code / f"{robot.name}.c", folder / f"floor_{robot.name}.c"]
        timed += loops(robot, functions)
    header = "\n".join(f'#include "{robot.name}.h"' for robot in robots)
    program = common.build(folder, "harness", common.harness(timed, header), sources)
    return common.run_loops(program, calls, rounds)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=7)
    arguments = parser.parse_args()
    robots = [common.shipped(name) for name in ROBOTS]
    operations = {}
    for robot in robots:
        variants = common.casadi_variants(robot)
        q = np.random.default_rng(0).uniform(-1, 1, robot.dof)
        T, J = (np.asarray(value) for value in variants["casadi"](q))
        assert np.allclose(T, reference.fk(robot, q), atol=1e-12) and np.allclose(J, reference.jacobian(robot, q), atol=1e-12)
        ours = {f.name: f.body.operation_count for f in Generator(robot).functions()}
        operations[robot.name] = (ours["fk_jacobian"], ours["fk"], ours["jacobian"],
                                  casadi_operations(variants["casadi"]), casadi_operations(variants["casadi_cse"]))
    with tempfile.TemporaryDirectory(prefix="jacgen-bench-") as temporary:
        median = native_times(robots, Path(temporary), arguments.calls, arguments.rounds)
    header = ["robot", "ours ns", "fk ns", "jac ns", "separate ns", "casadi ns", "cse ns", "floor ns", "ours/casadi",
              "ours/floor", "separate/casadi", "ours ops", "separate ops (fk+jac)", "casadi ops", "cse ops"]
    rows = [header]
    for robot in robots:
        m = {variant: median[(robot.name, variant)] for variant in VARIANTS}
        fused_ops, fk_ops, jac_ops, casadi_ops, cse_ops = operations[robot.name]
        rows.append([robot.name] + [f"{m[v]:.1f}" for v in VARIANTS] + [
            f"{m['ours'] / m['casadi']:.2f}", f"{m['ours'] / m['floor']:.2f}", f"{m['separate'] / m['casadi']:.2f}",
            str(fused_ops), f"{fk_ops}+{jac_ops}={fk_ops + jac_ops}", str(casadi_ops), str(cse_ops)])
    widths = [max(len(row[c]) for row in rows) for c in range(len(header))]
    print(f"median of {arguments.rounds} interleaved rounds of {arguments.calls} calls, gcc -O2, double")
    for row in rows:
        print("  ".join(cell.rjust(width) for cell, width in zip(row, widths)))


if __name__ == "__main__":
    main()
