/* Tests of the bare-metal UART template: the ISR ring buffer (with a
 * producer thread standing in for the interrupt) and the port functions. */
#include <pthread.h>
#include <sched.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "tase/frame.h"
#include "tase/bm_uart.h"
#include "tase/ring.h"

/* Byte number i of the test stream: not periodic in 256, so a lost,
 * repeated or reordered byte changes the sequence. */
static uint8_t stream_byte(uint32_t i)
{
    return (uint8_t)(i ^ (i >> 8) ^ (i >> 16) ^ (i * 37u));
}

static void init_rejects_sizes_that_are_not_a_power_of_two(void **state)
{
    tase_ring_t r;
    uint8_t buf[64];
    (void)state;
    assert_int_equal(tase_ring_init(&r, buf, 0), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, buf, 48), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, NULL, 64), TASE_EARG);
    assert_int_equal(tase_ring_init(NULL, buf, 64), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, buf, 64), TASE_OK);
    assert_int_equal(tase_ring_capacity(&r), 64);
    assert_int_equal(tase_ring_init(&r, buf, 1), TASE_OK);
    assert_int_equal(tase_ring_capacity(&r), 1);
    assert_int_equal(tase_ring_count(NULL), 0);
    assert_int_equal(tase_ring_overflows(NULL), 0);
    assert_int_equal(tase_ring_get(NULL, buf, 4), 0);
}

static void a_full_ring_drops_and_counts_every_extra_byte(void **state)
{
    tase_ring_t r;
    uint8_t buf[8], out[16];
    uint32_t i;
    (void)state;
    assert_int_equal(tase_ring_init(&r, buf, sizeof buf), TASE_OK);
    for (i = 0; i < 8; i++) {
        assert_true(tase_ring_put(&r, (uint8_t)i));
    }
    assert_int_equal(tase_ring_count(&r), 8); /* every slot usable */
    for (i = 0; i < 5; i++) {
        assert_false(tase_ring_put(&r, 0xEE));
    }
    assert_int_equal(tase_ring_overflows(&r), 5);
    assert_int_equal(tase_ring_get(&r, out, sizeof out), 8);
    for (i = 0; i < 8; i++) {
        assert_int_equal(out[i], i); /* the dropped 0xEE never got in */
    }
    assert_int_equal(tase_ring_count(&r), 0);
    assert_true(tase_ring_put(&r, 42));           /* room again */
    assert_int_equal(tase_ring_overflows(&r), 5); /* not reset by reading */
}

static void order_survives_many_wrap_arounds(void **state)
{
    tase_ring_t r;
    uint8_t buf[16], out[16];
    uint32_t produced = 0, consumed = 0, round;
    (void)state;
    assert_int_equal(tase_ring_init(&r, buf, sizeof buf), TASE_OK);
    for (round = 0; round < 10000; round++) {
        uint32_t k, put = 1u + round % 16u;
        size_t n, j;
        for (k = 0; k < put; k++) {
            assert_true(tase_ring_put(&r, stream_byte(produced++)));
        }
        n = tase_ring_get(&r, out, 1u + (round * 7u) % 16u);
        for (j = 0; j < n; j++) {
            assert_int_equal(out[j], stream_byte(consumed++));
        }
        n = tase_ring_get(&r, out, sizeof out); /* empty it */
        for (j = 0; j < n; j++) {
            assert_int_equal(out[j], stream_byte(consumed++));
        }
    }
    assert_int_equal(consumed, produced);
    assert_int_equal(tase_ring_overflows(&r), 0);
}

/* ---- producer thread standing in for the RX interrupt ---------------- */

/* Valgrind runs threads one at a time, so the spinning producer and
 * consumer crawl under it: scale the volume down there (the ordering and
 * accounting assertions are the same). */
static uint32_t scaled(uint32_t n)
{
    return getenv("TASE_UNDER_VALGRIND") != NULL ? n / 100u : n;
}

#define STRESS_BYTES scaled(4000000u)

typedef struct {
    tase_ring_t *ring;
    uint32_t n;
    uint8_t *dropped; /* dropped[i] = 1 when byte i did not fit */
    uint32_t drops;
    volatile int done;
} producer_t;

