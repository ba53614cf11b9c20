/*
 * Frame encoder and receiver. The contract (which frames, order, latency,
 * re-entrancy) is in include/tase/frame.h; comments here explain how.
 *
 * The receiver runs the greedy scan of frame.h online. Its whole state is
 * the window buf[0..len), which holds one of:
 *   - nothing (len 0);
 *   - a partial sync: 00, 00 FF or 00 FF 5A (len 1..3, end 0);
 *   - the earliest pending candidate, from its first sync byte on: Size
 *     >= 2 known, last byte still to come (4 <= len <= end, end = Size + 5).
 * Bytes after a pending candidate are not examined: a frame in them could
 * only be delivered if the candidate fails, and then the rest of the window
 * is scanned as if it were new input (scan()). So the scan position never
 * moves back, each candidate is judged once, and nothing needs tracking
 * besides the one candidate.
 *
 * tase_rx_push() stores a byte inside a frame with one test (len < end).
 * Every other path runs with `busy` set and `end` zero, so that test fails
 * while a callback runs and a re-entrant call lands on the busy check.
 */
#include "tase/frame.h"

#include <limits.h>
#include <string.h>

#define RX_CAP ((uint16_t)TASE_FRAME_MAX)

/* C99 has no _Static_assert: a negative array size fails the build. */
typedef char tase_rx_size_check[sizeof(tase_rx_t) <= TASE_RX_SIZE_BUDGET ? 1 : -1];
typedef char tase_rx_cand_check[(TASE_RX_CANDIDATES >= 1 && TASE_RX_CANDIDATES <= 16) ? 1 : -1];

/* The checksum adds a machine word of bytes per step: the word is split
 * into 16-bit lanes (even and odd bytes) that are added and folded at the
 * end. Byte order does not matter to a sum. A lane gains at most 2 * 255
 * per word, so folding every 128 words keeps it below 2^16. 32-bit targets
 * use 32-bit words (64-bit arithmetic costs them code and stack). */
#if defined(UINTPTR_MAX) && UINTPTR_MAX > 0xFFFFFFFFu
typedef uint64_t sum_word_t;
#define SUM_LANES 0x00FF00FF00FF00FFu

/* Sum of the four 16-bit lanes: pairs first, into two 32-bit lanes. */
static uint32_t lane_total(uint64_t lanes)
{
    uint64_t pairs = (lanes & 0x0000FFFF0000FFFFu) + ((lanes >> 16) & 0x0000FFFF0000FFFFu);
    return (uint32_t)(pairs & 0xFFFFFFFFu) + (uint32_t)(pairs >> 32);
}
#else
typedef uint32_t sum_word_t;
#define SUM_LANES 0x00FF00FFu

static uint32_t lane_total(uint32_t lanes)
{
    return (lanes & 0xFFFFu) + (lanes >> 16);
}
#endif

uint16_t tase_checksum(uint16_t seed, const uint8_t *p, size_t n)
{
    uint32_t sum = seed;
    size_t i = 0;
    if (p == NULL) {
        return seed;
    }
    while (n - i >= sizeof(sum_word_t)) {
        sum_word_t lanes = 0u;
        size_t stop = i + sizeof(sum_word_t) * 128u;
        if (stop > n) {
            stop = n;
        }
        while (stop - i >= sizeof(sum_word_t)) {
            sum_word_t w;
            /* A word of bytes at any alignment: memcpy is the defined way
             * to load it (a cast would break 11.3 and alignment). */
            /* cppcheck-suppress misra-c2012-21.15 */
            (void)memcpy(&w, &p[i], sizeof(w));
            lanes += (w & SUM_LANES) + ((w >> 8) & SUM_LANES);
            i += sizeof(sum_word_t);
        }
        sum += lane_total(lanes);
    }
    for (; i < n; i++) {
        sum += p[i];
    }
    return (uint16_t)sum;
}

int tase_frame_encode(uint8_t *out, size_t cap, uint8_t group, uint8_t type, const uint8_t *data,
                      size_t len)
{
    uint16_t sum;
    size_t total;
    if (out == NULL || (data == NULL && len > 0u)) {
        return TASE_EARG;
    }
    if (len > TASE_DATA_MAX) {
        return TASE_ETOOLONG;
    }
    total = len + TASE_FRAME_OVERHEAD;
    if (cap < total) {
        return TASE_ENOSPC;
    }
    if (len > 0u) {
        (void)memmove(out + TASE_FRAME_HEADER, data, len);
    }
    out[0] = TASE_SYNC1;
    out[1] = TASE_SYNC2;
    out[2] = TASE_SYNC3;
    out[3] = (uint8_t)(len + 2u);
    out[4] = group;
    out[5] = type;
    sum = tase_checksum(0u, out, len + TASE_FRAME_HEADER);
    out[len + TASE_FRAME_HEADER] = (uint8_t)(sum >> 8);
    out[len + TASE_FRAME_HEADER + 1u] = (uint8_t)(sum & 0xFFu);
    return (int)total;
}

