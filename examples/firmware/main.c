/*
 * Example gimbal firmware for QEMU's mps2-an385 (Cortex-M3).
 *
 * A recorded UART stream (stream.h: host requests mixed with line noise
 * and corruption) arrives byte by byte in a simulated receive interrupt
 * (SysTick stands in for the UART: 12 bytes per 1 ms tick, about 115200
 * baud), which puts each byte into a small ring buffer. The main loop
 * drains the ring into tase_rx_feed(), the gimbal answers setup queries
 * and sends GIMBAL_ANGLE, GIMBAL_RATE and GEOREFERENCE_DATA telemetry at
 * the rates of its PACKET_RATE settings into a transmit buffer. After one
 * simulated second the image checks everything against stream.h (frames
 * found, their offsets and contents, receiver counters) and feeds its own
 * transmit buffer through a second receiver, as the host would, to check
 * the replies and the telemetry. The summary goes out through semihosting;
 * the exit status is 0 when every check passed.
 */
#include <stdio.h>
#include <string.h>

#include "board.h"
#include "gimbal.h"
#include "stream.h"
#include "tase/ids.h"

#define CPU_HZ 25000000u   /* mps2-an385 */
#define TICK_HZ 1000u      /* one simulated millisecond per SysTick */
#define BYTES_PER_TICK 12u /* ~115200 baud */
#define RUN_MS 1000u       /* simulated run time */
#define RING_SIZE 64u      /* power of two */

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

/* Shared between the "ISR" and the main loop: single producer, single
 * consumer, 32-bit indices read and written atomically on Cortex-M. */
static volatile uint8_t ring[RING_SIZE];
static volatile uint32_t ring_head, ring_tail, ring_overflows;
static volatile uint32_t ticks, uart_pos;

/* What a UART receive interrupt handler does with each byte. */
static void uart_rx_isr(uint8_t b)
{
    uint32_t head = ring_head;
    if (head - ring_tail == RING_SIZE) {
        ring_overflows++;
        return;
    }
    ring[head & (RING_SIZE - 1u)] = b;
    ring_head = head + 1u;
}

void SysTick_Handler(void)
{
    uint32_t i;
    for (i = 0; i < BYTES_PER_TICK && uart_pos < sizeof(stream_bytes); i++) {
        uart_rx_isr(stream_bytes[uart_pos]);
        uart_pos++;
    }
    ticks++;
}

/* The gimbal's transmit side: a buffer the checks read back. */
static uint8_t tx_buf[8192];
static size_t tx_len;

static int tx_write(void *user, const uint8_t *data, size_t n)
{
    (void)user;
    if (n > sizeof(tx_buf) - tx_len) {
        return TASE_ENOSPC;
    }
    memcpy(&tx_buf[tx_len], data, n);
    tx_len += n;
    return (int)n;
}

static unsigned failures;

static void check(int ok, const char *what, unsigned long got, unsigned long want)
{
    if (!ok) {
        failures++;
        printf("FAIL %s: got %lu, want %lu\n", what, got, want);
    }
}

/* ---- receive side: the gimbal's UART ---- */

typedef struct {
    gimbal_t gimbal;
    size_t frames;
} app_t;

/* Checks each frame against the recording, then hands it to the gimbal. */
static void on_rx_frame(void *user, const tase_frame_t *f)
{
    app_t *app = user;
    size_t k = app->frames++;
    if (k < sizeof(expect_frames) / sizeof(expect_frames[0])) {
        const expect_frame_t *e = &expect_frames[k];
        check(f->offset == e->offset, "frame offset", f->offset, e->offset);
        check(f->group == e->group && f->type == e->type, "frame id", TASE_ID(f->group, f->type),
              TASE_ID(e->group, e->type));
        check(f->len == e->len, "frame length", f->len, e->len);
        check(f->len == e->len && e->offset + 6u + e->len <= sizeof(stream_bytes) &&
                  memcmp(f->data, &stream_bytes[e->offset + 6u], e->len) == 0,
              "frame data matches the recording", k, k);
    }
    gimbal_on_frame(&app->gimbal, f);
}

