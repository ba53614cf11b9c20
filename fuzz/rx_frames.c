/*
 * Fuzz harness: valid frames (checksums computed here, so the fuzzer never
 * has to guess them) interleaved with fuzz-chosen noise and corruptions.
 *
 * Input: 2 bytes seeding the split points, then records, each an op byte
 * (low 3 bits) followed by its arguments:
 *   FZ_OP_FRAME  group, type, len (0..253: byte % 254), data bytes: append
 *                a valid frame;
 *   FZ_OP_NOISE  n (0..63), n raw bytes: append them (may hold syncs or
 *                whole frames of their own);
 *   FZ_OP_SYNC   size: append a false 00 FF 5A <size> header;
 *   FZ_OP_FLIP   pos, mask: XOR a byte of the last frame (mask 0 = none);
 *   FZ_OP_DROP   pos: remove a byte of the last frame;
 *   FZ_OP_INSERT pos, byte: insert a byte into the last frame;
 *   FZ_OP_TRUNC  n: cut the last n+1 bytes of the last frame.
 * Ops 5..7 are FZ_OP_FRAME again so that frames dominate.
 *
 * The checked property is zero collateral loss: every frame whose own
 * bytes were left untouched is delivered exactly once, in order, at its
 * offset, and within the documented latency bound (TASE_FRAME_MAX - 8
 * bytes when it lay inside a pending candidate, plus the scan's lag of at
 * most TASE_RX_LATE_MAX bytes).
 * The only excuse for missing one is a delivered frame that is not one of
 * ours overlapping it (a valid frame hidden in noise or in a corrupted
 * frame, or a checksum collision): the receiver cannot tell that frame
 * from a real one, and a valid frame's bytes are never re-used. Delivered
 * frames come in stream order and never overlap.
 */
#include <string.h>

#include "fuzz.h"
#include "tase/frame.h"

#define MAX_STREAM 65536u
#define MAX_TX 8192u
#define MAX_RX (MAX_STREAM / 3u + 1u)

enum { FZ_OP_FRAME, FZ_OP_NOISE, FZ_OP_SYNC, FZ_OP_FLIP, FZ_OP_DROP, FZ_OP_INSERT, FZ_OP_TRUNC };

typedef struct {
    uint32_t start, end; /* [start, end) in the stream */
    uint8_t touched;
} tx_t;

typedef struct {
    uint32_t start, end;
    uint32_t seen_at; /* bytes fed when delivered */
    uint8_t in_flush;
} rx_rec_t;

static uint8_t stream[MAX_STREAM + TASE_FRAME_MAX];
static tx_t tx[MAX_TX];
static rx_rec_t got[MAX_RX];

typedef struct {
    const tase_rx_t *rx;
    size_t n;
    uint8_t flushing;
} sink_t;

static void on_frame(void *user, const tase_frame_t *fr)
{
    sink_t *s = user;
    FZ_CHECK(s->n < MAX_RX);
    /* stream order; nothing inside (or overlapping) a delivered frame */
    FZ_CHECK(s->n == 0u || fr->offset >= got[s->n - 1u].end);
    got[s->n].start = fr->offset;
    got[s->n].end = fr->offset + fr->len + TASE_FRAME_OVERHEAD;
    got[s->n].seen_at = s->rx->stats.bytes_in;
    got[s->n].in_flush = s->flushing;
    FZ_CHECK(memcmp(fr->data, stream + fr->offset + TASE_FRAME_HEADER, fr->len) == 0);
    s->n++;
}

