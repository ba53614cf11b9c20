/* Tests of the circular-DMA receive helper (port/baremetal, tase/bm_dma.h):
 * a simulated DMA writes a stream of frames and noise round a buffer of
 * random size in random steps; polling at random points gives exactly the
 * frames of one whole feed (offsets and counters included), laps are
 * reported and cost only the bytes overwritten. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/bm_dma.h"
#include "tase/frame.h"

#define STREAM_MAX 20000u
#define LOG_MAX 4000u

typedef struct {
    uint32_t offset;
    uint8_t group, type, len;
    uint16_t sum; /* of the data */
} seen_t;

typedef struct {
    seen_t f[LOG_MAX];
    size_t n;
} log_t;

static void on_frame(void *user, const tase_frame_t *f)
{
    log_t *l = user;
    seen_t *s;
    assert_true(l->n < LOG_MAX);
    s = &l->f[l->n++];
    s->offset = f->offset;
    s->group = f->group;
    s->type = f->type;
    s->len = f->len;
    s->sum = tase_checksum(0, f->data, f->len);
}

static uint32_t rng_state;
static uint32_t rnd(uint32_t n)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (rng_state >> 8) % n;
}

/* Frames (some with corrupted Size bytes or checksums) and noise. */
static size_t make_stream(uint8_t *s, size_t cap)
{
    size_t n = 0;
    while (n + TASE_FRAME_MAX + 16u < cap) {
        uint8_t d[TASE_DATA_MAX];
        size_t len = rnd(40u);
        size_t k;
        int m;
        for (k = 0; k < len; k++) {
            d[k] = (uint8_t)rnd(256u);
        }
        m = tase_frame_build((uint8_t)rnd(256u), (uint8_t)rnd(256u), d, len, &s[n], cap - n);
        assert_true(m > 0);
        if (rnd(8u) == 0u) {
            s[n + 3] = (uint8_t)(s[n + 3] + 1u + rnd(200u)); /* Size corrupted upwards */
        } else if (rnd(8u) == 0u) {
            s[n + (size_t)m - 1u] ^= 0x40u; /* checksum */
        }
        n += (size_t)m;
        for (k = rnd(6u); k > 0u; k--) {
            s[n++] = (uint8_t)(rnd(4u) == 0u ? 0x00u : rnd(256u)); /* noise, some 00 */
        }
    }
    return n;
}

static void assert_same(const log_t *a, const log_t *b)
{
    size_t i;
    assert_int_equal(a->n, b->n);
    for (i = 0; i < a->n; i++) {
        assert_int_equal(a->f[i].offset, b->f[i].offset);
        assert_int_equal(a->f[i].group, b->f[i].group);
        assert_int_equal(a->f[i].type, b->f[i].type);
        assert_int_equal(a->f[i].len, b->f[i].len);
        assert_int_equal(a->f[i].sum, b->f[i].sum);
    }
}

/* The DMA: writes stream bytes round buf; `written` counts them all. */
typedef struct {
    uint8_t *buf;
    uint32_t size, written;
} dma_t;

static void dma_write(dma_t *d, const uint8_t *s, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        d->buf[(d->written + i) % d->size] = s[d->written + i];
    }
    d->written += n;
}

static void any_split_gives_the_frames_of_one_feed(void **state)
{
    static uint8_t stream[STREAM_MAX];
    static uint8_t buf[300];
    static log_t whole, got;
    unsigned run;
    (void)state;
    rng_state = 12345u;
    for (run = 0; run < 40u; run++) {
        size_t n = make_stream(stream, 1000u + rnd(STREAM_MAX - 1000u));
        tase_rx_t ref, rx;
        tase_bm_dma_t rd;
        dma_t dma = {buf, 1u + rnd(sizeof buf), 0};
        uint32_t now = 0;
        int frames = 0;
        int r;

        whole.n = got.n = 0;
        (void)tase_rx_init(&ref);
        assert_true(tase_rx_feed(&ref, stream, n, on_frame, &whole) >= 0);
        assert_true(tase_rx_flush(&ref, on_frame, &whole) >= 0);

        (void)tase_rx_init(&rx);
        assert_int_equal(tase_bm_dma_init(&rd, buf, dma.size), TASE_OK);
        while (dma.written < n) {
            /* at most a whole buffer between polls: never an overrun */
            uint32_t step = 1u + rnd(dma.size);
            if (step > n - dma.written) {
                step = (uint32_t)(n - dma.written);
            }
            dma_write(&dma, stream, step);
            r = tase_bm_dma_poll(&rd, dma.written, now, &rx, on_frame, &got);
            assert_true(r >= 0);
            frames += r;
        }
        r = tase_rx_flush(&rx, on_frame, &got);
        frames += r;
        assert_same(&whole, &got);
        assert_int_equal((size_t)frames, got.n);
        assert_int_equal(rd.stats.bytes_fed, n);
        assert_int_equal(rd.stats.overruns, 0);
        assert_memory_equal(&rx.stats, &ref.stats, sizeof rx.stats);
    }
}

