"""`jacgen verify`'s checks of the functions of velocity and dexterity whose results are not
unique or not well conditioned, so that they cannot be compared entry by entry with the
reference: each is held to what characterises its answer.

- velocity_ik, velocity_ik_nullspace, resolved_rate: backward errors, at the samples where Js
  is regular (there the answer is well defined): Js q_dot = mu_dot, and for the null-space
  solvers also q_dot - z in the row space of Js (so q_dot = Js^+ mu_dot + (I - Js^+ Js) z).
- velocity_ellipsoid: singular values against the reference's, U a rotation, and each singular
  vector within what its gap allows (`ellipsoid_error`).
- condition_number: the dexterity index 1 / kappa (in [0, 1], well conditioned where kappa is
  not: its relative error is ~ eps kappa), absolutely; 0 where Js is singular to the rounding
  of the backend's real type (contract §2).
- manipulability_gradient: entry by entry, but only where Js is regular: at a singularity the
  derivative of |sigma_min| has a kink.
"""

import math

import numpy as np

from jacgen.checking import reference
from jacgen.checking.generated_code import GeneratedCode
from jacgen.checking.result import Result, is_float
from jacgen.inputs.robot import Robot
from jacgen.model.tolerance_symbols import EPS, TOLERANCES
from jacgen.solvers.model import Model

# Functions of q that verify's comparison with the reference function of the same name leaves to this module.
CHECKED_HERE = ("velocity_ellipsoid", "condition_number", "manipulability_gradient")
# resolved_rate's targets: fk (or the task) this far from each sample, in radians and length units per joint.
TARGET_DISTANCE = 0.05


def characteristic_length(robot: Robot) -> float:
    """L, the length the position rows of Js are divided by in the condition number (the
    model's: Angeles' characteristic length, or the robot file's)."""
    return Model(robot).dexterity.length


def dexterity_results(robot: Robot, backends: GeneratedCode, q: np.ndarray, defined: np.ndarray, regular: np.ndarray,
                      tolerances: dict, product_tolerances: dict) -> list[Result]:
    """The rows of the functions of this module the robot has, at the samples q: `defined` where
    Js is defined (not at an Euler-angle singularity of a task Jacobian), `regular` where it is
    also far from singular."""
    generated, results = set(backends.signatures), []
    if "velocity_ellipsoid" in generated:
        errors = _per_backend(backends, "velocity_ellipsoid",
                              lambda backend: ellipsoid_error(robot, backends.call(backend, "velocity_ellipsoid", q), q))
        results.append(Result(robot.name, "velocity_ellipsoid", errors, tolerances,
                              f"at all {len(q)} samples: |s - s_ref| (SVD), U a rotation, "
                              "|u u^T - r r^T| gap / (1 + |J block|) (Wedin)"))
    if "condition_number" in generated:
        length = characteristic_length(robot)
        # kappa is infinite where Js is singular to the rounding of the backend's real type (EPS)
        expected = {real: 1 / reference.condition_number(robot, q[defined], length, float(TOLERANCES[real][EPS]))
                    for real in ("double", "float")}
        with np.errstate(divide="ignore"):  # a kappa of 0 (wrong) is an infinite error
            errors = _per_backend(backends, "condition_number", lambda backend: _largest(np.abs(
                1 / np.reshape(backends.call(backend, "condition_number", q[defined])[0], -1)
                - expected["float" if is_float(backend) else "double"])))
        results.append(Result(robot.name, "condition_number", errors, tolerances,
                              f"|1/kappa - 1/kappa_ref| at {int(defined.sum())} samples, position rows / L = {length:.6g}"))
    if "manipulability_gradient" in generated:
        expected = reference.manipulability_gradient(robot, q[regular])
        errors = _per_backend(backends, "manipulability_gradient", lambda backend: _largest(
            np.linalg.norm(backends.call(backend, "manipulability_gradient", q[regular])[0] - expected, axis=-1)
            / (1 + np.linalg.norm(expected, axis=-1))))
        results.append(Result(robot.name, "manipulability_gradient", errors, product_tolerances,
                              f"|g - g_ref| / (1 + |g_ref|) at the {int(regular.sum())} samples where Js is regular"))
    rng = np.random.default_rng(4)
    mu_dot, z = (rng.normal(size=(int(regular.sum()), size)) for size in (len(robot.task), robot.dof))
    if "velocity_ik_nullspace" in generated:
        results.append(_null_space_result(robot, backends, "velocity_ik_nullspace", q[regular], mu_dot, z,
                                          (mu_dot, z), tolerances))
    if "resolved_rate" in generated:
        targets = reference.ik_target(robot, q[regular] + TARGET_DISTANCE * rng.normal(size=z.shape))
        gain = rng.uniform(0.5, 2.0, size=mu_dot.shape)
        fed_back = mu_dot + gain * reference.task_error(robot, q[regular], targets)
        results.append(_null_space_result(robot, backends, "resolved_rate", q[regular], fed_back, z,
                                          (targets, mu_dot, gain, z), tolerances))
    return results


