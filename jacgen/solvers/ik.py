"""Closed-form inverse kinematics: each solver class, written once as expressions.

One solver per structure class (see `structure.SOLVERS`) serves every robot of that class.
What differs between robots is only their geometry at q = 0 (axis directions, points on
the axes, the tool pose), computed here with sympy (exactly; irrational numbers to 60
digits, see `structure.Geometry`) as the solver's constants, or as expressions in the
symbolic parameters. The solvers (below the constants) build every branch from the
Paden-Kahan subproblems of `subproblems.py`, and the fk pipeline prints them for every
backend as `ik_branches`.
"""

from dataclasses import dataclass

import numpy
import sympy

from jacgen.model.nearest_class import Nominal, nearest_class
from jacgen.model.node import AND, Node
from jacgen.model.structure import E_Z, SOLVERS, Geometry, SolverInfo, Structure, classify, is_zero, readable
from jacgen.model.tolerance_symbols import EPS
from jacgen.solvers import general6r, general6r_plan
from jacgen.solvers.ik_limits import limited
from jacgen.solvers.subproblems import Angle, Root, Subproblems, relative, times, times_transposed

Matrix = sympy.Matrix


@dataclass(frozen=True)
class ClosedForm:
    """A robot's closed-form solver: its class, its constants and the target it takes."""

    solver: str
    info: SolverInfo
    target: str  # "pose" (4x4) or "task" (the task vector mu)
    constants: tuple[tuple[str, sympy.Matrix], ...]  # name -> 3x1, 3x3 or 1x1 exact values
    indices: tuple[tuple[str, int], ...]  # named joint indices the planar skeleton places
    flip: bool  # axis 5 perpendicular to its neighbours: a second wrist root follows from the first
    joints: tuple[int, ...]  # the robot's joint of each of the solver's joints
    signs: tuple[int, ...]  # -1 where the solver turns the robot's joint the other way (a reversed chain)
    free: int | None  # the joint ik takes as an input (a 7-joint arm), else None
    elimination: "general6r_plan.Elimination | None" = None  # the general 6R solver's split (solver general_6r)
    fast_path: "FastPath | None" = None  # general_6r: a calibrated arm's nominal closed form


@dataclass(frozen=True)
class FastPath:
    """A calibrated arm's fast path (see general6r.FAST_STEPS): the nominal arm, its closed
    form, and bounds on how far the two arms' tool poses differ at one configuration."""

    nominal: Nominal
    form: ClosedForm
    position: float  # in the robot's length unit
    rotation: float  # rad


def _scalar(value) -> Matrix:
    return Matrix([readable(value)])


def _pose(g: Geometry) -> list[tuple[str, Matrix]]:
    """The tool pose at q = 0, from which the solver forms T T(0)^-1 = exp(xi_1 q_1) ... ."""
    return [("tool_rotation", g.tool[:3, :3]), ("tool_position", g.tool[:3, 3])]


def _wrist(g: Geometry) -> list[tuple[str, Matrix]]:
    h = g.axes
    return [("h4", h[3]), ("h5", h[4]), ("h6", h[5]), ("v6", g.normals[5]),
            ("centre", g.wrist_centre(3))]


def _planar(g: Geometry) -> tuple[list, list]:
    revolute = [i for i, r in enumerate(g.revolute) if r]
    prismatic = [i for i, r in enumerate(g.revolute) if not r]
    first, second = revolute[:2]
    sign = [g.axes[i].dot(E_Z) for i in range(len(g.axes))]
    wrist = g.points[revolute[2]] if len(revolute) == 3 else g.tool_point
    constants = [("k1", g.axes[first]), ("p1", g.points[first]), ("k2", g.axes[second]),
                 ("p2", g.points[second]), ("wrist", wrist), ("tool_point", g.tool_point)]
    indices = [("first", first), ("second", second)]
    if len(revolute) == 3:
        yaw = sympy.atan2(g.tool[1, 0], g.tool[0, 0])
        constants += [("yaw0", _scalar(yaw)), ("sign1", _scalar(sign[first])),
                      ("sign2", _scalar(sign[second])), ("sign3", _scalar(sign[revolute[2]]))]
        indices.append(("third", revolute[2]))
    if prismatic:
        constants.append(("sign_slide", _scalar(sign[prismatic[0]])))
        indices.append(("slide", prismatic[0]))
    return constants, indices


