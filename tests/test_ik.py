"""Closed-form ik and ik_numeric of the generated Python and C.

Round trips on random configurations (every solution reproduces fk(q), the original q is
among them), solution counts against EAIK and ik-geo on the arms they solve, random robots
of every class, unreachable targets, and the C (double and float) against the Python (the
targets on singularities, on every backend: tests/test_ik_contract.py). Forward kinematics is
the generated fk, itself checked against jacgen.reference elsewhere; the random robots are
checked against jacgen.reference.fk directly.
"""

import functools

import numpy as np
import pytest
from eaik.IK_HP import HPRobot
from ik_geo import Robot as IkGeoRobot

from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot
from jacgen.solvers.differential import IK_NUMERIC_DEFAULTS

from conftest import random_configurations, robot
from support.generated import c_ik
from support.ik import kinematic_chain, regular, target_error, wrapped_distance

WITH_IK = ["planar_2r", "planar_3r", "scara", "rexarm", "puma560", "kr5", "stanford", "ur5"]
FREE_JOINT = ["iiwa", "panda"]  # closed form with a free joint: tests/test_free_joint.py
SAMPLES = 1000  # random configurations per shipped robot (Python); the C takes 4 times as many
TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def modules(generated):
    """The committed generated modules of the shipped robots (test_golden checks they are current)."""
    return {name: generated.committed(name).python for name in WITH_IK + FREE_JOINT}


def _pose_task(arm) -> bool:
    return len(arm.task) == 6


def _targets(module, arm, q):
    return module.fk(q) if _pose_task(arm) else module.task(q)


def _batched(module, limits=False):
    """The module's ik over a batch of targets, as a list of solutions (k, n) per target
    (every branch, unless `limits`: those inside the joint limits, as the C ik returns)."""
    def solve(targets):
        q, valid = module.ik(targets, limits=limits)
        return [rows[mask] for rows, mask in zip(q, valid)]
    return solve


def _wrapped_or_inside(arm, q):
    """Per row of q: every revolute angle in (-pi, pi] or inside the joint's limits."""
    revolute = [joint.revolute for joint in arm.joints]
    bounds = np.array([joint.limits or (-np.inf, np.inf) for joint in arm.joints])
    inside = (q >= bounds[:, 0]) & (q <= bounds[:, 1])
    return np.all(((q > -np.pi) & (q <= np.pi) | inside)[:, revolute], axis=1)


def _check_round_trip(arm, ik, targets_of, q, regular):
    """ik(targets_of(q)): every solution reproduces its target, the original q is among them
    where `regular`, revolute angles in (-pi, pi] or inside the limits, no NaN. Returns the solution counts."""
    targets = targets_of(q)
    solutions = ik(targets)
    owner = np.concatenate([np.full(len(s), i) for i, s in enumerate(solutions)]).astype(int)
    stacked = np.concatenate(solutions)
    assert np.all(np.isfinite(stacked))
    errors = target_error(arm, targets_of(stacked), targets[owner])
    assert errors.max() < TOLERANCE, (arm.name, errors.max())
    assert np.all(_wrapped_or_inside(arm, stacked))
    for row, found in enumerate(solutions):
        if regular[row]:
            assert len(found) and wrapped_distance(arm, found, q[row]).min() < 1e-7, (arm.name, q[row])
    return np.array([len(s) for s in solutions])


@pytest.mark.parametrize("name", WITH_IK)
def test_round_trip_of_random_configurations(modules, name):
    arm, module = robot(name), modules[name]
    q = random_configurations(arm, SAMPLES, seed=11)
    counts = _check_round_trip(arm, _batched(module), lambda q: _targets(module, arm, q), q,
                               module.manipulability(q) > 1e-3)
    expected = {"planar_2r": {2}, "planar_3r": {2}, "scara": {2}, "puma560": {8}, "stanford": {8},
                "rexarm": {4, 8}, "kr5": {4, 8}, "ur5": {2, 4, 6, 8}}[name]
    assert set(counts) <= expected and max(counts) == max(expected)
    assert module.MAX_IK_SOLUTIONS == max(expected)


