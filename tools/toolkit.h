/*
 * tools/toolkit.h - private helpers shared by the `tase` command line and
 * `tase-sim` (host-only, POSIX 2008). Not part of the library's API.
 *
 *  - errors and exit status: every failure ends the program with one line
 *    on stderr ("tase: <reason>") and one of the TK_EXIT_* codes;
 *  - numbers: one strict grammar for every integer and decimal argument;
 *  - standard output: buffered, every write error reported;
 *  - signals: SIGINT/SIGTERM/SIGHUP set a flag the loops poll, so links
 *    are always closed (and devices restored) by the normal path;
 *  - links: a tase_port_t over a serial device, a pty master or a CAN
 *    interface;
 *  - packets: a thin view of the library's schema table by name and by
 *    group/type, so output and `tase send` need no per-packet code;
 *  - output: one line per frame, JSON (the public contract of
 *    docs/TOOLS.md) or text, with optional time and engineering units;
 *  - decoding: byte streams (serial, or one CAN direction of one
 *    interface) fed into receivers with 64-bit offsets and counters.
 */
#ifndef TASE_TOOLS_TOOLKIT_H
#define TASE_TOOLS_TOOLKIT_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "tase/can.h"
#include "tase/candump.h"
#include "tase/frame.h"
#include "tase/port.h"
#include "tase/posix_uart.h"
#include "tase/schema.h"
#include "tase/socketcan.h"

/* Stringify a number (usage texts). The version is TASE_VERSION_STRING. */
#define TK_STR_(x) #x
#define TK_STR(x) TK_STR_(x)

/* ---- errors and exit status ---- */

#define TK_EXIT_OK 0
#define TK_EXIT_FAIL 1     /* device, I/O, timeout, write error */
#define TK_EXIT_USAGE 2    /* bad command line: nothing was sent */
#define TK_EXIT_MISMATCH 3 /* the gimbal's echo differs from what was sent */
#define TK_EXIT_INPUT 4    /* input not (fully) understood: bad lines, nothing found */
#define TK_EXIT_SENT 5     /* the packet was sent, but writing the output failed */
/* Interrupted by signal N: 128 + N (the shell's convention). */

/* Program name used as the prefix of error lines. */
extern const char *tk_prog;

/* Print "<prog>: <message>\n" to stderr (after flushing stdout) and exit
 * with the given status. Newlines in the message are folded into spaces. */
void tk_exit(int status, const char *fmt, ...);
/* tk_exit(TK_EXIT_FAIL, ...) and tk_exit(TK_EXIT_USAGE, ...). */
void tk_die(const char *fmt, ...);
void tk_usage_error(const char *fmt, ...);
/* The same line without exiting. */
void tk_warn(const char *fmt, ...);
/* Record that packet `what` (a name that outlives the run) has gone out to
 * the device. From then on an exit through tk_exit() with status 1 or
 * 128+N appends "(what was sent)" to its line, and a failure to write
 * standard output (a full disk, a closed pipe) exits TK_EXIT_SENT with
 * "what was sent; cannot write to standard output: <reason>". */
void tk_mark_sent(const char *what);
/* What tk_mark_sent() noted, or NULL. */
const char *tk_sent(void);

/* ---- numbers ----
 * Integers: an optional sign ('+' or '-'), then decimal digits (leading
 * zeros are still decimal) or "0x" and hexadecimal digits. Nothing else:
 * no spaces, no "0X", no octal, no suffix. Decimal numbers (degrees,
 * seconds): an optional sign, digits, optionally '.' and digits. */

#define TK_NUM_OK 0
#define TK_NUM_SYNTAX (-1) /* not a number of the grammar above */
#define TK_NUM_RANGE (-2)  /* a number, outside [min, max] */

/* Parse a whole integer in [min, max]. Returns a TK_NUM_* code; *out is
 * set only on TK_NUM_OK. *hex (may be NULL) tells whether it was written
 * in hex without a sign. */
