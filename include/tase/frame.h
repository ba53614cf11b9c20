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
 * RECEIVER
 *
 * The receiver is a caller-owned tase_rx_t. It never allocates, never
 * blocks, uses no globals and no recursion. Bytes go in with
 * tase_rx_feed() (a buffer) or tase_rx_push() (one byte); every valid
 * frame is handed to a callback given with that call, as a view into the
 * receiver's window or into the caller's buffer.
 *
 * WHICH FRAMES. Exactly those of the greedy scan: from the start of the
 * stream, at each position where a complete frame with a valid checksum
 * begins (00 FF 5A, Size >= 2, Size + 6 bytes, checksum right), that frame
 * is taken and the scan continues after its last byte; anywhere else the
 * scan moves on one byte. So:
 *   - a valid frame's bytes are its data: nothing that lies inside a
 *     delivered frame is ever delivered. A CAMERA_PASS whose camera bytes
 *     happen to hold a complete valid frame (a GIMBAL_CMD, say) gives the
 *     CAMERA_PASS only; the frame-like bytes reach the application as
 *     camera data and nothing else. (A CAMERA_PASS that is itself
 *     corrupted or cut short is no frame: a valid frame inside it is then
 *     delivered by the next rule, as any receiver would have to);
 *   - no frame is lost behind a corrupted Size byte, a false sync or
 *     noise: when a candidate fails (Size < 2, stats.bad_size; checksum
 *     wrong, stats.checksum_errors) the scan resumes at the byte after its
 *     first sync byte, and a frame inside the failed candidate is found
 *     there;
 *   - frames are delivered in stream order, each exactly once.
 *
 * LATENCY. A frame is delivered once the stream decides it: by its own
 * last byte, or, when it lies inside an earlier candidate that is still
 * pending (a candidate whose last byte has not arrived yet, e.g. after a
 * Size byte corrupted upwards), by the last byte of the last such
 * candidate to fail (if one turns out valid, the frame was its data and
 * is dropped); that is at most TASE_FRAME_MAX - 8 = 253 bytes after its
 * own last byte (each began before it and spans at most TASE_FRAME_MAX
 * bytes). The scan behind it does a bounded amount of work per byte (COST
 * below), so when one byte decides much at once (a failed candidate over
 * a window full of candidates or frames) the scan lags, and the frame
 * comes out at most TASE_RX_LATE_MAX bytes after the byte that decided
 * it, from the call that feeds that later byte, or earlier from a
 * tase_rx_tick() (each tick continues a lagging scan like a byte would).
 * Frames, their order, offsets and the final counters are those of the
 * greedy scan exactly; only that moment moves. In the callback,
 * stats.bytes_in counts the bytes fed up to the delivering byte, and the
 * other counters the candidates judged so far. The result is the same for
 * any split of the stream into calls that take bytes (seen_at included);
 * a call with no byte (a 0-byte tase_rx_feed(), a tick) continues a
 * lagging scan with a byte's worth of work, so frames may come out
 * earlier with such calls between, never later.
 * tase_rx_flush() settles whatever is pending at end of input: the scan
 * catches up, pending candidates can no longer complete, so they fail and
 * what they were hiding is scanned.
 *
 * COST. The scan position never moves back: each byte is examined once,
 * each candidate judged once, and a candidate's checksum is read off
 * running sums (to the scan, to the last byte, and to the last judged
 * candidate's checksum bytes) plus the shortest stretch between one of
 * them and its checksum bytes (at most half the window, 2 bytes for a
 * candidate whose last byte just came). The scan runs on credit: every byte taken in (and
 * a call with no byte, or a tick) brings a fixed amount of scan work,
 * what a byte leaves unused is kept up to a cap, and the scan stops when
 * the credit is spent; it goes on in the next call. So every call has a
 * worst case that does not depend on the stream, and a call taking n
 * bytes at most the cap plus n bytes' worth (plus its callbacks):
 * docs/TIMING.md lists it per function, measured on Cortex-M4 and M0+ on
 * the adversarial streams of bench/ (on a Cortex-M4 -O2: about 900
 * instructions for one tase_rx_push(), 4,000 for a 16-byte
 * tase_rx_feed(), 14,000 for a 64-byte one; these are the longest calls
 * found, not proven bounds, and a search finds a few per cent more:
 * docs/DESIGN.md). tase_rx_push() stores a
 * byte inside a frame with one test, a store and an add; the sync bytes,
 * the Size byte and the last byte of a valid frame (its checksum is two
 * bytes off the running sum) are handled beside it without the general
 * path. A buffer fed with tase_rx_feed() takes noise and the bytes of a
 * held candidate in bulk (memchr, memcpy, one checksum pass). On telemetry
 * a byte costs 1.2 times a minimal classic parser's on a Cortex-M4
 * (less on an M0+: docs/DESIGN.md); the
 * worst streams measured (false syncs every 4 bytes whose Sizes keep the
 * scan behind and make it sum long stretches) cost about 92 Thumb
 * instructions per byte through tase_rx_push() on a Cortex-M4 (-O2; the
 * adversarial search of bench/search.sh finds 97.7) and 161 on an M0+
 * (-Os). docs/PERFORMANCE.md has the numbers.
 *
 * RAM. sizeof(tase_rx_t) is 360: the TASE_RX_WINDOW (296) window bytes (a
 * frame and the room a lagging scan needs), 28 of counters, 15 of the time
 * bound, 13 of scan state, 4 of the scan's credit and 4 of its sum cursor;
 * checked against
 * TASE_RX_SIZE_BUDGET at compile time. Stack: see docs/FOOTPRINT.md.
 *
 * TIME BOUND. A held candidate waits for its last byte, and with it every
 * frame inside it. On a link that goes quiet (a command link: a few
 * frames, then silence) that byte may never come: four bytes of noise,
 * 00 FF 5A FF, claim 257 more, and the frames after them would wait until
 * 257 more bytes arrived. tase_rx_tick() bounds that in time: a held
 * candidate (or partial sync) that has seen no new byte for longer than
 * its QUIET LIMIT is judged false, exactly as at end of input
 * (tase_rx_flush()): the frames inside it are delivered, in stream order,
 * and the stream goes on (offsets and counters run on). The quiet limit
 * of what is held is
 *     max(time its remaining bytes need at the link's byte rate, margin)
 * where the remaining bytes are those up to the held candidate's last
 * byte (for a partial sync, up to a maximal frame's; while the scan lags,
 * and so has not found what it will hold, a maximal frame's whole
 * TASE_FRAME_MAX), the byte rate is
 * set with tase_rx_set_timing() (0, the default after tase_rx_init(), is
 * taken as TASE_RX_SLOWEST_RATE, 960 bytes/s: a 9600-baud line, the
 * slowest of the spec) and the margin is TASE_RX_QUIET_MS (20 ms unless
 * configured, or set per receiver). A real frame never pauses that long:
 * its sender writes it contiguously, so its bytes come at the line's rate,
 * and the margin covers what the receiving side adds (an OS scheduling a
 * reader late, a USB-serial adapter delivering in bursts: FTDI parts every
 * 16 ms by default). A frame followed by silence is thus delivered at most
 * max(249 byte times, margin) after its last byte (a frame inside a held
 * candidate ends at least 12 bytes after the candidate began), plus the
 * time until the next tick: 44 ms at 57600 baud, 260 ms at 9600 (and the
 * margin, when it is the larger).
 * The receiver reads no clock: the caller passes its time (a port's
 * now_ms, monotonic, modulo 2^32) to tase_rx_tick(), which it calls
 *   - after every tase_rx_feed()/tase_rx_push() of bytes received at
 *     now_ms (the tick notes that the line was active), and
 *   - after every read that found no byte waiting (the line was quiet
 *     until now_ms): this tick settles what has been quiet for too long.
 * Never tick while received bytes wait unread (a ring buffer not yet
 * drained): the tick would count their time as quiet. A caller that
 * blocks in a read waits at most tase_rx_quiet_ms(), so that an empty read
 * and its tick come by the limit, and bytes arriving later cannot extend
 * a stale candidate. The host and gimbal roles (tase/host.h,
 * tase/gimbal.h) do all of this from their ports' clocks and byte rates;
 * a receiver that is never ticked behaves as before (a held candidate
 * waits for its bytes).
 *
 * STATISTICS are 32-bit counters in the instance. The receiver only ever
 * increments them; tase_rx_stats_reset() (and tase_rx_init()) are the only
 * things that clear them. Counters wrap modulo 2^32.
 *
 * RE-ENTRANCY. The callback runs inside tase_rx_feed(), tase_rx_push() or
 * tase_rx_flush(). On the same receiver, from inside the callback:
 *   - tase_rx_feed(), tase_rx_push() and tase_rx_flush() return TASE_EBUSY
 *     and change nothing;
 *   - tase_rx_stats_reset() is allowed: the counters restart from zero at
 *     that point (offsets of later frames count from there, modulo 2^32);
 *   - tase_rx_init() is allowed: the receiver is reset, and the call that
 *     made the callback returns as soon as the callback does, with the
 *     number of frames it delivered; the rest of its input is not consumed
 *     (nor counted in bytes_in). The receiver is no longer busy: the
 *     callback may feed it at once, and the interrupted call leaves what
 *     that did alone;
 *   - tase_rx_stop() is allowed: the call returns after this frame (see
 *     there), so the frame can be handled with the receiver's stack
 *     unwound.
 * Return values count the frames delivered by that call (never negative
 * except for an error code), whatever the callback does to the counters.
 * Different receivers are independent; one receiver must not be used from
 * two contexts concurrently (e.g. a main loop and an interrupt).
 *
 * INTERRUPTS. The receiver may run in an interrupt handler (a UART's
 * receive interrupt calling tase_rx_push(), a DMA IDLE-line interrupt
 * calling tase_rx_feed()): it keeps no global state, takes no lock and
 * allocates nothing, and every call has a bounded worst case (COST). The
 * callback then runs in that handler too, so it must be safe there (or
 * copy the frame out); and every call on that receiver, tase_rx_tick()
 * included, must come from that one context (the rule above). Receiving
 * into a ring in the interrupt and feeding from the main loop
 * (tase/ring.h) keeps the callback out of the interrupt.
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

/* TASE_RX_CANDIDATES (1..16, default 4; tase/config.h) has no effect
 * since 0.2.0. It was the number of overlapping candidate frames the
 * previous receiver tracked; the greedy receiver above keeps only the
 * earliest pending candidate, so every value gives the same frames,
 * timing, RAM (sizeof(tase_rx_t)) and code. It is still accepted and
 * range-checked so that configurations that set it keep building, it is
 * not part of any link name, and an application may set it differently
 * from its library. */

/* A received frame, passed to the callback. The struct itself lives only
 * while the callback runs (copy it to keep it); `data` points into the
 * receiver's window or into the caller's input buffer and is valid until
 * the callback returns, or, after tase_rx_stop(), until the next call on
 * the receiver. */
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
    uint32_t checksum_errors; /* candidates the scan reached (not inside a
                                 delivered frame) whose checksum failed */
    uint32_t bad_size;        /* the same, rejected for Size < 2 */
    uint32_t bytes_discarded; /* bytes released without being part of a
                                 delivered frame (noise, failed frames,
                                 incomplete frames at flush) */
    uint32_t bad_length;      /* reserved for the packet layer: valid frame
                                 whose data length is wrong for its type */
    uint32_t unknown;         /* reserved for the packet layer: valid frame
                                 of a group/type the schema does not know */
} tase_rx_stats_t;

/* Bytes the receiver's window holds: a whole frame (TASE_FRAME_MAX) and
 * the slack the resumable scan needs (frame.h COST, docs/DESIGN.md). */
#define TASE_RX_WINDOW 296u

/* Receiver instance. Treat every field except `stats` as private. */
typedef struct {
    tase_rx_stats_t stats;
    /* The time bound (TIME BOUND above): the link's byte rate and margin
     * (tase_rx_set_timing()), stats.bytes_in at the last tase_rx_tick()
     * and the now_ms of the last tick that saw new bytes (`ticked` says
     * whether those two are set yet, and that a settling tick a callback
     * stopped is to go on). */
    uint32_t rate;
    uint32_t tick_bytes;
    uint32_t quiet_since;
    uint16_t margin_ms;
    uint8_t ticked;
    /* `busy` is set while a call (and so its callback) runs; `lag` while
     * the scan has not caught up with the bytes held; `stop` from
     * tase_rx_stop() until that call returns. */
    uint8_t busy;
    uint8_t lag;
    uint8_t stop;
    /* buf[0..len) holds the bytes not yet decided from buf[scan] on (see
     * src/tase_frame.c); `end` is the index of the last byte of the
     * candidate held at buf[scan] once the scan has caught up (0 when
     * none, and during a call); sum_len and sum_scan are running sums of
     * buf up to len and up to scan. */
    uint16_t len;
    uint16_t end;
    uint16_t scan;
    uint16_t sum_len;
    uint16_t sum_scan;
    /* The scan's credit (src/tase_frame.c): units left at the last
     * budgeted scan, and the low 16 bits of stats.bytes_in then. */
    uint16_t bank;
    uint16_t bank_at;
    /* A third known prefix of the window for the scan's sums: sum_at is
     * the running sum up to buf[at] (at is 0 when there is none). */
    uint16_t at;
    uint16_t sum_at;
    uint8_t buf[TASE_RX_WINDOW];
} tase_rx_t;

/* How many bytes after the byte that decides it a frame may be delivered
 * (LATENCY above): the scan's lag, bounded in src/tase_frame.c. */
#define TASE_RX_LATE_MAX 224u

/* How many candidates a call judges (and so frames it delivers) at most
 * per byte it takes in, and per tick (COST above). */
#define TASE_RX_JUDGE_MAX 12u

/* Upper bound on sizeof(tase_rx_t) (the same on 32- and 64-bit targets:
 * the instance holds no pointers), enforced at compile time in tase_frame.c. */
#define TASE_RX_SIZE_BUDGET 360u

/* Called once per valid frame, in stream order. See RE-ENTRANCY above for
 * what it may call on the same receiver. */
typedef void (*tase_rx_handler_t)(void *user, const tase_frame_t *frame);

/* 16-bit additive checksum: `seed` plus the sum of n bytes, modulo 2^16.
 * p == NULL (any n) returns seed without reading. O(n), reentrant. */
uint16_t tase_checksum(uint16_t seed, const uint8_t *p, size_t n);

/* Build one frame of (group, type) carrying data[0..len) into
 * out[0..cap). The arguments come in the order of every encoder of the
 * library: what, then the input, then the output (as
 * tase_packet_encode(id, msg, out, cap)).
 * Returns the frame length (len + 8) or
 *   TASE_EARG     out is NULL, or data is NULL with len > 0;
 *   TASE_ETOOLONG len > TASE_DATA_MAX;
 *   TASE_ENOSPC   cap < len + 8.
 * On error nothing is written. `data` may point at out + TASE_FRAME_HEADER
 * (encode the payload in place, then frame it without a copy); any other
 * overlap is allowed too. O(len), reentrant, ISR-safe. */
int tase_frame_build(uint8_t group, uint8_t type, const uint8_t *data, size_t len, uint8_t *out,
                     size_t cap);

/* Deprecated since 0.3.0, removed in 0.4.0: tase_frame_build() with the
 * output first, tase_frame_build(group, type, data, len, out, cap) in
 * the old order. Same results. */
TASE_DEPRECATED_("use tase_frame_build(group, type, data, len, out, cap)")
int tase_frame_encode(uint8_t *out, size_t cap, uint8_t group, uint8_t type, const uint8_t *data,
                      size_t len);

/* Initialise (or reset) a receiver: empty window, all counters zero.
 * Returns TASE_OK, or TASE_EARG if rx is NULL. O(sizeof(tase_rx_t)).
 * Allowed from inside the receiver's own callback (see RE-ENTRANCY). */
int tase_rx_init(tase_rx_t *rx);

/* Feed n bytes. Each valid frame they complete is passed to
 * on_frame(user, frame) before this returns; on_frame may be NULL (frames
 * are then only counted). Returns the number of frames delivered by this
 * call (>= 0; INT_MAX if more), or
 *   TASE_EARG  rx is NULL, or data is NULL with n > 0 (any n up to
 *              SIZE_MAX), or rx is visibly not an initialised receiver
 *              (held length, held candidate's end and Size disagree);
 *   TASE_EBUSY called from inside a callback of this receiver;
 * and then nothing is consumed and rx is unchanged.
 * All n bytes are taken in unless the callback stopped the call
 * (tase_rx_stop()) or re-initialised rx: stats.bytes_in then says how
 * many were.
 * Feeding a stream one byte at a time or in any split gives the same
 * frames, offsets, counters and moments of delivery. Feeding 0 bytes
 * continues a lagging scan. Cost O(n): the scan work of the credit kept
 * from earlier bytes (at most a fixed cap) and of a fixed amount per byte
 * taken in (COST), plus the callbacks; worst case per call on Cortex-M in
 * docs/TIMING.md. */
int tase_rx_feed(tase_rx_t *rx, const uint8_t *data, size_t n, tase_rx_handler_t on_frame,
                 void *user);

/* Feed one byte: the same as tase_rx_feed(rx, &byte, 1, on_frame, user),
 * for callers that get one byte at a time (a UART interrupt's ring). A
 * byte inside a frame is only stored, and a frame's sync, Size and last
 * byte are handled here too, so a clean stream never takes the general
 * path. Returns the number of frames delivered (0 or 1 on a clean stream;
 * a few more while a lagging scan releases frames; the byte is not taken
 * in if a callback stopped the call before room was made for it:
 * stats.bytes_in says), or TASE_EARG (rx NULL
 * or visibly corrupted) / TASE_EBUSY (inside a callback of this
 * receiver), receiver unchanged. One difference from tase_rx_feed(): a
 * byte inside a held candidate (the fast path) is checked only as far as
 * keeps it inside the window; a receiver corrupted otherwise (its held
 * candidate's Size and end disagree) takes such bytes and is refused
 * (TASE_EARG) at the candidate's last byte, at most 253 bytes later,
 * where tase_rx_feed() refuses it at once (the full check costs every
 * byte a frame carries). Longest block: the scan work the byte's
 * credit pays for (COST: the byte's own and what earlier bytes left, up
 * to a cap) plus one compaction of the window and the callbacks of the
 * frames that work releases: bounded whatever the stream (docs/TIMING.md:
 * the measured worst case on Cortex-M4 and M0+ and the stream that gives
 * it). */
int tase_rx_push(tase_rx_t *rx, uint8_t byte, tase_rx_handler_t on_frame, void *user);

/* End of input (end of a capture file, link closed): settle what is
 * pending. A pending candidate can no longer complete, so it fails (its
 * bytes are discarded, no counter other than bytes_discarded) and the
 * bytes after its first sync byte are scanned: frames found there are
 * delivered. Afterwards the receiver is empty (counters kept) and ready for
 * a new stream. Returns frames delivered (>= 0), or TASE_EARG /
 * TASE_EBUSY as tase_rx_feed() (receiver unchanged). Longest block: the
 * whole window's scan work (at most one window of TASE_RX_WINDOW
 * positions, its candidates and frames), with no budget: end of input is
 * where everything is decided (docs/TIMING.md). */
int tase_rx_flush(tase_rx_t *rx, tase_rx_handler_t on_frame, void *user);

/* The byte rate taken when none is set: 9600 baud 8N1. */
#define TASE_RX_SLOWEST_RATE 960u

/* Set the byte rate of the receiver's link (bytes per second, e.g.
 * TASE_UART_BYTES_PER_S(57600); 0: unknown, taken as
 * TASE_RX_SLOWEST_RATE) and the margin of its time bound in ms (0: the
 * default TASE_RX_QUIET_MS). Returns TASE_OK, TASE_EARG (rx NULL or
 * visibly corrupted, as tase_rx_feed()) or TASE_EBUSY (inside a callback
 * of this receiver); nothing changed on error. Kept
 * by tase_rx_flush() and tase_rx_stats_reset(), reset by tase_rx_init().
 * O(1). */
int tase_rx_set_timing(tase_rx_t *rx, uint32_t bytes_per_s, uint16_t margin_ms);

/* The receiver's clock input (TIME BOUND above), with the caller's time
 * now_ms: call it after feeding bytes received at now_ms and after a read
 * that found nothing waiting. If bytes were fed since the previous tick,
 * notes the line as active at now_ms and returns 0. Otherwise, if
 * something is held and the line has been quiet for longer than its
 * quiet limit, settles it like tase_rx_flush() (the receiver is then
 * empty; counters kept) and returns the number of frames delivered; else
 * returns 0. The first tick after tase_rx_init() only notes the time. A
 * now_ms earlier than the noted time (a stale sample: a difference of
 * 2^31 or more) counts as no time passed. Returns TASE_EARG / TASE_EBUSY
 * as tase_rx_flush() (receiver unchanged). A tick also continues a
 * lagging scan (one byte's credit, and its frames are counted in the
 * return value). Longest block: as tase_rx_flush() when it settles, as
 * tase_rx_push() otherwise. */
int tase_rx_tick(tase_rx_t *rx, uint32_t now_ms, tase_rx_handler_t on_frame, void *user);

/* How long (ms from now_ms) the caller may wait for bytes before it must
 * call tase_rx_tick() for the time bound to hold: 0 when a tick is due
 * (bytes fed since the last tick, or the limit has passed), UINT32_MAX
 * when nothing is held (no bound to keep), else what is left of the quiet
 * limit. A blocking reader waits at most this long (the roles' service
 * calls do); 0 also while the scan lags (ticks continue it). UINT32_MAX
 * for rx NULL. O(1), reentrant; allowed from the callback. */
uint32_t tase_rx_quiet_ms(const tase_rx_t *rx, uint32_t now_ms);

/* From inside rx's frame callback: end the call that delivers this frame
 * as soon as the callback returns. That call returns the frames it
 * delivered (this one the last). Copy *frame in the callback (the struct
 * is the receiver's local); the bytes at frame->data stay valid until the
 * next call on rx, so the caller can handle the frame there, with the
 * receiver's stack unwound (the gimbal role does). Input the call had not
 * taken in is not consumed: stats.bytes_in counts what was (it grows by
 * exactly the bytes taken, unless the callback also reset the counters),
 * the caller feeds the rest again. A scan the call had not finished goes
 * on in the next call on rx, as a lagging scan does (a 0-byte
 * tase_rx_feed(), tase_rx_tick() or tase_rx_flush() included); that call
 * may stop on a frame too, so a caller repeats it while its callback
 * stops (a stopped flush or settling tick likewise, until it returns 0).
 * Frames, their order and offsets are the same as without stops. A
 * caller that handles every frame outside the callback (the callback
 * copies *frame to f and stops; n bytes at p to feed):
 *     bool stopped = false;
 *     do {
 *         uint32_t in = rx.stats.bytes_in;
 *         f.data = NULL;
 *         (void)tase_rx_feed(&rx, p, stopped ? 0u : n, cb, &f);
 *         p += rx.stats.bytes_in - in;
 *         n -= rx.stats.bytes_in - in;
 *         stopped = f.data != NULL;
 *         if (stopped) handle(&f);
 *     } while (stopped || n > 0u);
 * (tase_gimbal_feed() in src/tase_gimbal.c is this loop.) TASE_RX_LATE_MAX holds when every stop is followed by a
 * 0-byte tase_rx_feed() before more bytes are fed (each such call brings
 * a byte's credit; a stop forfeits none).
 * Returns TASE_OK; TASE_ESTATE when no call of rx is running (outside its
 * callback); TASE_EARG for rx NULL. O(1). */
int tase_rx_stop(tase_rx_t *rx);

/* Zero every counter, nothing else: the frames and the bytes that
 * deliver them are the same as without the reset. Returns TASE_OK or
 * TASE_EARG (rx NULL). Allowed from inside the receiver's own callback. */
int tase_rx_stats_reset(tase_rx_t *rx);

#ifdef __cplusplus
}
#endif

#endif /* TASE_FRAME_H */
