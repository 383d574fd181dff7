"""Inverse differential kinematics on the value graph: the fixed-size solve of velocity_ik,
the step of ik_numeric, the rotation vector of a pose error.

Written once and printed for every backend like fk; built with nodes' arithmetic and the
graph's functions (`graph.py`), each intermediate value named (`Lowering.name_node`) as the
chain's are, so that the common-subexpression elimination sees sums of named values. The k x k system (k = min(m, n)) is
solved by Householder QR, which is backward stable without pivoting, so the code has no
branch: a zero column is a select, not an `if`. The system counts as singular when a
diagonal entry of R is at most RANK times the Frobenius norm of the system (R's smallest
diagonal entry bounds its smallest singular value from above), or when an input is not
finite; then q_dot is 0.
"""

from typing import Callable

import numpy
import sympy

from jacgen.model.graph import Graph, elementwise
from jacgen.model.node import AND, OR, Node
from jacgen.model.tolerance_symbols import RANK
from jacgen.tolerances import IK_NUMERIC_DEFAULT

# Statuses of velocity_ik, the same in every backend.
VELOCITY_IK_OK, VELOCITY_IK_SINGULAR, VELOCITY_IK_NOT_FINITE = 0, 1, 2

# ik_numeric: the loop each language's template writes around ik_numeric_step (its step, built
# below), one source for its statuses, defaults and damping in every backend and in c_library.py.
IK_NUMERIC_STATUSES = (
    ("CONVERGED", 0, "|error| <= tol"),
    ("ITERATION_LIMIT", 1, "max_iter steps tried, |error| still above tol"),
    ("STALLED", 2, "no step lowers |error|^2 by a millionth: out of reach, joint limit or local minimum"),
    ("INVALID", 3, "target or q0 not finite, or max_iter < 0: q = q0"),
)
IK_NUMERIC_DEFAULTS = {"max_iter": 100, "tol": IK_NUMERIC_DEFAULT}
# CasADi's ik_numeric takes this many steps (a fixed graph; the C and numpy stop when done).
IK_NUMERIC_ITERATIONS = 100
# A bound on the operations of one ik_numeric call of the default length (100 steps).
IK_NUMERIC_OPERATIONS = 100 * 3 * 1_000
# The Levenberg-Marquardt damping (added to the diagonal): start, least, most.
IK_NUMERIC_DAMPING = {"start": 1e-6, "min": 1e-12, "max": 1e8}
# A step lowers the error when it lowers |error|^2 by more than this fraction of it. Toward a
# target out of reach the steps lower it ever less without end (the ur5 100 m out: still by
# 3e-6 after 40 steps, 8e-8 after 800): the damping then rises, and the loop stalls.
IK_NUMERIC_PROGRESS = 1e-6


def named(name: Callable, value: Node) -> Node:
    """`value` named, unless it is a symbol or number already (where the graph folded a zero)."""
    return name(value) if value.args else value


def triangulate(A, g: Graph, name: Callable, right=()) -> tuple[list, list, list, list]:
    """Householder QR of the p x k matrix A (rows of nodes, p >= k): R (k x k, upper triangular,
    as rows), Q^T applied to each column of `right` (p long), the norms of the reflected
    columns (|R_jj|), and the reflections (v, beta), H_j = I - beta v v^T acting on rows j..p-1,
    A = H_0 ... H_{k-1} [R; 0]. alpha = R_jj takes the sign that avoids cancellation.

    v is scaled to v_0 = 1 (LAPACK's dlarfg): v_i = x_i / (x_0 - alpha), at most 1, and
    beta = 1 + |x_0| / |x| in [1, 2]. The unscaled 2 / |x - alpha e_0|^2 overflows for a column
    of norm below 1e-19 in float; these do not: |x| is 0 or at least the square root of the
    least subnormal, so neither division overflows."""
    p, k = len(A), len(A[0])
    zero, one = g.number(0), g.number(1)
    A, right = [list(row) for row in A], [list(column) for column in right]
    norms, reflections = [], []
    for j in range(k):
        column = [A[i][j] for i in range(j, p)]
        norm = name(g.sqrt(sum(c**2 for c in column)))
        reflected = g.relation(">", norm, zero)
        alpha = named(name, -g.select(g.relation(">=", column[0], zero), one, -one) * norm)  # R[j][j]; the sign
        scale = name(g.select(reflected, 1 / (column[0] - alpha), zero))
        v = [one] + [named(name, c * scale) for c in column[1:]]
        beta = name(g.select(reflected, 1 + g.call("Abs", column[0]) / norm, zero))
        for c in range(j + 1, k):
            s = name(beta * sum(v[i - j] * A[i][c] for i in range(j, p)))
            for i in range(j, p):
                A[i][c] = named(name, A[i][c] - s * v[i - j])
        for b in right:
            s = name(beta * sum(v[i - j] * b[i] for i in range(j, p)))
            for i in range(j, p):
                b[i] = named(name, b[i] - s * v[i - j])
        A[j][j] = alpha
        norms.append(norm)
        reflections.append((v, beta))
    return [[A[i][c] if c >= i else zero for c in range(k)] for i in range(k)], right, norms, reflections


