/* Tests of the KLV metadata packet: codec, stream scanner, units. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#include <cmocka.h>

#include "tase/klv.h"

/* ---- a packet built by hand from table 31 ----------------------------- */

/* Values chosen so each sign and byte position shows. Byte sums of each
 * item (tag + length + value bytes) are in the comments; they add up to
 * the checksum. */
static const uint8_t hand_packet[87] = {
    /* universal key */
    0x06, 0x0E, 0x2B, 0x34, 0x02, 0x03, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x46,                                              /* BER length 70 */
    0x01, 0x08, 0, 0, 0, 0x01, 0x02, 0x03, 0x04, 0x05, /* 1+8+1+2+3+4+5 = 24 */
    0x02, 0x04, 0x12, 0x34, 0x56, 0x78,                /* 2+4+18+52+86+120     = 282  */
    0x03, 0x04, 0xFF, 0xFF, 0xFF, 0xFE,                /* 3+4+255+255+255+254  = 1026 */
    0x04, 0x02, 0x10, 0x00,                            /* 4+2+16               = 22   */
    0x05, 0x02, 0x80, 0x00,                            /* 5+2+128              = 135  */
    0x06, 0x02, 0xFF, 0x00,                            /* 6+2+255              = 263  */
    0x07, 0x02, 0x40, 0x00,                            /* 7+2+64               = 73   */
    0x08, 0x02, 0x01, 0x02,                            /* 8+2+1+2              = 13   */
    0x09, 0x02, 0xFF, 0xFF,                            /* 9+2+255+255          = 521  */
    0x0A, 0x02, 0x00, 0x10,                            /* 10+2+16              = 28   */
    0x0B, 0x02, 0xFF, 0xF0,                            /* 11+2+255+240         = 508  */
    0x0C, 0x02, 0x20, 0x00,                            /* 12+2+32              = 46   */
    0x0D, 0x02, 0x18, 0x00,                            /* 13+2+24              = 39   */
    0x0E, 0x02, 0xE0, 0x00,                            /* 14+2+224             = 240  */
    /* 24+282+1026+22+135+263+73+13+521+28+508+46+39+240 = 3220 = 0x0C94 */
    0x0F, 0x02, 0x0C, 0x94};

static tase_klv_t hand_values(void)
{
    tase_klv_t k;
    memset(&k, 0, sizeof(k));
    k.utc = 0x0102030405ull;
    k.lat = 0x12345678;
    k.lon = -2;
    k.alt = 0x1000;
    k.pan = 0x8000;
    k.tilt = -256;
    k.heading = 0x4000;
    k.pitch = 0x0102;
    k.roll = -1;
    k.vnorth = 16;
    k.veast = -16;
    k.hfov = 0x2000;
    k.vfov = 0x1800;
    k.gps_status = 0xE000;
    return k;
}

static void assert_klv_equal(const tase_klv_t *a, const tase_klv_t *b)
{
    assert_true(a->utc == b->utc);
    assert_int_equal(a->lat, b->lat);
    assert_int_equal(a->lon, b->lon);
    assert_int_equal(a->alt, b->alt);
    assert_int_equal(a->pan, b->pan);
    assert_int_equal(a->tilt, b->tilt);
    assert_int_equal(a->heading, b->heading);
    assert_int_equal(a->pitch, b->pitch);
    assert_int_equal(a->roll, b->roll);
    assert_int_equal(a->vnorth, b->vnorth);
    assert_int_equal(a->veast, b->veast);
    assert_int_equal(a->hfov, b->hfov);
    assert_int_equal(a->vfov, b->vfov);
    assert_int_equal(a->gps_status, b->gps_status);
}

/* A decode that must fail must also leave the output alone. */
static void assert_decode_fails(const uint8_t *p, size_t n, int err)
{
    tase_klv_t k, before;
    memset(&k, 0xA5, sizeof(k));
    before = k;
    assert_int_equal(tase_klv_decode(p, n, &k), err);
    assert_memory_equal(&k, &before, sizeof(k));
}

/* Deterministic PRNG so failures are reproducible. */
static uint32_t rng_state = 0x12345u;
static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static tase_klv_t random_values(void)
{
    tase_klv_t k;
    k.utc = ((uint64_t)rnd() << 32) | rnd();
    k.lat = (int32_t)rnd();
    k.lon = (int32_t)rnd();
    k.alt = (uint16_t)rnd();
    k.pan = (uint16_t)rnd();
    k.tilt = (int16_t)rnd();
    k.heading = (uint16_t)rnd();
    k.pitch = (int16_t)rnd();
    k.roll = (int16_t)rnd();
    k.vnorth = (int16_t)rnd();
    k.veast = (int16_t)rnd();
    k.hfov = (uint16_t)rnd();
    k.vfov = (uint16_t)rnd();
    k.gps_status = (uint16_t)rnd();
    return k;
}

/* ---- codec ------------------------------------------------------------ */

static void encode_matches_hand_built_packet(void **state)
{
    tase_klv_t k = hand_values();
    uint8_t out[100];
    (void)state;
    memset(out, 0xEE, sizeof(out));
    assert_int_equal(tase_klv_encode(&k, out, sizeof(out)), 87);
    assert_memory_equal(out, hand_packet, 87);
    assert_int_equal(out[87], 0xEE); /* nothing written past the packet */
}

static void decode_of_hand_built_packet_gives_hand_values(void **state)
{
    tase_klv_t want = hand_values(), got;
    (void)state;
    memset(&got, 0, sizeof(got));
    assert_int_equal(tase_klv_decode(hand_packet, sizeof(hand_packet), &got), 87);
    assert_klv_equal(&got, &want);
}

static void round_trip_keeps_random_and_extreme_values(void **state)
{
    uint8_t buf[87];
    tase_klv_t k, got;
    int i;
    (void)state;
    for (i = 0; i < 2000; i++) {
        if (i == 0) {
            memset(&k, 0, sizeof(k));
        } else if (i == 1) {
            memset(&k, 0xFF, sizeof(k)); /* all-ones: -1 and max unsigned */
        } else if (i == 2 || i == 3) {
            uint16_t u = i == 2 ? 0xFFFFu : 0u;
            int16_t s = i == 2 ? INT16_MAX : INT16_MIN;
            k.utc = i == 2 ? UINT64_MAX : 0u;
            k.lat = k.lon = i == 2 ? INT32_MAX : INT32_MIN;
            k.alt = k.pan = k.heading = k.hfov = k.vfov = k.gps_status = u;
            k.tilt = k.pitch = k.roll = k.vnorth = k.veast = s;
        } else {
            k = random_values();
        }
        assert_int_equal(tase_klv_encode(&k, buf, sizeof(buf)), 87);
        assert_int_equal(tase_klv_decode(buf, sizeof(buf), &got), 87);
        assert_klv_equal(&got, &k);
    }
}

