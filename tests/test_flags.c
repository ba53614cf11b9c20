/* Tests of the MSB-first bit helpers and flag constants against the
 * values printed in the spec. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "../tools/sim_words.h"
#include "tase/codec.h"
#include "tase/flags.h"
#include "tase/ids.h"

static void msb_first_bits_number_from_the_left(void **state)
{
    (void)state;
    assert_int_equal(TASE_BIT8(0), 0x80);
    assert_int_equal(TASE_BIT8(7), 0x01);
    assert_int_equal(TASE_BIT16(0), 0x8000);
    assert_int_equal(TASE_BIT16(15), 0x0001);
    assert_int_equal(TASE_MASK8(3, 7), 0x1F);
    assert_int_equal(TASE_MASK8(1, 3), 0x70);
    assert_int_equal(TASE_MASK16(0, 2), 0xE000);
    assert_int_equal(TASE_MASK16(13, 14), 0x0006);
    assert_int_equal(TASE_MASK16(12, 15), 0x000F);
    assert_int_equal(TASE_BITS8_SET(0xFF, 1, 3, 0), 0x8F);
    assert_int_equal(TASE_BITS8_SET(0x00, 1, 3, 0xFF), 0x70); /* excess dropped */
    assert_int_equal(TASE_BITS16_GET(TASE_BITS16_SET(0xFFFF, 13, 14, 2), 13, 14), 2);
}

static void gimbal_cmd_flags_match_the_spec_table(void **state)
{
    (void)state;
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_RATE, 0), 0x10);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_RATE, 1), 0x90);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_POSITION, 0), 0x20);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_POSITION, 1), 0xA0);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_IMPULSE, 0), 0x30);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_IMPULSE, 1), 0xB0);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_SPOI_ERROR, 1), 0xC0);
    assert_int_equal(TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_SPOI_ERROR_RATE, 1), 0xD0);
    assert_int_equal(TASE_GIMBAL_KIND(0xD0), TASE_GIMBAL_KIND_SPOI_ERROR_RATE);
    assert_int_equal(TASE_GIMBAL_KIND(TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB), 0);
    assert_int_equal(TASE_GIMBAL_LEGACY_STAB | TASE_GIMBAL_LEGACY_POSITION, 0x03);
    assert_int_equal(TASE_GIMBAL_FLAGS_LEGACY_RATE_STAB, TASE_GIMBAL_LEGACY_STAB);
}

/* A review: TASE_GIMBAL_KIND_LAST was 3, so a range check with the pair
 * refused the SPOI error commands 0xC0 and 0xD0. Every kind of the range
 * makes a flags byte the spec defines (with stabilisation), the next one
 * none. */
static void gimbal_kinds_first_to_last_are_the_defined_ones(void **state)
{
    tase_gimbal_cmd_t c;
    unsigned k;
    (void)state;
    memset(&c, 0, sizeof c);
    for (k = TASE_GIMBAL_KIND_FIRST; k <= TASE_GIMBAL_KIND_LAST; k++) {
        c.flags = TASE_GIMBAL_FLAGS(k, 1);
        assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), TASE_OK);
    }
    assert_int_equal(TASE_GIMBAL_KIND_LAST, TASE_GIMBAL_KIND_SPOI_ERROR_RATE);
    c.flags = TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_LAST + 1u, 1);
    assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), TASE_ERANGE);
    c.flags = TASE_GIMBAL_FLAGS(TASE_GIMBAL_KIND_FIRST - 1u, 1); /* 0x80 */
    assert_int_equal(tase_command_check(TASE_ID_GIMBAL_CMD, &c), TASE_ERANGE);
}

static void byte_flags_use_msb_first_numbering(void **state)
{
    (void)state;
    assert_int_equal(TASE_CAMERA_FLAG_NO_CHANGE, 0x80);
    assert_int_equal(TASE_CAMERA_FLAG_BLACK_HOT, 0x04);
    assert_int_equal(TASE_CAMERA_FLAG_STAB, 0x02);
    assert_int_equal(TASE_CAMERA_FLAG_TITLE, 0x01);
    assert_int_equal(TASE_HOST_SENSOR_BIAS_CORRECTED | TASE_HOST_SENSOR_ACCEL_VALID |
                         TASE_HOST_SENSOR_TAS_VALID,
                     0xE0);
    assert_int_equal(TASE_HOST_ATT_AID_YAW, 0x02);
    assert_int_equal(TASE_HOST_ATT_OVERWRITE, 0x01); /* "7 (lsb)" */
    assert_int_equal(TASE_SPOI_ECHO, 0x80);
    /* mode byte: stab + deployed + position feedback */
    assert_int_equal(TASE_MODE_STAB | TASE_MODE_3AX_DEPLOYED, 0xC0);
    assert_int_equal(TASE_MODE_3AX_RETRACTED, 0x20);
    assert_int_equal(TASE_MODE_VALUE(0xC0 | TASE_MODE_POSITION), TASE_MODE_POSITION);
    assert_int_equal(TASE_MODE_SET_VALUE(0xE0, TASE_MODE_POSITION_INIT), 0xE0 | 13);
}

