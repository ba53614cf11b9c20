/* Tests of the typed codec: byte-exact frames computed by hand, a
 * round trip of every packet type with random and extreme values, every
 * wrong length rejected, and argument errors that write nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "packet_fill.h"
#include "tase/codec.h"
#include "tase/flags.h"

static uint32_t rng_state = 0x2545F491u;
static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static tase_frame_t frame_of(const uint8_t *buf, int n)
{
    tase_frame_t f;
    assert_true(n >= 8);
    memset(&f, 0, sizeof(f));
    f.group = buf[4];
    f.type = buf[5];
    f.len = (uint8_t)(n - 8);
    f.data = buf + 6;
    return f;
}

/* ---- byte-exact frames, one or more per group ----------------------- */

static void gimbal_cmd_extremes_encode_to_hand_computed_frame(void **state)
{
    /* pan INT16_MIN = 80 00, tilt -1 = FF FF, roll INT16_MAX = 7F FF,
     * flags rate+stab = 0x90, impulse 200 = C8. Size = 8 + 2 = 0x0A.
     * Sum: 00+FF+5A+0A+00+80 = 483; 80+00+FF+FF+7F+FF+90+C8 = 1364;
     * 1847 = 0x0737. */
    static const uint8_t want[] = {0x00, 0xFF, 0x5A, 0x0A, 0x00, 0x80, 0x80, 0x00,
                                   0xFF, 0xFF, 0x7F, 0xFF, 0x90, 0xC8, 0x07, 0x37};
    tase_gimbal_cmd_t m = {INT16_MIN, -1, INT16_MAX, TASE_GIMBAL_FLAGS_RATE_STAB, 200};
    tase_gimbal_cmd_t back;
    uint8_t out[64];
    tase_frame_t f;
    (void)state;
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &m, out, sizeof(out)), 16);
    assert_memory_equal(out, want, sizeof(want));
    f = frame_of(out, 16);
    memset(&back, 0x55, sizeof(back));
    assert_int_equal(tase_packet_decode(&f, &back), 8);
    assert_int_equal(back.pan, INT16_MIN);
    assert_int_equal(back.tilt, -1);
    assert_int_equal(back.roll, INT16_MAX);
    assert_int_equal(back.flags, 0x90);
    assert_int_equal(back.impulse_time, 200);
}

static void gyro_zero_and_camera_short_forms_encode_to_hand_computed_frames(void **state)
{
    /* GYRO_ZERO_CMD: 00 FF 5A 02 00 40, sum 411 = 0x019B. */
    static const uint8_t gyro[] = {0x00, 0xFF, 0x5A, 0x02, 0x00, 0x40, 0x01, 0x9B};
    /* CAMERA_CMD camera-only form, camera B: 00 FF 5A 03 00 41 01,
     * sum 414 = 0x019E. */
    static const uint8_t cam1[] = {0x00, 0xFF, 0x5A, 0x03, 0x00, 0x41, 0x01, 0x01, 0x9E};
    /* CAMERA_PASS camera C, 57600 baud = 48 * 1200 (0x30), bytes 'A' 'B':
     * 00 FF 5A 08 00 42 02 30 00 00 41 42, sum 600 = 0x0258. */
    static const uint8_t pass[] = {0x00, 0xFF, 0x5A, 0x08, 0x00, 0x42, 0x02,
                                   0x30, 0x00, 0x00, 0x41, 0x42, 0x02, 0x58};
    tase_camera_cmd_t cam = {TASE_CAMERA_B, 1234, 0xFFFF, 1, 2, 3, 0x80};
    tase_camera_pass_t cp = {TASE_CAMERA_C, 48, 2, (const uint8_t *)"AB"};
    tase_camera_pass_t cpb;
    tase_camera_cmd_t camb;
    uint8_t out[64];
    tase_frame_t f;
    (void)state;
    assert_int_equal(tase_packet_encode(TASE_ID_GYRO_ZERO_CMD, NULL, out, sizeof(out)), 8);
    assert_memory_equal(out, gyro, sizeof(gyro));
    assert_int_equal(tase_packet_encode_query(TASE_ID_GYRO_ZERO_CMD, out, sizeof(out)), 8);
    assert_memory_equal(out, gyro, sizeof(gyro));
    f = frame_of(out, 8);
    assert_int_equal(tase_packet_decode(&f, NULL), 0);

    assert_int_equal(tase_packet_encode_len(TASE_ID_CAMERA_CMD, &cam, 1, out, sizeof(out)), 9);
    assert_memory_equal(out, cam1, sizeof(cam1));
    f = frame_of(out, 9);
    memset(&camb, 0x55, sizeof(camb));
    assert_int_equal(tase_packet_decode(&f, &camb), 1);
    assert_int_equal(camb.camera, 1);
    /* Not sent: "do not change" (4.1.3), never a zero that is a command
     * (focus 0 = auto-focus, exposure 0 = full auto, flags 0 = white hot,
     * stabilisation and title off). */
    assert_int_equal(camb.hfov, -1);
    assert_int_equal(camb.focus, 0xFFFF);
    assert_int_equal(camb.exposure, 0xFF);
    assert_int_equal(camb.shutter_speed, 0xFF);
    assert_int_equal(camb.bright, 0xFF);
    assert_int_equal(camb.flags, TASE_CAMERA_FLAG_NO_CHANGE);

    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)), 14);
    assert_memory_equal(out, pass, sizeof(pass));
    f = frame_of(out, 14);
    assert_int_equal(tase_packet_decode(&f, &cpb), 6);
    assert_int_equal(cpb.camera, 2);
    assert_int_equal(cpb.baud, 48);
    assert_int_equal(cpb.len, 2);
    assert_ptr_equal(cpb.data, out + 10); /* points into the frame */
}

static void gimbal_angle_encodes_to_hand_computed_frame(void **state)
{
    /* pan 1.00 deg = 100 = 00 64, tilt -45.00 deg = -4500 = EE 6C, roll 0.
     * Sum: 00+FF+5A+08+08+10 = 377; 64+EE+6C = 446; 823 = 0x0337. */
    static const uint8_t want[] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x00,
                                   0x64, 0xEE, 0x6C, 0x00, 0x00, 0x03, 0x37};
    tase_gimbal_angle_t m = {100, -4500, 0};
    uint8_t out[32];
    (void)state;
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_ANGLE, &m, out, sizeof(out)), 14);
    assert_memory_equal(out, want, sizeof(want));
}

