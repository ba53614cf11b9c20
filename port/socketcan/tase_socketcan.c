/* SocketCAN port: struct can_frame <-> tase_can_frame_t lives here only. */
#define _DEFAULT_SOURCE 1

#include "tase/socketcan.h"

#include <errno.h>
#include <fcntl.h>
#include <net/if.h>
#include <net/if_arp.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>

#define RETRY_SLEEP_MS 1u
/* Frames with nothing for the caller taken between two looks at the clock
 * (skip_ends()). */
#define SKIP_BATCH 64u

#ifndef CAN_ERR_CNT
#define CAN_ERR_CNT 0x00000200U /* Linux 5.19+: error counters in data[6..7] */
#endif

/* The error classes the port asks the kernel for: everything about the
 * bus's health, not lost arbitration (normal on a busy bus). */
#define ERR_CLASSES                                                                                \
    (CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK |                \
     CAN_ERR_BUSOFF | CAN_ERR_BUSERROR | CAN_ERR_RESTARTED | CAN_ERR_CNT)

/* The IDs each role's filter passes: its datalink ID, and for the gimbal
 * the 3AX status it listens to. */
static size_t role_filter_ids(tase_can_role_t role, uint32_t ids[2])
{
    uint32_t rx_id = 0;
    (void)tase_can_role_ids(role, NULL, &rx_id);
    ids[0] = rx_id;
    if (role == TASE_CAN_ROLE_GIMBAL) {
        ids[1] = TASE_CAN_ID_3AX_STATUS;
        return 2;
    }
    return 1;
}

/* EAGAIN or EWOULDBLOCK (equal on Linux, where testing both would be a
 * "logical and of equal expressions" under -Wlogical-op). */
static bool would_block(int e)
{
#if EAGAIN == EWOULDBLOCK
    return e == EAGAIN;
#else
    return e == EAGAIN || e == EWOULDBLOCK;
#endif
}

static bool role_wants(tase_can_role_t role, const tase_can_frame_t *f)
{
    uint32_t ids[2];
    size_t n = role_filter_ids(role, ids);
    size_t i;
    for (i = 0; i < n && f->extended; i++) {
        if (f->id == ids[i]) {
            return true;
        }
    }
    return false;
}

static int set_filter(int fd, tase_can_role_t role)
{
    struct can_filter flt[2];
    uint32_t ids[2];
    can_err_mask_t err = ERR_CLASSES;
    size_t n = role_filter_ids(role, ids);
    size_t i;
    for (i = 0; i < n; i++) {
        flt[i].can_id = ids[i] | CAN_EFF_FLAG;
        flt[i].can_mask = CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_EFF_MASK;
    }
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, flt, (socklen_t)(n * sizeof(flt[0]))) != 0 ||
        setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err, sizeof err) != 0) {
        return TASE_EIO;
    }
    return TASE_OK;
}

/* Kernel receive timestamps on every record, best effort: a socket that
 * cannot give them reports 0. */
static void want_timestamps(int fd)
{
    int on = 1;
    (void)setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
}

uint32_t tase_socketcan_now_ms(void *ctx)
{
    struct timespec ts;
    (void)ctx;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0) {
        return 0u; /* time standing still: every wait still ends (wait_fd()) */
    }
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

/* The deadline timeout_ms from now. Longer waits are clamped to
 * TASE_SOCKETCAN_TIMEOUT_MAX (about 24.8 days): a deadline 2^31 ms or
 * more ahead would read as passed (the clock's wrap rule), so UINT32_MAX
 * as "wait for ever" returned at once. */
static uint32_t deadline_in(uint32_t timeout_ms)
{
    uint32_t t = timeout_ms > TASE_SOCKETCAN_TIMEOUT_MAX ? TASE_SOCKETCAN_TIMEOUT_MAX : timeout_ms;
    return tase_socketcan_now_ms(NULL) + t;
}

