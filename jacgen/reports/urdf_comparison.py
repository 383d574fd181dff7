"""`jacgen show --compare-urdf`: is the robot file the arm of a URDF?

A hand-written DH table and the vendor's URDF put their frames in different places, but
both describe the same joint axes: lines in space that move with q. So each joint's axis
line is compared (its direction, signed, since it says which way the joint turns, and the
distance of the URDF's joint origin from the robot file's line), and so is the tool pose
against the tip link's, at the zero configuration and random ones within the limits. The
first joint whose axis differs names the DH row to check: the rows before it place the
axes before it right.
"""

from dataclasses import dataclass

import numpy as np

from jacgen.errors import JacgenError
from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import Robot
from jacgen.inputs.urdf import MOVABLE, Snapper, joint_axes, read_chain

CONFIGURATIONS = 50  # the zero configuration and 49 random ones within the ranges


@dataclass(frozen=True)
class Comparison:
    """The largest differences over the configurations: per joint, the angle (rad) between
    the axis directions and the distance of the URDF's axis from the robot file's (0 for a
    prismatic joint, which has a direction only); for the
    tool, the rotation angle (rad) and the distance between its origin and the tip link's."""

    base: str
    tip: str
    axes: tuple[tuple[float, float], ...]
    tool: tuple[float, float]


def compare_urdf(robot: Robot, path: str, base: str | None = None, tip: str | None = None,
                 seed: int = 0) -> Comparison:
    """The robot file's axes and tool pose against the URDF chain base -> tip, read as written
    (nothing made exact)."""
    chain = read_chain(path, base, tip, Snapper(0.0))
    moving = sum(joint.kind in MOVABLE for joint in chain.joints)
    if moving != robot.dof:
        raise JacgenError(f"{path}: the chain {chain.base} -> {chain.tip} has {moving} moving joints, "
                          f"{robot.source} has {robot.dof}; choose the links with --base and --tip")
    low, high = np.array(robot.ranges).T
    q = np.vstack([np.zeros(robot.dof), np.random.default_rng(seed).uniform(low, high, (CONFIGURATIONS - 1, robot.dof))])
    frames, tool = numeric_chain.axis_frames(robot, q)
    urdf_axes, tip_pose = joint_axes(chain, q)
    axes = []
    for joint, frame, (point, direction) in zip(robot.joints, frames, urdf_axes):
        ours = frame[:, :3, 2]
        offset = point - frame[:, :3, 3]  # a prismatic joint is a direction: no line to compare
        off_line = (offset - np.sum(offset * ours, -1, keepdims=True) * ours) * joint.revolute
        angle = np.arctan2(np.linalg.norm(np.cross(ours, direction), axis=-1), np.sum(ours * direction, -1))
        axes.append((float(angle.max()), float(np.linalg.norm(off_line, axis=-1).max())))
    turn = np.swapaxes(tool[:, :3, :3], 1, 2) @ tip_pose[:, :3, :3]
    return Comparison(chain.base, chain.tip, tuple(axes),
                      (float(_rotation_angle(turn).max()),
                       float(np.linalg.norm(tool[:, :3, 3] - tip_pose[:, :3, 3], axis=-1).max())))


def _rotation_angle(rotation: np.ndarray) -> np.ndarray:
    """The angle of rotations (..., 3, 3), accurate near 0 (arccos of the trace is not)."""
    skew = rotation - np.swapaxes(rotation, -1, -2)
    sine = np.linalg.norm(np.stack([skew[..., 2, 1], skew[..., 0, 2], skew[..., 1, 0]], -1), axis=-1) / 2
    return np.arctan2(sine, (np.trace(rotation, axis1=-2, axis2=-1) - 1) / 2)


def first_difference(comparison: Comparison, tolerance: float) -> int | None:
    """The first joint (0-based) whose axis differs by more than `tolerance`; the number of
    joints when only the tool differs; None when everything agrees."""
    differs = [max(axis) > tolerance for axis in comparison.axes] + [max(comparison.tool) > tolerance]
    return differs.index(True) if any(differs) else None


def comparison_lines(robot: Robot, path: str, comparison: Comparison, tolerance: float) -> list[str]:
    """The table of differences and the verdict, naming the DH row to check."""
    unit = robot.length_unit
    lines = [f"{robot.name} against {path} (links {comparison.base} -> {comparison.tip}), largest differences at "
             f"{CONFIGURATIONS} configurations (q = 0 and random within the limits):",
             f"  {'joint':<24}{'axis direction':>16}{'axis line':>16}"]
    for i, (joint, (angle, distance)) in enumerate(zip(robot.joints, comparison.axes)):
        lines.append(f"  {f'{i + 1} {joint.name}':<24}{angle:>12.3g} rad{distance:>13.3g} {unit}")
    lines.append(f"  {'tool pose':<24}{comparison.tool[0]:>12.3g} rad{comparison.tool[1]:>13.3g} {unit}")
    k = first_difference(comparison, tolerance)
    if k is None:
        return lines + [f"agree to {tolerance:g}: the robot file describes the URDF's chain"]
    return lines + [f"first difference (over {tolerance:g}): {_suspect(robot, comparison, k)}"]


def _suspect(robot: Robot, comparison: Comparison, k: int) -> str:
    """Which entries of the robot file place what differs first."""
    if k == robot.dof:
        last = robot.joints[-1]
        return (f"the tool pose, every axis agreeing: check the tool and the last row ({last.name}"
                + ("'s a, alpha, d, offset)" if robot.convention == "standard" else "'s d, offset)"))
    joint, (angle, distance) = robot.joints[k], comparison.axes[k]
    what = f"the axis of joint {k + 1} ({joint.name}) is {angle:.3g} rad and {distance:.3g} {robot.length_unit} off"
    if distance <= 1e-9 and abs(angle - np.pi) < 1e-6:  # a twist of the wrong sign, or a joint turning the other way
        what = f"the axis of joint {k + 1} ({joint.name}) is reversed"
    if k == 0:
        rows = "the base pose" + ("" if robot.convention == "standard" else " or joint 1's a, alpha")
    elif robot.convention == "standard":
        before = robot.joints[k - 1]
        rows = f"joint {k}'s DH row ({before.name}: a, alpha, d, offset), which places it"
    else:
        before = robot.joints[k - 1]
        rows = (f"joint {k + 1}'s DH row ({joint.name}: a, alpha), or joint {k}'s ({before.name}: d, offset), "
                f"which place it")
    return f"{what}: check {rows}"
