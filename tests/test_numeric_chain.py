"""jacgen.numeric_chain (the production's floating-point DH chain) against the independent
reference, on random arms of both conventions with prismatic joints, base and tool poses."""

import numpy as np
import pytest

from jacgen.inputs import numeric_chain
from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot
from support.random_arms import random_arm_text


@pytest.mark.parametrize("seed", range(12))
def test_frames_and_jacobian_equal_the_reference(seed):
    robot = parse_robot(random_arm_text(seed).encode(), f"<random arm {seed}>")
    q = np.random.default_rng(seed).uniform(-2.0, 2.0, (40, robot.dof))
    frames, tool = numeric_chain.axis_frames(robot, q)
    expected_frames, expected_tool = reference.frames(robot, q)
    assert np.allclose(tool, expected_tool, rtol=0, atol=1e-12)
    for frame, expected in zip(frames, expected_frames):  # each axis: its direction, and a point on it
        expected = np.broadcast_to(expected, frame.shape)
        assert np.allclose(frame[..., :3, 2], expected[..., :3, 2], rtol=0, atol=1e-12)
        offset = frame[..., :3, 3] - expected[..., :3, 3]
        assert np.allclose(np.cross(offset, expected[..., :3, 2]), 0.0, atol=1e-12)
    assert np.allclose(numeric_chain.jacobian(robot, q), reference.jacobian(robot, q), rtol=0, atol=1e-12)