static void encode_rejects_null_and_short_buffer_writing_nothing(void **state)
{
    tase_klv_t k = hand_values();
    uint8_t out[87];
    (void)state;
    memset(out, 0xEE, sizeof(out));
    assert_int_equal(tase_klv_encode(NULL, out, sizeof(out)), TASE_EARG);
    assert_int_equal(tase_klv_encode(&k, NULL, 87), TASE_EARG);
    assert_int_equal(tase_klv_encode(&k, out, 86), TASE_ENOSPC);
    assert_int_equal(out[0], 0xEE);
    assert_int_equal(out[85], 0xEE);
}

static void decode_rejects_null_arguments(void **state)
{
    tase_klv_t k;
    (void)state;
    assert_int_equal(tase_klv_decode(NULL, 87, &k), TASE_EARG);
    assert_int_equal(tase_klv_decode(hand_packet, 87, NULL), TASE_EARG);
}

static void declared_lengths_69_and_70_are_both_accepted(void **state)
{
    uint8_t p[87];
    tase_klv_t want = hand_values(), got;
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[16] = 69; /* the spec's value; the checksum does not cover it */
    assert_int_equal(tase_klv_decode(p, sizeof(p), &got), 87);
    assert_klv_equal(&got, &want);
    p[16] = 70;
    assert_int_equal(tase_klv_decode(p, sizeof(p), &got), 87);
}

static void other_declared_lengths_are_rejected(void **state)
{
    static const uint8_t bad[] = {0, 1, 66, 68, 71, 72, 86, 87, 0x7F};
    uint8_t p[87];
    size_t i;
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    for (i = 0; i < sizeof(bad); i++) {
        p[16] = bad[i];
        assert_decode_fails(p, sizeof(p), TASE_ELENGTH);
    }
}

static void long_form_ber_length_is_accepted_and_counted(void **state)
{
    uint8_t p[91];
    tase_klv_t want = hand_values(), got;
    (void)state;
    /* 0x81 0x46: one length octet */
    memcpy(p, hand_packet, 16);
    p[16] = 0x81;
    p[17] = 0x46;
    memcpy(p + 18, hand_packet + 17, 70);
    assert_int_equal(tase_klv_decode(p, 88, &got), 88);
    assert_klv_equal(&got, &want);
    /* 0x84 00 00 00 45: four octets, the spec's 69 */
    p[16] = 0x84;
    p[17] = 0;
    p[18] = 0;
    p[19] = 0;
    p[20] = 0x45;
    memcpy(p + 21, hand_packet + 17, 70);
    assert_int_equal(tase_klv_decode(p, 91, &got), 91);
    assert_decode_fails(p, 90, TASE_ETRUNC);
    p[19] = 1; /* 0x0145 */
    assert_decode_fails(p, 91, TASE_ELENGTH);
}

/* TASE_ETRUNC means exactly "a valid packet may still follow": a long
 * form whose octets already make 256 or more (82 FF: at least 0xFF00) was
 * ETRUNC until its last octet came (a review). */
static void long_form_lengths_of_256_or_more_are_elength_at_once(void **state)
{
    uint8_t p[21];
    (void)state;
    memcpy(p, hand_packet, 16);
    p[16] = 0x82;
    p[17] = 0xFF;
    assert_decode_fails(p, 18, TASE_ELENGTH);
    p[17] = 0x00;
    assert_decode_fails(p, 18, TASE_ETRUNC); /* 0x00xx may be 0x0046 */
    p[16] = 0x84;
    p[17] = 0x01;
    assert_decode_fails(p, 18, TASE_ELENGTH);
    p[17] = 0x00;
    p[18] = 0x00;
    p[19] = 0x00;
    assert_decode_fails(p, 20, TASE_ETRUNC);
    p[19] = 0x01;
    assert_decode_fails(p, 20, TASE_ELENGTH);
    /* the last octet alone decides as before: 84 00 00 00 FF is ELENGTH
     * once that octet is in */
    p[19] = 0x00;
    p[20] = 0xFF;
    assert_decode_fails(p, 21, TASE_ELENGTH);
}

static void indefinite_and_overlong_ber_forms_are_malformed(void **state)
{
    uint8_t p[87];
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[16] = 0x80;
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    p[16] = 0x85;
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    p[16] = 0xFF;
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
}

static void bad_checksum_is_rejected(void **state)
{
    uint8_t p[87];
    size_t i;
    (void)state;
    for (i = 17; i < 87; i++) {
        /* Skip tag and length bytes: those fail as format errors. */
        int is_header = 0;
        size_t pos = 17;
        while (pos < 87) {
            if (i == pos || i == pos + 1u) {
                is_header = 1;
            }
            pos += 2u + hand_packet[pos + 1u];
        }
        if (is_header) {
            continue;
        }
        memcpy(p, hand_packet, sizeof(p));
        p[i] ^= 0x01;
        assert_decode_fails(p, sizeof(p), TASE_ECHECKSUM);
    }
}

static void checksum_covers_exactly_the_items_before_it(void **state)
{
    /* Moving one unit between two value bytes inside the covered range
     * keeps the sum; the decode still succeeds. A change of the length
     * byte (not covered) was shown above. */
    uint8_t p[87];
    tase_klv_t got;
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[19] = 1; /* first UTC byte, +1 */
    p[26] = 4; /* last UTC byte, 5 -> 4 */
    assert_int_equal(tase_klv_decode(p, sizeof(p), &got), 87);
    assert_true(got.utc == 0x0100000102030404ull);
}

static void every_truncation_is_reported_as_truncated(void **state)
{
    uint8_t p[87];
    size_t n;
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    for (n = 0; n < 87; n++) {
        assert_decode_fails(hand_packet, n, TASE_ETRUNC);
    }
    p[16] = 69;
    for (n = 0; n < 87; n++) {
        assert_decode_fails(p, n, TASE_ETRUNC);
    }
}

