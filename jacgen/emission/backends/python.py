"""The numpy backend (any array API namespace: numpy, JAX, PyTorch; batched): its printer, the
data of `templates/python/`."""

import numpy
import sympy

from jacgen.emission.backends.common import (Backend, characteristic_length, common_context, dimensions, ik_context,
                                             ik_numeric_context, kernels_context, velocity_ik_context)
from jacgen.emission.catalogue import Function
from jacgen.emission.generator import Generator
from jacgen.model.node import ADD, CALL, MUL, NUMBER, SELECT, SYMBOL
from jacgen.emission.printers import ATOM, MATH_FUNCTIONS, RELATION, Printer
from jacgen.inputs.robot import Robot


class PythonPrinter(Printer):
    """Python over the array API namespace `xp` of the inputs (numpy, JAX, PyTorch), batched.

    A select is `xp.where`, both sides computed (the generated function ignores numpy's
    floating-point warnings of the side not taken). A select of two numbers makes the first an
    array of the function's `dtype`: otherwise PyTorch makes it float32, and numpy an integer
    array that turns float32 arithmetic into float64 (the context makes statuses integers again).
    """

    functions = {name: f"xp.{function}" for name, function in (MATH_FUNCTIONS | {"Abs": "abs"}).items()}
    COMPARISONS = {">=": "greater_equal", ">": "greater", "<=": "less_equal", "<": "less", "==": "equal",
                   "!=": "not_equal"}

    def relation(self, lhs, operator, rhs):
        return f"xp.{self.COMPARISONS[operator]}({lhs}, {rhs})", ATOM

    def select(self, condition, value, otherwise, numbers):
        value = f"xp.asarray({value}, dtype=dtype)" if numbers else value
        return f"xp.where({condition}, {value}, {otherwise})"

    def logic(self, name, operands):
        return (" & " if name == "And" else " | ").join(self._operand(operand, RELATION) for operand in operands)

    def negation(self, operand):
        return f"xp.logical_not({self.doprint(operand)})"

    def finite(self, text):
        return f"xp.isfinite({text})"

    def _state(self, node):
        """A constant entry of a kernel's state as an array of the batch's shape, so that each
        part read is one (a loop broadcasts the other entries; a call's compute at the shapes
        of what they read, as written out)."""
        text = self.doprint(node)
        return f"xp.full(batch, {text}, dtype=dtype, device=device)" if node.constant else text

    def repeat(self, kernel, count, state):
        return f"_{kernel}(xp, {count}, ({', '.join(state)},))"


def python_number(value) -> str:
    """A constant as Python reads it back exactly (the numpy and CasADi modules alike)."""
    return repr(float(value))


# How ik_numeric's loop (templates/python/ik_numeric_loop.jinja) reads over arrays.
LOOP_SYNTAX = {"where": "xp.where", "logical_and": "xp.logical_and", "maximum": "xp.maximum",
               "finite": "(cost >= 0.0) & (max_iter >= 0)", "iterations": "max(max_iter, 0)",
               "widen": "[..., None]", "q0": "xp.asarray(q0, dtype=q.dtype)", "fixed": False}


