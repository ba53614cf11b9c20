/*
 * Generic typed codec: one loop over the schema's fields moves each
 * member between the typed struct and big-endian wire bytes. Members are
 * accessed through memcpy at their offsetof() position, so no struct
 * layout or host byte order is assumed. int16_t and friends are two's
 * complement by definition, so copying the unsigned bit pattern of a
 * width into a signed member gives the right value.
 */
#include "tase/codec.h"

#include <string.h>

#include "tase_schema_layout.h"

/* The member's own type is not known here, only its width: hence void. */
static uint64_t member_load(const void *src, unsigned w)
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

static void member_store(void *dst, unsigned w, uint64_t v)
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

/* The fields of msg that lie within len bytes, big-endian into body, at
 * the offsets of the layout that len selects (AXIS_SETTING 22 or 23). */
static void pack_fields(const tase_packet_desc_t *p, const void *msg, size_t len, uint8_t *body)
{
    size_t i;
    bool short_layout = tase_layout_is_short(p, len);
    for (i = 0; i < p->nfields; i++) {
        const tase_field_t *f = tase_schema_field(p, i);
        unsigned w = TASE_FIELD_WIDTH(f);
        size_t at = tase_layout_offset(f, short_layout);
        uint64_t v;
        if (at + w > len) {
            continue; /* short form: CAMERA_CMD camera byte only */
        }
        v = member_load((const uint8_t *)msg + f->member, w);
        while (w > 0u) {
            w--;
            body[at + w] = (uint8_t)v;
            v >>= 8;
        }
    }
}

/* The checks both encoders make before writing, in the order codec.h
 * documents (the output buffer and its capacity are the caller's). */
static int encode_check(const tase_packet_desc_t *p, const void *msg, size_t len)
{
    const tase_camera_pass_t *cp = msg;
    if (msg == NULL && len > 0u) {
        return TASE_EARG;
    }
    if ((p->flags & TASE_LEN_TAIL) != 0u && len > 0u) {
        if (cp->len > TASE_CAMERA_PASS_MAX) {
            return TASE_ETOOLONG;
        }
        if (cp->data == NULL && cp->len > 0u) {
            return TASE_EARG;
        }
        if (len != (size_t)p->len + cp->len) {
            return TASE_ELENGTH;
        }
    }
    return tase_schema_length_ok(p, len) ? TASE_OK : TASE_ELENGTH;
}

/* The len data bytes of msg into body (checked by encode_check()). */
static void encode_body(const tase_packet_desc_t *p, const void *msg, size_t len, uint8_t *body)
{
    const tase_camera_pass_t *cp = msg;
    size_t fixed;
    if (len > p->len) {
        fixed = p->len;
        /* The tail first: its source may lie anywhere in the output. */
        (void)memmove(&body[fixed], cp->data, len - fixed);
    } else {
        fixed = len;
    }
    (void)memset(body, 0, fixed); /* reserved bytes */
    if (msg != NULL) {            /* else a query: no data */
        pack_fields(p, msg, len, body);
    }
}

/* The table length of p for msg (CAMERA_PASS: plus its tail). */
static size_t table_len(const tase_packet_desc_t *p, const void *msg)
{
    size_t len = p->len;
    if ((p->flags & TASE_LEN_TAIL) != 0u && msg != NULL) {
        len += ((const tase_camera_pass_t *)msg)->len;
    }
    return len;
}

/* Every encoder: packet `id` from msg at data length *len (NULL: the table
 * length) into out[0..cap), as a whole frame or as its data only. */
static int encode(uint16_t id, const void *msg, const size_t *len, uint8_t *out, size_t cap,
                  bool frame)
{
    const tase_packet_desc_t *p = tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id));
    size_t n;
    size_t header = 0u;
    size_t overhead = 0u;
    int r;
    if (out == NULL) {
        return TASE_EARG;
    }
    if (p == NULL) {
        return TASE_EUNKNOWN;
    }
    if (frame) {
        header = TASE_FRAME_HEADER;
        overhead = TASE_FRAME_OVERHEAD;
    }
    n = len != NULL ? *len : table_len(p, msg);
    r = encode_check(p, msg, n);
    if (r != TASE_OK) {
        return r;
    }
    if (cap < n + overhead) {
        return TASE_ENOSPC;
    }
    encode_body(p, msg, n, out + header);
    if (!frame) {
        return (int)n;
    }
    return tase_frame_encode(out, cap, TASE_ID_GROUP(id), TASE_ID_TYPE(id), out + header, n);
}

