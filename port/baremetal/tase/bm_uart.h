/*
 * tase/bm_uart.h - bare-metal UART port TEMPLATE for microcontrollers:
 * an RX interrupt fills a tase_ring_t (tase/ring.h), the main loop drains
 * it, and transmission goes through a blocking TX hook. It implements
 * tase_port_ops_t (tase/port.h), so the host and gimbal roles run on it
 * unchanged. Copy it next to your UART driver, or use it as it is and
 * supply the three hooks.
 *
 * WIRING IT UP (e.g. STM32 USART, any Cortex-M):
 *
 *     static uint8_t rx_storage[512];                // power of two
 *     static tase_bm_uart_t com3;
 *     static const tase_bm_uart_hooks_t com3_hooks = {my_tx, my_millis, my_wfi,
 *                                                     my_irq_off, my_irq_on};
 *     tase_bm_uart_init(&com3, rx_storage, sizeof rx_storage, &com3_hooks, USART3);
 *     // then enable the RXNE interrupt:
 *     void USART3_IRQHandler(void) {
 *         while (USART3->ISR & USART_ISR_RXNE)
 *             tase_bm_uart_rx_isr(&com3, (uint8_t)USART3->RDR);
 *     }
 *     // main loop: tase_bm_uart_poll(&com3, &rx, on_frame, user);
 *     //       or: tase_gimbal_service(&g, now) with tase_bm_uart_port(&com3)
 *
 * CONTEXTS: tase_bm_uart_rx_isr() is the ring's producer: call it only
 * from the one RX interrupt of this UART. Everything else (poll, the
 * port's read/write/now_ms) is the consumer side: call it only from the
 * main loop (one context). tase_bm_uart_init() runs before the interrupt
 * is enabled. The ring's memory-ordering rules and the TASE_RING_BARRIER()
 * hook are explained in tase/ring.h.
 *
 * The port functions (tase_bm_uart_ops):
 *  write   calls hooks->tx(hw, data, n), which must send all bytes
 *          (blocking on the TX-empty flag, or queue them to a TX ring/DMA)
 *          and return 0, or a negative TASE_E* code (passed on; TASE_EAGAIN
 *          for a full TX ring makes tase_port_write_all() retry until its
 *          deadline). The hook's longest block is this port's write
 *          bound W (tase/port.h): n bytes at the line rate. Returns n,
 *          or TASE_EARG (ctx NULL or not initialised, data NULL with
 *          n > 0, n > INT_MAX, the largest int result: INT32_MAX on a
 *          32-bit core; the hook is not called).
 *  read    takes what the ring holds; if empty, waits until bytes arrive
 *          or timeout_ms passes on hooks->millis() (wrap- and stale-safe),
 *          spinning if idle is NULL, else sleeping race-free:
 *              irq_off(hw);                    // __disable_irq()
 *              if (ring empty) idle(hw);       // __WFI()
 *              irq_on(hw);                     // __enable_irq()
 *          A byte that arrives after the emptiness check cannot be missed:
 *          its interrupt stays pending while masked, and a pending
 *          interrupt ends WFI even while PRIMASK masks it (Cortex-M), so
 *          the core does not sleep on until the next, unrelated interrupt.
 *          (Calling __WFI() after an unmasked check is the classic
 *          lost-wakeup race: init refuses an idle hook without
 *          irq_off/irq_on.) Sleeping ends on any interrupt; the timeout
 *          needs one that ticks, e.g. SysTick. Returns the count (0:
 *          timeout), or TASE_EARG (ctx NULL or not initialised, buf NULL,
 *          cap 0). A cap above INT_MAX reads at most INT_MAX bytes.
 *  now_ms  hooks->millis(hw) (a SysTick millisecond counter); 0 for ctx
 *          NULL or not initialised.
 */
#ifndef TASE_BM_UART_H
#define TASE_BM_UART_H

