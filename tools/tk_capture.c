/* Capture files of the bench tools: pcap through libpcap (format in
 * tk_capture.h), recording from serial devices and CAN interfaces, and
 * replay with the recorded timing. */
#define _GNU_SOURCE 1 /* fopencookie: libpcap reads a pipe whose head we consumed */

#include "tk_capture.h"

#include <errno.h>
#include <stdlib.h>
#include <net/if.h>
#include <poll.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/raw.h>
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
     * one): a device, a FIFO or /dev/stdout is written in place, never
     * replaced by a rename */
    if (!append && (stat(path, &st) != 0 ? errno == ENOENT : S_ISREG(st.st_mode))) {
        int k = snprintf(w->tmp, sizeof(w->tmp), "%s.partial-%ld", path, (long)getpid());
        if (k < 0 || (size_t)k >= sizeof(w->tmp)) {
            tk_die("cannot write capture %s: the path is too long", path);
        }
    }
    d = append ? pcap_dump_open_append(p, path)
               : pcap_dump_open(p, w->tmp[0] != '\0' ? w->tmp : path);
    if (d == NULL) {
        /* libpcap's message names the file and the reason */
        tk_die("cannot write capture: %s", pcap_geterr(p));
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

void tk_cap_flush(tk_cap_writer_t *w)
{
    if (pcap_dump_flush(w->dumper) != 0) {
        tk_die("cannot write capture %s: %s", w->path, strerror(errno));
    }
}

int tk_cap_finish(tk_cap_writer_t *w)
{
    FILE *f = pcap_dump_file(w->dumper);
    int e = 0;
    if (fflush(f) != 0 || ferror(f)) {
        e = errno != 0 ? errno : EIO;
    }
    if (fsync(fileno(f)) != 0 && errno != EINVAL && e == 0) {
        e = errno; /* a full or failing disk may only tell here */
    }
    pcap_dump_close(w->dumper); /* fclose() */
    pcap_close(w->pcap);
    w->dumper = NULL;
    w->pcap = NULL;
    if (w->tmp[0] != '\0') {
        if (e == 0 && rename(w->tmp, w->path) != 0) {
            e = errno;
        }
        if (e != 0) {
            fflush(stdout);
            fprintf(stderr, "%s: the capture so far is kept in %s; %s is unchanged\n", tk_prog,
                    w->tmp, w->path);
        }
    }
    return e;
}

void tk_cap_close(tk_cap_writer_t *w)
{
    int e = tk_cap_finish(w);
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
    errno = 0;
    tk_cap_put_serial(tap->w, &t, dir, data, n);
    if (pcap_dump_flush(tap->w->dumper) != 0) {
        tap->w->err = errno != 0 ? errno : EIO;
    } else {
        tap->w->good = ftell(pcap_dump_file(tap->w->dumper)); /* a record boundary */
    }
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
    if (session_capture.err != 0) {
        e = session_capture.err; /* the first failure, not the close's */
        if (session_capture.good > 0) {
            /* end the file at its last whole record */
            (void)truncate(session_capture.path, (off_t)session_capture.good);
        }
    }
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

/* ---- recording ---- */

static void print_recorded(const tk_cap_writer_t *w, unsigned long bytes, const char *what)
{
    printf("recorded %lu record%s (%lu %s) to %s\n", w->records, w->records == 1 ? "" : "s", bytes,
           what, w->path);
}

static void print_recording(const tk_cap_writer_t *w, const char *what, const char *tap_in,
                            double seconds)
{
    printf("recording %s%s%s to %s ", what, tap_in != NULL ? " and " : "",
           tap_in != NULL ? tap_in : "", w->path);
    if (seconds > 0.0) {
        printf("for %g s\n", seconds);
    } else {
        printf("until interrupted (Ctrl-C)\n");
    }
    tk_stdout_flush();
}

static int ms_left(double t_end)
{
    double left = t_end - tk_now_s();
    if (t_end == 0.0) {
        return 200; /* no end: wake up now and then to flush */
    }
    return left <= 0.0 ? 0 : (left > 0.2 ? 200 : (int)(left * 1000.0) + 1);
}

void tk_cap_record_serial(tk_cap_writer_t *w, const char *path, const char *dev, const char *tap_in,
                          long baud, double seconds)
{
    tk_link_t links[2];
    tase_port_t ports[2];
    struct pollfd pfd[2];
    unsigned long bytes = 0;
    size_t n = tap_in != NULL ? 2u : 1u, i, failed_dev = 0;
    int failed = 0;
    double t_end = seconds > 0.0 ? tk_now_s() + seconds : 0.0;
    uint8_t buf[READ_CHUNK];
    tk_link_serial(&links[0], dev, baud);
    if (tap_in != NULL) {
        tk_link_serial(&links[1], tap_in, baud);
    }
    /* the sources are open: only now is the capture created */
    tk_cap_create(w, path, TK_CAP_LINKTYPE_SERIAL, false);
    print_recording(w, dev, tap_in, seconds);
    for (i = 0; i < n; i++) {
        ports[i] = tk_link_port(&links[i]);
        pfd[i].fd = links[i].uart.fd;
        pfd[i].events = POLLIN;
    }
    while (tk_signal == 0 && failed == 0) {
        int timeout = ms_left(t_end), pr;
        if (timeout == 0) {
            break;
        }
        pr = poll(pfd, (nfds_t)n, timeout);
        if (pr < 0 && errno != EINTR) {
            tk_die("cannot wait for %s: %s", dev, strerror(errno));
        }
        for (i = 0; pr > 0 && i < n && failed == 0; i++) {
            int got;
            struct timespec t;
            if (pfd[i].revents == 0) {
                continue;
            }
            /* a hang-up wakes poll() too: the read then reports it */
            got = ports[i].ops->read(ports[i].ctx, buf, sizeof(buf), 0);
            clock_gettime(CLOCK_REALTIME, &t);
            if (got < 0) {
                failed = got; /* what was recorded is kept: close, then say why */
                failed_dev = i;
            }
            if (got > 0) {
                tk_cap_put_serial(w, &t, i == 0 ? TK_CAP_FROM_GIMBAL : TK_CAP_TO_GIMBAL, buf,
                                  (size_t)got);
                bytes += (unsigned long)got;
            }
        }
        tk_cap_flush(w);
    }
    for (i = 0; i < n; i++) {
        tk_link_close(&links[i]);
    }
    tk_cap_close(w);
    print_recorded(w, bytes, "bytes");
    tk_stdout_flush();
    if (failed != 0) {
        tk_die("cannot read %s: %s", failed_dev == 0 ? dev : tap_in,
               tk_link_error(&links[failed_dev], failed));
    }
}

/* A raw socket on `iface` that receives every frame, error frames and CAN
 * FD included, with the kernel's receive timestamps. */
static int open_can_recorder(const char *iface)
{
    tk_link_t probe;
    struct sockaddr_can addr;
    can_err_mask_t errs = CAN_ERR_MASK;
    int on = 1, fd;
    /* the port's checks give the usual messages (missing, down, no CAN) */
    tk_link_can(&probe, iface, false);
    tk_link_close(&probe);
    fd = socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        tk_die("cannot open CAN interface %s: %s", iface, strerror(errno));
    }
    (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on,
                     sizeof(on)); /* old kernels: classic only */
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errs, sizeof(errs)) != 0 ||
        setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof(on)) != 0) {
        tk_die("cannot set up CAN interface %s: %s", iface, strerror(errno));
    }
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)if_nametoindex(iface);
    if (addr.can_ifindex == 0 || bind(fd, (const struct sockaddr *)&addr, sizeof(addr)) != 0) {
        tk_die("cannot open CAN interface %s: %s", iface, strerror(errno));
    }
    return fd;
}

