/* tase: `decode` (a raw serial byte capture, a pcap/pcapng capture of
 * 'tase record', or a candump log, to JSON) and `klv` (the KLV metadata
 * line, to JSON). */
#include <string.h>

#include "tase/candump.h"
#include "tase/klv.h"
#include "tase_cli.h"
#include "tk_capture.h"

#define KLV_BAUD 9600L /* the spec's KLV line (table 1) */
#define BAD_LINES_SHOWN 10u

/* What the start of an input that held no packet looks like. */
static const char *input_guess(const cli_input_t *in, const tk_dec_t *d, bool candump)
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
    if (!candump && cli_input_is_text(in)) {
        return ": it is text, not a raw serial capture";
    }
    if (d->n.paused > 0u) {
        return " (frames were cut short by pauses longer than the quiet limit; --margin MS "
               "waits longer)";
    }
    if (d->n.checksum_errors > 0u) {
        return " (candidate frames were found, each with a bad checksum)";
    }
    /* a candump log, or a capture of a CAN bus (SocketCAN link type) */
    if ((candump || d->n.can_frames > 0u) && d->n.can_frames > d->n.can_other) {
        return " (its frames of ID 10000000 and 11000000 hold no whole frame)";
    }
    if (candump || d->n.can_frames > 0u) {
        return " (no frame of ID 10000000 or 11000000)";
    }
    return " (not a capture of a TASE serial line?)";
}

/* Raw bytes; buf[0..n) holds the first ones, read already. */
static void decode_raw(cli_input_t *in, tk_dec_t *d, uint8_t *buf, size_t cap, size_t n)
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
        n = cli_input_read(in, buf, cap);
    }
}

/* Each good record of a pcap/pcapng capture of 'tase record' (tk_capture.h)
 * whose first bytes are head[0..n), to fn; bad ones are said (the first
 * BAD_LINES_SHOWN) and skipped. serial_only: a CAN capture is refused
 * (`what` says for what). A file that can be read no further (cut inside
 * a record, a read error) ends the records there with the message in
 * err[0..TK_CAP_WHY_MAX), for the caller to say after it has decoded what
 * came before (err[0] is 0 otherwise). Returns the number of bad records. */
typedef void (*cap_record_fn)(void *ctx, int linktype, const tk_cap_rec_t *rec);

static unsigned long each_record(cli_input_t *in, const uint8_t *head, size_t n, cap_record_fn fn,
                                 void *ctx, const char *serial_only, char *err)
{
    tk_cap_reader_t r;
    tk_cap_rec_t rec;
    unsigned long bad = 0;
    char why[TK_CAP_WHY_MAX];
    int rc;
    tk_cap_reader_open(&r, in->fd, head, n, in->name);
    if (serial_only != NULL && r.linktype != TK_CAP_LINKTYPE_SERIAL) {
        tk_exit(TK_EXIT_INPUT, "%s is a CAN capture: %s", in->name, serial_only);
    }
    err[0] = '\0';
    while ((rc = tk_cap_next(&r, &rec, why, sizeof(why))) != TK_CAP_END) {
        if (rc == TK_CAP_ERROR) {
            (void)snprintf(err, TK_CAP_WHY_MAX, "%s", why);
            break;
        }
        if (rc == TK_CAP_BAD) {
            if (++bad <= BAD_LINES_SHOWN) {
                tk_warn("%s: record %lu skipped: %s", in->name, rec.index, why);
            }
        } else {
            fn(ctx, r.linktype, &rec);
        }
        tk_exit_if_signalled();
    }
    tk_cap_reader_close(&r);
    if (bad > BAD_LINES_SHOWN) {
        tk_warn("%s: %lu more bad records not shown", in->name, bad - BAD_LINES_SHOWN);
    }
    return bad;
}

/* A record of a capture decoded: serial records go to the stream of their
 * direction, CAN frames as in a candump log. */
static void decode_record(void *ctx, int linktype, const tk_cap_rec_t *rec)
{
    tk_dec_t *d = ctx;
    if (linktype == TK_CAP_LINKTYPE_SERIAL) {
        tk_stream_t *s = tk_dec_stream(d, "", rec->dir == TK_CAP_FROM_GIMBAL ? "out" : "in");
        tk_dec_bytes(d, s, rec->data, rec->len, &rec->t);
    } else if (rec->can_data) {
        (void)tk_dec_can(d, "", &rec->frame, &rec->t); /* one interface: no name */
    } else {
        /* remote, FD or error frames: counted, as a candump log's
         * (a capture of only those said nothing and exited 0) */
        d->n.can_frames++;
        d->n.can_other++;
    }
}

