/*
 * Adversarial search for the receiver's worst calls, on Cortex-M under
 * QEMU (bench/search.sh builds and runs it). A hill climb over one period
 * of bytes, repeated to fill SEARCH_EVAL bytes: each step mutates the
 * period (a byte, a sync, a Size nudged, a run copied, bytes inserted or
 * deleted, a valid frame made) and keeps the mutation when the measure is
 * at least as large. Counts are exact (bench_cm.c, THE CLOCK), so a run is
 * the same on every machine: the seed stream, SEARCH_ITERS and SEARCH_RNG
 * name it.
 *
 * Measures (SEARCH_MODE): 0 the longest tase_rx_push(), 1 the longest
 * 16-byte tase_rx_feed(), 2 the longest 64-byte one (the longest call of
 * the SEARCH_EVAL bytes: coarse counts for all, exact for the few within a
 * tick of the largest), 3 the instructions of pushing all SEARCH_EVAL
 * bytes (the sustained cost, per byte once divided), to the timer's tick
 * (MEASURE_TICK_INSNS): an exact count would take MEASURE_REPS runs of
 * every call, and the tiled replay that reports the figure (below) spans
 * 128 periods, where a tick is nothing.
 *
 * Output: "seed SCORE", a line per improvement ("step N SCORE at OFFSET")
 * and "best SCORE"; the best period goes to SEARCH_OUT (semihosting). For
 * the sustained measure the best period is also tiled over a bench
 * stream's length and reported as bench.sh reports a stream ("tiled ...
 * a byte net"). The best period is measured again
 * at the end: the program fails (exit 1) unless it scores the same, as
 * exact counts must (the sustained measure: within a tick, since the
 * count of a span depends on where it starts within one).
 */
#include <stdio.h>
#include <string.h>

#include "../streams.h"
#include "longest.h"
#include "measure.h"
#include "tase/frame.h"

#ifndef SEARCH_MODE
#define SEARCH_MODE 0
#endif
#ifndef SEARCH_EVAL
#define SEARCH_EVAL 2048u
#endif
#ifndef SEARCH_PERIOD
#define SEARCH_PERIOD 2048u
#endif
#ifndef SEARCH_ITERS
#define SEARCH_ITERS 2000u
#endif
#ifndef SEARCH_RNG
#define SEARCH_RNG 12345u
#endif
#ifndef SEARCH_SEED
#define SEARCH_SEED "syncrand"
#endif
#ifndef SEARCH_OUT
#define SEARCH_OUT "search.bin"
#endif
/* calls measured exactly per evaluation (the longest by coarse count) */
#define EXACT_CALLS 4u

typedef char search_period_check[(SEARCH_PERIOD >= 64u && SEARCH_PERIOD <= SEARCH_EVAL) ? 1 : -1];

static uint8_t period[SEARCH_PERIOD];
static uint8_t kept[SEARCH_PERIOD];
static uint8_t stream[SEARCH_EVAL];
static uint16_t coarse[SEARCH_EVAL];
static tase_rx_t rx;
static unsigned long frames;
static uint32_t rng = SEARCH_RNG;
static size_t worst_at;

static uint32_t rnd(void)
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    frames += f->len + 1u;
}

/* One call of the receiver on n bytes at p; out of line, so that the
 * measured call is the same for every input. */
typedef longest_call_fn rx_call_fn;

__attribute__((noinline, unused)) static int call_push(const uint8_t *p, size_t n)
{
    (void)n;
    return tase_rx_push(&rx, *p, on_frame, NULL);
}

__attribute__((noinline, unused)) static int call_feed(const uint8_t *p, size_t n)
{
    return tase_rx_feed(&rx, p, n, on_frame, NULL);
}

/* The longest call when the stream goes in `chunk` bytes a call. */
__attribute__((unused)) static unsigned long longest(rx_call_fn fn, size_t chunk)
{
    longest_t r = longest_call(&rx, fn, stream, SEARCH_EVAL, chunk, coarse, EXACT_CALLS);
    worst_at = r.call * chunk;
    return r.insns;
}

