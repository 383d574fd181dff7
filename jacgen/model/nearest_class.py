"""A calibrated arm's nearest special class (contract §2, "Calibrated arms"): the nominal arm,
its few near-special DH values snapped to the special ones, whose closed form seeds the
general 6R solver's fast path (`ik.py`, `general6r.py`).
"""

import math
from dataclasses import dataclass, replace

import sympy

from jacgen.inputs.robot import Robot
from jacgen.inputs.values import Value
from jacgen.model.structure import Structure, classify

# A calibrated arm's nearest special class (contract §2, "Calibrated arms"): twists within NEAR_TWIST
# of a multiple of pi/2 and lengths a, d within NEAR_LENGTH times the reach of 0 may be snapped.
NEAR_TWIST = 0.02  # rad
NEAR_LENGTH = 0.005


@dataclass(frozen=True)
class Nominal:
    """The arm with the fewest of its near-special DH values snapped to the special ones that
    puts it in a special class: the calibrated arm's nominal arm, whose closed form seeds the
    general solver's fast path."""

    robot: Robot
    snapped: tuple[str, ...]  # each snapped value, e.g. "alpha2 -0.001 -> 0 rad"
    structure: Structure


def _near_special(robot: Robot) -> list[tuple[float, int, str, Value, str]]:
    """The DH values within NEAR_TWIST or NEAR_LENGTH of a special one: (how far, in the
    robot's length unit at its reach, joint index, key, the special value, text), farthest first."""
    found = []
    for i, joint in enumerate(robot.joints):
        quarter = round(joint.alpha.approx / (math.pi / 2))
        off = joint.alpha.approx - quarter * math.pi / 2
        if 0 < abs(off) <= NEAR_TWIST:
            special = Value(quarter * sympy.pi / 2, quarter * math.pi / 2)
            found.append((abs(off) * robot.reach, i, "alpha", special,
                          f"alpha{i + 1} {joint.alpha.approx:.8g} -> {special.approx:.8g} rad"))
        for key in ("a", "d"):
            value = getattr(joint, key)
            if value is not None and 0 < abs(value.approx) <= NEAR_LENGTH * robot.reach:
                found.append((abs(value.approx), i, key, Value(sympy.Integer(0), 0.0),
                              f"{key}{i + 1} {value.approx:.8g} -> 0 {robot.length_unit}"))
    return sorted(found, key=lambda entry: -entry[0])


def _snapped(robot: Robot, values, free: int | None) -> Robot:
    joints = list(robot.joints)
    for _, i, key, special, _ in values:
        joints[i] = replace(joints[i], **{key: special})
    return replace(robot, joints=tuple(joints), nearest_class=False, free_joint=free)


def nearest_class(robot: Robot, free: int | None = None) -> Nominal | None:
    """The nominal arm of a 6R arm without a special class (of a 7R arm: with joint `free` free,
    as the general solver has it), None when snapping every near-special value does not give
    one. Greedy: from all of them snapped, each (farthest first) is put back when the arm stays
    in a special class without it."""
    snapped = _near_special(robot)
    structure = classify(_snapped(robot, snapped, free))
    if structure.solver in (None, "general_6r"):
        return None
    for value in list(snapped):
        trial = [other for other in snapped if other is not value]
        candidate = classify(_snapped(robot, trial, free))
        if candidate.solver not in (None, "general_6r"):
            snapped, structure = trial, candidate
    return Nominal(_snapped(robot, snapped, free), tuple(entry[4] for entry in snapped), structure)
