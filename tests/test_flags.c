/* Tests of the MSB-first bit helpers and flag constants against the
 * values printed in the spec. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tase/flags.h"

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
    assert_int_equal(TASE_SPOI_MODE(0x80 | TASE_MODE_SPOI), TASE_MODE_SPOI);
    /* mode byte: stab + deployed + position feedback */
    assert_int_equal(TASE_MODE_STAB | TASE_MODE_3AX_DEPLOYED, 0xC0);
    assert_int_equal(TASE_MODE_3AX_RETRACTED, 0x20);
    assert_int_equal(TASE_MODE_VALUE(0xC0 | TASE_MODE_POSITION), TASE_MODE_POSITION);
    assert_int_equal(TASE_MODE_SET_VALUE(0xE0, TASE_MODE_POSITION_INIT), 0xE5);
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
    assert_int_equal(TASE_NAV_FILTER_MODE(0xFFF3), TASE_NAV_FILTER_NORMAL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(msb_first_bits_number_from_the_left),
        cmocka_unit_test(gimbal_cmd_flags_match_the_spec_table),
        cmocka_unit_test(byte_flags_use_msb_first_numbering),
        cmocka_unit_test(gps_status_and_nav_health_fields_decode),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
