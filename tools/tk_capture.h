/*
 * tools/tk_capture.h - the bench tools' capture files (tools-private, Linux,
 * libpcap). Not part of the library's API.
 *
 * FORMAT. Captures are pcap files written through libpcap with nanosecond
 * timestamps (the host's wall clock, CLOCK_REALTIME, taken when the read
 * that returned the bytes came back; for CAN the kernel's receive time).
 * Readers take pcap and pcapng (libpcap converts the timestamps).
 *
 *   - Serial: link type TK_CAP_LINKTYPE_SERIAL (LINKTYPE_USER0, 147). One
 *     record per read() (or per write of the tool's own transmissions),
 *     byte-exact: a one-byte pseudo-header, then the bytes.
 *         byte 0   direction: TK_CAP_FROM_GIMBAL (0x00, JSON "dir":"out")
 *                             TK_CAP_TO_GIMBAL   (0x01, JSON "dir":"in")
 *                  any other value is an error in the record
 *         byte 1.. the bytes as they were read or written (at least one)
 *   - CAN: link type LINKTYPE_CAN_SOCKETCAN (227), the standard layout
 *     Wireshark's CAN dissector reads: 4-byte identifier with the
 *     SocketCAN EFF/RTR/ERR flags in its top bits (big-endian), payload
 *     length, FD flags, two reserved bytes, then the data: 16-byte records
 *     for classic frames, 72-byte records for CAN FD frames, exactly as
 *     the kernel's struct can_frame / canfd_frame with the identifier
 *     stored big-endian. Every frame on the interface is recorded (error
 *     frames included).
 *
 * JSON and replay use the toolkit's microsecond tk_time_t (the files keep
 * nanoseconds). Every function prints one line and exits (tk_die) on an
 * error it cannot recover from, like the rest of the toolkit; malformed
 * records in a capture being read are reported to the caller instead, so a
 * decode can go on with the rest.
 */
#ifndef TASE_TOOLS_TK_CAPTURE_H
#define TASE_TOOLS_TK_CAPTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <time.h>

#include "toolkit.h"

#define TK_CAP_LINKTYPE_SERIAL 147 /* LINKTYPE_USER0: TASE serial, see above */
#define TK_CAP_LINKTYPE_CAN 227    /* LINKTYPE_CAN_SOCKETCAN */
#define TK_CAP_FROM_GIMBAL 0u      /* serial pseudo-header: bytes sent by the gimbal */
#define TK_CAP_TO_GIMBAL 1u        /* serial pseudo-header: bytes sent to the gimbal */
#define TK_CAP_CAN_HEADER 8u       /* bytes before a CAN record's data */
#define TK_CAP_CAN_MAX 72u         /* a CAN FD record */

/* Replay/record selection of directions. */
typedef enum {
    TK_CAP_DIR_OUT = 1, /* from the gimbal */
    TK_CAP_DIR_IN = 2,  /* to the gimbal */
    TK_CAP_DIR_ALL = 3  /* both; for CAN every frame, whatever its ID */
} tk_cap_dirs_t;

/* ---- writing ---- */

typedef struct {
    void *pcap;   /* pcap_t of pcap_open_dead() (a new capture) */
    void *dumper; /* pcap_dumper_t (a new capture) */
    /* appending (tk_cap_create()'s `append`): whole records written to an
     * O_APPEND descriptor, one write a flush, in the file's byte order
     * and time precision */
    int afd; /* -1 when not appending */
    uint8_t *abuf;
    size_t alen;
    bool big;
    bool nano;
    bool open;
    const char *path;
    int linktype;
    unsigned long records;
    /* a new capture is written to tmp ("PATH.partial-PID") and renamed to
     * path when it is complete: an existing file at path is never touched
     * by a recording that fails or is killed (the partial file stays) */
    char tmp[4096];
    int err;   /* the errno of the first failed write (recording stopped), 0 none */
    long good; /* file length after the last whole record flushed, -1 unknown */
} tk_cap_writer_t;

