/*
 * tools/sim_model.h - the physical model behind tase-sim: a two-axis
 * pan/tilt head, a retract/deploy mechanism and the camera geometry.
 *
 * Host-only code (doubles, libm); it knows nothing of the wire. tase-sim
 * converts packet fields to the units used here (degrees, deg/s, seconds,
 * metres) and back.
 *
 * ANGLE CONVENTIONS
 *  - Mount (body) frame: x forward, y right, z down. Host attitude is the
 *    usual aerospace Z-Y-X Euler sequence yaw, pitch, roll from the local
 *    North-East-Down frame to the body frame.
 *  - Pan: rotation about body z, 0 = forward, positive to the right
 *    (clockwise seen from above), wrapped to [-180, 180).
 *  - Tilt: elevation of the boresight above the body x-y plane, 0 =
 *    horizontal, positive up, -90 = straight down; wrapped to [-180, 180).
 *    The spec's default tilt no-go zone (centre 90, range 60) therefore
 *    forbids looking more than 60 degrees up.
 *  - Camera boresight in body axes: (cos t cos p, cos t sin p, -sin t).
 *  - SPOI geometry is a flat-earth local tangent plane at the host:
 *    north = dlat * R, east = dlon * R * cos(lat_host), down = -dheight,
 *    with R = 6371000 m. Good to a few hundredths of a degree within a few
 *    kilometres, which is all a bench simulator needs.
 *
 * MOTION
 *  - Rate: the axis turns at the commanded rate, clamped to the axis
 *    maximum. It stops at the edge of a no-go zone.
 *  - Position: proportional control (rate = gain * error, clamped to the
 *    maximum), snapping to the target when within one step. Pan takes
 *    the short way round unless that crosses the no-go zone; a target
 *    inside a no-go zone is moved to the zone's nearest edge.
 *  - Impulse: the commanded rate for impulse_time hundredths of a second,
 *    then the axis holds its position.
 *  - SPOI: a position command recomputed every step from the latest host
 *    position/attitude and the SPOI location (propagated by its velocity).
 *  - Acceleration limits are not modelled. Stabilisation is a flag only:
 *    the simulated mount does not move, so there is nothing to reject.
 */
#ifndef TASE_TOOLS_SIM_MODEL_H
#define TASE_TOOLS_SIM_MODEL_H

#include <stdbool.h>
#include <stdint.h>

#define SIM_EARTH_RADIUS_M 6371000.0

typedef enum {
    SIM_MODE_RATE = 0,
    SIM_MODE_POSITION = 1,
    SIM_MODE_SPOI = 2,
    SIM_MODE_IMPULSE = 3
} sim_mode_t;

typedef enum { SIM_3AX_DEPLOYED = 0, SIM_3AX_RETRACTED = 1, SIM_3AX_MOVING = 2 } sim_3ax_t;

typedef struct {
    double max_rate;    /* deg/s, > 0 */
    double gain;        /* position gain, (deg/s) per degree of error */
    double nogo_center; /* deg */
    double nogo_range;  /* deg, 0 = free running */
} sim_axis_t;

typedef struct {
    double lat, lon;   /* degrees */
    double height;     /* metres above the ellipsoid */
    double vn, ve, vd; /* m/s */
} sim_pos_t;

typedef struct {
    double roll, pitch, yaw; /* degrees */
} sim_att_t;

typedef struct {
    /* state */
    double pan, tilt;           /* deg */
    double pan_rate, tilt_rate; /* deg/s actually moved during the last step */
    sim_mode_t mode;
    bool stabilised;
    /* command */
    double cmd_pan, cmd_tilt; /* deg (position) or deg/s (rate, impulse) */
    double impulse_left;      /* s */
    /* settings */
    sim_axis_t axis_pan, axis_tilt;
    /* environment */
    sim_pos_t host;
    sim_att_t att;
    sim_pos_t spoi;
    /* retract/deploy mechanism */
    sim_3ax_t tax;
    bool tax_target_deployed;
    double tax_left;     /* s until the move completes */
    double tax_duration; /* s a full move takes */
} sim_model_t;

/* Defaults of spec table 22: max rate 300 deg/s, gain 4, pan free, tilt
 * no-go centre 90 range 60; gimbal deployed at pan 0, tilt 0, rate mode
 * at rest; host at 45 N 0 E 100 m, level, heading north. */
void sim_model_init(sim_model_t *m);

/* GIMBAL_CMD flags (spec table 5) to a command. pan/tilt in degrees or
 * deg/s, impulse_s in seconds. Returns 0 (the model follows it), 1 for the
 * SPOI error forms (flags 0xC0, 0xD0: accepted but not modelled, state
 * unchanged), or -1 for an unknown flags value (state unchanged). */
int sim_model_command(sim_model_t *m, double pan, double tilt, uint8_t flags, double impulse_s);

/* Point at a location (switches to SPOI mode). */
void sim_model_spoi(sim_model_t *m, const sim_pos_t *target);

/* Start a retract (deploy = false) or deploy move. */
void sim_model_retract_deploy(sim_model_t *m, bool deploy);

/* Advance by dt seconds (0 < dt <= 1). Returns true when a retract/deploy
 * move completed during this step. */
bool sim_model_step(sim_model_t *m, double dt);

/* Pan/tilt (degrees, conventions above) that points the boresight from
 * the host at the target, given the host attitude. */
void sim_spoi_angles(const sim_pos_t *host, const sim_att_t *att, const sim_pos_t *target,
                     double *pan, double *tilt);

/* Euler angles (roll, pitch, yaw; degrees) of the camera in NED, from the
 * host attitude and the current pan/tilt. */
void sim_model_camera_euler(const sim_model_t *m, double *roll, double *pitch, double *yaw);

/* Wrap an angle to [-180, 180). */
double sim_wrap180(double deg);

#endif /* TASE_TOOLS_SIM_MODEL_H */
