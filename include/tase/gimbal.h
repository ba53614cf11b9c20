/*
 * tase/gimbal.h - the gimbal role: what the gimbal end of the link does
 * without knowing what the gimbal is (firmware, a simulator, a test).
 *
 * A tase_gimbal_t serves up to TASE_GIMBAL_PORTS ports ("external
 * communications port 1..3" of the PACKET_RATE packet, index 0..2 here:
 * index i is port i + 1), each a tase_port_t with its own frame receiver.
 * The spec never says which connector is port 1..3; the three that table 1
 * gives for gimbal communications, in its order, are Com2 (9600 baud),
 * Com3 (57600) and CAN, so pass them as indices 0, 1, 2 (Com1 is the
 * magnetometer's; docs/PROTOCOL-NOTES.md A2). It
 *
 *  - SETUP PACKETS (group 0x48, types 0x00..0x07, spec 4.4): stores the
 *    current data bytes of every setup packet (110 bytes), seeded at init
 *    with the spec's defaults where it gives them (CAMERA_TYPE: 0xFF "no
 *    camera" until the application stores its cameras). A zero-length
 *    packet is a query: the role answers, on the port it came from, with
 *    the stored bytes. A packet with data of an accepted length is first
 *    made what the gimbal would store: reserved bytes zero, and every field
 *    holding its "do not change" value (AXIS_SETTING 0xFF/0xFFFF,
 *    CAMERA_TYPE 0; tase_field_is_keep()) replaced by the stored setting,
 *    in the table's layout (a 22-byte AXIS_SETTING is laid out as 23). It
 *    is then handed to the application's apply_setup() callback, which
 *    validates and applies it and may change the bytes (clamp values);
 *    the bytes it leaves are stored and echoed, in the layout the packet
 *    came in (22 or 23 bytes for AXIS_SETTING). If apply_setup() refuses,
 *    the stored bytes are echoed unchanged, so the host always learns the
 *    settings in force. The stored bytes never hold a non-zero reserved
 *    byte nor a "do not change" value.
 *    SYSTEM_VERSION is query-only: a SYSTEM_VERSION packet of 0 or 42
 *    data bytes is answered with the bytes the application set
 *    (tase_gimbal_setup_set()); until it sets them, version 0.0.0 and no
 *    cameras (A, B and C 0xFF, 4.4.4's "if none"), so set it at start-up.
 *    A setup packet with a wrong data length (SYSTEM_VERSION's included)
 *    is counted (stats.bad_length) and not answered.
 *
 *  - TELEMETRY: emits GIMBAL_ANGLE (0x08/0x10), GIMBAL_RATE (0x08/0x40)
 *    and GEOREFERENCE_DATA (0x10/0x41) on each port at the rates of the
 *    PACKET_RATE packet (bytes 0,1,2 port 1; 5,6,7 port 2; 10,11,12
 *    port 3; packets per second, 0 disables; defaults 10, 10, 4). The
 *    application's fill_telemetry() callback writes each packet's data
 *    bytes when it is due.
 *
 *  - EVERYTHING ELSE (commands, host sensor/attitude/GPS, SPOI, unknown
 *    setup types) is the application's to act on: the role does not
 *    move the gimbal. It goes either to the application's dispatcher
 *    (app.dispatch, TYPED COMMANDS below) or as raw bytes to its on_frame()
 *    callback, which may answer with tase_gimbal_send_msg() (e.g. a
 *    zero-length SPOI_CMD query).
 *
 * TYPED COMMANDS. Set app.dispatch to a tase_dispatch_t (tase/dispatch.h)
 * that the application initialised with its handler table, e.g.
 *     [TASE_PKT_GIMBAL_CMD] = on_gimbal_cmd, [TASE_PKT_SPOI_CMD] = on_spoi,
 *     [TASE_PKT_RETRACT_DEPLOY_CMD] = on_retract, ...
 * and every frame the role does not answer itself goes through it: a
 * GIMBAL_CMD arrives in on_gimbal_cmd as a decoded tase_gimbal_cmd_t, a
 * zero-length query as a zeroed struct with frame->len 0 (a SPOI_CMD
 * handler tests it: that struct is no point to aim at), a wrong length
 * at the dispatcher's error hook, the rest at its default handler.
 * tase_gimbal_frame_port() tells a handler which port the frame came in
 * on. The setups stay the role's (they never reach the dispatcher).
 *
 * TYPED OR BYTES. Each application callback that carries packet data has
 * a typed form taking the packet's struct (tase/codec.h) and a form taking
 * its data bytes; set one of each pair (init refuses both):
 *     fill_telemetry_msg  / fill_telemetry   (telemetry due)
 *     apply_setup_msg     / apply_setup      (a setting arrived)
 * and tase_gimbal_send_msg(), tase_gimbal_setup_set_msg(),
 * tase_gimbal_setup_get_msg() are the typed forms of tase_gimbal_send(),
 * tase_gimbal_setup_set(), tase_gimbal_setup_get().
 *
 * DISPATCH. on_frame gets (user, port, frame); the dispatcher
 * (tase/dispatch.h) wants (dispatcher, frame). Either let the role receive
 * and pass the rest on to a dispatcher with a two-line adapter:
 *     static void to_dispatch(void *d, unsigned port, const tase_frame_t *f)
 *     {
 *         (void)port;                    // or keep it in your context
 *         tase_dispatch_frame(d, f);
 *     }
 *     app.on_frame = to_dispatch; app.user = &dispatcher;
 * The dispatcher counts unknown and wrong-length frames into the
 * tase_rx_stats_t given to tase_dispatch_init(): with one port, that
 * port's receiver's (&rx[0].stats); with several, one dispatcher per port,
 * each with its receiver's counters (the adapter picks it by `port`), or
 * one counting into a tase_rx_stats_t of the application's for all.
 * or run your own receiver with tase_dispatch_frame() as its handler and
 * hand the setup packets to the role from their typed handlers with
 * tase_gimbal_handle_frame() (init with rx NULL; examples/firmware does
 * this).
 *
 * SCHEDULE. Each (port, stream) has an anchor time t0 and a slot index k:
 * slot k is due at t0 + floor(k * 1000 / rate) ms. When k reaches rate,
 * t0 advances by exactly 1000 ms and k restarts at 0, so after any number
 * of seconds exactly rate * seconds packets are due: nothing accumulates
 * a rounded period, there is no drift, and no product overflows. A rate
 * change on a stream re-anchors it at the moment of the change (t0 = now,
 * first packet one new period later); streams whose rate did not change
 * keep their phase. A stream whose slot is due sends one packet per
 * tase_gimbal_poll(); if the poll came so late that further slots have
 * passed too, they are skipped (counted in stats.slots_skipped), never
 * sent as a burst. Poll at least once per shortest period (every few ms)
 * and every slot is sent, within the poll interval of its due time. A
 * next slot more than a second ahead of now_ms (the clock stepped back,
 * or polls came 2^31 ms or more apart) re-anchors its stream at now_ms,
 * as a rate change does, instead of waiting for that time; the slots of
 * such a gap are not counted.
 *
 * PRIORITY AND CAPACITY. Setup echoes, query answers and the
 * application's own sends are written before the call that received the
 * frame returns (tase_gimbal_handle_frame() at once; tase_gimbal_feed()
 * right after each frame, in stream order, see there;
 * tase_gimbal_service() reads and answers before it
 * polls telemetry), and are never held back. Telemetry is what yields: a
 * link carries only so many bytes per second (9600 baud 8N1: 960 B/s),
 * and PACKET_RATE may ask for far more (255/255/255 is 28,305 B/s). Bytes
 * written beyond what the link carries pile up in the driver's transmit
 * queue, where an echo written later waits behind them (4.3 s behind a
 * 4 KB tty queue at 9600 baud: longer than a host's retries), and every
 * write blocks until the queue has room. So each port has a capacity in
 * bytes per second: by default the byte rate its tase_port_t states
 * (bytes_per_s, filled by the ports' *_port() functions, e.g.
 * TASE_UART_BYTES_PER_S(9600) for a 9600-baud line), or, when the port
 * states none, the slowest line of the spec (960 B/s); no set-up can leave
 * a port without one. tase_gimbal_set_capacity() overrides it. Telemetry
 * may use at most TASE_GIMBAL_TELEMETRY_SHARE percent of it, the rest
 * staying free for answers. When the rates ask for more, every stream of that port sends
 * the same fraction of its due slots, spread evenly, and skips the rest
 * (stats.slots_over_capacity); the stored and echoed PACKET_RATE stay
 * what the host asked for. The transmit queue then stays short, and an
 * answer leaves within a few frame times (24 ms at 9600 baud and
 * 255/255/255, measured in tests/test_gimbal.c, against 4.3 s without a
 * limit).
 *
 * NOISE. Each port's receiver has the time bound of tase/frame.h (TIME
 * BOUND), at the port's byte rate: line noise that leaves a candidate held
 * (00 FF 5A FF claims 257 bytes) delays the commands after it by at most
 * the bound (44 ms at 57600 baud, 260 ms at 9600), never until more bytes
 * come. tase_gimbal_service() applies it by itself; an application that
 * feeds its own bytes calls tase_gimbal_feed() with n == 0 when it finds
 * its receive buffer empty (see there).
 *
 * LONGEST BLOCK. Each frame write blocks at most the port's frame bound
 * (port_io.h: TASE_PORT_WRITE_TIMEOUT_MS + the port's W; an answer or
 * tase_gimbal_send() goes in 16-byte pieces, so a port that takes every
 * piece whole but blocks W in each call blocks W per piece: up to 17 W for
 * the longest frame, 2 W for a 24-byte PACKET_RATE echo). A port whose
 * write fails gets no further telemetry in the same poll (its remaining
 * due slots count in stats.slots_after_tx_error), so a stuck port costs
 * tase_gimbal_poll() one frame bound, not one per due stream: a poll
 * blocks at most one bound per frame it wrote plus one per present port;
 * tase_gimbal_feed()/_handle_frame() one per answer written. Within the
 * capacity the driver's queue has room and writes do not block at all.
 *
 * TIME comes in as `now_ms` (monotonic, wraps modulo 2^32; e.g. a port's
 * now_ms()). Nothing here reads a clock, allocates or uses globals.
 *
 * STACK. Nothing the size of a frame or a packet struct is on the
 * stack: typed callbacks get a struct in the instance and telemetry is
 * built there, and
 * tase_gimbal_feed() handles the receiver's frames, and writes their
 * echoes, after the receiver has returned (tase_rx_stop()). docs/FOOTPRINT.md
 * lists the deepest stack of every entry point on Cortex-M (the
 * application's callbacks and the port's functions not included).
 *
 * REENTRANCY. Not reentrant per instance, not ISR-safe: call everything
 * from one context (the main loop draining the UART rings). Callbacks run
 * inside tase_gimbal_feed()/_handle_frame()/_poll()/_service(); they may
 * call tase_gimbal_send(), _send_msg(), _setup_get(), _setup_get_msg(),
 * _setup_len() and _frame_port(), nothing else of the same instance. The
 * calls that change its state are refused there with TASE_EBUSY, nothing
 * changed or written: _feed(), _handle_frame(), _poll(), _service(),
 * _setup_set(), _setup_set_msg() and _set_capacity() (a feed from a
 * callback moved the outer feed's place in its bytes, a setup_set() from
 * fill_telemetry() rewrote the frame being built). tase_gimbal_init() is
 * not refused (it cannot tell an instance from uninitialised memory): do
 * not call it from a callback.
 */
