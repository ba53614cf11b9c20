/* tase: talk to a TASE gimbal (or tase-sim) and decode captures.
 * Usage and the JSON contract: docs/TOOLS.md, or `tase --help`. */
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "tase/candump.h"
#include "tase/flags.h"
#include "tase/host.h"
#include "tase/klv.h"
#include "tase/units.h"
#include "tk_capture.h"
#include "toolkit.h"

#define DEFAULT_BAUD 57600L
#define KLV_BAUD 9600L /* the spec's KLV line (table 1) */
#define DEFAULT_TIMEOUT_MS 500
#define DEFAULT_RETRIES 2
#define READ_CHUNK 65536u
#define BAD_LINES_SHOWN 10u

static const char usage_exit[] =
    "exit status: 0 success; 1 failure (device, I/O, timeout, writing the output;\n"
    "  \"(NAME was sent)\" ends the line if the packet went out before);\n"
    "  2 bad command line (nothing was sent); 3 the gimbal's echo differs from the\n"
    "  setting sent; 4 input not fully understood (bad candump lines, no packet\n"
    "  found); 5 the packet was sent, but writing the output failed (do not send it\n"
    "  again); 128+N interrupted by signal N (141: the output's reader went away).\n";

static const char usage_link[] =
    "link options:\n"
    "  --serial DEV   serial device or pty (e.g. /dev/ttyUSB0, the path tase-sim prints)\n"
    "  --baud N       serial rate, default 57600\n"
    "  --can IFACE    CAN interface instead of a serial device (e.g. can0)\n"
    "  --record FILE  also record the session's bytes, both directions, to the pcap\n"
    "                 capture FILE (appended to; serial links only: on CAN run\n"
    "                 'tase record --can IFACE' beside it)\n";

static const char usage_req[] =
    "request options (when an answer is awaited):\n"
    "  --timeout MS   wait per attempt, default " TK_STR(
        DEFAULT_TIMEOUT_MS) " ms\n"
                            "  --retries N    attempts after the first, default " TK_STR(
                                DEFAULT_RETRIES) "\n"
                                                 "  --json         print JSON lines (what was sent "
                                                 "\"dir\":\"in\", the answer \"out\")\n";

static const char usage_point[] =
    "usage: tase point PAN TILT [--stab on|off] LINK [--json]\n"
    "Position command (GIMBAL_CMD flags 0xA0, or 0x20 with --stab off): turn to pan\n"
    "PAN and tilt TILT degrees (-180..180; sent in 1/100 deg). Stabilisation is on\n"
    "unless --stab off. Prints what it sent. Negative numbers need no '--'.\n";

static const char usage_rate[] =
    "usage: tase rate PAN_RATE TILT_RATE [--stab on|off] LINK [--json]\n"
    "Rate command (GIMBAL_CMD flags 0x90, or 0x10 with --stab off): turn at the\n"
    "given degrees per second (-327.68..327.67; sent in 1/100 deg/s) until the next\n"
    "command. 'tase rate 0 0' stops. Prints what it sent.\n";

static const char usage_camera[] =
    "usage: tase camera [A|B|C] [--hfov DEG | --zoom X] LINK [--json] [request options]\n"
    "CAMERA_CMD. A camera alone selects it (the 1-byte form: nothing else changes).\n"
    "--hfov DEG sets the horizontal field of view (0.01..327.67 deg), --zoom X the\n"
    "zoom ratio (1..327.68); every other camera setting is sent as \"do not change\"\n"
    "(and the active camera too, unless one is named). Prints what it sent.\n"
    "CAMERA_CMD has no echo: a named camera is first looked up in the gimbal's\n"
    "SYSTEM_VERSION, and one the gimbal does not have (type 0xFF) is refused with\n"
    "nothing sent (exit 1).\n";

static const char usage_gyro[] = "usage: tase gyro-zero LINK [--json]\n"
                                 "GYRO_ZERO_CMD: the gimbal zeroes its rate gyros. Send it only "
                                 "while the\ngimbal is not moving.\n";

static const char usage_deploy[] =
    "usage: tase deploy|retract LINK [--wait S] [--json]\n"
    "RETRACT_DEPLOY_CMD (deploy 1 or 0). The gimbal echoes it when the move is\n"
    "complete: --wait S waits up to S seconds for that echo (exit 1 if it does not\n"
    "come).\n";

static const char usage_spoi[] =
    "usage: tase spoi LAT LON HEIGHT LINK [--no-wait] [--json] [request options]\n"
    "SPOI_CMD: point at latitude LAT, longitude LON (degrees, WGS-84; sent in\n"
    "milli-arcseconds) and HEIGHT metres above the ellipsoid (sent in cm), not\n"
    "moving. The echo is requested and awaited (--no-wait: neither); exit 3 if the\n"
    "echoed position differs. The gimbal needs host GPS and attitude to use it.\n";

static const char usage_monitor[] =
    "usage: tase monitor LINK [--json] [--time] [--units] [--count N] [--seconds S]\n"
    "Prints every packet received, one per line: readable text by default, one JSON\n"
    "object per line with --json. --time adds the host time of arrival (text:\n"
    "HH:MM:SS.mmm, JSON: \"time\" in Unix seconds); --units adds engineering units\n"
    "beside the raw fields (JSON: a top-level \"units\" object). Stops after N\n"
    "packets, S seconds, or on SIGINT/SIGTERM/SIGHUP (exit 0), and prints a summary\n"
    "line on stderr (frames, checksum errors, bad sizes, wrong lengths, unknown,\n"
    "bytes discarded; on CAN the bus state and error counts the port reports).\n"
    "A device that goes away or hangs up also stops it: the summary, then\n"
    "'cannot read DEV: the device went away or hung up' (exit 1). Bytes received\n"
    "but no frame found: the summary and a one-line hint (exit 4).\n"
    "On CAN, --time is the kernel's receive time of the frame.\n";

static const char usage_send[] =
    "usage: tase send NAME [field=value ...] LINK [--len N] [--zero] [--no-wait]\n"
    "                 [--json] [--timeout MS] [--retries N]\n"
    "Sends packet NAME (an In or Both packet; see 'tase list') with raw wire integer\n"
    "field values: decimal (leading zeros are decimal), 0x hex, an optional sign; a\n"
    "signed field also takes its hex bit pattern (hfov=0xFFFF is -1). CAMERA_PASS\n"
    "takes data=1,2,... . Each field at most once. Fields left out:\n"
    "  - a field with a \"do not change\" value in the spec takes it (CAMERA_CMD,\n"
    "    AXIS_SETTING, CAMERA_TYPE, LEGACY_CAMERA_CMD focus and shutter_speed,\n"
    "    CAMERA_PASS baud);\n"
    "  - other fields of setup packets (group 0x48): the gimbal's current settings\n"
    "    are queried first and kept, and the packet is sent in the layout of the\n"
    "    answer (AXIS_SETTING: 22 or 23 bytes, so it is always queried first)\n"
    "    unless --len says otherwise;\n"
    "  - otherwise every field must be given (the error names the missing ones);\n"
    "  - --zero: fields left out without such a value are 0 instead.\n"
    "temporary (PACKET_RATE, AXIS_SETTING) left out is 1: the setting lasts until\n"
    "the gimbal is powered off. temporary=0 makes the gimbal write it to its\n"
    "non-volatile storage (spec 4.4.1, 4.4.3), where it survives power cycles.\n"
    "GIMBAL_CMD always needs flags (its mode; or use 'tase point' / 'tase rate').\n"
    "Setup packets are echoed by the gimbal: the echo is awaited, printed and\n"
    "compared with what was sent; a field that differs (a value the gimbal refused\n"
    "or changed) exits 3 naming it. --no-wait sends without waiting for anything\n"
    "(a setup packet then needs every field, or --zero). --len N sends a shorter\n"
    "accepted form (CAMERA_CMD --len 1: change camera only; AXIS_SETTING --len 22:\n"
    "the 22-byte layout).\n";

static const char usage_query[] =
    "usage: tase query NAME LINK [--json] [--timeout MS] [--retries N]\n"
    "Sends the zero-length query of NAME (a setup packet, SPOI_CMD or\n"
    "SYSTEM_VERSION), waits for the answer and prints it. Each attempt waits\n"
    "--timeout ms (default " TK_STR(DEFAULT_TIMEOUT_MS) "); --retries (default " TK_STR(
        DEFAULT_RETRIES) ") more attempts are made.\n";

static const char usage_decode[] =
    "usage: tase decode [FILE|-] [--candump] [--stats] [--baud N]\n"
    "Decodes a capture of 'tase record' (pcap or pcapng; each object carries\n"
    "\"time\" and \"dir\"; a bad record is reported with its number, exit 4) or a\n"
    "raw serial byte capture (default: standard input; a live pty or\n"
    "pipe is read as bytes arrive) to one JSON object per valid packet, in stream\n"
    "order (contract: docs/TOOLS.md). With --candump the input is a candump log\n"
    "(candump -l or -L): frames of ID 10000000 (from the gimbal, \"dir\":\"out\") and\n"
    "11000000 (to the gimbal, \"dir\":\"in\") are reassembled per interface and\n"
    "direction, each object carrying \"time\", \"dir\" and \"interface\"; other IDs are\n"
    "ignored, blank and '#' lines skipped, a bad line reported with its number\n"
    "(the rest is still decoded; exit 4). --stats prints a summary line on stderr.\n"
    "When a non-empty input holds no packet, a one-line hint says why and the exit\n"
    "status is 4. A serial device (or pty) named as FILE is opened as the link\n"
    "commands open one: raw 8N1 at --baud N (default 57600), exclusively, its\n"
    "settings given back at exit; SIGINT/SIGTERM/SIGHUP end it (exit 0), a hang-up\n"
    "is an error (exit 1). As a live receiver does, a candidate frame the line\n"
    "went quiet on is judged false after its remaining bytes' time at the line's\n"
    "rate (a capture's: --baud; CAN: 1 Mbit/s), at least 20 ms: on a device by\n"
    "the clock, in a capture or candump log by the gaps in the record times.\n";

static const char usage_klv[] =
    "usage: tase klv [FILE|-] [--baud N]\n"
    "Decodes a KLV metadata byte stream (the gimbal's 9600-baud KLV line; a live\n"
    "pty is read as bytes arrive) to one JSON object per valid packet:\n"
    "{\"offset\":N,\"fields\":{raw values in tag order},\"units\":{engineering values}}.\n"
    "Noise and damaged packets are skipped; a non-empty input without a packet is\n"
    "reported with a one-line hint (exit 4). A serial device (or pty) named as FILE\n"
    "is opened raw 8N1 at --baud N (default 9600, the KLV line), exclusively, its\n"
    "settings given back at exit; SIGINT/SIGTERM/SIGHUP end it (exit 0), a hang-up\n"
    "is an error (exit 1).\n";

