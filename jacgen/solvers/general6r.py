"""General 6R inverse kinematics, the per-robot part: Raghavan & Roth's 14 equations
(Raghavan & Roth 1993; Manocha & Canny 1994), derived for one robot and one way of cutting
its loop.

A 6-joint revolute DH chain is `head Z1 C1 Z2 C2 ... Z5 C5 Z6 tail`, with Z_i = Rz(theta_i),
theta_i = q_i + offset_i, and C_i = Tz(d_i) Tx(a_i) Rx(alpha_i) constant. A standard table
is that form as it is (head = base, tail = Tz(d6) Tx(a6) Rx(alpha6) tool); a modified one is
regrouped into it (head = base Rx(alpha_0) Tx(a_0), C_i from row i's d and row i+1's a and
alpha, tail = Tz(d6) tool). For a target T, N = head^-1 T tail^-1 closes it into a loop

    Z0 L0 Z1 L1 Z2 L2 Z3 L3 Z4 L4 Z5 L5 = I,   L0..L4 = C1..C5, L5 = N^-1

(loop positions from 0), or, read backwards, the loop of the joints 6..1 with their angles
negated and the links inverted (L5 = N). A split cuts the loop at a free joint f: with
a, b, c the three positions before it and g, h the two after,

    Z_a L_a Z_b L_b Z_c L_c Z_f = L_h^-1 Z_h^-1 L_g^-1 Z_g^-1 L_f^-1.

Z_f leaves the third and fourth columns of the left side alone: an axis l and a point p.
With p.p, p.l, p x l and (p.p) l - 2 (p.l) p these are 14 equations

    (P0 + s_a Ps + c_a Pc) v_bc = Q v_gh,
    v_bc = (s_b s_c, s_b c_c, c_b s_c, c_b c_c, s_b, c_b, s_c, c_c, 1),
    v_gh = (s_g s_h, s_g c_h, c_g s_h, c_g c_h, s_g, c_g, s_h, c_h),

whose entries are polynomials in the entries of V, the target's link as it appears in the
split (N or N^-1): the side that holds it is G V H, and its products are taken through V's
rotation (|V x| = |x|, V x . V y = x . y) so that no orthogonality of V is needed. This module
derives them by sparse polynomial arithmetic over 200-bit floats (milliseconds), reducing
s^2 = 1 - c^2 for every joint; the twists' cosines and sines enter as 60-digit numbers, as in
the structure stage, and what cancels between them (below 1e-40) is dropped.
"""

import math
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
import sympy
from sympy.polys.domains import RealField
from sympy.polys.rings import ring

from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import Robot
from jacgen.inputs.transforms import pose_transform, translation, twist
from jacgen.model import kinematics
from jacgen.model.joint_ring import circle_reduced

PRECISION = 60  # digits of the twists' cosines and sines
NEGLIGIBLE = 1e-40  # a coefficient below this is a cancellation left by those digits
TARGET = ("r00 r01 r02 r10 r11 r12 r20 r21 r22", "t0 t1 t2")  # V's rotation and translation
GENERATORS = " ".join(f"s{k} c{k}" for k in range(6)) + " " + " ".join(TARGET)


@dataclass(frozen=True)
class Link:
    """C_i = Tz(d) Tx(a) Rx(alpha): the constant transform after joint i's rotation."""

    d: sympy.Expr
    a: sympy.Expr
    alpha: sympy.Expr


@dataclass(frozen=True)
class Split:
    """A cut of the loop: read backwards or not, and the loop position of the free joint."""

    backwards: bool
    free: int

    @property
    def hidden(self) -> int:
        """a: the loop position whose tan(theta / 2) the eigenproblem finds."""
        return (self.free - 3) % 6

    @property
    def triple(self) -> tuple[int, int, int]:
        return tuple((self.free + k) % 6 for k in (-3, -2, -1))

    @property
    def pair(self) -> tuple[int, int]:
        return (self.free + 1) % 6, (self.free + 2) % 6

    def joint(self, position: int) -> int:
        """The robot joint (0-based) at a loop position."""
        return 5 - position if self.backwards else position

    @property
    def target_inverted(self) -> bool:
        """Whether V is N^-1 (else N): L5 on the left side, L5^-1 on the right."""
        on_left = 5 in self.triple
        return on_left != self.backwards

    def text(self, joints: tuple[int, ...] = tuple(range(6))) -> str:
        """The order in which the solver finds the joints, named as the robot's (`joints`: the
        robot's joint of each of the chain's six)."""
        def names(positions) -> str:
            return ", ".join(f"q{joints[self.joint(p)] + 1}" for p in positions)
        return (f"tan({names((self.hidden,))}/2) from the eigenproblem, then {names(self.triple[1:])}, "
                f"{names(self.pair)} and {names((self.free,))}")


