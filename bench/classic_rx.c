/* The floor references of the receiver benchmark: see classic_rx.h. */
#include "classic_rx.h"

enum { C_SYNC1, C_SYNC2, C_SYNC3, C_SIZE, C_BODY, C_CHECK1, C_CHECK2 };

void classic_rx_init(classic_rx_t *p)
{
    p->frames = 0u;
    p->sum = 0u;
    p->idx = 0u;
    p->state = C_SYNC1;
    p->size = 0u;
    p->check_hi = 0u;
}

int classic_rx_push(classic_rx_t *p, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    switch (p->state) {
    case C_SYNC1:
        if (b == TASE_SYNC1) {
            p->state = C_SYNC2;
        }
        return 0;
    case C_SYNC2:
        p->state = (b == TASE_SYNC2) ? C_SYNC3 : (b == TASE_SYNC1) ? C_SYNC2 : C_SYNC1;
        return 0;
    case C_SYNC3:
        p->state = (b == TASE_SYNC3) ? C_SIZE : (b == TASE_SYNC1) ? C_SYNC2 : C_SYNC1;
        return 0;
    case C_SIZE:
        if (b < 2u) {
            p->state = (b == TASE_SYNC1) ? C_SYNC2 : C_SYNC1;
            return 0;
        }
        p->size = b;
        p->sum = (uint16_t)(TASE_SYNC1 + TASE_SYNC2 + TASE_SYNC3 + b);
        p->idx = 0u;
        p->state = C_BODY;
        return 0;
    case C_BODY:
        p->body[p->idx++] = b;
        p->sum = (uint16_t)(p->sum + b);
        if (p->idx == p->size) {
            p->state = C_CHECK1;
        }
        return 0;
    case C_CHECK1:
        p->check_hi = b;
        p->state = C_CHECK2;
        return 0;
    default:
        p->state = C_SYNC1;
        if ((uint16_t)(((uint16_t)p->check_hi << 8) | b) != p->sum) {
            return 0;
        }
        p->frames++;
        if (on_frame != NULL) {
            tase_frame_t f;
            f.offset = 0u; /* not kept: see classic_rx.h */
            f.group = p->body[0];
            f.type = p->body[1];
            f.len = (uint8_t)(p->size - 2u);
            f.data = &p->body[2];
            on_frame(user, &f);
        }
        return 1;
    }
}

void store_sum_push(store_sum_t *s, uint8_t b)
{
    s->buf[s->len & 0xFFu] = b;
    s->len++;
    s->sum = (uint16_t)(s->sum + b);
}