static const char usage_record[] =
    "usage: tase record (--serial DEV [--tap-in DEV2] [--baud N] | --can IFACE) -o FILE\n"
    "                   [--seconds S]\n"
    "Records what arrives to the pcap capture FILE (replaced), with a timestamp per\n"
    "received chunk, until interrupted (Ctrl-C, SIGTERM, SIGHUP: exit 0) or S seconds\n"
    "have passed.\n"
    "  --serial DEV   one record per read, byte-exact, as sent by the gimbal\n"
    "                 (link type USER0 with a direction byte; docs/TOOLS.md)\n"
    "  --tap-in DEV2  a second device on the other line of a tap: its bytes are\n"
    "                 recorded as sent to the gimbal\n"
    "  --can IFACE    every frame on the bus, as SocketCAN records\n"
    "'tase decode FILE' decodes it; Wireshark reads it (tools/wireshark/tase.lua).\n";

static const char usage_replay[] =
    "usage: tase replay FILE (--serial DEV [--baud N] | --can IFACE) --dir out|in|all\n"
    "                   [--speed X]\n"
    "Sends the records of the pcap capture FILE with their recorded timing (divided\n"
    "by X, default 1; 0 sends without waiting). --dir is required (no default: a\n"
    "capture holds commands either way):\n"
    "  --dir out   the gimbal's side, to exercise a host; it holds the gimbal's\n"
    "              echoes of setup packets, RETRACT_DEPLOY_CMD and SPOI_CMD, which a\n"
    "              gimbal takes as commands: never replay it into a gimbal\n"
    "  --dir in    the host's side: the commands sent to the gimbal (moves a gimbal)\n"
    "  --dir all   both (moves a gimbal); on CAN every recorded frame, whatever its ID\n"
    "Serial bytes go to a CAN interface as frames of their direction's ID, and the\n"
    "datalink bytes of CAN frames to a serial device; CAN FD, remote and error\n"
    "frames are not sent. A bad record is reported and skipped (exit 4).\n";

static const char usage_list[] = "usage: tase list\nLists every packet: group, type, "
                                 "direction, data length and field names.\n";

/* ---- command-line parsing ---- */

#define SEEN_MAX 16

typedef struct {
    int argc;
    char **argv;
    int i;
    bool dashdash; /* "--" seen: the rest are arguments */
    const char *usage;
    unsigned extra; /* USAGE_* sections appended to --help */
    /* options with a value given so far: each at most once */
    const char *seen[SEEN_MAX];
    unsigned nseen;
} args_t;

#define USAGE_LINK 1u
#define USAGE_REQ 2u

typedef struct {
    const char *serial;
    const char *can;
    long baud;
    const char *record; /* --record FILE, or NULL */
} link_opts_t;

static void print_usage(const args_t *a)
{
    fputs(a->usage, stdout);
    if (a->extra & USAGE_LINK) {
        fputs(usage_link, stdout);
    }
    if (a->extra & USAGE_REQ) {
        fputs(usage_req, stdout);
    }
    fputs(usage_exit, stdout);
    tk_stdout_flush();
}

/* An option with a value is given once: a second one is an error, not
 * the silent winner. */
static void opt_once(args_t *a, const char *name)
{
    unsigned k;
    for (k = 0; k < a->nseen; k++) {
        if (strcmp(a->seen[k], name) == 0) {
            tk_usage_error("option %s given twice", name);
        }
    }
    if (a->nseen < SEEN_MAX) {
        a->seen[a->nseen++] = name;
    }
}

/* If argv[i] is option `name` (with "--name V" or "--name=V" when has_arg),
 * consume it and return true; *val gets the value. A separate value that
 * starts with "--" is the next option, so the value is missing (numbers
 * such as -5 are values). */
static bool opt(args_t *a, const char *name, bool has_arg, const char **val)
{
    const char *s = a->argv[a->i];
    size_t n = strlen(name);
    if (a->dashdash || strncmp(s, name, n) != 0) {
        return false;
    }
    if (s[n] == '\0') {
        if (has_arg) {
            if (a->i + 1 >= a->argc || strncmp(a->argv[a->i + 1], "--", 2) == 0) {
                tk_usage_error("option %s needs a value", name);
            }
            opt_once(a, name);
            *val = a->argv[++a->i];
        }
        a->i++;
        return true;
    }
    if (s[n] == '=' && has_arg) {
        opt_once(a, name);
        *val = s + n + 1;
        a->i++;
        return true;
    }
    return false;
}

/* --help, -h and "--" */
static bool common_opt(args_t *a)
{
    const char *s = a->argv[a->i];
    if (a->dashdash) {
        return false;
    }
    if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
        print_usage(a);
        exit(TK_EXIT_OK);
    }
    if (strcmp(s, "--") == 0) {
        a->dashdash = true;
        a->i++;
        return true;
    }
    return false;
}

/* Whether argv[i] is an argument rather than an option: after "--", "-"
 * (standard input), anything not starting with '-', and, where numbers are
 * expected, a negative number. */
static bool is_arg(const args_t *a, bool numbers)
{
    const char *s = a->argv[a->i];
    double x;
    return a->dashdash || s[0] != '-' || s[1] == '\0' ||
           (numbers && tk_parse_real(s, &x) == TK_NUM_OK);
}

/* --baud N */
static bool baud_opt(args_t *a, long *baud)
{
    const char *v;
    long long n;
    if (!opt(a, "--baud", true, &v)) {
        return false;
    }
    if (tk_parse_int(v, 1, 4000000, &n, NULL) != TK_NUM_OK) {
        tk_usage_error("bad --baud value '%s'", v);
    }
    *baud = (long)n;
    return true;
}

static bool link_opt(args_t *a, link_opts_t *l)
{
    return opt(a, "--serial", true, &l->serial) || opt(a, "--can", true, &l->can) ||
           opt(a, "--record", true, &l->record) || baud_opt(a, &l->baud);
}

static long long int_opt_value(const char *name, const char *v, long long min, long long max)
{
    long long n;
    if (tk_parse_int(v, min, max, &n, NULL) != TK_NUM_OK) {
        tk_usage_error("bad %s value '%s' (expected an integer %lld..%lld)", name, v, min, max);
    }
    return n;
}

static void bad_arg(const args_t *a)
{
    const char *s = a->argv[a->i];
    if (!a->dashdash && s[0] == '-' && s[1] != '\0') {
        tk_usage_error("unknown option '%s' (see --help)", s);
    }
    tk_usage_error("unexpected argument '%s' (see --help)", s);
}

static void check_link_opts(const link_opts_t *lo)
{
    if (lo->serial != NULL && lo->can != NULL) {
        tk_usage_error("give either --serial or --can, not both");
    }
    if (lo->serial == NULL && lo->can == NULL) {
        tk_usage_error("no link given: use --serial DEV or --can IFACE");
    }
    if (lo->record != NULL && lo->can != NULL) {
        tk_usage_error("--record records serial links; on CAN run 'tase record --can %s -o FILE' "
                       "beside this command",
                       lo->can);
    }
}

static void open_link(const link_opts_t *lo, tk_link_t *l, tase_port_t *port)
{
    check_link_opts(lo);
    if (lo->serial != NULL) {
        tk_link_serial(l, lo->serial, lo->baud);
    } else {
        tk_link_can(l, lo->can, false);
    }
    *port = tk_link_port(l);
    if (lo->record != NULL) {
        *port = tk_cap_record_session(lo->record, *port);
    }
}

/* ---- requests ---- */

typedef struct {
    uint32_t timeout_ms;
    uint8_t retries;
    bool json;
} req_opts_t;

static bool req_opt(args_t *a, req_opts_t *r)
{
    const char *v;
    if (opt(a, "--timeout", true, &v)) {
        r->timeout_ms = (uint32_t)int_opt_value("--timeout", v, 1, 600000);
        return true;
    }
    if (opt(a, "--retries", true, &v)) {
        r->retries = (uint8_t)int_opt_value("--retries", v, 0, 20);
        return true;
    }
    if (opt(a, "--json", false, &v)) {
        r->json = true;
        return true;
    }
    return false;
}

/* One open link with a host role on it. */
typedef struct {
    tk_link_t link;
    tase_port_t port;
    tase_host_t h;
    const char *name; /* the device or interface, for messages */
} session_t;

static void session_open(session_t *s, const link_opts_t *lo, tase_rx_handler_t on_frame,
                         void *user)
{
    s->name = lo->serial != NULL ? lo->serial : lo->can;
    open_link(lo, &s->link, &s->port);
    if (tase_host_init(&s->h, &s->port, on_frame, user) != TASE_OK) {
        tk_die("internal error: host role init failed");
    }
}

static void session_close(session_t *s)
{
    tk_link_close(&s->link);
    tk_stdout_flush();
}

/* Die: reading the session's link failed with `rc` (a hang-up says so). */
static void session_read_failed(const session_t *s, int rc)
{
    tk_die("cannot read %s: %s", s->name, tk_link_error(&s->link, rc));
}

/* Service the session's port for up to wait_ms; dies when reading fails. */
static void session_service(session_t *s, uint32_t wait_ms)
{
    int rc = tase_host_service(&s->h, wait_ms);
    if (rc < 0) {
        session_read_failed(s, rc);
    }
}

/* Wait for the answer to a request, servicing the port so a signal is
 * seen within 20 ms; dies with the reason on failure, `note` (or NULL)
 * added to a timeout's message. */
static int transact_note(session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                         uint8_t *reply, const req_opts_t *r, const char *note)
{
    int rc = tase_host_request_start(&s->h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len,
                                     reply, TASE_DATA_MAX, r->timeout_ms, r->retries,
                                     s->port.ops->now_ms(s->port.ctx));
    if (rc >= 0 && len > 0) {
        tk_mark_sent(tase_schema_packet_name(p)); /* a query changes nothing */
    }
    while (rc >= 0) {
        tk_exit_if_signalled();
        session_service(s, 20);
        rc = tase_host_poll(&s->h, s->port.ops->now_ms(s->port.ctx));
        if (rc != TASE_EAGAIN) {
            break;
        }
        rc = 0;
    }
    if (rc == TASE_ETIMEOUT) {
        tk_die("timeout: no answer to %s after %u attempt%s of %lu ms%s",
               tase_schema_packet_name(p), (unsigned)r->retries + 1u, r->retries ? "s" : "",
               (unsigned long)r->timeout_ms, note != NULL ? note : "");
    }
    if (rc < 0) {
        tk_die("%s request failed on %s: %s", tase_schema_packet_name(p), s->name,
               tk_link_error(&s->link, rc));
    }
    return rc;
}

