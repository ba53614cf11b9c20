/*
 * Example autopilot firmware for QEMU's mps2-an386 (Cortex-M4F): the host
 * side of the TASE protocol, flying a SPOI mission against a live gimbal.
 *
 * UART0's receive interrupt hands each byte to the library's bare-metal
 * port (port/baremetal: tase_bm_uart_rx_isr() into a tase_ring_t); the
 * main loop wakes on every SysTick millisecond or UART interrupt, feeds
 * what arrived to the library's host role (tase_host_service() reading
 * the bm_uart port, link.c), and runs the mission with the role's typed
 * calls (tase_host_send_msg(), tase_host_request_msg_start()):
 *
 *  1. query SYSTEM_VERSION and report the gimbal's software and cameras;
 *  2. query PACKET_RATE, set GIMBAL_PORT's rates (port 2: the gimbal's
 *     Com3 this image is wired to, PROTOCOL-NOTES A2; the other ports'
 *     rates are sent back as they were) to ANGLE_HZ/RATE_HZ/GEO_HZ and confirm
 *     the echo; query NAV_SOURCE and, unless it is already external
 *     attitude and GPS, set it so and confirm (NAV_SOURCE has no
 *     "temporary" byte: a gimbal may store every setting in flash, so it
 *     is not sent when nothing would change);
 *  3. stream HOST_ATTITUDE (ATT_HZ) and HOST_GPS_DATA (GPS_HZ) from the
 *     flight model (flight.c: a circle at constant height);
 *  4. after WARMUP_MS, command a SPOI at a ground point with echo
 *     requested and check the echo;
 *  5. from the command until TRACK_MS after its echo, consume GIMBAL_ANGLE,
 *     GIMBAL_RATE and GEOREFERENCE_DATA through the library's dispatcher:
 *     the camera line of sight that GEOREFERENCE_DATA reports must come
 *     within TOLERANCE_DEG of the SPOI within SETTLE_MS of the command and
 *     stay there; the gimbal must report SPOI mode and echo our host
 *     position and attitude;
 *  6. stop the host data and query SPOI_CMD: the gimbal still holds our
 *     point; then wait for the next GEOREFERENCE_DATA (up to HOLD_MS): the
 *     line of sight is still on the SPOI after the query;
 * from step 3 on, telemetry that stops for TELEMETRY_LOST_MS aborts the
 * mission (the gimbal's state is no longer known);
 * then print a summary (with its own flash/RAM/stack numbers) through
 * semihosting and exit 0 on success, 1 on any failure.
 *
 * The peer is whatever is on the UART: scripts/checks/autopilot.sh wires it
 * to a live tase-sim (no canned replies), at the link's real pace.
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "board.h"
#include "flight.h"
#include "link.h"
#include "tase/flags.h"
#include "tase/units.h"

/* The gimbal port this UART is wired to, as PACKET_RATE numbers them:
 * 1, 2 or 3 (bytes 0-2, 5-7, 10-12). Port 2 is the gimbal's Com3
 * (PROTOCOL-NOTES A2). Only its rates are changed. */
#ifndef GIMBAL_PORT
#define GIMBAL_PORT 2u
#endif
typedef char gimbal_port_check[(GIMBAL_PORT >= 1u && GIMBAL_PORT <= 3u) ? 1 : -1];
/* Telemetry asked of the gimbal on that port, packets per second. */
#define ANGLE_HZ 20u
#define RATE_HZ 10u
#define GEO_HZ 10u
/* Host data streamed to the gimbal. */
#define ATT_HZ 50u
#define GPS_HZ 10u
/* Both directions must fit the line with room to spare (three quarters
 * of BOARD_BAUD's bytes per second; a frame is its data plus 8 bytes):
 * GIMBAL_ANGLE 6, GIMBAL_RATE 18, GEOREFERENCE_DATA 63 bytes in,
 * HOST_ATTITUDE 12 and HOST_GPS_DATA 32 out (1,250 and 1,400 B/s of
 * 5,760 at 57600 baud; at 9600 neither fits: lower the rates) */
#define LINE_BUDGET (TASE_UART_BYTES_PER_S(BOARD_BAUD) * 3u / 4u)
typedef char telemetry_fits_the_line[(ANGLE_HZ * 14u + RATE_HZ * 26u + GEO_HZ * 71u <= LINE_BUDGET)
                                         ? 1
                                         : -1];
typedef char host_data_fits_the_line[(ATT_HZ * 20u + GPS_HZ * 40u <= LINE_BUDGET) ? 1 : -1];

#define REQUEST_TIMEOUT_MS 300u /* per attempt */
#define REQUEST_RETRIES 3u      /* re-sends after a timeout */

