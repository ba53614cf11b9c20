/* Shared helpers of the host tools: errors, numbers, standard output,
 * signals, clocks, descriptor-backed ports and pseudo-terminals. */
#define _GNU_SOURCE /* posix_openpt, grantpt, unlockpt, ptsname */

#include "toolkit.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <limits.h>
#include <net/if.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

const char *tk_prog = "tase";

volatile sig_atomic_t tk_signal;

/* Links open now: every exit path closes them, so a device is always left
 * as the port's close() leaves it. */
#define MAX_OPEN_LINKS 4
static tk_link_t *open_links[MAX_OPEN_LINKS];

static void track_link(tk_link_t *l, bool open)
{
    size_t i;
    for (i = 0; i < MAX_OPEN_LINKS; i++) {
        if (open ? open_links[i] == NULL : open_links[i] == l) {
            open_links[i] = open ? l : NULL;
            return;
        }
    }
}

static void close_all_links(void)
{
    size_t i;
    for (i = 0; i < MAX_OPEN_LINKS; i++) {
        if (open_links[i] != NULL) {
            tk_link_close(open_links[i]);
        }
    }
}

static void vmsg(const char *fmt, va_list ap)
{
    char msg[3 * PATH_MAX + 1024]; /* vexit()'s message and its "(X was sent)" */
    vsnprintf(msg, sizeof(msg), fmt, ap);
    /* the contract is one line: fold anything a caller let through */
    for (char *c = msg; *c != '\0'; c++) {
        if (*c == '\n' || *c == '\r') {
            *c = ' ';
        }
    }
    fprintf(stderr, "%s: %s\n", tk_prog, msg);
}

/* The packet this run has sent, NULL before (tk_mark_sent()). */
static const char *volatile sent_what; /* read by on_fatal_signal() too */

void tk_mark_sent(const char *what)
{
    sent_what = what;
}

const char *tk_sent(void)
{
    return sent_what;
}

static void vexit(int status, const char *fmt, va_list ap)
{
    char msg[3 * PATH_MAX + 512]; /* a message may name three paths */
    /* what was printed before the error still goes out (errors ignored:
     * the error line is the one to report) */
    (void)fflush(stdout);
    close_all_links();
    vsnprintf(msg, sizeof(msg), fmt, ap);
    if (sent_what != NULL && status != TK_EXIT_MISMATCH && status != TK_EXIT_SENT) {
        /* a failure after the packet went out says so: a retry would send
         * it again */
        tk_warn("%s (%s was sent)", msg, sent_what);
    } else {
        tk_warn("%s", msg);
    }
    exit(status);
}

void tk_exit(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vexit(status, fmt, ap);
    va_end(ap);
}

void tk_die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vexit(TK_EXIT_FAIL, fmt, ap);
    va_end(ap);
}

void tk_usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vexit(TK_EXIT_USAGE, fmt, ap);
    va_end(ap);
}

void tk_warn(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmsg(fmt, ap);
    va_end(ap);
}

/* ---- numbers ---- */

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

int tk_parse_int(const char *s, long long min, long long max, long long *out, bool *hex)
{
    unsigned long long mag = 0, limit;
    unsigned base = 10;
    bool neg = false, overflow = false;
    long long v;
    if (s == NULL) {
        return TK_NUM_SYNTAX;
    }
    if (*s == '+' || *s == '-') {
        neg = *s == '-';
        s++;
    }
    if (s[0] == '0' && s[1] == 'x') {
        base = 16;
        s += 2;
    }
    if (*s == '\0') {
        return TK_NUM_SYNTAX;
    }
    /* magnitudes up to 2^63 (INT64_MIN) are representable */
    limit = (unsigned long long)INT64_MAX + 1u;
    for (; *s != '\0'; s++) {
        int d = base == 16 ? hex_digit(*s) : (*s >= '0' && *s <= '9' ? *s - '0' : -1);
        if (d < 0) {
            return TK_NUM_SYNTAX;
        }
        if (mag > (limit - (unsigned)d) / base) {
            overflow = true; /* keep checking the syntax */
        } else {
            mag = mag * base + (unsigned)d;
        }
    }
    if (overflow || (!neg && mag > (unsigned long long)INT64_MAX)) {
        return TK_NUM_RANGE;
    }
    v = neg ? (mag == limit ? INT64_MIN : -(long long)mag) : (long long)mag;
    if (v < min || v > max) {
        return TK_NUM_RANGE;
    }
    *out = v;
    if (hex != NULL) {
        *hex = base == 16 && !neg;
    }
    return TK_NUM_OK;
}

