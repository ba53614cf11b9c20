/*
 * Worst case per call of the schema (tase/schema.h): lookups over every
 * packet and a few unknown ones, length checks over every packet and the
 * lengths its rules tell apart, the by-field functions over every field
 * of every packet (in both layouts of AXIS_SETTING), the walk's moves
 * from every position, the names over every name and every name with one
 * character more (found last or not at all), each at every address mod
 * 4. The header-inline helpers are called through a noinline wrapper.
 */
#include <stdio.h>
#include <string.h>

#include "timing.h"

static const tase_packet_desc_t *a_p;
static size_t a_i, a_len;
static uint8_t a_group, a_type;
static int64_t a_value;
static const char *a_name;
static uint8_t a_data[TASE_DATA_MAX];
static tase_field_iter_t a_it, it_snap;
static uint32_t a_bits;

static void restore_it(void *ctx)
{
    (void)ctx;
    a_it = it_snap;
}

MEASURED(c_at, tase_schema_at(a_i))
MEASURED(c_find, tase_schema_find(a_group, a_type))
MEASURED(c_iter_find, tase_field_iter_find(&a_it, a_group, a_type, a_len))
MEASURED(c_length_ok, tase_schema_length_ok(a_p, a_len))
MEASURED(c_is_query, tase_schema_is_query(a_p, a_len))
MEASURED(c_reserved, tase_schema_reserved_flags(a_p))
MEASURED(c_iter_init, tase_field_iter_init(&a_it, a_p, a_len))
MEASURED(c_iter_begin, tase_field_iter_begin(&a_it, a_len))
MEASURED(c_short, tase_schema_short_(a_p, a_len))
MEASURED(c_field, tase_schema_field(a_p, a_i))
MEASURED(c_offset, tase_field_offset(a_p, a_i, a_len))
MEASURED(c_get, tase_field_get(a_p, a_i, a_data, a_len, &a_value))
MEASURED(c_keep, tase_field_keep(a_p, a_i, &a_value))
MEASURED(c_is_keep, tase_field_is_keep(a_p, a_i, a_value))
MEASURED(c_iter_get, tase_field_iter_get(&a_it, a_data, &a_value))
MEASURED(c_iter_bits, tase_field_iter_bits_(&a_it, a_data))
MEASURED(c_iter_keep_bits, tase_field_iter_keep_bits(&a_it, &a_bits))
MEASURED(c_field_at, tase_field_at_(a_it.field, a_it.short_layout))
MEASURED(c_iter_seek, tase_field_iter_seek(&a_it, a_i))
MEASURED(c_iter_next, tase_field_iter_next(&a_it))
MEASURED(c_packet_name, tase_schema_packet_name(a_p))
MEASURED(c_field_name, tase_schema_field_name(a_p, a_i))
MEASURED(c_find_name, tase_schema_find_name(a_name))
MEASURED(c_field_index, tase_schema_field_index(a_p, a_name))

/* One function measured over many inputs. */
typedef struct {
    const char *fn;
    measure_fn call;
    const char *how; /* appended to the worst input */
    worst_t w;
} probe_t;

#define INLINE_NOTE "; header-inline: through a noinline wrapper"
#define PROBE(fn, call)                                                                            \
    {                                                                                              \
        fn, call, "",                                                                              \
        {                                                                                          \
            0, ""                                                                                  \
        }                                                                                          \
    }
#define PROBE_INLINE(fn, call)                                                                     \
    {                                                                                              \
        fn, call, INLINE_NOTE,                                                                     \
        {                                                                                          \
            0, ""                                                                                  \
        }                                                                                          \
    }

static void probe_all(probe_t *pr, size_t n, const char *fmt, const char *a, const char *b,
                      unsigned long c)
{
    size_t k;
    for (k = 0; k < n; k++) {
        worst_try(&pr[k].w, measure_plain(pr[k].call), fmt, a, b, c);
    }
}

static void report_all(const probe_t *pr, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++) {
        worst_report(pr[k].fn, &pr[k].w, pr[k].how);
    }
}

