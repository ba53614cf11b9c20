/* tase-sim's physical model (tools/sim_model.c): motion modes, limits,
 * SPOI geometry against hand-computed values and against an independent
 * WGS-84 computation, navigation sources, cameras, the measured packet
 * rate, and the status words of tools/sim_words.h. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "../tools/sim_model.h"
#include "../tools/sim_words.h"

#define PI 3.14159265358979323846
#define E2 (SIM_WGS84_F * (2.0 - SIM_WGS84_F))

/* Degrees of latitude / longitude spanned by `m` metres at latitude lat
 * on the WGS-84 ellipsoid (meridian and parallel radii; good for the
 * 100 m offsets below, to a few 1e-4 degree of pointing). */
static double north_deg(double lat, double m)
{
    double s = sin(lat * PI / 180.0);
    return m / (SIM_WGS84_A * (1.0 - E2) / pow(1.0 - E2 * s * s, 1.5)) * 180.0 / PI;
}
static double east_deg(double lat, double m)
{
    double s = sin(lat * PI / 180.0), c = cos(lat * PI / 180.0);
    return m / (SIM_WGS84_A / sqrt(1.0 - E2 * s * s) * c) * 180.0 / PI;
}

static void near(double got, double want, double tol)
{
    if (fabs(got - want) > tol) {
        print_error("got %.9f, want %.9f (tolerance %g)\n", got, want, tol);
        fail();
    }
}

static void run(sim_model_t *m, double seconds)
{
    int i, n = (int)lround(seconds / 0.01);
    for (i = 0; i < n; i++) {
        sim_model_step(m, 0.01);
    }
}

static void rate_command_integrates_both_axes(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 10.0, -5.0, 0x10, 0.0), 0);
    run(&m, 1.0);
    near(m.pan, 10.0, 1e-9);
    near(m.tilt, -5.0, 1e-9);
    near(m.pan_rate, 10.0, 1e-9);
    assert_false(m.stabilised);
    assert_int_equal(sim_model_command(&m, 0.0, 0.0, 0x90, 0.0), 0);
    assert_true(m.stabilised);
}

static void rate_is_clamped_to_axis_max_rate(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.max_rate = 20.0;
    sim_model_command(&m, 100.0, 0.0, 0x10, 0.0);
    run(&m, 1.0);
    near(m.pan, 20.0, 1e-9);
    near(m.pan_rate, 20.0, 1e-9);
}

static void position_command_uses_gain_then_settles(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 30.0, -20.0, 0x20, 0.0), 0);
    /* gain 4 (deg/s)/deg: first 0.1 s step moves 4 * 30 * 0.1 = 12 deg */
    sim_model_step(&m, 0.1);
    near(m.pan, 12.0, 1e-9);
    near(m.tilt, -8.0, 1e-9);
    run(&m, 5.0);
    near(m.pan, 30.0, 1e-6);
    near(m.tilt, -20.0, 1e-6);
}

static void position_pan_takes_short_way_across_180(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    sim_model_command(&m, 170.0, 0.0, 0x20, 0.0);
    run(&m, 5.0);
    sim_model_command(&m, -170.0, 0.0, 0x20, 0.0);
    sim_model_step(&m, 0.01);
    assert_true(m.pan_rate > 0.0); /* 170 -> 180 -> -170: 20 deg the positive way */
    run(&m, 5.0);
    near(m.pan, -170.0, 1e-6);
}

static void impulse_moves_for_impulse_time_only(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 10.0, 4.0, 0x30, 0.5), 0);
    run(&m, 2.0);
    near(m.pan, 5.0, 1e-9);
    near(m.tilt, 2.0, 1e-9);
    near(m.pan_rate, 0.0, 1e-12);
}

static void rate_stops_at_pan_nogo_edge(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.nogo_center = 90.0;
    m.axis_pan.nogo_range = 20.0; /* forbidden: 80..100 */
    sim_model_command(&m, 50.0, 0.0, 0x10, 0.0);
    run(&m, 3.0);
    near(m.pan, 80.0, 1e-9);
    near(m.pan_rate, 0.0, 1e-9);
}

static void default_tilt_nogo_blocks_looking_above_60(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    sim_model_command(&m, 0.0, 50.0, 0x10, 0.0);
    run(&m, 3.0);
    near(m.tilt, 60.0, 1e-9);
}

static void position_goes_round_the_nogo_zone(void **state)
{
    sim_model_t m;
    int i;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.nogo_center = 90.0;
    m.axis_pan.nogo_range = 20.0;
    sim_model_command(&m, 170.0, 0.0, 0x20, 0.0);
    sim_model_step(&m, 0.01);
    assert_true(m.pan < 0.0); /* the short way (+170) crosses 80..100 */
    for (i = 0; i < 2000; i++) {
        sim_model_step(&m, 0.01);
        assert_false(m.pan > 80.0 + 1e-6 && m.pan < 100.0 - 1e-6);
    }
    near(m.pan, 170.0, 1e-6);
}

static void position_target_inside_nogo_goes_to_nearest_edge(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.nogo_center = 90.0;
    m.axis_pan.nogo_range = 20.0;
    sim_model_command(&m, 85.0, 0.0, 0x20, 0.0);
    run(&m, 5.0);
    near(m.pan, 80.0, 1e-6);
}

