/* Gimbal role: setup echo/query and telemetry scheduling (see tase/gimbal.h). */
#include "tase/gimbal.h"

#include <string.h>

#include "tase/codec.h"
#include "tase/ids.h"
#include "tase/port_io.h"
#include "tase/schema.h"
#include "tase_frame_private.h"
#include "tase_schema_layout.h"

#define SETUP_SYSTEM_VERSION 0x03u
#define SETUP_PACKET_RATE 0x00u
#define SETUP_CAMERA_TYPE 0x05u
#define SETUP_AXIS_SETTING 0x02u
#define SETUP_MAX 42u          /* longest setup packet: SYSTEM_VERSION */
#define RATE_BYTES_PER_PORT 5u /* Angle, Rate, Geo-ref, Camera, Reserved */
#define SETUP_APPLY_MAX 23u    /* longest writable setup packet: AXIS_SETTING */
#define SERVICE_CHUNK 64u
#define NO_FRAME 0xFFu     /* frame_port outside a callback */
#define ECHO_SHORT_AXIS 8u /* an echo: AXIS_SETTING in its 22-byte layout */
/* g->tx_frame is telemetry's frame during tase_gimbal_poll() and the
 * setup path's scratch otherwise: the setting offered to the application
 * at TX_APPLY, the bytes being stored at TX_STORE, an echo's short layout
 * at 0 (after both are done). */
#define TX_APPLY 0u
#define TX_STORE 24u
typedef char
    chk_tx_scratch[(TX_STORE >= SETUP_APPLY_MAX &&
                    TX_STORE + SETUP_MAX <= TASE_GIMBAL_TELEMETRY_MAX + TASE_FRAME_OVERHEAD)
                       ? 1
                       : -1];

/* Data length and offset into g->setup of each setup packet (spec 4.4). */
static const uint8_t setup_len[TASE_GIMBAL_SETUP_TYPES] = {16u, 2u, 23u, 42u, 2u, 3u, 6u, 16u};
static const uint8_t setup_off[TASE_GIMBAL_SETUP_TYPES] = {0u, 16u, 18u, 41u, 83u, 85u, 88u, 94u};

/* How far ahead of the clock a stream's next slot can be: a whole period
 * of a 1-per-second stream. */
#define SCHED_AHEAD_MAX_MS 1000u

/* Slot k's offset from t0. k < rate <= 255 keeps the product small. */
static uint32_t slot_ms(uint32_t k, uint32_t rate)
{
    return k * 1000u / rate;
}

/* now_ms is at or after t (clock wraps modulo 2^32; times compared must be
 * less than 2^31 ms apart). */
static bool reached(uint32_t now_ms, uint32_t t)
{
    return (uint32_t)(now_ms - t) < 0x80000000u;
}

static bool port_present(const tase_gimbal_t *g, unsigned port)
{
    return port < TASE_GIMBAL_PORTS && g->port[port].ops != NULL;
}

/* The error of a call g refuses while its busy byte is set (gimbal.h
 * REENTRANCY): TASE_EBUSY from inside one of its callbacks (1), TASE_EARG
 * for any other value (a corrupted instance). */
static int busy_error(const tase_gimbal_t *g)
{
    return g->busy == 1u ? TASE_EBUSY : TASE_EARG;
}

/* Anchor a stream at `now`: its first packet one period later. */
static void sched_start(tase_gimbal_sched_t *s, uint8_t rate, uint32_t now_ms)
{
    s->rate = rate;
    s->t0 = now_ms;
    s->k = 1;
    if (rate == 1u) {
        s->t0 += 1000u;
        s->k = 0;
    }
}

/* A port's telemetry demand (bytes/s at the scheduled rates) and its
 * pacing, restarted so that the next due slot of each stream is sent. */
