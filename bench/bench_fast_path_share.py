"""Study: the share of random poses a calibrated arm's fast path decides, with the mismatch's
ball scaled (contract §2, "What a smaller ball would decide").

    PYTHONPATH=. python bench/bench_fast_path_share.py [--arms ur5_calibrated,puma560_calibrated]
        [--scales 1,0.5,0.3,0.1] [--poses 20000] [--steps 4]

For each arm and scale s, the generated Python fast path is built with the bound on the two
arms' tool poses (general6r.mismatch) multiplied by s, the arm itself unchanged, and run on the
same random poses (fk of uniform joint vectors). Per row: where the certificate fails, where it
holds but a branch's Newton steps (--steps after the first) do not converge, where two branches
reach one solution, and the share decided. A directional certificate's residual ball is a
fraction of the mismatch: this shows what such a fraction can decide at best.
"""

import argparse
import tempfile
from pathlib import Path

import numpy as np

import common
from jacgen.checking import reference
from jacgen.emission.render import render_robot
from jacgen.inputs.robot_file import load_robot
from jacgen.solvers import general6r
from jacgen.solvers.model import Model


def fast_path_module(name: str, scale: float, folder: Path):
    """The arm's generated Python (ik_branches only) with its mismatch scaled by `scale`."""
    original = general6r.mismatch
    general6r.mismatch = lambda robot, nominal: tuple(scale * bound for bound in original(robot, nominal))
    try:
        robot = load_robot(common.robot_path(name))
        text = render_robot(robot, languages=("python",), functions=["ik_branches"])[f"{name}/{name}.py"]
    finally:
        general6r.mismatch = original
    path = folder / f"{name}_{scale:g}.py"
    path.write_text(text)
    return common.load_module(path)


def shares(module, targets: np.ndarray, free: tuple, steps: int) -> dict:
    """Why the fast path does not decide, as shares of the poses (its own steps: _fast_branches);
    `free`: () or (a 7-axis arm's free joint angle per pose,)."""
    q, nominal, certified = module.ik_general_nominal(targets, *free)
    cost, q = module._newton(targets[..., None, :, :], q)
    cost, q = module._polish(targets[..., None, :, :], q, cost, steps)
    converged = nominal & (cost <= module._CONVERGED_SQUARED)
    distinct = (module._first_of_equals(q, converged) == converged).all(-1)
    certified = certified != 0
    converges = (converged == nominal).all(-1)
    return {"certificate fails": (~certified).mean(), "not converged": (certified & ~converges).mean(),
            "one solution twice": (certified & converges & ~distinct).mean(),
            "decided": (certified & converges & distinct).mean()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arms", default="ur5_calibrated,puma560_calibrated")
    parser.add_argument("--scales", default="1,0.5,0.3,0.1")
    parser.add_argument("--poses", type=int, default=20000)
    parser.add_argument("--steps", type=int, default=general6r.FAST_STEPS)
    arguments = parser.parse_args()
    with tempfile.TemporaryDirectory() as temporary:
        for name in arguments.arms.split(","):
            robot = load_robot(common.robot_path(name))
            q = np.random.default_rng(7).uniform(-np.pi, np.pi, (arguments.poses, robot.dof))
            targets = reference.fk(robot, q)
            form = Model(robot).closed_form
            free = () if form.free is None else (q[:, form.free],)
            for scale in (float(s) for s in arguments.scales.split(",")):
                module = fast_path_module(name, scale, Path(temporary))
                row = shares(module, targets, free, arguments.steps)
                print(f"{name:20s} ball x {scale:<6g} " + "  ".join(f"{key} {value:6.2%}" for key, value in row.items()),
                      flush=True)


if __name__ == "__main__":
    main()
