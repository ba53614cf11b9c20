/*
 * tools/tase_sim.h - what the files of tase-sim share (private to the
 * program): the simulator's state, its log, and the handler of the
 * commands and host data it receives (sim_commands.c). The physics is
 * sim_model.h.
 */
#ifndef TASE_TOOLS_TASE_SIM_H
#define TASE_TOOLS_TASE_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "sim_model.h"
#include "tase/gimbal.h"

typedef struct {
    tase_gimbal_t g;
    tase_rx_t rx[TASE_GIMBAL_PORTS]; /* receivers; only the link's port is present */
    unsigned link;                   /* port index of the link (sim_link_port()) */
    sim_model_t m;
    sim_rate_meter_t georef_rate[TASE_GIMBAL_PORTS]; /* GEOREFERENCE_DATA sent */
    uint32_t t0;                                     /* start, ms */
    int16_t p, q, r; /* host body rates from HOST_SENSOR, 1/100 deg/s */
    bool quiet;
    bool spoi_valid;
    bool version_due;       /* the cameras changed: store SYSTEM_VERSION again */
    int gps_said, att_said; /* what the log last said of HOST_GPS_DATA/_ATTITUDE */
    bool sensor_said;       /* the first HOST_SENSOR was logged */
    /* wrong-length setup packets: the role's count when the log last said
     * so, and when (at most one line a second) */
    uint32_t bad_length_said, bad_length_at;
} sim_t;

/* One line "[seconds] message" on stdout, unless --quiet (tase_sim.c). */
void sim_log(const sim_t *s, uint32_t now, const char *fmt, ...);
/* Send a typed packet on `port`; nobody listening drops it (tase_sim.c). */
void sim_send_packet(sim_t *s, unsigned port, uint16_t id, const void *msg);
/* The gimbal role's handler of the packets that are no setup packet:
 * commands, host data and SPOI_CMD (sim_commands.c). */
void sim_on_frame(void *user, unsigned port, const tase_frame_t *f);

#endif /* TASE_TOOLS_TASE_SIM_H */
