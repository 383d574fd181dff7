"""The native backend: `NAME_native`, a CPython extension module around the generated C, with
the numpy API of `NAME.py` (float64 runs the double C, float32 the float C), batches in blocks
that gcc vectorises and threads split, and every function as a numpy gufunc.

It prints no expression. The C backend writes both builds (the float one named `NAME_float`,
so that the two link into one module), and the templates under `templates/native/` lay out
the glue: a table of every function's operands, one kernel per function and build that calls
the C function on a block of rows, the module (around its fixed C,
`templates/runtime/native_module.c`), and its `setup.py` and `pyproject.toml`.
"""

from dataclasses import replace
from math import prod

from jacgen.emission.backends.c import CPrinter, c_context
from jacgen.emission.backends.common import Backend
from jacgen.emission.catalogue import Function
from jacgen.emission.generator import Generator
from jacgen.inputs.robot import Robot
from jacgen.version import __version__

BUILDS = ("double", "float")
MODULE_DOC = """{name}'s generated C as a CPython extension module: the functions of {name}.py for numpy
arrays, at the C's speed (float64 runs the double C, float32 the float C).

The same names, arguments, shapes, batch rules, statuses and exceptions as {name}.py, so that
`import {name}_native as {name}` replaces it. Inputs may be lists or any numpy arrays; every
function also takes `out=` (arrays to write the results into), `threads=` (how many threads a
batch may use; default: the processors this process may run on) and `simd=False` (the C
function row by row instead of the vectorised blocks). JAX and PyTorch arrays stay with
{name}.py, which differentiates and compiles.

`gufuncs` holds every function as a numpy generalized ufunc (broadcasting, out=, axes=;
dask.array.apply_gufunc runs them on chunks). SIMD says what the batches run: avx512f, avx2,
baseline (vectorised for the oldest x86-64) or scalar (no vector math library at build)."""
# Every <math.h> function the C backend may call (printers.MATH_FUNCTIONS) that glibc's libmvec
# has in vector form; sqrt, fabs, floor and ceil are instructions.
VECTOR_MATH = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "exp", "log", "pow")
# A batch is split over threads when each gets at least this many operations (about 50 us).
WORK_PER_THREAD = 100_000


def build_name(robot: Robot, build: str) -> str:
    """The C name of a build: NAME (double) and NAME_float, which link into one module."""
    return robot.name if build == "double" else f"{robot.name}_float"


def _operand(name: str, shape: tuple, kind: str, default: str | None = None,
             scalar_allowed: bool = False) -> dict:
    """One input or output: kind "real", "int" (a status or count: C int, numpy int32) or
    "bool" (C int, numpy bool); its rows are `pad` apart in a block, a power of two, so that
    gcc vectorises their accesses; `scalar_allowed`: one number stands for each component."""
    size = prod(shape)
    return {"name": name, "shape": list(shape), "size": size, "pad": 1 << (size - 1).bit_length(),
            "kind": kind, "default": default, "scalar_allowed": scalar_allowed}


def c_string(text: str) -> str:
    """A C string literal of `text`."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _kind(output) -> str:
    return "bool" if output.boolean else "int" if output.integer else "real"


def _entry(name: str, summary: str, inputs: list[dict], outputs: list[dict], returned: int | None,
           operations: int, simd: bool, parameters: list[dict]) -> dict:
    """A function of the module: its operands (inputs, then parameters, then outputs), the index
    of the output C returns, and whether its kernel is a straight line to vectorise."""
    inputs = inputs + [_operand(p["name"], (), "real", p["value"]) for p in parameters]
    operands = inputs + outputs
    shown = [f"{o['name']}={o['default']}" if o["default"] else o["name"] for o in inputs]
    shown.insert(len(inputs) - len(parameters), "limits=True, *" if name == "ik" else "*")
    shown += ["out=None"] * (name != "ik") + ["threads=None", "simd=True"]
    arguments = [f"b{k}[l]" if not o["shape"] else f"b{k} + {o['pad']} * l"
                 for k, o in enumerate(inputs[:len(inputs) - len(parameters)])]
    arguments += [f"b{len(inputs) + k} + {o['pad']} * l" for k, o in enumerate(outputs) if k != returned]
    return {
        "name": name,
        "doc": c_string(f"{name}({', '.join(shown)})\n\n{summary[:1].upper()}{summary[1:]}."),
        "positional": len(inputs) - len(parameters),
        "inputs": len(inputs),
        "operands": operands,
        "signature": ",".join(f"({','.join(map(str, o['shape']))})" for o in inputs) + "->"
                     + ",".join(f"({','.join(map(str, o['shape']))})" for o in outputs),
        "arguments": arguments,
        "parameters": [f"b{len(inputs) - len(parameters) + k}[l]" for k in range(len(parameters))],
        "result": None if returned is None else f"b{len(inputs) + returned}[l]",
        "operations": max(operations, 1),
        "simd": simd,
    }


def entries(generator: Generator, parameters: list[dict]) -> list[dict]:
    """Every function of NAME.py with its operands, in the catalogue's order, ik last: it runs
    ik_branches' kernels and keeps the valid rows (its Python result is not its C one)."""
    loops = {loop.name: loop for loop in generator.loops}
    made = []
    for f in (*generator.functions(), *(loop for loop in loops.values() if loop.name != "ik")):
        inputs = [_operand(a.name, a.shape, "int" if a.integer else "real", a.default, a.scalar_allowed)
                  for a in f.arguments]
        outputs = [_operand(o.name, o.shape, _kind(o)) for o in f.outputs]
        returned = next((k for k, o in enumerate(f.outputs) if o is f.returned), None)
        straight = isinstance(f, Function)
        simd = straight and not any(call.function in loops for call in f.calls)
        made.append(_entry(f.name, f.summary, inputs, outputs, returned,
                           f.body.operation_count if straight else f.operations, simd, parameters))
    if "ik" in loops:
        branches = next(e for e in made if e["name"] == "ik_branches")
        ik = _entry("ik", loops["ik"].summary, branches["operands"][:branches["positional"]],
                    branches["operands"][branches["inputs"]:], None, branches["operations"], False, parameters)
        made.append(ik | {"wraps": made.index(branches)})
    return made


