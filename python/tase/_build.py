"""cffi builder of tase._tase: the library's C sources, compiled into the
extension (API mode: the compiler reads the public headers, so no struct
layout or size is written here), plus a small C helper (PY_HELPER below).

Everything that reads the schema table (tase/schema.h: fields, offsets,
"do not change" values) is in PY_HELPER's py_field(), py_decode() and
py_encode(): the one place to change when that API moves.

The JSON of packets comes from the bench tools' own formatter
(tools/tk_json.c, tk_format_frame()), so the package prints exactly what
`tase --json` prints; a serial link is checked as the tools check it
(tools/tk_simlink.c: never the stale link of a killed tase-sim).

Sources are found from the repository root: TASE_SOURCE_DIR in the
environment, else two directories above this package (python/tase/..).
"""

import glob
import os

from cffi import FFI

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.environ.get("TASE_SOURCE_DIR") or os.path.join(HERE, "..", ".."))

LIB_CDEF = r"""
#define TASE_FRAME_MAX ...
#define TASE_DATA_MAX ...
#define TASE_PKT_COUNT ...
#define TASE_DIR_IN ...
#define TASE_DIR_OUT ...
#define TASE_LEN_QUERY ...
#define TASE_LEN_SHORT1 ...
#define TASE_LEN_TAIL ...
#define TASE_LEN_SHORT ...
#define TASE_VERSION_MAJOR ...
#define TASE_VERSION_MINOR ...
#define TASE_VERSION_PATCH ...
#define TASE_ABI_LEVEL ...
#define TASE_CAN_ID_TO_GIMBAL ...
#define TASE_CAN_ID_FROM_GIMBAL ...
#define TASE_CAMERA_PASS_MAX ...
#define TASE_SOCKETCAN_BYTES_PER_S ...
#define TASE_GIMBAL_FLAGS_LEGACY_RATE ...
#define TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB ...
#define TASE_GIMBAL_FLAGS_RATE ...
#define TASE_GIMBAL_FLAGS_RATE_STAB ...
#define TASE_GIMBAL_FLAGS_POSITION ...
#define TASE_GIMBAL_FLAGS_POSITION_STAB ...
#define TASE_GIMBAL_FLAGS_IMPULSE ...
#define TASE_GIMBAL_FLAGS_IMPULSE_STAB ...
#define TASE_GIMBAL_FLAGS_SPOI_ERROR ...
#define TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE ...
#define TASE_SPOI_ECHO ...
#define TASE_MODE_SPOI ...
#define TASE_DEPLOY ...
#define TASE_RETRACT ...
#define TASE_CAMTYPE_NONE ...
#define TASE_PAN_MIN_CDEG ...
#define TASE_PAN_MAX_CDEG ...
#define TASE_TILT_MIN_CDEG ...
#define TASE_TILT_MAX_CDEG ...
#define TASE_CAN_ROLE_HOST ...
#define TASE_CAN_ROLE_GIMBAL ...
#define TASE_OK ...
#define TASE_EARG ...
#define TASE_ENOSPC ...
#define TASE_ETOOLONG ...
#define TASE_ELENGTH ...
#define TASE_EUNKNOWN ...
#define TASE_ECHECKSUM ...
#define TASE_EFORMAT ...
#define TASE_ERANGE ...
#define TASE_EAGAIN ...
#define TASE_ETIMEOUT ...
#define TASE_EIO ...
#define TASE_ENODEV ...
#define TASE_EDOWN ...
#define TASE_EACCES ...
#define TASE_EBUSY ...
#define TASE_ENOBUFS ...
#define TASE_ETRUNC ...
#define TASE_EUNSUPPORTED ...
#define TASE_ESTATE ...

const char *tase_strerror(int err);

typedef struct {
    uint16_t id;
    uint8_t len;
    uint8_t flags;
    uint8_t nfields;
    uint8_t index;
    ...;
} tase_packet_desc_t;
const tase_packet_desc_t *tase_schema_at(size_t i);
const tase_packet_desc_t *tase_schema_find(uint8_t group, uint8_t type);
const char *tase_schema_packet_name(const tase_packet_desc_t *p);
bool tase_schema_length_ok(const tase_packet_desc_t *p, size_t len);
bool tase_schema_is_query(const tase_packet_desc_t *p, size_t len);
uint8_t tase_schema_reserved_flags(const tase_packet_desc_t *p);

int tase_frame_build(uint8_t group, uint8_t type, const uint8_t *data, size_t len,
                     uint8_t *out, size_t cap);
int tase_command_check_data(uint16_t id, const uint8_t *data, size_t len);

typedef struct {
    uint32_t bytes_in;
    uint32_t frames_ok;
    uint32_t checksum_errors;
    uint32_t bad_size;
    uint32_t bytes_discarded;
    uint32_t bad_length;
    uint32_t unknown;
} tase_rx_stats_t;
typedef struct {
    tase_rx_stats_t stats;
    ...;
} tase_rx_t;
int tase_rx_init(tase_rx_t *rx);
int tase_rx_set_timing(tase_rx_t *rx, uint32_t bytes_per_s, uint16_t margin_ms);
uint32_t tase_rx_quiet_ms(const tase_rx_t *rx, uint32_t now_ms);

typedef struct {
    uint32_t frames_tx;
    uint32_t tx_errors;
    uint32_t frames_rx;
    uint32_t requests;
    uint32_t retries;
    uint32_t replies;
    uint32_t timeouts;
    uint32_t late;
    uint32_t stale;
    uint32_t queries_rx;
} tase_host_stats_t;
typedef struct {
    tase_host_stats_t stats;
    tase_rx_t rx;
    ...;
} tase_host_t;
int tase_host_send(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data, size_t len);
int tase_host_service(tase_host_t *h, uint32_t wait_ms);
int tase_host_drain(tase_host_t *h);
int tase_host_transact(tase_host_t *h, uint8_t group, uint8_t type, const uint8_t *data,
                       size_t len, uint8_t *reply, size_t reply_cap, uint32_t timeout_ms,
                       uint8_t retries);

typedef struct {
    uint32_t id;
    bool extended;
    uint8_t dlc;
    uint8_t data[8];
} tase_can_frame_t;
int tase_can_split(int sender, const uint8_t *data, size_t n, tase_can_frame_t *out,
                   size_t cap);
int tase_can_accept(int role, const tase_can_frame_t *f);

"""


