/*
 * Worst-case instructions per call of the public functions of src/ on
 * Cortex-M under QEMU (bench/bench.sh writes docs/TIMING.md from it). Each
 * function is called on inputs built to be its worst (named in the
 * output), from a state put back before every call, and counted exactly
 * (measure.c). One line per function:
 *   timing FUNCTION INSTRUCTIONS WORST-CASE-INPUT (underscores for spaces)
 *
 * The calls are written against today's API in this one file; a function
 * that is renamed or removed breaks the build (bench.sh stops there), and
 * bench.sh also checks that every function it lists was printed.
 */
#include <stdio.h>
#include <string.h>

#include "../streams.h"
#include "measure.h"
#include "tase/can.h"
#include "tase/codec.h"
#include "tase/dispatch.h"
#include "tase/frame.h"
#include "tase/klv.h"
#include "tase/schema.h"

#define NOINLINE __attribute__((noinline, noipa))

static uint8_t stream[16384];
static size_t stream_n;
static tase_rx_t rx, rx_snap;
static uint8_t out[TASE_FRAME_MAX + 16u];
static uint8_t data[TASE_DATA_MAX];
static unsigned long sink;

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    sink += f->len;
}

static void report(const char *fn, unsigned long insns, const char *input)
{
    printf("timing %s %lu %s\n", fn, insns, input);
}

static void nothing(void *ctx)
{
    (void)ctx;
}

static void restore_rx(void *ctx)
{
    (void)ctx;
    rx = rx_snap;
}

/* ---- receiver ---------------------------------------------------------- */

static const uint8_t *arg_p;
static size_t arg_n;
static uint32_t arg_now;

NOINLINE static void c_checksum(void *ctx)
{
    (void)ctx;
    sink += tase_checksum(0u, arg_p, arg_n);
}

NOINLINE static void c_encode(void *ctx)
{
    (void)ctx;
    (void)tase_frame_build(0x08u, 0x10u, data, TASE_DATA_MAX, out, sizeof(out));
}

NOINLINE static void c_init(void *ctx)
{
    (void)ctx;
    (void)tase_rx_init(&rx);
}

NOINLINE static void c_stats_reset(void *ctx)
{
    (void)ctx;
    (void)tase_rx_stats_reset(&rx);
}

NOINLINE static void c_set_timing(void *ctx)
{
    (void)ctx;
    (void)tase_rx_set_timing(&rx, 5760u, 0u);
}

NOINLINE static void c_quiet_ms(void *ctx)
{
    (void)ctx;
    sink += tase_rx_quiet_ms(&rx, arg_now);
}

NOINLINE static void c_flush(void *ctx)
{
    (void)ctx;
    (void)tase_rx_flush(&rx, on_frame, NULL);
}

NOINLINE static void c_tick(void *ctx)
{
    (void)ctx;
    (void)tase_rx_tick(&rx, arg_now, on_frame, NULL);
}

/* The longest call of `call` from every state that pushing a prefix of the
 * stream (up to `upto` bytes) leaves: coarse on all, exact on the top. */
static unsigned long worst_over_prefixes(measure_fn call, size_t upto, uint32_t now, size_t *where)
{
    static uint16_t coarse[2048];
    size_t i, best_at = 0;
    uint16_t top = 0;
    unsigned long best = 0;
    if (upto > 2048u) {
        upto = 2048u;
    }
    (void)tase_rx_init(&rx_snap);
    (void)tase_rx_set_timing(&rx_snap, 5760u, 0u);
    for (i = 0; i < upto; i++) {
        uint32_t t0;
        (void)tase_rx_push(&rx_snap, stream[i], NULL, NULL);
        (void)tase_rx_tick(&rx_snap, 0u, NULL, NULL); /* the line active at 0 */
        rx = rx_snap;
        arg_now = now;
        t0 = measure_ticks();
        call(NULL);
        coarse[i] = (uint16_t)(t0 - measure_ticks());
        top = coarse[i] > top ? coarse[i] : top;
    }
    (void)tase_rx_init(&rx_snap);
    (void)tase_rx_set_timing(&rx_snap, 5760u, 0u);
    for (i = 0; i < upto; i++) {
        (void)tase_rx_push(&rx_snap, stream[i], NULL, NULL);
        (void)tase_rx_tick(&rx_snap, 0u, NULL, NULL);
        if (coarse[i] + 1u >= top) {
            unsigned long e;
            arg_now = now;
            e = measure_exact(restore_rx, call, NULL);
            if (e > best) {
                best = e;
                best_at = i + 1u;
            }
        }
    }
    *where = best_at;
    return best;
}

static const char *const rx_streams[] = {"held255", "burst", "syncrand",
                                         "sync4",   "zeros", "badsize"};

