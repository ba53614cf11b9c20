/*
 * Worst case per call of the send path (tase/port_io.h) and the roles
 * (tase/gimbal.h, tase/host.h), over an in-memory fake port: write()
 * copies what it is given to RAM and takes it all, read() serves scripted
 * bytes at once (at most what it is asked for), now_ms() is a constant.
 * The port's own cost is inside every count (PORT below says so in each
 * input).
 */
#include <string.h>

#include "../streams.h"
#include "tase/frame.h"
#include "tase/gimbal.h"
#include "tase/host.h"
#include "tase/port_io.h"
#include "timing.h"

#define NOW_MS 1000u /* the fake port's clock */
#define BYTES_PER_S 5760u
#define PORT "; the fake port's write() counted"
#define READS "; the fake port's read() and write() counted"

/* ---- the fake port ------------------------------------------------------ */

typedef struct {
    const uint8_t *in; /* what read() serves */
    size_t nin, rin;
    unsigned long written;
} fport_t;

static uint8_t tx_ram[TASE_FRAME_MAX]; /* where written bytes go */

static int f_write(void *ctx, const uint8_t *d, size_t n)
{
    fport_t *f = ctx;
    (void)memcpy(tx_ram, d, n < sizeof(tx_ram) ? n : sizeof(tx_ram));
    f->written += n;
    return (int)n;
}

static int f_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    fport_t *f = ctx;
    size_t k = f->nin - f->rin;
    (void)timeout_ms;
    if (k > cap) {
        k = cap;
    }
    (void)memcpy(buf, f->in + f->rin, k);
    f->rin += k;
    return (int)k;
}

static uint32_t f_now(void *ctx)
{
    (void)ctx;
    return NOW_MS;
}

static const tase_port_ops_t fops = {f_write, f_read, f_now};

static uint8_t payload[TASE_DATA_MAX];    /* 253 data bytes */
static uint8_t big_frame[TASE_FRAME_MAX]; /* their frame, 0x00/0x42 */
/* The worst of `call` over every packet's longest message. */
static void roles_per_packet(const char *fn, bool (*prep)(const tase_packet_desc_t *p),
                             measure_fn setup, measure_fn call, const char *how)
{
    worst_t w = {0, ""};
    over_packets(&w, prep, setup, call);
    worst_report(fn, &w, how);
}

/* ---- port_io ------------------------------------------------------------ */

static fport_t fp;
static const tase_port_t port = {&fops, &fp, BYTES_PER_S};
static uint32_t a_now, a_since, a_sent, a_errors;
static int a_r;

MEASURED(c_write_all, tase_port_write_all(&port, big_frame, sizeof(big_frame)))
MEASURED(c_send_frame, tase_port_send_frame(&port, 0x00u, 0x42u, payload, sizeof(payload)))
MEASURED(c_send_msg, tase_port_send_msg(&port, cur_pkt->id, &full_msg))
MEASURED(c_elapsed, tase_port_elapsed_ms(a_now, a_since))
MEASURED(c_count_tx, tase_port_count_tx(a_r, &a_sent, &a_errors))

static void port_io(void)
{
    static const int results[] = {261, TASE_EIO, TASE_ENOBUFS, TASE_EARG, TASE_EUNKNOWN};
    worst_t w = {0, ""};
    size_t i;
    report("tase_port_write_all", measure_plain(c_write_all), "261 bytes (a whole frame)" PORT);
    report("tase_port_send_frame", measure_plain(c_send_frame), "253 data bytes" PORT);
    roles_per_packet("tase_port_send_msg", prep_full_frame, nothing, c_send_msg,
                     ", every member set" PORT);
    for (i = 0; i < 2u; i++) {
        a_since = 5000u;
        a_now = i == 0u ? 7000u : 3000u;
        worst_try(&w, measure_plain(c_elapsed), "%s", i == 0u ? "2 s elapsed" : "a stale sample");
    }
    worst_report("tase_port_elapsed_ms", &w, "");
    w.insns = 0;
    for (i = 0; i < sizeof(results) / sizeof(results[0]); i++) {
        a_r = results[i];
        worst_try(&w, measure_plain(c_count_tx), "r = %d", a_r);
    }
    worst_report("tase_port_count_tx", &w, ", both counters given");
}

/* ---- gimbal ------------------------------------------------------------- */

