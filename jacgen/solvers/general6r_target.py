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
from jacgen.model.node import AND, OR, Node
from jacgen.model.tangents import Tangents
from jacgen.solvers import general6r, general6r_plan, ik
from jacgen.solvers.subproblems import CERTIFICATE, Fold, Subproblems, greatest


def equations_at(robot: Robot, form: "ik.ClosedForm", plan: "general6r_plan.Elimination", target: sympy.Matrix,
                 name) -> tuple[sympy.Matrix, ...]:
    """(N, P, Q) of the elimination `plan` (the form's, or its fallback) at the target pose
    `target`: N = head^-1 T tail^-1, the loop's closing link; P = [P0; Ps; Pc] (42 x 9) with the
    hidden angle's shift applied and Q (14 x 8), the equations (P0 + s Ps + c Pc) v_bc = Q v_gh.
    `name` names the shared values. A 7R arm's free joint is in the chain's head or tail."""
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


def loop_configuration(robot: Robot, form: "ik.ClosedForm", plan: "general6r_plan.Elimination", n: sympy.Matrix,
                       angles, joints: list, name) -> list:
    """The robot's joint values (`joints`, the chain's joint symbols, of which a 7R arm's free
    one stays) of one root's loop angles `angles` (a - shift, b, c, g, h) of the elimination
    `plan`, the loop's free joint from the loop closed by N (`equations_at`)."""
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


def nominal_branches(form: "ik.ClosedForm", sp: Subproblems, target: sympy.Matrix, free_angle,
                     value_of) -> tuple:
    """(q, valid, certified): a calibrated arm's fast path's starting points, every branch of
    its nominal arm's closed form at `target`, whether the target allows it, and whether its
    certificate holds (`Certificate`). `value_of` gives a named value's definition."""
    fast = form.fast_path
    certificate = Certificate(sp, target, value_of, fast.rotation, fast.position)
    sp.margins = certificate.test
    q, valid, _ = ik.branches(fast.nominal.robot, fast.form, sp, target, free_angle)
    sp.margins = None
    return q, valid, sp.graph.logic(AND, *certificate.tests)


class Certificate:
    """Whether every margin m of a branch that the target allows is at least CERTIFICATE times
    its radius, the most it moves to first order while the target turns by up to `rotation`
    and its position moves by up to `position`: |m| >= CERTIFICATE (rotation |dm/dw| + position
    |dm/dv|), T' = (exp(w) R, t + v). A margin is 0 where a root is double or an angle free, so
    where this holds no branch appears, vanishes or meets another for any target within that
    distance (contract §2, "Calibrated arms").

    A fold (`Fold`: two roots that meet) whose margin is positive but below that is *relaxed*
    instead, unless a fold it depends on is: over the targets within the mismatch its two
    roots lie on one sheet, between (1 - cos) bounds of their half-gap, which holds at most two
    of the exact arm's solutions, and the two branches must reach two. Every margin computed
    from the sheet's roots then adds, where the fold is relaxed, how far it moves along the
    sheet: |dm/dtheta| (the roots' first-order move + their half-gap + the greatest half-gap +
    the midpoint's turn). Each test is built as its margin is recorded, so that the generated
    code computes it while the margin's values are at hand."""

    def __init__(self, sp: Subproblems, target: sympy.Matrix, value_of, rotation: float, position: float):
        g = self.graph = sp.graph
        self.name, self.value_of, self.rotation, self.position = sp.name, value_of, rotation, position
        rows = [[g.symbol(target[i, j]) for j in range(4)] for i in range(3)]
        seeds = {}
        for i in range(3):  # the directions along which the target moves (not the rotation's where it does not turn)
            for j in range(3):  # d(exp(w) R)/dw_k = e_k x R
                column = [rows[m][j] for m in range(3)]
                seeds[rows[i][j]] = tuple(_cross_unit(k, column)[i] if rotation else None for k in range(3)) + \
                    (None,) * 3
            seeds[rows[i][3]] = (None,) * 3 + tuple(g.number(1) if k == i else None for k in range(3))
        self.tangents = Tangents(g, sp.name, value_of, seeds)
        self.tests: list = []
        self.slacks: list = []  # each test's margin - CERTIFICATE radius where its branch is allowed, else 1
        self._sheets: list[tuple] = []  # (relaxed, span, tangents along the roots) of each fold

    def _radius(self, parts: list, rates) -> Node:
        """The sum of factor |a part's move|, each move's size `rates(the part's entries)`."""
        g = self.graph
        radius = g.number(0)
        for factor, part in parts:
            radius += factor * rates(_entries(part))
        return radius

    def _target_move(self, entries) -> Node:
        """rotation |d/dw| + position |d/dv| of a vector (Frobenius norms)."""
        g = self.graph
        d = [[x or g.number(0) for x in self.tangents.of(entry)] for entry in entries]
        turned, moved = (g.sqrt(sum((row[k] * row[k] for row in d for k in directions), g.number(0)))
                         for directions in ((0, 1, 2), (3, 4, 5)))
        return self.rotation * turned + self.position * moved

    def test(self, margin, parts: list, valid, fold: Fold | None = None) -> None:
        """Records the test of one margin (see `Subproblems._margin`), which counts where `valid`."""
        g = self.graph
        radius = self._radius(parts, self._target_move)
        upstream = []
        for relaxed, span, along in self._sheets:
            if all(along.of(entry)[0] is None for _, part in parts for entry in _entries(part)):
                continue  # not computed from this fold's roots
            turning = self._radius(parts, lambda entries: g.sqrt(sum(
                ((along.of(entry)[0] or g.number(0)) ** 2 for entry in entries), g.number(0))))
            radius += g.select(relaxed, turning * span, g.number(0))
            upstream.append(relaxed)
        slack = self.name(g.select(valid, margin - CERTIFICATE * radius, g.number(1)))  # NaN fails the test
        test = g.relation(">=", slack, g.number(0))
        if fold is not None:
            widest, turn, bounded = fold.sheet(radius)
            relaxed = g.logic(AND, g.relation("<", slack, g.number(0)), g.relation(">", fold.signed, g.number(0)),
                              fold.both, bounded, *(g.negation(r) for r in upstream))
            along = Tangents(g, self.name, self.value_of, fold.along)
            self._sheets.append((relaxed, self._span(fold, widest, turn), along))
            test = g.logic(OR, test, relaxed)
        self.slacks.append(slack)
        self.tests.append(test)

    def _span(self, fold: Fold, widest, turn) -> Node:
        """How far a root of the fold can move along its sheet: its first-order move + the
        half-gap now + the greatest half-gap + the midpoint's move."""
        g = self.graph
        moves = [self._target_move((coordinate,)) for coordinate in fold.coordinates]
        return self.name(greatest(g, *moves) + fold.half_gap + widest + turn)


def _entries(part) -> tuple:
    """A part's values: a vector's entries, or the one number."""
    return part if isinstance(part, tuple) else (part,)


def _cross_unit(k: int, v: list) -> list:
    """e_k x v."""
    i, j = (k + 1) % 3, (k + 2) % 3
    out = [None] * 3
    out[i], out[j] = -v[j], v[i]
    return out