/* A review: a no-go range of 360 deg (4.4.3's maximum: nowhere to go)
 * left the axis free (it is always "inside" the zone, and an axis inside
 * may move anywhere): a 50 deg/s rate moved it 65 deg. */
static void a_nogo_zone_of_the_whole_turn_holds_the_axis(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.nogo_center = 90.0; /* the axis (at 0) inside it */
    m.axis_pan.nogo_range = 360.0;
    sim_model_command(&m, 50.0, 0.0, 0x10, 0.0);
    run(&m, 2.0);
    near(m.pan, 0.0, 1e-9);
    sim_model_command(&m, 120.0, 0.0, 0x20, 0.0);
    run(&m, 2.0);
    near(m.pan, 0.0, 1e-9);
}

/* A review: after CAMERA_TYPE removed every camera, LEGACY_CAMERA_CMD set
 * camera A's HFOV to NaN (a lens of 0..0 deg) and a CAMERA_CMD "no change
 * of camera" set the removed one's HFOV to 0. */
static void camera_commands_refuse_a_removed_camera(void **state)
{
    sim_model_t m;
    const uint8_t none[SIM_CAMERAS] = {TASE_CAMTYPE_NONE, TASE_CAMTYPE_NONE, TASE_CAMTYPE_NONE};
    (void)state;
    sim_model_init(&m);
    sim_model_camera_types(&m, none);
    assert_int_equal(sim_model_camera_legacy_zoom(&m, 0x2000u), SIM_CAM_NO_CAMERA);
    assert_int_equal(sim_model_camera_cmd(&m, TASE_CAMERA_NO_CHANGE, true, 10.0),
                     SIM_CAM_NO_CAMERA);
    assert_true(m.cam[0].hfov >= 0.0); /* not NaN: every comparison with it is false */
    near(m.cam[0].hfov, 0.0, 0.0);
    near(m.cam[m.active_cam].hfov, 0.0, 0.0);
}

static void unknown_gimbal_flags_are_rejected(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 10.0, 0.0, 0x55, 0.0), -1);
    assert_int_equal(m.mode, SIM_MODE_RATE);
    near(m.cmd_pan, 0.0, 0.0);
}

static void spoi_error_forms_change_nothing_outside_spoi(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 30.0, -10.0, 0x20, 0.0), 0);
    /* outside SPOI the error forms change nothing */
    assert_int_equal(sim_model_command(&m, 1.0, 2.0, 0xC0, 0.0), SIM_CMD_NOT_SPOI);
    assert_int_equal(sim_model_command(&m, 1.0, 2.0, 0xD0, 0.0), SIM_CMD_NOT_SPOI);
    assert_int_equal(m.mode, SIM_MODE_POSITION);
    assert_false(m.stabilised);
    near(m.cmd_pan, 30.0, 0.0);
    near(m.cmd_tilt, -10.0, 0.0);
}

static void spoi_angles_level_host(void **state)
{
    sim_pos_t host = {0.0, 0.0, 100.0, 0.0, 0.0, 0.0};
    sim_att_t att = {0.0, 0.0, 0.0};
    sim_pos_t t = host;
    double pan, tilt;
    (void)state;
    /* 100 m north, 100 m below: straight ahead, 45 degrees down (the
     * earth's curvature over 100 m is worth 5e-4 degree) */
    t.lat = north_deg(0.0, 100.0);
    t.height = 0.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-6);
    near(tilt, -45.0, 1e-3);
    /* 100 m east at the same height: right, level */
    t = host;
    t.lon = east_deg(0.0, 100.0);
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 90.0, 1e-6);
    near(tilt, 0.0, 1e-3);
    /* 100 m west, 100 m up... but 50 m south: pan atan2(-100,-50) */
    t = host;
    t.lat = -north_deg(0.0, 50.0);
    t.lon = -east_deg(0.0, 100.0);
    t.height = 100.0 + sqrt(100.0 * 100.0 + 50.0 * 50.0);
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, -180.0 + atan(2.0) * 180.0 / PI, 3e-3); /* -116.565 */
    near(tilt, 45.0, 3e-3);
}

static void spoi_angles_account_for_latitude_and_attitude(void **state)
{
    sim_pos_t host = {60.0, 10.0, 0.0, 0.0, 0.0, 0.0};
    sim_att_t att = {0.0, 0.0, 0.0};
    sim_pos_t t = host;
    double pan, tilt;
    (void)state;
    /* 100 m north and 100 m east at 60 N */
    t.lat += north_deg(60.0, 100.0);
    t.lon += east_deg(60.0, 100.0);
    sim_spoi_angles(&host, &att, &t, &pan, &tilt); /* parallels curve: 1e-3 deg */
    near(pan, 45.0, 3e-3);
    /* heading 90 (east): an east target is straight ahead */
    t = host;
    t.lon += east_deg(60.0, 100.0);
    att.yaw = 90.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-3);
    near(tilt, 0.0, 1e-3);
    /* nose up 10 degrees: a level target ahead is 10 degrees below the mount plane */
    att.pitch = 10.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-3);
    near(tilt, -10.0, 1e-3);
    /* heading north, right wing down 90: an east target is straight "up" in the mount */
    att.pitch = 0.0;
    att.yaw = 0.0;
    att.roll = 90.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(tilt, 90.0, 1e-3);
}

