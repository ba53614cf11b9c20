/*
 * tase/flags.h - named bits and enumerations of the packet fields.
 *
 * The spec numbers bits from 0 = the most significant bit (section 3.1).
 * Every constant here uses that numbering through TASE_BIT8()/TASE_BIT16()
 * so it can be checked against the spec's tables by eye; multi-bit fields
 * are read and written with TASE_BITS8_GET/SET and TASE_BITS16_GET/SET,
 * taking the spec's first and last bit numbers. Header only; the macros
 * are constant expressions usable in case labels.
 *
 * Enumerations the spec lists without values are numbered by this
 * library (docs/PROTOCOL-NOTES.md): the gimbal mode (D2) and the
 * navigation filter mode (P8) both as Cloud Cap's later public gimbal
 * header numbers the same modes.
 */
#ifndef TASE_FLAGS_H
#define TASE_FLAGS_H

#include "tase/common.h"

/* ---- MSB-first bit helpers (spec 3.1) -------------------------------- */

/* Spec bit n (0 = MSB) of a byte / of a 16-bit word. */
#define TASE_BIT8(n) TASE_CAST_(uint8_t, 0x80u >> (n))
#define TASE_BIT16(n) TASE_CAST_(uint16_t, 0x8000u >> (n))
/* Mask of spec bits first..last (inclusive, first <= last). */
#define TASE_MASK8(first, last)                                                                    \
    TASE_CAST_(uint8_t, ((0xFFu >> (first)) & (0xFFu << (7u - (last)))) & 0xFFu)
#define TASE_MASK16(first, last)                                                                   \
    TASE_CAST_(uint16_t, ((0xFFFFu >> (first)) & (0xFFFFu << (15u - (last)))) & 0xFFFFu)
/* Value of spec bits first..last of v, right-aligned. */
#define TASE_BITS8_GET(v, first, last)                                                             \
    ((TASE_CAST_(unsigned, v) & TASE_MASK8(first, last)) >> (7u - (last)))
#define TASE_BITS16_GET(v, first, last)                                                            \
    ((TASE_CAST_(unsigned, v) & TASE_MASK16(first, last)) >> (15u - (last)))
/* v with spec bits first..last replaced by x (excess bits of x dropped). */
#define TASE_BITS8_SET(v, first, last, x)                                                          \
    TASE_CAST_(uint8_t,                                                                            \
               (TASE_CAST_(unsigned, v) & ~TASE_CAST_(unsigned, TASE_MASK8(first, last))) |        \
                   ((TASE_CAST_(unsigned, x) << (7u - (last))) & TASE_MASK8(first, last)))
#define TASE_BITS16_SET(v, first, last, x)                                                         \
    TASE_CAST_(uint16_t,                                                                           \
               (TASE_CAST_(unsigned, v) & ~TASE_CAST_(unsigned, TASE_MASK16(first, last))) |       \
                   ((TASE_CAST_(unsigned, x) << (15u - (last))) & TASE_MASK16(first, last)))

/* ---- GIMBAL_CMD flags byte (4.1.1) ----------------------------------- */
/* Legacy encoding: high nibble zero, bit 6 stabilisation, bit 7 position. */
#define TASE_GIMBAL_FLAGS_LEGACY_RATE 0x00u
#define TASE_GIMBAL_FLAGS_LEGACY_POSITION 0x01u
#define TASE_GIMBAL_FLAGS_LEGACY_RATE_STAB 0x02u
#define TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB 0x03u
#define TASE_GIMBAL_LEGACY_STAB TASE_BIT8(6)
#define TASE_GIMBAL_LEGACY_POSITION TASE_BIT8(7)
/* Current encoding: bit 0 stabilisation on, bits 1-3 the command kind,
 * bits 4-7 zero. Kinds FIRST..LAST are defined (table 5); the SPOI error
 * kinds (4, 5) only with bit 0 set (0xC0, 0xD0): tase_command_check()
 * (codec.h) tells a defined flags byte. (LAST was 3 until 0.3.0, which
 * left the SPOI error kinds out.) */
