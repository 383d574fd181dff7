"""Benchmark: jacgen from Python in one table: NAME_native, NAME.py (numpy, jax.jit) and the peers.

    python bench/bench_python.py [--robots ur5,panda,jaco] [--sizes 1000,1000000] [--rounds 5]
                                 [--batch-rounds 3]

At the start, `generate --lang native` is rendered for each robot into a temporary folder and
built with `jacgen.building.load_native` (the build time and `NAME_native.SIMD` are printed).
Then, for `fk`, `fk_jacobian`, `ik` and `velocity_ik` of each robot, one row per batch size
(1: one call; then each of `--sizes`) and one column per implementation:

- "NAME_native": the extension module; one call goes straight to the C function, a batch
  through its gufunc (SIMD kernels, over every usable processor: the default `threads=`);
- "NAME.py numpy": the committed generated/NAME/NAME.py on numpy arrays;
- "NAME.py jax.jit": the same module under `jax.jit` (float64: jax_enable_x64), compiled by
  the untimed warm-up call, results waited for (`jax.block_until_ready`). One target of `ik`
  runs `ik_branches` (every branch, fixed size: `ik`'s (k, DOF) has a data-dependent shape);
  the general 6R ik (jaco) is numpy-only (numpy's eigensolver): "-";
- "Pinocchio" (`pin`, from Python, on `common.pinocchio_from_dh`'s model of the DH table):
  fk is forwardKinematics + updateFramePlacement + `oMf[tool].homogeneous`, fk_jacobian is
  computeFrameJacobian(LOCAL_WORLD_ALIGNED) (it places the frame too) + that pose;
- "rtb ETS" (Robotics Toolbox for Python): `fkine(q).A` and `jacob0(q)` of the ETS of
  `rtb.models.DH.NAME()` (the model the robot file was transcribed from);
- "EAIK": ur5 `ik`, every solution (`DhRobot(alpha, a, d).IK(T)`, and `IK_batched(T,
  threads)` for a batch); its least-squares candidates are not solutions;
- "NAME_casadi.py": the committed generated CasADi Function called with numpy arrays, one
  call (it returns casadi.DM; `ik` is `ik_branches`, every branch); jaco has no CasADi ik.

Before any timing, each implementation is checked once, on one call and on a batch of the
smallest size (CHECKS): fk and fk_jacobian against jacgen.reference (1e-9); velocity_ik's
q_dot against pinv(J) mu_dot, J from jacgen.reference (1e-9, relative to the largest joint
rate above 1); ik's solutions against NAME_native's (each within 1e-6 rad of one of the
other, modulo 2 pi) on at least 99% of the targets, any difference noted (a general 6R root
at the edge of the solver's tolerance), NAME_native's own solutions having been checked to
reach their targets (1e-8, jacgen.reference fk) and to include the generating configuration
(99% of the targets: common.ik_quality). A peer that disagrees is not timed ("wrong" and a
note), and the run stops if NAME_native does; a library not installed gives "-" and a note.

Inputs: configurations uniform within the joint limits (+-pi where wider or none), targets
their reference fk (panda: with the angle of joint 7 as ik's q_free, a Python float), mu_dot
normal, damping 0. Each call of a single-call row takes another input. Times follow common.py's
policy: a warm-up, then the median of the rounds (`--rounds` for one call, enough calls per
round to last ROUND_SECONDS; `--batch-rounds` for batches), rounds interleaving the
implementations of a row. One call: microseconds per call; a batch: seconds per batch.
"~" marks a scaled figure, with the rows actually timed in brackets: a batch whose run would
last more than BATCH_SECONDS (estimated from a call on PROBE_ROWS rows) is timed on the
largest slice of size / 10^k rows that would not, and scaled linearly; Pinocchio and rtb
have no batched call, and their batch is a Python loop timed over LOOP_CALLS calls and
scaled. "numpy / native" and "best peer / native" are ratios of times (best peer: the fastest
of Pinocchio, rtb, EAIK and CasADi in the row). The batched ur5 ik of NAME_native is also
given in poses per second. The load average is printed at the start and the end: NAME_native
splits a batch over every usable processor, and a busy one delays the whole batch.
"""

import argparse
import os
import tempfile
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Callable

import numpy as np

import common
from jacgen.checking import reference
from jacgen.building import load_native

