/* tase: talk to a TASE gimbal (or tase-sim) and decode captures. This
 * file holds the command table and the usage texts; the commands are in
 * the files tase_cli.h lists. Usage and the JSON contract: docs/TOOLS.md,
 * or `tase --help`. */
#include <string.h>

#include "tase_cli.h"

static const char usage_exit[] =
    "exit status: 0 success; 1 failure (device, I/O, timeout, writing the output;\n"
    "  \"(NAME was sent)\" ends the line if the packet went out before);\n"
    "  2 bad command line (nothing was sent); 3 the gimbal's echo differs from the\n"
    "  setting sent; 4 input not fully understood (bad candump lines, no packet\n"
    "  found); 5 the packet was sent, but writing the output failed (do not send it\n"
    "  again); 128+N interrupted by signal N (141: the output's reader went away).\n";

static const char usage_link[] =
    "link options:\n"
    "  --serial DEV   serial device or pty (e.g. /dev/ttyUSB0, the path tase-sim prints)\n"
    "  --baud N       serial rate, default 57600\n"
    "  --can IFACE    CAN interface instead of a serial device (e.g. can0)\n"
    "  --record FILE  also record the session's bytes, both directions, to the pcap\n"
    "                 capture FILE (appended to; serial links only: on CAN run\n"
    "                 'tase record --can IFACE' beside it)\n";

static const char usage_req[] =
    "request options (when an answer is awaited):\n"
    "  --timeout MS   wait per attempt, default " TK_STR(
        CLI_DEFAULT_TIMEOUT_MS) " ms\n"
                                "  --retries N    attempts after the first, default " TK_STR(
                                    CLI_DEFAULT_RETRIES) "\n"
                                                         "  --json         print JSON lines (what "
                                                         "was sent "
                                                         "\"dir\":\"in\", the answer \"out\"; "
                                                         "query: the answer only)\n";

static const char usage_point[] =
    "usage: tase point PAN TILT [--stab on|off] LINK [--json]\n"
    "Position command (GIMBAL_CMD flags 0xA0, or 0x20 with --stab off): turn to pan\n"
    "PAN degrees (-180..180) and tilt TILT degrees (-270..90, the spec's range;\n"
    "both sent in 1/100 deg). Stabilisation is on unless --stab off. Prints what\n"
    "it sent. Negative numbers need no '--'.\n";

static const char usage_rate[] =
    "usage: tase rate PAN_RATE TILT_RATE [--stab on|off] LINK [--json]\n"
    "Rate command (GIMBAL_CMD flags 0x90, or 0x10 with --stab off): turn at the\n"
    "given degrees per second (-327.68..327.67; sent in 1/100 deg/s) until the next\n"
    "command. 'tase rate 0 0' stops. Prints what it sent.\n";

static const char usage_camera[] =
    "usage: tase camera [A|B|C] [--hfov DEG | --zoom X] LINK [--json] [request options]\n"
    "CAMERA_CMD. A camera alone selects it (the 1-byte form: nothing else changes).\n"
    "--hfov DEG sets the horizontal field of view (0.01..327.67 deg), --zoom X the\n"
    "zoom ratio (1..327.68); every other camera setting is sent as \"do not change\"\n"
    "(and the active camera too, unless one is named). Prints what it sent.\n"
    "CAMERA_CMD has no echo: a named camera is first looked up in the gimbal's\n"
    "SYSTEM_VERSION, and one the gimbal does not have (type 0xFF) is refused with\n"
    "nothing sent (exit 1).\n";

static const char usage_gyro[] = "usage: tase gyro-zero LINK [--json]\n"
                                 "GYRO_ZERO_CMD: the gimbal zeroes its rate gyros. Send it only "
                                 "while the\ngimbal is not moving.\n";

static const char usage_deploy[] =
    "usage: tase deploy|retract LINK [--wait S] [--json]\n"
    "RETRACT_DEPLOY_CMD (deploy 1 or 0). The gimbal echoes it when the move is\n"
    "complete: --wait S waits up to S seconds for that echo (exit 1 if it does not\n"
    "come).\n";

static const char usage_spoi[] =
    "usage: tase spoi LAT LON HEIGHT LINK [--no-wait] [--json] [request options]\n"
    "SPOI_CMD: point at latitude LAT, longitude LON (degrees, WGS-84; sent in\n"
    "milli-arcseconds) and HEIGHT metres above the ellipsoid (sent in cm), not\n"
    "moving. The echo is requested and awaited (--no-wait: neither); exit 3 if the\n"
    "echoed position differs. The gimbal needs host GPS and attitude to use it.\n";

