/*
 * Writes the committed seed corpus: fuzz/corpus/<harness>/seed-NN.
 * Run by scripts/dev/fuzz-seeds.sh; the output is deterministic so re-running
 * it changes nothing in git. A new harness adds a seeds_<name>() here.
 * Host-only helper (stdio).
 */
#include <stdio.h>
#include <string.h>

#include "tase/codec.h"
#include "tase/frame.h"
#include "tase/klv.h"

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
    n += (size_t)tase_frame_build(group, type, data, len, buf + n, sizeof(buf) - n);
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
    /* ten overlapping false syncs hiding two frames */
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
        int ni = tase_frame_build(0x08, 0x10, (const uint8_t *)"abcdef", 6, inner, sizeof(inner));
        int no = tase_frame_build(0x00, 0x42, inner, (size_t)ni, outer, sizeof(outer));
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

/* decode: mode, sel1, sel2, lensel, data (see fuzz/decode.c). */
static int seeds_decode(const char *dir)
{
    int bad = 0, idx = 0;
    size_t i, j;
    for (i = 0; i < TASE_PKT_COUNT; i++) { /* every packet at its table length */
        const tase_packet_desc_t *p = tase_schema_at(i);
        put_byte(1), put_byte((uint8_t)i), put_byte(0), put_byte(0);
        for (j = 0; j < p->len; j++) {
            put_byte((uint8_t)(0x80u + j * 29u + i));
        }
        bad |= save(dir, "decode", idx++);
    }
    /* queries, CAMERA_CMD short form, a CAMERA_PASS tail, near misses */
    put_byte(3), put_byte(TASE_PKT_PACKET_RATE), put_byte(0), put_byte(0);
    bad |= save(dir, "decode", idx++);
    put_byte(3), put_byte(TASE_PKT_CAMERA_CMD), put_byte(0), put_byte(1), put_byte(2);
    bad |= save(dir, "decode", idx++);
    put_byte(5), put_byte(TASE_PKT_CAMERA_PASS), put_byte(0), put_byte(0);
    for (j = 0; j < 40u; j++) {
        put_byte((uint8_t)(j * 7u));
    }
    bad |= save(dir, "decode", idx++);
    put_byte(7), put_byte(TASE_PKT_GEOREFERENCE_DATA), put_byte(0), put_byte(5);
    for (j = 0; j < 64u; j++) {
        put_byte((uint8_t)j);
    }
    bad |= save(dir, "decode", idx++);
    /* unknown: group 0x28 STATUS, and an unknown type of a known group */
    put_byte(2), put_byte(0x28), put_byte(0x10), put_byte(4);
    put_byte(1), put_byte(2), put_byte(3), put_byte(4);
    bad |= save(dir, "decode", idx++);
    put_byte(2), put_byte(0x48), put_byte(0x08), put_byte(16);
    bad |= save(dir, "decode", idx++);
    return bad;
}

static void put_klv(uint8_t fill, int spec_len)
{
    tase_klv_t k;
    uint8_t pkt[TASE_KLV_PACKET_LEN];
    memset(&k, 0, sizeof(k));
    k.utc = 1700000000000000ull + fill;
    k.lat = 0x12345678 + fill;
    k.lon = -0x1234567 - fill;
    k.alt = 0x4000;
    k.pan = (uint16_t)(fill * 300u);
    k.tilt = -1000;
    k.heading = 0x8000;
    k.hfov = 0x1000;
    k.vfov = 0x0C00;
    k.gps_status = 0xE020;
    tase_klv_encode(&k, pkt, sizeof(pkt));
    if (spec_len) {
        pkt[TASE_KLV_KEY_LEN] = TASE_KLV_SET_LEN_SPEC;
    }
    put(pkt, sizeof(pkt));
}

/* klv: mode, 2 split-seed bytes, then the stream (mode 1) or op records
 * (mode 0, see fuzz/klv.c). */
static int seeds_klv(const char *dir)
{
    int bad = 0, k, j;
    /* raw: clean packets (70 and 69), noise and a cut one between */
    put_byte(1), put_byte(0x12), put_byte(0x34);
    put_klv(1, 0);
    put((const uint8_t *)"\x06\x0E\x2B\x34noise\x06", 10);
    put_klv(2, 1);
    put_klv(3, 0);
    n -= 20;
    put_klv(4, 0);
    bad |= save(dir, "klv", 0);
    /* built: packets in every length form, flips, truncation, false keys */
    put_byte(0), put_byte(0x00), put_byte(0x07);
    for (k = 0; k < 8; k++) {
        put_byte(0), put_byte((uint8_t)(k % 2 + (k / 2) * 2)); /* PACKET, form */
        for (j = 0; j < 40; j++) {
            put_byte((uint8_t)(j * 11 + k));
        }
        switch (k) {
        case 1: put_byte(2), put_byte(70), put_byte(0x01); break; /* FLIP checksum */
        case 2: put_byte(3), put_byte(5); break;                  /* TRUNC */
        case 3: put_byte(4), put_byte(15); break;                 /* KEY */
        case 4: put_byte(1), put_byte(3), put(buf, 3); break;     /* NOISE */
        case 5: put_byte(2), put_byte(16), put_byte(0x10); break; /* FLIP length */
        default: break;
        }
    }
    bad |= save(dir, "klv", 1);
    return bad;
}

/* can: mode, count, frames, ops (see fuzz/can.c); mode 3: candump text. */
static int seeds_can(const char *dir)
{
    static const char lines[] = "(1700000000.123456) vcan0 11000000#00FF5A0808100001\n"
                                "(0000000001.000000) can1 10000000#00.FF.5A.02.48.03\r\n"
                                "(1.999999)\tslcan0  123#DEADBEEF R\n"
                                "(1700000000.000001) vcan0 12010000#FE00 T\n"
                                "(1700000000.000002) vcan0 7FF#\n"
                                "(1700000000.000003) vcan0 123#R\n"
                                "(1700000000.000004) vcan0 20000080#0000000000000000\n"
                                "(1700000000.000005) vcan0 123##1AABB\n";
    int bad = 0, k, j;
    for (k = 0; k < 4; k++) { /* host/gimbal x per-frame/packed, clean */
        if (k == 3) {
            put_byte(0x10 | 1); /* gimbal, per frame */
        } else {
            put_byte((uint8_t)k);
        }
        put_byte(3); /* 4 frames */
        for (j = 0; j < 4; j++) {
            size_t m, len = (size_t)(j * 9 + k);
            put_byte(0x08), put_byte(j % 2 ? 0x10 : 0x40), put_byte((uint8_t)len);
            for (m = 0; m < len; m++) {
                put_byte((uint8_t)(m * 5u + (size_t)j));
            }
        }
        for (j = 0; j < 24; j++) { /* drop, duplicate, swap, inject each kind */
            static const uint8_t ops[] = {0, 4, 0, 5, 0,  6,    0,    7,    1,    2,    3, 4,
                                          0, 0, 0, 7, 15, 0x7F, 0xFF, 0x23, 0x47, 0x67, 0, 0x37};
            put_byte(k == 0 ? 0 : ops[j]);
        }
        bad |= save(dir, "can", k);
    }
    put_byte(3);
    put((const uint8_t *)lines, sizeof(lines) - 1u);
    bad |= save(dir, "can", 4);
    return bad;
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "fuzz/corpus";
    return seeds_rx_bytes(dir) | seeds_rx_frames(dir) | seeds_decode(dir) | seeds_klv(dir) |
           seeds_can(dir);
}
