"""Symbolic kinematics (contract §2): the DH chain, fk, geometric and task Jacobians.

The chain is built once over *trig atoms*: for the readable matrices the atoms are
`cos(q_i + offset_i)` and `sin(...)`; for code generation they are plain symbols `c_i`,
`s_i`, so the emitted code computes each sine and cosine once and common-subexpression
elimination keeps the link-to-link structure (cost linear in the number of joints).
"""

from dataclasses import dataclass
from functools import cached_property
from typing import Callable

import numpy
import sympy
from sympy.simplify.fu import TR10i

from jacgen.inputs import names
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.inputs.transforms import exact_trig, pose_transform, rot_x, rot_z, translation
from jacgen.model.graph import elementwise

Matrix = sympy.Matrix
CosSin = Callable[[int], tuple[sympy.Expr, sympy.Expr]]


def generated_symbol(prefix: str, *indices: int, separator: str = "_", real: bool | None = True) -> sympy.Symbol:
    """A symbol the generator makes up, named by `names.indexed`: q3, qb3_1, T03."""
    return sympy.Symbol(names.indexed(prefix, *indices, separator=separator), real=real)


def joint_symbols(robot: Robot) -> tuple[sympy.Symbol, ...]:
    return tuple(generated_symbol("q", i + 1) for i in range(robot.dof))


def trig_symbols(joints: tuple[int, ...], dof: int) -> tuple[sympy.Symbol, sympy.Symbol]:
    """The symbols of the cos and sin of a sum of joint angles (0-based joints of a `dof`-joint
    robot), named by `names.trig`: c2, s2 for joint 2, c23, s23 for joints 2 and 3."""
    return tuple(sympy.Symbol(name, real=True) for name in names.trig(joints, dof))


def link_transforms(robot: Robot, cos_sin: CosSin, q) -> list[tuple[Matrix, Matrix]]:
    """Per joint, (before, after): the link transform split at the joint's axis frame.

    Standard DH `Rz(theta) Tz(d) Tx(a) Rx(alpha)` moves about the axis at its start;
    modified DH `Rx(alpha) Tx(a) Rz(theta) Tz(d)` about the axis after `Rx Tx`.
    """
    links = []
    for i, joint in enumerate(robot.joints):
        c, s = cos_sin(i) if joint.revolute else exact_trig(joint.theta.exact)
        d = joint.d.exact if joint.revolute else q[i] + joint.offset.exact
        twist = rot_x(*exact_trig(joint.alpha.exact)) * translation(joint.a.exact, 0, 0)
        if robot.convention == "standard":
            links.append((sympy.eye(4), rot_z(c, s) * translation(0, 0, d) * twist))
        else:
            links.append((twist, rot_z(c, s) * translation(0, 0, d)))
    return links


@dataclass(frozen=True)
class Chain:
    """World poses of each joint's axis frame (z = joint axis) and of the tool, and the
    lever of each revolute axis: the vector from its origin to the tool origin."""

    axes: tuple[Matrix, ...]
    levers: tuple[Matrix | None, ...]  # None for a prismatic joint
    tool: Matrix


def angle_sum_products(a, b):
    """cos and sin of an angle sum from those of its two terms."""
    return a[0] * b[0] - a[1] * b[1], a[1] * b[0] + a[0] * b[1]


def _pose(rotation: Matrix, origin: Matrix) -> Matrix:
    return Matrix.vstack(Matrix.hstack(rotation, origin), Matrix([[0, 0, 0, 1]]))


