/* Tests of the port helpers: write-all over ports that take part of a
 * write or refuse it, and frame sending. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fake_port.h"
#include "fault_port.h"
#include "tase/codec.h"
#include "tase/ids.h"
#include "tase/port_io.h"
#include "tase/schema.h"

static fake_port_t *new_fake(void)
{
    fake_port_t *f = calloc(1, sizeof *f);
    assert_non_null(f);
    return f;
}

static void write_all_reassembles_partial_writes(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    uint8_t data[100];
    size_t i;
    (void)state;
    for (i = 0; i < sizeof data; i++) {
        data[i] = (uint8_t)i;
    }
    f->write_limit = 7;
    assert_int_equal(tase_port_write_all(&p, data, sizeof data), 100);
    assert_int_equal(f->nout, 100);
    assert_memory_equal(f->out, data, 100);
    assert_int_equal(f->writes, 15); /* ceil(100 / 7) calls */
    free(f);
}

/* A port that takes `budget` bytes in total, then nothing (EAGAIN). */
typedef struct {
    size_t budget, taken;
    unsigned calls;
} stingy_t;

static int stingy_write(void *ctx, const uint8_t *data, size_t n)
{
    stingy_t *s = ctx;
    size_t take = s->budget - s->taken;
    (void)data;
    s->calls++;
    if (take == 0) {
        return TASE_EAGAIN;
    }
    if (take > n) {
        take = n;
    }
    s->taken += take;
    return (int)take;
}

static const tase_port_ops_t stingy_ops = {stingy_write, NULL, NULL};

static void write_all_reports_eagain_when_nothing_went_out(void **state)
{
    stingy_t s = {0, 0, 0};
    tase_port_t p = {&stingy_ops, &s, 0};
    (void)state;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"abcd", 4), TASE_EAGAIN);
    assert_int_equal(s.calls, TASE_PORT_WRITE_TRIES); /* bounded, no endless spin */
}

static void write_all_reports_a_full_queue_when_a_frame_was_cut(void **state)
{
    stingy_t s = {3, 0, 0};
    tase_port_t p = {&stingy_ops, &s, 0};
    (void)state;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"abcdef", 6), TASE_ENOBUFS);
    assert_int_equal(s.taken, 3);
}

static void write_all_passes_hard_errors_on_at_once(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    (void)state;
    f->write_result = TASE_EDOWN;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"ab", 2), TASE_EDOWN);
    assert_int_equal(tase_port_write_all(NULL, (const uint8_t *)"ab", 2), TASE_EARG);
    assert_int_equal(tase_port_write_all(&p, NULL, 2), TASE_EARG);
    free(f);
}

static void send_frame_writes_one_encoded_frame(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    uint8_t want[TASE_FRAME_MAX];
    int n;
    (void)state;
    n = tase_frame_build(0x48, 0x00, (const uint8_t *)"\x01\x02", 2, want, sizeof want);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, (const uint8_t *)"\x01\x02", 2), n);
    assert_int_equal(f->nout, (size_t)n);
    assert_memory_equal(f->out, want, (size_t)n);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, want, 254), TASE_ETOOLONG);
    assert_int_equal(f->nout, (size_t)n); /* nothing more written */
    free(f);
}

static void write_all_rejects_incomplete_ports_and_lengths_beyond_int(void **state)
{
    static const tase_port_ops_t no_write = {NULL, NULL, NULL};
    stingy_t s = {100, 0, 0};
    tase_port_t p = {&stingy_ops, &s, 0};
    tase_port_t no_ops = {NULL, &s, 0};
    tase_port_t nw = {&no_write, &s, 0};
    (void)state;
    assert_int_equal(tase_port_write_all(&no_ops, (const uint8_t *)"ab", 2), TASE_EARG);
    assert_int_equal(tase_port_write_all(&nw, (const uint8_t *)"ab", 2), TASE_EARG);
    /* the result could not be returned as an int: refused before writing */
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"ab", (size_t)0x80000000u),
                     TASE_EARG);
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"ab", SIZE_MAX), TASE_EARG);
    assert_int_equal(s.calls, 0);
    /* zero bytes: nothing to do, NULL data allowed */
    assert_int_equal(tase_port_write_all(&p, NULL, 0), 0);
    assert_int_equal(s.calls, 0);
}

