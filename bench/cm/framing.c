/* The framing entry points and nothing else, for the flash measurement of
 * bench/bench.sh: linked with --gc-sections, what is left of
 * src/tase_frame.c and src/tase_frame_time.c is what a firmware that calls
 * tase_rx_init(), tase_rx_push(), tase_rx_feed() and tase_rx_flush()
 * carries. */
#include "tase/frame.h"

static void on_frame(void *user, const tase_frame_t *f)
{
    *(volatile uint8_t *)user = f->len;
}

int main(void);

int main(void)
{
    static tase_rx_t rx;
    static volatile uint8_t sink;
    static const uint8_t b[8] = {0};
    (void)tase_rx_init(&rx);
    (void)tase_rx_push(&rx, b[0], on_frame, (void *)&sink);
    (void)tase_rx_feed(&rx, b, sizeof(b), on_frame, (void *)&sink);
    (void)tase_rx_flush(&rx, on_frame, (void *)&sink);
    return 0;
}
