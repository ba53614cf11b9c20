/*
 * Frame encoder, checksum and receiver: everything of include/tase/frame.h
 * that takes stream bytes. The contract (which frames, order, latency, cost
 * per call, re-entrancy) is in frame.h; comments here explain how. The
 * receiver's set-up and its time bound (tase_rx_init(),
 * tase_rx_stats_reset(), tase_rx_set_timing(), tase_rx_tick(),
 * tase_rx_quiet_ms()) and tase_rx_stop() are src/tase_frame_time.c.
 *
 * The receiver runs the greedy scan of frame.h online, over a window
 * buf[0..len) of the bytes received and not yet decided. buf[scan] is the
 * scan position: everything before it is decided (delivered or
 * discarded), and buf[0..scan) is dead space, dropped by compact() when
 * room is needed. From buf[scan] on the window holds
 *   - nothing, a partial sync (00, 00 FF, 00 FF 5A: then scan is 0) or a
 *     candidate whose last byte has not come (Size >= 2 known, `end` the
 *     index of its last byte): the scan has caught up (lag 0); or
 *   - bytes not yet examined (lag 1): a call stopped scanning because it
 *     had spent its credit. Each later call, even one that brings no byte,
 *     continues the scan before anything else, with the credit it brings.
 * The scan position never moves back: each position is examined once and
 * each candidate judged once.
 *
 * Judging a complete candidate needs the 16-bit sum of its bytes before
 * the checksum. sum_len (the sum of buf[0..len) plus a constant) grows
 * with every byte stored; sum_scan is the same up to buf[scan]. The
 * candidate's sum is prefix(be) - sum_scan, where be is the index of its
 * Check_0 byte and prefix(be) is summed forward from scan, backward from
 * len, or either way from the sum cursor (at, sum_at: the last judged
 * candidate's be and prefix(be)), whichever is shortest: for the held
 * candidate whose last byte just came, that is 2 bytes back; for syncs a
 * few bytes apart, the distance between two candidates' ends. (compact()
 * moves the constant, not the sums: the differences stay right; it moves
 * `at` with its byte.) The cursor is 0 (none) whenever len may be cut
 * back: an emptied window, hunting (a partial sync held), a delivery by
 * push_last().
 *
 * CREDIT. Every byte taken in brings RX_BUDGET units of scan work (a
 * unit is about an instruction on a Cortex-M4; see the costs below); the
 * scan spends them and stops with lag 1 when they run out. What a byte
 * leaves is kept in `bank` (with `bank_at`, the byte count then) up to
 * RX_BANK_MAX, so the credit of a byte depends on the byte count only and
 * a quiet receiver settles an isolated failure at once. While tase_rx_feed()
 * has input left, a scan that runs out takes the next byte in itself
 * (take()) instead of returning to run() for it. Whatever work the window
 * holds is bounded (RX_WORK_MAX below), so a frame comes out at most
 * TASE_RX_LATE_MAX bytes after the byte that decides it (frame.h,
 * LATENCY). A byte that finds the window full first makes room: one step
 * of the scan if the scan is at buf[0] (on top of the credit), then
 * compact().
 *
 * tase_rx_push() stores a byte inside a held candidate with one test
 * (len < end) and nothing saved but the return address; the sync and Size
 * bytes of a frame (push_other()), the last byte of a candidate
 * (push_last()), a lagging scan's byte (push_lag(), with the scan compiled
 * in, except at -Os: RX_LAG_FUSED) and every other byte (push_body():
 * stored, then the scan on its credit, as run() does) are out of line.
 * Every other
 * path runs with `busy` set and `end` RX_BLOCKED, so that test fails while
 * a callback runs and a re-entrant call lands on the busy check.
 */
#include "tase/frame.h"

#include <limits.h>
#include <string.h>

#include "tase_frame_private.h"

#define RX_CAP ((uint16_t)TASE_RX_WINDOW)

/* The scan's credit per byte taken in and its cap (frame.h COST, CREDIT
 * above), in units of about one instruction of the scan on a Cortex-M4
 * (measured: bench/, docs/TIMING.md), so that the credit bounds the time
 * of a call and not only its steps: every position the scan examines
 * costs RX_COST_STEP, every noise byte walked RX_COST_NOISE, a complete
 * candidate judged RX_COST_JUDGE plus a unit per byte summed, a delivery
 * RX_COST_FRAME. A step starts only with at least RX_COST_STEP left (or
 * when it only holds: the scan has caught up, which needs no credit), a
 * judgement only with RX_COST_JUDGE left, and a noise walk goes only as
 * far as what is left pays for. */
#define RX_BUDGET 128u
#define RX_BANK_MAX 384u
#define RX_COST_STEP 24u
#define RX_COST_NOISE 4u
#define RX_COST_JUDGE 48u
#define RX_COST_FRAME 48u
#define RX_UNLIMITED INT32_MAX

