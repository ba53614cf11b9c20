/* Byte streams to printed frames: one receiver per stream (the serial
 * line, or one direction of one CAN interface), 64-bit offsets and
 * counters on top of the library's 32-bit ones. */
#include "toolkit.h"

#include <string.h>

void tk_dec_init(tk_dec_t *d, const tk_fmt_t *fmt, FILE *out)
{
    memset(d, 0, sizeof(*d));
    d->fmt = *fmt;
    d->out = out;
    d->serial_rate = TASE_UART_BYTES_PER_S(57600);
}

static bool same_dir(const char *a, const char *b)
{
    return a == b || (a != NULL && b != NULL && strcmp(a, b) == 0);
}

tk_stream_t *tk_dec_stream(tk_dec_t *d, const char *iface, const char *dir)
{
    tk_stream_t *s;
    size_t i;
    for (i = 0; i < d->nstreams; i++) {
        s = &d->stream[i];
        if (same_dir(s->dir, dir) && strncmp(s->iface, iface, sizeof(s->iface) - 1u) == 0) {
            return s;
        }
    }
    if (d->nstreams == TK_STREAMS_MAX) {
        return NULL;
    }
    s = &d->stream[d->nstreams++];
    memset(s, 0, sizeof(*s));
    strncpy(s->iface, iface, sizeof(s->iface) - 1u);
    s->dir = dir;
    (void)tase_rx_init(&s->rx);
    (void)tase_rx_set_timing(&s->rx, d->serial_rate, d->margin_ms);
    return s;
}

/* Lines are formatted straight into the decoder's buffer and written in
 * blocks: one fwrite per line costs more than formatting it. */
static void flush_out(tk_dec_t *d)
{
    if (d->olen > 0u) {
        (void)fwrite(d->obuf, 1, d->olen, d->out);
        d->olen = 0;
    }
}

/* The time of the chunk that brought the byte before stream offset `end`
 * (a frame's last byte), or `fallback` when it is no longer (or never
 * was) in the history. */
static const tk_time_t *frame_time(const tk_stream_t *s, uint64_t end, const tk_time_t *fallback)
{
    const tk_time_t *t = fallback;
    size_t i;
    for (i = 0; i < s->hcount; i++) { /* newest first */
        size_t k = (s->hnext + TK_HIST - 1u - i) % TK_HIST;
        if (s->hist[k].end < end) {
            break;
        }
        t = &s->hist[k].time;
    }
    return t;
}

static void on_frame(void *user, const tase_frame_t *f)
{
    tk_dec_t *d = user;
    const tk_stream_t *s = d->cur;
    const tase_packet_desc_t *p = tk_schema_find(f->group, f->type);
    tk_meta_t m;
    /* every frame is counted (the summary adds up to the bytes read); those
     * past the limit are not printed */
    d->n.frames++;
    if (p == NULL) {
        d->n.unknown++;
    } else if (!tase_schema_length_ok(p, f->len)) {
        d->n.bad_length++;
    }
    if (d->limit != 0u && d->n.frames > d->limit) {
        return;
    }
    m.offset = tk_offset64(d->base64, d->base32, f->offset);
    m.time = frame_time(s, m.offset + f->len + TASE_FRAME_OVERHEAD, d->time);
    m.dir = s->dir;
    m.iface = s->iface[0] != '\0' ? s->iface : NULL;
    if (sizeof(d->obuf) - d->olen < TK_LINE_MAX) {
        flush_out(d);
    }
    d->olen += tk_format_frame(d->obuf + d->olen, TK_LINE_MAX, &d->fmt, &m, f);
}

/* Add what the receiver counted since last time (its counters are 32-bit). */
static void account(tk_dec_t *d, tk_stream_t *s)
{
    const tase_rx_stats_t *now = &s->rx.stats;
    d->n.checksum_errors += (uint32_t)(now->checksum_errors - s->seen.checksum_errors);
    d->n.bad_size += (uint32_t)(now->bad_size - s->seen.bad_size);
    d->n.discarded += (uint32_t)(now->bytes_discarded - s->seen.bytes_discarded);
    s->seen = *now;
}

static void begin(tk_dec_t *d, tk_stream_t *s, const tk_time_t *time)
{
    d->cur = s;
    d->base64 = s->bytes;
    d->base32 = s->rx.stats.bytes_in;
    d->time = time;
}

void tk_dec_tick(tk_dec_t *d, tk_stream_t *s, uint32_t now_ms)
{
    /* A tick with no byte since the last one, after a held candidate's
     * whole quiet limit (the last tick saw one held, the scan caught up),
     * settles it: a candidate cut short by the pause. (A tick also goes on
     * with a lagging scan, which discards bytes without any pause.) */
    bool cut = s->ticked && s->rx.stats.bytes_in == s->tick_bytes && s->tick_left != 0u &&
               s->tick_left != UINT32_MAX && (uint32_t)(now_ms - s->tick_at) < 0x80000000u &&
               now_ms - s->tick_at >= s->tick_left;
    begin(d, s, s->timed ? &s->last : NULL);
    (void)tase_rx_tick(&s->rx, now_ms, on_frame, d);
    s->ticked = true;
    s->tick_at = now_ms;
    s->tick_bytes = s->rx.stats.bytes_in;
    s->tick_left = tase_rx_quiet_ms(&s->rx, now_ms);
    if (cut && s->tick_left == UINT32_MAX) {
        d->n.paused++; /* settled: the receiver holds nothing now */
    }
    account(d, s);
    flush_out(d);
}

