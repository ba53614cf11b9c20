/*
 * Fuzz harness: every packet decoder (tase_packet_decode) and the
 * dispatcher on a frame of any (group, type) and any data length.
 *
 * Input: mode, sel1, sel2, lensel, then data bytes (zero-padded when the
 * input is shorter than the chosen length).
 *   mode bit 0   1: the packet is schema entry sel1 % TASE_PKT_COUNT (so
 *                known packets are reached at once); 0: group = sel1,
 *                type = sel2 (mostly unknown ones).
 *   mode bits 1-2 the data length: 0 the packet's table length, 1 lensel
 *                (0..255), 2 the rest of the input (at most 253), 3 the
 *                table length + lensel % 8 - 4 (the near misses).
 * The data lives in a buffer of exactly that length, so ASan sees any
 * read beyond it. Checks:
 *   - decode returns TASE_EUNKNOWN when the schema does not know (group,
 *     type), TASE_ELENGTH when the length is not one the header documents
 *     for the packet (table length; 0 for a query; 1 for CAMERA_CMD; 22
 *     for AXIS_SETTING; table length..253 for CAMERA_PASS), else the
 *     length; on error the output struct is byte-for-byte unchanged (it
 *     holds a canary), and on success nothing beyond the packet's struct
 *     is written;
 *   - tase_field_get agrees with the decoded member for every field that
 *     lies within the data (at the offset of the layout the length
 *     selects) and says TASE_ETRUNC otherwise, the member then zero in a
 *     query and the field's "do not change" value in a short form;
 *   - re-encoding the struct with tase_packet_encode_len (and
 *     tase_packet_encode at the full length) gives back the same frame:
 *     header, group, type and the data bytes, with reserved bytes (no
 *     field covers them) as zero;
 *   - the dispatcher counts unknown / bad_length exactly as documented,
 *     calls the error hook with TASE_ELENGTH, the typed handler with the
 *     same decoded struct, and the default handler when no typed handler
 *     is set.
 */
#include <string.h>

#include "fuzz.h"
#include "tase/codec.h"
#include "tase/dispatch.h"

#define CANARY 0xA5u

typedef struct {
    int typed, deflt, error, err;
    const tase_frame_t *frame;
    tase_packet_msg_t msg;
    int msg_null;
} calls_t;

static void on_typed(void *user, const tase_frame_t *frame, const void *msg)
{
    calls_t *c = user;
    c->typed++;
    c->frame = frame;
    c->msg_null = msg == NULL;
    if (msg != NULL) {
        const tase_packet_desc_t *p = tase_schema_find(frame->group, frame->type);
        FZ_CHECK(p != NULL);
        memcpy(&c->msg, msg, p->size);
    }
}

static void on_default(void *user, const tase_frame_t *frame)
{
    calls_t *c = user;
    c->deflt++;
    c->frame = frame;
}

static void on_error(void *user, const tase_frame_t *frame, int err)
{
    calls_t *c = user;
    c->error++;
    c->err = err;
    c->frame = frame;
}

/* The documented accepted lengths, written out independently of
 * tase_schema_length_ok(). */
static int length_documented(const tase_packet_desc_t *p, size_t len)
{
    if (len == p->len) {
        return 1;
    }
    if (len == 0u) { /* queries: every setup packet and SPOI_CMD */
        return TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP || p->id == TASE_ID_SPOI_CMD;
    }
    if (len == 1u && p->id == TASE_ID_CAMERA_CMD) {
        return 1;
    }
    if (len == 22u && p->id == TASE_ID_AXIS_SETTING) { /* table 22 without byte 13 */
        return 1;
    }
    return p->id == TASE_ID_CAMERA_PASS && len > p->len && len <= TASE_DATA_MAX;
}

/* Where field f lies in `len` data bytes, written out independently of
 * tase_field_offset(): in the 22-byte AXIS_SETTING every row after byte 12
 * is one byte earlier. */
static size_t wire_offset(const tase_packet_desc_t *p, const tase_field_t *f, size_t len)
{
    if (p->id == TASE_ID_AXIS_SETTING && len == 22u && f->offset > 12u) {
        return f->offset - 1u;
    }
    return f->offset;
}