/* Milliseconds left until `deadline` (0 once it has passed). */
static uint32_t remaining(uint32_t deadline)
{
    uint32_t left = deadline - tase_socketcan_now_ms(NULL);
    return left > 0x7FFFFFFFu ? 0u : left;
}

static uint32_t min_u32(uint32_t a, uint32_t b)
{
    return a < b ? a : b;
}

static void sleep_ms(uint32_t ms)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(ms / 1000u);
    ts.tv_nsec = (long)(ms % 1000u) * 1000000L;
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

/* wait_fd()'s results besides TASE_EIO (errno set). */
#define WAIT_READY 1   /* an event came */
#define WAIT_TIMEOUT 0 /* poll() waited all of timeout_ms: the time left is spent */
#define WAIT_INTR 2    /* a signal interrupted the wait: resume with the time left */

/* Wait for events up to timeout_ms, the caller's time left (remaining()
 * gives at most 0x7FFFFFFF). A wait that ran its full time ends the
 * caller's wait whatever the clock says, so that a clock that stands
 * still (or fails, tase_socketcan_now_ms()) cannot hold a call for ever;
 * a signal only interrupts it (the caller resumes with the time left). */
static int wait_fd(int fd, short events, uint32_t timeout_ms)
{
    struct pollfd p;
    int rc;
    p.fd = fd;
    p.events = events;
    p.revents = 0;
    rc = poll(&p, 1, timeout_ms > 0x7FFFFFFFu ? 0x7FFFFFFF : (int)timeout_ms);
    if (rc < 0) {
        return errno == EINTR ? WAIT_INTR : TASE_EIO;
    }
    return rc == 0 ? WAIT_TIMEOUT : WAIT_READY;
}

static void init_instance(tase_socketcan_t *s, int fd, tase_can_role_t role, unsigned flags)
{
    memset(s, 0, sizeof(*s));
    s->fd = fd;
    s->flags = flags;
    s->role = role;
    s->tx_timeout_ms = TASE_SOCKETCAN_TX_TIMEOUT_MS;
}

static int errno_to_tase(int e)
{
    switch (e) {
    case EAFNOSUPPORT:
    case EPROTONOSUPPORT: return TASE_EUNSUPPORTED;
    case EPERM:
    case EACCES: return TASE_EACCES;
    case ENODEV:
    case ENXIO: return TASE_ENODEV;
    case ENETDOWN: return TASE_EDOWN;
    default: return TASE_EIO;
    }
}

/* A descriptor error of a read or write: counted in last_errno, and the
 * code ERRORS in the header gives it. */
static int io_error(tase_socketcan_t *s, int e)
{
    s->stats.last_errno = e;
    if (e == ENETDOWN) {
        return TASE_EDOWN; /* interface down (or bus-off without auto-restart) */
    }
    return (e == ENODEV || e == ENXIO) ? TASE_ENODEV : TASE_EIO;
}

/* Everything open() checks once the socket exists. */
static int bind_to(int fd, const char *ifname, tase_can_role_t role)
{
    struct ifreq ifr;
    struct sockaddr_can addr;
    unsigned idx = if_nametoindex(ifname);
    if (idx == 0u) {
        return TASE_ENODEV;
    }
    memset(&ifr, 0, sizeof(ifr));
    memcpy(ifr.ifr_name, ifname, strlen(ifname) + 1u);
    /* bind() says ENODEV for lo or eth0 too: tell them apart */
    if (ioctl(fd, SIOCGIFHWADDR, &ifr) != 0) {
        return errno_to_tase(errno);
    }
    if (ifr.ifr_hwaddr.sa_family != ARPHRD_CAN) {
        return TASE_EARG;
    }
    if (ioctl(fd, SIOCGIFFLAGS, &ifr) != 0) {
        return errno_to_tase(errno);
    }
    if ((ifr.ifr_flags & IFF_UP) == 0) {
        return TASE_EDOWN;
    }
    if (set_filter(fd, role) != TASE_OK) {
        return TASE_EIO;
    }
    memset(&addr, 0, sizeof(addr));
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (bind(fd, (const struct sockaddr *)&addr, sizeof(addr)) != 0) {
        return errno_to_tase(errno);
    }
    return TASE_OK;
}