# The helper's types and functions: declared once, for cdef and for C.
HELPER_DECL = r"""
typedef struct {
    const char *name;
    unsigned width;
    int is_signed;
    int has_keep;
    long long keep;
    int offset; /* in a frame of `len` data bytes */
    int has_unit;
    const char *unit_suffix;
    const char *unit_label;
    unsigned decimals;
    double scale;
    int unavailable_ones; /* all ones: "unavailable", no engineering value */
} py_field_t;
int py_field(size_t pkt, size_t i, size_t len, py_field_t *out);
int py_decode(size_t pkt, const uint8_t *data, size_t len, int64_t *vals, size_t cap);
int py_encode(size_t pkt, const int64_t *vals, size_t nvals, const uint8_t *tail,
              size_t tail_len, size_t len, uint8_t *out, size_t cap, int *bad);

typedef struct {
    uint64_t *offset; /* stream offset of each frame's first sync byte */
    uint64_t *key;    /* id << 40 | data length << 32 | position in `data` */
    uint64_t *time;   /* NULL, or each frame's `now` when delivered */
    uint64_t now;     /* the caller's time (links: when the last read returned) */
    size_t n;
    size_t cap;
    uint8_t *data;
    size_t dlen;
    size_t dcap;
    uint64_t base64; /* 64-bit stream count when rx.stats.bytes_in was base32 */
    uint32_t base32;
    unsigned long dropped; /* frames that did not fit (never in decode) */
} py_sink_t;
int py_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, py_sink_t *s);
int py_rx_flush(tase_rx_t *rx, py_sink_t *s);
int py_rx_tick(tase_rx_t *rx, uint32_t now_ms, py_sink_t *s);

typedef struct {
    py_sink_t *s;
    const tase_rx_t *rx;
} py_ctx_t;
int py_host_init(tase_host_t *h, void *ctx, uint32_t bytes_per_s, py_ctx_t *c);
void py_host_begin(tase_host_t *h, py_sink_t *s, uint64_t base64);

size_t py_json(char *buf, size_t cap, int units, uint64_t offset, int timed, int64_t sec,
               uint32_t usec, const char *dir, uint8_t group, uint8_t type,
               const uint8_t *data, size_t len);
"""

