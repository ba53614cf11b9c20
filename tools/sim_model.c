/* The tase-sim physical model; conventions and behaviour in sim_model.h. */
#include "sim_model.h"

#include <math.h>
#include <string.h>

#include "tase/flags.h"
#include "tase/units.h"

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

/* deg wrapped to [lo, lo + 360) */
static double wrap_from(double deg, double lo)
{
    return lo + wrap360(deg - lo);
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
 * may leave it freely, so that case reports no obstacle; a zone of the
 * whole turn has no outside, and stops it where it is. */
static double nogo_distance(const sim_axis_t *ax, double pos, double dir)
{
    if (ax->nogo_range >= 360.0) {
        return 0.0; /* the whole turn is no-go (4.4.3's 360): nowhere to go */
    }
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
    *pos = wrap_from(*pos + delta, ax->wrap_lo);
    return delta;
}

/* A position step towards target: the gain on the error plus ff (deg/s:
 * the rate at which the target moved during this step, 0 for a fixed
 * one), within the max rate. */
static double axis_position_step(const sim_axis_t *ax, double *pos, double target, double ff,
                                 double dt)
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
    /* the gain on the error from where the target was at the start of the
     * step (err - ff * dt), ff for its motion during it: a target moving
     * steadily is followed with no error left (the gain on err itself
     * leaves one step of motion behind) */
    step = clamp(ax->gain * (err - ff * dt) + ff, ax->max_rate) * dt;
    if (ff == 0.0 && fabs(step) >= fabs(err)) {
        step = err;
    }
    return axis_move(ax, pos, step);
}

void sim_model_init(sim_model_t *m)
{
    static const sim_axis_t pan = {TASE_PAN_MIN_DEG, 300.0, 4.0, 0.0, 0.0};
    static const sim_axis_t tilt = {TASE_TILT_MIN_DEG, 300.0, 4.0, 90.0, 60.0};
    memset(m, 0, sizeof(*m));
    m->axis_pan = pan;
    m->axis_tilt = tilt;
    m->mode = SIM_MODE_RATE;
    m->own_pos.lat = 45.0;
    m->own_pos.height = 100.0;
    m->host = m->own_pos;
    m->tax = SIM_3AX_DEPLOYED;
    m->tax_target_deployed = true;
    m->tax_duration = 2.0;
    m->cam[0].type = 68; /* SONY_FCB_EX1010, 36x optical zoom */
    m->cam[0].max_hfov = SIM_CAM_A_MAX_HFOV;
    m->cam[0].min_hfov = SIM_CAM_A_MIN_HFOV;
    m->cam[0].hfov = SIM_CAM_A_MAX_HFOV;
    m->cam[0].baud = 8;  /* 9600, VISCA */
    m->cam[1].type = 97; /* FLIR_320_PHOTON_23 */
    m->cam[1].max_hfov = 23.0;
    m->cam[1].min_hfov = 23.0;
    m->cam[1].hfov = 23.0;
    m->cam[1].baud = 8;
    m->cam[2].type = TASE_CAMTYPE_NONE;
}

/* ---- cameras ---- */

static bool camera_present(const sim_model_t *m, unsigned camera)
{
    return camera < SIM_CAMERAS && m->cam[camera].type != TASE_CAMTYPE_NONE;
}

int sim_model_camera_cmd(sim_model_t *m, unsigned camera, bool set_hfov, double hfov)
{
    sim_camera_t *c;
    if (m->pass_through) {
        return SIM_CAM_PASS_THROUGH;
    }
    if (camera != TASE_CAMERA_NO_CHANGE) {
        if (!camera_present(m, camera)) {
            return SIM_CAM_NO_CAMERA;
        }
        m->active_cam = camera;
    } else if (!camera_present(m, m->active_cam)) {
        return SIM_CAM_NO_CAMERA; /* CAMERA_TYPE removed every camera */
    } else {
        /* the active camera */
    }
    c = &m->cam[m->active_cam];
    if (set_hfov) {
        /* a zoom ratio r (negative hfov) is the focal length's: tan(h/2)
         * shrinks by r (GEOREFERENCE_DATA's focal length is then r times
         * the widest's; max_hfov / r was 2.141x at 2x) */
        double h = hfov > 0.0   ? hfov
                   : hfov < 0.0 ? 2.0 * atan(tan(c->max_hfov * DEG / 2.0) / -hfov) / DEG
                                : c->max_hfov;
        c->hfov = h < c->min_hfov ? c->min_hfov : (h > c->max_hfov ? c->max_hfov : h);
    }
    return SIM_CAM_OK;
}

