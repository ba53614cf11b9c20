/*
 * Fuzz harness: the KLV decoder (tase_klv_decode) and stream scanner
 * (tase_klv_rx_t).
 *
 * Input: mode, 2 bytes seeding the split points, then either (mode bit 0
 * set) the raw byte stream, or records that build one, each an op byte
 * (low 3 bits) and its arguments:
 *   OP_NOISE  n (0..63), n raw bytes;
 *   OP_FLIP   pos, mask: XOR a byte of the last packet (mask 0 = none);
 *   OP_TRUNC  n: cut the last n % 16 + 1 bytes of the last packet;
 *   OP_KEY    n: the first n % 16 + 1 key bytes (a false candidate);
 *   else      OP_PACKET: form, 40 value bytes (38 used): a valid packet (checksum
 *             computed by the encoder); form bit 0: declared length 69
 *             (as the spec prints it), bits 1-2: BER long form with 1..3
 *             length octets (0x81 0x46, 0x82 0x00 0x46, ...).
 * Checks on tase_klv_decode, at the start of the stream and at every
 * candidate the scanner reports:
 *   - only documented codes: 87..91 (and <= n), TASE_ETRUNC, _EFORMAT,
 *     _ELENGTH, _EUNKNOWN, _ECHECKSUM; the output is untouched on error;
 *   - a success re-encodes to the same key and set bytes (all 87 bytes
 *     when the declared length was 70, all but the length byte for 69);
 *   - the first failure wins: over growing prefixes of the input the
 *     result is TASE_ETRUNC until it settles, then never changes, and
 *     nothing past 91 bytes matters.
 * Checks on the scanner, fed in random chunks and, separately, at once:
 *   - every call returns the packets it delivered; packets_ok, bytes_in
 *     and the error counters agree with the callbacks (one counter per
 *     code; TASE_ETRUNC only from flush); every error is reported at a
 *     full key, and decoding the stream there gives the same error;
 *   - delivered offsets increase and packets do not overlap; each lies
 *     inside the bytes fed so far and decodes from the stream at its
 *     offset to the same values;
 *   - after flush the window is empty and bytes_discarded plus the bytes
 *     of delivered packets equal bytes_in; chunked and one-shot feeding
 *     give the same packets and counters;
 *   - built streams: every packet whose bytes were not touched is
 *     delivered, by the call that feeds its last byte (or 3 bytes later,
 *     behind a long-form length) or by flush at the end of the input,
 *     unless a delivered packet that is not one of ours overlaps it.
 */
#include <string.h>

#include "fuzz.h"
#include "tase/klv.h"

#define MAX_STREAM 16384u
#define MAX_TX 512u
#define MAX_EV (MAX_STREAM + 1u)

enum { OP_PACKET, OP_NOISE, OP_FLIP, OP_TRUNC, OP_KEY };

static const uint8_t key[TASE_KLV_KEY_LEN] = {0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01,
                                              0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};

typedef struct {
    uint32_t start, end;
    uint8_t touched;
} tx_t;

typedef struct {
    uint32_t offset;
    int err; /* 0: a packet */
    uint32_t end;
    uint32_t call_start, call_end; /* stream range fed by the delivering call */
    uint8_t in_flush;
    tase_klv_t klv;
} ev_t;

typedef struct {
    const tase_klv_rx_t *rx;
    ev_t *ev;
    size_t n, packets;
    uint32_t call_start, call_end;
    uint8_t flushing;
} sink_t;

static uint8_t stream[MAX_STREAM + 128u];
static size_t stream_len;
static tx_t tx[MAX_TX];
static ev_t ev_a[MAX_EV], ev_b[MAX_EV];

static int klv_eq(const tase_klv_t *a, const tase_klv_t *b)
{
    return a->utc == b->utc && a->lat == b->lat && a->lon == b->lon && a->alt == b->alt &&
           a->pan == b->pan && a->tilt == b->tilt && a->heading == b->heading &&
           a->pitch == b->pitch && a->roll == b->roll && a->vnorth == b->vnorth &&
           a->veast == b->veast && a->hfov == b->hfov && a->vfov == b->vfov &&
           a->gps_status == b->gps_status;
}

static int documented_error(int rc)
{
    return rc == TASE_ETRUNC || rc == TASE_EFORMAT || rc == TASE_ELENGTH || rc == TASE_EUNKNOWN ||
           rc == TASE_ECHECKSUM;
}