/* Work a window can hold for the scan, in units: every position a step
 * and a noise byte; every judged candidate (00 FF 5A Size with Size >= 2:
 * the next one starts 4 bytes later at the earliest) RX_COST_JUDGE and a
 * sum of at most half the window (the shorter of the two ways, which
 * together span at most the window); every frame delivered (at least 8
 * bytes each) RX_COST_FRAME; and one compaction (a unit per byte). A frame
 * the reference decides at byte t lies in the window at t with everything
 * before it, and every byte from t on brings RX_BUDGET units (a byte never
 * waits behind a full window: the byte that finds it full is stored after
 * a step taken on top of the credit). So the frame is delivered by the
 * call that takes byte t + (RX_WORK_MAX + RX_COST_JUDGE) / RX_BUDGET
 * (rounded up, see the checks below) at the latest: TASE_RX_LATE_MAX. */
#define RX_WORK_MAX                                                                                \
    ((uint32_t)RX_CAP * (RX_COST_STEP + RX_COST_NOISE) +                                           \
     ((uint32_t)RX_CAP / 4u + 1u) * (RX_COST_JUDGE + (uint32_t)RX_CAP / 2u) +                      \
     ((uint32_t)RX_CAP / 8u) * RX_COST_FRAME + 2u * (uint32_t)RX_CAP)
/* A judgement costs at least RX_COST_STEP + RX_COST_JUDGE + 2; the last
 * one may overrun the credit, and a byte that finds the window full takes
 * one step more. */
typedef char tase_rx_judge_check
    [RX_BANK_MAX / (RX_COST_STEP + RX_COST_JUDGE + 2u) + 2u <= TASE_RX_JUDGE_MAX ? 1 : -1];
/* A lagging scan stops with less than RX_COST_JUDGE left, and what it
 * leaves plus a byte's RX_BUDGET never exceeds RX_BANK_MAX: so over m
 * bytes it spends at least m * RX_BUDGET - RX_COST_JUDGE + 1 units. */
typedef char tase_rx_bank_check[RX_COST_JUDGE + RX_BUDGET <= RX_BANK_MAX ? 1 : -1];
typedef char tase_rx_late_check
    [(RX_WORK_MAX + RX_COST_JUDGE + RX_BUDGET - 1u) / RX_BUDGET <= TASE_RX_LATE_MAX ? 1 : -1];

/* Keeps the other paths of tase_rx_push() out of line, so that its fast
 * path (a byte inside a frame) saves nothing but the return address. GCC
 * and clang only;
 * another compiler may inline it, which costs speed, not correctness. */
#if defined(__GNUC__)
#define RX_NOINLINE __attribute__((noinline))
#define RX_INLINE __inline__ __attribute__((always_inline))
#define RX_LIKELY(x) __builtin_expect(!!(x), 1)
#else
#define RX_NOINLINE
#define RX_INLINE
#define RX_LIKELY(x) (x)
#endif

/* A lagging scan's byte through tase_rx_push() (bench's synclong and the
 * searched sustained streams: about one byte in four) pays for two calls
 * and their bookkeeping before any scan work: push_body(), then advance().
 * Where code size is not the aim (GCC or clang, not -Os), push_lag() takes
 * such a byte with the scan compiled into it: RX_SCAN makes scan() inline
 * there and in advance(), the one out-of-line copy every other caller
 * uses. At -Os (and for other compilers) advance() is scan() under
 * another name, and push_body() takes every lagging byte, as before
 * (docs/DESIGN.md). */
#if defined(__GNUC__) && !defined(__OPTIMIZE_SIZE__)
#define RX_LAG_FUSED 1
#define RX_SCAN RX_INLINE
#define RX_ADVANCE RX_NOINLINE
#else
#define RX_LAG_FUSED 0
#define RX_SCAN
#define RX_ADVANCE RX_INLINE
#endif

/* C99 has no _Static_assert: a negative array size fails the build. */
typedef char tase_rx_size_check[sizeof(tase_rx_t) <= TASE_RX_SIZE_BUDGET ? 1 : -1];
typedef char tase_rx_window_check[(TASE_RX_WINDOW > TASE_FRAME_MAX + 8u && TASE_RX_WINDOW < 0xFFFFu)
                                      ? 1
                                      : -1];
typedef char tase_rx_cand_check[(TASE_RX_CANDIDATES >= 1 && TASE_RX_CANDIDATES <= 16) ? 1 : -1];

/* Word access at any alignment is native on x86, 64-bit ARM and the
 * ARMv7-M/ARMv8-M mainline cores (Cortex-M3/M4/M7/M33: the compiler says
 * so with __ARM_FEATURE_UNALIGNED); elsewhere (Cortex-M0/M0+, AVR, ...)
 * memcpy of a word is a library call or four byte loads, and a byte loop
 * is shorter and faster. */
#if defined(__x86_64__) || defined(__i386__) || defined(__aarch64__) ||                            \
    defined(__ARM_FEATURE_UNALIGNED)
#define RX_WORDS 1
#else
#define RX_WORDS 0
#endif

/* Cortex-M4/M7/M33 (the DSP extension, ACLE's __ARM_FEATURE_SIMD32): the
 * checksum adds a word of bytes with one USADA8 (docs/DESIGN.md). */
#if defined(__ARM_FEATURE_SIMD32) && defined(__ARM_FEATURE_UNALIGNED) && defined(__GNUC__)
#include <arm_acle.h>
#define RX_SAD 1
#else
#define RX_SAD 0
#endif

