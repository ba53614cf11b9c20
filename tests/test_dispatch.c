/* Tests of the dispatcher as the receiver's callback: typed handlers by
 * (group, type), unknown packets passed through intact and counted, wrong
 * lengths counted and reported to the error hook only. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/dispatch.h"

typedef struct {
    unsigned typed[TASE_PKT_COUNT];
    unsigned defaults, errors;
    int last_err;
    size_t last_len;
    uint8_t last_group, last_type;
    uint8_t last_data[TASE_DATA_MAX];
    tase_packet_msg_t last_msg;
    int msg_was_null;
} log_t;

static void on_typed(void *user, const tase_frame_t *f, const void *msg)
{
    log_t *l = user;
    const tase_packet_desc_t *p = tase_schema_find(f->group, f->type);
    assert_non_null(p);
    l->typed[p->index]++;
    l->last_len = f->len;
    l->msg_was_null = msg == NULL;
    if (msg != NULL) {
        memcpy(&l->last_msg, msg, p->size);
    }
}

static void on_default(void *user, const tase_frame_t *f)
{
    log_t *l = user;
    l->defaults++;
    l->last_group = f->group;
    l->last_type = f->type;
    l->last_len = f->len;
    memcpy(l->last_data, f->data, f->len);
}

static void on_error(void *user, const tase_frame_t *f, int err)
{
    log_t *l = user;
    l->errors++;
    l->last_err = err;
    l->last_len = f->len;
}

static const tase_packet_handler_t all_typed[TASE_PKT_COUNT] = {
    [TASE_PKT_GIMBAL_CMD] = on_typed,        [TASE_PKT_GYRO_ZERO_CMD] = on_typed,
    [TASE_PKT_CAMERA_CMD] = on_typed,        [TASE_PKT_LEGACY_CAMERA_CMD] = on_typed,
    [TASE_PKT_CAMERA_PASS] = on_typed,       [TASE_PKT_RETRACT_DEPLOY_CMD] = on_typed,
    [TASE_PKT_GIMBAL_ANGLE] = on_typed,      [TASE_PKT_GIMBAL_RATE] = on_typed,
    [TASE_PKT_HOST_SENSOR] = on_typed,       [TASE_PKT_HOST_ATTITUDE] = on_typed,
    [TASE_PKT_HOST_GPS_DATA] = on_typed,     [TASE_PKT_SPOI_CMD] = on_typed,
    [TASE_PKT_GEOREFERENCE_DATA] = on_typed, [TASE_PKT_PACKET_RATE] = on_typed,
    [TASE_PKT_SENSOR_FILTER] = on_typed,     [TASE_PKT_AXIS_SETTING] = on_typed,
    [TASE_PKT_SYSTEM_VERSION] = on_typed,    [TASE_PKT_NAV_SOURCE] = on_typed,
    [TASE_PKT_CAMERA_TYPE] = on_typed,       [TASE_PKT_GPS_LEVER_ARM] = on_typed,
    [TASE_PKT_CAMERA_ALIGN] = on_typed,
};

/* A fresh receiver and a dispatcher with every hook logging into l. */
static void start(tase_rx_t *rx, tase_dispatch_t *d, log_t *l,
                  const tase_packet_handler_t *handlers)
{
    memset(l, 0, sizeof(*l));
    assert_int_equal(tase_rx_init(rx), TASE_OK);
    assert_int_equal(tase_dispatch_init(d, handlers, on_default, on_error, l, &rx->stats), TASE_OK);
}

/* Frame `len` bytes of `fill` as (g, t) and feed it to rx through d. */
static void feed(tase_rx_t *rx, tase_dispatch_t *d, uint8_t g, uint8_t t, size_t len, uint8_t fill)
{
    uint8_t data[TASE_DATA_MAX], out[TASE_FRAME_MAX];
    int n;
    memset(data, fill, sizeof(data));
    n = tase_frame_build(g, t, data, len, out, sizeof(out));
    assert_true(n > 0);
    assert_int_equal(tase_rx_feed(rx, out, (size_t)n, tase_dispatch_frame, d), 1);
}

