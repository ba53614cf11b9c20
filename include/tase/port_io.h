/*
 * tase/port_io.h - small helpers on top of the port boundary (port.h):
 * write a whole buffer, and encode + write one frame.
 *
 * A port's write() may accept only part of a buffer (it reports how much).
 * The roles (host.h, gimbal.h) must never leave half a frame on the wire
 * when it can be avoided, so they send through tase_port_write_all(),
 * which keeps writing until everything is taken, the port fails, or the
 * port makes no progress TASE_PORT_WRITE_TRIES times in a row.
 *
 * Neither helper blocks by itself: how long a write may wait is the port's
 * business (the POSIX UART port waits up to its write timeout, the
 * bare-metal template's TX hook is blocking).
 */
#ifndef TASE_PORT_IO_H
#define TASE_PORT_IO_H

#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

/* TASE_PORT_WRITE_TRIES (tase/config.h, default 64): consecutive calls
 * to write() that took nothing (TASE_EAGAIN, TASE_ENOBUFS or 0) after
 * which tase_port_write_all() gives up. */

/* Write all n bytes of data to the port.
 * Returns n, or
 *   TASE_EARG    port/ops/write NULL, data NULL with n > 0, or
 *                n > INT32_MAX (the count must fit the int result);
 *   TASE_EAGAIN / TASE_ENOBUFS  the port took nothing at all (retry later;
 *                nothing was sent);
 *   TASE_EIO     the port stopped taking bytes part-way (some bytes were
 *                sent; a receiver will discard the cut frame by its
 *                checksum), also when write() claims more than it was
 *                given (a broken port);
 *   any other negative code the port's write() returned.
 * O(n) plus the port's cost. Reentrant if the port's write is; not
 * ISR-safe unless the port's write is. */
int tase_port_write_all(const tase_port_t *port, const uint8_t *data, size_t n);

/* Encode one frame (tase_frame_encode) into a stack buffer of
 * TASE_FRAME_MAX bytes and write it with tase_port_write_all().
 * Returns the frame length, an encoder error (TASE_EARG: data NULL with
 * len > 0; TASE_ETOOLONG: len > 253; checked first, nothing sent),
 * TASE_EARG for port NULL, or a tase_port_write_all() error. Uses 261 bytes of stack. */
int tase_port_send_frame(const tase_port_t *port, uint8_t group, uint8_t type, const uint8_t *data,
                         size_t len);

/* Encode packet `id` from its typed struct (tase/codec.h) into a stack
 * buffer of TASE_FRAME_MAX bytes and write it with tase_port_write_all().
 * msg NULL sends the zero-length form (a query, or GYRO_ZERO_CMD).
 * Returns the frame length, a codec error (checked first, nothing sent:
 * TASE_EUNKNOWN id not in the schema; TASE_ELENGTH msg NULL for a packet
 * without a zero-length form; TASE_EARG / TASE_ETOOLONG for a bad
 * CAMERA_PASS tail), TASE_EARG for port NULL, or a tase_port_write_all()
 * error. Uses 261 bytes of stack. */
int tase_port_send_msg(const tase_port_t *port, uint16_t id, const void *msg);

/* Count the result r of a frame write (tase_port_send_frame(),
 * tase_port_send_msg() or tase_port_write_all()): a success in *sent, a
 * failure of the link in *errors. Failures caused by the caller's
 * arguments (TASE_EARG, TASE_ETOOLONG, TASE_ELENGTH, TASE_EUNKNOWN) are
 * not the link's and count in neither. Either pointer may be NULL.
 * Returns r unchanged. O(1), reentrant. */
int tase_port_count_tx(int r, uint32_t *sent, uint32_t *errors);

#ifdef __cplusplus
}
#endif

#endif /* TASE_PORT_IO_H */
