/*
 * gimbal.h - the gimbal side of the example firmware: what a TASE gimbal
 * does with the frames it receives, and the telemetry it sends.
 *
 * Board-independent: frames come in through gimbal_on_frame() (a
 * tase_rx_handler_t), bytes go out through a transmit function, time comes
 * in as milliseconds. The same code would run on a real Cortex-M with a
 * real UART.
 */
#ifndef GIMBAL_H
#define GIMBAL_H

#include "tase/frame.h"

/* Transmit a complete frame. Returns n or a negative TASE_E* code. */
typedef int (*gimbal_tx_t)(void *user, const uint8_t *data, size_t n);

#define GIMBAL_RATES_LEN 16u   /* PACKET_RATE (spec 4.4.1) */
#define GIMBAL_FILTER_LEN 2u   /* SENSOR_FILTER (4.4.2) */
#define GIMBAL_NAV_LEN 2u      /* NAV_SOURCE (4.4.5) */
#define GIMBAL_VERSION_LEN 42u /* SYSTEM_VERSION (4.4.4), read only */

typedef struct {
    /* Settings the setup group reads and writes (persistent on a real
     * gimbal; RAM here). */
    uint8_t rates[GIMBAL_RATES_LEN];
    uint8_t filter[GIMBAL_FILTER_LEN];
    uint8_t nav[GIMBAL_NAV_LEN];
    /* Last GIMBAL_CMD. */
    int16_t cmd_pan;
    int16_t cmd_tilt;
    uint8_t cmd_flags;
    /* Counters. */
    uint32_t commands;     /* GIMBAL_CMD accepted */
    uint32_t gyro_zeros;   /* GYRO_ZERO_CMD accepted */
    uint32_t replies;      /* setup echoes sent */
    uint32_t telemetry;    /* telemetry frames sent */
    uint32_t ignored;      /* valid frames this gimbal does not act on */
    uint32_t wrong_length; /* known packet with a length it cannot have */
    uint32_t tx_errors;    /* encode or transmit failures */
    /* Telemetry schedule: next due time of ANGLE, RATE, GEOREFERENCE. */
    uint32_t next_due[3];
    gimbal_tx_t tx;
    void *tx_user;
} gimbal_t;

/* Factory settings, nothing sent yet, telemetry due from time 0. */
void gimbal_init(gimbal_t *g, gimbal_tx_t tx, void *tx_user);

/* Receive handler: act on one valid frame (user is the gimbal_t). */
void gimbal_on_frame(void *user, const tase_frame_t *frame);

/* Send every telemetry frame due at or before now_ms. */
void gimbal_poll(gimbal_t *g, uint32_t now_ms);

/* Telemetry contents are a function of the scheduled time t (ms), so a
 * receiver can check them: pan = 3t, tilt = -t (1/100 degree, wrapping). */
int16_t gimbal_sim_pan(uint32_t t);
int16_t gimbal_sim_tilt(uint32_t t);

#endif /* GIMBAL_H */
