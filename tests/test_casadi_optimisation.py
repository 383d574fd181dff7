"""The optimisation user's path: jacgen's CasADi functions inside ipopt problems
(examples/casadi_opti.py) converge to what the reference says; CasADi's own automatic
derivative of `fk` equals jacgen's symbolic `jacobian` on every shipped robot; and CasADi's
C code generation of a jacgen function compiles and computes what jacgen's C computes."""

import subprocess
from pathlib import Path

import casadi
import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.checking.c_library import CLibrary, c_compiler, compile_shared
from jacgen.emission.generator import Generator
from jacgen.building import import_module
from jacgen.inputs.robot_file import load_robot

ROOT = Path(__file__).resolve().parent.parent
SHIPPED = sorted(path.stem for path in (ROOT / "robots").glob("*.yaml"))


@pytest.fixture(scope="module")
def example():
    return import_module(ROOT / "examples" / "casadi_opti.py", "casadi_opti")


@pytest.fixture(scope="module")
def ur5(example):
    return example.load("ur5"), load_robot(ROOT / "robots" / "ur5.yaml")


def test_least_squares_ik_reaches_the_pose(example, ur5):
    module, robot = ur5
    q_goal = np.array([0.4, -1.1, 1.3, -0.9, -1.4, 0.3])
    target = reference.fk(robot, q_goal)
    q, stats = example.least_squares_ik(module, target, reference.fk(robot, q_goal + 0.05), q_goal + 0.2)
    assert stats["success"]
    assert np.abs(reference.fk(robot, q) - target).max() < 1e-10


def test_trajectory_reaches_the_pose_within_the_speed_bound(example, ur5):
    module, robot = ur5
    q_start = np.array([0.0, -1.5, 1.5, -1.5, -1.5, 0.0])
    target = reference.fk(robot, np.array([0.4, -1.1, 1.3, -0.9, -1.4, 0.3]))
    path, stats = example.trajectory(module, q_start, target, knots=20, duration=3.0, speed=0.1)
    assert stats["success"]
    assert np.abs(path[:, 0] - q_start).max() < 1e-12
    assert np.abs(reference.fk(robot, path[:, -1]) - target).max() < 1e-9
    dt = 3.0 / 19
    speeds = [np.linalg.norm(reference.jacobian(robot, path[:, k])[:3] @ (path[:, k + 1] - path[:, k])) / dt
              for k in range(19)]
    assert max(speeds) <= 0.1 + 1e-6


def test_most_manipulable_beats_every_sample(example, ur5):
    """Within the bounds, no random configuration is more manipulable than ipopt's answer
    (manipulability |det J| from the reference)."""
    module, robot = ur5
    q_start = np.array([0.0, -1.5, 1.5, -1.5, -1.5, 0.0])
    q, stats = example.most_manipulable(module, q_start - 0.5, q_start + 0.5, q_start)
    assert stats["success"]
    assert np.all(q >= q_start - 0.5 - 1e-7) and np.all(q <= q_start + 0.5 + 1e-7)  # ipopt relaxes bounds by 1e-8
    samples = np.random.default_rng(0).uniform(q_start - 0.5, q_start + 0.5, (2000, 6))
    best = max(abs(np.linalg.det(reference.jacobian(robot, sample))) for sample in samples)
    assert abs(np.linalg.det(reference.jacobian(robot, q))) >= best - 1e-12


def test_the_examples_run_in_under_a_second_each(example, capsys):
    example.main()
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 3 and all("Solve_Succeeded" in line for line in lines)
    assert all(int(line.split(" in ")[1].split(" ms")[0]) < 1000 for line in lines), lines


@pytest.mark.parametrize("name", SHIPPED)
def test_casadi_ad_of_fk_equals_jacobian(name):
    """casadi.jacobian of fk's position, and the angular velocity from dR/dq_k R^T, equal the
    generated `jacobian` (6 x n) at random configurations: another AD engine's derivative."""
    module = import_module(ROOT / "generated" / name / f"{name}_casadi.py", f"_ad_{name}")
    robot = load_robot(ROOT / "robots" / f"{name}.yaml")
    q = casadi.SX.sym("q", robot.dof)
    T = module.fk(q)
    rotation = T[:3, :3]
    d_rotation = casadi.jacobian(casadi.vec(rotation), q)  # column k: vec(dR/dq_k), column-major
    angular = []
    for k in range(robot.dof):
        skew = casadi.reshape(d_rotation[:, k], 3, 3) @ rotation.T
        angular.append(casadi.vertcat(skew[2, 1], skew[0, 2], skew[1, 0]))
    derived = casadi.Function("derived", [q], [casadi.vertcat(casadi.jacobian(T[:3, 3], q), casadi.horzcat(*angular))])
    for sample in np.random.default_rng(1).uniform(-np.pi, np.pi, (20, robot.dof)):
        expected = np.asarray(module.jacobian(sample))
        assert np.abs(np.asarray(derived(sample)) - expected).max() <= 1e-12 * (1 + robot.reach), name


def test_casadi_generated_c_equals_jacgens_c(tmp_path, ur5, monkeypatch):
    """casadi.Function.generate of jacgen's fk_jacobian compiles, and the library computes what
    jacgen's own C does (both built -O2 here)."""
    module, robot = ur5
    source = tmp_path / "casadi_fk_jacobian.c"
    monkeypatch.chdir(tmp_path)  # Function.generate writes where it runs
    module.fk_jacobian.generate(source.name)
    library = tmp_path / "casadi_fk_jacobian.so"
    compiled = subprocess.run([c_compiler(), "-O2", "-shared", "-fPIC", "-o", str(library), str(source), "-lm"],
                              capture_output=True, text=True)
    assert compiled.returncode == 0, compiled.stderr
    theirs = casadi.external("fk_jacobian", str(library))
    ours = CLibrary(compile_shared([ROOT / "generated" / "ur5" / "ur5.c"], tmp_path / "ur5.so", ("-O2",)), robot,
                    Generator(robot, selection=["fk_jacobian"]).functions(), "double")
    q = np.random.default_rng(2).uniform(-np.pi, np.pi, (50, 6))
    expected = ours.evaluate("fk_jacobian", q)
    found = np.array([np.hstack([np.asarray(part).ravel() for part in theirs(row)]) for row in q])
    assert np.abs(found - expected).max() < 1e-14
