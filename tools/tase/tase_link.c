/* tase: the link to a gimbal. Opening it (serial or CAN, optionally
 * recorded), requests that wait for their answer while a signal is still
 * seen within 20 ms, sending, printing what went each way, checking a
 * setup packet's echo; and `monitor`, which reads the link as it is. */
#include <string.h>

#include "tase_cli.h"
#include "tk_capture.h"

void cli_check_link_baud(const cli_link_opts_t *lo)
{
    if (lo->baud_given && lo->can != NULL) {
        tk_usage_error("--baud is a serial link's rate; a CAN interface has its own bit rate "
                       "(ip link set %s type can bitrate ...)",
                       lo->can);
    }
}

void cli_check_link_opts(const cli_link_opts_t *lo)
{
    if (lo->serial != NULL && lo->can != NULL) {
        tk_usage_error("give either --serial or --can, not both");
    }
    if (lo->serial == NULL && lo->can == NULL) {
        tk_usage_error("no link given: use --serial DEV or --can IFACE");
    }
    cli_check_link_baud(lo);
    if (lo->record != NULL && lo->can != NULL) {
        tk_usage_error("--record records serial links; on CAN run 'tase record --can %s -o FILE' "
                       "beside this command",
                       lo->can);
    }
}

static void open_link(const cli_link_opts_t *lo, tk_link_t *l, tase_port_t *port)
{
    cli_check_link_opts(lo);
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

void cli_session_open(cli_session_t *s, const cli_link_opts_t *lo, tase_rx_handler_t on_frame,
                      void *user)
{
    s->name = lo->serial != NULL ? lo->serial : lo->can;
    open_link(lo, &s->link, &s->port);
    if (tase_host_init(&s->h, &s->port, on_frame, user) != TASE_OK) {
        tk_die("internal error: host role init failed");
    }
}

void cli_session_close(cli_session_t *s)
{
    tk_link_close(&s->link);
    tk_stdout_flush();
}

/* Die: reading the session's link failed with `rc` (a hang-up says so). */
static void session_read_failed(const cli_session_t *s, int rc)
{
    tk_die("cannot read %s: %s", s->name, tk_link_error(&s->link, rc));
}

/* Service the session's port for up to wait_ms; dies when reading fails. */
void cli_session_service(cli_session_t *s, uint32_t wait_ms)
{
    int rc = tase_host_service(&s->h, wait_ms);
    if (rc < 0) {
        session_read_failed(s, rc);
    }
}

/* Start a request and wait for its outcome (the reply length or an
 * error), servicing the port so a signal is seen within 20 ms. */
static int request(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                   uint8_t *reply, const cli_req_opts_t *r, bool show_sent)
{
    /* what waited unread is not this request's answer (tase/host.h,
     * MATCHING) */
    int rc = tase_host_drain(&s->h);
    if (rc < 0) {
        session_read_failed(s, rc);
    }
    rc = tase_host_request_start(&s->h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len, reply,
                                 TASE_DATA_MAX, r->timeout_ms, r->retries,
                                 s->port.ops->now_ms(s->port.ctx));
    if (rc >= 0 && len > 0) {
        tk_mark_sent(tase_schema_packet_name(p)); /* a query changes nothing */
    }
    if (rc >= 0 && show_sent) {
        cli_print_packet(p, data, len, r->json, "in", "sent");
        tk_stdout_flush_soft(); /* seen while it waits; a failure reported at the end */
    }
    while (rc >= 0) {
        tk_exit_if_signalled();
        cli_session_service(s, 20);
        rc = tase_host_poll(&s->h, s->port.ops->now_ms(s->port.ctx));
        if (rc != TASE_EAGAIN) {
            break;
        }
        rc = 0;
    }
    return rc;
}

/* Die with the reason a request failed (rc), `note` (or NULL) added to a
 * timeout's message, with what the line did say. */
static void request_failed(const cli_session_t *s, const tase_packet_desc_t *p,
                           const cli_req_opts_t *r, const char *note, int rc)
{
    if (rc == TASE_ETIMEOUT) {
        /* our own queries coming back (a line that echoes, nothing else
         * answering on it), or bytes that never made a frame (a wrong
         * baud: monitor's hint) */
        const tase_rx_stats_t *rx = &s->h.rx.stats;
        char hint[160] = "";
        if (s->h.stats.queries_rx != 0u) {
            (void)snprintf(hint, sizeof hint,
                           " (our own queries came back on this line: it echoes what is sent (a "
                           "loop-back plug or a half-duplex adapter); is a gimbal on it?)");
        } else if (rx->frames_ok == 0u && rx->bytes_in != 0u) {
            (void)snprintf(hint, sizeof hint, " (%lu bytes came, none of them a frame: %s)",
                           (unsigned long)rx->bytes_in,
                           s->link.is_can ? "datalink frames that never formed a TASE frame"
                                          : "a wrong --baud, or not the gimbal's datalink port?");
        } else {
            /* silence, or frames of other kinds only */
        }
        tk_die("timeout: no answer to %s after %u attempt%s of %lu ms%s%s",
               tase_schema_packet_name(p), (unsigned)r->retries + 1u, r->retries ? "s" : "",
               (unsigned long)r->timeout_ms, note != NULL ? note : "", hint);
    }
    tk_die("%s request failed on %s: %s", tase_schema_packet_name(p), s->name,
           tk_link_error(&s->link, rc));
}

/* A request and its answer; dies with the reason on failure, `note` (or
 * NULL) added to a timeout's message. With `show_sent`, the packet is
 * printed ("sent ...") as soon as it has gone out, before the wait: a
 * gimbal that never answers leaves that line, as every other command
 * that sends. */
static int transact(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                    uint8_t *reply, const cli_req_opts_t *r, const char *note, bool show_sent)
{
    int rc = request(s, p, data, len, reply, r, show_sent);
    if (rc < 0) {
        request_failed(s, p, r, note, rc);
    }
    return rc;
}

int cli_transact_note(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data,
                      size_t len, uint8_t *reply, const cli_req_opts_t *r, const char *note)
{
    return transact(s, p, data, len, reply, r, note, false);
}

int cli_transact(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                 uint8_t *reply, const cli_req_opts_t *r)
{
    return transact(s, p, data, len, reply, r, NULL, len > 0u);
}

void cli_send_frame(cli_session_t *s, const tase_packet_desc_t *p, const uint8_t *data, size_t len)
{
    int rc = tase_host_send(&s->h, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), data, len);
    if (rc < 0) {
        tk_exit_if_signalled(); /* a stalled line's write a signal came in */
        tk_die("cannot send %s to %s: %s", tase_schema_packet_name(p), s->name,
               tk_link_error(&s->link, rc));
    }
    tk_mark_sent(tase_schema_packet_name(p));
}

