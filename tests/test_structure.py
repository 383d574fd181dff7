"""Structure detection: the zero-configuration geometry against the numpy reference, the class
of every shipped robot, and robots built to fall in (or just outside) each class."""

import re
import time

import numpy as np
import pytest

from jacgen.checking import reference
from jacgen.inputs.robot_file import parse_robot
from jacgen.model.structure import SOLVERS, Geometry, classify

from conftest import ROBOT_NAMES, robot

EXPECTED = {
    "planar_2r": "planar",
    "planar_3r": "planar",
    "scara": "planar",
    "rexarm": "yaw_pitch",
    "puma560": "spherical_wrist_parallel",
    "kr5": "spherical_wrist_parallel",
    "stanford": "spherical_wrist_prismatic",
    "ur5": "three_parallel",
    "iiwa": "spherical_wrist_intersecting",  # joint 3 free
    "panda": "spherical_wrist_intersecting",  # joint 7 free, solved from the tool back
    "jaco": "general_6r",
    "mico": "general_6r",
    "manocha_canny": "general_6r",
    "ur5_calibrated": "general_6r",
    "sawyer": "general_6r",  # joint 7 free
    "panda_calibrated": "general_6r",  # joint 7 free
}

# Craig's Puma 560 table (modified DH): the same arm class whatever the convention.
PUMA_MODIFIED = """
name: puma_mdh
convention: modified
angle_unit: deg
joints:
  - {type: revolute, alpha: 0,   a: 0,      d: 0,       offset: 0}
  - {type: revolute, alpha: -90, a: 0,      d: 0,       offset: 0}
  - {type: revolute, alpha: 0,   a: 0.4318, d: 0.15005, offset: 0}
  - {type: revolute, alpha: -90, a: 0.0203, d: 0.4318,  offset: 0}
  - {type: revolute, alpha: 90,  a: 0,      d: 0,       offset: 0}
  - {type: revolute, alpha: -90, a: 0,      d: 0,       offset: 0}
"""
# Axes 1, 2 intersect but 2, 3 are not parallel (alpha2 = 40 deg): the SP3 + SP2 variant.
TWISTED = """
name: twisted
convention: standard
angle_unit: deg
joints:
  - {type: revolute, a: 0,    alpha: 90,  d: 0.5, offset: 0}
  - {type: revolute, a: 0.4,  alpha: 40,  d: 0.1, offset: 0}
  - {type: revolute, a: 0.05, alpha: -90, d: 0.2, offset: 0}
  - {type: revolute, a: 0,    alpha: 90,  d: 0.4, offset: 0}
  - {type: revolute, a: 0,    alpha: -90, d: 0,   offset: 0}
  - {type: revolute, a: 0,    alpha: 0,   d: 0.1, offset: 0}
"""
# A wrist offset (d5) breaks the spherical wrist, and no three axes are parallel.
NO_STRUCTURE = TWISTED.replace("name: twisted", "name: skewed").replace(
    "alpha: -90, d: 0,   offset: 0}", "alpha: -90, d: 0.07, offset: 0}")


def test_zero_geometry_matches_the_reference():
    """Axes and points at q = 0 (exact, from the symbolic chain) against the numpy DH chain."""
    for name in ROBOT_NAMES:
        arm = robot(name)
        geometry = Geometry(arm)
        frames, tool = reference.frames(arm, np.zeros(arm.dof))
        for axis, point, frame in zip(geometry.axes, geometry.points, frames):
            np.testing.assert_allclose(np.array(axis, dtype=float).ravel(), frame[:3, 2], atol=1e-15)
            np.testing.assert_allclose(np.array(point, dtype=float).ravel(), frame[:3, 3], atol=1e-15)
        np.testing.assert_allclose(np.array(geometry.tool, dtype=float), tool, atol=1e-15)


@pytest.mark.parametrize("name", ROBOT_NAMES)
def test_shipped_robots_are_classified(name):
    start = time.perf_counter()
    structure = classify(robot(name))
    assert time.perf_counter() - start < 5.0
    assert structure.solver == EXPECTED[name], structure.reason


def test_reasons_name_what_is_missing():
    seven = open(robot("iiwa").source).read().replace("ik: {free_joint: 3}", "")
    a7 = next(line for line in seven.splitlines() if "name: a7" in line)
    eight = seven.replace(a7, a7 + "\n  - {name: a8, type: revolute, a: 0, alpha: 90, d: 0.1, offset: 0}")
    assert "redundant" in classify(parse_robot(eight.encode())).reason
    skewed = classify(parse_robot(NO_STRUCTURE.encode()))
    assert skewed.solver == "general_6r"
    assert "no spherical wrist" in skewed.reason and "no three parallel" in skewed.reason


