/*
 * Generic typed codec: one walk over the packet's fields (the schema's
 * field iterator, tase/schema.h) moves each member between the typed
 * struct and big-endian wire bytes. A walk calls into the schema once, to
 * bind the iterator; the layout, offsets, widths and "do not change"
 * values then come from the iterator inline. Members are accessed through
 * memcpy at their offsetof() position, so no struct layout or host byte
 * order is assumed. int16_t and friends are two's complement by
 * definition, so copying the unsigned bit pattern of a width into a
 * signed member gives the right value.
 */
#include "tase/codec.h"

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "tase_codec_private.h"
#include "tase/flags.h"

/* SPOI_CMD's latitude and longitude limits (90 and 180 degrees) in
 * milli-arcseconds, its wire unit. */
#define SPOI_LAT_MAX_MAS 324000000
#define SPOI_LON_MAX_MAS 648000000

static TASE_INLINE_ void member_store(void *dst, unsigned w, uint64_t v)
{
    uint8_t b = (uint8_t)v;
    uint16_t h = (uint16_t)v;
    uint32_t x = (uint32_t)v;
    switch (w) {
    case 1: (void)memcpy(dst, &b, 1); break;
    case 2: (void)memcpy(dst, &h, 2); break;
    case 4: (void)memcpy(dst, &x, 4); break;
    default: (void)memcpy(dst, &v, 8); break;
    }
}

/* The fields of msg that lie within the walk's length, big-endian into
 * body, at the offsets of the layout the length selects (AXIS_SETTING 22
 * or 23). */
static void pack_fields(tase_field_iter_t *it, const void *msg, uint8_t *body)
{
    while (tase_field_iter_next(it)) {
        unsigned w = it->width;
        uint64_t v;
        if (!it->within) {
            continue; /* short form: CAMERA_CMD camera byte only */
        }
        v = tase_member_load((const uint8_t *)msg + it->field->member, w);
        while (w > 0u) {
            w--;
            body[it->offset + w] = (uint8_t)v;
            v >>= 8;
        }
    }
}

/* The checks both encoders make before writing, in the order codec.h
 * documents (the output buffer and its capacity are the caller's); the
 * walk was begun at len. */
static int encode_check(const tase_field_iter_t *it, const void *msg, size_t len)
{
    const tase_packet_desc_t *p = it->packet;
    const tase_camera_pass_t *cp = msg;
    if (msg == NULL && len > 0u) {
        return TASE_EARG;
    }
    if ((p->flags & TASE_LEN_TAIL) != 0u && len > 0u) {
        if (cp->data == NULL && cp->len > 0u) {
            return TASE_EARG; /* before ETOOLONG, in codec.h's order */
        }
        if (cp->len > TASE_CAMERA_PASS_MAX) {
            return TASE_ETOOLONG;
        }
        if (len != (size_t)p->len + cp->len) {
            return TASE_ELENGTH;
        }
    }
    return it->accepted ? TASE_OK : TASE_ELENGTH;
}

/* The len data bytes of msg into body (checked by encode_check()). Not
 * inlined: the walk's registers stay out of encode()'s frame, which is
 * live while it calls tase_frame_build() (the deepest path). */
TASE_NOINLINE_ static void encode_body(tase_field_iter_t *it, const void *msg, size_t len,
                                       uint8_t *body)
{
    const tase_camera_pass_t *cp = msg;
    size_t table = it->packet->len;
    size_t fixed;
    if (len > table) {
        fixed = table;
        /* The tail first: its source may lie anywhere in the output. */
        (void)memmove(&body[fixed], cp->data, len - fixed);
    } else {
        fixed = len;
    }
    (void)memset(body, 0, fixed); /* reserved bytes */
    if (msg != NULL) {            /* else a query: no data */
        pack_fields(it, msg, body);
    }
}

/* A caller's data length for a walk: every length above TASE_DATA_MAX is
 * refused alike, and SIZE_MAX must not read as TASE_FIELD_ITER_TABLE_LEN
 * (codec.h: any size_t up to SIZE_MAX gives TASE_ELENGTH). */
