/*
 * tase/dispatch.h - hands each received frame to a typed handler chosen by
 * (group, type), decoded through the schema.
 *
 * A caller-owned tase_dispatch_t is the `user` argument of
 * tase_dispatch_frame(), which is a tase_rx_handler_t:
 *
 *     tase_dispatch_t d;
 *     tase_dispatch_init(&d, handlers, on_other, on_error, ctx, &rx.stats);
 *     tase_rx_feed(&rx, bytes, n, tase_dispatch_frame, &d);
 *
 * For every valid frame, in this order:
 *   1. (group, type) unknown to the schema (e.g. group 0x28 STATUS, which
 *      spec v1.0.0 leaves empty): stats->unknown is incremented and the
 *      frame goes intact to the default handler.
 *   2. Known packet with a data length it does not accept:
 *      stats->bad_length is incremented and the error hook gets the frame
 *      with TASE_ELENGTH. It never reaches a typed handler.
 *   3. Known packet, accepted length, typed handler set: the frame is
 *      decoded into the dispatcher's buffer, as tase_packet_decode() would
 *      but with the field walk of the lookup above (tase_field_iter_find(),
 *      tase_packet_decode_iter(): one call into the schema per frame), and
 *      the handler gets the frame and the typed struct (tase/codec.h; NULL for
 *      GYRO_ZERO_CMD). A query (tase_schema_is_query()) arrives as a
 *      zeroed struct with frame->len == 0: test frame->len before acting
 *      on a SPOI_CMD (the only query a gimbal application gets: its
 *      zeroed struct reads as a point at 0 deg N, 0 deg E, which must not
 *      be pointed at); a 1-byte CAMERA_CMD has frame->len == 1 (the
 *      fields it omits decode to their "do not change" values).
 *   4. Known packet, accepted length, no typed handler: the default
 *      handler gets the frame (not counted), so a default handler alone
 *      sees every frame.
 *
 * HANDLER TABLE. `handlers` is an array of TASE_PKT_COUNT entries indexed
 * by TASE_PKT_* (tase/schema.h), typically a static const table in ROM:
 *
 *     static const tase_packet_handler_t handlers[TASE_PKT_COUNT] = {
 *         [TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd,
 *         [TASE_PKT_PACKET_RATE] = on_packet_rate,
 *     };
 *
 * C++ has no array designators (g++: "non-trivial designated
 * initializers not supported"). From C++14 on, a constexpr function
 * builds the same constant table, still in ROM and set up at compile time:
 *
 *     struct handler_table { tase_packet_handler_t h[TASE_PKT_COUNT]; };
 *     constexpr handler_table make_handlers()
 *     {
 *         handler_table t{};  // every entry NULL
 *         t.h[TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd;
 *         t.h[TASE_PKT_PACKET_RATE] = on_packet_rate;
 *         return t;
 *     }
 *     static constexpr handler_table handlers = make_handlers();
 *     ...
 *     tase_dispatch_init(&d, handlers.h, on_other, on_error, ctx, &rx.stats);
 *
 * (Before C++14, fill a static array at start-up instead; it is then in
 * RAM.)
 *
 * Lookup is O(1): the schema's direct index gives the TASE_PKT_* index.
 *
 * STACK AND RAM. The decoded struct lives in the dispatcher instance
 * (`msg`, sizeof(tase_packet_msg_t) = 64 bytes on Cortex-M), not on the
 * stack, so the receive path stays shallow on small RTOS task stacks. It
 * is valid only during the handler call (copy what you keep). See
 * docs/FOOTPRINT.md for the measured stack of the receive path.
 *
 * Handlers run inside tase_rx_feed(): they must not feed the same
 * receiver. The frame and any pointer into it (CAMERA_PASS data) are valid
 * only during the call.
 */
#ifndef TASE_DISPATCH_H
#define TASE_DISPATCH_H

#include "tase/codec.h"
#include "tase/frame.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Typed handler: msg points at the packet's typed struct. */
typedef void (*tase_packet_handler_t)(void *user, const tase_frame_t *frame, const void *msg);

/* Error hook: a valid frame the packet layer rejects (err is
 * TASE_ELENGTH: wrong data length for its type). */
typedef void (*tase_dispatch_error_t)(void *user, const tase_frame_t *frame, int err);

typedef struct {
    const tase_packet_handler_t *handlers; /* TASE_PKT_COUNT entries, or NULL */
    tase_rx_handler_t on_default;          /* unknown / unhandled; may be NULL */
    tase_dispatch_error_t on_error;        /* may be NULL */
    void *user;                            /* first argument of every callback */
    tase_rx_stats_t *stats;                /* bad_length / unknown; may be NULL */
    tase_packet_msg_t msg;                 /* private: the decoded packet */
} tase_dispatch_t;

/* Initialise d. Every pointer argument except d may be NULL (`stats` is
 * usually &rx.stats so all link statistics are in one place; it is only
 * ever incremented). The dispatcher keeps the pointers: the handler table
 * and stats must outlive it. Returns TASE_OK or TASE_EARG if d is NULL. */
/* Every parameter is named; cppcheck 2.10's MISRA addon miscounts them. */
/* cppcheck-suppress misra-c2012-8.2 */
int tase_dispatch_init(tase_dispatch_t *d, const tase_packet_handler_t *handlers,
                       tase_rx_handler_t on_default, tase_dispatch_error_t on_error, void *user,
                       tase_rx_stats_t *stats);

/* Dispatch one frame as described above; `dispatcher` is a
 * tase_dispatch_t *. Ignores the call if either argument is NULL, or if
 * the frame's data is NULL with len > 0 (not a frame a receiver
 * delivers): no callback runs, nothing is counted.
 * O(frame length). Reentrant for different dispatchers; ISR-safe if the
 * handlers are. */
void tase_dispatch_frame(void *dispatcher, const tase_frame_t *frame);

#ifdef __cplusplus
}
#endif

#endif /* TASE_DISPATCH_H */
