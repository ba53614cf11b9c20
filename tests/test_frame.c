/* Tests of the datalink layer: frame encoder and receive state machine. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/frame.h"

/* ---- helpers ---------------------------------------------------------- */

#define MAX_SEEN 8192

typedef struct {
    uint32_t offset;
    uint8_t group, type, len;
    uint8_t data[TASE_DATA_MAX];
    uint32_t seen_at; /* stats.bytes_in when delivered: how much was fed */
} seen_t;

typedef struct {
    tase_rx_t *rx;
    size_t n;
    seen_t f[MAX_SEEN];
} recorder_t;

static void record(void *user, const tase_frame_t *fr)
{
    recorder_t *r = user;
    seen_t *s;
    assert_true(r->n < MAX_SEEN);
    s = &r->f[r->n++];
    s->offset = fr->offset;
    s->group = fr->group;
    s->type = fr->type;
    s->len = fr->len;
    assert_non_null(fr->data);
    memcpy(s->data, fr->data, fr->len);
    s->seen_at = r->rx->stats.bytes_in;
}

static recorder_t *new_recorder(tase_rx_t *rx)
{
    recorder_t *r = calloc(1, sizeof(*r));
    assert_non_null(r);
    r->rx = rx;
    assert_int_equal(tase_rx_init(rx), TASE_OK);
    return r;
}

/* Deterministic PRNG so failures are reproducible. */
static uint32_t rng_state;
static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static size_t make_frame(uint8_t *out, uint8_t group, uint8_t type, size_t len)
{
    uint8_t data[TASE_DATA_MAX];
    size_t i;
    int n;
    for (i = 0; i < len; i++) {
        data[i] = (uint8_t)rnd();
    }
    n = tase_frame_encode(out, TASE_FRAME_MAX, group, type, data, len);
    assert_true(n > 0);
    return (size_t)n;
}

/* Byte at a time, alternating the two one-byte entry points so both are
 * held to every expectation of the tests that use this. */
static void feed_bytes_one_by_one(tase_rx_t *rx, const uint8_t *p, size_t n, recorder_t *r)
{
    size_t i;
    for (i = 0; i < n; i++) {
        if ((i / 7u) % 2u == 0u) {
            assert_true(tase_rx_push(rx, p[i], record, r) >= 0);
        } else {
            assert_true(tase_rx_feed(rx, &p[i], 1, record, r) >= 0);
        }
    }
}

static void assert_frame_is(const seen_t *s, const uint8_t *frame)
{
    assert_int_equal(s->group, frame[4]);
    assert_int_equal(s->type, frame[5]);
    assert_int_equal(s->len, frame[3] - 2);
    assert_memory_equal(s->data, frame + 6, s->len);
}

/* ---- encoder ---------------------------------------------------------- */

static void encode_zero_length_frame_matches_hand_computed_bytes(void **state)
{
    /* GYRO_ZERO_CMD: 00+FF+5A+02+00+40 = 0x019B */
    static const uint8_t expect[] = {0x00, 0xFF, 0x5A, 0x02, 0x00, 0x40, 0x01, 0x9B};
    uint8_t out[16];
    (void)state;
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0x00, 0x40, NULL, 0), 8);
    assert_memory_equal(out, expect, sizeof(expect));
}

static void encode_with_data_matches_hand_computed_bytes(void **state)
{
    /* GIMBAL_ANGLE pan=1000 (03 E8) tilt=-500 (FE 0C) roll=0:
     * 00+FF+5A+08+08+10+03+E8+FE+0C+00+00 = 0x036E */
    static const uint8_t data[] = {0x03, 0xE8, 0xFE, 0x0C, 0x00, 0x00};
    static const uint8_t expect[] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x03,
                                     0xE8, 0xFE, 0x0C, 0x00, 0x00, 0x03, 0x6E};
    uint8_t out[32];
    (void)state;
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0x08, 0x10, data, sizeof(data)), 14);
    assert_memory_equal(out, expect, sizeof(expect));
}

static void encode_checksum_wraps_modulo_65536(void **state)
{
    uint8_t data[TASE_DATA_MAX];
    uint8_t out[TASE_FRAME_MAX];
    uint32_t sum = 0x00 + 0xFF + 0x5A + 0xFF + 0xFF + 0xFF;
    (void)state;
    memset(data, 0xFF, sizeof(data));
    sum += 0xFFu * TASE_DATA_MAX; /* 0x1040E: wraps */
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0xFF, 0xFF, data, sizeof(data)),
                     (int)TASE_FRAME_MAX);
    assert_int_equal(out[3], 0xFF);
    assert_int_equal(out[TASE_FRAME_MAX - 2], (sum >> 8) & 0xFF);
    assert_int_equal(out[TASE_FRAME_MAX - 1], sum & 0xFF);
    assert_true(sum > 0xFFFF);
}

