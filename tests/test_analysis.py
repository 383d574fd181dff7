"""Singularity analysis against conditions derived independently of it.

Every expected condition comes from the textbooks' geometry (sin of a joint angle, a
prismatic joint at zero extension, the wrist point coplanar with two parallel axes or with
the first two axes), and each is first confirmed by the rank of the numpy reference Js at
configurations that satisfy it. The factors must vanish exactly there, nowhere else, and
multiply back to det(Js) (or the Gram determinant) at random configurations.
"""


import numpy as np
import pytest
import sympy
from scipy.optimize import brentq, minimize

from jacgen.model import kinematics
from jacgen.checking import reference
from jacgen.model.singularities import analyse
from jacgen.inputs.robot_file import parse_robot

from conftest import ROBOT_NAMES, generated_module, random_configurations, robot
from support.ik import reference_js
from support.random_arms import random_arm_text

RANK_TOLERANCE = 1e-9  # smallest / largest singular value of Js at a singular configuration


def rank_ratio(arm, q) -> float:
    s = np.linalg.svd(reference_js(arm, q), compute_uv=False)
    return s[-1] / s[0]


# --- independent conditions: f(arm, q) whose zero set is a singular set ----------------------

def sine(k):
    return lambda arm, q: np.sin(q[k])


def extension(k):
    return lambda arm, q: q[k] + arm.joints[k].offset.approx


def _axes(arm, q):
    frames, tool = reference.frames(arm, q)
    return [(f[:3, 3], f[:3, 2]) for f in frames], tool[:3, 3]


def elbow(j, k):
    """Wrist point (origin of the last axis frame) in the plane of parallel axes j and k."""
    def condition(arm, q):
        axes, _ = _axes(arm, q)
        (oj, n), (ok, _), (w, _) = axes[j], axes[k], axes[-1]
        return np.dot(np.cross(ok - oj, w - oj), n)
    return condition


def shoulder(point="wrist"):
    """The point in the plane through axis 1 spanned by axes 1 and 2 (Spong: the wrist
    centre on the axis of joint 1, shifted by the shoulder offset)."""
    def condition(arm, q):
        axes, tool = _axes(arm, q)
        p = axes[-1][0] if point == "wrist" else tool
        normal = np.cross(axes[0][1], axes[1][1])
        return np.dot(p - axes[0][0], normal / np.linalg.norm(normal))
    return condition


# robot -> [(condition, joint to solve it along)], one per expected factor
CONDITIONS = {
    "planar_2r": [(sine(1), 1)],
    "planar_3r": [(sine(1), 1)],
    "scara": [(sine(1), 1)],
    "rexarm": [(sine(2), 2), (shoulder("tool"), 1)],
    "puma560": [(elbow(1, 2), 2), (sine(4), 4), (shoulder(), 1)],
    "kr5": [(elbow(1, 2), 2), (sine(4), 4), (shoulder(), 1)],
    "ur5": [(sine(2), 2), (sine(4), 4), (shoulder(), 1)],
    "stanford": [(sine(1), 1), (extension(2), 2), (sine(4), 4)],
    "iiwa": [(sine(3), 3)],  # and the numeric Gram determinant (issue 9: never expanded)
    "panda": [],  # only the numeric Gram determinant
}


def solve_along(arm, condition, q, joint):
    """q with `joint` moved to a root of condition (a sign change on a grid, then brentq)."""
    lo, hi = (-np.pi, np.pi) if arm.joints[joint].revolute else (-2.0, 2.0)
    grid = np.linspace(lo - 0.01 * (hi - lo), hi, 400)

    def value(x):
        trial = q.copy()
        trial[joint] = x
        return condition(arm, trial)

    values = np.array([value(x) for x in grid])
    change = np.nonzero(np.sign(values[:-1]) != np.sign(values[1:]))[0]
    assert len(change), "no root on this line"
    root = q.copy()
    root[joint] = brentq(value, grid[change[0]], grid[change[0] + 1], xtol=1e-15, rtol=1e-15)
    return root


@pytest.fixture(scope="module")
def analyses():
    return {}


def analysed(cache, name):
    if name not in cache:
        arm = robot(name)
        result = analyse(arm)
        q = kinematics.joint_symbols(arm)
        functions = [sympy.lambdify([q], f.condition, "numpy") for f in result.factors]
        cache[name] = (arm, result, lambda x: np.array([f(x) for f in functions], dtype=float))
    return cache[name]


@pytest.mark.parametrize("name", sorted(CONDITIONS))  # the arms whose conditions are known in closed form
def test_factors_are_the_independent_conditions(name, analyses):
    arm, result, factors = analysed(analyses, name)
    expected = CONDITIONS[name]
    assert len(result.factors) == len(expected)
    assert result.complete == (arm.dof == len(arm.task))  # redundant arms: the Gram rest is numeric
    rng = np.random.default_rng(7)
    for q in random_configurations(arm, 20, seed=11):  # regular: no factor vanishes
        assert np.abs(factors(q)).min(initial=1.0) > 1e-6 and rank_ratio(arm, q) > 1e-6
    matched = set()
    for condition, joint in expected:
        if condition is None:
            continue
        for q in random_configurations(arm, 3, seed=int(rng.integers(1000))):
            singular = solve_along(arm, condition, q, joint)
            assert rank_ratio(arm, singular) < RANK_TOLERANCE  # the condition is a singularity
            values = np.abs(factors(singular))
            assert (values < 1e-8).sum() == 1, values  # exactly one factor vanishes there
            matched.add(int(np.argmin(values)))
    assert len(matched) == sum(condition is not None for condition, _ in expected)


