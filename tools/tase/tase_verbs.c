/* tase: the bench verbs, each one packet built from engineering units:
 * point and rate (GIMBAL_CMD in a mode the verb states), camera, gyro-zero,
 * deploy and retract (RETRACT_DEPLOY_CMD, optionally awaiting the echo
 * that says the move is complete) and spoi. */
#include <string.h>

#include "tase/flags.h"
#include "tase/units.h"
#include "tase_cli.h"

/* ---- GIMBAL_CMD modes ---- */

static const struct {
    uint8_t flags;
    const char *what;
} gimbal_modes[] = {
    {TASE_GIMBAL_FLAGS_RATE, "rate"},
    {TASE_GIMBAL_FLAGS_RATE_STAB, "rate stabilised"},
    {TASE_GIMBAL_FLAGS_POSITION, "position"},
    {TASE_GIMBAL_FLAGS_POSITION_STAB, "position stabilised"},
    {TASE_GIMBAL_FLAGS_IMPULSE, "impulse"},
    {TASE_GIMBAL_FLAGS_IMPULSE_STAB, "impulse stabilised"},
    {TASE_GIMBAL_FLAGS_SPOI_ERROR, "SPOI error"},
    {TASE_GIMBAL_FLAGS_SPOI_ERROR_RATE, "SPOI error rate"},
    {TASE_GIMBAL_FLAGS_LEGACY_RATE, "legacy rate"},
    {TASE_GIMBAL_FLAGS_LEGACY_POSITION, "legacy position"},
    {TASE_GIMBAL_FLAGS_LEGACY_RATE_STAB, "legacy rate stabilised"},
    {TASE_GIMBAL_FLAGS_LEGACY_POSITION_STAB, "legacy position stabilised"},
};

const char *cli_gimbal_mode(long long flags)
{
    size_t i;
    for (i = 0; i < sizeof(gimbal_modes) / sizeof(gimbal_modes[0]); i++) {
        if (gimbal_modes[i].flags == flags) {
            return gimbal_modes[i].what;
        }
    }
    return NULL;
}

void cli_refuse_gimbal_cmd(const char *why)
{
    char list[512];
    size_t i, used = 0;
    for (i = 0; i < sizeof(gimbal_modes) / sizeof(gimbal_modes[0]); i++) {
        int w = snprintf(list + used, sizeof(list) - used, "%s0x%02X %s", i ? ", " : "",
                         (unsigned)gimbal_modes[i].flags, gimbal_modes[i].what);
        if (w > 0 && (size_t)w < sizeof(list) - used) {
            used += (size_t)w;
        }
    }
    tk_usage_error("GIMBAL_CMD %s: flags=MODE states what pan/tilt mean, one of: %s (or use "
                   "'tase point' / 'tase rate')",
                   why, list);
}

/* ---- verbs ---- */

typedef struct {
    cli_link_opts_t lo;
    cli_req_opts_t r;
    const char *pos[3];
    size_t npos;
    const char *stab;   /* "on", "off" or NULL */
    const char *hfov;   /* camera */
    const char *zoom;   /* camera */
    const char *wait_s; /* deploy/retract */
    bool no_wait;       /* spoi */
} verb_args_t;

