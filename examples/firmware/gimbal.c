/* The gimbal's behaviour: setup echo, commands, telemetry. */
#include "gimbal.h"

#include <string.h>

#include "tase/ids.h"

/* Software 0.1.0 released 2024-05-17; board fields zero; camera A type 3
 * with 40.00..2.00 degrees of field of view; no cameras B and C. */
static const uint8_t version_info[GIMBAL_VERSION_LEN] = {
    0, 1, 0, 1, 0x07, 0xE8, 5,    17,   0,    0,    0, 0, 0, 0, 0, 0,    0, 0, 0, 0, 0,
    0, 0, 0, 3, 0,    0x0F, 0xA0, 0x00, 0xC8, 0xFF, 0, 0, 0, 0, 0, 0xFF, 0, 0, 0, 0, 0,
};

static void put16(uint8_t *p, int32_t v)
{
    p[0] = (uint8_t)(((uint32_t)v >> 8) & 0xFFu);
    p[1] = (uint8_t)((uint32_t)v & 0xFFu);
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

int16_t gimbal_sim_pan(uint32_t t)
{
    return (int16_t)(int32_t)((t * 3u) & 0x7FFFu);
}

int16_t gimbal_sim_tilt(uint32_t t)
{
    return (int16_t) - (int32_t)(t & 0x3FFFu);
}

void gimbal_init(gimbal_t *g, gimbal_tx_t tx, void *tx_user)
{
    static const uint8_t default_rates[GIMBAL_RATES_LEN] = {10, 10, 4,  0,  0, 10, 10, 4,
                                                            0,  0,  10, 10, 4, 0,  0,  0};
    memset(g, 0, sizeof(*g));
    memcpy(g->rates, default_rates, sizeof(g->rates));
    g->filter[0] = 100; /* 10 Hz cutoff */
    g->filter[1] = 5;   /* 0.5 deg/s decimation */
    g->tx = tx;
    g->tx_user = tx_user;
}

static void send(gimbal_t *g, uint16_t id, const uint8_t *data, size_t len)
{
    uint8_t out[TASE_FRAME_MAX];
    int n = tase_frame_encode(out, sizeof(out), TASE_ID_GROUP(id), TASE_ID_TYPE(id), data, len);
    if (n < 0 || g->tx(g->tx_user, out, (size_t)n) != n) {
        g->tx_errors++;
    }
}

/* A setup packet with data stores it; with or without data the gimbal
 * answers with its current settings (spec 4.4: "each of these packets can
 * be sent as zero length in order to query the current settings"). */
static void on_setting(gimbal_t *g, uint16_t id, uint8_t *store, size_t size, const tase_frame_t *f)
{
    if (f->len != 0u && f->len != size) {
        g->wrong_length++;
        return;
    }
    if (f->len == size && store != NULL) {
        memcpy(store, f->data, size);
    }
    send(g, id, store != NULL ? store : version_info, size);
    g->replies++;
}

static void on_gimbal_cmd(gimbal_t *g, const tase_frame_t *f)
{
    if (f->len != 8u) {
        g->wrong_length++;
        return;
    }
    g->cmd_pan = (int16_t)(int32_t)(((uint32_t)f->data[0] << 8) | f->data[1]);
    g->cmd_tilt = (int16_t)(int32_t)(((uint32_t)f->data[2] << 8) | f->data[3]);
    g->cmd_flags = f->data[6];
    g->commands++;
}

/* PLUG-IN POINT for typed dispatch. Today this switch on the raw
 * (group, type) is the dispatcher and the handlers read bytes. When the
 * dispatch/codec modules are merged, register on_gimbal_cmd/on_setting as
 * handlers in a tase dispatch table (with typed structs from the codec),
 * make the dispatcher's frame handler the one main.c passes to
 * tase_rx_feed(), and let its default handler count `ignored` and its
 * error hook count `wrong_length`. */
void gimbal_on_frame(void *user, const tase_frame_t *f)
{
    gimbal_t *g = user;
    uint16_t id = TASE_ID(f->group, f->type);
    switch (id) {
    case TASE_ID_GIMBAL_CMD: on_gimbal_cmd(g, f); break;
    case TASE_ID_GYRO_ZERO_CMD:
        if (f->len == 0u) {
            g->gyro_zeros++;
        } else {
            g->wrong_length++;
        }
        break;
    case TASE_ID_PACKET_RATE: on_setting(g, id, g->rates, sizeof(g->rates), f); break;
    case TASE_ID_SENSOR_FILTER: on_setting(g, id, g->filter, sizeof(g->filter), f); break;
    case TASE_ID_NAV_SOURCE: on_setting(g, id, g->nav, sizeof(g->nav), f); break;
    case TASE_ID_SYSTEM_VERSION: on_setting(g, id, NULL, GIMBAL_VERSION_LEN, f); break;
    default: g->ignored++; break;
    }
}

static void send_telemetry(gimbal_t *g, unsigned which, uint32_t t)
{
    uint8_t d[63];
    size_t i;
    switch (which) {
    case 0: /* GIMBAL_ANGLE: pan, tilt, roll */
        put16(&d[0], gimbal_sim_pan(t));
        put16(&d[2], gimbal_sim_tilt(t));
        put16(&d[4], 0);
        send(g, TASE_ID_GIMBAL_ANGLE, d, 6u);
        break;
    case 1: /* GIMBAL_RATE: time, axis rates, body rates, reserved, mode */
        memset(d, 0, 18u);
        put32(&d[0], t);
        put16(&d[4], 300);
        put16(&d[6], -100);
        d[17] = (uint8_t)(0x80u | (g->cmd_flags & 0x20u ? 0x08u : 0u));
        send(g, TASE_ID_GIMBAL_RATE, d, 18u);
        break;
    default: /* GEOREFERENCE_DATA: time, then a pattern standing in for
              * position and camera geometry */
        put32(&d[0], t);
        for (i = 4u; i < sizeof(d); i++) {
            d[i] = (uint8_t)(i + t);
        }
        send(g, TASE_ID_GEOREFERENCE_DATA, d, sizeof(d));
        break;
    }
    g->telemetry++;
}

void gimbal_poll(gimbal_t *g, uint32_t now_ms)
{
    unsigned k;
    for (k = 0; k < 3u; k++) {
        uint8_t rate = g->rates[k]; /* external port 1 */
        if (rate == 0u) {
            continue;
        }
        while ((int32_t)(now_ms - g->next_due[k]) >= 0) {
            send_telemetry(g, k, g->next_due[k]);
            g->next_due[k] += 1000u / rate;
        }
    }
}