/* A capture whose first bytes are head[0..n), decoded. Returns the number
 * of bad records. */
static unsigned long decode_capture(cli_input_t *in, tk_dec_t *d, const uint8_t *head, size_t n,
                                    char *err)
{
    return each_record(in, head, n, decode_record, d, NULL, err);
}

typedef struct {
    cli_input_t *in;
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
        c->d->n.can_frames++; /* remote, FD or error frames carry no datalink bytes */
        c->d->n.can_other++;
        return;
    }
    if (rc != TASE_OK) {
        candump_bad(c, memchr(line, '\0', len) != NULL
                           ? " (it holds a NUL byte)"
                           : (memchr(line, '[', len) != NULL && memchr(line, '#', len) == NULL
                                  ? " (candump's screen output? record a log with 'candump -L')"
                                  : ""));
        return;
    }
    if (rec.sec > (uint64_t)INT64_MAX) {
        /* printed as a negative time before (the tools' times are signed) */
        candump_bad(c, " (a time of 2^63 s or more)");
        return;
    }
    t.sec = (int64_t)rec.sec;
    t.usec = rec.usec;
    if (!tk_dec_can(c->d, rec.ifname, &rec.frame, &t)) {
        tk_die("%s:%lu: too many CAN streams (at most %u: an interface and a direction each, "
               "%u interfaces both ways)",
               c->in->name, c->lineno, TK_STREAMS_MAX, TK_STREAMS_MAX / 2u);
    }
}

