/*
 * fuzz/fuzz.h - helpers shared by the libFuzzer harnesses in fuzz/.
 *
 * Every harness is one file fuzz/<name>.c that defines
 * LLVMFuzzerTestOneInput() and nothing else global. It is built two ways:
 *   - by scripts/checks/fuzz.sh with clang -fsanitize=fuzzer,address,undefined
 *     (the bounded fuzz run, tests/checks/fuzz.cmake);
 *   - with fuzz/replay_main.c by any C compiler, to replay a corpus (the
 *     fuzz_replay_<name> tests and scripts/checks/sanitize.sh).
 * A harness reports a broken invariant with FZ_CHECK, which aborts: the
 * fuzzer then saves the input as a crash artifact.
 */
#ifndef TASE_FUZZ_H
#define TASE_FUZZ_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FZ_CHECK(cond)                                                                             \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "%s:%d: invariant broken: %s\n", __FILE__, __LINE__, #cond);           \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* Sequential reader over the fuzz input; reads past the end give 0 so a
 * harness never has to bail out half way through building its scenario. */
typedef struct {
    const uint8_t *p;
    size_t n;
} fz_in_t;

static inline int fz_more(const fz_in_t *in)
{
    return in->n > 0u;
}

static inline uint8_t fz_u8(fz_in_t *in)
{
    uint8_t b = 0;
    if (in->n > 0u) {
        b = in->p[0];
        in->p++;
        in->n--;
    }
    return b;
}

static inline uint16_t fz_u16(fz_in_t *in)
{
    uint16_t hi = fz_u8(in);
    return (uint16_t)((hi << 8) | fz_u8(in));
}

/* xorshift32 for derived choices (split points); never seeded with 0. */
static inline uint32_t fz_rand(uint32_t *s)
{
    uint32_t x = (*s != 0u) ? *s : 0x9E3779B9u;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    *s = x;
    return x;
}

#endif /* TASE_FUZZ_H */
