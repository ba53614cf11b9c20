/* Tests of the can-utils log format reader and writer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "tase/candump.h"

static int parse(const char *line, tase_candump_rec_t *r)
{
    return tase_candump_parse(line, strlen(line), r);
}

static void extended_line_parses_into_fields(void **state)
{
    tase_candump_rec_t r;
    static const uint8_t want[8] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x03, 0xE8};
    (void)state;
    assert_int_equal(parse("(1700000000.123456) vcan0 11000000#00FF5A08081003E8\n", &r), TASE_OK);
    assert_true(r.sec == 1700000000u);
    assert_int_equal(r.usec, 123456);
    assert_string_equal(r.ifname, "vcan0");
    assert_true(r.frame.extended);
    assert_int_equal(r.frame.id, 0x11000000u);
    assert_int_equal(r.frame.dlc, 8);
    assert_memory_equal(r.frame.data, want, 8);
}

static void standard_and_empty_frames_parse(void **state)
{
    tase_candump_rec_t r;
    (void)state;
    assert_int_equal(parse("(0000000001.000001) can1 7ff#", &r), TASE_OK);
    assert_false(r.frame.extended);
    assert_int_equal(r.frame.id, 0x7FF);
    assert_int_equal(r.frame.dlc, 0);
    assert_int_equal(r.usec, 1);
    assert_int_equal(parse("(1.000000) can1 123#de.ad.BE.ef\r\n", &r), TASE_OK);
    assert_int_equal(r.frame.dlc, 4);
    assert_int_equal(r.frame.data[2], 0xBE);
    assert_int_equal(parse("(1.000000)  can1\t12020000#80F6 R\n", &r), TASE_OK);
    assert_int_equal(r.frame.id, 0x12020000u);
    /* blanks before the timestamp too (candump.h) */
    assert_int_equal(parse(" \t (2.000003) can1 123#01", &r), TASE_OK);
    assert_int_equal(r.usec, 3);
    assert_int_equal(r.frame.data[0], 1);
}

static void malformed_lines_are_rejected_and_leave_output_alone(void **state)
{
    static const char *bad[] = {
        "",
        "\n",
        "1700000000.123456 vcan0 123#00",                   /* no parentheses */
        "(1700000000.12345) vcan0 123#00",                  /* 5 microsecond digits */
        "(1700000000.1234567) vcan0 123#00",                /* 7 */
        "(1700000000.123456)vcan0 123#00",                  /* no space */
        "(1700000000.123456) vcan0 12#00",                  /* 2-digit id */
        "(1700000000.123456) vcan0 1234#00",                /* 4-digit id */
        "(1700000000.123456) vcan0 800#00",                 /* standard id too big */
        "(1700000000.123456) vcan0 123#0",                  /* odd nibble */
        "(1700000000.123456) vcan0 123#0G",                 /* not hex */
        "(1700000000.123456) vcan0 123#001122334455667788", /* 9 bytes */
        "(1700000000.123456) vcan0 123#00..",               /* two dots */
        "(1700000000.123456) vcan0 123#00 junk",            /* trailing text */
        "(1700000000.123456) vcan0 C0000000#00",            /* flag bits 30/31 */
        "(1700000000.123456) averyveryverylongname 123#00", /* name > 15 */
        "(1700000000.123456) vcan0 123",                    /* no '#' */
        "(99999999999999999999.000000) vcan0 123#00",       /* > 2^64 seconds */
        "(-1.000000) vcan0 123#00",
    };
    tase_candump_rec_t r;
    size_t i;
    (void)state;
    for (i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        memset(&r, 0x77, sizeof(r));
        assert_int_equal(parse(bad[i], &r), TASE_EFORMAT);
        assert_int_equal(r.usec, 0x77777777u);
    }
    /* An embedded NUL is a bad character, not the end of the line. */
    assert_int_equal(tase_candump_parse("(1.000000) vcan0 123#00\0", 24, &r), TASE_EFORMAT);
    assert_int_equal(tase_candump_parse(NULL, 3, &r), TASE_EARG);
    assert_int_equal(tase_candump_parse("x", 1, NULL), TASE_EARG);
}