#define WARMUP_MS 1000u /* host data streamed before the SPOI command */
#define TRACK_MS 10000u /* tracking observed after the SPOI echo */
#define SETTLE_MS 5000u /* the line of sight must converge within this */
#define HOLD_MS 2000u   /* for a GEOREFERENCE after the SPOI query */
/* No GIMBAL_ANGLE, GIMBAL_RATE or GEOREFERENCE_DATA for this long once
 * the rates are set (20 periods of the slowest stream asked for): the
 * gimbal stopped reporting (a review: a 3 s silence passed unnoticed) */
#define TELEMETRY_LOST_MS 2000u
#define MISSION_MS 30000u /* hard limit of the whole run */
/* A gimbal often boots more slowly than the autopilot: the first request
 * (SYSTEM_VERSION) is made again until this long has passed before no
 * answer is a failure (a review: one unanswered request ended the
 * mission for good) */
#define BOOT_WAIT_MS 10000u
#define TOLERANCE_DEG 1.0f
/* Echoed yaw against the heading at the echoed position: the aircraft
 * turns 360 * speed / (2 pi radius) = 2.1 deg/s, 0.2 deg per GPS period. */
#define YAW_TOLERANCE_DEG 1.0f

#define RING_SIZE 512u /* power of two; ~89 ms of BOARD_BAUD (57600) */
#define READS_PER_WAKE 8u

static const flight_plan_t plan = {
    46.5,    /* centre latitude, deg */
    7.5,     /* centre longitude, deg */
    1200.0f, /* height above the ellipsoid, m */
    800.0f,  /* radius, m */
    30.0f,   /* ground speed, m/s */
};
/* The SPOI: a ground point off the circle's centre. */
#define SPOI_NORTH_M 150.0f
#define SPOI_EAST_M (-100.0f)
#define SPOI_HEIGHT_M 600.0f

typedef enum {
    STEP_VERSION,
    STEP_RATE_GET,
    STEP_RATE_SET,
    STEP_NAV_GET,
    STEP_NAV_SET,
    STEP_WARMUP,
    STEP_SPOI,
    STEP_TRACK,
    STEP_SPOI_GET,
    STEP_HOLD,
    STEP_DONE
} step_t;

typedef struct {
    link_t link;
    step_t step;
    /* the step the mission was in when it was aborted (STEP_DONE if it
     * never was): the summary reports only the steps before it */
    step_t aborted_in;
    uint32_t boot_timeouts; /* first requests unanswered while the gimbal boots */
    bool requesting;
    uint32_t start;   /* the clock when the mission began, ms */
    uint32_t step_at; /* when the current step began, ms */
    tase_packet_msg_t reply;
    tase_packet_rate_t rate_req;
    tase_nav_source_t nav_req;
    bool nav_kept;            /* NAV_SOURCE was already ours: not sent */
    tase_spoi_cmd_t spoi_req; /* built before the mission starts */
    bool spoi_built;
    /* kept for the summary (nothing is printed while the mission runs, so
     * the stack high-water mark is the mission's, not printf's) */
    tase_system_version_t version;
    tase_packet_rate_t rate_before;
    uint32_t spoi_echo_ms; /* SPOI command to its echo */
    /* host data */
    bool streaming;
    uint32_t next_att, next_gps;
    uint32_t att_sent, gps_sent, host_late, send_errors;
    /* telemetry, counted from the SPOI echo on */
    uint32_t angles, rates, georefs;
    uint32_t angles_all, rates_all, georefs_all, other, bad_length;
    uint8_t last_mode;
    uint32_t telem_at;        /* the last telemetry frame (or the rates' echo), ms */
    uint32_t spoi_mode_rates; /* GIMBAL_RATE in SPOI mode while tracking */
    tase_gimbal_angle_t last_angle;
    /* pointing, from GEOREFERENCE_DATA */
    bool tracking;
    float err_before;       /* last error before the SPOI command */
    uint32_t unaimed;       /* GEOREFERENCEs measured before the point was built */
    uint32_t held;          /* GEOREFERENCEs after the SPOI query */
    float err_held;         /* the error of the first of them */
    float err_first;        /* first error after it */
    uint32_t converged_ms;  /* after the echo; 0 = not yet */
    uint32_t after;         /* samples after convergence */
    uint32_t outside;       /* of them, beyond the tolerance */
    float err_max, err_sum; /* over `after` */
    uint32_t steady;        /* of them, from SETTLE_MS after the command on */
    float steady_max, steady_sum;
    uint32_t position_bad; /* host position/attitude not echoed */
    float pos_max_m;       /* largest distance of an echoed position from the circle */
    float yaw_max_deg;     /* largest echoed yaw off the heading at the echoed position */
    uint32_t spoi_at;      /* when the SPOI command was sent */
    uint32_t track_ms;     /* from then to the end of tracking */
    uint32_t now;
    /* checks */
    unsigned checks, failures;
    tase_rx_stats_t rx_mark; /* receiver counters at the first reply */
} mission_t;

static void check(mission_t *m, bool ok, const char *what, long got, long want)
{
    m->checks++;
    if (!ok) {
        m->failures++;
        printf("FAIL %s: got %ld, want %ld\n", what, got, want);
    }
}

