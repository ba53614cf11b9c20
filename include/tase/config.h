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
 *     #define TASE_RX_CANDIDATES 1
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
 *   TASE_RX_CANDIDATES (1..16, default 4)   ABI: changes sizeof(tase_rx_t),
 *       so also of tase_host_t and tase_can_rx_t, and the stride of the
 *       receiver array given to tase_gimbal_init(). See tase/frame.h.
 *   TASE_PORT_WRITE_TIMEOUT_MS (default 100)  the deadline of one frame
 *       write by tase_port_write_all() (tase/port_io.h).
 *   TASE_PORT_WRITE_TRIES (default 64)  tase_port_write_all()'s give-up
 *       count for a port whose clock does not move (tase/port_io.h).
 *       Both are used only inside the library: the values the library
 *       was built with are the ones that apply.
 *   TASE_RING_BARRIER()  the bare-metal ring's barrier hook (tase/ring.h),
 *       used only inside port/baremetal/tase_ring.c.
 * No other macro changes a type's size or a function's signature.
 *
 * MISMATCH DETECTION
 * A program whose configuration differs from the library's must not link:
 * an instance sized for one TASE_RX_CANDIDATES and initialised by code
 * built for another is a memory overrun. So every function that
 * initialises an instance whose size depends on the configuration has a
 * link name that carries the configuration: the call tase_rx_init(&rx)
 * compiled with the default links to tase_rx_init_rx_candidates_4, and
 * the library built with TASE_RX_CANDIDATES 1 only defines
 * tase_rx_init_rx_candidates_1. A mismatch is then a link error naming
 * the value the application expected, e.g.
 *     undefined reference to `tase_host_init_rx_candidates_1'
 * Fix: build the library and the application with the same
 * TASE_CONFIG_HEADER. In source code the functions keep their plain
 * names (macros below); debuggers and nm show the link names.
 */
#ifndef TASE_CONFIG_H
#define TASE_CONFIG_H

#if defined(TASE_CONFIG_HEADER)
#include TASE_CONFIG_HEADER
#elif defined(TASE_USER_CONFIG)
#include "tase/user_config.h" /* the configuration a CMake build was given */
#endif

#ifndef TASE_RX_CANDIDATES
#define TASE_RX_CANDIDATES 4
#endif
#if TASE_RX_CANDIDATES < 1 || TASE_RX_CANDIDATES > 16
#error "TASE_RX_CANDIDATES must be 1..16"
#endif

#ifndef TASE_PORT_WRITE_TIMEOUT_MS
#define TASE_PORT_WRITE_TIMEOUT_MS 100u
#endif
#ifndef TASE_PORT_WRITE_TRIES
#define TASE_PORT_WRITE_TRIES 64u
#endif

/* The configuration's link-name tag (one value per ABI-changing setting;
 * a chain of #if rather than token pasting, so that 4, 4u and (4) give
 * the same name). */
#if TASE_RX_CANDIDATES == 1
#define TASE_CONFIG_TAG_ rx_candidates_1
#elif TASE_RX_CANDIDATES == 2
#define TASE_CONFIG_TAG_ rx_candidates_2
#elif TASE_RX_CANDIDATES == 3
#define TASE_CONFIG_TAG_ rx_candidates_3
#elif TASE_RX_CANDIDATES == 4
#define TASE_CONFIG_TAG_ rx_candidates_4
#elif TASE_RX_CANDIDATES == 5
#define TASE_CONFIG_TAG_ rx_candidates_5
#elif TASE_RX_CANDIDATES == 6
#define TASE_CONFIG_TAG_ rx_candidates_6
#elif TASE_RX_CANDIDATES == 7
#define TASE_CONFIG_TAG_ rx_candidates_7
#elif TASE_RX_CANDIDATES == 8
#define TASE_CONFIG_TAG_ rx_candidates_8
#elif TASE_RX_CANDIDATES == 9
#define TASE_CONFIG_TAG_ rx_candidates_9
#elif TASE_RX_CANDIDATES == 10
#define TASE_CONFIG_TAG_ rx_candidates_10
#elif TASE_RX_CANDIDATES == 11
#define TASE_CONFIG_TAG_ rx_candidates_11
#elif TASE_RX_CANDIDATES == 12
#define TASE_CONFIG_TAG_ rx_candidates_12
#elif TASE_RX_CANDIDATES == 13
#define TASE_CONFIG_TAG_ rx_candidates_13
#elif TASE_RX_CANDIDATES == 14
#define TASE_CONFIG_TAG_ rx_candidates_14
#elif TASE_RX_CANDIDATES == 15
#define TASE_CONFIG_TAG_ rx_candidates_15
#elif TASE_RX_CANDIDATES == 16
#define TASE_CONFIG_TAG_ rx_candidates_16
#endif

#define TASE_CONFIG_PASTE_(stem, tag) stem##tag
#define TASE_CONFIG_NAME_(stem, tag) TASE_CONFIG_PASTE_(stem, tag)
/* stem -> stem<configuration tag>: the link name of an ABI-guarded
 * function is its name, "_", and the tag. (The stem is spelled with the
 * trailing "_" so that no macro expands to its own name: clang
 * -Wdisabled-macro-expansion.) */
#define TASE_CONFIG_LINK_NAME(stem) TASE_CONFIG_NAME_(stem, TASE_CONFIG_TAG_)

/* The ABI-guarded functions: the initialisers of tase_rx_t (frame.h),
 * tase_can_rx_t (can.h), tase_host_t (host.h) and of tase_gimbal_t with
 * its receiver array (gimbal.h). A new type that embeds a tase_rx_t, or
 * takes an array of them, adds its initialiser here. */
#define tase_rx_init TASE_CONFIG_LINK_NAME(tase_rx_init_)
#define tase_can_rx_init TASE_CONFIG_LINK_NAME(tase_can_rx_init_)
#define tase_host_init TASE_CONFIG_LINK_NAME(tase_host_init_)
#define tase_gimbal_init TASE_CONFIG_LINK_NAME(tase_gimbal_init_)

#endif /* TASE_CONFIG_H */
