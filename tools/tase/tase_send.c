/* tase: `send` and `query`, any packet by name with its fields given as
 * field=value in raw wire integers (the fields left out kept, filled from
 * the gimbal's settings, or refused), and `list`, the table they read. */
#include <string.h>

#include "tase/codec.h"
#include "tase/flags.h"
#include "tase_cli.h"

/* ---- field assignments ---- */

void cli_fields_init(cli_fields_t *fs, const tase_packet_desc_t *p, size_t len)
{
    memset(fs, 0, sizeof(*fs));
    fs->p = p;
    fs->len = len;
}

static size_t parse_tail(const char *v, uint8_t *out, size_t cap)
{
    size_t n = 0, item = 0;
    const char *s = v;
    if (*v == '\0') {
        tk_usage_error("empty data list (expected data=BYTE,BYTE,...)");
    }
    for (;;) {
        const char *comma = strchr(s, ',');
        size_t l = comma != NULL ? (size_t)(comma - s) : strlen(s);
        char tok[32];
        long long b;
        int rc;
        item++;
        if (l == 0) {
            tk_usage_error("empty item %lu in data list '%s'", (unsigned long)item, v);
        }
        if (l >= sizeof(tok)) {
            tk_usage_error("bad data byte in '%s' (expected 0..255)", v);
        }
        memcpy(tok, s, l);
        tok[l] = '\0';
        if (n >= cap) {
            tk_usage_error("too many data bytes (at most %lu)", (unsigned long)cap);
        }
        rc = tk_parse_int(tok, 0, 255, &b, NULL);
        if (rc != TK_NUM_OK) {
            tk_usage_error("bad data byte '%s': %s", tok,
                           rc == TK_NUM_RANGE ? "out of range 0..255"
                                              : "not a number (decimal or 0x hex)");
        }
        out[n++] = (uint8_t)b;
        if (comma == NULL) {
            return n;
        }
        s = comma + 1;
    }
}

/* Apply one "field=value" argument; usage error on anything wrong. */
static void fields_assign(cli_fields_t *fs, const char *arg)
{
    const tase_packet_desc_t *p = fs->p;
    const char *name = tase_schema_packet_name(p);
    const char *eq = strchr(arg, '=');
    char fname[64], range[64];
    size_t fl = (size_t)(eq - arg);
    int fi, rc;
    tk_field_t fd;
    long long val;
    if (fl == 0 || fl >= sizeof(fname)) {
        tk_usage_error("bad assignment '%s' (expected field=value)", arg);
    }
    memcpy(fname, arg, fl);
    fname[fl] = '\0';
    if (tk_packet_has_tail(p) && strcmp(fname, "data") == 0) {
        if (fs->tail_given) {
            tk_usage_error("%s.data given twice", name);
        }
        fs->tail = parse_tail(eq + 1, fs->data + p->len, TASE_DATA_MAX - p->len);
        fs->tail_given = true;
        return;
    }
    fi = tase_schema_field_index(p, fname);
    if (fi < 0 || (size_t)fi >= sizeof(fs->given)) {
        tk_usage_error("%s has no field '%s' (see 'tase list')", name, fname);
    }
    if (fs->given[fi]) {
        tk_usage_error("%s.%s given twice", name, fname);
    }
    tk_field(p, (unsigned)fi, fs->len, &fd);
    tk_field_range(&fd, range, sizeof(range));
    rc = tk_field_parse(&fd, eq + 1, &val);
    if (eq[1] == '\0') {
        tk_usage_error("bad value '' for %s.%s: empty (expected an integer %s)", name, fname,
                       range);
    } else if (rc == TK_NUM_SYNTAX) {
        tk_usage_error("bad value '%s' for %s.%s: not a number (decimal, or 0x hex, with an "
                       "optional sign)",
                       eq + 1, name, fname);
    } else if (rc != TK_NUM_OK) {
        tk_usage_error("bad value '%s' for %s.%s: out of range %s (%s %u-bit)", eq + 1, name, fname,
                       range, fd.is_signed ? "signed" : "unsigned", 8u * fd.width);
    }
    (void)tk_field_set(&fd, fs->data, val);
    fs->given[fi] = true;
}

