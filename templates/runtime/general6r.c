/* Runtime helper of the general 6R solver (included by robot.c.jinja for its robots): from
 * Raghavan & Roth's 14 equations at one target, (P0 + s Ps + c Pc) v_bc = Q v_gh with the hidden
 * angle's shift already applied (jacgen/solvers/general6r.py), the loop angles (a, b, c, g, h)
 * of every real root. Q = QR by Householder reflections: the rows 8..13 of Q^T P are the six equations
 * free of v_gh; their twelve in the monomials x_b^i x_c^j (the six, and the six times x_b) give
 * M(x) = M0 + x M1 + x^2 M2, x = tan(a / 2). Of the 24 eigenvalues of its companion matrix, 8 are
 * x = +-i for every target (jacgen_g6_spurious); the other 16 are those of the companion matrix
 * with them deflated (jacgen_g6_deflated, jacgen_eigenvalues). Per real root, the null vector of
 * M(x) (inverse iteration) gives x_b and x_c, and R^-1 (Q^T P v_bc)[0..7] gives v_gh. Fixed size,
 * no allocation, no recursion. Returns the number of roots (0 when M2 or R is singular), and
 * M2's 1-norm condition number in *condition (infinite when it is singular): above
 * JACGEN_G6_DEGENERATE, its eigenvalues are noise and the caller takes its fallback elimination.
 * Defined before it: JACGEN_G6_IMAGINARY, an eigenvalue being a root when |imaginary part| <= that
 * (1 + |x|) (jacgen/solvers/general6r.py's IMAGINARY for the build's real type). */
#define JACGEN_G6_ROOTS 16
/* The QR of Q (14 x 8) is singular where an entry of R's diagonal is below this times the largest. */
#define JACGEN_G6_SINGULAR_R 1e-12
/* The rounding a zero pivot of the null vector's LU stands for, relative to the largest pivot. */
#define JACGEN_G6_ZERO_PIVOT 1e-16

/* sum_k c[k] v_bc[k] times (1 + x_b^2) (1 + x_c^2) as a polynomial in x_b, x_c: its coefficient of
 * x_b^i x_c^j at 3 i + j (jacgen/solvers/general6r.py's MONOMIALS, written out without its
 * zeros). */
static void jacgen_g6_monomials(const double c[9], double out[9]) {
    out[0] = c[3] + c[5] + c[7] + c[8];
    out[1] = 2.0 * c[2] + 2.0 * c[6];
    out[2] = -c[3] + c[5] - c[7] + c[8];
    out[3] = 2.0 * c[1] + 2.0 * c[4];
    out[4] = 4.0 * c[0];
    out[5] = -2.0 * c[1] + 2.0 * c[4];
    out[6] = -c[3] - c[5] + c[7] + c[8];
    out[7] = -2.0 * c[2] + 2.0 * c[6];
    out[8] = c[3] - c[5] - c[7] + c[8];
}

/* The Householder reflections of q (14 x 8) in place below the diagonal with their scales; r's
 * diagonal in rdiag. Returns -1 when a column is (numerically) dependent on the others. */
static int jacgen_g6_qr(double q[14][8], double beta[8], double rdiag[8]) {
    for (int k = 0; k < 8; k++) {
        double norm = 0.0;
        for (int i = k; i < 14; i++) norm += q[i][k] * q[i][k];
        norm = sqrt(norm);
        if (!(norm > 0.0)) return -1;
        double alpha = q[k][k] > 0.0 ? -norm : norm;
        q[k][k] -= alpha;
        beta[k] = 1.0 / (-alpha * q[k][k]);
        rdiag[k] = alpha;
        for (int j = k + 1; j < 8; j++) {
            double s = 0.0;
            for (int i = k; i < 14; i++) s += q[i][k] * q[i][j];
            s *= beta[k];
            for (int i = k; i < 14; i++) q[i][j] -= s * q[i][k];
        }
    }
    double largest = 0.0;
    for (int k = 0; k < 8; k++) largest = fmax(largest, fabs(rdiag[k]));
    for (int k = 0; k < 8; k++)
        if (!(fabs(rdiag[k]) > JACGEN_G6_SINGULAR_R * largest)) return -1;
    return 0;
}

