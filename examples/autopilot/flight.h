/*
 * flight.h - the autopilot example's flight model and pointing geometry.
 *
 * The aircraft flies a circle at constant height and speed, clockwise
 * seen from above, in a coordinated turn (bank angle atan(v^2 / (g r)),
 * pitch 0, heading along the track). Positions are kept as north/east
 * metres from the circle's centre in single precision (the Cortex-M4F's
 * FPU) and converted to the wire's milli-arcseconds with tase/units.h.
 *
 * Geometry is a flat-earth local tangent plane at the circle's centre
 * (north = dlat * R, east = dlon * R * cos(lat)), R = 6371000 m, which is
 * good to a few hundredths of a degree within a few kilometres; the
 * pointing tolerance of the mission is far wider.
 */
#ifndef AUTOPILOT_FLIGHT_H
#define AUTOPILOT_FLIGHT_H

#include "tase/codec.h"

typedef struct {
    double lat_deg; /* circle centre */
    double lon_deg;
    float height_m; /* flight height above the ellipsoid */
    float radius_m;
    float speed_mps;
} flight_plan_t;

typedef struct {
    float north_m; /* from the centre */
    float east_m;
    float vnorth_mps;
    float veast_mps;
    float roll_deg; /* pitch is 0 */
    float yaw_deg;  /* heading, -180..180 */
} flight_state_t;

/* Where the aircraft is t_ms after the start (at the circle's north point,
 * heading east). */
void flight_at(const flight_plan_t *p, uint32_t t_ms, flight_state_t *s);

/* HOST_GPS_DATA for state s at host time t_ms (the UTC fields count from
 * 2024-06-01 12:00:00 at t = 0), announced at sample_rate per second. */
void flight_gps(const flight_plan_t *p, const flight_state_t *s, uint32_t t_ms, uint8_t sample_rate,
                tase_host_gps_t *g);

/* HOST_ATTITUDE for state s at host time t_ms. */
void flight_attitude(const flight_state_t *s, uint32_t t_ms, uint8_t sample_rate,
                     tase_host_attitude_t *a);

/* A point north_m/east_m from the centre at height_m, as a SPOI_CMD with
 * zero velocity and the given flags. A command: converted with the checked
 * forms of tase/units.h, so a position the wire cannot carry is
 * TASE_ERANGE (c then incomplete: not to be sent), never a saturated one. */
int flight_spoi(const flight_plan_t *p, float north_m, float east_m, float height_m, uint8_t flags,
                tase_spoi_cmd_t *c);

/* North/east metres of a wire position from the centre. */
void flight_offset(const flight_plan_t *p, int32_t lat_mas, int32_t lon_mas, float *north_m,
                   float *east_m);

/* Angle in degrees between the camera line of sight a GEOREFERENCE_DATA
 * reports (camera pitch and yaw from the host position it reports) and
 * the direction from that position to the point `target`. */
float flight_pointing_error_deg(const flight_plan_t *p, const tase_georeference_t *g,
                                const tase_spoi_cmd_t *target);

/* The flight's bank angle in degrees. */
float flight_bank_deg(const flight_plan_t *p);

/* The heading in degrees (-180..180) of an aircraft on the circle at
 * north_m/east_m from its centre: the tangent, turning clockwise. */
float flight_heading_deg(float north_m, float east_m);

/* a - b wrapped to -180..180 degrees. */
float flight_angle_diff_deg(float a, float b);

#endif /* AUTOPILOT_FLIGHT_H */
