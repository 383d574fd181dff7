"""How generation scales with the number of joints (issue 9).

For random arms of 1 to 32 joints (the test suite's `random_arm_text`: both conventions,
prismatic joints, arbitrary twists, base and tool, any task shape; fixed seeds), renders
every language in a fresh process (`common.render_in_process`, bench_generate's worker)
and reports, averaged over the arms of each size: generation time (Python start-up
excluded), the process's peak memory, and the operation counts of `fk_jacobian`,
`singularity_factors` and `manipulability`; then the log-log slopes (least squares on the
logs) of each against n, over all sizes and from 6 joints up.

    PYTHONPATH=. python bench/bench_scaling.py [--sizes 1,2,4,6,8,12,16,24,32] [--repeats 3]
"""

import argparse
import tempfile
from pathlib import Path

import common
from common import random_arm_text

COLUMNS = ("seconds", "peak_mb", "fk_jacobian", "singularity_factors", "manipulability")


def measure(dof: int, repeats: int, folder: Path) -> dict:
    """The means over `repeats` random arms of `dof` joints, each rendered in a fresh process."""
    rows = []
    for repeat in range(repeats):
        seed = 1000 * dof + repeat
        path = folder / f"arm{seed}.yaml"
        path.write_text(random_arm_text(seed, dof=dof))
        result = common.render_in_process(common.ROOT, path, timeout=3600)
        rows.append({"seconds": result["seconds"], "peak_mb": result["peak_mb"], "complete": result["complete"],
                     **{name: result["operations"][name] for name in COLUMNS[2:]}})
    mean = {key: sum(row[key] for row in rows) / len(rows) for key in COLUMNS}
    return {"n": dof, **mean, "peak_mb": max(row["peak_mb"] for row in rows),
            "max_seconds": max(row["seconds"] for row in rows), "exact": sum(row["complete"] for row in rows)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1,2,4,6,8,12,16,24,32", help="comma-separated joint counts")
    parser.add_argument("--repeats", type=int, default=3, help="random arms per size")
    arguments = parser.parse_args()
    rows = []
    print(f"random arms, {arguments.repeats} per size; time and operations are means, memory the largest")
    print(f"{'n':>3} {'time s':>7} {'max s':>7} {'peak MB':>8} {'fk_jacobian':>12} {'sing. factors':>14} "
          f"{'manipulab.':>11} {'exact':>6}")
    for n in (int(size) for size in arguments.sizes.split(",")):
        with tempfile.TemporaryDirectory() as folder:
            row = measure(n, arguments.repeats, Path(folder))
        rows.append(row)
        print(f"{n:>3} {row['seconds']:>7.2f} {row['max_seconds']:>7.2f} {row['peak_mb']:>8.0f} "
              f"{row['fk_jacobian']:>12.0f} {row['singularity_factors']:>14.0f} {row['manipulability']:>11.0f} "
              f"{row['exact']:>4}/{arguments.repeats}", flush=True)
    for label, chosen in (("all sizes", rows), ("n >= 6", [row for row in rows if row["n"] >= 6])):
        if len(chosen) >= 2:
            sizes = [row["n"] for row in chosen]
            slopes = ", ".join(f"{key} n^{common.slope(sizes, [row[key] for row in chosen]):.2f}" for key in COLUMNS
                               if all(row[key] > 0 for row in chosen))  # a log needs positive values
            print(f"log-log slopes ({label}): {slopes}")


if __name__ == "__main__":
    main()
