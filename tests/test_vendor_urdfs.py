"""URDFs as vendors write them (docs/urdf.md, "Exactly k*90 degrees"): every arm of the corpus
(tests/data/urdf/README.md) imports as published, and again with its rpy angles written as
description packages write them, to 4, 6, 8 and 12 decimals and at full double precision
(xacro's `${pi/2}`), and with the zeros of its origins written as the rounding noise that a
composed export leaves (0.316 * cos(pi/2) = 1.9e-17). In every form:
- it imports (no length at rounding level, no far common normal is refused);
- its fk equals Pinocchio's fk of that very text within the change that import-urdf reports;
- the closed-form IK class is the one of the arm with exact axes."""

import math
import re

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.model.structure import classify
from jacgen.urdf_import import import_urdf

from support.urdf import DATA, configurations, pinocchio_fk

# file: (base link, tip link, closed-form IK class of the arm with exact axes)
CORPUS = {
    "ur3_robot.urdf": ("base", "tool0", "three_parallel"),
    "ur5_robot.urdf": ("base", "tool0", "three_parallel"),
    "ur10_robot.urdf": ("base_link", "ee_link", "three_parallel"),
    "so100.urdf": (None, "gripper", None),  # 5 joints
    "so101.urdf": (None, "gripper_frame_link", None),
    "xarm7.urdf": (None, None, "spherical_wrist_intersecting"),  # joint 7 free
    "z1.urdf": (None, "link06", "three_parallel"),
    "kinova.urdf": (None, "j2s6s200_end_effector", "spherical_wrist_parallel"),
    "panda.urdf": (None, "panda_hand_tcp", "spherical_wrist_intersecting"),
    "panda_arm_hand.urdf": (None, "panda_hand", "spherical_wrist_intersecting"),
    "lbr_iiwa_14_r820.urdf": (None, "tool0", "spherical_wrist_intersecting"),
    "puma560_robot.urdf": (None, "link7", "spherical_wrist_parallel"),
    "al5d_robot.urdf": (None, "link4", "yaw_pitch"),
    "irb140.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr3r540.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr5_arc.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr6r700sixx.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr10r1100sixx.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr16_2.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr120r2500pro.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr150_2.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "kr210l150.urdf": (None, "tool0", "spherical_wrist_parallel"),
    "px100.urdf": (None, "/ee_arm_link", "yaw_pitch"),
    "px150.urdf": (None, "/ee_arm_link", None),
    "rx200.urdf": (None, "/ee_arm_link", None),
    "vx300s.urdf": (None, "/ee_arm_link", "spherical_wrist_parallel"),
    "wx250s.urdf": (None, "/ee_arm_link", "spherical_wrist_parallel"),
    "tiago_no_hand.urdf": ("base_footprint", "arm_tool_link", None),
    "baxter.urdf": ("base", "left_gripper_base_link", "general_6r"),
}
FK_TOLERANCE = 1e-12
NOISE = "1.9349e-17"  # 0.316 * cos(pi/2) in doubles: what Franka's description writes for a 0 when exported


def _rpy(text: str, write) -> str:
    """`text` with every number of every rpy attribute replaced by write(value)."""

    def rewrite(match):
        parts = []
        for token in match.group(1).split():
            try:
                parts.append(write(float(token)))
            except ValueError:  # xacro left-overs off the chain (tiago)
                parts.append(token)
        return f'rpy="{" ".join(parts)}"'

    return re.sub(r'rpy="([^"]*)"', rewrite, text)


def _meant(value: float) -> float:
    """The angle the author meant: k*pi/2 when within 1e-3 of it, else the value."""
    quarter_turns = round(value / (math.pi / 2))
    return quarter_turns * math.pi / 2 if abs(value - quarter_turns * math.pi / 2) < 1e-3 else value


def _decimals(digits: int):
    """Each angle meant rounded to `digits` decimals, as a description written by hand or by
    a printer with that precision has it (UR's 1.57079632679, xArm's 1.5708)."""
    return lambda text: _rpy(text, lambda value: f"{_meant(value):.{digits}f}")


def _full_double(text: str) -> str:
    """Each angle meant written as its double, as xacro writes ${pi/2}."""
    return _rpy(text, lambda value: repr(_meant(value)))


def _rounding_noise(text: str) -> str:
    """`_full_double`, and every 0 of every joint origin's xyz written as rounding noise."""

    def rewrite(match):
        parts = [NOISE if float(token) == 0 else token for token in match.group(2).split()]
        return f'{match.group(1)}{" ".join(parts)}"'

    return re.sub(r'(<origin[^>]*\bxyz=")([^"]*)"', rewrite, _full_double(text))


FORMS = {"published": lambda text: text, "4 decimals": _decimals(4), "6 decimals": _decimals(6),
         "8 decimals": _decimals(8), "12 decimals": _decimals(12), "full double": _full_double,
         "rounding noise": _rounding_noise}


@pytest.mark.parametrize("form", list(FORMS))
@pytest.mark.parametrize("file", list(CORPUS))
def test_vendor_urdf_imports_with_its_fk_and_ik_class(file, form, tmp_path):
    base, tip, ik_class = CORPUS[file]
    text = FORMS[form]((DATA / file).read_text())
    path = tmp_path / file
    path.write_text(text)
    result = import_urdf(str(path), base, tip)
    robot = result.robot
    tip = tip or re.search(r"-> (\S+)\)", robot.description).group(1)
    qs = configurations(robot, 20, seed=3)
    difference = max(np.abs(reference.fk(robot, q) - pose).max()
                     for q, pose in zip(qs, pinocchio_fk(text, tmp_path, robot, base, tip, qs)))
    assert difference < 2 * result.fk_difference + FK_TOLERANCE
    # Each of the 3 rpy angles of a joint made exact moved by at most `snapped`, and turns the
    # rest of the arm by that: a rotation entry by that, a position by that times the reach.
    bound = max(1.0, robot.reach) * 3 * result.snapped * (text.count("<joint") + 2)
    assert result.fk_difference < bound + FK_TOLERANCE
    assert classify(robot).solver == ik_class
    if form == "rounding noise":  # some DH lengths come out at rounding level: made 0, and said so
        assert result.zeroed and all(abs(value) < 1e-15 for _, value in result.zeroed)
        assert f"were made 0: {result.zeroed[0][0]} " in result.text