int tase_socketcan_open(tase_socketcan_t *s, const char *ifname, tase_can_role_t role)
{
    int fd;
    int rc;
    size_t len;
    if (s == NULL || ifname == NULL || tase_can_role_ids(role, NULL, NULL) != TASE_OK) {
        return TASE_EARG;
    }
    len = strlen(ifname);
    if (len == 0u || len >= IFNAMSIZ) {
        return TASE_EARG;
    }
    /* The socket first: on a kernel without CAN "unsupported" is the
     * useful answer whatever the name. */
    fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        return errno_to_tase(errno);
    }
    rc = bind_to(fd, ifname, role);
    if (rc != TASE_OK) {
        close(fd);
        return rc;
    }
    want_timestamps(fd);
    init_instance(s, fd, role, TASE_SOCKETCAN_OWN_FD);
    return TASE_OK;
}

int tase_socketcan_adopt(tase_socketcan_t *s, int fd, tase_can_role_t role, unsigned flags)
{
    int fl;
    if (s == NULL || fd < 0 || tase_can_role_ids(role, NULL, NULL) != TASE_OK ||
        (flags & ~(TASE_SOCKETCAN_OWN_FD | TASE_SOCKETCAN_SET_FILTER)) != 0u) {
        return TASE_EARG;
    }
    fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) {
        return TASE_EIO;
    }
    if ((flags & TASE_SOCKETCAN_SET_FILTER) != 0u && set_filter(fd, role) != TASE_OK) {
        return TASE_EIO;
    }
    want_timestamps(fd);
    init_instance(s, fd, role, flags);
    return TASE_OK;
}

void tase_socketcan_close(tase_socketcan_t *s)
{
    if (s == NULL || s->fd < 0) {
        return;
    }
    if ((s->flags & TASE_SOCKETCAN_OWN_FD) != 0u) {
        close(s->fd);
    }
    s->fd = -1;
}

/* An open instance whose private indices are in range: a corrupted or
 * never-initialised one gives TASE_EARG instead of indexing outside pend[]
 * or side[]. */
static bool usable(const tase_socketcan_t *s)
{
    return s != NULL && s->fd >= 0 && tase_can_role_ids(s->role, NULL, NULL) == TASE_OK &&
           s->pend_len <= sizeof s->pend && s->pend_pos <= s->pend_len &&
           s->side_head < TASE_SOCKETCAN_SIDEQ && s->side_count <= TASE_SOCKETCAN_SIDEQ;
}

/* ---- frames --------------------------------------------------------- */

static void to_linux(const tase_can_frame_t *f, struct can_frame *cf)
{
    memset(cf, 0, sizeof(*cf));
    cf->can_id = f->extended ? (f->id | CAN_EFF_FLAG) : f->id;
    cf->can_dlc = f->dlc;
    memcpy(cf->data, f->data, f->dlc);
}

