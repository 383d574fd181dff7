"""Robot files: every kind of mistake gives one line `FILE:LINE:COL: key.path: what is wrong`
and exit code 2, and valid values load to the exact numbers they denote.

Each bad file is the valid BASE below with one edit; the expected line and column are found
by searching the edited text for the offending token, so the table reads as the mistakes.
"""

import math
import subprocess
import sys

import pytest
import sympy
from click.testing import CliRunner

from jacgen.cli import main
from jacgen.errors import RobotFileError
from jacgen.inputs.values import ExpressionError, Value, parse
from jacgen.inputs.robot_file import MAX_NESTING, parse_robot

from conftest import ROOT

BASE = """\
name: arm
description: test arm
convention: standard
angle_unit: deg
parameters:
  a2: 0.4
joints:
  - name: j1
    type: revolute
    a: 0
    alpha: 90
    d: 0.3
  - name: j2
    type: revolute
    a: a2
    alpha: 0
    d: 0
  - name: j3
    type: revolute
    a: 0.25
    alpha: -90
    d: 0.05
    limits: [-170, 170]
task: [x, y, z]
"""
TOP_KEYS = "name, description, convention, angle_unit, length_unit, parameters, joints, base, tool, task, ik, characteristic_length"
JOINT_KEYS = "name, type, a, alpha, d, theta, offset, limits"


def edit(old: str, new: str, text: str = BASE) -> str:
    assert text.count(old) == 1, old
    return text.replace(old, new)


def position(text: str, token: str, occurrence: int = 1) -> tuple[int, int]:
    """1-based line and column of the `occurrence`-th `token` in `text`."""
    index = -1
    for _ in range(occurrence):
        index = text.index(token, index + 1)
    line = text.count("\n", 0, index) + 1
    return line, index - (text.rfind("\n", 0, index) + 1) + 1


def rows(count: int) -> str:
    return "  - {type: revolute, a: 0.1, alpha: 0, d: 0}\n" * count


