/*
 * Receiver benchmark on Cortex-M (M4 and M0+ code), run under QEMU's
 * mps2-an386 board with -icount shift=0 (bench/bench.sh). M0+ images are
 * ARMv6-M code (-mcpu=cortex-m0plus), which the board's Cortex-M4 runs
 * instruction for instruction the same: QEMU has no M0+ board.
 *
 * THE CLOCK. With -icount shift=0 QEMU's virtual clock advances one
 * nanosecond per executed instruction, and the board's CMSDK APB timer 0
 * counts down at 25 MHz of that clock: one tick is 40 instructions.
 *   - Long runs (a whole stream): ticks * 40, exact to 40 in millions. A
 *     calibration loop of known length checks the factor.
 *   - One call, exactly (measure.c): the call is repeated 200 times from
 *     a copy of the receiver taken before it (restore, call), and the same
 *     loop is timed around a function that does nothing (1 instruction,
 *     bx lr). (A - B) / 200 + 1 is the call's count with an error below
 *     80 / 200 < 0.5: rounded, it is exact, and the same on every run.
 *   - The longest call of a stream: pass 1 times every call once (a
 *     coarse count, +-39 instructions); pass 2 replays the stream and
 *     counts exactly every call whose coarse count is within 79 of the
 *     largest (no other call can be longer than the longest of those), the
 *     first MAX_EXACT of them (longest.c, shared with search.c).
 *
 * Output lines (bench/bench.sh parses them):
 *   calibration INSNS                       (want 2000000)
 *   loop NAME STREAM BYTES INSNS FRAMES     a whole-stream loop
 *   maxcall NAME STREAM INSNS CALL EXACT CANDIDATES
 *   stack NAME BYTES                        deepest stack below the caller, by painting
 *   sizeof tase_rx_t BYTES
 */
#include <stdio.h>
#include <string.h>

#include "../classic_rx.h"
#include "../streams.h"
#include "longest.h"
#include "measure.h"
#include "tase/frame.h"

#define STREAM_BYTES (256u * 1024u)
#define MAXCALL_BYTES 8192u /* calls examined for the longest one */
#define MAX_EXACT 64u

#define NOINLINE __attribute__((noinline, noipa))

static uint8_t stream[STREAM_BYTES];
static uint16_t coarse[MAXCALL_BYTES];
static unsigned long seen;
static tase_rx_t rx;

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    seen += f->len + 1u;
}

static uint32_t ticks(void)
{
    return measure_ticks();
}

static unsigned long since(uint32_t t0)
{
    return measure_since(t0);
}

/* ---- the calls measured: one signature, so one timing loop ----------- */

typedef longest_call_fn call_fn;

NOINLINE static int call_push(const uint8_t *p, size_t n)
{
    (void)n;
    return tase_rx_push(&rx, *p, on_frame, NULL);
}

NOINLINE static int call_feed(const uint8_t *p, size_t n)
{
    return tase_rx_feed(&rx, p, n, on_frame, NULL);
}

/* The caller's loop alone: the same call, to a function that returns. */
NOINLINE static int empty_call(const uint8_t *p, size_t n)
{
    (void)p;
    (void)n;
    return 0;
}

/* The longest single call of f over the first `bytes` of the stream, fed
 * `chunk` bytes per call (1 for push): longest.c. */
static void max_call(const char *name, const char *sname, call_fn f, size_t n, size_t chunk)
{
    longest_t r;
    if (n > MAXCALL_BYTES) {
        n = MAXCALL_BYTES;
    }
    r = longest_call(&rx, f, stream, n, chunk, coarse, MAX_EXACT);
    printf("maxcall %s %s %lu %lu %lu %lu\n", name, sname, r.insns, (unsigned long)r.call,
           (unsigned long)r.exact, (unsigned long)r.candidates);
}

/* ---- whole-stream loops ---------------------------------------------- */

