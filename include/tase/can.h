/*
 * tase/can.h - the datalink over CAN (spec section 5) and the 3AX
 * retract/deploy drive frames (section 5.3). Pure C99, no OS.
 *
 * ENCAPSULATION. Over CAN the datalink is unchanged: the bytes of encoded
 * frames (tase_frame_build()) are cut into consecutive CAN frames of 1..8
 * bytes, all with 29-bit extended IDs:
 *
 *     0x11000000  bytes going to the gimbal   (sent by the host)
 *     0x10000000  bytes coming from the gimbal (sent by the gimbal)
 *
 * CAN frames carry no sequence number, so the receiver relies on the bus
 * keeping their order (the spec requires it) and simply feeds each
 * payload to an ordinary datalink receiver (tase_rx_t), which finds the
 * 00 FF 5A frames in the byte stream exactly as on a UART. A lost CAN
 * frame costs the datalink frame it belonged to and nothing more. It is
 * counted as a checksum error when the next packet's bytes complete the
 * short candidate before the line goes quiet for its quiet limit (PAUSES
 * below); otherwise the time bound settles the candidate and it counts
 * only in bytes_discarded, as it does when the packet's first CAN frame
 * was the one lost (the rest has no sync: noise).
 *
 * PAUSES. The receiver's time bound (tase/frame.h, TIME BOUND) applies to
 * the reassembled bytes as to a UART's: a candidate that sees no byte for
 * its quiet limit is judged false, and the limit is at least the margin,
 * TASE_RX_QUIET_MS (20 ms). A sender that pauses longer between the CAN
 * frames of one packet (frames sent one at a time by hand with cansend,
 * or by a scheduler that sends one per slow cycle) has its packets cut
 * short, counted only in bytes_discarded. Such a link needs a larger
 * margin on its receiver: tase_rx_set_timing(&h.rx,
 * TASE_SOCKETCAN_BYTES_PER_S, 250) after tase_host_init() (the gimbal
 * role: on each rx it was given); `tase decode --candump` takes --margin.
 *
 * ROLES. A node is either the host (autopilot: sends 0x11000000, listens
 * to 0x10000000) or the gimbal (sends 0x10000000, listens to 0x11000000;
 * it also commands the 3AX drive with 0x12010000 and hears its status on
 * 0x12020000). Acceptance is by role, so frames of every other node on
 * the multidrop bus are counted and ignored.
 *
 * ONE SENDER PER ID. Every node sending in one direction uses the same ID
 * and the frames carry no source or sequence, so the receiver cannot tell
 * two senders' bytes apart: if an autopilot and a bench tool both send on
 * 0x11000000 at the same time, the CAN frames of their datalink frames
 * (any longer than 8 bytes spans several) interleave on the bus and both
 * datalink frames fail their checksums (0 of 2 delivered, 2 checksum
 * errors); two gimbals on 0x10000000 the same. This is a limit
 * of the protocol, not of this library: give each ID exactly one sender
 * at a time (disconnect or silence the autopilot before a bench tool
 * commands the gimbal, or put the tool on its own bus). Listening is
 * always safe: any number of nodes may receive either ID.
 *
 * 3AX. Two fixed 2-byte frames outside the datalink: the move command
 * (gimbal -> 3AX) and the position/speed status (3AX -> gimbal). The move
 * frame's byte has the opposite polarity of the datalink's
 * RETRACT_DEPLOY_CMD (0x00/0x43): on CAN, 0 means deploy. The command
 * names below carry RETRACT_DEPLOY_CMD's values and the codec inverts.
 *
 * Everything here is reentrant and ISR-safe except where an instance is
 * shared: one tase_can_rx_t or tase_can_split_t must be used from one
 * context at a time. Nothing allocates; all state is caller-owned.
 */
#ifndef TASE_CAN_H
#define TASE_CAN_H

#include "tase/common.h"
#include "tase/frame.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_CAN_ID_TO_GIMBAL 0x11000000u   /* datalink bytes host -> gimbal */
#define TASE_CAN_ID_FROM_GIMBAL 0x10000000u /* datalink bytes gimbal -> host */
#define TASE_CAN_ID_3AX_MOVE 0x12010000u    /* move command, gimbal -> 3AX */
#define TASE_CAN_ID_3AX_STATUS 0x12020000u  /* position/speed, 3AX -> gimbal */

#define TASE_CAN_SFF_MASK 0x000007FFu /* 11-bit standard identifier */
#define TASE_CAN_EFF_MASK 0x1FFFFFFFu /* 29-bit extended identifier */
#define TASE_CAN_DLC_MAX 8u
/* CAN frames one datalink frame needs at most: ceil(261 / 8) = 33. */
#define TASE_CAN_FRAMES_MAX ((TASE_FRAME_MAX + TASE_CAN_DLC_MAX - 1u) / TASE_CAN_DLC_MAX)

/* A classic CAN data frame, independent of any OS's layout. `dlc` is the
 * number of data bytes (0..8); data[dlc..8) are unspecified (the library
 * writes zeros). */
