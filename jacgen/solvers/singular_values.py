"""Singular values and vectors on the value graph: a Householder QR
(`differential.triangulate`), then one-sided Jacobi rotations on the triangular factor: a
sweep of them is a kernel (`Lowering.repeated`) that the generated code runs in a loop, and
from 4 x 4 on, a round of its rotations is a kernel that the sweep runs in a loop.

Both steps are backward stable on the matrix itself, so every singular value is accurate to a
few roundings of its largest one, also where the smallest is 1e-8 or 0: the eigenvalues of
J J^T, which MoveIt's metrics and Robotics Toolbox's ellipsoids take, lose half the digits
there, because squaring does. The QR first makes the Jacobi's matrix k x k (k = min(rows,
cols)) and nearly diagonal in its columns' norms.

A sweep rotates every pair of columns once, in rounds of disjoint pairs (`rounds`), and
Jacobi converges quadratically: once the error is small, each sweep squares it. `SWEEPS` are
run, with no test, one more than the first count that reached rounding on every kind of
matrix `bench/bench_jacobi_sweeps.py` tries (singular values random, spread over 1e-8 ... 1,
one of 1e-16 ... 1e-6, clustered within 1e-12 ... 1e-2, two zeros; 2,000 of each for k = 3,
500 for k = 6). The worst error relative to the largest value, after each sweep: turning R's
columns, k = 3: 4e-2, 7e-7, 1e-15 after sweeps 2, 3, 4. Turning its rows, k = 3: 4e-3, 1e-12,
1e-15 after sweeps 2, 3, 4; k = 6: 2e-3, 2e-7, 4e-11, 2e-15 after sweeps 3, 4, 5, 6. The extra
sweep squares an error already at rounding: the margin for a matrix slower than those.
"""

from typing import Callable

from jacgen.model.graph import Graph
from jacgen.model.node import OR, Node
from jacgen.model.tolerance_symbols import RANK
from jacgen.solvers.differential import named, triangulate

# Sweeps of the one-sided Jacobi by the size k of the triangular factor R, rotating R's columns
# (the singular vectors: velocity_ellipsoid) or, faster, its rows (the values alone:
# condition_number; a 3 x n block's R is 3 x 3). A 2 x 2 is diagonal after its one rotation;
# 3 and 6 as measured (the module's docstring), 4 and 5 as 6.
SWEEPS = {"columns": {1: 0, 2: 1, 3: 5}, "rows": {1: 0, 2: 1, 3: 5, 4: 7, 5: 7, 6: 7}}

# From this k on, a sweep runs its rounds as a kernel of their own, in a loop: a 6 x 6 sweep
# written out is 15 rotations (the M4F's condition_number: 12.9 KB of flash, 5.7 KB as rounds).
# A round of 3 x 3 matrices rotates one pair of each, beside a state of 42 values that the loop
# carries: as rounds, velocity_ellipsoid took 18 % more instructions on the M4F, so a 3 x 3
# sweep writes its 3 rounds out.
ROUND_KERNEL = 4


