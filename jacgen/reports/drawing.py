"""`jacgen show --plot`: the arm a robot file describes, drawn so that a wrong DH table shows.

Each configuration gets a 3D panel: the chain as the DH table builds it (from each frame's
origin along its z axis by d, then along x by a: the lengths of the table are the segments
drawn), each joint's axis as an arrow with its number (revolute solid, prismatic dashed),
the base and tool frames as x, y, z triads in red, green, blue, equal scaling on the three
axes, and the tool's velocity ellipsoid (velocity_ellipsoid) at a factor the caption states.
An arm that moves in a plane (every axis parallel to world z) gets one more panel: the
manipulability over its workspace, the workspace boundary and a few velocity ellipses.

matplotlib is imported here only, when a drawing is made: generating code never needs it.
No drawing goes into generated/, since PNG bytes change with matplotlib's version and
`generate --check` must stay exact everywhere.
"""

import io
import textwrap

import numpy as np

from jacgen.errors import JacgenError
from jacgen.inputs import numeric_chain
from jacgen.inputs.robot import TASK_COMPONENTS, Robot
from jacgen.reports.description import moves_in_plane

AXIS_STYLE = {True: {"color": "tab:orange", "linestyle": "-"},  # revolute
              False: {"color": "tab:purple", "linestyle": "--"}}  # prismatic
TRIAD_COLOURS = ("tab:red", "tab:green", "tab:blue")  # x, y, z
ELLIPSOID_COLOUR = "m"  # magenta: apart from the triads and from the map's viridis
AXIS_LENGTH, TRIAD_LENGTH = 0.2, 0.12  # arrows and triads, as fractions of the drawing's size
LABEL_GAP = 0.06  # an axis number from its arrow's tip, other numbers, arrows: this fraction of the size
ELLIPSOID_SIZE = 0.3  # a 3D panel's largest drawn semi-axis, at most this fraction of the arm's extent
ELLIPSE_GRID, ELLIPSE_SIZE = 3, 0.5  # the map's velocity ellipses: one per cell of a 3 x 3 grid over the
# workspace, the largest drawn semi-axis at most half a cell
SECOND_TURN = np.pi / 4  # default_configurations: the largest turn of a joint in the second panel
BOUNDARY_SAMPLES, BOUNDARY_CELLS = 60_000, 100  # tool positions sampled, grid cells across the map
CAPTION_POINTS, PANEL_INCHES = 8, 5.5


def default_configurations(robot: Robot) -> dict[str, np.ndarray]:
    """The configurations drawn without --q, keyed by what they are: q = 0 and the middle of
    the limits. Where the middle is q = 0 (every range symmetric, as the UR5's +-360 deg), the
    second is each joint halfway to its upper limit, a revolute joint at most SECOND_TURN: a
    second panel that shows the arm moved rather than q = 0 twice."""
    low, high = np.array(robot.ranges).T
    middle, zero = (low + high) / 2, np.zeros(robot.dof)
    if not np.array_equal(middle, zero):
        return {"at q = 0": zero, "at the middle of its limits": middle}
    revolute = np.array([joint.revolute for joint in robot.joints])
    moved = np.where(revolute, np.minimum(high / 2, SECOND_TURN), high / 2)
    return {"at q = 0, the middle of its limits": zero,
            f"with each joint halfway to its upper limit (at most {np.degrees(SECOND_TURN):g} deg)": moved}


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


def draw(robot: Robot, configurations: dict[str, np.ndarray], file_format: str = "png") -> bytes:
    """The drawing of `robot` (drawing_figure) as the bytes of a file in `file_format` (png,
    svg, pdf, ...: what matplotlib writes)."""
    check_plot_format(file_format)
    stream = io.BytesIO()
    drawing_figure(robot, configurations).savefig(stream, format=file_format)
    return stream.getvalue()


