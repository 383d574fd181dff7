"""Singular values and vectors on the value graph, as straight-line code: a Householder QR
(`differential.triangulate`), then one-sided Jacobi rotations on the triangular factor.

Both steps are backward stable on the matrix itself, so every singular value is accurate to a
few roundings of its largest one, also where the smallest is 1e-8 or 0: the eigenvalues of
J J^T, which MoveIt's metrics and Robotics Toolbox's ellipsoids take, lose half the digits
there, because squaring does. The QR first makes the Jacobi's matrix k x k (k = min(rows,
cols)) and nearly diagonal in its columns' norms.

A cyclic sweep rotates every pair of columns once, and Jacobi converges quadratically: once
the error is small, each sweep squares it. `SWEEPS` are run, with no test, one more than the
first count that reached rounding on every kind of matrix `bench/bench_jacobi_sweeps.py` tries
(singular values random, spread over 1e-8 ... 1, one of 1e-16 ... 1e-6, clustered within
1e-12 ... 1e-2, two zeros; 2,000 of each for k = 3, 500 for k = 6). The worst error relative
to the largest value, after each sweep: turning R's columns, k = 3: 4e-2, 7e-7, 1e-15 after
sweeps 2, 3, 4; k = 6: 2e-2, 9e-6, 1e-9, 7e-15 after sweeps 4, 5, 6, 7. Turning its rows,
k = 3: 2e-3, 2e-12, 1e-15 after sweeps 2, 3, 4; k = 6: 9e-4, 1e-7, 1e-12, 2e-15 after sweeps
3, 4, 5, 6. The extra sweep squares an error already at rounding: the margin for a matrix
slower than those.
"""

from typing import Callable

from jacgen.model.graph import Graph
from jacgen.model.node import OR, Node
from jacgen.model.tolerance_symbols import RANK
from jacgen.solvers.differential import named, triangulate

# Sweeps of the one-sided Jacobi by the size k of the triangular factor R, rotating R's columns
# (the singular vectors: velocity_ellipsoid) or, faster, its rows (the values alone:
# condition_number). A 2 x 2 is diagonal after its one rotation; 3 and 6 as measured (the
# module's docstring), 4 and 5 as 6.
SWEEPS = {"columns": {1: 0, 2: 1, 3: 5, 4: 8, 5: 8, 6: 8}, "rows": {1: 0, 2: 1, 3: 5, 4: 7, 5: 7, 6: 7}}


def jacobi(R: list, g: Graph, name: Callable, vectors: bool) -> tuple[list[Node], list | None]:
    """The column norms of R V, with V the product of one-sided Jacobi rotations that make R's
    columns orthogonal: the singular values of R (unsorted), and V (k x k, as rows) when
    `vectors`: R's right singular vectors, as its columns. Without vectors, the rotations turn
    R's rows (the columns of R^T, whose singular values are the same): that converges faster.

    A rotation of columns i, j with a = |w_i|^2, b = |w_j|^2, c = w_i . w_j: zeta = (b - a) /
    2c, t = sign(zeta) / (|zeta| + sqrt(1 + zeta^2)) (the smaller angle; for |zeta| >= 1 as
    sign(zeta) |1/zeta| / (1 + sqrt(1 + 1/zeta^2)), which does not overflow), and none where
    c = 0 (selects of divisors that stay finite, so that the gradients of JAX and PyTorch do too).
    It makes a and b a - t c and b + t c, which are kept rather than summed again."""
    k = len(R)
    zero, one = g.number(0), g.number(1)
    W = [[R[r][c] for r in range(k)] for c in range(k)] if vectors else [list(row) for row in R]  # turned
    V = [[one if r == c else zero for r in range(k)] for c in range(k)] if vectors else None
    squares = [name(sum(e**2 for e in column)) for column in W]
    for _ in range(SWEEPS["columns" if vectors else "rows"][k]):
        for i in range(k - 1):
            for j in range(i + 1, k):
                a, b = squares[i], squares[j]
                c = named(name, sum(x * y for x, y in zip(W[i], W[j])))
                rotated = g.relation("!=", c, zero)
                zeta = named(name, (b - a) / g.select(rotated, 2 * c, one))
                sign = g.select(g.relation(">=", zeta, zero), one, -one)
                large = g.relation(">=", g.call("Abs", zeta), one)
                w = named(name, 1 / g.call("Abs", g.select(large, zeta, one)))  # |1 / zeta| where that is <= 1
                small = g.call("Abs", zeta)
                t = named(name, g.select(rotated, sign * g.select(large, w / (1 + g.sqrt(1 + w**2)),
                                                           1 / (small + g.sqrt(1 + small**2))), zero))
                cos = named(name, 1 / g.sqrt(1 + t**2))
                sin = named(name, cos * t)
                squares[i], squares[j] = named(name, a - t * c), named(name, b + t * c)
                pairs = [W] + ([V] if vectors else [])
                for columns in pairs:
                    x, y = columns[i], columns[j]
                    columns[i] = [named(name, cos * p - sin * r) for p, r in zip(x, y)]
                    columns[j] = [named(name, sin * p + cos * r) for p, r in zip(x, y)]
    norms = [name(g.sqrt(sum(e**2 for e in column))) for column in W]
    return norms, V and [[V[c][r] for c in range(k)] for r in range(k)]


def singular_values(A: list, g: Graph, name: Callable) -> list[Node]:
    """The singular values of the p x k matrix A (rows of nodes, p >= k), unsorted."""
    R, _, _, _ = triangulate(A, g, name)
    return jacobi(R, g, name, vectors=False)[0]