/* The options every verb takes, plus the ones `which` lists. */
static void verb_parse(cli_args_t *a, verb_args_t *v, size_t max_pos, const char *which)
{
    memset(v, 0, sizeof(*v));
    v->lo.baud = CLI_DEFAULT_BAUD;
    v->r.timeout_ms = CLI_DEFAULT_TIMEOUT_MS;
    v->r.retries = CLI_DEFAULT_RETRIES;
    while (a->i < a->argc) {
        const char *x;
        if (strstr(which, "req") == NULL &&
            (cli_opt(a, "--timeout", true, &x) || cli_opt(a, "--retries", true, &x))) {
            /* taken and ignored, it looked as if the verb waited for something */
            tk_usage_error("this command awaits no answer: --timeout and --retries do not "
                           "apply (see --help)");
        }
        if (cli_common_opt(a) || cli_link_opt(a, &v->lo) || cli_req_opt(a, &v->r)) {
            continue;
        }
        if (strstr(which, "stab") && cli_opt(a, "--stab", true, &v->stab)) {
            if (strcmp(v->stab, "on") != 0 && strcmp(v->stab, "off") != 0) {
                tk_usage_error("bad --stab value '%s' (on or off)", v->stab);
            }
        } else if (strstr(which, "hfov") && cli_opt(a, "--hfov", true, &v->hfov)) {
        } else if (strstr(which, "zoom") && cli_opt(a, "--zoom", true, &v->zoom)) {
        } else if (strstr(which, "wait") && cli_opt(a, "--wait", true, &v->wait_s)) {
        } else if (strstr(which, "no-wait") && cli_opt(a, "--no-wait", false, &x)) {
            v->no_wait = true;
        } else if (cli_is_arg(a, true) && v->npos < max_pos) {
            v->pos[v->npos++] = a->argv[a->i++];
        } else {
            cli_bad_arg(a);
        }
    }
}

/* Verbs send a complete packet without waiting for an echo (unless they
 * run a request themselves). */
static cli_send_opts_t verb_opts(const verb_args_t *v)
{
    cli_send_opts_t o;
    o.zero = false;
    o.no_wait = true;
    o.raw = false;
    o.len = -1;
    o.r = v->r;
    return o;
}

static void need_args(const verb_args_t *v, size_t n, const char *what)
{
    if (v->npos != n) {
        tk_usage_error("expected %s (see --help)", what);
    }
    cli_check_link_opts(&v->lo);
}

/* point and rate: GIMBAL_CMD with its mode stated by the verb. */
typedef struct {
    uint8_t kind; /* TASE_GIMBAL_KIND_* */
    const char *args;
    const char *what; /* "pan" / "pan rate" in messages */
    double pan_lo, pan_hi, tilt_lo, tilt_hi;
    const char *unit;
} gimbal_verb_t;

/* positions: the spec's axis ranges (tase/units.h) */
static const gimbal_verb_t verb_point = {
    TASE_GIMBAL_KIND_POSITION, "PAN TILT in degrees", "",   TASE_PAN_MIN_DEG, TASE_PAN_MAX_DEG,
    TASE_TILT_MIN_DEG,         TASE_TILT_MAX_DEG,     "deg"};
static const gimbal_verb_t verb_rate = {TASE_GIMBAL_KIND_RATE,
                                        "PAN_RATE TILT_RATE in degrees per second",
                                        " rate",
                                        -327.68,
                                        327.67,
                                        -327.68,
                                        327.67,
                                        "deg/s"};

static int gimbal_verb(cli_args_t *a, const gimbal_verb_t *gv)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x80);
    verb_args_t v;
    cli_send_opts_t o;
    cli_fields_t fs;
    cli_session_t s;
    char what[32];
    long long pan, tilt;
    uint8_t flags;
    verb_parse(a, &v, 2, "stab");
    need_args(&v, 2, gv->args);
    snprintf(what, sizeof(what), "pan%s", gv->what);
    pan = cli_scaled_arg(what, v.pos[0], gv->pan_lo, gv->pan_hi, gv->unit, 100u);
    snprintf(what, sizeof(what), "tilt%s", gv->what);
    tilt = cli_scaled_arg(what, v.pos[1], gv->tilt_lo, gv->tilt_hi, gv->unit, 100u);
    flags = TASE_GIMBAL_FLAGS(gv->kind, v.stab == NULL || strcmp(v.stab, "on") == 0);
    cli_fields_init(&fs, p, p->len);
    cli_fields_set(&fs, "pan", pan);
    cli_fields_set(&fs, "tilt", tilt);
    cli_fields_set(&fs, "roll", 0);
    cli_fields_set(&fs, "flags", flags);
    cli_fields_set(&fs, "impulse_time", 0);
    o = verb_opts(&v);
    cli_session_open(&s, &v.lo, NULL, NULL);
    cli_send_fields(&s, &fs, p->len, &o);
    if (!v.r.json) {
        printf("  = %s: pan %.2f %s, tilt %.2f %s (flags 0x%02X)\n", cli_gimbal_mode(flags),
               (double)pan / 100.0, gv->unit, (double)tilt / 100.0, gv->unit, (unsigned)flags);
    }
    cli_session_close(&s);
    return TK_EXIT_OK;
}

