/* Helpers over the port boundary: write-all and frame send. */
#include "tase/port_io.h"

#include <limits.h>
#include <string.h>

#include "tase/codec.h"
#include "tase/frame.h"
#include "tase/ids.h"

#include "tase_codec_private.h"

uint32_t tase_port_elapsed_ms(uint32_t now_ms, uint32_t since_ms)
{
    uint32_t d = now_ms - since_ms;
    return d >= 0x80000000u ? 0u : d;
}

/* One frame write in progress: the progress and the one deadline of
 * tase_port_write_all(), kept across the pieces of a frame. */
typedef struct {
    const tase_port_t *port;
    uint32_t start;  /* now_ms() at the first write */
    uint32_t waited; /* the longest wait seen, ms */
    uint32_t idle;   /* write() calls that took nothing (without a clock: in
                      * all; with one: since the clock last moved on) */
    bool done;       /* the port took some of the frame */
    bool clock;
} wr_t;

static TASE_INLINE_ void wr_init(wr_t *w, const tase_port_t *port)
{
    w->port = port;
    w->idle = 0;
    w->done = false;
    w->waited = 0;
    w->start = 0;
    w->clock = port->ops->now_ms != NULL;
    if (w->clock) {
        w->start = port->ops->now_ms(port->ctx);
    }
}

/* Write data[0..n) as the next piece of the frame; TASE_OK when all of it
 * went, else the result tase_port_write_all() documents. */
static TASE_INLINE_ int wr_put(wr_t *w, const uint8_t *data, size_t n)
{
    const tase_port_t *port = w->port;
    size_t off = 0;
    while (off < n) {
        int r = port->ops->write(port->ctx, data + off, n - off);
        if (r > 0) {
            if ((size_t)r > n - off) {
                return TASE_EIO; /* a port claiming more than asked is broken */
            }
            off += (size_t)r;
            w->done = true;
        } else if (r != 0 && r != TASE_EAGAIN && r != TASE_ENOBUFS) {
            return r;
        } else {
            w->idle++;
        }
        if (w->clock && off < n) {
            /* The longest wait seen so far: a stale sample cannot undo it.
             * While it grows, time passes and the deadline bounds the
             * retries (a TX ring that refuses until it drains is retried
             * until then, however fast it refuses); only a clock that
             * stands still (or goes back) counts calls. */
            uint32_t e = tase_port_elapsed_ms(port->ops->now_ms(port->ctx), w->start);
            if (e > w->waited) {
                w->waited = e;
                w->idle = 0;
            }
        }
        if (off < n && (w->waited >= TASE_PORT_WRITE_TIMEOUT_MS ||
                        w->idle >= (w->clock ? TASE_PORT_WRITE_SPINS : TASE_PORT_WRITE_TRIES))) {
            /* The port kept refusing until the deadline: its queue is full.
             * Nothing went out, or part of the frame did (the receiver drops
             * a cut frame by its checksum and finds the next one). */
            if (!w->done) {
                return r < 0 ? r : TASE_EAGAIN;
            }
            return TASE_ENOBUFS;
        }
    }
    return TASE_OK;
}

static bool port_writable(const tase_port_t *port)
{
    return port != NULL && port->ops != NULL && port->ops->write != NULL;
}

int tase_port_write_all(const tase_port_t *port, const uint8_t *data, size_t n)
{
    wr_t w;
    int r;
    if (!port_writable(port) || (data == NULL && n > 0)) {
        return TASE_EARG;
    }
    if (n > (size_t)INT_MAX) {
        return TASE_EARG; /* the result must fit the int return */
    }
    wr_init(&w, port);
    r = wr_put(&w, data, n);
    return r < 0 ? r : (int)n;
}

/* A frame goes out in pieces of up to STAGE bytes, produced and summed
 * on the way: no frame or packet buffer on the stack. STAGE is a multiple
 * of 8, so a CAN port packs every piece but the last into whole 8-byte
 * frames, as it would the frame in one write. */
#define STAGE 16u

/* Write the frame of (group, type) with `len` data bytes (<= 253, checked
 * by the callers) to port: the w->fixed bytes of a typed packet (w NULL:
 * none), then tail[0..len - fixed). The one path of both senders; the
 * write loop is inlined here, so the port's write() is called from this
 * frame and nothing deeper (tase_port_send_msg() <= 128 B of stack on
 * Cortex-M4 -Os, issue 26). */
static int send_stream(const tase_port_t *port, uint8_t group, uint8_t type, tase_wire_t *w,
                       const uint8_t *tail, size_t len)
{
    uint8_t st[STAGE];
    wr_t wr;
    size_t fixed = w != NULL ? w->fixed : 0u;
    size_t d;                     /* data (then checksum) bytes staged */
    size_t n = TASE_FRAME_HEADER; /* bytes in the stage */
    uint16_t sum;
    st[0] = TASE_SYNC1;
    st[1] = TASE_SYNC2;
    st[2] = TASE_SYNC3;
    st[3] = (uint8_t)(len + 2u);
    st[4] = group;
    st[5] = type;
    sum = (uint16_t)(TASE_SYNC1 + TASE_SYNC2 + TASE_SYNC3 + len + 2u + group + type);
    wr_init(&wr, port);
    d = 0;
    while (d < len + 2u) {
        int r;
        /* fill the stage: the fields byte by byte, the tail in a run, then
         * the checksum (big-endian) */
        while (n < STAGE && d < len + 2u) {
            if (d < fixed) {
                uint8_t b = tase_wire_byte(w, d);
                st[n] = b;
                sum = (uint16_t)(sum + b);
                n++;
                d++;
            } else if (d < len) {
                size_t k = STAGE - n;
                size_t j;
                if (tail == NULL) {
                    return TASE_EARG; /* not reached: the callers pass a tail when len > fixed */
                }
                if (k > len - d) {
                    k = len - d;
                }
                for (j = 0; j < k; j++) {
                    uint8_t b = tail[d - fixed + j];
                    st[n + j] = b;
                    sum = (uint16_t)(sum + b);
                }
                n += k;
                d += k;
            } else {
                st[n] = (uint8_t)(d == len ? sum >> 8 : sum);
                n++;
                d++;
            }
        }
        r = wr_put(&wr, st, n);
        if (r < 0) {
            return r;
        }
        n = 0;
    }
    return (int)(len + TASE_FRAME_OVERHEAD);
}

int tase_port_send_frame(const tase_port_t *port, uint8_t group, uint8_t type, const uint8_t *data,
                         size_t len)
{
    /* the encoder's checks first (tase_frame_build()'s codes) */
    if (data == NULL && len > 0u) {
        return TASE_EARG;
    }
    if (len > TASE_DATA_MAX) {
        return TASE_ETOOLONG;
    }
    if (!port_writable(port)) {
        return TASE_EARG;
    }
    return send_stream(port, group, type, NULL, data, len);
}

int tase_port_send_msg(const tase_port_t *port, uint16_t id, const void *msg)
{
    tase_wire_t w;
    const uint8_t *tail = NULL;
    int n = tase_wire_begin(&w, id, msg); /* the codec's checks first */
    if (n < 0) {
        return n;
    }
    if (!port_writable(port)) {
        return TASE_EARG;
    }
    if ((size_t)n > w.fixed) { /* CAMERA_PASS: the camera bytes where they are */
        tail = ((const tase_camera_pass_t *)msg)->data;
    }
    return send_stream(port, TASE_ID_GROUP(id), TASE_ID_TYPE(id), &w, tail, (size_t)n);
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