/* A lap between two polls: counted, the overwritten bytes lost (and only
 * those), the frames before and after the gap delivered. */
static void a_lap_is_reported_and_loses_only_what_was_overwritten(void **state)
{
    static uint8_t stream[4096];
    static uint8_t buf[64];
    static log_t got, want;
    uint8_t d[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    tase_rx_t rx, ref;
    tase_bm_dma_t rd;
    dma_t dma = {buf, sizeof buf, 0};
    size_t n = 0;
    unsigned i;
    int r;
    (void)state;
    for (i = 0; i < 60u; i++) { /* 16-byte frames, type = index */
        d[0] = (uint8_t)i;
        n += (size_t)tase_frame_build(0x08, (uint8_t)i, d, 8, &stream[n], sizeof stream - n);
    }
    got.n = want.n = 0;
    (void)tase_rx_init(&rx);
    assert_int_equal(tase_bm_dma_init(&rd, buf, sizeof buf), TASE_OK);
    /* 3 frames, polled; then 200 bytes at once (a lap: 200 > 64); then 64 */
    dma_write(&dma, stream, 48);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 1, &rx, on_frame, &got), 3);
    dma_write(&dma, stream, 200);
    r = tase_bm_dma_poll(&rd, dma.written, 2, &rx, on_frame, &got);
    assert_int_equal(r, 0);
    assert_int_equal(rd.stats.overruns, 1);
    assert_int_equal(rd.stats.lost_bytes, 200);
    assert_int_equal(rd.stats.bytes_fed, 48);
    dma_write(&dma, stream, 64); /* bytes 248..312: frame 15 from 248 is cut, 16..18 whole */
    r = tase_bm_dma_poll(&rd, dma.written, 3, &rx, on_frame, &got);
    assert_true(r >= 0);
    assert_int_equal(tase_rx_flush(&rx, on_frame, &got), 0);
    /* the reference: the same bytes without the lost ones, flushed at the gap */
    (void)tase_rx_init(&ref);
    assert_int_equal(tase_rx_feed(&ref, stream, 48, on_frame, &want), 3);
    assert_int_equal(tase_rx_flush(&ref, on_frame, &want), 0);
    assert_true(tase_rx_feed(&ref, &stream[248], 64, on_frame, &want) >= 0);
    assert_int_equal(tase_rx_flush(&ref, on_frame, &want), 0);
    assert_same(&want, &got);
    assert_int_equal(got.n, 3u + 3u); /* 0..2, then 16..18: 248 cuts frame 15, 312 frame 19 */
    assert_int_equal(got.f[3].type, 16);
    assert_int_equal(rd.stats.bytes_fed, 48u + 64u);
    /* exactly one buffer between polls is no lap: bytes 312..376 give
     * frames 20..22 (the start of 19 went with the flush above) */
    dma_write(&dma, stream, 64);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 4, &rx, on_frame, &got), 3);
    assert_int_equal(got.f[6].type, 20);
    assert_int_equal(rd.stats.overruns, 1);
}

/* The DMA as hardware runs it: its index is its whole count modulo the
 * size, also past 2^32 (a 64-bit count here); the stream repeats a
 * 256-byte period of sixteen 16-byte frames. */
typedef struct {
    uint8_t *buf;
    uint32_t size;
    uint64_t total;
    const uint8_t *s;
} dma64_t;

static void dma64_write(dma64_t *d, uint32_t n)
{
    uint32_t i;
    for (i = 0; i < n; i++) {
        d->buf[(d->total + i) % d->size] = d->s[(d->total + i) % 256u];
    }
    d->total += n;
}

