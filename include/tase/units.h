/*
 * tase/units.h - conversions between the spec's integer wire units and SI
 * / degree values, so users never hand-code the scalings.
 *
 *   1/100 degree (angles, rates, FOV)   tase_units_cdeg_to_deg / deg_to_cdeg
 *   milli-arcseconds (lat, lon)         tase_units_mas_to_deg / deg_to_mas
 *   centimetres (height)                tase_units_cm_to_m / m_to_cm
 *   cm/s (velocities; TAS)              tase_units_cmps_to_mps / mps_to_cmps
 *   1/300 m/s^2 (HOST_SENSOR accel)     tase_units_accel_to_mps2 / mps2_to_accel
 *   0.1 PDOP                            tase_units_pdop_to_raw / raw_to_pdop
 *
 * and the axes' angle ranges (TASE_PAN_*, TASE_TILT_*: tase/common.h,
 * which this header includes).
 *
 * To-wire conversions round to the nearest integer, halves away from zero
 * (2.5 -> 3, -2.5 -> -3), then SATURATE to the field's range (a value
 * beyond it gives the nearest representable one); NaN gives 0. For what
 * is sent as a command use the *_checked forms (end of this header):
 * the same rounding, TASE_ERANGE instead of a saturated value or 0. Mind
 * reserved values at the ends of a range: e.g. HFOV -1 and TAS 0xFFFF
 * mean "no change"/"unavailable", so clamp before converting if a real
 * value could land there. The rounding is of the double given: 1.005 is
 * stored just below 1.005, so tase_units_deg_to_cdeg(1.005) is 100 (the
 * `tase` tool and the Python package round the decimal as written, 101).
 * From-wire conversions are exact within double.
 *
 * Header only (static inline, no libm): unused helpers cost nothing.
 * Clean as C and as C++ under the strictest cast warnings (gcc
 * -Wbad-function-cast, clang -Weverything, clang++ -Wold-style-cast).
 * All functions are pure, reentrant and ISR-safe (when the FPU or soft
 * float may be used there).
 */
#ifndef TASE_UNITS_H
#define TASE_UNITS_H

#include "tase/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The axes' angle ranges (TASE_PAN_*, TASE_TILT_*) are in tase/common.h. */

/* Round half away from zero and clamp to [lo, hi]; NaN -> 0. Exact for
 * every |v| < 2^52 except values within one ulp below a .5 boundary. */
static inline double tase_units_round_clamp(double v, double lo, double hi)
{
    if (!(v < 0.0) && !(v >= 0.0)) {
        return 0.0; /* NaN: every comparison is false */
    }
    v = v >= 0.0 ? v + 0.5 : v - 0.5;
    if (v <= lo) {
        return lo;
    }
    if (v >= hi) {
        return hi;
    }
    return v; /* the caller's conversion truncates toward zero */
}

static inline int16_t tase_units_sat_i16(double v)
{
    double r = tase_units_round_clamp(v, -32768.0, 32767.0);
    return TASE_CAST_(int16_t, r);
}
static inline uint16_t tase_units_sat_u16(double v)
{
    double r = tase_units_round_clamp(v, 0.0, 65535.0);
    return TASE_CAST_(uint16_t, r);
}
static inline int32_t tase_units_sat_i32(double v)
{
    double r = tase_units_round_clamp(v, -2147483648.0, 2147483647.0);
    return TASE_CAST_(int32_t, r);
}
static inline uint8_t tase_units_sat_u8(double v)
{
    double r = tase_units_round_clamp(v, 0.0, 255.0);
    return TASE_CAST_(uint8_t, r);
}

/* 1/100 degree (or deg/s) */
static inline double tase_units_cdeg_to_deg(int32_t cdeg)
{
    return cdeg / 100.0;
}
static inline int16_t tase_units_deg_to_cdeg(double deg)
{
    return tase_units_sat_i16(deg * 100.0);
}
static inline uint16_t tase_units_deg_to_cdeg_u16(double deg)
{
    return tase_units_sat_u16(deg * 100.0); /* HFOV, VFOV, no-go ranges */
}

/* milli-arcseconds: 1 degree = 3 600 000 mas */
static inline double tase_units_mas_to_deg(int32_t mas)
{
    return mas / 3600000.0;
}
static inline int32_t tase_units_deg_to_mas(double deg)
{
    return tase_units_sat_i32(deg * 3600000.0);
}