def test_a_7_axis_arm_without_a_closed_form_gives_each_reason_once():
    """A prismatic joint 3 keeps the general solver out; the same two reasons rule out every
    free joint, from the base and from the tool: said once, with the joints."""
    joints = ["{type: revolute, a: 0.1, alpha: pi/2, d: 0.3}", "{type: revolute, a: 0.4, alpha: 0.3, d: 0.05}",
              "{type: prismatic, a: 0.05, alpha: -pi/2, theta: 0.2}", "{type: revolute, a: 0.02, alpha: pi/2, d: 0.3}",
              "{type: revolute, a: 0.03, alpha: -pi/2, d: 0.1}", "{type: revolute, a: 0, alpha: pi/2, d: 0.05}",
              "{type: revolute, a: 0, alpha: 0, d: 0.1}"]
    text = "name: p7\nconvention: standard\njoints:\n" + "".join(f"  - {joint}\n" for joint in joints)
    structure = classify(parse_robot(text.encode()))
    assert structure.solver is None
    assert structure.reason == ("joints 7, 6, 5, 4, 2, 1 free: no spherical wrist (axes 4, 5, 6 do not meet in one "
                                "point); no three parallel revolute axes 2, 3, 4 (axes numbered from the base, and "
                                "from the tool)")


@pytest.mark.parametrize("name", ["puma560", "kr5", "stanford"])
def test_the_wrist_centre_lies_on_the_reference_axes(name):
    """The spherical wrist's centre, as the structure holds it (the chain its solver solves,
    numbered from the base), is where axes 4, 5 and 6 of the numpy DH chain meet at q = 0: the
    point nearest all three (least squares), on each of them. The reason names its coordinates."""
    arm = robot(name)
    frames, _ = reference.frames(arm, np.zeros(arm.dof))
    across = [np.eye(3) - np.outer(frame[:3, 2], frame[:3, 2]) for frame in frames[3:6]]  # across each axis
    points = [frame[:3, 3] for frame in frames[3:6]]
    meeting = np.linalg.lstsq(np.vstack(across), np.concatenate([m @ p for m, p in zip(across, points)]), rcond=None)[0]
    assert max(np.linalg.norm(m @ (meeting - p)) for m, p in zip(across, points)) < 1e-12
    structure = classify(arm)
    assert structure.solver.startswith("spherical_wrist") and structure.chain.joints == tuple(range(6))
    np.testing.assert_allclose(np.array(structure.chain.wrist_centre(3), dtype=float).ravel(), meeting, atol=1e-12)
    named = [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?", structure.reason)]
    assert all(any(abs(x - c) <= 1e-5 * max(1.0, abs(c)) for x in named) for c in meeting), structure.reason


def test_classes_do_not_depend_on_the_convention_or_exact_angles():
    assert classify(parse_robot(PUMA_MODIFIED.encode())).solver == "spherical_wrist_parallel"
    assert classify(parse_robot(TWISTED.encode())).solver == "spherical_wrist_intersecting"
    # 89.99 deg is not 90 deg: axes 2 and 3 of the UR5 stop being parallel.
    ur5 = open(robot("ur5").source).read()
    bent = ur5.replace("a: a3, alpha: 0,", "a: a3, alpha: 0.01,")
    assert classify(parse_robot(bent.encode())).solver == "general_6r"  # no special class


def test_a_calibrated_arm_is_not_parallel():
    """Off by 1e-4 rad (far above the 1e-40 tolerance of the contract), axes 2 and 3 of a UR5
    are not parallel, and no special class applies (the general 6R solver does); within 1e-9
    rad of pi/2 the file snaps to it."""
    ur5 = open(robot("ur5").source).read()
    assert "a: a3, alpha: 0," in ur5
    calibrated = ur5.replace("a: a3, alpha: 0,", "a: a3, alpha: 0.0057296,")  # deg: 1e-4 rad
    assert classify(parse_robot(calibrated.encode())).solver == "general_6r"


def test_irrational_twists_are_decided_in_bounded_time():
    """Twists in radians such as 1.2001 (exact 12001/10000 in the file) used to stay as nested
    cos(12001/10000) terms whose evaluation grew with the chain: 143 s for this 6-joint arm and
    minutes for 11 joints. The geometry is numbers now, each relation a fixed cost."""
    joints = "\n".join(f"  - {{type: revolute, a: {0.1 + 0.01 * i}, alpha: \"{1.2001 + 0.1 * i}\", d: 0.05, "
                        f"offset: \"{0.3 * i}\"}}" for i in range(11))
    text = f"name: twisty\nconvention: modified\nangle_unit: rad\njoints:\n{joints}\n"
    start = time.perf_counter()
    structure = classify(parse_robot(text.encode()))
    assert time.perf_counter() - start < 5.0  # 0.02 s here
    assert structure.solver is None and "redundant" in structure.reason


def test_symbolic_parameters_keep_the_class():
    text = open(robot("puma560").source).read().replace("d3: 0.15005", "d3: {value: 0.15005, symbolic: true}")
    assert classify(parse_robot(text.encode())).solver == "spherical_wrist_parallel"


def test_planar_needs_a_matching_task():
    text = open(robot("planar_3r").source).read().replace("task: [x, y, yaw]", "task: [x, y]")
    structure = classify(parse_robot(text.encode()))
    assert structure.solver is None and "task (x, y[, z][, yaw])" in structure.reason


def test_every_solver_is_documented():
    for name, info in SOLVERS.items():
        assert info.max_solutions == {"planar": 2, "general_6r": 16}.get(name, 8)
        assert info.branches