/* Start a new capture for `path`: a new or regular file is written to
 * w->tmp and renamed to path by tk_cap_close()/tk_cap_finish() when
 * complete (until then an existing file at path is untouched; a failed
 * finish keeps the partial file and says where), anything else (a device,
 * a FIFO) is written in place; or with `append` add to path itself, a
 * regular file (created when it does not exist; an existing one must be a
 * classic pcap of the same link type, whose records are then written in
 * its byte order and time precision, each flush one O_APPEND write of
 * whole records, so that other programs appending to it do not overwrite
 * them). A record a crash or a full disk cut short at its end is cut off
 * first (said on stderr); a damaged record header anywhere is refused,
 * the file left as it is. Dies with the reason on failure. */
void tk_cap_create(tk_cap_writer_t *w, const char *path, int linktype, bool append);
/* One serial record: direction byte + n (>= 1) bytes, at wall-clock time t. */
void tk_cap_put_serial(tk_cap_writer_t *w, const struct timespec *t, unsigned dir,
                       const uint8_t *data, size_t n);
/* One CAN record: `rec` is a SocketCAN struct can_frame (16 bytes) or
 * canfd_frame (72 bytes) exactly as read from a raw socket, identifier in
 * host byte order (it is written big-endian). */
void tk_cap_put_can(tk_cap_writer_t *w, const struct timespec *t, const uint8_t *rec, size_t n);
/* Push buffered records to the file. Returns false on a write error (a
 * full disk): w->err says which; stop recording and close, which reports
 * it. */
bool tk_cap_flush(tk_cap_writer_t *w);
/* Flush and close; dies on a write error, or one tk_cap_flush() met,
 * after tk_cap_finish() has kept what it could; a pipe whose reader went
 * away (EPIPE) ends the program quietly with 128 + SIGPIPE instead. */
void tk_cap_close(tk_cap_writer_t *w);
/* The same without dying (for exit handlers): returns 0 or an errno (the
 * first write error). After an error the file written ends at its last
 * whole record, and a new capture's partial file is kept and named on
 * stderr. */
int tk_cap_finish(tk_cap_writer_t *w);

/* A port that records what passes through `inner` into `w` (reads as
 * TK_CAP_FROM_GIMBAL, accepted writes as TK_CAP_TO_GIMBAL) and is
 * otherwise `inner` itself. `tap` must outlive the port.
 * Its records are stamped on the port's own millisecond clock (now_ms),
 * carried to wall-clock time by the offset seen at the first record: a
 * receiver ticked at `last_read_ms` (the port time of the last read
 * recorded) decides every quiet gap exactly as `tase decode` of the
 * capture does from the record times (both differences of the same whole
 * milliseconds). Times in such a capture have millisecond resolution and
 * follow the port's clock, not later steps of the wall clock. */
typedef struct {
    tase_port_t inner;
    tk_cap_writer_t *w;
    bool based;      /* base_ns and base_ms set */
    int64_t base_ns; /* wall-clock ns (a whole ms) at port time base_ms */
    uint32_t base_ms;
    uint32_t last_read_ms;       /* the port time of the last read recorded */
    struct timespec last_read_t; /* and its record time */
    bool read_recorded;          /* last_read_ms and last_read_t are set */
} tk_cap_tap_t;
tase_port_t tk_cap_tap_port(tk_cap_tap_t *tap, tase_port_t inner, tk_cap_writer_t *w);
/* --record FILE: append this process's serial session to FILE (a tap port
 * over `inner`, the capture closed by an exit handler, which reports a
 * write error on stderr and exits 1). Once per run. */
tase_port_t tk_cap_record_session(const char *path, tase_port_t inner);
/* Whether this run records its session (--record) and has recorded a
 * read: then *ms is the port time of the last read recorded and *t its
 * record time (what `tase decode` of the capture will see). */
bool tk_cap_session_last_read(uint32_t *ms, struct timespec *t);

/* ---- reading ---- */

/* Whether the first bytes of a file are a pcap or pcapng header (n >= 4). */
bool tk_cap_is_capture(const uint8_t *head, size_t n);

typedef struct {
    void *pcap;
    int linktype;   /* TK_CAP_LINKTYPE_SERIAL or TK_CAP_LINKTYPE_CAN */
    bool pcapng;    /* else classic pcap */
    bool usec;      /* a classic pcap whose fractions are microseconds */
    tk_time_t last; /* the time of the record read last */
    const char *path;
    unsigned long index; /* records read so far */
} tk_cap_reader_t;

