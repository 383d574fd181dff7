/*
 * jacgen's generated C in a firmware control loop: resolved-rate control at 1 kHz. Each tick
 * reads q, calls NAME_resolved_rate towards a target pose (gain 20/s, no feedforward, no
 * null-space motion) and integrates q += dt q_dot, as a control interrupt would: the tool's
 * distance from the target shrinks by (1 - 20 dt) each tick, exp(-10) in 0.5 s.
 *
 * Build: `make` (host, runs it) or `make cortex-m4` (cross-compiles for a Cortex-M4F); the
 * robot code comes from generated/NAME/ (`jacgen generate robots/NAME.yaml`), the Puma 560
 * unless built with -DROBOT=panda -DROBOT_UPPER=PANDA (any arm whose task is a pose).
 * `make check-m4` runs it on the emulated Cortex-M4F with -DON_TARGET, and prints the
 * instructions and the stack of one tick.
 */
#include <math.h>
#include <stdio.h>

#ifndef ROBOT
#define ROBOT puma560
#define ROBOT_UPPER PUMA560
#endif
#define GLUE_(prefix, name) prefix##_##name
#define GLUE(prefix, name) GLUE_(prefix, name)
#define QUOTE_(text) #text
#define QUOTE(text) QUOTE_(text)
#define CALL(function) GLUE(ROBOT, function) /* CALL(fk): puma560_fk */
#define DOF GLUE(ROBOT_UPPER, DOF)
#define TASK_DIM GLUE(ROBOT_UPPER, TASK_DIM)

#include QUOTE(ROBOT.h)

typedef GLUE(ROBOT, real) real;

#ifdef ON_TARGET /* the emulated board's clock and stack painting (templates/runtime/target_runtime.c) */
#include <stdint.h>

#include "target_runtime.h"

static uintptr_t stack_pointer(void)
{
    uintptr_t sp;
    __asm volatile("mov %0, sp" : "=r"(sp));
    return sp;
}
#endif

#define TICKS 500
static const real dt = (real)0.001; /* s: the 1 kHz loop */

/* Binary fractions, exact in float and double, so the same code builds with `--real float` (rad). */
#if DOF == 6
static const real start[DOF] = {0.125, 0.5, -0.75, 0.25, 0.625, -0.375};
#else
static const real start[DOF] = {0.5, -0.5, 1.5, -1.75, -0.5, 1.375, 0.75}; /* inside the Panda's limits */
#endif

/* One control tick: q_dot = resolved_rate(q, target, 0, gain, 0), then q += dt q_dot. */
static int control_tick(real q[DOF], const real target[16], const real gain[TASK_DIM])
{
    static const real target_rate[TASK_DIM] = {0}, z[DOF] = {0};
    real q_dot[DOF];
    int j;
    const int status = CALL(resolved_rate)(q, target, target_rate, gain, z, 0, q_dot);
    for (j = 0; j < DOF; ++j) {
        q[j] += dt * q_dot[j];
    }
    return status;
}

/* The distance from the tool at q to the target's position (m). */
static double distance(const real q[DOF], const real target[16])
{
    real T[16];
    double squares = 0;
    int r;
    CALL(fk)(q, T);
    for (r = 0; r < 3; ++r) {
        const double d = (double)(T[r * 4 + 3] - target[r * 4 + 3]);
        squares += d * d;
    }
    return sqrt(squares);
}

int main(void)
{
    real q[DOF], goal[DOF], target[16], gain[TASK_DIM];
    double before;
    int j, tick;

    for (j = 0; j < DOF; ++j) {
        q[j] = start[j];
        goal[j] = start[j] + (real)0.0625;
    }
    for (j = 0; j < TASK_DIM; ++j) {
        gain[j] = 20; /* 1/s */
    }
    CALL(fk)(goal, target); /* a pose the arm can reach */
    before = distance(q, target);
#ifdef ON_TARGET
    target_paint_stack();
    const uintptr_t sp = stack_pointer();
    target_start_clock();
    const uint32_t ticks = target_ticks();
#endif
    for (tick = 0; tick < TICKS; ++tick) {
        if (control_tick(q, target, gain) != GLUE(ROBOT_UPPER, VELOCITY_IK_OK)) {
            printf("resolved_rate failed at tick %d\n", tick);
            return 1;
        }
    }
#ifdef ON_TARGET
    /* QEMU's -icount shift=6 (jacgen/checking/cortex_m4f.py): 64 ns per instruction, SysTick at 25 MHz. */
    const double instructions = (double)(target_ticks() - ticks) * 40.0 / 64.0 / TICKS;
    printf("%s control tick (resolved_rate, q += dt q_dot): %.0f instructions, %lu bytes of stack\n",
           QUOTE(ROBOT), instructions, (unsigned long)target_stack_used(sp));
#endif
    printf("%s: tool %.2e m from the target, %.2e m after %d ticks ((1 - gain dt)^%d of it: %.2e m)\n",
           QUOTE(ROBOT), before, distance(q, target), TICKS, TICKS, before * pow(1.0 - 20 * (double)dt, TICKS));
    return 0;
}
