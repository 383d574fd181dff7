"""What the benches share, written once: paths, generated code, one timer policy, one native harness.

Paths. A bench runs as `python bench/NAME.py` from anywhere, with or without PYTHONPATH=.:
Python puts bench/ first on sys.path, and a bench's `import common` puts the repository
root there (for `jacgen`) and appends tests/ (for the seeded arms and the test suite's
builders of peer models). Benches reach tests/ only through this module: `random_arm_text`,
`without_limits`, `kinematic_chain` and `pinocchio_from_dh` are imported from it, each from
tests/support/ when first asked for (FROM_TESTS), so a bench loads only what it uses.
No bench imports another bench.

Timer policy, for Python and native timings alike: one untimed warm-up round, then the
MEDIAN over `rounds` rounds (`timed`, `median_times`, `per_call`; `run_loops` for the
native harness). The median and not the minimum: the benches run on shared machines (CI is
a loaded 2-core VM), where the minimum is the one round that happened to run alone, and
moves with whatever else runs; the median discards a slow round and a lucky one alike, so
repeated runs agree. Rounds interleave the implementations compared (`median_times`, the
harness's main), so that a change of load falls on all of them. The warm-up takes JIT
compilation, first-touch allocation and cold caches out of the figures. The two benches
that time generation in a fresh process each (bench_generate, bench_scaling) have no
warm-up by design: a cold start is what they measure.

Native harness, one for C and C++: `PRELUDE` gives the one timer, `bench_now()` (seconds,
CLOCK_MONOTONIC), the one sink, `bench_sink` (a volatile double every timed loop adds its
outputs to, and whose NaN check is main's exit status, so that nothing computed is dead),
and the joint vector of call i, `bench_configuration` (it changes every call, so that
nothing is hoisted out of a loop). `harness` writes one timed function per `Loop` and a
main printing `ROUND NS ROBOT VARIANT` per loop and round; `build` compiles it, `run_loops`
runs it and takes the medians. One set of flags, FLAGS (-O2 -DNDEBUG; C as -std=c99, C++
as -std=c++17, linked with -lm), every source its own translation unit (no inlining across
them); the shared libraries called through ctypes (`shared_library`) take the same FLAGS,
beside jacgen.checking.c_library's warning flags.
"""

import importlib
import json
import math
import statistics
import subprocess
import sys
import sysconfig
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, NamedTuple

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this checkout's jacgen, whatever else is on the path
if str(ROOT / "tests") not in sys.path:
    sys.path.append(str(ROOT / "tests"))

import casadi  # noqa: E402 (a dependency of jacgen)
import numpy as np  # noqa: E402
import sympy  # noqa: E402

from jacgen.checking import reference  # noqa: E402
from jacgen.checking.c_library import c_compiler, compile_shared  # noqa: E402
from jacgen.files import write_files  # noqa: E402
from jacgen.building import import_module  # noqa: E402
from jacgen.emission.render import render_robot  # noqa: E402
from jacgen.inputs.robot_file import load_robot  # noqa: E402

# What benches take from tests/: {name: the module of tests/ that defines it}.
FROM_TESTS = {"random_arm_text": "support.random_arms", "pinocchio_from_dh": "support.pinocchio_chain",
              "without_limits": "support.ik", "kinematic_chain": "support.ik", "wrapped": "support.ik"}


def from_tests(name: str):
    """FROM_TESTS[name], imported from its module of tests/."""
    return getattr(importlib.import_module(FROM_TESTS[name]), name)


def __getattr__(name: str):
    """`from common import kinematic_chain` and the rest of FROM_TESTS, imported when asked for."""
    if name in FROM_TESTS:
        return from_tests(name)
    raise AttributeError(f"module 'common' has no attribute {name!r}")


