"""Exact homogeneous transforms (sympy 4 x 4 matrices): the elementary rotations and
translations, a rigid transform's inverse, and the poses of robot files and URDFs (translation xyz, then Rz(yaw) Ry(pitch)
Rx(roll))."""

import sympy

from jacgen.inputs.robot import Pose

Matrix = sympy.Matrix


def rot_x(c, s) -> Matrix:
    return Matrix([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def rot_z(c, s) -> Matrix:
    return Matrix([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def translation(x, y, z) -> Matrix:
    return Matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def twist(d, a, alpha) -> Matrix:
    """Tz(d) Tx(a) Rx(alpha): a DH row's constant transform after its joint's rotation (the
    general 6R solver's C_i)."""
    return translation(0, 0, d) * translation(a, 0, 0) * rot_x(sympy.cos(alpha), sympy.sin(alpha))


def rigid_inverse(transform: Matrix) -> Matrix:
    """[R p; 0 1]^-1 = [R^T -R^T p; 0 1]."""
    rotation = transform[:3, :3].T
    return Matrix.vstack(Matrix.hstack(rotation, -rotation * transform[:3, 3]), Matrix([[0, 0, 0, 1]]))


def exact_trig(angle) -> tuple[sympy.Expr, sympy.Expr]:
    return sympy.cos(angle), sympy.sin(angle)


def xyz_rpy_transform(xyz, rpy, trig=exact_trig) -> Matrix:
    """Translation xyz, then Rz(yaw) Ry(pitch) Rx(roll) (robot files and URDF alike);
    `trig(angle)` gives (cos, sin)."""
    roll, pitch, yaw = rpy
    cp, sp = trig(pitch)
    rot_y = Matrix([[cp, 0, sp, 0], [0, 1, 0, 0], [-sp, 0, cp, 0], [0, 0, 0, 1]])
    return translation(*xyz) * rot_z(*trig(yaw)) * rot_y * rot_x(*trig(roll))


def pose_transform(pose: Pose) -> Matrix:
    """Exact transform of a base/tool pose."""
    return xyz_rpy_transform([v.exact for v in pose.xyz], [v.exact for v in pose.rpy])
