"""`generate`'s cache (contract §4, "The cache"): an unchanged robot file is not rendered
again, a hand edit or a changed robot file is still found, a corrupt or foreign entry is
ignored, and the command line starts without sympy, casadi or matplotlib."""

import json
import subprocess
import sys

import pytest
from click.testing import CliRunner

from jacgen import cache
from jacgen.emission import render
from jacgen.cli import main

from conftest import ROOT

ROBOT = ROOT / "robots" / "planar_2r.yaml"


def run(*arguments):
    return CliRunner().invoke(main, [str(argument) for argument in arguments])


@pytest.fixture(autouse=True)
def empty_cache(tmp_path_factory, monkeypatch):
    """Each test starts with a cache of its own."""
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path_factory.mktemp("xdg_cache")))


@pytest.fixture
def rendered(monkeypatch):
    """The robots render_robots is asked for, in order."""
    calls = []
    real = render.render_robots

    def counting(robots, *arguments, **keywords):
        calls.extend(robot.name for robot in robots)
        return real(robots, *arguments, **keywords)

    monkeypatch.setattr(render, "render_robots", counting)
    return calls


def test_an_unchanged_robot_is_not_rendered_again(tmp_path, rendered):
    assert run("generate", ROBOT, "-o", tmp_path, "--lang", "python,c").exit_code == 0
    assert rendered == ["planar_2r"]
    again = run("generate", ROBOT, "-o", tmp_path, "--lang", "python,c", "--check")
    assert (again.exit_code, again.stderr) == (0, "jacgen: 3 generated file(s) up to date\n")
    written = run("generate", ROBOT, "-o", tmp_path, "--lang", "python,c")
    assert written.stderr == f"jacgen: wrote 0 file(s), 3 unchanged, in {tmp_path}\n"
    assert rendered == ["planar_2r"]
    assert run("generate", ROBOT, "-o", tmp_path, "--lang", "python").exit_code == 0  # other options: rendered
    assert run("generate", ROBOT, "-o", tmp_path, "--lang", "python,c", "--no-cache").exit_code == 0
    assert rendered == ["planar_2r"] * 3


def test_a_hand_edit_and_a_changed_robot_file_are_found(tmp_path, rendered):
    robot = tmp_path / "planar_2r.yaml"
    robot.write_bytes(ROBOT.read_bytes())
    out = tmp_path / "out"
    assert run("generate", robot, "-o", out, "--lang", "python").exit_code == 0
    module = out / "planar_2r" / "planar_2r.py"
    module.write_text(module.read_text() + "# edited\n")
    edited = run("generate", robot, "-o", out, "--lang", "python", "--check")
    assert edited.exit_code == 1 and "-# edited" in edited.stdout
    assert run("generate", robot, "-o", out, "--lang", "python").exit_code == 0  # restores it
    robot.write_text(robot.read_text().replace("a2: 1.0", "a2: 1.5"))
    changed = run("generate", robot, "-o", out, "--lang", "python", "--check")
    assert changed.exit_code == 1 and "1.5" in changed.stdout
    assert rendered == ["planar_2r"] * 4


@pytest.mark.parametrize("damage", ["not json", "foreign key", "path outside its folder", "wrong hash"])
def test_a_corrupt_or_foreign_entry_is_ignored(tmp_path, rendered, damage):
    assert run("generate", ROBOT, "-o", tmp_path, "--lang", "python").exit_code == 0
    (entry_file,) = cache.folder().glob("*.json")
    entry = json.loads(entry_file.read_text())
    if damage == "not json":
        entry_file.write_text("{")
    else:
        if damage == "foreign key":
            entry["key"] = "0" * 64
        elif damage == "path outside its folder":
            entry["files"] = {"../planar_2r.py": entry["files"]["planar_2r/planar_2r.py"]}
        else:
            entry["files"]["planar_2r/planar_2r.py"] = "0" * 64
        entry_file.write_text(json.dumps(entry))
    again = run("generate", ROBOT, "-o", tmp_path, "--lang", "python", "--check")
    assert (again.exit_code, again.stderr) == (0, "jacgen: 1 generated file(s) up to date\n")
    assert rendered == ["planar_2r"] * 2  # the entry was not trusted: rendered and compared


def test_the_command_line_starts_without_the_generator(tmp_path):
    """--help, validate and a cached --check import neither sympy, casadi nor matplotlib."""
    assert run("generate", ROBOT, "-o", tmp_path, "--lang", "python").exit_code == 0
    probe = ("import sys\nfrom jacgen.cli import main\ntry:\n    main(sys.argv[1:])\nexcept SystemExit:\n    pass\n"
             "print(sorted({name.split('.')[0] for name in sys.modules} & {'sympy', 'casadi', 'matplotlib'}))")
    for arguments in (["--help"], ["validate", *map(str, sorted((ROOT / "robots").glob("*.yaml")))], ["generate", str(ROBOT), "-o", str(tmp_path), "--lang", "python", "--check"]):
        result = subprocess.run([sys.executable, "-c", probe, *arguments], capture_output=True, text=True, check=True)
        assert result.stdout.splitlines()[-1] == "[]", (arguments, result.stdout, result.stderr)
