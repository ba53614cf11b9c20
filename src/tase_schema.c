/*
 * The schema table. Descriptors are generated from the X-macro list in
 * tase_schema_def.h so that each field is written once; the names are
 * generated from the same list in tase_schema_names.c.
 */
#include "tase/schema.h"

#include "tase/codec.h"
#include "tase/flags.h"

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
 * Every member must be as wide as its field, every field at most 4 bytes
 * wide (the frame writer's byte producer, tase_codec_private.h, and
 * tase_field_keep() rely on it), a field whose "do not change" value is
 * MSB unsigned, and the enumeration in schema.h must follow the list. */
#define P(N, g, t, fl, l, sz)                                                                      \
    typedef char chk_idx_##N[((int)TASE_PKT_##N == (int)PKTIDX_##N) ? 1 : -1];
/* T is a type and m a member name: neither can be parenthesised. */
/* cppcheck-suppress misra-c2012-20.7 */
#define F(T, m, o, w, s, k)                                                                        \
    typedef char chk_##T##_##m[(sizeof(((T *)0)->m) == (w) && offsetof(T, m) < 256u && (w) <= 4 && \
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
 * scope although only bind() reads it. */
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

/* tase_schema_length_ok() for a descriptor that is not NULL. */
static bool length_ok(const tase_packet_desc_t *p, size_t len)
{
    if (len == p->len) {
        return true;
    }
    if (len == 0u) {
        return (p->flags & TASE_LEN_QUERY) != 0u;
    }
    if (len == 1u) {
        return (p->flags & TASE_LEN_SHORT1) != 0u;
    }
    if (tase_schema_short_(p, len)) {
        return true;
    }
    return (p->flags & TASE_LEN_TAIL) != 0u && len > p->len && len <= TASE_DATA_MAX;
}

bool tase_schema_length_ok(const tase_packet_desc_t *p, size_t len)
{
    return p != NULL && length_ok(p, len);
}

bool tase_schema_is_query(const tase_packet_desc_t *p, size_t len)
{
    return p != NULL && len == 0u && (p->flags & TASE_LEN_QUERY) != 0u;
}

uint8_t tase_schema_reserved_flags(const tase_packet_desc_t *p)
{
    uint8_t mask = 0u;
    if (p != NULL) {
        switch (p->id) {
        case TASE_ID_CAMERA_CMD: mask = TASE_CAMERA_FLAGS_RESERVED; break;
        case TASE_ID_HOST_SENSOR: mask = TASE_HOST_SENSOR_FLAGS_RESERVED; break;
        case TASE_ID_HOST_ATTITUDE: mask = TASE_HOST_ATT_FLAGS_RESERVED; break;
        case TASE_ID_SPOI_CMD: mask = TASE_SPOI_FLAGS_RESERVED; break;
        default: break;
        }
    }
    return mask;
}

bool tase_field_iter_begin(tase_field_iter_t *it, size_t len)
{
    const tase_packet_desc_t *p = it->packet;
    size_t n = len;
    it->field = NULL;
    it->next = 0u;
    if (n > TASE_DATA_MAX) {
        n = (n == TASE_FIELD_ITER_TABLE_LEN && p != NULL) ? p->len : TASE_DATA_MAX + 1u;
    }
    it->len = (uint8_t)n; /* <= TASE_DATA_MAX + 1 */
    if (p == NULL) {
        it->accepted = false;
        it->short_layout = false;
        return false;
    }
    it->accepted = length_ok(p, it->len);
    it->short_layout = tase_schema_short_(p, it->len);
    return it->accepted;
}

/* Bind it to p, a descriptor of the table or NULL, and begin a walk. */
static void bind(tase_field_iter_t *it, const tase_packet_desc_t *p, size_t len)
{
    it->packet = p;
    it->count = (p != NULL) ? p->nfields : 0u;
    it->fields = (p != NULL) ? &fields[p->first_field] : NULL;
    (void)tase_field_iter_begin(it, len);
}

const tase_packet_desc_t *tase_field_iter_find(tase_field_iter_t *it, uint8_t group, uint8_t type,
                                               size_t len)
{
    const tase_packet_desc_t *p = tase_schema_find(group, type);
    if (it == NULL) {
        return NULL;
    }
    bind(it, p, len);
    return p;
}

