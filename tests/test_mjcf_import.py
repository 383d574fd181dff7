"""MJCF import (docs/mjcf.md): MuJoCo is the reference. Real MJCF arms (robosuite's, and those
MuJoCo writes from the URDFs of tests/data/urdf) and one file holding every part of MJCF that
import-mjcf reads become robot files whose fk equals MuJoCo's `mj_kinematics` of the same file;
what jacgen cannot represent exactly, and hostile XML, is one line and exit code 2."""

import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest
from click.testing import CliRunner

from jacgen import arm
from jacgen.checking import reference
from jacgen.cli import main
from jacgen.solvers.model import Model
from jacgen.urdf_import import import_mjcf

from conftest import ROOT

mujoco = pytest.importorskip("mujoco")

DATA = ROOT / "tests" / "data" / "mjcf"
FK_TOLERANCE = 1e-12  # metres and rotation entries; every arm here reaches less than 2 m
# robosuite 1.5.2's arms (tests/data/mjcf/README.md), and the closed-form IK class of each: the
# UR5e's three parallel axes, a spherical wrist on the 7-axis arms with one (a free joint
# makes them 6R), and the general 6R solver for the Gen3 and the Sawyer, whose wrists are offset.
ROBOSUITE = {"ur5e": "three_parallel", "panda": "spherical_wrist_intersecting", "iiwa": "spherical_wrist_intersecting",
             "jaco": "spherical_wrist_intersecting", "xarm7": "spherical_wrist_intersecting", "kinova3": "general_6r",
             "sawyer": "general_6r"}


def kinematic_model(path):
    """MuJoCo's model of an MJCF file without its meshes (not shipped here; kinematics only)."""
    root = ElementTree.parse(path).getroot()
    for element in list(root.iter()):
        for child in list(element):
            if child.tag in ("mesh", "texture", "material") or (child.tag == "geom" and child.get("type") == "mesh"):
                element.remove(child)
    for geom in root.iter("geom"):
        geom.attrib.pop("material", None)
    included = {e.get("file"): (path.parent / e.get("file")).read_bytes() for e in root.iter("include")}
    return mujoco.MjModel.from_xml_string(ElementTree.tostring(root, encoding="unicode"), included)


def mujoco_fk(model, joints: list[str], tip: str, q: np.ndarray) -> np.ndarray:
    """The pose of the body or site `tip` by mj_kinematics, the named joints at q, the rest at 0."""
    data = mujoco.MjData(model)
    for name, value in zip(joints, q):
        data.qpos[model.joint(name).qposadr[0]] = value
    mujoco.mj_kinematics(model, data)
    pose = np.eye(4)
    try:
        site = model.site(tip).id
        pose[:3, :3], pose[:3, 3] = data.site_xmat[site].reshape(3, 3), data.site_xpos[site]
    except KeyError:
        body = model.body(tip).id
        pose[:3, :3], pose[:3, 3] = data.xmat[body].reshape(3, 3), data.xpos[body]
    return pose


def largest_difference(robot, model, tip: str, count: int = 50) -> float:
    """The largest difference of the robot file's fk from MuJoCo's, at random configurations
    within the joints' ranges (within +-pi where a hinge has none)."""
    rng = np.random.default_rng(0)
    low, high = np.array(robot.ranges).T
    joints = [joint.name for joint in robot.joints]
    return max(np.abs(reference.fk(robot, q) - mujoco_fk(model, joints, tip, q)).max()
               for q in rng.uniform(low, high, (count, robot.dof)))


@pytest.mark.parametrize("name", list(ROBOSUITE))
def test_robosuite_arms_equal_mujoco(name):
    path = DATA / "robosuite" / f"{name}.xml"
    imported = import_mjcf(str(path), tip="right_hand")
    assert imported.snapped == 0 and imported.fk_difference < FK_TOLERANCE
    assert largest_difference(imported.robot, kinematic_model(path), "right_hand") < FK_TOLERANCE
    form = Model(imported.robot).closed_form
    assert form is not None and form.solver == ROBOSUITE[name]