/* A port that returns a fixed value from every write. */
typedef struct {
    int ret;
    unsigned calls;
} fixed_t;

static int fixed_write(void *ctx, const uint8_t *data, size_t n)
{
    fixed_t *x = ctx;
    (void)data;
    x->calls++;
    return x->ret == 1 ? (int)n + 1 : x->ret; /* 1: claim one byte more */
}

static const tase_port_ops_t fixed_ops = {fixed_write, NULL, NULL};

static void write_all_rejects_a_port_claiming_more_than_asked(void **state)
{
    fixed_t x = {1, 0};
    tase_port_t p = {&fixed_ops, &x, 0};
    (void)state;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"abc", 3), TASE_EIO);
    assert_int_equal(x.calls, 1);
}

static void write_all_counts_zero_and_enobufs_as_no_progress(void **state)
{
    fixed_t zero = {0, 0}, full = {TASE_ENOBUFS, 0};
    tase_port_t pz = {&fixed_ops, &zero, 0}, pf = {&fixed_ops, &full, 0};
    (void)state;
    /* a port that takes 0 bytes forever: EAGAIN (nothing sent), bounded */
    assert_int_equal(tase_port_write_all(&pz, (const uint8_t *)"abc", 3), TASE_EAGAIN);
    assert_int_equal(zero.calls, TASE_PORT_WRITE_TRIES);
    /* a full queue keeps its own code */
    assert_int_equal(tase_port_write_all(&pf, (const uint8_t *)"abc", 3), TASE_ENOBUFS);
    assert_int_equal(full.calls, TASE_PORT_WRITE_TRIES);
}

/* A TX ring of 64 bytes that a 9600-baud UART drains (a byte every 1042
 * us), refusing while full; each write() costs 2 us of a microsecond
 * clock that now_ms() reads in milliseconds. A 71-byte frame
 * (GEOREFERENCE_DATA) needs 7 ms of draining: the helper gave up after 64
 * refusals, 0.13 ms, with 64 bytes on the wire (TASE_ENOBUFS). */
typedef struct {
    uint64_t us;
    size_t used, sent;
    unsigned calls;
    uint32_t frozen; /* 1: now_ms() stands still; 2: it only goes back (and
                      * the UART is stopped: nothing drains) */
} ring_t;

static void ring_drain(ring_t *r)
{
    uint64_t drained = r->us / 1042u;
    if (r->frozen != 0u) {
        return;
    }
    while (r->sent < drained && r->used > 0u) {
        r->used--;
        r->sent++;
    }
    r->sent = (size_t)drained;
}

static int ring_write(void *ctx, const uint8_t *data, size_t n)
{
    ring_t *r = ctx;
    size_t room;
    (void)data;
    r->calls++;
    r->us += 2u;
    ring_drain(r);
    room = 64u - r->used;
    if (room == 0u) {
        return TASE_EAGAIN;
    }
    if (n > room) {
        n = room;
    }
    r->used += n;
    return (int)n;
}

static uint32_t ring_now(void *ctx)
{
    const ring_t *r = ctx;
    if (r->frozen == 1u) {
        return 5000u;
    }
    if (r->frozen == 2u) {
        return 5000u - (r->calls & 1u); /* a clock that only goes back */
    }
    return (uint32_t)(r->us / 1000u);
}

static const tase_port_ops_t ring_ops = {ring_write, NULL, ring_now};