static const char usage_monitor[] =
    "usage: tase monitor LINK [--json] [--time] [--units] [--count N] [--seconds S]\n"
    "                    [--margin MS]\n"
    "Prints every packet received, one per line: readable text by default, one JSON\n"
    "object per line with --json. --time adds the host time of arrival (text:\n"
    "HH:MM:SS.mmm, JSON: \"time\" in Unix seconds); --units adds engineering units\n"
    "beside the raw fields (JSON: a top-level \"units\" object). Stops after N\n"
    "packets, S seconds, or on SIGINT/SIGTERM/SIGHUP (exit 0), and prints a summary\n"
    "line on stderr (frames, checksum errors, bad sizes, wrong lengths, unknown,\n"
    "bytes discarded; on CAN the bus state and error counts the port reports).\n"
    "A device that goes away or hangs up also stops it: the summary, then\n"
    "'cannot read DEV: the device went away or hung up' (exit 1). Bytes received\n"
    "but no frame found: the summary and a one-line hint (exit 4).\n"
    "On CAN, --time is the kernel's receive time of the frame. --margin MS: a\n"
    "candidate frame the line goes quiet on is judged false after at least MS\n"
    "(1..65535; default 20) as in 'tase decode', for a sender that pauses inside a\n"
    "packet (CAN frames sent one at a time, a loaded virtual machine).\n";

static const char usage_send[] =
    "usage: tase send NAME [field=value ...] LINK [--len N] [--zero] [--raw]\n"
    "                 [--no-wait] [--json] [--timeout MS] [--retries N]\n"
    "Sends packet NAME (an In or Both packet; see 'tase list') with raw wire integer\n"
    "field values: decimal (leading zeros are decimal), 0x hex, an optional sign; a\n"
    "signed field also takes its hex bit pattern (hfov=0xFFFF is -1). CAMERA_PASS\n"
    "takes data=1,2,... . Each field at most once. Fields left out:\n"
    "  - a field with a \"do not change\" value in the spec takes it (CAMERA_CMD,\n"
    "    AXIS_SETTING, CAMERA_TYPE, LEGACY_CAMERA_CMD focus and shutter_speed,\n"
    "    CAMERA_PASS baud);\n"
    "  - other fields of setup packets (group 0x48): the gimbal's current settings\n"
    "    are queried first and kept, and the packet is sent in the layout of the\n"
    "    answer (AXIS_SETTING: 22 or 23 bytes, so it is always queried first)\n"
    "    unless --len says otherwise;\n"
    "  - otherwise every field must be given (the error names the missing ones);\n"
    "  - --zero: fields left out without such a value are 0 instead.\n"
    "temporary (PACKET_RATE, AXIS_SETTING) left out is 1: the setting lasts until\n"
    "the gimbal is powered off. temporary=0 makes the gimbal write it to its\n"
    "non-volatile storage (spec 4.4.1, 4.4.3), where it survives power cycles.\n"
    "GIMBAL_CMD always needs flags (its mode; or use 'tase point' / 'tase rate').\n"
    "Setup packets are echoed by the gimbal: the echo is awaited, printed and\n"
    "compared with what was sent; a field that differs (a value the gimbal refused\n"
    "or changed) exits 3 naming it. --no-wait sends without waiting for anything\n"
    "(a setup packet then needs every field, or --zero). --len N sends a shorter\n"
    "accepted form (CAMERA_CMD --len 1: change camera only; AXIS_SETTING --len 22:\n"
    "the 22-byte layout). A flags field with a bit the spec reserves (\"set to\n"
    "zero\") set is refused, nothing sent: CAMERA_CMD 0x78, HOST_SENSOR 0x1F,\n"
    "HOST_ATTITUDE 0xFC, SPOI_CMD 0x7F (to the gimbal only bit 0, the echo\n"
    "request); --raw sends them as given, to test how a gimbal takes them.\n";

static const char usage_query[] =
    "usage: tase query NAME LINK [--json] [--timeout MS] [--retries N]\n"
    "Sends the zero-length query of NAME (a setup packet, SPOI_CMD or\n"
    "SYSTEM_VERSION), waits for the answer and prints it. Each attempt waits\n"
    "--timeout ms (default " TK_STR(CLI_DEFAULT_TIMEOUT_MS) "); --retries (default " TK_STR(
        CLI_DEFAULT_RETRIES) ") more attempts are made.\n";

