/*
 * Minimal use of jacgen's generated C: forward kinematics and the Jacobian of the
 * Puma 560 at one configuration, then one resolved-rate step q_dot = J^T K e towards a
 * target position (the Jacobian-transpose law: no matrix inverse, no allocation).
 *
 * Build: `make` (host, runs it) or `make cortex-m4` (cross-compiles for a Cortex-M4F).
 * The robot code comes from generated/puma560/ (`jacgen generate robots/puma560.yaml`).
 */
#include <stdio.h>

#include "puma560.h"

int main(void)
{
    /* Binary fractions, exact in float and double, so the same code builds with `--real float`. */
    const puma560_real q[PUMA560_DOF] = {0.125, 0.5, -0.75, 0.25, 0.625, -0.375}; /* rad */
    const puma560_real target[3] = {0.5, 0.25, 0.875};                             /* m, world frame */
    const puma560_real gain = 2.0;                                                 /* 1/s */
    puma560_real T[16];
    puma560_real J[6 * PUMA560_DOF];
    puma560_real error[3];
    puma560_real q_dot[PUMA560_DOF];
    int r, c;

    puma560_fk(q, T);
    puma560_jacobian(q, J);

    /* Tool position: column 3 of the row-major 4x4 pose. */
    for (r = 0; r < 3; ++r) {
        error[r] = target[r] - T[r * 4 + 3];
    }
    /* q_dot = J_v^T K e, with J_v the linear-velocity rows 0..2 of J (6 x DOF, row-major). */
    for (c = 0; c < PUMA560_DOF; ++c) {
        q_dot[c] = 0;
        for (r = 0; r < 3; ++r) {
            q_dot[c] += J[r * PUMA560_DOF + c] * gain * error[r];
        }
    }

    printf("tool position  %9.5f %9.5f %9.5f m\n", (double)T[3], (double)T[7], (double)T[11]);
    printf("joint rates   ");
    for (c = 0; c < PUMA560_DOF; ++c) {
        printf(" %9.5f", (double)q_dot[c]);
    }
    printf(" rad/s\n");
    return 0;
}
