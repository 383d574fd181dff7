"""Kinematic structure of an arm, decided exactly from its geometry at q = 0.

At q = 0 every joint is a line in the world frame: the unit direction h_i of its axis and a
point p_i on it (the origin of the joint's axis frame), computed with sympy from the DH table
by `kinematics.build_chain` (base, joint offsets and tool included). This is the
product-of-exponentials description T(q) = exp(xi_1 q_1) ... exp(xi_n q_n) T(0) that the
closed-form solvers of `ik.py` work on. Relations between axes (parallel, intersecting,
meeting in one point) are decided exactly, so a structure is recognised only when it holds
for the robot's dimensions (with symbolic parameters: for every value of them).

A 7-joint arm is solved as a 6-joint chain with one joint free (an input of ik): the
geometry then holds that joint at the angle whose cos and sin are the symbols c_k, s_k, the
axes after it depend on them, and a relation is decided for every angle of the free joint
(exactly: polynomials in c_k, s_k reduced by c_k^2 + s_k^2 = 1). A chain whose first axes
meet in a point (a spherical shoulder) is solved backwards: `Geometry.reversed`.
"""

import copy
from dataclasses import dataclass, field, replace

import sympy

from jacgen.inputs import names
from jacgen.inputs.robot import TASK_COMPONENTS, Pose, Robot
from jacgen.inputs.values import Value
from jacgen.model import kinematics

Matrix = sympy.Matrix
E_Z = Matrix([0, 0, 1])
PRECISION = 60  # digits of the irrational numbers of the geometry
TOLERANCE = 1e-40  # a relation holds when its measure (a squared distance or sine) is below this
GENERIC_POINTS = 3  # values of the symbolic parameters (and the free joint) a relation must hold at


@dataclass(frozen=True)
class SolverInfo:
    """What a closed-form solver does, for the report and the generated documentation."""

    title: str
    max_solutions: int
    branches: tuple[str, ...]  # the branch loops, outermost first; solutions come in this order


SOLVERS = {
    "planar": SolverInfo(
        "planar arm: revolute axes (and any prismatic axis) parallel to world z; the last "
        "revolute joint sets the yaw, the first two place the wrist point (SP3, SP1)",
        2, ("elbow: the second revolute joint, '+' then '-' (elbow on either side of the line "
            "from the first axis to the wrist point)",)),
    "yaw_pitch": SolverInfo(
        "base yaw + three parallel pitch axes: the pitch fixes the sum of the pitch angles "
        "(SP4), the base yaw puts the arm's plane through the target (SP4), the law of "
        "cosines gives the elbow (SP3)",
        8, ("base: the two yaw angles that put the target in the arm's plane, '+' then '-' "
            "(facing the target, then reaching over the top)",
            "approach: the two sums of the pitch angles with the target pitch, '+' then '-'",
            "elbow: q3, '+' then '-' (elbow up and down)")),
    "spherical_wrist_parallel": SolverInfo(
        "6R with a spherical wrist and axes 2, 3 parallel (Pieper): wrist centre, base "
        "angle (SP4), elbow (SP3), shoulder (SP1), then the wrist orientation (SP2, SP1)",
        8, ("shoulder: q1, '+' then '-' (the arm left and right of the base axis, rtb's l/r)",
            "elbow: q3, '+' then '-' (elbow up and down, rtb's u/d)",
            "wrist: (q4, q5), '+' then '-' (wrist flipped or not, rtb's f/n)")),
    "spherical_wrist_intersecting": SolverInfo(
        "6R with a spherical wrist and axes 1, 2 intersecting (Pieper): wrist centre, elbow "
        "(SP3), base and shoulder together (SP2), then the wrist orientation (SP2, SP1)",
        8, ("elbow: q3, '+' then '-' (elbow up and down)",
            "shoulder: (q1, q2), '+' then '-' (the arm on either side of the base axis)",
            "wrist: (q4, q5), '+' then '-' (wrist flipped or not)")),
    "spherical_wrist_prismatic": SolverInfo(
        "RRP + spherical wrist (Stanford arm): wrist centre, the prismatic joint 3 from the "
        "distance to the shoulder point (quadratic), base and shoulder (SP2), then the wrist "
        "orientation (SP2, SP1)",
        8, ("reach: q3, larger root then smaller (the smaller is usually negative: check limits)",
            "shoulder: (q1, q2), '+' then '-' (the arm on either side of the base axis)",
            "wrist: (q4, q5), '+' then '-' (wrist flipped or not)")),
    "three_parallel": SolverInfo(
        "6R with axes 2, 3, 4 parallel and axes 5, 6 intersecting (Universal Robots): base "
        "angle (SP4), wrist 2 (SP4), wrist 3 (SP1), the sum q2 + q3 + q4 (SP1), elbow (SP3), "
        "shoulder (SP1)",
        8, ("shoulder: q1, '+' then '-' (the arm left and right of the base axis)",
            "wrist: q5, '+' then '-' (the two wrist-2 angles, wrist up and down)",
            "elbow: q3, '+' then '-' (elbow up and down)")),
    "general_6r": SolverInfo(
        "general 6R: Raghavan & Roth's 14 equations, eliminated to a 12 x 12 quadratic matrix "
        "polynomial in tan(q_k/2) solved as an eigenproblem (24 x 24, its eight roots +-i deflated in C), "
        "back-substitution and up to six Newton steps (jacgen/solvers/general6r.py)",
        16, ("the real eigenvalues in the order the eigensolver gives them; a solution that does not "
             "reach the target after the Newton steps (a spurious root) is skipped",)),
}


