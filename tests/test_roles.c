/* The "done when": a host and a gimbal talk over a REAL
 * pseudo-terminal pair through the POSIX UART port (the gimbal runs in its
 * own thread on the real clock): query, echo, command, telemetry at the
 * configured rates. */
#define _DEFAULT_SOURCE

#include <pthread.h>
#include <pty.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "tase/gimbal.h"
#include "tase/host.h"
#include "tase/ids.h"
#include "tase/posix_uart.h"

typedef struct {
    tase_posix_uart_t uart;
    tase_gimbal_t g;
    tase_rx_t rx[1];
    int stop;
    /* written by the gimbal thread, read after join */
    unsigned commands;
    uint8_t command[8];
    unsigned spoi_queries;
} gimbal_side_t;

static const uint8_t spoi_now[19] = {0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A,
                                     0x0B, 0x0C, 0,    0,    0,    0,    0,    0,    0x80};

static int fill(void *user, unsigned port, uint16_t id, uint8_t *data, size_t cap, uint32_t now)
{
    size_t len = id == TASE_ID_GIMBAL_ANGLE ? 6u : id == TASE_ID_GIMBAL_RATE ? 18u : 63u;
    (void)user;
    (void)port;
    assert_true(cap >= len);
    memset(data, 0, len);
    data[0] = (uint8_t)(now >> 24);
    data[1] = (uint8_t)(now >> 16);
    data[2] = (uint8_t)(now >> 8);
    data[3] = (uint8_t)now;
    return (int)len;
}

static void gimbal_frame(void *user, unsigned port, const tase_frame_t *f)
{
    gimbal_side_t *s = user;
    uint16_t id = TASE_ID(f->group, f->type);
    if (id == TASE_ID_GIMBAL_CMD && f->len == 8) {
        s->commands++;
        memcpy(s->command, f->data, 8);
    } else if (id == TASE_ID_SPOI_CMD && f->len == 0) {
        s->spoi_queries++;
        tase_gimbal_send(&s->g, port, f->group, f->type, spoi_now, sizeof spoi_now);
    }
}

static void *gimbal_thread(void *arg)
{
    gimbal_side_t *s = arg;
    tase_port_t port = tase_posix_uart_port(&s->uart);
    uint8_t buf[64];

    while (!__atomic_load_n(&s->stop, __ATOMIC_ACQUIRE)) {
        int n = port.ops->read(port.ctx, buf, sizeof buf, 2);
        uint32_t now = port.ops->now_ms(port.ctx);
        if (n > 0) {
            tase_gimbal_feed(&s->g, 0, buf, (size_t)n, now);
        }
        tase_gimbal_poll(&s->g, now);
    }
    return NULL;
}

typedef struct {
    uint32_t since; /* count telemetry arriving at or after this time */
    uint32_t until;
    unsigned count[3];
    unsigned all;
} host_side_t;

static void host_frame(void *user, const tase_frame_t *f)
{
    host_side_t *h = user;
    uint32_t now = tase_posix_now_ms();
    uint16_t id = TASE_ID(f->group, f->type);
    int s = id == TASE_ID_GIMBAL_ANGLE        ? 0
            : id == TASE_ID_GIMBAL_RATE       ? 1
            : id == TASE_ID_GEOREFERENCE_DATA ? 2
                                              : -1;
    h->all++;
    if (s >= 0 && (uint32_t)(now - h->since) < (uint32_t)(h->until - h->since)) {
        h->count[s]++;
    }
}

