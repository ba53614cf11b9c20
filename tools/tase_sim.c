/* tase-sim: a simulated TASE gimbal on a pseudo-terminal or a CAN
 * interface, built on the library's gimbal role (tase/gimbal.h). The
 * physics is in sim_model.c; this file is the protocol glue (setup
 * packets, telemetry, KLV, the main loop), the commands it receives are
 * in sim_commands.c. Behaviour and conventions: docs/TOOLS.md. */
#define _XOPEN_SOURCE 700

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "sim_model.h"
#include "sim_words.h"
#include "tase/codec.h"
#include "tase/flags.h"
#include "tase/gimbal.h"
#include "tase/klv.h"
#include "tase/units.h"
#include "tase_sim.h"
#include "toolkit.h"

#define STEP_MS 5u         /* model step and service period */
#define KLV_PERIOD_MS 900u /* spec section 6: about every 900 ms */

static const char usage[] =
    "usage: tase-sim [--link PATH [--baud N | --can-pty] | --can IFACE]\n"
    "                [--klv-link PATH] [--seconds S] [--quiet]\n"
    "A simulated TASE gimbal. By default it serves the serial datalink on a new\n"
    "pseudo-terminal and prints its path; --link PATH also makes PATH a symlink to\n"
    "it. --can IFACE serves the CAN datalink on a SocketCAN interface instead.\n"
    "--can-pty serves the CAN datalink's bytes on the pseudo-terminal, for a bridge\n"
    "that carries them in CAN frames (the Python package's virtual bus): the link\n"
    "is then port 3 with the CAN port's capacity.\n"
    "--klv-link PATH adds the KLV metadata output (an 87-byte packet about every\n"
    "900 ms) on a second pseudo-terminal, symlinked at PATH. It answers every In\n"
    "packet of the spec and streams GIMBAL_ANGLE, GIMBAL_RATE and GEOREFERENCE_DATA\n"
    "at the PACKET_RATE rates of its link's port (the serial link is port 2, Com3;\n"
    "port 1, Com2, with --baud 9600; CAN is port 3), never more than the link\n"
    "carries (GEOREFERENCE_DATA's sample_rate says what it achieves): on the serial\n"
    "link (--baud, default 57600) telemetry uses at most 75% of baud/10 bytes per\n"
    "second (the gimbal role's capacity rule), whatever PACKET_RATE asks. Runs until SIGINT, "
    "SIGTERM or SIGHUP, or for S\n"
    "seconds, then removes its links. A link another running tase-sim holds is\n"
    "refused; it holds a lock on PATH.lock beside each link while it runs, so that\n"
    "the tools refuse the link of a simulator that was killed. A log that cannot be\n"
    "written (a full disk) is said on standard error; the simulation goes on.\n"
    "Exit status: 0 success, 1 failure (a log left incomplete included), 2 bad\n"
    "command line.\n";

/* The log (standard output) that cannot be written: a full disk,
 * /dev/full, a reader that went away. The simulator is the gimbal a host
 * under test talks to, so it goes on serving (ending it would turn a
 * logging problem into a link failure of the test); the failure is said at
 * once on standard error, nothing more is written to the log, and the exit
 * status is 1 with a count of the lines lost, so that neither the engineer
 * nor a script takes an incomplete log for a complete run. */
static struct {
    int err;            /* errno of the first failed write, 0 none */
    unsigned long lost; /* log lines not written from then on */
} log_failed;

/* Flush `lines` log lines just printed; on a failure say so (once). */
static void log_flush(unsigned long lines)
{
    if (log_failed.err != 0) {
        log_failed.lost += lines;
        return;
    }
    errno = 0;
    if (fflush(stdout) != 0 || ferror(stdout)) {
        log_failed.err = errno != 0 ? errno : EIO;
        log_failed.lost = lines;
        tk_warn("cannot write the log to standard output: %s; the simulated gimbal goes on "
                "without its log (exit status 1 at the end)",
                strerror(log_failed.err));
    }
}

void sim_log(const sim_t *s, uint32_t now, const char *fmt, ...)
{
    va_list ap;
    if (s->quiet) {
        return;
    }
    if (log_failed.err != 0) {
        log_failed.lost++;
        return;
    }
    printf("[%8.3f] ", (double)(uint32_t)(now - s->t0) / 1000.0);
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    fputc('\n', stdout);
    log_flush(1u);
}