def build_chain(robot: Robot, cos_sin: CosSin, q, simplify=lambda e: e, angle_sum=None) -> Chain:
    """Multiply out the DH chain, one rotation per run of parallel joint axes.

    A rotation about z is kept pending while the next axes stay parallel to it
    (alpha = 0), since Rz(a) Tz(d) Tx(b) Rz(c) = Tz(d) T(b cos a, b sin a, 0) Rz(a + c):
    the chain then multiplies one rotation for the run, with the cos and sin of the
    summed angle from `angle_sum(joints)` (default: the product formulas inline).

    Translations are added up in world coordinates into one step per stretch between two
    revolute joint axes. The lever of an axis (from its origin to the tool origin) is the sum of
    the steps after it, added up backwards from the tool, each lever the next one plus a
    step; the tool origin is the base origin plus every step. With `simplify` naming each
    sum, every lever costs three additions, not a sum over the rest of the chain.

    One walk down the chain in one function: the pending rotation, the translation steps and
    the levers are state of the same walk, and split apart they would be passed back and forth.
    """
    base = pose_transform(robot.base)
    rotation = base[:3, :3]  # the running frame's rotation, before the pending rotation
    origin, segment = base[:3, 3], sympy.zeros(3, 1)  # the last axis' origin; the translation since
    run: tuple[int, ...] = ()
    pending = (sympy.Integer(1), sympy.Integer(0))  # cos, sin of the pending rotation about z
    steps: list[Matrix] = []
    steps_before: list[int] = []  # per axis, the number of steps before its origin

    def flushed() -> Matrix:
        return (rotation * rot_z(*pending)[:3, :3]).applyfunc(simplify)

    def turn(i: int):
        nonlocal run, pending
        run += (i,)
        if len(run) == 1:
            pending = cos_sin(i)
        else:
            pending = angle_sum(run) if angle_sum else angle_sum_products(pending, cos_sin(i))

    def rotate(fixed: Matrix):  # flush the pending rotation, then turn by a constant one
        nonlocal rotation, run, pending
        rotation, run, pending = flushed() * fixed[:3, :3], (), (sympy.Integer(1), sympy.Integer(0))

    def shift(local: Matrix):  # Rz(pending) T(local) in the running frame
        nonlocal segment
        (x, y, z), (c, s) = local, pending
        segment = segment + rotation * Matrix([x * c - y * s, x * s + y * c, z])

    def close_segment():
        nonlocal origin, segment
        step = segment.applyfunc(simplify)
        if any(step):
            steps.append(step)
            origin = (origin + step).applyfunc(simplify)
        segment = sympy.zeros(3, 1)

    axes = []
    for i, joint in enumerate(robot.joints):
        d = joint.d.exact if joint.revolute else q[i] + joint.offset.exact
        if robot.convention == "modified":
            if joint.alpha.exact != 0:
                rotate(rot_x(*exact_trig(joint.alpha.exact)))
            shift(Matrix([joint.a.exact, 0, 0]))
        if joint.revolute:  # a prismatic column needs no lever: its translation joins the next step
            close_segment()
        axes.append(_pose(flushed(), (origin + segment).applyfunc(simplify)))
        steps_before.append(len(steps))
        if joint.revolute:
            turn(i)
        elif joint.theta.exact != 0:
            rotate(rot_z(*exact_trig(joint.theta.exact)))
        shift(Matrix([joint.a.exact if robot.convention == "standard" else 0, 0, d]))
        if robot.convention == "standard" and joint.alpha.exact != 0:
            rotate(rot_x(*exact_trig(joint.alpha.exact)))
    tool = pose_transform(robot.tool)
    shift(tool[:3, 3])
    rotate(tool)
    close_segment()
    tails = [sympy.zeros(3, 1)]  # tails[k]: the sum of the last k steps
    for step in reversed(steps):
        tails.append((tails[-1] + step).applyfunc(simplify))
    levers = [tails[len(steps) - before] if joint.revolute else None
              for before, joint in zip(steps_before, robot.joints)]
    position = (base[:3, 3] + tails[-1]).applyfunc(simplify)
    return Chain(tuple(axes), tuple(levers), _pose(rotation.applyfunc(simplify), position))


