"""Exact polynomials in a robot's joints: the ring over the joint atoms c_i, s_i (cos and sin
of q_i + offset_i), the variables of prismatic joints and the symbolic parameters, where the
singularity analysis (`singularities.py`) and the general 6R equations (`general6r.py`) multiply,
expand determinants (`js_rank.maximal_minors`, with this ring's products) and factor, each
product counted against one work limit.
"""

import math

import sympy
from sympy.polys.orderings import lex
from sympy.polys.rings import PolyElement, PolyRing

from jacgen.inputs import names
from jacgen.inputs.robot import Robot
from jacgen.inputs.transforms import pose_transform
from jacgen.model import kinematics

# The monomial products of all polynomial multiplications of one robot (about 3 s of sympy's
# sparse arithmetic at the most): past it the analysis stops with the factors found so far.
WORK_LIMIT = 250_000
READABLE_TERMS = 64  # factors up to this many terms are written with angle sums collapsed


def joint_atoms(robot: Robot) -> tuple[tuple[sympy.Symbol, ...], ...]:
    """Per joint, the symbols analysis polynomials are written in: (c_i, s_i), the cos and
    sin of q_i + offset_i, for a revolute joint; (q_i,) for a prismatic one."""
    q = kinematics.joint_symbols(robot)
    return tuple(kinematics.trig_symbols((i,), robot.dof) if joint.revolute else (q[i],)
                 for i, joint in enumerate(robot.joints))


# ---------------------------------------------------------------------------------------
# The polynomial ring of a robot


