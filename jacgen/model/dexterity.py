"""Dexterity (Angeles): the characteristic length L, the best condition number of Js over the
joint ranges, and a configuration where it is reached.

Js (`js_rank`) mixes rows in length units (x, y, z) with rows in radians (the angles), so its
condition number kappa = sigma_max / sigma_min depends on the length unit. Dividing the
position rows by a length L makes it a pure number; Angeles' characteristic length is the L
whose best (least) kappa over the configurations is least (J. Angeles, "Fundamentals of Robotic
Mechanical Systems": the characteristic length of the kinetostatic conditioning index). Where
that kappa is 1 the arm is isotropic there.

The search is numeric (the DH chain in floating point, `numeric_chain`), deterministic (fixed
seeds) and bounded (a fixed number of samples and steps): seeded configurations in the
joint ranges, each with the best L of a geometric grid; then the best few polished together by
a compass search in (q, log L) whose directions are a fresh seeded orthonormal basis each
step (so a valley along no coordinate axis does not stall it), the step grown after a move
and halved after none. For a task of only positions or only angles L scales every singular
value alike and cancels: the search is over q alone and L is 1 (NEUTRAL_LENGTH) unless the file
gives it; so it is where Js has lost rank at every configuration (kappa infinite for every L).

What it finds is the least kappa of a bounded search, not a proven global minimum: the least
kappa of a 6-axis arm sits where two singular values meet (a ridge, where kappa has no
gradient), which a compass search approaches slowly; nearby configurations may do better by
up to about 1e-3 (tests/test_dexterity.py), other basins by a few 1e-3. The planar 2R's
isotropic point (a one-dimensional cone) is found to rounding. The whole search costs about
0.1 s for a 6-axis arm, a few per cent of its generation.
"""

import math
from dataclasses import dataclass

import numpy as np

from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import EULER_ANGLES, Robot
from jacgen.model.js_rank import singularity_rows

SAMPLES = 192  # seeded configurations in the joint ranges
LENGTH_GRID = 8  # values of L per configuration, geometric over LENGTH_RANGE
LENGTH_RANGE = (1e-3, 10.0)  # where L is sought, times the arm's reach
CANDIDATES = 3  # the best configurations polished
POLISH_STEPS = 60  # compass steps at most (each one batch of every candidate's trial points)
FIRST_STEP, LARGEST_STEP, LAST_STEP = 0.02, 0.25, 1e-10  # in the unit cube of the search
GROWTH = 1.5  # of the step after a move (it halves after none)
ISOTROPIC = 1e-9  # kappa - 1 below it: isotropic
RANK_DEFICIENT = 1e-12  # sigma_min / sigma_max below it: Js has lost rank, kappa infinite
SIGNIFICANT_DIGITS = 6  # of a computed L: kappa is flat around its optimum, and L prints the same everywhere
NEUTRAL_LENGTH = 1.0  # L where it cannot change the best kappa: Js unchanged (and divided by 1 exactly)


@dataclass(frozen=True)
class Dexterity:
    """Angeles' characteristic length and the best-conditioned configuration of Js / L."""

    length: float  # L, in the robot file's length unit
    given: bool  # L from the file's `characteristic_length` rather than computed
    best_condition: float  # least kappa of Js with its position rows divided by L; inf: rank-deficient everywhere
    configuration: tuple[float, ...]  # a q (in the joint ranges) where it is reached
    length_matters: bool  # False for a task of only positions or only angles: L cancels from kappa

    @property
    def isotropic(self) -> bool:
        """kappa = 1 (to ISOTROPIC): every direction of the task equally easy at `configuration`."""
        return self.best_condition - 1 <= ISOTROPIC


def dexterity(robot: Robot) -> Dexterity:
    """The characteristic length (the file's, or Angeles' value) and the best kappa at it."""
    position_rows = np.array([component not in EULER_ANGLES for component in robot.task])
    length_matters = 0 < position_rows.sum() < len(robot.task)
    given = robot.characteristic_length
    search = _Search(robot, position_rows, given if given is not None else None if length_matters else NEUTRAL_LENGTH)
    u, v = search.start()
    u, v, best = search.polish(u, v)
    length = search.length
    if length is None:  # computed: rounded, and kappa at the rounded L
        length = float(f"{search.length_of(v):.{SIGNIFICANT_DIGITS}g}") if math.isfinite(best) else NEUTRAL_LENGTH
        best = float(search.condition(u, np.log(length)))
    return Dexterity(length, given is not None, best,
                     tuple(float(x) for x in search.configuration(u)), bool(length_matters))


