"""How many one-sided Jacobi sweeps the straight-line SVD needs (`jacgen/solvers/singular_values.py`).

The same arithmetic as the generated code (a Householder QR of A^T, then round-robin rotations
of the triangular factor's columns or rows, the squared norms summed afresh each sweep and
updated by each rotation), in numpy, on k x k factors of matrices with known singular values
(U diag(s) V^T, U and V orthogonal): spread over 1e-8 ... 1, one of 1e-16 ... 1e-6,
clustered within 1e-12 ... 1e-2 of 1, two zeros. Prints, per size and kind, the worst error
of the singular values relative to the largest after each number of sweeps, turning R's columns
(as velocity_ellipsoid does, for the vectors) or its rows (condition_number); the sweeps chosen
(`SWEEPS`) are one more than the first that reaches rounding on every kind.

    .venv/bin/python bench/bench_jacobi_sweeps.py
"""

import numpy as np

from jacgen.solvers.singular_values import SWEEPS, rounds

KINDS = ("random", "spread", "tiny", "clustered", "zeros")


def jacobi_norms(R: np.ndarray, sweeps: int) -> np.ndarray:
    W, k = R.copy(), R.shape[1]
    for _ in range(sweeps):
        squares = [W[:, i] @ W[:, i] for i in range(k)]  # summed afresh each sweep, updated by each rotation
        for i, j in (pair for pairs in rounds(k) for pair in pairs):
            a, b, c = squares[i], squares[j], W[:, i] @ W[:, j]
            d = b - a
            h = np.sqrt(d * d + 4 * c * c)
            if abs(d) + h == 0:
                continue
            t = (2 * c if d >= 0 else -2 * c) / (abs(d) + h)
            cos = 1 / np.sqrt(1 + t * t)
            W[:, i], W[:, j] = cos * W[:, i] - cos * t * W[:, j], cos * t * W[:, i] + cos * W[:, j]
            squares[i], squares[j] = a - t * c, b + t * c
    return np.linalg.norm(W, axis=0)


def singular_values(kind: str, k: int, rng) -> np.ndarray:
    s = np.sort(np.abs(rng.normal(size=k)))[::-1]
    if kind == "spread":
        s = np.sort(10.0 ** rng.uniform(-8, 0, size=k))[::-1]
    elif kind == "tiny":
        s[-1] = 10.0 ** rng.uniform(-16, -6)
    elif kind == "clustered":
        s = np.sort(np.abs(1 + 10.0 ** rng.uniform(-12, -2, size=k) * rng.normal(size=k)))[::-1]
    elif kind == "zeros":
        s[-2:] = 0
    return s


def worst_errors(rows: int, cols: int, kind: str, trials: int, sweeps: int, turned: str, rng) -> list[float]:
    k = min(rows, cols)
    worst = [0.0] * (sweeps + 1)
    for _ in range(trials):
        s = singular_values(kind, k, rng)
        U, _ = np.linalg.qr(rng.normal(size=(rows, rows)))
        V, _ = np.linalg.qr(rng.normal(size=(cols, cols)))
        A = U[:, :k] @ np.diag(s) @ V[:, :k].T
        _, R = np.linalg.qr(A.T if rows <= cols else A)
        for count in range(sweeps + 1):
            error = np.max(np.abs(np.sort(jacobi_norms(R if turned == "columns" else R.T, count))[::-1] - s)) / s[0]
            worst[count] = max(worst[count], error)
    return worst


def main():
    rng = np.random.default_rng(0)
    for turned, shapes in (("columns", ((3, 7, 2000), (3, 6, 2000))),
                           ("rows", ((3, 7, 2000), (3, 6, 2000), (6, 7, 500), (6, 6, 500)))):
        for rows, cols, trials in shapes:
            k = min(rows, cols)
            sweeps = SWEEPS[turned][k]
            print(f"{rows} x {cols}, R's {turned} turned: {sweeps} sweeps; worst error after 0, 1, ... sweeps")
            for kind in KINDS:
                errors = worst_errors(rows, cols, kind, trials, sweeps, turned, rng)
                print(f"  {kind:10s}" + " ".join(f"{e:8.0e}" for e in errors))


if __name__ == "__main__":
    main()
