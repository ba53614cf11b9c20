/* Tests of the CAN core: splitting, role acceptance, reassembly, 3AX. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/can.h"
#include "tase/flags.h"

/* GIMBAL_ANGLE pan 10.00, tilt -5.00, roll 0 framed by hand from the spec:
 * checksum 0x00+0xFF+0x5A+0x08+0x08+0x10+0x03+0xE8+0xFE+0x0C = 0x036E. */
static const uint8_t angle_pkt[14] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x03,
                                      0xE8, 0xFE, 0x0C, 0x00, 0x00, 0x03, 0x6E};

typedef struct {
    int n;
    uint8_t group, type, len;
    uint8_t data[TASE_DATA_MAX];
} got_t;

static void on_frame(void *user, const tase_frame_t *f)
{
    got_t *g = user;
    g->n++;
    g->group = f->group;
    g->type = f->type;
    g->len = f->len;
    memcpy(g->data, f->data, f->len);
}

static tase_can_frame_t ext_frame(uint32_t id, const uint8_t *d, uint8_t dlc)
{
    tase_can_frame_t f;
    memset(&f, 0, sizeof(f));
    f.id = id;
    f.extended = true;
    f.dlc = dlc;
    if (dlc > 0) {
        memcpy(f.data, d, dlc);
    }
    return f;
}

static void role_ids_follow_the_spec(void **state)
{
    uint32_t tx = 0, rx = 0;
    (void)state;
    assert_int_equal(tase_can_role_ids(TASE_CAN_ROLE_HOST, &tx, &rx), TASE_OK);
    assert_int_equal(tx, 0x11000000u);
    assert_int_equal(rx, 0x10000000u);
    assert_int_equal(tase_can_role_ids(TASE_CAN_ROLE_GIMBAL, &tx, &rx), TASE_OK);
    assert_int_equal(tx, 0x10000000u);
    assert_int_equal(rx, 0x11000000u);
    tx = 7;
    assert_int_equal(tase_can_role_ids((tase_can_role_t)2, &tx, NULL), TASE_EARG);
    assert_int_equal(tx, 7);
}

static void angle_packet_from_gimbal_is_8_plus_6_bytes(void **state)
{
    tase_can_frame_t out[4];
    uint8_t wire[TASE_FRAME_MAX];
    static const uint8_t pt[6] = {0x03, 0xE8, 0xFE, 0x0C, 0, 0};
    (void)state;
    /* The encoder agrees with the hand-made packet, so the rest of the
     * file may use it to make packets. */
    assert_int_equal(tase_frame_build(0x08, 0x10, pt, 6, wire, sizeof(wire)), 14);
    assert_memory_equal(wire, angle_pkt, 14);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_GIMBAL, angle_pkt, 14, out, 4), 2);
    assert_int_equal(out[0].id, 0x10000000u);
    assert_true(out[0].extended);
    assert_int_equal(out[0].dlc, 8);
    assert_memory_equal(out[0].data, angle_pkt, 8);
    assert_int_equal(out[1].id, 0x10000000u);
    assert_int_equal(out[1].dlc, 6);
    assert_memory_equal(out[1].data, angle_pkt + 8, 6);
    assert_int_equal(out[1].data[6], 0);
    assert_int_equal(out[1].data[7], 0);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, angle_pkt, 14, out, 4), 2);
    assert_int_equal(out[0].id, 0x11000000u);
    assert_int_equal(out[1].id, 0x11000000u);
}

static void split_covers_every_length_in_order(void **state)
{
    uint8_t src[TASE_FRAME_MAX];
    uint8_t back[TASE_FRAME_MAX];
    tase_can_frame_t out[TASE_CAN_FRAMES_MAX];
    size_t n, i, k;
    int frames;
    (void)state;
    for (i = 0; i < sizeof(src); i++) {
        src[i] = (uint8_t)(i * 7u + 1u);
    }
    for (n = 0; n <= TASE_FRAME_MAX; n++) {
        frames = tase_can_split(TASE_CAN_ROLE_HOST, src, n, out, TASE_CAN_FRAMES_MAX);
        assert_int_equal(frames, (int)((n + 7) / 8));
        k = 0;
        for (i = 0; i < (size_t)frames; i++) {
            assert_true(out[i].dlc >= 1 && out[i].dlc <= 8);
            if (i + 1 < (size_t)frames) {
                assert_int_equal(out[i].dlc, 8);
            }
            memcpy(back + k, out[i].data, out[i].dlc);
            k += out[i].dlc;
        }
        assert_int_equal(k, n);
        if (n > 0) {
            assert_memory_equal(back, src, n);
        }
    }
    assert_int_equal(TASE_CAN_FRAMES_MAX, 33);
}

