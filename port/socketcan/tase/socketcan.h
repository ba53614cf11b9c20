/*
 * tase/socketcan.h - the datalink over Linux SocketCAN (port, Linux only).
 *
 * A tase_socketcan_t is a raw CAN socket plus a role (tase/can.h). It is a
 * tase_port_t byte stream like a UART:
 *   - write() cuts the bytes into CAN frames of the role's transmit ID
 *     (host 0x11000000, gimbal 0x10000000), 8 bytes each, the rest last;
 *   - read() returns the payload bytes of received frames that the role
 *     accepts (tase_can_accept()), in bus order.
 * It also sends and receives single frames (the 3AX drive frames).
 *
 * RECEIVE FILTERS. tase_socketcan_open() installs CAN_RAW_FILTER entries
 * for exactly the IDs the role needs, as extended IDs (CAN_EFF_FLAG, mask
 * CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_EFF_MASK, so standard and remote frames
 * with the same number do not pass):
 *     host:   0x10000000
 *     gimbal: 0x11000000 and 0x12020000 (3AX status)
 * The port checks every frame again in software, so an adopted descriptor
 * without kernel filters behaves the same, only with more wake-ups.
 *
 * Frames outside the role's ID set (possible on an adopted socket) are
 * counted in stats.frames_ignored and dropped by both read paths.
 *
 * FRAMES THAT ARE NOT DATALINK BYTES. read() keeps the other frames of the
 * role's set it meets (the gimbal's 3AX status) in a small queue for
 * tase_socketcan_recv_frame(); when the queue is full the oldest is
 * dropped and counted in stats.side_dropped. recv_frame() hands out that
 * queue first, then every frame of the role's set from the socket,
 * datalink frames included: a program that uses both must feed the
 * datalink frames recv_frame() returns into its own receiver
 * (tase_can_rx_feed()).
 *
 * TRANSMIT QUEUE FULL. Linux reports a full interface queue as ENOBUFS
 * (not EAGAIN) and poll() may still say POLLOUT. write() and send_frame()
 * retry EAGAIN/ENOBUFS, waiting with poll(POLLOUT) and a short sleep, for
 * at most tx_timeout_ms in total (default TASE_SOCKETCAN_TX_TIMEOUT_MS).
 * If the time runs out, write() returns how many bytes went out in whole
 * frames (0 < n < len: the caller sends the rest later), or TASE_ENOBUFS
 * when none did; nothing is ever dropped silently. A queue stays full
 * when no node acknowledges the frames or the controller is bus-off:
 * tase_socketcan_bus() tells which.
 *
 * LONGEST BLOCK (the port contract of tase/port.h): write() and
 * send_frame() tx_timeout_ms in total; read() and recv_frame() timeout_ms
 * in total, and then at most 63 more frames handled that carry nothing for
 * the caller (a flood of other nodes' frames, error frames or 3AX status is
 * looked through 64 at a time, the clock read between: read() with timeout
 * 0 takes at most 64 such frames and returns 0). A signal (EINTR) never
 * ends a wait early or makes it fail: the wait resumes with the time left;
 * an interrupted read or write once the time is spent ends the call as its
 * timeout does (read() 0, write() TASE_ENOBUFS), so a storm of signals
 * cannot hold it. The waits end even with a clock that stands still (or
 * fails, tase_socketcan_now_ms()): a poll() that waited all the time left
 * ends the call, and the sleeps on a full interface queue (ENOBUFS) add up
 * to tx_timeout_ms at most. (With such a clock a call can still be held by
 * signals that never let a poll() run its time, or by frames arriving
 * without pause.)
 *
 * BUS HEALTH. open() (and adopt() with TASE_SOCKETCAN_SET_FILTER) asks the
 * kernel for error frames (CAN_RAW_ERR_FILTER: controller state, bus-off,
 * restarts, TX timeouts, missing ACKs, protocol and transceiver errors).
 * They arrive in the receive queue with the data, so they are taken into
 * account as the socket is read (read(), recv_frame()); none reaches the
 * caller as data. tase_socketcan_bus() returns the state they reported
 * and the counts, plus the ENOBUFS refusals of the transmit path. What a
 * given controller reports depends on its driver; vcan reports nothing
 * by itself (docs/CAN.md).
 *
 * CAN FD. The datalink is classic CAN. On an adopted socket with
 * CAN_RAW_FD_FRAMES, classic frames (CAN_MTU records) are read as usual and
 * FD frames (CANFD_MTU records) are dropped: counted in stats.fd_rejected
 * when they carry one of the role's IDs, else in stats.frames_ignored.
 *
 * RECEIVE TIMESTAMPS. The port asks for kernel receive timestamps
 * (SO_TIMESTAMPNS: CLOCK_REALTIME, taken when the frame entered the
 * kernel, so they are not delayed by a late read).
 * tase_socketcan_rx_time_ns() gives the one of the frame whose data was
 * last returned.
 *
 * ERRORS. open(): name empty or too long -> TASE_EARG; no interface of
 * that name -> TASE_ENODEV; an interface that is not CAN (lo, eth0: its
 * hardware type is not ARPHRD_CAN) -> TASE_EARG; interface not up ->
 * TASE_EDOWN; kernel without CAN (EAFNOSUPPORT/EPROTONOSUPPORT) ->
 * TASE_EUNSUPPORTED; EPERM/EACCES -> TASE_EACCES; anything else ->
 * TASE_EIO. Reading or writing: an interface that went down (ENETDOWN)
 * -> TASE_EDOWN; one that was removed (ENODEV, ENXIO; a raw socket stays
 * unbound when an interface of the same name comes back, so open a new
 * one) -> TASE_ENODEV; any other descriptor error -> TASE_EIO; errno kept
 * in stats.last_errno. The kernel reports a read error once: a read()
 * that meets it with bytes in hand returns the bytes, and the next read()
 * returns the error (also when it finds nothing else).
 *
 * Threads: one instance is used by one thread at a time. Not ISR code.
 */