# -- robots and generated code --------------------------------------------------------------------
def optional(name: str, note: Callable[[str], None] = print):
    """The module `name`, or None and a note when it is not installed (its rows or columns
    are then skipped); the peers' import-time deprecation warnings silenced."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return importlib.import_module(name)
    except ImportError as error:
        note(f"{name} is not installed ({error}): skipped")
        return None


def shipped(name: str):
    """The robot of robots/NAME.yaml."""
    return load_robot(ROOT / "robots" / f"{name}.yaml")


def robot_path(name: str) -> Path:
    """robots/NAME.yaml, or else the calibrated or perturbed arm tests/data/calibrated/NAME.yaml."""
    path = ROOT / "robots" / f"{name}.yaml"
    return path if path.exists() else ROOT / "tests" / "data" / "calibrated" / f"{name}.yaml"


def generate(robot, folder: Path, languages=("c",), real: str = "double") -> Path:
    """Render `robot` in `languages` into folder/NAME/ and return that folder."""
    write_files(render_robot(robot, languages, real), folder)
    return folder / robot.name


def load_module(path: Path, name: str | None = None):
    """Import a generated Python file by its path (jacgen.building.import_module)."""
    return import_module(path, name or f"bench_{path.stem}")


def shared_library(source: Path) -> Path:
    """`source` (generated C) built with FLAGS into a shared library beside it, for ctypes."""
    return compile_shared([source], source.parent / f"lib{source.stem}.so", FLAGS)


# One worker renders a robot in a fresh process (bench_generate, bench_scaling): run in the
# tree being measured (its jacgen first on sys.path), it prints one line of JSON.
WORKER = """
import json, resource, sys, time
sys.path.insert(0, ".")
try:  # the stage folders (issue 38), else the flat layout of earlier commits
    from jacgen.emission.generator import Generator
    from jacgen.emission.render import render_robot
    from jacgen.inputs.robot_file import load_robot
except ImportError:
    from jacgen.functions import Generator
    from jacgen.render import render_robot
    from jacgen.robot import load_robot
robot = load_robot(sys.argv[1])
start = time.perf_counter()
generator = Generator(robot)
render_robot(robot, generator=generator)
seconds = time.perf_counter() - start
operations = {f.name: f.body.operation_count for f in generator.functions()}
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"seconds": seconds, "peak_mb": peak, "operations": operations,
                  "complete": generator.singularities.complete}))
"""


def render_in_process(tree: Path, robot: Path, timeout: float) -> dict | None:
    """One rendering of every language of `robot` by the jacgen in `tree`, in a fresh process
    (start-up and imports not timed): {seconds, peak_mb, operations, complete}; None past
    `timeout` seconds."""
    try:
        done = subprocess.run([sys.executable, "-c", WORKER, str(robot)], cwd=tree, capture_output=True,
                              text=True, timeout=timeout, check=True)
    except subprocess.TimeoutExpired:
        return None
    except subprocess.CalledProcessError as error:
        raise SystemExit(f"{Path(sys.argv[0]).stem}: {robot} failed in {tree}:\n{error.stderr}") from None
    return json.loads(done.stdout.splitlines()[-1])


# -- the timer policy: a warm-up, then the median of the rounds; log-log slopes ----------------------
median = statistics.median  # the one statistic of repeated measurements


def slope(xs, ys) -> float:
    """Least-squares slope of log(y) against log(x) (how a figure grows with the joint count)."""
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


class Timing(NamedTuple):
    seconds: float  # the median wall time of one run
    result: object  # what the warm-up run returned


def _same(result):
    return result


def median_times(runs: dict, rounds: int, ready: Callable = _same) -> dict:
    """{key: Timing} of each `runs[key]()`: one untimed warm-up call each, then `rounds` rounds,
    every round timing every run once. `ready(result)` is timed with the run (for example
    jax.block_until_ready: the work an asynchronous library has only queued)."""
    results = {}
    for key, run in runs.items():
        results[key] = run()
        ready(results[key])
    times = {key: [] for key in runs}
    for _ in range(rounds):
        for key, run in runs.items():
            start = time.perf_counter()
            ready(run())
            times[key].append(time.perf_counter() - start)
    return {key: Timing(median(times[key]), results[key]) for key in runs}


def timed(run: Callable, rounds: int, ready: Callable = _same) -> Timing:
    """Timing of `run()`: a warm-up, then the median of `rounds` rounds."""
    return median_times({None: run}, rounds, ready)[None]


def each(function: Callable, arguments: list) -> Callable:
    """A run that calls `function(*argument)` for every argument (the results dropped)."""
    def run():
        for argument in arguments:
            function(*argument)
    return run


def per_call(function: Callable, arguments: list, rounds: int) -> float:
    """Median seconds per call of `function(*argument)` over the list `arguments`."""
    return timed(each(function, arguments), rounds).seconds / len(arguments)


# -- the native harness -----------------------------------------------------------------------------
FLAGS = ("-O2", "-DNDEBUG")  # every native build of the benches, C and C++
STANDARD = {"c": "-std=c99", "c++": "-std=c++17"}

PRELUDE = r"""
#if !defined(__cplusplus) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 199309L /* clock_gettime */
#endif
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* Every timed loop adds its outputs here, and main returns its NaN check: nothing is dead. */
static volatile double bench_sink;

