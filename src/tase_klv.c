/*
 * KLV metadata packet: codec, stream scanner, units. The wire format and
 * the decoder policy are described in include/tase/klv.h; the departures
 * from the printed spec in docs/PROTOCOL-NOTES.md.
 */
#include "tase/klv.h"

#include "tase/frame.h" /* tase_checksum(): the same 16-bit byte sum */

#include <limits.h>
#include <string.h>

/* C99 has no _Static_assert: a negative array size fails the build. */
typedef char tase_klv_rx_size_check[sizeof(tase_klv_rx_t) <= TASE_KLV_RX_SIZE_BUDGET ? 1 : -1];
typedef char tase_klv_window_check[TASE_KLV_PACKET_MAX <= 255u ? 1 : -1];

#define KEY_FIRST 0x06u
#define BER_MAX_OCTETS 4u
#define SET_START (TASE_KLV_KEY_LEN + 1u) /* with a short-form length */

static const uint8_t klv_key[TASE_KLV_KEY_LEN] = {0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01,
                                                  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};

/* Value length of each tag; index 0 is unused. */
static const uint8_t item_len[TASE_KLV_ITEMS + 1u] = {0, 8, 4, 4, 2, 2, 2, 2,
                                                      2, 2, 2, 2, 2, 2, 2, 2};

/* Two's complement reinterpretation without implementation-defined
 * conversions of out-of-range unsigned values. */
static int32_t as_s32(uint32_t u)
{
    return u < 0x80000000u ? (int32_t)u : (int32_t)(u - 0x80000000u) - INT32_MAX - 1;
}

static int16_t as_s16(uint32_t u)
{
    uint32_t low = u & 0xFFFFu;
    return (int16_t)(low < 0x8000u ? (int32_t)low : (int32_t)low - 65536);
}

static uint64_t field_get(const tase_klv_t *k, unsigned tag)
{
    switch (tag) {
    case TASE_KLV_TAG_UTC: return k->utc;
    case TASE_KLV_TAG_LAT: return (uint32_t)k->lat;
    case TASE_KLV_TAG_LON: return (uint32_t)k->lon;
    case TASE_KLV_TAG_ALT: return k->alt;
    case TASE_KLV_TAG_PAN: return k->pan;
    case TASE_KLV_TAG_TILT: return (uint16_t)k->tilt;
    case TASE_KLV_TAG_HEADING: return k->heading;
    case TASE_KLV_TAG_PITCH: return (uint16_t)k->pitch;
    case TASE_KLV_TAG_ROLL: return (uint16_t)k->roll;
    case TASE_KLV_TAG_VNORTH: return (uint16_t)k->vnorth;
    case TASE_KLV_TAG_VEAST: return (uint16_t)k->veast;
    case TASE_KLV_TAG_HFOV: return k->hfov;
    case TASE_KLV_TAG_VFOV: return k->vfov;
    default: return k->gps_status;
    }
}

static void field_set(tase_klv_t *k, unsigned tag, uint64_t v)
{
    uint16_t w = (uint16_t)(v & 0xFFFFu);
    switch (tag) {
    case TASE_KLV_TAG_UTC: k->utc = v; break;
    case TASE_KLV_TAG_LAT: k->lat = as_s32((uint32_t)v); break;
    case TASE_KLV_TAG_LON: k->lon = as_s32((uint32_t)v); break;
    case TASE_KLV_TAG_ALT: k->alt = w; break;
    case TASE_KLV_TAG_PAN: k->pan = w; break;
    case TASE_KLV_TAG_TILT: k->tilt = as_s16(w); break;
    case TASE_KLV_TAG_HEADING: k->heading = w; break;
    case TASE_KLV_TAG_PITCH: k->pitch = as_s16(w); break;
    case TASE_KLV_TAG_ROLL: k->roll = as_s16(w); break;
    case TASE_KLV_TAG_VNORTH: k->vnorth = as_s16(w); break;
    case TASE_KLV_TAG_VEAST: k->veast = as_s16(w); break;
    case TASE_KLV_TAG_HFOV: k->hfov = w; break;
    case TASE_KLV_TAG_VFOV: k->vfov = w; break;
    default: k->gps_status = w; break;
    }
}

static size_t put_item(uint8_t *p, unsigned tag, uint64_t v)
{
    unsigned len = item_len[tag];
    unsigned i;
    uint64_t rest = v;
    p[0] = (uint8_t)tag;
    p[1] = (uint8_t)len;
    for (i = len; i > 0u; i--) {
        p[1u + i] = (uint8_t)(rest & 0xFFu);
        rest >>= 8;
    }
    return 2u + len;
}