static void pace_port(tase_gimbal_t *g, unsigned p, bool keep)
{
    /* Frame length of each telemetry stream's packet (data + 8). */
    static const uint8_t stream_frame_len[TASE_GIMBAL_STREAMS] = {14u, 26u, 71u};
    unsigned s;
    uint32_t d = 0;
    for (s = 0; s < TASE_GIMBAL_STREAMS; s++) {
        d += (uint32_t)g->sched[p][s].rate * stream_frame_len[s];
    }
    g->demand[p] = d;
    for (s = 0; s < TASE_GIMBAL_STREAMS; s++) {
        tase_gimbal_sched_t *st = &g->sched[p][s];
        /* keep: a rate changed. Each stream keeps what it had earned, at
         * most one slot (a full accumulator for every change gave each
         * stream a slot for free: a host changing a rate every 200 ms
         * drove a 9600-baud port at 1,119 B/s of its 720) */
        st->acc = (!keep || st->acc > d) ? d : st->acc;
    }
}

/* Restart the streams whose rate changed (all: every stream) and the
 * pacing of their ports only: a PACKET_RATE that changes nothing on a port
 * leaves its pacing alone (re-sent every 200 ms, it restarted every port
 * with a full budget and the ports sent far beyond their capacity), and
 * one that changes a rate keeps the budget earned (pace_port()). */
static void sched_from_rates(tase_gimbal_t *g, uint32_t now_ms, bool all)
{
    unsigned p;
    unsigned s;
    for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
        bool changed = all;
        for (s = 0; s < TASE_GIMBAL_STREAMS; s++) {
            uint8_t rate = g->setup[setup_off[SETUP_PACKET_RATE] + p * RATE_BYTES_PER_PORT + s];
            if (all || rate != g->sched[p][s].rate) {
                sched_start(&g->sched[p][s], rate, now_ms);
                changed = true;
            }
        }
        if (changed) {
            pace_port(g, p, !all);
        }
    }
}

/* Telemetry's share of a port's capacity, bytes/s, in 32-bit arithmetic
 * (no 64-bit division helper linked): whole hundreds, then the rest. */
static uint32_t telemetry_budget(const tase_gimbal_t *g, unsigned p)
{
    uint32_t c = g->capacity[p];
    return (c / 100u) * TASE_GIMBAL_TELEMETRY_SHARE +
           (c % 100u) * TASE_GIMBAL_TELEMETRY_SHARE / 100u;
}

/* Whether this due slot of stream s fits the port's budget. When the
 * rates ask for more than the budget, every stream gets the same fraction
 * of its slots, spread evenly (an error accumulator, as in Bresenham's
 * line): no stream starves, and the bytes sent per second stay at the
 * budget. */
static bool within_budget(tase_gimbal_t *g, unsigned p, tase_gimbal_sched_t *st)
{
    uint32_t budget = telemetry_budget(g, p);
    if (g->demand[p] <= budget) {
        return true;
    }
    st->acc += budget;
    if (st->acc < g->demand[p]) {
        return false;
    }
    st->acc -= g->demand[p];
    return true;
}

/* A port's default capacity: its byte rate, or the slowest line's. */
static uint32_t port_capacity(const tase_port_t *port)
{
    return port->bytes_per_s != 0u ? port->bytes_per_s : TASE_RX_SLOWEST_RATE;
}

int tase_gimbal_set_capacity(tase_gimbal_t *g, unsigned port, uint32_t bytes_per_s)
{
    if (g == NULL || port >= TASE_GIMBAL_PORTS) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    g->capacity[port] = bytes_per_s != 0u ? bytes_per_s : port_capacity(&g->port[port]);
    pace_port(g, port, false);
    return TASE_OK;
}