/* v <- H_k v (14): Householder reflection k of jacgen_g6_qr (Q = H_0 ... H_7). */
static void jacgen_g6_reflect(double q[14][8], const double beta[8], int k, double v[14]) {
    double s = 0.0;
    for (int i = k; i < 14; i++) s += q[i][k] * v[i];
    s *= beta[k];
    for (int i = k; i < 14; i++) v[i] -= s * q[i][k];
}

/* v <- Q^T v (14) */
static void jacgen_g6_transpose_times(double q[14][8], const double beta[8], double v[14]) {
    for (int k = 0; k < 8; k++) jacgen_g6_reflect(q, beta, k, v);
}

/* The rows 8..13 of Q^T (the left null space of the QR's matrix), as Q e_(8 + r). */
static void jacgen_g6_left_null(double q[14][8], const double beta[8], double n[6][14]) {
    for (int r = 0; r < 6; r++) {
        for (int i = 0; i < 14; i++) n[r][i] = i == 8 + r ? 1.0 : 0.0;
        for (int k = 7; k >= 0; k--) jacgen_g6_reflect(q, beta, k, n[r]);
    }
}

/* x solving a x = b in place (a: n x n, b: n x nb, both row by row), by LU with partial pivoting
 * (a is left with U above its diagonal, its pivots' inverses on it and scratch below).
 * Returns -1 when a pivot is 0. */
static int jacgen_g6_solve(int n, double *a, int nb, double *b) {
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(a[i * n + k]) > fabs(a[p * n + k])) p = i;
        if (!(fabs(a[p * n + k]) > 0.0)) return -1;
        if (p != k) {
            for (int j = k; j < n; j++) { double t = a[k * n + j]; a[k * n + j] = a[p * n + j]; a[p * n + j] = t; }
            for (int j = 0; j < nb; j++) { double t = b[k * nb + j]; b[k * nb + j] = b[p * nb + j]; b[p * nb + j] = t; }
        }
        double inverse = a[k * n + k] = 1.0 / a[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double f = a[i * n + k] * inverse;
            for (int j = k + 1; j < n; j++) a[i * n + j] -= f * a[k * n + j];
            for (int j = 0; j < nb; j++) b[i * nb + j] -= f * b[k * nb + j];
        }
    }
    for (int k = n - 1; k >= 0; k--)
        for (int j = 0; j < nb; j++) {
            double s = b[k * nb + j];
            for (int i = k + 1; i < n; i++) s -= a[k * n + i] * b[i * nb + j];
            b[k * nb + j] = s * a[k * n + k];
        }
    return 0;
}

/* The Newton steps' linear solves, JACGEN_G6_LANES 6 x 6 systems at once: lane k of a and b
 * holds system k, a x = b, and x replaces b. The arithmetic and pivots of jacgen_g6_solve (each
 * row swapped with the pivot row where its entry is larger, so the largest ends there first),
 * but a swap is a select in every lane, never a jump: a compiler vectorises the loops over the
 * lanes (JACGEN_SIMD_LOOP). solved[k] is 0 where a pivot is 0 (b is then not x). Defined before
 * it: JACGEN_G6_LANES (jacgen/solvers/general6r.py's NEWTON_ROWS). */
/* The native module's kernels define JACGEN_SIMD_LOOP (omp simd), JACGEN_SIMD_KERNEL (flatten)
 * and JACGEN_KERNEL_LOOP (unroll). A vector computes every lane: none is skipped there. */
#ifdef JACGEN_SIMD_LOOP
#define JACGEN_SKIP_LANE(skip)
#else
#define JACGEN_SIMD_LOOP
#define JACGEN_SIMD_KERNEL
#define JACGEN_KERNEL_LOOP
#define JACGEN_SKIP_LANE(skip) if (skip) continue;
#endif
struct jacgen_g6_lanes {
    double a[6][6][JACGEN_G6_LANES], b[6][JACGEN_G6_LANES];
    int solved[JACGEN_G6_LANES];
};