int cli_cmd_point(cli_args_t *a)
{
    return gimbal_verb(a, &verb_point);
}

int cli_cmd_rate(cli_args_t *a)
{
    return gimbal_verb(a, &verb_rate);
}

static int camera_index(const char *s)
{
    /* the letters only: "1" was taken for camera B (0-based, as on the
     * wire), which no help text said */
    static const char *const names[] = {"A", "B", "C", "a", "b", "c"};
    size_t i;
    for (i = 0; i < sizeof(names) / sizeof(names[0]); i++) {
        if (strcmp(s, names[i]) == 0) {
            return (int)(i % 3u);
        }
    }
    tk_usage_error("bad camera '%s' (A, B or C)", s);
    return -1;
}

/* The type of camera `cam` (0..2) in the gimbal's SYSTEM_VERSION; dies
 * when the gimbal has none there, before CAMERA_CMD is sent. */
static int camera_type(cli_session_t *s, int cam, const cli_req_opts_t *r)
{
    static const char *const fields[] = {"camera_a", "camera_b", "camera_c"};
    const tase_packet_desc_t *sv = tase_schema_find(TASE_ID_GROUP(TASE_ID_SYSTEM_VERSION),
                                                    TASE_ID_TYPE(TASE_ID_SYSTEM_VERSION));
    uint8_t reply[TASE_DATA_MAX];
    long long type = -1;
    int n = cli_transact_note(s, sv, NULL, 0, reply, r,
                              " (the query asks which cameras the gimbal has; CAMERA_CMD was not "
                              "sent)");
    if (!tk_field_get(sv, (unsigned)tase_schema_field_index(sv, fields[cam]), reply, (size_t)n,
                      &type)) {
        tk_die("SYSTEM_VERSION answered with %d data bytes, no camera types; CAMERA_CMD was not "
               "sent",
               n);
    }
    if (type == TASE_CAMTYPE_NONE) {
        tk_die("the gimbal has no camera %c (SYSTEM_VERSION: type 0xFF, none); CAMERA_CMD was not "
               "sent",
               "ABC"[cam]);
    }
    return (int)type;
}

