/*
 * Example gimbal firmware for QEMU's mps2-an385 (Cortex-M3).
 *
 * A recorded UART stream (stream.h: host requests mixed with line noise
 * and corruption) arrives byte by byte in a simulated receive interrupt
 * (SysTick stands in for the UART and its receive DMA: 12 bytes per 1 ms
 * tick, about 115200 baud, written round a 64-byte circular buffer as a
 * circular DMA channel does, with a count of the bytes written). Once per
 * tick the main loop polls the library's gimbal role (telemetry due at the
 * rates of PACKET_RATE), then feeds what the "DMA" wrote since the last
 * tick, one span or two at the wrap, into tase_rx_feed() with
 * tase_dispatch_frame() as the frame callback (port/baremetal's
 * tase_bm_dma_poll(), which also ticks the receiver's time bound). The
 * application (gimbal.c) registers typed handlers in a ROM table; the
 * setup handler passes setup packets on to the gimbal role, which answers
 * queries and echoes settings through the same port, whose TX hook
 * appends to a buffer. Once the line goes quiet for 100 ms right after
 * noise that looks like a sync with Size 255 and a GIMBAL_CMD: the
 * receiver's time bound (tase/frame.h, TIME BOUND; ticked by
 * tase_bm_dma_poll()) delivers the command 22 ms after its last byte,
 * not when 241 more bytes have come.
 *
 * After the simulated run the image checks everything against stream.h,
 * whose expectations come from an independent Python model: every clean
 * frame (offset, id, length, route: typed handler / error hook / default
 * handler, decoded fields, the tick whose bytes decide it: the receiver
 * delivers it then or within its latency bound after), the receiver's
 * counters, and, through a second receiver and the typed decoder as a
 * host would see them, every reply and telemetry frame with its time and
 * contents. It prints a summary with its own flash/RAM/stack numbers
 * through semihosting and exits 0 when every check passed.
 */
#include <stdio.h>
#include <string.h>

#include "board.h"
#include "gimbal.h"
#include "stream.h"
#include "tase/bm_dma.h"
#include "tase/bm_uart.h"
#include "tase/flags.h"

#define CPU_HZ 25000000u /* mps2-an385 */
#define TICK_HZ 1000u    /* one simulated millisecond per SysTick */
#define RING_SIZE 64u    /* power of two: the TX port's (unused) receive ring */
/* The receive DMA's circular buffer. A transmit that takes the line's time
 * (a plain UART without transmit DMA, unlike this image's instant one)
 * lets the DMA write as many bytes as go out meanwhile, so the buffer
 * holds a loop pass's longest transmit, TX_BURST_MAX (the three telemetry
 * streams due at once, 14 + 26 + 71 bytes, and two setup echoes of up to
 * 50), and a tick's input besides. 64 overran a review's transmit hook
 * that took the line's time: 144 bytes lost. */
#define DMA_SIZE 256u
#define TX_BURST_MAX (14u + 26u + 71u + 2u * 50u)
typedef char dma_size_check[DMA_SIZE >= TX_BURST_MAX + STREAM_BYTES_PER_TICK ? 1 : -1];
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

/* ---- board: the simulated UART and its clock ---- */

static uint8_t ring_storage[RING_SIZE];
static tase_bm_uart_t uart;
static tase_bm_dma_t dma;
static uint8_t dma_buf[DMA_SIZE];
static volatile uint32_t ticks, uart_pos;

/* What the UART's receive interrupt would do with each byte. */
void SysTick_Handler(void)
{
    static uint32_t paused;
    uint32_t i;
    if (uart_pos == STREAM_PAUSE_AT && paused < STREAM_PAUSE_MS) {
        paused++; /* the line is quiet */
        ticks++;
        return;
    }
    for (i = 0; i < STREAM_BYTES_PER_TICK && uart_pos < sizeof(stream_bytes); i++) {
        if (uart_pos == STREAM_PAUSE_AT && paused < STREAM_PAUSE_MS) {
            break;
        }
        dma_buf[uart_pos % DMA_SIZE] = stream_bytes[uart_pos]; /* what the DMA does */
        uart_pos++; /* the DMA's count of bytes written */
    }
    ticks++;
}

