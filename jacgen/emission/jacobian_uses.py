"""What the Jacobian is for, as generated functions: the pose and velocity of every link, the
velocity ellipsoids, the condition number, the manipulability gradient, null-space motion and
resolved-rate control; and velocity_ik, whose solve the last two call. Each is built from the
Generator's chain and lowered by its `function`; the algorithms are in
`solvers/singular_values.py` and `solvers/differential.py`. `generator` is the `Generator`
that calls them.
"""

import numpy
import sympy
from sympy.core.parameters import distribute

from jacgen.emission.catalogue import Argument, Function, matrix, scalar, status, vector
from jacgen.inputs.robot import EULER_ANGLES
from jacgen.inputs.transforms import xyz_rpy_transform
from jacgen.model import kinematics
from jacgen.model.graph import elementwise
from jacgen.model.js_rank import singularity_rows
from jacgen.model.kinematics import generated_symbol
from jacgen.model.node import NUMBER, OR, Kernel, Node
from jacgen.model.tolerance_symbols import EPS
from jacgen.solvers import differential, singular_values

# The uses of the Jacobian, as the report lists them (velocity_ik is among the inverses there).
NAMES = ("link_poses", "link_velocities", "manipulability_gradient", "velocity_ellipsoid", "condition_number",
         "velocity_ik_nullspace", "resolved_rate")


def link_frames(generator) -> list[sympy.Matrix]:
    """World pose of each link's DH frame, base A_1 ... A_i (no tool): the axis frame of the
    next joint (standard DH, where joint i + 1 turns about frame i's z), or the axis frame of
    the joint moved along and about its axis (modified DH, and standard's last link)."""
    robot, chain = generator.robot, generator.chain
    links = kinematics.link_transforms(robot, lambda i: generator.cos_sin((i,)), generator.q)
    frames = []
    for i, (axis, (_, after)) in enumerate(zip(chain.axes, links)):
        if robot.convention == "standard" and i + 1 < robot.dof:
            frames.append(chain.axes[i + 1])
        else:
            frames.append((axis * after).applyfunc(generator.named))
    return frames


def link_velocities(generator, frames: list, rates: list) -> numpy.ndarray:
    """[v; w] of each link frame's origin (n x 6), propagated from the base: w_i = w_{i-1} +
    z_i qd_i (revolute), v_i = v_{i-1} + w x (p_i - p_{i-1}) + z_i qd_i (prismatic), where w
    is w_i in standard DH (joint i turns about frame i-1's origin) and w_{i-1} in modified DH
    (joint i's axis passes through p_i, so it moves p_i not at all)."""
    robot, g, name = generator.robot, generator.graph, generator.name_node
    origin = g.values(generator.chain.axes[0][:3, 3] if robot.convention == "standard"
                      else kinematics.pose_transform(robot.base)[:3, 3]).flatten()
    v, w = numpy.zeros(3, dtype=object), numpy.zeros(3, dtype=object)
    rows = []
    for joint, axis, frame, rate in zip(robot.joints, generator.chain.axes, frames, rates):
        z, position = g.values(axis[:3, 2]).flatten(), g.values(frame[:3, 3]).flatten()
        turned = elementwise(name, w + z * rate) if joint.revolute else w
        lever = turned if robot.convention == "standard" else w
        v = elementwise(name, v + numpy.cross(lever, elementwise(name, position - origin))
                        + (0 if joint.revolute else z * rate))
        w, origin = turned, position
        rows.append(numpy.concatenate([v, w]))
    return numpy.stack(rows)


def js_layers(generator, task_jacobian: sympy.Matrix) -> list[numpy.ndarray]:
    """dJs/dq_k for each k (m x n arrays of nodes): the task's rows of the hessian's layers, or,
    where Js is the task Jacobian, its rate along the unit joint rate e_k."""
    robot, g, name = generator.robot, generator.graph, generator.name_node
    columns = elementwise(name, g.values(generator.jacobian))
    layers = kinematics.hessian(robot, columns)
    rows = singularity_rows(robot)
    if rows is not None:
        return [layer[list(rows), :] for layer in layers]
    pose = g.values(generator.chain.tool)
    units = numpy.eye(robot.dof, dtype=int)
    return [kinematics.task_jacobian_dot(robot, pose, columns, elementwise(name, layer),
                                         g.values(list(unit)).flatten(), name) for layer, unit in zip(layers, units)]


