/*
 * board.h - the autopilot example's board layer for QEMU's mps2-an386
 * (Cortex-M4F at 25 MHz): UART0 (an ARM CMSDK APB UART) with its receive
 * interrupt feeding the library's bare-metal ring, a millisecond clock,
 * a 1 kHz SysTick wake-up, and the stack high-water mark.
 *
 * CLOCK. SysTick interrupts every millisecond to wake the main loop, but
 * the clock is not a count of them: under QEMU without -icount, a busy
 * host delays the timer and QEMU then raises one SysTick interrupt for
 * several periods (measured: 11.0 s of ticks in 17.5 s of run with three
 * busy loops on two cores). The milliseconds come from TIMER0, a CMSDK
 * APB timer counting the 25 MHz clock down from 0xFFFFFFFF, whose value
 * QEMU computes from the host clock when it is read; board_millis()
 * extends it past its 171 s wrap. On real hardware either would do.
 *
 * The UART is the link to the gimbal. Under QEMU it is wired to tase-sim's
 * pseudo-terminal (-chardev serial,path=<link> -serial chardev:...), so the
 * bytes move at the pace of the real simulator on the host's real clock.
 */
#ifndef AUTOPILOT_BOARD_H
#define AUTOPILOT_BOARD_H

#include <stddef.h>
#include <stdint.h>

#include "tase/bm_uart.h"

#define BOARD_CPU_HZ 25000000u /* mps2-an386 system clock */
/* UART0 is wired to the gimbal's Com3, port 2 of its PACKET_RATE (main.c GIMBAL_PORT), at
 * 57600 baud (spec 3.1): BAUDDIV = 25 MHz / 57600. One constant for the
 * line, its byte rate (main.c) and the comments (a review: the UART was
 * programmed for 115200 while main.c sized the time bound for 57600; QEMU
 * ignores the rate, a real Com3 would have read garbage). */
#define BOARD_BAUD 57600u
/* 11 byte times at BOARD_BAUD, rounded up (2 ms at 57600) */
#define BOARD_TX_TIMEOUT_MS ((110000u + BOARD_BAUD - 1u) / BOARD_BAUD)

/* Board counters, written by the interrupts and the TX hook. */
typedef struct {
    uint32_t ticks;       /* SysTick interrupts taken */
    uint32_t rx_irqs;     /* UART0 receive interrupts taken */
    uint32_t rx_overruns; /* bytes the UART lost (RX overrun flag) */
    uint32_t tx_timeouts; /* writes abandoned: TX stayed full too long */
} board_stats_t;

/* Start TIMER0 (the clock), SysTick (1 kHz) and UART0 (BOARD_BAUD 8N1, receive interrupt), and
 * route every received byte to tase_bm_uart_rx_isr(uart, byte). uart must
 * be initialised (tase_bm_uart_init) and outlive the program. */
void board_init(tase_bm_uart_t *uart);

/* Milliseconds since board_init, from TIMER0. Main loop only (it keeps
 * the extension's state); call it at least every 171 s. The bm_uart
 * millis hook. */
uint32_t board_millis(void *hw);

/* Send n bytes on UART0, waiting on the TX-full flag before each byte;
 * gives up after BOARD_TX_TIMEOUT_MS without progress (TASE_EIO). The
 * bm_uart tx hook: returns 0 or TASE_EIO. */
int board_uart_tx(void *hw, const uint8_t *data, size_t n);

/* Sleep until an interrupt (SysTick or UART0 receive) has been taken
 * since the previous call, without the lost-wakeup race: the flag the
 * handlers set is tested with interrupts masked, and WFI wakes on a
 * pending interrupt even then. */
void board_sleep(void);

/* The counters above (a snapshot). */
board_stats_t board_stats(void);

/* Deepest stack use so far in bytes: the reset handler paints the stack
 * area, this finds the lowest word overwritten. */
unsigned long board_stack_used(void);

/* Stop SysTick and the UART interrupt (before printing the summary). */
void board_stop(void);

/* Exception handlers named in the vector table (startup.c). */
void SysTick_Handler(void);
void UART0_RX_Handler(void);

#endif /* AUTOPILOT_BOARD_H */