static void frames_we_cannot_represent_are_unsupported(void **state)
{
    tase_candump_rec_t r;
    (void)state;
    assert_int_equal(parse("(1.000000) vcan0 123#R", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 123##100", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 20000080#0000000000000000", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 123#r", &r), TASE_EUNSUPPORTED); /* as canplayer */
    assert_int_equal(parse("(1.000000) vcan0 123#R5", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 12345678#R8_9 R", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 123##0", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 12345678##3AA.BB.CC", &r), TASE_EUNSUPPORTED);
    assert_int_equal(parse("(1.000000) vcan0 11000000##1AA.", &r), TASE_EUNSUPPORTED);
}

/* Classic CAN carries 8 bytes for any DLC above 8, and the SocketCAN port
 * receives such a frame as its 8 bytes; candump logs it with `_9`..`_F`.
 * Those lines were skipped as unsupported, so `tase decode --candump` lost
 * a packet `tase monitor --can` had received (a review). canplayer also
 * takes a '.' before the first byte and after the last. */
static void raw_dlc_frames_are_their_8_bytes_and_dots_separate_as_canplayer(void **state)
{
    static const uint8_t want[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
    tase_candump_rec_t r;
    (void)state;
    assert_int_equal(parse("(1.000000) vcan0 123#1122334455667788_E", &r), TASE_OK);
    assert_int_equal(r.frame.dlc, 8);
    assert_memory_equal(r.frame.data, want, 8);
    assert_int_equal(parse("(1.000000) vcan0 10000000#11.22.33.44.55.66.77.88_F\r\n", &r), TASE_OK);
    assert_int_equal(r.frame.dlc, 8);
    assert_true(r.frame.extended);
    assert_memory_equal(r.frame.data, want, 8);
    assert_int_equal(parse("(1.000000) vcan0 123#.1122", &r), TASE_OK);
    assert_int_equal(r.frame.dlc, 2);
    assert_int_equal(parse("(1.000000) vcan0 123#11.22.", &r), TASE_OK);
    assert_int_equal(r.frame.dlc, 2);
    assert_int_equal(r.frame.data[1], 0x22);
}

/* Only a well-formed line of those kinds is unsupported: a corrupted one
 * is not a log line (they were all "unsupported", so `tase decode
 * --candump` skipped corrupt lines on the datalink IDs without a word). */
static void malformed_unsupported_forms_are_format_errors(void **state)
{
    static const char *const bad[] = {
        "(1.000000) vcan0 123#Rgarbage!!",
        "(1.000000) vcan0 123#rubbish",
        "(1.000000) vcan0 11000000#R9",
        "(1.000000) vcan0 11000000#R3_9",
        "(1.000000) vcan0 11000000#R8_3",
        "(1.000000) vcan0 123##",
        "(1.000000) vcan0 123##ZZZZ not fd",
        "(1.000000) vcan0 123#11_E",
        "(1.000000) vcan0 123#1122334455667788_Zjunk",
        "(1.000000) vcan0 123#1122334455667788_E junk",
        "(1.000000) vcan0 20000080#this is not hex",
        "(1.000000) vcan0 20000080#001122334455667788",
    };
    char fd[256];
    size_t i;
    tase_candump_rec_t r;
    tase_candump_rec_t before;
    (void)state;
    memset(&r, 0x5A, sizeof r);
    before = r;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(parse(bad[i], &r), TASE_EFORMAT);
    }
    /* CAN FD carries at most 64 bytes */
    strcpy(fd, "(1.000000) vcan0 123##1");
    for (i = 0; i < 65; i++) {
        strcat(fd, "AB");
    }
    assert_int_equal(parse(fd, &r), TASE_EFORMAT);
    fd[strlen(fd) - 2] = '\0';
    assert_int_equal(parse(fd, &r), TASE_EUNSUPPORTED);
    assert_memory_equal(&r, &before, sizeof r);
}

static void format_writes_candump_style_lines(void **state)
{
    tase_candump_rec_t r;
    char line[TASE_CANDUMP_LINE_MAX];
    (void)state;
    memset(&r, 0, sizeof(r));
    r.sec = 42;
    r.usec = 7;
    strcpy(r.ifname, "vcan0");
    r.frame.id = 0x10000000u;
    r.frame.extended = true;
    r.frame.dlc = 3;
    r.frame.data[0] = 0x00;
    r.frame.data[1] = 0xFF;
    r.frame.data[2] = 0x5a;
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)),
                     (int)strlen("(0000000042.000007) vcan0 10000000#00FF5A\n"));
    assert_string_equal(line, "(0000000042.000007) vcan0 10000000#00FF5A\n");
    r.frame.extended = false;
    r.frame.id = 0x12;
    r.frame.dlc = 0;
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)),
                     (int)strlen("(0000000042.000007) vcan0 012#\n"));
    assert_string_equal(line, "(0000000042.000007) vcan0 012#\n");
}

