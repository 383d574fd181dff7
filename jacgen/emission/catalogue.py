"""The catalogue: every function a robot can get, in the order the backends emit them, those
each one calls, and their arguments and outputs with shapes and the contract's C extents,
as data. `generator.Generator` builds each one from its algorithm; a backend lays out what
the catalogue says.
"""

from dataclasses import dataclass

import numpy
import sympy

from jacgen.emission.lowering import Body
from jacgen.model.node import Node
from jacgen.solvers import differential, ik_limits

SECOND_ORDER = ("fk_jacobian_dot", "jacobian_dot", "bias_acceleration", "task_jacobian_dot", "hessian")


@dataclass(frozen=True)
class Status:
    """A value of a function's integer status, the same in every backend (`NAME_VELOCITY_IK_OK`)."""

    name: str
    value: int
    meaning: str = ""


@dataclass(frozen=True)
class Declaration:
    """What is fixed about a function whatever the robot: the functions it calls (`--functions`
    generates them too), the values of its status, and the facts `verify` needs to compare it."""

    name: str
    callees: tuple[str, ...] = ()
    statuses: tuple[Status, ...] = ()
    euler_rows: bool = False  # rows of Euler angles or their rates: undefined where cos(pitch) = 0
    of_js: bool = False  # a function of Js: undefined where cos(pitch) = 0 when Js is the task Jacobian


def _statuses(*pairs) -> tuple[Status, ...]:
    return tuple(Status(*pair) for pair in pairs)


# Every function a robot can get, in the order the backends emit them. `ik`, `ik_numeric` and
# the general 6R solver's `ik_branches` are loops (`Loop`), which each language's template
# writes around the generated functions they call.
CATALOGUE = (
    Declaration("fk"), Declaration("jacobian"), Declaration("fk_jacobian"), Declaration("jacobian_tool"),
    Declaration("task", euler_rows=True), Declaration("task_jacobian", euler_rows=True),
    *(Declaration(name, euler_rows=name == "task_jacobian_dot") for name in SECOND_ORDER),
    Declaration("link_poses"), Declaration("link_velocities"),
    Declaration("singularity_factors"), Declaration("manipulability", of_js=True), Declaration("jacobian_det", of_js=True),
    Declaration("manipulability_gradient", of_js=True), Declaration("velocity_ellipsoid"),
    Declaration("condition_number", of_js=True),
    Declaration("velocity_ik", statuses=_statuses(("OK", differential.VELOCITY_IK_OK),
                                                  ("SINGULAR", differential.VELOCITY_IK_SINGULAR),
                                                  ("NOT_FINITE", differential.VELOCITY_IK_NOT_FINITE))),
    Declaration("velocity_ik_nullspace"), Declaration("resolved_rate"),
    Declaration("ik_numeric_step"),
    Declaration("ik_numeric", ("ik_numeric_step",), _statuses(*differential.IK_NUMERIC_STATUSES)),
    Declaration("ik_branches"),
    Declaration("ik_nearest", ("ik_branches",), _statuses(*ik_limits.IK_NEAREST_STATUSES)),
    Declaration("ik", ("ik_branches",)),
)
DECLARED = {declaration.name: declaration for declaration in CATALOGUE}
FUNCTION_NAMES = tuple(DECLARED)