static void *producer(void *arg)
{
    producer_t *p = arg;
    uint32_t i;
    for (i = 0; i < p->n; i++) {
        /* The stream is cut into 16 phases. Three phases of four wait
         * while the ring is full (a line with gaps: nothing may be lost);
         * the fourth runs flat out and must overflow a ring the consumer
         * cannot keep up with. */
        if (((i / (p->n / 16u + 1u)) & 3u) != 3u) {
            while (tase_ring_count(p->ring) == tase_ring_capacity(p->ring)) {
                sched_yield();
            }
        }
        if (!tase_ring_put(p->ring, stream_byte(i))) {
            p->dropped[i] = 1;
            p->drops++;
        }
    }
    __atomic_store_n(&p->done, 1, __ATOMIC_RELEASE);
    return NULL;
}

static void run_stress(uint32_t ring_size, unsigned consumer_pause_every)
{
    tase_ring_t ring;
    uint8_t *storage = malloc(ring_size);
    uint8_t *got = malloc(STRESS_BYTES);
    producer_t p;
    pthread_t th;
    uint32_t received = 0, j, k, iter = 0;
    uint8_t chunk[97];

    assert_non_null(storage);
    assert_non_null(got);
    memset(&p, 0, sizeof p);
    p.dropped = calloc(STRESS_BYTES, 1);
    assert_non_null(p.dropped);
    assert_int_equal(tase_ring_init(&ring, storage, ring_size), TASE_OK);
    p.ring = &ring;
    p.n = STRESS_BYTES;
    assert_int_equal(pthread_create(&th, NULL, producer, &p), 0);
    for (;;) {
        int finished = __atomic_load_n(&p.done, __ATOMIC_ACQUIRE);
        size_t n = tase_ring_get(&ring, chunk, 1u + iter % sizeof chunk);
        assert_true(received + n <= STRESS_BYTES);
        memcpy(got + received, chunk, n);
        received += (uint32_t)n;
        iter++;
        if (consumer_pause_every != 0 && iter % consumer_pause_every == 0) {
            sched_yield(); /* a slow main loop: forces overflows */
        }
        if (finished && n == 0 && tase_ring_count(&ring) == 0) {
            break;
        }
    }
    pthread_join(th, NULL);

    assert_int_equal(tase_ring_overflows(&ring), p.drops);
    assert_int_equal((uint64_t)received + tase_ring_overflows(&ring), STRESS_BYTES);
    /* What arrived is exactly the produced stream minus the dropped bytes,
     * in order. */
    for (j = 0, k = 0; j < STRESS_BYTES; j++) {
        if (p.dropped[j]) {
            continue;
        }
        if (got[k] != stream_byte(j)) {
            fail_msg("byte %u (received #%u) is %u, expected %u", j, k, got[k], stream_byte(j));
        }
        k++;
    }
    assert_int_equal(k, received);
    assert_true(received >= STRESS_BYTES / 2); /* the paced phases got through */
    if (consumer_pause_every != 0) {
        assert_true(tase_ring_overflows(&ring) > 0); /* the slow loop fell behind */
    }
    print_message("ring %u B: %u bytes produced, %u received, %u overflowed\n", ring_size,
                  STRESS_BYTES, received, tase_ring_overflows(&ring));
    free(p.dropped);
    free(got);
    free(storage);
}

static void millions_of_bytes_from_an_isr_thread_arrive_in_order_or_counted(void **state)
{
    (void)state;
    run_stress(1024, 0);
}

static void a_slow_consumer_loses_only_counted_bytes(void **state)
{
    (void)state;
    run_stress(64, 3); /* tiny ring and a main loop that keeps yielding */
}

/* ---- the port template ------------------------------------------------ */

/* A fake core: a millisecond clock, a TX buffer, an interrupt mask, and
 * a receive interrupt that can be made to fire at chosen points. WFI
 * (idle) returns at once when an interrupt is pending, else sleeps until
 * the next SysTick, 1 ms later, as a Cortex-M does. */
typedef struct {
    uint32_t now;
    uint8_t tx[4096];
    size_t ntx;
    int tx_result;
    tase_bm_uart_t *uart;
    int masked, pending;
    uint8_t pending_byte;
    unsigned millis_calls, irq_offs;
    unsigned arrive_on_millis;  /* the RX interrupt fires in this millis() call */
    unsigned arrive_on_irq_off; /* ... or right after this irq_off() */
    int idle_calls;
    int deliver_after_idles; /* ... or during this sleep */
    int slept_with_data;     /* sleeps begun while a byte waited: lost wake-ups */
    int wakes_on_pending;
} fake_hw_t;