/* ---- telemetry, through the dispatcher ---- */

static void on_angle(void *user, const tase_frame_t *f, const void *msg)
{
    mission_t *m = user;
    (void)f;
    m->angles_all++;
    m->telem_at = m->now;
    m->angles += m->tracking ? 1u : 0u;
    m->last_angle = *(const tase_gimbal_angle_t *)msg;
}

static void on_rate(void *user, const tase_frame_t *f, const void *msg)
{
    mission_t *m = user;
    const tase_gimbal_rate_t *r = msg;
    (void)f;
    m->rates_all++;
    m->telem_at = m->now;
    m->last_mode = (uint8_t)TASE_MODE_VALUE(r->mode);
    if (m->tracking) {
        m->rates++;
        m->spoi_mode_rates += m->last_mode == TASE_MODE_SPOI ? 1u : 0u;
    }
}

/* The navigation data the gimbal reports must be ours: a position on the
 * circle at our height, our bank and zero pitch, and a yaw that matches
 * the heading at that position (within what the aircraft turns between
 * two HOST_GPS_DATA: the attitude is sent more often). Only then does a
 * line of sight on the SPOI in the gimbal's frame mean one in ours. */
static void check_host_echo(mission_t *m, const tase_georeference_t *g)
{
    float n, e, off, dyaw;
    flight_offset(&plan, g->lat, g->lon, &n, &e);
    off = fabsf(sqrtf(n * n + e * e) - plan.radius_m);
    dyaw = fabsf(flight_angle_diff_deg((float)tase_units_cdeg_to_deg(g->mount_yaw),
                                       flight_heading_deg(n, e)));
    m->pos_max_m = off > m->pos_max_m ? off : m->pos_max_m;
    m->yaw_max_deg = dyaw > m->yaw_max_deg ? dyaw : m->yaw_max_deg;
    if (off > 0.5f || dyaw > YAW_TOLERANCE_DEG ||
        g->height != tase_units_m_to_cm((double)plan.height_m) ||
        g->mount_roll != tase_units_deg_to_cdeg((double)flight_bank_deg(&plan)) ||
        g->mount_pitch != 0) {
        m->position_bad++;
    }
}

static void on_georef(void *user, const tase_frame_t *f, const void *msg)
{
    mission_t *m = user;
    const tase_georeference_t *g = msg;
    float err = flight_pointing_error_deg(&plan, g, &m->spoi_req);
    (void)f;
    m->georefs_all++;
    m->telem_at = m->now;
    m->unaimed += m->spoi_built ? 0u : 1u;
    if (!m->tracking) {
        /* Before the command, or after tracking ended: a GEOREFERENCE of
         * the query's round trip or later is not "before" (it would hold
         * the converged error). */
        if (m->step <= STEP_WARMUP) {
            m->err_before = err;
        } else if (m->step == STEP_HOLD) {
            m->err_held = (m->held == 0u) ? err : m->err_held;
            m->held++;
        } else {
            /* during the query */
        }
        return;
    }
    m->georefs++;
    check_host_echo(m, g);
    if (m->georefs == 1u) {
        m->err_first = err;
    }
    if (m->converged_ms == 0u) {
        if (err <= TOLERANCE_DEG) {
            m->converged_ms = m->now - m->spoi_at;
            if (m->converged_ms == 0u) {
                m->converged_ms = 1u;
            }
        } else {
            return;
        }
    }
    m->after++;
    m->err_sum += err;
    if (err > m->err_max) {
        m->err_max = err;
    }
    if (err > TOLERANCE_DEG) {
        m->outside++;
    }
    if (m->now - m->spoi_at >= SETTLE_MS) {
        m->steady++;
        m->steady_sum += err;
        m->steady_max = err > m->steady_max ? err : m->steady_max;
    }
}

static void on_other(void *user, const tase_frame_t *f)
{
    mission_t *m = user;
    (void)f;
    m->other++; /* e.g. a late duplicate echo after a retry */
}

static void on_error(void *user, const tase_frame_t *f, int err)
{
    mission_t *m = user;
    (void)f;
    (void)err;
    m->bad_length++;
}

static const tase_packet_handler_t handlers[TASE_PKT_COUNT] = {
    [TASE_PKT_GIMBAL_ANGLE] = on_angle,
    [TASE_PKT_GIMBAL_RATE] = on_rate,
    [TASE_PKT_GEOREFERENCE_DATA] = on_georef,
};

/* ---- the mission ---- */

static void next_step(mission_t *m, step_t s)
{
    m->step = s;
    m->step_at = m->now;
}

static void abort_mission(mission_t *m, const char *what, int r)
{
    printf("FAIL %s: %s (%d)\n", what, r < 0 ? tase_strerror(r) : "unexpected reply", r);
    m->checks++;
    m->failures++;
    m->aborted_in = m->step;
    if (m->tracking) {
        m->tracking = false; /* the summary's rates over the time tracked */
        m->track_ms = m->now - m->spoi_at;
    }
    next_step(m, STEP_DONE);
}

