/* Frame -> JSON (the public contract in docs/TOOLS.md) or -> one text
 * line. Both walk the library's schema table: no per-packet code. The
 * JSON is built by hand into a line buffer (no printf per field): decode
 * prints millions of lines, and this is most of its time. */
#define _POSIX_C_SOURCE 200809L /* localtime_r */

#include "toolkit.h"

#include <string.h>
#include <strings.h>
#include <time.h>

void tk_field(const tase_packet_desc_t *p, unsigned i, size_t len, tk_field_t *out)
{
    const tase_field_t *f = tase_schema_field(p, i);
    int off = tase_field_offset(p, i, len);
    out->name = tase_schema_field_name(p, i);
    out->offset = off >= 0 ? (unsigned)off : f->offset;
    out->width = TASE_FIELD_WIDTH(f);
    out->is_signed = TASE_FIELD_IS_SIGNED(f);
    {
        int64_t keep = 0;
        out->has_keep = tase_field_keep(p, i, &keep) == TASE_OK;
        out->keep = (long long)keep;
    }
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

static void field_limits(const tk_field_t *f, long long *lo, long long *hi)
{
    unsigned bits = 8u * f->width;
    if (f->width >= 8u) {
        *lo = f->is_signed ? INT64_MIN : 0;
        *hi = INT64_MAX;
        return;
    }
    *lo = f->is_signed ? -(1ll << (bits - 1u)) : 0;
    *hi = f->is_signed ? (1ll << (bits - 1u)) - 1 : (long long)((1ull << bits) - 1u);
}

int tk_field_set(const tk_field_t *f, uint8_t *data, long long v)
{
    long long lo, hi;
    unsigned long long u;
    unsigned i;
    field_limits(f, &lo, &hi);
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

void tk_field_range(const tk_field_t *f, char *buf, size_t cap)
{
    long long lo, hi;
    field_limits(f, &lo, &hi);
    snprintf(buf, cap, "%lld..%lld", lo, hi);
}

int tk_field_parse(const tk_field_t *f, const char *s, long long *v)
{
    long long lo, hi, x;
    bool hex = false;
    int rc;
    field_limits(f, &lo, &hi);
    rc = tk_parse_int(s, INT64_MIN, INT64_MAX, &x, &hex);
    if (rc != TK_NUM_OK) {
        return rc;
    }
    if (hex && f->is_signed && f->has_keep && f->keep < 0 && f->width < 8u &&
        x == f->keep + 2 * hi + 2) {
        /* the "do not change" code as the spec writes it (0xFFFF); any
         * other pattern beyond the range is refused, never wrapped into a
         * value of the other sign */
        x = f->keep;
    }
    if (x < lo || x > hi) {
        return TK_NUM_RANGE;
    }
    *v = x;
    return TK_NUM_OK;
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
    if (strcasecmp(name, "GIMBAL_TELEMETRY") == 0) {
        /* table 10's name, which 4.3.3 also gives GEOREFERENCE_DATA */
        tk_usage_error("unknown packet name '%s': table 10 gives it to 0x08/0x40, GIMBAL_RATE "
                       "(4.2.2); 4.3.3 calls GEOREFERENCE_DATA so too (PROTOCOL-NOTES D1)",
                       name);
    }
    tk_usage_error("unknown packet name '%s' (see 'tase list')", name);
    return NULL;
}

/* ---- engineering units ---- */

typedef enum {
    U_DEG,
    U_DPS,
    U_S,
    U_M,
    U_MPS,
    U_MPS2,
    U_DPS2,
    U_MM,
    U_HZ,
    U_RATIO,
    U_GAIN,
    U_PLAIN
} unit_kind_t;

static const struct {
    const char *suffix; /* JSON key: field name + "_" + suffix */
    const char *label;  /* text output */
} unit_kinds[] = {
    [U_DEG] = {"deg", "deg"},
    [U_DPS] = {"dps", "deg/s"},
    [U_S] = {"s", "s"},
    [U_M] = {"m", "m"},
    [U_MPS] = {"mps", "m/s"},
    [U_MPS2] = {"mps2", "m/s^2"},
    [U_DPS2] = {"dps2", "deg/s^2"},
    [U_MM] = {"mm", "mm"},
    [U_HZ] = {"hz", "Hz"},
    [U_RATIO] = {"x", "x"},
    [U_GAIN] = {"dps_per_deg", "(deg/s)/deg"},
    [U_PLAIN] = {"", ""},
};

typedef struct {
    uint8_t pkt;       /* TASE_PKT_* */
    const char *field; /* schema field name */
    uint8_t kind;      /* unit_kind_t */
    uint8_t decimals;
    double scale; /* unit per wire count */
} unit_t;

#define MAS (1.0 / 3600000.0)
#define ACC (1.0 / 300.0)

/* The scale of every field whose unit the spec states unambiguously.
 * GIMBAL_CMD (degrees or deg/s by its flags) and CAMERA_CMD (HFOV or
 * zoom by its sign) are left raw. */
static const unit_t units[] = {
    {TASE_PKT_GIMBAL_ANGLE, "pan", U_DEG, 2, 0.01},
    {TASE_PKT_GIMBAL_ANGLE, "tilt", U_DEG, 2, 0.01},
    {TASE_PKT_GIMBAL_ANGLE, "roll", U_DEG, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "time", U_S, 3, 0.001},
    {TASE_PKT_GIMBAL_RATE, "pan_rate", U_DPS, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "tilt_rate", U_DPS, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "roll_rate", U_DPS, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "p", U_DPS, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "q", U_DPS, 2, 0.01},
    {TASE_PKT_GIMBAL_RATE, "r", U_DPS, 2, 0.01},
    {TASE_PKT_HOST_SENSOR, "time", U_S, 3, 0.001},
    {TASE_PKT_HOST_SENSOR, "roll", U_DPS, 2, 0.01},
    {TASE_PKT_HOST_SENSOR, "pitch", U_DPS, 2, 0.01},
    {TASE_PKT_HOST_SENSOR, "yaw", U_DPS, 2, 0.01},
    {TASE_PKT_HOST_SENSOR, "x_accel", U_MPS2, 4, ACC},
    {TASE_PKT_HOST_SENSOR, "y_accel", U_MPS2, 4, ACC},
    {TASE_PKT_HOST_SENSOR, "z_accel", U_MPS2, 4, ACC},
    {TASE_PKT_HOST_SENSOR, "tas", U_MPS, 2, 0.01},
    {TASE_PKT_HOST_ATTITUDE, "time", U_S, 3, 0.001},
    {TASE_PKT_HOST_ATTITUDE, "roll", U_DEG, 2, 0.01},
    {TASE_PKT_HOST_ATTITUDE, "pitch", U_DEG, 2, 0.01},
    {TASE_PKT_HOST_ATTITUDE, "yaw", U_DEG, 2, 0.01},
    {TASE_PKT_HOST_GPS_DATA, "time", U_S, 3, 0.001},
    {TASE_PKT_HOST_GPS_DATA, "lat", U_DEG, 7, MAS},
    {TASE_PKT_HOST_GPS_DATA, "lon", U_DEG, 7, MAS},
    {TASE_PKT_HOST_GPS_DATA, "height", U_M, 2, 0.01},
    {TASE_PKT_HOST_GPS_DATA, "vnorth", U_MPS, 2, 0.01},
    {TASE_PKT_HOST_GPS_DATA, "veast", U_MPS, 2, 0.01},
    {TASE_PKT_HOST_GPS_DATA, "vdown", U_MPS, 2, 0.01},
    {TASE_PKT_SPOI_CMD, "lat", U_DEG, 7, MAS},
    {TASE_PKT_SPOI_CMD, "lon", U_DEG, 7, MAS},
    {TASE_PKT_SPOI_CMD, "height", U_M, 2, 0.01},
    {TASE_PKT_SPOI_CMD, "vnorth", U_MPS, 2, 0.01},
    {TASE_PKT_SPOI_CMD, "veast", U_MPS, 2, 0.01},
    {TASE_PKT_SPOI_CMD, "vdown", U_MPS, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "time", U_S, 3, 0.001},
    {TASE_PKT_GEOREFERENCE_DATA, "lat", U_DEG, 7, MAS},
    {TASE_PKT_GEOREFERENCE_DATA, "lon", U_DEG, 7, MAS},
    {TASE_PKT_GEOREFERENCE_DATA, "height", U_M, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "vnorth", U_MPS, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "veast", U_MPS, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "vdown", U_MPS, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "pdop", U_PLAIN, 1, 0.1},
    {TASE_PKT_GEOREFERENCE_DATA, "camera_roll", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "camera_pitch", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "camera_yaw", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "hfov", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "vfov", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "focal", U_MM, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "mount_roll", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "mount_pitch", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "mount_yaw", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "pan", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "tilt", U_DEG, 2, 0.01},
    {TASE_PKT_GEOREFERENCE_DATA, "roll", U_DEG, 2, 0.01},
    {TASE_PKT_SENSOR_FILTER, "cutoff", U_HZ, 1, 0.1},
    {TASE_PKT_SENSOR_FILTER, "decimation", U_DPS, 1, 0.1},
    {TASE_PKT_AXIS_SETTING, "pan_nogo_center", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "pan_nogo_range", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "tilt_nogo_center", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "tilt_nogo_range", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "roll_nogo_center", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "roll_nogo_range", U_DEG, 2, 0.01},
    {TASE_PKT_AXIS_SETTING, "pan_max_rate", U_DPS, 0, 5.0},
    {TASE_PKT_AXIS_SETTING, "tilt_max_rate", U_DPS, 0, 5.0},
    {TASE_PKT_AXIS_SETTING, "roll_max_rate", U_DPS, 0, 5.0},
    {TASE_PKT_AXIS_SETTING, "pan_max_accel", U_DPS2, 0, 200.0},
    {TASE_PKT_AXIS_SETTING, "tilt_max_accel", U_DPS2, 0, 200.0},
    {TASE_PKT_AXIS_SETTING, "roll_max_accel", U_DPS2, 0, 200.0},
    {TASE_PKT_AXIS_SETTING, "pan_pos_gain", U_GAIN, 1, 0.1},
    {TASE_PKT_AXIS_SETTING, "tilt_pos_gain", U_GAIN, 1, 0.1},
    {TASE_PKT_AXIS_SETTING, "roll_pos_gain", U_GAIN, 1, 0.1},
    {TASE_PKT_SYSTEM_VERSION, "max_hfov_a", U_DEG, 2, 0.01},
    {TASE_PKT_SYSTEM_VERSION, "min_hfov_a", U_DEG, 2, 0.01},
    {TASE_PKT_SYSTEM_VERSION, "max_hfov_b", U_DEG, 2, 0.01},
    {TASE_PKT_SYSTEM_VERSION, "min_hfov_b", U_DEG, 2, 0.01},
    {TASE_PKT_SYSTEM_VERSION, "max_hfov_c", U_DEG, 2, 0.01},
    {TASE_PKT_SYSTEM_VERSION, "min_hfov_c", U_DEG, 2, 0.01},
    {TASE_PKT_GPS_LEVER_ARM, "x", U_M, 3, 0.001},
    {TASE_PKT_GPS_LEVER_ARM, "y", U_M, 3, 0.001},
    {TASE_PKT_GPS_LEVER_ARM, "z", U_M, 3, 0.001},
    {TASE_PKT_CAMERA_ALIGN, "zoom_1", U_RATIO, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "pan_err_1", U_DEG, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "tilt_err_1", U_DEG, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "roll_err_1", U_DEG, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "zoom_2", U_RATIO, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "pan_err_2", U_DEG, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "tilt_err_2", U_DEG, 2, 0.01},
    {TASE_PKT_CAMERA_ALIGN, "roll_err_2", U_DEG, 2, 0.01},
};

static const unit_t *unit_of(const tase_packet_desc_t *p, const char *field)
{
    size_t i;
    for (i = 0; i < sizeof(units) / sizeof(units[0]); i++) {
        if (units[i].pkt == p->index && strcmp(units[i].field, field) == 0) {
            return &units[i];
        }
    }
    return NULL;
}

/* Whether all ones in the field of u mean "unavailable": the spec says so
 * of HOST_SENSOR's TAS only (4.2.3, "0xFFFF if this value is
 * unavailable"). */
static bool unavailable_ones(const unit_t *u)
{
    return u->pkt == TASE_PKT_HOST_SENSOR && strcmp(u->field, "tas") == 0;
}

bool tk_unit(const tase_packet_desc_t *p, const char *field, tk_unit_info_t *out)
{
    const unit_t *u = unit_of(p, field);
    if (u == NULL) {
        return false;
    }
    out->suffix = unit_kinds[u->kind].suffix;
    out->label = unit_kinds[u->kind].label;
    out->decimals = u->decimals;
    out->scale = u->scale;
    out->unavailable_ones = unavailable_ones(u);
    return true;
}

/* Why the current field of `it`, of unit u, holding v has no engineering
 * value: "no change" (its "do not change" value: AXIS_SETTING's 0xFF and
 * 0xFFFF), "unavailable" (TAS 0xFFFF), or NULL when it has one. */
static const char *no_value(const tase_field_iter_t *it, const unit_t *u, int64_t v)
{
    uint32_t ones = (it->width >= 4u) ? 0xFFFFFFFFu : (UINT32_C(1) << (8u * it->width)) - 1u;
    uint32_t bits = (uint32_t)((uint64_t)v & ones);
    uint32_t keep;
    if (tase_field_iter_keep_bits(it, &keep) && bits == keep) {
        return "no change";
    }
    if (unavailable_ones(u) && bits == ones) {
        return "unavailable";
    }
    return NULL;
}

/* ---- a bounded line builder ---- */

typedef struct {
    char *p;
    char *end; /* one before the buffer's end: room for the NUL */
} sb_t;

static void sb_mem(sb_t *b, const char *s, size_t n)
{
    size_t room = (size_t)(b->end - b->p);
    if (n > room) {
        n = room;
    }
    memcpy(b->p, s, n);
    b->p += n;
}

static void sb_str(sb_t *b, const char *s)
{
    sb_mem(b, s, strlen(s));
}

static void sb_c(sb_t *b, char c)
{
    if (b->p < b->end) {
        *b->p++ = c;
    }
}

/* s as the inside of a JSON string: '"' and '\\' escaped, control
 * characters as \u00XX (an interface name may hold any byte but '/',
 * ':' and white space). */
static void sb_json_str(sb_t *b, const char *s)
{
    static const char hex[] = "0123456789abcdef";
    for (; *s != '\0'; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') {
            sb_c(b, '\\');
            sb_c(b, (char)ch);
        } else if (ch < 0x20u) {
            sb_str(b, "\\u00");
            sb_c(b, hex[ch >> 4]);
            sb_c(b, hex[ch & 15u]);
        } else {
            sb_c(b, (char)ch);
        }
    }
}

static const char digit_pairs[] = "00010203040506070809101112131415161718192021222324252627282930"
                                  "31323334353637383940414243444546474849505152535455565758596061"
                                  "6263646566676869707172737475767778798081828384858687888990919293"
                                  "949596979899";

/* Digits are made right-aligned in a scratch buffer and copied with one
 * fixed-size memcpy (a few moves, no call) when the line has room, which
 * it always has below TK_LINE_MAX; the exact count is what advances. */
#define NUM_SPAN 24u

static void sb_u64(sb_t *b, uint64_t v)
{
    char t[2u * NUM_SPAN];
    char *end = t + NUM_SPAN, *p = end;
    uint32_t w;
    size_t n;
    while (v > 0xFFFFFFFFu) {
        unsigned r = (unsigned)(v % 100u);
        v /= 100u;
        p -= 2;
        memcpy(p, digit_pairs + 2u * r, 2);
    }
    for (w = (uint32_t)v; w >= 100u; w /= 100u) {
        p -= 2;
        memcpy(p, digit_pairs + 2u * (w % 100u), 2);
    }
    if (w >= 10u) {
        p -= 2;
        memcpy(p, digit_pairs + 2u * w, 2);
    } else {
        *--p = (char)('0' + (int)w);
    }
    n = (size_t)(end - p);
    if ((size_t)(b->end - b->p) >= NUM_SPAN) {
        memcpy(b->p, p, NUM_SPAN); /* p + NUM_SPAN stays inside t */
        b->p += n;
    } else {
        sb_mem(b, p, n);
    }
}

static void sb_i64(sb_t *b, long long v)
{
    if (v < 0) {
        sb_c(b, '-');
        sb_u64(b, 0u - (uint64_t)v);
    } else {
        sb_u64(b, (uint64_t)v);
    }
}

static void sb_real(sb_t *b, double v, unsigned decimals)
{
    char t[48];
    int n = snprintf(t, sizeof(t), "%.*f", (int)decimals, v);
    if (n > 0) {
        sb_mem(b, t, (size_t)n < sizeof(t) ? (size_t)n : sizeof(t) - 1u);
    }
}

static void sb_bytes(sb_t *b, const uint8_t *p, size_t n)
{
    size_t i;
    sb_c(b, '[');
    for (i = 0; i < n; i++) {
        if (i != 0) {
            sb_c(b, ',');
        }
        sb_u64(b, p[i]);
    }
    sb_c(b, ']');
}

size_t tk_format_time(char *buf, const tk_time_t *t)
{
    sb_t b;
    char us[6];
    uint32_t u = t->usec;
    int i;
    b.p = buf;
    b.end = buf + 28;
    if (t->sec < 0 && u > 0u) {
        /* -0.75 s is sec -1 + 250000 us: the digits of the negative
         * number, not of its two parts */
        sb_c(&b, '-');
        sb_i64(&b, -(t->sec + 1));
        u = 1000000u - u;
    } else {
        sb_i64(&b, t->sec);
    }
    sb_c(&b, '.');
    for (i = 5; i >= 0; i--) {
        us[i] = (char)('0' + (int)(u % 10u));
        u /= 10u;
    }
    sb_mem(&b, us, sizeof(us));
    return (size_t)(b.p - buf);
}

/* ---- frames ---- */

static void json_units(sb_t *b, const tase_packet_desc_t *p, const tase_frame_t *f)
{
    tase_field_iter_t it;
    bool any = false;
    (void)tase_field_iter_init(&it, p, f->len);
    while (tase_field_iter_next(&it)) {
        const char *name = tase_schema_field_name(p, it.index);
        const unit_t *u = unit_of(p, name);
        int64_t v;
        if (u == NULL || tase_field_iter_get(&it, f->data, &v) != TASE_OK) {
            continue;
        }
        sb_str(b, any ? ",\"" : ",\"units\":{\"");
        any = true;
        sb_str(b, name);
        if (unit_kinds[u->kind].suffix[0] != '\0') {
            sb_c(b, '_');
            sb_str(b, unit_kinds[u->kind].suffix);
        }
        sb_str(b, "\":");
        if (no_value(&it, u, v) != NULL) {
            sb_str(b, "null");
        } else {
            sb_real(b, (double)v * u->scale, u->decimals);
        }
    }
    if (any) {
        sb_c(b, '}');
    }
}

/* Per packet, the JSON text that never changes: the header keys and
 * values, and each field's key; plus each field's place in the data. Built
 * on first use from the schema table (the tools are single-threaded). */
#define MAX_FIELDS 48u

typedef struct {
    bool ready;
    uint8_t head_len;
    uint8_t full_len;
    char head[96];  /* ,"group":G,"type":T,"name":"NAME","size": */
    char full[128]; /* the same with the table's length and ,"fields":{ */
    struct {
        uint8_t key_len;
        uint8_t offset;
        uint8_t width;
        bool is_signed;
        char key[40]; /* ,"name": */
    } f[MAX_FIELDS];
} pkt_text_t;

static pkt_text_t pkt_text[TASE_PKT_COUNT];

static const pkt_text_t *text_of(const tase_packet_desc_t *p)
{
    pkt_text_t *t = &pkt_text[p->index];
    unsigned i;
    int n;
    if (t->ready) {
        return t;
    }
    n = snprintf(t->head, sizeof(t->head), ",\"group\":%u,\"type\":%u,\"name\":\"%s\",\"size\":",
                 (unsigned)TASE_ID_GROUP(p->id), (unsigned)TASE_ID_TYPE(p->id),
                 tase_schema_packet_name(p));
    t->head_len = (uint8_t)(n > 0 && (size_t)n < sizeof(t->head) ? n : 0);
    memcpy(t->full, t->head, t->head_len);
    n = snprintf(t->full + t->head_len, sizeof(t->full) - t->head_len, "%u,\"fields\":{",
                 (unsigned)p->len);
    t->full_len =
        (uint8_t)(n > 0 && (size_t)n < sizeof(t->full) - t->head_len ? t->head_len + n : 0);
    for (i = 0; i < p->nfields && i < MAX_FIELDS; i++) {
        tk_field_t fd;
        tk_field(p, i, p->len, &fd);
        n = snprintf(t->f[i].key, sizeof(t->f[i].key), ",\"%s\":", fd.name);
        t->f[i].key_len = (uint8_t)(n > 0 && (size_t)n < sizeof(t->f[i].key) ? n : 0);
        t->f[i].offset = (uint8_t)fd.offset;
        t->f[i].width = (uint8_t)fd.width;
        t->f[i].is_signed = fd.is_signed;
    }
    t->ready = true;
    return t;
}

/* Big-endian field value, sign-extended when signed. */
static long long field_value(const uint8_t *d, unsigned width, bool is_signed)
{
    uint64_t u = 0;
    unsigned i;
    for (i = 0; i < width; i++) {
        u = (u << 8) | d[i];
    }
    if (is_signed && width < 8u && (u >> (8u * width - 1u)) != 0u) {
        return (long long)(u | ~((1ull << (8u * width)) - 1u)); /* two's complement */
    }
    return (long long)u;
}

const tase_packet_desc_t *tk_schema_find(uint8_t group, uint8_t type)
{
    /* telemetry repeats a handful of packets: remember the last one */
    static uint16_t last_id = 0xFFFFu; /* not an id: group 0xFF has no packets */
    static const tase_packet_desc_t *last;
    uint16_t id = TASE_ID(group, type);
    if (id != last_id) {
        last = tase_schema_find(group, type);
        last_id = id;
    }
    return last;
}

static void json_frame(sb_t *b, const tk_fmt_t *fmt, const tk_meta_t *m, const tase_frame_t *f)
{
    const tase_packet_desc_t *p = tk_schema_find(f->group, f->type);
    const pkt_text_t *t;
    unsigned i;
    sb_mem(b, "{\"offset\":", 10);
    sb_u64(b, m->offset);
    if (m->time != NULL) {
        char tt[32];
        sb_mem(b, ",\"time\":", 8);
        sb_mem(b, tt, tk_format_time(tt, m->time));
    }
    if (m->dir != NULL) {
        sb_str(b, ",\"dir\":\"");
        sb_str(b, m->dir);
        sb_c(b, '"');
    }
    if (m->iface != NULL) {
        sb_str(b, ",\"interface\":\"");
        sb_json_str(b, m->iface); /* a name may hold '"' or '\\' */
        sb_c(b, '"');
    }
    if (p == NULL) {
        sb_str(b, ",\"group\":");
        sb_u64(b, f->group);
        sb_str(b, ",\"type\":");
        sb_u64(b, f->type);
        sb_str(b, ",\"name\":\"UNKNOWN\",\"size\":");
        sb_u64(b, f->len);
        sb_str(b, ",\"fields\":{\"data\":");
        sb_bytes(b, f->data, f->len);
        sb_mem(b, "}}\n", 3);
        return;
    }
    t = text_of(p);
    if (f->len == p->len) {
        sb_mem(b, t->full, t->full_len); /* ... "size":N,"fields":{ */
    } else {
        sb_mem(b, t->head, t->head_len);
        sb_u64(b, f->len);
        if (!tase_schema_length_ok(p, f->len)) {
            sb_str(b, ",\"error\":\"wrong length\"}\n");
            return;
        }
        sb_mem(b, ",\"fields\":{", 11);
    }
    for (i = 0; i < p->nfields && i < MAX_FIELDS; i++) {
        /* the first key without its leading comma */
        const char *key = t->f[i].key + (i == 0u);
        size_t key_len = (size_t)t->f[i].key_len - (i == 0u);
        long long v;
        if (f->len == p->len) { /* the table's layout: offsets known */
            v = field_value(f->data + t->f[i].offset, t->f[i].width, t->f[i].is_signed);
        } else if (!tk_field_get(p, i, f->data, f->len, &v)) {
            /* short accepted forms (queries, CAMERA_CMD's one byte) carry
             * only the fields that fit */
            break;
        }
        if ((size_t)(b->end - b->p) >= sizeof(t->f[i].key)) {
            memcpy(b->p, key, sizeof(t->f[i].key) - 1u); /* fixed size: no call */
            b->p += key_len;
        } else {
            sb_mem(b, key, key_len);
        }
        sb_i64(b, v);
    }
    sb_c(b, '}');
    if (tk_packet_has_tail(p)) {
        sb_str(b, ",\"data\":");
        sb_bytes(b, f->data + p->len, f->len > p->len ? (size_t)(f->len - p->len) : 0u);
    }
    if (fmt->units) {
        json_units(b, p, f);
    }
    sb_mem(b, "}\n", 2);
}

static void text_time(sb_t *b, const tk_time_t *t)
{
    struct tm tm;
    time_t s = (time_t)t->sec;
    char buf[32];
    if (localtime_r(&s, &tm) != NULL && strftime(buf, sizeof(buf), "%H:%M:%S", &tm) > 0) {
        sb_str(b, buf);
        snprintf(buf, sizeof(buf), ".%03u ", (unsigned)(t->usec / 1000u));
        sb_str(b, buf);
    }
}

static void text_frame(sb_t *b, const tk_fmt_t *fmt, const tk_meta_t *m, const tase_frame_t *f)
{
    const tase_packet_desc_t *p = tase_schema_find(f->group, f->type);
    tase_field_iter_t it;
    if (fmt->time && m->time != NULL) {
        text_time(b, m->time);
    }
    if (p == NULL) {
        char t[64];
        snprintf(t, sizeof(t), "UNKNOWN group 0x%02X type 0x%02X, %u bytes\n", (unsigned)f->group,
                 (unsigned)f->type, (unsigned)f->len);
        sb_str(b, t);
        return;
    }
    sb_str(b, tase_schema_packet_name(p));
    if (!tase_schema_length_ok(p, f->len)) {
        sb_str(b, ": wrong length ");
        sb_u64(b, f->len);
        sb_c(b, '\n');
        return;
    }
    if (f->len == 0) {
        sb_str(b, p->len == 0 ? "\n" : " (query)\n");
        return;
    }
    (void)tase_field_iter_init(&it, p, f->len);
    while (tase_field_iter_next(&it)) {
        const char *name = tase_schema_field_name(p, it.index);
        const unit_t *u;
        int64_t v;
        if (tase_field_iter_get(&it, f->data, &v) != TASE_OK) {
            break;
        }
        sb_c(b, ' ');
        sb_str(b, name);
        sb_c(b, '=');
        sb_i64(b, v);
        if (fmt->units && (u = unit_of(p, name)) != NULL) {
            const char *why = no_value(&it, u, v);
            sb_str(b, " (");
            if (why != NULL) {
                sb_str(b, why);
            } else {
                sb_real(b, (double)v * u->scale, u->decimals);
                if (unit_kinds[u->kind].label[0] != '\0') {
                    sb_c(b, ' ');
                    sb_str(b, unit_kinds[u->kind].label);
                }
            }
            sb_c(b, ')');
        }
    }
    if (tk_packet_has_tail(p) && f->len > p->len) {
        sb_str(b, " +");
        sb_u64(b, (uint64_t)(f->len - p->len));
        sb_str(b, " data bytes");
    }
    sb_c(b, '\n');
}

size_t tk_format_frame(char *buf, size_t cap, const tk_fmt_t *fmt, const tk_meta_t *m,
                       const tase_frame_t *f)
{
    sb_t b;
    if (cap < 2u) {
        return 0;
    }
    b.p = buf;
    b.end = buf + cap - 2u; /* room for a newline and the NUL */
    if (fmt->json) {
        json_frame(&b, fmt, m, f);
    } else {
        text_frame(&b, fmt, m, f);
    }
    if (b.p == b.end && (b.p == buf || b.p[-1] != '\n')) {
        *b.p++ = '\n'; /* cut short: still one line (cannot happen below TK_LINE_MAX) */
    }
    *b.p = '\0';
    return (size_t)(b.p - buf);
}

void tk_print_frame(FILE *out, const tk_fmt_t *fmt, const tk_meta_t *m, const tase_frame_t *f)
{
    char line[TK_LINE_MAX];
    size_t n = tk_format_frame(line, sizeof(line), fmt, m, f);
    (void)fwrite(line, 1, n, out);
}