def _python_function(function: Function, printer: PythonPrinter, parameters: list[dict]) -> dict:
    body = function.body
    definitions, outputs = printer.body(body)
    shapes = [() if a.scalar else a.symbols.shape[:1] if a.vector else a.symbols.shape for a in function.arguments]
    batched = sum(not a.scalar for a in function.arguments)
    of_parameters = _of_only(body, {sympy.Symbol(p["name"], real=True) for p in parameters})
    results = []
    for (output, values), (_, texts) in zip(function.parts(body.outputs), function.parts(outputs)):
        dtype = ", dtype=xp.bool" if output.boolean else ", dtype=dtype"
        codes = []
        for k, (value, code) in enumerate(zip(values, texts)):
            if not value.free_symbols:  # a number or truth value: an array of the batch shape, like the others
                code = f"xp.full(batch, {code}{dtype}, device=device)"
            elif value.free_symbols <= of_parameters:  # of symbolic parameters alone
                code = f"xp.broadcast_to(xp.asarray({code}{dtype}, device=device), batch)"
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
        "shape": " and ".join(dimensions(o) for o in function.outputs),
        "operations": body.operation_count,
        # symbolic parameters are arguments of shape (): in the arguments' dtype, and broadcast with them
        "scalar_allowed": [a.name for a in function.arguments if a.scalar_allowed],
        "arguments": [(a.name, repr(shape)) for a, shape in zip(function.arguments, shapes)]
                     + [(p["name"], "()") for p in parameters],
        "signature": ", ".join([f"{a.name}={a.default}" if a.default else a.name for a in function.arguments] + ["*"] * bool(parameters)
                               + [f"{p['name']}={p['value']}" for p in parameters]),
        "selects": any(e.contains(SELECT) for e in [v for _, v in body.definitions] + list(body.outputs)),
        "calls": [(", ".join(r.name for r in call.results), f"{call.function}({', '.join(call.passes)}"
                   + "".join(f", {p['name']}={p['name']}" for p in parameters) + ")") for call in function.calls],
        "inputs": [(str(symbol), f"{argument.name}[..., {row}]" if argument.vector else f"{argument.name}[..., {row}, {col}]")
                   for symbol, argument, row, col in function.inputs if symbol in read],
        "trig": repr(tuple(offsets)) if trig else None,
        "definitions": [(body.name(symbol), trig.get(symbol) or text) for (symbol, _), text in zip(body.definitions, definitions)],
        "results": results,
    }


def _of_only(body, symbols: set) -> set:
    """`symbols`, and the temporaries of `body` that read nothing else (directly or not)."""
    found = set(symbols)
    for symbol, value in body.definitions:
        if value.free_symbols <= found:
            found.add(symbol)
    return found


def _joint_trig(function: Function) -> tuple[dict, list]:
    """The definitions cos(q_j + offset) and sin(q_j + offset) of the argument q, and their
    negations (an offset of a quarter turn swaps them), as entries of `_cos_sin`'s array, and
    the offsets: ({symbol: code}, offset per joint). Read from the array, XLA computes them
    once; a call of its own is computed again in every fused loop that reads it."""
    joints = {symbol: row for symbol, argument, row, _ in function.inputs if argument.name == "q"}
    if not joints:
        return {}, []
    offsets, trig = [0.0] * function.arguments[0].size, {}
    for symbol, value in function.body.definitions:
        sign = ""
        if value.kind == MUL and len(value.args) == 2 and value.args[0].kind == NUMBER and value.args[0].value == -1:
            sign, value = "-", value.args[1]
        if value.kind == CALL and value.value in ("cos", "sin"):
            angle = value.args[0]
            offset, angle = angle.args if angle.kind == ADD and len(angle.args) == 2 else (None, angle)
            if angle.kind == SYMBOL and angle.value in joints and (offset is None or offset.kind == NUMBER):
                row = joints[angle.value]
                offsets[row] = float(offset.value) if offset else 0.0
                trig[symbol] = f"{sign}trig[..., {2 * row + (value.value == 'sin')}]"
    return trig, offsets


def python_context(robot: Robot, generator: Generator, printer: PythonPrinter, real: str) -> dict:
    """The numpy module's templates: every function and the IK documentation (double only)."""
    context = common_context(robot)
    context["functions"] = [_python_function(f, printer, context["parameters"]) for f in generator.functions()]
    context["kernels"] = kernels_context(generator, generator.functions(), printer)
    context["ik"] = ik_context(robot, generator, "double", python_number, "MAX_IK_SOLUTIONS")
    context["characteristic_length"] = characteristic_length(robot, generator, python_number)
    context["ik_numeric"] = generator.generates("ik_numeric") and (
        ik_numeric_context(robot, python_number) | {"python": LOOP_SYNTAX})
    context["velocity_ik"] = generator.generates("velocity_ik") and velocity_ik_context(robot, "double")
    return dict(sorted(context.items()))


BACKEND = Backend("python", (("python/robot.py.jinja", "{name}.py"),),
                  lambda real: PythonPrinter(), python_context)
