/* Capture files of the bench tools: pcap through libpcap (format in
 * tk_capture.h), written and read. The loops that record and replay them
 * are in tk_record.c. */
#define _GNU_SOURCE 1 /* fopencookie: libpcap reads a pipe whose head we consumed */

#include "tk_capture.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <pcap/pcap.h>

#include "tase/can.h"
#include "toolkit.h"

#define SERIAL_SNAPLEN 65535
#define READ_CHUNK 4096u

/* ---- writing ---- */

/* ---- appending (--record) ----
 * A capture is appended to by writes of whole records to a descriptor
 * opened O_APPEND, one write(2) a flush: two programs recording the same
 * session into one file (`tase monitor --record` beside `tase point
 * --record`, or a Python Link's recording) put their records between each
 * other's, never over them. (libpcap's append seeks to the end it saw at
 * the start and writes through stdio, which flushes where its buffer
 * fills, so a second writer overwrote the first.) */

#define APPEND_BUF 65536u

typedef struct {
    bool big;  /* byte order of the file's fields */
    bool nano; /* fractions in nanoseconds, else microseconds */
    uint32_t snaplen;
    uint32_t linktype;
} cap_head_t;

static uint32_t get32(const uint8_t *p, bool big)
{
    return big ? ((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3])
               : ((uint32_t)p[3] << 24 | (uint32_t)p[2] << 16 | (uint32_t)p[1] << 8 | p[0]);
}

static void put32(uint8_t *p, uint32_t v, bool big)
{
    unsigned i;
    for (i = 0; i < 4u; i++) {
        p[big ? i : 3u - i] = (uint8_t)(v >> (24u - 8u * i));
    }
}

/* The fields of a classic pcap file header; false when it is not one
 * (pcapng, or not a capture). */
static bool cap_head_parse(const uint8_t h[24], cap_head_t *c)
{
    if (((h[0] == 0xD4u && h[1] == 0xC3u) || (h[0] == 0x4Du && h[1] == 0x3Cu)) && h[2] == 0xB2u &&
        h[3] == 0xA1u) {
        c->big = false;
        c->nano = h[0] == 0x4Du;
    } else if (h[0] == 0xA1u && h[1] == 0xB2u &&
               ((h[2] == 0xC3u && h[3] == 0xD4u) || (h[2] == 0x3Cu && h[3] == 0x4Du))) {
        c->big = true;
        c->nano = h[3] == 0x4Du;
    } else {
        return false;
    }
    c->snaplen = get32(h + 16, c->big);
    c->linktype = get32(h + 20, c->big) & 0x03FFFFFFu; /* as libpcap: the low 26 bits name it */
    return true;
}

/* The largest record a capture's header allows: its snapshot length, 0
 * or above libpcap's maximum (262144) read as that maximum, as libpcap
 * reads them. */
#define PCAP_MAX_SNAPLEN 262144u
static uint32_t cap_limit(const cap_head_t *c)
{
    return (c->snaplen == 0u || c->snaplen > PCAP_MAX_SNAPLEN) ? PCAP_MAX_SNAPLEN : c->snaplen;
}

/* Scan the records of an existing classic pcap file from `at` (a record
 * boundary; *index records before it) to `size`: returns where its whole
 * records end, the 16-byte header and data of each complete. A record that
 * runs past the end of the file with a sound header is what a crash or a
 * full disk leaves (the caller cuts it off); a header no writer writes
 * (more data than the snapshot length allows or than the packet's length)
 * is damage in the middle of a file, not a cut: returns -1 with its number
 * in *index, and nothing may be cut (41 KB of a file behind a damaged
 * header were removed as if a crash had cut it). */
static long whole_records_len(int fd, long at, long size, const cap_head_t *c, unsigned long *index)
{
    while (at + 16 <= size) {
        uint8_t r[16];
        uint32_t caplen, len;
        if (pread(fd, r, sizeof(r), (off_t)at) != (ssize_t)sizeof(r)) {
            break;
        }
        caplen = get32(r + 8, c->big);
        len = get32(r + 12, c->big);
        if (caplen > cap_limit(c) || caplen > len) {
            ++*index;
            return -1;
        }
        if ((long)caplen > size - at - 16) {
            break; /* its data runs past the end */
        }
        at += 16 + (long)caplen;
        ++*index;
    }
    return at;
}

/* flock() that a caught signal ends (tk_exit_if_signalled(): exit 128+N)
 * and that says once when it waits for another program. */
static void lock_capture(int fd, const char *path)
{
    bool said = false;
    while (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        if (errno != EWOULDBLOCK && errno != EINTR) {
            tk_die("cannot lock capture %s: %s", path, strerror(errno));
        }
        tk_exit_if_signalled();
        if (!said) {
            tk_warn("%s is being written by another program: waiting for it", path);
            said = true;
        }
        {
            struct timespec ts = {0, 10000000};
            nanosleep(&ts, NULL);
        }
    }
}

