"""The calibrated arms' fast path (contract §2, "Calibrated arms"): the nominal arm the
structure stage finds, and on random and near-singular poses the same solution set as the
eigenproblem alone (the arm with `ik: {nearest_class: false}`), every solution reaching its
pose by the reference's fk, in numpy and in C."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.model import structure
from jacgen.solvers.model import Model
from jacgen.inputs.robot_file import load_robot

from conftest import GENERATED, robot
from support.ik import wrapped

DATA = Path(__file__).parent / "data" / "calibrated"
ARMS = {"ur5_calibrated": robot("ur5_calibrated"),
        "puma560_calibrated": load_robot(DATA / "puma560_calibrated.yaml"),
        "kr5_calibrated": load_robot(DATA / "kr5_calibrated.yaml")}
NOMINAL = {"ur5_calibrated": ("three_parallel", 3),
           "puma560_calibrated": ("spherical_wrist_intersecting", 4),
           "kr5_calibrated": ("spherical_wrist_parallel", 4)}


def _eigenproblem_only(arm):
    """The same arm without the fast path."""
    return dataclasses.replace(arm, name=f"{arm.name}_general", nearest_class=False)


def _random_poses(arm, count: int, seed: int) -> np.ndarray:
    q = np.random.default_rng(seed).uniform(-math.pi, math.pi, (count, 6))
    return reference.fk(arm, q)


def _near_singular_poses(arm, count: int, seed: int) -> np.ndarray:
    """`count` poses per joint with that joint within 1e-3 rad of 0 or pi (for these arms the
    wrist's, the elbow's and the shoulder's singular configurations are among them)."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-math.pi, math.pi, (6, count, 6))
    for joint in range(6):
        q[joint, :, joint] = rng.choice([0.0, math.pi], count) + rng.uniform(-1e-3, 1e-3, count)
    return reference.fk(arm, q.reshape(-1, 6))


def _differences(ours, valid, theirs, valid_theirs) -> tuple[int, int]:
    """(missed, extra): solutions of `theirs` not in `ours`, and of `ours` not in `theirs` (to 1e-7 rad)."""
    missed = extra = 0
    for mine, mine_valid, other, other_valid in zip(ours, valid, theirs, valid_theirs):
        a, b = mine[mine_valid.astype(bool)], other[other_valid.astype(bool)]
        close = np.abs(wrapped(a[:, None, :] - b[None, :, :])).max(axis=-1) < 1e-7 if len(a) and len(b) else \
            np.zeros((len(a), len(b)), dtype=bool)
        missed += int((~close.any(axis=0)).sum())
        extra += int((~close.any(axis=1)).sum())
    return missed, extra


@pytest.mark.parametrize("name", ARMS)
def test_the_nearest_special_class_snaps_the_fewest_values(name):
    arm = ARMS[name]
    nominal = Model(arm).closed_form.fast_path.nominal
    solver, snapped = NOMINAL[name]
    assert nominal.structure.solver == solver and len(nominal.snapped) == snapped
    assert structure.classify(arm).solver == "general_6r"
    assert Model(_eigenproblem_only(arm)).closed_form.fast_path is None
    assert Model(robot("jaco")).closed_form.fast_path is None  # the 60-degree wrist is not near a class


def test_ur5_calibrated_snaps_its_two_twists_and_the_wrist_offset():
    nominal = Model(robot("ur5_calibrated")).closed_form.fast_path.nominal
    assert nominal.snapped == ("alpha2 -0.001 -> 0 rad", "alpha3 0.001 -> 0 rad", "a5 0.0001 -> 0 m")
    assert "path: calibrated fast path. Nearest special class: three_parallel" in \
        (GENERATED / "ur5_calibrated" / "ur5_calibrated.md").read_text()


@pytest.mark.parametrize("name", ARMS)
def test_numpy_finds_what_the_eigenproblem_finds(name, generated):
    """10^4 random poses and 6 x 500 near-singular ones: 0 missed, 0 extra; every solution
    reaches its pose to 1e-9 (1 + reach); the fast path decides most random poses."""
    arm = ARMS[name]
    fast = generated(arm, functions=("ik_branches",)).python
    general = generated(_eigenproblem_only(arm), functions=("ik_branches",)).python
    for poses, decided_at_least in ((_random_poses(arm, 10_000, 1), 0.5), (_near_singular_poses(arm, 500, 2), 0.0)):
        q, valid, _ = fast.ik_branches(poses)
        q_general, valid_general, _ = general.ik_branches(poses)
        assert _differences(q, valid, q_general, valid_general) == (0, 0)
        reached = np.abs(reference.fk(arm, q) - poses[:, None]).max(axis=(-2, -1))
        assert reached[valid].max() < 1e-9 * (1 + arm.reach)
        assert fast._fast_branches(poses)[2].mean() >= decided_at_least


@pytest.mark.parametrize("name", ARMS)
def test_c_finds_what_its_eigenproblem_finds(name, generated):
    arm = ARMS[name]
    fast = generated(arm, ("c",), functions=("ik_branches",)).library("ik_branches")
    general = generated(_eigenproblem_only(arm), ("c",), functions=("ik_branches",)).library("ik_branches")
    poses = np.concatenate([_random_poses(arm, 1400, 3), _near_singular_poses(arm, 100, 4)])
    ours, theirs = zip(*([fast.call("ik_branches", T)[:2], general.call("ik_branches", T)[:2]] for T in poses))
    q, valid = map(np.array, zip(*ours))
    assert _differences(q, valid, *map(np.array, zip(*theirs))) == (0, 0)
    reached = np.abs(reference.fk(arm, q) - poses[:, None]).max(axis=(-2, -1))
    assert reached[valid.astype(bool)].max() < 1e-9 * (1 + arm.reach)
