/*
 * tools/tase/tase_cli.h - what the files of the `tase` command line share
 * (private to this program). Usage and behaviour: docs/TOOLS.md.
 *
 *   tase_main.c    the command table, the usage texts, main()
 *   tase_args.c    argument parsing: options given once, numbers, LINK
 *   tase_link.c    the link: open, request and answer, send, echo check;
 *                  `monitor`
 *   tase_send.c    field assignment: `send`, `query`, `list`
 *   tase_verbs.c   the gimbal verbs: point, rate, camera, gyro-zero,
 *                  deploy, retract, spoi
 *   tase_input.c   an input file, pipe or serial device read as bytes
 *   tase_decode.c  `decode` (raw bytes, pcap, candump) and `klv`
 *   tase_record.c  `record` and `replay` (the loops are in tk_capture.h)
 *
 * Every function here reports a failure the toolkit's way: one line on
 * stderr and an exit with a TK_EXIT_* status (toolkit.h); none returns an
 * error.
 */
#ifndef TASE_TOOLS_TASE_CLI_H
#define TASE_TOOLS_TASE_CLI_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tase/host.h"
#include "toolkit.h"

#define CLI_DEFAULT_BAUD 57600L
#define CLI_DEFAULT_TIMEOUT_MS 500
#define CLI_DEFAULT_RETRIES 2
#define CLI_READ_CHUNK 65536u

/* ---- arguments (tase_args.c) ---- */

#define CLI_SEEN_MAX 16
#define CLI_USAGE_LINK 1u /* --help adds the link options */
#define CLI_USAGE_REQ 2u  /* --help adds the request options */

typedef struct {
    int argc;
    char **argv;
    int i;
    bool dashdash; /* "--" seen: the rest are arguments */
    const char *usage;
    unsigned extra; /* CLI_USAGE_* sections appended to --help */
    /* options with a value given so far: each at most once */
    const char *seen[CLI_SEEN_MAX];
    unsigned nseen;
} cli_args_t;

typedef struct {
    const char *serial;
    const char *can;
    long baud;
    bool baud_given;    /* --baud was given (a serial link's option only) */
    const char *record; /* --record FILE, or NULL */
} cli_link_opts_t;

typedef struct {
    uint32_t timeout_ms;
    uint8_t retries;
    bool json;
} cli_req_opts_t;

/* The command's usage and the sections a->extra names (tase_main.c). */
void cli_print_usage(const cli_args_t *a);
/* If argv[i] is option `name` (with "--name V" or "--name=V" when has_arg),
 * consume it and return true; *val gets the value. */
bool cli_opt(cli_args_t *a, const char *name, bool has_arg, const char **val);
/* --help, -h (print the usage, exit 0) and "--". */
bool cli_common_opt(cli_args_t *a);
/* Whether argv[i] is an argument rather than an option (with `numbers`,
 * anything starting with a single '-': a negative number, or a bad one). */
bool cli_is_arg(const cli_args_t *a, bool numbers);
bool cli_baud_opt(cli_args_t *a, long *baud);
/* --serial, --can, --record, --baud */
bool cli_link_opt(cli_args_t *a, cli_link_opts_t *l);
/* --timeout, --retries, --json */
bool cli_req_opt(cli_args_t *a, cli_req_opts_t *r);
long long cli_int_opt_value(const char *name, const char *v, long long min, long long max);
/* A decimal number argument in [lo, hi]; `what` names it in messages. */
double cli_real_arg(const char *what, const char *v, double lo, double hi, const char *unit);
/* The same argument times mul (100: degrees -> 1/100 degree, metres -> cm;
 * 3600000: degrees -> milli-arcseconds), rounded half away from zero on
 * the decimal as typed (1.005 deg -> 101), not on its binary double. */
long long cli_scaled_arg(const char *what, const char *v, double lo, double hi, const char *unit,
                         unsigned long mul);
/* Usage error naming argv[i]: an unknown option or an unexpected argument. */
void cli_bad_arg(const cli_args_t *a);

/* ---- the link (tase_link.c) ---- */

/* One open link with a host role on it. */
typedef struct {
    tk_link_t link;
    tase_port_t port;
    tase_host_t h;
    const char *name; /* the device or interface, for messages */
} cli_session_t;

/* Usage error unless exactly one of --serial and --can is given (and no
 * --record with --can). */
/* Usage error: --baud given with --can. */
void cli_check_link_baud(const cli_link_opts_t *lo);
void cli_check_link_opts(const cli_link_opts_t *lo);
void cli_session_open(cli_session_t *s, const cli_link_opts_t *lo, tase_rx_handler_t on_frame,
                      void *user);
void cli_session_close(cli_session_t *s);
/* Service the session's port for up to wait_ms; dies when reading fails. */
void cli_session_service(cli_session_t *s, uint32_t wait_ms);
/* Send a request and wait for its answer (into reply, TASE_DATA_MAX
 * bytes); returns its length. `note` (or NULL) is added to a timeout's
 * message. */
int cli_transact_note(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data,
                      size_t len, uint8_t *reply, const cli_req_opts_t *r, const char *note);
