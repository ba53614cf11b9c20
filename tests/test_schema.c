/* Tests of the schema table: checked against an independent transcription
 * of the spec's tables (section 4), structural invariants, O(1) lookup,
 * accepted lengths, raw field access and names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/codec.h"
#include "tase/schema.h"

/* The spec, transcribed by hand from section 4 (not from the code):
 * "NAME group type dir len forms : field@offset<s|u><width> ...".
 * dir: I(n), O(ut), B(oth). forms: - none, Q zero-length query, 1 the
 * one-byte form, T trailing bytes, S the short layout (one byte less).
 * Reserved rows are not listed; offsets are the table's. */
static const char *const spec[] = {
    "GIMBAL_CMD 00 80 I 8 - : pan@0s2 tilt@2s2 roll@4s2 flags@6u1 impulse_time@7u1",
    "GYRO_ZERO_CMD 00 40 I 0 - :",
    "CAMERA_CMD 00 41 I 10 1 : camera@0u1 hfov@2s2 focus@4u2 exposure@6u1 "
    "shutter_speed@7u1 bright@8u1 flags@9u1",
    "LEGACY_CAMERA_CMD 00 81 I 8 - : zoom@0u2 focus@2u2 auto_exposure@4u1 "
    "shutter_speed@5u1 iris@6u1 gain@7u1",
    "CAMERA_PASS 00 42 B 4 T : camera@0u1 baud@1u1",
    "RETRACT_DEPLOY_CMD 00 43 B 2 - : deploy@0u1",
    "GIMBAL_ANGLE 08 10 O 6 - : pan@0s2 tilt@2s2 roll@4s2",
    "GIMBAL_RATE 08 40 O 18 - : time@0u4 pan_rate@4s2 tilt_rate@6s2 roll_rate@8s2 "
    "p@10s2 q@12s2 r@14s2 mode@17u1",
    "HOST_SENSOR 08 41 I 20 - : time@0u4 roll@4s2 pitch@6s2 yaw@8s2 flags@10u1 "
    "sample_rate@11u1 x_accel@12s2 y_accel@14s2 z_accel@16s2 tas@18u2",
    "HOST_ATTITUDE 08 42 I 12 - : time@0u4 roll@4s2 pitch@6s2 yaw@8s2 flags@10u1 "
    "sample_rate@11u1",
    "HOST_GPS_DATA 10 10 I 32 - : time@0u4 lat@4s4 lon@8s4 height@12s4 vnorth@16s2 "
    "veast@18s2 vdown@20s2 year@22u2 month@24u1 day@25u1 hour@26u1 minute@27u1 "
    "second@28u1 frac_second@29u1 valid@30u1 sample_rate@31u1",
    "SPOI_CMD 10 40 B 19 Q : lat@0s4 lon@4s4 height@8s4 vnorth@12s2 veast@14s2 "
    "vdown@16s2 flags@18u1",
    "GEOREFERENCE_DATA 10 41 O 63 - : time@0u4 lat@4s4 lon@8s4 height@12s4 "
    "vnorth@16s2 veast@18s2 vdown@20s2 year@22u2 month@24u1 day@25u1 hour@26u1 "
    "minute@27u1 second@28u1 frac_second@29u1 num_sats@30u1 pdop@31u1 status@32u2 "
    "camera_roll@34s2 camera_pitch@36s2 camera_yaw@38s2 hfov@40u2 vfov@42u2 "
    "focal@44u2 mode@46u1 sample_rate@47u1 nav_health@48u2 mount_roll@50s2 "
    "mount_pitch@52s2 mount_yaw@54s2 pan@56s2 tilt@58s2 roll@60s2 camera@62u1",
    "PACKET_RATE 48 00 B 16 Q : angle_1@0u1 rate_1@1u1 geo_ref_1@2u1 camera_1@3u1 "
    "angle_2@5u1 rate_2@6u1 geo_ref_2@7u1 camera_2@8u1 angle_3@10u1 rate_3@11u1 "
    "geo_ref_3@12u1 camera_3@13u1 temporary@15u1",
    "SENSOR_FILTER 48 01 B 2 Q : cutoff@0u1 decimation@1u1",
    "AXIS_SETTING 48 02 B 23 QS : pan_nogo_center@0s2 pan_nogo_range@2u2 "
    "tilt_nogo_center@4s2 tilt_nogo_range@6u2 roll_nogo_center@8s2 "
    "roll_nogo_range@10u2 pan_max_rate@12u1 tilt_max_rate@14u1 roll_max_rate@15u1 "
    "pan_max_accel@16u1 tilt_max_accel@17u1 roll_max_accel@18u1 pan_pos_gain@19u1 "
    "tilt_pos_gain@20u1 roll_pos_gain@21u1 temporary@22u1",
    "SYSTEM_VERSION 48 03 B 42 Q : major@0u1 minor@1u1 sub@2u1 released@3u1 "
    "soft_year@4u2 soft_month@6u1 soft_day@7u1 board_sn@8u4 board_rev@12u4 "
    "board_config@16u4 board_year@20u2 board_month@22u1 board_day@23u1 camera_a@24u1 "
    "max_hfov_a@26u2 min_hfov_a@28u2 camera_b@30u1 max_hfov_b@32u2 min_hfov_b@34u2 "
    "camera_c@36u1 max_hfov_c@38u2 min_hfov_c@40u2",
    "NAV_SOURCE 48 04 B 2 Q : external_attitude@0u1 external_gps@1u1",
    "CAMERA_TYPE 48 05 B 3 Q : camera_a@0u1 camera_b@1u1 camera_c@2u1",
    "GPS_LEVER_ARM 48 06 B 6 Q : x@0s2 y@2s2 z@4s2",
    "CAMERA_ALIGN 48 07 B 16 Q : zoom_1@0u2 pan_err_1@2s2 tilt_err_1@4s2 "
    "roll_err_1@6s2 zoom_2@8u2 pan_err_2@10s2 tilt_err_2@12s2 roll_err_2@14s2",
};

