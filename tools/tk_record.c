/* The capture loops of tk_capture.h: recording from serial devices and
 * CAN interfaces, and replay with the recorded timing. */
#define _GNU_SOURCE 1 /* SCM_TIMESTAMPNS: the kernel's receive time of a CAN frame */

#include "tk_capture.h"

#include <errno.h>
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

#include "tase/can.h"
#include "toolkit.h"

#define READ_CHUNK 4096u

/* ---- recording ---- */

/* Where the status lines go: standard output, unless the capture itself
 * goes there (`-o /dev/stdout` into a pipe): then standard error, so the
 * pcap stream stays a capture. */
static FILE *status_out(const char *path)
{
    struct stat sp, so;
    if (stat(path, &sp) == 0 && fstat(STDOUT_FILENO, &so) == 0 && sp.st_dev == so.st_dev &&
        sp.st_ino == so.st_ino) {
        return stderr;
    }
    return stdout;
}

static void print_recorded(const tk_cap_writer_t *w, unsigned long bytes, const char *what)
{
    FILE *out = status_out(w->path);
    fprintf(out, "recorded %lu record%s (%lu %s%s) to %s\n", w->records, w->records == 1 ? "" : "s",
            bytes, what, bytes == 1 ? "" : "s", w->path);
    if (out == stdout) {
        tk_stdout_flush();
    }
}

/* Said before the capture is created: output that fails (a closed pipe,
 * /dev/full) ends the run before any file exists. */
static void print_recording(const char *path, const char *what, const char *tap_in, double seconds)
{
    FILE *out = status_out(path);
    fprintf(out, "recording %s%s%s to %s ", what, tap_in != NULL ? " and " : "",
            tap_in != NULL ? tap_in : "", path);
    if (seconds > 0.0) {
        fprintf(out, "for %g s\n", seconds);
    } else {
        fprintf(out, "until interrupted (Ctrl-C)\n");
    }
    if (out == stdout) {
        tk_stdout_flush();
    }
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
    print_recording(path, dev, tap_in, seconds);
    tk_cap_create(w, path, TK_CAP_LINKTYPE_SERIAL, false);
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
        if (!tk_cap_flush(w)) {
            break; /* a full disk: tk_cap_close() keeps what it can and says so */
        }
    }
    for (i = 0; i < n; i++) {
        tk_link_close(&links[i]);
    }
    tk_cap_close(w);
    print_recorded(w, bytes, "byte");
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
    int failed = 0; /* errno of a read that ended the recording */
    print_recording(path, iface, NULL, seconds);
    tk_cap_create(w, path, TK_CAP_LINKTYPE_CAN, false); /* the source is open */
    while (tk_signal == 0 && failed == 0) {
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
                failed = errno; /* as in the serial loop: close, then say why */
                break;
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
        if (!tk_cap_flush(w)) {
            break; /* as in the serial loop */
        }
    }
    close(fd);
    tk_cap_close(w);
    print_recorded(w, frames, "frame");
    tk_stdout_flush();
    if (failed != 0) {
        tk_die("cannot read CAN interface %s: %s", iface,
               failed == ENETDOWN                      ? TK_CAN_DOWN_TEXT
               : (failed == ENODEV || failed == ENXIO) ? TK_CAN_REMOVED_TEXT
                                                       : strerror(failed));
    }
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
        while (tase_can_split_next(&s, &f) > 0) { /* the frame's dlc; 0 when done */
            send_frame(rp, &f);
        }
    } else {
        int rc = tk_port_write_all(&rp->port, d, n);
        if (rc != 0) {
            tk_exit_if_signalled(); /* the write a signal cut short */
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
    unsigned long bad = 0, last_index = 0, long_waits = 0;
    char why[TK_CAP_WHY_MAX];
    int rc;
    memset(&rp, 0, sizeof(rp));
    rp.o = o;
    *backward = 0;
    while ((rc = tk_cap_next(r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_ERROR) {
            tk_die("%s", why); /* a file cut inside a record: nothing sent yet */
        }
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
        } else if (any && o->speed > 0.0 &&
                   time_diff(&last, &rec.t) / o->speed >= TK_REPLAY_LONG_WAIT_S) {
            /* a silence that long, or a clock step forward: replay keeps
             * the timing, so say that it will wait */
            if (++long_waits <= 3u) {
                tk_warn("%s: record %lu comes %.0f s after record %lu (a clock step?): replay "
                        "waits %.0f s for it (--speed 0 does not wait; Ctrl-C stops)",
                        r->path, rec.index, time_diff(&last, &rec.t), last_index,
                        time_diff(&last, &rec.t) / o->speed);
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
    char why[TK_CAP_WHY_MAX];
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
    /* Only the records tk_cap_check() read: records another program
     * appends to the capture after the check are not sent (a record cut
     * short there would fail after the others had gone out). */
    while (tk_signal == 0 && r->index < o->records &&
           (rc = tk_cap_next(r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_ERROR) {
            tk_die("%s", why); /* it changed since the check read it */
        }
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
    printf("replayed %lu of %lu records (%lu bytes) to %s in %.3f s%s", rp.sent, o->records,
           rp.bytes, o->can != NULL ? o->can : o->serial, started ? tk_now_s() - start : 0.0,
           tk_signal != 0 ? ", interrupted" : "");
    if (rp.skipped > 0) {
        printf("; %lu CAN FD/remote/error frame%s not sent", rp.skipped,
               rp.skipped == 1 ? "" : "s");
    }
    printf("\n");
    tk_stdout_flush();
    return rp.bad;
}
