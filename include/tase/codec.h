/*
 * tase/codec.h - typed C structs for every packet of the spec and one
 * generic encoder/decoder between them and frames.
 *
 * Each struct member is a field of the schema (tase/schema.h) with the
 * same name as its JSON key, of the C type given by the field's width and
 * signedness; units are the wire units of the spec (use tase/units.h to
 * convert, tase/flags.h for flag bytes). Reserved bytes have no member:
 * they are sent as zero and ignored on receipt. The structs are ordinary
 * (not packed) C structs; the codec reads and writes the wire byte by
 * byte, big-endian, so the host's byte order and alignment never matter.
 *
 * GYRO_ZERO_CMD has no data and no struct: pass msg = NULL.
 *
 * Both roles use the same functions: a gimbal encodes Out packets and
 * decodes In ones, a host the reverse; setup packets go both ways.
 *
 * TWO LEVELS. tase_packet_encode() and tase_packet_decode() work on whole
 * frames (sync, size, type, checksum). tase_packet_encode_data() and
 * tase_packet_decode_data() work on the data bytes alone, which is what
 * the roles' raw tase_host_send()/tase_gimbal_send() take and what a
 * request's reply buffer holds; the roles' typed calls (tase_host_send_msg(),
 * tase_host_transact_msg(), tase_gimbal_send_msg(), ...) use them for you.
 *
 * Every function is reentrant and ISR-safe (no state besides its
 * arguments). A failing call writes nothing.
 */
#ifndef TASE_CODEC_H
#define TASE_CODEC_H

#include "tase/frame.h"
#include "tase/schema.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- group 0x00: command and control ------------------------------- */

typedef struct {          /* GIMBAL_CMD 0x00/0x80, In, 8 bytes */
    int16_t pan;          /* 1/100 deg or deg/s (see flags) */
    int16_t tilt;         /* 1/100 deg or deg/s */
    int16_t roll;         /* 1/100 deg or deg/s; ignored by the gimbal */
    uint8_t flags;        /* TASE_GIMBAL_FLAGS_* (tase/flags.h) */
    uint8_t impulse_time; /* 1/100 s */
} tase_gimbal_cmd_t;

typedef struct {           /* CAMERA_CMD 0x00/0x41, In, 10 or 1 bytes */
    uint8_t camera;        /* 0 A, 1 B, 2 C, 0xFF do not change */
    int16_t hfov;          /* 1/100 deg; < 0: -zoom ratio; -1 no change */
    uint16_t focus;        /* mm, or TASE_FOCUS_* special values */
    uint8_t exposure;      /* TASE_EXPOSURE_* */
    uint8_t shutter_speed; /* VISCA 0x00..0x15, 0xFF no change */
    uint8_t bright;        /* 0x00..0x1F, 0xFF no change */
    uint8_t flags;         /* TASE_CAMERA_FLAG_* */
} tase_camera_cmd_t;

typedef struct {           /* LEGACY_CAMERA_CMD 0x00/0x81, In, 8 bytes */
    uint16_t zoom;         /* VISCA 0x0000 (wide) .. 0x4000 (narrow) */
    uint16_t focus;        /* VISCA, or TASE_LEGACY_FOCUS_* */
    uint8_t auto_exposure; /* TASE_LEGACY_AE_* */
    uint8_t shutter_speed; /* VISCA 0x00..0x15, 0xFF no change */
    uint8_t iris;          /* VISCA 0x00..0x11 */
    uint8_t gain;          /* VISCA 0x00..0x0F */
} tase_legacy_camera_cmd_t;

typedef struct {         /* CAMERA_PASS 0x00/0x42, Both, 4 + 0..249 */
    uint8_t camera;      /* 0 A, 1 B, 2 C */
    uint8_t baud;        /* units of 1200 baud; 0 do not change */
    uint8_t len;         /* number of camera bytes, 0..249 */
    const uint8_t *data; /* camera bytes. Encode: read (may be NULL
                                when len is 0). Decode: points into the
                                frame, valid as long as the frame is. */
} tase_camera_pass_t;
#define TASE_CAMERA_PASS_MAX 249u

typedef struct {    /* RETRACT_DEPLOY_CMD 0x00/0x43, Both, 2 */
    uint8_t deploy; /* non-zero deploy, 0 retract */
} tase_retract_deploy_cmd_t;

