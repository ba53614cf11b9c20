/*
 * Worst case per call of the send path (tase/port_io.h) and the roles
 * (tase/gimbal.h, tase/host.h), over an in-memory fake port: write()
 * copies what it is given to RAM and takes it all, read() serves scripted
 * bytes at once (at most what it is asked for), now_ms() is a constant.
 * The port's own cost is inside every count (PORT below says so in each
 * input). Two variants of it make the ".../bytewise" rows (write() takes
 * 1 byte a call, read() hands over 1 byte a call: a driver without a
 * queue) and the ".../stalled" ones (write() takes nothing, or read()
 * returns nothing at once, while the clock stands still: the loops run
 * to TASE_PORT_WRITE_SPINS, tase/config.h; timed once).
 */
#include <stdio.h>
#include <string.h>

#include "../streams.h"
#include "tase/flags.h"
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
    unsigned long after; /* in comes once this many bytes were written (0: at once) */
    const uint8_t *pre;  /* served first, at once: what waited before a request */
    size_t npre, rpre;
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
    size_t k;
    (void)timeout_ms;
    if (f->rpre < f->npre) {
        k = f->npre - f->rpre;
        k = k > cap ? cap : k;
        (void)memcpy(buf, f->pre + f->rpre, k);
        f->rpre += k;
        return (int)k;
    }
    if (f->written < f->after) {
        return 0; /* the answer comes once the request went out */
    }
    k = f->nin - f->rin;
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

/* The bytewise port: write() takes 1 byte a call, read() hands over 1
 * byte a call. */
static int f_write1(void *ctx, const uint8_t *d, size_t n)
{
    return f_write(ctx, d, n < 1u ? n : 1u);
}

static int f_read1(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    return f_read(ctx, buf, cap < 1u ? cap : 1u, timeout_ms);
}

static const tase_port_ops_t fops1 = {f_write1, f_read1, f_now};

/* The stalled writer: write() takes nothing (a queue that stays full). */
static int f_write0(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    (void)d;
    (void)n;
    return 0;
}

static const tase_port_ops_t fops0 = {f_write0, f_read, f_now};

#define BYTEWISE "; the fake port's write() takes 1 byte a call"
#define STALLED ", the fake port's clock standing still; timed once, to 40 instructions"

/* 253 data bytes (0xA5) and their frame (0x00/0x42), both at an address
 * 0..3 mod 4 (place_payload(); the C library's copies take other paths
 * at other alignments). */
static uint8_t payload_mem[TASE_DATA_MAX + 4u] __attribute__((aligned(4)));
static uint8_t frame_mem[TASE_FRAME_MAX + 4u] __attribute__((aligned(4)));
static const uint8_t *payload = payload_mem;
static const uint8_t *big_frame = frame_mem;

static void place_payload(size_t off)
{
    memset(payload_mem, 0xA5, sizeof(payload_mem));
    (void)tase_frame_build(0x00u, 0x42u, &payload_mem[off], TASE_DATA_MAX, &frame_mem[off],
                           TASE_FRAME_MAX);
    payload = &payload_mem[off];
    big_frame = &frame_mem[off];
}

/* `call` after `setup` with the payload and its frame at each address
 * 0..3 mod 4: the worst, reported as fn. */
static void at_each_address(const char *fn, measure_fn setup, measure_fn call, const char *what,
                            const char *how)
{
    worst_t w = {0, ""};
    size_t off;
    for (off = 0; off < 4u; off++) {
        place_payload(off);
        worst_try(&w, measure_exact(setup, call, NULL), "%s at an address %lu mod 4", what,
                  (unsigned long)off);
    }
    place_payload(0u);
    worst_report(fn, &w, how);
}
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
static const tase_port_t port1 = {&fops1, &fp, BYTES_PER_S};
static const tase_port_t port0 = {&fops0, &fp, BYTES_PER_S};
static uint32_t a_now, a_since, a_sent, a_errors;
static int a_r;

