"""Hostile names and text in robot files, and where `generate` may write (issue 6).

Every name that reaches generated code either generates code that compiles, imports and
matches the reference (checked with `jacgen verify`), or is refused with one line and exit
code 2 that says the rule:
- robot names: C/Python keywords, C headers and Python modules are refused (`for.py`
  cannot be imported, `math/math.h` would hide <math.h>); `main`, `print`, `fk` are fine;
- joint names go only into comments: C and Python keywords are fine there, and anything that
  could end a comment or string does not match the identifier pattern;
- parameter names: every name the generated code uses where a parameter is in scope is
  refused; a scan of the generated Python and C checks that the reserved list is complete;
- description: nothing that ends a comment or docstring or escapes a string.
`generate` writes only NAME/ folders inside -o, and a run with one invalid robot file writes
nothing at all.
"""

import ast
import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from jacgen.cli import main
from jacgen.inputs.names import PARAMETER_NAME_RULE, ROBOT_NAME_RULE, parameter_name_problem
from jacgen.emission.render import DEFAULT_LANGUAGES, render_robot
from jacgen.inputs.robot_file import parse_robot

from conftest import ROOT

# contract §3: the files of robot NAME, by language.
CONTRACT_FILES = {"c": ("{name}.h", "{name}.c"), "python": ("{name}.py",), "casadi": ("{name}_casadi.py",),
              "report": ("{name}.md",)}


def arm(name: str = "arm", joints=("j1", "j2", "j3"), description: str = "test arm",
        parameter: str = "length") -> str:
    """A 3R arm with one symbolic parameter; every name is written as a YAML double-quoted string."""
    quoted = [json.dumps(joint) for joint in joints]
    return f"""\
name: {json.dumps(name)}
description: {json.dumps(description)}
convention: standard
parameters:
  {json.dumps(parameter)}: {{value: 0.3, symbolic: true}}
joints:
  - {{name: {quoted[0]}, type: revolute, a: 0, alpha: pi/2, d: 0.2, limits: [-3, 3]}}
  - {{name: {quoted[1]}, type: revolute, a: {json.dumps(parameter)}, alpha: 0, d: 0, limits: [-3, 3]}}
  - {{name: {quoted[2]}, type: revolute, a: 0.25, alpha: 0, d: 0.1, limits: [-3, 3]}}
task: [x, y, z]
"""


def run(*arguments: str):
    return CliRunner().invoke(main, [str(argument) for argument in arguments])


def refused(tmp_path, text: str) -> str:
    """The one error line of `jacgen validate` on `text` (which must fail with exit 2)."""
    path = tmp_path / "robot.yaml"
    path.write_text(text, encoding="utf-8")
    result = run("validate", path)
    assert result.exit_code == 2, result.output
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    prefix = f"jacgen: error: {path}:"
    assert result.stderr.startswith(prefix)
    return result.stderr[len(prefix):].rstrip("\n")


# -- robot names -----------------------------------------------------------------------------------
@pytest.mark.parametrize("name, problem", [
    ("for", "is a keyword"), ("class", "is a keyword"), ("lambda", "is a keyword"), ("int", "is a keyword"),
    ("float", "is a keyword"), ("static", "is a keyword"), ("return", "is a keyword"), ("while", "is a keyword"),
    ("math", "would hide the C header <math.h>"), ("string", "would hide the C header <string.h>"),
    ("numpy", "would hide the Python module 'numpy'"), ("casadi", "would hide the Python module 'casadi'"),
    ("os", "would hide the Python module 'os'"), ("random", "would hide the Python module 'random'"),
])
def test_robot_name_that_cannot_name_files_is_refused(tmp_path, name, problem):
    assert refused(tmp_path, arm(name)) == f"1:7: name: '{name}' {problem}: {ROBOT_NAME_RULE}"


@pytest.mark.parametrize("name", ["../x", "a/b", "x.yaml", "rö", "ロボット", "Arm", "_arm", "1arm", "a-b", "a" * 49, ""])
def test_robot_name_outside_the_pattern_is_refused(tmp_path, name):
    assert refused(tmp_path, arm(name)) == (f"1:7: name: invalid name {name!r} "
                                            "(expected ^[a-z][a-z0-9_]{0,47}$)")


# -- joint names -------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["x*/y", 'a"""b', "a\nb", "../x", "jö", "a b", "a-b", "a//b", "", "a" * 49])
def test_joint_name_that_could_escape_a_comment_is_refused(tmp_path, name):
    message = refused(tmp_path, arm(joints=("j1", name, "j3")))
    assert message.endswith(f"joints[1].name: invalid name {name!r} (expected ^[A-Za-z_][A-Za-z0-9_]{{0,47}}$)")


