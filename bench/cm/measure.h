/*
 * bench/cm/measure.h - exact instruction counts under QEMU -icount
 * shift=0 on mps2-an386 (bench_cm.c, timing.c): see bench_cm.c, THE CLOCK.
 */
#ifndef BENCH_CM_MEASURE_H
#define BENCH_CM_MEASURE_H

#include <stdint.h>

#define MEASURE_REPS 200u

/* Instructions per timer tick: measure_since() counts to this many (1 ns
 * an instruction, a 25 MHz timer). */
#define MEASURE_TICK_INSNS 40u

/* Start the CMSDK timer (call once). */
void measure_start(void);

/* Timer value (counts down, MEASURE_TICK_INSNS instructions a tick). */
uint32_t measure_ticks(void);

/* Instructions since measure_ticks() returned t0, to a tick: how many
 * ticks fall in the span depends on where it starts within one. */
unsigned long measure_since(uint32_t t0);

/* A step of a measurement, on a context. */
typedef void (*measure_fn)(void *ctx);

/* Exact instructions of call(ctx) right after setup(ctx) (which puts the
 * state back), as a caller that passes ctx makes the call (the argument
 * setup and branch included): both run MEASURE_REPS times, against the
 * same loop around an empty function. */
unsigned long measure_exact(measure_fn setup, measure_fn call, void *ctx);

/* Exactly 2 * n instructions (n >= 1): the calibration loop. */
void measure_known_loop(uint32_t n);

#endif /* BENCH_CM_MEASURE_H */