int tase_klv_encode(const tase_klv_t *klv, uint8_t *out, size_t cap)
{
    size_t pos = SET_START;
    unsigned tag;
    if (klv == NULL || out == NULL) {
        return TASE_EARG;
    }
    if (cap < TASE_KLV_PACKET_LEN) {
        return TASE_ENOSPC;
    }
    (void)memcpy(out, klv_key, sizeof(klv_key));
    out[TASE_KLV_KEY_LEN] = (uint8_t)TASE_KLV_SET_LEN;
    for (tag = TASE_KLV_TAG_UTC; tag < TASE_KLV_TAG_CHECKSUM; tag++) {
        pos += put_item(out + pos, tag, field_get(klv, tag));
    }
    (void)put_item(out + pos, TASE_KLV_TAG_CHECKSUM,
                   tase_checksum(0u, out + SET_START, TASE_KLV_SUM_LEN));
    return (int)TASE_KLV_PACKET_LEN;
}

/* Reads the BER length at in[TASE_KLV_KEY_LEN]; on success stores the
 * value and the index of the first local-set byte. */
static int read_ber(const uint8_t *in, size_t n, uint32_t *value, size_t *set_start)
{
    size_t pos = TASE_KLV_KEY_LEN;
    uint32_t v;
    if (n <= pos) {
        return TASE_ETRUNC;
    }
    v = in[pos];
    pos++;
    if (v >= 0x80u) {
        unsigned octets = v & 0x7Fu;
        unsigned i;
        /* 0x80 is BER's indefinite form, meaningless for a fixed set. */
        if (octets == 0u || octets > BER_MAX_OCTETS) {
            return TASE_EFORMAT;
        }
        v = 0;
        for (i = 0; i < octets; i++) {
            if (n <= pos) {
                return TASE_ETRUNC;
            }
            if (i + 1u < octets && in[pos] != 0u) {
                /* at least 256 whatever follows: never 69 or 70, decided
                 * now (TASE_ETRUNC means a valid packet may still follow) */
                return TASE_ELENGTH;
            }
            v = (v << 8) | in[pos];
            pos++;
        }
    }
    *value = v;
    *set_start = pos;
    return TASE_OK;
}

int tase_klv_decode(const uint8_t *in, size_t n, tase_klv_t *out)
{
    tase_klv_t k;
    uint32_t declared = 0;
    size_t set = 0;
    size_t pos;
    size_t i;
    unsigned tag;
    uint64_t v = 0;
    int r;
    if (in == NULL || out == NULL) {
        return TASE_EARG;
    }
    /* Byte by byte so that a mismatch inside a short input is EFORMAT, not
     * ETRUNC: the scanner must drop such a candidate at once. */
    for (i = 0; i < TASE_KLV_KEY_LEN; i++) {
        if (i >= n) {
            return TASE_ETRUNC;
        }
        if (in[i] != klv_key[i]) {
            return TASE_EFORMAT;
        }
    }
    r = read_ber(in, n, &declared, &set);
    if (r < 0) {
        return r;
    }
    /* The items always take 70 bytes; 69 is the spec's miscount of them. */
    if (declared != TASE_KLV_SET_LEN && declared != TASE_KLV_SET_LEN_SPEC) {
        return TASE_ELENGTH;
    }
    (void)memset(&k, 0, sizeof(k));
    pos = set;
    for (tag = TASE_KLV_TAG_UTC; tag <= TASE_KLV_TAG_CHECKSUM; tag++) {
        unsigned len = item_len[tag];
        if (pos >= n) {
            return TASE_ETRUNC;
        }
        if (in[pos] == 0u || in[pos] > TASE_KLV_ITEMS) {
            return TASE_EUNKNOWN;
        }
        if (in[pos] != tag) {
            return TASE_EFORMAT; /* repeated, missing or out of order */
        }
        if (pos + 1u >= n) {
            return TASE_ETRUNC;
        }
        if (in[pos + 1u] != len) {
            return TASE_EFORMAT;
        }
        pos += 2u;
        if (n - pos < len) {
            return TASE_ETRUNC;
        }
        v = 0;
        for (i = 0; i < len; i++) {
            v = (v << 8) | in[pos + i];
        }
        pos += len;
        if (tag != TASE_KLV_TAG_CHECKSUM) {
            field_set(&k, tag, v);
        }
    }
    if (v != tase_checksum(0u, in + set, TASE_KLV_SUM_LEN)) {
        return TASE_ECHECKSUM;
    }
    *out = k;
    return (int)pos;
}