def _yaw_pitch(g: Geometry) -> tuple[list, list]:
    h, p = g.axes, g.points
    return [("h1", h[0]), ("p1", p[0]), ("h2", h[1]), ("p2", p[1]), ("h3", h[2]), ("p3", p[2]),
            ("p4", p[3]), ("tool_x", g.tool[:3, 0]), ("tool_point", g.tool_point),
            ("reach", _scalar(h[1].dot(g.tool_point - p[0]))),
            ("sign3", _scalar(h[1].dot(h[2]))), ("sign4", _scalar(h[1].dot(h[3])))], []


def _spherical_wrist_parallel(g: Geometry) -> tuple[list, list]:
    h, p = g.axes, g.points
    centre = g.wrist_centre(3)
    return _pose(g) + [("h1", h[0]), ("p1", p[0]), ("h2", h[1]), ("p2", p[1]), ("h3", h[2]),
                       ("p3", p[2]), ("reach", _scalar(h[1].dot(centre - p[0]))),
                       ("sign3", _scalar(h[1].dot(h[2])))] + _wrist(g), []


def _spherical_wrist_intersecting(g: Geometry) -> tuple[list, list]:
    h, p = g.axes, g.points
    return _pose(g) + [("h1", h[0]), ("h2", h[1]), ("shoulder", g.intersection(0, 1)), ("h3", h[2]),
                       ("p3", p[2])] + _wrist(g), []


def _spherical_wrist_prismatic(g: Geometry) -> tuple[list, list]:
    h = g.axes
    return _pose(g) + [("h1", h[0]), ("h2", h[1]), ("shoulder", g.intersection(0, 1)),
                       ("h3", h[2])] + _wrist(g), []


def _three_parallel(g: Geometry) -> tuple[list, list]:
    h, p = g.axes, g.points
    centre = g.intersection(4, 5)
    return _pose(g) + [
        ("h1", h[0]), ("p1", p[0]), ("h", h[1]), ("v", g.normals[1]), ("p2", p[1]),
        ("h3", h[2]), ("p3", p[2]), ("p4", p[3]), ("h5", h[4]), ("h6", h[5]), ("centre", centre),
        ("reach", _scalar(h[1].dot(centre - p[0]))),
        ("sign3", _scalar(h[1].dot(h[2]))), ("sign4", _scalar(h[1].dot(h[3]))),
    ], []


# Solvers whose wrist has a second root that follows from the first when axis 5 is
# perpendicular to the axes listed (0-based): rot(a, pi) rot(h5, x) = rot(h5, -x) rot(a, pi) for
# a perpendicular to h5. Spherical wrist: (q4 + pi, wrist_flip - q5, q6 + pi), wrist_flip =
# -2 angle(h4 -> h6 about h5); axes 2, 3, 4 parallel to h: q6 + pi and q2 + q3 + q4 + pi.
_FLIPS = {"spherical_wrist_parallel": (3, 5), "spherical_wrist_intersecting": (3, 5),
          "spherical_wrist_prismatic": (3, 5), "three_parallel": (1, 5)}

_CONSTANTS = {
    "planar": _planar,
    "yaw_pitch": _yaw_pitch,
    "spherical_wrist_parallel": _spherical_wrist_parallel,
    "spherical_wrist_intersecting": _spherical_wrist_intersecting,
    "spherical_wrist_prismatic": _spherical_wrist_prismatic,
    "three_parallel": _three_parallel,
}