/* Polls of 40 bytes, `polls` of them: the frames delivered. */
static unsigned dma64_run(dma64_t *d, tase_bm_dma_t *rd, tase_rx_t *rx, log_t *got, unsigned polls)
{
    unsigned k, frames = 0;
    for (k = 0; k < polls; k++) {
        int r;
        dma64_write(d, 40);
        r = tase_bm_dma_poll(rd, (uint32_t)d->total, k, rx, on_frame, got);
        assert_true(r >= 0);
        frames += (unsigned)r;
    }
    return frames;
}

/* A review, at a buffer size that does not divide 2^32 (100): a reader
 * 2^31 bytes or more behind took the sample for a stale one and read
 * nothing, uncounted, for another 2^31 bytes; and after the count wrapped
 * at 2^32 an overrun resumed at `written % size`, which is no longer the
 * DMA's index: the reader stayed at the wrong place for good (599 of 1000
 * frames). */
static void overruns_far_behind_and_past_2_32_resume_at_the_dmas_index(void **state)
{
    static uint8_t period[256];
    static uint8_t buf[100];
    static log_t got;
    uint8_t d[8] = {0};
    dma64_t dma = {buf, sizeof buf, 0, period};
    tase_bm_dma_t rd;
    tase_rx_t rx;
    unsigned i, frames;
    (void)state;
    for (i = 0; i < 16u; i++) {
        d[0] = (uint8_t)i;
        assert_int_equal(tase_frame_build(0x08, (uint8_t)i, d, 8, &period[16u * i], 16), 16);
    }
    got.n = 0;
    (void)tase_rx_init(&rx);
    assert_int_equal(tase_bm_dma_init(&rd, buf, sizeof buf), TASE_OK);
    /* the DMA ran on alone for 2^31 bytes (`written` 2^31 behind the
     * reader reads as far ahead: the farthest overrun), then for another
     * 2^31 - 1000 (2^32 - 1000 in all: in one step it would read as 1000
     * behind, a stale sample) */
    dma.total = 0x80000000u - 300u;
    dma64_write(&dma, 300);
    assert_true(tase_bm_dma_poll(&rd, (uint32_t)dma.total, 0, &rx, on_frame, &got) >= 0);
    assert_int_equal(rd.stats.overruns, 1);
    assert_true(rd.stats.lost_bytes == 0x80000000u);
    dma.total = 0x100000000u - 1000u - 300u;
    dma64_write(&dma, 300);
    assert_true(tase_bm_dma_poll(&rd, (uint32_t)dma.total, 0, &rx, on_frame, &got) >= 0);
    assert_int_equal(rd.stats.overruns, 2);
    assert_true(rd.stats.lost_bytes == 0x100000000u - 1000u);
    frames = dma64_run(&dma, &rd, &rx, &got, 50); /* 2,000 bytes: across 2^32 */
    assert_true(frames >= 2000u / 16u - 2u);
    assert_true(dma.total > 0x100000000u);
    /* an overrun after the wrap: the reader resumes at the DMA's index */
    dma64_write(&dma, 350);
    assert_true(tase_bm_dma_poll(&rd, (uint32_t)dma.total, 60, &rx, on_frame, &got) >= 0);
    assert_int_equal(rd.stats.overruns, 3);
    frames = dma64_run(&dma, &rd, &rx, &got, 100); /* 4,000 bytes */
    assert_true(frames >= 4000u / 16u - 2u);
    assert_int_equal(rd.stats.overruns, 3);
    /* and every frame delivered is one of the stream's (data[0] = type) */
    for (i = 0; i < got.n; i++) {
        assert_int_equal(got.f[i].group, 0x08);
        assert_int_equal(got.f[i].len, 8);
        assert_int_equal(got.f[i].sum, got.f[i].type);
    }
}

/* The reader's state (its stats included) is what it was. */
static void assert_unchanged(const tase_bm_dma_t *a, const tase_bm_dma_t *b)
{
    assert_ptr_equal(a->buf, b->buf);
    assert_int_equal(a->size, b->size);
    assert_int_equal(a->pos, b->pos);
    assert_int_equal(a->read, b->read);
    assert_int_equal(a->stats.bytes_fed, b->stats.bytes_fed);
    assert_int_equal(a->stats.overruns, b->stats.overruns);
    assert_int_equal(a->stats.lost_bytes, b->stats.lost_bytes);
}