/* Reserved bytes per packet in the spec's tables (same order). */
static const unsigned reserved[] = {0, 0, 1, 0, 2, 1, 0, 1, 0, 0, 0, 0, 0, 3, 0, 1, 3, 0, 0, 0, 0};

static void schema_matches_spec_transcription(void **state)
{
    size_t i;
    (void)state;
    assert_int_equal(sizeof(spec) / sizeof(spec[0]), TASE_PKT_COUNT);
    assert_int_equal(TASE_PKT_COUNT, TASE_PACKET_COUNT);
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        char name[32], dir[4], forms[4];
        unsigned g, t, len, nf = 0;
        int used = 0;
        const char *rest;
        const tase_packet_desc_t *p = tase_schema_at(i);
        unsigned want_flags;
        assert_non_null(p);
        assert_int_equal(p->index, i);
        assert_int_equal(
            sscanf(spec[i], "%31s %x %x %3s %u %3s :%n", name, &g, &t, dir, &len, forms, &used), 6);
        assert_string_equal(tase_schema_packet_name(p), name);
        assert_int_equal(p->id, TASE_ID(g, t));
        assert_int_equal(p->len, len);
        want_flags = dir[0] == 'I' ? TASE_DIR_IN : dir[0] == 'O' ? TASE_DIR_OUT : TASE_DIR_BOTH;
        for (nf = 0; forms[nf] != '\0'; nf++) {
            want_flags |= forms[nf] == 'Q'   ? TASE_LEN_QUERY
                          : forms[nf] == '1' ? TASE_LEN_SHORT1
                          : forms[nf] == 'T' ? TASE_LEN_TAIL
                          : forms[nf] == 'S' ? TASE_LEN_SHORT
                                             : 0u;
        }
        nf = 0;
        assert_int_equal(p->flags, want_flags);
        rest = spec[i] + used;
        while (*rest != '\0') {
            char fname[32], sign;
            unsigned off, width;
            int n = 0;
            const tase_field_t *f = tase_schema_field(p, nf);
            assert_int_equal(sscanf(rest, " %31[a-z0-9_]@%u%c%u%n", fname, &off, &sign, &width, &n),
                             4);
            assert_non_null(f);
            assert_string_equal(tase_schema_field_name(p, nf), fname);
            assert_int_equal(f->offset, off);
            assert_int_equal(TASE_FIELD_WIDTH(f), width);
            assert_int_equal(TASE_FIELD_IS_SIGNED(f), sign == 's');
            rest += n;
            nf++;
        }
        assert_int_equal(p->nfields, nf);
        assert_null(tase_schema_field(p, nf));
    }
    assert_null(tase_schema_at(TASE_PKT_COUNT));
}

static void fields_are_in_range_ordered_disjoint_and_cover_all_but_reserved(void **state)
{
    size_t i, k;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        unsigned sum = 0, end = 0;
        for (k = 0; k < p->nfields; k++) {
            const tase_field_t *f = tase_schema_field(p, k);
            unsigned w = TASE_FIELD_WIDTH(f);
            assert_true(w == 1 || w == 2 || w == 4 || w == 8);
            assert_true(f->offset >= end); /* table order, no overlap */
            end = f->offset + w;
            assert_true(end <= p->len);
            assert_true(f->member + w <= p->size);
            sum += w;
        }
        assert_int_equal(sum + reserved[i], p->len);
        assert_true(p->len <= TASE_DATA_MAX);
    }
}

/* White-box: the member of each field has the field's width, signedness
 * and offset. Generated from the private list the schema is built from. */
