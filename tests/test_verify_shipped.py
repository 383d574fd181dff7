"""`jacgen verify` on every shipped robot, as the CLI runs it (200 samples, seed 0): every
function of every backend against jacgen.reference, none above tolerance. In the test suite
rather than after it, so that it runs beside the other test files."""

from jacgen.verify import verify

from conftest import ROBOT_NAMES, robot


def test_every_shipped_robot_passes_verify():
    results = verify([robot(name) for name in ROBOT_NAMES], samples=200, seed=0)
    assert {result.robot for result in results} == set(ROBOT_NAMES)
    assert [(r.robot, r.function, r.errors) for r in results if r.failed] == []
    assert len(results) >= 15 * len(ROBOT_NAMES)
