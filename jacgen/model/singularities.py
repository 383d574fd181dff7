"""Singularity analysis (docs/contract.md §2): the polynomial of the singularity Jacobian Js
(`js_rank.py`) and its exact factors. The robot is singular where det(Js) (m = n),
det(Js Js^T) (m < n) or det(Js^T Js) (m > n) vanishes; the Euler-angle singularity at
pitch = ±90° is reported separately.

The polynomial is computed exactly in a polynomial ring over the joint atoms c_i, s_i
(cos and sin of q_i + offset_i), the variables of prismatic joints and the symbolic
parameters, where products and determinants are cheap. Where Js is the whole geometric
Jacobian, its determinant and its maximal minors do not change when the twist is
expressed in another frame or about another reference point (a rotation and a shift,
both of determinant 1), so they are computed in whichever joint frame and about whichever
joint origin make the matrix smallest: about a spherical wrist's centre the matrix is
block triangular and det = det(arm 3x3) * det(wrist 3x3).

Factoring happens in the free ring first (the product structure survives there), then
each factor is reduced with s_i^2 + c_i^2 = 1 towards cosines and towards sines and
factored again, keeping whichever splits it further. Trig polynomials do not factor
uniquely (sin^2 = (1 - cos)(1 + cos)), so "irreducible" means no further split is found
this way; every factor is exact, and constant * product of factors equals the polynomial
wherever c_i^2 + s_i^2 = 1.
"""

import math
from dataclasses import dataclass

import numpy as np
import sympy
from sympy.polys.rings import PolyElement

from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.model.graph import Graph
from jacgen.model.node import ADD, evaluate
from jacgen.model.joint_ring import (READABLE_TERMS, JointRing, TooLarge, factorise, frames_about, geometric_columns,
                                     multiply, permutation_sign, term_count)
from jacgen.model.js_rank import MINOR_LIMIT, maximal_minors, singularity_rows
from jacgen.tolerances import PARALLEL, ROOT

# What `evaluate` calls over numpy arrays (the zero sets of factors, on a grid of one joint).
NUMPY = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "atan2": np.arctan2, "Abs": np.abs, ADD: sum}

# The exact analysis is bounded by counts, never by a clock, so its outcome is the same on
# every machine: the monomial products of all polynomial multiplications of one robot
# (joint_ring.WORK_LIMIT); the maximal minors whose common factors are sought
# (js_rank.MINOR_LIMIT); FACTOR_TERM_LIMIT the size of a polynomial handed to sympy's factoring.
# Past any of them the exact factors found so far stay, and the generated code computes the
# rest of the rank condition numerically (det(Js), or det(Js Js^T) / det(Js^T Js)).
FACTOR_TERM_LIMIT = 400


def _analysed_matrix(ring: JointRing):
    """(rows, sign, cos(pitch)^2 or None): a matrix with the singularity polynomial of Js.

    The whole geometric Jacobian: in the joint frame and about the reference point (that
    frame's origin or the tool point; always the tool point when tall, where only rotations
    keep det(Js^T Js)) that make it smallest; its determinant is sign * det(Js). Otherwise
    Js in the world frame, Euler-angle rows multiplied by their denominators, which are
    returned as cos(pitch)^2.
    """
    robot = ring.robot
    n, rows = robot.dof, singularity_rows(robot)
    if rows is not None and len(rows) == 6:
        best = None
        for k in range(n):
            frames = frames_about(ring, k)
            points = [frames[-1]] if n < 6 else [frames[k], frames[-1]]  # about a wrist centre at most
            for frame in points:
                matrix = geometric_columns(ring, frames, [frame[r][3] for r in range(3)])
                if best is None or term_count(matrix) < term_count(best):
                    best = matrix
        return best, permutation_sign(rows), None
    base_axis = multiply(ring, ring.base, ring.links[0][0])
    frames = [multiply(ring, base_axis, frame) for frame in frames_about(ring, 0)]
    tool = frames[-1]
    geometric = geometric_columns(ring, frames, [tool[r][3] for r in range(3)])
    if rows is not None:
        return [geometric[r] for r in rows], 1, None
    euler, cos_pitch_sq = _euler_rows(ring, [row[:3] for row in tool[:3]], geometric[3:])
    chosen = [geometric[TASK_COMPONENTS.index(c)] if c in "xyz" else euler[c] for c in robot.task]
    return [[ring.reduce(e, True) for e in row] for row in chosen], 1, cos_pitch_sq


