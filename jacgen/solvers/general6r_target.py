"""The general 6R solver at a target, as expressions on the target's symbols: the parts of
ik_branches that its language's template loop calls around the eigenproblem (`general6r.py`
derives the equations once per robot; this module evaluates them at T and turns a root's loop
angles back into joints). The Generator declares each part as a generated function.
"""

import math

import sympy
from sympy.core.parameters import distribute

from jacgen.inputs.robot import Robot
from jacgen.inputs.transforms import rigid_inverse, rot_z, twist
from jacgen.solvers import general6r, ik
from jacgen.solvers.subproblems import Subproblems


def equations_at(robot: Robot, form: "ik.ClosedForm", target: sympy.Matrix, name) -> tuple[sympy.Matrix, ...]:
    """(N, P, Q) at the target pose `target`: N = head^-1 T tail^-1, the loop's closing link;
    P = [P0; Ps; Pc] (42 x 9) with the hidden angle's shift applied and Q (14 x 8), the
    equations (P0 + s Ps + c Pc) v_bc = Q v_gh. `name` names the shared values. A 7R arm's
    free joint is in the chain's head or tail."""
    plan = form.elimination
    equations, split = plan.equations, plan.equations.split
    head, _, tail = general6r.chain_form(robot, form.free)
    with distribute(False):
        n = (rigid_inverse(head) * target * rigid_inverse(tail)).applyfunc(name)
        v = rigid_inverse(n).applyfunc(name) if split.target_inverted else n
        values = {**{equations.rotation[k]: v[k // 3, k % 3] for k in range(9)},
                  **{equations.translation[k]: v[k, 3] for k in range(3)}}
        p0, ps, pc, q = (m.xreplace(values) for m in equations.matrices)
        cos, sin = sympy.Float(math.cos(plan.shift), 17), sympy.Float(math.sin(plan.shift), 17)
        ps, pc = cos * ps - sin * pc, sin * ps + cos * pc
        return n, sympy.Matrix.vstack(p0, ps, pc), q


def loop_configuration(robot: Robot, form: "ik.ClosedForm", n: sympy.Matrix, angles, joints: list,
                       name) -> list:
    """The robot's joint values (`joints`, the chain's joint symbols, of which a 7R arm's free
    one stays) of one root's loop angles `angles` (a - shift, b, c, g, h), the loop's free joint
    from the loop closed by N (`equations_at`)."""
    plan = form.elimination
    split = plan.equations.split
    _, links, _ = general6r.chain_form(robot, form.free)
    loop = dict(zip((*split.triple, *split.pair), angles))
    loop[split.hidden] = loop[split.hidden] + sympy.Float(plan.shift, 17)
    theta = [None] * 6
    for position, angle in loop.items():
        theta[split.joint(position)] = -angle if split.backwards else angle
    free = split.joint(split.free)
    constants = [twist(link.d, link.a, link.alpha) for link in links]
    # The loop angles' rotations, made before distribute(False): under it the -(g + shift) of a
    # backwards split is not canonical, and cos's "could extract a minus sign" negates it back
    # and forth forever.
    turns = [None if i == free else rot_z(sympy.cos(theta[i]), sympy.sin(theta[i]))[:3, :3]
             for i in range(6)]
    with distribute(False):
        before, after = sympy.eye(3), constants[free][:3, :3] if free < 5 else sympy.eye(3)
        for i, turn in enumerate(turns):
            if i < free:
                before = (before * turn * constants[i][:3, :3]).applyfunc(name)
            elif i > free:
                after = (after * turn * (constants[i][:3, :3] if i < 5 else sympy.eye(3))).applyfunc(name)
        column = (before.T * n[:3, :3] * after.T[:, 0]).applyfunc(name)  # Z_free's first column
        theta[free] = sympy.atan2(column[1], column[0])
        q = list(joints)
        for k, t in zip(form.joints, theta):
            q[k] = t - robot.joints[k].offset.exact
    return q


def nominal_branches(form: "ik.ClosedForm", sp: Subproblems, target: sympy.Matrix, free_angle) -> tuple:
    """(q, valid, margin): a calibrated arm's fast path's starting points, every branch of its
    nominal arm's closed form at `target`, whether the target allows it, and the least margin
    of its subproblems."""
    fast = form.fast_path
    sp.margins = []
    q, valid, _ = ik.branches(fast.nominal.robot, fast.form, sp, target, free_angle)
    g, margin = sp.graph, sp.margins[0]
    for other in sp.margins[1:]:
        margin = sp.name(g.select(g.relation("<=", margin, other), margin, other))
    return q, valid, margin
