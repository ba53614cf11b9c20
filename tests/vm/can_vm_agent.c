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
 *   agent gimbal IF gimbal MS        the library's gimbal role on IF for MS
 *                                    ms (answers setup queries, telemetry
 *                                    at the default rates); prints READY
 *   agent query IF host              host-role PACKET_RATE queries (typed,
 *                                    500 ms, 2 retries) under a SIGALRM
 *                                    every millisecond, until 300 signals
 *                                    came (at least 20 queries); prints
 *                                    "QUERY rc=.. ok=.. alarms=.. .."
 *   agent fill IF host               GIMBAL_CMDs as host until the transmit
 *                                    queue refuses one; prints "FULL rc=..
 *                                    ms=.. sent=.. enobufs=.." (ms: that
 *                                    last call)
 *   agent health IF host COUNT MS    read as host until COUNT error frames
 *                                    came or MS passed; prints READY, then
 *                                    "BUS state=.. errors=.. ..."
 *   agent downread IF host           prints READY, reads 5 of the 8 bytes of
 *                                    a frame, takes IF down (ip link), reads
 *                                    twice more: "DOWNREAD r1=.. r2=.. r3=..
 *                                    errno=.." (the kernel says ENETDOWN once)
 *   agent gone IF host               deletes IF (ip link), then reads and
 *                                    writes: "GONE read=.. write=.. errno=.."
 */
#define _DEFAULT_SOURCE 1
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/time.h>
#include <time.h>

