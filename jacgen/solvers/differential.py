"""Inverse differential kinematics as expressions: the fixed-size solve of velocity_ik.

Written once and printed for every backend like fk. The k x k system (k = min(m, n)) is
solved by Householder QR, which is backward stable without pivoting, so the code has no
branch: a zero column is a select, not an `if`. The system counts as singular when a
diagonal entry of R is at most RANK times the Frobenius norm of the system (R's smallest
diagonal entry bounds its smallest singular value from above), or when an input is not
finite; then q_dot is 0.
"""

from typing import Callable

import sympy

from jacgen.model.nodes import RANK, Above, AtLeast, AtMost, Below, IsFinite, Unequal, select
from jacgen.tolerances import IK_NUMERIC_DEFAULT

# Statuses of velocity_ik, the same in every backend.
VELOCITY_IK_OK, VELOCITY_IK_SINGULAR, VELOCITY_IK_NOT_FINITE = 0, 1, 2

# ik_numeric: the loop each language's template writes around ik_numeric_step (its step, built
# below), one source for its statuses, defaults and damping in every backend and in c_library.py.
IK_NUMERIC_STATUSES = (
    ("CONVERGED", 0, "|error| <= tol"),
    ("ITERATION_LIMIT", 1, "max_iter steps tried, |error| still above tol"),
    ("STALLED", 2, "no step lowers |error|: out of reach, joint limit or local minimum"),
    ("INVALID", 3, "target or q0 not finite, or max_iter < 0: q = q0"),
)
IK_NUMERIC_DEFAULTS = {"max_iter": 100, "tol": IK_NUMERIC_DEFAULT}
# CasADi's ik_numeric takes this many steps (a fixed graph; the C and numpy stop when done).
IK_NUMERIC_ITERATIONS = 100
# The Levenberg-Marquardt damping (added to the diagonal): start, least, most.
IK_NUMERIC_DAMPING = {"start": 1e-6, "min": 1e-12, "max": 1e8}


def householder_solve(A: list[list[sympy.Expr]], b: list[sympy.Expr], name: Callable) -> tuple[list, sympy.Basic]:
    """x with A x = b, and whether A is numerically singular (see the module's rule)."""
    k = len(A)
    scale = name(sympy.sqrt(sympy.Add(*(e**2 for row in A for e in row))))  # |A|_F, kept by the reflections
    A, b = [list(row) for row in A], list(b)
    norms = []
    for j in range(k):
        column = [A[i][j] for i in range(j, k)]
        norm = name(sympy.sqrt(sympy.Add(*(c**2 for c in column))))
        alpha = name(-select(AtLeast(column[0], 0), 1, -1) * norm)  # R[j][j]; the sign avoids cancellation
        v = [name(column[0] - alpha)] + column[1:]
        beta = name(select(Above(norm, 0), 1 / (norm * (norm + sympy.Abs(column[0]))), 0))  # 2 / |v|^2
        for c in range(j + 1, k):
            s = name(beta * sympy.Add(*(v[i - j] * A[i][c] for i in range(j, k))))
            for i in range(j, k):
                A[i][c] = name(A[i][c] - s * v[i - j])
        s = name(beta * sympy.Add(*(v[i - j] * b[i] for i in range(j, k))))
        for i in range(j, k):
            b[i] = name(b[i] - s * v[i - j])
        A[j][j] = alpha
        norms.append(norm)
    x = [sympy.Integer(0)] * k
    for j in reversed(range(k)):
        x[j] = name(select(Unequal(A[j][j], 0), (b[j] - sympy.Add(*(A[j][c] * x[c] for c in range(j + 1, k)))) / A[j][j], 0))
    return x, sympy.Or(*(AtMost(norm, RANK * scale) for norm in norms))


def velocity_ik(js: sympy.Matrix, q: list, mu_dot: list, damping: sympy.Symbol,
                name: Callable) -> tuple[list, sympy.Expr]:
    """q_dot solving Js q_dot = mu_dot (Js at q) and the status.

    m = n: Js^-1 mu_dot for damping 0, else Js^T (Js Js^T + damping^2 I)^-1 mu_dot (both
    computed, one selected); m < n: Js^T (Js Js^T + damping^2 I)^-1 mu_dot; m > n:
    (Js^T Js + damping^2 I)^-1 Js^T mu_dot."""
    m, n = js.shape
    js = js.applyfunc(name)
    k = min(m, n)
    gram = (js * js.T if m <= n else js.T * js).applyfunc(name) + damping**2 * sympy.eye(k)
    rhs = list(mu_dot) if m <= n else [name(e) for e in js.T * sympy.Matrix(mu_dot)]
    x, singular = householder_solve(gram.tolist(), rhs, name)
    q_dot = [name(e) for e in js.T * sympy.Matrix(x)] if m <= n else x
    if m == n:
        direct, direct_singular = householder_solve(js.tolist(), list(mu_dot), name)
        damped = Above(damping, 0)
        q_dot = [select(damped, a, b) for a, b in zip(q_dot, direct)]
        singular = sympy.Or(sympy.And(damped, singular), sympy.And(sympy.Not(damped), direct_singular))
    inputs = [*q, *mu_dot, damping, *(e for e in js)]
    finite = sympy.And(IsFinite(name(sympy.Add(*inputs))), AtLeast(damping, 0))
    status = select(sympy.Not(finite), VELOCITY_IK_NOT_FINITE, select(singular, VELOCITY_IK_SINGULAR, VELOCITY_IK_OK))
    ok = sympy.And(finite, sympy.Not(singular))
    return [select(ok, e, 0) for e in q_dot], status


