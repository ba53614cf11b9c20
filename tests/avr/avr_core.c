/*
 * The core on an 8-bit AVR, where int and size_t are 16 bits wide: run
 * under simavr (ATmega2560) by scripts/checks/avr.sh, which reads the
 * UART output. Two parts:
 *
 *  1. every packet of the schema, with extreme and pseudo-random field
 *     values: data bytes -> frame -> typed struct (every member equal to
 *     the big-endian field read back with tase_field_get()) -> frame
 *     again, byte-identical;
 *  2. the receiver on a noisy stream: pseudo-random noise, valid frames of
 *     every packet, frames with a broken checksum and frames whose Size
 *     byte was corrupted upwards, fed to one receiver in pseudo-random
 *     chunks and to another one byte at a time: both must deliver exactly
 *     the valid frames, in stream order, and end with identical counters;
 *  3. counts that must fit an int: tase_port_write_all() of more bytes
 *     than INT_MAX (32767 here) is refused, never "sent" with a negative
 *     result that reads as an error code.
 *
 * Prints one line per part and finally "AVR RESULT: PASS" or
 * "AVR RESULT: FAIL"; then sleeps with interrupts off, which ends the
 * simulation. Also builds on a host (stdout instead of the UART) for
 * debugging.
 */
#include <string.h>

#include <limits.h>

#include "tase/codec.h"
#include "tase/frame.h"
#include "tase/ids.h"
#include "tase/port_io.h"
#include "tase/schema.h"

#include "../packet_fill.h"

#ifdef __AVR__
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>

static void out_char(char c)
{
    while ((UCSR0A & (1u << UDRE0)) == 0u) {
    }
    UDR0 = (uint8_t)c;
}
static void out_init(void)
{
    UCSR0B = (uint8_t)(1u << TXEN0);
}
static void out_end(void)
{
    cli();
    sleep_mode(); /* simavr: sleeping with interrupts off ends the run */
}
#else
#include <stdio.h>
static void out_char(char c)
{
    (void)putchar(c);
}
static void out_init(void)
{
}
static void out_end(void)
{
}
#endif

static void out_str(const char *s)
{
    while (*s != '\0') {
        out_char(*s++);
    }
}

static void out_u32(uint32_t v)
{
    char buf[11];
    int i = 0;
    do {
        buf[i++] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (i > 0) {
        out_char(buf[--i]);
    }
}

static uint32_t failures;

static void check(bool ok, const char *what, uint32_t detail)
{
    if (!ok) {
        failures++;
        if (failures <= 10u) {
            out_str("FAIL ");
            out_str(what);
            out_str(" ");
            out_u32(detail);
            out_str("\n");
        }
    }
}

/* Deterministic pseudo-random numbers (a 32-bit LCG; high bits used). */
static uint32_t lcg_state = 12345u;
static uint8_t rnd8(void)
{
    lcg_state = lcg_state * 1664525u + 1013904223u;
    return (uint8_t)(lcg_state >> 24);
}
static uint16_t rnd16(void)
{
    return (uint16_t)(((uint16_t)rnd8() << 8) | rnd8());
}

/* ---- 1. every packet ------------------------------------------------ */

static tase_frame_t frame_view(const uint8_t *wire, int n)
{
    tase_frame_t f;
    f.offset = 0;
    f.group = wire[4];
    f.type = wire[5];
    f.len = (uint8_t)(n - 8);
    f.data = wire + TASE_FRAME_HEADER;
    return f;
}

static uint32_t every_packet(void)
{
    uint32_t done = 0;
    size_t i, k;
    int mode, rep;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (mode = 0; mode < 5; mode++) {
            for (rep = 0; rep < (mode == 4 ? 20 : 1); rep++) {
                static uint8_t data[TASE_DATA_MAX];
                static uint8_t wire[TASE_FRAME_MAX];
                static uint8_t again[TASE_FRAME_MAX];
                static tase_packet_msg_t m1, m2;
                tase_frame_t f;
                size_t len = p->len;
                int n, r;
                packet_fill_fields(p, data, mode, rnd8);
                if ((p->flags & TASE_LEN_TAIL) != 0u) {
                    size_t extra = rnd8() % (TASE_CAMERA_PASS_MAX + 1u);
                    for (k = 0; k < extra; k++) {
                        data[len + k] = rnd8();
                    }
                    len += extra;
                }
                n = tase_frame_build(TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len, wire,
                                     sizeof wire);
                check(n == (int)len + 8, "frame_encode", (uint32_t)i);
                f = frame_view(wire, n);
                memset(&m1, 0x55, sizeof m1);
                r = tase_packet_decode(&f, p->size != 0u ? &m1 : NULL);
                check(r == (int)len, "decode", (uint32_t)i);
                for (k = 0; k < p->nfields; k++) {
                    const tase_field_t *fd = tase_schema_field(p, k);
                    unsigned w = TASE_FIELD_WIDTH(fd);
                    int64_t raw = 0;
                    uint64_t want;
                    check(tase_field_get(p, k, f.data, f.len, &raw) == TASE_OK, "field_get",
                          (uint32_t)i);
                    want = w == 8u ? (uint64_t)raw : ((uint64_t)raw & ((1ull << (8u * w)) - 1u));
                    check(packet_member_bits((const uint8_t *)&m1 + fd->member, w) == want,
                          "member", (uint32_t)(i * 100u + k));
                }
                n = tase_packet_encode(p->id, p->size != 0u ? &m1 : NULL, again, sizeof again);
                check(n == (int)len + 8 && memcmp(again, wire, (size_t)n) == 0, "re-encode",
                      (uint32_t)i);
                f = frame_view(again, n);
                memset(&m2, 0x33, sizeof m2);
                r = tase_packet_decode(&f, p->size != 0u ? &m2 : NULL);
                if ((p->flags & TASE_LEN_TAIL) != 0u) {
                    m2.camera_pass.data = m1.camera_pass.data; /* points into the other frame */
                }
                check(r == (int)len && memcmp(&m1, &m2, p->size) == 0, "decode again", (uint32_t)i);
                done++;
            }
        }
    }
    return done;
}

