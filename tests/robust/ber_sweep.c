/*
 * Bit-error sweep: a long stream of valid packets (telemetry-like mix)
 * through a noisy channel (random bit flips, dropped bytes, inserted
 * bytes) into the receiver, fed in random chunks.
 *
 *   ber_sweep [--packets N] [--seed S] [--markdown] [--check]
 *
 * For each channel it counts packets delivered, lost (their own bytes
 * touched vs untouched) and false packets accepted (delivered frames that
 * are not a transmitted packet at that offset). --check (the ctest test)
 * fails unless:
 *   - no untouched packet is lost, and each is delivered within the
 *     documented latency bound (no stall);
 *   - no packet hit by exactly one bit flip outside its Size byte is
 *     accepted (an additive sum detects every single-bit error);
 *   - every accepted corrupted packet with intact framing really does
 *     satisfy the checksum (the receiver accepted nothing the sum rejects);
 *   - misframed false frames stay within 4x + 3 of the expectation
 *     (candidates that reached a checksum test / 65536).
 * --markdown prints the table of docs/ROBUSTNESS.md (bench/ber-sweep.sh).
 */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tase/frame.h"

typedef struct {
    uint32_t start;     /* in the transmitted stream */
    uint32_t out_start; /* in the received stream; UINT32_MAX if first byte dropped */
    uint16_t len;
    uint8_t flips;    /* bit flips in its bytes */
    uint8_t size_hit; /* a flip hit its Size byte (or sync: framing) */
    uint8_t moved;    /* a byte of it dropped, or one inserted inside it */
    uint8_t outcome;  /* OUT_* */
} pkt_t;

enum { OUT_LOST, OUT_CLEAN, OUT_INTACT, OUT_COLLISION };

typedef struct {
    uint32_t offset, len, seen_at;
} got_t;

typedef struct {
    const char *name;
    double flip; /* per bit */
    double drop; /* per byte */
    double ins;  /* per byte */
} channel_t;

static const channel_t channels[] = {
    {"bit flips 1e-5", 1e-5, 0, 0},
    {"bit flips 1e-4", 1e-4, 0, 0},
    {"bit flips 1e-3", 1e-3, 0, 0},
    {"bit flips 1e-2", 1e-2, 0, 0},
    {"dropped bytes 1e-4", 0, 1e-4, 0},
    {"dropped bytes 1e-3", 0, 1e-3, 0},
    {"inserted bytes 1e-4", 0, 0, 1e-4},
    {"inserted bytes 1e-3", 0, 0, 1e-3},
    {"flips 1e-3 + drop 1e-4 + insert 1e-4", 1e-3, 1e-4, 1e-4},
};

static uint64_t rng = 88172645463325252ull;

static uint64_t rnd64(void)
{
    /* xorshift64*: good enough statistics for a channel model */
    rng ^= rng >> 12;
    rng ^= rng << 25;
    rng ^= rng >> 27;
    return rng * 2685821657736338717ull;
}

static double unit(void)
{
    return ((double)(rnd64() >> 11) + 0.5) / 9007199254740992.0;
}

/* Gap to the next event of a Bernoulli(p) process (geometric). */
static uint64_t gap(double p)
{
    if (p <= 0.0) {
        return UINT64_MAX / 2u;
    }
    return (uint64_t)floor(log(unit()) / log1p(-p));
}

static tase_rx_t rx;
static got_t *got;
static size_t ngot, got_cap;
static got_t *falses; /* accepted frames other than clean packets, by offset */

static void on_frame(void *user, const tase_frame_t *f)
{
    (void)user;
    if (ngot == got_cap) {
        got_cap = got_cap ? got_cap * 2u : 4096u;
        got = realloc(got, got_cap * sizeof(*got));
        if (got == NULL) {
            abort();
        }
    }
    got[ngot].offset = f->offset;
    got[ngot].len = (uint32_t)f->len + TASE_FRAME_OVERHEAD;
    got[ngot].seen_at = rx.stats.bytes_in;
    ngot++;
}

static int cmp_got(const void *a, const void *b)
{
    const got_t *x = a, *y = b;
    return (x->offset > y->offset) - (x->offset < y->offset);
}

/* One telemetry-like packet: mostly angles and rates, some GPS/sensor,
 * occasional camera pass-through and setup echoes. */
