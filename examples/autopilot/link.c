/* The autopilot's link to the gimbal; see link.h. */
#include "link.h"

#include <string.h>

int link_init(link_t *l, const tase_port_t *port, const tase_packet_handler_t *handlers,
              tase_rx_handler_t on_other, tase_dispatch_error_t on_error, void *user)
{
    int r;
    memset(l, 0, sizeof(*l));
    r = tase_dispatch_init(&l->dispatch, handlers, on_other, on_error, user, &l->host.rx.stats);
    if (r != TASE_OK) {
        return r;
    }
    return tase_host_init(&l->host, port, tase_dispatch_frame, &l->dispatch);
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
