/* The gimbal application: typed handlers, error hook, default handler,
 * and the callbacks of the library's gimbal role. */
#include "gimbal.h"

#include <string.h>

#include "tase/flags.h"

/* Software 0.1.0 released 2024-05-17; board fields zero; camera A type 3
 * with 40.00..2.00 degrees of field of view; no cameras B and C. */
static const uint8_t version_info[42] = {
    0, 1, 0, 1, 0x07, 0xE8, 5,    17,   0,    0,    0, 0, 0, 0, 0, 0,    0, 0, 0, 0, 0,
    0, 0, 0, 3, 0,    0x0F, 0xA0, 0x00, 0xC8, 0xFF, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0, 0,
};

int16_t gimbal_sim_pan(uint32_t t)
{
    return (int16_t)(t * 3u % 18000u);
}

int16_t gimbal_sim_tilt(uint32_t t)
{
    return (int16_t) - (int32_t)(t % 9000u);
}

uint8_t gimbal_mode_byte(uint8_t cmd_flags)
{
    unsigned kind = TASE_GIMBAL_KIND(cmd_flags);
    bool stab;
    unsigned mode;

    if (kind == 0u) { /* legacy encoding: bit 6 stabilisation, bit 7 position */
        stab = (cmd_flags & TASE_GIMBAL_LEGACY_STAB) != 0u;
        mode =
            (cmd_flags & TASE_GIMBAL_LEGACY_POSITION) != 0u ? TASE_MODE_POSITION : TASE_MODE_RATE;
    } else {
        stab = (cmd_flags & TASE_GIMBAL_STAB) != 0u;
        if (kind == TASE_GIMBAL_KIND_POSITION) {
            mode = TASE_MODE_POSITION;
        } else if (kind == TASE_GIMBAL_KIND_SPOI_ERROR ||
                   kind == TASE_GIMBAL_KIND_SPOI_ERROR_RATE) {
            mode = TASE_MODE_SPOI;
        } else {
            mode = TASE_MODE_RATE; /* rate, impulse (a timed rate) */
        }
    }
    return (uint8_t)(TASE_MODE_SET_VALUE(0u, mode) | (stab ? TASE_MODE_STAB : 0u));
}

uint8_t gimbal_mode(const gimbal_app_t *app)
{
    return app->spoi_mode ? (uint8_t)(TASE_MODE_SET_VALUE(0u, TASE_MODE_SPOI) | TASE_MODE_STAB)
                          : gimbal_mode_byte(app->cmd_flags);
}

static void trace(gimbal_app_t *app, const tase_frame_t *f, unsigned route, const int64_t *v,
                  size_t n)
{
    if (app->trace != NULL) {
        app->trace(app->trace_user, f, route, v, n);
    }
}

static void on_gimbal_cmd(void *user, const tase_frame_t *f, const void *msg)
{
    gimbal_app_t *app = user;
    const tase_gimbal_cmd_t *m = msg;
    int64_t v[5];
    unsigned kind;
    bool spoi_error;
    v[0] = m->pan;
    v[1] = m->tilt;
    v[2] = m->roll;
    v[3] = m->flags;
    v[4] = m->impulse_time;
    trace(app, f, GIMBAL_ROUTE_TYPED, v, 5u);
    if (tase_command_check(TASE_ID_GIMBAL_CMD, m) != TASE_OK) {
        /* flags not of the spec's table 5, or a position beyond the
         * axes' ranges: never applied (a product gimbal built from this
         * must not move on it); the command in force stays */
        app->commands_refused++;
        return;
    }
    kind = TASE_GIMBAL_KIND(m->flags);
    spoi_error = kind == TASE_GIMBAL_KIND_SPOI_ERROR || kind == TASE_GIMBAL_KIND_SPOI_ERROR_RATE;
    if (spoi_error && !app->spoi_mode) {
        /* a SPOI error with no SPOI to shift: changes nothing */
        app->commands_ignored++;
        return;
    }
    if (!spoi_error && kind != TASE_GIMBAL_KIND_IMPULSE) {
        app->spoi_mode = false; /* rate, position, legacy: SPOI ends */
    }
    app->cmd_pan = m->pan;
    app->cmd_tilt = m->tilt;
    app->cmd_flags = m->flags;
    app->commands++;
}

/* SPOI_CMD: a point to track, or (zero length, the dispatcher's zeroed
 * struct) a request for the one in force. The answers go out on the port
 * the request came in on; this board has one (index 0). */