static size_t make_packet(uint8_t *out)
{
    uint8_t data[TASE_DATA_MAX];
    uint32_t r = (uint32_t)(rnd64() % 100u);
    uint8_t group, type;
    size_t len, i;
    if (r < 40) {
        group = 0x08, type = 0x10, len = 6; /* GIMBAL_ANGLE */
    } else if (r < 70) {
        group = 0x08, type = 0x40, len = 18; /* GIMBAL_RATE */
    } else if (r < 85) {
        group = 0x08, type = 0x41, len = 24; /* HOST_SENSOR's id (its packet: 20 bytes) */
    } else if (r < 93) {
        group = 0x10, type = 0x10, len = 30; /* HOST_GPS_DATA's id (32: framing only) */
    } else if (r < 98) {
        group = 0x00, type = 0x42, len = (size_t)(rnd64() % 64u); /* CAMERA_PASS */
    } else {
        group = 0x48, type = 0x03, len = 0; /* SYSTEM_VERSION query */
    }
    for (i = 0; i < len; i++) {
        data[i] = (uint8_t)rnd64();
    }
    return (size_t)tase_frame_build(group, type, data, len, out, TASE_FRAME_MAX);
}

typedef struct {
    size_t packets, touched, delivered, lost_touched, lost_untouched;
    size_t false_collision, false_misframed;
    size_t single_flip, single_flip_accepted, size_flip, two_flip, two_flip_accepted;
    size_t intact;            /* touched, yet delivered byte-identical */
    size_t lost_behind_false; /* untouched, under an accepted false frame */
    size_t late, predicted_collisions;
    double expected_misframed;
    double seconds;
    int failures;
} result_t;

#define FAIL(res, ...)                                                                             \
    do {                                                                                           \
        fprintf(stderr, __VA_ARGS__);                                                              \
        fputc('\n', stderr);                                                                       \
        (res)->failures++;                                                                         \
    } while (0)

