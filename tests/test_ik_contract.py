"""One behaviour for the closed-form ik and velocity_ik: tables of cases, each run on every
backend with the same expectations (C double through ctypes, numpy one target at a time,
numpy over a batch, CasADi), and velocity_ik of every shipped robot's committed code (numpy
over a batch, C). Targets and checks come from jacgen.reference and numpy's linear algebra,
never from a backend.

For ik every backend is a function `solve(targets) -> [solutions (k, n) per target]`; for
velocity_ik a function `(q, mu_dot, damping) -> (q_dot, status)`.
"""

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.solvers.differential import IK_NUMERIC_DEFAULTS

from conftest import ROBOT_NAMES, random_configurations, robot
from support.ik import reference_js, regular, target_error, without_limits, wrapped_distance

ROBOTS = ["puma560", "ur5", "stanford", "rexarm", "planar_3r", "scara"]
BACKENDS = ["c", "numpy", "numpy_batch", "casadi"]
TOLERANCE = 1e-9


# Our name for each backend -> the name `jacgen verify` calls it by (jacgen.generated_code); the
# numpy module one target at a time is this file's own.
VERIFIED = {"c": "c double", "numpy_batch": "python", "casadi": "casadi"}


@pytest.fixture(scope="module")
def backends(generated):
    """name -> (arm, {backend: solve}, {backend: ik_numeric}, {backend: velocity_ik}), each
    robot generated and compiled once (the `generated` fixture). Batches are called through
    jacgen.generated_code, as `jacgen verify` calls them; single targets through this wrapper."""
    def load(name):
        arm = without_limits(robot(name))  # these cases are about the branches (limits: test_ik_limits)
        code = generated(arm, ("c", "python", "casadi"))
        module, calls = code.python, code.backends

        def solve(backend):
            return lambda targets: calls.ik(backend, np.asarray(targets), None)[0]

        def numeric(backend):
            return lambda target, q0: tuple(v[0] for v in calls.call(backend, "ik_numeric", np.asarray(target)[None],
                                                                     np.asarray(q0)[None], *IK_NUMERIC_DEFAULTS.values()))

        def velocity(backend):
            return lambda q, mu_dot, damping: tuple(v[0] for v in calls.call(
                backend, "velocity_ik", np.asarray(q)[None], np.asarray(mu_dot)[None], damping))

        return arm, {
            "numpy": lambda targets: [module.ik(t) for t in targets],
            **{ours: solve(theirs) for ours, theirs in VERIFIED.items()},
        }, {
            "numpy": lambda target, q0: module.ik_numeric(target, q0),
            **{ours: numeric(theirs) for ours, theirs in VERIFIED.items()},
        }, {
            "numpy": lambda q, mu_dot, damping: tuple(np.asarray(v) for v in module.velocity_ik(q, mu_dot, damping)),
            **{ours: velocity(theirs) for ours, theirs in VERIFIED.items()},
        }

    return load


def _check_solutions(arm, solutions, target, count=None, original=None):
    """Every solution finite, revolute angles in (-pi, pi], reaching the target to 1e-9,
    distinct; the expected count; the original configuration among them."""
    assert np.all(np.isfinite(solutions)), solutions
    if count is not None:
        assert len(solutions) == count, (arm.name, len(solutions), count)
    if len(solutions):
        revolute = solutions[:, [joint.revolute for joint in arm.joints]]
        assert np.all((revolute > -np.pi) & (revolute <= np.pi))
        assert target_error(arm, reference.ik_target(arm, solutions), target).max() < TOLERANCE
        distances = [wrapped_distance(arm, a, b) for i, a in enumerate(solutions) for b in solutions[i + 1:]]
        assert min(distances, default=1.0) > 1e-6
    if original is not None:
        assert len(solutions) and wrapped_distance(arm, solutions, original).min() < 1e-7


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ROBOTS)
def test_round_trips(backends, name, backend):
    """Random configurations inside the limits: one solution set per target, none empty (each
    target was reached at its configuration), every solution reaching it, and the configuration
    itself among them where the arm is regular."""
    arm, solvers, _, _ = backends(name)
    q = random_configurations(robot(name), 60, seed=21)
    targets = reference.ik_target(arm, q)
    found = solvers[backend](targets)
    assert len(found) == len(targets), (len(found), len(targets))
    for row, target, solutions in zip(q, targets, found):
        assert len(solutions), (row, target)
        _check_solutions(arm, solutions, target, original=row if regular(arm, row) else None)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ROBOTS)
