"""The URDFs of tests/data/urdf (tests/data/urdf/README.md), their import and Pinocchio's fk
of them, for tests/test_urdf_import.py and tests/test_vendor_urdfs.py (fk against Pinocchio)
and tests/test_urdf_round_trip.py (generate and verify)."""

import math
import re
from decimal import Decimal
from pathlib import Path

import numpy as np
import pinocchio as pin

from jacgen.urdf_import import import_urdf

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"
# name: (file, base link, tip link, closed-form ik class of the imported arm)
URDFS = {
    "ur5": ("ur5_robot.urdf", "base", "tool0", "three_parallel"),
    "ur10": ("ur10_robot.urdf", "base_link", "ee_link", "three_parallel"),
    "panda": ("panda.urdf", None, "panda_hand_tcp", "spherical_wrist_intersecting"),  # joint 7 free
    "kinova_jaco2": ("kinova.urdf", None, "j2s6s200_end_effector", "spherical_wrist_parallel"),
    "xarm7": ("xarm7.urdf", None, None, "spherical_wrist_intersecting"),  # writes 1.5708: pi/2 to its digits
    "z1": ("z1.urdf", None, "link06", "three_parallel"),
    "tiago": ("tiago_no_hand.urdf", "base_footprint", "arm_tool_link", None),
    "pr2": ("pr2.urdf", "base_link", "r_gripper_palm_link", None),
    "so101": ("so101.urdf", None, "gripper_frame_link", None),
    "talos_arm": ("talos_left_arm.urdf", None, "gripper_left_base_link", "spherical_wrist_intersecting"),
    "pendulum": ("double_pendulum_continuous.urdf", None, None, None),
    "finger_edu": ("finger_edu.urdf", None, None, None),
    "baxter": ("baxter.urdf", "base", "left_gripper_base_link", "general_6r"),  # joint 7 (or 1) free
}


def imported(key: str, convention: str = "standard", **options):
    """The import of URDFS[key] (jacgen.urdf_import.Imported)."""
    file, base, tip, _ = URDFS[key]
    return import_urdf(str(DATA / file), base, tip, convention, **options)


def as_read(text: str) -> str:
    """The URDF with each rpy angle that docs/urdf.md makes exact written out as that multiple
    of pi/2 to full double precision, so that Pinocchio reads the numbers jacgen reads: an angle
    within 1e-9 of k*pi/2, or, for k != 0, within two units of its last written digit and 1e-3."""

    def exact(match):
        values = []
        for token in match.group(1).split():
            try:
                value = float(token)
            except ValueError:  # xacro left-overs off the chain (tiago)
                values.append(token)
                continue
            quarter_turns = round(value / (math.pi / 2))
            change = abs(value - quarter_turns * math.pi / 2)
            unit = 10.0 ** Decimal(token).as_tuple().exponent
            values.append(repr(quarter_turns * math.pi / 2) if change < 1e-9 or quarter_turns and change < min(2 * unit, 1e-3)
                          else token)
        return f'rpy="{" ".join(values)}"'

    return re.sub(r'rpy="([^"]*)"', exact, text)


def pinocchio_fk(urdf_text: str, tmp_path, robot, base: str | None, tip: str, configurations):
    """Pinocchio's pose of `tip` in `base` at each configuration of the imported robot's joints
    (the URDF joint names are the robot file's; continuous joints take (cos, sin))."""
    path = tmp_path / "model.urdf"
    path.write_text(urdf_text)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    poses = []
    for q in configurations:
        q_pin = pin.neutral(model)
        for joint, value in zip(robot.joints, q):
            model_joint = model.joints[model.getJointId(joint.name)]
            if model_joint.nq == 2:
                q_pin[model_joint.idx_q:model_joint.idx_q + 2] = (math.cos(value), math.sin(value))
            else:
                q_pin[model_joint.idx_q] = value
        pin.framesForwardKinematics(model, data, q_pin)
        base_pose = data.oMf[model.getFrameId(base, pin.BODY)] if base else pin.SE3.Identity()
        poses.append((base_pose.inverse() * data.oMf[model.getFrameId(tip, pin.BODY)]).homogeneous)
    return poses


def configurations(robot, count=30, seed=1):
    rng = np.random.default_rng(seed)
    return [np.array([rng.uniform(*j.limits) if j.limits else rng.uniform(-math.pi, math.pi) for j in robot.joints])
            for _ in range(count)]
