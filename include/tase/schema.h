/*
 * tase/schema.h - the one description of every packet of the spec
 * (section 4): identity, direction, accepted data lengths and fields.
 *
 * The schema is a `static const` table in ROM. It drives the typed codec
 * (tase/codec.h), the dispatcher (tase/dispatch.h) and the JSON output of
 * the tools, so a field is described exactly once.
 *
 * A packet descriptor (tase_packet_desc_t) gives:
 *   - id: TASE_ID(group, type) (tase/ids.h);
 *   - len: the length of the data table in the spec (the fixed 4-byte
 *     header for CAMERA_PASS);
 *   - flags: direction (TASE_DIR_*) and which other lengths are accepted
 *     (TASE_LEN_*), see tase_schema_length_ok();
 *   - the fields, in the order of the spec's table. Rows named "Reserved"
 *     are not fields: they are written as zero and ignored when read.
 *
 * TWO LAYOUTS. Table 22 (AXIS_SETTING) has no row 13: read as printed the
 * packet is 23 bytes with byte 13 reserved, read as a numbering slip it
 * is 22 bytes with every row from 14 on one byte earlier. Both are
 * accepted (docs/PROTOCOL-NOTES.md S2): a packet flagged TASE_LEN_SHORT
 * also takes len - 1 data bytes, and then each field flagged
 * TASE_FIELD_SHIFT sits one byte earlier. The length of the frame selects
 * the layout; the field iterator applies it (a walk is begun for a data
 * length), and the codec, the dispatcher, tase_field_offset(),
 * tase_field_get() and the tools' JSON all go through it.
 *
 * A field descriptor (tase_field_t) gives its byte offset in the data,
 * its width (1, 2, 4 or 8 bytes, big-endian on the wire), its signedness
 * and the offset of the matching member in the packet's typed struct
 * (tase/codec.h), so one generic routine encodes and decodes every packet.
 *
 * WALKING A PACKET. A field iterator (tase_field_iter_t, below) walks the
 * fields of one packet in a frame of a given length with each field's
 * descriptor, offset (the layout applied), width and "do not change" value
 * in hand; the codec's encoders and decoders and the dispatcher walk
 * packets with it, and the by-index functions (tase_schema_field(),
 * tase_field_offset(), tase_field_get(), tase_field_keep(),
 * tase_field_is_keep()) are conveniences built on it.
 *
 * NAMES. Packet names ("GIMBAL_CMD", ...) and field names (the JSON keys
 * "pan", "impulse_time", ...) live in a separate translation unit
 * (src/tase_schema_names.c): firmware that never calls the *_name functions
 * does not link the strings. Field names are a public contract: the
 * snake_case form of the spec's Name column without byte suffixes, equal
 * to the member names of the typed structs. See docs/PROTOCOL-NOTES.md.
 *
 * LOOKUP by (group, type) is O(1): a 60-byte ROM index (4 groups x 15
 * type slots), not a scan of the table.
 *
 * Every function here is reentrant and ISR-safe: they only read ROM (and
 * the caller's iterator).
 */
#ifndef TASE_SCHEMA_H
#define TASE_SCHEMA_H

#include "tase/ids.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Index of each packet in the schema table (0..TASE_PKT_COUNT-1), in the
 * order of the spec. Use it to build a dispatch handler table with
 * designated initialisers: `[TASE_PKT_GIMBAL_CMD] = on_cmd`. */
enum {
    TASE_PKT_GIMBAL_CMD,
    TASE_PKT_GYRO_ZERO_CMD,
    TASE_PKT_CAMERA_CMD,
    TASE_PKT_LEGACY_CAMERA_CMD,
    TASE_PKT_CAMERA_PASS,
    TASE_PKT_RETRACT_DEPLOY_CMD,
    TASE_PKT_GIMBAL_ANGLE,
    TASE_PKT_GIMBAL_RATE,
    TASE_PKT_HOST_SENSOR,
    TASE_PKT_HOST_ATTITUDE,
    TASE_PKT_HOST_GPS_DATA,
    TASE_PKT_SPOI_CMD,
    TASE_PKT_GEOREFERENCE_DATA,
    TASE_PKT_PACKET_RATE,
    TASE_PKT_SENSOR_FILTER,
    TASE_PKT_AXIS_SETTING,
    TASE_PKT_SYSTEM_VERSION,
    TASE_PKT_NAV_SOURCE,
    TASE_PKT_CAMERA_TYPE,
    TASE_PKT_GPS_LEVER_ARM,
    TASE_PKT_CAMERA_ALIGN,
    TASE_PKT_COUNT
};