/* Seconds on the monotonic clock: the one timer. */
static double bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The joint vector of call i: it changes on every call, so nothing is hoisted out of a loop. */
static void bench_configuration(double *q, int n, long i)
{
    const double step = (double)(i & 1023) * 1e-6;
    for (int j = 0; j < n; ++j) q[j] = 0.3 + 0.1 * (double)j + step * (double)(j + 1);
}

/* One round's figure of a timed loop; round -1 is the warm-up, not printed. */
static void bench_report(int round, double nanoseconds, const char *label)
{
    if (round >= 0) printf("%d %.3f %s\n", round, nanoseconds, label);
}
"""

LOOP = """
static double time_{index}(long calls)
{{
    double q[{dof}], sink = 0;
    {setup}
    const double t0 = bench_now();
    for (long i = 0; i < calls; ++i) {{
        bench_configuration(q, {dof}, i);
        {call}
        sink += {sink};
    }}
    const double t1 = bench_now();
    bench_sink = bench_sink + sink;
    return (t1 - t0) * 1e9 / (double)calls;
}}
"""

MAIN = """
int main(int argc, char **argv)
{{
    const long calls = argc > 2 ? atol(argv[1]) : 0;
    const int rounds = argc > 2 ? atoi(argv[2]) : 0;
    {setup}
    for (int round = -1; round < rounds; ++round) {{
{reports}
    }}
    return bench_sink != bench_sink;
}}
"""


@dataclass(frozen=True)
class Loop:
    """One timed loop: the statements `call`, on `q` (the `dof` joint values of each call), run
    `calls` times, the expression `sink` of their outputs added up. `setup` declares what
    the loop uses, outside the timing; `declare` the C functions it calls (C linkage)."""
    robot: str
    variant: str
    dof: int
    call: str
    sink: str
    setup: str = ""
    declare: str = ""


def harness(loops: list[Loop], header: str = "", main_setup: str = "") -> str:
    """C (or C++) of a harness: `header` (includes), each loop's timed function, and a main
    taking `calls rounds ...` that runs a warm-up round and `rounds` rounds, each timing every
    loop once, and prints `ROUND NS ROBOT VARIANT` per loop and round."""
    declarations = list(dict.fromkeys(loop.declare for loop in loops if loop.declare))
    linkage = ["#ifdef __cplusplus", 'extern "C" {', "#endif", *declarations, "#ifdef __cplusplus", "}", "#endif"]
    functions = [LOOP.format(index=k, dof=loop.dof, setup=loop.setup, call=loop.call, sink=loop.sink)
                 for k, loop in enumerate(loops)]
    reports = "\n".join(f'        bench_report(round, time_{k}(calls), "{loop.robot} {loop.variant}");'
                        for k, loop in enumerate(loops))
    return "\n".join([PRELUDE, header, *(linkage if declarations else []), *functions,
                      MAIN.format(setup=main_setup, reports=reports)])


def build(folder: Path, name: str, source: str, sources=(), language: str = "c", options=(),
          libraries=()) -> Path:
    """The program folder/NAME: the harness `source` (C or C++, written to folder) linked with the
    C `sources`, each compiled on its own with FLAGS (the folder of each on the include path);
    `options` (include paths, definitions) and `libraries` for the harness's own needs."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / (f"{name}.c" if language == "c" else f"{name}.cpp")
    path.write_text(source)
    includes = [f"-I{parent}" for parent in dict.fromkeys(Path(s).parent for s in sources)]
    objects = []
    for c_source in map(Path, sources):
        objects.append(c_source.with_suffix(".o"))
        subprocess.run([c_compiler(), STANDARD["c"], *FLAGS, *includes, "-c", "-o", str(objects[-1]), str(c_source)],
                       check=True)
    compiler = c_compiler() if language == "c" else "g++"
    subprocess.run([compiler, STANDARD[language], *FLAGS, *includes, *options, "-o", str(folder / name), str(path),
                    *map(str, objects), *libraries, "-lm"], check=True)
    return folder / name


