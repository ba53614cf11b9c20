/* Helpers over the port boundary: write-all and frame send. */
#include "tase/port_io.h"

#include <limits.h>
#include <string.h>

#include "tase/codec.h"
#include "tase/frame.h"
#include "tase/ids.h"

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
    unsigned idle;   /* write() calls that took nothing */
    size_t done;     /* bytes the port took */
    bool clock;
} wr_t;

static void wr_init(wr_t *w, const tase_port_t *port)
{
    w->port = port;
    w->idle = 0;
    w->done = 0;
    w->waited = 0;
    w->start = 0;
    w->clock = port->ops->now_ms != NULL;
    if (w->clock) {
        w->start = port->ops->now_ms(port->ctx);
    }
}

/* Write data[0..n) as the next piece of the frame; TASE_OK when all of it
 * went, else the result tase_port_write_all() documents. */
static int wr_put(wr_t *w, const uint8_t *data, size_t n)
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
            w->done += (size_t)r;
        } else if (r != 0 && r != TASE_EAGAIN && r != TASE_ENOBUFS) {
            return r;
        } else {
            w->idle++;
        }
        if (w->clock && off < n) {
            /* The longest wait seen so far: a stale sample cannot undo it. */
            uint32_t e = tase_port_elapsed_ms(port->ops->now_ms(port->ctx), w->start);
            w->waited = e > w->waited ? e : w->waited;
        }
        if (off < n &&
            (w->waited >= TASE_PORT_WRITE_TIMEOUT_MS || w->idle >= TASE_PORT_WRITE_TRIES)) {
            /* The port kept refusing until the deadline: its queue is full.
             * Nothing went out, or part of the frame did (the receiver drops
             * a cut frame by its checksum and finds the next one). */
            if (w->done == 0) {
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

/* A frame goes out in pieces of up to STAGE bytes, summed on the way: no
 * frame buffer on the stack. STAGE is a multiple of 8, so a CAN port packs
 * every piece but the last into whole 8-byte frames, as it would the
 * frame in one write. */
#define STAGE 24u

/* Write the frame of (group, type) whose data is a[0..na) then b[0..nb)
 * (na + nb <= 253, checked by the callers) to port: header, data and
 * checksum staged through STAGE bytes. */
static int send_pieces(const tase_port_t *port, uint8_t group, uint8_t type, const uint8_t *a,
                       size_t na, const uint8_t *b, size_t nb)
{
    uint8_t st[STAGE];
    wr_t w;
    const uint8_t *src = a;
    size_t len = na; /* bytes of src */
    size_t off = 0;  /* of them staged */
    bool second = false;
    size_t n = TASE_FRAME_HEADER;
    uint16_t sum;
    int r;

    st[0] = 0x00u;
    st[1] = 0xFFu;
    st[2] = 0x5Au;
    st[3] = (uint8_t)(na + nb + 2u);
    st[4] = group;
    st[5] = type;
    sum = tase_checksum(0u, st, TASE_FRAME_HEADER);
    wr_init(&w, port);
    for (;;) {
        size_t k = len - off;
        if (k > STAGE - n) {
            k = STAGE - n;
        }
        if (k > 0u) {
            (void)memcpy(&st[n], &src[off], k);
            sum = tase_checksum(sum, &st[n], k);
            n += k;
            off += k;
        }
        if (off == len && !second) {
            second = true; /* the second span (maybe empty) */
            src = b;
            len = nb;
            off = 0;
            continue;
        }
        if (off == len && n + 2u <= STAGE) {
            st[n] = (uint8_t)(sum >> 8);
            st[n + 1u] = (uint8_t)sum;
            r = wr_put(&w, st, n + 2u);
            return r < 0 ? r : (int)(na + nb + TASE_FRAME_OVERHEAD);
        }
        r = wr_put(&w, st, n);
        if (r < 0) {
            return r;
        }
        n = 0;
    }
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
    return send_pieces(port, group, type, data, len, NULL, 0u);
}

/* The longest fixed data of a typed packet (GEOREFERENCE_DATA's 63);
 * CAMERA_PASS's camera bytes go out from the caller's buffer.
 * tests/test_port_io.c sends every packet of the schema through it. */
#define MSG_FIXED_MAX 63u

int tase_port_send_msg(const tase_port_t *port, uint16_t id, const void *msg)
{
    uint8_t data[MSG_FIXED_MAX];
    const uint8_t *tail = NULL;
    size_t ntail = 0;
    int n;

    if (id == TASE_ID_CAMERA_PASS && msg != NULL) {
        /* the fixed bytes here, the camera bytes where they are */
        tase_camera_pass_t head = *(const tase_camera_pass_t *)msg;
        if (head.data == NULL && head.len > 0u) {
            return TASE_EARG; /* the codec's order: EARG, then ETOOLONG */
        }
        if (head.len > TASE_CAMERA_PASS_MAX) {
            return TASE_ETOOLONG;
        }
        tail = head.data;
        ntail = head.len;
        head.len = 0;
        head.data = NULL;
        n = tase_packet_encode_data(id, &head, data, sizeof data);
    } else if (msg != NULL) {
        n = tase_packet_encode_data(id, msg, data, sizeof data);
    } else {
        n = tase_packet_encode_data_len(id, NULL, 0u, data, sizeof data);
    }
    if (n < 0) {
        return n;
    }
    if (!port_writable(port)) {
        return TASE_EARG;
    }
    return send_pieces(port, TASE_ID_GROUP(id), TASE_ID_TYPE(id), data, (size_t)n, tail, ntail);
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