/* Open a capture on descriptor `fd` (a file or a pipe; not closed here),
 * of which head[0..nhead) were read already (the caller looked at the
 * magic): they are read again first. `path` names it in messages. Dies
 * when libpcap cannot read it or its link type is neither of the two. */
void tk_cap_reader_open(tk_cap_reader_t *r, int fd, const uint8_t *head, size_t nhead,
                        const char *path);
void tk_cap_reader_close(tk_cap_reader_t *r);

typedef struct {
    unsigned long index; /* 1-based record number in the file */
    tk_time_t t;         /* capture time, to the microsecond */
    /* serial records */
    unsigned dir;        /* TK_CAP_FROM_GIMBAL or TK_CAP_TO_GIMBAL */
    const uint8_t *data; /* valid until the next call */
    size_t len;
    /* CAN records */
    uint32_t can_id; /* identifier with the SocketCAN flag bits */
    bool can_data;   /* a classic data frame: `frame` holds it */
    tase_can_frame_t frame;
} tk_cap_rec_t;

#define TK_CAP_END 0
#define TK_CAP_RECORD 1
#define TK_CAP_BAD 2       /* malformed record: `why` says what; the next call goes on */
#define TK_CAP_ERROR 3     /* the file can be read no further: `why` says why, naming it */
#define TK_CAP_WHY_MAX 400 /* room for any `why` (a path is in TK_CAP_ERROR's) */

/* Next record. Returns TK_CAP_RECORD, TK_CAP_END, TK_CAP_BAD with a
 * reason in why[0..cap) (rec->index set), or TK_CAP_ERROR with the whole
 * message ("PATH: after record N: ...") in why: a read error or a file cut
 * inside a record (what came before it is good: a caller decodes it, then
 * says this). A signal that broke off the read exits as that signal. */
int tk_cap_next(tk_cap_reader_t *r, tk_cap_rec_t *rec, char *why, size_t cap);

/* ---- record and replay loops ---- */

/* Record the serial device `dev` (bytes from the gimbal) and optionally a
 * second device `tap_in` (bytes to the gimbal, the other line of a tap)
 * into a new capture `path` (through `w`, tk_cap_create()) until `seconds`
 * pass or, with 0, until a signal the toolkit catches (tk_signal: SIGINT,
 * SIGTERM, SIGHUP, the normal end of a recording). The devices are opened
 * first: one that cannot be opened ends the command before anything is
 * written. Closes `w` and prints a summary on stdout. */
void tk_cap_record_serial(tk_cap_writer_t *w, const char *path, const char *dev, const char *tap_in,
                          long baud, double seconds);
/* Record every frame of CAN interface `iface` likewise. */
void tk_cap_record_can(tk_cap_writer_t *w, const char *path, const char *iface, double seconds);

/* Send the records of `r` selected by `dirs` to a serial device (the
 * bytes) or, with `can` non-NULL, to a CAN interface (frames as recorded;
 * serial bytes cut into frames of their direction's ID), at the capture's
 * timing divided by `speed` (0: no waiting). Prints a summary on stdout;
 * a caught signal stops it (the caller then exits 128 + N). Sends at most
 * the first `records` records (those tk_cap_check() read: not what was
 * appended since). Returns the number of malformed records skipped (each
 * reported on stderr). */
typedef struct {
    const char *serial; /* device, or NULL */
    long baud;
    const char *can; /* interface, or NULL */
    tk_cap_dirs_t dirs;
    double speed;
    unsigned long records; /* in the capture (tk_cap_check() counted them) */
} tk_replay_opts_t;
/* A wait between two records (at --speed) that tk_cap_check() warns of. */
#define TK_REPLAY_LONG_WAIT_S 60.0
unsigned long tk_cap_replay(tk_cap_reader_t *r, const tk_replay_opts_t *o);
/* The check replay makes before sending anything: read every record of r
 * (dies, naming the record, on a file cut inside a record header), warn
 * about each bad record and return their count, and count in *backward
 * the records (of those o selects) stamped earlier than the one before,
 * warning about the first three (replay sends them right after it and
 * keeps the gaps after them); the first three waits of
 * TK_REPLAY_LONG_WAIT_S or more are warned of too. */
unsigned long tk_cap_check(tk_cap_reader_t *r, const tk_replay_opts_t *o, unsigned long *backward);

#endif /* TASE_TOOLS_TK_CAPTURE_H */
