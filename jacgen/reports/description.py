"""Words a person reads: DH table, task, singularities, dexterity and IK of a robot
(`jacgen show`, the generated NAME.md report)."""

import math

import numpy as np
import sympy

from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import EULER_ANGLES, Robot
from jacgen.model.dexterity import ISOTROPIC, NEUTRAL_LENGTH, Dexterity
from jacgen.model.js_rank import singularity_rows
from jacgen.model.nearest_class import NEAR_LENGTH, NEAR_TWIST
from jacgen.model.singularities import READABLE_TERMS, Factor, Singularities
from jacgen.model.structure import SOLVERS
from jacgen.solvers import general6r
from jacgen.solvers.model import Model
from jacgen.tolerances import PARALLEL

DH_HEADER = ["#", "name", "type", "a", "alpha", "d", "theta", "offset", "limits"]


def _angle(value) -> str:
    """An exact angle in degrees when it is a rational number of them (pi/2, 2159*pi/5000),
    else as it is (no nsimplify: its search took seconds on long arms, and found nothing)."""
    degrees = value.exact * 180 / sympy.pi if not value.exact.free_symbols else None
    if degrees is not None and degrees.is_Rational:
        return f"{degrees} deg" if degrees.q == 1 else f"{float(degrees):.6g} deg"
    return str(value.exact)


def _length(value) -> str:
    return f"{value.approx:.6g}" if not value.exact.free_symbols else str(value.exact)


def dh_table(robot: Robot) -> list[list[str]]:
    """Rows of the DH table with the joint variable written into theta or d."""
    rows = []
    for i, joint in enumerate(robot.joints, start=1):
        theta = f"q{i}" if joint.revolute else _angle(joint.theta)
        d = _length(joint.d) if joint.revolute else f"q{i}"
        offset = _angle(joint.offset) if joint.revolute else _length(joint.offset)
        limits = "-" if joint.limits is None else (
            f"[{joint.limits[0]:.6g}, {joint.limits[1]:.6g}]" + (" rad" if joint.revolute else ""))
        rows.append([str(i), joint.name, joint.kind, _length(joint.a), _angle(joint.alpha), d, theta, offset, limits])
    return rows


def readable(expr: sympy.Expr) -> str:
    """An expression with its non-integer numbers to 6 significant digits."""
    numbers = {a: sympy.Float(a, 6) for a in expr.atoms(sympy.Rational) if not a.is_Integer}
    return str(expr.xreplace(numbers))


def _root(value: sympy.Expr, revolute: bool) -> str:
    if not revolute:
        return f"{float(value):.6g}"
    turns = sympy.nsimplify(value / sympy.pi, rational=False)
    if turns.is_Rational and turns.q <= 12:
        return str(turns * sympy.pi)
    return f"{float(value):.6g} ({np.degrees(float(value)):.4g} deg)"


def condition_text(robot: Robot, factor: Factor) -> str:
    """`sin(q3) = 0  ->  q3 in {0, pi}: elbow: arm fully stretched or folded`."""
    terms = len(sympy.Add.make_args(factor.polynomial))
    if terms > READABLE_TERMS:
        joints = ", ".join(f"q{i + 1}" for i in factor.joints)
        text = f"a polynomial of {terms} terms in the sines and cosines of {joints} = 0"
    else:
        text = f"{readable(factor.condition)} = 0"
    if factor.roots:
        joint = factor.joints[0]
        values = ", ".join(_root(r, robot.joints[joint].revolute) for r in factor.roots)
        text += f"  ->  q{joint + 1} in {{{values}}}"
    if factor.multiplicity > 1:
        text += f"  (multiplicity {factor.multiplicity})"
    return text + (f": {factor.meaning}" if factor.meaning else "")


def singularity_lines(robot: Robot, singular: Singularities) -> list[str]:
    """The singularity conditions, one per line, then notes."""
    lines = [condition_text(robot, factor) for factor in singular.factors]
    if singular.everywhere:
        lines.append("everywhere: Js has less than full rank in every configuration")
    elif not lines and singular.complete:
        lines.append("none: Js has full rank everywhere")
    if singular.note:
        lines.append(f"note: {singular.note}")
    if robot.symbolic_parameters and any(f.roots for f in singular.factors):
        lines.append("note: roots at the nominal values of the runtime parameters")
    return lines


def euler_lines(robot: Robot, singular: Singularities) -> list[str]:
    """Where the roll-pitch-yaw representation itself is singular (cos(pitch) = 0)."""
    if not any(component in ("roll", "pitch", "yaw") for component in robot.task):
        return []
    if singularity_rows(robot) is not None:
        return ["cos(pitch) = 0 (pitch = ±90 deg): task_jacobian (roll, pitch, yaw rates) is undefined there; "
                "Js uses the angular velocity, so it is no kinematic singularity"]
    if not singular.euler:
        return ["cos(pitch) = 0 never happens: the tool's pitch is 0 in every configuration"]
    return ["cos(pitch) = 0 (pitch = ±90 deg), task_jacobian and Js undefined, where:"] + [
        f"  {condition_text(robot, factor)}" for factor in singular.euler]


def moves_in_plane(robot: Robot) -> bool:
    """Every joint axis parallel to the world z axis (checked at a generic configuration)."""
    frames, _ = numeric_chain.axis_frames(robot, np.linspace(0.3, 0.9, robot.dof))
    return all(np.linalg.norm(np.cross(frame[:3, 2], [0.0, 0.0, 1.0])) < PARALLEL for frame in frames)