int tase_rx_init(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    /* Clears `busy` too: a call whose callback re-initialises the receiver
     * sees that and returns without touching it again. */
    (void)memset(rx, 0, sizeof(*rx));
    return TASE_OK;
}

int tase_rx_stats_reset(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    (void)memset(&rx->stats, 0, sizeof(rx->stats));
    return TASE_OK;
}

/* What one call delivers to, and how many frames it has delivered. */
typedef struct {
    tase_rx_handler_t on_frame;
    void *user;
    uint32_t count;
} rx_call_t;

/* Hand on the valid frame f[0..Size+6) at stream offset `offset` (f is in
 * the window or in the caller's buffer). Returns false when the callback
 * re-initialised the receiver: the caller must then leave it alone. */
static bool deliver(tase_rx_t *rx, const uint8_t *f, uint32_t offset, rx_call_t *c)
{
    tase_frame_t fr;
    rx->stats.frames_ok++;
    c->count++;
    if (c->on_frame != NULL) {
        fr.offset = offset;
        fr.group = f[4];
        fr.type = f[5];
        fr.len = (uint8_t)(f[3] - 2u);
        fr.data = &f[TASE_FRAME_HEADER];
        c->on_frame(c->user, &fr);
    }
    return rx->busy != 0u;
}

/* The greedy scan of src[0..m), with nothing pending before it. The first
 * `counted` bytes are already in stats.bytes_in (bytes of the window); the
 * others are counted as the scan passes them, so that a callback sees
 * bytes_in up to the frame's last byte. A complete candidate is judged
 * where it lies. The first incomplete one (a sync still arriving, or a
 * candidate whose last byte has not come) is moved with everything after
 * it to the window, unless `final` (end of input), where it fails like a
 * bad one: discard its first byte and scan on. Returns false when a
 * callback re-initialised the receiver. */
static bool scan(tase_rx_t *rx, const uint8_t *src, size_t m, size_t counted_before, bool final,
                 rx_call_t *c)
{
    static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};
    size_t p = 0;
    size_t held = 0;
    size_t counted = counted_before;
    while (p < m) {
        const uint8_t *s = &src[p];
        size_t avail = m - p;
        size_t k = 1;
        if (s[0] != TASE_SYNC1) {
            /* noise up to the next 00 */
            const uint8_t *z = memchr(s, TASE_SYNC1, avail);
            size_t skip = (z != NULL) ? (size_t)(z - s) : avail;
            rx->stats.bytes_discarded += (uint32_t)skip;
            p += skip;
            continue;
        }
        while (k < 3u && k < avail && s[k] == sync[k]) {
            k++;
        }
        if (k == 3u && avail > 3u) {
            size_t flen = (size_t)s[3] + 6u;
            if (s[3] < 2u) {
                rx->stats.bad_size++;
            } else if (flen <= avail) {
                uint16_t want = (uint16_t)(((uint16_t)s[flen - 2u] << 8) | s[flen - 1u]);
                if (tase_checksum(0u, s, flen - 2u) == want) {
                    if (p + flen > counted) {
                        rx->stats.bytes_in += (uint32_t)(p + flen - counted);
                        counted = p + flen;
                    }
                    if (!deliver(rx, s, rx->stats.bytes_in - (uint32_t)(counted - p), c)) {
                        return false;
                    }
                    p += flen;
                    continue;
                }
                /* Failed, after looking up to its last byte: a frame
                 * found inside it is delivered as of that byte, the same
                 * moment as when the stream comes one byte at a time. */
                rx->stats.checksum_errors++;
                if (p + flen > counted) {
                    rx->stats.bytes_in += (uint32_t)(p + flen - counted);
                    counted = p + flen;
                }
            } else if (!final) {
                held = avail; /* a candidate whose last byte is still to come */
                break;
            } else {
                /* end of input: it can no longer complete */
            }
        } else if (k == avail && !final) {
            held = avail; /* a sync still arriving */
            break;
        } else {
            /* not a sync */
        }
        rx->stats.bytes_discarded++;
        p++;
    }
    if (m > counted) {
        rx->stats.bytes_in += (uint32_t)(m - counted);
    }
    if (held > 0u && &src[p] != rx->buf) {
        (void)memmove(rx->buf, &src[p], held);
    }
    rx->len = (uint16_t)held;
    return true;
}

/* The general path: feed data[0..n) (n may be 0), or settle everything at
 * end of input (`final`). While the window holds something, just enough
 * bytes to decide it are copied in and the window is scanned; once it is
 * empty, the rest of the input is scanned in place. */