int tase_gimbal_init(tase_gimbal_t *g, const tase_port_t *ports, tase_rx_t *rx, size_t nports,
                     const tase_gimbal_app_t *app, uint32_t now_ms)
{
    /* Defaults the spec states. PACKET_RATE: 10, 10, 4 per port. SENSOR_FILTER:
     * 10 Hz cutoff (0.1 Hz units), 0.5 deg/s decimation (0.1 deg/s units).
     * AXIS_SETTING: tilt no-go centre 90 deg and range 60 deg (0.01 deg units),
     * pan/tilt max rate 300 deg/s (5 deg/s units), max acceleration
     * 10000 deg/s^2 (200 units), position gain 4 (0.1 units); byte 13 is
     * missing from table 22 and stays 0. The rest has no stated default and
     * stays 0 too, from the memset. */
    static const uint8_t setup_defaults[] = {
        /* PACKET_RATE */
        10u, 10u, 4u, 0u, 0u, 10u, 10u, 4u, 0u, 0u, 10u, 10u, 4u, 0u, 0u, 0u,
        /* SENSOR_FILTER */
        100u, 5u,
        /* AXIS_SETTING */
        0x00u, 0x00u, 0x00u, 0x00u, 0x23u, 0x28u, 0x17u, 0x70u, 0x00u, 0x00u, 0x00u, 0x00u, 60u, 0u,
        60u, 0u, 50u, 50u, 0u, 40u, 40u, 0u, 0u,
        /* SYSTEM_VERSION .. CAMERA_ALIGN: none stated (0), but see below */
    };
    size_t i;

    if (g == NULL || (ports == NULL && nports > 0) || nports > TASE_GIMBAL_PORTS) {
        return TASE_EARG;
    }
    if (app != NULL && ((app->fill_telemetry != NULL && app->fill_telemetry_msg != NULL) ||
                        (app->apply_setup != NULL && app->apply_setup_msg != NULL) ||
                        (app->on_frame != NULL && app->dispatch != NULL))) {
        return TASE_EARG; /* which one would be meant? */
    }
    for (i = 0; i < nports; i++) {
        if (ports[i].ops != NULL && ports[i].ops->write == NULL) {
            return TASE_EARG;
        }
    }
    (void)memset(g, 0, sizeof *g);
    g->frame_port = NO_FRAME;
    for (i = 0; i < nports; i++) {
        g->port[i] = ports[i];
    }
    for (i = 0; i < TASE_GIMBAL_PORTS; i++) {
        g->capacity[i] = port_capacity(&g->port[i]);
    }
    if (rx != NULL) {
        g->rx = rx;
        g->nrx = (uint8_t)nports;
        for (i = 0; i < nports; i++) {
            (void)tase_rx_init(&rx[i]);
            (void)tase_rx_set_timing(&rx[i], ports[i].bytes_per_s, 0u);
        }
    }
    if (app != NULL) {
        g->app = *app;
    }
    (void)memcpy(g->setup, setup_defaults, sizeof setup_defaults);
    /* CAMERA_TYPE: "no camera" until the application stores its cameras;
     * 0 would be "do not change", which is not a setting. */
    (void)memset(&g->setup[setup_off[SETUP_CAMERA_TYPE]], 0xFF, setup_len[SETUP_CAMERA_TYPE]);
    /* SYSTEM_VERSION: no cameras (0xFF, 4.4.4's "if none"; 0 is no type of
     * table 28) until the application stores its version */
    for (i = 0; i < 3u; i++) {
        g->setup[setup_off[SETUP_SYSTEM_VERSION] + 24u + 6u * i] = 0xFFu;
    }
    sched_from_rates(g, now_ms, true);
    return TASE_OK;
}

/* Count the outcome of writing one frame; returns r. */
static int gimbal_write(tase_gimbal_t *g, int r)
{
    return tase_port_count_tx(r, &g->stats.frames_tx, &g->stats.tx_errors);
}

int tase_gimbal_send(tase_gimbal_t *g, unsigned port, uint8_t group, uint8_t type,
                     const uint8_t *data, size_t len)
{
    if (g == NULL || !port_present(g, port)) {
        return TASE_EARG;
    }
    return gimbal_write(g, tase_port_send_frame(&g->port[port], group, type, data, len));
}

