/*
 * tests/rx_reference.h - a reference receiver for tests/test_frame.c and
 * fuzz/rx_bytes.c: the greedy scan of include/tase/frame.h ("WHICH
 * FRAMES", "LATENCY") written straight from its definition, slow and
 * obvious, sharing no code with src/tase_frame.c.
 *
 * The whole stream is at hand, and after each byte (ref_feed_to()) the
 * scan position moves over everything the bytes so far decide. Each frame
 * is reported with seen_at = the number of bytes fed when it was decided,
 * which is what the receiver's stats.bytes_in must read inside its
 * callback, however the stream is split into calls. ref_advance(r, true)
 * is end of input (tase_rx_flush()): an undecided position holds no frame;
 * ref_quiet() is a quiet time past the time bound, which decides the same.
 *
 * Static functions only: include it once per program.
 */
#ifndef TASE_TESTS_RX_REFERENCE_H
#define TASE_TESTS_RX_REFERENCE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "tase/frame.h"

/* A frame of `flen` bytes at stream offset `offset`, decided after
 * `seen_at` bytes. */
typedef void (*ref_frame_fn)(void *user, const uint8_t *frame, size_t offset, size_t flen,
                             size_t seen_at);

typedef struct {
    const uint8_t *s;
    size_t t;           /* bytes fed */
    size_t pos;         /* everything before it is decided */
    tase_rx_stats_t st; /* what the receiver's counters must read */
    ref_frame_fn on_frame;
    void *user;
} ref_t;

static void ref_init(ref_t *r, const uint8_t *s, ref_frame_fn on_frame, void *user)
{
    memset(r, 0, sizeof(*r));
    r->s = s;
    r->on_frame = on_frame;
    r->user = user;
}

/* At r->pos: 1 = a valid frame of *flen bytes, 0 = none there (the scan
 * moves on one byte; a failed candidate is counted), -1 = not decided by
 * the bytes so far. */
static int ref_at(ref_t *r, bool final, size_t *flen)
{
    static const uint8_t sync[3] = {0x00, 0xFF, 0x5A};
    const uint8_t *s = r->s + r->pos;
    size_t avail = r->t - r->pos;
    size_t i;
    uint32_t sum = 0;
    for (i = 0; i < 3u; i++) {
        if (i == avail) {
            return final ? 0 : -1;
        }
        if (s[i] != sync[i]) {
            return 0;
        }
    }
    if (avail == 3u) {
        return final ? 0 : -1;
    }
    if (s[3] < 2u) {
        r->st.bad_size++;
        return 0;
    }
    *flen = (size_t)s[3] + 6u;
    if (*flen > avail) {
        return final ? 0 : -1;
    }
    for (i = 0; i + 2u < *flen; i++) {
        sum += s[i];
    }
    if ((sum & 0xFFFFu) != (((uint32_t)s[*flen - 2u] << 8) | s[*flen - 1u])) {
        r->st.checksum_errors++;
        return 0;
    }
    return 1;
}

static void ref_advance(ref_t *r, bool final)
{
    size_t flen = 0;
    int k;
    while (r->pos < r->t && (k = ref_at(r, final, &flen)) >= 0) {
        if (k == 0) {
            r->st.bytes_discarded++;
            r->pos++;
            continue;
        }
        r->st.frames_ok++;
        r->on_frame(r->user, r->s + r->pos, r->pos, flen, r->t);
        r->pos += flen;
    }
}

/* Feed the reference up to byte `upto`, one byte at a time. */
static void ref_feed_to(ref_t *r, size_t upto)
{
    while (r->t < upto) {
        r->t++;
        r->st.bytes_in++;
        ref_advance(r, false);
    }
}

/* A quiet time longer than the quiet limit of whatever is pending
 * (frame.h, TIME BOUND): everything pending fails, as at end of input,
 * and the stream goes on. */
static void ref_quiet(ref_t *r)
{
    ref_advance(r, true);
}

#endif /* TASE_TESTS_RX_REFERENCE_H */
