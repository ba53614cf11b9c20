/* Tests of the port helpers: write-all over ports that take part of a
 * write or refuse it, and frame sending. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fake_port.h"
#include "tase/port_io.h"

static fake_port_t *new_fake(void)
{
    fake_port_t *f = calloc(1, sizeof *f);
    assert_non_null(f);
    return f;
}

static void write_all_reassembles_partial_writes(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f};
    uint8_t data[100];
    size_t i;
    (void)state;
    for (i = 0; i < sizeof data; i++) {
        data[i] = (uint8_t)i;
    }
    f->write_limit = 7;
    assert_int_equal(tase_port_write_all(&p, data, sizeof data), 100);
    assert_int_equal(f->nout, 100);
    assert_memory_equal(f->out, data, 100);
    assert_int_equal(f->writes, 15); /* ceil(100 / 7) calls */
    free(f);
}

/* A port that takes `budget` bytes in total, then nothing (EAGAIN). */
typedef struct {
    size_t budget, taken;
    unsigned calls;
} stingy_t;

static int stingy_write(void *ctx, const uint8_t *data, size_t n)
{
    stingy_t *s = ctx;
    size_t take = s->budget - s->taken;
    (void)data;
    s->calls++;
    if (take == 0) {
        return TASE_EAGAIN;
    }
    if (take > n) {
        take = n;
    }
    s->taken += take;
    return (int)take;
}

static const tase_port_ops_t stingy_ops = {stingy_write, NULL, NULL};

static void write_all_reports_eagain_when_nothing_went_out(void **state)
{
    stingy_t s = {0, 0, 0};
    tase_port_t p = {&stingy_ops, &s};
    (void)state;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"abcd", 4), TASE_EAGAIN);
    assert_int_equal(s.calls, TASE_PORT_WRITE_TRIES); /* bounded, no endless spin */
}

static void write_all_reports_eio_when_a_frame_was_cut(void **state)
{
    stingy_t s = {3, 0, 0};
    tase_port_t p = {&stingy_ops, &s};
    (void)state;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"abcdef", 6), TASE_EIO);
    assert_int_equal(s.taken, 3);
}

static void write_all_passes_hard_errors_on_at_once(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f};
    (void)state;
    f->write_result = TASE_EDOWN;
    assert_int_equal(tase_port_write_all(&p, (const uint8_t *)"ab", 2), TASE_EDOWN);
    assert_int_equal(tase_port_write_all(NULL, (const uint8_t *)"ab", 2), TASE_EARG);
    assert_int_equal(tase_port_write_all(&p, NULL, 2), TASE_EARG);
    free(f);
}

static void send_frame_writes_one_encoded_frame(void **state)
{
    fake_port_t *f = new_fake();
    tase_port_t p = {&fake_ops, f};
    uint8_t want[TASE_FRAME_MAX];
    int n;
    (void)state;
    n = tase_frame_encode(want, sizeof want, 0x48, 0x00, (const uint8_t *)"\x01\x02", 2);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, (const uint8_t *)"\x01\x02", 2), n);
    assert_int_equal(f->nout, (size_t)n);
    assert_memory_equal(f->out, want, (size_t)n);
    assert_int_equal(tase_port_send_frame(&p, 0x48, 0x00, want, 254), TASE_ETOOLONG);
    assert_int_equal(f->nout, (size_t)n); /* nothing more written */
    free(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(write_all_reassembles_partial_writes),
        cmocka_unit_test(write_all_reports_eagain_when_nothing_went_out),
        cmocka_unit_test(write_all_reports_eio_when_a_frame_was_cut),
        cmocka_unit_test(write_all_passes_hard_errors_on_at_once),
        cmocka_unit_test(send_frame_writes_one_encoded_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