# The bench tools' own C the package shares (tools/toolkit.h).
TOOLS_CDEF = r"""
int tk_simlink_check(const char *path, char *why, size_t cap);
"""

CDEF = LIB_CDEF + HELPER_DECL + TOOLS_CDEF + r"""
extern "Python+C" int py_port_write(void *ctx, const uint8_t *data, size_t n);
extern "Python+C" int py_port_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms);
extern "Python+C" uint32_t py_port_now(void *ctx);
"""

PY_HELPER = (
    r"""
#include <string.h>

#include "tase/can.h"
#include "tase/codec.h"
#include "tase/flags.h"
#include "tase/host.h"
#include "tase/units.h"
#include "toolkit.h"
"""
    + HELPER_DECL
    + r"""
/* tools/tk_json.c refers to these two toolkit functions on paths the
 * package never takes (tk_packet_by_name(), tk_field_parse()); the rest of
 * the toolkit (exit, signals, devices) is not linked. */
void tk_usage_error(const char *fmt, ...)
{
    (void)fmt;
}
int tk_parse_int(const char *s, long long min, long long max, long long *out, bool *hex)
{
    (void)s; (void)min; (void)max; (void)out; (void)hex;
    return TK_NUM_SYNTAX;
}

/* ---- the schema: the one place the package reads it ---- */

int py_field(size_t pkt, size_t i, size_t len, py_field_t *out)
{
    const tase_packet_desc_t *p = tase_schema_at(pkt);
    const tase_field_t *f = tase_schema_field(p, i);
    int64_t keep = 0;
    tk_unit_info_t u;
    if (f == NULL) {
        return TASE_EARG;
    }
    memset(out, 0, sizeof(*out));
    out->name = tase_schema_field_name(p, i);
    out->width = TASE_FIELD_WIDTH(f);
    out->is_signed = TASE_FIELD_IS_SIGNED(f);
    out->has_keep = tase_field_keep(p, i, &keep) == TASE_OK;
    out->keep = (long long)keep;
    out->offset = tase_field_offset(p, i, len);
    if (tk_unit(p, out->name, &u)) {
        out->has_unit = 1;
        out->unit_suffix = u.suffix;
        out->unit_label = u.label;
        out->decimals = u.decimals;
        out->scale = u.scale;
        out->unavailable_ones = u.unavailable_ones;
    }
    return TASE_OK;
}

static int64_t member_get(const uint8_t *m, const tase_field_t *f)
{
    unsigned w = TASE_FIELD_WIDTH(f);
    bool s = TASE_FIELD_IS_SIGNED(f);
    if (w == 1u) {
        if (s) { int8_t v; memcpy(&v, m, 1); return v; }
        return m[0];
    }
    if (w == 2u) {
        if (s) { int16_t v; memcpy(&v, m, 2); return v; }
        { uint16_t v; memcpy(&v, m, 2); return v; }
    }
    if (w == 4u) {
        if (s) { int32_t v; memcpy(&v, m, 4); return v; }
        { uint32_t v; memcpy(&v, m, 4); return v; }
    }
    { int64_t v; memcpy(&v, m, 8); return v; }
}

static int member_set(uint8_t *m, const tase_field_t *f, int64_t x)
{
    unsigned w = TASE_FIELD_WIDTH(f);
    bool s = TASE_FIELD_IS_SIGNED(f);
    if (w == 1u) {
        if (s ? (x < INT8_MIN || x > INT8_MAX) : (x < 0 || x > UINT8_MAX)) return TASE_ERANGE;
        if (s) { int8_t v = (int8_t)x; memcpy(m, &v, 1); } else { m[0] = (uint8_t)x; }
    } else if (w == 2u) {
        if (s ? (x < INT16_MIN || x > INT16_MAX) : (x < 0 || x > UINT16_MAX)) return TASE_ERANGE;
        if (s) { int16_t v = (int16_t)x; memcpy(m, &v, 2); }
        else { uint16_t v = (uint16_t)x; memcpy(m, &v, 2); }
    } else if (w == 4u) {
        if (s ? (x < INT32_MIN || x > INT32_MAX) : (x < 0 || x > (int64_t)UINT32_MAX))
            return TASE_ERANGE;
        if (s) { int32_t v = (int32_t)x; memcpy(m, &v, 4); }
        else { uint32_t v = (uint32_t)x; memcpy(m, &v, 4); }
    } else {
        if (!s && x < 0) return TASE_ERANGE;
        memcpy(m, &x, 8);
    }
    return TASE_OK;
}

/* Decode data[0..len) of packet index `pkt` with the codec and read the
 * fields that lie within len (a query: none; CAMERA_CMD's 1-byte form:
 * camera) into vals. Returns how many, or a TASE_E* code. */
int py_decode(size_t pkt, const uint8_t *data, size_t len, int64_t *vals, size_t cap)
{
    const tase_packet_desc_t *p = tase_schema_at(pkt);
    tase_packet_msg_t msg;
    size_t i;
    int r;
    if (p == NULL) {
        return TASE_EARG;
    }
    r = tase_packet_decode_desc(p, data, len, &msg);
    if (r < 0) {
        return r;
    }
    for (i = 0; i < p->nfields && i < cap; i++) {
        const tase_field_t *f = tase_schema_field(p, i);
        int off = tase_field_offset(p, i, len);
        if (off < 0 || (size_t)off + TASE_FIELD_WIDTH(f) > len) {
            break;
        }
        vals[i] = member_get((const uint8_t *)&msg + f->member, f);
    }
    return (int)i;
}

/* Set the typed struct of packet `pkt` from vals[0..nvals) (table order;
 * nvals == nfields) and CAMERA_PASS's tail, and encode a frame of `len`
 * data bytes (SIZE_MAX: the table's length) with the codec into out.
 * Returns the frame length or a TASE_E* code; TASE_ERANGE sets *bad to
 * the field that does not fit its width. Nothing is written on error. */
int py_encode(size_t pkt, const int64_t *vals, size_t nvals, const uint8_t *tail,
              size_t tail_len, size_t len, uint8_t *out, size_t cap, int *bad)
{
    const tase_packet_desc_t *p = tase_schema_at(pkt);
    tase_packet_msg_t msg;
    size_t i;
    if (p == NULL || nvals != p->nfields) {
        return TASE_EARG;
    }
    memset(&msg, 0, sizeof(msg));
    for (i = 0; i < nvals; i++) {
        const tase_field_t *f = tase_schema_field(p, i);
        if (member_set((uint8_t *)&msg + f->member, f, vals[i]) != TASE_OK) {
            *bad = (int)i;
            return TASE_ERANGE;
        }
    }
    if (p->index == TASE_PKT_CAMERA_PASS) {
        if (tail_len > TASE_CAMERA_PASS_MAX) {
            return TASE_ETOOLONG;
        }
        msg.camera_pass.len = (uint8_t)tail_len;
        msg.camera_pass.data = tail;
        if (len == SIZE_MAX) {
            len = p->len + tail_len;
        }
    } else if (tail_len != 0u) {
        return TASE_ELENGTH;
    }
    if (len == SIZE_MAX) {
        return tase_packet_encode(p->id, p->nfields ? &msg : NULL, out, cap);
    }
    return tase_packet_encode_len(p->id, p->nfields ? &msg : NULL, len, out, cap);
}

/* ---- frames in bulk: the receiver's frames as columns ---- */

static void py_sink_put(py_sink_t *s, const tase_rx_t *rx, const tase_frame_t *f)
{
    if (s->n == s->cap || s->dcap - s->dlen < f->len || s->dlen + f->len > UINT32_MAX) {
        s->dropped++;
        return;
    }
    if (s->time != NULL) {
        s->time[s->n] = s->now;
    }
    s->offset[s->n] = s->base64 + (uint64_t)(int64_t)(int32_t)(f->offset - s->base32);
    s->key[s->n] = (uint64_t)TASE_ID(f->group, f->type) << 40 | (uint64_t)f->len << 32 |
                   (uint64_t)(uint32_t)s->dlen;
    memcpy(s->data + s->dlen, f->data, f->len);
    s->dlen += f->len;
    s->n++;
}

static void py_on_frame(void *user, const tase_frame_t *f)
{
    py_ctx_t *c = user;
    py_sink_put(c->s, c->rx, f);
}

int py_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, py_sink_t *s)
{
    py_ctx_t c = {s, rx};
    int r;
    s->base32 = rx->stats.bytes_in;
    r = tase_rx_feed(rx, data, n, py_on_frame, &c);
    if (r >= 0) {
        s->base64 += n;
        s->base32 += (uint32_t)n;
    }
    return r;
}

int py_rx_flush(tase_rx_t *rx, py_sink_t *s)
{
    py_ctx_t c = {s, rx};
    s->base32 = rx->stats.bytes_in;
    return tase_rx_flush(rx, py_on_frame, &c);
}

int py_rx_tick(tase_rx_t *rx, uint32_t now_ms, py_sink_t *s)
{
    py_ctx_t c = {s, rx};
    s->base32 = rx->stats.bytes_in;
    return tase_rx_tick(rx, now_ms, py_on_frame, &c);
}

/* ---- the host role on a port of Python callbacks ---- */

int py_port_write(void *ctx, const uint8_t *data, size_t n);
int py_port_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms);
uint32_t py_port_now(void *ctx);

static const tase_port_ops_t py_ops = {
    .write = py_port_write,
    .read = py_port_read,
    .now_ms = py_port_now,
};

/* A host whose frames (those that do not complete a request) go to
 * c->s; c must live as long as h, and c->rx is set here. Before a call
 * that may receive, set c->s->base64/base32 (py_host_begin()). */
int py_host_init(tase_host_t *h, void *ctx, uint32_t bytes_per_s, py_ctx_t *c)
{
    tase_port_t port;
    port.ops = &py_ops;
    port.ctx = ctx;
    port.bytes_per_s = bytes_per_s;
    c->rx = &h->rx;
    return tase_host_init(h, &port, py_on_frame, c);
}

void py_host_begin(tase_host_t *h, py_sink_t *s, uint64_t base64)
{
    s->base64 = base64;
    s->base32 = h->rx.stats.bytes_in;
}

size_t py_json(char *buf, size_t cap, int units, uint64_t offset, int timed, int64_t sec,
               uint32_t usec, const char *dir, uint8_t group, uint8_t type,
               const uint8_t *data, size_t len)
{
    tk_fmt_t fmt = {true, units != 0, timed != 0};
    tk_time_t t;
    tk_meta_t m;
    tase_frame_t f;
    t.sec = sec;
    t.usec = usec;
    m.offset = offset;
    m.time = timed ? &t : NULL;
    m.dir = dir;
    m.iface = NULL;
    f.offset = 0;
    f.group = group;
    f.type = type;
    f.len = (uint8_t)len;
    f.data = data;
    return tk_format_frame(buf, cap, &fmt, &m, &f);
}
"""
)

