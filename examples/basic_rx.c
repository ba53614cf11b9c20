/* The README's example: encode a few frames, corrupt the stream, feed it
 * through a receiver and print what comes out. */
#include <stdio.h>

#include "tase/frame.h"

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    printf("frame at offset %lu: group 0x%02X type 0x%02X, %u data bytes\n",
           (unsigned long)f->offset, f->group, f->type, (unsigned)f->len);
}

int main(void)
{
    static const uint8_t angle[6] = {0x03, 0xE8, 0xFE, 0x0C, 0x00, 0x00};
    uint8_t stream[128];
    size_t n = 0;
    tase_rx_t rx;
    int rc;

    stream[n++] = 0x42; /* line noise */
    rc = tase_frame_build(0x08, 0x10, angle, sizeof(angle), &stream[n], sizeof(stream) - n);
    stream[n + 3] = 0xFF; /* corrupt its Size: it now claims 253 data bytes */
    n += (size_t)rc;
    rc = tase_frame_build(0x08, 0x10, angle, sizeof(angle), &stream[n], sizeof(stream) - n);
    n += (size_t)rc;
    rc = tase_frame_build(0x00, 0x40, NULL, 0, &stream[n], sizeof(stream) - n);
    n += (size_t)rc;

    tase_rx_init(&rx);
    tase_rx_feed(&rx, stream, n, on_frame, NULL);
    tase_rx_flush(&rx, on_frame, NULL);
    printf("%lu bytes in, %lu frames ok, %lu checksum errors, %lu bytes discarded\n",
           (unsigned long)rx.stats.bytes_in, (unsigned long)rx.stats.frames_ok,
           (unsigned long)rx.stats.checksum_errors, (unsigned long)rx.stats.bytes_discarded);
    return rx.stats.frames_ok == 2 ? 0 : 1;
}
