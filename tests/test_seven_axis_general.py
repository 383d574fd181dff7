"""7-axis arms without a special class (contract §2): the general 6R solver with joint 7 free,
on the shipped Sawyer (offsets at every joint, from rtb's public DH table) and calibrated Panda
(with the fast path from the nominal Panda), and both with joint 1 free. Every random
configuration is recovered for its free joint's value, every solution reaches its pose by the
reference's fk, and no solution of a multi-start numeric search on the six other joints is
missing; numpy and C."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import sympy

from jacgen.inputs import numeric_chain
from jacgen.checking import reference
from jacgen.inputs.values import Value
from jacgen.solvers.model import Model
from jacgen.inputs.robot import Pose
from jacgen.inputs.robot_file import parse_robot

from conftest import generated_module, robot
from support.general6r_arms import multi_start
from support.ik import wrapped

ARMS = ("sawyer", "panda_calibrated")
FREE = 6  # joint 7


def _configurations(count: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-math.pi, math.pi, (count, 7))


def _held(arm, q_free: float):
    """The six-joint arm of joints 1-6 with joint 7 held at q_free (its row moved into the tool),
    for the independent multi-start search."""
    tool = numeric_chain._link(arm, arm.joints[FREE], np.array(q_free)) @ numeric_chain.fixed_pose(arm.tool)
    roll, yaw = math.atan2(tool[2, 1], tool[2, 2]), math.atan2(tool[1, 0], tool[0, 0])
    pitch = math.atan2(-tool[2, 0], math.hypot(tool[0, 0], tool[1, 0]))
    exact = tuple(Value(sympy.Float(float(v), 30), float(v)) for v in (*tool[:3, 3], roll, pitch, yaw))
    return dataclasses.replace(arm, joints=arm.joints[:FREE], tool=Pose(exact[:3], exact[3:]), free_joint=None)


@pytest.mark.parametrize("name", ARMS)
def test_the_class_is_the_general_solver_with_joint_7_free(name):
    form = Model(robot(name)).closed_form
    assert form.solver == "general_6r" and form.free == FREE and form.joints == (0, 1, 2, 3, 4, 5)
    assert (form.fast_path is not None) == (name == "panda_calibrated")


@pytest.mark.parametrize("name", ARMS)
def test_numpy_recovers_every_configuration(name):
    arm, module = robot(name), generated_module(name)
    q = _configurations(2000, 1)
    poses = reference.fk(arm, q)
    solutions, valid, _ = module.ik_branches(poses, q[:, FREE])
    assert solutions.shape == (2000, 16, 7)
    recovered = ((np.abs(wrapped(solutions - q[:, None])).max(axis=-1) < 1e-8) & valid).any(axis=-1)
    assert recovered.all(), np.nonzero(~recovered)[0][:5]
    assert np.all(solutions[..., FREE][valid] == np.repeat(q[:, FREE, None], 16, 1)[valid])
    reached = np.abs(reference.fk(arm, solutions) - poses[:, None]).max(axis=(-2, -1))
    assert reached[valid].max() < 1e-9 * (1 + arm.reach)


@pytest.mark.parametrize("name", ARMS)
def test_c_recovers_every_configuration(name, generated):
    arm = robot(name)
    library = generated.committed(name).library("ik_branches")
    q = _configurations(300, 2)
    poses = reference.fk(arm, q)
    for k in range(len(q)):
        branches, valid, _ = library.call("ik_branches", poses[k], q[k, FREE])
        found = branches[valid.astype(bool)]
        assert min(np.abs(wrapped(s - q[k])).max() for s in found) < 1e-8
        assert max(np.abs(reference.fk(arm, s) - poses[k]).max() for s in found) < 1e-9 * (1 + arm.reach)


@pytest.mark.parametrize("name", ARMS)
def test_no_solution_of_a_multi_start_search_is_missing(name):
    arm, module = robot(name), generated_module(name)
    rng = np.random.default_rng(8)
    for q in _configurations(3, 3):
        pose = reference.fk(arm, q)
        theirs = multi_start(_held(arm, q[FREE]), pose, 100, rng)
        ours = module.ik(pose, q[FREE], limits=False)
        assert len(theirs) >= 2 and len(ours) >= len(theirs)
        for t in theirs:
            assert min(np.abs(wrapped(t - o[:FREE])).max() for o in ours) < 1e-6


@pytest.mark.parametrize("name", ARMS)  # standard and modified DH
def test_joint_1_free_recovers_every_configuration(name, generated):
    """With `ik: {free_joint: 1}` the free joint's row is part of the chain's head instead of
    its tail: 500 random configurations, numpy, all recovered for their q1."""
    text = Path(robot(name).source).read_text().replace("ik: {free_joint: 7}\n", "")
    arm = parse_robot((text + "ik: {free_joint: 1}\n").encode(), f"{name}.yaml")
    assert Model(arm).closed_form.free == 0
    module = generated(arm, functions=("ik_branches",)).python
    q = _configurations(500, 4)
    poses = reference.fk(arm, q)
    solutions, valid, _ = module.ik_branches(poses, q[:, 0])
    recovered = ((np.abs(wrapped(solutions - q[:, None])).max(axis=-1) < 1e-8) & valid).any(axis=-1)
    assert recovered.all()
    assert np.abs(reference.fk(arm, solutions) - poses[:, None]).max(axis=(-2, -1))[valid].max() < 1e-9 * (1 + arm.reach)
