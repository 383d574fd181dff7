"""NAME_native (`generate --lang native`): built by its own setup.py, verified against the
reference like every backend (one call and batched, SIMD and scalar, double and float), and a
drop-in for NAME.py on numpy arrays: the same names, constants, arguments, batch rules,
dtypes and exceptions. Its batches through threads and through dask on a cluster of two
processes give what NAME.py gives.

Four robots, one of each kind: a special 6R arm (ur5: closed-form ik), a 7-axis arm with a
free joint (panda), a general 6R arm (jaco: the eigensolver's ik) and a random 4-joint arm
with two symbolic parameters and no ik (seed 15). Building each takes about 20 s.
"""

import inspect
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from jacgen.cli import main
from jacgen.emission.generator import Generator
from jacgen.checking.generated_code import NATIVE_BACKENDS
from jacgen.building import host_instruction_set, import_module
from jacgen.files import write_files
from jacgen.emission.render import render_robot
from jacgen.inputs.robot_file import load_robot, parse_robot
from jacgen.checking.verify import verify_on_host
from support.random_arms import random_arm_text

ROOT = Path(__file__).resolve().parent.parent
ROBOTS = ("ur5", "panda", "jaco", "arm15")
# ur5's module holds every function. The others hold what their kind changes, beside the
# kinematics every test compares: the panda's seventh axis (the free joint's ik, the null space,
# a Jacobian that is not square), jaco's general 6R solver, arm15's symbolic parameters and its
# 15 joints. Whole, the four modules took 110 s to build; the C of each function is verified
# on every arm by the C's own tests, and the module's glue is the same for every function.
KINEMATICS = ("fk", "jacobian", "fk_jacobian", "task_jacobian", "hessian", "velocity_ik", "ik_numeric")
FUNCTIONS = {"panda": (*KINEMATICS, "link_velocities", "manipulability_gradient", "velocity_ik_nullspace",
                       "resolved_rate", "ik", "ik_nearest"),
             "jaco": (*KINEMATICS, "ik", "ik_nearest"),
             "arm15": KINEMATICS}


def _robot(name: str):
    if name == "arm15":
        return parse_robot(random_arm_text(15).encode(), "arm15.yaml")
    return load_robot(ROOT / "robots" / f"{name}.yaml")


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """Each robot generated in every language, NAME_native built, and verify's results: {name:
    (results, native module, numpy module, folder of the native sources)}."""
    folder = tmp_path_factory.mktemp("native")
    made = {}
    for name in ROBOTS:
        robot = _robot(name)
        results = verify_on_host(robot, 60, 0, folder, native=True, functions=FUNCTIONS.get(name))
        numpy_module = import_module(folder / name / "double" / name / f"{name}.py", f"_numpy_{name}")
        made[name] = results, sys.modules[f"{name}_native"], numpy_module, folder / name / "native" / name
    return made


@pytest.mark.parametrize("name", ROBOTS)
def test_verified_against_the_reference(built, name):
    """Every function of NAME_native, every way it is called, within verify's tolerances of the
    reference; and compared (not skipped) wherever NAME.py is."""
    results = built[name][0]
    assert results and not [r for r in results if r.failed], "\n".join(
        f"{r.function}: {r.errors}" for r in results if r.failed)
    for result in results:
        for backend in NATIVE_BACKENDS:
            assert (result.errors[backend] is None) == (result.errors["python"] is None), (result.function, backend)
    compared = {r.function for r in results if r.errors["native double"] is not None}
    assert {"fk", "fk_jacobian", "jacobian", "hessian", "velocity_ik", "ik_numeric"} <= compared
    if name != "arm15":
        assert {"ik", "ik_branches", "ik_nearest"} <= compared


