/*
 * The receiver's set-up and its time bound (include/tase/frame.h, TIME
 * BOUND): tase_rx_init() and tase_rx_stats_reset(), which also set and
 * reset the time bound's state, tase_rx_set_timing(), tase_rx_tick() and
 * tase_rx_quiet_ms(); and tase_rx_stop(). A settle is the end of input of
 * the scan in src/tase_frame.c, reached through tase_rx_continue().
 */
#include "tase/frame.h"

#include <string.h>

#include "tase_frame_private.h"

/* `ticked` while a settling tick stopped by its callback (tase_rx_stop())
 * has not finished: the next tick settles the rest. */
#define RX_SETTLING 2u

int tase_rx_init(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    /* Clears `busy` too: a call whose callback re-initialises the receiver
     * sees that and returns without touching it again. */
    (void)memset(rx, 0, sizeof(*rx));
    rx->margin_ms = (uint16_t)TASE_RX_QUIET_MS;
    return TASE_OK;
}

/* The call in progress ends after the frame its callback is handling:
 * advance() in src/tase_frame.c looks at `stop`, finish() clears it. */
int tase_rx_stop(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    if (rx->busy != 1u) {
        return TASE_ESTATE;
    }
    rx->stop = 1u;
    return TASE_OK;
}

int tase_rx_stats_reset(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    /* The scan's credit counts bytes since bank_at (src/tase_frame.c) and
     * the time bound bytes since the last tick (tick_bytes): both move
     * with the count, so that a reset (from a callback too) changes
     * nothing of when frames come out. */
    rx->bank_at = (uint16_t)(rx->bank_at - rx->stats.bytes_in);
    rx->tick_bytes -= rx->stats.bytes_in;
    (void)memset(&rx->stats, 0, sizeof(rx->stats));
    return TASE_OK;
}

int tase_rx_set_timing(tase_rx_t *rx, uint32_t bytes_per_s, uint16_t margin_ms)
{
    int r = tase_rx_state_check(rx);
    if (r == TASE_OK) {
        rx->rate = bytes_per_s;
        rx->margin_ms = (margin_ms != 0u) ? margin_ms : (uint16_t)TASE_RX_QUIET_MS;
    }
    return r;
}

/* The quiet limit of what the window holds (frame.h, TIME BOUND): the
 * time its remaining bytes need at the link's rate, or the margin. The
 * remaining bytes run to the held candidate's last byte, or, for a partial
 * sync, to the last byte of a maximal frame beginning at the scan
 * position. A scan not caught up has not found the candidate it will
 * hold: one may begin at any byte it has not reached, the last one too,
 * so a whole maximal frame's time (a review: counted from the lagging
 * scan position, the limit shrank to the margin, and a real frame whose
 * first bytes came behind a burst was settled away mid-pause). */
static uint32_t quiet_limit(const tase_rx_t *rx)
{
    uint32_t rate = (rx->rate != 0u) ? rx->rate : TASE_RX_SLOWEST_RATE;
    uint32_t last = (rx->end != 0u && rx->end != RX_BLOCKED) ? (uint32_t)rx->end + 1u
                                                             : (uint32_t)rx->scan + TASE_FRAME_MAX;
    uint32_t left = (last > rx->len) ? last - rx->len : 0u;
    uint32_t ms;
    if (rx->lag != 0u) {
        left = TASE_FRAME_MAX;
    }
    ms = (left * 1000u + rate - 1u) / rate; /* at most 261,000 / 1 */
    return (ms > rx->margin_ms) ? ms : rx->margin_ms;
}

/* Milliseconds from `since` to `now`; 0 for a sample older than `since`
 * (a difference of 2^31 or more, the port contract's "not yet"). */
static uint32_t quiet_for(uint32_t now, uint32_t since)
{
    uint32_t d = now - since;
    return (d >= 0x80000000u) ? 0u : d;
}

int tase_rx_tick(tase_rx_t *rx, uint32_t now_ms, tase_rx_handler_t on_frame, void *user)
{
    int r = tase_rx_state_check(rx);
    bool settle = false;
    if (r != TASE_OK) {
        return r;
    }
    if (rx->ticked == 0u || rx->stats.bytes_in != rx->tick_bytes) {
        rx->ticked = 1u;
        rx->tick_bytes = rx->stats.bytes_in;
        rx->quiet_since = now_ms;
    } else if (rx->ticked == RX_SETTLING) {
        settle = true; /* a settle a callback stopped goes on (tase_rx_stop()) */
    } else {
        settle = rx->len != 0u && quiet_for(now_ms, rx->quiet_since) > quiet_limit(rx);
    }
    if (!settle && rx->lag == 0u) {
        return 0;
    }
    /* a lagging scan goes on; past the quiet limit, as at end of input.
     * A settle marks `ticked` first: a callback that re-initialises rx
     * clears it (and may tick the new receiver: never to RX_SETTLING
     * unless its own settle was stopped), so that the end below leaves a
     * re-initialised receiver alone (a review: it set RX_SETTLING on the
     * new one, whose next tick then settled a frame still arriving). */
    if (settle) {
        rx->ticked = RX_SETTLING;
    }
    r = tase_rx_continue(rx, settle, on_frame, user);
    if (settle && rx->ticked == RX_SETTLING && (r < 0 || rx->lag == 0u)) {
        rx->ticked = 1u; /* done; stopped before it was, the next tick settles the rest */
    }
    return r;
}

uint32_t tase_rx_quiet_ms(const tase_rx_t *rx, uint32_t now_ms)
{
    uint32_t limit;
    uint32_t quiet;
    if (rx == NULL || rx->len == 0u) {
        return UINT32_MAX;
    }
    if (rx->ticked == 0u || rx->stats.bytes_in != rx->tick_bytes || rx->lag != 0u) {
        return 0u;
    }
    limit = quiet_limit(rx);
    quiet = quiet_for(now_ms, rx->quiet_since);
    /* a tick settles once the quiet time is past the limit: one ms more */
    return (quiet > limit) ? 0u : limit - quiet + 1u;
}
