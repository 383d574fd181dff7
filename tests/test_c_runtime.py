"""The C runtime helpers of the general 6R solver, compiled with the generated code's warning
flags: templates/runtime/eigenvalues.c against matrices whose eigenvalues are known by
construction (similarity transforms of block-diagonal matrices, companion matrices of
polynomials with given roots, repeated ones included) and against LAPACK;
templates/runtime/general6r.c (the elimination from the equations at a target to the loop
angles) through whole solutions: the configurations its roots complete to reach the pose on
the numpy reference, the generating one among them, as many as numpy's eigensolver gives; its tables are those of jacgen/solvers/general6r.py."""

import ctypes
import math

import numpy as np
import pytest

from jacgen.solvers import general6r
from jacgen.checking import reference
from jacgen.checking.c_library import compile_shared

from conftest import ROOT
from support.general6r_arms import ARMS, solver_of
from support.ik import wrapped

HARNESS = """
#include <math.h>
#include "eigenvalues.c"
#include "general6r.c"
void monomials(const double *c, double *out);
void monomials(const double *c, double *out) { jacgen_g6_monomials(c, out); }
int roots(const double *p, const double *q, double *angles);
int roots(const double *p, const double *q, double *angles) {
    double pm[3][14][9], qm[14][8], out[JACGEN_G6_ROOTS][5];
    static struct jacgen_g6_work work;
    for (int i = 0; i < 3 * 14 * 9; i++) pm[i / 126][i / 9 % 14][i % 9] = p[i];
    for (int i = 0; i < 14 * 8; i++) qm[i / 8][i % 8] = q[i];
    double condition;
    int count = jacgen_general6r_roots(pm, qm, out, &work, &condition);
    for (int i = 0; i < count * 5; i++) angles[i] = out[i / 5][i % 5];
    return count;
}
int solve_lanes(const double *a, const double *b, const int *moving, double *x, int *solved);
int solve_lanes(const double *a, const double *b, const int *moving, double *x, int *solved) {
    static struct jacgen_g6_lanes lanes;
    for (int k = 0; k < JACGEN_G6_LANES; k++)
        for (int i = 0; i < 6; i++) {
            for (int j = 0; j < 6; j++) lanes.a[i][j][k] = a[36 * k + 6 * i + j];
            lanes.b[i][k] = b[6 * k + i];
        }
    jacgen_g6_solve_lanes(&lanes, moving);
    for (int k = 0; k < JACGEN_G6_LANES; k++) {
        for (int i = 0; i < 6; i++) x[6 * k + i] = lanes.b[i][k];
        solved[k] = lanes.solved[k];
    }
    return JACGEN_G6_LANES;
}
int eigenvalues(int n, const double *matrix, double *re, double *im);
int eigenvalues(int n, const double *matrix, double *re, double *im) {
    double a[JACGEN_EIG_MAX][JACGEN_EIG_MAX];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) a[i][j] = matrix[i * n + j];
    return jacgen_eigenvalues(n, a, re, im);
}
"""


POINTER = ctypes.POINTER(ctypes.c_double)
RUNTIME = ROOT / "templates" / "runtime"


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    folder = tmp_path_factory.mktemp("runtime")
    (folder / "harness.c").write_text(HARNESS)
    flags = ("-O2", f"-I{RUNTIME}", f"-DJACGEN_G6_IMAGINARY={general6r.IMAGINARY['double']}",
             f"-DJACGEN_G6_LANES={general6r.NEWTON_ROWS}")
    library = ctypes.CDLL(str(compile_shared([folder / "harness.c"], folder / "libruntime.so", flags)))
    library.monomials.argtypes = [POINTER, POINTER]
    library.eigenvalues.argtypes = [ctypes.c_int, POINTER, POINTER, POINTER]
    library.roots.argtypes = [POINTER, POINTER, POINTER]
    INT = ctypes.POINTER(ctypes.c_int)
    library.solve_lanes.argtypes = [POINTER, POINTER, INT, POINTER, INT]
    return library


def test_the_lane_solve_solves_each_lane_as_lapack_does(library):
    """jacgen_g6_solve_lanes (the Newton steps' 6 x 6 solves, 8 at once): lanes of random,
    ill-conditioned (1e10) and permuted-triangular systems (every pivot a row exchange) solved
    to LAPACK's answer within their conditioning; a singular lane reports it, and a lane that
    is not moving is skipped (the build without JACGEN_SIMD_LOOP: a vector computes every lane)."""
    rng = np.random.default_rng(11)
    a = rng.normal(size=(8, 6, 6))
    u, _, vt = np.linalg.svd(a[1])
    a[1] = u @ np.diag(np.logspace(0, -10, 6)) @ vt
    a[2] = np.triu(rng.normal(size=(6, 6)) + 3 * np.eye(6))[::-1]  # the largest entry of each column last
    a[3, :, 2] = 0.0  # singular
    b = rng.normal(size=(8, 6))
    moving = np.array([1, 1, 1, 1, 1, 1, 0, 1], dtype=np.intc)
    x, solved = np.zeros((8, 6)), np.zeros(8, dtype=np.intc)
    int_pointer = ctypes.POINTER(ctypes.c_int)
    assert library.solve_lanes(np.ascontiguousarray(a).ctypes.data_as(POINTER), b.ctypes.data_as(POINTER),
                               moving.ctypes.data_as(int_pointer), x.ctypes.data_as(POINTER),
                               solved.ctypes.data_as(int_pointer)) == 8
    assert solved[3] == 0 and solved[[0, 1, 2, 4, 5, 7]].all()
    for k in (0, 1, 2, 4, 5, 7):
        expected = np.linalg.solve(a[k], b[k])
        assert np.abs(x[k] - expected).max() <= 1e-15 * np.linalg.cond(a[k]) * np.abs(expected).max() * 10
    assert np.array_equal(x[6], b[6])  # not moving: its right-hand side untouched