@pytest.mark.parametrize("tip", ["tool", "camera"])
def test_every_part_read_equals_mujoco(tip):
    """Degrees, the Euler sequence zYx, nested default classes, childclass, an include, each
    orientation, a frame, joints off their body's origin, a reference angle, a slide joint, a
    site as the tool, and limits as MuJoCo reads them (the roll's class makes it unlimited)."""
    path = DATA / "features.xml"
    imported = import_mjcf(str(path), tip=tip)
    model = kinematic_model(path)
    assert largest_difference(imported.robot, model, tip) < FK_TOLERANCE
    for joint in imported.robot.joints:
        limited = model.jnt_limited[model.joint(joint.name).id]
        assert (joint.limits is not None) == bool(limited), joint.name
        if limited:
            np.testing.assert_allclose(joint.limits, model.joint(joint.name).range, rtol=0, atol=1e-15)
    assert [joint.kind for joint in imported.robot.joints] == ["revolute"] * 3 + ["prismatic"] + ["revolute"] * 2


@pytest.mark.parametrize("urdf, tip", [("ur5_robot.urdf", "wrist_3_link"), ("kinova.urdf", "j2s6s200_link_6"),
                                       ("z1.urdf", "link06"), ("so101.urdf", "gripper_link")])
def test_what_mujoco_writes_from_a_urdf(urdf, tip, tmp_path):
    """MuJoCo's own MJCF of a vendor's URDF (mj_saveLastXML: quaternions, radians, fixed links
    fused) imports, and equals MuJoCo's fk."""
    root = ElementTree.parse(ROOT / "tests" / "data" / "urdf" / urdf).getroot()
    for link in root.iter("link"):
        for child in [c for c in link if c.tag in ("visual", "collision")]:
            link.remove(child)
    written = tmp_path / f"{urdf.removesuffix('.urdf')}.xml"
    mujoco.mj_saveLastXML(str(written), mujoco.MjModel.from_xml_string(ElementTree.tostring(root, encoding="unicode")))
    imported = import_mjcf(str(written), tip=tip)
    # An angle within 1e-9 of a quarter turn is one (docs/urdf.md; the SO-101 has one 1.1e-11 off),
    # which turns the rest of the arm by that angle; a length the DH fit computes at rounding
    # level is made 0, which moves the tool by that length.
    moved = 2.0 * imported.snapped * (imported.robot.dof + 2) + sum(abs(value) for _, value in imported.zeroed)
    assert largest_difference(imported.robot, mujoco.MjModel.from_xml_path(str(written)), tip) < FK_TOLERANCE + moved
    assert imported.snapped < 1e-9


def test_command_and_jacgen_arm(tmp_path):
    path = DATA / "robosuite" / "ur5e.xml"
    output = tmp_path / "ur5e.yaml"
    result = CliRunner().invoke(main, ["import-mjcf", str(path), "-o", str(output)])
    assert result.exit_code == 0, result.output
    assert "fk within 4e-16 of the MJCF file as written" in result.output
    assert output.read_text().startswith("# Imported by jacgen")
    module = arm(str(path), cache_folder=tmp_path / "cache")
    q = np.random.default_rng(1).uniform(-2, 2, (5, 6))
    model = kinematic_model(path)
    joints = [j.name for j in import_mjcf(str(path)).robot.joints]
    assert max(np.abs(module.fk(row) - mujoco_fk(model, joints, "right_hand", row)).max() for row in q) < FK_TOLERANCE


