/* Prints the packet table of tools/wireshark/tase.lua from the library's
 * schema (tase/schema.h), so the dissector names every packet and field
 * exactly as `tase list` and the JSON contract do. The generated block sits
 * between the "BEGIN GENERATED" and "END GENERATED" lines of tase.lua;
 * tests/tools/wireshark.sh fails when they differ (`--fix` rewrites it).
 * Usage: tase-schema-lua > block */
#include <stdio.h>

#include "tase/schema.h"

int main(void)
{
    size_t i;
    tase_field_iter_t it;
    puts("-- BEGIN GENERATED (tools/wireshark/schema_lua.c; do not edit by hand)");
    puts("-- {group, type, name, data length, flags,");
    puts("--  {{field, offset, width, signed[, shift]}...}}");
    puts("-- flags: q = zero-length query form, 1 = one-byte form, t = free bytes after");
    puts("-- the fields (CAMERA_PASS), s = a short layout one byte shorter, where the");
    puts("-- fields marked shift sit one byte earlier (AXIS_SETTING's 22 bytes)");
    puts("local SCHEMA = {");
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        printf("    {0x%02X, 0x%02X, \"%s\", %u, \"%s%s%s%s\", {", (unsigned)TASE_ID_GROUP(p->id),
               (unsigned)TASE_ID_TYPE(p->id), tase_schema_packet_name(p), (unsigned)p->len,
               (p->flags & TASE_LEN_QUERY) != 0u ? "q" : "",
               (p->flags & TASE_LEN_SHORT1) != 0u ? "1" : "",
               (p->flags & TASE_LEN_TAIL) != 0u ? "t" : "",
               (p->flags & TASE_LEN_SHORT) != 0u ? "s" : "");
        (void)tase_field_iter_init(&it, p, TASE_FIELD_ITER_TABLE_LEN);
        while (tase_field_iter_next(&it)) {
            printf("%s{\"%s\", %u, %u, %s%s},", it.index % 3u == 0u ? "\n        " : " ",
                   tase_schema_field_name(p, it.index), (unsigned)it.offset, (unsigned)it.width,
                   TASE_FIELD_IS_SIGNED(it.field) ? "true" : "false",
                   (p->flags & TASE_LEN_SHORT) != 0u && (it.field->fmt & TASE_FIELD_SHIFT) != 0u
                       ? ", true"
                       : "");
        }
        puts(p->nfields > 0 ? "\n    }}," : "}},");
    }
    puts("}");
    puts("-- END GENERATED");
    return 0;
}
