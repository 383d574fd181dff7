"""Joint axes -> a Denavit-Hartenberg table, exactly (the frame rules are in docs/urdf.md).

Input: each moving joint's axis line at q = 0 (a point and the unit direction of positive
motion) and the tool frame at q = 0, all in the base link's frame. Every DH frame is fixed
to the link it belongs to and every joint turns (or slides) about its own z, so a table
that reproduces the chain at q = 0 reproduces it at every q.

Numbers stay in a small exact domain: rationals, a rational times sqrt(rational) and, for
angles, a rational times pi. Anything else becomes a 30-digit float, so every step costs
O(1) whatever the arm: no expression can grow.
"""

import math
from dataclasses import dataclass

import sympy
from sympy import Matrix

from jacgen.inputs.urdf import DIGITS, Snapper, inverse_transform

NOISE = 1e-25  # a 30-digit result below this is the rounding of a zero


@dataclass(frozen=True)
class Axis:
    """A moving joint: its axis line at q = 0 and its URDF name, kind and limit text."""

    name: str
    kind: str  # "revolute" | "prismatic"
    point: Matrix
    direction: Matrix
    limits: tuple[str, str] | None


@dataclass(frozen=True)
class Row:
    """One DH row (standard: a, alpha of this joint's normal; modified: of the previous one)."""

    axis: Axis
    a: sympy.Expr
    alpha: sympy.Expr
    d: sympy.Expr  # revolute: d; prismatic: the offset of d
    theta: sympy.Expr  # revolute: the offset of theta; prismatic: theta


@dataclass(frozen=True)
class Table:
    rows: tuple[Row, ...]
    base: tuple[tuple, tuple]  # (xyz, rpy)
    tool: tuple[tuple, tuple]


def exact_or_float(x) -> sympy.Expr:
    """x, kept exact inside the exact domain, else as a 30-digit float (tiny ones: zero)."""
    x = sympy.sympify(x)
    if x.is_Rational or (not x.has(sympy.Float) and _simple(x)):
        return x
    value = sympy.Float(x.evalf(DIGITS), DIGITS)
    return sympy.Integer(0) if abs(value) < NOISE else value


def _simple(x: sympy.Expr) -> bool:
    coefficient, rest = x.as_coeff_Mul()
    return coefficient.is_Rational and (rest is sympy.pi or (rest.is_Pow and rest.exp == sympy.S.Half
                                                             and rest.base.is_Rational))


def dot(u: Matrix, v: Matrix) -> sympy.Expr:
    return exact_or_float(sum(a * b for a, b in zip(u, v)))


def cross(u: Matrix, v: Matrix) -> Matrix:
    return u.cross(v).applyfunc(exact_or_float)


def unit(v: Matrix) -> Matrix:
    return (v / sympy.sqrt(dot(v, v))).applyfunc(exact_or_float)


def is_zero_vector(v: Matrix) -> bool:
    return all(exact_or_float(e) == 0 for e in v)


class _Fit:
    def __init__(self, snapper: Snapper):
        self.snapper = snapper

    def angle(self, y, x) -> sympy.Expr:
        """atan2(y, x), exactly k*pi/2 when nearly so (robot files snap such angles anyway)."""
        value = exact_or_float(sympy.atan2(y, x))
        return self.snapper.angle(value) if value.has(sympy.Float) else value

    def parallel(self, z: Matrix, w: Matrix) -> bool:
        """Parallel exactly, or (30-digit directions) within the snapper's tolerance."""
        sine = cross(z, w)
        if any(e.has(sympy.Float) for e in sine):
            return self.snapper.close(math.sqrt(sum(float(e) ** 2 for e in sine)))
        return is_zero_vector(sine)

    def rpy(self, rotation: Matrix) -> tuple:
        """(roll, pitch, yaw) with R = Rz(yaw) Ry(pitch) Rx(roll); roll = 0 at pitch = +-90 deg."""
        pitch = self.angle(-rotation[2, 0], sympy.sqrt(dot(rotation[:2, 0], rotation[:2, 0])))
        if sympy.cos(pitch) == 0 or exact_or_float(sympy.cos(pitch)) == 0:
            return (sympy.Integer(0), pitch, self.angle(-rotation[0, 1], rotation[1, 1]))
        return (self.angle(rotation[2, 1], rotation[2, 2]), pitch, self.angle(rotation[1, 0], rotation[0, 0]))

    def pose(self, frame: Matrix) -> tuple[tuple, tuple]:
        return tuple(exact_or_float(e) for e in frame[:3, 3]), self.rpy(frame[:3, :3])


