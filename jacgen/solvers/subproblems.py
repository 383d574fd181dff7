"""Paden-Kahan subproblems on the value graph, every root computed, each with its validity.

The closed-form solvers of `ik.py` are written with these once, and every backend prints
them. Nothing branches: a root the target does not allow is still computed (from clamped
values) and flagged invalid, a degenerate case is a `select`. So a solver is straight-line
code, the same in C, over a numpy batch and in CasADi.

Vectors are 3-tuples of nodes (`graph.py`), relative to a point of the axis where it matters;
every intermediate value is passed to `name` (`Lowering.name_node`), so that the common-
subexpression elimination sees sums of named values. The tolerances are the symbols EPS and TINY,
replaced by the numbers of the build's real type when printed (`nodes.TOLERANCES`):

- a discriminant (a squared sine) within EPS of 0 is one double root: its second copy is
  invalid, so a tangent target or a target on a singularity gives one solution;
- a vector whose squared length is below TINY times its scale counts as zero: an angle it
  leaves free is 0.
"""

from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable

import sympy

from jacgen.model.graph import Graph
from jacgen.model.node import AND, CALL, NUMBER, OR, SELECT, Node
from jacgen.model.tolerance_symbols import EPS, TINY

Vector = tuple[Node, Node, Node]
# The calibrated fast path's certificate (general6r_target.Certificate): a margin must be this many
# times its first-order radius, so that the first-order term dominates what it leaves out.
CERTIFICATE = 2.0


@dataclass(frozen=True)
class Angle:
    """An angle with its cosine and sine (the solvers rotate by c and s, never by theta)."""

    theta: Node
    c: Node
    s: Node

    def turned_half(self) -> "Angle":
        """The angle + pi."""
        return Angle(self.theta + sympy.pi, -self.c, -self.s)


@dataclass(frozen=True)
class Root:
    """One root of a subproblem and whether it exists for this target."""

    angle: Angle
    valid: Node


@dataclass(frozen=True)
class Fold:
    """Where a subproblem's two roots meet (an elbow straight or folded, SP4's right-hand side
    at its amplitude, SP2's cones touching): both exist where `signed` > 0 (`both`: where the
    target allows both), neither where it is negative. Along the fold the roots are the values
    of one coordinate (an angle, or SP2's gamma): `coordinates` at each root, `along` the
    derivative along it of the values each root's branch reads, `half_gap` half their distance.
    `sheet(radius)`, where `signed` moves by up to `radius` to first order, bounds the greatest
    half-gap and how far their midpoint moves: (half-gap, move, whether these bounds hold). The
    certificate's relaxed fold (general6r_target.Certificate) reads them."""

    signed: Node
    both: Node
    coordinates: tuple[Node, Node]
    along: dict
    half_gap: Node
    sheet: Callable[[Node], tuple[Node, Node, Node]]


