"""Closed-form ik of 7-joint arms with a free joint (`ik: {free_joint: k}`).

Panda (joint 7 free: its first three axes meet, so the chain is solved from the tool back)
and iiwa (joint 3 free: the axes after it turn with it) from the committed generated code,
round trips through jacgen.reference on 10^4 in-limit configurations each, the C and CasADi
against the numpy, Panda against frankik (He & Liu's solver), and random 7R arms of both
kinds with every workable free joint.
"""

import frankik
import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot

from conftest import random_configurations, robot
from support.generated import c_ik
from support.ik import regular, wrapped

SHIPPED = {"panda": 6, "iiwa": 2}  # robot -> free joint, 0-based
MISS = 1e-8  # a returned solution farther than this from its target is a miss (issue 13)


def _check_round_trips(arm, module, q, free):
    """Batched ik at fk(q) with q[free] given, every branch (limits=False): no miss, the free
    joint kept, at most 8 solutions, the original q among them where the other six are well
    conditioned.
    Returns (solutions, valid)."""
    targets = reference.fk(arm, q)
    solutions, valid = module.ik(targets, q[:, free], limits=False)
    assert solutions.shape == (len(q), 8, 7) and valid.shape == (len(q), 8)
    found = solutions[valid]
    misses = np.abs(reference.fk(arm, found) - np.repeat(targets, valid.sum(axis=1), axis=0)).max(axis=(1, 2))
    assert misses.max() < MISS, misses.max()
    assert np.array_equal(found[:, free], np.repeat(q[:, free], valid.sum(axis=1)))
    distance = np.where(valid, np.abs(wrapped(solutions - q[:, None, :])).max(axis=2), np.inf).min(axis=1)
    well = regular(arm, q, free)  # the six joints left are well conditioned
    assert np.all(distance[well] < 1e-6), np.flatnonzero(well & (distance >= 1e-6))[:5]
    return solutions, valid


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_arms_round_trip(name, generated):
    arm, module, free = robot(name), generated.committed(name).python, SHIPPED[name]
    assert arm.free_joint == free == module.IK_FREE_JOINT
    q = random_configurations(arm, 10_000, seed=31)
    _, valid = _check_round_trips(arm, module, q, free)
    counts = np.bincount(valid.sum(axis=1), minlength=9)
    assert counts[8] > 0 and counts[0] == 0, counts


@pytest.mark.parametrize("name", SHIPPED)
def test_c_and_casadi_give_the_numpy_solutions(name, generated):
    """The committed C (double) and CasADi: the numpy's solutions, in its order, to 1e-9."""
    arm, code, free = robot(name), generated.committed(name), SHIPPED[name]
    module, library, casadi = code.python, code.library("ik"), code.casadi
    q = random_configurations(arm, 300, seed=32)
    for row, target in zip(q, reference.fk(arm, q)):
        ours = module.ik(target, row[free])
        in_c = c_ik(library, target, row[free])
        assert in_c.shape == ours.shape and np.abs(in_c - ours).max(initial=0) < 1e-9
    for row, target in zip(q[:40], reference.fk(arm, q[:40])):
        branches, valid, in_limits = casadi.ik(target, row[free])
        in_casadi = branches.full()[(valid.full() * in_limits.full()).ravel() == 1]
        assert np.abs(in_casadi - module.ik(target, row[free])).max(initial=0) < 1e-9


def test_panda_contains_frankik_solutions(generated):
    """frankik (He & Liu's solver) returns up to 4 of the solutions for a given q7: every one it
    returns that reaches the target is one of ours. Its fk ends at a hand TCP 0.1034 m beyond
    the flange (ours is 0.103 m) and its ik takes the flange pose: the test checks that its fk
    is our Panda with its TCP, then solves flange poses with our Panda without a tool."""
    text = open(robot("panda").source).read().replace("name: panda", "name: panda_flange")
    tcp = parse_robot(text.replace("tool: {xyz: [0, 0, 0.103]", "tool: {xyz: [0, 0, 0.1034]").encode())
    flange = parse_robot(text.replace("tool: {xyz: [0, 0, 0.103], rpy: [0, 0, -45]}", "").encode())
    module = generated(flange, functions=("ik",)).python
    q = random_configurations(flange, 1000, seed=33)
    compared = 0
    for row in q:
        assert np.abs(frankik.fk(row) - reference.fk(tcp, row)).max() < 1e-12  # the same arm
        target = reference.fk(flange, row)
        ours = module.ik(target, row[6], limits=False)
        for theirs in frankik.ik_full(target, row, row[6]):
            if np.all(np.isfinite(theirs)) and np.abs(reference.fk(flange, theirs) - target).max() < MISS:
                assert np.abs(wrapped(ours - theirs)).max(axis=1).min() < 1e-7, (row, theirs)
                compared += 1
    assert compared > 1000