# (id, file text, token where the mistake is (None: 1:1), key path, message)
CASES = [
    ("unknown_top_key", BASE + "colour: red\n", "colour", "colour",
     f"unknown key; expected one of: {TOP_KEYS}"),
    ("unknown_joint_key", edit("    d: 0.3\n", "    d: 0.3\n    lenght: 1\n"), "lenght", "joints[0].lenght",
     f"unknown key; expected one of: {JOINT_KEYS}"),
    ("list_for_number", edit("alpha: -90", "alpha: [1, 2]"), "[1, 2]", "joints[2].alpha",
     "expected a number or expression, got a list"),
    ("mapping_for_number", edit("a: 0.25", "a: {x: 1}"), "{x: 1}", "joints[2].a",
     "expected a number or expression, got a mapping"),
    ("bool_for_number", edit("d: 0.05", "d: yes"), "yes", "joints[2].d",
     "expected a number or expression, got a boolean ('yes')"),
    ("number_for_string", edit("name: j2", "name: 5"), "5", "joints[1].name", "expected a string, got a number ('5')"),
    ("missing_top_key", edit("convention: standard\n", ""), None, "convention", "missing required key"),
    ("missing_joint_key", edit("    type: revolute\n    a: a2\n", "    a: a2\n"), "name: j2", "joints[1].type",
     "missing required key"),
    ("missing_d_of_revolute", edit("    d: 0.05\n", ""), "name: j3", "joints[2].d", "missing required key"),
    ("unknown_parameter", edit("a: a2", "a: a7"), "a7", "joints[1].a", "unknown parameter 'a7' in 'a7'"),
    ("bad_expression", edit("a: a2", 'a: "a2 +* 2"'), '"a2 +* 2"', "joints[1].a", "unexpected '*' in 'a2 +* 2'"),
    ("unbalanced_parenthesis", edit("a: a2", 'a: "(a2 + 1"'), '"(a2', "joints[1].a",
     "expression ends too early in '(a2 + 1'"),
    ("division_by_zero", edit("a: a2", 'a: "a2 / (1 - 1)"'), '"a2', "joints[1].a",
     "division by zero in 'a2 / (1 - 1)'"),
    ("limits_reversed", edit("[-170, 170]", "[170, -170]"), "[170", "joints[2].limits",
     "lower limit '170' is above upper limit '-170'"),
    ("limits_length", edit("[-170, 170]", "[-170, 0, 170]"), "[-170", "joints[2].limits",
     "expected a list of 2 items, got 3"),
    ("duplicate_joint_name", edit("name: j2", "name: j1"), "j1\n    type: revolute\n    a: a2", "joints[1].name",
     "duplicate joint name 'j1' (also joints[0])"),
    ("duplicate_yaml_key", edit("    a: 0.25\n", "    a: 0.25\n    a: 0.1\n"), "a: 0.1", "joints[2].a",
     "duplicate key"),
    ("duplicate_top_key", BASE + "name: other\n", "name: other", "name", "duplicate key"),
    ("theta_on_revolute", edit("    d: 0.3\n", "    d: 0.3\n    theta: 5\n"), "5", "joints[0].theta",
     "not allowed for a revolute joint (theta = q + offset)"),
    ("d_on_prismatic", edit("    type: revolute\n    a: 0.25", "    type: prismatic\n    theta: 0\n    a: 0.25"),
     "0.05", "joints[2].d", "not allowed for a prismatic joint (d = q + offset)"),
    ("bad_robot_name", edit("name: arm", "name: Arm"), "Arm", "name",
     "invalid name 'Arm' (expected ^[a-z][a-z0-9_]{0,47}$)"),
    ("bad_joint_name", edit("name: j2", "name: 2nd"), "2nd", "joints[1].name",
     "invalid name '2nd' (expected ^[A-Za-z_][A-Za-z0-9_]{0,47}$)"),
    ("bad_parameter_name", edit("  a2: 0.4", "  a-2: 0.4"), "a-2", "parameters.a-2",
     "invalid parameter name 'a-2' (expected ^[A-Za-z_][A-Za-z0-9_]{0,47}$)"),
    ("bad_convention", edit("convention: standard", "convention: dh"), "dh", "convention",
     "expected one of standard, modified, got 'dh'"),
    ("bad_angle_unit", edit("angle_unit: deg", "angle_unit: degrees"), "degrees", "angle_unit",
     "expected one of deg, rad, got 'degrees'"),
    ("bad_joint_type", edit("type: revolute\n    a: a2", "type: spherical\n    a: a2"), "spherical",
     "joints[1].type", "expected one of revolute, prismatic, got 'spherical'"),
    ("no_joints", BASE[: BASE.index("joints:")] + "joints: []\ntask: [x]\n", "[]", "joints",
     "expected 1 to 32 joints, got 0"),
    ("33_joints", BASE[: BASE.index("joints:")] + "joints:\n" + rows(33), "- {type", "joints",
     "expected 1 to 32 joints, got 33"),
    ("task_missing", edit("task: [x, y, z]\n", ""), None, "task",
     "missing required key (a robot with 3 joints must declare its task, e.g. [x, y])"),
    ("task_out_of_order", edit("[x, y, z]", "[z, x]"), "[z, x]", "task",
     "components must be distinct and in the order x, y, z, roll, pitch, yaw: write [x, z]"),
    ("task_duplicate", edit("[x, y, z]", "[x, y, y]"), "[x, y, y]", "task",
     "components must be distinct and in the order x, y, z, roll, pitch, yaw: write [x, y]"),
    ("task_unknown", edit("[x, y, z]", "[x, y, w]"), "w]", "task[2]",
     "expected one of x, y, z, roll, pitch, yaw, got 'w'"),
    ("task_empty", edit("[x, y, z]", "[]"), "[]", "task", "expected at least one component"),
    ("nan", edit("a: 0.25", "a: .nan"), ".nan", "joints[2].a", "expected a finite number, got .nan"),
    ("inf", edit("d: 0.05", "d: -.inf"), "-.inf", "joints[2].d", "expected a finite number, got -.inf"),
    ("huge", edit("a: 0.25", "a: 1e300"), "1e300", "joints[2].a",
     "value 1e300 is out of range (|value| <= 1e+06) in '1e300'"),
    ("tiny", edit("a: 0.25", "a: 1e-400"), "1e-400", "joints[2].a",
     "value 1e-400 is too small for a double (underflows) in '1e-400'"),
    ("huge_exponent", edit("a: 0.25", 'a: "2**100"'), '"2**100"', "joints[2].a",
     "exponent 100 too large (|exponent| <= 16) in '2**100'"),
    ("long_expression", edit("a: 0.25", "a: " + "1" * 300), "111", "joints[2].a",
     "expression longer than 200 characters in '" + "1" * 60 + "'..."),
    ("non_scalar_key", BASE + "? [a, b]\n: 1\n", "[a, b]", "file", "expected a name as key, got a list"),
    ("control_in_description", edit("description: test arm", 'description: "one\\x07two"'), '"one', "description",
     "must be lines of printable characters"),
    ("multiline_length_unit", edit("description: test arm", 'length_unit: "m\\nm"'), '"m', "length_unit",
     "must be one line of printable characters"),
    ("comment_in_description", edit("description: test arm", "description: ends */ here"), "ends", "description",
     "may not contain '*/' (it is copied into generated comments and strings; "
     "not allowed: \\ \"\"\" /* */ ??)"),
    ("free_joint_needs_seven", BASE + "ik: {free_joint: 2}\n", "2}", "ik.free_joint",
     "a free joint needs 7 joints and the full pose task (one joint more than the task), not 3 joints for 3 components"),
    ("free_joint_out_of_range", BASE + "ik: {free_joint: 4}\n", "4}", "ik.free_joint", "expected a joint number 1 to 3, got 4"),
    ("free_joint_not_a_number", BASE + "ik: {free_joint: last}\n", "last", "ik.free_joint",
     "expected a joint number 1 to 3, got a string ('last')"),
    ("free_joint_misspelt", BASE + "ik: {free: 2}\n", "free", "ik.free",
     "unknown key; expected one of: free_joint, nearest_class"),
    ("nearest_class_not_a_flag", BASE + "ik: {nearest_class: 0}\n", "0}", "ik.nearest_class",
     "expected true or false, got a number ('0')"),
    ("free_joint_prismatic", "name: slide7\nconvention: standard\njoints:\n" + rows(6)
     + "  - {type: prismatic, a: 0, alpha: 0, theta: 0}\nik: {free_joint: 7}\n", "7}", "ik.free_joint",
     "joint 7 is prismatic: the free joint must be revolute"),
]
# Mistakes found while reading the YAML, reported without a key path: (id, text, where, message),
# `where` a token of the text or a (line, column) the YAML parser gives.
DEEP = edit("a: 0.25", "a: " + "[" * 100 + "]" * 100)
YAML_CASES = [
    ("yaml_syntax", edit("task: [x, y, z]", "task: [x, y, z"), (25, 1),
     "invalid YAML: expected ',' or ']', but got '<stream end>'"),
    ("yaml_tab", edit("  a2: 0.4", "\ta2: 0.4"), "\ta2", "invalid YAML: found character '\\t' that cannot start any token"),
    ("alias", edit("  a2: 0.4", "  a2: &len 0.4").replace("a: a2", "a: *len"), "*len",
     "YAML aliases (*name) are not supported; write the value out"),
    ("merge_key", BASE + "base: &b {xyz: [0, 0, 0]}\ntool: {<<: *b}\n", "*b",
     "YAML aliases (*name) are not supported; write the value out"),
    # a joint's value sits at depth 3 (file, joints, joint): the list at depth MAX_NESTING is refused
    ("deep_nesting", DEEP, (position(DEEP, "[")[0], position(DEEP, "[")[1] + MAX_NESTING - 3),
     f"nested deeper than {MAX_NESTING} levels"),
    ("two_documents", BASE + "---\nname: other\n", "---", "invalid YAML: but found another document"),
    ("empty_file", "", (1, 1), "file is empty"),
    ("only_comments", "# nothing here\n", (1, 1), "file is empty"),
    ("not_a_mapping", "- 1\n- 2\n", (1, 1), "file: expected a mapping, got a list"),
]