static tase_gimbal_t g, g_snap;
static tase_rx_t grx[TASE_GIMBAL_PORTS], grx_snap[TASE_GIMBAL_PORTS];
static fport_t gfp[TASE_GIMBAL_PORTS], gfp_snap[TASE_GIMBAL_PORTS];
static tase_port_t gports[TASE_GIMBAL_PORTS];
static uint8_t setup_frame[TASE_FRAME_MAX], worst_setup[TASE_FRAME_MAX];
static size_t setup_n, worst_setup_n;
static tase_frame_t setup_f;
static uint8_t setup_data[64];
static uint8_t a_type;
static uint16_t a_id;
static uint32_t a_poll_now;

static int apply_bytes(void *user, unsigned p, uint8_t type, uint8_t *data, size_t len)
{
    (void)user;
    (void)p;
    (void)type;
    (void)data;
    timing_sink += len;
    return 0;
}

static int fill_bytes(void *user, unsigned p, uint16_t id, uint8_t *data, size_t cap,
                      uint32_t now_ms)
{
    size_t n = id == TASE_ID_GIMBAL_ANGLE ? 6u : id == TASE_ID_GIMBAL_RATE ? 18u : 63u;
    (void)user;
    (void)p;
    (void)cap;
    (void)now_ms;
    (void)memset(data, 0xA5, n);
    return (int)n;
}

static int fill_msg(void *user, unsigned p, uint16_t id, void *msg, uint32_t now_ms)
{
    (void)user;
    (void)p;
    (void)msg;
    timing_sink += id + now_ms;
    return 0;
}

static int apply_msg(void *user, unsigned p, uint16_t id, void *msg)
{
    (void)user;
    (void)p;
    (void)msg;
    timing_sink += id;
    return 0;
}

static void on_gframe(void *user, unsigned p, const tase_frame_t *f)
{
    (void)user;
    (void)p;
    timing_sink += f->len;
}

static const tase_gimbal_app_t app_typed = {
    .on_frame = on_gframe, .fill_telemetry_msg = fill_msg, .apply_setup_msg = apply_msg};
static const tase_gimbal_app_t app_bytes = {
    .apply_setup = apply_bytes, .fill_telemetry = fill_bytes, .on_frame = on_gframe};
static const tase_gimbal_app_t *const apps[2] = {&app_typed, &app_bytes};
static const char *const app_names[2] = {"typed callbacks", "byte callbacks"};

/* g_snap: three fake ports with receivers, app, initialised at 0 ms. */
static void gimbal_snapshot(const tase_gimbal_app_t *app)
{
    size_t i;
    for (i = 0; i < TASE_GIMBAL_PORTS; i++) {
        gports[i].ops = &fops;
        gports[i].ctx = &gfp[i];
        gports[i].bytes_per_s = BYTES_PER_S;
    }
    memset(gfp, 0, sizeof(gfp));
    (void)tase_gimbal_init(&g, gports, grx, TASE_GIMBAL_PORTS, app, 0u);
    g_snap = g;
    memcpy(grx_snap, grx, sizeof(grx));
    memcpy(gfp_snap, gfp, sizeof(gfp));
}

static void restore_g(void *ctx)
{
    (void)ctx;
    g = g_snap;
    memcpy(grx, grx_snap, sizeof(grx));
    memcpy(gfp, gfp_snap, sizeof(gfp));
}

MEASURED(c_ginit, tase_gimbal_init(&g, gports, grx, TASE_GIMBAL_PORTS, &app_typed, 0u))
MEASURED(c_gfeed, tase_gimbal_feed(&g, 0u, setup_frame, setup_n, 0u))
MEASURED(c_ghandle, tase_gimbal_handle_frame(&g, 0u, &setup_f, 0u))
MEASURED(c_gpoll, tase_gimbal_poll(&g, a_poll_now))
MEASURED(c_gservice, tase_gimbal_service(&g, a_poll_now))
MEASURED(c_gsend, tase_gimbal_send(&g, 2u, 0x00u, 0x42u, payload, sizeof(payload)))
MEASURED(c_gsend_msg, tase_gimbal_send_msg(&g, 2u, cur_pkt->id, &full_msg))
MEASURED(c_gset,
         tase_gimbal_setup_set(&g, a_type, setup_data, (size_t)tase_gimbal_setup_len(a_type), 0u))