/* Returns the number of bad lines. */
static unsigned long decode_candump(cli_input_t *in, tk_dec_t *d)
{
    static uint8_t buf[CLI_READ_CHUNK];
    static char line[1024]; /* a log line is at most 73 bytes; anything longer is bad */
    candump_t c = {in, d, 0, 0};
    size_t nline = 0, n, i;
    bool overlong = false;
    while ((n = cli_input_read(in, buf, sizeof(buf))) > 0) {
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

int cli_cmd_decode(cli_args_t *a)
{
    const char *path = NULL, *v;
    bool candump = false, stats = false, capture = false;
    unsigned long bad = 0;
    long baud = CLI_DEFAULT_BAUD;
    bool baud_given = false;
    uint16_t margin = 0;
    cli_input_t in;
    static tk_dec_t d;
    static char err[TK_CAP_WHY_MAX]; /* a capture that could be read no further */
    tk_fmt_t fmt = {true, false, true};
    while (a->i < a->argc) {
        if (cli_common_opt(a)) {
            continue;
        }
        if (cli_baud_opt(a, &baud)) {
            baud_given = true;
        } else if (cli_opt(a, "--candump", false, &v)) {
            candump = true;
        } else if (cli_opt(a, "--stats", false, &v)) {
            stats = true;
        } else if (cli_opt(a, "--margin", true, &v)) {
            margin = (uint16_t)cli_int_opt_value("--margin", v, 1, 65535);
        } else if (path == NULL && cli_is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
    cli_input_open(&in, path, baud);
    tk_stdout_buffered();
    tk_dec_init(&d, &fmt, stdout);
    /* a capture's record times are the receivers' clock: a gap in them
     * ends a held candidate as it did on the live line, at --baud */
    d.by_time = true;
    d.serial_rate = TASE_UART_BYTES_PER_S((uint32_t)baud);
    d.margin_ms = margin;
    if (candump) {
        cli_input_check_baud(&in, baud_given, " or a serial capture");
        bad = decode_candump(&in, &d);
    } else {
        static uint8_t buf[CLI_READ_CHUNK];
        /* a serial line carries raw bytes, never a capture file */
        size_t n = in.device ? cli_input_read(&in, buf, sizeof(buf))
                             : cli_input_head(&in, buf, sizeof(buf));
        if (!in.device && tk_cap_is_capture(buf, n)) {
            capture = true; /* --baud: the rate of its serial line */
            bad = decode_capture(&in, &d, buf, n, err);
        } else {
            cli_input_check_baud(&in, baud_given, " or a serial capture");
            decode_raw(&in, &d, buf, sizeof(buf), n);
        }
    }
    tk_dec_finish(&d);
    cli_input_close(&in);
    tk_stdout_flush();
    if (stats) {
        tk_dec_summary(&d, stderr, "");
    }
    if (err[0] != '\0') {
        /* what came before it is decoded (the frames a held candidate
         * kept went out with the flush above) */
        tk_die("%s", err);
    }
    cli_input_check_end(&in);
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad %s%s (the rest was decoded)", in.name, bad,
                capture ? "record" : "line", bad == 1 ? "" : "s");
    }
    /* an input with nothing in it is no error: for a capture, one without
     * records (a silent line recorded), not the pcap file header */
    if (d.n.frames == 0 && (capture ? d.n.bytes > 0u || d.n.can_frames > 0u : in.nhead > 0)) {
        tk_exit(TK_EXIT_INPUT, "no TASE packet found in %s%s", in.name,
                input_guess(&in, &d, candump));
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
static const char *klv_guess(const cli_input_t *in)
{
    static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};
    size_t i;
    if (cli_input_is_text(in)) {
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
    printf("\"units\":{\"utc_s\":%.6f,\"lat_deg\":%.9f,\"lon_deg\":%.9f,\"alt_m\":%.2f,"
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

static void klv_feed(tase_klv_rx_t *rx, klv_ctx_t *c, const uint8_t *bytes, size_t n)
{
    c->base32 = rx->stats.bytes_in;
    (void)tase_klv_rx_feed(rx, bytes, n, print_klv, NULL, c);
    c->base64 += n;
}

typedef struct {
    tase_klv_rx_t *rx;
    klv_ctx_t *c;
} klv_cap_t;

/* A record of a `tase record --serial` capture of the KLV line: its bytes
 * from the gimbal fed in order (those to it, a tap's other line, are not
 * its KLV output). */
static void klv_record(void *ctx, int linktype, const tk_cap_rec_t *rec)
{
    klv_cap_t *k = ctx;
    (void)linktype; /* serial: each_record() refuses the others */
    if (rec->dir == TK_CAP_FROM_GIMBAL) {
        klv_feed(k->rx, k->c, rec->data, rec->len);
    }
}

int cli_cmd_klv(cli_args_t *a)
{
    const char *path = NULL;
    static tase_klv_rx_t rx;
    static uint8_t buf[CLI_READ_CHUNK];
    klv_ctx_t c = {0, 0, 0};
    long baud = KLV_BAUD;
    bool baud_given = false;
    cli_input_t in;
    size_t n;
    bool capture = false;
    unsigned long bad = 0;
    static char err[TK_CAP_WHY_MAX]; /* a capture that could be read no further */
    while (a->i < a->argc) {
        if (cli_common_opt(a)) {
            continue;
        }
        if (cli_baud_opt(a, &baud)) {
            baud_given = true;
        } else if (path == NULL && cli_is_arg(a, false)) {
            path = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
    cli_input_open(&in, path, baud);
    cli_input_check_baud(&in, baud_given, "");
    tk_stdout_buffered();
    (void)tase_klv_rx_init(&rx);
    /* a serial line carries raw bytes, never a capture file */
    n = in.device ? cli_input_read(&in, buf, sizeof(buf)) : cli_input_head(&in, buf, sizeof(buf));
    if (!in.device && tk_cap_is_capture(buf, n)) {
        /* `tase record` of the KLV line: its records' bytes, in order (a
         * packet is often split across records); fed raw, the pcap headers
         * cut packets and the offsets were the file's */
        klv_cap_t k;
        k.rx = &rx;
        k.c = &c;
        capture = true;
        bad = each_record(&in, buf, n, klv_record, &k, "the KLV line is a serial line", err);
    } else {
        while (n > 0) {
            klv_feed(&rx, &c, buf, n);
            tk_stdout_flush(); /* a live line's packets go out as they come */
            n = cli_input_read(&in, buf, sizeof(buf));
        }
    }
    c.base32 = rx.stats.bytes_in;
    (void)tase_klv_rx_flush(&rx, print_klv, NULL, &c);
    cli_input_close(&in);
    tk_stdout_flush();
    if (err[0] != '\0') {
        tk_die("%s", err); /* after the packets that came before it */
    }
    cli_input_check_end(&in);
    if (bad > 0) {
        tk_exit(TK_EXIT_INPUT, "%s: %lu bad record%s (the rest was decoded)", in.name, bad,
                bad == 1 ? "" : "s");
    }
    if (c.packets == 0 && (capture ? rx.stats.bytes_in > 0u : in.nhead > 0)) {
        tk_exit(TK_EXIT_INPUT, "no KLV packet found in %s%s", in.name,
                capture ? " (a capture of the datalink? 'tase decode' reads those)"
                        : klv_guess(&in));
    }
    return TK_EXIT_OK;
}
