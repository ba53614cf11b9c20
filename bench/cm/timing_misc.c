/*
 * Worst case per call of the rest: CAN helpers and 3AX frames, candump
 * lines, the KLV unit helpers (soft-float
 * on these cores: the library calls are part of the call), the GPS status
 * word, tase/units.h (header-inline: called through a noinline wrapper),
 * tase_strerror() and tase_rx_stop(). Functions of a number are measured
 * over a spread of inputs (zero, signs, extremes, a subnormal, huge
 * values, NaN, infinity, angles past a turn) and the inputs a review's
 * random search found slowest, and the slowest is named. tase_can_split()
 * reads its frame and tase_candump_parse() its line at each address the
 * row names (the C library's copies take other paths at other
 * alignments).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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
/* tase_can_split()'s frame at each address 0..7 mod 8 (copied by the byte) */
static uint8_t split_mem[TASE_FRAME_MAX + 8u] __attribute__((aligned(8)));
static const uint8_t *split_src = split_mem;
static size_t split_n;
static uint32_t id_tx, id_rx;

MEASURED(c_role_ids, tase_can_role_ids(TASE_CAN_ROLE_GIMBAL, &id_tx, &id_rx))
MEASURED(c_frame_check, tase_can_frame_check(&cf))
MEASURED(c_accept, tase_can_accept(TASE_CAN_ROLE_HOST, &cf))
MEASURED(c_split_init, tase_can_split_init(&sp, TASE_CAN_ROLE_GIMBAL, frame261, sizeof(frame261)))
MEASURED(c_split, tase_can_split(TASE_CAN_ROLE_GIMBAL, split_src, split_n, cframes, COUNT(cframes)))
MEASURED(c_can_rx_init, tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST))
MEASURED(c_move_encode, tase_can_3ax_move_encode(&mv, &cf))
MEASURED(c_move_decode, tase_can_3ax_move_decode(&cf, &mv))
MEASURED(c_status_encode, tase_can_3ax_status_encode(&st, &cf))
MEASURED(c_status_decode, tase_can_3ax_status_decode(&cf, &st))