/* Decode in[0..n) with every check above; returns the result. */
static int check_decode(const uint8_t *in, size_t n, tase_klv_t *out)
{
    tase_klv_t canary, k;
    uint8_t enc[TASE_KLV_PACKET_LEN];
    size_t m, lim = n < TASE_KLV_PACKET_MAX ? n : TASE_KLV_PACKET_MAX;
    int rc, prev = TASE_ETRUNC;
    memset(&canary, 0xA5, sizeof(canary));
    k = canary;
    rc = tase_klv_decode(in, n, &k);
    if (rc < 0) {
        FZ_CHECK(documented_error(rc));
        FZ_CHECK(memcmp(&k, &canary, sizeof(k)) == 0);
    } else {
        size_t hdr = (size_t)rc - TASE_KLV_SET_LEN;
        FZ_CHECK(rc >= (int)TASE_KLV_PACKET_LEN && rc <= (int)TASE_KLV_PACKET_MAX);
        FZ_CHECK((size_t)rc <= n);
        FZ_CHECK(tase_klv_encode(&k, enc, sizeof(enc)) == (int)TASE_KLV_PACKET_LEN);
        FZ_CHECK(memcmp(enc, in, TASE_KLV_KEY_LEN) == 0);
        FZ_CHECK(memcmp(enc + TASE_KLV_KEY_LEN + 1u, in + hdr, TASE_KLV_SET_LEN) == 0);
        if (in[TASE_KLV_KEY_LEN] == TASE_KLV_SET_LEN) {
            FZ_CHECK(rc == (int)TASE_KLV_PACKET_LEN && memcmp(enc, in, (size_t)rc) == 0);
        } else if (in[TASE_KLV_KEY_LEN] == TASE_KLV_SET_LEN_SPEC) {
            FZ_CHECK(rc == (int)TASE_KLV_PACKET_LEN);
        } else {
            FZ_CHECK(in[TASE_KLV_KEY_LEN] > 0x80u && in[TASE_KLV_KEY_LEN] <= 0x84u);
        }
    }
    /* the first failure in wire order wins; 91 bytes decide everything */
    for (m = 0; m <= lim; m++) {
        tase_klv_t t;
        int r = tase_klv_decode(in, m, &t);
        FZ_CHECK(r > 0 || documented_error(r));
        if (prev != TASE_ETRUNC) {
            FZ_CHECK(r == prev);
        }
        prev = r;
    }
    FZ_CHECK(prev == rc);
    if (out != NULL && rc > 0) {
        *out = k;
    }
    return rc;
}

static void on_packet(void *user, uint32_t offset, const tase_klv_t *klv)
{
    sink_t *s = user;
    tase_klv_t k;
    int r;
    FZ_CHECK(s->n < MAX_EV);
    FZ_CHECK(offset < stream_len);
    r = tase_klv_decode(stream + offset, stream_len - offset, &k);
    FZ_CHECK(r > 0);
    FZ_CHECK(klv_eq(&k, klv));
    FZ_CHECK(offset + (uint32_t)r <= s->rx->stats.bytes_in);
    s->ev[s->n].offset = offset;
    s->ev[s->n].err = 0;
    s->ev[s->n].end = offset + (uint32_t)r;
    s->ev[s->n].call_start = s->call_start;
    s->ev[s->n].call_end = s->call_end;
    s->ev[s->n].in_flush = s->flushing;
    s->ev[s->n].klv = *klv;
    s->n++;
    s->packets++;
}

static void on_error(void *user, uint32_t offset, int err)
{
    sink_t *s = user;
    FZ_CHECK(s->n < MAX_EV);
    FZ_CHECK(err < 0 && documented_error(err));
    FZ_CHECK(err != TASE_ETRUNC || s->flushing);
    FZ_CHECK((size_t)offset + TASE_KLV_KEY_LEN <= stream_len);
    FZ_CHECK(memcmp(stream + offset, key, TASE_KLV_KEY_LEN) == 0);
    FZ_CHECK(check_decode(stream + offset, stream_len - offset, NULL) == err);
    memset(&s->ev[s->n], 0, sizeof(s->ev[s->n]));
    s->ev[s->n].offset = offset;
    s->ev[s->n].err = err;
    s->n++;
}

static void check_counters(const tase_klv_rx_t *rx, const sink_t *s, size_t fed)
{
    uint32_t c[5] = {0, 0, 0, 0, 0};
    size_t i;
    for (i = 0; i < s->n; i++) {
        switch (s->ev[i].err) {
        case 0: break;
        case TASE_ECHECKSUM: c[0]++; break;
        case TASE_EFORMAT: c[1]++; break;
        case TASE_ELENGTH: c[2]++; break;
        case TASE_EUNKNOWN: c[3]++; break;
        default: c[4]++; break;
        }
    }
    FZ_CHECK(rx->stats.bytes_in == (uint32_t)fed);
    FZ_CHECK(rx->stats.packets_ok == (uint32_t)s->packets);
    FZ_CHECK(rx->stats.checksum_errors == c[0] && rx->stats.format_errors == c[1]);
    FZ_CHECK(rx->stats.length_errors == c[2] && rx->stats.unknown_tags == c[3]);
    FZ_CHECK(rx->stats.truncated == c[4]);
}

