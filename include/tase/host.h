/*
 * tase/host.h - the host role: the side that commands a gimbal and asks it
 * questions (spec 4.4: "Anytime the gimbal receives one of these packets it
 * replies by sending the packet back. Hence each of these packets can be
 * sent as zero length in order to query the current settings.").
 *
 * A tase_host_t owns one port (port.h) and one frame receiver. It can
 *  - send any packet at any time (commands, host data): from its typed
 *    struct with tase_host_send_msg(), or as data bytes with
 *    tase_host_send();
 *  - run ONE request at a time: send a frame (a zero-length query, or a
 *    setup packet / SPOI command whose echo confirms it; never a packet
 *    the gimbal does not answer, which a retry would repeat; a
 *    SYSTEM_VERSION with data is sent as given and answered with the
 *    version, as its query is: PROTOCOL-NOTES R1, where the Python
 *    package refuses it) and wait for the
 *    gimbal's frame of the same group and type, re-sending the request
 *    after `timeout_ms` up to `retries` times. A typed request
 *    (tase_host_request_msg_start(), tase_host_transact_msg()) decodes
 *    the reply into the caller's typed struct; a raw one copies the
 *    reply's data bytes into a caller buffer.
 *
 * TYPED USE (tase/codec.h structs; scripts/checks/readme-example.sh
 * compiles this example):
 *     #include "tase/codec.h"  // the structs, TASE_ID_* (tase/ids.h)
 *     #include "tase/flags.h"  // TASE_GIMBAL_FLAGS_*, TASE_SETUP_TEMPORARY
 *     tase_gimbal_cmd_t cmd = {1500, -2000, 0, TASE_GIMBAL_FLAGS_POSITION, 0};
 *     tase_packet_rate_t rates;
 *     tase_host_send_msg(&h, TASE_ID_GIMBAL_CMD, &cmd);
 *     r = tase_host_transact_msg(&h, TASE_ID_PACKET_RATE, NULL, &rates, 500, 2);
 *     // r = 16 (the reply's data length): rates holds the gimbal's settings
 *     if (r > 0) {                            // else rates holds nothing
 *         rates.angle_1 = 20;
 *         rates.temporary = TASE_SETUP_TEMPORARY; // the answer may say 0: stored
 *         r = tase_host_transact_msg(&h, TASE_ID_PACKET_RATE, &rates, &rates, 500, 2);
 *     }
 * PACKET_RATE and AXIS_SETTING sent with `temporary` 0 are written to the
 * gimbal's non-volatile memory; the other setup packets have no such byte
 * and are always stored (docs/PROTOCOL-NOTES.md S11). To change one
 * setting of a packet whose fields have "do not change" values
 * (AXIS_SETTING, CAMERA_TYPE, CAMERA_CMD), start from
 * tase_packet_init_keep() (codec.h), never from a zeroed struct.
 *
 * DISPATCH. The frames that are not the pending request's reply go to
 * on_frame, which is a tase_rx_handler_t like tase_dispatch_frame()
 * (tase/dispatch.h): pass a dispatcher to get telemetry decoded into
 * typed handlers:
 *     tase_dispatch_init(&d, handlers, NULL, NULL, app, &h.rx.stats);
 *     tase_host_init(&h, &port, tase_dispatch_frame, &d);
 *
 * MATCHING. The pending request completes on the first received frame
 * with the request's group and type and at least one data byte (a
 * zero-length frame is a query, never an answer: this keeps a loop-back or
 * our own query echoed by a half-duplex line from completing it). A frame
 * WITH data echoed by such a line cannot be told from the gimbal's answer:
 * a setup packet, SPOI_CMD and RETRACT_DEPLOY_CMD come back byte for byte
 * as the gimbal's echo would, and complete the request (a retract then
 * "completes" at once). Use a line that does not echo what it sends; a
 * host that receives packets only a host sends (GIMBAL_CMD, HOST_SENSOR,
 * ...) or its own zero-length queries is on one that does. Any
 * such frame counts, including a late echo of an earlier attempt that
 * arrives after a retry was sent: the gimbal's answer always carries its
 * current settings, so any of them is a valid answer. A frame of another
 * type never completes it. Frames that do not complete the request
 * (telemetry, other answers, unsolicited frames) go to the on_frame
 * callback given at init; the completing reply does not.
 * A frame that began before the request's first attempt was sent (its
 * first byte among those fed before; also a frame finished inside the
 * feed call from whose on_frame the request was started) never completes
 * it: it goes to on_frame and counts in stats.stale (the host keeps its
 * own count of the bytes fed; a reset of rx.stats, also from on_frame,
 * does not move it). tase_host_transact() and tase_host_transact_msg()
 * first read what the port has ready (tase_host_drain(): reads that do
 * not wait until two in a row bring nothing, at most 256 of 64 bytes), so
 * an answer to an earlier request that waited unread is not taken either (a gimbal that
 * answered twice, a second gimbal on the line, or answers it sent after a
 * stall). An answer that begins after the send can still be such a one
 * (a duplicate that comes just after the next request went out): a
 * setting's echo that differs from what was sent may be stale (`tase
 * send` then asks once more before it reports a mismatch; an application
 * can do the same).
 * Zero-length frames received are counted in stats.queries_rx: a gimbal
 * sends none, so a line where they appear echoes what the host sends.
 * A request that ended after n attempts (completed by one answer: n - 1;
 * failed or cancelled: n) may still be answered for the others: that many
 * answers of its group and type are then OWED, and an owed answer never
 * completes a later request (a slow gimbal answering an earlier query
 * must not pass for the echo of the setting sent after it); it goes to
 * on_frame and counts in stats.late. Answers are owed for a while: after
 * a completed request, the time it took plus one attempt timeout after
 * its last attempt; after a failed or cancelled one, one attempt timeout.
 * Only the last request's group and type is tracked (a request of another
 * type forgets what an earlier one was owed once it owes answers itself).
 * When an owed answer was lost, the next request of that type takes the
 * timeout and a retry to complete: slower, never wrong. With retries 0 it
 * fails (TASE_ETIMEOUT, its echo counted in stats.late) although the
 * gimbal took it: within one attempt timeout of a failed request, start
 * the next of its type with retries >= 1.
 *
 * TIME. The core never reads a clock by itself: the poll-driven API takes
 * `now_ms` (any monotonic millisecond count that wraps modulo 2^32, e.g.
 * port->ops->now_ms()). Timeouts are measured per attempt from the
 * moment the attempt was sent, as the unsigned difference now_ms - sent,
 * so they work across the 2^32 wrap. A sample older than the send (a
 * clock read before the request started and passed in afterwards, or a
 * clock that stepped back) makes that difference 2^31 or more: it counts
 * as no time elapsed, never as an expired timeout. Samples must therefore
 * be less than 2^31 ms (24.8 days) apart: timeout_ms is under 2^31, and
 * timeout_ms plus the longest gap between two polls must be too.
 *
 * TWO WAYS TO USE IT
 *  - Firmware main loop (never blocks):
 *        tase_host_query_start(&h, TASE_GROUP_SETUP, 0x00, buf, sizeof buf,
 *                              200, 3, now);
 *        for (;;) {                              // main loop
 *            n = uart_ring_drain(bytes);         // whatever your RX is
 *            tase_host_feed(&h, bytes, n, now);
 *            r = tase_host_poll(&h, now);        // re-sends when due
 *            if (r != TASE_EAGAIN) { ...done: r = length or error... }
 *        }
 *  - Tools (blocks, reading the port): tase_host_transact().
 *
 * All functions: not reentrant per instance, not ISR-safe (call from one
 * context); different instances are independent. From on_frame (inside
 * the host's receiver) the calls that send, start, poll or cancel a
 * request may be made; tase_host_service(), tase_host_transact() and
 * tase_host_transact_msg() return TASE_EBUSY there, nothing read or sent
 * (they would feed the receiver that is calling: every byte they read
 * was lost). No allocation, no
 * globals. sizeof(tase_host_t) is 736 bytes on Cortex-M (a tase_rx_t plus a copy
 * of the pending request for re-sending).
 */
