"""`jacgen verify` on the shipped robots, as the CLI runs it (200 samples, seed 0): every
function of every backend against jacgen.reference, none above tolerance. puma560 and
stanford are verified by tests/test_verify.py (through the CLI). In the test suite rather
than after it, so that it runs beside the other test files."""

from jacgen.verify import verify

from conftest import ROBOT_NAMES, robot


NAMES = [name for name in ROBOT_NAMES if name not in ("puma560", "stanford")]


def test_shipped_robots_pass_verify():
    results = verify([robot(name) for name in NAMES], samples=200, seed=0)
    assert {result.robot for result in results} == set(NAMES)
    assert [(r.robot, r.function, r.errors) for r in results if r.failed] == []
    assert len(results) >= 15 * len(NAMES)