static void loops(const char *sname, size_t n)
{
    static classic_rx_t classic;
    static store_sum_t ss;
    static const size_t chunks[3] = {4096u, 64u, 16u};
    size_t i, k;
    uint32_t t0;
    unsigned long frames0;

    t0 = ticks();
    for (i = 0; i < n; i++) {
        (void)empty_call(&stream[i], 1u);
    }
    printf("loop empty %s %lu %lu 0\n", sname, (unsigned long)n, since(t0));

    t0 = ticks();
    for (i = 0; i < n; i++) {
        store_sum_push(&ss, stream[i]);
    }
    printf("loop store_sum %s %lu %lu 0\n", sname, (unsigned long)n, since(t0));

    classic_rx_init(&classic);
    t0 = ticks();
    for (i = 0; i < n; i++) {
        (void)classic_rx_push(&classic, stream[i], on_frame, NULL);
    }
    printf("loop classic %s %lu %lu %lu\n", sname, (unsigned long)n, since(t0),
           (unsigned long)classic.frames);

    (void)tase_rx_init(&rx);
    t0 = ticks();
    for (i = 0; i < n; i++) {
        (void)tase_rx_push(&rx, stream[i], on_frame, NULL);
    }
    printf("loop tase_rx_push %s %lu %lu %lu\n", sname, (unsigned long)n, since(t0),
           (unsigned long)rx.stats.frames_ok);

    for (k = 0; k < 3u; k++) {
        (void)tase_rx_init(&rx);
        t0 = ticks();
        for (i = 0; i < n; i += chunks[k]) {
            (void)tase_rx_feed(&rx, &stream[i], (n - i < chunks[k]) ? n - i : chunks[k], on_frame,
                               NULL);
        }
        frames0 = since(t0);
        printf("loop tase_rx_feed/%lu %s %lu %lu %lu\n", (unsigned long)chunks[k], sname,
               (unsigned long)n, frames0, (unsigned long)rx.stats.frames_ok);
    }
}

/* Deepest stack below this function's frame while tase_rx_push() runs
 * over the stream (painted before, read back after): the push path only
 * (tase_rx_flush()'s is in docs/FOOTPRINT.md). */
#define PAINT_BYTES 2048u
#define PAINT 0xA5C3E187u

NOINLINE static void stack_push(const char *sname, size_t n)
{
    uint32_t *sp;
    uint32_t *w;
    size_t i;
    __asm__ volatile("mov %0, sp" : "=l"(sp));
    for (w = sp - PAINT_BYTES / 4u; w < sp - 4; w++) {
        *w = PAINT;
    }
    (void)tase_rx_init(&rx);
    for (i = 0; i < n; i++) {
        (void)tase_rx_push(&rx, stream[i], on_frame, NULL);
    }
    for (w = sp - PAINT_BYTES / 4u; w < sp - 4 && *w == PAINT; w++) {
    }
    printf("stack tase_rx_push/%s %lu\n", sname, (unsigned long)((size_t)(sp - w) * 4u));
}

static const char *const streams[] = {"telemetry", "badsize", "sync4",   "syncrand",
                                      "noise",     "zeros",   "held255", "burst",
                                      "heldnoise", "halfsum", "synclong"};

int main(void)
{
    uint32_t t0;
    size_t s, n;
    measure_start();
    t0 = ticks();
    measure_known_loop(1000000u);
    printf("calibration %lu\n", since(t0));
    printf("sizeof tase_rx_t %lu\n", (unsigned long)sizeof(tase_rx_t));
    for (s = 0; s < sizeof(streams) / sizeof(streams[0]); s++) {
        n = bench_stream(streams[s], stream, sizeof(stream));
        loops(streams[s], n);
        max_call("tase_rx_push", streams[s], call_push, n, 1u);
        max_call("tase_rx_feed/16", streams[s], call_feed, n, 16u);
        max_call("tase_rx_feed/64", streams[s], call_feed, n, 64u);
        stack_push(streams[s], n < MAXCALL_BYTES ? n : MAXCALL_BYTES);
    }
    return 0;
}
