/*
 * Receiver benchmark: feeds a synthetic stream through tase_rx_feed() and
 * prints what came out. Run by bench/bench.sh under callgrind (which
 * counts only the instructions inside tase_rx_feed) and natively for MB/s.
 *
 *   bench_rx STREAM CHUNK MODE [DISPATCH]
 *     STREAM   telemetry, badsize, sync4, syncrand, noise, zeros (streams.h)
 *     CHUNK    bytes per tase_rx_feed() call (1 = byte by byte with tase_rx_push())
 *     MODE     once    feed the stream once (for callgrind)
 *              empty   build the stream, feed nothing (callgrind baseline)
 *              time    feed it repeatedly for ~0.3 s and print MB/s
 *              compare in one run, feed the stream to the classic parser
 *                      and the store-and-sum loop of classic_rx.h, to
 *                      tase_rx_push() byte by byte and to tase_rx_feed() in
 *                      CHUNK-byte calls (callgrind's inclusive cost of each
 *                      function / stream bytes: the same program run)
 *     DISPATCH "dispatch" passes frames through tase_dispatch_frame()
 *              (typed decode + a trivial handler per packet type); only
 *              when built with -DBENCH_DISPATCH (include/tase/dispatch.h).
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "classic_rx.h"
#include "streams.h"
#include "tase/frame.h"
#ifdef BENCH_DISPATCH
#include "tase/dispatch.h"
#endif

#define STREAM_BYTES (256u * 1024u)

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

static void feed_all(tase_rx_t *rx, const uint8_t *s, size_t n, size_t chunk, tase_rx_handler_t h,
                     void *user)
{
    size_t i;
    if (chunk == 1u) { /* byte at a time: the one-byte entry point */
        for (i = 0; i < n; i++) {
            (void)tase_rx_push(rx, s[i], h, user);
        }
    } else {
        for (i = 0; i < n; i += chunk) {
            (void)tase_rx_feed(rx, &s[i], (n - i < chunk) ? n - i : chunk, h, user);
        }
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
    size_t n, chunk, i2;
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
    n = bench_stream(argv[1], stream, sizeof(stream));
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

    if (strcmp(mode, "compare") == 0) {
        static classic_rx_t classic;
        static store_sum_t ss;
        classic_rx_init(&classic);
        for (i2 = 0; i2 < n; i2++) {
            (void)classic_rx_push(&classic, stream[i2], h, user);
        }
        for (i2 = 0; i2 < n; i2++) {
            store_sum_push(&ss, stream[i2]);
        }
        feed_all(&rx, stream, n, 1u, h, user);
        printf("classic_frames=%lu push_frames=%lu ", (unsigned long)classic.frames,
               (unsigned long)rx.stats.frames_ok);
        tase_rx_init(&rx);
        feed_all(&rx, stream, n, chunk, h, user);
    } else if (strcmp(mode, "once") == 0) {
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