def test_not_finite_and_out_of_reach(backends, name, backend):
    """NaN or inf anywhere in the entries read, or a target beyond reach: no solution."""
    arm, solvers, _, _ = backends(name)
    target = reference.ik_target(arm, random_configurations(robot(name), 1, seed=22))[0]
    cases = []
    for k in range(3 * 4 if len(arm.task) == 6 else len(arm.task)):
        for bad in (np.nan, np.inf, -np.inf):
            broken = target.copy()
            broken.flat[k] = bad
            cases.append(broken)
    if name != "stanford":  # its prismatic joint has no limit: unbounded reach
        far = target.copy()
        if len(arm.task) == 6:
            far[:3, 3] += 10.0
        else:
            far[:2] += 10.0
        cases.append(far)
    if name == "rexarm":
        cases.append(np.array([0.2, 0.0, 0.1, 2.0]))  # pitch beyond 90 degrees
    found = solvers[backend](np.array(cases))
    assert len(found) == len(cases), (len(found), len(cases))  # one empty set per case, not none at all
    for case, solutions in zip(cases, found):
        assert solutions.shape == (0, arm.dof), (case, solutions)


# Targets on singularities: (robot, configuration, solutions expected, a solution expected
# among them or None). A double root is returned once and an angle the target leaves free is 0.
SINGULAR = {
    "wrist (puma q5 = 0): 3 regular arm branches x 2 + 1, with q4 = 0": (
        "puma560", [0.3, 0.5, -0.4, 0.6, 0.0, -0.2], 7, [0.3, 0.5, -0.4, 0.0, 0.0, 0.4]),
    "elbow stretched (puma): 2 shoulders x 1 elbow x 2 wrists": (
        "puma560", [0.3, 0.5, np.arctan2(0.0203, 0.4318) - np.pi / 2, 0.6, 0.4, -0.2], 4, None),
    "wrist (ur5 q5 = 0): 4 + 4, each wrist and its flip (q4, q6 + pi: the elbow elsewhere)": (
        "ur5", [0.3, -1.0, 1.2, 0.4, 0.0, 0.7], 8, None),
    "stretched planar 3R arm": ("planar_3r", [0.3, 0.0, 1.0], 1, None),
    "stretched planar 2R arm": ("planar_2r", [0.3, 0.0], 1, None),
}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", SINGULAR)
def test_singular_targets(backends, case, backend):
    name, q, count, among = SINGULAR[case]
    arm, solvers, _, _ = backends(name)
    target = reference.ik_target(arm, np.array(q, dtype=float))
    solutions = solvers[backend]([target])[0]
    _check_solutions(arm, solutions, target, count=count)
    if among is not None:
        assert wrapped_distance(arm, solutions, among).min() < 1e-12, solutions


def _puma_on_shoulder_singularity():
    """Puma with its wrist centre (origin of the frame of joint 5) in the plane of axes 1 and
    2 (q1 is then a double root): q2 by bisection on the centre's signed distance from that
    plane, measured with the reference's frames."""
    arm = robot("puma560")

    def distance(q2):
        axes, _ = reference.frames(arm, np.array([0.2, q2, -0.4, 0.6, 0.5, -0.2]))
        normal = np.cross(axes[0][:3, 2], axes[1][:3, 2])
        return np.dot(axes[4][:3, 3] - axes[0][:3, 3], normal)

    grid = np.linspace(-np.pi, np.pi, 73)
    k = next(i for i in range(len(grid) - 1) if distance(grid[i]) * distance(grid[i + 1]) < 0)
    low, high = grid[k], grid[k + 1]
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if distance(mid) * distance(low) > 0 else (low, mid)
    assert abs(distance(low)) < 1e-12
    return arm, np.array([0.2, low, -0.4, 0.6, 0.5, -0.2])


@pytest.mark.parametrize("backend", BACKENDS)
def test_shoulder_singularity(backends, backend):
    """The two shoulder branches meet: 1 x 2 elbows x 2 wrists, all reaching the target."""
    arm, q = _puma_on_shoulder_singularity()
    target = reference.ik_target(arm, q)
    _check_solutions(arm, backends("puma560")[1][backend]([target])[0], target, count=4, original=q)