void tk_cap_record_can(tk_cap_writer_t *w, const char *path, const char *iface, double seconds)
{
    int fd = open_can_recorder(iface);
    double t_end = seconds > 0.0 ? tk_now_s() + seconds : 0.0;
    unsigned long frames = 0;
    tk_cap_create(w, path, TK_CAP_LINKTYPE_CAN, false); /* the source is open */
    print_recording(w, iface, NULL, seconds);
    while (tk_signal == 0) {
        struct pollfd pfd = {fd, POLLIN, 0};
        int timeout = ms_left(t_end), pr;
        if (timeout == 0) {
            break;
        }
        pr = poll(&pfd, 1, timeout);
        if (pr < 0 && errno != EINTR) {
            tk_die("cannot wait for %s: %s", iface, strerror(errno));
        }
        while (pr > 0) {
            union {
                struct can_frame c;
                struct canfd_frame fd;
            } frame;
            char ctrl[CMSG_SPACE(sizeof(struct timespec))];
            struct iovec iov = {&frame, sizeof(frame)};
            struct msghdr msg;
            struct cmsghdr *c;
            struct timespec t;
            ssize_t got;
            memset(&msg, 0, sizeof(msg));
            msg.msg_iov = &iov;
            msg.msg_iovlen = 1;
            msg.msg_control = ctrl;
            msg.msg_controllen = sizeof(ctrl);
            got = recvmsg(fd, &msg, MSG_DONTWAIT);
            if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) {
                break;
            }
            if (got < 0) {
                tk_die("cannot read CAN interface %s: %s", iface, strerror(errno));
            }
            if (got != (ssize_t)CAN_MTU && got != (ssize_t)CANFD_MTU) {
                continue; /* not a frame record */
            }
            clock_gettime(CLOCK_REALTIME, &t); /* unless the kernel says when */
            for (c = CMSG_FIRSTHDR(&msg); c != NULL; c = CMSG_NXTHDR(&msg, c)) {
                if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
                    memcpy(&t, CMSG_DATA(c), sizeof(t));
                }
            }
            tk_cap_put_can(w, &t, (const uint8_t *)&frame, (size_t)got);
            frames++;
        }
        tk_cap_flush(w);
    }
    close(fd);
    tk_cap_close(w);
    print_recorded(w, frames, "frames");
    tk_stdout_flush();
}