def test_keywords_as_names_generate_correct_code(tmp_path):
    """Robots named `main` and `print`, joints named after C and Python keywords, a description
    with quotes and non-ASCII text: `jacgen verify` builds C (double and float, -Werror), the
    Python and CasADi modules, and compares them with the reference."""
    files = []
    for name, joints in (("main", ("for", "int", "static")), ("print", ("class", "lambda", "return"))):
        path = tmp_path / f"{name}.yaml"
        path.write_text(arm(name, joints, description='Ünïcode "quoted" arm — 3R, 90°', parameter="length"),
                        encoding="utf-8")
        files.append(path)
    result = run("verify", *files, "--samples", "5")
    assert result.exit_code == 0, result.output
    assert "FAIL" not in result.output


# -- parameter names -----------------------------------------------------------------------------------
@pytest.mark.parametrize("name, problem", [
    ("numpy", "is used by the generated code"), ("q", "is used by the generated code"),
    ("p", "is used by the generated code"), ("t0", "is used by the generated code"),
    ("c1", "is used by the generated code"), ("s2", "is used by the generated code"),
    ("c10_11", "is used by the generated code"), ("T03", "is used by the generated code"), ("mu0", "is used by the generated code"),
    ("q3", "is used by the generated code"), ("fk", "is used by the generated code"),
    ("solutions", "is used by the generated code"), ("M_PI", "is used by the generated code"),
    ("_x", "is used by the generated code"),
    ("int", "is a keyword"), ("return", "is a keyword"), ("class", "is a keyword"), ("new", "is a keyword"),
    ("print", "is a Python builtin"), ("len", "is a Python builtin"),
    ("sin", "is a <math.h> name"), ("sqrtf", "is a <math.h> name"), ("NULL", "is a <math.h> name"),
    ("arm_length", "starts with the robot's prefix 'arm_'"), ("ARM_DOF", "starts with the robot's prefix 'arm_'"),
])
def test_parameter_name_used_by_generated_code_is_refused(tmp_path, name, problem):
    assert refused(tmp_path, arm(parameter=name)) == (
        f"5:3: parameters.{name}: parameter name '{name}' {problem}: {PARAMETER_NAME_RULE}")


def symbolic_variant(robot_name: str):
    """A shipped robot with every parameter made symbolic (a runtime argument of the code)."""
    text = (ROOT / "robots" / f"{robot_name}.yaml").read_text()
    head, joints = text.split("\njoints:", 1)
    head = re.sub(r"^  (\w+): ([^#\n]+?)\s*(#.*)?$", r"  \1: {value: \2, symbolic: true}", head, flags=re.M)
    return parse_robot(f"{head}\njoints:{joints}".encode(), f"{robot_name}.yaml")


