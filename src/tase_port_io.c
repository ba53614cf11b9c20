/* Helpers over the port boundary: write-all and frame send. */
#include "tase/port_io.h"

#include <limits.h>

#include "tase/codec.h"
#include "tase/frame.h"

uint32_t tase_port_elapsed_ms(uint32_t now_ms, uint32_t since_ms)
{
    uint32_t d = now_ms - since_ms;
    return d >= 0x80000000u ? 0u : d;
}

int tase_port_write_all(const tase_port_t *port, const uint8_t *data, size_t n)
{
    size_t done = 0;
    unsigned idle = 0;
    uint32_t start = 0;
    uint32_t waited = 0;
    bool clock;

    if (port == NULL || port->ops == NULL || port->ops->write == NULL || (data == NULL && n > 0)) {
        return TASE_EARG;
    }
    if (n > (size_t)INT_MAX) {
        return TASE_EARG; /* the result must fit the int return */
    }
    clock = port->ops->now_ms != NULL;
    if (clock) {
        start = port->ops->now_ms(port->ctx);
    }
    while (done < n) {
        int r = port->ops->write(port->ctx, data + done, n - done);
        if (r > 0) {
            if ((size_t)r > n - done) {
                return TASE_EIO; /* a port claiming more than asked is broken */
            }
            done += (size_t)r;
        } else if (r != 0 && r != TASE_EAGAIN && r != TASE_ENOBUFS) {
            return r;
        } else {
            idle++;
        }
        if (clock && done < n) {
            /* The longest wait seen so far: a stale sample cannot undo it. */
            uint32_t e = tase_port_elapsed_ms(port->ops->now_ms(port->ctx), start);
            waited = e > waited ? e : waited;
        }
        if (done < n && (waited >= TASE_PORT_WRITE_TIMEOUT_MS || idle >= TASE_PORT_WRITE_TRIES)) {
            /* The port kept refusing until the deadline: its queue is full.
             * Nothing went out, or part of the frame did (the receiver drops
             * a cut frame by its checksum and finds the next one). */
            if (done == 0) {
                return r < 0 ? r : TASE_EAGAIN;
            }
            return TASE_ENOBUFS;
        }
    }
    return (int)n;
}

/* The end of both send helpers: an encoder's result n (checked first, as
 * port_io.h documents), then the port, then the write. */
static int send_encoded(const tase_port_t *port, const uint8_t *buf, int n)
{
    if (n < 0) {
        return n;
    }
    if (port == NULL) {
        return TASE_EARG;
    }
    return tase_port_write_all(port, buf, (size_t)n);
}

int tase_port_send_frame(const tase_port_t *port, uint8_t group, uint8_t type, const uint8_t *data,
                         size_t len)
{
    uint8_t buf[TASE_FRAME_MAX];
    int n = tase_frame_encode(buf, sizeof buf, group, type, data, len);

    return send_encoded(port, buf, n);
}

int tase_port_send_msg(const tase_port_t *port, uint16_t id, const void *msg)
{
    uint8_t buf[TASE_FRAME_MAX];
    int n = msg != NULL ? tase_packet_encode(id, msg, buf, sizeof buf)
                        : tase_packet_encode_len(id, NULL, 0u, buf, sizeof buf);

    return send_encoded(port, buf, n);
}

int tase_port_count_tx(int r, uint32_t *sent, uint32_t *errors)
{
    if (r >= 0) {
        if (sent != NULL) {
            (*sent)++;
        }
    } else if (r != TASE_EARG && r != TASE_ETOOLONG && r != TASE_ELENGTH && r != TASE_EUNKNOWN) {
        if (errors != NULL) {
            (*errors)++;
        }
    } else {
        /* the caller's mistake, not the link's */
    }
    return r;
}
