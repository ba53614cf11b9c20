/*
 * The schema table. Descriptors are generated from the X-macro list in
 * tase_schema_def.h so that each field is written once; the names are
 * generated from the same list in tase_schema_names.c.
 */
#include "tase/schema.h"

#include "tase/codec.h"
#include "tase_schema_layout.h"

/* Field index bookkeeping: FIRST_x / END_x are the flat field indices of
 * packet x. Each marker rewinds the counter so it takes no slot. */
#define P(N, g, t, fl, l, sz) FIRST_##N, FIRST_##N##_ = FIRST_##N - 1,
#define F(T, m, o, w, s, k) FLD_##T##_##m,
#define E(N) END_##N, END_##N##_ = END_##N - 1,
/* The rewinding markers give the next constant its marker's value on
 * purpose: that is how a marker takes no slot. */
/* cppcheck-suppress misra-c2012-8.12 */
enum {
#include "tase_schema_def.h"
    FIELD_TOTAL
};
#undef P
#undef F
#undef E

/* Packet positions in the list, to check the enumeration in schema.h. */
#define P(N, g, t, fl, l, sz) PKTIDX_##N,
#define F(T, m, o, w, s, k)
#define E(N)
enum {
#include "tase_schema_def.h"
    PKTIDX_COUNT
};
#undef P
#undef F

#define FMT_U 0u
#define FMT_S TASE_FIELD_SIGNED
/* The list's names for a field's "do not change" value. */
#define ONES TASE_FIELD_KEEP_ONES
#define ZERO TASE_FIELD_KEEP_ZERO
#define MSB TASE_FIELD_KEEP_MSB
#define SHIFT TASE_FIELD_SHIFT

/* C99 has no _Static_assert: a negative array size fails the build.
 * Every member must be as wide as its field, a field with a "do not
 * change" value at most 4 bytes wide (unsigned if MSB: tase_field_keep()
 * relies on both), and the enumeration in schema.h must follow the list. */
#define P(N, g, t, fl, l, sz)                                                                      \
    typedef char chk_idx_##N[((int)TASE_PKT_##N == (int)PKTIDX_##N) ? 1 : -1];
/* T is a type and m a member name: neither can be parenthesised. */
/* cppcheck-suppress misra-c2012-20.7 */
#define F(T, m, o, w, s, k)                                                                        \
    typedef char chk_##T##_##m[(sizeof(((T *)0)->m) == (w) && offsetof(T, m) < 256u &&             \
                                (((k)&TASE_FIELD_KEEP_MASK) == 0u || (w) <= 4) &&                  \
                                (((k)&TASE_FIELD_KEEP_MASK) != MSB || FMT_##s == 0u))              \
                                   ? 1                                                             \
                                   : -1];
#include "tase_schema_def.h"
#undef P
#undef F
#undef E
typedef char chk_count
    [((int)PKTIDX_COUNT == (int)TASE_PKT_COUNT && TASE_PKT_COUNT == TASE_PACKET_COUNT) ? 1 : -1];
typedef char chk_fields[(FIELD_TOTAL < 256) ? 1 : -1];

/* Generated from the list like its siblings here, so it stays at file
 * scope although only tase_schema_field() reads it. */
/* cppcheck-suppress misra-c2012-8.9 */
static const tase_field_t fields[FIELD_TOTAL] = {
#define P(N, g, t, fl, l, sz)
#define F(T, m, o, w, s, k) {o, offsetof(T, m), (w) | FMT_##s | (k)},
#define E(N)
#include "tase_schema_def.h"
#undef P
#undef F
#undef E
};
#undef ONES
#undef ZERO
#undef MSB
#undef SHIFT