FUNCTIONS = ("fk", "fk_jacobian", "ik", "velocity_ik")
PEERS = ("pinocchio", "rtb", "eaik", "casadi")
COLUMNS = ("native", "numpy", "jax", *PEERS)
HEADERS = {"native": "NAME_native", "numpy": "NAME.py numpy", "jax": "NAME.py jax.jit", "pinocchio": "Pinocchio",
           "rtb": "rtb ETS", "eaik": "EAIK", "casadi": "NAME_casadi.py"}
RTB_MODELS = {"ur5": "UR5", "panda": "Panda", "jaco": "Jaco"}
ROUND_SECONDS = 0.02  # a round of single calls lasts about this long
MAX_CALLS = 20_000  # single calls per round, at most
BATCH_SECONDS = 3.0  # a batch run longer than this is timed on a slice and scaled
LOOP_CALLS = 1_000  # a Python loop standing for a batch is timed over this many calls
PROBE_ROWS = 1_000  # rows of the call that estimates a batch's time
USABLE_PROCESSORS = len(os.sched_getaffinity(0))


# -- inputs ----------------------------------------------------------------------------------------
def configurations(robot, count: int, seed: int) -> np.ndarray:
    """`count` joint vectors uniform within the joint limits, clipped to +-pi."""
    limits = np.array([joint.limits if joint.limits is not None else (-np.pi, np.pi) for joint in robot.joints])
    low, high = np.maximum(limits[:, 0], -np.pi), np.minimum(limits[:, 1], np.pi)
    return np.random.default_rng(seed).uniform(low, high, (count, robot.dof))


def inputs(robot, function: str, count: int) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """The generating configurations q and the arguments of `function` for `count` calls, as
    batches: (q,), (q, mu_dot), (T,) or, with a free joint, (T, q_free)."""
    q = configurations(robot, count, seed=FUNCTIONS.index(function))
    if function == "velocity_ik":
        return q, (q, np.random.default_rng(7).normal(size=(count, 6)))
    if function == "ik":
        targets = reference.fk(robot, q)
        return q, (targets, q[:, robot.free_joint]) if robot.free_joint is not None else (targets,)
    return q, (q,)


def one_call(arrays: tuple, row: int) -> tuple:
    """The arguments of one call: row `row` of each batch (a number as a Python float)."""
    return tuple(float(array[row]) if array.ndim == 1 else array[row] for array in arrays)


# -- the implementations ---------------------------------------------------------------------------
def _same(value):
    return value


@dataclass(frozen=True)
class Implementation:
    """One implementation of a function. `single(*arguments)` computes one input; `read(result,
    batched)` gives the function's canonical form of a result (checks only); `batch(*arrays)`
    computes a batch (None: no batched call; `loop`: a batch is a Python loop of single
    calls); `prepare` turns arguments (one call's or a batch's) into its inputs, before timing."""
    single: Callable
    read: Callable
    batch: Callable | None = None
    prepare: Callable = _same
    loop: bool = False


def jacgen_read(function: str) -> Callable:
    """The canonical form of a result of NAME.py's API, always batched: fk T (m, 4, 4);
    fk_jacobian (T, J); velocity_ik q_dot (m, n); ik a list of (k, n) solutions per target."""
    def read(result, batched: bool):
        if function == "ik":
            return [np.asarray(q)[np.asarray(keep)] for q, keep in zip(*result)] if batched else [np.asarray(result)]
        if function == "velocity_ik":
            result = result[0]
        if function == "fk_jacobian":
            return tuple(np.asarray(r) if batched else np.asarray(r)[None] for r in result)
        return np.asarray(result) if batched else np.asarray(result)[None]
    return read


def branches_read(result, batched: bool) -> list:
    """The solutions among every branch (q, valid, in_limits) of one target, as a list of one."""
    q, valid, in_limits = (np.asarray(r) for r in result)
    return [q[(valid.astype(bool) & in_limits.astype(bool)).ravel()]]


def jacgen_module(module, function: str) -> Implementation:
    """NAME_native or NAME.py on numpy: the same call for one input and a batch."""
    return Implementation(getattr(module, function), jacgen_read(function), getattr(module, function))