/* ---- group 0x08: dynamics ------------------------------------------ */

typedef struct { /* GIMBAL_ANGLE 0x08/0x10, Out, 6 bytes */
    int16_t pan; /* 1/100 deg */
    int16_t tilt;
    int16_t roll; /* always 0: no roll axis */
} tase_gimbal_angle_t;

typedef struct {      /* GIMBAL_RATE 0x08/0x40, Out, 18 bytes */
    uint32_t time;    /* ms since gimbal reset */
    int16_t pan_rate; /* 1/100 deg/s, axis relative to mount */
    int16_t tilt_rate;
    int16_t roll_rate;
    int16_t p;    /* 1/100 deg/s, mount body roll rate */
    int16_t q;    /* mount body pitch rate */
    int16_t r;    /* mount body yaw rate */
    uint8_t mode; /* TASE_MODE_* (tase/flags.h) */
} tase_gimbal_rate_t;

typedef struct {   /* HOST_SENSOR 0x08/0x41, In, 20 bytes */
    uint32_t time; /* host ms */
    int16_t roll;  /* 1/100 deg/s body rates */
    int16_t pitch;
    int16_t yaw;
    uint8_t flags;       /* TASE_HOST_SENSOR_* */
    uint8_t sample_rate; /* packets per second */
    int16_t x_accel;     /* 1/300 m/s^2 */
    int16_t y_accel;
    int16_t z_accel;
    uint16_t tas; /* 1/100 m/s; 0xFFFF unavailable */
} tase_host_sensor_t;

typedef struct {         /* HOST_ATTITUDE 0x08/0x42, In, 12 bytes */
    uint32_t time;       /* host ms */
    int16_t roll;        /* 1/100 deg, -180..180 */
    int16_t pitch;       /* 1/100 deg, -90..90 */
    int16_t yaw;         /* 1/100 deg, -180..180 */
    uint8_t flags;       /* TASE_HOST_ATT_* */
    uint8_t sample_rate; /* packets per second */
} tase_host_attitude_t;

/* ---- group 0x10: position ------------------------------------------ */

typedef struct {    /* HOST_GPS_DATA 0x10/0x10, In, 32 bytes */
    uint32_t time;  /* host ms */
    int32_t lat;    /* milli-arcseconds */
    int32_t lon;    /* milli-arcseconds */
    int32_t height; /* cm above WGS-84 ellipsoid */
    int16_t vnorth; /* cm/s */
    int16_t veast;
    int16_t vdown;
    uint16_t year;
    uint8_t month;
    uint8_t day;
    uint8_t hour;
    uint8_t minute;
    uint8_t second;
    uint8_t frac_second; /* 1/100 s, 0..99 */
    uint8_t valid;       /* 1 valid, 0 not */
    uint8_t sample_rate; /* packets per second */
} tase_host_gps_t;

typedef struct { /* SPOI_CMD 0x10/0x40, Both, 19 or 0 bytes */
    int32_t lat; /* milli-arcseconds */
    int32_t lon;
    int32_t height; /* cm above ellipsoid */
    int16_t vnorth; /* cm/s */
    int16_t veast;
    int16_t vdown;
    uint8_t flags; /* TASE_SPOI_* */
} tase_spoi_cmd_t;

typedef struct {   /* GEOREFERENCE_DATA 0x10/0x41, Out, 63 */
    uint32_t time; /* ms since gimbal reset */
    int32_t lat;   /* milli-arcseconds */
    int32_t lon;
    int32_t height; /* cm above ellipsoid */
    int16_t vnorth; /* cm/s */
    int16_t veast;
    int16_t vdown;
    uint16_t year;
    uint8_t month;
    uint8_t day;
    uint8_t hour;
    uint8_t minute;
    uint8_t second;
    uint8_t frac_second; /* 1/100 s */
    uint8_t num_sats;
    uint8_t pdop;        /* 0.1 PDOP */
    uint16_t status;     /* TASE_GPS_* (tase/flags.h) */
    int16_t camera_roll; /* 1/100 deg Euler angles of the camera */
    int16_t camera_pitch;
    int16_t camera_yaw;
    uint16_t hfov;       /* 1/100 deg */
    uint16_t vfov;       /* 1/100 deg */
    uint16_t focal;      /* 1/100 mm */
    uint8_t mode;        /* TASE_MODE_* */
    uint8_t sample_rate; /* packets per second */
    uint16_t nav_health; /* TASE_NAV_* */
    int16_t mount_roll;  /* 1/100 deg Euler angles of the mount */
    int16_t mount_pitch;
    int16_t mount_yaw;
    int16_t pan; /* 1/100 deg gimbal angles */
    int16_t tilt;
    int16_t roll;
    uint8_t camera; /* active camera 0 A, 1 B, 2 C */
} tase_georeference_t;

