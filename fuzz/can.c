/*
 * Fuzz harness: datalink reassembly over CAN with lost, repeated,
 * reordered, corrupted and foreign CAN frames; and the candump log parser.
 *
 * Input: mode byte. (mode & 3) == 3: candump mode, the rest is text split
 * into lines at '\n' (see check_candump()). Otherwise bit 0 is the sending
 * role (host or gimbal; the receiver has the other one) and bit 1 chooses
 * how the stream is cut: 0 each datalink frame on its own (as the roles
 * send), 1 the whole stream at once (CAN frames straddle two frames).
 * Then: count (1..16 datalink frames), per frame group, type, len
 * (0..253: byte % 254) and data; then one op byte per CAN frame, in order
 * (missing ops: pass):
 *   0..3 pass; 4 drop; 5 duplicate; 6 swap with the next one;
 *   7 inject a frame before this one, kind = op >> 3 (then pass it):
 *     0 another extended ID (4 bytes), 1 a standard frame (2 bytes: its
 *     id; 0x7FF: the receiver's extended ID number without the extended
 *     flag), 2 our ID with dlc 0, 3 our ID with dlc 9..15, 4 the other
 *     direction's ID, 5 a 3AX ID, 6 no injection but flip bits of this
 *     frame's data (pos, mask), 7 a frame of garbage with our ID (dlc,
 *     bytes).
 * Checks:
 *   - tase_can_rx_feed returns TASE_EUNKNOWN for foreign frames,
 *     TASE_ELENGTH for our ID with a bad dlc, else the frames it
 *     delivered; frames_ignored, bad_length, frames_accepted, frames_in,
 *     rx.stats.bytes_in and rx.stats.frames_ok match what was fed;
 *   - every delivered frame is exactly the accepted bytes at its offset
 *     (so its checksum holds); one that is not byte-for-byte a sent frame
 *     appears only if the fuzz damaged the stream or it lies inside the
 *     data of a sent frame (a frame carried in CAMERA_PASS-like data);
 *   - every sent frame whose CAN frames all arrived once, undamaged, in
 *     order and with nothing accepted between them is delivered at its
 *     place, unless a delivered frame that is not it overlaps it (a valid
 *     frame made of damaged neighbours' bytes: the receiver never reuses
 *     a valid frame's bytes).
 */
#include <string.h>

#include "fuzz.h"
#include "tase/can.h"
#include "tase/candump.h"

#define MAX_DL 16u
#define MAX_TX (MAX_DL * TASE_FRAME_MAX)
#define MAX_CF (MAX_TX / 8u + MAX_DL)
#define MAX_FED (3u * MAX_CF + 8u)
#define MAX_GOT (MAX_FED * 8u / 3u + 1u)

typedef struct {
    uint32_t start, end; /* in the sent stream */
} range_t;

typedef struct {
    int cf;          /* index of the sent CAN frame; -1: garbage */
    uint8_t damaged; /* data bits flipped */
    uint32_t at;     /* its payload's offset in the accepted stream */
} acc_t;

typedef struct {
    uint32_t start, end; /* in the accepted stream */
    uint8_t ours;        /* byte-identical to a sent frame */
} got_t;

static uint8_t txs[MAX_TX];
static range_t dl[MAX_DL];
static tase_can_frame_t cf[MAX_CF];
static range_t cfr[MAX_CF];
static acc_t acc[MAX_FED];
static uint8_t rxs[MAX_FED * 8u];
static got_t got[MAX_GOT];
static size_t ndl, ngot;

static void on_frame(void *user, const tase_frame_t *fr)
{
    uint8_t enc[TASE_FRAME_MAX];
    size_t total = (size_t)fr->len + TASE_FRAME_OVERHEAD, k;
    const tase_can_rx_t *crx = user;
    int n = tase_frame_build(fr->group, fr->type, fr->data, fr->len, enc, sizeof(enc));
    FZ_CHECK(n == (int)total);
    FZ_CHECK((size_t)fr->offset + total <= crx->rx.stats.bytes_in);
    FZ_CHECK(memcmp(enc, rxs + fr->offset, total) == 0);
    FZ_CHECK(ngot < MAX_GOT);
    got[ngot].start = fr->offset;
    got[ngot].end = fr->offset + (uint32_t)total;
    got[ngot].ours = 0;
    for (k = 0; k < ndl && !got[ngot].ours; k++) {
        got[ngot].ours =
            dl[k].end - dl[k].start == total && memcmp(txs + dl[k].start, enc, total) == 0;
    }
    ngot++;
}