/* The RX interrupt: runs now, or stays pending while masked. */
static void fake_rx_interrupt(fake_hw_t *f, uint8_t b)
{
    if (f->masked) {
        f->pending = 1;
        f->pending_byte = b;
    } else {
        tase_bm_uart_rx_isr(f->uart, b);
    }
}

static int fake_tx(void *hw, const uint8_t *data, size_t n)
{
    fake_hw_t *f = hw;
    if (f->tx_result < 0) {
        return f->tx_result;
    }
    assert_true(f->ntx + n <= sizeof f->tx);
    memcpy(f->tx + f->ntx, data, n);
    f->ntx += n;
    return 0;
}

static uint32_t fake_millis(void *hw)
{
    fake_hw_t *f = hw;
    if (++f->millis_calls == f->arrive_on_millis) {
        fake_rx_interrupt(f, 0xA5);
    }
    return f->now;
}

static void fake_idle(void *hw)
{
    fake_hw_t *f = hw;
    f->idle_calls++;
    if (f->uart != NULL && tase_ring_count(&f->uart->rx) > 0u) {
        f->slept_with_data++;
    }
    if (f->pending) {
        f->wakes_on_pending++;
        return; /* WFI: a pending interrupt wakes the core at once */
    }
    f->now += 1; /* asleep until the next SysTick */
    if (f->idle_calls == f->deliver_after_idles) {
        fake_rx_interrupt(f, 0x5A);
    }
}

static void fake_irq_off(void *hw)
{
    fake_hw_t *f = hw;
    f->masked = 1;
    if (++f->irq_offs == f->arrive_on_irq_off) {
        fake_rx_interrupt(f, 0xA6);
    }
}

static void fake_irq_on(void *hw)
{
    fake_hw_t *f = hw;
    f->masked = 0;
    if (f->pending) {
        f->pending = 0;
        tase_bm_uart_rx_isr(f->uart, f->pending_byte);
    }
}

static const tase_bm_uart_hooks_t fake_hooks = {fake_tx, fake_millis, fake_idle, fake_irq_off,
                                                fake_irq_on};