int tase_gimbal_send_msg(tase_gimbal_t *g, unsigned port, uint16_t id, const void *msg)
{
    if (g == NULL || !port_present(g, port)) {
        return TASE_EARG;
    }
    return gimbal_write(g, tase_port_send_msg(&g->port[port], id, msg));
}

int tase_gimbal_setup_len(uint8_t type)
{
    if (type >= TASE_GIMBAL_SETUP_TYPES) {
        return TASE_EUNKNOWN;
    }
    return setup_len[type];
}

int tase_gimbal_setup_get(const tase_gimbal_t *g, uint8_t type, uint8_t *out, size_t cap)
{
    if (g == NULL || out == NULL) {
        return TASE_EARG;
    }
    if (type >= TASE_GIMBAL_SETUP_TYPES) {
        return TASE_EUNKNOWN;
    }
    if (cap < setup_len[type]) {
        return TASE_ENOSPC;
    }
    (void)memcpy(out, &g->setup[setup_off[type]], setup_len[type]);
    return setup_len[type];
}

/* Copy the fields of setup packet p from src (src_len bytes, a layout the
 * schema accepts) to dst (dst_len bytes, AXIS_SETTING 22 or 23), each at
 * the offset of its layout; reserved bytes become zero. With `cur` (the
 * stored bytes, table layout), a field holding its "do not change" value
 * takes the stored one instead. */
static void setup_copy(const tase_packet_desc_t *p, const uint8_t *src, size_t src_len,
                       uint8_t *dst, size_t dst_len, const uint8_t *cur)
{
    tase_field_iter_t it; /* the walk of the source's layout */
    bool dst_short = tase_layout_is_short(p, dst_len);
    (void)memset(dst, 0, dst_len);
    (void)tase_field_iter_init(&it, p, src_len); /* p: the table's, found by the caller */
    while (tase_field_iter_next(&it)) {
        const uint8_t *from = &src[it.offset];
        uint32_t keep;
        /* the wire bits against the "do not change" bits (no setup field
         * has the MSB kind, where any value with the top bit set would do) */
        if (cur != NULL && tase_field_iter_keep_bits(&it, &keep) &&
            tase_field_iter_bits_(&it, src) == keep) {
            from = &cur[tase_layout_offset(it.field, false)]; /* stored: table layout */
        }
        (void)memcpy(&dst[tase_layout_offset(it.field, dst_short)], from, it.width);
    }
}

static const tase_packet_desc_t *setup_desc(uint8_t type)
{
    return tase_schema_find(TASE_GROUP_SETUP, type);
}

/* data (table layout) is what the host or the application asked for:
 * stored with reserved bytes zero and "do not change" fields unchanged. */
static void setup_store(tase_gimbal_t *g, uint8_t type, const uint8_t *data, uint32_t now_ms)
{
    uint8_t *tmp = &g->tx_frame[TX_STORE]; /* not on the stack; after TX_APPLY */
    const tase_packet_desc_t *p = setup_desc(type);
    setup_copy(p, data, p->len, tmp, p->len, &g->setup[setup_off[type]]);
    (void)memcpy(&g->setup[setup_off[type]], tmp, setup_len[type]);
    if (type == SETUP_PACKET_RATE) {
        sched_from_rates(g, now_ms, false);
    }
}

int tase_gimbal_setup_set(tase_gimbal_t *g, uint8_t type, const uint8_t *data, size_t len,
                          uint32_t now_ms)
{
    if (g == NULL || data == NULL) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    if (type >= TASE_GIMBAL_SETUP_TYPES) {
        return TASE_EUNKNOWN;
    }
    if (len != setup_len[type]) {
        return TASE_ELENGTH;
    }
    setup_store(g, type, data, now_ms);
    return TASE_OK;
}

/* The setup type of packet id, or TASE_EUNKNOWN when it is not one. */
static int setup_type(uint16_t id)
{
    if (TASE_ID_GROUP(id) != TASE_GROUP_SETUP || TASE_ID_TYPE(id) >= TASE_GIMBAL_SETUP_TYPES) {
        return TASE_EUNKNOWN;
    }
    return TASE_ID_TYPE(id);
}

