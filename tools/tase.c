/* tase: talk to a TASE gimbal (or tase-sim) and decode captures.
 * Usage and the JSON contract: docs/TOOLS.md, or `tase --help`. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "tase/candump.h"
#include "tase/host.h"
#include "tase/klv.h"
#include "tk_capture.h"
#include "toolkit.h"

#define DEFAULT_BAUD 57600L

static const char usage_main[] =
    "usage: tase <command> [options]   (tase <command> --help for details)\n"
    "commands:\n"
    "  monitor  print decoded packets from a live link\n"
    "  send     send one packet with fields from the command line\n"
    "  query    zero-length query of a setup packet, SPOI_CMD or SYSTEM_VERSION\n"
    "  decode   decode a raw serial capture or a candump log to JSON lines\n"
    "  klv      decode a KLV metadata byte stream to JSON lines\n"
    "  record   record a serial line or a CAN bus to a pcap capture with timestamps\n"
    "  replay   send a capture back to a serial device or CAN interface with its timing\n"
    "  list     list the packets and their field names\n";

static const char usage_link[] =
    "link options:\n"
    "  --serial DEV   serial device or pty (e.g. /dev/ttyUSB0, the path tase-sim prints)\n"
    "  --baud N       serial rate, default 57600\n"
    "  --can IFACE    CAN interface instead of a serial device (e.g. can0)\n"
    "  --record FILE  also record the session's bytes, both directions, to the pcap\n"
    "                 capture FILE (appended to; serial links only: on CAN run\n"
    "                 'tase record --can IFACE' beside it)\n";

static const char usage_monitor[] =
    "usage: tase monitor (--serial DEV [--baud N] | --can IFACE) [--json] [--count N]\n"
    "                    [--seconds S]\n"
    "Prints every packet received, one per line: human-readable by default,\n"
    "one JSON object per line with --json. Stops after N packets or S seconds\n"
    "(default: runs until interrupted).\n";

static const char usage_send[] =
    "usage: tase send NAME [field=value ...] (--serial DEV [--baud N] | --can IFACE)\n"
    "                 [--len N] [--zero] [--no-wait] [--json] [--timeout MS] [--retries N]\n"
    "Sends packet NAME (an In or Both packet; see 'tase list') with raw integer\n"
    "field values (decimal, 0x hex, negative). CAMERA_PASS takes data=1,2,... .\n"
    "Fields not given are 0, except for setup packets (group 0x48): their current\n"
    "settings are queried first and only the given fields change (--zero: start\n"
    "from zeros). The gimbal echoes setup packets: the echo is awaited and printed\n"
    "(--no-wait: do not wait). --len N sends a shorter accepted form (CAMERA_CMD 1).\n";

static const char usage_query[] =
    "usage: tase query NAME (--serial DEV [--baud N] | --can IFACE) [--json]\n"
    "                  [--timeout MS] [--retries N]\n"
    "Sends the zero-length query of NAME (a setup packet, SPOI_CMD or\n"
    "SYSTEM_VERSION), waits for the answer (default 500 ms per attempt, 2 retries)\n"
    "and prints it.\n";

static const char usage_decode[] =
    "usage: tase decode [FILE|-] [--candump]\n"
    "Decodes a raw serial byte capture (default: standard input) to one JSON\n"
    "object per valid packet, in stream order (contract: docs/TOOLS.md). With\n"
    "--candump the input is a candump log: frames of ID 10000000 (from the gimbal,\n"
    "\"dir\":\"out\") and 11000000 (to the gimbal, \"dir\":\"in\") are reassembled per\n"
    "direction; other IDs are ignored.\n";

static const char usage_klv[] =
    "usage: tase klv [FILE|-]\n"
    "Decodes a KLV metadata byte stream (the gimbal's 9600-baud KLV line) to one\n"
    "JSON object per valid packet: {\"offset\":N,\"fields\":{raw values in tag order},\n"
    "\"units\":{engineering values}}. Noise and damaged packets are skipped.\n";

static const char usage_record[] =
    "usage: tase record (--serial DEV [--tap-in DEV2] [--baud N] | --can IFACE) -o FILE\n"
    "                   [--seconds S]\n"
    "Records what arrives to the pcap capture FILE (replaced), with a timestamp per\n"
    "received chunk, until interrupted (Ctrl-C) or S seconds have passed.\n"
    "  --serial DEV   one record per read, byte-exact, as sent by the gimbal\n"
    "                 (link type USER0 with a direction byte; docs/TOOLS.md)\n"
    "  --tap-in DEV2  a second device on the other line of a tap: its bytes are\n"
    "                 recorded as sent to the gimbal\n"
    "  --can IFACE    every frame on the bus, as SocketCAN records (LINKTYPE_CAN_SOCKETCAN)\n"
    "'tase decode FILE' decodes it; Wireshark reads it (tools/wireshark/tase.lua).\n";

static const char usage_replay[] =
    "usage: tase replay FILE (--serial DEV [--baud N] | --can IFACE) [--speed X]\n"
    "                   [--dir out|in|all]\n"
    "Sends the records of the pcap capture FILE with their recorded timing (divided\n"
    "by X, default 1; 0 sends without waiting).\n"
    "  --dir out   what the gimbal sent (the default: plays the gimbal's side)\n"
    "  --dir in    what was sent to the gimbal (commands: moves a real gimbal)\n"
    "  --dir all   both; on CAN every recorded frame, whatever its ID\n"
    "Serial bytes go to a CAN interface as frames of their direction's ID, and the\n"
    "datalink bytes of CAN frames to a serial device; CAN FD, remote and error\n"
    "frames are skipped.\n";

static const char usage_list[] = "usage: tase list\nLists every packet: group, type, "
                                 "direction, data length and field names.\n";

/* ---- command-line parsing ---- */