MEASURED(c_gset_msg, tase_gimbal_setup_set_msg(&g, a_id, &full_msg, 0u))
MEASURED(c_gget, tase_gimbal_setup_get(&g, a_type, setup_data, sizeof(setup_data)))
MEASURED(c_gget_msg, tase_gimbal_setup_get_msg(&g, a_id, &full_msg))
MEASURED(c_gcapacity, tase_gimbal_set_capacity(&g, 2u, 0u))
MEASURED(c_gsetup_len, tase_gimbal_setup_len(a_type))
MEASURED(c_gframe_port, tase_gimbal_frame_port(&g))

/* Every setup packet (each length it takes, data bytes 0x01 or all "do
 * not change" 0xFF) fed as one frame and handed over, with either form
 * of the callbacks: applied (or a query answered) and echoed. */
static void gimbal_setups(void)
{
    worst_t wf = {0, ""}, wh = {0, ""};
    unsigned a, t, l, fill;
    for (a = 0; a < 2u; a++) {
        gimbal_snapshot(apps[a]);
        for (t = 0; t < TASE_GIMBAL_SETUP_TYPES; t++) {
            const tase_packet_desc_t *p = tase_schema_find(0x48u, (uint8_t)t);
            size_t lens[3] = {p->len, 0u, p->len - 1u};
            for (l = 0; l < 3u; l++) {
                if (!tase_schema_length_ok(p, lens[l])) {
                    continue;
                }
                for (fill = 0; fill < 2u; fill++) {
                    unsigned long e;
                    int n;
                    memset(setup_data, fill == 0u ? 0x01 : 0xFF, sizeof(setup_data));
                    n = tase_frame_build(0x48u, (uint8_t)t, setup_data, lens[l], setup_frame,
                                         sizeof(setup_frame));
                    setup_n = (size_t)n;
                    setup_f.offset = 0u;
                    setup_f.group = 0x48u;
                    setup_f.type = (uint8_t)t;
                    setup_f.len = (uint8_t)lens[l];
                    setup_f.data = &setup_frame[TASE_FRAME_HEADER];
                    e = measure_exact(restore_g, c_gfeed, NULL);
                    if (e > wf.insns) {
                        memcpy(worst_setup, setup_frame, setup_n);
                        worst_setup_n = setup_n;
                    }
                    worst_try(&wf, e, "%s setup frame, %lu data bytes of 0x%02X, %s",
                              tase_schema_packet_name(p), (unsigned long)lens[l],
                              fill == 0u ? 0x01u : 0xFFu, app_names[a]);
                    worst_try(&wh, measure_exact(restore_g, c_ghandle, NULL),
                              "%s setup frame, %lu data bytes of 0x%02X, %s",
                              tase_schema_packet_name(p), (unsigned long)lens[l],
                              fill == 0u ? 0x01u : 0xFFu, app_names[a]);
                }
            }
        }
    }
    /* A review's input: the same frame when an earlier call left a held
     * false candidate (00 FF 5A FF) with 8 copies of the frame inside it:
     * the frame fails the candidate, and all 9 are applied and echoed. */
    for (a = 0; a < 2u; a++) {
        static uint8_t pre[4u + 8u * TASE_FRAME_MAX];
        static const uint8_t sync4[4] = {0x00, 0xFF, 0x5A, 0xFF};
        size_t n = 0, i;
        memcpy(pre, sync4, sizeof(sync4));
        n = sizeof(sync4);
        for (i = 0; i < 8u; i++) {
            memcpy(&pre[n], worst_setup, worst_setup_n);
            n += worst_setup_n;
        }
        gimbal_snapshot(apps[a]);
        restore_g(NULL);
        (void)tase_gimbal_feed(&g, 0u, pre, n, 0u);
        g_snap = g;
        memcpy(grx_snap, grx, sizeof(grx));
        memcpy(gfp_snap, gfp, sizeof(gfp));
        memcpy(setup_frame, worst_setup, worst_setup_n);
        setup_n = worst_setup_n;
        worst_try(&wf, measure_exact(restore_g, c_gfeed, NULL),
                  "the costliest single setup frame, after an earlier call left 00 FF 5A FF "
                  "and 8 copies of it held (all 9 applied and echoed), %s",
                  app_names[a]);
    }
    worst_report("tase_gimbal_feed", &wf, ", the whole frame in one call: applied and echoed" PORT);
    worst_report("tase_gimbal_handle_frame", &wh, ": applied and echoed" PORT);
}

