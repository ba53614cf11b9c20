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

unsigned long measure_once(measure_fn setup, measure_fn call, void *ctx)
{
    uint32_t t0;
    setup(ctx);
    t0 = measure_ticks();
    call(ctx);
    return measure_since(t0);
}

const char *const all_streams[ALL_STREAMS] = {"telemetry", "badsize", "sync4",   "syncrand",
                                              "noise",     "zeros",   "held255", "burst",
                                              "heldnoise", "halfsum", "synclong"};

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
static uint8_t camera_mem[TASE_CAMERA_PASS_MAX + 4u] __attribute__((aligned(4)));
const uint8_t *camera_bytes = camera_mem;
size_t camera_off;

void set_camera_off(size_t off)
{
    camera_off = off;
    camera_bytes = &camera_mem[off];
}

size_t fill_full_msg(const tase_packet_desc_t *p)
{
    memset(&full_msg, 0xA5, sizeof(full_msg));
    if ((p->flags & TASE_LEN_TAIL) != 0u) {
        memset(camera_mem, 0x5A, sizeof(camera_mem));
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

/* What tase_checksum() and tase_frame_build() read and write, at each
 * address 0..3 mod 4 (the sum's word loop and the C library's copies take
 * other paths at other alignments). */
static uint8_t in_mem[TASE_FRAME_MAX + 4u] __attribute__((aligned(4)));
static uint8_t out_mem[TASE_FRAME_MAX + 4u] __attribute__((aligned(4)));
static uint8_t *out_at = out_mem;

NOINLINE static void c_checksum(void *ctx)
{
    (void)ctx;
    sink += tase_checksum(0u, arg_p, arg_n);
}

MEASURED(c_encode, tase_frame_build(0x08u, 0x10u, arg_p, arg_n, out_at, TASE_FRAME_MAX))

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
    worst_t wc = {0, ""}, wb = {0, ""};
    size_t in, o, n;

    /* the sum of each length of the last 16 up to a whole frame's (every
     * tail its word loop leaves), the frame of each of the last 5 data
     * lengths, each at every address mod 4 */
    memset(in_mem, 0xA5, sizeof(in_mem));
    for (in = 0; in < 4u; in++) {
        arg_p = &in_mem[in];
        for (n = TASE_FRAME_MAX - 15u; n <= TASE_FRAME_MAX; n++) {
            arg_n = n;
            worst_try(&wc, measure_exact(nothing, c_checksum, NULL),
                      "%lu bytes at an address %lu mod 4", (unsigned long)n, (unsigned long)in);
        }
        for (o = 0; o < 4u; o++) {
            out_at = &out_mem[o];
            for (n = TASE_DATA_MAX - 4u; n <= TASE_DATA_MAX; n++) {
                arg_n = n;
                worst_try(&wb, measure_exact(nothing, c_encode, NULL),
                          "%lu data bytes at an address %lu mod 4, the frame written at %lu mod 4",
                          (unsigned long)n, (unsigned long)in, (unsigned long)o);
            }
        }
    }
    worst_report("tase_checksum", &wc, " (the slowest of 246..261 bytes, a whole frame's at most)");
    worst_report("tase_frame_build", &wb, " (the slowest of 249..253)");
    memset(data, 0xA5, sizeof(data));
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

#define CAN_SEARCH 3072u /* bytes of each stream split into CAN frames */
#define CAN_SHIFTS 8u    /* ... from each of its first 8 bytes on */
#define CAN_FRAMES (CAN_SEARCH / 8u)

static tase_can_split_t split, split_snap;
static tase_can_rx_t crx, crx_snap;
static tase_can_frame_t cf;
/* A frame at each address 0..7 mod 8 (the copies are by the byte). */
static uint8_t split_mem[TASE_FRAME_MAX + 8u] __attribute__((aligned(8)));
static unsigned long can_coarse[ALL_STREAMS][CAN_SHIFTS][CAN_FRAMES];

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

MEASURED(c_split_next, tase_can_split_next(&split, &cf))
MEASURED(c_can_rx_feed, tase_can_rx_feed(&crx, &cf, on_frame, NULL))

/* Every call of a split of a 261-byte frame (the 33 frames and the call
 * that ends it), the frame at each address 0..7 mod 8. */
static void can_split_next(void)
{
    worst_t w = {0, ""};
    size_t off, k;
    for (off = 0; off < 8u; off++) {
        int n =
            tase_frame_build(0x08u, 0x10u, data, TASE_DATA_MAX, &split_mem[off], TASE_FRAME_MAX);
        (void)tase_can_split_init(&split_snap, TASE_CAN_ROLE_GIMBAL, &split_mem[off], (size_t)n);
        for (k = 0;; k++) {
            tase_can_split_t next = split_snap;
            int r = tase_can_split_next(&next, &cf);
            worst_try(&w, measure_exact(restore_split, c_split_next, NULL),
                      "CAN frame %lu (%d bytes) of a 261-byte frame at an address %lu mod 8",
                      (unsigned long)k, r, (unsigned long)off);
            if (r <= 0) {
                break;
            }
            split_snap = next;
        }
    }
    worst_report("tase_can_split_next", &w, "");
}

/* Every stream of PERFORMANCE.md split into the CAN frames the gimbal
 * sends, from each of its first 8 bytes on (CAN_SEARCH bytes), each frame
 * fed to a host's reassembler in the state the frames before it left:
 * coarse on all, exact on those within a tick of the longest. */
static void can_rx_search(void)
{
    worst_t w = {0, ""};
    unsigned long top = 0;
    size_t s, sh, i, pass;
    for (pass = 0; pass < 2u; pass++) {
        for (s = 0; s < ALL_STREAMS; s++) {
            (void)bench_stream(all_streams[s], stream, sizeof(stream));
            for (sh = 0; sh < CAN_SHIFTS; sh++) {
                tase_can_split_t sp;
                (void)tase_can_rx_init(&crx_snap, TASE_CAN_ROLE_HOST);
                (void)tase_can_split_init(&sp, TASE_CAN_ROLE_GIMBAL, &stream[sh], CAN_SEARCH);
                for (i = 0; i < CAN_FRAMES && tase_can_split_next(&sp, &cf) > 0; i++) {
                    unsigned long *c = &can_coarse[s][sh][i];
                    if (pass == 0u) {
                        *c = measure_once(restore_crx, c_can_rx_feed, NULL);
                        top = *c > top ? *c : top;
                    } else if (*c + MEASURE_TICK_INSNS >= top) {
                        worst_try(&w, measure_exact(restore_crx, c_can_rx_feed, NULL),
                                  "CAN frame %lu of %s split from its byte %lu", (unsigned long)i,
                                  all_streams[s], (unsigned long)sh);
                    }
                    (void)tase_can_rx_feed(&crx_snap, &cf, NULL, NULL);
                }
            }
        }
    }
    worst_report("tase_can_rx_feed", &w,
                 " (the worst of every stream's first 3072 bytes split from each of bytes 0..7, "
                 "each frame after those before it)");
}

static void can(void)
{
    can_split_next();
    can_rx_search();
}

/* ---- KLV --------------------------------------------------------------- */

static tase_klv_t klv;
static tase_klv_rx_t krx_snap;
/* The scanner at an address 0 or 4 mod 8 (the library's memchr() reads
 * its window by aligned words): krx points at one of them. */
static struct {
    tase_klv_rx_t r;
} krx_at0 __attribute__((aligned(8)));
static struct {
    uint32_t pad;
    tase_klv_rx_t r;
} krx_at4 __attribute__((aligned(8)));
static tase_klv_rx_t *const krx_at[2] = {&krx_at0.r, &krx_at4.r};
static tase_klv_rx_t *krx = &krx_at0.r;
static uint8_t kbuf[TASE_KLV_PACKET_MAX];
static size_t klen;
/* A packet at each address 0..3 mod 4. */
static uint8_t kmem[TASE_KLV_PACKET_MAX + 4u] __attribute__((aligned(4)));
static uint8_t *kat = kmem;

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
    *krx = krx_snap;
}

/* krx's address mod 8 */
static unsigned long krx_mod8(void)
{
    return (unsigned long)((uintptr_t)krx & 7u);
}

MEASURED(c_klv_encode, tase_klv_encode(&klv, kat, TASE_KLV_PACKET_MAX))
MEASURED(c_klv_decode, tase_klv_decode(kat, klen, &klv))
MEASURED(c_klv_rx_feed, tase_klv_rx_feed(krx, arg_p, arg_n, on_klv, on_klv_error, NULL))
MEASURED(c_klv_rx_init, tase_klv_rx_init(krx))
MEASURED(c_klv_stats_reset, tase_klv_rx_stats_reset(krx))
MEASURED(c_klv_flush, tase_klv_rx_flush(krx, on_klv, on_klv_error, NULL))

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
 * most, the scanner at each placement. */
static void klv_scanner(void)
{
    static uint8_t buf[TASE_KLV_PACKET_MAX + 8u];
    static const int fills[] = {0x06, -1, 0x00};
    static const char *const names[] = {"every value byte 0x06 (a false key start each)",
                                        "values spelling the key's first bytes",
                                        "every value byte 0x00"};
    worst_t w = {0, ""};
    size_t k, at;
    report("tase_klv_rx_init", measure_plain(c_klv_rx_init), "any state");
    report("tase_klv_rx_stats_reset", measure_plain(c_klv_stats_reset), "any state");
    for (k = 0; k < COUNT(fills); k++) {
        size_t n = klv_cut_packet(buf, fills[k]);
        (void)tase_klv_rx_init(&krx_snap);
        (void)tase_klv_rx_feed(&krx_snap, buf, n, NULL, NULL, NULL);
        for (at = 0; at < COUNT(krx_at); at++) {
            krx = krx_at[at];
            worst_try(&w, measure_exact(restore_krx, c_klv_flush, NULL),
                      "%u bytes held: a packet with a 4-octet BER length cut 1 byte short, %s, "
                      "the scanner at an address %lu mod 8",
                      (unsigned)krx_snap.len, names[k], krx_mod8());
        }
    }
    worst_report("tase_klv_rx_flush", &w, "");
}

/* The encoder on structs whose every member byte is 0x00, 0xFF or 0x80,
 * writing at each address 0..3 mod 4; the decoder on the packets it
 * makes, their BER length as written (short form) or in the long form
 * of 1 or 4 octets (0x81 0x46, 0x84 00 00 00 0x46: up to 91 bytes), at
 * each address 0..3 mod 4. */
static void klv_codec(void)
{
    static const uint8_t fills[] = {0x00, 0xFF, 0x80};
    static const char *const forms[] = {"short", "1-octet long", "4-octet long"};
    static uint8_t one[TASE_KLV_PACKET_MAX];
    worst_t we = {0, ""}, wd = {0, ""};
    size_t f, form, off;
    for (f = 0; f < COUNT(fills); f++) {
        int n;
        memset(&klv, fills[f], sizeof(klv));
        for (off = 0; off < 4u; off++) {
            kat = &kmem[off];
            worst_try(&we, measure_plain(c_klv_encode),
                      "a full packet, every member byte 0x%02X, written at an address %lu mod 4",
                      (unsigned)fills[f], (unsigned long)off);
        }
        n = tase_klv_encode(&klv, one, sizeof(one));
        for (form = 0; n > 0 && form < COUNT(forms); form++) {
            size_t extra = form == 0u ? 0u : form == 1u ? 1u : 4u; /* octets after 0x8n */
            for (off = 0; off < 4u; off++) {
                kat = &kmem[off];
                memcpy(kat, one, TASE_KLV_KEY_LEN);
                if (extra > 0u) {
                    kat[TASE_KLV_KEY_LEN] = (uint8_t)(0x80u | extra);
                    memset(&kat[TASE_KLV_KEY_LEN + 1u], 0, extra - 1u);
                }
                memcpy(&kat[TASE_KLV_KEY_LEN + extra], &one[TASE_KLV_KEY_LEN],
                       (size_t)n - TASE_KLV_KEY_LEN);
                klen = (size_t)n + extra;
                if (tase_klv_decode(kat, klen, &klv) != (int)klen) {
                    continue; /* valid packets only */
                }
                worst_try(&wd, measure_plain(c_klv_decode),
                          "a valid packet, every member byte 0x%02X, its BER length in the %s "
                          "form (%lu bytes), at an address %lu mod 4",
                          (unsigned)fills[f], forms[form], (unsigned long)klen, (unsigned long)off);
            }
        }
    }
    worst_report("tase_klv_encode", &we, "");
    worst_report("tase_klv_decode", &wd, "");
}

static void klv_(void)
{
    static uint8_t held[TASE_KLV_PACKET_MAX + 8u];
    static uint8_t sixes[64 + 8u] __attribute__((aligned(8)));
    worst_t w = {0, ""};
    size_t i, at, off;
    int n;
    klv_codec();
    memset(&klv, 0, sizeof(klv));
    n = tase_klv_encode(&klv, kbuf, sizeof(kbuf));
    klen = n > 0 ? (size_t)n : 0u;
    /* 64-byte feeds over packets, each with one byte corrupted, back to back */
    for (i = 0; i + klen <= sizeof(stream); i += klen) {
        memcpy(&stream[i], kbuf, klen);
        stream[i + (i / klen) % klen] ^= 0x01u;
    }
    for (at = 0; at < COUNT(krx_at); at++) {
        krx = krx_at[at];
        (void)tase_klv_rx_init(&krx_snap);
        for (i = 0; i + 64u <= 4096u; i += 64u) {
            arg_p = &stream[i];
            arg_n = 64u;
            worst_try(&w, measure_exact(restore_krx, c_klv_rx_feed, NULL),
                      "64 bytes at %lu of corrupted packets, the scanner at an address %lu mod 8",
                      (unsigned long)i, krx_mod8());
            (void)tase_klv_rx_feed(&krx_snap, arg_p, 64u, NULL, NULL, NULL);
        }
    }
    /* A review's input: the 90-byte cut packet held (every value 0x06),
     * then 64 bytes of 0x06, each a false key start (the scanner moved its
     * window down for each: 41,850 instructions on Cortex-M4 -O2); the
     * bytes at each address 0..7 mod 8. */
    (void)tase_klv_rx_init(&krx_snap);
    (void)tase_klv_rx_feed(&krx_snap, held, klv_cut_packet(held, 0x06), NULL, NULL, NULL);
    memset(sixes, 0x06, sizeof(sixes));
    arg_n = 64u;
    for (at = 0; at < COUNT(krx_at); at++) {
        krx = krx_at[at];
        for (off = 0; off < 8u; off++) {
            arg_p = &sixes[off];
            worst_try(&w, measure_exact(restore_krx, c_klv_rx_feed, NULL),
                      "64 bytes of 0x06 (at an address %lu mod 8) after a cut packet of 0x06 "
                      "values (90 bytes held), the scanner at an address %lu mod 8",
                      (unsigned long)off, krx_mod8());
        }
    }
    worst_report("tase_klv_rx_feed/64", &w, "");
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