typedef struct {
    uint32_t id;   /* 11-bit (standard) or 29-bit (extended) identifier */
    bool extended; /* true: 29-bit identifier */
    uint8_t dlc;   /* data length, 0..8 */
    uint8_t data[8];
} tase_can_frame_t;

typedef enum {
    TASE_CAN_ROLE_HOST = 0,  /* sends TO_GIMBAL, listens to FROM_GIMBAL */
    TASE_CAN_ROLE_GIMBAL = 1 /* sends FROM_GIMBAL, listens to TO_GIMBAL */
} tase_can_role_t;

/* The datalink IDs a role transmits with and listens to. Either output may
 * be NULL. Returns TASE_OK or TASE_EARG (unknown role; outputs untouched).
 * O(1), reentrant, ISR-safe. */
int tase_can_role_ids(tase_can_role_t role, uint32_t *tx_id, uint32_t *rx_id);

/* Whether f is a well-formed classic data frame: identifier within 11 or
 * 29 bits as `extended` says, dlc <= 8. Returns TASE_OK, TASE_EARG (f is
 * NULL), TASE_ERANGE (identifier too wide) or TASE_ELENGTH (dlc > 8).
 * O(1), reentrant, ISR-safe. */
int tase_can_frame_check(const tase_can_frame_t *f);

/* ---- sending: splitting a byte stream into CAN frames ---------------- */

/* Splitter (iterator) over n bytes. Fields are private except `pos`, the
 * number of bytes handed out in frames so far (read only): after a
 * transmit failure it says how much of the data went out. The data must
 * stay valid and unchanged while the splitter is used. */
typedef struct {
    const uint8_t *data;
    size_t len;
    size_t pos;
    uint32_t id;
} tase_can_split_t;

/* Start splitting data[0..n) as sent by `sender` (host: ID TO_GIMBAL,
 * gimbal: ID FROM_GIMBAL). Any byte stream may be split: a whole encoded
 * frame, several, or a part; n == 0 gives no frames. Returns TASE_OK or
 * TASE_EARG (s NULL, unknown role, data NULL with n > 0; s untouched).
 * O(1), reentrant. */
int tase_can_split_init(tase_can_split_t *s, tase_can_role_t sender, const uint8_t *data, size_t n);

/* Next frame: 8 bytes while at least 8 remain, then the 1..7 left over.
 * Returns the frame's dlc (1..8), 0 when every byte has been handed out
 * (out untouched), or TASE_EARG (NULL argument, or s not initialised:
 * bytes left but no data pointer; s and out untouched). O(1), reentrant. */
int tase_can_split_next(tase_can_split_t *s, tase_can_frame_t *out);

/* Split data[0..n) into out[0..cap) in one call. Returns the number of
 * frames written ((n + 7) / 8), or TASE_EARG (out NULL with n > 0, data
 * NULL with n > 0, unknown role) or TASE_ENOSPC (cap too small, 0
 * included, or more than INT16_MAX frames needed; nothing written).
 * TASE_CAN_FRAMES_MAX frames hold any single datalink frame. O(n),
 * reentrant, ISR-safe. */
int tase_can_split(tase_can_role_t sender, const uint8_t *data, size_t n, tase_can_frame_t *out,
                   size_t cap);

/* ---- receiving: acceptance by role and reassembly -------------------- */

/* Whether f carries datalink bytes for `role` (extended, the role's
 * listening ID, dlc 1..8). Returns the payload length 1..8, or
 *   TASE_EUNKNOWN not for this role (another ID, or a standard frame);
 *   TASE_ELENGTH  the role's ID but dlc 0 or > 8;
 *   TASE_EARG     f NULL or unknown role.
 * O(1), reentrant, ISR-safe. */
int tase_can_accept(tase_can_role_t role, const tase_can_frame_t *f);

/* Counters of a CAN receiver; only incremented by the library, wrap
 * modulo 2^32. frames_in = accepted + ignored + bad_length. */
typedef struct {
    uint32_t frames_in;       /* every frame fed */
    uint32_t frames_accepted; /* payload passed to the datalink receiver */
    uint32_t frames_ignored;  /* not this role's ID (other nodes, 3AX, ...) */
    uint32_t bad_length;      /* this role's ID with dlc 0 or > 8 */
} tase_can_rx_stats_t;

/* A CAN receiver: role acceptance in front of a datalink receiver. `rx`
 * (datalink counters in rx.stats) and `stats` may be read; the rest is
 * private. 380 bytes (docs/FOOTPRINT.md). */
typedef struct {
    tase_rx_t rx;
    tase_can_rx_stats_t stats;
    tase_can_role_t role;
} tase_can_rx_t;

/* Initialise for `role` (the role of the node that receives): empty
 * datalink receiver, all counters zero. Returns TASE_OK or TASE_EARG
 * (crx NULL or unknown role; crx untouched). O(1). Allowed from inside
 * the instance's own frame callback (see tase_can_rx_feed()). */
int tase_can_rx_init(tase_can_rx_t *crx, tase_can_role_t role);