class _Search:
    """kappa over the unit cube: u in [0, 1]^n the joints across their ranges, v in [0, 1]
    log L across LENGTH_RANGE (only while L is sought: `length` None)."""

    def __init__(self, robot: Robot, position_rows: np.ndarray, length: float | None):
        self.robot, self.position_rows, self.length = robot, position_rows, length
        self.ranges = np.array(robot.ranges)
        size = robot.reach or 1.0
        self.log_lengths = np.log(np.array(LENGTH_RANGE) * size)
        self.rng = np.random.default_rng(0)

    def configuration(self, u: np.ndarray) -> np.ndarray:
        return self.ranges[:, 0] + u * (self.ranges[:, 1] - self.ranges[:, 0])

    def log_length(self, v) -> np.ndarray:
        return self.log_lengths[0] + np.asarray(v) * (self.log_lengths[1] - self.log_lengths[0])

    def length_of(self, v) -> float:
        return float(np.exp(self.log_length(v)))

    def condition(self, u: np.ndarray, log_length) -> np.ndarray:
        """kappa at configurations u (..., n), position rows divided by exp(log_length) (...)."""
        return condition_number(singularity_jacobian(self.robot, self.configuration(u)),
                                self.position_rows, np.exp(log_length))

    def start(self) -> tuple[np.ndarray, np.ndarray]:
        """The CANDIDATES best of SAMPLES seeded configurations, each with its best L of the grid."""
        u = self.rng.random((SAMPLES, self.robot.dof))
        js = singularity_jacobian(self.robot, self.configuration(u))
        if self.length is None:
            grid = np.linspace(0, 1, LENGTH_GRID)
            kappa = condition_number(js[:, None], self.position_rows, np.exp(self.log_length(grid)))
            v = grid[np.argmin(kappa, 1)]
            kappa = kappa.min(1)
        else:
            v, kappa = np.zeros(SAMPLES), condition_number(js, self.position_rows, self.length)
        best = np.argsort(kappa, kind="stable")[:CANDIDATES]
        return u[best], v[best]

    def polish(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, float, float]:
        """The compass search from each candidate; the best point reached: u, v and kappa."""
        sought = self.length is None
        x = np.concatenate([u, v[:, None]], 1) if sought else u
        value = self._values(x)
        step = np.full(len(x), FIRST_STEP)
        for _ in range(POLISH_STEPS):
            if np.all(step < LAST_STEP) or not np.isfinite(value).any():
                break
            basis = np.linalg.qr(self.rng.standard_normal((x.shape[1],) * 2))[0]
            trials = np.clip(x[:, None] + step[:, None, None] * np.concatenate([basis, -basis])[None], 0, 1)
            values = self._values(trials)
            best = np.argmin(values, 1)
            moved = values[np.arange(len(x)), best] < value
            x = np.where(moved[:, None], trials[np.arange(len(x)), best], x)
            value = np.where(moved, values[np.arange(len(x)), best], value)
            step = np.where(moved, np.minimum(GROWTH * step, LARGEST_STEP), step / 2)
        winner = int(np.argmin(value))
        return (x[winner, :-1], x[winner, -1], float(value[winner])) if sought else (x[winner], 0.0, float(value[winner]))

    def _values(self, x: np.ndarray) -> np.ndarray:
        if self.length is None:
            return self.condition(x[..., :-1], self.log_length(x[..., -1]))
        return self.condition(x, np.log(self.length))


def condition_number(js: np.ndarray, position_rows: np.ndarray, length) -> np.ndarray:
    """kappa of Js (..., m, n) with its position rows divided by `length` (broadcast over the
    batch): sigma_max / sigma_min of its min(m, n) singular values, inf where Js has lost rank
    or is not finite (a task's Euler rates at pitch = +-90 deg)."""
    scale = np.where(position_rows, 1 / np.asarray(length, dtype=float)[..., None], 1.0)
    scaled = js * scale[..., None]
    finite = np.isfinite(scaled).all((-2, -1))
    sigma = np.linalg.svd(np.where(finite[..., None, None], scaled, 0.0), compute_uv=False)
    largest, least = sigma[..., 0], sigma[..., -1]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(least > RANK_DEFICIENT * largest, largest / least, np.inf)


def singularity_jacobian(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Js (..., m, n) at configurations q: rows of the geometric Jacobian, or, for a task with
    some but not all of roll, pitch, yaw, the task Jacobian (the angular velocity turned into
    ZYX Euler-angle rates)."""
    jacobian = numeric_chain.jacobian(robot, q)
    rows = singularity_rows(robot)
    if rows is not None:
        return jacobian[..., list(rows), :]
    rotation = numeric_chain.link_frames(robot, q)[1][..., :3, :3]
    pitch = np.arctan2(-rotation[..., 2, 0], np.hypot(rotation[..., 0, 0], rotation[..., 1, 0]))
    yaw = np.arctan2(rotation[..., 1, 0], rotation[..., 0, 0])
    (sp, cp), (sy, cy) = ((np.sin(a)[..., None], np.cos(a)[..., None]) for a in (pitch, yaw))
    wx, wy, wz = jacobian[..., 3, :], jacobian[..., 4, :], jacobian[..., 5, :]
    with np.errstate(divide="ignore", invalid="ignore"):  # inf at cos(pitch) = 0: kappa inf there
        roll_rate = (cy * wx + sy * wy) / cp  # w = E(rpy) rpy_dot, solved for the rates
        rates = {"roll": roll_rate, "pitch": -sy * wx + cy * wy, "yaw": wz + sp * roll_rate}
    task = {"x": jacobian[..., 0, :], "y": jacobian[..., 1, :], "z": jacobian[..., 2, :]} | rates
    return np.stack([task[component] for component in robot.task], -2)
