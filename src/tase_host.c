/* Host role: command sending and request/echo matching (see tase/host.h). */
#include "tase/host.h"

#include <string.h>

#include "tase/port_io.h"

enum { HOST_IDLE = 0, HOST_WAITING = 1, HOST_COMPLETE = 2 };

#define HOST_SERVICE_CHUNK 64u

int tase_host_init(tase_host_t *h, const tase_port_t *port, tase_rx_handler_t on_frame, void *user)
{
    if (h == NULL || port == NULL || port->ops == NULL || port->ops->write == NULL) {
        return TASE_EARG;
    }
    (void)memset(h, 0, sizeof *h);
    (void)tase_rx_init(&h->rx);
    h->port = *port;
    h->on_frame = on_frame;
    h->user = user;
    h->state = HOST_IDLE;
    return TASE_OK;
}

static int host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len)
{
    return tase_port_count_tx(tase_port_send_frame(&h->port, group, type, data, len),
                              &h->stats.frames_tx, &h->stats.tx_errors);
}

int tase_host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    return host_send(h, group, type, data, len);
}

int tase_host_request_start(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data,
                            size_t len, uint8_t *reply, size_t reply_cap, uint32_t timeout_ms,
                            uint8_t retries, uint32_t now_ms)
{
    int r;

    if (h == NULL || (data == NULL && len > 0) || (reply == NULL && reply_cap > 0) ||
        timeout_ms == 0 || timeout_ms > 0x80000000u) {
        return TASE_EARG;
    }
    if (len > TASE_DATA_MAX) {
        return TASE_ETOOLONG;
    }
    if (h->state != HOST_IDLE) {
        return TASE_EBUSY;
    }
    r = host_send(h, group, type, data, len);
    if (r < 0) {
        return r;
    }
    if (len > 0) {
        (void)memcpy(h->req, data, len);
    }
    h->req_len = (uint8_t)len;
    h->group = group;
    h->type = type;
    h->reply = reply;
    h->reply_cap = reply_cap;
    h->timeout_ms = timeout_ms;
    h->retries_left = retries;
    h->sent_at = now_ms;
    h->result = TASE_EAGAIN;
    h->state = HOST_WAITING;
    h->stats.requests++;
    return TASE_OK;
}

int tase_host_query_start(tase_host_t *h, uint8_t group, uint8_t type, uint8_t *reply,
                          size_t reply_cap, uint32_t timeout_ms, uint8_t retries, uint32_t now_ms)
{
    return tase_host_request_start(h, group, type, NULL, 0, reply, reply_cap, timeout_ms, retries,
                                   now_ms);
}

int tase_host_handle_frame(tase_host_t *h, const tase_frame_t *frame)
{
    if (h == NULL || frame == NULL || frame->data == NULL) {
        return TASE_EARG;
    }
    h->stats.frames_rx++;
    /* A zero-length frame is somebody's query (possibly our own, looped
     * back), never the gimbal's answer. */
    if (h->state == HOST_WAITING && frame->group == h->group && frame->type == h->type &&
        frame->len > 0) {
        if (h->reply == NULL) {
            h->result = (int)frame->len;
        } else if (frame->len > h->reply_cap) {
            h->result = TASE_ENOSPC;
        } else {
            (void)memcpy(h->reply, frame->data, frame->len);
            h->result = (int)frame->len;
        }
        h->state = HOST_COMPLETE;
        h->stats.replies++;
        return 1;
    }
    if (h->on_frame != NULL) {
        h->on_frame(h->user, frame);
    }
    return 0;
}

static void host_rx(void *user, const tase_frame_t *frame)
{
    (void)tase_host_handle_frame((tase_host_t *)user, frame);
}

int tase_host_feed(tase_host_t *h, const uint8_t *bytes, size_t n, uint32_t now_ms)
{
    (void)now_ms;
    if (h == NULL) {
        return TASE_EARG;
    }
    return tase_rx_feed(&h->rx, bytes, n, host_rx, h);
}

int tase_host_poll(tase_host_t *h, uint32_t now_ms)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    if (h->state == HOST_COMPLETE) {
        h->state = HOST_IDLE;
        return h->result;
    }
    if (h->state != HOST_WAITING) {
        return TASE_ESTATE;
    }
    /* Unsigned difference: correct across the 2^32 wrap of the clock. */
    if ((uint32_t)(now_ms - h->sent_at) < h->timeout_ms) {
        return TASE_EAGAIN;
    }
    if (h->retries_left == 0) {
        h->state = HOST_IDLE;
        h->stats.timeouts++;
        return TASE_ETIMEOUT;
    }
    h->retries_left--;
    h->stats.retries++;
    h->sent_at = now_ms;
    (void)host_send(h, h->group, h->type, h->req, h->req_len);
    return TASE_EAGAIN;
}

int tase_host_cancel(tase_host_t *h)
{
    if (h == NULL) {
        return TASE_EARG;
    }
    h->state = HOST_IDLE;
    return TASE_OK;
}

bool tase_host_busy(const tase_host_t *h)
{
    return h != NULL && h->state == HOST_WAITING;
}

int tase_host_service(tase_host_t *h, uint32_t wait_ms)
{
    uint8_t buf[HOST_SERVICE_CHUNK];
    int n;

    if (h == NULL || h->port.ops == NULL) {
        return TASE_EARG;
    }
    if (h->port.ops->read == NULL || h->port.ops->now_ms == NULL) {
        return TASE_EUNSUPPORTED;
    }
    n = h->port.ops->read(h->port.ctx, buf, sizeof buf, wait_ms);
    if (n > (int)sizeof buf) {
        return TASE_EIO; /* a port claiming more than asked is broken */
    }
    if (n > 0) {
        (void)tase_host_feed(h, buf, (size_t)n, h->port.ops->now_ms(h->port.ctx));
    }
    return n;
}

int tase_host_transact(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len,
                       uint8_t *reply, size_t reply_cap, uint32_t timeout_ms, uint8_t retries)
{
    int r;

    if (h == NULL || h->port.ops == NULL) {
        return TASE_EARG;
    }
    if (h->port.ops->read == NULL || h->port.ops->now_ms == NULL) {
        return TASE_EUNSUPPORTED;
    }
    r = tase_host_request_start(h, group, type, data, len, reply, reply_cap, timeout_ms, retries,
                                h->port.ops->now_ms(h->port.ctx));
    if (r < 0) {
        return r;
    }
    for (;;) {
        uint32_t now = h->port.ops->now_ms(h->port.ctx);
        uint32_t waited;
        r = tase_host_poll(h, now);
        if (r != TASE_EAGAIN) {
            return r;
        }
        waited = (uint32_t)(now - h->sent_at);
        r = tase_host_service(h, waited < h->timeout_ms ? h->timeout_ms - waited : 0u);
        if (r < 0) {
            (void)tase_host_cancel(h);
            return r;
        }
    }
}