static void format_needs_room_and_valid_records(void **state)
{
    tase_candump_rec_t r;
    char line[TASE_CANDUMP_LINE_MAX];
    (void)state;
    memset(&r, 0, sizeof(r));
    strcpy(r.ifname, "vcan0");
    r.frame.id = 0x123;
    r.frame.dlc = 1;
    memset(line, '#', sizeof(line));
    /* "(0000000000.000000) vcan0 123#00\n" is 33 characters + NUL */
    assert_int_equal(tase_candump_format(&r, line, 33), TASE_ENOSPC);
    assert_int_equal(line[0], '#');
    assert_int_equal(tase_candump_format(&r, line, 34), 33);
    assert_string_equal(line, "(0000000000.000000) vcan0 123#00\n");
    r.usec = 1000000;
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)), TASE_EARG);
    r.usec = 0;
    r.frame.id = 0x800;
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)), TASE_EARG);
    r.frame.id = 0x123;
    strcpy(r.ifname, "a b");
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)), TASE_EARG);
    r.ifname[0] = '\0';
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)), TASE_EARG);
    memset(r.ifname, 'x', sizeof(r.ifname)); /* not terminated */
    assert_int_equal(tase_candump_format(&r, line, sizeof(line)), TASE_EARG);
}

static void longest_line_fits_the_documented_maximum_and_round_trips(void **state)
{
    tase_candump_rec_t r, back;
    char line[TASE_CANDUMP_LINE_MAX];
    int n;
    (void)state;
    memset(&r, 0, sizeof(r));
    r.sec = UINT64_MAX;
    r.usec = 999999;
    strcpy(r.ifname, "abcdefghijklmno");
    r.frame.extended = true;
    r.frame.id = 0x1FFFFFFFu;
    r.frame.dlc = 8;
    memset(r.frame.data, 0xA5, 8);
    n = tase_candump_format(&r, line, sizeof(line));
    assert_int_equal(n, (int)TASE_CANDUMP_LINE_MAX - 1);
    assert_int_equal(tase_candump_parse(line, (size_t)n, &back), TASE_OK);
    assert_true(back.sec == UINT64_MAX);
    assert_int_equal(back.usec, 999999);
    assert_string_equal(back.ifname, r.ifname);
    assert_int_equal(back.frame.id, r.frame.id);
    assert_true(back.frame.extended);
    assert_int_equal(back.frame.dlc, 8);
    assert_memory_equal(back.frame.data, r.frame.data, 8);
}

/* Seconds at the edges of uint64_t parse and print exactly (the decimal
 * conversions use no 64-bit division, issue 26: checked digit by digit
 * here against values whose digits differ in every position). */
