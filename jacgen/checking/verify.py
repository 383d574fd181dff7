"""`jacgen verify` (contract §4): every function of every backend against the numpy reference.

For each robot the code is generated into a temporary folder, the C is compiled twice
(double and float) into shared libraries called through ctypes, and the Python and
CasADi modules are imported. Every generated function is evaluated at random
configurations inside the joint limits plus configurations near singularities, and
compared with the function of the same name in `jacgen.checking.reference` (functions the
reference does not have are listed as not compared).

The random joint vectors are rounded to float32 first, so that the float build, which can
only read float32 joint angles, is compared at exactly the configuration the reference
sees, and its error is the error of its arithmetic alone. `ik` and `ik_numeric` are
checked by round trip, `velocity_ik` by its backward error, and the functions of velocity and
dexterity whose results are not unique or not well conditioned (the velocity ellipsoid, the
condition number, ...) by what characterises them (`dexterity_checks`).

`--target cortex-m4f` checks the float C alone, run on an emulated Cortex-M4F
(`jacgen.checking.cortex_m4f`), with the same samples, comparisons and tolerances.
"""

import inspect
import math
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Callable

import numpy as np

from jacgen.checking import reference
from jacgen.checking.c_library import c_compiler, compile_shared
from jacgen.checking.cortex_m4f import Emulator, check_tools
from jacgen.checking.dexterity_checks import CHECKED_HERE, dexterity_results, velocity_ik_residual
from jacgen.checking.generated_code import HOST_BACKENDS, GeneratedCode
from jacgen.checking.result import Result, is_float
from jacgen.checking.samples import configurations
from jacgen.emission.catalogue import Function
from jacgen.emission.generator import Generator
from jacgen.emission.render import render_robot
from jacgen.files import write_files
from jacgen.inputs.robot import EULER_ANGLES, Robot
from jacgen.building import load_native
from jacgen.model import js_rank
from jacgen.parallel import for_each_robot
from jacgen.solvers import ik
from jacgen.tolerances import IK_NUMERIC_VERIFIED, VERIFIED

# Where cos(pitch) < this, roll and yaw and the Euler-angle rates are ill-conditioned (they
# are undefined at pitch = +-90 deg): the angle rows of the functions the catalogue declares
# with `euler_rows`, and the functions of Js (`of_js`) where Js is the task Jacobian, are not
# compared there (and may be NaN). Beyond 0.05 (|pitch| < 87 deg) rounding is amplified at
# most 1/0.05^2 = 400-fold and the reference's central differences (step 1e-4) agree with
# the exact rates to 3e-11; at 0.01 they were measured 4e-9 off (stanford).
EULER_MARGIN = 0.05
# Smallest singular value of Js, over the largest or over what its entries can be (`_rank_ratios`),
# below which factors must vanish, and above which velocity_ik is checked (there |q_dot| <~ 1e3
# |mu_dot|, so the reference's finite-difference error of 1e-11 in task_jacobian stays below the
# tolerance in the residual).
SINGULAR_RANK, REGULAR_RANK = 1e-9, 1e-3
# ik_numeric iterates in Python per target: enough targets to cover the workspace, few
# enough to keep verify quick.
NUMERIC_IK_SAMPLES = 20
# ik_numeric as verify runs it: up to this many steps, to IK_NUMERIC_VERIFIED by real type.
IK_NUMERIC_STEPS = 200
# ik_numeric_step as verify compares it: enough damping that J J^T + damping I is conditioned
# well at any sample (below 50 for the shipped arms), so that the float build's step is within
# its tolerance of the reference's.
STEP_DAMPING = 0.1


def _reference(robot: Robot, function: Function, q: np.ndarray, *more: np.ndarray) -> np.ndarray | None:
    """The reference's values of each output side by side, None where it has no counterpart.
    Each reference function takes the arguments it needs: q, or q and q_dot."""
    evaluators = [getattr(reference, output.result_of or function.name, None) for output in function.outputs]
    if not all(callable(evaluate) for evaluate in evaluators):
        return None
    needs = [sum(p.default is inspect.Parameter.empty for p in inspect.signature(e).parameters.values()) - 1
             for e in evaluators]
    return np.concatenate([np.reshape(evaluate(robot, *(q, *more)[:count]), (len(q), -1))
                           for evaluate, count in zip(evaluators, needs)], axis=1)