def dexterity_lines(model: Model) -> list[str]:
    """Angeles' characteristic length L, the best condition number of Js with its position
    rows divided by L, where it is reached, and whether the arm is isotropic there."""
    robot, dexterity = model.robot, model.dexterity
    unit = robot.length_unit
    where = ", ".join(f"{np.degrees(value):.4g} deg" if joint.revolute else f"{value:.4g} {unit}"
                      for joint, value in zip(robot.joints, dexterity.configuration))
    lines = [f"characteristic length L = {dexterity.length!r} {unit}: {_length_origin(robot, dexterity)}"]
    if not math.isfinite(dexterity.best_condition):
        lines.append("best condition number: infinite (Js has less than full rank in every configuration)")
    elif dexterity.isotropic:
        lines.append(f"isotropic: condition number 1 (to {ISOTROPIC:g}) at q = ({where})")
    else:
        lines.append(f"not isotropic: best condition number {dexterity.best_condition:.4g} at q = ({where})")
    if robot.symbolic_parameters:
        lines.append("note: at the nominal values of the runtime parameters")
    return lines


def _length_origin(robot: Robot, dexterity: Dexterity) -> str:
    """Where L comes from, and why it is 1 where it is not computed."""
    origin = "from the robot file" if dexterity.given else f"{NEUTRAL_LENGTH:g} (Js unchanged)"
    if not dexterity.length_matters:
        kind = "positions" if any(c not in EULER_ANGLES for c in robot.task) else "angles"
        return f"{origin}: the task has only {kind}, so L does not change the condition number"
    if dexterity.given:
        return origin
    if not math.isfinite(dexterity.best_condition):
        return f"{origin}: no L conditions Js, which has less than full rank everywhere"
    return "computed: the L whose best condition number over the joint ranges is least"


def characteristic_length_note(robot: Robot, dexterity: Dexterity) -> str:
    """The one-line comment of the generated CHARACTERISTIC_LENGTH constant."""
    return (f"Characteristic length L (Angeles), {robot.length_unit}: divide the position rows of Js by it for a "
            f"unit-free condition number; {_length_origin(robot, dexterity)}")


def ik_lines(model: Model) -> list[str]:
    structure, form = model.structure, model.closed_form
    if structure.solver is None:
        return [f"no closed form ({structure.reason}); ik_numeric only"]
    info = SOLVERS[structure.solver]
    if structure.solver == "general_6r":
        if form is None:
            return [f"no closed form ({structure.reason}, but no split of its loop is conditioned well enough "
                    f"for it: see general6r_plan.WORST_CONDITION); ik_numeric only"]
        plan = form.elimination
        free = "" if form.free is None else f", joint {form.free + 1} free (an input of ik, q_free)"
        return [f"general 6R{free}: {info.max_solutions} solutions at most ({structure.reason})",
                f"{info.title}: {plan.equations.split.text(form.joints)}; the half angle shifted by "
                f"{plan.shift:.6g} rad; median condition number {plan.condition:.2g} over random configurations",
                _fast_path_line(model)]
    chain = structure.chain
    joints = ""
    if chain.joints != tuple(range(len(chain.joints))):
        turned = ", each turned the other way" if chain.signs[0] < 0 else ""
        joints = f" (the solver's q1..q6 are joints {', '.join(str(j + 1) for j in chain.joints)}{turned})"
    return [f"{info.title} ({structure.reason}), at most {info.max_solutions} solutions, branches "
            f"(outermost first){joints}: {'; '.join(info.branches)}"]


def _fast_path_line(model: Model) -> str:
    """Which path a 6R arm without a special class takes: the nearest class's fast path or not."""
    fast = model.closed_form.fast_path
    if fast is None:
        why = ("ik.nearest_class: false" if not model.robot.nearest_class else
               f"no special class within {NEAR_TWIST} rad of its twists and "
               f"{NEAR_LENGTH * 100:g} % of its reach of its lengths")
        return f"path: every target to the eigenproblem ({why})"
    return (f"path: calibrated fast path. Nearest special class: {fast.form.solver}, with "
            f"{', '.join(fast.nominal.snapped)} (the arms differ by {fast.position:.3g} {model.robot.length_unit} "
            f"and {fast.rotation:.3g} rad at most). Its closed form, then up to {general6r.FAST_STEPS} Newton steps "
            f"per branch on this arm; the eigenproblem decides when a branch does not converge, two reach one "
            f"solution, or the closed form's certificate fails (a target within the mismatch of a double root "
            f"or a free angle)")


def describe(model: Model) -> str:
    """`jacgen show`: everything above as plain text."""
    robot, singular = model.robot, model.singularities
    rows = [DH_HEADER] + dh_table(robot)
    widths = [max(len(row[c]) for row in rows) for c in range(len(DH_HEADER))]
    lines = [f"{robot.name}: {robot.description}".rstrip(": "),
             f"{robot.dof} joints, {robot.convention} DH, lengths in {robot.length_unit}", ""]
    lines += ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]
    lines += ["", f"task: ({', '.join(robot.task)})  [{len(robot.task)} of 6 components]"]
    symbolic = robot.symbolic_parameters
    if symbolic:
        lines.append("runtime parameters: " + ", ".join(f"{p.name} (nominal {p.value:g})" for p in symbolic))
    lines += ["", f"singularities ({singular.kind} = 0, Js = {js_text(robot)}):"]
    lines += [f"  {line}" for line in singularity_lines(robot, singular) + euler_lines(robot, singular)]
    lines += ["", "dexterity:"] + [f"  {line}" for line in dexterity_lines(model)]
    lines += ["", "inverse kinematics:"] + [f"  {line}" for line in ik_lines(model)]
    return "\n".join(lines)


def js_text(robot: Robot) -> str:
    rows = singularity_rows(robot)
    if rows is None:
        return "task_jacobian"
    names = ("vx", "vy", "vz", "wx", "wy", "wz")
    return "jacobian rows (" + ", ".join(names[r] for r in rows) + ")"
