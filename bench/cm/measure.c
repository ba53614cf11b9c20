/* Exact instruction counts under QEMU: see measure.h. */
#include "measure.h"

#define TIMER0_CTRL (*(volatile uint32_t *)0x40000000u)
#define TIMER0_VALUE (*(volatile uint32_t *)0x40000004u)
#define TIMER0_RELOAD (*(volatile uint32_t *)0x40000008u)
#define EMPTY_INSNS 1u    /* measure_empty(): bx lr */

void measure_start(void)
{
    TIMER0_CTRL = 0u;
    TIMER0_RELOAD = 0xFFFFFFFFu;
    TIMER0_VALUE = 0xFFFFFFFFu;
    TIMER0_CTRL = 1u; /* enable, no interrupt */
}

uint32_t measure_ticks(void)
{
    return TIMER0_VALUE;
}

unsigned long measure_since(uint32_t t0)
{
    return (unsigned long)(t0 - measure_ticks()) * MEASURE_TICK_INSNS;
}

__attribute__((noinline, noipa)) static void measure_empty(void *ctx)
{
    (void)ctx;
}

__attribute__((noinline, noipa)) static unsigned long measure_loop(measure_fn setup,
                                                                   measure_fn call, void *ctx)
{
    uint32_t t0 = measure_ticks();
    unsigned r;
    for (r = 0; r < MEASURE_REPS; r++) {
        setup(ctx);
        call(ctx);
    }
    return measure_since(t0);
}

unsigned long measure_exact(measure_fn setup, measure_fn call, void *ctx)
{
    unsigned long a = measure_loop(setup, call, ctx);
    unsigned long b = measure_loop(setup, measure_empty, ctx);
    return (a - b + MEASURE_REPS / 2u) / MEASURE_REPS + EMPTY_INSNS;
}

void measure_known_loop(uint32_t n)
{
    __asm__ volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
}
