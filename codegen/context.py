"""The data each template receives: a plain, sorted dict per language, decided here so
that templates only lay text out."""

import math

import sympy

from . import analysis, ik, report
from .functions import Function, Generator, Output
from .printers import CasadiPrinter, CPrinter, PythonPrinter, fold_constants
from .robot import Robot

# SPEC §3: the C array extent of each output it names, as factors that are numbers or the
# suffixes of size macros (`6 * NAME_DOF`); any other function's output gets its size.
C_EXTENTS = {
    "fk": (16,),
    "jacobian": (6, "DOF"),
    "jacobian_tool": (6, "DOF"),
    "task": ("TASK_DIM",),
    "task_jacobian": ("TASK_DIM", "DOF"),
    "singularity_factors": ("NUM_SINGULARITY_FACTORS",),
}
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


def _python_function(function: Function, printer: PythonPrinter) -> dict:
    body = function.body
    results = []
    for output, values in function.parts(body.outputs):
        indices = [", ".join(["..."] + [str(i) for i in divmod(k, output.cols)[: len(output.shape)]])
                   for k in range(output.size)]
        results.append({"name": output.name, "shape": repr(output.shape),
                        "values": [(index, printer.doprint(e)) for index, e in zip(indices, values)]})
    return {
        "name": function.name,
        "summary": function.summary,
        "shape": " and ".join(" x ".join(map(str, (o.rows, o.cols))) for o in function.outputs),
        "operations": body.operation_count,
        "inputs": [(f"q{i + 1}", f"q[..., {i}]") for i in body.joints_used],
        "definitions": [(str(symbol), printer.doprint(e)) for symbol, e in body.definitions],
        "results": results,
    }


def _sentence(text: str) -> str:
    """First letter upper case, the rest as written (jinja's `capitalize` lowers `DOF`)."""
    return text[:1].upper() + text[1:]


def _layout(output: Output) -> str:
    """How a result is laid out, for the C header."""
    if output.scalar:
        return "returned as a scalar"
    if output.cols == 1:
        return f"{output.name}[i], i < {output.rows}"
    return f"{output.name}: {output.rows} x {output.cols} row-major, element (r, c) at {output.name}[r * {output.cols} + c]"


def _c_macros(robot: Robot, functions: list[Function]) -> dict[str, int]:
    macros = {"DOF": robot.dof, "TASK_DIM": len(robot.task)}
    macros.update({C_ROW_MACROS[f.name]: f.outputs[0].rows for f in functions if f.name in C_ROW_MACROS})
    return macros


def _c_extent(function: Function, output: Output, macros: dict[str, int], prefix: str) -> str:
    """`6 * NAME_DOF`: the SPEC's extent of an output array, checked against its size."""
    factors = C_EXTENTS.get(output.equals or function.name, (output.size,))
    size = 1
    for factor in factors:
        size *= macros[factor] if isinstance(factor, str) else factor
    if size != output.size:
        raise ValueError(f"{function.name}: SPEC extent {factors} != {output.rows} x {output.cols}")
    return " * ".join(f"{prefix}_{factor}" if isinstance(factor, str) else str(factor) for factor in factors)


def _parameters_read(body, robot: Robot) -> list[str]:
    read = set().union(*(e.free_symbols for _, e in body.definitions), *(e.free_symbols for e in body.outputs))
    return [p.name for p in robot.symbolic_parameters if p.symbol in read]


def _c_function(function: Function, robot: Robot, printer: CPrinter, macros: dict[str, int]) -> dict:
    body, prefix, real = function.body, robot.name.upper(), f"{robot.name}_real"
    arguments = [f"const {real} q[{prefix}_DOF]"]
    if not function.scalar:
        arguments += [f"{real} {o.name}[{_c_extent(function, o, macros, prefix)}]" for o in function.outputs]
    parameters = _parameters_read(body, robot)
    if robot.symbolic_parameters:
        arguments.append(f"const {robot.name}_params *p")
    unused = ["q"] * (not body.joints_used) + ["p"] * bool(robot.symbolic_parameters and not parameters)
    returns = real if function.scalar else "void"
    return {
        "name": function.name,
        "summary": _sentence(function.summary),
        "layouts": [_layout(output) for output in function.outputs],
        "operations": body.operation_count,
        "prototype": f"{returns} {robot.name}_{function.name}({', '.join(arguments)})",
        "unused": unused,
        "inputs": [(f"q{i + 1}", f"q[{i}]") for i in body.joints_used] + [(name, f"p->{name}") for name in parameters],
        "definitions": [(str(symbol), printer.doprint(e)) for symbol, e in body.definitions],
        "outputs": [] if function.scalar else [(f"{output.name}[{k}]", printer.doprint(e))
                                               for output, values in function.parts(body.outputs)
                                               for k, e in enumerate(values)],
        "result": printer.doprint(body.outputs[0]) if function.scalar else None,
    }


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