static void encode_rejects_bad_arguments_without_writing(void **state)
{
    uint8_t out[TASE_FRAME_MAX + 1];
    uint8_t data[TASE_DATA_MAX + 1];
    uint8_t untouched[sizeof(out)];
    (void)state;
    memset(data, 0x11, sizeof(data));
    memset(out, 0xA5, sizeof(out));
    memcpy(untouched, out, sizeof(out));
    assert_int_equal(tase_frame_encode(NULL, 64, 0, 0, data, 1), TASE_EARG);
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0, 0, NULL, 1), TASE_EARG);
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0, 0, data, TASE_DATA_MAX + 1),
                     TASE_ETOOLONG);
    assert_int_equal(tase_frame_encode(out, 7, 0, 0, NULL, 0), TASE_ENOSPC);
    assert_int_equal(tase_frame_encode(out, 10 + 7, 0, 0, data, 10), TASE_ENOSPC);
    assert_memory_equal(out, untouched, sizeof(out));
    /* Exactly enough room is fine. */
    assert_int_equal(tase_frame_encode(out, 18, 0, 0, data, 10), 18);
}

static void encode_in_place_payload_needs_no_copy(void **state)
{
    uint8_t a[32], b[32];
    static const uint8_t data[] = {1, 2, 3, 4, 5};
    (void)state;
    assert_int_equal(tase_frame_encode(a, sizeof(a), 0x10, 0x41, data, sizeof(data)), 13);
    memcpy(b + TASE_FRAME_HEADER, data, sizeof(data));
    assert_int_equal(
        tase_frame_encode(b, sizeof(b), 0x10, 0x41, b + TASE_FRAME_HEADER, sizeof(data)), 13);
    assert_memory_equal(a, b, 13);
}

static void checksum_helper_matches_definition(void **state)
{
    static const uint8_t p[] = {0xFF, 0xFF, 0x02};
    (void)state;
    assert_int_equal(tase_checksum(0, p, 3), 0x0200);
    assert_int_equal(tase_checksum(0xFFFF, p, 1), 0x00FE);
    assert_int_equal(tase_checksum(7, NULL, 0), 7);
}

/* ---- receiver: basics ------------------------------------------------- */

static void receiver_rejects_null_arguments(void **state)
{
    tase_rx_t rx;
    uint8_t b = 0;
    (void)state;
    assert_int_equal(tase_rx_init(NULL), TASE_EARG);
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_rx_feed(NULL, &b, 1, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_rx_feed(&rx, NULL, 1, NULL, NULL), TASE_EARG);
    assert_int_equal(rx.stats.bytes_in, 0);
    assert_int_equal(tase_rx_feed(&rx, NULL, 0, NULL, NULL), 0);
    assert_int_equal(tase_rx_flush(NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_rx_stats_reset(NULL), TASE_EARG);
}

static void api_extreme_lengths_give_error_codes_and_change_nothing(void **state)
{
    tase_rx_t rx, copy;
    uint8_t out[TASE_FRAME_MAX], untouched[TASE_FRAME_MAX];
    static const uint8_t data[4] = {1, 2, 3, 4};
    (void)state;
    memset(out, 0x5C, sizeof(out));
    memcpy(untouched, out, sizeof(out));
    /* lengths near SIZE_MAX must not overflow len + 8 into a small total */
    assert_int_equal(tase_frame_encode(out, SIZE_MAX, 0, 0, data, SIZE_MAX), TASE_ETOOLONG);
    assert_int_equal(tase_frame_encode(out, SIZE_MAX, 0, 0, data, SIZE_MAX - 7u), TASE_ETOOLONG);
    assert_int_equal(tase_frame_encode(out, 0, 0, 0, NULL, 0), TASE_ENOSPC);
    assert_int_equal(tase_frame_encode(NULL, 0, 0, 0, NULL, SIZE_MAX), TASE_EARG);
    assert_memory_equal(out, untouched, sizeof(out));
    /* a NULL buffer is never read, whatever the length */
    assert_int_equal(tase_checksum(0x1234, NULL, SIZE_MAX), 0x1234);
    /* a rejected feed leaves the whole receiver as it was, mid-frame too */
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_frame_encode(out, sizeof(out), 0x08, 0x10, data, 4), 12);
    assert_int_equal(tase_rx_feed(&rx, out, 7, NULL, NULL), 0);
    memcpy(&copy, &rx, sizeof(rx));
    assert_int_equal(tase_rx_feed(&rx, NULL, SIZE_MAX, NULL, NULL), TASE_EARG);
    assert_memory_equal(&copy, &rx, sizeof(rx));
    assert_int_equal(tase_rx_feed(&rx, out + 7, 5, NULL, NULL), 1);
    /* flushing an empty receiver twice is harmless */
    assert_int_equal(tase_rx_flush(&rx, NULL, NULL), 0);
    memcpy(&copy, &rx, sizeof(rx));
    assert_int_equal(tase_rx_flush(&rx, NULL, NULL), 0);
    assert_memory_equal(&copy, &rx, sizeof(rx));
}