/* Packet flags: direction as seen from the gimbal ... */
#define TASE_DIR_IN 0x01u   /* to the gimbal (sent by the host) */
#define TASE_DIR_OUT 0x02u  /* from the gimbal */
#define TASE_DIR_BOTH 0x03u /* either way (setup echo, pass-through) */
/* ... and the data lengths accepted besides `len` itself. */
#define TASE_LEN_QUERY 0x04u  /* 0 bytes: query (the setup echo answers) */
#define TASE_LEN_SHORT1 0x08u /* 1 byte: CAMERA_CMD "change camera only" */
#define TASE_LEN_TAIL 0x10u   /* len + 0..(253-len) trailing bytes */
#define TASE_LEN_SHORT 0x20u  /* len - 1: the short layout, see below */

/* Field format byte (LSB numbering here: this is a C value, not a wire
 * byte): width in bytes (1, 2, 4, 8) in bits 0-3, signed in bit 4, and in
 * bits 5-6 the kind of the field's "do not change" value (the spec's value
 * that leaves a setting as it is; read it with tase_field_keep()). */
#define TASE_FIELD_SIGNED 0x10u
#define TASE_FIELD_KEEP_NONE 0x00u /* the field has no such value */
#define TASE_FIELD_KEEP_ONES 0x20u /* all bits set: 0xFF, 0xFFFF (-1 if signed) */
#define TASE_FIELD_KEEP_ZERO 0x40u /* zero */
#define TASE_FIELD_KEEP_MSB 0x60u  /* a flags byte whose MSB means "no change" */
#define TASE_FIELD_KEEP_MASK 0x60u
/* Bit 7: in the packet's short layout (TASE_LEN_SHORT: one data byte
 * fewer than the table, AXIS_SETTING's 22 bytes) the field sits one byte
 * earlier than `offset`. Read offsets through tase_field_offset(). */
#define TASE_FIELD_SHIFT 0x80u
#define TASE_FIELD_WIDTH(f) (TASE_CAST_(unsigned, (f)->fmt) & 0x0Fu)
#define TASE_FIELD_IS_SIGNED(f) ((TASE_CAST_(unsigned, (f)->fmt) & TASE_FIELD_SIGNED) != 0u)
#define TASE_FIELD_KEEP(f) (TASE_CAST_(unsigned, (f)->fmt) & TASE_FIELD_KEEP_MASK)

typedef struct {
    uint8_t offset; /* byte offset in the packet data */
    uint8_t member; /* offsetof() the member in the packet's typed struct */
    uint8_t fmt;    /* width | TASE_FIELD_SIGNED | TASE_FIELD_KEEP_* | _SHIFT */
} tase_field_t;

typedef struct {
    uint16_t id;         /* TASE_ID(group, type) */
    uint8_t len;         /* data length of the spec's table */
    uint8_t flags;       /* TASE_DIR_* | TASE_LEN_* */
    uint8_t first_field; /* private: index of the first field */
    uint8_t nfields;     /* number of fields (Reserved rows excluded) */
    uint8_t size;        /* sizeof the typed struct (0: none) */
    uint8_t index;       /* TASE_PKT_* index of this packet */
} tase_packet_desc_t;

/* ---- lookup and accepted lengths ---------------------------------------- */

/* The descriptor of packet (group, type), or NULL if the schema does not
 * know it (group 0x28 STATUS has no packets in spec v1.0.0; any byte
 * values may be passed). O(1). */
const tase_packet_desc_t *tase_schema_find(uint8_t group, uint8_t type);

/* The descriptor of TASE_PKT_* index i (0..TASE_PKT_COUNT-1), or NULL
 * when i is out of range. O(1). Iterate over every packet with it. */
const tase_packet_desc_t *tase_schema_at(size_t i);

/* True when `len` data bytes are a valid form of packet p: its table
 * length, or 0 with TASE_LEN_QUERY, 1 with TASE_LEN_SHORT1, len - 1 with
 * TASE_LEN_SHORT, or len..253 with TASE_LEN_TAIL. False when p is NULL.
 * O(1). (A field walk begun for len has the answer in it->accepted.) */