static void receiver(void)
{
    static char what[96];
    size_t s, at;
    unsigned long e, worst_flush = 0, worst_tick = 0, worst_quiet = 0;
    const char *flush_in = "", *tick_in = "", *quiet_in = "";
    size_t flush_at = 0, tick_at = 0, quiet_at = 0;

    arg_p = stream;
    arg_n = TASE_FRAME_MAX;
    report("tase_checksum", measure_exact(nothing, c_checksum, NULL), "261_bytes_(a_whole_frame)");
    memset(data, 0xA5, sizeof(data));
    report("tase_frame_build", measure_exact(nothing, c_encode, NULL), "253_data_bytes");
    report("tase_rx_init", measure_exact(nothing, c_init, NULL), "any_state");
    report("tase_rx_stats_reset", measure_exact(nothing, c_stats_reset, NULL), "any_state");
    (void)tase_rx_init(&rx_snap);
    report("tase_rx_set_timing", measure_exact(restore_rx, c_set_timing, NULL), "any_state");

    for (s = 0; s < sizeof(rx_streams) / sizeof(rx_streams[0]); s++) {
        stream_n = bench_stream(rx_streams[s], stream, sizeof(stream));
        (void)stream_n;
        e = worst_over_prefixes(c_flush, 2048u, 0u, &at);
        if (e > worst_flush) {
            worst_flush = e, flush_in = rx_streams[s], flush_at = at;
        }
        /* a tick 100 s after the last byte: past every quiet limit */
        e = worst_over_prefixes(c_tick, 2048u, 100000u, &at);
        if (e > worst_tick) {
            worst_tick = e, tick_in = rx_streams[s], tick_at = at;
        }
        e = worst_over_prefixes(c_quiet_ms, 600u, 7u, &at);
        if (e > worst_quiet) {
            worst_quiet = e, quiet_in = rx_streams[s], quiet_at = at;
        }
    }
    snprintf(what, sizeof(what), "after_%lu_bytes_of_%s_(settles_the_window)",
             (unsigned long)flush_at, flush_in);
    report("tase_rx_flush", worst_flush, what);
    snprintf(what, sizeof(what), "100_s_quiet_after_%lu_bytes_of_%s_(settles)",
             (unsigned long)tick_at, tick_in);
    report("tase_rx_tick", worst_tick, what);
    snprintf(what, sizeof(what), "after_%lu_bytes_of_%s", (unsigned long)quiet_at, quiet_in);
    report("tase_rx_quiet_ms", worst_quiet, what);
}

/* ---- codec and dispatch ------------------------------------------------ */

static uint16_t arg_id;
static size_t arg_len;
static tase_frame_t arg_frame;
static tase_packet_msg_t msg;
static tase_dispatch_t disp;
static tase_packet_handler_t handlers[TASE_PKT_COUNT];

static void on_msg(void *user, const tase_frame_t *f, const void *m)
{
    (void)user;
    (void)m;
    sink += f->len;
}

NOINLINE static void c_packet_encode(void *ctx)
{
    (void)ctx;
    (void)tase_packet_encode_len(arg_id, &msg, arg_len, out, sizeof(out));
}

NOINLINE static void c_packet_decode(void *ctx)
{
    (void)ctx;
    (void)tase_packet_decode(&arg_frame, &msg);
}

NOINLINE static void c_dispatch(void *ctx)
{
    (void)ctx;
    tase_dispatch_frame(&disp, &arg_frame);
}

static void codec(void)
{
    static char what[3][64];
    size_t i;
    unsigned long e, best[3] = {0, 0, 0};
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        handlers[i] = on_msg;
    }
    (void)tase_dispatch_init(&disp, handlers, on_frame, NULL, NULL, &rx.stats);
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *d = tase_schema_at(i);
        int n;
        if (d == NULL) {
            continue;
        }
        memset(&msg, 0, sizeof(msg));
        arg_id = d->id;
        arg_len = d->len;
        n = tase_packet_encode_len(arg_id, &msg, arg_len, out, sizeof(out));
        if (n < 0) {
            continue; /* a length this packet does not take with a zero message */
        }
        e = measure_exact(nothing, c_packet_encode, NULL);
        if (e > best[0]) {
            best[0] = e;
            snprintf(what[0], sizeof(what[0]), "id_0x%04X_(%u_data_bytes)", (unsigned)d->id,
                     (unsigned)d->len);
        }
        arg_frame.offset = 0u;
        arg_frame.group = out[4];
        arg_frame.type = out[5];
        arg_frame.len = (uint8_t)(out[3] - 2u);
        arg_frame.data = &out[TASE_FRAME_HEADER];
        e = measure_exact(nothing, c_packet_decode, NULL);
        if (e > best[1]) {
            best[1] = e;
            snprintf(what[1], sizeof(what[1]), "id_0x%04X_(%u_data_bytes)", (unsigned)d->id,
                     (unsigned)d->len);
        }
        e = measure_exact(nothing, c_dispatch, NULL);
        if (e > best[2]) {
            best[2] = e;
            snprintf(what[2], sizeof(what[2]), "id_0x%04X_(%u_data_bytes,_trivial_handler)",
                     (unsigned)d->id, (unsigned)d->len);
        }
    }
    report("tase_packet_encode_len", best[0], what[0]);
    report("tase_packet_decode", best[1], what[1]);
    report("tase_dispatch_frame", best[2], what[2]);
}