static void spoi_full_and_query_forms_encode_to_hand_computed_frames(void **state)
{
    /* lat INT32_MIN, lon -1, height 0x12345678, vnorth -2, veast 0x0102,
     * vdown 0, flags echo. Size 19 + 2 = 0x15. Sum: header
     * FF+5A+15+10+40 = 446; data 80 + 4*FF + 12+34+56+78 + FF+FE + 01+02
     * + 80 = 2064; 2510 = 0x09CE. Query: 00 FF 5A 02 10 40, 427 = 0x01AB. */
    static const uint8_t want[] = {0x00, 0xFF, 0x5A, 0x15, 0x10, 0x40, 0x80, 0x00, 0x00,
                                   0x00, 0xFF, 0xFF, 0xFF, 0xFF, 0x12, 0x34, 0x56, 0x78,
                                   0xFF, 0xFE, 0x01, 0x02, 0x00, 0x00, 0x80, 0x09, 0xCE};
    static const uint8_t query[] = {0x00, 0xFF, 0x5A, 0x02, 0x10, 0x40, 0x01, 0xAB};
    tase_spoi_cmd_t m = {INT32_MIN, -1, 0x12345678, -2, 0x0102, 0, TASE_SPOI_ECHO};
    tase_spoi_cmd_t back;
    uint8_t out[64];
    tase_frame_t f;
    (void)state;
    assert_int_equal(tase_packet_encode(TASE_ID_SPOI_CMD, &m, out, sizeof(out)), 27);
    assert_memory_equal(out, want, sizeof(want));
    f = frame_of(out, 27);
    assert_int_equal(tase_packet_decode(&f, &back), 19);
    assert_true(back.lat == INT32_MIN);
    assert_int_equal(back.lon, -1);
    assert_int_equal(back.vnorth, -2);
    assert_int_equal(tase_packet_encode_query(TASE_ID_SPOI_CMD, out, sizeof(out)), 8);
    assert_memory_equal(out, query, sizeof(query));
    f = frame_of(out, 8);
    memset(&back, 0x55, sizeof(back));
    assert_int_equal(tase_packet_decode(&f, &back), 0);
    assert_int_equal(back.lat, 0); /* a query decodes as a zeroed struct */
    assert_int_equal(back.flags, 0);
}

static void axis_setting_leaves_byte_13_reserved_zero(void **state)
{
    /* Data: B9B0 (-18000) FFFF 2328 (9000) 1770 (6000) 0000 0000, 3C,
     * [13] 00, 3C FF 32 32 FF 28 28 FF 01. Size 23 + 2 = 0x19.
     * Sum: header FF+5A+19+48+02 = 444; data 2147; 2591 = 0x0A1F. */
    static const uint8_t want[] = {0x00, 0xFF, 0x5A, 0x19, 0x48, 0x02, 0xB9, 0xB0, 0xFF, 0xFF, 0x23,
                                   0x28, 0x17, 0x70, 0x00, 0x00, 0x00, 0x00, 0x3C, 0x00, 0x3C, 0xFF,
                                   0x32, 0x32, 0xFF, 0x28, 0x28, 0xFF, 0x01, 0x0A, 0x1F};
    tase_axis_setting_t m;
    uint8_t out[64];
    (void)state;
    memset(&m, 0, sizeof(m));
    m.pan_nogo_center = -18000;
    m.pan_nogo_range = TASE_AXIS_NO_CHANGE16;
    m.tilt_nogo_center = 9000;
    m.tilt_nogo_range = 6000;
    m.pan_max_rate = 60;
    m.tilt_max_rate = 60;
    m.roll_max_rate = TASE_AXIS_NO_CHANGE8;
    m.pan_max_accel = 50;
    m.tilt_max_accel = 50;
    m.roll_max_accel = 0xFF;
    m.pan_pos_gain = 40;
    m.tilt_pos_gain = 40;
    m.roll_pos_gain = 0xFF;
    m.temporary = TASE_SETUP_TEMPORARY;
    memset(out, 0xAA, sizeof(out)); /* reserved byte must be cleared */
    assert_int_equal(tase_packet_encode(TASE_ID_AXIS_SETTING, &m, out, sizeof(out)), 31);
    assert_memory_equal(out, want, sizeof(want));
}

/* Table 22 read as a row-numbering slip (no byte 13, 22 bytes): accepted
 * and decoded by its own layout, and encoded when asked for (S2). */
static void axis_setting_22_byte_layout_decodes_and_encodes_to_hand_computed_frames(void **state)
{
    /* The data of the test above without byte 13: ... 3C, 3C FF 32 32 FF
     * 28 28 FF 01. Size 22 + 2 = 0x18. Sum: header FF+5A+18+48+02 = 443;
     * data 2147; 2590 = 0x0A1E. */
    static const uint8_t want22[] = {0x00, 0xFF, 0x5A, 0x18, 0x48, 0x02, 0xB9, 0xB0, 0xFF, 0xFF,
                                     0x23, 0x28, 0x17, 0x70, 0x00, 0x00, 0x00, 0x00, 0x3C, 0x3C,
                                     0xFF, 0x32, 0x32, 0xFF, 0x28, 0x28, 0xFF, 0x01, 0x0A, 0x1E};
    /* The 23-byte frame with a non-zero byte 13 (ignored): sum + 0xAB. */
    static const uint8_t in23[] = {0x00, 0xFF, 0x5A, 0x19, 0x48, 0x02, 0xB9, 0xB0, 0xFF, 0xFF, 0x23,
                                   0x28, 0x17, 0x70, 0x00, 0x00, 0x00, 0x00, 0x3C, 0xAB, 0x3C, 0xFF,
                                   0x32, 0x32, 0xFF, 0x28, 0x28, 0xFF, 0x01, 0x0A, 0xCA};
    tase_axis_setting_t a22, a23;
    uint8_t out[64];
    tase_frame_t f;
    (void)state;
    f = frame_of(want22, sizeof(want22));
    memset(&a22, 0x55, sizeof(a22));
    assert_int_equal(tase_packet_decode(&f, &a22), 22);
    assert_int_equal(a22.pan_nogo_center, -18000);
    assert_int_equal(a22.pan_nogo_range, 0xFFFF);
    assert_int_equal(a22.tilt_nogo_center, 9000);
    assert_int_equal(a22.tilt_nogo_range, 6000);
    assert_int_equal(a22.pan_max_rate, 60);    /* byte 12 */
    assert_int_equal(a22.tilt_max_rate, 60);   /* byte 13 */
    assert_int_equal(a22.roll_max_rate, 0xFF); /* 14 */
    assert_int_equal(a22.pan_max_accel, 50);   /* 15 */
    assert_int_equal(a22.tilt_max_accel, 50);  /* 16 */
    assert_int_equal(a22.roll_max_accel, 0xFF);
    assert_int_equal(a22.pan_pos_gain, 40); /* 18 */
    assert_int_equal(a22.tilt_pos_gain, 40);
    assert_int_equal(a22.roll_pos_gain, 0xFF);
    assert_int_equal(a22.temporary, 1); /* 21 */
    /* the same settings in the 23-byte layout decode to the same struct */
    f = frame_of(in23, sizeof(in23));
    memset(&a23, 0x33, sizeof(a23));
    assert_int_equal(tase_packet_decode(&f, &a23), 23);
    assert_memory_equal(&a22, &a23, sizeof(a22));
    /* the encoder writes 23 unless asked for the short layout */
    assert_int_equal(tase_packet_encode_len(TASE_ID_AXIS_SETTING, &a22, 22, out, sizeof(out)), 30);
    assert_memory_equal(out, want22, sizeof(want22));
    assert_int_equal(tase_packet_encode(TASE_ID_AXIS_SETTING, &a22, out, sizeof(out)), 31);
    assert_int_equal(out[6 + 13], 0x00);
    assert_int_equal(out[6 + 22], 0x01);
}