def _c_context(robot: Robot, generator: Generator, real: str) -> dict:
    functions = generator.functions()
    macros = _c_macros(robot, functions)
    printer = CPrinter(real)
    return {
        "prefix": robot.name.upper(),
        "real": real,
        "macros": list(macros.items()),
        "joint_lines": _joint_lines(robot),
        "task_lines": _task_lines(robot),
        "functions": [_c_function(f, robot, printer, macros) for f in functions],
    }


def _casadi_function(function: Function, robot: Robot, printer: CasadiPrinter) -> dict:
    body = function.body
    results = []
    for output, values in function.parts(body.outputs):
        positions = [divmod(k, output.cols) for k in range(output.size)]
        # Zeros stay structural zeros of the sparse SX result.
        results.append({"name": output.name, "rows": output.rows, "cols": output.cols,
                        "values": [(row, col, printer.doprint(e)) for (row, col), e in zip(positions, values)
                                   if e != sympy.S.Zero]})
    return {
        "name": function.name,
        "summary": _sentence(function.summary),
        "operations": body.operation_count,
        "inputs": [(f"q{i + 1}", f"q[{i}]") for i in body.joints_used]
        + [(name, f"p[{[q.name for q in robot.symbolic_parameters].index(name)}]")
           for name in _parameters_read(body, robot)],
        "definitions": [(str(symbol), printer.doprint(e)) for symbol, e in body.definitions],
        "results": results,
    }


# ik_numeric's Levenberg-Marquardt damping (added to the diagonal): start, least, most.
IK_NUMERIC_DAMPING = {"start": 1e-6, "min": 1e-12, "max": 1e8}


def _ik_context(robot: Robot, printer, language: str, real: str) -> dict | None:
    """The closed-form solver's partial: constants printed in the language, None without one."""
    form = ik.closed_form(robot)
    if form is None:
        return None
    is_python, prefix, real_type = language == "python", robot.name.upper(), f"{robot.name}_real"

    def literal(values: sympy.Matrix) -> str:
        items = [printer.doprint(fold_constants(e)) for e in values]  # row-major
        if len(items) == 1:
            return items[0]
        return f"({', '.join(items)})" if is_python else f"{{{', '.join(items)}}}"

    pose = form.target == "pose"
    read = set().union(*(value.free_symbols for _, value in form.constants))
    read_names = [p.name for p in robot.symbolic_parameters if p.symbol in read]
    target = f"const {real_type} T[16]" if pose else f"const {real_type} mu[{prefix}_TASK_DIM]"
    arguments = [target, f"{real_type} q[{prefix}_MAX_IK_SOLUTIONS * {prefix}_DOF]"]
    arguments += [f"const {robot.name}_params *p"] * bool(robot.symbolic_parameters)
    return {
        "solver": form.solver,
        "max_solutions": form.info.max_solutions,
        "doc": ik.documentation(robot, form, "MAX_IK_SOLUTIONS" if is_python else f"{prefix}_MAX_IK_SOLUTIONS"),
        "helpers": list(form.helpers),
        "flip": form.flip,
        "constants": [(name, literal(value)) for name, value in form.constants],
        "fields": [(name, len(value)) for name, value in form.constants],
        "parameters": ", ".join(name for name, _ in form.constants),
        "parameters_read": read_names,
        "parameters_unused": bool(robot.symbolic_parameters) and not read_names,
        "indices": dict(form.indices),
        "revolute": [i for i, joint in enumerate(robot.joints) if joint.revolute],
        "pose": pose,
        "target_shape": "(4, 4)" if pose else f"({len(robot.task)},)",
        "target_name": "T" if pose else "mu",
        "target_size": 12 if pose else f"{prefix}_TASK_DIM",  # the entries read (not T's last row)
        "signature": ", ".join(arguments),
        **{name: repr(value) for name, value in ik.TOLERANCES["double" if is_python else real].items()},
    }


