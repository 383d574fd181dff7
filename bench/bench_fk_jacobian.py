"""Benchmark: jacgen's C fk + jacobian (double) beside CasADi's generated C and a trig floor.

    PYTHONPATH=. python bench/bench_fk_jacobian.py [--calls 1000000] [--rounds 7]

For each robot, three implementations of the same numbers are linked into one C harness
compiled with -O2, each in its own translation unit (no inlining across them):

- ours: `NAME_fk_jacobian(q, T, J)`, fk and jacobian lowered together (one CSE, each sine
  and cosine once); "ours fk", "ours jac" and "separate" time `NAME_fk`, `NAME_jacobian` and
  the two called one after the other;
- casadi: one CasADi function returning T and J, built here directly from the robot's DH
  table as SX (link transforms multiplied out, Jacobian by the column formula; constant
  sines and cosines exact, so cos(90 deg) is 0 and not 6e-17), then written out by
  `casadi.CodeGenerator`; once as built ("casadi") and once after `casadi.cse` ("casadi cse");
- floor: a straight-line function that only computes the sine and cosine of every joint.

The harness loops natively (`--calls` calls per measurement); the joint vector changes on
every call so that nothing can be hoisted out of the loop, and outputs are summed into a
sink so that nothing is dead. Rounds interleave all robots and implementations in one
process; the table shows medians.

Operation counts: ours is sympy's `count_ops` of the generated bodies (`Body.operation_count`,
trig definitions included, each sin/cos one operation); CasADi's is the number of
instructions of the SX function that are operations (`Function.instruction_id` other than
input, output and constant), each sin/cos one operation as well.
"""

import argparse
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import casadi
import numpy as np
import sympy

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from jacgen import reference  # noqa: E402
from jacgen.functions import Generator  # noqa: E402
from jacgen.render import render_robot, write_files  # noqa: E402
from jacgen.robot import load_robot  # noqa: E402

ROBOTS = ("puma560", "ur5", "panda")
VARIANTS = ("ours", "ours_fk", "ours_jac", "separate", "casadi", "casadi_cse", "floor")
NOT_OPERATIONS = {casadi.OP_INPUT, casadi.OP_OUTPUT, casadi.OP_CONST}


# -- CasADi, built from the DH table alone ---------------------------------------------------
def _constant_trig(angle) -> tuple[float, float]:
    """cos and sin of a constant angle, exact zeros and ones where the angle is a multiple of pi/2."""
    return float(sympy.cos(angle.exact)), float(sympy.sin(angle.exact))