/* A review: a sample more than `size` (but under 2^31) behind the reader
 * (a lap count read one lap off) was taken for an overrun of about 2^32
 * bytes (lost_bytes + 4294967231 at 65 behind on 64 bytes), moved the
 * reader back to it, and the next good sample, 10 bytes on, was a second
 * overrun. Any sample behind is stale: nothing read, nothing counted. */
static void a_sample_behind_by_under_2_31_is_stale_however_far(void **state)
{
    static uint8_t stream[1024];
    static uint8_t buf[64];
    static log_t got;
    uint8_t d[8] = {0};
    tase_rx_t rx;
    tase_bm_dma_t rd, was;
    dma_t dma = {buf, sizeof buf, 0};
    uint32_t in;
    size_t n = 0;
    unsigned i;
    (void)state;
    for (i = 0; i < 60u; i++) { /* 16-byte frames, type = index */
        d[0] = (uint8_t)i;
        n += (size_t)tase_frame_build(0x08, (uint8_t)i, d, 8, &stream[n], sizeof stream - n);
    }
    got.n = 0;
    (void)tase_rx_init(&rx);
    assert_int_equal(tase_bm_dma_init(&rd, buf, sizeof buf), TASE_OK);
    dma_write(&dma, stream, 48);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 0, &rx, on_frame, &got), 3);
    dma_write(&dma, stream, 54); /* frames 3..5 and 6 bytes of frame 6 */
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 0, &rx, on_frame, &got), 3);
    assert_int_equal(rd.read, 102);
    was = rd;
    in = rx.stats.bytes_in;
    /* 65 behind (more than the 64 of the buffer): stale */
    assert_int_equal(tase_bm_dma_poll(&rd, 102u - 65u, 0, &rx, on_frame, &got), 0);
    assert_unchanged(&rd, &was);
    assert_int_equal(rx.stats.bytes_in, in);
    assert_int_equal(got.n, 6);
    /* the next good sample, 10 bytes on from the real position: those 10
     * bytes, which end frame 6 */
    dma_write(&dma, stream, 10);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 0, &rx, on_frame, &got), 1);
    assert_int_equal(got.n, 7);
    assert_int_equal(got.f[6].type, 6);
    assert_int_equal(got.f[6].offset, 96);
    assert_int_equal(rx.stats.bytes_in, in + 10u);
    assert_int_equal(rd.stats.bytes_fed, 112);
    assert_int_equal(rd.stats.overruns, 0);
    assert_int_equal(rd.stats.lost_bytes, 0);
    /* 2^31 - 1 behind, the farthest stale sample: nothing either */
    was = rd;
    assert_int_equal(tase_bm_dma_poll(&rd, 112u - 0x7FFFFFFFu, 0, &rx, on_frame, &got), 0);
    assert_unchanged(&rd, &was);
    /* a stale sample, then the DMA really laps (100 > 64 bytes on): that
     * sample is an overrun of those 100 bytes */
    assert_int_equal(tase_bm_dma_poll(&rd, 112u - 100u, 0, &rx, on_frame, &got), 0);
    assert_unchanged(&rd, &was);
    dma_write(&dma, stream, 100);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 0, &rx, on_frame, &got), 0);
    assert_int_equal(rd.stats.overruns, 1);
    assert_int_equal(rd.stats.lost_bytes, 100);
    assert_int_equal(rd.read, 212);
    assert_int_equal(rd.pos, 212u % 64u);
    /* exactly 2^31 behind reads as 2^31 ahead: an overrun */
    assert_int_equal(tase_bm_dma_poll(&rd, 212u - 0x80000000u, 0, &rx, on_frame, &got), 0);
    assert_int_equal(rd.stats.overruns, 2);
    assert_true(rd.stats.lost_bytes == 100u + 0x80000000u);
    assert_true(rd.read == 212u + 0x80000000u);
    assert_int_equal(rd.stats.bytes_fed, 112);
}

/* The time bound: noise then a frame, then nothing: the frame comes out
 * by the tick of a later empty poll. */
