"""`jacgen show --plot` and `--compare-urdf` (contract §4, docs/contract.md "Drawing and
comparing an arm"): the drawing read back from matplotlib's artists (never the pixels) against
jacgen.reference's frames, the planar workspace boundary against the annulus of a 2R arm,
and the URDF comparison against imports that agree (as Pinocchio reads the URDF) and tables
with one twist flipped."""

import re

import numpy as np
import pinocchio as pin
import pytest
from click.testing import CliRunner

from jacgen.checking import reference
from jacgen.cli import main
from jacgen.reports.urdf_comparison import compare_urdf, first_difference
from jacgen.reports.drawing import (BOUNDARY_CELLS, default_configurations, draw_arm, draw_workspace,
                                    drawing_figure)
from jacgen.inputs.robot_file import parse_robot

from conftest import ROBOT_NAMES, ROOT, random_configurations, robot
from support.random_arms import random_arm_text
from support.urdf import DATA, URDFS, as_read, imported

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from mpl_toolkits.mplot3d import proj3d  # noqa: E402

STRESS_SEEDS = 30  # tests/test_random_arms.py's arms, 1 to 12 joints, and two of 16 and 32
ARMS = {name: robot(name) for name in ROBOT_NAMES} | {
    f"random{seed}_{dof or ''}": parse_robot(random_arm_text(seed, dof=dof).encode(), f"random{seed}.yaml")
    for seed, dof in [(seed, None) for seed in range(STRESS_SEEDS)] + [(16, 16), (32, 32)]}


def _artist(axes, gid):
    found = [a for a in axes.get_children() if a.get_gid() == gid]
    assert len(found) == 1, gid
    return found[0]


def _projected(axes, points):
    """Points (k, 3) as the 3D axes project them onto the screen plane."""
    return np.transpose(proj3d.proj_transform(*np.transpose(points), axes.get_proj())[:2])


@pytest.mark.parametrize("name", ARMS)
def test_drawing_is_the_reference_chain(name):
    """At a random configuration: the chain's polyline passes, in order, through the
    reference's joint-axis origins and ends at its tool origin, in 3D and as projected on
    screen; each joint's arrow starts at its axis origin along the reference's axis; the base
    and tool triads start at the reference's origins along its x, y, z."""
    arm = ARMS[name]
    q = random_configurations(arm, 1, seed=31)[0]
    axes_frames, tool = reference.frames(arm, q)
    figure = plt.figure()
    axes = figure.add_subplot(projection="3d")
    draw_arm(axes, arm, q, scale=0.2)
    figure.canvas.draw()
    chain = _artist(axes, "chain")
    vertices = np.transpose(chain.get_data_3d())
    on_screen = chain.get_xydata()
    expected = [frame[:3, 3] for frame in axes_frames] + [tool[:3, 3]]
    size = np.ptp(vertices, axis=0).max()
    k = 0
    for point, shown in zip(expected, _projected(axes, np.array(expected))):
        while k < len(vertices) and np.abs(vertices[k] - point).max() > 1e-12 * max(1.0, size):
            k += 1
        assert k < len(vertices), (name, point)
        assert np.abs(on_screen[k] - shown).max() < 1e-12
    assert np.abs(vertices[-1] - tool[:3, 3]).max() < 1e-12 * max(1.0, size)
    for i, frame in enumerate(axes_frames):
        end, start = _artist(axes, f"axis {i + 1}").get_segments()[0]  # the shaft, from its tip
        origin, along = _projected(axes, np.array([frame[:3, 3], frame[:3, 3] + 1e-3 * size * frame[:3, 2]]))
        assert np.abs(start - origin).max() < 1e-9
        direction = (end - start) / np.linalg.norm(end - start)
        expected_direction = (along - origin) / np.linalg.norm(along - origin)
        assert np.linalg.norm(along - origin) < 1e-9 or np.abs(direction - expected_direction).max() < 1e-6
    for label, pose in (("base", _base_pose(arm, axes_frames[0])), ("tool", tool)):
        for column, letter in enumerate("xyz"):
            line = np.transpose(_artist(axes, f"{label} {letter}").get_data_3d())
            assert np.abs(line[0] - pose[:3, 3]).max() < 1e-12 * max(1.0, size)
            step = line[1] - line[0]
            assert np.abs(step / np.linalg.norm(step) - pose[:3, column]).max() < 1e-12
    plt.close(figure)