MEASURED(c_write_all, tase_port_write_all(&port, big_frame, TASE_FRAME_MAX))
MEASURED(c_send_frame, tase_port_send_frame(&port, 0x00u, 0x42u, payload, TASE_DATA_MAX))
MEASURED(c_send_msg, tase_port_send_msg(&port, cur_pkt->id, &full_msg))
MEASURED(c_elapsed, tase_port_elapsed_ms(a_now, a_since))
MEASURED(c_count_tx, tase_port_count_tx(a_r, &a_sent, &a_errors))
MEASURED(c_write_all1, tase_port_write_all(&port1, big_frame, TASE_FRAME_MAX))
MEASURED(c_send_frame1, tase_port_send_frame(&port1, 0x00u, 0x42u, payload, TASE_DATA_MAX))
MEASURED(c_send_msg1, tase_port_send_msg(&port1, cur_pkt->id, &full_msg))
MEASURED(c_write_all0, tase_port_write_all(&port0, big_frame, TASE_FRAME_MAX))

static void port_io(void)
{
    static const int results[] = {261, TASE_EIO, TASE_ENOBUFS, TASE_EARG, TASE_EUNKNOWN};
    worst_t w = {0, ""};
    size_t i;
    at_each_address("tase_port_write_all", nothing, c_write_all, "261 bytes (a whole frame)", PORT);
    at_each_address("tase_port_send_frame", nothing, c_send_frame, "253 data bytes", PORT);
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
    at_each_address("tase_port_write_all/bytewise", nothing, c_write_all1,
                    "261 bytes (a whole frame)", ", in 261 calls" BYTEWISE);
    at_each_address("tase_port_send_frame/bytewise", nothing, c_send_frame1, "253 data bytes",
                    BYTEWISE);
    roles_per_packet("tase_port_send_msg/bytewise", prep_full_frame, nothing, c_send_msg1,
                     ", every member set" BYTEWISE);
    w.insns = 0;
    worst_try(&w, measure_once(nothing, c_write_all0, NULL),
              "261 bytes, write() taking nothing: TASE_PORT_WRITE_SPINS (%lu) calls, then "
              "TASE_EAGAIN",
              (unsigned long)TASE_PORT_WRITE_SPINS);
    worst_report("tase_port_write_all/stalled", &w, STALLED);
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
static const uint8_t *feed_frame; /* setup_frame, in a variable as a caller's */
MEASURED(c_gfeed, tase_gimbal_feed(&g, 0u, feed_frame, setup_n, 0u))
MEASURED(c_ghandle, tase_gimbal_handle_frame(&g, 0u, &setup_f, 0u))
MEASURED(c_gpoll, tase_gimbal_poll(&g, a_poll_now))
MEASURED(c_gservice, tase_gimbal_service(&g, a_poll_now))
MEASURED(c_gsend, tase_gimbal_send(&g, 2u, 0x00u, 0x42u, payload, TASE_DATA_MAX))
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
                    feed_frame = setup_frame;
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

/* The set-ups tase_gimbal_poll() is measured in: the default rates
 * (10/10/4) at the bench's port rate (within capacity), and rate 1, 3 or
 * 255 on all nine streams with a capacity of 1 B/s or unlimited (every
 * due slot written, or every one over the capacity: a review found the
 * worst there, M4 at rate 1 with 1 B/s, M0+ at rate 3 unlimited; the
 * bench's ports skip most slots of 255 at their rate cheaply). g_snap is
 * taken again after it. */
typedef struct {
    uint8_t rate;      /* 0: the default rates */
    uint32_t capacity; /* B/s, each port */
    const char *name;
} poll_cfg_t;

static const poll_cfg_t poll_cfgs[] = {
    {0u, 0u, "default rates on 3 ports"},
    {255u, UINT32_MAX, "rate 255 on all 9 streams, capacity unlimited"},
    {255u, 1u, "rate 255 on all 9 streams, capacity 1 B/s"},
    {3u, UINT32_MAX, "rate 3 on all 9 streams, capacity unlimited"},
    {3u, 1u, "rate 3 on all 9 streams, capacity 1 B/s"},
    {1u, UINT32_MAX, "rate 1 on all 9 streams, capacity unlimited"},
    {1u, 1u, "rate 1 on all 9 streams, capacity 1 B/s"},
};

static void gimbal_config(unsigned cfg)
{
    const poll_cfg_t *c = &poll_cfgs[cfg];
    if (c->rate != 0u) {
        uint8_t r[16];
        unsigned p;
        memset(r, 0, sizeof(r));
        for (p = 0; p < TASE_GIMBAL_PORTS; p++) {
            memset(&r[p * 5u], c->rate, 3u);
            (void)tase_gimbal_set_capacity(&g, p, c->capacity);
        }
        (void)tase_gimbal_setup_set(&g, 0x00u, r, sizeof(r), 0u);
        g_snap = g;
    }
}

/* Telemetry due on every port, polled at several moments after init (late
 * ones skip slots too; a day late, the catch-up's division is longest;
 * 2^31 - 1 ms, the latest a clock may be read): coarse on every set-up,
 * callback form and moment, exact on those within a tick of the
 * longest. */
static void gimbal_poll(uint32_t *worst_now, unsigned *worst_app, unsigned *worst_cfg)
{
    static const uint32_t moments[] = {100u,  250u,    1000u,     1250u,
                                       4000u, 100000u, 86400000u, 2147483647u};
    static unsigned long coarse[COUNT(poll_cfgs)][2][COUNT(moments)];
    worst_t w = {0, ""};
    unsigned long top = 0;
    unsigned a, m, c, pass;
    for (pass = 0; pass < 2u; pass++) {
        for (c = 0; c < COUNT(poll_cfgs); c++) {
            for (a = 0; a < 2u; a++) {
                gimbal_snapshot(apps[a]);
                gimbal_config(c);
                for (m = 0; m < COUNT(moments); m++) {
                    unsigned long e;
                    a_poll_now = moments[m];
                    if (pass == 0u) {
                        coarse[c][a][m] = measure_once(restore_g, c_gpoll, NULL);
                        top = coarse[c][a][m] > top ? coarse[c][a][m] : top;
                        continue;
                    }
                    if (coarse[c][a][m] + MEASURE_TICK_INSNS < top) {
                        continue;
                    }
                    e = measure_exact(restore_g, c_gpoll, NULL);
                    if (e > w.insns) {
                        *worst_now = moments[m];
                        *worst_app = a;
                        *worst_cfg = c;
                    }
                    worst_try(&w, e, "%lu ms after init, %s, %s", (unsigned long)moments[m],
                              poll_cfgs[c].name, app_names[a]);
                }
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
                  (unsigned long)now, poll_cfgs[cfg].name, (unsigned long)sizeof(script),
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
    at_each_address("tase_gimbal_send", restore_g, c_gsend, "253 data bytes", PORT);
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
static const tase_port_t hport1 = {&fops1, &hfp, BYTES_PER_S};
static const tase_port_t *host_port = &hport; /* host_snapshot()'s */
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

/* h_snap: an idle host on the fake port (host_port: hport, or hport1
 * for the bytewise rows). */
static void host_snapshot(void)
{
    memset(&hfp, 0, sizeof(hfp));
    (void)tase_host_init(&h_snap, host_port, on_hframe, NULL);
    hfp_snap = hfp;
}

MEASURED(c_hinit, tase_host_init(&h, &hport, on_hframe, NULL))
MEASURED(c_hsend, tase_host_send(&h, 0x00u, 0x42u, payload, TASE_DATA_MAX))
MEASURED(c_hsend_msg, tase_host_send_msg(&h, cur_pkt->id, &full_msg))
/* Requests without retries: a CAMERA_PASS (the longest, 253 data bytes)
 * may not have any (host.h: a re-send would repeat camera bytes), and the
 * cost of a start does not depend on them. The re-send is measured on
 * every packet that may be re-sent (a setup packet, SPOI_CMD with its
 * echo flag, a query), at its longest and as a query (c_hrequest_any):
 * the longest is SYSTEM_VERSION with its 42 data bytes (sent as given
 * and answered with the version, host.h), not AXIS_SETTING's 23. */
MEASURED(c_hrequest, tase_host_request_start(&h, 0x00u, 0x42u, payload, TASE_DATA_MAX, reply,
                                             sizeof(reply), 100u, 0u, NOW_MS))
static uint8_t req_group, req_type, req_data[TASE_DATA_MAX];
static size_t req_len;
MEASURED(c_hrequest_any, tase_host_request_start(&h, req_group, req_type, req_data, req_len, reply,
                                                 sizeof(reply), 100u, 3u, NOW_MS))
MEASURED(c_hrequest_msg,
         tase_host_request_msg_start(&h, cur_pkt->id, &full_msg, &reply_msg, 100u, 0u, NOW_MS))
MEASURED(c_hquery, tase_host_query_start(&h, 0x48u, 0x03u, reply, sizeof(reply), 100u, 3u, NOW_MS))
MEASURED(c_hpoll, tase_host_poll(&h, NOW_MS + 100u))
static const uint8_t *feed_p; /* pkt_frame */
MEASURED(c_hfeed, tase_host_feed(&h, feed_p, pkt_frame_n, NOW_MS))
MEASURED(c_hhandle, tase_host_handle_frame(&h, &pkt_f))
MEASURED(c_hservice, tase_host_service(&h, 100u))
MEASURED(c_hdrain, tase_host_drain(&h))
MEASURED(c_hbusy, tase_host_busy(&h))
MEASURED(c_hcancel, tase_host_cancel(&h))
MEASURED(c_htransact, tase_host_transact(&h, 0x00u, 0x42u, payload, TASE_DATA_MAX, reply,
                                         sizeof(reply), 100u, 0u))
MEASURED(c_htransact_msg, tase_host_transact_msg(&h, cur_pkt->id, &full_msg, &reply_msg, 100u, 0u))
MEASURED(c_hquery_transact,
         tase_host_transact(&h, 0x48u, 0x03u, NULL, 0u, reply, sizeof(reply), 100u, 0u))

/* A pending request for cur_pkt (typed, its longest message) whose reply
 * is the packet's longest frame. */
static bool prep_reply(const tase_packet_desc_t *p)
{
    int r;
    if (!prep_full_frame(p) || cur_len == 0u) {
        return false; /* a zero-length frame is never a reply */
    }
    feed_p = pkt_frame;
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

/* A transaction whose reply (cur_pkt's longest frame) the port has as
 * soon as the request went out (one waiting before it is read first and
 * is no answer, host.h MATCHING). */
static bool prep_transact(const tase_packet_desc_t *p)
{
    if (!prep_full_frame(p) || cur_len == 0u) {
        return false; /* never answered: the transaction would wait forever */
    }
    host_snapshot();
    hfp_snap.in = pkt_frame;
    hfp_snap.nin = pkt_frame_n;
    hfp_snap.after = 1u;
    return true;
}

/* A review's input, searched: a typed CAMERA_PASS request pending (the
 * longest reply, 253 data bytes), an earlier call fed the first 16 * k
 * bytes of a stream (every stream of PERFORMANCE.md, k = 0..127), then the
 * reply in one call: coarse on all, exact on those within a tick of the
 * longest. */
static void host_feed_search(worst_t *w)
{
    static uint8_t script[2048];
    static unsigned long coarse[ALL_STREAMS][sizeof(script) / 16u];
    tase_host_t with_request;
    unsigned long top = 0;
    size_t s, k, pass;
    a_typed = true;
    cur_pkt = tase_schema_find(0x00u, 0x42u);
    if (cur_pkt == NULL || !prep_reply(cur_pkt)) {
        return;
    }
    with_request = h_snap;
    for (pass = 0; pass < 2u; pass++) {
        for (s = 0; s < ALL_STREAMS; s++) {
            (void)bench_stream(all_streams[s], script, sizeof(script));
            h_pre = with_request;
            for (k = 0; k < COUNT(coarse[0]); k++) {
                unsigned long *c = &coarse[s][k];
                h_snap = h_pre;
                if (pass == 0u) {
                    *c = measure_once(restore_h, c_hfeed, NULL);
                    top = *c > top ? *c : top;
                } else if (*c + MEASURE_TICK_INSNS >= top) {
                    int r;
                    restore_h(NULL);
                    (void)tase_host_feed(&h, feed_p, pkt_frame_n, NOW_MS);
                    r = tase_host_poll(&h, NOW_MS);
                    worst_try(w, measure_exact(restore_h, c_hfeed, NULL),
                              "CAMERA_PASS reply frame (253 data bytes) %s a pending typed "
                              "request, after an earlier call fed %s's first %lu bytes",
                              r == (int)cur_len ? "completing" : "not yet completing",
                              all_streams[s], (unsigned long)(k * 16u));
                }
                (void)tase_host_feed(&h_pre, &script[k * 16u], 16u, NOW_MS);
            }
        }
    }
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
    host_feed_search(&wf);
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

/* h_snap: a 253-byte CAMERA_PASS request pending just after an identical
 * one timed out (its answer owed until 200 ms after it: the request ends
 * owing one more, and the two windows merge). */
static void host_owing(void)
{
    host_snapshot();
    h = h_snap;
    c_hrequest(NULL);
    (void)tase_host_poll(&h, NOW_MS + 100u); /* timed out: one answer owed */
    c_hrequest(NULL);
    h_snap = h;
}

/* A pending request whose attempt timed out: every packet that may be
 * re-sent, at its longest (data bytes 0x00, SPOI_CMD's echo flag set) and
 * as a query (re-sent); the longest, a 253-byte CAMERA_PASS (failed); the
 * same after an identical one timed out (failed, owed answers merged). */
static void host_poll(void)
{
    worst_t w = {0, ""};
    size_t i, l;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        const size_t lens[2] = {p->len, 0u};
        for (l = 0; l < 2u; l++) {
            static char what[112];
            req_group = (uint8_t)TASE_ID_GROUP(p->id);
            req_type = (uint8_t)TASE_ID_TYPE(p->id);
            req_len = lens[l];
            memset(req_data, 0, sizeof(req_data));
            if (p->id == TASE_ID_SPOI_CMD) {
                req_data[18] = TASE_SPOI_ECHO;
            }
            host_snapshot();
            h = h_snap;
            if (tase_host_request_start(&h, req_group, req_type, req_data, req_len, reply,
                                        sizeof(reply), 100u, 3u, NOW_MS) != TASE_OK) {
                continue; /* not one the host may re-send */
            }
            (void)snprintf(what, sizeof(what),
                           "the attempt of a pending %s request (%lu data bytes, retries 3) "
                           "timed out: re-sent",
                           tase_schema_packet_name(p), (unsigned long)req_len);
            host_poll_pending(&w, c_hrequest_any, what);
        }
    }
    host_owing();
    worst_try(&w, measure_exact(restore_h, c_hpoll, NULL),
              "the one attempt of a pending 253-byte CAMERA_PASS request timed out just after "
              "an identical one did: failed, the owed answers merged");
    host_poll_pending(&w, c_hrequest,
                      "the one attempt of a pending 253-byte CAMERA_PASS request timed out: "
                      "failed");
    worst_report("tase_host_poll", &w, PORT);
}

/* h_snap: an idle host whose port answers the 253-byte request with the
 * 253-byte frame as soon as the request went out (the transact rows). */
static void answer_after_send(void)
{
    host_snapshot();
    hfp_snap.in = big_frame;
    hfp_snap.nin = TASE_FRAME_MAX;
    hfp_snap.after = 1u;
}

/* What tase_host_drain() reads at its most: 256 full reads (16 KiB) of a
 * stream that waited unread (every stream of PERFORMANCE.md, the costliest
 * kept), alone and as the read before tase_host_transact()'s send (the
 * port then answers the request as soon as it went out). */
static void host_backlog(const char *fn, measure_fn call, const char *before, const char *then)
{
    static uint8_t backlog[TASE_HOST_DRAIN_READS * 64u];
    worst_t w = {0, ""};
    size_t s;
    for (s = 0; s < ALL_STREAMS; s++) {
        (void)bench_stream(all_streams[s], backlog, sizeof(backlog));
        answer_after_send();
        hfp_snap.pre = backlog;
        hfp_snap.npre = sizeof(backlog);
        worst_try(&w, measure_exact(restore_h, call, NULL),
                  "%s16 KiB of %s waited unread (256 full reads, the most it reads)%s", before,
                  all_streams[s], then);
    }
    worst_report(fn, &w, READS);
}

/* tase_host_transact() and tase_host_transact_msg() on the bytewise port
 * (every byte of the request a write() of its own, every byte of the
 * reply a read()), and on a port whose read() returns nothing at once
 * while its clock stands still (the wait runs TASE_PORT_WRITE_SPINS
 * loops, then TASE_ETIMEOUT). */
static void host_transact_ports(void)
{
    worst_t w = {0, ""};
    host_port = &hport1;
    answer_after_send();
    report("tase_host_transact/bytewise", measure_exact(restore_h, c_htransact, NULL),
           "253 data bytes out, the port answers as soon as they went out with 253 (two empty "
           "reads before, 261 after)" BYTEWISE " and its read() hands over 1 byte a call");
    roles_per_packet(
        "tase_host_transact_msg/bytewise", prep_transact, restore_h, c_htransact_msg,
        ", every member set, the port answers with the same as soon as it went out" BYTEWISE
        " and its read() hands over 1 byte a call");
    host_port = &hport;
    host_snapshot(); /* read() has nothing: it returns 0 at once */
    worst_try(&w, measure_once(restore_h, c_hquery_transact, NULL),
              "SYSTEM_VERSION query, read() returning nothing at once: TASE_PORT_WRITE_SPINS "
              "(%lu) loops of an empty read and a poll, then TASE_ETIMEOUT",
              (unsigned long)TASE_PORT_WRITE_SPINS);
    worst_report("tase_host_transact/stalled", &w, STALLED);
}

static void host(void)
{
    worst_t w = {0, ""};
    report("tase_host_init", measure_plain(c_hinit), "a port with byte rate 5760 B/s");
    host_snapshot();
    at_each_address("tase_host_send", restore_h, c_hsend, "253 data bytes", PORT);
    roles_per_packet("tase_host_send_msg", prep_full_frame, restore_h, c_hsend_msg,
                     ", every member set" PORT);
    host_snapshot();
    at_each_address("tase_host_request_start", restore_h, c_hrequest, "253 data bytes",
                    ", idle host" PORT);
    roles_per_packet("tase_host_request_msg_start", prep_full_frame, restore_h, c_hrequest_msg,
                     ", every member set, idle host" PORT);
    host_snapshot();
    report("tase_host_query_start", measure_exact(restore_h, c_hquery, NULL),
           "SYSTEM_VERSION query, idle host" PORT);
    host_poll();
    /* h_snap: a 253-byte CAMERA_PASS request pending (host_poll()'s last) */
    report("tase_host_busy", measure_exact(restore_h, c_hbusy, NULL),
           "a request pending (253-byte CAMERA_PASS)");
    worst_try(&w, measure_exact(restore_h, c_hcancel, NULL),
              "a request pending (253-byte CAMERA_PASS)");
    host_owing();
    worst_try(&w, measure_exact(restore_h, c_hcancel, NULL),
              "a 253-byte CAMERA_PASS request pending just after an identical one timed out "
              "(one answer owed: the owed windows merge)");
    worst_report("tase_host_cancel", &w, "");
    host_replies();
    host_service();
    host_backlog("tase_host_drain", c_hdrain, "", "");
    answer_after_send();
    report("tase_host_transact", measure_exact(restore_h, c_htransact, NULL),
           "253 data bytes out, the port answers as soon as they went out with 253 (two empty "
           "reads before, five after)" READS);
    host_backlog("tase_host_transact/backlog", c_htransact, "253 data bytes out after ",
                 "; the port answers as soon as they went out");
    roles_per_packet(
        "tase_host_transact_msg", prep_transact, restore_h, c_htransact_msg,
        ", every member set, the port answers with the same as soon as it went out" READS);
    host_transact_ports();
}

void timing_roles(void)
{
    place_payload(0u);
    port_io();
    gimbal();
    host();
}
