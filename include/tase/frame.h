/*
 * tase/frame.h - the TASE datalink layer: frame encoder and receive state
 * machine (spec section 3.1).
 *
 * Wire format of one frame (all multi-byte values big-endian):
 *
 *     00 FF 5A | Size | Group | PktType | Data[Size-2] | Check_0 Check_1
 *
 * Size counts Group, PktType and Data, so Size = data length + 2 and the
 * data length is 0..253. The checksum is the 16-bit unsigned sum of every
 * byte before it, sync bytes included, sent most significant byte first.
 * A frame is therefore 8..261 bytes long.
 *
 * RECEIVER DESIGN
 *
 * The receiver is a caller-owned tase_rx_t. It never allocates, never
 * blocks, uses no globals and no recursion. Bytes go in with
 * tase_rx_feed(); every valid frame is handed to a callback given with
 * that call, as a view into the receiver's window.
 *
 * Every occurrence of 00 FF 5A in the stream starts a *candidate* frame.
 * Candidates are tracked concurrently (up to TASE_RX_CANDIDATES of them),
 * each judged on its own bytes:
 *   - its Size byte < 2 rejects it at once (stats.bad_size);
 *   - when its last byte arrives its checksum is compared
 *     (stats.checksum_errors on mismatch);
 *   - a candidate whose checksum holds is delivered immediately, and any
 *     candidate that began inside its bytes is dropped (those bytes were
 *     data of a valid frame), as is any sync that starts inside it later.
 * Because a candidate never blocks the ones that start inside it, a
 * corrupted Size byte that claims 255 bytes cannot swallow the packets
 * behind it, and re-scanning after a checksum failure is implicit: the
 * bytes after a failed frame's first sync byte were examined as they
 * arrived.
 *
 * LATENCY. While no more than TASE_RX_CANDIDATES candidates overlap, a
 * clean frame is delivered from within the call that feeds its own last
 * byte: zero added latency, also when it began inside a longer candidate
 * that has not failed yet. Real links rarely overlap more than two
 * candidates (a corrupted frame plus the clean one inside it). When more
 * overlap (adversarial streams full of false sync sequences), syncs past
 * the limit are re-scanned from the window as soon as a tracked candidate
 * ends, and a frame found that way is delivered late by at most
 * TASE_FRAME_MAX - 8 = 253 bytes (it is found no later than the end of the
 * oldest overlapping candidate, which began before it). No frame is lost
 * either way; tase_rx_flush() settles whatever is pending at end of input.
 *
 * One consequence of judging candidates independently: a valid frame whose
 * data carries a complete valid frame (possible with CAMERA_PASS payloads)
 * produces both, the inner one first. In the over-limit path only the
 * outer one is delivered.
 *
 * COST. From idle, a frame that is wholly inside the bytes of one feed
 * call and has no 5A byte after its sync (so no other candidate can start
 * in it) is checked and delivered straight from the caller's buffer. Other
 * bytes are copied in runs (memchr/memcpy) between sync bytes and frame
 * ends. On x86-64 (gcc -O2, callgrind) a clean telemetry stream costs
 * about 9 instructions per byte fed in 4 KB buffers and about 51 fed one
 * byte at a time through tase_rx_push(); a stream made only of false syncs
 * claiming 253 data bytes is the worst case, about 240 (300 byte at a
 * time). docs/PERFORMANCE.md has the measured numbers.
 *
 * RAM. sizeof(tase_rx_t) is TASE_FRAME_MAX window bytes + counters +
 * candidate bookkeeping; checked against TASE_RX_SIZE_BUDGET at compile
 * time. See docs/DESIGN.md for why the 272-byte target of the original
 * brief cannot hold with 32-bit counters in the instance.
 *
 * STATISTICS are 32-bit counters in the instance. The receiver only ever
 * increments them; tase_rx_stats_reset() is the only thing that clears
 * them. Counters wrap modulo 2^32.
 */
#ifndef TASE_FRAME_H
#define TASE_FRAME_H

#include "tase/common.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_SYNC1 0x00u
#define TASE_SYNC2 0xFFu
#define TASE_SYNC3 0x5Au

#define TASE_FRAME_HEADER 6u   /* sync x3, Size, Group, PktType */
#define TASE_FRAME_OVERHEAD 8u /* header + 2 checksum bytes */
#define TASE_DATA_MAX 253u     /* Size is one byte and counts Group+Type */
#define TASE_FRAME_MAX (TASE_DATA_MAX + TASE_FRAME_OVERHEAD) /* 261 */

/* TASE_RX_CANDIDATES: how many overlapping candidate frames are tracked
 * for zero added latency (1..16, default 4; set it in TASE_CONFIG_HEADER,
 * see tase/config.h). 1 gives a classic parser that re-scans after a
 * failure (bounded latency, never loses a frame). Each extra candidate
 * costs 6 bytes of RAM. It changes sizeof(tase_rx_t): an application
 * built with another value than the library does not link. */

/* A received frame. `data` points into the receiver's window or into the
 * caller's input buffer and is valid only until the callback returns. */
typedef struct {
    /* Stream offset of the first sync byte, counted like stats.bytes_in:
     * from tase_rx_init() or the last tase_rx_stats_reset(), modulo 2^32. */
    uint32_t offset;
    uint8_t group;
    uint8_t type;
    uint8_t len;         /* data length, 0..253 */
    const uint8_t *data; /* `len` bytes (not NULL even when len == 0) */
} tase_frame_t;