static void split_refuses_small_arrays_and_bad_arguments_without_writing(void **state)
{
    tase_can_frame_t out[2];
    (void)state;
    memset(out, 0xAB, sizeof(out));
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, angle_pkt, 17, out, 2), TASE_ENOSPC);
    assert_int_equal(out[0].dlc, 0xAB);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, NULL, 3, out, 2), TASE_EARG);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, angle_pkt, 3, NULL, 2), TASE_EARG);
    assert_int_equal(tase_can_split((tase_can_role_t)5, angle_pkt, 3, out, 2), TASE_EARG);
    assert_int_equal(out[0].dlc, 0xAB);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, NULL, 0, NULL, 0), 0);
}

static void splitter_reports_progress_and_then_ends(void **state)
{
    tase_can_split_t s;
    tase_can_frame_t f;
    (void)state;
    assert_int_equal(tase_can_split_init(&s, TASE_CAN_ROLE_GIMBAL, angle_pkt, 14), TASE_OK);
    assert_int_equal(s.pos, 0);
    assert_int_equal(tase_can_split_next(&s, &f), 8);
    assert_int_equal(s.pos, 8);
    assert_int_equal(tase_can_split_next(&s, &f), 6);
    assert_int_equal(s.pos, 14);
    f.dlc = 99;
    assert_int_equal(tase_can_split_next(&s, &f), 0);
    assert_int_equal(f.dlc, 99);
    assert_int_equal(tase_can_split_next(NULL, &f), TASE_EARG);
    assert_int_equal(tase_can_split_init(&s, TASE_CAN_ROLE_GIMBAL, NULL, 1), TASE_EARG);
}

/* Sends a max-size frame split by `sender` through a receiver of `rcv`. */
static void max_frame_round_trip(tase_can_role_t sender, tase_can_role_t rcv)
{
    uint8_t data[TASE_DATA_MAX];
    uint8_t wire[TASE_FRAME_MAX];
    tase_can_frame_t out[TASE_CAN_FRAMES_MAX];
    tase_can_rx_t crx;
    got_t g;
    int n, frames, i, delivered = 0;
    for (i = 0; i < (int)sizeof(data); i++) {
        data[i] = (uint8_t)(255 - i);
    }
    n = tase_frame_build(0x00, 0x42, data, sizeof(data), wire, sizeof(wire));
    assert_int_equal(n, 261);
    frames = tase_can_split(sender, wire, (size_t)n, out, TASE_CAN_FRAMES_MAX);
    assert_int_equal(frames, 33);
    assert_int_equal(out[32].dlc, 5);
    assert_int_equal(tase_can_rx_init(&crx, rcv), TASE_OK);
    memset(&g, 0, sizeof(g));
    for (i = 0; i < frames; i++) {
        delivered += tase_can_rx_feed(&crx, &out[i], on_frame, &g);
        /* Nothing before the last frame completes the packet. */
        assert_int_equal(g.n, i == frames - 1 ? 1 : 0);
    }
    assert_int_equal(delivered, 1);
    assert_int_equal(g.group, 0x00);
    assert_int_equal(g.type, 0x42);
    assert_int_equal(g.len, TASE_DATA_MAX);
    assert_memory_equal(g.data, data, TASE_DATA_MAX);
    assert_int_equal(crx.stats.frames_accepted, 33);
    assert_int_equal(crx.rx.stats.frames_ok, 1);
}

static void max_frame_survives_host_to_gimbal(void **state)
{
    (void)state;
    max_frame_round_trip(TASE_CAN_ROLE_HOST, TASE_CAN_ROLE_GIMBAL);
}

static void max_frame_survives_gimbal_to_host(void **state)
{
    (void)state;
    max_frame_round_trip(TASE_CAN_ROLE_GIMBAL, TASE_CAN_ROLE_HOST);
}