ffibuilder = FFI()
ffibuilder.cdef(CDEF)
ffibuilder.set_source(
    "tase._tase",
    PY_HELPER,
    sources=sorted(glob.glob(os.path.join(ROOT, "src", "*.c")))
    + [os.path.join(ROOT, "tools", "tk_json.c"), os.path.join(ROOT, "tools", "tk_simlink.c")],
    include_dirs=[
        os.path.join(ROOT, "include"),
        os.path.join(ROOT, "src"),
        os.path.join(ROOT, "tools"),
        os.path.join(ROOT, "port", "posix_uart"),
        os.path.join(ROOT, "port", "socketcan"),
    ],
    define_macros=[("_POSIX_C_SOURCE", "200809L")],
    extra_compile_args=["-std=c99", "-O2"],
)


def build_into(out):
    """Build the package into directory `out` (out/tase: the Python files
    and the extension), leaving the source tree as it is: what the CMake
    build and ctest use (tests/checks/python.cmake)."""
    import shutil

    pkg = os.path.join(out, "tase")
    os.makedirs(pkg, exist_ok=True)
    for f in glob.glob(os.path.join(HERE, "*.py")):
        shutil.copy2(f, pkg)
    return ffibuilder.compile(tmpdir=out)


if __name__ == "__main__":
    import sys

    if len(sys.argv) != 3 or sys.argv[1] != "--out":
        sys.exit("usage: _build.py --out DIR")
    print(build_into(sys.argv[2]))