static void receiver_size_fits_budget(void **state)
{
    (void)state;
    /* Also enforced at compile time; the number is quoted in the docs. */
    assert_true(sizeof(tase_rx_t) <= TASE_RX_SIZE_BUDGET);
    assert_true(sizeof(((tase_rx_t *)0)->buf) >= TASE_FRAME_MAX);
}

static void every_split_point_gives_the_same_frame(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t fr[TASE_FRAME_MAX];
    size_t lens[] = {0, 1, 6, 18, 63, TASE_DATA_MAX};
    size_t k, a, b;
    (void)state;
    rng_state = 12345;
    for (k = 0; k < sizeof(lens) / sizeof(lens[0]); k++) {
        size_t n = make_frame(fr, 0x08, 0x40, lens[k]);
        /* every pair of cut points (a <= b) splits it into three feeds */
        for (a = 0; a <= n; a += (n > 40 ? 7 : 1)) {
            for (b = a; b <= n; b += (n > 40 ? 5 : 1)) {
                assert_int_equal(tase_rx_init(&rx), TASE_OK);
                r->n = 0;
                assert_true(tase_rx_feed(&rx, fr, a, record, r) >= 0);
                assert_true(tase_rx_feed(&rx, fr + a, b - a, record, r) >= 0);
                assert_true(tase_rx_feed(&rx, fr + b, n - b, record, r) >= 0);
                assert_int_equal(r->n, 1);
                assert_frame_is(&r->f[0], fr);
                assert_int_equal(r->f[0].offset, 0);
                assert_int_equal(r->f[0].seen_at, n); /* at its last byte */
                assert_int_equal(rx.stats.frames_ok, 1);
                assert_int_equal(rx.stats.bytes_discarded, 0);
            }
        }
    }
    free(r);
}

static void random_split_points_of_a_long_stream(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    static uint8_t stream[64 * TASE_FRAME_MAX];
    size_t starts[64];
    size_t n = 0, k, pos, trial;
    (void)state;
    rng_state = 777;
    for (k = 0; k < 64; k++) {
        starts[k] = n;
        n += make_frame(stream + n, (uint8_t)rnd(), (uint8_t)rnd(), rnd() % (TASE_DATA_MAX + 1));
    }
    for (trial = 0; trial < 50; trial++) {
        assert_int_equal(tase_rx_init(&rx), TASE_OK);
        r->n = 0;
        for (pos = 0; pos < n;) {
            size_t chunk = 1 + rnd() % 300;
            if (chunk > n - pos) {
                chunk = n - pos;
            }
            assert_true(tase_rx_feed(&rx, stream + pos, chunk, record, r) >= 0);
            pos += chunk;
        }
        assert_int_equal(r->n, 64);
        for (k = 0; k < 64; k++) {
            assert_int_equal(r->f[k].offset, starts[k]);
            assert_frame_is(&r->f[k], stream + starts[k]);
        }
    }
    free(r);
}

/* ---- receiver: sync edge cases --------------------------------------- */

static void run_prefix_then_frame(const uint8_t *prefix, size_t plen, uint32_t noise)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64];
    size_t n;
    rng_state = 99;
    memcpy(buf, prefix, plen);
    n = plen + make_frame(buf + plen, 0x00, 0x80, 8);
    feed_bytes_one_by_one(&rx, buf, n, r);
    assert_int_equal(r->n, 1);
    assert_frame_is(&r->f[0], buf + plen);
    assert_int_equal(r->f[0].offset, plen);
    assert_int_equal(rx.stats.bytes_discarded, noise);
    /* the same stream in one call */
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    r->n = 0;
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 1);
    assert_int_equal(r->f[0].offset, plen);
    assert_int_equal(rx.stats.bytes_discarded, noise);
    free(r);
}

static void sync_double_zero_is_found(void **state)
{
    static const uint8_t p[] = {0x00};
    (void)state;
    run_prefix_then_frame(p, sizeof(p), 1); /* 00 00 FF 5A ... */
}

static void sync_restarts_after_broken_match(void **state)
{
    static const uint8_t p1[] = {0x00, 0xFF};             /* 00 FF 00 FF 5A */
    static const uint8_t p2[] = {0x00, 0xFF, 0xFF};       /* 00 FF FF 00 FF 5A */
    static const uint8_t p3[] = {0x5A, 0xFF, 0x00, 0x00}; /* stray 5A, FF, 00 00 */
    static const uint8_t p4[] = {0x00, 0x00, 0x00, 0xFF, 0x00};
    (void)state;
    run_prefix_then_frame(p1, sizeof(p1), 2);
    run_prefix_then_frame(p2, sizeof(p2), 3);
    run_prefix_then_frame(p3, sizeof(p3), 4);
    run_prefix_then_frame(p4, sizeof(p4), 5);
}

