/*
 * tase/common.h - error codes and small definitions shared by every module.
 *
 * Conventions used throughout the library:
 *  - Functions that can fail return int: 0 (or a length/count) on success,
 *    a negative TASE_E* code on failure. A failing call leaves its outputs
 *    and the instance it was given unchanged unless its contract says
 *    otherwise.
 *  - Errors that come from the wire (bad checksums, noise, wrong lengths)
 *    are not return codes: they are counted in statistics and may be
 *    reported to an error hook.
 *  - All state is owned by the caller; the library keeps no globals and
 *    never allocates.
 *  - Arguments come in one order: the instance (rx, g, port, ...), then
 *    what (group and type of a frame, the TASE_ID of a packet), then the
 *    input (data and its length, or the message struct), then the output
 *    and its capacity last: tase_frame_build(group, type, data, len, out,
 *    cap), tase_packet_encode(id, msg, out, cap),
 *    tase_packet_decode_data(id, data, len, msg).
 */
#ifndef TASE_COMMON_H
#define TASE_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "tase/config.h" /* TASE_CONFIG_HEADER and the defaults */
#include "tase/version.h"

#if defined(__cplusplus) && __cplusplus >= 201103L && defined(__GNUC__) && !defined(__clang__)
/* Private: TASE_CAST_() below for g++ from C++11 on. A static_cast the
 * macros of the headers make of a user's argument (TASE_GIMBAL_FLAGS(2, 1),
 * TASE_UART_BYTES_PER_S(57600u)) is "useless" to g++ -Wuseless-cast when
 * the argument has the type already, and a user's code built with that
 * warning as an error failed; inside a function template the cast is not
 * reported. constexpr, so that the macros stay constant expressions. (Not
 * for clang++, which has no such warning and whose -Wc++98-compat reports
 * the template.) Outside extern "C": a template cannot have C linkage. */
template <typename T, typename U> constexpr T tase_cast_(U v)
{
    return static_cast<T>(v);
}
#define TASE_CAST_TEMPLATE_ 1
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Private: an explicit conversion for code in the public headers (static
 * inline functions, macros) that compiles cleanly as C and as C++ (no
 * old-style cast there: clang++ -Wold-style-cast). A type name cannot be
 * put in parentheses, hence the MISRA 20.7 suppressions. */
#if defined(TASE_CAST_TEMPLATE_)
/* cppcheck-suppress misra-c2012-20.7 */
#define TASE_CAST_(type, value) (tase_cast_<type>(value))
#elif defined(__cplusplus)
/* cppcheck-suppress misra-c2012-20.7 */
#define TASE_CAST_(type, value) (static_cast<type>(value))
#else
/* cppcheck-suppress misra-c2012-20.7 */
#define TASE_CAST_(type, value) ((type)(value))
#endif

/* Private: `inline` for the static inline functions of the public headers
 * that sit in a loop of the library (the field iterator's step): GCC and
 * clang inline them even at -Os, where a call per field cost the codec up
 * to 13% more instructions on a Cortex-M0+. */
#if defined(__GNUC__)
#define TASE_INLINE_ __inline__ __attribute__((always_inline))
#else
#define TASE_INLINE_ inline
#endif

/* Private: keeps a helper out of its caller, so that the caller's stack
 * frame (on a path that goes deeper elsewhere) does not take the helper's
 * registers and locals too. */
#if defined(__GNUC__)
#define TASE_NOINLINE_ __attribute__((noinline))
#else
#define TASE_NOINLINE_
#endif

/* Marks a function kept for a release after its replacement came (the
 * compiler names the replacement where it is used); define
 * TASE_ALLOW_DEPRECATED to silence it while migrating. */
#if defined(__GNUC__) && !defined(TASE_ALLOW_DEPRECATED)
#define TASE_DEPRECATED_(msg) __attribute__((deprecated(msg)))
#else
#define TASE_DEPRECATED_(msg)
#endif

/* Error codes. Stable: values never change meaning once released. */
/* Bytes per second a UART carries at `baud` with 8N1 framing (10 bits per
 * byte: start, 8 data, stop): TASE_UART_BYTES_PER_S(57600) is 5760. The
 * byte rate of tase_port_t and tase_rx_set_timing(). */
#define TASE_UART_BYTES_PER_S(baud) (TASE_CAST_(uint32_t, baud) / 10u)

#define TASE_OK 0
#define TASE_EARG (-1)          /* NULL pointer or out-of-range argument */
#define TASE_ENOSPC (-2)        /* caller's buffer too small */
#define TASE_ETOOLONG (-3)      /* data longer than the protocol allows */
#define TASE_ELENGTH (-4)       /* wrong data length for this packet type */
#define TASE_EUNKNOWN (-5)      /* group/type (or name, tag) not known */
#define TASE_ECHECKSUM (-6)     /* checksum mismatch */
#define TASE_EFORMAT (-7)       /* malformed input (bad key, tag, layout) */
#define TASE_ERANGE (-8)        /* value outside its representable range */
#define TASE_EAGAIN (-9)        /* nothing to do now / would block; retry */
#define TASE_ETIMEOUT (-10)     /* no answer within the time allowed */
#define TASE_EIO (-11)          /* operating-system I/O error */
#define TASE_ENODEV (-12)       /* device or interface does not exist */
#define TASE_EDOWN (-13)        /* interface exists but is down */
#define TASE_EACCES (-14)       /* permission denied */
#define TASE_EBUSY (-15)        /* busy: call or request in progress, device held */
#define TASE_ENOBUFS (-16)      /* transmit queue full (see the call for what was sent) */
#define TASE_ETRUNC (-17)       /* input ends before the item is complete */
#define TASE_EUNSUPPORTED (-18) /* valid request this build/port cannot do */
#define TASE_ESTATE (-19)       /* call not valid in the current state */

/* Returns a short constant English description of a TASE_E* code (or of
 * TASE_OK). Unknown codes give "unknown error". Never returns NULL.
 * Lives in its own translation unit so firmware that never calls it does
 * not link the strings. Reentrant, ISR-safe. */
const char *tase_strerror(int err);

/* Axis angle ranges of the spec (4.3.3, GEOREFERENCE_DATA bytes 56-59):
 * pan "from -180 to 180", tilt "from -270 to 90" degrees. Tilt covers a
 * whole turn from -270 to 90: the default tilt no-go zone (4.4.3: centre
 * 90, range 60) forbids 60..90 and -270..-240 of it. The host role
 * (tase_command_check(), tase/codec.h), the tools and the simulator check
 * commands and report angles in these ranges; TASE_*_CDEG are the same in
 * 1/100 degree, as on the wire. */
#define TASE_PAN_MIN_DEG (-180.0)
#define TASE_PAN_MAX_DEG 180.0
#define TASE_TILT_MIN_DEG (-270.0)
#define TASE_TILT_MAX_DEG 90.0
#define TASE_PAN_MIN_CDEG (-18000)
#define TASE_PAN_MAX_CDEG 18000
#define TASE_TILT_MIN_CDEG (-27000)
#define TASE_TILT_MAX_CDEG 9000

#ifdef __cplusplus
}
#endif

#endif /* TASE_COMMON_H */