int cli_cmd_camera(cli_args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x41);
    verb_args_t v;
    cli_send_opts_t o;
    cli_fields_t fs;
    cli_session_t s;
    int cam = -1, camtype = -1;
    long long hfov = 0;
    size_t len;
    char what[96];
    verb_parse(a, &v, 1, "hfov zoom req");
    cli_check_link_opts(&v.lo);
    if (v.npos == 1) {
        cam = camera_index(v.pos[0]);
    }
    if (v.hfov != NULL && v.zoom != NULL) {
        tk_usage_error("give either --hfov or --zoom, not both");
    }
    if (cam < 0 && v.hfov == NULL && v.zoom == NULL) {
        tk_usage_error("expected a camera (A, B, C), --hfov DEG or --zoom X (see --help)");
    }
    if (v.hfov != NULL) {
        hfov = cli_scaled_arg("--hfov", v.hfov, 0.01, 327.67, "deg", 100u);
        snprintf(what, sizeof(what), ", HFOV %.2f deg", (double)hfov / 100.0);
    } else if (v.zoom != NULL) {
        /* a negative HFOV is a zoom ratio in -1/100 (-1 itself means "no
         * change", which a ratio of at least 1 never reaches) */
        hfov = -cli_scaled_arg("--zoom", v.zoom, 1.0, 327.68, "x", 100u);
        snprintf(what, sizeof(what), ", zoom %.2fx", (double)-hfov / 100.0);
    } else {
        what[0] = '\0';
    }
    o = verb_opts(&v);
    len = v.hfov != NULL || v.zoom != NULL ? p->len : 1u;
    cli_fields_init(&fs, p, len);
    if (cam >= 0) {
        cli_fields_set(&fs, "camera", cam);
    }
    if (len > 1u) {
        cli_fields_set(&fs, "hfov", hfov);
    }
    cli_fields_keep(&fs, cli_fields_within(p, len)); /* everything else: "do not change" */
    cli_session_open(&s, &v.lo, NULL, NULL);
    if (cam >= 0) {
        /* CAMERA_CMD has no echo: a camera the gimbal does not have would
         * be "selected" with nothing to confirm it, so ask first */
        camtype = camera_type(&s, cam, &v.r);
    }
    cli_send_fields(&s, &fs, len, &o);
    if (!v.r.json) {
        char sel[64] = "active camera unchanged";
        if (cam >= 0) {
            snprintf(sel, sizeof(sel), "camera %c%s (type %d in SYSTEM_VERSION)", "ABC"[cam],
                     what[0] ? "" : " selected", camtype);
        }
        printf("  = %s%s%s\n", sel, what, what[0] ? ", other settings unchanged" : "");
    }
    cli_session_close(&s);
    return TK_EXIT_OK;
}

int cli_cmd_gyro_zero(cli_args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x40);
    verb_args_t v;
    cli_session_t s;
    verb_parse(a, &v, 0, "");
    need_args(&v, 0, "no arguments");
    cli_session_open(&s, &v.lo, NULL, NULL);
    cli_send_frame(&s, p, NULL, 0);
    cli_print_packet(p, NULL, 0, v.r.json, "in", "sent");
    cli_session_close(&s);
    return TK_EXIT_OK;
}

typedef struct {
    bool seen;
    uint8_t deploy;
} rd_echo_t;

static void on_rd_frame(void *user, const tase_frame_t *f)
{
    rd_echo_t *e = user;
    if (f->group == 0x00 && f->type == 0x43 && f->len == 2u) {
        e->seen = true;
        e->deploy = f->data[0];
    }
}

static int retract_deploy(cli_args_t *a, bool deploy)
{
    const tase_packet_desc_t *p = tase_schema_find(0x00, 0x43);
    verb_args_t v;
    cli_session_t s;
    rd_echo_t e = {false, 0};
    double wait = 0.0, t_end;
    uint8_t data[2] = {deploy ? TASE_DEPLOY : TASE_RETRACT, 0};
    verb_parse(a, &v, 0, "wait");
    need_args(&v, 0, "no arguments");
    if (v.wait_s != NULL && (tk_parse_seconds(v.wait_s, &wait) != 0 || wait <= 0.0)) {
        tk_usage_error("bad --wait value '%s' (seconds)", v.wait_s);
    }
    cli_session_open(&s, &v.lo, on_rd_frame, &e);
    cli_send_frame(&s, p, data, sizeof(data));
    cli_print_packet(p, data, sizeof(data), v.r.json, "in", "sent");
    /* shown before the wait; a failing output is reported after it (exit
     * 5 once confirmed, 1 on a timeout: "sent" alone is not "confirmed") */
    tk_stdout_flush_soft();
    t_end = tk_now_s() + wait;
    while (wait > 0.0 && !e.seen && tk_now_s() < t_end) {
        tk_exit_if_signalled();
        cli_session_service(&s, 20);
    }
    if (wait > 0.0 && !e.seen) {
        tk_die("timeout: no RETRACT_DEPLOY_CMD echo within %g s (the move is not complete, or "
               "the gimbal has no 3AX retract: it is an option, 4.1.6)",
               wait);
    }
    if (e.seen) {
        cli_print_packet(p, (uint8_t[]){e.deploy, 0}, 2, v.r.json, "out", "echo");
        if ((e.deploy != 0) != deploy) {
            tk_exit(TK_EXIT_MISMATCH, "RETRACT_DEPLOY_CMD echo reports %s, not %s",
                    e.deploy ? "deployed" : "retracted", deploy ? "deployed" : "retracted");
        }
    }
    cli_session_close(&s);
    return TK_EXIT_OK;
}

