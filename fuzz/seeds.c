/*
 * Writes the committed seed corpus: fuzz/corpus/<harness>/seed-NN.
 * Run by scripts/fuzz-seeds.sh; the output is deterministic so re-running
 * it changes nothing in git. A new harness adds a seeds_<name>() here.
 * Host-only helper (stdio).
 */
#include <stdio.h>
#include <string.h>

#include "tase/frame.h"

static uint8_t buf[8192];
static size_t n;

static void put(const uint8_t *p, size_t len)
{
    memcpy(buf + n, p, len);
    n += len;
}

static void put_byte(uint8_t b)
{
    buf[n++] = b;
}

static void put_frame(uint8_t group, uint8_t type, size_t len, uint8_t fill)
{
    uint8_t data[TASE_DATA_MAX];
    size_t i;
    for (i = 0; i < len; i++) {
        data[i] = (uint8_t)(fill + i * 37u);
    }
    n += (size_t)tase_frame_encode(buf + n, sizeof(buf) - n, group, type, data, len);
}

static int save(const char *dir, const char *harness, int idx)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof(path), "%s/%s/seed-%02d", dir, harness, idx);
    f = fopen(path, "wb");
    if (f == NULL || fwrite(buf, 1, n, f) != n) {
        perror(path);
        return 1;
    }
    fclose(f);
    n = 0;
    return 0;
}

/* rx_bytes: 2 split-seed bytes, then a stream. */
static int seeds_rx_bytes(const char *dir)
{
    static const uint8_t sync[] = {0x00, 0xFF, 0x5A};
    int bad = 0, k;
    /* a telemetry-like run of clean frames */
    put_byte(0x12), put_byte(0x34);
    for (k = 0; k < 6; k++) {
        put_frame(0x08, k % 2 ? 0x10 : 0x40, k % 2 ? 6 : 18, (uint8_t)k);
    }
    bad |= save(dir, "rx_bytes", 0);
    /* noise, partial syncs, bad sizes, then a frame */
    put_byte(0x00), put_byte(0x01);
    put((const uint8_t *)"\x11\x00\x00\xFF\x00\xFF\xFF\x00\xFF\x5A\x01\x00\xFF\x5A\x00", 15);
    put_frame(0x00, 0x40, 0, 0);
    bad |= save(dir, "rx_bytes", 1);
    /* a corrupted Size that claims 253 bytes over clean frames */
    put_byte(0xAB), put_byte(0xCD);
    put(sync, 3), put_byte(0xFF), put_byte(0x08), put_byte(0x10);
    for (k = 0; k < 5; k++) {
        put_frame(0x10, 0x10, 30, (uint8_t)k);
    }
    bad |= save(dir, "rx_bytes", 2);
    /* more overlapping false syncs than candidate slots */
    put_byte(0x00), put_byte(0x07);
    for (k = 0; k < 10; k++) {
        put(sync, 3), put_byte(0xF0);
    }
    put_frame(0x48, 0x03, 0, 0);
    put_frame(0x08, 0x10, 6, 9);
    bad |= save(dir, "rx_bytes", 3);
    /* a frame carrying a frame (CAMERA_PASS style) and a maximal frame */
    put_byte(0x55), put_byte(0x55);
    {
        uint8_t inner[32], outer[64];
        int ni = tase_frame_encode(inner, sizeof(inner), 0x08, 0x10, (const uint8_t *)"abcdef", 6);
        int no = tase_frame_encode(outer, sizeof(outer), 0x00, 0x42, inner, (size_t)ni);
        put(outer, (size_t)no);
    }
    put_frame(0xFF, 0xFF, TASE_DATA_MAX, 0xFF);
    put(sync, 2);
    bad |= save(dir, "rx_bytes", 4);
    /* one frame of every length 0..64, then long ones: the fuzzer need not
     * invent a matching checksum to reach a delivery of any short length */
    put_byte(0x0F), put_byte(0xF0);
    for (k = 0; k <= 64; k++) {
        put_frame(0x08, (uint8_t)k, (size_t)k, (uint8_t)(k * 3));
    }
    put_frame(0x00, 0x42, 100, 1);
    put_frame(0x10, 0x41, 200, 2);
    bad |= save(dir, "rx_bytes", 5);
    return bad;
}

/* rx_frames: 2 split-seed bytes, then op records (see fuzz/rx_frames.c). */
static int seeds_rx_frames(const char *dir)
{
    int bad = 0, k;
    put_byte(0x01), put_byte(0x02);
    for (k = 0; k < 8; k++) { /* FRAME group type len data... */
        size_t j, len = k % 2 ? 6 : 18;
        put_byte(0), put_byte(0x08), put_byte(k % 2 ? 0x10 : 0x40), put_byte((uint8_t)len);
        for (j = 0; j < len; j++) {
            put_byte((uint8_t)(j * 13u + (size_t)k));
        }
    }
    bad |= save(dir, "rx_frames", 0);
    put_byte(0x03), put_byte(0x04);
    for (k = 0; k < 6; k++) {
        put_byte(0), put_byte(0x08), put_byte(0x10), put_byte(6);
        put((const uint8_t *)"\x01\x02\x03\x04\x05\x06", 6);
        switch (k) {
        case 0: put_byte(3), put_byte(3), put_byte(0x01); break; /* FLIP Size */
        case 1: put_byte(4), put_byte(7); break;                 /* DROP */
        case 2: put_byte(5), put_byte(9), put_byte(0x5A); break; /* INSERT */
        case 3: put_byte(6), put_byte(2); break;                 /* TRUNC */
        case 4: put_byte(2), put_byte(0xFF); break;              /* false SYNC */
        default: put_byte(1), put_byte(4), put(buf, 4); break;   /* NOISE */
        }
    }
    bad |= save(dir, "rx_frames", 1);
    return bad;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "fuzz/corpus";
    return seeds_rx_bytes(dir) | seeds_rx_frames(dir);
}
