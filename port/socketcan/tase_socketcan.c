/* SocketCAN port: struct can_frame <-> tase_can_frame_t lives here only. */
#define _DEFAULT_SOURCE 1

#include "tase/socketcan.h"

#include <errno.h>
#include <fcntl.h>
#include <net/if.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <linux/can.h>
#include <linux/can/raw.h>

#define RETRY_SLEEP_MS 1u

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
    size_t n = role_filter_ids(role, ids);
    size_t i;
    for (i = 0; i < n; i++) {
        flt[i].can_id = ids[i] | CAN_EFF_FLAG;
        flt[i].can_mask = CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_EFF_MASK;
    }
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, flt, (socklen_t)(n * sizeof(flt[0]))) != 0) {
        return TASE_EIO;
    }
    return TASE_OK;
}

uint32_t tase_socketcan_now_ms(void *ctx)
{
    struct timespec ts;
    (void)ctx;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

/* Milliseconds left until `deadline` (0 once it has passed). */
static uint32_t remaining(uint32_t deadline)
{
    uint32_t left = deadline - tase_socketcan_now_ms(NULL);
    return left > 0x7FFFFFFFu ? 0u : left;
}

static void sleep_ms(uint32_t ms)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(ms / 1000u);
    ts.tv_nsec = (long)(ms % 1000u) * 1000000L;
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

static int wait_fd(int fd, short events, uint32_t timeout_ms)
{
    struct pollfd p;
    int rc;
    p.fd = fd;
    p.events = events;
    p.revents = 0;
    rc = poll(&p, 1, timeout_ms > 0x7FFFFFFFu ? 0x7FFFFFFF : (int)timeout_ms);
    return rc < 0 && errno != EINTR ? TASE_EIO : rc;
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

/* One frame out, retrying a full queue until `deadline`. */
static int send_until(tase_socketcan_t *s, const tase_can_frame_t *f, uint32_t deadline)
{
    struct can_frame cf;
    to_linux(f, &cf);
    for (;;) {
        ssize_t n = write(s->fd, &cf, sizeof(cf));
        int e = errno;
        if (n == (ssize_t)sizeof(cf)) {
            s->stats.frames_tx++;
            return TASE_OK;
        }
        if (n >= 0) {
            s->stats.last_errno = EMSGSIZE;
            return TASE_EIO;
        }
        if (e == EINTR) {
            continue;
        }
        if (e != EAGAIN && e != EWOULDBLOCK && e != ENOBUFS) {
            s->stats.last_errno = e;
            return TASE_EIO;
        }
        if (remaining(deadline) == 0u) {
            s->stats.tx_full++;
            return TASE_ENOBUFS;
        }
        s->stats.tx_retries++;
        /* ENOBUFS comes from the interface queue, which poll() does not
         * see, so sleep a little too rather than spin on POLLOUT. */
        if (e == ENOBUFS) {
            sleep_ms(RETRY_SLEEP_MS);
        } else if (wait_fd(s->fd, POLLOUT, remaining(deadline)) < 0) {
            s->stats.last_errno = errno;
            return TASE_EIO;
        }
    }
}

int tase_socketcan_send_frame(tase_socketcan_t *s, const tase_can_frame_t *f)
{
    if (!usable(s) || tase_can_frame_check(f) != TASE_OK) {
        return TASE_EARG;
    }
    return send_until(s, f, tase_socketcan_now_ms(NULL) + s->tx_timeout_ms);
}

int tase_socketcan_write(tase_socketcan_t *s, const uint8_t *data, size_t n)
{
    tase_can_split_t sp;
    tase_can_frame_t f;
    uint32_t deadline;
    if (!usable(s) || n > (size_t)0x7FFFFFFF ||
        tase_can_split_init(&sp, s->role, data, n) != TASE_OK) {
        return TASE_EARG;
    }
    deadline = tase_socketcan_now_ms(NULL) + s->tx_timeout_ms;
    for (;;) {
        size_t before = sp.pos;
        int rc;
        if (tase_can_split_next(&sp, &f) <= 0) {
            return (int)n;
        }
        rc = send_until(s, &f, deadline);
        if (rc != TASE_OK) {
            return before > 0u ? (int)before : rc;
        }
    }
}

/* Next data frame from the socket within timeout_ms: 1, 0 or TASE_EIO. */
static int raw_recv(tase_socketcan_t *s, tase_can_frame_t *f, uint32_t timeout_ms)
{
    struct can_frame cf;
    uint32_t deadline = tase_socketcan_now_ms(NULL) + timeout_ms;
    for (;;) {
        ssize_t n = read(s->fd, &cf, sizeof(cf));
        if (n == (ssize_t)sizeof(cf)) {
            s->stats.frames_rx++;
            if (from_linux(&cf, f)) {
                return 1;
            }
            s->stats.bad_frames++;
            continue;
        }
        if (n >= 0) {
            /* A CAN FD record or a short message: not ours to decode. An
             * AF_UNIX peer that closed gives 0 bytes: report it. */
            if (n == 0) {
                s->stats.last_errno = EPIPE;
                return TASE_EIO;
            }
            s->stats.bad_frames++;
            continue;
        }
        if (errno == EINTR) {
            continue;
        }
        if (errno != EAGAIN && errno != EWOULDBLOCK) {
            s->stats.last_errno = errno;
            return TASE_EIO;
        }
        if (remaining(deadline) == 0u) {
            return 0;
        }
        if (wait_fd(s->fd, POLLIN, remaining(deadline)) < 0) {
            s->stats.last_errno = errno;
            return TASE_EIO;
        }
    }
}

/* Next frame the role's filter passes (software copy of the kernel's). */
static int recv_wanted(tase_socketcan_t *s, tase_can_frame_t *f, uint32_t timeout_ms)
{
    uint32_t deadline = tase_socketcan_now_ms(NULL) + timeout_ms;
    for (;;) {
        int rc = raw_recv(s, f, remaining(deadline));
        if (rc <= 0 || role_wants(s->role, f)) {
            return rc;
        }
        s->stats.frames_ignored++;
    }
}

static void side_push(tase_socketcan_t *s, const tase_can_frame_t *f)
{
    if (s->side_count == TASE_SOCKETCAN_SIDEQ) {
        s->side_head = (uint8_t)((s->side_head + 1u) % TASE_SOCKETCAN_SIDEQ);
        s->side_count--;
        s->stats.side_dropped++;
    }
    s->side[(s->side_head + s->side_count) % TASE_SOCKETCAN_SIDEQ] = *f;
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
    return k;
}

int tase_socketcan_read(tase_socketcan_t *s, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    tase_can_frame_t f;
    uint32_t deadline;
    size_t got;
    if (!usable(s) || buf == NULL || cap > (size_t)0x7FFFFFFF) {
        return TASE_EARG;
    }
    deadline = tase_socketcan_now_ms(NULL) + timeout_ms;
    got = take_pending(s, buf, cap);
    /* Once some bytes are in hand, only drain what is already queued. */
    while (got < cap) {
        int rc = recv_wanted(s, &f, got > 0u ? 0u : remaining(deadline));
        if (rc < 0) {
            return got > 0u ? (int)got : rc;
        }
        if (rc == 0) {
            break;
        }
        rc = tase_can_accept(s->role, &f);
        if (rc > 0) {
            memcpy(s->pend, f.data, (size_t)rc);
            s->pend_pos = 0;
            s->pend_len = (uint8_t)rc;
            got += take_pending(s, buf + got, cap - got);
        } else if (rc == TASE_EUNKNOWN) {
            side_push(s, &f);
        } else {
            s->stats.bad_frames++;
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
        s->side_head = (uint8_t)((s->side_head + 1u) % TASE_SOCKETCAN_SIDEQ);
        s->side_count--;
        return 1;
    }
    return recv_wanted(s, f, timeout_ms);
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
    return p;
}
