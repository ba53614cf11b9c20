/*
 * Shared by tests/test_codec.c and tests/avr/avr_core.c: the data bytes of
 * a packet with every field set by a pattern, and a struct member read
 * back as raw bits, for the round trips of every packet.
 */
#ifndef TASE_TEST_PACKET_FILL_H
#define TASE_TEST_PACKET_FILL_H

#include <string.h>

#include "tase/schema.h"

/* Fill the data bytes of packet p: every field's bytes from `mode` (0 all
 * ones, 1 signed minimum, 2 signed maximum, 3 zero, otherwise
 * random_byte()), reserved bytes zero. */
static void packet_fill_fields(const tase_packet_desc_t *p, uint8_t *data, int mode,
                               uint8_t (*random_byte)(void))
{
    size_t k;
    unsigned b;
    memset(data, 0, p->len);
    for (k = 0; k < p->nfields; k++) {
        const tase_field_t *f = tase_schema_field(p, k);
        unsigned w = TASE_FIELD_WIDTH(f);
        for (b = 0; b < w; b++) {
            uint8_t v;
            switch (mode) {
            case 0: v = 0xFFu; break;                   /* -1, 0xFFFF, 0xFFFFFFFF */
            case 1: v = b == 0u ? 0x80u : 0x00u; break; /* INT16_MIN, INT32_MIN */
            case 2: v = b == 0u ? 0x7Fu : 0xFFu; break; /* INT16_MAX, INT32_MAX */
            case 3: v = 0x00u; break;
            default: v = random_byte(); break;
            }
            data[f->offset + b] = v;
        }
    }
}

/* The value of the struct member of width w (1, 2, 4 or 8 bytes) at p,
 * as unsigned bits. */
static uint64_t packet_member_bits(const uint8_t *p, unsigned w)
{
    uint8_t b;
    uint16_t h;
    uint32_t x;
    uint64_t q;
    switch (w) {
    case 1: memcpy(&b, p, 1); return b;
    case 2: memcpy(&h, p, 2); return h;
    case 4: memcpy(&x, p, 4); return x;
    default: memcpy(&q, p, 8); return q;
    }
}

#endif /* TASE_TEST_PACKET_FILL_H */
