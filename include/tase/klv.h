/*
 * tase/klv.h - the KLV metadata packet (spec section 6, table 31): typed
 * encoder and decoder, a stream scanner for noisy byte streams, and units
 * helpers.
 *
 * The gimbal sends this packet on its 9600-baud TTL "KLV" line about every
 * 900 ms so that video systems can geo-reference the image. It is not a
 * datalink frame: it has its own key, length and checksum.
 *
 * WIRE FORMAT (all multi-byte values big-endian; see docs/PROTOCOL-NOTES.md
 * for where this departs from the printed table and why):
 *
 *     key   06 0E 2B 34 02 03 01 01 00 00 00 00 00 00 00 00   16 bytes
 *     len   0x46 (70), BER short form                           1 byte
 *     set   15 items, each tag(1) length(1) value(length):      70 bytes
 *            1 utc 8 | 2 lat 4 | 3 lon 4 | 4 alt 2 | 5 pan 2 | 6 tilt 2 |
 *            7 heading 2 | 8 pitch 2 | 9 roll 2 | 10 vnorth 2 |
 *            11 veast 2 | 12 hfov 2 | 13 vfov 2 | 14 gps_status 2 |
 *            15 checksum 2
 *
 * The packet is 87 bytes. The spec says "Key length 69" (its table numbers
 * one byte twice); the encoder writes the true 70, the decoder accepts a
 * declared 69 or 70. The checksum (item 15) is the 16-bit sum of the 66
 * local-set bytes before it: from the UTC tag through the last GPS status
 * byte (the spec's "bytes 17 through 81"). It does not cover the key, the
 * length byte, or the checksum item's own tag and length.
 *
 * DECODER POLICY (strict: this gimbal's packet has one fixed layout).
 *   - The 16 key bytes must match exactly              else TASE_EFORMAT.
 *   - The length is read as BER: short form, or long form with 1..4 length
 *     octets (0x81 0x46 ...); indefinite (0x80) or longer forms give
 *     TASE_EFORMAT; a value other than 69 or 70 gives TASE_ELENGTH (as
 *     soon as a long form's octets make it 256 or more).
 *   - Items are parsed one by one. A tag outside 1..15 is TASE_EUNKNOWN.
 *     Tags must appear exactly once each, in order 1..15: a repeated,
 *     missing or out-of-order tag shows up as "tag k where k-th was
 *     expected" and gives TASE_EFORMAT. Each item's length byte must be
 *     the table's length for that tag, else TASE_EFORMAT. Nothing may
 *     follow tag 15 inside the set (its length is fixed by the items).
 *   - The checksum is verified last                     else TASE_ECHECKSUM.
 *   - Checks run in wire order and the first failure is returned. If the
 *     input ends before any check fails, the result is TASE_ETRUNC, so a
 *     packet that more bytes could still make valid is never refused
 *     early; the stream scanner relies on this. (The converse does not
 *     hold: the checksum is checked only when both its bytes are in, so a
 *     packet one byte short whose first checksum byte is already wrong is
 *     TASE_ETRUNC too, and is refused with the next byte.)
 *
 * STREAM SCANNER. tase_klv_rx_t is a caller-owned receiver fed arbitrary
 * chunks of a byte stream (noise, partial and corrupted packets allowed).
 * It keeps a window of at most TASE_KLV_PACKET_MAX bytes that starts at the
 * current candidate (a 0x06 byte). When the candidate fails, the scan
 * resumes at the byte after its first byte, so a packet that begins inside
 * a false or corrupted candidate is never lost. The key holds no other
 * 0x06, so a candidate whose key matches cannot hide a packet that starts
 * within its key. LATENCY: every candidate that starts before a clean
 * packet is decided by the time the packet's last byte arrives, unless it
 * declared a long-form BER length (then up to 3 bytes later), so a clean
 * packet is normally delivered by the call that feeds its last byte, also
 * behind a cut or corrupted one.
 * A delivered packet's bytes are never re-scanned.
 *
 * RAM: sizeof(tase_klv_rx_t) <= TASE_KLV_RX_SIZE_BUDGET (132 bytes: the
 * 91-byte window, 8 counters, the offset, the length and a busy flag,
 * padded; no pointers, so the same on 32- and 64-bit). Stack: about 210
 * bytes for feed -> scan -> decode -> checksum on Cortex-M4 -Os (212 in
 * docs/FOOTPRINT.md, from gcc -fstack-usage), of which one tase_klv_t
 * (40 bytes).
 *
 * UNITS. The raw fields are what travels on the wire; tase_klv_*_deg() and
 * friends convert them with the corrected scale factors (the spec prints
 * each formula inverted), and tase_klv_*_raw() convert back with rounding
 * to nearest (halves away from zero). Circular quantities (lon, pan, tilt,
 * heading) wrap modulo 360 deg; the others saturate at the ends of the
 * raw type. NaN (and, for circular values, an infinity or a magnitude
 * of 1e9 deg or more) gives raw 0. These helpers use double arithmetic only
 * (no libm); on an FPU-less or single-precision MCU they pull in the
 * soft-float routines, so firmware that only forwards raw values should
 * not call them.
 */