#define TASE_GIMBAL_STAB TASE_BIT8(0)
#define TASE_GIMBAL_KIND_FIRST 1u
#define TASE_GIMBAL_KIND_LAST 5u
#define TASE_GIMBAL_KIND_RATE 1u
#define TASE_GIMBAL_KIND_POSITION 2u
#define TASE_GIMBAL_KIND_IMPULSE 3u
#define TASE_GIMBAL_KIND_SPOI_ERROR 4u
#define TASE_GIMBAL_KIND_SPOI_ERROR_RATE 5u
/* Command kind of a flags byte (0 for the legacy encoding). */
#define TASE_GIMBAL_KIND(flags) TASE_BITS8_GET(flags, 1, 3)
/* Flags byte for a kind and stabilisation (0/1). */
#define TASE_GIMBAL_FLAGS(kind, stab)                                                              \
    TASE_CAST_(uint8_t, TASE_BITS8_SET(0u, 1, 3, kind) | ((stab) ? TASE_GIMBAL_STAB : 0u))
/* The values of the spec's table. */
#define TASE_GIMBAL_FLAGS_RATE 0x10u
#define TASE_GIMBAL_FLAGS_RATE_STAB 0x90u
#define TASE_GIMBAL_FLAGS_POSITION 0x20u
#define TASE_GIMBAL_FLAGS_POSITION_STAB 0xA0u
#define TASE_GIMBAL_FLAGS_IMPULSE 0x30u
#define TASE_GIMBAL_FLAGS_IMPULSE_STAB 0xB0u
#define TASE_GIMBAL_FLAGS_SPOI_ERROR 0xC0u
#define TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE 0xD0u

/* ---- CAMERA_CMD (4.1.3), LEGACY_CAMERA_CMD (4.1.4) ------------------- */
#define TASE_CAMERA_A 0u
#define TASE_CAMERA_B 1u
#define TASE_CAMERA_C 2u
#define TASE_CAMERA_NO_CHANGE 0xFFu /* camera designator */
#define TASE_HFOV_NO_CHANGE (-1)    /* hfov (0xFFFF on the wire) */
#define TASE_FOCUS_AUTO 0x0000u
#define TASE_FOCUS_TRIGGER 0xFFFDu   /* printed 0xFFFFD in the spec */
#define TASE_FOCUS_INFINITE 0xFFFEu  /* printed 0xFFFFE */
#define TASE_FOCUS_NO_CHANGE 0xFFFFu /* printed 0xFFFFF */
#define TASE_LEGACY_FOCUS_AUTO_FAST 0x0000u
#define TASE_LEGACY_FOCUS_AUTO_SLOW 0x0001u
#define TASE_EXPOSURE_AUTO 0u
#define TASE_EXPOSURE_SHUTTER 1u
#define TASE_EXPOSURE_BRIGHT 2u
#define TASE_EXPOSURE_NO_CHANGE 0xFFu
#define TASE_SHUTTER_NO_CHANGE 0xFFu
#define TASE_BRIGHT_NO_CHANGE 0xFFu
#define TASE_LEGACY_AE_AUTO 0u
#define TASE_LEGACY_AE_SHUTTER 1u
#define TASE_LEGACY_AE_IRIS 2u
#define TASE_LEGACY_AE_MANUAL 3u
/* Camera flags byte: bit 0 set = leave the flags unchanged. */
#define TASE_CAMERA_FLAG_NO_CHANGE TASE_BIT8(0)
#define TASE_CAMERA_FLAG_BLACK_HOT TASE_BIT8(5)
#define TASE_CAMERA_FLAG_STAB TASE_BIT8(6)
#define TASE_CAMERA_FLAG_TITLE TASE_BIT8(7)
/* Bits 1-4 are reserved ("set to zero"; tase_schema_reserved_flags()). */
#define TASE_CAMERA_FLAGS_RESERVED TASE_MASK8(1, 4)

/* ---- RETRACT_DEPLOY_CMD (4.1.6) --------------------------------------- */
/* The `deploy` byte: non-zero deploys, zero retracts. The 3AX CAN move
 * frame (5.3.1) has the opposite byte sense; tase/can.h hides it behind
 * TASE_3AX_MOVE_DEPLOY / _RETRACT, which have these same values. */
#define TASE_RETRACT 0u
#define TASE_DEPLOY 1u /* any non-zero value deploys */

