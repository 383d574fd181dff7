"""Dexterity (issue 48): Angeles' characteristic length L, the best condition number of Js
with its position rows divided by L, and where it is reached (`jacgen/model/dexterity.py`).

The planar 2R facts are derived by hand (below), the 6-axis arm's against the independent
reference (`jacgen.checking.reference`) and a dense random sample."""

import math
import re
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.optimize import minimize_scalar

from jacgen.checking import reference
from jacgen.cli import main
from jacgen.inputs.robot import EULER_ANGLES
from jacgen.inputs.robot_file import load_robot
from jacgen.model import dexterity as dexterity_module
from jacgen.model.dexterity import dexterity

from conftest import ROOT, robot


def write_arm(tmp_path, a1, a2, extra="", task="[x, y]", name="two"):
    """A planar 2R arm (axes along z, standard DH), links a1 and a2."""
    path = tmp_path / f"{name}.yaml"
    path.write_text(f"name: {name}\nconvention: standard\nparameters:\n  a1: {a1}\n  a2: {a2}\njoints:\n"
                    f"  - {{type: revolute, a: a1, alpha: 0, d: 0}}\n"
                    f"  - {{type: revolute, a: a2, alpha: 0, d: 0}}\ntask: {task}\n{extra}")
    return path


def reference_condition(arm, q, length):
    """sigma_max / sigma_min of the reference Js with its position rows divided by `length`."""
    js = reference.singularity_jacobian(arm, np.asarray(q, dtype=float))
    scale = np.array([1 / length if name not in EULER_ANGLES else 1.0 for name in arm.task])
    sigma = np.linalg.svd(js * scale[:, None], compute_uv=False)
    return sigma[..., 0] / sigma[..., -1]


def elbow(q2: float) -> float:
    """q2 folded into (-pi, pi]."""
    return math.remainder(q2, 2 * math.pi)


@pytest.mark.parametrize("a2", [1.0, 0.3])
def test_planar_2r_with_l1_sqrt2_l2_is_isotropic_at_135_degrees(tmp_path, a2):
    """J of the planar 2R in the frame of link 2 has the columns l1 (sin q2, cos q2) + l2 (0, 1)
    and l2 (0, 1): J^T J = [[l1^2 + l2^2 + 2 l1 l2 cos q2, l2^2 + l1 l2 cos q2], [., l2^2]], a
    multiple of the identity exactly when cos q2 = -l2 / l1 and l1^2 - l2^2 = l2^2: l1 = sqrt(2) l2
    and q2 = +-135 deg."""
    path = write_arm(tmp_path, f"sqrt(2) * {a2}", a2)
    found = dexterity(load_robot(path))
    assert found.isotropic and abs(found.best_condition - 1) < 1e-9
    assert abs(abs(elbow(found.configuration[1])) - 3 * math.pi / 4) < 1e-6
    assert not found.length_matters and found.length == 1.0 and not found.given
    shown = CliRunner().invoke(main, ["show", str(path)])
    assert shown.exit_code == 0
    assert re.search(r"isotropic: condition number 1 \(to 1e-09\) at q = \(\S+ deg, -?135 deg\)", shown.output)


def test_planar_2r_with_equal_links_is_not_isotropic(tmp_path):
    """With l1 = l2 = 1 and c, s the cosine and sine of q2 (J as above): trace(J^T J) = 3 + 2c
    and det(J^T J) = (2 + 2c) - (1 + c)^2 = s^2, so kappa + 1/kappa = (3 + 2c) / |s|, whose
    derivative in q2 vanishes at c = -2/3: there kappa + 1/kappa = sqrt(5), kappa the golden
    ratio (1 + sqrt(5)) / 2."""
    arm = load_robot(write_arm(tmp_path, 1, 1))
    found = dexterity(arm)
    assert not found.isotropic
    assert found.best_condition == pytest.approx((1 + math.sqrt(5)) / 2, rel=1e-9)
    assert abs(abs(elbow(found.configuration[1])) - math.acos(-2 / 3)) < 1e-6
    assert reference_condition(arm, found.configuration, found.length) == pytest.approx(found.best_condition, rel=1e-9)


@pytest.mark.parametrize("a1, a2", [(0.5, 0.8), (2.0, 0.5)])
def test_planar_2r_against_a_scan_of_the_reference(tmp_path, a1, a2):
    """Other link lengths: the best kappa and |q2| where the reference J is best conditioned
    (a dense scan of q2, refined by scipy), the same to 1e-9 and 1e-6 rad."""
    arm = load_robot(write_arm(tmp_path, a1, a2))
    def condition(q2):
        return float(reference_condition(arm, [0.3, q2], 1.0))

    grid = np.linspace(0.01, np.pi - 0.01, 721)
    start = grid[int(np.argmin([condition(x) for x in grid]))]
    best = minimize_scalar(condition, bounds=(start - 0.01, start + 0.01), method="bounded",
                           options={"xatol": 1e-10})
    found = dexterity(arm)
    assert found.best_condition == pytest.approx(best.fun, rel=1e-9) and not found.isotropic
    assert abs(abs(elbow(found.configuration[1])) - best.x) < 1e-6


def test_an_arm_that_is_rank_deficient_everywhere(tmp_path):
    """a2 = 0: both columns of the position Jacobian are parallel (the tool is on joint 2's axis)."""
    arm = load_robot(write_arm(tmp_path, 1, 0))
    found = dexterity(arm)
    assert found.best_condition == math.inf and not found.isotropic and found.length == 1.0
    shown = CliRunner().invoke(main, ["show", str(arm.source)])
    assert "best condition number: infinite" in shown.output