def left_singular_3(A: list, g: Graph, name: Callable) -> tuple[list, list]:
    """(U, s) of a 3 x n matrix (rows of nodes): the left singular vectors (U's columns, as rows
    of U) and the singular values, descending, 0 past n; U a rotation (det +1, the third
    column's sign chosen), so that it orients an ellipsoid.

    A^T = Q R (A^T padded with zero rows to at least 3), so A = R^T Q^T; with R V = W of
    orthogonal columns, R^T = V S W'^T and A's left singular vectors are V's columns."""
    rows = [[A[r][c] for r in range(3)] for c in range(len(A[0]))]
    rows += [[g.number(0)] * 3] * (3 - len(rows))
    R, _, _, _ = triangulate(rows, g, name)
    s, V = jacobi(R, g, name, vectors=True)
    columns = [[V[r][c] for r in range(3)] for c in range(3)]
    for i, j in ((0, 1), (1, 2), (0, 1)):  # a sorting network, descending
        swap = g.relation("<", s[i], s[j])
        s[i], s[j] = named(name, g.select(swap, s[j], s[i])), named(name, g.select(swap, s[i], s[j]))
        columns[i], columns[j] = ([named(name, g.select(swap, y, x)) for x, y in zip(columns[i], columns[j])],
                                  [named(name, g.select(swap, x, y)) for x, y in zip(columns[i], columns[j])])
    u, v, w = columns
    determinant = name(u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                       + u[2] * (v[0] * w[1] - v[1] * w[0]))
    flip = g.select(g.relation("<", determinant, g.number(0)), g.number(-1), g.number(1))
    columns[2] = [named(name, flip * e) for e in w]
    return [[columns[c][r] for c in range(3)] for r in range(3)], s


def adjugate_triangular(R: list, g: Graph, name: Callable) -> list:
    """det(R) R^-1 of an upper triangular R, without a division (finite where R is singular):
    entry (i, j) is N_ij times the diagonal entries outside i..j, N_jj = 1 and
    N_ij = -sum_{c = i+1..j} R_ic N_cj R_{i+1,i+1} ... R_{c-1,c-1} (back substitution
    multiplied through by the diagonal)."""
    k = len(R)
    zero, one = g.number(0), g.number(1)
    N = [[one if i == j else zero for j in range(k)] for i in range(k)]
    for j in range(k):
        for i in reversed(range(j)):
            terms, between = [], one
            for c in range(i + 1, j + 1):
                terms.append(R[i][c] * N[c][j] * between)
                between = between * R[c][c]
            N[i][j] = name(-sum(terms))
    adjugate = [[zero] * k for _ in range(k)]
    for i in range(k):
        for j in range(i, k):
            outside = [R[l][l] for l in range(k) if not i <= l <= j]
            adjugate[i][j] = name(N[i][j] * _product(outside, one))
    return adjugate


def _product(factors: list, one: Node) -> Node:
    result = one
    for factor in factors:
        result = result * factor
    return result


def manipulability_gradient(js, layers: list, g: Graph, name: Callable) -> list[Node]:
    """d w / d q_k of w = sqrt(det(Js Js^T)) (|det Js| when square, sqrt(det(Js^T Js)) when tall),
    from the derivatives dJs/dq_k (`layers`, m x n arrays of nodes), finite everywhere.

    With A = Js^T (m <= n) or Js, A = Q R and dA_k the same of dJs/dq_k: w = |det R| and
    dw/dq_k = w tr((A^T A)^-1 A^T dA_k) = |det R| tr(R^-1 Q^T dA_k)
            = sign(det R) sum(dA_k * Q adj(R)^T),
    no division, so it is finite at a singularity too. There |sigma_min| has a kink, and the
    value is 0, the mean of its two one-sided derivatives: wherever velocity_ik's rule finds Js
    singular (a |R_jj| at most RANK |Js|_F), so that rounding does not pick a side."""
    m, n = js.shape
    tall = m > n
    A = (js if tall else js.T).tolist()
    p, k = len(A), len(A[0])
    zero, one = g.number(0), g.number(1)
    scale = name(g.sqrt(sum(e**2 for row in A for e in row)))
    R, _, norms, reflections = triangulate(A, g, name)
    singular = g.logic(OR, *(g.relation("<=", norm, g.symbol(RANK) * scale) for norm in norms))
    Q = [[one if r == c else zero for r in range(p)] for c in range(k)]  # Q's first k columns
    for j, (v, beta) in reversed(list(enumerate(reflections))):
        for c in range(k):
            s = name(beta * sum(v[i - j] * Q[c][i] for i in range(j, p)))
            Q[c] = Q[c][:j] + [name(Q[c][i] - s * v[i - j]) for i in range(j, p)]
    adjugate = adjugate_triangular(R, g, name)
    weights = [[name(sum(Q[a][r] * adjugate[c][a] for a in range(k))) for c in range(k)] for r in range(p)]
    sign = one  # of det R: its diagonal's signs multiplied (no product of values, which may underflow)
    for j in range(k):
        sign = name(g.select(g.relation("<", R[j][j], zero), -sign, sign))
    sign = name(g.select(singular, zero, sign))
    gradient = []
    for layer in layers:
        dA = layer if tall else layer.T
        gradient.append(name(sign * sum(dA[r][c] * weights[r][c] for r in range(p) for c in range(k))))
    return gradient
