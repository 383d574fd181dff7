"""The closed forms exact up to their singularities: poses made with one joint at 10^-k and at
pi + 10^-k (k = 3 ... 15), for every shipped special class, in numpy (one batch) and in C.

- Every solution ik returns reaches its pose to 1e-9 (1 + reach), by jacgen.reference's fk.
- For k = 3 the configuration that made the pose is among the solutions, to 1e-6 rad.
- Every pose has a solution.

Closer to a singularity the split of a nearly free angle is not fixed by the pose to 1e-6, so
only the pose error is asked there. NAME_native (built with ik alone) runs them too: batched
through its SIMD kernels ("native double") and row by row through the C ("native double
scalar").
"""

import dataclasses

import numpy as np
import pytest

from jacgen.checking import reference

from conftest import robot
from support.ik import target_error, without_limits, wrapped_distance

# One robot of each shipped special class (planar, yaw_pitch, spherical wrist with parallel,
# intersecting (a free joint, a chain solved backwards) and prismatic shoulders, three parallel)
ROBOTS = ["planar_2r", "scara", "rexarm", "puma560", "kr5", "panda", "iiwa", "stanford", "ur5"]
BACKENDS = ["python", "c double", "native double", "native double scalar"]
EXPONENTS = range(3, 16)
TOLERANCE = 1e-9


def near_singular(arm, free, seeds=4):
    """(configurations, the joint set near 0 or pi, k) for each revolute joint but the free one,
    k, side (0 or pi) and sign, from `seeds` random configurations."""
    rng = np.random.default_rng(11)
    rows, joints, exponents = [], [], []
    for q0 in rng.uniform(-np.pi, np.pi, (seeds, arm.dof)):
        for joint in range(arm.dof):
            if not arm.joints[joint].revolute or joint == free:
                continue
            for k in EXPONENTS:
                for value in (10.0**-k, -10.0**-k, np.pi + 10.0**-k, np.pi - 10.0**-k):
                    q = q0.copy()
                    q[joint] = value
                    rows.append(q)
                    joints.append(joint)
                    exponents.append(k)
    return np.array(rows), np.array(joints), np.array(exponents)


def backends(generated, arm, backend: str) -> tuple:
    """(the numpy module, the backends that answer `backend`'s ik calls): the generated code's,
    or for a native backend NAME_native's, built once per robot with ik and its callees. The
    native arm is renamed NAME_ik: an extension module loads once per process, and a worker
    that runs tests/test_native.py after this file must find its own full NAME_native."""
    if not backend.startswith("native"):
        code = generated(arm, ("c", "python", "casadi"))
        return code.python, code.backends
    code = generated(dataclasses.replace(arm, name=f"{arm.name}_ik"), ("python", "casadi", "native"), functions=("ik",))
    return code.python, code.native_backends


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ROBOTS)
def test_exact_up_to_the_singularity(generated, name, backend):
    arm = without_limits(robot(name))
    python, calls = backends(generated, arm, backend)
    free = getattr(python, "IK_FREE_JOINT", None)
    q, joints, exponents = near_singular(arm, free)
    targets = reference.ik_target(arm, q)
    solutions, _ = calls.ik(backend, targets, None if free is None else q[:, free])
    scale = 1 + arm.reach
    for row, found in enumerate(solutions):
        where = f"{name} {backend}: joint {joints[row] + 1} at {q[row, joints[row]]!r} (k = {exponents[row]})"
        assert len(found), f"{where}: no solution"
        error = target_error(arm, reference.ik_target(arm, found), targets[row]).max()
        assert error <= TOLERANCE * scale, f"{where}: a solution {error:.2e} from its pose"
        if exponents[row] == 3:
            assert wrapped_distance(arm, found, q[row]).min() <= 1e-6, f"{where}: its configuration not found"


def test_the_ur5_pose_that_broke_the_wrist_rule(generated):
    """A pose 6.77e-7 rad from ur5's wrist singularity: the branches with q5 = 0 (taken as
    singular) were 6e-7 from it, and its own configuration was not among them."""
    arm = without_limits(robot("ur5"))
    q = np.array([-0.479485, -1.968904, -2.353171, -0.967762, 6.77e-7, 1.494600])
    target = reference.fk(arm, q)
    for backend in BACKENDS:
        [found], _ = backends(generated, arm, backend)[1].ik(backend, target[None], None)
        assert target_error(arm, reference.fk(arm, found), target).max() <= TOLERANCE * (1 + arm.reach)
        assert wrapped_distance(arm, found, q).min() <= 1e-9, backend