#ifndef TASE_GIMBAL_H
#define TASE_GIMBAL_H

#include "tase/codec.h"
#include "tase/dispatch.h"
#include "tase/frame.h"
#include "tase/port.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TASE_GIMBAL_PORTS 3u         /* external communications ports 1..3 */
#define TASE_GIMBAL_STREAMS 3u       /* telemetry packets per port */
#define TASE_GIMBAL_SETUP_TYPES 8u   /* setup types 0x00..0x07 */
#define TASE_GIMBAL_SETUP_BYTES 110u /* sum of their data lengths */

/* Telemetry streams, in PACKET_RATE byte order. */
#define TASE_STREAM_ANGLE 0u  /* GIMBAL_ANGLE 0x08/0x10 */
#define TASE_STREAM_RATE 1u   /* GIMBAL_RATE 0x08/0x40 */
#define TASE_STREAM_GEOREF 2u /* GEOREFERENCE_DATA 0x10/0x41 */

/* The longest telemetry packet's data (GEOREFERENCE_DATA, 63 bytes): the
 * room fill_telemetry() gets. */
#define TASE_GIMBAL_TELEMETRY_MAX 63u

/* TASE_GIMBAL_TELEMETRY_SHARE (tase/config.h, default 75): the
 * percentage of a port's capacity telemetry may use (see PRIORITY AND
 * CAPACITY); the rest is kept for echoes and answers. */

