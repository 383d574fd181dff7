"""How long `jacgen show --plot` takes to draw an arm (issue 25: under 1 s each), and beside
the Robotics Toolbox's `robot.plot` on the same arms.

1. Every shipped robot and the stress suite's arms (tests/test_drawing.py's: 30 seeded
   random arms of 1 to 12 joints, one of 16 and one of 32): `jacgen.reports.drawing.draw`
   into a PNG at its default configurations (two panels with the velocity ellipsoid; planar
   arms also the workspace map with its ellipses). matplotlib's import is taken once,
   before (it is the same for every drawing).
2. One configuration into a PNG, jacgen's `draw` with one panel against rtb's
   `robot.plot(q, backend="pyplot", jointaxes=True, eeframe=True)` then `savefig`, on the
   rtb DH models the shipped robot files come from (their tables equal rtb's to 1e-15).

Seconds are the median of --rounds after a warm-up (common.timed).

    PYTHONPATH=. python bench/bench_drawing.py [--rounds 3]
"""

import argparse
import tempfile
from pathlib import Path

import matplotlib
import numpy as np

import common
from common import random_arm_text
from jacgen.reports import drawing
from jacgen.inputs.robot_file import parse_robot

RTB_MODELS = {"puma560": "Puma560", "panda": "Panda", "ur5": "UR5", "stanford": "Stanford", "kr5": "KR5",
              "jaco": "Jaco"}


def stress_arms() -> dict:
    """tests/test_drawing.py's random arms, by label."""
    seeds = [(seed, None) for seed in range(30)] + [(16, 16), (32, 32)]
    return {f"random {seed}" + (f" ({dof})" if dof else ""):
            parse_robot(random_arm_text(seed, dof=dof).encode(), f"random{seed}.yaml") for seed, dof in seeds}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(tempfile.mkdtemp())
    arms = {path.stem: common.shipped(path.stem) for path in sorted((common.ROOT / "robots").glob("*.yaml"))}
    times = {}
    for label, arm in (arms | stress_arms()).items():
        path = folder / f"{label}.png"
        times[label] = (arm.dof, common.timed(
            lambda: path.write_bytes(drawing.draw(arm, drawing.default_configurations(arm))), args.rounds).seconds)
    print("1. jacgen show --plot, default configurations, seconds per drawing (median)")
    print(f"{'arm':<18}{'joints':>7}{'seconds':>9}")
    for name, (dof, seconds) in times.items():
        print(f"{name:<18}{dof:>7}{seconds:>9.3f}")
    slowest = max(times.items(), key=lambda item: item[1][1])
    print(f"{len(times)} arms: median {np.median([s for _, s in times.values()]):.3f} s, "
          f"slowest {slowest[0]} {slowest[1][1]:.3f} s\n")

    import roboticstoolbox as rtb

    print("2. one configuration into a PNG: jacgen draw / rtb robot.plot + savefig (median seconds)")
    print(f"{'robot':<10}{'jacgen':>9}{'rtb':>9}{'ratio':>8}")
    for name, model in RTB_MODELS.items():
        arm, theirs = common.shipped(name), getattr(rtb.models.DH, model)()
        q = np.random.default_rng(0).uniform(*np.array(arm.ranges).T)

        def rtb_plot():
            environment = theirs.plot(q, backend="pyplot", block=False, jointaxes=True, eeframe=True)
            environment.fig.savefig(folder / f"rtb_{name}.png")
            plt.close("all")

        def jacgen_plot():
            (folder / f"one_{name}.png").write_bytes(drawing.draw(arm, {"at a random q": q}))

        measured = common.median_times({"jacgen": jacgen_plot, "rtb": rtb_plot}, args.rounds)
        ours, peer = measured["jacgen"].seconds, measured["rtb"].seconds
        print(f"{name:<10}{ours:>9.3f}{peer:>9.3f}{ours / peer:>8.2f}")


if __name__ == "__main__":
    main()
