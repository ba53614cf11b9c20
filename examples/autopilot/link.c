/* The autopilot's link to the gimbal; see link.h.
 *
 * Until the roles take typed packets themselves, the two conversions the
 * host role needs are done here with the library's codec: a typed struct
 * becomes the data bytes tase_host_send() takes by encoding it with
 * tase_packet_encode() and handing over the frame's data part; a reply's
 * data bytes become a typed struct through tase_packet_decode() on a
 * tase_frame_t view of them. These two functions are the only places to
 * change when the roles offer typed send and typed replies. */
#include "link.h"

#include <string.h>

/* Encode packet `id` from *msg (NULL: its zero-length query) into
 * frame[0..cap); returns the data length (the data is at
 * frame + TASE_FRAME_HEADER) or the codec's error. */
static int encode_data(uint16_t id, const void *msg, uint8_t *frame, size_t cap)
{
    int n = msg != NULL ? tase_packet_encode(id, msg, frame, cap)
                        : tase_packet_encode_query(id, frame, cap);
    return n < 0 ? n : n - (int)TASE_FRAME_OVERHEAD;
}

/* Decode the data bytes of packet `id` into its typed struct. */
static int decode_data(uint16_t id, const uint8_t *data, size_t len, void *msg)
{
    tase_frame_t f;
    f.offset = 0;
    f.group = TASE_ID_GROUP(id);
    f.type = TASE_ID_TYPE(id);
    f.len = (uint8_t)len;
    f.data = data;
    return tase_packet_decode(&f, msg);
}

int link_init(link_t *l, const tase_port_t *port, const tase_packet_handler_t *handlers,
              tase_rx_handler_t on_other, tase_dispatch_error_t on_error, void *user)
{
    int r;
    memset(l, 0, sizeof(*l));
    r = tase_host_init(&l->host, port, tase_dispatch_frame, &l->dispatch);
    if (r != TASE_OK) {
        return r;
    }
    return tase_dispatch_init(&l->dispatch, handlers, on_other, on_error, user, &l->host.rx.stats);
}

int link_service(link_t *l, unsigned max_reads)
{
    int total = 0;
    while (max_reads-- > 0u) {
        int n = tase_host_service(&l->host, 0u);
        if (n <= 0) {
            return n < 0 ? n : total;
        }
        total += n;
    }
    return total;
}

int link_send(link_t *l, uint16_t id, const void *msg)
{
    uint8_t frame[TASE_FRAME_MAX];
    int n = encode_data(id, msg, frame, sizeof(frame));
    if (n < 0) {
        return n;
    }
    return tase_host_send(&l->host, TASE_ID_GROUP(id), TASE_ID_TYPE(id), &frame[TASE_FRAME_HEADER],
                          (size_t)n);
}

int link_request(link_t *l, uint16_t id, const void *msg, uint32_t now_ms)
{
    uint8_t frame[TASE_FRAME_MAX];
    int r, n = encode_data(id, msg, frame, sizeof(frame));
    if (n < 0) {
        return n;
    }
    r = tase_host_request_start(&l->host, TASE_ID_GROUP(id), TASE_ID_TYPE(id),
                                &frame[TASE_FRAME_HEADER], (size_t)n, l->reply, sizeof(l->reply),
                                LINK_TIMEOUT_MS, LINK_RETRIES, now_ms);
    if (r == TASE_OK) {
        l->pending = id;
    }
    return r;
}

int link_poll(link_t *l, uint32_t now_ms, void *reply)
{
    int r = tase_host_poll(&l->host, now_ms);
    if (r < 0) {
        return r;
    }
    return decode_data(l->pending, l->reply, (size_t)r, reply);
}
