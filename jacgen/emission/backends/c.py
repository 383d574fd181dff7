"""The C99 backend: its printer (double or float, no double promotion), the data of the header
and source templates (`templates/c/`: the functions and the IK loops; the general 6R
eigensolver's runtime is C of its own, `templates/runtime/`)."""

import numpy

from jacgen.emission.backends.common import (Backend, characteristic_length, common_context, ik_context, ik_numeric_context,
                                             joint_lines, kernels_context, parameters_read, sentence, task_lines,
                                             velocity_ik_context)
from jacgen.emission.catalogue import Argument, Call, Function, Output
from jacgen.emission.generator import Generator
from jacgen.emission.printers import AND, ATOM, MATH_FUNCTIONS, PRODUCT, RELATION, Printer
from jacgen.inputs import names
from jacgen.inputs.robot import Robot
from jacgen.model.node import PART, REPEAT
from jacgen.model.tolerance_symbols import TOLERANCES

_FLOAT_MAX = float(numpy.finfo(numpy.float32).max)


class CPrinter(Printer):
    """C99 for `double` or `float` builds: the type's functions (`sinf`, `atan2f`) and literals
    (`0.5F`), so a float build has no double promotion; small integer and half-integer powers
    as products (`(x*x)`, `(sqrt(x)*x)`), never `pow()`; selects as `(c ? a : b)`. No math
    macro: `M_PI` and `M_SQRT2` are POSIX, not C99."""

    LARGEST_EXPANDED_POWER = 8

    def __init__(self, real: str):
        if real not in TOLERANCES:
            raise ValueError(f"real must be one of {', '.join(TOLERANCES)}, got {real!r}")
        super().__init__(real)
        self.real = real
        suffix = "f" if real == "float" else ""
        self.functions = {name: function + suffix for name, function in MATH_FUNCTIONS.items()}
        self.one = self.literal(1.0)

    def literal(self, value: float) -> str:
        """Shortest literal that reads back as the nearest value of the build's type."""
        if self.real == "double":
            return repr(value)
        if not abs(value) <= _FLOAT_MAX:
            raise ValueError(f"constant {value!r} is out of the range of float")
        return str(numpy.float32(value)) + "F"

    def truth(self, value: bool) -> str:
        return str(int(value))

    def power(self, base, exponent):
        if exponent.q not in (1, 2) or exponent > self.LARGEST_EXPANDED_POWER:
            return f"pow{'f' * (self.real == 'float')}({self.doprint(base)}, {self.literal(float(exponent))})", ATOM
        factor = self._operand(base, PRODUCT + 1)
        root = [f"{self.functions['sqrt']}({self.doprint(base)})"] * (exponent.q == 2)
        return "(" + "*".join(root + [factor] * int(exponent)) + ")", ATOM

    def relation(self, lhs, operator, rhs):
        return f"{lhs} {operator} {rhs}", RELATION

    def select(self, condition, value, otherwise, numbers):
        return f"({condition} ? {value} : {otherwise})"

    def logic(self, name, operands):
        """`a && b`, and every operand of `||` that is not an atom in parentheses (gcc's
        -Wparentheses)."""
        if name == "And":
            return " && ".join(self._operand(operand, AND + 1) for operand in operands)
        return " || ".join(self._operand(operand, ATOM) for operand in operands)

    def negation(self, operand):
        return "!" + self._operand(operand, ATOM)

    def finite(self, text):
        return f"isfinite({text})"

    def repeat(self, kernel, count, state):
        """The starting state, a struct (`kernel_type`) that the kernel's function then changes
        in place (`kernel_run`): a run is always a temporary of its own."""
        return f"{{{{{', '.join(state)}}}}}"

    def part(self, state, index):
        return f"{state}.w[{index}]"


def kernel_function(kernel: str) -> str:
    """The C function of a kernel (static: each file defines those it runs)."""
    return f"{names.KERNEL_PREFIX}{kernel}"


def kernel_type(kernel: str) -> str:
    """The C struct of a kernel's state."""
    return f"{kernel_function(kernel)}_state"


