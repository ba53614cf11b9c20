/*
 * Receiver benchmark: feeds a synthetic stream through tase_rx_feed() and
 * prints what came out. Run by scripts/bench.sh under callgrind (which
 * counts only the instructions inside tase_rx_feed) and natively for MB/s.
 *
 *   bench_rx STREAM CHUNK MODE [DISPATCH]
 *     STREAM   telemetry  GIMBAL_ANGLE + GIMBAL_RATE at 10 Hz,
 *                         GEOREFERENCE_DATA at 4 Hz
 *              badsize    the same, every other frame's Size byte random
 *              sync4      00 FF 5A FF repeated (every sync claims 253 bytes)
 *              syncrand   00 FF 5A then a random Size, repeated
 *              noise      uniformly random bytes
 *              zeros      0x00 repeated (every byte may start a sync)
 *     CHUNK    bytes per tase_rx_feed() call (1 = byte by byte with tase_rx_push())
 *     MODE     once   feed the stream once (for callgrind)
 *              empty  build the stream, feed nothing (callgrind baseline)
 *              time   feed it repeatedly for ~0.3 s and print MB/s
 *     DISPATCH "dispatch" passes frames through tase_dispatch_frame()
 *              (typed decode + a trivial handler per packet type); only
 *              when built with -DBENCH_DISPATCH (include/tase/dispatch.h).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tase/frame.h"
#include "tase/ids.h"
#ifdef BENCH_DISPATCH
#include "tase/dispatch.h"
#endif

#define STREAM_BYTES (256u * 1024u)

static uint32_t rng = 0x2545F491u;

static uint8_t rnd8(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return (uint8_t)(rng >> 11);
}

static void put16(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

static void put32(uint8_t *p, uint32_t v)
{
    put16(p, v >> 16);
    put16(p + 2, v);
}

/* Appends one frame unless the buffer is nearly full; with `corrupt` set
 * its Size byte is replaced by a random value. Returns 0 when full. */
static int emit(uint8_t *buf, size_t cap, size_t *n, uint16_t id, const uint8_t *d, size_t len,
                int corrupt)
{
    int r;
    if (*n + TASE_FRAME_MAX > cap) {
        return 0;
    }
    r = tase_frame_encode(&buf[*n], cap - *n, TASE_ID_GROUP(id), TASE_ID_TYPE(id), d, len);
    if (corrupt) {
        buf[*n + 3] = rnd8();
    }
    *n += (size_t)r;
    return 1;
}

/* Telemetry as a gimbal sends it, in 50 ms steps; corrupt_size != 0
 * corrupts the Size byte of every other frame. */
static size_t gen_telemetry(uint8_t *buf, size_t cap, int corrupt_size)
{
    size_t n = 0;
    uint32_t t;
    unsigned k = 0, i;
    uint8_t d[63];
    for (t = 0;; t += 50u) {
        if (t % 100u == 0u) {
            put16(&d[0], 4500u + t % 1000u); /* pan, tilt, roll */
            put16(&d[2], (uint32_t)(65536 - 1000));
            put16(&d[4], 0);
            if (!emit(buf, cap, &n, TASE_ID_GIMBAL_ANGLE, d, 6u, corrupt_size && (k++ & 1u))) {
                return n;
            }
            memset(d, 0, 18u);
            put32(&d[0], t);
            for (i = 4; i < 16u; i += 2u) {
                put16(&d[i], (uint32_t)(rnd8() % 64u)); /* small rates */
            }
            d[17] = 0x80u;
            if (!emit(buf, cap, &n, TASE_ID_GIMBAL_RATE, d, 18u, corrupt_size && (k++ & 1u))) {
                return n;
            }
        }
        if (t % 250u == 0u) {
            put32(&d[0], t);
            put32(&d[4], 163000000u + rnd8()); /* lat, lon in mas, then the rest */
            put32(&d[8], (uint32_t)-440000000 + rnd8());
            for (i = 12; i < 63u; i++) {
                d[i] = (uint8_t)((i & 3u) == 0u ? rnd8() : i);
            }
            if (!emit(buf, cap, &n, TASE_ID_GEOREFERENCE_DATA, d, 63u,
                      corrupt_size && (k++ & 1u))) {
                return n;
            }
        }
    }
}

