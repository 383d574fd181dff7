"""Structure detection: the zero-configuration geometry against the numpy reference, the class
of every shipped robot, and robots built to fall in (or just outside) each class."""

import time

import numpy as np
import pytest

from jacgen import reference
from jacgen.robot import parse_robot
from jacgen.structure import SOLVERS, Geometry, classify, describe_structure

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
    assert skewed.solver is None
    assert "no spherical wrist" in skewed.reason and "no three parallel" in skewed.reason
    lines = describe_structure(parse_robot(NO_STRUCTURE.encode()))
    assert lines[-1].startswith("closed-form ik: none (") and lines[-1].endswith("ik_numeric is generated")


def test_features_list_the_relations_found():
    puma = describe_structure(robot("puma560"))
    assert "structure: consecutive axes: 1-2 intersect at (0, 0, 0.67183); 2-3 parallel; 3-4 skew; " \
           "4-5 intersect at (0.4521, -0.15005, 1.10363); 5-6 intersect at (0.4521, -0.15005, 1.10363)" in puma
    assert "structure: axes 4, 5, 6 meet at (0.4521, -0.15005, 1.10363) (spherical joint)" in puma
    assert any(line.startswith("solver: 6R with a spherical wrist") for line in puma)
    assert len([line for line in puma if line.startswith("  ")]) == 3  # three branch loops
    scara = describe_structure(robot("scara"))
    assert "structure: prismatic joint 3" in scara and "structure: planar: every axis parallel to world z" in scara


def test_classes_do_not_depend_on_the_convention_or_exact_angles():
    assert classify(parse_robot(PUMA_MODIFIED.encode())).solver == "spherical_wrist_parallel"
    assert classify(parse_robot(TWISTED.encode())).solver == "spherical_wrist_intersecting"
    # 89.99 deg is not 90 deg: axes 2 and 3 of the UR5 stop being parallel.
    ur5 = open(robot("ur5").source).read()
    bent = ur5.replace("a: a3, alpha: 0,", "a: a3, alpha: 0.01,")
    assert classify(parse_robot(bent.encode())).solver is None


def test_symbolic_parameters_keep_the_class():
    text = open(robot("puma560").source).read().replace("d3: 0.15005", "d3: {value: 0.15005, symbolic: true}")
    assert classify(parse_robot(text.encode())).solver == "spherical_wrist_parallel"


def test_planar_needs_a_matching_task():
    text = open(robot("planar_3r").source).read().replace("task: [x, y, yaw]", "task: [x, y]")
    structure = classify(parse_robot(text.encode()))
    assert structure.solver is None and "task (x, y[, z][, yaw])" in structure.reason


def test_every_solver_is_documented():
    for info in SOLVERS.values():
        assert info.max_solutions in (2, 8) and info.branches