static void bad_size_is_rejected_at_once(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64];
    size_t n;
    (void)state;
    rng_state = 5;
    /* Size 1 and Size 0; the 00 Size byte itself begins the next sync. */
    static const uint8_t bad[] = {0x00, 0xFF, 0x5A, 0x01, 0x00, 0xFF, 0x5A};
    memcpy(buf, bad, sizeof(bad));
    n = sizeof(bad) + make_frame(buf + sizeof(bad) - 3, 0x48, 0x00, 16) - 3;
    feed_bytes_one_by_one(&rx, buf, 4, r);
    assert_int_equal(rx.stats.bad_size, 1); /* decided on the Size byte */
    feed_bytes_one_by_one(&rx, buf + 4, n - 4, r);
    assert_int_equal(r->n, 1);
    assert_int_equal(r->f[0].offset, 4);
    assert_frame_is(&r->f[0], buf + 4);
    assert_int_equal(rx.stats.bad_size, 1);
    assert_int_equal(rx.stats.bytes_discarded, 4);

    /* 00 FF 5A 00 FF 5A <frame...>: Size 0 rejected, its 00 is a new sync */
    static const uint8_t zero[] = {0x00, 0xFF, 0x5A};
    memcpy(buf, zero, 3);
    n = 3 + make_frame(buf + 3, 0x10, 0x10, 32);
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    r->n = 0;
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 1);
    assert_int_equal(rx.stats.bad_size, 1);
    assert_int_equal(r->f[0].offset, 3);
    free(r);
}

/* ---- receiver: corruption and recovery ------------------------------ */

static void corrupted_size_does_not_swallow_following_packets(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[1024];
    size_t starts[8], ends[8], n = 0, k;
    (void)state;
    rng_state = 31337;
    /* First frame's Size corrupted to 255: it claims the next 255 bytes. */
    n += make_frame(buf, 0x08, 0x10, 6);
    buf[3] = 0xFF;
    for (k = 0; k < 8; k++) {
        starts[k] = n;
        n += make_frame(buf + n, 0x08, (uint8_t)k, 10 + k);
        ends[k] = n;
    }
    feed_bytes_one_by_one(&rx, buf, n, r);
    assert_int_equal(r->n, 8);
    for (k = 0; k < 8; k++) {
        assert_int_equal(r->f[k].offset, starts[k]);
        assert_int_equal(r->f[k].type, k);
        /* zero added latency: delivered when its own last byte arrived,
         * while the corrupted candidate was still undecided */
        assert_int_equal(r->f[k].seen_at, ends[k]);
    }
    assert_int_equal(rx.stats.frames_ok, 8);
    free(r);
}

static void checksum_error_then_clean_packet_inside_claimed_length(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[600];
    size_t n, a, b;
    (void)state;
    rng_state = 4242;
    /* A: 40-byte payload whose checksum is wrong; B starts right after A's
     * sync header, i.e. inside A's claimed length: A's data bytes are
     * really B. */
    a = make_frame(buf, 0x00, 0x80, 8);
    memmove(buf + 6, buf, a); /* B starts at offset 6 */
    buf[0] = 0x00;
    buf[1] = 0xFF;
    buf[2] = 0x5A;
    buf[3] = 40;   /* A claims 38 data bytes */
    buf[4] = 0x08; /* A's group/type: the frame B is inside A */
    buf[5] = 0x10;
    b = 6 + a;
    n = b + make_frame(buf + b, 0x10, 0x41, 63);
    feed_bytes_one_by_one(&rx, buf, n, r);
    assert_int_equal(rx.stats.checksum_errors, 1);
    assert_int_equal(r->n, 2);
    assert_int_equal(r->f[0].offset, 6);
    assert_int_equal(r->f[0].seen_at, 6 + a);
    assert_int_equal(r->f[1].offset, b);
    /* only A's first six bytes were noise */
    assert_int_equal(rx.stats.bytes_discarded, 6);
    free(r);
}

static void failed_frame_is_rescanned_from_the_byte_after_its_first_sync(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64];
    size_t n;
    (void)state;
    rng_state = 8;
    /* 00 FF 5A 00 FF 5A 02 00 40 ... : a candidate with Size 00 whose Size
     * byte begins a real GYRO_ZERO_CMD frame, delivered after the
     * corrupted one failed. */
    buf[0] = 0x00;
    buf[1] = 0xFF;
    buf[2] = 0x5A;
    n = 3 + make_frame(buf + 3, 0x00, 0x40, 0);
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 1);
    assert_int_equal(r->f[0].offset, 3);
    assert_int_equal(rx.stats.bad_size, 1);
    free(r);
}

/* Build a stream of clean frames separated by hostile noise: random bytes,
 * sync sequences with random sizes, and frames with a flipped bit. */