#if RX_WORDS && !RX_SAD
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
#endif

uint16_t tase_checksum(uint16_t seed, const uint8_t *p, size_t n)
{
    uint32_t sum = seed;
    size_t i = 0;
    if (p == NULL) {
        return seed;
    }
#if RX_SAD
    /* Cortex-M4/M7/M33 with the DSP extension: USADA8 adds the four bytes
     * of a word to the total in one instruction (the sum of their absolute
     * differences from zero), four words per step (11 instructions for 16
     * bytes on M4 -O2; with two words per step the worst sustained stream,
     * bench's `synclong`, costs 106.5 instructions a byte instead of
     * 103.6), then two. */
    for (; n - i >= 16u; i += 16u) {
        uint32_t w0;
        uint32_t w1;
        uint32_t w2;
        uint32_t w3;
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w0, &p[i], 4u);
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w1, &p[i + 4u], 4u);
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w2, &p[i + 8u], 4u);
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w3, &p[i + 12u], 4u);
        sum = __usada8(w0, 0u, sum);
        sum = __usada8(w1, 0u, sum);
        sum = __usada8(w2, 0u, sum);
        sum = __usada8(w3, 0u, sum);
    }
    if (n - i >= 8u) {
        uint32_t w0;
        uint32_t w1;
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w0, &p[i], 4u);
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w1, &p[i + 4u], 4u);
        sum = __usada8(w0, 0u, sum);
        sum = __usada8(w1, 0u, sum);
        i += 8u;
    }
    if (n - i >= 4u) {
        uint32_t w;
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w, &p[i], 4u);
        sum = __usada8(w, 0u, sum);
        i += 4u;
    }
#elif RX_WORDS
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
#endif
    for (; i < n; i++) {
        sum += p[i];
    }
    return (uint16_t)sum;
}

int tase_frame_build(uint8_t group, uint8_t type, const uint8_t *data, size_t len, uint8_t *out,
                     size_t cap)
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

static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};

/* What one call delivers to, and how many frames it has delivered. */
typedef struct {
    tase_rx_handler_t on_frame;
    void *user;
    uint32_t count;
    /* tase_rx_feed()'s input not taken in yet: bytes advance() takes in
     * itself while the scan lags (see take()); NULL for the others */
    struct rx_input *in;
} rx_call_t;

/* The input of a tase_rx_feed() call from `next` to `end`. */
struct rx_input {
    const uint8_t *next;
    const uint8_t *end;
};

/* Count and hand on the valid frame f[0..Size+6) at stream offset
 * `offset`. Returns false when the callback re-initialised the receiver:
 * the caller must then leave it alone. */
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

/* The scan's delivery, out of line: the frame f[0..Size+6) at stream
 * offset `offset` handed to c's callback (not NULL; the caller counts the
 * frame and looks at `busy` afterwards). The tase_frame_t then lives only
 * while the callback runs, not in advance()'s frame for the whole scan,
 * and this frame holds nothing else (the push path's stack,
 * docs/FOOTPRINT.md). */
RX_NOINLINE static void hand_on(const uint8_t *f, uint32_t offset, const rx_call_t *c)
{
    tase_frame_t fr;
    fr.offset = offset;
    fr.group = f[4];
    fr.type = f[5];
    fr.len = (uint8_t)(f[3] - 2u);
    fr.data = &f[TASE_FRAME_HEADER];
    c->on_frame(c->user, &fr);
}

/* Drop the decided bytes buf[0..scan): the rest moves to the front. The
 * running sums stay as they are (they carry a constant, see above). */
static void compact(tase_rx_t *rx)
{
    size_t s = rx->scan;
    size_t n = (size_t)rx->len - s;
    size_t i = 0;
    uint8_t *b = rx->buf;
    /* A forward copy down by s >= 1: every load is ahead of every store
     * before it, so the overlap is safe word by word as well. */
#if RX_WORDS
    for (; n - i >= 4u; i += 4u) {
        uint32_t w;
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&w, &b[s + i], 4u);
        /* cppcheck-suppress misra-c2012-21.15 */
        (void)memcpy(&b[i], &w, 4u);
    }
#else
    for (; n - i >= 4u; i += 4u) {
        const uint8_t *q = &b[s + i];
        b[i] = q[0];
        b[i + 1u] = q[1];
        b[i + 2u] = q[2];
        b[i + 3u] = q[3];
    }
#endif
    for (; i < n; i++) {
        b[i] = b[s + i];
    }
    rx->len = (uint16_t)n;
    rx->scan = 0u;
    /* the sum cursor moves with its byte (gone if it was decided) */
    rx->at = (rx->at > s) ? (uint16_t)(rx->at - s) : 0u;
}

/* The scan has caught up with something to hold at buf[s]: a partial
 * sync, or a candidate of flen bytes still incomplete. A partial sync
 * moves to the front (at most 3 bytes), a candidate only if the window
 * has no room for its last byte. */
static void hold(tase_rx_t *rx, size_t s, size_t flen)
{
    rx->lag = 0u;
    if (s > 0u && s + flen > RX_CAP) {
        compact(rx);
    }
}

