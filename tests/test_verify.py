"""`jacgen verify`: exit codes, the table, and that it notices a wrong result."""

import math

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.optimize import brentq

from jacgen.checking import reference, samples, verify
from jacgen.checking.dexterity_checks import characteristic_length
from jacgen.cli import main
from jacgen.checking.c_library import CompileError, compile_shared
from jacgen.checking.generated_code import HOST_BACKENDS, TARGET_BACKENDS
from jacgen.emission.generator import Generator, scalar
from jacgen.inputs.robot_file import load_robot

from conftest import robot as shipped_robot

FUNCTIONS = ("fk", "jacobian", "jacobian_tool", "task", "task_jacobian", "ik", "ik_branches", "ik_nearest")


def _verify(*arguments, **environment):
    return CliRunner().invoke(main, ["verify", *arguments], env=environment)


def _rows(output: str) -> dict[tuple[str, str], list[str]]:
    return {tuple(line.split()[:2]): line.split()[2:] for line in output.splitlines()[1:-1]}


def test_every_function_of_every_backend_is_within_tolerance():
    result = _verify("robots/planar_3r.yaml", "robots/scara.yaml", "--samples", "40")
    assert result.exit_code == 0, result.output
    assert result.output.splitlines()[0].split()[:6] == ["robot", "function", "python", "casadi", "c", "double"]
    rows = _rows(result.output)
    assert set(rows) >= {(robot, function) for robot in ("planar_3r", "scara") for function in FUNCTIONS}
    for (robot, function), cells in rows.items():
        if cells[:4] == ["-"] * 4:  # a function the reference does not have
            assert function not in FUNCTIONS and " ".join(cells[5:]) == "not compared: no reference"
            continue
        errors = [0.0 if cell == "-" else float(cell) for cell in cells[:4]]
        assert max(errors[:3]) <= 1e-9 and errors[3] <= float(cells[4])
    assert f"0 of {len(rows)} functions above tolerance" in result.output
    assert result.stderr == ""  # no progress when stderr is not a terminal


def test_a_wrong_result_fails(monkeypatch):
    correct = reference.jacobian_tool
    monkeypatch.setattr(reference, "jacobian_tool", lambda robot, q: correct(robot, q) + 1e-3)
    result = _verify("robots/planar_2r.yaml", "--samples", "5")
    assert result.exit_code == 1
    rows = _rows(result.output)
    assert rows[("planar_2r", "jacobian_tool")][:8] == ["1.0e-03", "FAIL"] * 4
    assert result.output.splitlines()[-1].endswith(f"; 1 of {len(rows)} functions above tolerance")


def test_the_summary_states_the_tolerances_of_the_builds_run():
    """The host's table: double and float; --target cortex-m4f's: the float build alone."""
    host = verify.Result("arm", "fk", dict.fromkeys(HOST_BACKENDS, 0.0), dict.fromkeys(HOST_BACKENDS, 1.0))
    target = verify.Result("arm", "fk", {TARGET_BACKENDS["cortex-m4f"]: 0.0}, {TARGET_BACKENDS["cortex-m4f"]: 1.0})
    assert verify.format_table([host]).splitlines()[-1] == (
        "tolerance x (1 + reach): double 1e-09, float 1e-04; 0 of 1 functions above tolerance")
    assert verify.format_table([target]).splitlines()[-1] == (
        "tolerance x (1 + reach): float 1e-04; 0 of 1 functions above tolerance")


def test_a_function_without_reference_fails_not_compared(monkeypatch):
    original = Generator.functions

    def functions(self):
        return original(self) + [self.function("tool_height", "z of the tool",
                                               scalar("h", self.chain.tool[2, 3]))]

    monkeypatch.setattr(Generator, "functions", functions)
    result = _verify("robots/scara.yaml", "--samples", "5")
    assert result.exit_code == 1, result.output
    cells = _rows(result.output)[("scara", "tool_height")]
    assert cells[:4] == ["-"] * 4 and " ".join(cells[5:]) == "not compared: no reference"
    assert result.output.splitlines()[-1].endswith("0 of %d functions above tolerance, 1 not compared"
                                                   % len(_rows(result.output)))


def test_a_function_verify_has_no_check_of_fails(monkeypatch):
    """ik_numeric_step (its arguments are neither q nor q, q_dot) without its check: a row that
    says so, and exit 1."""
    monkeypatch.setattr(verify, "_ik_numeric_step_result", lambda robot, backends, q, tolerances: verify.Result(
        robot.name, "fk", dict.fromkeys(backends.names), tolerances, "(a second row of fk in its place)"))
    result = _verify("robots/planar_2r.yaml", "--samples", "5")
    assert result.exit_code == 1, result.output
    cells = _rows(result.output)[("planar_2r", "ik_numeric_step")]
    assert cells[:4] == ["-"] * 4 and " ".join(cells[5:]).startswith("not compared: verify has no check of it")