/* Where sent frame k lies in the accepted stream, or -1 if it did not
 * arrive intact (all its CAN frames once, undamaged, in order, adjacent). */
static long intact_at(size_t k, size_t ncf, size_t nacc)
{
    size_t a = 0, b, i, j;
    while (cfr[a].end <= dl[k].start) {
        a++;
    }
    b = a;
    while (b + 1u < ncf && cfr[b + 1u].start < dl[k].end) {
        b++;
    }
    i = 0;
    while (i < nacc && acc[i].cf != (int)a) {
        i++;
    }
    if (i == nacc || i + (b - a) >= nacc) {
        return -1;
    }
    for (j = 0; j <= b - a; j++) {
        if (acc[i + j].cf != (int)(a + j) || acc[i + j].damaged) {
            return -1;
        }
    }
    for (j = 0; j < nacc; j++) { /* each exactly once */
        if (acc[j].cf >= (int)a && acc[j].cf <= (int)b && (j < i || j > i + (b - a))) {
            return -1;
        }
    }
    return (long)(acc[i].at + (dl[k].start - cfr[a].start));
}

static void check_candump(const uint8_t *text, size_t n)
{
    size_t pos = 0;
    while (pos < n) {
        const char *line = (const char *)text + pos;
        const uint8_t *nl = memchr(text + pos, '\n', n - pos);
        size_t len = nl != NULL ? (size_t)(nl - (text + pos)) + 1u : n - pos;
        tase_candump_rec_t rec, rec2, canary;
        char out[TASE_CANDUMP_LINE_MAX], out2[TASE_CANDUMP_LINE_MAX];
        int rc, w;
        pos += len;
        memset(&canary, 0xA5, sizeof(canary));
        rec = canary;
        rc = tase_candump_parse(line, len, &rec);
        if (rc != TASE_OK) {
            FZ_CHECK(rc == TASE_EFORMAT || rc == TASE_EUNSUPPORTED);
            FZ_CHECK(memcmp(&rec, &canary, sizeof(rec)) == 0);
            continue;
        }
        FZ_CHECK(tase_can_frame_check(&rec.frame) == TASE_OK);
        FZ_CHECK(rec.usec <= 999999u);
        FZ_CHECK(memchr(rec.ifname, 0, sizeof(rec.ifname)) != NULL);
        FZ_CHECK(strlen(rec.ifname) >= 1u);
        w = tase_candump_format(&rec, out, sizeof(out));
        FZ_CHECK(w > 0 && (size_t)w < sizeof(out) && out[w] == '\0' && out[w - 1] == '\n');
        /* too small by one: nothing written */
        memset(out2, 0x5A, sizeof(out2));
        FZ_CHECK(tase_candump_format(&rec, out2, (size_t)w) == TASE_ENOSPC);
        FZ_CHECK(out2[0] == 0x5A);
        rec2 = canary;
        FZ_CHECK(tase_candump_parse(out, (size_t)w, &rec2) == TASE_OK);
        FZ_CHECK(rec2.sec == rec.sec && rec2.usec == rec.usec);
        FZ_CHECK(strcmp(rec2.ifname, rec.ifname) == 0);
        FZ_CHECK(rec2.frame.id == rec.frame.id && rec2.frame.extended == rec.frame.extended);
        FZ_CHECK(rec2.frame.dlc == rec.frame.dlc);
        FZ_CHECK(memcmp(rec2.frame.data, rec.frame.data, rec.frame.dlc) == 0);
        FZ_CHECK(tase_candump_format(&rec2, out2, sizeof(out2)) == w);
        FZ_CHECK(memcmp(out, out2, (size_t)w + 1u) == 0);
    }
}

/* The frame to inject for kind 0..5 and 7; returns what feeding it must
 * give: TASE_EUNKNOWN (ignored), TASE_ELENGTH, or 1 (accepted). */
