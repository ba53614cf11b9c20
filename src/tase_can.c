/* The datalink over CAN and the 3AX frames (spec section 5). */
#include "tase/can.h"

#include <string.h>

#include "tase_frame_private.h"

static bool role_valid(tase_can_role_t role)
{
    return role == TASE_CAN_ROLE_HOST || role == TASE_CAN_ROLE_GIMBAL;
}

int tase_can_role_ids(tase_can_role_t role, uint32_t *tx_id, uint32_t *rx_id)
{
    bool host = role == TASE_CAN_ROLE_HOST;
    if (!role_valid(role)) {
        return TASE_EARG;
    }
    if (tx_id != NULL) {
        *tx_id = host ? TASE_CAN_ID_TO_GIMBAL : TASE_CAN_ID_FROM_GIMBAL;
    }
    if (rx_id != NULL) {
        *rx_id = host ? TASE_CAN_ID_FROM_GIMBAL : TASE_CAN_ID_TO_GIMBAL;
    }
    return TASE_OK;
}

int tase_can_frame_check(const tase_can_frame_t *f)
{
    if (f == NULL) {
        return TASE_EARG;
    }
    if (f->id > (f->extended ? TASE_CAN_EFF_MASK : TASE_CAN_SFF_MASK)) {
        return TASE_ERANGE;
    }
    return f->dlc > TASE_CAN_DLC_MAX ? TASE_ELENGTH : TASE_OK;
}

int tase_can_split_init(tase_can_split_t *s, tase_can_role_t sender, const uint8_t *data, size_t n)
{
    uint32_t id;
    if (s == NULL || (data == NULL && n > 0) || tase_can_role_ids(sender, &id, NULL) != TASE_OK) {
        return TASE_EARG;
    }
    s->data = data;
    s->len = n;
    s->pos = 0;
    s->id = id;
    return TASE_OK;
}

int tase_can_split_next(tase_can_split_t *s, tase_can_frame_t *out)
{
    size_t chunk;
    if (s == NULL || out == NULL) {
        return TASE_EARG;
    }
    if (s->pos >= s->len) {
        return 0;
    }
    if (s->data == NULL) {
        return TASE_EARG; /* never initialised or corrupted: bytes left, no data */
    }
    chunk = s->len - s->pos;
    if (chunk > TASE_CAN_DLC_MAX) {
        chunk = TASE_CAN_DLC_MAX;
    }
    (void)memset(out, 0, sizeof(*out));
    out->id = s->id;
    out->extended = true;
    out->dlc = (uint8_t)chunk;
    (void)memcpy(out->data, s->data + s->pos, chunk);
    s->pos += chunk;
    return (int)chunk;
}

int tase_can_split(tase_can_role_t sender, const uint8_t *data, size_t n, tase_can_frame_t *out,
                   size_t cap)
{
    tase_can_split_t s;
    size_t count = n / TASE_CAN_DLC_MAX + (n % TASE_CAN_DLC_MAX != 0u ? 1u : 0u);
    size_t i = 0;
    if ((out == NULL && n > 0) || tase_can_split_init(&s, sender, data, n) != TASE_OK) {
        return TASE_EARG;
    }
    /* The return value is an int; a count that does not fit cannot have
     * a caller array behind it either. */
    if (count > cap || count > (size_t)INT16_MAX) {
        return TASE_ENOSPC;
    }
    /* i < count first: with n == 0, out may be NULL and &out[0] is not
     * even to be formed. */
    while (i < count && tase_can_split_next(&s, &out[i]) > 0) {
        i++;
    }
    return (int)i;
}

int tase_can_accept(tase_can_role_t role, const tase_can_frame_t *f)
{
    uint32_t rx_id;
    if (f == NULL || tase_can_role_ids(role, NULL, &rx_id) != TASE_OK) {
        return TASE_EARG;
    }
    if (!f->extended || f->id != rx_id) {
        return TASE_EUNKNOWN;
    }
    if (f->dlc == 0u || f->dlc > TASE_CAN_DLC_MAX) {
        return TASE_ELENGTH;
    }
    return (int)f->dlc;
}

int tase_can_rx_init(tase_can_rx_t *crx, tase_can_role_t role)
{
    if (crx == NULL || !role_valid(role)) {
        return TASE_EARG;
    }
    (void)memset(crx, 0, sizeof(*crx));
    crx->role = role;
    return tase_rx_init(&crx->rx);
}

