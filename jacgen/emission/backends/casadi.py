"""The CasADi backend: Python that builds each function as an SX graph (`templates/casadi/`),
and its printer."""

from jacgen.emission.backends.common import (Backend, characteristic_length, common_context, ik_numeric_context,
                                             kernels_context, parameters_read, sentence)
from jacgen.emission.backends.python import python_number
from jacgen.emission.catalogue import Function
from jacgen.emission.generator import Generator
from jacgen.model.node import is_zero
from jacgen.emission.printers import MATH_FUNCTIONS, Printer
from jacgen.inputs.robot import Robot


class CasadiPrinter(Printer):
    """Python building CasADi SX expressions: `casadi.cos(q1)`, `casadi.if_else(c, a, b)`."""

    functions = {name: f"casadi.{function}" for name, function in MATH_FUNCTIONS.items()}

    def select(self, condition, value, otherwise, numbers):
        return f"casadi.if_else({condition}, {value}, {otherwise})"

    def logic(self, name, operands):
        function = "casadi.logic_and" if name == "And" else "casadi.logic_or"
        text = self.doprint(operands[0])
        for operand in operands[1:]:
            text = f"{function}({text}, {self.doprint(operand)})"
        return text

    def negation(self, operand):
        return f"casadi.logic_not({self.doprint(operand)})"

    def finite(self, text):
        """NaN < inf is false, as is inf < inf."""
        return f"(casadi.fabs({text}) < casadi.inf)"


# How ik_numeric's loop (templates/python/ik_numeric_loop.jinja) reads over SX: a fixed number of steps.
LOOP_SYNTAX = {"where": "casadi.if_else", "logical_and": "casadi.logic_and", "maximum": "casadi.fmax",
               "finite": "cost >= 0.0", "iterations": "IK_NUMERIC_ITERATIONS",
               "widen": "", "q0": "q0", "fixed": True}


def _casadi_function(function: Function, robot: Robot, printer: CasadiPrinter) -> dict:
    body = function.body
    definitions, outputs = printer.body(body)
    results = []
    for (output, values), (_, texts) in zip(function.parts(body.outputs), function.parts(outputs)):
        positions = [divmod(k, output.cols) for k in range(output.size)]
        # Zeros stay structural zeros of the sparse SX result.
        results.append({"name": output.name, "rows": output.rows, "cols": output.cols,
                        "values": [(row, col, text) for (row, col), e, text in zip(positions, values, texts)
                                   if not is_zero(e)]})
    return {
        "name": function.name,
        "summary": sentence(function.summary),
        "operations": body.operation_count,
        "arguments": [(a.name, a.symbols.rows, a.symbols.cols) for a in function.arguments],
        "calls": [(", ".join(r.name for r in call.results), f"_{call.function}({', '.join(call.passes)}"
                   + ", p" * bool(robot.symbolic_parameters) + ")") for call in function.calls],
        "inputs": [(str(symbol), f"{argument.name}[{row}]" if argument.vector else f"{argument.name}[{row}, {col}]")
                   for symbol, argument, row, col in function.inputs]
        + [(name, f"p[{[q.name for q in robot.symbolic_parameters].index(name)}]")
           for name in parameters_read(body, robot)],
        "definitions": [(body.name(symbol), text) for (symbol, _), text in zip(body.definitions, definitions)],
        "results": results,
    }


def casadi_context(robot: Robot, generator: Generator, printer: CasadiPrinter, real: str) -> dict:
    """The CasADi module: every function as an SX graph, with the symbols of its inputs."""
    context = common_context(robot)
    functions = generator.without_loops()
    context["functions"] = [_casadi_function(f, robot, printer) for f in functions]
    context["kernels"] = kernels_context(generator, functions, printer)
    context["arguments"] = sorted({(a.name, a.symbols.rows, a.symbols.cols) for f in functions for a in f.arguments},
                                  key=lambda a: ("q", "q_dot", "mu_dot", "z", "target_rate", "gain", "damping", "target", "T", "mu", "q_seed",
                                                 "q_free", "weights").index(a[0]))
    context["characteristic_length"] = characteristic_length(robot, generator, python_number)
    context["ik"] = any(loop.name == "ik" and loop.casadi for loop in generator.loops)
    context["nearest_statuses"] = [(status.name, status.value) for f in functions if f.name == "ik_nearest"
                                   for status in f.statuses]
    context["ik_numeric"] = generator.generates("ik_numeric") and (
        ik_numeric_context(robot, python_number) | {"casadi": LOOP_SYNTAX})
    return dict(sorted(context.items()))


BACKEND = Backend("casadi", (("casadi/robot_casadi.py.jinja", "{name}_casadi.py"),),
                  lambda real: CasadiPrinter(), casadi_context)