/* Print a frame we sent ("dir":"in") or received ("out"); `label` starts
 * the text line ("sent", "echo", NULL for none). */
void cli_print_packet(const tase_packet_desc_t *p, const uint8_t *data, size_t len, bool json,
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

/* Write into diff[0..cap) every field of echo (elen bytes) that differs
 * from fs (len bytes sent; fields sent as "do not change" and `skip` not
 * compared); returns how many differ. */
static size_t echo_diff(const cli_fields_t *fs, size_t len, const uint8_t *echo, int elen,
                        const char *skip, char *diff, size_t cap)
{
    const tase_packet_desc_t *p = fs->p;
    size_t used = 0, count = 0;
    unsigned i, n = cli_fields_within(p, len);
    diff[0] = '\0';
    for (i = 0; i < n; i++) {
        long long sent = cli_fields_value(fs, i), got = 0;
        const char *name = tase_schema_field_name(p, i);
        (void)tk_field_get(p, i, echo, (size_t)elen, &got);
        if (got != sent && !tase_field_is_keep(p, i, sent) &&
            (skip == NULL || strcmp(skip, name) != 0)) {
            int w = snprintf(diff + used, cap - used, "%s%s sent %lld, gimbal has %lld",
                             count ? "; " : "", name, sent, got);
            if (w > 0 && (size_t)w < cap - used) {
                used += (size_t)w;
            }
            count++;
        }
    }
    return count;
}

/* Compare the gimbal's echo with what was sent; exit 3 naming every field
 * that differs. Fields sent as "do not change" are not compared (the echo
 * has the setting in force); `skip` names another one (or NULL). */
void cli_confirm_echo(const cli_fields_t *fs, size_t len, const uint8_t *echo, int elen,
                      const char *skip)
{
    char diff[1024];
    if ((size_t)elen != len) {
        tk_exit(TK_EXIT_MISMATCH, "%s not confirmed: the echo has %d data bytes, %lu were sent",
                tase_schema_packet_name(fs->p), elen, (unsigned long)len);
    }
    if (echo_diff(fs, len, echo, elen, skip, diff, sizeof diff) != 0) {
        tk_exit(TK_EXIT_MISMATCH, "%s not applied as sent: %s", tase_schema_packet_name(fs->p),
                diff);
    }
}

/* Confirm a setting by its echo (n bytes in reply). `temporary` tells the
 * gimbal what to do with the packet (store it or not); it is no setting
 * in force, so its echo proves nothing. An echo that differs may be a
 * stale answer that came after the send (to a request made before a
 * stall, a gimbal answering twice, a second gimbal): the setting in force
 * decides, asked once more; an error is still one line. */
static void confirm_setting(cli_session_t *s, const cli_fields_t *fs, size_t len, uint8_t *reply,
                            int n, const cli_send_opts_t *o)
{
    const tase_packet_desc_t *p = fs->p;
    char first[1024], diff[1024];
    if ((size_t)n == len && echo_diff(fs, len, reply, n, "temporary", first, sizeof first) != 0) {
        int q = request(s, p, NULL, 0, reply, &o->r, false);
        if (q == TASE_ETIMEOUT) {
            /* the echo is all there is to go by */
            tk_exit(TK_EXIT_MISMATCH,
                    "%s not applied as sent: %s (and the query for the setting in force went "
                    "unanswered)",
                    tase_schema_packet_name(p), first);
        }
        if (q < 0) {
            request_failed(s, p, &o->r, NULL, q);
        }
        n = q;
        cli_print_packet(p, reply, (size_t)n, o->r.json, "out", "echo");
        if (echo_diff(fs, len, reply, n, "temporary", diff, sizeof diff) == 0) {
            fprintf(stderr,
                    "tase: note: the first answer differed (%s) but the %s in force is as "
                    "sent (a late or repeated answer, another gimbal on this line, or one that "
                    "answered before it applied the setting)\n",
                    first, tase_schema_packet_name(p));
        } else if (s->h.stats.retries + s->h.stats.late + s->h.stats.stale != 0u) {
            tk_exit(TK_EXIT_MISMATCH,
                    "%s not applied as sent: %s (answers came late or twice here: %lu re-sent, "
                    "%lu late, %lu begun before their request; a longer --timeout may show the "
                    "setting's own echo)",
                    tase_schema_packet_name(p), diff, (unsigned long)s->h.stats.retries,
                    (unsigned long)s->h.stats.late, (unsigned long)s->h.stats.stale);
        } else {
            /* the setting in force differs: cli_confirm_echo() says how */
        }
        len = (size_t)n; /* the answer's layout (AXIS_SETTING 22 or 23) */
    }
    cli_confirm_echo(fs, len, reply, n, "temporary");
    if (s->h.stats.queries_rx != 0u) {
        fprintf(stderr,
                "tase: warning: our own queries came back on %s: the line echoes what is "
                "sent (a loop-back plug or a half-duplex adapter), so this echo may be our "
                "own frame and does not show the gimbal took it\n",
                s->name);
    }
}

/* Send fs (len bytes); for setup packets wait for the echo and confirm it
 * (unless no_wait). */
void cli_send_fields(cli_session_t *s, const cli_fields_t *fs, size_t len, const cli_send_opts_t *o)
{
    const tase_packet_desc_t *p = fs->p;
    uint8_t reply[TASE_DATA_MAX];
    bool echoed = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP && !o->no_wait;
    int n;
    if (!echoed) {
        cli_send_frame(s, p, fs->data, len);
        cli_print_packet(p, fs->data, len, o->r.json, "in", "sent");
        return;
    }
    n = transact(s, p, fs->data, len, reply, &o->r, NULL, true);
    cli_print_packet(p, reply, (size_t)n, o->r.json, "out", "echo");
    if (len > 0) {
        confirm_setting(s, fs, len, reply, n, o);
    }
}

/* ---- monitor ---- */

int cli_cmd_monitor(cli_args_t *a)
{
    cli_link_opts_t lo = {NULL, NULL, CLI_DEFAULT_BAUD, false, NULL};
    tk_fmt_t fmt = {false, false, false};
    double seconds = 0.0, t_end;
    long long limit = 0;
    uint16_t margin = 0; /* the receiver's default */
    const char *v;
    tk_link_t link;
    tase_port_t port;
    static tk_dec_t d;
    tk_stream_t *st;
    static uint8_t buf[4096];
    char extra[192] = "";
    int failed = 0;
    while (a->i < a->argc) {
        if (cli_common_opt(a) || cli_link_opt(a, &lo)) {
            continue;
        }
        if (cli_opt(a, "--json", false, &v)) {
            fmt.json = true;
        } else if (cli_opt(a, "--time", false, &v)) {
            fmt.time = true;
        } else if (cli_opt(a, "--units", false, &v)) {
            fmt.units = true;
        } else if (cli_opt(a, "--count", true, &v)) {
            limit = cli_int_opt_value("--count", v, 1, 1000000000);
        } else if (cli_opt(a, "--margin", true, &v)) {
            margin = (uint16_t)cli_int_opt_value("--margin", v, 1, 65535);
        } else if (cli_opt(a, "--seconds", true, &v)) {
            if (tk_parse_seconds(v, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", v);
            }
        } else {
            cli_bad_arg(a);
        }
    }
    open_link(&lo, &link, &port);
    tk_dec_init(&d, &fmt, stdout);
    d.limit = (uint64_t)limit;
    d.serial_rate = port.bytes_per_s;
    d.margin_ms = margin;
    st = tk_dec_stream(&d, "", NULL);
    t_end = tk_now_s() + seconds;
    while ((limit == 0 || d.n.frames < (uint64_t)limit) && (seconds == 0.0 || tk_now_s() < t_end) &&
           tk_signal == 0) {
        /* wake by the receiver's quiet limit (tase/frame.h, TIME BOUND) */
        uint32_t asked = port.ops->now_ms(port.ctx);
        uint32_t wait = tase_rx_quiet_ms(&st->rx, asked);
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
            uint32_t at = port.ops->now_ms(port.ctx);
            struct timespec rec;
            if (ns != 0u) { /* the kernel's receive time of the frame */
                now.sec = (int64_t)(ns / 1000000000u);
                now.usec = (uint32_t)(ns % 1000000000u / 1000u);
            } else if (tk_cap_session_last_read(&at, &rec)) {
                /* --record: the time and port time of the record, so that
                 * `tase decode` of the capture ticks as this loop does */
                now.sec = (int64_t)rec.tv_sec;
                now.usec = (uint32_t)(rec.tv_nsec / 1000);
            } else {
                tk_time_now(&now);
            }
            /* A read that waited for its bytes says the line was quiet
             * until they came: tick there first (a candidate whose limit
             * passed before them is settled, as decode does at the
             * record's time). Bytes that were waiting when read was
             * called (this loop was late: a slow standard output) came at
             * some time before: no such tick, no pause read into it. */
            if (at != asked) {
                tk_dec_tick(&d, st, at);
            }
            tk_dec_bytes(&d, st, buf, (size_t)n, fmt.time ? &now : NULL);
            tk_dec_tick(&d, st, at);
        } else {
            tk_dec_tick(&d, st, port.ops->now_ms(port.ctx)); /* quiet until now */
        }
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