/* ---- stream scanner --------------------------------------------------- */

int tase_klv_rx_init(tase_klv_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    /* Clears `busy` too: a call whose callback re-initialises the scanner
     * sees that and returns without touching it again. */
    (void)memset(rx, 0, sizeof(*rx));
    return TASE_OK;
}

int tase_klv_rx_stats_reset(tase_klv_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    (void)memset(&rx->stats, 0, sizeof(rx->stats));
    return TASE_OK;
}

/* The scan decides buf[0..*s) as it goes: `offset` follows buf[*s], and
 * the window is moved down once, when the scan stops (rx_keep()), not
 * for every byte it passes (that made a stream of near-miss candidates
 * cost a copy of the window per byte: 41,688 Cortex-M4 instructions for a
 * 64-byte feed behind a held candidate, a review found). */
static void rx_drop(tase_klv_rx_t *rx, size_t *s, size_t k, int delivered)
{
    *s += k;
    rx->offset += (uint32_t)k;
    if (!delivered) {
        rx->stats.bytes_discarded += (uint32_t)k;
    }
}

/* The undecided bytes buf[s..len) to the front; `offset` is buf[0]'s again. */
static void rx_keep(tase_klv_rx_t *rx, size_t s)
{
    if (s >= rx->len || s >= sizeof(rx->buf)) {
        rx->len = 0u;
    } else if (s > 0u) {
        (void)memmove(rx->buf, &rx->buf[s], (size_t)rx->len - s);
        rx->len = (uint8_t)(rx->len - s);
    } else {
        /* nothing decided: the window stays as it is */
    }
}

static void rx_count(tase_klv_rx_stats_t *s, int err)
{
    switch (err) {
    case TASE_ECHECKSUM: s->checksum_errors++; break;
    case TASE_ELENGTH: s->length_errors++; break;
    case TASE_EUNKNOWN: s->unknown_tags++; break;
    case TASE_ETRUNC: s->truncated++; break;
    default: s->format_errors++; break;
    }
}

/* What one call reports to, and how many packets it has delivered. */
typedef struct {
    tase_klv_handler_t on_packet;
    tase_klv_error_handler_t on_error;
    void *user;
    int delivered;
} klv_call_t;

/* Settle the window as far as its bytes allow. With `final`, a candidate
 * still waiting for bytes fails as truncated instead. Returns false when a
 * handler re-initialised the scanner (it must then be left alone). */
static bool rx_scan(tase_klv_rx_t *rx, int final, klv_call_t *c)
{
    size_t s = 0; /* buf[0..s) decided by this scan */
    for (;;) {
        size_t avail = (size_t)rx->len - s;
        const uint8_t *q = &rx->buf[s];
        const uint8_t *p = (avail > 0u) ? memchr(q, (int)KEY_FIRST, avail) : NULL;
        size_t m;
        tase_klv_t k;
        int r;
        rx_drop(rx, &s, p == NULL ? avail : (size_t)(p - q), 0);
        avail = (size_t)rx->len - s;
        q = &rx->buf[s];
        if (avail == 0u) {
            break;
        }
        /* Noise that merely starts with 0x06 is not worth an error. */
        m = avail < TASE_KLV_KEY_LEN ? avail : TASE_KLV_KEY_LEN;
        if (memcmp(q, klv_key, m) != 0) {
            rx_drop(rx, &s, 1u, 0);
            continue;
        }
        r = tase_klv_decode(q, avail, &k);
        if (r > 0) {
            rx->stats.packets_ok++;
            if (c->delivered < INT_MAX) {
                c->delivered++;
            }
            if (c->on_packet != NULL) {
                c->on_packet(c->user, rx->offset, &k);
                if (rx->busy == 0u) {
                    return false;
                }
            }
            rx_drop(rx, &s, (size_t)r, 1);
            continue;
        }
        if (r == TASE_ETRUNC && !final) {
            break;
        }
        if (m == TASE_KLV_KEY_LEN) {
            rx_count(&rx->stats, r);
            if (c->on_error != NULL) {
                c->on_error(c->user, rx->offset, r);
                if (rx->busy == 0u) {
                    return false;
                }
            }
        }
        /* Re-scan from the byte after the failed candidate's first byte. */
        rx_drop(rx, &s, 1u, 0);
    }
    rx_keep(rx, s);
    return true;
}