long long cli_fields_value(const cli_fields_t *fs, unsigned i)
{
    long long v = 0;
    (void)tk_field_get(fs->p, i, fs->data, fs->len, &v);
    return v;
}

/* Set field `name` (which must exist) as if given on the command line. */
void cli_fields_set(cli_fields_t *fs, const char *name, long long v)
{
    int fi = tase_schema_field_index(fs->p, name);
    tk_field_t fd;
    if (fi < 0) {
        tk_die("internal error: no field %s", name);
    }
    tk_field(fs->p, (unsigned)fi, fs->len, &fd);
    if (tk_field_set(&fd, fs->data, v) != 0) {
        tk_die("internal error: %s=%lld does not fit", name, v);
    }
    fs->given[fi] = true;
}

/* The fields that lie within `len` bytes. */
unsigned cli_fields_within(const tase_packet_desc_t *p, size_t len)
{
    unsigned i;
    for (i = 0; i < p->nfields; i++) {
        tk_field_t fd;
        tk_field(p, i, len, &fd);
        if (fd.offset + fd.width > len) {
            break;
        }
    }
    return i;
}

/* Move the fields set so far to the layout of `len` data bytes (a setup
 * packet sent in the layout the gimbal answered with: AXIS_SETTING's 22 or
 * 23 bytes; the widths are the same, offsets move). A field that does not
 * fit `len` is dropped. */
static void fields_relayout(cli_fields_t *fs, size_t len)
{
    uint8_t data[TASE_DATA_MAX];
    unsigned i;
    memset(data, 0, sizeof(data));
    for (i = 0; i < fs->p->nfields && i < sizeof(fs->given); i++) {
        tk_field_t fd;
        long long v;
        if (!fs->given[i]) {
            continue;
        }
        tk_field(fs->p, i, len, &fd);
        if (fd.offset + fd.width > len || !tk_field_get(fs->p, i, fs->data, fs->len, &v)) {
            fs->given[i] = false;
            continue;
        }
        (void)tk_field_set(&fd, data, v);
    }
    memcpy(fs->data, data, sizeof(data));
    fs->len = len;
}

/* Fields [0, n) left out that have a "do not change" value in the spec
 * (the schema's, tase_field_keep()) take it. */
void cli_fields_keep(cli_fields_t *fs, unsigned n)
{
    unsigned i;
    for (i = 0; i < n; i++) {
        int64_t keep;
        if (!fs->given[i] && tase_field_keep(fs->p, i, &keep) == TASE_OK) {
            cli_fields_set(fs, tase_schema_field_name(fs->p, i), (long long)keep);
        }
    }
}

/* A comma-separated list of the names of fields [0, n) not given. */
static size_t missing_list(const cli_fields_t *fs, unsigned n, char *buf, size_t cap)
{
    size_t count = 0, used = 0;
    unsigned i;
    buf[0] = '\0';
    for (i = 0; i < n; i++) {
        if (!fs->given[i]) {
            int w = snprintf(buf + used, cap - used, "%s%s", count ? ", " : "",
                             tase_schema_field_name(fs->p, i));
            if (w > 0 && (size_t)w < cap - used) {
                used += (size_t)w;
            }
            count++;
        }
    }
    return count;
}

/* ---- send ---- */

/* Refuse (usage error, nothing sent) a flags value with a bit the spec
 * reserves (tase_schema_reserved_flags(): a contiguous run of spec bits,
 * 0 = MSB). */
static void check_reserved_flags(const cli_fields_t *fs, unsigned nf)
{
    const tase_packet_desc_t *p = fs->p;
    int fi = tase_schema_field_index(p, "flags");
    unsigned mask = tase_schema_reserved_flags(p);
    unsigned first = 0;
    unsigned last;
    long long v;
    if (mask == 0u || fi < 0 || (unsigned)fi >= nf || !fs->given[fi]) {
        return;
    }
    v = cli_fields_value(fs, (unsigned)fi);
    if ((v & (long long)mask) == 0) {
        return;
    }
    while ((mask & (0x80u >> first)) == 0u) {
        first++;
    }
    last = first;
    while (last < 7u && (mask & (0x80u >> (last + 1u))) != 0u) {
        last++;
    }
    tk_usage_error("%s flags=0x%02llX sets reserved bits %u-%u (0x%02X); nothing sent (--raw "
                   "sends it anyway)",
                   tase_schema_packet_name(p), v, first, last, mask);
}