int sim_model_camera_legacy_zoom(sim_model_t *m, unsigned zoom)
{
    sim_camera_t *c = &m->cam[0];
    double z = (zoom > 0x4000u ? 0x4000u : zoom) / 16384.0;
    if (m->pass_through) {
        return SIM_CAM_PASS_THROUGH;
    }
    if (!camera_present(m, 0u)) {
        return SIM_CAM_NO_CAMERA; /* it has no lens: the HFOV was NaN */
    }
    c->hfov = c->max_hfov * pow(c->min_hfov / c->max_hfov, z);
    return SIM_CAM_OK;
}

int sim_model_camera_pass(sim_model_t *m, unsigned camera, unsigned baud)
{
    if (!camera_present(m, camera)) {
        return SIM_CAM_NO_CAMERA;
    }
    if (baud != 0u) {
        m->cam[camera].baud = (uint8_t)(baud > 255u ? 255u : baud);
    }
    m->pass_through = true;
    return m->cam[camera].baud;
}

void sim_model_camera_types(sim_model_t *m, const uint8_t types[SIM_CAMERAS])
{
    unsigned i;
    for (i = 0; i < SIM_CAMERAS; i++) {
        sim_camera_t *c = &m->cam[i];
        if (types[i] == TASE_CAMTYPE_NO_CHANGE) {
            continue;
        }
        if (types[i] == TASE_CAMTYPE_NONE) {
            memset(c, 0, sizeof(*c)); /* no lens, as camera C at start */
        } else if (c->type == TASE_CAMTYPE_NONE) {
            /* a new camera: camera A's lens at start, at its widest */
            c->max_hfov = SIM_CAM_A_MAX_HFOV;
            c->min_hfov = SIM_CAM_A_MIN_HFOV;
            c->hfov = c->max_hfov;
            c->baud = 8;
        } else {
            /* another type in the same place: the lens stays */
        }
        c->type = types[i];
    }
    /* the active camera is one that exists: the first there is */
    for (i = 0; i < SIM_CAMERAS && !camera_present(m, m->active_cam); i++) {
        if (camera_present(m, i)) {
            m->active_cam = i;
        }
    }
}

unsigned sim_link_port(bool can, uint32_t baud)
{
    return can ? 2u : (baud == 9600u ? 0u : 1u);
}

int sim_model_command(sim_model_t *m, double pan, double tilt, uint8_t flags, double impulse_s)
{
    sim_mode_t mode;
    bool stab = (flags & 0x80u) != 0 || flags == 0x02 || flags == 0x03;
    bool spoi = m->mode == SIM_MODE_SPOI;
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
    case 0xD0: mode = SIM_MODE_SPOI; break;
    default: return SIM_CMD_UNKNOWN;
    }
    if (m->tax != SIM_3AX_DEPLOYED) {
        return SIM_CMD_NOT_DEPLOYED;
    }
    if (mode == SIM_MODE_SPOI && !spoi) {
        return SIM_CMD_NOT_SPOI; /* "if sensor point of interest is on" */
    }
    m->stabilised = stab;
    if (spoi && mode == SIM_MODE_IMPULSE) {
        /* shifts the SPOI error and stays in SPOI (4.1.1) */
        m->err_imp_pan = pan;
        m->err_imp_tilt = tilt;
        m->err_imp_left = impulse_s;
    } else if (flags == 0xC0) {
        m->err_pan = pan;
        m->err_tilt = tilt;
    } else if (flags == 0xD0) {
        m->err_rate_pan = pan;
        m->err_rate_tilt = tilt;
    } else {
        m->mode = mode;
        m->cmd_pan = pan;
        m->cmd_tilt = tilt;
        m->impulse_left = mode == SIM_MODE_IMPULSE ? impulse_s : 0.0;
    }
    return SIM_CMD_OK;
}

int sim_model_spoi(sim_model_t *m, const sim_pos_t *target)
{
    if (m->tax != SIM_3AX_DEPLOYED) {
        return SIM_CMD_NOT_DEPLOYED;
    }
    m->spoi = *target;
    m->mode = SIM_MODE_SPOI;
    m->err_pan = m->err_tilt = 0.0;
    m->err_rate_pan = m->err_rate_tilt = 0.0;
    m->err_imp_left = 0.0;
    return SIM_CMD_OK;
}

void sim_model_retract_deploy(sim_model_t *m, bool deploy)
{
    bool there = m->tax != SIM_3AX_MOVING && m->tax_target_deployed == deploy;
    if (!deploy) {
        /* hold still where the axes are, now and once deployed again */
        m->mode = SIM_MODE_POSITION;
        m->cmd_pan = m->pan;
        m->cmd_tilt = m->tilt;
        m->impulse_left = 0.0;
    }
    m->tax_target_deployed = deploy;
    if (there) {
        /* already there: echoed at once, never "moving" (a deploy sent to
         * a deployed gimbal dropped the command sent right after it) */
        m->tax_echo_due = true;
        return;
    }
    m->tax = SIM_3AX_MOVING;
    m->tax_left = m->tax_duration;
}

