/* Tests of the unit conversions: scale factors, rounding half away from
 * zero, saturation at the field limits, NaN. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tase/units.h"

/* No libm: the tests link without -lm. */
static double absd(double v)
{
    return v < 0.0 ? -v : v;
}

static void to_wire_rounds_half_away_from_zero(void **state)
{
    (void)state;
    assert_int_equal(tase_units_sat_i16(2.5), 3);
    assert_int_equal(tase_units_sat_i16(-2.5), -3);
    assert_int_equal(tase_units_sat_i16(2.4999), 2);
    assert_int_equal(tase_units_sat_i16(-0.4), 0);
    assert_int_equal(tase_units_deg_to_cdeg(-45.0), -4500);
    assert_int_equal(tase_units_deg_to_cdeg(0.005), 1);
    assert_int_equal(tase_units_mps2_to_accel(9.80665), 2942); /* 2941.995 */
    assert_int_equal(tase_units_pdop_to_raw(1.25), 13);
}

static void to_wire_saturates_at_field_limits_and_maps_nan_to_zero(void **state)
{
    (void)state;
    assert_int_equal(tase_units_deg_to_cdeg(1000.0), INT16_MAX);
    assert_int_equal(tase_units_deg_to_cdeg(-1000.0), INT16_MIN);
    assert_int_equal(tase_units_sat_i16(32767.49), 32767);
    assert_int_equal(tase_units_sat_i16(-32768.49), -32768);
    assert_int_equal(tase_units_deg_to_cdeg_u16(-1.0), 0);
    assert_int_equal(tase_units_deg_to_cdeg_u16(1000.0), 65535);
    assert_true(tase_units_deg_to_mas(1000.0) == INT32_MAX);
    assert_true(tase_units_deg_to_mas(-1000.0) == INT32_MIN);
    assert_true(tase_units_m_to_cm(1e12) == INT32_MAX);
    assert_int_equal(tase_units_pdop_to_raw(99.0), 255);
    assert_int_equal(tase_units_pdop_to_raw(-1.0), 0);
    assert_int_equal(tase_units_sat_i16(NAN), 0);
    assert_int_equal(tase_units_sat_u8(NAN), 0);
    assert_true(tase_units_sat_i32(NAN) == 0);
    assert_int_equal(tase_units_mps_to_cmps(INFINITY), INT16_MAX);
}

static void from_wire_applies_the_spec_scales(void **state)
{
    (void)state;
    assert_true(absd(tase_units_cdeg_to_deg(-4500) - -45.0) < 1e-12);
    assert_true(absd(tase_units_mas_to_deg(INT32_MIN) - -596.5232355555556) < 1e-9);
    assert_true(absd(tase_units_mas_to_deg(3600000 * 45) - 45.0) < 1e-12);
    assert_true(absd(tase_units_cm_to_m(123456) - 1234.56) < 1e-9);
    assert_true(absd(tase_units_cmps_to_mps(-250) - -2.5) < 1e-12);
    assert_true(absd(tase_units_accel_to_mps2(300) - 1.0) < 1e-12);
    assert_true(absd(tase_units_raw_to_pdop(15) - 1.5) < 1e-12);
    /* degrees -> mas -> degrees is exact to a milli-arcsecond */
    assert_true(absd(tase_units_mas_to_deg(tase_units_deg_to_mas(-122.4194)) - -122.4194) <
                1.0 / 3600000.0);
}

/* A review: a NaN pan became 0 and went out as a position command; 400
 * degrees became 327.67. The checked forms give TASE_ERANGE for NaN, the
 * infinities and anything that rounds beyond the field, *out untouched,
 * and round like the saturating ones everywhere else. */