static void each_packet_reaches_its_typed_handler_decoded(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    size_t i;
    uint8_t out[TASE_FRAME_MAX];
    tase_gimbal_rate_t rate;
    int n;
    (void)state;
    memset(&rate, 0, sizeof(rate)); /* padding compares equal too */
    rate.time = 0xFFFFFFFFu;
    rate.pan_rate = INT16_MIN;
    rate.tilt_rate = -1;
    rate.r = INT16_MAX;
    rate.mode = 0x85;
    start(&rx, &d, &l, all_typed);
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        feed(&rx, &d, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), p->len, 0x11);
        assert_int_equal(l.typed[i], 1);
        assert_int_equal(l.last_len, p->len);
        assert_int_equal(l.msg_was_null, p->size == 0);
    }
    n = tase_packet_encode(TASE_ID_GIMBAL_RATE, &rate, out, sizeof(out));
    assert_int_equal(tase_rx_feed(&rx, out, (size_t)n, tase_dispatch_frame, &d), 1);
    assert_memory_equal(&l.last_msg.gimbal_rate, &rate, sizeof(rate));
    assert_int_equal(l.defaults, 0);
    assert_int_equal(l.errors, 0);
    assert_int_equal(rx.stats.unknown, 0);
    assert_int_equal(rx.stats.bad_length, 0);
    assert_int_equal(rx.stats.frames_ok, TASE_PKT_COUNT + 1);
}

static void queries_and_short_forms_reach_the_typed_handler(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    (void)state;
    start(&rx, &d, &l, all_typed);
    feed(&rx, &d, 0x48, 0x03, 0, 0); /* SYSTEM_VERSION query */
    assert_int_equal(l.typed[TASE_PKT_SYSTEM_VERSION], 1);
    assert_int_equal(l.last_len, 0);
    assert_int_equal(l.last_msg.system_version.board_sn, 0);
    feed(&rx, &d, 0x00, 0x41, 1, 2); /* CAMERA_CMD: switch to camera C */
    assert_int_equal(l.typed[TASE_PKT_CAMERA_CMD], 1);
    assert_int_equal(l.last_len, 1);
    assert_int_equal(l.last_msg.camera_cmd.camera, 2);
    feed(&rx, &d, 0x00, 0x42, 4 + 249, 0x42); /* longest CAMERA_PASS */
    assert_int_equal(l.typed[TASE_PKT_CAMERA_PASS], 1);
    assert_int_equal(l.last_msg.camera_pass.len, 249);
    assert_int_equal(l.errors, 0);
}

static void unknown_packets_pass_through_intact_and_are_counted(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    unsigned t;
    uint8_t want[TASE_DATA_MAX];
    (void)state;
    memset(want, 0x77, sizeof(want));
    start(&rx, &d, &l, all_typed);
    /* every type of the STATUS group, which spec v1.0.0 leaves empty */
    for (t = 0; t < 256; t++) {
        size_t len = t % (TASE_DATA_MAX + 1);
        feed(&rx, &d, TASE_GROUP_STATUS, (uint8_t)t, len, 0x77);
        assert_int_equal(l.defaults, t + 1);
        assert_int_equal(l.last_group, 0x28);
        assert_int_equal(l.last_type, t);
        assert_int_equal(l.last_len, len);
        assert_memory_equal(l.last_data, want, len);
    }
    /* an unknown type in a known group */
    feed(&rx, &d, 0x00, 0x99, 3, 0x77);
    assert_int_equal(l.last_type, 0x99);
    assert_int_equal(rx.stats.unknown, 257);
    assert_int_equal(rx.stats.bad_length, 0);
    assert_int_equal(l.errors, 0);
    for (t = 0; t < TASE_PKT_COUNT; t++) {
        assert_int_equal(l.typed[t], 0);
    }
}

static void every_wrong_length_is_counted_and_reported_never_typed(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    size_t i, len;
    unsigned expected = 0;
    (void)state;
    start(&rx, &d, &l, all_typed);
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        const tase_packet_desc_t *p = tase_schema_at(i);
        for (len = 0; len <= TASE_DATA_MAX; len++) {
            if (tase_schema_length_ok(p, len)) {
                continue;
            }
            feed(&rx, &d, TASE_ID_GROUP(p->id), TASE_ID_TYPE(p->id), len, 0xEE);
            expected++;
            assert_int_equal(l.errors, expected);
            assert_int_equal(l.last_err, TASE_ELENGTH);
            assert_int_equal(l.last_len, len);
        }
        assert_int_equal(l.typed[i], 0);
    }
    assert_true(expected > 20u * 200u);
    assert_int_equal(rx.stats.bad_length, expected);
    assert_int_equal(rx.stats.unknown, 0);
    assert_int_equal(l.defaults, 0);
}

static void packets_without_typed_handler_go_to_default_uncounted(void **state)
{
    static const tase_packet_handler_t only_angle[TASE_PKT_COUNT] = {
        [TASE_PKT_GIMBAL_ANGLE] = on_typed,
    };
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    (void)state;
    start(&rx, &d, &l, only_angle);
    feed(&rx, &d, 0x08, 0x10, 6, 1);
    feed(&rx, &d, 0x00, 0x80, 8, 1);
    assert_int_equal(l.typed[TASE_PKT_GIMBAL_ANGLE], 1);
    assert_int_equal(l.defaults, 1);
    assert_int_equal(l.last_type, 0x80);
    assert_int_equal(rx.stats.unknown, 0);
    /* no table at all: everything is a default */
    tase_dispatch_init(&d, NULL, on_default, NULL, &l, &rx.stats);
    feed(&rx, &d, 0x08, 0x10, 6, 1);
    assert_int_equal(l.defaults, 2);
    assert_int_equal(l.typed[TASE_PKT_GIMBAL_ANGLE], 1);
}