static void a_tx_ring_that_refuses_fast_is_retried_until_the_deadline(void **state)
{
    ring_t r;
    tase_port_t p = {&ring_ops, &r, 960};
    uint8_t frame[TASE_FRAME_MAX];
    (void)state;
    memset(frame, 0x5A, sizeof frame);
    memset(&r, 0, sizeof r);
    r.us = 1000000u;
    r.sent = (size_t)(r.us / 1042u);
    assert_int_equal(tase_port_write_all(&p, frame, 71), 71);
    assert_true(r.us - 1000000u < 10000u); /* about 7 ms of draining */
    /* the longest frame: what drains in 100 ms goes, then ENOBUFS */
    memset(&r, 0, sizeof r);
    r.us = 1000000u;
    r.sent = (size_t)(r.us / 1042u);
    assert_int_equal(tase_port_send_frame(&p, 0x00, 0x42, frame, 253), TASE_ENOBUFS);
    assert_true(r.us - 1000000u >= (uint64_t)TASE_PORT_WRITE_TIMEOUT_MS * 1000u);
    assert_true(r.us - 1000000u < ((uint64_t)TASE_PORT_WRITE_TIMEOUT_MS + 1u) * 1000u);
    /* a clock that stands still, or only goes back: the backstop counts
     * the refused calls in a row */
    memset(&r, 0, sizeof r);
    r.used = 64u;
    r.frozen = 1u;
    assert_int_equal(tase_port_write_all(&p, frame, 8), TASE_EAGAIN);
    assert_int_equal(r.calls, TASE_PORT_WRITE_SPINS);
    r.calls = 0u;
    r.frozen = 2u;
    assert_int_equal(tase_port_write_all(&p, frame, 8), TASE_EAGAIN);
    assert_int_equal(r.calls, TASE_PORT_WRITE_SPINS);
}

static void send_frame_checks_the_frame_before_the_port(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    static const uint8_t big[300];
    (void)state;
    assert_int_equal(tase_port_send_frame(NULL, 0x48, 0x00, NULL, 0), TASE_EARG);
    /* an encoder error wins over the missing port: nothing to send anyway */
    assert_int_equal(tase_port_send_frame(NULL, 0x48, 0x00, big, sizeof big), TASE_ETOOLONG);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, NULL, 3), TASE_EARG);
    assert_int_equal(f->nout, 0);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, NULL, 0), 8);
    assert_int_equal(fake_frames_out(f), 1);
    free(f);
}

static void count_tx_counts_link_failures_but_not_caller_mistakes(void **state)
{
    uint32_t sent = 0, errors = 0;
    (void)state;
    assert_int_equal(tase_port_count_tx(14, &sent, &errors), 14);
    assert_int_equal(tase_port_count_tx(0, &sent, &errors), 0);
    assert_int_equal(tase_port_count_tx(TASE_EIO, &sent, &errors), TASE_EIO);
    assert_int_equal(tase_port_count_tx(TASE_EAGAIN, &sent, &errors), TASE_EAGAIN);
    assert_int_equal(tase_port_count_tx(TASE_EARG, &sent, &errors), TASE_EARG);
    assert_int_equal(tase_port_count_tx(TASE_ETOOLONG, &sent, &errors), TASE_ETOOLONG);
    assert_int_equal(tase_port_count_tx(TASE_ELENGTH, &sent, &errors), TASE_ELENGTH);
    assert_int_equal(tase_port_count_tx(TASE_EUNKNOWN, &sent, &errors), TASE_EUNKNOWN);
    assert_int_equal(sent, 2);
    assert_int_equal(errors, 2);
    assert_int_equal(tase_port_count_tx(5, NULL, NULL), 5);
    assert_int_equal(tase_port_count_tx(TASE_EIO, NULL, NULL), TASE_EIO);
}

/* Bad arguments of port_io.h give TASE_EARG / TASE_ETOOLONG and put
 * nothing on the wire: NULL port, ops or write, data NULL with n > 0, a
 * count that does not fit the int result, an over-long frame. */
