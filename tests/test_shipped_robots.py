"""The shipped robots: `jacgen verify` as the CLI runs it (200 samples, seed 0), every
function of every backend against jacgen.reference, none above tolerance; and the C it
verified, double and float, compiled for the host (-O2), and float for a Cortex-M4F (-Os), with
every warning as an error, calling libm only, every function's stack static and small. One
generation of each robot serves both (generated/ itself is checked by tests/test_golden.py)."""

import shutil
import subprocess

import pytest

from jacgen.checking.c_library import WARNING_FLAGS
from jacgen.model.structure import classify
from jacgen.solvers import general6r
from jacgen.parallel import usable_cpus
from jacgen.checking.verify import verify

from conftest import ROBOT_NAMES, robot

ARM_FLAGS = ("-mcpu=cortex-m4", "-mthumb", "-mfloat-abi=hard", "-mfpu=fpv4-sp-d16", "-Os")
LIBM = {name + suffix for name in "sin cos sincos tan asin acos atan atan2 sqrt fabs hypot ceil floor fmax remainder".split()
        for suffix in ("", "f")}
# The general 6R solver's eigenproblem kernel computes in double in a float build too (its
# 24 x 24 eigenproblem needs it; docs/contract.md): those objects may call the double functions
# and, on the Cortex-M4F, libgcc's software double arithmetic.
DOUBLE_KERNEL = {f"{name}.o" for name in ROBOT_NAMES if classify(robot(name)).solver == "general_6r"}
# GCC may emit calls to these for array copies even in freestanding code, which must provide
# them ("Standards", GCC manual); the sources call none of them.
COMPILER_RUNTIME = {"memcpy", "memmove", "memset", "memcmp"}
# Bytes per function. Straight-line functions keep only scalars (a few hundred bytes); ik
# keeps its candidate solutions. A change that puts big arrays on the stack fails here.
STACK_LIMIT = 4096
# The general 6R solver's ik_branches holds its working memory (struct NAME_ik_work, about 31 kB)
# as a local by default, with 1 kB of scalars beside it; compiled with NAME_IK_STATIC_WORK it is
# static, and every function of every robot stays under STACK_LIMIT (contract §4).
GENERAL_STACK_LIMIT = general6r.work_bytes("double") + 1024
STATIC_WORK = tuple(f"-D{name.upper()}_IK_STATIC_WORK" for name in ROBOT_NAMES)


def _run(command, cwd=None):
    result = subprocess.run([str(part) for part in command], capture_output=True, text=True, cwd=cwd)
    assert result.returncode == 0 and not result.stderr, result.stderr
    return result.stdout


@pytest.fixture(scope="module")
def verified(tmp_path_factory):
    """verify's results for every shipped robot (a process per robot, as `jacgen verify` runs
    them), and the folder it generated them in."""
    folder = tmp_path_factory.mktemp("shipped")
    return verify([robot(name) for name in ROBOT_NAMES], samples=200, seed=0, folder=folder,
                  jobs=usable_cpus()), folder


def test_shipped_robots_pass_verify(verified):
    results, _ = verified
    assert {result.robot for result in results} == set(ROBOT_NAMES)
    assert [(r.robot, r.function, r.errors) for r in results if r.failed] == []
    assert len(results) >= 15 * len(ROBOT_NAMES)


@pytest.fixture(params=["double", "float"])
def shipped_c(request, verified):
    """The C of every shipped robot in one precision: (real, [.c files])."""
    _, folder = verified
    return request.param, sorted(folder.glob(f"*/{request.param}/*/*.c"))


def _check_objects(folder, nm, real, static_work=False):
    """Only libm symbols (and the compiler's runtime) are undefined, only the f functions in
    float builds; every function's stack use is static and small (with the general solver's
    working memory static: every one under STACK_LIMIT)."""
    for obj in sorted(folder.glob("*.o")):
        undefined = set(_run([nm, "-u", obj]).split()) - {"U"} - COMPILER_RUNTIME
        if obj.name in DOUBLE_KERNEL:  # libgcc's software double arithmetic, on a Cortex-M4F
            undefined = {name for name in undefined if not name.startswith("__aeabi_")}
        assert undefined <= LIBM, (obj.name, undefined - LIBM)
        if real == "float" and obj.name not in DOUBLE_KERNEL:
            assert all(name.endswith("f") for name in undefined), (obj.name, undefined)
    usage = []
    for path in folder.glob("*.su"):
        general = f"{path.stem}.o" in DOUBLE_KERNEL
        for line in path.read_text().splitlines():
            where, size, kind = line.rsplit("\t", 2)
            function = where.rsplit(":", 1)[-1]
            body = function.split(".")[0]  # gcc's clones: NAME_ik_branches.part.0
            limit = GENERAL_STACK_LIMIT if general and body.endswith("_ik_branches") and not static_work \
                else STACK_LIMIT
            usage.append((int(size), function, kind, limit))
    worst = max(usage)
    print(f"worst stack usage ({real}): {worst[0]} bytes in {worst[1]} ({worst[2]})")
    assert all(size <= limit and kind == "static" for size, _, kind, limit in usage), \
        [(size, function) for size, function, _, limit in usage if size > limit]


def test_host_compile_is_warning_free_and_needs_only_libm(shipped_c, tmp_path):
    real, sources = shipped_c
    _run(["gcc", *WARNING_FLAGS, "-O2", "-fstack-usage", "-c", *sources], cwd=tmp_path)
    _check_objects(tmp_path, "nm", real)
    static = tmp_path / "static"  # again, the sources whose working memory the macro makes static
    static.mkdir()
    _run(["gcc", *WARNING_FLAGS, *STATIC_WORK, "-O2", "-fstack-usage", "-c",
          *(source for source in sources if "_IK_STATIC_WORK" in source.read_text())], cwd=static)
    _check_objects(static, "nm", real, static_work=True)


@pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None, reason="arm-none-eabi-gcc not installed")
def test_cortex_m4_compile_is_warning_free_and_needs_only_libm(verified, tmp_path):
    """The float build, the one for a single-precision FPU (a double build there runs in
    libgcc's software arithmetic; its source is the host's double build, checked above)."""
    _, folder = verified
    _run(["arm-none-eabi-gcc", *ARM_FLAGS, *WARNING_FLAGS, *STATIC_WORK, "-fstack-usage", "-c",
          *folder.glob("*/float/*/*.c")], cwd=tmp_path)
    _check_objects(tmp_path, "arm-none-eabi-nm", "float", static_work=True)