static size_t walk_len(size_t len)
{
    return len > TASE_DATA_MAX ? TASE_DATA_MAX + 1u : len;
}

/* The walk of packet `id` begun for msg at data length `len`
 * (TASE_FIELD_ITER_TABLE_LEN: the table length, CAMERA_PASS's tail added)
 * and checked in codec.h's order: the one call into the schema (the
 * packet found, the length checked, the walk begun). Returns the data
 * length or an error. */
static TASE_INLINE_ int encode_begin(tase_field_iter_t *it, uint16_t id, const void *msg,
                                     size_t len)
{
    const tase_packet_desc_t *p;
    size_t n = len;
    int r;
    p = tase_field_iter_find(it, TASE_ID_GROUP(id), TASE_ID_TYPE(id), len);
    if (p == NULL) {
        return TASE_EUNKNOWN;
    }
    if (len == TASE_FIELD_ITER_TABLE_LEN) {
        n = it->len; /* every field lies within it, as within the tail form */
        if ((p->flags & TASE_LEN_TAIL) != 0u && msg != NULL) {
            n += ((const tase_camera_pass_t *)msg)->len;
        }
    }
    r = encode_check(it, msg, n);
    return r != TASE_OK ? r : (int)n;
}

/* Every encoder: packet `id` from msg at data length `len` (as
 * encode_begin()) into out[header..cap), header 0 for the data only or
 * TASE_FRAME_HEADER to leave room for a frame around it. Returns the data
 * length. */
static int encode(uint8_t *out, size_t cap, size_t header, uint16_t id, const void *msg, size_t len)
{
    tase_field_iter_t it;
    size_t overhead = 0u;
    int n;
    if (out == NULL) {
        return TASE_EARG;
    }
    if (header > 0u) {
        overhead = TASE_FRAME_OVERHEAD;
    }
    n = encode_begin(&it, id, msg, len);
    if (n < 0) {
        return n;
    }
    if (cap < (size_t)n + overhead) {
        return TASE_ENOSPC;
    }
    encode_body(&it, msg, (size_t)n, out + header);
    return n;
}

int tase_wire_begin(tase_wire_t *w, uint16_t id, const void *msg)
{
    tase_field_iter_t it;
    int n = encode_begin(&it, id, msg, msg != NULL ? TASE_FIELD_ITER_TABLE_LEN : 0u);
    if (n < 0) {
        return n;
    }
    w->msg = msg;
    w->field = it.fields; /* the walk at the table length: table offsets */
    w->nfields = it.count;
    w->fixed = it.len; /* CAMERA_PASS: its 4, the camera bytes follow */
    if ((size_t)n < it.len) {
        w->fixed = (uint8_t)n; /* the zero-length form */
    }
    return n;
}

/* A whole frame around the data encode() wrote: the frame encoder is
 * called from here, so the data-only encoders never reach it (their
 * stack is the data's alone). */
static int encode_frame(uint8_t *out, size_t cap, uint16_t id, const void *msg, size_t len)
{
    int r = encode(out, cap, TASE_FRAME_HEADER, id, msg, len);
    if (r < 0) {
        return r;
    }
    return tase_frame_build(TASE_ID_GROUP(id), TASE_ID_TYPE(id), out + TASE_FRAME_HEADER, (size_t)r,
                            out, cap);
}

int tase_packet_encode(uint16_t id, const void *msg, uint8_t *out, size_t cap)
{
    return encode_frame(out, cap, id, msg, TASE_FIELD_ITER_TABLE_LEN);
}

int tase_packet_encode_len(uint16_t id, const void *msg, size_t len, uint8_t *out, size_t cap)
{
    return encode_frame(out, cap, id, msg, walk_len(len));
}

int tase_packet_encode_data(uint16_t id, const void *msg, uint8_t *data, size_t cap)
{
    return encode(data, cap, 0u, id, msg, TASE_FIELD_ITER_TABLE_LEN);
}

int tase_packet_encode_data_len(uint16_t id, const void *msg, size_t len, uint8_t *data, size_t cap)
{
    return encode(data, cap, 0u, id, msg, walk_len(len));
}