static void jacgen_g6_solve_lanes(struct jacgen_g6_lanes *restrict s, const int *restrict moving) {
    long k;
    JACGEN_SIMD_LOOP
    for (k = 0; k < JACGEN_G6_LANES; k++) {
        JACGEN_SKIP_LANE(!moving[k])
        int solved = 1;
        JACGEN_KERNEL_LOOP
        for (int c = 0; c < 6; c++) {
            JACGEN_KERNEL_LOOP
            for (int r = c + 1; r < 6; r++) {
                int larger = fabs(s->a[r][c][k]) > fabs(s->a[c][c][k]);
                JACGEN_KERNEL_LOOP
                for (int j = c; j < 6; j++) {
                    double pivot_row = s->a[c][j][k], row = s->a[r][j][k];
                    s->a[c][j][k] = larger ? row : pivot_row;
                    s->a[r][j][k] = larger ? pivot_row : row;
                }
                double pivot_row = s->b[c][k], row = s->b[r][k];
                s->b[c][k] = larger ? row : pivot_row;
                s->b[r][k] = larger ? pivot_row : row;
            }
            solved &= fabs(s->a[c][c][k]) > 0.0;
            double inverse = s->a[c][c][k] = 1.0 / s->a[c][c][k];
            JACGEN_KERNEL_LOOP
            for (int r = c + 1; r < 6; r++) {
                double f = s->a[r][c][k] * inverse;
                JACGEN_KERNEL_LOOP
                for (int j = c + 1; j < 6; j++) s->a[r][j][k] -= f * s->a[c][j][k];
                s->b[r][k] -= f * s->b[c][k];
            }
        }
        JACGEN_KERNEL_LOOP
        for (int c = 5; c >= 0; c--) {
            double sum = s->b[c][k];
            JACGEN_KERNEL_LOOP
            for (int j = c + 1; j < 6; j++) sum -= s->a[c][j][k] * s->b[j][k];
            s->b[c][k] = sum * s->a[c][c][k];
        }
        s->solved[k] = solved;
    }
}

/* The null vector of a (12 x 12, singular to rounding) by inverse iteration: LU with partial
 * pivoting, then U v = (1, ..., 1), the start vector L (1, ..., 1) being one whose component
 * along the null vector the elimination does not cancel (Wilkinson). A zero pivot is taken as
 * the rounding that it is: JACGEN_G6_ZERO_PIVOT times the largest pivot before it. Rows with a zero below the
 * pivot are skipped: M(x)'s rows 6..11 have none in columns 0..2. (a: overwritten, U with its
 * inverted diagonal.) */
static void jacgen_g6_null_vector(double a[12][12], double v[12]) {
    double largest = 1.0;
    for (int k = 0; k < 12; k++) {
        int p = k;
        for (int i = k + 1; i < 12; i++)
            if (fabs(a[i][k]) > fabs(a[p][k])) p = i;
        if (p != k)
            for (int j = k; j < 12; j++) { double t = a[k][j]; a[k][j] = a[p][j]; a[p][j] = t; }
        if (a[k][k] == 0.0) a[k][k] = JACGEN_G6_ZERO_PIVOT * largest;
        else if (k == 0 || fabs(a[k][k]) > largest) largest = fabs(a[k][k]);
        double inverse = 1.0 / a[k][k];
        for (int i = k + 1; i < 12; i++) {
            if (a[i][k] == 0.0) continue;
            double f = a[i][k] * inverse;
            for (int j = k + 1; j < 12; j++) a[i][j] -= f * a[k][j];
        }
        a[k][k] = inverse;
    }
    for (int k = 11; k >= 0; k--) {
        double s = 1.0;
        for (int j = k + 1; j < 12; j++) s -= a[k][j] * v[j];
        v[k] = s * a[k][k];
    }
}

