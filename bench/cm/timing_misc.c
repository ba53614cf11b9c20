/*
 * Worst case per call of the rest: CAN helpers and 3AX frames, candump
 * lines, the KLV unit helpers (soft-float
 * on these cores: the library calls are part of the call), the GPS status
 * word, tase/units.h (header-inline: called through a noinline wrapper),
 * tase_strerror() and tase_rx_stop(). Functions of a number are measured
 * over a spread of inputs (zero, signs, extremes, a subnormal, huge
 * values, NaN, infinity) and the slowest is named.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "tase/can.h"
#include "tase/candump.h"
#include "tase/frame.h"
#include "tase/klv.h"
#include "tase/units.h"
#include "timing.h"

static volatile double dsink;
static int64_t a_int;
static double a_dbl;

/* ---- CAN ---------------------------------------------------------------- */

static tase_can_frame_t cf, cframes[TASE_CAN_FRAMES_MAX];
static tase_can_split_t sp;
static tase_can_rx_t crx;
static tase_can_3ax_move_t mv = {TASE_3AX_MOVE_RETRACT};
static tase_can_3ax_status_t st = {0xFEu, TASE_3AX_SPEED_MIN_DPS};
static uint8_t frame261[TASE_FRAME_MAX];
static uint32_t id_tx, id_rx;

MEASURED(c_role_ids, tase_can_role_ids(TASE_CAN_ROLE_GIMBAL, &id_tx, &id_rx))
MEASURED(c_frame_check, tase_can_frame_check(&cf))
MEASURED(c_accept, tase_can_accept(TASE_CAN_ROLE_HOST, &cf))
MEASURED(c_split_init, tase_can_split_init(&sp, TASE_CAN_ROLE_GIMBAL, frame261, sizeof(frame261)))
MEASURED(c_split,
         tase_can_split(TASE_CAN_ROLE_GIMBAL, frame261, sizeof(frame261), cframes, COUNT(cframes)))
MEASURED(c_can_rx_init, tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST))
MEASURED(c_move_encode, tase_can_3ax_move_encode(&mv, &cf))
MEASURED(c_move_decode, tase_can_3ax_move_decode(&cf, &mv))
MEASURED(c_status_encode, tase_can_3ax_status_encode(&st, &cf))
MEASURED(c_status_decode, tase_can_3ax_status_decode(&cf, &st))

static void can_misc(void)
{
    static const char *const kinds[] = {"a datalink frame from the gimbal, 8 bytes",
                                        "an 11-bit frame", "another extended ID"};
    worst_t wc = {0, ""}, wa = {0, ""};
    size_t k;
    memset(frame261, 0xA5, sizeof(frame261));
    report("tase_can_role_ids", measure_plain(c_role_ids), "gimbal, both outputs");
    for (k = 0; k < COUNT(kinds); k++) {
        memset(&cf, 0, sizeof(cf));
        cf.id = k == 0u ? TASE_CAN_ID_FROM_GIMBAL : k == 1u ? 0x7FFu : TASE_CAN_ID_3AX_STATUS;
        cf.extended = k != 1u;
        cf.dlc = 8u;
        worst_try(&wc, measure_plain(c_frame_check), "%s", kinds[k]);
        worst_try(&wa, measure_plain(c_accept), "%s, host role", kinds[k]);
    }
    worst_report("tase_can_frame_check", &wc, "");
    worst_report("tase_can_accept", &wa, "");
    report("tase_can_split_init", measure_plain(c_split_init), "a 261-byte frame");
    report("tase_can_split", measure_plain(c_split), "a 261-byte frame into 33 CAN frames");
    report("tase_can_rx_init", measure_plain(c_can_rx_init), "host role");
    report("tase_can_3ax_move_encode", measure_plain(c_move_encode), "retract");
    report("tase_can_3ax_move_decode", measure_plain(c_move_decode), "a retract frame");
    report("tase_can_3ax_status_encode", measure_plain(c_status_encode),
           "speed -640 deg/s (negative: two's complement byte)");
    report("tase_can_3ax_status_decode", measure_plain(c_status_decode), "speed -640 deg/s");
}

/* ---- candump ------------------------------------------------------------ */

static tase_candump_rec_t rec;
static char line[128];
static size_t line_n;

MEASURED(c_format, tase_candump_format(&rec, line, sizeof(line)))
MEASURED(c_parse, tase_candump_parse(line, line_n, &rec))

