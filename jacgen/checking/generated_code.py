"""One robot's generated code, loaded and called on batches, backend by backend: the numpy
module, the CasADi module, the C built for the host (double and float, through ctypes) or
for an emulated target (`target.Emulator`). `jacgen verify` compares what it returns with
the reference; the tests call the same functions through it."""

from pathlib import Path

import numpy as np

from jacgen.checking.c_library import CLibrary
from jacgen.checking.cortex_m4f import Emulator
from jacgen.emission.catalogue import Signature
from jacgen.inputs.robot import Robot
from jacgen.building import import_module

HOST_BACKENDS = ("python", "casadi", "c double", "c float")  # what `jacgen verify` compares on the host
# NAME_native as `verify --native` calls it: batches of float64 (the double C) and float32 (the
# float C) through the SIMD kernels and through the C function row by row, and one call per row.
NATIVE_BACKENDS = ("native double", "native double scalar", "native double one", "native float",
                   "native float scalar")
TARGET_BACKENDS = {"cortex-m4f": "cortex-m4f float"}  # `verify --target`: the target's float C alone


class GeneratedCode:
    """The generated code of one robot, each backend calling any function the catalogue declares
    on a batch: the host's (Python, CasADi, C double and float) or the emulated target's float C."""

    def __init__(self, robot: Robot, signatures: list[Signature], folder: Path, libraries: dict[str, Path],
                 emulator: Emulator | None = None, native=None):
        """signatures: the robot's functions (`Generator.signatures`); folder: where `generate -o`
        wrote the double-precision Python and CasADi (folder/NAME/); libraries: the compiled C by
        real type; emulator: the target instead of the host; native: the built NAME_native
        module, to compare as well."""
        self.robot, self.emulator = robot, emulator
        self.signatures = {f.name: f for f in signatures}
        self.names = HOST_BACKENDS if emulator is None else (TARGET_BACKENDS["cortex-m4f"],)
        self.native = {}
        if native is not None:
            self.names += NATIVE_BACKENDS
            self.native = {backend: NativeCalls(native, backend) for backend in NATIVE_BACKENDS}
        self.nominal = {p.name: p.value for p in robot.symbolic_parameters}  # keywords of the Python functions
        if emulator is None:
            self.python = import_module(folder / robot.name / f"{robot.name}.py", f"_jacgen_{robot.name}")
            self.casadi = import_module(folder / robot.name / f"{robot.name}_casadi.py", f"_jacgen_{robot.name}_casadi")
            # CasADi's functions take the parameters as one trailing vector
            self.casadi_parameters = [list(self.casadi.PARAMETERS.values())] if self.nominal else []
        self.c = {real: CLibrary(path, robot, signatures, real) for real, path in libraries.items()}

    def module(self, backend: str):
        """What answers NAME.py's calls for a backend: the numpy module, or NAME_native called one
        of its ways."""
        return self.python if backend == "python" else self.native[backend]

    def has(self, backend: str, name: str) -> bool:
        """Whether the backend has the function: CasADi lacks the loops it cannot run, and the
        target runs the contract's functions only."""
        if backend == "casadi":
            return hasattr(self.casadi, name)
        return name in (self.emulator.calls if self.emulator is not None else self.signatures)

    def call(self, backend: str, name: str, *arguments) -> tuple[np.ndarray, ...]:
        """`name` at k rows of its arguments, in the order the catalogue declares them (a scalar
        argument may be one number for every row): its results, each (k, *shape), as the
        Python module returns them. CasADi's functions take only the arguments they name (its
        ik_numeric runs a fixed number of steps: no max_iter)."""
        if backend == "python" or backend in self.native:
            with np.errstate(divide="ignore", invalid="ignore"):  # NaN at Euler singularities
                found = getattr(self.module(backend), name)(*arguments, **self.nominal)
            return found if isinstance(found, tuple) else (found,)
        if self.emulator is not None:
            return self.emulator.results(name, *arguments)
        signature = self.signatures[name]
        count = next(len(value) for value in arguments if np.ndim(value))
        if not count:
            return tuple(np.zeros((0, *output.shape)) for output in signature.outputs)
        rows = [[value if argument.scalar and np.ndim(value) == 0 else value[k]
                 for argument, value in zip(signature.arguments, arguments, strict=True)] for k in range(count)]
        shapes = {output.name: output.shape for output in signature.outputs}
        if backend == "casadi":  # its results as it names them (its ik: every branch and its flags)
            function = getattr(self.casadi, name)
            position = {argument.name: k for k, argument in enumerate(signature.arguments)}
            found = [[value.full() for value in function.call([_column(np.asarray(row[position[taken]], dtype=float))
                                                               for taken in function.name_in() if taken in position]
                                                              + self.casadi_parameters)] for row in rows]
            names = function.name_out()
        else:
            library = self.c[backend.split()[1]]
            found = [library.call(name, *row) for row in rows]
            names = list(shapes)
        return tuple(np.array(values).reshape(count, *shapes[taken]) if taken in shapes else np.array(values)
                     for values, taken in zip(zip(*found), names))

    def evaluate(self, backend: str, name: str, q: np.ndarray, *more: np.ndarray) -> np.ndarray:
        """(k, size) results at the rows of q (and of q_dot, for the functions that take it),
        each output row-major, several outputs side by side, at the nominal parameter values."""
        return np.hstack([np.reshape(part, (len(q), -1)) for part in self.call(backend, name, q, *more)])

    def ik(self, backend: str, targets: np.ndarray, free: np.ndarray | None) -> tuple[list[np.ndarray], np.ndarray | None]:
        """ik at each target (with the free joint's angle, if any): the solutions (k_i, dof) per
        target, and the target's own check of them (None on the host). Its result is the one
        whose layout differs by language: kept rows and a mask (Python), a count (C), every
        branch with its flags (CasADi)."""
        given = (targets,) if free is None else (targets, free)
        if backend == "casadi":  # every branch, its validity and its limits: keep the solutions
            q, valid, in_limits = self.call(backend, "ik", *given)
            return [rows[mask.ravel() == 1] for rows, mask in zip(q, valid * in_limits)], None
        if backend == "python" or backend in self.native:  # one batched call
            q, keep = self.call(backend, "ik", *given)
            return [rows[mask] for rows, mask in zip(q, keep)], None
        q, count = self.call(backend, "ik", *given)
        checked = self.emulator.measured["ik"].ik_error if self.emulator is not None else None
        return [rows[:int(n)] for rows, n in zip(q, count)], checked