def _real_solutions(solutions):
    return np.array([q for q, least_squares in solutions if not least_squares]).reshape(-1, 6)


def _assert_same_sets(arm, ours, theirs, context):
    assert len(ours) == len(theirs), (context, ours, theirs)
    if len(ours):
        distance = wrapped_distance(arm, ours[:, None, :], theirs[None, :, :])
        assert distance.min(axis=1).max() < 1e-6 and distance.min(axis=0).max() < 1e-6, context


def _compare_with_eaik(module, arm, q, fk, ik_geo_factory=None):
    """Same real solution sets as EAIK (and ik-geo when given its factory) at the poses fk(q)."""
    H, P, tool_rotation = kinematic_chain(arm)
    eaik = HPRobot(H, P)
    other = ik_geo_factory(H, P) if ik_geo_factory else None
    counts = []
    for row, T in zip(q, fk(q)):
        ours = module.ik(T, limits=False)
        shifted = T.copy()
        shifted[:3, :3] = T[:3, :3] @ tool_rotation.T
        result = eaik.IK(shifted)
        theirs = np.array(result.Q)[~np.array(result.is_LS, dtype=bool)].reshape(-1, 6)
        _assert_same_sets(arm, ours, theirs, ("eaik", arm.name, row))
        if other is not None:
            # ik-geo's rotations are lists of columns (its forward_kinematics returns R^T)
            found = _real_solutions(other.get_ik(shifted[:3, :3].T, shifted[:3, 3]))
            _assert_same_sets(arm, ours, found, ("ik_geo", arm.name, row))
        counts.append(len(ours))
    return counts


def test_ur5_matches_eaik_and_ik_geo(modules):
    """Poses anywhere in the workspace (q in [-pi, pi]^6): 2, 4, 6 or 8 real solutions."""
    arm = robot("ur5")
    q = np.random.default_rng(12).uniform(-np.pi, np.pi, (300, 6))
    counts = _compare_with_eaik(modules["ur5"], arm, q, modules["ur5"].fk, IkGeoRobot.three_parallel_two_intersecting)
    assert set(counts) == {2, 4, 6, 8}


@pytest.mark.parametrize("name", ["puma560", "kr5"])
def test_spherical_wrist_arms_match_eaik_and_ik_geo(modules, name):
    arm = robot(name)
    counts = _compare_with_eaik(modules[name], arm, random_configurations(arm, 200, seed=13), modules[name].fk,
                                IkGeoRobot.spherical_two_parallel)
    assert max(counts) == 8


# -- random robots of every class ---------------------------------------------------------------


def _uniform(rng, low, high):
    return float(np.round(rng.uniform(low, high), 4))


def _pose(rng, planar=False):
    xyz = [_uniform(rng, -0.3, 0.3) for _ in range(3)]
    rpy = [0, 0, _uniform(rng, -180, 180)] if planar else [_uniform(rng, -180, 180) for _ in range(3)]
    return f"{{xyz: {xyz}, rpy: {rpy}}}"


def _revolute(a, alpha, d, offset):
    return f"  - {{type: revolute, a: {a}, alpha: {alpha}, d: {d}, offset: {offset}}}\n"


