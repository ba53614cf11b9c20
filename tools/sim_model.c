/* The tase-sim physical model; conventions and behaviour in sim_model.h. */
#include "sim_model.h"

#include <math.h>
#include <string.h>

#define DEG (3.14159265358979323846 / 180.0)
#define EDGE_EPS 1e-9

double sim_wrap180(double deg)
{
    double w = fmod(deg + 180.0, 360.0);
    if (w < 0.0) {
        w += 360.0;
    }
    return w - 180.0;
}

static double wrap360(double deg)
{
    double w = fmod(deg, 360.0);
    return w < 0.0 ? w + 360.0 : w;
}

static double clamp(double v, double lim)
{
    return v > lim ? lim : (v < -lim ? -lim : v);
}

static bool in_nogo(const sim_axis_t *ax, double pos)
{
    return ax->nogo_range > 0.0 &&
           fabs(sim_wrap180(pos - ax->nogo_center)) < ax->nogo_range / 2.0 - EDGE_EPS;
}

/* Distance travelled in direction dir (+1/-1) from pos before entering the
 * no-go zone. An axis already inside the zone (settings changed under it)
 * may leave it freely, so that case reports no obstacle. */
static double nogo_distance(const sim_axis_t *ax, double pos, double dir)
{
    if (ax->nogo_range <= 0.0 || in_nogo(ax, pos)) {
        return HUGE_VAL;
    }
    return wrap360(dir * (ax->nogo_center - dir * ax->nogo_range / 2.0 - pos));
}

/* Move by delta degrees, stopping at a no-go edge. Returns the distance
 * actually moved (signed). */
static double axis_move(const sim_axis_t *ax, double *pos, double delta)
{
    double dir = delta >= 0.0 ? 1.0 : -1.0;
    double room = nogo_distance(ax, *pos, dir);
    if (fabs(delta) > room) {
        delta = dir * room;
    }
    *pos = sim_wrap180(*pos + delta);
    return delta;
}

static double axis_position_step(const sim_axis_t *ax, double *pos, double target, double dt)
{
    double err, dir, step;
    if (in_nogo(ax, target)) {
        double off = sim_wrap180(target - ax->nogo_center);
        target = ax->nogo_center + (off >= 0.0 ? 1.0 : -1.0) * ax->nogo_range / 2.0;
    }
    err = sim_wrap180(target - *pos);
    dir = err >= 0.0 ? 1.0 : -1.0;
    if (nogo_distance(ax, *pos, dir) < fabs(err) - EDGE_EPS) {
        err -= dir * 360.0; /* the short way is blocked: go round */
    }
    step = clamp(ax->gain * err, ax->max_rate) * dt;
    if (fabs(step) >= fabs(err)) {
        step = err;
    }
    return axis_move(ax, pos, step);
}

void sim_model_init(sim_model_t *m)
{
    static const sim_axis_t pan = {300.0, 4.0, 0.0, 0.0};
    static const sim_axis_t tilt = {300.0, 4.0, 90.0, 60.0};
    memset(m, 0, sizeof(*m));
    m->axis_pan = pan;
    m->axis_tilt = tilt;
    m->mode = SIM_MODE_RATE;
    m->host.lat = 45.0;
    m->host.height = 100.0;
    m->tax = SIM_3AX_DEPLOYED;
    m->tax_target_deployed = true;
    m->tax_duration = 2.0;
}

int sim_model_command(sim_model_t *m, double pan, double tilt, uint8_t flags, double impulse_s)
{
    sim_mode_t mode;
    bool stab;
    switch (flags) {
    case 0x00:
    case 0x02:
    case 0x10:
    case 0x90: mode = SIM_MODE_RATE; break;
    case 0x01:
    case 0x03:
    case 0x20:
    case 0xA0: mode = SIM_MODE_POSITION; break;
    case 0x30:
    case 0xB0: mode = SIM_MODE_IMPULSE; break;
    case 0xC0:
    case 0xD0: return 1; /* SPOI error forms: not modelled */
    default: return -1;
    }
    stab = (flags & 0x80u) != 0 || flags == 0x02 || flags == 0x03;
    m->mode = mode;
    m->stabilised = stab;
    m->cmd_pan = pan;
    m->cmd_tilt = tilt;
    m->impulse_left = mode == SIM_MODE_IMPULSE ? impulse_s : 0.0;
    return 0;
}

void sim_model_spoi(sim_model_t *m, const sim_pos_t *target)
{
    m->spoi = *target;
    m->mode = SIM_MODE_SPOI;
}

void sim_model_retract_deploy(sim_model_t *m, bool deploy)
{
    bool there = m->tax != SIM_3AX_MOVING && m->tax_target_deployed == deploy;
    m->tax_target_deployed = deploy;
    m->tax = SIM_3AX_MOVING;
    m->tax_left = there ? 0.0 : m->tax_duration;
}