/* The set-ups tase_gimbal_poll() is measured in: 0 the default rates
 * (10/10/4) at the bench's port rate (within capacity); 1 rate 255 on all
 * nine streams with unlimited capacity (every due slot written: a review
 * found the M0+ worst there, the bench's ports skip most slots of 255 at
 * their rate cheaply). g_snap is taken again after it. */
static const char *const poll_cfgs[2] = {"default rates on 3 ports",
                                         "rate 255 on all 9 streams, capacity unlimited"};

static void gimbal_config(unsigned cfg)
{
    if (cfg == 1u) {
        uint8_t r[16];
        unsigned p;
        memset(r, 0, sizeof(r));
        for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
            memset(&r[p * 5u], 255, 3u);
            (void)tase_gimbal_set_capacity(&g, p, UINT32_MAX);
        }
        (void)tase_gimbal_setup_set(&g, 0x00u, r, sizeof(r), 0u);
        g_snap = g;
    }
}

/* Telemetry due on every port, polled at several moments after init (late
 * ones skip slots too; a day late, the catch-up's division is longest). */
static void gimbal_poll(uint32_t *worst_now, unsigned *worst_app, unsigned *worst_cfg)
{
    static const uint32_t moments[] = {100u, 250u, 1000u, 1250u, 100000u, 86400000u};
    worst_t w = {0, ""};
    unsigned a, m, c;
    for (c = 0; c < 2u; c++) {
        for (a = 0; a < 2u; a++) {
            gimbal_snapshot(apps[a]);
            gimbal_config(c);
            for (m = 0; m < sizeof(moments) / sizeof(moments[0]); m++) {
                unsigned long e;
                a_poll_now = moments[m];
                e = measure_exact(restore_g, c_gpoll, NULL);
                if (e > w.insns) {
                    *worst_now = moments[m];
                    *worst_app = a;
                    *worst_cfg = c;
                }
                worst_try(&w, e, "%lu ms after init, %s, %s", (unsigned long)moments[m],
                          poll_cfgs[c], app_names[a]);
            }
        }
    }
    worst_report("tase_gimbal_poll", &w, PORT);
}

/* Each port's read() has as many bytes waiting as tase_gimbal_service()
 * reads from a port in one call (TASE_GIMBAL_SERVICE_READS reads of 64
 * bytes, tase/config.h: 4096 at the default): back-to-back copies of the
 * costliest setup frame of gimbal_setups(), or the receiver's adversarial
 * streams; then the poll. */
static void gimbal_service(uint32_t now, unsigned app, unsigned cfg)
{
    static uint8_t script[TASE_GIMBAL_SERVICE_READS * 64u];
    static const char *const streams[] = {"held255", "syncrand", "halfsum"};
    worst_t w = {0, ""};
    size_t i, s;
    for (s = 0; s <= sizeof(streams) / sizeof(streams[0]); s++) {
        if (s == 0u) {
            for (i = 0; i + worst_setup_n <= sizeof(script); i += worst_setup_n) {
                memcpy(&script[i], worst_setup, worst_setup_n);
            }
            memset(&script[i], 0, sizeof(script) - i);
        } else {
            (void)bench_stream(streams[s - 1u], script, sizeof(script));
        }
        gimbal_snapshot(apps[app]);
        gimbal_config(cfg);
        for (i = 0; i < TASE_GIMBAL_PORTS; i++) {
            gfp_snap[i].in = script;
            gfp_snap[i].nin = sizeof(script);
        }
        a_poll_now = now;
        worst_try(&w, measure_exact(restore_g, c_gservice, NULL),
                  "at %lu ms (tase_gimbal_poll's worst moment), %s, %lu bytes waiting on each "
                  "of 3 ports (%s), %s, then the telemetry due",
                  (unsigned long)now, poll_cfgs[cfg], (unsigned long)sizeof(script),
                  s == 0u ? "back-to-back copies of tase_gimbal_feed's worst setup frame"
                          : streams[s - 1u],
                  app_names[app]);
    }
    worst_report("tase_gimbal_service", &w, READS);
}

static bool prep_setup_msg(const tase_packet_desc_t *p)
{
    if (TASE_ID_GROUP(p->id) != 0x48u) {
        return false;
    }
    a_id = p->id;
    cur_len = fill_full_msg(p);
    return true;
}

