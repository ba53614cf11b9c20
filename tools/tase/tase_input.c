/* tase: the input of `decode`, `klv` and `replay`: a file, standard
 * input, a pipe, or a serial device (or pty) named as the file and read as
 * the link commands open one. A live input is read as bytes arrive; its
 * first bytes are kept for the hint when nothing is found in it. */
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tase_cli.h"

/* Open FILE (NULL or "-": standard input). With baud > 0 a terminal named
 * as FILE (a serial device, a pty) is opened through the POSIX UART port
 * as the link commands open it: raw 8N1 at `baud`, exclusive, its settings
 * given back on every exit path. */
void cli_input_open(cli_input_t *in, const char *path, long baud)
{
    struct stat st;
    memset(in, 0, sizeof(*in));
    if (path == NULL || strcmp(path, "-") == 0) {
        in->fd = STDIN_FILENO;
        in->name = "standard input";
        return;
    }
    in->name = path;
    if (baud > 0 && stat(path, &st) == 0 && S_ISCHR(st.st_mode)) {
        int rc = tk_link_serial_try(&in->link, path, baud);
        if (rc == TASE_OK) {
            in->device = true;
            in->port = tk_link_port(&in->link);
            in->fd = in->link.uart.fd;
            return;
        }
        if (rc != TASE_ENODEV) {
            tk_link_serial_die(path, rc);
        }
        /* a character device that is no terminal (/dev/zero): read it */
    }
    in->fd = open(path, O_RDONLY | O_NOCTTY);
    if (in->fd < 0) {
        if (errno == EINTR) {
            tk_exit_if_signalled(); /* Ctrl-C while a FIFO waits for a writer */
        }
        tk_die("cannot open %s: %s", path, strerror(errno));
    }
}

void cli_input_close(cli_input_t *in)
{
    if (in->device) {
        tk_link_close(&in->link);
    } else if (in->fd != STDIN_FILENO) {
        (void)close(in->fd);
    }
}

/* After the input ended: a device that hung up is an error (what was
 * decoded is out already). */
void cli_input_check_end(const cli_input_t *in)
{
    if (in->hung_up) {
        tk_die("cannot read %s: the device went away or hung up", in->name);
    }
}

static size_t input_keep_head(cli_input_t *in, const uint8_t *buf, size_t k)
{
    if (in->nhead < sizeof(in->head) - 1u) {
        size_t room = sizeof(in->head) - 1u - in->nhead;
        size_t c = room < k ? room : k;
        memcpy(in->head + in->nhead, buf, c);
        in->nhead += c;
    }
    return k;
}

/* What is there now (a live pty or pipe is not made to wait for a full
 * buffer). Returns the count, 0 at the end: end of file, or for a device
 * a hang-up (in->hung_up) or SIGINT/SIGTERM/SIGHUP, a live line's normal
 * end. */
size_t cli_input_read(cli_input_t *in, uint8_t *buf, size_t cap)
{
    while (in->device) {
        int n;
        if (tk_signal != 0) {
            return 0;
        }
        uint32_t wait = in->st != NULL
                            ? tase_rx_quiet_ms(&in->st->rx, in->port.ops->now_ms(in->port.ctx))
                            : 100u;
        n = in->port.ops->read(in->port.ctx, buf, cap, wait < 100u ? wait : 100u);
        if (n > 0) {
            return input_keep_head(in, buf, (size_t)n);
        }
        if (n == 0 && in->st != NULL) { /* quiet until now */
            tk_dec_tick(in->dec, in->st, in->port.ops->now_ms(in->port.ctx));
            tk_stdout_flush(); /* what it settled goes out now */
        }
        if (n == TASE_EIO) {
            in->hung_up = true;
            return 0;
        }
        if (n < 0) {
            tk_die("cannot read %s: %s", in->name, tase_strerror(n));
        }
    }
    for (;;) {
        ssize_t n;
        /* a file or pipe that never blocks never gives EINTR: a signal
         * ends the run here, at the next read (decode of /dev/zero spun
         * until SIGKILL) */
        tk_exit_if_signalled();
        n = read(in->fd, buf, cap);
        if (n > 0) {
            return input_keep_head(in, buf, (size_t)n);
        }
        if (n == 0 || (errno == EIO && tk_read_eio_is_end(in->fd))) {
            return 0;
        }
        if (errno == EINTR && tk_signal == 0) {
            continue;
        }
        tk_exit_if_signalled();
        tk_die("cannot read %s: %s", in->name, strerror(errno));
    }
}

/* Whether the first bytes of an input are all printable text. */
bool cli_input_is_text(const cli_input_t *in)
{
    size_t i;
    for (i = 0; i < in->nhead; i++) {
        uint8_t c = in->head[i];
        if (!((c >= 0x20 && c < 0x7F) || c == '\n' || c == '\r' || c == '\t')) {
            return false;
        }
    }
    return in->nhead > 0;
}
/* Read the first bytes of an input (at least 4 unless it ends) into buf;
 * returns how many. */
size_t cli_input_head(cli_input_t *in, uint8_t *buf, size_t cap)
{
    size_t n = 0, k;
    while (n < 4 && (k = cli_input_read(in, buf + n, cap - n)) > 0) {
        n += k;
    }
    return n;
}

/* --baud given for an input that is no serial device */
void cli_input_check_baud(const cli_input_t *in, bool baud_given, const char *or_capture)
{
    if (baud_given && !in->device) {
        tk_usage_error("--baud is for a serial device%s; %s is not one", or_capture, in->name);
    }
}
