/* Capture files of the bench tools: pcap through libpcap (format in
 * tk_capture.h), written and read. The loops that record and replay them
 * are in tk_record.c. */
#define _GNU_SOURCE 1 /* fopencookie: libpcap reads a pipe whose head we consumed */

#include "tk_capture.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
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

/* The length of the whole records of an existing classic pcap file:
 * the 24-byte file header and every record whose 16-byte header and data
 * are complete. Returns -1 when it is not a classic pcap (pcapng, or not a
 * capture: libpcap's append refuses those with its own message). */
static long whole_records_len(FILE *f, long size)
{
    uint8_t h[24];
    bool big;
    long at = 24;
    if (fread(h, 1, sizeof(h), f) != sizeof(h)) {
        return -1;
    }
    /* magic a1b2c3d4 (microseconds) or a1b23c4d (nanoseconds), either order */
    if (((h[0] == 0xD4u && h[1] == 0xC3u) || (h[0] == 0x4Du && h[1] == 0x3Cu)) && h[2] == 0xB2u &&
        h[3] == 0xA1u) {
        big = false;
    } else if (h[0] == 0xA1u && h[1] == 0xB2u &&
               ((h[2] == 0xC3u && h[3] == 0xD4u) || (h[2] == 0x3Cu && h[3] == 0x4Du))) {
        big = true;
    } else {
        return -1;
    }
    while (at + 16 <= size) {
        uint8_t r[16];
        uint32_t caplen;
        if (fseek(f, at, SEEK_SET) != 0 || fread(r, 1, sizeof(r), f) != sizeof(r)) {
            break;
        }
        caplen = big ? ((uint32_t)r[8] << 24 | (uint32_t)r[9] << 16 | (uint32_t)r[10] << 8 | r[11])
                     : ((uint32_t)r[11] << 24 | (uint32_t)r[10] << 16 | (uint32_t)r[9] << 8 | r[8]);
        if ((long)caplen > size - at - 16) {
            break; /* its data runs past the end */
        }
        at += 16 + (long)caplen;
    }
    return at;
}

/* Appending to a capture that a full disk or a crash cut inside a record
 * would put every new record behind the partial one, unreadable: cut the
 * file back to its last whole record first, and say so. */
static void trim_partial_record(const char *path)
{
    FILE *f = fopen(path, "rb");
    struct stat st;
    long keep;
    if (f == NULL) {
        return; /* a new file, or libpcap reports why it cannot open it */
    }
    keep = (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode))
               ? whole_records_len(f, (long)st.st_size)
               : -1;
    (void)fclose(f);
    if (keep >= 24 && keep < (long)st.st_size) {
        if (truncate(path, (off_t)keep) != 0) {
            tk_die("cannot repair capture %s: %s", path, strerror(errno));
        }
        tk_warn("%s ended inside a record (a full disk or a crash?): %ld bytes of it removed "
                "before appending",
                path, (long)st.st_size - keep);
    }
}

void tk_cap_create(tk_cap_writer_t *w, const char *path, int linktype, bool append)
{
    int snaplen = linktype == TK_CAP_LINKTYPE_CAN ? (int)TK_CAP_CAN_MAX : SERIAL_SNAPLEN;
    pcap_t *p = pcap_open_dead_with_tstamp_precision(linktype, snaplen, PCAP_TSTAMP_PRECISION_NANO);
    pcap_dumper_t *d;
    struct stat st;
    /* the path itself, not what a symlink names: a rename onto a symlink
     * replaces the link (`-o /dev/stdout` into a file, as root, turned
     * /dev/stdout into a regular file) */
    bool existed = lstat(path, &st) == 0;
    if (p == NULL) {
        tk_die("cannot start a capture: out of memory");
    }
    w->tmp[0] = '\0';
    w->err = 0;
    w->good = -1;
    if (append) {
        trim_partial_record(path);
    }
    /* a temporary file and a rename only for a regular file (or a new
     * one): a device, a FIFO, a symlink (/dev/stdout) is written in place
     * (through the link), never replaced by a rename */
    if (!append && (existed ? S_ISREG(st.st_mode) : errno == ENOENT)) {
        int k = snprintf(w->tmp, sizeof(w->tmp), "%s.partial-%ld", path, (long)getpid());
        if (k < 0 || (size_t)k >= sizeof(w->tmp)) {
            tk_die("cannot write capture %s: the path is too long", path);
        }
    }
    errno = 0;
    d = append ? pcap_dump_open_append(p, path)
               : pcap_dump_open(p, w->tmp[0] != '\0' ? w->tmp : path);
    if (d == NULL) {
        int e = errno;
        /* nothing recorded: a file this call created goes again (a full
         * disk leaves it empty or cut inside the file header) */
        if (w->tmp[0] != '\0') {
            (void)unlink(w->tmp);
        } else if (append && !existed) {
            (void)unlink(path);
        }
        /* the reason: errno where libpcap's own message is of a step
         * ("Can't seek to the end of ..." for a full disk) */
        if (e != 0) {
            tk_die("cannot write capture %s: %s", path, strerror(e));
        }
        tk_die("cannot write capture %s: %s", path, pcap_geterr(p));
    }
    w->pcap = p;
    w->dumper = d;
    w->good = ftell(pcap_dump_file(d)); /* the end of the last whole record */
    w->path = path;
    w->linktype = linktype;
    w->records = 0;
}

