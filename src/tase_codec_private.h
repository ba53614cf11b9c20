/*
 * Private to src/: what the codec (tase_codec.c) shares with the frame
 * writer (tase_port_io.c), which sends a typed packet without encoding it
 * into a buffer first. Not part of the API: no header in include/
 * declares these.
 */
#ifndef TASE_CODEC_PRIVATE_H
#define TASE_CODEC_PRIVATE_H

#include <string.h>

#include "tase/codec.h"

/* A member of `w` bytes (1, 2, 4 or 8) at src, as an unsigned value of
 * that width; its own type is not known here, only its width. */
static inline uint64_t tase_member_load(const void *src, unsigned w)
{
    uint8_t b;
    uint16_t h;
    uint32_t x;
    uint64_t q;
    switch (w) {
    case 1: (void)memcpy(&b, src, 1); return b;
    case 2: (void)memcpy(&h, src, 2); return h;
    case 4: (void)memcpy(&x, src, 4); return x;
    default: (void)memcpy(&q, src, 8); return q;
    }
}

/* The data of a typed packet in wire order, one byte at a time: the
 * fields of its table layout big-endian, the reserved bytes zero; then,
 * for CAMERA_PASS, the caller's camera bytes (not produced here). What a
 * send in progress needs in place of an encoded packet (12 bytes instead
 * of up to 63). At the table length every field lies within the data at
 * its table offset; every field of the schema is at most 4 bytes wide
 * (tase_schema.c checks it at build time) and the fields are in offset
 * order without overlap (tests/test_schema.c checks both). */
typedef struct {
    const tase_field_t *field; /* the first field not yet passed */
    const void *msg;           /* the typed struct */
    uint8_t nfields;           /* fields from `field` on */
    uint8_t fixed;             /* the data bytes produced here; a tail follows */
} tase_wire_t;

/* Begin the data of packet `id` from msg (NULL: the zero-length form) with
 * the checks of tase_packet_encode_data(), in codec.h's order. Returns the
 * data length (w->fixed, plus CAMERA_PASS's camera bytes), or
 * TASE_EUNKNOWN / TASE_ELENGTH / TASE_EARG / TASE_ETOOLONG as the codec's
 * encoders do. */
int tase_wire_begin(tase_wire_t *w, uint16_t id, const void *msg);

/* Data byte d, for d = 0, 1, ... w->fixed - 1 in turn after
 * tase_wire_begin(). O(1) amortised: each field is passed once. */
static inline uint8_t tase_wire_byte(tase_wire_t *w, size_t d)
{
    const tase_field_t *f = w->field;
    unsigned width;
    while (w->nfields > 0u && (size_t)f->offset + TASE_FIELD_WIDTH(f) <= d) {
        f++;
        w->nfields--;
    }
    w->field = f;
    if (w->nfields == 0u || d < f->offset) {
        return 0u; /* a reserved byte */
    }
    width = TASE_FIELD_WIDTH(f);
    return (uint8_t)((uint32_t)tase_member_load((const uint8_t *)w->msg + f->member, width) >>
                     (8u * (f->offset + width - 1u - d)));
}

#endif /* TASE_CODEC_PRIVATE_H */