def _base_pose(arm, first_axis):
    """The base frame: joint 1's axis frame (standard DH), or that frame with the first row's
    Rx(alpha) Tx(a) taken off (modified)."""
    if arm.convention == "standard":
        return first_axis
    joint = arm.joints[0]
    c, s = np.cos(joint.alpha.approx), np.sin(joint.alpha.approx)
    twist = np.array([[1, 0, 0, joint.a.approx], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])
    return first_axis @ np.linalg.inv(twist)


TWO_LINKS = """
name: two_links
convention: standard
angle_unit: deg
joints:
  - {type: revolute, a: 1.0, alpha: 0, d: 0, offset: 0}
  - {type: revolute, a: 0.6, alpha: 0, d: 0, offset: 0}
task: [x, y]
"""


def test_workspace_boundary_of_a_2r_arm_is_its_annulus():
    """Links 1 and 0.6 without limits reach the annulus 0.4 <= r <= 1.6: every vertex of the
    drawn boundary lies within two grid cells of one of its circles, and both are drawn."""
    arm = parse_robot(TWO_LINKS.encode(), "two_links.yaml")
    figure, axes = plt.subplots()
    draw_workspace(figure, axes, arm)
    vertices = np.vstack([path.vertices for path in _artist(axes, "workspace boundary").get_paths()])
    cell = 1.1 * 3.2 / BOUNDARY_CELLS
    radius = np.linalg.norm(vertices, axis=1)
    assert np.all(np.minimum(abs(radius - 1.6), abs(radius - 0.4)) < 2 * cell)
    assert np.any(abs(radius - 0.4) < 2 * cell) and np.any(abs(radius - 1.6) < 2 * cell)
    plt.close(figure)


def test_workspace_boundary_with_limits():
    """The same arm with q1 in [0, 90] deg and q2 in [0, 60] deg: the region is bounded by
    arcs of the circles the limits leave; every boundary vertex lies within two cells of the
    tool positions with a joint at a limit or q2 = 0 (the only singular q2 in range)."""
    arm = parse_robot(TWO_LINKS.replace("offset: 0}", "offset: 0, limits: [0, 90]}", 1)
                      .replace("a: 0.6, alpha: 0, d: 0, offset: 0}", "a: 0.6, alpha: 0, d: 0, offset: 0, limits: [0, 60]}")
                      .encode(), "limited.yaml")
    figure, axes = plt.subplots()
    draw_workspace(figure, axes, arm)
    vertices = np.vstack([path.vertices for path in _artist(axes, "workspace boundary").get_paths()])
    t = np.linspace(0, 1, 2000)
    edges = [(np.radians(90) * t, 0 * t), (np.radians(90) * t, np.radians(60) + 0 * t),
             (0 * t, np.radians(60) * t), (np.radians(90) + 0 * t, np.radians(60) * t)]
    curve = np.vstack([reference.fk(arm, np.stack([q1, q2], -1))[:, :2, 3] for q1, q2 in edges])
    distance = np.min(np.linalg.norm(vertices[:, None] - curve[None], axis=-1), axis=1)
    assert distance.max() < 2 * 1.1 * (np.ptp(curve, axis=0).max()) / BOUNDARY_CELLS
    plt.close(figure)