static void an_empty_poll_ticks_the_time_bound(void **state)
{
    static uint8_t buf[128];
    static const uint8_t noise[4] = {0x00, 0xFF, 0x5A, 0xFF};
    static log_t got;
    uint8_t fr[TASE_FRAME_MAX];
    uint8_t s[64];
    tase_rx_t rx;
    tase_bm_dma_t rd;
    dma_t dma = {buf, sizeof buf, 0};
    int m = tase_frame_build(0x00, 0x80, NULL, 0, fr, sizeof fr); /* GYRO_ZERO-like, no data */
    (void)state;
    memcpy(s, noise, 4);
    memcpy(s + 4, fr, (size_t)m);
    got.n = 0;
    (void)tase_rx_init(&rx);
    assert_int_equal(tase_rx_set_timing(&rx, 11520u, 20u), TASE_OK);
    assert_int_equal(tase_bm_dma_init(&rd, buf, sizeof buf), TASE_OK);
    dma_write(&dma, s, 4u + (uint32_t)m);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 100, &rx, on_frame, &got), 0);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 120, &rx, on_frame, &got), 0);
    assert_int_equal(tase_bm_dma_poll(&rd, dma.written, 124, &rx, on_frame, &got), 1);
    assert_int_equal(got.f[0].type, 0x80);
}

typedef struct {
    tase_bm_dma_t *rd;
    tase_rx_t *rx;
    int inner; /* what a poll from inside the callback returned */
    uint32_t fed_inside;
} nest_t;

static void poll_from_the_callback(void *user, const tase_frame_t *f)
{
    nest_t *x = user;
    (void)f;
    x->inner = tase_bm_dma_poll(x->rd, x->rd->read + 8u, 0, x->rx, poll_from_the_callback, x);
    x->fed_inside = x->rd->stats.bytes_fed;
}

static void bad_arguments_and_a_busy_receiver_read_nothing(void **state)
{
    static uint8_t buf[64];
    tase_bm_dma_t rd;
    tase_rx_t rx;
    nest_t x = {&rd, &rx, 1, 0};
    static const uint8_t angle[6] = {1, 2, 3, 4, 5, 6};
    uint8_t fr[16];
    int m = tase_frame_build(0x08, 0x10, angle, sizeof angle, fr, sizeof fr);
    (void)state;
    (void)tase_rx_init(&rx);
    assert_int_equal(tase_bm_dma_init(NULL, buf, 16), TASE_EARG);
    assert_int_equal(tase_bm_dma_init(&rd, NULL, 16), TASE_EARG);
    assert_int_equal(tase_bm_dma_init(&rd, buf, 0), TASE_EARG);
    assert_int_equal(tase_bm_dma_init(&rd, buf, sizeof buf), TASE_OK);
    assert_int_equal(tase_bm_dma_poll(NULL, 4, 0, &rx, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_bm_dma_poll(&rd, 4, 0, NULL, NULL, NULL), TASE_EARG);
    /* a stale sample (written going backwards) reads nothing */
    memset(buf, 0x11, sizeof buf);
    assert_int_equal(tase_bm_dma_poll(&rd, 4, 0, &rx, NULL, NULL), 0);
    assert_int_equal(tase_bm_dma_poll(&rd, 2, 0, &rx, NULL, NULL), 0);
    assert_int_equal(rd.stats.bytes_fed, 4);
    assert_int_equal(rd.stats.overruns, 0);
    /* from the receiver's own callback: TASE_EBUSY, nothing read */
    assert_true(m > 0);
    memcpy(&buf[4], fr, (size_t)m);
    assert_int_equal(tase_bm_dma_poll(&rd, 4u + (uint32_t)m, 0, &rx, poll_from_the_callback, &x),
                     1);
    assert_int_equal(x.inner, TASE_EBUSY);
    assert_int_equal(x.fed_inside, 4u); /* the inner poll read nothing */
    assert_int_equal(rd.stats.bytes_fed, 4u + (uint32_t)m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(any_split_gives_the_frames_of_one_feed),
        cmocka_unit_test(a_lap_is_reported_and_loses_only_what_was_overwritten),
        cmocka_unit_test(overruns_far_behind_and_past_2_32_resume_at_the_dmas_index),
        cmocka_unit_test(a_sample_behind_by_under_2_31_is_stale_however_far),
        cmocka_unit_test(an_empty_poll_ticks_the_time_bound),
        cmocka_unit_test(bad_arguments_and_a_busy_receiver_read_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