def test_batched_numpy_finds_the_c_solution_sets(backends):
    """10^5 ur5 poses: batched numpy and C return the same solutions in the same order."""
    arm, solvers, _, _ = backends("ur5")
    q = random_configurations(robot("ur5"), 100_000, seed=23)
    targets = reference.ik_target(arm, q)
    batch, c = solvers["numpy_batch"](targets), solvers["c"](targets)
    assert len(batch) == len(c) == len(q), (len(batch), len(c), len(q))
    assert sum(map(len, batch)) > 4 * len(q)
    for ours, theirs in zip(batch, c):
        assert ours.shape == theirs.shape and (not len(ours) or np.abs(ours - theirs).max() < 1e-9)


# -- velocity_ik ------------------------------------------------------------------------------


DAMPING = 0.1


def _expected_rates(js, mu_dot, damping):
    """The closed forms of the contract, with numpy."""
    m, n = js.shape
    if m == n and damping == 0:
        return np.linalg.solve(js, mu_dot)
    if m <= n:
        return js.T @ np.linalg.solve(js @ js.T + damping**2 * np.eye(m), mu_dot)
    return np.linalg.solve(js.T @ js + damping**2 * np.eye(n), js.T @ mu_dot)


VELOCITY_ROBOTS = ["puma560", "ur5", "rexarm", "planar_2r", "iiwa"]
# Configurations where Js is singular (checked below with the SVD of the reference's Js and of
# the Js made from its geometric Jacobian alone).
SINGULAR_JS = {"puma560": [0.1, 0.5, -0.3, 0.2, 0.0, 0.4], "ur5": [0.3, -1.0, 1.2, 0.4, 0.0, 0.7],
               "planar_2r": [0.4, 0.0], "iiwa": [0.1, 0.5, 0.2, 0.0, 0.3, 0.4, 0.3]}


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", VELOCITY_ROBOTS)
def test_velocity_ik_cases(backends, name, backend):
    """Regular Js with damping 0 and 0.1; singular Js: status 1 and q_dot 0 without damping,
    the damped solution with; NaN or inf in q (first or last joint), mu_dot or damping, or
    damping < 0: status 2."""
    arm, _, _, velocity = backends(name)
    solve = velocity[backend]
    rng = np.random.default_rng(24)
    for q in random_configurations(arm, 5, seed=24):
        mu_dot = rng.normal(size=len(arm.task))
        js = reference.singularity_jacobian(arm, q)
        for damping in (0.0, DAMPING):
            q_dot, status = solve(q, mu_dot, damping)
            assert status == 0
            np.testing.assert_allclose(q_dot, _expected_rates(js, mu_dot, damping), atol=1e-9)
    mu_dot = np.ones(len(arm.task))
    if name in SINGULAR_JS:
        q = np.array(SINGULAR_JS[name])
        js = reference.singularity_jacobian(arm, q)
        assert np.linalg.svd(js, compute_uv=False)[-1] < 1e-12
        assert np.linalg.svd(reference_js(arm, q), compute_uv=False)[-1] < 1e-12
        q_dot, status = solve(q, mu_dot, 0.0)
        assert status == 1 and np.all(np.asarray(q_dot) == 0)
        q_dot, status = solve(q, mu_dot, DAMPING)
        assert status == 0
        np.testing.assert_allclose(q_dot, _expected_rates(js, mu_dot, DAMPING), atol=1e-9)
    q = random_configurations(arm, 1, seed=25)[0]
    for bad in (np.nan, np.inf):
        for joint in (0, -1):  # the first, and the last: often absent from Js, and still checked
            broken = q.copy()
            broken[joint] = bad
            assert solve(broken, mu_dot, 0.0)[1] == 2
        broken = mu_dot.copy()
        broken[0] = bad
        assert solve(q, broken, 0.0)[1] == 2
        assert solve(q, mu_dot, bad)[1] == 2
    q_dot, status = solve(q, mu_dot, -0.1)
    assert status == 2 and np.all(np.asarray(q_dot) == 0)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_velocity_ik_of_every_shipped_robot(generated, name):
    """The committed code, 20 random configurations: the batched numpy without damping (its
    default) solves Js q_dot = mu_dot with the minimum-norm solution (numpy's pinv: 7 axes), with
    damping gives the damped least squares, statuses VELOCITY_IK_OK; the C gives the closed
    forms with and without damping. Js here is made from the reference's geometric Jacobian
    alone (support.ik.reference_js), not taken from the reference's singularity_jacobian."""
    code = generated.committed(name)
    arm, module, library = code.robot, code.python, code.library("velocity_ik")
    assert (module.VELOCITY_IK_OK, module.VELOCITY_IK_SINGULAR, module.VELOCITY_IK_NOT_FINITE) == (0, 1, 2)
    q = random_configurations(arm, 20, seed=8)
    mu_dot = np.random.default_rng(1).normal(size=(20, len(arm.task)))
    undamped, status = module.velocity_ik(q, mu_dot)
    assert np.all(status == module.VELOCITY_IK_OK) and undamped.shape == (20, arm.dof)
    damped, status = module.velocity_ik(q, mu_dot, DAMPING)
    assert np.all(status == module.VELOCITY_IK_OK) and damped.shape == (20, arm.dof)
    for x, target, rates, damped_rates in zip(q, mu_dot, undamped, damped):
        js = reference_js(arm, x)
        assert np.abs(js @ rates - target).max() < 1e-9
        np.testing.assert_allclose(rates, np.linalg.pinv(js) @ target, atol=1e-9)
        np.testing.assert_allclose(damped_rates, _expected_rates(js, target, DAMPING), atol=1e-9)
        for damping in (0.0, DAMPING):
            c_rates, c_status = library.call("velocity_ik", x, target, damping)
            assert c_status == 0
            np.testing.assert_allclose(c_rates, _expected_rates(js, target, damping), atol=1e-9)