static void receiver_takes_only_its_direction(void **state)
{
    tase_can_rx_t crx;
    tase_can_frame_t f;
    got_t g;
    static const uint8_t junk[8] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0, 0};
    (void)state;
    memset(&g, 0, sizeof(g));
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST), TASE_OK);
    f = ext_frame(TASE_CAN_ID_TO_GIMBAL, junk, 8); /* the host's own direction */
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &g), TASE_EUNKNOWN);
    f = ext_frame(TASE_CAN_ID_3AX_STATUS, junk, 2);
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &g), TASE_EUNKNOWN);
    f = ext_frame(TASE_CAN_ID_FROM_GIMBAL, junk, 8);
    f.extended = false; /* same number as a standard id cannot be ours */
    f.id = 0x000;
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &g), TASE_EUNKNOWN);
    f = ext_frame(TASE_CAN_ID_FROM_GIMBAL, junk, 0);
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &g), TASE_ELENGTH);
    f = ext_frame(TASE_CAN_ID_FROM_GIMBAL, junk, 8);
    f.dlc = 9;
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &g), TASE_ELENGTH);
    assert_int_equal(crx.stats.frames_in, 5);
    assert_int_equal(crx.stats.frames_ignored, 3);
    assert_int_equal(crx.stats.bad_length, 2);
    assert_int_equal(crx.stats.frames_accepted, 0);
    assert_int_equal(crx.rx.stats.bytes_in, 0); /* nothing reached the datalink */
    assert_int_equal(tase_can_rx_feed(NULL, &f, on_frame, &g), TASE_EARG);
    assert_int_equal(tase_can_rx_feed(&crx, NULL, on_frame, &g), TASE_EARG);
    assert_int_equal(crx.stats.frames_in, 5);
    assert_int_equal(tase_can_accept(TASE_CAN_ROLE_GIMBAL, &f), TASE_EUNKNOWN);
    f.dlc = 3;
    assert_int_equal(tase_can_accept(TASE_CAN_ROLE_HOST, &f), 3);
}

static void other_ids_between_fragments_do_not_break_a_packet(void **state)
{
    tase_can_rx_t crx;
    tase_can_frame_t a, b, other, wrongdir;
    got_t g;
    (void)state;
    memset(&g, 0, sizeof(g));
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST), TASE_OK);
    a = ext_frame(TASE_CAN_ID_FROM_GIMBAL, angle_pkt, 8);
    b = ext_frame(TASE_CAN_ID_FROM_GIMBAL, angle_pkt + 8, 6);
    other = ext_frame(0x12345678u, angle_pkt, 8);
    wrongdir = ext_frame(TASE_CAN_ID_TO_GIMBAL, angle_pkt + 3, 5);
    assert_int_equal(tase_can_rx_feed(&crx, &a, on_frame, &g), 0);
    assert_int_equal(tase_can_rx_feed(&crx, &other, on_frame, &g), TASE_EUNKNOWN);
    assert_int_equal(tase_can_rx_feed(&crx, &wrongdir, on_frame, &g), TASE_EUNKNOWN);
    assert_int_equal(tase_can_rx_feed(&crx, &b, on_frame, &g), 1);
    assert_int_equal(g.n, 1);
    assert_int_equal(g.group, 0x08);
    assert_int_equal(g.type, 0x10);
    assert_int_equal(g.len, 6);
    assert_memory_equal(g.data, angle_pkt + 6, 6);
    assert_int_equal(tase_can_rx_init(&crx, (tase_can_role_t)9), TASE_EARG);
}

/* What a frame callback does to its own CAN receiver. */
typedef struct {
    tase_can_rx_t *crx;
    int init; /* 0: feed frames into it; 1: re-initialise it */
    int calls;
    int refused;
} can_reenter_t;

