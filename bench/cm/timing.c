/*
 * Worst-case instructions per call of the public functions of src/ on
 * Cortex-M under QEMU (bench/bench.sh writes docs/TIMING.md from it). Each
 * function is called on inputs built to be its worst (named in the
 * output), from a state put back before every call, and counted exactly
 * (measure.c). One line per function:
 *   timing FUNCTION INSTRUCTIONS WORST-CASE-INPUT (the rest of the line)
 *
 * This file has main(), the shared helpers (timing.h) and the receiver,
 * CAN stream and KLV stream calls; timing_codec.c, timing_schema.c,
 * timing_roles.c and timing_misc.c the rest. The calls are written
 * against today's API; a function that is renamed or removed breaks the
 * build (bench.sh stops there).
 */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "../streams.h"
#include "tase/can.h"
#include "tase/frame.h"
#include "tase/klv.h"
#include "timing.h"

static uint8_t stream[16384];
static size_t stream_n;
static tase_rx_t rx, rx_snap;
static uint8_t out[TASE_FRAME_MAX + 16u];
static uint8_t data[TASE_DATA_MAX];
volatile unsigned long timing_sink;
#define sink timing_sink

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    sink += f->len;
}

void report(const char *fn, unsigned long insns, const char *input)
{
    printf("timing %s %lu %s\n", fn, insns, input);
}

void nothing(void *ctx)
{
    (void)ctx;
}

unsigned long measure_plain(measure_fn call)
{
    return measure_exact(nothing, call, NULL);
}

void worst_try(worst_t *w, unsigned long insns, const char *fmt, ...)
{
    va_list ap;
    if (insns <= w->insns) {
        return;
    }
    w->insns = insns;
    va_start(ap, fmt);
    (void)vsnprintf(w->input, sizeof(w->input), fmt, ap);
    va_end(ap);
}

void worst_report(const char *fn, const worst_t *w, const char *how)
{
    static char line[448];
    (void)snprintf(line, sizeof(line), "%s%s", w->input, how);
    report(fn, w->insns, line);
}

const tase_packet_desc_t *cur_pkt;
size_t cur_len;
tase_packet_msg_t full_msg;
uint8_t camera_bytes[TASE_CAMERA_PASS_MAX];

size_t fill_full_msg(const tase_packet_desc_t *p)
{
    memset(&full_msg, 0xA5, sizeof(full_msg));
    if ((p->flags & TASE_LEN_TAIL) != 0u) {
        memset(camera_bytes, 0x5A, sizeof(camera_bytes));
        full_msg.camera_pass.camera = 1u;
        full_msg.camera_pass.baud = 2u;
        full_msg.camera_pass.len = (uint8_t)TASE_CAMERA_PASS_MAX;
        full_msg.camera_pass.data = camera_bytes;
        return (size_t)p->len + TASE_CAMERA_PASS_MAX;
    }
    return p->len;
}

uint8_t pkt_frame[TASE_FRAME_MAX + 16u];
size_t pkt_frame_n;
tase_frame_t pkt_f;

bool prep_full_frame(const tase_packet_desc_t *p)
{
    int n;
    cur_len = fill_full_msg(p);
    n = tase_packet_encode(p->id, &full_msg, pkt_frame, sizeof(pkt_frame));
    if (n < 0) {
        return false;
    }
    pkt_frame_n = (size_t)n;
    pkt_f.offset = 0u;
    pkt_f.group = TASE_ID_GROUP(p->id);
    pkt_f.type = TASE_ID_TYPE(p->id);
    pkt_f.len = (uint8_t)cur_len;
    pkt_f.data = &pkt_frame[TASE_FRAME_HEADER];
    return true;
}

void over_packets(worst_t *w, bool (*prep)(const tase_packet_desc_t *p), measure_fn setup,
                  measure_fn call)
{
    size_t i;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        cur_pkt = tase_schema_at(i);
        if (cur_pkt == NULL || !prep(cur_pkt)) {
            continue;
        }
        worst_try(w, measure_exact(setup, call, NULL), "%s (%lu data bytes)",
                  tase_schema_packet_name(cur_pkt), (unsigned long)cur_len);
    }
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

static const char *const rx_streams[] = {"held255", "burst",     "syncrand", "sync4",   "zeros",
                                         "badsize", "heldnoise", "halfsum",  "synclong"};

