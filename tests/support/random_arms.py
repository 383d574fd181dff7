"""Seeded random robot files: arms nobody tuned jacgen for (issue 9's stress suite and
bench/bench_scaling.py).

`random_arm(seed)` draws a whole robot file from one seed: 1 to 12 joints, either DH
convention, revolute and prismatic joints mixed, each alpha one of 0, ±90, 180 degrees or
an arbitrary angle, arbitrary offsets and lengths, base and tool transforms with arbitrary
rotations, a task of any shape (fewer, as many or more components than joints; with or
without Euler angles) and some lengths kept as symbolic runtime parameters. With
`radians`, the same arm is written in radians: 0, pi/2, -pi/2, pi, and arbitrary angles as
4-decimal numbers such as 1.2001 (exact rationals whose cosines have no closed form, the
arms whose structure detection once took minutes).
"""

import math
import random
import re

from click.testing import CliRunner

from jacgen.cli import main
from jacgen.inputs.robot import TASK_COMPONENTS

SPECIAL_ALPHAS = (0.0, 90.0, -90.0, 180.0)


def _number(rng: random.Random, low: float, high: float) -> str:
    return f"{rng.uniform(low, high):.4f}"


def _alpha(rng: random.Random) -> str:
    return f"{rng.choice(SPECIAL_ALPHAS)}" if rng.random() < 0.7 else _number(rng, -180, 180)


def _pose(rng: random.Random) -> str:
    xyz = ", ".join(_number(rng, -0.3, 0.3) for _ in range(3))
    rpy = ", ".join(_number(rng, -180, 180) for _ in range(3))
    return f"{{xyz: [{xyz}], rpy: [{rpy}]}}"


def _task(rng: random.Random, dof: int) -> list[str]:
    """Any non-empty subset of (x, y, z, roll, pitch, yaw), in that order; its size is
    below, at or above the joint count about equally often (as the six components allow),
    and a small one holds positions only about as often as it holds angles."""
    shape = rng.choice(("fewer", "equal", "more"))
    size = {"fewer": rng.randint(1, max(1, min(dof - 1, 6))), "equal": min(dof, 6),
            "more": rng.randint(min(dof + 1, 6), 6)}[shape]
    positions_only = size <= 3 and rng.random() < 0.4
    return sorted(rng.sample(TASK_COMPONENTS[:3] if positions_only else TASK_COMPONENTS, size),
                  key=TASK_COMPONENTS.index)


SPECIAL_RADIANS = {"0": "0", "0.0": "0", "90.0": "pi/2", "-90.0": "-pi/2", "180.0": "pi"}


def _in_radians(degrees: str) -> str:
    """A drawn angle (degrees, as text) in radians: exact for the special ones."""
    return SPECIAL_RADIANS.get(degrees) or f"{math.radians(float(degrees)):.4f}"


def random_arm_text(seed: int, dof: int | None = None, revolute_only: bool = False, radians: bool = False) -> str:
    """Robot file text of the random arm `seed` (angles in degrees, or radians; lengths in metres)."""
    text = _random_arm_text(seed, dof, revolute_only)
    if not radians:
        return text
    text = re.sub(r"(type: revolute.*?)(offset: )([-\d.]+)", lambda m: m[1] + m[2] + _in_radians(m[3]), text)
    text = re.sub(r"((?:alpha|theta): )([-\d.]+)", lambda m: m[1] + _in_radians(m[2]), text)
    text = re.sub(r"rpy: \[([^\]]*)\]", lambda m: "rpy: [" + ", ".join(map(_in_radians, m[1].split(", "))) + "]", text)
    return text.replace("angle_unit: deg", "angle_unit: rad")


def _random_arm_text(seed: int, dof: int | None, revolute_only: bool) -> str:
    rng = random.Random(seed)
    dof = dof or rng.randint(1, 12)
    lines = [f"name: arm{seed}", f"description: random arm, seed {seed}",
             f"convention: {rng.choice(('standard', 'modified'))}", "angle_unit: deg", "parameters:"]
    symbolic = [f"len{k}" for k in range(rng.randint(0, 2))]
    lines += [f"  {name}: {{value: {_number(rng, 0.05, 0.5)}, symbolic: true}}" for name in symbolic]
    if not symbolic:
        lines[-1] = "parameters: {}"
    lines.append("joints:")
    for _ in range(dof):
        prismatic = not revolute_only and rng.random() < 0.2
        a = rng.choice(symbolic) if symbolic and rng.random() < 0.2 else _number(rng, -0.5, 0.5)
        a = "0" if rng.random() < 0.3 else a
        d = "0" if rng.random() < 0.3 else _number(rng, -0.5, 0.5)
        offset = "0" if rng.random() < 0.5 else _number(rng, -180, 180)
        if prismatic:
            theta = f"{rng.choice(SPECIAL_ALPHAS)}" if rng.random() < 0.7 else _number(rng, -180, 180)
            lines.append(f"  - {{type: prismatic, a: {a}, alpha: {_alpha(rng)}, theta: {theta}, "
                         f"offset: {_number(rng, 0, 0.3)}, limits: [0, 0.5]}}")
        else:
            lines.append(f"  - {{type: revolute, a: {a}, alpha: {_alpha(rng)}, d: {d}, offset: {offset}}}")
    if rng.random() < 0.7:
        lines.append(f"base: {_pose(rng)}")
    if rng.random() < 0.7:
        lines.append(f"tool: {_pose(rng)}")
    lines.append(f"task: [{', '.join(_task(rng, dof))}]")
    return "\n".join(lines) + "\n"


def generates_and_verifies(path, text: str):
    """Write `text` to `path`, then `jacgen verify` it: every language generated, built and
    within tolerance of the numpy reference, with no fallback."""
    path.write_text(text)
    verified = CliRunner().invoke(main, ["verify", str(path), "--samples", "40"], catch_exceptions=False)
    assert verified.exit_code == 0, verified.output  # generated every language, built, compared
    assert "warning" not in verified.output  # no fallback: the result does not depend on the machine
    compared = [line for line in verified.output.splitlines() if re.search(r"\d\.\de-\d\d", line)]
    assert len(compared) >= 8, verified.output  # every function was evaluated, not skipped