def _random_robot(kind: str, seed: int):
    """A robot of the given class with random dimensions, offsets and base/tool poses."""
    rng = np.random.default_rng(seed)
    u = lambda low=0.1, high=0.6: _uniform(rng, low, high)  # noqa: E731
    angle = lambda: _uniform(rng, -180, 180)  # noqa: E731
    flip = lambda: int(rng.choice([0, 180]))  # noqa: E731 (axis direction reversed or not)
    planar = kind in ("planar_2r", "planar_3r", "scara", "yaw_pitch")  # base turns about z only
    rows, task = "", None
    if kind == "planar_2r":
        rows = _revolute(u(), flip(), u(-0.1, 0.1), angle()) + _revolute(u(), flip(), 0, angle())
        task = "[x, y]"
    elif kind == "planar_3r":
        rows = "".join(_revolute(u(), flip(), u(-0.1, 0.1), angle()) for _ in range(3))
        task = "[x, y, yaw]"
    elif kind == "scara":
        rows = (_revolute(u(), flip(), u(), angle()) + _revolute(u(), flip(), 0, angle())
                + f"  - {{type: prismatic, a: {u(0, 0.05)}, alpha: {flip()}, theta: {angle()}, offset: {u()}}}\n"
                + _revolute(0, 0, u(0, 0.1), angle()))
        task = "[x, y, z, yaw]"
    elif kind == "yaw_pitch":
        rows = (_revolute(u(0, 0.05), 90, u(), 0) + _revolute(u(), 0, u(-0.05, 0.05), angle())
                + _revolute(u(), 0, 0, angle()) + _revolute(u(), 0, 0, angle()))
        task = "[x, y, z, pitch]"
    elif kind == "spherical_wrist_parallel":  # Puma / KR5 / industrial arms
        rows = (_revolute(u(0, 0.2), 90, u(), angle()) + _revolute(u(), 0, u(-0.2, 0.2), angle())
                + _revolute(u(0, 0.1), -90, u(-0.2, 0.2), angle()) + _revolute(0, 90, u(), angle())
                + _revolute(0, -90, 0, angle()) + _revolute(0, 0, u(), angle()))
    elif kind == "spherical_wrist_intersecting":  # and a wrist whose axes are not perpendicular
        rows = (_revolute(0, 90, u(), angle()) + _revolute(u(), _uniform(rng, 20, 70), u(-0.2, 0.2), angle())
                + _revolute(u(0, 0.1), -90, u(-0.2, 0.2), angle()) + _revolute(0, _uniform(rng, 30, 80), u(), angle())
                + _revolute(0, _uniform(rng, -80, -30), 0, angle()) + _revolute(0, 0, u(), angle()))
    elif kind == "spherical_wrist_prismatic":  # Stanford arm
        rows = (_revolute(0, -90, u(), angle()) + _revolute(0, 90, u(), angle())
                + f"  - {{type: prismatic, a: {u(0, 0.05)}, alpha: 0, theta: {angle()}, offset: {u()}}}\n"
                + _revolute(0, -90, 0, angle()) + _revolute(0, 90, 0, angle()) + _revolute(0, 0, u(), angle()))
    elif kind == "three_parallel":  # Universal Robots; odd seeds with axis 5 not perpendicular to h
        twist = 90 if seed % 2 == 0 else _uniform(rng, 30, 80)
        rows = (_revolute(0, 90, u(), angle()) + _revolute(-u(), 0, 0, angle()) + _revolute(-u(), 0, 0, angle())
                + _revolute(0, twist, u(), angle()) + _revolute(0, -90, u(), angle()) + _revolute(0, 0, u(), angle()))
    text = (f"name: random_{kind}_{seed}\nconvention: standard\nangle_unit: deg\njoints:\n{rows}"
            f"base: {_pose(rng, planar)}\ntool: {_pose(rng, planar)}\n" + (f"task: {task}\n" if task else ""))
    return parse_robot(text.encode())


EAIK_CLASSES = {"spherical_wrist_parallel", "spherical_wrist_intersecting", "three_parallel"}
RANDOM_CLASSES = ["planar_2r", "planar_3r", "scara", "yaw_pitch", "spherical_wrist_parallel",
                  "spherical_wrist_intersecting", "spherical_wrist_prismatic", "three_parallel"]


def _c_ik(generated, arm, real):
    """A function target -> solutions (k, n) calling the C NAME_ik of `arm` (ik and its
    callees, compiled with the contract's warning flags)."""
    return functools.partial(c_ik, generated(arm, ("c",), real, ("ik",)).library("ik"))


def _c_ik_numeric(library, target, q0, max_iter=IK_NUMERIC_DEFAULTS["max_iter"], tol=IK_NUMERIC_DEFAULTS["tol"]):
    """NAME_ik_numeric from q0: (q, status), with the generated Python's defaults."""
    return library.call("ik_numeric", target, q0, max_iter, tol)


