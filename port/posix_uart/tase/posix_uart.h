/*
 * tase/posix_uart.h - the POSIX serial port: a termios device (RS-232
 * adapter, USB serial, pseudo-terminal) as a tase_port_t (tase/port.h).
 *
 * EXCLUSIVE ACCESS. tase_posix_uart_open() takes the device for itself:
 * an flock(LOCK_EX | LOCK_NB) lock, which every program that locks serial
 * devices the same way respects (a second tase_posix_uart_open() of the
 * device, in this or another process, fails with TASE_EBUSY, "device
 * busy: in use by another program"), plus the kernel's TIOCEXCL, which
 * makes any further open() of the device fail with EBUSY for everybody
 * but root. A device whose TIOCEXCL another program set without the lock
 * is busy as well, for root too (read with TIOCGEXCL, Linux 3.8 and
 * later), and its flag is left alone: root's open used to succeed and its
 * close cleared the other program's flag. Two readers of one serial line
 * would each get a random half of the byte stream; this makes that
 * impossible by accident.
 * TASE_POSIX_UART_SHARED (tase_posix_uart_open_flags()) opens without
 * either. Both end when the device is closed. When the process exits
 * without closing it, the lock ends with it, but the kernel keeps the
 * flag while another process still has the device open (a pty that
 * tase-sim holds): the tools clear it on the signals they can catch, and
 * tase-sim clears a flag whose owner's lock is gone (SIGKILL); elsewhere
 * root, or closing every other open of the device, clears it.
 *
 * SETTINGS GIVEN BACK. The device's termios settings as found at open are
 * saved and restored by tase_posix_uart_close(), so a shell, `cat` or
 * another program sees the device as it was (otherwise VMIN = 0 would
 * stay behind and make a blocking read return at once). A program that
 * may be killed by a signal should close the port from its handler, or
 * restore the saved settings itself: `saved` holds them while open.
 *
 * The device is opened in raw 8N1 mode at one of the standard rates
 * (the TASE links are 9600 baud on Com2 and 57600 on Com3): no echo, no
 * canonical line editing, no signal characters, no CR/LF translation in
 * either direction, no software (XON/XOFF) or hardware (RTS/CTS) flow
 * control, modem lines ignored (CLOCAL), receiver on (CREAD). The file
 * descriptor is non-blocking; reads wait with poll() for at most the
 * timeout given.
 *
 * CONTRACT OF THE PORT FUNCTIONS (tase_posix_uart_ops; tase/port.h)
 *  write   writes all n bytes, waiting with poll() up to write_timeout_ms
 *          (default 1000 ms; the port's write bound W, for the whole call)
 *          while the kernel's output queue is full. A signal (EINTR)
 *          resumes the wait with the time left. A hung-up line fails with
 *          TASE_EIO.
 *          Returns n, the count written when the timeout expired part-way,
 *          TASE_EAGAIN when nothing could be written in time, TASE_EIO on
 *          an OS error, TASE_EARG (ctx NULL or closed, data NULL with
 *          n > 0, n > INT32_MAX; nothing written).
 *  read    returns what is available now, or waits up to timeout_ms in
 *          total for the first bytes (EINTR resumes the wait with the time
 *          left). Returns the count (0 = nothing within the timeout),
 *          TASE_EIO (OS error, or the other end hung up: after the bytes
 *          still queued, and also with timeout_ms 0) or TASE_EARG (ctx
 *          NULL or closed, buf NULL, cap 0). A cap above INT32_MAX reads at most
 *          INT32_MAX bytes.
 *  now_ms  CLOCK_MONOTONIC in milliseconds, modulo 2^32; 0 when the clock
 *          cannot be read (clock_gettime() fails: time stands still, and
 *          every wait above still ends, bounded by poll() and a count of
 *          looks; only signals that never let a poll() run its time can
 *          then hold a call).
 * A read on a line where poll() says readable but read() brings nothing
 * (another reader of a shared line takes the bytes) returns 0 after 1024
 * such looks, possibly before its timeout.
 * One instance is used from one thread at a time; separate instances are
 * independent.
 */
#ifndef TASE_POSIX_UART_H
#define TASE_POSIX_UART_H

#include <termios.h>

#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_POSIX_UART_WRITE_TIMEOUT_MS 1000u

/* tase_posix_uart_open_flags() flags */
#define TASE_POSIX_UART_SHARED 0x1u /* no flock(), no TIOCEXCL */