static void on_spoi(void *user, const tase_frame_t *f, const void *msg)
{
    gimbal_app_t *app = user;
    const tase_spoi_cmd_t *m = msg;
    tase_spoi_cmd_t answer;
    int64_t v[7];
    v[0] = m->lat;
    v[1] = m->lon;
    v[2] = m->height;
    v[3] = m->vnorth;
    v[4] = m->veast;
    v[5] = m->vdown;
    v[6] = m->flags;
    trace(app, f, GIMBAL_ROUTE_TYPED, v, 7u);
    if (f->len != 0u) {
        if (tase_command_check(TASE_ID_SPOI_CMD, m) != TASE_OK) {
            /* beyond 90 deg of latitude or 180 of longitude: not a
             * point, never tracked; the SPOI in force stays */
            app->spois_refused++;
            return;
        }
        app->spoi = *m;
        app->spoi.flags = 0u;
        app->spoi_mode = true; /* a new SPOI clears the SPOI error too */
        app->cmd_pan = 0;
        app->cmd_tilt = 0;
        app->spois++;
        if ((m->flags & TASE_SPOI_ECHO) == 0u) {
            return;
        }
    } else {
        app->spoi_queries++;
    }
    answer = app->spoi;
    answer.flags = gimbal_mode(app);

    if (tase_gimbal_send_msg(&app->role, 0u, TASE_ID_SPOI_CMD, &answer) < 0) {
        app->encode_errors++;
    }
}

static void on_gyro_zero(void *user, const tase_frame_t *f, const void *msg)
{
    gimbal_app_t *app = user;
    (void)msg; /* NULL: GYRO_ZERO_CMD has no data */
    app->gyro_zeros++;
    trace(app, f, GIMBAL_ROUTE_TYPED, NULL, 0u);
}

static void on_host_attitude(void *user, const tase_frame_t *f, const void *msg)
{
    gimbal_app_t *app = user;
    const tase_host_attitude_t *m = msg;
    int64_t v[6];
    v[0] = m->time;
    v[1] = m->roll;
    v[2] = m->pitch;
    v[3] = m->yaw;
    v[4] = m->flags;
    v[5] = m->sample_rate;
    app->host_attitudes++;
    trace(app, f, GIMBAL_ROUTE_TYPED, v, 6u);
}

/* Every setup packet: show the decoded fields, then let the library's
 * gimbal role store, answer and reschedule. */
static void on_setup(void *user, const tase_frame_t *f, const void *msg)
{
    gimbal_app_t *app = user;
    int64_t v[GIMBAL_TRACE_MAX];
    size_t n = 0;

    if (f->type == TASE_ID_TYPE(TASE_ID_PACKET_RATE)) {
        const tase_packet_rate_t *m = msg;
        const uint8_t r[13] = {m->angle_1,   m->rate_1,    m->geo_ref_1, m->camera_1, m->angle_2,
                               m->rate_2,    m->geo_ref_2, m->camera_2,  m->angle_3,  m->rate_3,
                               m->geo_ref_3, m->camera_3,  m->temporary};
        for (n = 0; n < sizeof r; n++) {
            v[n] = r[n];
        }
    } else if (f->type == TASE_ID_TYPE(TASE_ID_SENSOR_FILTER)) {
        const tase_sensor_filter_t *m = msg;
        v[0] = m->cutoff;
        v[1] = m->decimation;
        n = 2;
    } else if (f->type == TASE_ID_TYPE(TASE_ID_NAV_SOURCE)) {
        const tase_nav_source_t *m = msg;
        v[0] = m->external_attitude;
        v[1] = m->external_gps;
        n = 2;
    }
    app->setups++;
    trace(app, f, GIMBAL_ROUTE_TYPED, v, n);
    (void)tase_gimbal_handle_frame(&app->role, 0, f, app->now_ms);
}

static void on_length_error(void *user, const tase_frame_t *f, int err)
{
    gimbal_app_t *app = user;
    if (err == TASE_ELENGTH) {
        app->length_errors++;
        trace(app, f, GIMBAL_ROUTE_ERROR, NULL, 0u);
    }
}

static void on_unknown(void *user, const tase_frame_t *f)
{
    gimbal_app_t *app = user;
    app->unknown++;
    trace(app, f, GIMBAL_ROUTE_DEFAULT, NULL, 0u);
}

/* In ROM: one entry per packet of the schema, NULL sends a packet to the
 * default handler. */