void sim_send_packet(sim_t *s, unsigned port, uint16_t id, const void *msg)
{
    (void)tase_gimbal_send_msg(&s->g, port, id, msg);
}

/* ---- setup packets ---- */

static void apply_axis(sim_t *s, const tase_axis_setting_t *a)
{
    s->m.axis_pan.nogo_center = tase_units_cdeg_to_deg(a->pan_nogo_center);
    s->m.axis_pan.nogo_range = (double)a->pan_nogo_range / 100.0;
    s->m.axis_tilt.nogo_center = tase_units_cdeg_to_deg(a->tilt_nogo_center);
    s->m.axis_tilt.nogo_range = (double)a->tilt_nogo_range / 100.0;
    s->m.axis_pan.max_rate = 5.0 * a->pan_max_rate;
    s->m.axis_tilt.max_rate = 5.0 * a->tilt_max_rate;
    s->m.axis_pan.gain = 0.1 * a->pan_pos_gain;
    s->m.axis_tilt.gain = 0.1 * a->tilt_pos_gain;
}

/* What a real gimbal does with a setup packet's `temporary` byte (the
 * simulator keeps every setting for its run only). The packets without
 * one are always stored (4.4; PROTOCOL-NOTES S11). */
#define STORED "a gimbal would store it in non-volatile memory"
static const char *storage(uint8_t temporary)
{
    return temporary == TASE_SETUP_TEMPORARY ? "temporary" : STORED;
}

/* Setup packets arrive resolved by the role ("do not change" fields
 * already replaced by the settings in force). */
static int apply_setup(void *user, unsigned port, uint16_t id, void *msg)
{
    sim_t *s = user;
    uint32_t now = tase_posix_now_ms();
    (void)port;
    if (id == TASE_ID_AXIS_SETTING) {
        const tase_axis_setting_t *a = msg;
        if (a->pan_max_rate == 0 || a->tilt_max_rate == 0) {
            sim_log(s, now, "AXIS_SETTING refused: a max rate of 0 would lock the axis");
            return -1;
        }
        if (a->pan_pos_gain == 0 || a->tilt_pos_gain == 0) {
            /* no feedback: a position or SPOI command would never move */
            sim_log(s, now,
                    "AXIS_SETTING refused: a position gain of 0 would lock the axis "
                    "in position and SPOI modes");
            return -1;
        }
        if (a->pan_nogo_center < TASE_PAN_MIN_CDEG || a->pan_nogo_center > TASE_PAN_MAX_CDEG ||
            a->tilt_nogo_center < TASE_TILT_MIN_CDEG || a->tilt_nogo_center > TASE_TILT_MAX_CDEG ||
            a->pan_nogo_range > 36000u || a->tilt_nogo_range > 36000u) {
            /* 4.4.3: centres -180..180 (pan), -270..90 (tilt), ranges
             * 0..360 deg */
            sim_log(s, now,
                    "AXIS_SETTING refused: a no-go zone beyond the spec's ranges (pan centre "
                    "%.2f, tilt centre %.2f, ranges %.2f/%.2f deg; 4.4.3: centres -180..180 and "
                    "-270..90, ranges 0..360)",
                    a->pan_nogo_center / 100.0, a->tilt_nogo_center / 100.0,
                    a->pan_nogo_range / 100.0, a->tilt_nogo_range / 100.0);
            return -1;
        }
        apply_axis(s, a);
        sim_log(s, now,
                "AXIS_SETTING: pan no-go %.2f+-%.2f, tilt no-go %.2f+-%.2f, max rates "
                "%.0f/%.0f deg/s (%s)",
                s->m.axis_pan.nogo_center, s->m.axis_pan.nogo_range / 2, s->m.axis_tilt.nogo_center,
                s->m.axis_tilt.nogo_range / 2, s->m.axis_pan.max_rate, s->m.axis_tilt.max_rate,
                storage(a->temporary));
    } else if (id == TASE_ID_PACKET_RATE) {
        const tase_packet_rate_t *r = msg;
        const uint8_t a[] = {r->angle_1, r->angle_2, r->angle_3};
        const uint8_t t[] = {r->rate_1, r->rate_2, r->rate_3};
        const uint8_t g[] = {r->geo_ref_1, r->geo_ref_2, r->geo_ref_3};
        tase_packet_rate_t old; /* in force until this one is stored */
        bool have_old;
        uint8_t og[TASE_GIMBAL_PORTS];
        unsigned i;
        memset(&old, 0, sizeof old);
        have_old = tase_gimbal_setup_get_msg(&s->g, TASE_ID_PACKET_RATE, &old) >= 0;
        og[0] = old.geo_ref_1;
        og[1] = old.geo_ref_2;
        og[2] = old.geo_ref_3;
        for (i = 0; i < TASE_GIMBAL_PORTS; i++) {
            /* only a port whose GEOREFERENCE rate changed starts measuring
             * afresh (the gimbal role keeps the others' timing; resetting
             * all made sample_rate read 20, 10, 7, 255 under a host that
             * re-sends the same setting) */
            if (!have_old || og[i] != g[i]) {
                sim_rate_reset(&s->georef_rate[i], now);
            }
        }
        sim_log(s, now, "PACKET_RATE: port %u (this link) angle %u/s, rate %u/s, georef %u/s (%s)",
                s->link + 1u, a[s->link], t[s->link], g[s->link], storage(r->temporary));
    } else if (id == TASE_ID_CAMERA_TYPE) {
        const tase_camera_type_t *c = msg;
        const uint8_t types[SIM_CAMERAS] = {c->camera_a, c->camera_b, c->camera_c};
        sim_model_camera_types(&s->m, types);
        s->version_due = true; /* SYSTEM_VERSION reports the same cameras */
        sim_log(s, now, "CAMERA_TYPE: cameras %u/%u/%u, SYSTEM_VERSION follows (" STORED ")",
                c->camera_a, c->camera_b, c->camera_c);
    } else if (id == TASE_ID_NAV_SOURCE) {
        const tase_nav_source_t *n = msg;
        sim_model_nav_source(&s->m, n->external_attitude != 0, n->external_gps != 0);
        sim_log(s, now, "NAV_SOURCE: attitude from %s, position from %s (" STORED ")",
                n->external_attitude ? "HOST_ATTITUDE" : "the gimbal's own GPS/INS",
                n->external_gps ? "HOST_GPS_DATA" : "the gimbal's own GPS/INS");
        s->gps_said = s->att_said = -1;
    } else {
        sim_log(s, now, "%s: stored, not modelled (" STORED ")",
                tase_schema_packet_name(tase_schema_find(TASE_ID_GROUP(id), TASE_ID_TYPE(id))));
    }
    return 0;
}

