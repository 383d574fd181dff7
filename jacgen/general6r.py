"""General 6R inverse kinematics, the per-robot part: Raghavan & Roth's 14 equations
(Raghavan & Roth 1993; Manocha & Canny 1994), derived for one robot.

A 6-joint revolute DH chain is `head Z1 C1 Z2 C2 ... Z5 C5 Z6 tail`, with Z_i = Rz(theta_i),
theta_i = q_i + offset_i, and C_i = Tz(d_i) Tx(a_i) Rx(alpha_i) constant. A standard table
is that form as it is (head = base, tail = Tz(d6) Tx(a6) Rx(alpha6) tool); a modified one is
regrouped into it (head = base Rx(alpha_0) Tx(a_0), C_i from row i's d and row i+1's a and
alpha, tail = Tz(d6) tool). For a target T, with N = head^-1 T tail^-1:

    Z3 C3 Z4 C4 Z5 C5 Z6 = C2^-1 Z2^-1 C1^-1 Z1^-1 N.

Z6 leaves the third and fourth columns of the left side alone: an axis l and a point p that
depend on theta3, theta4, theta5, equal to those of the right side, which depend on theta1,
theta2 and N. With p.p, p.l, p x l and (p.p) l - 2 (p.l) p these are 14 equations

    (P0 + s3 Ps + c3 Pc) v45 = Q v12,
    v45 = (s4 s5, s4 c5, c4 s5, c4 c5, s4, c4, s5, c5, 1),
    v12 = (s1 s2, s1 c2, c1 s2, c1 c2, s1, c1, s2, c2),

where Q and the last column of P0 are polynomials (degree 3 at most) in N's third column n and
fourth column m, and the rest of P0, Ps, Pc are constants of the robot. This module derives
them by sparse polynomial arithmetic over 200-bit floats (a few thousand terms: milliseconds),
reducing s^2 = 1 - c^2 for every joint; the twists' cosines and sines enter as 60-digit numbers,
as in the structure stage, and what cancels between them (below 1e-40) is dropped.
"""

from dataclasses import dataclass

import sympy
from sympy.polys.domains import RealField
from sympy.polys.rings import ring

from . import kinematics
from .analysis import circle_reduced
from .robot import Robot

PRECISION = 60  # digits of the twists' cosines and sines
NEGLIGIBLE = 1e-40  # a coefficient below this is a cancellation left by those digits
GENERATORS = "s1 c1 s2 c2 s3 c3 s4 c4 s5 c5 n0 n1 n2 m0 m1 m2"


@dataclass(frozen=True)
class Link:
    """C_i = Tz(d) Tx(a) Rx(alpha): the constant transform after joint i's rotation."""

    d: sympy.Expr
    a: sympy.Expr
    alpha: sympy.Expr


@dataclass(frozen=True)
class Equations:
    """(p0 + s3 ps + c3 pc) v45 = q v12, over the symbols n (N's third column) and m (fourth)."""

    p0: sympy.Matrix  # 14 x 9
    ps: sympy.Matrix  # 14 x 9
    pc: sympy.Matrix  # 14 x 9
    q: sympy.Matrix  # 14 x 8
    n: tuple[sympy.Symbol, ...]
    m: tuple[sympy.Symbol, ...]


def chain_form(robot: Robot) -> tuple[sympy.Matrix, list[Link], sympy.Matrix]:
    """(head, [C1 .. C5], tail) of a 6R robot: its chain is head Z1 C1 ... Z5 C5 Z6 tail."""
    if robot.dof != 6 or not all(joint.revolute for joint in robot.joints):
        raise ValueError(f"{robot.name}: the general 6R solver needs six revolute joints")
    if robot.symbolic_parameters:
        raise ValueError(f"{robot.name}: the general 6R solver needs numeric DH parameters")
    joints = robot.joints
    base, tool = kinematics.pose_transform(robot.base), kinematics.pose_transform(robot.tool)

    def step(d, a, alpha) -> sympy.Matrix:
        return (kinematics.translation(0, 0, d) * kinematics.translation(a, 0, 0)
                * kinematics.rot_x(sympy.cos(alpha), sympy.sin(alpha)))

    if robot.convention == "standard":
        links = [Link(j.d.exact, j.a.exact, j.alpha.exact) for j in joints[:5]]
        last = joints[5]
        return base, links, step(last.d.exact, last.a.exact, last.alpha.exact) * tool
    first = joints[0]
    head = base * step(0, first.a.exact, first.alpha.exact)
    links = [Link(joints[i].d.exact, joints[i + 1].a.exact, joints[i + 1].alpha.exact) for i in range(5)]
    return head, links, kinematics.translation(0, 0, joints[5].d.exact) * tool