/* The member of field f in struct msg, as the integer its C type holds. */
static int64_t member_value(const void *msg, const tase_field_t *f)
{
    const uint8_t *m = (const uint8_t *)msg + f->member;
    unsigned w = TASE_FIELD_WIDTH(f);
    uint64_t u = 0;
    uint8_t b;
    uint16_t h;
    uint32_t x;
    switch (w) {
    case 1: memcpy(&b, m, 1), u = b; break;
    case 2: memcpy(&h, m, 2), u = h; break;
    case 4: memcpy(&x, m, 4), u = x; break;
    default: memcpy(&u, m, 8); break;
    }
    if (TASE_FIELD_IS_SIGNED(f) && w < 8u && ((u >> (8u * w - 1u)) & 1u) != 0u) {
        return (int64_t)u - ((int64_t)1 << (8u * w));
    }
    return (int64_t)u;
}

static void check_roundtrip(const tase_packet_desc_t *p, const tase_frame_t *f,
                            const tase_packet_msg_t *msg)
{
    uint8_t expect[TASE_DATA_MAX], out[TASE_FRAME_MAX], out2[TASE_FRAME_MAX];
    size_t i, len = f->len;
    int n;
    memset(expect, 0, sizeof(expect));
    if (len > p->len) { /* CAMERA_PASS tail: every byte is data */
        memcpy(expect + p->len, f->data + p->len, len - p->len);
    }
    for (i = 0; i < p->nfields; i++) {
        const tase_field_t *fd = tase_schema_field(p, i);
        unsigned w = TASE_FIELD_WIDTH(fd);
        size_t at = wire_offset(p, fd, len);
        int64_t v = 0x5A5A, keep = 0;
        int rc = tase_field_get(p, i, f->data, len, &v);
        FZ_CHECK(fd != NULL);
        if (at + w > len) {
            /* beyond a short form: zero in a query, else the field's "do
             * not change" value (zero if it has none) */
            FZ_CHECK(rc == TASE_ETRUNC && v == 0x5A5A);
            if (len > 0u && tase_field_keep(p, i, &keep) != TASE_OK) {
                keep = 0;
            }
            FZ_CHECK(member_value(msg, fd) == (len > 0u ? keep : 0));
            continue;
        }
        FZ_CHECK(rc == TASE_OK);
        FZ_CHECK(v == member_value(msg, fd));
        memcpy(expect + at, f->data + at, w);
    }
    n = tase_packet_encode_len(p->id, p->size != 0u ? msg : NULL, len, out, sizeof(out));
    FZ_CHECK(n == (int)(len + TASE_FRAME_OVERHEAD));
    FZ_CHECK(out[0] == TASE_SYNC1 && out[1] == TASE_SYNC2 && out[2] == TASE_SYNC3);
    FZ_CHECK(out[3] == (uint8_t)(len + 2u) && out[4] == f->group && out[5] == f->type);
    FZ_CHECK(memcmp(out + TASE_FRAME_HEADER, expect, len) == 0);
    if (len >= p->len && (len == p->len || (p->flags & TASE_LEN_TAIL) != 0u)) {
        n = tase_packet_encode(p->id, p->size != 0u ? msg : NULL, out2, sizeof(out2));
        FZ_CHECK(n == (int)(len + TASE_FRAME_OVERHEAD));
        FZ_CHECK(memcmp(out, out2, (size_t)n) == 0);
    }
}