static void set_version(sim_t *s, uint32_t now)
{
    const sim_camera_t *cam = s->m.cam;
    tase_system_version_t v;
    tase_camera_type_t c;
    memset(&v, 0, sizeof(v));
    v.major = 2;
    v.minor = 5;
    v.sub = 1;
    v.released = 1;
    v.soft_year = 2024;
    v.soft_month = 3;
    v.soft_day = 15;
    v.board_sn = 100123u;
    v.board_rev = 3u;
    v.board_config = 0x00010002u;
    v.board_year = 2023;
    v.board_month = 11;
    v.board_day = 2;
    v.camera_a = cam[0].type;
    v.max_hfov_a = tase_units_deg_to_cdeg_u16(cam[0].max_hfov);
    v.min_hfov_a = tase_units_deg_to_cdeg_u16(cam[0].min_hfov);
    v.camera_b = cam[1].type;
    v.max_hfov_b = tase_units_deg_to_cdeg_u16(cam[1].max_hfov);
    v.min_hfov_b = tase_units_deg_to_cdeg_u16(cam[1].min_hfov);
    v.camera_c = cam[2].type;
    v.max_hfov_c = tase_units_deg_to_cdeg_u16(cam[2].max_hfov);
    v.min_hfov_c = tase_units_deg_to_cdeg_u16(cam[2].min_hfov);
    if (tase_gimbal_setup_set_msg(&s->g, TASE_ID_SYSTEM_VERSION, &v, now) != TASE_OK) {
        tk_die("internal error: cannot store SYSTEM_VERSION");
    }
    /* CAMERA_TYPE reports the same cameras (the role starts at "none") */
    c.camera_a = cam[0].type;
    c.camera_b = cam[1].type;
    c.camera_c = cam[2].type;
    if (tase_gimbal_setup_set_msg(&s->g, TASE_ID_CAMERA_TYPE, &c, now) != TASE_OK) {
        tk_die("internal error: cannot store CAMERA_TYPE");
    }
}

