/*
 * Worst case per call of the bare-metal port layer (port/baremetal:
 * tase/ring.h, tase/bm_uart.h, tase/bm_dma.h), compiled as firmware
 * compiles it (the ring's barrier hook left empty). The ring has 512
 * bytes (tase/bm_uart.h's example), the DMA buffer 256 (tase/bm_dma.h's).
 * The UART's hooks are trivial: tx copies to RAM, millis returns a
 * variable, no idle hook. Every state is reached through the API.
 *
 * The two polls feed a receiver, so their count holds the receiver's
 * calls (tase_rx_feed(), tase_rx_tick(): rows of their own): the worst
 * is searched over the first 8 KiB of every stream of PERFORMANCE.md, a
 * window at every 32-byte offset, the receiver in the state that feeding
 * the bytes before it left (coarse on all, exact on the top), and over
 * a poll that finds nothing after 100 s of quiet (the tick settles). The
 * ".../own" rows are the same call less the receiver calls it makes,
 * made directly on the same state and bytes: the port's own share.
 */
#include <stdio.h>
#include <string.h>

#include "../streams.h"
#include "tase/bm_dma.h"
#include "tase/bm_uart.h"
#include "tase/frame.h"
#include "tase/ring.h"
#include "timing.h"

#define RING_CAP 512u /* tase/bm_uart.h's example */
#define DMA_SIZE 256u /* tase/bm_dma.h's example */
#define CHUNK 32u     /* tase_bm_uart_poll()'s drain chunk (DRAIN_CHUNK) */
#define SEARCH 8192u  /* bytes of each stream the windows start in */
#define STEP 32u      /* between window starts */
#define QUIET_MS 100000u
#define SLOTS (SEARCH / STEP)

static const char *const streams[] = {"telemetry", "badsize", "sync4",   "syncrand",
                                      "noise",     "zeros",   "held255", "burst",
                                      "heldnoise", "halfsum", "synclong"};

/* Each stream generated once, so that every pass of a search and the
 * rows' inputs read the same memory. */
static uint8_t streams_mem[COUNT(streams)][SEARCH + RING_CAP];
static size_t streams_n[COUNT(streams)];
static const uint8_t *stream;
static size_t stream_n;
static tase_rx_t rx, rx_snap;

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    timing_sink += f->len;
}

/* ---- hooks and the objects --------------------------------------------- */

static uint8_t tx_ram[TASE_FRAME_MAX];
static uint32_t clock_ms;

static int h_tx(void *hw, const uint8_t *data, size_t n)
{
    (void)hw;
    (void)memcpy(tx_ram, data, n < sizeof(tx_ram) ? n : sizeof(tx_ram));
    return 0;
}

static uint32_t h_millis(void *hw)
{
    (void)hw;
    return clock_ms;
}

static void h_idle(void *hw)
{
    (void)hw;
}

static const tase_bm_uart_hooks_t hooks = {h_tx, h_millis, NULL, NULL, NULL};
static const tase_bm_uart_hooks_t hooks_idle = {h_tx, h_millis, h_idle, h_idle, h_idle};

static uint8_t ring_mem[RING_CAP];
static tase_ring_t ring, ring_snap;
static tase_bm_uart_t u, u_snap;
static uint8_t dma_mem[DMA_SIZE];
static tase_bm_dma_t d, d_snap;
static uint32_t a_written;
static uint8_t a_byte = 0x5Au;
static size_t a_cap;
static uint8_t out[RING_CAP];
static uint8_t frame261[TASE_FRAME_MAX];

/* The window the poll finds, in stream order (for the .../own rows). */
static const uint8_t *win;
static uint32_t win_n;   /* 0: nothing new */
static uint32_t win_pos; /* DMA: the reader's index in the buffer */

static void restore_ring(void *ctx)
{
    (void)ctx;
    ring = ring_snap;
}

static void restore_u(void *ctx)
{
    (void)ctx;
    u = u_snap;
    rx = rx_snap;
}

static void restore_d(void *ctx)
{
    (void)ctx;
    d = d_snap;
    rx = rx_snap;
}