def householder_solve(A, b, g: Graph, name: Callable) -> tuple[list, Node]:
    """x with A x = b (nodes), and whether A is numerically singular (see the module's rule)."""
    k = len(A)
    zero = g.number(0)
    scale = name(g.sqrt(sum(e**2 for row in A for e in row)))  # |A|_F, kept by the reflections
    R, (b,), norms, _ = triangulate(A, g, name, [b])
    x = [zero] * k
    for j in reversed(range(k)):
        x[j] = name(g.select(g.relation("!=", R[j][j], zero),
                             (b[j] - sum((R[j][c] * x[c] for c in range(j + 1, k)), zero)) / R[j][j], zero))
    return x, g.logic(OR, *(g.relation("<=", norm, g.symbol(RANK) * scale) for norm in norms))


def symmetric_solve(A, b, g: Graph, name: Callable, call: Callable) -> tuple[list, Node]:
    """householder_solve of a symmetric A (a Gram matrix), as the kernel symmetric_solve{k}
    (`call`: `Lowering.called`): each generated file writes it once, and every such k x k
    system of its functions calls it with A's upper triangle."""
    k = len(A)
    upper = [(r, c) for r in range(k) for c in range(r, k)]
    index = {pair: n for n, pair in enumerate(upper)}

    def step(values: list[Node]) -> list[Node]:
        rows = [[values[index[min(r, c), max(r, c)]] for c in range(k)] for r in range(k)]
        x, singular = householder_solve(rows, values[len(upper):], g, name)
        return x + [g.select(singular, g.number(1), g.number(0))]

    values = call(f"symmetric_solve{k}", f"the solution x of a symmetric {k} x {k} system A x = b (A's upper "
                  "triangle) by Householder QR, and 1 where A is numerically singular", step,
                  [A[r][c] for r, c in upper] + list(b))
    return values[:k], g.relation(">", values[k], g.number(0))


def velocity_ik(js: sympy.Matrix, q: list, mu_dot: list, damping: sympy.Symbol, g: Graph,
                name: Callable, call: Callable, z: list | None = None) -> tuple[list, Node]:
    """q_dot solving Js q_dot = mu_dot (Js at q) and the status; with joint rates `z`, plus
    their projection onto the null space of Js, (I - Js# Js) z.

    m = n: Js^-1 mu_dot for damping 0, else Js^T (Js Js^T + damping^2 I)^-1 mu_dot (both
    computed, one selected); m < n: Js^T (Js Js^T + damping^2 I)^-1 mu_dot; m > n:
    (Js^T Js + damping^2 I)^-1 Js^T mu_dot. The null space of a square or tall Js is
    {0}: there z changes nothing. For m < n, Js# mu_dot + (I - Js# Js) z is
    Js# (mu_dot - Js z) + z: one solve of the same system."""
    m, n = js.shape
    js, q, mu_dot, damping = elementwise(name, g.values(js)), g.values(q), g.values(mu_dot), g.value(damping)
    z = None if z is None else g.values(z)
    k = min(m, n)
    gram = elementwise(name, js @ js.T if m <= n else js.T @ js) + numpy.eye(k, dtype=int) * damping**2
    moved = z is not None and m < n  # the self-motion's task velocity, taken out of the solve
    rhs = (list(elementwise(name, mu_dot - js @ z)) if moved else list(mu_dot)) if m <= n \
        else list(elementwise(name, js.T @ mu_dot))
    x, singular = symmetric_solve(gram.tolist(), rhs, g, name, call)
    q_dot = list(elementwise(name, js.T @ numpy.array(x, dtype=object))) if m <= n else x
    if moved:
        q_dot = [name(rate + zi) for rate, zi in zip(q_dot, z)]
    if m == n:
        direct, direct_singular = householder_solve(js.tolist(), list(mu_dot), g, name)
        damped = g.relation(">", damping, g.number(0))
        q_dot = [g.select(damped, a, b) for a, b in zip(q_dot, direct)]
        singular = g.logic(OR, g.logic(AND, damped, singular), g.logic(AND, g.negation(damped), direct_singular))
    inputs = [*q, *mu_dot, damping, *js.flat, *(() if z is None else z)]
    finite = g.logic(AND, g.finite(name(sum(inputs))), g.relation(">=", damping, g.number(0)))
    status = g.select(g.negation(finite), g.number(VELOCITY_IK_NOT_FINITE),
                      g.select(singular, g.number(VELOCITY_IK_SINGULAR), g.number(VELOCITY_IK_OK)))
    ok = g.logic(AND, finite, g.negation(singular))
    return [g.select(ok, e, g.number(0)) for e in q_dot], status


