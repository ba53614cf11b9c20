/*
 * tase/version.h - the library's version (semantic versioning).
 *
 * This header is the one place the version is written: CMake's project()
 * reads it (so the CMake package, the pkg-config files and the Debian
 * packages carry the same number), and a copy of src/ + include/ built by
 * hand has it too. Also included by tase/common.h.
 *
 * Compare at build time with TASE_VERSION_NUMBER, e.g.
 *     #if TASE_VERSION_NUMBER >= 200  (0.2.0 or later)
 */
#ifndef TASE_VERSION_H
#define TASE_VERSION_H

/* Keep each of these three lines exactly "#define NAME <number>":
 * CMakeLists.txt parses them. */
#define TASE_VERSION_MAJOR 0
#define TASE_VERSION_MINOR 3
#define TASE_VERSION_PATCH 0

/* MAJOR * 10000 + MINOR * 100 + PATCH (minor and patch stay below 100). */
#define TASE_VERSION_NUMBER                                                                        \
    (TASE_VERSION_MAJOR * 10000 + TASE_VERSION_MINOR * 100 + TASE_VERSION_PATCH)

/* "MAJOR.MINOR.PATCH", built from the three numbers above so that it can
 * never disagree with them. */
#define TASE_VERSION_STR_(x) #x
#define TASE_VERSION_XSTR_(x) TASE_VERSION_STR_(x)
#define TASE_VERSION_STRING                                                                        \
    TASE_VERSION_XSTR_(TASE_VERSION_MAJOR)                                                         \
    "." TASE_VERSION_XSTR_(TASE_VERSION_MINOR) "." TASE_VERSION_XSTR_(TASE_VERSION_PATCH)

/* The ABI level: which layout of the public types and which function
 * signatures these headers describe. It is raised whenever a release
 * changes the layout (size or members) of a public type or the signature
 * of a public function, and only then, so two releases with the same
 * level can be mixed. The initialisers of the instances an application
 * allocates and the library fills link under names that carry it
 * (tase_rx_init -> tase_rx_init_abi3; the list is in tase/config.h), so
 * headers of one level used with the library of another, such as a stale
 * copy in /usr/local/include, fail to link instead of overrunning memory:
 *     undefined reference to `tase_rx_init_abi3'
 * Levels:
 *   1  0.1.0, the first release (its initialisers link under their plain
 *      names, tase_rx_init; sizeof(tase_rx_t) 328 on x86-64).
 *   2  0.2.0: the greedy receiver (sizeof(tase_rx_t) 296 on x86-64)
 *      and the other changes CHANGELOG.md lists under 0.2.0.
 *   3  0.3.0: the receiver's time bound and bounded calls (sizeof(tase_rx_t) 360),
 *      tase_port_t's bytes_per_s and the other changes under 0.3.0.
 * Keep it a plain decimal number: it is pasted into link names. */
#define TASE_ABI_LEVEL 3

#endif /* TASE_VERSION_H */
