/*
 * tase/candump.h - can-utils' log format (`candump -l` files, `candump -L`
 * output, `canplayer` input), so bench captures can be replayed and
 * decoded offline. Pure C99, no OS, no stdio.
 *
 * One line per frame:
 *
 *     (1700000000.123456) vcan0 11000000#00FF5A0808100001
 *
 *   - timestamp: seconds, '.', exactly six digits of microseconds;
 *   - interface name: 1..15 printable ASCII characters, no spaces (a
 *     name with other bytes, which Linux allows, is TASE_EFORMAT);
 *   - identifier: 3 hex digits for a standard frame (<= 7FF), 8 for an
 *     extended one (<= 1FFFFFFF); then '#' and 0..8 data bytes as pairs
 *     of hex digits (the writer uses upper case; the reader takes either,
 *     and a '.' before any byte and one at the end, as canplayer does);
 *     after 8 bytes an optional raw DLC `_9`..`_F` (classic CAN carries 8
 *     bytes for any DLC above 8: read as those 8 bytes, as the SocketCAN
 *     port receives such a frame).
 *
 * The reader accepts fields separated by runs of spaces/tabs, spaces and
 * tabs before the timestamp, a trailing
 * "\n" or "\r\n", and an optional trailing direction flag "T" or "R"
 * (later can-utils with -x). Valid can-utils lines this library cannot
 * represent (remote frames `123#R` or `123#r`, CAN FD `123##1...`, error
 * frames, whose 8-digit identifier has bit 29 set) give
 * TASE_EUNSUPPORTED, so a replay can count and skip them; anything else
 * that does not match gives TASE_EFORMAT.
 */
#ifndef TASE_CANDUMP_H
#define TASE_CANDUMP_H

#include "tase/can.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_CANDUMP_IFNAME_MAX 16u /* bytes including the NUL (Linux IFNAMSIZ) */
/* Longest line the writer produces, including "\n" and the NUL:
 * "(" 20 digits "." 6 ") " 15 " " 8 "#" 16 "\n" NUL. */
#define TASE_CANDUMP_LINE_MAX 73u

/* One log record. */
typedef struct {
    uint64_t sec;                         /* seconds (Unix time in captures) */
    uint32_t usec;                        /* 0..999999 */
    char ifname[TASE_CANDUMP_IFNAME_MAX]; /* NUL-terminated, 1..15 chars */
    tase_can_frame_t frame;
} tase_candump_rec_t;

/* Parse line[0..len) (no NUL needed; a NUL inside ends nothing: it is a
 * malformed character). Returns TASE_OK and fills *rec, or
 *   TASE_EARG          line or rec NULL;
 *   TASE_EFORMAT       not a log line (bad timestamp, name, identifier,
 *                      odd or non-hex data, more than 8 bytes, trailing
 *                      text, empty line);
 *   TASE_EUNSUPPORTED  a remote, CAN FD or error frame.
 * rec is untouched on error. O(len), reentrant, ISR-safe. */
int tase_candump_parse(const char *line, size_t len, tase_candump_rec_t *rec);

/* Write rec as one line ending in "\n", NUL-terminated, into out[0..cap).
 * Seconds are zero-padded to at least 10 digits like candump. Returns the
 * line length without the NUL, or TASE_EARG (NULL, usec > 999999, empty,
 * too long or unprintable/space-containing ifname, frame failing
 * tase_can_frame_check()) or TASE_ENOSPC (cap too small;
 * TASE_CANDUMP_LINE_MAX always suffices). out untouched on error. O(1),
 * reentrant, ISR-safe. */
int tase_candump_format(const tase_candump_rec_t *rec, char *out, size_t cap);

#ifdef __cplusplus
}
#endif

#endif /* TASE_CANDUMP_H */