def jax_module(jax, robot, module, function: str, notes: list) -> Implementation | None:
    """NAME.py under jax.jit, its results waited for; one target of ik through ik_branches."""
    if function == "ik" and hasattr(module, "ik_general_equations"):
        notes.append(f"jax.jit: {robot.name}'s ik (the general 6R solver) is numpy-only (numpy's eigensolver): '-'")
        return None
    jacgen = jacgen_read(function)

    def blocking(jitted):
        return lambda *arguments: jax.block_until_ready(jitted(*arguments))

    def read(result, batched):
        return branches_read(result, batched) if function == "ik" and not batched else jacgen(result, batched)

    single = jax.jit(module.ik_branches if function == "ik" else getattr(module, function))
    batch = jax.jit(getattr(module, function))
    return Implementation(blocking(single), read, blocking(batch), partial(as_arrays, jax.numpy.asarray))


def as_arrays(convert: Callable, arguments: tuple) -> tuple:
    """Each argument converted by `convert` (to the arrays of another library)."""
    return tuple(convert(argument) for argument in arguments)


def pinocchio_peer(pin, robot, function: str) -> Implementation | None:
    """Pinocchio from Python on the DH table's model: fk and fk_jacobian of the tool frame."""
    model = common.pinocchio_from_dh(robot)
    data, frame = model.createData(), model.getFrameId("tool")

    def fk(q):
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacement(model, data, frame)
        return data.oMf[frame].homogeneous

    def fk_jacobian(q):
        J = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        return data.oMf[frame].homogeneous, J

    calls = {"fk": fk, "fk_jacobian": fk_jacobian}
    return Implementation(calls[function], jacgen_read(function), loop=True) if function in calls else None


def rtb_peer(rtb, robot, function: str) -> Implementation | None:
    """The Robotics Toolbox's ETS of its DH model: fkine and jacob0."""
    ets = getattr(rtb.models.DH, RTB_MODELS[robot.name])().ets()
    calls = {"fk": lambda q: ets.fkine(q).A, "fk_jacobian": lambda q: (ets.fkine(q).A, ets.jacob0(q))}
    return Implementation(calls[function], jacgen_read(function), loop=True) if function in calls else None


def eaik_peer(eaik_dh, robot, function: str) -> Implementation | None:
    """EAIK's ik of the DH table (ur5): every solution, one target or a batch on the threads."""
    if function != "ik" or robot.name != "ur5":
        return None
    alpha, a, d = (np.array([getattr(joint, key).approx for joint in robot.joints]) for key in ("alpha", "a", "d"))
    solver = eaik_dh.DhRobot(alpha, a, d)

    def solutions(solution):
        return np.asarray(solution.Q)[~np.asarray(solution.is_LS, dtype=bool)]

    def read(result, batched):
        return [solutions(s) for s in result] if batched else [solutions(result)]
    return Implementation(solver.IK, read, lambda T: solver.IK_batched(T, USABLE_PROCESSORS))


def casadi_peer(module, function: str) -> Implementation | None:
    """The generated CasADi Function, one call with numpy arrays (velocity_ik with damping 0)."""
    if not hasattr(module, function):
        return None
    call = getattr(module, function)
    if function == "velocity_ik":
        return Implementation(lambda q, mu_dot: call(q, mu_dot, 0.0), lambda result, batched: np.asarray(result[0]).T)
    return Implementation(call, branches_read if function == "ik" else jacgen_read(function))


def implementations(robot, function: str, native, libraries: dict, notes: list) -> dict[str, Implementation]:
    """{column: Implementation} of `function` on `robot`, for the columns that have one."""
    generated = common.ROOT / "generated" / robot.name
    numpy_module = common.load_module(generated / f"{robot.name}.py")
    made = {"native": jacgen_module(native, function), "numpy": jacgen_module(numpy_module, function)}
    if libraries["jax"]:
        made["jax"] = jax_module(libraries["jax"], robot, numpy_module, function, notes)
    if libraries["pinocchio"]:
        made["pinocchio"] = pinocchio_peer(libraries["pinocchio"], robot, function)
    if libraries["roboticstoolbox"]:
        made["rtb"] = rtb_peer(libraries["roboticstoolbox"], robot, function)
    if libraries["eaik.IK_DH"]:
        made["eaik"] = eaik_peer(libraries["eaik.IK_DH"], robot, function)
    made["casadi"] = casadi_peer(common.load_module(generated / f"{robot.name}_casadi.py"), function)
    return {column: implementation for column, implementation in made.items() if implementation is not None}