static void host_and_gimbal_talk_over_a_real_pty(void **state)
{
    int master, slave;
    char name[128];
    static gimbal_side_t gs;
    static tase_host_t host;
    static host_side_t hs;
    tase_posix_uart_t hu;
    tase_port_t hport;
    tase_gimbal_app_t app = {NULL, fill, gimbal_frame, &gs, NULL, NULL, NULL};
    tase_port_t gport;
    pthread_t th;
    uint8_t reply[TASE_DATA_MAX], version[42];
    uint8_t rates[16] = {20, 5, 2, 0, 0, 10, 10, 4, 0, 0, 10, 10, 4, 0, 0, 1};
    const uint8_t cmd[8] = {0x11, 0x22, 0xEE, 0xDD, 0, 0, 0x00, 0x05};
    const uint8_t defaults[16] = {10, 10, 4, 0, 0, 10, 10, 4, 0, 0, 10, 10, 4, 0, 0, 0};
    uint32_t t;
    size_t i;
    int n;
    (void)state;

    assert_int_equal(openpty(&master, &slave, name, NULL, NULL), 0);
    memset(&gs, 0, sizeof gs);
    memset(&hs, 0, sizeof hs);
    assert_int_equal(tase_posix_uart_open(&gs.uart, name, 57600), TASE_OK);
    close(slave); /* the port has its own descriptor */
    gport = tase_posix_uart_port(&gs.uart);
    assert_int_equal(tase_gimbal_init(&gs.g, &gport, gs.rx, 1, &app, tase_posix_now_ms()), TASE_OK);
    for (i = 0; i < sizeof version; i++) {
        version[i] = (uint8_t)(0xA0u + i);
    }
    assert_int_equal(tase_gimbal_setup_set(&gs.g, 0x03, version, sizeof version, 0), TASE_OK);
    version[25] = version[31] = version[37] = 0; /* reserved: stored as zero */

    assert_int_equal(tase_posix_uart_attach(&hu, master, 57600), TASE_OK);
    hport = tase_posix_uart_port(&hu);
    assert_int_equal(tase_host_init(&host, &hport, host_frame, &hs), TASE_OK);
    assert_int_equal(pthread_create(&th, NULL, gimbal_thread, &gs), 0);

    /* Query: the defaults, while default-rate telemetry already flows. */
    n = tase_host_transact(&host, 0x48, 0x00, NULL, 0, reply, sizeof reply, 300, 3);
    assert_int_equal(n, 16);
    assert_memory_equal(reply, defaults, 16);
    n = tase_host_transact(&host, 0x48, 0x03, NULL, 0, reply, sizeof reply, 300, 3);
    assert_int_equal(n, 42);
    assert_memory_equal(reply, version, 42);
    n = tase_host_transact(&host, 0x10, 0x40, NULL, 0, reply, sizeof reply, 300, 3);
    assert_int_equal(n, 19);
    assert_memory_equal(reply, spoi_now, 19);

    /* Set and confirm: the echo carries the applied rates. */
    n = tase_host_transact(&host, 0x48, 0x00, rates, sizeof rates, reply, sizeof reply, 300, 3);
    assert_int_equal(n, 16);
    assert_memory_equal(reply, rates, 16);

    /* A command. */
    assert_int_equal(tase_host_send(&host, 0x00, 0x80, cmd, sizeof cmd), 16);

    /* Telemetry at the new rates: count 3 s of it, after 200 ms to settle. */
    t = tase_posix_now_ms();
    hs.since = t + 200u;
    hs.until = t + 3200u;
    while ((uint32_t)(tase_posix_now_ms() - t) < 3400u) {
        assert_true(tase_host_service(&host, 50) >= 0);
    }
    __atomic_store_n(&gs.stop, 1, __ATOMIC_RELEASE);
    pthread_join(th, NULL);

    print_message("3 s at 20/5/2 per s: angle %u, rate %u, georef %u frames\n", hs.count[0],
                  hs.count[1], hs.count[2]);
    assert_true(hs.count[0] >= 58 && hs.count[0] <= 62);
    assert_true(hs.count[1] >= 14 && hs.count[1] <= 16);
    assert_true(hs.count[2] >= 5 && hs.count[2] <= 7);
    assert_int_equal(gs.commands, 1);
    assert_memory_equal(gs.command, cmd, 8);
    assert_int_equal(gs.spoi_queries, 1);
    assert_int_equal(host.stats.replies, 4);
    assert_int_equal(host.stats.retries, 0);
    assert_int_equal(host.rx.stats.checksum_errors, 0);
    assert_int_equal(host.rx.stats.bytes_discarded, 0);
    assert_int_equal(gs.rx[0].stats.checksum_errors, 0);
    assert_int_equal(gs.g.stats.setup_applied, 1);
    assert_int_equal(gs.g.stats.tx_errors, 0);
    tase_posix_uart_close(&hu);
    tase_posix_uart_close(&gs.uart);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(host_and_gimbal_talk_over_a_real_pty),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