int tk_parse_real(const char *s, double *out)
{
    const char *p = s;
    size_t digits = 0;
    if (s == NULL) {
        return TK_NUM_SYNTAX;
    }
    if (*p == '+' || *p == '-') {
        p++;
    }
    for (; *p >= '0' && *p <= '9'; p++) {
        digits++;
    }
    if (*p == '.') {
        for (p++; *p >= '0' && *p <= '9'; p++) {
            digits++;
        }
    }
    if (digits == 0 || *p != '\0' || digits > 30) {
        return TK_NUM_SYNTAX;
    }
    *out = strtod(s, NULL);
    return TK_NUM_OK;
}

int tk_parse_seconds(const char *s, double *out)
{
    double v;
    /* a leading '+' as the other number options take it; never '-' */
    if (tk_parse_real(s, &v) != TK_NUM_OK || s[0] == '-' || v > 1e7) {
        return -1;
    }
    *out = v;
    return 0;
}

/* ---- standard output and signals ---- */

void tk_stdout_buffered(void)
{
    (void)setvbuf(stdout, NULL, _IOFBF, 1u << 16);
}

/* The first failed write's errno that tk_stdout_flush_soft() saw (its
 * error stays on stdout for tk_stdout_flush() to report). */
static int stdout_errno;

void tk_stdout_flush_soft(void)
{
    if (fflush(stdout) != 0 && stdout_errno == 0) {
        stdout_errno = (errno != 0) ? errno : EIO;
    }
}

void tk_stdout_flush(void)
{
    if (fflush(stdout) != 0 || ferror(stdout)) {
        int e = (stdout_errno != 0) ? stdout_errno : errno;
        stdout_errno = 0;
        clearerr(stdout);
        if (sent_what != NULL) {
            /* the packet went out: say so, also to a closed pipe, with a
             * status of its own, so nobody sends it again believing it was
             * not */
            tk_exit(TK_EXIT_SENT, "%s was sent; cannot write to standard output: %s", sent_what,
                    e ? strerror(e) : "write error");
        }
        if (e == EPIPE) {
            tk_exit_broken_pipe(); /* `tase monitor | head` */
        }
        tk_die("cannot write to standard output: %s", e ? strerror(e) : "write error");
    }
}

bool tk_read_eio_is_end(int fd)
{
    struct stat st;
    int e = errno;
    bool end = fstat(fd, &st) == 0 && S_ISCHR(st.st_mode);
    errno = e; /* the caller reports the read's error */
    return end;
}

void tk_exit_broken_pipe(void)
{
    /* quietly, as SIGPIPE would, but through the path that closes the
     * links (their settings restored) */
    close_all_links();
    exit(128 + SIGPIPE);
}

static void on_signal(int sig)
{
    tk_signal = sig;
}

/* A signal whose default action ends the process and that the tools do
 * not treat as the normal end of a run (SIGQUIT, SIGUSR1, SIGALRM, ...):
 * give every open serial line its settings back (tcsetattr() and ioctl()
 * are async-signal-safe), then die of the signal as before. Without this
 * the line stayed raw with VMIN 0 for the next program (issue 25 item 4). */
static sigset_t fatal_set; /* the signals on_fatal_signal() handles */

/* The links this process made (tk_pty_open()), removed at its exit: the
 * link first (if still ours), then its lock file. */
#define MAX_CLAIMS 2
static struct {
    const char *link;
    char lock[PATH_MAX]; /* its lock file (tk_simlink_lock_path()) */
    int lock_fd;
    char slave[64]; /* "" until the link exists */
} claims[MAX_CLAIMS];
static volatile size_t nclaims;