class NativeCalls:
    """NAME_native's functions called as a native backend says: float32 arrays (the float C) or
    float64, the SIMD kernels or the C function row by row (simd=False), or one call per row."""

    def __init__(self, module, backend: str):
        self.module = module
        self.dtype = np.float32 if "float" in backend else np.float64
        self.keywords = {"simd": False} if backend.endswith("scalar") else {}
        self.one = backend.endswith("one")

    def __getattr__(self, name: str):
        function = getattr(self.module, name)

        def call(*arguments, **keywords):
            arguments = [np.asarray(value, dtype=self.dtype) if isinstance(value, np.ndarray) and value.dtype.kind == "f"
                         else value for value in arguments]
            if not self.one:
                return function(*arguments, **keywords, **self.keywords)
            rows = len(arguments[0])  # the arrays of that length are per row, the rest shared
            results = [function(*(a[k] if isinstance(a, np.ndarray) and a.ndim and len(a) == rows else a
                                  for a in arguments), **keywords) for k in range(rows)]
            if name == "ik":  # one target gives the kept rows: back to every branch and a mask
                q = np.zeros((rows, self.module.MAX_IK_SOLUTIONS, self.module.DOF))
                keep = np.zeros((rows, self.module.MAX_IK_SOLUTIONS), dtype=bool)
                for k, found in enumerate(results):
                    q[k, :len(found)], keep[k, :len(found)] = found, True
                return q, keep
            if isinstance(results[0], tuple):
                return tuple(np.stack(parts) for parts in zip(*results))
            return np.stack(results)

        return call


def _column(value: np.ndarray) -> np.ndarray:
    """A value as CasADi takes it: a vector as a column, a matrix or a number as it is."""
    return value[:, None] if value.ndim == 1 else value