static const tase_packet_desc_t packets[TASE_PKT_COUNT] = {
#define P(N, g, t, fl, l, sz)                                                                      \
    {TASE_ID(g, t), l, fl, FIRST_##N, END_##N - FIRST_##N, sz, TASE_PKT_##N},
#define F(T, m, o, w, s, k)
#define E(N)
#include "tase_schema_def.h"
#undef P
#undef F
#undef E
};

#define NSLOTS 15u

static unsigned group_slot(uint8_t group)
{
    switch (group) {
    case TASE_GROUP_COMMAND: return 0u;
    case TASE_GROUP_DYNAMICS: return 1u;
    case TASE_GROUP_POSITION: return 2u;
    case TASE_GROUP_SETUP: return 3u;
    default: return 4u;
    }
}

static unsigned type_slot(uint8_t type)
{
    if (type < 0x08u) {
        return type;
    }
    if (type == 0x10u) {
        return 8u;
    }
    if (type >= 0x40u && type <= 0x43u) {
        return 9u + (type - 0x40u);
    }
    if (type == 0x80u || type == 0x81u) {
        return 13u + (type - 0x80u);
    }
    return NSLOTS;
}

const tase_packet_desc_t *tase_schema_find(uint8_t group, uint8_t type)
{
    /* Direct index: the spec uses only 15 distinct type numbers across its
     * four groups, so (group slot, type slot) -> packet index + 1 fits in 60
     * bytes of ROM, against 1 KB for full 256-entry rows. */
    static const uint8_t by_slot[4][NSLOTS] = {
        /* types: 00..07, 10, 40..43, 80, 81 */
        {0, 0, 0, 0, 0, 0, 0, 0, 0, TASE_PKT_GYRO_ZERO_CMD + 1, TASE_PKT_CAMERA_CMD + 1,
         TASE_PKT_CAMERA_PASS + 1, TASE_PKT_RETRACT_DEPLOY_CMD + 1, TASE_PKT_GIMBAL_CMD + 1,
         TASE_PKT_LEGACY_CAMERA_CMD + 1},
        {0, 0, 0, 0, 0, 0, 0, 0, TASE_PKT_GIMBAL_ANGLE + 1, TASE_PKT_GIMBAL_RATE + 1,
         TASE_PKT_HOST_SENSOR + 1, TASE_PKT_HOST_ATTITUDE + 1, 0, 0, 0},
        {0, 0, 0, 0, 0, 0, 0, 0, TASE_PKT_HOST_GPS_DATA + 1, TASE_PKT_SPOI_CMD + 1,
         TASE_PKT_GEOREFERENCE_DATA + 1, 0, 0, 0, 0},
        {TASE_PKT_PACKET_RATE + 1, TASE_PKT_SENSOR_FILTER + 1, TASE_PKT_AXIS_SETTING + 1,
         TASE_PKT_SYSTEM_VERSION + 1, TASE_PKT_NAV_SOURCE + 1, TASE_PKT_CAMERA_TYPE + 1,
         TASE_PKT_GPS_LEVER_ARM + 1, TASE_PKT_CAMERA_ALIGN + 1, 0, 0, 0, 0, 0, 0, 0},
    };
    unsigned g = group_slot(group);
    unsigned t = type_slot(type);
    unsigned k;
    if (g >= 4u || t >= NSLOTS) {
        return NULL;
    }
    k = by_slot[g][t];
    return k == 0u ? NULL : &packets[k - 1u];
}

const tase_packet_desc_t *tase_schema_at(size_t i)
{
    return i < TASE_PKT_COUNT ? &packets[i] : NULL;
}

const tase_field_t *tase_schema_field(const tase_packet_desc_t *p, size_t i)
{
    /* The second bound only matters for a descriptor that is not one of
     * the table's (a corrupted copy): it keeps the index inside fields[]. */
    if (p == NULL || i >= p->nfields || (size_t)p->first_field + i >= (size_t)FIELD_TOTAL) {
        return NULL;
    }
    return &fields[p->first_field + i];
}

bool tase_schema_length_ok(const tase_packet_desc_t *p, size_t len)
{
    if (p == NULL) {
        return false;
    }
    if (len == p->len) {
        return true;
    }
    if (len == 0u) {
        return (p->flags & TASE_LEN_QUERY) != 0u;
    }
    if (len == 1u) {
        return (p->flags & TASE_LEN_SHORT1) != 0u;
    }
    if (len + 1u == p->len && (p->flags & TASE_LEN_SHORT) != 0u) {
        return true;
    }
    return (p->flags & TASE_LEN_TAIL) != 0u && len > p->len && len <= TASE_DATA_MAX;
}

bool tase_schema_is_query(const tase_packet_desc_t *p, size_t len)
{
    return p != NULL && len == 0u && (p->flags & TASE_LEN_QUERY) != 0u;
}

int tase_field_offset(const tase_packet_desc_t *p, size_t i, size_t len)
{
    const tase_field_t *f = tase_schema_field(p, i);
    if (f == NULL) {
        return TASE_EARG;
    }
    return (int)tase_layout_offset(f, tase_layout_is_short(p, len));
}

int tase_field_get(const tase_packet_desc_t *p, size_t i, const uint8_t *data, size_t len,
                   int64_t *value)
{
    const tase_field_t *f = tase_schema_field(p, i);
    size_t at;
    unsigned w;
    unsigned k;
    uint64_t v = 0u;
    if (f == NULL || value == NULL || (data == NULL && len > 0u)) {
        return TASE_EARG;
    }
    w = TASE_FIELD_WIDTH(f);
    at = (size_t)tase_field_offset(p, i, len); /* >= 0: f is valid */
    /* data is NULL only with len 0, where no field fits. */
    if (data == NULL || at + w > len) {
        return TASE_ETRUNC;
    }
    for (k = 0; k < w; k++) {
        v = (v << 8) | data[at + k];
    }
    /* Big-endian: the sign bit is the top bit of the first byte. */
    if (TASE_FIELD_IS_SIGNED(f) && (data[at] & 0x80u) != 0u) {
        /* Two's complement by arithmetic, without an implementation-
         * defined conversion of an out-of-range unsigned value. */
        uint64_t mag = ~v;
        if (w < 8u) {
            unsigned bits = 8u * w;
            uint64_t mask = ((uint64_t)1u << bits) - 1u;
            mag &= mask;
        }
        *value = -(int64_t)mag - 1;
    } else {
        *value = (int64_t)v;
    }
    return TASE_OK;
}

/* All bits of an unsigned field of w (1..4, checked at build time) bytes. */
int tase_field_keep(const tase_packet_desc_t *p, size_t i, int64_t *value)
{
    const tase_field_t *f = tase_schema_field(p, i);
    uint32_t bits;
    if (f == NULL || value == NULL) {
        return TASE_EARG;
    }
    if (!tase_layout_keep_bits(f, &bits)) {
        return TASE_EUNKNOWN;
    }
    /* all ones of a signed field is -1 (HFOV "do not change") */
    *value = (TASE_FIELD_KEEP(f) == TASE_FIELD_KEEP_ONES && TASE_FIELD_IS_SIGNED(f))
                 ? -1
                 : (int64_t)bits;
    return TASE_OK;
}

bool tase_field_is_keep(const tase_packet_desc_t *p, size_t i, int64_t value)
{
    int64_t keep;
    if (tase_field_keep(p, i, &keep) != TASE_OK) {
        return false;
    }
    /* MSB (unsigned fields only): any value of the field with its top bit
     * set, i.e. from the keep value up to all ones. */
    if (TASE_FIELD_KEEP(tase_schema_field(p, i)) == TASE_FIELD_KEEP_MSB) {
        return value >= keep && value <= 2 * keep - 1;
    }
    return value == keep;
}
