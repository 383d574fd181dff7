"""Generated C as a shared library called from Python: for `jacgen verify` and the tests.

The C is compiled with the warning flags contract §3 promises (any warning is an error) and
loaded with ctypes; `CLibrary.evaluate` runs one generated function on a batch of joint
vectors, one native call per configuration.
"""

import ctypes
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from jacgen.emission.catalogue import Signature
from jacgen.errors import JacgenError
from jacgen.inputs.robot import Robot
from jacgen.building import first_error

# contract §3: the generated C compiles without a warning under these flags.
WARNING_FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Wconversion", "-Wshadow",
                 "-Wdouble-promotion", "-Werror")
C_TYPES = {"double": ctypes.c_double, "float": ctypes.c_float}
NUMPY_TYPES = {"double": np.float64, "float": np.float32}


class CompileError(JacgenError):
    """No C compiler, or the generated C did not compile cleanly."""


def c_compiler() -> str:
    """The compiler to use: $CC, else gcc; an error when it is not installed."""
    name = os.environ.get("CC", "gcc")
    if shutil.which(name) is None:
        raise CompileError(f"C compiler {name!r} not found (install gcc or set CC)")
    return name


def compile_shared(sources: list[Path], output: Path, flags: tuple[str, ...] = ("-O0",)) -> Path:
    """Compile `sources` into the shared library `output`; CompileError with gcc's first error.

    -O0 by default, for checking numbers: under -std=c99 gcc neither contracts nor
    reassociates, so the numbers are those of an -O2 build, and the build takes a fifth of
    the time (0.8 against 3.9 s for a 245 kB robot.c). Benches pass -O2."""
    compiler = c_compiler()
    command = [compiler, *WARNING_FLAGS, *flags, "-shared", "-fPIC", "-o", str(output),
               *(str(source) for source in sources), "-lm"]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        names = ", ".join(Path(source).name for source in sources)
        raise CompileError(f"{compiler} failed on {names}: {first_error(result.stderr)}")
    return output


class CLibrary:
    """One robot's compiled functions (`NAME_fk`, ...), called on numpy arrays: any function the
    catalogue declares (`signatures`: the straight-line ones and the loops), the same way."""

    def __init__(self, path: Path, robot: Robot, signatures: list[Signature], real: str):
        self.robot, self.real = robot, real
        self.dtype = NUMPY_TYPES[real]
        scalar = C_TYPES[real]
        self._library = ctypes.CDLL(str(path))
        self._signatures = {f.name: f for f in signatures}
        self._parameters = None  # the ctypes struct NAME_params
        pointer = ctypes.POINTER(scalar)
        extra = []
        if robot.symbolic_parameters:
            fields = [(p.name, scalar) for p in robot.symbolic_parameters]
            self._parameters = type(f"{robot.name}_params", (ctypes.Structure,), {"_fields_": fields})
            extra = [ctypes.POINTER(self._parameters)]
        for function in signatures:
            symbol = getattr(self._library, f"{robot.name}_{function.name}")
            returned = function.returned
            outputs = [ctypes.POINTER(ctypes.c_int) if o.boolean or o.integer else pointer
                       for o in function.outputs if o is not returned]
            symbol.argtypes = [(ctypes.c_int if a.integer else scalar) if a.scalar else pointer
                               for a in function.arguments] + outputs + extra
            symbol.restype = None if returned is None else ctypes.c_int if returned.integer or returned.boolean else scalar

    def evaluate(self, name: str, q: np.ndarray, *more: np.ndarray,
                 parameters: dict[str, float] | None = None) -> np.ndarray:
        """Function `name` at each row of q (k, dof) and of any further array arguments
        (q_dot): results (k, size), each output row-major and the outputs of a fused function
        side by side.

        Symbolic parameters take their nominal values unless given in `parameters`.
        """
        rows = [self.call(name, *arguments, parameters=parameters) for arguments in zip(q, *more)]
        return np.array([np.concatenate([np.ravel(value) for value in row]) for row in rows],
                        dtype=np.float64).reshape(len(q), -1)

    def call(self, name: str, *arguments, parameters: dict[str, float] | None = None) -> tuple:
        """One call of `NAME_name` with the function's arguments in order (arrays of any shape
        holding their values, scalars as numbers): its results in the catalogue's order, each
        in its numpy shape (a returned scalar as a number; truth values and statuses as ints).

        Symbolic parameters take their nominal values unless given in `parameters`.
        """
        function = self._signatures[name]
        real = C_TYPES[self.real]
        given = [(ctypes.c_int if argument.integer else real)(value) if argument.scalar else
                 np.ascontiguousarray(np.ravel(value), dtype=self.dtype)
                 for argument, value in zip(function.arguments, arguments, strict=True)]
        returned = function.returned
        arrays = {output.name: np.zeros(output.size, dtype=np.intc if output.boolean or output.integer else self.dtype)
                  for output in function.outputs if output is not returned}
        value = getattr(self._library, f"{self.robot.name}_{name}")(
            *(argument if isinstance(argument, ctypes._SimpleCData) else _pointer(argument) for argument in given),
            *(_pointer(array) for array in arrays.values()), *self._extra(parameters))
        return tuple(value if output is returned else _widened(arrays[output.name]).reshape(output.shape)
                     for output in function.outputs)

    def _extra(self, parameters: dict[str, float] | None = None) -> list:
        """The trailing `const NAME_params *p` argument, if the robot has runtime parameters."""
        if self._parameters is None:
            return []
        values = {p.name: p.value for p in self.robot.symbolic_parameters} | (parameters or {})
        return [ctypes.byref(self._parameters(*(values[p.name] for p in self.robot.symbolic_parameters)))]


def _pointer(array: np.ndarray):
    """A C pointer to a numpy array's first element, of its type."""
    kind = {np.dtype(np.intc): ctypes.c_int, np.dtype(np.float64): ctypes.c_double, np.dtype(np.float32): ctypes.c_float}
    return array.ctypes.data_as(ctypes.POINTER(kind[array.dtype]))


def _widened(array: np.ndarray) -> np.ndarray:
    """Reals as float64, whatever the build's type; ints as they are."""
    return array.astype(np.float64) if array.dtype.kind == "f" else array
