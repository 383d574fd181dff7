"""How generation scales with the number of joints (issue 6).

For random standard-DH chains of 2..12 revolute joints (fixed seed; each alpha one of 0,
+90, -90 degrees or a random angle; random link lengths a and d), measures the time to build
the symbolic chain and lower fk and the geometric Jacobian to straight-line code
(`codegen.functions.Generator`), and the operation count of the result
(`Body.operation_count`), averaged over a few chains per size. Prints a table and the
log-log slopes (least squares on the logs) of operations and time against n.

    PYTHONPATH=. python bench/bench_scaling.py [--seed 1] [--sizes 2,4,6,8,10,12] [--repeats 3]
"""

import argparse
import math
import random
import time

from codegen.functions import Generator
from codegen.robot import parse_robot

ALPHAS = ("0", "90", "-90", "random")


def random_chain(n: int, rng: random.Random) -> str:
    """Robot file text of a random n-joint revolute chain (angles in degrees)."""
    rows = []
    for _ in range(n):
        alpha = rng.choice(ALPHAS)
        if alpha == "random":
            alpha = f"{rng.uniform(-180, 180):.1f}"
        rows.append(f"  - {{type: revolute, a: {rng.uniform(0.05, 0.5):.3f}, alpha: {alpha}, "
                    f"d: {rng.uniform(0.05, 0.5):.3f}}}")
    task = "task: [x, y, z]\n" if n < 6 else ""
    return f"name: chain{n}\nconvention: standard\nangle_unit: deg\njoints:\n" + "\n".join(rows) + "\n" + task


def measure(n: int, rng: random.Random, repeats: int) -> dict:
    """Mean operation counts and seconds over `repeats` random chains of n joints."""
    totals = {"fk": 0, "jacobian": 0, "seconds": 0.0}
    for _ in range(repeats):
        robot = parse_robot(random_chain(n, rng).encode(), f"chain{n}.yaml")
        start = time.perf_counter()
        generator = Generator(robot)
        fk = generator.lower(generator.chain.tool)
        jacobian = generator.lower(generator.jacobian)
        totals["seconds"] += time.perf_counter() - start
        totals["fk"] += fk.operation_count
        totals["jacobian"] += jacobian.operation_count
    row = {key: value / repeats for key, value in totals.items()}
    return {"n": n, **row, "ops": row["fk"] + row["jacobian"]}


def slope(xs, ys) -> float:
    """Least-squares slope of log(y) against log(x)."""
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--sizes", default="2,4,6,8,10,12", help="comma-separated joint counts")
    parser.add_argument("--repeats", type=int, default=3, help="random chains per size")
    arguments = parser.parse_args()
    rng = random.Random(arguments.seed)
    rows = [measure(int(n), rng, arguments.repeats) for n in arguments.sizes.split(",")]
    print(f"mean of {arguments.repeats} random chains per size (seed {arguments.seed})")
    print(f"{'n':>3} {'fk ops':>8} {'jacobian ops':>13} {'total ops':>10} {'time s':>8}")
    for row in rows:
        print(f"{row['n']:>3} {row['fk']:>8.0f} {row['jacobian']:>13.0f} {row['ops']:>10.0f} {row['seconds']:>8.2f}")
    sizes = [row["n"] for row in rows]
    print(f"log-log slope: ops ~ n^{slope(sizes, [row['ops'] for row in rows]):.2f}, "
          f"time ~ n^{slope(sizes, [row['seconds'] for row in rows]):.2f}")


if __name__ == "__main__":
    main()