static void can_reenter(void *user, const tase_frame_t *f)
{
    can_reenter_t *e = user;
    tase_can_rx_t before;
    tase_can_frame_t ours = ext_frame(TASE_CAN_ID_FROM_GIMBAL, angle_pkt, 8);
    tase_can_frame_t theirs = ext_frame(0x12345678u, angle_pkt, 8);
    (void)f;
    e->calls++;
    if (e->init) {
        assert_int_equal(tase_can_rx_init(e->crx, TASE_CAN_ROLE_HOST), TASE_OK);
        return;
    }
    memcpy(&before, e->crx, sizeof(before));
    /* ours or not, nothing is counted or fed while its callback runs */
    assert_int_equal(tase_can_rx_feed(e->crx, &ours, can_reenter, e), TASE_EBUSY);
    assert_int_equal(tase_can_rx_feed(e->crx, &theirs, can_reenter, e), TASE_EBUSY);
    assert_memory_equal(&before, e->crx, sizeof(before));
    e->refused++;
}

/* Issue 12: tase_can_rx_feed() from inside its own frame callback is
 * refused with TASE_EBUSY and counts nothing; tase_can_rx_init() there
 * resets the instance and the feed that made the callback returns the one
 * frame it delivered (before, the datalink receiver memcpy'd past its
 * window, or returned a wrapped negative count). */
static void can_receiver_calls_from_inside_its_callback(void **state)
{
    uint8_t two[28];
    tase_can_frame_t f[4];
    tase_can_rx_t crx, fresh;
    can_reenter_t e;
    int i, delivered = 0;
    (void)state;
    memcpy(two, angle_pkt, 14);
    memcpy(two + 14, angle_pkt, 14);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_GIMBAL, two, 28, f, 4), 4);
    memset(&e, 0, sizeof(e));
    e.crx = &crx;
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST), TASE_OK);
    for (i = 0; i < 4; i++) {
        int r = tase_can_rx_feed(&crx, &f[i], can_reenter, &e);
        assert_true(r >= 0);
        delivered += r;
    }
    assert_int_equal(delivered, 2);
    assert_int_equal(e.refused, 2);
    assert_int_equal(crx.stats.frames_in, 4);
    assert_int_equal(crx.stats.frames_accepted, 4);
    assert_int_equal(crx.stats.frames_ignored, 0);
    assert_int_equal(crx.rx.stats.bytes_in, 28);
    assert_int_equal(crx.rx.stats.frames_ok, 2);

    /* Re-initialised from the callback: the second CAN frame completes the
     * first packet (and starts the second, whose bytes are not consumed). */
    memset(&e, 0, sizeof(e));
    e.crx = &crx;
    e.init = 1;
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST), TASE_OK);
    assert_int_equal(tase_can_rx_init(&fresh, TASE_CAN_ROLE_HOST), TASE_OK);
    assert_int_equal(tase_can_rx_feed(&crx, &f[0], can_reenter, &e), 0);
    assert_int_equal(tase_can_rx_feed(&crx, &f[1], can_reenter, &e), 1);
    assert_int_equal(e.calls, 1);
    assert_memory_equal(&crx, &fresh, sizeof(crx));
}

static void move_command_encodes_deploy_as_zero_and_retract_as_nonzero(void **state)
{
    tase_can_3ax_move_t m;
    tase_can_frame_t f;
    (void)state;
    m.command = TASE_3AX_MOVE_DEPLOY;
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_OK);
    assert_int_equal(f.id, 0x12010000u);
    assert_true(f.extended);
    assert_int_equal(f.dlc, 2);
    assert_int_equal(f.data[0], 0x00);
    assert_int_equal(f.data[1], 0x00);
    m.command = TASE_3AX_MOVE_RETRACT;
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_OK);
    assert_int_not_equal(f.data[0], 0x00);
    assert_int_equal(f.data[1], 0x00);
    m.command = TASE_3AX_MOVE_DEPLOY;
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_OK);
    assert_int_equal(m.command, TASE_3AX_MOVE_RETRACT);
    f.data[0] = 0x01; /* any non-zero byte means retract */
    m.command = TASE_3AX_MOVE_DEPLOY;
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_OK);
    assert_int_equal(m.command, TASE_3AX_MOVE_RETRACT);
    f.data[0] = 0x00;
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_OK);
    assert_int_equal(m.command, TASE_3AX_MOVE_DEPLOY);
}

/* Spec 4.1.6 vs 5.3.1: RETRACT_DEPLOY_CMD's byte 1 deploys, the move
 * frame's byte 1 retracts. The command names carry the packet's values, so
 * a gimbal passing the packet's byte on moves the right way (or, for a
 * non-zero byte other than 1, gets TASE_ERANGE: nothing moves). */
