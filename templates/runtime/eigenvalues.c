/* Runtime helper of the general 6R solver (included by robot.c.jinja for its robots):
 * the eigenvalues of a real n x n matrix, n <= JACGEN_EIG_MAX. Balancing (powers of 2, exact),
 * reduction to upper Hessenberg form by Gaussian elimination with row pivoting, then Francis
 * double-shift QR iterations with deflation (Golub & Van Loan, Matrix Computations, 7.5).
 * Fixed size, no allocation, no recursion, at most JACGEN_EIG_ITERATIONS iterations per
 * eigenvalue (exceptional shifts at 10 and 20). */
#define JACGEN_EIG_MAX 16
#define JACGEN_EIG_ITERATIONS 60

static void jacgen_eig_balance(int n, double a[JACGEN_EIG_MAX][JACGEN_EIG_MAX]) {
    const double radix = 2.0, sqrdx = radix * radix;
    int done = 0;
    while (!done) {
        done = 1;
        for (int i = 0; i < n; i++) {
            double r = 0.0, c = 0.0;
            for (int j = 0; j < n; j++)
                if (j != i) { c += fabs(a[j][i]); r += fabs(a[i][j]); }
            if (c != 0.0 && r != 0.0) {
                double g = r / radix, f = 1.0, s = c + r;
                while (c < g) { f *= radix; c *= sqrdx; }
                g = r * radix;
                while (c > g) { f /= radix; c /= sqrdx; }
                if ((c + r) / f < 0.95 * s) {
                    done = 0;
                    g = 1.0 / f;
                    for (int j = 0; j < n; j++) a[i][j] *= g;
                    for (int j = 0; j < n; j++) a[j][i] *= f;
                }
            }
        }
    }
}

static void jacgen_eig_hessenberg(int n, double a[JACGEN_EIG_MAX][JACGEN_EIG_MAX]) {
    for (int m = 1; m < n - 1; m++) {
        double x = 0.0;
        int i = m;
        for (int j = m; j < n; j++)
            if (fabs(a[j][m - 1]) > fabs(x)) { x = a[j][m - 1]; i = j; }
        if (i != m) {
            for (int j = m - 1; j < n; j++) { double t = a[i][j]; a[i][j] = a[m][j]; a[m][j] = t; }
            for (int j = 0; j < n; j++) { double t = a[j][i]; a[j][i] = a[j][m]; a[j][m] = t; }
        }
        if (x != 0.0) {
            for (i = m + 1; i < n; i++) {
                double y = a[i][m - 1];
                if (y != 0.0) {
                    y /= x;
                    a[i][m - 1] = y;
                    for (int j = m; j < n; j++) a[i][j] -= y * a[m][j];
                    for (int j = 0; j < n; j++) a[j][m] += y * a[j][i];
                }
            }
        }
    }
    for (int i = 2; i < n; i++)
        for (int j = 0; j < i - 1; j++) a[i][j] = 0.0;
}

static double jacgen_eig_sign(double a, double b) { return b >= 0.0 ? fabs(a) : -fabs(a); }