typedef struct {
    int argc;
    char **argv;
    int i;
    const char *usage;
} args_t;

typedef struct {
    const char *serial;
    const char *can;
    long baud;
    const char *record; /* --record FILE, or NULL */
} link_opts_t;

/* If argv[i] is option `name` (with "--name V" or "--name=V" when has_arg),
 * consume it and return true; *val gets the value. */
static bool opt(args_t *a, const char *name, bool has_arg, const char **val)
{
    const char *s = a->argv[a->i];
    size_t n = strlen(name);
    if (strncmp(s, name, n) != 0) {
        return false;
    }
    if (s[n] == '\0') {
        if (has_arg) {
            if (a->i + 1 >= a->argc) {
                tk_usage_error("option %s needs a value", name);
            }
            *val = a->argv[++a->i];
        }
        a->i++;
        return true;
    }
    if (s[n] == '=' && has_arg) {
        *val = s + n + 1;
        a->i++;
        return true;
    }
    return false;
}

static bool help_opt(args_t *a)
{
    const char *s = a->argv[a->i];
    if (strcmp(s, "--help") == 0 || strcmp(s, "-h") == 0) {
        fputs(a->usage, stdout);
        if (a->usage == usage_monitor || a->usage == usage_send || a->usage == usage_query) {
            fputs(usage_link, stdout);
        }
        exit(0);
    }
    return false;
}

static bool link_opt(args_t *a, link_opts_t *l)
{
    const char *v;
    long long n;
    if (opt(a, "--serial", true, &l->serial) || opt(a, "--can", true, &l->can) ||
        opt(a, "--record", true, &l->record)) {
        return true;
    }
    if (opt(a, "--baud", true, &v)) {
        if (tk_parse_int(v, 1, 4000000, &n) != 0) {
            tk_usage_error("bad --baud value '%s'", v);
        }
        l->baud = (long)n;
        return true;
    }
    return false;
}