static void checked_to_wire_refuses_what_the_field_cannot_carry(void **state)
{
    int16_t i16 = 7;
    uint16_t u16 = 7;
    int32_t i32 = 7;
    uint8_t u8 = 7;
    double v;
    (void)state;
    assert_int_equal(tase_units_deg_to_cdeg_checked(NAN, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_cdeg_checked(INFINITY, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_cdeg_checked(400.0, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_cdeg_checked(327.675, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_cdeg_checked(-327.685, &i16), TASE_ERANGE);
    assert_int_equal(i16, 7);
    assert_int_equal(tase_units_deg_to_cdeg_checked(327.67, &i16), TASE_OK);
    assert_int_equal(i16, 32767);
    assert_int_equal(tase_units_deg_to_cdeg_checked(-327.68, &i16), TASE_OK);
    assert_int_equal(i16, -32768);
    assert_int_equal(tase_units_deg_to_cdeg_checked(-0.025, &i16), TASE_OK);
    assert_int_equal(i16, -3);
    assert_int_equal(tase_units_deg_to_cdeg_u16_checked(-0.01, &u16), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_cdeg_u16_checked(-0.004, &u16), TASE_OK);
    assert_int_equal(u16, 0);
    assert_int_equal(tase_units_deg_to_cdeg_u16_checked(655.35, &u16), TASE_OK);
    assert_int_equal(u16, 65535);
    assert_int_equal(tase_units_deg_to_mas_checked(NAN, &i32), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_mas_checked(1000.0, &i32), TASE_ERANGE);
    assert_int_equal(tase_units_deg_to_mas_checked(-122.5, &i32), TASE_OK);
    assert_true(i32 == -441000000);
    assert_int_equal(tase_units_m_to_cm_checked(-INFINITY, &i32), TASE_ERANGE);
    assert_int_equal(tase_units_m_to_cm_checked(1e12, &i32), TASE_ERANGE);
    assert_true(i32 == -441000000);
    assert_int_equal(tase_units_m_to_cm_checked(10.255, &i32), TASE_OK);
    assert_true(i32 == tase_units_m_to_cm(10.255));
    assert_int_equal(tase_units_mps_to_cmps_checked(NAN, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_mps2_to_accel_checked(110.0, &i16), TASE_ERANGE);
    assert_int_equal(tase_units_mps2_to_accel_checked(9.80665, &i16), TASE_OK);
    assert_int_equal(i16, 2942);
    assert_int_equal(tase_units_pdop_to_raw_checked(-0.1, &u8), TASE_ERANGE);
    assert_int_equal(tase_units_pdop_to_raw_checked(25.55, &u8), TASE_ERANGE);
    assert_int_equal(u8, 7);
    assert_int_equal(tase_units_pdop_to_raw_checked(1.25, &u8), TASE_OK);
    assert_int_equal(u8, 13);
    /* inside the range the two forms agree */
    for (v = -327.0; v <= 327.0; v += 0.123) {
        assert_int_equal(tase_units_deg_to_cdeg_checked(v, &i16), TASE_OK);
        assert_int_equal(i16, tase_units_deg_to_cdeg(v));
    }
}

/* Checked rounding of v into wire type k (0 int16, 1 uint16, 2 int32,
 * 3 uint8), the result widened into *value; the typed output starts as 7,
 * so a refusal that leaves it untouched reads 7. */
static int checked_into(unsigned k, double v, int64_t *value)
{
    int16_t i16 = 7;
    uint16_t u16 = 7;
    int32_t i32 = 7;
    uint8_t u8 = 7;
    int r;
    switch (k) {
    case 0:
        r = tase_units_checked_i16(v, &i16);
        *value = i16;
        break;
    case 1:
        r = tase_units_checked_u16(v, &u16);
        *value = u16;
        break;
    case 2:
        r = tase_units_checked_i32(v, &i32);
        *value = i32;
        break;
    default:
        r = tase_units_checked_u8(v, &u8);
        *value = u8;
        break;
    }
    return r;
}

/* The checked forms end exactly half a unit past each wire type's range
 * (a half rounds away from zero, beyond the type): a quarter past an end
 * gives the end, the half past it TASE_ERANGE with *out untouched, at
 * both ends of each of the four types (every value here is exact in
 * double arithmetic). A range typed wrong in one of the four
 * (2147483648.0 for INT32_MAX, 65536.0 for UINT16_MAX) went unnoticed by
 * the scaled conversions' tests, and such a cast is undefined. */
static void each_checked_type_ends_half_a_unit_past_its_range(void **state)
{
    static const double ends[4][2] = {
        {-32768.0, 32767.0}, {0.0, 65535.0}, {-2147483648.0, 2147483647.0}, {0.0, 255.0}};
    unsigned k;
    int64_t v;
    (void)state;
    for (k = 0; k < 4u; k++) {
        double lo = ends[k][0];
        double hi = ends[k][1];
        assert_int_equal(checked_into(k, hi + 0.5, &v), TASE_ERANGE);
        assert_true(v == 7);
        assert_int_equal(checked_into(k, lo - 0.5, &v), TASE_ERANGE);
        assert_true(v == 7);
        assert_int_equal(checked_into(k, hi + 0.25, &v), TASE_OK);
        assert_true(v == (int64_t)hi);
        assert_int_equal(checked_into(k, lo - 0.25, &v), TASE_OK);
        assert_true(v == (int64_t)lo);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(to_wire_rounds_half_away_from_zero),
        cmocka_unit_test(to_wire_saturates_at_field_limits_and_maps_nan_to_zero),
        cmocka_unit_test(from_wire_applies_the_spec_scales),
        cmocka_unit_test(checked_to_wire_refuses_what_the_field_cannot_carry),
        cmocka_unit_test(each_checked_type_ends_half_a_unit_past_its_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