def closed_form(robot, geometry: Geometry | None = None, structure: Structure | None = None) -> ClosedForm | None:
    """The closed-form solver of `robot` with its exact constants, None when no class applies
    (pass the robot's geometry and structure when they are known: see `model.Model`)."""
    structure = structure or classify(robot, geometry)
    if structure.solver is None:
        return None
    if structure.solver == "general_6r":
        return _general(robot)
    chain = structure.chain
    constants, indices = _CONSTANTS[structure.solver](chain)
    if chain.start is not None:  # a reversed chain: its target is T(0) T^-1
        constants += [("start_rotation", chain.start[:3, :3]), ("start_position", chain.start[:3, 3])]
    target = "pose" if len(robot.task) == 6 else "task"
    h = chain.axes
    flip = structure.solver in _FLIPS and all(is_zero(h[4].dot(h[i])) for i in _FLIPS[structure.solver])
    if flip and structure.solver.startswith("spherical_wrist"):
        turn = sympy.atan2(readable(h[4].dot(h[3].cross(h[5]))), readable(h[3].dot(h[5])))  # h6 = rot(h5, turn) h4
        constants.append(("wrist_flip", _scalar(-2 * turn)))
    return ClosedForm(structure.solver, SOLVERS[structure.solver], target,
                      tuple((name, Matrix(value)) for name, value in constants), tuple(indices), flip,
                      chain.joints, chain.signs, chain.free)


def _general(robot) -> ClosedForm | None:
    """The general 6R solver of a 6R arm, or of a 7R arm with its first or last joint free (the
    file's `ik.free_joint`, else the one whose split rates better); with the fast path when a
    special class is near. None when no split is conditioned well enough."""
    candidates = (None,) if robot.dof == 6 else (robot.free_joint,) if robot.free_joint is not None else (6, 0)
    plan, free = min(((general6r_plan.elimination(robot, free), free) for free in candidates),
                     key=lambda pair: pair[0].condition)
    if plan.condition > general6r_plan.WORST_CONDITION:
        return None
    nominal = nearest_class(robot, free) if robot.nearest_class else None
    fast_path = nominal and FastPath(nominal, closed_form(nominal.robot, structure=nominal.structure),
                                     *general6r.mismatch(robot, nominal.robot))
    joints = tuple(j for j in range(robot.dof) if j != free)
    return ClosedForm("general_6r", SOLVERS["general_6r"], "pose", (), (), False, joints, (1,) * 6, free, plan,
                      fast_path)


# -- The solvers, as expressions (see `subproblems`) -------------------------------------------
# Each returns the branches in the documented order: (joint values, validity), one per
# solution the class can have; `k` holds the constants of `closed_form`.

Branches = list[tuple[tuple[Node, ...], Node]]


def _planar_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """The last revolute joint takes the yaw, the first two put its axis on the wrist point
    by SP3 (elbow) and SP1 (shoulder); rotations about z keep heights."""
    g, index = sp.graph, dict(form.indices)
    point = (target[0], target[1], k["tool_point"][2])
    if "third" in index:
        phi = sp.name(target[-1] - k["yaw0"])
        point = sp.sub(point, sp.rot(sp.vector((0, 0, 1)), sp.name(g.call("cos", phi)), sp.name(g.call("sin", phi)),
                                     sp.sub(k["tool_point"], k["wrist"])))
    d = sp.sub(point, k["p1"])
    branches = []
    for elbow in sp.sp3(sp.sub(k["wrist"], k["p2"]), sp.sub(k["p1"], k["p2"]), k["k2"], d):
        shoulder = sp.sp1(sp.sub(sp.add(k["p2"], sp.turn(k["k2"], elbow.angle, sp.sub(k["wrist"], k["p2"]))), k["p1"]),
                          d, k["k1"])
        q = [g.number(0)] * dof
        q[index["first"]], q[index["second"]] = shoulder.theta, elbow.angle.theta
        if "third" in index:
            q[index["third"]] = k["sign3"] * (phi - k["sign1"] * shoulder.theta - k["sign2"] * elbow.angle.theta)
        if "slide" in index:
            q[index["slide"]] = k["sign_slide"] * (target[2] - k["tool_point"][2])
        branches.append((tuple(q), elbow.valid))
    return branches


