"""Words a person reads: the DH table and task of a robot (`jacgen show`, the report)."""

import sympy

from .robot import Robot


def _angle(value) -> str:
    degrees = sympy.nsimplify(value.exact * 180 / sympy.pi) if not value.exact.free_symbols else None
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


def describe(robot: Robot) -> str:
    header = ["#", "name", "type", "a", "alpha", "d", "theta", "offset", "limits"]
    rows = [header] + dh_table(robot)
    widths = [max(len(row[c]) for row in rows) for c in range(len(header))]
    lines = [f"{robot.name}: {robot.description}".rstrip(": "),
             f"{robot.dof} joints, {robot.convention} DH, lengths in {robot.length_unit}", ""]
    lines += ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]
    lines += ["", f"task: ({', '.join(robot.task)})  [{len(robot.task)} of 6 components]"]
    symbolic = robot.symbolic_parameters
    if symbolic:
        lines.append("runtime parameters: " + ", ".join(f"{p.name} (nominal {p.value:g})" for p in symbolic))
    return "\n".join(lines)