bool tase_schema_length_ok(const tase_packet_desc_t *p, size_t len);

/* True when a frame of packet p with `len` data bytes is a query (zero
 * length and p has a query form). GYRO_ZERO_CMD is always zero length and
 * is a command, not a query. False when p is NULL. O(1). */
bool tase_schema_is_query(const tase_packet_desc_t *p, size_t len);

/* The bits of packet p's `flags` field reserved in what is sent to the
 * gimbal, as a mask (tase/flags.h): CAMERA_CMD, HOST_SENSOR and
 * HOST_ATTITUDE bits the spec says to set to zero; SPOI_CMD bits 1-7, the
 * Mode the gimbal fills in (to the gimbal only bit 0 means something:
 * docs/PROTOCOL-NOTES.md P4). 0 for every other packet and for p NULL.
 * What `tase send` and the Python Link refuse unless told to send it
 * anyway. O(1). */
uint8_t tase_schema_reserved_flags(const tase_packet_desc_t *p);

/* ---- walking the fields of a packet ------------------------------------
 *
 * tase_field_iter_find() (by group and type) or tase_field_iter_init() (a
 * descriptor in hand) binds an iterator to a packet and begins a walk over
 * its fields for a frame of a given data length, which it checks and
 * which selects the layout: that is a walk's one call into the schema's
 * code. tase_field_iter_next() is static inline, so the walk itself runs
 * in the caller with the descriptors in hand:
 *
 *     tase_field_iter_t it;
 *     if (tase_field_iter_find(&it, f->group, f->type, f->len) == NULL) {
 *         unknown packet
 *     } else if (!it.accepted) {
 *         not an accepted length
 *     } else {
 *         while (tase_field_iter_next(&it)) {
 *             if (it.within) { the field: f->data[it.offset], it.width
 *                              bytes, TASE_FIELD_IS_SIGNED(it.field) }
 *         }
 *     }
 *
 * The model is nanopb's pb_field_iter_t. The iterator is the caller's and
 * holds no pointer but into ROM; the members after "private" are not part
 * of the API. Every function here is reentrant and ISR-safe.
 */
typedef struct {
    const tase_packet_desc_t *packet; /* the bound packet; NULL: none (walks nothing) */
    const tase_field_t *field;        /* the current field; NULL before the first */
    uint8_t len;    /* the data length of the walk (one above TASE_DATA_MAX: too long) */
    uint8_t offset; /* the field's byte offset in len bytes (layout applied) */
    uint8_t width;  /* its width in bytes: 1, 2, 4 or 8 */
    uint8_t index;  /* its index, 0..nfields-1 */
    bool accepted;  /* len is an accepted length of the packet */
    bool within;    /* offset + width <= len: the field is in the data */
    /* private */
    bool short_layout;          /* len is the packet's short layout */
    uint8_t next;               /* index of the next field */
    const tase_field_t *fields; /* the bound packet's first field */
    uint8_t count;              /* fields of the bound packet */
} tase_field_iter_t;

/* `len` for tase_field_iter_find(), tase_field_iter_init() and
 * tase_field_iter_begin(): the packet's table length (its descriptor's
 * `len`), whatever it is. Any other length above TASE_DATA_MAX is refused
 * (it->accepted false); this one value is not a length. */
#define TASE_FIELD_ITER_TABLE_LEN SIZE_MAX

/* Bind `it` to packet (group, type) (any byte values; O(1), as
 * tase_schema_find()) and begin a walk for a frame of `len` data bytes (as
 * tase_field_iter_begin()). Returns the packet's descriptor, or NULL when
 * the schema does not know it (or `it` is NULL): `it` is then bound to no
 * packet, walks nothing and has accepted false. */
const tase_packet_desc_t *tase_field_iter_find(tase_field_iter_t *it, uint8_t group, uint8_t type,
                                               size_t len);

/* Bind `it` to descriptor p (from tase_schema_find(), tase_schema_at(),
 * tase_schema_find_name()) and begin a walk for a frame of `len` data
 * bytes. Returns TASE_OK (it->accepted tells whether the packet accepts
 * len), or, leaving `it` bound to no packet,
 *   TASE_EUNKNOWN p is NULL (a failed lookup may be passed as it is);
 *   TASE_EARG     it is NULL (nothing written), or p is not a descriptor
 *                 of the schema table (a copy: its field counts are not
 *                 to be trusted).
 * O(1). */