/* What feed and flush check (rx NULL, a call in progress, a held length
 * beyond the window: corrupted or never initialised, it would make the
 * copy size wrap), then the call's context; the scanner is busy from here
 * to rx_end(). */
static int rx_begin(tase_klv_rx_t *rx, tase_klv_handler_t on_packet,
                    tase_klv_error_handler_t on_error, void *user, klv_call_t *c)
{
    /* the held length and a busy byte other than 0 and 1 first: a
     * corrupted or never initialised scanner is TASE_EARG even when its
     * `busy` byte happens to be set (TASE_EBUSY would have a caller retry
     * for ever) */
    if (rx == NULL || rx->len > TASE_KLV_PACKET_MAX || rx->busy > 1u) {
        return TASE_EARG;
    }
    if (rx->busy != 0u) {
        return TASE_EBUSY;
    }
    c->on_packet = on_packet;
    c->on_error = on_error;
    c->user = user;
    c->delivered = 0;
    rx->busy = 1u;
    return TASE_OK;
}

/* `live`: no handler re-initialised the scanner, so it is still ours. */
static int rx_end(tase_klv_rx_t *rx, bool live, const klv_call_t *c)
{
    if (live) {
        rx->busy = 0u;
    }
    return c->delivered;
}

int tase_klv_rx_feed(tase_klv_rx_t *rx, const uint8_t *data, size_t n, tase_klv_handler_t on_packet,
                     tase_klv_error_handler_t on_error, void *user)
{
    klv_call_t c;
    size_t done = 0;
    bool live = true;
    int r = (data == NULL && n > 0u) ? TASE_EARG : rx_begin(rx, on_packet, on_error, user, &c);
    if (r != TASE_OK) {
        return r;
    }
    while (live && done < n) {
        /* rx_scan leaves the window short of a full packet (a full window
         * always decides its candidate), so there is always room. */
        size_t take = TASE_KLV_PACKET_MAX - rx->len;
        if (take > n - done) {
            take = n - done;
        }
        (void)memcpy(&rx->buf[rx->len], &data[done], take);
        rx->len = (uint8_t)(rx->len + take);
        rx->stats.bytes_in += (uint32_t)take;
        done += take;
        live = rx_scan(rx, 0, &c);
    }
    return rx_end(rx, live, &c);
}

int tase_klv_rx_flush(tase_klv_rx_t *rx, tase_klv_handler_t on_packet,
                      tase_klv_error_handler_t on_error, void *user)
{
    klv_call_t c;
    int r = rx_begin(rx, on_packet, on_error, user, &c);
    return (r != TASE_OK) ? r : rx_end(rx, rx_scan(rx, 1, &c), &c);
}

/* ---- units ------------------------------------------------------------ */

#define TWO32 4294967296.0
#define TWO16 65536.0
#define WRAP_LIMIT_DEG 1e9

double tase_klv_lat_deg(int32_t v)
{
    return (double)v * 180.0 / TWO32;
}

double tase_klv_lon_deg(int32_t v)
{
    return (double)v * 360.0 / TWO32;
}

double tase_klv_alt_m(uint16_t v)
{
    return (double)v * 10900.0 / TWO16 - 900.0;
}

double tase_klv_angle_deg(uint16_t v)
{
    return (double)v * 360.0 / TWO16;
}

double tase_klv_tilt_deg(int16_t v)
{
    return (double)v * 360.0 / TWO16;
}

double tase_klv_pitch_deg(int16_t v)
{
    return (double)v * 40.0 / TWO16;
}

double tase_klv_roll_deg(int16_t v)
{
    return (double)v * 100.0 / TWO16;
}

double tase_klv_speed_mps(int16_t v)
{
    return (double)v * 510.0 / TWO16;
}

double tase_klv_fov_deg(uint16_t v)
{
    return (double)v * 180.0 / TWO16;
}

double tase_klv_utc_s(uint64_t v)
{
    return (double)v / 1e6;
}

/* Nearest integer to x in [lo, hi], halves away from zero; NaN gives 0
 * (every range here contains 0). */