def validate(tmp_path, data: bytes):
    path = tmp_path / "x.yaml"
    path.write_bytes(data)
    return str(path), CliRunner().invoke(main, ["validate", str(path)])


@pytest.mark.parametrize("text, token, key, message", [case[1:] for case in CASES], ids=[case[0] for case in CASES])
def test_mistake_is_located(tmp_path, text, token, key, message):
    path, result = validate(tmp_path, text.encode())
    line, column = position(text, token) if token else (1, 1)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr == f"jacgen: error: {path}:{line}:{column}: {key}: {message}\n"


@pytest.mark.parametrize("text, where, message", [case[1:] for case in YAML_CASES],
                         ids=[case[0] for case in YAML_CASES])
def test_yaml_mistake_is_located(tmp_path, text, where, message):
    path, result = validate(tmp_path, text.encode())
    line, column = position(text, where) if isinstance(where, str) else where
    assert result.exit_code == 2
    assert result.stderr == f"jacgen: error: {path}:{line}:{column}: {message}\n"


def test_non_utf8_bytes_are_located(tmp_path):
    data = BASE.replace("name: j2", "name: j\xe92").encode("latin-1")
    path, result = validate(tmp_path, data)
    line, column = position(BASE, "j2")
    assert result.exit_code == 2
    assert result.stderr == f"jacgen: error: {path}:{line}:{column + 1}: file is not valid UTF-8\n"


