/*
 * bench/cm/timing.h - what the parts of the worst-case-per-call program
 * share (timing.c has main() and the receiver, codec and KLV stream calls;
 * timing_roles.c the port helpers and the roles; timing_schema.c the
 * schema and field functions; timing_misc.c CAN, candump, KLV helpers,
 * units and the rest; timing_port.c the bare-metal port, port/baremetal).
 * One output line per function:
 *   timing FUNCTION INSTRUCTIONS WORST-CASE-INPUT (the rest of the line)
 */
#ifndef BENCH_CM_TIMING_H
#define BENCH_CM_TIMING_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "measure.h"
#include "tase/codec.h"
#include "tase/schema.h"

/* A measured call: kept out of its caller, as a caller makes it. */
#define NOINLINE __attribute__((noinline, noipa))

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

/* Results land here so that the compiler keeps the calls. */
extern volatile unsigned long timing_sink;

/* A measured call: `name`(ctx) makes the call `expr` (arguments from
 * file-scope variables) and keeps its result. */
#define MEASURED(name, expr)                                                                       \
    NOINLINE static void name(void *ctx)                                                           \
    {                                                                                              \
        (void)ctx;                                                                                 \
        timing_sink += (unsigned long)(expr);                                                      \
    }

void report(const char *fn, unsigned long insns, const char *input);

/* The empty setup: the call needs no state put back. */
void nothing(void *ctx);

/* Exact instructions of call(NULL) with no state to put back. */
unsigned long measure_plain(measure_fn call);

/* call(ctx) right after setup(ctx), timed once to the timer's tick
 * (MEASURE_TICK_INSNS instructions): the first pass of a search, whose
 * second counts exactly only the calls that came within a tick of the
 * longest (no other can be longer), and the figure of a call too long to
 * repeat. */
unsigned long measure_once(measure_fn setup, measure_fn call, void *ctx);

/* Every stream of PERFORMANCE.md (bench/streams.h), for the searches. */
#define ALL_STREAMS 11u
extern const char *const all_streams[ALL_STREAMS];

/* The worst count seen so far over several inputs, and which input. */
typedef struct {
    unsigned long insns;
    char input[320];
} worst_t;

/* Keep insns and the input described by fmt when it is the worst yet. */
void worst_try(worst_t *w, unsigned long insns, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* report() the worst, its input followed by `how` (may be ""). */
void worst_report(const char *fn, const worst_t *w, const char *how);

/* The packet a per-packet measurement is on, and its longest typed
 * message: every member bytes 0xA5 except CAMERA_PASS, which carries
 * TASE_CAMERA_PASS_MAX camera bytes (253 data bytes) from camera_bytes,
 * at an address camera_off mod 4 (0 unless set_camera_off() moved it). */
extern const tase_packet_desc_t *cur_pkt;
extern size_t cur_len; /* its data length in the input's name */
extern tase_packet_msg_t full_msg;
extern const uint8_t *camera_bytes;
extern size_t camera_off;
void set_camera_off(size_t off); /* 0..3 */

/* Fill full_msg for packet p; returns the data length of its full form. */
size_t fill_full_msg(const tase_packet_desc_t *p);

/* fill_full_msg(p) and cur_len, and its frame encoded in pkt_frame
 * (pkt_frame_n bytes, pkt_f the received frame it makes); false when p
 * cannot be encoded so. */
bool prep_full_frame(const tase_packet_desc_t *p);
extern uint8_t pkt_frame[TASE_FRAME_MAX + 16u];
extern size_t pkt_frame_n;
extern tase_frame_t pkt_f;

/* The worst of `call` over every packet of the schema: prep(p) sets up
 * cur_pkt's arguments and returns false to skip p; `setup` puts the state
 * back before each call. The input reads "NAME (N data bytes)". */
void over_packets(worst_t *w, bool (*prep)(const tase_packet_desc_t *p), measure_fn setup,
                  measure_fn call);

void timing_codec(void);
void timing_schema(void);
void timing_roles(void);
void timing_misc(void);
void timing_port(void);

#endif /* BENCH_CM_TIMING_H */
