"""The data each template receives: a plain, sorted dict per language, decided here so
that templates only lay text out. `backends.py` names the builder of each language."""


import numpy
import sympy

from . import analysis, differential, general6r, ik, report
from .functions import Argument, Call, Function, Generator, Output
from .lowering import is_boolean
from .printers import CasadiPrinter, CPrinter, PythonPrinter
from .robot import Robot
from .nodes import RANK, TOLERANCES, Select

# The contract's C array extent of each argument and output (`function.output`, or the function
# when it has one), as factors that are numbers or the suffixes of size macros
# (`6 * NAME_DOF`); any other function's output gets its size.
# SPEC §3 size macros that are the row count of a function, defined when it is generated.
C_ROW_MACROS = {"singularity_factors": "NUM_SINGULARITY_FACTORS"}


def _common(robot: Robot) -> dict:
    return {
        "name": robot.name,
        "description": robot.description.split("\n") if robot.description else [],
        "dof": robot.dof,
        "task": list(robot.task),
        "length_unit": robot.length_unit,
        "joints": [{"name": j.name, "kind": j.kind} for j in robot.joints],
        "parameters": [{"name": p.name, "value": repr(p.value)} for p in robot.symbolic_parameters],
    }


def _python_function(function: Function, printer: PythonPrinter, parameters: list[dict]) -> dict:
    body = function.body
    definitions, outputs = printer.body(body)
    shapes = [() if a.scalar else a.symbols.shape[:1] if a.vector else a.symbols.shape for a in function.arguments]
    batched = sum(not a.scalar for a in function.arguments)
    results = []
    for (output, values), (_, texts) in zip(function.parts(body.outputs), function.parts(outputs)):
        dtype = ", dtype=xp.bool" if output.boolean else ", dtype=dtype"
        codes = []
        for k, (value, code) in enumerate(zip(values, texts)):
            if not value.free_symbols:  # a number or truth value: an array of the batch shape, like the others
                code = f"xp.full(batch, {code}{dtype}, device=device)"
            elif batched > 1 or output.scalar:  # it may read only some of the batched arguments
                code = f"xp.broadcast_to({code}, batch)"
            if output.integer:  # a status, computed as a real number
                code = f"xp.astype({code}, xp.int32)"
            codes.append((", ".join(map(str, numpy.unravel_index(k, output.shape))), code))
        results.append({"name": output.name, "shape": repr(output.shape), "scalar": not output.shape,
                        "values": codes})
    trig, offsets = _joint_trig(function)
    read = set().union(*(e.free_symbols for s, e in body.definitions if s not in trig),
                       *(e.free_symbols for e in body.outputs))
    return {
        "name": function.name,
        "summary": function.summary,
        "shape": " and ".join(_dimensions(o) for o in function.outputs),
        "operations": body.operation_count,
        "arguments": [(a.name, repr(shape)) for a, shape in zip(function.arguments, shapes)],
        "signature": ", ".join([f"{a.name}={a.default}" if a.default else a.name for a in function.arguments] + ["*"] * bool(parameters)
                               + [f"{p['name']}={p['value']}" for p in parameters]),
        "selects": any(e.has(Select) for e in [v for _, v in body.definitions] + list(body.outputs)),
        "calls": [(", ".join(r.name for r in call.results), f"{call.function}({', '.join(call.passes)}"
                   + "".join(f", {p['name']}={p['name']}" for p in parameters) + ")") for call in function.calls],
        "inputs": [(str(symbol), f"{argument.name}[..., {row}]" if argument.vector else f"{argument.name}[..., {row}, {col}]")
                   for symbol, argument, row, col in function.inputs if symbol in read],
        "trig": repr(tuple(offsets)) if trig else None,
        "definitions": [(body.name(symbol), trig.get(symbol) or text) for (symbol, _), text in zip(body.definitions, definitions)],
        "results": results,
    }