def drawing_figure(robot: Robot, configurations: dict[str, np.ndarray]):
    """A matplotlib Figure: a 3D panel per configuration (keyed by what it is: "at q = 0", ...),
    a planar arm's map, and below them the caption (gid "caption"), wrapped to the figure's width."""
    planar = moves_in_plane(robot)
    panels = len(configurations) + planar
    scale = visible_scale([ELLIPSOID_SIZE * drawing_size(chain_points(robot, q)) for q in configurations.values()],
                          [velocity_ellipsoid(robot, q)[1].max() for q in configurations.values()])
    width = PANEL_INCHES * panels
    caption = textwrap.wrap(caption_text(robot, scale, planar), int(width * 72 / (0.6 * CAPTION_POINTS)))
    line_inches = 1.25 * CAPTION_POINTS / 72
    caption_inches = (len(caption) + 0.5) * line_inches
    figure = _figure(figsize=(width, PANEL_INCHES + caption_inches), dpi=100)
    figure.subplots_adjust(left=0.02, right=0.94, bottom=(caption_inches + 0.4) / figure.get_figheight(),
                           top=0.9, wspace=0.3)
    for k, (label, q) in enumerate(configurations.items()):
        draw_arm(figure.add_subplot(1, panels, k + 1, projection="3d"), robot, q, scale, label)
    if planar:
        draw_workspace(figure, figure.add_subplot(1, panels, panels), robot)
    figure.text(0.01, 0.25 * line_inches / figure.get_figheight(), "\n".join(caption), fontsize=CAPTION_POINTS,
                verticalalignment="bottom", color="0.3", gid="caption")
    return figure


def caption_text(robot: Robot, scale: float, planar: bool) -> str:
    """What the arrows and colours mean, and the factor the velocity ellipsoids are drawn at."""
    unit = robot.length_unit
    rates = "rad/s" if all(j.revolute for j in robot.joints) else f"rad/s, {unit}/s for a prismatic joint"
    text = ("arrows: joint axes, numbered (solid: revolute, dashed: prismatic); red, green, blue: x, y, z of the "
            f"base and tool frames; magenta: the tool's velocity ellipsoid for |q_dot| = 1 {rates}, x{scale:g} "
            f"(1 {unit}/s drawn as {scale:g} {unit}; axes: the left singular vectors of J_v, the world "
            "Jacobian's rows vx, vy, vz; semi-axes: its singular values)")
    return text + ("; on the map, the ellipses of the rows vx, vy, at the factor in its title" if planar else "")


