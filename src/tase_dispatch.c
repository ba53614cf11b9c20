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

/* Where frame goes (the contract's order): looks its packet up once, then
 * counts an unknown packet or a wrong length, and for a typed handler
 * decodes the frame into d->msg with the walk of that lookup. Returns the
 * handler (NULL: the default handler), or sets *refused for a wrong
 * length. Not inlined, so that the walk is off the stack while the
 * application's handler runs. */
TASE_NOINLINE_ static tase_packet_handler_t route(tase_dispatch_t *d, const tase_frame_t *frame,
                                                  void **msg, bool *refused)
{
    tase_field_iter_t it;
    const tase_packet_desc_t *p = tase_field_iter_find(&it, frame->group, frame->type, frame->len);
    tase_packet_handler_t h = NULL;
    *refused = false;
    if (p == NULL) {
        if (d->stats != NULL) {
            d->stats->unknown++;
        }
    } else if (!it.accepted) {
        if (d->stats != NULL) {
            d->stats->bad_length++;
        }
        *refused = true;
    } else if (d->handlers != NULL) {
        h = d->handlers[p->index];
    } else {
        /* no handler table: everything goes to on_default */
    }
    if (h != NULL) {
        /* Cannot fail: the packet is known, its length accepted and its
         * data there (tase_dispatch_frame() checked). */
        *msg = p->size != 0u ? &d->msg : NULL;
        (void)tase_packet_decode_iter(&it, frame->data, *msg);
    }
    return h;
}

void tase_dispatch_frame(void *dispatcher, const tase_frame_t *frame)
{
    tase_dispatch_t *d = dispatcher;
    tase_packet_handler_t h;
    void *msg = NULL;
    bool refused;
    if (d == NULL || frame == NULL || (frame->data == NULL && frame->len > 0u)) {
        return; /* no frame the receiver delivers: nothing to decode */
    }
    h = route(d, frame, &msg, &refused);
    if (refused) {
        if (d->on_error != NULL) {
            d->on_error(d->user, frame, TASE_ELENGTH);
        }
    } else if (h == NULL) {
        if (d->on_default != NULL) {
            d->on_default(d->user, frame);
        }
    } else {
        h(d->user, frame, msg);
    }
}