static int make_foreign(fz_in_t *in, unsigned kind, uint32_t rx_id, uint32_t tx_id,
                        tase_can_frame_t *f)
{
    unsigned j;
    memset(f, 0, sizeof(*f));
    f->extended = true;
    f->id = rx_id;
    f->dlc = 8;
    switch (kind) {
    case 0:
        for (j = 0; j < 4u; j++) {
            f->id = (f->id << 8) | fz_u8(in);
        }
        f->id &= TASE_CAN_EFF_MASK;
        if (f->id == rx_id) {
            f->id ^= 1u;
        }
        return TASE_EUNKNOWN;
    case 1: {
        uint16_t id = fz_u16(in);
        f->extended = false;
        f->id = (id & 0x7FFu) == 0x7FFu ? rx_id : (id & 0x7FFu);
        return TASE_EUNKNOWN;
    }
    case 2: f->dlc = 0; return TASE_ELENGTH;
    case 3: f->dlc = (uint8_t)(9u + fz_u8(in) % 7u); return TASE_ELENGTH;
    case 4: f->id = tx_id; return TASE_EUNKNOWN;
    case 5:
        f->id = (fz_u8(in) & 1u) != 0u ? TASE_CAN_ID_3AX_MOVE : TASE_CAN_ID_3AX_STATUS;
        f->dlc = 2;
        return TASE_EUNKNOWN;
    default:
        f->dlc = (uint8_t)(fz_u8(in) % 8u + 1u);
        for (j = 0; j < f->dlc; j++) {
            f->data[j] = fz_u8(in);
        }
        return 1;
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static tase_can_rx_t crx;
    fz_in_t in = {data, size};
    uint8_t mode = fz_u8(&in);
    tase_can_role_t sender = (mode & 1u) != 0u ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST;
    tase_can_role_t receiver =
        sender == TASE_CAN_ROLE_HOST ? TASE_CAN_ROLE_GIMBAL : TASE_CAN_ROLE_HOST;
    uint32_t rx_id, tx_id, ignored = 0, bad_len = 0, fed = 0;
    size_t ntx = 0, ncf = 0, nacc = 0, nrx = 0, i, k;
    int damaged = 0;

    if ((mode & 3u) == 3u) {
        check_candump(in.p, in.n);
        return 0;
    }
    FZ_CHECK(tase_can_role_ids(receiver, &tx_id, &rx_id) == TASE_OK);

    /* the datalink frames */
    ndl = fz_u8(&in) % MAX_DL + 1u;
    for (k = 0; k < ndl; k++) {
        uint8_t group = fz_u8(&in), type = fz_u8(&in), buf[TASE_DATA_MAX];
        size_t len = fz_u8(&in) % (TASE_DATA_MAX + 1u);
        int w;
        for (i = 0; i < len; i++) {
            buf[i] = fz_u8(&in);
        }
        w = tase_frame_build(group, type, buf, len, txs + ntx, sizeof(txs) - ntx);
        FZ_CHECK(w == (int)(len + TASE_FRAME_OVERHEAD));
        dl[k].start = (uint32_t)ntx;
        ntx += (size_t)w;
        dl[k].end = (uint32_t)ntx;
    }
    /* cut into CAN frames by the sender */
    for (k = 0; k < ndl; k++) {
        size_t from = (mode & 2u) != 0u ? 0u : dl[k].start;
        size_t to = (mode & 2u) != 0u ? ntx : dl[k].end;
        int n = tase_can_split(sender, txs + from, to - from, cf + ncf, MAX_CF - ncf);
        FZ_CHECK(n == (int)((to - from + 7u) / 8u));
        for (i = 0; i < (size_t)n; i++) {
            cfr[ncf + i].start = (uint32_t)(from + 8u * i);
            cfr[ncf + i].end = (uint32_t)(from + 8u * i + cf[ncf + i].dlc);
            FZ_CHECK(cf[ncf + i].extended && cf[ncf + i].id == rx_id);
            FZ_CHECK(tase_can_accept(receiver, &cf[ncf + i]) == (int)cf[ncf + i].dlc);
        }
        ncf += (size_t)n;
        if ((mode & 2u) != 0u) {
            break;
        }
    }

    FZ_CHECK(tase_can_rx_init(&crx, receiver) == TASE_OK);
    ngot = 0;
    for (i = 0; i < ncf; i++) {
        uint8_t op = fz_u8(&in);
        size_t order[2] = {i, i}, nsend = 1, s;
        uint8_t dmg = 0;
        tase_can_frame_t f = cf[i];
        if ((op & 7u) == 4u) {
            damaged = 1;
            continue;
        }
        if ((op & 7u) == 5u) {
            nsend = 2;
            damaged = 1;
        } else if ((op & 7u) == 6u && i + 1u < ncf) {
            order[0] = i + 1u;
            nsend = 2;
            i++;
            damaged = 1;
        } else if ((op & 7u) == 7u) {
            unsigned kind = (op >> 3) & 7u;
            if (kind == 6u) {
                uint8_t pos = fz_u8(&in), mask = fz_u8(&in);
                if (mask != 0u) {
                    dmg = 1;
                    damaged = 1;
                    f.data[pos % f.dlc] ^= mask;
                }
            } else {
                tase_can_frame_t x;
                size_t before = ngot;
                int expect = make_foreign(&in, kind, rx_id, tx_id, &x), r;
                if (expect == 1) { /* recorded before feeding: on_frame reads rxs */
                    FZ_CHECK(nacc < MAX_FED);
                    acc[nacc].cf = -1;
                    acc[nacc].damaged = 1;
                    acc[nacc].at = (uint32_t)nrx;
                    memcpy(rxs + nrx, x.data, x.dlc);
                    nrx += x.dlc;
                    nacc++;
                    damaged = 1;
                }
                r = tase_can_rx_feed(&crx, &x, on_frame, &crx);
                fed++;
                if (expect == 1) {
                    FZ_CHECK(r >= 0 && (size_t)r == ngot - before);
                } else {
                    FZ_CHECK(r == expect);
                    ignored += expect == TASE_EUNKNOWN;
                    bad_len += expect == TASE_ELENGTH;
                }
            }
        }
        for (s = 0; s < nsend; s++) {
            size_t before = ngot;
            const tase_can_frame_t *p = dmg ? &f : &cf[order[s]];
            int r;
            FZ_CHECK(nacc < MAX_FED);
            acc[nacc].cf = (int)order[s];
            acc[nacc].damaged = dmg;
            acc[nacc].at = (uint32_t)nrx;
            memcpy(rxs + nrx, p->data, p->dlc);
            nrx += p->dlc;
            nacc++;
            r = tase_can_rx_feed(&crx, p, on_frame, &crx);
            fed++;
            FZ_CHECK(r >= 0 && (size_t)r == ngot - before);
        }
    }
    {
        size_t before = ngot;
        int r = tase_rx_flush(&crx.rx, on_frame, &crx);
        FZ_CHECK(r >= 0 && (size_t)r == ngot - before);
    }

    /* counters */
    FZ_CHECK(crx.stats.frames_in == fed);
    FZ_CHECK(crx.stats.frames_ignored == ignored && crx.stats.bad_length == bad_len);
    FZ_CHECK(crx.stats.frames_accepted == (uint32_t)nacc);
    FZ_CHECK(crx.rx.stats.bytes_in == (uint32_t)nrx);
    FZ_CHECK(crx.rx.stats.frames_ok == (uint32_t)ngot);

    /* nothing foreign without damage, except a valid frame carried inside
     * the data of a sent one (frame.h: both are delivered) */
    for (i = 0; i < ngot; i++) {
        int nested = 0;
        for (k = 0; k < ndl && !got[i].ours && !damaged && !nested; k++) {
            long at = intact_at(k, ncf, nacc);
            nested = at >= 0 && got[i].start >= (uint32_t)at &&
                     got[i].end <= (uint32_t)at + (dl[k].end - dl[k].start);
        }
        FZ_CHECK(got[i].ours || damaged || nested);
    }
    /* every intact frame delivered at its place */
    for (k = 0; k < ndl; k++) {
        long at = intact_at(k, ncf, nacc);
        uint32_t len = dl[k].end - dl[k].start;
        int found = 0, excused = 0;
        if (at < 0) {
            FZ_CHECK(damaged);
            continue;
        }
        for (i = 0; i < ngot && !found; i++) {
            found = got[i].start == (uint32_t)at && got[i].end == (uint32_t)at + len;
        }
        for (i = 0; i < ngot && !found && !excused; i++) {
            excused = got[i].start < (uint32_t)at + len && (uint32_t)at < got[i].end;
        }
        if (!found && !excused) {
            fprintf(stderr, "intact frame %zu at %ld (+%u) lost\n", k, at, (unsigned)len);
        }
        FZ_CHECK(found || excused);
    }
    return 0;
}