def equations(links: list[Link]) -> Equations:
    """Raghavan & Roth's 14 equations of the chain C1 .. C5 (see the module docstring)."""
    field = RealField(PRECISION * 4)
    polynomials, *generators = ring(GENERATORS, field)
    s1, c1, s2, c2, s3, c3, s4, c4, s5, c5, n0, n1, n2, m0, m1, m2 = generators
    sines, cosines = (s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5)
    number = lambda value: field(sympy.N(value, PRECISION))  # noqa: E731
    d = [number(link.d) for link in links]
    a = [number(link.a) for link in links]
    ca = [number(sympy.cos(link.alpha)) for link in links]
    sa = [number(sympy.sin(link.alpha)) for link in links]
    zero, one = polynomials.zero, polynomials.one

    def rot_z(i, v, sign=1):
        return [cosines[i] * v[0] - sign * sines[i] * v[1], sign * sines[i] * v[0] + cosines[i] * v[1], v[2]]

    def rot_x(i, v, sign=1):
        return [v[0], ca[i] * v[1] - sign * sa[i] * v[2], sign * sa[i] * v[1] + ca[i] * v[2]]

    # Left: Z3 C3 Z4 C4 Z5 C5 applied to the axis (0, 0, 1) and to the origin.
    axis, point = rot_x(4, [zero, zero, one]), [one * a[4], zero, one * d[4]]
    axis, point = rot_z(4, axis), rot_z(4, point)
    for i in (3, 2):
        axis, point = rot_x(i, axis), rot_x(i, point)
        point[0] += a[i]
        axis, point = rot_z(i, axis), rot_z(i, point)
        point[2] += d[i]
    # Right: C2^-1 Z2^-1 C1^-1 Z1^-1 applied to n (an axis) and m (a point).
    target_axis, target_point = [n0, n1, n2], [m0, m1, m2]
    for i in (0, 1):
        target_axis = rot_x(i, rot_z(i, target_axis, -1), -1)
        target_point = rot_z(i, target_point, -1)
        target_point[2] -= d[i]
        target_point[0] -= a[i]
        target_point = rot_x(i, target_point, -1)
    left = [_reduced(e) for e in _fourteen(axis, point)]
    right = [_reduced(e) for e in _fourteen(target_axis, target_point)]
    return _matrices(left, right)


def _fourteen(axis: list, point: list) -> list:
    """l, p, p.p, p.l, p x l, (p.p) l - 2 (p.l) p."""
    pp = sum(x * x for x in point)
    pl = sum(x * y for x, y in zip(point, axis))
    cross = [point[1] * axis[2] - point[2] * axis[1], point[2] * axis[0] - point[0] * axis[2],
             point[0] * axis[1] - point[1] * axis[0]]
    return [*axis, *point, pp, pl, *cross, *(pp * l - 2 * pl * p for l, p in zip(axis, point))]


def _reduced(polynomial) -> dict[tuple[int, ...], object]:
    """The terms of `polynomial` with s_i^2 = 1 - c_i^2 for every joint, cancellations below
    NEGLIGIBLE dropped."""
    terms = dict(polynomial)
    for sine in range(0, 10, 2):
        terms = circle_reduced(terms, sine, sine + 1)
    return {monomial: coefficient for monomial, coefficient in terms.items() if abs(coefficient) > NEGLIGIBLE}


# Exponents of (s_a, c_a, s_b, c_b) of the products in v45 (a, b = 4, 5) and v12 (a, b = 1, 2).
PRODUCTS = ((1, 0, 1, 0), (1, 0, 0, 1), (0, 1, 1, 0), (0, 1, 0, 1), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0),
            (0, 0, 0, 1), (0, 0, 0, 0))


def _matrices(left: list[dict], right: list[dict]) -> Equations:
    symbols = sympy.symbols(GENERATORS, real=True)
    n, m = symbols[10:13], symbols[13:16]
    p = [sympy.zeros(14, 9) for _ in range(3)]  # constant, s3, c3
    q = sympy.zeros(14, 8)
    for row, (lhs, rhs) in enumerate(zip(left, right)):
        for monomial, coefficient in lhs.items():
            if any(monomial[:4]) or any(monomial[10:]) or monomial[4] + monomial[5] > 1:
                raise ValueError(f"left side of equation {row} outside the products of Raghavan-Roth: {monomial}")
            part = 1 if monomial[4] else 2 if monomial[5] else 0
            p[part][row, PRODUCTS.index(monomial[6:10])] += sympy.Float(coefficient, PRECISION)
        for monomial, coefficient in rhs.items():
            if any(monomial[4:10]):
                raise ValueError(f"right side of equation {row} reads joints 3 to 6: {monomial}")
            target = sympy.Mul(*(s**e for s, e in zip(symbols[10:], monomial[10:])))
            value = sympy.Float(coefficient, PRECISION) * target
            column = PRODUCTS.index(monomial[:4])
            if column == 8:  # the constant goes to the left side
                p[0][row, 8] -= value
            else:
                q[row, column] += value
    return Equations(*p, q, n, m)