int tase_gimbal_setup_set_msg(tase_gimbal_t *g, uint16_t id, const void *msg, uint32_t now_ms)
{
    uint8_t data[SETUP_MAX];
    int type = setup_type(id);
    int n;
    if (g == NULL || msg == NULL) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    if (type < 0) {
        return type;
    }
    n = tase_packet_encode_data(id, msg, data, sizeof data);
    if (n < 0) {
        return n;
    }
    return tase_gimbal_setup_set(g, (uint8_t)type, data, (size_t)n, now_ms);
}

int tase_gimbal_setup_get_msg(const tase_gimbal_t *g, uint16_t id, void *msg)
{
    int type = setup_type(id);
    if (g == NULL || msg == NULL) {
        return TASE_EARG;
    }
    if (type < 0) {
        return type;
    }
    return tase_packet_decode_data(id, &g->setup[setup_off[type]], setup_len[type], msg);
}

/* Offer a received setting to the application (typed or as bytes); the
 * bytes it leaves in data are what will be stored. >= 0 accepts. */
static int apply_setup(tase_gimbal_t *g, unsigned port, uint8_t type, uint8_t *data, size_t len)
{
    uint16_t id = TASE_ID(TASE_GROUP_SETUP, type);
    tase_packet_msg_t *m = &g->msg; /* not on the stack (STACK in gimbal.h) */
    int r;
    if (g->app.apply_setup != NULL) {
        return g->app.apply_setup(g->app.user, port, type, data, len);
    }
    if (g->app.apply_setup_msg == NULL) {
        return 0;
    }
    /* Cannot fail: a known setup packet of its full length. */
    (void)tase_packet_decode_data(id, data, len, m);
    r = g->app.apply_setup_msg(g->app.user, port, id, m);
    if (r >= 0) {
        (void)tase_packet_encode_data(id, m, data, len);
    }
    return r;
}

/* Write echo e (a setup type, or ECHO_SHORT_AXIS for AXIS_SETTING in its
 * 22-byte layout) on port: what is in force now. */
TASE_NOINLINE_ static void send_echo(tase_gimbal_t *g, unsigned port, unsigned e)
{
    uint8_t type = e == ECHO_SHORT_AXIS ? SETUP_AXIS_SETTING : (uint8_t)e;
    const uint8_t *cur = &g->setup[setup_off[type]];
    size_t len = setup_len[type];
    if (e == ECHO_SHORT_AXIS) {
        /* laid out in the frame buffer, free outside tase_gimbal_poll() */
        len = (size_t)setup_len[type] - 1u;
        setup_copy(setup_desc(type), cur, setup_len[type], g->tx_frame, len, NULL);
        cur = g->tx_frame;
    }
    (void)gimbal_write(g, tase_port_send_frame(&g->port[port], TASE_GROUP_SETUP, type, cur, len));
}

/* Handle setup frame f: apply it. Returns the echo it owes (as
 * send_echo() takes it), or -1 for none; the caller writes it. */
static int handle_setup(tase_gimbal_t *g, unsigned port, const tase_frame_t *f, uint32_t now_ms)
{
    uint8_t type = f->type;
    const tase_packet_desc_t *p = setup_desc(type);
    bool short_axis = false;

    if (!tase_schema_length_ok(p, f->len)) {
        g->stats.bad_length++; /* SYSTEM_VERSION too (R3): 0 or 42 bytes */
        return -1;
    }
    if (f->len == 0 || type == SETUP_SYSTEM_VERSION) {
        g->stats.setup_queries++;
    } else if (p->len > SETUP_APPLY_MAX) {
        g->stats.bad_length++;
        return -1;
    } else {
        /* The application sees the settings asked for in the table's
         * layout: reserved bytes zero, "do not change" resolved. */
        uint8_t *tmp = &g->tx_frame[TX_APPLY];
        setup_copy(p, f->data, f->len, tmp, p->len, &g->setup[setup_off[type]]);
        if (apply_setup(g, port, type, tmp, p->len) >= 0) {
            setup_store(g, type, tmp, now_ms);
            g->stats.setup_applied++;
        } else {
            g->stats.setup_refused++;
        }
        short_axis = f->len != setup_len[type]; /* answered in the layout it came in */
    }
    /* The echo always carries what is in force when it is written. */
    return short_axis ? (int)ECHO_SHORT_AXIS : (int)type;
}