static void move_command_values_mean_what_retract_deploy_cmd_means(void **state)
{
    tase_can_3ax_move_t m;
    tase_can_frame_t f;
    (void)state;
    assert_int_equal(TASE_3AX_MOVE_DEPLOY, TASE_DEPLOY);
    assert_int_equal(TASE_3AX_MOVE_RETRACT, TASE_RETRACT);
    m.command = (tase_3ax_command_t)TASE_DEPLOY;
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_OK);
    assert_int_equal(f.data[0], 0x00); /* 5.3.1: "0 for deploy" */
    m.command = (tase_3ax_command_t)TASE_RETRACT;
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_OK);
    assert_int_equal(f.data[0], TASE_3AX_RETRACT_BYTE);
    m.command = (tase_3ax_command_t)2; /* a deploy byte of 2: not a command here */
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_ERANGE);
}

static void move_command_rejects_bad_input(void **state)
{
    tase_can_3ax_move_t m;
    tase_can_frame_t f;
    (void)state;
    memset(&f, 0x5C, sizeof(f));
    m.command = (tase_3ax_command_t)2;
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_ERANGE);
    assert_int_equal(f.dlc, 0x5C);
    assert_int_equal(tase_can_3ax_move_encode(NULL, &f), TASE_EARG);
    f = ext_frame(TASE_CAN_ID_3AX_STATUS, angle_pkt, 2);
    m.command = TASE_3AX_MOVE_DEPLOY;
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_EUNKNOWN);
    f = ext_frame(TASE_CAN_ID_3AX_MOVE, angle_pkt + 1, 3);
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_ELENGTH);
    f.dlc = 2;
    f.extended = false;
    assert_int_equal(tase_can_3ax_move_decode(&f, &m), TASE_EUNKNOWN);
    assert_int_equal(m.command, TASE_3AX_MOVE_DEPLOY);
}

static void status_bytes_decode_to_position_and_signed_speed(void **state)
{
    static const uint8_t b[2] = {0x80, 0xF6}; /* half way, -10 units */
    tase_can_frame_t f = ext_frame(TASE_CAN_ID_3AX_STATUS, b, 2);
    tase_can_3ax_status_t st;
    (void)state;
    assert_int_equal(tase_can_3ax_status_decode(&f, &st), TASE_OK);
    assert_int_equal(st.position, 0x80);
    assert_int_equal(st.speed_dps, -50);
    f.data[0] = 0xFF;
    f.data[1] = 0x7F;
    assert_int_equal(tase_can_3ax_status_decode(&f, &st), TASE_OK);
    assert_int_equal(st.position, TASE_3AX_POSITION_UNKNOWN);
    assert_int_equal(st.speed_dps, 635);
    f.data[1] = 0x80;
    assert_int_equal(tase_can_3ax_status_decode(&f, &st), TASE_OK);
    assert_int_equal(st.speed_dps, -640);
    f.dlc = 1;
    assert_int_equal(tase_can_3ax_status_decode(&f, &st), TASE_ELENGTH);
    f.dlc = 2;
    f.id = TASE_CAN_ID_3AX_MOVE;
    assert_int_equal(tase_can_3ax_status_decode(&f, &st), TASE_EUNKNOWN);
    assert_int_equal(st.speed_dps, -640);
}

static void status_round_trips_every_speed_and_position(void **state)
{
    tase_can_3ax_status_t in, back;
    tase_can_frame_t f;
    int speed, pos;
    (void)state;
    for (pos = 0; pos <= 0xFF; pos += 0x33) {
        for (speed = -640; speed <= 635; speed += 5) {
            in.position = (uint8_t)pos;
            in.speed_dps = (int16_t)speed;
            assert_int_equal(tase_can_3ax_status_encode(&in, &f), TASE_OK);
            assert_int_equal(f.id, 0x12020000u);
            assert_int_equal(f.dlc, 2);
            assert_int_equal(f.data[0], pos);
            assert_int_equal(f.data[1], (uint8_t)((speed / 5) & 0xFF));
            assert_int_equal(tase_can_3ax_status_decode(&f, &back), TASE_OK);
            assert_int_equal(back.position, in.position);
            assert_int_equal(back.speed_dps, in.speed_dps);
        }
    }
}