/* Whether the scan, at p with avail bytes, has caught up: a partial sync
 * or a candidate whose last byte is still to come (what advance() holds;
 * O(1), so it needs no credit). */
RX_INLINE static bool holds(const uint8_t *p, size_t avail)
{
    if (p[0] != TASE_SYNC1) {
        return false;
    }
    if (avail < 4u) {
        return avail == 1u || (p[1] == TASE_SYNC2 && (avail == 2u || p[2] == TASE_SYNC3));
    }
    return p[1] == TASE_SYNC2 && p[2] == TASE_SYNC3 && p[3] >= 2u && (size_t)p[3] + 6u > avail;
}

/* A scan that has spent its credit while tase_rx_feed() has more input
 * takes the next byte in itself, exactly as the call would (put(), then
 * scan_on() with the credit that byte brings), without leaving the scan:
 * the byte is stored (*len one more) and *budget becomes its credit.
 * Returns false, changing nothing, when there is no byte to take or the
 * window is full (the caller's put() makes room first). */
RX_INLINE static bool take(tase_rx_t *rx, rx_call_t *c, size_t *len, int32_t *budget)
{
    uint8_t byte;
    uint32_t left;
    uint32_t units;
    if (c->in == NULL || c->in->next == c->in->end || *len >= RX_CAP) {
        return false;
    }
    /* what the scan of the byte before would have kept (scan_on()) */
    left = (*budget > 0) ? (uint32_t)*budget : 0u;
    rx->bank = (uint16_t)left;
    rx->bank_at = (uint16_t)rx->stats.bytes_in;
    byte = *c->in->next;
    c->in->next++;
    rx->buf[*len] = byte;
    *len += 1u;
    rx->len = (uint16_t)*len;
    rx->sum_len = (uint16_t)(rx->sum_len + byte);
    rx->stats.bytes_in++;
    units = left + RX_BUDGET;
    *budget = (int32_t)((units < RX_BANK_MAX) ? units : RX_BANK_MAX);
    return true;
}

/* The greedy scan from buf[scan] on, until it has caught up (lag 0) or
 * spent `allowance` units and, in a tase_rx_feed(), the credit of every
 * byte it took in itself (lag 1); what is left goes to the bank unless
 * nothing is left to decide. `final`: end of input, so an incomplete
 * candidate or partial sync fails like a bad one. Returns false when a
 * callback re-initialised the receiver. Reached through advance(), and
 * where RX_LAG_FUSED, also from push_lag() (compiled into it). */
