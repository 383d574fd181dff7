"""Joint limits in the closed-form IK: each branch in ik's form (revolute angles wrapped, or
moved by whole turns into the limits), whether it is inside the limits, and ik_nearest's
choice of the solution nearest a seed. On the value graph, like the solvers of `ik.py`.
"""

from typing import Callable

import sympy

from jacgen.model.node import AND, OR, Node
from jacgen.solvers.subproblems import Subproblems, wrapped

# ik_nearest's statuses
IK_NEAREST_OK, IK_NEAREST_NO_SOLUTION, IK_NEAREST_NOT_FINITE = 0, 1, 2
IK_NEAREST_STATUSES = (("OK", IK_NEAREST_OK), ("NO_SOLUTION", IK_NEAREST_NO_SOLUTION),
                       ("NOT_FINITE", IK_NEAREST_NOT_FINITE))  # as each backend names them, IK_NEAREST_OK ...
TURN = 2 * sympy.pi
# ik_nearest calls its step (a kernel) for each row of a table this long at most; each call keeps
# its state on the C stack, and the general solver's 16 rows would pass the 4 KB a function may
# take (tests/test_shipped_robots.py): there the step is written out for each row.
CALLED_ROWS = 8


def _inside(value: Node, limits: tuple[float, float]) -> Node:
    g = value.graph
    return g.logic(AND, g.relation(">=", value, g.value(limits[0])), g.relation("<=", value, g.value(limits[1])))


def in_limits(sp: Subproblems, value: Node, joint) -> tuple[Node, Node]:
    """A joint's value as ik returns it, and whether it is inside the joint's limits.

    A revolute angle stays wrapped into (-pi, pi] unless that is outside the limits and its
    lowest equivalent above the lower limit, lower + (angle - lower) mod 2 pi, is inside them
    (the Panda's joint 6, -0.0175 to 3.7525 rad, needs it); a joint without limits is always
    inside."""
    g, limits = sp.graph, joint.limits
    if limits is None:
        return value, g.true
    if not joint.revolute:
        return value, _inside(value, limits)
    value = sp.name(value)
    shifted = sp.name(value - TURN * g.call("Floor", (value - limits[0]) / TURN))
    wrapped_inside, shifted_inside = _inside(value, limits), g.relation("<=", shifted, g.value(limits[1]))
    return g.select(g.logic(AND, g.negation(wrapped_inside), shifted_inside), shifted, value), \
        g.logic(OR, wrapped_inside, shifted_inside)


def limited(robot, sp: Subproblems, q: list, order: tuple[int, ...], free: int | None = None
            ) -> tuple[list, Node]:
    """ik's form of a configuration (revolute angles wrapped, see `in_limits`; the free joint
    as given) and whether it is inside the joint limits; the joints named in `order`."""
    g = sp.graph
    q = [g.value(value) for value in q]
    inside = [] if free is None else [_inside(q[free], robot.joints[free].limits) if robot.joints[free].limits
                                      else g.true]
    for j in order:
        joint = robot.joints[j]
        q[j], joint_inside = in_limits(sp, wrapped(q[j]) if joint.revolute else q[j], joint)
        inside.append(joint_inside)
    return q, g.logic(AND, *inside)


def _nearest_equivalent(sp: Subproblems, value: Node, given: Node, seed: Node, joint) -> Node:
    """The equivalent (modulo 2 pi) of a revolute angle nearest the seed inside the limits: of
    the nearest one and its neighbours on either side, the first inside; else `given` (the
    lowest inside, `in_limits`). A prismatic joint's value as it is."""
    if not joint.revolute:
        return value
    g = sp.graph
    nearest = sp.name(value + TURN * g.call("Floor", (seed - value) / TURN + sympy.Rational(1, 2)))
    limits = joint.limits
    if limits is None:
        return nearest
    step = g.select(g.relation("<", nearest, seed), g.value(TURN), g.value(-TURN))
    second, third = sp.name(nearest + step), sp.name(nearest - step)
    return g.select(_inside(nearest, limits), nearest,
                    g.select(_inside(second, limits), second, g.select(_inside(third, limits), third, given)))


def nearest(robot, sp: Subproblems, q, valid: list, inside: list, seed, weights,
            free: int | None, read: list, call: Callable) -> tuple[list, Node]:
    """ik_nearest: of the valid branches inside the limits, the one nearest the seed by
    sum_j weights_j (q_j - seed_j)^2, each revolute joint at its equivalent nearest the seed
    inside the limits; and the status. No solution, or an entry of the target `read`, a seed
    or a weight that is not finite: q = seed.

    The running minimum over the rows is one body, the kernel nearer_branch (`call`:
    `Lowering.called`), called for each row: (row, allowed, seed, weights, best, distance,
    found) to the next (best, distance, found); written out for each row of a table longer
    than CALLED_ROWS. Truth values are carried as 0/1 numbers."""
    g = sp.graph
    zero, one = g.number(0), g.number(1)
    n = robot.dof
    q, valid, inside = g.values(q).tolist(), list(g.values(valid)), list(g.values(inside))
    seed, weights, read = list(g.values(seed)), list(g.values(weights)), list(g.values(read))

    def step(values: list[Node]) -> list[Node]:
        row, allowed, seed, weights = values[:n], values[n], values[n + 1:2 * n + 1], values[2 * n + 1:3 * n + 1]
        best, distance, found = values[3 * n + 1:4 * n + 1], values[4 * n + 1], values[4 * n + 2]
        candidate = [sp.name(value if j == free else _nearest_equivalent(sp, value, value, seed[j], joint))
                     for j, (value, joint) in enumerate(zip(row, robot.joints))]
        cost = sp.name(sum(w * (x - s) ** 2 for w, x, s in zip(weights, candidate, seed)))
        closer = g.logic(OR, g.relation("<", found, one), g.relation("<", cost, distance))
        take = g.relation(">", sp.name(g.select(g.logic(AND, g.relation(">", allowed, zero), closer), one, zero)),
                          zero)
        return [*(sp.name(g.select(take, x, b)) for x, b in zip(candidate, best)),
                sp.name(g.select(take, cost, distance)), sp.name(g.select(g.relation(">", allowed, zero), one, found))]

    if len(q) > CALLED_ROWS:
        def call(name, summary, step, values):  # the step written out in place
            return step(values)
    best, distance, found = list(seed), zero, zero
    for row, row_valid, row_inside in zip(q, valid, inside):
        allowed = g.select(g.logic(AND, row_valid, row_inside), one, zero)
        state = call("nearer_branch", "the nearer of the best branch so far and the next one, in the limits and "
                     "nearest the seed by its joints' equivalents", step,
                     [*row, allowed, *seed, *weights, *best, distance, found])
        best, distance, found = state[:n], state[n], state[n + 1]
    inputs_finite = g.finite(sp.name(sum([*read, *seed, *weights])))
    status = g.select(g.negation(inputs_finite), g.number(IK_NEAREST_NOT_FINITE),
                      g.select(g.relation(">", found, zero), g.number(IK_NEAREST_OK), g.number(IK_NEAREST_NO_SOLUTION)))
    return [g.select(g.logic(AND, g.relation(">", found, zero), inputs_finite), x, s) for x, s in zip(best, seed)], status