static void status_encoder_range_checks_speed(void **state)
{
    tase_can_3ax_status_t st;
    tase_can_frame_t f;
    static const int16_t bad[] = {3, -1, 640, -645, 1000, -32768};
    size_t i;
    (void)state;
    memset(&f, 0x11, sizeof(f));
    st.position = 0;
    for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        st.speed_dps = bad[i];
        assert_int_equal(tase_can_3ax_status_encode(&st, &f), TASE_ERANGE);
        assert_int_equal(f.dlc, 0x11);
    }
    assert_int_equal(tase_can_3ax_status_encode(&st, NULL), TASE_EARG);
}

static void frame_check_enforces_id_width_and_dlc(void **state)
{
    tase_can_frame_t f = ext_frame(0x1FFFFFFFu, angle_pkt, 8);
    (void)state;
    assert_int_equal(tase_can_frame_check(&f), TASE_OK);
    f.id = 0x20000000u;
    assert_int_equal(tase_can_frame_check(&f), TASE_ERANGE);
    f.extended = false;
    f.id = 0x7FF;
    assert_int_equal(tase_can_frame_check(&f), TASE_OK);
    f.id = 0x800;
    assert_int_equal(tase_can_frame_check(&f), TASE_ERANGE);
    f.id = 0x123;
    f.dlc = 9;
    assert_int_equal(tase_can_frame_check(&f), TASE_ELENGTH);
    assert_int_equal(tase_can_frame_check(NULL), TASE_EARG);
}

static void split_refuses_counts_an_int_result_cannot_carry(void **state)
{
    /* 32768 frames of 8 bytes: the count would not fit the contract's
     * int16 bound, even with an array large enough for it */
    size_t n = 8u * 32768u;
    uint8_t *data = calloc(n, 1);
    tase_can_frame_t *out = calloc(32768u, sizeof(*out));
    (void)state;
    assert_non_null(data);
    assert_non_null(out);
    out[0].dlc = 0xAB;
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, n, out, 32768u), TASE_ENOSPC);
    assert_int_equal(out[0].dlc, 0xAB);
    /* one frame fewer is fine */
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, n - 8u, out, 32768u), 32767);
    assert_int_equal(out[32766].dlc, 8);
    free(data);
    free(out);
}

static void null_and_unknown_roles_are_rejected_without_counting(void **state)
{
    tase_can_rx_t crx;
    tase_can_split_t s;
    tase_can_frame_t f = ext_frame(TASE_CAN_ID_TO_GIMBAL, angle_pkt, 8), copy;
    tase_can_3ax_move_t m = {TASE_3AX_MOVE_RETRACT};
    tase_can_3ax_status_t st = {7, 5};
    got_t got;
    (void)state;
    memset(&got, 0, sizeof(got));
    assert_int_equal(tase_can_rx_init(NULL, TASE_CAN_ROLE_GIMBAL), TASE_EARG);
    memset(&crx, 0x5A, sizeof(crx));
    assert_int_equal(tase_can_rx_init(&crx, (tase_can_role_t)2), TASE_EARG);
    assert_int_equal(crx.stats.frames_in, 0x5A5A5A5Au); /* untouched */
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_GIMBAL), TASE_OK);
    assert_int_equal(tase_can_rx_feed(NULL, &f, on_frame, &got), TASE_EARG);
    assert_int_equal(tase_can_rx_feed(&crx, NULL, on_frame, &got), TASE_EARG);
    /* an instance whose role was overwritten counts nothing */
    crx.role = (tase_can_role_t)9;
    assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &got), TASE_EARG);
    assert_int_equal(crx.stats.frames_in, 0);
    assert_int_equal(crx.rx.stats.bytes_in, 0);
    assert_int_equal(got.n, 0);
    assert_int_equal(tase_can_accept(TASE_CAN_ROLE_HOST, NULL), TASE_EARG);

    assert_int_equal(tase_can_split_init(NULL, TASE_CAN_ROLE_HOST, angle_pkt, 3), TASE_EARG);
    assert_int_equal(tase_can_split_init(&s, (tase_can_role_t)3, angle_pkt, 3), TASE_EARG);
    assert_int_equal(tase_can_split_init(&s, TASE_CAN_ROLE_HOST, angle_pkt, 3), TASE_OK);
    assert_int_equal(tase_can_split_next(&s, NULL), TASE_EARG);
    assert_int_equal(s.pos, 0);

    copy = f;
    assert_int_equal(tase_can_3ax_move_encode(&m, NULL), TASE_EARG);
    assert_int_equal(tase_can_3ax_status_encode(NULL, &f), TASE_EARG);
    assert_int_equal(tase_can_3ax_status_encode(&st, NULL), TASE_EARG);
    assert_memory_equal(&f, &copy, sizeof(f));
    assert_int_equal(tase_can_3ax_move_encode(&m, &f), TASE_OK);
    assert_int_equal(tase_can_3ax_move_decode(NULL, &m), TASE_EARG);
    assert_int_equal(tase_can_3ax_move_decode(&f, NULL), TASE_EARG);
    assert_int_equal(tase_can_3ax_status_encode(&st, &f), TASE_OK);
    assert_int_equal(tase_can_3ax_status_decode(NULL, &st), TASE_EARG);
    assert_int_equal(tase_can_3ax_status_decode(&f, NULL), TASE_EARG);
    assert_int_equal(st.position, 7);
    assert_int_equal(st.speed_dps, 5);
    assert_int_equal(m.command, TASE_3AX_MOVE_RETRACT);
}