static void run(const channel_t *ch, size_t npk, result_t *res)
{
    size_t cap = npk * TASE_FRAME_MAX / 4u + TASE_FRAME_MAX, n = 0, k, o = 0, g, pos, nfalse;
    uint8_t *tx = malloc(cap), *out = malloc(cap + cap / 8u + 64u);
    pkt_t *p = calloc(npk, sizeof(*p));
    uint64_t next_flip, next_drop, next_ins, bit = 0;
    struct timespec t0, t1;
    if (tx == NULL || out == NULL || p == NULL) {
        abort();
    }
    memset(res, 0, sizeof(*res));
    for (k = 0; k < npk; k++) {
        if (n + TASE_FRAME_MAX > cap) {
            npk = k;
            break;
        }
        p[k].start = (uint32_t)n;
        p[k].len = (uint16_t)make_packet(tx + n);
        n += p[k].len;
    }
    res->packets = npk;

    /* the channel */
    next_flip = gap(ch->flip);
    next_drop = gap(ch->drop);
    next_ins = gap(ch->ins);
    for (k = 0; k < npk; k++) {
        size_t j;
        p[k].out_start = UINT32_MAX;
        for (j = 0; j < p[k].len; j++) {
            uint8_t b = tx[p[k].start + j];
            int b8;
            for (b8 = 0; b8 < 8; b8++, bit++) {
                if (bit == next_flip) {
                    b ^= (uint8_t)(1u << b8);
                    p[k].flips++;
                    if (j <= 3u) {
                        p[k].size_hit = 1; /* sync or Size: framing changed */
                    }
                    next_flip = bit + 1u + gap(ch->flip);
                }
            }
            if (next_drop == 0u) {
                p[k].moved = 1;
                next_drop = gap(ch->drop);
            } else {
                next_drop--;
                if (j == 0u) {
                    p[k].out_start = (uint32_t)o;
                }
                out[o++] = b;
            }
            if (next_ins == 0u) {
                out[o++] = (uint8_t)rnd64();
                if (j + 1u < p[k].len) {
                    p[k].moved = 1; /* inside the packet */
                }
                next_ins = gap(ch->ins);
            } else {
                next_ins--;
            }
        }
    }

    /* the receiver, fed in random chunks as from a UART driver */
    clock_gettime(CLOCK_MONOTONIC, &t0);
    tase_rx_init(&rx);
    ngot = 0;
    for (pos = 0; pos < o;) {
        size_t chunk = 1u + (size_t)(rnd64() % 512u);
        if (chunk > o - pos) {
            chunk = o - pos;
        }
        tase_rx_feed(&rx, out + pos, chunk, on_frame, NULL);
        pos += chunk;
    }
    tase_rx_flush(&rx, on_frame, NULL);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    res->seconds = (double)(t1.tv_sec - t0.tv_sec) + (double)(t1.tv_nsec - t0.tv_nsec) * 1e-9;
    if (rx.stats.bytes_in != (uint32_t)o || rx.stats.frames_ok != (uint32_t)ngot) {
        FAIL(res, "%s: counters disagree with the stream", ch->name);
    }

    /* classify: walk delivered frames and packets by received offset */
    qsort(got, ngot, sizeof(*got), cmp_got);
    falses = realloc(falses, (ngot + 1u) * sizeof(*falses));
    if (falses == NULL) {
        abort();
    }
    k = 0;
    nfalse = 0;
    for (g = 0; g < ngot; g++) {
        const got_t *d = &got[g];
        size_t m;
        while (k < npk && (p[k].out_start == UINT32_MAX || p[k].out_start < d->offset)) {
            k++;
        }
        if (k < npk && p[k].out_start == d->offset && p[k].flips == 0u && !p[k].moved &&
            d->len == p[k].len) {
            p[k].outcome = OUT_CLEAN;
            if (d->seen_at - (d->offset + d->len) > TASE_FRAME_MAX - 8u + TASE_RX_LATE_MAX) {
                FAIL(res, "%s: packet %zu delivered %u bytes late", ch->name, k,
                     (unsigned)(d->seen_at - (d->offset + d->len)));
            }
            if (d->seen_at != d->offset + d->len) {
                res->late++;
            }
            continue;
        }
        /* A touched packet can still arrive byte-identical, at or next to
         * its place: a dropped 00 sync replaced by a preceding 00, a byte
         * inserted between the checksum bytes equal to the one after it.
         * That is what was sent, not a false packet. */
        for (m = (k >= 3u ? k - 3u : 0u); m <= k && m < npk; m++) {
            if (p[m].len == d->len && p[m].outcome == OUT_LOST &&
                memcmp(out + d->offset, tx + p[m].start, d->len) == 0) {
                break;
            }
        }
        /* Either way this frame is not a clean packet at its place: its
         * bytes may include the first bytes of the next packet (a dropped
         * final 00 replaced by the next sync's 00), which then cannot be
         * delivered. Remember it as an excuse for such a loss. */
        falses[nfalse].offset = d->offset;
        falses[nfalse].len = d->len;
        nfalse++;
        if (m <= k && m < npk) {
            p[m].outcome = OUT_INTACT;
            continue;
        }
        if (k < npk && p[k].out_start == d->offset && !p[k].moved && !p[k].size_hit &&
            d->len == p[k].len) {
            p[k].outcome = OUT_COLLISION; /* flips that cancel in the sum */
            res->false_collision++;
            if (p[k].flips == 1u) {
                res->single_flip_accepted++;
            }
            if (p[k].flips == 2u) {
                res->two_flip_accepted++;
            }
        } else {
            res->false_misframed++;
        }
    }
    g = 0;
    for (k = 0; k < npk; k++) {
        const pkt_t *q = &p[k];
        if (q->flips != 0u || q->moved) {
            res->touched++;
            if (q->flips == 1u && !q->moved && !q->size_hit) {
                res->single_flip++;
            }
            if (q->flips == 2u && !q->moved && !q->size_hit) {
                res->two_flip++;
            }
            if (!q->moved && !q->size_hit && q->out_start != UINT32_MAX) {
                /* intact framing: the checksum alone decides */
                const uint8_t *b = out + q->out_start;
                uint16_t want = (uint16_t)((b[q->len - 2u] << 8) | b[q->len - 1u]);
                if (tase_checksum(0, b, q->len - 2u) == want) {
                    res->predicted_collisions++;
                }
            }
        }
        if (q->outcome == OUT_CLEAN || q->outcome == OUT_INTACT) {
            res->delivered++;
            res->intact += q->outcome == OUT_INTACT;
        } else if (q->outcome == OUT_LOST && (q->flips != 0u || q->moved)) {
            res->lost_touched++;
        } else if (q->outcome == OUT_LOST) {
            /* untouched and lost: only an accepted frame over its bytes that
             * is not a clean packet (false, or a touched packet that came
             * out byte-identical but longer into the stream) excuses that */
            while (g < nfalse && falses[g].offset + falses[g].len <= q->out_start) {
                g++;
            }
            if (g < nfalse && falses[g].offset < q->out_start + q->len) {
                res->lost_behind_false++;
            } else {
                res->lost_untouched++;
                if (res->lost_untouched <= 5u) {
                    FAIL(res, "%s: untouched packet %zu at received offset %u lost", ch->name, k,
                         (unsigned)q->out_start);
                }
            }
        }
    }
    res->expected_misframed = (double)rx.stats.checksum_errors / 65536.0;
    if (res->lost_untouched > 0u) {
        FAIL(res, "%s: %zu untouched packets lost (collateral loss)", ch->name,
             res->lost_untouched);
    }
    if (res->single_flip_accepted > 0u) {
        FAIL(res, "%s: %zu single-bit errors accepted", ch->name, res->single_flip_accepted);
    }
    if (res->false_collision > res->predicted_collisions) {
        FAIL(res, "%s: accepted %zu corrupted packets, the checksum passes only %zu", ch->name,
             res->false_collision, res->predicted_collisions);
    }
    if ((double)(res->false_misframed) > 4.0 * res->expected_misframed + 3.0) {
        FAIL(res, "%s: %zu misframed false frames, expected about %.2f", ch->name,
             res->false_misframed, res->expected_misframed);
    }
    free(tx);
    free(out);
    free(p);
}

