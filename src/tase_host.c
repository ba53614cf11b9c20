/* Host role: command sending and request/echo matching (see tase/host.h). */
#include "tase/host.h"

#include <string.h>

#include "tase/codec.h"
#include "tase/flags.h"
#include "tase/port_io.h"
#include "tase_frame_private.h"

enum { HOST_IDLE = 0, HOST_WAITING = 1, HOST_COMPLETE = 2 };

#define HOST_SERVICE_CHUNK 64u

int tase_host_init(tase_host_t *h, const tase_port_t *port, tase_rx_handler_t on_frame, void *user)
{
    if (h == NULL || port == NULL || port->ops == NULL || port->ops->write == NULL) {
        return TASE_EARG;
    }
    (void)memset(h, 0, sizeof *h);
    (void)tase_rx_init(&h->rx);
    (void)tase_rx_set_timing(&h->rx, port->bytes_per_s, 0u);
    h->port = *port;
    h->on_frame = on_frame;
    h->user = user;
    h->state = HOST_IDLE;
    return TASE_OK;
}

/* The pending request ends leaving n of its attempts unanswered: n answers
 * of its group and type are owed until `until` (host.h, MATCHING), on top
 * of those still owed of the same type. */
static void owe(tase_host_t *h, unsigned n, uint32_t until)
{
    unsigned total = n;
    uint32_t end = until;
    if (n == 0u) {
        return;
    }
    /* tase_port_elapsed_ms(b, a) != 0: a is before b on the wrapping
     * clock (the windows are shorter than 2^31 ms) */
    if (h->owed > 0u && h->owed_group == h->group && h->owed_type == h->type &&
        tase_port_elapsed_ms(h->owed_until, h->now) != 0u) {
        total += h->owed;
        if (tase_port_elapsed_ms(h->owed_until, until) != 0u) {
            end = h->owed_until;
        }
    }
    h->owed = (uint8_t)(total < 255u ? total : 255u);
    h->owed_group = h->group;
    h->owed_type = h->type;
    h->owed_until = end;
}

/* Whether frame is an owed answer (counted, and one fewer owed). */
static bool owed_answer(tase_host_t *h, const tase_frame_t *frame)
{
    if (h->owed == 0u || frame->group != h->owed_group || frame->type != h->owed_type ||
        frame->len == 0u) {
        return false;
    }
    if (tase_port_elapsed_ms(h->owed_until, h->now) == 0u) {
        h->owed = 0u; /* no longer: it is an answer like any other */
        return false;
    }
    h->owed--;
    h->stats.late++;
    return true;
}

static int host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len)
{
    return tase_port_count_tx(tase_port_send_frame(&h->port, group, type, data, len),
                              &h->stats.frames_tx, &h->stats.tx_errors);
}

int tase_host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len)
{
    int r;
    if (h == NULL) {
        return TASE_EARG;
    }
    /* the port's argument checks first (as tase_port_send_frame() makes them) */
    if (data == NULL && len > 0u) {
        return TASE_EARG;
    }
    if (len > TASE_DATA_MAX) {
        return TASE_ETOOLONG;
    }
    r = tase_command_check_data(TASE_ID(group, type), data, len);
    return (r != TASE_OK) ? r : host_send(h, group, type, data, len);
}

int tase_host_send_msg(tase_host_t *h, uint16_t id, const void *msg)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    if (msg != NULL && tase_command_check(id, msg) != TASE_OK) {
        return TASE_ERANGE;
    }
    return tase_port_count_tx(tase_port_send_msg(&h->port, id, msg), &h->stats.frames_tx,
                              &h->stats.tx_errors);
}

/* Send an attempt of the request in h->req and say when it went out in
 * *sent_at: now_ms plus the time the write took by the port's clock (a
 * write may block up to the port's bound W, and an attempt's timeout
 * counts from its sending: timed from before the write, a slow write ate
 * the wait, and an answer a few ms after it found the request given up). */
static int send_attempt(tase_host_t *h, uint8_t group, uint8_t type, size_t len, uint32_t now_ms,
                        uint32_t *sent_at)
{
    uint32_t (*clock)(void *) = h->port.ops != NULL ? h->port.ops->now_ms : NULL;
    uint32_t t0 = clock != NULL ? clock(h->port.ctx) : 0u;
    int r = host_send(h, group, type, h->req, len);
    *sent_at = now_ms + (clock != NULL ? tase_port_elapsed_ms(clock(h->port.ctx), t0) : 0u);
    return r;
}