class Subproblems:
    """Vector algebra and the subproblems on `graph`, naming every intermediate with `name`."""

    def __init__(self, graph: Graph, name: Callable[[object], Node]):
        self.graph = graph
        self.name = name
        self.eps, self.tiny = graph.symbol(EPS), graph.symbol(TINY)
        # Sizes that are 0 where a root is double or an angle free, recorded (with the validity of
        # the branch that computes them) only when the fast path asks, by its certificate
        # (general6r_target.Certificate). Each is a difference of lengths or angles (or a product
        # of lengths), never of squares: its first-order change bounds its change, also
        # where a square's gradient vanishes (a folded elbow whose links are nearly equal).
        # - where two roots meet, appear or vanish: SP4's rotating part less |its right-hand
        #   side| (or, for a d that is the cosine of an angle, how far inside its range that angle
        #   is), SP3's third side's distance from the two others' sum and difference, and in SP2,
        #   how far inside its range the angle of q to k1 is;
        # - where an angle is free, as at a wrist singularity: the rotating part of SP1 or SP4
        #   (the product of its vectors' distances from the axis).
        self.margins: Callable[..., None] | None = None  # records (margin, parts, valid, fold)
        self._given: list[Node] = []  # the validity of the branches being built (see `given`)

    def _margin(self, size: Callable[[], tuple]) -> None:
        """Records size() = (margin, its parts[, its Fold]) when the margins are asked for (built
        only then). Each part is (factor, value), a value a number or a vector: the margin moves
        by at most the sum of factor |value's move|, also across the kink of an |x| or of a least
        of two, and for a length |v| also where v is near 0 (its move across v is not first order)."""
        if self.margins is not None:
            g = self.graph
            margin, parts, *fold = size()
            self.margins(margin, parts, g.logic(AND, *self._given) if self._given else g.truth(True), *fold)

    def _product_margin(self, u: Vector, v: Vector) -> tuple[Node, list]:
        """|u| |v|, the rotating part of SP1 and SP4."""
        size_u, size_v = self.norm(u), self.norm(v)
        return self.name(size_u * size_v), [(size_v, u), (size_u, v)]

    def _fold_margin(self, h_perp: Vector, p_perp: Vector, rhs: Node, roots: tuple[Root, Root]) -> tuple:
        """SP4's |h_perp| |p_perp| - |rhs|: two roots where positive, none where negative. With
        A = |h_perp| |p_perp|, 1 - cos(half-gap) = margin / A, and the midpoint's (A cos, A sin)
        moves by at most the radius to first order (its parts are the margin's first two), so
        by twice that over the ball (the certificate's factor 2), as A does."""
        size_h, size_p = self.norm(h_perp), self.norm(p_perp)
        g = self.graph
        amplitude = self.name(size_h * size_p)
        signed = self.name(amplitude - g.call("Abs", rhs))

        def sheet(radius):
            lower = amplitude - 2 * radius  # the amplitude over the ball, at least
            return (signed + 2 * radius) / lower, 2 * radius / lower, g.relation(">", lower, g.number(0))
        parts = [(size_p, h_perp), (size_h, p_perp), (1, rhs)]
        return g.call("Abs", signed), parts, self._angle_fold(signed, roots, sheet)

    def _angle_fold(self, signed: Node, roots: tuple[Root, Root], sheet: Callable) -> Fold:
        """The fold of two roots t = phi +- alpha, `sheet(radius)` giving a bound on 1 - cos of
        the greatest half-gap (min(alpha, pi - alpha)) and the midpoint's turn."""
        g = self.graph
        (c, s), (c2, s2) = ((root.angle.c, root.angle.s) for root in roots)
        along = {}  # d/dt (cos t, sin t, t)
        for root in roots:
            angle = root.angle
            along.update({angle.c: (-angle.s,), angle.s: (angle.c,), angle.theta: (g.number(1),)})

        def angles(radius):
            bound, turn, hold = sheet(radius)
            return 2 * g.call("asin", g.sqrt(_within(g, bound, 0, 2) / 2)), turn, hold
        return Fold(signed, roots[1].valid, (roots[0].angle.theta, roots[1].angle.theta), along,
                    g.call("Abs", g.call("atan2", s * c2 - c * s2, c * c2 + s * s2)) / 2, angles)

    def _angle_margin(self, x: Vector, y: Vector, h: Vector, p: Vector, k: Vector) -> tuple[Node, list]:
        """The angle b between x and y against the range of the angle between h and rot(k, t) p,
        [|t_h - t_p|, min(t_h + t_p, 2 pi - t_h - t_p)] (t_h, t_p the angles of h and p to k):
        some t turns p to angle b from h where b is inside. An angle between u and v moves by
        |u's move| / |u| + |v's move| / |v| to first order."""
        signed, parts, _ = self._angle_range(x, y, h, p, k)
        return self.graph.call("Abs", signed), parts

    def _angle_range(self, x: Vector, y: Vector, h: Vector, p: Vector, k: Vector) -> tuple[Node, list, tuple]:
        """`_angle_margin` signed (positive inside), its parts, and the angles of h and p to k."""
        g = self.graph
        angle, h_to_k, p_to_k = (g.call("atan2", self.norm(self.cross(u, v)), self.dot(u, v))
                                 for u, v in ((x, y), (h, k), (p, k)))
        spread = h_to_k + p_to_k
        signed = self.name(least(g, least(g, angle - g.call("Abs", h_to_k - p_to_k), spread - angle),
                                  2 * sympy.pi - spread - angle))
        return signed, [(1 / self.norm(u), u) for u in (x, y, h, p, k)], (h_to_k, p_to_k)

    def _cones_margin(self, k1: Vector, q: Vector, p: Vector, k2: Vector, gamma: Node, roots: tuple,
                      both: Node) -> tuple:
        """SP2's margin, how far inside its range the angle b of q to k1 is, as a fold of gamma:
        c = rot(k2, t) p on its cone (angle t_p to k2) is at angle b to k1 (angle psi to k2) at
        tau from the plane of k1 and k2 where sin(t_p) sin(psi) (1 - |cos tau|) <= the margin,
        and gamma = |p_perp| sin(tau) / sin(psi), p_perp p's part across k2. To first order each
        of the angles b, t_p, psi moves by at most the margin's radius and |p_perp| by 2 |p| times
        it; over the ball, by twice that (the certificate's factor 2)."""
        g = self.graph
        signed, parts, (psi, t_p) = self._angle_range(k1, q, k1, p, k2)
        across, size = self.norm(self.perpendicular(p, k2)), self.norm(p)

        def sheet(radius):
            sin_psi, sin_p = g.call("sin", psi) - 2 * radius, g.call("sin", t_p) - 2 * radius
            bound = (signed + 2 * radius) / (sin_p * sin_psi)  # 1 - cos(tau) at most
            bound = _within(g, bound, 0, 1)
            sine = g.sqrt(bound * (2 - bound))
            hold = g.logic(AND, g.relation(">", sin_p, g.number(0)), g.relation(">", sin_psi, g.number(0)))
            return (across + 4 * size * radius) / sin_psi * sine, g.number(0), hold
        normal = self.cross(k1, k2)
        along = {c[i]: (normal[i],) for c in roots for i in range(3)}  # c = alpha k1 + beta k2 + gamma' normal
        return g.call("Abs", signed), parts, Fold(signed, both, (gamma, gamma), along, gamma, sheet)

    def norm(self, v: Vector) -> Node:
        return self.name(self.graph.sqrt(self.dot(v, v)))

    @contextmanager
    def given(self, valid: Node):
        """Margins recorded within belong to a branch that exists only where `valid`: where it does
        not, and the certificate shows it cannot for any target near, its margins do not matter."""
        self._given.append(valid)
        try:
            yield
        finally:
            self._given.pop()

    def vector(self, values) -> Vector:
        return tuple(self.name(v) for v in values)

    def dot(self, a: Vector, b: Vector) -> Node:
        return self.name(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])

    def cross(self, a: Vector, b: Vector) -> Vector:
        return self.vector((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))

    def add(self, a: Vector, b: Vector) -> Vector:
        return self.vector(x + y for x, y in zip(a, b))

    def sub(self, a: Vector, b: Vector) -> Vector:
        return self.vector(x - y for x, y in zip(a, b))

    def scaled(self, a: Vector, factor: Node) -> Vector:
        return self.vector(factor * x for x in a)

    def rot(self, k: Vector, c: Node, s: Node, v: Vector) -> Vector:
        """v turned about the unit axis k by the angle whose cosine and sine are c and s (Rodrigues)."""
        kxv = self.cross(k, v)
        kv = self.name(self.dot(k, v) * (1 - c))
        return self.vector(v[i] * c + kxv[i] * s + k[i] * kv for i in range(3))

    def turn(self, k: Vector, angle: Angle, v: Vector, back: bool = False) -> Vector:
        """v turned about k by `angle` (by -angle when `back`)."""
        return self.rot(k, angle.c, -angle.s if back else angle.s, v)

    def angle(self, c: Node, s: Node) -> Angle:
        c, s = self.name(c), self.name(s)
        return Angle(self.graph.call("atan2", s, c), c, s)

    def clamped_sqrt(self, value: Node) -> Node:
        """sqrt(value), 0 where value is not positive (a root the target does not allow)."""
        g = self.graph
        return g.select(g.relation(">", value, g.number(0)), g.sqrt(value), g.number(0))

    def perpendicular(self, p: Vector, k: Vector) -> Vector:
        """The part of p perpendicular to the unit axis k. Angles about k are read from it,
        never from p . q - (k . p)(k . q): near the axis that difference cancels to rounding
        noise, where the parts themselves keep their digits."""
        kp = self.dot(k, p)
        return self.vector(p[i] - kp * k[i] for i in range(3))

    def sp1(self, p: Vector, q: Vector, k: Vector) -> Angle:
        """SP1: the angle turning p into q about the unit axis k (least squares when they
        differ in length or height along k); 0 when p or q lies on the axis (any angle would do:
        the product of their distances from it below sqrt(TINY) times |p| |q|)."""
        g = self.graph
        zero, one = g.number(0), g.number(1)
        p_perp, q_perp = self.perpendicular(p, k), self.perpendicular(q, k)
        x = self.dot(p_perp, q_perp)
        y = self.dot(k, self.cross(p_perp, q_perp))
        rr = self.name(x * x + y * y)
        pq = self.name(self.dot(p, p) * self.dot(q, q))
        self._margin(lambda: self._product_margin(p_perp, q_perp))
        free = g.relation("<=", rr, self.tiny * pq)
        scale = self.name(g.select(free, one, 1 / g.sqrt(rr)))  # never 1/0, even for constant vectors
        return Angle(g.select(free, zero, g.call("atan2", y, x)), self.name(g.select(free, one, x * scale)),
                     self.name(g.select(free, zero, y * scale)))

    def sp4(self, h: Vector, p: Vector, k: Vector, d: Node, across: Node | None = None,
            spread: Node | None = None, fold_margin: bool = True,
            between: tuple[Vector, Vector] | None = None) -> tuple[Root, Root]:
        """SP4: the angles t with h . rot(k, t) p = d, (phi + alpha, phi - alpha), for unit h
        and k.

        h . rot(k, t) p = A cos t + B sin t + C. Two roots within sqrt(EPS) of each other
        (sin(alpha)^2 within EPS of 0) are one double root: the first, phi + alpha, alpha kept
        as it is (it is not rounded to 0: a wrist near its singularity needs it); when the left
        side does not depend on t, the first root is 0 if it equals d.

        `across`, when the caller knows it, is |h x x|^2 for a vector x with |x| = |p| and
        h . x = d (the direction that the rotation about k and one about h carry p to). Then
        sin(alpha)^2 = (|h x k|^2 across - (k . p - (h . k) d)^2) / (A^2 + B^2), which keeps
        its digits where alpha is small and an error in it moves the pose to first order (a
        wrist axis nearly parallel to h); 1 - cos(alpha)^2 would leave alpha only
        sqrt(rounding) ~ 1e-8. `spread` is (A^2 + B^2) sin(alpha)^2 itself, where the caller
        has a form without cancellation (`sp3`, which records the margin of its fold itself).
        `between`, for the certificate, is the pair of unit vectors whose angle d is the cosine of,
        where h, p are unit vectors too."""
        g = self.graph
        zero, one = g.number(0), g.number(1)
        hk, kp = self.dot(h, k), self.dot(k, p)
        h_perp, p_perp = self.perpendicular(h, k), self.perpendicular(p, k)
        a = self.dot(h_perp, p_perp)
        b = self.dot(h, self.cross(k, p_perp))
        rhs = self.name(d - hk * kp)
        r2 = self.name(a * a + b * b)
        scale = self.name(self.dot(h, h) * self.dot(p, p))
        self._margin(lambda: self._product_margin(h_perp, p_perp))
        if fold_margin and between is not None:  # d = cos(b), b within the range of the angles of h to rot(k, t) p
            self._margin(lambda: self._angle_margin(*between, h, p, k))
        constant = g.relation("<=", r2, self.tiny * scale)
        inverse_r = self.name(g.select(constant, one, 1 / g.sqrt(r2)))
        cos_phi, sin_phi = self.name(a * inverse_r), self.name(b * inverse_r)
        cos_alpha = self.name(rhs * inverse_r)
        if spread is None and across is not None:
            hxk = self.cross(h, k)
            spread = self.dot(hxk, hxk) * across - (kp - hk * d)**2
        disc = self.name(1 - cos_alpha**2 if spread is None else spread * inverse_r**2)
        two, real = g.relation(">", disc, self.eps), g.relation(">", disc, zero)
        # beyond a double root (cos(alpha) = +-1 to rounding): sin(alpha) = 0
        cos_alpha = self.name(g.select(real, cos_alpha, g.select(g.relation(">", cos_alpha, zero), one, -one)))
        sin_alpha = self.name(self.clamped_sqrt(disc))
        phi, alpha = self.name(g.call("atan2", b, a)), self.name(g.call("atan2", sin_alpha, cos_alpha))
        plus = Angle(self.name(g.select(constant, zero, phi + alpha)),
                     self.name(g.select(constant, one, cos_phi * cos_alpha - sin_phi * sin_alpha)),
                     self.name(g.select(constant, zero, sin_phi * cos_alpha + cos_phi * sin_alpha)))
        minus = Angle(self.name(phi - alpha), self.name(cos_phi * cos_alpha + sin_phi * sin_alpha),
                      self.name(sin_phi * cos_alpha - cos_phi * sin_alpha))
        plus_valid = g.logic(OR, g.logic(AND, constant, g.relation("<=", rhs**2, self.eps * scale)),
                             g.logic(AND, g.negation(constant), g.relation(">=", disc, -self.eps)))
        roots = Root(plus, plus_valid), Root(minus, g.logic(AND, g.negation(constant), two))
        if fold_margin and between is None:
            self._margin(lambda: self._fold_margin(h_perp, p_perp, rhs, roots))
        return roots

    def sp3(self, p: Vector, q: Vector, k: Vector, d: Vector) -> tuple[Root, Root]:
        """SP3: the angles t with |rot(k, t) p - q| = |d| (p, q relative to a point of the axis).

        Across k, the distances |p_perp|, |q_perp| from the axis and c, the one asked between
        the two points, are a triangle, and (A^2 + B^2) sin(alpha)^2 is 4 times its area squared
        (Heron's product): it keeps its digits where c is small (a folded arm whose two links
        are equal, a target near the base), where 1 - cos(alpha)^2 would lose them."""
        p_perp, q_perp = self.perpendicular(p, k), self.perpendicular(q, k)
        a, b = self.norm(p_perp), self.norm(q_perp)
        dd, height = self.dot(d, d), self.name(self.dot(k, p) - self.dot(k, q))
        c = self.name(self.clamped_sqrt(self.name(dd - height**2)))
        spread = self.name((c - a + b) * (c + a - b) * (a + b - c) * (a + b + c) / 4)
        roots = self.sp4(q, p, k, self.name((self.dot(p, p) + self.dot(q, q) - dd) / 2), spread=spread,
                         fold_margin=False)
        self._margin(lambda: self._triangle_margin(a, b, c, (d, p, q), height, roots))
        return roots

    def _triangle_margin(self, a: Node, b: Node, c: Node, moving: tuple[Vector, Vector, Vector], height: Node,
                         roots: tuple[Root, Root]) -> tuple:
        """SP3's c's distance from a + b and from |a - b|: two roots where positive, none where
        negative. c = sqrt(|d|^2 - height^2) moves by |d| / c times d's move, and by |height| / c
        times p's and q's, which move a and b by at most their own. 1 - cos(half-gap) is
        (a + b - c)(a + b + c) / 2ab or (c - |a - b|)(c + |a - b|) / 2ab, and (A cos, A sin) of
        the midpoint, A = ab, moves by at most max(a, b) times p's and q's moves."""
        g = self.graph
        d, p, q = moving
        signed = self.name(least(g, a + b - c, c - g.call("Abs", a - b)))

        def sheet(radius):
            lower = least(g, a, b) - 2 * radius  # the shorter side over the ball, at least
            bound = (signed + 2 * radius) * (a + b + c + 6 * radius) / (2 * (a - 2 * radius) * (b - 2 * radius))
            return bound, 2 * radius / lower, g.relation(">", lower, g.number(0))
        slope = 1 + g.call("Abs", height) / c
        return (g.call("Abs", signed), [(self.norm(d) / c, d), (slope, p), (slope, q)],
                self._angle_fold(signed, roots, sheet))

    def sp2(self, p: Vector, q: Vector, k1: Vector, k2: Vector) -> tuple[tuple[Angle, Angle, Node], ...]:
        """SP2: the angle pairs (t1, t2, valid) with rot(k1, t1) rot(k2, t2) p = q, for two axes
        through one point (p, q relative to it): rot(k2, t2) p = rot(k1, -t1) q = c,
        c = alpha k1 + beta k2 +- gamma k1 x k2. One pair when gamma^2 is within EPS |p|^2 of 0
        (gamma kept as it is, as alpha in `sp4`)."""
        g = self.graph
        k12 = self.dot(k1, k2)
        nn = self.name(1 - k12**2)
        u, v = self.dot(k1, q), self.dot(k2, p)
        alpha, beta = self.name((u - k12 * v) / nn), self.name((v - k12 * u) / nn)
        pp = self.dot(p, p)
        # nn gamma^2 = |c|^2 - |alpha k1 + beta k2|^2 = |k1 x q|^2 - nn beta^2 = |k2 x p|^2 - nn alpha^2
        # (c turns into q about k1 and from p about k2). The smaller cross product is the form that
        # keeps its digits where q nears k1 or p nears k2 (a wrist near its singularity, two axes
        # lining up), where |p|^2 - u^2 - ... would leave gamma only sqrt(rounding) ~ 1e-8.
        k1q, k2p = self.cross(k1, q), self.cross(k2, p)
        q_across, p_across = self.dot(k1q, k1q), self.dot(k2p, k2p)
        gg = self.name(g.select(g.relation("<", p_across, q_across), p_across - nn * alpha**2,
                                q_across - nn * beta**2) / nn)
        two = g.relation(">", gg, self.eps * pp)
        gamma = self.name(self.clamped_sqrt(gg))
        normal = self.cross(k1, k2)
        roots = [(self.vector(alpha * k1[i] + beta * k2[i] + sign * gamma * normal[i] for i in range(3)), valid)
                 for sign, valid in ((1, g.relation(">=", gg, -self.eps * pp)), (-1, two))]
        # c exists where rot(k2, t2) p can make the angle of q with k1 (SP4 for t2)
        self._margin(lambda: self._cones_margin(k1, q, p, k2, gamma, tuple(c for c, _ in roots), two))
        pairs = []
        for c, valid in roots:
            with self.given(valid):
                pairs.append((self.sp1(c, q, k1), self.sp1(p, c, k2), valid))
        return tuple(pairs)

    def wrist(self, a: Vector, b: Vector, h4: Vector, h5: Vector, h6: Vector, v6: Vector,
              flip: Node | None) -> tuple[tuple[tuple[Node, ...], Node], ...]:
        """Spherical wrist: the angles ((q4, q5, q6), valid) with R4 R5 R6 h6 = a and
        R4 R5 R6 v6 = b (v6 perpendicular to h6): SP2 for (q4, q5), SP1 for q6.

        With axis 5 perpendicular to axes 4 and 6, `flip` = -2 angle(h4 -> h6 about h5) and
        the second solution is (q4 + pi, flip - q5, q6 + pi): rot(h4, pi) reflects the plane
        perpendicular to h5 across h4."""
        pairs = self.sp2(h6, a, h4, h5)
        solutions = []
        for t4, t5, valid in pairs[:1] if flip is not None else pairs:
            with self.given(valid):
                t6 = self.sp1(v6, self.turn(h5, t5, self.turn(h4, t4, b, back=True), back=True), h6)
            solutions.append(((t4.theta, t5.theta, t6.theta), valid))
        if flip is not None:
            (t4, t5, t6), _ = solutions[0]
            solutions.append(((t4 + sympy.pi, flip - t5, t6 + sympy.pi), pairs[1][2]))
        return tuple(solutions)


