/*
 * Fuzz harness: the datalink receiver fed arbitrary bytes, against a
 * reference greedy scan.
 *
 * Input: 2 bytes seeding the split points, then the byte stream. The
 * stream is fed to three receivers: in random chunks (1..300 bytes), one
 * byte at a time with tase_rx_push(), and in a single call, each beside
 * the reference greedy scan of tests/rx_reference.h (slow and obvious,
 * sharing no code with src/tase_frame.c) fed one byte at a time. Checks:
 *   - after every call, within the latency bound of frame.h (the scan may
 *     lag by up to TASE_RX_LATE_MAX bytes): the frames delivered so far
 *     are the reference's first ones, every frame the reference decided
 *     more than TASE_RX_LATE_MAX bytes ago among them; bytes_in is equal,
 *     frames_ok counts the deliveries, the other counters trail the
 *     reference's; the return value equals the callbacks made by that
 *     call;
 *   - every receiver delivers exactly the reference's frames, in order:
 *     same offset, header and data, and stats.bytes_in in the callback
 *     at least the byte count at which the reference decided the frame
 *     (its own last byte, or the last byte of the earlier candidate whose
 *     failure released it) and at most TASE_RX_LATE_MAX more; and the
 *     same (seen_at included) whatever the split;
 *   - every delivered frame re-encodes to exactly the input bytes at its
 *     offset, and delivered frames never overlap (nothing inside a
 *     delivered frame is delivered);
 *   - from inside the callback, tase_rx_feed(), tase_rx_push() and
 *     tase_rx_flush() on the same receiver return TASE_EBUSY and change
 *     nothing;
 *   - after tase_rx_flush(): bytes_discarded + bytes of delivered frames ==
 *     bytes_in, and the receiver is empty and reusable;
 *   - a fourth run in random chunks with the time bound: after each chunk
 *     a tick at an unchanged clock settles nothing (it may continue a
 *     lagging scan), and now and then the line goes quiet past every
 *     limit (a tick 100 s later), where the reference fails everything
 *     pending (ref_quiet()): exactly the same frames and counters there.
 */
#include <string.h>

#include "../tests/rx_reference.h"
#include "fuzz.h"
#include "tase/frame.h"

#define MAX_INPUT 65536u
#define MAX_FRAMES (MAX_INPUT / 8u + 1u) /* delivered frames never overlap */

typedef struct {
    uint32_t offset, seen_at;
    uint8_t group, type, len;
} rec_t;

/* ---- the reference greedy scan (tests/rx_reference.h) ---------------- */

typedef struct {
    rec_t *f;
    size_t n;
} ref_out_t;

static void ref_record(void *user, const uint8_t *frame, size_t offset, size_t flen, size_t seen_at)
{
    ref_out_t *o = user;
    FZ_CHECK(o->n < MAX_FRAMES);
    o->f[o->n].offset = (uint32_t)offset;
    o->f[o->n].seen_at = (uint32_t)seen_at;
    o->f[o->n].group = frame[4];
    o->f[o->n].type = frame[5];
    o->f[o->n].len = (uint8_t)(flen - 8u);
    o->n++;
}

/* ---- the receivers ------------------------------------------------------ */

typedef struct {
    const uint8_t *stream;
    size_t stream_len;
    tase_rx_t *rx;
    size_t n; /* callbacks so far */
    rec_t *f; /* f[0..n) */
} sink_t;

static rec_t want[MAX_FRAMES], got[MAX_FRAMES], split[MAX_FRAMES];

/* got[k] is want[k], delivered within the latency bound. */
static void check_frame(size_t k)
{
    FZ_CHECK(got[k].offset == want[k].offset && got[k].group == want[k].group &&
             got[k].type == want[k].type && got[k].len == want[k].len);
    FZ_CHECK(got[k].seen_at >= want[k].seen_at &&
             got[k].seen_at - want[k].seen_at <= TASE_RX_LATE_MAX);
}