static void struct_members_match_field_width_sign_and_offset(void **state)
{
    (void)state;
#define P(N, g, t, fl, l, sz)                                                                      \
    {                                                                                              \
        const tase_packet_desc_t *p = tase_schema_at(TASE_PKT_##N);                                \
        size_t k = 0;
#define F(T, m, o, w, s, keep)                                                                     \
    {                                                                                              \
        T x;                                                                                       \
        const tase_field_t *f = tase_schema_field(p, k++);                                         \
        memset(&x, 0, sizeof(x));                                                                  \
        x.m = 0;                                                                                   \
        x.m--; /* -1 if signed, the maximum if unsigned */                                         \
        assert_non_null(f);                                                                        \
        assert_int_equal(sizeof(x.m), w);                                                          \
        assert_int_equal(f->member, offsetof(T, m));                                               \
        assert_int_equal(TASE_FIELD_IS_SIGNED(f), !(x.m > 0));                                     \
        assert_string_equal(tase_schema_field_name(p, k - 1), #m);                                 \
    }
#define E(N)                                                                                       \
    assert_int_equal(k, p->nfields);                                                               \
    }
#include "../src/tase_schema_def.h"
#undef P
#undef F
#undef E
}

static int is_spec_packet(unsigned g, unsigned t)
{
    size_t i;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        unsigned sg, st;
        assert_int_equal(sscanf(spec[i], "%*s %x %x", &sg, &st), 2);
        if (sg == g && st == t) {
            return (int)i;
        }
    }
    return -1;
}

static void lookup_finds_exactly_the_spec_packets_among_all_65536_ids(void **state)
{
    unsigned g, t;
    (void)state;
    for (g = 0; g < 256; g++) {
        for (t = 0; t < 256; t++) {
            const tase_packet_desc_t *p = tase_schema_find((uint8_t)g, (uint8_t)t);
            int want = is_spec_packet(g, t);
            if (want < 0) {
                assert_null(p);
            } else {
                assert_non_null(p);
                assert_int_equal(p->index, want);
                assert_int_equal(p->id, TASE_ID(g, t));
            }
        }
    }
    assert_null(tase_schema_find(TASE_GROUP_STATUS, 0x00));
}

static void accepted_lengths_follow_the_spec_rules(void **state)
{
    size_t i, len;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        const char *name = tase_schema_packet_name(p);
        int setup = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP;
        for (len = 0; len <= 300; len++) {
            int want = len == p->len;
            if (len == 0 && (setup || strcmp(name, "SPOI_CMD") == 0)) {
                want = 1; /* zero-length query form */
            }
            if (strcmp(name, "CAMERA_CMD") == 0 && len == 1) {
                want = 1;
            }
            if (strcmp(name, "AXIS_SETTING") == 0 && len == 22) {
                want = 1; /* table 22 read as a numbering slip (S2) */
            }
            if (strcmp(name, "CAMERA_PASS") == 0) {
                want = len >= 4 && len <= 4 + 249;
            }
            assert_int_equal(tase_schema_length_ok(p, len), want);
            assert_int_equal(tase_schema_is_query(p, len),
                             len == 0 && want && strcmp(name, "GYRO_ZERO_CMD") != 0);
        }
    }
    assert_false(tase_schema_length_ok(NULL, 0));
    assert_false(tase_schema_is_query(NULL, 0));
}

/* The flags bits the spec reserves in what goes to the gimbal, from the
 * spec's tables by hand (4.1.3 bits 1-4, 4.2.3 bits 3-7, 4.2.4 bits 0-5,
 * 4.3.2 "bits 1-7" to the gimbal); each lies in a 1-byte `flags` field of
 * its packet. The tool and the Python link read them here (they kept a
 * table each before). */
static void reserved_flags_are_the_specs(void **state)
{
    size_t i;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        const char *name = tase_schema_packet_name(p);
        unsigned want = 0;
        unsigned got = tase_schema_reserved_flags(p);
        if (strcmp(name, "CAMERA_CMD") == 0) {
            want = 0x78;
        } else if (strcmp(name, "HOST_SENSOR") == 0) {
            want = 0x1F;
        } else if (strcmp(name, "HOST_ATTITUDE") == 0) {
            want = 0xFC;
        } else if (strcmp(name, "SPOI_CMD") == 0) {
            want = 0x7F;
        }
        assert_int_equal(got, want);
        if (want != 0) {
            int fi = tase_schema_field_index(p, "flags");
            assert_true(fi >= 0);
            assert_int_equal(TASE_FIELD_WIDTH(tase_schema_field(p, (size_t)fi)), 1u);
            assert_true((p->flags & TASE_DIR_IN) != 0u);
        }
    }
    assert_int_equal(tase_schema_reserved_flags(NULL), 0);
}

/* Table 22 read with row "14" as byte 13 and every later row one less:
 * transcribed by hand, not from the code. */
static const char *const axis22 =
    "pan_nogo_center@0 pan_nogo_range@2 tilt_nogo_center@4 tilt_nogo_range@6 "
    "roll_nogo_center@8 roll_nogo_range@10 pan_max_rate@12 tilt_max_rate@13 "
    "roll_max_rate@14 pan_max_accel@15 tilt_max_accel@16 roll_max_accel@17 "
    "pan_pos_gain@18 tilt_pos_gain@19 roll_pos_gain@20 temporary@21";