def _per_backend(backends: GeneratedCode, name: str, error_of) -> dict[str, float | None]:
    """error_of(backend) for each backend that has the function, None for the others."""
    return {backend: error_of(backend) if backends.has(backend, name) else None for backend in backends.names}


def _largest(errors: np.ndarray) -> float:
    """The largest error, infinite where one is NaN or infinite; 0 for none."""
    return float(np.max(np.where(np.isfinite(errors), errors, math.inf), initial=0.0))


def ellipsoid_error(robot: Robot, found: tuple[np.ndarray, ...], q: np.ndarray) -> float:
    """The largest error of velocity_ellipsoid's (U_v, s_v, U_w, s_w) at q, over both blocks A
    (J[:3] and J[3:] of the reference's `jacobian`):

    - |s_i - s_i,ref|, absolutely: a backward-stable SVD returns the exact singular values of
      A + E with |E| ~ eps |A|, within |E| of A's (Weyl), however small they are (where an
      eigenvalue solver of A A^T, the square roots of values within eps |A|^2, loses half the digits);
    - |U^T U - I| and |det U - 1|: U is a rotation;
    - each column u_i where it is defined. Singular vectors are not unique (each one's sign, any
      basis of a repeated value's space), so u_i is compared through its projector, which has no
      sign: |u_i u_i^T - r_i r_i^T| (spectral norm) is sin(theta_i), the angle to the reference's
      r_i. The exact singular vectors of A + E lie within sin(theta_i) <= |E| / gap_i of A's
      (Wedin), gap_i = min_{j != i} |s_i - s_j| (the reference's values, the zeros of a block
      of n < 3 columns among them). So sin(theta_i) gap_i / (1 + |A|) is within the tolerance:
      nothing is asked of a vector whose value is repeated (gap 0), everything of a well
      separated one.
    """
    expected, J = reference.velocity_ellipsoid(robot, q), reference.jacobian(robot, q)
    errors = []
    for block, rows in enumerate((slice(0, 3), slice(3, 6))):
        U, values = np.reshape(found[2 * block], (len(q), 3, 3)), np.reshape(found[2 * block + 1], (len(q), 3))
        U_ref, values_ref = expected[2 * block], expected[2 * block + 1]
        if not (np.isfinite(U).all() and np.isfinite(values).all()):
            return math.inf
        gaps = np.abs(values_ref[:, :, None] - values_ref[:, None, :]) + np.diag(np.full(3, math.inf))
        projectors = (np.einsum("kai,kbi->kiab", U, U) - np.einsum("kai,kbi->kiab", U_ref, U_ref))
        angles = np.linalg.norm(projectors, ord=2, axis=(-2, -1))
        size = np.linalg.norm(J[:, rows, :], ord=2, axis=(-2, -1))
        errors += [np.abs(values - values_ref), np.abs(np.swapaxes(U, 1, 2) @ U - np.eye(3)),
                   np.abs(np.linalg.det(U) - 1), angles * gaps.min(axis=2) / (1 + size[:, None])]
    return max(_largest(error) for error in errors)