def test_missing_file(tmp_path):
    path = tmp_path / "absent.yaml"
    result = CliRunner().invoke(main, ["validate", str(path)])
    assert result.exit_code == 2
    assert result.stderr == f"jacgen: error: {path}:1:1: cannot read file: No such file or directory\n"


def test_valid_base_and_first_error_of_several(tmp_path):
    good = tmp_path / "good.yaml"
    good.write_text(BASE)
    bad = tmp_path / "bad.yaml"
    bad.write_text(edit("alpha: -90", "alpha: [1]"))
    result = CliRunner().invoke(main, ["validate", str(good), str(bad)])
    assert result.exit_code == 2
    assert result.stdout == f"{good}: ok (arm, 3 joints)\n"
    assert len(result.stderr.splitlines()) == 1


def test_subprocess_prints_one_line_without_traceback(tmp_path):
    path = tmp_path / "x.yaml"
    path.write_text(edit("alpha: -90", "alpha: [1, 2]"))
    run = subprocess.run([sys.executable, "-m", "jacgen", "validate", str(path)], cwd=ROOT,
                         capture_output=True, text=True, timeout=120)
    line, column = position(path.read_text(), "[1, 2]")
    assert run.returncode == 2
    assert run.stdout == ""
    assert run.stderr == (f"jacgen: error: {path}:{line}:{column}: joints[2].alpha: "
                          "expected a number or expression, got a list\n")


# -- valid values ----------------------------------------------------------------------------
def load(text: str):
    return parse_robot(text.encode(), "x.yaml")


def test_degrees_and_radians_give_the_same_exact_values():
    in_degrees = load(edit("alpha: 0\n", "alpha: 30\n"))
    in_radians = load(edit("angle_unit: deg", "angle_unit: rad", BASE)
                      .replace("alpha: 90", "alpha: pi/2").replace("alpha: 0\n", "alpha: pi/6\n")
                      .replace("alpha: -90", "alpha: -pi/2").replace("[-170, 170]", "[-170*pi/180, 170*pi/180]"))
    for deg, rad, exact in zip(in_degrees.joints, in_radians.joints, (sympy.pi / 2, sympy.pi / 6, -sympy.pi / 2)):
        assert deg.alpha == rad.alpha
        assert deg.alpha.exact == exact
        assert deg.alpha.approx == pytest.approx(float(exact), rel=1e-15)
    assert in_degrees.joints[2].limits == in_radians.joints[2].limits
    assert in_degrees.joints[2].limits == pytest.approx((-170 * math.pi / 180, 170 * math.pi / 180), rel=1e-15)


@pytest.mark.parametrize("written, exact", [
    ("1.5707963267948966", sympy.pi / 2), ("3.141592653589793", sympy.pi), ("-1.5707963267948966", -sympy.pi / 2),
    ("4.71238898038469", 3 * sympy.pi / 2), ("1.5707963", sympy.Rational(15707963, 10**7)),
])
def test_decimal_angles_near_quarter_turns_become_exact(written, exact):
    robot = load(edit("angle_unit: deg", "angle_unit: rad").replace("alpha: 0\n", f"alpha: {written}\n"))
    assert robot.joints[1].alpha.exact == exact
    assert robot.joints[1].alpha.approx == pytest.approx(float(written), abs=1e-9)


