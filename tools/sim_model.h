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
 *    horizontal, positive up, -90 = straight down, -180 = horizontal
 *    looking back over the top; wrapped to the spec's [-270, 90)
 *    (TASE_TILT_MIN_DEG..TASE_TILT_MAX_DEG, tase/units.h). The spec's
 *    default tilt no-go zone (centre 90, range 60) therefore forbids
 *    looking more than 60 degrees up, and tilt runs from 60 down through
 *    -90 to -240.
 *  - Camera boresight in body axes: (cos t cos p, cos t sin p, -sin t).
 *  - SPOI geometry is exact WGS-84 in double precision, in one place
 *    (sim_geo_ned()): both points geodetic -> ECEF, their difference
 *    turned into the local North-East-Down frame at the gimbal. Checked
 *    against an independent computation to better than 1e-6 degree from
 *    100 m to 50 km (tests/test_sim_model.c). A moving SPOI is propagated
 *    along the ellipsoid's meridian and prime-vertical radii.
 *
 * NAVIGATION (NAV_SOURCE, spec 4.4.5; docs/PROTOCOL-NOTES.md P10)
 *  - The gimbal has its own GPS/INS solution (own_pos, own_att: the
 *    defaults below, a mount at rest). By default it uses that, for SPOI
 *    and for GEOREFERENCE_DATA/KLV; host data is used only where NAV_SOURCE
 *    selects it: external attitude -> HOST_ATTITUDE, external GPS ->
 *    HOST_GPS_DATA (only packets with Valid 1; an invalid one is dropped).
 *    A HOST_ATTITUDE with the overwrite flag replaces the own attitude
 *    solution whatever NAV_SOURCE says (4.2.4); with the aid-yaw flag its
 *    yaw replaces the own heading. `host` and `att` are the solution in
 *    use, recomputed whenever one of these inputs changes.
 *
 * MOTION
 *  - Rate: the axis turns at the commanded rate, clamped to the axis
 *    maximum. It stops at the edge of a no-go zone.
 *  - Position: proportional control (rate = gain * error, clamped to the
 *    maximum), snapping to the target when within one step. Pan takes
 *    the short way round unless that crosses the no-go zone; a target
 *    inside a no-go zone is moved to the zone's nearest edge.
 *  - Impulse: the commanded rate for impulse_time hundredths of a second,
 *    then the axis holds its position. In SPOI mode an impulse stays in
 *    SPOI and shifts the SPOI pointing error instead, at the commanded
 *    rate for impulse_time (PROTOCOL-NOTES C14: a rate, as outside SPOI).
 *  - SPOI: a position command recomputed every step from the navigation
 *    solution and the SPOI location (propagated by its velocity), plus
 *    the SPOI pointing error (pan, tilt): set by GIMBAL_CMD 0xC0, changed
 *    at the rate set by 0xD0 and shifted by impulses; a new SPOI_CMD
 *    clears it. Outside SPOI the error forms change nothing.
 *  - Retract/deploy: unless the mechanism is deployed (retracted or
 *    moving) the axes hold still: a retract stops them where they are
 *    (position mode, holding), and motion commands and SPOI_CMD are
 *    refused until the deploy completes.
 *  - Acceleration limits are not modelled. Stabilisation is a flag only:
 *    the simulated mount does not move, so there is nothing to reject.
 */
#ifndef TASE_TOOLS_SIM_MODEL_H
#define TASE_TOOLS_SIM_MODEL_H

#include <stdbool.h>
#include <stdint.h>

/* WGS-84 ellipsoid: semi-major axis (m), flattening. */
#define SIM_WGS84_A 6378137.0
#define SIM_WGS84_F (1.0 / 298.257223563)

typedef enum {
    SIM_MODE_RATE = 0,
    SIM_MODE_POSITION = 1,
    SIM_MODE_SPOI = 2,
    SIM_MODE_IMPULSE = 3
} sim_mode_t;

typedef enum { SIM_3AX_DEPLOYED = 0, SIM_3AX_RETRACTED = 1, SIM_3AX_MOVING = 2 } sim_3ax_t;