int cli_cmd_deploy(cli_args_t *a)
{
    return retract_deploy(a, true);
}

int cli_cmd_retract(cli_args_t *a)
{
    return retract_deploy(a, false);
}

int cli_cmd_spoi(cli_args_t *a)
{
    const tase_packet_desc_t *p = tase_schema_find(0x10, 0x40);
    verb_args_t v;
    cli_send_opts_t o;
    cli_fields_t fs;
    cli_session_t s;
    long long lat, lon, height;
    verb_parse(a, &v, 3, "no-wait req");
    need_args(&v, 3, "LAT LON HEIGHT (degrees, degrees, metres)");
    lat = cli_scaled_arg("latitude", v.pos[0], -90.0, 90.0, "deg", 3600000u);
    lon = cli_scaled_arg("longitude", v.pos[1], -180.0, 180.0, "deg", 3600000u);
    height = cli_scaled_arg("height", v.pos[2], -21474836.48, 21474836.47, "m", 100u);
    cli_fields_init(&fs, p, p->len);
    cli_fields_set(&fs, "lat", lat);
    cli_fields_set(&fs, "lon", lon);
    cli_fields_set(&fs, "height", height);
    cli_fields_set(&fs, "vnorth", 0);
    cli_fields_set(&fs, "veast", 0);
    cli_fields_set(&fs, "vdown", 0);
    cli_fields_set(&fs, "flags", v.no_wait ? 0u : TASE_SPOI_ECHO);
    o = verb_opts(&v);
    cli_session_open(&s, &v.lo, NULL, NULL);
    if (v.no_wait) {
        cli_send_fields(&s, &fs, p->len, &o);
    } else {
        uint8_t reply[TASE_DATA_MAX];
        int n = cli_transact(&s, p, fs.data, p->len, reply, &v.r); /* prints it sent */
        cli_print_packet(p, reply, (size_t)n, v.r.json, "out", "echo");
        /* the echo's flags carry the gimbal's state, not our request */
        cli_confirm_echo(&fs, p->len, reply, n, "flags");
        /* ... and a gimbal that took the point tracks it (4.3.2): any
         * other mode is a point not taken (or, flags 0x80 as sent, our own
         * packet back from a line that echoes) */
        if (TASE_SPOI_MODE(reply[18]) != TASE_MODE_SPOI) {
            tk_exit(TK_EXIT_MISMATCH,
                    "SPOI_CMD echoed with flags 0x%02X: the gimbal reports mode %u, not SPOI (%u), "
                    "so it is not tracking the point%s",
                    reply[18], (unsigned)TASE_SPOI_MODE(reply[18]), (unsigned)TASE_MODE_SPOI,
                    reply[18] == TASE_SPOI_ECHO
                        ? " (flags as sent: our own packet back from a line that echoes?)"
                        : "");
        }
    }
    if (!v.r.json) {
        printf("  = SPOI at %.7f deg, %.7f deg, %.2f m%s\n",
               tase_units_mas_to_deg((int32_t)cli_fields_value(&fs, 0)),
               tase_units_mas_to_deg((int32_t)cli_fields_value(&fs, 1)),
               tase_units_cm_to_m((int32_t)cli_fields_value(&fs, 2)), v.no_wait ? "" : ", echoed");
    }
    cli_session_close(&s);
    return TK_EXIT_OK;
}