/* Application callbacks; any may be NULL. `user` is passed back. */
typedef struct {
    /* A setup packet of `type` (0..7, not SYSTEM_VERSION) with data
     * arrived on `port`. data[0..len) is a private copy in the table's
     * layout (len is the table length), reserved bytes zero and "do not
     * change" fields already replaced by the stored settings; the callback
     * may modify it. Return >= 0 to accept (the bytes are stored, a
     * PACKET_RATE change reschedules, and the bytes are echoed) or < 0 to
     * refuse (the current settings are echoed). NULL accepts all. */
    int (*apply_setup)(void *user, unsigned port, uint8_t type, uint8_t *data, size_t len);
    /* Telemetry packet `id` (TASE_ID_GIMBAL_ANGLE, _GIMBAL_RATE,
     * _GEOREFERENCE_DATA) is due on `port`: write its data into
     * data[0..cap) (cap is TASE_GIMBAL_TELEMETRY_MAX, 63: GEOREFERENCE_DATA's
     * length, the longest) and return the length, or a negative value to
     * skip this slot (stats.telemetry_skipped); a length over cap or not
     * the packet's (6, 18, 63: a host drops a wrong length) skips it too.
     * NULL: nothing is sent. */
    int (*fill_telemetry)(void *user, unsigned port, uint16_t id, uint8_t *data, size_t cap,
                          uint32_t now_ms);
    /* Every other valid frame received on `port`. */
    void (*on_frame)(void *user, unsigned port, const tase_frame_t *frame);
    void *user;
    /* Typed form of fill_telemetry: telemetry packet `id` is due on
     * `port`: fill its struct at msg (a zeroed tase_packet_msg_t: use its
     * gimbal_angle, gimbal_rate or georeference member, or cast to that
     * struct) and return >= 0 to send it, < 0 to skip the slot. */
    int (*fill_telemetry_msg)(void *user, unsigned port, uint16_t id, void *msg, uint32_t now_ms);
    /* Typed form of apply_setup: setup packet `id` (TASE_ID_PACKET_RATE
     * ..., not SYSTEM_VERSION) arrived on `port`, decoded into a private
     * struct msg that the callback may change. Return >= 0 to accept (msg
     * is encoded, stored and echoed; reserved bytes as zero) or < 0 to
     * refuse (the current settings are echoed). */
    int (*apply_setup_msg)(void *user, unsigned port, uint16_t id, void *msg);
    /* Typed commands (TYPED COMMANDS above): the application's dispatcher,
     * given every frame the role does not answer itself, instead of
     * on_frame (init refuses both). It must outlive the role. */
    tase_dispatch_t *dispatch;
} tase_gimbal_app_t;

