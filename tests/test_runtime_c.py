"""Each file of templates/runtime/ compiled on its own (gcc -c) with the contract's warning
flags (§3), given only the macros and types it expects from the template around it: as -D, as
another runtime file (-include), or, for the native glue's per-robot table, a stub of one
function. The static helpers that the per-robot code calls are unused in such a file, hence
-Wno-unused-function; the native module is C11 (_Thread_local; setup.py builds it with the
compiler's default standard), hence -std=c11 there. The generated code compiles them in place (tests/test_c_runtime.py,
tests/test_native.py, tests/test_target.py)."""

import shutil
import subprocess
import sysconfig

import numpy
import pytest

from jacgen.checking.c_library import WARNING_FLAGS, c_compiler
from jacgen.solvers import general6r

from conftest import ROOT

RUNTIME = ROOT / "templates" / "runtime"
INCLUDED = ("-Wno-unused-function",)  # static helpers for the code around them
# The native glue's per-robot part (templates/native/module.c.jinja) for a module of one function.
NATIVE_STUB = """
static const jacgen_function jacgen_functions[1] = {
    {"f", "f(q)", "(6)->()", 1, 1, 1, 0, 1.0, {{"q", JACGEN_REAL, 1, {6}, 6, 8, NULL, 0}, {"y", JACGEN_REAL, 0, {0}, 1, 1, NULL, 0}}},
};
static const jacgen_kernels *const jacgen_builds[2] = {NULL, NULL};
"""


C11 = [flag.replace("-std=c99", "-std=c11") for flag in WARNING_FLAGS]


def compile_alone(compiler: str, source: str, flags: list[str], tmp_path, warnings=WARNING_FLAGS) -> None:
    command = [compiler, *warnings, *flags, "-c", str(RUNTIME / source), "-o", str(tmp_path / "out.o")]
    result = subprocess.run(command, capture_output=True, text=True)
    assert result.returncode == 0, f"{' '.join(command)}\n{result.stderr}"


def test_eigenvalues(tmp_path):
    compile_alone(c_compiler(), "eigenvalues.c", [*INCLUDED, "-include", "math.h"], tmp_path)


@pytest.mark.parametrize("imaginary", ["1e-05", "0.001"], ids=["double", "float"])
def test_general6r(tmp_path, imaginary):
    """The kernel runs in double in both builds; the float build's IMAGINARY is another number."""
    compile_alone(c_compiler(), "general6r.c", [*INCLUDED, "-include", "math.h", "-include",
                                                str(RUNTIME / "eigenvalues.c"), f"-DJACGEN_G6_IMAGINARY={imaginary}",
                                                f"-DJACGEN_G6_LANES={general6r.NEWTON_ROWS}"],
                  tmp_path)


def test_native_kernels_header(tmp_path):
    compile_alone(c_compiler(), "native_kernels.h", ["-x", "c"], tmp_path)


def test_native_module(tmp_path):
    (tmp_path / "stub.h").write_text(NATIVE_STUB)
    includes = ["-isystem", sysconfig.get_paths()["include"], "-isystem", numpy.get_include()]  # their own warnings are not ours
    sizes = ["-DJACGEN_OPERANDS=2", "-DJACGEN_FLAGS=1", "-DJACGEN_DOF=6", "-DJACGEN_WORK_PER_THREAD=100000.0",
             "-DJACGEN_FUNCTIONS=1"]
    compile_alone(c_compiler(), "native_module.h", ["-x", "c", *includes, "-DJACGEN_OPERANDS=2"], tmp_path, C11)
    compile_alone(c_compiler(), "native_module.c", [*INCLUDED, *includes, *sizes, "-include", str(RUNTIME / "native_module.h"),
                                                    "-include", str(RUNTIME / "native_kernels.h"),
                                                    "-include", str(tmp_path / "stub.h")], tmp_path, C11)


@pytest.mark.skipif(shutil.which("arm-none-eabi-gcc") is None, reason="arm-none-eabi-gcc not installed")
def test_target_runtime(tmp_path):
    from jacgen.checking.cortex_m4f import CPU_FLAGS
    compile_alone("arm-none-eabi-gcc", "target_runtime.c", [*CPU_FLAGS, "-O2"], tmp_path)