static size_t build_noisy_stream(uint8_t *buf, size_t cap, size_t frames, size_t *starts,
                                 size_t *ends)
{
    size_t n = 0, k, j;
    for (k = 0; k < frames; k++) {
        uint32_t kind = rnd() % 4;
        if (kind == 0) {
            size_t m = rnd() % 40;
            for (j = 0; j < m; j++) {
                buf[n++] = (uint8_t)rnd();
            }
        } else if (kind == 1) {
            buf[n++] = 0x00;
            buf[n++] = 0xFF;
            buf[n++] = 0x5A;
            buf[n++] = (uint8_t)rnd(); /* random Size, often huge */
        } else if (kind == 2) {
            size_t m = make_frame(buf + n, 0x08, 0x41, rnd() % 30);
            buf[n + 6 + rnd() % (m - 6)] ^= (uint8_t)(1u << (rnd() % 8));
            n += m;
        }
        starts[k] = n;
        n += make_frame(buf + n, (uint8_t)(rnd() % 4 * 8), (uint8_t)rnd(), rnd() % 64);
        ends[k] = n;
        assert_true(n + 2 * TASE_FRAME_MAX < cap);
    }
    return n;
}

static void noisy_stream_delivers_every_clean_packet_once_in_order(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    static uint8_t buf[1 << 20];
    static size_t starts[2000], ends[2000];
    size_t n, k, late = 0, seed;
    (void)state;
    for (seed = 1; seed <= 5; seed++) {
        rng_state = (uint32_t)(seed * 2654435761u);
        n = build_noisy_stream(buf, sizeof(buf), 2000, starts, ends);
        assert_int_equal(tase_rx_init(&rx), TASE_OK);
        r->n = 0;
        feed_bytes_one_by_one(&rx, buf, n, r);
        assert_true(tase_rx_flush(&rx, record, r) >= 0);
        assert_int_equal(r->n, 2000);
        for (k = 0; k < 2000; k++) {
            assert_int_equal(r->f[k].offset, starts[k]);
            assert_frame_is(&r->f[k], buf + starts[k]);
            /* zero added latency, or the documented bound when more
             * false candidates overlap than there are slots */
            assert_true(r->f[k].seen_at - ends[k] <= TASE_FRAME_MAX - 8);
            if (r->f[k].seen_at != ends[k]) {
                late++;
            }
        }
        assert_int_equal(rx.stats.frames_ok, 2000);
        /* noise accounting: every byte is either in a frame or discarded */
        {
            uint32_t framed = 0;
            for (k = 0; k < 2000; k++) {
                framed += (uint32_t)(ends[k] - starts[k]);
            }
            assert_int_equal(rx.stats.bytes_in, n);
            assert_int_equal(rx.stats.bytes_discarded + framed, n);
        }
    }
    /* this noise is dense (a false sync before a quarter of the frames),
     * so a few frames take the re-scan path; most must not */
    assert_true(late < 10000 / 100);
    free(r);
}

static void bit_errors_cost_untouched_frames_no_latency(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    static uint8_t buf[1 << 19];
    static size_t starts[6000], ends[6000];
    static uint8_t touched[6000];
    size_t n = 0, k, i, got = 0, hit = 0;
    (void)state;
    rng_state = 99991;
    for (k = 0; k < 6000; k++) {
        starts[k] = n;
        n += make_frame(buf + n, 0x08, (uint8_t)(k % 3 == 0 ? 0x10 : 0x40), k % 3 == 0 ? 6 : 18);
        ends[k] = n;
    }
    /* flip one bit per 1000 bits on average */
    for (i = 0; i < n * 8; i += 1 + rnd() % 2000) {
        buf[i / 8] ^= (uint8_t)(1u << (i % 8));
        for (k = 0; k < 6000; k++) {
            if (i / 8 >= starts[k] && i / 8 < ends[k]) {
                touched[k] = 1;
                break;
            }
        }
    }
    feed_bytes_one_by_one(&rx, buf, n, r);
    assert_true(tase_rx_flush(&rx, record, r) >= 0);
    for (k = 0; k < 6000; k++) {
        if (touched[k]) {
            hit++;
            continue;
        }
        while (got < r->n && r->f[got].offset < starts[k]) {
            got++;
        }
        assert_true(got < r->n);
        assert_int_equal(r->f[got].offset, starts[k]);
        assert_int_equal(r->f[got].seen_at, ends[k]);
    }
    assert_true(hit > 500); /* the channel really did corrupt frames */
    free(r);
}