/* After a call that fed up to `pos`: see the list above. */
static void check_lag(const tase_rx_t *rx, size_t n, size_t nref, const tase_rx_stats_t *st,
                      size_t pos)
{
    size_t k;
    FZ_CHECK(n <= nref);
    for (k = 0; k < n; k++) {
        check_frame(k);
    }
    for (; k < nref; k++) {
        FZ_CHECK(pos - want[k].seen_at < TASE_RX_LATE_MAX);
    }
    FZ_CHECK(rx->stats.bytes_in == st->bytes_in && rx->stats.frames_ok == n);
    FZ_CHECK(rx->stats.checksum_errors <= st->checksum_errors &&
             rx->stats.bad_size <= st->bad_size &&
             rx->stats.bytes_discarded <= st->bytes_discarded);
}

static void on_frame(void *user, const tase_frame_t *fr)
{
    sink_t *s = user;
    uint8_t enc[TASE_FRAME_MAX];
    size_t total = (size_t)fr->len + TASE_FRAME_OVERHEAD;
    tase_rx_t before;
    int n;
    FZ_CHECK(fr->data != NULL);
    FZ_CHECK(fr->len <= TASE_DATA_MAX);
    /* the frame lies inside the bytes fed so far */
    FZ_CHECK((size_t)fr->offset + total <= (size_t)s->rx->stats.bytes_in);
    FZ_CHECK((size_t)fr->offset + total <= s->stream_len);
    n = tase_frame_build(fr->group, fr->type, fr->data, fr->len, enc, sizeof(enc));
    FZ_CHECK(n == (int)total);
    FZ_CHECK(memcmp(enc, s->stream + fr->offset, total) == 0);
    /* stream order, never inside (or overlapping) the previous one */
    FZ_CHECK(s->n == 0u || fr->offset >= s->f[s->n - 1u].offset + s->f[s->n - 1u].len + 8u);
    FZ_CHECK(s->n < MAX_FRAMES);
    s->f[s->n].offset = fr->offset;
    s->f[s->n].seen_at = s->rx->stats.bytes_in;
    s->f[s->n].group = fr->group;
    s->f[s->n].type = fr->type;
    s->f[s->n].len = fr->len;
    s->n++;
    /* re-entrant calls are refused and change nothing */
    memcpy(&before, s->rx, sizeof(before));
    FZ_CHECK(tase_rx_feed(s->rx, enc, total, on_frame, s) == TASE_EBUSY);
    FZ_CHECK(tase_rx_push(s->rx, enc[0], on_frame, s) == TASE_EBUSY);
    FZ_CHECK(tase_rx_flush(s->rx, on_frame, s) == TASE_EBUSY);
    FZ_CHECK(memcmp(&before, s->rx, sizeof(before)) == 0);
}

enum { FEED_CHUNKS, FEED_PUSH, FEED_WHOLE, FEED_QUIET };

/* Feed data[0..size) to rx in `mode` beside a reference, comparing after
 * every call; then flush and compare the frames with want[0..nwant). */
