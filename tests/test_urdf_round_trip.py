"""URDF import, round trip: every imported arm (the 13 URDFs of tests/data, and the Jaco2
in modified DH too) generates, builds and passes `jacgen verify` (every function of every
backend against the numpy reference). The fk of every URDF is checked against Pinocchio in
test_urdf_import; this file checks that what the import writes generates."""

from jacgen.checking.verify import verify

from support.urdf import URDFS, imported

ROUND_TRIP = list(URDFS)


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
