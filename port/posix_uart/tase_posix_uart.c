/* POSIX termios serial port; see tase/posix_uart.h. */
#define _DEFAULT_SOURCE /* CRTSCTS, rates above B38400 with -std=c99 */

#include "tase/posix_uart.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

typedef struct {
    uint32_t baud;
    speed_t code;
} baud_map_t;

static const baud_map_t baud_map[] = {
    {50u, B50},           {75u, B75},     {110u, B110},   {134u, B134},     {150u, B150},
    {200u, B200},         {300u, B300},   {600u, B600},   {1200u, B1200},   {1800u, B1800},
    {2400u, B2400},       {4800u, B4800}, {9600u, B9600}, {19200u, B19200}, {38400u, B38400},
#ifdef B57600
    {57600u, B57600},
#endif
#ifdef B115200
    {115200u, B115200},
#endif
#ifdef B230400
    {230400u, B230400},
#endif
#ifdef B460800
    {460800u, B460800},
#endif
#ifdef B500000
    {500000u, B500000},
#endif
#ifdef B576000
    {576000u, B576000},
#endif
#ifdef B921600
    {921600u, B921600},
#endif
#ifdef B1000000
    {1000000u, B1000000},
#endif
#ifdef B1152000
    {1152000u, B1152000},
#endif
#ifdef B1500000
    {1500000u, B1500000},
#endif
#ifdef B2000000
    {2000000u, B2000000},
#endif
#ifdef B2500000
    {2500000u, B2500000},
#endif
#ifdef B3000000
    {3000000u, B3000000},
#endif
#ifdef B3500000
    {3500000u, B3500000},
#endif
#ifdef B4000000
    {4000000u, B4000000},
#endif
};

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

static bool baud_code(uint32_t baud, speed_t *code)
{
    size_t i;
    for (i = 0; i < sizeof baud_map / sizeof baud_map[0]; i++) {
        if (baud_map[i].baud == baud) {
            *code = baud_map[i].code;
            return true;
        }
    }
    return false;
}

bool tase_posix_uart_baud_supported(uint32_t baud)
{
    speed_t code;
    return baud_code(baud, &code);
}

uint32_t tase_posix_now_ms(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) != 0) {
        return 0u; /* no clock (a sandbox refusing it): time stands still */
    }
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

static int map_open_errno(int e)
{
    switch (e) {
    case EBUSY: return TASE_EBUSY; /* TIOCEXCL of another program */
    case ENOENT:
    case ENXIO:
    case ENODEV:
    case ENOTDIR:
    case EISDIR:
    case ENOTTY: return TASE_ENODEV;
    case EACCES:
    case EPERM:
    case EROFS: return TASE_EACCES;
    default: return TASE_EIO;
    }
}

/* Raw 8N1, spelled out flag by flag rather than cfmakeraw() (not POSIX)
 * so the contract in the header is visibly what the code does. */
static int configure(int fd, speed_t code)
{
    struct termios t;
    struct termios check;

    if (tcgetattr(fd, &t) != 0) {
        return map_open_errno(errno);
    }
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                             IXOFF | IXANY | INPCK);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHOE | ECHOK | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB);
#ifdef CRTSCTS
    t.c_cflag &= ~(tcflag_t)CRTSCTS;
#endif
    t.c_cflag |= (tcflag_t)(CS8 | CLOCAL | CREAD);
    /* Reads never block in the kernel: waiting is done with poll(). */
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    if (cfsetispeed(&t, code) != 0 || cfsetospeed(&t, code) != 0) {
        return TASE_EUNSUPPORTED;
    }
    if (tcsetattr(fd, TCSANOW, &t) != 0) {
        return errno == EINVAL ? TASE_EUNSUPPORTED : TASE_EIO;
    }
    /* tcsetattr() succeeds if *any* change was applied: read back. */
    if (tcgetattr(fd, &check) != 0) {
        return TASE_EIO;
    }
    if (cfgetospeed(&check) != code) {
        return TASE_EUNSUPPORTED;
    }
    /* Stale input (received before we owned the line) is dropped; output
     * still queued by the previous owner is not ours to drop: on a pty it
     * is that program's last command, not yet read by the peer. */
    (void)tcflush(fd, TCIFLUSH);
    return TASE_OK;
}

/* Exclusive use of the device: an advisory lock every cooperating
 * program (ours, and minicom, picocom, ModemManager...) sees, and the
 * kernel's TIOCEXCL, which refuses any further open() except root's. */
static int take_exclusive(tase_posix_uart_t *u, int fd)
{
    int r;
    do {
        r = flock(fd, LOCK_EX | LOCK_NB);
    } while (r != 0 && errno == EINTR);
    if (r != 0) {
        return errno == EWOULDBLOCK ? TASE_EBUSY : TASE_EIO;
    }
#ifdef TIOCGEXCL
    {
        /* Another program's TIOCEXCL without a lock: the kernel lets only
         * root past it, and clearing it at close would take the other
         * program's exclusivity away. */
        int held = 0;
        if (ioctl(fd, TIOCGEXCL, &held) == 0 && held != 0) {
            return TASE_EBUSY; /* the lock goes with the descriptor */
        }
    }
#endif
#ifdef TIOCEXCL
    /* Best effort: the lock above already keeps our own programs apart. */
    u->excl = ioctl(fd, TIOCEXCL) == 0;
#endif
    return TASE_OK;
}

