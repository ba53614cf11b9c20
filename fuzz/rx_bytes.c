/*
 * Fuzz harness: the datalink receiver fed arbitrary bytes.
 *
 * Input: 2 bytes seeding the split points, then the byte stream. The
 * stream is fed to one receiver in random chunks (1..300 bytes) and to a
 * second one in a single call; after every call the harness checks:
 *   - stats.bytes_in equals the bytes fed so far;
 *   - the return value equals the callbacks made by that call, and
 *     stats.frames_ok equals all callbacks so far;
 *   - every delivered frame re-encodes to exactly the input bytes at its
 *     offset, and lies inside what was fed (no false frame, no corruption,
 *     no frame from beyond the input);
 *   - bytes_discarded + bytes covered by delivered frames <= bytes_in, with
 *     equality after tase_rx_flush();
 * and at the end: flush leaves the receiver empty and reusable, and the
 * chunked and one-shot receivers saw the same frames and counters (the
 * header promises split independence).
 */
#include <string.h>

#include "fuzz.h"
#include "tase/frame.h"

#define MAX_INPUT 65536u
#define MAX_FRAMES (MAX_INPUT / 3u + 1u) /* distinct sync starts */

typedef struct {
    uint32_t offset;
    uint8_t group, type, len;
} rec_t;

typedef struct {
    const uint8_t *stream;
    size_t stream_len;
    const tase_rx_t *rx;
    size_t n;         /* callbacks so far */
    rec_t *f;         /* f[0..n) */
    uint8_t *cover;   /* cover[i] = 1 when byte i is inside a delivered frame */
    uint32_t covered; /* bytes marked in cover */
} sink_t;

static rec_t frames_a[MAX_FRAMES], frames_b[MAX_FRAMES];
static uint8_t cover_a[MAX_INPUT], cover_b[MAX_INPUT];

static void on_frame(void *user, const tase_frame_t *fr)
{
    sink_t *s = user;
    uint8_t enc[TASE_FRAME_MAX];
    size_t total = (size_t)fr->len + TASE_FRAME_OVERHEAD;
    int n;
    FZ_CHECK(fr->data != NULL);
    FZ_CHECK(fr->len <= TASE_DATA_MAX);
    /* the frame lies inside the bytes fed so far */
    FZ_CHECK((size_t)fr->offset + total <= (size_t)s->rx->stats.bytes_in);
    FZ_CHECK((size_t)fr->offset + total <= s->stream_len);
    n = tase_frame_encode(enc, sizeof(enc), fr->group, fr->type, fr->data, fr->len);
    FZ_CHECK(n == (int)total);
    FZ_CHECK(memcmp(enc, s->stream + fr->offset, total) == 0);
    FZ_CHECK(s->n < MAX_FRAMES);
    s->f[s->n].offset = fr->offset;
    s->f[s->n].group = fr->group;
    s->f[s->n].type = fr->type;
    s->f[s->n].len = fr->len;
    s->n++;
    for (n = 0; n < (int)total; n++) {
        s->covered += 1u - s->cover[fr->offset + (uint32_t)n];
        s->cover[fr->offset + (uint32_t)n] = 1;
    }
}

static void check_call(const tase_rx_t *rx, const sink_t *s, int ret, size_t before, size_t fed)
{
    FZ_CHECK(ret >= 0);
    FZ_CHECK((size_t)ret == s->n - before);
    FZ_CHECK(rx->stats.frames_ok == (uint32_t)s->n);
    FZ_CHECK(rx->stats.bytes_in == (uint32_t)fed);
    FZ_CHECK(rx->stats.bytes_discarded + s->covered <= rx->stats.bytes_in);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_rx_t a, b;
    sink_t sa, sb;
    uint32_t seed;
    size_t pos = 0, before;
    int ret;
    uint8_t probe[TASE_FRAME_MAX];
    int plen;

    if (size < 2u || size - 2u > MAX_INPUT) {
        return 0;
    }
    seed = ((uint32_t)data[0] << 8) | data[1];
    data += 2;
    size -= 2u;

    FZ_CHECK(tase_rx_init(&a) == TASE_OK);
    FZ_CHECK(tase_rx_init(&b) == TASE_OK);
    memset(cover_a, 0, size);
    memset(cover_b, 0, size);
    sa = (sink_t){data, size, &a, 0, frames_a, cover_a, 0};
    sb = (sink_t){data, size, &b, 0, frames_b, cover_b, 0};

    while (pos < size) {
        size_t chunk = 1u + fz_rand(&seed) % 300u;
        if (chunk > size - pos) {
            chunk = size - pos;
        }
        before = sa.n;
        ret = tase_rx_feed(&a, data + pos, chunk, on_frame, &sa);
        pos += chunk;
        check_call(&a, &sa, ret, before, pos);
    }
    ret = tase_rx_feed(&b, data, size, on_frame, &sb);
    check_call(&b, &sb, ret, 0, size);

    /* split independence, before and after flush */
    FZ_CHECK(memcmp(&a.stats, &b.stats, sizeof(a.stats)) == 0);
    before = sa.n;
    ret = tase_rx_flush(&a, on_frame, &sa);
    check_call(&a, &sa, ret, before, size);
    before = sb.n;
    ret = tase_rx_flush(&b, on_frame, &sb);
    check_call(&b, &sb, ret, before, size);
    FZ_CHECK(memcmp(&a.stats, &b.stats, sizeof(a.stats)) == 0);
    FZ_CHECK(sa.n == sb.n);
    FZ_CHECK(memcmp(frames_a, frames_b, sa.n * sizeof(rec_t)) == 0);

    /* every byte is now either in a delivered frame or discarded */
    FZ_CHECK(a.stats.bytes_discarded + sa.covered == (uint32_t)size);

    /* flush left the receiver empty: a fresh frame is found at once, at
     * the offset that follows the input, and nothing else is */
    FZ_CHECK(a.len == 0u && a.ncand == 0u);
    plen = tase_frame_encode(probe, sizeof(probe), 0x08, 0x10, data, size < 6u ? size : 6u);
    FZ_CHECK(plen > 0);
    {
        uint32_t ok = a.stats.frames_ok, disc = a.stats.bytes_discarded;
        tase_rx_t c = a;
        FZ_CHECK(tase_rx_feed(&c, probe, (size_t)plen, NULL, NULL) == 1);
        FZ_CHECK(c.stats.frames_ok == ok + 1u && c.stats.bytes_discarded == disc);
    }
    return 0;
}