/* ---- every packet: round trips -------------------------------------- */

static uint8_t rnd8(void)
{
    return (uint8_t)rnd();
}

static void every_packet_round_trips_random_and_extreme_values(void **state)
{
    size_t i, k;
    int mode, rep;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (mode = 0; mode < 5; mode++) {
            for (rep = 0; rep < (mode == 4 ? 200 : 1); rep++) {
                uint8_t data[TASE_DATA_MAX], tail[TASE_CAMERA_PASS_MAX];
                uint8_t wire[TASE_FRAME_MAX], again[TASE_FRAME_MAX];
                tase_packet_msg_t m1, m2;
                tase_frame_t f;
                size_t len = p->len;
                int n;
                packet_fill_fields(p, data, mode, rnd8);
                if (p->flags & TASE_LEN_TAIL) {
                    size_t extra = rnd() % (TASE_CAMERA_PASS_MAX + 1);
                    for (k = 0; k < extra; k++) {
                        tail[k] = (uint8_t)rnd();
                    }
                    memcpy(data + len, tail, extra);
                    len += extra;
                }
                n = tase_frame_build(TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len, wire,
                                     sizeof(wire));
                assert_int_equal(n, (int)len + 8);
                f = frame_of(wire, n);
                /* wire -> struct: every member equals the raw field value */
                memset(&m1, 0x55, sizeof(m1));
                assert_int_equal(tase_packet_decode(&f, p->size ? &m1 : NULL), (int)len);
                for (k = 0; k < p->nfields; k++) {
                    const tase_field_t *fd = tase_schema_field(p, k);
                    int64_t raw;
                    uint64_t bits = 0, want;
                    unsigned w = TASE_FIELD_WIDTH(fd);
                    assert_int_equal(tase_field_get(p, k, f.data, f.len, &raw), TASE_OK);
                    bits = packet_member_bits((const uint8_t *)&m1 + fd->member, w);
                    want = w == 8 ? (uint64_t)raw : ((uint64_t)raw & ((1ull << (8 * w)) - 1));
                    assert_true(bits == want);
                }
                /* struct -> wire: byte-identical frame */
                n = tase_packet_encode(p->id, p->size ? &m1 : NULL, again, sizeof(again));
                assert_int_equal(n, (int)len + 8);
                assert_memory_equal(again, wire, (size_t)n);
                /* and back to an identical struct */
                f = frame_of(again, n);
                memset(&m2, 0x33, sizeof(m2));
                assert_int_equal(tase_packet_decode(&f, p->size ? &m2 : NULL), (int)len);
                if (p->flags & TASE_LEN_TAIL) {
                    assert_memory_equal(m2.camera_pass.data, tail, m2.camera_pass.len);
                    m2.camera_pass.data = m1.camera_pass.data;
                }
                assert_memory_equal(&m1, &m2, p->size);
            }
        }
    }
}

static void every_query_capable_packet_encodes_an_eight_byte_query(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        uint8_t out[16];
        int n;
        memset(out, 0xAA, sizeof(out));
        n = tase_packet_encode_query(p->id, out, sizeof(out));
        if (tase_schema_length_ok(p, 0)) {
            uint16_t sum = (uint16_t)(0xFF + 0x5A + 2 + TASE_ID_GROUP(p->id) + TASE_ID_TYPE(p->id));
            assert_int_equal(n, 8);
            assert_int_equal(out[3], 2);
            assert_int_equal(out[6], sum >> 8);
            assert_int_equal(out[7], sum & 0xFF);
        } else {
            assert_int_equal(n, TASE_ELENGTH);
            assert_int_equal(out[0], 0xAA);
        }
    }
}

static void every_wrong_length_is_rejected_on_decode_and_encode(void **state)
{
    size_t i, len;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (len = 0; len <= TASE_DATA_MAX; len++) {
            uint8_t data[TASE_DATA_MAX] = {0};
            uint8_t out[TASE_FRAME_MAX];
            tase_packet_msg_t m, before;
            tase_frame_t f;
            if (tase_schema_length_ok(p, len)) {
                continue;
            }
            memset(&f, 0, sizeof(f));
            f.group = TASE_ID_GROUP(p->id);
            f.type = TASE_ID_TYPE(p->id);
            f.len = (uint8_t)len;
            f.data = data;
            memset(&m, 0x5A, sizeof(m));
            before = m;
            assert_int_equal(tase_packet_decode(&f, &m), TASE_ELENGTH);
            assert_memory_equal(&m, &before, sizeof(m));
            memset(out, 0xAA, sizeof(out));
            memset(&m, 0, sizeof(m));
            /* (CAMERA_PASS: m.camera_pass.len is 0, so only 4 fits) */
            assert_int_equal(tase_packet_encode_len(p->id, &m, len, out, sizeof(out)),
                             TASE_ELENGTH);
            assert_int_equal(out[0], 0xAA);
        }
    }
}

static void argument_errors_are_reported_and_write_nothing(void **state)
{
    tase_gimbal_cmd_t m = {1, 2, 3, 4, 5};
    tase_camera_pass_t cp = {0, 0, 250, (const uint8_t *)"x"};
    uint8_t out[TASE_FRAME_MAX];
    uint8_t d[8] = {0};
    tase_frame_t f = {0, 0x28, 0x00, 8, d};
    tase_packet_msg_t msg;
    size_t cap;
    (void)state;
    memset(out, 0xAA, sizeof(out));
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &m, NULL, 64), TASE_EARG);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, NULL, out, 64), TASE_EARG);
    assert_int_equal(tase_packet_encode(TASE_ID(0x28, 0x00), &m, out, 64), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_encode_query(TASE_ID(0x00, 0x99), out, 64), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)), TASE_ETOOLONG);
    cp.len = 3;
    cp.data = NULL;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)), TASE_EARG);
    for (cap = 0; cap < 16; cap++) {
        assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &m, out, cap), TASE_ENOSPC);
    }
    assert_int_equal(out[0], 0xAA);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &m, out, 16), 16);

    assert_int_equal(tase_packet_decode(NULL, &msg), TASE_EARG);
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_EUNKNOWN);
    f.group = 0x00;
    f.type = 0x80;
    assert_int_equal(tase_packet_decode(&f, NULL), TASE_EARG);
    f.data = NULL;
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_EARG);
}

