/*
 * Private to src/: where a field lies in a frame of a given length. One
 * packet (AXIS_SETTING) has a second, one byte shorter layout in which the
 * fields flagged TASE_FIELD_SHIFT sit one byte earlier (see
 * tase_field_offset() in tase/schema.h). The codec and the gimbal role decide the
 * layout once per packet and then place each field with no call; the
 * "do not change" bits of a field are read the same way, so that the
 * receive path (dispatch -> decode) calls no schema function per field
 * and its stack stays one frame deep.
 */
#ifndef TASE_SCHEMA_LAYOUT_H
#define TASE_SCHEMA_LAYOUT_H

#include "tase/schema.h"

/* True when `len` data bytes are packet p's short layout. The field flag
 * alone (a corrupted descriptor) never moves a field: the packet must be
 * flagged for it too. */
static inline bool tase_layout_is_short(const tase_packet_desc_t *p, size_t len)
{
    return (p->flags & TASE_LEN_SHORT) != 0u && len + 1u == p->len;
}

/* The byte offset of field f in the layout chosen above. */
static inline size_t tase_layout_offset(const tase_field_t *f, bool short_layout)
{
    if (short_layout && (f->fmt & TASE_FIELD_SHIFT) != 0u && f->offset > 0u) {
        return (size_t)f->offset - 1u;
    }
    return f->offset;
}

/* The wire bits of field f's "do not change" value (tase_field_keep():
 * all ones of its width, zero, or its top bit; fields with one are at most
 * 4 bytes wide, checked at build time in tase_schema.c). False when the
 * field has none. */
static inline bool tase_layout_keep_bits(const tase_field_t *f, uint32_t *bits)
{
    unsigned w = TASE_FIELD_WIDTH(f);
    uint32_t ones = w >= 4u ? 0xFFFFFFFFu : ((uint32_t)1u << (8u * w)) - 1u;
    switch (TASE_FIELD_KEEP(f)) {
    case TASE_FIELD_KEEP_ONES: *bits = ones; return true;
    case TASE_FIELD_KEEP_ZERO: *bits = 0u; return true;
    case TASE_FIELD_KEEP_MSB: *bits = ones ^ (ones >> 1); return true; /* top bit */
    default: return false;
    }
}

#endif /* TASE_SCHEMA_LAYOUT_H */