static void null_hooks_and_stats_are_allowed(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    tase_frame_t f = {0, 0x28, 0, 0, (const uint8_t *)""};
    (void)state;
    tase_rx_init(&rx);
    assert_int_equal(tase_dispatch_init(NULL, NULL, NULL, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_dispatch_init(&d, NULL, NULL, NULL, NULL, NULL), TASE_OK);
    feed(&rx, &d, 0x28, 0x01, 2, 0); /* unknown, no hook, no stats */
    feed(&rx, &d, 0x08, 0x10, 5, 0); /* bad length, no hook */
    feed(&rx, &d, 0x08, 0x10, 6, 0); /* no handler */
    tase_dispatch_frame(NULL, &f);
    tase_dispatch_frame(&d, NULL);
    assert_int_equal(rx.stats.frames_ok, 3);
    assert_int_equal(rx.stats.unknown, 0);
    assert_int_equal(rx.stats.bad_length, 0);
}

static unsigned bad_arg_calls;

static void count_default(void *user, const tase_frame_t *frame)
{
    (void)user;
    (void)frame;
    bad_arg_calls++;
}

/* tase_dispatch_init(NULL) is refused; tase_dispatch_frame() with a NULL
 * dispatcher or frame runs no callback and counts nothing. */
static void dispatch_api_rejects_bad_arguments(void **state)
{
    tase_dispatch_t d;
    tase_dispatch_t copy;
    tase_rx_stats_t stats;
    tase_rx_stats_t scopy;
    (void)state;

    memset(&stats, 0, sizeof stats);
    assert_int_equal(tase_dispatch_init(NULL, NULL, count_default, NULL, NULL, &stats), TASE_EARG);
    assert_int_equal(tase_dispatch_init(&d, NULL, count_default, NULL, NULL, &stats), TASE_OK);
    memcpy(&copy, &d, sizeof d);
    memcpy(&scopy, &stats, sizeof stats);
    bad_arg_calls = 0;
    tase_dispatch_frame(&d, NULL);
    tase_dispatch_frame(NULL, NULL);
    assert_int_equal(bad_arg_calls, 0);
    assert_memory_equal(&d, &copy, sizeof d);
    assert_memory_equal(&stats, &scopy, sizeof stats);
}

/* A frame with its data NULL and len > 0 (a caller-built one; the
 * receiver never delivers such) reaches no hook: a typed handler got the
 * struct the previous frame left in the dispatcher. */
static void a_frame_without_its_data_reaches_no_handler(void **state)
{
    tase_rx_t rx;
    tase_dispatch_t d;
    log_t l;
    tase_frame_t f;
    (void)state;
    start(&rx, &d, &l, all_typed);
    feed(&rx, &d, 0x00, 0x80, 8, 0x12); /* a GIMBAL_CMD, typed */
    assert_int_equal(l.typed[TASE_PKT_GIMBAL_CMD], 1);
    memset(&f, 0, sizeof f);
    f.group = 0x00;
    f.type = 0x80;
    f.len = 8;
    f.data = NULL;
    tase_dispatch_frame(&d, &f);
    f.group = 0x7F; /* unknown: on_default would read data[0..len) */
    tase_dispatch_frame(&d, &f);
    assert_int_equal(l.typed[TASE_PKT_GIMBAL_CMD], 1);
    assert_int_equal(l.defaults + l.errors, 0);
    assert_int_equal(rx.stats.unknown + rx.stats.bad_length, 0);
    /* a zero-length one with data NULL is a query: dispatched */
    f.group = 0x00;
    f.len = 0;
    tase_dispatch_frame(&d, &f);
    assert_int_equal(l.typed[TASE_PKT_GIMBAL_CMD] + l.errors, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(dispatch_api_rejects_bad_arguments),
        cmocka_unit_test(a_frame_without_its_data_reaches_no_handler),
        cmocka_unit_test(each_packet_reaches_its_typed_handler_decoded),
        cmocka_unit_test(queries_and_short_forms_reach_the_typed_handler),
        cmocka_unit_test(unknown_packets_pass_through_intact_and_are_counted),
        cmocka_unit_test(every_wrong_length_is_counted_and_reported_never_typed),
        cmocka_unit_test(packets_without_typed_handler_go_to_default_uncounted),
        cmocka_unit_test(null_hooks_and_stats_are_allowed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