/* ---- 2. the receiver on a noisy stream ------------------------------- */

/* What a delivered frame must be: the valid frames put into the stream,
 * in order, identified by group, type, length and the sum of their data. */
typedef struct {
    uint8_t group, type, len;
    uint16_t sum;
} want_t;

#define WANT_MAX 32u
static want_t wants[WANT_MAX];
static uint16_t want_put; /* frames put into the stream (mod 2^16) */

typedef struct {
    uint16_t next; /* index of the next expected frame */
    uint32_t got;
} seen_t;

static void on_frame(void *user, const tase_frame_t *f)
{
    seen_t *s = (seen_t *)user;
    const want_t *w = &wants[s->next % WANT_MAX];
    uint16_t sum = tase_checksum(0, f->data, f->len);
    check(s->next != want_put, "unexpected frame", s->got);
    check(f->group == w->group && f->type == w->type && f->len == w->len && sum == w->sum,
          "frame differs", s->got);
    s->next++;
    s->got++;
}

static tase_rx_t rx_chunks, rx_bytes;
static seen_t seen_chunks, seen_bytes;
static uint32_t stream_len;

/* Feed n bytes to both receivers: to one in pseudo-random chunks, to the
 * other byte by byte. */
static void feed(const uint8_t *b, size_t n)
{
    size_t at = 0, i;
    while (at < n) {
        size_t c = (size_t)(rnd8() % 64u) + 1u;
        if (c > n - at) {
            c = n - at;
        }
        check(tase_rx_feed(&rx_chunks, b + at, c, on_frame, &seen_chunks) >= 0, "feed",
              (uint32_t)at);
        at += c;
    }
    for (i = 0; i < n; i++) {
        check(tase_rx_push(&rx_bytes, b[i], on_frame, &seen_bytes) >= 0, "push", (uint32_t)i);
    }
    stream_len += (uint32_t)n;
}