def constants(robot: Robot, generator: Generator, c: dict) -> list[tuple[str, str]]:
    """The module's constants, as NAME.py has them: (name, Python expression)."""
    made = [("DOF", str(robot.dof)), ("TASK", repr(tuple(robot.task))),
            ("CHARACTERISTIC_LENGTH", c["characteristic_length"]["value"])]
    if robot.symbolic_parameters:
        made.append(("PARAMETERS", repr({p.name: p.value for p in robot.symbolic_parameters})))
    if c["ik"]:
        made.append(("MAX_IK_SOLUTIONS", str(c["ik"]["max_solutions"])))
        if c["ik"]["free_joint"] is not None:
            made.append(("IK_FREE_JOINT", str(c["ik"]["free_joint"])))
    for f in sorted((*generator.functions(), *generator.loops), key=lambda f: f.name):
        made += [(f"{f.name.upper()}_{status.name}", str(status.value)) for status in f.statuses]
    return made


def native_context(robot: Robot, generator: Generator, printer, real: str) -> dict:
    """The module and both builds of the C it wraps (`real` does not apply: it has both)."""
    builds = {build: c_context(replace(robot, name=build_name(robot, build)), generator, CPrinter(build), build)
              for build in BUILDS}
    functions = entries(generator, builds["double"]["parameters"])
    native = {
        "name": robot.name,
        "module": f"{robot.name}_native",
        "version": __version__,
        "dof": robot.dof,
        "entries": functions,
        # the functions with kernels of their own (and gufuncs): all but ik, which comes last and
        # uses ik_branches', so that an entry's index is its kernels' index
        "kernels": [e for e in functions if "wraps" not in e],
        "constants": [(constant, c_string(value)) for constant, value in constants(robot, generator, builds["double"])],
        "module_doc": c_string(MODULE_DOC.format(name=robot.name)),
        "builds": [(build, build_name(robot, build)) for build in BUILDS],
        "vector_math": VECTOR_MATH,
        "work_per_thread": WORK_PER_THREAD,
        "largest_operands": max(len(e["operands"]) for e in functions),
        "largest_flags": max([o["size"] for e in functions for o in e["operands"] if o["kind"] == "bool"] or [1]),
    }
    for build in BUILDS:
        builds[build]["native"] = native | {"build": build, "c_name": build_name(robot, build)}
    return native | {"double": builds["double"], "float": builds["float"]}


BACKEND = Backend(
    "native",
    (("c/robot.h.jinja", "{name}.h", "double"), ("c/robot.c.jinja", "{name}.c", "double"),
     ("c/robot.h.jinja", "{name}_float.h", "float"), ("c/robot.c.jinja", "{name}_float.c", "float"),
     ("native/kernels.c.jinja", "{name}_native_double.c", "double"),
     ("native/kernels.c.jinja", "{name}_native_float.c", "float"),
     ("native/native.h.jinja", "{name}_native.h"), ("native/module.c.jinja", "{name}_native.c"),
     ("native/setup.py.jinja", "setup.py"), ("native/pyproject.toml.jinja", "pyproject.toml")),
    None, native_context)