/* ---- CAN --------------------------------------------------------------- */

static tase_can_split_t split, split_snap;
static tase_can_rx_t crx, crx_snap;
static tase_can_frame_t cf;

static void restore_split(void *ctx)
{
    (void)ctx;
    split = split_snap;
}

static void restore_crx(void *ctx)
{
    (void)ctx;
    crx = crx_snap;
}

NOINLINE static void c_split_next(void *ctx)
{
    (void)ctx;
    (void)tase_can_split_next(&split, &cf);
}

NOINLINE static void c_can_rx_feed(void *ctx)
{
    (void)ctx;
    (void)tase_can_rx_feed(&crx, &cf, on_frame, NULL);
}

static void can(void)
{
    static char what[64];
    size_t i, s;
    unsigned long e, best = 0;
    int n = tase_frame_build(0x08u, 0x10u, data, TASE_DATA_MAX, out, sizeof(out));
    (void)tase_can_split_init(&split_snap, TASE_CAN_ROLE_GIMBAL, out, (size_t)n);
    report("tase_can_split_next", measure_exact(restore_split, c_split_next, NULL),
           "8_of_a_261-byte_frame");
    /* every 8-byte frame of the adversarial streams, as the gimbal sends them */
    for (s = 0; s < 3u; s++) {
        tase_can_split_t sp;
        (void)bench_stream(rx_streams[s], stream, sizeof(stream));
        (void)tase_can_rx_init(&crx_snap, TASE_CAN_ROLE_HOST);
        (void)tase_can_split_init(&sp, TASE_CAN_ROLE_GIMBAL, stream, 2048u);
        for (i = 0; tase_can_split_next(&sp, &cf) > 0; i++) {
            e = measure_exact(restore_crx, c_can_rx_feed, NULL);
            if (e > best) {
                best = e;
                snprintf(what, sizeof(what), "CAN_frame_%lu_of_%s", (unsigned long)i,
                         rx_streams[s]);
            }
            (void)tase_can_rx_feed(&crx_snap, &cf, NULL, NULL);
        }
    }
    report("tase_can_rx_feed", best, what);
}

/* ---- KLV --------------------------------------------------------------- */

static tase_klv_t klv;
static tase_klv_rx_t krx, krx_snap;
static uint8_t kbuf[TASE_KLV_PACKET_MAX];
static size_t klen;

static void on_klv(void *user, uint32_t offset, const tase_klv_t *k)
{
    (void)user;
    (void)offset;
    sink += k->alt;
}

static void on_klv_error(void *user, uint32_t offset, int err)
{
    (void)user;
    (void)offset;
    sink += (unsigned long)(long)err;
}

static void restore_krx(void *ctx)
{
    (void)ctx;
    krx = krx_snap;
}

NOINLINE static void c_klv_encode(void *ctx)
{
    (void)ctx;
    (void)tase_klv_encode(&klv, kbuf, sizeof(kbuf));
}

NOINLINE static void c_klv_decode(void *ctx)
{
    (void)ctx;
    (void)tase_klv_decode(kbuf, klen, &klv);
}

NOINLINE static void c_klv_rx_feed(void *ctx)
{
    (void)ctx;
    (void)tase_klv_rx_feed(&krx, arg_p, arg_n, on_klv, on_klv_error, NULL);
}

static void klv_(void)
{
    static char what[64];
    size_t i;
    unsigned long e, best = 0;
    int n;
    memset(&klv, 0, sizeof(klv));
    n = tase_klv_encode(&klv, kbuf, sizeof(kbuf));
    klen = n > 0 ? (size_t)n : 0u;
    report("tase_klv_encode", measure_exact(nothing, c_klv_encode, NULL), "a_full_packet");
    report("tase_klv_decode", measure_exact(nothing, c_klv_decode, NULL), "a_full_packet");
    /* 64-byte feeds over packets, each with one byte corrupted, back to back */
    for (i = 0; i + klen <= sizeof(stream); i += klen) {
        memcpy(&stream[i], kbuf, klen);
        stream[i + (i / klen) % klen] ^= 0x01u;
    }
    (void)tase_klv_rx_init(&krx_snap);
    for (i = 0; i + 64u <= 4096u; i += 64u) {
        arg_p = &stream[i];
        arg_n = 64u;
        e = measure_exact(restore_krx, c_klv_rx_feed, NULL);
        if (e > best) {
            best = e;
            snprintf(what, sizeof(what), "64_bytes_at_%lu_of_corrupted_packets", (unsigned long)i);
        }
        (void)tase_klv_rx_feed(&krx_snap, arg_p, 64u, NULL, NULL, NULL);
    }
    report("tase_klv_rx_feed/64", best, what);
}

int main(void)
{
    uint32_t t0;
    measure_start();
    t0 = measure_ticks();
    measure_known_loop(1000000u);
    printf("calibration %lu\n", measure_since(t0));
    receiver();
    codec();
    can();
    klv_();
    printf("done\n");
    return 0;
}
