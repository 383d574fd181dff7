"""The C99 backend: contract §3 signatures, a header C++ can include, and the C of test robots
with runtime parameters, a function that reads no joint, a scalar result and a function the contract
does not name, against jacgen.reference. The shipped robots' C is verified, and compiled
warning-free for the host and a Cortex-M4F, by tests/test_shipped_robots.py.
"""

import re
import shutil
import subprocess

import numpy as np
import pytest
import sympy
from numpy.testing import assert_allclose

from jacgen.checking import reference
from jacgen.checking.c_library import CLibrary, compile_shared
from jacgen.emission.generator import Generator, matrix, scalar
from jacgen.emission.backends.c import CPrinter
from jacgen.files import write_files
from jacgen.emission.render import render_robot
from jacgen.inputs.robot_file import load_robot

from conftest import ROOT, random_configurations
from support.graph_sympy import printed
from support.robot_texts import PARAMETRIC

# Cartesian gantry: its Jacobians read no joint (q must be marked unused).
GANTRY = """
name: gantry
convention: standard
angle_unit: deg
joints:
  - {type: prismatic, a: 0, alpha: -90, theta: 0, offset: 0, limits: [0, 1]}
  - {type: prismatic, a: 0, alpha: 0, theta: -90, offset: 0, limits: [0, 1]}
task: [x, y, z]
"""


def _write_robot(folder, text, **replace):
    name = re.search(r"name: (\w+)", text).group(1)
    for old, new in replace.items():
        text = text.replace(old, new)
    path = folder / f"{name}{len(replace)}.yaml"
    path.write_text(text)
    return load_robot(path)


def _run(command, cwd=None):
    result = subprocess.run([str(part) for part in command], capture_output=True, text=True, cwd=cwd)
    assert result.returncode == 0 and not result.stderr, result.stderr
    return result.stdout


def test_prototypes_are_those_of_spec():
    header = render_robot(load_robot(ROOT / "robots" / "puma560.yaml"), ("c",))["puma560/puma560.h"]
    spec = """
        void      NAME_fk(const NAME_real q[NAME_DOF], NAME_real T[16]);
        void      NAME_jacobian(const NAME_real q[NAME_DOF], NAME_real J[6 * NAME_DOF]);
        void      NAME_jacobian_tool(const NAME_real q[NAME_DOF], NAME_real J[6 * NAME_DOF]);
        void      NAME_task(const NAME_real q[NAME_DOF], NAME_real mu[NAME_TASK_DIM]);
        void      NAME_task_jacobian(const NAME_real q[NAME_DOF], NAME_real J[NAME_TASK_DIM * NAME_DOF]);
    """
    for line in spec.strip().splitlines():
        prototype = re.sub(r"\s+", " ", line.strip()).replace("NAME_real", "puma560_real").replace("NAME", "PUMA560")
        prototype = prototype.replace("PUMA560_", "puma560_", 1)
        assert prototype in header
    for line in ("typedef double puma560_real;", "#define PUMA560_DOF 6", "#define PUMA560_TASK_DIM 6",
                 "#ifndef PUMA560_H", 'extern "C" {'):
        assert line in header


@pytest.mark.skipif(shutil.which("g++") is None, reason="g++ not installed")
def test_header_is_usable_from_cpp(tmp_path):
    write_files(render_robot(load_robot(ROOT / "robots" / "ur5.yaml"), ("c",)), tmp_path)
    source = tmp_path / "use.cpp"
    source.write_text('#include "ur5.h"\nvoid use(const ur5_real *q, ur5_real *T) { ur5_fk(q, T); }\n')
    _run(["g++", "-std=c++11", "-Wall", "-Wextra", "-Werror", "-fsyntax-only", f"-I{tmp_path / 'ur5'}", source])


