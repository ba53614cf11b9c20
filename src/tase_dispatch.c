/* Frame dispatch through the schema; the order of the checks is the
 * contract described in include/tase/dispatch.h. */
#include "tase/dispatch.h"

#include <string.h>

int tase_dispatch_init(tase_dispatch_t *d, const tase_packet_handler_t *handlers,
                       tase_rx_handler_t on_default, tase_dispatch_error_t on_error, void *user,
                       tase_rx_stats_t *stats)
{
    if (d == NULL) {
        return TASE_EARG;
    }
    (void)memset(d, 0, sizeof *d); /* the decode buffer too: no undefined bytes */
    d->handlers = handlers;
    d->on_default = on_default;
    d->on_error = on_error;
    d->user = user;
    d->stats = stats;
    return TASE_OK;
}

void tase_dispatch_frame(void *dispatcher, const tase_frame_t *frame)
{
    tase_dispatch_t *d = dispatcher;
    tase_field_iter_t it;
    const tase_packet_desc_t *p;
    tase_packet_handler_t h = NULL;
    void *msg;
    if (d == NULL || frame == NULL) {
        return;
    }
    /* The one call into the schema: the packet found and the walk bound. */
    p = tase_field_iter_find(&it, frame->group, frame->type, frame->len);
    if (p == NULL) {
        if (d->stats != NULL) {
            d->stats->unknown++;
        }
    } else if (!it.accepted) {
        if (d->stats != NULL) {
            d->stats->bad_length++;
        }
        if (d->on_error != NULL) {
            d->on_error(d->user, frame, TASE_ELENGTH);
        }
        return;
    } else if (d->handlers != NULL) {
        h = d->handlers[p->index];
    } else {
        /* no handler table: everything goes to on_default */
    }
    if (h == NULL) {
        if (d->on_default != NULL) {
            d->on_default(d->user, frame);
        }
        return;
    }
    /* Cannot fail: the packet is known and its length accepted. Decoded
     * with the walk in hand, not looked up a second time. */
    msg = p->size != 0u ? &d->msg : NULL;
    (void)tase_packet_decode_iter(&it, frame->data, msg);
    h(d->user, frame, msg);
}
