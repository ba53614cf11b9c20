/* Cortex-M3 startup for QEMU's mps2-an385: the vector table, a reset
 * handler that sets up the C environment, and fault handlers that end the
 * run with a failure status through semihosting. Written for this example;
 * any Cortex-M part needs the same few things. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "board.h"

extern uint32_t _estack, _sidata, _sdata, _edata, _sbss, _ebss, _sstack_paint;

#define STACK_PAINT 0x5AC3A55Cu
extern int main(void);
/* newlib's rdimon: opens stdin/stdout/stderr on the semihosting host. */
extern void initialise_monitor_handles(void);

void Reset_Handler(void);
void Fault_Handler(void);
void Default_Handler(void);

typedef void (*vector_t)(void);

/* Core exceptions then the board's 32 external interrupts; only SysTick is
 * used here. The first word is the initial stack pointer. */
__attribute__((section(".isr_vector"), used)) const vector_t vector_table[16 + 32] = {
    (vector_t)(uintptr_t)&_estack,
    Reset_Handler,
    Default_Handler, /* NMI */
    Fault_Handler,   /* HardFault */
    Fault_Handler,   /* MemManage */
    Fault_Handler,   /* BusFault */
    Fault_Handler,   /* UsageFault */
    0,
    0,
    0,
    0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMonitor */
    0,
    Default_Handler, /* PendSV */
    SysTick_Handler,
    /* external interrupts: all Default_Handler (filled below by the range
     * designator would be a GNU extension; zero means "never enabled") */
};

void Reset_Handler(void)
{
    uint32_t *src = &_sidata;
    uint32_t *dst = &_sdata;
    while (dst < &_edata) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss; dst++) {
        *dst = 0u;
    }
    /* Paint the stack area below our own frame (board_stack_used()). */
    {
        uint32_t *sp;
        __asm__ volatile("mov %0, sp" : "=r"(sp));
        for (dst = &_sstack_paint; dst < sp - 16; dst++) {
            *dst = STACK_PAINT;
        }
    }
    initialise_monitor_handles();
    exit(main());
}

unsigned long board_stack_used(void)
{
    const uint32_t *p = &_sstack_paint;
    while (p < &_estack && *p == STACK_PAINT) {
        p++;
    }
    return (unsigned long)((uintptr_t)&_estack - (uintptr_t)p);
}

/* Semihosting SYS_EXIT with "run-time error": QEMU exits with status 1. */
static void semihosting_fail(void)
{
    register uint32_t op __asm__("r0") = 0x18u;     /* SYS_EXIT */
    register uint32_t arg __asm__("r1") = 0x20023u; /* ADP_Stopped_RunTimeErrorUnknown */
    __asm__ volatile("bkpt 0xAB" : : "r"(op), "r"(arg) : "memory");
    for (;;) {
    }
}

void Fault_Handler(void)
{
    semihosting_fail();
}

void Default_Handler(void)
{
    semihosting_fail();
}