static void unknown_tags_are_rejected(void **state)
{
    uint8_t p[87];
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[43] = 16; /* pan's tag */
    assert_decode_fails(p, sizeof(p), TASE_EUNKNOWN);
    p[43] = 0;
    assert_decode_fails(p, sizeof(p), TASE_EUNKNOWN);
    p[43] = 0xFF;
    assert_decode_fails(p, sizeof(p), TASE_EUNKNOWN);
    memcpy(p, hand_packet, sizeof(p));
    p[17] = 0x30; /* first tag */
    assert_decode_fails(p, sizeof(p), TASE_EUNKNOWN);
}

static void repeated_missing_and_out_of_order_tags_are_malformed(void **state)
{
    uint8_t p[87];
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[47] = 5; /* tilt's tag repeats pan's */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    p[47] = 7; /* tilt missing: heading comes first */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    memcpy(p, hand_packet, sizeof(p));
    p[83] = 14; /* checksum item tagged as GPS status again */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
}

static void wrong_item_lengths_are_malformed(void **state)
{
    uint8_t p[87];
    (void)state;
    memcpy(p, hand_packet, sizeof(p));
    p[18] = 4; /* UTC must be 8 */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    memcpy(p, hand_packet, sizeof(p));
    p[60] = 1; /* roll must be 2 */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
    memcpy(p, hand_packet, sizeof(p));
    p[84] = 0x82; /* checksum length as a BER long form */
    assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
}

static void bad_key_is_malformed_even_when_truncated(void **state)
{
    uint8_t p[87];
    size_t i;
    (void)state;
    for (i = 0; i < 16; i++) {
        memcpy(p, hand_packet, sizeof(p));
        p[i] ^= 0x40;
        assert_decode_fails(p, sizeof(p), TASE_EFORMAT);
        assert_decode_fails(p, i + 1u, TASE_EFORMAT);
    }
}

static void trailing_bytes_after_a_packet_are_not_consumed(void **state)
{
    uint8_t p[100];
    tase_klv_t got;
    (void)state;
    memcpy(p, hand_packet, 87);
    memset(p + 87, 0x06, 13);
    assert_int_equal(tase_klv_decode(p, sizeof(p), &got), 87);
}

/* ---- stream scanner --------------------------------------------------- */

#define MAX_SEEN 64

typedef struct {
    size_t n, nerr;
    uint32_t offset[MAX_SEEN];
    tase_klv_t klv[MAX_SEEN];
    uint32_t err_offset[MAX_SEEN];
    int err[MAX_SEEN];
} seen_t;

static void on_packet(void *user, uint32_t offset, const tase_klv_t *klv)
{
    seen_t *s = user;
    assert_true(s->n < MAX_SEEN);
    s->offset[s->n] = offset;
    s->klv[s->n] = *klv;
    s->n++;
}

static void on_error(void *user, uint32_t offset, int err)
{
    seen_t *s = user;
    assert_true(s->nerr < MAX_SEEN);
    s->err_offset[s->nerr] = offset;
    s->err[s->nerr] = err;
    s->nerr++;
}

typedef struct {
    uint8_t bytes[4096];
    size_t len;
    size_t n;                  /* clean packets */
    uint32_t offset[MAX_SEEN]; /* where each clean packet starts */
    tase_klv_t klv[MAX_SEEN];
} stream_t;

static void put(stream_t *s, const uint8_t *p, size_t n)
{
    assert_true(s->len + n <= sizeof(s->bytes));
    memcpy(s->bytes + s->len, p, n);
    s->len += n;
}

static void put_clean(stream_t *s, int declare_69)
{
    uint8_t p[87];
    tase_klv_t k = random_values();
    assert_int_equal(tase_klv_encode(&k, p, sizeof(p)), 87);
    if (declare_69) {
        p[16] = 69;
    }
    assert_true(s->n < MAX_SEEN);
    s->offset[s->n] = (uint32_t)s->len;
    s->klv[s->n] = k;
    s->n++;
    put(s, p, sizeof(p));
}

/* Noise laced with key fragments and lone 0x06 bytes. */
static void put_noise(stream_t *s, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++) {
        uint8_t b = (uint8_t)rnd();
        switch (rnd() % 8u) {
        case 0: b = 0x06; break;
        case 1: put(s, hand_packet, 1u + rnd() % 16u); break;
        default: break;
        }
        put(s, &b, 1);
    }
}

/* Feed the stream in chunks of 1..maxchunk bytes (0: all at once). */
static void scan(const stream_t *s, size_t maxchunk, seen_t *seen, tase_klv_rx_t *rx)
{
    size_t pos = 0;
    int total = 0, r;
    memset(seen, 0, sizeof(*seen));
    assert_int_equal(tase_klv_rx_init(rx), TASE_OK);
    while (pos < s->len) {
        size_t n = maxchunk == 0u ? s->len : 1u + rnd() % maxchunk;
        if (n > s->len - pos) {
            n = s->len - pos;
        }
        r = tase_klv_rx_feed(rx, s->bytes + pos, n, on_packet, on_error, seen);
        assert_true(r >= 0);
        total += r;
        pos += n;
    }
    r = tase_klv_rx_flush(rx, on_packet, on_error, seen);
    assert_true(r >= 0);
    total += r;
    assert_int_equal(total, (int)seen->n);
}

static void assert_all_clean_packets_once_in_order(const stream_t *s, const seen_t *seen)
{
    size_t i;
    assert_int_equal(seen->n, s->n);
    for (i = 0; i < s->n; i++) {
        assert_int_equal(seen->offset[i], s->offset[i]);
        assert_klv_equal(&seen->klv[i], &s->klv[i]);
    }
}