/* centimetres (32-bit heights) */
static inline double tase_units_cm_to_m(int32_t cm)
{
    return cm / 100.0;
}
static inline int32_t tase_units_m_to_cm(double m)
{
    return tase_units_sat_i32(m * 100.0);
}

/* cm/s (16-bit signed velocities; use sat_u16(mps * 100) for TAS) */
static inline double tase_units_cmps_to_mps(int32_t cmps)
{
    return cmps / 100.0;
}
static inline int16_t tase_units_mps_to_cmps(double mps)
{
    return tase_units_sat_i16(mps * 100.0);
}

/* 1/300 m/s^2 */
static inline double tase_units_accel_to_mps2(int32_t raw)
{
    return raw / 300.0;
}
static inline int16_t tase_units_mps2_to_accel(double mps2)
{
    return tase_units_sat_i16(mps2 * 300.0);
}

/* 0.1 PDOP */
static inline double tase_units_raw_to_pdop(uint8_t raw)
{
    return raw / 10.0;
}
static inline uint8_t tase_units_pdop_to_raw(double pdop)
{
    return tase_units_sat_u8(pdop * 10.0);
}

/* ---- checked to-wire conversions: for what is sent as a command --------
 * The same rounding (half away from zero), but a value the field cannot
 * carry is an error instead of a neighbour: NaN, an infinity, or a value
 * that rounds beyond the field's range gives TASE_ERANGE and leaves *out
 * untouched (a saturating conversion would turn a NaN pan into 0, a
 * position command the gimbal then obeys). TASE_OK and *out otherwise. out
 * must not be NULL. The fields' meanings (a position's axis range, a "do
 * not change" code such as HFOV -1) are the caller's to respect:
 * tase_command_check() (tase/codec.h) checks the commands that move. */
static inline int tase_units_round_checked(double v, double lo, double hi, double *out)
{
    if (!(v > lo - 0.5 && v < hi + 0.5)) {
        return TASE_ERANGE; /* NaN fails every comparison */
    }
    *out = v >= 0.0 ? v + 0.5 : v - 0.5; /* the caller's cast truncates toward zero */
    return TASE_OK;
}
/* The checked rounding into each wire type (as tase_units_sat_*). */
static inline int tase_units_checked_i16(double v, int16_t *out)
{
    double r = 0.0;
    int e = tase_units_round_checked(v, -32768.0, 32767.0, &r);
    if (e == TASE_OK) {
        *out = TASE_CAST_(int16_t, r);
    }
    return e;
}
static inline int tase_units_checked_u16(double v, uint16_t *out)
{
    double r = 0.0;
    int e = tase_units_round_checked(v, 0.0, 65535.0, &r);
    if (e == TASE_OK) {
        *out = TASE_CAST_(uint16_t, r);
    }
    return e;
}
static inline int tase_units_checked_i32(double v, int32_t *out)
{
    double r = 0.0;
    int e = tase_units_round_checked(v, -2147483648.0, 2147483647.0, &r);
    if (e == TASE_OK) {
        *out = TASE_CAST_(int32_t, r);
    }
    return e;
}
static inline int tase_units_checked_u8(double v, uint8_t *out)
{
    double r = 0.0;
    int e = tase_units_round_checked(v, 0.0, 255.0, &r);
    if (e == TASE_OK) {
        *out = TASE_CAST_(uint8_t, r);
    }
    return e;
}

static inline int tase_units_deg_to_cdeg_checked(double deg, int16_t *cdeg)
{
    return tase_units_checked_i16(deg * 100.0, cdeg);
}
static inline int tase_units_deg_to_cdeg_u16_checked(double deg, uint16_t *cdeg)
{
    return tase_units_checked_u16(deg * 100.0, cdeg);
}
static inline int tase_units_deg_to_mas_checked(double deg, int32_t *mas)
{
    return tase_units_checked_i32(deg * 3600000.0, mas);
}
static inline int tase_units_m_to_cm_checked(double m, int32_t *cm)
{
    return tase_units_checked_i32(m * 100.0, cm);
}
static inline int tase_units_mps_to_cmps_checked(double mps, int16_t *cmps)
{
    return tase_units_checked_i16(mps * 100.0, cmps);
}
static inline int tase_units_mps2_to_accel_checked(double mps2, int16_t *accel)
{
    return tase_units_checked_i16(mps2 * 300.0, accel);
}
static inline int tase_units_pdop_to_raw_checked(double pdop, uint8_t *raw)
{
    return tase_units_checked_u8(pdop * 10.0, raw);
}

#ifdef __cplusplus
}
#endif

#endif /* TASE_UNITS_H */
