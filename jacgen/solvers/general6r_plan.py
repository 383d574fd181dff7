"""How the general 6R solver cuts its loop (`general6r`): of the 12 splits and 16 shifts of the
hidden joint's half angle, the plan that rates best on random configurations, and its fallback,
the plan that the generated solvers take at a target where the first one's leading matrix is
singular to rounding (contract §2, "The fallback elimination").
"""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from jacgen.inputs.robot import Robot
from jacgen.solvers.general6r import (SPLITS, Equations, Link, Split, chain_form, chain_product, equations,
                                      half_angle, shifted)

SAMPLES = 24  # random configurations that rate a split
WORST_CONDITION = 1e8  # a robot whose best split rates worse gets no general solver (ik_numeric only)
SHIFTS = 16  # origins of the hidden joint's half angle tried per split: multiples of 2 pi / SHIFTS
SHIFT_ANGLES = [2 * np.pi * k / SHIFTS for k in range(SHIFTS)]
TIE = 0.01  # a later candidate must rate 1% better: near ties (a shift and the shift + pi) go to the
# first, not to rounding noise of the machine's LAPACK, so that generated code is the same everywhere


@dataclass(frozen=True)
class Elimination:
    """A split's equations and the shift of its hidden angle (theta_a = shift + 2 atan(x)) that
    make the leading matrix, Q and the null vector best conditioned: `condition` is the largest
    of their median condition numbers over random configurations. `fallback`: the plan the
    solver takes at a target where this one's leading matrix is singular to rounding (its
    condition number above DEGENERATE), or None; chosen when first read, from `rated` (the
    ratings of every split, `elimination` keeps them), so that a 7R arm rates both its free
    joints but samples the degenerate set of the one it keeps only."""

    equations: Equations
    shift: float
    condition: float
    links: tuple = field(default=(), compare=False, repr=False)
    rated: tuple = field(default=(), compare=False, repr=False)  # none for a fallback

    @cached_property
    def fallback(self) -> "Elimination | None":
        return _fallback(list(self.links), self, self.rated) if self.rated else None


# A target where the leading matrix M2 of the solver's plan has a 1-norm condition number above
# this takes the fallback plan. The eigenvalues of a singular M2 are noise: at poses on its
# degenerate set the first plan finds 1 to 6 of the Puma 560's 8 solutions, at 1e-9 rad from it
# (condition 1e11) 6 to 8, at 1e-6 (1e8) all. Where the pencil is singular for every angle of
# the hidden joint (puma560_calibrated near q = (-2.12, -2.24, 1.55, 1.19, -2.16, any)), the
# condition is 8e7 at every shift, and 2 to 4 are lost. 0.01 to 0.25 % of random targets are
# above it (10^4 on each general and calibrated shipped arm), and pay the second eigenproblem.
DEGENERATE = 1e7
DEGENERATE_LINES = 24  # random lines in joint space searched for the first plan's degenerate set


def elimination(robot: Robot, free: int | None = None) -> Elimination:
    """The best conditioned of the 12 splits and 16 shifts (a matrix polynomial singular for
    every x, as the Jaco's is for the textbook split, rates as badly as a singular leading
    matrix; so do a Q of rank below 8, from which v_gh cannot be read back, and equations
    whose null space at a root has more than one vector, from which v_bc cannot), with its
    fallback: the best of the other splits rated also on the first plan's degenerate set
    (`_fallback`). Derivations are milliseconds each; the rating is a few hundred 12 x 12
    condition numbers."""
    _, links, _ = chain_form(robot, free)
    theta = np.random.default_rng(0).uniform(-np.pi, np.pi, (SAMPLES, 6))
    rated = tuple(_rated(links, split, theta) for split in SPLITS)
    best = None
    for equations_, conditions in rated:
        for shift, condition in conditions:
            if best is None or condition < best.condition * (1 - TIE):
                best = Elimination(equations_, shift, condition, tuple(links), rated)
    return best