def _srs(seed: int) -> str:
    """A random S-R-S arm (iiwa-like), standard DH: random lengths, twists +-90, offsets, base, tool."""
    rng = np.random.default_rng(seed)
    length = lambda: round(float(rng.uniform(0.1, 0.5)), 4)  # noqa: E731
    twist = lambda: int(rng.choice([-90, 90]))  # noqa: E731
    offset = lambda: round(float(rng.uniform(-180, 180)), 3)  # noqa: E731
    rows = [(0, twist(), length()), (0, twist(), 0), (0, twist(), length()), (0, twist(), 0),
            (0, twist(), length()), (0, twist(), 0), (0, 0, length())]
    return _arm(f"srs_{seed}", "standard", rows, offset, rng)


def _offset_elbow(seed: int) -> str:
    """A random Panda-like arm, modified DH: spherical shoulder, offset elbow, axes 5 and 6
    intersecting, a last axis offset from them."""
    rng = np.random.default_rng(seed)
    length = lambda: round(float(rng.uniform(0.05, 0.5)), 4)  # noqa: E731
    offset = lambda: round(float(rng.uniform(-180, 180)), 3)  # noqa: E731
    sign = lambda: int(rng.choice([-1, 1]))  # noqa: E731
    rows = [(0, 0, length()), (0, -90 * sign(), 0), (0, 90 * sign(), length()), (length(), 90 * sign(), 0),
            (-length(), -90 * sign(), length()), (0, 90 * sign(), 0), (length(), 90 * sign(), length())]
    return _arm(f"offset_elbow_{seed}", "modified", rows, offset, rng)


def _arm(name, convention, rows, offset, rng) -> str:
    pose = lambda: (f"{{xyz: {[round(float(x), 4) for x in rng.uniform(-0.3, 0.3, 3)]}, "  # noqa: E731
                    f"rpy: {[round(float(x), 3) for x in rng.uniform(-180, 180, 3)]}}}")
    joints = "".join(f"  - {{type: revolute, a: {a}, alpha: {alpha}, d: {d}, offset: {offset()}}}\n"
                     for a, alpha, d in rows)
    return f"name: {name}\nconvention: {convention}\nangle_unit: deg\njoints:\n{joints}base: {pose()}\ntool: {pose()}\n"


@pytest.mark.parametrize("kind, seed, free", [
    ("srs", 0, 1), ("srs", 2, 3), ("srs", 3, 5), ("srs", 4, None), ("offset_elbow", 1, None),
])
def test_random_arms_round_trip(kind, seed, free, generated):
    """Random arms with the free joint given (1-based) or chosen by the structure detection
    (None: joint 7, the first it tries, works for both kinds)."""
    text = (_srs if kind == "srs" else _offset_elbow)(seed) + (f"ik: {{free_joint: {free}}}\n" if free else "")
    arm = parse_robot(text.encode())
    module = generated(arm, functions=("ik",)).python
    assert module.IK_FREE_JOINT == (free or 7) - 1
    q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (300, 7))
    _check_round_trips(arm, module, q, module.IK_FREE_JOINT)


def test_elbow_cannot_be_the_free_joint():
    """With the elbow (joint 4) of an S-R-S arm held, shoulder and wrist are fixed distance
    apart: the six joints left have infinitely many solutions, and no class applies."""
    from jacgen.model.structure import classify

    structure = classify(parse_robot((_srs(0) + "ik: {free_joint: 4}\n").encode()))
    assert structure.solver is None and "joint 4 free" in structure.reason
