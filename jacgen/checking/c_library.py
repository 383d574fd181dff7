"""Generated C as a shared library called from Python: for `jacgen verify` and the tests.

The C is compiled with the warning flags contract §3 promises (any warning is an error) and
loaded with ctypes; `CLibrary.evaluate` runs one generated function on a batch of joint
vectors, one native call per configuration. `build_native` builds and imports the native
module (`generate --lang native`) the way pip does, through its own setup.py.
"""

import ctypes
import importlib.util
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from jacgen.emission.catalogue import Function
from jacgen.errors import JacgenError
from jacgen.inputs.robot import Robot
from jacgen.solvers.differential import IK_NUMERIC_DEFAULTS

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


def build_native(folder: Path, name: str):
    """Build NAME_native in `folder` (what `generate --lang native` wrote for the robot) with its
    setup.py, and import it; CompileError with the first error."""
    result = subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"], cwd=folder,
                            capture_output=True, text=True)
    built = sorted(folder.glob(f"{name}_native.*.so")) + sorted(folder.glob(f"{name}_native.*.pyd"))
    if result.returncode != 0 or not built:
        raise CompileError(f"building {name}_native failed: {first_error(result.stderr + result.stdout)}")
    module_name = f"{name}_native"
    if module_name in sys.modules:  # an extension module loads once per process
        return sys.modules[module_name]
    spec = importlib.util.spec_from_file_location(module_name, built[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules[module_name] = module
    return module


def first_error(output: str) -> str:
    """The line of a compiler's (or tool's) output worth one error line: its first error."""
    lines = output.splitlines()
    return next((line for line in lines if " error: " in line or "cannot build: " in line),
                lines[0] if lines else "no output").strip()


class CLibrary:
    """One robot's compiled functions (`NAME_fk`, ...), called on numpy arrays."""

    def __init__(self, path: Path, robot: Robot, functions: list[Function], real: str):
        self.robot, self.real = robot, real
        self.dtype = NUMPY_TYPES[real]
        scalar = C_TYPES[real]
        self._library = ctypes.CDLL(str(path))
        self._functions = {f.name: f for f in functions}
        self._parameters = None  # the ctypes struct NAME_params
        pointer = ctypes.POINTER(scalar)
        extra = []
        if robot.symbolic_parameters:
            fields = [(p.name, scalar) for p in robot.symbolic_parameters]
            self._parameters = type(f"{robot.name}_params", (ctypes.Structure,), {"_fields_": fields})
            extra = [ctypes.POINTER(self._parameters)]
        for function in functions:
            symbol = getattr(self._library, f"{robot.name}_{function.name}")
            returned = function.returned
            outputs = [ctypes.POINTER(ctypes.c_int) if o.boolean else pointer for o in function.outputs if o is not returned]
            symbol.argtypes = [scalar if a.scalar else pointer for a in function.arguments] + outputs + extra
            symbol.restype = None if returned is None else ctypes.c_int if returned.integer or returned.boolean else scalar

    def evaluate(self, name: str, q: np.ndarray, *more: np.ndarray,
                 parameters: dict[str, float] | None = None) -> np.ndarray:
        """Function `name` at each row of q (k, dof) and of any further array arguments
        (q_dot): results (k, size), each output row-major and the outputs of a fused function
        side by side.

        Symbolic parameters take their nominal values unless given in `parameters`.
        """
        function = self._functions[name]
        symbol = getattr(self._library, f"{self.robot.name}_{name}")
        extra = self._extra(parameters)
        inputs = [np.ascontiguousarray(array, dtype=self.dtype) for array in (q, *more)]
        starts = np.cumsum([0] + [output.size for output in function.outputs])
        results = np.empty((len(inputs[0]), starts[-1]), dtype=self.dtype)
        pointer = ctypes.POINTER(C_TYPES[self.real])
        for k, out in enumerate(results):
            arguments = [array[k].ctypes.data_as(pointer) for array in inputs]
            if function.scalar:
                out[0] = symbol(*arguments, *extra)
            else:
                symbol(*arguments, *(out[start:].ctypes.data_as(pointer) for start in starts[:-1]), *extra)
        return results.astype(np.float64)

    def _extra(self, parameters: dict[str, float] | None = None) -> list:
        """The trailing `const NAME_params *p` argument, if the robot has runtime parameters."""
        if self._parameters is None:
            return []
        values = {p.name: p.value for p in self.robot.symbolic_parameters} | (parameters or {})
        return [ctypes.byref(self._parameters(*(values[p.name] for p in self.robot.symbolic_parameters)))]

    def ik(self, target: np.ndarray, max_solutions: int, parameters: dict[str, float] | None = None,
           q_free: float | None = None) -> np.ndarray:
        """`NAME_ik` for one target (4x4 pose or task vector) and, with a free joint, its
        angle: the solutions, (k, dof)."""
        pointer = ctypes.POINTER(C_TYPES[self.real])
        target = np.ascontiguousarray(np.ravel(target), dtype=self.dtype)
        solutions = np.zeros(max_solutions * self.robot.dof, dtype=self.dtype)
        free = [] if q_free is None else [C_TYPES[self.real](q_free)]
        count = getattr(self._library, f"{self.robot.name}_ik")(target.ctypes.data_as(pointer), *free,
                                                                 solutions.ctypes.data_as(pointer),
                                                                 *self._extra(parameters))
        return solutions[: count * self.robot.dof].reshape(count, self.robot.dof).astype(np.float64)

    def ik_branches(self, target: np.ndarray, max_solutions: int,
                    q_free: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`NAME_ik_branches` for one target: every branch (max_solutions, dof), and whether
        each is valid and inside the limits."""
        pointer = ctypes.POINTER(C_TYPES[self.real])
        target = np.ascontiguousarray(np.ravel(target), dtype=self.dtype)
        q = np.zeros(max_solutions * self.robot.dof, dtype=self.dtype)
        valid, in_limits = (np.zeros(max_solutions, dtype=np.intc) for _ in range(2))
        free = [] if q_free is None else [C_TYPES[self.real](q_free)]
        flags = ctypes.POINTER(ctypes.c_int)
        getattr(self._library, f"{self.robot.name}_ik_branches")(
            target.ctypes.data_as(pointer), *free, q.ctypes.data_as(pointer), valid.ctypes.data_as(flags),
            in_limits.ctypes.data_as(flags), *self._extra())
        return q.reshape(max_solutions, self.robot.dof).astype(np.float64), valid, in_limits

    def ik_nearest(self, target: np.ndarray, q_seed: np.ndarray, weights: np.ndarray,
                   q_free: float | None = None) -> tuple[np.ndarray, int]:
        """`NAME_ik_nearest`: (q, status)."""
        pointer = ctypes.POINTER(C_TYPES[self.real])
        target, q_seed, weights = (np.ascontiguousarray(np.ravel(a), dtype=self.dtype) for a in (target, q_seed, weights))
        q = np.zeros(self.robot.dof, dtype=self.dtype)
        free = [] if q_free is None else [C_TYPES[self.real](q_free)]
        status = getattr(self._library, f"{self.robot.name}_ik_nearest")(
            target.ctypes.data_as(pointer), q_seed.ctypes.data_as(pointer), *free, weights.ctypes.data_as(pointer),
            q.ctypes.data_as(pointer), *self._extra())
        return q.astype(np.float64), int(status)

    def velocity_ik(self, q: np.ndarray, mu_dot: np.ndarray, damping: float) -> tuple[np.ndarray, int]:
        """`NAME_velocity_ik`: (q_dot, status)."""
        pointer = ctypes.POINTER(C_TYPES[self.real])
        q = np.ascontiguousarray(q, dtype=self.dtype)
        mu_dot = np.ascontiguousarray(mu_dot, dtype=self.dtype)
        q_dot = np.zeros(self.robot.dof, dtype=self.dtype)
        status = getattr(self._library, f"{self.robot.name}_velocity_ik")(
            q.ctypes.data_as(pointer), mu_dot.ctypes.data_as(pointer), C_TYPES[self.real](damping),
            q_dot.ctypes.data_as(pointer), *self._extra())
        return q_dot.astype(np.float64), int(status)

    def ik_numeric(self, target: np.ndarray, q0: np.ndarray, max_iter: int = IK_NUMERIC_DEFAULTS["max_iter"],
                   tol: float = IK_NUMERIC_DEFAULTS["tol"]) -> tuple[np.ndarray, int]:
        """`NAME_ik_numeric` from q0: (q, status); the defaults are the generated Python's."""
        pointer = ctypes.POINTER(C_TYPES[self.real])
        target = np.ascontiguousarray(np.ravel(target), dtype=self.dtype)
        start = np.ascontiguousarray(q0, dtype=self.dtype)
        q = np.zeros(self.robot.dof, dtype=self.dtype)
        function = getattr(self._library, f"{self.robot.name}_ik_numeric")
        function.argtypes = [pointer, pointer, ctypes.c_int, C_TYPES[self.real], pointer]
        status = function(target.ctypes.data_as(pointer), start.ctypes.data_as(pointer), max_iter, tol,
                          q.ctypes.data_as(pointer), *self._extra())
        return q.astype(np.float64), status