/* Statistics; only incremented by the library, wrap modulo 2^32. */
typedef struct {
    uint32_t frames_rx;            /* valid frames received on all ports */
    uint32_t setup_applied;        /* setup packets accepted and stored */
    uint32_t setup_refused;        /* setup packets apply_setup() refused */
    uint32_t setup_queries;        /* setup queries answered: zero-length ones and
                                    * 42-byte SYSTEM_VERSIONs (R1) */
    uint32_t bad_length;           /* setup packets with a wrong data length */
    uint32_t telemetry_tx;         /* telemetry frames written */
    uint32_t telemetry_skipped;    /* due slots fill_telemetry() declined */
    uint32_t slots_skipped;        /* slots passed over because poll was late */
    uint32_t frames_tx;            /* all frames written (echoes, telemetry, sends) */
    uint32_t tx_errors;            /* frames a port did not take completely */
    uint32_t slots_over_capacity;  /* due slots skipped to stay within capacity */
    uint32_t slots_after_tx_error; /* due slots not tried: the port failed earlier
                                      in the same poll */
} tase_gimbal_stats_t;

/* Private: the schedule of one telemetry stream. */
typedef struct {
    uint32_t t0;  /* anchor: slot k is due at t0 + k * 1000 / rate */
    uint32_t acc; /* capacity pacing: accumulated budget */
    uint16_t k;   /* next slot, 0 <= k < rate */
    uint8_t rate; /* packets per second, 0 = off */
} tase_gimbal_sched_t;

