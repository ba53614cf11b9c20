/* The bench tools' capture writer (tools/tk_capture.c): the clock of a
 * --record tap and appending in an existing file's own format. The shell
 * tests (tests/tools/capture.sh) run the programs; these run the module
 * with a fake port whose clock the test sets. */
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <cmocka.h>

#include "tk_capture.h"

static uint32_t fake_ms;

static int fake_write(void *ctx, const uint8_t *data, size_t n)
{
    (void)ctx;
    (void)data;
    return (int)n;
}

/* one byte a read: its value is the read's number */
static int fake_read(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms)
{
    static uint8_t next;
    (void)ctx;
    (void)timeout_ms;
    if (cap == 0u) {
        return 0;
    }
    buf[0] = next++;
    return 1;
}

static uint32_t fake_now(void *ctx)
{
    (void)ctx;
    return fake_ms;
}

static const tase_port_ops_t fake_ops = {fake_write, fake_read, fake_now};

static void temp_path(char *out, size_t cap)
{
    int fd;
    snprintf(out, cap, "/tmp/tase_test_tk_capture_XXXXXX");
    fd = mkstemp(out);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(unlink(out), 0); /* tk_cap_create() makes it */
}

static int64_t rec_us(const tk_cap_rec_t *rec)
{
    return rec->t.sec * 1000000 + (int64_t)rec->t.usec;
}

/* Record the reads of a tap whose port clock takes the steps given into
 * a new capture; returns their times (microseconds) in t[0..n). */
static void tap_session(const uint32_t *ms, int n, int64_t *t)
{
    char path[64];
    tk_cap_writer_t w;
    tk_cap_tap_t tap;
    tase_port_t inner = {&fake_ops, NULL, 5760u};
    tase_port_t port;
    tk_cap_reader_t r;
    tk_cap_rec_t rec;
    char why[160];
    uint8_t b;
    int fd, i;
    temp_path(path, sizeof(path));
    tk_cap_create(&w, path, TK_CAP_LINKTYPE_SERIAL, true);
    port = tk_cap_tap_port(&tap, inner, &w);
    for (i = 0; i < n; i++) {
        fake_ms = ms[i];
        assert_int_equal(port.ops->read(port.ctx, &b, 1u, 0u), 1);
    }
    assert_int_equal(tk_cap_finish(&w), 0);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    tk_cap_reader_open(&r, fd, NULL, 0u, path);
    for (i = 0; i < n; i++) {
        assert_int_equal(tk_cap_next(&r, &rec, why, sizeof(why)), TK_CAP_RECORD);
        assert_int_equal(rec.dir, TK_CAP_FROM_GIMBAL);
        t[i] = rec_us(&rec);
    }
    assert_int_equal(tk_cap_next(&r, &rec, why, sizeof(why)), TK_CAP_END);
    tk_cap_reader_close(&r);
    close(fd);
    unlink(path);
}

static int64_t wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * 1000000 + ts.tv_nsec / 1000;
}

/* The tap stamps its records on the port's 32-bit millisecond clock, so
 * that `tase decode` measures the gaps the live receiver did: exactly its
 * steps, also where that clock wraps. */
static void tap_times_are_the_port_clocks_steps_across_its_wrap(void **state)
{
    static const uint32_t ms[6] = {0xFFFFFF00u, 0xFFFFFF64u, 0xFFFFFFC8u,
                                   0x0000002Cu, 0x00000090u, 0x000000F4u};
    int64_t t[6];
    int i;
    (void)state;
    tap_session(ms, 6, t);
    for (i = 1; i < 6; i++) {
        assert_true(t[i] - t[i - 1] == 100000); /* 100 ms, to the microsecond */
    }
}

/* A port clock that leaves the wall clock (it stood still while the
 * computer slept, or no record came for 2^31 ms: a difference from the
 * first record of 2^31 ms or more turned negative, times went back 49.7
 * days): the times stay at the wall clock, in order. */
static void tap_times_follow_the_wall_clock_when_the_port_clock_jumps(void **state)
{
    static const uint32_t ms[6] = {0xF0000000u, 0xF0000000u, 0x80000000u,
                                   0x80000000u, 0x10000000u, 0x10000000u};
    int64_t t[6], before = wall_us(), after;
    int i;
    (void)state;
    tap_session(ms, 6, t);
    after = wall_us();
    for (i = 0; i < 6; i++) {
        assert_true(t[i] >= before - 1000 && t[i] <= after + 1000); /* whole ms */
        if (i > 0) {
            assert_true(t[i] >= t[i - 1]);
        }
    }
}

static void put_be32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v >> 24);
    p[1] = (uint8_t)(v >> 16);
    p[2] = (uint8_t)(v >> 8);
    p[3] = (uint8_t)v;
}