def scaled_js(generator, js: sympy.Matrix) -> numpy.ndarray:
    """Js with its position rows divided by the characteristic length (`model.dexterity`)."""
    g, length = generator.graph, generator.model.dexterity.length
    inverse = g.number(1) if length == 1 else g.value(1 / length)
    rows = [g.values(js[r, :]).flatten() * (inverse if component in ("x", "y", "z") else 1)
            for r, component in enumerate(generator.robot.task)]
    return elementwise(generator.name_node, numpy.stack(rows))


def feedback_error(generator, target: Argument, task_jacobian: sympy.Matrix) -> list:
    """resolved_rate's task error e, in the rows of Js: ik_numeric's (the position error and the
    rotation vector of R_target R^T, world frame, for a six-component task; else the task
    error, angles wrapped, whose Js is the task Jacobian or has no angle), or, for a task of
    the three angles and fewer positions, whose Js has angular velocity rows, the position
    error and the rotation vector of the rotation the target's angles make, times R^T."""
    robot, g = generator.robot, generator.graph
    if len(robot.task) == 6 or singularity_rows(robot) is None or not set(EULER_ANGLES) <= set(robot.task):
        return generator.task_error(target, task_jacobian)[0]
    goal = dict(zip(robot.task, target.symbols))
    rotation = xyz_rpy_transform((0, 0, 0), [goal[angle] for angle in EULER_ANGLES])[:3, :3]
    tool = generator.chain.tool
    turn = differential.rotation_vector(g.values(rotation) @ g.values(tool[:3, :3]).T, g, generator.name_node)
    error = {axis: goal.get(axis, 0) - tool[i, 3] for i, axis in enumerate(("x", "y", "z"))}
    error.update(zip(EULER_ANGLES, turn))
    return [error[component] for component in robot.task]


def functions(generator, js: sympy.Matrix, task_jacobian: sympy.Matrix) -> list[Function]:
    """Those of NAMES the generator generates, in the catalogue's order (sorted by the caller)."""
    g, name, n = generator.graph, generator.name_node, generator.robot.dof
    q = Argument("q", sympy.Matrix(generator.q))
    q_dot = Argument("q_dot", sympy.Matrix([generated_symbol("qd", i + 1) for i in range(n)]))
    made = []
    frames = link_frames(generator) if any(map(generator.generates, NAMES[:2])) else []
    if generator.generates("link_poses"):
        made.append(generator.function("link_poses", "world pose of each link's DH frame, base A_1 ... A_i, without "
                                       "the tool (DOF x 4 x 4)", matrix("T", sympy.Matrix.vstack(*frames), layers=n)))
    if generator.generates("link_velocities"):
        rates = g.values(q_dot.symbols).flatten()
        made.append(generator.function("link_velocities", "linear and angular velocity [v; w] of each link frame's "
                                       "origin, world frame, propagated from the base (DOF x 6)",
                                       matrix("V", link_velocities(generator, frames, rates)), arguments=(q, q_dot)))
    if generator.generates("manipulability_gradient"):
        gradient = singular_values.manipulability_gradient(
            elementwise(name, g.values(js)), js_layers(generator, task_jacobian), g, name)
        made.append(generator.function("manipulability_gradient", "d manipulability / dq (DOF), from the hessian's "
                                       "layers; 0 where Js is singular (velocity_ik's rule)", vector("dw", gradient)))
    if generator.generates("velocity_ellipsoid"):
        blocks = elementwise(name, g.values(generator.jacobian))
        (U_v, s_v), (U_w, s_w) = singular_values.left_singular_3([blocks[:3].tolist(), blocks[3:].tolist()], g, name,
                                                                     generator.lowering.repeated)
        made.append(generator.function("velocity_ellipsoid", "axes (U's columns, a rotation) and semi-axes s "
                                       "(descending) of the tool's velocity ellipsoids for |q_dot| = 1, linear (v) and "
                                       "angular (w): the SVD of jacobian's blocks; the force ellipsoids have the same "
                                       "axes and semi-axes 1/s", matrix("U_v", numpy.array(U_v, dtype=object)),
                                       vector("s_v", s_v), matrix("U_w", numpy.array(U_w, dtype=object)),
                                       vector("s_w", s_w)))
    if generator.generates("condition_number"):
        made.append(condition_number_function(generator, js))
    made += _rate_functions(generator, js, task_jacobian, q)
    return made