static void any_split_gives_identical_frames_and_counters(void **state)
{
    static uint8_t buf[1 << 20];
    static size_t starts[3000], ends[3000];
    tase_rx_t a, b;
    recorder_t *ra = new_recorder(&a);
    recorder_t *rb = new_recorder(&b);
    size_t n, pos, k, trial;
    (void)state;
    for (trial = 0; trial < 6; trial++) {
        rng_state = (uint32_t)(0xC0FFEEu + trial);
        n = build_noisy_stream(buf, sizeof(buf), 3000, starts, ends);
        assert_int_equal(tase_rx_init(&a), TASE_OK);
        assert_int_equal(tase_rx_init(&b), TASE_OK);
        ra->n = 0;
        rb->n = 0;
        feed_bytes_one_by_one(&a, buf, n, ra);
        if (trial == 0) {
            assert_true(tase_rx_feed(&b, buf, n, record, rb) >= 0); /* one call */
        } else {
            for (pos = 0; pos < n;) {
                size_t chunk = 1 + rnd() % (trial * 100);
                if (chunk > n - pos) {
                    chunk = n - pos;
                }
                assert_true(tase_rx_feed(&b, buf + pos, chunk, record, rb) >= 0);
                pos += chunk;
            }
        }
        assert_true(tase_rx_flush(&a, record, ra) >= 0);
        assert_true(tase_rx_flush(&b, record, rb) >= 0);
        assert_int_equal(ra->n, rb->n);
        for (k = 0; k < ra->n; k++) {
            assert_int_equal(ra->f[k].offset, rb->f[k].offset);
            assert_int_equal(ra->f[k].len, rb->f[k].len);
            assert_memory_equal(ra->f[k].data, rb->f[k].data, ra->f[k].len);
        }
        assert_memory_equal(&a.stats, &b.stats, sizeof(a.stats));
    }
    free(ra);
    free(rb);
}

static void more_overlapping_candidates_than_slots_still_loses_nothing(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[4096];
    size_t n = 0, k, starts[4], ends[4];
    (void)state;
    rng_state = 2024;
    /* Ten false syncs claiming 255 bytes each overlap the clean frames. */
    for (k = 0; k < 10; k++) {
        buf[n++] = 0x00;
        buf[n++] = 0xFF;
        buf[n++] = 0x5A;
        buf[n++] = 0xFF;
    }
    for (k = 0; k < 4; k++) {
        starts[k] = n;
        n += make_frame(buf + n, 0x08, 0x10, 6);
        ends[k] = n;
    }
    feed_bytes_one_by_one(&rx, buf, n, r);
    assert_int_equal(r->n, 0); /* candidates pending: found later */
    /* filler noise lets the false candidates end */
    memset(buf + n, 0x11, 300);
    feed_bytes_one_by_one(&rx, buf + n, 300, r);
    assert_int_equal(r->n, 4);
    for (k = 0; k < 4; k++) {
        assert_int_equal(r->f[k].offset, starts[k]);
        /* late, but within the documented bound */
        assert_true(r->f[k].seen_at - ends[k] <= TASE_FRAME_MAX - 8);
    }
    assert_int_equal(rx.stats.checksum_errors, 10);
    free(r);
}

static void flush_finds_clean_packets_held_at_end_of_input(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[512];
    size_t n = 0, k, start;
    (void)state;
    rng_state = 11;
    for (k = 0; k < 6; k++) { /* more than TASE_RX_CANDIDATES */
        buf[n++] = 0x00;
        buf[n++] = 0xFF;
        buf[n++] = 0x5A;
        buf[n++] = 0xF0;
    }
    start = n;
    n += make_frame(buf + n, 0x48, 0x03, 0);
    buf[n++] = 0x00; /* a partial sync left over at the end */
    buf[n++] = 0xFF;
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 0);
    assert_int_equal(tase_rx_flush(&rx, record, r), 1);
    assert_int_equal(r->n, 1);
    assert_int_equal(r->f[0].offset, start);
    assert_int_equal(rx.stats.bytes_discarded, n - 8);
    /* the receiver is empty again and reusable */
    r->n = 0;
    assert_int_equal(tase_rx_feed(&rx, buf + start, 8, record, r), 1);
    assert_int_equal(r->f[0].offset, n);
    free(r);
}

static void flush_of_clean_stream_changes_nothing(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64];
    size_t n;
    (void)state;
    rng_state = 3;
    n = make_frame(buf, 0x08, 0x10, 6);
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 1);
    assert_int_equal(tase_rx_flush(&rx, record, r), 0);
    assert_int_equal(rx.stats.bytes_discarded, 0);
    /* a half frame at the end is discarded by flush, not delivered */
    assert_int_equal(tase_rx_feed(&rx, buf, n - 1, record, r), 0);
    assert_int_equal(tase_rx_flush(&rx, record, r), 0);
    assert_int_equal(rx.stats.bytes_discarded, n - 1);
    assert_int_equal(r->n, 1);
    free(r);
}