int tase_can_rx_feed(tase_can_rx_t *crx, const tase_can_frame_t *f, tase_rx_handler_t on_frame,
                     void *user)
{
    int n;
    if (crx == NULL || f == NULL) {
        return TASE_EARG;
    }
    /* What tase_rx_feed() would refuse, refused before anything is
     * counted: a call from inside its own frame callback (TASE_EBUSY), a
     * visibly corrupted receiver (TASE_EARG). */
    n = tase_rx_state_check(&crx->rx);
    if (n != TASE_OK) {
        return n;
    }
    n = tase_can_accept(crx->role, f);
    if (n == TASE_EARG) {
        return n; /* corrupted role field: do not count */
    }
    crx->stats.frames_in++;
    if (n == TASE_EUNKNOWN) {
        crx->stats.frames_ignored++;
        return n;
    }
    if (n < 0) {
        crx->stats.bad_length++;
        return n;
    }
    crx->stats.frames_accepted++;
    return tase_rx_feed(&crx->rx, f->data, (size_t)n, on_frame, user);
}

/* Both 3AX frames are an extended ID with exactly two bytes. */
static void frame2(tase_can_frame_t *out, uint32_t id, uint8_t b0, uint8_t b1)
{
    (void)memset(out, 0, sizeof(*out));
    out->id = id;
    out->extended = true;
    out->dlc = 2;
    out->data[0] = b0;
    out->data[1] = b1;
}

static int check2(const tase_can_frame_t *f, uint32_t id)
{
    if (!f->extended || f->id != id) {
        return TASE_EUNKNOWN;
    }
    return f->dlc == 2u ? TASE_OK : TASE_ELENGTH;
}

int tase_can_3ax_move_encode(const tase_can_3ax_move_t *m, tase_can_frame_t *out)
{
    if (m == NULL || out == NULL) {
        return TASE_EARG;
    }
    if (m->command != TASE_3AX_MOVE_DEPLOY && m->command != TASE_3AX_MOVE_RETRACT) {
        return TASE_ERANGE;
    }
    /* 0xFE rather than 1: "non-zero" to a drive that tests for zero, and
     * "completely retracted" to one that reads the byte as a target. */
    frame2(out, TASE_CAN_ID_3AX_MOVE,
           m->command == TASE_3AX_MOVE_RETRACT ? (uint8_t)TASE_3AX_RETRACT_BYTE : 0u, 0u);
    return TASE_OK;
}

int tase_can_3ax_move_decode(const tase_can_frame_t *f, tase_can_3ax_move_t *m)
{
    int rc;
    if (f == NULL || m == NULL) {
        return TASE_EARG;
    }
    rc = check2(f, TASE_CAN_ID_3AX_MOVE);
    if (rc == TASE_OK) {
        m->command = f->data[0] == 0u ? TASE_3AX_MOVE_DEPLOY : TASE_3AX_MOVE_RETRACT;
    }
    return rc;
}

int tase_can_3ax_status_encode(const tase_can_3ax_status_t *st, tase_can_frame_t *out)
{
    int units;
    if (st == NULL || out == NULL) {
        return TASE_EARG;
    }
    if (st->speed_dps < TASE_3AX_SPEED_MIN_DPS || st->speed_dps > TASE_3AX_SPEED_MAX_DPS ||
        st->speed_dps % TASE_3AX_SPEED_STEP_DPS != 0) {
        return TASE_ERANGE;
    }
    units = st->speed_dps / TASE_3AX_SPEED_STEP_DPS;
    /* Two's complement byte built arithmetically: no implementation-defined
     * signed-to-unsigned conversion. */
    frame2(out, TASE_CAN_ID_3AX_STATUS, st->position, (uint8_t)(units < 0 ? units + 256 : units));
    return TASE_OK;
}

int tase_can_3ax_status_decode(const tase_can_frame_t *f, tase_can_3ax_status_t *st)
{
    int rc;
    if (f == NULL || st == NULL) {
        return TASE_EARG;
    }
    rc = check2(f, TASE_CAN_ID_3AX_STATUS);
    if (rc == TASE_OK) {
        int units = f->data[1] >= 0x80u ? (int)f->data[1] - 256 : (int)f->data[1];
        st->position = f->data[0];
        st->speed_dps = (int16_t)(units * TASE_3AX_SPEED_STEP_DPS);
    }
    return rc;
}
