/* can-utils log lines <-> tase_can_frame_t. No stdio: the core must build
 * for targets without printf/sscanf, and sscanf would accept signs and
 * spaces where the format has none. */
#include "tase/candump.h"

#include <string.h>

typedef struct {
    const char *p;
    size_t len;
    size_t i;
} cursor_t;

static int peek(const cursor_t *c)
{
    return c->i < c->len ? (unsigned char)c->p[c->i] : -1;
}

static int hexval(int ch)
{
    if (ch >= '0' && ch <= '9') {
        return ch - (int)'0';
    }
    if (ch >= 'A' && ch <= 'F') {
        return ch - (int)'A' + 10;
    }
    if (ch >= 'a' && ch <= 'f') {
        return ch - (int)'a' + 10;
    }
    return -1;
}

static bool is_blank(int ch)
{
    return ch == ' ' || ch == '\t';
}

/* Skips spaces and tabs; returns how many. */
static size_t skip_blanks(cursor_t *c)
{
    size_t start = c->i;
    while (is_blank(peek(c))) {
        c->i++;
    }
    return c->i - start;
}

/* Decimal digits into *v; at most max_digits, at least one. */
static bool read_dec(cursor_t *c, size_t max_digits, uint64_t *v, size_t *ndigits)
{
    size_t n = 0;
    uint64_t acc = 0;
    while (peek(c) >= '0' && peek(c) <= '9') {
        if (n == max_digits) {
            return false;
        }
        /* acc * 10 + digit must fit: UINT64_MAX is 1844674407370955161 * 10
         * + 5 (compared, not divided: no 64-bit division on 32-bit MCUs) */
        if (acc > 1844674407370955161u || (acc == 1844674407370955161u && peek(c) > '5')) {
            return false;
        }
        acc = acc * 10u + (uint64_t)(peek(c) - '0');
        c->i++;
        n++;
    }
    *v = acc;
    *ndigits = n;
    return n > 0;
}

static bool read_timestamp(cursor_t *c, uint64_t *sec, uint32_t *usec)
{
    uint64_t s;
    uint64_t u;
    size_t nd;
    if (peek(c) != '(') {
        return false;
    }
    c->i++;
    if (!read_dec(c, 20, &s, &nd) || peek(c) != '.') {
        return false;
    }
    c->i++;
    if (!read_dec(c, 6, &u, &nd) || nd != 6 || peek(c) != ')') {
        return false;
    }
    c->i++;
    *sec = s;
    *usec = (uint32_t)u;
    return true;
}

static bool name_char_ok(int ch)
{
    return ch > ' ' && ch < 0x7F;
}

static bool read_ifname(cursor_t *c, char *name)
{
    size_t n = 0;
    while (name_char_ok(peek(c))) {
        if (n + 1u >= TASE_CANDUMP_IFNAME_MAX) {
            return false;
        }
        name[n] = (char)peek(c);
        n++;
        c->i++;
    }
    name[n] = '\0';
    return n > 0;
}

/* Identifier up to '#'. Returns TASE_OK, TASE_EFORMAT or TASE_EUNSUPPORTED
 * (an error frame: its data is read as a classic frame's, and the line
 * must end after it like any other). */
static int read_id(cursor_t *c, uint32_t *id, bool *extended)
{
    uint32_t v = 0;
    size_t n = 0;
    int d = hexval(peek(c));
    while (d >= 0) {
        if (n == 8u) {
            return TASE_EFORMAT;
        }
        v = (v << 4) | (uint32_t)d;
        c->i++;
        n++;
        d = hexval(peek(c));
    }
    if (peek(c) != '#') {
        return TASE_EFORMAT;
    }
    c->i++;
    if (n == 3u) {
        if (v > TASE_CAN_SFF_MASK) {
            return TASE_EFORMAT;
        }
        *extended = false;
    } else if (n == 8u) {
        /* can-utils prints error frames with CAN_ERR_FLAG (bit 29) set in
         * an 8-digit identifier; bits 30/31 never appear in a log. */
        if (v > TASE_CAN_EFF_MASK) {
            return v <= 0x3FFFFFFFu ? TASE_EUNSUPPORTED : TASE_EFORMAT;
        }
        *extended = true;
    } else {
        return TASE_EFORMAT;
    }
    *id = v;
    return TASE_OK;
}

