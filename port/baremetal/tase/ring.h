/*
 * tase/ring.h - single-producer single-consumer byte ring for a UART
 * receive interrupt (producer) and the main loop (consumer).
 *
 * The caller gives the storage; its capacity must be a power of two
 * (1 .. 2^31 bytes) so that positions are free-running 32-bit counters
 * reduced with a mask: head - tail is the fill level even after the
 * counters wrap, and all `cap` bytes are usable (no empty slot).
 * A byte that arrives while the ring is full is dropped and counted in the
 * overflow counter: it is never silently lost, and the counter is never
 * reset (compare two readings to get the losses in between).
 *
 * WHO MAY CALL WHAT
 *   producer (the RX interrupt, exactly one context):  tase_ring_put()
 *   consumer (the main loop, exactly one context):     tase_ring_get()
 *   either side, any time:  tase_ring_count(), tase_ring_overflows()
 *   before interrupts are enabled (neither side running): tase_ring_init()
 * Several producers (two ISRs of different priorities feeding one ring)
 * or several consumers are NOT supported: give each its own ring or add a
 * lock.
 *
 * WHY IT NEEDS NO LOCK ON A SINGLE-CORE CORTEX-M
 *  - Each field has one writer: the producer writes `head`, `overflow` and
 *    the free slots; the consumer writes `tail`. Nobody performs a
 *    read-modify-write of a field the other side writes.
 *  - Aligned 32-bit loads and stores (LDR/STR) are single-copy atomic on
 *    every Cortex-M, so the other side sees an index either before or
 *    after an update, never torn. (An 8- or 16-bit MCU cannot load a
 *    32-bit index atomically: there, mask the RX interrupt around the
 *    consumer's read of `head`, or narrow the indices.)
 *  - Publication order: the producer stores the byte into its slot FIRST
 *    and only then stores the new `head`; the consumer reads `head`, then
 *    the bytes below it, and only then stores the new `tail` that frees
 *    their slots. An interrupt can preempt the consumer anywhere: it only
 *    writes slots at or above the `head` the consumer has not yet seen
 *    and below `tail + cap`, which the consumer is not reading.
 *  - The order must survive the compiler. C99 has no atomics and no
 *    fences; what it does guarantee is that accesses to volatile objects
 *    are performed in program order (C99 5.1.2.3). Both indices AND the
 *    data slots are accessed through volatile lvalues here, so the
 *    compiler may not sink the data store below the index store, nor
 *    hoist the data load above the index load.
 *  - The core observes its own accesses in program order, and the ISR
 *    runs on the same core as the main loop, so no hardware barrier is
 *    needed; Cortex-M0/M0+/M3/M4 also have no cache and do not reorder
 *    normal memory accesses observably to themselves.
 *
 * WHEN A BARRIER IS NEEDED, AND THE HOOK
 * If the two sides run on DIFFERENT cores (dual-core parts such as an
 * STM32H7's M7 + M4, a host test with threads) or the ring is written by
 * another bus master, volatile is not enough: the hardware may make the
 * `head` store visible to the other core before the data store (Cortex-M7
 * write buffers, caches, ARMv8-A weak ordering). Define the port hook
 *     TASE_RING_BARRIER()
 * before compiling tase_ring.c (e.g. -D'TASE_RING_BARRIER()=__DMB()' with
 * CMSIS, or a C11 atomic_thread_fence(memory_order_seq_cst)), on the
 * command line, in the library's configuration header (TASE_CONFIG_HEADER,
 * tase/config.h) or in a header named by -DTASE_RING_CONFIG='"file.h"'
 * that tase_ring.c includes after tase/ring.h (so after the configuration
 * header, whose definition the hosted build's own header leaves alone).
 * The ring
 * calls it between writing data and publishing `head`, between reading
 * `head` and reading data, between reading data and publishing `tail`, and
 * between reading `tail` and overwriting a slot. Its default is empty,
 * correct for the single-core case above and free of compiler extensions.
 * With caches and DMA, the ring memory must also be non-cacheable or
 * maintained by the port (not the ring's business). The hosted build in
 * this repository defines the hook as a sequentially consistent fence (in
 * tase_ring_host_config.h, unless the configuration header defined it)
 * because its test runs the producer on another CPU core.
 *
 * COST: put is O(1) (a few loads/stores: ISR-friendly); get is O(n).
 */
#ifndef TASE_RING_H
#define TASE_RING_H

#include "tase/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Ring instance. Fields are private; read them only through the
 * functions below. */
typedef struct {
    volatile uint8_t *buf;
    uint32_t mask;              /* capacity - 1; constant after init */
    volatile uint32_t head;     /* bytes ever written; producer's */
    volatile uint32_t tail;     /* bytes ever read; consumer's */
    volatile uint32_t overflow; /* bytes dropped while full; producer's */
} tase_ring_t;

/* Attach storage buf[0..cap). cap must be a power of two in 1..2^31.
 * Empties the ring and zeroes the overflow counter. Call while neither
 * side runs. Returns TASE_OK or TASE_EARG (r or buf NULL, cap not a power
 * of two or too large). O(1). */
int tase_ring_init(tase_ring_t *r, uint8_t *buf, size_t cap);

/* PRODUCER ONLY (the RX ISR). Append one byte. Returns true if stored,
 * false if the ring was full (the byte is dropped and counted) or r is
 * NULL or has no storage (never initialised; nothing changes). Other
 * corruption is not checked: this is the ISR fast path. O(1), ISR-safe,
 * lock-free, wait-free. */
bool tase_ring_put(tase_ring_t *r, uint8_t byte);

/* CONSUMER ONLY (the main loop). Move up to cap bytes, oldest first, into
 * out. Returns the number moved (0 when empty, cap 0, r/out NULL or r
 * without storage; nothing changes then).
 * O(returned). Lock-free; safe while the producer interrupts it. */
size_t tase_ring_get(tase_ring_t *r, uint8_t *out, size_t cap);

/* Bytes currently held (a snapshot: the producer may add more at any
 * moment, the consumer may take some). 0 for NULL. Either side. O(1). */
uint32_t tase_ring_count(const tase_ring_t *r);

/* Bytes dropped because the ring was full, since init, modulo 2^32.
 * 0 for NULL. Either side. O(1). */
uint32_t tase_ring_overflows(const tase_ring_t *r);

/* Capacity in bytes (0 for NULL). O(1). */
uint32_t tase_ring_capacity(const tase_ring_t *r);

#ifdef __cplusplus
}
#endif

#endif /* TASE_RING_H */