def _foot(point: Matrix, axis: Axis) -> Matrix:
    """The point of the axis line nearest `point`."""
    return (axis.point + dot(point - axis.point, axis.direction) * axis.direction).applyfunc(exact_or_float)


def _placed(axes: list[Axis], tip: Matrix, fitting: "_Fit") -> list[Axis]:
    """The axes, each prismatic one moved (it may be: only its direction matters) to pass
    through the next axis, or through the tool origin when it is last: a = 0 there."""
    placed = list(axes)
    for i in reversed(range(len(axes))):
        axis = placed[i]
        if axis.kind != "prismatic":
            continue
        if i == len(axes) - 1:
            point = tip[:3, 3]
        else:
            after = placed[i + 1]
            point = after.point if fitting.parallel(axis.direction, after.direction) else _closest_points(axis, after)[1]
        placed[i] = Axis(axis.name, axis.kind, point, axis.direction, axis.limits)
    return placed


def _closest_points(here: Axis, there: Axis) -> tuple[Matrix, Matrix]:
    """The points of two axis lines that are not parallel nearest each other: the feet of
    their common normal on `here` and on `there`."""
    r = (there.point - here.point).applyfunc(exact_or_float)
    b, d1, d2 = dot(here.direction, there.direction), dot(here.direction, r), dot(there.direction, r)
    s, t = exact_or_float((d1 - b * d2) / (1 - b * b)), exact_or_float((b * d1 - d2) / (1 - b * b))
    return (here.point + s * here.direction).applyfunc(exact_or_float), (there.point + t * there.direction).applyfunc(exact_or_float)


def _oriented(x: Matrix, previous: Matrix, z: Matrix) -> Matrix:
    """x or -x, whichever lies within (-90, 90] degrees of `previous` about z."""
    along = dot(x, previous)
    flip = dot(cross(previous, x), z) < 0 if along == 0 else along < 0
    return -x if flip else x


def _frame(origin: Matrix, x: Matrix, z: Matrix) -> Matrix:
    frame = sympy.eye(4)
    frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = x, cross(z, x), z, origin
    return frame


def fit(axes: list[Axis], tip: Matrix, convention: str, snapper: Snapper) -> Table:
    """The DH table of the chain of `axes` whose tool frame at q = 0 is `tip`."""
    fitting = _Fit(snapper)
    axes = _placed(axes, tip, fitting)
    n = len(axes)
    first = axes[0]
    origin = _foot(sympy.zeros(3, 1), first)  # frame 0: on axis 1, at the foot of the base origin
    reference = next(unit(v) for v in (e - dot(e, first.direction) * first.direction
                                       for e in (sympy.eye(3)[:, k] for k in range(3))) if not is_zero_vector(v))
    # The common normal of axes i and i + 1: its feet on each and its direction x_i.
    feet, x = [(origin, origin)], [reference]
    for here, there in zip(axes, axes[1:]):
        previous_foot, previous_x = feet[-1][1], x[-1]
        if fitting.parallel(here.direction, there.direction):
            start, end = previous_foot, _foot(previous_foot, there)  # the normal through the last foot: d_i = 0
            between = (end - start).applyfunc(exact_or_float)
            direction = previous_x if is_zero_vector(between) else unit(between)
        else:
            start, end = _closest_points(here, there)
            direction = unit(cross(here.direction, there.direction))
        feet.append((start, end))
        x.append(_oriented(direction, previous_x, here.direction))
    if n > 1:
        x[0] = x[1]  # theta_1's offset 0: the base frame takes the rotation
    last = axes[-1]
    end = _foot(tip[:3, 3], last)  # frame n: on axis n, at the foot of the tool origin
    feet.append((end, end))
    x.append(x[-1])

    rows = []
    for i, axis in enumerate(axes, start=1):
        z = axis.direction
        theta = fitting.angle(dot(cross(x[i - 1], x[i]), z), dot(x[i - 1], x[i]))
        d = dot(feet[i][0] - feet[i - 1][1], z)
        j = i if convention == "standard" else i - 1  # the normal this row carries
        if 1 <= j < n:
            a = dot(feet[j][1] - feet[j][0], x[j])
            alpha = fitting.angle(dot(cross(axes[j - 1].direction, axes[j].direction), x[j]),
                                  dot(axes[j - 1].direction, axes[j].direction))
        else:
            a = alpha = sympy.Integer(0)
        rows.append(Row(axis, a, alpha, d, theta))
    base = _frame(origin, x[0], first.direction)
    tool = inverse_transform(_frame(end, x[n], last.direction)) * tip
    return Table(tuple(rows), fitting.pose(base), fitting.pose(tool.applyfunc(exact_or_float)))