@pytest.mark.parametrize("name", ["iiwa", "panda", "rexarm", "puma560"])
def test_every_factor_vanishes_only_where_js_is_singular(name, analyses):
    """Minimising factor^2 from random starts reaches its zero set, where the reference Js
    loses rank (a Gram cofactor touches 0 without changing sign, so no root bracketing;
    there the smallest singular value goes as sqrt(|factor|), hence the looser bound)."""
    arm, result, factors = analysed(analyses, name)
    for index, factor in enumerate(result.factors):
        reached = []
        for start in random_configurations(arm, 4, seed=5 + index):
            found = minimize(lambda x: factors(x)[index] ** 2, start, method="BFGS", options={"gtol": 1e-14})
            if abs(factors(found.x)[index]) < 1e-8:
                reached.append(found.x)
        assert reached
        assert all(rank_ratio(arm, q) < 1e-4 for q in reached)


def test_named_conditions():
    expected = {
        "planar_2r": ["sin(q2)"], "scara": ["sin(q2)"], "ur5": ["sin(q3)", "sin(q5)", None],
        "stanford": ["sin(q2)", "q3", "sin(q5)"], "puma560": [None, "sin(q5)", None],
    }
    for name, conditions in expected.items():
        result = analyse(robot(name))
        for factor, condition in zip(result.factors, conditions):
            if condition is not None:
                assert str(factor.condition) == condition
    puma = analyse(robot("puma560"))
    assert [f.roots for f in puma.factors][1] == (0, sympy.pi)
    assert puma.factors[1].meaning.startswith("wrist singularity")
    assert puma.factors[0].meaning.startswith("elbow")
    assert puma.factors[2].meaning.startswith("shoulder")


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_generated_determinant_and_manipulability(name):
    """constant * prod(factors) is det(Js) (or det(Js Js^T)) exactly, not just its zero set: the
    committed generated module (test_golden checks it is current)."""
    arm, module = robot(name), generated_module(name)
    q = random_configurations(arm, 25, seed=2)
    js = [reference_js(arm, x) for x in q]
    m, n = js[0].shape
    gram = np.array([np.linalg.det(j @ j.T if m <= n else j.T @ j) for j in js])
    np.testing.assert_allclose(module.manipulability(q), np.sqrt(gram), rtol=1e-8)
    if m == n:
        np.testing.assert_allclose(module.jacobian_det(q), [np.linalg.det(j) for j in js], rtol=1e-8)
    singular = analyse(arm)
    assert module.singularity_factors(q).shape == (25, len(singular.factors) + (not singular.complete))


def test_euler_singularity_of_a_pitch_task():
    """rexarm's Js divides by cos(pitch): its zero set is reported apart, at pitch = ±90°."""
    arm = robot("rexarm")
    result = analyse(arm)
    (factor,) = result.euler
    value = sympy.lambdify([kinematics.joint_symbols(arm)], factor.condition, "numpy")
    q = solve_along(arm, lambda a, x: value(x), random_configurations(arm, 1, seed=4)[0], 3)
    assert abs(abs(reference.rpy(reference.fk(arm, q)[:3, :3])[1]) - np.pi / 2) < 1e-6


@pytest.mark.parametrize("polynomial", ["c2**3 - 1/2", "4*c2**3 - 3*c2 - 1/5", "s2*c2 + s2 - 1/3", "c2 + 1"])
def test_roots_of_a_one_joint_factor(polynomial):
    """Roots from the polynomial in tan(q/2) (numeric above degree 2), against a dense scan
    of the factor over one turn: the same roots, each within 1e-9 (q = pi included)."""
    from jacgen.model.singularities import _Numeric
    from jacgen.model.joint_ring import JointRing

    arm = robot("planar_2r")
    ring = JointRing(arm)
    factor = ring.ring.from_expr(sympy.sympify(polynomial, locals={"c2": ring.atoms[1][0], "s2": ring.atoms[1][1]}))
    roots = np.array([float(r) for r in _Numeric(arm, ring)._roots(factor, 1)])
    value = sympy.lambdify(ring.atoms[1], ring.expr(factor), "numpy")
    grid = np.linspace(-np.pi, np.pi, 200001)
    values = value(np.cos(grid), np.sin(grid))
    scanned = grid[1:][(np.sign(values[:-1]) != np.sign(values[1:])) | (np.abs(values[1:]) < 1e-12)]
    scanned = np.unique(np.round(np.where(scanned <= -np.pi + 1e-4, np.pi, scanned), 3))
    assert len(roots) == len(scanned), (roots, scanned)
    assert np.allclose(np.sort(np.round(roots, 3)), scanned, atol=2e-3)
    assert np.all(np.abs(value(np.cos(roots), np.sin(roots))) < 1e-9)


def test_roots_with_the_cosine_of_an_angle_in_a_coefficient():
    """A two-joint arm (random arm 4345, task x, roll, yaw) whose base turns by 42.2438, 105.238,
    69.2617 deg: its one factor, of q1, has quadratic coefficients in cos and sin of those
    angles, whose roots are found numerically (sympy's closed form took seconds); the factor
    vanishes at each, and a dense scan over one turn finds no other."""
    arm = parse_robot(random_arm_text(4345, 2).encode(), "arm4345.yaml")
    [factor] = analyse(arm).factors
    assert factor.joints == (0,) and len(factor.roots) == 2
    value = sympy.lambdify(sympy.Symbol("q1"), factor.condition, "numpy")
    roots = np.array([float(r) for r in factor.roots])
    assert np.all(np.abs(value(roots)) < 1e-9)
    grid = np.linspace(-np.pi, np.pi, 200001)
    values = value(grid)
    scanned = grid[1:][np.sign(values[:-1]) != np.sign(values[1:])]
    assert np.allclose(np.sort(roots), scanned, atol=1e-4)