MEASURED(c_ring_init, tase_ring_init(&ring, ring_mem, sizeof(ring_mem)))
MEASURED(c_ring_put, tase_ring_put(&ring, a_byte))
MEASURED(c_ring_get, tase_ring_get(&ring, out, a_cap))
MEASURED(c_ring_count, tase_ring_count(&ring))
MEASURED(c_ring_overflows, tase_ring_overflows(&ring))
MEASURED(c_ring_capacity, tase_ring_capacity(&ring))
MEASURED(c_u_init, tase_bm_uart_init(&u, ring_mem, sizeof(ring_mem), &hooks_idle, NULL))
MEASURED(c_u_port, tase_bm_uart_port(&u).bytes_per_s)
MEASURED(c_u_write, tase_bm_uart_ops.write(&u, frame261, sizeof(frame261)))
MEASURED(c_u_read, tase_bm_uart_ops.read(&u, out, a_cap, 0u))
MEASURED(c_u_now, tase_bm_uart_ops.now_ms(&u))
MEASURED(c_u_poll, tase_bm_uart_poll(&u, &rx, on_frame, NULL))
MEASURED(c_d_init, tase_bm_dma_init(&d, dma_mem, sizeof(dma_mem)))
MEASURED(c_d_poll, tase_bm_dma_poll(&d, a_written, clock_ms, &rx, on_frame, NULL))

NOINLINE static void c_isr(void *ctx)
{
    (void)ctx;
    tase_bm_uart_rx_isr(&u, a_byte);
}

/* The receiver calls tase_bm_uart_poll() makes on the window, made
 * directly: the probe, a feed per 32-byte chunk, the tick. */
NOINLINE static void c_u_poll_rx(void *ctx)
{
    uint32_t i;
    int r = tase_rx_feed(&rx, NULL, 0u, on_frame, NULL);
    (void)ctx;
    for (i = 0; i < win_n; i += CHUNK) {
        r += tase_rx_feed(&rx, &win[i], CHUNK, on_frame, NULL);
    }
    r += tase_rx_tick(&rx, clock_ms, on_frame, NULL);
    timing_sink += (unsigned long)r;
}

/* The receiver calls tase_bm_dma_poll() makes: the probe, the span up to
 * the buffer's end, the rest from its start, the tick. */
NOINLINE static void c_d_poll_rx(void *ctx)
{
    uint32_t first = DMA_SIZE - win_pos;
    int r = tase_rx_feed(&rx, NULL, 0u, on_frame, NULL);
    (void)ctx;
    if (first > win_n) {
        first = win_n;
    }
    if (first > 0u) {
        r += tase_rx_feed(&rx, win, first, on_frame, NULL);
    }
    if (win_n > first) {
        r += tase_rx_feed(&rx, &win[first], win_n - first, on_frame, NULL);
    }
    r += tase_rx_tick(&rx, clock_ms, on_frame, NULL);
    timing_sink += (unsigned long)r;
}

/* ---- the ring ------------------------------------------------------------ */

/* ring_snap: `at` bytes put and taken (the index moved on), then `fill`
 * put. */
static void ring_state(uint32_t at, uint32_t fill)
{
    uint32_t i;
    (void)tase_ring_init(&ring_snap, ring_mem, sizeof(ring_mem));
    for (i = 0; i < at; i++) {
        (void)tase_ring_put(&ring_snap, (uint8_t)i);
        (void)tase_ring_get(&ring_snap, out, 1u);
    }
    for (i = 0; i < fill; i++) {
        (void)tase_ring_put(&ring_snap, (uint8_t)(i * 7u));
    }
}

/* The states a put is tried in: one slot left (the storage's last byte),
 * empty, full (the byte dropped and counted). The first of equal counts
 * is named. */
static const struct {
    uint32_t at, fill;
    const char *what, *put;
} put_states[] = {
    {0u, RING_CAP - 1u, "511 bytes held, the free slot the storage's last", " (stored)"},
    {0u, 0u, "empty", " (stored)"},
    {RING_CAP / 2u, RING_CAP, "full", " (dropped and counted)"},
};