/* Bad arguments of can.h give their documented codes and change nothing,
 * including a never-initialised splitter and a receiver whose role field
 * is corrupted. */
static void can_api_rejects_bad_arguments(void **state)
{
    static const uint8_t data[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    tase_can_split_t s;
    tase_can_split_t scopy;
    tase_can_frame_t f;
    tase_can_frame_t fcopy;
    tase_can_frame_t frames[2];
    tase_can_frame_t fbefore[2];
    tase_can_rx_t crx;
    tase_can_rx_t ccopy;
    uint32_t tx = 7;
    uint32_t rxid = 7;
    (void)state;

    memset(&f, 0x77, sizeof f);
    memcpy(&fcopy, &f, sizeof f);
    memset(&s, 0, sizeof s);
    s.len = 5; /* bytes left but no data: never initialised */
    memcpy(&scopy, &s, sizeof s);
    assert_int_equal(tase_can_split_next(&s, &f), TASE_EARG);
    assert_int_equal(tase_can_split_next(NULL, &f), TASE_EARG);
    assert_int_equal(tase_can_split_next(&s, NULL), TASE_EARG);
    assert_memory_equal(&s, &scopy, sizeof s);
    assert_memory_equal(&f, &fcopy, sizeof f);
    assert_int_equal(tase_can_split_init(&s, (tase_can_role_t)2, data, 1), TASE_EARG);
    assert_int_equal(tase_can_split_init(&s, TASE_CAN_ROLE_HOST, NULL, SIZE_MAX), TASE_EARG);
    assert_memory_equal(&s, &scopy, sizeof s);

    assert_int_equal(tase_can_role_ids((tase_can_role_t)2, &tx, &rxid), TASE_EARG);
    assert_int_equal(tx, 7);
    assert_int_equal(rxid, 7);

    memset(frames, 0x55, sizeof frames);
    memcpy(fbefore, frames, sizeof frames);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, sizeof data, frames, 1), TASE_ENOSPC);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, sizeof data, frames, 0), TASE_ENOSPC);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, NULL, SIZE_MAX, frames, SIZE_MAX),
                     TASE_EARG);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, sizeof data, NULL, 2), TASE_EARG);
    assert_int_equal(tase_can_split((tase_can_role_t)9, data, sizeof data, frames, 2), TASE_EARG);
    assert_memory_equal(frames, fbefore, sizeof frames);

    assert_int_equal(tase_can_accept((tase_can_role_t)9, &f), TASE_EARG);
    assert_int_equal(tase_can_accept(TASE_CAN_ROLE_HOST, NULL), TASE_EARG);
    assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_HOST), TASE_OK);
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_GIMBAL, data, 8, frames, 2), 1);
    crx.role = (tase_can_role_t)5;
    memcpy(&ccopy, &crx, sizeof crx);
    assert_int_equal(tase_can_rx_feed(&crx, &frames[0], NULL, NULL), TASE_EARG);
    assert_int_equal(tase_can_rx_feed(&crx, NULL, NULL, NULL), TASE_EARG);
    assert_memory_equal(&crx, &ccopy, sizeof crx);
    assert_int_equal(tase_can_rx_init(&crx, (tase_can_role_t)5), TASE_EARG);
    assert_memory_equal(&crx, &ccopy, sizeof crx);
}

