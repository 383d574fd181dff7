"""Independent numeric reference (contract §5): numpy only, sharing no code with the symbolic path.

The DH chain is multiplied out with floats, the geometric Jacobian is built column by
column from the frame origins and axes, and the task Jacobian by central differences.
It reads only the float side (`approx`) of the robot's values, at the nominal values of
symbolic parameters. Every function takes one configuration q (n,) or a batch (..., n): the
batch is the same arithmetic, broadcast (`jacgen verify` evaluates its samples at once).
"""

import numpy as np

TASK_COMPONENTS = ("x", "y", "z", "roll", "pitch", "yaw")


def _matrix(rows):
    """A matrix from its entries, numbers or arrays of one batch shape: (..., rows, columns)."""
    shape = np.broadcast_shapes(*(entry.shape for row in rows for entry in row if getattr(entry, "ndim", 0)))
    if shape:
        matrix = np.stack([np.broadcast_to(entry, shape) for row in rows for entry in row], -1)
        matrix = matrix.reshape(*shape, len(rows), len(rows[0]))
    else:  # one configuration: numbers
        matrix = np.array(rows)
    return matrix if matrix.dtype.kind in "fc" else matrix.astype(float)


def _rot_x(angle):
    c, s = np.cos(angle), np.sin(angle)
    return _matrix([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return _matrix([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def _translation(x, y, z):
    return _matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def _rpy_rotation(roll, pitch, yaw):
    """Rz(yaw) Ry(pitch) Rx(roll), 4x4."""
    cp, sp = np.cos(pitch), np.sin(pitch)
    rot_y = _matrix([[cp, 0, sp, 0], [0, 1, 0, 0], [-sp, 0, cp, 0], [0, 0, 0, 1]])
    return _rot_z(yaw) @ rot_y @ _rot_x(roll)


def _pose(pose):
    """world<-frame transform of a base/tool Pose: Rz(yaw) Ry(pitch) Rx(roll) after xyz."""
    return _translation(*(v.approx for v in pose.xyz)) @ _rpy_rotation(*(v.approx for v in pose.rpy))


def _link(robot, joint, qi):
    theta = (qi + joint.offset.approx) if joint.revolute else joint.theta.approx
    d = joint.d.approx if joint.revolute else (qi + joint.offset.approx)
    a, alpha = joint.a.approx, joint.alpha.approx
    if robot.convention == "standard":
        return _rot_z(theta) @ _translation(0, 0, d) @ _translation(a, 0, 0) @ _rot_x(alpha)
    return _rot_x(alpha) @ _translation(a, 0, 0) @ _rot_z(theta) @ _translation(0, 0, d)


def frames(robot, q):
    """World poses of the joint frames whose z axes are the joint axes, and of the tool.

    Standard DH: joint i moves about z_{i-1}, so the axes are frames 0..n-1.
    Modified DH: joint i moves about z_i, the frame after the row's Rx Tx.
    Complex q is carried through (for complex-step derivatives).
    """
    axes, links = _chain(robot, q)
    return axes, links[-1] @ _pose(robot.tool)


def _chain(robot, q):
    """The joint axis frames (see `frames`) and the link frames base A_1 ... A_i, world poses."""
    q = np.asarray(q)
    q = q if np.iscomplexobj(q) else q.astype(float)
    current = _pose(robot.base)
    axes, links = [], []
    for i, joint in enumerate(robot.joints):
        if robot.convention == "standard":
            axes.append(current)
        else:
            axes.append(current @ _rot_x(joint.alpha.approx) @ _translation(joint.a.approx, 0, 0))
        current = current @ _link(robot, joint, q[..., i])
        links.append(current)
    return axes, links


def fk(robot, q):
    """4x4 pose of the tool in the world frame."""
    return frames(robot, q)[1]


def jacobian(robot, q):
    """Geometric Jacobian in the world frame, rows vx vy vz wx wy wz (column formula)."""
    axes, tool = frames(robot, q)
    p = tool[..., :3, 3]
    columns = []
    for joint, axis_frame in zip(robot.joints, axes):
        axis_frame = np.broadcast_to(axis_frame, tool.shape)  # the base frame is not batched
        z, o = axis_frame[..., :3, 2], axis_frame[..., :3, 3]
        columns.append(np.concatenate([np.cross(z, p - o) if joint.revolute else z,
                                       z if joint.revolute else np.zeros_like(z)], -1))
    return np.stack(columns, -1)


def jacobian_tool(robot, q):
    """The same twist expressed in the tool frame."""
    transposed = np.swapaxes(fk(robot, q)[..., :3, :3], -1, -2)
    J = jacobian(robot, q)
    return np.concatenate([transposed @ J[..., :3, :], transposed @ J[..., 3:, :]], -2)


COMPLEX_STEP = 1e-30


def jacobian_dot(robot, q, q_dot):
    """dJ/dt along q_dot: the complex-step derivative of `jacobian` (J(q + i h q_dot).imag / h),
    which has no cancellation, so it is exact to rounding."""
    q, q_dot = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
    return jacobian(robot, q + 1j * COMPLEX_STEP * q_dot).imag / COMPLEX_STEP


def hessian(robot, q):
    """d J / d q_k for each k, shape (n, 6, n): `jacobian_dot` along each joint."""
    q = np.asarray(q, dtype=float)
    return np.stack([jacobian_dot(robot, q, unit) for unit in np.eye(q.shape[-1])], -3)


def bias_acceleration(robot, q, q_dot):
    """J' q_dot: the tool's classical acceleration at zero joint acceleration."""
    q_dot = np.asarray(q_dot, dtype=float)
    return (jacobian_dot(robot, q, q_dot) @ q_dot[..., None])[..., 0]


def rpy(rotation):
    """roll, pitch, yaw with R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r = lambda i, j: rotation[..., i, j]  # noqa: E731
    pitch = np.arctan2(-r(2, 0), np.hypot(r(0, 0), r(1, 0)))
    return np.stack([np.arctan2(r(2, 1), r(2, 2)), pitch, np.arctan2(r(1, 0), r(0, 0))], -1)


def task(robot, q):
    """The task vector mu(q): declared components of (x, y, z, roll, pitch, yaw)."""
    pose = fk(robot, q)
    full = np.concatenate([pose[..., :3, 3], rpy(pose[..., :3, :3])], -1)
    return full[..., [TASK_COMPONENTS.index(name) for name in robot.task]]


def ik_target(robot, q):
    """What `ik` takes at q: the 4x4 pose for a six-component task, the task vector otherwise."""
    return fk(robot, q) if len(robot.task) == 6 else task(robot, q)


def task_jacobian(robot, q, step=1e-4):
    """d mu / d q by fourth-order central differences (angles unwrapped across the ±pi seam)."""
    q = np.asarray(q, dtype=float)
    angular = [k for k, name in enumerate(robot.task) if name in ("roll", "pitch", "yaw")]
    centre = task(robot, q)

    def offset(i, h):
        difference = task(robot, q + h * np.eye(q.shape[-1])[i]) - centre
        difference[..., angular] = (difference[..., angular] + np.pi) % (2 * np.pi) - np.pi
        return difference

    return np.stack([(8 * (offset(i, step) - offset(i, -step)) - (offset(i, 2 * step) - offset(i, -2 * step)))
                     / (12 * step) for i in range(q.shape[-1])], -1)


def _euler_rates_jacobian(robot, q):
    """d mu / d q from the geometric Jacobian: the angle rows solve E(rpy) rpy_dot = omega,
    E's columns being the world axes of the roll, pitch and yaw rotations, with cos and sin
    of pitch and yaw read off R (no arctan2, so complex q is carried through)."""
    pose, J = fk(robot, q), jacobian(robot, q)
    r = pose[..., :3, :3]
    cos_pitch = np.sqrt(r[..., 0, 0] ** 2 + r[..., 1, 0] ** 2)
    cos_yaw, sin_yaw, sin_pitch = r[..., 0, 0] / cos_pitch, r[..., 1, 0] / cos_pitch, -r[..., 2, 0]
    axes = _matrix([[cos_yaw * cos_pitch, -sin_yaw, 0], [sin_yaw * cos_pitch, cos_yaw, 0], [-sin_pitch, 0, 1]])
    rows = np.concatenate([J[..., :3, :], np.linalg.solve(axes, J[..., 3:, :])], -2)
    return rows[..., [TASK_COMPONENTS.index(name) for name in robot.task], :]


def task_jacobian_dot(robot, q, q_dot):
    """d/dt of d mu / d q along q_dot: the complex-step derivative of the Euler-rate form of
    the task Jacobian (exact to rounding, away from cos(pitch) = 0)."""
    q, q_dot = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
    return _euler_rates_jacobian(robot, q + 1j * COMPLEX_STEP * q_dot).imag / COMPLEX_STEP


def singularity_jacobian(robot, q):
    """Js (contract §2): the geometric rows of the task when it holds all or none of roll, pitch,
    yaw (angular velocity for the angles), else the task Jacobian."""
    angles = sum(name in ("roll", "pitch", "yaw") for name in robot.task)
    if angles in (0, 3):
        return jacobian(robot, q)[..., [TASK_COMPONENTS.index(name) for name in robot.task], :]
    return task_jacobian(robot, q)


def manipulability(robot, q):
    """sqrt(det(Js Js^T)) (sqrt(det(Js^T Js)) when Js is tall): the product of the singular
    values of Js, which stays accurate near 0 where the square root of a rounded det does not."""
    return np.prod(np.linalg.svd(singularity_jacobian(robot, q), compute_uv=False), -1)


def jacobian_det(robot, q):
    """det(Js) of a square Js."""
    return np.linalg.det(singularity_jacobian(robot, q))


# -- link frames and dexterity (issue 48) ------------------------------------------------------
def link_poses(robot, q):
    """World poses of the link frames base A_1 ... A_i, (..., n, 4, 4): the tool transform is not
    applied, so link_poses(q)[-1] @ tool = fk(q)."""
    return np.stack(np.broadcast_arrays(*_chain(robot, q)[1]), -3)


def link_velocities(robot, q, q_dot):
    """[v; w] of each link frame, (..., n, 6), world frame: v the rate of its origin, w the axial
    vector of dR/dt R^T. dR/dt and dp/dt are complex-step derivatives of `link_poses` along q_dot,
    so this shares nothing with a propagation of velocities from link to link."""
    q, q_dot = np.asarray(q, dtype=float), np.asarray(q_dot, dtype=float)
    poses = link_poses(robot, q + 1j * COMPLEX_STEP * q_dot)
    rates = poses.imag / COMPLEX_STEP
    spin = rates[..., :3, :3] @ np.swapaxes(poses.real[..., :3, :3], -1, -2)
    return np.concatenate([rates[..., :3, 3], _axial(spin)], -1)


def _axial(matrix):
    """The axial vector of the skew-symmetric part of 3x3 matrices."""
    skew = (matrix - np.swapaxes(matrix, -1, -2)) / 2
    return np.stack([skew[..., 2, 1], skew[..., 0, 2], skew[..., 1, 0]], -1)


def velocity_ellipsoid(robot, q):
    """(U_v, s_v, U_w, s_w): left singular vectors (columns of a rotation) and singular values,
    descending, of the linear rows J[:3] and the angular rows J[3:] of `jacobian`; for n < 3 the
    trailing values are 0. By SVD, not by the eigenvalues of J J^T, whose square roots lose half
    the digits of a small singular value (tests/test_reference_dexterity.py)."""
    J = jacobian(robot, q)
    return (*_left_singular(J[..., :3, :]), *_left_singular(J[..., 3:, :]))


def _left_singular(block):
    """U (a rotation: its last column's sign chosen so) and the 3 singular values of a 3 x n block."""
    U, values, _ = np.linalg.svd(block)
    values = np.concatenate([values, np.zeros((*values.shape[:-1], 3 - values.shape[-1]))], -1)
    U[..., :, 2] *= np.sign(np.linalg.det(U))[..., None]
    return U, values


def condition_number(robot, q, length, eps=0.0):
    """sigma_max / sigma_min of Js with its position rows divided by `length` (the characteristic
    length, so the value has no unit); +inf where Js is singular to `eps` (contract §2): where
    sigma_min <= eps sigma_max, or where sigma_max <= eps (1 + (1 + reach) / length), a bound on
    the scaled Js's entries (rotation rows 1, revolute columns' positions reach / length,
    prismatic columns' 1 / length). With eps 0, where sigma_min is 0."""
    rows = np.array([1 / length if name in ("x", "y", "z") else 1.0 for name in robot.task])
    values = np.linalg.svd(singularity_jacobian(robot, q) * rows[:, None], compute_uv=False)
    largest, smallest = values[..., 0], values[..., -1]
    singular = (smallest <= eps * largest) | (largest <= eps * (1 + (1 + robot.reach) / length))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(singular, np.inf, largest / smallest)


def _js_and_derivatives(robot, q):
    """Js at q and its partial derivatives d Js / d q_k, (..., n, m, n), each exact to rounding:
    the geometric rows and `hessian`, or the Euler-rate form of the task Jacobian and
    `task_jacobian_dot` along each joint."""
    q = np.asarray(q, dtype=float)
    if sum(name in ("roll", "pitch", "yaw") for name in robot.task) in (0, 3):
        rows = [TASK_COMPONENTS.index(name) for name in robot.task]
        return jacobian(robot, q)[..., rows, :], hessian(robot, q)[..., rows, :]
    units = np.eye(q.shape[-1])
    return _euler_rates_jacobian(robot, q), np.stack([task_jacobian_dot(robot, q, unit) for unit in units], -3)


def manipulability_gradient(robot, q):
    """d manipulability / d q_k, (..., n). With Js = sum_i s_i u_i v_i^T (thin SVD) the
    manipulability is prod_i s_i and d s_i = u_i^T dJs v_i, so the derivative is
    sum_i (prod_{j != i} s_j) u_i^T (d Js / d q_k) v_i, for a wide, square or tall Js alike.
    Where the manipulability is exactly 0 (|s| has a kink there) it is 0, as in the generated code."""
    js, derivatives = _js_and_derivatives(robot, q)
    u, values, vt = np.linalg.svd(js, full_matrices=False)
    others = np.stack([np.prod(np.delete(values, i, -1), -1) for i in range(values.shape[-1])], -1)
    rates = np.einsum("...ai,...kab,...ib->...ki", u, derivatives, vt)
    gradient = np.einsum("...ki,...i->...k", rates, others)
    return np.where(np.prod(values, -1)[..., None] == 0, 0.0, gradient)


def rotation_vector(rotation):
    """The rotation vector (axis times angle in [0, pi]) of rotation matrices, the log map.

    With v the axial vector of (R - R^T) / 2 (the axis times sin(angle)) and cos(angle) =
    (trace - 1) / 2: below a quarter turn it is v angle / sin(angle) (angle / sin within [1,
    pi / 2]); beyond, the axis is the eigenvector of (R + R^T) / 2 of eigenvalue 1 (the other two
    are cos(angle) <= 0, a gap of at least 1), signed along v."""
    v = _axial(rotation)
    sin = np.linalg.norm(v, axis=-1)
    cos = (np.trace(rotation, axis1=-2, axis2=-1) - 1) / 2
    angle = np.arctan2(sin, cos)
    axis = np.linalg.eigh((rotation + np.swapaxes(rotation, -1, -2)) / 2)[1][..., :, -1]
    axis = axis * np.where(np.sum(axis * v, -1) < 0, -1.0, 1.0)[..., None]
    ratio = np.where(sin > 0, angle / np.where(sin > 0, sin, 1.0), 1.0)
    return np.where((cos > 0)[..., None], v * ratio[..., None], axis * angle[..., None])


def task_error(robot, q, target):
    """The error resolved_rate feeds back, in the rows of Js: for a six-component task (a 4x4
    target) ik_numeric's, the position error and the rotation vector of R_target R(q)^T, world
    frame; for another task with all of roll, pitch and yaw (whose Js has angular-velocity rows)
    the same from the target's angles, R_target = Rz(yaw) Ry(pitch) Rx(roll); else target - mu(q)
    with the Euler angles wrapped into (-pi, pi]."""
    target = np.asarray(target, dtype=float)
    pose = fk(robot, q)
    if len(robot.task) == 6:
        position, goal = target[..., :3, 3], target[..., :3, :3]
    elif {"roll", "pitch", "yaw"} <= set(robot.task):
        given = dict(zip(robot.task, np.moveaxis(target, -1, 0)))
        position = np.stack([given.get(axis, pose[..., i, 3]) for i, axis in enumerate("xyz")], -1)
        goal = _rpy_rotation(given["roll"], given["pitch"], given["yaw"])[..., :3, :3]
    else:
        return _task_difference(robot, q, target)
    turn = rotation_vector(goal @ np.swapaxes(pose[..., :3, :3], -1, -2))
    full = np.concatenate([position - pose[..., :3, 3], turn], -1)
    return full[..., [TASK_COMPONENTS.index(name) for name in robot.task]]


def ik_numeric_step(robot, target, q, damping):
    """One damped least-squares step of ik_numeric (contract §2): q clamped to the joint limits
    (a joint without limits is not), the error e there (a pose: the position error and the
    rotation vector of R_target R^T with the geometric Jacobian J; else target - mu, Euler angles
    wrapped, with the task Jacobian), q + J^T (J J^T + damping I)^-1 e (or (J^T J + damping I)^-1
    J^T e where J is tall) clamped again; and |e|^2 at the clamped q: (q clamped, the next q, |e|^2)."""
    low = np.array([joint.limits[0] if joint.limits else -np.inf for joint in robot.joints])
    high = np.array([joint.limits[1] if joint.limits else np.inf for joint in robot.joints])
    start = np.clip(q, low, high)
    if len(robot.task) == 6:
        error, J = task_error(robot, start, target), jacobian(robot, start)
    else:
        error, J = _task_difference(robot, start, np.asarray(target, dtype=float)), task_jacobian(robot, start)
    m, n = J.shape[-2:]
    transposed = np.swapaxes(J, -1, -2)
    if m <= n:
        step = transposed @ np.linalg.solve(J @ transposed + damping * np.eye(m), error[..., None])
    else:
        step = np.linalg.solve(transposed @ J + damping * np.eye(n), transposed @ error[..., None])
    return start, np.clip(start + step[..., 0], low, high), np.sum(error * error, -1)


def _task_difference(robot, q, target):
    """target - mu(q), the Euler angles wrapped into (-pi, pi]."""
    difference = target - task(robot, q)
    angular = [k for k, name in enumerate(robot.task) if name in ("roll", "pitch", "yaw")]
    difference[..., angular] = np.pi - (np.pi - difference[..., angular]) % (2 * np.pi)
    return difference