def _ik_numeric_context(robot: Robot, language: str, real: str) -> dict:
    """The iterative solver's partial."""
    pose = len(robot.task) == 6
    m, n = (6 if pose else len(robot.task)), robot.dof
    prefix, real_type = robot.name.upper(), f"{robot.name}_real"
    number = (lambda x: repr(float(x))) if language == "python" else CPrinter(real).doprint
    target = f"const {real_type} target[16]" if pose else f"const {real_type} target[{prefix}_TASK_DIM]"
    parameters = [f"const {robot.name}_params *p"] * bool(robot.symbolic_parameters)
    arguments = [target, f"const {real_type} q0[{prefix}_DOF]", "int max_iter", f"{real_type} tol",
                 f"{real_type} q[{prefix}_DOF]"] + parameters
    limits = [joint.limits or (-math.inf, math.inf) for joint in robot.joints]
    return {
        "target": "pose" if pose else "task",
        "target_shape": "(4, 4)" if pose else f"({m},)",
        "target_size": 12 if pose else f"{prefix}_TASK_DIM",
        "target_text": "the 4x4 tool pose in the world frame" if pose
        else f"the task vector ({', '.join(robot.task)})",
        "error_text": "position error and rotation vector of R_target R^T, world frame" if pose
        else "target - mu(q), angles wrapped into (-pi, pi]",
        "jacobian": "the geometric Jacobian" if pose else "the task Jacobian",
        "m": m,
        "k": min(m, n),
        "rows_first": m <= n,
        "step_text": "q += J^T (J J^T + damping I)^-1 e" if m <= n else "q += (J^T J + damping I)^-1 J^T e",
        "angles": [] if pose else [i for i, name in enumerate(robot.task) if name in ("roll", "pitch", "yaw")],
        "lower": "[" + ", ".join("-numpy.inf" if math.isinf(low) else repr(low) for low, _ in limits) + "]",
        "upper": "[" + ", ".join("numpy.inf" if math.isinf(high) else repr(high) for _, high in limits) + "]",
        "clamps": [(j, number(sympy.Float(low)), number(sympy.Float(high)))
                   for j, (low, high) in enumerate(limits) if not math.isinf(low)],
        "damping": {key: number(sympy.Float(value)) for key, value in IK_NUMERIC_DAMPING.items()},
        "signature": ", ".join(arguments),
        "params_argument": "".join(f", {argument}" for argument in parameters),
    }


# atan(t) = t + t z P(z) / Q(z), z = t^2, |t| <= tan(pi/8): Cephes' minimax coefficients of P
# and Q, highest power first (S. L. Moshier, Cephes Math Library: atan.c, atanf.c; Q = 1 for float).
ATAN_APPROXIMATION = {
    "double": ((-8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1,
                -1.228866684490136173410e2, -6.485021904942025371773e1),
               (1.0, 2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2,
                4.853903996359136964868e2, 1.945506571482613964425e2)),
    "float": ((8.05374449538e-2, -1.38776856032e-1, 1.99777106478e-1, -3.33329491539e-1), ()),
}


def _estrin(coefficients: tuple[float, ...], printer: CPrinter) -> tuple[str, set[str]]:
    """The polynomial in z with these coefficients (highest power first) by Estrin's scheme,
    (a0 + a1 z) + z2 (a2 + a3 z) + z4 (a4 + a5 z), shorter dependency chains than Horner's;
    returns the code and the powers of z it reads."""
    ascending = list(reversed(coefficients))
    if len(ascending) > 6:
        raise ValueError("Estrin's scheme here takes at most 6 coefficients")
    literal = lambda c: printer.doprint(sympy.Float(c))  # noqa: E731
    terms, powers = [], set()
    for j, power in enumerate(("", "z2", "z4")):
        pair = ascending[2 * j:2 * j + 2]
        if not pair:
            break
        text = literal(pair[0])
        if len(pair) == 2:
            slope = "z" if pair[1] == 1 else f"{literal(abs(pair[1]))} * z"
            text += f" {'-' if pair[1] < 0 else '+'} {slope}"
        terms.append(f"({text})" if not power else f"{power} * ({text})")
        powers |= {power} - {""}
    return " + ".join(terms), powers


def _ik_math(robot: Robot, real: str) -> dict:
    """What the hand-written C of the ik partials needs: <math.h> names, literals, and whether
    the angle-wrapping helper is emitted (used by ik and by ik_numeric's angle errors)."""
    printer = CPrinter(real)
    suffix = "f" if real == "float" else ""
    numerator, powers = _estrin(ATAN_APPROXIMATION[real][0], printer)
    denominator, more_powers = _estrin(ATAN_APPROXIMATION[real][1], printer) if ATAN_APPROXIMATION[real][1] else ("", set())
    angles = len(robot.task) < 6 and any(name in ("roll", "pitch", "yaw") for name in robot.task)
    return {
        "fn": {name: name + suffix for name in ("sqrt", "atan2", "sin", "cos", "fabs")},
        "literal_suffix": "F" if real == "float" else "",
        "pi": printer.doprint(fold_constants(sympy.pi)),
        "two_pi": printer.doprint(fold_constants(2 * sympy.pi)),
        "half_pi": printer.doprint(fold_constants(sympy.pi / 2)),
        "quarter_pi": printer.doprint(fold_constants(sympy.pi / 4)),
        "tan_pi_8": printer.doprint(fold_constants(sympy.sqrt(2) - 1)),
        "atan_numerator": numerator,
        "atan_denominator": denominator,
        "atan_powers": sorted(powers | more_powers),
        "wrap": angles or ik.closed_form(robot) is not None,
    }