static void candump(void)
{
    /* the most decimal digit subtractions that fit 64 bits, and the largest */
    static const uint64_t secs[] = {17999999999999999999u, 18446744073709551615u};
    /* the writer's longest line, lowercase hex (the reader's slowest digits),
     * '.' between the bytes, a direction flag and CR LF */
    static const char longest[] = "(17999999999999999999.999999) can0123456789ab "
                                  "1fffffff#ff.ff.ff.ff.ff.ff.ff.ff T\r\n";
    worst_t wf = {0, ""}, wp = {0, ""};
    size_t k;
    for (k = 0; k < COUNT(secs); k++) {
        memset(&rec, 0, sizeof(rec));
        rec.sec = secs[k];
        rec.usec = 999999u;
        memcpy(rec.ifname, "can0123456789ab", 16u); /* 15 characters */
        rec.frame.id = 0x1FFFFFFFu;
        rec.frame.extended = true;
        rec.frame.dlc = 8u;
        memset(rec.frame.data, 0xFF, 8u);
        worst_try(&wf, measure_plain(c_format),
                  "the longest line: %llu s, 15-character name, extended ID, 8 bytes",
                  (unsigned long long)secs[k]);
        line_n = strlen(line);
        worst_try(&wp, measure_plain(c_parse), "the writer's longest line (%lu characters)",
                  (unsigned long)line_n);
    }
    line_n = strlen(longest);
    memcpy(line, longest, line_n);
    worst_try(&wp, measure_plain(c_parse),
              "the writer's longest line in lowercase hex with '.' between bytes, a T flag and "
              "CR LF (%lu characters)",
              (unsigned long)line_n);
    worst_report("tase_candump_format", &wf, "");
    worst_report("tase_candump_parse", &wp, "; each extra blank in a run adds to it: O(len)");
}

/* ---- numbers: KLV units, tase/units.h, the GPS status word --------------- */

/* c_NAME: NAME called on the current input, as its parameter's type T;
 * s_NAME: that input as T, printed with FMT as CT. */
#define OF_INT(name, T, FMT, CT)                                                                   \
    NOINLINE static void c_##name(void *ctx)                                                       \
    {                                                                                              \
        (void)ctx;                                                                                 \
        dsink = (double)name((T)a_int);                                                            \
    }                                                                                              \
    static void s_##name(char *buf, size_t cap)                                                    \
    {                                                                                              \
        (void)snprintf(buf, cap, FMT, (CT)(T)a_int);                                               \
    }
#define OF_S32(name) OF_INT(name, int32_t, "%ld", long)
#define OF_S16(name) OF_INT(name, int16_t, "%ld", long)
#define OF_U16(name) OF_INT(name, uint16_t, "%lu", unsigned long)
#define OF_DBL(name)                                                                               \
    NOINLINE static void c_##name(void *ctx)                                                       \
    {                                                                                              \
        (void)ctx;                                                                                 \
        dsink = (double)name(a_dbl);                                                               \
    }
OF_S32(tase_klv_lat_deg)
OF_S32(tase_klv_lon_deg)
OF_U16(tase_klv_alt_m)
OF_U16(tase_klv_angle_deg)
OF_S16(tase_klv_tilt_deg)
OF_S16(tase_klv_pitch_deg)
OF_S16(tase_klv_roll_deg)
OF_S16(tase_klv_speed_mps)
OF_U16(tase_klv_fov_deg)
OF_INT(tase_klv_utc_s, uint64_t, "%llu", unsigned long long)
OF_DBL(tase_klv_lat_raw)
OF_DBL(tase_klv_lon_raw)
OF_DBL(tase_klv_alt_raw)
OF_DBL(tase_klv_angle_raw)
OF_DBL(tase_klv_tilt_raw)
OF_DBL(tase_klv_pitch_raw)
OF_DBL(tase_klv_roll_raw)
OF_DBL(tase_klv_speed_raw)
OF_DBL(tase_klv_fov_raw)
OF_U16(tase_klv_gps_fix)
OF_U16(tase_klv_gps_antenna)
OF_S32(tase_units_cdeg_to_deg)
OF_S32(tase_units_mas_to_deg)
OF_S32(tase_units_cm_to_m)
OF_S32(tase_units_cmps_to_mps)
OF_S32(tase_units_accel_to_mps2)
OF_INT(tase_units_raw_to_pdop, uint8_t, "%lu", unsigned long)
OF_DBL(tase_units_sat_i16)
OF_DBL(tase_units_sat_u16)
OF_DBL(tase_units_sat_i32)
OF_DBL(tase_units_sat_u8)
OF_DBL(tase_units_deg_to_cdeg)
OF_DBL(tase_units_deg_to_cdeg_u16)
OF_DBL(tase_units_deg_to_mas)
OF_DBL(tase_units_m_to_cm)
OF_DBL(tase_units_mps_to_cmps)
OF_DBL(tase_units_mps2_to_accel)
OF_DBL(tase_units_pdop_to_raw)

NOINLINE static void c_tase_units_round_clamp(void *ctx)
{
    (void)ctx;
    dsink = tase_units_round_clamp(a_dbl, -32768.0, 32767.0);
}

NOINLINE static void c_tase_klv_gps_status(void *ctx)
{
    (void)ctx;
    dsink = tase_klv_gps_status((unsigned)a_int, (unsigned)a_int, (uint16_t)a_int);
}

static void s_tase_klv_gps_status(char *buf, size_t cap)
{
    (void)snprintf(buf, cap, "fix, antenna and flags %lu", (unsigned long)(uint16_t)a_int);
}