def condition_number_function(generator, js: sympy.Matrix) -> Function | None:
    """condition_number: the singular values of Js with its position rows divided by L, their
    largest over their smallest; None where Js is singular at every configuration."""
    g, name, m, n = generator.graph, generator.name_node, js.rows, generator.robot.dof
    scaled = scaled_js(generator, js)
    values = singular_values.singular_values((scaled.T if m <= n else scaled).tolist(), g, name,
                                             generator.lowering.repeated)
    largest, smallest = values[0], values[0]
    for value in values[1:]:
        largest = name(g.select(g.relation(">", value, largest), value, largest))
        smallest = name(g.select(g.relation("<", value, smallest), value, smallest))
    # Js is singular to rounding where sigma_min is at most EPS sigma_max, or where sigma_max is at
    # most EPS of the largest an entry can be (a task the joints cannot move: a one-row Js
    # vanishes where the joints' motion is square to it): then sigma_min is 0, and kappa infinite
    # (x / 0 in IEEE arithmetic). A Js singular everywhere (a smallest value that is the number 0)
    # gets no condition_number.
    if smallest.kind == NUMBER:
        return None
    zero = g.logic(OR, g.relation("<=", smallest, g.symbol(EPS) * largest),
                   g.relation("<=", largest, g.symbol(EPS) * g.value(largest_entry(generator))))
    smallest = name(g.select(zero, g.number(0), smallest))
    positive = name(g.select(g.relation(">", largest, g.number(0)), largest, g.number(1)))
    return generator.function("condition_number", "sigma_max / sigma_min of Js with its position rows divided by "
                              "CHARACTERISTIC_LENGTH; infinite where sigma_min <= EPS sigma_max or sigma_max <= EPS "
                              "times its largest entry's bound (Js singular to rounding)",
                              scalar("kappa", positive / smallest))


def largest_entry(generator) -> float:
    """A bound on the entries of Js with its position rows divided by L (`scaled_js`): an
    angular row's are at most 1, a revolute column's position entries at most reach / L, a
    prismatic column's 1 / L (`reference.condition_number` reads the same bound)."""
    return 1 + (1 + generator.robot.reach) / generator.model.dexterity.length


def velocity_solve(generator, js: sympy.Matrix, joints: list[sympy.Symbol], mu_dot: list[sympy.Symbol],
                   damping: sympy.Symbol, z: list[sympy.Symbol]) -> Kernel:
    """The solve of velocity_ik and its relatives (`differential.velocity_ik`): one kernel,
    (joint values, mu_dot, damping[, z]) to (q_dot, status), that velocity_ik,
    velocity_ik_nullspace and resolved_rate call (`_rate_functions`); z only where Js has a
    null space (m < n; empty otherwise). Its joint values (`_joint_values`) are what Js reads,
    which the callers compute (resolved_rate's task error reads them too): a q that is not
    finite has a cos and sin that are not."""
    def solved() -> list:
        q_dot, outcome = differential.velocity_ik(js, joints, mu_dot, damping, generator.graph, generator.name_node,
                                                  generator.lowering.called, z or None)
        return [*q_dot, outcome]

    return generator.lowering.kernel("velocity_solve", "the joint rates q_dot solving Js q_dot = mu_dot (plus z's "
                                     "motion in the null space of Js, if it has one), and velocity_ik's status",
                                     [*joints, *mu_dot, damping, *z], solved)


