"""The data each template receives: a plain, sorted dict per language, decided here so
that templates only lay text out."""

from .functions import Function, Generator
from .printers import PythonPrinter
from .robot import Robot


def _common(robot: Robot) -> dict:
    return {
        "name": robot.name,
        "description": robot.description,
        "dof": robot.dof,
        "task": list(robot.task),
        "length_unit": robot.length_unit,
        "joints": [{"name": j.name, "kind": j.kind} for j in robot.joints],
        "parameters": [{"name": p.name, "value": repr(p.value)} for p in robot.symbolic_parameters],
    }


def _shape(function: Function) -> tuple[int, ...]:
    """Array shape of a result: matrices (rows, cols), column vectors (rows,), scalars ()."""
    if function.scalar:
        return ()
    return (function.rows,) if function.cols == 1 else (function.rows, function.cols)


def _python_function(function: Function, printer: PythonPrinter) -> dict:
    body = function.body
    shape = _shape(function)
    indices = [", ".join(["..."] + [str(i) for i in divmod(k, function.cols)[: len(shape)]])
               for k in range(len(body.outputs))]
    return {
        "name": function.name,
        "summary": function.summary,
        "output": function.output,
        "rows": function.rows,
        "cols": function.cols,
        "operations": body.operation_count,
        "inputs": [(f"q{i + 1}", f"q[..., {i}]") for i in body.joints_used],
        "definitions": [(str(symbol), printer.doprint(e)) for symbol, e in body.definitions],
        "shape": repr(shape),
        "outputs": [(index, printer.doprint(e)) for index, e in zip(indices, body.outputs)],
    }


def template_context(robot: Robot, generator: Generator, language: str, real: str) -> dict:
    context = _common(robot)
    if language == "python":
        printer = PythonPrinter()
        context["functions"] = [_python_function(f, printer) for f in generator.functions()]
    return dict(sorted(context.items()))
