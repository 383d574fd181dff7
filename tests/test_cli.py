"""The command line (contract §4): version, generate and its idempotence, --check with a diff,
usage mistakes as one line. (Byte-identical output under any PYTHONHASHSEED: test_golden.)"""

import os
import re

import numpy as np
from click.testing import CliRunner

from jacgen import __version__, load_robot
from jacgen.checking import reference
from jacgen.cli import main
from jacgen.checking.c_library import CLibrary, compile_shared
from jacgen.emission.generator import Generator

from conftest import ROOT, import_module, random_configurations


def run(*arguments):
    return CliRunner().invoke(main, [str(argument) for argument in arguments])


def files_under(folder):
    return {str(path.relative_to(folder)): path.read_bytes() for path in sorted(folder.rglob("*")) if path.is_file()}


def test_version():
    result = run("--version")
    assert result.exit_code == 0
    assert result.output == f"jacgen, version {__version__}\n"


def test_generate_writes_then_is_idempotent(tmp_path):
    robot = ROOT / "robots" / "planar_2r.yaml"
    first = run("generate", robot, "-o", tmp_path)
    assert first.exit_code == 0, first.output
    written = files_under(tmp_path)
    assert written and all(path.startswith("planar_2r/") for path in written)
    assert first.stderr == f"jacgen: wrote {len(written)} file(s), 0 unchanged, in {tmp_path}\n"
    umask = os.umask(0)
    os.umask(umask)
    assert {(tmp_path / path).stat().st_mode & 0o777 for path in written} == {0o666 & ~umask}  # not mkstemp's 0600
    times = {path: (tmp_path / path).stat().st_mtime_ns for path in written}
    second = run("generate", robot, "-o", tmp_path)
    assert second.exit_code == 0
    assert second.stderr == f"jacgen: wrote 0 file(s), {len(written)} unchanged, in {tmp_path}\n"
    assert files_under(tmp_path) == written
    assert {path: (tmp_path / path).stat().st_mtime_ns for path in written} == times


def test_check_passes_when_up_to_date_and_diffs_after_an_edit(tmp_path):
    robot = tmp_path / "robots" / "planar_2r.yaml"
    robot.parent.mkdir()
    robot.write_text((ROOT / "robots" / "planar_2r.yaml").read_text())
    out = tmp_path / "out"
    assert run("generate", robot, "-o", out, "--lang", "python").exit_code == 0
    before = files_under(out)

    up_to_date = run("generate", robot, "-o", out, "--lang", "python", "--check")
    assert up_to_date.exit_code == 0
    assert up_to_date.stdout == ""
    assert up_to_date.stderr == "jacgen: 1 generated file(s) up to date\n"

    robot.write_text(robot.read_text().replace("a2: 1.0", "a2: 1.5"))
    stale = run("generate", robot, "-o", out, "--lang", "python", "--check")
    assert stale.exit_code == 1
    diff = stale.stdout.splitlines()
    assert diff[:2] == ["--- a/planar_2r/planar_2r.py", "+++ b/planar_2r/planar_2r.py"]
    assert any(line.startswith("@@ ") for line in diff)
    assert any(line.startswith("-") and "1.0" in line for line in diff[2:])
    assert any(line.startswith("+") and "1.5" in line for line in diff[2:])
    assert stale.stderr == f"jacgen: 1 generated file(s) out of date in {out}\n"
    assert files_under(out) == before  # --check writes nothing


def test_unknown_language_is_one_line():
    result = run("generate", ROOT / "robots" / "planar_2r.yaml", "--lang", "c,fortran")
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.count("\n") == 1
    assert result.stderr.startswith("jacgen: error: Invalid value for '--lang': unknown language 'fortran'")


def test_usage_mistakes_are_one_line():
    for arguments in (["generate"], ["frobnicate"], ["generate", "x.yaml", "--real", "quad"],
                      ["generate", "x.yaml", "--budget", "-1"]):
        result = run(*arguments)
        assert result.exit_code == 2, arguments
        assert result.stderr.count("\n") == 1 and result.stderr.startswith("jacgen: error: "), result.stderr


def test_internal_error_is_one_line_and_debug_shows_the_traceback(tmp_path, monkeypatch):
    """A bug of jacgen's is one line and exit 1, the traceback only with --debug, and
    nothing already on disk is touched (files are written after everything is generated)."""
    import jacgen.emission.render

    def broken(*args, **kwargs):
        raise ZeroDivisionError("polynomial division")

    existing = tmp_path / "planar_2r" / "planar_2r.py"
    existing.parent.mkdir()
    existing.write_text("earlier output\n")
    monkeypatch.setattr(jacgen.emission.render, "render_robot", broken)
    arguments = ["generate", str(ROOT / "robots" / "planar_2r.yaml"), "-o", str(tmp_path)]
    result = CliRunner().invoke(main, arguments)
    assert result.exit_code == 1
    assert result.output == ("jacgen: internal error: ZeroDivisionError: polynomial division "
                             "(a bug in jacgen; run with --debug for the traceback)\n")
    assert existing.read_text() == "earlier output\n"
    debug = CliRunner().invoke(main, ["--debug"] + arguments)
    assert isinstance(debug.exception, ZeroDivisionError)


