/*
 * Private to src/: where a field lies in a frame of a given length, by
 * the rules of the field iterator (tase/schema.h, TWO LAYOUTS), for code
 * that places one field in two layouts at once (the gimbal role's setup
 * copy, src/tase_gimbal.c). A walk over a packet uses the iterator
 * (tase_field_iter_t) instead, which applies the same rules.
 */
#ifndef TASE_SCHEMA_LAYOUT_H
#define TASE_SCHEMA_LAYOUT_H

#include "tase/schema.h"

/* True when `len` data bytes are packet p's short layout. */
static inline bool tase_layout_is_short(const tase_packet_desc_t *p, size_t len)
{
    return tase_schema_short_(p, len);
}

/* The byte offset of field f in the layout chosen above. */
static inline size_t tase_layout_offset(const tase_field_t *f, bool short_layout)
{
    return tase_field_at_(f, short_layout);
}

#endif /* TASE_SCHEMA_LAYOUT_H */
