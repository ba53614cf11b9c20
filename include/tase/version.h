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
#define TASE_VERSION_MINOR 2
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

#endif /* TASE_VERSION_H */
