"""One robot's generated code, loaded and called on batches, backend by backend: the numpy
module, the CasADi module, the C built for the host (double and float, through ctypes) or
for an emulated target (`target.Emulator`). `jacgen verify` compares what it returns with
the reference; the tests call the same functions through it."""

import importlib.util
from pathlib import Path

import numpy as np

from jacgen.checking.c_library import CLibrary
from jacgen.checking.cortex_m4f import Emulator
from jacgen.emission.catalogue import Function
from jacgen.inputs.robot import Robot
from jacgen.tolerances import IK_NUMERIC_VERIFIED

HOST_BACKENDS = ("python", "casadi", "c double", "c float")  # what `jacgen verify` compares on the host
# NAME_native as `verify --native` calls it: batches of float64 (the double C) and float32 (the
# float C) through the SIMD kernels and through the C function row by row, and one call per row.
NATIVE_BACKENDS = ("native double", "native double scalar", "native double one", "native float",
                   "native float scalar")
TARGET_BACKENDS = {"cortex-m4f": "cortex-m4f float"}  # `verify --target`: the target's float C alone
# ik_numeric as verify runs it: up to this many steps, to this |error| by real type.
IK_NUMERIC_STEPS = 200


def import_module(path: Path, module_name: str):
    spec = importlib.util.spec_from_file_location(module_name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class GeneratedCode:
    """The generated code of one robot, each backend evaluating a function on a batch of q:
    the host's (Python, CasADi, C double and float) or the emulated target's float C."""

    def __init__(self, robot: Robot, functions: list[Function], folder: Path, libraries: dict[str, Path],
                 emulator: Emulator | None = None, native=None):
        """folder: where `generate -o` wrote the double-precision Python and CasADi (folder/NAME/);
        libraries: the compiled C by real type; emulator: the target instead of the host;
        native: the built NAME_native module, to compare as well."""
        self.robot, self.emulator = robot, emulator
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
        self.c = {real: CLibrary(path, robot, functions, real) for real, path in libraries.items()}

    def module(self, backend: str):
        """What answers NAME.py's calls for a backend: the numpy module, or NAME_native called one
        of its ways."""
        return self.python if backend == "python" else self.native[backend]

    def evaluate(self, backend: str, name: str, q: np.ndarray, *more: np.ndarray) -> np.ndarray:
        """(k, size) results at the rows of q (and of q_dot, for the functions that take it),
        each output row-major, several outputs side by side, at the nominal parameter values."""
        if backend == "python" or backend in self.native:
            with np.errstate(divide="ignore", invalid="ignore"):  # NaN at Euler singularities
                return _side_by_side(getattr(self.module(backend), name)(q, *more, **self.nominal), len(q))
        if backend == "casadi":
            function = getattr(self.casadi, name)
            return np.vstack([_side_by_side(function(*rows, *self.casadi_parameters), 1) for rows in zip(q, *more)])
        if self.emulator is not None:
            return self.emulator.evaluate(name, q, *more)
        return self.c[backend.split()[1]].evaluate(name, q, *more)

    def velocity_ik(self, backend: str, q: np.ndarray, mu_dot: np.ndarray,
                    damping: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """velocity_ik at each row of q and mu_dot: (q_dot (k, dof), status (k,))."""
        if not len(q):  # no regular configuration: the numpy module says what nothing looks like
            return self.python.velocity_ik(q, mu_dot, damping, **self.nominal)
        if backend == "python" or backend in self.native:
            return self.module(backend).velocity_ik(q, mu_dot, damping, **self.nominal)
        if backend == "casadi":
            rows = [self.casadi.velocity_ik(x, rates, damping, *self.casadi_parameters) for x, rates in zip(q, mu_dot)]
            return (np.array([q_dot.full().ravel() for q_dot, _ in rows]).reshape(len(q), -1),
                    np.array([float(status) for _, status in rows]))
        if self.emulator is not None:
            return self.emulator.velocity_ik(q, mu_dot, damping)
        rows = [self.c[backend.split()[1]].velocity_ik(x, rates, damping) for x, rates in zip(q, mu_dot)]
        return np.array([q_dot for q_dot, _ in rows]).reshape(len(q), -1), np.array([status for _, status in rows])

    def ik(self, backend: str, targets: np.ndarray, free: np.ndarray | None,
           max_solutions: int) -> tuple[list[np.ndarray], np.ndarray | None]:
        """ik at each target (with the free joint's angle, if any): the solutions (k_i, dof) per
        target, and the target's own check of them (None on the host)."""
        if self.emulator is not None:
            return self.emulator.ik(targets, free)
        if backend == "python" or backend in self.native:  # one batched call
            q, keep = self.module(backend).ik(targets, *(() if free is None else (free,)), **self.nominal)
            return [rows[mask] for rows, mask in zip(q, keep)], None

        def solve(target: np.ndarray, *angle: float) -> np.ndarray:
            if backend == "casadi":  # every branch, its validity and its limits: keep the solutions
                q, valid, in_limits = self.casadi.ik(_column(target), *angle, *self.casadi_parameters)
                return q.full()[(valid.full() * in_limits.full()).ravel() == 1]
            return self.c[backend.split()[1]].ik(target, max_solutions, None, *angle)

        return [np.reshape(solve(target, *angle), (-1, self.robot.dof)) for target, angle in _with_free(targets, free)], None

    def ik_branches(self, backend: str, targets: np.ndarray, free: np.ndarray | None,
                    max_solutions: int) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """ik_branches at each target: every branch (k, m, dof) and whether each is valid and
        inside the limits (k, m); None where the backend has no ik_branches (general 6R: only C
        and Python, as loops around the eigensolver)."""
        if self.emulator is not None:
            return self.emulator.ik_branches(targets, free) if "ik_branches" in self.emulator.calls else None
        if backend == "python" or backend in self.native:
            found = self.module(backend).ik_branches(targets, *(() if free is None else (free,)), **self.nominal)
        elif backend == "casadi":
            if not hasattr(self.casadi, "ik_branches"):
                return None
            rows = [[value.full() for value in self.casadi.ik_branches(_column(target), *angle, *self.casadi_parameters)]
                    for target, angle in _with_free(targets, free)]
            found = [np.array(values) for values in zip(*rows)]
        else:
            library = self.c[backend.split()[1]]
            found = [np.array(values) for values in zip(*(library.ik_branches(target, max_solutions, *angle)
                                                           for target, angle in _with_free(targets, free)))]
        q, valid, in_limits = (np.asarray(value) for value in found)
        count = len(targets)
        return (q.reshape(count, -1, self.robot.dof), valid.reshape(count, -1).astype(bool),
                in_limits.reshape(count, -1).astype(bool))

    def ik_nearest(self, backend: str, targets: np.ndarray, seeds: np.ndarray, weights: np.ndarray,
                   free: np.ndarray | None) -> tuple[np.ndarray, np.ndarray] | None:
        """ik_nearest at each target from each seed: (q (k, dof), status (k,)); None where the
        backend has none."""
        if self.emulator is not None:
            return self.emulator.ik_nearest(targets, seeds, weights, free) if "ik_nearest" in self.emulator.calls else None
        if backend == "python" or backend in self.native:
            return self.module(backend).ik_nearest(targets, seeds, *(() if free is None else (free,)), weights,
                                                   **self.nominal)
        if backend == "casadi":
            if not hasattr(self.casadi, "ik_nearest"):
                return None
            rows = [self.casadi.ik_nearest(_column(target), seed, *angle, weight, *self.casadi_parameters)
                    for (target, angle), seed, weight in zip(_with_free(targets, free), seeds, weights)]
            return np.array([q.full().ravel() for q, _ in rows]), np.array([float(status) for _, status in rows])
        library = self.c[backend.split()[1]]
        rows = [library.ik_nearest(target, seed, weight, *angle)
                for (target, angle), seed, weight in zip(_with_free(targets, free), seeds, weights)]
        return np.array([q for q, _ in rows]), np.array([status for _, status in rows])

    def ik_numeric(self, backend: str, targets: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """ik_numeric from each start: (q (k, dof), status (k,))."""
        if self.emulator is not None:
            return self.emulator.ik_numeric(targets, starts, IK_NUMERIC_STEPS, IK_NUMERIC_VERIFIED["float"])
        if backend == "python" or backend in self.native:  # one batched call
            real = "float" if "float" in backend else "double"
            return self.module(backend).ik_numeric(targets, starts, IK_NUMERIC_STEPS, IK_NUMERIC_VERIFIED[real],
                                                   **self.nominal)

        def solve(target: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, int]:
            if backend == "casadi":  # a fixed number of steps
                q, status = self.casadi.ik_numeric(_column(target), start, IK_NUMERIC_VERIFIED["double"],
                                                   *self.casadi_parameters)
                return q.full().ravel(), int(status)
            real = backend.split()[1]
            return self.c[real].ik_numeric(target, start, IK_NUMERIC_STEPS, IK_NUMERIC_VERIFIED[real])

        found, status = zip(*(solve(target, start) for target, start in zip(targets, starts)))
        return np.array(found), np.array(status)


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


def _side_by_side(results, count: int) -> np.ndarray:
    """One result array, or a tuple of them (a fused function), as (count, size)."""
    parts = results if isinstance(results, tuple) else (results,)
    return np.hstack([np.reshape(np.asarray(part), (count, -1)) for part in parts])


def _column(target: np.ndarray) -> np.ndarray:
    """A target as CasADi takes it: a 4x4 pose as it is, a task vector as a column."""
    return target if target.ndim == 2 else target[:, None]


def _with_free(targets: np.ndarray, free: np.ndarray | None) -> list[tuple[np.ndarray, tuple]]:
    """Each target with the free joint's angle as a trailing argument (none without a free joint)."""
    return [(target, () if free is None else (free[k],)) for k, target in enumerate(targets)]