static void frame_embedded_in_a_valid_frame_yields_both_inner_first(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t inner[32], outer[64];
    size_t ni, no;
    (void)state;
    rng_state = 6;
    ni = make_frame(inner, 0x08, 0x10, 6);
    /* CAMERA_PASS carrying a whole TASE frame as camera bytes */
    memcpy(outer + 6 + 4, inner, ni);
    memset(outer + 6, 0, 4);
    no = (size_t)tase_frame_encode(outer, sizeof(outer), 0x00, 0x42, outer + 6, 4 + ni);
    assert_int_equal(tase_rx_feed(&rx, outer, no, record, r), 2);
    assert_int_equal(r->f[0].type, 0x10);
    assert_int_equal(r->f[0].offset, 10);
    assert_int_equal(r->f[1].type, 0x42);
    assert_int_equal(r->f[1].offset, 0);
    assert_int_equal(rx.stats.bytes_discarded, 0);
    free(r);
}

static void sync_inside_a_delivered_frame_starts_nothing(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64], data[8] = {1, 2, 0x00, 0xFF, 0x5A, 0x02, 0x00, 0x40};
    int n;
    (void)state;
    /* payload ends in 00 FF 5A 02 00 40: a sync whose frame would run past
     * the end of the valid frame that contains it */
    n = tase_frame_encode(buf, sizeof(buf), 0x00, 0x42, data, sizeof(data));
    assert_int_equal(tase_rx_feed(&rx, buf, (size_t)n, record, r), 1);
    assert_int_equal(tase_rx_flush(&rx, record, r), 0);
    assert_int_equal(rx.stats.checksum_errors, 0);
    assert_int_equal(rx.stats.bytes_discarded, 0);
    free(r);
}

static void counters_only_reset_on_request(void **state)
{
    tase_rx_t rx;
    recorder_t *r = new_recorder(&rx);
    uint8_t buf[64];
    size_t n;
    (void)state;
    rng_state = 1;
    buf[0] = 0x77;
    n = 1 + make_frame(buf + 1, 0, 0x80, 8);
    assert_int_equal(tase_rx_feed(&rx, buf, n, NULL, NULL), 1); /* no callback */
    assert_int_equal(tase_rx_flush(&rx, NULL, NULL), 0);
    assert_int_equal(rx.stats.frames_ok, 1);
    assert_int_equal(rx.stats.bytes_discarded, 1);
    assert_int_equal(rx.stats.bytes_in, n);
    assert_int_equal(tase_rx_stats_reset(&rx), TASE_OK);
    assert_int_equal(rx.stats.frames_ok, 0);
    assert_int_equal(rx.stats.bytes_in, 0);
    assert_int_equal(tase_rx_feed(&rx, buf, n, record, r), 1);
    assert_int_equal(r->f[0].offset, 1);
    free(r);
}

static void strerror_names_every_code(void **state)
{
    int e;
    (void)state;
    for (e = TASE_ESTATE; e <= TASE_OK; e++) {
        assert_string_not_equal(tase_strerror(e), "unknown error");
    }
    assert_string_equal(tase_strerror(-1000), "unknown error");
    assert_string_equal(tase_strerror(5), "unknown error");
}

static void push_one_byte_at_a_time_equals_feeding_one_buffer(void **state)
{
    static uint8_t buf[1 << 19];
    static size_t starts[2000], ends[2000];
    tase_rx_t a, b;
    recorder_t *ra;
    recorder_t *rb;
    size_t n, i, k;
    (void)state;
    ra = new_recorder(&a);
    rb = new_recorder(&b);
    rng_state = 0xABCDu;
    n = build_noisy_stream(buf, sizeof(buf), 2000, starts, ends);
    for (i = 0; i < n; i++) {
        assert_true(tase_rx_push(&a, buf[i], record, ra) >= 0);
    }
    assert_true(tase_rx_feed(&b, buf, n, record, rb) >= 0);
    assert_true(tase_rx_flush(&a, record, ra) >= 0);
    assert_true(tase_rx_flush(&b, record, rb) >= 0);
    assert_int_equal(ra->n, rb->n);
    assert_int_equal(ra->n, 2000);
    for (k = 0; k < ra->n; k++) {
        assert_int_equal(ra->f[k].offset, rb->f[k].offset);
        assert_int_equal(ra->f[k].offset, starts[k]);
    }
    assert_memory_equal(&a.stats, &b.stats, sizeof(a.stats));
    assert_int_equal(tase_rx_push(NULL, 0, NULL, NULL), TASE_EARG);
    free(ra);
    free(rb);
}

/* Every bad argument of frame.h gives its documented code, and a receiver
 * that is visibly corrupted (indices out of range) is refused by every
 * entry point without being changed or read outside its window. */