#ifndef TASE_HOST_H
#define TASE_HOST_H

#include "tase/frame.h"
#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Statistics; only incremented by the library, wrap modulo 2^32. */
typedef struct {
    uint32_t frames_tx;  /* frames written completely (commands, requests,
                           re-sent requests) */
    uint32_t tx_errors;  /* frames the port did not take completely */
    uint32_t frames_rx;  /* valid frames received */
    uint32_t requests;   /* requests started */
    uint32_t retries;    /* requests re-sent after a timeout */
    uint32_t replies;    /* requests completed by a matching frame */
    uint32_t timeouts;   /* requests that failed after their last attempt */
    uint32_t late;       /* owed answers of ended requests (MATCHING) */
    uint32_t stale;      /* frames of the pending request's type that began
                           before it was sent: never its answer (MATCHING) */
    uint32_t queries_rx; /* zero-length frames received: a gimbal sends
                            none, so they are most likely our own queries
                            coming back (a line that echoes, MATCHING) */
} tase_host_stats_t;

/* Host instance. Treat every field except `stats` and `rx.stats` as
 * private. */
typedef struct {
    tase_host_stats_t stats;
    tase_rx_t rx;
    tase_port_t port;
    tase_rx_handler_t on_frame;
    void *user;
    uint8_t *reply;  /* reply buffer of the pending request */
    void *reply_msg; /* typed request: the caller's struct, or NULL */
    bool typed;      /* the pending request is typed */
    size_t reply_cap;
    uint32_t timeout_ms; /* per attempt */
    uint32_t sent_at;    /* when the current attempt was sent */
    uint32_t first_at;   /* when the first attempt was sent */
    uint32_t now;        /* the latest now_ms given (feed, poll, start) */
    uint32_t owed_until; /* answers are owed (MATCHING) until then */
    uint32_t in_count;   /* bytes given to tase_host_feed(), mod 2^32 */
    uint32_t in_shift;   /* in_count - rx.stats.bytes_in as the feed began */
    uint32_t mark;       /* in_count when the pending request was sent */
    int result;          /* reply length or error once complete */
    uint8_t state;       /* idle / waiting / complete */
    uint8_t retries_left;
    uint8_t attempts; /* of the pending request, sent so far */
    uint8_t owed;     /* answers owed of owed_group/owed_type */
    uint8_t owed_group;
    uint8_t owed_type;
    uint8_t group; /* of the pending request */
    uint8_t type;
    uint8_t req_len;
    uint8_t req[TASE_DATA_MAX]; /* the request's data, for re-sending */
} tase_host_t;

