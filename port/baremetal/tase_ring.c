/* SPSC byte ring for ISR -> main loop; the ordering argument is in
 * tase/ring.h. */
#include "tase/ring.h"

/* Optional port configuration header (e.g. -DTASE_RING_CONFIG='"cfg.h"')
 * that may define TASE_RING_BARRIER(). */
#ifdef TASE_RING_CONFIG
#include TASE_RING_CONFIG
#endif

#ifndef TASE_RING_BARRIER
#define TASE_RING_BARRIER() ((void)0)
#endif

int tase_ring_init(tase_ring_t *r, uint8_t *buf, size_t cap)
{
    /* cap - 1 must fit 31 bits, tested without comparing size_t to a
     * constant it cannot reach where size_t is 16 bits (AVR). */
    uint32_t mask = (uint32_t)(cap - 1u);

    if (r == NULL || buf == NULL || cap == 0 || (size_t)mask != cap - 1u || mask > 0x7FFFFFFFu ||
        (cap & (cap - 1u)) != 0) {
        return TASE_EARG;
    }
    r->buf = buf;
    r->mask = mask;
    r->head = 0;
    r->tail = 0;
    r->overflow = 0;
    return TASE_OK;
}

bool tase_ring_put(tase_ring_t *r, uint8_t byte)
{
    uint32_t head;
    uint32_t tail;

    if (r == NULL || r->buf == NULL) {
        return false; /* two compares: cheap enough for the ISR path */
    }
    head = r->head; /* ours: no one else changes it */
    tail = r->tail;
    if (head - tail > r->mask) {
        r->overflow = r->overflow + 1u;
        return false;
    }
    /* The slot was freed by the consumer's tail store; its reads of the
     * slot must be complete before we overwrite it. */
    TASE_RING_BARRIER();
    r->buf[head & r->mask] = byte;
    /* Data before index: the consumer trusts every byte below head. */
    TASE_RING_BARRIER();
    r->head = head + 1u;
    return true;
}

size_t tase_ring_get(tase_ring_t *r, uint8_t *out, size_t cap)
{
    uint32_t tail, avail, i;

    if (r == NULL || out == NULL || r->buf == NULL) {
        return 0;
    }
    tail = r->tail;
    avail = r->head - tail;
    TASE_RING_BARRIER(); /* head read before the data it publishes */
    if (cap < avail) {
        avail = (uint32_t)cap;
    }
    for (i = 0; i < avail; i++) {
        out[i] = r->buf[(tail + i) & r->mask];
    }
    /* Finish reading the slots before handing them back to the ISR. */
    TASE_RING_BARRIER();
    r->tail = tail + avail;
    return (size_t)avail; /* <= cap */
}

uint32_t tase_ring_count(const tase_ring_t *r)
{
    uint32_t tail, n;
    if (r == NULL) {
        return 0;
    }
    /* tail first: both only grow, so the difference cannot go negative;
     * clamp because both sides may have moved between the two loads. */
    tail = r->tail;
    n = r->head - tail;
    return n > r->mask ? r->mask + 1u : n;
}

uint32_t tase_ring_overflows(const tase_ring_t *r)
{
    return r == NULL ? 0u : r->overflow;
}

uint32_t tase_ring_capacity(const tase_ring_t *r)
{
    return r == NULL ? 0u : r->mask + 1u;
}