/* A record time in milliseconds (truncated); seconds held to +-2^50 (35
 * million years), so that no product or difference of two overflows (a
 * hostile pcapng's if_tsoffset can give 2^62 s). */
static int64_t time_ms64(const tk_time_t *t)
{
    const int64_t lim = (int64_t)1 << 50;
    int64_t sec = t->sec > lim ? lim : (t->sec < -lim ? -lim : t->sec);
    return sec * 1000 + (int64_t)(t->usec / 1000u);
}

/* A record time on stream s's receiver clock (modulo 2^32): the record
 * time plus the steps back before it. */
static uint32_t rx_ms(const tk_stream_t *s, const tk_time_t *t)
{
    return (uint32_t)((uint64_t)time_ms64(t) + s->back_ms);
}

void tk_dec_bytes(tk_dec_t *d, tk_stream_t *s, const uint8_t *data, size_t n, const tk_time_t *time)
{
    if (d->by_time && time != NULL) {
        int64_t step = s->timed ? time_ms64(time) - time_ms64(&s->last) : 0;
        if (step < 0) {
            /* a clock stepped back: no time passed (any step: one of
             * 2^31..2^32 ms wrapped into a long pause on the receiver's
             * 32-bit clock and cut a frame split across it) */
            s->back_ms += (uint32_t)(0u - (uint64_t)step);
        } else if (step >= (int64_t)0x80000000LL) {
            /* a pause of 2^31 ms (24.8 days) or more reads as no time on
             * the 32-bit clock: told of 2^30 ms of quiet first (a capture
             * appended to over weeks joined the sessions' cut frames) */
            tk_dec_tick(d, s, rx_ms(s, &s->last) + 0x40000000u);
        }
        /* the line was quiet from the last record until this one */
        tk_dec_tick(d, s, rx_ms(s, time));
    }
    if (time != NULL) {
        s->last = *time;
        s->timed = true;
    }
    while (n > 0u) {
        /* chunks well below 2^31 keep tk_offset64()'s reference valid */
        size_t k = n > (1u << 30) ? (size_t)1u << 30 : n;
        begin(d, s, time);
        if (time != NULL) {
            s->hist[s->hnext].end = s->bytes + k;
            s->hist[s->hnext].time = *time;
            s->hnext = (s->hnext + 1u) % TK_HIST;
            s->hcount += s->hcount < TK_HIST ? 1u : 0u;
        }
        (void)tase_rx_feed(&s->rx, data, k, on_frame, d);
        s->bytes += k;
        d->n.bytes += k;
        account(d, s);
        data += k;
        n -= k;
    }
    if (d->by_time && time != NULL) {
        tk_dec_tick(d, s, rx_ms(s, time)); /* notes the bytes' arrival */
    }
    flush_out(d);
}

bool tk_dec_can(tk_dec_t *d, const char *iface, const tase_can_frame_t *f, const tk_time_t *time)
{
    const char *dir = "out"; /* from the gimbal: what a host accepts */
    tk_stream_t *s;
    int n = tase_can_accept(TASE_CAN_ROLE_HOST, f);
    d->n.can_frames++;
    if (n <= 0) {
        dir = "in";
        n = tase_can_accept(TASE_CAN_ROLE_GIMBAL, f);
    }
    if (n <= 0) {
        d->n.can_other++; /* 3AX, other nodes, empty frames */
        return true;
    }
    s = tk_dec_stream(d, iface, dir);
    if (s == NULL) {
        return false;
    }
    (void)tase_rx_set_timing(&s->rx, TASE_SOCKETCAN_BYTES_PER_S, d->margin_ms);
    tk_dec_bytes(d, s, f->data, (size_t)n, time);
    return true;
}

void tk_dec_finish(tk_dec_t *d)
{
    size_t i;
    for (i = 0; i < d->nstreams; i++) {
        tk_stream_t *s = &d->stream[i];
        begin(d, s, s->timed ? &s->last : NULL);
        (void)tase_rx_flush(&s->rx, on_frame, d);
        account(d, s);
    }
    flush_out(d);
}

void tk_dec_summary(const tk_dec_t *d, FILE *out, const char *extra)
{
    const tk_counts_t *n = &d->n;
    fprintf(out,
            "%s: summary: %llu frames (%llu unknown, %llu wrong length), %llu checksum errors, "
            "%llu bad sizes, %llu of %llu bytes discarded",
            tk_prog, (unsigned long long)n->frames, (unsigned long long)n->unknown,
            (unsigned long long)n->bad_length, (unsigned long long)n->checksum_errors,
            (unsigned long long)n->bad_size, (unsigned long long)n->discarded,
            (unsigned long long)n->bytes);
    if (n->can_frames != 0u) {
        fprintf(out, ", %llu CAN frames (%llu not datalink)", (unsigned long long)n->can_frames,
                (unsigned long long)n->can_other);
    }
    if (d->limit != 0u && n->frames > d->limit) {
        fprintf(out, ", %llu frames past --count not printed",
                (unsigned long long)(n->frames - d->limit));
    }
    if (n->paused != 0u) {
        fprintf(out, ", %llu held frames cut short by a pause", (unsigned long long)n->paused);
    }
    fprintf(out, "%s\n", extra);
}