def compare(robot: Robot, function: Function, value: np.ndarray, expected: np.ndarray,
            q: np.ndarray) -> tuple[float, int]:
    """Largest error of results (k, rows * cols) against the reference at q (k, dof), and the
    number of samples whose Euler-angle rows were not compared.

    Angles of the task vector are compared modulo 2 pi; a NaN or infinity that is compared
    is an infinite error. Each error is divided by 1 + |expected|: float and double round
    relative to the value (manipulability grows as the reach cubed), and the Euler-rate rows
    of task_jacobian_dot reach |q_dot|^2 / cos(pitch)^2 near the margin.
    """
    elements = np.zeros(value.shape[1], dtype=bool)  # the entries undefined where cos(pitch) = 0
    if function.declaration.euler_rows:
        elements = np.repeat([name in EULER_ANGLES for name in robot.task], function.outputs[0].cols)
    elif function.declaration.of_js and js_rank.singularity_rows(robot) is None:
        elements[:] = True
    compared = np.ones(value.shape, dtype=bool)
    if elements.any():
        rotations = reference.fk(robot, q)[:, :3, :3]
        euler_singular = np.hypot(rotations[:, 0, 0], rotations[:, 1, 0]) < EULER_MARGIN
        compared[np.ix_(euler_singular, elements)] = False
    difference = value - expected
    if function.name == "task":
        difference[:, elements] = _wrapped(difference[:, elements])
    skipped = int((~compared.all(axis=1)).sum())
    if not np.isfinite(value[compared]).all():
        return math.inf, skipped
    relative = difference / (1 + np.abs(expected))
    return float(np.max(np.abs(relative[compared]), initial=0.0)), skipped


def verify_robot(robot: Robot, backends: GeneratedCode, functions: list[Function], q: np.ndarray,
                 random_count: int, form: ik.ClosedForm | None) -> list[Result]:
    """Every function at q, whose first `random_count` rows are random (not singular) samples."""
    names = backends.names
    tolerances = {backend: VERIFIED["float" if is_float(backend) else "double"] * (1 + robot.reach)
                  for backend in names}
    # Js's determinant and manipulability are products of one entry per position row, each up to the reach
    positions = sum(component in ("x", "y", "z") for component in robot.task)
    product_tolerances = {backend: tolerance * (1 + robot.reach) ** max(positions - 1, 0)
                          for backend, tolerance in tolerances.items()}
    results = []
    ranks = _rank_ratios(robot, q)
    q_dot = np.random.default_rng(1).normal(size=q.shape)  # joint rates, for the second-order functions
    compared = [f for f in functions if [a.name for a in f.arguments] in (["q"], ["q", "q_dot"])  # the IK: below
                and f.name not in CHECKED_HERE]
    for function in compared:
        more = (q_dot,) if len(function.arguments) == 2 else ()
        if function.name == "singularity_factors":
            errors = {backend: _vanishing_error(backends.evaluate(backend, function.name, q), ranks)
                      for backend in names}
            results.append(Result(robot.name, function.name, errors, tolerances,
                                  f"min |factor| at the {int((ranks < SINGULAR_RANK).sum())} samples where Js is singular"))
            continue
        expected = _reference(robot, function, q, *more)
        if expected is None or expected.shape[1] != sum(output.size for output in function.outputs):
            note = "not compared: " + ("no reference" if expected is None else "reference has another shape")
            results.append(Result(robot.name, function.name, dict.fromkeys(names), tolerances, note, compared=False))
            continue
        errors = {}
        for backend in names:
            errors[backend], skipped = compare(robot, function, backends.evaluate(backend, function.name, q, *more),
                                               expected, q)
        note = (f"angle rows not compared at {skipped} of {len(q)} samples (cos(pitch) < {EULER_MARGIN})"
                if skipped else "")
        results.append(Result(robot.name, function.name, errors,
                              product_tolerances if function.declaration.of_js else tolerances, note))
    regular = ranks > REGULAR_RANK
    results += _ik_results(robot, backends, q[:random_count], tolerances, form)
    results.append(_ik_numeric_step_result(robot, backends, q[:random_count], tolerances))
    mu_dot = np.random.default_rng(0).normal(size=(int(regular.sum()), len(robot.task)))
    residuals, flagged = {}, {}
    for backend in names:
        residuals[backend], flagged[backend] = velocity_ik_residual(
            robot, backends.call(backend, "velocity_ik", q[regular], mu_dot, 0.0), q[regular], mu_dot,
            allow_singular=is_float(backend))
    results.append(Result(robot.name, "velocity_ik", residuals, tolerances,
                          ("|Js^T (Js q_dot - mu_dot)| / |Js| (|Js| |q_dot| + |mu_dot|)" if len(robot.task) > robot.dof
                           else "|Js q_dot - mu_dot| / (|Js| |q_dot| + |mu_dot|)")
                          + f" at the {int(regular.sum())} samples where Js is regular"
                          + "".join(f"; {backend}: {flagged[backend]} reported singular (float's threshold)"
                                    for backend in names if is_float(backend) and flagged[backend])))
    results += dexterity_results(robot, backends, q, ~np.isnan(ranks), regular, tolerances, product_tolerances)
    checked = {result.function for result in results}
    return results + [Result(robot.name, f.name, dict.fromkeys(names), tolerances,
                             "not compared: verify has no check of it (add one to verify.py or dexterity_checks.py)",
                             compared=False)
                      for f in functions if f.name not in checked and not f.part_of]  # a part: its whole is checked