def round_pairs(k: int) -> list[tuple[int, int]]:
    """The disjoint pairs of slots that every round of a sweep over k columns rotates (the
    circle method of a round-robin tournament, with the columns moved between rounds by
    `next_round`): k even, slot 0 stays and is paired with k - 1, 1 with k - 2, ...; k odd,
    every slot moves and the last one sits a round out."""
    fixed = 1 - k % 2
    return [(i, k - 2 + fixed - i) for i in range(k // 2)]


def next_round(slots: list) -> list:
    """The slots' contents in the next round's places: the circle method's turn, every slot but a
    fixed first one (k even) one place on, the last to the front. After `len(rounds(k))` turns
    every column is back in its own slot."""
    fixed = 1 - len(slots) % 2
    return slots[:fixed] + slots[-1:] + slots[fixed:-1]


def rounds(k: int) -> list[list[tuple[int, int]]]:
    """Every pair of k columns once, as k - 1 rounds (k odd: k) of disjoint pairs: a round's
    rotations are independent of each other, so the processor overlaps them, where the cyclic
    order's share a column, one after the other. The generated code runs one round as a kernel
    on fixed slots (`round_pairs`), and moves the columns between rounds (`next_round`)."""
    columns, result = list(range(k)), []
    for _ in range(k - 1 + k % 2):
        result.append([tuple(sorted((columns[i], columns[j]))) for i, j in round_pairs(k)])
        columns = next_round(columns)
    return result


def jacobi(matrices: list, g: Graph, name: Callable, repeat: Callable, vectors: bool
           ) -> list[tuple[list[Node], list | None]]:
    """For each k x k R of `matrices`: the column norms of R V, with V the product of one-sided
    Jacobi rotations that make R's columns orthogonal: the singular values of R (unsorted), and
    V (k x k, as rows) when `vectors`: R's right singular vectors, as its columns. Without
    vectors, the rotations turn R's rows (the columns of R^T, whose singular values are the
    same): that converges faster.

    A sweep is one kernel (`repeat`: `Lowering.repeated`), run SWEEPS times on the state of
    every matrix's turned columns (and V's): the generated code loops over the sweeps, written
    once. From k = ROUND_KERNEL on, a round is a kernel too, which the sweep runs once for each
    of `rounds`: it rotates the pairs of fixed slots (`round_pairs`), then moves the columns to
    the slots of the next round (`next_round`), so that the same code serves every round. The
    matrices are rotated in lockstep, each step for every rotation of the round before the
    next: the step is in the order the values are built, so that the processor finds the
    independent rotations side by side, rather than one rotation's chain of square roots and
    divisions after another's.

    The squared column norms are summed afresh at the start of each sweep, carried through its
    rounds and updated by each rotation: an update a - t c carries an error of a rounding of a,
    which stalls the convergence of two close values far below it where they came out of larger
    columns (sigma 1.02e-8 and 1.01e-8 beside 0.98, updated only: by 15 % a sweep, still 4e-12
    off after 8). Within a sweep, the updates of small columns are from small values."""
    zero, one = g.number(0), g.number(1)
    k, many = len(matrices[0]), len(matrices)
    turned = [[[R[r][c] for r in range(k)] for c in range(k)] if vectors else [list(row) for row in R]
              for R in matrices]
    V = [[[one if r == c else zero for r in range(k)] for c in range(k)] for _ in matrices] if vectors else []

    def turn(state: list[Node]) -> list[Node]:
        """One round: the rotations of `round_pairs`, then the columns and their squares moved
        to the next round's slots."""
        blocks, sums = _blocks(state[:-many * k], k), state[-many * k:]
        turned, V = blocks[:many], blocks[many:]
        squares = [sums[m * k:(m + 1) * k] for m in range(many)]
        work = [(m, i, j) for m in range(many) for i, j in round_pairs(k)]
        products = [named(name, sum(x * y for x, y in zip(turned[m][i], turned[m][j]))) for m, i, j in work]
        angles = [rotation(squares[m][i], squares[m][j], c, g, name) for (m, i, j), c in zip(work, products)]
        for (m, i, j), c, (cos, t) in zip(work, products, angles):
            a, b = squares[m][i], squares[m][j]
            squares[m][i], squares[m][j] = named(name, a - t * c), named(name, b + t * c)
            sin = named(name, cos * t)
            for columns in [turned[m]] + ([V[m]] if vectors else []):
                x, y = columns[i], columns[j]
                columns[i] = [named(name, cos * p - sin * r) for p, r in zip(x, y)]
                columns[j] = [named(name, sin * p + cos * r) for p, r in zip(x, y)]
        return _flat([next_round(block) for block in turned + V]) + [e for block in squares for e in next_round(block)]

    def sweep(state: list[Node]) -> list[Node]:
        state = state + [named(name, sum(e**2 for e in column)) for W in _blocks(state, k)[:many] for column in W]
        if k >= ROUND_KERNEL:
            state = repeat(f"jacobi{k}_{kind}_round" + suffix, f"round of Jacobi rotations of {what} (its {kind})",
                           len(rounds(k)), turn, state)
        else:
            for _ in rounds(k):
                state = turn(state)
        return state[:-many * k]

    kind, suffix = ("columns" if vectors else "rows"), (f"_{many}" if many > 1 else "")
    what = f"{many} {k} x {k} matrices" if many > 1 else f"a {k} x {k} matrix"
    state = repeat(f"jacobi{k}_{kind}" + suffix, f"one-sided Jacobi sweep of {what} (its {kind})"
                   + (", with V" if vectors else ""), SWEEPS[kind][k], sweep, _flat(turned + V))
    blocks = _blocks(state, k)
    turned, V = blocks[:many], blocks[many:]
    norms = [[name(g.sqrt(sum(e**2 for e in column))) for column in W] for W in turned]
    return [(s, V and [[V[m][c][r] for c in range(k)] for r in range(k)]) for m, s in enumerate(norms)]


def _flat(blocks: list) -> list[Node]:
    """k x k blocks (lists of columns, or of rows) as one state: block by block, column by column."""
    return [e for block in blocks for column in block for e in column]


def _blocks(state: list[Node], k: int) -> list:
    """`_flat`'s state as its k x k blocks again."""
    return [[state[(b * k + c) * k:(b * k + c + 1) * k] for c in range(k)] for b in range(len(state) // k**2)]


def rotation(a: Node, b: Node, c: Node, g: Graph, name: Callable) -> tuple[Node, Node]:
    """cos and tan of the rotation that makes columns w_i, w_j with a = |w_i|^2, b = |w_j|^2,
    c = w_i . w_j orthogonal, by the smaller angle: t = 2c sign(d) / (|d| + h), with d = b - a
    and h = sqrt(d^2 + 4c^2) (the textbook's zeta = d / 2c overflows where c is tiny; its guard
    took a third square root and a select), and cos = 1 / sqrt(1 + t^2). `jacobi` makes the
    columns cos w_i - sin w_j and sin w_i + cos w_j, and a, b: a - t c, b + t c. (Not
    cos (w_i - t w_j): with that form XLA's fusion blows up, and jax.jit of the Panda's
    condition_number took 112 s at 5 sweeps and over 10 minutes at 7, against 6 s and 5 s.)

    cos is computed from t, so the rotation is orthogonal to a rounding whatever h's accuracy:
    where d^2 + 4c^2 underflows (|d| and |c| below 1e-154, float 1e-19) it is only a worse
    angle. Where d = c = 0 the columns are left as they are (selects of values that stay
    finite, so that the gradients of JAX and PyTorch do too)."""
    zero, one = g.number(0), g.number(1)
    d = named(name, b - a)
    h = named(name, g.sqrt(d**2 + 4 * c**2))
    divisor = named(name, g.call("Abs", d) + h)
    rotated = g.relation(">", divisor, zero)
    t = named(name, g.select(rotated, g.select(g.relation(">=", d, zero), 2 * c, -2 * c)
                             / g.select(rotated, divisor, one), zero))
    return named(name, 1 / g.sqrt(1 + t**2)), t


def singular_values(A: list, g: Graph, name: Callable, repeat: Callable) -> list[Node]:
    """The singular values of the p x k matrix A (rows of nodes, p >= k), unsorted."""
    R, _, _, _ = triangulate(A, g, name)
    return jacobi([R], g, name, repeat, vectors=False)[0][0]


def left_singular_3(matrices: list, g: Graph, name: Callable, repeat: Callable) -> list[tuple[list, list]]:
    """(U, s) of each 3 x n matrix (rows of nodes): the left singular vectors (U's columns, as
    rows of U) and the singular values, descending, 0 past n; U a rotation (det +1, the third
    column's sign chosen), so that it orients an ellipsoid. The matrices' Jacobi run in lockstep.

    A^T = Q R (A^T padded with zero rows to at least 3), so A = R^T Q^T; with R V = W of
    orthogonal columns, R^T = V S W'^T and A's left singular vectors are V's columns."""
    triangles = []
    for A in matrices:
        rows = [[A[r][c] for r in range(3)] for c in range(len(A[0]))]
        rows += [[g.number(0)] * 3] * (3 - len(rows))
        triangles.append(triangulate(rows, g, name)[0])
    return [_sorted_rotation(s, V, g, name) for s, V in jacobi(triangles, g, name, repeat, vectors=True)]


def _sorted_rotation(s: list, V: list, g: Graph, name: Callable) -> tuple[list, list]:
    """V's columns and the values s sorted descending, the third column's sign making V a rotation."""
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
            outside = [R[d][d] for d in range(k) if not i <= d <= j]
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