def _joint_values(generator) -> list[sympy.Symbol]:
    """What the kinematics read: of q, each revolute joint's cos and sin and each prismatic q;
    and the robot's symbolic parameters."""
    return [symbol for i, joint in enumerate(generator.robot.joints)
            for symbol in (generator.cos_sin((i,)) if joint.revolute else (generator.q[i],))] + \
        [parameter.symbol for parameter in generator.robot.symbolic_parameters]


def _rate_functions(generator, js: sympy.Matrix, task_jacobian: sympy.Matrix,
                    q: Argument) -> list[Function]:
    """velocity_ik, velocity_ik_nullspace and resolved_rate: each a run of velocity_solve."""
    g, name, n, m = generator.graph, generator.name_node, generator.robot.dof, js.rows
    z = Argument("z", sympy.Matrix([generated_symbol("qz", i + 1) for i in range(n)]))
    damping = generator.damping_argument()
    form = "Js# mu_dot + (I - Js# Js) z" + (" (Js has no null space: z is not used)" if m >= n else "")
    mu_dot = Argument("mu_dot", sympy.Matrix([generated_symbol("mu_dot", i) for i in range(m)]))
    joints, null_space = _joint_values(generator), list(z.symbols) if m < n else []

    def solve(rates: list, motion: list) -> tuple[list, Node]:
        kernel = velocity_solve(generator, js, joints, list(mu_dot.symbols), damping.symbols[0], null_space)
        solved = generator.lowering.run(kernel, 1, [*joints, *rates, *damping.symbols, *motion[:len(null_space)]])
        return solved[:n], solved[n]

    made = []
    if generator.generates("velocity_ik"):
        q_dot, outcome = solve(list(mu_dot.symbols), [0] * n)
        solution = "Js^-1 mu_dot (damping 0) or " if m == n else ""
        solution += ("Js^T (Js Js^T + damping^2 I)^-1 mu_dot" if m <= n else "(Js^T Js + damping^2 I)^-1 Js^T mu_dot")
        made.append(generator.function("velocity_ik", f"joint rates q_dot solving Js q_dot = mu_dot: {solution}; and "
                                       "the status", vector("q_dot", q_dot), status("status", outcome),
                                       arguments=(q, mu_dot, damping)))
    if generator.generates("velocity_ik_nullspace"):
        q_dot, outcome = solve(list(mu_dot.symbols), list(z.symbols))
        made.append(generator.function("velocity_ik_nullspace", f"velocity_ik plus null-space motion: {form}, Js# "
                                       "velocity_ik's (damped) inverse; and the status (VELOCITY_IK_*)",
                                       vector("q_dot", q_dot), status("status", outcome),
                                       arguments=(q, mu_dot, z, damping)))
    if generator.generates("resolved_rate"):
        target = generator.ik_target()
        rate = Argument("target_rate", sympy.Matrix([generated_symbol("mu_dot", i) for i in range(m)]))
        gain = Argument("gain", sympy.Matrix([generated_symbol("gain", i) for i in range(m)]),
                        scalar_allowed=True)
        with distribute(False):
            error = feedback_error(generator, target, task_jacobian)
        command = [name(g.value(r) + g.value(k) * g.value(e)) for r, k, e in zip(rate.symbols, gain.symbols, error)]
        q_dot, outcome = solve(command, list(z.symbols))
        made.append(generator.function("resolved_rate", "resolved-rate control: q_dot = Js# (target_rate + gain e) "
                                       "+ (I - Js# Js) z, e ik_numeric's task error at q; and the status "
                                       "(VELOCITY_IK_*)", vector("q_dot", q_dot), status("status", outcome),
                                       arguments=(q, target, rate, gain, z, damping)))
    return made
