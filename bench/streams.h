/*
 * bench/streams.h - the deterministic byte streams of the receiver
 * benchmark (bench_rx.c on the host, m4/bench_m4.c on Cortex-M4 in QEMU):
 *
 *   telemetry  GIMBAL_ANGLE + GIMBAL_RATE at 10 Hz, GEOREFERENCE_DATA at
 *              4 Hz, back to back
 *   badsize    the same, every other frame's Size byte random
 *   sync4      00 FF 5A FF repeated (every sync claims 253 data bytes)
 *   syncrand   00 FF 5A then a random Size, repeated
 *   noise      uniformly random bytes
 *   zeros      0x00 repeated (every byte may start a sync)
 *   held255    00 FF 5A FF + 63 groups 00 FF 5A (255-4k), repeated: 64
 *              complete false candidates decided by one byte (issue 21)
 *   burst      00 FF 5A FF + 31 valid empty frames + 9 noise bytes,
 *              repeated: one byte releases 31 frames
 *   heldnoise  00 FF 5A FF + 257 noise bytes without a 00, repeated: the
 *              scan walks what the failed candidate was holding
 *   halfsum    60 noise bytes, 00 FF 5A FF + 64 syncs whose candidates
 *              end half-way through what is left: long sums per judged
 *              candidate (a review's worst case), repeated
 *   synclong   00 FF 5A then a Size of 0x5A..0x93 (about 9 in 100: 0xFF),
 *              repeated: the scan never catches up, long sums (found by
 *              a hill-climb: the worst sustained cost)
 */
#ifndef BENCH_STREAMS_H
#define BENCH_STREAMS_H

#include <stddef.h>
#include <stdint.h>

/* Fills buf[0..cap) with the named stream (whole frames only) and returns
 * its length, or 0 for an unknown name. The same bytes for a name and cap
 * on every call, whatever was generated before, on every run and every
 * target. */
size_t bench_stream(const char *name, uint8_t *buf, size_t cap);

#endif /* BENCH_STREAMS_H */