/* ---- telemetry ---- */

static void gps_time(tase_georeference_t *r)
{
    struct timespec ts;
    struct tm tm;
    clock_gettime(CLOCK_REALTIME, &ts);
    gmtime_r(&ts.tv_sec, &tm);
    r->year = (uint16_t)(tm.tm_year + 1900);
    r->month = (uint8_t)(tm.tm_mon + 1);
    r->day = (uint8_t)tm.tm_mday;
    r->hour = (uint8_t)tm.tm_hour;
    r->minute = (uint8_t)tm.tm_min;
    r->second = (uint8_t)(tm.tm_sec > 59 ? 59 : tm.tm_sec);
    r->frac_second = (uint8_t)(ts.tv_nsec / 10000000L);
}

static double vfov_of(double hfov)
{
    return 2.0 * atan(0.75 * tan(hfov * M_PI / 360.0)) * 180.0 / M_PI; /* 4:3 image */
}

/* The role hands over a zeroed struct of the packet due. */
static int fill_telemetry(void *user, unsigned port, uint16_t id, void *msg, uint32_t now)
{
    sim_t *s = user;
    const sim_model_t *m = &s->m;
    if (id == TASE_ID_GIMBAL_ANGLE) {
        tase_gimbal_angle_t *a = msg;
        a->pan = tase_units_deg_to_cdeg(m->pan);
        a->tilt = tase_units_deg_to_cdeg(m->tilt);
        return 0;
    }
    if (id == TASE_ID_GIMBAL_RATE) {
        tase_gimbal_rate_t *r = msg;
        r->time = now - s->t0;
        r->pan_rate = tase_units_deg_to_cdeg(m->pan_rate);
        r->tilt_rate = tase_units_deg_to_cdeg(m->tilt_rate);
        r->p = s->p;
        r->q = s->q;
        r->r = s->r;
        r->mode = sim_mode_byte(&s->m);
        return 0;
    }
    if (id == TASE_ID_GEOREFERENCE_DATA) {
        tase_georeference_t *r = msg;
        double cr, cp, cy, hfov = m->cam[m->active_cam].hfov;
        r->time = now - s->t0;
        r->lat = tase_units_deg_to_mas(m->host.lat);
        r->lon = tase_units_deg_to_mas(m->host.lon);
        r->height = tase_units_m_to_cm(m->host.height);
        r->vnorth = tase_units_sat_i16(m->host.vn * 100.0);
        r->veast = tase_units_sat_i16(m->host.ve * 100.0);
        r->vdown = tase_units_sat_i16(m->host.vd * 100.0);
        gps_time(r);
        r->num_sats = 12;
        r->pdop = 12;
        r->status = TASE_BITS16_SET(0u, 0, 2, TASE_GPS_FIX_3D);
        sim_model_camera_euler(m, &cr, &cp, &cy);
        r->camera_roll = tase_units_deg_to_cdeg(cr);
        r->camera_pitch = tase_units_deg_to_cdeg(cp);
        r->camera_yaw = tase_units_deg_to_cdeg(cy);
        r->hfov = tase_units_deg_to_cdeg_u16(hfov);
        r->vfov = tase_units_deg_to_cdeg_u16(vfov_of(hfov));
        r->focal = tase_units_sat_u16(100.0 * 2.4 / tan(hfov * M_PI / 360.0)); /* 4.8 mm sensor */
        r->mode = sim_mode_byte(&s->m);
        /* "the rate at which this packet is being sent": the rate achieved
         * (the link's capacity may allow fewer than PACKET_RATE asks) */
        sim_rate_note(&s->georef_rate[port], now);
        r->sample_rate = (uint8_t)sim_rate_hz(&s->georef_rate[port], now);
        r->nav_health = sim_nav_health();
        r->mount_roll = tase_units_deg_to_cdeg(m->att.roll);
        r->mount_pitch = tase_units_deg_to_cdeg(m->att.pitch);
        r->mount_yaw = tase_units_deg_to_cdeg(m->att.yaw);
        r->pan = tase_units_deg_to_cdeg(m->pan);
        r->tilt = tase_units_deg_to_cdeg(m->tilt);
        r->camera = (uint8_t)m->active_cam;
        return 0;
    }
    return -1;
}

/* ---- KLV ---- */

