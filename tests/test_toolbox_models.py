"""Every DH model of the Robotics Toolbox (24 arms: Jaco and Mico with their 60-degree
wrists, the 10-joint Ball, Coil and Hyper chains, the P8 on its two prismatic axes, ...),
written as a robot file, generated for every language without a warning, and its generated
fk, world and tool Jacobians compared with the Toolbox's own fkine, jacob0 and jacobe.

Joints the Toolbox flips (theta = -q) are not in the robot file schema: the robot file
uses q' = -q for them, so the Toolbox is called with q = flip * q' and its Jacobian
columns are multiplied by the flips.
"""

import math
import re

import numpy as np
import pytest

rtb = pytest.importorskip("roboticstoolbox")

from click.testing import CliRunner  # noqa: E402

from jacgen.cli import main  # noqa: E402
from conftest import import_module  # noqa: E402

MODELS = ["AL5D", "Ball", "Baxter", "Cobra600", "Coil", "Hyper", "Hyper3d", "IRB140", "Jaco", "KR5", "LWR4",
          "Mico", "Orion5", "P8", "Panda", "Planar2", "Planar3", "Puma560", "Sawyer", "Stanford", "TwoLink",
          "UR10", "UR3", "UR5"]


def _pose_text(pose) -> str:
    """xyz and rpy (R = Rz(yaw) Ry(pitch) Rx(roll), radians) of a spatialmath SE3."""
    xyz = ", ".join(repr(float(v)) for v in pose.t)
    rpy = ", ".join(repr(float(v)) for v in pose.rpy(order="zyx"))
    return f"{{xyz: [{xyz}], rpy: [{rpy}]}}"


def robot_file(model) -> tuple[str, np.ndarray]:
    """The robot file of a Toolbox DHRobot (angles in radians) and its joint flips (+-1)."""
    lines = [f"name: rtb_{re.sub(r'[^a-z0-9]', '', model.name.lower())}",
             f"convention: {'modified' if model.mdh else 'standard'}", "angle_unit: rad", "joints:"]
    for link in model.links:
        common = f"a: {float(link.a)!r}, alpha: {float(link.alpha)!r}, offset: {float(link.offset)!r}"
        if link.isprismatic:
            lines.append(f"  - {{type: prismatic, {common}, theta: {float(link.theta)!r}}}")
        else:
            lines.append(f"  - {{type: revolute, {common}, d: {float(link.d)!r}}}")
    lines += [f"base: {_pose_text(model.base)}", f"tool: {_pose_text(model.tool)}"]
    if model.n < 6:
        lines.append(f"task: [{', '.join(('x', 'y', 'z')[:min(model.n, 3)])}]")
    flips = np.array([-1.0 if link.isflip else 1.0 for link in model.links])
    return "\n".join(lines) + "\n", flips


@pytest.mark.parametrize("name", MODELS)
def test_toolbox_model_generates_and_matches(tmp_path, name):
    model = getattr(rtb.models.DH, name)()
    text, flips = robot_file(model)
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    result = CliRunner().invoke(main, ["generate", str(path), "-o", str(tmp_path)], catch_exceptions=False)
    assert result.exit_code == 0 and "warning" not in result.output, result.output
    robot_name = text.split("\n")[0].split(": ")[1]
    module = import_module(tmp_path / robot_name / f"{robot_name}.py", f"toolbox_{robot_name}")
    rng = np.random.default_rng(3)
    for _ in range(5):
        ours = rng.uniform(-math.pi, math.pi, model.n)
        ours[[link.isprismatic for link in model.links]] = rng.uniform(0, 0.5, sum(link.isprismatic for link in model.links))
        theirs = flips * ours
        np.testing.assert_allclose(module.fk(ours), model.fkine(theirs).A, atol=1e-12, rtol=0)
        np.testing.assert_allclose(module.jacobian(ours), model.jacob0(theirs) * flips, atol=1e-12, rtol=0)
        np.testing.assert_allclose(module.jacobian_tool(ours), model.jacobe(theirs) * flips, atol=1e-12, rtol=0)