/* Receiver statistics. Only incremented by the library. */
typedef struct {
    uint32_t bytes_in;        /* every byte fed */
    uint32_t frames_ok;       /* valid frames delivered */
    uint32_t checksum_errors; /* candidates whose checksum failed */
    uint32_t bad_size;        /* candidates rejected for Size < 2 */
    uint32_t bytes_discarded; /* bytes released without being part of a
                                 delivered frame (noise, failed frames,
                                 incomplete frames at flush) */
    uint32_t bad_length;      /* reserved for the packet layer: valid frame
                                 whose data length is wrong for its type */
    uint32_t unknown;         /* reserved for the packet layer: valid frame
                                 of a group/type the schema does not know */
} tase_rx_stats_t;

/* Private bookkeeping of one candidate; do not touch. */
typedef struct {
    uint16_t start;  /* window index of its first sync byte */
    uint16_t end;    /* window index of its last byte; 0 until Size seen */
    uint16_t credit; /* delivered bytes before `start` (noise accounting) */
} tase_rx_cand_t;

/* Receiver instance. Treat every field except `stats` as private. */
typedef struct {
    tase_rx_stats_t stats;
    uint16_t len;    /* bytes held in buf */
    uint16_t scan;   /* buf[scan..len) not yet examined for sync */
    uint16_t floor;  /* no new frame may start below this index */
    uint16_t next;   /* index of the next candidate event, 0xFFFF none */
    uint16_t credit; /* bytes of delivered frames still in buf */
    uint8_t ncand;
    tase_rx_cand_t cand[TASE_RX_CANDIDATES];
    uint8_t buf[TASE_FRAME_MAX];
} tase_rx_t;

/* Upper bound on sizeof(tase_rx_t) (the same on 32- and 64-bit targets:
 * the instance holds no pointers), enforced at compile time in tase_frame.c. */
#define TASE_RX_SIZE_BUDGET (328u + 6u * ((unsigned)TASE_RX_CANDIDATES - 4u))

/* Called once per valid frame, in stream order of the frames' last bytes
 * (see LATENCY above for the over-limit exception). Must not call
 * tase_rx_feed()/tase_rx_flush() on the same receiver. */
typedef void (*tase_rx_handler_t)(void *user, const tase_frame_t *frame);

/* 16-bit additive checksum: `seed` plus the sum of n bytes, modulo 2^16.
 * p == NULL (any n) returns seed without reading. O(n), reentrant. */
uint16_t tase_checksum(uint16_t seed, const uint8_t *p, size_t n);

/* Encode one frame into out[0..cap).
 * Returns the frame length (len + 8) or
 *   TASE_EARG     out is NULL, or data is NULL with len > 0;
 *   TASE_ETOOLONG len > TASE_DATA_MAX;
 *   TASE_ENOSPC   cap < len + 8.
 * On error nothing is written. `data` may point at out + TASE_FRAME_HEADER
 * (encode the payload in place, then frame it without a copy); any other
 * overlap is allowed too. O(len), reentrant, ISR-safe. */
int tase_frame_encode(uint8_t *out, size_t cap, uint8_t group, uint8_t type, const uint8_t *data,
                      size_t len);

/* Initialise (or reset) a receiver: empty window, all counters zero.
 * Returns TASE_OK, or TASE_EARG if rx is NULL. */
int tase_rx_init(tase_rx_t *rx);

/* Feed n bytes. Each valid frame completed by them is passed to
 * on_frame(user, frame) before this returns; on_frame may be NULL (frames
 * are then only counted). Returns the number of frames delivered (>= 0),
 * or TASE_EARG if rx is NULL or data is NULL with n > 0 (any n up to
 * SIZE_MAX), or rx is visibly not an initialised receiver (held length,
 * scan position or candidate count out of range); nothing is consumed.
 * Feeding a stream one byte at a time or in any split gives the same
 * frames and counters. Not reentrant per receiver; different receivers
 * are independent. Call from one context (e.g. the main loop draining an
 * ISR ring buffer), not concurrently. Worst case O(n * TASE_FRAME_MAX). */
int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user);

/* Feed one byte: the same as tase_rx_feed(rx, &byte, 1, on_frame, user),
 * with a shorter path for the common bytes (inside a frame, or noise while
 * hunting for a sync), for callers that get one byte at a time. Returns
 * the number of frames delivered (0 or more) or TASE_EARG if rx is NULL
 * or visibly corrupted (as tase_rx_feed(); receiver unchanged).
 * Same context rules as tase_rx_feed(). */
int tase_rx_push(tase_rx_t *rx, uint8_t byte, tase_rx_handler_t on_frame, void *user);

/* End of input (end of a capture file, link closed): settle every pending
 * candidate. Frames that can still be completed from the bytes held are
 * delivered; incomplete ones are released and counted in bytes_discarded.
 * Afterwards the receiver is empty (counters kept) and ready for a new
 * stream. Returns frames delivered (>= 0) or TASE_EARG if rx is NULL or
 * visibly corrupted (as tase_rx_feed(); receiver unchanged). */
int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user);

/* Zero every counter, nothing else. Returns TASE_OK or TASE_EARG (rx
 * NULL). */
int tase_rx_stats_reset(tase_rx_t *rx);

#ifdef __cplusplus
}
#endif

#endif /* TASE_FRAME_H */
