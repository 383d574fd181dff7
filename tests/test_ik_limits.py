"""Closed-form ik for a controller: joint limits and ik_nearest, on the committed generated code.

- `ik` keeps exactly the solutions with every joint inside its limits (modulo 2 pi for a
  revolute joint), returned inside them; `ik(..., limits=False)` keeps the rest too.
- `ik_nearest` returns the solution nearest the seed, checked against a brute force over
  every solution of `ik(..., limits=False)` that reaches the target (jacgen.reference fk) and
  every equivalent of each joint inside its limits; with random weights; its statuses.
- The C (double) and CasADi give the numpy's `ik_nearest`.
"""

import ctypes

import numpy as np
import pytest

from jacgen.checking import reference

from conftest import generated_module, random_configurations, robot
from support.ik import wrapped

ROBOTS = ["puma560", "ur5", "kr5", "panda"]  # limits within one turn, +-2 pi, +-350 deg, a free joint
MISS = 1e-8


def _free(module, q):
    """The free joint's angles of q, as ik's extra argument (none for a six-joint arm)."""
    free = getattr(module, "IK_FREE_JOINT", None)
    return () if free is None else (q[..., free],)


def _equivalents(arm, value, j):
    """Every value of joint j equal to `value` (modulo 2 pi if revolute) inside its limits."""
    joint = arm.joints[j]
    candidates = value + 2 * np.pi * np.arange(-3, 4) if joint.revolute else np.array([value])
    lower, upper = joint.limits
    return candidates[(candidates >= lower) & (candidates <= upper)]


@pytest.mark.parametrize("name", ROBOTS)
def test_limits_keep_exactly_the_solutions_inside(name):
    arm, module = robot(name), generated_module(name)
    q = random_configurations(arm, 500, seed=41)
    targets = reference.fk(arm, q)
    kept, keep = module.ik(targets, *_free(module, q))
    every, valid = module.ik(targets, *_free(module, q), limits=False)
    assert np.array_equal(kept, every) and not np.any(keep & ~valid)
    lower, upper = np.array([joint.limits for joint in arm.joints]).T
    assert np.all((kept[keep] >= lower) & (kept[keep] <= upper))
    dropped = every[valid & ~keep]
    assert all(any(not len(_equivalents(arm, value, j)) for j, value in enumerate(row)) for row in dropped)
    revolute = [joint.revolute for joint in arm.joints]
    outside = every[valid][:, revolute]
    inside_one_turn = (outside > -np.pi) & (outside <= np.pi)
    assert np.all(inside_one_turn | ((every[valid] >= lower) & (every[valid] <= upper))[:, revolute])
    assert keep.sum() > 0 and (name == "ur5" or (valid & ~keep).sum() > 0)


def _brute_force_nearest(arm, every, target, seed, weights):
    """The least weighted distance to the seed over the solutions that reach the target and
    the in-limit equivalents of each of their joints (the distance is a sum over joints)."""
    best = np.inf
    for row in every:
        if np.abs(reference.fk(arm, row) - target).max() > MISS:
            continue
        per_joint = [_equivalents(arm, value, j) for j, value in enumerate(row)]
        if any(not len(values) for values in per_joint):
            continue
        best = min(best, sum(w * np.min((values - s) ** 2) for w, values, s in zip(weights, per_joint, seed)))
    return best


@pytest.mark.parametrize("name", ROBOTS)
def test_nearest_is_the_nearest(name):
    arm, module = robot(name), generated_module(name)
    rng = np.random.default_rng(42)
    q = random_configurations(arm, 300, seed=43)
    seeds = q + rng.normal(0.0, 1.0, q.shape)
    weights = rng.uniform(0.1, 2.0, q.shape)
    targets = reference.fk(arm, q)
    found, status = module.ik_nearest(targets, seeds, *_free(module, q), weights)
    assert np.all(status == module.IK_NEAREST_OK)
    lower, upper = np.array([joint.limits for joint in arm.joints]).T
    assert np.all((found >= lower) & (found <= upper))
    for row, target, seed, weight, x in zip(q, targets, seeds, weights, found):
        assert np.abs(reference.fk(arm, x) - target).max() < MISS
        every = module.ik(target, *_free(module, row), limits=False)
        assert np.sum(weight * (x - seed) ** 2) == pytest.approx(_brute_force_nearest(arm, every, target, seed, weight),
                                                                  abs=1e-9)


