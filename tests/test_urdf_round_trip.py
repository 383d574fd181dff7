"""URDF import, round trip: imported arms generate, build and pass `jacgen verify` (every
function of every backend against the numpy reference).

One arm per kind of import: each closed-form class (UR5, Jaco2 in modified DH, TALOS's arm),
a prismatic joint with continuous ones (PR2's arm, 8 joints), a 5-axis arm with a chosen
task (so101) and a 3-joint finger. The fk of every URDF in tests/data is checked against
Pinocchio in test_urdf_import; this file checks that what the import writes generates."""

from jacgen.verify import verify

from test_urdf_import import imported

ROUND_TRIP = ["ur5", "talos_arm", "pr2", "so101", "finger_edu"]


def test_imported_arms_pass_verify():
    robots = [imported(name, name=f"urdf_{name}").robot for name in ROUND_TRIP]
    robots.append(imported("kinova_jaco2", "modified", name="urdf_kinova_mdh").robot)
    results = verify(robots, samples=40, seed=0)
    assert {result.robot for result in results} == {robot.name for robot in robots}
    failed = [(r.robot, r.function, r.errors) for r in results if r.failed]
    assert not failed
    for robot in robots:
        checked = {r.function for r in results if r.robot == robot.name and any(e is not None for e in r.errors.values())}
        assert {"fk", "jacobian", "jacobian_tool", "task", "task_jacobian", "velocity_ik", "ik_numeric"} <= checked