def column_jacobian(robot: Robot, chain: Chain) -> Matrix:
    """Geometric Jacobian in the world frame by the column formula of contract §2."""
    columns = []
    for joint, axis, lever in zip(robot.joints, chain.axes, chain.levers):
        z = axis[:3, 2]
        columns.append(Matrix.vstack(z.cross(lever), z) if joint.revolute else Matrix.vstack(z, sympy.zeros(3, 1)))
    return Matrix.hstack(*columns)


def angular_velocities(robot: Robot, axes: list, q_dot, name) -> list:
    """omega_i for i = 0..n: the angular velocity of the link that carries axis i (the sum of
    z_j qd_j over the revolute joints before i), the last one the tool's; each partial sum
    named once, so that every function reading them shares them."""
    omegas, omega = [], numpy.zeros(3, dtype=object)
    for joint, z, rate in zip(robot.joints, axes, q_dot):
        omegas.append(omega)
        if joint.revolute:
            omega = elementwise(name, omega + z * rate)
    return omegas + [omega]


def jacobian_dot(robot: Robot, axes: list, jacobian: numpy.ndarray, q_dot, name) -> numpy.ndarray:
    """dJ/dt of the world geometric Jacobian along q_dot, column by column from the chain's
    axes z_i (arrays of nodes, as J): z_i' = w_i x z_i and (p - o_i)' = w_i x (p - o_i) + S_i,
    where w_i is the angular velocity of the link carrying axis i and
    S_i = sum_{j >= i} Jv_j qd_j the velocity of the tool origin relative to that link. By the
    Jacobi identity a revolute column is then [w_i x Jv_i + z_i x S_i; w_i x z_i], a prismatic
    one [w_i x z_i; 0]. Prefix and suffix sums are named once, so each column costs O(1) on
    top of J."""
    n = robot.dof
    omegas = angular_velocities(robot, axes, q_dot, name)
    suffix, sums = numpy.zeros(3, dtype=object), [None] * n
    for i in reversed(range(n)):
        suffix = elementwise(name, suffix + jacobian[:3, i] * q_dot[i])
        sums[i] = suffix
    columns = []
    for i, joint in enumerate(robot.joints):
        z, omega = axes[i], omegas[i]
        turn = numpy.cross(omega, z)
        if joint.revolute:
            columns.append(numpy.concatenate([numpy.cross(omega, jacobian[:3, i]) + numpy.cross(z, sums[i]), turn]))
        else:
            columns.append(numpy.concatenate([turn, numpy.zeros(3, dtype=object)]))
    return numpy.stack(columns, axis=1)


def hessian(robot: Robot, jacobian: numpy.ndarray) -> list[numpy.ndarray]:
    """d J / d q_k for each k (6 x n each), from the columns of J alone: rotating about axis k
    turns every column after it (z_k x each half), and a joint k at or after a revolute
    column c moves the tool point, so c's linear part changes by z_c x Jv_k."""
    layers, zero = [], numpy.zeros(3, dtype=object)
    for k, moving in enumerate(robot.joints):
        columns = []
        for c, joint in enumerate(robot.joints):
            if k < c and moving.revolute:
                z_k = jacobian[3:, k]
                columns.append(numpy.concatenate([numpy.cross(z_k, jacobian[:3, c]), numpy.cross(z_k, jacobian[3:, c])]))
            elif k >= c and joint.revolute:
                columns.append(numpy.concatenate([numpy.cross(jacobian[3:, c], jacobian[:3, k]), zero]))
            else:
                columns.append(numpy.concatenate([zero, zero]))
        layers.append(numpy.stack(columns, axis=1))
    return layers


def tool_frame(jacobian: Matrix, pose: Matrix) -> Matrix:
    """The same twist expressed in the frame whose world pose is `pose`."""
    rotation_t = pose[:3, :3].T
    return Matrix.vstack(rotation_t * jacobian[:3, :], rotation_t * jacobian[3:, :])