@pytest.mark.parametrize("real", ["double", "float"])
def test_runtime_parameters(tmp_path, real):
    robot = _write_robot(tmp_path, PARAMETRIC)
    files = render_robot(robot, ("c",), real)
    header = files["lifted/lifted.h"]
    assert "typedef struct {\n    lifted_real height; /* nominal 0.25 */\n    lifted_real shift; /* nominal -0.1 */\n} lifted_params;" in header
    functions = Generator(robot).functions()
    for function in functions:
        prototype = re.search(rf"^(?:void|int|lifted_real) lifted_{function.name}\(.*\);$", header, flags=re.MULTILINE)
        assert prototype.group().endswith(", const lifted_params *p);")
    write_files(files, tmp_path)
    library = CLibrary(compile_shared([tmp_path / "lifted" / "lifted.c"], tmp_path / "lifted.so"), robot,
                       functions, real)
    moved = _write_robot(tmp_path, PARAMETRIC, **{"height: {value: 0.25, symbolic: true}": "height: 0.75",
                                                  "shift: {value: -0.1, symbolic: true}": "shift: 0.5"})
    q = random_configurations(robot, 20, seed=3)
    tolerance = 1e-12 if real == "double" else 1e-5
    for name in ("fk", "jacobian", "task"):
        expected = np.array([getattr(reference, name)(robot, row).ravel() for row in q])
        assert_allclose(library.evaluate(name, q), expected, atol=tolerance)
        expected = np.array([getattr(reference, name)(moved, row).ravel() for row in q])
        assert_allclose(library.evaluate(name, q, parameters={"height": 0.75, "shift": 0.5}), expected, atol=tolerance)


def test_functions_beyond_spec_render_generically(tmp_path, monkeypatch):
    """A scalar function returns NAME_real; an output the contract does not name gets its literal size."""
    def functions(self):
        pose = self.chain.tool
        position = pose[:3, 3]
        return original(self) + [
            self.function("reach_squared", "squared distance of the tool from the origin",
                          scalar("r", position.dot(position))),
            self.function("tool_position", "tool origin", matrix("v", position)),
        ]

    original = Generator.functions
    monkeypatch.setattr(Generator, "functions", functions)
    robot = _write_robot(tmp_path, GANTRY)
    files = render_robot(robot, ("c",))
    header = files["gantry/gantry.h"]
    assert "gantry_real gantry_reach_squared(const gantry_real q[GANTRY_DOF]);" in header
    assert "void gantry_tool_position(const gantry_real q[GANTRY_DOF], gantry_real v[3]);" in header
    assert "(void)q;" in files["gantry/gantry.c"]
    write_files(files, tmp_path)
    library = CLibrary(compile_shared([tmp_path / "gantry" / "gantry.c"], tmp_path / "gantry.so"), robot,
                       Generator(robot).functions(), "double")
    q = random_configurations(robot, 10, seed=4)
    positions = reference.fk(robot, q)[:, :3, 3]
    assert_allclose(library.evaluate("tool_position", q), positions, atol=1e-12)
    assert_allclose(library.evaluate("reach_squared", q)[:, 0], (positions**2).sum(axis=1), atol=1e-12)
    assert_allclose(library.evaluate("jacobian", q), reference.jacobian(robot, q).reshape(len(q), -1),
                    atol=1e-12)


def test_printer():
    x, y = sympy.symbols("x y", real=True)
    double, single = CPrinter("double"), CPrinter("float")
    assert printed(double, x**2 + y / x**3) == "(x*x) + y/(x*x*x)"  # terms in sympy's stored order
    assert printed(double, 0.4318 * sympy.cos(x) / sympy.sqrt(y)) == "0.4318*cos(x)/sqrt(y)"
    assert printed(double, 1 / sympy.sqrt(x + y)) == "1.0/sqrt(x + y)"
    assert printed(single, 0.4318 * sympy.atan2(x, sympy.sqrt(y)) + 1 / x) == "1.0F/x + 0.4318F*atan2f(x, sqrtf(y))"
    assert printed(double, x ** sympy.Rational(-3, 2) + y ** sympy.Rational(5, 2)) == \
        "1.0/(sqrt(x)*x) + (sqrt(y)*y*y)"  # no pow(): half-integer powers through sqrt
    with pytest.raises(Exception, match="[Uu]nsupported|not supported"):
        printed(double, sympy.Function("mystery")(x))
    with pytest.raises(ValueError):
        CPrinter("long double")


def test_no_posix_math_macros():
    """C99 has no M_PI or M_SQRT2 (they are POSIX): constants sympy rebuilds after CSE, like
    sqrt(2) out of sqrt(2*x**2), print as literals."""
    x = sympy.Symbol("x", real=True)
    assert printed(CPrinter("double"), sympy.sqrt(2 * x**2)) == "1.4142135623730951*fabs(x)"
    assert printed(CPrinter("float"), sympy.pi * x) == "3.1415927F*x"
    for path in sorted((ROOT / "generated").glob("*/*.[ch]")):
        assert not re.search(r"\bM_[A-Z0-9_]+\b", path.read_text()), path
