/*
 * Frame encoder and receive state machine. The design is described in
 * include/tase/frame.h; comments here explain the non-obvious choices.
 *
 * Window invariants (all indices are into rx->buf):
 *   - buf[0..len) holds every byte that may still belong to a frame: it
 *     starts at the oldest live candidate's first sync byte, or holds only
 *     a partial sync (00 or 00 FF) when no candidate is alive.
 *   - cand[] is sorted by start; bytes before `scan` have been examined
 *     for sync. scan < len only while more syncs overlap than there are
 *     candidate slots; those bytes are re-examined when a slot frees.
 *   - Delivered frames still in the window are disjoint or nested and all
 *     end below `floor`; `credit` is their total length counting nested
 *     ones once. Each candidate remembers the credit that lay before it,
 *     so trimming the window can tell delivered bytes from discarded ones.
 */
#include "tase/frame.h"

#include <string.h>

#define RX_CAP ((uint16_t)TASE_FRAME_MAX)
#define NO_EVENT ((uint16_t)0xFFFFu)

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
    (void)memset(rx, 0, sizeof(*rx));
    rx->next = NO_EVENT;
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

static uint16_t cand_event(const tase_rx_cand_t *c)
{
    return (c->end != 0u) ? c->end : (uint16_t)(c->start + 3u);
}

static void update_next(tase_rx_t *rx)
{
    uint16_t nx = NO_EVENT;
    uint8_t i;
    for (i = 0; i < rx->ncand; i++) {
        uint16_t e = cand_event(&rx->cand[i]);
        if (e < nx) {
            nx = e;
        }
    }
    rx->next = nx;
}

/* Remove cand[first..last) and close the gap. */
static void drop_cands(tase_rx_t *rx, uint8_t first, uint8_t last)
{
    uint8_t i;
    uint8_t n = (uint8_t)(last - first);
    for (i = first; (uint8_t)(i + n) < rx->ncand; i++) {
        rx->cand[i] = rx->cand[i + n];
    }
    rx->ncand = (uint8_t)(rx->ncand - n);
}

/* Does a sync sequence end at index q (the 0x5A byte)? A frame may not
 * start below `floor`: those bytes belong to a delivered frame. */
static bool sync_ends_at(const tase_rx_t *rx, uint16_t q)
{
    /* q < len <= TASE_FRAME_MAX always; cppcheck cannot see that. */
    /* cppcheck-suppress arrayIndexOutOfBoundsCond */
    return q >= 2u && (uint16_t)(q - 2u) >= rx->floor && rx->buf[q] == TASE_SYNC3 &&
           rx->buf[q - 1u] == TASE_SYNC2 && rx->buf[q - 2u] == TASE_SYNC1;
}

static void add_cand(tase_rx_t *rx, uint16_t start)
{
    tase_rx_cand_t *c = &rx->cand[rx->ncand];
    c->start = start;
    c->end = 0u;
    c->credit = rx->credit;
    rx->ncand++;
}

/* cand[i] has reached its event (Size byte or last byte, both already in
 * the window): judge it. Returns true when it is a valid frame, described
 * in *out; the caller hands it on. The callback is not called from here so
 * that it runs on the stack of tase_rx_feed() alone, not below this. The
 * caller refreshes rx->next afterwards. */