@pytest.fixture(scope="module")
def eigenvalues(library):
    pointer = POINTER

    def call(matrix: np.ndarray) -> np.ndarray:
        n = len(matrix)
        a, re, im = np.ascontiguousarray(matrix, dtype=float), np.zeros(n), np.zeros(n)
        assert library.eigenvalues(n, a.ctypes.data_as(pointer), re.ctypes.data_as(pointer),
                                   im.ctypes.data_as(pointer)) == 0
        return re + 1j * im

    return call


def _distance(found: np.ndarray, expected: np.ndarray) -> float:
    """The largest relative distance of a matching of the two multisets (greedy, nearest first)."""
    left, worst = list(expected), 0.0
    for value in found:
        k = int(np.argmin([abs(value - e) for e in left]))
        worst = max(worst, abs(value - left.pop(k)) / max(1.0, abs(value)))
    return worst


@pytest.mark.parametrize("n", [1, 2, 3, 5, 12, 16])
def test_similar_to_block_diagonal(eigenvalues, n):
    """S D S^-1 with D of 1x1 blocks (real eigenvalues) and 2x2 rotation-scalings (complex pairs)."""
    rng = np.random.default_rng(n)
    for _ in range(20):
        d, expected, k = np.zeros((n, n)), [], 0
        while k < n:
            if k + 1 < n and rng.random() < 0.4:
                a, b = rng.normal(), rng.uniform(0.1, 2)
                d[k:k + 2, k:k + 2] = [[a, -b], [b, a]]
                expected += [a + 1j * b, a - 1j * b]
                k += 2
            else:
                d[k, k] = rng.normal()
                expected.append(d[k, k] + 0j)
                k += 1
        s = rng.normal(size=(n, n)) + n * np.eye(n)
        assert _distance(eigenvalues(s @ d @ np.linalg.inv(s)), np.array(expected)) < 1e-9


@pytest.mark.parametrize("roots", [
    [1, 2, 3, 4], [-0.5, 0.25, 3, 7, -2, 1e-3], [2, 2, 1 + 1j, 1 - 1j], [1.5 * np.exp(2j * np.pi * k / 16) for k in range(16)],
    [0.5 * np.exp(1j * np.pi * (2 * k + 1) / 16) for k in range(16)]], ids=["4", "6", "repeated", "16", "16-no-real"])
def test_companion_matrices(eigenvalues, roots):
    coefficients = np.poly(roots).real
    n = len(coefficients) - 1
    companion = np.zeros((n, n))
    companion[0] = -coefficients[1:] / coefficients[0]
    companion[1:, :-1] = np.eye(n - 1)
    tolerance = 1e-6 if len(set(np.round(roots, 9))) < len(roots) else 1e-7  # a double root: sqrt(eps)
    assert _distance(eigenvalues(companion), np.array(roots, dtype=complex)) < tolerance


def test_random_matrices_as_lapack(eigenvalues):
    rng = np.random.default_rng(0)
    for n in (4, 12, 16):
        for _ in range(50):
            matrix = rng.normal(size=(n, n)) * rng.choice([1e-3, 1, 1e3], size=(n, n))
            assert _distance(eigenvalues(matrix), np.linalg.eigvals(matrix)) < 1e-9


def test_zero_and_triangular(eigenvalues):
    assert np.all(eigenvalues(np.zeros((6, 6))) == 0)
    upper = np.triu(np.arange(1.0, 65.0).reshape(8, 8))
    assert _distance(eigenvalues(upper), np.diag(upper).astype(complex)) < 1e-12


@pytest.mark.parametrize("name", ARMS)
def test_general6r_roots_complete_to_every_solution(library, name):
    arm = solver_of(name)

    def roots(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        p, q, angles = np.ascontiguousarray(p), np.ascontiguousarray(q), np.zeros((16, 5))
        count = library.roots(p.ctypes.data_as(POINTER), q.ctypes.data_as(POINTER), angles.ctypes.data_as(POINTER))
        return angles[:count]

    for q in np.random.default_rng(21).uniform(-math.pi, math.pi, (60, 6)):
        pose = reference.fk(arm.robot, q)
        ours = arm.solve(pose, roots)
        assert min(np.abs(wrapped(s - q)).max() for s in ours) < 1e-8
        assert len(ours) == len(arm.solve(pose))


def test_tables_are_those_of_the_numpy_solver(library):
    """The C's MONOMIALS (written out) and ALONG_B, ALONG_C are jacgen/solvers/general6r.py's."""
    for k in range(9):
        unit, out = np.eye(9)[k], np.zeros(9)
        library.monomials(unit.ctypes.data_as(POINTER), out.ctypes.data_as(POINTER))
        assert list(out) == list(general6r.MONOMIALS[k])
    text = (RUNTIME / "general6r.c").read_text()
    for name, table in (("along_b", general6r.ALONG_B), ("along_c", general6r.ALONG_C)):
        assert f"static const int {name}[{len(table)}] = {{{', '.join(map(str, table))}}};" in text
