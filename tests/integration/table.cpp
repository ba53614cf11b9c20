// C++ consumer of scripts/checks/integration.sh: includes every public
// header (tase_all.h, generated from the installed or source headers) and
// builds its dispatcher table as tase/dispatch.h documents for C++, a
// constexpr table set up at compile time. The script checks that the table
// is in a read-only section and runs the program where it can.
#include "tase_all.h"

#include <stdio.h>

static int pan_seen = -1;

static void on_gimbal_cmd(void *user, const tase_frame_t *frame, const void *msg)
{
    (void)user;
    (void)frame;
    pan_seen = static_cast<const tase_gimbal_cmd_t *>(msg)->pan;
}

struct handler_table {
    tase_packet_handler_t h[TASE_PKT_COUNT];
};
constexpr handler_table make_handlers()
{
    handler_table t{};
    t.h[TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd;
    return t;
}
static constexpr handler_table handlers = make_handlers();

int main()
{
    tase_gimbal_cmd_t cmd = {};
    uint8_t wire[TASE_FRAME_MAX];
    tase_rx_t rx;
    tase_dispatch_t d;
    cmd.pan = -1234;
    int n = tase_packet_encode(TASE_ID_GIMBAL_CMD, &cmd, wire, sizeof wire);
    if (n <= 0 || tase_rx_init(&rx) != TASE_OK ||
        tase_dispatch_init(&d, handlers.h, nullptr, nullptr, nullptr, &rx.stats) != TASE_OK ||
        tase_rx_feed(&rx, wire, static_cast<size_t>(n), tase_dispatch_frame, &d) != 1 ||
        pan_seen != -1234) {
        printf("FAIL: C++ handler table\n");
        return 1;
    }
    printf("ok: C++ handler table, tase %s\n", TASE_VERSION_STRING);
    return 0;
}