def _yaw_pitch_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """The pitch fixes the sum phi of the pitch angles (SP4 on the tool's x axis), the base
    yaw puts the target in the arm's plane (SP4), and the wrist point is reached by SP3
    (elbow) and SP1 (shoulder). A pitch beyond +-pi/2 has no solution."""
    g, point = sp.graph, tuple(target[:3])
    pitch_valid = g.relation("<=", g.call("Abs", target[3]), g.value(sympy.pi / 2))
    approaches = sp.sp4(sp.vector((0, 0, 1)), k["tool_x"], k["h2"], sp.name(-g.call("sin", target[3])),
                        across=sp.name(g.call("cos", target[3])**2))
    branches = []
    for base in sp.sp4(sp.sub(point, k["p1"]), k["h2"], k["h1"], k["reach"]):
        w = sp.add(k["p1"], sp.turn(k["h1"], base.angle, sp.sub(point, k["p1"]), back=True))
        for phi in approaches:
            wrist = sp.sub(w, sp.turn(k["h2"], phi.angle, sp.sub(k["tool_point"], k["p4"])))
            d = sp.sub(wrist, k["p2"])
            for elbow in sp.sp3(sp.sub(k["p4"], k["p3"]), sp.sub(k["p2"], k["p3"]), k["h3"], d):
                shoulder = sp.sp1(sp.sub(sp.add(k["p3"], sp.turn(k["h3"], elbow.angle, sp.sub(k["p4"], k["p3"]))), k["p2"]),
                                  d, k["h2"])
                last = k["sign4"] * (phi.angle.theta - shoulder.theta - k["sign3"] * elbow.angle.theta)
                branches.append(((base.angle.theta, shoulder.theta, elbow.angle.theta, last),
                                 g.logic(AND, pitch_valid, base.valid, phi.valid, elbow.valid)))
    return branches


def _pose_start(sp: Subproblems, k: dict, target):
    """R, t of T T(0)^-1, the wrist centre and the tool axes h6, v6 in the world frame."""
    R, t = relative(sp, target, k["tool_rotation"], k["tool_position"])
    return R, t, sp.add(times(sp, R, k["centre"]), t)


def _wrist_branches(sp: Subproblems, k: dict, R, turns, shoulder: tuple, valid) -> Branches:
    """The spherical wrist's solutions after the arm's `turns` (axis, angle) undone from the
    tool axes, appended to the arm's `shoulder` joint values."""
    a, b = times(sp, R, k["h6"]), times(sp, R, k["v6"])
    for axis, angle in turns:
        a, b = sp.turn(axis, angle, a, back=True), sp.turn(axis, angle, b, back=True)
    return [(shoulder + q, sp.graph.logic(AND, valid, wrist_valid))
            for q, wrist_valid in sp.wrist(a, b, k["h4"], k["h5"], k["h6"], k["v6"], k.get("wrist_flip"))]


def _spherical_wrist_parallel_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """The wrist centre fixes q1 (SP4: its height along axis 2 is constant), q3 (SP3) and
    q2 (SP1); the orientation left to the wrist gives q4, q5, q6."""
    R, _, wc = _pose_start(sp, k, target)
    branches = []
    for t1 in sp.sp4(sp.sub(wc, k["p1"]), k["h2"], k["h1"], k["reach"]):
        with sp.given(t1.valid):
            d = sp.sub(sp.add(k["p1"], sp.turn(k["h1"], t1.angle, sp.sub(wc, k["p1"]), back=True)), k["p2"])
            for t3 in sp.sp3(sp.sub(k["centre"], k["p3"]), sp.sub(k["p2"], k["p3"]), k["h3"], d):
                with sp.given(t3.valid):
                    t2 = sp.sp1(sp.sub(sp.add(k["p3"], sp.turn(k["h3"], t3.angle, sp.sub(k["centre"], k["p3"]))),
                                       k["p2"]), d, k["h2"])
                    # R2 R3 = rot(h2, q2 + sign3 q3), h3 = sign3 h2: one turn back for both
                    c23 = t2.c * t3.angle.c - k["sign3"] * t2.s * t3.angle.s
                    s23 = t2.s * t3.angle.c + k["sign3"] * t2.c * t3.angle.s
                    turns = ((k["h1"], t1.angle), (k["h2"], Angle(None, sp.name(c23), sp.name(s23))))
                    branches += _wrist_branches(sp, k, R, turns, (t1.angle.theta, t2.theta, t3.angle.theta),
                                                sp.graph.logic(AND, t1.valid, t3.valid))
    return branches