/* 2 atan(num / den) of the pair (num, den) = (v[i + step], v[i]) of largest size, i in `from`
 * (sizes squared: v is a null vector by inverse iteration, about 1 / rounding, far from overflow). */
static double jacgen_g6_half_angle(const double v[12], const int *from, int count, int step) {
    int best = from[0];
    double largest = -1.0;
    for (int k = 0; k < count; k++) {
        double size = v[from[k]] * v[from[k]] + v[from[k] + step] * v[from[k] + step];
        if (size > largest) { largest = size; best = from[k]; }
    }
    return 2.0 * atan2(v[best + step], v[best]);
}

/* M_e (12 x 12), e = 0, 1, 2: the coefficient of x^e of (1 + x^2) (S0 + s Ss + c Sc) (free: S0,
 * Ss, Sc; s = 2x / (1 + x^2), c = (1 - x^2) / (1 + x^2)), in the monomials x_b^i x_c^j; rows 6..11
 * are rows 0..5 times x_b. */
static void jacgen_g6_pencil(double free[3][6][9], double m[3][12][12]) {
    for (int r = 0; r < 6; r++) {
        double c[3][9];
        for (int k = 0; k < 9; k++) {
            double s0 = free[0][r][k], ss = free[1][r][k], sc = free[2][r][k];
            c[0][k] = s0 + sc;
            c[1][k] = 2.0 * ss;
            c[2][k] = s0 - sc;
        }
        for (int e = 0; e < 3; e++) {
            double row[9];
            jacgen_g6_monomials(c[e], row);
            for (int j = 0; j < 3; j++) m[e][r][9 + j] = m[e][r + 6][j] = 0.0;
            for (int j = 0; j < 9; j++) m[e][r][j] = m[e][r + 6][j + 3] = row[j];
        }
    }
}

/* The kernel's working memory: the QR of Q, its left null space, the six v_gh-free equations, M0,
 * M1, M2, the null space of M(i) (u + i v), M2^-1 [M0 M1 I] (at the deflated matrix's columns,
 * and M2's inverse), the deflated matrix (eigenvalues in re, im) and two 12 x 12 matrices (M(i);
 * M2's LU; M(x) at each root). */
struct jacgen_g6_work {
    double q[14][8], beta[8], rdiag[8], left_null[6][14], free[3][6][9], m[3][12][12];
    double u[12][4], v[12][4], columns[12][28], square[2][12][12];
    double deflated[JACGEN_EIG_MAX][JACGEN_EIG_MAX], re[JACGEN_EIG_MAX], im[JACGEN_EIG_MAX];
};

/* The null space of M(i) = (M0 - M2) + i M1 as four complex vectors u + i v (columns of u, v):
 * the rows of the equations that turn with the hidden angle, by e^(ia) = (1 + ix)^2 / (1 + x^2),
 * have rank 4 at x = i, so M(i) has rank 8 and x = +-i are roots four times over. Complete
 * pivoting, eight steps (re, im: scratch), the four unknowns left set to unit vectors: column
 * order[8 + k] of M(i) is the unit vector of u's column k, and v is 0 there. The eight pivot
 * columns in order[0..7]; -1 when a pivot is 0. */