int tase_packet_encode_query(uint16_t id, uint8_t *out, size_t cap)
{
    return tase_packet_encode_len(id, NULL, 0u, out, cap);
}

/* The fields of the walk, from the frame's data into msg. Only the wire
 * bits are needed (no sign extension: see the top of this file), read
 * inline so that the receive path's stack stays small. A field a short
 * form leaves out (CAMERA_CMD's 1-byte form) takes its "do not change"
 * value, so a handler that ignores the length never acts on a zero it was
 * not sent; fields without one stay zero. */
TASE_NOINLINE_ static void unpack_fields(tase_field_iter_t *it, const uint8_t *data, void *msg)
{
    while (tase_field_iter_next(it)) {
        uint8_t *m = (uint8_t *)msg + it->field->member;
        uint32_t keep;
        if (!it->within || data == NULL) { /* data is NULL only at length 0 */
            if (tase_field_iter_keep_bits(it, &keep)) {
                member_store(m, it->width, keep);
            }
            continue;
        }
        member_store(m, it->width, tase_field_iter_bits_(it, data));
    }
}

/* Every decoder, once the walk is begun at the frame's length: data into
 * msg (data NULL only with length 0, checked by the caller). */
static int decode(tase_field_iter_t *it, const uint8_t *data, void *msg)
{
    const tase_packet_desc_t *p = it->packet;
    size_t len = it->len;
    if (!it->accepted) {
        return TASE_ELENGTH;
    }
    if (msg == NULL) {
        return len == 0u ? 0 : TASE_EARG;
    }
    (void)memset(msg, 0, p->size);
    if (len > 0u) { /* else a query: no data, every member zero */
        unpack_fields(it, data, msg);
    }
    if ((p->flags & TASE_LEN_TAIL) != 0u) {
        tase_camera_pass_t *cp = msg;
        cp->len = (uint8_t)(len - p->len);
        cp->data = data + p->len;
    }
    return (int)len;
}

int tase_packet_decode_iter(tase_field_iter_t *it, const uint8_t *data, void *msg)
{
    if (it == NULL || it->packet == NULL || (data == NULL && it->len > 0u)) {
        return TASE_EARG;
    }
    it->next = 0u; /* back to the first field; the length stays checked */
    return decode(it, data, msg);
}

int tase_packet_decode_desc(const tase_packet_desc_t *p, const uint8_t *data, size_t len, void *msg)
{
    tase_field_iter_t it;
    int r;
    if (data == NULL && len > 0u) {
        return TASE_EARG;
    }
    /* TASE_EUNKNOWN for NULL; TASE_EARG for a pointer that is not a
     * descriptor of the table (its size is not to be trusted) */
    r = tase_field_iter_init(&it, p, walk_len(len));
    return r != TASE_OK ? r : decode(&it, data, msg);
}

/* tase_packet_decode_data() and tase_packet_decode(): the packet looked up
 * as the walk is bound. */
static int decode_find(uint8_t group, uint8_t type, const uint8_t *data, size_t len, void *msg)
{
    tase_field_iter_t it;
    if (data == NULL && len > 0u) {
        return TASE_EARG;
    }
    if (tase_field_iter_find(&it, group, type, walk_len(len)) == NULL) {
        return TASE_EUNKNOWN;
    }
    return decode(&it, data, msg);
}

int tase_packet_decode_data(uint16_t id, const uint8_t *data, size_t len, void *msg)
{
    return decode_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id), data, len, msg);
}

int tase_packet_decode(const tase_frame_t *f, void *msg)
{
    if (f == NULL) {
        return TASE_EARG;
    }
    return decode_find(f->group, f->type, f->data, f->len, msg);
}