@pytest.mark.parametrize("name", ROBOTS)
def test_same_api_as_the_numpy_module(built, name):
    """The public names, the constants' values and every function's arguments (names, order,
    defaults) of NAME.py; plus out=, threads= and simd= (ik: limits=, no out=)."""
    _, native, numpy_module, _ = built[name]

    def public(module):
        return {key for key in dir(module) if not key.startswith("_") and key != "numpy"}

    assert public(native) - {"gufuncs", "SIMD"} == public(numpy_module)
    for key in public(numpy_module):
        value = getattr(numpy_module, key)
        if not callable(value):
            assert getattr(native, key) == value, key
            continue
        shown = getattr(native, key).__doc__.split("\n")[0]
        expected = [f"{p.name}={p.default!r}" if p.default is not inspect.Parameter.empty else p.name
                    for p in inspect.signature(value).parameters.values() if p.kind != p.KEYWORD_ONLY]
        arguments = [a.replace("(1.0,) * DOF", repr((1.0,) * numpy_module.DOF)) for a in
                     re.fullmatch(rf"{key}\((.*)\)", shown)[1].split(", ")]
        assert arguments[:len(expected)] == expected, (key, shown)
        assert arguments[-2:] == ["threads=None", "simd=True"], shown


def test_batch_rules_dtypes_and_errors(built):
    """Lists, strided arrays, broadcasting between arguments, float32 in and out (the float C),
    integers as float64, out=, and the exceptions NAME.py raises."""
    _, ur5, numpy_ur5, _ = built["ur5"]
    rng = np.random.default_rng(3)
    q = rng.uniform(-3, 3, (5, 6))
    T, J = numpy_ur5.fk_jacobian(q)
    np.testing.assert_allclose(ur5.fk(q[0].tolist()), T[0], atol=1e-14)
    strided = np.asfortranarray(np.repeat(q, 2, axis=0)[::2])
    np.testing.assert_allclose(ur5.jacobian(strided), J, atol=1e-14)
    q_dot = rng.normal(size=(3, 1, 6))  # broadcast against q (5, 6): (3, 5)
    q_ddot_free = numpy_ur5.bias_acceleration(q, q_dot)
    np.testing.assert_allclose(ur5.bias_acceleration(q, q_dot), q_ddot_free, atol=1e-13)
    assert ur5.bias_acceleration(q, q_dot).shape == (3, 5, 6)
    single = q.astype(np.float32)
    assert ur5.fk(single).dtype == np.float32 and ur5.fk(single[0]).dtype == np.float32
    np.testing.assert_allclose(ur5.fk(single), T, atol=1e-5)
    assert ur5.fk(np.zeros(6, dtype=np.int64)).dtype == np.float64
    q_dot, status = ur5.velocity_ik(q, np.ones(6), 0.1)
    expected = numpy_ur5.velocity_ik(q, np.ones(6), 0.1)
    np.testing.assert_allclose(q_dot, expected[0], atol=1e-12)
    assert status.dtype == np.int32 and (status == expected[1]).all()
    for module in (ur5, numpy_ur5):  # ik_numeric's status, one target and a batch
        assert module.ik_numeric(T[0], q[0] + 0.01)[1].dtype == np.int32
        assert module.ik_numeric(T, q + 0.01)[1].dtype == np.int32
    out = (np.empty((5, 4, 4)), np.empty((5, 6, 6)))
    returned = ur5.fk_jacobian(q, out=out)
    assert returned[0] is out[0] and np.allclose(out[1], J, atol=1e-14)
    with pytest.raises(ValueError):
        ur5.fk(np.zeros(5))
    with pytest.raises(ValueError):
        numpy_ur5.fk(np.zeros(5))
    with pytest.raises(TypeError):
        ur5.fk()
    with pytest.raises(TypeError):
        ur5.fk(q, colour=1)


def test_ik_one_target_and_batch(built):
    """ik of one target: the valid rows in ik_branches' order, as (k, DOF); of a batch: (q, keep);
    limits=False keeps those outside the limits; a free joint is an argument."""
    _, ur5, numpy_ur5, _ = built["ur5"]
    rng = np.random.default_rng(4)
    targets = numpy_ur5.fk(rng.uniform(-3, 3, (50, 6)))
    for target in targets[:10]:
        np.testing.assert_allclose(ur5.ik(target), numpy_ur5.ik(target), atol=1e-12)
        assert ur5.ik(target, limits=False).shape == numpy_ur5.ik(target, limits=False).shape
    q, keep = ur5.ik(targets)
    expected_q, expected_keep = numpy_ur5.ik(targets)
    assert (keep == expected_keep).all()
    np.testing.assert_allclose(q[keep], expected_q[expected_keep], atol=1e-12)
    _, panda, numpy_panda, _ = built["panda"]
    target = numpy_panda.fk(np.array([0.1, -0.3, 0.2, -1.8, 0.1, 1.6, 0.4]))
    np.testing.assert_allclose(panda.ik(target, 0.4), numpy_panda.ik(target, 0.4), atol=1e-10)
    assert (panda.ik(target, 0.4)[:, 6] == 0.4).all()