static void feed(tase_klv_rx_t *rx, sink_t *s, size_t from, size_t n)
{
    size_t before = s->packets;
    int ret;
    s->call_start = (uint32_t)from;
    s->call_end = (uint32_t)(from + n);
    ret = tase_klv_rx_feed(rx, stream + from, n, on_packet, on_error, s);
    FZ_CHECK(ret >= 0 && (size_t)ret == s->packets - before);
    check_counters(rx, s, from + n);
}

static void flush(tase_klv_rx_t *rx, sink_t *s)
{
    size_t before = s->packets, i;
    uint32_t covered = 0, prev_end = 0;
    int ret;
    s->flushing = 1;
    s->call_start = s->call_end = (uint32_t)stream_len;
    ret = tase_klv_rx_flush(rx, on_packet, on_error, s);
    FZ_CHECK(ret >= 0 && (size_t)ret == s->packets - before);
    check_counters(rx, s, stream_len);
    FZ_CHECK(rx->len == 0u);
    for (i = 0; i < s->n; i++) {
        if (s->ev[i].err == 0) {
            FZ_CHECK(s->ev[i].offset >= prev_end);
            prev_end = s->ev[i].end;
            covered += s->ev[i].end - s->ev[i].offset;
        }
    }
    FZ_CHECK(rx->stats.bytes_discarded + covered == (uint32_t)stream_len);
}

static uint16_t be16(const uint8_t *p)
{
    return (uint16_t)((p[0] << 8) | p[1]);
}

/* Append one valid packet; returns its length or 0 when it does not fit. */
static size_t put_packet(fz_in_t *in)
{
    uint8_t form = fz_u8(in), enc[TASE_KLV_PACKET_LEN];
    unsigned octets = (form >> 1) & 3u, j;
    tase_klv_t k;
    size_t len = TASE_KLV_PACKET_LEN + octets;
    uint8_t v[40];
    for (j = 0; j < sizeof(v); j++) { /* one call per statement: defined order */
        v[j] = fz_u8(in);
    }
    k.utc = 0;
    for (j = 0; j < 8u; j++) {
        k.utc = (k.utc << 8) | v[j];
    }
    k.lat =
        (int32_t)(((uint32_t)v[8] << 24) | ((uint32_t)v[9] << 16) | ((uint32_t)v[10] << 8) | v[11]);
    k.lon = (int32_t)(((uint32_t)v[12] << 24) | ((uint32_t)v[13] << 16) | ((uint32_t)v[14] << 8) |
                      v[15]);
    k.alt = be16(v + 16);
    k.pan = be16(v + 18);
    k.tilt = (int16_t)be16(v + 20);
    k.heading = be16(v + 22);
    k.pitch = (int16_t)be16(v + 24);
    k.roll = (int16_t)be16(v + 26);
    k.vnorth = (int16_t)be16(v + 28);
    k.veast = (int16_t)be16(v + 30);
    k.hfov = be16(v + 32);
    k.vfov = be16(v + 34);
    k.gps_status = be16(v + 36);
    FZ_CHECK(tase_klv_encode(&k, enc, sizeof(enc)) == (int)TASE_KLV_PACKET_LEN);
    if (stream_len + len > MAX_STREAM) {
        return 0;
    }
    memcpy(stream + stream_len, enc, TASE_KLV_KEY_LEN);
    if (octets == 0u) {
        stream[stream_len + TASE_KLV_KEY_LEN] =
            (form & 1u) != 0u ? (uint8_t)TASE_KLV_SET_LEN_SPEC : (uint8_t)TASE_KLV_SET_LEN;
    } else {
        stream[stream_len + TASE_KLV_KEY_LEN] = (uint8_t)(0x80u | octets);
        for (j = 1; j < octets; j++) {
            stream[stream_len + TASE_KLV_KEY_LEN + j] = 0;
        }
        stream[stream_len + TASE_KLV_KEY_LEN + octets] = (uint8_t)TASE_KLV_SET_LEN;
    }
    memcpy(stream + stream_len + len - TASE_KLV_SET_LEN, enc + TASE_KLV_KEY_LEN + 1u,
           TASE_KLV_SET_LEN);
    return len;
}