/* The gimbal's transmit side: a buffer the checks read back. */
static uint8_t tx_buf[4096];
static size_t tx_len;

static int tx_hook(void *hw, const uint8_t *data, size_t n)
{
    (void)hw;
    if (n > sizeof(tx_buf) - tx_len) {
        return TASE_ENOSPC;
    }
    memcpy(&tx_buf[tx_len], data, n);
    tx_len += n;
    return 0;
}

static uint32_t millis_hook(void *hw)
{
    (void)hw;
    return ticks;
}

static const tase_bm_uart_hooks_t uart_hooks = {tx_hook, millis_hook, NULL, NULL, NULL};

/* ---- checks ---- */

static unsigned failures, checks;

static void check(int ok, const char *what, long got, long want)
{
    checks++;
    if (!ok) {
        failures++;
        printf("FAIL %s: got %ld, want %ld\n", what, got, want);
    }
}

/* Receive side: every frame the application saw, against the recording. */
typedef struct {
    size_t frames;
    size_t routes[3];
    uint32_t now;    /* the main loop's tick */
    size_t lagged;   /* frames delivered after the tick whose bytes decided them */
    uint32_t behind; /* the most ticks one of them came after it */
} seen_t;

/* Ticks that feed TASE_RX_LATE_MAX bytes: how much later than the tick
 * whose bytes decide it the receiver may deliver a frame (tase/frame.h,
 * LATENCY: when one byte decides more than the scan's credit pays for at
 * once, here a corrupted candidate over nine frames). */
#define LATE_TICKS ((TASE_RX_LATE_MAX + STREAM_BYTES_PER_TICK - 1u) / STREAM_BYTES_PER_TICK)

static void on_trace(void *user, const tase_frame_t *f, unsigned route, const int64_t *v, size_t n)
{
    seen_t *s = user;
    size_t k = s->frames++;
    size_t i;
    const expect_frame_t *e;

    if (route < COUNT(s->routes)) {
        s->routes[route]++;
    }
    if (k >= COUNT(expect_frames)) {
        check(0, "frame beyond the expected ones at offset", (long)f->offset, -1);
        return;
    }
    e = &expect_frames[k];
    check(f->offset == e->offset, "frame offset", (long)f->offset, (long)e->offset);
    check(f->group == e->group && f->type == e->type, "frame id", TASE_ID(f->group, f->type),
          TASE_ID(e->group, e->type));
    check(f->len == e->len, "frame length", f->len, e->len);
    check(f->len == e->len && e->offset + 6u + e->len <= sizeof(stream_bytes) &&
              memcmp(f->data, &stream_bytes[e->offset + 6u], e->len) == 0,
          "frame data matches the recording (frame #)", (long)k, (long)k);
    check(route == e->route, "frame route", (long)route, e->route);
    /* delivered at the tick the model says (the tick whose bytes decide
     * it: held frames and the time bound's settling included), or within
     * the receiver's latency bound after it */
    check(s->now >= e->tick && s->now - e->tick <= LATE_TICKS, "frame delivered at tick",
          (long)s->now, (long)e->tick);
    if (s->now > e->tick) {
        s->lagged++;
        s->behind = (s->now - e->tick > s->behind) ? s->now - e->tick : s->behind;
    }
    check(n == e->nfields, "decoded field count", (long)n, e->nfields);
    for (i = 0; i < n && i < e->nfields; i++) {
        check(v[i] == expect_values[e->first + i], "decoded field value", (long)v[i],
              (long)expect_values[e->first + i]);
    }
}

/* Host side: what the gimbal sent, through a second receiver. */
typedef struct {
    size_t replies, telemetry, angles, rates, georefs, other;
    bool spoi; /* a SPOI_CMD answer in SPOI mode has come */
} host_t;