/* ---- group 0x48: setup (every one Both, echoed, zero-length query) -- */

typedef struct {     /* PACKET_RATE 0x48/0x00, 16 bytes */
    uint8_t angle_1; /* port 1, packets/s */
    uint8_t rate_1;
    uint8_t geo_ref_1;
    uint8_t camera_1;
    uint8_t angle_2; /* port 2 */
    uint8_t rate_2;
    uint8_t geo_ref_2;
    uint8_t camera_2;
    uint8_t angle_3; /* port 3 */
    uint8_t rate_3;
    uint8_t geo_ref_3;
    uint8_t camera_3;
    uint8_t temporary; /* TASE_SETUP_TEMPORARY (1): not stored; 0 (a zeroed struct,
                        * and maybe the gimbal's answer) writes the rates to the
                        * gimbal's non-volatile memory. tase_packet_init_keep() */
} tase_packet_rate_t;

typedef struct {        /* SENSOR_FILTER 0x48/0x01, 2 bytes */
    uint8_t cutoff;     /* 0.1 Hz */
    uint8_t decimation; /* 0.1 deg/s */
} tase_sensor_filter_t;

typedef struct {             /* AXIS_SETTING 0x48/0x02, 23 bytes */
    int16_t pan_nogo_center; /* 1/100 deg; 0xFFFF (-1) no change */
    uint16_t pan_nogo_range; /* 1/100 deg; 0xFFFF no change */
    int16_t tilt_nogo_center;
    uint16_t tilt_nogo_range;
    int16_t roll_nogo_center;
    uint16_t roll_nogo_range;
    uint8_t pan_max_rate; /* 5 deg/s; 0xFF no change */
    uint8_t tilt_max_rate;
    uint8_t roll_max_rate;
    uint8_t pan_max_accel; /* 200 deg/s^2 */
    uint8_t tilt_max_accel;
    uint8_t roll_max_accel;
    uint8_t pan_pos_gain; /* 0.1 (deg/s)/deg */
    uint8_t tilt_pos_gain;
    uint8_t roll_pos_gain;
    uint8_t temporary; /* as PACKET_RATE's: 0 stores; tase_packet_init_keep() */
} tase_axis_setting_t;

typedef struct { /* SYSTEM_VERSION 0x48/0x03, 42 bytes */
    uint8_t major;
    uint8_t minor;
    uint8_t sub;
    uint8_t released; /* 1 released, else test version */
    uint16_t soft_year;
    uint8_t soft_month;
    uint8_t soft_day;
    uint32_t board_sn;
    uint32_t board_rev;
    uint32_t board_config;
    uint16_t board_year;
    uint8_t board_month;
    uint8_t board_day;
    uint8_t camera_a;    /* TASE_CAMTYPE_* */
    uint16_t max_hfov_a; /* 1/100 deg */
    uint16_t min_hfov_a;
    uint8_t camera_b; /* 0xFF none */
    uint16_t max_hfov_b;
    uint16_t min_hfov_b;
    uint8_t camera_c; /* 0xFF none */
    uint16_t max_hfov_c;
    uint16_t min_hfov_c;
} tase_system_version_t;

typedef struct {               /* NAV_SOURCE 0x48/0x04, 2 bytes */
    uint8_t external_attitude; /* non-zero: use HOST_ATTITUDE */
    uint8_t external_gps;      /* non-zero: use HOST_GPS_DATA */
} tase_nav_source_t;

typedef struct {      /* CAMERA_TYPE 0x48/0x05, 3 bytes */
    uint8_t camera_a; /* TASE_CAMTYPE_*, 0 no change, 0xFF none */
    uint8_t camera_b;
    uint8_t camera_c;
} tase_camera_type_t;