def propagated_jacobian_tool(robot: Robot, cos_sin: CosSin, q) -> Matrix:
    """Tool-frame geometric Jacobian by link-to-link velocity propagation (Craig 5.7).

    Independent of the column formula: angular and linear velocity are carried from
    frame to frame in local coordinates, w' = R^T (w + qd z), v' = R^T (v + w x p) (+ dd z),
    and the Jacobian read off as the coefficients of the joint rates.
    """
    rates = tuple(generated_symbol("qd", i + 1) for i in range(robot.dof))
    z = Matrix([0, 0, 1])
    omega, velocity = sympy.zeros(3, 1), sympy.zeros(3, 1)  # of the base, in base coordinates

    def carry(transform: Matrix):
        rotation_t, offset = transform[:3, :3].T, transform[:3, 3]
        return rotation_t * omega, rotation_t * (velocity + omega.cross(offset))

    for joint, rate, (before, after) in zip(robot.joints, rates, link_transforms(robot, cos_sin, q)):
        omega, velocity = carry(before)
        if joint.revolute:
            omega = omega + rate * z
        else:
            velocity = velocity + rate * z
        omega, velocity = carry(after)
    omega, velocity = carry(pose_transform(robot.tool))
    return Matrix.vstack(velocity, omega).jacobian(rates)


def rpy_rates(rotation: Matrix, angular: Matrix) -> Matrix:
    """Rows d(roll, pitch, yaw)/dq from the angular-velocity rows, for R = Rz Ry Rx.

    omega = E(rpy) rpy_dot inverted with cos(pitch)^2 = R00^2 + R10^2; singular where
    cos(pitch) = 0 (the Euler-angle representation singularity).
    """
    r00, r10, r20 = rotation[0, 0], rotation[1, 0], rotation[2, 0]
    cos_pitch_sq = r00**2 + r10**2
    wx, wy, wz = angular[0, :], angular[1, :], angular[2, :]
    heading = (r00 * wx + r10 * wy) / cos_pitch_sq
    return Matrix.vstack(heading, (r00 * wy - r10 * wx) / sympy.sqrt(cos_pitch_sq), wz - r20 * heading)


def task_vector(robot: Robot, pose: Matrix) -> Matrix:
    """mu: the declared components of (x, y, z, roll, pitch, yaw) of the pose."""
    rotation = pose[:3, :3]
    full = list(pose[:3, 3]) + [
        sympy.atan2(rotation[2, 1], rotation[2, 2]),
        sympy.atan2(-rotation[2, 0], sympy.sqrt(rotation[0, 0] ** 2 + rotation[1, 0] ** 2)),
        sympy.atan2(rotation[1, 0], rotation[0, 0]),
    ]
    return Matrix([full[TASK_COMPONENTS.index(name)] for name in robot.task])


def task_jacobian(robot: Robot, pose: Matrix, jacobian: Matrix) -> Matrix:
    """d mu / d q: position rows of the geometric Jacobian, Euler-angle rates for the rest."""
    rates = rpy_rates(pose[:3, :3], jacobian[3:, :])
    rows = {name: jacobian[i, :] for i, name in enumerate(("x", "y", "z"))}
    rows.update({name: rates[i, :] for i, name in enumerate(("roll", "pitch", "yaw"))})
    return Matrix.vstack(*(rows[name] for name in robot.task))