/* Handle one frame; returns the echo it owes (handle_setup()) or -1. */
TASE_NOINLINE_ static int handle(tase_gimbal_t *g, unsigned port, const tase_frame_t *frame,
                                 uint32_t now_ms)
{
    uint8_t outer = g->frame_port; /* a handler may hand over another frame */
    int echo = -1;
    g->stats.frames_rx++;
    g->frame_port = (uint8_t)port;
    if (frame->group == TASE_GROUP_SETUP && frame->type < TASE_GIMBAL_SETUP_TYPES) {
        if (port_present(g, port)) {
            echo = handle_setup(g, port, frame, now_ms);
        }
    } else if (g->app.dispatch != NULL) {
        tase_dispatch_frame(g->app.dispatch, frame);
    } else if (g->app.on_frame != NULL) {
        g->app.on_frame(g->app.user, port, frame);
    } else {
        /* nobody to tell */
    }
    g->frame_port = outer;
    return echo;
}

/* Handle one frame and write the echo it owes. */
static void handle_and_echo(tase_gimbal_t *g, unsigned port, const tase_frame_t *frame,
                            uint32_t now_ms)
{
    int e = handle(g, port, frame, now_ms);
    if (e >= 0) {
        send_echo(g, port, (unsigned)e);
    }
}

int tase_gimbal_handle_frame(tase_gimbal_t *g, unsigned port, const tase_frame_t *frame,
                             uint32_t now_ms)
{
    if (g == NULL || frame == NULL || frame->data == NULL || port >= TASE_GIMBAL_PORTS) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    g->busy = 1u; /* until its callbacks have returned */
    handle_and_echo(g, port, frame, now_ms);
    g->busy = 0u;
    return TASE_OK;
}

int tase_gimbal_frame_port(const tase_gimbal_t *g)
{
    if (g == NULL) {
        return TASE_EARG;
    }
    return g->frame_port == NO_FRAME ? TASE_ESTATE : (int)g->frame_port;
}

/* The receiver's callback inside tase_gimbal_feed(): the frame is noted
 * and the receiver stopped (tase_rx_stop()), so that the frame is handled
 * by tase_gimbal_feed() with the receiver's stack unwound. */
static void gimbal_rx(void *user, const tase_frame_t *frame)
{
    tase_gimbal_t *g = user;
    g->pending = *frame;
    (void)tase_rx_stop(&g->rx[g->feed_port]);
}