def test_missing_compiler_and_compile_errors_exit_2():
    for compiler in ("no-such-cc", "false"):
        result = _verify("robots/planar_2r.yaml", "--samples", "2", CC=compiler)
        assert result.exit_code == 2
        assert len(result.stderr.splitlines()) == 1 and result.stderr.startswith("jacgen: error: ")
        assert "Traceback" not in result.output


def test_bad_input_exits_2(tmp_path):
    assert _verify("robots/does_not_exist.yaml").exit_code == 2
    assert _verify("robots/planar_2r.yaml", "--samples", "0").exit_code == 2


def test_singular_configurations_are_inside_the_limits():
    for name in ("puma560", "stanford", "planar_3r"):
        robot = shipped_robot(name)
        q = samples.singular_configurations(robot)
        bounds = np.array(robot.ranges)
        assert ((q >= bounds[:, 0]) & (q <= bounds[:, 1])).all()
        revolute = [joint.revolute for joint in robot.joints]
        zero = np.clip(np.where(revolute, 0.0, bounds.mean(axis=1)), bounds[:, 0], bounds[:, 1])
        assert (q == zero).all(axis=1).any()  # the stretched arm (all revolute joints at 0)
    assert len(samples.singular_configurations(shipped_robot("planar_3r"))) == 27 + 3  # 3^3 grid, 3 on sin(q2) = 0


def test_task_angles_compare_modulo_two_pi():
    robot = shipped_robot("puma560")
    function = next(f for f in Generator(robot).functions() if f.name == "task")
    q = np.array([[0.1, 0.2, -0.3, 0.4, 0.5, 0.6]])
    expected = reference.task(robot, q[0])[None]
    shifted = expected + np.array([0, 0, 0, 2 * math.pi, 0, -2 * math.pi])
    assert verify.compare(robot, function, shifted, expected, q) == (0.0, 0)
    broken = expected.copy()
    broken[0, 0] = math.nan
    assert verify.compare(robot, function, broken, expected, q)[0] == math.inf


@pytest.mark.parametrize("name, expected", [("planar_2r", 2.0), ("stanford", 0.412 + 0.154 + 0.0203 + 50 * 0.0254)])
def test_reach(name, expected):
    assert shipped_robot(name).reach == pytest.approx(expected)


def test_compile_error_is_one_line(tmp_path):
    source = tmp_path / "bad.c"
    source.write_text("int narrow(double x) { return x; }\n")
    with pytest.raises(CompileError, match=r"^gcc failed on bad\.c: .*bad\.c:1:\d+: error: conversion"):
        compile_shared([source], tmp_path / "bad.so")


# A random arm (shared/tools/random_arm.py --seed 683826518) whose one-row Js (task [y]) vanishes
# as a whole at q1 = -1.6335: there its float C's Js rounded to exactly 0 (kappa infinite) and the
# double reference's to 5.6e-17 (kappa 1), and 2e-3 rad away the float C's Js of 3.4e-5 was
# 2.5e-4 off, in velocity_ik's residual.
VANISHING_JS_ARM = """name: arm_26518
convention: modified
angle_unit: rad
joints:
  - {type: revolute, a: -0.2884, alpha: "0", d: -0.3442, offset: "0", limits: [-2.8539, 1.6102]}
  - {type: revolute, a: 0.0172, alpha: "pi", d: 0.0378, offset: "pi/2", limits: [-0.7887, 1.2682]}
base: {xyz: [0.1008, 0.1193, 0.1801], rpy: [-0.3921, -0.8725, 0.0926]}
tool: {xyz: [0, 0, 0.025], rpy: [0.4585, 0, 0]}
task: [y]
"""


def test_a_js_that_vanishes_as_a_whole_is_singular(tmp_path):
    """kappa is infinite where Js is zero to rounding, in every backend, and verify passes there."""
    path = tmp_path / "arm_26518.yaml"
    path.write_text(VANISHING_JS_ARM)
    result = _verify(str(path), "--samples", "200")
    assert result.exit_code == 0, result.output
    arm = load_robot(path)
    q1 = brentq(lambda angle: reference.singularity_jacobian(arm, np.array([angle, 0.4]))[0, 0], -1.7, -1.6)
    q = np.array([q1, 0.4])
    length = characteristic_length(arm)
    assert np.abs(reference.singularity_jacobian(arm, q)).max() < 1e-15
    assert reference.condition_number(arm, q, length, 1e-12) == math.inf
    assert reference.condition_number(arm, q + [2e-3, 0], length, 1e-6) == 1.0