static void port_read_waits_on_the_millisecond_hook_and_wakes_on_rx(void **state)
{
    static fake_hw_t hw;
    tase_bm_uart_t u;
    uint8_t storage[32], buf[8];
    tase_port_t port;
    (void)state;

    memset(&hw, 0, sizeof hw);
    hw.now = 0xFFFFFFF0u; /* the wait spans the 2^32 wrap */
    hw.uart = &u;
    assert_int_equal(tase_bm_uart_init(&u, storage, 48, &fake_hooks, &hw), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    port = tase_bm_uart_port(&u);

    hw.deliver_after_idles = -1;
    assert_int_equal(port.ops->read(port.ctx, buf, sizeof buf, 50), 0);
    assert_int_equal(hw.now, 0xFFFFFFF0u + 50u);

    hw.idle_calls = 0;
    hw.deliver_after_idles = 7;
    assert_int_equal(port.ops->read(port.ctx, buf, sizeof buf, 1000), 1);
    assert_int_equal(buf[0], 0x5A);
    assert_int_equal(hw.idle_calls, 7);
    assert_int_equal(port.ops->now_ms(port.ctx), hw.now);
}

static void port_write_goes_to_the_tx_hook_whole_or_reports_its_error(void **state)
{
    static fake_hw_t hw;
    tase_bm_uart_t u;
    uint8_t storage[32];
    tase_port_t port;
    (void)state;

    memset(&hw, 0, sizeof hw);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    port = tase_bm_uart_port(&u);
    assert_int_equal(port.ops->write(port.ctx, (const uint8_t *)"hello", 5), 5);
    assert_memory_equal(hw.tx, "hello", 5);
    hw.tx_result = TASE_EIO;
    assert_int_equal(port.ops->write(port.ctx, (const uint8_t *)"x", 1), TASE_EIO);
}

typedef struct {
    uint32_t frames;
    uint32_t bad;
    uint32_t next_seq;
} frame_count_t;

static void count_frame(void *user, const tase_frame_t *f)
{
    frame_count_t *c = user;
    uint32_t seq = ((uint32_t)f->data[0] << 24) | ((uint32_t)f->data[1] << 16) |
                   ((uint32_t)f->data[2] << 8) | f->data[3];
    if (f->group != 0x08 || f->type != 0x10 || f->len != 20 || seq != c->next_seq) {
        c->bad++;
    }
    c->next_seq = seq + 1u;
    c->frames++;
}

#define ISR_FRAMES scaled(20000u)

typedef struct {
    tase_bm_uart_t *u;
    volatile int done;
} isr_sim_t;

/* Sends ISR_FRAMES frames byte by byte like a UART RX interrupt, waiting
 * (hardware flow control style) whenever the ring is full, so that no
 * byte may be lost. */
static void *isr_frames(void *arg)
{
    isr_sim_t *s = arg;
    uint8_t frame[TASE_FRAME_MAX], data[20];
    uint32_t seq;
    for (seq = 0; seq < ISR_FRAMES; seq++) {
        int n, i;
        memset(data, (int)(seq & 0xFFu), sizeof data);
        data[0] = (uint8_t)(seq >> 24);
        data[1] = (uint8_t)(seq >> 16);
        data[2] = (uint8_t)(seq >> 8);
        data[3] = (uint8_t)seq;
        n = tase_frame_build(0x08, 0x10, data, sizeof data, frame, sizeof frame);
        for (i = 0; i < n; i++) {
            while (tase_ring_count(&s->u->rx) == tase_ring_capacity(&s->u->rx)) {
                sched_yield();
            }
            tase_bm_uart_rx_isr(s->u, frame[i]);
        }
    }
    __atomic_store_n(&s->done, 1, __ATOMIC_RELEASE);
    return NULL;
}

static void main_loop_poll_delivers_every_frame_the_isr_received(void **state)
{
    static fake_hw_t hw;
    static tase_rx_t rx;
    tase_bm_uart_t u;
    uint8_t storage[256];
    frame_count_t c = {0, 0, 0};
    isr_sim_t s;
    pthread_t th;
    (void)state;

    memset(&hw, 0, sizeof hw);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    s.u = &u;
    s.done = 0;
    assert_int_equal(pthread_create(&th, NULL, isr_frames, &s), 0);
    for (;;) {
        int finished = __atomic_load_n(&s.done, __ATOMIC_ACQUIRE);
        int r = tase_bm_uart_poll(&u, &rx, count_frame, &c);
        assert_true(r >= 0);
        if (finished && tase_ring_count(&u.rx) == 0) {
            break;
        }
    }
    pthread_join(th, NULL);
    assert_int_equal(tase_bm_uart_poll(&u, &rx, count_frame, &c), 0);
    assert_int_equal(c.frames, ISR_FRAMES);
    assert_int_equal(c.bad, 0);
    assert_int_equal(rx.stats.checksum_errors, 0);
    assert_int_equal(tase_ring_overflows(&u.rx), 0);
    assert_int_equal(tase_bm_uart_poll(NULL, &rx, count_frame, &c), TASE_EARG);
}

/* Bad arguments of the ring and the bare-metal UART template give their
 * documented results and change nothing: NULL, a never-initialised ring
 * or UART (no storage, no hooks), bad capacities. */
static void baremetal_api_rejects_bad_arguments(void **state)
{
    static uint8_t storage[8];
    tase_ring_t r;
    tase_ring_t rcopy;
    tase_bm_uart_t u;
    tase_bm_uart_t ucopy;
    uint8_t out[4];
    uint8_t before[sizeof out];
    (void)state;

    memset(out, 0xA5, sizeof out);
    memcpy(before, out, sizeof out);
    memset(&r, 0, sizeof r); /* never initialised: no storage */
    memcpy(&rcopy, &r, sizeof r);
    assert_false(tase_ring_put(NULL, 1));
    assert_false(tase_ring_put(&r, 1));
    assert_int_equal(tase_ring_get(&r, out, sizeof out), 0);
    assert_int_equal(tase_ring_get(NULL, out, sizeof out), 0);
    assert_memory_equal(&r, &rcopy, sizeof r);
    assert_int_equal(tase_ring_init(&r, storage, 0), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, storage, 3), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, storage, SIZE_MAX), TASE_EARG);
    assert_int_equal(tase_ring_init(&r, NULL, 8), TASE_EARG);
    assert_int_equal(tase_ring_init(NULL, storage, 8), TASE_EARG);
    assert_memory_equal(&r, &rcopy, sizeof r);
    assert_int_equal(tase_ring_init(&r, storage, sizeof storage), TASE_OK);
    assert_true(tase_ring_put(&r, 0x42));
    memcpy(&rcopy, &r, sizeof r);
    assert_int_equal(tase_ring_get(&r, NULL, 4), 0);
    assert_int_equal(tase_ring_get(&r, out, 0), 0);
    assert_memory_equal(&r, &rcopy, sizeof r);
    assert_memory_equal(out, before, sizeof out);
    assert_int_equal(tase_ring_count(NULL), 0);
    assert_int_equal(tase_ring_overflows(NULL), 0);
    assert_int_equal(tase_ring_capacity(NULL), 0);

    memset(&u, 0, sizeof u); /* never initialised: no hooks */
    memcpy(&ucopy, &u, sizeof u);
    tase_bm_uart_rx_isr(NULL, 1);
    tase_bm_uart_rx_isr(&u, 1);
    assert_int_equal(tase_bm_uart_ops.write(&u, out, 1), TASE_EARG);
    assert_int_equal(tase_bm_uart_ops.write(NULL, out, 1), TASE_EARG);
    assert_int_equal(tase_bm_uart_ops.read(&u, out, sizeof out, 0), TASE_EARG);
    assert_int_equal(tase_bm_uart_ops.read(NULL, out, sizeof out, 0), TASE_EARG);
    assert_int_equal(tase_bm_uart_ops.now_ms(&u), 0);
    assert_int_equal(tase_bm_uart_ops.now_ms(NULL), 0);
    assert_int_equal(tase_bm_uart_poll(NULL, NULL, NULL, NULL), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, storage, 3, &fake_hooks, NULL), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, NULL, 8, &fake_hooks, NULL), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, storage, 8, NULL, NULL), TASE_EARG);
    assert_memory_equal(&u, &ucopy, sizeof u);
    assert_memory_equal(out, before, sizeof out);
}

