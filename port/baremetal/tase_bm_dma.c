/* Circular-DMA receive: spans of a DMA ring into a receiver (tase/bm_dma.h). */
#include "tase/bm_dma.h"

int tase_bm_dma_init(tase_bm_dma_t *d, const uint8_t *buf, uint32_t size)
{
    if (d == NULL || buf == NULL || size == 0u || size > 0x80000000u) {
        return TASE_EARG;
    }
    d->buf = buf;
    d->size = size;
    d->pos = 0;
    d->read = 0;
    d->stats.bytes_fed = 0;
    d->stats.overruns = 0;
    d->stats.lost_bytes = 0;
    return TASE_OK;
}

/* Feed buf[pos..pos+n) (n <= size - pos); returns frames or an error. */
static int feed_span(tase_bm_dma_t *d, uint32_t n, tase_rx_t *rx, tase_rx_handler_t on_frame,
                     void *user)
{
    int r = tase_rx_feed(rx, &d->buf[d->pos], (size_t)n, on_frame, user);
    if (r >= 0) {
        d->stats.bytes_fed += n;
        d->read += n;
        d->pos += n;
        if (d->pos == d->size) {
            d->pos = 0;
        }
    }
    return r;
}

int tase_bm_dma_poll(tase_bm_dma_t *d, uint32_t written, uint32_t now_ms, tase_rx_t *rx,
                     tase_rx_handler_t on_frame, void *user)
{
    uint32_t fresh;
    int frames = 0;
    int r;

    if (d == NULL || rx == NULL || d->buf == NULL || d->size == 0u || d->pos >= d->size) {
        return TASE_EARG;
    }
    /* A receiver that cannot take bytes now (its own callback is running)
     * is found before anything is read: nothing is lost to it. */
    r = tase_rx_feed(rx, NULL, 0u, on_frame, user);
    if (r < 0) {
        return r;
    }
    frames = r; /* the probe may finish a scan the last call left pending */
    fresh = written - d->read;
    if (fresh > 0x80000000u) {
        /* `written` 1..2^31-1 behind what was read: a stale sample (a lap
         * count one lap off), as the DMA cannot run backwards, however far
         * behind (also more than `size`). Nothing is read or counted and
         * the reader stays where it is: the next good sample catches up,
         * and if the DMA really lapped, that one is more than `size` ahead
         * (below). 2^31 or more behind reads as far ahead (the count wraps
         * at 2^32; size <= 2^31): an overrun if more than `size`. */
        fresh = 0;
    }
    if (fresh > d->size) {
        /* Lapped: the buffer mixes two laps. Lose it all, settle what the
         * receiver holds (the gap cuts any candidate), resume at the DMA:
         * `fresh` bytes on from where the reader is (written % size is the
         * DMA's index only while the count has not wrapped at 2^32, unless
         * the size divides 2^32: the reader landed elsewhere for good). */
        d->stats.overruns++;
        d->stats.lost_bytes += fresh;
        d->read = written;
        d->pos = (d->pos + fresh % d->size) % d->size;
        r = tase_rx_flush(rx, on_frame, user);
        frames += r > 0 ? r : 0;
        fresh = 0;
    }
    if (fresh > 0u) {
        uint32_t first = d->size - d->pos; /* up to the end of the buffer */
        if (first > fresh) {
            first = fresh;
        }
        r = feed_span(d, first, rx, on_frame, user);
        if (r < 0) {
            return r;
        }
        frames += r;
        if (fresh > first) { /* the rest from the start: the wrap */
            r = feed_span(d, fresh - first, rx, on_frame, user);
            if (r < 0) {
                return r;
            }
            frames += r;
        }
    }
    r = tase_rx_tick(rx, now_ms, on_frame, user);
    return r < 0 ? r : frames + r;
}
