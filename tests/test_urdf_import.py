"""URDF import (docs/urdf.md): real URDFs that nobody here wrote (tests/data/urdf/README.md)
become robot files whose fk equals Pinocchio's fk of the URDF; UR5 and Panda match their
published DH tables and the shipped robot files; hostile XML is one line and exit code 2."""

import math
import re

import numpy as np
import pytest
import sympy
from click.testing import CliRunner

from jacgen.checking import reference
from jacgen.cli import main
from jacgen.inputs.values import parse
from jacgen.urdf_import import import_urdf, literal
from jacgen.inputs.robot_file import load_robot, parse_robot
from jacgen.model.structure import classify

from conftest import ROOT
from support.urdf import DATA, URDFS, as_read, configurations, imported, pinocchio_fk

FK_TOLERANCE = 1e-12
REACH = 2.0  # metres: bounds the lever arm of every arm here


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("name", list(URDFS))
def test_fk_equals_pinocchio(name, convention, tmp_path):
    file, base, tip, _ = URDFS[name]
    result = imported(name, convention)
    robot = result.robot
    tip = tip or re.search(r"-> (\w+)\)", robot.description).group(1)
    qs = configurations(robot)
    text = (DATA / file).read_text()
    ours = reference.fk(robot, np.array(qs))
    exact = max(np.abs(a - b).max() for a, b in zip(ours, pinocchio_fk(as_read(text), tmp_path, robot, base, tip, qs)))
    assert exact < FK_TOLERANCE
    # Against the numbers as written: the difference import-urdf reports (at its own 20
    # configurations), and each angle made exact turns the rest of the arm by at most `snapped`,
    # so the tool moves by at most that times the reach, per joint transform.
    literal_difference = max(np.abs(a - b).max() for a, b in zip(ours, pinocchio_fk(text, tmp_path, robot, base, tip, qs)))
    assert literal_difference < 2 * result.fk_difference + FK_TOLERANCE
    assert result.fk_difference < REACH * result.snapped * (text.count("<joint") + 2) + FK_TOLERANCE


@pytest.mark.parametrize("name", list(URDFS))
def test_structure_and_ik_class_survive_import(name):
    assert classify(imported(name).robot).solver == URDFS[name][3]


def random_urdf(seed: int) -> str:
    """A random serial URDF nobody tuned for: 1 to 8 moving joints (revolute, continuous,
    prismatic) with fixed joints between, offsets of 0 or up to 0.5 m, angles of 0, k*90
    degrees or anything, axes along +-x/y/z or anywhere, and a fixed tool."""
    rng = np.random.default_rng(seed)

    def length():
        return "0" if rng.random() < 0.4 else f"{rng.uniform(-0.5, 0.5):.4f}"

    def angle():
        kind = rng.random()
        return ("0" if kind < 0.35 else repr(int(rng.integers(-2, 3)) * math.pi / 2) if kind < 0.75
                else f"{rng.uniform(-3, 3):.6f}")

    def axis():
        if rng.random() < 0.8:
            along, sign = rng.integers(3), int(rng.choice([-1, 1]))
            return " ".join(str(sign if k == along else 0) for k in range(3))
        return " ".join(f"{x:.5f}" for x in rng.normal(size=3))

    def origin():
        return f'<origin xyz="{length()} {length()} {length()}" rpy="{angle()} {angle()} {angle()}"/>'

    lines, moving, k = ['<robot name="random">', '<link name="l0"/>'], 0, 0
    count = int(rng.integers(1, 9))
    while moving < count:
        k += 1
        kind = rng.choice(["revolute", "revolute", "revolute", "prismatic", "continuous", "fixed"])
        limit = (f'<limit lower="-{rng.uniform(0.5, 3):.3f}" upper="{rng.uniform(0.5, 3):.3f}" effort="1" velocity="1"/>'
                 if kind in ("revolute", "prismatic") else "")
        lines += [f'<link name="l{k}"/>', f'<joint name="j{k}" type="{kind}"><parent link="l{k - 1}"/>'
                  f'<child link="l{k}"/>{origin()}<axis xyz="{axis()}"/>{limit}</joint>']
        moving += kind != "fixed"
    lines += [f'<link name="l{k + 1}"/>', f'<joint name="tool" type="fixed"><parent link="l{k}"/>'
              f'<child link="l{k + 1}"/>{origin()}</joint>', "</robot>"]
    return "\n".join(lines)


@pytest.mark.parametrize("seed", range(40))
def test_random_urdf_fk_equals_pinocchio(seed, tmp_path):
    path = tmp_path / "random.urdf"
    path.write_text(random_urdf(seed))
    for convention in ("standard", "modified"):
        result = import_urdf(str(path), convention=convention)
        assert result.robot.name == "random_robot"
        tip = re.search(r"-> (\w+)\)", result.robot.description).group(1)
        qs = configurations(result.robot, 10, seed)
        poses = pinocchio_fk(path.read_text(), tmp_path, result.robot, None, tip, qs)
        assert max(np.abs(reference.fk(result.robot, q) - pose).max() for q, pose in zip(qs, poses)) < 1e-12