static void ring_calls(void)
{
    worst_t w = {0, ""}, wi = {0, ""}, wc = {0, ""}, wo = {0, ""}, wk = {0, ""};
    size_t k;
    report("tase_ring_init", measure_plain(c_ring_init), "512-byte storage");
    for (k = 0; k < COUNT(put_states); k++) {
        ring_state(put_states[k].at, put_states[k].fill);
        worst_try(&w, measure_exact(restore_ring, c_ring_put, NULL), "%s%s", put_states[k].what,
                  put_states[k].put);
        worst_try(&wc, measure_exact(restore_ring, c_ring_count, NULL), "%s", put_states[k].what);
        worst_try(&wo, measure_exact(restore_ring, c_ring_overflows, NULL), "%s",
                  put_states[k].what);
        worst_try(&wk, measure_exact(restore_ring, c_ring_capacity, NULL), "%s",
                  put_states[k].what);
        (void)tase_bm_uart_init(&u_snap, ring_mem, sizeof(ring_mem), &hooks, NULL);
        u_snap.rx = ring_snap;
        rx_snap = rx;
        worst_try(&wi, measure_exact(restore_u, c_isr, NULL), "%s%s", put_states[k].what,
                  put_states[k].put);
    }
    worst_report("tase_ring_put", &w, ", 512-byte ring");
    worst_report("tase_bm_uart_rx_isr", &wi, ", 512-byte ring; one call per received byte");
    /* full and wrapping round the storage's end: 32 bytes from index 496,
     * all 512 from index 256 */
    ring_state(RING_CAP - 16u, RING_CAP);
    a_cap = CHUNK;
    report("tase_ring_get/32", measure_exact(restore_ring, c_ring_get, NULL),
           "32 of a full 512-byte ring, wrapping round the storage's end; O(bytes taken)");
    ring_state(RING_CAP / 2u, RING_CAP);
    a_cap = RING_CAP;
    report("tase_ring_get/512", measure_exact(restore_ring, c_ring_get, NULL),
           "all of a full 512-byte ring, wrapping round the storage's end; O(bytes taken)");
    worst_report("tase_ring_count", &wc, ", 512-byte ring");
    worst_report("tase_ring_overflows", &wo, ", 512-byte ring");
    worst_report("tase_ring_capacity", &wk, ", 512-byte ring");
}

/* ---- the polls: the search ------------------------------------------------ */

/* Sets u_snap/d_snap (and win, clock_ms, a_written) for the window of the
 * stream at o, or for a poll that finds nothing after 100 s of quiet. */
typedef void (*load_fn)(size_t o, bool quiet);

static void load_u(size_t o, bool quiet)
{
    uint32_t i;
    ring_state(RING_CAP / 2u, 0u); /* the window wraps round the storage's end */
    for (i = 0; !quiet && i < RING_CAP; i++) {
        (void)tase_ring_put(&ring_snap, stream[o + i]);
    }
    (void)tase_bm_uart_init(&u_snap, ring_mem, sizeof(ring_mem), &hooks, NULL);
    u_snap.rx = ring_snap; /* the ring moved on as above */
    win = &stream[o];
    win_n = quiet ? 0u : RING_CAP;
    clock_ms = quiet ? QUIET_MS : 0u;
}

/* The DMA's reader at index win_pos (its count there too); the DMA wrote
 * the window from there on, round the end. */
static void load_d_at(size_t o, bool quiet, uint32_t pos)
{
    static tase_rx_t scratch;
    uint32_t i;
    (void)tase_rx_init(&scratch);
    (void)tase_bm_dma_init(&d_snap, dma_mem, sizeof(dma_mem));
    (void)tase_bm_dma_poll(&d_snap, pos, 0u, &scratch, NULL, NULL);
    for (i = 0; i < DMA_SIZE; i++) {
        dma_mem[(pos + i) % DMA_SIZE] = stream[o + i];
    }
    win = &stream[o];
    win_pos = pos;
    win_n = quiet ? 0u : DMA_SIZE;
    a_written = pos + win_n;
    clock_ms = quiet ? QUIET_MS : 0u;
}

static void load_d(size_t o, bool quiet)
{
    load_d_at(o, quiet, DMA_SIZE / 2u);
}

/* The DMA lapped the reader: over_lap new bytes (more than the buffer). */
static uint32_t over_lap = 0xFFFFFFFFu - DMA_SIZE;

static void load_d_over(size_t o, bool quiet)
{
    (void)quiet;
    load_d_at(o, false, DMA_SIZE / 2u);
    a_written = DMA_SIZE / 2u + over_lap;
}

/* rx_snap: the receiver after the first `o` bytes of the stream, fed and
 * ticked a chunk at a time while the line is active at 0 ms. */
static void rx_start(void)
{
    (void)tase_rx_init(&rx_snap);
    (void)tase_rx_set_timing(&rx_snap, 5760u, 0u);
}

