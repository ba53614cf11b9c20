/* tase-sim: the commands and host data it receives (GIMBAL_CMD, cameras,
 * retract/deploy, host sensors and navigation, SPOI_CMD), applied to the
 * model (sim_model.h) and logged. */
#include <string.h>

#include "sim_words.h"
#include "tase/codec.h"
#include "tase/flags.h"
#include "tase/posix_uart.h"
#include "tase/units.h"
#include "tase_sim.h"

/* ---- commands and host data ---- */

/* SPOI_CMD from the gimbal: the SPOI in force (zeros before the first)
 * and the gimbal's own flags (stabilisation and mode). */
static void send_spoi(sim_t *s, unsigned port)
{
    tase_spoi_cmd_t a;
    memset(&a, 0, sizeof(a));
    if (s->spoi_valid) {
        a.lat = tase_units_deg_to_mas(s->m.spoi.lat);
        a.lon = tase_units_deg_to_mas(s->m.spoi.lon);
        a.height = tase_units_m_to_cm(s->m.spoi.height);
        a.vnorth = tase_units_sat_i16(s->m.spoi.vn * 100.0);
        a.veast = tase_units_sat_i16(s->m.spoi.ve * 100.0);
        a.vdown = tase_units_sat_i16(s->m.spoi.vd * 100.0);
    }
    a.flags = sim_spoi_flags(&s->m);
    sim_send_packet(s, port, TASE_ID_SPOI_CMD, &a);
}

static const char *mode_name(const sim_model_t *m)
{
    static const char *const names[] = {"rate", "position", "SPOI", "impulse"};
    return names[m->mode];
}

static const char *camera_refusal(int rc)
{
    return rc == SIM_CAM_PASS_THROUGH ? "camera control is disabled since a CAMERA_PASS (4.1.5) "
                                        "until tase-sim restarts"
                                      : "no such camera";
}

static void camera_cmd(sim_t *s, const tase_camera_cmd_t *c, int len, uint32_t now)
{
    bool set_hfov = len > 1 && c->hfov != TASE_HFOV_NO_CHANGE;
    int rc = sim_model_camera_cmd(&s->m, c->camera, set_hfov, c->hfov / 100.0);
    if (rc != SIM_CAM_OK) {
        sim_log(s, now, "CAMERA_CMD (camera %u) ignored: %s", (unsigned)c->camera,
                camera_refusal(rc));
        return;
    }
    sim_log(s, now, "CAMERA_CMD: camera %c, HFOV %.2f deg", 'A' + (int)s->m.active_cam,
            s->m.cam[s->m.active_cam].hfov);
}

static void camera_pass(sim_t *s, unsigned port, const tase_camera_pass_t *c, uint32_t now)
{
    tase_camera_pass_t a = *c;
    int baud = sim_model_camera_pass(&s->m, c->camera, c->baud);
    if (baud < 0) {
        sim_log(s, now, "CAMERA_PASS to camera %u ignored: no such camera", (unsigned)c->camera);
        return;
    }
    /* the simulated camera answers by echoing what it was sent; packets
     * from the gimbal carry the interface's current baud */
    a.baud = (uint8_t)baud;
    sim_send_packet(s, port, TASE_ID_CAMERA_PASS, &a);
    sim_log(s, now,
            "CAMERA_PASS: %u bytes echoed by camera %u at %u baud; camera control disabled until "
            "tase-sim restarts",
            c->len, c->camera, 1200u * (unsigned)baud);
}

static const char *const not_deployed =
    "the gimbal is not deployed; it holds still until a deploy completes";

/* Log what happened to host navigation data when it changes (these
 * packets come at 10-50 per second). */
static void nav_said(sim_t *s, uint32_t now, int *said, int rc, const char *what)
{
    static const char *const how[] = {
        "used", "ignored: NAV_SOURCE selects the gimbal's own GPS/INS", "ignored: Valid is not 1",
        "overwrote the gimbal's own attitude solution", "aided the gimbal's own heading"};
    if (rc != *said) {
        sim_log(s, now, "%s: %s", what, how[rc]);
        *said = rc;
    }
}

/* A position and velocity in wire units (mas, cm, cm/s) in the model's. */
static sim_pos_t wire_pos(int32_t lat, int32_t lon, int32_t height, int16_t vn, int16_t ve,
                          int16_t vd)
{
    sim_pos_t p;
    p.lat = tase_units_mas_to_deg(lat);
    p.lon = tase_units_mas_to_deg(lon);
    p.height = tase_units_cm_to_m(height);
    p.vn = tase_units_cmps_to_mps(vn);
    p.ve = tase_units_cmps_to_mps(ve);
    p.vd = tase_units_cmps_to_mps(vd);
    return p;
}