def _null_space_result(robot: Robot, backends: GeneratedCode, name: str, q: np.ndarray, mu_dot: np.ndarray,
                       z: np.ndarray, arguments: tuple, tolerances: dict) -> Result:
    """The row of velocity_ik_nullspace or resolved_rate, called at q with `arguments` (and damping
    0), which must return velocity_ik_nullspace(q, mu_dot, z): the larger of its two backward errors."""
    errors, flagged = {}, {}
    for backend in backends.names:
        if not backends.has(backend, name):
            errors[backend] = None
            continue
        solved = backends.call(backend, name, q, *arguments, 0.0)
        residual, flagged[backend] = velocity_ik_residual(robot, solved, q, mu_dot, allow_singular=is_float(backend))
        errors[backend] = max(residual, _row_space_residual(robot, solved, q, z))
    what = "target_rate + gain e (e: the task error)" if name == "resolved_rate" else "mu_dot"
    return Result(robot.name, name, errors, tolerances,
                  f"velocity_ik's residual for mu_dot = {what}, and |(I - Js^+ Js)(q_dot - z)| / (|q_dot| + |z|), "
                  f"at the {len(q)} samples where Js is regular"
                  + "".join(f"; {backend}: {count} reported singular (float's threshold)"
                            for backend, count in flagged.items() if count))


def _row_space_residual(robot: Robot, solved: tuple[np.ndarray, np.ndarray], q: np.ndarray, z: np.ndarray) -> float:
    """The largest |(I - P)(q_dot - z)| / (|q_dot| + |z|), P = Js^+ Js the projector onto the row
    space of Js, where the status is OK: 0 exactly when q_dot - z = Js^+ (mu_dot - Js z), the
    null-space term (I - P) z being added to velocity_ik's minimum-norm answer. (The
    other residual, Js q_dot = mu_dot, fixes the row-space part.)"""
    q_dot, status = solved
    ok = np.asarray(status) == 0
    js = reference.singularity_jacobian(robot, q[ok])
    leaving = q_dot[ok] - z[ok]
    residual = leaving - np.einsum("kij,kj->ki", np.linalg.pinv(js) @ js, leaving)
    return _largest(np.linalg.norm(residual, axis=1)
                    / (np.linalg.norm(q_dot[ok], axis=1) + np.linalg.norm(z[ok], axis=1)))


def velocity_ik_residual(robot: Robot, solved: tuple[np.ndarray, np.ndarray], q: np.ndarray,
                          mu_dot: np.ndarray, allow_singular: bool = False) -> tuple[float, int]:
    """Largest backward error of velocity_ik's (q_dot, status) at q for mu_dot, and how many
    samples reported singular: the residual |Js q_dot - mu_dot| / (|Js| |q_dot| + |mu_dot|),
    scaled by what rounding alone leaves so the bound does not depend on how well
    conditioned Js is. A tall Js (m > n) has no exact solution: there the residual is that of
    the normal equations, Js^T (Js q_dot - mu_dot). A status other than OK is an infinite
    error, except that `allow_singular` lets a sample be reported singular: in float, a
    system whose R has a diagonal ratio below 1e-5 is, and the Gram matrix of a Js sampled
    here (condition number up to 1e3) reaches 1e6."""
    q_dot, status = solved
    singular = (status == 1) if allow_singular else np.zeros(len(q), dtype=bool)
    if np.any((status != 0) & ~singular):
        return math.inf, int(singular.sum())
    q, q_dot, mu_dot = q[~singular], q_dot[~singular], mu_dot[~singular]
    if not len(q):
        return 0.0, int(singular.sum())
    js = reference.singularity_jacobian(robot, q)
    residual = np.einsum("kij,kj->ki", js, q_dot) - mu_dot
    norm = np.linalg.norm(js, ord=2, axis=(1, 2))
    scale = norm * np.linalg.norm(q_dot, axis=1) + np.linalg.norm(mu_dot, axis=1)
    if len(robot.task) > robot.dof:
        residual, scale = np.einsum("kij,ki->kj", js, residual), norm * scale
    return float(np.max(np.linalg.norm(residual, axis=1) / scale, initial=0.0)), int(singular.sum())