def run(program: Path, *arguments) -> str:
    """What `program arguments...` prints."""
    return subprocess.run([str(program), *map(str, arguments)], check=True, capture_output=True, text=True).stdout


def run_loops(program: Path, calls: int, rounds: int, *arguments) -> dict[tuple[str, str], float]:
    """Run a `harness`: {(robot, variant): median ns per call over the rounds}."""
    times: dict[tuple[str, str], list[float]] = {}
    for line in run(program, calls, rounds, *arguments).splitlines():
        _, nanoseconds, robot, variant = line.split(maxsplit=3)
        times.setdefault((robot, variant), []).append(float(nanoseconds))
    return {key: median(values) for key, values in times.items()}


def fk_jacobian_loop(robot, variant: str) -> Loop:
    """jacgen's generated `NAME_fk_jacobian(q, T, J)` (double)."""
    last = 6 * robot.dof - 1
    return Loop(robot.name, variant, robot.dof, f"{robot.name}_fk_jacobian(q, T, J);", f"T[3] + J[{last}]",
                setup=f"double T[16], J[{last + 1}];")


# -- closed-form ik: the native loop over stored poses, and the quality of solutions ------------------
IK_HARNESS = r"""
#include "NAME.h"

#ifdef NAME_UPPER_IK_FREE_JOINT /* a 7-joint arm: the free joint's angle per target, from argv[4] */
#define FREE(i) frees[i],
#else
#define FREE(i)
#endif

static int load(const char *path, double *values, long count)
{
    FILE *file = fopen(path, "rb");
    int ok = file && fread(values, sizeof(double), (size_t)count, file) == (size_t)count;
    if (file) fclose(file);
    return ok;
}

int main(int argc, char **argv)
{
    const long count = argc >= 4 ? atol(argv[2]) : 0;
    const int rounds = argc >= 4 ? atoi(argv[3]) : 0;
    double *targets = (double *)malloc(sizeof(double) * 16 * (size_t)count);
    double *frees = (double *)malloc(sizeof(double) * (size_t)count);
    double q[NAME_UPPER_MAX_IK_SOLUTIONS * NAME_UPPER_DOF];
    if (!targets || !frees || !load(argv[1], targets, 16 * count) || (argc > 4 && !load(argv[4], frees, count))) {
        return 2;
    }
    (void)frees;
    for (int round = -1; round < rounds; ++round) {
        long solutions = 0;
        char label[32];
        const double t0 = bench_now();
        for (long i = 0; i < count; ++i) solutions += NAME_ik(targets + 16 * i, FREE(i) q);
        const double t1 = bench_now();
        bench_sink = bench_sink + (double)solutions;
        snprintf(label, sizeof label, "%ld", solutions);
        bench_report(round, (t1 - t0) * 1e9 / (double)count, label);
    }
    free(targets);
    free(frees);
    return bench_sink != bench_sink;
}
"""


def native_ik(robot, source: Path, targets: np.ndarray, rounds: int, folder: Path,
              frees: np.ndarray | None = None) -> tuple[float, int]:
    """Median microseconds per pose of the generated NAME_ik (in `source`) called in a native
    loop over `targets` (with the free joint's angle per target for a 7-joint arm), and the
    solutions it found."""
    data = folder / f"targets_{robot.name}.bin"
    targets.astype(np.float64).tofile(data)
    extra = []
    if frees is not None:
        extra = [folder / f"frees_{robot.name}.bin"]
        frees.astype(np.float64).tofile(extra[0])
    text = PRELUDE + IK_HARNESS.replace("NAME_UPPER", robot.name.upper()).replace("NAME", robot.name)
    program = build(folder, f"harness_{robot.name}", text, [source])
    rows = [line.split() for line in run(program, data, len(targets), rounds, *extra).splitlines()]
    return median(float(row[1]) for row in rows) / 1e3, int(rows[-1][2])


