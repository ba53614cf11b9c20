/*
 * tools/toolkit.h - private helpers shared by the `tase` command line and
 * `tase-sim` (host-only, POSIX 2008). Not part of the library's API.
 *
 *  - errors: every failure ends the program with exactly one line on
 *    stderr ("tase: <reason>") and exit status 1 (2 for usage errors);
 *  - links: a tase_port_t over a file descriptor (serial device, pty) and
 *    over a CAN interface when the SocketCAN port is built;
 *  - packets: a thin view of the library's schema table by name and by
 *    group/type, so JSON output and `tase send` need no per-packet code;
 *  - JSON: one object per frame, the public contract of docs/TOOLS.md.
 */
#ifndef TASE_TOOLS_TOOLKIT_H
#define TASE_TOOLS_TOOLKIT_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "tase/frame.h"
#include "tase/port.h"
#include "tase/schema.h"
#include "tase/socketcan.h"
#include "tase/posix_uart.h"

/* ---- errors and arguments ---- */

#define TK_EXIT_FAIL 1
#define TK_EXIT_USAGE 2

/* Program name used as the prefix of error lines. */
extern const char *tk_prog;

/* Print "<prog>: <message>\n" to stderr and exit(TK_EXIT_FAIL). */
void tk_die(const char *fmt, ...);
/* Same with exit status TK_EXIT_USAGE (bad command line). */
void tk_usage_error(const char *fmt, ...);

/* Parse a whole decimal, 0x-hex or negative integer in [min, max].
 * Returns 0 or -1 (not a number, trailing characters, out of range). */
int tk_parse_int(const char *s, long long min, long long max, long long *out);
/* Parse a non-negative decimal number with an optional fraction. */
int tk_parse_seconds(const char *s, double *out);

/* Monotonic clock in milliseconds and seconds. */
uint32_t tk_now_ms(void);
double tk_now_s(void);

/* ---- links ---- */

typedef struct {
    bool is_can;
    tase_posix_uart_t uart;
    tase_socketcan_t can;
} tk_link_t;

/* Open a serial device (or a pty slave path) raw 8N1 at `baud`; dies with
 * a one-line reason on failure. */
void tk_link_serial(tk_link_t *l, const char *path, long baud);
/* Open a CAN interface as the host (gimbal == false) or the gimbal. */
void tk_link_can(tk_link_t *l, const char *iface, bool gimbal);
/* Take over an open terminal descriptor (a pty master). */
void tk_link_pty(tk_link_t *l, int fd);
/* The port interface over an open link. */
tase_port_t tk_link_port(tk_link_t *l);
void tk_link_close(tk_link_t *l);

/* Write a whole buffer through a port, waiting while it is busy. Returns
 * 0 or a negative TASE_E* code. */
int tk_port_write_all(const tase_port_t *p, const uint8_t *data, size_t n);

/* Create a pseudo-terminal; returns the master descriptor, writes the
 * slave's path (cap bytes) and a descriptor of the slave that this process
 * keeps open (so the master never sees a hang-up between clients). With
 * `link` non-NULL, also makes `link` a symlink to the slave (replacing an
 * old symlink). Dies on error. */
int tk_pty_open(char *slave, size_t cap, const char *link, int *slave_fd);
/* Discard what is waiting unread in a pty slave's input (a serial line
 * does not keep bytes nobody reads). Returns the bytes discarded. */
int tk_pty_drop_unread(int slave_fd);
/* Bytes waiting unread in a pty slave's input. */
int tk_pty_unread(int slave_fd);

/* ---- packets (the library's schema table, tase/schema.h) ---- */

typedef struct {
    const char *name; /* JSON name */
    unsigned offset;  /* byte offset in the data */
    unsigned width;   /* 1, 2, 4 or 8 bytes */
    bool is_signed;
} tk_field_t;

/* Field i of packet p (i < p->nfields). */
void tk_field(const tase_packet_desc_t *p, unsigned i, tk_field_t *out);
/* Raw value of field i from data[0..len); false if it lies beyond len. */
bool tk_field_get(const tase_packet_desc_t *p, unsigned i, const uint8_t *data, size_t len,
                  long long *v);
/* Store a raw value big-endian; returns -1 if it does not fit the field. */
int tk_field_set(const tk_field_t *f, uint8_t *data, long long v);
/* The packet named `name`, case-insensitive; dies with a one-line list
 * hint when unknown. */
const tase_packet_desc_t *tk_packet_by_name(const char *name);
/* Whether the packet carries free bytes after its fields (CAMERA_PASS). */
bool tk_packet_has_tail(const tase_packet_desc_t *p);

/* ---- JSON ---- */

/* One JSON object for a frame, with a newline. `dir` (NULL, "in", "out")
 * adds the direction key; `time` (NULL or a JSON number of seconds) the
 * capture time key. */
void tk_json_frame(FILE *out, const tase_frame_t *f, const char *dir, const char *time);
/* One human-readable line for a frame. */
void tk_text_frame(FILE *out, const tase_frame_t *f);

#endif /* TASE_TOOLS_TOOLKIT_H */