static void check_telemetry(host_t *h, const tase_frame_t *f)
{
    tase_packet_msg_t m;
    const expect_telemetry_t *e;
    int32_t got[8];
    size_t k = h->telemetry++, i, n;
    int r = tase_packet_decode(f, &m);

    check(r == (int)f->len, "telemetry decodes", r, f->len);
    if (k >= COUNT(expect_telemetry)) {
        check(0, "telemetry beyond the expected frames", (long)k, (long)COUNT(expect_telemetry));
        return;
    }
    e = &expect_telemetry[k];
    check(f->group == e->group && f->type == e->type, "telemetry id", TASE_ID(f->group, f->type),
          TASE_ID(e->group, e->type));
    memset(got, 0, sizeof got);
    if (f->group == 0x08u && f->type == 0x10u) {
        h->angles++;
        got[0] = m.gimbal_angle.pan;
        got[1] = m.gimbal_angle.tilt;
        got[2] = m.gimbal_angle.roll;
        n = 3;
    } else if (f->group == 0x08u && f->type == 0x40u) {
        h->rates++;
        got[0] = (int32_t)m.gimbal_rate.time;
        got[1] = m.gimbal_rate.pan_rate;
        got[2] = m.gimbal_rate.tilt_rate;
        got[3] = m.gimbal_rate.roll_rate;
        got[4] = m.gimbal_rate.p;
        got[5] = m.gimbal_rate.q;
        got[6] = m.gimbal_rate.r;
        got[7] = m.gimbal_rate.mode;
        n = 8;
        /* Read through flags.h: every GIMBAL_CMD of the stream that
         * moves the axes is a stabilised position command (0xA0); before
         * the first, rate feedback without stabilisation; once a SPOI
         * was echoed, stabilised SPOI (its error commands keep it). */
        if (h->spoi) {
            check(TASE_MODE_VALUE(m.gimbal_rate.mode) == TASE_MODE_SPOI &&
                      (m.gimbal_rate.mode & TASE_MODE_STAB) != 0u,
                  "mode byte: stabilised SPOI", m.gimbal_rate.mode,
                  TASE_MODE_STAB | TASE_MODE_SET_VALUE(0u, TASE_MODE_SPOI));
        } else if (m.gimbal_rate.pan_rate != 0) {
            check(TASE_MODE_VALUE(m.gimbal_rate.mode) == TASE_MODE_POSITION &&
                      (m.gimbal_rate.mode & TASE_MODE_STAB) != 0u,
                  "mode byte: stabilised position feedback", m.gimbal_rate.mode,
                  TASE_MODE_STAB | TASE_MODE_POSITION);
        } else {
            check(TASE_MODE_VALUE(m.gimbal_rate.mode) == TASE_MODE_RATE &&
                      (m.gimbal_rate.mode & TASE_MODE_STAB) == 0u,
                  "mode byte: rate feedback", m.gimbal_rate.mode, TASE_MODE_RATE);
        }
    } else {
        h->georefs++;
        got[0] = (int32_t)m.georeference.time;
        got[1] = m.georeference.lat;
        got[2] = m.georeference.lon;
        got[3] = m.georeference.height;
        got[4] = m.georeference.pan;
        got[5] = m.georeference.tilt;
        got[6] = m.georeference.sample_rate;
        got[7] = m.georeference.hfov;
        n = 8;
    }
    for (i = 0; i < n; i++) {
        if (got[i] != e->v[i]) {
            printf("telemetry frame %u (due at %u ms), field %u:\n", (unsigned)k, e->t,
                   (unsigned)i);
        }
        check(got[i] == e->v[i], "telemetry field", got[i], e->v[i]);
    }
}

