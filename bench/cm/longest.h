/*
 * bench/cm/longest.h - the longest single receiver call over a stream,
 * with an exact count (bench_cm.c, THE CLOCK): used by bench_cm.c and
 * search.c.
 */
#ifndef BENCH_CM_LONGEST_H
#define BENCH_CM_LONGEST_H

#include <stddef.h>
#include <stdint.h>

#include "tase/frame.h"

/* One call of the receiver *rx (the program's own) on p[0..n): a wrapper
 * around tase_rx_push() or tase_rx_feed(), out of line, so that every
 * call measured goes through the same code. */
typedef int (*longest_call_fn)(const uint8_t *p, size_t n);

typedef struct {
    unsigned long insns; /* the longest call's exact count */
    size_t call;         /* its index (0: the first call) */
    size_t exact;        /* calls counted exactly */
    size_t candidates;   /* calls whose coarse count was within a tick of the largest */
} longest_t;

/* Feed stream[0..n) to a fresh *rx in `chunk`-byte calls of f twice: the
 * first pass counts every call to a tick (40 instructions, into
 * coarse[0..n / chunk + 1)), the second counts exactly, from the state
 * before it, each call within a tick of the largest (the first max_exact
 * of them: no other can be longer). Argument setup and branch of the
 * caller included. */
longest_t longest_call(tase_rx_t *rx, longest_call_fn f, const uint8_t *stream, size_t n,
                       size_t chunk, uint16_t *coarse, size_t max_exact);

#endif /* BENCH_CM_LONGEST_H */