def _joint_trig(function: Function) -> tuple[dict, list]:
    """The definitions cos(q_j + offset) and sin(q_j + offset) of the argument q, as entries of
    `_cos_sin`'s array, and the offsets: ({symbol: code}, offset per joint)."""
    joints = {symbol: row for symbol, argument, row, _ in function.inputs if argument.name == "q"}
    if not joints:
        return {}, []
    offsets, trig = [0.0] * function.arguments[0].size, {}
    for symbol, value in function.body.definitions:
        if isinstance(value, (sympy.cos, sympy.sin)):
            offset, angle = value.args[0].as_independent(*joints, as_Add=True)
            if angle in joints and offset.is_number:
                row = joints[angle]
                offsets[row] = float(offset)
                trig[symbol] = f"trig[..., {2 * row + isinstance(value, sympy.sin)}]"
    return trig, offsets


def _dimensions(output: Output) -> str:
    """`6 x 7`, or `7 x 6 x 7` for a stack."""
    return " x ".join(map(str, output.shape if output.layers > 1 else (output.rows, output.cols)))


def _sentence(text: str) -> str:
    """First letter upper case, the rest as written (jinja's `capitalize` lowers `DOF`)."""
    return text[:1].upper() + text[1:]


def _layout(output: Output) -> str:
    """How a result is laid out, for the C header."""
    if output.scalar:
        return "returned as a scalar"
    if output.layers > 1:
        layers, rows, cols = output.shape
        return (f"{output.name}: {layers} x {rows} x {cols} row-major, element (k, r, c) at "
                f"{output.name}[k * {rows * cols} + r * {cols} + c]")
    if output.cols == 1:
        return f"{output.name}[i], i < {output.rows}"
    return f"{output.name}: {output.rows} x {output.cols} row-major, element (r, c) at {output.name}[r * {output.cols} + c]"


def _c_macros(robot: Robot, functions: list) -> dict[str, int]:
    macros = {"DOF": robot.dof, "TASK_DIM": len(robot.task)}
    macros.update({C_ROW_MACROS[f.name]: f.outputs[0].rows for f in functions if f.name in C_ROW_MACROS})
    macros.update({"MAX_IK_SOLUTIONS": f.outputs[0].rows for f in functions if f.name == "ik_branches"})
    return macros


def _c_extent(array: Argument | Output, macros: dict[str, int], prefix: str) -> str:
    """`6 * NAME_DOF`: the catalogue's extent of an array in C macros, checked against its size."""
    product = 1
    for factor in array.extent:
        product *= macros[factor] if isinstance(factor, str) else factor
    if product != array.size:
        raise ValueError(f"{array.name}: contract extent {array.extent} != {array.size}")
    return " * ".join(f"{prefix}_{factor}" if isinstance(factor, str) else str(factor) for factor in array.extent)


def _parameters_read(body, robot: Robot) -> list[str]:
    read = set().union(*(e.free_symbols for _, e in body.definitions), *(e.free_symbols for e in body.outputs))
    return [p.name for p in robot.symbolic_parameters if p.symbol in read]


def _c_type(output: Output, real: str) -> str:
    return "int" if output.boolean or output.integer else real