static void only_axis_setting_has_a_short_layout_and_its_offsets_are_table_22s(void **state)
{
    size_t i, k;
    const char *rest = axis22;
    const tase_packet_desc_t *axis = tase_schema_find(0x48, 0x02);
    uint8_t d[23];
    int64_t v;
    (void)state;
    for (k = 0; *rest != '\0'; k++) {
        char fname[32];
        unsigned off;
        int n = 0;
        assert_int_equal(sscanf(rest, " %31[a-z_]@%u%n", fname, &off, &n), 2);
        assert_string_equal(tase_schema_field_name(axis, k), fname);
        assert_int_equal(tase_field_offset(axis, k, 22), (int)off);
        assert_int_equal(tase_field_offset(axis, k, 23), tase_schema_field(axis, k)->offset);
        rest += n;
    }
    assert_int_equal(k, axis->nfields);
    /* every other packet has one layout whatever the length */
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        size_t len;
        if (p == axis) {
            continue;
        }
        assert_int_equal(p->flags & TASE_LEN_SHORT, 0);
        for (k = 0; k < p->nfields; k++) {
            for (len = 0; len <= TASE_DATA_MAX; len++) {
                assert_int_equal(tase_field_offset(p, k, len), tase_schema_field(p, k)->offset);
            }
        }
    }
    /* tase_field_get reads the layout the length selects */
    memset(d, 0, sizeof(d));
    d[13] = 0x3C;
    d[21] = 0x01;
    assert_int_equal(tase_field_get(axis, 7, d, 22, &v), TASE_OK); /* tilt_max_rate */
    assert_true(v == 0x3C);
    assert_int_equal(tase_field_get(axis, 15, d, 22, &v), TASE_OK); /* temporary */
    assert_true(v == 1);
    assert_int_equal(tase_field_get(axis, 7, d, 23, &v), TASE_OK); /* byte 14 */
    assert_true(v == 0);
    assert_int_equal(tase_field_offset(NULL, 0, 22), TASE_EARG);
    assert_int_equal(tase_field_offset(axis, axis->nfields, 22), TASE_EARG);
    assert_int_equal(tase_field_offset(axis, SIZE_MAX, 22), TASE_EARG);
}

static void field_get_sign_extends_signed_fields_only(void **state)
{
    const tase_packet_desc_t *gps = tase_schema_find(0x10, 0x10);
    const tase_packet_desc_t *sensor = tase_schema_find(0x08, 0x41);
    uint8_t d[32];
    int64_t v = 12345;
    (void)state;
    memset(d, 0, sizeof(d));
    d[0] = 0xFF;
    d[1] = 0xFF;
    d[2] = 0xFF;
    d[3] = 0xFF; /* time: u32 */
    d[4] = 0x80; /* lat: INT32_MIN */
    d[8] = 0x7F;
    d[9] = 0xFF;
    d[10] = 0xFF;
    d[11] = 0xFF; /* lon: INT32_MAX */
    d[16] = 0x80;
    d[17] = 0x00; /* vnorth: INT16_MIN */
    d[18] = 0xFF;
    d[19] = 0xFE; /* veast: -2 */
    d[22] = 0xFF;
    d[23] = 0xFF; /* year: u16 65535 */
    assert_int_equal(tase_field_get(gps, 0, d, 32, &v), TASE_OK);
    assert_true(v == 0xFFFFFFFFll);
    assert_int_equal(tase_field_get(gps, 1, d, 32, &v), TASE_OK);
    assert_true(v == INT32_MIN);
    assert_int_equal(tase_field_get(gps, 2, d, 32, &v), TASE_OK);
    assert_true(v == INT32_MAX);
    assert_int_equal(tase_field_get(gps, 4, d, 32, &v), TASE_OK);
    assert_true(v == INT16_MIN);
    assert_int_equal(tase_field_get(gps, 5, d, 32, &v), TASE_OK);
    assert_true(v == -2);
    assert_int_equal(tase_field_get(gps, 7, d, 32, &v), TASE_OK);
    assert_true(v == 65535);
    /* HOST_SENSOR tas (field 9, bytes 18-19, unsigned) */
    d[18] = 0xFF;
    d[19] = 0xFF;
    assert_int_equal(tase_field_get(sensor, 9, d, 20, &v), TASE_OK);
    assert_true(v == 0xFFFF);
    assert_int_equal(tase_field_get(sensor, 8, d, 20, &v), TASE_OK); /* z_accel 16-17 */
    assert_true(v == INT16_MIN);
    /* errors leave *value alone */
    v = 99;
    assert_int_equal(tase_field_get(gps, 15, d, 31, &v), TASE_ETRUNC);
    assert_int_equal(tase_field_get(gps, 0, d, 0, &v), TASE_ETRUNC);
    assert_int_equal(tase_field_get(gps, 16, d, 32, &v), TASE_EARG);
    assert_int_equal(tase_field_get(NULL, 0, d, 32, &v), TASE_EARG);
    assert_int_equal(tase_field_get(gps, 0, NULL, 32, &v), TASE_EARG);
    assert_int_equal(tase_field_get(gps, 0, d, 32, NULL), TASE_EARG);
    assert_true(v == 99);
}

/* Every "do not change" value of the spec, transcribed by hand from its
 * sentences (4.1.3 tables 6, 4.1.4 table 7, 4.1.5 table 8, 4.4.3 and 4.4.6;
 * see docs/PROTOCOL-NOTES.md K1). Every other field has none. */