#ifndef TASE_SOCKETCAN_H
#define TASE_SOCKETCAN_H

#include "tase/can.h"
#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_SOCKETCAN_TX_TIMEOUT_MS 100u
#define TASE_SOCKETCAN_SIDEQ 8u /* non-datalink frames kept by read() */

/* adopt() flags */
#define TASE_SOCKETCAN_OWN_FD 0x1u     /* close() closes the descriptor */
#define TASE_SOCKETCAN_SET_FILTER 0x2u /* install the role's CAN_RAW_FILTER */

typedef struct {
    uint32_t frames_rx;      /* data frames read from the socket */
    uint32_t frames_tx;      /* frames written */
    uint32_t bytes_rx;       /* datalink payload bytes returned by read() */
    uint32_t frames_ignored; /* outside the role's ID set (dropped) */
    uint32_t bad_frames;     /* wrong size, remote frames, bad dlc */
    uint32_t side_dropped;   /* side-queue overflow */
    uint32_t tx_retries;     /* EAGAIN/ENOBUFS retried */
    uint32_t tx_full;        /* writes that ran out of time (TASE_ENOBUFS or short) */
    int last_errno;          /* errno of the last TASE_EIO / TASE_EDOWN */
    uint32_t fd_rejected;    /* CAN FD frames with one of the role's IDs (dropped) */
} tase_socketcan_stats_t;

/* Controller state, as the last error frame reported it. */
#define TASE_SOCKETCAN_BUS_ACTIVE 0u  /* error-active: normal (and before any report) */
#define TASE_SOCKETCAN_BUS_WARNING 1u /* an error counter reached 96 */
#define TASE_SOCKETCAN_BUS_PASSIVE 2u /* error-passive: a counter reached 128 */
#define TASE_SOCKETCAN_BUS_OFF 3u     /* bus-off: the controller left the bus */

/* Bus health, from the kernel's error frames (counts wrap modulo 2^32). */
typedef struct {
    uint8_t state;          /* TASE_SOCKETCAN_BUS_* */
    uint8_t tx_error_count; /* the controller's TEC and REC, from the last */
    uint8_t rx_error_count; /*   error frame that carried them (else 0) */
    uint32_t error_frames;  /* error frames received */
    uint32_t warnings;      /* reports of the warning level */
    uint32_t passives;      /* reports of error-passive */
    uint32_t bus_offs;      /* reports of bus-off */
    uint32_t restarts;      /* controller restarts (back to error-active) */
    uint32_t tx_timeouts;   /* frames the driver gave up transmitting */
    uint32_t no_acks;       /* transmissions nobody acknowledged */
    uint32_t bus_errors;    /* protocol, transceiver and bus errors */
    uint32_t overflows;     /* controller RX/TX buffer overflows */
    uint32_t enobufs;       /* frames the interface queue refused (ENOBUFS), each
                             * counted once however often it was retried */
} tase_socketcan_bus_t;

/* Instance; every field but `stats` and `tx_timeout_ms` is private. */
typedef struct {
    int fd;
    unsigned flags;
    tase_can_role_t role;
    uint32_t tx_timeout_ms; /* retry budget of one write()/send_frame() */
    tase_socketcan_stats_t stats;
    tase_socketcan_bus_t bus; /* read with tase_socketcan_bus() */
    uint64_t rx_ns;           /* see tase_socketcan_rx_time_ns() */
    uint64_t pend_ns;         /* receive time of the frame in pend[] */
    uint8_t pend[8];          /* accepted payload not yet returned by read() */
    uint8_t pend_pos;
    uint8_t pend_len;
    uint8_t side_head;
    uint8_t side_count;
    tase_can_frame_t side[TASE_SOCKETCAN_SIDEQ];
    uint64_t side_ns[TASE_SOCKETCAN_SIDEQ];
    int rx_err; /* a read error met with bytes in hand: the next read()'s */
} tase_socketcan_t;

