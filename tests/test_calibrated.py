"""The calibrated arms' fast path (contract §2, "Calibrated arms"): the nominal arm the
structure stage finds, and on random and near-singular poses the same solution set as the
eigenproblem alone (the arm with `ik: {nearest_class: false}`), every solution reaching its
pose by the reference's fk, in numpy and in C."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import sympy

from jacgen.checking import reference
from jacgen.emission.generator import Generator
from jacgen.inputs.robot_file import load_robot
from jacgen.model import structure
from jacgen.model.node import NUMBER, TOLERANCE_VALUES, evaluate
from jacgen.solvers import ik
from jacgen.solvers.general6r_target import Certificate
from jacgen.solvers.subproblems import Subproblems

from conftest import GENERATED, robot
from support.generated import model
from support.ik import wrapped

DATA = Path(__file__).parent / "data" / "calibrated"
ARMS = {"ur5_calibrated": robot("ur5_calibrated"),
        "puma560_calibrated": load_robot(DATA / "puma560_calibrated.yaml"),
        "kr5_calibrated": load_robot(DATA / "kr5_calibrated.yaml"),
        "panda_calibrated": robot("panda_calibrated")}
NOMINAL = {"ur5_calibrated": ("three_parallel", 3),
           "puma560_calibrated": ("spherical_wrist_intersecting", 4),
           "kr5_calibrated": ("spherical_wrist_parallel", 4),
           "panda_calibrated": ("spherical_wrist_intersecting", 4)}
# The share of random poses each arm's fast path decides, at least (measured on 2 x 10^4: 87.5 %,
# 92.2 %, 96.9 %, 86.7 %): a floor against regressions of the certificate, not a target.
DECIDED = {"ur5_calibrated": 0.85, "puma560_calibrated": 0.90, "kr5_calibrated": 0.95, "panda_calibrated": 0.84}


# Arms nobody tuned for: the UR5 and the Puma with their twists moved by up to 5e-3 rad and their
# lengths by up to 0.5 mm, at random (see the files).
PERTURBED = {name: load_robot(DATA / f"{name}.yaml") for name in ("ur5_perturbed", "puma560_perturbed")}


def _eigenproblem_only(arm):
    """The same arm without the fast path."""
    return dataclasses.replace(arm, name=f"{arm.name}_general", nearest_class=False)


def _free_angles(arm, q: np.ndarray) -> tuple:
    """The general solver's input angle of a 7R arm at configurations q, as ik_branches takes it."""
    free = model(arm).closed_form.free
    return () if free is None else (q[:, free],)


def _random_configurations(arm, count: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).uniform(-math.pi, math.pi, (count, arm.dof))


def _near_singular_configurations(arm, count: int, seed: int) -> np.ndarray:
    """`count` random configurations per joint with that joint 10^-k rad (k uniform in 3 ... 12)
    from 0 or pi, and `count` with the elbow (the nominal closed form's SP3 joint) 10^-k from
    where it is straight or folded (where the least singular value of the Jacobian of the six
    joints ik solves is least along its turn): wrists near aligned, elbows near straight."""
    rng = np.random.default_rng(seed)
    form = model(arm).closed_form
    q = rng.uniform(-math.pi, math.pi, (arm.dof + 1, count, arm.dof))
    offsets = rng.choice([-1.0, 1.0], (arm.dof + 1, count)) * 10.0 ** rng.uniform(-12, -3, (arm.dof + 1, count))
    for joint in range(arm.dof):
        q[joint, :, joint] = rng.choice([0.0, math.pi], count) + offsets[joint]
    elbow = form.joints[form.fast_path.form.joints[2]]

    def least_singular_value(angles):  # of the configurations q[-1] with the elbow at `angles` (count, m)
        trial = np.repeat(q[-1][:, None, :], angles.shape[1], axis=1)
        trial[..., elbow] = angles
        return np.linalg.svd(reference.jacobian(arm, trial)[..., list(form.joints)], compute_uv=False)[..., -1]
    grid = np.linspace(-math.pi, math.pi, 181)
    best = grid[np.argmin(least_singular_value(np.broadcast_to(grid, (count, len(grid)))), axis=1)]
    low, high = best - 2 * math.pi / 180, best + 2 * math.pi / 180
    for _ in range(60):  # golden-section search within the grid's cell
        a, b = high - 0.618 * (high - low), low + 0.618 * (high - low)
        left = least_singular_value(a[:, None])[:, 0] < least_singular_value(b[:, None])[:, 0]
        high, low = np.where(left, b, high), np.where(left, low, a)
    q[-1, :, elbow] = (low + high) / 2 + offsets[-1]
    return q.reshape(-1, arm.dof)