/* Initialise a host on `port` (copied; port->ops must have write, and
 * read/now_ms for tase_host_service()/tase_host_transact()). on_frame
 * (may be NULL) receives every valid frame that does not complete the
 * pending request, with `user`. Returns TASE_OK or TASE_EARG (h or port
 * or port->ops or port->ops->write NULL). O(1). */
int tase_host_init(tase_host_t *h, const tase_port_t *port, tase_rx_handler_t on_frame, void *user);

/* Send one frame now (a command, host data, anything; a request may be
 * pending meanwhile). A GIMBAL_CMD or SPOI_CMD with data must be one the
 * spec defines (tase_command_check_data(), tase/codec.h: a flags value of
 * table 5, a position within the axes' ranges, a SPOI within 90/180
 * degrees, the packet's length): nothing moves on a value the spec gives
 * no meaning. Returns the frame length, or TASE_EARG (h NULL, data NULL
 * with len > 0), TASE_ETOOLONG (len > 253), TASE_ERANGE / TASE_ELENGTH
 * (such a GIMBAL_CMD or SPOI_CMD; TASE_ELENGTH also for a
 * RETRACT_DEPLOY_CMD of a length it does not accept, 0 included), all
 * checked before anything is sent,
 * or a port error from tase_port_write_all() (port_io.h). O(len). */
int tase_host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len);

