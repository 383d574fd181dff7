"""The checks of inverse kinematics, from jacgen.reference and numpy alone: where an arm is
regular, how far a reached target is from its target, joint distances modulo 2 pi, and the
Jacobian Js that velocity_ik inverts."""

import re

import numpy as np

from jacgen.checking import reference
from jacgen.inputs.robot import EULER_ANGLES as EULER
from jacgen.inputs.robot_file import parse_robot


def wrapped(angles):
    """Angles (or differences of angles) wrapped into [-pi, pi)."""
    return (angles + np.pi) % (2 * np.pi) - np.pi


def wrapped_distance(arm, a, b):
    """Largest joint difference between configurations a and b (broadcast), revolute joints
    modulo 2 pi."""
    difference = np.abs(np.asarray(a, dtype=float) - b)
    revolute = [joint.revolute for joint in arm.joints]
    difference[..., revolute] = np.abs(wrapped(difference[..., revolute]))
    return difference.max(axis=-1)


def target_error(arm, reached, target):
    """Per row of `reached` (poses (k, 4, 4) or task vectors (k, m)): its largest difference
    from `target`, the angles of a task vector compared modulo 2 pi."""
    difference = np.abs(reached - target)
    if len(arm.task) < 6:
        angles = [i for i, name in enumerate(arm.task) if name in EULER]
        difference[..., angles] = np.abs(wrapped(difference[..., angles]))
    return difference.reshape(len(difference), -1).max(axis=1) if difference.size else np.zeros(0)


def regular(arm, q, free=None):
    """Whether the arm is well conditioned at q (one configuration, or a batch (k, n)): the
    smallest singular value of the reference Jacobian (geometric for a pose task, else the task
    Jacobian; without the column of the `free` joint, an input of ik) above 1e-3."""
    jacobian = (reference.jacobian if len(arm.task) == 6 else reference.task_jacobian)(arm, q)
    if free is not None:
        jacobian = np.delete(jacobian, free, axis=-1)
    return np.linalg.svd(jacobian, compute_uv=False).min(axis=-1) > 1e-3


def reference_js(arm, q):
    """Js from jacgen.reference's geometric Jacobian alone: its rows of the task, or, when the
    task has some Euler angles, the ZYX Euler-angle rates omega = E(roll, pitch, yaw) rpy_dot
    solved for rpy_dot."""
    J = reference.jacobian(arm, q)
    angles = [c for c in arm.task if c in EULER]
    if len(angles) in (0, 3):
        return J[[("x", "y", "z", "roll", "pitch", "yaw").index(c) for c in arm.task]]
    _, pitch, yaw = reference.rpy(reference.fk(arm, q)[:3, :3])
    E = np.array([[np.cos(yaw) * np.cos(pitch), -np.sin(yaw), 0],
                  [np.sin(yaw) * np.cos(pitch), np.cos(yaw), 0],
                  [-np.sin(pitch), 0, 1]])
    rates = np.linalg.solve(E, J[3:])
    rows = {"x": J[0], "y": J[1], "z": J[2], "roll": rates[0], "pitch": rates[1], "yaw": rates[2]}
    return np.array([rows[c] for c in arm.task])


def without_limits(arm):
    """The arm read from its file with every `limits: [...]` removed (for the ik's branches
    alone: every solution, none dropped by the limits)."""
    text = re.sub(r",\s*limits: \[[^]]*\]", "", open(arm.source).read())
    return parse_robot(text.encode(), arm.source)


def kinematic_chain(arm):
    """The arm as EAIK and ik-geo take it, from jacgen.reference at q = 0: axes H, offsets P
    between points on consecutive axes, and the tool rotation (theirs is the identity at q = 0).
    When axes 4, 5, 6 meet, their points are moved to the common point (ik-geo needs that)."""
    frames, tool = reference.frames(arm, np.zeros(arm.dof))
    points = [frame[:3, 3] for frame in frames]
    H = np.array([frame[:3, 2] for frame in frames])
    projections = [np.eye(3) - np.outer(h, h) for h in H[3:]]
    centre = np.linalg.lstsq(np.vstack(projections), np.concatenate(
        [m @ p for m, p in zip(projections, points[3:])]), rcond=None)[0]
    if all(np.linalg.norm(m @ (centre - p)) < 1e-12 for m, p in zip(projections, points[3:])):
        points[3:] = [centre] * 3
    P = np.array([points[0]] + [b - a for a, b in zip(points, points[1:])] + [tool[:3, 3] - points[-1]])
    return H, P, tool[:3, :3]
