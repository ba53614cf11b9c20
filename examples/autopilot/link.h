/*
 * link.h - the autopilot's link to the gimbal: the library's host role
 * (tase/host.h) on one port, with every received frame that is not the
 * answer to a pending request going through the library's dispatcher
 * (tase/dispatch.h) to typed handlers. The mission sends and requests
 * typed packets on link->host directly (tase_host_send_msg(),
 * tase_host_request_msg_start(), tase_host_poll()).
 *
 * Not reentrant; call from the main loop only.
 */
#ifndef AUTOPILOT_LINK_H
#define AUTOPILOT_LINK_H

#include "tase/dispatch.h"
#include "tase/host.h"

typedef struct {
    tase_host_t host;         /* library: requests, retries, receiver */
    tase_dispatch_t dispatch; /* library: typed handlers (host's on_frame) */
} link_t;

/* Set up the host role on `port` with the dispatcher as its frame
 * callback: handlers (TASE_PKT_COUNT entries, ROM), on_other for frames
 * without a handler, on_error for wrong lengths, all called with `user`.
 * The dispatcher counts into the host receiver's statistics
 * (l->host.rx.stats). Returns TASE_OK or the library's error. */
int link_init(link_t *l, const tase_port_t *port, const tase_packet_handler_t *handlers,
              tase_rx_handler_t on_other, tase_dispatch_error_t on_error, void *user);

/* Feed what the port has received (without waiting) to the host role:
 * a reply completes the pending request, everything else is dispatched.
 * Reads at most `max_reads` chunks so that the main loop keeps its pace.
 * Returns the bytes fed (>= 0) or a negative library error. */
int link_service(link_t *l, unsigned max_reads);

#endif /* AUTOPILOT_LINK_H */