static int run(tase_rx_t *rx, const uint8_t *data, size_t n, bool final, rx_call_t *c)
{
    size_t i = 0;
    bool live = true;
    rx->busy = 1u;
    rx->end = 0u;
    while (live) {
        size_t len = rx->len;
        size_t need;
        size_t k;
        bool short_of;
        if (len == 0u) {
            if (i < n) {
                live = scan(rx, &data[i], n - i, 0u, final, c);
            }
            break;
        }
        /* the rest of the header, or of the held candidate */
        need = (len < 4u) ? 4u - len : (size_t)rx->buf[3] + 6u - len;
        short_of = n - i < need;
        k = short_of ? n - i : need;
        if (k > 0u) {
            (void)memcpy(&rx->buf[len], &data[i], k);
            rx->len = (uint16_t)(len + k);
            rx->stats.bytes_in += (uint32_t)k;
            i += k;
        }
        /* Scan unless nothing can be decided yet: no new byte, or a held
         * candidate still short of its last byte. (A partial sync is
         * decided by any byte that breaks it.) */
        if (short_of && !final && (k == 0u || rx->len >= 4u)) {
            break;
        }
        live = scan(rx, rx->buf, rx->len, rx->len, final, c);
    }
    if (live) {
        rx->end = (rx->len >= 4u) ? (uint16_t)(rx->buf[3] + 5u) : 0u;
        rx->busy = 0u;
    }
    return (c->count > (uint32_t)INT_MAX) ? INT_MAX : (int)c->count;
}

/* What every entry point checks of an instance, so that a corrupted or
 * never-initialised one gives TASE_EARG instead of indexing outside buf:
 * nothing held beyond a partial sync without a candidate, and a held
 * candidate's end agrees with its Size byte and lies ahead. */
static bool rx_sane(const tase_rx_t *rx)
{
    uint16_t len = rx->len;
    if (len < 4u) {
        return rx->end == 0u;
    }
    return rx->buf[3] >= 2u && rx->end == (uint16_t)(rx->buf[3] + 5u) && len <= rx->end;
}

/* What every entry point checks (rx NULL, a call in progress, visibly
 * corrupted), and the context of the call. */
static int rx_begin(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user, rx_call_t *c)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    if (rx->busy != 0u) {
        return TASE_EBUSY;
    }
    if (!rx_sane(rx)) {
        return TASE_EARG;
    }
    c->on_frame = on_frame;
    c->user = user;
    c->count = 0u;
    return TASE_OK;
}

int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user)
{
    rx_call_t c;
    int r = (data == NULL && n > 0u) ? TASE_EARG : rx_begin(rx, on_frame, user, &c);
    return (r != TASE_OK) ? r : run(rx, data, n, false, &c);
}

/* tase_rx_push() for every byte that is not simply stored: the byte state
 * machine of a classic parser (hunt the sync, take the Size, check the
 * last byte), and the general path only when a candidate fails. */
static int push_event(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};
    uint16_t len = rx->len;
    rx_call_t c;
    int r = rx_begin(rx, on_frame, user, &c);
    if (r != TASE_OK) {
        return r;
    }
    if (len < 3u) {
        rx->stats.bytes_in++;
        if (b == sync[len]) {
            rx->buf[len] = b;
            rx->len = (uint16_t)(len + 1u);
        } else {
            /* a 00 may begin a sync: keep it (buf[0] is 00 already) */
            uint16_t keep = 0u;
            if (b == TASE_SYNC1) {
                keep = 1u;
            }
            rx->stats.bytes_discarded += (uint32_t)(len + 1u - keep);
            rx->len = keep;
        }
        return 0;
    }
    if (len == 3u && b >= 2u) {
        rx->stats.bytes_in++;
        rx->buf[3] = b;
        rx->len = 4u;
        rx->end = (uint16_t)(b + 5u);
        return 0;
    }
    if (len > 3u && len == rx->end) { /* the held candidate's last byte */
        uint16_t want = (uint16_t)(((uint16_t)rx->buf[len - 1u] << 8) | b);
        rx->stats.bytes_in++;
        if (tase_checksum(0u, rx->buf, (size_t)len - 1u) == want) {
            rx->len = 0u;
            rx->end = 0u;
            rx->busy = 1u;
            (void)deliver(rx, rx->buf, rx->stats.bytes_in - (uint32_t)len - 1u, &c);
            rx->busy = 0u; /* also right when the callback re-initialised rx */
            return 1;
        }
        rx->stats.checksum_errors++;
        rx->buf[len] = b;
        rx->len = (uint16_t)(len + 1u);
        /* Judged: make its first byte noise for the scan of the rest. */
        rx->buf[0] = TASE_SYNC2;
        return run(rx, NULL, 0u, false, &c);
    }
    return run(rx, &b, 1u, false, &c); /* Size < 2 */
}

int tase_rx_push(tase_rx_t *rx, uint8_t byte, tase_rx_handler_t on_frame, void *user)
{
    uint16_t len;
    uint16_t end;
    if (rx == NULL) {
        return TASE_EARG;
    }
    len = rx->len;
    end = rx->end;
    /* Inside a held candidate, not its last byte: store it. (end < RX_CAP
     * holds for any initialised receiver; testing it keeps a corrupted one
     * inside buf.) */
    if (len < end && end < RX_CAP) {
        rx->buf[len] = byte;
        rx->len = (uint16_t)(len + 1u);
        rx->stats.bytes_in++;
        return 0;
    }
    return push_event(rx, byte, on_frame, user);
}

int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c;
    int r = rx_begin(rx, on_frame, user, &c);
    return (r != TASE_OK) ? r : run(rx, NULL, 0u, true, &c);
}