int tase_packet_encode(uint16_t id, const void *msg, uint8_t *out, size_t cap)
{
    return encode(id, msg, NULL, out, cap, true);
}

int tase_packet_encode_len(uint16_t id, const void *msg, size_t len, uint8_t *out, size_t cap)
{
    return encode(id, msg, &len, out, cap, true);
}

int tase_packet_encode_data(uint16_t id, const void *msg, uint8_t *data, size_t cap)
{
    return encode(id, msg, NULL, data, cap, false);
}

int tase_packet_encode_data_len(uint16_t id, const void *msg, size_t len, uint8_t *data, size_t cap)
{
    return encode(id, msg, &len, data, cap, false);
}

int tase_packet_encode_query(uint16_t id, uint8_t *out, size_t cap)
{
    return tase_packet_encode_len(id, NULL, 0u, out, cap);
}

/* The fields that lie within the frame's data, into msg. Only the wire
 * bits are needed (no sign extension: see the top of this file), and
 * reading them inline instead of through tase_field_get() keeps the
 * receive path's stack small. A field a short form leaves out (CAMERA_CMD's
 * 1-byte form) takes its "do not change" value, so a handler that ignores
 * the length never acts on a zero it was not sent; fields without one stay
 * zero. */
static void unpack_fields(const tase_packet_desc_t *p, const uint8_t *data, size_t len, void *msg)
{
    size_t i;
    bool short_layout = tase_layout_is_short(p, len);
    for (i = 0; i < p->nfields; i++) {
        const tase_field_t *fd = tase_schema_field(p, i);
        unsigned w = TASE_FIELD_WIDTH(fd);
        size_t at = tase_layout_offset(fd, short_layout);
        unsigned k;
        uint64_t v = 0u;
        uint32_t keep;
        if (at + w > len) {
            if (tase_layout_keep_bits(fd, &keep)) {
                member_store((uint8_t *)msg + fd->member, w, keep);
            }
            continue;
        }
        for (k = 0; k < w; k++) {
            v = (v << 8) | data[at + k];
        }
        member_store((uint8_t *)msg + fd->member, w, v);
    }
}

int tase_packet_decode_desc(const tase_packet_desc_t *p, const uint8_t *data, size_t len, void *msg)
{
    if (data == NULL && len > 0u) {
        return TASE_EARG;
    }
    if (p == NULL) {
        return TASE_EUNKNOWN;
    }
    if (tase_schema_at(p->index) != p) {
        return TASE_EARG; /* not a descriptor of the table: its size is not to be trusted */
    }
    if (!tase_schema_length_ok(p, len)) {
        return TASE_ELENGTH;
    }
    if (msg == NULL) {
        return len == 0u ? 0 : TASE_EARG;
    }
    (void)memset(msg, 0, p->size);
    if (len > 0u) { /* else a query: no data, every member zero */
        unpack_fields(p, data, len, msg);
    }
    if ((p->flags & TASE_LEN_TAIL) != 0u) {
        tase_camera_pass_t *cp = msg;
        cp->len = (uint8_t)(len - p->len);
        cp->data = data + p->len;
    }
    return (int)len;
}

int tase_packet_decode_data(uint16_t id, const uint8_t *data, size_t len, void *msg)
{
    return tase_packet_decode_desc(tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id)), data, len,
                                   msg);
}

int tase_packet_decode(const tase_frame_t *f, void *msg)
{
    if (f == NULL) {
        return TASE_EARG;
    }
    return tase_packet_decode_desc(tase_schema_find(f->group, f->type), f->data, f->len, msg);
}
