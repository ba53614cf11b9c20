/* The benchmark's synthetic streams: see streams.h. */
#include "streams.h"

#include <string.h>

#include "tase/frame.h"
#include "tase/ids.h"

/* The generator: bench_stream() starts it over from RNG_SEED for every
 * stream, so a stream's bytes depend on its name and length only, not on
 * which streams a program generated before (until 2026-11-27 they did:
 * bench_cm.c's syncrand, synclong, noise and badsize were not the bytes
 * bench_rx.c or search.c got for the same names). */
#define RNG_SEED 0x2545F491u
static uint32_t rng = RNG_SEED;

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
    r = tase_frame_build(TASE_ID_GROUP(id), TASE_ID_TYPE(id), d, len, &buf[*n], cap - *n);
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

/* 00 FF 5A and a Size byte at buf[n] (a sync; a candidate claiming
 * size - 2 data bytes). Returns n + 4. */
static size_t put_sync(uint8_t *buf, size_t n, uint8_t size)
{
    buf[n] = 0x00;
    buf[n + 1u] = 0xFF;
    buf[n + 2u] = 0x5A;
    buf[n + 3u] = size;
    return n + 4u;
}

/* 00 FF 5A FF (a false sync claiming 253 data bytes), then 63 groups
 * 00 FF 5A (255 - 4k), k = 1..63: every group is a complete false
 * candidate ending where the first one ends, so all 64 are decided by the
 * same byte (issue 21's longest call). Repeated. */
static size_t gen_held255(uint8_t *buf, size_t cap)
{
    size_t n = 0, k;
    while (n + 256u <= cap) {
        for (k = 0; k < 64u; k++) {
            n = put_sync(buf, n, (uint8_t)(255u - 4u * k));
        }
    }
    return n;
}

/* 60 noise bytes, 00 FF 5A FF, then 64 syncs 4 bytes apart whose Size
 * bytes make each candidate end about half-way through what is left of a
 * window of `reach` bytes (Size = (reach - 4k) / 2 - 4, within 2..255):
 * when the first candidate fails on the next period's first byte, every
 * inner candidate is complete and each is summed over a long stretch
 * (held255's all end at the same byte, a 3-byte sum each). Found by a
 * review that beat the documented longest calls with it (2026-11-26;
 * reach 270 gave its longest 16-byte feed, 290 its longest 64-byte feed
 * with the receiver's charges of then). The periods go through reach
 * 262, 266, ..., 330 (18 of them, within the 8 KiB whose calls the bench
 * times one by one), so that the worst reach is met whatever the
 * receiver's charges are. Each period is 320 bytes, so the failing byte
 * starts a 16- and a 64-byte call. */
static size_t gen_halfsum(uint8_t *buf, size_t cap)
{
    size_t n = 0, h = 0, i;
    unsigned k;
    while (n + 320u <= cap) {
        unsigned w = 262u + 4u * (unsigned)(h++ % 18u);
        for (i = 0; i < 60u; i++) {
            buf[n++] = 0x11;
        }
        n = put_sync(buf, n, 0xFF);
        for (k = 1; k <= 64u; k++) {
            unsigned s = w > 4u * k + 12u ? (w - 4u * k) / 2u - 4u : 2u;
            n = put_sync(buf, n, (uint8_t)(s > 255u ? 255u : s));
        }
    }
    return n;
}

/* 00 FF 5A FF, then 31 valid empty frames (8 bytes each) and 9 bytes of
 * noise: the false candidate fails on its 261st byte and releases the 31
 * frames it was hiding, all decided by that byte. Repeated. */
static size_t gen_burst(uint8_t *buf, size_t cap)
{
    size_t n = 0, k;
    while (n + 261u <= cap) {
        n = put_sync(buf, n, 0xFF);
        for (k = 0; k < 31u; k++) {
            n += (size_t)tase_frame_build(0x00, (uint8_t)k, NULL, 0u, &buf[n], cap - n);
        }
        for (k = 0; k < 9u; k++) {
            buf[n++] = (uint8_t)(0x11u + k);
        }
    }
    return n;
}

/* 00 FF 5A FF, then 257 noise bytes without a 00: the false candidate
 * fails on its 261st byte and the scan walks the 257 noise bytes it was
 * holding. Repeated. */
static size_t gen_heldnoise(uint8_t *buf, size_t cap)
{
    size_t n = 0, k;
    while (n + 261u <= cap) {
        n = put_sync(buf, n, 0xFF);
        for (k = 0; k < 257u; k++) {
            buf[n++] = (uint8_t)(0x11u + k % 0xEEu);
        }
    }
    return n;
}

size_t bench_stream(const char *name, uint8_t *buf, size_t cap)
{
    size_t i;
    rng = RNG_SEED;
    if (strcmp(name, "held255") == 0) {
        return gen_held255(buf, cap);
    }
    if (strcmp(name, "burst") == 0) {
        return gen_burst(buf, cap);
    }
    if (strcmp(name, "halfsum") == 0) {
        return gen_halfsum(buf, cap);
    }
    if (strcmp(name, "heldnoise") == 0) {
        return gen_heldnoise(buf, cap);
    }
    if (strcmp(name, "telemetry") == 0) {
        return gen_telemetry(buf, cap, 0);
    }
    if (strcmp(name, "badsize") == 0) {
        return gen_telemetry(buf, cap, 1);
    }
    if (strcmp(name, "synclong") == 0) {
        /* syncs 4 bytes apart, each Size 0x5A..0x93 (about 9 in 100:
         * 0xFF): a helper's hill-climb found the scan lags for good on
         * such a stream, every judged candidate summed over a long
         * stretch */
        for (i = 0; i + 4u <= cap;) {
            uint8_t r = rnd8();
            i = put_sync(buf, i, (r < 24u) ? 0xFFu : (uint8_t)(0x5Au + r % 58u));
        }
        return i;
    }
    if (strcmp(name, "sync4") == 0 || strcmp(name, "syncrand") == 0) {
        int r = strcmp(name, "syncrand") == 0;
        for (i = 0; i + 4u <= cap;) {
            i = put_sync(buf, i, r ? rnd8() : 0xFF);
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
