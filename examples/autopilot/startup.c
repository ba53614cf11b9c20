/* Cortex-M4F startup for QEMU's mps2-an386: vector table with SysTick and
 * the UART0 receive interrupt, a reset handler that turns the FPU on and
 * sets up the C environment (data, bss, stack paint, semihosting stdio),
 * and fault handlers that end the run with a failure status. The memory
 * map and its symbols come from examples/firmware/mps2-an385.ld (AN385 and
 * AN386 share it). */
#include <stdint.h>
#include <stdlib.h>

#include "board.h"

extern uint32_t _estack, _sidata, _sdata, _edata, _sbss, _ebss, _sstack_paint;
extern int main(void);
extern void initialise_monitor_handles(void); /* newlib rdimon */

#define STACK_PAINT 0xA5C35A3Cu
#define SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define CPACR_CP10_CP11_FULL (0xFu << 20)

void Reset_Handler(void);
void Fault_Handler(void);

typedef void (*vector_t)(void);

/* 16 core exceptions, then external interrupt 0 (UART0 RX); a zero entry
 * is an interrupt this image never enables. */
__attribute__((section(".isr_vector"), used)) const vector_t vector_table[16 + 1] = {
    (vector_t)(uintptr_t)&_estack,
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0,
    0,
    0,
    0,
    Fault_Handler, /* SVCall */
    Fault_Handler, /* DebugMonitor */
    0,
    Fault_Handler, /* PendSV */
    SysTick_Handler,
    UART0_RX_Handler, /* IRQ 0 */
};

void Reset_Handler(void)
{
    uint32_t *src = &_sidata, *dst, *sp;

    /* Full access to CP10/CP11 before any floating-point instruction. */
    SCB_CPACR |= CPACR_CP10_CP11_FULL;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    for (dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (dst = &_sbss; dst < &_ebss; dst++) {
        *dst = 0u;
    }
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (dst = &_sstack_paint; dst < sp - 16; dst++) {
        *dst = STACK_PAINT;
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

/* Semihosting SYS_EXIT, "run-time error": QEMU exits with status 1. */
void Fault_Handler(void)
{
    register uint32_t op __asm__("r0") = 0x18u;
    register uint32_t arg __asm__("r1") = 0x20023u;
    __asm__ volatile("bkpt 0xAB" : : "r"(op), "r"(arg) : "memory");
    for (;;) {
    }
}