/* Send the request whose data is already in h->req and make it pending.
 * Nothing is pending if the first attempt cannot be sent. */
static int request_send(tase_host_t *h, uint8_t group, uint8_t type, size_t len, uint8_t *reply,
                        size_t reply_cap, uint32_t timeout_ms, uint8_t retries, uint32_t now_ms)
{
    uint32_t sent_at;
    int r = send_attempt(h, group, type, len, now_ms, &sent_at);
    if (r < 0) {
        return r;
    }
    h->req_len = (uint8_t)len;
    h->group = group;
    h->type = type;
    h->reply = reply;
    h->reply_cap = reply_cap;
    h->timeout_ms = timeout_ms;
    h->retries_left = retries;
    h->sent_at = sent_at;
    h->first_at = sent_at;
    h->mark = h->in_count; /* every byte fed so far came before the send */
    h->now = sent_at;
    h->attempts = 1u;
    h->result = TASE_EAGAIN;
    h->state = HOST_WAITING;
    h->stats.requests++;
    return TASE_OK;
}

/* A timeout the clock arithmetic can see expire: an elapsed time of 2^31
 * ms or more reads as none (tase_port_elapsed_ms()). */
static bool timeout_ok(uint32_t timeout_ms)
{
    return timeout_ms > 0u && timeout_ms < 0x80000000u;
}

/* Whether the gimbal answers packet p (NULL: unknown to the schema),
 * sent with data or without, with a frame of the same group and type, so
 * that a request may wait for it, and whether it may be re-sent: a
 * zero-length query of a packet with a query form, and the packets it
 * sends back (the setup packets' echo, RETRACT_DEPLOY_CMD when the move
 * ends, CAMERA_PASS with the camera's bytes), SPOI_CMD only with its echo
 * flag (4.3.2: spoi_flags, its data byte 18). TASE_ELENGTH for zero length
 * without a query form (GYRO_ZERO_CMD is a command), TASE_EARG for a
 * packet the gimbal does not answer (a re-send would repeat a command). A
 * re-send (retries > 0) repeats the packet, so only what sets absolute
 * values may have one: a query, a setup packet, SPOI_CMD; not
 * RETRACT_DEPLOY_CMD (its echo comes when the move ends, later than any
 * timeout may say), CAMERA_PASS (camera bytes, often relative commands)
 * or a packet the schema does not know (nothing says what a repeat does),
 * which are TASE_EARG with retries. Decided before anything is written to
 * h->req, which may hold a typed CAMERA_PASS reply. */
static int answered(const tase_packet_desc_t *p, size_t len, unsigned spoi_flags, uint8_t retries)
{
    if (p == NULL) {
        return (retries == 0u) ? TASE_OK : TASE_EARG;
    }
    if (len == 0u) {
        return tase_schema_is_query(p, 0u) ? TASE_OK : TASE_ELENGTH;
    }
    if (p->id == TASE_ID_SPOI_CMD && !tase_schema_length_ok(p, len)) {
        return TASE_ELENGTH; /* before its echo flag, which it may not have */
    }
    if ((p->flags & TASE_DIR_BOTH) != TASE_DIR_BOTH ||
        (p->id == TASE_ID_SPOI_CMD && (spoi_flags & TASE_SPOI_ECHO) == 0u)) {
        return TASE_EARG;
    }
    if (retries > 0u && TASE_ID_GROUP(p->id) != TASE_GROUP_SETUP && p->id != TASE_ID_SPOI_CMD) {
        return TASE_EARG;
    }
    return TASE_OK;
}

int tase_host_request_start(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data,
                            size_t len, uint8_t *reply, size_t reply_cap, uint32_t timeout_ms,
                            uint8_t retries, uint32_t now_ms)
{
    int r;
    if (h == NULL || (data == NULL && len > 0) || (reply == NULL && reply_cap > 0) ||
        !timeout_ok(timeout_ms)) {
        return TASE_EARG;
    }
    if (len > TASE_DATA_MAX) {
        return TASE_ETOOLONG;
    }
    if (h->state != HOST_IDLE) {
        return TASE_EBUSY;
    }
    r = answered(tase_schema_find(group, type), len, len > 18u ? data[18] : 0u, retries);
    if (r == TASE_OK) {
        r = tase_command_check_data(TASE_ID(group, type), data, len);
    }
    if (r != TASE_OK) {
        return r;
    }
    if (len > 0) {
        (void)memmove(h->req, data, len); /* data may be a former reply in h->req */
    }
    h->typed = false;
    return request_send(h, group, type, len, reply, reply_cap, timeout_ms, retries, now_ms);
}