static int jacgen_g6_spurious(double m[3][12][12], double re[12][12], double im[12][12], double u[12][4],
                              double v[12][4], int order[12]) {
    int *column = order;
    for (int i = 0; i < 12; i++) {
        column[i] = i;
        for (int j = 0; j < 12; j++) { re[i][j] = m[0][i][j] - m[2][i][j]; im[i][j] = m[1][i][j]; }
    }
    for (int k = 0; k < 8; k++) {
        int pr = k, pc = k;
        double largest = 0.0;
        for (int i = k; i < 12; i++)
            for (int j = k; j < 12; j++) {
                double size = re[i][j] * re[i][j] + im[i][j] * im[i][j];
                if (size > largest) { largest = size; pr = i; pc = j; }
            }
        if (!(largest > 0.0)) return -1;
        for (int j = 0; j < 12; j++) {
            double t = re[k][j]; re[k][j] = re[pr][j]; re[pr][j] = t;
            t = im[k][j]; im[k][j] = im[pr][j]; im[pr][j] = t;
        }
        for (int i = 0; i < 12; i++) {
            double t = re[i][k]; re[i][k] = re[i][pc]; re[i][pc] = t;
            t = im[i][k]; im[i][k] = im[i][pc]; im[i][pc] = t;
        }
        int t = column[k]; column[k] = column[pc]; column[pc] = t;
        double inverse_re = re[k][k] / largest, inverse_im = -im[k][k] / largest;
        for (int i = k + 1; i < 12; i++) {
            double f_re = re[i][k] * inverse_re - im[i][k] * inverse_im;
            double f_im = re[i][k] * inverse_im + im[i][k] * inverse_re;
            for (int j = k + 1; j < 12; j++) {
                re[i][j] -= f_re * re[k][j] - f_im * im[k][j];
                im[i][j] -= f_re * im[k][j] + f_im * re[k][j];
            }
        }
    }
    for (int f = 0; f < 4; f++) {
        double z_re[12], z_im[12];
        for (int j = 8; j < 12; j++) { z_re[j] = j == 8 + f ? 1.0 : 0.0; z_im[j] = 0.0; }
        for (int k = 7; k >= 0; k--) {
            double s_re = -re[k][8 + f], s_im = -im[k][8 + f];
            for (int j = k + 1; j < 8; j++) {
                s_re -= re[k][j] * z_re[j] - im[k][j] * z_im[j];
                s_im -= re[k][j] * z_im[j] + im[k][j] * z_re[j];
            }
            double size = re[k][k] * re[k][k] + im[k][k] * im[k][k];
            z_re[k] = (s_re * re[k][k] + s_im * im[k][k]) / size;
            z_im[k] = (s_im * re[k][k] - s_re * im[k][k]) / size;
        }
        for (int j = 0; j < 12; j++) { u[column[j]][f] = z_re[j]; v[column[j]][f] = z_im[j]; }
    }
    return 0;
}

/* The 16 x 16 matrix whose eigenvalues are those of the companion matrix C = [0 I; -S] (S = M2^-1
 * [M0 M1], on (y, x y) with M(x) y = 0) less x = +-i. Their eigenvectors [z; i z] (z = u + i v in
 * the null space of M(i)) and conjugates span the invariant subspace W = [u v; -v u]; the
 * rows of W at the free columns order[8..11] of M(i) and at 12 + those are the identity, so the
 * unit vectors e_r at the other rows r complete W to a basis and C's map on R^24 / W in that
 * basis is C[r][r'] - W[r] C[sel][r'] (sel: the identity's rows): with C[sel] = [0; -S[free]] at
 * the columns r', the rows [0 I] + v S[free] and -S + u S[free] at the pivot columns.
 * -1 when M2 is singular. */
static int jacgen_g6_deflated(struct jacgen_g6_work *w, const int order[12], double *condition) {
    double (*s)[28] = w->columns, (*lead)[12] = w->square[0];
    double norm = 0.0, inverse_norm = 0.0;
    for (int i = 0; i < 12; i++) {
        for (int j = 0; j < 12; j++) { lead[i][j] = w->m[2][i][j]; s[i][16 + j] = i == j; }
        for (int b = 0; b < 8; b++) { s[i][b] = w->m[0][i][order[b]]; s[i][8 + b] = w->m[1][i][order[b]]; }
    }
    if (jacgen_g6_solve(12, &lead[0][0], 28, &s[0][0]) != 0) return -1;
    for (int j = 0; j < 12; j++) {  /* M2's 1-norm condition number, from M2^-1 in columns 16.. */
        double column = 0.0, inverse_column = 0.0;
        for (int i = 0; i < 12; i++) { column += fabs(w->m[2][i][j]); inverse_column += fabs(s[i][16 + j]); }
        if (column > norm) norm = column;
        if (inverse_column > inverse_norm) inverse_norm = inverse_column;
    }
    *condition = norm * inverse_norm;
    for (int a = 0; a < 8; a++) {
        int r = order[a];
        for (int b = 0; b < 16; b++) {
            double top = b == 8 + a ? 1.0 : 0.0, bottom = -s[r][b];
            for (int k = 0; k < 4; k++) {
                top += w->v[r][k] * s[order[8 + k]][b];
                bottom += w->u[r][k] * s[order[8 + k]][b];
            }
            w->deflated[a][b] = top;
            w->deflated[8 + a][b] = bottom;
        }
    }
    return 0;
}