def _c_function(function: Function, robot: Robot, printer: CPrinter, macros: dict[str, int],
                functions: dict[str, Function]) -> dict:
    body, prefix, real = function.body, robot.name.upper(), f"{robot.name}_real"
    arguments = [f"{real} {a.name}" if a.scalar else f"const {real} {a.name}[{_c_extent(a, macros, prefix)}]"
                 for a in function.arguments]
    returned = function.returned
    arrays = [o for o in function.outputs if o is not returned]
    arguments += [f"{_c_type(o, real)} {o.name}[{_c_extent(o, macros, prefix)}]"
                  for o in arrays]
    parameters = _parameters_read(body, robot)
    if robot.symbolic_parameters:
        arguments.append(f"const {robot.name}_params *p")
    inputs = list(function.inputs)
    passed = {name for call in function.calls for name in call.passes}
    unused = [a.name for a in function.arguments if a.name not in passed
              and not any(argument is a for _, argument, _, _ in inputs) and not (a.scalar and a.symbols[0] in body.read)]
    unused += ["p"] * bool(robot.symbolic_parameters and not parameters)
    definitions, outputs = printer.body(body)
    values = dict(function.parts(outputs))
    types = {result.name: _c_type(output, real) for call in function.calls
             for result, output in zip(call.results, functions[call.function].outputs)}
    return {
        "name": function.name,
        "summary": _sentence(function.summary),
        "layouts": [_layout(output) for output in function.outputs],
        "operations": body.operation_count,
        "prototype": f"{_c_type(returned, real) if returned else 'void'} {robot.name}_{function.name}({', '.join(arguments)})",
        "unused": unused,
        "calls": [_c_call(call, functions[call.function], robot, macros) for call in function.calls],
        "inputs": [(types.get(argument.name, real), str(symbol), f"{argument.name}[{row * argument.symbols.cols + col}]")
                   for symbol, argument, row, col in inputs] + [(real, name, f"p->{name}") for name in parameters],
        "definitions": [("int" if is_boolean(e) else real, body.name(symbol), text)
                        for (symbol, e), text in zip(body.definitions, definitions)],
        "outputs": [(f"{output.name}[{k}]", text) for output in arrays for k, text in enumerate(values[output])],
        "result": values[returned][0] if returned else None,
    }


def _c_call(call: Call, callee: Function, robot: Robot, macros: dict[str, int]) -> dict:
    """The local arrays that receive a call's results, and the call."""
    prefix, real = robot.name.upper(), f"{robot.name}_real"
    arrays = [f"{_c_type(output, real)} {result.name}[{_c_extent(output, macros, prefix)}]"
              for result, output in zip(call.results, callee.outputs)]
    arguments = [*call.passes, *(result.name for result in call.results)] + ["p"] * bool(robot.symbolic_parameters)
    return {"arrays": arrays, "call": f"{robot.name}_{callee.name}({', '.join(arguments)})"}


def _joint_lines(robot: Robot) -> list[str]:
    """`q[0]  waist  revolute  rad  limits [-2.79, 2.79]`, aligned, for documentation."""
    units = {"revolute": "rad", "prismatic": robot.length_unit}
    rows = [[f"q[{i}]", joint.name, joint.kind, units[joint.kind],
             "" if joint.limits is None else f"limits [{joint.limits[0]:.6g}, {joint.limits[1]:.6g}]"]
            for i, joint in enumerate(robot.joints)]
    widths = [max(len(row[c]) for row in rows) for c in range(len(rows[0]))]
    return ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]


def _task_lines(robot: Robot) -> list[str]:
    """The task components and their units, for documentation."""
    positions = [name for name in robot.task if name in ("x", "y", "z")]
    angles = [name for name in robot.task if name not in positions]
    lines = [f"({', '.join(robot.task)})"]
    if positions:
        lines.append(f"{' '.join(positions)}: tool origin in the world frame, {robot.length_unit}")
    if angles:
        lines.append(f"{' '.join(angles)}: ZYX Euler angles of the tool, R = Rz(yaw) Ry(pitch) Rx(roll), rad")
    return lines


def _casadi_function(function: Function, robot: Robot, printer: CasadiPrinter) -> dict:
    body = function.body
    definitions, outputs = printer.body(body)
    results = []
    for (output, values), (_, texts) in zip(function.parts(body.outputs), function.parts(outputs)):
        positions = [divmod(k, output.cols) for k in range(output.size)]
        # Zeros stay structural zeros of the sparse SX result.
        results.append({"name": output.name, "rows": output.rows, "cols": output.cols,
                        "values": [(row, col, text) for (row, col), e, text in zip(positions, values, texts)
                                   if e != sympy.S.Zero]})
    return {
        "name": function.name,
        "summary": _sentence(function.summary),
        "operations": body.operation_count,
        "arguments": [(a.name, a.symbols.rows, a.symbols.cols) for a in function.arguments],
        "calls": [(", ".join(r.name for r in call.results), f"_{call.function}({', '.join(call.passes)}"
                   + ", p" * bool(robot.symbolic_parameters) + ")") for call in function.calls],
        "inputs": [(str(symbol), f"{argument.name}[{row}]" if argument.vector else f"{argument.name}[{row}, {col}]")
                   for symbol, argument, row, col in function.inputs]
        + [(name, f"p[{[q.name for q in robot.symbolic_parameters].index(name)}]")
           for name in _parameters_read(body, robot)],
        "definitions": [(body.name(symbol), text) for (symbol, _), text in zip(body.definitions, definitions)],
        "results": results,
    }