static void rx_advance(size_t o)
{
    (void)tase_rx_feed(&rx_snap, &stream[o], STEP, NULL, NULL);
    (void)tase_rx_tick(&rx_snap, 0u, NULL, NULL);
}

static size_t load_stream(size_t s, size_t window)
{
    stream = streams_mem[s];
    stream_n = streams_n[s];
    return stream_n >= window ? stream_n - window : 0u; /* last start + 1 */
}

/* The worst of `call` (restored by `restore`) over every window start
 * and the quiet poll: coarse on all, exact where the coarse count is
 * within two ticks of the top. Leaves the worst's state loaded (its
 * stream, offset and whether quiet in *ws, *wo, *wq). */
static unsigned long poll_search(load_fn load, measure_fn restore, measure_fn call, size_t window,
                                 bool quiet_too, size_t *ws, size_t *wo, bool *wq)
{
    static uint16_t coarse[COUNT(streams)][SLOTS][2];
    size_t s, k, q;
    uint16_t top = 0;
    unsigned long best = 0;
    for (s = 0; s < COUNT(streams); s++) {
        size_t end = load_stream(s, window);
        rx_start();
        for (k = 0; k < SLOTS; k++) {
            size_t o = k * STEP;
            for (q = 0; q < (quiet_too ? 2u : 1u); q++) {
                uint32_t t0;
                coarse[s][k][q] = 0;
                if (o >= end) {
                    continue;
                }
                load(o, q != 0u);
                restore(NULL);
                t0 = measure_ticks();
                call(NULL);
                coarse[s][k][q] = (uint16_t)(t0 - measure_ticks());
                top = coarse[s][k][q] > top ? coarse[s][k][q] : top;
            }
            if (o + STEP <= stream_n) {
                rx_advance(o);
            }
        }
    }
    for (s = 0; s < COUNT(streams); s++) {
        size_t end = load_stream(s, window);
        rx_start();
        for (k = 0; k < SLOTS; k++) {
            size_t o = k * STEP;
            for (q = 0; q < (quiet_too ? 2u : 1u) && o < end; q++) {
                if (coarse[s][k][q] + 2u >= top) { /* each may be a tick off */
                    unsigned long e;
                    load(o, q != 0u);
                    e = measure_exact(restore, call, NULL);
                    if (e > best) {
                        best = e, *ws = s, *wo = o, *wq = q != 0u;
                    }
                }
            }
            if (o + STEP <= stream_n) {
                rx_advance(o);
            }
        }
    }
    /* back to the worst */
    (void)load_stream(*ws, window);
    rx_start();
    for (k = 0; k < *wo; k += STEP) {
        rx_advance(k);
    }
    load(*wo, *wq);
    return best;
}

static void describe(char *buf, size_t cap, const char *what, size_t s, size_t o, bool q)
{
    if (q) {
        (void)snprintf(buf, cap,
                       "nothing new, 100 s quiet after %lu bytes of %s (the tick settles); "
                       "the receiver's calls counted",
                       (unsigned long)o, streams[s]);
    } else {
        (void)snprintf(buf, cap, "bytes %lu.. of %s in %s; the receiver's calls counted",
                       (unsigned long)o, streams[s], what);
    }
}

/* A poll's row (e instructions on input `what`) and its /own row: e less
 * the receiver calls `rx_calls` that c_rx makes directly on the state
 * `restore` gives, leaving `own`. */
static void report_poll(const char *fn, unsigned long e, const char *what, measure_fn restore,
                        measure_fn c_rx, const char *rx_calls, const char *own)
{
    static char name[64], how[256];
    (void)snprintf(name, sizeof(name), "%s/own", fn);
    (void)snprintf(how, sizeof(how),
                   "the row above less its receiver calls (%s), made directly on the same state "
                   "and bytes: %s",
                   rx_calls, own);
    report(fn, e, what);
    report(name, e - measure_exact(restore, c_rx, NULL), how);
}