static const tase_packet_handler_t handlers[TASE_PKT_COUNT] = {
    [TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd,   [TASE_PKT_SPOI_CMD] = on_spoi,
    [TASE_PKT_GYRO_ZERO_CMD] = on_gyro_zero, [TASE_PKT_HOST_ATTITUDE] = on_host_attitude,
    [TASE_PKT_PACKET_RATE] = on_setup,       [TASE_PKT_SENSOR_FILTER] = on_setup,
    [TASE_PKT_AXIS_SETTING] = on_setup,      [TASE_PKT_SYSTEM_VERSION] = on_setup,
    [TASE_PKT_NAV_SOURCE] = on_setup,        [TASE_PKT_CAMERA_TYPE] = on_setup,
    [TASE_PKT_GPS_LEVER_ARM] = on_setup,     [TASE_PKT_CAMERA_ALIGN] = on_setup,
};

/* The role calls this with a setting that arrived, before it stores and
 * echoes it: refuse what no axis can move with (a max rate of 0 locks it;
 * tase-sim refuses it too), and the role echoes the settings in force.
 * A product checks its other limits here as well, and writes a setting
 * to non-volatile memory only when its `temporary` byte is 0 (PACKET_RATE,
 * AXIS_SETTING). */
static int apply_setup(void *user, unsigned port, uint16_t id, void *msg)
{
    gimbal_app_t *app = user;
    (void)port;
    if (id == TASE_ID_AXIS_SETTING) {
        const tase_axis_setting_t *a = msg;
        if (a->pan_max_rate == 0u || a->tilt_max_rate == 0u) {
            app->setups_refused++;
            return -1;
        }
    }
    return 0;
}

/* The role calls this when a telemetry packet is due: fill its typed
 * struct; the role lays out the bytes. */
static int fill_telemetry(void *user, unsigned port, uint16_t id, void *msg, uint32_t now_ms)
{
    gimbal_app_t *app = user;
    tase_packet_msg_t m;

    (void)port;
    memset(&m, 0, sizeof m);
    if (id == TASE_ID_GIMBAL_ANGLE) {
        m.gimbal_angle.pan = gimbal_sim_pan(now_ms);
        m.gimbal_angle.tilt = gimbal_sim_tilt(now_ms);
    } else if (id == TASE_ID_GIMBAL_RATE) {
        m.gimbal_rate.time = now_ms;
        m.gimbal_rate.pan_rate = app->cmd_pan;
        m.gimbal_rate.tilt_rate = app->cmd_tilt;
        m.gimbal_rate.mode = gimbal_mode(app);
    } else if (id == TASE_ID_GEOREFERENCE_DATA) {
        uint8_t rates[16];
        m.georeference.time = now_ms;
        m.georeference.lat = (int32_t)(now_ms * 1000u);
        m.georeference.lon = -(int32_t)(now_ms * 2000u);
        m.georeference.height = 12345;
        m.georeference.pan = gimbal_sim_pan(now_ms);
        m.georeference.tilt = gimbal_sim_tilt(now_ms);
        if (tase_gimbal_setup_get(&app->role, 0, rates, sizeof rates) == 16) {
            m.georeference.sample_rate = rates[2];
        }
        m.georeference.hfov = 4000u;
    } else {
        return TASE_EUNKNOWN;
    }
    memcpy(msg, &m, sizeof m); /* msg is the role's tase_packet_msg_t */
    return 0;
}

int gimbal_app_init(gimbal_app_t *app, const tase_port_t *port, tase_rx_stats_t *stats,
                    gimbal_trace_t trace_fn, void *trace_user, uint32_t now_ms)
{
    tase_gimbal_app_t cb;
    int r;

    memset(app, 0, sizeof *app);
    app->trace = trace_fn;
    app->trace_user = trace_user;
    app->now_ms = now_ms;
    r = tase_dispatch_init(&app->dispatch, handlers, on_unknown, on_length_error, app, stats);
    if (r < 0) {
        return r;
    }
    memset(&cb, 0, sizeof cb);
    cb.fill_telemetry_msg = fill_telemetry;
    cb.apply_setup_msg = apply_setup;
    cb.user = app;
    r = tase_gimbal_init(&app->role, port, NULL, 1u, &cb, now_ms);
    if (r < 0) {
        return r;
    }
    return tase_gimbal_setup_set(&app->role, TASE_ID_TYPE(TASE_ID_SYSTEM_VERSION), version_info,
                                 sizeof version_info, now_ms);
}