@dataclass(frozen=True)
class Structure:
    """The class of a robot: its closed-form solver (None when none applies) and why."""

    solver: str | None
    reason: str  # why the solver applies, or why no solver does
    chain: "Geometry | None" = field(default=None, compare=False)  # what the solver solves (see Geometry)


def _circle(expr: sympy.Expr) -> tuple[sympy.Symbol, sympy.Symbol] | None:
    """The cos and sin symbols of the free joint when `expr` depends on them."""
    joint = next((k for x in expr.free_symbols if (k := names.trig_joint(x.name)) is not None), None)
    return None if joint is None else kinematics.trig_symbols((joint,), joint + 1)  # one joint's names: any dof


def _on_circle(polynomial: sympy.Expr, cos: sympy.Symbol, sin: sympy.Symbol) -> sympy.Expr:
    """The polynomial with sin^2 = 1 - cos^2: a(cos) + sin b(cos), one form per function on the
    circle; numeric coefficients below TOLERANCE (the rounding of 60-digit numbers) dropped."""
    terms = sympy.Poly(sympy.expand(polynomial), sin).terms()
    reduced = sympy.Poly(sympy.Add(*(c * sin ** (k % 2) * (1 - cos**2) ** (k // 2) for (k,), c in terms)), cos, sin)
    return sympy.Add(*(c * cos**i * sin**j for (i, j), c in reduced.terms() if c.free_symbols or not is_zero(c)))


def _rational(expr: sympy.Expr, circle: tuple[sympy.Symbol, sympy.Symbol]) -> bool:
    """A rational function of the free joint's cos and sin (the geometry's relations are)."""
    return all(not atom.has(*circle) or atom in circle for atom in expr.atoms(sympy.Function, sympy.Pow)
               if not (isinstance(atom, sympy.Pow) and atom.exp.is_Integer))


def _generic_points(symbols: set[sympy.Symbol]) -> list[dict[sympy.Symbol, sympy.Float]]:
    """GENERIC_POINTS fixed values of the symbols, none special: each symbolic parameter in
    [0.5, 1.5), each free joint at an angle whose cos and sin replace its c_k and s_k. An
    expression of the geometry that vanishes at all of them vanishes for every value (up to a
    set of measure zero that fixed irrational fractions do not hit)."""
    def fraction(k: int, j: int) -> sympy.Float:
        return sympy.Float((0.3819660112501051 * k + 0.7548776662466927 * j) % 1, PRECISION)

    points = []
    for k in range(1, GENERIC_POINTS + 1):
        point = {}
        for j, symbol in enumerate(sorted(symbols, key=lambda x: x.name), 1):
            if (joint := names.trig_joint(symbol.name)) is not None:
                angle = 2 * sympy.pi * fraction(k, joint + 1)  # one angle for c_k and s_k
                value = (sympy.cos if symbol.name[0] == "c" else sympy.sin)(angle)
            else:
                value = 0.5 + fraction(k, j)
            point[symbol] = sympy.Float(sympy.N(value, PRECISION), PRECISION)
        points.append(point)
    return points


def is_zero(expr) -> bool:
    """Below TOLERANCE, evaluated with 60-digit numbers: the geometry's entries are numbers
    (see `_precise`), so each test costs a fixed number of operations. An expression of
    symbolic parameters or of the free joint's angle is zero when it is at GENERIC_POINTS
    fixed generic values of them (for every value of them, then)."""
    expr = sympy.sympify(expr)
    points = _generic_points(expr.free_symbols) if expr.free_symbols else [{}]
    return all(abs(complex(sympy.N(expr.xreplace(point), PRECISION))) < TOLERANCE for point in points)


def readable(expr: sympy.Expr) -> sympy.Expr:
    """Simplified when symbolic (for readable reports), reduced on the circle when a function of
    the free joint; numbers stay as they are, since their value is all that is used."""
    circle = _circle(expr)
    if circle and _rational(expr, circle):
        numerator, denominator = sympy.fraction(sympy.together(expr))
        return _on_circle(numerator, *circle) / _on_circle(denominator, *circle)
    return sympy.simplify(expr) if expr.free_symbols else expr


def _precise_length(value: Value) -> Value:
    """A length: exact when rational or symbolic, else a 60-digit float."""
    e = value.exact
    if e.free_symbols or e.is_Rational:
        return value
    return Value(sympy.Float(sympy.N(e, PRECISION), PRECISION), value.approx)


def _precise_angle(value: Value) -> Value:
    """An angle: exact when a multiple of pi/2 (its cos and sin are 0 and +-1) or symbolic, else
    a 60-digit float, so that its cos and sin are 60-digit floats too. Kept exact, an angle such
    as 1.2001 rad stays cos(12001/10000) and the chain's products of such terms grow with every
    joint, while only their value is used."""
    e = value.exact
    if e.free_symbols or (2 * e / sympy.pi).is_Integer:
        return value
    return Value(sympy.Float(sympy.N(e, PRECISION), PRECISION), value.approx)


def _precise_robot(robot: Robot) -> Robot:
    """The robot with its angles and lengths made precise: every entry of its geometry is then a
    number (a rational or a 60-digit float) or, with symbolic parameters, a function of them."""
    def pose(p: Pose) -> Pose:
        return Pose(tuple(map(_precise_length, p.xyz)), tuple(map(_precise_angle, p.rpy)))

    def offset(joint):
        return _precise_angle(joint.offset) if joint.revolute else _precise_length(joint.offset)

    joints = tuple(replace(j, a=_precise_length(j.a), alpha=_precise_angle(j.alpha), offset=offset(j),
                           d=None if j.d is None else _precise_length(j.d),
                           theta=None if j.theta is None else _precise_angle(j.theta))
                   for j in robot.joints)
    return replace(robot, joints=joints, base=pose(robot.base), tool=pose(robot.tool))


def squared_norm(v: Matrix) -> sympy.Expr:
    return v.dot(v)


class Geometry:
    """Joint axes (unit directions, a point on each) and tool pose at q = 0, in the world frame,
    exact (irrational numbers to 60 digits), and the relations between the axes.

    With a `free` joint, that joint is held at the angle of the symbols (c_k, s_k) and left
    out of the axes: the geometry is that of the remaining chain; with `generic`, at the first
    of the generic angles `is_zero` tries instead (numbers only, a fraction of the cost).
    `joints` gives the robot's joint of each axis, `signs` whether the solver's angle is the
    robot's (1) or its negative."""

    def __init__(self, robot: Robot, free: int | None = None, generic: bool = False):
        n = robot.dof
        precise = _precise_robot(robot)

        def cos_sin(i):
            if i == free:
                symbols = kinematics.trig_symbols((i,), n)
                return tuple(_generic_points(set(symbols))[0][s] for s in symbols) if generic else symbols
            return (sympy.cos(precise.joints[i].offset.exact), sympy.sin(precise.joints[i].offset.exact))

        chain = kinematics.build_chain(precise, cos_sin, [sympy.Integer(0)] * n)
        self.joints = tuple(i for i in range(n) if i != free)
        self.signs = (1,) * len(self.joints)
        self.free = free
        self.revolute = tuple(robot.joints[i].revolute for i in self.joints)
        self.axes = tuple(chain.axes[i][:3, 2] for i in self.joints)
        self.points = tuple(chain.axes[i][:3, 3] for i in self.joints)
        self.normals = tuple(chain.axes[i][:3, 0] for i in self.joints)  # unit, across each axis
        self.tool = chain.tool
        self.tool_point = self.tool[:3, 3]
        self.start = None  # reversed: the pose T(0) of the chain forwards (the target is T(0) T^-1)

    def reversed(self) -> "Geometry":
        """The chain from the tool back to the base. With T(q) = exp(xi_1 q_1) ... exp(xi_n q_n)
        T(0), T(0) T(q)^-1 = exp(xi_n (-q_n)) ... exp(xi_1 (-q_1)): the same axes in reverse
        order, angles negated, target T(0) T^-1 and the identity as the tool."""
        other = copy.copy(self)
        for name in ("joints", "signs", "revolute", "axes", "points", "normals"):
            setattr(other, name, getattr(self, name)[::-1])
        other.signs = tuple(-sign for sign in other.signs)
        other.tool, other.start = sympy.eye(4), self.tool
        other.tool_point = other.tool[:3, 3]
        return other

    def parallel(self, i: int, j: int) -> bool:
        return is_zero(squared_norm(self.axes[i].cross(self.axes[j])))

    def on_axis(self, point: Matrix, i: int) -> bool:
        return is_zero(squared_norm((point - self.points[i]).cross(self.axes[i])))

    def same_line(self, i: int, j: int) -> bool:
        return self.parallel(i, j) and self.on_axis(self.points[j], i)

    def intersection(self, i: int, j: int) -> Matrix | None:
        """The point where axes i and j cross, None when they are parallel or skew."""
        normal = self.axes[i].cross(self.axes[j])
        if is_zero(squared_norm(normal)):
            return None
        offset = self.points[j] - self.points[i]
        if not is_zero(offset.dot(normal)):
            return None
        along = offset.cross(self.axes[j]).dot(normal) / squared_norm(normal)
        return (self.points[i] + along * self.axes[i]).applyfunc(readable)

    def wrist_centre(self, i: int) -> Matrix | None:
        """The point where revolute axes i, i+1, i+2 meet (consecutive ones not parallel), else None."""
        if not all(self.revolute[i:i + 3]):
            return None
        point = self.intersection(i, i + 1)
        if point is None or self.parallel(i + 1, i + 2) or not self.on_axis(point, i + 2):
            return None
        return point


def _point_text(point: Matrix) -> str:
    if any(e.free_symbols for e in point):
        return "(" + ", ".join(str(readable(e)) for e in point) + ")"
    return "(" + ", ".join(f"{float(e):.6g}" for e in point) + ")"


def _spherical_wrist(g: Geometry) -> tuple[str | None, str]:
    """Solver and reason for a six-joint arm whose axes 4, 5, 6 might meet in one point."""
    centre = g.wrist_centre(3)
    if centre is None:
        return None, "no spherical wrist (axes 4, 5, 6 do not meet in one point)"
    wrist = f"spherical wrist: axes 4, 5, 6 meet at {_point_text(centre)}"
    rev = g.revolute
    if all(rev[:3]) and g.parallel(1, 2) and not g.parallel(0, 1):
        if g.same_line(1, 2) or g.on_axis(centre, 2):
            return None, f"{wrist}, but axes 2 and 3 coincide or the wrist centre lies on axis 3"
        return "spherical_wrist_parallel", f"{wrist}; axes 2 and 3 parallel"
    x12 = g.intersection(0, 1) if rev[0] and rev[1] else None
    if x12 is None:
        return None, f"{wrist}, but neither axes 2, 3 parallel nor axes 1, 2 intersecting"
    shoulder = f"axes 1 and 2 intersect at {_point_text(x12)}"
    if not rev[2]:
        return "spherical_wrist_prismatic", f"{wrist}; {shoulder}; joint 3 prismatic"
    if g.on_axis(x12, 2) or g.on_axis(centre, 2):
        return None, f"{wrist}; {shoulder}, but axis 3 passes through that point or the wrist centre"
    return "spherical_wrist_intersecting", f"{wrist}; {shoulder}"


def _three_parallel(g: Geometry) -> tuple[str | None, str]:
    """Solver and reason for a six-joint arm whose axes 2, 3, 4 might be parallel."""
    if not (all(g.revolute) and g.parallel(1, 2) and g.parallel(2, 3)):
        return None, "no three parallel revolute axes 2, 3, 4"
    point = g.intersection(4, 5)
    if point is None:
        return None, "axes 2, 3, 4 parallel, but axes 5 and 6 do not intersect"
    if g.parallel(0, 1) or g.parallel(4, 1):
        return None, "axes 2, 3, 4 parallel, but axis 1 or axis 5 is parallel to them too"
    if g.same_line(1, 2) or g.same_line(2, 3):
        return None, "axes 2, 3, 4 parallel, but two of them coincide"
    return "three_parallel", f"axes 2, 3, 4 parallel; axes 5 and 6 intersect at {_point_text(point)}"


def _six_dof(g: Geometry) -> tuple[str | None, str, Geometry | None]:
    """Solver, reason and the chain it solves for a six-joint arm with a full-pose task: the
    first class that applies to the chain, else to the chain reversed (a spherical shoulder)."""
    reasons = []
    for chain, how in ((g, ""), (g.reversed(), "reversed (axes numbered from the tool): ")):
        for candidate in (_spherical_wrist, _three_parallel):
            solver, reason = candidate(chain)
            if solver is not None:
                return solver, how + reason, chain
            reasons.append(reason)
    forward, backward = reasons[:2], reasons[2:]
    if forward == backward:
        return None, "; ".join(forward) + " (axes numbered from the base, and from the tool)", None
    return None, "; ".join(forward + [f"reversed (axes numbered from the tool): {reason}" for reason in backward]), None


def _free_joint(robot: Robot) -> tuple[str | None, str, Geometry | None]:
    """Solver, reason and chain for a seven-joint arm: the six-joint chain left when the free
    joint (the file's `ik.free_joint`, else the first of joints 7, 6, ..., 1 that leaves a
    solvable chain) is an input."""
    candidates = (robot.free_joint,) if robot.free_joint is not None else range(robot.dof - 1, -1, -1)
    reasons: dict[str, list[str]] = {}  # each reason once, with the joints whose chain it rules out
    for free in candidates:
        if not robot.joints[free].revolute:
            continue
        # A relation that holds for every free angle holds at the first generic one: a chain
        # without a class there has none (and the exact chain of c_k, s_k is not built).
        solver, reason, chain = _six_dof(Geometry(robot, free, generic=True))
        if solver is not None:
            solver, reason, chain = _six_dof(Geometry(robot, free))
        if solver is not None:
            return solver, f"joint {free + 1} free (an input of ik), the other six: {reason}", chain
        reasons.setdefault(reason, []).append(str(free + 1))
    return None, "; ".join(f"joint{'s' * (len(joints) > 1)} {', '.join(joints)} free: {reason}"
                           for reason, joints in reasons.items()) or "no revolute joint to leave free", None


def _planar_class(g: Geometry, task: tuple[str, ...]) -> tuple[str | None, str] | None:
    """Solver and reason for an arm whose axes are all parallel to world z (None: not such an arm)."""
    if not all(is_zero(squared_norm(h.cross(E_Z))) for h in g.axes):
        return None
    revolute = [i for i, r in enumerate(g.revolute) if r]
    prismatic = [i for i, r in enumerate(g.revolute) if not r]
    expected = ("x", "y") + (("z",) if prismatic else ()) + (("yaw",) if len(revolute) == 3 else ())
    if len(revolute) not in (2, 3) or len(prismatic) > 1 or task != expected:
        return None, (f"axes parallel to world z, but {len(revolute)} revolute and {len(prismatic)} "
                      f"prismatic joints with task ({', '.join(task)}): the planar solver needs 2 or 3 "
                      f"revolute joints, at most one prismatic, and the task (x, y[, z][, yaw])")
    first, second = revolute[:2]
    point = g.points[revolute[2]] if len(revolute) == 3 else g.tool_point
    if g.same_line(first, second):
        return None, f"axes {first + 1} and {second + 1} coincide"
    if g.on_axis(point, second):
        what = f"axis {revolute[2] + 1}" if len(revolute) == 3 else "the tool point"
        return None, f"{what} lies on axis {second + 1}: the arm cannot reach around"
    if "yaw" in task and is_zero(g.tool[0, 0] ** 2 + g.tool[1, 0] ** 2):
        return None, "the tool's x axis is vertical at q = 0: yaw is undefined"
    kinds = {2: "2R", 3: "3R"}[len(revolute)] + (" + prismatic z" if prismatic else "")
    return "planar", f"planar {kinds}: every axis parallel to world z"


def _yaw_pitch_class(g: Geometry, task: tuple[str, ...]) -> tuple[str | None, str] | None:
    """Solver and reason for a base-yaw + three-pitch arm (None: not such an arm)."""
    if len(g.axes) != 4 or not all(g.revolute) or task != ("x", "y", "z", "pitch"):
        return None
    if not is_zero(squared_norm(g.axes[0].cross(E_Z))):
        return None, "task (x, y, z, pitch) but axis 1 is not vertical"
    if not (g.parallel(1, 2) and g.parallel(2, 3)) or g.parallel(0, 1):
        return None, "task (x, y, z, pitch) but axes 2, 3, 4 are not parallel pitch axes"
    if g.same_line(1, 2) or g.same_line(2, 3):
        return None, "axes 2, 3, 4 parallel, but two of them coincide"
    if is_zero(squared_norm(g.tool[:3, 0].cross(g.axes[1]))):
        return None, "the tool's x axis is parallel to the pitch axes: the pitch does not change"
    return "yaw_pitch", "axis 1 vertical (yaw); axes 2, 3, 4 parallel (pitch)"


def classify(robot: Robot, geometry: Geometry | None = None) -> Structure:
    """The structure of `robot` and the closed-form solver that applies to it, if any."""
    g = geometry or Geometry(robot)
    n, task = robot.dof, robot.task
    if task == TASK_COMPONENTS:
        general = all(g.revolute) and not robot.symbolic_parameters
        if n == 6:
            solver, reason, chain = _six_dof(g)
            if solver is None and general:
                solver, reason = "general_6r", f"no special class: {reason}"
        elif n == 7:
            solver, reason, chain = _free_joint(robot)
            if solver is None and general and robot.free_joint in (None, 0, 6):
                solver, reason = "general_6r", f"joint 1 or 7 free, the other six: no special class ({reason})"
        elif n > 7:
            solver, reason, chain = None, f"{n} joints for a 6-component task: redundant, infinitely many solutions", None
        else:
            solver, reason, chain = None, f"{n} joints cannot reach every pose of a 6-component task", None
        return Structure(solver, reason, chain)
    for candidate in (_planar_class, _yaw_pitch_class):
        found = candidate(g, task)
        if found is not None:
            return Structure(found[0], found[1], g)
    return Structure(None, (
        f"{n} joints with task ({', '.join(task)}): closed forms exist for planar arms (axes parallel "
        f"to world z, task x, y[, z][, yaw]) and base yaw + three parallel pitch axes (task x, y, z, pitch)"))