SPLITS = tuple(Split(backwards, free) for backwards in (False, True) for free in range(6))


@dataclass(frozen=True)
class Equations:
    """(p0 + s_a ps + c_a pc) v_bc = q v_gh, over the symbols of V's rotation and translation,
    as terms: (matrix: 0 p0, 1 ps, 2 pc, 3 q; its flat entry; V's exponents; coefficient). The
    rating of a split reads them as numbers (`evaluated`); the sympy matrices are built for the
    chosen split alone (`matrices`)."""

    split: Split
    terms: tuple[tuple[int, int, tuple[int, ...], object], ...]

    @cached_property
    def _arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The terms' exponents and coefficients, sorted by the entry they add to; each entry
        that has terms, and where its terms start."""
        matrix, entry, exponents, coefficients = zip(*self.terms)
        entries = np.array(matrix) * 14 * 9 + np.array(entry)
        order = np.argsort(entries, kind="stable")
        present, starts = np.unique(entries[order], return_index=True)
        return (np.array(exponents, dtype=float)[order], np.array([float(c) for c in coefficients])[order], present,
                starts)

    def evaluated(self, targets: np.ndarray) -> np.ndarray:
        """p0, ps, pc, q at a batch of V's (..., 12: rotation by rows, then translation), as an
        array (..., 4, 14, 9) (q's last column zero)."""
        exponents, coefficients, present, starts = self._arrays
        values = coefficients * np.prod(targets[..., None, :] ** exponents, axis=-1)
        out = np.zeros((*targets.shape[:-1], 4 * 14 * 9))
        out[..., present] = np.add.reduceat(values, starts, axis=-1)  # each entry's terms summed
        return out.reshape(*targets.shape[:-1], 4, 14, 9)

    @cached_property
    def matrices(self) -> tuple[sympy.Matrix, sympy.Matrix, sympy.Matrix, sympy.Matrix]:
        """p0, ps, pc (14 x 9) and q (14 x 8) over `rotation` and `translation`."""
        target = sympy.symbols(GENERATORS, real=True)[12:]
        matrices = [sympy.zeros(14, 9) for _ in range(4)]
        for matrix, entry, exponents, coefficient in self.terms:
            matrices[matrix][entry] += sympy.Float(coefficient, PRECISION) * _monomial(target, exponents)
        return (*matrices[:3], matrices[3][:, :8])

    @property
    def rotation(self) -> sympy.Matrix:
        return sympy.Matrix(3, 3, sympy.symbols(GENERATORS, real=True)[12:21])

    @property
    def translation(self) -> sympy.Matrix:
        return sympy.Matrix(sympy.symbols(GENERATORS, real=True)[21:])


def chain_form(robot: Robot, free: int | None = None) -> tuple[sympy.Matrix, list[Link], sympy.Matrix]:
    """(head, [C1 .. C5], tail) of a 6R robot, or of a 7R robot's six joints other than `free`
    (its first or last joint, an input of ik): the chain is head Z1 C1 ... Z5 C5 Z6 tail, and the
    free joint's row, at the cos and sin symbols of its angle, is part of the head or the tail."""
    if not all(joint.revolute for joint in robot.joints) or robot.dof - (free is not None) != 6 \
            or free not in (None, 0, robot.dof - 1):
        raise ValueError(f"{robot.name}: the general 6R solver needs six revolute joints (and a 7th free, first or last)")
    if robot.symbolic_parameters:
        raise ValueError(f"{robot.name}: the general 6R solver needs numeric DH parameters")
    base, tool = pose_transform(robot.base), pose_transform(robot.tool)
    if free is not None:
        row = kinematics.link_transforms(replace(robot, joints=(robot.joints[free],)),
                                         lambda _: kinematics.trig_symbols((free,), robot.dof), ())[0]
        moved = row[0] * row[1]
        base, tool = (base * moved, tool) if free == 0 else (base, moved * tool)
    joints = [joint for k, joint in enumerate(robot.joints) if k != free]

    if robot.convention == "standard":
        links = [Link(j.d.exact, j.a.exact, j.alpha.exact) for j in joints[:5]]
        last = joints[5]
        return base, links, twist(last.d.exact, last.a.exact, last.alpha.exact) * tool
    first = joints[0]
    head = base * twist(0, first.a.exact, first.alpha.exact)
    links = [Link(joints[i].d.exact, joints[i + 1].a.exact, joints[i + 1].alpha.exact) for i in range(5)]
    return head, links, translation(0, 0, joints[5].d.exact) * tool


def equations(links: list[Link], split: Split) -> Equations:
    """Raghavan & Roth's 14 equations of the loop of C1 .. C5 cut by `split` (see the module
    docstring)."""
    field = RealField(PRECISION * 4)
    polynomials, *generators = ring(GENERATORS, field)
    sines, cosines = generators[0:12:2], generators[1:12:2]
    rotation = [generators[12:15], generators[15:18], generators[18:21]]
    translation = generators[21:24]
    zero, one = polynomials.zero, polynomials.one
    constants = [_link_matrix(link, field) for link in links]
    if split.backwards:  # loop joint k is robot joint 5 - k: L'_k = C_(5 - k)^-1, L'_5 = (N^-1)^-1
        constants = [_inverted(constants[4 - k]) for k in range(5)]

    def apply(step, v, point):
        kind, position, inverse = step
        if kind == "z":
            sign = -1 if inverse else 1
            return [cosines[position] * v[0] - sign * sines[position] * v[1],
                    sign * sines[position] * v[0] + cosines[position] * v[1], v[2]]
        r, t = constants[position]
        if inverse:
            w = [v[k] - t[k] for k in range(3)] if point else v
            return [sum(w[k] * r[k][i] for k in range(3)) for i in range(3)]  # polynomial * number: sympy's fast path
        return [sum(v[k] * r[i][k] for k in range(3)) + (t[i] if point else zero) for i in range(3)]

    def through(steps, v, point):
        for step in reversed(steps):
            v = apply(step, v, point)
        return v

    def side(steps):
        """The 14 quantities of the product of `steps` (rightmost applied first) on (e3, o)."""
        target = [i for i, (kind, position, _) in enumerate(steps) if kind == "l" and position == 5]
        if target:
            outer, inner = steps[:target[0]], steps[target[0] + 1:]
            rv, tv = rotation, translation
        else:
            outer, inner = steps, []
            rv, tv = [[one if i == j else zero for j in range(3)] for i in range(3)], [zero] * 3
        h_axis, h_point = through(inner, [zero, zero, one], False), through(inner, [zero] * 3, True)
        # k = G^-1 o, so that G x = R_G (x - k): the outer motion's inverse, applied to the origin
        k = [zero] * 3
        for kind, position, inverse in outer:
            k = apply((kind, position, not inverse), k, True)
        turn = lambda v: [sum(rv[i][j] * v[j] for j in range(3)) for i in range(3)]  # noqa: E731
        w_axis, w_point = turn(h_axis), turn(h_point)
        offset = [tv[i] - k[i] for i in range(3)]  # V's translation less k
        axis = through(outer, w_axis, False)
        point = through(outer, [w_point[i] + offset[i] for i in range(3)], False)
        pp = _dot(h_point, h_point) + 2 * _dot(w_point, offset) + _dot(offset, offset)
        pl = _dot(h_point, h_axis) + _dot(offset, w_axis)
        inner_cross, offset_cross = turn(_cross(h_point, h_axis)), _cross(offset, w_axis)
        cross = through(outer, [inner_cross[i] + offset_cross[i] for i in range(3)], False)
        return [*axis, *point, pp, pl, *cross, *(pp * along - 2 * pl * at for along, at in zip(axis, point))]

    a, b, c = split.triple
    f, (g, h) = split.free, split.pair
    left = side([("z", a, False), ("l", a, False), ("z", b, False), ("l", b, False), ("z", c, False), ("l", c, False)])
    right = side([("l", h, True), ("z", h, True), ("l", g, True), ("z", g, True), ("l", f, True)])
    return _matrices(split, [_reduced(e) for e in left], [_reduced(e) for e in right])


def _link_matrix(link: Link, field) -> tuple[list, list]:
    """C = Tz(d) Tx(a) Rx(alpha) as (rotation rows, translation), 60-digit numbers."""
    number = lambda value: field(sympy.N(value, PRECISION))  # noqa: E731
    ca, sa = number(sympy.cos(link.alpha)), number(sympy.sin(link.alpha))
    zero, one = field(0), field(1)
    return [[one, zero, zero], [zero, ca, -sa], [zero, sa, ca]], [number(link.a), zero, number(link.d)]


def _inverted(transform: tuple[list, list]) -> tuple[list, list]:
    r, t = transform
    rt = [[r[j][i] for j in range(3)] for i in range(3)]
    return rt, [-sum(rt[i][k] * t[k] for k in range(3)) for i in range(3)]


def _dot(u, v):
    return sum(x * y for x, y in zip(u, v))


def _cross(u, v):
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def _reduced(polynomial) -> dict[tuple[int, ...], object]:
    """The terms of `polynomial` with s_k^2 = 1 - c_k^2 for every joint, cancellations below
    NEGLIGIBLE dropped."""
    terms = dict(polynomial)
    for sine in range(0, 12, 2):
        terms = circle_reduced(terms, sine, sine + 1)
    return {monomial: coefficient for monomial, coefficient in terms.items() if abs(coefficient) > NEGLIGIBLE}


# Exponents of (s_x, c_x, s_y, c_y) of the products in v_bc (x, y = b, c) and v_gh (x, y = g, h).
PRODUCTS = ((1, 0, 1, 0), (1, 0, 0, 1), (0, 1, 1, 0), (0, 1, 0, 1), (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0),
            (0, 0, 0, 1), (0, 0, 0, 0))


def _product(monomial: tuple[int, ...], x: int, y: int, others: tuple[int, ...], where: str) -> int:
    if any(monomial[2 * k] or monomial[2 * k + 1] for k in others):
        raise ValueError(f"{where} reads joints outside its side: {monomial}")
    key = (*monomial[2 * x: 2 * x + 2], *monomial[2 * y: 2 * y + 2])
    if key not in PRODUCTS:
        raise ValueError(f"{where} outside the products of Raghavan-Roth: {monomial}")
    return PRODUCTS.index(key)


def _matrices(split: Split, left: list[dict], right: list[dict]) -> Equations:
    a, b, c = split.triple
    g, h = split.pair
    terms = []

    def add(matrix, row, column, coefficient, monomial):
        terms.append((matrix, row * 9 + column, monomial[12:], coefficient))

    for row, (lhs, rhs) in enumerate(zip(left, right)):
        for monomial, coefficient in lhs.items():
            hidden = monomial[2 * a: 2 * a + 2]
            if sum(hidden) > 1:
                raise ValueError(f"left side of equation {row} not linear in the hidden joint: {monomial}")
            part = 1 if hidden[0] else 2 if hidden[1] else 0
            add(part, row, _product(monomial, b, c, (split.free, g, h), f"left side of equation {row}"), coefficient,
                monomial)
        for monomial, coefficient in rhs.items():
            column = _product(monomial, g, h, (split.free, a, b, c), f"right side of equation {row}")
            if column == 8:  # the constant goes to the left side
                add(0, row, 8, -coefficient, monomial)
            else:
                add(3, row, column, coefficient, monomial)
    return Equations(split, tuple(terms))


def _monomial(symbols, exponents) -> sympy.Expr:
    return sympy.Mul(*(s**e for s, e in zip(symbols, exponents)))


# (sin, cos, 1) of an angle times (1 + x^2), x = tan(angle / 2), as coefficients of (1, x, x^2)
_HALF_ANGLE = {"s": (0, 2, 0), "c": (1, 0, -1), "1": (1, 0, 1)}
# v_bc's entries as polynomials in (x_b, x_c): row k holds the coefficients of x_b^i x_c^j at 3 i + j
MONOMIALS = np.array([np.outer(_HALF_ANGLE[b], _HALF_ANGLE[c]).ravel()
                       for b, c in ("ss", "sc", "cs", "cc", "s1", "c1", "1s", "1c", "11")])


# Pairs (i, i + step) of those monomials whose ratio is x_c (step 1) or x_b (step 3): the kernels
# read each from the pair of largest size in the null vector.
ALONG_C = (0, 1, 3, 4, 6, 7, 9, 10)
ALONG_B = tuple(range(9))
NEWTON_STEPS = 6  # at most, on the pose, after the back-substitution (a near-double root needs more than 2)
# The C takes its Newton steps on this many configurations at once (JACGEN_G6_LANES, templates/c/ik.c.jinja):
# the roots a few batches at a time, a calibrated arm's branches (at most 8) in one.
NEWTON_ROWS = 8
# The fast path of a calibrated arm (a nearest_class.Nominal): the nominal arm's closed form, then up
# to FAST_STEPS Newton steps on the exact arm from each branch that the target allows. Each must
# reach T to CONVERGED (1 + reach), at a solution of its own, and the closed form's certificate
# must hold for every target within the arms' mismatch (`mismatch`; general6r_target.Certificate): no
# branch appears or vanishes there, so the exact arm has one solution near each branch and no
# other (contract §2, "Calibrated arms"). Else the eigenproblem decides.
FAST_STEPS = 4
CONVERGED = {"double": 1e-12, "float": 1e-5}
# An eigenvalue is a root when |imaginary part| <= this (1 + |x|): a double root the target's
# rounding splits into a complex pair (by about the square root of that rounding) still counts,
# and the Newton steps and the tolerance above decide.
IMAGINARY = {"double": 1e-5, "float": 1e-3}
# A bound on the operations of one ik_branches call (what the native module splits batches by).
OPERATIONS = 200_000


def half_angle(s: np.ndarray) -> np.ndarray:
    """Six equations in v_bc (..., 6, 9) as twelve in the monomials x_b^i x_c^j (i <= 3, j <= 2,
    at 3 i + j): the six, and the six times x_b (..., 12, 12)."""
    expanded = s @ MONOMIALS
    out = np.zeros((*s.shape[:-2], 12, 12))
    out[..., :6, :9], out[..., 6:, 3:] = expanded, expanded
    return out


def shifted(ps: np.ndarray, pc: np.ndarray, shift: float) -> tuple[np.ndarray, np.ndarray]:
    """ps, pc for the hidden angle less `shift`: s_a ps + c_a pc = s' ps' + c' pc'."""
    cos, sin = np.cos(shift), np.sin(shift)
    return cos * ps - sin * pc, sin * ps + cos * pc


def chain_product(links: list[Link], theta: np.ndarray) -> np.ndarray:
    """Z1 C1 ... Zk Ck Zk+1 at a batch of joint angles (..., k + 1), in doubles (k = 5 for the
    loop): Z_i C_i is a standard DH link."""
    out = numeric_chain.standard_link(theta[..., len(links)], 0.0, 0.0, 0.0)
    for i, link in reversed(list(enumerate(links))):
        out = numeric_chain.standard_link(theta[..., i], float(link.d), float(link.a), float(link.alpha)) @ out
    return out


def mismatch(robot: Robot, nominal: Robot) -> tuple[float, float]:
    """Bounds on the position error and the rotation angle between the two arms' tool poses at
    any one configuration (the arms differ only in DH twists and lengths: `nearest_class`).
    Telescoping the chain, link i's difference adds its twist's to the angle, and to the
    position its own length's plus the twist's times the farthest the tool point can be from
    where that twist turns (the lengths after it, or from it in the modified convention)."""
    lengths = [math.hypot(joint.a.approx, joint.d.approx if joint.revolute
                          else abs(joint.offset.approx) + max(map(abs, robot.ranges[i])))  # a prismatic joint's travel
               for i, joint in enumerate(robot.joints)]
    tool = math.sqrt(sum(v.approx ** 2 for v in robot.tool.xyz))
    after = 1 if robot.convention == "standard" else 0
    position = rotation = 0.0
    for i, (exact, near) in enumerate(zip(robot.joints, nominal.joints)):
        twist = abs(exact.alpha.approx - near.alpha.approx)
        length = math.hypot(exact.a.approx - near.a.approx, (exact.d.approx - near.d.approx) if exact.revolute else 0.0)
        rotation += twist
        position += length + twist * (sum(lengths[i + after:]) + tool)
    return position, rotation


def work_bytes(real: str) -> int:
    """The size of the C solver's working memory (struct NAME_ik_work in templates/c/ik.c.jinja:
    the equations in the build's real type and in double, the kernel's matrices in double, and
    the Newton steps' 8 rows of x, e and J in the real type, with their solves in double), as
    the contract documents it; tests/test_shipped_robots.py checks it against the compiler's."""
    lanes = NEWTON_ROWS
    reals = 378 + 112 + lanes * (8 + 8 + 64)
    doubles = 3 * 14 * 9 + 14 * 8 + 16 * 5 + (14 * 8 + 8 + 8 + 6 * 14 + 3 * 6 * 9 + 3 * 12 * 12 + 2 * 12 * 4 + 12 * 28
                                           + 16 * 16 + 2 * 12 * 12 + 16 + 16) + lanes * (6 * 6 + 6)
    return reals * {"double": 8, "float": 4}[real] + doubles * 8 + lanes * 4  # and the solves' int flags