def test_the_same_answer_twice():
    arm = robot("puma560")
    assert dexterity(arm) == dexterity(arm)


def test_a_given_length_is_used_as_it_is(tmp_path):
    """A mixed task (x, y, yaw): the file's L is kept, and the best kappa is the one at that L,
    no better than at the computed L, which minimises it over L too."""
    computed = dexterity(load_robot(write_arm(tmp_path, 1, 0.5, task="[x, y, yaw]")))
    arm = load_robot(write_arm(tmp_path, 1, 0.5, "characteristic_length: a1 / 4\n", "[x, y, yaw]", "given"))
    found = dexterity(arm)
    assert found.length == 0.25 and found.given and found.length_matters
    assert found.best_condition >= computed.best_condition * (1 - 1e-9)
    assert reference_condition(arm, found.configuration, 0.25) == pytest.approx(found.best_condition, rel=1e-9)
    written = CliRunner().invoke(main, ["generate", str(arm.source), "-o", str(tmp_path / "out"), "--lang", "c,python"])
    assert written.exit_code == 0, written.output
    assert "#define GIVEN_CHARACTERISTIC_LENGTH 0.25\n" in (tmp_path / "out/given/given.h").read_text()
    assert "\nCHARACTERISTIC_LENGTH = 0.25\n" in (tmp_path / "out/given/given.py").read_text()


@pytest.mark.parametrize("value, message", [
    ("0", "expected a positive length, got '0'"),
    ("-0.5", "expected a positive length, got '-0.5'"),
    ("a1 - a1", "expected a positive length, got 'a1 - a1'"),
    (".inf", "expected a finite number, got .inf"),
    (".nan", "expected a finite number, got .nan"),
    ("k", "may not hold a symbolic parameter (it is a constant of the generated code), got 'k'"),
    ("2 * k", "may not hold a symbolic parameter (it is a constant of the generated code), got '2 * k'"),
    ("[1]", "expected a number or expression, got a list"),
])
@pytest.mark.parametrize("command", ["validate", "generate"])
def test_a_bad_length_is_refused_where_it_is_written(tmp_path, value, message, command):
    path = write_arm(tmp_path, 1, 1, f"characteristic_length: {value}\n")
    path.write_text(path.read_text().replace("parameters:\n", "parameters:\n  k: {value: 0.5, symbolic: true}\n"))
    line, column = path.read_text().count("\n"), len("characteristic_length: ") + 1  # the value, on the last line
    arguments = [command, str(path)] + ["-o", str(tmp_path / "out")] * (command == "generate")
    result = CliRunner().invoke(main, arguments)
    assert result.exit_code == 2
    assert result.stderr == f"jacgen: error: {path}:{line}:{column}: characteristic_length: {message}\n"
    assert not (tmp_path / "out").exists()


def test_euler_rate_rows_against_the_reference():
    """A task with some but not all angles: Js is the task Jacobian (Euler-angle rates)."""
    arm = robot("ur5")
    for task in (("x", "y", "z", "roll", "pitch"), ("x", "yaw"), ("pitch",)):
        partial = replace(arm, task=task)
        q = np.random.default_rng(3).uniform(-np.pi, np.pi, (20, arm.dof))
        expected = np.stack([reference.singularity_jacobian(partial, x) for x in q])
        assert np.allclose(dexterity_module.singularity_jacobian(partial, q), expected, atol=1e-8)


@pytest.mark.parametrize("name", ["ur5", "puma560"])
def test_a_six_axis_arm_where_the_length_matters(name):
    """The reported kappa is the reference's at the reported q and L; no configuration of a
    dense random sample near it (q and L perturbed) does better by more than 1e-3 (the search is
    bounded, and its least kappa sits where two singular values meet: see model/dexterity.py),
    and none of a uniform sample does better at all."""
    arm = robot(name)
    found = dexterity(arm)
    assert found.length_matters and not found.given and not found.isotropic
    low, high = np.array(arm.ranges).T
    q = np.array(found.configuration)
    assert np.all((low <= q) & (q <= high))
    assert reference_condition(arm, q, found.length) == pytest.approx(found.best_condition, rel=1e-9)
    rng = np.random.default_rng(48)
    for spread in (1e-1, 1e-2, 1e-3, 1e-4):
        near = np.clip(q + rng.normal(0, spread, (400, arm.dof)), low, high)
        lengths = found.length * np.exp(rng.normal(0, spread, 400))
        kappa = [reference_condition(arm, x, length) for x, length in zip(near, lengths)]
        assert min(kappa) >= found.best_condition * (1 - 1e-3)
    uniform = rng.uniform(low, high, (5000, arm.dof))
    assert reference_condition(arm, uniform, found.length).min() >= found.best_condition


def test_shipped_arms_name_the_constant():
    """Every shipped arm's generated header defines the constant its report gives."""
    for header in sorted((ROOT / "generated").glob("*/*.h")):
        report = header.with_suffix(".md")
        if not report.exists():
            continue
        macro = re.search(r"#define \w+_CHARACTERISTIC_LENGTH (\S+)\n", header.read_text())
        assert macro and f"characteristic length L = {macro.group(1)} " in report.read_text()