static void on_tx_frame(void *user, const tase_frame_t *f)
{
    host_t *h = user;
    uint16_t id = TASE_ID(f->group, f->type);
    if (f->group == TASE_GROUP_SETUP || id == TASE_ID_SPOI_CMD) {
        tase_packet_msg_t m;
        size_t k = h->replies++;
        check(tase_packet_decode(f, &m) == (int)f->len, "reply decodes", f->len, f->len);
        if (id == TASE_ID_SPOI_CMD && TASE_SPOI_MODE(m.spoi_cmd.flags) == TASE_MODE_SPOI) {
            h->spoi = true;
        }
        if (k < COUNT(expect_replies)) {
            const expect_reply_t *e = &expect_replies[k];
            check(f->group == e->group && f->type == e->type && f->len == e->len &&
                      memcmp(f->data, e->data, e->len) == 0,
                  "reply matches", TASE_ID(f->group, f->type), TASE_ID(e->group, e->type));
        }
    } else if (id == TASE_ID_GIMBAL_ANGLE || id == TASE_ID_GIMBAL_RATE ||
               id == TASE_ID_GEOREFERENCE_DATA) {
        check_telemetry(h, f);
    } else {
        h->other++;
    }
}

/* ---- the image's own size, from the linker script's symbols ---- */

extern const uint8_t __flash_end[], __tase_lib_start[], __tase_lib_end[];
extern const uint8_t __tase_port_start[], __tase_port_end[];
extern uint8_t _sdata[], _ebss[];

static unsigned long span(const uint8_t *a, const uint8_t *b)
{
    return (unsigned long)((uintptr_t)b - (uintptr_t)a);
}