int tase_host_request_msg_start(tase_host_t *h, uint16_t id, const void *msg, void *reply_msg,
                                uint32_t timeout_ms, uint8_t retries, uint32_t now_ms)
{
    int n;
    if (h == NULL || !timeout_ok(timeout_ms)) {
        return TASE_EARG;
    }
    if (h->state != HOST_IDLE) {
        return TASE_EBUSY;
    }
    {
        /* with data unless msg is NULL or the packet has none (GYRO_ZERO) */
        const tase_packet_desc_t *p = tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id));
        int r = answered(
            p, (msg != NULL && p != NULL) ? p->len : 0u, /* a typed packet has its length */
            (msg != NULL && id == TASE_ID_SPOI_CMD) ? ((const tase_spoi_cmd_t *)msg)->flags : 0u,
            retries);
        if (r == TASE_OK && msg != NULL) {
            r = tase_command_check(id, msg);
        }
        if (r != TASE_OK) {
            return r;
        }
    }
    /* The request's data goes where re-sends take it from; the reply will
     * land in the same buffer once no re-send is due any more. The codec
     * checks everything before it writes: an error leaves h->req as it was. */
    n = msg != NULL ? tase_packet_encode_data(id, msg, h->req, sizeof h->req)
                    : tase_packet_encode_data_len(id, NULL, 0u, h->req, sizeof h->req);
    if (n < 0) {
        return n;
    }
    h->typed = true;
    h->reply_msg = reply_msg;
    return request_send(h, TASE_ID_GROUP(id), TASE_ID_TYPE(id), (size_t)n, h->req, sizeof h->req,
                        timeout_ms, retries, now_ms);
}

int tase_host_query_start(tase_host_t *h, uint8_t group, uint8_t type, uint8_t *reply,
                          size_t reply_cap, uint32_t timeout_ms, uint8_t retries, uint32_t now_ms)
{
    return tase_host_request_start(h, group, type, NULL, 0, reply, reply_cap, timeout_ms, retries,
                                   now_ms);
}

/* A typed request's reply, already copied into h->req, into the caller's
 * struct; its data length, or TASE_ELENGTH (the struct is not touched). */
static int decode_reply(tase_host_t *h, size_t len)
{
    const tase_packet_desc_t *p = tase_schema_find(h->group, h->type);
    if (!tase_schema_length_ok(p, len)) {
        return TASE_ELENGTH;
    }
    if (h->reply_msg == NULL) {
        return (int)len;
    }
    return tase_packet_decode_desc(p, h->req, len, h->reply_msg);
}

/* tase_host_handle_frame() for a frame that may (answer) or may not
 * (it began before the pending request was sent) complete it. */
static int handle(tase_host_t *h, const tase_frame_t *frame, bool answer)
{
    bool owed;
    bool match;
    h->stats.frames_rx++;
    /* A zero-length frame is somebody's query (possibly our own, looped
     * back), never the gimbal's answer; an owed one answers an earlier
     * request (counted however it comes). */
    if (frame->len == 0u) {
        h->stats.queries_rx++;
    }
    owed = owed_answer(h, frame);
    match = !owed && h->state == HOST_WAITING && frame->group == h->group &&
            frame->type == h->type && frame->len > 0;
    if (match && !answer) {
        h->stats.stale++;
    } else if (match) {
        if (h->reply == NULL) {
            h->result = (int)frame->len;
        } else if (frame->len > h->reply_cap) {
            h->result = TASE_ENOSPC;
        } else {
            (void)memcpy(h->reply, frame->data, frame->len);
            h->result = (int)frame->len;
        }
        if (h->typed) {
            h->result = decode_reply(h, frame->len);
        }
        h->state = HOST_COMPLETE;
        h->stats.replies++;
        /* the other attempts may still be answered, as late as this one
         * came after the first attempt */
        owe(h, h->attempts - 1u,
            h->sent_at + tase_port_elapsed_ms(h->now, h->first_at) + h->timeout_ms);
        return 1;
    } else {
        /* not of the pending request */
    }
    if (h->on_frame != NULL) {
        /* a callback may reset rx.stats (frame.h allows it): later frames
         * of the feed in progress are then counted from there, and the
         * shift to the host's own count moves with them */
        uint32_t before = h->rx.stats.bytes_in;
        h->on_frame(h->user, frame);
        h->in_shift += before - h->rx.stats.bytes_in;
    }
    return 0;
}