PARAMETERS = {"d4": Value(sympy.Rational(4318, 10000), 0.4318), "a2": Value(sympy.Rational(2, 5), 0.4)}


@pytest.mark.parametrize("text, exact, approx", [
    ("-d4", -sympy.Rational(4318, 10000), -0.4318),
    ("pi/2", sympy.pi / 2, math.pi / 2),
    ("a2 + 0.1", sympy.Rational(1, 2), 0.4 + 0.1),
    ("sqrt(2)/2", sympy.sqrt(2) / 2, math.sqrt(2) / 2),
    ("2**-1", sympy.Rational(1, 2), 0.5),
    ("-2**2", -4, -4.0),
    ("(1 + 2) * 3 - 4 / 8", sympy.Rational(17, 2), 8.5),
    ("26.45 * 0.0254", sympy.Rational(67183, 100000), 26.45 * 0.0254),
    ("1.5e-3", sympy.Rational(3, 2000), 1.5e-3),
])
def test_expressions_evaluate_exactly_and_as_floats(text, exact, approx):
    value = parse(text, PARAMETERS.__getitem__)
    assert sympy.simplify(value.exact - exact) == 0
    assert value.approx == pytest.approx(approx, rel=1e-15)


@pytest.mark.parametrize("text", ["", "1 +", "2 ** ", "sqrt 2", "sqrt(-1)", "(-8)**(1/3)", "0**-1", "1 2", "a2 $ 1"])
def test_bad_expressions_raise_expression_error(text):
    with pytest.raises(ExpressionError):
        parse(text, PARAMETERS.__getitem__)


def test_symbolic_parameter_stays_a_symbol():
    robot = load(edit("  a2: 0.4", "  a2: {value: 0.4, symbolic: true}"))
    symbol = sympy.Symbol("a2", real=True)
    assert robot.joints[1].a == Value(symbol, 0.4)
    assert [(p.name, p.value, p.symbolic) for p in robot.symbolic_parameters] == [("a2", 0.4, True)]
    in_expression = load(edit("  a2: 0.4", "  a2: {value: 0.4, symbolic: true}").replace("a: a2", 'a: "2*a2 + 0.1"'))
    assert in_expression.joints[1].a.exact == 2 * symbol + sympy.Rational(1, 10)
    assert in_expression.joints[1].a.approx == pytest.approx(0.9, rel=1e-15)


def test_base_and_tool_default_to_identity_and_convert_rpy():
    robot = load(BASE)
    assert all(v.exact == 0 for pose in (robot.base, robot.tool) for v in pose.xyz + pose.rpy)  # identity poses
    posed = load(BASE + "tool: {xyz: [0, 0, 0.1], rpy: [90, 0, 45]}\nbase: {rpy: [0, 180, 0]}\n")
    assert [v.exact for v in posed.tool.xyz] == [0, 0, sympy.Rational(1, 10)]
    assert [v.exact for v in posed.tool.rpy] == [sympy.pi / 2, 0, sympy.pi / 4]
    assert [v.exact for v in posed.base.xyz] == [0, 0, 0]
    assert [v.exact for v in posed.base.rpy] == [0, sympy.pi, 0]


def test_defaults_of_optional_keys():
    robot = load(edit("  - name: j1\n    type", "  - type").replace("    limits: [-170, 170]\n", ""))
    assert robot.joints[0].name == "joint1"
    assert robot.joints[2].limits is None
    assert robot.joints[0].offset == Value(0, 0.0)
    assert robot.length_unit == "m"
    six = load(BASE[: BASE.index("joints:")] + "joints:\n" + rows(6))
    assert six.task == ("x", "y", "z", "roll", "pitch", "yaw")
    assert load(BASE[: BASE.index("joints:")] + "joints:\n" + rows(32)).dof == 32


def test_error_carries_its_parts():
    with pytest.raises(RobotFileError) as caught:
        load(edit("a: a2", "a: a7"))
    error = caught.value
    assert (error.path, error.line, error.column, error.key) == ("x.yaml", *position(BASE, "a2\n    alpha"), "joints[1].a")