static void camera_pass_carries_249_bytes_and_may_be_encoded_in_place(void **state)
{
    uint8_t out[TASE_FRAME_MAX];
    uint8_t want[TASE_CAMERA_PASS_MAX];
    tase_camera_pass_t cp, back;
    tase_frame_t f;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof(want); k++) {
        want[k] = (uint8_t)(k * 7u + 1u);
    }
    /* the camera bytes already sit where the payload goes */
    memcpy(out + TASE_FRAME_HEADER + 4, want, sizeof(want));
    cp.camera = 1;
    cp.baud = 8;
    cp.len = TASE_CAMERA_PASS_MAX;
    cp.data = out + TASE_FRAME_HEADER + 4;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)),
                     (int)TASE_FRAME_MAX);
    assert_int_equal(out[3], 255); /* Size: 253 + 2 */
    f = frame_of(out, (int)TASE_FRAME_MAX);
    assert_int_equal(tase_packet_decode(&f, &back), 253);
    assert_int_equal(back.len, 249);
    assert_memory_equal(back.data, want, sizeof(want));
    /* an empty pass-through packet is 4 bytes */
    cp.len = 0;
    cp.data = NULL;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)), 12);
}

/* codec.h: CAMERA_PASS's camera bytes may lie anywhere in the output,
 * also under the frame header or the 4 fixed bytes the encoders write:
 * at every offset, tase_packet_encode() and tase_packet_encode_data()
 * give what they give from a separate copy. */
static void camera_bytes_anywhere_in_the_output_encode_the_same(void **state)
{
    static const uint8_t cam[10] = {0x81, 1, 6, 1, 0x30, 0x30, 3, 3, 0xFF, 0x5A};
    tase_camera_pass_t cp = {2, 8, sizeof cam, cam};
    uint8_t want[sizeof cam + 4u + TASE_FRAME_OVERHEAD];
    uint8_t want_data[sizeof cam + 4u];
    uint8_t buf[48];
    size_t at;
    (void)state;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, want, sizeof want),
                     (int)sizeof want);
    assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, want_data, sizeof want_data),
                     (int)sizeof want_data);
    for (at = 0; at + sizeof cam <= sizeof buf; at++) {
        memset(buf, 0xEE, sizeof buf);
        memcpy(&buf[at], cam, sizeof cam);
        cp.data = &buf[at];
        assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, buf, sizeof buf),
                         (int)sizeof want);
        assert_memory_equal(buf, want, sizeof want);
        memset(buf, 0xEE, sizeof buf);
        memcpy(&buf[at], cam, sizeof cam);
        assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, buf, sizeof buf),
                         (int)sizeof want_data);
        assert_memory_equal(buf, want_data, sizeof want_data);
    }
}

static void unknown_ids_and_missing_structs_are_told_apart_from_missing_buffers(void **state)
{
    uint8_t out[TASE_FRAME_MAX];
    tase_camera_pass_t cp = {1, 2, 0, NULL};
    tase_frame_t gyro = {0, 0x00, 0x40, 0, NULL};
    tase_frame_t pass = {0, 0x00, 0x42, 4, NULL};
    (void)state;
    memset(out, 0xAA, sizeof(out));
    /* unknown packet: no buffer is TASE_EARG, else TASE_EUNKNOWN */
    assert_int_equal(tase_packet_encode(TASE_ID(0x28, 0x00), &cp, NULL, 64), TASE_EARG);
    assert_int_equal(tase_packet_encode_len(TASE_ID(0x28, 0x00), &cp, 4, NULL, 64), TASE_EARG);
    assert_int_equal(tase_packet_encode_len(TASE_ID(0x28, 0x00), &cp, 4, out, 64), TASE_EUNKNOWN);
    /* CAMERA_PASS without its struct: its 4 header bytes have no source */
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, NULL, out, sizeof(out)), TASE_EARG);
    assert_int_equal(out[0], 0xAA);
    /* ... with an empty tail it is the 4-byte form */
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof(out)), 12);
    assert_int_equal(out[6], 1);
    assert_int_equal(out[7], 2);
    /* a zero-length frame may come without data; a longer one may not */
    assert_int_equal(tase_packet_decode(&gyro, NULL), 0);
    assert_int_equal(tase_packet_decode(&pass, &cp), TASE_EARG);
    assert_int_equal(cp.camera, 1); /* untouched */
}

/* Bad arguments of codec.h give their documented codes; neither the output
 * buffer nor the decoded struct changes on any of them. */
static void codec_api_rejects_bad_arguments(void **state)
{
    tase_gimbal_cmd_t cmd;
    tase_camera_pass_t cp;
    uint8_t out[TASE_FRAME_MAX];
    uint8_t before[sizeof out];
    tase_packet_msg_t msg;
    tase_packet_msg_t mcopy;
    tase_frame_t f;
    (void)state;

    memset(&cmd, 0, sizeof cmd);
    memset(out, 0xA5, sizeof out);
    memcpy(before, out, sizeof out);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &cmd, NULL, sizeof out), TASE_EARG);
    assert_int_equal(tase_packet_encode(TASE_ID(0x28u, 0u), &cmd, NULL, sizeof out), TASE_EARG);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, NULL, out, sizeof out), TASE_EARG);
    assert_int_equal(tase_packet_encode(TASE_ID(0x28u, 0u), &cmd, out, sizeof out), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &cmd, out, 0), TASE_ENOSPC);
    assert_int_equal(tase_packet_encode(TASE_ID_GIMBAL_CMD, &cmd, out, 15), TASE_ENOSPC);
    assert_int_equal(tase_packet_encode_len(TASE_ID_GIMBAL_CMD, &cmd, SIZE_MAX, out, SIZE_MAX),
                     TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_len(TASE_ID_GIMBAL_CMD, &cmd, 9, out, sizeof out),
                     TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_len(TASE_ID_GIMBAL_CMD, &cmd, 0, out, sizeof out),
                     TASE_ELENGTH);
    cp.camera = 0;
    cp.baud = 0;
    cp.len = (uint8_t)(TASE_CAMERA_PASS_MAX + 1u);
    cp.data = before;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof out), TASE_ETOOLONG);
    cp.len = 3;
    cp.data = NULL;
    assert_int_equal(tase_packet_encode(TASE_ID_CAMERA_PASS, &cp, out, sizeof out), TASE_EARG);
    cp.data = before;
    assert_int_equal(tase_packet_encode_len(TASE_ID_CAMERA_PASS, &cp, SIZE_MAX, out, sizeof out),
                     TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_len(TASE_ID_CAMERA_PASS, &cp, 8, out, sizeof out),
                     TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_query(TASE_ID_GIMBAL_CMD, out, sizeof out), TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_query(TASE_ID_PACKET_RATE, NULL, 8), TASE_EARG);
    assert_int_equal(tase_packet_encode_query(TASE_ID_PACKET_RATE, out, 7), TASE_ENOSPC);
    assert_memory_equal(out, before, sizeof out);

    memset(&msg, 0x5A, sizeof msg);
    memcpy(&mcopy, &msg, sizeof msg);
    f.offset = 0;
    f.group = 0x00;
    f.type = 0x80; /* GIMBAL_CMD */
    f.len = 8;
    f.data = NULL;
    assert_int_equal(tase_packet_decode(NULL, &msg), TASE_EARG);
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_EARG);
    f.data = before;
    assert_int_equal(tase_packet_decode(&f, NULL), TASE_EARG);
    f.len = 7;
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_ELENGTH);
    f.len = 255;
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_ELENGTH);
    f.group = 0x28;
    assert_int_equal(tase_packet_decode(&f, &msg), TASE_EUNKNOWN);
    assert_memory_equal(&msg, &mcopy, sizeof msg);
}