static int transact(session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                    uint8_t *reply, const req_opts_t *r)
{
    return transact_note(s, p, data, len, reply, r, NULL);
}

static void send_frame(session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len)
{
    int rc = tase_host_send(&s->h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len);
    if (rc < 0) {
        tk_die("cannot send %s to %s: %s", tase_schema_packet_name(p), s->name,
               tk_link_error(&s->link, rc));
    }
    tk_mark_sent(tase_schema_packet_name(p));
}

/* Print a frame we sent ("dir":"in") or received ("out"); `label` starts
 * the text line ("sent", "echo", NULL for none). */
static void print_packet(const tase_packet_desc_t *p, const uint8_t *data, size_t len, bool json,
                         const char *dir, const char *label)
{
    tase_frame_t f;
    tk_fmt_t fmt = {json, false, false};
    tk_meta_t m = {0, NULL, NULL, NULL};
    f.offset = 0;
    f.group = TASE_ID_GROUP(p->id);
    f.type = TASE_ID_TYPE(p->id);
    f.len = (uint8_t)len;
    f.data = data;
    if (json) {
        m.dir = dir;
    } else if (label != NULL) {
        printf("%s ", label);
    }
    tk_print_frame(stdout, &fmt, &m, &f);
}

/* ---- field assignments ---- */

typedef struct {
    const tase_packet_desc_t *p;
    size_t len; /* the layout's length (fields move in AXIS_SETTING's 22) */
    uint8_t data[TASE_DATA_MAX];
    bool given[32]; /* per field: given, or filled in */
    size_t tail;    /* CAMERA_PASS data bytes */
    bool tail_given;
} fields_t;

static void fields_init(fields_t *fs, const tase_packet_desc_t *p, size_t len)
{
    memset(fs, 0, sizeof(*fs));
    fs->p = p;
    fs->len = len;
}

static size_t parse_tail(const char *v, uint8_t *out, size_t cap)
{
    size_t n = 0, item = 0;
    const char *s = v;
    if (*v == '\0') {
        tk_usage_error("empty data list (expected data=BYTE,BYTE,...)");
    }
    for (;;) {
        const char *comma = strchr(s, ',');
        size_t l = comma != NULL ? (size_t)(comma - s) : strlen(s);
        char tok[32];
        long long b;
        int rc;
        item++;
        if (l == 0) {
            tk_usage_error("empty item %lu in data list '%s'", (unsigned long)item, v);
        }
        if (l >= sizeof(tok)) {
            tk_usage_error("bad data byte in '%s' (expected 0..255)", v);
        }
        memcpy(tok, s, l);
        tok[l] = '\0';
        if (n >= cap) {
            tk_usage_error("too many data bytes (at most %lu)", (unsigned long)cap);
        }
        rc = tk_parse_int(tok, 0, 255, &b, NULL);
        if (rc != TK_NUM_OK) {
            tk_usage_error("bad data byte '%s': %s", tok,
                           rc == TK_NUM_RANGE ? "out of range 0..255"
                                              : "not a number (decimal or 0x hex)");
        }
        out[n++] = (uint8_t)b;
        if (comma == NULL) {
            return n;
        }
        s = comma + 1;
    }
}

/* Apply one "field=value" argument; usage error on anything wrong. */
static void fields_assign(fields_t *fs, const char *arg)
{
    const tase_packet_desc_t *p = fs->p;
    const char *name = tase_schema_packet_name(p);
    const char *eq = strchr(arg, '=');
    char fname[64], range[64];
    size_t fl = (size_t)(eq - arg);
    int fi, rc;
    tk_field_t fd;
    long long val;
    if (fl == 0 || fl >= sizeof(fname)) {
        tk_usage_error("bad assignment '%s' (expected field=value)", arg);
    }
    memcpy(fname, arg, fl);
    fname[fl] = '\0';
    if (tk_packet_has_tail(p) && strcmp(fname, "data") == 0) {
        if (fs->tail_given) {
            tk_usage_error("%s.data given twice", name);
        }
        fs->tail = parse_tail(eq + 1, fs->data + p->len, TASE_DATA_MAX - p->len);
        fs->tail_given = true;
        return;
    }
    fi = tase_schema_field_index(p, fname);
    if (fi < 0 || (size_t)fi >= sizeof(fs->given)) {
        tk_usage_error("%s has no field '%s' (see 'tase list')", name, fname);
    }
    if (fs->given[fi]) {
        tk_usage_error("%s.%s given twice", name, fname);
    }
    tk_field(p, (unsigned)fi, fs->len, &fd);
    tk_field_range(&fd, range, sizeof(range));
    rc = tk_field_parse(&fd, eq + 1, &val);
    if (eq[1] == '\0') {
        tk_usage_error("bad value '' for %s.%s: empty (expected an integer %s)", name, fname,
                       range);
    } else if (rc == TK_NUM_SYNTAX) {
        tk_usage_error("bad value '%s' for %s.%s: not a number (decimal, or 0x hex, with an "
                       "optional sign)",
                       eq + 1, name, fname);
    } else if (rc != TK_NUM_OK) {
        tk_usage_error("bad value '%s' for %s.%s: out of range %s (%s %u-bit)", eq + 1, name, fname,
                       range, fd.is_signed ? "signed" : "unsigned", 8u * fd.width);
    }
    (void)tk_field_set(&fd, fs->data, val);
    fs->given[fi] = true;
}

static long long fields_value(const fields_t *fs, unsigned i)
{
    long long v = 0;
    (void)tk_field_get(fs->p, i, fs->data, fs->len, &v);
    return v;
}

/* Set field `name` (which must exist) as if given on the command line. */
static void fields_set(fields_t *fs, const char *name, long long v)
{
    int fi = tase_schema_field_index(fs->p, name);
    tk_field_t fd;
    if (fi < 0) {
        tk_die("internal error: no field %s", name);
    }
    tk_field(fs->p, (unsigned)fi, fs->len, &fd);
    if (tk_field_set(&fd, fs->data, v) != 0) {
        tk_die("internal error: %s=%lld does not fit", name, v);
    }
    fs->given[fi] = true;
}

/* The fields that lie within `len` bytes. */
static unsigned fields_within(const tase_packet_desc_t *p, size_t len)
{
    unsigned i;
    for (i = 0; i < p->nfields; i++) {
        tk_field_t fd;
        tk_field(p, i, len, &fd);
        if (fd.offset + fd.width > len) {
            break;
        }
    }
    return i;
}

/* Move the fields set so far to the layout of `len` data bytes (a setup
 * packet sent in the layout the gimbal answered with: AXIS_SETTING's 22 or
 * 23 bytes; the widths are the same, offsets move). A field that does not
 * fit `len` is dropped. */
static void fields_relayout(fields_t *fs, size_t len)
{
    uint8_t data[TASE_DATA_MAX];
    unsigned i;
    memset(data, 0, sizeof(data));
    for (i = 0; i < fs->p->nfields && i < sizeof(fs->given); i++) {
        tk_field_t fd;
        long long v;
        if (!fs->given[i]) {
            continue;
        }
        tk_field(fs->p, i, len, &fd);
        if (fd.offset + fd.width > len || !tk_field_get(fs->p, i, fs->data, fs->len, &v)) {
            fs->given[i] = false;
            continue;
        }
        (void)tk_field_set(&fd, data, v);
    }
    memcpy(fs->data, data, sizeof(data));
    fs->len = len;
}

/* Fields [0, n) left out that have a "do not change" value in the spec
 * (the schema's, tase_field_keep()) take it. */
static void fields_keep(fields_t *fs, unsigned n)
{
    unsigned i;
    for (i = 0; i < n; i++) {
        int64_t keep;
        if (!fs->given[i] && tase_field_keep(fs->p, i, &keep) == TASE_OK) {
            fields_set(fs, tase_schema_field_name(fs->p, i), (long long)keep);
        }
    }
}

/* A comma-separated list of the names of fields [0, n) not given. */
static size_t missing_list(const fields_t *fs, unsigned n, char *buf, size_t cap)
{
    size_t count = 0, used = 0;
    unsigned i;
    buf[0] = '\0';
    for (i = 0; i < n; i++) {
        if (!fs->given[i]) {
            int w = snprintf(buf + used, cap - used, "%s%s", count ? ", " : "",
                             tase_schema_field_name(fs->p, i));
            if (w > 0 && (size_t)w < cap - used) {
                used += (size_t)w;
            }
            count++;
        }
    }
    return count;
}

/* ---- GIMBAL_CMD modes ---- */

static const struct {
    uint8_t flags;
    const char *what;
} gimbal_modes[] = {
    {TASE_GIMBAL_FLAGS_RATE, "rate"},
    {TASE_GIMBAL_FLAGS_RATE_STAB, "rate stabilised"},
    {TASE_GIMBAL_FLAGS_POSITION, "position"},
    {TASE_GIMBAL_FLAGS_POSITION_STAB, "position stabilised"},
    {TASE_GIMBAL_FLAGS_IMPULSE, "impulse"},
    {TASE_GIMBAL_FLAGS_IMPULSE_STAB, "impulse stabilised"},
    {TASE_GIMBAL_FLAGS_SPOI_ERROR, "SPOI error"},
    {TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE, "SPOI error rate"},
    {TASE_GIMBAL_FLAGS_LEGACY_RATE, "legacy rate"},
    {TASE_GIMBAL_FLAGS_LEGACY_POSITION, "legacy position"},
    {TASE_GIMBAL_FLAGS_LEGACY_RATE_STAB, "legacy rate stabilised"},
    {TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB, "legacy position stabilised"},
};

static const char *gimbal_mode(long long flags)
{
    size_t i;
    for (i = 0; i < sizeof(gimbal_modes) / sizeof(gimbal_modes[0]); i++) {
        if (gimbal_modes[i].flags == flags) {
            return gimbal_modes[i].what;
        }
    }
    return NULL;
}