/* Whether a GIMBAL_CMD's flags are a mode of the spec's table 5: the
 * library's answer (tase_command_check_data(), what the host role checks),
 * asked of the packet with pan and tilt 0 (in range for every mode), so
 * that only the flags can fail; a position out of range has its own
 * message below. The names of the modes (cli_gimbal_mode(),
 * cli_refuse_gimbal_cmd()) are only for the messages. */
static bool gimbal_mode_ok(const cli_fields_t *fs, size_t len)
{
    cli_fields_t probe = *fs;
    cli_fields_set(&probe, "pan", 0);
    cli_fields_set(&probe, "tilt", 0);
    return tase_command_check_data(TASE_ID_GIMBAL_CMD, probe.data, len) == TASE_OK;
}

int cli_cmd_send(cli_args_t *a)
{
    cli_link_opts_t lo = {NULL, NULL, CLI_DEFAULT_BAUD, false, NULL};
    cli_send_opts_t o = {
        false, false, false, -1, {CLI_DEFAULT_TIMEOUT_MS, CLI_DEFAULT_RETRIES, false}};
    const char *name = NULL, *v;
    const char *assign[64];
    size_t nassign = 0, i, len;
    unsigned nf;
    bool setup, rmw = false, relaid = false, temp_default = false;
    int tfi;
    const tase_packet_desc_t *p;
    cli_fields_t fs;
    cli_session_t s;
    while (a->i < a->argc) {
        if (cli_common_opt(a) || cli_link_opt(a, &lo) || cli_req_opt(a, &o.r)) {
            continue;
        }
        if (cli_opt(a, "--zero", false, &v)) {
            o.zero = true;
        } else if (cli_opt(a, "--no-wait", false, &v)) {
            o.no_wait = true;
        } else if (cli_opt(a, "--raw", false, &v)) {
            o.raw = true;
        } else if (cli_opt(a, "--len", true, &v)) {
            o.len = cli_int_opt_value("--len", v, 0, TASE_DATA_MAX);
        } else if (cli_is_arg(a, false) && name == NULL) {
            name = a->argv[a->i++];
        } else if (cli_is_arg(a, false) && strchr(a->argv[a->i], '=') != NULL) {
            if (nassign == sizeof(assign) / sizeof(assign[0])) {
                tk_usage_error("too many field assignments");
            }
            assign[nassign++] = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
    if (name == NULL) {
        tk_usage_error("send needs a packet name (e.g. PACKET_RATE; see 'tase list')");
    }
    p = tk_packet_by_name(name);
    name = tase_schema_packet_name(p);
    if ((p->flags & TASE_DIR_IN) == 0) {
        tk_usage_error("%s is sent by the gimbal, not to it", name);
    }
    if (p->id == TASE_ID_SYSTEM_VERSION) {
        tk_usage_error("SYSTEM_VERSION is query-only: use 'tase query SYSTEM_VERSION'");
    }
    setup = TASE_ID_GROUP(p->id) == TASE_GROUP_SETUP;
    cli_fields_init(&fs, p, o.len >= 0 ? (size_t)o.len : p->len);
    for (i = 0; i < nassign; i++) {
        fields_assign(&fs, assign[i]);
    }
    len = o.len >= 0 ? (size_t)o.len : p->len + fs.tail;
    if (tk_packet_has_tail(p) && len != p->len + fs.tail) {
        /* CAMERA_PASS: its length is its fields and the data= bytes; any
         * other --len pads the camera's bytes with zeros or drops some */
        tk_usage_error("%s with %lu data byte%s is %lu bytes, not --len %lu; nothing sent", name,
                       (unsigned long)fs.tail, fs.tail == 1u ? "" : "s",
                       (unsigned long)(p->len + fs.tail), (unsigned long)len);
    }
    if (!tase_schema_length_ok(p, len)) {
        tk_usage_error("%s does not accept a data length of %lu", name, (unsigned long)len);
    }
    nf = cli_fields_within(p, len);
    for (i = nf; i < p->nfields; i++) {
        if (fs.given[i]) {
            /* a value the form cannot carry was dropped without a word */
            tk_usage_error("%s: the %lu-byte form does not carry %s; nothing sent", name,
                           (unsigned long)len, tase_schema_field_name(p, (unsigned)i));
        }
    }
    tfi = tase_schema_field_index(p, "temporary");
    if (setup && tfi >= 0 && (unsigned)tfi < nf && !fs.given[tfi]) {
        /* A setup packet with temporary 0 is written to the gimbal's
         * non-volatile storage (spec 4.4.1, 4.4.3): a bench change is kept
         * for this power cycle only unless temporary=0 asks to store it. */
        cli_fields_set(&fs, "temporary", TASE_SETUP_TEMPORARY);
        temp_default = true;
    }
    if (p->id == TASE_ID_GIMBAL_CMD && len > 0) {
        int fi = tase_schema_field_index(p, "flags");
        if (!fs.given[fi]) {
            cli_refuse_gimbal_cmd("needs flags");
        }
        if (!gimbal_mode_ok(&fs, len)) {
            cli_refuse_gimbal_cmd("flags is not a mode of the spec's table 5");
        }
    }
    if (!o.raw) {
        check_reserved_flags(&fs, nf);
    }
    cli_fields_keep(&fs, nf);
    if (!o.zero) {
        char missing[512];
        size_t nmiss = missing_list(&fs, nf, missing, sizeof(missing));
        if (nmiss > 0 && setup && !o.no_wait) {
            rmw = true; /* fill them from the gimbal's current settings */
        } else if (nmiss > 0) {
            tk_usage_error("%s needs every field%s: missing %s (give them, or --zero to send 0)",
                           name, setup ? " with --no-wait (nothing is queried)" : "", missing);
        }
    }
    if (tase_command_check_data(p->id, fs.data, len) == TASE_ERANGE) {
        /* the flags were checked above: a value beyond the spec's ranges
         * (tase_command_check(); the library would refuse it too) */
        tk_usage_error("%s", p->id == TASE_ID_GIMBAL_CMD
                                 ? "GIMBAL_CMD position outside pan -180..180 / tilt -270..90 "
                                   "degrees (pan/tilt in 1/100 degree); nothing sent"
                                 : "SPOI_CMD lat/lon outside -90..90 / -180..180 degrees "
                                   "(milli-arcseconds); nothing sent");
    }
    if (setup && !o.no_wait && o.len < 0 && (p->flags & TASE_LEN_SHORT) != 0u) {
        /* a packet of two layouts (AXIS_SETTING, PROTOCOL-NOTES S2): the
         * query's answer tells which one this gimbal uses, even when
         * every field is given */
        rmw = true;
    }
    cli_session_open(&s, &lo, NULL, NULL);
    if (rmw) {
        uint8_t cur[TASE_DATA_MAX];
        unsigned k;
        int n = cli_transact_note(&s, p, NULL, 0, cur, &o.r,
                                  " (only the query went out, to read the gimbal's settings; the "
                                  "new setting was not sent)");
        if (n <= 0 || !tase_schema_length_ok(p, (size_t)n)) {
            tk_die("%s query answered with %d data bytes, not a length of %s; nothing was set",
                   name, n, name);
        }
        if (o.len < 0 && (size_t)n != len) {
            /* the layout this gimbal uses (AXIS_SETTING's 22 bytes): send
             * in it, as the gimbal answered, unless --len says otherwise */
            fields_relayout(&fs, (size_t)n);
            len = (size_t)n;
            nf = cli_fields_within(p, len);
            relaid = true;
        }
        /* each field read at its place in the answer's own layout */
        for (k = 0; k < nf; k++) {
            long long cv;
            if (!fs.given[k] && tk_field_get(p, k, cur, (size_t)n, &cv)) {
                cli_fields_set(&fs, tase_schema_field_name(p, k), cv);
            }
        }
    }
    cli_send_fields(&s, &fs, len, &o);
    if (relaid && !o.r.json) {
        printf("  = sent in the %lu-byte layout the gimbal answered the query with\n",
               (unsigned long)len);
    }
    if (temp_default && !o.r.json) {
        printf("  = temporary=1 (the default): not written to the gimbal's non-volatile "
               "storage; temporary=0 stores it\n");
    }
    cli_session_close(&s);
    return TK_EXIT_OK;
}

/* ---- query ---- */

int cli_cmd_query(cli_args_t *a)
{
    cli_link_opts_t lo = {NULL, NULL, CLI_DEFAULT_BAUD, false, NULL};
    cli_req_opts_t r = {CLI_DEFAULT_TIMEOUT_MS, CLI_DEFAULT_RETRIES, false};
    const char *name = NULL;
    const tase_packet_desc_t *p;
    cli_session_t s;
    uint8_t reply[TASE_DATA_MAX];
    int n;
    while (a->i < a->argc) {
        if (cli_common_opt(a) || cli_link_opt(a, &lo) || cli_req_opt(a, &r)) {
            continue;
        }
        if (cli_is_arg(a, false) && name == NULL) {
            name = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
    if (name == NULL) {
        tk_usage_error("query needs a packet name (e.g. SYSTEM_VERSION)");
    }
    p = tk_packet_by_name(name);
    if ((p->flags & TASE_LEN_QUERY) == 0) {
        tk_usage_error("%s has no zero-length query form (queryable: the setup packets, "
                       "SPOI_CMD, SYSTEM_VERSION)",
                       tase_schema_packet_name(p));
    }
    cli_session_open(&s, &lo, NULL, NULL);
    n = cli_transact(&s, p, NULL, 0, reply, &r);
    cli_print_packet(p, reply, (size_t)n, r.json, "out", NULL);
    cli_session_close(&s);
    if (!tase_schema_length_ok(p, (size_t)n)) {
        /* shown as it came ("wrong length"), but no answer to the query */
        tk_die("the answer to %s has %d data bytes, a length %s does not have",
               tase_schema_packet_name(p), n, tase_schema_packet_name(p));
    }
    return TK_EXIT_OK;
}

/* ---- list ---- */

int cli_cmd_list(cli_args_t *a)
{
    size_t i;
    unsigned j;
    while (a->i < a->argc) {
        if (!cli_common_opt(a)) {
            cli_bad_arg(a);
        }
    }
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        unsigned dir = p->flags & TASE_DIR_BOTH;
        char other[32] = ""; /* the other lengths accepted */
        if ((p->flags & TASE_LEN_SHORT1) != 0u) {
            (void)snprintf(other, sizeof other, "or 1"); /* CAMERA_CMD: C9 */
        } else if ((p->flags & TASE_LEN_SHORT) != 0u) {
            (void)snprintf(other, sizeof other, "or %u", (unsigned)p->len - 1u); /* S2 */
        }
        if ((p->flags & TASE_LEN_QUERY) != 0u) {
            (void)snprintf(other + strlen(other), sizeof other - strlen(other), "%squery",
                           other[0] != '\0' ? "; " : "");
        }
        printf("%-19s 0x%02X/0x%02X %-4s %3u%s%s%s%s:", tase_schema_packet_name(p),
               (unsigned)TASE_ID_GROUP(p->id), (unsigned)TASE_ID_TYPE(p->id),
               dir == TASE_DIR_BOTH ? "both" : (dir == TASE_DIR_IN ? "in" : "out"),
               (unsigned)p->len, tk_packet_has_tail(p) ? "+" : "", other[0] != '\0' ? " (" : "",
               other, other[0] != '\0' ? ")" : "");
        for (j = 0; j < p->nfields; j++) {
            tk_field_t f;
            tk_field(p, j, p->len, &f);
            printf(" %s:%c%u", f.name, f.is_signed ? 's' : 'u', 8u * f.width);
        }
        printf("%s\n", tk_packet_has_tail(p) ? " data:bytes" : "");
    }
    tk_stdout_flush();
    return TK_EXIT_OK;
}