def _two_link_velocities(q1, q2, l1=1.0, l2=0.6):
    """The planar 2R arm's tool position and its velocity ellipse by hand: J = [[-l1 s1 - l2 s12,
    -l2 s12], [l1 c1 + l2 c12, l2 c12]]; the semi-axes sigma^2 = (T +- sqrt(T^2 - 4 D^2)) / 2 with
    T = |J|_F^2 = l1^2 + 2 l2^2 + 2 l1 l2 c2 and D = det J = l1 l2 s2; the major axis at the angle
    atan2(2 b, a - c) / 2 of J J^T = [[a, b], [b, c]]."""
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    jacobian = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])
    trace, determinant = l1**2 + 2 * l2**2 + 2 * l1 * l2 * np.cos(q2), l1 * l2 * np.sin(q2)
    root = np.sqrt(trace**2 - 4 * determinant**2)
    semi_axes = np.sqrt([(trace + root) / 2, (trace - root) / 2])
    (a, b), (_, c) = jacobian @ jacobian.T
    major = np.arctan2(2 * b, a - c) / 2
    return np.array([l1 * c1 + l2 * c12, l1 * s1 + l2 * s12]), semi_axes, major


def test_velocity_ellipsoid_of_a_2r_arm():
    """At q = (0.4, 1.1) the 3D panel's ellipsoid sits on the tool; its principal semi-axes are
    the 2R Jacobian's singular values (by hand) times the stated factor, along the axes of
    J J^T, and flat across the plane (a 2-joint arm's tool cannot leave it)."""
    arm = parse_robot(TWO_LINKS.encode(), "two_links.yaml")
    tool, semi_axes, major = _two_link_velocities(0.4, 1.1)
    figure = plt.figure()
    axes = figure.add_subplot(projection="3d")
    draw_arm(axes, arm, np.array([0.4, 1.1]), scale=0.2)
    lines = [np.transpose(_artist(axes, f"velocity axis {k}").get_data_3d()) for k in (1, 2, 3)]
    for (start, end), expected in zip(lines, [*semi_axes, 0.0]):
        assert np.abs((start + end) / 2 - [*tool, 0]).max() < 1e-12
        assert abs(np.linalg.norm(end - start) / 2 - 0.2 * expected) < 1e-12
    start, end = lines[0]
    along = (end - start) / np.linalg.norm(end - start)
    assert abs(along[0] * np.sin(major) - along[1] * np.cos(major)) < 1e-9  # parallel to the major axis
    assert abs(lines[1][1][2] - lines[1][0][2]) < 1e-12  # the minor axis in the plane too
    plt.close(figure)


def test_velocity_ellipses_on_the_map_of_a_2r_arm():
    """Each ellipse on the planar map: semi-axes (width and height / 2) are the singular values
    of the 2R Jacobian at its centre (they depend on the elbow angle only, cos q2 from the
    centre's distance to the base) times the factor the title states; its angle is the major
    axis of J J^T at one of the two elbows that reach the centre. A few, spread over the map."""
    arm = parse_robot(TWO_LINKS.encode(), "two_links.yaml")
    figure, axes = plt.subplots()
    draw_workspace(figure, axes, arm)
    scale = float(re.search(r"magenta, x([0-9.e+-]+)\)", axes.get_title()).group(1))
    ellipses = [patch for patch in axes.patches if (patch.get_gid() or "").startswith("velocity ellipse")]
    assert 5 <= len(ellipses) <= 9
    assert np.ptp([e.center for e in ellipses], axis=0).min() > 1.6  # over the annulus, not in a corner of it
    for ellipse in ellipses:
        x, y = ellipse.center
        q2 = np.arccos(np.clip((x * x + y * y - 1.0 - 0.36) / 1.2, -1, 1))
        angles = []
        for elbow in (q2, -q2):
            q1 = np.arctan2(y, x) - np.arctan2(0.6 * np.sin(elbow), 1 + 0.6 * np.cos(elbow))
            tool, semi_axes, major = _two_link_velocities(q1, elbow)
            assert np.abs(tool - [x, y]).max() < 1e-9
            angles.append(major)
        assert np.abs(np.array([ellipse.width, ellipse.height]) / 2 - scale * semi_axes).max() < 1e-9
        assert min(abs(np.sin(np.radians(ellipse.angle) - angle)) for angle in angles) < 1e-6
    assert 0.2 * 1.6 / 3 <= max(e.width / 2 for e in ellipses) <= 0.5 * 3.2 / 3  # visible, within a grid cell
    plt.close(figure)


