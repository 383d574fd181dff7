"""examples/resolved_rate.py, as its README section runs it (on the committed generated/panda/
panda.py), over its first half second: the tool stays on the circle with and without
null-space motion, and the null-space motion raises the manipulability. Distances and
manipulability are jacgen/checking/reference.py's, not the generated module's."""

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.building import import_module
from jacgen.inputs.robot_file import load_robot
from conftest import ROOT


@pytest.fixture(scope="module")
def runs():
    """Half a second of both runs: the times, q (steps + 1, runs, 7), the targets, the null-space gains."""
    example = import_module(ROOT / "examples" / "resolved_rate.py", "resolved_rate")
    times, trajectory, targets = example.simulate(example.load("panda"), 0.5)
    return times, trajectory, targets, example.NULL_SPACE_GAINS


def test_resolved_rate_tracks_the_circle_and_null_space_motion_raises_the_manipulability(runs):
    times, trajectory, targets, gains = runs
    assert gains[0] == 0 and gains[1] > 0 and len(times) == 501
    panda = load_robot(ROOT / "robots" / "panda.yaml")
    reached = reference.fk(panda, trajectory)
    # The circle: RADIUS from its centre, in the plane of the start, with the start's orientation.
    centre = targets[0, :3, 3] + np.array([0.1, 0, 0])
    assert np.linalg.norm(targets[:, :3, 3] - centre, axis=-1) == pytest.approx(0.1, abs=1e-12)
    assert np.abs(targets[:, :3, :3] - targets[0, :3, :3]).max() == 0
    position_error = np.linalg.norm(reached[..., :3, 3] - targets[:, None, :3, 3], axis=-1)
    orientation_error = np.abs(reached[..., :3, :3] - targets[:, None, :3, :3]).max(axis=(-2, -1))
    assert position_error.max(axis=0) == pytest.approx([0, 0], abs=1e-4)  # both runs on the circle
    assert orientation_error.max() < 1e-4
    manipulability = reference.manipulability(panda, trajectory)
    assert manipulability[0, 0] == manipulability[0, 1]
    assert manipulability[-1, 1] > 1.2 * manipulability[-1, 0]  # the null-space run ends higher
    assert (manipulability[1:, 1] > manipulability[1:, 0]).all()  # and stays higher throughout