def c_definitions(body, texts: list[str], real: str) -> list[tuple]:
    """A body's definitions as C declares them: (type, name, code, the statement that runs a
    kernel on the state it starts, or None)."""
    made = []
    for (symbol, value), text in zip(body.definitions, texts):
        if value.kind == REPEAT:
            kernel, count = value.value
            run = f"{kernel_function(kernel.name)}({count}, &{body.name(symbol)})"
            made.append((kernel_type(kernel.name), body.name(symbol), text, run))
        else:
            made.append(("int" if value.boolean else real, body.name(symbol), text, None))
    return made


# The contract's C array extent of each argument and output (`function.output`, or the function
# when it has one), as factors that are numbers or the suffixes of size macros
# (`6 * NAME_DOF`); any other function's output gets its size.
# contract §3 size macros that are the row count of a function, defined when it is generated.
C_ROW_MACROS = {"singularity_factors": "NUM_SINGULARITY_FACTORS"}


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
    parameters = parameters_read(body, robot)
    if robot.symbolic_parameters:
        arguments.append(f"const {robot.name}_params *p")
    inputs = list(function.inputs)
    passed = {name for call in function.calls for name in call.passes}
    unused = [a.name for a in function.arguments if a.name not in passed
              and not any(argument is a for _, argument, _, _ in inputs) and not (a.scalar and a.symbols[0] in body.read)]
    unused += ["p"] * bool(robot.symbolic_parameters and not parameters)
    definitions, outputs = printer.body(body)
    # a status or flag that a kernel computed is a real of its state, converted explicitly
    values = {output: [f"(int){t}" if n.kind == PART and _c_type(output, real) == "int" else t
                       for n, t in zip(nodes, texts)]
              for (output, texts), (_, nodes) in zip(function.parts(outputs), function.parts(body.outputs))}
    types = {result.name: _c_type(output, real) for call in function.calls
             for result, output in zip(call.results, functions[call.function].outputs)}
    return {
        "name": function.name,
        "summary": sentence(function.summary),
        "layouts": [_layout(output) for output in function.outputs],
        "operations": body.operation_count,
        "prototype": f"{_c_type(returned, real) if returned else 'void'} {robot.name}_{function.name}({', '.join(arguments)})",
        "unused": unused,
        "calls": [_c_call(call, functions[call.function], robot, macros) for call in function.calls],
        "inputs": [(types.get(argument.name, real), str(symbol), f"{argument.name}[{row * argument.symbols.cols + col}]")
                   for symbol, argument, row, col in inputs] + [(real, name, f"p->{name}") for name in parameters],
        "definitions": c_definitions(body, definitions, real),
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


def c_context(robot: Robot, generator: Generator, printer: CPrinter, real: str) -> dict:
    """The C header and source: functions with prototypes and size macros, in `real`."""
    context = common_context(robot)
    functions = generator.functions()
    by_name = {f.name: f for f in (*functions, *generator.loops)}  # the callees of functions that call another
    macros = _c_macros(robot, [*functions, *generator.loops])
    if generator.closed_form and generator.closed_form.free is not None:
        macros["IK_FREE_JOINT"] = generator.closed_form.free  # 0-based index into q of ik's q_free
    context.update({
        "prefix": robot.name.upper(),
        "real": real,
        "macros": list(macros.items()),
        "characteristic_length": characteristic_length(robot, generator, printer.number),
        "joint_lines": joint_lines(robot),
        "task_lines": task_lines(robot),
        "functions": [_c_function(f, robot, printer, macros, by_name) for f in functions],
        "kernels": [kernel | {"function": kernel_function(kernel["name"]), "type": kernel_type(kernel["name"]),
                              "definitions": c_definitions(kernel["body"], [text for *_, text in kernel["definitions"]],
                                                           f"{robot.name}_real")}
                    for kernel in kernels_context(generator, functions, printer)],
        "ik": ik_context(robot, generator, real, printer.number, f"{robot.name.upper()}_MAX_IK_SOLUTIONS"),
        "ik_numeric": generator.generates("ik_numeric") and ik_numeric_context(robot, printer.number),
        "velocity_ik": generator.generates("velocity_ik") and velocity_ik_context(robot, real),
    })
    return dict(sorted(context.items()))


BACKEND = Backend("c", (("c/robot.h.jinja", "{name}.h"), ("c/robot.c.jinja", "{name}.c")), CPrinter, c_context)
