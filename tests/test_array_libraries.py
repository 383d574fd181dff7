"""The committed generated Python on numpy, JAX and PyTorch arrays (the array API), against
jacgen.reference: numbers, dtype and type preserved, jax.jit / vmap / grad, torch.autograd and
torch.compile. JAX runs in double precision (jax_enable_x64) except where float32 is tested.
PyTorch is tested where it is installed (CI installs the CPU build; see .ci/run)."""

import numpy as np
import pytest

from jacgen.checking import reference

from conftest import generated_module, random_configurations, robot

jax = pytest.importorskip("jax")
jax.config.update("jax_enable_x64", True)
jnp = jax.numpy
try:
    import torch
except ImportError:  # the tests of PyTorch are skipped, and say so
    torch = None

SAMPLES = 40
LIBRARIES = ["numpy", "jax", "torch"]
# One arm of each kind: 6R with a closed form, 7R with a free joint, prismatic joints and a 5-axis task.
ROBOTS = ["ur5", "panda", "stanford", "rexarm"]


def library(name):
    """(to the library's array, back to numpy, its array type)."""
    if name == "numpy":
        return np.asarray, np.asarray, np.ndarray
    if name == "jax":
        return jnp.asarray, np.asarray, jax.Array
    if torch is None:
        pytest.skip("PyTorch is not installed")
    return torch.from_numpy, lambda t: t.detach().numpy(), torch.Tensor


def as_tuple(value):
    return value if isinstance(value, tuple) else (value,)


def free_joint(module, q):
    return (q[:, module.IK_FREE_JOINT],) if hasattr(module, "IK_FREE_JOINT") else ()


@pytest.mark.parametrize("name", ROBOTS)
@pytest.mark.parametrize("lib", LIBRARIES)
def test_every_function_matches_the_reference(lib, name):
    to, back, kind = library(lib)
    arm, module = robot(name), generated_module(name)
    q = random_configurations(arm, SAMPLES, seed=11)
    q_dot = np.random.default_rng(12).normal(size=q.shape)

    def call(function, *arguments):
        results = as_tuple(getattr(module, function)(*map(to, arguments)))
        assert all(isinstance(r, kind) for r in results), function
        return [back(r) for r in results]

    for function in ("fk", "jacobian", "jacobian_tool"):
        want = getattr(reference, function)(arm, q)
        np.testing.assert_allclose(call(function, q)[0], want, atol=1e-12, rtol=0, err_msg=function)
    pose, jacobian = call("fk_jacobian", q)
    np.testing.assert_allclose(pose, reference.fk(arm, q), atol=1e-12, rtol=0)
    np.testing.assert_allclose(jacobian, reference.jacobian(arm, q), atol=1e-12, rtol=0)
    want = reference.jacobian_dot(arm, q, q_dot)
    np.testing.assert_allclose(call("jacobian_dot", q, q_dot)[0], want, atol=1e-9, rtol=0)
    np.testing.assert_allclose(call("hessian", q)[0], reference.hessian(arm, q), atol=1e-9, rtol=0)
    np.testing.assert_allclose(call("manipulability", q)[0], reference.manipulability(arm, q), atol=1e-10, rtol=1e-9)

    js = reference.singularity_jacobian(arm, q)
    mu_dot = np.random.default_rng(13).normal(size=js.shape[:2])
    rates, status = call("velocity_ik", q, mu_dot, np.full(SAMPLES, 1e-3))
    regularised = js @ np.swapaxes(js, 1, 2) + 1e-6 * np.eye(js.shape[1]) if js.shape[1] <= js.shape[2] else None
    if regularised is not None:  # Js^T (Js Js^T + d^2 I)^-1 mu_dot
        want = np.einsum("bji,bj->bi", js, np.linalg.solve(regularised, mu_dot[..., None])[..., 0])
        np.testing.assert_allclose(rates, want, atol=1e-8, rtol=1e-8)
    assert (status == module.VELOCITY_IK_OK).all()

    targets = reference.fk(arm, q)
    task = targets if len(arm.task) == 6 else reference.task(arm, q)
    start, step, cost = call("ik_numeric_step", task, q + 0.01, np.zeros(SAMPLES))
    assert (cost >= 0).all() and np.isfinite(step).all()
    _, status = call("ik_numeric", task, q + 0.01)
    assert status.dtype == np.int32 and (status == module.IK_NUMERIC_CONVERGED).all()
    _, status = module.ik_numeric(to(task[0]), to(q[0] + 0.01))  # one target
    assert str(status.dtype).split(".")[-1] == "int32" and int(status) == module.IK_NUMERIC_CONVERGED

    if hasattr(module, "ik_branches"):
        branches, valid, _ = call("ik_branches", task, *free_joint(module, q))
        assert valid.any(axis=1).all()
        reached = reference.fk(arm, branches[valid])
        wanted = np.repeat(targets, valid.sum(axis=1), axis=0)
        if len(arm.task) == 6:
            np.testing.assert_allclose(reached, wanted, atol=1e-8, rtol=0)
        else:
            np.testing.assert_allclose(reference.task(arm, branches[valid]),
                                       np.repeat(task, valid.sum(axis=1), axis=0), atol=1e-8, rtol=0)
        nearest, status = call("ik_nearest", task, q + 0.01, *free_joint(module, q))
        assert status.dtype == np.int32 and (status == module.IK_NEAREST_OK).all()
        np.testing.assert_allclose(nearest, q, atol=1e-6, rtol=0)  # the seed's own solution