static void frame_api_rejects_bad_arguments(void **state)
{
    static const uint8_t bytes[4] = {0x00, 0xFF, 0x5A, 0x04};
    uint8_t out[TASE_FRAME_MAX + 1u];
    uint8_t before[sizeof out];
    tase_rx_t rx;
    tase_rx_t bad;
    tase_rx_t copy;
    int k;
    (void)state;

    memset(out, 0xA5, sizeof out);
    memcpy(before, out, sizeof out);
    assert_int_equal(tase_frame_encode(NULL, sizeof out, 0, 0, NULL, 0), TASE_EARG);
    assert_int_equal(tase_frame_encode(out, sizeof out, 0, 0, NULL, 1), TASE_EARG);
    assert_int_equal(tase_frame_encode(out, sizeof out, 0, 0, NULL, SIZE_MAX), TASE_EARG);
    assert_int_equal(tase_frame_encode(out, sizeof out, 0, 0, bytes, TASE_DATA_MAX + 1u),
                     TASE_ETOOLONG);
    assert_int_equal(tase_frame_encode(out, sizeof out, 0, 0, bytes, SIZE_MAX), TASE_ETOOLONG);
    assert_int_equal(tase_frame_encode(out, 0, 0, 0, NULL, 0), TASE_ENOSPC);
    assert_int_equal(tase_frame_encode(out, 11, 0, 0, bytes, 4), TASE_ENOSPC);
    assert_memory_equal(out, before, sizeof out);
    assert_int_equal(tase_checksum(0x1234u, NULL, SIZE_MAX), 0x1234u);

    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_rx_feed(&rx, bytes, 3, NULL, NULL), 0); /* a candidate pending */
    memcpy(&copy, &rx, sizeof rx);
    assert_int_equal(tase_rx_feed(&rx, NULL, SIZE_MAX, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_rx_feed(&rx, NULL, 0, NULL, NULL), 0);
    assert_memory_equal(&rx, &copy, sizeof rx);

    for (k = 0; k < 5; k++) {
        memcpy(&bad, &rx, sizeof rx);
        switch (k) {
        case 0: bad.len = (uint16_t)(TASE_FRAME_MAX + 1u); break;
        case 1: bad.len = 0xFFFFu; break;
        case 2: bad.scan = (uint16_t)(bad.len + 1u); break;
        case 3: bad.ncand = (uint8_t)(TASE_RX_CANDIDATES + 1); break;
        default: bad.ncand = 0; break; /* 3 sync bytes held, no candidate */
        }
        memcpy(&copy, &bad, sizeof bad);
        assert_int_equal(tase_rx_feed(&bad, bytes, sizeof bytes, NULL, NULL), TASE_EARG);
        assert_int_equal(tase_rx_push(&bad, 0x5A, NULL, NULL), TASE_EARG);
        assert_int_equal(tase_rx_flush(&bad, NULL, NULL), TASE_EARG);
        assert_memory_equal(&bad, &copy, sizeof bad);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(frame_api_rejects_bad_arguments),
        cmocka_unit_test(encode_zero_length_frame_matches_hand_computed_bytes),
        cmocka_unit_test(encode_with_data_matches_hand_computed_bytes),
        cmocka_unit_test(encode_checksum_wraps_modulo_65536),
        cmocka_unit_test(encode_rejects_bad_arguments_without_writing),
        cmocka_unit_test(encode_in_place_payload_needs_no_copy),
        cmocka_unit_test(checksum_helper_matches_definition),
        cmocka_unit_test(receiver_rejects_null_arguments),
        cmocka_unit_test(api_extreme_lengths_give_error_codes_and_change_nothing),
        cmocka_unit_test(receiver_size_fits_budget),
        cmocka_unit_test(every_split_point_gives_the_same_frame),
        cmocka_unit_test(random_split_points_of_a_long_stream),
        cmocka_unit_test(sync_double_zero_is_found),
        cmocka_unit_test(sync_restarts_after_broken_match),
        cmocka_unit_test(bad_size_is_rejected_at_once),
        cmocka_unit_test(corrupted_size_does_not_swallow_following_packets),
        cmocka_unit_test(checksum_error_then_clean_packet_inside_claimed_length),
        cmocka_unit_test(failed_frame_is_rescanned_from_the_byte_after_its_first_sync),
        cmocka_unit_test(noisy_stream_delivers_every_clean_packet_once_in_order),
        cmocka_unit_test(bit_errors_cost_untouched_frames_no_latency),
        cmocka_unit_test(any_split_gives_identical_frames_and_counters),
        cmocka_unit_test(push_one_byte_at_a_time_equals_feeding_one_buffer),
        cmocka_unit_test(more_overlapping_candidates_than_slots_still_loses_nothing),
        cmocka_unit_test(flush_finds_clean_packets_held_at_end_of_input),
        cmocka_unit_test(flush_of_clean_stream_changes_nothing),
        cmocka_unit_test(frame_embedded_in_a_valid_frame_yields_both_inner_first),
        cmocka_unit_test(sync_inside_a_delivered_frame_starts_nothing),
        cmocka_unit_test(counters_only_reset_on_request),
        cmocka_unit_test(strerror_names_every_code),
    };
    return cmocka_run_group_tests_name("frame", tests, NULL, NULL);
}