/* Run one request across main-loop passes (msg NULL: a query). True once
 * the gimbal answered with `len` data bytes, decoded into m->reply; false
 * while waiting, or after aborting the mission on any other outcome. */
static bool answered(mission_t *m, uint16_t id, const void *msg, int len, const char *what)
{
    int r;
    if (!m->requesting) {
        r = tase_host_request_msg_start(&m->link.host, id, msg, &m->reply, REQUEST_TIMEOUT_MS,
                                        REQUEST_RETRIES, m->now);
        m->requesting = r == TASE_OK;
    } else {
        r = tase_host_poll(&m->link.host, m->now);
        m->requesting = r == TASE_EAGAIN;
    }
    if (r == len) {
        return true;
    }
    if (r == TASE_ETIMEOUT && m->step == STEP_VERSION && m->now - m->step_at < BOOT_WAIT_MS) {
        /* the gimbal may still be booting: ask again (m->requesting is
         * false: the next pass starts the request anew) */
        if (m->boot_timeouts == 0u) {
            printf("gimbal not answering yet: asking again for up to %u ms\n", BOOT_WAIT_MS);
        }
        m->boot_timeouts++;
        return false;
    }
    if (r != TASE_OK && r != TASE_EAGAIN) {
        abort_mission(m, what, r);
    }
    return false;
}

static const char *camera_name(uint8_t type)
{
    switch (type) {
    case TASE_CAMTYPE_SONY_FCB_EX1010: return "Sony FCB-EX1010";
    case TASE_CAMTYPE_FLIR_320_PHOTON_23: return "FLIR Photon 320, 23 mm";
    default: return "see the spec's table 28";
    }
}

static void report_version(const tase_system_version_t *v)
{
    const uint8_t type[3] = {v->camera_a, v->camera_b, v->camera_c};
    const uint16_t hmax[3] = {v->max_hfov_a, v->max_hfov_b, v->max_hfov_c};
    const uint16_t hmin[3] = {v->min_hfov_a, v->min_hfov_b, v->min_hfov_c};
    unsigned i;
    printf("gimbal: software %u.%u.%u%s (%04u-%02u-%02u), board s/n %lu rev %lu\n", v->major,
           v->minor, v->sub, v->released == 1u ? "" : " (test)", v->soft_year, v->soft_month,
           v->soft_day, (unsigned long)v->board_sn, (unsigned long)v->board_rev);
    for (i = 0; i < 3u; i++) {
        if (type[i] == TASE_CAMTYPE_NONE) {
            printf("  camera %c: none\n", 'A' + i);
        } else {
            printf("  camera %c: type %u (%s), HFOV %u.%02u..%u.%02u deg\n", 'A' + i, type[i],
                   camera_name(type[i]), hmin[i] / 100u, hmin[i] % 100u, hmax[i] / 100u,
                   hmax[i] % 100u);
        }
    }
}

/* Host data, each at its own rate, without drift; a slot missed by more
 * than a period is skipped (counted), never sent in a burst. */
static void send_host(mission_t *m, uint16_t id, const void *msg, uint32_t *next, uint32_t hz)
{
    m->send_errors += tase_host_send_msg(&m->link.host, id, msg) < 0 ? 1u : 0u;
    *next += 1000u / hz;
    if ((int32_t)(m->now - *next) >= 0) {
        m->host_late++;
        *next = m->now + 1000u / hz;
    }
}

static void stream(mission_t *m)
{
    flight_state_t s;
    bool att = (int32_t)(m->now - m->next_att) >= 0;
    bool gps = (int32_t)(m->now - m->next_gps) >= 0;
    if (!m->streaming || (!att && !gps)) {
        return;
    }
    flight_at(&plan, m->now - m->start, &s); /* the flight from the mission's start */
    if (att) {
        tase_host_attitude_t a;
        flight_attitude(&s, m->now - m->start, (uint8_t)ATT_HZ, &a);
        send_host(m, TASE_ID_HOST_ATTITUDE, &a, &m->next_att, ATT_HZ);
        m->att_sent++;
    }
    if (gps) {
        tase_host_gps_t g;
        flight_gps(&plan, &s, m->now - m->start, (uint8_t)GPS_HZ, &g);
        send_host(m, TASE_ID_HOST_GPS_DATA, &g, &m->next_gps, GPS_HZ);
        m->gps_sent++;
    }
}

/* NAV_SOURCE is ours: stream the host data from now on. */
static void start_host_data(mission_t *m)
{
    m->streaming = true;
    m->next_att = m->now;
    m->next_gps = m->now;
    next_step(m, STEP_WARMUP);
}

/* GIMBAL_PORT's rate of stream i (0 GIMBAL_ANGLE, 1 GIMBAL_RATE, 2
 * GEOREFERENCE_DATA) in a PACKET_RATE. */
