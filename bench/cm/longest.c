/* The longest single receiver call over a stream: see longest.h. */
#include "longest.h"

#include "measure.h"

/* One call of the stream, from the receiver state before it. */
typedef struct {
    tase_rx_t *rx;
    longest_call_fn f;
    const tase_rx_t *before;
    const uint8_t *p;
    size_t n;
} one_call_t;

static void put_back(void *ctx)
{
    const one_call_t *o = ctx;
    *o->rx = *o->before;
}

static void call_once(void *ctx)
{
    const one_call_t *o = ctx;
    (void)o->f(o->p, o->n);
}

longest_t longest_call(tase_rx_t *rx, longest_call_fn f, const uint8_t *stream, size_t n,
                       size_t chunk, uint16_t *coarse, size_t max_exact)
{
    static tase_rx_t before;
    longest_t r = {0u, 0u, 0u, 0u};
    size_t i;
    size_t c;
    uint16_t top = 0;
    (void)tase_rx_init(rx);
    for (i = 0, c = 0; i < n; i += chunk, c++) {
        size_t k = (n - i < chunk) ? n - i : chunk;
        uint32_t t0 = measure_ticks();
        (void)f(&stream[i], k);
        coarse[c] = (uint16_t)(t0 - measure_ticks());
        if (coarse[c] > top) {
            top = coarse[c];
        }
    }
    (void)tase_rx_init(rx);
    for (i = 0, c = 0; i < n; i += chunk, c++) {
        size_t k = (n - i < chunk) ? n - i : chunk;
        if ((unsigned)coarse[c] + 1u >= top) {
            r.candidates++;
            if (r.exact < max_exact) {
                one_call_t o;
                unsigned long e;
                before = *rx;
                o.rx = rx;
                o.f = f;
                o.before = &before;
                o.p = &stream[i];
                o.n = k;
                e = measure_exact(put_back, call_once, &o);
                *rx = before;
                r.exact++;
                if (e > r.insns) {
                    r.insns = e;
                    r.call = c;
                }
            }
        }
        (void)f(&stream[i], k);
    }
    return r;
}