static void gimbal_setup_calls(void)
{
    worst_t ws = {0, ""}, wg = {0, ""}, wl = {0, ""};
    unsigned t, fill;
    gimbal_snapshot(&app_typed);
    for (t = 0; t < TASE_GIMBAL_SETUP_TYPES; t++) {
        const char *name = tase_schema_packet_name(tase_schema_find(0x48u, (uint8_t)t));
        a_type = (uint8_t)t;
        for (fill = 0; fill < 2u; fill++) {
            memset(setup_data, fill == 0u ? 0x01 : 0xFF, sizeof(setup_data));
            worst_try(&ws, measure_exact(restore_g, c_gset, NULL), "%s, data bytes 0x%02X", name,
                      fill == 0u ? 0x01u : 0xFFu);
        }
        worst_try(&wg, measure_exact(restore_g, c_gget, NULL), "%s", name);
        worst_try(&wl, measure_plain(c_gsetup_len), "type %u", t);
    }
    worst_report("tase_gimbal_setup_set", &ws, "");
    worst_report("tase_gimbal_setup_get", &wg, "");
    worst_report("tase_gimbal_setup_len", &wl, "");
    roles_per_packet("tase_gimbal_setup_set_msg", prep_setup_msg, restore_g, c_gset_msg,
                     ", members 0xA5");
    roles_per_packet("tase_gimbal_setup_get_msg", prep_setup_msg, restore_g, c_gget_msg, "");
}

static void gimbal(void)
{
    uint32_t now = 0;
    unsigned app = 0, cfg = 0;
    size_t i;
    for (i = 0; i < TASE_GIMBAL_PORTS; i++) {
        gports[i].ops = &fops;
        gports[i].ctx = &gfp[i];
        gports[i].bytes_per_s = BYTES_PER_S;
    }
    report("tase_gimbal_init", measure_plain(c_ginit),
           "3 ports with receivers, typed callbacks (every receiver initialised)");
    gimbal_setups();
    gimbal_poll(&now, &app, &cfg);
    gimbal_service(now, app, cfg);
    gimbal_snapshot(&app_typed);
    report("tase_gimbal_send", measure_exact(restore_g, c_gsend, NULL), "253 data bytes" PORT);
    roles_per_packet("tase_gimbal_send_msg", prep_full_frame, restore_g, c_gsend_msg,
                     ", every member set" PORT);
    gimbal_setup_calls();
    report("tase_gimbal_set_capacity", measure_exact(restore_g, c_gcapacity, NULL),
           "0: back to the port's default, pacing restarted");
    report("tase_gimbal_frame_port", measure_plain(c_gframe_port), "any state");
}

/* ---- host --------------------------------------------------------------- */

static tase_host_t h, h_snap, h_pre;
static fport_t hfp, hfp_snap;
static const tase_port_t hport = {&fops, &hfp, BYTES_PER_S};
static uint8_t reply[TASE_DATA_MAX];
static tase_packet_msg_t reply_msg;
static bool a_typed;

static void on_hframe(void *user, const tase_frame_t *f)
{
    (void)user;
    timing_sink += f->len;
}

static void restore_h(void *ctx)
{
    (void)ctx;
    h = h_snap;
    hfp = hfp_snap;
}

/* h_snap: an idle host on the fake port. */
static void host_snapshot(void)
{
    memset(&hfp, 0, sizeof(hfp));
    (void)tase_host_init(&h_snap, &hport, on_hframe, NULL);
    hfp_snap = hfp;
}

MEASURED(c_hinit, tase_host_init(&h, &hport, on_hframe, NULL))
MEASURED(c_hsend, tase_host_send(&h, 0x00u, 0x42u, payload, sizeof(payload)))
MEASURED(c_hsend_msg, tase_host_send_msg(&h, cur_pkt->id, &full_msg))
/* Requests without retries: a CAMERA_PASS (the longest, 253 data bytes)
 * may not have any (host.h: a re-send would repeat camera bytes), and the
 * cost of a start does not depend on them. The re-send is measured with
 * the longest packet that may be re-sent, a setup packet (AXIS_SETTING,
 * 23 bytes). */
MEASURED(c_hrequest, tase_host_request_start(&h, 0x00u, 0x42u, payload, sizeof(payload), reply,
                                             sizeof(reply), 100u, 0u, NOW_MS))
MEASURED(c_hrequest_setup, tase_host_request_start(&h, 0x48u, 0x02u, payload, 23u, reply,
                                                   sizeof(reply), 100u, 3u, NOW_MS))