def _differences(arm, poses, ours, valid, theirs, valid_theirs) -> tuple[int, int, int]:
    """(missed, extra, eigenproblem missed): solutions of `theirs` not in `ours` (to 1e-7 rad);
    of `ours` not in `theirs` that do not reach their pose to 1e-9 (1 + reach), or repeat one;
    and of `ours` not in `theirs` that do: solutions the eigenproblem does not find."""
    missed = repeated = 0
    alone, targets = [], []
    for T, mine, mine_valid, other, other_valid in zip(poses, ours, valid, theirs, valid_theirs):
        a, b = mine[mine_valid.astype(bool)], other[other_valid.astype(bool)]
        close = np.abs(wrapped(a[:, None, :] - b[None, :, :])).max(axis=-1) < 1e-7
        missed += int((~close.any(axis=0)).sum())
        same = np.abs(wrapped(a[:, None, :] - a[None, :, :])).max(axis=-1) < 1e-6
        repeated += int(same.sum() - len(a))
        alone += list(a[~close.any(axis=1)])
        targets += [T] * int((~close.any(axis=1)).sum())
    if not alone:
        return missed, repeated, 0
    reached = np.abs(reference.fk(arm, np.array(alone)) - np.array(targets)).max(axis=(-2, -1)) < 1e-9 * (1 + arm.reach)
    return missed, repeated + int((~reached).sum()), int(reached.sum())


@pytest.mark.parametrize("name", ARMS)
def test_the_nearest_special_class_snaps_the_fewest_values(name):
    arm = ARMS[name]
    nominal = model(arm).closed_form.fast_path.nominal
    solver, snapped = NOMINAL[name]
    assert nominal.structure.solver == solver and len(nominal.snapped) == snapped
    assert structure.classify(arm).solver == "general_6r"
    assert model(_eigenproblem_only(arm)).closed_form.fast_path is None
    assert model(robot("jaco")).closed_form.fast_path is None  # the 60-degree wrist is not near a class


def test_ur5_calibrated_snaps_its_two_twists_and_the_wrist_offset():
    nominal = model(robot("ur5_calibrated")).closed_form.fast_path.nominal
    assert nominal.snapped == ("alpha2 -0.001 -> 0 rad", "alpha3 0.001 -> 0 rad", "a5 0.0001 -> 0 m")
    assert "path: calibrated fast path. Nearest special class: three_parallel" in \
        (GENERATED / "ur5_calibrated" / "ur5_calibrated.md").read_text()


def _compare(arm, code, general_code, q) -> tuple[int, int, int]:
    """ik_branches of the fast path and of the eigenproblem alone (numpy) at the poses of q."""
    poses, free = reference.fk(arm, q), _free_angles(arm, q)
    ours = code.ik_branches(poses, *free)[:2]
    theirs = general_code.ik_branches(poses, *free)[:2]
    return _differences(arm, poses, *ours, *theirs)


@pytest.mark.parametrize("name", ARMS)
def test_numpy_finds_what_the_eigenproblem_finds(name, generated):
    """10^4 random poses and 7 x 1000 near-singular ones: 0 missed, 0 extra; the fast path
    decides at least DECIDED of the random ones."""
    arm = ARMS[name]
    fast = generated(arm, functions=("ik_branches",)).python
    general = generated(_eigenproblem_only(arm), functions=("ik_branches",)).python
    q = _random_configurations(arm, 10_000, 1)
    assert _compare(arm, fast, general, q)[:2] == (0, 0)
    assert fast._fast_branches(reference.fk(arm, q), *_free_angles(arm, q))[2].mean() >= DECIDED[name]
    assert _compare(arm, fast, general, _near_singular_configurations(arm, 1000, 2))[:2] == (0, 0)


@pytest.mark.parametrize("name", PERTURBED)
def test_arms_nobody_tuned_for(name, generated):
    """Shipped arms with twists off by up to 5e-3 rad and lengths by up to 0.5 mm: the same."""
    arm = PERTURBED[name]
    assert model(arm).closed_form.fast_path is not None
    fast = generated(arm, functions=("ik_branches",)).python
    general = generated(_eigenproblem_only(arm), functions=("ik_branches",)).python
    for q in (_random_configurations(arm, 4000, 3), _near_singular_configurations(arm, 300, 4)):
        assert _compare(arm, fast, general, q)[:2] == (0, 0)


