/*
 * link.h - the autopilot's link to the gimbal: the library's host role
 * (tase/host.h) on one port, with every received frame that is not the
 * answer to a pending request going through the library's dispatcher
 * (tase/dispatch.h) to typed handlers.
 *
 * Every call the mission makes into the library's roles goes through these
 * few functions, and they speak typed packets only (tase/codec.h structs,
 * TASE_ID_* identifiers): no payload bytes, frames or field packing
 * outside the library.
 *
 * Not reentrant; call from the main loop only.
 */
#ifndef AUTOPILOT_LINK_H
#define AUTOPILOT_LINK_H

#include "tase/dispatch.h"
#include "tase/host.h"

#define LINK_TIMEOUT_MS 300u /* per attempt of a request */
#define LINK_RETRIES 3u      /* re-sends after a timeout */

typedef struct {
    tase_host_t host;         /* library: requests, retries, receiver */
    tase_dispatch_t dispatch; /* library: typed handlers (host's on_frame) */
    uint16_t pending;         /* TASE_ID_* of the request in flight */
    uint8_t reply[TASE_DATA_MAX];
} link_t;

/* Set up the host role on `port` with the dispatcher as its frame
 * callback: handlers (TASE_PKT_COUNT entries, ROM), on_other for frames
 * without a handler, on_error for wrong lengths, all called with `user`.
 * The dispatcher counts into the host receiver's statistics
 * (l->host.rx.stats). Returns TASE_OK or the library's error. */
int link_init(link_t *l, const tase_port_t *port, const tase_packet_handler_t *handlers,
              tase_rx_handler_t on_other, tase_dispatch_error_t on_error, void *user);

/* Feed what the port has received (without waiting) to the host role:
 * replies complete the pending request, everything else is dispatched.
 * Reads at most `max_reads` chunks so that the main loop keeps its pace.
 * Returns the bytes fed (>= 0) or a negative library error. */
int link_service(link_t *l, unsigned max_reads);

/* Send packet `id` (a command or host data) from its typed struct. Returns
 * the frame length or a negative library error. */
int link_send(link_t *l, uint16_t id, const void *msg);

/* Start a request: packet `id` from *msg (a setting or a command whose
 * echo confirms it), or a zero-length query when msg is NULL. Timeout
 * LINK_TIMEOUT_MS per attempt, LINK_RETRIES re-sends. Returns TASE_OK or
 * a negative library error (TASE_EBUSY: one is pending). */
int link_request(link_t *l, uint16_t id, const void *msg, uint32_t now_ms);

/* Drive the pending request. Returns TASE_EAGAIN while waiting; the
 * reply's data length (>= 0) once answered, with the reply decoded into
 * *reply (the typed struct of the request's packet); or a negative
 * library error (TASE_ETIMEOUT after the last attempt, or the decoder's
 * error for a reply of the wrong length). */
int link_poll(link_t *l, uint32_t now_ms, void *reply);

#endif /* AUTOPILOT_LINK_H */