static void port_io_api_rejects_bad_arguments(void **state)
{
    static fake_port_t fp;
    static const uint8_t data[4] = {1, 2, 3, 4};
    static const tase_port_ops_t no_write = {NULL, fake_read, fake_now};
    tase_port_t port = {&fake_ops, &fp, 0};
    tase_port_t no_ops = {NULL, &fp, 0};
    tase_port_t bad_ops = {&no_write, &fp, 0};
    (void)state;

    memset(&fp, 0, sizeof fp);
    assert_int_equal(tase_port_write_all(NULL, data, 4), TASE_EARG);
    assert_int_equal(tase_port_write_all(&no_ops, data, 4), TASE_EARG);
    assert_int_equal(tase_port_write_all(&bad_ops, data, 4), TASE_EARG);
    assert_int_equal(tase_port_write_all(&port, NULL, 1), TASE_EARG);
    assert_int_equal(tase_port_write_all(&port, NULL, SIZE_MAX), TASE_EARG);
    assert_int_equal(tase_port_write_all(&port, data, (size_t)INT32_MAX + 1u), TASE_EARG);
    assert_int_equal(tase_port_write_all(&port, data, SIZE_MAX), TASE_EARG);
    assert_int_equal(tase_port_send_frame(NULL, 0, 0, data, 4), TASE_EARG);
    assert_int_equal(tase_port_send_frame(&no_ops, 0, 0, data, 4), TASE_EARG);
    assert_int_equal(tase_port_send_frame(&port, 0, 0, NULL, 1), TASE_EARG);
    assert_int_equal(tase_port_send_frame(&port, 0, 0, data, TASE_DATA_MAX + 1u), TASE_ETOOLONG);
    assert_int_equal(tase_port_send_frame(&port, 0, 0, data, SIZE_MAX), TASE_ETOOLONG);
    assert_int_equal(fp.nout, 0);
    assert_int_equal(fp.writes, 0);
    assert_int_equal(tase_port_write_all(&port, NULL, 0), 0);
}

/* ---- one deadline per frame, under faults ------------------------------ */

/* The case: a port stuck for good (a tty that never drains, a CAN
 * queue in bus-off). Each write() waits its whole bound W and takes
 * nothing. One frame must cost one bound, not 64 of them. */
static void a_stuck_port_costs_one_write_bound_per_frame_not_64(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t inner = {&fake_ops, f, 0};
    fault_port_t fp;
    tase_port_t p;
    const uint32_t bounds[3] = {1000u, 100u, 20u};
    unsigned i;
    (void)state;
    for (i = 0; i < 3; i++) {
        fault_init(&fp, &inner, 1u);
        fp.p_stall = 256u;
        fp.write_bound_ms = bounds[i];
        p = fault_port(&fp);
        assert_int_equal(tase_port_send_frame(&p, 0x00, 0x80, (const uint8_t *)"12345678", 8),
                         TASE_EAGAIN);
        assert_true(fp.spent_ms <= TASE_PORT_WRITE_TIMEOUT_MS + bounds[i]);
        assert_true(fp.spent_ms >= (bounds[i] < TASE_PORT_WRITE_TIMEOUT_MS
                                        ? TASE_PORT_WRITE_TIMEOUT_MS
                                        : bounds[i])); /* and it did try until the deadline */
        assert_int_equal(f->nout, 0);
    }
    free(f);
}

/* Every kind of write fault, 3000 seeds: write_all returns n, or the port
 * took nothing (EAGAIN, nothing on the wire), or its queue stayed full
 * (ENOBUFS: nothing or a prefix on the wire), or the hang-up's EIO. What reached the wire
 * is always a prefix of the data, never a byte twice. And the time spent
 * is within the documented bound: deadline + W, plus one W for each stale
 * clock sample that could hide time already spent. */