def test_simd_and_scalar_batches_agree(built):
    """The SIMD kernels against the C function row by row on 10^5 rows: within 1e-13 for the
    kinematics, ik's valid and in_limits flags identical, its solutions within 1e-9 (a few ulp
    of the vector math, through IK's ill-conditioned branches); threads and a row's place in
    the batch change nothing; no floating-point warning from the selects' untaken sides."""
    _, ur5, _, _ = built["ur5"]
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, (100_000, 6))
    warnings.simplefilter("error")
    T, J = ur5.fk_jacobian(q)
    shifted = ur5.fk_jacobian(q[7:], threads=3)
    assert (shifted[0] == T[7:]).all() and (shifted[1] == J[7:]).all()
    T_scalar, J_scalar = ur5.fk_jacobian(q, simd=False)
    assert np.abs(T - T_scalar).max() < 1e-13 and np.abs(J - J_scalar).max() < 1e-13
    one_thread = ur5.fk_jacobian(q, threads=1)
    assert (one_thread[0] == T).all() and (one_thread[1] == J).all()
    branches, valid, in_limits = ur5.ik_branches(T)
    branches_scalar, valid_scalar, in_limits_scalar = ur5.ik_branches(T, simd=False)
    assert (valid == valid_scalar).all() and (in_limits == in_limits_scalar).all()
    assert np.abs(branches - branches_scalar)[valid].max() < 1e-9


def test_every_kind_of_robot_runs_batched_and_one_by_one(built):
    """The general 6R solver and the parameters of the random arm, batched and one call: the
    same as NAME.py (parameters as keywords, broadcast)."""
    _, jaco, numpy_jaco, _ = built["jaco"]
    rng = np.random.default_rng(6)
    targets = numpy_jaco.fk(rng.uniform(-2, 2, (20, 6)))
    q, keep = jaco.ik(targets)
    expected_q, expected_keep = numpy_jaco.ik(targets)
    assert keep.sum() == expected_keep.sum() and keep.sum() > 20
    np.testing.assert_allclose(numpy_jaco.fk(q[keep]), np.repeat(targets, keep.sum(axis=1), axis=0), atol=1e-9)
    _, arm, numpy_arm, _ = built["arm15"]
    q = rng.uniform(-2, 2, (7, arm.DOF))
    parameters = {name: value * 1.5 for name, value in numpy_arm.PARAMETERS.items()}
    np.testing.assert_allclose(arm.fk(q, **parameters), numpy_arm.fk(q, **parameters), atol=1e-13)
    np.testing.assert_allclose(arm.fk(q[0], **parameters), numpy_arm.fk(q[0], **parameters), atol=1e-13)
    np.testing.assert_allclose(arm.task_jacobian(q), numpy_arm.task_jacobian(q), atol=1e-12)