/* Returns 0, or -1 when an eigenvalue did not converge. */
static int jacgen_eig_qr(int n, double a[JACGEN_EIG_MAX][JACGEN_EIG_MAX], double re[], double im[]) {
    double norm = 0.0, shift = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = i > 0 ? i - 1 : 0; j < n; j++) norm += fabs(a[i][j]);
    int last = n - 1;
    while (last >= 0) {
        int iterations = 0, low;
        do {
            for (low = last; low >= 1; low--) {
                double s = fabs(a[low - 1][low - 1]) + fabs(a[low][low]);
                if (s == 0.0) s = norm;
                if (fabs(a[low][low - 1]) + s == s) { a[low][low - 1] = 0.0; break; }
            }
            double x = a[last][last];
            if (low == last) {
                re[last] = x + shift; im[last] = 0.0; last--;
            } else {
                double y = a[last - 1][last - 1], w = a[last][last - 1] * a[last - 1][last];
                if (low == last - 1) {
                    double p = 0.5 * (y - x), q = p * p + w, z = sqrt(fabs(q));
                    x += shift;
                    if (q >= 0.0) {
                        z = p + jacgen_eig_sign(z, p);
                        re[last - 1] = re[last] = x + z;
                        if (z != 0.0) re[last] = x - w / z;
                        im[last - 1] = im[last] = 0.0;
                    } else {
                        re[last - 1] = re[last] = x + p;
                        im[last - 1] = -z; im[last] = z;
                    }
                    last -= 2;
                } else {
                    if (iterations == JACGEN_EIG_ITERATIONS) return -1;
                    if (iterations == 10 || iterations == 20) { /* exceptional shift */
                        shift += x;
                        for (int i = 0; i <= last; i++) a[i][i] -= x;
                        double s = fabs(a[last][last - 1]) + fabs(a[last - 1][last - 2]);
                        x = y = 0.75 * s;
                        w = -0.4375 * s * s;
                    }
                    iterations++;
                    int m;
                    double p = 0.0, q = 0.0, r = 0.0, z;
                    for (m = last - 2; m >= low; m--) {
                        z = a[m][m];
                        double rr = x - z, ss = y - z;
                        p = (rr * ss - w) / a[m + 1][m] + a[m][m + 1];
                        q = a[m + 1][m + 1] - z - rr - ss;
                        r = a[m + 2][m + 1];
                        double s = fabs(p) + fabs(q) + fabs(r);
                        p /= s; q /= s; r /= s;
                        if (m == low) break;
                        double u = fabs(a[m][m - 1]) * (fabs(q) + fabs(r));
                        double v = fabs(p) * (fabs(a[m - 1][m - 1]) + fabs(z) + fabs(a[m + 1][m + 1]));
                        if (u + v == v) break;
                    }
                    for (int i = m + 2; i <= last; i++) {
                        a[i][i - 2] = 0.0;
                        if (i != m + 2) a[i][i - 3] = 0.0;
                    }
                    for (int k = m; k <= last - 1; k++) {
                        if (k != m) {
                            p = a[k][k - 1]; q = a[k + 1][k - 1]; r = k != last - 1 ? a[k + 2][k - 1] : 0.0;
                            x = fabs(p) + fabs(q) + fabs(r);
                            if (x != 0.0) { p /= x; q /= x; r /= x; }
                        }
                        double s = jacgen_eig_sign(sqrt(p * p + q * q + r * r), p);
                        if (s != 0.0) {
                            if (k == m) { if (low != m) a[k][k - 1] = -a[k][k - 1]; }
                            else a[k][k - 1] = -s * x;
                            p += s; x = p / s; y = q / s; z = r / s; q /= p; r /= p;
                            for (int j = k; j <= last; j++) {
                                p = a[k][j] + q * a[k + 1][j];
                                if (k != last - 1) { p += r * a[k + 2][j]; a[k + 2][j] -= p * z; }
                                a[k + 1][j] -= p * y; a[k][j] -= p * x;
                            }
                            int top = last < k + 3 ? last : k + 3;
                            for (int i = low; i <= top; i++) {
                                p = x * a[i][k] + y * a[i][k + 1];
                                if (k != last - 1) { p += z * a[i][k + 2]; a[i][k + 2] -= p * r; }
                                a[i][k + 1] -= p * q; a[i][k] -= p;
                            }
                        }
                    }
                }
            }
        } while (low < last - 1);
    }
    return 0;
}

/* The eigenvalues re[k] + i im[k] of the n x n matrix a (overwritten); 0, or -1 when one did not
 * converge. Complex pairs come as conjugates, the positive imaginary part second. */
static int jacgen_eigenvalues(int n, double a[JACGEN_EIG_MAX][JACGEN_EIG_MAX], double re[], double im[]) {
    jacgen_eig_balance(n, a);
    jacgen_eig_hessenberg(n, a);
    return jacgen_eig_qr(n, a, re, im);
}