/* can.h: only TASE_EUNKNOWN and TASE_ELENGTH change the instance (a
 * counter). A receiver whose datalink receiver is visibly corrupted (its
 * held length beyond the window; `busy` neither 0 nor 1) is refused with
 * TASE_EARG, as tase_rx_feed() refuses it, and nothing is counted: the
 * frame of this role used to be counted in frames_in and
 * frames_accepted before tase_rx_feed() refused its payload, and a busy
 * byte of 2 read as TASE_EBUSY, which a caller retries for ever. */
static void a_corrupted_datalink_receiver_is_refused_without_counting(void **state)
{
    tase_can_frame_t f = ext_frame(TASE_CAN_ID_TO_GIMBAL, angle_pkt, 8);
    tase_can_rx_t crx;
    tase_can_rx_t copy;
    got_t got;
    int k;
    (void)state;
    memset(&got, 0, sizeof got);
    for (k = 0; k < 2; k++) {
        assert_int_equal(tase_can_rx_init(&crx, TASE_CAN_ROLE_GIMBAL), TASE_OK);
        if (k == 0) {
            crx.rx.len = 0xFFFFu;
        } else {
            crx.rx.busy = 2u;
        }
        memcpy(&copy, &crx, sizeof crx);
        assert_int_equal(tase_can_rx_feed(&crx, &f, on_frame, &got), TASE_EARG);
        assert_memory_equal(&crx, &copy, sizeof crx);
    }
    assert_int_equal(got.n, 0);
}

/* tase_can_split() with no array: TASE_EARG for any byte count above 0
 * (a single byte too), whatever capacity is claimed. */
static void split_into_no_array_is_an_argument_error(void **state)
{
    static const uint8_t data[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    size_t n;
    (void)state;
    for (n = 1; n <= sizeof data; n++) {
        assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, n, NULL, 0), TASE_EARG);
        assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, n, NULL, 4), TASE_EARG);
    }
    assert_int_equal(tase_can_split(TASE_CAN_ROLE_HOST, data, 0, NULL, 0), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(can_api_rejects_bad_arguments),
        cmocka_unit_test(split_into_no_array_is_an_argument_error),
        cmocka_unit_test(a_corrupted_datalink_receiver_is_refused_without_counting),
        cmocka_unit_test(split_refuses_counts_an_int_result_cannot_carry),
        cmocka_unit_test(null_and_unknown_roles_are_rejected_without_counting),
        cmocka_unit_test(role_ids_follow_the_spec),
        cmocka_unit_test(angle_packet_from_gimbal_is_8_plus_6_bytes),
        cmocka_unit_test(split_covers_every_length_in_order),
        cmocka_unit_test(split_refuses_small_arrays_and_bad_arguments_without_writing),
        cmocka_unit_test(splitter_reports_progress_and_then_ends),
        cmocka_unit_test(max_frame_survives_host_to_gimbal),
        cmocka_unit_test(max_frame_survives_gimbal_to_host),
        cmocka_unit_test(receiver_takes_only_its_direction),
        cmocka_unit_test(other_ids_between_fragments_do_not_break_a_packet),
        cmocka_unit_test(can_receiver_calls_from_inside_its_callback),
        cmocka_unit_test(move_command_encodes_deploy_as_zero_and_retract_as_nonzero),
        cmocka_unit_test(move_command_values_mean_what_retract_deploy_cmd_means),
        cmocka_unit_test(move_command_rejects_bad_input),
        cmocka_unit_test(status_bytes_decode_to_position_and_signed_speed),
        cmocka_unit_test(status_round_trips_every_speed_and_position),
        cmocka_unit_test(status_encoder_range_checks_speed),
        cmocka_unit_test(frame_check_enforces_id_width_and_dlc),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