static void noisy_stream_yields_every_clean_packet_once_with_its_offset(void **state)
{
    static stream_t s;
    static seen_t seen;
    tase_klv_rx_t rx;
    uint8_t bad[87];
    size_t chunks[] = {0, 1, 2, 7, 64, 200};
    size_t c;
    (void)state;
    memset(&s, 0, sizeof(s));
    put_noise(&s, 30);
    put_clean(&s, 0);
    put_clean(&s, 1); /* back to back, declared 69 */
    put_noise(&s, 50);
    /* a corrupted packet (bad checksum) in the middle */
    memcpy(bad, hand_packet, sizeof(bad));
    bad[30] ^= 0x10;
    put(&s, bad, sizeof(bad));
    put_clean(&s, 0);
    put_noise(&s, 5);
    /* a packet cut short, then a clean one right behind it */
    put(&s, hand_packet, 50);
    put_clean(&s, 0);
    put_noise(&s, 40);
    put_clean(&s, 1);
    put(&s, hand_packet, 20); /* incomplete at end of input */

    for (c = 0; c < sizeof(chunks) / sizeof(chunks[0]); c++) {
        scan(&s, chunks[c], &seen, &rx);
        assert_all_clean_packets_once_in_order(&s, &seen);
        assert_int_equal(rx.stats.bytes_in, s.len);
        assert_int_equal(rx.stats.packets_ok, s.n);
        assert_int_equal(rx.stats.bytes_discarded, s.len - 87u * s.n);
        assert_int_equal(rx.stats.checksum_errors, 1);
        assert_int_equal(rx.stats.truncated, 1); /* the tail, at flush */
        assert_int_equal(rx.len, 0);
    }
}

static void packet_behind_a_cut_packet_is_found_for_every_cut(void **state)
{
    static stream_t s;
    static seen_t seen;
    tase_klv_rx_t rx;
    size_t cut;
    (void)state;
    for (cut = 1; cut < 87; cut++) {
        memset(&s, 0, sizeof(s));
        put(&s, hand_packet, cut);
        put_clean(&s, (int)(cut & 1u));
        put(&s, hand_packet, cut);
        put_clean(&s, 0);
        scan(&s, cut % 3u == 0u ? 0u : 5u, &seen, &rx);
        assert_all_clean_packets_once_in_order(&s, &seen);
    }
}

static void errors_are_reported_with_offset_and_code(void **state)
{
    static stream_t s;
    static seen_t seen;
    tase_klv_rx_t rx;
    static const uint8_t noise[] = {0x55, 0x06, 0xAA};
    uint8_t p[87];
    (void)state;
    memset(&s, 0, sizeof(s));
    put(&s, noise, sizeof(noise));
    memcpy(p, hand_packet, sizeof(p));
    p[86] ^= 1; /* checksum */
    put(&s, p, sizeof(p));
    memcpy(p, hand_packet, sizeof(p));
    p[16] = 71;
    put(&s, p, sizeof(p));
    memcpy(p, hand_packet, sizeof(p));
    p[17] = 99;
    put(&s, p, sizeof(p));
    memcpy(p, hand_packet, sizeof(p));
    p[18] = 3;
    put(&s, p, sizeof(p));
    scan(&s, 0, &seen, &rx);
    assert_int_equal(seen.n, 0);
    assert_int_equal(seen.nerr, 4);
    assert_int_equal(seen.err[0], TASE_ECHECKSUM);
    assert_int_equal(seen.err[1], TASE_ELENGTH);
    assert_int_equal(seen.err[2], TASE_EUNKNOWN);
    assert_int_equal(seen.err[3], TASE_EFORMAT);
    assert_int_equal(seen.err_offset[1] - seen.err_offset[0], 87);
    assert_int_equal(seen.err_offset[3], s.len - 87u);
    assert_int_equal(rx.stats.checksum_errors, 1);
    assert_int_equal(rx.stats.length_errors, 1);
    assert_int_equal(rx.stats.unknown_tags, 1);
    assert_int_equal(rx.stats.format_errors, 1);
    assert_int_equal(rx.stats.bytes_discarded, s.len);
}

static void flush_reports_only_candidates_with_a_whole_key(void **state)
{
    tase_klv_rx_t rx;
    seen_t seen;
    (void)state;
    memset(&seen, 0, sizeof(seen));
    assert_int_equal(tase_klv_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 10, on_packet, on_error, &seen), 0);
    assert_int_equal(rx.len, 10); /* held: it may still become a packet */
    assert_int_equal(tase_klv_rx_flush(&rx, on_packet, on_error, &seen), 0);
    assert_int_equal(seen.nerr, 0);
    assert_int_equal(rx.stats.truncated, 0);
    assert_int_equal(rx.stats.bytes_discarded, 10);
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 86, on_packet, on_error, &seen), 0);
    assert_int_equal(tase_klv_rx_flush(&rx, on_packet, on_error, &seen), 0);
    assert_int_equal(seen.nerr, 1);
    assert_int_equal(seen.err[0], TASE_ETRUNC);
    assert_int_equal(seen.err_offset[0], 10);
    assert_int_equal(rx.stats.truncated, 1);
    /* The receiver is reusable: offsets continue. */
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 87, on_packet, on_error, &seen), 1);
    assert_int_equal(seen.offset[0], 96);
}

static void packet_is_delivered_by_the_call_that_feeds_its_last_byte(void **state)
{
    tase_klv_rx_t rx;
    seen_t seen;
    size_t i;
    (void)state;
    memset(&seen, 0, sizeof(seen));
    assert_int_equal(tase_klv_rx_init(&rx), TASE_OK);
    for (i = 0; i < 86; i++) {
        assert_int_equal(tase_klv_rx_feed(&rx, hand_packet + i, 1, on_packet, NULL, &seen), 0);
    }
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet + 86, 1, on_packet, NULL, &seen), 1);
    assert_int_equal(seen.n, 1);
}

static void packet_behind_a_cut_packet_comes_out_with_its_last_byte(void **state)
{
    tase_klv_rx_t rx;
    seen_t seen;
    size_t cut, i;
    (void)state;
    for (cut = 1; cut < 87; cut++) {
        memset(&seen, 0, sizeof(seen));
        assert_int_equal(tase_klv_rx_init(&rx), TASE_OK);
        assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, cut, on_packet, NULL, &seen), 0);
        for (i = 0; i < 86; i++) {
            assert_int_equal(tase_klv_rx_feed(&rx, hand_packet + i, 1, on_packet, NULL, &seen), 0);
        }
        assert_int_equal(tase_klv_rx_feed(&rx, hand_packet + 86, 1, on_packet, NULL, &seen), 1);
        assert_int_equal(seen.offset[0], cut);
    }
}