/* ---- Mode byte of GIMBAL_RATE (4.2.2) and GEOREFERENCE_DATA (4.3.3) -- */
#define TASE_MODE_STAB TASE_BIT8(0)
#define TASE_MODE_3AX_DEPLOYED TASE_BIT8(1)
#define TASE_MODE_3AX_RETRACTED TASE_BIT8(2)
#define TASE_MODE_VALUE(mode) TASE_BITS8_GET(mode, 3, 7)
#define TASE_MODE_SET_VALUE(mode, v) TASE_BITS8_SET(mode, 3, 7, v)
/* Mode values (bits 3-7, 0..31). The spec lists six modes without values;
 * these are the values Cloud Cap's later public gimbal packet header gives
 * the same modes (PROTOCOL-NOTES D2). Its numbers 3-9 and 14-15 are modes
 * this spec does not have (video tracking, scan, rig test, retract
 * detection), and it splits tilt initialisation into two phases. */
#define TASE_MODE_RATE 0u           /* "Rate feedback" */
#define TASE_MODE_POSITION 1u       /* "Position feedback" */
#define TASE_MODE_SPOI 2u           /* "Sensor point of interest" */
#define TASE_MODE_PAN_INIT 10u      /* "Pan initialization" */
#define TASE_MODE_TILT_INIT 11u     /* "Tilt initialization", first phase */
#define TASE_MODE_TILT_INIT_2 12u   /* "Tilt initialization", second phase */
#define TASE_MODE_POSITION_INIT 13u /* "Position initialization" */

/* ---- HOST_SENSOR flags (4.2.3) ---------------------------------------- */
#define TASE_HOST_SENSOR_BIAS_CORRECTED TASE_BIT8(0)
#define TASE_HOST_SENSOR_ACCEL_VALID TASE_BIT8(1)
#define TASE_HOST_SENSOR_TAS_VALID TASE_BIT8(2)
#define TASE_HOST_SENSOR_FLAGS_RESERVED TASE_MASK8(3, 7) /* "set to zero" */
#define TASE_TAS_UNAVAILABLE 0xFFFFu

/* ---- HOST_ATTITUDE flags (4.2.4) -------------------------------------- */
#define TASE_HOST_ATT_AID_YAW TASE_BIT8(6)
#define TASE_HOST_ATT_OVERWRITE TASE_BIT8(7)
#define TASE_HOST_ATT_FLAGS_RESERVED TASE_MASK8(0, 5) /* "set to zero" */

/* ---- SPOI_CMD flags (4.3.2) ------------------------------------------- */
/* To the gimbal: bit 0 requests an echo, bits 1-7 zero. From the gimbal:
 * "bit 0 set if stabilization is on", "1-7) Mode": read exactly like the
 * Mode byte above (PROTOCOL-NOTES P4), i.e. bits 1-2 the 3AX state and bits
 * 3-7 the mode. A gimbal that writes a bare mode number into bits 1-7
 * instead leaves bits 1-2 clear for every mode below 32, so the mode reads
 * the same under both readings; reading bits 1-7 as the number would turn
 * a copied Mode byte (0xC2: stabilised, deployed, SPOI) into mode 66. */
#define TASE_SPOI_ECHO TASE_BIT8(0)
#define TASE_SPOI_FLAGS_RESERVED TASE_MASK8(1, 7) /* to the gimbal only */
#define TASE_SPOI_STAB TASE_MODE_STAB
#define TASE_SPOI_3AX_DEPLOYED TASE_MODE_3AX_DEPLOYED
#define TASE_SPOI_3AX_RETRACTED TASE_MODE_3AX_RETRACTED
#define TASE_SPOI_MODE(flags) TASE_MODE_VALUE(flags)

/* ---- GPS status word of GEOREFERENCE_DATA (4.3.3) --------------------- */
#define TASE_GPS_FIX(status) TASE_BITS16_GET(status, 0, 2)
#define TASE_GPS_FIX_3D 7u
#define TASE_GPS_FIX_2D 6u
#define TASE_GPS_FIX_PROPAGATE 5u
#define TASE_GPS_FIX_POSITION_HOLD 4u
#define TASE_GPS_FIX_ACQUIRING 3u
#define TASE_GPS_FIX_BAD_GEOMETRY 2u
#define TASE_GPS_DEAD_RECKONED TASE_BIT16(3)
#define TASE_GPS_SBAS TASE_BIT16(4)
#define TASE_GPS_FAST_ACQUISITION TASE_BIT16(6)
#define TASE_GPS_RAW TASE_BIT16(7)
#define TASE_GPS_COLD_START TASE_BIT16(8)
#define TASE_GPS_DIFFERENTIAL TASE_BIT16(9)
#define TASE_GPS_POSITION_LOCK TASE_BIT16(10)
#define TASE_GPS_AUTO_SURVEY TASE_BIT16(11)
#define TASE_GPS_INSUFFICIENT_SATS TASE_BIT16(12)
#define TASE_GPS_ANTENNA(status) TASE_BITS16_GET(status, 13, 14)
#define TASE_GPS_ANTENNA_GOOD 0u
#define TASE_GPS_ANTENNA_OVERCURRENT 1u
#define TASE_GPS_ANTENNA_UNDERCURRENT 2u
#define TASE_GPS_ANTENNA_NO_POWER 3u

