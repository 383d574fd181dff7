"""The generated general 6R solver (class general_6r) of the shipped arms without a special
class (Jaco, Mico, Manocha-Canny, a calibrated UR5): batched numpy `ik_branches` and C `ik`
(double and float) by round trip on the numpy reference, the generating configuration among
the solutions, every solution of a multi-start search among them, degenerate targets giving
no solution rather than a wrong one; and the class and report of such an arm."""

import ctypes
import math

import numpy as np
import pytest

from jacgen.solvers import general6r
from jacgen.checking import reference
from jacgen.checking.c_library import compile_shared
from jacgen.solvers.model import Model
from jacgen.inputs.robot_file import parse_robot

from conftest import GENERATED, generated_module, robot
from support.general6r_arms import multi_start
from support.generated import c_ik
from support.ik import wrapped

ARMS = ["jaco", "mico", "manocha_canny", "ur5_calibrated"]


def _poses(arm, count: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    q = np.random.default_rng(seed).uniform(-math.pi, math.pi, (count, 6))
    return q, reference.fk(arm, q)


@pytest.mark.parametrize("name", ARMS)
def test_numpy_ik_branches_give_back_every_configuration(name):
    arm, module = robot(name), generated_module(name)
    q, poses = _poses(arm, 150, 1)
    solutions, valid, _ = module.ik_branches(poses)
    assert solutions.shape == (150, 16, 6) and valid.shape == (150, 16)
    for k in range(len(q)):
        found = solutions[k][valid[k]]
        assert valid[k].sum() % 2 == 0 and np.all(np.isfinite(found))
        assert max(np.abs(reference.fk(arm, s) - poses[k]).max() for s in found) < 1e-9
        assert min(np.abs(wrapped(s - q[k])).max() for s in found) < 1e-8
        assert not valid[k][int(valid[k].sum()):].any()  # the valid rows first
    if name == "manocha_canny":
        assert valid.sum(1).max() == 16


@pytest.mark.parametrize("name", ARMS)
def test_numpy_ik_finds_every_solution_of_a_multi_start_search(name):
    arm, module = robot(name), generated_module(name)
    rng = np.random.default_rng(8)
    for q in rng.uniform(-math.pi, math.pi, (2, 6)):
        pose = reference.fk(arm, q)
        ours, theirs = module.ik(pose, limits=False), multi_start(arm, pose, 100, rng)
        assert len(theirs) >= 2 and len(ours) >= len(theirs)
        for t in theirs:
            assert min(np.abs(wrapped(t - o)).max() for o in ours) < 1e-6


@pytest.fixture(scope="module", params=["double", "float"])
def c_solver(request, generated):
    """The C ik of each arm, in double from generated/, in float (ik and its callees) generated here."""
    if request.param == "double":
        return "double", {name: generated.committed(name).library("ik") for name in ARMS}
    return "float", {name: generated(robot(name), ("c",), "float", ("ik",)).library("ik") for name in ARMS}


@pytest.mark.parametrize("name", ARMS)
def test_c_ik_gives_back_every_configuration(c_solver, name):
    real, libraries = c_solver
    arm, library = robot(name), libraries[name]
    tolerance = 1e-9 if real == "double" else 2e-3
    q, poses = _poses(arm, 60, 2)
    python = generated_module(name)
    for k in range(len(q)):
        found = c_ik(library, poses[k])
        assert len(found) and max(np.abs(reference.fk(arm, s) - poses[k]).max() for s in found) < tolerance
        if real == "double":
            assert min(np.abs(wrapped(s - q[k])).max() for s in found) < 1e-8
            assert len(found) == len(python.ik(poses[k]))


def test_targets_out_of_reach_or_not_finite_give_no_solution():
    module = generated_module("jaco")
    far = np.eye(4)
    far[:3, 3] = (5.0, 0.0, 0.0)  # the Jaco reaches about 1 m
    bad = np.full((4, 4), np.nan)
    solutions, valid, _ = module.ik_branches(np.array([far, bad]))
    assert not valid.any() and np.all(np.isfinite(solutions))


def test_the_class_and_the_report_name_the_general_solver():
    model = Model(robot("jaco"))
    assert model.structure.solver == "general_6r" and model.closed_form.info.max_solutions == 16
    report = (GENERATED / "jaco" / "jaco.md").read_text()
    assert "general 6R: 16 solutions at most" in report


# A calibrated 6R arm (../shared/tools/random_arm.py --seed 380175037) whose chosen split runs
# the loop backwards with the hidden angle shifted (no shipped arm does): building
# ik_general_start recursed forever (cos of an unevaluated -(g + c) under distribute(False)).
BACKWARDS_SHIFTED = """
name: arm_75037
convention: standard
angle_unit: rad
joints:
  - {type: revolute, a: -8.36e-05, alpha: 1.5702249, d: 0.6719973, offset: 0.0004128, limits: [-3.1, 3.1]}
  - {type: revolute, a: 0.4316648, alpha: 0.0019664, d: -7.75e-05, offset: -0.0005013, limits: [-3.1, 3.1]}
  - {type: revolute, a: 0.0202426, alpha: -1.5696174, d: 0.1500003, offset: -0.0007412, limits: [-3.1, 3.1]}
  - {type: revolute, a: 0.0001441, alpha: 1.5706244, d: 0.4316002, offset: 0.0002873, limits: [-3.1, 3.1]}
  - {type: revolute, a: -0.0001265, alpha: -1.5712539, d: -0.0001612, offset: -0.0003699, limits: [-3.1, 3.1]}
  - {type: revolute, a: 0.0001163, alpha: 0.0006432, d: -0.0001397, offset: -0.0006262, limits: [-3.1, 3.1]}
"""


def test_a_backwards_shifted_split_generates_and_solves(generated):
    """That arm's numpy ik_branches gives back every configuration, each solution reaching its
    pose (the reference's fk) to 1e-9."""
    arm = parse_robot(BACKWARDS_SHIFTED.encode(), "arm_75037.yaml")
    plan = Model(arm).closed_form.elimination
    assert plan.equations.split.backwards and plan.shift != 0
    module = generated(arm, ("python",), functions=("ik_branches",)).python
    q = np.random.default_rng(2).uniform(-3.1, 3.1, (60, 6))
    solutions, valid, _ = module.ik_branches(reference.fk(arm, q))
    for k in range(len(q)):
        found = solutions[k][valid[k]]
        assert max(np.abs(reference.fk(arm, s) - reference.fk(arm, q[k])).max() for s in found) < 1e-9
        assert min(np.abs(wrapped(s - q[k])).max() for s in found) < 1e-8


@pytest.mark.parametrize("real", ["double", "float"])
def test_the_working_memory_is_the_documented_size(real, generated, tmp_path):
    """struct NAME_ik_work, as the compiler lays it out, is the size the generated comment (and
    the contract) states."""
    folder = generated(robot("jaco"), ("c",), real, ("ik",)).folder / "jaco"
    probe = tmp_path / "probe.c"
    probe.write_text('#include "jaco.c"\nunsigned long jaco_work_size(void);\n'
                     "unsigned long jaco_work_size(void) { return sizeof(struct jaco_ik_work); }\n")
    library = ctypes.CDLL(str(compile_shared([probe], tmp_path / "probe.so", ("-O0", f"-I{folder}"))))
    library.jaco_work_size.restype = ctypes.c_ulong
    assert library.jaco_work_size() == general6r.work_bytes(real)
    assert f"{general6r.work_bytes(real)} bytes in this build" in (folder / "jaco.c").read_text()