static uint8_t *port_rate(tase_packet_rate_t *r, unsigned i)
{
    uint8_t *const rates[3][3] = {{&r->angle_1, &r->rate_1, &r->geo_ref_1},
                                  {&r->angle_2, &r->rate_2, &r->geo_ref_2},
                                  {&r->angle_3, &r->rate_3, &r->geo_ref_3}};
    return rates[GIMBAL_PORT - 1u][i];
}

static void run_step(mission_t *m)
{
    const tase_spoi_cmd_t *spoi = &m->reply.spoi_cmd;
    switch (m->step) {
    case STEP_VERSION:
        if (answered(m, TASE_ID_SYSTEM_VERSION, NULL, 42, "SYSTEM_VERSION query")) {
            m->rx_mark = m->link.host.rx.stats;
            m->version = m->reply.system_version;
            next_step(m, STEP_RATE_GET);
        }
        return;
    case STEP_RATE_GET:
        if (answered(m, TASE_ID_PACKET_RATE, NULL, 16, "PACKET_RATE query")) {
            /* read-modify-write: only GIMBAL_PORT (this line) changes */
            m->rate_before = m->reply.packet_rate;
            m->rate_req = m->reply.packet_rate;
            *port_rate(&m->rate_req, 0u) = (uint8_t)ANGLE_HZ;
            *port_rate(&m->rate_req, 1u) = (uint8_t)RATE_HZ;
            *port_rate(&m->rate_req, 2u) = (uint8_t)GEO_HZ;
            m->rate_req.temporary = 1u; /* a mission setting, not for flash */
            next_step(m, STEP_RATE_SET);
        }
        return;
    case STEP_RATE_SET:
        if (answered(m, TASE_ID_PACKET_RATE, &m->rate_req, 16, "PACKET_RATE setting")) {
            /* tase_packet_rate_t has only byte members: no padding */
            if (memcmp(&m->reply.packet_rate, &m->rate_req, sizeof(m->rate_req)) != 0) {
                abort_mission(m, "PACKET_RATE echo differs from the request", 16);
                return;
            }
            m->telem_at = m->now; /* telemetry expected from here on */
            next_step(m, STEP_NAV_GET);
        }
        return;
    case STEP_NAV_GET:
        if (answered(m, TASE_ID_NAV_SOURCE, NULL, 2, "NAV_SOURCE query")) {
            if (m->reply.nav_source.external_attitude != 0u &&
                m->reply.nav_source.external_gps != 0u) {
                m->nav_kept = true; /* nothing to change: nothing stored */
                start_host_data(m);
                return;
            }
            m->nav_req.external_attitude = 1u;
            m->nav_req.external_gps = 1u;
            next_step(m, STEP_NAV_SET);
        }
        return;
    case STEP_NAV_SET:
        if (answered(m, TASE_ID_NAV_SOURCE, &m->nav_req, 2, "NAV_SOURCE setting")) {
            if (m->reply.nav_source.external_attitude != 1u ||
                m->reply.nav_source.external_gps != 1u) {
                abort_mission(m, "NAV_SOURCE echo differs from the request", 2);
                return;
            }
            start_host_data(m);
        }
        return;
    case STEP_WARMUP:
        if (m->now - m->step_at >= WARMUP_MS) {
            /* From here on a GEOREFERENCE may reflect the command (it is
             * sent on the next pass): none counts as "before" any more. */
            m->spoi_at = m->now;
            m->tracking = true;
            next_step(m, STEP_SPOI);
        }
        return;
    case STEP_SPOI:
        if (answered(m, TASE_ID_SPOI_CMD, &m->spoi_req, 19, "SPOI_CMD")) {
            /* The echo's flags are the gimbal's (stabilisation, mode). */
            if (spoi->lat != m->spoi_req.lat || spoi->lon != m->spoi_req.lon ||
                spoi->height != m->spoi_req.height || spoi->vnorth != 0 || spoi->veast != 0 ||
                spoi->vdown != 0) {
                abort_mission(m, "SPOI_CMD echo differs from the command", 19);
                return;
            }
            m->spoi_echo_ms = m->now - m->step_at;
            next_step(m, STEP_TRACK);
        }
        return;
    case STEP_TRACK:
        if (m->now - m->step_at >= TRACK_MS) {
            m->tracking = false;
            m->track_ms = m->now - m->spoi_at;
            /* the query is the last frame sent: its reply shows the gimbal
             * read everything before it (autopilot.sh counts both ends) */
            m->streaming = false;
            next_step(m, STEP_SPOI_GET);
        }
        return;
    case STEP_SPOI_GET:
        if (answered(m, TASE_ID_SPOI_CMD, NULL, 19, "SPOI_CMD query")) {
            check(m,
                  spoi->lat == m->spoi_req.lat && spoi->lon == m->spoi_req.lon &&
                      spoi->height == m->spoi_req.height,
                  "SPOI query returns our point (lat difference, mas)",
                  (long)(spoi->lat - m->spoi_req.lat), 0);
            check(m, TASE_SPOI_MODE(spoi->flags) == TASE_MODE_SPOI, "SPOI query reports SPOI mode",
                  (long)TASE_SPOI_MODE(spoi->flags), TASE_MODE_SPOI);
            next_step(m, STEP_HOLD);
        }
        return;
    case STEP_HOLD:
        if (m->held > 0u || m->now - m->step_at >= HOLD_MS) {
            next_step(m, STEP_DONE);
        }
        return;
    case STEP_DONE: return;
    }
}