/* Send packet `id` (TASE_ID_*) from its typed struct msg (tase/codec.h)
 * now; msg NULL sends the zero-length form (GYRO_ZERO_CMD, or a query
 * whose answer then goes to on_frame). Returns the frame length, or
 * TASE_EARG (h NULL, or a CAMERA_PASS tail NULL with len > 0),
 * TASE_ERANGE (a GIMBAL_CMD or SPOI_CMD tase_command_check() refuses, as
 * tase_host_send()), TASE_EUNKNOWN (id not in the schema), TASE_ELENGTH
 * (msg NULL for a packet without a zero-length form), TASE_ETOOLONG
 * (CAMERA_PASS tail over 249 bytes), all checked before anything is
 * sent, or a port error
 * from tase_port_write_all(). msg must not change until the call returns;
 * stack: tase_port_send_msg() (port_io.h).
 * O(length). */
int tase_host_send_msg(tase_host_t *h, uint16_t id, const void *msg);

/* Start a request: send (group, type, data[0..len)) and wait for the
 * gimbal's frame of the same group and type. len 0 is a query. Up to
 * 1 + retries attempts, each waiting timeout_ms from its sending: from
 * the end of its write, now_ms plus the time the port's write() took by
 * the port's clock (a write may block up to the port's bound W). The
 * reply's data will be copied into reply[0..reply_cap) (reply may be NULL
 * when reply_cap is 0: only the length is reported). The data is copied;
 * `reply` must stay valid until the request completes or is cancelled.
 * Only what the gimbal answers with a frame of the same group and type
 * can be requested (a retry sends it again): a zero-length query of a
 * packet with a query form, a setup packet, RETRACT_DEPLOY_CMD (echoed
 * when the move ends), CAMERA_PASS (the camera's bytes come back),
 * SPOI_CMD with TASE_SPOI_ECHO set, or a group/type the schema does not
 * know. Send the others with tase_host_send() / tase_host_send_msg().
 * A retry repeats the packet, so retries > 0 only for what sets absolute
 * values (a query, a setup packet, SPOI_CMD; a SPOI_CMD with a velocity
 * is repeated as it was first sent, so the gimbal propagates the point
 * from the retry's arrival: a timeout's worth behind, which a fresh
 * SPOI_CMD would not be); RETRACT_DEPLOY_CMD (its echo
 * comes when the move ends, later than a timeout may say), CAMERA_PASS
 * (camera bytes, often relative commands) and unknown packets (nothing
 * says what a repeat does) need retries 0.
 * Returns TASE_OK (first attempt sent), or
 *   TASE_EARG     h NULL, data NULL with len > 0, reply NULL with
 *                 reply_cap > 0, timeout_ms 0 or >= 2^31; a packet the
 *                 gimbal does not answer (GIMBAL_CMD, CAMERA_CMD, the
 *                 host's data, telemetry, SPOI_CMD without its echo flag);
 *                 retries > 0 for a packet that needs 0 (above);
 *   TASE_ERANGE   a SPOI_CMD tase_command_check_data() refuses;
 *   TASE_ELENGTH  len 0 for a known packet without a query form
 *                 (GYRO_ZERO_CMD: a command, never sent as a request), a
 *                 SPOI_CMD or RETRACT_DEPLOY_CMD of a length it does not
 *                 accept (other packets' lengths are not checked: a
 *                 setup packet of a wrong length goes out, and the
 *                 gimbal does not answer it);
 *   TASE_ETOOLONG len > 253;
 *   TASE_EBUSY    a request is pending (it is left untouched; checked
 *                 before what the request is);
 *   a port error  the first attempt could not be sent (no request pending).
 * Nothing is sent on an error. O(len). */
int tase_host_request_start(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data,
                            size_t len, uint8_t *reply, size_t reply_cap, uint32_t timeout_ms,
                            uint8_t retries, uint32_t now_ms);