def rotation_vector(E: sympy.Matrix, name: Callable) -> list[sympy.Expr]:
    """The rotation vector (axis times angle in [0, pi]) of the rotation matrix E.

    Away from a half turn it is v angle / sin(angle), v the axial vector of (E - E^T) / 2;
    near one (sin(angle) <= 1e-6 with cos(angle) <= 0) v vanishes and the axis is the
    column of (E + I) / 2 = u u^T with the largest diagonal entry (the first of equals),
    signed along v. Both are computed; a select takes one."""
    v = [name((E[2, 1] - E[1, 2]) / 2), name((E[0, 2] - E[2, 0]) / 2), name((E[1, 0] - E[0, 1]) / 2)]
    cos = name((E[0, 0] + E[1, 1] + E[2, 2] - 1) / 2)
    sin = name(sympy.sqrt(v[0]**2 + v[1]**2 + v[2]**2))
    angle = name(sympy.atan2(sin, cos))
    regular = sympy.Or(Above(sin, sympy.Float(1e-6)), Above(cos, 0))
    scale = name(select(Above(sin, 0), angle / sin, 1))
    first = [sympy.And(AtLeast(E[0, 0], E[1, 1]), AtLeast(E[0, 0], E[2, 2])), AtLeast(E[1, 1], E[2, 2])]
    column = [name(select(first[0], (E[i, 0] + int(i == 0)) / 2, select(first[1], (E[i, 1] + int(i == 1)) / 2,
                                                                       (E[i, 2] + int(i == 2)) / 2))) for i in range(3)]
    length = name(sympy.sqrt(column[0]**2 + column[1]**2 + column[2]**2))
    sign = name(select(AtLeast(column[0] * v[0] + column[1] * v[1] + column[2] * v[2], 0), 1, -1))
    return [name(select(regular, scale * v[i], sign * angle * column[i] / length)) for i in range(3)]


def ik_numeric_step(error: list[sympy.Expr], jacobian: sympy.Matrix, q: list, damping: sympy.Symbol,
                    limits: list, name: Callable) -> tuple[list, list, sympy.Expr]:
    """One damped least-squares step on the task error e at q: (clamp(clamp(q) + step), |e|^2),
    the step J^T (J J^T + damping I)^-1 e (m <= n) or (J^T J + damping I)^-1 J^T e,
    the joints clamped to `limits` ((low, high), None: none). `error` and `jacobian` are
    those of clamp(q), which the caller substitutes."""
    m, n = jacobian.shape
    jacobian = jacobian.applyfunc(name)
    error = [name(e) for e in error]
    if m <= n:
        gram = (jacobian * jacobian.T).applyfunc(name) + damping * sympy.eye(m)
        x, _ = householder_solve(gram.tolist(), error, name)
        step = jacobian.T * sympy.Matrix(x)
    else:
        gram = (jacobian.T * jacobian).applyfunc(name) + damping * sympy.eye(n)
        step, _ = householder_solve(gram.tolist(), [name(e) for e in jacobian.T * sympy.Matrix(error)], name)
    trial = [clamp(name(qi + si), bounds) for qi, si, bounds in zip(q, step, limits)]
    return trial, name(sympy.Add(*(e**2 for e in error)))


def flagged_cost(cost: sympy.Expr, inputs: list, name: Callable) -> sympy.Expr:
    """The cost, or -1 when an input is not finite (a clamp would hide an infinite joint)."""
    return select(IsFinite(name(sympy.Add(*inputs))), cost, -1)


def clamp(value: sympy.Expr, bounds) -> sympy.Expr:
    """value limited to bounds = (low, high), or unchanged for None."""
    if bounds is None:
        return value
    low, high = (sympy.Float(b) for b in bounds)
    return select(Below(value, low), low, select(Above(value, high), high, value))