/* ---- data bytes only ---------------------------------------------------- */

/* For every packet and every accepted length, the data-only encoders write
 * exactly the data bytes of the frame the frame encoders build, and the
 * data-only decoders give exactly the struct tase_packet_decode() gives. */
static void data_only_codec_matches_the_frame_codec_for_every_packet(void **state)
{
    size_t i, len, k;
    int rep;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (len = 0; len <= TASE_DATA_MAX; len++) {
            for (rep = 0; rep < 3 && tase_schema_length_ok(p, len); rep++) {
                uint8_t data[TASE_DATA_MAX], wire[TASE_FRAME_MAX], only[TASE_DATA_MAX + 1];
                tase_packet_msg_t by_frame, by_data, by_desc;
                void *msg = p->size ? &by_frame : NULL;
                tase_frame_t f;
                int n;
                for (k = 0; k < len; k++) {
                    data[k] = (uint8_t)rnd();
                }
                n = tase_frame_build(TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len, wire,
                                     sizeof wire);
                f = frame_of(wire, n);
                memset(&by_frame, 0x11, sizeof by_frame);
                memset(&by_data, 0x22, sizeof by_data);
                memset(&by_desc, 0x33, sizeof by_desc);
                assert_int_equal(tase_packet_decode(&f, msg), (int)len);
                assert_int_equal(
                    tase_packet_decode_data(p->id, data, len, p->size ? &by_data : NULL), (int)len);
                assert_int_equal(tase_packet_decode_desc(p, data, len, p->size ? &by_desc : NULL),
                                 (int)len);
                if (p->flags & TASE_LEN_TAIL) {
                    /* the tail points into what was decoded */
                    assert_ptr_equal(by_frame.camera_pass.data, f.data + 4);
                    assert_ptr_equal(by_data.camera_pass.data, data + 4);
                    assert_ptr_equal(by_desc.camera_pass.data, data + 4);
                    by_data.camera_pass.data = by_frame.camera_pass.data;
                    by_desc.camera_pass.data = by_frame.camera_pass.data;
                }
                assert_memory_equal(&by_data, &by_frame, p->size);
                assert_memory_equal(&by_desc, &by_frame, p->size);
                /* the struct back to data bytes: those of the frame encoder */
                n = tase_packet_encode_len(p->id, msg, len, wire, sizeof wire);
                assert_int_equal(n, (int)len + 8);
                memset(only, 0xEE, sizeof only);
                assert_int_equal(tase_packet_encode_data_len(p->id, msg, len, only, len), (int)len);
                assert_memory_equal(only, wire + TASE_FRAME_HEADER, len);
                assert_int_equal(only[len], 0xEE); /* nothing past the data */
                if (len == (size_t)p->len || (p->flags & TASE_LEN_TAIL)) {
                    n = tase_packet_encode(p->id, msg, wire, sizeof wire);
                    memset(only, 0xEE, sizeof only);
                    assert_int_equal(tase_packet_encode_data(p->id, msg, only, sizeof only), n - 8);
                    assert_memory_equal(only, wire + TASE_FRAME_HEADER, (size_t)n - 8u);
                }
            }
        }
    }
}

/* Bad arguments of the data-only functions give their documented codes
 * and write nothing. */
static void data_only_codec_rejects_bad_arguments(void **state)
{
    tase_gimbal_cmd_t cmd = {1, 2, 3, 4, 5};
    tase_camera_pass_t cp = {0, 0, 250, (const uint8_t *)"x"};
    tase_packet_desc_t fake;
    uint8_t out[TASE_DATA_MAX], before[TASE_DATA_MAX], in[8] = {0};
    tase_packet_msg_t msg, mcopy;
    size_t cap;
    (void)state;

    memset(out, 0xA5, sizeof out);
    memcpy(before, out, sizeof out);
    assert_int_equal(tase_packet_encode_data(TASE_ID_GIMBAL_CMD, &cmd, NULL, 8), TASE_EARG);
    assert_int_equal(tase_packet_encode_data(TASE_ID_GYRO_ZERO_CMD, NULL, NULL, 0), TASE_EARG);
    assert_int_equal(tase_packet_encode_data(TASE_ID(0x28u, 0u), &cmd, NULL, 8), TASE_EARG);
    assert_int_equal(tase_packet_encode_data(TASE_ID(0x28u, 0u), &cmd, out, 8), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_encode_data(TASE_ID_GIMBAL_CMD, NULL, out, 8), TASE_EARG);
    assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, out, sizeof out),
                     TASE_ETOOLONG);
    cp.data = NULL; /* both wrong: TASE_EARG first, in the documented order */
    assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, out, sizeof out), TASE_EARG);
    cp.len = 3;
    assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, out, sizeof out), TASE_EARG);
    for (cap = 0; cap < 8; cap++) {
        assert_int_equal(tase_packet_encode_data(TASE_ID_GIMBAL_CMD, &cmd, out, cap), TASE_ENOSPC);
    }
    assert_int_equal(tase_packet_encode_data_len(TASE_ID_GIMBAL_CMD, &cmd, 0, out, 8),
                     TASE_ELENGTH);
    assert_int_equal(tase_packet_encode_data_len(TASE_ID_GIMBAL_CMD, &cmd, SIZE_MAX, out, SIZE_MAX),
                     TASE_ELENGTH);
    assert_memory_equal(out, before, sizeof out);
    /* the forms without data need a buffer but no room */
    assert_int_equal(tase_packet_encode_data(TASE_ID_GYRO_ZERO_CMD, NULL, out, 0), 0);
    assert_int_equal(tase_packet_encode_data_len(TASE_ID_PACKET_RATE, NULL, 0, out, 0), 0);
    assert_int_equal(tase_packet_encode_data(TASE_ID_GIMBAL_CMD, &cmd, out, 8), 8);
    assert_int_equal(out[1], 1);

    memset(&msg, 0x5A, sizeof msg);
    memcpy(&mcopy, &msg, sizeof msg);
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, NULL, 8, &msg), TASE_EARG);
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, in, 8, NULL), TASE_EARG);
    assert_int_equal(tase_packet_decode_data(TASE_ID(0x28u, 0u), in, 8, &msg), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, in, 7, &msg), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, in, SIZE_MAX, &msg), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode_desc(NULL, in, 8, &msg), TASE_EUNKNOWN);
    assert_int_equal(tase_packet_decode_desc(NULL, NULL, 8, &msg), TASE_EARG);
    /* a copy of a real descriptor is not one of the table: its size could
     * be anything, so it is refused before msg is written */
    fake = *tase_schema_find(0x00, 0x80);
    fake.size = 255;
    assert_int_equal(tase_packet_decode_desc(&fake, in, 8, &msg), TASE_EARG);
    assert_memory_equal(&msg, &mcopy, sizeof msg);
    /* queries and GYRO_ZERO_CMD decode without data or struct */
    assert_int_equal(tase_packet_decode_data(TASE_ID_GYRO_ZERO_CMD, NULL, 0, NULL), 0);
    assert_int_equal(tase_packet_decode_data(TASE_ID_PACKET_RATE, NULL, 0, &msg), 0);
    assert_int_equal(msg.packet_rate.angle_1, 0); /* zeroed */
}

