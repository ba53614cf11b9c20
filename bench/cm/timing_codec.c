/*
 * Worst case per call of the typed codec (tase/codec.h) and the
 * dispatcher: every encoder and decoder over every packet of the schema,
 * each at its longest form (all members set, CAMERA_PASS with 249 camera
 * bytes: 253 data bytes), the worst packet named.
 */
#define TASE_ALLOW_DEPRECATED /* tase_frame_encode() is measured too */
#include <stdio.h>
#include <string.h>

#include "tase/dispatch.h"
#include "tase/flags.h"
#include "tase/frame.h"
#include "timing.h"

/* Where the encoders write, at each address 0..3 mod 4 (the C library's
 * copies take other paths at other alignments). */
#define OUT_CAP (TASE_FRAME_MAX + 16u)
static uint8_t out_mem[OUT_CAP + 4u] __attribute__((aligned(4)));
static uint8_t *out = out_mem;
/* tase_frame_encode()'s data bytes, at each address 0..3 mod 4 */
static uint8_t in_mem[TASE_DATA_MAX + 4u] __attribute__((aligned(4)));
static const uint8_t *in_at = in_mem;
static size_t in_n;
static tase_packet_msg_t dec;
static tase_field_iter_t iter;
static tase_dispatch_t disp;
static tase_packet_handler_t handlers[TASE_PKT_COUNT];
static tase_rx_stats_t stats;

static void on_msg(void *user, const tase_frame_t *f, const void *m)
{
    (void)user;
    (void)m;
    timing_sink += f->len;
}

static void on_other(void *user, const tase_frame_t *f)
{
    (void)user;
    timing_sink += f->len;
}

/* cur_pkt's full message and frame, and a walk bound at its length. */
static bool prep_full(const tase_packet_desc_t *p)
{
    if (!prep_full_frame(p)) {
        return false;
    }
    (void)tase_field_iter_find(&iter, pkt_f.group, pkt_f.type, cur_len);
    return true;
}

/* Packets with a zero-length form (queries, GYRO_ZERO_CMD). */
static bool prep_query(const tase_packet_desc_t *p)
{
    cur_len = 0u;
    return tase_schema_length_ok(p, 0u);
}

MEASURED(c_encode, tase_packet_encode(cur_pkt->id, &full_msg, out, OUT_CAP))
MEASURED(c_encode_len, tase_packet_encode_len(cur_pkt->id, &full_msg, cur_len, out, OUT_CAP))
MEASURED(c_encode_query, tase_packet_encode_query(cur_pkt->id, out, OUT_CAP))
MEASURED(c_encode_data, tase_packet_encode_data(cur_pkt->id, &full_msg, out, OUT_CAP))
MEASURED(c_encode_data_len,
         tase_packet_encode_data_len(cur_pkt->id, &full_msg, cur_len, out, OUT_CAP))
MEASURED(c_decode, tase_packet_decode(&pkt_f, &dec))
MEASURED(c_decode_data, tase_packet_decode_data(cur_pkt->id, pkt_f.data, cur_len, &dec))
MEASURED(c_decode_desc, tase_packet_decode_desc(cur_pkt, pkt_f.data, cur_len, &dec))
MEASURED(c_decode_iter, tase_packet_decode_iter(&iter, pkt_f.data, &dec))

NOINLINE static void c_dispatch(void *ctx)
{
    (void)ctx;
    tase_dispatch_frame(&disp, &pkt_f);
}

/* The commands tase_command_check() judges, set to pass every check (the
 * longest path: a position command in range, a SPOI in range); every other
 * packet at its full form. cmd_data: the same as data bytes. */
static uint8_t cmd_data[TASE_DATA_MAX];
static size_t cmd_len;

static bool prep_cmd(const tase_packet_desc_t *p)
{
    int n;
    if (!prep_full_frame(p)) {
        return false;
    }
    if (p->id == TASE_ID_GIMBAL_CMD) {
        full_msg.gimbal_cmd.flags = TASE_GIMBAL_FLAGS_POSITION_STAB;
        full_msg.gimbal_cmd.pan = TASE_PAN_MAX_CDEG;
        full_msg.gimbal_cmd.tilt = TASE_TILT_MIN_CDEG;
    } else if (p->id == TASE_ID_SPOI_CMD) {
        full_msg.spoi_cmd.lat = 324000000;
        full_msg.spoi_cmd.lon = -648000000;
    }
    n = tase_packet_encode_data(p->id, &full_msg, cmd_data, sizeof(cmd_data));
    cmd_len = n > 0 ? (size_t)n : 0u;
    return n >= 0;
}

MEASURED(c_command_check, tase_command_check(cur_pkt->id, &full_msg))
MEASURED(c_command_check_data, tase_command_check_data(cur_pkt->id, cmd_data, cmd_len))