static void spoi_mode_drives_axes_to_the_target(void **state)
{
    sim_model_t m;
    sim_pos_t t;
    (void)state;
    sim_model_init(&m);
    m.host.lat = 0.0;
    m.host.lon = 0.0;
    m.host.height = 100.0;
    t = m.host;
    t.lon = east_deg(0.0, 100.0);
    t.height = 0.0; /* 100 m east, 100 m down */
    assert_int_equal(sim_model_spoi(&m, &t), SIM_CMD_OK);
    run(&m, 5.0);
    assert_int_equal(m.mode, SIM_MODE_SPOI);
    near(m.pan, 90.0, 1e-3);
    near(m.tilt, -45.0, 1e-3);
}

static void retract_completes_after_its_duration_once(void **state)
{
    sim_model_t m;
    int i, done = 0;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(m.tax, SIM_3AX_DEPLOYED);
    sim_model_retract_deploy(&m, false);
    assert_int_equal(m.tax, SIM_3AX_MOVING);
    for (i = 0; i < 150; i++) {
        done += sim_model_step(&m, 0.01) ? 1 : 0;
    }
    assert_int_equal(done, 0); /* 1.5 s of a 2 s move */
    for (i = 0; i < 100; i++) {
        done += sim_model_step(&m, 0.01) ? 1 : 0;
    }
    assert_int_equal(done, 1);
    assert_int_equal(m.tax, SIM_3AX_RETRACTED);
}

static void camera_euler_combines_mount_and_axes(void **state)
{
    sim_model_t m;
    double r, p, y;
    (void)state;
    sim_model_init(&m);
    m.att.yaw = 30.0;
    m.pan = 20.0;
    m.tilt = -10.0;
    sim_model_camera_euler(&m, &r, &p, &y);
    near(y, 50.0, 1e-9);
    near(p, -10.0, 1e-9);
    near(r, 0.0, 1e-9);
}

/* ---- issue 23 ---- */

/* Item 1: the SPOI flags carry stabilisation and the mode, 3AX bits clear. */
static void spoi_flags_carry_stabilisation_and_mode_only(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    m.mode = SIM_MODE_SPOI;
    m.stabilised = true; /* deployed, as after init */
    assert_int_equal(sim_spoi_flags(&m), 0x82);
    m.mode = SIM_MODE_POSITION;
    m.stabilised = false;
    m.tax = SIM_3AX_RETRACTED;
    assert_int_equal(sim_spoi_flags(&m), 0x01);
    /* the Mode byte itself still carries the 3AX state */
    assert_int_equal(sim_mode_byte(&m), 0x21);
}

static void point_east_down(sim_model_t *m)
{
    sim_pos_t t;
    m->host.lat = 0.0;
    m->host.lon = 0.0;
    m->host.height = 100.0;
    t = m->host;
    t.lon = east_deg(0.0, 100.0);
    t.height = 0.0; /* 100 m east, 100 m down: pan 90, tilt -45 */
    assert_int_equal(sim_model_spoi(m, &t), SIM_CMD_OK);
    run(m, 5.0);
}

/* Item 2: an impulse during SPOI shifts the SPOI pointing error (a rate
 * held for impulse_time) and the gimbal stays in SPOI. */
static void impulse_in_spoi_shifts_the_error_and_stays_in_spoi(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    point_east_down(&m);
    assert_int_equal(sim_model_command(&m, 4.0, -2.0, 0x30, 0.5), SIM_CMD_OK);
    assert_int_equal(m.mode, SIM_MODE_SPOI);
    run(&m, 5.0);
    assert_int_equal(m.mode, SIM_MODE_SPOI);
    assert_false(m.stabilised); /* 0x30: stabilisation off */
    near(m.err_pan, 2.0, 1e-9);
    near(m.err_tilt, -1.0, 1e-9);
    near(m.pan, 92.0, 1e-3);
    near(m.tilt, -46.0, 1e-3);
    /* 0xC0 sets the error, 0xD0 its rate; a new SPOI clears both */
    assert_int_equal(sim_model_command(&m, -3.0, 1.0, 0xC0, 0.0), SIM_CMD_OK);
    assert_true(m.stabilised);
    run(&m, 3.0);
    near(m.pan, 87.0, 1e-3);
    near(m.tilt, -44.0, 1e-3);
    assert_int_equal(sim_model_command(&m, 1.0, 0.0, 0xD0, 0.0), SIM_CMD_OK);
    run(&m, 2.0);
    near(m.err_pan, -1.0, 1e-6);
    point_east_down(&m);
    near(m.err_pan, 0.0, 0.0);
    near(m.pan, 90.0, 1e-3);
}

/* C14: an impulse (and the 0xD0 error rate) in SPOI is bounded by the
 * axis's max rate, as the same packet is outside SPOI: 100 deg/s for 1 s
 * with a 10 deg/s max rate shifts the error 10 deg, not 100. */