static void seconds_at_the_uint64_edges_round_trip(void **state)
{
    static const struct {
        const char *text;
        uint64_t sec;
    } ok[] = {
        {"0000000000", 0u},
        {"0000000001", 1u},
        {"1234567890", 1234567890u},
        {"9999999999", 9999999999u},
        {"10000000000", 10000000000u},
        {"18446744073709551610", 18446744073709551610u},
        {"18446744073709551615", UINT64_MAX},
        {"9876543210123456789", 9876543210123456789u},
    };
    static const char *const too_big[] = {"18446744073709551616", "18446744073709551619",
                                          "18446744073709551620", "99999999999999999999"};
    tase_candump_rec_t r;
    char line[TASE_CANDUMP_LINE_MAX];
    char want[TASE_CANDUMP_LINE_MAX];
    size_t i;
    int n;
    (void)state;
    for (i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        snprintf(line, sizeof line, "(%s.000001) can0 123#", ok[i].text);
        assert_int_equal(tase_candump_parse(line, strlen(line), &r), TASE_OK);
        assert_true(r.sec == ok[i].sec);
        n = tase_candump_format(&r, line, sizeof line);
        assert_true(n > 0);
        snprintf(want, sizeof want, "(%s.000001) can0 123#\n", ok[i].text);
        assert_string_equal(line, want);
    }
    for (i = 0; i < sizeof too_big / sizeof too_big[0]; i++) {
        snprintf(line, sizeof line, "(%s.000001) can0 123#", too_big[i]);
        assert_int_equal(tase_candump_parse(line, strlen(line), &r), TASE_EFORMAT);
    }
}

/* Bad arguments of candump.h give their documented codes and leave the
 * record and the output unchanged. */
static void candump_api_rejects_bad_arguments(void **state)
{
    static const char line[] = "(1.000000) can0 123#11\n";
    tase_candump_rec_t rec;
    tase_candump_rec_t copy;
    char out[TASE_CANDUMP_LINE_MAX];
    char before[sizeof out];
    (void)state;

    memset(&rec, 0x33, sizeof rec);
    memcpy(&copy, &rec, sizeof rec);
    assert_int_equal(tase_candump_parse(NULL, SIZE_MAX, &rec), TASE_EARG);
    assert_int_equal(tase_candump_parse(line, sizeof line - 1u, NULL), TASE_EARG);
    assert_int_equal(tase_candump_parse(line, 0, &rec), TASE_EFORMAT);
    assert_int_equal(tase_candump_parse(line, 5, &rec), TASE_EFORMAT);
    assert_memory_equal(&rec, &copy, sizeof rec);

    assert_int_equal(tase_candump_parse(line, sizeof line - 1u, &rec), TASE_OK);
    memset(out, 'x', sizeof out);
    memcpy(before, out, sizeof out);
    assert_int_equal(tase_candump_format(NULL, out, sizeof out), TASE_EARG);
    assert_int_equal(tase_candump_format(&rec, NULL, sizeof out), TASE_EARG);
    assert_int_equal(tase_candump_format(&rec, out, 0), TASE_ENOSPC);
    assert_int_equal(tase_candump_format(&rec, out, 5), TASE_ENOSPC);
    rec.usec = 1000000u;
    assert_int_equal(tase_candump_format(&rec, out, sizeof out), TASE_EARG);
    rec.usec = 0;
    memset(rec.ifname, 'a', sizeof rec.ifname); /* no terminating NUL */
    assert_int_equal(tase_candump_format(&rec, out, sizeof out), TASE_EARG);
    rec.ifname[0] = '\0'; /* empty */
    assert_int_equal(tase_candump_format(&rec, out, sizeof out), TASE_EARG);
    strcpy(rec.ifname, "can0");
    rec.frame.dlc = 9;
    assert_int_equal(tase_candump_format(&rec, out, sizeof out), TASE_EARG);
    assert_memory_equal(out, before, sizeof out);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(candump_api_rejects_bad_arguments),
        cmocka_unit_test(extended_line_parses_into_fields),
        cmocka_unit_test(standard_and_empty_frames_parse),
        cmocka_unit_test(malformed_lines_are_rejected_and_leave_output_alone),
        cmocka_unit_test(frames_we_cannot_represent_are_unsupported),
        cmocka_unit_test(raw_dlc_frames_are_their_8_bytes_and_dots_separate_as_canplayer),
        cmocka_unit_test(malformed_unsupported_forms_are_format_errors),
        cmocka_unit_test(format_writes_candump_style_lines),
        cmocka_unit_test(format_needs_room_and_valid_records),
        cmocka_unit_test(longest_line_fits_the_documented_maximum_and_round_trips),
        cmocka_unit_test(seconds_at_the_uint64_edges_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
