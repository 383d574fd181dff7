"""The configurations `jacgen verify` checks at: random ones inside the joint ranges, and
those at or near each singularity.
"""

import itertools
import math

import numpy as np

from jacgen.inputs.robot import Robot
from jacgen.model import singularities


def random_configurations(robot: Robot, count: int, rng: np.random.Generator) -> np.ndarray:
    ranges = np.array(robot.ranges)
    return rng.uniform(ranges[:, 0], ranges[:, 1], size=(count, robot.dof))


def singular_configurations(robot: Robot, singular: singularities.Singularities | None = None) -> np.ndarray:
    """Configurations at or near singularities, (k, dof), verified besides the random ones.

    Points on the zero set of each singularity factor (from `singular`, the robot's
    analysis, computed when not given), and a generic grid: revolute joints at 0 and
    +-pi/2 (all zero is the stretched-arm singularity of most arms), prismatic joints
    mid-travel, clipped into the limits; every combination for up to 4 revolute joints,
    otherwise all zero, one joint at +-pi/2 at a time, and pairs of joints at +-pi/2.
    """
    ranges = np.array(robot.ranges)
    revolute = [i for i, joint in enumerate(robot.joints) if joint.revolute]
    values = (0.0, math.pi / 2, -math.pi / 2)
    if len(revolute) <= 4:
        settings = list(itertools.product(values, repeat=len(revolute)))
    else:
        settings = [(0.0,) * len(revolute)]
        for count in (1, 2):
            for chosen in itertools.combinations(range(len(revolute)), count):
                for signs in itertools.product(values[1:], repeat=count):
                    setting = [0.0] * len(revolute)
                    for index, value in zip(chosen, signs):
                        setting[index] = value
                    settings.append(tuple(setting))
    grid = np.tile(ranges.mean(axis=1), (len(settings), 1))
    grid[:, revolute] = settings
    found = singularities.singular_configurations(robot, singular or singularities.analyse(robot))
    return np.vstack([np.clip(grid, ranges[:, 0], ranges[:, 1]), found])


def configurations(robot: Robot, singular: singularities.Singularities, samples: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The random samples, and those with the configurations near each singularity after
    them. The random ones are rounded to float32 so the float build sees exactly the
    reference's input; singular ones are not, since rounding would move them off the
    singular set."""
    random = random_configurations(robot, samples, np.random.default_rng(seed)).astype(np.float32).astype(np.float64)
    return random, np.vstack([random, singular_configurations(robot, singular)])