static void impulse_in_spoi_is_bounded_by_the_max_rate(void **state)
{
    sim_model_t m;
    sim_model_t out;
    (void)state;
    sim_model_init(&m);
    m.axis_pan.max_rate = 10.0;
    m.axis_tilt.max_rate = 10.0;
    out = m;
    point_east_down(&m);
    assert_int_equal(sim_model_command(&m, 100.0, -100.0, 0xB0, 1.0), SIM_CMD_OK);
    run(&m, 3.0);
    assert_int_equal(m.mode, SIM_MODE_SPOI);
    near(m.err_pan, 10.0, 1e-9);
    near(m.err_tilt, -10.0, 1e-9);
    assert_int_equal(sim_model_command(&m, 100.0, 0.0, 0xD0, 0.0), SIM_CMD_OK);
    run(&m, 1.0);
    near(m.err_pan, 20.0, 1e-6);
    /* the same impulse outside SPOI: 10 deg */
    assert_int_equal(sim_model_command(&out, 100.0, 0.0, 0xB0, 1.0), SIM_CMD_OK);
    run(&out, 3.0);
    near(out.pan, 10.0, 1e-3);
}

/* Item 3: tilt runs in the spec's -270..90, through -180, to the far edge
 * of the default no-go zone (120 = -240); a position target below -180 is
 * reached and reported as such. */
static void tilt_uses_the_spec_range_minus_270_to_90(void **state)
{
    sim_model_t m;
    int i;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 0.0, -50.0, 0x10, 0.0), SIM_CMD_OK);
    for (i = 0; i < 700; i++) {
        sim_model_step(&m, 0.01);
        assert_true(m.tilt >= -270.0 && m.tilt < 90.0);
    }
    near(m.tilt, -240.0, 1e-9);
    sim_model_init(&m);
    sim_model_command(&m, 0.0, -200.0, 0x20, 0.0);
    run(&m, 10.0);
    near(m.tilt, -200.0, 1e-6);
    /* a free-running tilt wraps from 90 to -270 */
    sim_model_init(&m);
    m.axis_tilt.nogo_range = 0.0;
    m.tilt = 80.0;
    sim_model_command(&m, 0.0, 50.0, 0x10, 0.0);
    run(&m, 0.4);
    near(m.tilt, -260.0, 1e-9);
}

/* Item 4: which PACKET_RATE port the simulator's link is (A2). */
static void link_port_follows_a2(void **state)
{
    (void)state;
    assert_int_equal(sim_link_port(false, 57600), 1); /* Com3, port 2 */
    assert_int_equal(sim_link_port(false, 115200), 1);
    assert_int_equal(sim_link_port(false, 9600), 0); /* Com2, port 1 */
    assert_int_equal(sim_link_port(true, 0), 2);     /* CAN, port 3 */
}

/* Item 5: the sample rate is the rate achieved, not the one asked. */
static void rate_meter_measures_what_was_sent(void **state)
{
    sim_rate_meter_t r;
    uint32_t t;
    unsigned k = 0;
    (void)state;
    sim_rate_reset(&r, 1000);
    assert_int_equal(sim_rate_hz(&r, 1000), 0);
    sim_rate_note(&r, 1250); /* first packet one period after the reset */
    assert_int_equal(sim_rate_hz(&r, 1250), 4);
    for (t = 1500; t <= 5000; t += 250) {
        sim_rate_note(&r, t + (t % 3u)); /* a few ms of poll jitter */
    }
    assert_int_equal(sim_rate_hz(&r, 5002), 4);
    /* 255/s asked, about one slot in eight sent: every 34 ms */
    sim_rate_reset(&r, 10000);
    for (t = 10034; t < 13000; t += 34) {
        sim_rate_note(&r, t);
        k++;
    }
    assert_int_equal(sim_rate_hz(&r, t), 29);
    assert_true(k > 80);
    /* nothing sent for over two seconds: none measured */
    assert_int_equal(sim_rate_hz(&r, t + 2100), 0);
}

/* Item 6: CAMERA_PASS answers with the interface's baud in force and
 * disables camera control. */
static void camera_pass_reports_its_baud_and_disables_camera_control(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_camera_cmd(&m, 0, true, 10.0), SIM_CAM_OK);
    near(m.cam[0].hfov, 10.0, 1e-9);
    assert_int_equal(sim_model_camera_pass(&m, 0, 0), 8); /* 0: no change, 9600 */
    assert_int_equal(sim_model_camera_pass(&m, 1, 16), 16);
    assert_int_equal(sim_model_camera_pass(&m, 2, 0), SIM_CAM_NO_CAMERA);
    assert_int_equal(sim_model_camera_cmd(&m, 1, true, 20.0), SIM_CAM_PASS_THROUGH);
    assert_int_equal(sim_model_camera_cmd(&m, 0xFF, true, 20.0), SIM_CAM_PASS_THROUGH);
    assert_int_equal(sim_model_camera_legacy_zoom(&m, 0x4000), SIM_CAM_PASS_THROUGH);
    assert_int_equal(m.active_cam, 0);
    near(m.cam[0].hfov, 10.0, 1e-9);
}