def test_functions_option_emits_only_the_named_functions_and_their_callees(tmp_path):
    """`--functions fk_jacobian,ik_nearest`: the C declares those and ik_branches (which
    ik_nearest calls), nothing else; it compiles on its own, and fk_jacobian equals the numpy
    reference fk and Jacobian."""
    result = run("generate", ROOT / "robots" / "ur5.yaml", "-o", tmp_path, "--functions", "fk_jacobian,ik_nearest")
    assert result.exit_code == 0, result.output
    header = (tmp_path / "ur5" / "ur5.h").read_text()
    declared = re.findall(r"^\w+ (ur5_\w+)\(", header, re.MULTILINE)
    assert declared == ["ur5_fk_jacobian", "ur5_ik_branches", "ur5_ik_nearest"]
    assert "UR5_VELOCITY_IK_OK" not in header and "UR5_IK_NUMERIC" not in header and "UR5_IK_NEAREST_OK" in header
    robot = load_robot(ROOT / "robots" / "ur5.yaml")
    generator = Generator(robot, selection=("fk_jacobian",))
    library = CLibrary(compile_shared([tmp_path / "ur5" / "ur5.c"], tmp_path / "ur5.so"), robot,
                       generator.functions(), "double")
    q = random_configurations(robot, 20)
    values = library.evaluate("fk_jacobian", q)
    expected = np.array([np.concatenate([reference.fk(robot, x).ravel(), reference.jacobian(robot, x).ravel()])
                         for x in q])
    np.testing.assert_allclose(values, expected, atol=1e-13)
    module = import_module(tmp_path / "ur5" / "ur5.py", "ur5_selected")
    assert not hasattr(module, "jacobian") and not hasattr(module, "ik_numeric") and hasattr(module, "ik_nearest")


def test_the_report_analyses_singularities_for_the_functions_that_read_them(tmp_path):
    """`--functions fk` skips the singularity analysis, and its report says so; with
    singularity_factors the report lists the UR5's three conditions (Spong: the wrist's
    s5 = 0, the elbow's s3 = 0, and the shoulder's)."""
    for functions, folder in (("fk", "fk"), ("fk,singularity_factors", "factors")):
        result = run("generate", ROOT / "robots" / "ur5.yaml", "-o", tmp_path / folder, "--functions", functions,
                     "--no-cache")
        assert result.exit_code == 0, result.output
    section = lambda folder: (tmp_path / folder / "ur5" / "ur5.md").read_text().split("## Singularities")[1] \
        .split("## Dexterity")[0]  # noqa: E731
    assert section("fk").strip().startswith("Not analysed: no function generated reads the analysis")
    assert [line[:3] for line in section("factors").splitlines() if line[:2] in ("1.", "2.", "3.", "4.")] \
        == ["1. ", "2. ", "3. "]


def test_functions_option_rejects_what_cannot_be_made(tmp_path):
    unknown = run("generate", ROOT / "robots" / "ur5.yaml", "-o", tmp_path, "--functions", "fk,fkk")
    assert unknown.exit_code == 2
    assert unknown.stderr.startswith("jacgen: error: Invalid value for '--functions': unknown function 'fkk'")
    missing = run("generate", ROOT / "robots" / "iiwa.yaml", "-o", tmp_path, "--functions", "fk,jacobian_det")
    assert missing.exit_code == 2
    assert missing.stderr.endswith("iiwa.yaml: robot iiwa has no jacobian_det: Js is 6 x 7, not square\n")
    assert len(missing.stderr.splitlines()) == 1 and not list(tmp_path.iterdir())


def test_robots_in_parallel_processes_write_the_same_bytes(tmp_path):
    """`--jobs 2` (a process per robot) writes exactly what `--jobs 1` writes; a robot the
    functions asked for cannot be made for is one line from the worker, exit 2, nothing written."""
    robots = [ROOT / "robots" / f"{name}.yaml" for name in ("planar_2r", "scara", "rexarm")]
    for jobs in ("1", "2"):
        result = run("generate", *robots, "-o", tmp_path / jobs, "--jobs", jobs, "--functions", "fk_jacobian,ik")
        assert result.exit_code == 0, result.output
    written = files_under(tmp_path / "1")
    assert len(written) == 15 and written == files_under(tmp_path / "2")  # 3 robots x (h, c, py, casadi, md)
    assert all((tmp_path / "1" / path).read_bytes() == (tmp_path / "2" / path).read_bytes() for path in written)
    missing = run("generate", robots[0], ROOT / "robots" / "iiwa.yaml", "-o", tmp_path / "3", "--jobs", "2",
                  "--functions", "fk,jacobian_det")
    assert missing.exit_code == 2 and not (tmp_path / "3").exists()
    assert missing.stderr.endswith("iiwa.yaml: robot iiwa has no jacobian_det: Js is 6 x 7, not square\n")
    assert len(missing.stderr.splitlines()) == 1
