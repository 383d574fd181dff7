"""What every language's templates share: the robot's description, the IK and velocity_ik
documentation, and the Backend record each language module fills in (`backends/c.py`, ...)."""

from dataclasses import dataclass
from typing import Callable


from jacgen.emission.catalogue import DECLARED, Output
from jacgen.emission.generator import Generator
from jacgen.emission.lowering import kernels_of
from jacgen.inputs.robot import Robot
from jacgen.model import js_rank
from jacgen.model.node import SELECT
from jacgen.model.tolerance_symbols import RANK, TOLERANCES
from jacgen.reports import ik_documentation
from jacgen.reports.description import characteristic_length_note
from jacgen.solvers import differential, general6r, general6r_plan
from jacgen.tolerances import REACHED


@dataclass(frozen=True)
class Backend:
    """One target language: its templates with the file each becomes, its expression printer
    for a real type ("double", "float"; None: prints no expression) and the builder of what its
    templates receive. The words it reserves are `names.RESERVED[name]`."""

    name: str
    # (template, output file pattern with {name}[, the key of the context's part it renders])
    templates: tuple[tuple[str, ...], ...]
    printer: Callable[[str], object] | None
    context: Callable  # (robot, generator, printer, real) -> the templates' data


def common_context(robot: Robot) -> dict:
    return {
        "name": robot.name,
        "description": robot.description.split("\n") if robot.description else [],
        "dof": robot.dof,
        "task": list(robot.task),
        "length_unit": robot.length_unit,
        "joints": [{"name": j.name, "kind": j.kind} for j in robot.joints],
        "parameters": [{"name": p.name, "value": repr(p.value)} for p in robot.symbolic_parameters],
    }


def kernels_context(generator: Generator, functions: list, printer) -> list[dict]:
    """The kernels the functions run (`Lowering.repeated`, `Lowering.called`), each once, as its
    file defines them: its step's definitions (flagged boolean) and the next state, over the
    state's entries w0, w1, ... (`names`; `state`: those the step reads, with their index), and
    its `body` (the C declares a definition by its value's kind)."""
    made = []
    for kernel in kernels_of(function.body for function in functions):
        body = kernel.body
        definitions, outputs = printer.body(body)
        values = [value for _, value in body.definitions] + list(body.outputs)
        made.append({
            "name": kernel.name,
            "summary": sentence(kernel.summary),
            "size": max(len(kernel.state), len(body.outputs)),  # the state, and a call's outputs
            "names": [body.name(symbol) for symbol in kernel.state],
            "operations": body.operation_count,
            "state": [(body.name(symbol), k) for k, symbol in enumerate(kernel.state) if symbol in body.read],
            "definitions": [(value.boolean, body.name(symbol), text)
                            for (symbol, value), text in zip(body.definitions, definitions)],
            "body": body,
            "outputs": outputs,
            "selects": any(value.contains(SELECT) for value in values),
        })
    return made


def dimensions(output: Output) -> str:
    """`6 x 7`, or `7 x 6 x 7` for a stack."""
    return " x ".join(map(str, output.shape if output.layers > 1 else (output.rows, output.cols)))


def sentence(text: str) -> str:
    """First letter upper case, the rest as written (jinja's `capitalize` lowers `DOF`)."""
    return text[:1].upper() + text[1:]


def parameters_read(body, robot: Robot) -> list[str]:
    read = set().union(*(e.free_symbols for _, e in body.definitions), *(e.free_symbols for e in body.outputs))
    return [p.name for p in robot.symbolic_parameters if p.symbol in read]


def joint_lines(robot: Robot) -> list[str]:
    """`q[0]  waist  revolute  rad  limits [-2.79, 2.79]`, aligned, for documentation."""
    units = {"revolute": "rad", "prismatic": robot.length_unit}
    rows = [[f"q[{i}]", joint.name, joint.kind, units[joint.kind],
             "" if joint.limits is None else f"limits [{joint.limits[0]:.6g}, {joint.limits[1]:.6g}]"]
            for i, joint in enumerate(robot.joints)]
    widths = [max(len(row[c]) for row in rows) for c in range(len(rows[0]))]
    return ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]


def task_lines(robot: Robot) -> list[str]:
    """The task components and their units, for documentation."""
    positions = [name for name in robot.task if name in ("x", "y", "z")]
    angles = [name for name in robot.task if name not in positions]
    lines = [f"({', '.join(robot.task)})"]
    if positions:
        lines.append(f"{' '.join(positions)}: tool origin in the world frame, {robot.length_unit}")
    if angles:
        lines.append(f"{' '.join(angles)}: ZYX Euler angles of the tool, R = Rz(yaw) Ry(pitch) Rx(roll), rad")
    return lines


def characteristic_length(robot: Robot, generator: Generator, number: Callable) -> dict:
    """The CHARACTERISTIC_LENGTH constant (`model/dexterity.py`): its literal, printed by
    `number`, and its one-line comment."""
    dexterity = generator.model.dexterity
    return {"value": number(dexterity.length), "note": characteristic_length_note(robot, dexterity)}


