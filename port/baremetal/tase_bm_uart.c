/* Bare-metal UART port template; see tase/bm_uart.h. */
#include "tase/bm_uart.h"

#include <limits.h>

#include "tase/port_io.h"

#define DRAIN_CHUNK 32u

int tase_bm_uart_init(tase_bm_uart_t *u, uint8_t *rx_buf, size_t cap,
                      const tase_bm_uart_hooks_t *hooks, void *hw)
{
    if (u == NULL || hooks == NULL || hooks->tx == NULL || hooks->millis == NULL) {
        return TASE_EARG;
    }
    if (hooks->idle != NULL && (hooks->irq_off == NULL || hooks->irq_on == NULL)) {
        return TASE_EARG; /* an idle hook without the mask is the lost-wakeup race */
    }
    if (tase_ring_init(&u->rx, rx_buf, cap) != TASE_OK) {
        return TASE_EARG;
    }
    u->hooks = hooks;
    u->hw = hw;
    return TASE_OK;
}

void tase_bm_uart_rx_isr(tase_bm_uart_t *u, uint8_t byte)
{
    if (u != NULL) {
        (void)tase_ring_put(&u->rx, byte);
    }
}

int tase_bm_uart_poll(tase_bm_uart_t *u, tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    uint8_t chunk[DRAIN_CHUNK];
    uint32_t budget;
    int frames = 0;

    if (u == NULL || rx == NULL) {
        return TASE_EARG;
    }
    /* A receiver that cannot take bytes (never initialised, corrupted) is
     * found before any byte leaves the ring: nothing is lost to it. */
    {
        int r = tase_rx_feed(rx, NULL, 0u, on_frame, user);
        if (r < 0) {
            return r;
        }
        frames = r; /* the probe may finish a scan the last call left pending */
    }
    budget = tase_ring_capacity(&u->rx);
    while (budget > 0) {
        size_t want = (size_t)(budget < DRAIN_CHUNK ? budget : DRAIN_CHUNK);
        size_t n = tase_ring_get(&u->rx, chunk, want);
        int r;
        if (n == 0) {
            break;
        }
        budget -= (uint32_t)n;
        r = tase_rx_feed(rx, chunk, n, on_frame, user);
        if (r < 0) {
            return r; /* e.g. a handler that corrupted the receiver */
        }
        frames += r;
    }
    /* The ring is drained (or the budget spent right after feeding): the
     * receiver's time bound hears of the activity, or of the quiet. */
    {
        int r = tase_rx_tick(rx, u->hooks->millis(u->hw), on_frame, user);
        return r < 0 ? r : frames + r;
    }
}

static int bm_write(void *ctx, const uint8_t *data, size_t n)
{
    tase_bm_uart_t *u = ctx;
    int r;
    if (u == NULL || u->hooks == NULL || (data == NULL && n > 0) || n > (size_t)INT_MAX) {
        return TASE_EARG;
    }
    r = u->hooks->tx(u->hw, data, n);
    return r < 0 ? r : (int)n;
}

static int bm_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    tase_bm_uart_t *u = ctx;
    uint32_t start;

    if (u == NULL || u->hooks == NULL || buf == NULL || cap == 0) {
        return TASE_EARG;
    }
    if (cap > (size_t)INT_MAX) {
        cap = (size_t)INT_MAX; /* the count must fit the int result */
    }
    start = u->hooks->millis(u->hw);
    for (;;) {
        size_t n = tase_ring_get(&u->rx, buf, cap);
        if (n > 0) {
            return (int)n;
        }
        if (tase_port_elapsed_ms(u->hooks->millis(u->hw), start) >= timeout_ms) {
            return 0;
        }
        if (u->hooks->idle != NULL) {
            /* Check and sleep with the interrupt masked: a byte arriving
             * after the check leaves its interrupt pending, which ends
             * the sleep at once (WFI wakes on a pending interrupt even
             * while masked); unmasking then runs it. */
            u->hooks->irq_off(u->hw);
            if (tase_ring_count(&u->rx) == 0u) {
                u->hooks->idle(u->hw);
            }
            u->hooks->irq_on(u->hw);
        }
    }
}

static uint32_t bm_now_ms(void *ctx)
{
    tase_bm_uart_t *u = ctx;
    return (u == NULL || u->hooks == NULL) ? 0u : u->hooks->millis(u->hw);
}

const tase_port_ops_t tase_bm_uart_ops = {bm_write, bm_read, bm_now_ms};

tase_port_t tase_bm_uart_port(tase_bm_uart_t *u)
{
    tase_port_t p;
    p.ops = &tase_bm_uart_ops;
    p.ctx = u;
    p.bytes_per_s = 0u; /* the UART's rate is the application's: set it */
    return p;
}