def _ik_context(robot: Robot, generator: Generator, language: str, real: str) -> dict | None:
    """What the ik wrapper around ik_branches (`wrapper`) and ik_nearest's statuses (`nearest`)
    document and declare, None without ik_branches."""
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
        "doc": ik.documentation(robot, form, "MAX_IK_SOLUTIONS" if language == "python" else f"{prefix}_MAX_IK_SOLUTIONS"),
        "inputs": ", ".join(inputs),
        "free_joint": form.free,
        "nearest_statuses": [("OK", ik.IK_NEAREST_OK), ("NO_SOLUTION", ik.IK_NEAREST_NO_SOLUTION),
                             ("NOT_FINITE", ik.IK_NEAREST_NOT_FINITE)],
        "signature": ", ".join(arguments),
        "wrapper": generator.generates("ik"),
        "nearest": generator.generates("ik_nearest"),
        "general": form.solver == "general_6r" and {
            "monomials": general6r.MONOMIALS.astype(int).tolist(), "along_b": general6r.ALONG_B,
            "along_c": general6r.ALONG_C, "newton_steps": general6r.NEWTON_STEPS,
            "tolerance": general6r.TOLERANCE[real], "imaginary": general6r.IMAGINARY[real],
            "squared": (repr if language == "python" else CPrinter(real).doprint)(
                sympy.Float(general6r.TOLERANCE[real] ** 2))},
    }


def _ik_numeric_context(robot: Robot, language: str, real: str) -> dict:
    """What the loop of ik_numeric declares and documents."""
    pose = len(robot.task) == 6
    m, n = (6 if pose else len(robot.task)), robot.dof
    prefix, real_type = robot.name.upper(), f"{robot.name}_real"
    number = (lambda x: repr(float(x))) if language == "python" else CPrinter(real).doprint
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
        "damping": {key: number(sympy.Float(value)) for key, value in differential.IK_NUMERIC_DAMPING.items()},
        "tenth": number(sympy.Float(0.1)),
        "iterations": differential.IK_NUMERIC_ITERATIONS,
        "statuses": differential.IK_NUMERIC_STATUSES,
        "defaults": {key: repr(value) for key, value in differential.IK_NUMERIC_DEFAULTS.items()},
        "python": {"where": "xp.where", "logical_and": "xp.logical_and", "maximum": "xp.maximum",
                   "finite": "(cost >= 0.0) & (max_iter >= 0)", "iterations": "max(max_iter, 0)",
                   "widen": "[..., None]", "q0": "xp.asarray(q0, dtype=q.dtype)", "fixed": False},
        "casadi": {"where": "casadi.if_else", "logical_and": "casadi.logic_and", "maximum": "casadi.fmax",
                   "finite": "cost >= 0.0", "iterations": "IK_NUMERIC_ITERATIONS",
                   "widen": "", "q0": "q0", "fixed": True},
        "ten": number(sympy.Float(10)),
        "signature": ", ".join(arguments),
    }


def _velocity_ik_context(robot: Robot, real: str) -> dict:
    """What the documentation of velocity_ik says: Js, mu_dot, the system and its statuses."""
    m, n = len(robot.task), robot.dof
    rows = analysis.singularity_rows(robot)
    names = ", ".join(("vx", "vy", "vz", "wx", "wy", "wz")[r] for r in rows) if rows is not None else ""
    return {
        "system": min(m, n),
        "js_text": "the task Jacobian" if rows is None else
        ("the geometric Jacobian" if len(rows) == 6 and list(rows) == list(range(6))
         else f"rows ({names}) of the geometric Jacobian"),
        "mu_text": f"({names}): components of the tool's linear (v) and angular (w) velocity in the world frame"
        if rows is not None else f"the rate of the task vector ({', '.join(robot.task)})",
        "rank": repr(float(TOLERANCES[real][RANK])),
        "statuses": [("OK", differential.VELOCITY_IK_OK), ("SINGULAR", differential.VELOCITY_IK_SINGULAR),
                     ("NOT_FINITE", differential.VELOCITY_IK_NOT_FINITE)],
    }


