"""Js, the Jacobian whose rank loss is a singularity (docs/contract.md §2), and its rank
condition: which rows form it, its maximal minors, and the determinant the generated code
computes (det(Js), or the Gram determinant of a non-square Js).

Js is the task Jacobian, except that a task holding all of roll, pitch and yaw uses the
geometric angular-velocity rows instead (so the Euler-angle singularity at pitch = ±90° is not
mistaken for a kinematic one). The exact analysis (`singularities.py`) expands the same minors
in the joint ring; the generated code expands them on the value graph.
"""

import itertools
import math
from functools import lru_cache

import sympy

from jacgen.inputs.robot import EULER_ANGLES, TASK_COMPONENTS, Robot
from jacgen.model.graph import Graph, elementwise
from jacgen.model.node import Node, is_zero

# The maximal minors of Js (C(n, m) of them) the exact analysis seeks common factors of, and the
# generated Gram determinant sums the squares of; past it, QR (`rank_determinant`).
MINOR_LIMIT = 64


def singularity_rows(robot: Robot) -> tuple[int, ...] | None:
    """Rows of the geometric Jacobian (vx vy vz wx wy wz) forming Js, in task order;
    None when Js is the task Jacobian itself (a task with some but not all Euler angles)."""
    if sum(component in EULER_ANGLES for component in robot.task) in (0, 3):
        return tuple(TASK_COMPONENTS.index(component) for component in robot.task)
    return None


def singularity_jacobian(robot: Robot, jacobian: sympy.Matrix, task_jacobian: sympy.Matrix) -> sympy.Matrix:
    """Js from the geometric and the task Jacobian of one chain."""
    rows = singularity_rows(robot)
    return task_jacobian if rows is None else jacobian.extract(list(rows), list(range(robot.dof)))


def maximal_minors(matrix, zero=0, one=1, times=lambda a, b: a * b) -> list:
    """Every largest square minor of a matrix (list of rows), by Laplace expansion.

    The minors of the lower rows are shared (memoised), so a 6 x 7 matrix costs about 450
    products, and the result is division-free: exact in a ring, and straight-line code
    that stays finite at singular configurations. Wide matrices give one minor per column
    subset, tall ones per row subset, subsets in lexicographic order.
    """
    if len(matrix) > len(matrix[0]):
        matrix = [list(column) for column in zip(*matrix)]
    rows, cols = len(matrix), len(matrix[0])

    @lru_cache(maxsize=None)
    def minor(row: int, columns: tuple[int, ...]):
        if row == rows:
            return one
        total = zero
        for k, c in enumerate(columns):
            if matrix[row][c] != 0:
                term = times(matrix[row][c], minor(row + 1, columns[:k] + columns[k + 1:]))
                total = total - term if k % 2 else total + term
        return total

    return [minor(0, subset) for subset in itertools.combinations(range(cols), rows)]


def rank_determinant(js: sympy.Matrix, graph: Graph, name) -> Node:
    """det(Js) for square Js, else the Gram determinant det(Js Js^T) or det(Js^T Js), on the
    value graph `graph` by Laplace expansion (memoised minors: division-free, at most 6 * 2^5
    products per determinant) over the entries named by `name`: a fixed cost on top of Js,
    whatever the arm.

    The Gram determinant is the sum of the squared maximal minors of Js (Cauchy-Binet)
    while there are at most MINOR_LIMIT of them; beyond, the product of the
    squared diagonal of R in a QR factorisation of the tall one of Js, Js^T (modified
    Gram-Schmidt, whose R is backward stable). Both stay accurate to rounding near a
    singularity, where det(Js Js^T) formed from the product loses half the digits (its
    square root, the manipulability, good only to sqrt(eps) * |Js|^m).
    """
    m, n = js.shape
    g = graph
    if m == n or math.comb(max(m, n), min(m, n)) <= MINOR_LIMIT:
        named = [[0 if is_zero(entry) else entry for entry in row] for row in elementwise(name, g.values(js))]
        minors = maximal_minors(named, g.number(0), g.number(1))
        return minors[0] if m == n else sum(name(minor) ** 2 for minor in minors)
    tall = js.T if m < n else js
    columns = [list(column) for column in elementwise(name, g.values(tall)).T]
    squared_diagonal = []
    for k, column in enumerate(columns):
        norm = name(sum(entry**2 for entry in column))
        squared_diagonal.append(norm)
        divisor = name(g.select(g.relation(">", norm, g.number(0)), norm, g.number(1)))
        for j in range(k + 1, len(columns)):  # the part of column j orthogonal to column k
            share = name(sum(a * b for a, b in zip(columns[j], column)) / divisor)
            columns[j] = [name(entry - share * value) for entry, value in zip(columns[j], column)]
    return g.mul(*squared_diagonal)
