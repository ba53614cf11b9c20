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
 *
 * THE CONTRACT every port keeps, and every caller may rely on:
 *
 *  LONGEST BLOCK. Each call has ONE documented bound, for the call as a
 *  whole, not per retry or per system call inside it:
 *    read    at most timeout_ms (0: does not wait at all), plus the
 *            scheduling delay of the OS;
 *    write   at most the port's write bound W, stated by each port (the
 *            POSIX UART port's write_timeout_ms, the SocketCAN port's
 *            tx_timeout_ms, the bare-metal template's tx hook);
 *    now_ms  never blocks.
 *  A port never retries beyond its bound on its own: once the time is
 *  spent it returns what it has.
 *
 *  SIGNALS. A wait interrupted by a signal (EINTR) is resumed with the time
 *  left, never reported: a program with timers or child processes gets
 *  neither spurious errors nor longer waits. (A caller must still accept a
 *  read() that returns 0 early: a port may give up its wait at any time
 *  before timeout_ms with nothing read, never after it.)
 *
 *  PARTIAL WRITES. write() returns n when all n bytes were taken, the count
 *  taken (0 < r < n) when its bound expired part-way, or TASE_EAGAIN /
 *  TASE_ENOBUFS (or 0) when it took none: nothing was sent. It never drops
 *  bytes silently. tase_port_write_all() (port_io.h) sends the rest
 *  within one deadline per frame.
 *
 *  HANG-UP. When the other end goes away (USB adapter unplugged, pty
 *  closed, CAN socket closed) read() first returns the bytes the system
 *  still holds, then TASE_EIO; write() returns TASE_EIO. (A Linux tty's
 *  hang-up discards its input queue, so bytes that came just before it
 *  can be gone; a pty master keeps them. A write to a pty master whose
 *  peer closed is taken until the kernel's queue is full (12 to 20 KB
 *  measured, by kernel), then fails.) The port does not reopen anything:
 *  close it, and open it again when the device is back.
 *
 *  CLOCK. now_ms is monotonic milliseconds that wrap modulo 2^32. Compare
 *  times with unsigned subtraction, and treat a difference of 2^31 or more
 *  as "not yet" (a sample taken before the time it is compared with, e.g.
 *  read before a request was sent and used after): see
 *  tase_port_elapsed_ms() in port_io.h.
 *
 *  ERRORS are negative TASE_E* codes (tase/common.h); TASE_EARG for a NULL
 *  or closed context, a NULL buffer, or a write count the int result
 *  cannot hold. A read's cap above that is refused (SocketCAN) or read as
 *  that many (POSIX UART, bare metal): each port's header says which.
 *
 * tests/fault_port.h wraps any port and injects short writes, interrupted
 * and refused calls, stalls, hang-ups, clock jumps and stale clock samples;
 * the roles and tase_port_write_all() are tested through it.
 */
#ifndef TASE_PORT_H
#define TASE_PORT_H

#include "tase/common.h"

typedef struct {
    /* Queue n bytes for transmission, blocking at most the port's write
     * bound W (see THE CONTRACT). Returns n when all were accepted,
     * 0 < r < n when W ran out part-way, TASE_EAGAIN / TASE_ENOBUFS (or
     * 0) when none could be accepted (nothing was sent; retry later),
     * TASE_EIO on hang-up or failure, or another negative TASE_E* code. */
    int (*write)(void *ctx, const uint8_t *data, size_t n);
    /* Read up to cap bytes, waiting at most timeout_ms in total for the
     * first ones (0 = do not wait). Returns the number of bytes read
     * (0: none within the timeout), TASE_EIO on hang-up (after the bytes
     * already received) or failure, or another negative TASE_E* code. */
    int (*read)(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms);
    /* Monotonic milliseconds (wraps modulo 2^32; compare with
     * subtraction). Never blocks. */
    uint32_t (*now_ms)(void *ctx);
} tase_port_ops_t;

typedef struct {
    const tase_port_ops_t *ops;
    void *ctx;
    /* The link's byte rate in bytes per second (TASE_UART_BYTES_PER_S(baud)
     * for an 8N1 UART), or 0 when the port does not know it. The roles use
     * it for the receiver's time bound (tase/frame.h, TIME BOUND) and the
     * gimbal's telemetry capacity (tase/gimbal.h); 0 makes both assume the
     * slowest line of the spec, 9600 baud, which is safe but slow. The
     * ports' *_port() functions fill it; set it yourself for a port of
     * your own. */
    uint32_t bytes_per_s;
} tase_port_t;

#endif /* TASE_PORT_H */
