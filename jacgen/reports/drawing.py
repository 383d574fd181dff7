"""`jacgen show --plot`: the arm a robot file describes, drawn so that a wrong DH table shows.

Each configuration gets a 3D panel: the chain as the DH table builds it (from each frame's
origin along its z axis by d, then along x by a: the lengths of the table are the segments
drawn), each joint's axis as an arrow with its number (revolute solid, prismatic dashed),
the base and tool frames as x, y, z triads in red, green, blue, equal scaling on the three
axes. An arm that moves in a plane (every axis parallel to world z) gets one more panel:
the manipulability over its workspace and the workspace boundary.

matplotlib is imported here only, when a drawing is made: generating code never needs it.
No drawing goes into generated/, since PNG bytes change with matplotlib's version and
`generate --check` must stay exact everywhere.
"""

import io

import numpy as np

from jacgen.errors import JacgenError
from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.reports.description import moves_in_plane

AXIS_STYLE = {True: {"color": "tab:orange", "linestyle": "-"},  # revolute
              False: {"color": "tab:purple", "linestyle": "--"}}  # prismatic
TRIAD_COLOURS = ("tab:red", "tab:green", "tab:blue")  # x, y, z
AXIS_LENGTH, TRIAD_LENGTH = 0.12, 0.15  # arrows and triads, as fractions of the drawing's size
BOUNDARY_SAMPLES, BOUNDARY_CELLS = 60_000, 100  # tool positions sampled, grid cells across the map


def default_configurations(robot: Robot) -> list[np.ndarray]:
    """The zero configuration and the middle of the limits (once, where they are the same)."""
    middle = np.array([(low + high) / 2 for low, high in robot.ranges])
    zero = np.zeros(robot.dof)
    return [zero] if np.array_equal(middle, zero) else [zero, middle]


def chain_points(robot: Robot, q: np.ndarray) -> np.ndarray:
    """The polyline of the chain at q (m, 3): the base origin, then per DH row the point
    its first translation reaches (standard: d along z; modified: a along x) and the
    origin of the row's frame, then the tool origin."""
    frames, tool = numeric_chain.link_frames(robot, q)
    points = [frames[0][:3, 3]]
    for i, (joint, frame, after) in enumerate(zip(robot.joints, frames, frames[1:])):
        if robot.convention == "standard":
            d = joint.d.approx if joint.revolute else q[i] + joint.offset.approx
            points.append(frame[:3, 3] + d * frame[:3, 2])
        else:
            points.append(frame[:3, 3] + joint.a.approx * frame[:3, 0])
        points.append(after[:3, 3])
    points.append(tool[:3, 3])
    return np.array(points)


def check_plot_format(file_format: str) -> None:
    """One error line (JacgenError) without matplotlib, or for a format it does not write."""
    formats = _figure().canvas.get_supported_filetypes()
    if file_format not in formats:
        raise JacgenError(f"--plot: matplotlib writes no '{file_format}' files; use one of {', '.join(sorted(formats))}")


def draw(robot: Robot, configurations: list[np.ndarray], file_format: str = "png") -> bytes:
    """The drawing of `robot` at each configuration (and its planar map) as the bytes of a
    file in `file_format` (png, svg, pdf, ...: what matplotlib writes)."""
    check_plot_format(file_format)
    planar = moves_in_plane(robot)
    panels = len(configurations) + planar
    figure = _figure(figsize=(5.5 * panels, 5.5), dpi=100)
    figure.subplots_adjust(left=0.02, right=0.94, bottom=0.1, top=0.9, wspace=0.3)
    for k, q in enumerate(configurations):
        draw_arm(figure.add_subplot(1, panels, k + 1, projection="3d"), robot, q)
    if planar:
        draw_workspace(figure, figure.add_subplot(1, panels, panels), robot)
    figure.text(0.01, 0.01, "arrows: joint axes (solid: revolute, dashed: prismatic), numbered; "
                "red, green, blue: x, y, z of the base and tool frames", fontsize=7, color="0.3")
    stream = io.BytesIO()
    figure.savefig(stream, format=file_format)
    return stream.getvalue()


def draw_arm(axes, robot: Robot, q: np.ndarray) -> None:
    """One 3D panel: the chain, the joint axes, the base and tool triads at q."""
    points = chain_points(robot, q)
    frames, tool = numeric_chain.axis_frames(robot, q)
    size = max(float(np.ptp(points, axis=0).max()), 1e-3)
    axes.plot(*points.T, color="0.25", linewidth=2, marker="o", markersize=3, gid="chain")
    for i, (joint, frame) in enumerate(zip(robot.joints, frames)):
        origin, tip = frame[:3, 3], frame[:3, 3] + AXIS_LENGTH * size * frame[:3, 2]
        axes.quiver(*origin, *(tip - origin), arrow_length_ratio=0.3, linewidth=1.5, gid=f"axis {i + 1}",
                    **AXIS_STYLE[joint.revolute])
        axes.text(*(tip + 0.02 * size * frame[:3, 2]), str(i + 1), fontsize=8, color=AXIS_STYLE[joint.revolute]["color"])
    for name, pose in (("base", numeric_chain.fixed_pose(robot.base)), ("tool", tool)):
        for column, colour in enumerate(TRIAD_COLOURS):
            end = pose[:3, 3] + TRIAD_LENGTH * size * pose[:3, column]
            axes.plot(*np.transpose([pose[:3, 3], end]), color=colour, linewidth=1.5, gid=f"{name} {'xyz'[column]}")
    centre, half = (points.max(0) + points.min(0)) / 2, 0.6 * size
    axes.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
             zlim=(centre[2] - half, centre[2] + half), xlabel=f"x ({robot.length_unit})",
             ylabel=f"y ({robot.length_unit})", zlabel=f"z ({robot.length_unit})")
    axes.set_box_aspect((1, 1, 1), zoom=1.1)
    axes.tick_params(labelsize=7)
    axes.set_title(f"{robot.name}\n{configuration_text(q)}", fontsize=9)