/* A zoom ratio (CAMERA_CMD hfov negative: ratio x 100) is the focal
 * length's, so GEOREFERENCE_DATA's focal length is that many times the
 * widest's (a review: max_hfov / ratio gave 2.141x at 2x, 10.935x at 10x) */
static void a_zoom_ratio_is_the_focal_lengths(void **state)
{
    sim_model_t m;
    double wide, r;
    (void)state;
    sim_model_init(&m);
    wide = tan(m.cam[0].max_hfov * PI / 360.0);
    for (r = 2.0; r <= 10.0; r += 8.0) {
        assert_int_equal(sim_model_camera_cmd(&m, 0, true, -r), SIM_CAM_OK);
        near(wide / tan(m.cam[0].hfov * PI / 360.0), r, 1e-9);
    }
    near(m.cam[0].hfov, 2.0 * atan(wide / 10.0) * 180.0 / PI, 1e-9);
}

/* A moving SPOI carried over a pole comes down the meridian on the other
 * side (a review: its latitude went past 90, 90.0053 in the SPOI_CMD
 * echo); one moving elsewhere is tracked without the position loop's lag
 * (a review: 5.05 deg of pan behind a target crossing at 100 m/s north,
 * 200 m/s west, about 4 km off) */
static void a_moving_spoi_crosses_a_pole(void **state)
{
    sim_model_t m;
    sim_pos_t t;
    (void)state;
    sim_model_init(&m);
    m.host.lat = 89.99;
    m.host.lon = 0.0;
    m.host.height = 1500.0;
    t = m.host;
    t.lat = 89.99995;
    t.height = 0.0;
    t.vn = 300.0;
    assert_int_equal(sim_model_spoi(&m, &t), SIM_CMD_OK);
    run(&m, 3.0);
    assert_true(m.spoi.lat <= 90.0);
    near(fabs(m.spoi.lon), 180.0, 1e-6);
    assert_true(m.spoi.vn < 0.0);
    near(m.spoi.lat, 90.0 - (300.0 * 3.0 - 0.00005 * 111694.0) / 111694.0, 2e-4);
}

static void a_moving_spoi_is_tracked_without_lag(void **state)
{
    sim_model_t m;
    sim_pos_t t;
    double pan, tilt;
    int i;
    (void)state;
    sim_model_init(&m);
    m.host.lat = 45.0;
    m.host.lon = 7.0;
    m.host.height = 1500.0;
    t = m.host;
    t.lat = 45.0 + north_deg(45.0, 2000.0);
    t.lon = 7.0 + east_deg(45.0, 3000.0);
    t.height = 0.0;
    t.vn = 100.0;
    t.ve = -200.0;
    assert_int_equal(sim_model_spoi(&m, &t), SIM_CMD_OK);
    for (i = 0; i < 1000; i++) { /* 10 s: settled, the target 2.2 km on */
        sim_model_step(&m, 0.01);
    }
    sim_spoi_angles(&m.host, &m.att, &m.spoi, &pan, &tilt);
    near(sim_wrap180(m.pan - pan), 0.0, 0.02);
    near(m.tilt - tilt, 0.0, 0.02);
}

/* Item 7: host navigation data is used only where NAV_SOURCE selects it
 * (and HOST_GPS_DATA only when valid); CAMERA_TYPE changes the cameras. */
static void navigation_sources_select_host_data(void **state)
{
    sim_model_t m;
    sim_pos_t gps = {10.0, 20.0, 500.0, 1.0, 2.0, 0.0};
    sim_att_t att = {5.0, -3.0, 120.0};
    uint8_t types[SIM_CAMERAS] = {0, 0, 98};
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_host_gps(&m, &gps, true), SIM_NAV_NOT_SELECTED);
    assert_int_equal(sim_model_host_attitude(&m, &att, false, false), SIM_NAV_NOT_SELECTED);
    near(m.host.lat, 45.0, 0.0); /* the gimbal's own solution */
    near(m.att.yaw, 0.0, 0.0);
    sim_model_nav_source(&m, true, true);
    near(m.host.lat, 10.0, 0.0);
    near(m.att.yaw, 120.0, 0.0);
    gps.lat = 11.0;
    assert_int_equal(sim_model_host_gps(&m, &gps, false), SIM_NAV_INVALID);
    near(m.host.lat, 10.0, 0.0);
    assert_int_equal(sim_model_host_gps(&m, &gps, true), SIM_NAV_USED);
    near(m.host.lat, 11.0, 0.0);
    sim_model_nav_source(&m, false, false);
    near(m.host.lat, 45.0, 0.0);
    /* HOST_ATTITUDE flags act on the own solution whatever NAV_SOURCE says */
    assert_int_equal(sim_model_host_attitude(&m, &att, false, true), SIM_NAV_AID_YAW);
    near(m.att.yaw, 120.0, 0.0);
    near(m.att.roll, 0.0, 0.0);
    assert_int_equal(sim_model_host_attitude(&m, &att, true, false), SIM_NAV_OVERWRITE);
    near(m.att.roll, 5.0, 0.0);
    /* CAMERA_TYPE: camera C appears, A and B unchanged (0: do not change) */
    assert_int_equal(sim_model_camera_cmd(&m, 2, false, 0.0), SIM_CAM_NO_CAMERA);
    sim_model_camera_types(&m, types);
    assert_int_equal(m.cam[0].type, 68);
    assert_int_equal(m.cam[1].type, 97);
    assert_int_equal(m.cam[2].type, 98);
    assert_int_equal(sim_model_camera_cmd(&m, 2, false, 0.0), SIM_CAM_OK);
}