int tase_packet_init_keep(uint16_t id, void *msg)
{
    tase_field_iter_t it;
    const tase_packet_desc_t *p;
    size_t temp = SIZE_MAX; /* the member of a `temporary` byte */
    int none = 0;
    if (msg == NULL) {
        return TASE_EARG;
    }
    p = tase_field_iter_find(&it, TASE_ID_GROUP(id), TASE_ID_TYPE(id), TASE_FIELD_ITER_TABLE_LEN);
    if (p == NULL) {
        return TASE_EUNKNOWN;
    }
    if (id == TASE_ID_PACKET_RATE) {
        temp = offsetof(tase_packet_rate_t, temporary);
    } else if (id == TASE_ID_AXIS_SETTING) {
        temp = offsetof(tase_axis_setting_t, temporary);
    } else {
        /* no other packet has one */
    }
    (void)memset(msg, 0, p->size);
    while (tase_field_iter_next(&it)) {
        uint8_t *m = (uint8_t *)msg + it.field->member;
        uint32_t keep;
        if (it.field->member == temp) {
            *m = TASE_SETUP_TEMPORARY;
        } else if (tase_field_iter_keep_bits(&it, &keep)) {
            member_store(m, it.width, keep);
        } else {
            none++;
        }
    }
    return none;
}

int tase_command_check(uint16_t id, const void *msg)
{
    if (msg == NULL) {
        return TASE_EARG;
    }
    if (id == TASE_ID_GIMBAL_CMD) {
        const tase_gimbal_cmd_t *c = msg;
        bool position;
        switch (c->flags) {
        case TASE_GIMBAL_FLAGS_LEGACY_POSITION:
        case TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB:
        case TASE_GIMBAL_FLAGS_POSITION:
        case TASE_GIMBAL_FLAGS_POSITION_STAB: position = true; break;
        case TASE_GIMBAL_FLAGS_LEGACY_RATE:
        case TASE_GIMBAL_FLAGS_LEGACY_RATE_STAB:
        case TASE_GIMBAL_FLAGS_RATE:
        case TASE_GIMBAL_FLAGS_RATE_STAB:
        case TASE_GIMBAL_FLAGS_IMPULSE:
        case TASE_GIMBAL_FLAGS_IMPULSE_STAB:
        case TASE_GIMBAL_FLAGS_SPOI_ERROR:
        case TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE: position = false; break;
        default: return TASE_ERANGE; /* not a mode of table 5 */
        }
        if (position && (c->pan < TASE_PAN_MIN_CDEG || c->pan > TASE_PAN_MAX_CDEG ||
                         c->tilt < TASE_TILT_MIN_CDEG || c->tilt > TASE_TILT_MAX_CDEG)) {
            return TASE_ERANGE;
        }
    } else if (id == TASE_ID_SPOI_CMD) {
        const tase_spoi_cmd_t *c = msg;
        if (c->lat < -SPOI_LAT_MAX_MAS || c->lat > SPOI_LAT_MAX_MAS || c->lon < -SPOI_LON_MAX_MAS ||
            c->lon > SPOI_LON_MAX_MAS) {
            return TASE_ERANGE;
        }
    } else {
        /* no other packet moves the gimbal on a value the wire can carry */
    }
    return TASE_OK;
}

int tase_command_check_data(uint16_t id, const uint8_t *data, size_t len)
{
    tase_gimbal_cmd_t gimbal_cmd;
    tase_spoi_cmd_t spoi_cmd;
    void *m = (id == TASE_ID_GIMBAL_CMD) ? (void *)&gimbal_cmd : (void *)&spoi_cmd;
    int r;
    if (id == TASE_ID_RETRACT_DEPLOY_CMD || (len == 0u && id == TASE_ID_GIMBAL_CMD)) {
        /* no values to check, but a length the packet does not accept (a
         * zero-length GIMBAL_CMD, which has no query form) is refused */
        const tase_packet_desc_t *p = tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id));
        return (tase_schema_length_ok(p, len) || tase_schema_is_query(p, len)) ? TASE_OK
                                                                               : TASE_ELENGTH;
    }
    if ((id != TASE_ID_GIMBAL_CMD && id != TASE_ID_SPOI_CMD) || len == 0u) {
        return TASE_OK;
    }
    r = tase_packet_decode_data(id, data, len, m);
    return (r < 0) ? r : tase_command_check(id, m);
}