def test_ur5_gets_two_different_configurations():
    """The UR5's limits are symmetric, so the middle of its limits is q = 0: the second panel
    turns each joint halfway to its upper limit (at most 45 deg), and the titles say so."""
    configurations = default_configurations(robot("ur5"))
    assert len(configurations) == 2
    zero, moved = configurations.values()
    assert np.array_equal(zero, np.zeros(6)) and np.allclose(moved, np.radians(45))
    figure = drawing_figure(robot("ur5"), configurations)
    titles = [axes.get_title() for axes in figure.axes]
    assert titles == ["ur5 at q = 0, the middle of its limits\nq = (0, 0, 0, 0, 0, 0)",
                      "ur5 with each joint halfway to its upper limit (at most 45 deg)\n"
                      "q = (0.785, 0.785, 0.785, 0.785, 0.785, 0.785)"]
    puma = robot("puma560")
    middle = np.mean(puma.ranges, axis=1)
    assert [list(q) for q in default_configurations(puma).values()] == [[0.0] * 6, list(middle)]


@pytest.mark.parametrize("name", ["ur5", "puma560", "panda"])
def test_axis_numbers_do_not_overlap(name):
    """The joints' numbers, as rendered, overlap no other number: the UR5's wrist axes 4, 5, 6
    are about 0.1 m apart at q = 0, the Puma's 4 and 6 collinear at the middle of its limits."""
    arm = robot(name)
    canvas = FigureCanvasAgg(drawing_figure(arm, default_configurations(arm)))
    canvas.draw()
    for axes in canvas.figure.axes:
        boxes = []
        for i in range(arm.dof):  # each number's size as rendered, centred where its 3D point projects
            number = _artist(axes, f"axis number {i + 1}")
            size = number.get_window_extent(canvas.get_renderer()).size
            centre = axes.transData.transform(_projected(axes, np.array([number.get_position_3d()]))[0])
            boxes.append(np.array([centre - size / 2, centre + size / 2]))
        overlapping = [(i + 1, j + 1) for i in range(arm.dof) for j in range(i)
                       if np.all(boxes[i][0] < boxes[j][1]) and np.all(boxes[j][0] < boxes[i][1])]
        assert not overlapping, (axes.get_title(), overlapping)


@pytest.mark.parametrize("name, panels", [("ur5", 1), ("ur5", 2), ("planar_3r", 3), ("scara", 3)])
def test_the_caption_fits_in_the_figure(name, panels):
    """The caption (wrapped) lies inside the figure, below every panel, and states the factor
    the ellipsoids are drawn at."""
    arm = robot(name)
    configurations = dict(list(default_configurations(arm).items())[:panels - (panels == 3)])
    canvas = FigureCanvasAgg(drawing_figure(arm, configurations))
    canvas.draw()
    figure, renderer = canvas.figure, canvas.get_renderer()
    caption = [text for text in figure.texts if text.get_gid() == "caption"][0]
    box, frame = caption.get_window_extent(renderer), figure.bbox
    assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0 and box.y1 <= frame.y1
    assert all(box.y1 < axes.get_position().y0 * frame.height for axes in figure.axes)
    text = caption.get_text().replace("\n", " ")
    assert re.search(r"velocity ellipsoid for \|q_dot\| = 1 rad/s.*, x[0-9.]+ \(1 m/s drawn as [0-9.]+ m", text)


# -- --compare-urdf ---------------------------------------------------------------------------