/* The links and lock files of this process, removed by a fatal signal's
 * handler as the exit handler removes them (only async-signal-safe calls:
 * readlink, unlink, fstat, stat); a SIGUSR1 or SIGQUIT left both behind. */
static void release_claims_on_signal(void)
{
    size_t i;
    for (i = 0; i < nclaims && i < MAX_CLAIMS; i++) {
        char target[64];
        struct stat a, b;
        size_t k = 0;
        if (claims[i].slave[0] != '\0') {
            ssize_t n = readlink(claims[i].link, target, sizeof(target));
            while (k < sizeof(claims[i].slave) && claims[i].slave[k] != '\0') {
                k++;
            }
            if (n == (ssize_t)k && memcmp(target, claims[i].slave, k) == 0) {
                (void)unlink(claims[i].link);
            }
        }
        if (claims[i].lock[0] != '\0' && fstat(claims[i].lock_fd, &a) == 0 &&
            stat(claims[i].lock, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino) {
            (void)unlink(claims[i].lock);
        }
    }
}

/* The signals on_fatal_signal() handles, by name. */
static const struct {
    int sig;
    const char *name;
} fatal_signals[] = {{SIGQUIT, "SIGQUIT"}, {SIGUSR1, "SIGUSR1"}, {SIGUSR2, "SIGUSR2"},
                     {SIGALRM, "SIGALRM"}, {SIGPROF, "SIGPROF"}, {SIGVTALRM, "SIGVTALRM"},
                     {SIGXCPU, "SIGXCPU"}, {SIGPOLL, "SIGPOLL"}};

/* write(2) of a string, in a signal handler */
static void say_on_signal(const char *text)
{
    size_t n = 0;
    while (text[n] != '\0') {
        n++;
    }
    if (write(STDERR_FILENO, text, n) < 0) {
        return; /* nowhere to say it */
    }
}

static void on_fatal_signal(int sig)
{
    size_t i;
    const char *what = sent_what;
    if (what != NULL) {
        /* as after SIGINT/SIGTERM/SIGHUP: a script must not take the exit
         * status 128+N without this line for "nothing was sent" */
        size_t k;
        say_on_signal(tk_prog);
        say_on_signal(": killed by ");
        for (k = 0; k < sizeof(fatal_signals) / sizeof(fatal_signals[0]); k++) {
            if (fatal_signals[k].sig == sig) {
                say_on_signal(fatal_signals[k].name);
            }
        }
        say_on_signal(" (");
        say_on_signal(what);
        say_on_signal(" was sent)\n");
    }
    release_claims_on_signal();
    for (i = 0; i < MAX_OPEN_LINKS; i++) {
        tk_link_t *l = open_links[i];
        if (l != NULL && !l->is_can && l->uart.fd >= 0 && l->uart.restore) {
            (void)tcsetattr(l->uart.fd, TCSANOW, &l->uart.saved);
#ifdef TIOCNXCL
            if (l->uart.excl) {
                (void)ioctl(l->uart.fd, TIOCNXCL);
            }
#endif
        }
    }
    (void)signal(sig, SIG_DFL);
    (void)raise(sig);
}

void tk_hold_fatal_signals(sigset_t *old)
{
    (void)sigprocmask(SIG_BLOCK, &fatal_set, old);
}

void tk_release_fatal_signals(const sigset_t *old)
{
    (void)sigprocmask(SIG_SETMASK, old, NULL);
}

/* Whether fd is the master side of a pty: its path (/proc/self/fd/N is
 * /dev/ptmx) opens a new pty, not this one. */
static bool pty_master(int fd)
{
#ifdef TIOCGPTN
    unsigned int n;
    return ioctl(fd, TIOCGPTN, &n) == 0;
#else
    (void)fd;
    return false;
#endif
}

/* A standard output or error inherited non-blocking (a program sharing the
 * pipe or terminal set O_NONBLOCK on it) fails a write that would wait
 * with EAGAIN, and stdio drops what it could not write. Opened again
 * through /proc (a description of our own: theirs keeps its flags) and
 * made blocking; a socket, which cannot be opened so, stays as it is, and
 * so does a pty's master side (opened again it was a new pty that nobody
 * reads: the output lost with success) and any character device but a
 * terminal (/dev/null never waits; another's open may do anything). */
static void std_fd_blocking(int fd)
{
    char path[32];
    struct stat st;
    int fl = fcntl(fd, F_GETFL), nfd;
    if (fl < 0 || (fl & O_NONBLOCK) == 0 || (fl & O_ACCMODE) == O_RDONLY || fstat(fd, &st) != 0 ||
        !(S_ISFIFO(st.st_mode) || (S_ISCHR(st.st_mode) && isatty(fd) && !pty_master(fd)))) {
        return;
    }
    (void)snprintf(path, sizeof(path), "/proc/self/fd/%d", fd);
    /* non-blocking for the open: a pipe whose reader is gone fails (ENXIO)
     * rather than waits */
    nfd = open(path, O_WRONLY | O_NONBLOCK | O_NOCTTY | (fl & O_APPEND));
    if (nfd < 0) {
        return;
    }
    if (fcntl(nfd, F_SETFL, fl & ~O_NONBLOCK) == 0) {
        (void)dup2(nfd, fd);
    }
    (void)close(nfd);
}

void tk_std_fds_open(void)
{
    int fd;
    for (fd = 0; fd <= 2; fd++) {
        if (fcntl(fd, F_GETFD) == -1 && errno == EBADF) {
            /* the lowest free descriptor: this one, opened the other way,
             * so that a read of standard input, a write to standard output
             * or error fails (EBADF) as on the closed descriptor and never
             * passes for success (output lost with exit 0) */
            if (open("/dev/null", fd == 0 ? O_WRONLY : O_RDONLY) != fd) {
                _exit(TK_EXIT_FAIL); /* nothing to say it on */
            }
        }
    }
    std_fd_blocking(STDOUT_FILENO);
    std_fd_blocking(STDERR_FILENO);
}

void tk_catch_signals(void)
{
    struct sigaction sa;
    sigset_t caught;
    sigemptyset(&caught);
    (void)sigaddset(&caught, SIGINT);
    (void)sigaddset(&caught, SIGTERM);
    memset(&sa, 0, sizeof(sa));
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: a blocking wait returns at once */
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
    {
        /* under nohup (SIGHUP ignored) a closed terminal does not end the run */
        struct sigaction hup;
        if (sigaction(SIGHUP, NULL, &hup) != 0 || hup.sa_handler != SIG_IGN) {
            (void)sigaction(SIGHUP, &sa, NULL);
            (void)sigaddset(&caught, SIGHUP);
        }
    }
    (void)signal(SIGPIPE, SIG_IGN);
    /* A file-size limit (ulimit -f) is a write error (EFBIG, "File too
     * large"), handled as a full disk is: the default action killed the
     * tool without a word, after a packet went out too */
    (void)signal(SIGXFSZ, SIG_IGN);
    {
        size_t i;
        sa.sa_handler = on_fatal_signal;
        sa.sa_flags = 0; /* the handler resets the action itself */
        sigemptyset(&fatal_set);
        for (i = 0; i < sizeof(fatal_signals) / sizeof(fatal_signals[0]); i++) {
            struct sigaction old;
            int sig = fatal_signals[i].sig;
            /* one the caller's shell ignores stays ignored */
            if (sigaction(sig, NULL, &old) == 0 && old.sa_handler != SIG_IGN) {
                (void)sigaction(sig, &sa, NULL);
                (void)sigaddset(&fatal_set, sig);
                (void)sigaddset(&caught, sig);
            }
        }
    }
    /* A signal mask is inherited: a launcher that blocks these in its
     * threads left them blocked here, so SIGTERM did not end the run and
     * the SIGKILL after it left the line raw (and tase-sim's link). */
    (void)sigprocmask(SIG_UNBLOCK, &caught, NULL);
}

void tk_exit_if_signalled(void)
{
    int sig = tk_signal;
    if (sig != 0) {
        tk_exit(128 + sig, "interrupted by %s",
                sig == SIGINT ? "SIGINT" : (sig == SIGTERM ? "SIGTERM" : "SIGHUP"));
    }
}

/* ---- clocks ---- */

void tk_time_now(tk_time_t *t)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    t->sec = (int64_t)ts.tv_sec;
    t->usec = (uint32_t)(ts.tv_nsec / 1000);
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

int tk_link_serial_try(tk_link_t *l, const char *path, long baud)
{
    char why[PATH_MAX * 3 + 512];
    int rc;
    memset(l, 0, sizeof(*l));
    if (baud <= 0 || !tase_posix_uart_baud_supported((uint32_t)baud)) {
        tk_usage_error("unsupported baud rate %ld", baud);
    }
    /* a stale link of a killed simulator leads to a pty that may be
     * another program's now: refused before the open (which already sets
     * up the line), and again after it (the simulator may have died in
     * between) */
    if (tk_simlink_check(path, why, sizeof(why)) != 0) {
        tk_die("%s", why);
    }
    {
        /* a fatal signal between the open (the line is raw from here) and
         * the tracking (from which its handler restores the line) waits
         * until both are done */
        sigset_t old;
        tk_hold_fatal_signals(&old);
        rc = tase_posix_uart_open(&l->uart, path, (uint32_t)baud);
        if (rc == TASE_OK) {
            l->open = true;
            track_link(l, true);
        }
        tk_release_fatal_signals(&old);
    }
    if (rc == TASE_OK && tk_simlink_check(path, why, sizeof(why)) != 0) {
        tk_die("%s", why); /* closes the link: its settings given back */
    }
    return rc;
}

void tk_link_serial_die(const char *path, int rc)
{
    struct stat st;
    if (rc == TASE_ENODEV && stat(path, &st) == 0) {
        tk_die("cannot open serial device %s: not a terminal (a serial device or pseudo-terminal "
               "is needed)",
               path);
    } else if (rc == TASE_ENODEV) {
        tk_die("cannot open serial device %s: %s", path, strerror(errno));
    } else if (rc == TASE_EBUSY) {
        tk_die("cannot open serial device %s: device busy: in use by another program", path);
    }
    tk_die("cannot open serial device %s: %s", path,
           rc == TASE_EIO ? strerror(errno) : tase_strerror(rc));
}

void tk_link_serial(tk_link_t *l, const char *path, long baud)
{
    int rc = tk_link_serial_try(l, path, baud);
    if (rc != TASE_OK) {
        tk_link_serial_die(path, rc);
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
    l->open = true;
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
    size_t n = strlen(iface);
    if (n == 0u || n >= (size_t)IFNAMSIZ) {
        tk_usage_error("bad CAN interface name '%s' (1 to %d characters)", iface, IFNAMSIZ - 1);
    }
    memset(l, 0, sizeof(*l));
    l->is_can = true;
    rc = tase_socketcan_open(&l->can, iface, gimbal ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST);
    if (rc == TASE_EARG) {
        tk_die("cannot open CAN interface %s: not a CAN interface", iface);
    } else if (rc == TASE_EUNSUPPORTED) {
        tk_die("cannot open CAN interface %s: this kernel has no SocketCAN support (load the can "
               "and can-raw modules, or see docs/CAN.md for the VM)",
               iface);
    } else if (rc == TASE_ENODEV) {
        tk_die("cannot open CAN interface %s: no such device", iface);
    } else if (rc == TASE_EDOWN) {
        tk_die("cannot open CAN interface %s: interface is down (ip link set %s up)", iface, iface);
    } else if (rc != TASE_OK) {
        tk_die("cannot open CAN interface %s: %s", iface, tase_strerror(rc));
    }
    l->open = true;
    track_link(l, true);
}

int tk_link_can_reopen(tk_link_t *l, const char *iface, bool gimbal)
{
    tase_socketcan_t fresh;
    int rc = tase_socketcan_open(&fresh, iface, gimbal ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST);
    if (rc == TASE_OK) {
        fresh.tx_timeout_ms = l->can.tx_timeout_ms;
        tase_socketcan_close(&l->can);
        l->can = fresh;
    }
    return rc;
}

tase_port_t tk_link_port(tk_link_t *l)
{
    return l->is_can ? tase_socketcan_port(&l->can) : tase_posix_uart_port(&l->uart);
}

void tk_link_close(tk_link_t *l)
{
    if (!l->open) {
        return;
    }
    {
        /* a fatal signal between the untracking and the close (which gives
         * the line its settings back and ends its exclusive use; on a UART
         * the drain before it may take a second) left the line raw and
         * exclusive, "device busy" to the next program: it waits until
         * the line is closed */
        sigset_t old;
        tk_hold_fatal_signals(&old);
        l->open = false;
        track_link(l, false);
        if (l->is_can) {
            tase_socketcan_close(&l->can);
        } else {
            (void)tase_posix_uart_close(&l->uart);
        }
        tk_release_fatal_signals(&old);
    }
}

const char *tk_link_error(const tk_link_t *l, int rc)
{
    if (rc == TASE_EIO && !l->is_can) {
        return "the device went away or hung up";
    }
    if (rc == TASE_EDOWN && l->is_can) {
        return TK_CAN_DOWN_TEXT;
    }
    if (rc == TASE_ENODEV && l->is_can) {
        return TK_CAN_REMOVED_TEXT;
    }
    return tase_strerror(rc);
}

int tk_port_write_all(const tase_port_t *p, const uint8_t *data, size_t n)
{
    size_t done = 0;
    double deadline = tk_now_s() + 2.0;
    while (done < n) {
        int w;
        tk_exit_if_signalled(); /* Ctrl-C between the attempts on a stalled line */
        w = p->ops->write(p->ctx, data + done, n - done);
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

int tk_canonical_path(const char *path, char *out, size_t cap)
{
    char dir[PATH_MAX], real[PATH_MAX];
    const char *slash = strrchr(path, '/');
    const char *base = slash != NULL ? slash + 1 : path;
    size_t dl = slash != NULL ? (size_t)(slash - path) : 0u;
    int n;
    if (*base == '\0' || dl >= sizeof(dir)) {
        errno = EINVAL;
        return -1;
    }
    if (slash == NULL) {
        strcpy(dir, ".");
    } else if (dl == 0u) {
        strcpy(dir, "/");
    } else {
        memcpy(dir, path, dl);
        dir[dl] = '\0';
    }
    if (realpath(dir, real) == NULL) {
        return -1;
    }
    n = snprintf(out, cap, "%s/%s", strcmp(real, "/") == 0 ? "" : real, base);
    if (n < 0 || (size_t)n >= cap) {
        errno = ENAMETOOLONG;
        return -1;
    }
    return 0;
}

static void release_claims(void)
{
    size_t i;
    for (i = 0; i < nclaims; i++) {
        if (claims[i].slave[0] != '\0') {
            tk_pty_unlink(claims[i].link, claims[i].slave);
        }
        tk_simlink_release(claims[i].link, claims[i].lock_fd);
    }
    nclaims = 0;
}

/* Claim `link` for this process (tk_simlink_claim()); dies when it cannot. */
static size_t claim_link(const char *link)
{
    char why[3 * PATH_MAX + 256];
    int fd;
    if (nclaims == MAX_CLAIMS) {
        tk_die("internal error: more than %d links", MAX_CLAIMS);
    }
    fd = tk_simlink_claim(link, why, sizeof(why));
    if (fd < 0) {
        tk_die("%s", why);
    }
    if (nclaims == 0 && atexit(release_claims) != 0) {
        tk_simlink_release(link, fd);
        tk_die("cannot claim %s: atexit failed", link);
    }
    claims[nclaims].link = link;
    claims[nclaims].lock_fd = fd;
    claims[nclaims].slave[0] = '\0';
    if (tk_simlink_lock_path(link, claims[nclaims].lock, sizeof(claims[nclaims].lock)) != 0) {
        claims[nclaims].lock[0] = '\0';
    }
    return nclaims++;
}

/* An existing `link` we hold the claim of: removed when it is a stale
 * link of a simulator (into /dev/pts/; its maker is gone, since the claim
 * is ours), before the new pty exists, so that no tool opens it
 * meanwhile; anything else is never touched. */
static void remove_stale_link(const char *link)
{
    struct stat st;
    char target[PATH_MAX];
    ssize_t n;
    if (lstat(link, &st) != 0) {
        return;
    }
    if (!S_ISLNK(st.st_mode)) {
        tk_die("%s exists and is not a symlink; not replacing it", link);
    }
    /* Only a link of our own kind, into /dev/pts/, is replaced. Anyone
     * else's symlink (ln -s /dev/ttyS0 PATH) is left alone. */
    n = readlink(link, target, sizeof(target) - 1u);
    if (n <= 0 || (size_t)n >= sizeof(target) - 1u) {
        tk_die("cannot read symlink %s: %s", link, n < 0 ? strerror(errno) : "too long");
    }
    target[n] = '\0';
    if (strncmp(target, "/dev/pts/", 9) != 0 || strchr(target + 9, '/') != NULL) {
        tk_die("%s is a symlink to %s, not a link left by tase-sim (those lead into "
               "/dev/pts/); not replacing it (remove it, or choose another path)",
               link, target);
    }
    if (unlink(link) != 0) {
        tk_die("cannot replace the stale link %s: %s", link, strerror(errno));
    }
}

int tk_pty_open(char *slave, size_t cap, const char *link, int *slave_fd)
{
    int fd, sfd;
    const char *name;
    size_t c = 0;
    sigset_t old;
    /* A fatal signal's handler removes the link and the lock file of the
     * claims it knows: one that came after the lock file or the link was
     * made, but before the claim recorded it, left it behind (a SIGUSR1 as
     * soon as the link appeared, found by CI). Such a signal waits until
     * the claim is whole. */
    tk_hold_fatal_signals(&old);
    if (link != NULL) {
        c = claim_link(link); /* before anything is created */
        remove_stale_link(link);
    }
    fd = posix_openpt(O_RDWR | O_NOCTTY);
    if (fd < 0) {
        tk_die("cannot create a pseudo-terminal: %s", strerror(errno));
    }
    if (grantpt(fd) != 0 || unlockpt(fd) != 0 || (name = ptsname(fd)) == NULL) {
        tk_die("cannot set up the pseudo-terminal: %s", strerror(errno));
    }
    if (strlen(name) + 1 > cap || (link != NULL && strlen(name) + 1 > sizeof(claims[c].slave))) {
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
        /* the record first: a tool that finds the link finds it too */
        if (tk_simlink_record(claims[c].lock_fd, slave) != 0) {
            tk_die("cannot write the lock file of %s: %s", link, strerror(errno));
        }
        if (symlink(slave, link) != 0) {
            tk_die("cannot create symlink %s: %s", link, strerror(errno));
        }
        strcpy(claims[c].slave, slave);
    }
    tk_release_fatal_signals(&old);
    return fd;
}

void tk_pty_unlink(const char *link, const char *slave)
{
    char target[PATH_MAX];
    ssize_t n = readlink(link, target, sizeof(target) - 1u);
    if (n > 0 && (size_t)n < sizeof(target) - 1u) {
        target[n] = '\0';
        if (strcmp(target, slave) == 0) {
            (void)unlink(link);
        }
    }
}

int tk_pty_unread(int slave_fd)
{
    int n = 0;
    return ioctl(slave_fd, FIONREAD, &n) == 0 && n > 0 ? n : 0;
}

bool tk_pty_clear_stale_excl(int slave_fd)
{
#if defined(TIOCGEXCL) && defined(TIOCNXCL)
    int excl = 0;
    if (ioctl(slave_fd, TIOCGEXCL, &excl) != 0 || excl == 0) {
        return false;
    }
    /* The lock is the owner's: held, it is still there (and our attempt
     * changes nothing); free, the flag outlived it. */
    if (flock(slave_fd, LOCK_EX | LOCK_NB) != 0) {
        return false;
    }
    (void)ioctl(slave_fd, TIOCNXCL);
    (void)flock(slave_fd, LOCK_UN);
    return true;
#else
    (void)slave_fd;
    return false;
#endif
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

uint64_t tk_offset64(uint64_t base64, uint32_t base32, uint32_t off32)
{
    uint32_t d = off32 - base32; /* modulo 2^32 */
    return (d & 0x80000000u) != 0u ? base64 - (uint64_t)(0u - d) : base64 + d;
}