static void write_all_keeps_its_contract_under_random_faults(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t inner = {&fake_ops, f, 0};
    uint8_t data[TASE_FRAME_MAX];
    uint32_t seed;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof data; k++) {
        data[k] = (uint8_t)(k * 13u + 5u);
    }
    for (seed = 1; seed <= 3000u; seed++) {
        fault_port_t fp;
        tase_port_t p;
        size_t n;
        int r;
        uint32_t stales_before;
        memset(f, 0, sizeof *f);
        f->now = seed & 1u ? 0xFFFFF000u : seed * 7919u; /* across the wrap, too */
        fault_init(&fp, &inner, seed);
        fp.p_short = fault_rand(&fp) & 0xFFu;
        fp.p_eagain = fault_rand(&fp) & 0xFFu;
        fp.p_eintr = fault_rand(&fp) & 0x7Fu;
        fp.p_stall = fault_rand(&fp) & 0x3Fu;
        fp.p_jump = fault_rand(&fp) & 0x1Fu;
        fp.p_stale = fault_rand(&fp) & 0x1Fu;
        fp.p_slow = fault_rand(&fp) & 0x1Fu;
        fp.slow_ms = fault_rand(&fp) % 50u;
        fp.write_bound_ms = 1u + fault_rand(&fp) % 1000u;
        fp.hangup_after = seed % 5u == 0u ? fault_rand(&fp) % 20u + 1u : 0u;
        f->write_limit = (size_t)(fault_rand(&fp) % 40u);
        n = 1u + fault_rand(&fp) % sizeof data;
        p = fault_port(&fp);
        stales_before = fp.stales;
        r = tase_port_write_all(&p, data, n);
        if (r >= 0) {
            assert_int_equal(r, (int)n);
            assert_int_equal(f->nout, n);
        } else if (r == TASE_EAGAIN) {
            assert_int_equal(f->nout, 0);
        } else if (r == TASE_ENOBUFS) {
            assert_true(f->nout < n); /* nothing, or a cut frame */
        } else {
            assert_int_equal(r, TASE_EIO); /* the hang-up */
            assert_true(fp.hangups > 0u);
        }
        assert_memory_equal(f->out, data, f->nout);
        assert_true(fp.spent_ms <=
                    TASE_PORT_WRITE_TIMEOUT_MS +
                        (fp.write_bound_ms + fp.slow_ms) * (1u + fp.stales - stales_before));
    }
    free(f);
}

static void elapsed_is_wrap_safe_and_a_stale_sample_is_no_time(void **state)
{
    (void)state;
    assert_int_equal(tase_port_elapsed_ms(1100u, 1000u), 100);
    assert_int_equal(tase_port_elapsed_ms(0x0000000Fu, 0xFFFFFFF0u), 0x1F);
    assert_int_equal(tase_port_elapsed_ms(0xFFFFF000u + 4096u, 0xFFFFF000u), 4096);
    assert_int_equal(tase_port_elapsed_ms(999u, 1000u), 0);              /* 1 ms stale */
    assert_int_equal(tase_port_elapsed_ms(0xFFFFFFFFu, 0u), 0);          /* stale across the wrap */
    assert_int_equal(tase_port_elapsed_ms(0x7FFFFFFFu, 0u), 0x7FFFFFFF); /* the longest */
    assert_int_equal(tase_port_elapsed_ms(0x80000000u, 0u), 0);
}

static void send_msg_writes_the_codec_frame_and_checks_it_first(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    tase_gimbal_angle_t a = {100, -200, 0};
    uint8_t want[TASE_FRAME_MAX];
    int n;
    (void)state;
    n = tase_packet_encode(TASE_ID_GIMBAL_ANGLE, &a, want, sizeof want);
    assert_int_equal(tase_port_send_msg(&p, TASE_ID_GIMBAL_ANGLE, &a), n);
    assert_memory_equal(f->out, want, (size_t)n);
    f->nout = 0;
    assert_int_equal(tase_port_send_msg(&p, TASE_ID_PACKET_RATE, NULL), 8); /* a query */
    assert_int_equal(tase_port_send_msg(&p, TASE_ID_GIMBAL_ANGLE, NULL), TASE_ELENGTH);
    assert_int_equal(tase_port_send_msg(&p, TASE_ID(0x28, 0), &a), TASE_EUNKNOWN);
    assert_int_equal(tase_port_send_msg(NULL, TASE_ID(0x28, 0), &a), TASE_EUNKNOWN);
    assert_int_equal(tase_port_send_msg(NULL, TASE_ID_GIMBAL_ANGLE, &a), TASE_EARG);
    assert_int_equal(f->nout, 8);
    free(f);
}

