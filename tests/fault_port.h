/* A fault-injecting port: wraps any tase_port_t and, driven by a seed,
 * makes its calls misbehave in every way the port contract (tase/port.h)
 * allows, plus the clock faults a real system shows. Modelled on nanopb's
 * fault-injecting streams: the code under test must survive any sequence
 * of them, and a seed reproduces a failing sequence exactly.
 *
 * Faults, each drawn per call with a probability in 1/256:
 *   short    write() passes only 1..n-1 bytes on to the wrapped port
 *   eagain   write() returns TASE_EAGAIN at once, taking nothing
 *   eintr    the call was interrupted before it did anything: write()
 *            returns 0, read() returns 0 at once (the early 0 the
 *            contract allows; a port resumes EINTR itself, so this is
 *            what an interruption may look like from above)
 *   stall    the call blocks for its whole bound and achieves nothing:
 *            write() spends write_bound_ms and returns TASE_EAGAIN, read()
 *            spends its timeout and returns 0
 *   slow     write() passes only 1..n-1 bytes on (all of a 1-byte write)
 *            and spends slow_ms doing it: a partial AND slow write (a
 *            serial driver that trickles a frame out)
 *   jump     now_ms() jumps forward by 1..jump_max_ms (time that did not
 *            pass: a clock step; jump_max_ms 0: no jumps)
 *   stale    now_ms() returns a sample 1..stale_max_ms older than the last
 *            one it returned (a value read earlier and handed in late;
 *            stale_max_ms 0: no stale samples)
 * and a hang-up after `hangup_after` calls (0: never): from then on read()
 * and write() return TASE_EIO.
 *
 * Time: the fault port's clock is the wrapped port's now_ms() plus an
 * offset that stalls and jumps advance. `spent_ms` counts only the time
 * stalls really spent, so a test can check a bound against it. Header-only,
 * like fake_port.h. */
#ifndef TASE_TEST_FAULT_PORT_H
#define TASE_TEST_FAULT_PORT_H

#include <string.h>

#include "tase/port.h"

typedef struct {
    tase_port_t inner;
    uint32_t rng; /* xorshift32 state, from the seed */
    /* probabilities in 1/256 per call (0: never) */
    unsigned p_short, p_eagain, p_eintr, p_stall, p_jump, p_stale, p_slow;
    uint32_t write_bound_ms; /* what a stalled write spends (the port's W) */
    uint32_t slow_ms;        /* what a slow partial write spends */
    uint32_t jump_max_ms, stale_max_ms;
    uint32_t hangup_after; /* calls before a permanent hang-up; 0 never */
    /* state */
    uint32_t offset;   /* added to the inner clock */
    uint32_t last;     /* last sample now_ms() returned honestly */
    uint32_t spent_ms; /* time stalls spent */
    uint32_t calls;    /* read() + write() calls */
    /* what was injected */
    unsigned shorts, eagains, eintrs, stalls, jumps, stales, hangups, slows;
} fault_port_t;

static inline uint32_t fault_rand(fault_port_t *f)
{
    f->rng ^= f->rng << 13;
    f->rng ^= f->rng >> 17;
    f->rng ^= f->rng << 5;
    return f->rng;
}

static inline int fault_hit(fault_port_t *f, unsigned p)
{
    return p > 0u && (fault_rand(f) & 0xFFu) < p;
}

/* Wrap `inner`; every probability zero (set the ones wanted), no hang-up. */
static inline void fault_init(fault_port_t *f, const tase_port_t *inner, uint32_t seed)
{
    memset(f, 0, sizeof *f);
    f->inner = *inner;
    f->rng = seed != 0u ? seed : 0x9E3779B9u;
    f->write_bound_ms = 100u;
    f->jump_max_ms = 1000u;
    f->stale_max_ms = 1000u;
    f->slow_ms = 10u;
    if (inner->ops->now_ms != NULL) {
        f->last = inner->ops->now_ms(inner->ctx);
    }
}

/* The faults read() and write() share: a hang-up (TASE_EIO from then on)
 * and an interruption before anything was done (0). True when one hit,
 * with the call's result in *r. */
static inline int fault_early(fault_port_t *f, int *r)
{
    f->calls++;
    if (f->hangup_after != 0u && f->calls > f->hangup_after) {
        f->hangups++;
        *r = TASE_EIO;
        return 1;
    }
    if (fault_hit(f, f->p_eintr)) {
        f->eintrs++;
        *r = 0;
        return 1;
    }
    return 0;
}

static inline int fault_write(void *ctx, const uint8_t *data, size_t n)
{
    fault_port_t *f = ctx;
    int r;
    if (fault_early(f, &r)) {
        return r;
    }
    if (fault_hit(f, f->p_eagain)) {
        f->eagains++;
        return TASE_EAGAIN;
    }
    if (fault_hit(f, f->p_stall)) {
        f->stalls++;
        f->offset += f->write_bound_ms;
        f->spent_ms += f->write_bound_ms;
        return TASE_EAGAIN;
    }
    if (fault_hit(f, f->p_slow)) {
        f->slows++;
        f->offset += f->slow_ms;
        f->spent_ms += f->slow_ms;
        if (n > 1u) {
            n = 1u + fault_rand(f) % (uint32_t)(n - 1u);
        }
    } else if (n > 1u && fault_hit(f, f->p_short)) {
        f->shorts++;
        n = 1u + fault_rand(f) % (uint32_t)(n - 1u);
    }
    return f->inner.ops->write(f->inner.ctx, data, n);
}

static inline int fault_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    fault_port_t *f = ctx;
    int r;
    if (fault_early(f, &r)) {
        return r;
    }
    if (fault_hit(f, f->p_stall)) {
        f->stalls++;
        f->offset += timeout_ms;
        f->spent_ms += timeout_ms;
        return 0;
    }
    return f->inner.ops->read(f->inner.ctx, buf, cap, timeout_ms);
}

static inline uint32_t fault_now(void *ctx)
{
    fault_port_t *f = ctx;
    uint32_t now;
    if (f->jump_max_ms > 0u && fault_hit(f, f->p_jump)) {
        f->jumps++;
        f->offset += 1u + fault_rand(f) % f->jump_max_ms;
    }
    now = f->inner.ops->now_ms(f->inner.ctx) + f->offset;
    if (f->stale_max_ms > 0u && fault_hit(f, f->p_stale)) {
        f->stales++;
        return f->last - (1u + fault_rand(f) % f->stale_max_ms);
    }
    f->last = now;
    return now;
}

static const tase_port_ops_t fault_ops = {fault_write, fault_read, fault_now};

static inline tase_port_t fault_port(fault_port_t *f)
{
    tase_port_t p;
    p.ops = &fault_ops;
    p.ctx = f;
    p.bytes_per_s = f->inner.bytes_per_s;
    return p;
}

#endif
