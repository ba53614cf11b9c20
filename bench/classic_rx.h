/*
 * bench/classic_rx.h - the floor references of the receiver benchmark,
 * written here for it (not part of the library):
 *
 *   classic_rx: a classic single-state TASE parser, the way most hand-written
 *     parsers look: a switch over sync1, sync2, sync3, Size, body and the two
 *     checksum bytes, summing as it goes, no window. It is not a correct
 *     receiver for this project: after a false sync or a corrupted Size it
 *     hunts again after the bytes it consumed, so it loses the frames behind
 *     them (and it delivers a frame inside a frame only if it was hunting
 *     there). It shows what a byte costs when nothing is kept: it counts
 *     no bytes (every frame's offset is 0), the minimal parser issue 21
 *     measures against (18.7 instructions a byte on Cortex-M4 -O2 and 29.5
 *     on M0+ -Os on telemetry by the issue; this one 19.6 and 31.7 here).
 *     Until 2026-11-26 it counted the bytes fed for the offsets, as
 *     tase_rx_push() does (stats.bytes_in): 3 instructions a byte more on
 *     Cortex-M4 (23.7), which made the receiver look like 1.0x a parser
 *     that is in fact 1.2x faster on that core.
 *   store_sum: what any byte-at-a-time receiver must at least do: store the
 *     byte and add it to a sum.
 *
 * Both take one byte per call, like tase_rx_push(), so that a benchmark
 * compares the same amount of calling.
 */
#ifndef BENCH_CLASSIC_RX_H
#define BENCH_CLASSIC_RX_H

#include "tase/frame.h"

typedef struct {
    uint32_t frames; /* valid frames delivered */
    uint16_t sum;    /* running checksum of the frame so far */
    uint16_t idx;    /* body bytes stored */
    uint8_t state;
    uint8_t size; /* Size byte of the frame */
    uint8_t check_hi;
    uint8_t body[TASE_DATA_MAX + 2u]; /* Group, PktType, data */
} classic_rx_t;

void classic_rx_init(classic_rx_t *p);

/* One byte; returns 1 when it completed a valid frame (handed to on_frame,
 * which may be NULL), else 0. */
int classic_rx_push(classic_rx_t *p, uint8_t b, tase_rx_handler_t on_frame, void *user);

typedef struct {
    uint16_t len;
    uint16_t sum;
    uint8_t buf[256];
} store_sum_t;

void store_sum_push(store_sum_t *s, uint8_t b);

#endif /* BENCH_CLASSIC_RX_H */
