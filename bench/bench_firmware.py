"""Benchmark: jacgen's float C beside CasADi's on an emulated Cortex-M4F: flash, stack, instructions.

    PYTHONPATH=. python bench/bench_firmware.py [--samples 200]

Needs arm-none-eabi-gcc, newlib and qemu-system-arm (`jacgen.checking.cortex_m4f`). For the Puma 560, the
UR5 and the Panda, both are built the same way in the same run (-O2, Cortex-M4F hard float,
`jacgen.checking.cortex_m4f`'s harness on QEMU mps2-an386) and called at the same random configurations:

- jacgen: `NAME_fk_jacobian` and `NAME_jacobian_det` (`NAME_manipulability` for the 7-axis
  Panda, which has no square Jacobian) as generated with `--real float`;
- CasADi: T and J as one SX function built from the DH table and passed through `casadi.cse`
  (`common.casadi_variants`), and `det(J)` (`sqrt(det(J J^T))`), written out by
  `casadi.CodeGenerator` with casadi_real = float, behind a wrapper with jacgen's signature.
  CasADi's float C calls sin, cos and sqrt in double and writes double constants; for a fair
  count its calls are renamed to sinf, cosf, sqrtf and it is built with
  -fsingle-precision-constant (otherwise every call would go through soft double).

Both results are checked against the reference before a figure is shown. Instructions are
QEMU's -icount, the mean per call: an instruction count, not cycles (QEMU is not
cycle-accurate). Flash is the .text of the function and what it calls, libm not counted;
stack (gcc) the deepest chain of -fstack-usage frames; measured, what the calls wrote.
"""

import argparse
import re
import tempfile
from pathlib import Path

import casadi
import numpy as np

import common
from jacgen.checking import reference
from jacgen.emission.generator import Generator
from jacgen.checking.cortex_m4f import Emulator, check_tools
from jacgen.tolerances import VERIFIED

ROBOTS = ("puma560", "ur5", "panda")
MATH = ("sin", "cos", "tan", "sqrt", "fabs", "atan2", "asin", "acos", "exp", "log", "pow", "fmin", "fmax", "floor")


def scalar_name(robot) -> str:
    return "jacobian_det" if robot.dof == 6 else "manipulability"


def casadi_source(robot, folder: Path) -> None:
    """folder/NAME/NAME.h and .c: CasADi's C of fk+J and of the scalar, behind jacgen's signatures."""
    built = common.casadi_variants(robot)["casadi_cse"]
    q = built.sx_in()[0]
    T, J = built(q)
    # CasADi stores matrices column-major, jacgen row-major: the transposes, stored, are the same arrays.
    fk_jacobian = casadi.Function(f"casadi_fk_jacobian_{robot.name}", [q], [T.T, J.T])
    scalar = casadi.det(J) if robot.dof == 6 else casadi.sqrt(casadi.det(casadi.mtimes(J, J.T)))
    scalar = casadi.Function(f"casadi_{scalar_name(robot)}", [q], casadi.cse([scalar]))
    name, code = robot.name, folder / robot.name
    code.mkdir(parents=True, exist_ok=True)
    text = "\n".join(common.casadi_c(function, code, "float", "int", prefix=f"{function.name()}_").read_text()
                     for function in (fk_jacobian, scalar))
    text = re.sub(r"\b(" + "|".join(MATH) + r")\(", r"\1f(", text)
    real = f"{name}_real"
    header = (f"typedef float {real};\n"
              f"void {name}_fk_jacobian(const {real} q[{robot.dof}], {real} T[16], {real} J[{6 * robot.dof}]);\n"
              f"{real} {name}_{scalar_name(robot)}(const {real} q[{robot.dof}]);\n")
    (code / f"{name}.h").write_text(header)
    wrappers = f"""
#include "{name}.h"
static float w_fk[{max(fk_jacobian.sz_w(), 1)}], w_scalar[{max(scalar.sz_w(), 1)}];
static int iw_fk[{max(fk_jacobian.sz_iw(), 1)}], iw_scalar[{max(scalar.sz_iw(), 1)}];
void {name}_fk_jacobian(const {real} q[{robot.dof}], {real} T[16], {real} J[{6 * robot.dof}])
{{
    const float *arg[1] = {{q}};
    float *res[2] = {{T, J}};
    {fk_jacobian.name()}(arg, res, iw_fk, w_fk, 0);
}}
{real} {name}_{scalar_name(robot)}(const {real} q[{robot.dof}])
{{
    const float *arg[1] = {{q}};
    float value;
    float *res[1] = {{&value}};
    {scalar.name()}(arg, res, iw_scalar, w_scalar, 0);
    return value;
}}
"""
    (code / f"{name}.c").write_text(text + wrappers)


def measure(robot, folder: Path, q: np.ndarray, sources: Path | None) -> dict[str, tuple]:
    """{function: (flash, stack gcc, stack measured, mean instructions)}, each result checked."""
    generator = Generator(robot, selection=("fk_jacobian", scalar_name(robot)))
    emulator = Emulator(robot, generator, folder, sources)
    if sources is None:
        emulator.build()
    else:  # CasADi's C: its own code, not held to jacgen's warning flags
        emulator.build(warnings=("-std=c99", "-fsingle-precision-constant"))
    expected = {"fk_jacobian": np.hstack([reference.fk(robot, q).reshape(len(q), -1),
                                          reference.jacobian(robot, q).reshape(len(q), -1)]),
                scalar_name(robot): getattr(reference, scalar_name(robot))(robot, q)[:, None]}
    figures = {}
    for name, value in expected.items():
        found = np.hstack([np.reshape(part, (len(q), -1)) for part in emulator.results(name, q)])
        error = np.max(np.abs(found - value) / (1 + np.abs(value)))
        if not error <= VERIFIED["float"] * (1 + robot.reach):  # `jacgen verify`'s float tolerance
            raise SystemExit(f"{robot.name} {name} ({'casadi' if sources else 'jacgen'}): off by {error:.1e}")
        batch, cost = emulator.measured[name], emulator.resources[name]
        figures[name] = (cost.flash, cost.stack, int(batch.stack.max()), float(batch.instructions.mean()))
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=200)
    arguments = parser.parse_args()
    check_tools()
    print("| robot | function | flash B jacgen / CasADi | stack B (gcc) | stack B (measured) "
          "| instructions/call | ratio |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        for name in ROBOTS:
            robot = common.shipped(name)
            ranges = np.array([joint.limits or (-np.pi, np.pi) for joint in robot.joints])
            q = np.random.default_rng(0).uniform(ranges[:, 0], ranges[:, 1], size=(arguments.samples, robot.dof))
            q = q.astype(np.float32).astype(np.float64)
            casadi_source(robot, folder / "casadi_c")
            ours = measure(robot, folder / "jacgen" / name, q, None)
            theirs = measure(robot, folder / "casadi" / name, q, folder / "casadi_c")
            for function in ours:
                (flash, stack, used, count), (flash_c, stack_c, used_c, count_c) = ours[function], theirs[function]
                print(f"| {name} | {function} | {flash} / {flash_c} | {stack} / {stack_c} | {used} / {used_c} "
                      f"| {count:.0f} / {count_c:.0f} | {count / count_c:.2f} |")


if __name__ == "__main__":
    main()