#ifndef TASE_KLV_H
#define TASE_KLV_H

#include "tase/common.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_KLV_KEY_LEN 16u      /* universal key */
#define TASE_KLV_SET_LEN 70u      /* local set: 15 x (tag+len) + 40 */
#define TASE_KLV_SET_LEN_SPEC 69u /* what the spec declares */
#define TASE_KLV_PACKET_LEN 87u   /* key + 1 length byte + set */
#define TASE_KLV_PACKET_MAX 91u   /* with the longest BER length accepted */
#define TASE_KLV_SUM_LEN 66u      /* local-set bytes covered by the sum */
#define TASE_KLV_ITEMS 15u

/* Tags of the local set, in the order they must appear. */
#define TASE_KLV_TAG_UTC 1u
#define TASE_KLV_TAG_LAT 2u
#define TASE_KLV_TAG_LON 3u
#define TASE_KLV_TAG_ALT 4u
#define TASE_KLV_TAG_PAN 5u
#define TASE_KLV_TAG_TILT 6u
#define TASE_KLV_TAG_HEADING 7u
#define TASE_KLV_TAG_PITCH 8u
#define TASE_KLV_TAG_ROLL 9u
#define TASE_KLV_TAG_VNORTH 10u
#define TASE_KLV_TAG_VEAST 11u
#define TASE_KLV_TAG_HFOV 12u
#define TASE_KLV_TAG_VFOV 13u
#define TASE_KLV_TAG_GPS_STATUS 14u
#define TASE_KLV_TAG_CHECKSUM 15u

/* One packet's values, raw as on the wire (units in the comments). */
typedef struct {
    uint64_t utc;        /* microseconds since 1970-01-01 00:00 UTC */
    int32_t lat;         /* deg = v * 180 / 2^32 */
    int32_t lon;         /* deg = v * 360 / 2^32 */
    uint16_t alt;        /* m = v * 10900 / 65536 - 900 */
    uint16_t pan;        /* sensor azimuth, deg = v * 360 / 65536 */
    int16_t tilt;        /* sensor elevation, deg = v * 360 / 65536 */
    uint16_t heading;    /* platform heading, deg = v * 360 / 65536 */
    int16_t pitch;       /* platform pitch, deg = v * 40 / 65536 */
    int16_t roll;        /* platform roll, deg = v * 100 / 65536 */
    int16_t vnorth;      /* m/s = v * 510 / 65536 */
    int16_t veast;       /* m/s = v * 510 / 65536 */
    uint16_t hfov;       /* deg = v * 180 / 65536 */
    uint16_t vfov;       /* deg = v * 180 / 65536 */
    uint16_t gps_status; /* see TASE_KLV_GPS_* below */
} tase_klv_t;

/* Encode one packet (TASE_KLV_PACKET_LEN bytes, declared set length 70)
 * into out[0..cap). Returns TASE_KLV_PACKET_LEN, or TASE_EARG (klv or out
 * NULL) or TASE_ENOSPC (cap < 87, 0 included); on error nothing is
 * written. To imitate a gimbal that follows the spec literally, overwrite
 * out[16] with TASE_KLV_SET_LEN_SPEC afterwards: the checksum does not
 * cover that byte.
 * O(1), reentrant, ISR-safe. */
int tase_klv_encode(const tase_klv_t *klv, uint8_t *out, size_t cap);

/* Decode the packet that starts at in[0] (n bytes available; bytes after
 * the packet are ignored). Returns the number of bytes the packet takes
 * (87, or up to 91 with a long-form BER length) and fills *out, or
 *   TASE_EARG      in or out NULL;
 *   TASE_ETRUNC    input ends before the packet is complete (everything
 *                  up to there is consistent);
 *   TASE_EFORMAT   bad key, BER form, tag order or item length;
 *   TASE_ELENGTH   declared set length not 69 or 70;
 *   TASE_EUNKNOWN  a tag outside 1..15;
 *   TASE_ECHECKSUM checksum mismatch.
 * See DECODER POLICY above. *out is untouched on error. O(1) (reads at
 * most 91 bytes), reentrant, ISR-safe. */
int tase_klv_decode(const uint8_t *in, size_t n, tase_klv_t *out);

/* ---- stream scanner --------------------------------------------------- */