def ik_context(robot: Robot, generator: Generator, real: str, number: Callable, solutions_macro: str) -> dict | None:
    """What the ik wrapper around ik_branches (`wrapper`) and ik_nearest's statuses (`nearest`)
    document and declare, None without ik_branches: numbers printed by `number`, the largest
    solution count named `solutions_macro`."""
    form = generator.closed_form
    if form is None or not generator.generates("ik_branches"):
        return None
    prefix, real_type = robot.name.upper(), f"{robot.name}_real"
    pose = form.target == "pose"
    target = f"const {real_type} T[16]" if pose else f"const {real_type} mu[{prefix}_TASK_DIM]"
    inputs = ["T" if pose else "mu"] + ["q_free"] * (form.free is not None)
    arguments = [target] + [f"{real_type} q_free"] * (form.free is not None)
    arguments += [f"{real_type} q[{prefix}_MAX_IK_SOLUTIONS * {prefix}_DOF]"]
    arguments += [f"const {robot.name}_params *p"] * bool(robot.symbolic_parameters)
    return {
        "solver": form.solver,
        "max_solutions": form.info.max_solutions,
        "doc": ik_documentation.documentation(robot, form, solutions_macro),
        "inputs": ", ".join(inputs),
        "free_joint": form.free,
        "nearest_statuses": [(status.name, status.value) for status in DECLARED["ik_nearest"].statuses],
        "signature": ", ".join(arguments),
        "wrapper": generator.generates("ik"),
        "nearest": generator.generates("ik_nearest"),
        "general": form.solver == "general_6r" and {
            "monomials": general6r.MONOMIALS.astype(int).tolist(), "along_b": general6r.ALONG_B,
            "along_c": general6r.ALONG_C, "newton_steps": general6r.NEWTON_STEPS,
            "tolerance": REACHED[real], "imaginary": general6r.IMAGINARY[real],
            "squared": number(REACHED[real] ** 2),
            "converged_squared": number((general6r.CONVERGED[real] * (1 + robot.reach)) ** 2),
            "work_bytes": general6r.work_bytes(real),
            "lanes": general6r.NEWTON_ROWS,
            "degenerate": repr(general6r_plan.DEGENERATE),  # a double in every build (the eigenproblem is)
            "fallback": form.elimination.fallback is not None,
            "joints": form.joints,
            "fast": form.fast_path and {
                "rows": form.fast_path.form.info.max_solutions, "steps": general6r.FAST_STEPS}},
    }


def ik_numeric_context(robot: Robot, number: Callable) -> dict:
    """What the loop of ik_numeric declares and documents, numbers printed by `number`; each
    language adds the syntax its loop is written in."""
    pose = len(robot.task) == 6
    m, n = (6 if pose else len(robot.task)), robot.dof
    prefix, real_type = robot.name.upper(), f"{robot.name}_real"
    target = f"const {real_type} target[16]" if pose else f"const {real_type} target[{prefix}_TASK_DIM]"
    parameters = [f"const {robot.name}_params *p"] * bool(robot.symbolic_parameters)
    arguments = [target, f"const {real_type} q0[{prefix}_DOF]", "int max_iter", f"{real_type} tol",
                 f"{real_type} q[{prefix}_DOF]"] + parameters
    return {
        "target_text": "the 4x4 tool pose in the world frame" if pose
        else f"the task vector ({', '.join(robot.task)})",
        "error_text": "position error and rotation vector of R_target R^T, world frame" if pose
        else "target - mu(q), angles wrapped into (-pi, pi]",
        "jacobian": "the geometric Jacobian" if pose else "the task Jacobian",
        "step_text": "q += J^T (J J^T + damping I)^-1 e" if m <= n else "q += (J^T J + damping I)^-1 J^T e",
        "damping": {key: number(value) for key, value in differential.IK_NUMERIC_DAMPING.items()},
        "tenth": number(0.1),
        "lowered": number(1 - differential.IK_NUMERIC_PROGRESS),  # the cost after a step that lowers it, at most
        "iterations": differential.IK_NUMERIC_ITERATIONS,
        "statuses": differential.IK_NUMERIC_STATUSES,
        "defaults": {key: repr(value) for key, value in differential.IK_NUMERIC_DEFAULTS.items()},
        "ten": number(10),
        "signature": ", ".join(arguments),
    }


def velocity_ik_context(robot: Robot, real: str) -> dict:
    """What the documentation of velocity_ik says: Js, mu_dot, the system and its statuses."""
    m, n = len(robot.task), robot.dof
    rows = js_rank.singularity_rows(robot)
    names = ", ".join(("vx", "vy", "vz", "wx", "wy", "wz")[r] for r in rows) if rows is not None else ""
    return {
        "system": min(m, n),
        "js_text": "the task Jacobian" if rows is None else
        ("the geometric Jacobian" if len(rows) == 6 and list(rows) == list(range(6))
         else f"rows ({names}) of the geometric Jacobian"),
        "mu_text": f"({names}): components of the tool's linear (v) and angular (w) velocity in the world frame"
        if rows is not None else f"the rate of the task vector ({', '.join(robot.task)})",
        "rank": repr(float(TOLERANCES[real][RANK])),
        "statuses": [(status.name, status.value) for status in DECLARED["velocity_ik"].statuses],
    }