static size_t build(fz_in_t *in)
{
    size_t k = 0;
    stream_len = 0;
    while (fz_more(in) && stream_len + 128u <= MAX_STREAM && k < MAX_TX) {
        uint8_t op = (uint8_t)(fz_u8(in) & 7u);
        tx_t *last = (k > 0u && tx[k - 1u].end == stream_len) ? &tx[k - 1u] : NULL;
        uint32_t plen = last != NULL ? last->end - last->start : 0u;
        if (op == OP_NOISE) {
            size_t m = fz_u8(in) & 63u, j;
            for (j = 0; j < m; j++) {
                stream[stream_len++] = fz_u8(in);
            }
        } else if (op == OP_FLIP) {
            uint8_t pos = fz_u8(in), mask = fz_u8(in);
            if (last != NULL && mask != 0u) {
                stream[last->start + pos % plen] ^= mask;
                last->touched = 1;
            }
        } else if (op == OP_TRUNC) {
            uint32_t cut = fz_u8(in) % 16u + 1u;
            if (last != NULL && cut < plen) {
                stream_len -= cut;
                last->end -= cut;
                last->touched = 1;
            }
        } else if (op == OP_KEY) {
            size_t m = fz_u8(in) % TASE_KLV_KEY_LEN + 1u;
            memcpy(stream + stream_len, key, m);
            stream_len += m;
        } else {
            size_t len = put_packet(in);
            if (len > 0u) {
                tx[k].start = (uint32_t)stream_len;
                tx[k].end = (uint32_t)(stream_len + len);
                tx[k].touched = 0;
                k++;
                stream_len += len;
            }
        }
    }
    return k;
}

static void check_complete(const sink_t *s, size_t ntx)
{
    size_t t, i;
    for (t = 0; t < ntx; t++) {
        int found = 0, excused = 0;
        if (tx[t].touched) {
            continue;
        }
        for (i = 0; i < s->n && !found; i++) {
            const ev_t *e = &s->ev[i];
            if (e->err == 0 && e->offset == tx[t].start) {
                FZ_CHECK(e->end == tx[t].end);
                /* latency: the call that fed its last byte, or 3 bytes
                 * later behind a long-form length, or flush */
                FZ_CHECK(e->in_flush ? tx[t].end + 3u > stream_len
                                     : e->call_end >= tx[t].end && e->call_start < tx[t].end + 3u);
                found = 1;
            }
        }
        for (i = 0; i < s->n && !found && !excused; i++) {
            const ev_t *e = &s->ev[i];
            excused = e->err == 0 && e->offset < tx[t].end && tx[t].start < e->end;
        }
        if (!found && !excused) {
            fprintf(stderr, "untouched packet %zu at [%u,%u) lost\n", t, (unsigned)tx[t].start,
                    (unsigned)tx[t].end);
        }
        FZ_CHECK(found || excused);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_klv_rx_t a, b;
    fz_in_t in = {data, size};
    uint8_t mode = fz_u8(&in);
    uint32_t seed = fz_u16(&in);
    sink_t sa = {&a, ev_a, 0, 0, 0, 0, 0}, sb = {&b, ev_b, 0, 0, 0, 0, 0};
    size_t ntx = 0, pos = 0, i;

    if ((mode & 1u) != 0u) {
        if (in.n > MAX_STREAM) {
            return 0;
        }
        memcpy(stream, in.p, in.n);
        stream_len = in.n;
    } else {
        ntx = build(&in);
    }
    (void)check_decode(stream, stream_len, NULL);

    FZ_CHECK(tase_klv_rx_init(&a) == TASE_OK && tase_klv_rx_init(&b) == TASE_OK);
    while (pos < stream_len) {
        size_t chunk = 1u + fz_rand(&seed) % 100u;
        if (chunk > stream_len - pos) {
            chunk = stream_len - pos;
        }
        feed(&a, &sa, pos, chunk);
        pos += chunk;
    }
    feed(&b, &sb, 0, stream_len);
    flush(&a, &sa);
    flush(&b, &sb);

    /* split independence */
    FZ_CHECK(memcmp(&a.stats, &b.stats, sizeof(a.stats)) == 0);
    FZ_CHECK(sa.n == sb.n);
    for (i = 0; i < sa.n; i++) {
        FZ_CHECK(ev_a[i].offset == ev_b[i].offset && ev_a[i].err == ev_b[i].err);
    }
    check_complete(&sa, ntx);
    check_complete(&sb, ntx);
    return 0;
}