/* The same without a note; a request with data (a command, not a query)
 * is printed ("sent ...") as soon as it has gone out, before the wait. */
int cli_transact(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                 uint8_t *reply, const cli_req_opts_t *r);
/* Send a packet, awaiting nothing. */
void cli_send_frame(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len);
/* Print a packet sent ("dir":"in") or received ("out"); `label` starts the
 * text line ("sent", "echo", NULL for none). */
void cli_print_packet(const tase_packet_desc_t *p, const uint8_t *data, size_t len, bool json,
                      const char *dir, const char *label);

/* ---- fields (tase_send.c) ---- */

typedef struct {
    const tase_packet_desc_t *p;
    size_t len; /* the layout's length (fields move in AXIS_SETTING's 22) */
    uint8_t data[TASE_DATA_MAX];
    bool given[32]; /* per field: given, or filled in */
    size_t tail;    /* CAMERA_PASS data bytes */
    bool tail_given;
} cli_fields_t;

typedef struct {
    bool zero;     /* fields left out are 0 */
    bool no_wait;  /* wait for nothing */
    bool raw;      /* reserved flag bits allowed */
    long long len; /* forced data length, -1 none */
    cli_req_opts_t r;
} cli_send_opts_t;

void cli_fields_init(cli_fields_t *fs, const tase_packet_desc_t *p, size_t len);
long long cli_fields_value(const cli_fields_t *fs, unsigned i);
/* Set field `name` (which must exist) as if given on the command line. */
void cli_fields_set(cli_fields_t *fs, const char *name, long long v);
/* The number of fields that lie within `len` bytes. */
unsigned cli_fields_within(const tase_packet_desc_t *p, size_t len);
/* Fields [0, n) left out take their "do not change" value, if any. */
void cli_fields_keep(cli_fields_t *fs, unsigned n);
/* Send fs (len bytes); a setup packet's echo is awaited and checked
 * (cli_confirm_echo()) unless o->no_wait (tase_link.c). */
void cli_send_fields(cli_session_t *s, const cli_fields_t *fs, size_t len,
                     const cli_send_opts_t *o);
/* Exit 3 naming every field of the echo that differs from fs, except
 * "do not change" fields and `skip` (or NULL) (tase_link.c). */
void cli_confirm_echo(const cli_fields_t *fs, size_t len, const uint8_t *echo, int elen,
                      const char *skip);

/* ---- GIMBAL_CMD modes (tase_verbs.c) ---- */

/* The mode the spec's table 5 gives GIMBAL_CMD flags, or NULL. */
const char *cli_gimbal_mode(long long flags);
/* Usage error `why`, listing the modes. */
void cli_refuse_gimbal_cmd(const char *why);

/* ---- inputs (tase_input.c) ---- */

typedef struct {
    int fd;
    const char *name; /* for messages */
    /* a serial device named as FILE, read through the POSIX UART port */
    bool device;
    bool hung_up; /* the device went away or hung up */
    tk_link_t link;
    tase_port_t port;
    /* a device's stream, ticked by its reads (tase/frame.h, TIME BOUND) */
    tk_dec_t *dec;
    tk_stream_t *st;
    /* the first bytes, kept for the hint when nothing is found (one
     * more for a terminating NUL) */
    uint8_t head[513];
    size_t nhead;
} cli_input_t;

/* Open FILE (NULL or "-": standard input); with baud > 0 a terminal is
 * opened as a serial link at that rate. */
void cli_input_open(cli_input_t *in, const char *path, long baud);
void cli_input_close(cli_input_t *in);
/* After the input ended: dies if the device hung up. */
void cli_input_check_end(const cli_input_t *in);
/* What is there now; 0 at the end (of file, or of a live line). */
size_t cli_input_read(cli_input_t *in, uint8_t *buf, size_t cap);
/* The first bytes (at least 4 unless the input ends); returns how many. */
size_t cli_input_head(cli_input_t *in, uint8_t *buf, size_t cap);
/* Whether the first bytes are all printable text. */
bool cli_input_is_text(const cli_input_t *in);
/* Usage error: --baud given for an input that is no serial device. */
void cli_input_check_baud(const cli_input_t *in, bool baud_given, const char *or_capture);

/* ---- the commands (the table in tase_main.c) ---- */

int cli_cmd_point(cli_args_t *a);
int cli_cmd_rate(cli_args_t *a);
int cli_cmd_camera(cli_args_t *a);
int cli_cmd_gyro_zero(cli_args_t *a);
int cli_cmd_deploy(cli_args_t *a);
int cli_cmd_retract(cli_args_t *a);
int cli_cmd_spoi(cli_args_t *a);
int cli_cmd_send(cli_args_t *a);
int cli_cmd_query(cli_args_t *a);
int cli_cmd_list(cli_args_t *a);
int cli_cmd_monitor(cli_args_t *a);
int cli_cmd_decode(cli_args_t *a);
int cli_cmd_klv(cli_args_t *a);
int cli_cmd_record(cli_args_t *a);
int cli_cmd_replay(cli_args_t *a);

#endif /* TASE_TOOLS_TASE_CLI_H */