int tk_parse_int(const char *s, long long min, long long max, long long *out, bool *hex);
/* Parse a whole decimal number. Returns TK_NUM_OK or TK_NUM_SYNTAX. */
int tk_parse_real(const char *s, double *out);
/* A non-negative decimal number of seconds (at most 1e7). */
int tk_parse_seconds(const char *s, double *out);

/* ---- clocks ---- */

/* Monotonic clock in milliseconds and seconds. */
uint32_t tk_now_ms(void);
double tk_now_s(void);

/* Wall-clock time (Unix seconds and microseconds), as captures carry. */
typedef struct {
    int64_t sec;
    uint32_t usec; /* 0..999999 */
} tk_time_t;
void tk_time_now(tk_time_t *t);

/* ---- standard output ---- */

/* Use a large buffer for standard output (before the first write). */
void tk_stdout_buffered(void);
/* Flush standard output; on any write error so far exit TK_EXIT_FAIL with
 * "cannot write to standard output: <reason>", except a reader that went
 * away (EPIPE): then exit 128 + SIGPIPE without a message, as programs
 * killed by SIGPIPE do (links closed first). After tk_mark_sent() both
 * exit TK_EXIT_SENT naming the packet sent. */
void tk_stdout_flush(void);
/* The reader of our output went away (EPIPE on standard output or on a
 * capture written to a pipe): close every link and exit 128 + SIGPIPE
 * without a message, as a program killed by SIGPIPE does. */
void tk_exit_broken_pipe(void);
/* Flush standard output now, as far as it goes: a failure is kept (on
 * stdout and its errno) for the next tk_stdout_flush() to report, so a
 * command that waits after printing (for an echo) finishes its wait and
 * exits with the code of what happened on the link. */
void tk_stdout_flush_soft(void);

/* ---- signals ---- */

/* SIGINT, SIGTERM or SIGHUP caught since tk_catch_signals(), 0 if none. */
extern volatile sig_atomic_t tk_signal;
/* Catch those three (without SA_RESTART, so blocking calls return; a
 * SIGHUP the process was started with ignored stays ignored) and ignore
 * SIGPIPE (a closed reader is then a write error). The signals that end a
 * process (SIGQUIT, SIGUSR1, ...) give the open serial lines their settings
 * back and remove tase-sim's links first, and say what was sent. Every
 * signal caught is unblocked (a blocked one may be inherited). */
void tk_catch_signals(void);
/* Hold those fatal signals (*old: the mask before) until
 * tk_release_fatal_signals(old), for a step that must not be cut in two
 * (a capture file made and its header written). */
void tk_hold_fatal_signals(sigset_t *old);
void tk_release_fatal_signals(const sigset_t *old);
/* Open /dev/null on whichever of descriptors 0, 1 and 2 is closed (first
 * thing in main): a program started with its standard output closed wrote
 * its log into the first file it opened (tase-sim: the lock file of its
 * link, which then named no simulator). It is opened the other way (0 for
 * writing, 1 and 2 for reading), so that using the descriptor fails with
 * EBADF as on the closed one: output is never lost with success. A
 * standard output or error inherited non-blocking (pipe, FIFO, terminal;
 * not a pty's master side) is replaced by a blocking description of the
 * same file. */
void tk_std_fds_open(void);
/* Whether a read() of fd that failed with EIO is the end of the input:
 * for a terminal (a pty whose other side went away), and for nothing
 * else (a disk's read error would pass a file cut short for complete). */
bool tk_read_eio_is_end(int fd);
/* If a signal was caught: run the cleanup the caller did (nothing here)
 * and exit 128 + signal with "interrupted by SIGxxx". */
void tk_exit_if_signalled(void);

/* ---- links ---- */

typedef struct {
    bool is_can;
    bool open;
    tase_posix_uart_t uart;
    tase_socketcan_t can;
} tk_link_t;

/* Open a serial device (or a pty slave path) raw 8N1 at `baud`; dies with
 * a one-line reason on failure. */
