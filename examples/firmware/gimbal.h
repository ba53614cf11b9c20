/*
 * gimbal.h - the application of the example firmware: what this gimbal
 * does with the packets it receives, built from the library's pieces.
 *
 *  - tase_dispatch_t with a static const handler table (ROM): typed
 *    handlers for GIMBAL_CMD, SPOI_CMD, GYRO_ZERO_CMD, HOST_ATTITUDE and
 *    the eight setup packets; wrong-length frames go to the error hook,
 *    packets the schema does not know to the default handler.
 *  - SPOI_CMD: a point that tase_command_check() accepts becomes the SPOI
 *    in force (SPOI mode, echoed when its flags ask), a zero-length one
 *    is answered with it (zeros before the first); a SPOI error command
 *    (GIMBAL_CMD 0xC0/0xD0) acts only in SPOI mode, and a rate, position
 *    or legacy command leaves it (docs/PROTOCOL-NOTES.md C14, P4). This
 *    board does not point anything: a product aims its axes here.
 *  - tase_gimbal_t, the library's gimbal role, on one port: the setup
 *    handler hands each setup frame to it, and it answers queries and
 *    echoes settings; tase_gimbal_poll() sends GIMBAL_ANGLE, GIMBAL_RATE
 *    and GEOREFERENCE_DATA at the rates of PACKET_RATE, their contents
 *    written by the fill_telemetry callback through the typed encoder.
 *
 * Board-independent: the board (main.c) gives the port the role writes
 * to, feeds frames to tase_dispatch_frame() with &app->dispatch, sets
 * app->now_ms and polls. A trace hook shows the self-checks every frame
 * and how it was routed.
 */
#ifndef GIMBAL_H
#define GIMBAL_H

#include "tase/codec.h"
#include "tase/dispatch.h"
#include "tase/gimbal.h"

/* How a received frame reached the application (stream.h ROUTE_*). */
#define GIMBAL_ROUTE_TYPED 0u
#define GIMBAL_ROUTE_ERROR 1u
#define GIMBAL_ROUTE_DEFAULT 2u
#define GIMBAL_TRACE_MAX 13u /* most decoded values passed to the trace */

/* Called for every received frame: its route and, for a typed frame, the
 * decoded fields in the spec's order (n values). */
typedef void (*gimbal_trace_t)(void *user, const tase_frame_t *frame, unsigned route,
                               const int64_t *values, size_t n);

typedef struct {
    tase_gimbal_t role;       /* library: setup echo/query, telemetry */
    tase_dispatch_t dispatch; /* library: typed dispatch */
    uint32_t now_ms;          /* set by the main loop before feeding */
    /* Last GIMBAL_CMD. */
    int16_t cmd_pan;
    int16_t cmd_tilt;
    uint8_t cmd_flags;
    /* The SPOI in force (zeros before the first) and whether the gimbal
     * is tracking it (SPOI mode). */
    tase_spoi_cmd_t spoi;
    bool spoi_mode;
    /* Counters. */
    uint32_t commands;         /* GIMBAL_CMD applied */
    uint32_t commands_refused; /* GIMBAL_CMD failing tase_command_check() */
    uint32_t commands_ignored; /* SPOI error commands outside SPOI mode */
    uint32_t spois;            /* SPOI_CMD points applied */
    uint32_t spois_refused;    /* SPOI_CMD failing tase_command_check() */
    uint32_t spoi_queries;     /* zero-length SPOI_CMD answered */
    uint32_t gyro_zeros;       /* GYRO_ZERO_CMD */
    uint32_t host_attitudes;   /* HOST_ATTITUDE */
    uint32_t setups;           /* setup packets handed to the role */
    uint32_t setups_refused;   /* of them, settings apply_setup() refused */
    uint32_t length_errors;    /* error hook calls */
    uint32_t unknown;          /* default handler calls */
    uint32_t encode_errors;    /* SPOI answers the role could not send */
    gimbal_trace_t trace;
    void *trace_user;
} gimbal_app_t;

/* Set up the dispatcher (its counters go to *stats, usually &rx.stats) and
 * the gimbal role on `port` with SYSTEM_VERSION filled in, anchored at
 * now_ms. Returns TASE_OK or the library's error code. */
int gimbal_app_init(gimbal_app_t *app, const tase_port_t *port, tase_rx_stats_t *stats,
                    gimbal_trace_t trace, void *trace_user, uint32_t now_ms);

/* The Mode byte of GIMBAL_RATE (spec 4.2.2, tase/flags.h TASE_MODE_*) of a
 * gimbal obeying a GIMBAL_CMD with these flags: stabilisation from the
 * command, mode position / SPOI / rate (rate and impulse commands), no 3AX
 * (this board has none). */
uint8_t gimbal_mode_byte(uint8_t cmd_flags);

/* The Mode byte this gimbal reports (GIMBAL_RATE, and the flags of its
 * SPOI_CMD answers, PROTOCOL-NOTES P4): stabilised SPOI while it tracks a
 * SPOI, otherwise gimbal_mode_byte() of the last GIMBAL_CMD. */
uint8_t gimbal_mode(const gimbal_app_t *app);

/* Telemetry contents are functions of the poll time t (ms) so that a
 * receiver can check them: pan = 3t mod 18000, tilt = -(t mod 9000). */
int16_t gimbal_sim_pan(uint32_t t);
int16_t gimbal_sim_tilt(uint32_t t);

#endif /* GIMBAL_H */
