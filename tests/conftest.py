"""Shared fixtures: the shipped robots and the generated modules under test. What the test
modules share beyond these is in tests/support/ (`generated`, the fixture of generated and
compiled code, is registered here)."""

import os
from pathlib import Path

import numpy as np
import pytest

from jacgen import load_robot
from support.generated import generated, import_module  # noqa: F401 (the fixture, and the loader tests use)

ROOT = Path(__file__).resolve().parent.parent
ROBOT_FILES = sorted((ROOT / "robots").glob("*.yaml"))
ROBOT_NAMES = [path.stem for path in ROBOT_FILES]
GENERATED = ROOT / "generated"


# The files that take longest, run first: pytest-xdist (`--dist loadfile`) hands files to its
# workers in collection order, and a long file started last would run on alone.
SLOWEST_FILES = ("test_shipped_robots.py", "test_urdf_round_trip.py", "test_general6r_generated.py",
                 "test_array_libraries.py", "test_random_arms.py")


def pytest_collection_modifyitems(items):
    rank = {name: k for k, name in enumerate(SLOWEST_FILES)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the rest keep their order


@pytest.fixture(autouse=True, scope="session")
def _own_generate_cache(tmp_path_factory):
    """`jacgen generate` keeps its cache in $XDG_CACHE_HOME: the tests' own, not the user's."""
    os.environ["XDG_CACHE_HOME"] = str(tmp_path_factory.mktemp("xdg_cache"))


def pytest_addoption(parser):
    parser.addoption("--update", action="store_true", help="tests/test_golden.py: rewrite generated/ instead of comparing")


def robot(name: str):
    return load_robot(ROOT / "robots" / f"{name}.yaml")


def generated_module(name: str, suffix: str = ""):
    return import_module(GENERATED / name / f"{name}{suffix}.py", f"generated_{name}{suffix}")


def random_configurations(robot, count: int, seed: int = 0) -> np.ndarray:
    """Uniform samples inside the joint limits ([-pi, pi] for a joint without limits)."""
    rng = np.random.default_rng(seed)
    bounds = np.array([joint.limits or (-np.pi, np.pi) for joint in robot.joints])
    return rng.uniform(bounds[:, 0], bounds[:, 1], size=(count, robot.dof))


@pytest.fixture(params=ROBOT_NAMES)
def robot_name(request) -> str:
    return request.param
