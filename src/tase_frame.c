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

/* Keeps the byte events of tase_rx_push() out of line, so that its fast
 * path (a byte inside a frame) needs no stack frame. GCC and clang only;
 * another compiler may inline it, which costs speed, not correctness. */
#if defined(__GNUC__)
#define RX_NOINLINE __attribute__((noinline))
#else
#define RX_NOINLINE
#endif

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
    rx->margin_ms = (uint16_t)TASE_RX_QUIET_MS;
    return TASE_OK;
}

int tase_rx_stats_reset(tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    (void)memset(&rx->stats, 0, sizeof(rx->stats));
    rx->tick_bytes = 0u; /* bytes fed from here on still count as activity */
    return TASE_OK;
}

static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};

/* What one call delivers to, and how many frames it has delivered. */
typedef struct {
    tase_rx_handler_t on_frame;
    void *user;
    uint32_t count;
} rx_call_t;

/* Count and hand on the valid frame f[0..Size+6) at stream offset
 * `offset` (f is in the window or in the caller's buffer). Returns false
 * when the callback re-initialised the receiver: the caller must then
 * leave it alone. */
static bool deliver(tase_rx_t *rx, const uint8_t *f, uint32_t offset, tase_rx_handler_t on_frame,
                    void *user)
{
    tase_frame_t fr;
    rx->stats.frames_ok++;
    if (on_frame != NULL) {
        fr.offset = offset;
        fr.group = f[4];
        fr.type = f[5];
        fr.len = (uint8_t)(f[3] - 2u);
        fr.data = &f[TASE_FRAME_HEADER];
        on_frame(user, &fr);
    }
    return rx->busy != 0u;
}

/* The greedy scan of src[0..m), with nothing pending before it. The first
 * `counted_before` bytes are already in stats.bytes_in (bytes of the
 * window); the others are counted as the scan passes them, so that a
 * callback sees bytes_in up to the byte that decided its frame (its last
 * byte, or the last byte of a longer candidate before it that failed). A
 * complete candidate is judged where it lies. The first incomplete one (a sync still arriving, or a
 * candidate whose last byte has not come) is moved with everything after
 * it to the window, unless `final` (end of input), where it fails like a
 * bad one: discard its first byte and scan on. Returns false when a
 * callback re-initialised the receiver. */