int main(int argc, char **argv)
{
    size_t npk = 1000000, c;
    int markdown = 0, check = 0, i, failures = 0;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--packets") == 0 && i + 1 < argc) {
            npk = (size_t)strtoul(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            rng = strtoull(argv[++i], NULL, 10) | 1u;
        } else if (strcmp(argv[i], "--markdown") == 0) {
            markdown = 1;
        } else if (strcmp(argv[i], "--check") == 0) {
            check = 1;
        } else {
            fprintf(stderr, "usage: %s [--packets N] [--seed S] [--markdown] [--check]\n", argv[0]);
            return 2;
        }
    }
    if (markdown) {
        printf("| channel | packets | touched | delivered | lost: touched | lost: untouched | "
               "lost: untouched under an accepted frame | "
               "false accepted: checksum collision / misframed | expected misframed | "
               "single-bit errors (accepted) | two-bit errors (accepted) | late |\n");
        printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    }
    for (c = 0; c < sizeof(channels) / sizeof(channels[0]); c++) {
        result_t r;
        run(&channels[c], npk, &r);
        failures += r.failures;
        if (markdown) {
            printf("| %s | %zu | %zu | %zu | %zu | %zu | %zu | %zu / %zu | %.3f | %zu (%zu) | "
                   "%zu (%zu) | %zu |\n",
                   channels[c].name, r.packets, r.touched, r.delivered, r.lost_touched,
                   r.lost_untouched, r.lost_behind_false, r.false_collision, r.false_misframed,
                   r.expected_misframed, r.single_flip, r.single_flip_accepted, r.two_flip,
                   r.two_flip_accepted, r.late);
        } else {
            printf("%-38s %8zu pkts, %7zu touched, %8zu delivered, lost %zu touched + %zu "
                   "untouched + %zu under accepted frames, false %zu collision + %zu misframed "
                   "(exp %.3f; checksum "
                   "predicts %zu), %zu single-bit (%zu accepted), %zu two-bit (%zu accepted), "
                   "%zu intact, %zu late, %.0f MB/s\n",
                   channels[c].name, r.packets, r.touched, r.delivered, r.lost_touched,
                   r.lost_untouched, r.lost_behind_false, r.false_collision, r.false_misframed,
                   r.expected_misframed, r.predicted_collisions, r.single_flip,
                   r.single_flip_accepted, r.two_flip, r.two_flip_accepted, r.intact, r.late,
                   (double)rx.stats.bytes_in / 1e6 / (r.seconds > 0 ? r.seconds : 1e-9));
        }
    }
    free(got);
    free(falses);
    if (check && failures > 0) {
        fprintf(stderr, "ber_sweep: %d requirement(s) broken\n", failures);
        return 1;
    }
    return 0;
}