@pytest.mark.parametrize("name", ARMS)
def test_c_finds_what_its_eigenproblem_finds(name, generated):
    arm = ARMS[name]
    fast = generated(arm, ("c",), functions=("ik_branches",)).library("ik_branches")
    general = generated(_eigenproblem_only(arm), ("c",), functions=("ik_branches",)).library("ik_branches")
    q = np.concatenate([_random_configurations(arm, 1400, 3), _near_singular_configurations(arm, 100, 4)])
    poses, free = reference.fk(arm, q), _free_angles(arm, q)
    rows = [(fast.call("ik_branches", T, *f)[:2], general.call("ik_branches", T, *f)[:2])
            for T, *f in zip(poses, *free)]
    ours, theirs = zip(*rows)
    assert _differences(arm, poses, *map(np.array, zip(*ours)), *map(np.array, zip(*theirs)))[:2] == (0, 0)


def test_the_mismatch_bound_holds():
    """The arms' mismatch (general6r.mismatch, summed from their DH differences) bounds the
    difference of their tool poses at 10^5 random configurations, and is within 3 x of it."""
    for arm in (*ARMS.values(), *PERTURBED.values()):
        fast = model(arm).closed_form.fast_path
        q = _random_configurations(arm, 100_000, 5)
        exact, nominal = reference.fk(arm, q), reference.fk(fast.nominal.robot, q)
        position = np.linalg.norm(exact[:, :3, 3] - nominal[:, :3, 3], axis=-1).max()
        chord = np.linalg.norm(exact[:, :3, :3] - nominal[:, :3, :3], axis=(-2, -1)) / (2 * math.sqrt(2))
        rotation = (2 * np.arcsin(np.minimum(chord, 1.0))).max()  # |R1 - R2| = 2 sqrt(2) sin(angle / 2)
        assert position <= fast.position < 3 * position
        assert rotation <= fast.rotation + 1e-15 and fast.rotation <= 3 * rotation


def _rotation(w: np.ndarray) -> np.ndarray:
    """exp([w]x), Rodrigues."""
    angle = np.linalg.norm(w)
    k = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]]) / angle
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


@pytest.mark.parametrize("name", ["ur5_calibrated", "puma560_calibrated"])
def test_the_certificates_assumption_holds_where_it_certifies(name):
    """The certificate's assumption (contract §2): over the mismatch ball, a margin moves by
    less than twice its first-order radius, so one that is 2 radii from 0 keeps its sign. Each
    margin of the nominal closed form, evaluated from the value graph at 30 random poses and
    at 12 targets on the ball's boundary around each."""
    arm = ARMS[name]
    generator = Generator(arm, model(arm), selection=("ik_branches",))
    fast = generator.closed_form.fast_path
    sp = Subproblems(generator.graph, generator.name_node)
    target = sympy.Matrix(4, 4, lambda i, j: sympy.Symbol(f"T{i}{j}", real=True))
    certificate = Certificate(sp, target, generator.lowering.value_of, fast.rotation, fast.position)
    margins = []  # (margin, its slack: margin - 2 radius where valid, else 1)

    def record(margin, parts, valid, *fold):
        certificate.test(margin, parts, valid, *fold)
        if certificate.slacks[-1].kind != NUMBER:  # not a constant margin's test, decided when generated
            margins.append((margin, certificate.slacks[-1]))
    sp.margins = record
    ik.branches(fast.nominal.robot, fast.form, sp, target, None)
    body = generator.lower([node for pair in margins for node in pair])  # as the backends print them

    def evaluated(T):
        values = {target[i, j]: float(T[i, j]) for i in range(4) for j in range(4)}
        values.update(TOLERANCE_VALUES["double"])
        for symbol, value in body.definitions:
            values[symbol] = evaluate(value, values)
        return np.array([evaluate(node, values) for node in body.outputs]).reshape(-1, 2)

    rng = np.random.default_rng(7)
    checked = 0
    for T in reference.fk(arm, _random_configurations(arm, 30, 6)):
        at_target = evaluated(T)
        margin, slack = at_target[:, 0], at_target[:, 1]
        certified = slack < 1  # the margins of the branches T allows (the others have slack 1)
        certified &= slack >= 0
        radius = (margin - slack) / 2
        for _ in range(12):
            w, v = rng.normal(size=3), rng.normal(size=3)
            moved = T.copy()
            if fast.rotation:
                moved[:3, :3] = _rotation(w / np.linalg.norm(w) * fast.rotation) @ T[:3, :3]
            moved[:3, 3] += v / np.linalg.norm(v) * fast.position
            change = np.abs(evaluated(moved)[:, 0] - margin)
            assert (change[certified] <= 2 * radius[certified] + 1e-12).all()
            checked += int(certified.sum())
    assert checked > 1000