def _pinocchio_chain(path, base, tip, arm, q):
    """Pinocchio's reading of the URDF (no jacgen code) at the robot file's configuration q,
    joints matched by name (a continuous joint takes (cos, sin)), in the frame of the link
    `base` (None: the root): per joint a point of its axis and its signed direction, and the
    pose of the link `tip`."""
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    joints = [model.getJointId(joint.name) for joint in arm.joints]
    q_pin = pin.neutral(model)
    for k, value in zip(joints, q):
        start, nq = model.joints[k].idx_q, model.joints[k].nq
        q_pin[start:start + nq] = (np.cos(value), np.sin(value)) if nq == 2 else value
    pin.computeJointJacobians(model, data, q_pin)
    pin.framesForwardKinematics(model, data, q_pin)
    world = data.oMf[model.getFrameId(base)].inverse() if base else pin.SE3.Identity()
    axes = []
    for k in joints:
        motion = pin.getJointJacobian(model, data, k, pin.LOCAL_WORLD_ALIGNED)[:, model.joints[k].idx_v]
        direction = motion[3:] if np.linalg.norm(motion[3:]) > 0.5 else motion[:3]  # revolute, else prismatic
        axes.append(((world * data.oMi[k]).translation, world.rotation @ direction))
    return axes, (world * data.oMf[model.getFrameId(tip)]).homogeneous


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("key", URDFS)
def test_imported_robot_files_agree_with_their_urdf(key, convention, tmp_path):
    """The robot file import-urdf writes describes the URDF's chain (its angles made exact as
    docs/urdf.md says) as Pinocchio reads it (not
    jacgen's URDF reader, which import and compare share): at q = 0 and random configurations
    every axis (direction, and the URDF joint's origin on the robot file's line) and the tool
    pose agree to 1e-9; and compare_urdf finds them agreeing."""
    result = imported(key, convention)
    arm = result.robot
    file, base, tip, _ = URDFS[key]
    urdf = tmp_path / file  # with its angles made exact as import-urdf reads them (docs/urdf.md)
    urdf.write_text(as_read((DATA / file).read_text()))
    tip_link = tip or re.search(r"-> (\w+)\)", arm.description).group(1)
    for q in [np.zeros(arm.dof), *random_configurations(arm, 10, seed=32)]:
        frames, tool = reference.frames(arm, q)
        axes, tip_pose = _pinocchio_chain(urdf, base, tip_link, arm, q)
        for joint, frame, (point, direction) in zip(arm.joints, frames, axes):
            ours, offset = frame[:3, 2], point - frame[:3, 3]
            assert np.abs(direction - ours).max() < 1e-9, (key, joint.name, q)
            assert not joint.revolute or np.abs(offset - offset @ ours * ours).max() < 1e-9, (key, joint.name, q)
        assert np.abs(tool - tip_pose).max() < 1e-9, (key, q)
    comparison = compare_urdf(arm, str(urdf), base, tip)
    assert max(max(axis) for axis in comparison.axes) < 1e-9 and max(comparison.tool) < 1e-9, comparison
    assert first_difference(comparison, 1e-9) is None


def _flip_twist(text: str, row: int) -> str:
    """The robot file text with the sign of joint `row`'s (0-based) alpha flipped."""
    rows = [m for m in re.finditer(r"(?m)^  - .*$", text)]
    line = rows[row].group(0)
    value = re.search(r"alpha: ([^,}]+)", line).group(1).strip().strip('"')
    flipped = re.sub(r"alpha: ([^,}]+)", f'alpha: "-({value})"', line)
    return text[:rows[row].start()] + flipped + text[rows[row].end():]


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("key", ["ur5", "panda", "kinova_jaco2"])
def test_a_flipped_twist_names_its_row(key, convention, tmp_path):
    """One twist sign flipped in the imported table: `show --compare-urdf` exits 1 and names the
    row: in standard DH row k places the axis of joint k + 1, in modified DH that of joint k."""
    result = imported(key, convention)
    rows = [i for i, joint in enumerate(result.robot.joints) if abs(np.sin(joint.alpha.approx)) > 0.1
            and (convention == "modified" or i < result.robot.dof - 1)]
    k = rows[len(rows) // 2]
    path = tmp_path / f"{result.robot.name}.yaml"
    path.write_text(_flip_twist(result.text, k))
    file, base, tip, _ = URDFS[key]
    options = [arg for flag, value in (("--base", base), ("--tip", tip)) if value for arg in (flag, value)]
    run = CliRunner().invoke(main, ["show", str(path), "--compare-urdf", str(DATA / file), *options])
    assert run.exit_code == 1, run.output
    verdict = run.output.strip().splitlines()[-1]
    name = result.robot.joints[k].name
    if convention == "standard":
        assert f"the axis of joint {k + 2} " in verdict and f"check joint {k + 1}'s DH row ({name}:" in verdict
    else:
        assert f"the axis of joint {k + 1} " in verdict and f"check joint {k + 1}'s DH row ({name}:" in verdict


def test_compare_needs_the_same_number_of_joints():
    """A URDF chain with another number of moving joints: one line naming both, exit 2."""
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / "puma560.yaml"), "--compare-urdf",
                                    str(DATA / "panda.urdf"), "--tip", "panda_hand_tcp"])
    assert run.exit_code == 2
    assert run.output.strip().splitlines()[-1] == (
        f"jacgen: error: {DATA / 'panda.urdf'}: the chain panda_link0 -> panda_hand_tcp has 7 moving joints, "
        f"{ROOT / 'robots' / 'puma560.yaml'} has 6; choose the links with --base and --tip")