/* Copies out what the ISR has queued and feeds it to the receiver. */
static int drain(tase_rx_t *rx, app_t *app)
{
    uint8_t chunk[RING_SIZE];
    uint32_t tail = ring_tail;
    uint32_t n = ring_head - tail;
    uint32_t i;
    for (i = 0; i < n; i++) {
        chunk[i] = ring[(tail + i) & (RING_SIZE - 1u)];
    }
    ring_tail = tail + n;
    if (n > 0u) {
        (void)tase_rx_feed(rx, chunk, n, on_rx_frame, app);
    }
    return n > 0u;
}

/* ---- host side: what the gimbal sent ---- */

typedef struct {
    size_t replies, angles, rates, georefs, other;
} host_t;

static void on_tx_frame(void *user, const tase_frame_t *f)
{
    host_t *h = user;
    uint16_t id = TASE_ID(f->group, f->type);
    uint32_t t;
    if (f->group == TASE_GROUP_SETUP) {
        size_t k = h->replies++;
        if (k < sizeof(expect_replies) / sizeof(expect_replies[0])) {
            const expect_reply_t *e = &expect_replies[k];
            check(f->group == e->group && f->type == e->type && f->len == e->len &&
                      memcmp(f->data, e->data, e->len) == 0,
                  "reply matches", TASE_ID(f->group, f->type), TASE_ID(e->group, e->type));
        }
    } else if (id == TASE_ID_GIMBAL_ANGLE && f->len == 6u) {
        t = 100u * (uint32_t)h->angles++;
        check(f->data[0] == (uint8_t)((uint16_t)gimbal_sim_pan(t) >> 8) &&
                  f->data[1] == (uint8_t)gimbal_sim_pan(t) &&
                  f->data[2] == (uint8_t)((uint16_t)gimbal_sim_tilt(t) >> 8) &&
                  f->data[3] == (uint8_t)gimbal_sim_tilt(t),
              "GIMBAL_ANGLE contents at t", t, t);
    } else if (id == TASE_ID_GIMBAL_RATE && f->len == 18u) {
        t = ((uint32_t)f->data[0] << 24) | ((uint32_t)f->data[1] << 16) |
            ((uint32_t)f->data[2] << 8) | f->data[3];
        check(t == 100u * (uint32_t)h->rates, "GIMBAL_RATE time", t, 100u * h->rates);
        h->rates++;
    } else if (id == TASE_ID_GEOREFERENCE_DATA && f->len == 63u) {
        t = ((uint32_t)f->data[0] << 24) | ((uint32_t)f->data[1] << 16) |
            ((uint32_t)f->data[2] << 8) | f->data[3];
        check(t == 250u * (uint32_t)h->georefs, "GEOREFERENCE time", t, 250u * h->georefs);
        check(f->data[62] == (uint8_t)(62u + t), "GEOREFERENCE pattern", f->data[62], 62u + t);
        h->georefs++;
    } else {
        h->other++;
    }
}