def _spherical_wrist_intersecting_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """The wrist centre's distance from the shoulder point fixes q3 (SP3), its position q1
    and q2 (SP2); the orientation left to the wrist gives q4, q5, q6."""
    R, _, wc = _pose_start(sp, k, target)
    d = sp.sub(wc, k["shoulder"])
    branches = []
    for t3 in sp.sp3(sp.sub(k["centre"], k["p3"]), sp.sub(k["shoulder"], k["p3"]), k["h3"], d):
        with sp.given(t3.valid):
            reached = sp.sub(sp.add(k["p3"], sp.turn(k["h3"], t3.angle, sp.sub(k["centre"], k["p3"]))), k["shoulder"])
            for t1, t2, valid in sp.sp2(reached, d, k["h1"], k["h2"]):
                with sp.given(valid):
                    turns = ((k["h1"], t1), (k["h2"], t2), (k["h3"], t3.angle))
                    branches += _wrist_branches(sp, k, R, turns, (t1.theta, t2.theta, t3.angle.theta),
                                                sp.graph.logic(AND, t3.valid, valid))
    return branches


def _spherical_wrist_prismatic_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """The wrist centre's distance from the shoulder point fixes q3 (|e + q3 h3| = |d|, a
    quadratic), its position q1 and q2 (SP2); the orientation left to the wrist gives q4,
    q5, q6."""
    g = sp.graph
    R, _, wc = _pose_start(sp, k, target)
    d = sp.sub(wc, k["shoulder"])
    e = sp.sub(k["centre"], k["shoulder"])
    half, rest = sp.dot(k["h3"], e), sp.name(sp.dot(e, e) - sp.dot(d, d))
    disc = sp.name(half**2 - rest)
    scale = sp.name(sp.dot(e, e) + sp.dot(d, d))
    two = g.relation(">", disc, g.symbol(EPS) * scale)
    root = sp.name(sp.clamped_sqrt(disc))
    branches = []
    for t3, valid in ((sp.name(-half + root), g.relation(">=", disc, -g.symbol(EPS) * scale)), (sp.name(-half - root), two)):
        reached = sp.add(e, sp.scaled(k["h3"], t3))
        for t1, t2, shoulder_valid in sp.sp2(reached, d, k["h1"], k["h2"]):
            branches += _wrist_branches(sp, k, R, ((k["h1"], t1), (k["h2"], t2)), (t1.theta, t2.theta, t3),
                                        g.logic(AND, valid, shoulder_valid))
    return branches


def _three_parallel_branches(sp: Subproblems, k: dict, target, form: ClosedForm, dof: int) -> Branches:
    """Axes 2, 3, 4 parallel to h, axes 5 and 6 meeting at the wrist centre: the centre's
    height along h fixes q1 (SP4), the tool orientation q5 (SP4), q6 (SP1) and the sum
    q2 + q3 + q4 (SP1), the centre's position q3 (SP3) and q2 (SP1). With axis 5
    perpendicular to h and h6, the second q5 turns q6 and q2 + q3 + q4 by pi."""
    R, _, wc = _pose_start(sp, k, target)
    a = times(sp, R, k["h6"])
    h = k["h"]
    branches = []
    for t1 in sp.sp4(sp.sub(wc, k["p1"]), h, k["h1"], k["reach"]):
        with sp.given(t1.valid):
            g = sp.turn(k["h1"], t1.angle, h)
            w = sp.add(k["p1"], sp.turn(k["h1"], t1.angle, sp.sub(wc, k["p1"]), back=True))
            t6 = total = None  # set by the first root of q5
            ga = sp.cross(g, a)
            wrists = sp.sp4(h, k["h6"], k["h5"], sp.dot(g, a), across=sp.dot(ga, ga), between=(g, a))
            for j, t5 in enumerate(wrists):
                if j == 1 and form.flip:
                    # The flipped wrist is another configuration (q4 and q6 turned by pi, the elbow
                    # elsewhere) also where the two roots of q5 meet: valid with the first, or a pose
                    # whose q5 is within 1e-6 of 0 or pi could find only the flip it cannot reach.
                    t5 = Root(t5.angle, wrists[0].valid)
                    t6, total = t6.turned_half(), total.turned_half()
                with sp.given(t5.valid):
                    if j == 0 or not form.flip:
                        t6 = sp.sp1(times_transposed(sp, R, g), sp.turn(k["h5"], t5.angle, h, back=True), k["h6"])
                        x = sp.turn(k["h6"], t6, sp.turn(k["h5"], t5.angle, k["v"], back=True), back=True)
                        total = sp.sp1(k["v"], sp.turn(k["h1"], t1.angle, times(sp, R, x), back=True), h)
                    d = sp.sub(sp.sub(w, sp.turn(h, total, sp.sub(k["centre"], k["p4"]))), k["p2"])
                    for t3 in sp.sp3(sp.sub(k["p4"], k["p3"]), sp.sub(k["p2"], k["p3"]), k["h3"], d):
                        with sp.given(t3.valid):
                            t2 = sp.sp1(sp.sub(sp.add(k["p3"], sp.turn(k["h3"], t3.angle, sp.sub(k["p4"], k["p3"]))),
                                               k["p2"]), d, h)
                        t4 = k["sign4"] * (total.theta - t2.theta - k["sign3"] * t3.angle.theta)
                        branches.append(((t1.angle.theta, t2.theta, t3.angle.theta, t4, t5.angle.theta, t6.theta),
                                         sp.graph.logic(AND, t1.valid, t5.valid, t3.valid)))
    return branches