# velocity_ik: the system counts as singular below this reciprocal condition number (Python)
# or relative pivot (C, LU with partial pivoting).
VELOCITY_IK_TOLERANCE = {"double": 1e-12, "float": 1e-5}


def _velocity_ik_context(robot: Robot, real: str) -> dict:
    """velocity_ik's partial: which generated Jacobian gives Js, the system's shape."""
    m, n = len(robot.task), robot.dof
    rows = analysis.singularity_rows(robot)
    names = ", ".join(("vx", "vy", "vz", "wx", "wy", "wz")[r] for r in rows) if rows is not None else ""
    return {
        "m": m,
        "form": "square" if m == n else ("wide" if m < n else "tall"),
        "system": min(m, n),
        "source": "task_jacobian" if rows is None else "jacobian",
        "rows": list(rows) if rows is not None else list(range(m)),
        "row_index": "" if rows is None or list(rows) == list(range(6)) else f"[..., {list(rows)}, :]",
        "js_text": "the task Jacobian" if rows is None else
        ("the geometric Jacobian" if len(rows) == 6 and list(rows) == list(range(6))
         else f"rows ({names}) of the geometric Jacobian"),
        "mu_text": f"({names}): components of the tool's linear (v) and angular (w) velocity in the world frame"
        if rows is not None else f"the rate of the task vector ({', '.join(robot.task)})",
        "tolerance": repr(VELOCITY_IK_TOLERANCE[real]),
    }


def _velocity_ik_c_context(robot: Robot, real: str) -> dict:
    """The C partial of velocity_ik: its prototype, Jacobian buffer and literals."""
    context, prefix, real_type = _velocity_ik_context(robot, real), robot.name.upper(), f"{robot.name}_real"
    arguments = [f"const {real_type} q[{prefix}_DOF]", f"const {real_type} mu_dot[{prefix}_TASK_DIM]",
                 f"{real_type} damping", f"{real_type} q_dot[{prefix}_DOF]"]
    arguments += [f"const {robot.name}_params *p"] * bool(robot.symbolic_parameters)
    return {
        **context,
        "prototype": f"int {robot.name}_velocity_ik({', '.join(arguments)})",
        "jacobian_size": f"6 * {prefix}_DOF" if context["source"] == "jacobian" else f"{prefix}_TASK_DIM * {prefix}_DOF",
        "fabs": "fabsf" if real == "float" else "fabs",
        "tolerance_literal": CPrinter(real).doprint(sympy.Float(VELOCITY_IK_TOLERANCE[real])),
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
        "ik": report.ik_lines(robot),
        "operations": [{"name": f.name, "operations": f.body.operation_count,
                        "shape": "scalar" if f.scalar else " and ".join(f"{o.rows} x {o.cols}" for o in f.outputs)}
                       for f in generator.functions()],
        "velocity_ik": _velocity_ik_context(robot, "double"),
    }


def template_context(robot: Robot, generator: Generator, language: str, real: str) -> dict:
    context = _common(robot)
    if language == "python":
        printer = PythonPrinter()
        context["functions"] = [_python_function(f, printer) for f in generator.functions()]
        context["ik"] = _ik_context(robot, printer, language, real)
        context["ik_numeric"] = _ik_numeric_context(robot, language, real)
        context["ik_math"] = _ik_math(robot, "double")
        context["velocity_ik"] = _velocity_ik_context(robot, "double")
    elif language == "c":
        context.update(_c_context(robot, generator, real))
        context["ik"] = _ik_context(robot, CPrinter(real), language, real)
        context["ik_numeric"] = _ik_numeric_context(robot, language, real)
        context["ik_math"] = _ik_math(robot, real)
        context["velocity_ik"] = _velocity_ik_c_context(robot, real)
    elif language == "report":
        context.update(_report_context(robot, generator))
    elif language == "casadi":
        printer = CasadiPrinter()
        context["functions"] = [_casadi_function(f, robot, printer) for f in generator.functions()]
    return dict(sorted(context.items()))