/* ---- Navigation health word of GEOREFERENCE_DATA (4.3.3) -------------- */
#define TASE_NAV_POSITION TASE_BIT16(0)
#define TASE_NAV_VELOCITY TASE_BIT16(1)
#define TASE_NAV_HEADING TASE_BIT16(6)
#define TASE_NAV_ATTITUDE TASE_BIT16(7)
#define TASE_NAV_GYRO_BIAS TASE_BIT16(8)
#define TASE_NAV_ACCEL_BIAS TASE_BIT16(9)
#define TASE_NAV_MAG_BIAS TASE_BIT16(10)
#define TASE_NAV_FILTER_MODE(health) TASE_BITS16_GET(health, 12, 15)
/* Filter modes (bits 12-15). The spec lists "init, align, ready, normal,
 * AHRS" without values; these are the values Cloud Cap's later public
 * gimbal header gives the same modes (PROTOCOL-NOTES P8, the rule of D2):
 * init 0, buffering 1, AHRS 2, bound velocity 3, normal 4, align 5.
 * Buffering and bound velocity are not modes of this spec and have no
 * name here; the spec's "ready" has no counterpart there and no constant
 * (until 0.3.0: INIT 0, ALIGN 1, READY 2, NORMAL 3, AHRS 4, list order). */
#define TASE_NAV_FILTER_INIT 0u
#define TASE_NAV_FILTER_AHRS 2u
#define TASE_NAV_FILTER_NORMAL 4u
#define TASE_NAV_FILTER_ALIGN 5u

/* ---- Setup packets (4.4) ---------------------------------------------- */
#define TASE_SETUP_TEMPORARY 1u    /* `temporary` byte: do not store */
#define TASE_AXIS_NO_CHANGE8 0xFFu /* AXIS_SETTING 8-bit "do not change" */
#define TASE_AXIS_NO_CHANGE16 0xFFFFu
#define TASE_CAMTYPE_NO_CHANGE 0x00u /* CAMERA_TYPE */
#define TASE_CAMTYPE_NONE 0xFFu

/* ---- Camera types (4.5, table 28) ------------------------------------- */
#define TASE_CAMTYPE_SONY_FCB_EX480B 36u
#define TASE_CAMTYPE_SONY_FCB_EX480BP 37u
#define TASE_CAMTYPE_SONY_FCB_EX48B 38u
#define TASE_CAMTYPE_SONY_FCB_EX48BP 39u
#define TASE_CAMTYPE_SONY_FCB_EX980 48u
#define TASE_CAMTYPE_SONY_FCB_EX980P 49u
#define TASE_CAMTYPE_SONY_FCB_EX980S 50u
#define TASE_CAMTYPE_SONY_FCB_EX980SP 51u
#define TASE_CAMTYPE_SONY_FCB_EX480C 52u
#define TASE_CAMTYPE_SONY_FCB_EX480CP 53u
#define TASE_CAMTYPE_SONY_FCB_EX1010 68u
#define TASE_CAMTYPE_SONY_FCB_EX1010P 69u
#define TASE_CAMTYPE_FLIR_320_PHOTON_14 95u
#define TASE_CAMTYPE_FLIR_320_PHOTON_20 96u
#define TASE_CAMTYPE_FLIR_320_PHOTON_23 97u
#define TASE_CAMTYPE_FLIR_320_PHOTON_36 98u
#define TASE_CAMTYPE_FLIR_320_PHOTON_50 99u
/* The spec spells these THERMOTTEKNIX; the maker is Thermoteknix. The
 * suffix is the lens's field of view rounded, except 307_13, which table 28
 * lists with a 12.2 deg lens: value and name kept as listed (PROTOCOL-NOTES
 * S10). */
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_110_41 112u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_110_24 113u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_110_15 114u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_110_10 115u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_307_48 120u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_307_28 121u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_307_18 122u
#define TASE_CAMTYPE_THERMOTEKNIX_MIRACLE_307_13 123u

#endif /* TASE_FLAGS_H */
