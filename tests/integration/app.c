/* A small application as a user writes it, built by every consumer kind of
 * scripts/checks/integration.sh: a GIMBAL_CMD goes through the encoder,
 * the receiver and the dispatcher into a typed handler, a CAN receiver
 * (whose instance holds a tase_rx_t) is initialised, and, when the build
 * links a port, that port is exercised a little; a stalling port checks
 * that the library applies the frame write deadline the application's
 * headers name (TASE_PORT_WRITE_TIMEOUT_MS, tase/config.h). Exit 0 and
 * one "ok" line when everything behaved. APP_EXPECT_WRITE_TIMEOUT_MS,
 * when defined, is the TASE_PORT_WRITE_TIMEOUT_MS the build's
 * configuration header must have set. */
#include <stdio.h>
#include <string.h>

#include "tase/can.h"
#include "tase/codec.h"
#include "tase/dispatch.h"
#include "tase/frame.h"
#include "tase/ids.h"
#include "tase/port_io.h"
#if defined(APP_POSIX_UART)
#include "tase/posix_uart.h"
#endif
#if defined(APP_BAREMETAL)
#include "tase/bm_uart.h"
#endif
#if defined(APP_SOCKETCAN)
#include "tase/socketcan.h"
#endif

static int pan_seen = -1;

static void on_gimbal_cmd(void *user, const tase_frame_t *frame, const void *msg)
{
    const tase_gimbal_cmd_t *cmd = (const tase_gimbal_cmd_t *)msg;
    (void)user;
    (void)frame;
    pan_seen = cmd->pan;
}

/* A port that takes one byte per write() call while its clock advances
 * one millisecond per reading: tase_port_write_all() gives up with an
 * error after exactly TASE_PORT_WRITE_TIMEOUT_MS bytes, as the library
 * was built. */
typedef struct {
    uint32_t clock_ms;
    size_t taken;
} slow_port_t;

static int slow_write(void *ctx, const uint8_t *data, size_t n)
{
    slow_port_t *p = (slow_port_t *)ctx;
    (void)data;
    (void)n;
    p->taken++;
    return 1;
}

static uint32_t slow_now(void *ctx)
{
    slow_port_t *p = (slow_port_t *)ctx;
    return p->clock_ms++;
}

/* The library's write deadline equals the one these headers name. */
static int write_deadline_agrees(void)
{
    static const tase_port_ops_t ops = {slow_write, NULL, slow_now};
    static const uint8_t data[2u * TASE_PORT_WRITE_TIMEOUT_MS + 1u];
    slow_port_t sp = {0u, 0u};
    tase_port_t port;
    port.ops = &ops;
    port.ctx = &sp;
    port.bytes_per_s = 0u;
    return tase_port_write_all(&port, data, sizeof data) < 0 &&
           sp.taken == (size_t)TASE_PORT_WRITE_TIMEOUT_MS;
}

#if defined(APP_BAREMETAL)
static int no_tx(void *hw, const uint8_t *data, size_t n)
{
    (void)hw;
    (void)data;
    (void)n;
    return 0;
}
static uint32_t no_millis(void *hw)
{
    (void)hw;
    return 0;
}
#endif

int main(void)
{
    static const tase_packet_handler_t handlers[TASE_PKT_COUNT] = {
        [TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd,
    };
    tase_gimbal_cmd_t cmd;
    uint8_t wire[TASE_FRAME_MAX];
    tase_rx_t rx;
    tase_can_rx_t crx;
    tase_dispatch_t d;
    int n;
    int fails = 0;

    memset(&cmd, 0, sizeof cmd);
    cmd.pan = 4500;
    n = tase_packet_encode(TASE_ID_GIMBAL_CMD, &cmd, wire, sizeof wire);
    if (n <= 0 || tase_rx_init(&rx) != TASE_OK ||
        tase_dispatch_init(&d, handlers, NULL, NULL, NULL, &rx.stats) != TASE_OK) {
        fails++;
    } else if (tase_rx_feed(&rx, wire, (size_t)n, tase_dispatch_frame, &d) != 1 ||
               pan_seen != 4500) {
        fails++;
    }
    if (tase_can_rx_init(&crx, TASE_CAN_ROLE_GIMBAL) != TASE_OK) {
        fails++;
    }
    if (!write_deadline_agrees()) {
        fails++;
    }
#if defined(APP_EXPECT_WRITE_TIMEOUT_MS)
    if (TASE_PORT_WRITE_TIMEOUT_MS != APP_EXPECT_WRITE_TIMEOUT_MS) {
        fails++;
    }
#endif
#if defined(APP_POSIX_UART)
    {
        tase_posix_uart_t u;
        if (!tase_posix_uart_baud_supported(115200u) ||
            tase_posix_uart_open(&u, "/nonexistent/tty", 115200u) != TASE_ENODEV) {
            fails++;
        }
    }
#endif
#if defined(APP_SOCKETCAN)
    {
        /* No such interface: a clear error (which one depends on whether
         * the kernel has CAN at all), never TASE_EARG or success. */
        tase_socketcan_t s;
        int r = tase_socketcan_open(&s, "tasenosuch0", TASE_CAN_ROLE_HOST);
        if (r >= 0 || r == TASE_EARG) {
            fails++;
        }
    }
#endif
#if defined(APP_BAREMETAL)
    {
        static const tase_bm_uart_hooks_t hooks = {no_tx, no_millis, NULL, NULL, NULL};
        static uint8_t ring[512];
        tase_bm_uart_t u;
        int i;
        pan_seen = -1;
        if (tase_bm_uart_init(&u, ring, sizeof ring, &hooks, NULL) != TASE_OK) {
            fails++;
        } else {
            for (i = 0; i < n; i++) {
                tase_bm_uart_rx_isr(&u, wire[i]);
            }
            if (tase_bm_uart_poll(&u, &rx, tase_dispatch_frame, &d) != 1 || pan_seen != 4500) {
                fails++;
            }
        }
    }
#endif
    printf("%s: tase %s, ABI level %u, sizeof(tase_rx_t) %u, TASE_PORT_WRITE_TIMEOUT_MS %u, "
           "TASE_RX_CANDIDATES %u\n",
           fails ? "FAIL" : "ok", TASE_VERSION_STRING, (unsigned)TASE_ABI_LEVEL,
           (unsigned)sizeof(tase_rx_t), (unsigned)TASE_PORT_WRITE_TIMEOUT_MS,
           (unsigned)TASE_RX_CANDIDATES);
    return fails ? 1 : 0;
}