def _rz(c, s):
    return casadi.blockcat([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def _rx(c, s):
    return casadi.blockcat([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _translation(x, y, z):
    return casadi.blockcat([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def _pose(pose):
    (cr, sr), (cp, sp), (cy, sy) = (_constant_trig(angle) for angle in pose.rpy)
    rot_y = casadi.blockcat([[cp, 0, sp, 0], [0, 1, 0, 0], [-sp, 0, cp, 0], [0, 0, 0, 1]])
    return casadi.mtimes([_translation(*(v.approx for v in pose.xyz)), _rz(cy, sy), rot_y, _rx(cr, sr)])


def casadi_fk_jacobian(robot) -> casadi.Function:
    """T (4x4) and the world-frame geometric Jacobian J (6 x n) as one SX function of q."""
    q = casadi.SX.sym("q", robot.dof)
    current = casadi.SX(_pose(robot.base))
    axes = []
    for i, joint in enumerate(robot.joints):
        if joint.revolute:
            angle = q[i] + joint.offset.approx
            rotation, d = _rz(casadi.cos(angle), casadi.sin(angle)), joint.d.approx
        else:
            rotation, d = _rz(*_constant_trig(joint.theta)), q[i] + joint.offset.approx
        twist = casadi.mtimes(_rx(*_constant_trig(joint.alpha)), _translation(joint.a.approx, 0, 0))
        if robot.convention == "standard":
            axes.append(current)
            current = casadi.mtimes([current, rotation, _translation(0, 0, d), twist])
        else:
            axes.append(casadi.mtimes(current, twist))
            current = casadi.mtimes([axes[-1], rotation, _translation(0, 0, d)])
    tool = casadi.mtimes(current, _pose(robot.tool))
    p = tool[:3, 3]
    columns = []
    for joint, axis in zip(robot.joints, axes):
        z, o = axis[:3, 2], axis[:3, 3]
        columns.append(casadi.vertcat(casadi.cross(z, p - o), z) if joint.revolute
                       else casadi.vertcat(z, casadi.SX(3, 1)))
    return casadi.Function(f"casadi_{robot.name}", [q], [tool, casadi.horzcat(*columns)])


def casadi_operations(function: casadi.Function) -> int:
    return sum(function.instruction_id(k) not in NOT_OPERATIONS for k in range(function.n_instructions()))


# -- the C harness ---------------------------------------------------------------------------
def _loop(label: str, dof: int, call: str, sink: str) -> str:
    return f"""
static double time_{label}(long calls)
{{
    double q[{dof}], sink = 0;
    const double t0 = now();
    for (long i = 0; i < calls; ++i) {{
        const double step = (double)(i & 1023) * 1e-6;
        for (int j = 0; j < {dof}; ++j) q[j] = q0[j] + step * (double)(j + 1);
        {call}
        sink += {sink};
    }}
    const double t1 = now();
    global_sink += sink;
    return (t1 - t0) * 1e9 / (double)calls;
}}
"""


def harness(robots, functions: dict[str, dict[str, casadi.Function]]) -> str:
    parts = ["#define _POSIX_C_SOURCE 199309L", "#include <stdio.h>", "#include <stdlib.h>", "#include <time.h>"]
    parts += [f'#include "{robot.name}.h"' for robot in robots]
    parts += ["static const double q0[8] = {0.3, -0.7, 0.9, -0.4, 1.1, -1.3, 0.5, 0.8};",
              "static volatile double global_sink;",
              "static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); "
              "return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec; }"]
    labels = []
    for robot in robots:
        name, dof = robot.name, robot.dof
        parts.append(f"void floor_{name}(const double *q, double *out);")
        parts.append(f"static double T_{name}[16], J_{name}[6 * {dof}], trig_{name}[{2 * dof}];")
        calls = {
            "ours": (f"{name}_fk_jacobian(q, T_{name}, J_{name});", f"T_{name}[3] + J_{name}[{6 * dof - 1}]"),
            "ours_fk": (f"{name}_fk(q, T_{name});", f"T_{name}[3]"),
            "ours_jac": (f"{name}_jacobian(q, J_{name});", f"J_{name}[{6 * dof - 1}]"),
            "separate": (f"{name}_fk(q, T_{name}); {name}_jacobian(q, J_{name});",
                         f"T_{name}[3] + J_{name}[{6 * dof - 1}]"),
            "floor": (f"floor_{name}(q, trig_{name});", f"trig_{name}[0] + trig_{name}[{2 * dof - 1}]"),
        }
        for variant, function in functions[name].items():
            symbol = function.name()
            parts.append(f"int {symbol}(const double **arg, double **res, long long *iw, double *w, int mem);")
            parts.append(f"static double w_{symbol}[{max(function.sz_w(), 1)}]; "
                         f"static long long iw_{symbol}[{max(function.sz_iw(), 1)}];")
            calls[variant] = (
                f"const double *arg[1] = {{q}}; double *res[2] = {{T_{name}, J_{name}}}; "
                f"{symbol}(arg, res, iw_{symbol}, w_{symbol}, 0);",
                f"T_{name}[0] + J_{name}[{function.nnz_out(1) - 1}]")
        for variant in VARIANTS:
            call, sink = calls[variant]
            parts.append(_loop(f"{variant}_{name}", dof, call, sink))
            labels.append((name, variant))
    body = "\n".join(f'        printf("{name} {variant} %d %.3f\\n", round, time_{variant}_{name}(calls));'
                     for name, variant in labels)
    parts.append(f"""
int main(int argc, char **argv)
{{
    const long calls = atol(argv[1]);
    const int rounds = atoi(argv[2]);
    (void)argc;
    for (int round = 0; round < rounds; ++round) {{
{body}
    }}
    return global_sink != global_sink;  /* NaN check keeps the sink observable */
}}
""")
    return "\n".join(parts)


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


def casadi_variants(robot) -> dict[str, casadi.Function]:
    """CasADi's fk+jacobian as built, and after `casadi.cse`, named as the harness expects."""
    plain = casadi_fk_jacobian(robot)
    cse = casadi.Function(f"casadi_cse_{robot.name}", plain.sx_in(), casadi.cse(plain.call(plain.sx_in())))
    return {"casadi": plain, "casadi_cse": cse}


def native_times(robots, folder: Path, calls: int, rounds: int) -> dict[tuple[str, str], float]:
    """Build the harness with every variant in `folder`, run it: {(robot, variant): median ns}."""
    sources, functions = [folder / "harness.c"], {}
    for robot in robots:
        write_files(render_robot(robot, ("c",), "double"), folder)
        functions[robot.name] = casadi_variants(robot)
        for function in functions[robot.name].values():
            code = casadi.CodeGenerator(f"{function.name()}.c", {"casadi_real": "double",
                                                                "casadi_int": "long long int"})
            code.add(function)
            code.generate(str(folder) + "/")
            sources.append(folder / f"{function.name()}.c")
        (folder / f"floor_{robot.name}.c").write_text(floor_source(robot))
        sources += [folder / robot.name / f"{robot.name}.c", folder / f"floor_{robot.name}.c"]
    (folder / "harness.c").write_text(harness(robots, functions))
    includes = [f"-I{folder / robot.name}" for robot in robots]
    subprocess.run(["gcc", "-std=c99", "-O2", *includes, "-o", str(folder / "bench"), *map(str, sources), "-lm"],
                   check=True)
    output = subprocess.run([str(folder / "bench"), str(calls), str(rounds)],
                            check=True, capture_output=True, text=True).stdout
    times: dict[tuple[str, str], list[float]] = {}
    for line in output.splitlines():
        name, variant, _, nanoseconds = line.split()
        times.setdefault((name, variant), []).append(float(nanoseconds))
    return {key: statistics.median(values) for key, values in times.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=1_000_000)
    parser.add_argument("--rounds", type=int, default=7)
    arguments = parser.parse_args()
    robots = [load_robot(ROOT / "robots" / f"{name}.yaml") for name in ROBOTS]
    operations = {}
    for robot in robots:
        variants = casadi_variants(robot)
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
