"""A Pinocchio model of a robot's DH table (test code, sharing nothing with jacgen's
kinematics), and the seeded configurations of each shipped robot compared on it
(tests/test_external_libraries.py, tests/test_second_order.py)."""

import math
import zlib
from functools import lru_cache
from pathlib import Path

import numpy as np
import pinocchio as pin

from jacgen.inputs.robot_file import load_robot

ROBOTS = Path(__file__).resolve().parents[2] / "robots"
SAMPLES = 200


def rot_x(angle):
    return pin.SE3(pin.utils.rotate("x", angle), np.zeros(3))


def rot_z(angle):
    return pin.SE3(pin.utils.rotate("z", angle), np.zeros(3))


def translation(x, y, z):
    return pin.SE3(np.eye(3), np.array([x, y, z], dtype=float))


def placement_of(pose):
    """The SE3 of a robot file's pose (xyz, rpy: Rz(yaw) Ry(pitch) Rx(roll))."""
    roll, pitch, yaw = (v.approx for v in pose.rpy)
    rotation = pin.utils.rotate("z", yaw) @ pin.utils.rotate("y", pitch) @ pin.utils.rotate("x", roll)
    return pin.SE3(rotation, np.array([v.approx for v in pose.xyz]))


def pinocchio_from_dh(robot):
    """A Pinocchio chain for a DH table: joint i is RZ/PZ about the axis frame of row i.

    theta = q + offset (revolute) and d = q + offset (prismatic) commute with the joint's own
    motion along/about z, so every row splits into `before * motion(q) * after`:
    standard  Rz(theta) Tz(d) Tx(a) Rx(alpha): before = 1,           after = Rz(t0) Tz(d0) Tx(a) Rx(alpha)
    modified  Rx(alpha) Tx(a) Rz(theta) Tz(d): before = Rx(alpha) Tx(a), after = Rz(t0) Tz(d0)
    with (t0, d0) = (offset, d) for a revolute and (theta, offset) for a prismatic joint. The
    placement of joint i in joint i-1 is after_{i-1} * before_i (after_0 = the base), the link
    frame base A_1 ... A_i (frame `link_i`) sits at after_i on joint i, and the tool frame at
    after_n * tool on the last joint.
    """
    model = pin.Model()
    parent, placement = 0, placement_of(robot.base)
    for joint in robot.joints:
        a, alpha = joint.a.approx, joint.alpha.approx
        if joint.revolute:
            theta0, d0, motion = joint.offset.approx, joint.d.approx, pin.JointModelRZ()
        else:
            theta0, d0, motion = joint.theta.approx, joint.offset.approx, pin.JointModelPZ()
        if robot.convention == "modified":
            placement = placement * rot_x(alpha) * translation(a, 0, 0)
        parent = model.addJoint(parent, motion, placement, joint.name)
        placement = rot_z(theta0) * translation(0, 0, d0)
        if robot.convention == "standard":
            placement = placement * translation(a, 0, 0) * rot_x(alpha)
        model.addFrame(pin.Frame(f"link_{parent}", parent, placement, pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("tool", parent, placement * placement_of(robot.tool), pin.FrameType.OP_FRAME))
    return model


@lru_cache(maxsize=None)
def robot_of(name):
    return load_robot(ROBOTS / f"{name}.yaml")


@lru_cache(maxsize=None)
def samples(name):
    """SAMPLES configurations uniform within the joint limits (+-pi where there are none)."""
    robot = robot_of(name)
    limits = np.array([joint.limits if joint.limits is not None else (-math.pi, math.pi) for joint in robot.joints])
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    return limits[:, 0] + (limits[:, 1] - limits[:, 0]) * rng.random((SAMPLES, robot.dof))
