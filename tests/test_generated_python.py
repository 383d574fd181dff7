"""Every function of the generated Python (generated/NAME/NAME.py) against jacgen.reference."""

import numpy as np
import pytest

from jacgen.checking import reference

from conftest import generated_module, random_configurations, robot
from support.ik import wrapped

SAMPLES = 300
# Near pitch = ±90 deg the Euler-angle rates blow up, and so does finite-difference error.
MIN_COS_PITCH = 0.05


def test_every_function_matches_the_reference(robot_name):
    arm = robot(robot_name)
    module = generated_module(robot_name)
    q = random_configurations(arm, SAMPLES, seed=3)
    for name in ("fk", "jacobian", "jacobian_tool"):
        want = np.array([getattr(reference, name)(arm, sample) for sample in q])
        np.testing.assert_allclose(getattr(module, name)(q), want, atol=1e-9, rtol=0, err_msg=name)

    pose, jacobian = module.fk_jacobian(q)
    np.testing.assert_allclose(pose, module.fk(q), atol=1e-15, rtol=0)
    np.testing.assert_allclose(jacobian, module.jacobian(q), atol=1e-15, rtol=0)

    mu, mu_want = module.task(q), reference.task(arm, q)
    angular = [i for i, component in enumerate(arm.task) if component in ("roll", "pitch", "yaw")]
    linear = [i for i, component in enumerate(arm.task) if component in ("x", "y", "z")]
    np.testing.assert_allclose(mu[:, linear], mu_want[:, linear], atol=1e-9, rtol=0)
    assert np.abs(wrapped(mu[:, angular] - mu_want[:, angular])).max(initial=0) < 1e-9

    rotations = reference.fk(arm, q)[:, :3, :3]
    regular = np.hypot(rotations[:, 0, 0], rotations[:, 1, 0]) > MIN_COS_PITCH
    assert regular.sum() > SAMPLES // 2
    want = reference.task_jacobian(arm, q[regular])
    np.testing.assert_allclose(module.task_jacobian(q[regular]), want, atol=1e-8, rtol=0)


@pytest.mark.parametrize("name", ["puma560", "panda"])
def test_batched_shapes(name):
    module = generated_module(name)
    dof = robot(name).dof
    single = np.zeros(dof)
    assert module.fk(single).shape == (4, 4)
    assert module.jacobian(np.zeros((2, 3, dof))).shape == (2, 3, 6, dof)
    assert module.task(single).shape == (6,)
    with pytest.raises(ValueError, match="shape"):
        module.fk(np.zeros(dof + 1))