def ik_quality(robot, q: np.ndarray, targets: np.ndarray, found: list) -> tuple[float, float, float]:
    """The mean number of solutions per pose, the share of poses whose configuration (a row of
    q) is among them (every joint within 1e-6 rad, modulo 2 pi), and the share of solutions
    off their target by more than 1e-8 (largest entry of the 4x4 difference, jacgen.reference fk)."""
    found = [np.asarray(s, dtype=float).reshape(-1, robot.dof) for s in found]
    recovered = sum(len(s) > 0 and np.abs(from_tests("wrapped")(s - row)).max(axis=1).min() < 1e-6 for s, row in zip(found, q))
    errors = [np.abs(reference.fk(robot, x) - T).max() for s, T in zip(found, targets) for x in s]
    return (float(np.mean([len(s) for s in found])), recovered / len(q),
            sum(e > 1e-8 for e in errors) / max(len(errors), 1))


# -- CasADi's fk + Jacobian, built from the DH table alone --------------------------------------
def _constant_trig(angle) -> tuple[float, float]:
    """cos and sin of a constant angle, exact zeros and ones where the angle is a multiple of pi/2."""
    return float(sympy.cos(angle.exact)), float(sympy.sin(angle.exact))


def _rz(c, s):
    return casadi.blockcat([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def _rx(c, s):
    return casadi.blockcat([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _translation(x, y, z):
    return casadi.blockcat([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def _pose(pose):
    (cr, sr), (cp, sp), (cy, sy) = (_constant_trig(angle) for angle in pose.rpy)
    rot_y = casadi.blockcat([[cp, 0, sp, 0], [0, 1, 0, 0], [-sp, 0, cp, 0], [0, 0, 0, 1]])
    return casadi.mtimes([_translation(*(v.approx for v in pose.xyz)), _rz(cy, sy), rot_y, _rx(cr, sr)])


def casadi_fk_jacobian(robot) -> casadi.Function:
    """T (4x4) and the world-frame geometric Jacobian J (6 x n) as one SX function of q: link
    transforms multiplied out, J by the column formula, constant sines and cosines exact (so
    cos(90 deg) is 0 and not 6e-17)."""
    q = casadi.SX.sym("q", robot.dof)
    current = casadi.SX(_pose(robot.base))
    axes = []
    for i, joint in enumerate(robot.joints):
        if joint.revolute:
            angle = q[i] + joint.offset.approx
            rotation, d = _rz(casadi.cos(angle), casadi.sin(angle)), joint.d.approx
        else:
            rotation, d = _rz(*_constant_trig(joint.theta)), q[i] + joint.offset.approx
        twist = casadi.mtimes(_rx(*_constant_trig(joint.alpha)), _translation(joint.a.approx, 0, 0))
        if robot.convention == "standard":
            axes.append(current)
            current = casadi.mtimes([current, rotation, _translation(0, 0, d), twist])
        else:
            axes.append(casadi.mtimes(current, twist))
            current = casadi.mtimes([axes[-1], rotation, _translation(0, 0, d)])
    tool = casadi.mtimes(current, _pose(robot.tool))
    p = tool[:3, 3]
    columns = []
    for joint, axis in zip(robot.joints, axes):
        z, o = axis[:3, 2], axis[:3, 3]
        columns.append(casadi.vertcat(casadi.cross(z, p - o), z) if joint.revolute
                       else casadi.vertcat(z, casadi.SX(3, 1)))
    return casadi.Function(f"casadi_{robot.name}", [q], [tool, casadi.horzcat(*columns)])


def casadi_variants(robot) -> dict[str, casadi.Function]:
    """CasADi's fk+jacobian as built ("casadi") and after `casadi.cse` ("casadi_cse")."""
    plain = casadi_fk_jacobian(robot)
    cse = casadi.Function(f"casadi_cse_{robot.name}", plain.sx_in(), casadi.cse(plain.call(plain.sx_in())))
    return {"casadi": plain, "casadi_cse": cse}


def casadi_c(function: casadi.Function, folder: Path, real: str = "double", integer: str = "long long int",
             **options) -> Path:
    """folder/SYMBOL.c: `casadi.CodeGenerator`'s C of `function`."""
    generator = casadi.CodeGenerator(f"{function.name()}.c", {"casadi_real": real, "casadi_int": integer, **options})
    generator.add(function)
    generator.generate(str(folder) + "/")
    return folder / f"{function.name()}.c"


def casadi_loop(robot, function: casadi.Function, variant: str) -> Loop:
    """A CasADi function of q returning (T, J), as `casadi_c` writes it (double, long long int)."""
    symbol = function.name()
    return Loop(robot.name, variant, robot.dof, f"{symbol}(arg, res, iw, w, 0);",
                f"T[0] + J[{function.nnz_out(1) - 1}]",
                setup=f"double T[16], J[{6 * robot.dof}], w[{max(function.sz_w(), 1)}]; "
                      f"long long iw[{max(function.sz_iw(), 1)}]; "
                      "const double *arg[1] = {q}; double *res[2] = {T, J};",
                declare=f"int {symbol}(const double **arg, double **res, long long *iw, double *w, int mem);")


# -- Pinocchio's C++, from the `pin` wheel (Eigen's headers: `pip install cmeel-eigen`) -------------
PINOCCHIO_PREFIX = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix"
# INTERFACE_COMPILE_DEFINITIONS of the wheel's pinocchio::pinocchio_headers CMake target; its
# headers as system headers (their own deprecation warnings are not the bench's).
PINOCCHIO_OPTIONS = ("-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
                     "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
                     "-isystem", str(PINOCCHIO_PREFIX / "include"),
                     "-isystem", str(PINOCCHIO_PREFIX / "include" / "eigen3"))
PINOCCHIO_LIBRARIES = (f"-L{PINOCCHIO_PREFIX / 'lib'}", f"-Wl,-rpath,{PINOCCHIO_PREFIX / 'lib'}",
                       "-lpinocchio_default", "-lboost_serialization")
PINOCCHIO_INCLUDES = "\n".join(f"#include <pinocchio/{name}.hpp>" for name in (
    "multibody", "algorithm/kinematics", "algorithm/jacobian", "algorithm/frames", "serialization"))


def pinocchio_models(robots, folder: Path, first: int = 3) -> tuple[str, str, list[str]]:
    """Each robot's Pinocchio model from its DH table, saved in `folder` for a C++ harness: the
    harness's header (Pinocchio's includes, `model_NAME`), its main's setup (loading them from
    argv[first], argv[first + 1], ...) and those arguments."""
    pinocchio_from_dh = from_tests("pinocchio_from_dh")
    header, setup, arguments = [PINOCCHIO_INCLUDES], [], []
    for k, robot in enumerate(robots):
        arguments.append(str(folder / f"{robot.name}.pin"))
        pinocchio_from_dh(robot).saveToBinary(arguments[-1])
        header.append(f"static pinocchio::Model model_{robot.name};")
        setup.append(f"model_{robot.name}.loadFromBinary(argv[{first + k}]);")
    return "\n".join(header), "\n    ".join(setup), arguments


def pinocchio_setup(robot) -> str:
    """A loop's setup on `model_NAME`: data, frame (the tool), x (q as Eigen) and Jp (6 x n)."""
    return (f"pinocchio::Data data(model_{robot.name}); "
            f'const pinocchio::FrameIndex frame = model_{robot.name}.getFrameId("tool"); '
            f"Eigen::VectorXd x({robot.dof}); "
            f"pinocchio::Data::Matrix6x Jp = pinocchio::Data::Matrix6x::Zero(6, {robot.dof});")


def pinocchio_fk_jacobian_loop(robot, variant: str) -> Loop:
    """Pinocchio's forwardKinematics + computeFrameJacobian (LOCAL_WORLD_ALIGNED) of the tool."""
    model = f"model_{robot.name}"
    return Loop(robot.name, variant, robot.dof,
                f"for (int j = 0; j < {robot.dof}; ++j) x[j] = q[j]; "
                f"pinocchio::forwardKinematics({model}, data, x); "
                f"pinocchio::computeFrameJacobian({model}, data, x, frame, pinocchio::LOCAL_WORLD_ALIGNED, Jp);",
                f"data.oMf[frame].translation()[0] + Jp(5, {robot.dof - 1})", setup=pinocchio_setup(robot))