int main(void)
{
    static app_t app;
    static tase_rx_t rx;
    static tase_rx_t host_rx;
    host_t host;
    const tase_rx_stats_t *st = &rx.stats;
    uint32_t now;

    tase_rx_init(&rx);
    gimbal_init(&app.gimbal, tx_write, NULL);

    SYST_RVR = CPU_HZ / TICK_HZ - 1u;
    SYST_CVR = 0u;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */

    /* The firmware's main loop. */
    for (;;) {
        now = ticks;
        if (now >= RUN_MS) {
            break;
        }
        gimbal_poll(&app.gimbal, now);
        if (!drain(&rx, &app)) {
            __asm__ volatile("wfi");
        }
    }
    SYST_CSR = 0u;
    (void)drain(&rx, &app);
    (void)tase_rx_flush(&rx, on_rx_frame, &app);

    printf("TASE gimbal example on Cortex-M3 (mps2-an385), %u simulated ms\n", (unsigned)RUN_MS);
    printf("rx: %lu bytes, %lu frames ok, %lu checksum errors, %lu bad size, "
           "%lu bytes discarded\n",
           (unsigned long)st->bytes_in, (unsigned long)st->frames_ok,
           (unsigned long)st->checksum_errors, (unsigned long)st->bad_size,
           (unsigned long)st->bytes_discarded);
    check(uart_pos == sizeof(stream_bytes), "bytes delivered by the ISR", uart_pos,
          sizeof(stream_bytes));
    check(ring_overflows == 0u, "ring overflows", ring_overflows, 0u);
    check(st->bytes_in == sizeof(stream_bytes), "bytes_in", st->bytes_in, sizeof(stream_bytes));
    check(app.frames == sizeof(expect_frames) / sizeof(expect_frames[0]), "frames delivered",
          app.frames, sizeof(expect_frames) / sizeof(expect_frames[0]));
    check(st->frames_ok == app.frames, "frames_ok", st->frames_ok, app.frames);
    check(st->checksum_errors == EXPECT_CHECKSUM_ERRORS, "checksum_errors", st->checksum_errors,
          EXPECT_CHECKSUM_ERRORS);
    check(st->bad_size == EXPECT_BAD_SIZE, "bad_size", st->bad_size, EXPECT_BAD_SIZE);
    check(st->bytes_discarded == EXPECT_BYTES_DISCARDED, "bytes_discarded", st->bytes_discarded,
          EXPECT_BYTES_DISCARDED);

    printf("gimbal: %lu commands, %lu gyro zeros, %lu replies, %lu telemetry, %lu ignored\n",
           (unsigned long)app.gimbal.commands, (unsigned long)app.gimbal.gyro_zeros,
           (unsigned long)app.gimbal.replies, (unsigned long)app.gimbal.telemetry,
           (unsigned long)app.gimbal.ignored);
    check(app.gimbal.cmd_pan == EXPECT_CMD_PAN, "commanded pan", (unsigned long)app.gimbal.cmd_pan,
          (unsigned long)EXPECT_CMD_PAN);
    check(app.gimbal.cmd_tilt == EXPECT_CMD_TILT, "commanded tilt",
          (unsigned long)app.gimbal.cmd_tilt, EXPECT_CMD_TILT);
    check(app.gimbal.gyro_zeros == EXPECT_GYRO_ZEROS, "gyro zeros", app.gimbal.gyro_zeros,
          EXPECT_GYRO_ZEROS);
    check(app.gimbal.ignored == EXPECT_IGNORED, "ignored", app.gimbal.ignored, EXPECT_IGNORED);
    check(app.gimbal.wrong_length == 0u && app.gimbal.tx_errors == 0u, "gimbal errors",
          app.gimbal.wrong_length + app.gimbal.tx_errors, 0u);

    /* The host's view of what the gimbal sent. */
    memset(&host, 0, sizeof(host));
    tase_rx_init(&host_rx);
    (void)tase_rx_feed(&host_rx, tx_buf, tx_len, on_tx_frame, &host);
    (void)tase_rx_flush(&host_rx, on_tx_frame, &host);
    printf("tx: %lu bytes, %lu frames: %lu replies, %lu GIMBAL_ANGLE, %lu GIMBAL_RATE, "
           "%lu GEOREFERENCE\n",
           (unsigned long)tx_len, (unsigned long)host_rx.stats.frames_ok,
           (unsigned long)host.replies, (unsigned long)host.angles, (unsigned long)host.rates,
           (unsigned long)host.georefs);
    check(host.replies == sizeof(expect_replies) / sizeof(expect_replies[0]), "replies",
          host.replies, sizeof(expect_replies) / sizeof(expect_replies[0]));
    /* Default rates 10, 10 and 4 Hz over RUN_MS, first ones at t = 0. */
    check(host.angles == 10u, "GIMBAL_ANGLE frames", host.angles, 10u);
    check(host.rates == 10u, "GIMBAL_RATE frames", host.rates, 10u);
    check(host.georefs == 4u, "GEOREFERENCE frames", host.georefs, 4u);
    check(host.other == 0u, "unexpected frames sent", host.other, 0u);
    check(host_rx.stats.bytes_discarded == 0u && host_rx.stats.checksum_errors == 0u,
          "clean transmit stream", host_rx.stats.bytes_discarded, 0u);

    printf("%s: %u check(s) failed\n", failures == 0u ? "PASS" : "FAIL", failures);
    return failures == 0u ? 0 : 1;
}