static void check_dispatch(const tase_packet_desc_t *p, const tase_frame_t *f, int rc,
                           const tase_packet_msg_t *msg)
{
    static const tase_packet_handler_t all[TASE_PKT_COUNT] = {
        on_typed, on_typed, on_typed, on_typed, on_typed, on_typed, on_typed,
        on_typed, on_typed, on_typed, on_typed, on_typed, on_typed, on_typed,
        on_typed, on_typed, on_typed, on_typed, on_typed, on_typed, on_typed};
    static calls_t c;
    tase_dispatch_t d;
    tase_rx_stats_t st;
    int pass;
    for (pass = 0; pass < 2; pass++) { /* with and without typed handlers */
        memset(&c, 0, sizeof(c));
        memset(&st, 0, sizeof(st));
        FZ_CHECK(tase_dispatch_init(&d, pass == 0 ? all : NULL, on_default, on_error, &c, &st) ==
                 TASE_OK);
        tase_dispatch_frame(&d, f);
        FZ_CHECK(c.typed + c.deflt + c.error == 1);
        FZ_CHECK(c.frame == f);
        if (rc == TASE_EUNKNOWN) {
            FZ_CHECK(st.unknown == 1u && st.bad_length == 0u && c.deflt == 1);
        } else if (rc == TASE_ELENGTH) {
            FZ_CHECK(st.bad_length == 1u && st.unknown == 0u && c.error == 1);
            FZ_CHECK(c.err == TASE_ELENGTH);
        } else if (pass == 0) {
            FZ_CHECK(st.bad_length == 0u && st.unknown == 0u && c.typed == 1);
            FZ_CHECK(c.msg_null == (p->size == 0u));
            FZ_CHECK(p->size == 0u || memcmp(&c.msg, msg, p->size) == 0);
        } else {
            FZ_CHECK(st.bad_length == 0u && st.unknown == 0u && c.deflt == 1);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_packet_msg_t msg, canary;
    fz_in_t in = {data, size};
    uint8_t mode = fz_u8(&in), sel1 = fz_u8(&in), sel2 = fz_u8(&in), lensel = fz_u8(&in);
    const tase_packet_desc_t *p;
    tase_frame_t f;
    uint8_t group, type, *buf;
    size_t len, i;
    int rc;

    if ((mode & 1u) != 0u) {
        p = tase_schema_at(sel1 % TASE_PKT_COUNT);
        FZ_CHECK(p != NULL);
        group = TASE_ID_GROUP(p->id);
        type = TASE_ID_TYPE(p->id);
    } else {
        group = sel1;
        type = sel2;
    }
    p = tase_schema_find(group, type);
    switch ((mode >> 1) & 3u) {
    case 0: len = p != NULL ? p->len : lensel; break;
    case 1: len = lensel; break;
    case 2: len = in.n < TASE_DATA_MAX ? in.n : TASE_DATA_MAX; break;
    default: {
        int l = (p != NULL ? (int)p->len : 0) + (int)(lensel % 8u) - 4;
        len = l < 0 ? 0u : (size_t)l;
        break;
    }
    }
    /* The data ends where the allocation ends, so ASan catches even a
     * one-byte over-read (+1: never malloc(0)). */
    buf = malloc(len + 1u);
    FZ_CHECK(buf != NULL);
    for (i = 0; i < len; i++) {
        buf[1u + i] = fz_u8(&in);
    }
    f.offset = 0;
    f.group = group;
    f.type = type;
    f.len = (uint8_t)len;
    f.data = buf + 1;

    memset(&canary, CANARY, sizeof(canary));
    msg = canary;
    rc = tase_packet_decode(&f, &msg);
    if (p == NULL) {
        FZ_CHECK(rc == TASE_EUNKNOWN);
    } else if (!length_documented(p, len)) {
        FZ_CHECK(rc == TASE_ELENGTH);
        FZ_CHECK(!tase_schema_length_ok(p, len));
    } else {
        FZ_CHECK(rc == (int)len);
        FZ_CHECK(tase_schema_length_ok(p, len));
    }
    if (rc < 0) {
        FZ_CHECK(memcmp(&msg, &canary, sizeof(msg)) == 0);
    } else {
        /* nothing written beyond the packet's own struct */
        FZ_CHECK(memcmp((uint8_t *)&msg + p->size, (uint8_t *)&canary + p->size,
                        sizeof(msg) - p->size) == 0);
        if ((p->flags & TASE_LEN_TAIL) != 0u) {
            FZ_CHECK(msg.camera_pass.len == len - p->len);
            FZ_CHECK(msg.camera_pass.data == f.data + p->len);
        }
        check_roundtrip(p, &f, &msg);
    }
    /* a NULL output is only good for the packets without a struct */
    if (p != NULL && rc >= 0) {
        FZ_CHECK(tase_packet_decode(&f, NULL) == (len == 0u ? 0 : TASE_EARG));
    }
    check_dispatch(p, &f, rc, &msg);
    free(buf);
    return 0;
}