/* The header of a capture `--record` is to append `linktype` records to,
 * read into *c; a file of another kind, link type or a snapshot length
 * too small for our records is refused (fd closed, exit 1) with what is
 * wrong. Used before the lock and again under it for a header another
 * program may have written meanwhile. */
static void append_head_check(int fd, const char *path, int linktype, cap_head_t *c)
{
    uint8_t h[24];
    if (pread(fd, h, sizeof(h), 0) != (ssize_t)sizeof(h) || !cap_head_parse(h, c)) {
        (void)close(fd);
        tk_die("cannot write capture %s: not a classic pcap file (--record appends only to "
               "one; give a new file name)",
               path);
    }
    if (c->linktype != (uint32_t)linktype) {
        (void)close(fd);
        tk_die("cannot write capture %s: its link type is %lu, not TASE serial (%d): give a "
               "new file name",
               path, (unsigned long)c->linktype, linktype);
    }
    if (cap_limit(c) < 1u + READ_CHUNK) {
        (void)close(fd);
        tk_die("cannot write capture %s: its snapshot length (%lu bytes) is below the %u "
               "bytes a record of ours may take: give a new file name",
               path, (unsigned long)c->snaplen, 1u + READ_CHUNK);
    }
}

/* Open `path` for appending records of `linktype` (a new file gets a
 * nanosecond header): checked and, when a crash or a full disk cut it
 * inside its last record, cut back to its last whole record (every new
 * record would be unreadable behind the partial one), said on stderr. The
 * file is scanned first without the lock (a long capture takes a while,
 * and every other recorder waits for the lock); under the lock every
 * writer of ours holds for a write, only what was added since and the
 * tail are scanned again, so that two of our programs neither both write
 * a header nor cut a record the other is writing. */