def velocity_ellipsoid(robot: Robot, q: np.ndarray, rows: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """The tool's velocities for joint rates |q_dot| <= 1 at q (one or a batch): the ellipsoid
    whose axes are the left singular vectors of the linear block J_v (the first `rows` rows of
    the world Jacobian: vx, vy, vz; a planar arm's map takes vx, vy) and whose semi-axes are
    its singular values, zero beyond the number of joints. (1 / sigma would be the force
    ellipsoid.) Returns the axes as columns (..., rows, rows) and the semi-axes (..., rows)."""
    directions, semi_axes, _ = np.linalg.svd(numeric_chain.jacobian(robot, q)[..., :rows, :])
    missing = rows - semi_axes.shape[-1]
    return directions, np.pad(semi_axes, [(0, 0)] * (semi_axes.ndim - 1) + [(0, missing)])


def visible_scale(sizes: list[float], semi_axes: list[float]) -> float:
    """The factor velocity ellipsoids are drawn at: 1, 2 or 5 times a power of ten, the largest
    that keeps each largest semi-axis within its size (1 where the tool cannot move)."""
    ratios = [size / semi for size, semi in zip(sizes, semi_axes) if semi > 1e-9 * size]
    if not ratios:
        return 1.0
    limit = min(ratios)
    power = 10.0 ** np.floor(np.log10(limit))
    return max(step * power for step in (1, 2, 5, 10) if step * power <= limit * (1 + 1e-9))


def drawing_size(points: np.ndarray) -> float:
    """The largest extent of points (k, d) along an axis, at least 1e-3: the drawing's scale."""
    return max(float(np.ptp(points, axis=0).max()), 1e-3)


def draw_arm(axes, robot: Robot, q: np.ndarray, scale: float, label: str = "") -> None:
    """One 3D panel: the chain, the joint axes, the base and tool triads at q, and the tool's
    velocity ellipsoid drawn `scale` times its size; `label` says what q is."""
    points = chain_points(robot, q)
    frames, tool = numeric_chain.axis_frames(robot, q)
    size = drawing_size(points)
    axes.plot(*points.T, color="0.25", linewidth=2, marker="o", markersize=3, gid="chain")
    tips = []
    for i, (joint, frame) in enumerate(zip(robot.joints, frames)):
        origin, tip = frame[:3, 3], frame[:3, 3] + AXIS_LENGTH * size * frame[:3, 2]
        axes.quiver(*origin, *(tip - origin), arrow_length_ratio=0.2, linewidth=1.5, gid=f"axis {i + 1}",
                    **AXIS_STYLE[joint.revolute])
        tips.append(tip)
    shafts = [(frame[:3, 3], tip) for frame, tip in zip(frames, tips)] + list(zip(points, points[1:]))
    for i, (joint, at) in enumerate(zip(robot.joints, _label_positions(axes, tips, frames, shafts, size))):
        axes.text(*at, str(i + 1), fontsize=9, fontweight="bold", color=AXIS_STYLE[joint.revolute]["color"],
                  ha="center", va="center", zorder=100, gid=f"axis number {i + 1}",
                  bbox={"boxstyle": "round,pad=0.1", "facecolor": "white", "edgecolor": "none", "alpha": 0.7})
    for name, pose in (("base", numeric_chain.fixed_pose(robot.base)), ("tool", tool)):
        for column, colour in enumerate(TRIAD_COLOURS):
            end = pose[:3, 3] + TRIAD_LENGTH * size * pose[:3, column]
            axes.plot(*np.transpose([pose[:3, 3], end]), color=colour, linewidth=1.5, gid=f"{name} {'xyz'[column]}")
    directions, semi_axes = velocity_ellipsoid(robot, q)
    ends = _draw_ellipsoid(axes, tool[:3, 3], directions, scale * semi_axes)
    shown = np.vstack([points, ends])
    centre, half = (shown.max(0) + shown.min(0)) / 2, 0.55 * drawing_size(shown)
    axes.set(xlim=(centre[0] - half, centre[0] + half), ylim=(centre[1] - half, centre[1] + half),
             zlim=(centre[2] - half, centre[2] + half), xlabel=f"x ({robot.length_unit})",
             ylabel=f"y ({robot.length_unit})", zlabel=f"z ({robot.length_unit})")
    axes.set_box_aspect((1, 1, 1), zoom=1.1)
    axes.tick_params(labelsize=7)
    axes.set_title(f"{' '.join(filter(None, [robot.name, label]))}\n{configuration_text(q)}", fontsize=9)


def _label_positions(axes, tips, frames, shafts, size) -> list[np.ndarray]:
    """Where the joints' numbers go: LABEL_GAP of the drawing's size from each arrow's tip, in
    the screen plane (the view's right and up), in the first direction, starting from the
    arrow's own as seen and turning by 45 deg steps, that keeps the number LABEL_GAP from the
    numbers placed before and from every arrow and chain segment (the farthest, where none
    does): the numbers of close or collinear axes (a wrist) do not print over each other."""
    elev, azim = np.radians([axes.elev, axes.azim])
    screen = np.array([[-np.sin(azim), np.cos(azim), 0.0],
                       [-np.sin(elev) * np.cos(azim), -np.sin(elev) * np.sin(azim), np.cos(elev)]])
    segments = [(screen @ start, screen @ end) for start, end in shafts]
    gap, placed, positions = LABEL_GAP * size, [], []
    for tip, frame in zip(tips, frames):
        seen = screen @ frame[:3, 2]
        start = np.arctan2(seen[1], seen[0]) if np.linalg.norm(seen) > 0.3 else np.pi / 2
        candidates = [screen @ tip + gap * np.array([np.cos(start + turn), np.sin(start + turn)])
                      for turn in np.radians([0, 45, -45, 90, -90, 135, -135, 180])]
        clearances = [min([np.linalg.norm(c - other) for other in placed]
                          + [_distance_to_segment(c, *segment) for segment in segments]) for c in candidates]
        chosen = next((k for k, clear in enumerate(clearances) if clear >= gap), int(np.argmax(clearances)))
        placed.append(candidates[chosen])
        positions.append(tip + (candidates[chosen] - screen @ tip) @ screen)
    return positions


def _distance_to_segment(point: np.ndarray, start: np.ndarray, end: np.ndarray) -> float:
    """The distance from point to the segment start-end."""
    along = end - start
    t = np.clip((point - start) @ along / max(along @ along, 1e-300), 0.0, 1.0)
    return float(np.linalg.norm(point - start - t * along))


def _draw_ellipsoid(axes, centre: np.ndarray, directions: np.ndarray, semi_axes: np.ndarray) -> np.ndarray:
    """A translucent ellipsoid at centre with its principal semi-axes as lines (gids
    "velocity axis 1..3", largest first); returns the axes' six ends."""
    turn, tilt = np.meshgrid(np.linspace(0, 2 * np.pi, 25), np.linspace(0, np.pi, 13))
    sphere = np.stack([np.cos(turn) * np.sin(tilt), np.sin(turn) * np.sin(tilt), np.cos(tilt)], -1)
    surface = centre + (sphere * semi_axes) @ directions.T
    axes.plot_surface(*np.moveaxis(surface, -1, 0), color=ELLIPSOID_COLOUR, alpha=0.2, linewidth=0,
                      gid="velocity ellipsoid")
    ends = []
    for k, half_axis in enumerate(np.transpose(directions * semi_axes)):
        ends += [centre - half_axis, centre + half_axis]
        axes.plot(*np.transpose(ends[-2:]), color=ELLIPSOID_COLOUR, linewidth=1, gid=f"velocity axis {k + 1}")
    return np.array(ends)


def configuration_text(q: np.ndarray, per_line: int = 8) -> str:
    """q = (0, 0.3, ...) to 3 decimals, `per_line` values to a line."""
    values = [f"{value:.3g}" if value != 0 else "0" for value in q]
    lines = [", ".join(values[k:k + per_line]) for k in range(0, len(values), per_line)]
    return "q = (" + ",\n".join(lines) + ")"


def draw_workspace(figure, axes, robot: Robot, samples: int = 2500) -> None:
    """A planar arm's tool positions coloured by manipulability, its workspace boundary, and the
    velocity ellipses of the x, y rows (velocity_ellipsoid) at a few configurations spread over
    the workspace, drawn at the factor the title states (visible_scale)."""
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
    shown = spread_over(points)
    directions, semi_axes = velocity_ellipsoid(robot, configurations[shown], rows=2)
    scale = visible_scale([ELLIPSE_SIZE * drawing_size(points) / ELLIPSE_GRID], [semi_axes.max()])
    majors = directions[:, :, 0]
    for k, (centre, major, (a, b)) in enumerate(zip(points[shown], majors, semi_axes)):
        axes.add_patch(Ellipse(centre, 2 * scale * a, 2 * scale * b, angle=np.degrees(np.arctan2(major[1], major[0])),
                               fill=False,
                               color=ELLIPSOID_COLOUR, linewidth=1.5, gid=f"velocity ellipse {k + 1}"))
        axes.plot(*centre, "o", color=ELLIPSOID_COLOUR, markersize=2)
    axes.set_aspect("equal")
    axes.set(xlabel=f"x ({robot.length_unit})", ylabel=f"y ({robot.length_unit})")
    axes.set_title("manipulability over the workspace, its boundary (black)\n"
                   f"and velocity ellipses (magenta, x{scale:g})", fontsize=9)


def spread_over(points: np.ndarray) -> list[int]:
    """A few of the tool positions points (k, 2), spread over their extent: per cell of an
    ELLIPSE_GRID x ELLIPSE_GRID grid over it, the index of the point nearest the cell's centre
    (an empty cell: none)."""
    low, extent = points.min(0), np.maximum(np.ptp(points, axis=0), 1e-12)
    cells = np.minimum((ELLIPSE_GRID * (points - low) / extent).astype(int), ELLIPSE_GRID - 1)
    offsets = np.linalg.norm(points - (low + (cells + 0.5) * extent / ELLIPSE_GRID), axis=1)
    index = cells[:, 0] * ELLIPSE_GRID + cells[:, 1]
    return [int(np.flatnonzero(index == cell)[np.argmin(offsets[index == cell])]) for cell in np.unique(index)]


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