/* Gimbal instance (512 bytes on Cortex-M, docs/FOOTPRINT.md; the
 * receivers are the caller's, see tase_gimbal_init()). Treat every field
 * except `stats` as private. */
typedef struct {
    tase_gimbal_stats_t stats;
    tase_gimbal_app_t app;
    tase_port_t port[TASE_GIMBAL_PORTS]; /* ops NULL: port absent */
    tase_rx_t *rx;                       /* caller's receivers, or NULL */
    uint8_t nrx;                         /* how many */
    /* 1 while tase_gimbal_feed(), _handle_frame(), _poll() or _service()
     * runs (and so its callbacks): see REENTRANCY */
    uint8_t busy;
    tase_gimbal_sched_t sched[TASE_GIMBAL_PORTS][TASE_GIMBAL_STREAMS];
    uint32_t capacity[TASE_GIMBAL_PORTS]; /* bytes/s */
    uint32_t demand[TASE_GIMBAL_PORTS];   /* telemetry bytes/s the rates ask */
    uint8_t setup[TASE_GIMBAL_SETUP_BYTES];
    /* The frame being handled: its port, or 0xFF outside a callback; the
     * port tase_gimbal_feed() is feeding, and the frame its receiver
     * stopped on (data NULL: none), handled after the receiver returns. */
    uint8_t frame_port;
    uint8_t feed_port;
    tase_frame_t pending;
    /* Not on the stack: the packet struct of a typed callback (telemetry
     * to fill, a setting to apply) and the frame telemetry is built in. */
    tase_packet_msg_t msg;
    uint8_t tx_frame[TASE_GIMBAL_TELEMETRY_MAX + TASE_FRAME_OVERHEAD];
} tase_gimbal_t;

/* Initialise: ports[0..nports) are copied (nports 0..3; an entry whose ops
 * is NULL leaves that port absent: nothing is sent there), app is copied
 * (NULL: no callbacks), setup packets take their defaults and every
 * stream is anchored at now_ms (first packets one period later).
 * rx is the caller's array of nports receivers (360 bytes each), one per
 * port, used by tase_gimbal_feed() and tase_gimbal_service(); init
 * initialises them, sets each one's time bound to its port's byte rate
 * (tase_rx_set_timing()) and keeps the pointer. Each port's telemetry
 * capacity starts at its byte rate (PRIORITY AND CAPACITY). Pass NULL when the
 * application runs its own receiver and hands frames over with
 * tase_gimbal_handle_frame() (firmware that dispatches every frame
 * itself saves the RAM). Returns TASE_OK, or TASE_EARG (g NULL, ports
 * NULL with nports > 0, nports > 3, a present port without write, app
 * with both forms of fill_telemetry or of apply_setup, or with both
 * on_frame and dispatch). O(1). */
int tase_gimbal_init(tase_gimbal_t *g, const tase_port_t *ports, tase_rx_t *rx, size_t nports,
                     const tase_gimbal_app_t *app, uint32_t now_ms);