static const char usage_decode[] =
    "usage: tase decode [FILE|-] [--candump] [--stats] [--baud N] [--margin MS]\n"
    "Decodes a capture of 'tase record' (pcap or pcapng; each object carries\n"
    "\"time\" and \"dir\"; a bad record is reported with its number, exit 4) or a\n"
    "raw serial byte capture (default: standard input; a live pty or\n"
    "pipe is read as bytes arrive) to one JSON object per valid packet, in stream\n"
    "order (contract: docs/TOOLS.md). With --candump the input is a candump log\n"
    "(candump -l or -L): frames of ID 10000000 (from the gimbal, \"dir\":\"out\") and\n"
    "11000000 (to the gimbal, \"dir\":\"in\") are reassembled per interface and\n"
    "direction, each object carrying \"time\", \"dir\" and \"interface\"; other IDs are\n"
    "ignored, blank and '#' lines skipped, a bad line reported with its number\n"
    "(the rest is still decoded; exit 4). --stats prints a summary line on stderr.\n"
    "When a non-empty input holds no packet, a one-line hint says why and the exit\n"
    "status is 4. A serial device (or pty) named as FILE is opened as the link\n"
    "commands open one: raw 8N1 at --baud N (default 57600), exclusively, its\n"
    "settings given back at exit; SIGINT/SIGTERM/SIGHUP end it (exit 0), a hang-up\n"
    "is an error (exit 1). As a live receiver does, a candidate frame the line\n"
    "went quiet on is judged false after its remaining bytes' time at the line's\n"
    "rate (a capture's: --baud; CAN: 1 Mbit/s), at least 20 ms (--margin MS: at\n"
    "least MS, 1..65535, for a sender that pauses inside a packet, such as CAN\n"
    "frames sent one at a time): on a device by the clock, in a capture or candump\n"
    "log by the gaps in the record times (a record time stepped back is no time).\n"
    "--stats counts the frames so cut short. A capture cut inside a record (a\n"
    "recorder killed, a copy of one still being written) is decoded up to the cut,\n"
    "then the cut is said (exit 1).\n";

static const char usage_klv[] =
    "usage: tase klv [FILE|-] [--baud N]\n"
    "Decodes a KLV metadata byte stream (the gimbal's 9600-baud KLV line; a live\n"
    "pty is read as bytes arrive) to one JSON object per valid packet:\n"
    "{\"offset\":N,\"fields\":{raw values in tag order},\"units\":{engineering values}}.\n"
    "Noise and damaged packets are skipped; a non-empty input without a packet is\n"
    "reported with a one-line hint (exit 4). A serial device (or pty) named as FILE\n"
    "is opened raw 8N1 at --baud N (default 9600, the KLV line), exclusively, its\n"
    "settings given back at exit; SIGINT/SIGTERM/SIGHUP end it (exit 0), a hang-up\n"
    "is an error (exit 1).\n";

static const char usage_record[] =
    "usage: tase record (--serial DEV [--tap-in DEV2] [--baud N] | --can IFACE) -o FILE\n"
    "                   [--seconds S]\n"
    "Records what arrives to the pcap capture FILE (replaced; - or a FIFO, device or\n"
    "symlink is written in place, - being standard output), with a timestamp per\n"
    "received chunk, until interrupted (Ctrl-C, SIGTERM, SIGHUP: exit 0) or S seconds\n"
    "have passed.\n"
    "  --serial DEV   one record per read, byte-exact, as sent by the gimbal\n"
    "                 (link type USER0 with a direction byte; docs/TOOLS.md)\n"
    "  --tap-in DEV2  a second device on the other line of a tap: its bytes are\n"
    "                 recorded as sent to the gimbal\n"
    "  --can IFACE    every frame on the bus, as SocketCAN records\n"
    "'tase decode FILE' decodes it; Wireshark reads it with the dissector tase.lua\n"
    "(tools/wireshark/ in the source, /usr/share/tase/ from the tase-tools package).\n";

static const char usage_replay[] =
    "usage: tase replay FILE (--serial DEV [--baud N] | --can IFACE) --dir out|in|all\n"
    "                   [--speed X]\n"
    "Sends the records of the pcap capture FILE with their recorded timing (divided\n"
    "by X, default 1; 0 sends without waiting). --dir is required (no default: a\n"
    "capture holds commands either way):\n"
    "  --dir out   the gimbal's side, to exercise a host; it holds the gimbal's\n"
    "              echoes of setup packets, RETRACT_DEPLOY_CMD and SPOI_CMD, which a\n"
    "              gimbal takes as commands: never replay it into a gimbal\n"
    "  --dir in    the host's side: the commands sent to the gimbal (moves a gimbal)\n"
    "  --dir all   both (moves a gimbal); on CAN every recorded frame, whatever its ID\n"
    "Serial bytes go to a CAN interface as frames of their direction's ID, and the\n"
    "datalink bytes of CAN frames to a serial device; CAN FD, remote and error\n"
    "frames are not sent. A capture with a bad record is refused before anything is\n"
    "sent (exit 4).\n";

static const char usage_list[] = "usage: tase list\nLists every packet: group, type, "
                                 "direction, data length and field names.\n";

/* ---- usage ---- */