/* Undo what open did to the device, in reverse: settings, then
 * exclusivity (the lock goes with the descriptor). */
static void give_back(tase_posix_uart_t *u, int fd)
{
    if (u->restore) {
        while (tcsetattr(fd, TCSADRAIN, &u->saved) != 0 && errno == EINTR) {
        }
        u->restore = false;
    }
#ifdef TIOCNXCL
    if (u->excl) {
        (void)ioctl(fd, TIOCNXCL);
    }
#endif
    u->excl = false;
}

/* Wait up to timeout_ms for the bytes written to leave the kernel's output
 * queue; drop what is still there then (a stuck line would otherwise hold
 * close() for the kernel's closing wait, 30 s). */
static void drain_bounded(int fd, uint32_t timeout_ms)
{
#ifdef TIOCOUTQ
    uint32_t start = tase_posix_now_ms();
    uint32_t naps = 0; /* whole 2 ms naps: the bound also when the clock stands still */
    int queued = 0;
    while (ioctl(fd, TIOCOUTQ, &queued) == 0 && queued > 0) {
        struct timespec ts = {0, 2000000L};
        if ((uint32_t)(tase_posix_now_ms() - start) >= timeout_ms ||
            naps >= (timeout_ms + 1u) / 2u) {
            (void)tcflush(fd, TCOFLUSH);
            return;
        }
        while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
            /* a signal: the rest of the nap (a nap cut short by signals
             * would make the count end the drain early) */
        }
        naps++;
    }
#else
    (void)fd;
    (void)timeout_ms;
#endif
}

static int setup_fd(tase_posix_uart_t *u, int fd, uint32_t baud, speed_t code, unsigned flags)
{
    int fl = fcntl(fd, F_GETFL);
    int r;
    u->restore = false;
    u->excl = false;
    if (!isatty(fd)) {
        return TASE_ENODEV; /* before anything is changed */
    }
    if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) < 0) {
        return TASE_EIO;
    }
    if ((flags & TASE_POSIX_UART_SHARED) == 0u) {
        r = take_exclusive(u, fd);
        if (r != TASE_OK) {
            return r;
        }
    }
    if (tcgetattr(fd, &u->saved) != 0) {
        give_back(u, fd);
        return map_open_errno(errno);
    }
    u->restore = true;
    r = configure(fd, code);
    if (r != TASE_OK) {
        give_back(u, fd);
        return r;
    }
    u->fd = fd;
    u->baud = baud;
    u->write_timeout_ms = TASE_POSIX_UART_WRITE_TIMEOUT_MS;
    return TASE_OK;
}