static void scanner_rejects_bad_arguments_and_resets_counters(void **state)
{
    tase_klv_rx_t rx;
    (void)state;
    assert_true(sizeof(tase_klv_rx_t) <= TASE_KLV_RX_SIZE_BUDGET);
    assert_int_equal(tase_klv_rx_init(NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_klv_rx_feed(NULL, hand_packet, 1, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_feed(&rx, NULL, 1, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_feed(&rx, NULL, 0, NULL, NULL, NULL), 0);
    assert_int_equal(tase_klv_rx_flush(NULL, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_stats_reset(NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 87, NULL, NULL, NULL), 1);
    assert_int_equal(rx.stats.packets_ok, 1);
    assert_int_equal(tase_klv_rx_stats_reset(&rx), TASE_OK);
    assert_int_equal(rx.stats.packets_ok, 0);
    assert_int_equal(rx.stats.bytes_in, 0);
    /* a never initialised (here all 0xFF) scanner is TASE_EARG: it was
     * TASE_EBUSY, which has a caller retry for ever (a review) */
    memset(&rx, 0xFF, sizeof rx);
    assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 87, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_flush(&rx, NULL, NULL, NULL), TASE_EARG);
}

/* ---- scanner re-entrancy (issue 12) ----------------------------------- */

enum { KRE_NONE, KRE_FEED, KRE_FLUSH, KRE_RESET, KRE_INIT };

typedef struct {
    tase_klv_rx_t *rx;
    int action;
    bool init_from_error; /* KRE_INIT: in the first error handler call, not the first call */
    bool inited;
    size_t calls;   /* handler calls so far */
    size_t refused; /* nested feed/flush refused with TASE_EBUSY, rx unchanged */
} klv_reenter_t;

static void klv_reenter_packet(void *user, uint32_t offset, const tase_klv_t *klv);
static void klv_reenter_error(void *user, uint32_t offset, int err);

static void klv_reenter_act(klv_reenter_t *e, bool from_error)
{
    tase_klv_rx_t before;
    int r = TASE_OK;
    memcpy(&before, e->rx, sizeof(before));
    e->calls++;
    switch (e->action) {
    case KRE_FEED:
        r = tase_klv_rx_feed(e->rx, hand_packet, sizeof(hand_packet), klv_reenter_packet,
                             klv_reenter_error, e);
        break;
    case KRE_FLUSH: r = tase_klv_rx_flush(e->rx, klv_reenter_packet, klv_reenter_error, e); break;
    case KRE_RESET: r = tase_klv_rx_stats_reset(e->rx); break;
    case KRE_INIT:
        if (!e->inited && from_error == e->init_from_error) {
            e->inited = true;
            r = tase_klv_rx_init(e->rx);
        }
        break;
    default: break;
    }
    if (e->action == KRE_FEED || e->action == KRE_FLUSH) {
        assert_int_equal(r, TASE_EBUSY);
        assert_memory_equal(&before, e->rx, sizeof(before));
        e->refused++;
    } else {
        assert_int_equal(r, TASE_OK);
    }
}

static void klv_reenter_packet(void *user, uint32_t offset, const tase_klv_t *klv)
{
    (void)offset;
    (void)klv;
    klv_reenter_act(user, false);
}

static void klv_reenter_error(void *user, uint32_t offset, int err)
{
    (void)offset;
    (void)err;
    klv_reenter_act(user, true);
}

/* Feed s[0..n) (in one call or byte by byte) and flush; rets[] gets each
 * call's result. Stops after the call whose handler re-initialised rx. */
static size_t klv_reenter_run(klv_reenter_t *e, const uint8_t *s, size_t n, bool bytewise,
                              int *rets)
{
    size_t pos = 0, calls = 0;
    assert_int_equal(tase_klv_rx_init(e->rx), TASE_OK);
    while (pos < n) {
        size_t k = bytewise ? 1u : n;
        rets[calls] = tase_klv_rx_feed(e->rx, s + pos, k, klv_reenter_packet, klv_reenter_error, e);
        assert_true(rets[calls] >= 0);
        pos += k;
        calls++;
        if (e->inited) {
            return calls;
        }
    }
    rets[calls] = tase_klv_rx_flush(e->rx, klv_reenter_packet, klv_reenter_error, e);
    assert_true(rets[calls] >= 0);
    return calls + 1u;
}

/* Every scanner call from inside both handlers: feed/flush refused with
 * TASE_EBUSY, nothing changed; stats_reset and init allowed, and a call
 * whose handler re-initialised the scanner returns at once with the
 * packets it delivered (before issue 12, init from a handler made the next
 * drop a negative-size memmove). */
static void scanner_calls_from_inside_a_handler_are_refused_or_safe(void **state)
{
    static uint8_t s[4 * 87];
    static int rets[4 * 87 + 1], plain_rets[4 * 87 + 1];
    tase_klv_rx_t rx, fresh;
    tase_klv_rx_stats_t plain_stats;
    klv_reenter_t e;
    size_t calls, plain_calls, k, n = 0;
    int action, bytewise;
    (void)state;
    /* packet, key-matched packet with a wrong checksum, packet, cut packet */
    memcpy(s + n, hand_packet, 87);
    n += 87;
    memcpy(s + n, hand_packet, 87);
    s[n + 86] ^= 1u;
    n += 87;
    memcpy(s + n, hand_packet, 87);
    n += 87;
    memcpy(s + n, hand_packet, 40);
    n += 40;
    assert_int_equal(tase_klv_rx_init(&fresh), TASE_OK);
    for (bytewise = 0; bytewise <= 1; bytewise++) {
        memset(&e, 0, sizeof(e));
        e.rx = &rx;
        plain_calls = klv_reenter_run(&e, s, n, bytewise != 0, plain_rets);
        assert_int_equal(e.calls, 4); /* 2 packets, a checksum error, a cut */
        plain_stats = rx.stats;
        for (action = KRE_FEED; action <= KRE_INIT + 1; action++) {
            memset(&e, 0, sizeof(e));
            e.rx = &rx;
            e.action = action > KRE_INIT ? KRE_INIT : action;
            e.init_from_error = action > KRE_INIT;
            calls = klv_reenter_run(&e, s, n, bytewise != 0, rets);
            if (e.action == KRE_INIT) {
                /* from the packet handler (the first packet) or the error
                 * handler (after the first packet): the call returns the
                 * packets it delivered, the first one unless the stream
                 * comes byte by byte and the error came in a later call */
                assert_true(e.inited);
                assert_int_equal(rets[calls - 1u], (bytewise && e.init_from_error) ? 0 : 1);
                assert_memory_equal(&rx, &fresh, sizeof(rx));
                e.action = KRE_NONE;
                assert_int_equal(tase_klv_rx_feed(&rx, hand_packet, 87, klv_reenter_packet,
                                                  klv_reenter_error, &e),
                                 1);
                assert_int_equal(rx.stats.bytes_in, 87);
                continue;
            }
            assert_int_equal(calls, plain_calls);
            for (k = 0; k < calls; k++) {
                assert_int_equal(rets[k], plain_rets[k]);
            }
            if (action == KRE_RESET) {
                assert_int_equal(rx.stats.packets_ok, 0);
                assert_int_equal(rx.stats.truncated, 0); /* reset by that very handler */
            } else {
                assert_int_equal(e.refused, 4);
                assert_memory_equal(&rx.stats, &plain_stats, sizeof(plain_stats));
            }
        }
    }
}

/* ---- units ------------------------------------------------------------ */

#define EPS 1e-9

static void raw_to_units_match_hand_computed_values(void **state)
{
    (void)state;
    assert_float_equal(tase_klv_lat_deg(0x40000000), 45.0, EPS); /* 2^30*180/2^32 */
    assert_float_equal(tase_klv_lat_deg(INT32_MIN), -90.0, EPS);
    assert_float_equal(tase_klv_lon_deg(0x40000000), 90.0, EPS);
    assert_float_equal(tase_klv_lon_deg(-0x20000000), -45.0, EPS);
    assert_float_equal(tase_klv_alt_m(0), -900.0, EPS);
    assert_float_equal(tase_klv_alt_m(32768), 4550.0, EPS); /* 10900/2 - 900 */
    assert_float_equal(tase_klv_angle_deg(16384), 90.0, EPS);
    assert_float_equal(tase_klv_angle_deg(49152), 270.0, EPS);
    assert_float_equal(tase_klv_tilt_deg(-16384), -90.0, EPS);
    assert_float_equal(tase_klv_pitch_deg(16384), 10.0, EPS);
    assert_float_equal(tase_klv_pitch_deg(INT16_MIN), -20.0, EPS);
    assert_float_equal(tase_klv_roll_deg(16384), 25.0, EPS);
    assert_float_equal(tase_klv_roll_deg(INT16_MIN), -50.0, EPS);
    assert_float_equal(tase_klv_speed_mps(16384), 127.5, EPS);
    assert_float_equal(tase_klv_speed_mps(-256), -1.9921875, EPS); /* -510/256 */
    assert_float_equal(tase_klv_fov_deg(32768), 90.0, EPS);
    assert_float_equal(tase_klv_fov_deg(16384), 45.0, EPS);
    assert_float_equal(tase_klv_utc_s(1500000u), 1.5, EPS);
}

static void units_to_raw_round_to_nearest(void **state)
{
    const double lat_lsb = 180.0 / 4294967296.0;
    (void)state;
    assert_int_equal(tase_klv_lat_raw(45.0), 0x40000000);
    assert_int_equal(tase_klv_lat_raw(1.4 * lat_lsb), 1);
    assert_int_equal(tase_klv_lat_raw(1.6 * lat_lsb), 2);
    assert_int_equal(tase_klv_lat_raw(-1.6 * lat_lsb), -2);
    assert_int_equal(tase_klv_lon_raw(90.0), 0x40000000);
    assert_int_equal(tase_klv_alt_raw(-900.0), 0);
    assert_int_equal(tase_klv_alt_raw(4550.0), 32768);
    /* 900 * 65536 / 10900 = 5411.23 */
    assert_int_equal(tase_klv_alt_raw(0.0), 5411);
    assert_int_equal(tase_klv_angle_raw(90.0), 16384);
    assert_int_equal(tase_klv_angle_raw(359.99), 65534); /* 65534.18 */
    assert_int_equal(tase_klv_pitch_raw(10.0), 16384);
    assert_int_equal(tase_klv_roll_raw(25.0), 16384);
    assert_int_equal(tase_klv_speed_raw(127.5), 16384);
    assert_int_equal(tase_klv_speed_raw(-1.9921875), -256);
    assert_int_equal(tase_klv_fov_raw(90.0), 32768);
    /* a review: the value just below a half (0.5 - 2^-54 LSB) went to 1
     * ((int64_t)(x + 0.5) rounds the sum up); checked with exact fractions */
    assert_int_equal(tase_klv_lat_raw(2.0954757928848263e-08), 0);
    assert_int_equal(tase_klv_lat_raw(-2.0954757928848263e-08), 0);
}

static void units_to_raw_saturate_where_the_range_ends(void **state)
{
    (void)state;
    assert_int_equal(tase_klv_lat_raw(90.0), INT32_MAX);
    assert_int_equal(tase_klv_lat_raw(-90.0), INT32_MIN);
    assert_int_equal(tase_klv_lat_raw(-1000.0), INT32_MIN);
    assert_int_equal(tase_klv_alt_raw(20000.0), 65535);
    assert_int_equal(tase_klv_alt_raw(-5000.0), 0);
    assert_int_equal(tase_klv_pitch_raw(20.0), INT16_MAX);
    assert_int_equal(tase_klv_pitch_raw(-25.0), INT16_MIN);
    assert_int_equal(tase_klv_roll_raw(-50.0), INT16_MIN);
    assert_int_equal(tase_klv_roll_raw(1e30), INT16_MAX);
    assert_int_equal(tase_klv_speed_raw(-300.0), INT16_MIN);
    assert_int_equal(tase_klv_fov_raw(-1.0), 0);
    assert_int_equal(tase_klv_fov_raw(200.0), 65535);
    assert_int_equal(tase_klv_lat_raw(NAN), 0);
    assert_int_equal(tase_klv_fov_raw(NAN), 0);
}

static void circular_units_to_raw_wrap(void **state)
{
    (void)state;
    assert_int_equal(tase_klv_lon_raw(180.0), INT32_MIN);
    assert_int_equal(tase_klv_lon_raw(-180.0), INT32_MIN);
    assert_int_equal(tase_klv_lon_raw(270.0), -0x40000000);
    assert_int_equal(tase_klv_lon_raw(765.0), 0x20000000); /* 720 + 45 */
    assert_int_equal(tase_klv_angle_raw(-90.0), 49152);
    assert_int_equal(tase_klv_angle_raw(360.0), 0);
    assert_int_equal(tase_klv_angle_raw(359.999), 0); /* 65535.82 -> 65536 */
    assert_int_equal(tase_klv_tilt_raw(180.0), INT16_MIN);
    assert_int_equal(tase_klv_tilt_raw(270.0), -16384);
    assert_int_equal(tase_klv_tilt_raw(-90.0), -16384);
    assert_int_equal(tase_klv_angle_raw(INFINITY), 0);
    assert_int_equal(tase_klv_lon_raw(NAN), 0);
    assert_int_equal(tase_klv_tilt_raw(-1e12), 0);
    /* a review: far from 0 the inexact 2^32/360 factor was 1..2 LSB off
     * (exact nearest by fractions: 400,000,000 deg is 477,218,588 raw) */
    assert_int_equal(tase_klv_lon_raw(400000000.0), 477218588);
    assert_int_equal(tase_klv_lon_raw(-481056.2479878449), -1148283222);
}

static void every_16_bit_raw_value_survives_units_and_back(void **state)
{
    uint32_t u;
    (void)state;
    for (u = 0; u <= 0xFFFFu; u++) {
        uint16_t w = (uint16_t)u;
        int16_t s = (int16_t)(u < 0x8000u ? (int32_t)u : (int32_t)u - 65536);
        assert_int_equal(tase_klv_alt_raw(tase_klv_alt_m(w)), w);
        assert_int_equal(tase_klv_angle_raw(tase_klv_angle_deg(w)), w);
        assert_int_equal(tase_klv_fov_raw(tase_klv_fov_deg(w)), w);
        assert_int_equal(tase_klv_tilt_raw(tase_klv_tilt_deg(s)), s);
        assert_int_equal(tase_klv_pitch_raw(tase_klv_pitch_deg(s)), s);
        assert_int_equal(tase_klv_roll_raw(tase_klv_roll_deg(s)), s);
        assert_int_equal(tase_klv_speed_raw(tase_klv_speed_mps(s)), s);
    }
    for (u = 0; u < 100000u; u++) {
        int32_t v = (int32_t)rnd();
        assert_int_equal(tase_klv_lat_raw(tase_klv_lat_deg(v)), v);
        assert_int_equal(tase_klv_lon_raw(tase_klv_lon_deg(v)), v);
    }
}

static void gps_status_uses_msb_first_bit_numbers(void **state)
{
    (void)state;
    assert_int_equal(TASE_KLV_GPS_BIT(0), 0x8000);
    assert_int_equal(TASE_KLV_GPS_BIT(15), 0x0001);
    assert_int_equal(TASE_KLV_GPS_BIT(3), TASE_KLV_GPS_DEAD_RECKONED);
    assert_int_equal(TASE_KLV_GPS_BIT(12), TASE_KLV_GPS_FEW_SATS);
    /* bits 0-2 = 111: 3D fix; 110: 2D; 011: acquiring */
    assert_int_equal(tase_klv_gps_fix(0xE000), TASE_KLV_GPS_FIX_3D);
    assert_int_equal(tase_klv_gps_fix(0xC000), TASE_KLV_GPS_FIX_2D);
    assert_int_equal(tase_klv_gps_fix(0x7FFF), TASE_KLV_GPS_FIX_ACQUIRING);
    /* bits 13-14: 0x0004 is bit 13 ("10": undercurrent) */
    assert_int_equal(tase_klv_gps_antenna(0x0004), TASE_KLV_GPS_ANTENNA_UNDERCURRENT);
    assert_int_equal(tase_klv_gps_antenna(0x0002), TASE_KLV_GPS_ANTENNA_OVERCURRENT);
    assert_int_equal(tase_klv_gps_antenna(0xFFF9), TASE_KLV_GPS_ANTENNA_OK);
    assert_int_equal(tase_klv_gps_status(7, 0, TASE_KLV_GPS_DEAD_RECKONED), 0xF000);
    assert_int_equal(tase_klv_gps_status(2, 3, 0), 0x4006);
    /* reserved bits 5 and 15 and the fix/antenna fields are not flags:
     * 0x1000+0x0800+0x0200+0x0100+0x0080+0x0040+0x0020+0x0010+0x0008 */
    assert_int_equal(tase_klv_gps_status(0, 0, 0xFFFF), 0x1BF8);
    assert_int_equal(tase_klv_gps_status(15, 7, 0), 0xE006);
}

/* Bad arguments of klv.h give their documented codes and change nothing;
 * a scanner whose held length exceeds its window is refused; the units
 * helpers are total (NaN, infinities, huge values give defined results). */
static void klv_api_rejects_bad_arguments(void **state)
{
    tase_klv_t k;
    tase_klv_t kcopy;
    uint8_t out[TASE_KLV_PACKET_LEN];
    uint8_t before[sizeof out];
    tase_klv_rx_t rx;
    tase_klv_rx_t copy;
    uint16_t st;
    (void)state;

    memset(&k, 0x3C, sizeof k);
    memcpy(&kcopy, &k, sizeof k);
    memset(out, 0xA5, sizeof out);
    memcpy(before, out, sizeof out);
    assert_int_equal(tase_klv_encode(NULL, out, sizeof out), TASE_EARG);
    assert_int_equal(tase_klv_encode(&k, NULL, sizeof out), TASE_EARG);
    assert_int_equal(tase_klv_encode(&k, out, 0), TASE_ENOSPC);
    assert_int_equal(tase_klv_encode(&k, out, TASE_KLV_PACKET_LEN - 1u), TASE_ENOSPC);
    assert_memory_equal(out, before, sizeof out);
    assert_int_equal(tase_klv_decode(NULL, SIZE_MAX, &k), TASE_EARG);
    assert_int_equal(tase_klv_decode(out, sizeof out, NULL), TASE_EARG);
    assert_int_equal(tase_klv_decode(out, 0, &k), TASE_ETRUNC);
    assert_memory_equal(&k, &kcopy, sizeof k);

    assert_int_equal(tase_klv_rx_init(NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_feed(NULL, out, 1, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_flush(NULL, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_stats_reset(NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_klv_rx_feed(&rx, out, 5, NULL, NULL, NULL), 0);
    memcpy(&copy, &rx, sizeof rx);
    assert_int_equal(tase_klv_rx_feed(&rx, NULL, SIZE_MAX, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_feed(&rx, NULL, 0, NULL, NULL, NULL), 0);
    assert_memory_equal(&rx, &copy, sizeof rx);
    rx.len = (uint8_t)(TASE_KLV_PACKET_MAX + 1u);
    memcpy(&copy, &rx, sizeof rx);
    assert_int_equal(tase_klv_rx_feed(&rx, out, sizeof out, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_flush(&rx, NULL, NULL, NULL), TASE_EARG);
    assert_memory_equal(&rx, &copy, sizeof rx);
    /* a busy byte other than 0 and 1 is no call in progress but a
     * corrupted scanner: TASE_EARG (TASE_EBUSY is retried for ever) */
    rx.len = 5u;
    rx.busy = 2u;
    memcpy(&copy, &rx, sizeof rx);
    assert_int_equal(tase_klv_rx_feed(&rx, out, sizeof out, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_klv_rx_flush(&rx, NULL, NULL, NULL), TASE_EARG);
    assert_memory_equal(&rx, &copy, sizeof rx);

    assert_int_equal(tase_klv_lat_raw(NAN), 0);
    assert_int_equal(tase_klv_lon_raw(INFINITY), 0);
    assert_int_equal(tase_klv_angle_raw(-INFINITY), 0);
    assert_int_equal(tase_klv_pitch_raw(1e300), INT16_MAX);
    assert_int_equal(tase_klv_roll_raw(-1e300), INT16_MIN);
    assert_int_equal(tase_klv_fov_raw(-1e300), 0);
    assert_int_equal(tase_klv_alt_raw(1e300), UINT16_MAX);
    st = tase_klv_gps_status(UINT32_MAX, UINT32_MAX, 0xFFFFu);
    assert_int_equal(tase_klv_gps_fix(st), 7);
    assert_int_equal(tase_klv_gps_antenna(st), 3);
    assert_int_equal(st & 0x0401u, 0); /* reserved bits 5 and 15 stay clear */
}

/* Rounding is half away from zero, exactly at a half too (a raw value
 * and a half is exact in double arithmetic); a longitude within 1e9 deg
 * but past 2^53 raw (7.5e8 deg on) is still the nearest raw value (its
 * whole turns taken off first: scaled in one piece it is a double
 * rounded to 2, one LSB off; expected values by exact fractions); a
 * magnitude of exactly 1e9 deg gives 0, as klv.h says. */
static void units_to_raw_ties_far_longitudes_and_the_limit(void **state)
{
    const double half = 90.0 / 4294967296.0; /* lat_raw: 0.5 raw */
    (void)state;
    assert_int_equal(tase_klv_lat_raw(half), 1);
    assert_int_equal(tase_klv_lat_raw(-half), -1);
    assert_int_equal(tase_klv_lat_raw(5.0 * half), 3);
    assert_int_equal(tase_klv_lon_raw(943305908.5543873), 817885699);
    assert_int_equal(tase_klv_lon_raw(-943305908.5543873), -817885699);
    assert_int_equal(tase_klv_lon_raw(821216566.1774611), 550918571);
    assert_int_equal(tase_klv_lon_raw(-821216566.1774611), -550918571);
    assert_int_equal(tase_klv_lon_raw(1e9), 0);
    assert_int_equal(tase_klv_lon_raw(-1e9), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(klv_api_rejects_bad_arguments),
        cmocka_unit_test(encode_matches_hand_built_packet),
        cmocka_unit_test(decode_of_hand_built_packet_gives_hand_values),
        cmocka_unit_test(round_trip_keeps_random_and_extreme_values),
        cmocka_unit_test(encode_rejects_null_and_short_buffer_writing_nothing),
        cmocka_unit_test(decode_rejects_null_arguments),
        cmocka_unit_test(declared_lengths_69_and_70_are_both_accepted),
        cmocka_unit_test(other_declared_lengths_are_rejected),
        cmocka_unit_test(long_form_ber_length_is_accepted_and_counted),
        cmocka_unit_test(long_form_lengths_of_256_or_more_are_elength_at_once),
        cmocka_unit_test(indefinite_and_overlong_ber_forms_are_malformed),
        cmocka_unit_test(bad_checksum_is_rejected),
        cmocka_unit_test(checksum_covers_exactly_the_items_before_it),
        cmocka_unit_test(every_truncation_is_reported_as_truncated),
        cmocka_unit_test(unknown_tags_are_rejected),
        cmocka_unit_test(repeated_missing_and_out_of_order_tags_are_malformed),
        cmocka_unit_test(wrong_item_lengths_are_malformed),
        cmocka_unit_test(bad_key_is_malformed_even_when_truncated),
        cmocka_unit_test(trailing_bytes_after_a_packet_are_not_consumed),
        cmocka_unit_test(noisy_stream_yields_every_clean_packet_once_with_its_offset),
        cmocka_unit_test(packet_behind_a_cut_packet_is_found_for_every_cut),
        cmocka_unit_test(errors_are_reported_with_offset_and_code),
        cmocka_unit_test(flush_reports_only_candidates_with_a_whole_key),
        cmocka_unit_test(packet_is_delivered_by_the_call_that_feeds_its_last_byte),
        cmocka_unit_test(packet_behind_a_cut_packet_comes_out_with_its_last_byte),
        cmocka_unit_test(scanner_rejects_bad_arguments_and_resets_counters),
        cmocka_unit_test(scanner_calls_from_inside_a_handler_are_refused_or_safe),
        cmocka_unit_test(raw_to_units_match_hand_computed_values),
        cmocka_unit_test(units_to_raw_round_to_nearest),
        cmocka_unit_test(units_to_raw_saturate_where_the_range_ends),
        cmocka_unit_test(circular_units_to_raw_wrap),
        cmocka_unit_test(units_to_raw_ties_far_longitudes_and_the_limit),
        cmocka_unit_test(every_16_bit_raw_value_survives_units_and_back),
        cmocka_unit_test(gps_status_uses_msb_first_bit_numbers),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