static int jacgen_general6r_roots(double p[3][14][9], double q_matrix[14][8],
                                  double angles[JACGEN_G6_ROOTS][5], struct jacgen_g6_work *w, double *condition) {
    *condition = INFINITY;
    for (int i = 0; i < 14; i++)
        for (int j = 0; j < 8; j++) w->q[i][j] = q_matrix[i][j];
    if (jacgen_g6_qr(w->q, w->beta, w->rdiag) != 0) return 0;
    /* the rows 8..13 of Q^T P0, Q^T Ps, Q^T Pc: the six equations free of v_gh */
    jacgen_g6_left_null(w->q, w->beta, w->left_null);
    for (int m = 0; m < 3; m++)
        for (int r = 0; r < 6; r++) {
            for (int j = 0; j < 9; j++) w->free[m][r][j] = 0.0;
            for (int i = 0; i < 14; i++)
                for (int j = 0; j < 9; j++) w->free[m][r][j] += w->left_null[r][i] * p[m][i][j];
        }
    jacgen_g6_pencil(w->free, w->m);
    int order[12];
    if (jacgen_g6_spurious(w->m, w->square[0], w->square[1], w->u, w->v, order) != 0
        || jacgen_g6_deflated(w, order, condition) != 0
        || jacgen_eigenvalues(JACGEN_G6_ROOTS, w->deflated, w->re, w->im) != 0) return 0;
    static const int along_c[8] = {0, 1, 3, 4, 6, 7, 9, 10};
    static const int along_b[9] = {0, 1, 2, 3, 4, 5, 6, 7, 8};
    int found = 0;
    for (int k = 0; k < JACGEN_G6_ROOTS; k++) {
        double x = w->re[k], v[12];
        if (!(fabs(w->im[k]) <= JACGEN_G6_IMAGINARY * (1.0 + fabs(x)))) continue;
        for (int i = 0; i < 12; i++)
            for (int j = 0; j < 12; j++) w->square[0][i][j] = w->m[0][i][j] + x * (w->m[1][i][j] + x * w->m[2][i][j]);
        jacgen_g6_null_vector(w->square[0], v);
        double a_angle = 2.0 * atan(x);
        double b = jacgen_g6_half_angle(v, along_b, 9, 3);
        double c = jacgen_g6_half_angle(v, along_c, 8, 1);
        double sa = sin(a_angle), ca = cos(a_angle), sb = sin(b), cb = cos(b), sc = sin(c), cc = cos(c);
        double v_bc[9] = {sb * sc, sb * cc, cb * sc, cb * cc, sb, cb, sc, cc, 1.0}, equations[14], v_gh[8];
        for (int i = 0; i < 14; i++) {
            equations[i] = 0.0;
            for (int j = 0; j < 9; j++) equations[i] += (p[0][i][j] + sa * p[1][i][j] + ca * p[2][i][j]) * v_bc[j];
        }
        jacgen_g6_transpose_times(w->q, w->beta, equations);
        for (int i = 7; i >= 0; i--) {
            double s = equations[i];
            for (int j = i + 1; j < 8; j++) s -= w->q[i][j] * v_gh[j];
            v_gh[i] = s / w->rdiag[i];
        }
        double out[5] = {a_angle, b, c, atan2(v_gh[4], v_gh[5]), atan2(v_gh[6], v_gh[7])};
        for (int j = 0; j < 5; j++) angles[found][j] = out[j];
        found++;
    }
    return found;
}