typedef struct {
    const char *fn;
    measure_fn call;
    void (*show)(char *buf, size_t cap); /* NULL: the input is a double */
} number_fn_t;

#define INT_FN(name)                                                                               \
    {                                                                                              \
#name, c_##name, s_##name                                                                  \
    }
#define DBL_FN(name)                                                                               \
    {                                                                                              \
#name, c_##name, NULL                                                                      \
    }

static const number_fn_t number_fns[] = {
    INT_FN(tase_klv_lat_deg),         INT_FN(tase_klv_lon_deg),
    INT_FN(tase_klv_alt_m),           INT_FN(tase_klv_angle_deg),
    INT_FN(tase_klv_tilt_deg),        INT_FN(tase_klv_pitch_deg),
    INT_FN(tase_klv_roll_deg),        INT_FN(tase_klv_speed_mps),
    INT_FN(tase_klv_fov_deg),         INT_FN(tase_klv_utc_s),
    DBL_FN(tase_klv_lat_raw),         DBL_FN(tase_klv_lon_raw),
    DBL_FN(tase_klv_alt_raw),         DBL_FN(tase_klv_angle_raw),
    DBL_FN(tase_klv_tilt_raw),        DBL_FN(tase_klv_pitch_raw),
    DBL_FN(tase_klv_roll_raw),        DBL_FN(tase_klv_speed_raw),
    DBL_FN(tase_klv_fov_raw),         INT_FN(tase_klv_gps_fix),
    INT_FN(tase_klv_gps_antenna),     INT_FN(tase_klv_gps_status),
    DBL_FN(tase_units_round_clamp),   DBL_FN(tase_units_sat_i16),
    DBL_FN(tase_units_sat_u16),       DBL_FN(tase_units_sat_i32),
    DBL_FN(tase_units_sat_u8),        INT_FN(tase_units_cdeg_to_deg),
    DBL_FN(tase_units_deg_to_cdeg),   DBL_FN(tase_units_deg_to_cdeg_u16),
    INT_FN(tase_units_mas_to_deg),    DBL_FN(tase_units_deg_to_mas),
    INT_FN(tase_units_cm_to_m),       DBL_FN(tase_units_m_to_cm),
    INT_FN(tase_units_cmps_to_mps),   DBL_FN(tase_units_mps_to_cmps),
    INT_FN(tase_units_accel_to_mps2), DBL_FN(tase_units_mps2_to_accel),
    INT_FN(tase_units_raw_to_pdop),   DBL_FN(tase_units_pdop_to_raw),
};

static void numbers(void)
{
    static const int64_t ints[] = {
        0,      1,     -1,         12345,      -12345,          32767,
        -32768, 65535, 0x12345678, 2147483647, -2147483647 - 1, 1700000000123456};
    const double dbls[] = {0.0,
                           0.5,
                           -0.5,
                           1.0 / 3.0,
                           -1.0 / 3.0,
                           12.3456789012345,
                           -12.3456789012345,
                           89.9999999,
                           -179.9999999,
                           359.9999999,
                           4.9e-324,
                           -2.2e-308,
                           1e10,
                           -1e10,
                           1e300,
                           NAN,
                           INFINITY};
    static char how[96], shown[48];
    size_t f, k;
    for (f = 0; f < COUNT(number_fns); f++) {
        const number_fn_t *nf = &number_fns[f];
        worst_t w = {0, ""};
        size_t n = nf->show == NULL ? COUNT(dbls) : COUNT(ints);
        for (k = 0; k < n; k++) {
            if (nf->show == NULL) {
                a_dbl = dbls[k];
                (void)snprintf(shown, sizeof(shown), "%.15g", a_dbl);
            } else {
                a_int = ints[k];
                nf->show(shown, sizeof(shown));
            }
            worst_try(&w, measure_plain(nf->call), "%s", shown);
        }
        (void)snprintf(how, sizeof(how), " (the slowest of %lu inputs%s)", (unsigned long)n,
                       strncmp(nf->fn, "tase_units_", 11) == 0
                           ? "; header-inline: through a noinline wrapper"
                           : "");
        worst_report(nf->fn, &w, how);
    }
}

/* ---- the rest ----------------------------------------------------------- */

static int a_err;
static tase_rx_t rx_in_call;

MEASURED(c_strerror, tase_strerror(a_err))
MEASURED(c_rx_stop, tase_rx_stop(&rx_in_call))

void timing_misc(void)
{
    worst_t w = {0, ""};
    can_misc();
    candump();
    numbers();
    for (a_err = -20; a_err <= 1; a_err++) {
        worst_try(&w, measure_plain(c_strerror), "%d (%s)", a_err, tase_strerror(a_err));
    }
    worst_report("tase_strerror", &w, "");
    (void)tase_rx_init(&rx_in_call);
    rx_in_call.busy = 1u; /* as inside the receiver's callback */
    report("tase_rx_stop", measure_plain(c_rx_stop), "inside a call of the receiver (stops it)");
}