_BRANCHES = {
    "planar": _planar_branches,
    "yaw_pitch": _yaw_pitch_branches,
    "spherical_wrist_parallel": _spherical_wrist_parallel_branches,
    "spherical_wrist_intersecting": _spherical_wrist_intersecting_branches,
    "spherical_wrist_prismatic": _spherical_wrist_prismatic_branches,
    "three_parallel": _three_parallel_branches,
}


def _constant(g, value: Matrix):
    """A constant as the solvers use it, on the graph: a number, a 3-tuple, or a 3x3 array."""
    if value.shape == (1, 1):
        return g.value(value[0])
    return tuple(map(g.value, value)) if 1 in value.shape else g.values(value)


def _reversed_target(sp: Subproblems, k: dict, T) -> numpy.ndarray:
    """T(0) T^-1, the target of a reversed chain (see `structure.Geometry.reversed`)."""
    start, position = k["start_rotation"], k["start_position"]
    rotation = [[sp.name(sum(start[i, m] * T[j, m] for m in range(3))) for j in range(3)] for i in range(3)]
    offset = [sp.name(position[i] - sum(rotation[i][j] * T[j, 3] for j in range(3))) for i in range(3)]
    return sp.graph.values([row + [offset[i]] for i, row in enumerate(rotation)] + [[0, 0, 0, 1]])


def branches(robot, form: ClosedForm, sp: Subproblems, target, free_angle=None) -> tuple[numpy.ndarray, list, list]:
    """Every branch of the solver (MAX_IK_SOLUTIONS x DOF; revolute angles wrapped into
    (-pi, pi] or else into the limits, see `in_limits`; the free joint `free_angle` as given),
    whether the target allows it and whether it is inside the joint limits (MAX_IK_SOLUTIONS
    each). A branch is valid when the target allows it and every entry of the target read
    (not a pose's last row) is finite. `target` is the 4x4 pose or the task vector, as symbols."""
    g = sp.graph
    k = {name: _constant(g, value) for name, value in form.constants}
    target = g.values(target) if form.target == "pose" else g.values(target).flatten()
    solved = _BRANCHES[form.solver](sp, k, _reversed_target(sp, k, target) if "start_rotation" in k else target,
                                    form, len(form.joints))
    if len(solved) != form.info.max_solutions:
        raise AssertionError(f"{form.solver}: {len(solved)} branches, documented {form.info.max_solutions}")
    # One test for all entries: their sum is finite unless one is not (or they exceed 1e307).
    finite = g.finite(sp.name(sum((target[:3, :] if form.target == "pose" else target).flat)))
    rows, inside = [], []
    for values, _ in solved:
        q = [None if free_angle is None else g.value(free_angle)] * robot.dof
        for joint, sign, value in zip(form.joints, form.signs, values):
            q[joint] = sign * value
        q, row_inside = limited(robot, sp, q, form.joints, form.free)
        rows.append(q)
        inside.append(row_inside)
    return numpy.array(rows, dtype=object), [g.logic(AND, finite, valid) for _, valid in solved], inside