typedef struct {
    int fd; /* -1 when closed */
    uint32_t baud;
    uint32_t write_timeout_ms; /* may be changed after open */
    struct termios saved;      /* the device's settings found at open */
    bool restore;              /* saved is valid: close() restores it */
    bool excl;                 /* TIOCEXCL set by us: close() clears it */
} tase_posix_uart_t;

extern const tase_port_ops_t tase_posix_uart_ops;

/* Open `path` (e.g. "/dev/ttyUSB0") at `baud` bits per second, raw 8N1,
 * for exclusive use (see EXCLUSIVE ACCESS), saving the device's settings
 * for close(). Pending input (received before the open) is discarded;
 * output a previous owner left queued is not (it is still sent). Returns TASE_OK
 * or
 *   TASE_EARG         u or path NULL;
 *   TASE_EUNSUPPORTED baud is not a standard termios rate (checked before
 *                     the device is touched) or the device refused it;
 *   TASE_ENODEV       no such device, or it is not a terminal;
 *   TASE_EACCES       permission denied;
 *   TASE_EBUSY        the device is in use by another program (its lock,
 *                     or its TIOCEXCL); nothing was changed;
 *   TASE_EIO          any other OS error.
 * On error u is left closed (fd -1) and the device as it was. Blocks only
 * as long as open() of the device does (O_NONBLOCK: no carrier wait).
 * A SIMULATOR'S LINK (tase-sim --link PATH) is a symlink to a pty; a
 * simulator killed with SIGKILL leaves it behind, and its /dev/pts/N then
 * goes to the next program that asks for a pty (a terminal). This port
 * does not know the simulator and opens whatever PATH leads to: `tase`
 * and the Python package refuse such a stale link by the lock file the
 * simulator keeps beside it (PATH.lock, locked with fcntl while it runs:
 * docs/TOOLS.md). A program of your own on a simulator's link should
 * start the simulator itself, or check that lock (F_GETLK) first. */
int tase_posix_uart_open(tase_posix_uart_t *u, const char *path, uint32_t baud);

/* tase_posix_uart_open() with flags: 0 or TASE_POSIX_UART_SHARED (no
 * exclusive access; the settings are still saved and restored). Other
 * flag bits: TASE_EARG. */
int tase_posix_uart_open_flags(tase_posix_uart_t *u, const char *path, uint32_t baud,
                               unsigned flags);

/* Take over an already open terminal descriptor (e.g. an openpty()
 * master) and configure it exactly like tase_posix_uart_open(), saving its
 * settings for close(); no lock is taken (the caller opened it and
 * decides who else may). The descriptor is made non-blocking and is
 * closed by tase_posix_uart_close(). Returns as tase_posix_uart_open()
 * (TASE_ENODEV when fd is not a tty; the fd is then left open and
 * untouched). A fixed number of system calls; never waits. */
int tase_posix_uart_attach(tase_posix_uart_t *u, int fd, uint32_t baud);

/* Close the device: wait up to write_timeout_ms for the bytes written to
 * leave the kernel's queue (what is still queued then is discarded, so a
 * stuck line cannot hold the close), restore the settings saved at open
 * (after the last bytes went out at our rate), give up the exclusive
 * access, close the descriptor. Longest block: write_timeout_ms plus the
 * time the UART needs for its hardware FIFO. Returns TASE_OK (also when
 * already closed), TASE_EARG if u is NULL, TASE_EIO if close() failed
 * (the fd is gone anyway). */
int tase_posix_uart_close(tase_posix_uart_t *u);

/* The tase_port_t of an open instance: {&tase_posix_uart_ops, u, the
 * byte rate of its baud (TASE_UART_BYTES_PER_S(u->baud))}. With u NULL or
 * closed its write/read return TASE_EARG. O(1). */
tase_port_t tase_posix_uart_port(tase_posix_uart_t *u);

/* True if `baud` is a rate tase_posix_uart_open() accepts (any value may
 * be asked). O(1). */
bool tase_posix_uart_baud_supported(uint32_t baud);

/* CLOCK_MONOTONIC milliseconds modulo 2^32 (the ops' now_ms); 0 when the
 * clock cannot be read (see now_ms above). One system call. */
uint32_t tase_posix_now_ms(void);

#ifdef __cplusplus
}
#endif

#endif /* TASE_POSIX_UART_H */