def test_ur5_is_universal_robots_published_table():
    """UR's published DH table of the UR5 (Universal Robots, "DH parameters for calculations
    of kinematics and dynamics"), exactly: its base frame is the URDF's `base`, its flange `tool0`."""
    robot = imported("ur5").robot
    published = {"d": ["0.089159", 0, 0, "0.10915", "0.09465", "0.0823"], "a": [0, "-0.425", "-0.39225", 0, 0, 0],
                 "alpha": [sympy.pi / 2, 0, 0, sympy.pi / 2, -sympy.pi / 2, 0]}
    for key, values in published.items():
        assert [getattr(joint, key).exact for joint in robot.joints] == [sympy.Rational(v) if isinstance(v, str) else v for v in values], key
    assert all(joint.offset.exact == 0 for joint in robot.joints)
    assert all(v.exact == 0 for pose in (robot.base, robot.tool) for v in pose.xyz + pose.rpy)  # identity poses


def test_ur5_matches_the_shipped_robot_file():
    """robots/ur5.yaml is rtb's UR5, whose d1 is 0.089459 where UR and the URDF have 0.089159
    (the Toolbox's DH and URDF UR5 disagree there); with that value it is the same arm. From
    base_link instead of UR's base, fk turns by pi about z, as the URDF's base_link-base joint says."""
    shipped_text = (ROOT / "robots" / "ur5.yaml").read_text()
    assert "d1: 0.089459" in shipped_text
    shipped = parse_robot(shipped_text.replace("d1: 0.089459", "d1: 0.089159").encode())
    from_base = imported("ur5").robot
    from_base_link = import_urdf(str(DATA / "ur5_robot.urdf"), "base_link", "tool0").robot
    turn = np.diag([-1.0, -1.0, 1.0, 1.0])  # Rz(pi)
    for q in configurations(shipped, 20):
        assert np.abs(reference.fk(from_base, q) - reference.fk(shipped, q)).max() < 1e-12
        assert np.abs(reference.fk(from_base_link, q) - turn @ reference.fk(shipped, q)).max() < 1e-12
    assert classify(from_base).solver == classify(load_robot(ROOT / "robots" / "ur5.yaml")).solver


def test_panda_matches_the_shipped_robot_file():
    """Modified DH to the flange (panda_link8) is robots/panda.yaml's table; the shipped file adds
    rtb's tool transl(0, 0, 0.103) @ trotz(-45 deg), written out here."""
    shipped = load_robot(ROOT / "robots" / "panda.yaml")
    robot = import_urdf(str(DATA / "panda.urdf"), None, "panda_link8", "modified").robot
    assert [(j.a.exact, j.alpha.exact, j.d.exact, j.offset.exact) for j in robot.joints] == \
        [(j.a.exact, j.alpha.exact, j.d.exact, j.offset.exact) for j in shipped.joints]
    c = s = math.sqrt(0.5)
    tool = np.array([[c, s, 0, 0], [-s, c, 0, 0], [0, 0, 1, 0.103], [0, 0, 0, 1]])
    for q in configurations(shipped, 20):
        assert np.abs(reference.fk(robot, q) @ tool - reference.fk(shipped, q)).max() < 1e-12
    assert classify(robot).solver == classify(shipped).solver


def test_degenerate_geometry_takes_the_documented_choices():
    tiago = imported("tiago").robot  # prismatic torso, parallel to arm joint 1: moved onto it
    assert tiago.joints[0].kind == "prismatic" and tiago.joints[0].a.exact == 0
    pr2 = imported("pr2").robot  # continuous forearm and wrist rolls: no limits
    assert [j.name for j in pr2.joints if j.limits is None] == ["r_forearm_roll_joint", "r_wrist_roll_joint"]
    kinova = imported("kinova_jaco2").robot  # axis 1 along -z of the base: d1 < 0 along it
    assert kinova.joints[0].d.exact == sympy.Rational("-0.2755") and kinova.joints[0].limits is None
    ur5 = imported("ur5").robot  # parallel axes 2, 3, 4: d = 0 on the first two, the offsets gather in d4
    assert [j.d.exact for j in ur5.joints[1:4]] == [0, 0, sympy.Rational("0.10915")]
    pendulum = imported("pendulum").robot  # 2 joints in the base's y-z plane
    assert pendulum.task == ("y", "z")
    xarm = imported("xarm7").robot  # its URDF writes 1.5708: pi/2 to its digits
    assert [j.alpha.exact for j in xarm.joints] == [-sympy.pi / 2] + [sympy.pi / 2] * 4 + [-sympy.pi / 2, 0]