/* Open a raw CAN socket on interface `ifname` for `role`, non-blocking,
 * with the role's receive filters. Returns TASE_OK or a code listed under
 * ERRORS above (s untouched, nothing left open). A fixed number of
 * system calls; never waits. */
int tase_socketcan_open(tase_socketcan_t *s, const char *ifname, tase_can_role_t role);

/* Use an already-open descriptor that carries struct can_frame records
 * (a bound CAN_RAW socket, or in tests one end of
 * socketpair(AF_UNIX, SOCK_SEQPACKET)). Sets O_NONBLOCK. flags:
 * TASE_SOCKETCAN_OWN_FD, TASE_SOCKETCAN_SET_FILTER. Returns TASE_OK,
 * TASE_EARG (s NULL, fd < 0, bad role or flags) or TASE_EIO (fcntl or
 * setsockopt failed; s untouched, fd not closed). Never waits. */
int tase_socketcan_adopt(tase_socketcan_t *s, int fd, tase_can_role_t role, unsigned flags);

/* Close the descriptor if owned. Safe to call twice; s NULL is ignored.
 * Never waits (frames still queued in the kernel are its to send). */
void tase_socketcan_close(tase_socketcan_t *s);

/* The longest wait of any call: timeouts (read(), recv_frame()'s
 * timeout_ms, tx_timeout_ms) above it are clamped to it, so UINT32_MAX
 * serves as "wait as long as possible": 2^31 - 1 ms, about 24.8 days. */
#define TASE_SOCKETCAN_TIMEOUT_MAX 0x7FFFFFFFu

/* The byte rate the port states (tase_port_t.bytes_per_s): CAN at
 * 1 Mbit/s (spec 5) carries 8 datalink bytes per extended frame of at most
 * 160 bits with stuffing, about 50,000 bytes per second. */
#define TASE_SOCKETCAN_BYTES_PER_S 50000u

/* The port view: ops = &tase_socketcan_ops, ctx = s, bytes_per_s
 * TASE_SOCKETCAN_BYTES_PER_S. O(1). */
tase_port_t tase_socketcan_port(tase_socketcan_t *s);
extern const tase_port_ops_t tase_socketcan_ops;

/* Byte stream (the tase_port_ops_t contract, see tase/port.h; write() as
 * described under TRANSMIT QUEUE FULL, and TASE_EDOWN when the interface
 * went down before any byte went out). Both
 * return TASE_EARG, touching nothing, for s NULL, closed or corrupted
 * (role or private queue indices out of range), n or cap > INT32_MAX,
 * data NULL with n > 0, buf NULL. read() with cap 0 reads nothing: it
 * returns 0, or the error an earlier read met after the bytes it returned
 * (said once, whatever the cap). */
int tase_socketcan_write(tase_socketcan_t *s, const uint8_t *data, size_t n);
int tase_socketcan_read(tase_socketcan_t *s, uint8_t *buf, size_t cap, uint32_t timeout_ms);

/* Send one frame (validated with tase_can_frame_check()). Returns TASE_OK,
 * TASE_EARG (s as for write(), f NULL or failing the check; nothing
 * sent), TASE_ENOBUFS (queue still full after tx_timeout_ms),
 * TASE_EDOWN (the interface went down), TASE_ENODEV (it was removed) or
 * TASE_EIO. */
int tase_socketcan_send_frame(tase_socketcan_t *s, const tase_can_frame_t *f);

/* Receive one frame, waiting at most timeout_ms. Returns 1 (*f filled),
 * 0 (none in time), TASE_EARG (s as for read(), f NULL), TASE_EDOWN (the
 * interface went down), TASE_ENODEV (it was removed) or TASE_EIO.
 * Frames the filters let through but that are not classic data frames
 * are skipped: error frames update the bus health, remote frames and
 * wrong sizes count in stats.bad_frames, FD frames as described above. */
int tase_socketcan_recv_frame(tase_socketcan_t *s, tase_can_frame_t *f, uint32_t timeout_ms);

/* Copy the bus health (see BUS HEALTH) into *out. Returns TASE_OK, or
 * TASE_EARG (s or out NULL). O(1); never blocks. */
int tase_socketcan_bus(const tase_socketcan_t *s, tase_socketcan_bus_t *out);

/* Kernel receive time (CLOCK_REALTIME, ns since the epoch) of the frame
 * whose data read() or recv_frame() returned last: for read(), the frame
 * that carried its last byte. 0 before any, when the socket gives no
 * timestamps, or for s NULL. O(1). */
uint64_t tase_socketcan_rx_time_ns(const tase_socketcan_t *s);

/* Monotonic milliseconds (CLOCK_MONOTONIC), for the port table. A failed
 * clock_gettime() reads as 0 ms (time standing still: every wait of the
 * port still ends, LONGEST BLOCK). */
uint32_t tase_socketcan_now_ms(void *ctx);

#ifdef __cplusplus
}
#endif

#endif /* TASE_SOCKETCAN_H */
