/*
 * Receiver benchmark on Cortex-M4: Thumb-2 instructions per byte, run under
 * QEMU's mps2-an386 board with -icount shift=0 (scripts/bench.sh).
 *
 * With -icount shift=0 QEMU's virtual clock advances one nanosecond per
 * executed instruction, and the board's CMSDK APB timer 0 counts down at
 * 25 MHz of that clock: one tick is 40 instructions. Reading it before and
 * after feeding a 256 KiB stream counts the instructions of the run to 40
 * in millions. A calibration loop of known length checks the factor.
 *
 * Each line printed: NAME STREAM BYTES INSTRUCTIONS FRAMES. The byte loops
 * (store-and-sum, classic parser, tase_rx_push) count the caller's loop
 * too (load the byte, call, loop: the same for all three);
 * tase_rx_feed is called once per CHUNK bytes.
 */
#include <stdio.h>
#include <string.h>

#include "../classic_rx.h"
#include "../streams.h"
#include "tase/frame.h"

#define TIMER0_CTRL (*(volatile uint32_t *)0x40000000u)
#define TIMER0_VALUE (*(volatile uint32_t *)0x40000004u)
#define TIMER0_RELOAD (*(volatile uint32_t *)0x40000008u)
#define INSN_PER_TICK 40u /* 1 ns per instruction, 25 MHz timer */

static uint8_t stream[256u * 1024u];
static unsigned long seen;

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    seen += f->len + 1u;
}

static uint32_t ticks(void)
{
    return TIMER0_VALUE;
}

static unsigned long since(uint32_t t0)
{
    return (unsigned long)(t0 - ticks()) * INSN_PER_TICK; /* counts down */
}

/* Exactly 2 * n instructions (subs + bne per turn). */
static void known_loop(uint32_t n)
{
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
}

static void run_stream(const char *name)
{
    static tase_rx_t rx;
    static classic_rx_t classic;
    static store_sum_t ss;
    static const size_t chunks[2] = {4096u, 64u};
    size_t n = bench_stream(name, stream, sizeof(stream));
    size_t i, k;
    uint32_t t0;

    t0 = ticks();
    for (i = 0; i < n; i++) {
        store_sum_push(&ss, stream[i]);
    }
    printf("store_sum %s %lu %lu 0\n", name, (unsigned long)n, since(t0));

    classic_rx_init(&classic);
    t0 = ticks();
    for (i = 0; i < n; i++) {
        (void)classic_rx_push(&classic, stream[i], on_frame, NULL);
    }
    printf("classic %s %lu %lu %lu\n", name, (unsigned long)n, since(t0),
           (unsigned long)classic.frames);

    (void)tase_rx_init(&rx);
    t0 = ticks();
    for (i = 0; i < n; i++) {
        (void)tase_rx_push(&rx, stream[i], on_frame, NULL);
    }
    printf("tase_rx_push %s %lu %lu %lu\n", name, (unsigned long)n, since(t0),
           (unsigned long)rx.stats.frames_ok);

    for (k = 0; k < 2u; k++) {
        (void)tase_rx_init(&rx);
        t0 = ticks();
        for (i = 0; i < n; i += chunks[k]) {
            (void)tase_rx_feed(&rx, &stream[i], (n - i < chunks[k]) ? n - i : chunks[k], on_frame,
                               NULL);
        }
        printf("tase_rx_feed/%lu %s %lu %lu %lu\n", (unsigned long)chunks[k], name,
               (unsigned long)n, since(t0), (unsigned long)rx.stats.frames_ok);
    }
}

int main(void)
{
    uint32_t t0;
    TIMER0_CTRL = 0u;
    TIMER0_RELOAD = 0xFFFFFFFFu;
    TIMER0_VALUE = 0xFFFFFFFFu;
    TIMER0_CTRL = 1u; /* enable, no interrupt */
    t0 = ticks();
    known_loop(1000000u);
    printf("calibration - 2000000 %lu 0\n", since(t0));
    run_stream("telemetry");
    run_stream("sync4");
    return 0;
}