typedef struct { /* GPS_LEVER_ARM 0x48/0x06, 6 bytes */
    int16_t x;   /* mm, IMU to GPS antenna */
    int16_t y;
    int16_t z;
} tase_gps_lever_arm_t;

typedef struct {       /* CAMERA_ALIGN 0x48/0x07, 16 bytes */
    uint16_t zoom_1;   /* 1/100 zoom ratio of measurement 1 */
    int16_t pan_err_1; /* 1/100 deg */
    int16_t tilt_err_1;
    int16_t roll_err_1;
    uint16_t zoom_2;
    int16_t pan_err_2;
    int16_t tilt_err_2;
    int16_t roll_err_2;
} tase_camera_align_t;

/* Storage for any decoded packet (the dispatcher's stack buffer). */
typedef union {
    tase_gimbal_cmd_t gimbal_cmd;
    tase_camera_cmd_t camera_cmd;
    tase_legacy_camera_cmd_t legacy_camera_cmd;
    tase_camera_pass_t camera_pass;
    tase_retract_deploy_cmd_t retract_deploy_cmd;
    tase_gimbal_angle_t gimbal_angle;
    tase_gimbal_rate_t gimbal_rate;
    tase_host_sensor_t host_sensor;
    tase_host_attitude_t host_attitude;
    tase_host_gps_t host_gps;
    tase_spoi_cmd_t spoi_cmd;
    tase_georeference_t georeference;
    tase_packet_rate_t packet_rate;
    tase_sensor_filter_t sensor_filter;
    tase_axis_setting_t axis_setting;
    tase_system_version_t system_version;
    tase_nav_source_t nav_source;
    tase_camera_type_t camera_type;
    tase_gps_lever_arm_t gps_lever_arm;
    tase_camera_align_t camera_align;
} tase_packet_msg_t;

/* Encode packet `id` (TASE_ID_*) from its typed struct `msg` into a
 * complete frame out[0..cap) at the packet's table length (CAMERA_PASS:
 * 4 + msg->len). msg may be NULL only for GYRO_ZERO_CMD.
 * Returns the frame length (data length + 8), or
 *   TASE_EARG     out is NULL, msg is NULL for a packet with data, or
 *                 CAMERA_PASS data is NULL with len > 0;
 *   TASE_EUNKNOWN id is not in the schema;
 *   TASE_ETOOLONG CAMERA_PASS len > TASE_CAMERA_PASS_MAX;
 *   TASE_ENOSPC   cap is too small (0 included).
 * Checked in this order, except that out NULL gives TASE_EARG first.
 * The payload is built in place at out + TASE_FRAME_HEADER (no copy;
 * CAMERA_PASS's camera bytes may even lie in out, at the payload's place
 * or anywhere else). The struct msg itself must not overlap out: the
 * payload's bytes are zeroed before its fields are read. O(length). */
int tase_packet_encode(uint16_t id, const void *msg, uint8_t *out, size_t cap);

/* Like tase_packet_encode() but with an explicit data length `len`, which
 * must be an accepted length of the packet (tase_schema_length_ok()):
 * 0 for a query (msg may be NULL), 1 for CAMERA_CMD "change active camera
 * only" (only msg->camera is sent), 22 for AXIS_SETTING's short layout
 * (tase/schema.h TWO LAYOUTS). For CAMERA_PASS len must be
 * 4 + msg->len. Returns as tase_packet_encode(), plus TASE_ELENGTH when
 * len is not accepted (any size_t up to SIZE_MAX; compared without
 * overflow). */
int tase_packet_encode_len(uint16_t id, const void *msg, size_t len, uint8_t *out, size_t cap);

/* Encode the zero-length form of packet `id`: the query of a setup
 * packet, SPOI_CMD or SYSTEM_VERSION, and the GYRO_ZERO_CMD command.
 * Returns 8 (the frame length) or TASE_EARG (out NULL) / TASE_EUNKNOWN /
 * TASE_ELENGTH (packet has no zero-length form) / TASE_ENOSPC (cap < 8). */
int tase_packet_encode_query(uint16_t id, uint8_t *out, size_t cap);