static void propagate(sim_pos_t *p, double dt)
{
    p->lat += p->vn * dt / SIM_EARTH_RADIUS_M / DEG;
    p->lon += p->ve * dt / (SIM_EARTH_RADIUS_M * cos(p->lat * DEG)) / DEG;
    p->height -= p->vd * dt;
}

bool sim_model_step(sim_model_t *m, double dt)
{
    double dp = 0.0, dtl = 0.0, mdt = dt;
    bool done = false;
    bool rate_mode = m->mode == SIM_MODE_RATE;
    if (m->mode == SIM_MODE_IMPULSE && m->impulse_left > 0.0) {
        /* an impulse is a rate held for a limited time */
        if (mdt > m->impulse_left) {
            mdt = m->impulse_left;
        }
        m->impulse_left -= mdt;
        rate_mode = true;
    }
    if (rate_mode) {
        dp = axis_move(&m->axis_pan, &m->pan, clamp(m->cmd_pan, m->axis_pan.max_rate) * mdt);
        dtl = axis_move(&m->axis_tilt, &m->tilt, clamp(m->cmd_tilt, m->axis_tilt.max_rate) * mdt);
    } else if (m->mode == SIM_MODE_POSITION || m->mode == SIM_MODE_SPOI) {
        if (m->mode == SIM_MODE_SPOI) {
            propagate(&m->spoi, dt);
            sim_spoi_angles(&m->host, &m->att, &m->spoi, &m->cmd_pan, &m->cmd_tilt);
        }
        dp = axis_position_step(&m->axis_pan, &m->pan, m->cmd_pan, dt);
        dtl = axis_position_step(&m->axis_tilt, &m->tilt, m->cmd_tilt, dt);
    }
    m->pan_rate = dt > 0.0 ? dp / dt : 0.0;
    m->tilt_rate = dt > 0.0 ? dtl / dt : 0.0;
    if (m->tax == SIM_3AX_MOVING) {
        m->tax_left -= dt;
        if (m->tax_left <= 0.0) {
            m->tax = m->tax_target_deployed ? SIM_3AX_DEPLOYED : SIM_3AX_RETRACTED;
            done = true;
        }
    }
    return done;
}

typedef double mat3[3][3];

/* NED -> body direction cosine matrix for Z-Y-X Euler angles (degrees). */
static void dcm_body_from_ned(const sim_att_t *a, mat3 c)
{
    double cr = cos(a->roll * DEG), sr = sin(a->roll * DEG);
    double cp = cos(a->pitch * DEG), sp = sin(a->pitch * DEG);
    double cy = cos(a->yaw * DEG), sy = sin(a->yaw * DEG);
    c[0][0] = cp * cy;
    c[0][1] = cp * sy;
    c[0][2] = -sp;
    c[1][0] = sr * sp * cy - cr * sy;
    c[1][1] = sr * sp * sy + cr * cy;
    c[1][2] = sr * cp;
    c[2][0] = cr * sp * cy + sr * sy;
    c[2][1] = cr * sp * sy - sr * cy;
    c[2][2] = cr * cp;
}

void sim_spoi_angles(const sim_pos_t *host, const sim_att_t *att, const sim_pos_t *target,
                     double *pan, double *tilt)
{
    mat3 c;
    double n[3], b[3];
    int i;
    n[0] = (target->lat - host->lat) * DEG * SIM_EARTH_RADIUS_M;
    n[1] = sim_wrap180(target->lon - host->lon) * DEG * SIM_EARTH_RADIUS_M * cos(host->lat * DEG);
    n[2] = host->height - target->height;
    dcm_body_from_ned(att, c);
    for (i = 0; i < 3; i++) {
        b[i] = c[i][0] * n[0] + c[i][1] * n[1] + c[i][2] * n[2];
    }
    *pan = atan2(b[1], b[0]) / DEG;
    *tilt = atan2(-b[2], sqrt(b[0] * b[0] + b[1] * b[1])) / DEG;
}

void sim_model_camera_euler(const sim_model_t *m, double *roll, double *pitch, double *yaw)
{
    /* camera -> NED = (NED -> body)^T * (camera -> body); camera -> body is
     * a yaw by pan then a pitch by tilt. */
    sim_att_t cam = {0.0, 0.0, 0.0};
    mat3 bn, cb, cn;
    int i, j, k;
    cam.pitch = m->tilt;
    cam.yaw = m->pan;
    dcm_body_from_ned(&m->att, bn);
    dcm_body_from_ned(&cam, cb); /* body -> camera */
    for (i = 0; i < 3; i++) {
        for (j = 0; j < 3; j++) {
            cn[i][j] = 0.0; /* NED -> camera = (body -> camera)(NED -> body) */
            for (k = 0; k < 3; k++) {
                cn[i][j] += cb[i][k] * bn[k][j];
            }
        }
    }
    *yaw = atan2(cn[0][1], cn[0][0]) / DEG;
    *pitch = asin(clamp(-cn[0][2], 1.0)) / DEG;
    *roll = atan2(cn[1][2], cn[2][2]) / DEG;
}
