/* The autopilot example's flight model; see flight.h. */
#include "flight.h"

#include <math.h>
#include <string.h>

#include "tase/units.h"

#define EARTH_RADIUS_M 6371000.0
#define PI_F 3.14159265f
#define DEG_PER_RAD 57.2957795130823209
#define G_MPS2 9.80665f

float flight_bank_deg(const flight_plan_t *p)
{
    return atanf(p->speed_mps * p->speed_mps / (G_MPS2 * p->radius_m)) * (180.0f / PI_F);
}

void flight_at(const flight_plan_t *p, uint32_t t_ms, flight_state_t *s)
{
    /* angle round the circle, from north towards east; reduced in whole
     * milliseconds of one lap so that float keeps its precision */
    uint32_t lap_ms = (uint32_t)(2.0f * PI_F * p->radius_m / p->speed_mps * 1000.0f);
    float th = 2.0f * PI_F * (float)(t_ms % lap_ms) / (float)lap_ms;
    float c = cosf(th), sn = sinf(th);

    s->north_m = p->radius_m * c;
    s->east_m = p->radius_m * sn;
    s->vnorth_mps = -p->speed_mps * sn;
    s->veast_mps = p->speed_mps * c;
    s->roll_deg = flight_bank_deg(p);
    s->yaw_deg = flight_heading_deg(s->north_m, s->east_m);
}

float flight_angle_diff_deg(float a, float b)
{
    float d = fmodf(a - b, 360.0f);
    if (d >= 180.0f) {
        d -= 360.0f;
    } else if (d < -180.0f) {
        d += 360.0f;
    }
    return d;
}

float flight_heading_deg(float north_m, float east_m)
{
    return flight_angle_diff_deg(atan2f(east_m, north_m) * (180.0f / PI_F) + 90.0f, 0.0f);
}

static double lat_of(const flight_plan_t *p, float north_m)
{
    return p->lat_deg + (double)north_m / EARTH_RADIUS_M * DEG_PER_RAD;
}

static double lon_of(const flight_plan_t *p, float east_m)
{
    return p->lon_deg +
           (double)east_m / (EARTH_RADIUS_M * cos(p->lat_deg / DEG_PER_RAD)) * DEG_PER_RAD;
}

void flight_gps(const flight_plan_t *p, const flight_state_t *s, uint32_t t_ms, uint8_t sample_rate,
                tase_host_gps_t *g)
{
    uint32_t sec = t_ms / 1000u;
    memset(g, 0, sizeof(*g));
    g->time = t_ms;
    g->lat = tase_units_deg_to_mas(lat_of(p, s->north_m));
    g->lon = tase_units_deg_to_mas(lon_of(p, s->east_m));
    g->height = tase_units_m_to_cm((double)p->height_m);
    g->vnorth = tase_units_mps_to_cmps((double)s->vnorth_mps);
    g->veast = tase_units_mps_to_cmps((double)s->veast_mps);
    g->vdown = 0;
    g->year = 2024u;
    g->month = 6u;
    g->day = 1u;
    g->hour = (uint8_t)(12u + sec / 3600u % 12u);
    g->minute = (uint8_t)(sec / 60u % 60u);
    g->second = (uint8_t)(sec % 60u);
    g->frac_second = (uint8_t)(t_ms % 1000u / 10u);
    g->valid = 1u;
    g->sample_rate = sample_rate;
}

void flight_attitude(const flight_state_t *s, uint32_t t_ms, uint8_t sample_rate,
                     tase_host_attitude_t *a)
{
    memset(a, 0, sizeof(*a));
    a->time = t_ms;
    a->roll = tase_units_deg_to_cdeg((double)s->roll_deg);
    a->pitch = 0;
    a->yaw = tase_units_deg_to_cdeg((double)s->yaw_deg);
    a->flags = 0u;
    a->sample_rate = sample_rate;
}

int flight_spoi(const flight_plan_t *p, float north_m, float east_m, float height_m, uint8_t flags,
                tase_spoi_cmd_t *c)
{
    int r;
    memset(c, 0, sizeof(*c));
    c->flags = flags;
    r = tase_units_deg_to_mas_checked(lat_of(p, north_m), &c->lat);
    if (r == TASE_OK) {
        r = tase_units_deg_to_mas_checked(lon_of(p, east_m), &c->lon);
    }
    if (r == TASE_OK) {
        r = tase_units_m_to_cm_checked((double)height_m, &c->height);
    }
    return r;
}

void flight_offset(const flight_plan_t *p, int32_t lat_mas, int32_t lon_mas, float *north_m,
                   float *east_m)
{
    double dlat = tase_units_mas_to_deg(lat_mas) - p->lat_deg;
    double dlon = tase_units_mas_to_deg(lon_mas) - p->lon_deg;
    *north_m = (float)(dlat / DEG_PER_RAD * EARTH_RADIUS_M);
    *east_m = (float)(dlon / DEG_PER_RAD * EARTH_RADIUS_M * cos(p->lat_deg / DEG_PER_RAD));
}

float flight_pointing_error_deg(const flight_plan_t *p, const tase_georeference_t *g,
                                const tase_spoi_cmd_t *target)
{
    float hn, he, tn, te, v[3], u[3], x[3], dot;
    float pitch = (float)tase_units_cdeg_to_deg(g->camera_pitch) * (PI_F / 180.0f);
    float yaw = (float)tase_units_cdeg_to_deg(g->camera_yaw) * (PI_F / 180.0f);

    flight_offset(p, g->lat, g->lon, &hn, &he);
    flight_offset(p, target->lat, target->lon, &tn, &te);
    v[0] = tn - hn; /* NED, host to target */
    v[1] = te - he;
    v[2] = (float)tase_units_cm_to_m(g->height - target->height);
    u[0] = cosf(pitch) * cosf(yaw); /* boresight: pitch up, yaw from north */
    u[1] = cosf(pitch) * sinf(yaw);
    u[2] = -sinf(pitch);
    x[0] = u[1] * v[2] - u[2] * v[1];
    x[1] = u[2] * v[0] - u[0] * v[2];
    x[2] = u[0] * v[1] - u[1] * v[0];
    dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    return atan2f(sqrtf(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]), dot) * (180.0f / PI_F);
}