/* tase_command_check(): the twelve flags values of table 5 pass, the
 * other 244 are TASE_ERANGE; a position command must lie within pan
 * -180..180 and tilt -270..90 degrees (a rate, impulse or SPOI error
 * takes the wire's range); SPOI_CMD within 90 / 180 degrees. The table
 * and the limits are written out here from the spec, not from the code. */
static void command_check_takes_what_the_spec_defines_and_nothing_else(void **state)
{
    static const unsigned modes[] = {0x00, 0x01, 0x02, 0x03, 0x10, 0x90,
                                     0x20, 0xA0, 0x30, 0xB0, 0xC0, 0xD0};
    static const unsigned positions[] = {0x01, 0x03, 0x20, 0xA0};
    tase_gimbal_cmd_t c;
    tase_spoi_cmd_t sp;
    uint8_t data[TASE_DATA_MAX];
    unsigned f;
    size_t i;
    (void)state;
    memset(&c, 0, sizeof c);
    for (f = 0; f < 256u; f++) {
        int want = TASE_ERANGE;
        for (i = 0; i < sizeof modes / sizeof modes[0]; i++) {
            if (modes[i] == f) {
                want = TASE_OK;
            }
        }
        c.flags = (uint8_t)f;
        assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), want);
        assert_int_equal(tase_packet_encode_data(TASE_ID_GIMBAL_CMD, &c, data, sizeof data), 8);
        assert_int_equal(tase_command_check_data(TASE_ID_GIMBAL_CMD, data, 8), want);
    }
    for (i = 0; i < sizeof positions / sizeof positions[0]; i++) {
        static const int16_t pans[][2] = {{-18000, 1}, {18000, 1}, {-18001, 0},
                                          {18001, 0},  {32767, 0}, {-32768, 0}};
        static const int16_t tilts[][2] = {{-27000, 1}, {9000, 1}, {-27001, 0}, {9001, 0}};
        size_t k;
        c.flags = (uint8_t)positions[i];
        c.tilt = 0;
        for (k = 0; k < sizeof pans / sizeof pans[0]; k++) {
            c.pan = pans[k][0];
            assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c),
                             pans[k][1] ? TASE_OK : TASE_ERANGE);
        }
        c.pan = 0;
        for (k = 0; k < sizeof tilts / sizeof tilts[0]; k++) {
            c.tilt = tilts[k][0];
            assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c),
                             tilts[k][1] ? TASE_OK : TASE_ERANGE);
        }
    }
    c.pan = 32767;
    c.tilt = -32768;
    c.flags = TASE_GIMBAL_FLAGS_RATE_STAB;
    assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), TASE_OK);
    c.flags = TASE_GIMBAL_FLAGS_IMPULSE;
    assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), TASE_OK);

    memset(&sp, 0, sizeof sp);
    sp.lat = 324000000; /* 90 degrees in milli-arcseconds */
    sp.lon = -648000000;
    assert_int_equal(tase_command_check(TASE_ID_SPOI_CMD, &sp), TASE_OK);
    sp.lat = -324000001;
    assert_int_equal(tase_command_check(TASE_ID_SPOI_CMD, &sp), TASE_ERANGE);
    sp.lat = 0;
    sp.lon = 648000001;
    assert_int_equal(tase_command_check(TASE_ID_SPOI_CMD, &sp), TASE_ERANGE);
    assert_int_equal(tase_packet_encode_data(TASE_ID_SPOI_CMD, &sp, data, sizeof data), 19);
    assert_int_equal(tase_command_check_data(TASE_ID_SPOI_CMD, data, 19), TASE_ERANGE);
    /* a query, other packets, wrong lengths and NULL */
    assert_int_equal(tase_command_check_data(TASE_ID_SPOI_CMD, NULL, 0), TASE_OK);
    /* no query form: a zero-length GIMBAL_CMD or RETRACT_DEPLOY_CMD is no
     * command (a review: both passed and went out) */
    assert_int_equal(tase_command_check_data(TASE_ID_GIMBAL_CMD, NULL, 0), TASE_ELENGTH);
    assert_int_equal(tase_command_check_data(TASE_ID_RETRACT_DEPLOY_CMD, NULL, 0), TASE_ELENGTH);
    assert_int_equal(tase_command_check_data(TASE_ID_RETRACT_DEPLOY_CMD, data, 2), TASE_OK);
    assert_int_equal(tase_command_check_data(TASE_ID_SPOI_CMD, data, 18), TASE_ELENGTH);
    assert_int_equal(tase_command_check_data(TASE_ID_GIMBAL_CMD, NULL, 8), TASE_EARG);
    assert_int_equal(tase_command_check_data(TASE_ID_PACKET_RATE, data, 3), TASE_OK);
    assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, NULL), TASE_EARG);
    assert_int_equal(tase_command_check(TASE_ID_PACKET_RATE, &sp), TASE_OK);
}

/* tase_packet_init_keep(): the spec's "do not change" values (4.4.3:
 * 0xFF / 0xFFFF for AXIS_SETTING) and temporary 1, checked on the wire
 * bytes written by hand; the count of fields without such a value; for
 * every packet, against tase_field_get() and tase_field_is_keep(). */