static void refuse_gimbal_cmd(const char *why)
{
    char list[512];
    size_t i, used = 0;
    for (i = 0; i < sizeof(gimbal_modes) / sizeof(gimbal_modes[0]); i++) {
        int w = snprintf(list + used, sizeof(list) - used, "%s0x%02X %s", i ? ", " : "",
                         (unsigned)gimbal_modes[i].flags, gimbal_modes[i].what);
        if (w > 0 && (size_t)w < sizeof(list) - used) {
            used += (size_t)w;
        }
    }
    tk_usage_error("GIMBAL_CMD %s: flags=MODE states what pan/tilt mean, one of: %s (or use "
                   "'tase point' / 'tase rate')",
                   why, list);
}

/* ---- send ---- */

typedef struct {
    bool zero;     /* fields left out are 0 */
    bool no_wait;  /* wait for nothing */
    long long len; /* forced data length, -1 none */
    req_opts_t r;
} send_opts_t;

/* Compare the gimbal's echo with what was sent; exit 3 naming every field
 * that differs. Fields sent as "do not change" are not compared (the echo
 * has the setting in force); `skip` names another one (or NULL). */
static void confirm_echo(const fields_t *fs, size_t len, const uint8_t *echo, int elen,
                         const char *skip)
{
    const tase_packet_desc_t *p = fs->p;
    char diff[1024];
    size_t used = 0, count = 0;
    unsigned i, n = fields_within(p, len);
    if ((size_t)elen != len) {
        tk_exit(TK_EXIT_MISMATCH, "%s not confirmed: the echo has %d data bytes, %lu were sent",
                tase_schema_packet_name(p), elen, (unsigned long)len);
    }
    diff[0] = '\0';
    for (i = 0; i < n; i++) {
        long long sent = fields_value(fs, i), got = 0;
        const char *name = tase_schema_field_name(p, i);
        (void)tk_field_get(p, i, echo, (size_t)elen, &got);
        if (got != sent && !tase_field_is_keep(p, i, sent) &&
            (skip == NULL || strcmp(skip, name) != 0)) {
            int w = snprintf(diff + used, sizeof(diff) - used, "%s%s sent %lld, gimbal has %lld",
                             count ? "; " : "", name, sent, got);
            if (w > 0 && (size_t)w < sizeof(diff) - used) {
                used += (size_t)w;
            }
            count++;
        }
    }
    if (count != 0) {
        tk_exit(TK_EXIT_MISMATCH, "%s not applied as sent: %s", tase_schema_packet_name(p), diff);
    }
}

/* Send fs (len bytes); for setup packets wait for the echo and confirm it
 * (unless no_wait). */
static void send_fields(session_t *s, const fields_t *fs, size_t len, const send_opts_t *o)
{
    const tase_packet_desc_t *p = fs->p;
    uint8_t reply[TASE_DATA_MAX];
    bool echoed = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP && !o->no_wait;
    int n;
    if (!echoed) {
        send_frame(s, p, fs->data, len);
        print_packet(p, fs->data, len, o->r.json, "in", "sent");
        return;
    }
    n = transact(s, p, fs->data, len, reply, &o->r);
    print_packet(p, fs->data, len, o->r.json, "in", "sent");
    print_packet(p, reply, (size_t)n, o->r.json, "out", "echo");
    if (len > 0) {
        /* `temporary` tells the gimbal what to do with this packet (store
         * it or not); it is no setting in force, so its echo proves nothing */
        confirm_echo(fs, len, reply, n, "temporary");
    }
}

