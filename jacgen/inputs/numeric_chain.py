"""The DH chain in floating point, for the few numbers production needs: the robot file's
checks, the configurations where a singularity factor vanishes and what they mean
(`singularities`), the general 6R solver's choice of cut, the drawings of `jacgen show`
(`drawing`) and its comparison with a URDF (`urdf_comparison`). Built from the closed-form
link matrices of the textbooks (Spong's standard, Craig's modified DH), apart from
`jacgen.checking.reference`, which multiplies elementary transforms and stays an independent
oracle that no production module imports.

Every function takes one configuration q (n,) or a batch (..., n).
"""

import numpy as np


def _stack(rows, shape) -> np.ndarray:
    """A (..., 4, 4) matrix from 16 entries, numbers or arrays of the batch `shape` (each
    entry written in place: a single configuration costs tens of microseconds, not milliseconds)."""
    matrix = np.empty((*shape, 4, 4))
    for i, row in enumerate(rows):
        for j, entry in enumerate(row):
            matrix[..., i, j] = entry
    return matrix


def standard_link(theta: np.ndarray, d, a: float, alpha: float) -> np.ndarray:
    """Rz(theta) Tz(d) Tx(a) Rx(alpha), Spong's standard DH link, at a batch of theta."""
    ca, sa, ct, st = np.cos(alpha), np.sin(alpha), np.cos(theta), np.sin(theta)
    rows = [[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st], [0, sa, ca, d], [0, 0, 0, 1]]
    return _stack(rows, np.shape(theta))


def _link(robot, joint, qi: np.ndarray) -> np.ndarray:
    """The link transform of one DH row at joint value qi."""
    theta = qi + joint.offset.approx if joint.revolute else np.full(qi.shape, joint.theta.approx)
    d = np.full(qi.shape, joint.d.approx) if joint.revolute else qi + joint.offset.approx
    if robot.convention == "standard":
        return standard_link(theta, d, joint.a.approx, joint.alpha.approx)
    a, ca, sa = joint.a.approx, np.cos(joint.alpha.approx), np.sin(joint.alpha.approx)
    ct, st = np.cos(theta), np.sin(theta)
    # Rx(alpha) Tx(a) Rz(theta) Tz(d)
    rows = [[ct, -st, 0, a], [st * ca, ct * ca, -sa, -d * sa], [st * sa, ct * sa, ca, d * ca], [0, 0, 0, 1]]
    return _stack(rows, qi.shape)


def fixed_pose(pose) -> np.ndarray:
    """A base or tool pose: translation xyz, rotation Rz(yaw) Ry(pitch) Rx(roll)."""
    (cr, cp, cy), (sr, sp, sy) = ([f(v.approx) for v in pose.rpy] for f in (np.cos, np.sin))
    x, y, z = (v.approx for v in pose.xyz)
    return _stack([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr, x],
                   [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr, y],
                   [-sp, cp * sr, cp * cr, z], [0, 0, 0, 1]], ())


def link_frames(robot, q) -> tuple[list[np.ndarray], np.ndarray]:
    """The world frames 0..n of the DH table (frame 0 the base, frame i after row i), and the
    tool's pose."""
    q = np.asarray(q, dtype=float)
    frames = [np.broadcast_to(fixed_pose(robot.base), (*q.shape[:-1], 4, 4))]
    for i, joint in enumerate(robot.joints):
        frames.append(frames[-1] @ _link(robot, joint, q[..., i]))
    return frames, frames[-1] @ fixed_pose(robot.tool)


def axis_frames(robot, q) -> tuple[list[np.ndarray], np.ndarray]:
    """The world frame of each joint whose z axis is the joint's axis, and the tool's pose."""
    frames, tool = link_frames(robot, q)
    if robot.convention == "standard":  # joint i turns about z of the frame before its row
        return frames[:-1], tool
    shape = np.shape(q)[:-1]  # modified: about z of the frame after the row's twist Rx(alpha) Tx(a)
    return [frame @ _twist(joint, shape) for frame, joint in zip(frames, robot.joints)], tool


def _twist(joint, shape) -> np.ndarray:
    """Rx(alpha) Tx(a): the part of a modified-DH row before its joint."""
    a, ca, sa = joint.a.approx, np.cos(joint.alpha.approx), np.sin(joint.alpha.approx)
    return _stack([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]], shape)


def jacobian(robot, q) -> np.ndarray:
    """The geometric Jacobian in the world frame (..., 6, n), rows vx vy vz wx wy wz."""
    frames, tool = axis_frames(robot, q)
    columns = []
    for joint, frame in zip(robot.joints, frames):
        z, origin = frame[..., :3, 2], frame[..., :3, 3]
        linear = _cross(z, tool[..., :3, 3] - origin) if joint.revolute else z
        columns.append(np.concatenate([linear, z if joint.revolute else np.zeros_like(z)], -1))
    return np.stack(columns, -1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of 3-vectors (..., 3): np.cross's arithmetic, without its per-call overhead."""
    (a1, a2, a3), (b1, b2, b3) = np.moveaxis(a, -1, 0), np.moveaxis(b, -1, 0)
    return np.stack([a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1], -1)