/* Scanner statistics. Only incremented by the library. */
typedef struct {
    uint32_t bytes_in;        /* every byte fed */
    uint32_t packets_ok;      /* packets delivered */
    uint32_t checksum_errors; /* key, layout fine, checksum wrong */
    uint32_t format_errors;   /* key matched, then TASE_EFORMAT */
    uint32_t length_errors;   /* key matched, set length not 69/70 */
    uint32_t unknown_tags;    /* key matched, then a tag outside 1..15 */
    uint32_t truncated;       /* key matched, input ended (flush only) */
    uint32_t bytes_discarded; /* bytes not part of a delivered packet */
} tase_klv_rx_stats_t;

/* Scanner instance. Treat every field except `stats` as private. */
typedef struct {
    tase_klv_rx_stats_t stats;
    uint32_t offset; /* stream offset of buf[0] */
    uint8_t len;     /* bytes held in buf */
    uint8_t busy;    /* a call is in progress (a handler is running) */
    uint8_t buf[TASE_KLV_PACKET_MAX];
} tase_klv_rx_t;

/* Enforced at compile time in tase_klv.c. */
#define TASE_KLV_RX_SIZE_BUDGET 132u

/* Called once per valid packet, in stream order. `offset` is the stream
 * offset of the packet's first key byte, counted from tase_klv_rx_init()
 * (modulo 2^32; tase_klv_rx_stats_reset() does not change it). `klv` is
 * valid only during the call. On the same scanner, a handler (this one or
 * the error handler) may call tase_klv_rx_stats_reset() and
 * tase_klv_rx_init() (the call that ran the handler then returns as soon
 * as the handler does, with the packets it delivered; the rest of its
 * input is not consumed); tase_klv_rx_feed() and tase_klv_rx_flush()
 * return TASE_EBUSY there and change nothing, unless the handler has
 * called tase_klv_rx_init() first: that scanner is a new one, free to be
 * fed (the call that ran the handler leaves it alone). */
typedef void (*tase_klv_handler_t)(void *user, uint32_t offset, const tase_klv_t *klv);

/* Called once per candidate whose 16 key bytes matched but which failed,
 * with its offset and the TASE_E* code from tase_klv_decode() (TASE_ETRUNC
 * only from tase_klv_rx_flush()). For logging; the counters see it too.
 * Same re-entrancy rules as tase_klv_handler_t. */
typedef void (*tase_klv_error_handler_t)(void *user, uint32_t offset, int err);

/* Initialise (or reset) a scanner: empty window, offset 0, counters zero.
 * Returns TASE_OK, or TASE_EARG if rx is NULL. Allowed from inside the
 * scanner's own handlers (see tase_klv_handler_t). */
int tase_klv_rx_init(tase_klv_rx_t *rx);

/* Feed n bytes. Each packet they complete goes to on_packet(user, ...),
 * each failed candidate to on_error(user, ...), before this returns;
 * either handler may be NULL. Returns the number of packets delivered by
 * this call (>= 0; INT_MAX if more), or TASE_EARG if rx is NULL, data is
 * NULL with n > 0 (any n up to SIZE_MAX), or rx's held length exceeds its
 * window or its busy byte is neither 0 nor 1 (corrupted or never
 * initialised), or TASE_EBUSY if called from
 * inside a handler of this scanner; then nothing is consumed.
 * Any split of the stream into calls gives the same packets, offsets and
 * counters. Scanners are independent; one scanner must not be used from
 * two contexts concurrently.
 * Worst case O(n * TASE_KLV_PACKET_MAX) (a stream of near-miss
 * candidates); a clean stream costs O(n) when fed in large chunks and
 * O(n * 87) when fed one byte at a time. */
int tase_klv_rx_feed(tase_klv_rx_t *rx, const uint8_t *data, size_t n, tase_klv_handler_t on_packet,
                     tase_klv_error_handler_t on_error, void *user);

/* End of input: settle the bytes held. A candidate that can no longer be
 * completed is counted as truncated (reported with TASE_ETRUNC) and the
 * bytes after its first byte are scanned again. Afterwards the window is
 * empty (offset and counters kept). Returns packets delivered (>= 0) or
 * TASE_EARG / TASE_EBUSY as tase_klv_rx_feed() (rx unchanged). */
int tase_klv_rx_flush(tase_klv_rx_t *rx, tase_klv_handler_t on_packet,
                      tase_klv_error_handler_t on_error, void *user);

/* Zero every counter, nothing else. Returns TASE_OK or TASE_EARG (rx
 * NULL). Allowed from inside the scanner's own handlers. */
int tase_klv_rx_stats_reset(tase_klv_rx_t *rx);

/* ---- units (corrected formulas; reentrant, ISR-safe, no libm) ---------
 * Total functions: every input gives a defined result (see UNITS above for
 * NaN, infinities and out-of-range values); none can fail. */