int tase_field_iter_init(tase_field_iter_t *it, const tase_packet_desc_t *p, size_t len);

/* Begin the walk over the bound packet's fields anew, for a frame of `len`
 * data bytes (any size_t, or TASE_FIELD_ITER_TABLE_LEN): the length selects
 * the layout (TWO LAYOUTS above) and which fields lie within the data.
 * Sets it->len (a length above TASE_DATA_MAX is kept as TASE_DATA_MAX + 1)
 * and it->accepted (len is an accepted length of the packet, as
 * tase_schema_length_ok()) and returns it->accepted; the walk works
 * either way. False when `it` is bound to no packet. O(1). */
bool tase_field_iter_begin(tase_field_iter_t *it, size_t len);

/* Private: the layout rule, written once. A packet's short layout is one
 * data byte short of its table and flagged TASE_LEN_SHORT (the field flag
 * alone never moves a field). */
static inline bool tase_schema_short_(const tase_packet_desc_t *p, size_t len)
{
    return (p->flags & TASE_LEN_SHORT) != 0u && len + 1u == p->len;
}

/* Private: the byte offset of field f in the short or the table layout. */
static inline size_t tase_field_at_(const tase_field_t *f, bool short_layout)
{
    size_t at = f->offset;
    if (short_layout && (f->fmt & TASE_FIELD_SHIFT) != 0u && at > 0u) {
        at--;
    }
    return at;
}

/* Move to field i (0..nfields-1) of the walk, as i + 1 calls of
 * tase_field_iter_next() after the walk began would: sets field, index,
 * width, offset and within, and returns true. False, with nothing
 * changed, when i is out of range (any size_t). O(1). */
static TASE_INLINE_ bool tase_field_iter_seek(tase_field_iter_t *it, size_t i)
{
    const tase_field_t *f;
    if (i >= it->count) {
        return false;
    }
    f = &it->fields[i];
    it->field = f;
    it->index = TASE_CAST_(uint8_t, i);
    it->next = TASE_CAST_(uint8_t, i + 1u);
    it->width = TASE_CAST_(uint8_t, TASE_FIELD_WIDTH(f));
    it->offset = TASE_CAST_(uint8_t, tase_field_at_(f, it->short_layout));
    it->within = it->offset + it->width <= it->len;
    return true;
}

/* Move to the next field (the first after the walk began), as
 * tase_field_iter_seek() does; false past the last one. O(1). */
static TASE_INLINE_ bool tase_field_iter_next(tase_field_iter_t *it)
{
    return tase_field_iter_seek(it, it->next);
}

/* Private: the wire bits of the current field in data (big-endian,
 * it->width bytes at it->offset; the caller has checked it->within). The
 * one reader of a field's bytes: the codec, tase_field_iter_get() and the
 * gimbal role's setup copy. */
static inline uint64_t tase_field_iter_bits_(const tase_field_iter_t *it, const uint8_t *data)
{
    uint64_t v = 0u;
    unsigned k;
    for (k = 0u; k < it->width; k++) {
        v = (v << 8) | data[it->offset + k];
    }
    return v;
}

/* The wire bits of the current field's "do not change" value (all ones of
 * its width, zero, or its top bit; tase_field_keep() gives the value):
 * sets *bits and returns true, or returns false when the field has none
 * (or no field is current). Fields with one are at most 4 bytes wide
 * (checked at build time). O(1). */
static inline bool tase_field_iter_keep_bits(const tase_field_iter_t *it, uint32_t *bits)
{
    uint32_t ones;
    uint32_t one = 1u;    /* not UINT32_C(1): C++98 has it only on request (newlib) */
    if (it->next == 0u) { /* no field yet: begin() or bound to none */
        return false;
    }
    ones = (it->width >= 4u) ? 0xFFFFFFFFu : (one << (8u * it->width)) - 1u;
    switch (TASE_FIELD_KEEP(it->field)) {
    case TASE_FIELD_KEEP_ONES: *bits = ones; return true;
    case TASE_FIELD_KEEP_ZERO: *bits = 0u; return true;
    case TASE_FIELD_KEEP_MSB: *bits = ones ^ (ones >> 1); return true; /* top bit */
    default: return false;
    }
}