def python_names_in_scope(source: str, parameters: set[str]) -> set[str]:
    """Module-level names, and every name of the functions that take a parameter."""
    tree = ast.parse(source)
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names |= {alias.asname or alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
            names |= {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
    for function in ast.walk(tree):
        if isinstance(function, ast.FunctionDef):
            arguments = {a.arg for a in ast.walk(function.args) if isinstance(a, ast.arg)}
            if arguments & parameters:
                names |= arguments | {n.id for n in ast.walk(function) if isinstance(n, ast.Name)}
    return names


def c_names_in_scope(source: str) -> set[str]:
    """Identifiers of the C functions that bind parameters to locals (`const ... d3 = p->d3;`)."""
    source = re.sub(r"/\*.*?\*/", " ", source, flags=re.S)
    source = re.sub(r"^[ \t]*#.*$", " ", source, flags=re.M)
    names = set()
    for signature, body in re.findall(r"^(\w[^\n]*\)[^\n]*)\n\{\n(.*?)^\}", source, flags=re.S | re.M):
        if re.search(r"\b(\w+) = p->\1;", body):
            code = re.sub(r"->\s*\w+", " ", signature + body)
            names |= set(re.findall(r"\b[A-Za-z_]\w*\b", code))
    return names


@pytest.mark.parametrize("robot_name", ["planar_3r", "scara", "rexarm", "puma560", "ur5", "stanford"])
def test_reserved_parameter_names_cover_the_generated_code(robot_name):
    """No name the generated code binds or reads where parameters are in scope is a legal
    parameter name; a template that adds a local must reserve it (or start it with '_')."""
    robot = symbolic_variant(robot_name)
    parameters = {p.name for p in robot.symbolic_parameters}
    assert parameters
    files = render_robot(robot, tuple(language for language in DEFAULT_LANGUAGES if language in ("c", "python", "casadi")))
    unreserved = {}
    for path, source in files.items():
        if path.endswith(".py"):
            names = python_names_in_scope(source, parameters)
        elif path.endswith(".c"):
            names = c_names_in_scope(source)
            assert names, f"no function of {path} takes the parameters"
        else:
            continue
        loose = sorted(name for name in names - parameters if not parameter_name_problem(name, robot.name))
        if loose:
            unreserved[path] = loose
    assert not unreserved, f"names a parameter could take (add them to jacgen/inputs/names.py): {unreserved}"


def test_every_language_refuses_its_reserved_words():
    """The languages are names.RESERVED's keys: each has its backend, and each word any of
    them reserves is refused as a parameter name."""
    from jacgen.emission.backends import LANGUAGES, backend
    from jacgen.inputs.names import RESERVED

    assert LANGUAGES == tuple(RESERVED) and all(backend(language).name == language for language in LANGUAGES)
    words = set().union(*(words for reserved in RESERVED.values() for words in reserved.values()))
    assert all(parameter_name_problem(word, "arm") for word in words)


# -- free text ------------------------------------------------------------------------------------------
@pytest.mark.parametrize("text, problem", [
    ("ends */ here", "may not contain '*/'"), ("opens /* here", "may not contain '/*'"),
    ('a """ b', "may not contain '\"\"\"'"), ("back\\slash", "may not contain '\\\\'"),
    ("trigraph ??/", "may not contain '??'"), ("tab\tinside", "must be lines of printable characters"),
    ("bidi \u202e override", "must be lines of printable characters"),
])
def test_description_that_could_escape_is_refused(tmp_path, text, problem):
    assert refused(tmp_path, arm(description=text)).startswith(f"2:14: description: {problem}")


# -- where generate writes ---------------------------------------------------------------------------
def tree(folder: Path) -> dict[str, bytes]:
    return {str(path.relative_to(folder)): path.read_bytes() for path in sorted(folder.rglob("*")) if path.is_file()}


def expected_files(name: str) -> set[str]:
    return {f"{name}/{pattern.format(name=name)}" for language in DEFAULT_LANGUAGES for pattern in CONTRACT_FILES[language]}


def test_generate_writes_only_into_the_output_folder(tmp_path, monkeypatch):
    (tmp_path / "in").mkdir()
    (tmp_path / "work").mkdir()
    (tmp_path / "in" / "x.yaml").write_text(arm("arm"))
    monkeypatch.chdir(tmp_path / "work")
    result = run("generate", "../in/x.yaml", "-o", "out")
    assert result.exit_code == 0, result.output
    assert set(tree(tmp_path)) == {"in/x.yaml"} | {f"work/out/{path}" for path in expected_files("arm")}


def test_failed_run_writes_nothing(tmp_path):
    out = tmp_path / "out"
    first = tmp_path / "first.yaml"
    first.write_text(arm("first"))
    assert run("generate", first, "-o", out).exit_code == 0
    before = tree(out)
    assert set(before) == expected_files("first")
    first.write_text(arm("first").replace("d: 0.1", "d: 0.15"))  # would change the generated files
    second = tmp_path / "second.yaml"
    second.write_text(arm("second").replace("alpha: 0,", "alpha: [0],", 1))
    result = run("generate", first, second, "-o", out)
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and "second.yaml:" in result.stderr
    assert tree(out) == before


def test_two_files_naming_the_same_robot_write_nothing(tmp_path):
    (tmp_path / "a.yaml").write_text(arm("twin"))
    (tmp_path / "b.yaml").write_text(arm("twin").replace("d: 0.1", "d: 0.15"))
    result = run("generate", tmp_path / "a.yaml", tmp_path / "b.yaml", "-o", tmp_path / "out")
    assert result.exit_code == 2
    assert result.stderr == (f"jacgen: error: {tmp_path / 'b.yaml'}: name: robot name 'twin' is already used by "
                             f"{tmp_path / 'a.yaml'} (each robot is written to its own folder NAME/)\n")
    assert not (tmp_path / "out").exists()


def test_unwritable_output_is_one_line(tmp_path):
    (tmp_path / "robot.yaml").write_text(arm("arm"))
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "arm").write_text("a file where the folder arm/ should go")
    result = run("generate", tmp_path / "robot.yaml", "-o", tmp_path / "out")
    assert result.exit_code == 2
    assert result.stderr.count("\n") == 1 and result.stderr.startswith("jacgen: error: ")


def test_file_name_cannot_break_the_generated_header(tmp_path):
    """The robot file's name is copied into a one-line comment at the top of every file."""
    robot = tmp_path / "evil\nname ??.yaml"
    robot.write_text(arm("arm"))
    result = run("generate", robot, "-o", tmp_path / "out", "--lang", "python")
    assert result.exit_code == 0, result.output
    source = (tmp_path / "out" / "arm" / "arm.py").read_text()
    assert source.splitlines()[0].startswith("# Generated by jacgen ") and "evil?name ??.yaml" in source
    ast.parse(source)
