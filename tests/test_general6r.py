"""The general 6R solver's per-robot part (`jacgen.general6r`): Raghavan & Roth's 14
equations hold, for every split of the loop, at the configurations of random arms (poses from
the numpy reference); the split and shift chosen by conditioning, solved as the textbook does
(24 x 24 companion eigenproblem, back-substitution, two Newton steps on the reference), recover
the configuration of every pose of the Jaco, the Manocha-Canny arm, a calibrated UR5 and random
arms, with up to 16 solutions, and find every solution a multi-start search finds."""

import math

import numpy as np
import pytest
import roboticstoolbox as rtb

from jacgen.solvers import general6r, general6r_plan
from jacgen.checking import reference

from support.general6r_arms import ARMS, JACO, Solver, multi_start, numeric, robot_of, solver_of
from support.ik import wrapped
from support.random_arms import random_arm_text


def _six_revolute_arms():
    seeds = [s for s in range(200) if "symbolic" not in random_arm_text(s, dof=6, revolute_only=True)][:4]
    return [pytest.param(random_arm_text(s, dof=6, revolute_only=True, radians=s % 2 == 1), id=f"seed{s}")
            for s in seeds]


@pytest.mark.parametrize("text", _six_revolute_arms())
def test_fourteen_equations_hold_for_every_split(text):
    robot = robot_of(text)
    head, links, tail = general6r.chain_form(robot)
    head_inverse, tail_inverse = np.linalg.inv(numeric(head)), np.linalg.inv(numeric(tail))
    theta = np.random.default_rng(7).uniform(-math.pi, math.pi, (4, 6))
    offsets = np.array([joint.offset.approx for joint in robot.joints])
    poses = [head_inverse @ reference.fk(robot, t - offsets) @ tail_inverse for t in theta]
    for split in general6r.SPLITS:
        equations = general6r.equations(links, split)
        for t, n in zip(theta, poses):
            v = np.linalg.inv(n) if split.target_inverted else n
            p0, ps, pc, q = equations.evaluated(np.concatenate([v[:3, :3].ravel(), v[:3, 3]]))
            loop = [(-1 if split.backwards else 1) * t[split.joint(k)] for k in range(6)]
            (a, b, c), (g, h) = split.triple, split.pair
            products = lambda x, y: np.array([math.sin(loop[x]) * math.sin(loop[y]), math.sin(loop[x]) * math.cos(loop[y]),  # noqa: E731
                                             math.cos(loop[x]) * math.sin(loop[y]), math.cos(loop[x]) * math.cos(loop[y]),
                                             math.sin(loop[x]), math.cos(loop[x]), math.sin(loop[y]), math.cos(loop[y]), 1])
            residual = (p0 + math.sin(loop[a]) * ps + math.cos(loop[a]) * pc) @ products(b, c) - q @ products(g, h)
            assert np.abs(residual).max() < 1e-12 * (1 + np.abs(q).max() + np.abs(p0).max()), split


def test_both_conventions_are_covered():
    texts = [p.values[0] for p in _six_revolute_arms()]
    assert any("convention: standard" in t for t in texts) and any("convention: modified" in t for t in texts)


def test_jaco_file_is_the_toolbox_jaco():
    robot, jaco = robot_of(JACO), rtb.models.DH.Jaco()
    for q in np.random.default_rng(1).uniform(-math.pi, math.pi, (20, 6)):
        assert np.abs(reference.fk(robot, q) - jaco.fkine(q).A).max() < 1e-14


def test_the_textbook_split_is_singular_for_the_jaco_and_the_chosen_one_is_not():
    """Cut after q6 with tan(q3/2) hidden (Raghavan & Roth's), the Jaco's matrix polynomial is
    singular for every x; the split chosen is well conditioned."""
    robot = robot_of(JACO)
    assert general6r_plan.elimination(robot).condition < 1e4
    head, links, tail = general6r.chain_form(robot)
    textbook = general6r.equations(links, general6r.Split(backwards=False, free=5))
    theta = np.random.default_rng(2).uniform(-math.pi, math.pi, (1, 6))
    n = general6r.chain_product(links, theta)[0]
    p0, ps, pc, q = textbook.evaluated(np.concatenate([n[:3, :3].ravel(), n[:3, 3]]))
    left_null = np.linalg.svd(q[:, :8])[0][:, 8:].T
    x = 0.37
    s = left_null @ (p0 + 2 * x / (1 + x * x) * ps + (1 - x * x) / (1 + x * x) * pc)
    assert np.linalg.cond(general6r.half_angle(s)) > 1e14



@pytest.mark.parametrize("name", ARMS)
def test_every_pose_gives_back_its_configuration(name):
    solver = solver_of(name)
    robot, counts = solver.robot, []
    for q in np.random.default_rng(11).uniform(-math.pi, math.pi, (100, 6)):
        solutions = solver.solve(reference.fk(robot, q))
        assert min(np.abs(wrapped(s - q)).max() for s in solutions) < 1e-8
        counts.append(len(solutions))
    assert set(counts) <= set(range(2, 17, 2))
    if name == "manocha_canny":
        assert max(counts) == 16


@pytest.mark.parametrize("text", _six_revolute_arms())
def test_random_arms_give_back_their_configurations(text):
    robot = robot_of(text)
    arm = Solver(robot)
    for q in np.random.default_rng(5).uniform(-math.pi, math.pi, (40, 6)):
        solutions = arm.solve(reference.fk(robot, q))
        assert min(np.abs(wrapped(s - q)).max() for s in solutions) < 1e-8


@pytest.mark.parametrize("name", ARMS)
def test_finds_every_solution_a_multi_start_search_finds(name):
    solver, rng = solver_of(name), np.random.default_rng(4)
    robot = solver.robot
    for q in rng.uniform(-math.pi, math.pi, (2, 6)):
        pose = reference.fk(robot, q)
        ours, theirs = solver.solve(pose), multi_start(robot, pose, 100, rng)
        assert len(theirs) >= 2
        for s in theirs:
            assert min(np.abs(wrapped(s - o)).max() for o in ours) < 1e-6
        assert len(ours) >= len(theirs)


def test_rejects_what_it_cannot_solve():
    prismatic = random_arm_text(next(s for s in range(100) if "prismatic" in random_arm_text(s, dof=6)), dof=6)
    with pytest.raises(ValueError, match="six revolute joints"):
        general6r.chain_form(robot_of(prismatic))
