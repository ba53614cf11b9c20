/*
 * tase/bm_dma.h - circular-DMA receive for microcontrollers: the pattern
 * most STM32-class firmware uses for a UART (a DMA channel writes the
 * received bytes round a buffer for ever; an IDLE-line, half-transfer or
 * transfer-complete interrupt, or the main loop, looks how far it got).
 * This helper keeps the reader's position, feeds the bytes written since
 * the last call to a receiver as one span, or two where they wrap round
 * the end of the buffer, and reports when the DMA lapped the reader.
 *
 * WIRING IT UP (STM32 HAL names; any DMA that counts works the same;
 * scripts/checks/readme-example.sh compiles this example with stand-ins
 * for the HAL's names, a receiver `rx` and its `on_frame`):
 *
 *     static uint8_t dma_buf[256];          // any size >= 1
 *     static volatile uint32_t dma_laps;    // full buffers written so far
 *     static tase_bm_dma_t rxd;
 *     void HAL_UART_RxCpltCallback(UART_HandleTypeDef *h)
 *     {
 *         if (h == &huart3) {
 *             dma_laps++;
 *         }
 *     }
 *     void uart_rx_start(void)
 *     {
 *         tase_bm_dma_init(&rxd, dma_buf, sizeof dma_buf);
 *         HAL_UART_Receive_DMA(&huart3, dma_buf, sizeof dma_buf);  // circular
 *     }
 *     // from the main loop, or an interrupt (IDLE line) below the TC
 *     // interrupt's priority with on_frame safe there (see below):
 *     void uart_rx_poll(uint32_t now_ms)
 *     {
 *         uint32_t laps;
 *         uint32_t n;
 *         do { // the laps and the counter of one moment (below)
 *             laps = dma_laps;
 *             n = (uint32_t)sizeof dma_buf - __HAL_DMA_GET_COUNTER(huart3.hdmarx);
 *         } while (laps != dma_laps);
 *         tase_bm_dma_poll(&rxd, laps * (uint32_t)sizeof dma_buf + n, now_ms, &rx, on_frame,
 *                          NULL);
 *     }
 *
 * `written` is the number of bytes the DMA has written since it started,
 * modulo 2^32: laps * size + its position. Read the two consistently (a
 * transfer-complete interrupt between reading the counter and the laps
 * gives a position one lap off: read laps, the counter, laps again, and
 * retry if the laps changed). The laps must also be current: a poll that
 * the transfer-complete (TC) interrupt cannot preempt (an interrupt at
 * its priority or above) can run while a TC is pending, the counter
 * wrapped and dma_laps not yet counted: its samples are a lap behind,
 * stale (nothing read; the bytes come with the first poll after the TC
 * ran), and what overfills the buffer meanwhile is lost. Poll from the
 * main loop or a context below the TC interrupt's priority, or read the
 * TC pending flag with the counter (STM32: the channel's TCIF; read it,
 * the counter, it again, retry if it changed; if set, the counter has
 * wrapped and laps + 1 is the count). A DMA without a lap count can keep
 * `written` itself, adding the position's advance modulo `size` at each
 * poll, as long as it polls at least once per `size` bytes (then a lap
 * cannot be detected, only avoided).
 *
 * SPLITS ARE INVISIBLE. Feeding a stream in any split (one span, two at
 * the wrap, a byte at a time) gives the receiver exactly the same frames,
 * in the same order, with the same offsets and counters (tase/frame.h:
 * "in any split"); tests/test_bm_dma.c checks it against one whole feed
 * with random spans and laps.
 *
 * OVERRUN. If more than `size` bytes were written since the last call,
 * the DMA overwrote bytes the reader had not read: they are lost. Nothing
 * of the buffer is fed then (its contents are a mix of two laps); the
 * lost bytes are counted (stats.lost_bytes, stats.overruns), the receiver
 * is flushed (tase_rx_flush(): a candidate cut by the gap is judged
 * false, the frames before it are delivered), and reading resumes at the
 * DMA's position. Exactly `size` new bytes is not an overrun (the reader
 * takes the whole buffer), but is the last safe moment: poll well within
 * a buffer's time (256 bytes at 115200 baud: 22 ms).
 * The count is of the bytes written when `written` was sampled: bytes the
 * DMA writes while the call runs (on_frame runs inside it: a gimbal
 * writing its echo at line rate) must not reach the part not yet fed, or
 * they are fed in place of the old ones (a frame lost, one given twice,
 * nothing counted). Keep fresh bytes + the bytes that arrive during the
 * call within `size`: poll when the buffer is at most half full, or make
 * the buffer twice what one poll takes plus what the callbacks' time
 * brings in.
 *
 * TIME BOUND. After feeding, tase_rx_tick(rx, now_ms, ...) runs (the
 * receiver's time bound, tase/frame.h TIME BOUND): call this on every
 * IDLE-line interrupt and at least every few milliseconds from the main
 * loop, also when nothing arrived, so that noise cannot hold a command.
 *
 * CONTEXT: one context per instance (the main loop, or the one interrupt
 * that polls, below the TC interrupt's priority: WIRING IT UP); on_frame
 * runs inside tase_bm_dma_poll(). No heap, no globals; two 32-bit
 * remainders on an overrun, no other division. O(bytes fed) per call
 * plus the receiver's costs.
 */
#ifndef TASE_BM_DMA_H
#define TASE_BM_DMA_H

#include <stddef.h>
#include <stdint.h>

#include "tase/frame.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Counters; only incremented, wrap modulo 2^32. */
typedef struct {
    uint32_t bytes_fed;  /* bytes handed to the receiver */
    uint32_t overruns;   /* polls that found the DMA had lapped the reader */
    uint32_t lost_bytes; /* bytes overwritten before they were read */
} tase_bm_dma_stats_t;

/* The reader of one circular DMA buffer. Treat every field except
 * `stats` as private. */
typedef struct {
    const uint8_t *buf;
    uint32_t size;
    uint32_t pos;  /* index of the next byte to read, 0..size-1 */
    uint32_t read; /* bytes read (or lost) since init, modulo 2^32 */
    tase_bm_dma_stats_t stats;
} tase_bm_dma_t;

/* Start reading buf[0..size) from index 0, with the DMA's count at 0.
 * Returns TASE_OK or TASE_EARG (d or buf NULL, size 0 or > 2^31). */
int tase_bm_dma_init(tase_bm_dma_t *d, const uint8_t *buf, uint32_t size);

/* Feed the bytes the DMA wrote since the last call (see the top of this
 * file for `written`) to rx, then tick rx at now_ms. Returns the number
 * of frames delivered (by the feed, an overrun's flush and the tick), or
 * TASE_EARG (d, rx NULL or d not initialised; nothing read), or the
 * receiver's error (TASE_EBUSY when called from rx's own callback:
 * nothing read, call again later). `written` behind what was read by
 * any amount under 2^31 (a stale sample: the DMA cannot run backwards)
 * reads nothing: nothing fed or counted, d unchanged, rx ticked as on an
 * empty poll; the next good sample catches up. More than `size` ahead
 * is an overrun (OVERRUN above), up to 2^31 ahead (the count wraps at
 * 2^32: 2^31 or more behind reads as ahead, more than 2^31 ahead as
 * behind: poll at least once per 2^31 bytes). */
int tase_bm_dma_poll(tase_bm_dma_t *d, uint32_t written, uint32_t now_ms, tase_rx_t *rx,
                     tase_rx_handler_t on_frame, void *user);

#ifdef __cplusplus
}
#endif

#endif /* TASE_BM_DMA_H */