MEASURED(c_hrequest_msg,
         tase_host_request_msg_start(&h, cur_pkt->id, &full_msg, &reply_msg, 100u, 0u, NOW_MS))
MEASURED(c_hquery, tase_host_query_start(&h, 0x48u, 0x03u, reply, sizeof(reply), 100u, 3u, NOW_MS))
MEASURED(c_hpoll, tase_host_poll(&h, NOW_MS + 100u))
MEASURED(c_hfeed, tase_host_feed(&h, pkt_frame, pkt_frame_n, NOW_MS))
MEASURED(c_hhandle, tase_host_handle_frame(&h, &pkt_f))
MEASURED(c_hservice, tase_host_service(&h, 100u))
MEASURED(c_hbusy, tase_host_busy(&h))
MEASURED(c_hcancel, tase_host_cancel(&h))
MEASURED(c_htransact, tase_host_transact(&h, 0x00u, 0x42u, payload, sizeof(payload), reply,
                                         sizeof(reply), 100u, 0u))
MEASURED(c_htransact_msg, tase_host_transact_msg(&h, cur_pkt->id, &full_msg, &reply_msg, 100u, 0u))

/* A pending request for cur_pkt (typed, its longest message) whose reply
 * is the packet's longest frame. */
static bool prep_reply(const tase_packet_desc_t *p)
{
    int r;
    if (!prep_full_frame(p) || cur_len == 0u) {
        return false; /* a zero-length frame is never a reply */
    }
    host_snapshot();
    h = h_snap;
    if (a_typed) {
        r = tase_host_request_msg_start(&h, p->id, &full_msg, &reply_msg, 100u, 0u, NOW_MS);
    } else {
        r = tase_host_request_start(&h, pkt_f.group, pkt_f.type, pkt_f.data, cur_len, reply,
                                    sizeof(reply), 100u, 0u, NOW_MS);
    }
    h_snap = h;
    return r == TASE_OK; /* what the gimbal does not answer cannot be requested */
}

/* A transaction whose reply (cur_pkt's longest frame) the port has
 * waiting. */
static bool prep_transact(const tase_packet_desc_t *p)
{
    if (!prep_full_frame(p) || cur_len == 0u) {
        return false; /* never answered: the transaction would wait forever */
    }
    host_snapshot();
    hfp_snap.in = pkt_frame;
    hfp_snap.nin = pkt_frame_n;
    return true;
}

/* A reply to a request for cur_pkt, fed or handed over: the worst over
 * typed requests and raw ones. */
static void host_replies(void)
{
    worst_t wf = {0, ""}, wh = {0, ""};
    unsigned k;
    for (k = 0; k < 2u; k++) {
        worst_t f = {0, ""}, hf = {0, ""};
        a_typed = k == 0u;
        over_packets(&f, prep_reply, restore_h, c_hfeed);
        over_packets(&hf, prep_reply, restore_h, c_hhandle);
        worst_try(&wf, f.insns, "%s reply frame completing a pending %s request", f.input,
                  a_typed ? "typed" : "raw");
        worst_try(&wh, hf.insns, "%s reply completing a pending %s request", hf.input,
                  a_typed ? "typed" : "raw");
    }
    /* A review's input: a typed request pending, the receiver left with
     * halfsum's first 320 bytes by an earlier call, then the reply (it
     * still completes the request): the longest reply, CAMERA_PASS (the
     * review's GEOREFERENCE_DATA can no longer be requested). */
    {
        static uint8_t pre[320];
        a_typed = true;
        cur_pkt = tase_schema_find(0x00u, 0x42u);
        if (cur_pkt != NULL && prep_reply(cur_pkt)) {
            size_t n = bench_stream("halfsum", pre, sizeof(pre)); /* one 320-byte period */
            h = h_snap;
            (void)tase_host_feed(&h, pre, n, NOW_MS);
            h_snap = h;
            worst_try(&wf, measure_exact(restore_h, c_hfeed, NULL),
                      "CAMERA_PASS reply frame (253 data bytes) completing a pending typed request, "
                      "after an earlier call fed halfsum's first 320 bytes");
        }
    }
    worst_report("tase_host_feed", &wf, ", the whole frame in one call");
    worst_report("tase_host_handle_frame", &wh, "");
}

/* One service() read of 64 bytes from every state that feeding whole
 * 64-byte chunks of a stream leaves: coarse on all, exact on the top. */
