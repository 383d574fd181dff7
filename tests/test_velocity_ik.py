"""velocity_ik (Python and C) against numpy: Js q_dot = mu_dot, pseudo-inverse, damped least
squares, and the statuses (the same in both)."""

import ctypes

import numpy as np
import pytest

from jacgen.compile import compile_shared

from conftest import GENERATED, ROBOT_NAMES, generated_module, random_configurations, robot
from test_analysis import reference_js

DAMPING = 0.1


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """The committed Python module of a robot and its C, compiled into a shared library."""
    folder = tmp_path_factory.mktemp("velocity_ik")
    cache = {}

    def build(name):
        if name not in cache:
            library = compile_shared([GENERATED / name / f"{name}.c"], folder / f"lib{name}.so")
            cache[name] = (generated_module(name), ctypes.CDLL(str(library)))
        return cache[name]
    return build


def c_velocity_ik(library, name, q, mu_dot, damping):
    function = getattr(library, f"{name}_velocity_ik")
    pointer = ctypes.POINTER(ctypes.c_double)
    function.argtypes = [pointer, pointer, ctypes.c_double, pointer]
    function.restype = ctypes.c_int
    q, mu_dot = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(mu_dot, dtype=float)
    q_dot = np.full(len(q), np.nan)
    status = function(q.ctypes.data_as(pointer), mu_dot.ctypes.data_as(pointer), damping, q_dot.ctypes.data_as(pointer))
    return q_dot, status


def expected(js, mu_dot, damping):
    """The closed forms of SPEC §2, with numpy."""
    m, n = js.shape
    if m == n and damping == 0:
        return np.linalg.solve(js, mu_dot)
    if m <= n:
        return js.T @ np.linalg.solve(js @ js.T + damping**2 * np.eye(m), mu_dot)
    return np.linalg.solve(js.T @ js + damping**2 * np.eye(n), js.T @ mu_dot)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_solves_the_rates_away_from_singularities(name, generated):
    arm = robot(name)
    module, library = generated(name)
    q = random_configurations(arm, 20, seed=8)
    mu_dot = np.random.default_rng(1).normal(size=(20, len(arm.task)))
    q_dot, status = module.velocity_ik(q, mu_dot)
    assert (status == module.VELOCITY_IK_OK).all() and q_dot.shape == (20, arm.dof)
    for x, target, rates in zip(q, mu_dot, q_dot):
        js = reference_js(arm, x)
        assert np.abs(js @ rates - target).max() < 1e-9
        np.testing.assert_allclose(rates, np.linalg.pinv(js) @ target, atol=1e-9)  # minimum norm (7 axes)
        for damping in (0.0, DAMPING):
            c_rates, status = c_velocity_ik(library, name, x, target, damping)
            assert status == 0
            np.testing.assert_allclose(c_rates, expected(js, target, damping), atol=1e-9)
    damped, status = module.velocity_ik(q, mu_dot, DAMPING)
    assert (status == 0).all()
    want = [expected(reference_js(arm, x), target, DAMPING) for x, target in zip(q, mu_dot)]
    np.testing.assert_allclose(damped, want, atol=1e-9)


@pytest.mark.parametrize("name, singular", [("planar_2r", [0.4, 0.0]), ("puma560", [0.1, 0.5, -0.3, 0.2, 0.0, 0.4]),
                                            ("iiwa", [0.1, 0.5, 0.2, 0.0, 0.3, 0.4, 0.3])])
def test_singular_configuration_gives_the_status(name, singular, generated):
    arm = robot(name)
    module, library = generated(name)
    assert np.linalg.svd(reference_js(arm, singular), compute_uv=False)[-1] < 1e-12  # independently singular
    mu_dot = np.ones(len(arm.task))
    q_dot, status = module.velocity_ik(singular, mu_dot)
    assert status == module.VELOCITY_IK_SINGULAR and np.all(q_dot == 0)
    c_rates, status = c_velocity_ik(library, name, singular, mu_dot, 0.0)
    assert status == 1 and np.all(c_rates == 0)
    damped, status = module.velocity_ik(singular, mu_dot, DAMPING)  # damping makes it solvable
    assert status == 0 and np.all(np.isfinite(damped))
    assert c_velocity_ik(library, name, singular, mu_dot, DAMPING)[1] == 0
    bad = np.array(singular, dtype=float)
    bad[0] = np.nan
    assert c_velocity_ik(library, name, bad, mu_dot, 0.0)[1] == 2
    assert module.velocity_ik(bad, mu_dot)[1] == module.VELOCITY_IK_NOT_FINITE
    assert c_velocity_ik(library, name, singular, mu_dot, -1.0)[1] == 2
    assert module.velocity_ik(singular, mu_dot, -1.0)[1] == 2