# -- checks ----------------------------------------------------------------------------------------
def same_solutions(found: np.ndarray, expected: np.ndarray) -> bool:
    """Whether two solution sets (k, n) of one target are equal: every solution of each within
    1e-6 rad (modulo 2 pi) of one of the other."""
    if len(found) != len(expected):
        return False
    distance = np.abs(common.wrapped(found[:, None, :] - expected[None, :, :])).max(axis=-1, initial=0.0)
    return len(found) == 0 or max(distance.min(axis=1).max(), distance.min(axis=0).max()) < 1e-6


def expected_values(robot, function: str, arrays: tuple, native_solutions: list | None):
    """What `function` must give on the batch `arrays`: from jacgen.reference, ik from NAME_native."""
    if function == "ik":
        return native_solutions
    if function == "velocity_ik":
        q, mu_dot = arrays
        return np.einsum("...ij,...j->...i", np.linalg.pinv(reference.jacobian(robot, q)), mu_dot)
    T = reference.fk(robot, arrays[0])
    return T if function == "fk" else (T, reference.jacobian(robot, arrays[0]))


# Each function's measure of a result against the expected one, and its tolerance.
CHECKS = {"fk": ("largest entry difference", 1e-9), "fk_jacobian": ("largest entry difference", 1e-9),
          "velocity_ik": ("largest difference over max(1, largest joint rate)", 1e-9),
          "ik": ("share of the targets whose solutions differ", 0.01)}


def error(function: str, found, expected) -> float:
    """CHECKS' measure of a canonical result against the expected one."""
    if function == "ik":
        return float(np.mean([not same_solutions(mine, theirs) for mine, theirs in zip(found, expected)]))
    if function == "velocity_ik":
        return float(np.abs(found - expected).max() / max(1.0, np.abs(expected).max()))
    if function == "fk_jacobian":
        return max(float(np.abs(a - b).max()) for a, b in zip(found, expected))
    return float(np.abs(found - expected).max())


def check_native_ik(robot, q: np.ndarray, arrays: tuple, solutions: list) -> str | None:
    """Why NAME_native's ik solutions are not right (None when they are): each reaches its target,
    and the generating configuration is among them."""
    _, recovered, off = common.ik_quality(robot, q, arrays[0], solutions)
    if off > 0 or recovered < 0.99:
        return f"{off:.1%} of its solutions miss their target, generating configuration found for {recovered:.1%}"
    return None


def checked(robot, function: str, made: dict, q: np.ndarray, arrays: tuple, rows: int, notes: list) -> dict:
    """The implementations whose one call (on row 0) and batch (rows 0..rows-1) agree with the
    expected values (CHECKS); the others are noted and dropped, and the run stops if
    NAME_native is among them."""
    measure, tolerance = CHECKS[function]
    given = {False: tuple(array[:1] for array in arrays), True: tuple(array[:rows] for array in arrays)}
    arguments = {False: one_call(arrays, 0), True: given[True]}
    native = made["native"]
    native_solutions = {batched: native.read(native.single(*arguments[batched]), batched)
                        for batched in (False, True)} if function == "ik" else {}
    for batched, solutions in native_solutions.items():
        problem = check_native_ik(robot, q[:len(given[batched][0])], given[batched], solutions)
        if problem:
            raise SystemExit(f"{robot.name}_native ik ({'batch' if batched else 'one call'}): {problem}")
    passed = {}
    for column, implementation in made.items():
        worst = 0.0
        for batched, call in ((False, implementation.single), (True, implementation.batch)):
            if call is None:
                continue
            result = call(*implementation.prepare(arguments[batched]))
            expected = expected_values(robot, function, given[batched], native_solutions.get(batched))
            worst = max(worst, error(function, implementation.read(result, batched), expected))
        found = f"{robot.name} {function}: {HEADERS[column]}'s {measure}: {worst:.3g}"
        if worst > tolerance and column == "native":
            raise SystemExit(f"{found} > {tolerance:g}: NAME_native is what this bench measures")
        if worst > tolerance:
            notes.append(f"{found} > {tolerance:g}: not timed ('wrong')")
            continue
        if function == "ik" and worst > 0:
            notes.append(found)
        passed[column] = implementation
    return passed