static void host_service(void)
{
    static uint8_t script[4096];
    static uint16_t coarse[sizeof(script) / 64u];
    static const char *const streams[] = {"held255", "syncrand", "burst", "halfsum"};
    worst_t w = {0, ""};
    size_t s, k, pass;
    for (s = 0; s < sizeof(streams) / sizeof(streams[0]); s++) {
        uint16_t top = 0;
        (void)bench_stream(streams[s], script, sizeof(script));
        for (pass = 0; pass < 2u; pass++) {
            host_snapshot();
            h_pre = h_snap;
            for (k = 0; k < sizeof(coarse) / sizeof(coarse[0]); k++) {
                h_snap = h_pre;
                hfp_snap.in = &script[k * 64u];
                hfp_snap.nin = 64u;
                if (pass == 0u) {
                    uint32_t t0;
                    restore_h(NULL);
                    t0 = measure_ticks();
                    c_hservice(NULL);
                    coarse[k] = (uint16_t)(t0 - measure_ticks());
                    top = coarse[k] > top ? coarse[k] : top;
                } else if (coarse[k] + 1u >= top) {
                    worst_try(&w, measure_exact(restore_h, c_hservice, NULL),
                              "a 64-byte read: bytes %lu..%lu of %s", (unsigned long)(k * 64u),
                              (unsigned long)(k * 64u + 63u), streams[s]);
                }
                (void)tase_host_feed(&h_pre, &script[k * 64u], 64u, NOW_MS);
            }
        }
    }
    worst_report("tase_host_service", &w, ", each fed after the bytes before it" READS);
}

/* tase_host_poll() with the request `start` makes pending (its attempt
 * then times out), as one candidate for the worst case. */
static void host_poll_pending(worst_t *w, measure_fn start, const char *input)
{
    host_snapshot();
    h = h_snap;
    start(NULL);
    h_snap = h;
    worst_try(w, measure_exact(restore_h, c_hpoll, NULL), "%s", input);
}

static void host(void)
{
    report("tase_host_init", measure_plain(c_hinit), "a port with byte rate 5760 B/s");
    host_snapshot();
    report("tase_host_send", measure_exact(restore_h, c_hsend, NULL), "253 data bytes" PORT);
    roles_per_packet("tase_host_send_msg", prep_full_frame, restore_h, c_hsend_msg,
                     ", every member set" PORT);
    host_snapshot();
    report("tase_host_request_start", measure_exact(restore_h, c_hrequest, NULL),
           "253 data bytes, idle host" PORT);
    roles_per_packet("tase_host_request_msg_start", prep_full_frame, restore_h, c_hrequest_msg,
                     ", every member set, idle host" PORT);
    host_snapshot();
    report("tase_host_query_start", measure_exact(restore_h, c_hquery, NULL),
           "SYSTEM_VERSION query, idle host" PORT);
    /* a pending request whose attempt timed out: the longest that may be
     * re-sent (re-sent), and the longest (a 253-byte CAMERA_PASS, failed) */
    {
        worst_t w = {0, ""};
        host_poll_pending(&w, c_hrequest_setup,
                          "the attempt of a pending AXIS_SETTING request (23 bytes) timed out: "
                          "re-sent");
        host_poll_pending(&w, c_hrequest,
                          "the one attempt of a pending 253-byte CAMERA_PASS request timed out: "
                          "failed");
        worst_report("tase_host_poll", &w, PORT);
    }
    report("tase_host_busy", measure_exact(restore_h, c_hbusy, NULL),
           "a request pending (253-byte CAMERA_PASS)");
    report("tase_host_cancel", measure_exact(restore_h, c_hcancel, NULL),
           "a request pending (253-byte CAMERA_PASS)");
    host_replies();
    host_service();
    host_snapshot();
    hfp_snap.in = big_frame;
    hfp_snap.nin = sizeof(big_frame);
    report("tase_host_transact", measure_exact(restore_h, c_htransact, NULL),
           "253 data bytes out, the port answers at once with 253 (five reads)" READS);
    roles_per_packet("tase_host_transact_msg", prep_transact, restore_h, c_htransact_msg,
                     ", every member set, the port answers at once with the same" READS);
}

void timing_roles(void)
{
    memset(payload, 0xA5, sizeof(payload));
    (void)tase_frame_build(0x00u, 0x42u, payload, sizeof(payload), big_frame, sizeof(big_frame));
    port_io();
    gimbal();
    host();
}