# -- ik_numeric -------------------------------------------------------------------------------


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ["puma560", "rexarm", "iiwa", "planar_2r"])
def test_ik_numeric_cases(backends, name, backend):
    """Converged from 0.1 away (and the target reached, by the reference); NaN or inf in the
    target or q0: status 3 and q = q0; a target out of reach: stalled or at the iteration
    limit, never converged, q finite and inside the limits."""
    arm, _, numeric, _ = backends(name)
    solve = numeric[backend]
    q = random_configurations(arm, 4, seed=26)
    for row, target in zip(q, reference.ik_target(arm, q)):
        start = np.clip(row + 0.1, *np.array([j.limits or (-np.inf, np.inf) for j in arm.joints]).T)
        found, status = solve(target, start)
        assert status == 0
        assert target_error(arm, reference.ik_target(arm, np.array([found])), target).max() < 1e-8
    target = reference.ik_target(arm, q[:1])[0]
    for bad in (np.nan, np.inf):
        broken = target.copy()
        broken.flat[0] = bad
        found, status = solve(broken, q[1])
        assert status == 3 and np.array_equal(found, q[1])
        start = q[1].copy()
        start[0] = bad
        found, status = solve(target, start)
        assert status == 3 and np.array_equal(found, start, equal_nan=True)
    far = target.copy()
    if len(arm.task) == 6:
        far[:3, 3] += 10.0
    else:
        far[:2] += 10.0
    found, status = solve(far, q[1])
    low, high = np.array([j.limits or (-np.inf, np.inf) for j in arm.joints]).T
    assert status in (1, 2) and np.all(np.isfinite(found)) and np.all((found >= low) & (found <= high))


@pytest.mark.parametrize("name", ["ur5", "puma560", "panda"])
def test_ik_numeric_stalls_out_of_reach(generated, name):
    """A target 100 m out of reach, where each step lowers the error less than the one before
    without end: the damping rises and ik_numeric stalls within 200 steps (it ran to any
    max_iter, 10^5 looked like a hang), numpy and C; q inside the limits, the tool nearer the
    target than at q0."""
    arm, code = robot(name), generated.committed(name)
    q0 = np.full(arm.dof, 0.3)
    far = reference.fk(arm, q0)
    far[:3, 3] += 100.0
    low, high = np.array([j.limits or (-np.inf, np.inf) for j in arm.joints]).T
    library = code.library("ik_numeric")
    for solve in (code.python.ik_numeric,
                  lambda *given: library.call("ik_numeric", *given, IK_NUMERIC_DEFAULTS["tol"])):
        found, status = solve(far, q0, 200)
        assert status == code.python.IK_NUMERIC_STALLED
        assert np.all((found >= low) & (found <= high))
        distance = [np.linalg.norm(reference.fk(arm, q)[:3, 3] - far[:3, 3]) for q in (found, q0)]
        assert distance[0] < distance[1]