/* Start a TYPED request for packet `id`: msg NULL sends the zero-length
 * query (a setup packet, SPOI_CMD, SYSTEM_VERSION), otherwise msg's
 * packet (set and confirm). When the reply arrives its data is decoded
 * into reply_msg (the packet's struct or a tase_packet_msg_t; NULL: the
 * length alone is reported) and tase_host_poll() returns its data length.
 * A reply of a length the packet does not accept completes the request
 * with TASE_ELENGTH (reply_msg untouched). A decoded CAMERA_PASS points
 * into the host instance, valid until the next request starts. reply_msg
 * must stay valid until the request completes or is cancelled.
 * The packets that can be requested are tase_host_request_start()'s.
 * Returns TASE_OK (first attempt sent), or
 *   TASE_EARG     h NULL, timeout_ms 0 or >= 2^31; a packet the gimbal
 *                 does not answer (as tase_host_request_start()); or from
 *                 the codec: a CAMERA_PASS tail NULL with len > 0;
 *   TASE_EBUSY    a request is pending (checked before the packet is
 *                 encoded; the pending one is left untouched);
 *   TASE_EUNKNOWN id is not in the schema (with retries 0: with
 *                 retries > 0 it is TASE_EARG, as an unknown packet is
 *                 for tase_host_request_start());
 *   TASE_ELENGTH  msg NULL for a packet without a query form (and
 *                 GYRO_ZERO_CMD, which has no data: a command);
 *   TASE_ETOOLONG CAMERA_PASS tail over 249 bytes;
 *   a port error  the first attempt could not be sent (no request pending).
 * O(length). */
int tase_host_request_msg_start(tase_host_t *h, uint16_t id, const void *msg, void *reply_msg,
                                uint32_t timeout_ms, uint8_t retries, uint32_t now_ms);

/* tase_host_request_start() with no data: a zero-length query. */
int tase_host_query_start(tase_host_t *h, uint8_t group, uint8_t type, uint8_t *reply,
                          size_t reply_cap, uint32_t timeout_ms, uint8_t retries, uint32_t now_ms);

/* Feed received bytes (from the port, a ring buffer, a capture). Frames
 * complete the pending request or go to on_frame. now_ms is not used for
 * matching (a reply fed before the deadline poll always wins). Returns the
 * number of
 * frames received (>= 0), TASE_EARG (h NULL, bytes NULL with n > 0) or
 * TASE_EBUSY (called from on_frame: the feed in progress goes on); on
 * either error nothing is fed and h is unchanged.
 * now_ms is when the bytes arrived: it drives the receiver's time bound
 * (tase/frame.h, TIME BOUND), so call it with n == 0 too whenever a look
 * at your receive buffer found it empty; frames held behind noise are then
 * delivered once the line has been quiet for the bound (at the port's
 * byte rate, tase_port_t.bytes_per_s). Worst case O(n * TASE_FRAME_MAX),
 * see tase_rx_feed(). */
int tase_host_feed(tase_host_t *h, const uint8_t *bytes, size_t n, uint32_t now_ms);

/* Hand over one frame received some other way (e.g. reassembled from
 * CAN). Returns 1 if it completed the pending request, 0 if it went to
 * on_frame, TASE_EARG if h or frame (or frame->data) is NULL. Whether it
 * is an owed answer (MATCHING) is judged by the latest now_ms the host
 * was given (tase_host_feed(), tase_host_poll(), a request's start), so
 * call tase_host_poll() as time passes. O(len). */
int tase_host_handle_frame(tase_host_t *h, const tase_frame_t *frame);

/* Drive the pending request. Re-sends it when its attempt timed out and
 * retries remain. Returns
 *   >= 0          the request completed; the reply's data length (its
 *                 bytes are in the caller's reply buffer). The host is idle
 *                 again: each outcome is reported exactly once.
 *   TASE_EAGAIN   still waiting;
 *   TASE_ETIMEOUT the last attempt timed out (host idle again);
 *   TASE_ENOSPC   the reply was longer than reply_cap (nothing copied;
 *                 host idle again);
 *   TASE_ESTATE   no request was started (or its outcome was reported);
 *   TASE_EARG     h NULL.
 * now_ms is noted whatever the result (TASE_ESTATE too): it is the time
 * by which answers owed by ended requests expire (MATCHING), also for
 * frames given to tase_host_handle_frame(), which takes no time.
 * A re-send the port refuses still uses up the attempt (counted in
 * stats.tx_errors). O(request length). */
int tase_host_poll(tase_host_t *h, uint32_t now_ms);

/* Forget the pending request (its outcome will not be reported).
 * Returns TASE_OK, or TASE_EARG (h NULL). O(1). */
int tase_host_cancel(tase_host_t *h);