@pytest.mark.parametrize("lib", LIBRARIES)
def test_float32_in_float32_out(lib):
    to, back, _ = library(lib)
    module, arm = generated_module("panda"), robot("panda")
    q = random_configurations(arm, SAMPLES, seed=5)
    single = lambda x: to(np.asarray(x, dtype=np.float32))  # noqa: E731
    targets = module.fk(q)
    results = {
        "fk_jacobian": module.fk_jacobian(single(q)),
        "manipulability": module.manipulability(single(q)),
        "velocity_ik": module.velocity_ik(single(q), single(np.ones((SAMPLES, 6)))),
        "ik_numeric_step": module.ik_numeric_step(single(targets), single(q)),
        "ik_branches": module.ik_branches(single(targets), single(q[:, module.IK_FREE_JOINT])),
        "ik_nearest": module.ik_nearest(single(targets), single(q), single(q[:, module.IK_FREE_JOINT])),
    }
    for function, result in results.items():
        for output in as_tuple(result):
            assert str(output.dtype).split(".")[-1] in ("float32", "bool", "int32"), (function, output.dtype)
    np.testing.assert_allclose(back(results["fk_jacobian"][1]), module.jacobian(q), atol=1e-5, rtol=0)


def test_jax_jit_and_vmap_give_the_eager_numbers():
    module, arm = generated_module("ur5"), robot("ur5")
    q = jnp.asarray(random_configurations(arm, SAMPLES, seed=7))
    targets = module.fk(q)
    cases = [("fk_jacobian", (q,), True), ("manipulability", (q,), False), ("ik_branches", (targets,), False),
             ("ik_numeric_step", (targets, q + 0.01), False), ("velocity_ik", (q, jnp.ones((SAMPLES, 6))), True)]
    for function, arguments, vmap in cases:
        eager = as_tuple(getattr(module, function)(*arguments))
        transforms = (jax.jit, jax.vmap) if vmap else (jax.jit,)
        for transformed in (transform(getattr(module, function)) for transform in transforms):
            for a, b in zip(map(np.asarray, eager), map(np.asarray, as_tuple(transformed(*arguments)))):
                if a.dtype != np.float64:  # truth values, statuses
                    np.testing.assert_array_equal(a, b, err_msg=function)
                    continue
                np.testing.assert_array_equal(np.isfinite(a), np.isfinite(b), err_msg=function)
                difference = np.where(np.isfinite(a), a - b, 0)
                if function == "ik_branches":  # angles: pi and -pi are the same solution
                    difference = np.angle(np.exp(1j * difference))
                scale = max(1.0, np.abs(a[np.isfinite(a)]).max())
                np.testing.assert_allclose(difference / scale, 0, atol=1e-9, err_msg=function)  # XLA reorders
    solutions, keep = jax.jit(module.ik)(targets)  # a batch: fixed size, with a mask
    assert solutions.shape == (SAMPLES, module.MAX_IK_SOLUTIONS, arm.dof) and keep.any(axis=1).all()


def finite_difference(function, q, step=1e-6):
    return np.stack([(function(q + step * e) - function(q - step * e)) / (2 * step) for e in np.eye(len(q))], -1)


@pytest.mark.parametrize("lib", ["jax", "torch"])
def test_gradients_match_the_generated_jacobians(lib):
    """d task / d q by automatic differentiation = task_jacobian; d fk / d q gives the
    jacobian's linear rows; the gradient of manipulability matches the reference's by
    central differences."""
    library(lib)
    for name in ("panda", "stanford"):
        module, arm = generated_module(name), robot(name)
        for q in random_configurations(arm, 2, seed=9):
            if lib == "jax":
                task_jacobian = np.asarray(jax.jacfwd(module.task)(jnp.asarray(q)))
                position_jacobian = np.asarray(jax.jacrev(lambda x: module.fk(x)[:3, 3])(jnp.asarray(q)))
                gradient = np.asarray(jax.grad(module.manipulability)(jnp.asarray(q)))
            else:
                x = torch.tensor(q, requires_grad=True)
                task_jacobian = torch.autograd.functional.jacobian(module.task, x).numpy()
                position_jacobian = torch.autograd.functional.jacobian(lambda v: module.fk(v)[:3, 3], x).numpy()
                module.manipulability(x).backward()
                gradient = x.grad.numpy()
            np.testing.assert_allclose(task_jacobian, module.task_jacobian(q), atol=1e-12, rtol=0)
            np.testing.assert_allclose(position_jacobian, reference.jacobian(arm, q)[:3], atol=1e-12, rtol=0)
            want = finite_difference(lambda x: reference.manipulability(arm, x), q)
            np.testing.assert_allclose(gradient, want, atol=1e-7, rtol=1e-6)


@pytest.mark.filterwarnings("ignore::UserWarning")  # Dynamo on array-api-compat's lru_cache
def test_torch_compile_gives_the_eager_numbers():
    library("torch")
    module = generated_module("ur5")
    q = torch.from_numpy(random_configurations(robot("ur5"), SAMPLES, seed=3))
    compiled = torch.compile(module.fk_jacobian, fullgraph=True)
    for a, b in zip(module.fk_jacobian(q), compiled(q)):
        np.testing.assert_allclose(a.numpy(), b.numpy(), atol=1e-12, rtol=0)
