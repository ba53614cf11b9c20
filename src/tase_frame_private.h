/*
 * Private to src/: what the receiver (tase_frame.c) shares with its set-up
 * and time bound (tase_frame_time.c). Not part of the API: no header in
 * include/ declares these.
 */
#ifndef TASE_FRAME_PRIVATE_H
#define TASE_FRAME_PRIVATE_H

#include "tase/frame.h"

/* `end` while a call runs or the scan lags: every fast path of
 * tase_rx_push() fails on it (see the comment at the top of tase_frame.c). */
#define RX_BLOCKED 0xFFFFu

/* TASE_OK, or what every entry point returns for rx: TASE_EARG (NULL or
 * visibly corrupted), TASE_EBUSY (a call in progress). */
int tase_rx_state_check(const tase_rx_t *rx);

/* Continue a lagging scan with one byte's credit, or with `settle` run it
 * to the end of input as tase_rx_flush() does. rx has passed
 * tase_rx_state_check(). Returns the frames delivered. */
int tase_rx_continue(tase_rx_t *rx, bool settle, tase_rx_handler_t on_frame, void *user);

#endif /* TASE_FRAME_PRIVATE_H */
