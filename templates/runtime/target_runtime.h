/* The emulated board's runtime (target_runtime.c): clock and stack measurement. */
#ifndef TARGET_RUNTIME_H
#define TARGET_RUNTIME_H
#include <stdint.h>

#define TARGET_PAINTED_BYTES 65536u /* the stack painted below each call: a deeper call is reported as this */

void target_start_clock(void);
uint32_t target_ticks(void); /* SysTick ticks since target_start_clock */
void target_paint_stack(void);
uint32_t target_stack_used(uintptr_t caller_sp);

#endif