def test_dask_on_a_cluster_of_two_processes(built, monkeypatch):
    """10^5 poses on a dask.distributed LocalCluster of two worker processes, through the gufuncs
    (dask.array.apply_gufunc): fk_jacobian and ik equal the numpy module's."""
    distributed = pytest.importorskip("distributed")
    import dask.array as da

    _, ur5, numpy_ur5, _ = built["ur5"]
    monkeypatch.syspath_prepend(str(Path(ur5.__file__).parent))  # the workers start with this sys.path
    q = np.random.default_rng(7).uniform(-3, 3, (100_000, 6))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        chunks = da.from_array(q, chunks=(25_000, 6))
        # dask names the core dimensions (the gufunc's own signature is "(6)->(4,4),(6,6)")
        T, J = da.apply_gufunc(ur5.gufuncs.fk_jacobian, "(j)->(r,c),(k,j)", chunks, output_dtypes=[float, float],
                               output_sizes={"r": 4, "c": 4, "k": 6})
        _, valid, in_limits = da.apply_gufunc(ur5.gufuncs.ik_branches, "(r,c)->(b,j),(b),(b)", T,
                                              output_dtypes=[float, bool, bool], output_sizes={"b": 8, "j": 6})
        futures = client.compute([T, J, valid & in_limits])
        distributed.wait(futures, timeout=120)  # a worker that cannot import the module would retry forever
        T, J, keep = client.gather(futures)
    expected_T, expected_J = numpy_ur5.fk_jacobian(q)
    assert np.abs(T - expected_T).max() < 1e-13 and np.abs(J - expected_J).max() < 1e-13
    assert (keep == numpy_ur5.ik(T)[1]).all()


# What NAME_native.SIMD says for the kernels of each instruction set (a build with vector math).
SIMD_NAMES = {"avx512f": "avx512f", "avx2": "avx2", "default": "baseline"}


def test_builds_for_this_machine_compile_one_instruction_set(built):
    """jacgen's own builds (jacgen.arm, verify --native, these tests) compile the kernels for the
    widest set /proc/cpuinfo names, not the three clones of a package meant to be shipped; the
    module's SIMD, which the C reads from its build, says which."""
    _, native, _, _ = built["ur5"]
    if host_instruction_set() is None or native.SIMD == "scalar":
        pytest.skip("not x86-64 with vector math: there is no instruction set to choose")
    assert native.SIMD == SIMD_NAMES[host_instruction_set()]


def test_pip_builds_and_installs_it(tmp_path):
    """`pip install --no-build-isolation DIR/NAME` of a generated folder (planar_2r: quick to
    build), and the module imports and computes in a fresh interpreter. pip builds the package
    to ship, with the three clones: the processor picks one at load time, the one jacgen's own
    builds compile for."""
    robot = load_robot(ROOT / "robots" / "planar_2r.yaml")
    write_files(render_robot(robot, ("native",), "double", Generator(robot)), tmp_path / "src")
    installed = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-build-isolation", "--no-deps",
                                "--target", str(tmp_path / "site"), str(tmp_path / "src" / "planar_2r")],
                               capture_output=True, text=True)
    assert installed.returncode == 0, installed.stderr
    run = subprocess.run([sys.executable, "-c", "import planar_2r_native as arm; print(arm.fk([0.0, 0.0])[0, 3], arm.SIMD)"],
                         capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(tmp_path / "site")})
    assert run.returncode == 0, run.stderr
    reach, simd = run.stdout.split()
    assert float(reach) == 2.0  # two unit links, stretched along x
    assert simd == "scalar" or host_instruction_set() is None or simd == SIMD_NAMES[host_instruction_set()]


def test_no_compiler_is_one_line(tmp_path):
    """Without a C compiler, the build stops with one line that says so."""
    robot = load_robot(ROOT / "robots" / "planar_2r.yaml")
    write_files(render_robot(robot, ("native",), "double", Generator(robot)), tmp_path)
    built = subprocess.run([sys.executable, "setup.py", "build_ext", "--inplace"], cwd=tmp_path / "planar_2r",
                           capture_output=True, text=True, env={**os.environ, "CC": "no-such-compiler"})
    assert built.returncode != 0
    assert built.stderr.strip().splitlines()[-1] == ("planar_2r_native: cannot build: no C compiler: no-such-compiler "
                                                     "is not on PATH (install gcc or clang, e.g. apt-get install gcc)")


def test_command_line_refuses_what_cannot_be():
    """--real float with c and native (both would write NAME.c), and verify --native with --target:
    one line each, exit 2."""
    robot = str(ROOT / "robots" / "ur5.yaml")
    for arguments, said in ((["generate", robot, "--lang", "c,native", "--real", "float"], "--lang native writes NAME.c"),
                            (["verify", robot, "--native", "--target", "cortex-m4f"], "--native checks the host")):
        result = CliRunner().invoke(main, arguments)
        assert result.exit_code == 2 and said in result.output, result.output