double tase_klv_lat_deg(int32_t v);    /* v * 180 / 2^32 */
double tase_klv_lon_deg(int32_t v);    /* v * 360 / 2^32 */
double tase_klv_alt_m(uint16_t v);     /* v * 10900 / 65536 - 900 */
double tase_klv_angle_deg(uint16_t v); /* pan, heading: v * 360 / 65536 */
double tase_klv_tilt_deg(int16_t v);   /* v * 360 / 65536 */
double tase_klv_pitch_deg(int16_t v);  /* v * 40 / 65536 */
double tase_klv_roll_deg(int16_t v);   /* v * 100 / 65536 */
double tase_klv_speed_mps(int16_t v);  /* vnorth, veast: v * 510 / 65536 */
double tase_klv_fov_deg(uint16_t v);   /* hfov, vfov: v * 180 / 65536 */
double tase_klv_utc_s(uint64_t v);     /* seconds since 1970 */

/* Inverses: nearest raw value. Saturating unless marked "wraps". */
int32_t tase_klv_lat_raw(double deg);    /* [-90, 90) */
int32_t tase_klv_lon_raw(double deg);    /* wraps: 180 -> -180 */
uint16_t tase_klv_alt_raw(double m);     /* [-900, 10000 - 1 lsb] */
uint16_t tase_klv_angle_raw(double deg); /* wraps: -10 -> 350, 360 -> 0 */
int16_t tase_klv_tilt_raw(double deg);   /* wraps into [-180, 180) */
int16_t tase_klv_pitch_raw(double deg);  /* [-20, 20) */
int16_t tase_klv_roll_raw(double deg);   /* [-50, 50) */
int16_t tase_klv_speed_raw(double mps);  /* [-255, 255) */
uint16_t tase_klv_fov_raw(double deg);   /* [0, 180) */

/* ---- GPS status word ---------------------------------------------------
 * The spec numbers bits MSB first (section 3.1): bit 0 is 0x8000, bit 15
 * is 0x0001. TASE_KLV_GPS_BIT(n) maps spec bit n to its mask. */
#define TASE_KLV_GPS_BIT(n) TASE_CAST_(uint16_t, 0x8000u >> (n))

/* Fix type: spec bits 0-2 (mask 0xE000), read with tase_klv_gps_fix(). */
#define TASE_KLV_GPS_FIX_MASK 0xE000u
#define TASE_KLV_GPS_FIX_3D 7u
#define TASE_KLV_GPS_FIX_2D 6u
#define TASE_KLV_GPS_FIX_PROPAGATE 5u
#define TASE_KLV_GPS_FIX_POSITION_HOLD 4u
#define TASE_KLV_GPS_FIX_ACQUIRING 3u
#define TASE_KLV_GPS_FIX_BAD_GEOMETRY 2u /* 1 and 0 are reserved */

/* Single-bit flags (spec bit numbers in the comments). */
#define TASE_KLV_GPS_DEAD_RECKONED 0x1000u /* bit 3 */
#define TASE_KLV_GPS_SBAS 0x0800u          /* bit 4 */
#define TASE_KLV_GPS_FAST_ACQ 0x0200u      /* bit 6 (bit 5 reserved) */
#define TASE_KLV_GPS_RAW 0x0100u           /* bit 7: unfiltered */
#define TASE_KLV_GPS_COLD_START 0x0080u    /* bit 8 */
#define TASE_KLV_GPS_DIFFERENTIAL 0x0040u  /* bit 9 */
#define TASE_KLV_GPS_POSITION_LOCK 0x0020u /* bit 10 */
#define TASE_KLV_GPS_AUTO_SURVEY 0x0010u   /* bit 11 */
#define TASE_KLV_GPS_FEW_SATS 0x0008u      /* bit 12: insufficient */

/* Antenna state: spec bits 13-14 (mask 0x0006); bit 15 is reserved. */
#define TASE_KLV_GPS_ANTENNA_MASK 0x0006u
#define TASE_KLV_GPS_ANTENNA_OK 0u
#define TASE_KLV_GPS_ANTENNA_OVERCURRENT 1u
#define TASE_KLV_GPS_ANTENNA_UNDERCURRENT 2u
#define TASE_KLV_GPS_ANTENNA_NO_POWER 3u

/* Fix type (0..7) and antenna state (0..3) of a status word (any word;
 * the other bits are ignored). */
unsigned tase_klv_gps_fix(uint16_t status);
unsigned tase_klv_gps_antenna(uint16_t status);

/* Build a status word from a fix type, an antenna state and flag bits.
 * Out-of-range fix/antenna values are masked to their 3 and 2 bits; flags
 * outside the single-bit flag set above are dropped. */
uint16_t tase_klv_gps_status(unsigned fix, unsigned antenna, uint16_t flags);

#ifdef __cplusplus
}
#endif

#endif /* TASE_KLV_H */
