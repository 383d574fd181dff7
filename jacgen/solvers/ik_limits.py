"""Joint limits in the closed-form IK: each branch in ik's form (revolute angles wrapped, or
moved by whole turns into the limits), whether it is inside the limits, and ik_nearest's
choice of the solution nearest a seed. Expressions, like the solvers of `ik.py`.
"""

import sympy

from jacgen.model.nodes import Above, AtLeast, AtMost, Below, Floor, IsFinite, select
from jacgen.solvers.subproblems import Subproblems, wrapped

# ik_nearest's statuses
IK_NEAREST_OK, IK_NEAREST_NO_SOLUTION, IK_NEAREST_NOT_FINITE = 0, 1, 2
TURN = 2 * sympy.pi


def _inside(value, limits: tuple[float, float]) -> sympy.Basic:
    return sympy.And(AtLeast(value, limits[0]), AtMost(value, limits[1]))


def in_limits(sp: Subproblems, value, joint) -> tuple[sympy.Expr, sympy.Basic]:
    """A joint's value as ik returns it, and whether it is inside the joint's limits.

    A revolute angle stays wrapped into (-pi, pi] unless that is outside the limits and its
    lowest equivalent above the lower limit, lower + (angle - lower) mod 2 pi, is inside them
    (the Panda's joint 6, -0.0175 to 3.7525 rad, needs it); a joint without limits is always
    inside."""
    limits = joint.limits
    if limits is None:
        return value, sympy.true
    if not joint.revolute:
        return value, _inside(value, limits)
    value = sp.name(value)
    shifted = sp.name(value - TURN * Floor((value - limits[0]) / TURN))
    wrapped_inside, shifted_inside = _inside(value, limits), AtMost(shifted, limits[1])
    return select(sympy.And(sympy.Not(wrapped_inside), shifted_inside), shifted, value), \
        sympy.Or(wrapped_inside, shifted_inside)


def limited(robot, sp: Subproblems, q: list, order: tuple[int, ...], free: int | None = None
            ) -> tuple[list, sympy.Basic]:
    """ik's form of a configuration (revolute angles wrapped, see `in_limits`; the free joint
    as given) and whether it is inside the joint limits; the joints named in `order`."""
    q = list(q)
    inside = [] if free is None else [_inside(q[free], robot.joints[free].limits) if robot.joints[free].limits
                                      else sympy.true]
    for j in order:
        joint = robot.joints[j]
        q[j], joint_inside = in_limits(sp, wrapped(q[j]) if joint.revolute else q[j], joint)
        inside.append(joint_inside)
    return q, sympy.And(*inside)


def _nearest_equivalent(sp: Subproblems, value, given, seed, joint):
    """The equivalent (modulo 2 pi) of a revolute angle nearest the seed inside the limits: of
    the nearest one and its neighbours on either side, the first inside; else `given` (the
    lowest inside, `in_limits`). A prismatic joint's value as it is."""
    if not joint.revolute:
        return value
    nearest = sp.name(value + TURN * Floor((seed - value) / TURN + sympy.Rational(1, 2)))
    limits = joint.limits
    if limits is None:
        return nearest
    below = Below(nearest, seed)
    second, third = sp.name(nearest + select(below, TURN, -TURN)), sp.name(nearest - select(below, TURN, -TURN))
    return select(_inside(nearest, limits), nearest,
                  select(_inside(second, limits), second, select(_inside(third, limits), third, given)))


def nearest(robot, sp: Subproblems, q: sympy.Matrix, valid: list, inside: list, seed, weights,
            free: int | None, read: list) -> tuple[list, sympy.Expr]:
    """ik_nearest: of the valid branches inside the limits, the one nearest the seed by
    sum_j weights_j (q_j - seed_j)^2, each revolute joint at its equivalent nearest the seed
    inside the limits; and the status. No solution, or an entry of the target `read`, a seed
    or a weight that is not finite: q = seed."""
    # The running minimum over the rows; truth values carried as named 0/1 numbers, so that
    # no condition grows with the number of rows.
    best, found, distance = list(seed), sympy.Integer(0), sympy.Integer(0)
    for row, row_valid, row_inside in zip(q.tolist(), valid, inside):
        candidate = [sp.name(value if j == free else _nearest_equivalent(sp, sp.name(value), value, seed[j], joint))
                     for j, (value, joint) in enumerate(zip(row, robot.joints))]
        cost = sp.name(sympy.Add(*(w * (x - s) ** 2 for w, x, s in zip(weights, candidate, seed))))
        allowed = Above(sp.name(select(sympy.And(row_valid, row_inside), 1, 0)), 0)
        take = Above(sp.name(select(sympy.And(allowed, sympy.Or(Below(found, 1), Below(cost, distance))), 1, 0)), 0)
        best = [sp.name(select(take, x, b)) for x, b in zip(candidate, best)]
        distance = sp.name(select(take, cost, distance))
        found = sp.name(select(allowed, 1, found))
    inputs_finite = IsFinite(sp.name(sympy.Add(*read, *seed, *weights)))
    status = select(sympy.Not(inputs_finite), IK_NEAREST_NOT_FINITE,
                    select(Above(found, 0), IK_NEAREST_OK, IK_NEAREST_NO_SOLUTION))
    return [select(sympy.And(Above(found, 0), inputs_finite), x, s) for x, s in zip(best, seed)], status