ARM = """<mujoco model="arm">
  <worldbody>
    <body name="link1" pos="0 0 0.1">
      <joint name="j1" axis="0 0 1"/>
      {inside}
      <body name="link2" pos="0.3 0 0">
        <joint name="j2" axis="0 1 0"/>
        <site name="tip" pos="0.2 0 0"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("text, arguments, expected", [
    (ARM.format(inside='<joint name="j1b" axis="1 0 0"/>'), [], ":5:7: body[link1]: body 'link1' has 2 joints"),
    (ARM.format(inside="").replace('<joint name="j2" axis="0 1 0"/>', '<joint name="j2" type="ball"/>'), [],
     "body[link2].joint[j2].type: a ball joint is on the chain"),
    (ARM.format(inside="").replace('<joint name="j1" axis="0 0 1"/>', "<freejoint/>"), [],
     "a free joint is on the chain"),
    (ARM.format(inside="").replace('axis="0 1 0"', 'axis="0 0 0"'), [], "body[link2].joint[j2].axis: the axis is zero"),
    (ARM.format(inside="").replace('pos="0.3 0 0"', 'pos="0.3 0 0" quat="1 0 0 0" euler="0 0 1"'), [],
     "body[link2]: quat and euler both orient it: give one"),
    (ARM.format(inside="").replace('axis="0 1 0"', 'axis="0 1 0" limited="true"'), [],
     "body[link2].joint[j2].range: limited without a range"),
    (ARM.format(inside="").replace('axis="0 1 0"', 'axis="0 1 0" class="wrist"'), [],
     "joint.class: no default class 'wrist'"),
    (ARM.format(inside=""), ["--tip", "hand"], "--tip: no body or site named 'hand'"),
    (ARM.format(inside=""), ["--base", "link2", "--tip", "link1"], "--base: body 'link2' is not above 'link1'"),
    (ARM.format(inside='<body name="camera"/>'), [], "--tip: the world has 2 leaf bodies below it ('camera', 'link2')"),
    ('<?xml version="1.0"?>\n<!DOCTYPE mujoco [<!ENTITY a "aaaa">]>\n<mujoco/>', [],
     ":2:18: a DOCTYPE is not allowed in an MJCF file"),
    ("<robot name='r'/>", [], "robot: expected a <mujoco> element (is this an MJCF file?)"),
    ('<mujoco><include file="arm.xml"/></mujoco>', [], "include.file: 'arm.xml' includes itself"),
    ('<mujoco><include file="missing.xml"/></mujoco>', [], "arm.xml:1:9: include.file: cannot read 'missing.xml'"),
    (ARM.format(inside="").replace('<joint name="j2" axis="0 1 0"/>', '<joint name="j2" range="1 1"/>'), [],
     "body[link2].joint[j2].range: the range's low end 1 is not below its high end 1"),
    (ARM.format(inside='<replicate count="2"><body name="copy"/></replicate>'), [],
     "replicate: <replicate> makes bodies that jacgen does not read"),
    ('<mujoco><worldbody><body name="a"><body name="b"/></body></worldbody></mujoco>', [],
     "arm.xml:1:1: no hinge or slide joint between the world and 'b'"),
])
def test_what_cannot_be_read_is_one_line(text, arguments, expected, tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(text)
    result = CliRunner().invoke(main, ["import-mjcf", str(path), *arguments])
    assert result.exit_code == 2, result.output
    assert len(result.output.strip().splitlines()) == 1 and expected in result.output, result.output


def test_worldbody_sections_are_one(tmp_path):
    """Bodies in a second <worldbody> (an included file's) are part of the tree: here the second
    leaf, so that the tip must be named."""
    path = tmp_path / "arm.xml"
    path.write_text(ARM.format(inside="").replace("</mujoco>", '<worldbody><body name="table"/></worldbody></mujoco>'))
    result = CliRunner().invoke(main, ["import-mjcf", str(path)])
    assert result.exit_code == 2 and "the world has 2 leaf bodies below it ('link2', 'table')" in result.output
    assert CliRunner().invoke(main, ["import-mjcf", str(path), "--tip", "tip"]).exit_code == 0


def test_hostile_files(tmp_path):
    """Deeply nested default classes read without recursion; a chain past the robot files' 32
    joints, and a file past 16 MB, are one line and exit code 2."""
    depth = 100_000
    deep = tmp_path / "deep.xml"
    classes = "".join(f'<default class="c{k}">' for k in range(depth)) + "</default>" * depth
    deep.write_text(f'<mujoco><default>{classes}</default><worldbody><body name="a"><joint name="j"/></body>'
                    "</worldbody></mujoco>")
    assert CliRunner().invoke(main, ["import-mjcf", str(deep)]).exit_code == 0
    long = tmp_path / "long.xml"
    long.write_text("<mujoco><worldbody>" + "".join(f'<body name="b{k}"><joint name="j{k}"/>' for k in range(5000))
                    + "</body>" * 5000 + "</worldbody></mujoco>")
    huge = tmp_path / "huge.xml"
    huge.write_bytes(b"<mujoco>" + b" " * (17 << 20) + b"</mujoco>")
    for path, expected in ((long, "the chain has 5000 joints; a robot file holds at most 32"),
                           (huge, "file larger than 16777216 bytes")):
        result = CliRunner().invoke(main, ["import-mjcf", str(path)])
        assert result.exit_code == 2 and expected in result.output and len(result.output.strip().splitlines()) == 1