/* ---- replay ---- */

static bool dir_selected(tk_cap_dirs_t dirs, unsigned dir)
{
    return (dirs & (dir == TK_CAP_FROM_GIMBAL ? TK_CAP_DIR_OUT : TK_CAP_DIR_IN)) != 0;
}

/* Which TASE direction a datalink CAN frame carries: 1 from the gimbal, 0
 * to it, -1 neither (3AX and other nodes). */
static int can_frame_dir(const tase_can_frame_t *f)
{
    if (f->extended && f->id == TASE_CAN_ID_FROM_GIMBAL) {
        return (int)TK_CAP_FROM_GIMBAL;
    }
    if (f->extended && f->id == TASE_CAN_ID_TO_GIMBAL) {
        return (int)TK_CAP_TO_GIMBAL;
    }
    return -1;
}

/* Sleep until the monotonic time `due` (seconds); false when a signal asked
 * to stop. */
static bool wait_until(double due)
{
    for (;;) {
        double left = due - tk_now_s();
        struct timespec ts;
        if (tk_signal != 0) {
            return false;
        }
        if (left <= 0.0) {
            return true;
        }
        if (left > 0.2) {
            left = 0.2;
        }
        ts.tv_sec = (time_t)left;
        ts.tv_nsec = (long)((left - (double)ts.tv_sec) * 1e9);
        (void)nanosleep(&ts, NULL);
    }
}

typedef struct {
    const tk_replay_opts_t *o;
    tk_link_t link;
    tase_port_t port;
    unsigned long sent, skipped, bad, bytes;
} replay_t;

static void send_frame(replay_t *rp, const tase_can_frame_t *f)
{
    int rc = tase_socketcan_send_frame(&rp->link.can, f);
    if (rc != TASE_OK) {
        tk_die("cannot send to %s: %s", rp->o->can, tase_strerror(rc));
    }
}

static void send_bytes(replay_t *rp, const uint8_t *d, size_t n, unsigned dir)
{
    if (rp->o->can != NULL) { /* serial bytes onto CAN: frames of their direction's ID */
        tase_can_split_t s;
        tase_can_frame_t f;
        (void)tase_can_split_init(
            &s, dir == TK_CAP_FROM_GIMBAL ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST, d, n);
        while (tase_can_split_next(&s, &f) == TASE_OK) {
            send_frame(rp, &f);
        }
    } else {
        int rc = tk_port_write_all(&rp->port, d, n);
        if (rc != 0) {
            tk_die("cannot write to %s: %s", rp->o->serial, tase_strerror(rc));
        }
    }
    rp->bytes += (unsigned long)n;
}

/* Whether the options select a record, and through which path. */
static bool replay_selects(const replay_t *rp, const tk_cap_reader_t *r, const tk_cap_rec_t *rec)
{
    int d;
    if (r->linktype == TK_CAP_LINKTYPE_SERIAL) {
        return dir_selected(rp->o->dirs, rec->dir);
    }
    if (!rec->can_data) {
        return false; /* FD, remote and error frames are not sent */
    }
    d = can_frame_dir(&rec->frame);
    if (rp->o->can != NULL && rp->o->dirs == TK_CAP_DIR_ALL) {
        return true; /* every frame, whatever its ID */
    }
    /* otherwise the datalink frames of the selected directions (onto a
     * serial line: their bytes) */
    return d >= 0 && dir_selected(rp->o->dirs, (unsigned)d);
}