class JointRing:
    """Exact polynomials in the joint atoms (c_i, s_i of revolute joints, q_i of prismatic
    ones) and the symbolic parameters; other irrational constants become opaque generators
    so that every product stays in a ring over the rationals."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.q = kinematics.joint_symbols(robot)
        self.atoms = joint_atoms(robot)
        self.opaque: dict[sympy.Expr, sympy.Symbol] = {}
        self.work = 0
        links = kinematics.link_transforms(robot, lambda i: self.atoms[i], self.q)
        transforms = [m for pair in links for m in pair]
        transforms += [pose_transform(robot.base), pose_transform(robot.tool)]
        transforms = [m.applyfunc(self._hide_constants) for m in transforms]
        symbols = [a for atoms in self.atoms for a in atoms] + [p.symbol for p in robot.symbolic_parameters]
        symbols += list(self.opaque.values())
        self.ring = PolyRing(symbols, sympy.QQ, lex)  # c_i before s_i: reduces c_i^2
        matrices = [self.matrix(m) for m in transforms]
        self.links = [(matrices[2 * i], matrices[2 * i + 1]) for i in range(robot.dof)]
        self.base, self.tool = matrices[-2], matrices[-1]
        self.trig_gens = [i for i, atoms in enumerate(self.atoms) if len(atoms) == 2]
        position = {symbol: k for k, symbol in enumerate(symbols)}
        self.circle_gens = [(position[self.atoms[i][0]], position[self.atoms[i][1]]) for i in self.trig_gens]

    def _hide_constants(self, expr: sympy.Expr) -> sympy.Expr:
        """Replace each irrational constant (sqrt(2)/2, cos(22*pi/225)) by a generator."""
        if expr.is_Rational or expr.is_Symbol:
            return expr
        if expr.is_number or not (expr.is_Add or expr.is_Mul or (expr.is_Pow and expr.exp.is_Integer
                                                                    and expr.exp >= 0)):
            if expr not in self.opaque:
                self.opaque[expr] = sympy.Symbol(f"{names.INTERNAL_PREFIX}k{len(self.opaque)}", real=True)
            return self.opaque[expr]
        return expr.func(*(self._hide_constants(arg) for arg in expr.args))

    def charge(self, work: int) -> None:
        """Count `work` monomial operations against WORK_LIMIT."""
        self.work += work
        if self.work > WORK_LIMIT:
            raise TooLarge(f"more than {WORK_LIMIT:,} monomial operations")

    def times(self, a: PolyElement, b: PolyElement) -> PolyElement:
        """a * b, charged as len(a) * len(b) monomial products."""
        self.charge(len(a) * len(b))
        return a * b

    def matrix(self, m: sympy.Matrix) -> list[list[PolyElement]]:
        return [[self.ring.from_expr(m[r, c]) for c in range(m.cols)] for r in range(m.rows)]

    def expr(self, p: PolyElement) -> sympy.Expr:
        """Back to sympy, over the atoms c_i, s_i, q_i and parameters (constants restored)."""
        values = {symbol: value for value, symbol in self.opaque.items()}
        return p.as_expr().xreplace(values)

    def trig_expr(self, p: PolyElement) -> sympy.Expr:
        """Readable: cos(q_i + offset) for c_i, sums of angles collapsed (in polynomials of
        up to READABLE_TERMS terms: beyond, collapsing costs minutes and reads no better)."""
        values = {}
        for i, atoms in enumerate(self.atoms):
            if len(atoms) == 2:
                angle = self.q[i] + self.robot.joints[i].offset.exact
                values.update({atoms[0]: sympy.cos(angle), atoms[1]: sympy.sin(angle)})
        condition = self.expr(p).xreplace(values)
        return kinematics.simplify_trig(condition) if len(p) <= READABLE_TERMS else condition

    def reduce(self, p: PolyElement, toward_cos: bool) -> PolyElement:
        """Normal form modulo s_i^2 + c_i^2 - 1: no s_i^2 (toward cos) or no c_i^2.

        One pass per joint, s^(2k + r) -> s^r (1 - c^2)^k by the binomial theorem (or the
        same with c and s swapped): linear in the size of the result, which is charged."""
        terms = dict(p)
        for cos, sin in self.circle_gens:
            terms = {m: c for m, c in circle_reduced(terms, *((sin, cos) if toward_cos else (cos, sin))).items() if c}
            self.charge(len(terms))
        return self.ring.from_dict(terms) if terms else self.ring.zero

    def joints_of(self, p: PolyElement) -> tuple[int, ...]:
        degrees = p.degrees()
        used, g = [], 0
        for i, atoms in enumerate(self.atoms):
            if any(degrees[g + k] > 0 for k in range(len(atoms))):
                used.append(i)
            g += len(atoms)
        return tuple(used)


def circle_reduced(terms: dict, power: int, other: int) -> dict:
    """Polynomial terms {exponents: coefficient} with x^(2k + r) -> x^r (1 - y^2)^k, where x and y
    are the generators at positions `power` and `other` (a sine and cosine): one pass, by the
    binomial theorem, linear in the size of the result."""
    reduced: dict = {}
    for monomial, coefficient in terms.items():
        half = monomial[power] // 2
        for j in range(half + 1):
            exponents = list(monomial)
            exponents[power] -= 2 * half
            exponents[other] += 2 * j
            key = tuple(exponents)
            reduced[key] = reduced.get(key, 0) + coefficient * math.comb(half, j) * (-1) ** j
    return reduced


class TooLarge(Exception):
    """The exact analysis would pass one of the size limits above."""


def multiply(ring: JointRing, a, b):
    return [[sum((ring.times(a[r][k], b[k][c]) for k in range(len(b))), ring.ring.zero) for c in range(len(b[0]))]
            for r in range(len(a))]


def inverse(ring: JointRing, t):
    """Inverse of a rigid transform (exact wherever c_i^2 + s_i^2 = 1)."""
    rotation = [[t[c][r] for c in range(3)] for r in range(3)]
    shift = [-sum((ring.times(rotation[r][k], t[k][3]) for k in range(3)), ring.ring.zero) for r in range(3)]
    zero, one = t[0][0].ring.zero, t[0][0].ring.one
    return [rotation[r] + [shift[r]] for r in range(3)] + [[zero, zero, zero, one]]


def frames_about(ring: JointRing, k: int) -> list:
    """Poses of every joint-axis frame and of the tool relative to the axis frame of joint k."""
    n = ring.robot.dof
    step = [multiply(ring, ring.links[j][1], ring.links[j + 1][0]) for j in range(n - 1)]  # axis j -> axis j+1
    identity = [[ring.ring.one if r == c else ring.ring.zero for c in range(4)] for r in range(4)]
    frames = [None] * n
    frames[k] = identity
    for i in range(k + 1, n):
        frames[i] = multiply(ring, frames[i - 1], step[i - 1])
    back = identity
    for i in range(k - 1, -1, -1):
        back = multiply(ring, step[i], back)
        frames[i] = inverse(ring, back)
    tool = multiply(ring, multiply(ring, frames[n - 1], ring.links[n - 1][1]), ring.tool)
    return frames + [tool]


def geometric_columns(ring: JointRing, frames: list, point) -> list[list[PolyElement]]:
    """Geometric Jacobian (6 x n rows) in the frames' coordinates about `point`, reduced."""
    rows = [[None] * ring.robot.dof for _ in range(6)]
    x = ring.times
    for i, joint in enumerate(ring.robot.joints):
        z = [frames[i][r][2] for r in range(3)]
        if joint.revolute:
            arm = [point[r] - frames[i][r][3] for r in range(3)]
            linear = [x(z[1], arm[2]) - x(z[2], arm[1]), x(z[2], arm[0]) - x(z[0], arm[2]), x(z[0], arm[1]) - x(z[1], arm[0])]
            column = linear + z
        else:
            column = z + [ring.ring.zero] * 3
        for r in range(6):
            rows[r][i] = ring.reduce(column[r], toward_cos=True)
    return rows