static unsigned long score(void)
{
    size_t i;
    for (i = 0; i < SEARCH_EVAL; i++) {
        stream[i] = period[i % SEARCH_PERIOD];
    }
#if SEARCH_MODE == 0
    return longest(call_push, 1u);
#elif SEARCH_MODE == 1
    return longest(call_feed, 16u);
#elif SEARCH_MODE == 2
    return longest(call_feed, 64u);
#else
    {
        uint32_t t0;
        (void)tase_rx_init(&rx);
        t0 = measure_ticks();
        for (i = 0; i < SEARCH_EVAL; i++) {
            (void)tase_rx_push(&rx, stream[i], on_frame, NULL);
        }
        worst_at = 0;
        return measure_since(t0);
    }
#endif
}

/* A valid frame at period[at] whose Size is the byte there now (at least
 * 2), if it fits in the period. */
static void make_frame_at(size_t at)
{
    size_t size = period[(at + 3u) % SEARCH_PERIOD];
    size_t j;
    uint16_t sum = 0;
    if (size < 2u) {
        size = 2u;
    }
    if (at + size + 6u > SEARCH_PERIOD) {
        return;
    }
    period[at] = TASE_SYNC1;
    period[at + 1u] = TASE_SYNC2;
    period[at + 2u] = TASE_SYNC3;
    period[at + 3u] = (uint8_t)size;
    for (j = 0; j < size + 4u; j++) {
        sum = (uint16_t)(sum + period[at + j]);
    }
    period[at + size + 4u] = (uint8_t)(sum >> 8);
    period[at + size + 5u] = (uint8_t)sum;
}

static void mutate(void)
{
    static const uint8_t likely[] = {0x00, 0xFF, 0x5A, 0x01, 0x02, 0x11};
    const size_t P = SEARCH_PERIOD;
    unsigned m;
    unsigned count = 1u + rnd() % 3u;
    for (m = 0; m < count; m++) {
        size_t a = rnd() % P;
        size_t b = rnd() % P;
        size_t len;
        size_t j;
        switch (rnd() % 10u) {
        case 0: period[a] = (uint8_t)rnd(); break;
        case 1: period[a] = likely[rnd() % sizeof likely]; break;
        case 2:
        case 3:
            /* a sync with a random Size */
            period[a] = TASE_SYNC1;
            period[(a + 1u) % P] = TASE_SYNC2;
            period[(a + 2u) % P] = TASE_SYNC3;
            period[(a + 3u) % P] = (uint8_t)rnd();
            break;
        case 4:
            /* the Size of the next sync, by -4..+4 */
            for (j = 0; j < P; j++) {
                size_t q = (a + j) % P;
                if (period[q] == TASE_SYNC1 && period[(q + 1u) % P] == TASE_SYNC2 &&
                    period[(q + 2u) % P] == TASE_SYNC3) {
                    size_t s = (q + 3u) % P;
                    period[s] = (uint8_t)(period[s] + rnd() % 9u - 4u);
                    break;
                }
            }
            break;
        case 5:
            /* a run copied elsewhere */
            len = 1u + rnd() % 64u;
            for (j = 0; j < len; j++) {
                period[(b + j) % P] = period[(a + j) % P];
            }
            break;
        case 6:
            /* 1..4 bytes inserted (the end of the period drops off) */
            len = 1u + rnd() % 4u;
            if (a + len < P) {
                (void)memmove(&period[a + len], &period[a], P - a - len);
            }
            for (j = 0; j < len && a + j < P; j++) {
                period[a + j] = (rnd() & 1u) ? TASE_SYNC1 : (uint8_t)rnd();
            }
            break;
        case 7:
            /* 1..4 bytes deleted (the end repeats) */
            len = 1u + rnd() % 4u;
            if (a + len < P) {
                (void)memmove(&period[a], &period[a + len], P - a - len);
            }
            break;
        case 8: make_frame_at(a); break;
        default: period[a] = (uint8_t)(period[a] + rnd() % 5u - 2u); break;
        }
    }
}

#if SEARCH_MODE == 3
/* The best period as bench.sh measures a stream's sustained cost (its
 * "worst sustained, push" row): tiled TILE_PERIODS times through one
 * receiver (262,144 bytes, a bench stream's length), the instructions of
 * the tase_rx_push() loop less those of the same loop calling a function
 * that returns, per byte. The search's own score is one period pushed
 * into a fresh receiver, which counts the scan's start too. */
