/* tase: `record` and `replay`, the command lines of the capture loops of
 * tk_capture.h. */
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tase_cli.h"
#include "tk_capture.h"

/* Whether paths a and b name the same file (symlinks followed), or the
 * same character device through two nodes. */
static bool same_file(const char *a, const char *b)
{
    struct stat s1, s2;
    if (strcmp(a, b) == 0) {
        return true;
    }
    if (stat(a, &s1) != 0 || stat(b, &s2) != 0) {
        return false;
    }
    return (s1.st_dev == s2.st_dev && s1.st_ino == s2.st_ino) ||
           (S_ISCHR(s1.st_mode) && S_ISCHR(s2.st_mode) && s1.st_rdev == s2.st_rdev);
}

int cli_cmd_record(cli_args_t *a)
{
    cli_link_opts_t lo = {NULL, NULL, CLI_DEFAULT_BAUD, false, NULL};
    const char *out = NULL, *tap_in = NULL, *v;
    double seconds = 0.0;
    tk_cap_writer_t w;
    while (a->i < a->argc) {
        if (cli_common_opt(a) || cli_link_opt(a, &lo)) {
            continue;
        }
        if (cli_opt(a, "-o", true, &v) || cli_opt(a, "--output", true, &v)) {
            if (out != NULL) {
                tk_usage_error("option -o/--output given twice");
            }
            if (v[0] == '\0') { /* was recorded into ".partial-PID", then refused */
                tk_usage_error("option -o/--output needs a value");
            }
            out = v;
            continue;
        }
        if (cli_opt(a, "--tap-in", true, &tap_in)) {
            continue;
        }
        if (cli_opt(a, "--seconds", true, &v)) {
            if (tk_parse_seconds(v, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", v);
            }
        } else {
            cli_bad_arg(a);
        }
    }
    if (lo.record != NULL) {
        tk_usage_error("record writes its capture with -o FILE (--record is for the other "
                       "commands)");
    }
    if (out == NULL) {
        tk_usage_error("record needs an output file: -o FILE");
    }
    if (strcmp(out, "-") == 0) {
        out = "/dev/stdout"; /* as `-` is standard input to decode and replay */
    }
    /* /dev/stdout reopens descriptor 1 by its path: a closed one is held
     * by /dev/null for reading (tk_std_fds_open()), which that open
     * would write to, the capture lost with success */
    if (strcmp(out, "/dev/stdout") == 0 &&
        (fcntl(STDOUT_FILENO, F_GETFL) & O_ACCMODE) == O_RDONLY) {
        tk_die("cannot write capture to standard output: %s (it is closed)", strerror(EBADF));
    }
    if (strcmp(out, "/dev/stdout") == 0 && isatty(STDOUT_FILENO)) {
        tk_usage_error("-o %s is a terminal: a capture is binary (redirect it, or pipe it to "
                       "'tase decode -')",
                       out);
    }
    if ((lo.serial != NULL) == (lo.can != NULL)) {
        tk_usage_error("give either --serial DEV or --can IFACE");
    }
    cli_check_link_baud(&lo);
    if (tap_in != NULL && lo.serial == NULL) {
        tk_usage_error("--tap-in is the second line of a serial tap: it needs --serial");
    }
    /* the same line twice (by any path: symlinks followed) would be
     * "busy: in use by another program", the other program being this one */
    if (tap_in != NULL && same_file(tap_in, lo.serial)) {
        tk_usage_error("--tap-in must be the other line of the tap, not --serial's %s", lo.serial);
    }
    /* a capture written into a line it records (a device is written in
     * place) would hand the gimbal its own packets, echoes of commands
     * included, which it takes as commands */
    if (lo.serial != NULL &&
        (same_file(out, lo.serial) || (tap_in != NULL && same_file(out, tap_in)))) {
        tk_usage_error("-o %s is a serial device being recorded (%s): the capture would go to "
                       "the gimbal's line; write it to a file",
                       out, same_file(out, lo.serial) ? lo.serial : tap_in);
    }
    /* a signal is the normal end of a recording: the loops stop on it and
     * close the capture, and the command succeeds */
    if (lo.serial != NULL) {
        tk_cap_record_serial(&w, out, lo.serial, tap_in, lo.baud, seconds);
    } else {
        tk_cap_record_can(&w, out, lo.can, seconds);
    }
    return TK_EXIT_OK;
}

/* replay's words for a capture it cannot read twice (a pipe, a FIFO) */
#define REPLAY_NOT_A_FILE                                                                          \
    "%s: replay reads its capture twice (checked before anything is sent): give a file, not a "    \
    "pipe"

int cli_cmd_replay(cli_args_t *a)
{
    cli_link_opts_t lo = {NULL, NULL, CLI_DEFAULT_BAUD, false, NULL};
    tk_replay_opts_t ro;
    const char *path = NULL, *v;
    static uint8_t head[CLI_READ_CHUNK];
    unsigned long bad, backward;
    tk_cap_reader_t r;
    cli_input_t in;
    size_t n;
    memset(&ro, 0, sizeof(ro));
    ro.speed = 1.0;
    ro.dirs = (tk_cap_dirs_t)0; /* no default: --dir is required */
    while (a->i < a->argc) {
        if (cli_common_opt(a) || cli_link_opt(a, &lo)) {
            continue;
        }
        if (cli_opt(a, "--speed", true, &v)) {
            if (tk_parse_seconds(v, &ro.speed) != 0 || (ro.speed > 0.0 && ro.speed < 0.001)) {
                tk_usage_error("bad --speed value '%s' (a factor: 1 recorded timing, 2 twice as "
                               "fast, 0.001 the slowest, 0 no waiting)",
                               v);
            }
        } else if (cli_opt(a, "--dir", true, &v)) {
            if (strcmp(v, "out") == 0) {
                ro.dirs = TK_CAP_DIR_OUT;
            } else if (strcmp(v, "in") == 0) {
                ro.dirs = TK_CAP_DIR_IN;
            } else if (strcmp(v, "all") == 0) {
                ro.dirs = TK_CAP_DIR_ALL;
            } else {
                tk_usage_error("bad --dir value '%s' (out, in or all)", v);
            }
        } else if (path == NULL && cli_is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
    if (path == NULL) {
        tk_usage_error("replay needs a capture file (written by 'tase record')");
    }
    if (lo.record != NULL) {
        tk_usage_error("--record is not available with replay");
    }
    if ((lo.serial != NULL) == (lo.can != NULL)) {
        tk_usage_error("give either --serial DEV or --can IFACE");
    }
    cli_check_link_baud(&lo);
    if (ro.dirs == 0) {
        tk_usage_error("replay needs --dir: out = the gimbal's side, to exercise a host (its "
                       "echoes are commands to a gimbal); in = the host's commands (moves a "
                       "gimbal); all = both (moves a gimbal)");
    }
    {
        /* a FIFO is refused before its open() waits for a writer */
        struct stat st;
        if (strcmp(path, "-") != 0 && stat(path, &st) == 0 && S_ISFIFO(st.st_mode)) {
            tk_die(REPLAY_NOT_A_FILE, path);
        }
    }
    cli_input_open(&in, path, 0);
    n = cli_input_head(&in, head, sizeof(head));
    if (!tk_cap_is_capture(head, n)) {
        tk_die("%s is not a pcap or pcapng capture (candump logs: can-utils' canplayer "
               "replays them)",
               in.name);
    }
    ro.serial = lo.serial;
    ro.baud = lo.baud;
    ro.can = lo.can;
    /* The whole capture is checked before anything is sent: read it once
     * (so it must be a file, not a pipe), then again to send. */
    if (lseek(in.fd, 0, SEEK_SET) != 0) {
        tk_die(REPLAY_NOT_A_FILE, in.name);
    }
    tk_cap_reader_open(&r, in.fd, NULL, 0, in.name);
    bad = tk_cap_check(&r, &ro, &backward);
    ro.records = r.index; /* the summary's M, also when interrupted */
    tk_cap_reader_close(&r);
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad record%s: nothing was sent", in.name, bad,
                bad == 1 ? "" : "s");
    }
    if (lseek(in.fd, 0, SEEK_SET) != 0) {
        tk_die("cannot read %s again: %s", in.name, strerror(errno));
    }
    tk_cap_reader_open(&r, in.fd, NULL, 0, in.name);
    bad = tk_cap_replay(&r, &ro);
    tk_cap_reader_close(&r);
    cli_input_close(&in);
    tk_exit_if_signalled();
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad record%s skipped", in.name, bad, bad == 1 ? "" : "s");
    }
    return TK_EXIT_OK;
}