RX_SCAN static bool scan(tase_rx_t *rx, rx_call_t *c, int32_t allowance, bool final)
{
    int32_t budget = allowance; /* signed: a step may overrun what is left */
    const uint8_t *b = rx->buf;
    size_t s = rx->scan;
    size_t len = rx->len;
    uint32_t sum = rx->sum_scan; /* the running sum up to buf[s] (mod 2^16) */
    uint32_t dropped = 0;        /* bytes discarded, not yet counted */
    bool live = true;
    if (rx->stop != 0u) {
        return true; /* stopped by a callback of this call */
    }
    for (;;) {
        size_t avail = len - s;
        const uint8_t *p = &b[s];
        size_t k = 1;
        if (avail == 0u) {
            /* all decided: start the window over */
            len = 0u;
            s = 0u;
            rx->lag = 0u;
            rx->at = 0u;
            break;
        }
        if (budget < (int32_t)RX_COST_STEP && !holds(p, avail)) {
            /* the credit is spent: the next byte brings more */
            if (!take(rx, c, &len, &budget)) {
                rx->lag = 1u; /* the next call goes on */
                break;
            }
            continue;
        }
        budget -= (int32_t)RX_COST_STEP;
        if (p[0] != TASE_SYNC1) {
            /* noise up to the next 00 (summed on the way), as far as what
             * is left pays for */
            size_t lim = (budget > 0) ? (size_t)budget / RX_COST_NOISE + 1u : 1u;
            if (lim > avail) {
                lim = avail;
            }
            sum += p[0];
            while (k < lim && p[k] != TASE_SYNC1) {
                sum += p[k];
                k++;
            }
            dropped += (uint32_t)k;
            s += k;
            budget -= (int32_t)(k * RX_COST_NOISE);
            continue;
        }
        if (avail < 4u) {
            while (k < avail && p[k] == sync[k]) {
                k++;
            }
            if (k == avail && !final) {
                /* a sync still arriving: to the front (hunting from
                 * here, which keeps no cursor: hunt() may cut len) */
                rx->scan = (uint16_t)s;
                rx->at = 0u;
                hold(rx, s, RX_CAP);
                s = rx->scan;
                len = rx->len;
                break;
            }
        } else if (p[1] == TASE_SYNC2 && p[2] == TASE_SYNC3) {
            size_t flen = (size_t)p[3] + 6u;
            if (p[3] < 2u) {
                rx->stats.bad_size++;
            } else if (flen <= avail) {
                /* complete: judge it, if what is left pays for it (see
                 * the file comment for the sums: the shorter way to its
                 * Check_0 byte) */
                size_t fwd = flen - 2u;
                size_t bwd = avail - fwd;
                size_t cost = RX_COST_JUDGE;
                uint32_t at_be;
                uint16_t want;
                if (budget < (int32_t)RX_COST_JUDGE) {
                    /* judged with the next byte's credit */
                    if (!take(rx, c, &len, &budget)) {
                        rx->lag = 1u; /* the next call judges it */
                        break;
                    }
                    continue;
                }
                if (bwd == 2u) {
                    /* its last byte just came: the sum is 2 bytes back */
                    at_be = (uint32_t)rx->sum_len - p[fwd] - p[fwd + 1u];
                    cost += 2u;
                } else {
                    /* the shortest of three: b[from..from+n) summed
                     * forward from scan, back from len, or from the
                     * cursor either way */
                    size_t be = s + fwd;
                    size_t a = rx->at;
                    size_t from = s;
                    size_t n = fwd;
                    uint32_t base = sum;
                    uint32_t part;
                    bool back = false;
                    if (bwd < n) {
                        from = be;
                        n = bwd;
                        base = rx->sum_len;
                        back = true;
                    }
                    if (a > s) {
                        if (a <= be) {
                            if (be - a < n) {
                                from = a;
                                n = be - a;
                                base = rx->sum_at;
                                back = false;
                            }
                        } else if (a - be < n) {
                            from = be;
                            n = a - be;
                            base = rx->sum_at;
                            back = true;
                        } else {
                            /* farther than the other two */
                        }
                    }
                    part = tase_checksum(0u, &b[from], n);
                    at_be = back ? base - part : base + part;
                    cost += n;
                }
                rx->at = (uint16_t)(s + fwd);
                rx->sum_at = (uint16_t)at_be;
                want = (uint16_t)(((uint16_t)p[fwd] << 8) | p[fwd + 1u]);
                budget -= (int32_t)cost;
                if ((uint16_t)(at_be - sum) == want) {
                    sum = at_be + p[fwd] + p[fwd + 1u];
                    s += flen;
                    budget -= (int32_t)RX_COST_FRAME;
                    c->count++;
                    /* the state as the callback may see it */
                    rx->scan = (uint16_t)s;
                    rx->sum_scan = (uint16_t)sum;
                    rx->stats.bytes_discarded += dropped;
                    dropped = 0u;
                    rx->stats.frames_ok++;
                    if (c->on_frame != NULL) {
                        hand_on(p, rx->stats.bytes_in - (uint32_t)avail, c);
                    }
                    live = rx->busy != 0u;
                    if (!live) {
                        return false; /* re-initialised: leave rx alone */
                    }
                    if (rx->stop != 0u) {
                        rx->lag = 1u; /* stopped: the next call goes on from here */
                        break;
                    }
                    continue;
                }
                rx->stats.checksum_errors++;
            } else if (!final) {
                /* a candidate whose last byte is still to come */
                rx->scan = (uint16_t)s;
                hold(rx, s, flen);
                s = rx->scan;
                len = rx->len;
                break;
            } else {
                /* end of input: it can no longer complete */
            }
        } else {
            /* 00 not followed by FF 5A */
        }
        /* no frame here: the scan moves on one byte (a first sync byte is
         * 00: the sum does not change) */
        dropped++;
        s++;
    }
    rx->scan = (uint16_t)s;
    rx->len = (uint16_t)len;
    rx->sum_scan = (uint16_t)sum;
    rx->stats.bytes_discarded += dropped;
    if (!final && len != s) {
        /* something is left to decide: keep what is left of the credit
         * (scan_on()) */
        rx->bank = (uint16_t)((budget > 0) ? budget : 0);
        rx->bank_at = (uint16_t)rx->stats.bytes_in;
    }
    return live;
}

/* The scan, for every caller but push_lag(): out of line where
 * RX_LAG_FUSED (scan() is compiled into push_lag() and here), otherwise a
 * name for scan() itself. */
RX_ADVANCE static bool advance(tase_rx_t *rx, rx_call_t *c, int32_t allowance, bool final)
{
    return scan(rx, c, allowance, final);
}

/* The scan's credit for this byte (or tick, or 0-byte feed): what the
 * last budgeted scan left, plus RX_BUDGET for every byte taken in since
 * (at least one), up to RX_BANK_MAX. It depends on the stream only (the
 * count of bytes), never on how it was split into calls. */
RX_INLINE static int32_t credit(const tase_rx_t *rx)
{
    uint32_t since = (uint16_t)(rx->stats.bytes_in - rx->bank_at);
    uint32_t units = rx->bank + ((since != 0u) ? since : 1u) * RX_BUDGET;
    return (int32_t)((units < RX_BANK_MAX) ? units : RX_BANK_MAX);
}

/* Scan on with this byte's credit, less `spent` units already used on
 * it; advance() keeps what is left in the bank. A scan that ends with
 * nothing left to decide keeps the credit it had (tase_rx_push() delivers
 * a frame whose last byte came without scanning, so the credit must not
 * depend on it). Returns false when a callback re-initialised the
 * receiver. */
RX_INLINE static bool scan_on(tase_rx_t *rx, rx_call_t *c, uint32_t spent)
{
    return advance(rx, c, credit(rx) - (int32_t)spent, false);
}