/* Decode frame f into the typed struct of its packet at msg (which must
 * be that struct, or a tase_packet_msg_t), in the layout its length
 * selects (AXIS_SETTING 22 or 23 bytes). A query (length 0) decodes to a
 * zeroed struct. The fields a short form leaves out (CAMERA_CMD's 1-byte
 * form: all but camera) take their "do not change" values
 * (tase_field_keep(): hfov -1, focus 0xFFFF, flags 0x80, ...), never a
 * zero that would be a command; the return value tells the forms apart.
 * Returns the data length decoded (>= 0), or
 *   TASE_EARG     f NULL, f->data NULL with f->len > 0, or msg NULL for a
 *                 known packet of accepted length > 0 (msg may be NULL for
 *                 a zero-length frame: GYRO_ZERO_CMD or a query);
 *   TASE_EUNKNOWN the schema does not know (f->group, f->type);
 *   TASE_ELENGTH  f->len is not an accepted length for the packet.
 * On error msg is unchanged. O(length). */
int tase_packet_decode(const tase_frame_t *f, void *msg);

/* ---- data bytes only (no frame around them) ---------------------------- */

/* Encode the DATA of packet `id` (what a frame of it carries, without
 * sync, size, group/type and checksum) from msg into data[0..cap), at the
 * packet's table length (CAMERA_PASS: 4 + msg->len). msg may be NULL only
 * for GYRO_ZERO_CMD (length 0).
 * Returns the data length (0..253), or
 *   TASE_EARG     data is NULL (even for length 0), msg is NULL for a
 *                 packet with data, or CAMERA_PASS data NULL with len > 0;
 *   TASE_EUNKNOWN id is not in the schema;
 *   TASE_ETOOLONG CAMERA_PASS len > TASE_CAMERA_PASS_MAX;
 *   TASE_ENOSPC   cap is smaller than the data length.
 * Checked in this order. CAMERA_PASS's camera bytes may lie anywhere,
 * even in data; the struct msg itself must not overlap data (as
 * tase_packet_encode()). Nothing is written on error. O(length). */
int tase_packet_encode_data(uint16_t id, const void *msg, uint8_t *data, size_t cap);

/* Like tase_packet_encode_data() with an explicit data length `len`, as
 * in tase_packet_encode_len(): 0 for a query (msg may be NULL), 1 for the
 * CAMERA_CMD camera-only form; TASE_ELENGTH when len is not accepted. */
int tase_packet_encode_data_len(uint16_t id, const void *msg, size_t len, uint8_t *data,
                                size_t cap);

/* Decode the data bytes data[0..len) of packet `id` into msg, exactly as
 * tase_packet_decode() decodes a frame of (group, type) = id carrying
 * them: same zeroing, same results (TASE_EARG for data NULL with len > 0
 * or msg NULL with len > 0; TASE_EUNKNOWN; TASE_ELENGTH for any len up to
 * SIZE_MAX that the packet does not accept). A decoded CAMERA_PASS points
 * into data. On error msg is unchanged. O(length). */
int tase_packet_decode_data(uint16_t id, const uint8_t *data, size_t len, void *msg);

/* tase_packet_decode_data() for a descriptor already looked up. p NULL
 * gives TASE_EUNKNOWN (so the result of tase_schema_find() can be passed
 * as it is); a pointer that is not a descriptor of the schema table gives
 * TASE_EARG. O(length). */
int tase_packet_decode_desc(const tase_packet_desc_t *p, const uint8_t *data, size_t len,
                            void *msg);

/* Decode data[0..it->len) into msg for the packet the field walk `it`
 * (tase/schema.h) is bound to, at the length it was begun for: the
 * dispatcher's path, which found the packet and checked the length in one
 * call (tase_field_iter_find()) and decodes with the descriptors in hand,
 * no second lookup. The walk is restarted and run to its end. Same
 * results as tase_packet_decode_data() for that packet and length
 * (TASE_ELENGTH when it->accepted is false), and TASE_EARG when it is
 * NULL or bound to no packet. O(length). */
int tase_packet_decode_iter(tase_field_iter_t *it, const uint8_t *data, void *msg);