def _wrapped(angles: np.ndarray) -> np.ndarray:
    """Differences of angles in [-pi, pi)."""
    return (angles + math.pi) % (2 * math.pi) - math.pi


def _rank_ratios(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Smallest singular value of the reference Js at each sample over its largest, or over 1
    where the largest is less (NaN where Js is undefined: Euler-angle rows at cos(pitch) <
    EULER_MARGIN), made free of the length unit: position rows divided by the reach, prismatic
    columns multiplied by it, so that no entry can exceed about 1. A Js that is small as a whole
    is near singular so: a one-row Js near where the joints cannot move its task (3e-5 there
    left the float C a relative error of 2.5e-4 in it, and in velocity_ik's residual)."""
    ratios = np.full(len(q), np.nan)
    length = robot.reach or 1.0
    rows = np.array([length if component in ("x", "y", "z") else 1.0 for component in robot.task])
    columns = np.array([1.0 if joint.revolute else length for joint in robot.joints])
    for k, row in enumerate(q):
        rotation = reference.fk(robot, row)[:3, :3]
        if js_rank.singularity_rows(robot) is None and np.hypot(rotation[0, 0], rotation[1, 0]) < EULER_MARGIN:
            continue
        values = np.linalg.svd(reference.singularity_jacobian(robot, row) * columns / rows[:, None], compute_uv=False)
        ratios[k] = values[-1] / max(values[0], 1.0)
    return ratios


def _vanishing_error(factors: np.ndarray, ranks: np.ndarray) -> float:
    """The largest, over samples where Js is singular, of the smallest |factor| (0 if none)."""
    singular = ranks < SINGULAR_RANK
    return float(np.max(np.min(np.abs(factors[singular]), axis=1), initial=0.0))


def _target_error(robot: Robot, q: np.ndarray, targets: np.ndarray) -> float:
    """How far the rows of q miss their targets, at most (angles of a task vector compared
    modulo 2 pi); 0 for no rows."""
    if not len(q):
        return 0.0
    difference = reference.ik_target(robot, q) - targets
    if len(robot.task) < 6:
        angular = [i for i, name in enumerate(robot.task) if name in EULER_ANGLES]
        difference[:, angular] = _wrapped(difference[:, angular])
    return float(np.max(np.abs(difference)))


def _ik_results(robot: Robot, backends: GeneratedCode, q: np.ndarray, tolerances: dict,
                form: ik.ClosedForm | None) -> list[Result]:
    """`ik` and `ik_numeric` by round trip on targets reached at random configurations q.

    ik: every solution must reach the target, and there must be one (k = 0 is an infinite
    error); ik_numeric: started 0.1 rad (or length unit) away from q, wherever it reports
    convergence it must have reached the target (the note says how often it converged).
    """
    targets = reference.ik_target(robot, q)
    results = []
    if form is not None:
        # With a free joint, ik takes its angle: q's, which every solution must keep.
        free = None if form.free is None else q[:, form.free]
        errors, checked = {}, {}
        for backend in backends.names:
            if not backends.has(backend, "ik"):  # CasADi has no general 6R ik (an eigensolver loop)
                errors[backend] = None
                continue
            found, checked[backend] = backends.ik(backend, targets, free)
            kept = free is None or all((solutions[:, form.free] == given).all() for solutions, given in zip(found, free))
            reached = np.repeat(targets, [len(solutions) for solutions in found], axis=0)
            errors[backend] = (math.inf if not kept or not all(len(solutions) for solutions in found)
                               else _target_error(robot, np.concatenate(found), reached))
            if checked[backend] is not None:  # the target's own check of its solutions counts too
                errors[backend] = max(errors[backend], float(np.max(checked[backend], initial=0.0)))
        # The closed form divides by sines that vanish at singularities, so float rounding is
        # amplified there: measured up to 7.6e-4 on 2,000 ur5 targets, hence ten times the
        # tolerance of straight-line functions for the float builds.
        ik_tolerances = {backend: 10 * tolerance if is_float(backend) else tolerance
                         for backend, tolerance in tolerances.items()}
        on_target = [backend for backend, error in checked.items() if error is not None]
        results.append(Result(robot.name, "ik", errors, ik_tolerances,
                              f"every solution of {len(targets)} targets fk(q) reaches the target"
                              + (f", with joint {form.free + 1} as given" if form.free is not None else "")
                              + "".join(f"; checked on the target too ({backend})" for backend in on_target)))
        results += _branch_results(robot, backends, q, targets, free, ik_tolerances)
    starts = q + 0.1 * np.random.default_rng(1).choice([-1.0, 1.0], size=q.shape)
    limits = np.array(robot.ranges)
    starts = np.clip(starts, limits[:, 0], limits[:, 1])
    # On the target the whole batch is one QEMU run: every random sample.
    count = len(q) if backends.emulator is not None else min(len(q), NUMERIC_IK_SAMPLES)
    errors, converged = {}, {}
    for backend in backends.names:
        found, status = backends.call(backend, "ik_numeric", targets[:count], starts[:count], IK_NUMERIC_STEPS,
                                      IK_NUMERIC_VERIFIED["float" if is_float(backend) else "double"])
        # Status 0 promises |error| <= tol; a stall (a local minimum of the task error) is allowed.
        reached = np.asarray(status) == 0
        errors[backend] = _target_error(robot, np.asarray(found)[reached], targets[:count][reached])
        converged[backend] = int(reached.sum())
    results.append(Result(robot.name, "ik_numeric", errors, tolerances,
                          "error where it reports convergence, from 0.1 away; converged at "
                          + ", ".join(f"{n}/{count} ({backend})" for backend, n in converged.items())))
    return results


def _ik_numeric_step_result(robot: Robot, backends: GeneratedCode, q: np.ndarray, tolerances: dict) -> Result:
    """ik_numeric_step from each random sample toward the target of another one, against the
    reference's damped least-squares step (STEP_DAMPING), where the task's Euler angles are
    defined (cos(pitch) >= EULER_MARGIN at the start)."""
    if set(EULER_ANGLES) & set(robot.task):
        rotations = reference.fk(robot, q)[:, :3, :3]
        q = q[np.hypot(rotations[:, 0, 0], rotations[:, 1, 0]) >= EULER_MARGIN]
    targets = reference.ik_target(robot, np.roll(q, 1, axis=0))
    start, next_q, cost = reference.ik_numeric_step(robot, targets, q, STEP_DAMPING)
    expected = np.hstack([start, next_q, cost[:, None]])
    errors = {}
    for backend in backends.names:
        found = backends.call(backend, "ik_numeric_step", targets, q, STEP_DAMPING)
        value = np.hstack([np.reshape(part, (len(q), -1)) for part in found])
        errors[backend] = float(np.max(np.abs(value - expected) / (1 + np.abs(expected)), initial=0.0))
    return Result(robot.name, "ik_numeric_step", errors, tolerances,
                  f"one step toward another sample's target (damping {STEP_DAMPING}) at {len(q)} samples")


def _branch_results(robot: Robot, backends: GeneratedCode, q: np.ndarray, targets: np.ndarray, free: np.ndarray | None,
                    tolerances: dict) -> list[Result]:
    """ik_branches: every valid branch reaches its target, and at least one branch is valid
    (each target was reached at q); ik_nearest, seeded 0.05 away from q with random weights:
    status OK, a solution that reaches the target, and no valid branch inside the limits
    nearer the seed (its own metric, sum of weights_j (q_j - seed_j)^2, on the backend's own
    branches)."""
    rng = np.random.default_rng(3)
    seeds = q + 0.05 * rng.choice([-1.0, 1.0], size=q.shape)
    weights = rng.uniform(0.5, 2.0, size=q.shape)
    branch_errors, nearest_errors, nearer = {}, {}, {}
    given = () if free is None else (free,)
    for backend in backends.names:
        if not backends.has(backend, "ik_nearest"):  # CasADi has no general 6R ik_branches: nor its ik_nearest
            branch_errors[backend] = nearest_errors[backend] = None
            continue
        solutions, valid, in_limits = backends.call(backend, "ik_branches", targets, *given)
        valid, in_limits = valid.astype(bool), in_limits.astype(bool)
        found, status = backends.call(backend, "ik_nearest", targets, seeds, *given, weights)
        reached = np.repeat(targets, valid.sum(axis=1), axis=0)
        branch_errors[backend] = (math.inf if not valid.any(axis=1).all()
                                  else _target_error(robot, solutions[valid], reached))
        ok = np.asarray(status) == 0
        nearest_errors[backend] = math.inf if not ok.all() else _target_error(robot, np.asarray(found), targets)
        distance = np.einsum("kj,kj->k", weights, (np.asarray(found) - seeds) ** 2)
        branch_distance = np.einsum("kj,kmj->km", weights, (solutions - seeds[:, None, :]) ** 2)
        best = np.min(np.where(valid & in_limits, branch_distance, np.inf), axis=1)
        nearer[backend] = int((distance > best * (1 + 1e-5) + 1e-12).sum())
        if nearer[backend]:
            nearest_errors[backend] = math.inf
    return [Result(robot.name, "ik_branches", branch_errors, tolerances,
                   f"every valid branch of {len(targets)} targets reaches the target"),
            Result(robot.name, "ik_nearest", nearest_errors, tolerances,
                   "reaches the target, and no valid branch in the limits is nearer the seed"
                   + "".join(f"; {backend}: {n} not the nearest" for backend, n in nearer.items() if n))]


def verify(robots: list[Robot], samples: int, seed: int,
           progress: Callable[[str], None] = lambda message: None, folder: Path | None = None,
           target: str | None = None, sources: Path | None = None,
           emulators: list[Emulator] | None = None, jobs: int = 1, native: bool = False) -> list[Result]:
    """Generate, build and compare every robot, up to `jobs` robots at once in processes of
    their own (`parallel`). The code is written to `folder` (ROBOT/double/...,
    ROBOT/float/...) when one is given, to a temporary folder otherwise.

    With a `target` ("cortex-m4f"), only the float C is checked, run on the emulated target
    (`jacgen.checking.cortex_m4f`), one robot after the other: the C generated now, or NAME.h and NAME.c
    from `sources`. Each robot's Emulator, with the instructions and stack it measured, is
    appended to `emulators`. With `native`, NAME_native is built and compared as well."""
    if target is None:
        c_compiler()  # fail before generating anything when there is none
    else:
        check_tools()
    with tempfile.TemporaryDirectory(prefix="jacgen-verify-") as temporary:
        folder = folder or Path(temporary)
        if target is None:
            progress(f"generating and verifying {', '.join(robot.name for robot in robots)}")
            found = for_each_robot(verify_on_host, robots, jobs, (samples, seed, folder, native),
                                   lambda robot: progress(f"verified {robot.name}"))
            return [result for results in found for result in results]
        results = []
        for robot in robots:
            progress(f"verifying {robot.name} on the emulated {target}")
            generator = Generator(robot)
            emulator = Emulator(robot, generator, folder / robot.name / target, sources)
            emulator.build()
            random, q = configurations(robot, generator.singularities, samples, seed)
            results += verify_robot(robot, GeneratedCode(robot, generator.signatures(), folder / robot.name / "double",
                                                         {}, emulator), generator.functions(), q, len(random),
                                    generator.closed_form)
            emulator.measure_remaining(random, generator.closed_form and generator.closed_form.free)
            emulator.resources  # read from the build folder while it exists
            if emulators is not None:
                emulators.append(emulator)
        return results


def verify_on_host(robot: Robot, samples: int, seed: int, folder: Path, native: bool = False,
                   functions=None) -> list[Result]:
    """One robot on the host: generated into folder/NAME/{double,float}, its C built for
    both real types (at once), every backend compared with the reference; with `native`,
    NAME_native too (generated into folder/NAME/native and built by its setup.py). `functions`:
    only those and their callees (all by default)."""
    work, generator = folder / robot.name, Generator(robot, selection=functions)
    write_files(render_robot(robot, ("c", "python", "casadi"), "double", generator), work / "double")
    write_files(render_robot(robot, ("c",), "float", generator), work / "float")
    if native:
        write_files(render_robot(robot, ("native",), "double", generator), work / "native")
    with ThreadPoolExecutor(2) as pool:
        builds = {real: pool.submit(compile_shared, [work / real / robot.name / f"{robot.name}.c"],
                                    work / f"{robot.name}_{real}.so") for real in ("double", "float")}
        module = load_native(work / "native" / robot.name, robot.name) if native else None
        built = {real: build.result() for real, build in builds.items()}
    random, q = configurations(robot, generator.singularities, samples, seed)
    return verify_robot(robot, GeneratedCode(robot, generator.signatures(), work / "double", built, native=module),
                        generator.functions(), q, len(random), generator.closed_form)


def format_table(results: list[Result]) -> str:
    """One row per robot and function, one column per backend: the largest error."""
    names = list(results[0].errors) if results else list(HOST_BACKENDS)
    header = ["robot", "function", *names, "float tol", "note"]
    rows = [header]
    for result in results:
        cells = [result.robot, result.function]
        for backend in names:
            error = result.errors[backend]
            mark = "" if error is None or error <= result.tolerances[backend] else " FAIL"
            cells.append("-" if error is None else f"{error:.1e}{mark}")
        cells += [f"{max(result.tolerances[backend] for backend in names if is_float(backend)):.1e}", result.note]
        rows.append(cells)
    widths = [max(len(row[c]) for row in rows) for c in range(len(header))]
    lines = ["  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows]
    above = sum(result.above_tolerance for result in results)
    uncompared = sum(not result.compared for result in results)
    run = [real for real in VERIFIED if any(is_float(backend) == (real == "float") for backend in names)]
    tolerances = ", ".join(f"{real} {VERIFIED[real]:.0e}" for real in run)  # of the builds run
    lines.append(f"tolerance x (1 + reach): {tolerances}; {above} of {len(results)} functions above tolerance"
                 + (f", {uncompared} not compared" if uncompared else ""))
    return "\n".join(lines)