def _euler_rows(ring: JointRing, rotation, angular) -> tuple[dict, PolyElement]:
    """Roll, pitch and yaw rate rows times their denominators (cos(pitch)^2, cos(pitch),
    cos(pitch)^2: see kinematics.rpy_rates), and cos(pitch)^2 = r00^2 + r10^2 unreduced
    (its product structure shows which joints make pitch reach ±90°)."""
    r00, r10, r20 = rotation[0][0], rotation[1][0], rotation[2][0]
    wx, wy, wz = angular
    x = ring.times
    cos_pitch_sq = x(r00, r00) + x(r10, r10)
    reduced = ring.reduce(cos_pitch_sq, True)
    roll = [x(r00, wx[j]) + x(r10, wy[j]) for j in range(ring.robot.dof)]
    return {"roll": roll,
            "pitch": [x(r00, wy[j]) - x(r10, wx[j]) for j in range(ring.robot.dof)],
            "yaw": [x(reduced, wz[j]) - x(r20, roll[j]) for j in range(ring.robot.dof)]}, cos_pitch_sq


# ---------------------------------------------------------------------------------------
# The analysis


@dataclass(frozen=True)
class Factor:
    """One singularity condition `polynomial = 0`."""

    polynomial: sympy.Expr  # over c_i, s_i, q_i (prismatic joints) and parameters: for code
    condition: sympy.Expr  # the same in q (sin(q2 + q3)): for people
    multiplicity: int
    joints: tuple[int, ...]  # 0-based indices of the joints it depends on
    roots: tuple[sympy.Expr, ...] | None  # one joint: its values in (-pi, pi] (prismatic: all)
    meaning: str  # a name for the configuration, or ""


@dataclass(frozen=True)
class Singularities:
    """The singularity polynomial of a robot, factored as far as the size limits allow.

    complete: det(Js) = constant * prod(p^k for p, k in determinant) / cos(pitch)^euler_power
    (square Js), where cos(pitch) = sqrt(r00^2 + r10^2) of the tool rotation (euler_power > 0
    only when Js holds Euler-angle rate rows); for m != n, the factors are those of the Gram
    determinant. Not complete: `factors` are exact factors of it, and the rest of the rank
    condition is left to a numeric det(Js) or Gram determinant in the generated code.
    everywhere: Js is rank-deficient in every configuration (the polynomial is 0).
    """

    kind: str  # "det(Js)", "det(Js Js^T)" or "det(Js^T Js)"
    factors: tuple[Factor, ...]  # the kinematic singularity conditions
    complete: bool
    everywhere: bool
    constant: sympy.Expr
    determinant: tuple[tuple[sympy.Expr, int], ...]  # every factor of the polynomial, Euler ones too
    euler_power: int
    euler: tuple[Factor, ...]  # joint conditions for cos(pitch) = 0, when Js holds Euler rows
    note: str


def singularity_kind(robot: Robot) -> str:
    """The singularity polynomial: det(Js) (m = n), det(Js Js^T) (m < n) or det(Js^T Js) (m > n)."""
    n, m = robot.dof, len(robot.task)
    return "det(Js)" if m == n else ("det(Js Js^T)" if m < n else "det(Js^T Js)")