static bool settle(tase_rx_t *rx, uint8_t i, tase_frame_t *out)
{
    tase_rx_cand_t *c = &rx->cand[i];
    uint16_t start = c->start;
    uint16_t end;
    uint16_t want;
    uint8_t last;

    if (c->end == 0u) {
        uint8_t size = rx->buf[start + 3u];
        if (size < 2u) {
            rx->stats.bad_size++;
            drop_cands(rx, i, (uint8_t)(i + 1u));
        } else {
            c->end = (uint16_t)(start + size + 5u);
        }
        return false;
    }

    end = c->end;
    want = (uint16_t)(((uint16_t)rx->buf[end - 1u] << 8) | rx->buf[end]);
    if (tase_checksum(0u, &rx->buf[start], (size_t)end - 1u - start) != want) {
        rx->stats.checksum_errors++;
        drop_cands(rx, i, (uint8_t)(i + 1u));
        return false;
    }

    /* Valid. Nested frames delivered earlier are already part of the
     * credit accumulated since this candidate began; replace them by it. */
    rx->credit = (uint16_t)(c->credit + (end - start + 1u));
    rx->floor = (uint16_t)(end + 1u);
    last = (uint8_t)(i + 1u);
    while (last < rx->ncand && rx->cand[last].start <= end) {
        last++; /* began inside this frame: it was data */
    }
    drop_cands(rx, i, last);
    rx->stats.frames_ok++;

    out->offset = rx->stats.bytes_in - (uint32_t)(rx->len - start);
    out->group = rx->buf[start + 4u];
    out->type = rx->buf[start + 5u];
    out->len = (uint8_t)(rx->buf[start + 3u] - 2u);
    out->data = &rx->buf[start + TASE_FRAME_HEADER];
    return true;
}

/* Examine bytes skipped while every candidate slot was busy, adding the
 * candidates found there. Returns the index of one that is already
 * complete (the caller judges it with settle() and hands the frame on
 * before calling again), or -1 when the scan is done or the slots are full
 * again. It does not judge checksums itself, which keeps settle() and the
 * frame callback off this call chain and the receive-path stack shallow. */
static int rescan(tase_rx_t *rx)
{
    while (rx->scan < rx->len && rx->ncand < TASE_RX_CANDIDATES) {
        uint16_t q = rx->scan;
        rx->scan = (uint16_t)(q + 1u);
        if (!sync_ends_at(rx, q)) {
            continue;
        }
        if ((uint16_t)(q + 1u) < rx->len && rx->buf[q + 1u] < 2u) {
            rx->stats.bad_size++;
            continue;
        }
        add_cand(rx, (uint16_t)(q - 2u));
        if ((uint16_t)(q + 1u) < rx->len) { /* else its Size byte is still to come */
            tase_rx_cand_t *c = &rx->cand[rx->ncand - 1u];
            c->end = (uint16_t)(c->start + rx->buf[q + 1u] + 5u);
            if (c->end < rx->len) {
                return (int)(rx->ncand - 1u);
            }
        }
    }
    return -1;
}

/* Judge every candidate whose event is at index q, oldest first. At most
 * one of them is valid: a valid one drops every later candidate that ends
 * at q, since those began inside it. */
static bool events_at(tase_rx_t *rx, uint16_t q, tase_frame_t *out)
{
    uint8_t i = 0;
    bool got = false;
    while (i < rx->ncand) {
        uint8_t before = rx->ncand;
        if (cand_event(&rx->cand[i]) != q) {
            i++;
            continue;
        }
        if (settle(rx, i, out)) {
            got = true;
        }
        if (rx->ncand == before) {
            i++; /* Size accepted: the candidate stays */
        }
    }
    return got;
}

/* Release buf[0..cut): every byte there not inside a delivered frame is
 * counted as discarded. `credit_before` is the delivered length in it. */
static void release(tase_rx_t *rx, uint16_t cut, uint16_t credit_before)
{
    uint8_t i;
    rx->stats.bytes_discarded += (uint32_t)(cut - credit_before);
    rx->credit = (uint16_t)(rx->credit - credit_before);
    if (cut == 0u) {
        return;
    }
    (void)memmove(rx->buf, &rx->buf[cut], (size_t)(rx->len - cut));
    rx->len = (uint16_t)(rx->len - cut);
    rx->scan = (uint16_t)(rx->scan - cut);
    rx->floor = (rx->floor > cut) ? (uint16_t)(rx->floor - cut) : 0u;
    if (rx->next != NO_EVENT) {
        rx->next = (uint16_t)(rx->next - cut);
    }
    for (i = 0; i < rx->ncand; i++) {
        tase_rx_cand_t *c = &rx->cand[i];
        c->start = (uint16_t)(c->start - cut);
        if (c->end != 0u) {
            c->end = (uint16_t)(c->end - cut);
        }
        c->credit = (uint16_t)(c->credit - credit_before);
    }
}