static const struct {
    const char *packet;
    const char *field;
    int64_t keep;
} keeps[] = {
    {"CAMERA_CMD", "camera", 0xFF},
    {"CAMERA_CMD", "hfov", -1}, /* "0xFFFF (-1) means do not change" */
    {"CAMERA_CMD", "focus", 0xFFFF},
    {"CAMERA_CMD", "exposure", 0xFF},
    {"CAMERA_CMD", "shutter_speed", 0xFF},
    {"CAMERA_CMD", "bright", 0xFF},
    {"CAMERA_CMD", "flags", 0x80}, /* MSB: any value with it set */
    {"LEGACY_CAMERA_CMD", "focus", 0xFFFF},
    {"LEGACY_CAMERA_CMD", "shutter_speed", 0xFF},
    {"CAMERA_PASS", "baud", 0},
    {"AXIS_SETTING", "pan_nogo_center", -1},
    {"AXIS_SETTING", "pan_nogo_range", 0xFFFF},
    {"AXIS_SETTING", "tilt_nogo_center", -1},
    {"AXIS_SETTING", "tilt_nogo_range", 0xFFFF},
    {"AXIS_SETTING", "roll_nogo_center", -1},
    {"AXIS_SETTING", "roll_nogo_range", 0xFFFF},
    {"AXIS_SETTING", "pan_max_rate", 0xFF},
    {"AXIS_SETTING", "tilt_max_rate", 0xFF},
    {"AXIS_SETTING", "roll_max_rate", 0xFF},
    {"AXIS_SETTING", "pan_max_accel", 0xFF},
    {"AXIS_SETTING", "tilt_max_accel", 0xFF},
    {"AXIS_SETTING", "roll_max_accel", 0xFF},
    {"AXIS_SETTING", "pan_pos_gain", 0xFF},
    {"AXIS_SETTING", "tilt_pos_gain", 0xFF},
    {"AXIS_SETTING", "roll_pos_gain", 0xFF},
    {"CAMERA_TYPE", "camera_a", 0},
    {"CAMERA_TYPE", "camera_b", 0},
    {"CAMERA_TYPE", "camera_c", 0},
};

static int keep_row(const char *packet, const char *field)
{
    size_t k;
    for (k = 0; k < sizeof(keeps) / sizeof(keeps[0]); k++) {
        if (strcmp(keeps[k].packet, packet) == 0 && strcmp(keeps[k].field, field) == 0) {
            return (int)k;
        }
    }
    return -1;
}

static void keep_values_are_exactly_the_specs(void **state)
{
    size_t i, k, found = 0;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (k = 0; k < p->nfields; k++) {
            int row = keep_row(tase_schema_packet_name(p), tase_schema_field_name(p, k));
            int64_t v = 12345;
            if (row < 0) {
                assert_int_equal(tase_field_keep(p, k, &v), TASE_EUNKNOWN);
                assert_true(v == 12345);
                assert_false(tase_field_is_keep(p, k, 0));
                assert_false(tase_field_is_keep(p, k, -1));
                assert_false(tase_field_is_keep(p, k, 0xFF));
                assert_false(tase_field_is_keep(p, k, 0x80));
                continue;
            }
            found++;
            assert_int_equal(tase_field_keep(p, k, &v), TASE_OK);
            assert_true(v == keeps[row].keep);
            assert_true(tase_field_is_keep(p, k, v));
            /* its neighbours are ordinary values (0x7F for the flags byte) */
            assert_false(tase_field_is_keep(p, k, v - 1));
            if (v != 0x80) {
                assert_false(tase_field_is_keep(p, k, v + 1));
            }
        }
    }
    assert_int_equal(found, sizeof(keeps) / sizeof(keeps[0]));
}

static void camera_flags_with_the_msb_set_all_mean_no_change(void **state)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x41);
    int flags = tase_schema_field_index(p, "flags");
    int64_t v;
    (void)state;
    assert_true(flags >= 0);
    for (v = -300; v < 0x200; v++) {
        assert_int_equal(tase_field_is_keep(p, (size_t)flags, v), v >= 0x80 && v <= 0xFF);
    }
    /* the other camera fields: only their one value */
    assert_false(tase_field_is_keep(p, 0, 0x1FF)); /* camera: out of range */
    assert_true(tase_field_is_keep(p, 0, 0xFF));
    assert_false(tase_field_is_keep(p, 1, 0xFFFF)); /* hfov is signed: -1 */
}

static void keep_api_rejects_bad_arguments(void **state)
{
    const tase_packet_desc_t *p = tase_schema_find(0x48, 0x02);
    tase_packet_desc_t forged;
    int64_t v = 77;
    (void)state;
    assert_int_equal(tase_field_keep(NULL, 0, &v), TASE_EARG);
    assert_int_equal(tase_field_keep(p, p->nfields, &v), TASE_EARG);
    assert_int_equal(tase_field_keep(p, SIZE_MAX, &v), TASE_EARG);
    assert_int_equal(tase_field_keep(p, 0, NULL), TASE_EARG);
    assert_true(v == 77);
    assert_false(tase_field_is_keep(NULL, 0, -1));
    assert_false(tase_field_is_keep(p, p->nfields, 0xFF));
    assert_false(tase_field_is_keep(p, SIZE_MAX, 0xFF));
    forged = *p;
    forged.first_field = 255;
    assert_int_equal(tase_field_keep(&forged, 0, &v), TASE_EARG);
    assert_false(tase_field_is_keep(&forged, 0, -1));
}