# -- the command ------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["puma560", "planar_3r", "scara"])
def test_show_plot_writes_a_picture(name, tmp_path):
    """`show --plot` writes a PNG (and with --q one configuration); a wrong --q length is one
    line and exit 2."""
    out = tmp_path / f"{name}.png"
    arm = robot(name)
    q = ",".join(["0.3"] * arm.dof)
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / f"{name}.yaml"), "--plot", str(out), "--q", q])
    assert run.exit_code == 0, run.output
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / f"{name}.yaml"), "--plot", str(out), "--q", "0.3"])
    assert run.exit_code == 2 and run.output.strip() == (
        f"jacgen: error: --q: expected {arm.dof} values (one per joint of {name}), got 1")


def test_plot_without_matplotlib_is_one_line(tmp_path, monkeypatch):
    """Without matplotlib: `show` still describes; `--plot` is refused before the description,
    one line and exit 2."""
    modules = __import__("sys").modules
    for name in [name for name in modules if name.split(".")[0] in ("matplotlib", "mpl_toolkits")] + ["matplotlib"]:
        monkeypatch.setitem(modules, name, None)  # as if never installed, submodules too
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / "ur5.yaml")])
    assert run.exit_code == 0 and "ur5" in run.output
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / "ur5.yaml"), "--plot", str(tmp_path / "a.png")])
    assert run.exit_code == 2
    assert run.output.strip().splitlines() == ["jacgen: error: --plot needs matplotlib: pip install 'jacgen[plot]'"]
    assert not (tmp_path / "a.png").exists()


def test_a_format_matplotlib_cannot_write_is_one_line(tmp_path):
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / "planar_2r.yaml"), "--plot", str(tmp_path / "a.xyz")])
    assert run.exit_code == 2
    [line] = run.output.strip().splitlines()  # refused before the description
    assert line.startswith("jacgen: error: --plot: matplotlib writes no 'xyz' files; use one of ")
    assert not (tmp_path / "a.xyz").exists()


@pytest.mark.parametrize("q", ["0,nan", "0,x", "0,,1", "inf,0"])
def test_q_must_be_finite_numbers(q, tmp_path):
    run = CliRunner().invoke(main, ["show", str(ROOT / "robots" / "planar_2r.yaml"), "--plot", str(tmp_path / "a.png"),
                                    "--q", q])
    assert run.exit_code == 2
    assert run.output.strip().splitlines()[-1] == (
        f"jacgen: error: Invalid value for '--q': expected comma-separated finite numbers, got '{q}'")
    assert not (tmp_path / "a.png").exists()


def test_the_dh_table_writes_exact_angles_in_degrees(tmp_path):
    """The report's DH table: an angle that is a rational number of degrees is written in
    degrees (the robot file's pi/2 and -14.5341 deg alike), one in plain radians as it is."""
    from jacgen.inputs.robot_file import parse_robot
    from jacgen.reports.description import dh_table

    text = """name: angles
convention: standard
task: [x, y, z]
joints:
  - {type: revolute, a: 0, alpha: pi/2, d: 0}
  - {type: revolute, a: 0, alpha: -16149*pi/200000, d: 0}
  - {type: revolute, a: 0, alpha: 0.5, d: 0}
"""
    robot = parse_robot(text.encode(), "angles.yaml")
    assert [row[4] for row in dh_table(robot)] == ["90 deg", "-14.5341 deg", "1/2"]