int tase_gimbal_feed(tase_gimbal_t *g, unsigned port, const uint8_t *bytes, size_t n,
                     uint32_t now_ms)
{
    tase_rx_t *rx;
    size_t done = 0;
    int frames = 0;
    bool tick = false;
    bool stopped = false;
    if (g == NULL) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    if (g->rx == NULL) {
        return TASE_ESTATE;
    }
    if (port >= g->nrx || (bytes == NULL && n > 0u)) {
        return TASE_EARG;
    }
    rx = &g->rx[port];
    {
        /* a receiver its feed would refuse (corrupted) changes nothing */
        int r = tase_rx_state_check(rx);
        if (r != TASE_OK) {
            return r;
        }
    }
    g->feed_port = (uint8_t)port;
    g->busy = 1u; /* until the last frame's callbacks have returned */
    /* Each frame ends the receiver's call (gimbal_rx()) and is handled
     * here, between calls; after it a 0-byte call goes on with the scan
     * (frame.h, tase_rx_stop()). The first call takes no byte when n is
     * 0. Then the time bound, the same way. */
    for (;;) {
        uint32_t in = rx->stats.bytes_in;
        size_t k = stopped ? 0u : n - done;
        int r;
        g->pending.data = NULL;
        if (tick) {
            /* the bytes' arrival, or (n == 0) a look that found the line quiet */
            r = tase_rx_tick(rx, now_ms, gimbal_rx, g);
        } else {
            r = tase_rx_feed(rx, k > 0u ? &bytes[done] : NULL, k, gimbal_rx, g);
        }
        if (r < 0) {
            frames = r; /* only after a callback damaged the receiver */
            break;
        }
        frames += r;
        done += (size_t)(rx->stats.bytes_in - in);
        stopped = g->pending.data != NULL;
        if (stopped) {
            handle_and_echo(g, port, &g->pending, now_ms);
        } else if (tick) {
            break;
        } else if (done == n) {
            tick = true;
        } else {
            /* more bytes to feed */
        }
    }
    g->busy = 0u;
    return frames;
}

/* Move a stream to the first slot strictly after now_ms (a late poll
 * passed some). Computed, not looped, so a long stall costs O(1). */
static void sched_catch_up(tase_gimbal_t *g, tase_gimbal_sched_t *s, uint32_t now_ms)
{
    uint32_t elapsed = now_ms - s->t0;
    uint32_t rem = elapsed % 1000u;
    uint32_t k = ((rem + 1u) * s->rate + 999u) / 1000u;

    /* Slots passed over, counted from the old anchor: whole seconds plus
     * the partial one, minus those already sent. */
    g->stats.slots_skipped += (elapsed / 1000u) * s->rate + k - s->k;
    s->t0 += elapsed - rem;
    if (k >= s->rate) {
        s->t0 += 1000u;
        k -= s->rate;
    }
    s->k = (uint16_t)k;
}

/* Ask the application for telemetry packet id and frame it in
 * g->tx_frame: the frame length, or < 0 to skip the slot. */
static int telemetry_frame(tase_gimbal_t *g, unsigned port, uint16_t id, uint32_t now_ms)
{
    uint8_t *frame = g->tx_frame;
    int n;
    if (g->app.fill_telemetry_msg != NULL) {
        (void)memset(&g->msg, 0, sizeof g->msg);
        n = g->app.fill_telemetry_msg(g->app.user, port, id, &g->msg, now_ms);
        return n < 0 ? n : tase_packet_encode(id, &g->msg, frame, sizeof g->tx_frame);
    }
    /* The application writes the data where the frame will carry it, and
     * the frame is encoded around it in place: one buffer, not two. */
    n = g->app.fill_telemetry(g->app.user, port, id, frame + TASE_FRAME_HEADER,
                              TASE_GIMBAL_TELEMETRY_MAX, now_ms);
    if (n < 0 || n > (int)TASE_GIMBAL_TELEMETRY_MAX) {
        return TASE_ERANGE;
    }
    if (!tase_schema_length_ok(tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id)), (size_t)n)) {
        return TASE_ELENGTH; /* a host would drop it as a wrong length */
    }
    return tase_frame_build(TASE_ID_GROUP(id), TASE_ID_TYPE(id), frame + TASE_FRAME_HEADER,
                            (size_t)n, frame, sizeof g->tx_frame);
}

/* One stream's due slot, if any. *failed: the port failed a write earlier
 * in this poll (the remaining slots are not attempted: a stuck port costs
 * one write bound per poll, not one per due frame); set on a failure. */