static int cmd_send(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    send_opts_t o = {false, false, -1, {DEFAULT_TIMEOUT_MS, DEFAULT_RETRIES, false}};
    const char *name = NULL, *v;
    const char *assign[64];
    size_t nassign = 0, i, len;
    unsigned nf;
    bool setup, rmw = false, relaid = false, temp_default = false;
    int tfi;
    const tase_packet_desc_t *p;
    fields_t fs;
    session_t s;
    while (a->i < a->argc) {
        if (common_opt(a) || link_opt(a, &lo) || req_opt(a, &o.r)) {
            continue;
        }
        if (opt(a, "--zero", false, &v)) {
            o.zero = true;
        } else if (opt(a, "--no-wait", false, &v)) {
            o.no_wait = true;
        } else if (opt(a, "--len", true, &v)) {
            o.len = int_opt_value("--len", v, 0, TASE_DATA_MAX);
        } else if (is_arg(a, false) && name == NULL) {
            name = a->argv[a->i++];
        } else if (is_arg(a, false) && strchr(a->argv[a->i], '=') != NULL) {
            if (nassign == sizeof(assign) / sizeof(assign[0])) {
                tk_usage_error("too many field assignments");
            }
            assign[nassign++] = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    if (name == NULL) {
        tk_usage_error("send needs a packet name (e.g. PACKET_RATE; see 'tase list')");
    }
    p = tk_packet_by_name(name);
    name = tase_schema_packet_name(p);
    if ((p->flags & TASE_DIR_IN) == 0) {
        tk_usage_error("%s is sent by the gimbal, not to it", name);
    }
    if (p->id == TASE_ID_SYSTEM_VERSION) {
        tk_usage_error("SYSTEM_VERSION is query-only: use 'tase query SYSTEM_VERSION'");
    }
    setup = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP;
    fields_init(&fs, p, o.len >= 0 ? (size_t)o.len : p->len);
    for (i = 0; i < nassign; i++) {
        fields_assign(&fs, assign[i]);
    }
    len = o.len >= 0 ? (size_t)o.len : p->len + fs.tail;
    if (!tase_schema_length_ok(p, len)) {
        tk_usage_error("%s does not accept a data length of %lu", name, (unsigned long)len);
    }
    nf = fields_within(p, len);
    tfi = tase_schema_field_index(p, "temporary");
    if (setup && tfi >= 0 && (unsigned)tfi < nf && !fs.given[tfi]) {
        /* A setup packet with temporary 0 is written to the gimbal's
         * non-volatile storage (spec 4.4.1, 4.4.3): a bench change is kept
         * for this power cycle only unless temporary=0 asks to store it. */
        fields_set(&fs, "temporary", TASE_SETUP_TEMPORARY);
        temp_default = true;
    }
    if (p->id == TASE_ID_GIMBAL_CMD && len > 0) {
        int fi = tase_schema_field_index(p, "flags");
        if (!fs.given[fi]) {
            refuse_gimbal_cmd("needs flags");
        }
        if (gimbal_mode(fields_value(&fs, (unsigned)fi)) == NULL) {
            refuse_gimbal_cmd("flags is not a mode of the spec's table 5");
        }
    }
    fields_keep(&fs, nf);
    if (!o.zero) {
        char missing[512];
        size_t nmiss = missing_list(&fs, nf, missing, sizeof(missing));
        if (nmiss > 0 && setup && !o.no_wait) {
            rmw = true; /* fill them from the gimbal's current settings */
        } else if (nmiss > 0) {
            tk_usage_error("%s needs every field%s: missing %s (give them, or --zero to send 0)",
                           name, setup ? " with --no-wait (nothing is queried)" : "", missing);
        }
    }
    if (setup && !o.no_wait && o.len < 0 && (p->flags & TASE_LEN_SHORT) != 0u) {
        /* a packet of two layouts (AXIS_SETTING, PROTOCOL-NOTES S2): the
         * query's answer tells which one this gimbal uses, even when
         * every field is given */
        rmw = true;
    }
    session_open(&s, &lo, NULL, NULL);
    if (rmw) {
        uint8_t cur[TASE_DATA_MAX];
        unsigned k;
        int n = transact_note(&s, p, NULL, 0, cur, &o.r,
                              " (only the query went out, to read the gimbal's settings; the "
                              "new setting was not sent)");
        if (n <= 0 || !tase_schema_length_ok(p, (size_t)n)) {
            tk_die("%s query answered with %d data bytes, not a length of %s; nothing was set",
                   name, n, name);
        }
        if (o.len < 0 && (size_t)n != len) {
            /* the layout this gimbal uses (AXIS_SETTING's 22 bytes): send
             * in it, as the gimbal answered, unless --len says otherwise */
            fields_relayout(&fs, (size_t)n);
            len = (size_t)n;
            nf = fields_within(p, len);
            relaid = true;
        }
        /* each field read at its place in the answer's own layout */
        for (k = 0; k < nf; k++) {
            long long cv;
            if (!fs.given[k] && tk_field_get(p, k, cur, (size_t)n, &cv)) {
                fields_set(&fs, tase_schema_field_name(p, k), cv);
            }
        }
    }
    send_fields(&s, &fs, len, &o);
    if (relaid && !o.r.json) {
        printf("  = sent in the %lu-byte layout the gimbal answered the query with\n",
               (unsigned long)len);
    }
    if (temp_default && !o.r.json) {
        printf("  = temporary=1 (the default): not written to the gimbal's non-volatile "
               "storage; temporary=0 stores it\n");
    }
    session_close(&s);
    return TK_EXIT_OK;
}

/* ---- query ---- */

static int cmd_query(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    req_opts_t r = {DEFAULT_TIMEOUT_MS, DEFAULT_RETRIES, false};
    const char *name = NULL;
    const tase_packet_desc_t *p;
    session_t s;
    uint8_t reply[TASE_DATA_MAX];
    int n;
    while (a->i < a->argc) {
        if (common_opt(a) || link_opt(a, &lo) || req_opt(a, &r)) {
            continue;
        }
        if (is_arg(a, false) && name == NULL) {
            name = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    if (name == NULL) {
        tk_usage_error("query needs a packet name (e.g. SYSTEM_VERSION)");
    }
    p = tk_packet_by_name(name);
    if ((p->flags & TASE_LEN_QUERY) == 0) {
        tk_usage_error("%s has no zero-length query form (queryable: the setup packets, "
                       "SPOI_CMD, SYSTEM_VERSION)",
                       tase_schema_packet_name(p));
    }
    session_open(&s, &lo, NULL, NULL);
    n = transact(&s, p, NULL, 0, reply, &r);
    print_packet(p, reply, (size_t)n, r.json, "out", NULL);
    session_close(&s);
    return TK_EXIT_OK;
}

/* ---- verbs ---- */

/* x as a plain decimal number (no exponent; at most two decimals, no
 * trailing zeros): -21474836.48, 180, 0.01. */
static const char *plain_number(double x, char *buf, size_t cap)
{
    size_t n;
    snprintf(buf, cap, "%.2f", x);
    n = strlen(buf);
    while (n > 0 && buf[n - 1] == '0') {
        buf[--n] = '\0';
    }
    if (n > 0 && buf[n - 1] == '.') {
        buf[--n] = '\0';
    }
    return buf;
}

/* A decimal number argument in [lo, hi] (what names it in messages). */
static double real_arg(const char *what, const char *v, double lo, double hi, const char *unit)
{
    double x;
    char a[48], b[48];
    if (tk_parse_real(v, &x) != TK_NUM_OK) {
        tk_usage_error("bad %s '%s': not a number (decimal, e.g. -12.5)", what, v);
    }
    if (!(x >= lo && x <= hi)) {
        tk_usage_error("bad %s '%s': out of range %s..%s %s", what, v,
                       plain_number(lo, a, sizeof(a)), plain_number(hi, b, sizeof(b)), unit);
    }
    return x;
}

typedef struct {
    link_opts_t lo;
    req_opts_t r;
    const char *pos[3];
    size_t npos;
    const char *stab;   /* "on", "off" or NULL */
    const char *hfov;   /* camera */
    const char *zoom;   /* camera */
    const char *wait_s; /* deploy/retract */
    bool no_wait;       /* spoi */
} verb_args_t;

/* The options every verb takes, plus the ones `which` lists. */
static void verb_parse(args_t *a, verb_args_t *v, size_t max_pos, const char *which)
{
    memset(v, 0, sizeof(*v));
    v->lo.baud = DEFAULT_BAUD;
    v->r.timeout_ms = DEFAULT_TIMEOUT_MS;
    v->r.retries = DEFAULT_RETRIES;
    while (a->i < a->argc) {
        const char *x;
        if (common_opt(a) || link_opt(a, &v->lo) || req_opt(a, &v->r)) {
            continue;
        }
        if (strstr(which, "stab") && opt(a, "--stab", true, &v->stab)) {
            if (strcmp(v->stab, "on") != 0 && strcmp(v->stab, "off") != 0) {
                tk_usage_error("bad --stab value '%s' (on or off)", v->stab);
            }
        } else if (strstr(which, "hfov") && opt(a, "--hfov", true, &v->hfov)) {
        } else if (strstr(which, "zoom") && opt(a, "--zoom", true, &v->zoom)) {
        } else if (strstr(which, "wait") && opt(a, "--wait", true, &v->wait_s)) {
        } else if (strstr(which, "no-wait") && opt(a, "--no-wait", false, &x)) {
            v->no_wait = true;
        } else if (is_arg(a, true) && v->npos < max_pos) {
            v->pos[v->npos++] = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
}

/* Verbs send a complete packet without waiting for an echo (unless they
 * run a request themselves). */
static send_opts_t verb_opts(const verb_args_t *v)
{
    send_opts_t o;
    o.zero = false;
    o.no_wait = true;
    o.len = -1;
    o.r = v->r;
    return o;
}

static void need_args(const verb_args_t *v, size_t n, const char *what)
{
    if (v->npos != n) {
        tk_usage_error("expected %s (see --help)", what);
    }
    check_link_opts(&v->lo);
}

/* point and rate: GIMBAL_CMD with its mode stated by the verb. */
typedef struct {
    uint8_t kind; /* TASE_GIMBAL_KIND_* */
    const char *args;
    const char *what; /* "pan" / "pan rate" in messages */
    double lo, hi;
    const char *unit;
} gimbal_verb_t;

static const gimbal_verb_t verb_point = {
    TASE_GIMBAL_KIND_POSITION, "PAN TILT in degrees", "", -180.0, 180.0, "deg"};
static const gimbal_verb_t verb_rate = {TASE_GIMBAL_KIND_RATE,
                                        "PAN_RATE TILT_RATE in degrees per second",
                                        " rate",
                                        -327.68,
                                        327.67,
                                        "deg/s"};

static int gimbal_verb(args_t *a, const gimbal_verb_t *gv)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x80);
    verb_args_t v;
    send_opts_t o;
    fields_t fs;
    session_t s;
    char what[32];
    long long pan, tilt;
    uint8_t flags;
    verb_parse(a, &v, 2, "stab");
    need_args(&v, 2, gv->args);
    snprintf(what, sizeof(what), "pan%s", gv->what);
    pan = tase_units_deg_to_cdeg(real_arg(what, v.pos[0], gv->lo, gv->hi, gv->unit));
    snprintf(what, sizeof(what), "tilt%s", gv->what);
    tilt = tase_units_deg_to_cdeg(real_arg(what, v.pos[1], gv->lo, gv->hi, gv->unit));
    flags = TASE_GIMBAL_FLAGS(gv->kind, v.stab == NULL || strcmp(v.stab, "on") == 0);
    fields_init(&fs, p, p->len);
    fields_set(&fs, "pan", pan);
    fields_set(&fs, "tilt", tilt);
    fields_set(&fs, "roll", 0);
    fields_set(&fs, "flags", flags);
    fields_set(&fs, "impulse_time", 0);
    o = verb_opts(&v);
    session_open(&s, &v.lo, NULL, NULL);
    send_fields(&s, &fs, p->len, &o);
    if (!v.r.json) {
        printf("  = %s: pan %.2f %s, tilt %.2f %s (flags 0x%02X)\n", gimbal_mode(flags),
               (double)pan / 100.0, gv->unit, (double)tilt / 100.0, gv->unit, (unsigned)flags);
    }
    session_close(&s);
    return TK_EXIT_OK;
}

static int cmd_point(args_t *a)
{
    return gimbal_verb(a, &verb_point);
}

static int cmd_rate(args_t *a)
{
    return gimbal_verb(a, &verb_rate);
}

static int camera_index(const char *s)
{
    static const char *const names[] = {"A", "B", "C", "a", "b", "c", "0", "1", "2"};
    size_t i;
    for (i = 0; i < sizeof(names) / sizeof(names[0]); i++) {
        if (strcmp(s, names[i]) == 0) {
            return (int)(i % 3u);
        }
    }
    tk_usage_error("bad camera '%s' (A, B or C)", s);
    return -1;
}

/* The type of camera `cam` (0..2) in the gimbal's SYSTEM_VERSION; dies
 * when the gimbal has none there, before CAMERA_CMD is sent. */
static int camera_type(session_t *s, int cam, const req_opts_t *r)
{
    static const char *const fields[] = {"camera_a", "camera_b", "camera_c"};
    const tase_packet_desc_t *sv = tase_schema_find(TASE_ID_GROUP(TASE_ID_SYSTEM_VERSION),
                                                    TASE_ID_TYPE(TASE_ID_SYSTEM_VERSION));
    uint8_t reply[TASE_DATA_MAX];
    long long type = -1;
    int n = transact_note(s, sv, NULL, 0, reply, r,
                          " (the query asks which cameras the gimbal has; CAMERA_CMD was not "
                          "sent)");
    if (!tk_field_get(sv, (unsigned)tase_schema_field_index(sv, fields[cam]), reply, (size_t)n,
                      &type)) {
        tk_die("SYSTEM_VERSION answered with %d data bytes, no camera types; CAMERA_CMD was not "
               "sent",
               n);
    }
    if (type == TASE_CAMTYPE_NONE) {
        tk_die("the gimbal has no camera %c (SYSTEM_VERSION: type 0xFF, none); CAMERA_CMD was not "
               "sent",
               "ABC"[cam]);
    }
    return (int)type;
}

static int cmd_camera(args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x41);
    verb_args_t v;
    send_opts_t o;
    fields_t fs;
    session_t s;
    int cam = -1, camtype = -1;
    long long hfov = 0;
    size_t len;
    char what[96];
    verb_parse(a, &v, 1, "hfov zoom");
    check_link_opts(&v.lo);
    if (v.npos == 1) {
        cam = camera_index(v.pos[0]);
    }
    if (v.hfov != NULL && v.zoom != NULL) {
        tk_usage_error("give either --hfov or --zoom, not both");
    }
    if (cam < 0 && v.hfov == NULL && v.zoom == NULL) {
        tk_usage_error("expected a camera (A, B, C), --hfov DEG or --zoom X (see --help)");
    }
    if (v.hfov != NULL) {
        double d = real_arg("--hfov", v.hfov, 0.01, 327.67, "deg");
        hfov = tase_units_deg_to_cdeg(d);
        snprintf(what, sizeof(what), ", HFOV %.2f deg", (double)hfov / 100.0);
    } else if (v.zoom != NULL) {
        /* a negative HFOV is a zoom ratio in -1/100 (-1 itself means "no
         * change", which a ratio of at least 1 never reaches) */
        double z = real_arg("--zoom", v.zoom, 1.0, 327.68, "x");
        hfov = -(long long)tase_units_round_clamp(z * 100.0, 100.0, 32768.0);
        snprintf(what, sizeof(what), ", zoom %.2fx", (double)-hfov / 100.0);
    } else {
        what[0] = '\0';
    }
    o = verb_opts(&v);
    len = v.hfov != NULL || v.zoom != NULL ? p->len : 1u;
    fields_init(&fs, p, len);
    if (cam >= 0) {
        fields_set(&fs, "camera", cam);
    }
    if (len > 1u) {
        fields_set(&fs, "hfov", hfov);
    }
    fields_keep(&fs, fields_within(p, len)); /* everything else: "do not change" */
    session_open(&s, &v.lo, NULL, NULL);
    if (cam >= 0) {
        /* CAMERA_CMD has no echo: a camera the gimbal does not have would
         * be "selected" with nothing to confirm it, so ask first */
        camtype = camera_type(&s, cam, &v.r);
    }
    send_fields(&s, &fs, len, &o);
    if (!v.r.json) {
        char sel[64] = "active camera unchanged";
        if (cam >= 0) {
            snprintf(sel, sizeof(sel), "camera %c%s (type %d in SYSTEM_VERSION)", "ABC"[cam],
                     what[0] ? "" : " selected", camtype);
        }
        printf("  = %s%s%s\n", sel, what, what[0] ? ", other settings unchanged" : "");
    }
    session_close(&s);
    return TK_EXIT_OK;
}

static int cmd_gyro_zero(args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x40);
    verb_args_t v;
    session_t s;
    verb_parse(a, &v, 0, "");
    need_args(&v, 0, "no arguments");
    session_open(&s, &v.lo, NULL, NULL);
    send_frame(&s, p, NULL, 0);
    print_packet(p, NULL, 0, v.r.json, "in", "sent");
    session_close(&s);
    return TK_EXIT_OK;
}

typedef struct {
    bool seen;
    uint8_t deploy;
} rd_echo_t;

static void on_rd_frame(void *user, const tase_frame_t *f)
{
    rd_echo_t *e = user;
    if (f->group == 0x00 && f->type == 0x43 && f->len == 2u) {
        e->seen = true;
        e->deploy = f->data[0];
    }
}

static int retract_deploy(args_t *a, bool deploy)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x43);
    verb_args_t v;
    session_t s;
    rd_echo_t e = {false, 0};
    double wait = 0.0, t_end;
    uint8_t data[2] = {deploy ? TASE_DEPLOY : TASE_RETRACT, 0};
    verb_parse(a, &v, 0, "wait");
    need_args(&v, 0, "no arguments");
    if (v.wait_s != NULL && (tk_parse_seconds(v.wait_s, &wait) != 0 || wait <= 0.0)) {
        tk_usage_error("bad --wait value '%s' (seconds)", v.wait_s);
    }
    session_open(&s, &v.lo, on_rd_frame, &e);
    send_frame(&s, p, data, sizeof(data));
    print_packet(p, data, sizeof(data), v.r.json, "in", "sent");
    tk_stdout_flush();
    t_end = tk_now_s() + wait;
    while (wait > 0.0 && !e.seen && tk_now_s() < t_end) {
        tk_exit_if_signalled();
        session_service(&s, 20);
    }
    if (wait > 0.0 && !e.seen) {
        tk_die("timeout: no RETRACT_DEPLOY_CMD echo within %g s (the move is not complete)", wait);
    }
    if (e.seen) {
        print_packet(p, (uint8_t[]){e.deploy, 0}, 2, v.r.json, "out", "echo");
        if ((e.deploy != 0) != deploy) {
            tk_exit(TK_EXIT_MISMATCH, "RETRACT_DEPLOY_CMD echo reports %s, not %s",
                    e.deploy ? "deployed" : "retracted", deploy ? "deployed" : "retracted");
        }
    }
    session_close(&s);
    return TK_EXIT_OK;
}