# The contract's extent of every array, in named dimensions (C's `double J[6 * NAME_DOF]`), by
# argument name or "function.output", else by the function an output is the result of
# (`result_of`) or belongs to; an array not listed is a pose (16) or as long as it is.
EXTENTS = {
    "q": ("DOF",),
    "T": (16,),
    "mu": ("TASK_DIM",),
    "ik_branches.q": ("MAX_IK_SOLUTIONS", "DOF"),
    "ik_branches.valid": ("MAX_IK_SOLUTIONS",),
    "ik_branches.in_limits": ("MAX_IK_SOLUTIONS",),
    "ik_nearest.q": ("DOF",),
    "q_seed": ("DOF",),
    "weights": ("DOF",),
    "mu_dot": ("TASK_DIM",),
    "velocity_ik.q_dot": ("DOF",),
    "velocity_ik_nullspace.q_dot": ("DOF",),
    "resolved_rate.q_dot": ("DOF",),
    "z": ("DOF",),
    "gain": ("TASK_DIM",),
    "target_rate": ("TASK_DIM",),
    "link_poses": ("DOF", 4, 4),
    "link_velocities": ("DOF", 6),
    "manipulability_gradient": ("DOF",),
    "ik_numeric_step.q_start": ("DOF",),
    "ik_numeric_step.q_next": ("DOF",),
    "ik_general_start.q": ("DOF",),
    "ik_general_start_fallback.q": ("DOF",),
    "ik_general_residual.e": (6,),
    "ik_general_residual.J": (6, 6),
    "ik_general_limits.q": ("DOF",),
    "q_solution": ("DOF",),
    "fk": (16,),
    "jacobian": (6, "DOF"),
    "jacobian_tool": (6, "DOF"),
    "task": ("TASK_DIM",),
    "task_jacobian": ("TASK_DIM", "DOF"),
    "q_dot": ("DOF",),
    "jacobian_dot": (6, "DOF"),
    "bias_acceleration": (6,),
    "task_jacobian_dot": ("TASK_DIM", "DOF"),
    "hessian": ("DOF", 6, "DOF"),
    "singularity_factors": ("NUM_SINGULARITY_FACTORS",),
}


def extent_of(key: str, size: int) -> tuple[int | str, ...]:
    return EXTENTS.get(key, (16,) if size == 16 else ("TASK_DIM",) if key == "target" else (size,))


def in_catalogue_order(functions) -> list:
    """Functions (a loop's parts where the loop is) in the order the backends emit them."""
    return sorted(functions, key=lambda function: FUNCTION_NAMES.index(function.part_of or function.name))


def with_callees(names) -> frozenset[str]:
    """The functions named and those they call (ValueError for a name no robot has)."""
    unknown = [name for name in names if name not in FUNCTION_NAMES]
    if unknown:
        raise ValueError(f"unknown function {unknown[0]!r}; expected some of {', '.join(FUNCTION_NAMES)}")
    return frozenset(names).union(*(DECLARED[name].callees for name in names))


@dataclass(frozen=True)
class Argument:
    """An input of a generated function: its name and its symbols, in its shape."""

    name: str
    symbols: sympy.Matrix
    vector: bool = True  # numpy shape (..., rows); else (..., rows, cols)
    scalar: bool = False  # one number: by value in C, shape (...) in numpy, its symbol named as the argument
    default: str | None = None  # a scalar's default in Python
    integer: bool = False  # a count (ik_numeric's max_iter): an int in C
    scalar_allowed: bool = False  # a vector that Python also takes as one number for each component (a gain)

    @property
    def size(self) -> int:
        return len(self.symbols)

    @property
    def shape(self) -> tuple[int, ...]:
        """numpy shape of one call's value: () for a scalar, (rows,) for a vector."""
        return () if self.scalar else (self.size,) if self.vector else self.symbols.shape

    @property
    def extent(self) -> tuple[int | str, ...]:
        return extent_of(self.name, self.size)