/* A packet that changes nothing, to change a setting of: msg, the typed
 * struct of packet `id` (or a tase_packet_msg_t), zeroed, then every field
 * that has the spec's "do not change" value set to it (tase_field_keep():
 * AXIS_SETTING's 0xFF / 0xFFFF, CAMERA_TYPE's 0, CAMERA_CMD's 0xFF, -1,
 * 0xFFFF and flags 0x80, ...) and a `temporary` byte (PACKET_RATE,
 * AXIS_SETTING) set to TASE_SETUP_TEMPORARY, so that the gimbal does not
 * write the settings to its non-volatile memory. Set the fields to change
 * and send it:
 *     tase_axis_setting_t ax, now;
 *     (void)tase_packet_init_keep(TASE_ID_AXIS_SETTING, &ax);  // returns 0
 *     ax.pan_max_rate = 12;                                    // 60 deg/s
 *     r = tase_host_transact_msg(&h, TASE_ID_AXIS_SETTING, &ax, &now, 500, 2);
 *     // now: the settings in force (its `temporary` is the gimbal's: set it
 *     // to TASE_SETUP_TEMPORARY again before sending `now` back)
 * A zeroed struct is not such a packet: an AXIS_SETTING of zeros sets
 * every rate, acceleration and gain to 0 (the axes cannot move), and a
 * `temporary` of 0 stores whatever is sent. The other setup packets
 * (SENSOR_FILTER, NAV_SOURCE, CAMERA_TYPE, GPS_LEVER_ARM, CAMERA_ALIGN)
 * have no `temporary` byte: the gimbal always stores what they set
 * (docs/PROTOCOL-NOTES.md S11).
 * Returns the number of fields left at 0 because the spec gives them no
 * "do not change" value: 0 means every field holds such a value, so a
 * setup packet or CAMERA_CMD as filled changes nothing (a command still
 * acts when sent: GYRO_ZERO_CMD, which has no fields, zeroes the gyros);
 * otherwise those zeros are sent as values (PACKET_RATE: 12, its rates,
 * and a rate of 0 stops that stream; SENSOR_FILTER, GPS_LEVER_ARM,
 * CAMERA_ALIGN, NAV_SOURCE: every field). For such a packet ask for the
 * gimbal's settings first (a query: tase_host_transact_msg() with msg
 * NULL), change what you mean to, set `temporary` if it has one (an
 * answer may carry 0, which would store them) and send that back.
 * Or TASE_EARG (msg NULL), TASE_EUNKNOWN (id not in the schema; msg is
 * not written). O(fields), reentrant, no side effects but msg. */
int tase_packet_init_keep(uint16_t id, void *msg);

/* ---- commands that move the gimbal ------------------------------------ */

/* Whether a command that moves the gimbal is one the spec defines, so that
 * nothing moves on a value the spec gives no meaning (the host role checks
 * every GIMBAL_CMD and SPOI_CMD it sends with it: tase/host.h):
 *   GIMBAL_CMD  flags must be one of the twelve values of the spec's
 *               table 5 (4.1.1, the four legacy ones included), and a
 *               position command (flags 0x01, 0x03, 0x20, 0xA0) must lie
 *               in the axes' ranges (TASE_PAN_*_CDEG, TASE_TILT_*_CDEG in
 *               tase/common.h: pan -180..180, tilt -270..90 degrees);
 *   SPOI_CMD    lat within -90..90 and lon within -180..180 degrees
 *               (+-324,000,000 and +-648,000,000 milli-arcseconds).
 * Every other packet passes (its ranges are the wire's). Reserved flag
 * bits are not checked here (tase_schema_reserved_flags()).
 * Returns TASE_OK, TASE_ERANGE (a value above), or TASE_EARG (msg NULL).
 * O(1), no side effects. */
int tase_command_check(uint16_t id, const void *msg);

/* tase_command_check() of the data bytes data[0..len) of packet `id`: a
 * GIMBAL_CMD or SPOI_CMD with data is decoded (tase_packet_decode_data():
 * TASE_ELENGTH for a length the packet does not accept, TASE_EARG for data
 * NULL) and checked; a RETRACT_DEPLOY_CMD or GIMBAL_CMD of a length the
 * packet does not accept (a zero-length GIMBAL_CMD: it has no query form)
 * is TASE_ELENGTH; a zero-length SPOI_CMD (a query) and any other packet
 * give TASE_OK. O(1). */
int tase_command_check_data(uint16_t id, const uint8_t *data, size_t len);

#ifdef __cplusplus
}
#endif

#endif /* TASE_CODEC_H */