/* Data bytes as pairs of hex digits, at most `max` (into data when it is
 * not NULL), each after an optional '.' (as canplayer reads them: a
 * separator before any byte, the first too, and one at the end). Returns
 * the count, or -1. */
static int read_hex_bytes(cursor_t *c, uint8_t *data, unsigned max)
{
    unsigned n = 0;
    for (;;) {
        int hi;
        int lo;
        if (peek(c) == '.') {
            c->i++;
        }
        hi = hexval(peek(c));
        if (hi < 0) {
            return (int)n;
        }
        c->i++;
        lo = hexval(peek(c));
        if (lo < 0 || n == max) {
            return -1;
        }
        c->i++;
        if (data != NULL) {
            data[n] = (uint8_t)(((unsigned)hi << 4) | (unsigned)lo);
        }
        n++;
    }
}

/* The raw DLC suffix of a classic frame with 8 data bytes: '_' and one
 * hex digit 9..F. Returns 1 (one is there), 0 (none) or -1 (a '_' that
 * begins a malformed one). */
static int read_raw_dlc(cursor_t *c, unsigned n)
{
    if (peek(c) != '_') {
        return 0;
    }
    c->i++;
    if (n != TASE_CAN_DLC_MAX || hexval(peek(c)) < 9) {
        return -1;
    }
    c->i++;
    return 1;
}

/* After the '#': the frame's data. Returns TASE_OK, TASE_EFORMAT, or
 * TASE_EUNSUPPORTED for a well-formed frame this library cannot
 * represent (the caller still checks that the line ends after it): a
 * remote frame (R or r, an optional length digit 0..8, a raw DLC after 8)
 * or a CAN FD frame ('#', a flags digit, up to 64 bytes). A classic frame
 * of 8 bytes with a raw DLC 9..F is those 8 bytes (classic CAN carries 8
 * for any DLC above 8; the SocketCAN port receives it so). */
static int read_data(cursor_t *c, uint8_t *data, uint8_t *dlc)
{
    int n;
    int raw;
    if (peek(c) == '#') {
        c->i++;
        if (hexval(peek(c)) < 0) {
            return TASE_EFORMAT;
        }
        c->i++;
        return read_hex_bytes(c, NULL, 64u) < 0 ? TASE_EFORMAT : TASE_EUNSUPPORTED;
    }
    if (peek(c) == 'R' || peek(c) == 'r') {
        unsigned len = 0;
        c->i++;
        if (peek(c) >= '0' && peek(c) <= '8') {
            len = (unsigned)(peek(c) - '0');
            c->i++;
        }
        return read_raw_dlc(c, len) < 0 ? TASE_EFORMAT : TASE_EUNSUPPORTED;
    }
    n = read_hex_bytes(c, data, TASE_CAN_DLC_MAX);
    if (n < 0) {
        return TASE_EFORMAT;
    }
    raw = read_raw_dlc(c, (unsigned)n);
    if (raw < 0) {
        return TASE_EFORMAT;
    }
    *dlc = (uint8_t)n;
    return TASE_OK;
}

/* After the frame: blanks, an optional T/R flag, an optional line end. */
static bool at_line_end(cursor_t *c)
{
    if (skip_blanks(c) > 0 && (peek(c) == 'T' || peek(c) == 'R')) {
        c->i++;
        (void)skip_blanks(c);
    }
    if (peek(c) == '\r') {
        c->i++;
    }
    if (peek(c) == '\n') {
        c->i++;
    }
    return c->i == c->len;
}

