"""URDF import, round trip: every imported arm generates, builds and passes `jacgen verify`
(every function of every backend against the numpy reference)."""

from jacgen.verify import verify

from test_urdf_import import URDFS, imported


def test_every_imported_arm_passes_verify():
    robots = [imported(name, name=f"urdf_{name}").robot for name in URDFS]
    robots.append(imported("kinova_jaco2", "modified", name="urdf_kinova_mdh").robot)
    results = verify(robots, samples=40, seed=0)
    assert {result.robot for result in results} == {robot.name for robot in robots}
    failed = [(r.robot, r.function, r.errors) for r in results if r.failed]
    assert not failed
    for robot in robots:
        checked = {r.function for r in results if r.robot == robot.name and any(e is not None for e in r.errors.values())}
        assert {"fk", "jacobian", "jacobian_tool", "task", "task_jacobian", "velocity_ik", "ik_numeric"} <= checked