/* The value of the walk's current field in data[0..it->len) (the length
 * the walk was begun for; data NULL only when it is 0): big-endian,
 * sign-extended when the field is signed (a width-8 unsigned field above
 * INT64_MAX would wrap; the spec has none). Returns TASE_OK and sets
 * *value, or
 *   TASE_EARG   it or value is NULL, no field is current, or data is NULL
 *               with a length above 0;
 *   TASE_ETRUNC the field does not lie within the data (it->within false:
 *               a query, a short form).
 * O(width). */
int tase_field_iter_get(const tase_field_iter_t *it, const uint8_t *data, int64_t *value);

/* ---- one field by index: conveniences built on the iterator ------------
 *
 * Each call binds an iterator to p (tase_field_iter_init(): p must be a
 * descriptor of the table, a copy gives the error below) and seeks field
 * i, so each starts over: walk the fields with the iterator instead of
 * calling these in a loop. For callers that hold a field index (the tools'
 * field names, the gimbal role's setup copy). */

/* Field i (0..nfields-1) of packet p, or NULL if p is NULL or not a
 * descriptor of the table, or i is out of range (any size_t). O(1). */
const tase_field_t *tase_schema_field(const tase_packet_desc_t *p, size_t i);

/* Byte offset of field i of packet p in a frame with `len` data bytes:
 * the field's `offset`, one less in the short layout (len == p->len - 1,
 * p has TASE_LEN_SHORT and the field TASE_FIELD_SHIFT). Returns the
 * offset (>= 0; the field may still lie beyond len, e.g. in a query), or
 * TASE_EARG (p NULL or not of the table, or i out of range). O(1). */
int tase_field_offset(const tase_packet_desc_t *p, size_t i, size_t len);

/* Read the integer value of field i of packet p from data[0..len) (at
 * tase_field_offset(), so the length selects the layout): big-
 * endian, sign-extended when the field is signed. (A width-8 unsigned
 * field above INT64_MAX would wrap; the spec has no 8-byte field.)
 * Returns TASE_OK and sets *value, or
 *   TASE_EARG  p, data (with len > 0) or value is NULL, p is not of the
 *              table, or i >= nfields;
 *   TASE_ETRUNC the field does not lie within len bytes (e.g. a query).
 * O(width). */
int tase_field_get(const tase_packet_desc_t *p, size_t i, const uint8_t *data, size_t len,
                   int64_t *value);

/* The "do not change" value of field i of packet p (the spec's value that
 * leaves a setting as it is, e.g. CAMERA_CMD camera 0xFF, hfov -1, focus
 * 0xFFFF, flags 0x80; AXIS_SETTING 0xFF / 0xFFFF; CAMERA_TYPE 0): returns
 * TASE_OK and sets *value to the wire integer (sign-extended for signed
 * fields), TASE_EUNKNOWN if the field has none, TASE_EARG for NULL
 * arguments, p not of the table or i out of range. O(1). */
int tase_field_keep(const tase_packet_desc_t *p, size_t i, int64_t *value);

/* True when `value` of field i of packet p means "do not change" (for a
 * flags byte whose MSB means "no change", any value with that bit set).
 * False when the field has none, p is NULL or not of the table, or i is
 * out of range. O(1). */
bool tase_field_is_keep(const tase_packet_desc_t *p, size_t i, int64_t value);

/* ---- names (src/tase_schema_names.c; not linked unless used) ----------- */

/* The spec name of packet p ("GIMBAL_CMD", "GIMBAL_RATE" for 0x08/0x40,
 * ...), or NULL if p is NULL or its index is out of range (not a
 * descriptor of the table). */
const char *tase_schema_packet_name(const tase_packet_desc_t *p);

/* The JSON name of field i of packet p ("pan", "impulse_time"), or NULL if
 * p is NULL or i is out of range. */
const char *tase_schema_field_name(const tase_packet_desc_t *p, size_t i);

/* The packet named `name` (exact, case-sensitive spec name), or NULL
 * (also for name NULL).
 * O(TASE_PKT_COUNT) string compares: for tools, not for receive paths. */
const tase_packet_desc_t *tase_schema_find_name(const char *name);

/* The index of the field named `name` in packet p, or TASE_EUNKNOWN if it
 * has none, TASE_EARG if p or name is NULL. O(nfields). */
int tase_schema_field_index(const tase_packet_desc_t *p, const char *name);

#ifdef __cplusplus
}
#endif

#endif /* TASE_SCHEMA_H */