/* ---- the image's own size, from the linker script's symbols ---- */

extern const uint8_t __flash_end[], __tase_lib_start[], __tase_lib_end[];
extern const uint8_t __tase_port_start[], __tase_port_end[];
extern uint8_t _sdata[], _ebss[];

static unsigned long span(const uint8_t *a, const uint8_t *b)
{
    return (unsigned long)((uintptr_t)b - (uintptr_t)a);
}

static double per_s(uint32_t n, uint32_t ms)
{
    return ms > 0u ? (double)n * 1000.0 / (double)ms : 0.0;
}

static void summary(mission_t *m, unsigned long stack, const tase_bm_uart_t *uart)
{
    const tase_host_stats_t *hs = &m->link.host.stats;
    const tase_rx_stats_t *rs = &m->link.host.rx.stats;
    board_stats_t bs = board_stats();
    uint32_t track_ms = m->track_ms;
    uint32_t steady_ms = track_ms > SETTLE_MS ? track_ms - SETTLE_MS : 0u;
    /* how far it got (an abort ends in STEP_DONE too: a review saw the
     * summary confirm echoes of steps never reached) */
    step_t reached = m->aborted_in != STEP_DONE ? m->aborted_in : m->step;

    if (reached > STEP_VERSION) {
        report_version(&m->version);
        check(m, m->version.camera_a != TASE_CAMTYPE_NONE, "gimbal has camera A",
              m->version.camera_a, 0);
    }
    if (reached > STEP_RATE_SET) {
        printf("PACKET_RATE port %u: %u/%u/%u per s (angle/rate/georef), set to %u/%u/%u, echo "
               "confirmed\n",
               GIMBAL_PORT, *port_rate(&m->rate_before, 0u), *port_rate(&m->rate_before, 1u),
               *port_rate(&m->rate_before, 2u), ANGLE_HZ, RATE_HZ, GEO_HZ);
    }
    if (reached > STEP_NAV_SET) {
        printf("NAV_SOURCE: external attitude and GPS, %s; host data streamed\n",
               m->nav_kept ? "already (not sent)" : "echo confirmed");
    }
    if (reached > STEP_SPOI) {
        printf("SPOI_CMD at %.6f, %.6f, %.1f m, echo confirmed after %lu ms\n",
               tase_units_mas_to_deg(m->spoi_req.lat), tase_units_mas_to_deg(m->spoi_req.lon),
               tase_units_cm_to_m(m->spoi_req.height), (unsigned long)m->spoi_echo_ms);
    }
    printf("host role: %lu frames sent (%lu HOST_ATTITUDE, %lu HOST_GPS_DATA), %lu requests, "
           "%lu replies, %lu retries, %lu timeouts, %lu tx errors; %lu host data slots skipped\n",
           (unsigned long)hs->frames_tx, (unsigned long)m->att_sent, (unsigned long)m->gps_sent,
           (unsigned long)hs->requests, (unsigned long)hs->replies, (unsigned long)hs->retries,
           (unsigned long)hs->timeouts, (unsigned long)hs->tx_errors, (unsigned long)m->host_late);
    printf("rx: %lu bytes, %lu frames, %lu checksum errors, %lu bytes discarded (%lu before the "
           "first reply), %lu bad length, %lu unknown; UART %lu interrupts, %lu overruns, ring "
           "overflows %lu; SysTick %lu interrupts in %lu ms\n",
           (unsigned long)rs->bytes_in, (unsigned long)rs->frames_ok,
           (unsigned long)rs->checksum_errors, (unsigned long)rs->bytes_discarded,
           (unsigned long)m->rx_mark.bytes_discarded, (unsigned long)rs->bad_length,
           (unsigned long)rs->unknown, (unsigned long)bs.rx_irqs, (unsigned long)bs.rx_overruns,
           (unsigned long)tase_ring_overflows(&uart->rx), (unsigned long)bs.ticks,
           (unsigned long)(m->now - m->start));
    printf("telemetry while tracking (%lu ms): GIMBAL_ANGLE %lu (%.1f/s), GIMBAL_RATE %lu "
           "(%.1f/s, %lu in SPOI mode), GEOREFERENCE_DATA %lu (%.1f/s); %lu other frames\n",
           (unsigned long)track_ms, (unsigned long)m->angles, per_s(m->angles, track_ms),
           (unsigned long)m->rates, per_s(m->rates, track_ms), (unsigned long)m->spoi_mode_rates,
           (unsigned long)m->georefs, per_s(m->georefs, track_ms), (unsigned long)m->other);
    printf("pointing: error %.2f deg before the SPOI command, %.2f at the first GEOREFERENCE after "
           "it; within %.1f deg %lu ms after it; then %lu samples, mean %.3f, max %.3f deg, %lu "
           "outside; "
           "from %lu ms on: %lu samples, mean %.3f, max %.3f deg; host position echoed within "
           "%.2f m of the circle, yaw within %.2f deg of the heading there\n",
           (double)m->err_before, (double)m->err_first, (double)TOLERANCE_DEG,
           (unsigned long)m->converged_ms, (unsigned long)m->after,
           m->after > 0u ? (double)(m->err_sum / (float)m->after) : 0.0, (double)m->err_max,
           (unsigned long)m->outside, (unsigned long)SETTLE_MS, (unsigned long)m->steady,
           m->steady > 0u ? (double)(m->steady_sum / (float)m->steady) : 0.0, (double)m->steady_max,
           (double)m->pos_max_m, (double)m->yaw_max_deg);
    printf("after the SPOI query (host data stopped): error %.2f deg at the next "
           "GEOREFERENCE (%lu within %lu ms)\n",
           (double)m->err_held, (unsigned long)m->held, (unsigned long)HOLD_MS);

    check(m, reached == STEP_DONE && !m->requesting, "mission completed (the step reached)",
          (long)reached, STEP_DONE);
    check(m, hs->timeouts == m->boot_timeouts,
          "requests timed out (beyond the wait for the gimbal to boot)",
          (long)(hs->timeouts - m->boot_timeouts), 0);
    check(m, hs->tx_errors == 0u && m->send_errors == 0u && bs.tx_timeouts == 0u,
          "transmit errors (host role)", (long)hs->tx_errors, 0);
    check(m, rs->checksum_errors == m->rx_mark.checksum_errors,
          "clean link after the first reply (checksum errors)",
          (long)(rs->checksum_errors - m->rx_mark.checksum_errors), 0);
    check(m, rs->bytes_discarded == m->rx_mark.bytes_discarded,
          "clean link after the first reply (bytes discarded)",
          (long)(rs->bytes_discarded - m->rx_mark.bytes_discarded), 0);
    check(m, rs->bad_length == 0u && rs->unknown == 0u, "bad length or unknown frames",
          (long)(rs->bad_length + rs->unknown), 0);
    check(m, bs.rx_overruns == 0u && tase_ring_overflows(&uart->rx) == 0u, "receive overruns",
          (long)(bs.rx_overruns + tase_ring_overflows(&uart->rx)), 0);
    /* Every stream alive: a quarter of the asked rate at least (the
     * simulator shares the host with other work, and a late pass skips
     * the slots it missed, of every stream alike). That the PACKET_RATE
     * setting took is in the ratios, which such skips leave as they are:
     * the defaults 10/10/4 give GEOREFERENCE/GIMBAL_RATE 0.4 and
     * GIMBAL_ANGLE/GIMBAL_RATE 1.0, the setting 1.0 and 2.0. */
    check(m, m->angles * 4u >= ANGLE_HZ * track_ms / 1000u, "GIMBAL_ANGLE frames while tracking",
          (long)m->angles, (long)(ANGLE_HZ * track_ms / 1000u));
    check(m, m->rates * 4u >= RATE_HZ * track_ms / 1000u, "GIMBAL_RATE frames while tracking",
          (long)m->rates, (long)(RATE_HZ * track_ms / 1000u));
    check(m, m->georefs * 4u >= GEO_HZ * track_ms / 1000u,
          "GEOREFERENCE_DATA frames while tracking", (long)m->georefs,
          (long)(GEO_HZ * track_ms / 1000u));
    check(m, m->georefs * 10u >= m->rates * 7u,
          "GEOREFERENCE_DATA per GIMBAL_RATE, x100 (the default rates give 40)",
          (long)(m->georefs * 100u / (m->rates > 0u ? m->rates : 1u)), 70);
    check(m, m->angles * 10u >= m->rates * 15u,
          "GIMBAL_ANGLE per GIMBAL_RATE, x100 (the default rates give 100)",
          (long)(m->angles * 100u / (m->rates > 0u ? m->rates : 1u)), 150);
    check(m, m->last_mode == TASE_MODE_SPOI, "gimbal mode at the end (GIMBAL_RATE)",
          (long)m->last_mode, TASE_MODE_SPOI);
    check(m, m->unaimed == 0u, "GEOREFERENCEs measured against a SPOI not yet built",
          (long)m->unaimed, 0);
    check(m, m->err_before > 5.0f * TOLERANCE_DEG,
          "pointing error before the SPOI is large (so convergence means something), deg x100",
          (long)(m->err_before * 100.0f), (long)(500.0f * TOLERANCE_DEG));
    check(m, m->converged_ms > 0u && m->converged_ms <= SETTLE_MS,
          "line of sight within tolerance after (ms)", (long)m->converged_ms, SETTLE_MS);
    check(m, m->steady * 4u >= GEO_HZ * steady_ms / 1000u,
          "GEOREFERENCE samples after the settling time", (long)m->steady,
          (long)(GEO_HZ * steady_ms / 1000u));
    check(m, m->outside == 0u, "samples beyond the tolerance after convergence", (long)m->outside,
          0);
    check(m, m->position_bad == 0u, "GEOREFERENCE host position/attitude not what we sent",
          (long)m->position_bad, 0);
    check(m, m->held > 0u, "GEOREFERENCE_DATA after the SPOI query", (long)m->held, 1);
    check(m, m->held > 0u && m->err_held <= TOLERANCE_DEG,
          "line of sight on the SPOI after the query, deg x100", (long)(m->err_held * 100.0f),
          (long)(100.0f * TOLERANCE_DEG));

    printf("image: flash %lu B (library %lu B, bare-metal port %lu B), RAM %lu B static + %lu B "
           "stack used\n",
           span((const uint8_t *)0, __flash_end), span(__tase_lib_start, __tase_lib_end),
           span(__tase_port_start, __tase_port_end), span(_sdata, _ebss), stack);
    printf("library instances in RAM: tase_host_t %lu (its tase_rx_t %lu), tase_dispatch_t %lu, "
           "tase_bm_uart_t %lu + ring %lu\n",
           (unsigned long)sizeof(tase_host_t), (unsigned long)sizeof(tase_rx_t),
           (unsigned long)sizeof(tase_dispatch_t), (unsigned long)sizeof(tase_bm_uart_t),
           (unsigned long)RING_SIZE);
}