/* The race: a byte whose interrupt fires after read() saw an empty
 * ring but before the core went to sleep. With a check-then-WFI idle hook
 * the core slept on with the byte in the ring until the next interrupt;
 * now the check and the sleep happen with the interrupt masked. */
static void a_byte_arriving_between_the_check_and_the_sleep_is_not_missed(void **state)
{
    static fake_hw_t hw;
    tase_bm_uart_t u;
    uint8_t storage[32], buf[8];
    tase_port_t port;
    (void)state;

    memset(&hw, 0, sizeof hw);
    hw.uart = &u;
    hw.now = 1000;
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    port = tase_bm_uart_port(&u);
    /* millis() call 1 takes the start time, call 2 is the timeout check
     * right after the ring was found empty: the interrupt fires there. */
    hw.arrive_on_millis = 2;
    assert_int_equal(port.ops->read(port.ctx, buf, sizeof buf, 1000), 1);
    assert_int_equal(buf[0], 0xA5);
    assert_int_equal(hw.slept_with_data, 0);
    assert_int_equal(hw.now, 1000); /* returned at once, no tick slept */

    /* The interrupt fires once the mask is on: it stays pending, WFI
     * returns at once, unmasking runs it, read() returns its byte. */
    hw.arrive_on_millis = 0;
    hw.irq_offs = 0;
    hw.arrive_on_irq_off = 1;
    assert_int_equal(port.ops->read(port.ctx, buf, sizeof buf, 1000), 1);
    assert_int_equal(buf[0], 0xA6);
    assert_int_equal(hw.wakes_on_pending, 1);
    assert_int_equal(hw.slept_with_data, 0);
    assert_int_equal(hw.now, 1000);
    assert_int_equal(hw.masked, 0); /* left unmasked */
}

static void an_idle_hook_without_the_interrupt_mask_is_refused(void **state)
{
    static const tase_bm_uart_hooks_t racy = {fake_tx, fake_millis, fake_idle, NULL, NULL};
    static const tase_bm_uart_hooks_t half = {fake_tx, fake_millis, fake_idle, fake_irq_off, NULL};
    static const tase_bm_uart_hooks_t spin = {fake_tx, fake_millis, NULL, NULL, NULL};
    static fake_hw_t hw;
    tase_bm_uart_t u;
    uint8_t storage[8];
    (void)state;
    memset(&hw, 0, sizeof hw);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &racy, &hw), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &half, &hw), TASE_EARG);
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &spin, &hw), TASE_OK);
}