static void send_klv(sim_t *s, const tase_port_t *klv)
{
    tase_klv_t k;
    struct timespec ts;
    uint8_t buf[TASE_KLV_PACKET_LEN];
    double hfov = s->m.cam[s->m.active_cam].hfov;
    clock_gettime(CLOCK_REALTIME, &ts);
    k.utc = (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
    k.lat = tase_klv_lat_raw(s->m.host.lat);
    k.lon = tase_klv_lon_raw(s->m.host.lon);
    k.alt = tase_klv_alt_raw(s->m.host.height);
    k.pan = tase_klv_angle_raw(s->m.pan);
    k.tilt = tase_klv_tilt_raw(s->m.tilt);
    k.heading = tase_klv_angle_raw(s->m.att.yaw);
    k.pitch = tase_klv_pitch_raw(s->m.att.pitch);
    k.roll = tase_klv_roll_raw(s->m.att.roll);
    k.vnorth = tase_klv_speed_raw(s->m.host.vn);
    k.veast = tase_klv_speed_raw(s->m.host.ve);
    k.hfov = tase_klv_fov_raw(hfov);
    k.vfov = tase_klv_fov_raw(vfov_of(hfov));
    k.gps_status = tase_klv_gps_status(TASE_KLV_GPS_FIX_3D, TASE_KLV_GPS_ANTENNA_OK, 0);
    if (tase_klv_encode(&k, buf, sizeof(buf)) == (int)TASE_KLV_PACKET_LEN) {
        (void)klv->ops->write(klv->ctx, buf, sizeof(buf)); /* nobody listening: dropped */
    }
}

/* ---- a CAN interface that goes down or away ---- */

/* The gimbal role skips a port's read errors (the port may recover), and
 * an interface that is removed and made again (a USB adapter unplugged
 * and plugged back) leaves the raw socket unbound for good: tase-sim
 * watches its CAN port through this wrapper, says what happened in its
 * log, and opens the interface again when it is back. */
typedef struct {
    tase_port_t inner; /* the link's port (its ctx is the tk_link_t's) */
    int err;           /* the first error since the last look, 0: none */
    bool worked;       /* a read or write moved bytes since the last look */
    bool down, gone;   /* what the log said last */
    uint32_t next_try; /* gone: when to try opening it again */
} sim_can_watch_t;

static int can_watch_note(sim_can_watch_t *w, int r)
{
    if (r < 0 && w->err == 0) {
        w->err = r;
    } else if (r > 0) {
        w->worked = true;
    }
    return r;
}

static int can_watch_write(void *ctx, const uint8_t *data, size_t n)
{
    sim_can_watch_t *w = ctx;
    return can_watch_note(w, w->inner.ops->write(w->inner.ctx, data, n));
}

static int can_watch_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    sim_can_watch_t *w = ctx;
    return can_watch_note(w, w->inner.ops->read(w->inner.ctx, buf, cap, timeout_ms));
}

static uint32_t can_watch_now(void *ctx)
{
    sim_can_watch_t *w = ctx;
    return w->inner.ops->now_ms(w->inner.ctx);
}

static const tase_port_ops_t can_watch_ops = {can_watch_write, can_watch_read, can_watch_now};

/* After each service: log a change and, while the interface is gone, try
 * to open it again every half second. */
static void can_watch_look(sim_t *s, sim_can_watch_t *w, tk_link_t *dl, const char *iface,
                           uint32_t now)
{
    int err = w->err;
    bool worked = w->worked;
    w->err = 0;
    w->worked = false;
    if (err == TASE_ENODEV && !w->gone) {
        sim_log(s, now, "CAN interface %s: %s; opening it again when it is back", iface,
                TK_CAN_REMOVED_TEXT);
        w->gone = true;
        w->down = false;
        w->next_try = now;
    }
    if (w->gone) {
        if ((int32_t)(now - w->next_try) >= 0) {
            w->next_try = now + 500u;
            if (tk_link_can_reopen(dl, iface, true) == TASE_OK) {
                w->gone = false;
                sim_log(s, now, "CAN interface %s is back: serving on it again", iface);
            }
        }
    } else if (err == TASE_EDOWN && !w->down) {
        sim_log(s, now, "CAN interface %s: %s; waiting for it to come up", iface, TK_CAN_DOWN_TEXT);
        w->down = true;
    } else if (w->down && worked && err == 0) {
        sim_log(s, now, "CAN interface %s is up again", iface);
        w->down = false;
    }
}

/* ---- main ---- */