static int64_t nearest_sat(double x, int64_t lo, int64_t hi)
{
    /* NaN, for which every comparison is false (cppcheck assumes none). */
    /* cppcheck-suppress incorrectLogicOperator */
    if (!(x < 0.0) && !(x >= 0.0)) {
        return 0;
    }
    if (x <= (double)lo) {
        return lo;
    }
    if (x >= (double)hi) {
        return hi;
    }
    {
        /* halves away from zero, exactly: a - trunc(a) is exact in double
         * arithmetic, where (int64_t)(a + 0.5) rounded 0.5 - 2^-54 up to 1
         * and an odd a >= 2^52 up by one */
        double a = (x >= 0.0) ? x : -x;
        int64_t r = (int64_t)a;
        if (a - (double)r >= 0.5) {
            r++;
        }
        return (x >= 0.0) ? r : -r;
    }
}

/* deg * two_pow / 360 to the nearest raw value, as the low 32 bits
 * (binary angles wrap: modulo two_pow, 2^16 or 2^32, the raw type's).
 * Bounding deg keeps turns inside int64. Whole turns first (k * 360 and deg - k * 360 are
 * exact in double arithmetic for |deg| < 1e9, and a turn is two_pow raw),
 * then scaled by the power of two (exact) and divided once (one rounding):
 * deg times a precomputed two_pow / 360, inexact, was up to 2 LSB off from
 * 1e5 deg on. */
static uint32_t nearest_wrap(double deg, double two_pow)
{
    double rest;
    if (!(deg > -WRAP_LIMIT_DEG && deg < WRAP_LIMIT_DEG)) {
        return 0u;
    }
    if (deg > -360.0 && deg < 360.0) {
        rest = deg; /* no whole turn: the division saved */
    } else {
        double turns = (double)(int64_t)(deg / 360.0);
        rest = deg - turns * 360.0;
    }
    /* cppcheck's std.cfg spells INT64_MIN as an unsuffixed literal; the
     * libc's own definition is (-INT64_MAX - 1). */
    /* cppcheck-suppress misra-c2012-7.2 */
    return (uint32_t)((uint64_t)nearest_sat(rest * two_pow / 360.0, INT64_MIN, INT64_MAX) &
                      0xFFFFFFFFu);
}

int32_t tase_klv_lat_raw(double deg)
{
    return (int32_t)nearest_sat(deg * TWO32 / 180.0, INT32_MIN, INT32_MAX);
}

int32_t tase_klv_lon_raw(double deg)
{
    return as_s32(nearest_wrap(deg, TWO32));
}

uint16_t tase_klv_alt_raw(double m)
{
    return (uint16_t)nearest_sat((m + 900.0) * TWO16 / 10900.0, 0, UINT16_MAX);
}

uint16_t tase_klv_angle_raw(double deg)
{
    return (uint16_t)(nearest_wrap(deg, TWO16) & 0xFFFFu);
}

int16_t tase_klv_tilt_raw(double deg)
{
    return as_s16(nearest_wrap(deg, TWO16));
}

int16_t tase_klv_pitch_raw(double deg)
{
    return (int16_t)nearest_sat(deg * TWO16 / 40.0, INT16_MIN, INT16_MAX);
}

int16_t tase_klv_roll_raw(double deg)
{
    return (int16_t)nearest_sat(deg * TWO16 / 100.0, INT16_MIN, INT16_MAX);
}

int16_t tase_klv_speed_raw(double mps)
{
    return (int16_t)nearest_sat(mps * TWO16 / 510.0, INT16_MIN, INT16_MAX);
}

uint16_t tase_klv_fov_raw(double deg)
{
    return (uint16_t)nearest_sat(deg * TWO16 / 180.0, 0, UINT16_MAX);
}

/* ---- GPS status word (spec bit 0 = MSB) ------------------------------- */

#define GPS_FLAGS                                                                                  \
    (TASE_KLV_GPS_DEAD_RECKONED | TASE_KLV_GPS_SBAS | TASE_KLV_GPS_FAST_ACQ | TASE_KLV_GPS_RAW |   \
     TASE_KLV_GPS_COLD_START | TASE_KLV_GPS_DIFFERENTIAL | TASE_KLV_GPS_POSITION_LOCK |            \
     TASE_KLV_GPS_AUTO_SURVEY | TASE_KLV_GPS_FEW_SATS)

unsigned tase_klv_gps_fix(uint16_t status)
{
    return ((unsigned)status >> 13) & 7u;
}

unsigned tase_klv_gps_antenna(uint16_t status)
{
    return ((unsigned)status >> 1) & 3u;
}

uint16_t tase_klv_gps_status(unsigned fix, unsigned antenna, uint16_t flags)
{
    return (uint16_t)(((fix & 7u) << 13) | ((antenna & 3u) << 1) | (flags & GPS_FLAGS));
}