@pytest.mark.parametrize("suffix", ["", "_casadi"])
def test_nearest_statuses(suffix):
    """Each IK_NEAREST_* constant of the numpy and the CasADi module is what ik_nearest returns."""
    arm, module = robot("puma560"), generated_module("puma560", suffix)
    seed = np.full(6, 0.2)
    target = reference.fk(arm, random_configurations(arm, 1, seed=44)[0])
    far = target.copy()
    far[:3, 3] += 10.0
    for bad_target, bad_seed, status in [(target, seed, module.IK_NEAREST_OK), (far, seed, module.IK_NEAREST_NO_SOLUTION),
                                         (np.full((4, 4), np.nan), seed, module.IK_NEAREST_NOT_FINITE),
                                         (target, np.r_[np.inf, seed[1:]], module.IK_NEAREST_NOT_FINITE)]:
        if suffix:
            found, got = (np.asarray(v).ravel() for v in module.ik_nearest(bad_target, bad_seed, np.ones(6)))
        else:
            found, got = module.ik_nearest(bad_target, bad_seed)
        assert got == status
        assert status == module.IK_NEAREST_OK or np.array_equal(found, bad_seed)


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_c_and_casadi_nearest_match_numpy(name, generated):
    arm, code = robot(name), generated.committed(name)
    module, casadi = code.python, code.casadi
    function = getattr(code.library()._library, f"{name}_ik_nearest")
    free = getattr(module, "IK_FREE_JOINT", None)
    pointer = ctypes.POINTER(ctypes.c_double)
    function.argtypes = [pointer, pointer] + [ctypes.c_double] * (free is not None) + [pointer, pointer]
    function.restype = ctypes.c_int
    rng = np.random.default_rng(45)
    q = random_configurations(arm, 200, seed=46)
    for k, row in enumerate(q):
        target = np.ascontiguousarray(reference.fk(arm, row))
        seed, weights = row + rng.normal(0.0, 0.5, arm.dof), rng.uniform(0.1, 2.0, arm.dof)
        expected, status = module.ik_nearest(target, seed, *_free(module, row), weights)
        out = np.zeros(arm.dof)
        arguments = [a.ctypes.data_as(pointer) for a in (target, seed)] + [row[free]] * (free is not None)
        got = function(*arguments, weights.ctypes.data_as(pointer), out.ctypes.data_as(pointer))
        assert got == status and np.abs(out - expected).max() < 1e-9
        if k < 20:
            in_casadi, casadi_status = casadi.ik_nearest(target, seed, *_free(module, row), weights)
            assert int(casadi_status) == status and np.abs(in_casadi.full().ravel() - expected).max() < 1e-9


def test_free_joint_outside_its_limits_gives_no_solution():
    arm, module = robot("panda"), generated_module("panda")
    q = random_configurations(arm, 1, seed=47)[0]
    target = reference.fk(arm, q)
    assert len(module.ik(target, 3.0)) == 0  # joint 7 is limited to +-2.8973 rad
    assert len(module.ik(target, q[6])) >= 1
    assert all(len(module.ik(target, angle, limits=False)) <= 8 for angle in (3.0, q[6]))


def test_kr5_wrist_beyond_one_turn():
    """KR 5's axes 4 and 6 turn +-350 deg: ik returns each solution once (wrapped into
    (-pi, pi], inside the limits); ik_nearest picks the equivalent nearest the seed."""
    arm, module = robot("kr5"), generated_module("kr5")
    q = np.array([0.3, -1.0, 0.5, 5.5, 0.7, -5.8])  # axes 4 and 6 beyond +-pi
    target = reference.fk(arm, q)
    found = module.ik(target)
    assert np.all(np.abs(found[:, [3, 5]]) <= np.pi)
    nearest, status = module.ik_nearest(target, q)
    assert status == 0 and np.abs(nearest - q).max() < 1e-9
    assert np.abs(found - wrapped(q)).max(axis=1).min() < 1e-9  # q's wrapped copy is among ik's solutions