def term_count(matrix) -> int:
    return sum(len(entry) for row in matrix for entry in row)


# ---------------------------------------------------------------------------------------
# Factoring


def factorise(ring: JointRing, p: PolyElement) -> tuple[PolyElement, list[tuple[PolyElement, int]]]:
    """constant, [(factor, multiplicity)]: p = constant * prod(factor^multiplicity) on the torus.

    Factors free of joint variables (parameters, opaque constants) go into the constant.
    """
    constant, factors = ring.ring.one, {}
    coefficient, free = p.factor_list()
    constant *= coefficient
    for f, k in free:
        candidates = [g.factor_list() for g in (ring.reduce(f, True), ring.reduce(f, False))]
        best = max(candidates, key=lambda c: (sum(bool(ring.joints_of(g)) for g, _ in c[1]),
                                              -sum(len(g) for g, _ in c[1])))
        constant *= best[0] ** k
        for g, j in best[1]:
            if ring.joints_of(g):
                factors[g] = factors.get(g, 0) + j * k
            else:
                constant *= g ** (j * k)
    for i in ring.trig_gens:  # (c_i - 1)^a (c_i + 1)^a = (-1)^a s_i^(2a)
        c, s = (ring.ring(atom) for atom in ring.atoms[i])
        a = min(factors.get(c - 1, 0), factors.get(c + 1, 0))
        if a:
            for g in (c - 1, c + 1):
                factors[g] -= a
                if not factors[g]:
                    del factors[g]
            factors[s] = factors.get(s, 0) + 2 * a
            constant *= (-1) ** a
    normalised = []  # largest coefficient 1, so that factor values are of the order of 1
    for f, k in factors.items():
        scale = f.max_norm()
        normalised.append((f.quo_ground(scale), k))
        constant *= scale**k
    normalised.sort(key=lambda item: (len(ring.joints_of(item[0])), ring.joints_of(item[0]),
                                      len(item[0]), str(item[0])))
    return constant, normalised


# ---------------------------------------------------------------------------------------
# The matrix analysed


def permutation_sign(order) -> int:
    order, sign = list(order), 1
    for i in range(len(order)):
        while order[i] != i:
            j = order[i]
            order[i], order[j] = order[j], order[i]
            sign = -sign
    return sign
