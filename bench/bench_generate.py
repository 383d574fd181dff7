"""Generation time against an earlier jacgen, measured in the same run (issue 21).

For each robot file, renders every language (C, Python, CasADi, report) in a fresh process,
once with this checkout and once with a baseline commit checked out in a temporary
`git worktree` (`common.render_in_process`), and prints per robot: seconds now and then
(Python start-up and imports excluded; the median of --repeats, common.py's policy), their
ratio, each process's peak memory, and the operation counts of fk_jacobian, ik_branches,
velocity_ik and the second-order functions, now and then. The runs alternate (now, then,
now, ...) so that a load on the machine falls on both.

    python bench/bench_generate.py [ROBOT.yaml ...] [--baseline 70175b8] [--random 6,11,16,32]
        [--radians] [--repeats 1] [--timeout 300]

Without robot files: every shipped robot. `--random` adds arms of those joint counts from
the test suite's `random_arm_text` (seed 1000 * n, written to a temporary folder and read by
both; `--radians`: their angles in radians). The last line sums the robots both finished.
"""

import argparse
import subprocess
import tempfile
from pathlib import Path

import common
from common import random_arm_text

COUNTED = ("fk_jacobian", "ik_branches", "velocity_ik", "second_order")
SECOND_ORDER = ("fk_jacobian_dot", "jacobian_dot", "bias_acceleration", "task_jacobian_dot", "hessian")


def counts(result: dict | None) -> dict:
    if result is None:
        return {}
    operations = result["operations"]
    found = {name: operations.get(name) for name in COUNTED[:3]}
    found["second_order"] = sum(operations.get(name, 0) for name in SECOND_ORDER) or None
    return found


def typical(results: list[dict | None]) -> dict | None:
    """The first finished rendering, with the median seconds of those that finished."""
    finished = [r for r in results if r is not None]
    return {**finished[0], "seconds": common.median(r["seconds"] for r in finished)} if finished else None


def text(value, form: str = "{}") -> str:
    return "-" if value is None else form.format(value)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robots", nargs="*", type=Path)
    parser.add_argument("--baseline", default="70175b8")
    parser.add_argument("--random", default="", help="joint counts of random arms to add, e.g. 6,11,16,32")
    parser.add_argument("--radians", action="store_true",
                        help="the random arms' angles in radians (irrational twists: the slow case of issue 21)")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per rendering")
    options = parser.parse_args()
    robots = [path.resolve() for path in options.robots or sorted((common.ROOT / "robots").glob("*.yaml"))]
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        if options.random:
            for dof in map(int, options.random.split(",")):
                path = scratch / f"random{dof}{'_rad' * options.radians}.yaml"
                path.write_text(random_arm_text(1000 * dof, dof=dof, radians=options.radians))
                robots.append(path)
        baseline = scratch / "baseline"
        subprocess.run(["git", "-C", str(common.ROOT), "worktree", "add", "--detach", "-q", str(baseline),
                        options.baseline], check=True)
        try:
            print(f"{'robot':<14} {'now s':>7} {'then s':>7} {'ratio':>6} {'MB now':>7} {'MB then':>7}  "
                  + "  ".join(f"{name} now/then" for name in COUNTED))
            totals = [0.0, 0.0]
            for robot in robots:
                now, then = [], []
                for _ in range(options.repeats):
                    now.append(common.render_in_process(common.ROOT, robot, options.timeout))
                    then.append(common.render_in_process(baseline, robot, options.timeout))
                now, then = typical(now), typical(then)
                ratio = then["seconds"] / now["seconds"] if now and then else None
                operations = [f"{text(counts(now).get(name))}/{text(counts(then).get(name))}" for name in COUNTED]
                seconds = [f"{r['seconds']:.2f}" if r else f">{options.timeout:.0f}" for r in (now, then)]
                memory = [f"{r['peak_mb']:.0f}" if r else "-" for r in (now, then)]
                print(f"{robot.stem:<14} {seconds[0]:>7} {seconds[1]:>7} {text(ratio, '{:.1f}x'):>6} {memory[0]:>7} "
                      f"{memory[1]:>7}  " + "  ".join(operations), flush=True)
                if ratio:
                    totals = [totals[0] + now["seconds"], totals[1] + then["seconds"]]
            print(f"{'all finished':<14} {totals[0]:>7.2f} {totals[1]:>7.2f} "
                  f"{text(totals[1] / totals[0] if totals[0] else None, '{:.1f}x'):>6}")
        finally:
            subprocess.run(["git", "-C", str(common.ROOT), "worktree", "remove", "--force", str(baseline)], check=True)


if __name__ == "__main__":
    main()