/* No candidate alive and nothing left to scan: keep only a trailing
 * partial sync (00 or 00 FF) that may still start a frame. */
static void go_idle(tase_rx_t *rx)
{
    uint16_t len = rx->len;
    uint16_t keep = 0u;
    if (len > rx->floor) {
        if (rx->buf[len - 1u] == TASE_SYNC1) {
            keep = 1u;
        } else if (len >= 2u && (uint16_t)(len - 2u) >= rx->floor &&
                   rx->buf[len - 1u] == TASE_SYNC2 && rx->buf[len - 2u] == TASE_SYNC1) {
            keep = 2u;
        } else {
            /* no partial sync at the end: keep nothing */
        }
    }
    rx->stats.bytes_discarded += (uint32_t)(len - keep - rx->credit);
    rx->credit = 0u;
    rx->buf[0] = TASE_SYNC1;
    rx->buf[1] = TASE_SYNC2;
    rx->len = keep;
    rx->scan = keep;
    rx->floor = 0u;
    rx->next = NO_EVENT;
}

/* The window is full. The oldest candidate began at index >= 1 (a frame
 * spans at most RX_CAP bytes and it has not ended), so this frees room. */
static void make_room(tase_rx_t *rx)
{
    release(rx, rx->cand[0].start, rx->cand[0].credit);
}

/* No candidate alive: the window holds only a partial sync (len 0..2,
 * floor 0, no credit), so matching the next sync byte is all there is. */
static void hunt_byte(tase_rx_t *rx, uint8_t b)
{
    static const uint8_t sync[3] = {TASE_SYNC1, TASE_SYNC2, TASE_SYNC3};
    uint16_t len = rx->len;
    rx->stats.bytes_in++;
    if (b == sync[len]) {
        rx->buf[len] = b;
        len++;
        if (len == 3u) {
            add_cand(rx, 0u);
            rx->next = 3u;
        }
    } else if (b == TASE_SYNC1) {
        rx->stats.bytes_discarded += len; /* 00 or 00 FF, then 00 again */
        len = 1u;
    } else {
        rx->stats.bytes_discarded += (uint32_t)len + 1u;
        len = 0u;
    }
    rx->len = len;
    rx->scan = len;
}

/* Take one byte. Returns true when it completed a valid frame (in *out);
 * the caller then hands it on and calls finish_event(). */
static bool push_byte(tase_rx_t *rx, uint8_t b, tase_frame_t *out, bool *event)
{
    uint16_t q;
    *event = false;
    if (rx->ncand == 0u) {
        hunt_byte(rx, b);
        return false;
    }
    if (rx->len == RX_CAP) {
        make_room(rx);
    }
    q = rx->len;
    rx->buf[q] = b;
    rx->len = (uint16_t)(q + 1u);
    rx->stats.bytes_in++;
    if (rx->scan == q) {
        if (b == TASE_SYNC3 && sync_ends_at(rx, q)) {
            if (rx->ncand < TASE_RX_CANDIDATES) {
                add_cand(rx, (uint16_t)(q - 2u));
                if ((uint16_t)(q + 1u) < rx->next) {
                    rx->next = (uint16_t)(q + 1u);
                }
                rx->scan = (uint16_t)(q + 1u);
            } /* else: all slots busy; rescan() finds it later */
        } else {
            rx->scan = (uint16_t)(q + 1u);
        }
    }
    if (q != rx->next) {
        return false;
    }
    *event = true;
    return events_at(rx, q, out);
}

/* After an event: deliver the frame it completed, then the frames a rescan
 * of skipped bytes finds, each as soon as it is found; then tidy up. */