int main(void)
{
    static uint8_t ring_storage[RING_SIZE];
    static tase_bm_uart_t uart;
    static const tase_bm_uart_hooks_t hooks = {board_uart_tx, board_millis, NULL, NULL, NULL};
    static mission_t m;
    tase_port_t port;
    uint32_t last = 0;
    unsigned long stack;
    int r;

    r = tase_bm_uart_init(&uart, ring_storage, sizeof ring_storage, &hooks, NULL);
    port = tase_bm_uart_port(&uart);
    port.bytes_per_s = TASE_UART_BYTES_PER_S(BOARD_BAUD); /* the gimbal line: the time bound */
    if (r != TASE_OK || (r = link_init(&m.link, &port, handlers, on_other, on_error, &m)) != 0) {
        printf("FAIL init: %s\n", tase_strerror(r));
        return 1;
    }
    /* The point is built first: every GEOREFERENCE, the ones before the
     * command included, is measured against it (an error against a point
     * not yet built, 0 deg N 0 deg E, depends on where the circle has
     * taken the aircraft and could be anything). */
    r = flight_spoi(&plan, SPOI_NORTH_M, SPOI_EAST_M, SPOI_HEIGHT_M, (uint8_t)TASE_SPOI_ECHO,
                    &m.spoi_req);
    if (r != TASE_OK) {
        printf("FAIL SPOI_CMD position: %s\n", tase_strerror(r)); /* nothing sent */
        return 1;
    }
    m.spoi_built = true;
    board_init(&uart);
    m.now = board_millis(NULL);
    m.start = m.now;
    m.next_att = m.start; /* host data due from the start (0 is not the start) */
    m.next_gps = m.start;
    m.aborted_in = STEP_DONE; /* not aborted */
    next_step(&m, STEP_VERSION);

    while (m.step != STEP_DONE) {
        board_sleep(); /* until SysTick or a received byte */
        m.now = board_millis(NULL);
        r = link_service(&m.link, READS_PER_WAKE);
        if (r < 0) {
            abort_mission(&m, "receive", r);
        }
        if (m.now == last) {
            continue;
        }
        last = m.now;
        run_step(&m);
        if (m.step >= STEP_WARMUP && m.step != STEP_DONE &&
            m.now - m.telem_at >= TELEMETRY_LOST_MS) {
            abort_mission(&m, "gimbal telemetry stopped (TELEMETRY_LOST_MS without a frame)",
                          TASE_ETIMEOUT);
        }
        stream(&m);
        if (m.step != STEP_DONE && m.now - m.start >= MISSION_MS) { /* across a wrap too */
            abort_mission(&m, "mission time limit", TASE_ETIMEOUT);
        }
    }
    stack = board_stack_used(); /* before printf, which is not ours */
    board_stop();
    printf("TASE autopilot example on Cortex-M4F (mps2-an386): SPOI mission on UART0, %lu ms\n",
           (unsigned long)(m.now - m.start));
    summary(&m, stack, &uart);
    printf("%s: %u of %u checks failed\n", m.failures == 0u ? "PASS" : "FAIL", m.failures,
           m.checks);
    return m.failures == 0u ? 0 : 1;
}