#include "tase/candump.h"
#include "tase/codec.h"
#include "tase/gimbal.h"
#include "tase/host.h"
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
        n = tase_frame_build(0x08, 0x10, angle, sizeof(angle), wire, sizeof(wire));
    } else if (strcmp(what, "max") == 0) {
        for (i = 0; i < sizeof(data); i++) {
            data[i] = (uint8_t)(i * 3u + 7u);
        }
        n = tase_frame_build(0x00, 0x42, data, sizeof(data), wire, sizeof(wire));
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

static int do_gimbal(tase_socketcan_t *s, uint32_t ms)
{
    static tase_gimbal_t g;
    static tase_rx_t rx;
    tase_port_t port = tase_socketcan_port(s);
    uint32_t t0 = tase_socketcan_now_ms(NULL);
    struct timespec tick = {0, 1000000L};
    if (tase_gimbal_init(&g, &port, &rx, 1, NULL, t0) != TASE_OK) {
        return 1;
    }
    printf("READY\n");
    fflush(stdout);
    while (tase_socketcan_now_ms(NULL) - t0 < ms) {
        (void)tase_gimbal_service(&g, tase_socketcan_now_ms(NULL));
        (void)nanosleep(&tick, NULL);
    }
    printf("GIMBAL queries=%lu tx_errors=%lu\n", (unsigned long)g.stats.setup_queries,
           (unsigned long)g.stats.tx_errors);
    return 0;
}

static volatile sig_atomic_t alarms;

static void on_alarm(int sig)
{
    (void)sig;
    alarms++;
}

/* A SIGALRM every millisecond, without SA_RESTART: every wait of the
 * query is interrupted many times over. */
static int do_query(tase_socketcan_t *s)
{
    static tase_host_t h;
    tase_port_t port = tase_socketcan_port(s);
    tase_packet_rate_t pr;
    struct sigaction sa;
    struct itimerval it;
    int rc = TASE_ESTATE;
    int n;
    int ok = 0;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigemptyset(&sa.sa_mask);
    memset(&it, 0, sizeof it);
    it.it_interval.tv_usec = 1000;
    it.it_value.tv_usec = 1000;
    if (tase_host_init(&h, &port, NULL, NULL) != TASE_OK || sigaction(SIGALRM, &sa, NULL) != 0 ||
        setitimer(ITIMER_REAL, &it, NULL) != 0) {
        return 1;
    }
    /* Queries back to back until a few hundred signals have hit them. */
    for (n = 0; n < 1000 && (n < 20 || alarms < 300); n++) {
        memset(&pr, 0, sizeof pr);
        rc = tase_host_transact_msg(&h, TASE_ID_PACKET_RATE, NULL, &pr, 500, 2);
        if (rc != 16) {
            break;
        }
        ok++;
    }
    memset(&it, 0, sizeof it);
    (void)setitimer(ITIMER_REAL, &it, NULL);
    printf("QUERY rc=%d ok=%d alarms=%d angle_1=%u retries=%lu errno=%d\n", rc, ok, (int)alarms,
           pr.angle_1, (unsigned long)h.stats.retries, s->stats.last_errno);
    return rc == 16 ? 0 : 1;
}

static int do_fill(tase_socketcan_t *s)
{
    static tase_host_t h;
    tase_port_t port = tase_socketcan_port(s);
    tase_gimbal_cmd_t cmd = {1000, -500, 0, 0, 0};
    tase_socketcan_bus_t b;
    int sent = 0;
    int rc = 0;
    uint32_t ms = 0;
    if (tase_host_init(&h, &port, NULL, NULL) != TASE_OK) {
        return 1;
    }
    while (sent < 100000) {
        uint32_t t0 = tase_socketcan_now_ms(NULL);
        rc = tase_host_send_msg(&h, TASE_ID_GIMBAL_CMD, &cmd);
        ms = tase_socketcan_now_ms(NULL) - t0;
        if (rc < 0) {
            break;
        }
        sent++;
    }
    (void)tase_socketcan_bus(s, &b);
    printf("FULL rc=%d ms=%lu sent=%d enobufs=%lu (%s)\n", rc, (unsigned long)ms, sent,
           (unsigned long)b.enobufs, tase_strerror(rc));
    return 0;
}

static int do_health(tase_socketcan_t *s, uint32_t count, uint32_t ms)
{
    tase_socketcan_bus_t b;
    uint8_t buf[64];
    uint32_t t0 = tase_socketcan_now_ms(NULL);
    printf("READY\n");
    fflush(stdout);
    do {
        if (tase_socketcan_read(s, buf, sizeof buf, 20) < 0) {
            return 1;
        }
        (void)tase_socketcan_bus(s, &b);
    } while (b.error_frames < count && tase_socketcan_now_ms(NULL) - t0 < ms);
    printf("BUS state=%u errors=%lu bus_offs=%lu passives=%lu restarts=%lu no_acks=%lu "
           "tec=%u rec=%u bad=%lu\n",
           b.state, (unsigned long)b.error_frames, (unsigned long)b.bus_offs,
           (unsigned long)b.passives, (unsigned long)b.restarts, (unsigned long)b.no_acks,
           b.tx_error_count, b.rx_error_count, (unsigned long)s->stats.bad_frames);
    return 0;
}

/* `ip link ARGS` through the VM's shell; false when it failed. */
static bool ip_link(const char *args)
{
    char cmd[128];
    int n = snprintf(cmd, sizeof cmd, "ip link %s", args);
    return n > 0 && (size_t)n < sizeof cmd && system(cmd) == 0;
}

static int do_downread(tase_socketcan_t *s, const char *ifname)
{
    uint8_t buf[5];
    char args[64];
    int r1, r2, r3;
    printf("READY\n");
    fflush(stdout);
    r1 = tase_socketcan_read(s, buf, sizeof buf, 5000);
    (void)snprintf(args, sizeof args, "set %s down", ifname);
    if (!ip_link(args)) {
        return 1;
    }
    r2 = tase_socketcan_read(s, buf, sizeof buf, 500);
    r3 = tase_socketcan_read(s, buf, sizeof buf, 500);
    printf("DOWNREAD r1=%d r2=%d r3=%d errno=%d\n", r1, r2, r3, s->stats.last_errno);
    return 0;
}

static int do_gone(tase_socketcan_t *s, const char *ifname)
{
    static const uint8_t bytes[3] = {0x00, 0xFF, 0x5A};
    uint8_t buf[8];
    char args[64];
    int r, w;
    (void)snprintf(args, sizeof args, "del %s", ifname);
    if (!ip_link(args)) {
        return 1;
    }
    r = tase_socketcan_read(s, buf, sizeof buf, 500);
    w = tase_socketcan_write(s, bytes, sizeof bytes);
    printf("GONE read=%d write=%d errno=%d\n", r, w, s->stats.last_errno);
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
    } else if (strcmp(argv[1], "gimbal") == 0 && argc == 5) {
        rc = do_gimbal(&s, (uint32_t)strtoul(argv[4], NULL, 10));
    } else if (strcmp(argv[1], "query") == 0 && argc == 4) {
        rc = do_query(&s);
    } else if (strcmp(argv[1], "fill") == 0 && argc == 4) {
        rc = do_fill(&s);
    } else if (strcmp(argv[1], "downread") == 0 && argc == 4) {
        rc = do_downread(&s, argv[2]);
    } else if (strcmp(argv[1], "gone") == 0 && argc == 4) {
        rc = do_gone(&s, argv[2]);
    } else if (strcmp(argv[1], "health") == 0 && argc == 6) {
        rc = do_health(&s, (uint32_t)strtoul(argv[4], NULL, 10),
                       (uint32_t)strtoul(argv[5], NULL, 10));
    } else {
        rc = 2;
    }
    tase_socketcan_close(&s);
    return rc;
}