/* The solution in use from the sources (NAVIGATION in sim_model.h). */
static void nav_resolve(sim_model_t *m)
{
    m->host = m->ext_gps && m->have_gps_in ? m->gps_in : m->own_pos;
    m->att = m->ext_att && m->have_att_in ? m->att_in : m->own_att;
}

void sim_model_nav_source(sim_model_t *m, bool external_attitude, bool external_gps)
{
    m->ext_att = external_attitude;
    m->ext_gps = external_gps;
    nav_resolve(m);
}

int sim_model_host_gps(sim_model_t *m, const sim_pos_t *p, bool valid)
{
    if (!valid) {
        return SIM_NAV_INVALID;
    }
    m->gps_in = *p;
    m->have_gps_in = true;
    nav_resolve(m);
    return m->ext_gps ? SIM_NAV_USED : SIM_NAV_NOT_SELECTED;
}

int sim_model_host_attitude(sim_model_t *m, const sim_att_t *a, bool overwrite, bool aid_yaw)
{
    int r = m->ext_att ? SIM_NAV_USED : SIM_NAV_NOT_SELECTED;
    m->att_in = *a;
    m->have_att_in = true;
    if (overwrite) {
        m->own_att = *a;
        r = m->ext_att ? r : SIM_NAV_OVERWRITE;
    } else if (aid_yaw) {
        m->own_att.yaw = a->yaw;
        r = m->ext_att ? r : SIM_NAV_AID_YAW;
    }
    nav_resolve(m);
    return r;
}

/* ---- WGS-84 geometry: the one place the simulator models the earth ---- */

#define WGS84_E2 (SIM_WGS84_F * (2.0 - SIM_WGS84_F)) /* first eccentricity squared */

/* Prime-vertical radius of curvature at geodetic latitude phi (rad). */
static double wgs84_n(double phi)
{
    double s = sin(phi);
    return SIM_WGS84_A / sqrt(1.0 - WGS84_E2 * s * s);
}

static void wgs84_ecef(const sim_pos_t *p, double x[3])
{
    double phi = p->lat * DEG, lam = p->lon * DEG, n = wgs84_n(phi);
    x[0] = (n + p->height) * cos(phi) * cos(lam);
    x[1] = (n + p->height) * cos(phi) * sin(lam);
    x[2] = (n * (1.0 - WGS84_E2) + p->height) * sin(phi);
}

void sim_geo_ned(const sim_pos_t *from, const sim_pos_t *to, double ned[3])
{
    double a[3], b[3], d[3];
    double phi = from->lat * DEG, lam = from->lon * DEG;
    double sp = sin(phi), cp = cos(phi), sl = sin(lam), cl = cos(lam);
    int i;
    wgs84_ecef(from, a);
    wgs84_ecef(to, b);
    for (i = 0; i < 3; i++) {
        d[i] = b[i] - a[i];
    }
    ned[0] = -sp * cl * d[0] - sp * sl * d[1] + cp * d[2];
    ned[1] = -sl * d[0] + cl * d[1];
    ned[2] = -cp * cl * d[0] - cp * sl * d[1] - sp * d[2];
}

/* Move a point by its velocity for dt seconds along the ellipsoid's
 * meridian (M) and prime-vertical (N) radii at its height. */
static void propagate(sim_pos_t *p, double dt)
{
    double phi = p->lat * DEG, n = wgs84_n(phi), s = sin(phi);
    double mr = SIM_WGS84_A * (1.0 - WGS84_E2) / pow(1.0 - WGS84_E2 * s * s, 1.5);
    p->lat += p->vn * dt / (mr + p->height) / DEG;
    p->lon = sim_wrap180(p->lon + p->ve * dt / ((n + p->height) * cos(phi)) / DEG);
    p->height -= p->vd * dt;
    if (fabs(p->lat) > 90.0) {
        /* over a pole: down the meridian on the other side, the velocity
         * the same in space (north and east both turn round there); a
         * latitude above 90 went out in SPOI_CMD's echo */
        p->lat = (p->lat > 0.0 ? 180.0 : -180.0) - p->lat;
        p->lon = sim_wrap180(p->lon + 180.0);
        p->vn = -p->vn;
        p->ve = -p->ve;
    }
}

/* ---- motion ---- */

/* The SPOI error advances by its rate and by an impulse in progress,
 * each bounded by the axis's max rate like every other rate command
 * (PROTOCOL-NOTES C14: an impulse moves as far in SPOI as outside it; it
 * moved ten times as far with a 10 deg/s max rate and 100 deg/s sent). */
