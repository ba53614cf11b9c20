/*
 * tase/port_io.h - small helpers on top of the port boundary (port.h):
 * write a whole buffer, and encode + write one frame.
 *
 * A port's write() may accept only part of a buffer (it reports how much).
 * The roles (host.h, gimbal.h) must never leave half a frame on the wire
 * when it can be avoided, so they send through tase_port_write_all(),
 * which keeps writing until everything is taken, the port fails, or its
 * one deadline per frame has passed.
 *
 * LONGEST BLOCK of tase_port_write_all(), tase_port_send_frame() and
 * tase_port_send_msg(), per call (one frame), in total:
 *     TASE_PORT_WRITE_TIMEOUT_MS + W
 * where W is the port's own write bound (tase/port.h: the POSIX UART
 * port's write_timeout_ms, the SocketCAN port's tx_timeout_ms, the
 * bare-metal template's tx hook). write() is called again only while less
 * than TASE_PORT_WRITE_TIMEOUT_MS have passed since the helper started,
 * on the port's clock, so only a call started before that deadline can
 * still be running after it. A port that waits by itself (both POSIX
 * ports) returns short only once its own W has passed, so with W at
 * least the deadline (the defaults: 1000 and 100 ms) it is never called
 * twice for a frame and the bound is W alone; a port that does not wait
 * (a full TX ring) is retried until the deadline, however fast it
 * refuses. A clock sample older than the start counts as no time (see
 * tase_port_elapsed_ms()). A port without now_ms is bounded by calls
 * instead: at most TASE_PORT_WRITE_TRIES calls that take nothing; and a
 * port whose clock stands still (or only goes back) by
 * TASE_PORT_WRITE_SPINS such calls in a row.
 * tase_port_send_frame() and tase_port_send_msg() write a frame in pieces
 * of 16 bytes (at most 17), keeping the one deadline and the TRIES count
 * across them. The deadline is checked while a piece is refused or only
 * partly taken, so a port that takes every piece whole but blocks W in
 * each call is called once per piece: up to 17 W for the longest frame
 * (a POSIX port blocks only while its kernel queue is full; a TX ring
 * never). A port that refuses every other call uses up the
 * TASE_PORT_WRITE_TRIES count of a port without a clock about one call
 * per piece sooner than tase_port_write_all() of the same frame.
 */
#ifndef TASE_PORT_IO_H
#define TASE_PORT_IO_H

#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

/* TASE_PORT_WRITE_TIMEOUT_MS (tase/config.h, default 100): the deadline
 * of one frame write (see LONGEST BLOCK).
 * TASE_PORT_WRITE_TRIES (tase/config.h, default 64): the bound of a port
 * without a clock: calls to write() that took nothing (TASE_EAGAIN,
 * TASE_ENOBUFS or 0) after which tase_port_write_all() gives up.
 * TASE_PORT_WRITE_SPINS (tase/config.h, default 2^20): the backstop for a
 * port whose clock stands still: such calls in a row while the clock
 * shows no time passing (a working clock resets the count as it moves
 * on, so a TX ring is retried until the deadline). */

/* Milliseconds from since_ms to now_ms on a clock that wraps modulo 2^32
 * (unsigned difference). A now_ms sampled before since_ms (a stale sample
 * or a clock that stepped back: the difference is 2^31 or more) is 0, no
 * time at all, never 49 days. Times compared must be less than 2^31 ms
 * apart. O(1), reentrant, ISR-safe. */
uint32_t tase_port_elapsed_ms(uint32_t now_ms, uint32_t since_ms);

/* Write all n bytes of data to the port within the frame deadline (see
 * LONGEST BLOCK). Returns n, or
 *   TASE_EARG    port/ops/write NULL, data NULL with n > 0, or
 *                n > INT_MAX (the count must fit the int result;
 *                32767 where int is 16 bits);
 *   TASE_EAGAIN / TASE_ENOBUFS  the port took nothing before the deadline
 *                (its own refusal code; nothing was sent: retry later);
 *   TASE_ENOBUFS the deadline passed part-way: the port's queue stayed
 *                full, or it drains slower than the frame needs (some
 *                bytes were sent; a receiver discards the cut frame by
 *                its checksum and finds the next one);
 *   TASE_EIO     write() claimed more than it was given (a broken port);
 *   any other negative code the port's write() returned (at once).
 * O(n) plus the port's cost. Reentrant if the port's write is; not
 * ISR-safe unless the port's write is. */
int tase_port_write_all(const tase_port_t *port, const uint8_t *data, size_t n);

/* Write one frame of (group, type) around data[0..len), exactly the bytes
 * tase_frame_build() gives, with the retries and the one deadline of
 * tase_port_write_all(). No frame buffer: the frame goes out in pieces of
 * at most 16 bytes staged on the stack and summed on the way (a multiple
 * of 8, so a CAN port packs them into the same whole CAN frames as one
 * write; a frame of up to 8 data bytes is one write).
 * Returns the frame length, an encoder error (TASE_EARG: data NULL with
 * len > 0; TASE_ETOOLONG: len > 253; checked first, nothing sent),
 * TASE_EARG for port NULL (or without write), or a tase_port_write_all()
 * error. Stack: docs/FOOTPRINT.md (104 bytes on Cortex-M4 -Os, the port's
 * write() and now_ms() not included). */
int tase_port_send_frame(const tase_port_t *port, uint8_t group, uint8_t type, const uint8_t *data,
                         size_t len);

/* Write the frame of packet `id` from its typed struct (tase/codec.h):
 * the bytes tase_packet_encode() gives, produced field by field into the
 * pieces tase_port_send_frame() writes, so no packet or frame buffer is
 * on the stack (CAMERA_PASS's camera bytes are sent from the caller's
 * buffer). msg (and CAMERA_PASS's camera bytes) are read while the frame
 * is being written, piece by piece: they must not change until the call
 * returns (a sample an interrupt updates goes in a copy first, or the
 * frame may mix two samples under a valid checksum). msg NULL sends the
 * zero-length form (a query, or GYRO_ZERO_CMD). Returns the frame length, a codec error (checked first,
 * nothing sent: TASE_EUNKNOWN id not in the schema; TASE_ELENGTH msg NULL
 * for a packet without a zero-length form; TASE_EARG / TASE_ETOOLONG for
 * a bad CAMERA_PASS tail), TASE_EARG for port NULL, or a
 * tase_port_write_all() error. Stack: docs/FOOTPRINT.md (120 bytes on
 * Cortex-M4 -Os, the codec's checks included, the port's write() and
 * now_ms() not). */
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
