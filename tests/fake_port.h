/* A test double of the port boundary with a fake clock: records written
 * bytes, serves scripted received bytes, and lets time pass only when the
 * test (or a waiting read) says so. Header-only, shared by the role tests. */
#ifndef TASE_TEST_FAKE_PORT_H
#define TASE_TEST_FAKE_PORT_H

#include <string.h>

#include "tase/frame.h"
#include "tase/port.h"

#define FAKE_CAP 65536u

typedef struct {
    uint32_t now;
    uint8_t out[FAKE_CAP]; /* everything written */
    size_t nout;
    uint8_t in[FAKE_CAP]; /* bytes waiting to be read */
    size_t nin, rin;
    int write_result;   /* < 0: every write fails with it */
    size_t write_limit; /* > 0: a write takes at most this many bytes */
    unsigned writes;    /* write() calls that took bytes */
    uint32_t write_ms;  /* each write() call blocks this long (fake clock) */
    int frozen;         /* true: the clock never moves, an empty read returns at once */
    int discard;        /* true: count written bytes, keep none */
    size_t discarded;
    /* Scripted peer: after `reply_after` frames were written, the frame
     * reply[0..nreply) becomes readable (once). 0 disables. */
    unsigned reply_after;
    uint8_t reply[TASE_FRAME_MAX];
    size_t nreply;
    uint32_t reply_delay_ms; /* the reply comes this long after it is due */
    uint32_t reply_at;       /* when it comes (reply_due: it has not yet) */
    int reply_due;
} fake_port_t;

static inline void fake_push(fake_port_t *f, const uint8_t *p, size_t n)
{
    memcpy(f->in + f->nin, p, n);
    f->nin += n;
}

static inline void fake_push_frame(fake_port_t *f, uint8_t group, uint8_t type, const uint8_t *data,
                                   size_t len)
{
    uint8_t fr[TASE_FRAME_MAX];
    int n = tase_frame_build(group, type, data, len, fr, sizeof fr);
    if (n > 0) {
        fake_push(f, fr, (size_t)n);
    }
}

static inline int fake_write(void *ctx, const uint8_t *data, size_t n)
{
    fake_port_t *f = ctx;
    f->now += f->write_ms;
    if (f->write_result < 0) {
        return f->write_result;
    }
    if (f->write_limit > 0 && n > f->write_limit) {
        n = f->write_limit;
    }
    if (f->discard) {
        f->discarded += n;
        f->writes++;
        return (int)n;
    }
    if (f->nout + n > FAKE_CAP) {
        return TASE_ENOBUFS;
    }
    memcpy(f->out + f->nout, data, n);
    f->nout += n;
    f->writes++;
    return (int)n;
}

/* Frames found in the written bytes so far. */
static inline unsigned fake_frames_out(const fake_port_t *f)
{
    tase_rx_t rx;
    tase_rx_init(&rx);
    return (unsigned)tase_rx_feed(&rx, f->out, f->nout, NULL, NULL);
}

static inline int fake_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    fake_port_t *f = ctx;
    size_t n;
    if (f->reply_after != 0 && fake_frames_out(f) >= f->reply_after) {
        f->reply_after = 0;
        f->reply_at = f->now + f->reply_delay_ms;
        f->reply_due = 1;
    }
    if (f->reply_due && !f->frozen && f->reply_at - f->now <= timeout_ms) {
        f->now = f->reply_at - f->now < 0x80000000u ? f->reply_at : f->now; /* waited for it */
        f->reply_due = 0;
        fake_push(f, f->reply, f->nreply);
    }
    n = f->nin - f->rin;
    if (n == 0) {
        if (!f->frozen) {
            f->now += timeout_ms; /* waited in vain */
        }
        return 0;
    }
    if (n > cap) {
        n = cap;
    }
    memcpy(buf, f->in + f->rin, n);
    f->rin += n;
    f->now += 1; /* a byte takes time to arrive */
    return (int)n;
}

static inline uint32_t fake_now(void *ctx)
{
    return ((fake_port_t *)ctx)->now;
}

static const tase_port_ops_t fake_ops = {fake_write, fake_read, fake_now};

#endif