static void put_record(tk_cap_writer_t *w, const struct timespec *t, const uint8_t *rec, size_t n)
{
    struct pcap_pkthdr h;
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
    FILE *f = pcap_dump_file(w->dumper);
    int e = w->err; /* the first failure, not the close's */
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

/* Record what the tapped link moved. A capture that cannot be written
 * (a full disk) stops recording but not the command: the packet it sends
 * still goes out and is reported, and the failure is reported at exit
 * (close_session_capture()) with the status that says whether a packet
 * was sent. */
static void tap_record(tk_cap_tap_t *tap, unsigned dir, const uint8_t *data, size_t n)
{
    struct timespec t;
    if (tap->w->err != 0) {
        return;
    }
    clock_gettime(CLOCK_REALTIME, &t);
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
    if (session_capture.dumper == NULL) {
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
    if (session_capture.dumper != NULL) {
        tk_die("only one link per run can be recorded");
    }
    tk_cap_create(&session_capture, path, TK_CAP_LINKTYPE_SERIAL, true);
    if (atexit(close_session_capture) != 0) {
        tk_die("cannot record %s: atexit failed", path);
    }
    return tk_cap_tap_port(&session_tap, inner, &session_capture);
}

/* ---- reading ---- */

bool tk_cap_is_capture(const uint8_t *head, size_t n)
{
    static const uint8_t magics[][4] = {
        {0xA1, 0xB2, 0xC3, 0xD4}, /* pcap, microseconds */
        {0xA1, 0xB2, 0x3C, 0x4D}, /* pcap, nanoseconds */
        {0x0A, 0x0D, 0x0D, 0x0A}, /* pcapng section header block */
    };
    size_t i;
    if (n < 4) {
        return false;
    }
    for (i = 0; i < sizeof(magics) / sizeof(magics[0]); i++) {
        const uint8_t *m = magics[i];
        bool be = memcmp(head, m, 4) == 0;
        bool le = head[0] == m[3] && head[1] == m[2] && head[2] == m[1] && head[3] == m[0];
        if (be || le) {
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
        if (got >= 0 || errno == EIO) { /* EIO: a pty whose writer went away */
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

void tk_cap_reader_open(tk_cap_reader_t *r, int fd, const uint8_t *head, size_t nhead,
                        const char *path)
{
    static const cookie_io_functions_t io = {head_read, NULL, NULL, head_close};
    char err[PCAP_ERRBUF_SIZE];
    head_fd_t *h = calloc(1, sizeof(*h));
    pcap_t *p;
    FILE *in;
    int lt;
    memset(r, 0, sizeof(*r));
    r->path = path;
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
        tk_die("cannot read %s: %s", path, strerror(errno));
    }
    err[0] = '\0';
    p = pcap_fopen_offline_with_tstamp_precision(in, PCAP_TSTAMP_PRECISION_NANO, err);
    if (p == NULL) {
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
}

void tk_cap_reader_close(tk_cap_reader_t *r)
{
    if (r->pcap != NULL) {
        pcap_close(r->pcap); /* closes the FILE */
        r->pcap = NULL;
    }
}

static int parse_serial(const struct pcap_pkthdr *h, const uint8_t *d, tk_cap_rec_t *rec, char *why,
                        size_t cap)
{
    if (h->caplen < 2u) {
        snprintf(why, cap, "%s bytes after the direction byte",
                 h->caplen == 0 ? "no header, no" : "no");
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
        /* a read a signal broke off (a pipe or FIFO): the signal's exit,
         * not libpcap's "Interrupted system call" */
        tk_exit_if_signalled();
        tk_die("%s: after record %lu: %s", r->path, r->index, pcap_geterr(r->pcap));
    }
    memset(rec, 0, sizeof(*rec));
    rec->index = ++r->index;
    /* A classic pcap record's seconds are an unsigned 32-bit field (good
     * to 2106); libpcap hands them over as a signed 32-bit number, so a
     * time past 2038-01-19 03:14:07 would come out negative. No capture
     * holds times before 1970: a negative value is the unsigned field. A
     * fraction of a second beyond 10^9 ns (a writer that did not
     * normalise) carries into the seconds. */
    {
        int64_t sec = (int64_t)h->ts.tv_sec;
        uint64_t ns = (uint64_t)(uint32_t)h->ts.tv_usec; /* opened in nanoseconds */
        if (sec < 0 && sec >= -(int64_t)0x80000000) {
            sec += (int64_t)0x100000000;
        }
        sec += (int64_t)(ns / 1000000000u);
        rec->t.sec = sec;
        rec->t.usec = (uint32_t)(ns % 1000000000u / 1000u);
    }
    if (h->caplen < h->len) {
        snprintf(why, cap, "cut to %u of its %u bytes by the capture's snapshot length",
                 (unsigned)h->caplen, (unsigned)h->len);
        return TK_CAP_BAD;
    }
    return r->linktype == TK_CAP_LINKTYPE_SERIAL ? parse_serial(h, d, rec, why, cap)
                                                 : parse_can(h, d, rec, why, cap);
}