#define TILE_PERIODS (262144u / SEARCH_PERIOD)

__attribute__((noinline, noipa)) static int empty_call(const uint8_t *p, size_t n)
{
    (void)p;
    (void)n;
    return 0;
}

static void report_tiled(void)
{
    unsigned long bytes = (unsigned long)TILE_PERIODS * SEARCH_PERIOD;
    unsigned long push;
    unsigned long loop;
    unsigned long tenths;
    size_t k;
    size_t i;
    uint32_t t0;
    (void)tase_rx_init(&rx);
    t0 = measure_ticks();
    for (k = 0; k < TILE_PERIODS; k++) {
        for (i = 0; i < SEARCH_PERIOD; i++) {
            (void)tase_rx_push(&rx, kept[i], on_frame, NULL);
        }
    }
    push = measure_since(t0);
    t0 = measure_ticks();
    for (k = 0; k < TILE_PERIODS; k++) {
        for (i = 0; i < SEARCH_PERIOD; i++) {
            (void)empty_call(&kept[i], 1u);
        }
    }
    loop = measure_since(t0);
    tenths = (push > loop) ? ((push - loop) * 10u + bytes / 2u) / bytes : 0u;
    printf("tiled %lu bytes: %lu instructions, the caller's loop %lu: %lu.%lu a byte net "
           "(bench.sh's sustained push figure)\n",
           bytes, push, loop, tenths / 10u, tenths % 10u);
}
#endif

static void save(void)
{
    FILE *f = fopen(SEARCH_OUT, "wb");
    if (f != NULL) {
        (void)fwrite(kept, 1, SEARCH_PERIOD, f);
        (void)fclose(f);
    }
}

int main(void)
{
    static uint8_t seed[SEARCH_EVAL];
    static uint8_t regen[SEARCH_EVAL];
    size_t seed_n;
    unsigned long best;
    unsigned long again;
    unsigned long step;
    measure_start();
    seed_n = bench_stream(SEARCH_SEED, seed, sizeof seed);
    if (seed_n < SEARCH_PERIOD) {
        printf("search: seed stream %s is unknown or shorter than the period\n", SEARCH_SEED);
        return 1;
    }
    /* the seed is the bench's stream of that name whatever a program
     * generated before it (streams.h): generated again after another */
    (void)bench_stream("noise", regen, sizeof regen);
    if (bench_stream(SEARCH_SEED, regen, sizeof regen) != seed_n ||
        memcmp(regen, seed, seed_n) != 0) {
        printf("search: stream %s has other bytes after another stream\n", SEARCH_SEED);
        return 1;
    }
    (void)memcpy(period, seed, SEARCH_PERIOD);
    best = score();
    (void)memcpy(kept, period, SEARCH_PERIOD);
    printf("seed %lu (%s, mode %d, %u-byte period, %u bytes a measure)\n", best, SEARCH_SEED,
           SEARCH_MODE, (unsigned)SEARCH_PERIOD, (unsigned)SEARCH_EVAL);
    for (step = 0; step < SEARCH_ITERS; step++) {
        unsigned long s;
        mutate();
        s = score();
        if (s >= best) {
            if (s > best) {
                printf("step %lu %lu at %lu\n", step, s, (unsigned long)worst_at);
            }
            best = s;
            (void)memcpy(kept, period, SEARCH_PERIOD);
        } else {
            (void)memcpy(period, kept, SEARCH_PERIOD);
        }
    }
    save();
    printf("best %lu (%lu frames seen)\n", best, frames);
    (void)memcpy(period, kept, SEARCH_PERIOD);
    again = score();
#if SEARCH_MODE == 3
    if (again + MEASURE_TICK_INSNS < best || again > best + MEASURE_TICK_INSNS) {
#else
    if (again != best) {
#endif
        printf("search: the best period does not score %lu again (%lu)\n", best, again);
        return 1;
    }
#if SEARCH_MODE == 3
    report_tiled();
#endif
    return 0;
}