static void finish_event(tase_rx_t *rx, bool got, tase_frame_t *out, tase_rx_handler_t on_frame,
                         void *user)
{
    bool valid = got;
    for (;;) {
        int k;
        if (valid && on_frame != NULL) {
            on_frame(user, out);
        }
        k = rescan(rx);
        if (k < 0) {
            break;
        }
        valid = settle(rx, (uint8_t)k, out);
    }
    update_next(rx);
    if (rx->ncand == 0u && rx->scan == rx->len) {
        go_idle(rx);
    }
}

/* Invariants every entry point relies on, checked so that a corrupted or
 * never-initialised instance gives TASE_EARG instead of indexing outside
 * buf: held bytes fit, the scan is within them, the candidate count fits,
 * and with no candidate at most a partial sync (2 bytes) is held. */
static bool rx_sane(const tase_rx_t *rx)
{
    return rx->len <= RX_CAP && rx->scan <= rx->len && rx->ncand <= TASE_RX_CANDIDATES &&
           (rx->ncand != 0u || rx->len < 3u);
}

int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user)
{
    size_t i = 0;
    uint32_t before;
    tase_frame_t frame;
    if (rx == NULL || (data == NULL && n > 0u) || !rx_sane(rx)) {
        return TASE_EARG;
    }
    before = rx->stats.frames_ok;
    while (i < n) {
        if (rx->len == 0u && n - i >= 16u) {
            /* Idle: everything up to the next 00 is noise. (For a few
             * bytes a library call costs more than hunt_byte.) */
            const uint8_t *z = memchr(&data[i], TASE_SYNC1, n - i);
            size_t skip = (z != NULL) ? (size_t)(z - &data[i]) : (n - i);
            rx->stats.bytes_in += (uint32_t)skip;
            rx->stats.bytes_discarded += (uint32_t)skip;
            i += skip;
            if (z == NULL) {
                break;
            }
            /* Fast path: a whole frame is at hand and no byte after its
             * sync is 5A, so no other candidate can start inside it. Judge
             * it in place; on a checksum failure fall through to the
             * general path, which re-examines every byte. */
            if (n - i >= TASE_FRAME_OVERHEAD && data[i + 1u] == TASE_SYNC2 &&
                data[i + 2u] == TASE_SYNC3 && data[i + 3u] >= 2u) {
                size_t flen = (size_t)data[i + 3u] + 6u;
                if (flen <= n - i && memchr(&data[i + 3u], TASE_SYNC3, flen - 3u) == NULL &&
                    tase_checksum(0u, &data[i], flen - 2u) ==
                        (uint16_t)(((uint16_t)data[i + flen - 2u] << 8) | data[i + flen - 1u])) {
                    frame.offset = rx->stats.bytes_in;
                    frame.group = data[i + 4u];
                    frame.type = data[i + 5u];
                    frame.len = (uint8_t)(data[i + 3u] - 2u);
                    frame.data = &data[i + TASE_FRAME_HEADER];
                    rx->stats.bytes_in += (uint32_t)flen;
                    rx->stats.frames_ok++;
                    i += flen;
                    if (on_frame != NULL) {
                        on_frame(user, &frame);
                    }
                    continue;
                }
            }
            /* A whole header at hand: open the candidate in one step. */
            if (n - i >= 4u && data[i + 1u] == TASE_SYNC2 && data[i + 2u] == TASE_SYNC3 &&
                data[i + 3u] >= 2u) {
                (void)memcpy(rx->buf, &data[i], 4u);
                rx->len = 4u;
                rx->scan = 4u;
                rx->ncand = 1u;
                rx->cand[0].start = 0u;
                rx->cand[0].end = (uint16_t)(data[i + 3u] + 5u);
                rx->cand[0].credit = 0u;
                rx->next = rx->cand[0].end;
                rx->stats.bytes_in += 4u;
                i += 4u;
                continue;
            }
        } else if (rx->ncand > 0u && rx->len < RX_CAP) {
            /* Inside a candidate: copy the run of bytes before the next
             * event in one go, stopping at a 5A that may end a sync. */
            size_t run = (size_t)((rx->next < RX_CAP ? rx->next : RX_CAP) - rx->len);
            /* next > len here (events below len were settled when their
             * byte arrived); cppcheck's value flow assumes run == 0. */
            /* cppcheck-suppress knownConditionTrueFalse */
            if (run > n - i) {
                run = n - i;
            }
            /* cppcheck-suppress knownConditionTrueFalse */
            if (run > 0u && run < 8u) {
                /* Short runs (byte-at-a-time feeding): no library calls. */
                size_t k = 0u;
                bool scanning = rx->scan == rx->len;
                /* cppcheck-suppress knownConditionTrueFalse */
                while (k < run && !(scanning && data[i + k] == TASE_SYNC3)) {
                    rx->buf[rx->len + k] = data[i + k];
                    k++;
                }
                rx->len = (uint16_t)(rx->len + k);
                if (scanning) {
                    rx->scan = rx->len;
                }
                rx->stats.bytes_in += (uint32_t)k;
                i += k;
                if (i == n) {
                    break;
                }
                /* cppcheck-suppress knownConditionTrueFalse */
            } else if (run > 0u) {
                if (rx->scan == rx->len) {
                    const uint8_t *s = memchr(&data[i], TASE_SYNC3, run);
                    if (s != NULL) {
                        run = (size_t)(s - &data[i]);
                    }
                    rx->scan = (uint16_t)(rx->scan + run);
                }
                (void)memcpy(&rx->buf[rx->len], &data[i], run);
                rx->len = (uint16_t)(rx->len + run);
                rx->stats.bytes_in += (uint32_t)run;
                i += run;
                if (i == n) {
                    break;
                }
            } else {
                /* run == 0: nothing to copy before the next event */
            }
        } else {
            /* only a partial sync held, or the window is full: the byte
             * goes through push_byte() alone */
        }
        {
            bool event;
            bool got = push_byte(rx, data[i], &frame, &event);
            i++;
            if (event) {
                finish_event(rx, got, &frame, on_frame, user);
            }
        }
    }
    return (int)(rx->stats.frames_ok - before);
}