/* (group, type) of every packet, then of a few the schema does not know. */
static void lookups(void)
{
    static const uint16_t unknown[] = {0x2800u, 0x00FFu, 0x4808u, 0x1042u, 0x0844u, 0xFFFFu};
    static probe_t pr[] = {PROBE("tase_schema_find", c_find),
                           {"tase_field_iter_find", c_iter_find, ", at the table length", {0, ""}},
                           PROBE("tase_schema_at", c_at),
                           PROBE("tase_schema_reserved_flags", c_reserved)};
    static char id[16];
    size_t i;
    for (i = 0; i < TASE_PKT_COUNT + COUNT(unknown); i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        uint16_t pid = p != NULL ? p->id : unknown[i - TASE_PKT_COUNT];
        a_group = (uint8_t)TASE_ID_GROUP(pid);
        a_type = (uint8_t)TASE_ID_TYPE(pid);
        a_p = p; /* NULL for the unknown ones */
        a_len = TASE_FIELD_ITER_TABLE_LEN;
        a_i = i;
        (void)snprintf(id, sizeof(id), "0x%02X/0x%02X", (unsigned)a_group, (unsigned)a_type);
        probe_all(pr, COUNT(pr), "%s %s (index %lu)", id,
                  p != NULL ? tase_schema_packet_name(p) : "(unknown)", (unsigned long)i);
    }
    report_all(pr, COUNT(pr));
}

/* Every packet at every length its rules tell apart. */
static void lengths(void)
{
    static probe_t pr[] = {
        PROBE("tase_schema_length_ok", c_length_ok), PROBE("tase_schema_is_query", c_is_query),
        PROBE("tase_field_iter_init", c_iter_init), PROBE("tase_field_iter_begin", c_iter_begin),
        PROBE_INLINE("tase_schema_short_", c_short)};
    static char len[24];
    size_t i, k;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        a_p = tase_schema_at(i);
        {
            const size_t lens[] = {0u,
                                   1u,
                                   a_p->len - 1u,
                                   a_p->len,
                                   a_p->len + 1u,
                                   TASE_DATA_MAX,
                                   TASE_DATA_MAX + 1u,
                                   TASE_FIELD_ITER_TABLE_LEN};
            for (k = 0; k < COUNT(lens); k++) {
                a_len = lens[k];
                (void)tase_field_iter_init(&a_it, a_p, a_len);
                (void)snprintf(len, sizeof(len), "%lu", (unsigned long)a_len);
                probe_all(pr, COUNT(pr), "%s, len %s", tase_schema_packet_name(a_p),
                          a_len == TASE_FIELD_ITER_TABLE_LEN ? "TASE_FIELD_ITER_TABLE_LEN" : len,
                          0ul);
            }
        }
    }
    report_all(pr, COUNT(pr));
}

/* The walk's two moves (header-inline, always inlined: through a
 * noinline wrapper), from every position of a walk over every packet in
 * each layout, the iterator put back before each call: next from the
 * walk's start, from each field and from the last (false), and seek to
 * each field and to one past the last (false). */
static void walks(void)
{
    worst_t wn = {0, ""}, ws = {0, ""};
    size_t i, f, layout;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        a_p = tase_schema_at(i);
        for (layout = 0; layout < 2u; layout++) {
            const char *lay = layout == 0u ? "" : " (short layout)";
            if (layout == 1u && (a_p->flags & TASE_LEN_SHORT) == 0u) {
                continue;
            }
            a_len = a_p->len - layout;
            (void)tase_field_iter_init(&it_snap, a_p, a_len);
            for (f = 0; f <= a_p->nfields; f++) {
                a_i = f;
                worst_try(&wn, measure_exact(restore_it, c_iter_next, NULL),
                          "%s, %lu data bytes%s, from %s", tase_schema_packet_name(a_p),
                          (unsigned long)a_len, lay,
                          f == 0u ? "the walk's start" : tase_schema_field_name(a_p, f - 1u));
                worst_try(&ws, measure_exact(restore_it, c_iter_seek, NULL),
                          "%s, %lu data bytes%s, to %s", tase_schema_packet_name(a_p),
                          (unsigned long)a_len, lay,
                          f < a_p->nfields ? tase_schema_field_name(a_p, f)
                                           : "one past the last field (false)");
                (void)tase_field_iter_next(&it_snap);
            }
        }
    }
    worst_report("tase_field_iter_next", &wn, INLINE_NOTE);
    worst_report("tase_field_iter_seek", &ws, INLINE_NOTE);
}

