/*
 * tase/port.h - the one boundary between the portable core and an
 * operating system or hardware.
 *
 * A port is a const table of three functions plus a context pointer. The
 * datalink is a byte stream whatever carries it: a UART port moves bytes;
 * the SocketCAN port cuts written bytes into CAN frames of its direction's
 * ID and returns the payload bytes of received frames whose ID its role
 * accepts. Everything above the port (host and gimbal roles, tools) sees
 * only this interface, so it runs unchanged over a UART, a pty, CAN, or a
 * test double.
 *
 * Implementations live under port/<name>/ (posix_uart, socketcan,
 * baremetal). Nothing in src/ calls an OS directly.
 */
#ifndef TASE_PORT_H
#define TASE_PORT_H

#include "tase/common.h"

typedef struct {
    /* Queue n bytes for transmission. Returns n when all were accepted,
     * TASE_EAGAIN / TASE_ENOBUFS when none could be accepted now (nothing
     * was sent; retry later), or another negative TASE_E* code. A port
     * never accepts part of a write silently: it either takes all n bytes
     * or reports how many it took (0 < return < n) so the caller can send
     * the rest. */
    int (*write)(void *ctx, const uint8_t *data, size_t n);
    /* Read up to cap bytes, waiting at most timeout_ms (0 = do not wait).
     * Returns the number of bytes read (0: none within the timeout) or a
     * negative TASE_E* code. */
    int (*read)(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms);
    /* Monotonic milliseconds (wraps modulo 2^32; compare with
     * subtraction). */
    uint32_t (*now_ms)(void *ctx);
} tase_port_ops_t;

typedef struct {
    const tase_port_ops_t *ops;
    void *ctx;
} tase_port_t;

#endif /* TASE_PORT_H */