static void init_keep_fills_a_packet_that_changes_nothing(void **state)
{
    tase_packet_msg_t m;
    uint8_t data[TASE_DATA_MAX];
    uint8_t want_axis[23];
    static const uint8_t want_rate[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1};
    size_t i;
    (void)state;
    memset(want_axis, 0xFF, sizeof want_axis);
    want_axis[13] = 0x00; /* reserved */
    want_axis[22] = 0x01; /* temporary: not stored */
    memset(&m, 0x5A, sizeof m);
    assert_int_equal(tase_packet_init_keep(TASE_ID_AXIS_SETTING, &m.axis_setting), 0);
    assert_int_equal(
        tase_packet_encode_data(TASE_ID_AXIS_SETTING, &m.axis_setting, data, sizeof data), 23);
    assert_memory_equal(data, want_axis, 23);
    /* PACKET_RATE: twelve rates with no such value (left 0), temporary 1 */
    memset(&m, 0x5A, sizeof m);
    assert_int_equal(tase_packet_init_keep(TASE_ID_PACKET_RATE, &m.packet_rate), 12);
    assert_int_equal(
        tase_packet_encode_data(TASE_ID_PACKET_RATE, &m.packet_rate, data, sizeof data), 16);
    assert_memory_equal(data, want_rate, 16);
    /* CAMERA_CMD: camera 0xFF, hfov -1, focus 0xFFFF, flags 0x80 ... */
    memset(&m, 0x5A, sizeof m);
    assert_true(tase_packet_init_keep(TASE_ID_CAMERA_CMD, &m.camera_cmd) >= 0);
    assert_int_equal(m.camera_cmd.camera, 0xFF);
    assert_int_equal(m.camera_cmd.hfov, -1);
    assert_int_equal(m.camera_cmd.focus, 0xFFFF);
    assert_int_equal(m.camera_cmd.flags & 0x80, 0x80);
    /* GIMBAL_CMD has none: all five fields zero */
    memset(&m, 0x5A, sizeof m);
    assert_int_equal(tase_packet_init_keep(TASE_ID_GIMBAL_CMD, &m.gimbal_cmd), 5);
    assert_int_equal(m.gimbal_cmd.pan, 0);
    assert_int_equal(m.gimbal_cmd.flags, 0);
    assert_int_equal(m.gimbal_cmd.impulse_time, 0);
    /* errors write nothing */
    memset(&m, 0x5A, sizeof m);
    assert_int_equal(tase_packet_init_keep(TASE_ID(0x7F, 0x7F), &m), TASE_EUNKNOWN);
    assert_int_equal(((const uint8_t *)&m)[0], 0x5A);
    assert_int_equal(tase_packet_init_keep(TASE_ID_AXIS_SETTING, NULL), TASE_EARG);
    /* every packet: each field is its keep value, or 0 and counted */
    for (i = 0; tase_schema_at(i) != NULL; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        int none = 0;
        int n;
        size_t k;
        memset(&m, 0x5A, sizeof m);
        n = tase_packet_init_keep(p->id, &m);
        assert_true(n >= 0);
        assert_int_equal(tase_packet_encode_data_len(p->id, &m, p->len, data, sizeof data),
                         (int)p->len);
        for (k = 0; k < p->nfields; k++) {
            int64_t v;
            int64_t keep;
            assert_int_equal(tase_field_get(p, k, data, p->len, &v), TASE_OK);
            if (tase_field_keep(p, k, &keep) == TASE_OK) {
                assert_true(tase_field_is_keep(p, k, v));
            } else if (v == 1 && (p->id == TASE_ID_PACKET_RATE || p->id == TASE_ID_AXIS_SETTING)) {
                /* temporary */
            } else {
                assert_true(v == 0);
                none++;
            }
        }
        assert_int_equal(n, none);
    }
}

/* A query (length 0) decodes to a zeroed struct, also for a packet whose
 * fields have "do not change" values (AXIS_SETTING); NULL data is an
 * argument error at any length above 0, also 1; a length above
 * TASE_DATA_MAX is refused like any wrong one, also for CAMERA_PASS,
 * which takes every length from 4 to TASE_DATA_MAX. */
static void queries_null_data_and_lengths_past_the_maximum(void **state)
{
    tase_axis_setting_t ax;
    tase_camera_pass_t cp;
    tase_packet_rate_t pr;
    uint8_t data[TASE_DATA_MAX + 2u];
    uint8_t out[TASE_FRAME_MAX];
    const tase_packet_desc_t *p = tase_schema_find(0x48, 0x00);
    size_t k;
    (void)state;
    memset(&ax, 0xA5, sizeof ax);
    assert_int_equal(tase_packet_decode_data(TASE_ID_AXIS_SETTING, NULL, 0, &ax), 0);
    for (k = 0; k < sizeof ax; k++) {
        assert_int_equal(((const uint8_t *)&ax)[k], 0);
    }
    memset(&pr, 0xA5, sizeof pr);
    assert_int_equal(tase_packet_decode_desc(p, NULL, 0, &pr), 0);
    assert_int_equal(pr.angle_1, 0);
    assert_int_equal(tase_packet_decode_data(TASE_ID_PACKET_RATE, NULL, 1, &pr), TASE_EARG);
    assert_int_equal(tase_packet_decode_desc(p, NULL, 1, &pr), TASE_EARG);
    assert_int_equal(tase_packet_encode_data_len(TASE_ID_SENSOR_FILTER, NULL, 1, out, sizeof out),
                     TASE_EARG);
    memset(&cp, 0, sizeof cp);
    cp.len = 1;
    assert_int_equal(tase_packet_encode_data(TASE_ID_CAMERA_PASS, &cp, out, sizeof out), TASE_EARG);
    /* codec.h's order: the tail's NULL data before the length given */
    assert_int_equal(tase_packet_encode_data_len(TASE_ID_CAMERA_PASS, &cp, 1, out, sizeof out),
                     TASE_EARG);

    memset(data, 0x11, sizeof data);
    assert_int_equal(tase_packet_decode_data(TASE_ID_CAMERA_PASS, data, TASE_DATA_MAX, &cp),
                     (int)TASE_DATA_MAX);
    for (k = TASE_DATA_MAX + 1u; k <= TASE_DATA_MAX + 2u; k++) {
        assert_int_equal(tase_packet_decode_data(TASE_ID_CAMERA_PASS, data, k, &cp), TASE_ELENGTH);
    }
    assert_int_equal(tase_packet_decode_data(TASE_ID_CAMERA_PASS, data, SIZE_MAX, &cp),
                     TASE_ELENGTH);
}

/* tase_packet_decode_iter(): the walk is restarted, so the same iterator
 * decodes the same struct again; NULL, a walk bound to no packet and NULL
 * data with a length are TASE_EARG. */
