/*
 * The checksum and the receiver on the target's own code paths: built for
 * a Cortex-M CPU and run under QEMU (scripts/checks/cm-frame.sh). On the
 * host only the x86 paths run; on Cortex-M4/M7 tase_checksum() adds words
 * with USADA8 and on Cortex-M0+ it adds bytes (src/tase_frame.c), and the
 * window's compaction moves words or bytes the same way. This program
 * checks both against a byte loop written here, at every alignment 0..7
 * and every length that keeps the end within 600 bytes, with 4 seeds, and feeds a stream of
 * frames with noise between them through tase_rx_feed() in chunks of
 * every size 1..64 and through tase_rx_push(), expecting every frame.
 * Exit status 0 when everything holds, 1 with a message otherwise.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "tase/frame.h"

static uint8_t bytes[640];
static uint8_t stream[8192];
static size_t stream_n;
static unsigned frames_want;
static unsigned failures;

static uint32_t lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static uint16_t sum_bytes(uint16_t seed, const uint8_t *p, size_t n)
{
    uint16_t s = seed;
    size_t i;
    for (i = 0; i < n; i++) {
        s = (uint16_t)(s + p[i]);
    }
    return s;
}

static void check(int ok, const char *what, unsigned a, unsigned b)
{
    if (!ok) {
        failures++;
        if (failures <= 10u) {
            printf("FAIL %s (%u, %u)\n", what, a, b);
        }
    }
}

static unsigned checked; /* (alignment, length) pairs */

static void checksums(void)
{
    static const uint16_t seeds[] = {0u, 1u, 0x7FFFu, 0xFFFFu};
    uint32_t r = 12345u;
    size_t i;
    unsigned off;
    unsigned len;
    unsigned k;
    for (i = 0; i < sizeof bytes; i++) {
        bytes[i] = (uint8_t)lcg(&r);
    }
    bytes[100] = 0xFFu; /* runs of 0xFF: the largest lanes */
    (void)memset(&bytes[200], 0xFF, 300);
    for (off = 0; off < 8u; off++) {
        for (len = 0; len + off <= 600u; len++) {
            checked++;
            for (k = 0; k < sizeof seeds / sizeof seeds[0]; k++) {
                uint16_t want = sum_bytes(seeds[k], &bytes[off], len);
                uint16_t got = tase_checksum(seeds[k], &bytes[off], len);
                check(want == got, "tase_checksum", off, len);
            }
        }
    }
    check(tase_checksum(7u, NULL, 5u) == 7u, "tase_checksum NULL", 0u, 0u);
}

static void on_frame(void *user, const tase_frame_t *f)
{
    unsigned *n = user;
    /* every frame carries its index in its first two data bytes */
    check(f->len >= 2u && (unsigned)((f->data[0] << 8) | f->data[1]) == *n, "frame order", *n,
          f->len);
    (*n)++;
}

static void build_stream(void)
{
    uint32_t r = 777u;
    uint8_t data[TASE_DATA_MAX];
    stream_n = 0;
    frames_want = 0;
    for (;;) {
        size_t len = 2u + lcg(&r) % 252u;
        size_t noise = lcg(&r) % 9u;
        size_t i;
        int n;
        if (stream_n + noise + len + TASE_FRAME_OVERHEAD > sizeof stream) {
            break;
        }
        for (i = 0; i < noise; i++) {
            stream[stream_n++] = (uint8_t)(0x5Au + i); /* never 00 */
        }
        for (i = 0; i < len; i++) {
            data[i] = (uint8_t)lcg(&r);
        }
        data[0] = (uint8_t)(frames_want >> 8);
        data[1] = (uint8_t)frames_want;
        n = tase_frame_build(0x08u, 0x10u, data, len, &stream[stream_n], sizeof stream - stream_n);
        check(n > 0, "tase_frame_build", (unsigned)len, 0u);
        stream_n += (size_t)n;
        frames_want++;
    }
}

static void receive(void)
{
    static tase_rx_t rx;
    size_t chunk;
    size_t i;
    unsigned got;
    for (chunk = 1; chunk <= 64u; chunk++) {
        got = 0;
        tase_rx_init(&rx);
        for (i = 0; i < stream_n; i += chunk) {
            size_t n = stream_n - i < chunk ? stream_n - i : chunk;
            (void)tase_rx_feed(&rx, &stream[i], n, on_frame, &got);
        }
        (void)tase_rx_flush(&rx, on_frame, &got);
        check(got == frames_want && rx.stats.frames_ok == frames_want &&
                  rx.stats.checksum_errors == 0u,
              "tase_rx_feed frames", (unsigned)chunk, got);
    }
    got = 0;
    tase_rx_init(&rx);
    for (i = 0; i < stream_n; i++) {
        (void)tase_rx_push(&rx, stream[i], on_frame, &got);
    }
    (void)tase_rx_flush(&rx, on_frame, &got);
    check(got == frames_want, "tase_rx_push frames", got, frames_want);
}

int main(void)
{
    checksums();
    build_stream();
    receive();
    if (failures != 0u) {
        printf("frame_on_target: %u failures\n", failures);
        return 1;
    }
    printf("frame_on_target: checksum at %u (alignment, length) pairs x 4 seeds, %u frames in %u "
           "bytes fed 65 ways: ok\n",
           checked, frames_want, (unsigned)stream_n);
    return 0;
}