/* Feed bytes received on port index `port` at now_ms into that port's
 * receiver. Answers setup packets and calls on_frame for the rest. now_ms
 * also drives the receiver's time bound (NOISE above): call it with n == 0
 * (bytes may be NULL) whenever a look at the port's receive buffer found
 * nothing waiting, so that frames held behind noise come out once the line
 * has been quiet for the bound. Never with bytes still waiting unread.
 * Each frame is handled when the receiver has returned (it stops on
 * every frame: tase_rx_stop()), so handlers run with the receiver's stack
 * unwound: a setup is offered to apply_setup and stored and its echo
 * written at once (one per setup frame, in stream order, carrying the
 * settings in force after it), anything else goes to the dispatcher or
 * on_frame.
 * Returns frames received (>= 0), TASE_EARG (g NULL, port >= nports,
 * bytes NULL with n > 0, or that port's receiver visibly corrupted, as
 * tase_rx_feed() says; g and the receivers unchanged), TASE_EBUSY (from a
 * callback of this instance: REENTRANCY; nothing changed) or TASE_ESTATE
 * (initialised without receivers).
 * Worst case O(n * TASE_FRAME_MAX). */
int tase_gimbal_feed(tase_gimbal_t *g, unsigned port, const uint8_t *bytes, size_t n,
                     uint32_t now_ms);

/* Hand over one frame received on `port` some other way (e.g. CAN
 * reassembly). Returns TASE_OK, TASE_EARG (g, frame or frame->data
 * NULL, port >= 3; nothing counted) or TASE_EBUSY (from a callback of this
 * instance; nothing counted or written). A setup frame for an absent port (no
 * ops: nothing could answer it) is counted in stats.frames_rx only:
 * neither applied nor answered, whatever its length (no bad_length). O(len). */
int tase_gimbal_handle_frame(tase_gimbal_t *g, unsigned port, const tase_frame_t *frame,
                             uint32_t now_ms);

/* Inside a callback of this role (apply_setup, on_frame, the
 * dispatcher's handlers): the port index the frame being handled came in
 * on. TASE_EARG (g NULL) or TASE_ESTATE (no frame is being handled). */
int tase_gimbal_frame_port(const tase_gimbal_t *g);

/* Set the capacity of port index `port` in bytes per second, e.g.
 * TASE_UART_BYTES_PER_S(9600) for a 9600-baud line; 0 goes back to the
 * default (the port's bytes_per_s, or 960 when it states none); UINT32_MAX
 * is no limit in practice. See PRIORITY AND CAPACITY. Takes effect at the
 * next due slot. Returns TASE_OK, TASE_EARG (g NULL, port >= 3) or
 * TASE_EBUSY (from a callback of this instance; nothing changed). O(1). */
int tase_gimbal_set_capacity(tase_gimbal_t *g, unsigned port, uint32_t bytes_per_s);

/* Send every telemetry packet that is due at now_ms (at most one per
 * stream, see SCHEDULE; within the port's capacity, see PRIORITY AND
 * CAPACITY). Returns the number of frames written (>= 0), TASE_EARG (g
 * NULL) or TASE_EBUSY (from a callback of this instance; nothing sent).
 * Blocks at most one frame bound per frame written plus one per
 * present port (LONGEST BLOCK).
 * O(ports * streams) plus the callbacks and writes. */
int tase_gimbal_poll(tase_gimbal_t *g, uint32_t now_ms);

/* Read whatever each present port has ready (timeout 0, ports with a
 * read function), feed it (a read that finds nothing ticks the port's
 * receiver: NOISE above), then tase_gimbal_poll(). Returns the poll
 * result, TASE_EARG (g NULL, or the receiver of a port it would read
 * visibly corrupted, as tase_rx_feed() says), TASE_EBUSY (from a callback
 * of this instance), or TASE_ESTATE when a port has a read function but
 * the gimbal was initialised without receivers; on an error nothing is
 * read on any port and nothing sent. A port read error is
 * skipped (the port may
 * recover), counted nowhere else: check the port; so is a read() that
 * claims more bytes than asked (none of them is fed). Stack: a 64-byte
 * read buffer and the receive path, 360 B on Cortex-M4 and 400 B on M0+
 * with a setup packet handled, plus the callbacks' and the port's own
 * (docs/FOOTPRINT.md, "Role entry points"). It makes a bounded number of
 * reads: at most TASE_GIMBAL_SERVICE_READS (tase/config.h, default 64) of
 * at most 64 bytes per port per call,
 * after which it moves on and the rest waits for the next call. */