def rpy_rate_partials(column, angular, name) -> tuple[numpy.ndarray, numpy.ndarray]:
    """The partial derivatives of `rpy_rates`' three rows by r, the first column of R, and by w,
    one column of angular rows (nodes), written out: with c = r0^2 + r1^2 and the heading rate
    h = (r0 wx + r1 wy) / c, the rows are h, (r0 wy - r1 wx) / sqrt(c) and wz - r2 h."""
    (r0, r1, r2), (wx, wy, _) = column, angular
    c = name(r0**2 + r1**2)
    root = name(c.graph.sqrt(c))
    heading = name((r0 * wx + r1 * wy) / c)
    pitch_over_c = name((r0 * wy - r1 * wx) / (c * root))
    dh = [(wx - 2 * r0 * heading) / c, (wy - 2 * r1 * heading) / c, 0]
    by_r = numpy.array([dh, [wy / root - r0 * pitch_over_c, -wx / root - r1 * pitch_over_c, 0],
                        [-r2 * dh[0], -r2 * dh[1], -heading]], dtype=object)
    by_w = numpy.array([[r0 / c, r1 / c, 0], [-r1 / root, r0 / root, 0], [-r2 * r0 / c, -r2 * r1 / c, 1]],
                       dtype=object)
    return by_r, by_w


def task_jacobian_dot(robot: Robot, pose: numpy.ndarray, jacobian: numpy.ndarray, jacobian_dot: numpy.ndarray,
                      q_dot, name) -> numpy.ndarray:
    """d/dt of task_jacobian (arrays of nodes): the position rows of J', and for the angles the
    Euler-angle rates differentiated through what they read, the first column r of R
    (r' = w x r with w = Jw q_dot, the tool's angular velocity, added up as jacobian_dot's
    partial sums are) and the angular rows of J (whose rate is that of J')."""
    column = pose[:3, 0]
    omega = angular_velocities(robot, list(jacobian[3:, :].T), q_dot, name)[-1]
    column_rate = elementwise(name, numpy.cross(omega, column))
    angle_rows = []
    for c in range(robot.dof):
        by_r, by_w = rpy_rate_partials(column, jacobian[3:, c], name)
        angle_rows.append(by_r @ column_rate + by_w @ jacobian_dot[3:, c])
    rates_dot = numpy.stack(angle_rows, axis=1)
    rows = {name_: jacobian_dot[i, :] for i, name_ in enumerate(("x", "y", "z"))}
    rows.update({name_: rates_dot[i, :] for i, name_ in enumerate(("roll", "pitch", "yaw"))})
    return numpy.stack([rows[component] for component in robot.task])


READABLE_TERMS = 64  # a sum with more terms stays expanded: TR10i's pairing grows with their square


def simplify_trig(expression: sympy.Expr) -> sympy.Expr:
    """Expand, then collapse sin/cos products of joint sums (c1 c2 - s1 s2 -> cos(q1 + q2)),
    for a sum of at most READABLE_TERMS terms (an arm with irrational twists, the Jaco's 60
    degrees, makes sums of hundreds: TR10i took minutes on one)."""
    expanded = sympy.expand(expression)
    return TR10i(expanded) if len(sympy.Add.make_args(expanded)) <= READABLE_TERMS else expanded


class Kinematics:
    """The readable symbolic matrices of a robot, in the joint variables q1..qn."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.q = joint_symbols(robot)
        offsets = [joint.offset.exact for joint in robot.joints]
        self.cos_sin = lambda i: exact_trig(self.q[i] + offsets[i])

    @cached_property
    def chain(self) -> Chain:
        angles = [self.q[i] + joint.offset.exact for i, joint in enumerate(self.robot.joints)]
        return build_chain(self.robot, self.cos_sin, self.q, simplify_trig,
                           angle_sum=lambda joints: exact_trig(sum(angles[i] for i in joints)))

    @cached_property
    def fk(self) -> Matrix:
        return self.chain.tool

    @cached_property
    def jacobian(self) -> Matrix:
        return column_jacobian(self.robot, self.chain).applyfunc(simplify_trig)

    @cached_property
    def jacobian_tool(self) -> Matrix:
        return propagated_jacobian_tool(self.robot, self.cos_sin, self.q).applyfunc(simplify_trig)

    @cached_property
    def task(self) -> Matrix:
        return task_vector(self.robot, self.fk)

    @cached_property
    def task_jacobian(self) -> Matrix:
        return task_jacobian(self.robot, self.fk, self.jacobian)
