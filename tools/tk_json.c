/* Frame -> JSON (the public contract in docs/TOOLS.md) and -> one text
 * line. Both walk the library's schema table: no per-packet code. */
#include "toolkit.h"

#include <ctype.h>
#include <string.h>
#include <strings.h>

void tk_field(const tase_packet_desc_t *p, unsigned i, tk_field_t *out)
{
    const tase_field_t *f = tase_schema_field(p, i);
    out->name = tase_schema_field_name(p, i);
    out->offset = f->offset;
    out->width = TASE_FIELD_WIDTH(f);
    out->is_signed = TASE_FIELD_IS_SIGNED(f);
}

bool tk_field_get(const tase_packet_desc_t *p, unsigned i, const uint8_t *data, size_t len,
                  long long *v)
{
    int64_t x;
    if (tase_field_get(p, i, data, len, &x) != TASE_OK) {
        return false;
    }
    *v = (long long)x;
    return true;
}

int tk_field_set(const tk_field_t *f, uint8_t *data, long long v)
{
    unsigned bits = 8u * f->width;
    long long lo = f->is_signed ? -(1ll << (bits - 1u)) : 0;
    long long hi = f->is_signed ? (1ll << (bits - 1u)) - 1 : (long long)((1ull << bits) - 1u);
    unsigned long long u;
    unsigned i;
    if (f->width >= 8u) {
        lo = f->is_signed ? INT64_MIN : 0;
        hi = INT64_MAX;
    }
    if (v < lo || v > hi) {
        return -1;
    }
    u = (unsigned long long)v;
    for (i = f->width; i > 0; i--) {
        data[f->offset + i - 1u] = (uint8_t)(u & 0xFFu);
        u >>= 8;
    }
    return 0;
}

bool tk_packet_has_tail(const tase_packet_desc_t *p)
{
    return (p->flags & TASE_LEN_TAIL) != 0;
}

const tase_packet_desc_t *tk_packet_by_name(const char *name)
{
    size_t i;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        if (strcasecmp(tase_schema_packet_name(p), name) == 0) {
            return p;
        }
    }
    tk_usage_error("unknown packet name '%s' (see 'tase list')", name);
    return NULL;
}

static void json_bytes(FILE *out, const uint8_t *p, size_t n)
{
    size_t i;
    fputc('[', out);
    for (i = 0; i < n; i++) {
        fprintf(out, i ? ",%u" : "%u", (unsigned)p[i]);
    }
    fputc(']', out);
}

void tk_json_frame(FILE *out, const tase_frame_t *f, const char *dir, const char *time)
{
    const tase_packet_desc_t *p = tase_schema_find(f->group, f->type);
    unsigned i;
    fprintf(out, "{\"offset\":%lu,", (unsigned long)f->offset);
    if (time != NULL) {
        fprintf(out, "\"time\":%s,", time);
    }
    if (dir != NULL) {
        fprintf(out, "\"dir\":\"%s\",", dir);
    }
    fprintf(out, "\"group\":%u,\"type\":%u,\"name\":\"%s\",\"size\":%u,", (unsigned)f->group,
            (unsigned)f->type, p != NULL ? tase_schema_packet_name(p) : "UNKNOWN",
            (unsigned)f->len);
    if (p == NULL) {
        fputs("\"fields\":{\"data\":", out);
        json_bytes(out, f->data, f->len);
        fputs("}}\n", out);
        return;
    }
    if (!tase_schema_length_ok(p, f->len)) {
        fputs("\"error\":\"wrong length\"}\n", out);
        return;
    }
    fputs("\"fields\":{", out);
    for (i = 0; i < p->nfields; i++) {
        long long v;
        /* short accepted forms (queries, CAMERA_CMD's one byte) carry only
         * the fields that fit */
        if (!tk_field_get(p, i, f->data, f->len, &v)) {
            break;
        }
        fprintf(out, "%s\"%s\":%lld", i ? "," : "", tase_schema_field_name(p, i), v);
    }
    fputc('}', out);
    if (tk_packet_has_tail(p)) {
        fputs(",\"data\":", out);
        json_bytes(out, f->data + p->len, f->len > p->len ? (size_t)(f->len - p->len) : 0u);
    }
    fputs("}\n", out);
}

void tk_text_frame(FILE *out, const tase_frame_t *f)
{
    const tase_packet_desc_t *p = tase_schema_find(f->group, f->type);
    unsigned i;
    if (p == NULL) {
        fprintf(out, "UNKNOWN group 0x%02X type 0x%02X, %u bytes\n", (unsigned)f->group,
                (unsigned)f->type, (unsigned)f->len);
        return;
    }
    fputs(tase_schema_packet_name(p), out);
    if (!tase_schema_length_ok(p, f->len)) {
        fprintf(out, ": wrong length %u\n", (unsigned)f->len);
        return;
    }
    if (f->len == 0) {
        fputs(p->len == 0 ? "\n" : " (query)\n", out);
        return;
    }
    for (i = 0; i < p->nfields; i++) {
        long long v;
        if (!tk_field_get(p, i, f->data, f->len, &v)) {
            break;
        }
        fprintf(out, " %s=%lld", tase_schema_field_name(p, i), v);
    }
    if (tk_packet_has_tail(p) && f->len > p->len) {
        fprintf(out, " +%u data bytes", (unsigned)(f->len - p->len));
    }
    fputc('\n', out);
}