static int stream_poll(tase_gimbal_t *g, unsigned port, unsigned stream, uint32_t now_ms,
                       bool *failed)
{
    static const uint16_t stream_id[TASE_GIMBAL_STREAMS] = {
        TASE_ID_GIMBAL_ANGLE, TASE_ID_GIMBAL_RATE, TASE_ID_GEOREFERENCE_DATA};
    tase_gimbal_sched_t *s = &g->sched[port][stream];
    uint16_t id = stream_id[stream];
    int n;
    int sent = 0;
    uint32_t due;

    if (s->rate == 0) {
        return 0;
    }
    due = s->t0 + slot_ms(s->k, s->rate);
    if (!reached(now_ms, due)) {
        if (due - now_ms > SCHED_AHEAD_MAX_MS) {
            /* Never more than a second ahead in step with the clock: it
             * stepped back, or polls came 2^31 ms or more apart (the late
             * slot reads as one far ahead). Start over from now instead of
             * waiting (up to 24.8 days) for that time. */
            sched_start(s, s->rate, now_ms);
        }
        return 0;
    }
    if (*failed) {
        g->stats.slots_after_tx_error++;
    } else if (!within_budget(g, port, s)) {
        g->stats.slots_over_capacity++;
    } else {
        n = telemetry_frame(g, port, id, now_ms);
        if (n < 0) {
            g->stats.telemetry_skipped++;
        } else if (gimbal_write(g, tase_port_write_all(&g->port[port], g->tx_frame, (size_t)n)) >=
                   0) {
            g->stats.telemetry_tx++;
            sent = 1;
        } else {
            *failed = true; /* counted in tx_errors */
        }
    }
    if (++s->k >= s->rate) {
        s->k = 0;
        s->t0 += 1000u;
    }
    if (reached(now_ms, s->t0 + slot_ms(s->k, s->rate))) {
        sched_catch_up(g, s, now_ms);
    }
    return sent;
}

int tase_gimbal_poll(tase_gimbal_t *g, uint32_t now_ms)
{
    unsigned p;
    unsigned s;
    int sent = 0;

    if (g == NULL) {
        return TASE_EARG;
    }
    if (g->busy != 0u) {
        return busy_error(g);
    }
    if (g->app.fill_telemetry == NULL && g->app.fill_telemetry_msg == NULL) {
        return 0;
    }
    g->busy = 1u; /* until the last callback has returned */
    for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
        bool failed = false;
        if (!port_present(g, p)) {
            continue;
        }
        for (s = 0; s < TASE_GIMBAL_STREAMS; s++) {
            sent += stream_poll(g, p, s, now_ms, &failed);
        }
    }
    g->busy = 0u;
    return sent;
}

int tase_gimbal_service(tase_gimbal_t *g, uint32_t now_ms)
{
    uint8_t buf[SERVICE_CHUNK];
    unsigned p;
    unsigned i;

    if (g == NULL) {
        return TASE_EARG;
    }
    /* From a callback (busy): refused here, not only by the feeds below,
     * which would have read the bytes first */
    if (g->busy != 0u) {
        return busy_error(g);
    }
    /* Nothing is read before every port it would read has a receiver that
     * takes the bytes: none at all (TASE_ESTATE), or one its feed would
     * refuse, visibly corrupted (TASE_EARG): the bytes read were lost. */
    for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
        if (port_present(g, p) && g->port[p].ops->read != NULL) {
            int r = g->rx == NULL ? TASE_ESTATE : tase_rx_state_check(&g->rx[p]);
            if (r != TASE_OK) {
                return r;
            }
        }
    }
    for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
        if (!port_present(g, p) || g->port[p].ops->read == NULL) {
            continue;
        }
        for (i = 0; i < TASE_GIMBAL_SERVICE_READS; i++) {
            int n = g->port[p].ops->read(g->port[p].ctx, buf, sizeof buf, 0);
            /* More than asked: a broken port; skipped like a read error. */
            if (n < 0 || n > (int)sizeof buf) {
                break;
            }
            /* n == 0: nothing waiting, the receiver's time bound hears it */
            (void)tase_gimbal_feed(g, p, buf, (size_t)n, now_ms);
            if (n == 0) {
                break;
            }
        }
    }
    return tase_gimbal_poll(g, now_ms);
}