/* A camera CAMERA_TYPE removes (0xFF) loses its lens, and the active one
 * hands over to the first that exists (it stayed active, with camera A's
 * lens, so GEOREFERENCE_DATA named a camera that is not there). One added
 * back gets camera A's lens at start even with camera A gone. */
static void a_removed_camera_is_gone_from_every_report(void **state)
{
    sim_model_t m;
    uint8_t types[SIM_CAMERAS] = {TASE_CAMTYPE_NO_CHANGE, TASE_CAMTYPE_NONE,
                                  TASE_CAMTYPE_NO_CHANGE};
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_camera_cmd(&m, 1, false, 0.0), SIM_CAM_OK);
    assert_int_equal(m.active_cam, 1);
    sim_model_camera_types(&m, types);
    assert_int_equal(m.cam[1].type, TASE_CAMTYPE_NONE);
    near(m.cam[1].max_hfov, 0.0, 0.0);
    near(m.cam[1].min_hfov, 0.0, 0.0);
    assert_int_equal(m.active_cam, 0);
    assert_int_equal(sim_model_camera_cmd(&m, 1, false, 0.0), SIM_CAM_NO_CAMERA);
    /* A gone too: C is added, A's lens at start, and becomes active */
    types[0] = TASE_CAMTYPE_NONE;
    types[1] = TASE_CAMTYPE_NO_CHANGE;
    types[2] = 98;
    sim_model_camera_types(&m, types);
    assert_int_equal(m.active_cam, 2);
    near(m.cam[2].max_hfov, SIM_CAM_A_MAX_HFOV, 0.0);
    near(m.cam[2].min_hfov, SIM_CAM_A_MIN_HFOV, 0.0);
    near(m.cam[2].hfov, SIM_CAM_A_MAX_HFOV, 0.0);
}

/* Item 8: filter mode "normal" is 4 (P8, the vendor's numbering). */
static void nav_health_reports_filter_mode_normal_4(void **state)
{
    (void)state;
    assert_int_equal((sim_nav_health() & 0x000F), 4);
}

/* Item 9: a gimbal that is not deployed holds still, and refuses motion
 * until deployed. */
static void retracted_gimbal_holds_still_until_deployed(void **state)
{
    sim_model_t m;
    sim_pos_t t;
    double held;
    int i;
    (void)state;
    sim_model_init(&m);
    sim_model_command(&m, 10.0, 0.0, 0x10, 0.0);
    run(&m, 1.0);
    near(m.pan, 10.0, 1e-9);
    held = m.pan;
    sim_model_retract_deploy(&m, false);
    for (i = 0; i < 300; i++) { /* moving, then retracted */
        sim_model_step(&m, 0.01);
        near(m.pan, held, 0.0);
        near(m.pan_rate, 0.0, 0.0);
    }
    assert_int_equal(m.tax, SIM_3AX_RETRACTED);
    assert_int_equal(sim_model_command(&m, 0.0, 0.0, 0x20, 0.0), SIM_CMD_NOT_DEPLOYED);
    assert_int_equal(sim_model_command(&m, 5.0, 0.0, 0x10, 0.0), SIM_CMD_NOT_DEPLOYED);
    t = m.host;
    assert_int_equal(sim_model_spoi(&m, &t), SIM_CMD_NOT_DEPLOYED);
    assert_int_equal(m.mode, SIM_MODE_POSITION);
    run(&m, 1.0);
    near(m.pan, held, 0.0);
    sim_model_retract_deploy(&m, true);
    assert_int_equal(sim_model_command(&m, 5.0, 0.0, 0x10, 0.0), SIM_CMD_NOT_DEPLOYED);
    run(&m, 3.0);
    assert_int_equal(m.tax, SIM_3AX_DEPLOYED);
    near(m.pan, held, 0.0); /* deployed: still holding, nothing queued */
    assert_int_equal(sim_model_command(&m, 5.0, 0.0, 0x10, 0.0), SIM_CMD_OK);
    run(&m, 1.0);
    near(m.pan, 15.0, 1e-9);
}

/* A review: a deploy sent to a deployed gimbal made it "moving" for one
 * step, so the GIMBAL_CMD or SPOI_CMD sent right after it was dropped
 * (PROTOCOL-NOTES R6 drops commands only while retracted or moving). It is
 * echoed at the next step and nothing is dropped. */
