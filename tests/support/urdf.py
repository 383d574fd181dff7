"""The URDFs of tests/data/urdf (tests/data/urdf/README.md) and their import, for
tests/test_urdf_import.py (fk against Pinocchio) and tests/test_urdf_round_trip.py (generate
and verify)."""

from pathlib import Path

from jacgen.urdf_import import import_urdf

DATA = Path(__file__).resolve().parents[1] / "data" / "urdf"
# name: (file, base link, tip link, closed-form ik class of the imported arm)
URDFS = {
    "ur5": ("ur5_robot.urdf", "base", "tool0", "three_parallel"),
    "ur10": ("ur10_robot.urdf", "base_link", "ee_link", "three_parallel"),
    "panda": ("panda.urdf", None, "panda_hand_tcp", "spherical_wrist_intersecting"),  # joint 7 free
    "kinova_jaco2": ("kinova.urdf", None, "j2s6s200_end_effector", "spherical_wrist_parallel"),
    "xarm7": ("xarm7.urdf", None, None, "general_6r"),  # joint 7 (or 1) free
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