/* Store one byte, making room first if the window is full: one step of
 * the scan if it is at buf[0] (a lagging scan: a caught-up one holds at
 * most a frame there), then compact(). Returns false when a callback
 * re-initialised the receiver. */
RX_INLINE static bool put(tase_rx_t *rx, rx_call_t *c, uint8_t b)
{
    if (rx->len == RX_CAP) {
        if (rx->scan == 0u) {
            /* a step on top of the credit, which it leaves as it was (a
             * stats reset from its callback would leave bank_at from
             * before the reset: a state no search has reached, and
             * keeping the relation costs 66 B of flash and 8 B of the
             * push path's stack, docs/DESIGN.md) */
            uint16_t bank = rx->bank;
            uint16_t at = rx->bank_at;
            if (!advance(rx, c, (int32_t)(RX_COST_STEP + RX_COST_JUDGE), false)) {
                return false;
            }
            rx->bank = bank;
            rx->bank_at = at;
        }
        if (rx->stop != 0u) {
            return true; /* stopped: not taken (compact() would move the frame) */
        }
        if (rx->scan > 0u) {
            compact(rx);
        }
    }
    rx->buf[rx->len] = b;
    rx->len++;
    rx->sum_len = (uint16_t)(rx->sum_len + b);
    rx->stats.bytes_in++;
    return true;
}

/* A byte while the scan has caught up and holds nothing or a partial sync
 * at the front (len < 4, scan 0, lag 0): the sync and Size bytes of a
 * frame, or noise. Returns true when the byte was a Size >= 2 that makes
 * buf[0..4) a candidate. */
RX_INLINE static bool hunt(tase_rx_t *rx, uint8_t byte)
{
    uint16_t len = rx->len;
    rx->stats.bytes_in++;
    if ((len < 3u) ? (byte == sync[len]) : (byte >= 2u)) {
        rx->buf[len] = byte;
        rx->len = (uint16_t)(len + 1u);
        rx->sum_len = (uint16_t)(rx->sum_len + byte);
        return len == 3u;
    }
    /* Broken (a Size < 2 is a bad Size): the bytes held are noise; a 00
     * may begin a sync, keep it (buf[0] is 00 already; it adds nothing to
     * the sums). */
    if (len == 3u) {
        rx->stats.bad_size++;
    }
    len = (uint16_t)(len + 1u);
    if (byte == TASE_SYNC1) {
        len--;
        rx->len = 1u;
    } else {
        rx->len = 0u;
    }
    rx->stats.bytes_discarded += len;
    rx->sum_len = rx->sum_scan;
    return false;
}

/* Start a call that may deliver frames (its rx_call_t set up by the
 * caller): `busy` set and `end` blocked for its whole length (see the
 * file comment). */
static void begin(tase_rx_t *rx)
{
    rx->busy = 1u;
    rx->end = RX_BLOCKED;
}

/* End it: unless a callback re-initialised the receiver (live false),
 * set `end` for tase_rx_push()'s fast paths (the held candidate's last
 * byte, 0 while hunting, RX_BLOCKED while the scan lags) and clear
 * `busy`. Returns the frames delivered. */
static int finish(tase_rx_t *rx, const rx_call_t *c, bool live)
{
    if (live) {
        size_t s = rx->scan;
        uint16_t end = 0u;
        if (rx->lag != 0u) {
            end = RX_BLOCKED;
        } else if (rx->len >= s + 4u) {
            end = (uint16_t)(s + rx->buf[s + 3u] + 5u);
        } else {
            /* hunting */
        }
        rx->end = end;
        rx->stop = 0u;
        rx->busy = 0u;
    }
    return (c->count > (uint32_t)INT_MAX) ? INT_MAX : (int)c->count;
}

/* A call that brings no byte (a 0-byte tase_rx_feed(), tase_rx_flush(),
 * a tick): a lagging scan goes on with one byte's credit, then, if
 * `final` (tase_rx_flush(), a settling tick), everything is settled. Four
 * arguments, so that the wrappers reach it by a tail call. */
static int scan_only(tase_rx_t *rx, bool final, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c = {on_frame, user, 0u, NULL};
    bool live = true;
    begin(rx);
    if (rx->lag != 0u) {
        live = scan_on(rx, &c, 0u);
    }
    if (live && final) {
        live = advance(rx, &c, RX_UNLIMITED, true);
    }
    return finish(rx, &c, live);
}

/* The general path: feed data[0..n) (data not NULL, n > 0). Bytes that
 * cannot decide anything are taken in bulk: noise while nothing is held,
 * the sync and Size bytes of a frame, and the bytes of a held candidate
 * before its last one. Every other byte is stored and the scan runs on
 * with its credit, taking the bytes after it in itself while it lags: the
 * result is the same for any split of the stream into calls. */