def test_literals_read_back_exactly():
    values = [sympy.Rational("0.089159"), sympy.Rational(-1, 3), sympy.Rational(3, 1000) * sympy.sqrt(50773),
              sympy.Rational("-0.0001") * sympy.sqrt(8068765),
              sympy.sqrt(2), -sympy.pi / 2, 3 * sympy.pi / 4, sympy.pi, sympy.Rational("5.55112e-17")]
    for value in values:
        assert parse(literal(value).strip('"'), lambda name: None).exact == value
    assert literal(sympy.Float("0.1", 30)) == "0.1"


def run(*arguments):
    return CliRunner().invoke(main, [str(argument) for argument in arguments])


def test_cli_writes_the_file_and_reports_the_check(tmp_path):
    output = tmp_path / "ur5_urdf.yaml"
    result = run("import-urdf", DATA / "ur5_robot.urdf", "--base", "base", "--tip", "tool0", "--name", "ur5_urdf",
                 "-o", output)
    assert result.exit_code == 0, result.output
    assert result.stderr.startswith(f"jacgen: wrote {output}\njacgen: ur5_urdf: 6 joints; fk within ")
    robot = load_robot(output)
    assert robot.name == "ur5_urdf" and "sha256 cede880fc2a987ef" in output.read_text()


HOSTILE = {
    "billion_laughs": ('<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol">'
                       '<!ENTITY lol2 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">]>\n<robot name="r">&lol2;</robot>\n',
                       "2:", "a DOCTYPE is not allowed"),
    "external_entity": ('<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<robot name="&x;"/>\n',
                        "1:", "a DOCTYPE is not allowed"),
    "parameter_entity": ('<!DOCTYPE r [<!ENTITY % p SYSTEM "http://127.0.0.1/x.dtd"> %p;]>\n<robot name="r"/>\n',
                         "1:", "a DOCTYPE is not allowed"),
    "undeclared_entity": ('<robot name="r"><link name="&x;"/></robot>\n', "1:", "invalid XML: undefined entity"),
    "broken_xml": ('<robot name="r"><link name="a"></robot>\n', "1:", "invalid XML: mismatched tag"),
    "not_a_urdf": ("<html/>\n", "1:1", "expected a <robot> element"),
    "dangling_link": ('<robot name="r">\n<link name="a"/>\n<joint name="j" type="revolute"><parent link="a"/>'
                      '<child link="b"/></joint>\n</robot>\n', "3:", "joint[j].child.link: no link named 'b'"),
    "two_parents": ('<robot name="r">\n<link name="o"/><link name="a"/><link name="b"/>\n'
                    '<joint name="j0" type="revolute"><parent link="o"/><child link="a"/></joint>\n'
                    '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>\n'
                    '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint>\n</robot>\n',
                    "5:", "link 'a' is already the child of joint 'j0': a URDF is a tree"),
    "loop": ('<robot name="r">\n<link name="o"/><link name="a"/><link name="b"/>\n'
             '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>\n'
             '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint>\n</robot>\n',
             ":", "the joints of links 'a', 'b' form a loop"),
    "no_single_chain": ('<robot name="r">\n<link name="a"/><link name="b"/><link name="c"/>\n'
                        '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>\n'
                        '<joint name="j2" type="revolute"><parent link="a"/><child link="c"/></joint>\n</robot>\n',
                        "1:1: --tip", "link 'a' has 2 leaves below it ('b', 'c')"),
    "mimic": ('<robot name="r">\n<link name="a"/><link name="b"/><link name="c"/>\n'
              '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>\n'
              '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/><mimic joint="j1"/></joint>\n'
              '</robot>\n', "4:", "joint[j2].mimic: a mimic joint is on the chain"),
    "floating": ('<robot name="r">\n<link name="a"/><link name="b"/><link name="c"/>\n'
                 '<joint name="j1" type="floating"><parent link="a"/><child link="b"/></joint>\n'
                 '<joint name="j2" type="revolute"><parent link="b"/><child link="c"/></joint>\n</robot>\n',
                 "3:", "joint[j1].type: a floating joint is on the chain"),
    "xacro": ('<robot name="r">\n<link name="a"/><link name="b"/>\n<joint name="j" type="revolute">'
              '<parent link="a"/><child link="b"/><origin xyz="0 0 ${d1}"/></joint>\n</robot>\n',
              "3:", "joint[j].origin.xyz: not a decimal number: '${d1}' (a xacro file?"),
    "nan": ('<robot name="r">\n<link name="a"/><link name="b"/>\n<joint name="j" type="revolute">'
            '<parent link="a"/><child link="b"/><axis xyz="nan 0 1"/></joint>\n</robot>\n',
            "3:", "joint[j].axis.xyz: not a decimal number: 'nan'"),
    "no_moving_joint": ('<robot name="r">\n<link name="a"/><link name="b"/>\n<joint name="j" type="fixed">'
                        '<parent link="a"/><child link="b"/></joint>\n</robot>\n', "1:1", "no moving joint"),
    "empty": ("", "1:", "invalid XML: no element found"),
}