def configuration_text(q: np.ndarray, per_line: int = 8) -> str:
    """q = (0, 0.3, ...) to 3 decimals, `per_line` values to a line."""
    values = [f"{value:.3g}" if value != 0 else "0" for value in q]
    lines = [", ".join(values[k:k + per_line]) for k in range(0, len(values), per_line)]
    return "q = (" + ",\n".join(lines) + ")"


def draw_workspace(figure, axes, robot: Robot, samples: int = 2500, ellipses: int = 6) -> None:
    """A planar arm's tool positions coloured by manipulability, its workspace boundary, and
    at a few configurations the arm and its velocity ellipse (J_xy J_xy^T)."""
    from matplotlib.patches import Ellipse

    rows = [TASK_COMPONENTS.index(c) for c in robot.task]  # planar: yaw rate = wz, roll = pitch = 0
    low, high = np.array(robot.ranges).T
    configurations = np.random.default_rng(0).uniform(low, high, size=(samples, robot.dof))
    points = numeric_chain.axis_frames(robot, configurations)[1][:, :2, 3]
    js = numeric_chain.jacobian(robot, configurations)[:, rows]
    gram = js @ np.swapaxes(js, 1, 2) if len(rows) <= robot.dof else np.swapaxes(js, 1, 2) @ js
    measure = np.sqrt(np.maximum(np.linalg.det(gram), 0.0))
    cloud = axes.scatter(points[:, 0], points[:, 1], c=measure, s=4, cmap="viridis")
    figure.colorbar(cloud, ax=axes, label="manipulability sqrt(det(Js Js^T))", shrink=0.8)
    x, y, inside = workspace(robot)
    axes.contour(x, y, inside.T, levels=[0.5], colors="k", linewidths=1).set_gid("workspace boundary")
    reach = float(np.max(np.linalg.norm(points, axis=1))) or 1.0
    shown = configurations[:ellipses]
    jacobians = numeric_chain.jacobian(robot, shown)[:, :2]
    largest = max(np.linalg.svd(jacobians, compute_uv=False)[:, 0].max(), 1e-12)
    for q, j in zip(shown, jacobians):
        chain = chain_points(robot, q)[:, :2]
        axes.plot(chain[:, 0], chain[:, 1], "-o", color="0.3", lw=1, ms=2)
        u, s, _ = np.linalg.svd(j)
        scale = 0.25 * reach / largest
        axes.add_patch(Ellipse(chain[-1], 2 * scale * s[0], 2 * scale * (s[1] if len(s) > 1 else 0),
                               angle=np.degrees(np.arctan2(u[1, 0], u[0, 0])), fill=False, color="tab:red"))
    axes.set_aspect("equal")
    axes.set(xlabel=f"x ({robot.length_unit})", ylabel=f"y ({robot.length_unit})")
    axes.set_title("manipulability over the workspace, its boundary (black)\nand velocity ellipses (red)",
                   fontsize=9)


def workspace(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The set of tool positions (x, y) a planar arm reaches within its ranges, on a grid:
    cell centres x, y and whether each cell is reached (BOUNDARY_CELLS across). Sampled at
    BOUNDARY_SAMPLES configurations (a grid in joint space, limits included, for up to three
    joints; uniform random beyond), then closed (dilated, eroded) by two cells so that
    sampling gaps inside do not show as holes: the boundary is good to about two cells."""
    low, high = np.array(robot.ranges).T
    if robot.dof <= 3:
        per_joint = int(round(BOUNDARY_SAMPLES ** (1 / robot.dof)))
        grids = np.meshgrid(*(np.linspace(a, b, per_joint) for a, b in zip(low, high)), indexing="ij")
        configurations = np.stack([g.ravel() for g in grids], -1)
    else:
        configurations = np.random.default_rng(1).uniform(low, high, size=(BOUNDARY_SAMPLES, robot.dof))
    points = numeric_chain.axis_frames(robot, configurations)[1][:, :2, 3]
    centre = (points.max(0) + points.min(0)) / 2
    half = 0.55 * max(float(np.ptp(points, axis=0).max()), 1e-9)
    edges = [np.linspace(c - half, c + half, BOUNDARY_CELLS + 1) for c in centre]
    counts, _, _ = np.histogram2d(points[:, 0], points[:, 1], bins=edges)
    inside = _erode(_erode(_dilate(_dilate(counts > 0))))
    return tuple((e[:-1] + e[1:]) / 2 for e in edges) + (inside.astype(float),)


def _dilate(cells: np.ndarray) -> np.ndarray:
    """Each cell or any of its 8 neighbours set."""
    padded = np.pad(cells, 1)
    n, m = cells.shape
    return np.any([padded[i:i + n, j:j + m] for i in range(3) for j in range(3)], axis=0)


def _erode(cells: np.ndarray) -> np.ndarray:
    """Each cell with all 8 neighbours set."""
    return ~_dilate(~cells)


def _figure(**options):
    """A matplotlib Figure drawn by Agg (files only, no window, no pyplot state); one error
    line without matplotlib."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise JacgenError("--plot needs matplotlib: pip install 'jacgen[plot]'") from None
    return Figure(**options)
