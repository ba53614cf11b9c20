/* tase-sim's physical model (tools/sim_model.c): motion modes, limits and
 * SPOI geometry against hand-computed values. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "../tools/sim_model.h"

#define PI 3.14159265358979323846
/* degrees of latitude spanned by `m` metres on the model's sphere */
#define LAT_DEG(m) ((m) / (SIM_EARTH_RADIUS_M * PI / 180.0))

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

static void unknown_gimbal_flags_are_rejected(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 10.0, 0.0, 0x55, 0.0), -1);
    assert_int_equal(m.mode, SIM_MODE_RATE);
    near(m.cmd_pan, 0.0, 0.0);
}

static void spoi_error_forms_are_accepted_and_change_nothing(void **state)
{
    sim_model_t m;
    (void)state;
    sim_model_init(&m);
    assert_int_equal(sim_model_command(&m, 30.0, -10.0, 0x20, 0.0), 0);
    assert_int_equal(sim_model_command(&m, 1.0, 2.0, 0xC0, 0.0), 1);
    assert_int_equal(sim_model_command(&m, 1.0, 2.0, 0xD0, 0.0), 1);
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
    /* 100 m north, 100 m below: straight ahead, 45 degrees down */
    t.lat = LAT_DEG(100.0);
    t.height = 0.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-6);
    near(tilt, -45.0, 1e-6);
    /* 100 m east at the same height: right, level */
    t = host;
    t.lon = LAT_DEG(100.0); /* cos(0) = 1 at the equator */
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 90.0, 1e-6);
    near(tilt, 0.0, 1e-6);
    /* 100 m west, 100 m up... but 50 m south: pan atan2(-100,-50) */
    t = host;
    t.lat = -LAT_DEG(50.0);
    t.lon = -LAT_DEG(100.0);
    t.height = 100.0 + sqrt(100.0 * 100.0 + 50.0 * 50.0);
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, -180.0 + atan(2.0) * 180.0 / PI, 1e-6); /* -116.565 */
    near(tilt, 45.0, 1e-6);
}

static void spoi_angles_account_for_latitude_and_attitude(void **state)
{
    sim_pos_t host = {60.0, 10.0, 0.0, 0.0, 0.0, 0.0};
    sim_att_t att = {0.0, 0.0, 0.0};
    sim_pos_t t = host;
    double pan, tilt;
    (void)state;
    /* at 60 N a degree of longitude is half as long as one of latitude */
    t.lat += LAT_DEG(100.0);
    t.lon += LAT_DEG(100.0) / 0.5;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 45.0, 1e-6);
    /* heading 90 (east): an east target is straight ahead */
    t = host;
    t.lon += LAT_DEG(100.0) / 0.5;
    att.yaw = 90.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-6);
    near(tilt, 0.0, 1e-6);
    /* nose up 10 degrees: a level target ahead is 10 degrees below the mount plane */
    att.pitch = 10.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(pan, 0.0, 1e-6);
    near(tilt, -10.0, 1e-6);
    /* heading north, right wing down 90: an east target is straight "up" in the mount */
    att.pitch = 0.0;
    att.yaw = 0.0;
    att.roll = 90.0;
    sim_spoi_angles(&host, &att, &t, &pan, &tilt);
    near(tilt, 90.0, 1e-6);
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
    t.lon = LAT_DEG(100.0);
    t.height = 0.0; /* 100 m east, 100 m down */
    sim_model_spoi(&m, &t);
    run(&m, 5.0);
    assert_int_equal(m.mode, SIM_MODE_SPOI);
    near(m.pan, 90.0, 1e-4);
    near(m.tilt, -45.0, 1e-4);
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rate_command_integrates_both_axes),
        cmocka_unit_test(rate_is_clamped_to_axis_max_rate),
        cmocka_unit_test(position_command_uses_gain_then_settles),
        cmocka_unit_test(position_pan_takes_short_way_across_180),
        cmocka_unit_test(impulse_moves_for_impulse_time_only),
        cmocka_unit_test(rate_stops_at_pan_nogo_edge),
        cmocka_unit_test(default_tilt_nogo_blocks_looking_above_60),
        cmocka_unit_test(position_goes_round_the_nogo_zone),
        cmocka_unit_test(position_target_inside_nogo_goes_to_nearest_edge),
        cmocka_unit_test(unknown_gimbal_flags_are_rejected),
        cmocka_unit_test(spoi_error_forms_are_accepted_and_change_nothing),
        cmocka_unit_test(spoi_angles_level_host),
        cmocka_unit_test(spoi_angles_account_for_latitude_and_attitude),
        cmocka_unit_test(spoi_mode_drives_axes_to_the_target),
        cmocka_unit_test(retract_completes_after_its_duration_once),
        cmocka_unit_test(camera_euler_combines_mount_and_axes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