@pytest.mark.parametrize("case", list(HOSTILE))
def test_hostile_xml_is_one_line_and_exit_2(case, tmp_path):
    content, where, message = HOSTILE[case]
    path = tmp_path / f"{case}.urdf"
    path.write_text(content)
    output = tmp_path / "robot.yaml"
    output.write_text("kept\n")
    result = run("import-urdf", path, "-o", output)
    assert result.exit_code == 2
    assert result.stdout == ""
    assert result.stderr.count("\n") == 1 and result.stderr.startswith(f"jacgen: error: {path}:")
    line = result.stderr[len(f"jacgen: error: {path}:"):]
    assert line.startswith(where.lstrip(":")) or where == ":", result.stderr
    assert message in result.stderr
    assert output.read_text() == "kept\n"  # nothing on disk is damaged


NEARLY_PARALLEL_URDF = """<robot name="skewed">
<link name="l0"/><link name="l1"/><link name="l2"/><link name="l3"/>
<joint name="j1" type="revolute"><parent link="l0"/><child link="l1"/><axis xyz="0 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.4 0 0"/><axis xyz="0.00001 0 1"/>
  <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j3" type="fixed"><parent link="l2"/><child link="l3"/><origin xyz="0.3 0 0"/></joint>
</robot>
"""


def test_nearly_parallel_axes_are_refused_with_the_snap_that_imports_them(tmp_path):
    """Axes 1e-5 rad from parallel whose URDF no digit rule can judge (an axis, not an rpy):
    the common normal lies 4e4 m away. The one line names the joints, the angle, the DH length
    it would need and the --snap that imports the arm, with its effect on fk; that --snap does."""
    path = tmp_path / "skewed.urdf"
    path.write_text(NEARLY_PARALLEL_URDF)
    result = run("import-urdf", path)
    assert result.exit_code == 2 and result.stderr.count("\n") == 1, result.output
    assert re.fullmatch(rf"jacgen: error: {re.escape(str(path))}: joints 'j1' and 'j2': their axes are 1e-05 rad from "
                        r"parallel, so the DH common normal between them needs lengths of 4e\+04 m, where the URDF's "
                        r"chain spans 0.7 m; if they are meant to be parallel, import with --snap 0.0001, which makes "
                        r"them so and moves fk by at most (\S+) from the URDF as written\n", result.stderr), result.stderr
    effect = float(re.search(r"at most (\S+) from", result.stderr).group(1))
    assert 1e-6 < effect < 1e-5  # the tool 0.3 m beyond a joint turned by 1e-5 rad
    snapped = run("import-urdf", path, "--snap", "0.0001")
    assert snapped.exit_code == 0 and parse_robot(snapped.stdout.encode()).joints[1].alpha.exact == 0


def test_lengths_of_rounding_level_are_made_0_and_reported(tmp_path):
    """A URDF whose zeros a composed export wrote as 0.316 * cos(pi/2) (Franka's d = -1.93e-17):
    the DH lengths it gives are made 0, the header and the stderr line say so."""
    text = (DATA / "ur5_robot.urdf").read_text().replace('xyz="0.0 0.13585 0.0"', 'xyz="1.9349e-17 0.13585 0.0"')
    path = tmp_path / "ur5_noise.urdf"
    path.write_text(text)
    result = run("import-urdf", path, "--base", "base", "--tip", "tool0")
    assert result.exit_code == 0, result.output
    assert "# Lengths the DH fit computed below 1e-07 of the arm's size were made 0: joints[0].a -1.9e-17." in result.stdout
    assert "1 length(s) of rounding level made 0" in result.stderr
    assert parse_robot(result.stdout.encode()).joints[0].a.exact == 0


def test_huge_file_is_refused_before_parsing(tmp_path):
    path = tmp_path / "huge.urdf"
    with path.open("wb") as handle:
        handle.write(b'<robot name="r">')
        handle.truncate(17 << 20)
    result = run("import-urdf", path)
    assert result.exit_code == 2
    assert result.stderr == f"jacgen: error: {path}:1:1: file larger than {16 << 20} bytes\n"


def test_base_below_a_moving_joint_is_refused():
    result = run("import-urdf", DATA / "ur5_robot.urdf", "--base", "tool0", "--tip", "base_link")
    assert result.exit_code == 2
    assert "joint[wrist_3_joint]: link 'tool0' is below joint 'wrist_3_joint', which moves" in result.stderr
    assert result.stderr.count("\n") == 1