void tk_link_serial(tk_link_t *l, const char *path, long baud);
/* The same returning the port's code instead of dying (a bad baud rate is
 * still a usage error): TASE_OK, or TASE_ENODEV for a missing path or one
 * that is not a terminal, TASE_EBUSY, ... (tase_posix_uart_open()). */
int tk_link_serial_try(tk_link_t *l, const char *path, long baud);
/* Die with the one-line reason tk_link_serial() gives for code `rc`. */
void tk_link_serial_die(const char *path, int rc);
/* Open a CAN interface as the host (gimbal == false) or the gimbal. */
void tk_link_can(tk_link_t *l, const char *iface, bool gimbal);
/* Open the CAN interface of link l again (one removed and made anew
 * leaves the old socket unbound): TASE_OK, the link's port now on the new
 * socket (its ctx is unchanged), or the code of tase_socketcan_open(), the
 * link as it was. */
int tk_link_can_reopen(tk_link_t *l, const char *iface, bool gimbal);
/* What a CAN interface did when its reads or writes fail (tk_link_error()
 * and `record --can` say it so). */
#define TK_CAN_DOWN_TEXT "the interface went down"
#define TK_CAN_REMOVED_TEXT "the interface was removed"
/* Take over an open terminal descriptor (a pty master). */
void tk_link_pty(tk_link_t *l, int fd);
/* The port interface over an open link. */
tase_port_t tk_link_port(tk_link_t *l);
/* Close (safe to call twice). */
void tk_link_close(tk_link_t *l);

/* Why a read or write of an open link failed with port code `rc`, for a
 * message: on a serial link TASE_EIO is "the device went away or hung up"
 * (the port reports a hang-up so), on CAN TASE_EDOWN "the interface went
 * down"; otherwise tase_strerror(rc). */
const char *tk_link_error(const tk_link_t *l, int rc);

/* Write a whole buffer through a port, waiting while it is busy (2 s at
 * most). Returns 0 or a negative TASE_E* code; a signal that came
 * (tk_signal) ends the run between attempts, tk_exit_if_signalled(). */
int tk_port_write_all(const tase_port_t *p, const uint8_t *data, size_t n);

/* Create a pseudo-terminal; returns the master descriptor, writes the
 * slave's path (cap bytes) and a descriptor of the slave that this process
 * keeps open (so the master never sees a hang-up between clients). With
 * `link` non-NULL, also makes `link` a symlink to the slave. The link is
 * claimed for the life of the process first (tk_simlink_claim(): the lock
 * file LINK.lock): if a running process holds the claim it dies naming its
 * pid; a symlink into /dev/pts/ that nobody claims (left by a simulator
 * that was killed) is removed at once and replaced; any other symlink, and
 * a file that is not a symlink, never is. At exit (exit() or a return
 * from main, a fatal error included) the link is removed if it still
 * points at the slave, then the lock file. Dies on error. */
int tk_pty_open(char *slave, size_t cap, const char *link, int *slave_fd);
/* Remove `link` only if it is still a symlink to `slave` (ours). */
void tk_pty_unlink(const char *link, const char *slave);
/* `path` with its directory resolved (the file itself need not exist).
 * Returns 0, or -1 with errno set. */
int tk_canonical_path(const char *path, char *out, size_t cap);
/* Discard what is waiting unread in a pty slave's input (a serial line
 * does not keep bytes nobody reads). Returns the bytes discarded. */
int tk_pty_drop_unread(int slave_fd);
/* Bytes waiting unread in a pty slave's input. */
int tk_pty_unread(int slave_fd);
/* A program that took the pty for itself (tase/posix_uart.h, EXCLUSIVE
 * ACCESS: flock plus TIOCEXCL) and was killed with SIGKILL leaves
 * TIOCEXCL set, because the simulator keeps the slave open: every later
 * open but root's then fails with "device busy" although nobody uses the
 * device. If the flag is set and nobody holds the device's lock, clear
 * it. Returns true when it did. */
bool tk_pty_clear_stale_excl(int slave_fd);