static uint32_t get_be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* An existing big-endian microsecond capture (another tool's) is appended
 * to in its own byte order and precision, its first record kept. */
static void append_writes_in_the_files_own_format(void **state)
{
    char path[64];
    uint8_t file[24 + 16 + 3];
    uint8_t got[sizeof(file) + 16 + 2];
    tk_cap_writer_t w;
    tk_cap_tap_t tap;
    tase_port_t inner = {&fake_ops, NULL, 5760u};
    tase_port_t port;
    struct timespec t;
    uint8_t b;
    int fd;
    (void)state;
    temp_path(path, sizeof(path));
    memset(file, 0, sizeof(file));
    put_be32(file, 0xA1B2C3D4u); /* microseconds, big-endian */
    file[5] = 2;
    file[7] = 4;
    put_be32(file + 16, 65535u);
    put_be32(file + 20, TK_CAP_LINKTYPE_SERIAL);
    put_be32(file + 24, 1700000000u);
    put_be32(file + 28, 999999u);
    put_be32(file + 32, 3u);
    put_be32(file + 36, 3u);
    file[40] = 0;
    file[41] = 0xAA;
    file[42] = 0xBB;
    fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0600);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, file, sizeof(file)), (ssize_t)sizeof(file));
    close(fd);
    tk_cap_create(&w, path, TK_CAP_LINKTYPE_SERIAL, true);
    port = tk_cap_tap_port(&tap, inner, &w);
    fake_ms = 1234u;
    assert_int_equal(port.ops->read(port.ctx, &b, 1u, 0u), 1);
    assert_true(tk_cap_session_last_read(&fake_ms, &t) == false); /* not the session's tap */
    assert_int_equal(tk_cap_finish(&w), 0);
    fd = open(path, O_RDONLY);
    assert_true(fd >= 0);
    assert_int_equal(read(fd, got, sizeof(got)), (ssize_t)sizeof(got));
    assert_int_equal(read(fd, got, 1u), 0);
    close(fd);
    assert_memory_equal(got, file, sizeof(file));             /* header and record 1 kept */
    assert_true(get_be32(got + sizeof(file) + 4) < 1000000u); /* microseconds */
    assert_int_equal(get_be32(got + sizeof(file) + 8), 2u);   /* direction + 1 byte */
    assert_int_equal(get_be32(got + sizeof(file) + 12), 2u);
    assert_int_equal(got[sizeof(file) + 16], TK_CAP_FROM_GIMBAL);
    assert_int_equal(got[sizeof(file) + 17], b);
    unlink(path);
}

/* A review: a pcapng's if_tsoffset can give a record time of 2^62 s and
 * more; the decoder's millisecond arithmetic on such times overflowed a
 * signed 64-bit number (undefined: the sanitize check runs this test under
 * UBSan). A GIMBAL_ANGLE split across the largest and smallest times, a
 * step back (no time), and across a step forward as large, is decoded;
 * the pause forward cuts the one split across it. */
static void record_times_at_the_ends_of_int64_overflow_nothing(void **state)
{
    static tk_dec_t d;
    static const uint8_t angle[14] = {0x00, 0xFF, 0x5A, 0x08, 0x08, 0x10, 0x00,
                                      0x01, 0x00, 0x02, 0x00, 0x03, 0x00, 0x00};
    uint8_t f[14];
    unsigned sum = 0, i;
    const tk_fmt_t fmt = {true, false, true};
    const tk_time_t hi = {INT64_MAX, 999999}, lo = {INT64_MIN, 0}, mid = {1700000000, 0};
    FILE *out = tmpfile();
    tk_stream_t *s;
    (void)state;
    assert_non_null(out);
    memcpy(f, angle, sizeof f);
    for (i = 0; i < 12u; i++) {
        sum += f[i];
    }
    f[12] = (uint8_t)(sum >> 8); /* checksum of sync..data (spec 3.1) */
    f[13] = (uint8_t)sum;
    tk_dec_init(&d, &fmt, out);
    d.by_time = true;
    d.serial_rate = 5760u;
    s = tk_dec_stream(&d, "", "out");
    assert_non_null(s);
    tk_dec_bytes(&d, s, f, 5, &hi);
    tk_dec_bytes(&d, s, &f[5], sizeof f - 5u, &lo); /* a step back: no time */
    tk_dec_bytes(&d, s, f, 5, &mid);                /* forward, by 2^63 s */
    tk_dec_bytes(&d, s, &f[5], sizeof f - 5u, &hi); /* again: a long pause */
    tk_dec_finish(&d);
    assert_int_equal(d.n.frames, 1u);
    assert_int_equal(fclose(out), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tap_times_are_the_port_clocks_steps_across_its_wrap),
        cmocka_unit_test(tap_times_follow_the_wall_clock_when_the_port_clock_jumps),
        cmocka_unit_test(append_writes_in_the_files_own_format),
        cmocka_unit_test(record_times_at_the_ends_of_int64_overflow_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