static void a_deploy_while_deployed_is_echoed_and_drops_nothing(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(m.tax, SIM_3AX_DEPLOYED);
    sim_model_retract_deploy(&m, true);
    assert_int_equal(m.tax, SIM_3AX_DEPLOYED);
    assert_int_equal(sim_model_command(&m, 45.0, -10.0, 0x20, 0.0), SIM_CMD_OK);
    assert_true(sim_model_step(&m, 0.005)); /* the echo, at once */
    assert_false(sim_model_step(&m, 0.005));
    run(&m, 5.0);
    near(m.pan, 45.0, 1e-6);
    near(m.tilt, -10.0, 1e-6);
    /* a real move still takes its time and holds the axes */
    sim_model_retract_deploy(&m, false);
    assert_int_equal(m.tax, SIM_3AX_MOVING);
    assert_int_equal(sim_model_command(&m, 0.0, 0.0, 0x20, 0.0), SIM_CMD_NOT_DEPLOYED);
}

/* ---- item 11: an independent WGS-84 reference ----
 * Written differently from sim_model.c on purpose: points on the ellipsoid
 * from the reduced (parametric) latitude plus the height along the unit
 * normal, the local frame from cross products, the attitude applied as
 * three plane rotations in turn. */
typedef struct {
    double x, y, z;
} vec3;