def _gram_factors(ring: JointRing, minors: list) -> tuple[PolyElement, list, bool, str]:
    """(constant, factors, complete, note) of the Gram determinant sum(minor^2) (Cauchy-Binet),
    from the factors common to every maximal minor, never from the sum itself."""
    common = minors[0]
    for minor in minors[1:]:
        ring.charge(len(common) * len(minor))  # as a product: gcd costs about as much
        common = common.gcd(minor)
    if len(common) > FACTOR_TERM_LIMIT:
        raise TooLarge(f"a common factor of {len(common)} terms")
    constant, factors = factorise(ring, common)
    # Where some minor is a constant multiple of the common factor, the rest of the sum of
    # squares never vanishes: the common factors are the whole condition. A constant multiple
    # has as many terms, so only those minors are divided (a division is not charged).
    complete = any(minor and len(minor) == len(common) and minor.exquo(common).is_ground for minor in minors)
    note = "" if complete else (
        f"besides the factors common to all {len(minors)} maximal minors of Js, Js loses rank where the "
        f"Gram determinant {ring.robot.name}'s code computes numerically is 0")
    return constant**2, [(f, 2 * k) for f, k in factors], complete, note


def analyse(robot: Robot) -> Singularities:
    """Factor the singularity polynomial of `robot` (see the module docstring), as far as the
    size limits allow: bounded work, the same result on every machine."""
    ring = JointRing(robot)
    n, m = robot.dof, len(robot.task)
    kind = singularity_kind(robot)
    constant, factors, complete, note, cos_pitch_sq = ring.ring.one, [], False, "", None
    try:
        if math.comb(max(m, n), min(m, n)) > MINOR_LIMIT:  # known before any polynomial is built
            raise TooLarge(f"C({max(m, n)}, {min(m, n)}) maximal minors")
        matrix, sign, cos_pitch_sq = _analysed_matrix(ring)
        minors = maximal_minors(matrix, ring.ring.zero, ring.ring.one, ring.times)
        if all(not minor for minor in minors):
            return Singularities(kind, (), True, True, sympy.Integer(0), (), 0, (),
                                 f"Js has rank below {min(m, n)} in every configuration: "
                                 f"the arm cannot move its tool along every task direction at once")
        if m == n:
            if len(minors[0]) > FACTOR_TERM_LIMIT:
                raise TooLarge(f"det(Js) has {len(minors[0])} terms")
            constant, factors = factorise(ring, minors[0])
            constant, complete = constant * sign, True
        else:
            constant, factors, complete, note = _gram_factors(ring, minors)
    except TooLarge as reason:
        note = (f"the exact analysis stopped at its size limit ({reason}): "
                f"{'det(Js)' if m == n else 'the Gram determinant'}, computed numerically, stands as the condition")
    euler_power, euler = 0, []
    if cos_pitch_sq is not None and complete:
        euler_power = sum({"roll": 2, "pitch": 1, "yaw": 2}.get(c, 0) for c in robot.task)
        euler = factorise(ring, cos_pitch_sq)[1] if len(cos_pitch_sq) <= FACTOR_TERM_LIMIT else []
    scale = dict(euler)
    kinematic = [(f, k - euler_power * scale.get(f, 0) // 2) for f, k in factors]
    context = _Numeric(robot, ring)
    return Singularities(
        kind=kind,
        factors=tuple(context.describe(f, k) for f, k in kinematic if k > 0),
        complete=complete,
        everywhere=False,
        constant=ring.expr(constant),
        determinant=tuple((ring.expr(f), k) for f, k in factors),
        euler_power=euler_power,
        euler=tuple(context.describe(f, k // 2 or 1) for f, k in euler),
        note=note,
    )


def unanalysed(robot: Robot) -> Singularities:
    """No exact factors: the numeric rank determinant is the whole condition (the fallback
    of the analysis when it outlives --budget)."""
    kind = singularity_kind(robot)
    return Singularities(kind, (), False, False, sympy.Integer(1), (), 0, (),
                         f"the exact analysis took longer than --budget: {kind}, computed numerically, is the condition")


# ---------------------------------------------------------------------------------------
# Roots and names


class _Numeric:
    """Numbers about the factors: roots, zero sets, and the axes there (from the numeric
    chain, `numeric_chain`) to name the configuration."""

    def __init__(self, robot: Robot, ring: JointRing):
        self.robot, self.ring = robot, ring
        self.nominal = {p.symbol: sympy.Float(p.value, 30) for p in robot.symbolic_parameters}
        self.rng = np.random.default_rng(20240601)

    def describe(self, f: PolyElement, multiplicity: int) -> Factor:
        joints = self.ring.joints_of(f)
        condition = self.ring.trig_expr(f)
        roots = self._roots(f, joints[0]) if len(joints) == 1 else None
        factor = Factor(self.ring.expr(f), condition, multiplicity, joints, roots, "")
        return Factor(**{**factor.__dict__, "meaning": self._meaning(factor)})

    def _roots(self, f: PolyElement, joint: int) -> tuple[sympy.Expr, ...]:
        """The values of joint `joint` where the one-joint factor f vanishes, in (-pi, pi] for a
        revolute joint: with t = tan(q/2), f(cos q, sin q) (1 + t^2)^deg is a polynomial in t
        of degree at most 2 deg, and q = pi is a root where f(-1, 0) = 0. Closed form up to
        degree 2 with coefficients free of cos and sin (of an angle like 42.24 deg, whose
        radicals sympy's roots took seconds over), numeric roots otherwise, each checked
        against f."""
        expr, t = self.ring.expr(f).xreplace(self.nominal), sympy.Dummy("t", real=True)
        atoms = self.ring.atoms[joint]
        poly = sympy.Poly(expr, *atoms)
        scale = max(1.0, *(abs(float(c)) for c in poly.coeffs()))
        if len(atoms) == 1:
            in_t, at_pi = poly, []
        else:
            degree = poly.total_degree()
            in_t = sympy.Poly(sum(coefficient * (1 - t**2) ** i * (2 * t) ** j * (1 + t**2) ** (degree - i - j)
                                  for (i, j), coefficient in poly.terms()), t)
            at_pi = [sympy.pi] if abs(poly.eval((-1, 0))) <= ROOT * scale else []
        if in_t.is_zero:
            return ()
        if in_t.degree() <= 2 and not in_t.has(sympy.Float, sympy.cos, sympy.sin):
            values = [r for r in sympy.roots(in_t, multiple=True) if r.is_real]
        else:
            coefficients = [complex(c) for c in in_t.all_coeffs()]
            values = [sympy.Float(float(r.real), 17) for r in np.roots(coefficients)
                      if abs(r.imag) <= 1e-6 * (1 + abs(r))]
        roots = [2 * sympy.atan(v) for v in values] if len(atoms) == 2 else list(values)
        value = Graph().convert(expr)
        unique = {}
        for root in roots + at_pi:
            point = (math.cos(float(root)), math.sin(float(root))) if len(atoms) == 2 else (float(root),)
            if abs(evaluate(value, dict(zip(atoms, point)))) <= ROOT * scale and round(float(root), 9) not in unique:
                unique[round(float(root), 9)] = root
        return tuple(unique[key] for key in sorted(unique))

    def _function(self, condition: sympy.Expr):
        """The condition as a function of q, over numpy arrays (on the value graph: sympy's
        lambdify imports half of numpy the first time)."""
        value = Graph().convert(condition.xreplace(self.nominal))
        return lambda q: evaluate(value, dict(zip(self.ring.q, q)), NUMPY)

    def _configuration(self) -> np.ndarray:
        return np.array([self.rng.uniform(lo, hi) for lo, hi in self.robot.ranges])

    def zero_set_points(self, factor: Factor, count: int = 3) -> list[np.ndarray]:
        """Configurations where the factor vanishes: random ones with one joint solved for."""
        value = self._function(factor.condition)
        points = []
        for _ in range(8 * count):
            q = self._configuration()
            for joint in factor.joints:
                root = _solve_along(value, q, joint, self.robot.joints[joint])
                if root is not None:
                    points.append(root)
                    break
            if len(points) == count:
                break
        return points

    def _meaning(self, factor: Factor) -> str:
        robot = self.robot
        n = robot.dof
        if len(factor.joints) == 1:
            k = factor.joints[0]
            joint = robot.joints[k]
            if not joint.revolute:
                return f"prismatic joint {k + 1} at zero extension"
            if 0 < k < n - 1 and factor.roots:
                generic = _axes(robot, self._configuration())
                if not _parallel(generic[k - 1][1], generic[k + 1][1]):
                    aligned = []
                    for root in factor.roots:
                        q = self._configuration()
                        q[k] = float(root)
                        aligned.append(_axes(robot, q))
                    if all(_parallel(a[k - 1][1], a[k + 1][1]) for a in aligned):
                        word = "aligned" if all(_collinear(a[k - 1], a[k + 1]) for a in aligned) else "parallel"
                        prefix = "wrist singularity: " if k == n - 2 else ""
                        return f"{prefix}axes of joints {k} and {k + 2} {word}"
            if k > 0 and robot.joints[k - 1].revolute:
                generic = _axes(robot, self._configuration())
                if _parallel(generic[k - 1][1], generic[k][1]):
                    return "elbow: arm fully stretched or folded"
            return ""
        points = self.zero_set_points(factor) if len(sympy.Add.make_args(factor.polynomial)) <= READABLE_TERMS else []
        for name, point in (("wrist point", lambda q: _axes(robot, q)[-1][0]),
                            ("tool point", lambda q: numeric_chain.axis_frames(robot, q)[1][:3, 3])):
            if n >= 3 and points and all(_over_first_axis(robot, q, point(q)) for q in points):
                return f"shoulder: {name} in the plane of the axes of joints 1 and 2 (over the axis of joint 1)"
        return ""


def _solve_along(value, q: np.ndarray, joint: int, spec) -> np.ndarray | None:
    """q with joint `joint` moved to a root of `value` (a sign change on a grid, bisected)."""
    lo, hi = spec.limits or ((-np.pi, np.pi) if spec.revolute else (-2.0, 2.0))
    grid = np.linspace(lo, hi, 721)
    trial = np.repeat(q[None, :], len(grid), axis=0)
    trial[:, joint] = grid
    values = np.broadcast_to(value(trial.T), grid.shape)
    changes = np.nonzero(np.sign(values[:-1]) * np.sign(values[1:]) <= 0)[0]
    if not len(changes):
        return None
    a, b = grid[changes[0]], grid[changes[0] + 1]
    point = q.copy()
    for _ in range(80):
        point[joint] = 0.5 * (a + b)
        if np.sign(value(point)) == np.sign(value(np.where(np.arange(len(q)) == joint, a, point))):
            a = point[joint]
        else:
            b = point[joint]
    return point if abs(value(point)) < ROOT else None


def _axes(robot: Robot, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(point, unit direction) of every joint axis, from `numeric_chain`."""
    frames, _ = numeric_chain.axis_frames(robot, q)
    return [(frame[:3, 3], frame[:3, 2]) for frame in frames]


def _parallel(a: np.ndarray, b: np.ndarray) -> bool:
    return np.linalg.norm(np.cross(a, b)) < PARALLEL


def _collinear(a, b) -> bool:
    return _parallel(a[1], b[1]) and _parallel(a[1], b[0] - a[0])


def _over_first_axis(robot: Robot, q: np.ndarray, point: np.ndarray) -> bool:
    """`point` lies in the plane through the axis of joint 1 spanned by the directions of
    axes 1 and 2 (on the axis of joint 1 itself when the arm has no shoulder offset)."""
    axes = _axes(robot, q)
    (origin, first), (_, second) = axes[0], axes[1]
    normal = np.cross(first, second)
    if np.linalg.norm(normal) < PARALLEL:
        return False
    reach = max(1.0, float(np.linalg.norm(point - origin)))
    return abs(np.dot(point - origin, normal / np.linalg.norm(normal))) < 1e-7 * reach


def singular_configurations(robot: Robot, singular: Singularities, per_factor: int = 3) -> np.ndarray:
    """Configurations on the zero set of each factor that changes sign, found numerically
    (random configurations with one joint moved to a root), (k, dof)."""
    numeric = _Numeric(robot, JointRing(robot))
    points = [q for factor in singular.factors for q in numeric.zero_set_points(factor, per_factor)]
    return np.array(points).reshape(-1, robot.dof)