@dataclass(frozen=True)
class Output:
    """One result of a generated function: a rows x cols matrix, or a scalar returned by value."""

    name: str  # the array's name in C
    rows: int
    cols: int
    scalar: bool = False
    vector: bool = False  # a column vector: numpy shape (rows,), even for one row
    result_of: str = ""  # the function whose result this is, when the function fuses several
    boolean: bool = False  # truth values
    integer: bool = False  # a status: an int in C and numpy
    layers: int = 1  # > 1: a stack of `layers` matrices of rows / layers x cols (the hessian)
    extent: tuple[int | str, ...] = ()  # the contract's extent, in named dimensions (see EXTENTS)

    @property
    def size(self) -> int:
        return self.rows * self.cols

    @property
    def shape(self) -> tuple[int, ...]:
        """numpy shape: matrices (rows, cols) (a one-joint Jacobian too), vectors (rows,), scalars (),
        stacks (layers, rows / layers, cols)."""
        if self.scalar:
            return ()
        if self.layers > 1:
            return (self.layers, self.rows // self.layers, self.cols)
        return (self.rows,) if self.vector else (self.rows, self.cols)


@dataclass(frozen=True)
class Call:
    """Another generated function that a function calls before its body, passing some of its
    arguments; the body reads the callee's results, held as `results` (arguments named as
    the local arrays, with their symbols)."""

    function: str
    passes: tuple[str, ...]
    results: tuple[Argument, ...]


@dataclass(frozen=True)
class Signature:
    """How a generated function is called, in every language: its arguments, and its results
    (the contract's C returns a scalar one by value and writes the others into arrays)."""

    name: str
    summary: str
    outputs: tuple[Output, ...]
    arguments: tuple[Argument, ...]
    part_of: str = ""  # the loop whose template runs it, for a part of one (the general 6R solver's)

    @property
    def declaration(self) -> Declaration | None:
        """Its entry in the catalogue; None for the parts of a loop that the contract does not name."""
        return DECLARED.get(self.name)

    @property
    def statuses(self) -> tuple[Status, ...]:
        return self.declaration.statuses if self.declaration else ()

    @property
    def scalar(self) -> bool:
        """Returns its one result by value."""
        return len(self.outputs) == 1 and self.outputs[0].scalar

    @property
    def returned(self) -> Output | None:
        """The result C returns by value (a scalar), the others being arrays."""
        return next((output for output in self.outputs if output.scalar), None)


@dataclass(frozen=True)
class Loop(Signature):
    """A function with control flow, which each language's template writes around the generated
    functions it calls (`ik`, `ik_numeric`, the general 6R solver's `ik_branches`)."""

    operations: int = 0  # a bound on the operations of one call (no Body counts them)
    casadi: str | None = None  # "steps": CasADi runs a fixed number of steps and takes no integers; None: not there


@dataclass(frozen=True)
class Function(Signature):
    """One generated straight-line function; its body's outputs are those of `outputs`, concatenated."""

    body: Body = None
    calls: tuple[Call, ...] = ()

    @property
    def inputs(self):
        """(symbol, argument, row, col) of every input the body reads, in argument order, then
        the results of its calls."""
        for argument in (*self.arguments, *(result for call in self.calls for result in call.results)):
            for k, symbol in enumerate(argument.symbols):
                if symbol in self.body.read and not argument.scalar:
                    yield (symbol, argument, *divmod(k, argument.symbols.cols))

    def parts(self, values: tuple[sympy.Expr, ...]):
        """The body's outputs split per output: (Output, its values row-major)."""
        start = 0
        for output in self.outputs:
            yield output, values[start:start + output.size]
            start += output.size


# A function's result as `matrix`, `vector`, `scalar` and `status` make it: its Output (what it
# is truth values, and its extent, `Generator.function` adds) and its values, row by row.
Result = tuple[Output, list]


def matrix(name: str, value, result_of: str = "", layers: int = 1) -> Result:
    """A sympy Matrix, or a 2-D array of nodes (a stack of `layers` matrices: the hessian)."""
    rows, cols = value.shape
    return (Output(name, rows, cols, result_of=result_of, layers=layers),
            list(value.flat) if isinstance(value, numpy.ndarray) else list(value))


def _entry(value):
    """A node as it is; a number or sympy value as sympy's (the lowering takes both onto the graph)."""
    return value if isinstance(value, Node) else sympy.sympify(value)


def vector(name: str, values, result_of: str = "") -> Result:
    values = [_entry(value) for value in values]
    return Output(name, len(values), 1, vector=True, result_of=result_of), values


def scalar(name: str, value) -> Result:
    return Output(name, 1, 1, scalar=True), [_entry(value)]


def status(name: str, value) -> Result:
    return Output(name, 1, 1, scalar=True, integer=True), [_entry(value)]
