"""Benchmark: what jacgen's CasADi module costs an optimisation user, beside the generated C.

    python bench/bench_casadi_use.py [--robots ur5,puma560] [--rounds 7]

Per robot, for `fk_jacobian`:
- import: loading the committed generated/NAME/NAME_casadi.py (building its SX graphs and
  Functions) in a fresh interpreter, `import casadi` excluded (printed apart);
- one call from Python: the Function called with a numpy array (casadi.DM results);
- inside a solve: ipopt on examples/casadi_opti.py's least-squares IK, whose objective reads
  `fk`: the solve's time in the objective and its gradient and Hessian (CasADi's own
  `t_wall_nlp_f`, `t_wall_nlp_grad_f`, `t_wall_nlp_hess_l`) per evaluation, and the whole
  solve;
- the C: jacgen's `NAME_fk_jacobian`, in common.py's native harness (gcc -O2).
Medians after a warm-up (common.py's policy).
"""

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import common

EXAMPLE = common.ROOT / "examples" / "casadi_opti.py"
IMPORT = """import time, importlib.util, casadi
start = time.perf_counter()
spec = importlib.util.spec_from_file_location("m", {path!r})
spec.loader.exec_module(importlib.util.module_from_spec(spec))
print(time.perf_counter() - start)"""


def import_seconds(path: Path, rounds: int) -> float:
    """Median time to load a generated CasADi module in a fresh interpreter (casadi already imported)."""
    runs = [float(subprocess.run([sys.executable, "-c", IMPORT.format(path=str(path))], capture_output=True,
                                 text=True, check=True).stdout) for _ in range(rounds)]
    return common.median(runs)


def casadi_import_seconds(rounds: int) -> float:
    code = "import time; start = time.perf_counter(); import casadi; print(time.perf_counter() - start)"
    return common.median([float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                               check=True).stdout) for _ in range(rounds)])


def in_solve(example, module, robot, rounds: int) -> tuple[float, float, float]:
    """(seconds per objective evaluation, per gradient, per Hessian, whole solve with building
    the Opti problem) of the least-squares IK from a nearby pose, medians over `rounds` solves."""
    q_goal = np.random.default_rng(0).uniform(-1, 1, robot.dof)
    target, nearby = np.asarray(module.fk(q_goal)), np.asarray(module.fk(q_goal + 0.05))
    figures = []
    for _ in range(rounds + 1):  # the first, a warm-up, is dropped
        start = time.perf_counter()
        _, stats = example.least_squares_ik(module, target, nearby, q_goal + 0.2)
        figures.append((stats["t_wall_nlp_f"] / stats["n_call_nlp_f"],
                        stats["t_wall_nlp_grad_f"] / stats["n_call_nlp_grad_f"],
                        stats["t_wall_nlp_hess_l"] / stats["n_call_nlp_hess_l"], time.perf_counter() - start))
    figures = figures[1:]
    return tuple(common.median(column) for column in zip(*figures))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="ur5,puma560", help="6R arms with a closed-form ik (the warm start)")
    parser.add_argument("--rounds", type=int, default=7)
    arguments = parser.parse_args()
    example = common.load_module(EXAMPLE, "casadi_opti")
    robots = [common.shipped(name) for name in arguments.robots.split(",")]
    with tempfile.TemporaryDirectory() as folder:
        loops = [common.fk_jacobian_loop(robot, "c") for robot in robots]
        sources = [common.generate(robot, Path(folder)) / f"{robot.name}.c" for robot in robots]
        header = "\n".join(f'#include "{robot.name}.h"' for robot in robots)
        program = common.build(Path(folder), "harness", common.harness(loops, header), sources)
        c_ns = common.run_loops(program, 1_000_000, arguments.rounds)
    print(f"import casadi: {casadi_import_seconds(arguments.rounds) * 1e3:.0f} ms (once per process)\n")
    print("| robot | import NAME_casadi.py | fk_jacobian from Python | in ipopt: f / grad f / Hessian "
          "per evaluation | least-squares IK solve | generated C fk_jacobian |")
    print("|---|---:|---:|---:|---:|---:|")
    for robot in robots:
        path = common.ROOT / "generated" / robot.name / f"{robot.name}_casadi.py"
        module = common.load_module(path)
        q = np.random.default_rng(1).uniform(-1, 1, robot.dof)
        call = common.per_call(module.fk_jacobian, [(q,)] * 1000, arguments.rounds)
        f, gradient, hessian, solve = in_solve(example, module, robot, arguments.rounds)
        print(f"| {robot.name} | {import_seconds(path, arguments.rounds) * 1e3:.0f} ms | {call * 1e6:.1f} µs | "
              f"{f * 1e6:.1f} / {gradient * 1e6:.1f} / {hessian * 1e6:.1f} µs | {solve * 1e3:.1f} ms | "
              f"{c_ns[(robot.name, 'c')]:.0f} ns |")


if __name__ == "__main__":
    main()