#include "tase/frame.h"
#include "tase/port.h"
#include "tase/ring.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    /* Transmit n bytes (blocking, or queued for an interrupt/DMA). Returns
     * 0 when all were taken, a negative TASE_E* code otherwise. Its
     * longest block is the port's write bound W. Required. */
    int (*tx)(void *hw, const uint8_t *data, size_t n);
    /* Monotonic milliseconds (modulo 2^32). Required, and it must run:
     * read() of an empty ring waits on it, so with a clock that stands
     * still (SysTick not started) it waits until a byte comes, for ever
     * on a silent line (with idle set, asleep). */
    uint32_t (*millis)(void *hw);
    /* Sleep until an interrupt is pending, e.g. __WFI(). Called by read()
     * only between irq_off() and irq_on(), after it found the ring empty
     * with the interrupt masked; it must NOT unmask. NULL: read()
     * busy-waits (and irq_off/irq_on are not needed). */
    void (*idle)(void *hw);
    /* Mask / unmask the RX interrupt (or all: __disable_irq() and
     * __enable_irq()). Required when idle is set. */
    void (*irq_off)(void *hw);
    void (*irq_on)(void *hw);
} tase_bm_uart_hooks_t;

typedef struct {
    tase_ring_t rx;                    /* filled by the ISR */
    const tase_bm_uart_hooks_t *hooks; /* not copied: keep it alive */
    void *hw;                          /* passed to the hooks */
} tase_bm_uart_t;

extern const tase_port_ops_t tase_bm_uart_ops;

/* Set up u with receive storage rx_buf[0..cap) (power of two) and hooks.
 * Returns TASE_OK or TASE_EARG (NULL argument, hooks without tx or
 * millis, idle without irq_off and irq_on, cap not a power of two). Call
 * before enabling the interrupt. */
int tase_bm_uart_init(tase_bm_uart_t *u, uint8_t *rx_buf, size_t cap,
                      const tase_bm_uart_hooks_t *hooks, void *hw);

/* RX INTERRUPT ONLY: one received byte. Drops and counts it when the ring
 * is full (tase_ring_overflows(&u->rx)); ignored for u NULL. O(1). */
void tase_bm_uart_rx_isr(tase_bm_uart_t *u, uint8_t byte);

/* MAIN LOOP: drain everything the ring holds into a frame receiver, in
 * chunks of 32 bytes. Returns the number of frames delivered (>= 0), or
 * TASE_EARG (u or rx NULL), or the receiver's error: tase_rx_feed()'s
 * TASE_EARG for a receiver that is not initialised or was corrupted
 * (checked before any byte leaves the ring, so none is lost; if a frame
 * handler corrupts it midway, the chunk being fed is lost and the rest
 * stays in the ring). Bounded: stops after one ring capacity's worth of
 * bytes even if the ISR keeps adding, so the main loop cannot be
 * starved. Then ticks the receiver (tase_rx_tick() with hooks->millis()):
 * after draining, its time bound hears that the line was active or has
 * been quiet (tase/frame.h, TIME BOUND): noise that leaves a candidate
 * held cannot keep the frames after it from being delivered for longer
 * than the bound, provided poll runs at least every few milliseconds. Set
 * the receiver's byte rate with tase_rx_set_timing(). */
int tase_bm_uart_poll(tase_bm_uart_t *u, tase_rx_t *rx, tase_rx_handler_t on_frame, void *user);

/* The tase_port_t of u: {&tase_bm_uart_ops, u, 0}. The template does not
 * know the UART's baud rate: set the port's bytes_per_s yourself
 * (p.bytes_per_s = TASE_UART_BYTES_PER_S(57600)) so that the roles size
 * the receiver's time bound and the gimbal's telemetry capacity by it;
 * left 0, they assume the spec's slowest line (9600 baud). */
tase_port_t tase_bm_uart_port(tase_bm_uart_t *u);

#ifdef __cplusplus
}
#endif

#endif /* TASE_BM_UART_H */
