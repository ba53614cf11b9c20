/*
 * Packet and field names, generated from the same list as the schema.
 * A separate translation unit so firmware that never asks for a name does
 * not link the strings.
 */
#include <string.h>

#include "tase/codec.h"
#include "tase/schema.h"

static const char *const packet_names[TASE_PKT_COUNT] = {
#define P(N, g, t, fl, l, sz) #N,
#define F(T, m, o, w, s, k)
#define E(N)
#include "tase_schema_def.h"
#undef P
#undef F
#undef E
};

/* Generated from the list like packet_names, so it stays at file scope
 * although only tase_schema_field_name() reads it. */
/* cppcheck-suppress misra-c2012-8.9 */
static const char *const field_names[] = {
#define P(N, g, t, fl, l, sz)
#define F(T, m, o, w, s, k) #m,
#define E(N)
#include "tase_schema_def.h"
#undef P
#undef F
#undef E
};

const char *tase_schema_packet_name(const tase_packet_desc_t *p)
{
    return p != NULL && p->index < TASE_PKT_COUNT ? packet_names[p->index] : NULL;
}

const char *tase_schema_field_name(const tase_packet_desc_t *p, size_t i)
{
    size_t k;
    if (p == NULL || i >= p->nfields) {
        return NULL;
    }
    k = (size_t)p->first_field + i;
    return k < sizeof(field_names) / sizeof(field_names[0]) ? field_names[k] : NULL;
}

const tase_packet_desc_t *tase_schema_find_name(const char *name)
{
    size_t i;
    if (name == NULL) {
        return NULL;
    }
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        if (strcmp(packet_names[i], name) == 0) {
            return tase_schema_at(i);
        }
    }
    return NULL;
}

int tase_schema_field_index(const tase_packet_desc_t *p, const char *name)
{
    size_t i;
    if (p == NULL || name == NULL) {
        return TASE_EARG;
    }
    for (i = 0; i < p->nfields; i++) {
        /* NULL only for a corrupted descriptor whose fields run off the
         * table: never compared. */
        const char *fname = tase_schema_field_name(p, i);
        if (fname != NULL && strcmp(fname, name) == 0) {
            return (int)i;
        }
    }
    return TASE_EUNKNOWN;
}