/* Feed one received CAN frame. If tase_can_accept() takes it, its payload
 * goes to tase_rx_feed(&crx->rx, ..., on_frame, user) and the number of
 * datalink frames delivered (>= 0) is returned. Otherwise the frame is
 * counted and dropped, and the return code says why: TASE_EUNKNOWN (not
 * ours: normal on a shared bus) or TASE_ELENGTH (our ID, bad dlc). These
 * two are the only "errors" that still change the instance (a counter).
 * TASE_EARG: crx or f NULL, crx->role not a role, or crx->rx visibly
 * corrupted, as tase_rx_feed() says (a corrupted instance; nothing
 * counted). TASE_EBUSY: called from inside on_frame of this
 * instance (nothing counted, nothing changed). From inside on_frame,
 * tase_can_rx_init() is allowed: it resets the instance and the call that
 * made the callback returns as soon as it does (see frame.h, RE-ENTRANCY);
 * reading or clearing the counters is allowed too. tase_rx_stop() on
 * crx->rx is not: the call would return with the rest of this CAN
 * frame's payload not taken in, and nothing keeps it (copy the frame out
 * in on_frame instead; the gimbal role's stop-and-handle pattern is for
 * its UART ports). The returned count is never negative except for these
 * codes. O(dlc) plus the datalink
 * receiver's cost. */
int tase_can_rx_feed(tase_can_rx_t *crx, const tase_can_frame_t *f, tase_rx_handler_t on_frame,
                     void *user);

/* ---- 3AX retract/deploy drive ---------------------------------------- */

/* What the gimbal asks the 3AX to do. The values are those of the
 * RETRACT_DEPLOY_CMD `deploy` byte (tase/flags.h TASE_DEPLOY = 1,
 * TASE_RETRACT = 0), so a value carried from that packet keeps its meaning;
 * the move frame's own byte has the opposite sense (0 deploys) and only
 * the encoder and decoder see it. Formerly TASE_3AX_DEPLOY = 0 and
 * TASE_3AX_RETRACT = 1: renamed so that code written for those values
 * fails to build instead of moving the wrong way. */
typedef enum {
    TASE_3AX_MOVE_RETRACT = 0, /* frame byte 0 != 0; sent as 0xFE */
    TASE_3AX_MOVE_DEPLOY = 1   /* frame byte 0 == 0 */
} tase_3ax_command_t;

#define TASE_3AX_RETRACT_BYTE 0xFEu       /* what the encoder sends to retract */
#define TASE_3AX_POSITION_DEPLOYED 0x00u  /* completely deployed */
#define TASE_3AX_POSITION_RETRACTED 0xFEu /* completely retracted */
#define TASE_3AX_POSITION_UNKNOWN 0xFFu   /* reserved: position unknown */
#define TASE_3AX_SPEED_STEP_DPS 5         /* one speed unit, deg/s */
#define TASE_3AX_SPEED_MIN_DPS (-640)     /* -128 units */
#define TASE_3AX_SPEED_MAX_DPS 635        /* +127 units */

/* Move command, ID 0x12010000, 2 bytes: Position, Reserved (0). */
typedef struct {
    tase_3ax_command_t command;
} tase_can_3ax_move_t;

/* Status, ID 0x12020000, 2 bytes: Position, signed Speed. */
typedef struct {
    uint8_t position;  /* 0 deployed .. 0xFE retracted, 0xFF unknown */
    int16_t speed_dps; /* deg/s, multiple of 5 in -640..635; > 0 retracting */
} tase_can_3ax_status_t;

/* Encode a move command into *out (extended, ID 3AX_MOVE, dlc 2, byte 1 =
 * 0, unused bytes 0). Returns TASE_OK, TASE_EARG (NULL) or TASE_ERANGE
 * (command not one of the enum values); out untouched on error. O(1),
 * reentrant, ISR-safe. */
int tase_can_3ax_move_encode(const tase_can_3ax_move_t *m, tase_can_frame_t *out);

/* Decode a move command (byte 0 zero: deploy, else retract; the reserved
 * byte is not checked). Returns TASE_OK, TASE_EARG (NULL), TASE_EUNKNOWN
 * (not an extended frame with ID 3AX_MOVE) or TASE_ELENGTH (dlc != 2); m
 * untouched on error. O(1), reentrant, ISR-safe. */
int tase_can_3ax_move_decode(const tase_can_frame_t *f, tase_can_3ax_move_t *m);

/* Encode a status frame. Returns TASE_OK, TASE_EARG (NULL) or TASE_ERANGE
 * (speed_dps not a multiple of 5 within -640..635); out untouched on
 * error. O(1), reentrant, ISR-safe. */
int tase_can_3ax_status_encode(const tase_can_3ax_status_t *st, tase_can_frame_t *out);

/* Decode a status frame. Returns TASE_OK, TASE_EARG, TASE_EUNKNOWN (not
 * an extended frame with ID 3AX_STATUS) or TASE_ELENGTH (dlc != 2); st
 * untouched on error. O(1), reentrant, ISR-safe. */
int tase_can_3ax_status_decode(const tase_can_frame_t *f, tase_can_3ax_status_t *st);

#ifdef __cplusplus
}
#endif

#endif /* TASE_CAN_H */