static int run(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c = {on_frame, user, 0u, NULL};
    size_t i = 0;
    bool live = true;
    begin(rx);
    while (live && i < n && rx->stop == 0u) {
        if (rx->lag == 0u) {
            size_t k = 0;
            size_t s = rx->scan;
            size_t held = (size_t)rx->len - s;
            if (held == 0u && data[i] != TASE_SYNC1) {
                /* nothing held: noise up to the next 00 is decided now */
                const uint8_t *z = memchr(&data[i], TASE_SYNC1, n - i);
                k = (z != NULL) ? (size_t)(z - &data[i]) : n - i;
                rx->stats.bytes_discarded += (uint32_t)k;
                rx->stats.bytes_in += (uint32_t)k;
            } else if (held >= 4u) {
                /* the bytes of the held candidate before its last one */
                k = s + rx->buf[s + 3u] + 5u - rx->len;
                if (k > n - i) {
                    k = n - i;
                }
                if (k > 0u) {
                    uint8_t *to = &rx->buf[rx->len];
                    if (k < 8u) {
                        /* a few bytes: a loop costs less than the calls */
                        uint32_t sum = rx->sum_len;
                        size_t j;
                        for (j = 0; j < k; j++) {
                            to[j] = data[i + j];
                            sum += data[i + j];
                        }
                        rx->sum_len = (uint16_t)sum;
                    } else {
                        (void)memcpy(to, &data[i], k);
                        rx->sum_len = tase_checksum(rx->sum_len, &data[i], k);
                    }
                    rx->len = (uint16_t)(rx->len + k);
                    rx->stats.bytes_in += (uint32_t)k;
                }
            } else {
                /* the sync and Size bytes (a 00 while nothing is held too,
                 * exactly as tase_rx_push() takes them: no scan, so the
                 * scan's credit is the same for any split) */
                (void)hunt(rx, data[i]);
                k = 1u;
            }
            i += k;
            if (k > 0u) {
                continue;
            }
        }
        /* the byte, then the scan, which takes the bytes after it itself
         * while it lags */
        live = put(rx, &c, data[i]);
        i++;
        if (live && rx->stop == 0u) {
            struct rx_input in;
            in.next = &data[i];
            in.end = &data[n];
            c.in = &in;
            live = scan_on(rx, &c, 0u);
            c.in = NULL;
            i = (size_t)(in.next - data);
        }
    }
    return finish(rx, &c, live);
}

/* What every entry point checks of an instance, so that a corrupted or
 * never-initialised one gives TASE_EARG instead of indexing outside buf:
 * the indices in order inside the window; a caught-up receiver holds a
 * partial sync at the front, or a candidate at buf[scan] whose end agrees
 * with its Size byte and lies ahead inside the window. */