/* Issue 26: a frame goes out in pieces of at most 16 bytes (no frame or
 * packet buffer on the stack), byte for byte the frame tase_frame_build()
 * and tase_packet_encode() build, every piece but the last a multiple of 8
 * bytes (a CAN port packs it into whole CAN frames, as one write). Every
 * data length, with a port taking all and a port taking 5 bytes a call. */
static void frames_go_out_in_staged_pieces_byte_for_byte(void **state)
{
    static uint8_t data[TASE_DATA_MAX], camera[TASE_CAMERA_PASS_MAX];
    uint8_t want[TASE_FRAME_MAX];
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f, 0};
    tase_camera_pass_t cp;
    size_t len;
    unsigned limit;
    int n;
    (void)state;
    for (len = 0; len < sizeof data; len++) {
        data[len] = (uint8_t)(len * 37u + 11u);
    }
    for (len = 0; len < sizeof camera; len++) {
        camera[len] = (uint8_t)(len * 13u + 1u);
    }
    for (limit = 0; limit <= 5; limit += 5) {
        f->write_limit = limit;
        for (len = 0; len <= TASE_DATA_MAX; len++) {
            n = tase_frame_build(0x12, 0x34, data, len, want, sizeof want);
            f->nout = 0;
            f->writes = 0;
            assert_int_equal(tase_port_send_frame(&p, 0x12, 0x34, data, len), n);
            assert_int_equal(f->nout, n);
            assert_memory_equal(f->out, want, (size_t)n);
            if (limit == 0) {
                assert_int_equal(f->writes, ((unsigned)n + 15u) / 16u);
            }
        }
        /* CAMERA_PASS: the camera bytes from the caller's buffer */
        for (len = 0; len <= TASE_CAMERA_PASS_MAX; len += 7) {
            cp.camera = 1;
            cp.baud = 8;
            cp.len = (uint8_t)len;
            cp.data = camera;
            n = tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, want, sizeof want);
            f->nout = 0;
            assert_int_equal(tase_port_send_msg(&p, TASE_ID_CAMERA_PASS, &cp), n);
            assert_int_equal(f->nout, n);
            assert_memory_equal(f->out, want, (size_t)n);
        }
    }
    /* every packet of the schema, at its table length, with data */
    f->write_limit = 0;
    for (len = 0; tase_schema_at(len) != NULL; len++) {
        const tase_packet_desc_t *d = tase_schema_at(len);
        tase_packet_msg_t m;
        memset(&m, 0x5C, sizeof m);
        if (d->id == TASE_ID_CAMERA_PASS) {
            m.camera_pass.len = 9;
            m.camera_pass.data = camera;
        }
        n = tase_packet_encode(d->id, &m, want, sizeof want);
        assert_true(n >= 8);
        f->nout = 0;
        assert_int_equal(tase_port_send_msg(&p, d->id, &m), n);
        assert_memory_equal(f->out, want, (size_t)n);
    }
    cp.len = TASE_CAMERA_PASS_MAX + 1u;
    assert_int_equal(tase_port_send_msg(&p, TASE_ID_CAMERA_PASS, &cp), TASE_ETOOLONG);
    cp.len = 3;
    cp.data = NULL;
    f->nout = 0;
    assert_int_equal(tase_port_send_msg(&p, TASE_ID_CAMERA_PASS, &cp), TASE_EARG);
    assert_int_equal(f->nout, 0);
    free(f);
}