static void decode_iter_restarts_the_walk_and_checks_its_arguments(void **state)
{
    tase_field_iter_t it;
    tase_packet_rate_t a, b;
    tase_camera_cmd_t cam;
    uint8_t data[16];
    size_t k;
    (void)state;
    for (k = 0; k < sizeof data; k++) {
        data[k] = (uint8_t)(k + 1u);
    }
    assert_non_null(tase_field_iter_find(&it, 0x48, 0x00, sizeof data));
    memset(&a, 0xA5, sizeof a);
    memset(&b, 0x5A, sizeof b);
    assert_int_equal(tase_packet_decode_iter(&it, data, &a), 16);
    assert_int_equal(tase_packet_decode_iter(&it, data, &b), 16);
    assert_memory_equal(&a, &b, sizeof a);
    assert_int_equal(a.angle_1, 1);
    assert_int_equal(a.temporary, 16);
    assert_int_equal(tase_packet_decode_iter(&it, NULL, &a), TASE_EARG);
    assert_int_equal(tase_packet_decode_iter(NULL, data, &a), TASE_EARG);
    assert_null(tase_field_iter_find(&it, 0x48, 0x7F, 0));
    assert_int_equal(tase_packet_decode_iter(&it, NULL, &a), TASE_EARG);
    /* NULL data: a query decodes, the 1-byte form of CAMERA_CMD does not */
    assert_non_null(tase_field_iter_find(&it, 0x48, 0x00, 0));
    assert_int_equal(tase_packet_decode_iter(&it, NULL, &a), 0);
    assert_non_null(tase_field_iter_find(&it, 0x00, 0x41, 1));
    assert_true(it.accepted);
    assert_int_equal(tase_packet_decode_iter(&it, NULL, &cam), TASE_EARG);
}

/* codec.h: a length the packet does not accept is TASE_ELENGTH for every
 * decoder whatever msg is: msg NULL is allowed only for a zero-length
 * frame of a packet that has one (a query, GYRO_ZERO_CMD), so a
 * zero-length GIMBAL_CMD (no query form) is not decoded as one, and a
 * 7-byte one is not an argument error. tase_packet_decode_iter() gives
 * TASE_ELENGTH for a walk begun at such a length, msg unchanged. */
static void a_wrong_length_is_elength_with_or_without_a_struct(void **state)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x80); /* GIMBAL_CMD */
    tase_field_iter_t it;
    tase_gimbal_cmd_t cmd;
    tase_gimbal_cmd_t before;
    uint8_t data[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    tase_frame_t f = {0, 0x00, 0x80, 0, data};
    (void)state;
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, NULL, 0, NULL), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode_data(TASE_ID_GIMBAL_CMD, data, 7, NULL), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode_desc(p, NULL, 0, NULL), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode(&f, NULL), TASE_ELENGTH);
    f.len = 7;
    assert_int_equal(tase_packet_decode(&f, NULL), TASE_ELENGTH);

    memset(&cmd, 0x5A, sizeof cmd);
    before = cmd;
    assert_non_null(tase_field_iter_find(&it, 0x00, 0x80, 7));
    assert_false(it.accepted);
    assert_int_equal(tase_packet_decode_iter(&it, data, &cmd), TASE_ELENGTH);
    assert_int_equal(tase_packet_decode_iter(&it, data, NULL), TASE_ELENGTH);
    assert_memory_equal(&cmd, &before, sizeof cmd);
}

/* SPOI_CMD's limits are inclusive (90 and 180 degrees either way), and
 * each of the four bounds is checked on its own; tase_command_check_data()
 * refuses a 1-byte GIMBAL_CMD or SPOI_CMD as a wrong length. */
static void spoi_limits_are_inclusive_and_checked_one_by_one(void **state)
{
    static const int32_t lat[][2] = {
        {324000000, 1}, {-324000000, 1}, {324000001, 0}, {-324000001, 0}};
    static const int32_t lon[][2] = {
        {648000000, 1}, {-648000000, 1}, {648000001, 0}, {-648000001, 0}};
    tase_spoi_cmd_t sp;
    uint8_t data[TASE_DATA_MAX];
    size_t k;
    (void)state;
    for (k = 0; k < 4; k++) {
        memset(&sp, 0, sizeof sp);
        sp.lat = lat[k][0];
        assert_int_equal(tase_command_check(TASE_ID_SPOI_CMD, &sp),
                         lat[k][1] ? TASE_OK : TASE_ERANGE);
        memset(&sp, 0, sizeof sp);
        sp.lon = lon[k][0];
        assert_int_equal(tase_command_check(TASE_ID_SPOI_CMD, &sp),
                         lon[k][1] ? TASE_OK : TASE_ERANGE);
    }
    memset(data, 0, sizeof data);
    assert_int_equal(tase_command_check_data(TASE_ID_SPOI_CMD, data, 1), TASE_ELENGTH);
    assert_int_equal(tase_command_check_data(TASE_ID_GIMBAL_CMD, data, 1), TASE_ELENGTH);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(codec_api_rejects_bad_arguments),
        cmocka_unit_test(unknown_ids_and_missing_structs_are_told_apart_from_missing_buffers),
        cmocka_unit_test(gimbal_cmd_extremes_encode_to_hand_computed_frame),
        cmocka_unit_test(gyro_zero_and_camera_short_forms_encode_to_hand_computed_frames),
        cmocka_unit_test(gimbal_angle_encodes_to_hand_computed_frame),
        cmocka_unit_test(spoi_full_and_query_forms_encode_to_hand_computed_frames),
        cmocka_unit_test(axis_setting_leaves_byte_13_reserved_zero),
        cmocka_unit_test(axis_setting_22_byte_layout_decodes_and_encodes_to_hand_computed_frames),
        cmocka_unit_test(every_packet_round_trips_random_and_extreme_values),
        cmocka_unit_test(every_query_capable_packet_encodes_an_eight_byte_query),
        cmocka_unit_test(every_wrong_length_is_rejected_on_decode_and_encode),
        cmocka_unit_test(argument_errors_are_reported_and_write_nothing),
        cmocka_unit_test(camera_pass_carries_249_bytes_and_may_be_encoded_in_place),
        cmocka_unit_test(camera_bytes_anywhere_in_the_output_encode_the_same),
        cmocka_unit_test(data_only_codec_matches_the_frame_codec_for_every_packet),
        cmocka_unit_test(data_only_codec_rejects_bad_arguments),
        cmocka_unit_test(command_check_takes_what_the_spec_defines_and_nothing_else),
        cmocka_unit_test(init_keep_fills_a_packet_that_changes_nothing),
        cmocka_unit_test(queries_null_data_and_lengths_past_the_maximum),
        cmocka_unit_test(decode_iter_restarts_the_walk_and_checks_its_arguments),
        cmocka_unit_test(a_wrong_length_is_elength_with_or_without_a_struct),
        cmocka_unit_test(spoi_limits_are_inclusive_and_checked_one_by_one),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