/* Every field of every packet, in each layout; data bytes 0xA5 (signed
 * fields negative: sign extension). */
static void fields(void)
{
    static probe_t pr[] = {PROBE("tase_schema_field", c_field),
                           PROBE("tase_field_offset", c_offset),
                           PROBE("tase_field_get", c_get),
                           PROBE("tase_field_keep", c_keep),
                           PROBE("tase_field_is_keep", c_is_keep),
                           PROBE("tase_schema_field_name", c_field_name),
                           PROBE("tase_field_iter_get", c_iter_get),
                           PROBE_INLINE("tase_field_iter_bits_", c_iter_bits),
                           PROBE_INLINE("tase_field_iter_keep_bits", c_iter_keep_bits),
                           PROBE_INLINE("tase_field_at_", c_field_at)};
    static char what[48];
    size_t i, f, layout;
    memset(a_data, 0xA5, sizeof(a_data));
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        a_p = tase_schema_at(i);
        for (layout = 0; layout < 2u; layout++) {
            if (layout == 1u && (a_p->flags & TASE_LEN_SHORT) == 0u) {
                continue;
            }
            a_len = a_p->len - layout;
            for (f = 0; f < a_p->nfields; f++) {
                int64_t keep = 0;
                a_i = f;
                (void)tase_field_keep(a_p, f, &keep);
                a_value = keep; /* the value is_keep compares all the way */
                (void)tase_field_iter_init(&a_it, a_p, a_len);
                (void)tase_field_iter_seek(&a_it, f);
                (void)snprintf(what, sizeof(what), "%s (%u-byte, at %u)",
                               tase_schema_field_name(a_p, f), (unsigned)a_it.width,
                               (unsigned)a_it.offset);
                probe_all(pr, COUNT(pr), "%s field %s, %lu data bytes",
                          tase_schema_packet_name(a_p), what, (unsigned long)a_len);
            }
        }
    }
    report_all(pr, COUNT(pr));
}

/* Every name as it is and with one character more (not found), each at
 * an address 0..3 mod 4 (the library's strcmp() takes a slower path for
 * a string that is not word-aligned). */
static void names(void)
{
    static probe_t pn[] = {PROBE("tase_schema_packet_name", c_packet_name)};
    static probe_t pf[] = {PROBE("tase_schema_find_name", c_find_name)};
    static probe_t pi[] = {PROBE("tase_schema_field_index", c_field_index)};
    static char name_mem[40 + 4] __attribute__((aligned(4)));
    static char at[48];
    size_t i, f, x, off;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        a_p = tase_schema_at(i);
        probe_all(pn, 1u, "%s%s (index %lu)", tase_schema_packet_name(a_p), "", i);
        for (x = 0; x < 2u; x++) {
            for (off = 0; off < 4u; off++) {
                char *name = &name_mem[off];
                (void)snprintf(at, sizeof(at), "at an address %lu mod 4%s", (unsigned long)off,
                               x != 0u ? ", not found" : "");
                (void)snprintf(name, sizeof(name_mem) - off, "%s%s", tase_schema_packet_name(a_p),
                               x != 0u ? "X" : "");
                a_name = name;
                probe_all(pf, 1u, "\"%s\" %s (index %lu)", name, at, i);
                for (f = 0; f < a_p->nfields; f++) {
                    (void)snprintf(name, sizeof(name_mem) - off, "%s%s",
                                   tase_schema_field_name(a_p, f), x != 0u ? "X" : "");
                    probe_all(pi, 1u, "\"%s\" in %s at an address %lu mod 4", name,
                              tase_schema_packet_name(a_p), (unsigned long)off);
                }
            }
        }
    }
    report_all(pn, 1u);
    report_all(pf, 1u);
    report_all(pi, 1u);
}

void timing_schema(void)
{
    lookups();
    lengths();
    fields();
    walks();
    names();
}