int tase_candump_parse(const char *line, size_t len, tase_candump_rec_t *rec)
{
    cursor_t c;
    tase_candump_rec_t r;
    int rc;
    if (line == NULL || rec == NULL) {
        return TASE_EARG;
    }
    c.p = line;
    c.len = len;
    c.i = 0;
    (void)memset(&r, 0, sizeof(r));
    (void)skip_blanks(&c);
    if (!read_timestamp(&c, &r.sec, &r.usec) || skip_blanks(&c) == 0 ||
        !read_ifname(&c, r.ifname) || skip_blanks(&c) == 0) {
        return TASE_EFORMAT;
    }
    rc = read_id(&c, &r.frame.id, &r.frame.extended);
    if (rc != TASE_EFORMAT) {
        /* an error frame's data is a classic frame's */
        int d = read_data(&c, r.frame.data, &r.frame.dlc);
        rc = (d == TASE_OK) ? rc : d;
    }
    if (rc == TASE_EFORMAT || !at_line_end(&c)) {
        return TASE_EFORMAT;
    }
    if (rc != TASE_OK) {
        return rc;
    }
    *rec = r;
    return TASE_OK;
}

static size_t put_hex(char *out, uint32_t v, unsigned digits)
{
    static const char hex[] = "0123456789ABCDEF";
    unsigned k;
    for (k = 0; k < digits; k++) {
        out[k] = hex[(v >> (4u * (digits - 1u - k))) & 0xFu];
    }
    return digits;
}

static size_t put_char(char *out, char ch)
{
    out[0] = ch;
    return 1u;
}

/* v in decimal, at least min_digits (<= 20) with leading zeros. Digits
 * from the top by subtraction (at most 9 per digit): no 64-bit division,
 * which is a library call on 32-bit targets. */
static size_t put_dec(char *out, uint64_t v, unsigned min_digits)
{
    /* powers of ten up to 10^19, the largest a uint64_t holds */
    static const uint64_t pow10_u64[20] = {1u,
                                           10u,
                                           100u,
                                           1000u,
                                           10000u,
                                           100000u,
                                           1000000u,
                                           10000000u,
                                           100000000u,
                                           1000000000u,
                                           10000000000u,
                                           100000000000u,
                                           1000000000000u,
                                           10000000000000u,
                                           100000000000000u,
                                           1000000000000000u,
                                           10000000000000000u,
                                           100000000000000000u,
                                           1000000000000000000u,
                                           10000000000000000000u};
    uint64_t rest = v;
    size_t top = (min_digits > 0u) ? (size_t)min_digits - 1u : 0u;
    size_t n = 0;
    size_t k;
    while (top < 19u && pow10_u64[top + 1u] <= v) {
        top++;
    }
    for (k = top + 1u; k > 0u; k--) {
        char d = '0';
        while (rest >= pow10_u64[k - 1u]) {
            rest -= pow10_u64[k - 1u];
            d++;
        }
        out[n] = d;
        n++;
    }
    return n;
}

int tase_candump_format(const tase_candump_rec_t *rec, char *out, size_t cap)
{
    char line[TASE_CANDUMP_LINE_MAX];
    size_t n = 0;
    size_t k;
    size_t namelen;
    if (rec == NULL || out == NULL || rec->usec > 999999u ||
        tase_can_frame_check(&rec->frame) != TASE_OK) {
        return TASE_EARG;
    }
    namelen = 0;
    while (namelen < TASE_CANDUMP_IFNAME_MAX && rec->ifname[namelen] != '\0') {
        if (!name_char_ok((unsigned char)rec->ifname[namelen])) {
            return TASE_EARG;
        }
        namelen++;
    }
    if (namelen == 0u || namelen == TASE_CANDUMP_IFNAME_MAX) {
        return TASE_EARG;
    }
    n += put_char(&line[n], '(');
    n += put_dec(&line[n], rec->sec, 10);
    n += put_char(&line[n], '.');
    n += put_dec(&line[n], rec->usec, 6);
    n += put_char(&line[n], ')');
    n += put_char(&line[n], ' ');
    (void)memcpy(&line[n], rec->ifname, namelen);
    n += namelen;
    n += put_char(&line[n], ' ');
    n += put_hex(&line[n], rec->frame.id, rec->frame.extended ? 8u : 3u);
    n += put_char(&line[n], '#');
    for (k = 0; k < rec->frame.dlc; k++) {
        n += put_hex(&line[n], rec->frame.data[k], 2);
    }
    n += put_char(&line[n], '\n');
    if (n + 1u > cap) {
        return TASE_ENOSPC;
    }
    (void)memcpy(out, line, n);
    out[n] = '\0';
    return (int)n;
}