/* Setup packets of a wrong length are dropped by the gimbal role (no
 * echo; the host's request times out): say so, at most once a second, with
 * how many since the last line (the role counts them, it does not say
 * which). */
static void say_bad_lengths(sim_t *s, uint32_t now)
{
    uint32_t n = s->g.stats.bad_length - s->bad_length_said;
    if (n != 0u && (s->bad_length_said == 0u || now - s->bad_length_at >= 1000u)) {
        sim_log(s, now,
                "%lu setup packet%s of a wrong length ignored (each has its table's length or "
                "0 for a query; nothing echoed)",
                (unsigned long)n, n == 1u ? "" : "s");
        s->bad_length_said = s->g.stats.bad_length;
        s->bad_length_at = now;
    }
}

int main(int argc, char **argv)
{
    static sim_t s;
    const char *link = NULL, *can = NULL, *klv_link = NULL;
    double seconds = 0.0;
    long long baud = 57600;
    bool baud_given = false;
    bool can_pty = false;
    char path[256], klv_path[256];
    tk_link_t dl, kl;
    tase_port_t port, klv_port, ports[TASE_GIMBAL_PORTS];
    tase_gimbal_app_t app;
    uint32_t now, last, next_klv;
    double t_end;
    int i, slave_fd = -1, klv_slave = -1;
    bool have_klv = false;
    tase_axis_setting_t axs;
    tase_nav_source_t nav;
    sim_can_watch_t watch;
    int klv_unread = 0; /* unread bytes of the KLV link after its last look */

    tk_std_fds_open(); /* before anything opens a file */
    tk_prog = "tase-sim";
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        /* --opt=VALUE takes any value, as in tase (docs/TOOLS.md); otherwise
         * a value that starts with "--" is the next option: missing */
        char name[16];
        const char *eq = strchr(a, '=');
        const char *val = NULL;
        bool with_value;
        if (strncmp(a, "--", 2) == 0 && eq != NULL && (size_t)(eq - a) < sizeof(name)) {
            memcpy(name, a, (size_t)(eq - a));
            name[eq - a] = '\0';
            val = eq + 1;
            a = name;
            if (strcmp(a, "--quiet") == 0 || strcmp(a, "--can-pty") == 0 ||
                strcmp(a, "--help") == 0 || strcmp(a, "--version") == 0) {
                tk_usage_error("option %s takes no value", a);
            }
        }
        with_value = strcmp(a, "--link") == 0 || strcmp(a, "--can") == 0 ||
                     strcmp(a, "--klv-link") == 0 || strcmp(a, "--baud") == 0 ||
                     strcmp(a, "--seconds") == 0;
        if (with_value && val == NULL && i + 1 < argc && strncmp(argv[i + 1], "--", 2) != 0) {
            val = argv[++i];
        }
        /* each option with a value at most once */
        if ((strcmp(a, "--link") == 0 && link != NULL) ||
            (strcmp(a, "--can") == 0 && can != NULL) ||
            (strcmp(a, "--klv-link") == 0 && klv_link != NULL) ||
            (strcmp(a, "--baud") == 0 && baud_given) ||
            (strcmp(a, "--seconds") == 0 && seconds > 0.0)) {
            tk_usage_error("option %s given twice", a);
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            tk_stdout_flush();
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("tase-sim %s\n", TASE_VERSION_STRING);
            tk_stdout_flush();
            return 0;
        } else if (strcmp(a, "--quiet") == 0) {
            s.quiet = true;
        } else if (strcmp(a, "--can-pty") == 0) {
            can_pty = true;
        } else if (with_value && (val == NULL || val[0] == '\0')) {
            tk_usage_error("option %s needs a value", a);
        } else if (strcmp(a, "--link") == 0) {
            link = val;
        } else if (strcmp(a, "--can") == 0) {
            can = val;
        } else if (strcmp(a, "--klv-link") == 0) {
            klv_link = val;
        } else if (strcmp(a, "--baud") == 0) {
            if (tk_parse_int(val, 1, 4000000, &baud, NULL) != TK_NUM_OK ||
                !tase_posix_uart_baud_supported((uint32_t)baud)) {
                tk_usage_error("bad --baud value '%s' (a standard serial rate)", val);
            }
            baud_given = true;
        } else if (strcmp(a, "--seconds") == 0) {
            if (tk_parse_seconds(val, &seconds) != 0 || seconds <= 0.0) {
                tk_usage_error("bad --seconds value '%s'", val);
            }
        } else {
            tk_usage_error("unknown argument '%s' (see --help)", a);
        }
    }
    if (link != NULL && can != NULL) {
        tk_usage_error("give either --link or --can, not both");
    }
    if (can != NULL && baud_given) {
        tk_usage_error("--baud is for the serial link, not --can");
    }
    if (can_pty && (can != NULL || baud_given)) {
        tk_usage_error("--can-pty is a pseudo-terminal at CAN's capacity: not with %s",
                       can != NULL ? "--can" : "--baud");
    }
    if (link != NULL && klv_link != NULL) {
        char a[PATH_MAX], b[PATH_MAX];
        if (strcmp(link, klv_link) == 0 ||
            (tk_canonical_path(link, a, sizeof(a)) == 0 &&
             tk_canonical_path(klv_link, b, sizeof(b)) == 0 && strcmp(a, b) == 0)) {
            tk_usage_error("--klv-link must differ from --link (%s)", link);
        }
    }

    sim_model_init(&s.m);
    s.gps_said = s.att_said = -1;

    /* SIGINT, SIGTERM, SIGHUP stop the loop below; caught before the links
     * exist, so one that comes while they are made still removes them */
    tk_catch_signals();

    if (can != NULL) {
        tk_link_can(&dl, can, true);
        snprintf(path, sizeof(path), "%s", can);
    } else {
        tk_link_pty(&dl, tk_pty_open(path, sizeof(path), link, &slave_fd));
    }
    port = tk_link_port(&dl);
    memset(&watch, 0, sizeof(watch));
    if (can != NULL) {
        watch.inner = port;
        port.ops = &can_watch_ops;
        port.ctx = &watch;
    } else {
        /* a pty has no speed of its own: the simulated line's is --baud
         * (--can-pty: the CAN port's); the gimbal role sizes telemetry (its
         * capacity) and the receiver's time bound by it */
        port.bytes_per_s =
            can_pty ? TASE_SOCKETCAN_BYTES_PER_S : TASE_UART_BYTES_PER_S((uint32_t)baud);
    }
    if (klv_link != NULL) {
        tk_link_pty(&kl, tk_pty_open(klv_path, sizeof(klv_path), klv_link, &klv_slave));
        klv_port = tk_link_port(&kl);
        have_klv = true;
    }

    memset(&app, 0, sizeof(app));
    app.apply_setup_msg = apply_setup;
    app.fill_telemetry_msg = fill_telemetry;
    app.on_frame = sim_on_frame;
    app.user = &s;
    now = tase_posix_now_ms();
    s.t0 = now;
    /* the link is one of PACKET_RATE's ports 1..3 (PROTOCOL-NOTES A2); the
     * other two are absent */
    memset(ports, 0, sizeof(ports));
    s.link = sim_link_port(can != NULL || can_pty, (uint32_t)baud);
    ports[s.link] = port;
    for (i = 0; i < (int)TASE_GIMBAL_PORTS; i++) {
        sim_rate_reset(&s.georef_rate[i], now);
    }
    if (tase_gimbal_init(&s.g, ports, s.rx, TASE_GIMBAL_PORTS, &app, now) != TASE_OK) {
        tk_die("internal error: gimbal role init failed");
    }
    set_version(&s, now);
    /* the model starts from the role's stored (default) axis settings */
    if (tase_gimbal_setup_get_msg(&s.g, TASE_ID_AXIS_SETTING, &axs) < 0) {
        tk_die("internal error: no AXIS_SETTING");
    }
    apply_axis(&s, &axs);
    if (tase_gimbal_setup_get_msg(&s.g, TASE_ID_NAV_SOURCE, &nav) < 0) {
        tk_die("internal error: no NAV_SOURCE");
    }
    sim_model_nav_source(&s.m, nav.external_attitude != 0, nav.external_gps != 0);

    printf("tase-sim: simulated gimbal on %s%s", can ? "CAN interface " : "", path);
    if (can_pty) {
        printf(", the CAN link's rates and capacity"); /* no serial line: no baud */
    } else if (can == NULL) {
        printf(", %lld baud", baud);
    }
    printf(", PACKET_RATE port %u", s.link + 1u);
    printf(link ? " (link %s)\n" : "\n", link);
    if (have_klv) {
        printf("tase-sim: KLV output on %s (link %s)\n", klv_path, klv_link);
    }
    log_flush(have_klv ? 2u : 1u);

    last = now;
    next_klv = now + KLV_PERIOD_MS;
    t_end = tk_now_s() + seconds;
    while (tk_signal == 0 && (seconds == 0.0 || tk_now_s() < t_end)) {
        struct timespec ts = {0, (long)STEP_MS * 1000000L};
        uint32_t dt;
        nanosleep(&ts, NULL);
        now = tase_posix_now_ms();
        dt = now - last;
        last = now;
        if (dt > 0 && sim_model_step(&s.m, (dt > 1000u ? 1000u : dt) / 1000.0)) {
            tase_retract_deploy_cmd_t rd;
            rd.deploy = s.m.tax == SIM_3AX_DEPLOYED ? 1u : 0u;
            sim_send_packet(&s, s.link, TASE_ID_RETRACT_DEPLOY_CMD, &rd);
            sim_log(&s, now, "RETRACT_DEPLOY_CMD: %s, echoed",
                    rd.deploy ? "deployed" : "retracted");
        }
        if (slave_fd >= 0 && tk_pty_clear_stale_excl(slave_fd)) {
            sim_log(&s, now,
                    "%s: cleared the exclusive-use flag of a program that is gone "
                    "(killed while it held the link)",
                    path);
        }
        if (klv_slave >= 0 && tk_pty_clear_stale_excl(klv_slave)) {
            sim_log(&s, now,
                    "%s: cleared the exclusive-use flag of a program that is gone "
                    "(killed while it held the link)",
                    klv_path);
        }
        if (slave_fd >= 0 && tk_pty_unread(slave_fd) > 2048) {
            /* nobody has read the link for a while: keep only fresh data */
            (void)tk_pty_drop_unread(slave_fd);
        }
        (void)tase_gimbal_service(&s.g, now);
        say_bad_lengths(&s, now);
        if (can != NULL) {
            can_watch_look(&s, &watch, &dl, can, now);
        }
        if (s.version_due) {
            /* after the callbacks: they may not store setup packets */
            set_version(&s, now);
            s.version_due = false;
        }
        if (have_klv && (int32_t)(now - next_klv) >= 0) {
            int unread = tk_pty_unread(klv_slave);
            if (unread > 0 && unread < (int)TASE_KLV_PACKET_LEN && unread < klv_unread) {
                /* a reader is part-way through the last packet and has
                 * read some since the last look: this one is skipped
                 * rather than that one cut (dropping every unread byte
                 * left a reader slower than 97 B/s no whole packet) */
                klv_unread = unread;
            } else {
                /* a packet still unread after 900 ms (or a tail nobody
                 * reads any more) has no reader: drop it, as a serial line
                 * would, so a reader that opens later gets fresh data */
                (void)tk_pty_drop_unread(klv_slave);
                send_klv(&s, &klv_port);
                /* what was just queued, not a look now: the pty passes
                 * written bytes to its reader's side a little later, and a
                 * look right after the write saw some of them or none */
                klv_unread = (int)TASE_KLV_PACKET_LEN;
            }
            next_klv = sim_next_due(next_klv, now, KLV_PERIOD_MS); /* no burst after a stall */
        }
    }
    /* the links (only those that still point at our ptys) and their lock
     * files are removed at exit (tk_pty_open()) */
    {
        /* what was dropped too: checksum errors and frames a pause cut
         * short were never logged, wrong-length setup packets only as a
         * count a second at most */
        const tase_rx_stats_t *rs = &s.rx[s.link].stats;
        sim_log(&s, tase_posix_now_ms(),
                "stopped: %lu frames in, %lu out; dropped: %lu checksum errors, %lu setup "
                "packets of a wrong length, %lu of %lu bytes discarded",
                (unsigned long)s.g.stats.frames_rx, (unsigned long)s.g.stats.frames_tx,
                (unsigned long)rs->checksum_errors, (unsigned long)s.g.stats.bad_length,
                (unsigned long)rs->bytes_discarded, (unsigned long)rs->bytes_in);
    }
    tk_link_close(&dl);
    if (log_failed.err != 0) {
        tk_die("the log on standard output is incomplete: %lu line%s not written (%s)",
               log_failed.lost, log_failed.lost == 1u ? "" : "s", strerror(log_failed.err));
    }
    return 0;
}
