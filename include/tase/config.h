/*
 * tase/config.h - the library's compile-time configuration, in one place.
 * Included by tase/common.h, so by every public header; never include it
 * yourself.
 *
 * CHANGING THE CONFIGURATION
 * Put your settings in a header of your own and name it when compiling
 * the library AND every file of the application that includes a tase
 * header (libcanard's CANARD_CONFIG_HEADER is the model):
 *
 *     -DTASE_CONFIG_HEADER='"my_tase_config.h"'      (flat or Makefile build)
 *     cmake -DTASE_CONFIG_HEADER=/path/my_tase_config.h   (CMake; see below)
 *
 *     // my_tase_config.h
 *     #define TASE_PORT_WRITE_TIMEOUT_MS 250u
 *
 * It is included before the defaults below, so it may set any of them.
 * Passing single macros with -D works too, but one header named once in
 * the build cannot drift apart between files.
 *
 * With CMake, -DTASE_CONFIG_HEADER=<file> copies the file into the build
 * (and the install) as tase/user_config.h, builds the library with it and
 * passes it on to everything that links tase::tase (add_subdirectory,
 * FetchContent, find_package) and to pkg-config users: they all get
 * TASE_USER_CONFIG defined, which includes it from here.
 *
 * THE OPTIONS
 *   TASE_PORT_WRITE_TIMEOUT_MS (default 100, 1..2^31-1)  the deadline of
 *       one frame write by tase_port_write_all() (tase/port_io.h).
 *   TASE_PORT_WRITE_TRIES (default 64, 1..255)  tase_port_write_all()'s
 *       give-up count for a port without a clock (tase/port_io.h).
 *   TASE_PORT_WRITE_SPINS (default 1048576, 1..2^31)  the same for a port
 *       whose clock stands still: refused calls in a row while its clock
 *       shows no time passing. Far more than a port refuses within one
 *       tick of a working clock (a 1 ms tick and a 20 ns call: 50,000).
 *       The three are used only inside the library: the values the
 *       library was built with are the ones that apply.
 *   TASE_RX_QUIET_MS (default 20, 1..65535)  the margin of the
 *       receiver's time bound, the longest pause inside a real frame as a
 *       receiver sees it (tase/frame.h, TIME BOUND); the value the library
 *       was built with is what tase_rx_init() sets, and
 *       tase_rx_set_timing() changes it per receiver.
 *   TASE_GIMBAL_SERVICE_READS (default 64, 1..1024)  the reads
 *       tase_gimbal_service() makes of each port per call, each of at
 *       most 64 bytes (tase/gimbal.h): with the default a call takes up to
 *       4096 bytes a port, about 3.3 million instructions on a Cortex-M4
 *       for three ports of the worst input (docs/TIMING.md); 1 bounds it
 *       to 64 bytes a port for a fast loop. Used only inside the library.
 *   TASE_GIMBAL_TELEMETRY_SHARE (default 75, 1..100)  the percentage of
 *       a port's capacity the gimbal role's telemetry may use, the rest
 *       kept for echoes and answers (tase/gimbal.h, PRIORITY AND
 *       CAPACITY). Used only inside the library.
 *   TASE_RING_BARRIER()  the bare-metal ring's barrier hook (tase/ring.h),
 *       used only inside port/baremetal/tase_ring.c.
 *   TASE_RX_CANDIDATES (1..16, default 4)  NO EFFECT since 0.2.0: the
 *       receiver it sized keeps one pending candidate whatever the value
 *       (tase/frame.h). Accepted and range-checked so that configurations
 *       that set it keep building; the library and the application may
 *       differ in it.
 * No option changes a type's layout or a function's signature.
 *
 * MISMATCH DETECTION
 * Headers of one release used with the library of another (a stale copy
 * in /usr/local/include, an old libtase-dev) would describe instances of
 * another size than the library fills: 0.1.0's tase_rx_t is 328 bytes on
 * x86-64, 0.2.0's 296, 0.3.0's 360. So every function that initialises an instance the
 * application allocates and the library fills links under a name that
 * carries the headers' ABI level (TASE_ABI_LEVEL, tase/version.h): the
 * call tase_rx_init(&rx) links to tase_rx_init_abi3, and a library of
 * another level does not define that name. A mismatch is a link error
 * naming the level the application's headers expected, e.g.
 *     undefined reference to `tase_rx_init_abi3'
 * (0.1.0's headers give `tase_rx_init': that release had no tag). Fix:
 * build against the headers installed with the library you link. In
 * source code the functions keep their plain names (macros below);
 * debuggers and nm show the link names.
 * A future option that changes a layout joins the tag, so that a library
 * and an application configured differently fail to link the same way.
 */
#ifndef TASE_CONFIG_H
#define TASE_CONFIG_H

#include "tase/version.h" /* TASE_ABI_LEVEL */

#if defined(TASE_CONFIG_HEADER)
#include TASE_CONFIG_HEADER
#elif defined(TASE_USER_CONFIG)
#include "tase/user_config.h" /* the configuration a CMake build was given */
#endif

/* No effect (see THE OPTIONS); still range-checked. */
#ifndef TASE_RX_CANDIDATES
#define TASE_RX_CANDIDATES 4
#endif
#if TASE_RX_CANDIDATES < 1 || TASE_RX_CANDIDATES > 16
#error "TASE_RX_CANDIDATES must be 1..16"
#endif