def _report_context(robot: Robot, generator: Generator) -> dict:
    """The Markdown report: the lines `jacgen show` prints, and each function's size."""
    singular = generator.singularities
    return {
        "convention": robot.convention,
        "dh_header": report.DH_HEADER,
        "dh_rows": report.dh_table(robot),
        "singularity_kind": singular.kind,
        "js_text": report.js_text(robot),
        "singularities": report.singularity_lines(robot, singular),
        "euler": report.euler_lines(robot, singular),
        "isotropy": report.isotropy_lines(robot),
        "ik": report.ik_lines(generator.model),
        "operations": [{"name": f.name, "operations": f.body.operation_count,
                        "shape": "scalar" if f.scalar else " and ".join(_dimensions(o) for o in f.outputs)}
                       for f in generator.functions()],
    }


def python_context(robot: Robot, generator: Generator, printer: PythonPrinter, real: str) -> dict:
    """The numpy module's templates: every function and the IK documentation (double only)."""
    context = _common(robot)
    context["functions"] = [_python_function(f, printer, context["parameters"]) for f in generator.functions()]
    context["ik"] = _ik_context(robot, generator, "python", "double")
    context["ik_numeric"] = generator.generates("ik_numeric") and _ik_numeric_context(robot, "python", "double")
    context["velocity_ik"] = generator.generates("velocity_ik") and _velocity_ik_context(robot, "double")
    return dict(sorted(context.items()))


def c_context(robot: Robot, generator: Generator, printer: CPrinter, real: str) -> dict:
    """The C header and source: functions with prototypes and size macros, in `real`."""
    context = _common(robot)
    functions = generator.functions()
    by_name = {f.name: f for f in (*functions, *generator.loops)}  # the callees of functions that call another
    macros = _c_macros(robot, [*functions, *generator.loops])
    if generator.closed_form and generator.closed_form.free is not None:
        macros["IK_FREE_JOINT"] = generator.closed_form.free  # 0-based index into q of ik's q_free
    context.update({
        "prefix": robot.name.upper(),
        "real": real,
        "macros": list(macros.items()),
        "joint_lines": _joint_lines(robot),
        "task_lines": _task_lines(robot),
        "functions": [_c_function(f, robot, printer, macros, by_name) for f in functions],
        "ik": _ik_context(robot, generator, "c", real),
        "ik_numeric": generator.generates("ik_numeric") and _ik_numeric_context(robot, "c", real),
        "velocity_ik": generator.generates("velocity_ik") and _velocity_ik_context(robot, real),
    })
    return dict(sorted(context.items()))


def casadi_context(robot: Robot, generator: Generator, printer: CasadiPrinter, real: str) -> dict:
    """The CasADi module: every function as an SX graph, with the symbols of its inputs."""
    context = _common(robot)
    functions = generator.without_loops()
    context["functions"] = [_casadi_function(f, robot, printer) for f in functions]
    context["arguments"] = sorted({(a.name, a.symbols.rows, a.symbols.cols) for f in functions for a in f.arguments},
                                  key=lambda a: ("q", "q_dot", "mu_dot", "damping", "target", "T", "mu", "q_seed", "q_free", "weights").index(a[0]))
    context["ik"] = generator.closed_form is not None and not generator.loops and generator.generates("ik")
    context["ik_numeric"] = generator.generates("ik_numeric") and _ik_numeric_context(robot, "python", "double")
    return dict(sorted(context.items()))


def report_context(robot: Robot, generator: Generator, printer: None, real: str) -> dict:
    """The Markdown report."""
    return dict(sorted((_common(robot) | _report_context(robot, generator)).items()))