int tase_gimbal_service(tase_gimbal_t *g, uint32_t now_ms);

/* Send one frame on port index `port` (e.g. an answer from on_frame).
 * Returns the frame length, TASE_EARG (g NULL, port >= 3 or absent, data
 * NULL with len > 0), TASE_ETOOLONG, or a port error. O(len). */
int tase_gimbal_send(tase_gimbal_t *g, unsigned port, uint8_t group, uint8_t type,
                     const uint8_t *data, size_t len);

/* Send packet `id` from its typed struct msg (tase/codec.h) on port
 * index `port`; msg NULL sends the zero-length form (e.g. a SPOI_CMD
 * query). Returns the frame length, TASE_EARG (g NULL, port >= 3 or
 * absent, a CAMERA_PASS tail NULL with len > 0), TASE_EUNKNOWN (id not
 * in the schema), TASE_ELENGTH (msg NULL for a packet without a
 * zero-length form), TASE_ETOOLONG (CAMERA_PASS tail over 249 bytes),
 * or a port error. msg must not change until the call returns, and the
 * stack is tase_port_send_msg()'s (port_io.h). O(length). */
int tase_gimbal_send_msg(tase_gimbal_t *g, unsigned port, uint16_t id, const void *msg);

/* Data length of setup packet `type` (0..7), or TASE_EUNKNOWN (type > 7).
 * O(1). */
int tase_gimbal_setup_len(uint8_t type);

/* Copy the stored bytes of setup packet `type` into out[0..cap).
 * Returns the length, TASE_EARG (g/out NULL), TASE_EUNKNOWN (type > 7),
 * TASE_ENOSPC (cap too small; nothing copied). O(len). */
int tase_gimbal_setup_get(const tase_gimbal_t *g, uint8_t type, uint8_t *out, size_t cap);

/* Store setup packet `type` directly (no callback, no echo): load saved
 * settings at start-up, or set SYSTEM_VERSION. data is in the table's
 * layout; reserved bytes are stored as zero, and a field holding its "do
 * not change" value keeps the stored setting. A PACKET_RATE change
 * reschedules as described above, anchored at now_ms. Returns TASE_OK,
 * TASE_EARG (g NULL, data NULL), TASE_EUNKNOWN (type > 7), TASE_ELENGTH
 * (len is not the type's length, 0 and SIZE_MAX included), TASE_EBUSY
 * (from a callback of this instance); g unchanged on error. O(len). */
int tase_gimbal_setup_set(tase_gimbal_t *g, uint8_t type, const uint8_t *data, size_t len,
                          uint32_t now_ms);

/* tase_gimbal_setup_set() from the typed struct of setup packet `id`
 * (TASE_ID_PACKET_RATE .. TASE_ID_CAMERA_ALIGN; reserved bytes stored as
 * zero). Returns TASE_OK, TASE_EARG (g or msg NULL), TASE_EUNKNOWN (id
 * is not a setup packet), TASE_EBUSY (from a callback of this instance);
 * g unchanged on error. O(length). */
int tase_gimbal_setup_set_msg(tase_gimbal_t *g, uint16_t id, const void *msg, uint32_t now_ms);

/* The stored setting of setup packet `id` decoded into its struct msg.
 * Returns its data length, TASE_EARG (g or msg NULL), TASE_EUNKNOWN (id
 * is not a setup packet; msg unchanged). O(length). */
int tase_gimbal_setup_get_msg(const tase_gimbal_t *g, uint16_t id, void *msg);

#ifdef __cplusplus
}
#endif

#endif /* TASE_GIMBAL_H */