int tase_posix_uart_open_flags(tase_posix_uart_t *u, const char *path, uint32_t baud,
                               unsigned flags)
{
    speed_t code;
    int fd, r;

    if (u == NULL || path == NULL || (flags & ~TASE_POSIX_UART_SHARED) != 0u) {
        return TASE_EARG;
    }
    u->fd = -1;
    if (!baud_code(baud, &code)) {
        return TASE_EUNSUPPORTED;
    }
    do {
        fd = open(path, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    } while (fd < 0 && errno == EINTR);
    if (fd < 0) {
        return map_open_errno(errno);
    }
    r = setup_fd(u, fd, baud, code, flags);
    if (r != TASE_OK) {
        (void)close(fd);
    }
    return r;
}

int tase_posix_uart_open(tase_posix_uart_t *u, const char *path, uint32_t baud)
{
    return tase_posix_uart_open_flags(u, path, baud, 0u);
}

int tase_posix_uart_attach(tase_posix_uart_t *u, int fd, uint32_t baud)
{
    speed_t code;

    if (u == NULL || fd < 0) {
        return TASE_EARG;
    }
    u->fd = -1;
    if (!baud_code(baud, &code)) {
        return TASE_EUNSUPPORTED;
    }
    return setup_fd(u, fd, baud, code, TASE_POSIX_UART_SHARED);
}

int tase_posix_uart_close(tase_posix_uart_t *u)
{
    int r;
    if (u == NULL) {
        return TASE_EARG;
    }
    if (u->fd < 0) {
        return TASE_OK;
    }
    if (u->restore) {
        drain_bounded(u->fd, u->write_timeout_ms);
    }
    give_back(u, u->fd);
    r = close(u->fd);
    u->fd = -1;
    return r == 0 ? TASE_OK : TASE_EIO;
}

/* Times read() may find nothing after poll() said the line is readable
 * before the call ends as an idle line (early: a busy loop otherwise, and
 * one without end when the clock does not move). */
#define POSIX_UART_READY_SPINS 1024u

/* Milliseconds left of `total` since `start`, 0 when spent. */
static int time_left(uint32_t start, uint32_t total)
{
    uint32_t spent = tase_posix_now_ms() - start;
    uint32_t left = spent >= total ? 0u : total - spent;
    return left > 0x7FFFFFFFu ? 0x7FFFFFFF : (int)left;
}

static int uart_write(void *ctx, const uint8_t *data, size_t n)
{
    tase_posix_uart_t *u = ctx;
    uint32_t start = tase_posix_now_ms();
    size_t done = 0;

    if (u == NULL || u->fd < 0 || (data == NULL && n > 0) || n > 0x7FFFFFFFu) {
        return TASE_EARG;
    }
    if (n == 0u) {
        return 0;
    }
    while (done < n) {
        struct pollfd pfd;
        int left, pr;
        ssize_t w = write(u->fd, data + done, n - done);
        bool intr = w < 0 && errno == EINTR;
        if (w > 0) {
            done += (size_t)w;
            continue;
        }
        if (w < 0 && !intr && !would_block(errno)) {
            /* a hang-up after part of it went out: that part is counted
             * (port.h: never drop bytes silently); the next call says EIO */
            return done > 0 ? (int)done : TASE_EIO;
        }
        /* Full (or interrupted): wait for room within the bound. A signal
         * resumes with the time left, so a storm of them cannot hold the
         * call past it. */
        left = time_left(start, u->write_timeout_ms);
        if (left == 0) {
            break;
        }
        if (intr) {
            continue;
        }
        pfd.fd = u->fd;
        pfd.events = POLLOUT;
        pfd.revents = 0;
        pr = poll(&pfd, 1, left);
        if (pr < 0 && errno != EINTR) {
            return TASE_EIO;
        }
        if (pr == 0) {
            break; /* poll() waited the time left (also when the clock stands still) */
        }
        /* A pty master whose peer closed reports POLLHUP without POLLOUT
         * at once: without this test the loop spun until the bound. */
        if (pr > 0 && (pfd.revents & POLLOUT) == 0 &&
            (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
            return done > 0 ? (int)done : TASE_EIO;
        }
    }
    return done > 0 ? (int)done : TASE_EAGAIN;
}

static int uart_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    tase_posix_uart_t *u = ctx;
    uint32_t start = tase_posix_now_ms();
    bool hangup = false;
    unsigned ready_empty = 0; /* poll() said readable, read() brought nothing */

    if (u == NULL || u->fd < 0 || buf == NULL || cap == 0) {
        return TASE_EARG;
    }
    if (cap > 0x7FFFFFFFu) {
        cap = 0x7FFFFFFFu;
    }
    for (;;) {
        struct pollfd pfd;
        int pr, left;
        ssize_t r = read(u->fd, buf, cap);
        bool intr = r < 0 && errno == EINTR;
        if (r > 0) {
            return (int)r;
        }
        /* With VMIN = VTIME = 0 an empty tty reads as 0, not EAGAIN, and so
         * does a hung-up one: poll() below tells them apart. */
        if ((r < 0 && !intr && !would_block(errno)) || hangup) {
            return TASE_EIO;
        }
        /* With no time left poll() still runs, with a zero timeout: a
         * caller that never waits must see a hang-up too, not an idle line.
         * A signal resumes with the time left; once none is, the call ends
         * as an idle line would (a storm of signals cannot hold it). */
        left = time_left(start, timeout_ms);
        if (intr) {
            if (left == 0) {
                return 0;
            }
            continue;
        }
        pfd.fd = u->fd;
        pfd.events = POLLIN;
        pfd.revents = 0;
        pr = poll(&pfd, 1, left);
        if (pr < 0 && errno != EINTR) {
            return TASE_EIO;
        }
        if (pr == 0 || (pr < 0 && left == 0)) {
            return 0;
        }
        /* Hang-up reports POLLIN too (read gives 0): read once more for
         * bytes still queued, then fail. */
        if (pr > 0 && (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
            hangup = true;
        } else if (pr > 0 && ++ready_empty > 1u &&
                   (left == 0 || ready_empty > POSIX_UART_READY_SPINS)) {
            /* readable, yet read() brought nothing again (another reader
             * of a shared line took the bytes): with no time left, or
             * after POSIX_UART_READY_SPINS such looks, it ends as an idle
             * line, possibly before its timeout (port.h allows a read to
             * return 0 early; it spun for ever with a clock that stands
             * still, and would spin until the timeout otherwise) */
            return 0;
        }
    }
}

static uint32_t uart_now_ms(void *ctx)
{
    (void)ctx;
    return tase_posix_now_ms();
}

const tase_port_ops_t tase_posix_uart_ops = {uart_write, uart_read, uart_now_ms};

tase_port_t tase_posix_uart_port(tase_posix_uart_t *u)
{
    tase_port_t p;
    p.ops = &tase_posix_uart_ops;
    p.ctx = u;
    p.bytes_per_s = (u != NULL) ? TASE_UART_BYTES_PER_S(u->baud) : 0u;
    return p;
}