/* ---- tase-sim's links (tk_simlink.c, also in the Python package) ----
 * tase-sim's --link PATH is a symlink to its pty /dev/pts/N; beside it,
 * PATH.lock records "tase-sim PID /dev/pts/N" and tase-sim holds a POSIX
 * record lock on it while it runs (the kernel drops it when the process
 * ends, SIGKILL included). A killed simulator leaves both; its pty may
 * then belong to another program, which the tools must never write to. */

#define TK_SIMLINK_LOCK_SUFFIX ".lock"
/* The pty of a record written while the simulator starts (no pty yet). */
#define TK_SIMLINK_STARTING "-"

/* The lock file of `link` (LINK.lock). Returns 0, or -1 (ENAMETOOLONG). */
int tk_simlink_lock_path(const char *link, char *out, size_t cap);
/* Take `link`'s lock file (created if missing) for this process: returns
 * its descriptor, or -1 with the reason in why[0..cap) (a running
 * tase-sim holds it, naming its pid; a file of that name that is not a
 * lock file of tase-sim; an error). */
int tk_simlink_claim(const char *link, char *why, size_t cap);
/* Write the record (this pid, `slave`) into the claimed file. 0 or -1. */
int tk_simlink_record(int fd, const char *slave);
/* Remove `link`'s lock file if it is still the one `fd` holds; close fd. */
void tk_simlink_release(const char *link, int fd);
/* Before opening `path` as a serial device: -1 with the reason in
 * why[0..cap) when it is (or leads through) the link of a tase-sim that
 * no longer runs, whose pty may belong to another program now (its lock
 * file names the pty the link points to, and no process holds it, or one
 * other than the pid recorded: a new simulator taking it over); else 0 (no
 * symlink, no lock file: socat's or a user's symlink; a live tase-sim's
 * link; a link repointed since). Opens and writes nothing but the lock
 * file's reading. */
int tk_simlink_check(const char *path, char *why, size_t cap);

/* ---- packets (the library's schema table, tase/schema.h) ---- */

typedef struct {
    const char *name; /* JSON name */
    unsigned offset;  /* byte offset in the data (of the layout asked for) */
    unsigned width;   /* 1, 2, 4 or 8 bytes */
    bool is_signed;
    bool has_keep;  /* the field has a "do not change" code: */
    long long keep; /* that code (tase_field_keep()) */
} tk_field_t;

/* Field i of packet p (i < p->nfields) in a packet of `len` data bytes
 * (the length selects the layout: AXIS_SETTING's 22-byte form moves
 * fields, see tase_field_offset()). */
void tk_field(const tase_packet_desc_t *p, unsigned i, size_t len, tk_field_t *out);
/* Raw value of field i from data[0..len); false if it lies beyond len. */
bool tk_field_get(const tase_packet_desc_t *p, unsigned i, const uint8_t *data, size_t len,
                  long long *v);
/* Store a raw value big-endian; returns -1 if it does not fit the field. */
int tk_field_set(const tk_field_t *f, uint8_t *data, long long v);
/* The range of the field's values as text ("-32768..32767"). */
void tk_field_range(const tk_field_t *f, char *buf, size_t cap);
/* Parse a value for the field: the integer grammar above, within the
 * field's range; a signed field whose "do not change" code is negative
 * also takes that code's bit pattern in hex (CAMERA_CMD hfov=0xFFFF is
 * -1, as the spec writes it), and no other: pan=0x8000 is out of range,
 * not -32768. Returns a TK_NUM_* code. */
int tk_field_parse(const tk_field_t *f, const char *s, long long *v);
/* The packet named `name`, case-insensitive; dies with a one-line list
 * hint when unknown. */
const tase_packet_desc_t *tk_packet_by_name(const char *name);
/* tase_schema_find() remembering the last answer (decode looks up the
 * same few packets millions of times). */
const tase_packet_desc_t *tk_schema_find(uint8_t group, uint8_t type);
/* Whether the packet carries free bytes after its fields (CAMERA_PASS). */
bool tk_packet_has_tail(const tase_packet_desc_t *p);