# -- timing ----------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Cell:
    """One figure: seconds (per call, or per batch), and the rows timed when it is scaled."""
    seconds: float
    timed_rows: int | None = None


def seconds_of(run: Callable) -> float:
    """Seconds of one call of `run`, after one untimed call (a probe, not a measurement)."""
    run()
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def single_runs(made: dict, arrays: tuple) -> dict[str, tuple[Callable, int]]:
    """{column: (a run of single calls, each on another input, lasting about ROUND_SECONDS,
    and its number of calls)}."""
    runs = {}
    for column, implementation in made.items():
        first = implementation.prepare(one_call(arrays, 0))
        per_call = seconds_of(partial(implementation.single, *first))
        calls = int(min(MAX_CALLS, max(10, ROUND_SECONDS / max(per_call, 1e-9))))
        arguments = [implementation.prepare(one_call(arrays, row % len(arrays[0]))) for row in range(calls)]
        runs[column] = (common.each(implementation.single, arguments), calls)
    return runs


def time_single(made: dict, arrays: tuple, rounds: int) -> dict[str, Cell]:
    """{column: Cell of seconds per call}, each call on another input."""
    runs = single_runs(made, arrays)
    timings = common.median_times({column: run for column, (run, _) in runs.items()}, rounds)
    return {column: Cell(timing.seconds / runs[column][1]) for column, timing in timings.items()}


def batch_run(implementation: Implementation, arrays: tuple, size: int) -> tuple[Callable, int]:
    """A run of `implementation` standing for a batch of `size` rows, and the rows it computes:
    the batched call on the largest slice of size / 10^k rows whose run, estimated from a call
    on PROBE_ROWS rows, lasts at most BATCH_SECONDS; or a Python loop of LOOP_CALLS single calls."""
    if implementation.loop:
        calls = min(size, LOOP_CALLS)
        return common.each(implementation.single, [implementation.prepare(one_call(arrays, row))
                                                   for row in range(calls)]), calls
    probe_rows = min(size, PROBE_ROWS)
    probe = implementation.prepare(tuple(array[:probe_rows] for array in arrays))
    per_row = seconds_of(partial(implementation.batch, *probe)) / probe_rows
    rows = size
    while rows > probe_rows and per_row * rows > BATCH_SECONDS:
        rows //= 10
    sliced = implementation.prepare(tuple(array[:rows] for array in arrays))
    return partial(implementation.batch, *sliced), rows


def time_batch(made: dict, arrays: tuple, size: int, rounds: int) -> dict[str, Cell]:
    """{column: Cell of seconds per batch of `size` rows} of the implementations with a batch."""
    runs = {column: batch_run(implementation, arrays, size) for column, implementation in made.items()
            if implementation.batch is not None or implementation.loop}
    timings = common.median_times({column: run for column, (run, _) in runs.items()}, rounds)
    return {column: Cell(timing.seconds * size / runs[column][1], None if runs[column][1] == size else runs[column][1])
            for column, timing in timings.items()}


# -- the table -------------------------------------------------------------------------------------
def count_text(count: int) -> str:
    """A count of rows as the table writes it: 1, 1e3, 2e6."""
    return "1" if count == 1 else f"{count:.0e}".replace("+0", "").replace("+", "")


def significant(value: float) -> str:
    """Three significant digits, written out without an exponent."""
    return np.format_float_positional(value, precision=3, unique=False, fractional=False, trim="-")


def figure(cell: Cell | None, size: int) -> str:
    """A cell of the table: microseconds per call (size 1) or seconds per batch, '~' and the
    rows timed when scaled."""
    if cell is None:
        return "-"
    text = significant(cell.seconds * 1e6 if size == 1 else cell.seconds)
    return text if cell.timed_rows is None else f"~{text} [{count_text(cell.timed_rows)}]"


def ratio(cells: dict, column: str) -> str:
    if column not in cells or "native" not in cells:
        return "-"
    return significant(cells[column].seconds / cells["native"].seconds)


def best_peer(cells: dict) -> str:
    """The fastest peer's time over native's, and which peer."""
    peers = [column for column in PEERS if column in cells]
    if not peers or "native" not in cells:
        return "-"
    fastest = min(peers, key=lambda column: cells[column].seconds)
    return f"{ratio(cells, fastest)} ({HEADERS[fastest]})"