static void receiver(void)
{
    static char what[96];
    size_t s, at;
    unsigned long e, worst_flush = 0, worst_tick = 0, worst_quiet = 0;
    const char *flush_in = "", *tick_in = "", *quiet_in = "";
    size_t flush_at = 0, tick_at = 0, quiet_at = 0;

    arg_p = stream;
    arg_n = TASE_FRAME_MAX;
    report("tase_checksum", measure_exact(nothing, c_checksum, NULL), "261 bytes (a whole frame)");
    memset(data, 0xA5, sizeof(data));
    report("tase_frame_build", measure_exact(nothing, c_encode, NULL), "253 data bytes");
    report("tase_rx_init", measure_exact(nothing, c_init, NULL), "any state");
    report("tase_rx_stats_reset", measure_exact(nothing, c_stats_reset, NULL), "any state");
    (void)tase_rx_init(&rx_snap);
    report("tase_rx_set_timing", measure_exact(restore_rx, c_set_timing, NULL), "any state");

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
    snprintf(what, sizeof(what), "after %lu bytes of %s (settles the window)",
             (unsigned long)flush_at, flush_in);
    report("tase_rx_flush", worst_flush, what);
    snprintf(what, sizeof(what), "100 s quiet after %lu bytes of %s (settles)",
             (unsigned long)tick_at, tick_in);
    report("tase_rx_tick", worst_tick, what);
    snprintf(what, sizeof(what), "after %lu bytes of %s", (unsigned long)quiet_at, quiet_in);
    report("tase_rx_quiet_ms", worst_quiet, what);
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
           "8 of a 261-byte frame");
    /* every 8-byte frame of the adversarial streams, as the gimbal sends them */
    static const char *const can_streams[] = {"held255", "burst", "syncrand", "halfsum"};
    for (s = 0; s < sizeof(can_streams) / sizeof(can_streams[0]); s++) {
        tase_can_split_t sp;
        (void)bench_stream(can_streams[s], stream, sizeof(stream));
        (void)tase_can_rx_init(&crx_snap, TASE_CAN_ROLE_HOST);
        (void)tase_can_split_init(&sp, TASE_CAN_ROLE_GIMBAL, stream, 2048u);
        for (i = 0; tase_can_split_next(&sp, &cf) > 0; i++) {
            e = measure_exact(restore_crx, c_can_rx_feed, NULL);
            if (e > best) {
                best = e;
                snprintf(what, sizeof(what), "CAN frame %lu of %s", (unsigned long)i,
                         can_streams[s]);
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

MEASURED(c_klv_rx_init, tase_klv_rx_init(&krx))
MEASURED(c_klv_stats_reset, tase_klv_rx_stats_reset(&krx))
MEASURED(c_klv_flush, tase_klv_rx_flush(&krx, on_klv, on_klv_error, NULL))

/* A packet with the longest BER length (4 octets) cut one byte short (90
 * bytes: the scanner holds it), every value byte `v`, or the values
 * spelling as much of the key as they can (a false key in each value). */
static size_t klv_cut_packet(uint8_t *buf, int v)
{
    static const uint8_t key[8] = {0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01};
    static const uint8_t lens[TASE_KLV_ITEMS] = {8, 4, 4, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2};
    static const uint8_t head[21] = {0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01, 0, 0,   0,
                                     0,    0,    0,    0,    0,    0x84, 0,    0,    0, 0x46};
    size_t n = sizeof(head), t, i;
    memcpy(buf, head, sizeof(head));
    for (t = 0; t < TASE_KLV_ITEMS; t++) {
        buf[n++] = (uint8_t)(t + 1u);
        buf[n++] = lens[t];
        for (i = 0; i < lens[t]; i++) {
            buf[n++] = v >= 0 ? (uint8_t)v : key[i];
        }
    }
    return n - 1u; /* the checksum's last byte missing */
}

/* The scanner's small calls, and flush on the windows that hold the
 * most. */
static void klv_scanner(void)
{
    static uint8_t buf[TASE_KLV_PACKET_MAX + 8u];
    static const int fills[] = {0x06, -1, 0x00};
    static const char *const names[] = {"every value byte 0x06 (a false key start each)",
                                        "values spelling the key's first bytes",
                                        "every value byte 0x00"};
    worst_t w = {0, ""};
    size_t k;
    report("tase_klv_rx_init", measure_plain(c_klv_rx_init), "any state");
    report("tase_klv_rx_stats_reset", measure_plain(c_klv_stats_reset), "any state");
    for (k = 0; k < COUNT(fills); k++) {
        size_t n = klv_cut_packet(buf, fills[k]);
        (void)tase_klv_rx_init(&krx_snap);
        (void)tase_klv_rx_feed(&krx_snap, buf, n, NULL, NULL, NULL);
        worst_try(&w, measure_exact(restore_krx, c_klv_flush, NULL),
                  "%u bytes held: a packet with a 4-octet BER length cut 1 byte short, %s",
                  (unsigned)krx_snap.len, names[k]);
    }
    worst_report("tase_klv_rx_flush", &w, "");
}

static void klv_(void)
{
    static char what[96];
    static uint8_t held[TASE_KLV_PACKET_MAX + 8u];
    static uint8_t sixes[64];
    size_t i;
    unsigned long e, best = 0;
    int n;
    memset(&klv, 0, sizeof(klv));
    n = tase_klv_encode(&klv, kbuf, sizeof(kbuf));
    klen = n > 0 ? (size_t)n : 0u;
    report("tase_klv_encode", measure_exact(nothing, c_klv_encode, NULL), "a full packet");
    report("tase_klv_decode", measure_exact(nothing, c_klv_decode, NULL), "a full packet");
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
            snprintf(what, sizeof(what), "64 bytes at %lu of corrupted packets", (unsigned long)i);
        }
        (void)tase_klv_rx_feed(&krx_snap, arg_p, 64u, NULL, NULL, NULL);
    }
    /* A review's input: the 90-byte cut packet held (every value 0x06),
     * then 64 bytes of 0x06, each a false key start (the scanner moved its
     * window down for each: 41,850 instructions on Cortex-M4 -O2). */
    (void)tase_klv_rx_init(&krx_snap);
    (void)tase_klv_rx_feed(&krx_snap, held, klv_cut_packet(held, 0x06), NULL, NULL, NULL);
    memset(sixes, 0x06, sizeof(sixes));
    arg_p = sixes;
    arg_n = sizeof(sixes);
    e = measure_exact(restore_krx, c_klv_rx_feed, NULL);
    if (e > best) {
        best = e;
        snprintf(what, sizeof(what),
                 "64 bytes of 0x06 after a cut packet of 0x06 values (90 bytes held)");
    }
    report("tase_klv_rx_feed/64", best, what);
    klv_scanner();
}

int main(void)
{
    uint32_t t0;
    measure_start();
    t0 = measure_ticks();
    measure_known_loop(1000000u);
    printf("calibration %lu\n", measure_since(t0));
    receiver();
    timing_codec();
    timing_schema();
    timing_roles();
    can();
    klv_();
    timing_misc();
    timing_port();
    printf("done\n");
    return 0;
}