void cli_print_usage(const cli_args_t *a)
{
    fputs(a->usage, stdout);
    if (a->extra & CLI_USAGE_LINK) {
        fputs(usage_link, stdout);
    }
    if (a->extra & CLI_USAGE_REQ) {
        fputs(usage_req, stdout);
    }
    fputs(usage_exit, stdout);
    tk_stdout_flush();
}

/* ---- main ---- */

typedef struct {
    const char *name;
    int (*run)(cli_args_t *);
    const char *usage;
    unsigned extra; /* CLI_USAGE_* */
    const char *summary;
} command_t;

/* One row per command: add a row to add a command. */
static const command_t commands[] = {
    {"point", cli_cmd_point, usage_point, CLI_USAGE_LINK, "point at pan/tilt angles (degrees)"},
    {"rate", cli_cmd_rate, usage_rate, CLI_USAGE_LINK,
     "turn at pan/tilt rates (degrees per second)"},
    {"camera", cli_cmd_camera, usage_camera, CLI_USAGE_LINK | CLI_USAGE_REQ,
     "select a camera, set its HFOV or zoom"},
    {"gyro-zero", cli_cmd_gyro_zero, usage_gyro, CLI_USAGE_LINK, "zero the gimbal's rate gyros"},
    {"deploy", cli_cmd_deploy, usage_deploy, CLI_USAGE_LINK, "deploy the retract/deploy mechanism"},
    {"retract", cli_cmd_retract, usage_deploy, CLI_USAGE_LINK, "retract it"},
    {"spoi", cli_cmd_spoi, usage_spoi, CLI_USAGE_LINK | CLI_USAGE_REQ,
     "point at a location (latitude, longitude, height)"},
    {"send", cli_cmd_send, usage_send, CLI_USAGE_LINK | CLI_USAGE_REQ,
     "send any In packet, fields as raw wire integers"},
    {"query", cli_cmd_query, usage_query, CLI_USAGE_LINK | CLI_USAGE_REQ,
     "ask for a setup packet, SPOI_CMD or SYSTEM_VERSION"},
    {"monitor", cli_cmd_monitor, usage_monitor, CLI_USAGE_LINK,
     "print the packets a live link receives"},
    {"decode", cli_cmd_decode, usage_decode, 0,
     "decode a capture (pcap, raw bytes, candump log) to JSON"},
    {"klv", cli_cmd_klv, usage_klv, 0, "decode a KLV metadata byte stream to JSON"},
    {"record", cli_cmd_record, usage_record, 0,
     "record a serial line or CAN bus to a pcap capture"},
    {"replay", cli_cmd_replay, usage_replay, 0, "send a capture back with its recorded timing"},
    {"list", cli_cmd_list, usage_list, 0, "list the packets and their field names"},
};

#define NCOMMANDS (sizeof(commands) / sizeof(commands[0]))

static void main_usage(void)
{
    size_t i;
    printf("usage: tase <command> [options]   (tase help <command>, tase <command> --help)\n"
           "commands:\n");
    for (i = 0; i < NCOMMANDS; i++) {
        printf("  %-10s %s\n", commands[i].name, commands[i].summary);
    }
    printf("LINK is --serial DEV [--baud N] or --can IFACE. Angles are degrees, values of\n"
           "'send' raw wire integers. tase --version prints the version.\n");
    fputs(usage_exit, stdout);
    tk_stdout_flush();
}

static const command_t *find_command(const char *name)
{
    size_t i;
    for (i = 0; i < NCOMMANDS; i++) {
        if (strcmp(name, commands[i].name) == 0) {
            return &commands[i];
        }
    }
    tk_usage_error("unknown command '%s' (try 'tase --help')", name);
    return NULL;
}

int main(int argc, char **argv)
{
    const command_t *c;
    cli_args_t a;
    tk_std_fds_open(); /* before anything opens a file */
    tk_prog = "tase";
    tk_catch_signals();
    if (argc < 2) {
        tk_usage_error("no command given (try 'tase --help')");
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        (strcmp(argv[1], "help") == 0 && argc == 2)) {
        main_usage();
        return TK_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0) {
        printf("tase %s\n", TASE_VERSION_STRING);
        tk_stdout_flush();
        return TK_EXIT_OK;
    }
    memset(&a, 0, sizeof(a));
    a.argc = argc;
    a.argv = argv;
    if (strcmp(argv[1], "help") == 0) {
        if (argc > 3) {
            tk_usage_error("help takes one command name");
        }
        c = find_command(argv[2]);
        a.usage = c->usage;
        a.extra = c->extra;
        cli_print_usage(&a);
        return TK_EXIT_OK;
    }
    c = find_command(argv[1]);
    a.i = 2;
    a.usage = c->usage;
    a.extra = c->extra;
    return c->run(&a);
}