static bool rx_sane(const tase_rx_t *rx)
{
    size_t len = rx->len;
    size_t s = rx->scan;
    size_t end = rx->end;
    if (len > RX_CAP || s > len || rx->lag > 1u || rx->stop != 0u) {
        return false;
    }
    if (rx->lag != 0u) {
        return end == RX_BLOCKED;
    }
    if (len - s < 4u) {
        return s == 0u && end == 0u;
    }
    return rx->buf[s] == TASE_SYNC1 && rx->buf[s + 3u] >= 2u && end == s + rx->buf[s + 3u] + 5u &&
           len <= end && end < RX_CAP;
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

/* tase_rx_push() for every byte its fast paths do not take: the byte is
 * stored and the scan goes on with its credit, as run() does for each
 * byte. A lagging scan (`end` RX_BLOCKED outside a call) passes on the
 * checks rx_sane() makes of that state; anything else goes through
 * rx_check(), so a call from a callback or a corrupted instance gets its
 * error. */
RX_NOINLINE static int push_body(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c = {on_frame, user, 0u, NULL};
    if (rx->end != RX_BLOCKED || rx->busy != 0u || rx->lag != 1u || rx->stop != 0u ||
        rx->len > RX_CAP || rx->scan > rx->len) {
        int r = rx_check(rx);
        if (r != TASE_OK) {
            return r;
        }
    }
    begin(rx);
    return finish(rx, &c, put(rx, &c, b) && scan_on(rx, &c, 0u));
}

#if RX_LAG_FUSED
/* tase_rx_push() for a byte while the scan lags (`end` RX_BLOCKED outside
 * a call) and the window has room (so put() only stores): what push_body()
 * does for it, with the scan compiled in (RX_LAG_FUSED above). Every other
 * state, a full window included, goes to push_body(). */
RX_NOINLINE static int push_lag(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c = {on_frame, user, 0u, NULL};
    size_t len = rx->len;
    if (rx->busy != 0u || rx->lag != 1u || rx->stop != 0u || len >= RX_CAP || rx->scan > len) {
        return push_body(rx, b, on_frame, user);
    }
    begin(rx);
    return finish(rx, &c, put(rx, &c, b) && scan(rx, &c, credit(rx), false));
}
#endif

/* tase_rx_push() for the last byte of a held candidate that failed: the
 * byte is stored, the scan moves past the candidate's first byte (00) and
 * goes on with what is left of the credit after this judgement, exactly
 * as in run() (where advance() judges it: a step, a judgement and 2 bytes
 * summed), so
 * that any split of the stream gives the same result. */
RX_NOINLINE static int push_failed(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    rx_call_t c = {on_frame, user, 0u, NULL};
    size_t len = rx->len;
    begin(rx);
    rx->stats.checksum_errors++;
    /* the cursor at its Check_0 byte, as advance() leaves it */
    rx->at = (uint16_t)(len - 1u);
    rx->sum_at = (uint16_t)(rx->sum_len - rx->buf[len - 1u]);
    rx->buf[len] = b;
    rx->len = (uint16_t)(len + 1u);
    rx->sum_len = (uint16_t)(rx->sum_len + b);
    rx->stats.bytes_in++;
    rx->stats.bytes_discarded++;
    rx->scan = (uint16_t)(rx->scan + 1u);
    return finish(rx, &c, scan_on(rx, &c, RX_COST_STEP + RX_COST_JUDGE + 2u));
}

/* tase_rx_push() for the last byte of the candidate held at buf[scan]
 * (len == end): a valid frame is delivered from the window, which is then
 * empty; after a failed one the scan goes on (push_failed()). */
RX_NOINLINE static int push_last(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    size_t s = rx->scan;
    size_t len = rx->len;
    /* the checks of rx_sane() that make the frame lie inside buf (len is
     * end here); an instance that fails them fails rx_check() too: its
     * error */
    if (s + 4u > len || rx->buf[s + 3u] < 2u || len != s + rx->buf[s + 3u] + 5u) {
        return (rx->busy == 1u) ? TASE_EBUSY : TASE_EARG;
    }
    if ((uint16_t)(rx->sum_len - rx->buf[len - 1u] - rx->sum_scan) !=
        (uint16_t)(((uint16_t)rx->buf[len - 1u] << 8) | b)) {
        return push_failed(rx, b, on_frame, user);
    }
    rx->stats.bytes_in++;
    rx->len = 0u;
    rx->scan = 0u;
    rx->at = 0u;
    rx->sum_len = rx->sum_scan;
    rx->busy = 1u;
    rx->end = RX_BLOCKED;
    if (RX_LIKELY(deliver(rx, &rx->buf[s], rx->stats.bytes_in - (uint32_t)(len + 1u - s), on_frame,
                          user))) {
        /* hunting from here (also right when the callback stopped rx); a
         * callback that re-initialised rx may have fed it since: left as
         * it is */
        rx->end = 0u;
        rx->stop = 0u;
        rx->busy = 0u;
    }
    return 1;
}

/* tase_rx_push() for every byte that is not inside a held candidate: the
 * sync and Size bytes of a frame while hunting (here), the last byte of a
 * candidate (push_last()) and everything else (push_body()). Out of line,
 * so that the fast path of tase_rx_push() saves no register but the return
 * address (measured: telemetry 24.8 -> 23.6 instructions a byte on
 * Cortex-M4 -O2; docs/PERFORMANCE.md, docs/DESIGN.md). */
RX_NOINLINE static int push_other(tase_rx_t *rx, uint8_t byte, tase_rx_handler_t on_frame,
                                  void *user)
{
    uint16_t len = rx->len;
    uint16_t end = rx->end;
    /* Hunting a sync, or its Size byte: end is 0 only when the scan has
     * caught up and holds nothing or a partial sync at the front (never
     * during a call). */
    if (end == 0u && len < 4u) {
        if (hunt(rx, byte)) {
            rx->end = (uint16_t)(byte + 5u);
        }
        return 0;
    }
    /* One tail call through a pointer: gcc compiles two tail calls here
     * with five registers saved and the arguments moved (a lagging scan's
     * byte, bench's synclong: 103.1 -> 100.8 M4 instructions a byte). A
     * lagging scan's byte goes to push_lag() (100.8 -> 91.9 with the scan
     * compiled into it, the two searched periods of docs/DESIGN.md 102.3
     * -> 97.6 and 102.7 -> 97.7); at -Os, to push_body(). */
#if RX_LAG_FUSED
    return ((len == end && end != 0u && end < RX_CAP) ? push_last
            : (end == RX_BLOCKED)                     ? push_lag
                                                      : push_body)(rx, byte, on_frame, user);
#else
    return ((len == end && end != 0u && end < RX_CAP) ? push_last : push_body)(rx, byte, on_frame,
                                                                               user);
#endif
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
        rx->sum_len = (uint16_t)(rx->sum_len + byte);
        rx->stats.bytes_in++;
        return 0;
    }
    return push_other(rx, byte, on_frame, user);
}

int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user)
{
    int r = (data == NULL && n > 0u) ? TASE_EARG : rx_check(rx);
    if (r != TASE_OK) {
        return r;
    }
    return (n == 0u) ? scan_only(rx, false, on_frame, user) : run(rx, data, n, on_frame, user);
}

int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    int r = rx_check(rx);
    return (r != TASE_OK) ? r : scan_only(rx, true, on_frame, user);
}

/* The time bound's two ways into the scan (tase_frame_private.h): thin
 * wrappers, so that the static rx_check() and scan_only() keep the
 * callers gcc compiled them for. */
int tase_rx_state_check(const tase_rx_t *rx)
{
    return rx_check(rx);
}

int tase_rx_continue(tase_rx_t *rx, bool settle, tase_rx_handler_t on_frame, void *user)
{
    return scan_only(rx, settle, on_frame, user);
}