static void poll_reports_a_receiver_error_and_loses_no_byte_to_it(void **state)
{
    static fake_hw_t hw;
    tase_bm_uart_t u;
    uint8_t storage[64], wire[TASE_FRAME_MAX];
    tase_rx_t rx;
    frame_count_t c;
    int n, i;
    (void)state;
    memset(&hw, 0, sizeof hw);
    hw.uart = &u;
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    n = tase_frame_build(0x48, 0x00, NULL, 0, wire, sizeof wire);
    for (i = 0; i < n; i++) {
        tase_bm_uart_rx_isr(&u, wire[i]);
    }
    memset(&rx, 0xFF, sizeof rx); /* never initialised: garbage */
    memset(&c, 0, sizeof c);
    assert_int_equal(tase_bm_uart_poll(&u, &rx, count_frame, &c), TASE_EARG);
    assert_int_equal(tase_ring_count(&u.rx), (uint32_t)n); /* still there */
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    assert_int_equal(tase_bm_uart_poll(&u, &rx, count_frame, &c), 1);
    assert_int_equal(c.frames, 1);
}

static void count_any(void *user, const tase_frame_t *f)
{
    (void)f;
    (*(uint32_t *)user)++;
}

/* poll() returns every frame it delivers, also those a lagging receiver
 * releases when poll first checks it (before any byte leaves the ring):
 * false syncs claiming long frames, with real frames among them, make the
 * receiver's scan lag behind the bytes it took in. */
static void poll_counts_the_frames_a_lagging_scan_releases(void **state)
{
    static fake_hw_t hw;
    static uint8_t stream[6000];
    tase_bm_uart_t u;
    uint8_t storage[64];
    tase_rx_t rx;
    uint32_t delivered = 0, returned = 0;
    size_t n = 0, fed = 0;
    unsigned k, rep;
    (void)state;
    for (rep = 0; rep < 8u; rep++) {
        static const uint8_t sync255[4] = {0x00, 0xFF, 0x5A, 0xFF};
        uint8_t data[6] = {0, 2, 3, 4, 5, (uint8_t)rep};
        memcpy(&stream[n], sync255, 4);
        n += 4;
        for (k = 1; k <= 63u; k++) {
            stream[n++] = 0x00;
            stream[n++] = 0xFF;
            stream[n++] = 0x5A;
            stream[n++] = (uint8_t)(255u - 4u * k);
        }
        for (k = 0; k < 8u; k++) {
            data[0] = (uint8_t)k;
            n += (size_t)tase_frame_build(0x08, 0x10, data, sizeof data, &stream[n],
                                          sizeof stream - n);
        }
    }
    memset(&hw, 0, sizeof hw);
    hw.uart = &u;
    assert_int_equal(tase_bm_uart_init(&u, storage, sizeof storage, &fake_hooks, &hw), TASE_OK);
    assert_int_equal(tase_rx_init(&rx), TASE_OK);
    while (fed < n) {
        int r;
        while (fed < n && tase_ring_count(&u.rx) < tase_ring_capacity(&u.rx)) {
            tase_bm_uart_rx_isr(&u, stream[fed++]);
        }
        r = tase_bm_uart_poll(&u, &rx, count_any, &delivered);
        assert_true(r >= 0);
        returned += (uint32_t)r;
        /* nothing new: the probe alone may release lagging frames */
        r = tase_bm_uart_poll(&u, &rx, count_any, &delivered);
        assert_true(r >= 0);
        returned += (uint32_t)r;
        assert_int_equal(returned, delivered);
    }
    returned += (uint32_t)tase_rx_flush(&rx, count_any, &delivered);
    assert_int_equal(returned, delivered);
    assert_true(delivered >= 8u * 8u); /* the real frames, at least */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(baremetal_api_rejects_bad_arguments),
        cmocka_unit_test(init_rejects_sizes_that_are_not_a_power_of_two),
        cmocka_unit_test(a_full_ring_drops_and_counts_every_extra_byte),
        cmocka_unit_test(order_survives_many_wrap_arounds),
        cmocka_unit_test(millions_of_bytes_from_an_isr_thread_arrive_in_order_or_counted),
        cmocka_unit_test(a_slow_consumer_loses_only_counted_bytes),
        cmocka_unit_test(port_read_waits_on_the_millisecond_hook_and_wakes_on_rx),
        cmocka_unit_test(port_write_goes_to_the_tx_hook_whole_or_reports_its_error),
        cmocka_unit_test(main_loop_poll_delivers_every_frame_the_isr_received),
        cmocka_unit_test(a_byte_arriving_between_the_check_and_the_sleep_is_not_missed),
        cmocka_unit_test(an_idle_hook_without_the_interrupt_mask_is_refused),
        cmocka_unit_test(poll_reports_a_receiver_error_and_loses_no_byte_to_it),
        cmocka_unit_test(poll_counts_the_frames_a_lagging_scan_releases),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