int tase_rx_push(tase_rx_t *rx, uint8_t byte, tase_rx_handler_t on_frame, void *user)
{
    uint16_t len;
    if (rx == NULL) {
        return TASE_EARG;
    }
    len = rx->len;
    /* Most bytes of a frame only need storing: inside a tracked candidate,
     * fully scanned, not a 5A that may end a sync, not an event, room. */
    if (rx->ncand != 0u && rx->scan == len && byte != TASE_SYNC3 && len != rx->next &&
        len < RX_CAP) {
        rx->buf[len] = byte;
        len++;
        rx->len = len;
        rx->scan = len;
        rx->stats.bytes_in++;
        return 0;
    }
    if (!rx_sane(rx)) {
        return TASE_EARG;
    }
    if (rx->ncand == 0u) {
        hunt_byte(rx, byte);
        return 0;
    }
    return tase_rx_feed(rx, &byte, 1u, on_frame, user);
}

int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    uint32_t before;
    tase_frame_t frame;
    if (rx == NULL || !rx_sane(rx)) {
        return TASE_EARG;
    }
    before = rx->stats.frames_ok;
    /* Tracked candidates cannot complete any more; dropping them frees the
     * slots so that syncs skipped while they were busy get examined. Each
     * round either finishes the scan or fills the slots with candidates
     * that began later, so this terminates within len rounds. */
    for (;;) {
        rx->ncand = 0u;
        if (rx->scan >= rx->len) {
            break;
        }
        for (;;) {
            int k = rescan(rx);
            if (k < 0) {
                break;
            }
            if (settle(rx, (uint8_t)k, &frame) && on_frame != NULL) {
                on_frame(user, &frame);
            }
        }
    }
    rx->floor = rx->len; /* nothing pending may start a frame */
    go_idle(rx);
    return (int)(rx->stats.frames_ok - before);
}
