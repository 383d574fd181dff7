"""Closed-form inverse kinematics: the exact constants each solver class needs.

One solver per structure class (see `structure.SOLVERS`) serves every robot of that class:
the algorithm is a template (`templates/*/ik*.jinja`) built from Paden-Kahan subproblems,
and what differs between robots is only their geometry at q = 0 (axis directions, points on
the axes, the tool pose), computed here with sympy (exactly; irrational numbers to 60 digits,
see `structure.Geometry`) and emitted as literals, or as expressions in the symbolic parameters. The subproblems, on vectors relative to a point of
the axis:

- SP1: the angle turning p into q about the unit axis k;
- SP2: the angles (t1, t2) with rot(k1, t1) rot(k2, t2) p = q (axes through one point);
- SP3: the angles turning p about k to the distance d from q (reduces to SP4);
- SP4: the angles with h . rot(k, t) p = d.
"""

import textwrap
from dataclasses import dataclass

import sympy

from .structure import E_Z, SOLVERS, Geometry, SolverInfo, classify, is_zero, squared_norm, tidy

Matrix = sympy.Matrix

DOC_WIDTH = 88  # characters per line of the generated documentation
# Relative tolerances of the generated solvers, by real type. A discriminant (a squared sine)
# within EPS of 0 is one double root: tangent targets and targets on a singularity give one
# solution, not two copies, and a target out of reach by less than that still gets it. A
# vector whose squared length is below TINY times its scale is treated as zero (an SP1 with
# a free angle returns 0).
TOLERANCES = {"double": {"eps": 1e-12, "tiny": 1e-24}, "float": {"eps": 1e-6, "tiny": 1e-12}}


@dataclass(frozen=True)
class ClosedForm:
    """A robot's closed-form solver: its class, its constants and the target it takes."""

    solver: str
    info: SolverInfo
    target: str  # "pose" (4x4) or "task" (the task vector mu)
    constants: tuple[tuple[str, sympy.Matrix], ...]  # name -> 3x1, 3x3 or 1x1 exact values
    indices: tuple[tuple[str, int], ...]  # named joint indices the planar skeleton places
    helpers: tuple[str, ...]  # the template's helper functions, in dependency order
    flip: bool  # axis 5 perpendicular to its neighbours: a second wrist root follows from the first


def _unit(v: Matrix) -> Matrix:
    return (v / sympy.sqrt(squared_norm(v))).applyfunc(tidy)


def perpendicular(h: Matrix, nominal: dict) -> Matrix:
    """A unit vector perpendicular to the unit vector h: from the world axis least along h
    (at the parameters' nominal values)."""
    basis = [Matrix([1, 0, 0]), Matrix([0, 1, 0]), E_Z]
    e = min(basis, key=lambda b: abs(float(sympy.N(b.dot(h).subs(nominal)))))
    return _unit(e - e.dot(h) * h)


def _scalar(value) -> Matrix:
    return Matrix([tidy(value)])


def _pose(g: Geometry) -> list[tuple[str, Matrix]]:
    """The tool pose at q = 0, from which the solver forms T T(0)^-1 = exp(xi_1 q_1) ... ."""
    return [("tool_rotation", g.tool[:3, :3]), ("tool_position", g.tool[:3, 3])]


def _wrist(g: Geometry) -> list[tuple[str, Matrix]]:
    h = g.axes
    return [("h4", h[3]), ("h5", h[4]), ("h6", h[5]), ("v6", perpendicular(h[5], g.nominal)),
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
        ("h1", h[0]), ("p1", p[0]), ("h", h[1]), ("v", perpendicular(h[1], g.nominal)), ("p2", p[1]),
        ("h3", h[2]), ("p3", p[2]), ("p4", p[3]), ("h5", h[4]), ("h6", h[5]), ("centre", centre),
        ("reach", _scalar(h[1].dot(centre - p[0]))),
        ("sign3", _scalar(h[1].dot(h[2]))), ("sign4", _scalar(h[1].dot(h[3]))),
    ], []


# The helper functions each solver's template calls, in dependency order ("wrist" becomes
# "wrist_perpendicular" when the solver can flip, see _FLIPS).
HELPERS = {
    "planar": ("vectors", "sp1", "sp4", "sp3"),
    "yaw_pitch": ("vectors", "sp1", "sp4", "sp3"),
    "spherical_wrist_parallel": ("vectors", "sp1", "sp4", "sp3", "sp2", "relative", "wrist"),
    "spherical_wrist_intersecting": ("vectors", "sp1", "sp4", "sp3", "sp2", "relative", "wrist"),
    "spherical_wrist_prismatic": ("vectors", "sp1", "sp2", "relative", "wrist"),
    "three_parallel": ("vectors", "sp1", "sp4", "sp3", "relative", "transpose"),
}

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


def closed_form(robot) -> ClosedForm | None:
    """The closed-form solver of `robot` with its exact constants, None when no class applies."""
    geometry = Geometry(robot)
    structure = classify(robot, geometry)
    if structure.solver is None:
        return None
    constants, indices = _CONSTANTS[structure.solver](geometry)
    target = "pose" if len(robot.task) == 6 else "task"
    h = geometry.axes
    flip = structure.solver in _FLIPS and all(is_zero(h[4].dot(h[i])) for i in _FLIPS[structure.solver])
    helpers = tuple("wrist_perpendicular" if helper == "wrist" and flip else helper
                    for helper in HELPERS[structure.solver])
    if flip and "wrist" in HELPERS[structure.solver]:
        turn = sympy.atan2(h[4].dot(h[3].cross(h[5])), h[3].dot(h[5]))  # h6 = rot(h5, turn) h4
        constants.append(("wrist_flip", _scalar(-2 * turn)))
    return ClosedForm(structure.solver, SOLVERS[structure.solver], target,
                      tuple((name, Matrix(value)) for name, value in constants), tuple(indices), helpers, flip)


def documentation(robot, form: ClosedForm, max_name: str) -> list[str]:
    """The generated ik's documentation: target, result, solver and the order of the branches."""
    if form.target == "pose":
        target = "target: the 4x4 tool pose in the world frame (rotation part orthonormal)."
    else:
        target = f"target: the task vector ({', '.join(robot.task)})" + (
            ", pitch in [-pi/2, pi/2]." if "pitch" in robot.task else ".")
    text = [
        target,
        f"Result: k <= {max_name} solutions, revolute angles wrapped into (-pi, pi], joint limits "
        "not applied; k = 0 when the target is out of reach or not finite.",
        f"Solver: {form.info.title}.",
        "Order: nested loops over the branches, outermost first; where a subproblem has two roots "
        "phi +- alpha (alpha in (0, pi)), phi + alpha ('+') comes first:",
    ]
    lines = [line for paragraph in text for line in textwrap.wrap(paragraph, DOC_WIDTH)]
    lines += [f"  {line}" for branch in form.info.branches for line in textwrap.wrap(branch, DOC_WIDTH - 2)]
    notes = ("A branch the target does not allow is skipped; the others keep their order. A double "
             "root (a target on a singularity or on the workspace boundary) is returned once, and an "
             "angle the target leaves free (a singular wrist or shoulder) is set to 0.")
    return lines + textwrap.wrap(notes, DOC_WIDTH)