#ifndef TASE_RX_QUIET_MS
#define TASE_RX_QUIET_MS 20u
#endif
#if TASE_RX_QUIET_MS < 1 || TASE_RX_QUIET_MS > 65535
#error "TASE_RX_QUIET_MS must be 1..65535"
#endif

#ifndef TASE_PORT_WRITE_TIMEOUT_MS
#define TASE_PORT_WRITE_TIMEOUT_MS 100u
#endif
#if TASE_PORT_WRITE_TIMEOUT_MS < 1 || TASE_PORT_WRITE_TIMEOUT_MS > 0x7FFFFFFF
#error "TASE_PORT_WRITE_TIMEOUT_MS must be 1..2^31-1"
#endif
#ifndef TASE_PORT_WRITE_TRIES
#define TASE_PORT_WRITE_TRIES 64u
#endif
#if TASE_PORT_WRITE_TRIES < 1 || TASE_PORT_WRITE_TRIES > 255
#error "TASE_PORT_WRITE_TRIES must be 1..255"
#endif
#ifndef TASE_PORT_WRITE_SPINS
#define TASE_PORT_WRITE_SPINS 1048576u
#endif
#if TASE_PORT_WRITE_SPINS < 1 || TASE_PORT_WRITE_SPINS > 0x80000000
#error "TASE_PORT_WRITE_SPINS must be 1..2^31"
#endif
#ifndef TASE_GIMBAL_SERVICE_READS
#define TASE_GIMBAL_SERVICE_READS 64u
#endif
#if TASE_GIMBAL_SERVICE_READS < 1 || TASE_GIMBAL_SERVICE_READS > 1024
#error "TASE_GIMBAL_SERVICE_READS must be 1..1024"
#endif
#ifndef TASE_GIMBAL_TELEMETRY_SHARE
#define TASE_GIMBAL_TELEMETRY_SHARE 75u
#endif
#if TASE_GIMBAL_TELEMETRY_SHARE < 1 || TASE_GIMBAL_TELEMETRY_SHARE > 100
#error "TASE_GIMBAL_TELEMETRY_SHARE must be 1..100"
#endif

/* The link-name tag: "abi" and the ABI level. An option that changes a
 * layout adds its value as one more operand of the paste, through a chain
 * of #if (so that 4, 4u and (4) give the same name), e.g.
 * tase_rx_init_abi3_foo4. */
#define TASE_CONFIG_PASTE_(stem, level) stem##abi##level
#define TASE_CONFIG_NAME_(stem, level) TASE_CONFIG_PASTE_(stem, level)
/* stem -> stem<tag>: the link name of an ABI-guarded function is its
 * name, "_", and the tag. (The stem is spelled with the trailing "_" so
 * that no macro expands to its own name: clang
 * -Wdisabled-macro-expansion. Only the level is macro-expanded, so a
 * macro of the application's named like a part of the tag cannot
 * change it.) */
#define TASE_CONFIG_LINK_NAME(stem) TASE_CONFIG_NAME_(stem, TASE_ABI_LEVEL)

/* The ABI-guarded functions: every initialiser of an instance whose
 * layout the application allocates and the library fills. A program that
 * keeps any state of the library calls one of them, so it cannot link
 * against a library of another ABI level. A new such type adds its
 * initialisers here. The stateless functions (encoders, decoders,
 * schema lookups) are not guarded: a program that only encodes or
 * decodes is not caught this way, though a change to a message struct's
 * layout raises the level all the same. */
/* core (libtase): tase/frame.h, dispatch.h, can.h, klv.h, host.h, gimbal.h, schema.h */
#define tase_rx_init TASE_CONFIG_LINK_NAME(tase_rx_init_)
#define tase_dispatch_init TASE_CONFIG_LINK_NAME(tase_dispatch_init_)
#define tase_can_rx_init TASE_CONFIG_LINK_NAME(tase_can_rx_init_)
#define tase_can_split_init TASE_CONFIG_LINK_NAME(tase_can_split_init_)
#define tase_klv_rx_init TASE_CONFIG_LINK_NAME(tase_klv_rx_init_)
#define tase_host_init TASE_CONFIG_LINK_NAME(tase_host_init_)
#define tase_gimbal_init TASE_CONFIG_LINK_NAME(tase_gimbal_init_)
/* tase/schema.h: the field iterator, bound by either of these */
#define tase_field_iter_find TASE_CONFIG_LINK_NAME(tase_field_iter_find_)
#define tase_field_iter_init TASE_CONFIG_LINK_NAME(tase_field_iter_init_)
/* ports: tase/ring.h, bm_uart.h and bm_dma.h (libtase_baremetal), posix_uart.h
 * (libtase_posix_uart), socketcan.h (libtase_socketcan) */
#define tase_ring_init TASE_CONFIG_LINK_NAME(tase_ring_init_)
#define tase_bm_uart_init TASE_CONFIG_LINK_NAME(tase_bm_uart_init_)
#define tase_bm_dma_init TASE_CONFIG_LINK_NAME(tase_bm_dma_init_)
#define tase_posix_uart_open TASE_CONFIG_LINK_NAME(tase_posix_uart_open_)
#define tase_posix_uart_open_flags TASE_CONFIG_LINK_NAME(tase_posix_uart_open_flags_)
#define tase_posix_uart_attach TASE_CONFIG_LINK_NAME(tase_posix_uart_attach_)
#define tase_socketcan_open TASE_CONFIG_LINK_NAME(tase_socketcan_open_)
#define tase_socketcan_adopt TASE_CONFIG_LINK_NAME(tase_socketcan_adopt_)

#endif /* TASE_CONFIG_H */