typedef struct {
    double wrap_lo;     /* positions wrap to [wrap_lo, wrap_lo + 360) */
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

#define SIM_CAMERAS 3u

/* A camera (CAMERA_CMD, CAMERA_PASS, CAMERA_TYPE, SYSTEM_VERSION). */
typedef struct {
    uint8_t type;              /* table 28, 0xFF none */
    double max_hfov, min_hfov; /* deg, the lens */
    double hfov;               /* deg, current */
    uint8_t baud;              /* camera interface, units of 1200 baud */
} sim_camera_t;

typedef struct {
    /* state */
    double pan, tilt;           /* deg */
    double pan_rate, tilt_rate; /* deg/s actually moved during the last step */
    sim_mode_t mode;
    bool stabilised;
    /* command */
    double cmd_pan, cmd_tilt; /* deg (position) or deg/s (rate, impulse) */
    double impulse_left;      /* s */
    /* SPOI pointing error (deg), its rate (deg/s) and an impulse on it */
    double err_pan, err_tilt;
    double err_rate_pan, err_rate_tilt;
    double err_imp_pan, err_imp_tilt; /* deg/s */
    double err_imp_left;              /* s */
    /* settings */
    sim_axis_t axis_pan, axis_tilt;
    /* navigation: sources and the solution in use (NAVIGATION above) */
    sim_pos_t own_pos;
    sim_att_t own_att;
    sim_pos_t gps_in; /* last valid HOST_GPS_DATA */
    sim_att_t att_in; /* last HOST_ATTITUDE */
    bool have_gps_in, have_att_in;
    bool ext_att, ext_gps; /* NAV_SOURCE */
    sim_pos_t host;        /* position in use */
    sim_att_t att;         /* attitude in use */
    sim_pos_t spoi;
    /* cameras */
    sim_camera_t cam[SIM_CAMERAS];
    unsigned active_cam;
    bool pass_through; /* a CAMERA_PASS was sent: CAMERA_CMD is disabled */
    /* retract/deploy mechanism */
    sim_3ax_t tax;
    bool tax_target_deployed;
    bool tax_echo_due;   /* a command for where it already is: echoed at the next step */
    double tax_left;     /* s until the move completes */
    double tax_duration; /* s a full move takes */
} sim_model_t;

/* Defaults of spec table 22: max rate 300 deg/s, gain 4, pan free, tilt
 * no-go centre 90 range 60; gimbal deployed at pan 0, tilt 0, rate mode
 * at rest; own navigation solution at 45 N 0 E 100 m, level, heading
 * north, in use (NAV_SOURCE 0, 0). */
void sim_model_init(sim_model_t *m);

/* What sim_model_command() and sim_model_spoi() did. */
#define SIM_CMD_OK 0           /* followed */
#define SIM_CMD_NOT_SPOI 1     /* SPOI error form outside SPOI: nothing changed */
#define SIM_CMD_NOT_DEPLOYED 2 /* the 3AX is not deployed: held still, nothing changed */
#define SIM_CMD_UNKNOWN (-1)   /* flags value not in table 5: nothing changed */

/* GIMBAL_CMD flags (spec table 5) to a command. pan/tilt in degrees or
 * deg/s, impulse_s in seconds. In SPOI mode an impulse (0x30, 0xB0)
 * shifts the SPOI error and the error forms (0xC0 error, 0xD0 error rate)
 * set it; outside SPOI the error forms return SIM_CMD_NOT_SPOI. Returns
 * one of SIM_CMD_*; state unchanged unless SIM_CMD_OK. */
int sim_model_command(sim_model_t *m, double pan, double tilt, uint8_t flags, double impulse_s);

/* Point at a location (switches to SPOI mode, SPOI error cleared).
 * Returns SIM_CMD_OK, or SIM_CMD_NOT_DEPLOYED (nothing changed). */
int sim_model_spoi(sim_model_t *m, const sim_pos_t *target);

/* Start a retract (deploy = false) or deploy move. A retract stops the
 * axes where they are (position mode holding the current angles). */
void sim_model_retract_deploy(sim_model_t *m, bool deploy);

/* Camera A's lens at start (degrees of HFOV, widest and narrowest). */
#define SIM_CAM_A_MAX_HFOV 57.80
#define SIM_CAM_A_MIN_HFOV 1.70

/* CAMERAS. Camera A a Sony FCB-EX1010 (type 68, HFOV 57.8..1.7 deg),
 * camera B a FLIR Photon 23 deg (type 97), no camera C. Sending a
 * CAMERA_PASS disables the gimbal's camera control (4.1.5): from then on
 * CAMERA_CMD and LEGACY_CAMERA_CMD change nothing until the simulator
 * restarts (its power cycle; PROTOCOL-NOTES C15). */
#define SIM_CAM_OK 0
#define SIM_CAM_NO_CAMERA (-1)    /* no such camera, or type 0xFF there */
#define SIM_CAM_PASS_THROUGH (-2) /* camera control disabled by CAMERA_PASS */
/* CAMERA_CMD: select `camera` (0xFF: keep the active one) and, when
 * set_hfov, set its HFOV: hfov > 0 in degrees, hfov < 0 a zoom ratio
 * (-hfov), clamped to the lens. Returns SIM_CAM_*; nothing changed on an
 * error. */
int sim_model_camera_cmd(sim_model_t *m, unsigned camera, bool set_hfov, double hfov);
/* LEGACY_CAMERA_CMD zoom 0..0x4000 (wide..narrow) on camera A. */
int sim_model_camera_legacy_zoom(sim_model_t *m, unsigned zoom);
/* CAMERA_PASS to `camera` asking baud (units of 1200, 0 = do not change):
 * returns the camera interface's baud in force afterwards (1..255), or
 * SIM_CAM_NO_CAMERA. Disables camera control (above). */
int sim_model_camera_pass(sim_model_t *m, unsigned camera, unsigned baud);
/* CAMERA_TYPE: each type that is not 0 ("do not change") replaces the
 * camera's; a camera added where there was none gets camera A's lens at
 * start, one removed (0xFF) loses its lens (SYSTEM_VERSION: HFOV 0..0, as
 * camera C at start), and an active camera removed hands over to the
 * first that exists (A, B, C). */
void sim_model_camera_types(sim_model_t *m, const uint8_t types[SIM_CAMERAS]);

/* The port index (tase/gimbal.h: index i is PACKET_RATE's port i + 1) of
 * the simulator's link, by PROTOCOL-NOTES A2: a 9600-baud serial link is
 * Com2 (port 1, index 0), any other serial link Com3 (57600 by the spec;
 * port 2, index 1), CAN port 3 (index 2). */
unsigned sim_link_port(bool can, uint32_t baud);

/* Navigation inputs (NAVIGATION above). What happened to host data: */
#define SIM_NAV_USED 0         /* in the solution in use */
#define SIM_NAV_NOT_SELECTED 1 /* kept, but NAV_SOURCE selects the gimbal's own */
#define SIM_NAV_INVALID 2      /* HOST_GPS_DATA with Valid 0: dropped */
#define SIM_NAV_OVERWRITE 3    /* HOST_ATTITUDE overwrite flag: own attitude replaced */
#define SIM_NAV_AID_YAW 4      /* HOST_ATTITUDE aid-yaw flag: own heading replaced */
void sim_model_nav_source(sim_model_t *m, bool external_attitude, bool external_gps);
int sim_model_host_gps(sim_model_t *m, const sim_pos_t *p, bool valid);
int sim_model_host_attitude(sim_model_t *m, const sim_att_t *a, bool overwrite, bool aid_yaw);

/* Advance by dt seconds (0 < dt <= 1). Returns true when a retract/deploy
 * move completed during this step. */
bool sim_model_step(sim_model_t *m, double dt);

/* The vector from `from` to `to` (geodetic, WGS-84) in metres in the
 * local North-East-Down frame at `from`: exact (ECEF difference rotated),
 * double precision. The simulator's one piece of earth geometry. */
void sim_geo_ned(const sim_pos_t *from, const sim_pos_t *to, double ned[3]);

/* Pan/tilt (degrees, conventions above) that points the boresight from
 * the host at the target, given the host attitude. */
void sim_spoi_angles(const sim_pos_t *host, const sim_att_t *att, const sim_pos_t *target,
                     double *pan, double *tilt);

/* Euler angles (roll, pitch, yaw; degrees) of the camera in NED, from the
 * host attitude and the current pan/tilt. */
void sim_model_camera_euler(const sim_model_t *m, double *roll, double *pitch, double *yaw);

/* Wrap an angle to [-180, 180). */
double sim_wrap180(double deg);

/* Measured packet rate: the times (ms) packets were sent, the newest
 * SIM_RATE_NOTES within the last 2 s. */
#define SIM_RATE_NOTES 256u
typedef struct {
    uint32_t t[SIM_RATE_NOTES];
    uint32_t since; /* reset time */
    unsigned n, head;
} sim_rate_meter_t;

/* Start measuring afresh at now_ms (start, or a rate change). */
void sim_rate_reset(sim_rate_meter_t *r, uint32_t now_ms);
/* A packet is sent at now_ms. */
void sim_rate_note(sim_rate_meter_t *r, uint32_t now_ms);
/* Packets per second actually sent, rounded, 0..255: over the packets
 * noted in the last 2 s, (n - 1) * 1000 / (newest - oldest); with one
 * packet, 1000 / (its time - the reset time); 0 with none. */
unsigned sim_rate_hz(const sim_rate_meter_t *r, uint32_t now_ms);

/* A periodic output's next due time after the one due at `due` went out
 * at now_ms: one period later, or, when that has passed too (the
 * simulator was held up: stopped, a loaded machine), one period from now:
 * never a burst of the outputs missed meanwhile. Modulo 2^32. */
uint32_t sim_next_due(uint32_t due, uint32_t now_ms, uint32_t period_ms);

#endif /* TASE_TOOLS_SIM_MODEL_H */