def rotation_vector(E, g: Graph, name: Callable) -> list[Node]:
    """The rotation vector (axis times angle in [0, pi]) of the rotation matrix E.

    Away from a half turn it is v angle / sin(angle), v the axial vector of (E - E^T) / 2;
    near one (sin(angle) <= 1e-6 with cos(angle) <= 0) v vanishes and the axis is the
    column of (E + I) / 2 = u u^T with the largest diagonal entry (the first of equals),
    signed along v. Both are computed; a select takes one."""
    E = elementwise(name, g.values(E))
    v = [name((E[2, 1] - E[1, 2]) / 2), name((E[0, 2] - E[2, 0]) / 2), name((E[1, 0] - E[0, 1]) / 2)]
    cos = name((E[0, 0] + E[1, 1] + E[2, 2] - 1) / 2)
    sin = name(g.sqrt(v[0]**2 + v[1]**2 + v[2]**2))
    angle = name(g.call("atan2", sin, cos))
    regular = g.logic(OR, g.relation(">", sin, g.value(1e-6)), g.relation(">", cos, g.number(0)))
    scale = name(g.select(g.relation(">", sin, g.number(0)), angle / sin, g.number(1)))
    first = [g.logic(AND, g.relation(">=", E[0, 0], E[1, 1]), g.relation(">=", E[0, 0], E[2, 2])),
             g.relation(">=", E[1, 1], E[2, 2])]
    column = [name(g.select(first[0], (E[i, 0] + int(i == 0)) / 2,
                            g.select(first[1], (E[i, 1] + int(i == 1)) / 2, (E[i, 2] + int(i == 2)) / 2)))
              for i in range(3)]
    length = name(g.sqrt(column[0]**2 + column[1]**2 + column[2]**2))
    sign = name(g.select(g.relation(">=", column[0] * v[0] + column[1] * v[1] + column[2] * v[2], g.number(0)),
                         g.number(1), g.number(-1)))
    return [name(g.select(regular, scale * v[i], sign * angle * column[i] / length)) for i in range(3)]


def ik_numeric_step(error: list, jacobian: sympy.Matrix, q: list, damping: sympy.Symbol, limits: list,
                    g: Graph, name: Callable, call: Callable) -> tuple[list, Node]:
    """One damped least-squares step on the task error e at q: (clamp(clamp(q) + step), |e|^2),
    the step J^T (J J^T + damping I)^-1 e (m <= n) or (J^T J + damping I)^-1 J^T e,
    the joints clamped to `limits` ((low, high), None: none). `error` and `jacobian` are
    those of clamp(q), which the caller substitutes."""
    m, n = jacobian.shape
    jacobian, error = elementwise(name, g.values(jacobian)), elementwise(name, g.values(error))
    damping = g.value(damping)
    if m <= n:
        gram = elementwise(name, jacobian @ jacobian.T) + numpy.eye(m, dtype=int) * damping
        x, _ = symmetric_solve(gram.tolist(), list(error), g, name, call)
        step = list(jacobian.T @ numpy.array(x, dtype=object))
    else:
        gram = elementwise(name, jacobian.T @ jacobian) + numpy.eye(n, dtype=int) * damping
        step, _ = symmetric_solve(gram.tolist(), list(elementwise(name, jacobian.T @ error)), g, name, call)
    trial = [clamp(name(g.value(qi) + si), bounds, g) for qi, si, bounds in zip(q, step, limits)]
    return trial, name(sum(e**2 for e in error))


def flagged_cost(cost: Node, inputs: list, g: Graph, name: Callable) -> Node:
    """The cost, or -1 when an input is not finite (a clamp would hide an infinite joint)."""
    return g.select(g.finite(name(sum(g.values(inputs)))), cost, g.number(-1))


def clamp(value, bounds, g: Graph) -> Node:
    """value limited to bounds = (low, high), or unchanged for None."""
    value = g.value(value)
    if bounds is None:
        return value
    low, high = (g.value(float(b)) for b in bounds)
    return g.select(g.relation("<", value, low), low, g.select(g.relation(">", value, high), high, value))
