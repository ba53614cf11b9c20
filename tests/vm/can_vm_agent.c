/* The project's side of the SocketCAN VM test (scripts/can-vm/): a small
 * program the VM's init script drives against vcan0 while can-utils'
 * candump and cansend play the independent peer. Built static.
 *
 *   agent open IF ROLE               print "open <code>" of tase_socketcan_open
 *   agent send IF ROLE WHAT          WHAT: angle | max | retract; prints the
 *                                    frames sent as "IF ID#DATA" lines
 *   agent recv IF ROLE COUNT MS      print "READY", then one line per packet
 *                                    ("PKT gg tt len HEX") or 3AX status
 *                                    ("3AX position=P speed_dps=S") until
 *                                    COUNT items; exit 1 on timeout
 *   agent reformat FILE              parse candump -L lines and print each
 *                                    formatted again (no timestamp change)
 */
#define _DEFAULT_SOURCE 1
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tase/candump.h"
#include "tase/socketcan.h"

static int role_of(const char *s, tase_can_role_t *role)
{
    if (strcmp(s, "host") == 0) {
        *role = TASE_CAN_ROLE_HOST;
    } else if (strcmp(s, "gimbal") == 0) {
        *role = TASE_CAN_ROLE_GIMBAL;
    } else {
        return -1;
    }
    return 0;
}

/* "IF ID#DATA" without the timestamp, as `cut -d' ' -f2-` leaves it. */
static void print_frame(const char *ifname, const tase_can_frame_t *f)
{
    tase_candump_rec_t r;
    char line[TASE_CANDUMP_LINE_MAX];
    memset(&r, 0, sizeof(r));
    snprintf(r.ifname, sizeof(r.ifname), "%s", ifname);
    r.frame = *f;
    if (tase_candump_format(&r, line, sizeof(line)) > 0) {
        fputs(strchr(line, ' ') + 1, stdout);
    }
}

static int send_what(const char *ifname, tase_socketcan_t *s, const char *what)
{
    uint8_t wire[TASE_FRAME_MAX];
    uint8_t data[TASE_DATA_MAX];
    tase_can_split_t sp;
    tase_can_frame_t f;
    tase_can_3ax_move_t m;
    int n = 0;
    size_t i;
    static const uint8_t angle[6] = {0x03, 0xE8, 0xFE, 0x0C, 0x00, 0x00};
    if (strcmp(what, "retract") == 0) {
        m.command = TASE_3AX_MOVE_RETRACT;
        if (tase_can_3ax_move_encode(&m, &f) != TASE_OK || tase_socketcan_send_frame(s, &f) != 0) {
            return 1;
        }
        print_frame(ifname, &f);
        return 0;
    }
    if (strcmp(what, "angle") == 0) {
        n = tase_frame_encode(wire, sizeof(wire), 0x08, 0x10, angle, sizeof(angle));
    } else if (strcmp(what, "max") == 0) {
        for (i = 0; i < sizeof(data); i++) {
            data[i] = (uint8_t)(i * 3u + 7u);
        }
        n = tase_frame_encode(wire, sizeof(wire), 0x00, 0x42, data, sizeof(data));
    }
    if (n <= 0 || tase_socketcan_write(s, wire, (size_t)n) != n) {
        return 1;
    }
    (void)tase_can_split_init(&sp, s->role, wire, (size_t)n);
    while (tase_can_split_next(&sp, &f) > 0) {
        print_frame(ifname, &f);
    }
    return 0;
}

typedef struct {
    int items;
} recv_state_t;

static void on_packet(void *user, const tase_frame_t *fr)
{
    recv_state_t *st = user;
    unsigned i;
    printf("PKT %02X %02X %u ", fr->group, fr->type, (unsigned)fr->len);
    for (i = 0; i < fr->len; i++) {
        printf("%02X", fr->data[i]);
    }
    printf("\n");
    st->items++;
}

static int do_recv(tase_socketcan_t *s, int count, uint32_t ms)
{
    tase_rx_t rx;
    recv_state_t st;
    tase_can_frame_t f;
    tase_can_3ax_status_t ax;
    uint8_t buf[64];
    uint32_t t0 = tase_socketcan_now_ms(NULL);
    int n;
    st.items = 0;
    tase_rx_init(&rx);
    printf("READY\n");
    fflush(stdout);
    while (st.items < count && tase_socketcan_now_ms(NULL) - t0 < ms) {
        n = tase_socketcan_read(s, buf, sizeof(buf), 50);
        if (n < 0) {
            printf("read error %d\n", n);
            return 1;
        }
        tase_rx_feed(&rx, buf, (size_t)n, on_packet, &st);
        while (tase_socketcan_recv_frame(s, &f, 0) == 1) {
            if (tase_can_3ax_status_decode(&f, &ax) == TASE_OK) {
                printf("3AX position=%u speed_dps=%d\n", ax.position, ax.speed_dps);
                st.items++;
            } else {
                /* a datalink frame: recv_frame hands out everything */
                n = tase_can_accept(s->role, &f);
                if (n > 0) {
                    tase_rx_feed(&rx, f.data, (size_t)n, on_packet, &st);
                }
            }
        }
        fflush(stdout);
    }
    printf("END items=%d checksum_errors=%lu ignored=%lu\n", st.items,
           (unsigned long)rx.stats.checksum_errors, (unsigned long)s->stats.frames_ignored);
    return st.items == count ? 0 : 1;
}

static int do_reformat(const char *path)
{
    char line[256];
    char out[TASE_CANDUMP_LINE_MAX];
    tase_candump_rec_t r;
    FILE *fp = fopen(path, "r");
    int rc;
    if (fp == NULL) {
        return 1;
    }
    while (fgets(line, sizeof(line), fp) != NULL) {
        rc = tase_candump_parse(line, strlen(line), &r);
        if (rc != TASE_OK || tase_candump_format(&r, out, sizeof(out)) < 0) {
            printf("PARSE-ERROR %d %s", rc, line);
            continue;
        }
        fputs(out, stdout);
    }
    fclose(fp);
    return 0;
}

int main(int argc, char **argv)
{
    tase_socketcan_t s;
    tase_can_role_t role;
    int rc;
    if (argc == 3 && strcmp(argv[1], "reformat") == 0) {
        return do_reformat(argv[2]);
    }
    if (argc < 4 || role_of(argv[3], &role) != 0) {
        fprintf(stderr, "usage: see the comment at the top of can_vm_agent.c\n");
        return 2;
    }
    rc = tase_socketcan_open(&s, argv[2], role);
    if (strcmp(argv[1], "open") == 0) {
        printf("open %d\n", rc);
        return 0;
    }
    if (rc != TASE_OK) {
        printf("open %s failed: %s\n", argv[2], tase_strerror(rc));
        return 1;
    }
    if (strcmp(argv[1], "send") == 0 && argc == 5) {
        rc = send_what(argv[2], &s, argv[4]);
    } else if (strcmp(argv[1], "recv") == 0 && argc == 6) {
        rc = do_recv(&s, atoi(argv[4]), (uint32_t)strtoul(argv[5], NULL, 10));
    } else {
        rc = 2;
    }
    tase_socketcan_close(&s);
    return rc;
}