def _reference_targets(arm):
    """Batched fk (pose tasks) or task vector of jacgen.reference."""
    single = reference.fk if _pose_task(arm) else reference.task
    return lambda q: np.array([single(arm, row) for row in q])


@pytest.mark.parametrize("kind", RANDOM_CLASSES)
def test_random_robots_of_each_class(kind, generated):
    """Random dimensions, offsets, axis directions, base and tool: round trips through
    jacgen.reference, the revolute 6R classes also against EAIK."""
    for seed in range(2):
        arm = _random_robot(kind, seed)
        module = generated(arm, functions=("ik",)).python  # the function under test, and its callees
        q = np.random.default_rng(seed).uniform(-np.pi, np.pi, (100, arm.dof))
        q[:, [not joint.revolute for joint in arm.joints]] *= 0.1
        counts = _check_round_trip(arm, _batched(module), _reference_targets(arm), q, regular(arm, q))
        assert counts.max() == module.MAX_IK_SOLUTIONS
        if seed == 0:  # the C: the Python's solutions in the Python's order; float compiles cleanly
            solve = _c_ik(generated, arm, "double")
            targets = _reference_targets(arm)(q[:50])
            for target, python in zip(targets, _batched(module, limits=True)(targets)):
                ours = solve(target)
                assert len(ours) == len(python) and (not len(ours) or wrapped_distance(arm, ours, python).max() < 1e-6)
            _c_ik(generated, arm, "float")
        if kind in EAIK_CLASSES:
            _compare_with_eaik(module, arm, q[:50], _reference_targets(arm))


# -- edges: out of reach, not finite -----------------------------------------------------------


def test_unreachable_targets_give_no_solution(modules):
    for name in WITH_IK:
        module, arm = modules[name], robot(name)
        target = _targets(module, arm, random_configurations(arm, 1, seed=14)[0])
        if name == "stanford":  # the prismatic joint has no limit here: reach is unbounded
            continue
        far = target.copy()
        if _pose_task(arm):
            far[:3, 3] += 10.0
        else:
            far[:2] += 10.0
        assert module.ik(far).shape == (0, arm.dof), name
        nan = target.copy()
        nan.flat[0] = np.nan
        assert module.ik(nan).shape == (0, arm.dof), name
    assert modules["rexarm"].ik([0.2, 0.0, 0.1, 2.0]).shape == (0, 4)  # pitch beyond 90 deg
    # the Stanford arm's wrist centre (its tool point) cannot come within d2 of the shoulder point
    shoulder = np.eye(4)
    shoulder[2, 3] = 0.412
    assert modules["stanford"].ik(shoulder).shape == (0, 6)


# -- the C, double and float ------------------------------------------------------------------------


@pytest.fixture(scope="module", params=["double", "float"])
def c_solvers(request, generated):
    """Per robot: a function target -> solutions (k, n) calling NAME_ik, and NAME_ik_numeric
    (double: the committed C; float: the functions this fixture calls, generated here)."""
    real = request.param
    solvers = {}
    for name in WITH_IK + FREE_JOINT:
        code = generated.committed(name) if real == "double" else generated(robot(name), ("c",), real,
                                                                            ("ik", "ik_numeric"))
        library = code.library(*(("ik", "ik_numeric") if name in WITH_IK else ("ik_numeric",)))
        closed = functools.partial(c_ik, library) if name in WITH_IK else None  # see test_free_joint
        solvers[name] = (closed, functools.partial(_c_ik_numeric, library))
    return real, solvers