static void spoi_error_step(sim_model_t *m, double dt)
{
    double idt = dt < m->err_imp_left ? dt : m->err_imp_left;
    m->err_pan += clamp(m->err_rate_pan, m->axis_pan.max_rate) * dt;
    m->err_tilt += clamp(m->err_rate_tilt, m->axis_tilt.max_rate) * dt;
    if (idt > 0.0) {
        m->err_pan += clamp(m->err_imp_pan, m->axis_pan.max_rate) * idt;
        m->err_tilt += clamp(m->err_imp_tilt, m->axis_tilt.max_rate) * idt;
        m->err_imp_left -= idt;
    }
}

bool sim_model_step(sim_model_t *m, double dt)
{
    double dp = 0.0, dtl = 0.0, mdt = dt;
    double ff_pan = 0.0, ff_tilt = 0.0;
    bool done = false;
    bool rate_mode = m->mode == SIM_MODE_RATE;
    bool deployed = m->tax == SIM_3AX_DEPLOYED;
    if (m->mode == SIM_MODE_IMPULSE && m->impulse_left > 0.0) {
        /* an impulse is a rate held for a limited time */
        if (mdt > m->impulse_left) {
            mdt = m->impulse_left;
        }
        m->impulse_left -= mdt;
        rate_mode = true;
    }
    if (m->mode == SIM_MODE_SPOI) {
        /* the target's angles before and after this step's motion (its
         * velocity, the SPOI error's rate and impulse), from the same
         * host position and attitude: how fast the line of sight turns
         * by the target's own motion is fed forward, so that a moving
         * target is tracked without the lag of the position loop alone
         * (rate / gain: 5 deg behind a target crossing at 200 m/s). A
         * host that jumps (a new HOST_GPS_DATA) is not fed forward. */
        double p0, t0;
        sim_spoi_angles(&m->host, &m->att, &m->spoi, &p0, &t0);
        p0 += m->err_pan;
        t0 += m->err_tilt;
        propagate(&m->spoi, dt);
        spoi_error_step(m, dt);
        sim_spoi_angles(&m->host, &m->att, &m->spoi, &m->cmd_pan, &m->cmd_tilt);
        m->cmd_pan += m->err_pan;
        m->cmd_tilt += m->err_tilt;
        if (dt > 0.0) {
            ff_pan = sim_wrap180(m->cmd_pan - p0) / dt;
            ff_tilt = sim_wrap180(m->cmd_tilt - t0) / dt;
        }
    }
    if (!deployed) {
        /* retracted or moving: the axes hold still */
    } else if (rate_mode) {
        dp = axis_move(&m->axis_pan, &m->pan, clamp(m->cmd_pan, m->axis_pan.max_rate) * mdt);
        dtl = axis_move(&m->axis_tilt, &m->tilt, clamp(m->cmd_tilt, m->axis_tilt.max_rate) * mdt);
    } else if (m->mode == SIM_MODE_POSITION || m->mode == SIM_MODE_SPOI) {
        dp = axis_position_step(&m->axis_pan, &m->pan, m->cmd_pan, ff_pan, dt);
        dtl = axis_position_step(&m->axis_tilt, &m->tilt, m->cmd_tilt, ff_tilt, dt);
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
    if (m->tax_echo_due) {
        m->tax_echo_due = false;
        done = true;
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
    sim_geo_ned(host, target, n);
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

/* ---- measured packet rate ---- */

void sim_rate_reset(sim_rate_meter_t *r, uint32_t now_ms)
{
    r->n = 0;
    r->head = 0;
    r->since = now_ms;
}

void sim_rate_note(sim_rate_meter_t *r, uint32_t now_ms)
{
    r->t[r->head] = now_ms;
    r->head = (r->head + 1u) % SIM_RATE_NOTES;
    if (r->n < SIM_RATE_NOTES) {
        r->n++;
    }
}

unsigned sim_rate_hz(const sim_rate_meter_t *r, uint32_t now_ms)
{
    unsigned i, n = 0;
    uint32_t newest = 0, oldest = 0;
    double hz;
    for (i = 0; i < r->n; i++) {
        uint32_t t = r->t[(r->head + SIM_RATE_NOTES - 1u - i) % SIM_RATE_NOTES];
        if ((uint32_t)(now_ms - t) > 2000u) {
            break; /* newest first: the rest are older still */
        }
        if (n++ == 0) {
            newest = t;
        }
        oldest = t;
    }
    if (n == 0) {
        return 0;
    }
    if (n == 1) {
        uint32_t span = newest - r->since;
        hz = span == 0u ? 255.0 : 1000.0 / span;
    } else {
        hz = (n - 1u) * 1000.0 / (newest - oldest == 0u ? 1u : newest - oldest);
    }
    hz = floor(hz + 0.5);
    return hz > 255.0 ? 255u : (unsigned)hz;
}

uint32_t sim_next_due(uint32_t due, uint32_t now_ms, uint32_t period_ms)
{
    uint32_t next = due + period_ms;
    return ((int32_t)(now_ms - next) >= 0) ? now_ms + period_ms : next;
}