static void uart_calls(void)
{
    static char what[256];
    size_t s = 0, o = 0;
    bool q = false;
    unsigned long e;

    report("tase_bm_uart_init", measure_plain(c_u_init),
           "512-byte storage, every hook given (all checks pass)");
    report("tase_bm_uart_port", measure_plain(c_u_port), "any state");
    (void)tase_bm_uart_init(&u_snap, ring_mem, sizeof(ring_mem), &hooks, NULL);
    memset(frame261, 0xA5, sizeof(frame261));
    report("tase_bm_uart_ops.write", measure_exact(restore_u, c_u_write, NULL),
           "261 bytes (a whole frame); the tx hook's copy to RAM counted");
    ring_state(RING_CAP / 2u, RING_CAP);
    u_snap.rx = ring_snap;
    a_cap = RING_CAP;
    report("tase_bm_uart_ops.read", measure_exact(restore_u, c_u_read, NULL),
           "cap 512, a full 512-byte ring wrapping round the storage's end; O(bytes taken); "
           "an empty ring waits (spins, or sleeps in the idle hook) until a byte arrives or "
           "timeout_ms passes: not bounded in instructions");
    report("tase_bm_uart_ops.now_ms", measure_exact(restore_u, c_u_now, NULL),
           "any state; the millis hook counted");

    e = poll_search(load_u, restore_u, c_u_poll, RING_CAP, true, &s, &o, &q);
    describe(what, sizeof(what), "a full 512-byte ring, drained in 16 feeds of 32 bytes", s, o, q);
    report_poll("tase_bm_uart_poll", e, what, restore_u, c_u_poll_rx,
                "the probe, 16 tase_rx_feed of 32 bytes, tase_rx_tick",
                "ring copy, chunk loop, millis hook");
}

static void dma_calls(void)
{
    static char what[256], how[128];
    static const uint32_t positions[] = {0u, 1u, DMA_SIZE / 2u, DMA_SIZE - 1u};
    /* overruns: more than DMA_SIZE and up to 2^31 ahead (further reads as
     * behind: a stale sample, bm_dma.h) */
    static const uint32_t laps[] = {DMA_SIZE + 1u, 2u * DMA_SIZE - 1u, 0x10000u, 0x7FFFFFFFu,
                                    0x80000000u};
    size_t s = 0, o = 0, k, j;
    bool q = false;
    unsigned long e, best;
    uint32_t pos = DMA_SIZE / 2u, lap = 0u;

    report("tase_bm_dma_init", measure_plain(c_d_init), "256-byte buffer");
    e = poll_search(load_d, restore_d, c_d_poll, DMA_SIZE, true, &s, &o, &q);
    if (!q) { /* the reader elsewhere in the buffer: one span or two */
        for (k = 0; k < COUNT(positions); k++) {
            unsigned long x;
            load_d_at(o, false, positions[k]);
            x = measure_exact(restore_d, c_d_poll, NULL);
            if (x > e) {
                e = x, pos = positions[k];
            }
        }
        load_d_at(o, false, pos);
        (void)snprintf(how, sizeof(how),
                       "a full 256-byte buffer (exactly its size new), the reader at %lu (%s)",
                       (unsigned long)pos, pos == 0u ? "one span" : "two spans round the end");
        describe(what, sizeof(what), how, s, o, q);
    } else {
        describe(what, sizeof(what), "", s, o, q);
    }
    report_poll("tase_bm_dma_poll", e, what, restore_d, c_d_poll_rx,
                "the probe, a tase_rx_feed per span, tase_rx_tick", "span arithmetic and counters");

    /* An overrun: nothing fed, the receiver flushed (the window settles),
     * two remainders. The receiver's state from the same windows, then
     * the lap from a spread at the worst (the remainders' cost may depend
     * on it). */
    best = poll_search(load_d_over, restore_d, c_d_poll, DMA_SIZE, false, &s, &o, &q);
    lap = over_lap;
    for (j = 0; j < COUNT(laps); j++) {
        over_lap = laps[j];
        load_d_over(o, false);
        e = measure_exact(restore_d, c_d_poll, NULL);
        if (e > best) {
            best = e, lap = laps[j];
        }
    }
    (void)snprintf(what, sizeof(what),
                   "%lu new bytes in a 256-byte buffer (lapped: nothing fed, the receiver "
                   "flushed) after %lu bytes of %s; the flush counted",
                   (unsigned long)lap, (unsigned long)o, streams[s]);
    report("tase_bm_dma_poll/overrun", best, what);
}

void timing_port(void)
{
    size_t s;
    for (s = 0; s < COUNT(streams); s++) {
        streams_n[s] = bench_stream(streams[s], streams_mem[s], sizeof(streams_mem[s]));
    }
    (void)tase_rx_init(&rx);
    ring_calls();
    uart_calls();
    dma_calls();
}