int tase_field_iter_init(tase_field_iter_t *it, const tase_packet_desc_t *p, size_t len)
{
    if (it == NULL) {
        return TASE_EARG;
    }
    if (p == NULL) {
        bind(it, NULL, len);
        return TASE_EUNKNOWN;
    }
    /* Only the table's own descriptors: a copy's first_field and nfields
     * could index past the field table. */
    if (tase_schema_at(p->index) != p) {
        bind(it, NULL, len);
        return TASE_EARG;
    }
    bind(it, p, len);
    return TASE_OK;
}

/* The by-index functions: field i of p in a walk of len data bytes. */
static bool seek(tase_field_iter_t *it, const tase_packet_desc_t *p, size_t i, size_t len)
{
    return tase_field_iter_init(it, p, len) == TASE_OK && tase_field_iter_seek(it, i);
}

const tase_field_t *tase_schema_field(const tase_packet_desc_t *p, size_t i)
{
    tase_field_iter_t it;
    return seek(&it, p, i, 0u) ? it.field : NULL;
}

int tase_field_offset(const tase_packet_desc_t *p, size_t i, size_t len)
{
    tase_field_iter_t it;
    return seek(&it, p, i, len) ? (int)it.offset : TASE_EARG;
}

int tase_field_iter_get(const tase_field_iter_t *it, const uint8_t *data, int64_t *value)
{
    uint64_t v;
    if (it == NULL || it->field == NULL || value == NULL || (data == NULL && it->len > 0u)) {
        return TASE_EARG;
    }
    /* data is NULL only with length 0, where no field fits. */
    if (data == NULL || !it->within) {
        return TASE_ETRUNC;
    }
    v = tase_field_iter_bits_(it, data);
    /* Big-endian: the sign bit is the top bit of the first byte. */
    if (TASE_FIELD_IS_SIGNED(it->field) && (data[it->offset] & 0x80u) != 0u) {
        /* Two's complement by arithmetic, without an implementation-
         * defined conversion of an out-of-range unsigned value. */
        uint64_t mag = ~v;
        if (it->width < 8u) {
            unsigned bits = 8u * it->width;
            uint64_t mask = ((uint64_t)1u << bits) - 1u;
            mag &= mask;
        }
        *value = -(int64_t)mag - 1;
    } else {
        *value = (int64_t)v;
    }
    return TASE_OK;
}

int tase_field_get(const tase_packet_desc_t *p, size_t i, const uint8_t *data, size_t len,
                   int64_t *value)
{
    tase_field_iter_t it;
    if (!seek(&it, p, i, len) || value == NULL || (data == NULL && len > 0u)) {
        return TASE_EARG;
    }
    return tase_field_iter_get(&it, data, value);
}

/* The keep value of the field `it` is on (TASE_EUNKNOWN: it has none). */
static int keep_value(const tase_field_iter_t *it, int64_t *value)
{
    uint32_t bits;
    if (!tase_field_iter_keep_bits(it, &bits)) {
        return TASE_EUNKNOWN;
    }
    /* all ones of a signed field is -1 (HFOV "do not change") */
    *value = (TASE_FIELD_KEEP(it->field) == TASE_FIELD_KEEP_ONES && TASE_FIELD_IS_SIGNED(it->field))
                 ? -1
                 : (int64_t)bits;
    return TASE_OK;
}

int tase_field_keep(const tase_packet_desc_t *p, size_t i, int64_t *value)
{
    tase_field_iter_t it;
    if (!seek(&it, p, i, 0u) || value == NULL) {
        return TASE_EARG;
    }
    return keep_value(&it, value);
}

bool tase_field_is_keep(const tase_packet_desc_t *p, size_t i, int64_t value)
{
    tase_field_iter_t it;
    int64_t keep;
    if (!seek(&it, p, i, 0u) || keep_value(&it, &keep) != TASE_OK) {
        return false;
    }
    /* MSB (unsigned fields only): any value of the field with its top bit
     * set, i.e. from the keep value up to all ones. */
    if (TASE_FIELD_KEEP(it.field) == TASE_FIELD_KEEP_MSB) {
        return value >= keep && value <= 2 * keep - 1;
    }
    return value == keep;
}