static uint32_t noisy_stream(void)
{
    static uint8_t item[TASE_FRAME_MAX];
    uint32_t valid = 0;
    int round;
    check(tase_rx_init(&rx_chunks) == TASE_OK && tase_rx_init(&rx_bytes) == TASE_OK, "rx_init", 0);
    for (round = 0; round < 400; round++) {
        uint8_t kind = (uint8_t)(rnd8() % 8u);
        if (kind < 3u) { /* noise without 0x00, so no sync starts in it */
            size_t n = (size_t)(rnd8() % 40u) + 1u, i;
            for (i = 0; i < n; i++) {
                item[i] = (uint8_t)(rnd8() | 1u);
            }
            feed(item, n);
        } else {
            const tase_packet_desc_t *p = tase_schema_at(rnd16() % TASE_PKT_COUNT);
            size_t len = p->len, i;
            int n;
            for (i = 0; i < len; i++) {
                item[TASE_FRAME_HEADER + i] = rnd8();
            }
            n = tase_frame_build(TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id),
                                 item + TASE_FRAME_HEADER, len, item, sizeof item);
            check(n == (int)len + 8, "stream encode", (uint32_t)round);
            if (kind == 6u) {
                item[n - 1] ^= (uint8_t)(rnd8() | 1u); /* broken checksum */
            } else if (kind == 7u && item[3] < 255u) {
                item[3] = (uint8_t)(item[3] + 1u + rnd8() % (255u - item[3])); /* Size up */
            } else {
                want_t *w = &wants[want_put % WANT_MAX];
                w->group = item[4];
                w->type = item[5];
                w->len = (uint8_t)len;
                w->sum = tase_checksum(0, item + TASE_FRAME_HEADER, len);
                want_put++;
                valid++;
            }
            feed(item, (size_t)n);
        }
        /* Frames may be held back (inside a candidate not yet settled) by
         * at most one frame's length; never let the table wrap over them. */
        check((uint16_t)(want_put - seen_chunks.next) < WANT_MAX &&
                  (uint16_t)(want_put - seen_bytes.next) < WANT_MAX,
              "too many frames pending", (uint32_t)round);
    }
    check(tase_rx_flush(&rx_chunks, on_frame, &seen_chunks) >= 0, "flush", 0);
    check(tase_rx_flush(&rx_bytes, on_frame, &seen_bytes) >= 0, "flush", 1);
    check(seen_chunks.got == valid && seen_bytes.got == valid, "frames delivered", seen_chunks.got);
    check(rx_chunks.stats.frames_ok == valid && rx_chunks.stats.bytes_in == stream_len, "counters",
          rx_chunks.stats.frames_ok);
    check(memcmp(&rx_chunks.stats, &rx_bytes.stats, sizeof rx_chunks.stats) == 0,
          "chunked and byte-at-a-time counters differ", rx_bytes.stats.frames_ok);
    return valid;
}

/* ---- 3. counts wider than int ---------------------------------------- */

static uint32_t sink_bytes;
static int sink_write(void *ctx, const uint8_t *data, size_t n)
{
    (void)ctx;
    (void)data; /* never read: the test passes a length, not a buffer */
    n = n > 1000u ? 1000u : n;
    sink_bytes += (uint32_t)n;
    return (int)n;
}
static int sink_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    (void)ctx;
    (void)buf;
    (void)cap;
    (void)timeout_ms;
    return 0;
}
static uint32_t sink_now(void *ctx)
{
    (void)ctx;
    return 0;
}

static void int_width(void)
{
    static const tase_port_ops_t ops = {sink_write, sink_read, sink_now};
    static const uint8_t one = 0;
    tase_port_t port;
    int r;
    port.ops = &ops;
    port.ctx = NULL;
    port.bytes_per_s = 0u;
    r = tase_port_write_all(&port, &one, 1);
    check(r == 1, "write_all 1 byte", (uint32_t)r);
    if ((size_t)INT_MAX < (size_t)-1) { /* a count that does not fit the result */
        sink_bytes = 0;
        r = tase_port_write_all(&port, &one, (size_t)INT_MAX + 1u);
        check(r == TASE_EARG && sink_bytes == 0u, "write_all of more than INT_MAX bytes",
              (uint32_t)(int32_t)r);
    }
    out_str("int width: tase_port_write_all() beyond INT_MAX checked\n");
}

int main(void)
{
    uint32_t n;
    out_init();
    out_str("tase ");
    out_str(TASE_VERSION_STRING);
    out_str(", int is ");
    out_u32((uint32_t)(sizeof(int) * 8u));
    out_str(" bits, sizeof(tase_rx_t) ");
    out_u32((uint32_t)sizeof(tase_rx_t));
    out_str("\n");
    n = every_packet();
    out_str("packets: ");
    out_u32(n);
    out_str(" round trips of the ");
    out_u32((uint32_t)TASE_PKT_COUNT);
    out_str(" packets\n");
    n = noisy_stream();
    out_str("receiver: ");
    out_u32(n);
    out_str(" valid frames in ");
    out_u32(stream_len);
    out_str(" noisy bytes, ");
    out_u32(rx_chunks.stats.checksum_errors);
    out_str(" checksum errors, ");
    out_u32(rx_chunks.stats.bytes_discarded);
    out_str(" bytes discarded\n");
    int_width();
    out_str(failures == 0u ? "AVR RESULT: PASS\n" : "AVR RESULT: FAIL\n");
    out_end();
    return failures == 0u ? 0 : 1;
}