static int cmd_deploy(args_t *a)
{
    return retract_deploy(a, true);
}

static int cmd_retract(args_t *a)
{
    return retract_deploy(a, false);
}

static int cmd_spoi(args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x10, 0x40);
    verb_args_t v;
    send_opts_t o;
    fields_t fs;
    session_t s;
    double lat, lon, height;
    verb_parse(a, &v, 3, "no-wait");
    need_args(&v, 3, "LAT LON HEIGHT (degrees, degrees, metres)");
    lat = real_arg("latitude", v.pos[0], -90.0, 90.0, "deg");
    lon = real_arg("longitude", v.pos[1], -180.0, 180.0, "deg");
    height = real_arg("height", v.pos[2], -21474836.48, 21474836.47, "m");
    fields_init(&fs, p, p->len);
    fields_set(&fs, "lat", tase_units_deg_to_mas(lat));
    fields_set(&fs, "lon", tase_units_deg_to_mas(lon));
    fields_set(&fs, "height", tase_units_m_to_cm(height));
    fields_set(&fs, "vnorth", 0);
    fields_set(&fs, "veast", 0);
    fields_set(&fs, "vdown", 0);
    fields_set(&fs, "flags", v.no_wait ? 0u : TASE_SPOI_ECHO);
    o = verb_opts(&v);
    session_open(&s, &v.lo, NULL, NULL);
    if (v.no_wait) {
        send_fields(&s, &fs, p->len, &o);
    } else {
        uint8_t reply[TASE_DATA_MAX];
        int n = transact(&s, p, fs.data, p->len, reply, &v.r);
        print_packet(p, fs.data, p->len, v.r.json, "in", "sent");
        print_packet(p, reply, (size_t)n, v.r.json, "out", "echo");
        /* the echo's flags carry the gimbal's state, not our request */
        confirm_echo(&fs, p->len, reply, n, "flags");
    }
    if (!v.r.json) {
        printf("  = SPOI at %.7f deg, %.7f deg, %.2f m%s\n",
               tase_units_mas_to_deg((int32_t)fields_value(&fs, 0)),
               tase_units_mas_to_deg((int32_t)fields_value(&fs, 1)),
               tase_units_cm_to_m((int32_t)fields_value(&fs, 2)), v.no_wait ? "" : ", echoed");
    }
    session_close(&s);
    return TK_EXIT_OK;
}

/* ---- monitor ---- */

static int cmd_monitor(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    tk_fmt_t fmt = {false, false, false};
    double seconds = 0.0, t_end;
    long long limit = 0;
    const char *v;
    tk_link_t link;
    tase_port_t port;
    static tk_dec_t d;
    tk_stream_t *st;
    static uint8_t buf[4096];
    char extra[192] = "";
    int failed = 0;
    while (a->i < a->argc) {
        if (common_opt(a) || link_opt(a, &lo)) {
            continue;
        }
        if (opt(a, "--json", false, &v)) {
            fmt.json = true;
        } else if (opt(a, "--time", false, &v)) {
            fmt.time = true;
        } else if (opt(a, "--units", false, &v)) {
            fmt.units = true;
        } else if (opt(a, "--count", true, &v)) {
            limit = int_opt_value("--count", v, 1, 1000000000);
        } else if (opt(a, "--seconds", true, &v)) {
            if (tk_parse_seconds(v, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", v);
            }
        } else {
            bad_arg(a);
        }
    }
    open_link(&lo, &link, &port);
    tk_dec_init(&d, &fmt, stdout);
    d.limit = (uint64_t)limit;
    d.serial_rate = port.bytes_per_s;
    st = tk_dec_stream(&d, "", NULL);
    t_end = tk_now_s() + seconds;
    while ((limit == 0 || d.n.frames < (uint64_t)limit) && (seconds == 0.0 || tk_now_s() < t_end) &&
           tk_signal == 0) {
        /* wake by the receiver's quiet limit (tase/frame.h, TIME BOUND) */
        uint32_t wait = tase_rx_quiet_ms(&st->rx, port.ops->now_ms(port.ctx));
        int n = port.ops->read(port.ctx, buf, sizeof(buf), wait < 50u ? wait : 50u);
        if (n < 0) {
            if (tk_signal == 0) {
                failed = n; /* a hang-up, most likely: the summary, then why */
            }
            break;
        }
        if (n > 0) {
            tk_time_t now;
            uint64_t ns = link.is_can ? tase_socketcan_rx_time_ns(&link.can) : 0u;
            if (ns != 0u) { /* the kernel's receive time of the frame */
                now.sec = (int64_t)(ns / 1000000000u);
                now.usec = (uint32_t)(ns % 1000000000u / 1000u);
            } else {
                tk_time_now(&now);
            }
            tk_dec_bytes(&d, st, buf, (size_t)n, fmt.time ? &now : NULL);
        }
        tk_dec_tick(&d, st, port.ops->now_ms(port.ctx)); /* arrival, or quiet until now */
        tk_stdout_flush();
    }
    if (link.is_can) {
        tase_socketcan_bus_t bus;
        static const char *const states[] = {"error-active", "error-warning", "error-passive",
                                             "bus-off"};
        if (tase_socketcan_bus(&link.can, &bus) == TASE_OK) {
            snprintf(extra, sizeof(extra),
                     ", CAN bus %s (%lu error frames, %lu bus-off, %lu no-ACK, %lu queue full, "
                     "TEC %u, REC %u)",
                     states[bus.state & 3u], (unsigned long)bus.error_frames,
                     (unsigned long)bus.bus_offs, (unsigned long)bus.no_acks,
                     (unsigned long)bus.enobufs, (unsigned)bus.tx_error_count,
                     (unsigned)bus.rx_error_count);
        }
    }
    tk_link_close(&link);
    tk_stdout_flush();
    tk_dec_summary(&d, stderr, extra);
    if (failed != 0) {
        tk_die("cannot read %s: %s", lo.serial != NULL ? lo.serial : lo.can,
               tk_link_error(&link, failed));
    }
    if (d.n.frames == 0 && d.n.bytes > 0) {
        if (link.is_can) {
            tk_exit(TK_EXIT_INPUT,
                    "no TASE frame in the %llu datalink bytes received on %s (ID 10000000 "
                    "frames that never formed a valid frame)",
                    (unsigned long long)d.n.bytes, lo.can);
        }
        tk_exit(TK_EXIT_INPUT,
                "no TASE frame in the %llu bytes received on %s: a wrong --baud (%ld), or not "
                "the gimbal's datalink port (its KLV line?)",
                (unsigned long long)d.n.bytes, lo.serial, lo.baud);
    }
    return TK_EXIT_OK;
}

/* ---- decode ---- */

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
} input_t;

/* Open FILE (NULL or "-": standard input). With baud > 0 a terminal named
 * as FILE (a serial device, a pty) is opened through the POSIX UART port
 * as the link commands open it: raw 8N1 at `baud`, exclusive, its settings
 * given back on every exit path. */
static void input_open(input_t *in, const char *path, long baud)
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
        tk_die("cannot open %s: %s", path, strerror(errno));
    }
}

static void input_close(input_t *in)
{
    if (in->device) {
        tk_link_close(&in->link);
    } else if (in->fd != STDIN_FILENO) {
        (void)close(in->fd);
    }
}

/* After the input ended: a device that hung up is an error (what was
 * decoded is out already). */
static void input_check_end(const input_t *in)
{
    if (in->hung_up) {
        tk_die("cannot read %s: the device went away or hung up", in->name);
    }
}