static vec3 v3(double x, double y, double z)
{
    vec3 v;
    v.x = x;
    v.y = y;
    v.z = z;
    return v;
}
static vec3 v_sub(vec3 a, vec3 b)
{
    return v3(a.x - b.x, a.y - b.y, a.z - b.z);
}
static double v_dot(vec3 a, vec3 b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
static vec3 v_cross(vec3 a, vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static vec3 v_unit(vec3 a)
{
    double n = sqrt(v_dot(a, a));
    return v3(a.x / n, a.y / n, a.z / n);
}

static vec3 ref_normal(double lat, double lon)
{
    double p = lat * PI / 180.0, l = lon * PI / 180.0;
    return v3(cos(p) * cos(l), cos(p) * sin(l), sin(p));
}

static vec3 ref_point(const sim_pos_t *g)
{
    double b = SIM_WGS84_A * (1.0 - SIM_WGS84_F);
    double beta = atan((1.0 - SIM_WGS84_F) * tan(g->lat * PI / 180.0));
    double l = g->lon * PI / 180.0;
    vec3 n = ref_normal(g->lat, g->lon);
    return v3(SIM_WGS84_A * cos(beta) * cos(l) + g->height * n.x,
              SIM_WGS84_A * cos(beta) * sin(l) + g->height * n.y, b * sin(beta) + g->height * n.z);
}

/* rotate (a, b) by angle t (degrees): the coordinates in axes turned by t */
static void turn(double *a, double *b, double t)
{
    double c = cos(t * PI / 180.0), s = sin(t * PI / 180.0);
    double na = c * *a + s * *b, nb = -s * *a + c * *b;
    *a = na;
    *b = nb;
}

static void ref_angles(const sim_pos_t *host, const sim_att_t *att, const sim_pos_t *target,
                       double *pan, double *tilt, double *range)
{
    vec3 up = ref_normal(host->lat, host->lon);
    vec3 east = v_unit(v_cross(v3(0.0, 0.0, 1.0), up));
    vec3 north = v_cross(up, east);
    vec3 d = v_sub(ref_point(target), ref_point(host));
    double x = v_dot(d, north), y = v_dot(d, east), z = -v_dot(d, up);
    *range = sqrt(v_dot(d, d));
    turn(&x, &y, att->yaw);   /* about down */
    turn(&z, &x, att->pitch); /* about the new y (right wing) */
    turn(&y, &z, att->roll);  /* about the new x (nose) */
    *pan = atan2(y, x) * 180.0 / PI;
    *tilt = atan2(-z, sqrt(x * x + y * y)) * 180.0 / PI;
}

static void spoi_geometry_matches_an_independent_wgs84_reference(void **state)
{
    static const sim_pos_t hosts[] = {{45.5, 7.3, 1200.0, 0, 0, 0},
                                      {-33.9, 151.2, 300.0, 0, 0, 0},
                                      {70.0, -150.0, 5000.0, 0, 0, 0},
                                      {0.05, 179.99, 50.0, 0, 0, 0},
                                      {-80.0, 10.0, 2500.0, 0, 0, 0}};
    static const sim_att_t atts[] = {{0, 0, 0}, {12.0, -7.5, 233.0}, {-30.0, 20.0, -45.0}};
    static const double ranges[] = {100, 300, 1000, 1400, 2300, 5000, 12000, 33000, 50000};
    static const double bearings[] = {0, 37, 90, 143, 200, 271, 330};
    static const double drops[] = {0.0, 100.0, 1000.0, 3000.0};
    double worst_pan = 0.0, worst_tilt = 0.0, rmin = 1e9, rmax = 0.0;
    size_t h, a, r, b, k;
    (void)state;
    for (h = 0; h < sizeof(hosts) / sizeof(hosts[0]); h++) {
        for (a = 0; a < sizeof(atts) / sizeof(atts[0]); a++) {
            for (r = 0; r < sizeof(ranges) / sizeof(ranges[0]); r++) {
                for (b = 0; b < sizeof(bearings) / sizeof(bearings[0]); b++) {
                    for (k = 0; k < sizeof(drops) / sizeof(drops[0]); k++) {
                        const sim_pos_t *o = &hosts[h];
                        sim_pos_t t = *o;
                        double bb = bearings[b] * PI / 180.0, pan, tilt, rp, rt, rr, dp;
                        if (drops[k] > ranges[r]) {
                            continue;
                        }
                        t.lat += north_deg(o->lat, ranges[r] * cos(bb));
                        t.lon = sim_wrap180(t.lon + east_deg(o->lat, ranges[r] * sin(bb)));
                        t.height -= drops[k];
                        sim_spoi_angles(o, &atts[a], &t, &pan, &tilt);
                        ref_angles(o, &atts[a], &t, &rp, &rt, &rr);
                        dp = fabs(sim_wrap180(pan - rp)) * cos(rt * PI / 180.0);
                        worst_pan = dp > worst_pan ? dp : worst_pan;
                        worst_tilt = fabs(tilt - rt) > worst_tilt ? fabs(tilt - rt) : worst_tilt;
                        rmin = rr < rmin ? rr : rmin;
                        rmax = rr > rmax ? rr : rmax;
                    }
                }
            }
        }
    }
    print_message("SPOI geometry vs reference over %.0f m .. %.0f m: pan %.2g deg (on the sky), "
                  "tilt %.2g deg\n",
                  rmin, rmax, worst_pan, worst_tilt);
    assert_true(rmin < 110.0 && rmax > 49000.0);
    assert_true(worst_pan <= 1e-6);
    assert_true(worst_tilt <= 1e-6);
}

/* A review: held up for 5 s, tase-sim sent the KLV packets it had missed
 * 5 ms apart when it went on (the next due time only ever moved one period
 * on). */
static void a_stalled_periodic_output_resumes_without_a_burst(void **state)
{
    (void)state;
    assert_int_equal(sim_next_due(1000u, 1003u, 900u), 1900u); /* on time */
    assert_int_equal(sim_next_due(1000u, 1899u, 900u), 1900u); /* late, in its period */
    assert_int_equal(sim_next_due(1000u, 1900u, 900u), 2800u); /* a whole period late */
    assert_int_equal(sim_next_due(1000u, 6000u, 900u), 6900u); /* a 5 s stall */
    assert_int_equal(sim_next_due(0xFFFFFF00u, 0xFFFFFF10u, 900u), 0x284u); /* the wrap */
    assert_int_equal(sim_next_due(0xFFFFFF00u, 0x1000u, 900u), 0x1384u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rate_command_integrates_both_axes),
        cmocka_unit_test(a_zoom_ratio_is_the_focal_lengths),
        cmocka_unit_test(a_moving_spoi_crosses_a_pole),
        cmocka_unit_test(a_moving_spoi_is_tracked_without_lag),
        cmocka_unit_test(rate_is_clamped_to_axis_max_rate),
        cmocka_unit_test(position_command_uses_gain_then_settles),
        cmocka_unit_test(position_pan_takes_short_way_across_180),
        cmocka_unit_test(impulse_moves_for_impulse_time_only),
        cmocka_unit_test(rate_stops_at_pan_nogo_edge),
        cmocka_unit_test(default_tilt_nogo_blocks_looking_above_60),
        cmocka_unit_test(position_goes_round_the_nogo_zone),
        cmocka_unit_test(position_target_inside_nogo_goes_to_nearest_edge),
        cmocka_unit_test(a_nogo_zone_of_the_whole_turn_holds_the_axis),
        cmocka_unit_test(camera_commands_refuse_a_removed_camera),
        cmocka_unit_test(unknown_gimbal_flags_are_rejected),
        cmocka_unit_test(spoi_error_forms_change_nothing_outside_spoi),
        cmocka_unit_test(spoi_angles_level_host),
        cmocka_unit_test(spoi_angles_account_for_latitude_and_attitude),
        cmocka_unit_test(spoi_mode_drives_axes_to_the_target),
        cmocka_unit_test(retract_completes_after_its_duration_once),
        cmocka_unit_test(camera_euler_combines_mount_and_axes),
        cmocka_unit_test(spoi_flags_carry_stabilisation_and_mode_only),
        cmocka_unit_test(impulse_in_spoi_shifts_the_error_and_stays_in_spoi),
        cmocka_unit_test(impulse_in_spoi_is_bounded_by_the_max_rate),
        cmocka_unit_test(tilt_uses_the_spec_range_minus_270_to_90),
        cmocka_unit_test(link_port_follows_a2),
        cmocka_unit_test(rate_meter_measures_what_was_sent),
        cmocka_unit_test(camera_pass_reports_its_baud_and_disables_camera_control),
        cmocka_unit_test(navigation_sources_select_host_data),
        cmocka_unit_test(nav_health_reports_filter_mode_normal_4),
        cmocka_unit_test(a_removed_camera_is_gone_from_every_report),
        cmocka_unit_test(retracted_gimbal_holds_still_until_deployed),
        cmocka_unit_test(a_deploy_while_deployed_is_echoed_and_drops_nothing),
        cmocka_unit_test(spoi_geometry_matches_an_independent_wgs84_reference),
        cmocka_unit_test(a_stalled_periodic_output_resumes_without_a_burst),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