int main(void)
{
    static tase_rx_t rx;
    static gimbal_app_t app;
    static tase_rx_t host_rx;
    static seen_t seen;
    host_t host;
    tase_port_t port;
    const tase_rx_stats_t *st = &rx.stats;
    uint32_t now, last = 0, late = 0, poll_errors = 0;
    unsigned long stack;

    (void)tase_rx_init(&rx);
    check(tase_bm_uart_init(&uart, ring_storage, sizeof ring_storage, &uart_hooks, NULL) == TASE_OK,
          "tase_bm_uart_init", 0, 0);
    port = tase_bm_uart_port(&uart);
    check(tase_bm_dma_init(&dma, dma_buf, sizeof dma_buf) == TASE_OK, "tase_bm_dma_init", 0, 0);
    /* The UART's byte rate: sizes the gimbal's telemetry capacity and the
     * receiver's time bound (tase/frame.h, TIME BOUND). */
    port.bytes_per_s = STREAM_LINE_BYTES_PER_S;
    (void)tase_rx_set_timing(&rx, port.bytes_per_s, 0u);
    check(gimbal_app_init(&app, &port, &rx.stats, on_trace, &seen, 0u) == TASE_OK,
          "gimbal_app_init", 0, 0);

    SYST_RVR = CPU_HZ / TICK_HZ - 1u;
    SYST_CVR = 0u;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */

    /* The firmware's main loop: once per tick, telemetry then receive. */
    for (;;) {
        __asm__ volatile("cpsid i" ::: "memory");
        if (ticks == last) {
            __asm__ volatile("wfi"); /* a pending SysTick wakes it even masked */
        }
        __asm__ volatile("cpsie i" ::: "memory");
        now = ticks;
        if (now == last) {
            continue;
        }
        if (now != last + 1u) {
            late++;
        }
        last = now;
        app.now_ms = now;
        seen.now = now;
        /* Both return a library error code only for a misuse (an
         * instance not set up, a call from a callback): count it, as a
         * product logs it; 0 here. */
        if (tase_gimbal_poll(&app.role, now) < 0) {
            poll_errors++;
        }
        if (tase_bm_dma_poll(&dma, uart_pos, now, &rx, tase_dispatch_frame, &app.dispatch) < 0) {
            poll_errors++;
        }
        if (ticks != now) {
            late++; /* the next tick came before this one was handled */
        }
        if (now >= STREAM_RUN_MS) {
            break;
        }
    }
    SYST_CSR = 0u;
    if (tase_bm_dma_poll(&dma, uart_pos, ticks, &rx, tase_dispatch_frame, &app.dispatch) < 0 ||
        tase_rx_flush(&rx, tase_dispatch_frame, &app.dispatch) < 0) {
        poll_errors++;
    }
    stack = board_stack_used(); /* before printf, which is not ours */

    printf("TASE gimbal example on Cortex-M3 (mps2-an385), %u simulated ms\n",
           (unsigned)STREAM_RUN_MS);
    printf("rx: %lu bytes, %lu frames ok, %lu checksum errors, %lu bad size, "
           "%lu bytes discarded, %lu bad length, %lu unknown\n",
           (unsigned long)st->bytes_in, (unsigned long)st->frames_ok,
           (unsigned long)st->checksum_errors, (unsigned long)st->bad_size,
           (unsigned long)st->bytes_discarded, (unsigned long)st->bad_length,
           (unsigned long)st->unknown);
    printf("rx: %lu of %lu frames on the tick that decided them, %lu later (at most %lu "
           "ticks, bound %lu)\n",
           (unsigned long)(seen.frames - seen.lagged), (unsigned long)seen.frames,
           (unsigned long)seen.lagged, (unsigned long)seen.behind, (unsigned long)LATE_TICKS);
    check(uart_pos == sizeof(stream_bytes), "bytes delivered by the ISR", (long)uart_pos,
          (long)sizeof(stream_bytes));
    check(dma.stats.overruns == 0u, "DMA overruns", (long)dma.stats.overruns, 0);
    check(dma.stats.bytes_fed == sizeof(stream_bytes), "bytes fed from the DMA buffer",
          (long)dma.stats.bytes_fed, (long)sizeof(stream_bytes));
    check(late == 0u, "ticks the main loop fell behind", (long)late, 0);
    check(poll_errors == 0u, "poll and flush errors", (long)poll_errors, 0);
    check(st->bytes_in == sizeof(stream_bytes), "bytes_in", (long)st->bytes_in,
          (long)sizeof(stream_bytes));
    check(seen.frames == COUNT(expect_frames), "frames delivered", (long)seen.frames,
          (long)COUNT(expect_frames));
    check(st->frames_ok == seen.frames, "frames_ok", (long)st->frames_ok, (long)seen.frames);
    check(st->checksum_errors == EXPECT_CHECKSUM_ERRORS, "checksum_errors",
          (long)st->checksum_errors, EXPECT_CHECKSUM_ERRORS);
    check(st->bad_size == EXPECT_BAD_SIZE, "bad_size", (long)st->bad_size, EXPECT_BAD_SIZE);
    check(st->bytes_discarded == EXPECT_BYTES_DISCARDED, "bytes_discarded",
          (long)st->bytes_discarded, EXPECT_BYTES_DISCARDED);
    check(st->bad_length == EXPECT_BAD_LENGTH, "bad_length", (long)st->bad_length,
          EXPECT_BAD_LENGTH);
    check(st->unknown == EXPECT_UNKNOWN, "unknown", (long)st->unknown, EXPECT_UNKNOWN);
    check(app.length_errors == EXPECT_BAD_LENGTH, "error hook calls", (long)app.length_errors,
          EXPECT_BAD_LENGTH);
    check(app.unknown == EXPECT_UNKNOWN, "default handler calls", (long)app.unknown,
          EXPECT_UNKNOWN);
    check(app.commands_refused == EXPECT_COMMANDS_REFUSED, "GIMBAL_CMDs refused",
          (long)app.commands_refused, EXPECT_COMMANDS_REFUSED);
    check(app.commands_ignored == EXPECT_COMMANDS_IGNORED,
          "SPOI error commands outside SPOI mode ignored", (long)app.commands_ignored,
          EXPECT_COMMANDS_IGNORED);
    check(app.spois == EXPECT_SPOIS && app.spois_refused == EXPECT_SPOIS_REFUSED &&
              app.spoi_queries == EXPECT_SPOI_QUERIES,
          "SPOI_CMD points applied, refused (x100), queries (x10000)",
          (long)(app.spois + 100u * app.spois_refused + 10000u * app.spoi_queries),
          (long)(EXPECT_SPOIS + 100u * EXPECT_SPOIS_REFUSED + 10000u * EXPECT_SPOI_QUERIES));
    check(app.setups_refused == EXPECT_SETUPS_REFUSED &&
              app.role.stats.setup_refused == EXPECT_SETUPS_REFUSED,
          "settings refused (AXIS_SETTING max rate 0)", (long)app.role.stats.setup_refused,
          EXPECT_SETUPS_REFUSED);

    printf("app: %lu typed (%lu GIMBAL_CMD, %lu SPOI_CMD, %lu GYRO_ZERO_CMD, %lu HOST_ATTITUDE, "
           "%lu setup), %lu to the error hook, %lu to the default handler\n",
           (unsigned long)seen.routes[GIMBAL_ROUTE_TYPED], (unsigned long)app.commands,
           (unsigned long)(app.spois + app.spois_refused + app.spoi_queries),
           (unsigned long)app.gyro_zeros, (unsigned long)app.host_attitudes,
           (unsigned long)app.setups, (unsigned long)app.length_errors, (unsigned long)app.unknown);
    printf("gimbal role: %lu setup applied, %lu queries answered, %lu telemetry, "
           "%lu frames sent, %lu tx errors, %lu slots skipped\n",
           (unsigned long)app.role.stats.setup_applied, (unsigned long)app.role.stats.setup_queries,
           (unsigned long)app.role.stats.telemetry_tx, (unsigned long)app.role.stats.frames_tx,
           (unsigned long)app.role.stats.tx_errors, (unsigned long)app.role.stats.slots_skipped);
    check(app.role.stats.tx_errors == 0u && app.encode_errors == 0u, "transmit errors",
          (long)(app.role.stats.tx_errors + app.encode_errors), 0);
    check(app.role.stats.slots_skipped == 0u && app.role.stats.telemetry_skipped == 0u,
          "telemetry slots skipped", (long)app.role.stats.slots_skipped, 0);

    /* The host's view of what the gimbal sent. */
    memset(&host, 0, sizeof(host));
    (void)tase_rx_init(&host_rx);
    (void)tase_rx_feed(&host_rx, tx_buf, tx_len, on_tx_frame, &host);
    (void)tase_rx_flush(&host_rx, on_tx_frame, &host);
    printf("tx: %lu bytes, %lu frames: %lu replies, %lu GIMBAL_ANGLE, %lu GIMBAL_RATE, "
           "%lu GEOREFERENCE\n",
           (unsigned long)tx_len, (unsigned long)host_rx.stats.frames_ok,
           (unsigned long)host.replies, (unsigned long)host.angles, (unsigned long)host.rates,
           (unsigned long)host.georefs);
    check(host.replies == COUNT(expect_replies), "replies", (long)host.replies,
          (long)COUNT(expect_replies));
    check(host.telemetry == COUNT(expect_telemetry), "telemetry frames", (long)host.telemetry,
          (long)COUNT(expect_telemetry));
    check(host.other == 0u, "unexpected frames sent", (long)host.other, 0);
    check(host_rx.stats.bytes_discarded == 0u && host_rx.stats.checksum_errors == 0u,
          "clean transmit stream", (long)host_rx.stats.bytes_discarded, 0);

    printf("image: flash %lu B (library %lu B, bare-metal port %lu B), RAM %lu B static "
           "+ %lu B stack used\n",
           span((const uint8_t *)0, __flash_end), span(__tase_lib_start, __tase_lib_end),
           span(__tase_port_start, __tase_port_end), span(_sdata, _ebss), stack);
    printf("library instances in RAM: tase_rx_t %lu x2, tase_dispatch_t %lu (in app), "
           "tase_gimbal_t %lu (in app), tase_bm_uart_t %lu + ring %lu\n",
           (unsigned long)sizeof(tase_rx_t), (unsigned long)sizeof(tase_dispatch_t),
           (unsigned long)sizeof(tase_gimbal_t), (unsigned long)sizeof(tase_bm_uart_t),
           (unsigned long)sizeof ring_storage);

    printf("%s: %u of %u checks failed\n", failures == 0u ? "PASS" : "FAIL", failures, checks);
    return failures == 0u ? 0 : 1;
}