static long long int_opt_value(const char *name, const char *v, long long min, long long max)
{
    long long n;
    if (tk_parse_int(v, min, max, &n) != 0) {
        tk_usage_error("bad %s value '%s' (expected an integer %lld..%lld)", name, v, min, max);
    }
    return n;
}

static void bad_arg(const args_t *a)
{
    const char *s = a->argv[a->i];
    if (s[0] == '-' && s[1] != '\0') {
        tk_usage_error("unknown option '%s' (see --help)", s);
    }
    tk_usage_error("unexpected argument '%s' (see --help)", s);
}

static void open_link(const link_opts_t *lo, tk_link_t *l, tase_port_t *port)
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

/* ---- output of received frames ---- */

typedef struct {
    bool json;
    long count; /* frames printed */
    long limit; /* 0: no limit */
    const char *dir;
    char time[32]; /* JSON "time" of the record being fed ("": none) */
} printer_t;

static void print_frame(void *user, const tase_frame_t *f)
{
    printer_t *pr = user;
    if (pr->limit > 0 && pr->count >= pr->limit) {
        return;
    }
    if (pr->json) {
        tk_json_frame(stdout, f, pr->dir, pr->time[0] != '\0' ? pr->time : NULL);
    } else {
        tk_text_frame(stdout, f);
    }
    fflush(stdout);
    pr->count++;
}

/* ---- monitor ---- */