/* Spec 4.3.2 vs 4.2.2: a gimbal that copies its Mode byte into the SPOI
 * flags (stabilised, deployed, SPOI = 0xC2) and one that writes a bare
 * mode number into bits 1-7 (0x82) both read as SPOI mode (P4). */
static void spoi_flags_read_like_the_mode_byte_under_both_readings(void **state)
{
    unsigned mode, stab, tax;
    (void)state;
    assert_int_equal(TASE_SPOI_MODE(0xC2), TASE_MODE_SPOI);
    assert_int_equal(TASE_SPOI_MODE(0x82), TASE_MODE_SPOI);
    assert_true((0xC2 & TASE_SPOI_STAB) && (0xC2 & TASE_SPOI_3AX_DEPLOYED));
    for (mode = 0; mode < 32; mode++) {
        for (stab = 0; stab < 2; stab++) {
            uint8_t bare = (uint8_t)((stab ? 0x80u : 0u) | mode); /* bits 1-7 = mode */
            assert_int_equal(TASE_SPOI_MODE(bare), mode);
            for (tax = 0; tax < 3; tax++) {
                uint8_t copy = TASE_MODE_SET_VALUE(stab ? TASE_MODE_STAB : 0u, mode);
                copy |= tax == 1 ? TASE_MODE_3AX_DEPLOYED : tax == 2 ? TASE_MODE_3AX_RETRACTED : 0u;
                assert_int_equal(TASE_SPOI_MODE(copy), mode);
                assert_int_equal((copy & TASE_SPOI_STAB) != 0, stab);
            }
        }
    }
}

/* D2: every mode value fits the 5 bits the Mode byte has for it, and the
 * three the spec and the later header agree on keep their places. */
static void mode_values_fit_bits_3_to_7(void **state)
{
    static const unsigned modes[] = {
        TASE_MODE_RATE,      TASE_MODE_POSITION,    TASE_MODE_SPOI,         TASE_MODE_PAN_INIT,
        TASE_MODE_TILT_INIT, TASE_MODE_TILT_INIT_2, TASE_MODE_POSITION_INIT};
    size_t i, k;
    (void)state;
    assert_int_equal(TASE_MODE_RATE, 0);
    assert_int_equal(TASE_MODE_POSITION, 1);
    assert_int_equal(TASE_MODE_SPOI, 2);
    for (i = 0; i < sizeof(modes) / sizeof(modes[0]); i++) {
        assert_true(modes[i] < 32);
        assert_int_equal(TASE_MODE_VALUE(TASE_MODE_SET_VALUE(0xE0, modes[i])), modes[i]);
        for (k = 0; k < i; k++) {
            assert_int_not_equal(modes[i], modes[k]);
        }
    }
}