static void run(tase_rx_t *rx, const uint8_t *data, size_t size, int mode, uint32_t *seed,
                size_t nwant)
{
    sink_t sink = {data, size, rx, 0, got};
    ref_out_t out = {want, 0}; /* rewrites the frames of the first run */
    ref_t ref;
    size_t pos = 0, before, k;
    uint32_t covered = 0;
    int ret;
    uint32_t now = 0u;
    ref_init(&ref, data, ref_record, &out);
    FZ_CHECK(tase_rx_init(rx) == TASE_OK);
    FZ_CHECK(tase_rx_set_timing(rx, 5760u, 0u) == TASE_OK);
    while (pos < size) {
        size_t chunk = mode == FEED_WHOLE  ? size - pos
                       : mode == FEED_PUSH ? 1u
                                           : 1u + fz_rand(seed) % 300u;
        if (chunk > size - pos) {
            chunk = size - pos;
        }
        before = sink.n;
        if (mode == FEED_PUSH) {
            ret = tase_rx_push(rx, data[pos], on_frame, &sink);
        } else {
            ret = tase_rx_feed(rx, data + pos, chunk, on_frame, &sink);
        }
        pos += chunk;
        ref_feed_to(&ref, pos);
        FZ_CHECK(ret >= 0 && (size_t)ret == sink.n - before);
        if (mode == FEED_QUIET) {
            before = sink.n;
            ret = tase_rx_tick(rx, now, on_frame, &sink);
            FZ_CHECK(ret >= 0 && (size_t)ret == sink.n - before);
            if (fz_rand(seed) % 8u == 0u) {
                before = sink.n;
                now += 100000u;
                ret = tase_rx_tick(rx, now, on_frame, &sink);
                ref_quiet(&ref);
                FZ_CHECK(ret >= 0 && (size_t)ret == sink.n - before);
                FZ_CHECK(memcmp(&rx->stats, &ref.st, sizeof(ref.st)) == 0);
                FZ_CHECK(sink.n == out.n);
            }
        }
        check_lag(rx, sink.n, out.n, &ref.st, pos);
    }
    before = sink.n;
    ret = tase_rx_flush(rx, on_frame, &sink);
    ref_advance(&ref, true);
    FZ_CHECK(ret >= 0 && (size_t)ret == sink.n - before);
    FZ_CHECK(memcmp(&rx->stats, &ref.st, sizeof(ref.st)) == 0);
    FZ_CHECK(sink.n == out.n && (out.n == nwant || mode == FEED_QUIET));
    for (k = 0; k < sink.n; k++) {
        check_frame(k);
    }
    /* any split: the same frames at the same moments */
    if (mode == FEED_CHUNKS) {
        memcpy(split, got, sink.n * sizeof(rec_t));
    } else if (mode != FEED_QUIET) {
        FZ_CHECK(memcmp(split, got, sink.n * sizeof(rec_t)) == 0);
    }
    for (k = 0; k < sink.n; k++) {
        covered += got[k].len + 8u;
    }
    /* every byte is now either in a delivered frame or discarded */
    FZ_CHECK(rx->stats.bytes_in == (uint32_t)size);
    FZ_CHECK(rx->stats.bytes_discarded + covered == (uint32_t)size);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_rx_t rx;
    static rec_t first[MAX_FRAMES];
    ref_out_t out = {first, 0};
    ref_t ref;
    uint32_t seed;
    size_t nwant;
    int mode;
    uint8_t probe[TASE_FRAME_MAX];
    int plen;

    if (size < 2u || size - 2u > MAX_INPUT) {
        return 0;
    }
    seed = ((uint32_t)data[0] << 8) | data[1];
    data += 2;
    size -= 2u;

    /* the reference alone first: how many frames there are */
    ref_init(&ref, data, ref_record, &out);
    ref_feed_to(&ref, size);
    ref_advance(&ref, true);
    nwant = out.n;

    for (mode = FEED_CHUNKS; mode <= FEED_WHOLE; mode++) {
        run(&rx, data, size, mode, &seed, nwant);
        FZ_CHECK(memcmp(want, first, nwant * sizeof(rec_t)) == 0);
    }
    run(&rx, data, size, FEED_QUIET, &seed, nwant);

    /* flush left the receiver empty: a fresh frame is found at once, at
     * the offset that follows the input, and nothing else is */
    FZ_CHECK(rx.len == 0u && rx.end == 0u && rx.busy == 0u);
    plen = tase_frame_build(0x08, 0x10, data, size < 6u ? size : 6u, probe, sizeof(probe));
    FZ_CHECK(plen > 0);
    {
        uint32_t ok = rx.stats.frames_ok, disc = rx.stats.bytes_discarded;
        FZ_CHECK(tase_rx_feed(&rx, probe, (size_t)plen, NULL, NULL) == 1);
        FZ_CHECK(rx.stats.frames_ok == ok + 1u && rx.stats.bytes_discarded == disc);
    }
    return 0;
}