static void names_resolve_both_ways_and_reject_unknown(void **state)
{
    size_t i, k;
    (void)state;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        assert_ptr_equal(tase_schema_find_name(tase_schema_packet_name(p)), p);
        for (k = 0; k < p->nfields; k++) {
            assert_int_equal(tase_schema_field_index(p, tase_schema_field_name(p, k)), (int)k);
        }
    }
    assert_string_equal(tase_schema_packet_name(tase_schema_find(0x08, 0x40)), "GIMBAL_RATE");
    assert_null(tase_schema_find_name("GIMBAL_TELEMETRY"));
    assert_null(tase_schema_find_name("gimbal_cmd"));
    assert_null(tase_schema_find_name(NULL));
    assert_null(tase_schema_packet_name(NULL));
    assert_null(tase_schema_field_name(NULL, 0));
    assert_null(tase_schema_field_name(tase_schema_at(0), 5));
    assert_int_equal(tase_schema_field_index(tase_schema_at(0), "Pan"), TASE_EUNKNOWN);
    assert_int_equal(tase_schema_field_index(NULL, "pan"), TASE_EARG);
    assert_int_equal(tase_schema_field_index(tase_schema_at(0), NULL), TASE_EARG);
    assert_null(tase_schema_field(NULL, 0));
}

/* Bad arguments of schema.h give NULL / false / their documented codes,
 * and a corrupted copy of a descriptor (fields running off the table, an
 * index out of range) is never used to index the ROM tables. */
static void schema_api_rejects_bad_arguments(void **state)
{
    const tase_packet_desc_t *p = tase_schema_at(TASE_PKT_COUNT - 1u);
    tase_packet_desc_t forged;
    uint8_t data[TASE_DATA_MAX] = {0};
    int64_t v = 77;
    (void)state;

    assert_non_null(p);
    assert_null(tase_schema_at(TASE_PKT_COUNT));
    assert_null(tase_schema_at(SIZE_MAX));
    assert_null(tase_schema_field(NULL, 0));
    assert_null(tase_schema_field(p, p->nfields));
    assert_null(tase_schema_field(p, SIZE_MAX));
    assert_false(tase_schema_length_ok(NULL, 0));
    assert_false(tase_schema_length_ok(p, SIZE_MAX));
    assert_false(tase_schema_is_query(NULL, 0));
    assert_int_equal(tase_field_get(NULL, 0, data, sizeof data, &v), TASE_EARG);
    assert_int_equal(tase_field_get(p, p->nfields, data, sizeof data, &v), TASE_EARG);
    assert_int_equal(tase_field_get(p, SIZE_MAX, data, sizeof data, &v), TASE_EARG);
    assert_int_equal(tase_field_get(p, 0, NULL, SIZE_MAX, &v), TASE_EARG);
    assert_int_equal(tase_field_get(p, 0, data, sizeof data, NULL), TASE_EARG);
    assert_int_equal(tase_field_get(p, 0, NULL, 0, &v), TASE_ETRUNC);
    assert_int_equal(tase_field_get(p, 0, data, 1, &v), TASE_ETRUNC);
    assert_int_equal(v, 77);

    assert_null(tase_schema_packet_name(NULL));
    assert_null(tase_schema_field_name(NULL, 0));
    assert_null(tase_schema_field_name(p, SIZE_MAX));
    assert_null(tase_schema_find_name(NULL));
    assert_null(tase_schema_find_name(""));
    assert_int_equal(tase_schema_field_index(NULL, "pan"), TASE_EARG);
    assert_int_equal(tase_schema_field_index(p, NULL), TASE_EARG);
    assert_int_equal(tase_schema_field_index(p, "no_such_field"), TASE_EUNKNOWN);

    forged = *p;
    forged.first_field = 255; /* the table has fewer than 256 fields */
    forged.nfields = 200;
    assert_null(tase_schema_field(&forged, 0));
    assert_null(tase_schema_field_name(&forged, 0));
    assert_int_equal(tase_schema_field_index(&forged, "zoom_1"), TASE_EUNKNOWN);
    assert_int_equal(tase_field_get(&forged, 0, data, sizeof data, &v), TASE_EARG);
    assert_int_equal(v, 77);
    forged.index = 200;
    assert_null(tase_schema_packet_name(&forged));
}

/* The field walk (tase_field_iter_t) visits every field of every packet in
 * order, at every data length 0..TASE_DATA_MAX, with the same descriptor,
 * offset (layout applied), width, "within" and value as the by-index
 * functions, and says whether the length is accepted as
 * tase_schema_length_ok() does; tase_field_iter_find() and _init() agree;
 * seek() moves to a field as next() would; begin() restarts a walk. */