def table_row(robot: str, function: str, size: int, cells: dict, dropped: set) -> str:
    columns = ["wrong" if column in dropped else figure(cells.get(column), size) for column in COLUMNS]
    unit = "µs/call" if size == 1 else "s/batch"
    return (f"| {robot} | {function} | {count_text(size)} | {unit} | " + " | ".join(columns)
            + f" | {ratio(cells, 'numpy')} | {best_peer(cells)} |")


def print_table(rows: list[str]) -> None:
    header = ["robot", "function", "batch", "unit", *(HEADERS[column] for column in COLUMNS),
              "numpy / native", "best peer / native"]
    print("\n| " + " | ".join(header) + " |")
    print("|---|---|---:|---|" + "---:|" * (len(header) - 4))
    print("\n".join(rows))


# -- the run ---------------------------------------------------------------------------------------
def build_natives(robots, folder: Path) -> dict:
    """{name: NAME_native}, each rendered (`--lang native`) into `folder` and built there."""
    natives = {}
    for robot in robots:
        source = common.generate(robot, folder, ("native",))
        start = time.perf_counter()
        natives[robot.name] = load_native(source, robot.name)
        print(f"{robot.name}_native: built in {time.perf_counter() - start:.1f} s, SIMD {natives[robot.name].SIMD}")
    return natives


def bench_function(robot, function: str, native, libraries: dict, sizes: list[int], arguments,
                   notes: list) -> tuple[list[str], dict]:
    """The table rows of one function of one robot, and {size: Cell} of NAME_native's batches."""
    made = implementations(robot, function, native, libraries, notes)
    q, arrays = inputs(robot, function, max(*sizes, MAX_CALLS))
    passed = checked(robot, function, made, q, arrays, min(sizes), notes)
    dropped = set(made) - set(passed)
    rows = [table_row(robot.name, function, 1, time_single(passed, arrays, arguments.rounds), dropped)]
    natives = {}
    for size in sizes:
        cells = time_batch(passed, arrays, size, arguments.batch_rounds)
        natives[size] = cells.get("native")
        rows.append(table_row(robot.name, function, size, cells, dropped))
    return rows, natives


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", default="ur5,panda,jaco")
    parser.add_argument("--sizes", default="1000,1000000", help="batch sizes (rows)")
    parser.add_argument("--rounds", type=int, default=5, help="rounds of the single-call rows")
    parser.add_argument("--batch-rounds", type=int, default=3, help="rounds of the batch rows")
    arguments = parser.parse_args()
    start = time.perf_counter()
    sizes = sorted(int(size) for size in arguments.sizes.split(","))
    robots = [common.shipped(name) for name in arguments.robots.split(",")]
    notes = []
    libraries = {name: common.optional(name, notes.append) for name in ("jax", "pinocchio", "roboticstoolbox", "eaik.IK_DH")}
    if libraries["jax"]:
        libraries["jax"].config.update("jax_enable_x64", True)
    print(f"numpy {np.__version__}; {USABLE_PROCESSORS} usable processors (NAME_native's batches use them all); "
          f"load average {os.getloadavg()[0]:.2f}")
    rows, ur5_ik = [], {}
    with tempfile.TemporaryDirectory(prefix="jacgen-python-") as temporary:
        natives = build_natives(robots, Path(temporary))
        for robot in robots:
            for function in FUNCTIONS:
                made_rows, native_cells = bench_function(robot, function, natives[robot.name], libraries, sizes,
                                                         arguments, notes)
                rows += made_rows
                if (robot.name, function) == ("ur5", "ik"):
                    ur5_ik = native_cells
    print_table(rows)
    print(f"\nmedian of {arguments.rounds} rounds (one call) and {arguments.batch_rounds} rounds (batches), "
          "interleaved; '~x [rows]': timed on that many rows (or calls) and scaled linearly; '-': no such call")
    for size, cell in ur5_ik.items():
        print(f"ur5_native batched ik, {count_text(size)} poses: {significant(size / cell.seconds)} poses per second"
              + (f" (timed on {count_text(cell.timed_rows)})" if cell.timed_rows else ""))
    for note in dict.fromkeys(notes):
        print(f"note: {note}")
    print(f"run time {time.perf_counter() - start:.0f} s; load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
