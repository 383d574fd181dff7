"""jacgen.arm: one line from a robot file (or URDF, or a shipped robot's name) to its generated
module, built once and cached by content (jacgen/loading.py, issue 49).

The native builds here generate few functions (fk_jacobian) of small arms, so that each takes
seconds; tests/test_native.py checks a whole native module against the reference.
"""

import multiprocessing
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import jacgen
from jacgen import loading
from jacgen.checking import reference
from jacgen.emission.render import render_robot
from jacgen.inputs.robot_file import load_robot
from jacgen.urdf_import import import_urdf

from support.random_arms import random_arm_text
from support.urdf import URDFS

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data" / "urdf"
SMALL = ["fk_jacobian"]


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder of this test's own, for this process and those it starts."""
    folder = tmp_path / "cache"
    monkeypatch.setenv("JACGEN_CACHE_DIR", str(folder))
    monkeypatch.delenv(loading.NO_BUILD, raising=False)
    return folder


def shared_objects(folder: Path) -> list[Path]:
    return sorted((folder / "arms").glob("*/*_native.*.so"))


def test_the_python_module_is_generates_bit_for_bit(cache, tmp_path):
    ur5 = jacgen.arm("ur5")
    robot = load_robot(ROOT / "robots" / "ur5.yaml")
    assert Path(ur5.__file__).read_text() == render_robot(robot, ("python",))["ur5/ur5.py"]
    assert Path(ur5.__file__).read_text() == (ROOT / "generated" / "ur5" / "ur5.py").read_text()
    assert ur5.__name__.startswith("jacgen.built.k") and sys.modules[ur5.__name__] is ur5
    assert repr(ur5).startswith("<jacgen arm 'ur5' (python): fk, jacobian, fk_jacobian")
    q = np.array([0.3, -1.1, 0.7, 0.2, -0.4, 1.3])
    assert np.abs(ur5.fk(q) - reference.fk(robot, q)).max() < 1e-12
    assert jacgen.arm(ROOT / "robots" / "ur5.yaml") is ur5  # a shipped name and its path: one file, one key


def test_native_sources_are_generates_and_a_list_is_read_directly(cache):
    planar = jacgen.arm("planar_2r", backend="native", functions=SMALL)
    robot = load_robot(ROOT / "robots" / "planar_2r.yaml")
    written = render_robot(robot, ("native",), functions=SMALL)
    folder = Path(planar.__file__).parent
    for relative, text in written.items():
        assert (folder / Path(relative).name).read_text() == text, relative
    q = [0.4, -1.2]
    T, J = planar.fk_jacobian(q)
    assert np.array_equal(T, planar.fk_jacobian(np.array(q))[0])
    assert np.abs(T - reference.fk(robot, np.array(q))).max() < 1e-12
    assert np.abs(planar.fk_jacobian((1, 2))[0] - reference.fk(robot, np.array([1.0, 2.0]))).max() < 1e-12
    assert repr(planar) == "<jacgen arm 'planar_2r' (native): fk_jacobian>"