/* Issue 25 item 9: the fault port's clock faults with a zero range are
 * off (they divided by zero), and a write that is partial AND slow (a
 * driver trickling a frame out) still gets a whole frame out within one
 * deadline, or a cut frame reported as TASE_ENOBUFS after it, with the
 * time spent bounded by the deadline plus one slow call. */
static void slow_partial_writes_and_zero_fault_ranges(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t inner = {&fake_ops, f, 0};
    uint8_t data[TASE_FRAME_MAX];
    fault_port_t fp;
    tase_port_t p;
    uint32_t t0;
    unsigned i;
    int r;
    (void)state;
    for (i = 0; i < sizeof data; i++) {
        data[i] = (uint8_t)(i * 7u + 3u);
    }
    /* jump_max_ms / stale_max_ms 0: now_ms() works and never moves */
    fault_init(&fp, &inner, 7);
    fp.p_jump = 255;
    fp.p_stale = 255;
    fp.jump_max_ms = 0;
    fp.stale_max_ms = 0;
    p = fault_port(&fp);
    t0 = p.ops->now_ms(p.ctx);
    for (i = 0; i < 100u; i++) {
        assert_int_equal(p.ops->now_ms(p.ctx), t0);
    }
    assert_int_equal(fp.jumps + fp.stales, 0);

    /* every write partial and 10 ms slow: 24 bytes make it in 100 ms */
    fault_init(&fp, &inner, 11);
    fp.p_slow = 256;
    fp.slow_ms = 10;
    p = fault_port(&fp);
    f->nout = 0;
    r = tase_port_write_all(&p, data, 2);
    assert_int_equal(r, 2); /* at most 2 calls of 10 ms */
    assert_true(fp.slows >= 1u && fp.spent_ms <= 20u);
    f->nout = 0;
    fp.spent_ms = 0;
    f->write_limit = 4; /* the driver takes 4 bytes a call, 10 ms each */
    r = tase_port_write_all(&p, data, sizeof data);
    assert_int_equal(r, TASE_ENOBUFS); /* 261 bytes cannot trickle out in 100 ms */
    assert_true(f->nout > 0u && f->nout < sizeof data);
    assert_memory_equal(f->out, data, f->nout);
    assert_true(fp.spent_ms >= TASE_PORT_WRITE_TIMEOUT_MS);
    assert_true(fp.spent_ms <= TASE_PORT_WRITE_TIMEOUT_MS + fp.slow_ms);
    free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(port_io_api_rejects_bad_arguments),
        cmocka_unit_test(count_tx_counts_link_failures_but_not_caller_mistakes),
        cmocka_unit_test(write_all_reassembles_partial_writes),
        cmocka_unit_test(write_all_reports_eagain_when_nothing_went_out),
        cmocka_unit_test(write_all_reports_a_full_queue_when_a_frame_was_cut),
        cmocka_unit_test(write_all_passes_hard_errors_on_at_once),
        cmocka_unit_test(send_frame_writes_one_encoded_frame),
        cmocka_unit_test(write_all_rejects_incomplete_ports_and_lengths_beyond_int),
        cmocka_unit_test(write_all_rejects_a_port_claiming_more_than_asked),
        cmocka_unit_test(write_all_counts_zero_and_enobufs_as_no_progress),
        cmocka_unit_test(send_frame_checks_the_frame_before_the_port),
        cmocka_unit_test(a_tx_ring_that_refuses_fast_is_retried_until_the_deadline),
        cmocka_unit_test(a_stuck_port_costs_one_write_bound_per_frame_not_64),
        cmocka_unit_test(write_all_keeps_its_contract_under_random_faults),
        cmocka_unit_test(elapsed_is_wrap_safe_and_a_stale_sample_is_no_time),
        cmocka_unit_test(send_msg_writes_the_codec_frame_and_checks_it_first),
        cmocka_unit_test(frames_go_out_in_staged_pieces_byte_for_byte),
        cmocka_unit_test(slow_partial_writes_and_zero_fault_ranges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