def _within(g: Graph, x: Node, low: float, high: float) -> Node:
    """x clamped to [low, high] (low where x is NaN)."""
    return g.select(g.relation(">", x, g.number(high)), g.number(high), g.relation(">", x, g.number(low)), x,
                    g.number(low))


def least(g: Graph, a: Node, b: Node) -> Node:
    return g.select(g.relation("<=", a, b), a, b)


def greatest(g: Graph, a: Node, b: Node) -> Node:
    return g.select(g.relation(">=", a, b), a, b)


def relative(sp: Subproblems, T, rotation, position):
    """T T(0)^-1 = exp(xi_1 q_1) ... exp(xi_n q_n) as (rows of R, t), T(0) = (rotation,
    position) the tool pose at q = 0."""
    R = [sp.vector(sum(T[i, k] * rotation[j, k] for k in range(3)) for j in range(3)) for i in range(3)]
    t = sp.vector(T[i, 3] - sum(R[i][k] * position[k] for k in range(3)) for i in range(3))
    return R, t


def times(sp: Subproblems, R, v: Vector) -> Vector:
    """R v for R given by its rows."""
    return tuple(sp.dot(row, v) for row in R)


def times_transposed(sp: Subproblems, R, v: Vector) -> Vector:
    """R^T v for R given by its rows."""
    return sp.vector(sum(R[k][i] * v[k] for k in range(3)) for i in range(3))


def _in_range(angle: Node) -> bool:
    """An atan2, a number in (-pi, pi], or a select of such."""
    if angle.kind == SELECT:
        return all(_in_range(value) for value in angle.args[1::2] + angle.args[-1:])
    return (angle.kind == CALL and angle.value == "atan2") or (angle.kind == NUMBER and -sympy.pi < angle.value <= sympy.pi)


def wrapped(angle: Node) -> Node:
    """The angle wrapped into (-pi, pi]: unchanged when it is there by construction (an
    atan2), else angle - 2 pi ceil((angle - pi) / (2 pi))."""
    if _in_range(angle):
        return angle
    return angle - 2 * sympy.pi * angle.graph.call("Ceiling", (angle - sympy.pi) / (2 * sympy.pi))