static void can_misc(void)
{
    static const char *const kinds[] = {"a datalink frame from the gimbal, 8 bytes",
                                        "an 11-bit frame", "another extended ID"};
    worst_t wc = {0, ""}, wa = {0, ""}, ws = {0, ""};
    size_t k;
    memset(frame261, 0xA5, sizeof(frame261));
    memset(split_mem, 0xA5, sizeof(split_mem));
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
    for (k = 0; k < 8u; k++) {
        split_src = &split_mem[k];
        split_n = TASE_FRAME_MAX;
        worst_try(&ws, measure_plain(c_split),
                  "a 261-byte frame at an address %lu mod 8 into 33 CAN frames", (unsigned long)k);
    }
    worst_report("tase_can_split", &ws, "");
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
/* a line to parse at each address 0..3 mod 4 */
static char line_mem[128 + 4] __attribute__((aligned(4)));
static const char *parse_at = line;

MEASURED(c_format, tase_candump_format(&rec, line, sizeof(line)))
MEASURED(c_parse, tase_candump_parse(parse_at, line_n, &rec))

/* s[0..n) with its control characters spelled as C escapes. */
static const char *escaped(const char *s, size_t n)
{
    static char buf[160];
    size_t i, k = 0;
    for (i = 0; i < n && k + 3u < sizeof(buf); i++) {
        char e = s[i] == '\r' ? 'r' : s[i] == '\n' ? 'n' : s[i] == '\t' ? 't' : '\0';
        if (e != '\0') {
            buf[k++] = '\\';
            buf[k++] = e;
        } else {
            buf[k++] = s[i];
        }
    }
    buf[k] = '\0';
    return buf;
}

/* Parse line_n bytes of `text` at each address 0..3 mod 4; well-formed
 * lines only (a line the reader refuses ends early). */
static void parse_aligned(worst_t *w, const char *text, const char *what)
{
    size_t off;
    for (off = 0; off < 4u; off++) {
        memcpy(&line_mem[off], text, line_n);
        parse_at = &line_mem[off];
        if (tase_candump_parse(parse_at, line_n, &rec) != TASE_OK) {
            return;
        }
        worst_try(w, measure_plain(c_parse), "%s '%s' (%lu characters, at an address %lu mod 4)",
                  what, escaped(text, line_n), (unsigned long)line_n, (unsigned long)off);
    }
}

static void candump(void)
{
    /* the most decimal digit subtractions that fit 64 bits, the largest,
     * and the most nines */
    static const uint64_t secs[] = {17999999999999999999u, 18446744073709551615u,
                                    9999999999999999999u};
    static const uint32_t usecs[] = {999999u, 0u};
    /* Lines with what the writer never writes and the reader takes: hex
     * in lowercase (the reader's slowest digits) or uppercase, '.' between
     * the bytes, before the first and after the last, the raw DLC of a
     * classic 8-byte frame (_f), a direction flag after a blank or a tab,
     * CR LF; the most digits and the largest number of seconds. */
    static const char *const lines[] = {
        "(17999999999999999999.999999) can0123456789ab 1fffffff#ff.ff.ff.ff.ff.ff.ff.ff T\r\n",
        "(17999999999999999999.999999) can0123456789ab 1fffffff#.ff.ff.ff.ff.ff.ff.ff.ff. T\r\n",
        "(17999999999999999999.999999) can0123456789ab 1fffffff#.ff.ff.ff.ff.ff.ff.ff.ff_f T\r\n",
        "(17999999999999999999.999999) can0123456789ab 1fffffff#.ff.ff.ff.ff.ff.ff.ff.ff._f T\r\n",
        "(17999999999999999999.999999) can0123456789ab 1FFFFFFF#.FF.FF.FF.FF.FF.FF.FF.FF._F T\r\n",
        "(18446744073709551615.999999) can0123456789ab 1fffffff#.ff.ff.ff.ff.ff.ff.ff.ff._f T\r\n",
        "(09999999999999999999.999999) can0123456789ab 1fffffff#.ff.ff.ff.ff.ff.ff.ff.ff._f T\r\n",
        "(17999999999999999999.999999) can0123456789ab 1fffffff#.af.af.af.af.af.af.af.af._f\tT\r\n",
    };
    worst_t wf = {0, ""}, wp = {0, ""};
    size_t k, u;
    for (k = 0; k < COUNT(secs); k++) {
        for (u = 0; u < COUNT(usecs); u++) {
            memset(&rec, 0, sizeof(rec));
            rec.sec = secs[k];
            rec.usec = usecs[u];
            memcpy(rec.ifname, "can0123456789ab", 16u); /* 15 characters */
            rec.frame.id = 0x1FFFFFFFu;
            rec.frame.extended = true;
            rec.frame.dlc = 8u;
            memset(rec.frame.data, 0xFF, 8u);
            worst_try(&wf, measure_plain(c_format),
                      "%llu s, usec %lu, 15-character name, extended ID, 8 bytes",
                      (unsigned long long)secs[k], (unsigned long)usecs[u]);
            (void)tase_candump_format(&rec, line, sizeof(line));
            line_n = strlen(line);
            parse_aligned(&wp, line, "the costliest well-formed line tried (the writer's):");
        }
    }
    for (k = 0; k < COUNT(lines); k++) {
        line_n = strlen(lines[k]);
        parse_aligned(&wp, lines[k], "the costliest well-formed line tried:");
    }
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

/* The *_checked forms: the value through its out-parameter, the result
 * (TASE_OK or TASE_ERANGE) beside it. */
#define OF_CHK(name, type)                                                                         \
    NOINLINE static void c_##name(void *ctx)                                                       \
    {                                                                                              \
        type out = 0;                                                                              \
        (void)ctx;                                                                                 \
        dsink = (double)name(a_dbl, &out) + (double)out;                                           \
    }
OF_CHK(tase_units_checked_i16, int16_t)
OF_CHK(tase_units_checked_u16, uint16_t)
OF_CHK(tase_units_checked_i32, int32_t)
OF_CHK(tase_units_checked_u8, uint8_t)
OF_CHK(tase_units_deg_to_cdeg_checked, int16_t)
OF_CHK(tase_units_deg_to_cdeg_u16_checked, uint16_t)
OF_CHK(tase_units_deg_to_mas_checked, int32_t)
OF_CHK(tase_units_m_to_cm_checked, int32_t)
OF_CHK(tase_units_mps_to_cmps_checked, int16_t)
OF_CHK(tase_units_mps2_to_accel_checked, int16_t)
OF_CHK(tase_units_pdop_to_raw_checked, uint8_t)

NOINLINE static void c_tase_units_round_checked(void *ctx)
{
    double out = 0.0;
    (void)ctx;
    dsink = (double)tase_units_round_checked(a_dbl, -32768.0, 32767.0, &out) + out;
}

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
    DBL_FN(tase_units_round_checked), DBL_FN(tase_units_checked_i16),
    DBL_FN(tase_units_checked_u16),   DBL_FN(tase_units_checked_i32),
    DBL_FN(tase_units_checked_u8),    DBL_FN(tase_units_deg_to_cdeg_checked),
    DBL_FN(tase_units_deg_to_cdeg_u16_checked), DBL_FN(tase_units_deg_to_mas_checked),
    DBL_FN(tase_units_m_to_cm_checked), DBL_FN(tase_units_mps_to_cmps_checked),
    DBL_FN(tase_units_mps2_to_accel_checked), DBL_FN(tase_units_pdop_to_raw_checked),
};

/* d as the shortest "%.Ng" (N = 15..17) that reads back as d. */
static void show_double(char *buf, size_t cap, double d)
{
    int prec;
    for (prec = 15; prec < 17; prec++) {
        (void)snprintf(buf, cap, "%.*g", prec, d);
        if (strtod(buf, NULL) == d || d != d) {
            return;
        }
    }
    (void)snprintf(buf, cap, "%.17g", d);
}

static void numbers(void)
{
    static const int64_t ints[] = {0, 1, -1, 12345, -12345, 32767, -32768, 65535, 0x12345678,
                                   2147483647, -2147483647 - 1, 1700000000123456,
                                   /* a review's random search, slowest for one function each
                                    * (as the parameter type: alt_m, speed_mps, utc_s,
                                    * cdeg_to_deg, mas_to_deg, cm_to_m, cmps_to_mps,
                                    * accel_to_mps2, raw_to_pdop) */
                                   4570, 16437, -1682416156710579254, 1616686296, 850042941,
                                   -1592316646, 776587598, -1231636120, 238};
    const double dbls[] = {
        0.0, 0.5, -0.5, 1.0 / 3.0, -1.0 / 3.0, 12.3456789012345, -12.3456789012345, 89.9999999,
        -179.9999999, 359.9999999, 4.9e-324, -2.2e-308, 1e10, -1e10, 1e300, NAN, INFINITY,
        /* 360 <= |deg| < 1e9: whole turns taken off (a division and a
                            * truncation), with a review's slowest for lon, angle and tilt */
        360.0, -999999999.9999999, 2156.9952348988427, -821292362.27324867, 16533.840903517259,
        -765860983.5, 8218.201719458044, -646876753.5,
        /* a review's random search, slowest for one function each */
        -835.20427182120295, 462.45232379999999, 1.3146779716983462e-310, 2.9395884681868302e-311,
        -7.8574843824591198, 255.58649835570532, 255.55760986607152, -3.6106049494403578,
        -255.57624325145977, 7.8616422150423171, 1.2175706415724909e-310, 3036526895.3120918,
        -465562.0056012334, 3.9558247263548645e-311, -62.675279488907563, 1.2227910252545427e-309};
    static char how[96], shown[48];
    size_t f, k;
    for (f = 0; f < COUNT(number_fns); f++) {
        const number_fn_t *nf = &number_fns[f];
        worst_t w = {0, ""};
        size_t n = nf->show == NULL ? COUNT(dbls) : COUNT(ints);
        for (k = 0; k < n; k++) {
            if (nf->show == NULL) {
                a_dbl = dbls[k];
                show_double(shown, sizeof(shown), a_dbl);
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