static int cmd_monitor(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    printer_t pr = {false, 0, 0, NULL, ""};
    double seconds = 0.0, t_end;
    const char *v;
    tk_link_t link;
    tase_port_t port;
    tase_host_t h;
    while (a->i < a->argc) {
        if (help_opt(a) || link_opt(a, &lo)) {
            continue;
        }
        if (opt(a, "--json", false, &v)) {
            pr.json = true;
        } else if (opt(a, "--count", true, &v)) {
            pr.limit = (long)int_opt_value("--count", v, 1, 1000000000);
        } else if (opt(a, "--seconds", true, &v)) {
            if (tk_parse_seconds(v, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", v);
            }
        } else {
            bad_arg(a);
        }
    }
    open_link(&lo, &link, &port);
    tase_host_init(&h, &port, print_frame, &pr);
    t_end = tk_now_s() + seconds;
    while ((pr.limit == 0 || pr.count < pr.limit) && (seconds == 0.0 || tk_now_s() < t_end)) {
        int rc = tase_host_service(&h, 50);
        if (rc < 0) {
            tk_die("link read failed: %s", tase_strerror(rc));
        }
    }
    tk_link_close(&link);
    return 0;
}

/* ---- send / query ---- */

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

/* Wait for the answer to a request; dies with the reason on failure. */
static int transact(tase_host_t *h, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                    uint8_t *reply, const req_opts_t *r)
{
    int rc = tase_host_transact(h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len, reply,
                                TASE_DATA_MAX, r->timeout_ms, r->retries);
    if (rc == TASE_ETIMEOUT) {
        tk_die("timeout: no answer to %s after %u attempt%s of %lu ms", tase_schema_packet_name(p),
               (unsigned)r->retries + 1u, r->retries ? "s" : "", (unsigned long)r->timeout_ms);
    }
    if (rc < 0) {
        tk_die("%s request failed: %s", tase_schema_packet_name(p), tase_strerror(rc));
    }
    return rc;
}

static void print_reply(const tase_packet_desc_t *p, const uint8_t *reply, int len,
                        const req_opts_t *r)
{
    tase_frame_t f;
    printer_t pr = {r->json, 0, 0, NULL, ""};
    f.offset = 0;
    f.group = TASE_ID_GROUP(p->id);
    f.type = TASE_ID_TYPE(p->id);
    f.len = (uint8_t)len;
    f.data = reply;
    print_frame(&pr, &f);
}

static int cmd_query(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    req_opts_t r = {500, 2, false};
    const char *name = NULL;
    const tase_packet_desc_t *p;
    tk_link_t link;
    tase_port_t port;
    tase_host_t h;
    uint8_t reply[TASE_DATA_MAX];
    int n;
    while (a->i < a->argc) {
        if (help_opt(a) || link_opt(a, &lo) || req_opt(a, &r)) {
            continue;
        }
        if (a->argv[a->i][0] != '-' && name == NULL) {
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
    open_link(&lo, &link, &port);
    tase_host_init(&h, &port, NULL, NULL);
    n = transact(&h, p, NULL, 0, reply, &r);
    print_reply(p, reply, n, &r);
    tk_link_close(&link);
    return 0;
}

static size_t parse_tail(const char *v, uint8_t *out, size_t cap)
{
    size_t n = 0;
    char buf[1024];
    char *tok, *save = NULL;
    if (strlen(v) >= sizeof(buf)) {
        tk_usage_error("data list too long");
    }
    strcpy(buf, v);
    for (tok = strtok_r(buf, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save)) {
        long long b;
        if (n >= cap) {
            tk_usage_error("too many data bytes (at most %lu)", (unsigned long)cap);
        }
        if (tk_parse_int(tok, 0, 255, &b) != 0) {
            tk_usage_error("bad data byte '%s' (expected 0..255)", tok);
        }
        out[n++] = (uint8_t)b;
    }
    return n;
}

static int cmd_send(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    req_opts_t r = {500, 2, false};
    const char *name = NULL, *v;
    const char *assign[64];
    size_t nassign = 0, i, len, tail = 0;
    long long forced_len = -1;
    bool zero = false, no_wait = false, setup;
    const tase_packet_desc_t *p;
    uint8_t data[TASE_DATA_MAX], reply[TASE_DATA_MAX];
    tk_link_t link;
    tase_port_t port;
    tase_host_t h;
    int rc;
    memset(data, 0, sizeof(data));
    while (a->i < a->argc) {
        if (help_opt(a) || link_opt(a, &lo) || req_opt(a, &r)) {
            continue;
        }
        if (opt(a, "--zero", false, &v)) {
            zero = true;
        } else if (opt(a, "--no-wait", false, &v)) {
            no_wait = true;
        } else if (opt(a, "--len", true, &v)) {
            forced_len = int_opt_value("--len", v, 0, TASE_DATA_MAX);
        } else if (a->argv[a->i][0] != '-' && name == NULL) {
            name = a->argv[a->i++];
        } else if (a->argv[a->i][0] != '-' && strchr(a->argv[a->i], '=') != NULL) {
            if (nassign == sizeof(assign) / sizeof(assign[0])) {
                tk_usage_error("too many field assignments");
            }
            assign[nassign++] = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    if (name == NULL) {
        tk_usage_error("send needs a packet name (e.g. GIMBAL_CMD)");
    }
    p = tk_packet_by_name(name);
    if ((p->flags & TASE_DIR_IN) == 0) {
        tk_usage_error("%s is sent by the gimbal, not to it", tase_schema_packet_name(p));
    }
    if (p->id == TASE_ID_SYSTEM_VERSION) {
        tk_usage_error("SYSTEM_VERSION is query-only: use 'tase query SYSTEM_VERSION'");
    }
    setup = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP;
    /* check every assignment before touching the link */
    for (i = 0; i < nassign; i++) {
        const char *eq = strchr(assign[i], '=');
        char fname[64];
        size_t fl = (size_t)(eq - assign[i]);
        int fi;
        tk_field_t fd;
        long long val;
        if (fl == 0 || fl >= sizeof(fname)) {
            tk_usage_error("bad assignment '%s' (expected field=value)", assign[i]);
        }
        memcpy(fname, assign[i], fl);
        fname[fl] = '\0';
        if (tk_packet_has_tail(p) && strcmp(fname, "data") == 0) {
            tail = parse_tail(eq + 1, data + p->len, TASE_DATA_MAX - p->len);
            continue;
        }
        fi = tase_schema_field_index(p, fname);
        if (fi < 0) {
            tk_usage_error("%s has no field '%s' (see 'tase list')", tase_schema_packet_name(p),
                           fname);
        }
        tk_field(p, (unsigned)fi, &fd);
        if (tk_parse_int(eq + 1, INT64_MIN, INT64_MAX, &val) != 0 ||
            tk_field_set(&fd, data, val) != 0) {
            tk_usage_error("bad value '%s' for %s.%s (%s %u-bit integer)", eq + 1,
                           tase_schema_packet_name(p), fname, fd.is_signed ? "signed" : "unsigned",
                           8u * fd.width);
        }
    }
    len = forced_len >= 0 ? (size_t)forced_len : p->len + tail;
    if (!tase_schema_length_ok(p, len)) {
        tk_usage_error("%s does not accept a data length of %lu", tase_schema_packet_name(p),
                       (unsigned long)len);
    }
    open_link(&lo, &link, &port);
    tase_host_init(&h, &port, NULL, NULL);
    if (setup && !zero && len > 0) {
        /* read-modify-write: unspecified fields keep the gimbal's values */
        uint8_t cur[TASE_DATA_MAX], mine[TASE_DATA_MAX];
        int n = transact(&h, p, NULL, 0, cur, &r);
        if ((size_t)n != p->len) {
            tk_die("%s query answered with %d bytes, expected %u", tase_schema_packet_name(p), n,
                   (unsigned)p->len);
        }
        memcpy(mine, data, p->len);
        memcpy(data, cur, p->len);
        for (i = 0; i < nassign; i++) {
            char fname[64];
            size_t fl = (size_t)(strchr(assign[i], '=') - assign[i]);
            tk_field_t fd;
            memcpy(fname, assign[i], fl);
            fname[fl] = '\0';
            tk_field(p, (unsigned)tase_schema_field_index(p, fname), &fd);
            memcpy(data + fd.offset, mine + fd.offset, fd.width);
        }
    }
    if (setup && !no_wait) {
        int n = transact(&h, p, data, len, reply, &r);
        print_reply(p, reply, n, &r);
    } else {
        rc = tase_host_send(&h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len);
        if (rc < 0) {
            tk_die("cannot send %s: %s", tase_schema_packet_name(p), tase_strerror(rc));
        }
        if (!r.json) {
            printf("sent %s (%lu data bytes)\n", tase_schema_packet_name(p), (unsigned long)len);
        }
    }
    tk_link_close(&link);
    return 0;
}

/* ---- decode ---- */

static FILE *open_input(const char *path)
{
    FILE *f;
    if (path == NULL || strcmp(path, "-") == 0) {
        return stdin;
    }
    f = fopen(path, "rb");
    if (f == NULL) {
        tk_die("cannot open %s: %s", path, strerror(errno));
    }
    return f;
}

/* When `in` is a pcap or pcapng capture, open a reader over it and return
 * true; otherwise return false with the (up to 4) bytes read in head. */
static bool open_capture(FILE *in, const char *path, tk_cap_reader_t *r, uint8_t *head,
                         size_t *nhead)
{
    *nhead = fread(head, 1, 4, in);
    if (!tk_cap_is_capture(head, *nhead)) {
        return false;
    }
    tk_cap_reader_open(r, in, head, *nhead, path);
    return true;
}

/* Feed a CAN frame of a capture to the receiver of its direction (other
 * IDs are ignored), with the record's time for the JSON. */
static void feed_can_frame(tase_can_rx_t *from_gimbal, tase_can_rx_t *to_gimbal, printer_t *out_pr,
                           printer_t *in_pr, const tase_can_frame_t *f, const tk_time_t *t,
                           unsigned digits)
{
    if (tase_can_accept(TASE_CAN_ROLE_HOST, f) > 0) {
        tk_time_format(out_pr->time, sizeof(out_pr->time), t, digits);
        (void)tase_can_rx_feed(from_gimbal, f, print_frame, out_pr);
    } else if (tase_can_accept(TASE_CAN_ROLE_GIMBAL, f) > 0) {
        tk_time_format(in_pr->time, sizeof(in_pr->time), t, digits);
        (void)tase_can_rx_feed(to_gimbal, f, print_frame, in_pr);
    }
}

/* A pcap/pcapng capture of tase record: serial records go to one receiver
 * per direction, CAN records as in a candump log. Returns the number of
 * malformed records (reported and skipped). */
static unsigned long decode_capture(tk_cap_reader_t *r)
{
    tase_can_rx_t from_gimbal, to_gimbal;
    tase_rx_t serial[2]; /* indexed by the direction byte */
    printer_t out_pr = {true, 0, 0, "out", ""}, in_pr = {true, 0, 0, "in", ""};
    printer_t *prs[2] = {&out_pr, &in_pr};
    unsigned long bad = 0;
    tk_cap_rec_t rec;
    char why[160];
    int rc;
    tase_can_rx_init(&from_gimbal, TASE_CAN_ROLE_HOST);
    tase_can_rx_init(&to_gimbal, TASE_CAN_ROLE_GIMBAL);
    tase_rx_init(&serial[TK_CAP_FROM_GIMBAL]);
    tase_rx_init(&serial[TK_CAP_TO_GIMBAL]);
    while ((rc = tk_cap_next(r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_BAD) {
            fprintf(stderr, "%s: %s: record %lu skipped: %s\n", tk_prog, r->path, rec.index, why);
            bad++;
        } else if (r->linktype == TK_CAP_LINKTYPE_SERIAL) {
            tk_time_format(prs[rec.dir]->time, sizeof(prs[rec.dir]->time), &rec.t, 9);
            tase_rx_feed(&serial[rec.dir], rec.data, rec.len, print_frame, prs[rec.dir]);
        } else if (rec.can_data) {
            feed_can_frame(&from_gimbal, &to_gimbal, &out_pr, &in_pr, &rec.frame, &rec.t, 9);
        }
    }
    if (r->linktype == TK_CAP_LINKTYPE_SERIAL) {
        tase_rx_flush(&serial[TK_CAP_TO_GIMBAL], print_frame, &in_pr);
        tase_rx_flush(&serial[TK_CAP_FROM_GIMBAL], print_frame, &out_pr);
    } else {
        tase_rx_flush(&to_gimbal.rx, print_frame, &in_pr);
        tase_rx_flush(&from_gimbal.rx, print_frame, &out_pr);
    }
    return bad;
}

static void decode_candump(FILE *in, const char *path)
{
    /* from the gimbal: what a host receives; to the gimbal: what a gimbal
     * receives */
    tase_can_rx_t from_gimbal, to_gimbal;
    printer_t out_pr = {true, 0, 0, "out", ""}, in_pr = {true, 0, 0, "in", ""};
    char line[512];
    unsigned long lineno = 0;
    tase_can_rx_init(&from_gimbal, TASE_CAN_ROLE_HOST);
    tase_can_rx_init(&to_gimbal, TASE_CAN_ROLE_GIMBAL);
    while (fgets(line, sizeof(line), in) != NULL) {
        tase_candump_rec_t rec;
        size_t n = strlen(line);
        int rc;
        lineno++;
        if (n > 0 && line[n - 1] != '\n' && !feof(in)) {
            tk_die("%s:%lu: line too long for a candump log", path, lineno);
        }
        if (n == 0 || line[0] == '\n' || (line[0] == '\r' && line[1] == '\n')) {
            continue;
        }
        rc = tase_candump_parse(line, n, &rec);
        if (rc == TASE_EUNSUPPORTED) {
            continue; /* remote, FD or error frames carry no datalink bytes */
        }
        if (rc != TASE_OK) {
            tk_die("%s:%lu: not a candump log line", path, lineno);
        }
        tk_time_t t = {(int64_t)rec.sec, rec.usec * 1000u};
        feed_can_frame(&from_gimbal, &to_gimbal, &out_pr, &in_pr, &rec.frame, &t, 6);
    }
    if (ferror(in)) {
        tk_die("cannot read %s: %s", path, strerror(errno));
    }
    tase_rx_flush(&to_gimbal.rx, print_frame, &in_pr);
    tase_rx_flush(&from_gimbal.rx, print_frame, &out_pr);
}

static int cmd_decode(args_t *a)
{
    const char *path = NULL, *v;
    bool candump = false;
    FILE *in;
    while (a->i < a->argc) {
        if (help_opt(a)) {
            continue;
        }
        if (opt(a, "--candump", false, &v)) {
            candump = true;
        } else if (path == NULL && (a->argv[a->i][0] != '-' || a->argv[a->i][1] == '\0')) {
            path = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    in = open_input(path);
    if (path == NULL || strcmp(path, "-") == 0) {
        path = "standard input";
    }
    if (candump) {
        decode_candump(in, path);
    } else {
        printer_t pr = {true, 0, 0, NULL, ""};
        tase_rx_t rx;
        tk_cap_reader_t r;
        uint8_t buf[4096];
        size_t n;
        if (open_capture(in, path, &r, buf, &n)) {
            unsigned long bad = decode_capture(&r);
            tk_cap_reader_close(&r);
            if (bad > 0) {
                tk_die("%s: %lu malformed record%s skipped", path, bad, bad == 1 ? "" : "s");
            }
            return 0;
        }
        tase_rx_init(&rx);
        tase_rx_feed(&rx, buf, n, print_frame, &pr); /* the bytes open_capture() looked at */
        while ((n = fread(buf, 1, sizeof(buf), in)) > 0) {
            tase_rx_feed(&rx, buf, n, print_frame, &pr);
        }
        if (ferror(in) && errno != EIO) { /* EIO: a pty whose writer went away */
            tk_die("cannot read %s: %s", path, strerror(errno));
        }
        tase_rx_flush(&rx, print_frame, &pr);
    }
    if (in != stdin) {
        fclose(in);
    }
    return 0;
}

/* ---- klv ---- */

static void print_klv(void *user, uint32_t offset, const tase_klv_t *k)
{
    (void)user;
    printf("{\"offset\":%lu,\"fields\":{\"utc\":%llu,\"lat\":%ld,\"lon\":%ld,\"alt\":%u,"
           "\"pan\":%u,\"tilt\":%d,\"heading\":%u,\"pitch\":%d,\"roll\":%d,\"vnorth\":%d,"
           "\"veast\":%d,\"hfov\":%u,\"vfov\":%u,\"gps_status\":%u},",
           (unsigned long)offset, (unsigned long long)k->utc, (long)k->lat, (long)k->lon,
           (unsigned)k->alt, (unsigned)k->pan, (int)k->tilt, (unsigned)k->heading, (int)k->pitch,
           (int)k->roll, (int)k->vnorth, (int)k->veast, (unsigned)k->hfov, (unsigned)k->vfov,
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
    fflush(stdout);
}

static int cmd_klv(args_t *a)
{
    const char *path = NULL;
    tase_klv_rx_t rx;
    uint8_t buf[4096];
    size_t n;
    FILE *in;
    while (a->i < a->argc) {
        if (help_opt(a)) {
            continue;
        }
        if (path == NULL && (a->argv[a->i][0] != '-' || a->argv[a->i][1] == '\0')) {
            path = a->argv[a->i++];
        } else {
            bad_arg(a);
        }
    }
    in = open_input(path);
    tase_klv_rx_init(&rx);
    while ((n = fread(buf, 1, sizeof(buf), in)) > 0) {
        tase_klv_rx_feed(&rx, buf, n, print_klv, NULL, NULL);
    }
    if (ferror(in) && errno != EIO) { /* EIO: a pty whose writer went away */
        tk_die("cannot read %s: %s", path ? path : "standard input", strerror(errno));
    }
    tase_klv_rx_flush(&rx, print_klv, NULL, NULL);
    if (in != stdin) {
        fclose(in);
    }
    return 0;
}

/* ---- record / replay (tk_capture.c) ---- */

static int cmd_record(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    const char *out = NULL, *tap_in = NULL, *v;
    double seconds = 0.0;
    tk_cap_writer_t w;
    while (a->i < a->argc) {
        if (help_opt(a) || link_opt(a, &lo)) {
            continue;
        }
        if (opt(a, "-o", true, &out) || opt(a, "--output", true, &out) ||
            opt(a, "--tap-in", true, &tap_in)) {
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
    if (lo.serial != NULL) {
        tk_cap_create(&w, out, TK_CAP_LINKTYPE_SERIAL, false);
        tk_cap_record_serial(&w, lo.serial, tap_in, lo.baud, seconds);
    } else {
        tk_cap_create(&w, out, TK_CAP_LINKTYPE_CAN, false);
        tk_cap_record_can(&w, lo.can, seconds);
    }
    return 0;
}

static int cmd_replay(args_t *a)
{
    link_opts_t lo = {NULL, NULL, DEFAULT_BAUD, NULL};
    tk_replay_opts_t ro;
    const char *path = NULL, *v;
    tk_cap_reader_t r;
    uint8_t head[4];
    size_t nhead;
    FILE *in;
    memset(&ro, 0, sizeof(ro));
    ro.speed = 1.0;
    ro.dirs = TK_CAP_DIR_OUT;
    while (a->i < a->argc) {
        if (help_opt(a) || link_opt(a, &lo)) {
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
        } else if (path == NULL && a->argv[a->i][0] != '-') {
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
    in = open_input(path);
    if (!open_capture(in, path, &r, head, &nhead)) {
        tk_die("%s is not a pcap or pcapng capture (candump logs: can-utils' canplayer "
               "replays them)",
               path);
    }
    ro.serial = lo.serial;
    ro.baud = lo.baud;
    ro.can = lo.can;
    tk_cap_replay(&r, &ro);
    tk_cap_reader_close(&r);
    return 0;
}

/* ---- list ---- */

static int cmd_list(args_t *a)
{
    size_t i;
    unsigned j;
    while (a->i < a->argc) {
        if (!help_opt(a)) {
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
            tk_field(p, j, &f);
            printf(" %s:%c%u", f.name, f.is_signed ? 's' : 'u', 8u * f.width);
        }
        printf("%s\n", tk_packet_has_tail(p) ? " data:bytes" : "");
    }
    return 0;
}

int main(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*run)(args_t *);
        const char *usage;
    } cmds[] = {
        {"monitor", cmd_monitor, usage_monitor},
        {"send", cmd_send, usage_send},
        {"query", cmd_query, usage_query},
        {"decode", cmd_decode, usage_decode},
        {"klv", cmd_klv, usage_klv},
        {"record", cmd_record, usage_record},
        {"replay", cmd_replay, usage_replay},
        {"list", cmd_list, usage_list},
    };
    args_t a;
    size_t i;
    tk_prog = "tase";
    if (argc < 2) {
        tk_usage_error("no command given (try 'tase --help')");
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        fputs(usage_main, stdout);
        return 0;
    }
    for (i = 0; i < sizeof(cmds) / sizeof(cmds[0]); i++) {
        if (strcmp(argv[1], cmds[i].name) == 0) {
            a.argc = argc;
            a.argv = argv;
            a.i = 2;
            a.usage = cmds[i].usage;
            return cmds[i].run(&a);
        }
    }
    tk_usage_error("unknown command '%s' (try 'tase --help')", argv[1]);
    return TK_EXIT_USAGE;
}