@pytest.mark.parametrize("name", WITH_IK)
def test_c_ik_agrees_with_python(modules, c_solvers, name):
    """4000 random configurations: the double C reaches the targets to 1e-9 with the Python's
    solutions in the Python's order; the float C has the same counts except within float
    precision of a branch boundary (0.5 % allowed) and reaches the targets to 1e-2."""
    real, solvers = c_solvers
    arm, module, solve = robot(name), modules[name], solvers[name][0]
    q = random_configurations(arm, 4 * SAMPLES, seed=15)
    targets = _targets(module, arm, q)
    different, worst = 0, 0.0
    for target, python in zip(targets, _batched(module, limits=True)(targets)):
        ours = solve(target)
        assert np.all(np.isfinite(ours))
        if len(ours) != len(python):
            different += 1
            continue
        if len(ours) == 0:
            continue
        reached = _targets(module, arm, ours)
        worst = max(worst, target_error(arm, reached, np.broadcast_to(target, reached.shape)).max())
        if real == "double":  # the same branches in the same order (angles near a singularity
            assert wrapped_distance(arm, ours, python).max() < 1e-6  # are ill-conditioned)
    assert different == 0 if real == "double" else different <= len(q) // 200
    assert worst < (TOLERANCE if real == "double" else 1e-2)
    assert len(solve(np.full(targets.shape[1:], np.nan))) == 0


# -- ik_numeric -----------------------------------------------------------------------------------


@pytest.mark.parametrize("name", WITH_IK + FREE_JOINT)
def test_ik_numeric_converges_from_nearby(modules, c_solvers, name):
    real, solvers = c_solvers
    arm, module, numeric = robot(name), modules[name], solvers[name][1]
    rng = np.random.default_rng(16)
    tolerance = 1e-10 if real == "double" else 1e-4
    for q in random_configurations(arm, 10, seed=17):
        target = _targets(module, arm, q)
        start = q + rng.normal(0.0, 0.05, arm.dof)
        for solve in (module.ik_numeric, numeric):
            found, status = solve(target, start, 100, tolerance)
            assert status == 0, (name, solve, status)
            assert target_error(arm, _targets(module, arm, found)[None], target[None])[0] < 10 * tolerance


def test_ik_numeric_statuses_and_limits(modules, c_solvers):
    _, solvers = c_solvers
    arm, module, numeric = robot("puma560"), modules["puma560"], solvers["puma560"][1]
    lower, upper = np.array([joint.limits for joint in arm.joints]).T
    target = module.fk(np.zeros(6))
    target[:3, 3] += 5.0  # out of reach
    for solve in (module.ik_numeric, numeric):
        found, status = solve(target, np.zeros(6), 200, 1e-10)
        assert status in (1, 2)
        assert np.all(found >= lower - 1e-6) and np.all(found <= upper + 1e-6)
        found, status = solve(module.fk(np.zeros(6)), np.full(6, 10.0), 200, 1e-10)  # q0 beyond the limits
        assert np.all(found >= lower - 1e-6) and np.all(found <= upper + 1e-6)
    assert numeric(np.full(16, np.nan), np.zeros(6))[1] == 3
    assert numeric(module.fk(np.zeros(6)), np.zeros(6), -1)[1] == 3
    assert module.ik_numeric(module.fk(np.zeros(6)), np.zeros(6), 0)[1] == 0


def test_runtime_parameters(generated):
    """A symbolic d3 on the Puma: the constants become expressions in it, in Python (keyword)
    and C (the params struct)."""
    text = open(robot("puma560").source).read().replace("name: puma560", "name: puma_runtime")
    text = text.replace("  d3: 0.15005 ", "  d3: {value: 0.15005, symbolic: true} ")
    code = generated(parse_robot(text.encode()), ("python", "c"))
    arm, module, library = code.robot, code.python, code.library("ik")
    q = random_configurations(robot("puma560"), 20, seed=18)
    for d3 in (0.15005, 0.3):
        for row in q:
            T = module.fk(row, d3=d3)
            assert len(module.ik(T, limits=False, d3=d3)) == 8
            found = module.ik(T, d3=d3)  # inside the limits, as the C returns them
            assert wrapped_distance(arm, found, row).min() < 1e-7
            in_c = c_ik(library, T, parameters={"d3": d3})
            assert in_c.shape == found.shape and np.abs(in_c - found).max() < 1e-9