def test_a_hit_in_a_fresh_process_runs_no_compiler_and_imports_no_sympy(cache):
    jacgen.arm("planar_2r", backend="native", functions=SMALL)
    program = ("import sys, time; start = time.perf_counter(); import jacgen; "
               "m = jacgen.arm('planar_2r', backend='native', functions=['fk_jacobian']); "
               "print(m.fk_jacobian([0.1, 0.2])[0][0, 3], 'sympy' in sys.modules, time.perf_counter() - start)")
    environment = {**os.environ, "CC": "/nonexistent/cc", "PATH": "/nonexistent"}
    result = subprocess.run([sys.executable, "-c", program], env=environment, capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    x, sympy_imported, seconds = result.stdout.split()
    assert float(x) == pytest.approx(reference.fk(load_robot(ROOT / "robots" / "planar_2r.yaml"), np.array([0.1, 0.2]))[0, 3],
                                     abs=1e-12)
    assert sympy_imported == "False"
    assert result.stderr == ""  # no progress line: nothing was built
    print(f"cache hit in a fresh process: {float(seconds):.2f} s")


def test_an_edited_robot_file_is_a_new_module_beside_the_old(cache, tmp_path):
    path = tmp_path / "arm.yaml"
    text = (ROOT / "robots" / "planar_2r.yaml").read_text()
    path.write_text(text)
    first = jacgen.arm(path, backend="native", functions=SMALL)
    longer = text.replace("a1: 1.0", "a1: 2.0", 1)
    assert longer != text
    path.write_text(longer)
    second = jacgen.arm(path, backend="native", functions=SMALL)
    assert first is not second and first.__name__ != second.__name__
    q = [0.0, 0.0]
    assert first.fk_jacobian(q)[0][0, 3] + 1 == pytest.approx(second.fk_jacobian(q)[0][0, 3])  # both still work
    assert len(shared_objects(cache)) == 2


def test_a_corrupt_entry_is_rebuilt(cache):
    module = jacgen.arm("planar_2r", functions=SMALL)
    Path(module.__file__).write_text("raise SystemExit('tampered')\n")
    sys.modules.pop(module.__name__)
    rebuilt = jacgen.arm("planar_2r", functions=SMALL)
    assert rebuilt.fk_jacobian([0.0, 0.0])[0][0, 3] == pytest.approx(reference.fk(
        load_robot(ROOT / "robots" / "planar_2r.yaml"), np.zeros(2))[0, 3])


def _build_in_a_process(folder: str) -> str:
    os.environ["JACGEN_CACHE_DIR"] = folder
    import jacgen as fresh

    module = fresh.arm("planar_2r", backend="native", functions=["fk_jacobian"])
    return f"{module.__name__} {module.fk_jacobian([0.0, 0.0])[0][0, 3]}"


def test_four_processes_on_an_empty_cache_build_once(cache):
    with multiprocessing.get_context("spawn").Pool(4) as pool:
        answers = pool.map(_build_in_a_process, [str(cache)] * 4)
    assert len(set(answers)) == 1, answers
    assert answers[0].split()[1] == str(reference.fk(load_robot(ROOT / "robots" / "planar_2r.yaml"), np.zeros(2))[0, 3])
    assert len(shared_objects(cache)) == 1
    assert not [p for p in (cache / "arms").iterdir() if p.is_dir() and not p.name.startswith("k")]  # no private folder left


def test_a_cache_that_cannot_be_written_builds_in_a_temporary_folder(tmp_path, monkeypatch):
    blocked = tmp_path / "a file"
    blocked.write_text("")
    monkeypatch.setenv("JACGEN_CACHE_DIR", str(blocked / "cache"))  # under a file: mkdir fails, also for root
    loading._warned.clear()
    with pytest.warns(RuntimeWarning, match="cannot write the cache") as warned:
        module = jacgen.arm("planar_2r", functions=SMALL)
        jacgen.arm("planar_3r", functions=SMALL)
    assert len(warned) == 1
    assert module.fk_jacobian([0.0, 0.0])[0][0, 3] == pytest.approx(2.0)  # planar_2r: links 1 and 1
    assert not str(module.__file__).startswith(str(blocked))


def test_no_compiler(cache, monkeypatch):
    monkeypatch.setenv("CC", "/nonexistent/cc")
    with pytest.raises(jacgen.BuildError, match=r"no C compiler.*backend='python' needs no compiler"):
        jacgen.arm("planar_2r", backend="native", functions=SMALL)
    assert not shared_objects(cache) and not [p for p in (cache / "arms").iterdir() if p.is_dir()]
    loading._warned.clear()
    with pytest.warns(RuntimeWarning, match="the Python module instead of the native one: .*no C compiler"):
        auto = jacgen.arm("planar_2r", backend="auto", functions=SMALL)
    assert repr(auto).endswith("(python): fk_jacobian>")
    assert jacgen.arm("planar_2r", backend="casadi", functions=SMALL).fk_jacobian.n_in() == 1
    assert jacgen.arm("planar_2r", backend="python", functions=SMALL) is auto


def test_no_build_turns_a_miss_into_an_error(cache, monkeypatch):
    jacgen.arm("planar_2r", functions=SMALL)
    monkeypatch.setenv(loading.NO_BUILD, "1")
    assert jacgen.arm("planar_2r", functions=SMALL).DOF == 2  # a hit
    with pytest.raises(jacgen.BuildError, match="JACGEN_NO_BUILD is set"):
        jacgen.arm("planar_3r", functions=SMALL)


def _fk_jacobian_in_a_worker(function, q):
    return function(q)[0][:3, 3]


@pytest.mark.parametrize("backend", ["python", "native"])
def test_functions_pickle_into_spawn_workers(cache, backend):
    planar = jacgen.arm("planar_2r", backend=backend, functions=SMALL)
    assert pickle.loads(pickle.dumps(planar.fk_jacobian)) is planar.fk_jacobian
    rows = np.random.default_rng(1).uniform(-3, 3, (4, 2))
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        found = pool.starmap(_fk_jacobian_in_a_worker, [(planar.fk_jacobian, q) for q in rows])
    assert np.abs(np.array(found) - np.array([planar.fk_jacobian(q)[0][:3, 3] for q in rows])).max() == 0


@pytest.mark.parametrize("name", ["ur5", "panda", "so101"])
def test_a_urdf_is_import_urdf_then_arm(cache, tmp_path, name):
    file, base, tip, _ = URDFS[name]
    imported = import_urdf(str(DATA / file), base, tip)
    path = tmp_path / f"{imported.robot.name}.yaml"
    path.write_text(imported.text)
    from_urdf = jacgen.arm(DATA / file, base=base, tip=tip, functions=SMALL)
    from_file = jacgen.arm(path, functions=SMALL)
    assert Path(from_urdf.__file__).read_text() == Path(from_file.__file__).read_text()


@pytest.mark.parametrize("seed", [3, 8])
def test_random_arms_in_every_backend(cache, tmp_path, seed):
    """arm of a random arm is generate's module: the same text (python), the same numbers as it
    (native, casadi), and the reference's fk."""
    text = random_arm_text(seed)
    path = tmp_path / "arm.yaml"
    path.write_text(text)
    robot = load_robot(path)
    python = jacgen.arm(path, functions=SMALL)
    assert Path(python.__file__).read_text() == render_robot(robot, ("python",), functions=SMALL)[f"{robot.name}/{robot.name}.py"]
    native = jacgen.arm(path, backend="native", functions=SMALL)
    casadi = jacgen.arm(path, backend="casadi", functions=SMALL)
    parameters = {p.name: p.value for p in robot.symbolic_parameters}
    for q in np.random.default_rng(seed).uniform(-2, 2, (5, robot.dof)):
        T, J = python.fk_jacobian(q, **parameters)
        assert np.abs(T - reference.fk(robot, q)).max() < 1e-9 * (1 + robot.reach)
        assert np.abs(native.fk_jacobian(q, **parameters)[1] - J).max() < 1e-12 * (1 + robot.reach)
        found = casadi.fk_jacobian(q, *([list(parameters.values())] if parameters else []))
        assert np.abs(np.array(found[1]) - J).max() < 1e-12 * (1 + robot.reach)


def test_jacgen_build_fills_the_cache(cache):
    from click.testing import CliRunner

    from jacgen.cli import main

    result = CliRunner().invoke(main, ["build", "planar_2r", "--backend", "python", "--functions", "fk_jacobian"])
    assert result.exit_code == 0, result.output
    assert "jacgen.built.k" in result.output
    os.environ[loading.NO_BUILD] = "1"
    try:
        assert jacgen.arm("planar_2r", functions=SMALL).DOF == 2
    finally:
        del os.environ[loading.NO_BUILD]


def test_unknown_sources_are_one_clear_error(cache):
    with pytest.raises(jacgen.JacgenError, match="neither a file nor a shipped robot .*ur5"):
        jacgen.arm("ur6")
    with pytest.raises(jacgen.JacgenError, match="no such robot file"):
        jacgen.arm("robots/nothing.yaml")
    with pytest.raises(jacgen.JacgenError, match="options of a URDF"):
        jacgen.arm("ur5", tip="tool0")
    with pytest.raises(ValueError, match="backend must be one of"):
        jacgen.arm("ur5", backend="fortran")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        jacgen.arm("planar_2r", functions=SMALL)