/* Build the stream; returns its length and sets *ntx. */
static size_t build(fz_in_t *in, size_t *ntx)
{
    size_t n = 0, k = 0;
    while (fz_more(in) && n + TASE_FRAME_MAX + 1u <= MAX_STREAM && k < MAX_TX) {
        uint8_t op = (uint8_t)(fz_u8(in) & 7u);
        tx_t *last = (k > 0u && tx[k - 1u].end == n && tx[k - 1u].end > tx[k - 1u].start)
                         ? &tx[k - 1u]
                         : NULL;
        uint32_t flen = (last != NULL) ? last->end - last->start : 0u;
        if (op == FZ_OP_NOISE) {
            size_t m = fz_u8(in) & 63u, j;
            for (j = 0; j < m; j++) {
                stream[n++] = fz_u8(in);
            }
        } else if (op == FZ_OP_SYNC) {
            stream[n++] = TASE_SYNC1;
            stream[n++] = TASE_SYNC2;
            stream[n++] = TASE_SYNC3;
            stream[n++] = fz_u8(in);
        } else if (op == FZ_OP_FLIP) {
            uint8_t pos = fz_u8(in), mask = fz_u8(in);
            if (last != NULL && mask != 0u) {
                stream[last->start + pos % flen] ^= mask;
                last->touched = 1;
            }
        } else if (op == FZ_OP_DROP) {
            uint8_t pos = fz_u8(in);
            if (last != NULL) {
                uint32_t at = last->start + pos % flen;
                memmove(stream + at, stream + at + 1, n - at - 1u);
                n--;
                last->end--;
                last->touched = 1;
            }
        } else if (op == FZ_OP_INSERT) {
            uint8_t pos = fz_u8(in), b = fz_u8(in);
            if (last != NULL) {
                uint32_t at = last->start + pos % flen;
                memmove(stream + at + 1, stream + at, n - at);
                stream[at] = b;
                n++;
                last->end++;
                last->touched = 1;
            }
        } else if (op == FZ_OP_TRUNC) {
            uint8_t cut = (uint8_t)(fz_u8(in) % 8u + 1u);
            if (last != NULL && cut < flen) {
                n -= cut;
                last->end -= cut;
                last->touched = 1;
            }
        } else {
            uint8_t group = fz_u8(in), type = fz_u8(in);
            size_t len = fz_u8(in) % (TASE_DATA_MAX + 1u), j;
            uint8_t data[TASE_DATA_MAX];
            int w;
            for (j = 0; j < len; j++) {
                data[j] = fz_u8(in);
            }
            w = tase_frame_build(group, type, data, len, stream + n, TASE_FRAME_MAX);
            FZ_CHECK(w == (int)(len + TASE_FRAME_OVERHEAD));
            tx[k].start = (uint32_t)n;
            tx[k].end = (uint32_t)(n + (size_t)w);
            tx[k].touched = 0;
            k++;
            n += (size_t)w;
        }
    }
    *ntx = k;
    return n;
}

/* Is got[i] one of our untouched frames? */
static int is_ours(const rx_rec_t *g, size_t ntx)
{
    size_t lo = 0, hi = ntx;
    while (lo < hi) { /* tx[] is sorted by start */
        size_t mid = (lo + hi) / 2u;
        if (tx[mid].start < g->start) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo < ntx && tx[lo].start == g->start && tx[lo].end == g->end && !tx[lo].touched;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_rx_t rx;
    fz_in_t in = {data, size};
    uint32_t seed = fz_u16(&in);
    size_t n, ntx, pos = 0, k, g = 0;
    sink_t sink = {&rx, 0, 0};

    n = build(&in, &ntx);
    FZ_CHECK(tase_rx_init(&rx) == TASE_OK);
    while (pos < n) {
        size_t chunk = 1u + fz_rand(&seed) % 64u;
        if (chunk > n - pos) {
            chunk = n - pos;
        }
        FZ_CHECK(tase_rx_feed(&rx, stream + pos, chunk, on_frame, &sink) >= 0);
        pos += chunk;
    }
    sink.flushing = 1;
    FZ_CHECK(tase_rx_flush(&rx, on_frame, &sink) >= 0);
    FZ_CHECK(rx.stats.bytes_in == (uint32_t)n);

    /* Walk our untouched frames and the deliveries of ours in parallel. */
    for (k = 0; k < ntx; k++) {
        const tx_t *t = &tx[k];
        size_t j;
        int excused = 0;
        if (t->touched) {
            continue;
        }
        while (g < sink.n && !(is_ours(&got[g], ntx))) {
            g++;
        }
        if (g < sink.n && got[g].start == t->start) {
            /* delivered, in order; latency bound */
            FZ_CHECK(got[g].end == t->end);
            FZ_CHECK(got[g].seen_at >= t->end);
            FZ_CHECK(got[g].in_flush ||
                     got[g].seen_at - t->end <= TASE_FRAME_MAX - 8u + TASE_RX_LATE_MAX);
            g++;
            continue;
        }
        /* missing: only a foreign delivered frame overlapping it excuses it */
        for (j = 0; j < sink.n && !excused; j++) {
            excused = !is_ours(&got[j], ntx) && got[j].start < t->end && t->start < got[j].end;
        }
        if (!excused) {
            fprintf(stderr, "untouched frame %zu at [%u,%u) lost\n", k, (unsigned)t->start,
                    (unsigned)t->end);
        }
        FZ_CHECK(excused);
    }
    /* no frame of ours delivered twice or out of order */
    while (g < sink.n) {
        FZ_CHECK(!is_ours(&got[g], ntx));
        g++;
    }
    return 0;
}
