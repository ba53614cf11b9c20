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

uint16_t tase_checksum(uint16_t seed, const uint8_t *p, size_t n)
{
    /* A 32-bit accumulator vectorises well; reducing modulo 2^16 once at
     * the end gives the same result as wrapping after every byte. */
    uint32_t sum = seed;
    size_t i;
    if (p == NULL) {
        return seed;
    }
    for (i = 0; i < n; i++) {
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
        (void)memmove(&out[TASE_FRAME_HEADER], data, len);
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
 * the window): judge it. The caller refreshes rx->next afterwards. */
static void settle(tase_rx_t *rx, uint8_t i, tase_rx_handler_t on_frame, void *user)
{
    tase_rx_cand_t *c = &rx->cand[i];
    uint16_t start = c->start;
    uint16_t end;
    uint16_t want;
    uint8_t last;
    tase_frame_t frame;

    if (c->end == 0u) {
        uint8_t size = rx->buf[start + 3u];
        if (size < 2u) {
            rx->stats.bad_size++;
            drop_cands(rx, i, (uint8_t)(i + 1u));
        } else {
            c->end = (uint16_t)(start + size + 5u);
        }
        return;
    }

    end = c->end;
    want = (uint16_t)(((uint16_t)rx->buf[end - 1u] << 8) | rx->buf[end]);
    if (tase_checksum(0u, &rx->buf[start], (size_t)end - 1u - start) != want) {
        rx->stats.checksum_errors++;
        drop_cands(rx, i, (uint8_t)(i + 1u));
        return;
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

    frame.offset = rx->stats.bytes_in - (uint32_t)(rx->len - start);
    frame.group = rx->buf[start + 4u];
    frame.type = rx->buf[start + 5u];
    frame.len = (uint8_t)(rx->buf[start + 3u] - 2u);
    frame.data = &rx->buf[start + TASE_FRAME_HEADER];
    if (on_frame != NULL) {
        on_frame(user, &frame);
    }
}

/* Examine bytes skipped while every candidate slot was busy. A candidate
 * found here may already be complete; it is judged at once. */
static void rescan(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    while (rx->scan < rx->len) {
        uint16_t q = rx->scan;
        if (sync_ends_at(rx, q)) {
            uint8_t i;
            if (rx->ncand == TASE_RX_CANDIDATES) {
                return;
            }
            add_cand(rx, (uint16_t)(q - 2u));
            i = (uint8_t)(rx->ncand - 1u);
            if ((uint16_t)(q + 1u) < rx->len) {
                settle(rx, i, on_frame, user); /* Size */
                if (rx->ncand > i && rx->cand[i].end < rx->len) {
                    settle(rx, i, on_frame, user); /* checksum */
                }
            }
        }
        rx->scan = (uint16_t)(q + 1u);
    }
}

/* Judge every candidate whose event is at index q, oldest first. */
static void events_at(tase_rx_t *rx, uint16_t q, tase_rx_handler_t on_frame, void *user)
{
    uint8_t i = 0;
    while (i < rx->ncand) {
        uint8_t before = rx->ncand;
        if (cand_event(&rx->cand[i]) != q) {
            i++;
            continue;
        }
        settle(rx, i, on_frame, user);
        if (rx->ncand == before) {
            i++; /* Size accepted: the candidate stays */
        }
    }
    if (rx->scan < rx->len && rx->ncand < TASE_RX_CANDIDATES) {
        rescan(rx, on_frame, user);
    }
    update_next(rx);
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
    if (len >= 1u && rx->buf[len - 1u] == TASE_SYNC1 && (uint16_t)(len - 1u) >= rx->floor) {
        keep = 1u;
    } else if (len >= 2u && rx->buf[len - 1u] == TASE_SYNC2 && rx->buf[len - 2u] == TASE_SYNC1 &&
               (uint16_t)(len - 2u) >= rx->floor) {
        keep = 2u;
    } else {
        /* no partial sync at the end: keep nothing */
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

static void push_byte(tase_rx_t *rx, uint8_t b, tase_rx_handler_t on_frame, void *user)
{
    uint16_t q;
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
    if (q == rx->next) {
        events_at(rx, q, on_frame, user);
    }
    if (rx->ncand == 0u && rx->scan == rx->len) {
        go_idle(rx);
    }
}

int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user)
{
    size_t i = 0;
    uint32_t before;
    if (rx == NULL || (data == NULL && n > 0u)) {
        return TASE_EARG;
    }
    before = rx->stats.frames_ok;
    while (i < n) {
        if (rx->len == 0u) {
            /* Idle: everything up to the next 00 is noise. */
            const uint8_t *z = memchr(&data[i], TASE_SYNC1, n - i);
            size_t skip = (z != NULL) ? (size_t)(z - &data[i]) : (n - i);
            rx->stats.bytes_in += (uint32_t)skip;
            rx->stats.bytes_discarded += (uint32_t)skip;
            i += skip;
            if (z == NULL) {
                break;
            }
        } else if (rx->ncand > 0u && rx->len < RX_CAP) {
            /* Inside a candidate: copy the run of bytes before the next
             * event in one go, stopping at a 5A that may end a sync. */
            size_t run = (size_t)((rx->next < RX_CAP ? rx->next : RX_CAP) - rx->len);
            /* next > len here (events below len were settled when their
             * byte arrived); cppcheck's value flow assumes otherwise. */
            /* cppcheck-suppress knownConditionTrueFalse */
            if (run > n - i) {
                run = n - i;
            }
            /* cppcheck-suppress knownConditionTrueFalse */
            if (run > 0u) {
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
            }
        } else {
            /* only a partial sync held, or the window is full: the byte
             * goes through push_byte() alone */
        }
        push_byte(rx, data[i], on_frame, user);
        i++;
    }
    return (int)(rx->stats.frames_ok - before);
}

int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user)
{
    uint32_t before;
    if (rx == NULL) {
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
        rescan(rx, on_frame, user);
    }
    rx->floor = rx->len; /* nothing pending may start a frame */
    go_idle(rx);
    return (int)(rx->stats.frames_ok - before);
}