int tase_host_handle_frame(tase_host_t *h, const tase_frame_t *frame)
{
    if (h == NULL || frame == NULL || frame->data == NULL) {
        return TASE_EARG;
    }
    return handle(h, frame, true);
}

/* A frame from the host's own receiver: it answers the pending request
 * only if it began at or after the byte count of the request's sending
 * (its offset on the host's count, in_count, through in_shift). */
static void host_rx(void *user, const tase_frame_t *frame)
{
    tase_host_t *h = user;
    uint32_t at = frame->offset + h->in_shift;
    (void)handle(h, frame, (uint32_t)(at - h->mark) < 0x80000000u);
}

int tase_host_feed(tase_host_t *h, const uint8_t *bytes, size_t n, uint32_t now_ms)
{
    int r;
    int t;
    uint32_t count;
    uint32_t shift;
    uint32_t was;
    if (h == NULL) {
        return TASE_EARG;
    }
    /* set before the feed: the frames it delivers judge owed answers by it */
    was = h->now;
    h->now = now_ms;
    /* the host's own count of the bytes it was fed, which nothing resets
     * (rx.stats may be): frames are placed on it for MATCHING */
    count = h->in_count;
    shift = h->in_shift;
    h->in_shift = count - h->rx.stats.bytes_in;
    h->in_count = count + (uint32_t)n;
    r = tase_rx_feed(&h->rx, bytes, n, host_rx, h);
    if (r < 0) {
        /* nothing fed (bad arguments, or a call from on_frame: the feed
         * in progress goes on with its own shift) */
        h->now = was;
        h->in_count = count;
        h->in_shift = shift;
        return r;
    }
    /* the bytes' arrival, or (n == 0) a look that found the line quiet */
    t = tase_rx_tick(&h->rx, now_ms, host_rx, h);
    return t < 0 ? t : r + t;
}

int tase_host_poll(tase_host_t *h, uint32_t now_ms)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    h->now = now_ms;
    if (h->state == HOST_COMPLETE) {
        h->state = HOST_IDLE;
        return h->result;
    }
    if (h->state != HOST_WAITING) {
        return TASE_ESTATE;
    }
    if (tase_port_elapsed_ms(now_ms, h->sent_at) < h->timeout_ms) {
        return TASE_EAGAIN;
    }
    if (h->retries_left == 0) {
        h->state = HOST_IDLE;
        h->stats.timeouts++;
        owe(h, h->attempts, now_ms + h->timeout_ms);
        return TASE_ETIMEOUT;
    }
    h->retries_left--;
    h->stats.retries++;
    if (h->attempts < 255u) {
        h->attempts++;
    }
    (void)send_attempt(h, h->group, h->type, h->req_len, now_ms, &h->sent_at);
    h->now = h->sent_at;
    return TASE_EAGAIN;
}

int tase_host_cancel(tase_host_t *h)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    if (h->state == HOST_WAITING) {
        owe(h, h->attempts, h->now + h->timeout_ms);
    }
    h->state = HOST_IDLE;
    return TASE_OK;
}

bool tase_host_busy(const tase_host_t *h)
{
    /* waiting, or complete with the outcome not yet taken by poll():
     * tase_host_request_start() refuses both with TASE_EBUSY */
    return h != NULL && h->state != HOST_IDLE;
}

/* The checks of the calls that read the port (service, transact): TASE_OK
 * when it can be used. A receiver that could not take what they read
 * refuses them before the read, as tase_rx_feed() would after it (the
 * bytes would be lost): TASE_EBUSY inside its callback (on_frame),
 * TASE_EARG when it is visibly corrupted. */
static int port_ok(const tase_host_t *h)
{
    if (h == NULL || h->port.ops == NULL) {
        return TASE_EARG;
    }
    if (h->port.ops->read == NULL || h->port.ops->now_ms == NULL) {
        return TASE_EUNSUPPORTED;
    }
    return tase_rx_state_check(&h->rx);
}