/* True while a request is pending: waiting for its reply, or complete
 * with its outcome not yet taken by tase_host_poll() (either way
 * tase_host_request_start() says TASE_EBUSY); false for NULL. O(1). */
bool tase_host_busy(const tase_host_t *h);

/* Read once from the port, waiting at most wait_ms, and feed what
 * arrived (time from port->ops->now_ms). While the receiver holds a
 * candidate, the wait ends by its quiet limit instead, so that the time
 * bound holds (tase/frame.h, TIME BOUND): a call may return 0 early,
 * never late. Returns bytes read (>= 0), a
 * port error, TASE_EIO (the port's read() claimed more bytes than asked;
 * nothing fed), TASE_EUNSUPPORTED (port has no read or now_ms), TASE_EBUSY
 * (called from on_frame: nothing read) or TASE_EARG (h NULL, never
 * initialised: no port ops, or its receiver h->rx visibly corrupted, as
 * tase_rx_feed() says: nothing read). Stack: a 64-byte read buffer and the receive
 * path, 436 B on Cortex-M4 and 504 B on M0+ with the host's own frame
 * handling, plus on_frame's and the port's own (docs/FOOTPRINT.md, "Role
 * entry points"). */
int tase_host_service(tase_host_t *h, uint32_t wait_ms);

/* The most reads tase_host_drain() makes (of 64 bytes each: 16 KiB). */
#define TASE_HOST_DRAIN_READS 256u

/* Read and feed what the port has ready, never waiting: reads with
 * wait_ms 0 (tase_host_service()) until two in a row bring nothing (a
 * port may return 0 early, port.h) or TASE_HOST_DRAIN_READS were made.
 * Call it before starting a request, so that an answer to an earlier one
 * that waited unread is not taken as this request's (MATCHING above);
 * tase_host_transact() and tase_host_transact_msg() call it when no
 * request is pending. It may also be called with a request pending (a
 * frame read then completes it as tase_host_service() would). Returns the
 * bytes read in all (0..16384), or the first error of
 * tase_host_service() (what was read before it is fed). Worst case: 256
 * 64-byte reads fed (docs/TIMING.md). Stack: tase_host_service()'s and a
 * few words (docs/FOOTPRINT.md).
 * (A firmware that feeds its own receive buffer with tase_host_feed()
 * gets the same by feeding what it has before tase_host_request_start().) */
int tase_host_drain(tase_host_t *h);

/* Blocking convenience for tools: start a request, then service the port
 * and poll until it completes. Same arguments and results as
 * tase_host_request_start() + tase_host_poll(): returns the reply length
 * or a negative code (TASE_ETIMEOUT after 1 + retries attempts). Waits at
 * most about (1 + retries) * timeout_ms. Frames that arrive meanwhile go
 * to on_frame. TASE_EARG also for h without port ops (never initialised)
 * or with a corrupted receiver (as tase_host_service()), TASE_EUNSUPPORTED for a port without read or now_ms, TASE_EBUSY called
 * from on_frame (nothing sent).
 * Before sending it reads and feeds what the port has ready (reads of 64
 * bytes that do not wait, until two in a row bring nothing, at most 256:
 * see MATCHING); a read error there is returned, nothing sent.
 * A broken port whose clock stands still while read() returns nothing at
 * once ends with TASE_ETIMEOUT after TASE_PORT_WRITE_SPINS such reads in a
 * row (tase/config.h), instead of never. */
int tase_host_transact(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len,
                       uint8_t *reply, size_t reply_cap, uint32_t timeout_ms, uint8_t retries);

/* The typed blocking request: tase_host_request_msg_start() (msg NULL:
 * a query), then service and poll as tase_host_transact() does. Returns
 * the reply's data length with reply_msg filled, or a negative code as
 * tase_host_request_msg_start() + tase_host_poll() (TASE_ETIMEOUT,
 * TASE_ELENGTH for a reply of a wrong length, ...), TASE_EARG /
 * TASE_EUNSUPPORTED as tase_host_transact(). */
int tase_host_transact_msg(tase_host_t *h, uint16_t id, const void *msg, void *reply_msg,
                           uint32_t timeout_ms, uint8_t retries);

#ifdef __cplusplus
}
#endif

#endif /* TASE_HOST_H */