/* ---- output of frames ---- */

typedef struct {
    bool json;  /* JSON object (the contract) instead of a text line */
    bool units; /* engineering units beside the raw fields */
    bool time;  /* the time, when known */
} tk_fmt_t;

/* Where a frame came from. */
typedef struct {
    uint64_t offset;       /* stream offset of its first sync byte */
    const tk_time_t *time; /* when its last byte arrived, NULL unknown */
    const char *dir;       /* NULL, "in" (to the gimbal) or "out" */
    const char *iface;     /* CAN interface, or NULL */
} tk_meta_t;

/* The engineering unit of field `field` of packet p, as the output uses
 * it (--units): `suffix` of the JSON key (field "_" suffix; "" none),
 * `label` of the text output, the decimals printed and the unit per wire
 * count. Returns false when the field has none (raw only: GIMBAL_CMD's
 * pan, flags, ...). The Python package (python/) reads it too. */
typedef struct {
    const char *suffix;
    const char *label;
    unsigned decimals;
    double scale;
    bool unavailable_ones; /* all ones means "unavailable" (TAS): no value */
} tk_unit_info_t;
bool tk_unit(const tase_packet_desc_t *p, const char *field, tk_unit_info_t *out);

/* Longest line tk_format_frame() writes (with the newline and a NUL). */
#define TK_LINE_MAX 8192u

/* Format one frame as one line ending in '\n' into buf[0..cap) (cap >=
 * TK_LINE_MAX always suffices); returns its length. */
size_t tk_format_frame(char *buf, size_t cap, const tk_fmt_t *fmt, const tk_meta_t *m,
                       const tase_frame_t *f);
/* Format and write to `out` (no flush). */
void tk_print_frame(FILE *out, const tk_fmt_t *fmt, const tk_meta_t *m, const tase_frame_t *f);
/* Append the JSON number of a time ("1700000000.123456") to buf;
 * returns the length written (at most 28). */
size_t tk_format_time(char *buf, const tk_time_t *t);

/* ---- decoding byte streams ----
 * A decoder holds one receiver per stream: the serial line, or one
 * direction of one CAN interface. Every valid frame is printed with its
 * 64-bit stream offset, the stream's direction/interface and the time of
 * the chunk that completed it. Input parsers (raw bytes, candump lines,
 * captures) only call tk_dec_bytes() / tk_dec_can(). */

#define TK_STREAMS_MAX 32u
#define TK_HIST 264u /* > TASE_FRAME_MAX chunks */

typedef struct {
    char iface[TASE_CANDUMP_IFNAME_MAX]; /* "" for a serial stream */
    const char *dir;                     /* NULL, "in" or "out" */
    uint64_t bytes;                      /* bytes fed so far */
    tase_rx_stats_t seen;                /* rx.stats already added up */
    tk_time_t last;                      /* time of the last chunk */
    bool timed;                          /* last is known */
    /* The record clock's steps back so far (modulo 2^32), added to the
     * times fed to the receiver: a step back is no time (and no pause), as
     * in replay. */
    uint32_t back_ms;
    /* When the recent chunks ended (stream offset after each, and its
     * time): the receiver may decide a frame up to 253 bytes after its last
     * byte (a frame inside a longer candidate waits for that one to fail),
     * and a frame's time is when its last byte arrived, not when it was
     * decided. TK_HIST chunks cover a whole frame even at one byte each. */
    struct {
        uint64_t end;
        tk_time_t time;
    } hist[TK_HIST];
    size_t hnext, hcount;
    /* At the last tick: its time, rx.stats.bytes_in, and the quiet limit
     * left then (tase_rx_quiet_ms(): a held candidate's, or 0 / UINT32_MAX
     * for a lagging scan / nothing held), to tell a tick that cut a held
     * candidate short from one that only went on with the scan. */
    uint32_t tick_at, tick_bytes, tick_left;
    bool ticked;
    tase_rx_t rx;
} tk_stream_t;