void sim_on_frame(void *user, unsigned port, const tase_frame_t *f)
{
    sim_t *s = user;
    tase_packet_msg_t msg;
    uint16_t id = TASE_ID(f->group, f->type);
    uint32_t now = tase_posix_now_ms();
    int len = tase_packet_decode(f, &msg);
    if (len < 0) {
        sim_log(s, now, "ignored frame 0x%02X/0x%02X (%u bytes): %s", f->group, f->type,
                (unsigned)f->len, tase_strerror(len));
        return;
    }
    switch (id) {
    case TASE_ID_GIMBAL_CMD: {
        const tase_gimbal_cmd_t *c = &msg.gimbal_cmd;
        bool spoi = s->m.mode == SIM_MODE_SPOI;
        tase_gimbal_cmd_t flags_only = *c;
        int rc;
        flags_only.pan = 0;
        flags_only.tilt = 0;
        if (tase_command_check(TASE_ID_GIMBAL_CMD, c) != TASE_OK &&
            tase_command_check(TASE_ID_GIMBAL_CMD, &flags_only) == TASE_OK) {
            /* flags of table 5, a position beyond the axes (G8): a
             * gimbal must not move on it (wrapped, 200 deg went to -160) */
            sim_log(s, now,
                    "GIMBAL_CMD (flags 0x%02X, pan %.2f tilt %.2f) refused: a position beyond the "
                    "axes' ranges (pan %d..%d, tilt %d..%d deg); still in %s mode",
                    c->flags, c->pan / 100.0, c->tilt / 100.0, TASE_PAN_MIN_CDEG / 100,
                    TASE_PAN_MAX_CDEG / 100, TASE_TILT_MIN_CDEG / 100, TASE_TILT_MAX_CDEG / 100,
                    mode_name(&s->m));
            break;
        }
        rc = sim_model_command(&s->m, c->pan / 100.0, c->tilt / 100.0, c->flags,
                               c->impulse_time / 100.0);
        if (rc == SIM_CMD_UNKNOWN) {
            sim_log(s, now, "GIMBAL_CMD: unknown flags 0x%02X ignored", c->flags);
        } else if (rc == SIM_CMD_NOT_DEPLOYED) {
            sim_log(s, now, "GIMBAL_CMD (flags 0x%02X, pan %.2f tilt %.2f) ignored: %s", c->flags,
                    c->pan / 100.0, c->tilt / 100.0, not_deployed);
        } else if (rc == SIM_CMD_NOT_SPOI) {
            sim_log(s, now,
                    "GIMBAL_CMD: SPOI error%s (flags 0x%02X, pan %.2f tilt %.2f) ignored: not in "
                    "SPOI mode; still in %s mode%s",
                    c->flags == TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE ? " rate" : "", c->flags,
                    c->pan / 100.0, c->tilt / 100.0, mode_name(&s->m),
                    s->m.stabilised ? ", stabilised" : "");
        } else if (spoi && TASE_GIMBAL_KIND(c->flags) == TASE_GIMBAL_KIND_IMPULSE) {
            /* the error moves over the impulse's time: where it starts */
            sim_log(s, now,
                    "GIMBAL_CMD: SPOI error impulse pan %.2f tilt %.2f deg/s for %.2f s; SPOI "
                    "error %.2f/%.2f, moving by %.2f/%.2f",
                    c->pan / 100.0, c->tilt / 100.0, c->impulse_time / 100.0, s->m.err_pan,
                    s->m.err_tilt, c->pan / 100.0 * (c->impulse_time / 100.0),
                    c->tilt / 100.0 * (c->impulse_time / 100.0));
        } else if (spoi && TASE_GIMBAL_KIND(c->flags) > TASE_GIMBAL_KIND_IMPULSE) {
            sim_log(s, now,
                    "GIMBAL_CMD: SPOI error %s pan %.2f tilt %.2f%s; SPOI error now %.2f/%.2f",
                    c->flags == TASE_GIMBAL_FLAGS_SPOI_ERROR ? "set to" : "rate", c->pan / 100.0,
                    c->tilt / 100.0, c->flags == TASE_GIMBAL_FLAGS_SPOI_ERROR ? "" : " deg/s",
                    s->m.err_pan, s->m.err_tilt);
        } else {
            sim_log(s, now, "GIMBAL_CMD: %s pan %.2f tilt %.2f%s", mode_name(&s->m), c->pan / 100.0,
                    c->tilt / 100.0, s->m.stabilised ? ", stabilised" : "");
        }
        break;
    }
    case TASE_ID_GYRO_ZERO_CMD:
        /* 4.1.2: only while the gimbal is not moving (a real one would
         * take the motion for gyro bias) */
        sim_log(s, now, "GYRO_ZERO_CMD: gyros zeroed%s",
                s->m.pan_rate != 0.0 || s->m.tilt_rate != 0.0
                    ? " while the gimbal was moving (4.1.2: send it only when it is still; a real "
                      "gimbal's gyro biases would now be off)"
                    : "");
        break;
    case TASE_ID_CAMERA_CMD: camera_cmd(s, &msg.camera_cmd, len, now); break;
    case TASE_ID_LEGACY_CAMERA_CMD: {
        int rc = sim_model_camera_legacy_zoom(&s->m, msg.legacy_camera_cmd.zoom);
        if (rc != SIM_CAM_OK) {
            sim_log(s, now, "LEGACY_CAMERA_CMD ignored: %s", camera_refusal(rc));
        } else {
            sim_log(s, now, "LEGACY_CAMERA_CMD: camera A HFOV %.2f deg", s->m.cam[0].hfov);
        }
        break;
    }
    case TASE_ID_CAMERA_PASS: camera_pass(s, port, &msg.camera_pass, now); break;
    case TASE_ID_RETRACT_DEPLOY_CMD:
        sim_model_retract_deploy(&s->m, msg.retract_deploy_cmd.deploy != 0);
        sim_log(s, now, "RETRACT_DEPLOY_CMD: %s",
                msg.retract_deploy_cmd.deploy
                    ? "deploying; the axes move again once deployed"
                    : "retracting; the axes hold still (position hold) until deployed again");
        break;
    case TASE_ID_HOST_SENSOR:
        s->p = msg.host_sensor.roll;
        s->q = msg.host_sensor.pitch;
        s->r = msg.host_sensor.yaw;
        if (!s->sensor_said) { /* 10-50 a second: the first one only */
            sim_log(s, now,
                    "HOST_SENSOR: the host's body rates (p %.2f, q %.2f, r %.2f deg/s) are "
                    "reported in GIMBAL_RATE from now on",
                    s->p / 100.0, s->q / 100.0, s->r / 100.0);
            s->sensor_said = true;
        }
        break;
    case TASE_ID_HOST_ATTITUDE: {
        sim_att_t a;
        uint8_t fl = msg.host_attitude.flags;
        a.roll = tase_units_cdeg_to_deg(msg.host_attitude.roll);
        a.pitch = tase_units_cdeg_to_deg(msg.host_attitude.pitch);
        a.yaw = tase_units_cdeg_to_deg(msg.host_attitude.yaw);
        nav_said(s, now, &s->att_said,
                 sim_model_host_attitude(&s->m, &a, (fl & TASE_HOST_ATT_OVERWRITE) != 0,
                                         (fl & TASE_HOST_ATT_AID_YAW) != 0),
                 "HOST_ATTITUDE");
        break;
    }
    case TASE_ID_HOST_GPS_DATA: {
        const tase_host_gps_t *g = &msg.host_gps;
        sim_pos_t p = wire_pos(g->lat, g->lon, g->height, g->vnorth, g->veast, g->vdown);
        nav_said(s, now, &s->gps_said, sim_model_host_gps(&s->m, &p, g->valid == 1u),
                 "HOST_GPS_DATA");
        break;
    }
    case TASE_ID_SPOI_CMD:
        if (len == 0) {
            send_spoi(s, port);
        } else {
            const tase_spoi_cmd_t *c = &msg.spoi_cmd;
            sim_pos_t t = wire_pos(c->lat, c->lon, c->height, c->vnorth, c->veast, c->vdown);
            if (tase_command_check(TASE_ID_SPOI_CMD, c) != TASE_OK) {
                /* no point on the Earth: never tracked (the echo, if
                 * asked for, shows the SPOI in force) */
                sim_log(s, now,
                        "SPOI_CMD (%.6f, %.6f, %.1f m) refused: beyond 90 deg of latitude or 180 "
                        "of longitude; the SPOI in force stays",
                        t.lat, t.lon, t.height);
            } else if (sim_model_spoi(&s->m, &t) != SIM_CMD_OK) {
                sim_log(s, now, "SPOI_CMD (%.6f, %.6f, %.1f m) ignored: %s", t.lat, t.lon, t.height,
                        not_deployed);
            } else {
                s->spoi_valid = true;
                sim_log(s, now, "SPOI_CMD: pointing at %.6f, %.6f, %.1f m%s", t.lat, t.lon,
                        t.height,
                        s->m.host.lat == s->m.own_pos.lat && !s->m.ext_gps
                            ? " from the gimbal's own GPS/INS position (NAV_SOURCE)"
                            : "");
            }
            if (msg.spoi_cmd.flags & TASE_SPOI_ECHO) {
                send_spoi(s, port); /* the gimbal's flags, not the request's */
            }
        }
        break;
    default:
        sim_log(s, now, "%s: not an In packet, ignored",
                tase_schema_packet_name(tase_schema_find(f->group, f->type)));
        break;
    }
}