static void the_field_walk_agrees_with_the_by_index_functions(void **state)
{
    uint8_t data[TASE_DATA_MAX];
    size_t i, len, k;
    (void)state;
    for (k = 0; k < sizeof data; k++) {
        data[k] = (uint8_t)(0x9Bu * k + 0x41u); /* sign bits set and clear */
    }
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        tase_field_iter_t it, by_id;
        for (len = 0; len <= TASE_DATA_MAX + 1u; len++) {
            assert_int_equal(tase_field_iter_init(&it, p, len), TASE_OK);
            assert_ptr_equal(
                tase_field_iter_find(&by_id, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), len), p);
            assert_ptr_equal(it.packet, p);
            assert_null(it.field);
            assert_int_equal(it.len, len);
            assert_int_equal(it.accepted, tase_schema_length_ok(p, len));
            assert_int_equal(by_id.accepted, it.accepted);
            k = 0;
            while (tase_field_iter_next(&it)) {
                const tase_field_t *f = tase_schema_field(p, k);
                int off = tase_field_offset(p, k, len);
                int64_t a = 1, b = 2;
                int ra, rb;
                assert_true(tase_field_iter_next(&by_id));
                assert_ptr_equal(by_id.field, it.field);
                assert_ptr_equal(it.field, f);
                assert_int_equal(it.index, k);
                assert_int_equal(it.width, TASE_FIELD_WIDTH(f));
                assert_int_equal((int)it.offset, off);
                assert_int_equal(it.within, (size_t)off + it.width <= len);
                ra = tase_field_iter_get(&it, data, &a);
                rb = tase_field_get(p, k, data, len <= TASE_DATA_MAX ? len : 0u, &b);
                if (len <= TASE_DATA_MAX) {
                    assert_int_equal(ra, rb);
                    if (ra == TASE_OK) {
                        assert_true(a == b);
                    }
                }
                assert_int_equal(ra, it.within ? TASE_OK : TASE_ETRUNC);
                k++;
            }
            assert_int_equal(k, p->nfields);
            assert_false(tase_field_iter_next(&it)); /* stays at the end */
            assert_false(tase_field_iter_next(&by_id));
            /* seek: the same field as the walk; out of range changes nothing */
            for (k = p->nfields; k-- > 0;) {
                assert_true(tase_field_iter_seek(&it, k));
                assert_ptr_equal(it.field, tase_schema_field(p, k));
                assert_int_equal((int)it.offset, tase_field_offset(p, k, len));
            }
            k = it.index;
            assert_false(tase_field_iter_seek(&it, p->nfields));
            assert_false(tase_field_iter_seek(&it, SIZE_MAX));
            assert_int_equal(it.index, k);
            /* begin: the same packet anew at another length */
            assert_int_equal(tase_field_iter_begin(&it, p->len), true);
            assert_null(it.field);
            assert_int_equal(it.len, p->len);
        }
        /* the table length, whatever it is */
        assert_int_equal(tase_field_iter_init(&it, p, TASE_FIELD_ITER_TABLE_LEN), TASE_OK);
        assert_int_equal(it.len, p->len);
        assert_true(it.accepted);
        while (tase_field_iter_next(&it)) {
            assert_true(it.within);
            assert_int_equal(it.offset, tase_schema_field(p, it.index)->offset);
        }
    }
}

/* AXIS_SETTING's 22-byte layout and CAMERA_CMD's 1-byte form in a walk:
 * shifted fields one byte earlier, fields the short form leaves out not
 * within it, with their "do not change" bits at hand. */
static void the_field_walk_applies_the_layout_and_the_keep_bits(void **state)
{
    tase_field_iter_t it;
    uint32_t bits = 0;
    unsigned within = 0;
    (void)state;
    assert_non_null(tase_field_iter_find(&it, TASE_ID_GROUP(TASE_ID_AXIS_SETTING),
                                         TASE_ID_TYPE(TASE_ID_AXIS_SETTING), 22));
    assert_true(it.accepted);
    assert_true(tase_field_iter_seek(&it, 7)); /* tilt_max_rate: 14 in the table */
    assert_int_equal(it.offset, 13);
    assert_int_equal(tase_field_iter_begin(&it, 23), true);
    assert_true(tase_field_iter_seek(&it, 7));
    assert_int_equal(it.offset, 14);
    assert_int_equal(tase_field_iter_begin(&it, 21), false); /* refused; still walks */
    assert_true(tase_field_iter_next(&it));

    assert_non_null(tase_field_iter_find(&it, TASE_ID_GROUP(TASE_ID_CAMERA_CMD),
                                         TASE_ID_TYPE(TASE_ID_CAMERA_CMD), 1));
    assert_true(it.accepted);
    assert_false(tase_field_iter_keep_bits(&it, &bits)); /* no field yet */
    while (tase_field_iter_next(&it)) {
        int64_t keep;
        bool has = tase_field_iter_keep_bits(&it, &bits);
        assert_int_equal(has, tase_field_keep(it.packet, it.index, &keep) == TASE_OK);
        if (has) {
            /* the wire bits of the keep value: -1 (hfov) is all ones */
            uint64_t ones = it.width >= 8u ? UINT64_MAX : (1ull << (8u * it.width)) - 1u;
            assert_true(bits == ((uint64_t)keep & ones));
        }
        within += it.within ? 1u : 0u;
    }
    assert_int_equal(within, 1); /* the camera byte alone */
}

/* Bad arguments of the iterator: documented codes, and an iterator bound
 * to no packet walks nothing. A copy of a descriptor is refused (its
 * first_field and nfields could index past the field table). */
