/* Shared helpers of the host tools: errors, argument parsing, clocks,
 * descriptor-backed ports and pseudo-terminals. */
#define _XOPEN_SOURCE 700 /* posix_openpt, grantpt, unlockpt, ptsname */

#include "toolkit.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

const char *tk_prog = "tase";

static void vdie(int status, const char *fmt, va_list ap)
{
    char msg[512];
    vsnprintf(msg, sizeof(msg), fmt, ap);
    /* the contract is one line: fold anything a caller let through */
    for (char *c = msg; *c != '\0'; c++) {
        if (*c == '\n' || *c == '\r') {
            *c = ' ';
        }
    }
    fflush(stdout);
    fprintf(stderr, "%s: %s\n", tk_prog, msg);
    exit(status);
}

void tk_die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vdie(TK_EXIT_FAIL, fmt, ap);
    va_end(ap);
}

void tk_usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vdie(TK_EXIT_USAGE, fmt, ap);
    va_end(ap);
}

int tk_parse_int(const char *s, long long min, long long max, long long *out)
{
    char *end;
    long long v;
    if (s == NULL || *s == '\0') {
        return -1;
    }
    errno = 0;
    v = strtoll(s, &end, 0);
    if (errno != 0 || *end != '\0' || v < min || v > max) {
        return -1;
    }
    *out = v;
    return 0;
}

int tk_parse_seconds(const char *s, double *out)
{
    char *end;
    double v;
    if (s == NULL || *s == '\0' || *s == '-') {
        return -1;
    }
    errno = 0;
    v = strtod(s, &end);
    if (errno != 0 || *end != '\0' || !(v >= 0.0) || v > 1e7) {
        return -1;
    }
    *out = v;
    return 0;
}

double tk_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

uint32_t tk_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000u + (uint64_t)ts.tv_nsec / 1000000u);
}

/* ---- links ---- */

void tk_link_serial(tk_link_t *l, const char *path, long baud)
{
    int rc;
    memset(l, 0, sizeof(*l));
    if (baud <= 0 || !tase_posix_uart_baud_supported((uint32_t)baud)) {
        tk_usage_error("unsupported baud rate %ld", baud);
    }
    rc = tase_posix_uart_open(&l->uart, path, (uint32_t)baud);
    if (rc != TASE_OK) {
        tk_die("cannot open serial device %s: %s", path,
               rc == TASE_EIO ? strerror(errno) : tase_strerror(rc));
    }
}

void tk_link_pty(tk_link_t *l, int fd)
{
    struct termios t;
    int rc;
    memset(l, 0, sizeof(*l));
    rc = tase_posix_uart_attach(&l->uart, fd, 115200u);
    if (rc != TASE_OK) {
        tk_die("cannot set up the pseudo-terminal: %s", tase_strerror(rc));
    }
    /* a simulator must not stall when nobody reads the link: drop instead */
    l->uart.write_timeout_ms = 0;
    /* The port reads with poll(), but plain readers of the slave (cat, a
     * capture) need read() to block rather than report end of file. */
    if (tcgetattr(fd, &t) == 0) {
        t.c_cc[VMIN] = 1;
        t.c_cc[VTIME] = 0;
        (void)tcsetattr(fd, TCSANOW, &t);
    }
}

void tk_link_can(tk_link_t *l, const char *iface, bool gimbal)
{
    int rc;
    memset(l, 0, sizeof(*l));
    l->is_can = true;
    rc = tase_socketcan_open(&l->can, iface, gimbal ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST);
    if (rc != TASE_OK) {
        tk_die("cannot open CAN interface %s: %s", iface, tase_strerror(rc));
    }
}

tase_port_t tk_link_port(tk_link_t *l)
{
    return l->is_can ? tase_socketcan_port(&l->can) : tase_posix_uart_port(&l->uart);
}

void tk_link_close(tk_link_t *l)
{
    if (l->is_can) {
        tase_socketcan_close(&l->can);
    } else {
        (void)tase_posix_uart_close(&l->uart);
    }
}

int tk_port_write_all(const tase_port_t *p, const uint8_t *data, size_t n)
{
    size_t done = 0;
    double deadline = tk_now_s() + 2.0;
    while (done < n) {
        int w = p->ops->write(p->ctx, data + done, n - done);
        if (w > 0) {
            done += (size_t)w;
        } else if (w == TASE_EAGAIN || w == TASE_ENOBUFS || w == 0) {
            struct timespec ts = {0, 2000000};
            if (tk_now_s() > deadline) {
                return TASE_ETIMEOUT;
            }
            nanosleep(&ts, NULL);
        } else {
            return w;
        }
    }
    return 0;
}

int tk_pty_open(char *slave, size_t cap, const char *link, int *slave_fd)
{
    int fd = posix_openpt(O_RDWR | O_NOCTTY);
    const char *name;
    int sfd;
    struct stat st;
    if (fd < 0) {
        tk_die("cannot create a pseudo-terminal: %s", strerror(errno));
    }
    if (grantpt(fd) != 0 || unlockpt(fd) != 0 || (name = ptsname(fd)) == NULL) {
        tk_die("cannot set up the pseudo-terminal: %s", strerror(errno));
    }
    if (strlen(name) + 1 > cap) {
        tk_die("pseudo-terminal path too long");
    }
    strcpy(slave, name);
    /* The simulator holds the slave open itself (never reading it): with
     * no other holder the master reports a hang-up between clients. */
    sfd = open(slave, O_RDWR | O_NOCTTY);
    if (sfd < 0) {
        tk_die("cannot open %s: %s", slave, strerror(errno));
    }
    *slave_fd = sfd;
    if (link != NULL) {
        if (lstat(link, &st) == 0) {
            if (!S_ISLNK(st.st_mode)) {
                tk_die("%s exists and is not a symlink; not replacing it", link);
            }
            unlink(link);
        }
        if (symlink(slave, link) != 0) {
            tk_die("cannot create symlink %s: %s", link, strerror(errno));
        }
    }
    return fd;
}

int tk_pty_unread(int slave_fd)
{
    int n = 0;
    return ioctl(slave_fd, FIONREAD, &n) == 0 && n > 0 ? n : 0;
}

int tk_pty_drop_unread(int slave_fd)
{
    int n = tk_pty_unread(slave_fd);
    if (n == 0) {
        return 0;
    }
    (void)tcflush(slave_fd, TCIFLUSH);
    return n;
}
