"""Generation time against an earlier jacgen, measured in the same run (issue 21).

For each robot file, renders every language (C, Python, CasADi, report) in a fresh process,
once with this checkout and once with a baseline commit checked out in a temporary
`git worktree`, and prints per robot: seconds now and then (Python start-up and imports
excluded; the best of --repeats), their ratio, each process's peak memory, and the
operation counts of fk_jacobian, ik_branches, velocity_ik and the second-order functions,
now and then. The runs alternate (now, then, now, ...) so that a load on the machine
falls on both.

    python bench/bench_generate.py [ROBOT.yaml ...] [--baseline 70175b8] [--random 6,11,16,32]
        [--repeats 1] [--timeout 300]

Without robot files: every shipped robot. `--random` adds arms of those joint counts from
tests/random_arms.py (seed 1000 * n, written to a temporary folder and read by both).
"""

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
COUNTED = ("fk_jacobian", "ik_branches", "velocity_ik", "second_order")
SECOND_ORDER = ("fk_jacobian_dot", "jacobian_dot", "bias_acceleration", "task_jacobian_dot", "hessian")

# Run in the tree being measured (its jacgen first on sys.path): render one robot, print JSON.
WORKER = """
import json, resource, sys, time
sys.path.insert(0, ".")
from jacgen.functions import Generator
from jacgen.render import render_robot
from jacgen.robot import load_robot
robot = load_robot(sys.argv[1])
start = time.perf_counter()
generator = Generator(robot)
render_robot(robot, generator=generator)
seconds = time.perf_counter() - start
operations = {f.name: f.body.operation_count for f in generator.functions()}
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"seconds": seconds, "peak_mb": peak, "operations": operations,
                  "complete": generator.singularities.complete}))
"""


def measure(tree: Path, robot: Path, timeout: float) -> dict | None:
    """One rendering of `robot` by the jacgen in `tree`, None past `timeout` seconds."""
    try:
        done = subprocess.run([sys.executable, "-c", WORKER, str(robot)], cwd=tree, capture_output=True,
                              text=True, timeout=timeout, check=True)
    except subprocess.TimeoutExpired:
        return None
    except subprocess.CalledProcessError as error:
        raise SystemExit(f"bench_generate: {robot} failed in {tree}:\n{error.stderr}") from None
    return json.loads(done.stdout.splitlines()[-1])


def counts(result: dict | None) -> dict:
    if result is None:
        return {}
    operations = result["operations"]
    found = {name: operations.get(name) for name in COUNTED[:3]}
    found["second_order"] = sum(operations.get(name, 0) for name in SECOND_ORDER) or None
    return found


def best(results: list[dict | None]) -> dict | None:
    finished = [r for r in results if r is not None]
    return min(finished, key=lambda r: r["seconds"]) if finished else None


def text(value, form: str = "{}") -> str:
    return "-" if value is None else form.format(value)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("robots", nargs="*", type=Path)
    parser.add_argument("--baseline", default="70175b8")
    parser.add_argument("--random", default="", help="joint counts of random arms to add, e.g. 6,11,16,32")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per rendering")
    options = parser.parse_args()
    robots = [path.resolve() for path in options.robots or sorted((ROOT / "robots").glob("*.yaml"))]
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        if options.random:
            sys.path.insert(0, str(ROOT / "tests"))
            from random_arms import random_arm_text
            for dof in map(int, options.random.split(",")):
                path = scratch / f"random{dof}.yaml"
                path.write_text(random_arm_text(1000 * dof, dof=dof))
                robots.append(path)
        baseline = scratch / "baseline"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(baseline), options.baseline],
                       check=True)
        try:
            print(f"{'robot':<14} {'now s':>7} {'then s':>7} {'ratio':>6} {'MB now':>7} {'MB then':>7}  "
                  + "  ".join(f"{name} now/then" for name in COUNTED))
            for robot in robots:
                now, then = [], []
                for _ in range(options.repeats):
                    now.append(measure(ROOT, robot, options.timeout))
                    then.append(measure(baseline, robot, options.timeout))
                now, then = best(now), best(then)
                ratio = then["seconds"] / now["seconds"] if now and then else None
                operations = [f"{text(counts(now).get(name))}/{text(counts(then).get(name))}" for name in COUNTED]
                seconds = [f"{r['seconds']:.2f}" if r else f">{options.timeout:.0f}" for r in (now, then)]
                memory = [f"{r['peak_mb']:.0f}" if r else "-" for r in (now, then)]
                print(f"{robot.stem:<14} {seconds[0]:>7} {seconds[1]:>7} {text(ratio, '{:.1f}x'):>6} {memory[0]:>7} "
                      f"{memory[1]:>7}  " + "  ".join(operations), flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(baseline)], check=True)


if __name__ == "__main__":
    main()