int tase_host_service(tase_host_t *h, uint32_t wait_ms)
{
    uint8_t buf[HOST_SERVICE_CHUNK];
    uint32_t bound;
    int n = port_ok(h);

    if (n != TASE_OK) {
        return n;
    }
    /* Wake up by the receiver's quiet limit, so that an empty read ticks
     * it in time (tase/frame.h, TIME BOUND). */
    bound = tase_rx_quiet_ms(&h->rx, h->port.ops->now_ms(h->port.ctx));
    n = h->port.ops->read(h->port.ctx, buf, sizeof buf, wait_ms < bound ? wait_ms : bound);
    if (n > (int)sizeof buf) {
        return TASE_EIO; /* a port claiming more than asked is broken */
    }
    if (n >= 0) {
        int r = tase_host_feed(h, buf, (size_t)n, h->port.ops->now_ms(h->port.ctx));
        if (r < 0) {
            return r;
        }
    }
    return n;
}

/* Service the port and poll until the pending request completes. The
 * port is read before each poll, so an answer that came while the request
 * was being written is taken even when the write outlasted the attempt's
 * timeout (a read with no time left does not wait); polling first timed
 * such a request out, or re-sent it, with the answer unread. A port whose
 * clock stands still while its read() returns nothing at once would make
 * this loop endless: TASE_PORT_WRITE_SPINS such reads in a row end it as
 * a timeout (the backstop tase_port_write_all() has for writes). */
static int transact_wait(tase_host_t *h)
{
    uint32_t last = h->port.ops->now_ms(h->port.ctx);
    uint32_t idle = 0u;
    for (;;) {
        uint32_t now = h->port.ops->now_ms(h->port.ctx);
        uint32_t waited = tase_port_elapsed_ms(now, h->sent_at);
        int n = tase_host_service(h, waited < h->timeout_ms ? h->timeout_ms - waited : 0u);
        int r;
        if (n < 0) {
            (void)tase_host_cancel(h);
            return n;
        }
        now = h->port.ops->now_ms(h->port.ctx);
        r = tase_host_poll(h, now);
        if (r != TASE_EAGAIN) {
            return r;
        }
        idle = (n == 0 && tase_port_elapsed_ms(now, last) == 0u) ? idle + 1u : 0u;
        if (idle >= TASE_PORT_WRITE_SPINS) {
            (void)tase_host_cancel(h);
            h->stats.timeouts++;
            return TASE_ETIMEOUT;
        }
        last = now;
    }
}

int tase_host_drain(tase_host_t *h)
{
    unsigned i;
    unsigned empty = 0u;
    int total = 0;
    int r = port_ok(h);
    if (r != TASE_OK) {
        return r;
    }
    for (i = 0; i < TASE_HOST_DRAIN_READS && empty < 2u; i++) {
        int n = tase_host_service(h, 0u);
        if (n < 0) {
            return n;
        }
        total += n;
        empty = (n == 0) ? empty + 1u : 0u;
    }
    return total;
}

/* The read before a blocking request (host.h, MATCHING): only when idle;
 * with a request pending nothing is read (request_start() refuses it). */
static int drain_idle(tase_host_t *h)
{
    int r = port_ok(h);
    if (r == TASE_OK && h->state == HOST_IDLE) {
        r = tase_host_drain(h);
    }
    return r < 0 ? r : TASE_OK;
}

int tase_host_transact(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len,
                       uint8_t *reply, size_t reply_cap, uint32_t timeout_ms, uint8_t retries)
{
    int r = drain_idle(h);
    if (r != TASE_OK) {
        return r;
    }
    r = tase_host_request_start(h, group, type, data, len, reply, reply_cap, timeout_ms, retries,
                                h->port.ops->now_ms(h->port.ctx));
    return r < 0 ? r : transact_wait(h);
}

int tase_host_transact_msg(tase_host_t *h, uint16_t id, const void *msg, void *reply_msg,
                           uint32_t timeout_ms, uint8_t retries)
{
    int r = drain_idle(h);
    if (r != TASE_OK) {
        return r;
    }
    r = tase_host_request_msg_start(h, id, msg, reply_msg, timeout_ms, retries,
                                    h->port.ops->now_ms(h->port.ctx));
    return r < 0 ? r : transact_wait(h);
}