MEASURED(c_init_keep, tase_packet_init_keep(cur_pkt->id, &dec))

MEASURED(c_dispatch_init, tase_dispatch_init(&disp, handlers, on_other, NULL, NULL, &stats))

MEASURED(c_frame_encode, tase_frame_encode(out, OUT_CAP, 0x00u, 0x42u, in_at, in_n))

/* One codec function over every packet prep() takes. */
static void codec_one(const char *fn, bool (*prep)(const tase_packet_desc_t *p), measure_fn call,
                      const char *how)
{
    worst_t w = {0, ""};
    over_packets(&w, prep, nothing, call);
    worst_report(fn, &w, how);
}

/* An encoder over every packet prep() takes, writing at each address 0..3
 * mod 4, CAMERA_PASS's camera bytes read from each address 0..3 mod 4. */
static void encoder_one(const char *fn, bool (*prep)(const tase_packet_desc_t *p), measure_fn call,
                        const char *how)
{
    static char cam[40];
    worst_t w = {0, ""};
    size_t o, c, i;
    for (o = 0; o < 4u; o++) {
        out = &out_mem[o];
        for (c = 0; c < 4u; c++) {
            set_camera_off(c);
            for (i = 0; i < TASE_PKT_COUNT; i++) {
                bool tail;
                cur_pkt = tase_schema_at(i);
                tail = cur_pkt != NULL && (cur_pkt->flags & TASE_LEN_TAIL) != 0u;
                if (cur_pkt == NULL || (c > 0u && !tail) || !prep(cur_pkt)) {
                    continue; /* the camera's place matters to CAMERA_PASS alone */
                }
                (void)snprintf(cam, sizeof(cam), ", the camera bytes at %lu mod 4",
                               (unsigned long)c);
                worst_try(&w, measure_plain(call),
                          "%s (%lu data bytes)%s, written at an address %lu mod 4%s",
                          tase_schema_packet_name(cur_pkt), (unsigned long)cur_len, how,
                          (unsigned long)o, tail ? cam : "");
            }
        }
    }
    set_camera_off(0u);
    out = out_mem;
    worst_report(fn, &w, "");
}

void timing_codec(void)
{
    size_t i;
    for (i = 0; i < TASE_PKT_COUNT; i++) {
        handlers[i] = on_msg;
    }
    (void)tase_dispatch_init(&disp, handlers, on_other, NULL, NULL, &stats);
    encoder_one("tase_packet_encode", prep_full, c_encode, ", every member set");
    encoder_one("tase_packet_encode_len", prep_full, c_encode_len, ", every member set");
    codec_one("tase_packet_encode_query", prep_query, c_encode_query, "");
    encoder_one("tase_packet_encode_data", prep_full, c_encode_data, ", every member set");
    encoder_one("tase_packet_encode_data_len", prep_full, c_encode_data_len, ", every member set");
    codec_one("tase_packet_decode", prep_full, c_decode, "");
    codec_one("tase_packet_decode_data", prep_full, c_decode_data, "");
    codec_one("tase_packet_decode_desc", prep_full, c_decode_desc, "");
    codec_one("tase_packet_decode_iter", prep_full, c_decode_iter, ", walk bound at that length");
    codec_one("tase_dispatch_frame", prep_full, c_dispatch, ", trivial handler");
    codec_one("tase_command_check", prep_cmd, c_command_check, ", a command that passes");
    codec_one("tase_command_check_data", prep_cmd, c_command_check_data,
              ", a command that passes (decoded first)");
    codec_one("tase_packet_init_keep", prep_full, c_init_keep, "");
    report("tase_dispatch_init", measure_plain(c_dispatch_init),
           "handler table, default handler and stats given");
    {
        /* as tase_frame_build(): the last 5 data lengths, each at every
         * address mod 4, the frame written at every address mod 4 */
        worst_t w = {0, ""};
        size_t in, o;
        memset(in_mem, 0x5A, sizeof(in_mem));
        for (in = 0; in < 4u; in++) {
            in_at = &in_mem[in];
            for (o = 0; o < 4u; o++) {
                out = &out_mem[o];
                for (in_n = TASE_DATA_MAX - 4u; in_n <= TASE_DATA_MAX; in_n++) {
                    worst_try(&w, measure_plain(c_frame_encode),
                              "%lu data bytes at an address %lu mod 4, the frame written at %lu "
                              "mod 4 (the slowest of 249..253)",
                              (unsigned long)in_n, (unsigned long)in, (unsigned long)o);
                }
            }
        }
        out = out_mem;
        worst_report("tase_frame_encode", &w, "; deprecated: calls tase_frame_build");
    }
}