static void the_field_walk_rejects_bad_arguments(void **state)
{
    const tase_packet_desc_t *p = tase_schema_at(0);
    tase_packet_desc_t forged;
    tase_field_iter_t it;
    uint8_t data[TASE_DATA_MAX] = {0};
    int64_t v = 77;
    (void)state;
    assert_null(tase_field_iter_find(NULL, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), 0));
    assert_null(tase_field_iter_find(&it, 0x28, 0x01, 0));
    assert_null(it.packet);
    assert_false(it.accepted);
    assert_false(tase_field_iter_next(&it));
    assert_false(tase_field_iter_begin(&it, 0));
    assert_int_equal(tase_field_iter_init(NULL, p, 0), TASE_EARG);
    assert_int_equal(tase_field_iter_init(&it, NULL, 0), TASE_EUNKNOWN);
    assert_false(tase_field_iter_next(&it));
    forged = *p;
    forged.first_field = 255;
    forged.nfields = 200;
    assert_int_equal(tase_field_iter_init(&it, &forged, forged.len), TASE_EARG);
    assert_null(it.packet);
    assert_false(tase_field_iter_next(&it));
    assert_int_equal(tase_field_iter_init(&it, p, p->len), TASE_OK);
    assert_int_equal(tase_field_iter_get(&it, data, &v), TASE_EARG); /* no field yet */
    assert_true(tase_field_iter_next(&it));
    assert_int_equal(tase_field_iter_get(NULL, data, &v), TASE_EARG);
    assert_int_equal(tase_field_iter_get(&it, data, NULL), TASE_EARG);
    assert_int_equal(tase_field_iter_get(&it, NULL, &v), TASE_EARG);
    assert_int_equal(v, 77);
    assert_int_equal(tase_field_iter_init(&it, p, 0), TASE_OK); /* a query */
    assert_true(tase_field_iter_next(&it));
    assert_int_equal(tase_field_iter_get(&it, NULL, &v), TASE_ETRUNC);
    assert_int_equal(v, 77);
    /* lengths above TASE_DATA_MAX are never accepted */
    assert_int_equal(tase_field_iter_init(&it, p, TASE_DATA_MAX + 1u), TASE_OK);
    assert_false(it.accepted);
}

/* A walk bound to a packet, then to one the schema does not know (by
 * group and type, NULL, or a copy of a descriptor): schema.h says it is
 * then bound to no packet, walks nothing and has accepted false. */
static void a_walk_rebound_to_no_packet_forgets_the_last_one(void **state)
{
    tase_field_iter_t it;
    tase_packet_desc_t copy;
    int k;
    (void)state;
    memcpy(&copy, tase_schema_find(0x48, 0x02), sizeof copy);
    for (k = 0; k < 3; k++) {
        assert_non_null(tase_field_iter_find(&it, 0x48, 0x02, 22)); /* AXIS_SETTING, short */
        assert_true(it.accepted);
        assert_true(it.short_layout);
        switch (k) {
        case 0: assert_null(tase_field_iter_find(&it, 0x48, 0x7F, 22)); break;
        case 1: assert_int_equal(tase_field_iter_init(&it, NULL, 22), TASE_EUNKNOWN); break;
        default: assert_int_equal(tase_field_iter_init(&it, &copy, 22), TASE_EARG); break;
        }
        assert_null(it.packet);
        assert_false(it.accepted);
        assert_false(it.short_layout);
        assert_int_equal(it.count, 0);
        assert_false(tase_field_iter_next(&it));
    }
}

/* tase_field_iter_get() with NULL data: TASE_EARG whenever the walk's
 * length is above 0 (1 too), TASE_ETRUNC for a query's walk. */
static void field_get_with_no_data_is_an_argument_error_at_any_length(void **state)
{
    tase_field_iter_t it;
    int64_t v = 7;
    (void)state;
    assert_non_null(tase_field_iter_find(&it, 0x00, 0x41, 1)); /* CAMERA_CMD's 1-byte form */
    assert_true(tase_field_iter_next(&it));
    assert_int_equal(tase_field_iter_get(&it, NULL, &v), TASE_EARG);
    assert_non_null(tase_field_iter_find(&it, 0x48, 0x00, 0)); /* a query */
    assert_true(tase_field_iter_next(&it));
    assert_int_equal(tase_field_iter_get(&it, NULL, &v), TASE_ETRUNC);
    assert_int_equal(v, 7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(schema_api_rejects_bad_arguments),
        cmocka_unit_test(a_walk_rebound_to_no_packet_forgets_the_last_one),
        cmocka_unit_test(field_get_with_no_data_is_an_argument_error_at_any_length),
        cmocka_unit_test(reserved_flags_are_the_specs),
        cmocka_unit_test(schema_matches_spec_transcription),
        cmocka_unit_test(fields_are_in_range_ordered_disjoint_and_cover_all_but_reserved),
        cmocka_unit_test(struct_members_match_field_width_sign_and_offset),
        cmocka_unit_test(lookup_finds_exactly_the_spec_packets_among_all_65536_ids),
        cmocka_unit_test(accepted_lengths_follow_the_spec_rules),
        cmocka_unit_test(field_get_sign_extends_signed_fields_only),
        cmocka_unit_test(only_axis_setting_has_a_short_layout_and_its_offsets_are_table_22s),
        cmocka_unit_test(names_resolve_both_ways_and_reject_unknown),
        cmocka_unit_test(keep_values_are_exactly_the_specs),
        cmocka_unit_test(camera_flags_with_the_msb_set_all_mean_no_change),
        cmocka_unit_test(keep_api_rejects_bad_arguments),
        cmocka_unit_test(the_field_walk_agrees_with_the_by_index_functions),
        cmocka_unit_test(the_field_walk_applies_the_layout_and_the_keep_bits),
        cmocka_unit_test(the_field_walk_rejects_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