static size_t input_keep_head(input_t *in, const uint8_t *buf, size_t k)
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
static size_t input_read(input_t *in, uint8_t *buf, size_t cap)
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
        ssize_t n = read(in->fd, buf, cap);
        if (n > 0) {
            return input_keep_head(in, buf, (size_t)n);
        }
        if (n == 0 || errno == EIO) { /* EIO: a pty whose writer went away */
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
static bool input_is_text(const input_t *in)
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

/* What the start of an input that held no packet looks like. */
static const char *input_guess(const input_t *in, bool candump)
{
    size_t eol;
    const char *s = (const char *)in->head;
    tase_candump_rec_t rec;
    for (eol = 0; eol < in->nhead && s[eol] != '\n'; eol++) {
    }
    if (!candump && tase_candump_parse(s, eol, &rec) != TASE_EFORMAT) {
        return ": it looks like a candump log (add --candump)";
    }
    if (eol < in->nhead && strstr(s, "  [") != NULL && memchr(s, '[', eol) != NULL) {
        return ": it looks like candump's screen output; record a log with 'candump -L' "
               "(or -l) and decode it with --candump";
    }
    if (!candump && input_is_text(in)) {
        return ": it is text, not a raw serial capture";
    }
    if (candump) {
        return " (no frame of ID 10000000 or 11000000)";
    }
    return " (not a capture of a TASE serial line?)";
}

/* Read the first bytes of an input (at least 4 unless it ends) into buf;
 * returns how many. */
static size_t input_head(input_t *in, uint8_t *buf, size_t cap)
{
    size_t n = 0, k;
    while (n < 4 && (k = input_read(in, buf + n, cap - n)) > 0) {
        n += k;
    }
    return n;
}

/* Raw bytes; buf[0..n) holds the first ones, read already. */
static void decode_raw(input_t *in, tk_dec_t *d, uint8_t *buf, size_t cap, size_t n)
{
    tk_stream_t *s = tk_dec_stream(d, "", NULL);
    if (in->device) { /* a live line: the receiver's time bound applies */
        in->dec = d;
        in->st = s;
    }
    while (n > 0) {
        tk_dec_bytes(d, s, buf, n, NULL);
        if (in->device) {
            tk_dec_tick(d, s, in->port.ops->now_ms(in->port.ctx));
        }
        tk_stdout_flush(); /* a live input's frames go out as they come */
        n = input_read(in, buf, cap);
    }
}

/* A pcap/pcapng capture of 'tase record' (tk_capture.h), whose first bytes
 * are head[0..n): serial records go to the stream of their direction, CAN
 * frames as in a candump log. Returns the number of bad records. */
static unsigned long decode_capture(input_t *in, tk_dec_t *d, const uint8_t *head, size_t n)
{
    tk_cap_reader_t r;
    tk_cap_rec_t rec;
    unsigned long bad = 0;
    char why[160];
    int rc;
    tk_cap_reader_open(&r, in->fd, head, n, in->name);
    while ((rc = tk_cap_next(&r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_BAD) {
            if (++bad <= BAD_LINES_SHOWN) {
                tk_warn("%s: record %lu skipped: %s", in->name, rec.index, why);
            }
        } else if (r.linktype == TK_CAP_LINKTYPE_SERIAL) {
            tk_stream_t *s = tk_dec_stream(d, "", rec.dir == TK_CAP_FROM_GIMBAL ? "out" : "in");
            tk_dec_bytes(d, s, rec.data, rec.len, &rec.t);
        } else if (rec.can_data) {
            (void)tk_dec_can(d, "", &rec.frame, &rec.t); /* one interface: no name */
        }
        tk_exit_if_signalled();
    }
    tk_cap_reader_close(&r);
    if (bad > BAD_LINES_SHOWN) {
        tk_warn("%s: %lu more bad records not shown", in->name, bad - BAD_LINES_SHOWN);
    }
    return bad;
}

typedef struct {
    input_t *in;
    tk_dec_t *d;
    unsigned long lineno;
    unsigned long bad;
} candump_t;

static void candump_bad(candump_t *c, const char *why)
{
    c->bad++;
    if (c->bad <= BAD_LINES_SHOWN) {
        tk_warn("%s:%lu: not a candump log line%s", c->in->name, c->lineno, why);
    }
}

static void candump_line(candump_t *c, const char *line, size_t len, bool overlong)
{
    tase_candump_rec_t rec;
    tk_time_t t;
    size_t k;
    int rc;
    c->lineno++;
    if (len > 0 && line[len - 1] == '\r') {
        len--;
    }
    for (k = 0; k < len && (line[k] == ' ' || line[k] == '\t'); k++) {
    }
    if (overlong) {
        candump_bad(c, " (too long)");
        return;
    }
    if (k == len || line[k] == '#') {
        return; /* blank line or comment */
    }
    rc = tase_candump_parse(line, len, &rec);
    if (rc == TASE_EUNSUPPORTED) {
        return; /* remote, FD or error frames carry no datalink bytes */
    }
    if (rc != TASE_OK) {
        candump_bad(c, memchr(line, '\0', len) != NULL
                           ? " (it holds a NUL byte)"
                           : (memchr(line, '[', len) != NULL && memchr(line, '#', len) == NULL
                                  ? " (candump's screen output? record a log with 'candump -L')"
                                  : ""));
        return;
    }
    t.sec = (int64_t)rec.sec;
    t.usec = rec.usec;
    if (!tk_dec_can(c->d, rec.ifname, &rec.frame, &t)) {
        tk_die("%s:%lu: too many CAN interfaces (at most %u)", c->in->name, c->lineno,
               TK_STREAMS_MAX / 2u);
    }
}

/* Returns the number of bad lines. */
static unsigned long decode_candump(input_t *in, tk_dec_t *d)
{
    static uint8_t buf[READ_CHUNK];
    static char line[1024]; /* a log line is at most 73 bytes; anything longer is bad */
    candump_t c = {in, d, 0, 0};
    size_t nline = 0, n, i;
    bool overlong = false;
    while ((n = input_read(in, buf, sizeof(buf))) > 0) {
        for (i = 0; i < n; i++) {
            if (buf[i] != '\n') {
                if (nline < sizeof(line)) {
                    line[nline++] = (char)buf[i];
                } else {
                    overlong = true;
                }
                continue;
            }
            candump_line(&c, line, nline, overlong);
            nline = 0;
            overlong = false;
        }
        tk_stdout_flush(); /* a live input's frames go out as they come */
    }
    if (nline > 0 || overlong) {
        candump_line(&c, line, nline, overlong); /* a last line without a newline */
    }
    if (c.bad > BAD_LINES_SHOWN) {
        tk_warn("%s: %lu more bad lines not shown", in->name, c.bad - BAD_LINES_SHOWN);
    }
    return c.bad;
}

/* --baud given for an input that is no serial device */
static void input_check_baud(const input_t *in, bool baud_given, const char *or_capture)
{
    if (baud_given && !in->device) {
        tk_usage_error("--baud is for a serial device%s; %s is not one", or_capture, in->name);
    }
}

static int cmd_decode(args_t *a)
{
    const char *path = NULL, *v;
    bool candump = false, stats = false, capture = false;
    unsigned long bad = 0;
    long baud = DEFAULT_BAUD;
    bool baud_given = false;
    input_t in;
    static tk_dec_t d;
    tk_fmt_t fmt = {true, false, true};
    while (a->i < a->argc) {
        if (common_opt(a)) {
            continue;
        }
        if (baud_opt(a, &baud)) {
            baud_given = true;
        } else if (opt(a, "--candump", false, &v)) {
            candump = true;
        } else if (opt(a, "--stats", false, &v)) {
            stats = true;
        } else if (path == NULL && is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    input_open(&in, path, baud);
    tk_stdout_buffered();
    tk_dec_init(&d, &fmt, stdout);
    /* a capture's record times are the receivers' clock: a gap in them
     * ends a held candidate as it did on the live line, at --baud */
    d.by_time = true;
    d.serial_rate = TASE_UART_BYTES_PER_S((uint32_t)baud);
    if (candump) {
        input_check_baud(&in, baud_given, " or a serial capture");
        bad = decode_candump(&in, &d);
    } else {
        static uint8_t buf[READ_CHUNK];
        /* a serial line carries raw bytes, never a capture file */
        size_t n =
            in.device ? input_read(&in, buf, sizeof(buf)) : input_head(&in, buf, sizeof(buf));
        if (!in.device && tk_cap_is_capture(buf, n)) {
            capture = true; /* --baud: the rate of its serial line */
            bad = decode_capture(&in, &d, buf, n);
        } else {
            input_check_baud(&in, baud_given, " or a serial capture");
            decode_raw(&in, &d, buf, sizeof(buf), n);
        }
    }
    tk_dec_finish(&d);
    input_close(&in);
    tk_stdout_flush();
    if (stats) {
        tk_dec_summary(&d, stderr, "");
    }
    input_check_end(&in);
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad %s%s (the rest was decoded)", in.name, bad,
                capture ? "record" : "line", bad == 1 ? "" : "s");
    }
    if (d.n.frames == 0 && in.nhead > 0) {
        tk_exit(TK_EXIT_INPUT, "no TASE packet found in %s%s", in.name, input_guess(&in, candump));
    }
    return TK_EXIT_OK;
}

/* ---- klv ---- */

typedef struct {
    uint64_t base64;
    uint32_t base32;
    uint64_t packets;
} klv_ctx_t;

/* What an input that held no KLV packet looks like. */
static const char *klv_guess(const input_t *in)
{
    static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};
    size_t i;
    if (input_is_text(in)) {
        return ": it is text, not a KLV byte stream";
    }
    if (tk_cap_is_capture(in->head, in->nhead)) {
        return ": it is a pcap capture ('tase decode' reads those)";
    }
    for (i = 0; i + 3u <= in->nhead; i++) {
        if (memcmp(in->head + i, sync, sizeof(sync)) == 0) {
            return ": it looks like the TASE datalink ('tase decode' reads that)";
        }
    }
    return " (not a capture of the gimbal's KLV line?)";
}

static void print_klv(void *user, uint32_t offset, const tase_klv_t *k)
{
    klv_ctx_t *c = user;
    c->packets++;
    printf("{\"offset\":%llu,\"fields\":{\"utc\":%llu,\"lat\":%ld,\"lon\":%ld,\"alt\":%u,"
           "\"pan\":%u,\"tilt\":%d,\"heading\":%u,\"pitch\":%d,\"roll\":%d,\"vnorth\":%d,"
           "\"veast\":%d,\"hfov\":%u,\"vfov\":%u,\"gps_status\":%u},",
           (unsigned long long)tk_offset64(c->base64, c->base32, offset),
           (unsigned long long)k->utc, (long)k->lat, (long)k->lon, (unsigned)k->alt,
           (unsigned)k->pan, (int)k->tilt, (unsigned)k->heading, (int)k->pitch, (int)k->roll,
           (int)k->vnorth, (int)k->veast, (unsigned)k->hfov, (unsigned)k->vfov,
           (unsigned)k->gps_status);
    printf("\"units\":{\"utc_s\":%.6f,\"lat_deg\":%.7f,\"lon_deg\":%.7f,\"alt_m\":%.2f,"
           "\"pan_deg\":%.3f,\"tilt_deg\":%.3f,\"heading_deg\":%.3f,\"pitch_deg\":%.4f,"
           "\"roll_deg\":%.4f,\"vnorth_mps\":%.3f,\"veast_mps\":%.3f,\"hfov_deg\":%.3f,"
           "\"vfov_deg\":%.3f,\"gps_fix\":%u,\"gps_antenna\":%u}}\n",
           tase_klv_utc_s(k->utc), tase_klv_lat_deg(k->lat), tase_klv_lon_deg(k->lon),
           tase_klv_alt_m(k->alt), tase_klv_angle_deg(k->pan), tase_klv_tilt_deg(k->tilt),
           tase_klv_angle_deg(k->heading), tase_klv_pitch_deg(k->pitch), tase_klv_roll_deg(k->roll),
           tase_klv_speed_mps(k->vnorth), tase_klv_speed_mps(k->veast), tase_klv_fov_deg(k->hfov),
           tase_klv_fov_deg(k->vfov), tase_klv_gps_fix(k->gps_status),
           tase_klv_gps_antenna(k->gps_status));
}

static int cmd_klv(args_t *a)
{
    const char *path = NULL;
    static tase_klv_rx_t rx;
    static uint8_t buf[READ_CHUNK];
    klv_ctx_t c = {0, 0, 0};
    long baud = KLV_BAUD;
    bool baud_given = false;
    input_t in;
    size_t n;
    while (a->i < a->argc) {
        if (common_opt(a)) {
            continue;
        }
        if (baud_opt(a, &baud)) {
            baud_given = true;
        } else if (path == NULL && is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    input_open(&in, path, baud);
    input_check_baud(&in, baud_given, "");
    tk_stdout_buffered();
    (void)tase_klv_rx_init(&rx);
    while ((n = input_read(&in, buf, sizeof(buf))) > 0) {
        c.base32 = rx.stats.bytes_in;
        (void)tase_klv_rx_feed(&rx, buf, n, print_klv, NULL, &c);
        c.base64 += n;
        tk_stdout_flush(); /* a live line's packets go out as they come */
    }
    c.base32 = rx.stats.bytes_in;
    (void)tase_klv_rx_flush(&rx, print_klv, NULL, &c);
    input_close(&in);
    tk_stdout_flush();
    input_check_end(&in);
    if (c.packets == 0 && in.nhead > 0) {
        tk_exit(TK_EXIT_INPUT, "no KLV packet found in %s%s", in.name, klv_guess(&in));
    }
    return TK_EXIT_OK;
}

/* ---- record / replay (tk_capture.c) ---- */

static int cmd_record(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    const char *out = NULL, *tap_in = NULL, *v;
    double seconds = 0.0;
    tk_cap_writer_t w;
    while (a->i < a->argc) {
        if (common_opt(a) || link_opt(a, &lo)) {
            continue;
        }
        if (opt(a, "-o", true, &v) || opt(a, "--output", true, &v)) {
            if (out != NULL) {
                tk_usage_error("option -o/--output given twice");
            }
            out = v;
            continue;
        }
        if (opt(a, "--tap-in", true, &tap_in)) {
            continue;
        }
        if (opt(a, "--seconds", true, &v)) {
            if (tk_parse_seconds(v, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", v);
            }
        } else {
            bad_arg(a);
        }
    }
    if (lo.record != NULL) {
        tk_usage_error("record writes its capture with -o FILE (--record is for the other "
                       "commands)");
    }
    if (out == NULL) {
        tk_usage_error("record needs an output file: -o FILE");
    }
    if ((lo.serial != NULL) == (lo.can != NULL)) {
        tk_usage_error("give either --serial DEV or --can IFACE");
    }
    if (tap_in != NULL && lo.serial == NULL) {
        tk_usage_error("--tap-in is the second line of a serial tap: it needs --serial");
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

static int cmd_replay(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    tk_replay_opts_t ro;
    const char *path = NULL, *v;
    static uint8_t head[READ_CHUNK];
    unsigned long bad, backward;
    tk_cap_reader_t r;
    input_t in;
    size_t n;
    memset(&ro, 0, sizeof(ro));
    ro.speed = 1.0;
    ro.dirs = (tk_cap_dirs_t)0; /* no default: --dir is required */
    while (a->i < a->argc) {
        if (common_opt(a) || link_opt(a, &lo)) {
            continue;
        }
        if (opt(a, "--speed", true, &v)) {
            if (tk_parse_seconds(v, &ro.speed) != 0) {
                tk_usage_error("bad --speed value '%s' (a factor: 1 recorded timing, 2 twice as "
                               "fast, 0 no waiting)",
                               v);
            }
        } else if (opt(a, "--dir", true, &v)) {
            if (strcmp(v, "out") == 0) {
                ro.dirs = TK_CAP_DIR_OUT;
            } else if (strcmp(v, "in") == 0) {
                ro.dirs = TK_CAP_DIR_IN;
            } else if (strcmp(v, "all") == 0) {
                ro.dirs = TK_CAP_DIR_ALL;
            } else {
                tk_usage_error("bad --dir value '%s' (out, in or all)", v);
            }
        } else if (path == NULL && is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            bad_arg(a);
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
    if (ro.dirs == 0) {
        tk_usage_error("replay needs --dir: out = the gimbal's side, to exercise a host (its "
                       "echoes are commands to a gimbal); in = the host's commands (moves a "
                       "gimbal); all = both (moves a gimbal)");
    }
    input_open(&in, path, 0);
    n = input_head(&in, head, sizeof(head));
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
        tk_die("%s: replay reads its capture twice (checked before anything is sent): give a "
               "file, not a pipe",
               in.name);
    }
    tk_cap_reader_open(&r, in.fd, NULL, 0, in.name);
    bad = tk_cap_check(&r, &ro, &backward);
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
    input_close(&in);
    tk_exit_if_signalled();
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad record%s skipped", in.name, bad, bad == 1 ? "" : "s");
    }
    return TK_EXIT_OK;
}

/* ---- list ---- */

static int cmd_list(args_t *a)
{
    size_t i;
    unsigned j;
    while (a->i < a->argc) {
        if (!common_opt(a)) {
            bad_arg(a);
        }
    }
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        unsigned dir = p->flags & TASE_DIR_BOTH;
        printf("%-19s 0x%02X/0x%02X %-4s %3u%s%s:", tase_schema_packet_name(p),
               (unsigned)TASE_ID_GROUP(p->id), (unsigned)TASE_ID_TYPE(p->id),
               dir == TASE_DIR_BOTH ? "both" : (dir == TASE_DIR_IN ? "in" : "out"),
               (unsigned)p->len, tk_packet_has_tail(p) ? "+" : "",
               (p->flags & TASE_LEN_QUERY) ? " (query)" : "");
        for (j = 0; j < p->nfields; j++) {
            tk_field_t f;
            tk_field(p, j, p->len, &f);
            printf(" %s:%c%u", f.name, f.is_signed ? 's' : 'u', 8u * f.width);
        }
        printf("%s\n", tk_packet_has_tail(p) ? " data:bytes" : "");
    }
    tk_stdout_flush();
    return TK_EXIT_OK;
}

/* ---- main ---- */

typedef struct {
    const char *name;
    int (*run)(args_t *);
    const char *usage;
    unsigned extra; /* USAGE_* */
    const char *summary;
} command_t;

/* One row per command: add a row to add a command. */
static const command_t commands[] = {
    {"point", cmd_point, usage_point, USAGE_LINK, "point at pan/tilt angles (degrees)"},
    {"rate", cmd_rate, usage_rate, USAGE_LINK, "turn at pan/tilt rates (degrees per second)"},
    {"camera", cmd_camera, usage_camera, USAGE_LINK | USAGE_REQ,
     "select a camera, set its HFOV or zoom"},
    {"gyro-zero", cmd_gyro_zero, usage_gyro, USAGE_LINK, "zero the gimbal's rate gyros"},
    {"deploy", cmd_deploy, usage_deploy, USAGE_LINK, "deploy the retract/deploy mechanism"},
    {"retract", cmd_retract, usage_deploy, USAGE_LINK, "retract it"},
    {"spoi", cmd_spoi, usage_spoi, USAGE_LINK | USAGE_REQ,
     "point at a location (latitude, longitude, height)"},
    {"send", cmd_send, usage_send, USAGE_LINK | USAGE_REQ,
     "send any In packet, fields as raw wire integers"},
    {"query", cmd_query, usage_query, USAGE_LINK | USAGE_REQ,
     "ask for a setup packet, SPOI_CMD or SYSTEM_VERSION"},
    {"monitor", cmd_monitor, usage_monitor, USAGE_LINK, "print the packets a live link receives"},
    {"decode", cmd_decode, usage_decode, 0,
     "decode a capture (pcap, raw bytes, candump log) to JSON"},
    {"klv", cmd_klv, usage_klv, 0, "decode a KLV metadata byte stream to JSON"},
    {"record", cmd_record, usage_record, 0, "record a serial line or CAN bus to a pcap capture"},
    {"replay", cmd_replay, usage_replay, 0, "send a capture back with its recorded timing"},
    {"list", cmd_list, usage_list, 0, "list the packets and their field names"},
};

#define NCOMMANDS (sizeof(commands) / sizeof(commands[0]))

static void main_usage(void)
{
    size_t i;
    printf("usage: tase <command> [options]   (tase help <command>, tase <command> --help)\n"
           "commands:\n");
    for (i = 0; i < NCOMMANDS; i++) {
        printf("  %-10s %s\n", commands[i].name, commands[i].summary);
    }
    printf("LINK is --serial DEV [--baud N] or --can IFACE. Angles are degrees, values of\n"
           "'send' raw wire integers. tase --version prints the version.\n");
    fputs(usage_exit, stdout);
    tk_stdout_flush();
}

static const command_t *find_command(const char *name)
{
    size_t i;
    for (i = 0; i < NCOMMANDS; i++) {
        if (strcmp(name, commands[i].name) == 0) {
            return &commands[i];
        }
    }
    tk_usage_error("unknown command '%s' (try 'tase --help')", name);
    return NULL;
}

int main(int argc, char **argv)
{
    const command_t *c;
    args_t a;
    tk_prog = "tase";
    tk_catch_signals();
    if (argc < 2) {
        tk_usage_error("no command given (try 'tase --help')");
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        (strcmp(argv[1], "help") == 0 && argc == 2)) {
        main_usage();
        return TK_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("tase %s\n", TASE_VERSION_STRING);
        tk_stdout_flush();
        return TK_EXIT_OK;
    }
    memset(&a, 0, sizeof(a));
    a.argc = argc;
    a.argv = argv;
    if (strcmp(argv[1], "help") == 0) {
        if (argc > 3) {
            tk_usage_error("help takes one command name");
        }
        c = find_command(argv[2]);
        a.usage = c->usage;
        a.extra = c->extra;
        print_usage(&a);
        return TK_EXIT_OK;
    }
    c = find_command(argv[1]);
    a.i = 2;
    a.usage = c->usage;
    a.extra = c->extra;
    return c->run(&a);
}