static bool scan(tase_rx_t *rx, const uint8_t *src, size_t m, size_t counted_before, bool final,
                 rx_call_t *c)
{
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
                    c->count++;
                    if (!deliver(rx, s, rx->stats.bytes_in - (uint32_t)(counted - p), c->on_frame,
                                 c->user)) {
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
 * end of input (data NULL: tase_rx_flush()). While the window holds
 * something, just enough bytes to decide it are copied in and the window is
 * scanned; once it is empty, the rest of the input is scanned in place.
 * (Five arguments, like the entry points: they can tail-call it.) */
static int run(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c;
    size_t i = 0;
    bool live = true;
    bool final = data == NULL;
    c.on_frame = on_frame;
    c.user = user;
    c.count = 0u;
    rx->busy = 1u;
    rx->end = 0u;
    while (live) {
        size_t len = rx->len;
        size_t need;
        size_t k;
        bool short_of;
        const uint8_t *src = rx->buf;
        size_t m;
        size_t counted;
        if (len == 0u) {
            if (i == n) {
                break;
            }
            /* the rest of the input, in place */
            src = &data[i];
            m = n - i;
            counted = 0u;
            i = n;
        } else if (len < 4u) {
            /* A partial sync: the input continues it into a header, or
             * breaks it. Broken, its bytes are noise (00 FF 5A with a Size
             * < 2 is a bad Size), and the byte that broke it is scanned in
             * place like the rest of the input. */
            while (len < 3u && i < n && data[i] == sync[len]) {
                rx->buf[len] = data[i];
                len++;
                i++;
                rx->stats.bytes_in++;
            }
            if (i == n && !final) {
                rx->len = (uint16_t)len;
                break;
            }
            if (len == 3u && i < n && data[i] >= 2u) {
                rx->buf[3] = data[i];
                len = 4u;
                i++;
                rx->stats.bytes_in++;
            } else {
                if (len == 3u && i < n) {
                    rx->stats.bad_size++;
                }
                rx->stats.bytes_discarded += (uint32_t)len;
                len = 0u;
            }
            rx->len = (uint16_t)len;
            continue;
        } else {
            /* the rest of the held candidate (rx_sane: Size >= 2) */
            need = (size_t)rx->buf[3] + 6u - len;
            short_of = n - i < need;
            k = short_of ? n - i : need;
            if (k > 0u) {
                (void)memcpy(&rx->buf[len], &data[i], k);
                rx->len = (uint16_t)(len + k);
                rx->stats.bytes_in += (uint32_t)k;
                i += k;
            }
            if (short_of && !final) {
                break; /* its last byte is still to come */
            }
            m = rx->len;
            counted = m;
        }
        /* one call site: scan() is inlined here, one stack frame for both */
        live = scan(rx, src, m, counted, final, &c);
    }
    if (live) {
        rx->end = (rx->len >= 4u) ? (uint16_t)(rx->buf[3] + 5u) : 0u;
        rx->busy = 0u;
    }
    return (c.count > (uint32_t)INT_MAX) ? INT_MAX : (int)c.count;
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

/* What every entry point checks: rx NULL, a call in progress, visibly
 * corrupted. */
static int rx_check(const tase_rx_t *rx)
{
    if (rx == NULL) {
        return TASE_EARG;
    }
    if (rx->busy != 0u) {
        /* 1 while a callback runs; anything else is a corrupted instance */
        return rx->busy == 1u ? TASE_EBUSY : TASE_EARG;
    }
    return rx_sane(rx) ? TASE_OK : TASE_EARG;
}

/* tase_rx_push() for the last byte of a held candidate (and for a receiver
 * that is busy or visibly corrupted). A valid frame is delivered from the
 * window; a failed one leaves the byte in the window for the general path
 * to scan on. */
RX_NOINLINE static int push_event(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    uint16_t len = rx->len;
    uint16_t want;
    if (rx->busy != 0u) {
        return rx->busy == 1u ? TASE_EBUSY : TASE_EARG;
    }
    /* tase_rx_push() took every other byte of a sane receiver: held
     * candidate (len >= 4) and len == end is what is left */
    if (len < 4u || !rx_sane(rx)) {
        return TASE_EARG;
    }
    rx->stats.bytes_in++;
    want = (uint16_t)(((uint16_t)rx->buf[len - 1u] << 8) | b);
    if (tase_checksum(0u, rx->buf, (size_t)len - 1u) == want) {
        rx->len = 0u;
        rx->end = 0u;
        rx->busy = 1u;
        (void)deliver(rx, rx->buf, rx->stats.bytes_in - (uint32_t)len - 1u, on_frame, user);
        rx->busy = 0u; /* also right when the callback re-initialised rx */
        return 1;
    }
    rx->stats.checksum_errors++;
    rx->buf[len] = b;
    rx->len = (uint16_t)(len + 1u);
    rx->buf[0] = TASE_SYNC2;                     /* judged: its first byte is noise to the scan */
    return run(rx, rx->buf, 0u, on_frame, user); /* no new byte, not the end */
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
    /* Hunting a sync, or its Size byte (nothing or a partial sync held, so
     * end is 0). */
    if (len < 4u && end == 0u && rx->busy == 0u) {
        rx->stats.bytes_in++;
        if ((len < 3u) ? (byte == sync[len]) : (byte >= 2u)) {
            rx->buf[len] = byte;
            rx->len = (uint16_t)(len + 1u);
            if (len == 3u) {
                rx->end = (uint16_t)(byte + 5u);
            }
        } else {
            /* Broken (a Size < 2 is a bad Size): the bytes held are noise;
             * a 00 may begin a sync, keep it (buf[0] is 00 already). */
            uint16_t keep = 0u;
            if (byte == TASE_SYNC1) {
                keep = 1u;
            }
            if (len == 3u) {
                rx->stats.bad_size++;
            }
            rx->stats.bytes_discarded += (uint32_t)(len + 1u - keep);
            rx->len = keep;
        }
        return 0;
    }
    return push_event(rx, byte, on_frame, user);
}

int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user)
{
    int r = (data == NULL && n > 0u) ? TASE_EARG : rx_check(rx);
    if (r != TASE_OK) {
        return r;
    }
    return run(rx, (data != NULL) ? data : rx->buf, n, on_frame, user); /* NULL: flush */
}

int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    int r = rx_check(rx);
    return (r != TASE_OK) ? r : run(rx, NULL, 0u, on_frame, user);
}

int tase_rx_set_timing(tase_rx_t *rx, uint32_t bytes_per_s, uint16_t margin_ms)
{
    int r = rx_check(rx);
    if (r == TASE_OK) {
        rx->rate = bytes_per_s;
        rx->margin_ms = (margin_ms != 0u) ? margin_ms : (uint16_t)TASE_RX_QUIET_MS;
    }
    return r;
}

/* The quiet limit of what the window holds (frame.h, TIME BOUND): the
 * time its remaining bytes need at the link's rate, or the margin. */
static uint32_t quiet_limit(const tase_rx_t *rx)
{
    uint32_t rate = (rx->rate != 0u) ? rx->rate : TASE_RX_SLOWEST_RATE;
    uint32_t left =
        (rx->len >= 4u) ? (uint32_t)rx->end + 1u - rx->len : (uint32_t)TASE_FRAME_MAX - rx->len;
    uint32_t ms = (left * 1000u + rate - 1u) / rate; /* at most 261,000 / 1 */
    return (ms > rx->margin_ms) ? ms : rx->margin_ms;
}

/* Milliseconds from `since` to `now`; 0 for a sample older than `since`
 * (a difference of 2^31 or more, the port contract's "not yet"). */
static uint32_t quiet_for(uint32_t now, uint32_t since)
{
    uint32_t d = now - since;
    return (d >= 0x80000000u) ? 0u : d;
}

int tase_rx_tick(tase_rx_t *rx, uint32_t now_ms, tase_rx_handler_t on_frame, void *user)
{
    int r = rx_check(rx);
    if (r != TASE_OK) {
        return r;
    }
    if (rx->ticked == 0u || rx->stats.bytes_in != rx->tick_bytes) {
        rx->ticked = 1u;
        rx->tick_bytes = rx->stats.bytes_in;
        rx->quiet_since = now_ms;
        return 0;
    }
    if (rx->len == 0u || quiet_for(now_ms, rx->quiet_since) <= quiet_limit(rx)) {
        return 0;
    }
    return run(rx, NULL, 0u, on_frame, user); /* as at end of input */
}

uint32_t tase_rx_quiet_ms(const tase_rx_t *rx, uint32_t now_ms)
{
    uint32_t limit;
    uint32_t quiet;
    if (rx == NULL || rx->len == 0u) {
        return UINT32_MAX;
    }
    if (rx->ticked == 0u || rx->stats.bytes_in != rx->tick_bytes) {
        return 0u;
    }
    limit = quiet_limit(rx);
    quiet = quiet_for(now_ms, rx->quiet_since);
    /* a tick settles once the quiet time is past the limit: one ms more */
    return (quiet > limit) ? 0u : limit - quiet + 1u;
}