static size_t gen(const char *name, uint8_t *buf, size_t cap)
{
    size_t i;
    if (strcmp(name, "telemetry") == 0) {
        return gen_telemetry(buf, cap, 0);
    }
    if (strcmp(name, "badsize") == 0) {
        return gen_telemetry(buf, cap, 1);
    }
    if (strcmp(name, "sync4") == 0 || strcmp(name, "syncrand") == 0) {
        int r = strcmp(name, "syncrand") == 0;
        for (i = 0; i + 4u <= cap; i += 4u) {
            buf[i] = 0x00;
            buf[i + 1] = 0xFF;
            buf[i + 2] = 0x5A;
            buf[i + 3] = r ? rnd8() : 0xFF;
        }
        return i;
    }
    if (strcmp(name, "noise") == 0) {
        for (i = 0; i < cap; i++) {
            buf[i] = rnd8();
        }
        return cap;
    }
    if (strcmp(name, "zeros") == 0) {
        memset(buf, 0, cap);
        return cap;
    }
    return 0;
}

static unsigned long frames_seen;

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    frames_seen += f->len + 1u;
}

#ifdef BENCH_DISPATCH
static void on_msg(void *user, const tase_frame_t *f, const void *msg)
{
    (void)user;
    (void)msg;
    frames_seen += f->len + 1u;
}
#endif

static void feed_all(tase_rx_t *rx, const uint8_t *s, size_t n, size_t chunk,
                     tase_rx_handler_t h, void *user)
{
    size_t i;
    if (chunk == 1u) { /* byte at a time: the one-byte entry point */
        for (i = 0; i < n; i++) {
            (void)tase_rx_push(rx, s[i], h, user);
        }
        return;
    }
    for (i = 0; i < n; i += chunk) {
        (void)tase_rx_feed(rx, &s[i], (n - i < chunk) ? n - i : chunk, h, user);
    }
    (void)tase_rx_flush(rx, h, user);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv)
{
    static uint8_t stream[STREAM_BYTES];
    static tase_rx_t rx;
    tase_rx_handler_t h = on_frame;
    void *user = NULL;
    size_t n, chunk;
    const char *mode;
#ifdef BENCH_DISPATCH
    static tase_packet_handler_t handlers[TASE_PKT_COUNT];
    static tase_dispatch_t d;
    size_t i;
#endif

    if (argc < 4) {
        fprintf(stderr, "usage: %s STREAM CHUNK once|empty|time [dispatch]\n", argv[0]);
        return 2;
    }
    n = gen(argv[1], stream, sizeof(stream));
    chunk = (size_t)strtoul(argv[2], NULL, 10);
    mode = argv[3];
    if (n == 0u || chunk == 0u) {
        fprintf(stderr, "unknown stream or zero chunk\n");
        return 2;
    }
    tase_rx_init(&rx);
    if (argc > 4 && strcmp(argv[4], "dispatch") == 0) {
#ifdef BENCH_DISPATCH
        for (i = 0; i < TASE_PKT_COUNT; i++) {
            handlers[i] = on_msg;
        }
        tase_dispatch_init(&d, handlers, on_frame, NULL, NULL, &rx.stats);
        h = tase_dispatch_frame;
        user = &d;
#else
        fprintf(stderr, "built without include/tase/dispatch.h\n");
        return 2;
#endif
    }

    if (strcmp(mode, "once") == 0) {
        feed_all(&rx, stream, n, chunk, h, user);
    } else if (strcmp(mode, "time") == 0) {
        double t0 = now_s(), t;
        unsigned long reps = 0;
        do {
            tase_rx_init(&rx);
            feed_all(&rx, stream, n, chunk, h, user);
            reps++;
            t = now_s() - t0;
        } while (t < 0.3);
        printf("mbps=%.1f ", (double)n * (double)reps / t / 1e6);
    } else if (strcmp(mode, "empty") != 0) {
        fprintf(stderr, "unknown mode %s\n", mode);
        return 2;
    }
    printf("bytes=%lu frames=%lu checksum_errors=%lu bad_size=%lu discarded=%lu seen=%lu\n",
           (unsigned long)n, (unsigned long)rx.stats.frames_ok,
           (unsigned long)rx.stats.checksum_errors, (unsigned long)rx.stats.bad_size,
           (unsigned long)rx.stats.bytes_discarded, frames_seen);
    return 0;
}