def _rated(links: list[Link], split: Split, theta: np.ndarray) -> tuple[Equations, list[tuple[float, float]]]:
    """The split's equations, and (shift, condition) at each of the SHIFTS, `condition` as
    Elimination's at the configurations theta."""
    equations_ = equations(links, split)
    s0, ss, sc, q = _free_equations(equations_, links, theta)
    values = np.linalg.svd(q[..., :8], compute_uv=False)
    pair = float(np.median(values[..., 0] / np.maximum(values[..., -1], 1e-300)))  # v_gh from Q's columns
    # v_bc from the null vector of the equations at the configuration's own theta_a: one vector
    hidden = theta[:, split.joint(split.hidden)] * (-1 if split.backwards else 1)
    at_root = half_angle(s0 + np.sin(hidden)[:, None, None] * ss + np.cos(hidden)[:, None, None] * sc)
    singular = np.linalg.svd(at_root, compute_uv=False)
    vector = float(np.median(singular[..., 0] / np.maximum(singular[..., -2], 1e-300)))
    made = []
    for shift in SHIFT_ANGLES:
        leading = np.median(np.linalg.cond(_leading(s0, ss, sc, shift)))
        made.append((shift, float(max(leading, pair, vector))))
    return equations_, made


def _free_equations(equations_: Equations, links: list[Link], theta: np.ndarray) -> tuple[np.ndarray, ...]:
    """S0, Ss, Sc (the six equations free of v_gh, ..., 6, 9) and Q at the loop angles theta."""
    n = chain_product(links, theta)
    v = np.linalg.inv(n) if equations_.split.target_inverted else n
    p0, ps, pc, q = np.moveaxis(equations_.evaluated(np.concatenate([v[..., :3, :3].reshape(*v.shape[:-2], 9),
                                                                     v[..., :3, 3]], -1)), -3, 0)
    left = np.linalg.svd(q[..., :8])[0]
    left_null = np.swapaxes(left[..., 8:], -1, -2)
    return left_null @ p0, left_null @ ps, left_null @ pc, q


def leading_condition(equations_: Equations, links: list[Link], shift: float, theta: np.ndarray) -> np.ndarray:
    """The 1-norm condition number of the leading matrix M2 at the loop angles theta (..., 6),
    as the generated solvers measure it."""
    return np.linalg.cond(_leading(*_free_equations(equations_, links, theta)[:3], shift), 1)


def _leading(s0: np.ndarray, ss: np.ndarray, sc: np.ndarray, shift: float) -> np.ndarray:
    """The leading matrix M2 (..., 12, 12) of the pencil of the free equations S0, Ss, Sc, the
    hidden angle's half angle taken from `shift`."""
    return half_angle(s0 - shifted(ss, sc, shift)[1])


def degenerate_set(plan: Elimination, links: list[Link], lines: int, rng) -> np.ndarray:
    """Loop angles (k, 6) where the plan's leading matrix is singular: on random lines through
    joint space, where its determinant changes sign between 17 points, bisected to rounding."""
    starts, directions = rng.uniform(-np.pi, np.pi, (lines, 6)), rng.normal(size=(lines, 6))
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    grid = np.linspace(-np.pi, np.pi, 17)

    def sign(t):
        free = _free_equations(plan.equations, links, starts + t[:, None] * directions)[:3]
        return np.linalg.slogdet(_leading(*free, plan.shift))[0]

    signs = np.stack([sign(np.full(lines, t)) for t in grid], axis=1)
    change = signs[:, :-1] * signs[:, 1:] < 0
    crossing = change.any(axis=1)
    first = np.argmax(change, axis=1)
    low, high, low_sign = grid[first], grid[first + 1], signs[np.arange(lines), first]
    for _ in range(42):  # to 2 pi / 16 / 2^42 = 9e-14 rad
        middle = 0.5 * (low + high)
        same = sign(middle) == low_sign
        low, high = np.where(same, middle, low), np.where(same, high, middle)
    return (starts + 0.5 * (low + high)[:, None] * directions)[crossing]


def _fallback(links: list[Link], first: Elimination, rated: tuple) -> Elimination | None:
    """The plan for targets where `first` degenerates: of the other splits and their shifts, the
    one best by the larger of its rating and its worst leading-matrix condition on the first
    plan's degenerate set (`degenerate_set`, DEGENERATE_LINES lines). None where none is below
    WORST_CONDITION."""
    degenerate = degenerate_set(first, links, DEGENERATE_LINES, np.random.default_rng(1))
    best, best_rating = None, None
    for equations_, conditions in rated:
        if equations_.split == first.equations.split:
            continue
        free = _free_equations(equations_, links, degenerate)[:3]
        for shift, condition in conditions:
            worst = np.linalg.cond(_leading(*free, shift), 1).max(initial=0.0)
            rating = max(condition, float(worst))
            if best_rating is None or rating < best_rating * (1 - TIE):
                best, best_rating = Elimination(equations_, shift, condition), rating
    return best if best_rating is not None and best_rating <= WORST_CONDITION else None