/* Item 5 of issue 16: what tase-sim reports, decoded through flags.h. */
static void simulator_words_decode_through_flags_h(void **state)
{
    const unsigned health = TASE_NAV_POSITION | TASE_NAV_VELOCITY | TASE_NAV_HEADING |
                            TASE_NAV_ATTITUDE | TASE_NAV_GYRO_BIAS | TASE_NAV_ACCEL_BIAS |
                            TASE_NAV_MAG_BIAS;
    sim_model_t m;
    uint16_t h = sim_nav_health();
    uint8_t b;
    (void)state;

    /* NavHealth: filter "normal", every health bit, no reserved bit */
    assert_int_equal(TASE_NAV_FILTER_MODE(h), TASE_NAV_FILTER_NORMAL);
    assert_int_equal(h & health, health);
    assert_int_equal(h & (TASE_MASK16(2, 5) | TASE_BIT16(11)), 0);
    /* the word it used to send read as filter mode "init", reserved set */
    assert_int_equal(TASE_NAV_FILTER_MODE(0xFFF0), TASE_NAV_FILTER_INIT);

    /* Mode byte and SPOI flags: stabilised, deployed, pointing at a SPOI */
    memset(&m, 0, sizeof(m));
    m.mode = SIM_MODE_SPOI;
    m.stabilised = true;
    m.tax = SIM_3AX_DEPLOYED;
    b = sim_mode_byte(&m);
    assert_int_equal(TASE_MODE_VALUE(b), TASE_MODE_SPOI);
    assert_true(b & TASE_MODE_STAB);
    assert_true(b & TASE_MODE_3AX_DEPLOYED);
    assert_false(b & TASE_MODE_3AX_RETRACTED);
    b = sim_spoi_flags(&m);
    assert_int_equal(TASE_SPOI_MODE(b), TASE_MODE_SPOI);
    assert_true(b & TASE_SPOI_STAB);
    /* issue 23 item 1: the SPOI flags carry stabilisation and mode only */
    assert_int_equal(b, 0x80 | TASE_MODE_SPOI);
    /* retracted, unstabilised, position feedback; moving: neither 3AX bit */
    m.mode = SIM_MODE_POSITION;
    m.stabilised = false;
    m.tax = SIM_3AX_RETRACTED;
    b = sim_spoi_flags(&m);
    assert_int_equal(TASE_SPOI_MODE(b), TASE_MODE_POSITION);
    assert_false(b & TASE_SPOI_STAB);
    assert_false(b & (TASE_SPOI_3AX_DEPLOYED | TASE_SPOI_3AX_RETRACTED));
    m.tax = SIM_3AX_MOVING;
    m.mode = SIM_MODE_IMPULSE;
    b = sim_mode_byte(&m);
    assert_int_equal(b & (TASE_MODE_3AX_DEPLOYED | TASE_MODE_3AX_RETRACTED), 0);
    assert_int_equal(TASE_MODE_VALUE(b), TASE_MODE_RATE);
}

static void gps_status_and_nav_health_fields_decode(void **state)
{
    (void)state;
    assert_int_equal(TASE_GPS_FIX(0xE000), TASE_GPS_FIX_3D);           /* 111 */
    assert_int_equal(TASE_GPS_FIX(0xC000), TASE_GPS_FIX_2D);           /* 110 */
    assert_int_equal(TASE_GPS_FIX(0x4000), TASE_GPS_FIX_BAD_GEOMETRY); /* 010 */
    assert_int_equal(TASE_GPS_DEAD_RECKONED, 0x1000);
    assert_int_equal(TASE_GPS_INSUFFICIENT_SATS, 0x0008);
    assert_int_equal(TASE_GPS_ANTENNA(0x0006), TASE_GPS_ANTENNA_NO_POWER);     /* 11 */
    assert_int_equal(TASE_GPS_ANTENNA(0x0004), TASE_GPS_ANTENNA_UNDERCURRENT); /* 10 */
    assert_int_equal(TASE_GPS_ANTENNA(0x0002), TASE_GPS_ANTENNA_OVERCURRENT);  /* 01 */
    assert_int_equal(TASE_GPS_ANTENNA(0xFFF9), TASE_GPS_ANTENNA_GOOD);
    assert_int_equal(TASE_NAV_POSITION, 0x8000);
    assert_int_equal(TASE_NAV_MAG_BIAS, 0x0020);
    /* filter modes as the vendor's later header numbers them (P8) */
    assert_int_equal(TASE_NAV_FILTER_MODE(0xFFF4), TASE_NAV_FILTER_NORMAL);
    assert_int_equal(TASE_NAV_FILTER_MODE(0x0002), TASE_NAV_FILTER_AHRS);
    assert_int_equal(TASE_NAV_FILTER_MODE(0x0005), TASE_NAV_FILTER_ALIGN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(msb_first_bits_number_from_the_left),
        cmocka_unit_test(gimbal_cmd_flags_match_the_spec_table),
        cmocka_unit_test(gimbal_kinds_first_to_last_are_the_defined_ones),
        cmocka_unit_test(byte_flags_use_msb_first_numbering),
        cmocka_unit_test(gps_status_and_nav_health_fields_decode),
        cmocka_unit_test(spoi_flags_read_like_the_mode_byte_under_both_readings),
        cmocka_unit_test(mode_values_fit_bits_3_to_7),
        cmocka_unit_test(simulator_words_decode_through_flags_h),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