/* false for remote and error frames and impossible lengths */
static bool from_linux(const struct can_frame *cf, tase_can_frame_t *f)
{
    if ((cf->can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0u || cf->can_dlc > CAN_MAX_DLEN) {
        return false;
    }
    memset(f, 0, sizeof(*f));
    f->extended = (cf->can_id & CAN_EFF_FLAG) != 0u;
    f->id = cf->can_id & (f->extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    f->dlc = cf->can_dlc;
    memcpy(f->data, cf->data, cf->can_dlc);
    return true;
}

/* The time a write() or send_frame() may take: its deadline, and what it
 * has slept on ENOBUFS against the bound it started with, so that the
 * sleeps end even with a clock that stands still. */
typedef struct {
    uint32_t deadline;
    uint32_t budget; /* the bound at entry (clamped as deadline_in()) */
    uint32_t slept;  /* ms slept on ENOBUFS so far, all frames together */
} tx_time_t;

static tx_time_t tx_time(uint32_t timeout_ms)
{
    tx_time_t t;
    t.deadline = deadline_in(timeout_ms);
    t.budget = timeout_ms > TASE_SOCKETCAN_TIMEOUT_MAX ? TASE_SOCKETCAN_TIMEOUT_MAX : timeout_ms;
    t.slept = 0;
    return t;
}

/* One frame out, retrying a full queue until the deadline. Every wait
 * ends: a POLLOUT wait that ran the time left, or ENOBUFS sleeps adding up
 * to the budget, end the retries after one last try, and an interrupted
 * write() is retried only while time is left. */
static int send_until(tase_socketcan_t *s, const tase_can_frame_t *f, tx_time_t *t)
{
    struct can_frame cf;
    bool refused = false;
    bool spent = false; /* the last wait used up the time left */
    to_linux(f, &cf);
    for (;;) {
        ssize_t n = write(s->fd, &cf, sizeof(cf));
        int e = errno;
        uint32_t left;
        if (n == (ssize_t)sizeof(cf)) {
            s->stats.frames_tx++;
            return TASE_OK;
        }
        if (n >= 0) {
            s->stats.last_errno = EMSGSIZE;
            return TASE_EIO;
        }
        if (e != EINTR && !would_block(e) && e != ENOBUFS) {
            return io_error(s, e);
        }
        if (e == ENOBUFS && !refused) {
            refused = true; /* the frame, not each retry */
            s->bus.enobufs++;
        }
        left = remaining(t->deadline);
        if (left == 0u || spent) {
            s->stats.tx_full++;
            return TASE_ENOBUFS;
        }
        if (e == EINTR) {
            continue; /* resumed with the time left */
        }
        s->stats.tx_retries++;
        /* ENOBUFS comes from the interface queue, which poll() does not
         * see, so sleep a little too rather than spin on POLLOUT. */
        if (e == ENOBUFS) {
            uint32_t slice = min_u32(min_u32(left, RETRY_SLEEP_MS), t->budget - t->slept);
            sleep_ms(slice);
            t->slept += slice;
            spent = t->slept >= t->budget;
        } else {
            int w = wait_fd(s->fd, POLLOUT, left);
            if (w < 0) {
                s->stats.last_errno = errno;
                return TASE_EIO;
            }
            spent = w == WAIT_TIMEOUT;
        }
    }
}

int tase_socketcan_send_frame(tase_socketcan_t *s, const tase_can_frame_t *f)
{
    tx_time_t t;
    if (!usable(s) || tase_can_frame_check(f) != TASE_OK) {
        return TASE_EARG;
    }
    t = tx_time(s->tx_timeout_ms);
    return send_until(s, f, &t);
}

int tase_socketcan_write(tase_socketcan_t *s, const uint8_t *data, size_t n)
{
    tase_can_split_t sp;
    tase_can_frame_t f;
    tx_time_t t;
    if (!usable(s) || n > (size_t)0x7FFFFFFF ||
        tase_can_split_init(&sp, s->role, data, n) != TASE_OK) {
        return TASE_EARG;
    }
    t = tx_time(s->tx_timeout_ms);
    for (;;) {
        size_t before = sp.pos;
        int rc;
        if (tase_can_split_next(&sp, &f) <= 0) {
            return (int)n;
        }
        rc = send_until(s, &f, &t);
        if (rc != TASE_OK) {
            return before > 0u ? (int)before : rc;
        }
    }
}

/* One record of a CAN_RAW socket: a classic frame (CAN_MTU bytes) or, on
 * a socket with CAN_RAW_FD_FRAMES, an FD frame (CANFD_MTU bytes). */
typedef union {
    struct can_frame cc;
    struct canfd_frame fd;
} can_record_t;

/* Count an error frame and follow the bus state it reports. */
static void bus_error_frame(tase_socketcan_t *s, const struct can_frame *cf)
{
    tase_socketcan_bus_t *b = &s->bus;
    canid_t c = cf->can_id & CAN_ERR_MASK;
    uint8_t ctrl = (c & CAN_ERR_CRTL) != 0u ? cf->data[1] : 0u;
    b->error_frames++;
    if ((c & CAN_ERR_TX_TIMEOUT) != 0u) {
        b->tx_timeouts++;
    }
    if ((c & CAN_ERR_ACK) != 0u) {
        b->no_acks++;
    }
    if ((c & (CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_BUSERROR)) != 0u) {
        b->bus_errors++;
    }
    if ((ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0u) {
        b->overflows++;
    }
    if ((c & CAN_ERR_CNT) != 0u) {
        b->tx_error_count = cf->data[6];
        b->rx_error_count = cf->data[7];
    }
    /* The worst state a frame reports wins; a restart or "active again"
     * ends a passive or bus-off period. */
    if ((c & CAN_ERR_BUSOFF) != 0u) {
        b->bus_offs++;
        b->state = TASE_SOCKETCAN_BUS_OFF;
    } else if ((ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0u) {
        b->passives++;
        b->state = TASE_SOCKETCAN_BUS_PASSIVE;
    } else if ((ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0u) {
        b->warnings++;
        b->state = TASE_SOCKETCAN_BUS_WARNING;
    } else if ((ctrl & CAN_ERR_CRTL_ACTIVE) != 0u || (c & CAN_ERR_RESTARTED) != 0u) {
        b->state = TASE_SOCKETCAN_BUS_ACTIVE;
    } else {
        /* a bus error without a state change */
    }
    if ((c & CAN_ERR_RESTARTED) != 0u) {
        b->restarts++;
    }
}

/* One record from the socket into *cf (a classic frame fills the first
 * CAN_MTU bytes), with its kernel receive time in *ns (0: none). Returns
 * the record's length, 0 for an AF_UNIX peer that closed, -1 with errno. */
static ssize_t recv_record(int fd, can_record_t *cf, uint64_t *ns)
{
    union {
        struct cmsghdr align;
        unsigned char buf[CMSG_SPACE(sizeof(struct timespec))];
    } ctl;
    struct iovec iov;
    struct msghdr m;
    struct cmsghdr *c;
    ssize_t n;
    iov.iov_base = cf;
    iov.iov_len = sizeof *cf;
    memset(&m, 0, sizeof m);
    m.msg_iov = &iov;
    m.msg_iovlen = 1;
    m.msg_control = ctl.buf;
    m.msg_controllen = sizeof ctl.buf;
    n = recvmsg(fd, &m, 0);
    *ns = 0;
    if (n <= 0) {
        return n;
    }
    if ((m.msg_flags & MSG_TRUNC) != 0) {
        return (ssize_t)sizeof *cf + 1; /* longer than any CAN record */
    }
    for (c = CMSG_FIRSTHDR(&m); c != NULL; c = CMSG_NXTHDR(&m, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
            struct timespec ts;
            memcpy(&ts, CMSG_DATA(c), sizeof ts);
            *ns = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
        }
    }
    return n;
}

/* One record of the socket, sorted: 1 (a data frame for the caller, *f
 * filled), 0 (nothing for the caller: counted and dropped), or TASE_EIO. */
static int take_record(tase_socketcan_t *s, ssize_t n, const can_record_t *cf, tase_can_frame_t *f)
{
    if (n == (ssize_t)CAN_MTU && (cf->cc.can_id & CAN_ERR_FLAG) != 0u) {
        bus_error_frame(s, &cf->cc);
        return 0;
    }
    if (n == (ssize_t)CAN_MTU) {
        s->stats.frames_rx++;
        if (from_linux(&cf->cc, f)) {
            return 1;
        }
        s->stats.bad_frames++;
        return 0;
    }
    if (n == (ssize_t)CANFD_MTU) {
        /* An FD socket (adopted with CAN_RAW_FD_FRAMES) passes FD frames:
         * the TASE datalink is classic CAN only. */
        tase_can_frame_t id;
        s->stats.frames_rx++;
        memset(&id, 0, sizeof id);
        id.extended = (cf->fd.can_id & CAN_EFF_FLAG) != 0u;
        id.id = cf->fd.can_id & (id.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
        if (role_wants(s->role, &id)) {
            s->stats.fd_rejected++;
        } else {
            s->stats.frames_ignored++;
        }
        return 0;
    }
    if (n == 0) {
        s->stats.last_errno = EPIPE; /* an AF_UNIX peer that closed */
        return TASE_EIO;
    }
    s->stats.bad_frames++; /* a short or over-long message: not ours to decode */
    return 0;
}

/* A frame that gives the caller nothing was taken: true when the call is
 * to end as if its wait ran out (the deadline has passed, checked every
 * SKIP_BATCH such frames), so that a flood of them (error frames, other
 * nodes, 3AX status) cannot hold a read past its timeout: at most
 * SKIP_BATCH - 1 more are handled after it. */
static bool skip_ends(uint32_t deadline, unsigned *skipped)
{
    *skipped += 1u;
    return *skipped % SKIP_BATCH == 0u && remaining(deadline) == 0u;
}

/* Next data frame from the socket by `deadline`: 1, 0 or an error (ERRORS
 * in the header); *ns is the frame's kernel receive time. */
static int raw_recv(tase_socketcan_t *s, tase_can_frame_t *f, uint64_t *ns, uint32_t deadline,
                    unsigned *skipped)
{
    can_record_t cf;
    for (;;) {
        uint32_t left;
        int e;
        int w;
        ssize_t n = recv_record(s->fd, &cf, ns);
        if (n >= 0) {
            int rc = take_record(s, n, &cf, f);
            if (rc != 0) {
                return rc;
            }
            if (skip_ends(deadline, skipped)) {
                return 0;
            }
            continue;
        }
        e = errno; /* before the clock is read */
        if (e != EINTR && !would_block(e)) {
            return io_error(s, e);
        }
        left = remaining(deadline);
        if (left == 0u) {
            return 0; /* also for an interrupted recvmsg(): a storm of them ends */
        }
        if (e == EINTR) {
            continue; /* resumed with the time left */
        }
        w = wait_fd(s->fd, POLLIN, left);
        if (w < 0) {
            s->stats.last_errno = errno;
            return TASE_EIO;
        }
        if (w == WAIT_TIMEOUT) {
            return 0; /* the time left is spent, whatever the clock says */
        }
    }
}

/* Next frame the role's filter passes (software copy of the kernel's). */
static int recv_wanted(tase_socketcan_t *s, tase_can_frame_t *f, uint64_t *ns, uint32_t deadline,
                       unsigned *skipped)
{
    for (;;) {
        int rc = raw_recv(s, f, ns, deadline, skipped);
        if (rc <= 0 || role_wants(s->role, f)) {
            return rc;
        }
        s->stats.frames_ignored++;
        if (skip_ends(deadline, skipped)) {
            return 0;
        }
    }
}

static void side_push(tase_socketcan_t *s, const tase_can_frame_t *f, uint64_t ns)
{
    unsigned i;
    if (s->side_count == TASE_SOCKETCAN_SIDEQ) {
        s->side_head = (uint8_t)((s->side_head + 1u) % TASE_SOCKETCAN_SIDEQ);
        s->side_count--;
        s->stats.side_dropped++;
    }
    i = (s->side_head + s->side_count) % TASE_SOCKETCAN_SIDEQ;
    s->side[i] = *f;
    s->side_ns[i] = ns;
    s->side_count++;
}

static size_t take_pending(tase_socketcan_t *s, uint8_t *buf, size_t cap)
{
    size_t k = (size_t)(s->pend_len - s->pend_pos);
    if (k > cap) {
        k = cap;
    }
    memcpy(buf, &s->pend[s->pend_pos], k);
    s->pend_pos = (uint8_t)(s->pend_pos + k);
    s->stats.bytes_rx += (uint32_t)k;
    if (k > 0u) {
        s->rx_ns = s->pend_ns;
    }
    return k;
}

int tase_socketcan_read(tase_socketcan_t *s, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    tase_can_frame_t f;
    uint32_t deadline;
    uint64_t ns;
    size_t got;
    unsigned skipped = 0;
    if (!usable(s) || buf == NULL || cap > (size_t)0x7FFFFFFF) {
        return TASE_EARG;
    }
    deadline = deadline_in(timeout_ms);
    got = take_pending(s, buf, cap);
    if (s->rx_err != 0) {
        /* the error the last call met after its bytes: the kernel said it
         * once, so it is said now (after what was received before it) */
        int e = s->rx_err;
        if (got > 0u) {
            return (int)got;
        }
        s->rx_err = 0;
        return e;
    }
    /* Once some bytes are in hand, only drain what is already queued. */
    while (got < cap) {
        /* bytes in hand: what is queued only, now (also for the frames
         * skipped below) */
        uint32_t until = got > 0u ? deadline_in(0u) : deadline;
        int rc = recv_wanted(s, &f, &ns, until, &skipped);
        if (rc < 0 && got > 0u) {
            s->rx_err = rc;
            return (int)got;
        }
        if (rc < 0) {
            return rc;
        }
        if (rc == 0) {
            break;
        }
        rc = tase_can_accept(s->role, &f);
        if (rc > 0) {
            memcpy(s->pend, f.data, (size_t)rc);
            s->pend_pos = 0;
            s->pend_len = (uint8_t)rc;
            s->pend_ns = ns;
            got += take_pending(s, buf + got, cap - got);
        } else if (rc == TASE_EUNKNOWN) {
            side_push(s, &f, ns);
        } else {
            s->stats.bad_frames++;
        }
        if (rc <= 0 && skip_ends(until, &skipped)) {
            break; /* a frame with no bytes for the caller */
        }
    }
    return (int)got;
}

int tase_socketcan_recv_frame(tase_socketcan_t *s, tase_can_frame_t *f, uint32_t timeout_ms)
{
    if (!usable(s) || f == NULL) {
        return TASE_EARG;
    }
    if (s->side_count > 0u) {
        *f = s->side[s->side_head];
        s->rx_ns = s->side_ns[s->side_head];
        s->side_head = (uint8_t)((s->side_head + 1u) % TASE_SOCKETCAN_SIDEQ);
        s->side_count--;
        return 1;
    }
    {
        uint64_t ns;
        unsigned skipped = 0;
        int rc = recv_wanted(s, f, &ns, deadline_in(timeout_ms), &skipped);
        if (rc == 1) {
            s->rx_ns = ns;
        }
        return rc;
    }
}

int tase_socketcan_bus(const tase_socketcan_t *s, tase_socketcan_bus_t *out)
{
    if (s == NULL || out == NULL) {
        return TASE_EARG;
    }
    *out = s->bus;
    return TASE_OK;
}

uint64_t tase_socketcan_rx_time_ns(const tase_socketcan_t *s)
{
    return s == NULL ? 0u : s->rx_ns;
}

static int port_write(void *ctx, const uint8_t *data, size_t n)
{
    return tase_socketcan_write(ctx, data, n);
}

static int port_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    return tase_socketcan_read(ctx, buf, cap, timeout_ms);
}

const tase_port_ops_t tase_socketcan_ops = {port_write, port_read, tase_socketcan_now_ms};

tase_port_t tase_socketcan_port(tase_socketcan_t *s)
{
    tase_port_t p;
    p.ops = &tase_socketcan_ops;
    p.ctx = s;
    p.bytes_per_s = TASE_SOCKETCAN_BYTES_PER_S;
    return p;
}