static void append_open(tk_cap_writer_t *w, const char *path, int linktype)
{
    struct stat st;
    uint8_t h[24];
    cap_head_t c = {false, true, SERIAL_SNAPLEN, (uint32_t)linktype};
    int fd = open(path, O_RDWR | O_APPEND | O_CLOEXEC);
    int e = 0;
    long at = 24, keep;
    unsigned long index = 0;
    sigset_t held;
    bool made = false;
    if (fd < 0 && errno == ENOENT) {
        /* a file this call makes is not left empty, without its header, by
         * a signal that ends the process (a 0-byte FILE is no capture):
         * such a signal waits until the header is written (the lock below
         * is held by other writers for one write at a time) */
        tk_hold_fatal_signals(&held);
        fd = open(path, O_RDWR | O_APPEND | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        made = fd >= 0;
        if (!made) {
            int err = errno;
            tk_release_fatal_signals(&held);
            errno = err;
            if (errno == EEXIST) { /* another program made it meanwhile */
                fd = open(path, O_RDWR | O_APPEND | O_CLOEXEC);
            }
        }
    }
    if (fd < 0) {
        tk_die("cannot write capture %s: %s", path, strerror(errno));
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        (void)close(fd);
        tk_die("cannot write capture %s: not a regular file (--record appends to a file; "
               "'tase record -o' writes to a pipe or a device)",
               path);
    }
    if (st.st_size > 0) {
        append_head_check(fd, path, linktype, &c);
        at = whole_records_len(fd, 24, (long)st.st_size, &c, &index);
        if (at < 0) { /* looked at again under the lock: a write under way? */
            at = 24;
            index = 0;
        }
    }
    lock_capture(fd, path);
    if (fstat(fd, &st) != 0) {
        e = errno;
    } else if (st.st_size == 0) {
        /* new or empty: ours to start (another program may have written
         * the header since our open: then it is checked below) */
        memset(h, 0, sizeof(h));
        put32(h, 0xA1B23C4Du, false);
        h[4] = 2; /* version 2.4, little-endian */
        h[6] = 4;
        put32(h + 16, SERIAL_SNAPLEN, false);
        put32(h + 20, (uint32_t)linktype, false);
        errno = 0;
        if (write(fd, h, sizeof(h)) != (ssize_t)sizeof(h)) {
            e = errno != 0 ? errno : ENOSPC;
            (void)ftruncate(fd, 0);
            if (fstat(fd, &st) == 0 && st.st_size == 0) {
                (void)unlink(path); /* empty: nobody's capture */
            }
        }
        at = -2; /* nothing to scan */
    }
    if (e == 0 && at != -2) {
        if (at == 24 && index == 0) {
            /* empty at open, or no record looked at: the header may be
             * another program's, written meanwhile */
            append_head_check(fd, path, linktype, &c);
        }
        keep = whole_records_len(fd, at, (long)st.st_size, &c, &index);
        if (keep < 0) {
            (void)close(fd);
            tk_die("cannot write capture %s: its record %lu is damaged (not the end of a file a "
                   "crash cut short): not appending, the file is left as it is",
                   path, index);
        }
        if (keep < (long)st.st_size) {
            if (ftruncate(fd, (off_t)keep) != 0) {
                tk_die("cannot repair capture %s: %s", path, strerror(errno));
            }
            tk_warn("%s ended inside a record (a full disk or a crash?): %ld bytes of it removed "
                    "before appending",
                    path, (long)st.st_size - keep);
        }
    }
    (void)flock(fd, LOCK_UN);
    if (made) {
        tk_release_fatal_signals(&held);
    }
    if (e != 0) {
        (void)close(fd);
        tk_die("cannot write capture %s: %s", path, strerror(e));
    }
    w->abuf = malloc(APPEND_BUF);
    if (w->abuf == NULL) {
        tk_die("cannot write capture %s: out of memory", path);
    }
    w->afd = fd;
    w->alen = 0;
    w->big = c.big;
    w->nano = c.nano;
}

/* One append of the whole records buffered, under the lock; a write a
 * full disk cut short is cut off the file again (when nothing was
 * appended behind it), and the reason is the errno of the write that
 * failed (a short count has none). */
static bool append_flush(tk_cap_writer_t *w)
{
    size_t done = 0;
    bool locked = true;
    if (w->alen == 0u) {
        return true;
    }
    /* under the lock every writer of ours takes for a write (the Python
     * package's too), so that append_open() never takes another's record
     * in progress for one a crash cut short. A caught signal ends the wait
     * (a holder stopped with SIGSTOP would hold Ctrl-C up for good): the
     * records are written without the lock then (a holder is past its
     * write, which a stop does not cut), and the signal is seen after. */
    while (flock(w->afd, LOCK_EX) != 0) {
        if (errno != EINTR || tk_signal != 0) {
            locked = false;
            break;
        }
    }
    while (done < w->alen) {
        ssize_t k = write(w->afd, w->abuf + done, w->alen - done);
        if (k > 0) {
            done += (size_t)k;
        } else if (k < 0 && errno == EINTR) {
            continue;
        } else {
            struct stat st;
            off_t end = lseek(w->afd, 0, SEEK_CUR);
            w->err = (k < 0) ? errno : ENOSPC;
            if (done > 0u && end >= (off_t)done && fstat(w->afd, &st) == 0 && st.st_size == end) {
                (void)ftruncate(w->afd, end - (off_t)done);
            }
            break;
        }
    }
    if (locked) {
        (void)flock(w->afd, LOCK_UN);
    }
    w->alen = 0;
    return w->err == 0;
}

static void append_record(tk_cap_writer_t *w, const struct timespec *t, const uint8_t *rec,
                          size_t n)
{
    uint8_t *h;
    if (w->alen + 16u + n > APPEND_BUF && !append_flush(w)) {
        return;
    }
    h = w->abuf + w->alen;
    put32(h, (uint32_t)t->tv_sec, w->big);
    put32(h + 4, (uint32_t)(w->nano ? t->tv_nsec : t->tv_nsec / 1000), w->big);
    put32(h + 8, (uint32_t)n, w->big);
    put32(h + 12, (uint32_t)n, w->big);
    memcpy(h + 16, rec, n);
    w->alen += 16u + n;
    w->records++;
}

/* ---- writing a new capture ---- */

void tk_cap_create(tk_cap_writer_t *w, const char *path, int linktype, bool append)
{
    int snaplen = linktype == TK_CAP_LINKTYPE_CAN ? (int)TK_CAP_CAN_MAX : SERIAL_SNAPLEN;
    pcap_t *p;
    pcap_dumper_t *d;
    struct stat st;
    /* the path itself, not what a symlink names: a rename onto a symlink
     * replaces the link (`-o /dev/stdout` into a file, as root, turned
     * /dev/stdout into a regular file) */
    bool existed = lstat(path, &st) == 0;
    w->tmp[0] = '\0';
    w->err = 0;
    w->good = -1;
    w->afd = -1;
    w->path = path;
    w->linktype = linktype;
    w->records = 0;
    if (append) {
        append_open(w, path, linktype);
        w->open = true;
        return;
    }
    p = pcap_open_dead_with_tstamp_precision(linktype, snaplen, PCAP_TSTAMP_PRECISION_NANO);
    if (p == NULL) {
        tk_die("cannot start a capture: out of memory");
    }
    /* a temporary file and a rename only for a regular file (or a new
     * one): a device, a FIFO, a symlink (/dev/stdout) is written in place
     * (through the link), never replaced by a rename */
    if (existed ? S_ISREG(st.st_mode) : errno == ENOENT) {
        int k;
        /* the rename would replace a FILE that an open for writing is
         * refused (made read-only by its user): refused as that open */
        if (existed && faccessat(AT_FDCWD, path, W_OK, AT_EACCESS) != 0) {
            tk_die("cannot write capture %s: %s (it is not writable; record replaces it)", path,
                   strerror(errno));
        }
        k = snprintf(w->tmp, sizeof(w->tmp), "%s.partial-%ld", path, (long)getpid());
        if (k < 0 || (size_t)k >= sizeof(w->tmp)) {
            tk_die("cannot write capture %s: the path is too long", path);
        }
    }
    errno = 0;
    d = pcap_dump_open(p, w->tmp[0] != '\0' ? w->tmp : path);
    if (d == NULL) {
        int e = errno;
        /* nothing recorded: a file this call created goes again (a full
         * disk leaves it empty or cut inside the file header) */
        if (w->tmp[0] != '\0') {
            (void)unlink(w->tmp);
        }
        if (e == EINTR) {
            tk_exit_if_signalled(); /* Ctrl-C while a FIFO waits for a reader */
        }
        if (e != 0 && w->tmp[0] != '\0') {
            /* the file that could not be made is the one beside FILE */
            tk_die("cannot write capture %s: cannot create %s beside it: %s", path, w->tmp,
                   strerror(e));
        }
        if (e != 0) {
            tk_die("cannot write capture %s: %s", path, strerror(e));
        }
        tk_die("cannot write capture %s: %s", path, pcap_geterr(p));
    }
    w->pcap = p;
    w->dumper = d;
    w->good = ftell(pcap_dump_file(d)); /* the end of the last whole record */
    w->open = true;
}

static void put_record(tk_cap_writer_t *w, const struct timespec *t, const uint8_t *rec, size_t n)
{
    struct pcap_pkthdr h;
    if (w->afd >= 0) {
        append_record(w, t, rec, n);
        return;
    }
    memset(&h, 0, sizeof(h));
    h.ts.tv_sec = t->tv_sec;
    h.ts.tv_usec = (suseconds_t)t->tv_nsec; /* nanoseconds: the dumper's precision */
    h.caplen = (bpf_u_int32)n;
    h.len = (bpf_u_int32)n;
    pcap_dump((u_char *)w->dumper, &h, rec);
    w->records++;
}

void tk_cap_put_serial(tk_cap_writer_t *w, const struct timespec *t, unsigned dir,
                       const uint8_t *data, size_t n)
{
    uint8_t rec[1u + READ_CHUNK];
    while (n > 0) { /* longer writes become several records (never by reads) */
        size_t k = n < READ_CHUNK ? n : READ_CHUNK;
        rec[0] = (uint8_t)dir;
        memcpy(rec + 1, data, k);
        put_record(w, t, rec, k + 1u);
        data += k;
        n -= k;
    }
}

void tk_cap_put_can(tk_cap_writer_t *w, const struct timespec *t, const uint8_t *rec, size_t n)
{
    uint8_t out[TK_CAP_CAN_MAX];
    uint32_t id;
    if (n < TK_CAP_CAN_HEADER || n > sizeof(out)) {
        return;
    }
    memcpy(out, rec, n);
    memcpy(&id, rec, sizeof(id)); /* host byte order in the kernel's struct */
    out[0] = (uint8_t)(id >> 24);
    out[1] = (uint8_t)(id >> 16);
    out[2] = (uint8_t)(id >> 8);
    out[3] = (uint8_t)id;
    put_record(w, t, out, n);
}

bool tk_cap_flush(tk_cap_writer_t *w)
{
    if (w->err != 0) {
        return false;
    }
    if (w->afd >= 0) {
        return append_flush(w);
    }
    errno = 0;
    if (pcap_dump_flush(w->dumper) != 0) {
        w->err = errno != 0 ? errno : EIO;
        return false;
    }
    w->good = ftell(pcap_dump_file(w->dumper)); /* a record boundary */
    return true;
}

int tk_cap_finish(tk_cap_writer_t *w)
{
    FILE *f;
    int e;
    w->open = false;
    if (w->afd >= 0) {
        if (w->err == 0) {
            (void)append_flush(w);
        }
        e = w->err;
        if (fsync(w->afd) != 0 && e == 0) {
            e = errno; /* a full or failing disk may only tell here */
        }
        if (close(w->afd) != 0 && e == 0) {
            e = errno;
        }
        w->afd = -1;
        free(w->abuf);
        w->abuf = NULL;
        return e;
    }
    f = pcap_dump_file(w->dumper);
    e = w->err; /* the first failure, not the close's */
    if (e == 0 && (fflush(f) != 0 || ferror(f))) {
        e = errno != 0 ? errno : EIO;
    }
    if (fsync(fileno(f)) != 0 && errno != EINVAL && e == 0) {
        e = errno; /* a full or failing disk may only tell here */
    }
    pcap_dump_close(w->dumper); /* fclose() */
    pcap_close(w->pcap);
    w->dumper = NULL;
    w->pcap = NULL;
    if (e != 0 && w->good > 0) {
        /* end the file at its last whole record: readable, and what a
         * later --record appends to follows it */
        (void)truncate(w->tmp[0] != '\0' ? w->tmp : w->path, (off_t)w->good);
    }
    if (w->tmp[0] != '\0') {
        if (e == 0 && rename(w->tmp, w->path) != 0) {
            e = errno;
        }
        if (e != 0 && w->good >= 0 && w->good <= 24) {
            /* no record reached the disk (24: the file header) */
            (void)unlink(w->tmp);
            fflush(stdout);
            fprintf(stderr, "%s: nothing was recorded; %s is unchanged\n", tk_prog, w->path);
        } else if (e != 0) {
            fflush(stdout);
            fprintf(stderr, "%s: the capture so far is kept in %s; %s is unchanged\n", tk_prog,
                    w->tmp, w->path);
        } else {
            /* renamed */
        }
    }
    return e;
}

void tk_cap_close(tk_cap_writer_t *w)
{
    int e = tk_cap_finish(w);
    if (e == EPIPE) {
        tk_exit_broken_pipe(); /* `tase record -o - | head -c 100` */
    }
    if (e != 0) {
        tk_die("cannot write capture %s: %s", w->path, strerror(e));
    }
}

/* The record time of port time `ms` (tk_cap_tap_t): the wall clock's at
 * the tap's base plus the port clock's time since. A mapping more than
 * TAP_DRIFT_MS away from the wall clock starts again from it: the port's
 * clock stood still while the computer slept (CLOCK_MONOTONIC), the wall
 * clock was stepped, or no record came for 2^31 ms. Across such a
 * restart `tase decode` measures the wall clock's gap, the live receiver
 * the port's. */
#define TAP_DRIFT_MS 1000
static struct timespec tap_time(tk_cap_tap_t *tap, uint32_t ms)
{
    struct timespec t;
    int64_t ns, wall;
    clock_gettime(CLOCK_REALTIME, &t);
    wall = ((int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000) * 1000000; /* whole ms */
    ns = tap->base_ns + (int64_t)(int32_t)(ms - tap->base_ms) * 1000000;
    if (!tap->based || ns - wall > (int64_t)TAP_DRIFT_MS * 1000000 ||
        wall - ns > (int64_t)TAP_DRIFT_MS * 1000000) {
        tap->base_ns = wall;
        tap->base_ms = ms;
        tap->based = true;
        ns = wall;
    } else if ((uint32_t)(ms - tap->base_ms) >= 0x40000000u &&
               (uint32_t)(ms - tap->base_ms) < 0x80000000u) {
        /* 12 days on: the base follows, so that the 32-bit port clock's
         * difference never reaches 2^31 ms in a session of months */
        tap->base_ns = ns;
        tap->base_ms = ms;
    }
    t.tv_sec = (time_t)(ns / 1000000000);
    t.tv_nsec = (long)(ns % 1000000000);
    return t;
}

/* Record what the tapped link moved. A capture that cannot be written
 * (a full disk) stops recording but not the command: the packet it sends
 * still goes out and is reported, and the failure is reported at exit
 * (close_session_capture()) with the status that says whether a packet
 * was sent. The time of the last read is kept for
 * tk_cap_session_last_read() either way. */
static void tap_record(tk_cap_tap_t *tap, unsigned dir, const uint8_t *data, size_t n)
{
    uint32_t ms = tap->inner.ops->now_ms(tap->inner.ctx);
    struct timespec t = tap_time(tap, ms);
    if (dir == TK_CAP_FROM_GIMBAL) {
        tap->last_read_ms = ms;
        tap->last_read_t = t;
        tap->read_recorded = true;
    }
    if (tap->w->err != 0) {
        return;
    }
    tk_cap_put_serial(tap->w, &t, dir, data, n);
    (void)tk_cap_flush(tap->w); /* a failure stays in w->err */
}

static int tap_write(void *ctx, const uint8_t *data, size_t n)
{
    tk_cap_tap_t *tap = ctx;
    int rc = tap->inner.ops->write(tap->inner.ctx, data, n);
    if (rc > 0) {
        tap_record(tap, TK_CAP_TO_GIMBAL, data, (size_t)rc);
    }
    return rc;
}

static int tap_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    tk_cap_tap_t *tap = ctx;
    int rc = tap->inner.ops->read(tap->inner.ctx, buf, cap, timeout_ms);
    if (rc > 0) {
        tap_record(tap, TK_CAP_FROM_GIMBAL, buf, (size_t)rc);
    }
    return rc;
}

static uint32_t tap_now_ms(void *ctx)
{
    tk_cap_tap_t *tap = ctx;
    return tap->inner.ops->now_ms(tap->inner.ctx);
}

static const tase_port_ops_t tap_ops = {tap_write, tap_read, tap_now_ms};

tase_port_t tk_cap_tap_port(tk_cap_tap_t *tap, tase_port_t inner, tk_cap_writer_t *w)
{
    tase_port_t p;
    memset(tap, 0, sizeof(*tap));
    tap->inner = inner;
    tap->w = w;
    p.ops = &tap_ops;
    p.ctx = tap;
    p.bytes_per_s = inner.bytes_per_s;
    return p;
}

/* The --record capture of this process (one link per run), closed at exit. */
static tk_cap_writer_t session_capture;
static tk_cap_tap_t session_tap;

/* atexit: exit() must not be called again here */
static void close_session_capture(void)
{
    int e;
    if (!session_capture.open) {
        return;
    }
    e = tk_cap_finish(&session_capture);
    if (e != 0) {
        const char *sent = tk_sent();
        fflush(stdout);
        if (sent != NULL) {
            /* the packet went out: a retrying script must not send it again */
            fprintf(stderr, "%s: cannot write capture %s: %s (%s was sent)\n", tk_prog,
                    session_capture.path, strerror(e), sent);
            _exit(TK_EXIT_SENT);
        }
        fprintf(stderr, "%s: cannot write capture %s: %s\n", tk_prog, session_capture.path,
                strerror(e));
        _exit(TK_EXIT_FAIL);
    }
}

tase_port_t tk_cap_record_session(const char *path, tase_port_t inner)
{
    if (session_capture.open) {
        tk_die("only one link per run can be recorded");
    }
    tk_cap_create(&session_capture, path, TK_CAP_LINKTYPE_SERIAL, true);
    if (atexit(close_session_capture) != 0) {
        tk_die("cannot record %s: atexit failed", path);
    }
    return tk_cap_tap_port(&session_tap, inner, &session_capture);
}

bool tk_cap_session_last_read(uint32_t *ms, struct timespec *t)
{
    if (!session_capture.open || !session_tap.read_recorded) {
        return false;
    }
    *ms = session_tap.last_read_ms;
    *t = session_tap.last_read_t;
    return true;
}

/* ---- reading ---- */

/* The magic numbers of the captures libpcap reads here, big-endian. */
static const uint8_t cap_magics[][4] = {
    {0xA1, 0xB2, 0xC3, 0xD4}, /* pcap, microseconds */
    {0xA1, 0xB2, 0x3C, 0x4D}, /* pcap, nanoseconds */
    {0x0A, 0x0D, 0x0D, 0x0A}, /* pcapng section header block */
};
#define CAP_MAGIC_PCAP_US 0u

/* Whether head[0..4) is magic m in either byte order. */
static bool cap_magic_is(const uint8_t *head, const uint8_t *m)
{
    return memcmp(head, m, 4) == 0 ||
           (head[0] == m[3] && head[1] == m[2] && head[2] == m[1] && head[3] == m[0]);
}

bool tk_cap_is_capture(const uint8_t *head, size_t n)
{
    size_t i;
    if (n < 4) {
        return false;
    }
    for (i = 0; i < sizeof(cap_magics) / sizeof(cap_magics[0]); i++) {
        if (cap_magic_is(head, cap_magics[i])) {
            return true;
        }
    }
    return false;
}

/* libpcap reads a FILE; the caller has consumed the first bytes of the
 * descriptor (a pipe cannot seek back): a FILE that gives them back first,
 * then reads the descriptor. */
typedef struct {
    int fd;
    uint8_t *head;
    size_t n, pos;
} head_fd_t;

static ssize_t head_read(void *cookie, char *buf, size_t size)
{
    head_fd_t *h = cookie;
    if (h->pos < h->n) {
        size_t k = h->n - h->pos < size ? h->n - h->pos : size;
        memcpy(buf, h->head + h->pos, k);
        h->pos += k;
        return (ssize_t)k;
    }
    for (;;) {
        ssize_t got = read(h->fd, buf, size);
        if (got >= 0 || (errno == EIO && tk_read_eio_is_end(h->fd))) {
            return got < 0 ? 0 : got;
        }
        if (errno != EINTR || tk_signal != 0) {
            return -1;
        }
    }
}

static int head_close(void *cookie)
{
    head_fd_t *h = cookie;
    free(h->head);
    free(h);
    return 0; /* the descriptor is the caller's */
}

/* The reader open now: closed at exit when tk_die() ends the program
 * with it open (its cookie and head copy were left to the exit: a leak to
 * LeakSanitizer). One reader at a time is open in each program. */
static tk_cap_reader_t *open_reader;

static void close_open_reader(void)
{
    if (open_reader != NULL) {
        tk_cap_reader_close(open_reader);
    }
}

void tk_cap_reader_open(tk_cap_reader_t *r, int fd, const uint8_t *head, size_t nhead,
                        const char *path)
{
    static bool registered;
    static const cookie_io_functions_t io = {head_read, NULL, NULL, head_close};
    char err[PCAP_ERRBUF_SIZE];
    head_fd_t *h = calloc(1, sizeof(*h));
    pcap_t *p;
    FILE *in;
    int lt;
    memset(r, 0, sizeof(*r));
    r->path = path;
    if (!registered) {
        registered = atexit(close_open_reader) == 0;
    }
    if (h == NULL || (nhead > 0 && (h->head = malloc(nhead)) == NULL)) {
        tk_die("cannot read %s: out of memory", path);
    }
    h->fd = fd;
    if (nhead > 0) {
        memcpy(h->head, head, nhead);
    }
    h->n = nhead;
    in = fopencookie(h, "rb", io);
    if (in == NULL) {
        free(h->head);
        free(h);
        tk_die("cannot read %s: %s", path, strerror(errno));
    }
    err[0] = '\0';
    p = pcap_fopen_offline_with_tstamp_precision(in, PCAP_TSTAMP_PRECISION_NANO, err);
    if (p == NULL) {
        (void)fclose(in); /* frees h (head_close) */
        tk_die("%s: not a capture libpcap can read: %s", path, err);
    }
    lt = pcap_datalink(p);
    if (lt != TK_CAP_LINKTYPE_SERIAL && lt != TK_CAP_LINKTYPE_CAN) {
        const char *name = pcap_datalink_val_to_name(lt);
        pcap_close(p);
        tk_die("%s: link type %d (%s) is neither TASE serial (%d, USER0) nor "
               "SocketCAN (%d)",
               path, lt, name != NULL ? name : "unknown", TK_CAP_LINKTYPE_SERIAL,
               TK_CAP_LINKTYPE_CAN);
    }
    r->pcap = p;
    r->linktype = lt;
    r->pcapng = pcap_major_version(p) == 1; /* a pcapng section's version 1.0 */
    r->usec = nhead >= 4u && cap_magic_is(head, cap_magics[CAP_MAGIC_PCAP_US]);
    open_reader = r;
}

void tk_cap_reader_close(tk_cap_reader_t *r)
{
    if (r->pcap != NULL) {
        pcap_close(r->pcap); /* closes the FILE */
        r->pcap = NULL;
    }
    if (open_reader == r) {
        open_reader = NULL;
    }
}

static int parse_serial(const struct pcap_pkthdr *h, const uint8_t *d, tk_cap_rec_t *rec, char *why,
                        size_t cap)
{
    if (h->caplen < 2u) {
        snprintf(why, cap, "%s",
                 h->caplen == 0 ? "empty (no direction byte, no bytes)"
                                : "no bytes after the direction byte");
        return TK_CAP_BAD;
    }
    if (d[0] != TK_CAP_FROM_GIMBAL && d[0] != TK_CAP_TO_GIMBAL) {
        snprintf(why, cap, "direction byte 0x%02X (0x00 from the gimbal, 0x01 to it)",
                 (unsigned)d[0]);
        return TK_CAP_BAD;
    }
    rec->dir = d[0];
    rec->data = d + 1;
    rec->len = h->caplen - 1u;
    return TK_CAP_RECORD;
}

static int parse_can(const struct pcap_pkthdr *h, const uint8_t *d, tk_cap_rec_t *rec, char *why,
                     size_t cap)
{
    uint32_t id;
    unsigned len;
    bool fd;
    if (h->caplen < TK_CAP_CAN_HEADER) {
        snprintf(why, cap, "%u bytes, shorter than a SocketCAN header", (unsigned)h->caplen);
        return TK_CAP_BAD;
    }
    id = (uint32_t)d[0] << 24 | (uint32_t)d[1] << 16 | (uint32_t)d[2] << 8 | d[3];
    len = d[4];
    fd = h->caplen == TK_CAP_CAN_MAX || (d[5] & CANFD_FDF) != 0;
    if (len > (fd ? 64u : 8u) || h->caplen < TK_CAP_CAN_HEADER + len) {
        snprintf(why, cap, "payload length %u does not fit the record (%u bytes)", len,
                 (unsigned)h->caplen);
        return TK_CAP_BAD;
    }
    rec->can_id = id;
    rec->can_data = !fd && (id & (CAN_ERR_FLAG | CAN_RTR_FLAG)) == 0;
    if (rec->can_data) {
        memset(&rec->frame, 0, sizeof(rec->frame));
        rec->frame.extended = (id & CAN_EFF_FLAG) != 0;
        rec->frame.id = id & (rec->frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
        rec->frame.dlc = (uint8_t)len;
        memcpy(rec->frame.data, d + TK_CAP_CAN_HEADER, len);
    }
    rec->data = d + TK_CAP_CAN_HEADER;
    rec->len = len;
    return TK_CAP_RECORD;
}

int tk_cap_next(tk_cap_reader_t *r, tk_cap_rec_t *rec, char *why, size_t cap)
{
    struct pcap_pkthdr *h;
    const u_char *d;
    int rc = pcap_next_ex(r->pcap, &h, &d);
    if (rc == PCAP_ERROR_BREAK) {
        return TK_CAP_END;
    }
    if (rc != 1) {
        const char *err = pcap_geterr(r->pcap);
        /* a read a signal broke off (a pipe or FIFO): the signal's exit,
         * not libpcap's "Interrupted system call" */
        tk_exit_if_signalled();
        /* libpcap reads a pcapng file's later sections only in the first
         * one's byte order: another's header reads as a huge block */
        snprintf(why, cap, "%s: after record %lu: %s%s", r->path, r->index, err,
                 r->pcapng && strstr(err, "block size") != NULL
                     ? " (a damaged file, or a pcapng section in the other byte order, which "
                       "is not read)"
                     : "");
        return TK_CAP_ERROR;
    }
    memset(rec, 0, sizeof(*rec));
    rec->index = ++r->index;
    /* A classic pcap record's seconds are an unsigned 32-bit field (good
     * to 2106); libpcap hands them over as a signed 32-bit number, so a
     * time past 2038-01-19 03:14:07 would come out negative. No classic
     * capture holds times before 1970: a negative value is the unsigned
     * field. (A pcapng time is 64-bit: one before 1970, from its
     * if_tsoffset, stays negative.) A fraction of a second beyond 10^9 ns
     * (a writer that did not normalise; libpcap scales a microsecond
     * file's to nanoseconds in a 64-bit field) carries into the seconds.
     * That fraction is an unsigned 32-bit field too, which libpcap also
     * hands over signed: one of 2^31 or more came out negative (as 0, the
     * Python reader carrying it: a review), and a microsecond file's is
     * that negative number times 1000. */
    {
        int64_t sec = (int64_t)h->ts.tv_sec;
        int64_t frac = (int64_t)h->ts.tv_usec; /* opened in ns */
        uint64_t ns;
        if (!r->pcapng && sec < 0 && sec >= -(int64_t)0x80000000) {
            sec += (int64_t)0x100000000;
        }
        if (!r->pcapng && frac < 0) {
            int64_t unit = r->usec ? 1000 : 1;
            if (frac >= -(int64_t)0x80000000 * unit && frac % unit == 0) {
                frac += (int64_t)0x100000000 * unit;
            }
        }
        ns = frac > 0 ? (uint64_t)frac : 0u;
        sec += (int64_t)(ns / 1000000000u);
        rec->t.sec = sec;
        rec->t.usec = (uint32_t)(ns % 1000000000u / 1000u);
        if (r->pcapng && h->ts.tv_sec == 0 && h->ts.tv_usec == 0 && r->index > 1u) {
            /* a pcapng Simple Packet Block has no time (libpcap gives 0):
             * the time of the record before, not 1970 (whose gap cut a
             * frame split across the two as a pause) */
            rec->t = r->last;
        }
        r->last = rec->t;
    }
    if (h->caplen < h->len) {
        snprintf(why, cap, "cut to %u of its %u bytes by the capture's snapshot length",
                 (unsigned)h->caplen, (unsigned)h->len);
        return TK_CAP_BAD;
    }
    if (h->caplen > h->len) {
        /* no writer keeps more than the packet had: a damaged header (as
         * --record calls it) */
        snprintf(why, cap, "%u bytes captured of a packet of %u: a damaged record header",
                 (unsigned)h->caplen, (unsigned)h->len);
        return TK_CAP_BAD;
    }
    return r->linktype == TK_CAP_LINKTYPE_SERIAL ? parse_serial(h, d, rec, why, cap)
                                                 : parse_can(h, d, rec, why, cap);
}