typedef struct {
    uint64_t bytes;           /* bytes fed to receivers */
    uint64_t frames;          /* valid frames (printed) */
    uint64_t unknown;         /* of them: group/type not in the schema */
    uint64_t bad_length;      /* of them: wrong data length for the type */
    uint64_t checksum_errors; /* candidate frames with a bad checksum */
    uint64_t bad_size;        /* candidates with Size < 2 */
    uint64_t discarded;       /* bytes not part of any valid frame */
    uint64_t can_frames;      /* CAN frames seen */
    uint64_t can_other;       /* of them: not datalink frames (other IDs) */
    uint64_t paused;          /* held candidates cut short by a pause
                                 longer than their quiet limit */
} tk_counts_t;

typedef struct {
    tk_fmt_t fmt;
    FILE *out;
    uint64_t limit; /* print no frame after this many (they are counted), 0 none */
    /* The receivers' time bound (tase/frame.h, TIME BOUND): with by_time,
     * the times given to tk_dec_bytes()/tk_dec_can() are the clock (a
     * capture's record times: a gap in them settles a held candidate as
     * the live receiver did); otherwise the caller ticks (tk_dec_tick()).
     * serial_rate is a serial stream's byte rate (CAN streams: the
     * SocketCAN port's), margin_ms the time bound's margin (0: the
     * library's, TASE_RX_QUIET_MS). Set them before the first stream is
     * made. */
    bool by_time;
    uint32_t serial_rate;
    uint16_t margin_ms;
    tk_counts_t n;
    size_t nstreams;
    tk_stream_t stream[TK_STREAMS_MAX];
    /* the chunk being fed */
    tk_stream_t *cur;
    uint64_t base64;
    uint32_t base32;
    const tk_time_t *time;
    /* formatted lines not yet written to `out` */
    size_t olen;
    char obuf[1u << 16];
} tk_dec_t;

/* Initialise: no streams, counters zero, output to `out` in `fmt`,
 * ticked by the caller, serial streams at 57600 baud. */
void tk_dec_init(tk_dec_t *d, const tk_fmt_t *fmt, FILE *out);
/* The stream of (iface, dir), created on first use ("" / NULL for a
 * serial line); NULL when TK_STREAMS_MAX streams exist already. `dir` must
 * be a string constant. */
tk_stream_t *tk_dec_stream(tk_dec_t *d, const char *iface, const char *dir);
/* Feed bytes of one stream that arrived at `time` (NULL unknown). The
 * frames they complete are written to `out` (stdio) before it returns. */
void tk_dec_bytes(tk_dec_t *d, tk_stream_t *s, const uint8_t *data, size_t n,
                  const tk_time_t *time);
/* Feed one CAN frame seen on `iface`: datalink frames (ID 0x11000000 to
 * the gimbal, 0x10000000 from it) go to that interface's stream of their
 * direction, others are only counted. Returns false when no stream could
 * be created (too many interfaces). */
bool tk_dec_can(tk_dec_t *d, const char *iface, const tase_can_frame_t *f, const tk_time_t *time);
/* The receiver's clock (tase_rx_tick()): call after feeding bytes that
 * arrived at now_ms and after a read that found the line quiet until
 * now_ms; a candidate held past its quiet limit is settled and its frames
 * written out. */
void tk_dec_tick(tk_dec_t *d, tk_stream_t *s, uint32_t now_ms);
/* End of input: settle every stream's pending frames. */
void tk_dec_finish(tk_dec_t *d);
/* One summary line on `out` ("tase: summary: N frames, ..." and `extra`). */
void tk_dec_summary(const tk_dec_t *d, FILE *out, const char *extra);

/* ---- offsets ---- */

/* The 64-bit stream offset of a 32-bit one (the library's offsets wrap
 * modulo 2^32), given a reference point: the stream held base64 bytes
 * when its 32-bit count was base32, and off32 lies within 2^31 of it. */
uint64_t tk_offset64(uint64_t base64, uint32_t base32, uint32_t off32);

#endif /* TASE_TOOLS_TOOLKIT_H */
