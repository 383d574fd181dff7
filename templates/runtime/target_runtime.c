/* The bare-metal runtime of the emulated board (QEMU mps2-an386, a Cortex-M4F), for `jacgen
 * verify --target cortex-m4f`: the vector table, the FPU switched on before any float
 * instruction, a fault that exits through semihosting instead of hanging, the SysTick
 * counting the processor clock, and stack painting. newlib's rdimon start code (_start)
 * takes the stack and heap from what QEMU reports and calls main. */
#include <stdint.h>

#include "target_runtime.h"

#define CPACR (*(volatile uint32_t *)0xE000ED88u)
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYSTICK_RELOAD 0xFFFFFFu
#define STACK_PATTERN 0xA5A5A5A5u

extern void _start(void);
extern uint32_t __stack_top;

static volatile uint32_t systick_wraps;

static void reset(void)
{
    CPACR |= 0xFu << 20; /* CP10 and CP11: full access to the FPU */
    __asm volatile("dsb\n\tisb");
    _start();
}

/* Semihosting SYS_EXIT with ADP_Stopped_RunTimeErrorUnknown: QEMU exits with status 1. */
static void fault(void)
{
    register uint32_t operation __asm("r0") = 0x18u;
    register uint32_t reason __asm("r1") = 0x20023u;
    __asm volatile("bkpt 0xab" : : "r"(operation), "r"(reason));
    for (;;) {
    }
}

static void systick(void) { systick_wraps++; }

/* The initial stack pointer, then reset, NMI, hard fault, ..., SVCall, debug, PendSV, SysTick. */
struct vector_table {
    uint32_t *stack_top;
    void (*handlers[15])(void);
};
__attribute__((section(".vectors"), used)) static const struct vector_table vectors = {
    &__stack_top, {reset, fault, fault, fault, fault, fault, 0, 0, 0, 0, fault, fault, 0, fault, systick},
};

void target_start_clock(void)
{
    SYST_RVR = SYSTICK_RELOAD;
    SYST_CVR = 0;
    SYST_CSR = 7u; /* enabled, interrupt on wrap, processor clock */
    while (SYST_CVR == 0u) {
    }
}

uint32_t target_ticks(void)
{
    uint32_t wraps, value;
    do {
        wraps = systick_wraps;
        value = SYST_CVR;
    } while (wraps != systick_wraps);
    return wraps * (SYSTICK_RELOAD + 1u) + (SYSTICK_RELOAD - value);
}

/* Fill TARGET_PAINTED_BYTES below the caller's stack pointer with a pattern. A leaf that
 * keeps nothing on the stack it paints: the stores are volatile so that gcc does not make
 * the loop a call of memset, whose own frame would be painted over. */
void target_paint_stack(void)
{
    volatile uint32_t *top;
    __asm volatile("mov %0, sp" : "=r"(top));
    for (volatile uint32_t *word = top - TARGET_PAINTED_BYTES / 4u; word < top; ++word) {
        *word = STACK_PATTERN;
    }
}

/* The bytes below `caller_sp` written since the paint (TARGET_PAINTED_BYTES: all of them). */
uint32_t target_stack_used(uintptr_t caller_sp)
{
    const uint32_t *word = (const uint32_t *)caller_sp - TARGET_PAINTED_BYTES / 4u;
    while ((uintptr_t)word < caller_sp && *word == STACK_PATTERN) {
        ++word;
    }
    return (uint32_t)(caller_sp - (uintptr_t)word);
}