static void replay_send(replay_t *rp, const tk_cap_reader_t *r, const tk_cap_rec_t *rec)
{
    if (r->linktype == TK_CAP_LINKTYPE_SERIAL) {
        send_bytes(rp, rec->data, rec->len, rec->dir);
    } else if (rp->o->can != NULL) {
        send_frame(rp, &rec->frame);
        rp->bytes += rec->frame.dlc;
    } else {
        send_bytes(rp, rec->frame.data, rec->frame.dlc, (unsigned)can_frame_dir(&rec->frame));
    }
    if (rp->sent++ == 0) {
        tk_mark_sent("replayed data"); /* later failures say so */
    }
}

/* The seconds from record time a to b. */
static double time_diff(const tk_time_t *a, const tk_time_t *b)
{
    return (double)(b->sec - a->sec) + ((double)b->usec - (double)a->usec) * 1e-6;
}

unsigned long tk_cap_check(tk_cap_reader_t *r, const tk_replay_opts_t *o, unsigned long *backward)
{
    replay_t rp;
    tk_cap_rec_t rec;
    tk_time_t last = {0, 0};
    bool any = false;
    unsigned long bad = 0, last_index = 0;
    char why[160];
    int rc;
    memset(&rp, 0, sizeof(rp));
    rp.o = o;
    *backward = 0;
    /* tk_cap_next() dies on a file cut inside a record header, naming it */
    while ((rc = tk_cap_next(r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_BAD) {
            tk_warn("%s: record %lu is bad: %s", r->path, rec.index, why);
            bad++;
            continue;
        }
        if (!replay_selects(&rp, r, &rec)) {
            continue;
        }
        if (any && time_diff(&last, &rec.t) < 0.0) {
            if (++*backward <= 3u) {
                tk_warn("%s: record %lu is %.6f s earlier than record %lu (a clock step?): "
                        "replayed right after it",
                        r->path, rec.index, -time_diff(&last, &rec.t), last_index);
            }
        }
        last = rec.t;
        last_index = rec.index;
        any = true;
        tk_exit_if_signalled();
    }
    return bad;
}

unsigned long tk_cap_replay(tk_cap_reader_t *r, const tk_replay_opts_t *o)
{
    replay_t rp;
    tk_cap_rec_t rec;
    tk_time_t prev = {0, 0};
    bool started = false;
    double start = 0.0;
    double due = 0.0; /* seconds after the first record, at speed 1 */
    char why[160];
    int rc;
    memset(&rp, 0, sizeof(rp));
    rp.o = o;
    if (o->can != NULL) {
        /* the role only sets the socket's receive filter: replay sends
         * whatever IDs the capture holds */
        tk_link_can(&rp.link, o->can, false);
    } else {
        tk_link_serial(&rp.link, o->serial, o->baud);
    }
    rp.port = tk_link_port(&rp.link);
    while (tk_signal == 0 && (rc = tk_cap_next(r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_BAD) {
            tk_warn("%s: record %lu skipped: %s", r->path, rec.index, why);
            rp.bad++;
            continue;
        }
        if (!replay_selects(&rp, r, &rec)) {
            rp.skipped += r->linktype == TK_CAP_LINKTYPE_CAN && !rec.can_data ? 1u : 0u;
            continue;
        }
        if (!started) { /* the timing starts at the first record sent */
            prev = rec.t;
            start = tk_now_s();
            started = true;
        }
        /* the recorded gap to the record before; a step back in the
         * recorded clock is no gap (tk_cap_check() warned), and the gaps
         * after it keep their lengths */
        {
            double gap = time_diff(&prev, &rec.t);
            due += gap > 0.0 ? gap : 0.0;
            prev = rec.t;
        }
        if (o->speed > 0.0 && !wait_until(start + due / o->speed)) {
            break;
        }
        replay_send(&rp, r, &rec);
    }
    tk_link_close(&rp.link);
    printf("replayed %lu of %lu records (%lu bytes) to %s in %.3f s%s", rp.sent, r->index, rp.bytes,
           o->can != NULL ? o->can : o->serial, started ? tk_now_s() - start : 0.0,
           tk_signal != 0 ? ", interrupted" : "");
    if (rp.skipped > 0) {
        printf("; %lu CAN FD/remote/error frame%s not sent", rp.skipped,
               rp.skipped == 1 ? "" : "s");
    }
    printf("\n");
    tk_stdout_flush();
    return rp.bad;
}
