/* SPDX-License-Identifier: MIT */
/*
 * bsf_config.h - compile-time capacities of the bsf library.
 *
 * Every array the library uses lives in a caller-owned object whose size
 * follows from the caps below, so sizeof() of that object is the whole RAM
 * cost. Override any cap by defining it before this header is read, either
 * on the compiler command line (-DBSF_MAX_POINTS=361) or in a header of your
 * own named by BSF_CONFIG_HEADER (-DBSF_CONFIG_HEADER='"my_bsf_config.h"'),
 * which is included first.
 *
 * The library and every translation unit that uses its headers must see the
 * same values, and the link enforces it: the symbols of the functions that
 * take caps-sized objects carry the caps (bsf_abi.h), so a program compiled
 * with other caps (or another BSF_CONFIG_HEADER that sets other caps) than
 * the library fails to link with an undefined reference to a name such as
 * bsf_extract_capsP361K64S128F32C512, instead of running and corrupting
 * memory. Rebuild the library with the program's caps (or the program with
 * the library's). For that reason each cap must be a plain decimal integer
 * (361, not 361u, 0x169 or (360 + 1)); a cap may also be a macro that
 * expands to one.
 *
 * Switches (each may be set on the command line or in BSF_CONFIG_HEADER):
 *
 *   BSF_MAX_POINTS, BSF_MAX_KEYPOINTS, BSF_MAX_SEGMENTS,
 *   BSF_MAX_CTRL_PER_FEATURE, BSF_MAX_CTRL_POINTS
 *       the caps: sizes of the caller-owned objects (below; BSF_CONFIG_CAPS
 *       lists them for the caps guard).
 *   BSF_CONFIG_METHODS
 *       the extraction methods compiled in (below).
 *   BSF_CONFIG_FIT_BINS (0 or 1)
 *       1 (default): bsf_params_t.fit_bin_length, the opt-in fit on bin
 *       means for dense scans, is compiled in; 0 leaves its code out (about
 *       1.1 KiB at -Os) and bsf_params_check refuses a non-zero
 *       fit_bin_length with BSF_ERR_UNSUPPORTED, as it refuses a method left
 *       out. CMake: -DBSF_FIT_BINS=OFF.
 *   BSF_CONFIG_COMPACT (0 or 1)
 *       1: code kept only for speed is compiled in its short form (one
 *       general loop instead of written-out special cases, no fast paths
 *       that a general path also covers, nibble-table CRC). Default: 1 when
 *       the compiler optimises for size (-Os, -Oz: __OPTIMIZE_SIZE__), else 0.
 *   BSF_CONFIG_SIMD (0 or 1)
 *       1: the SSE2 (x86) and NEON (Arm) paths where the target has them.
 *       Default: 1 unless BSF_CONFIG_COMPACT is 1.
 *
 * The build variants (BSF_CONFIG_COMPACT, BSF_CONFIG_SIMD) change speed and
 * code size only: every combination computes the same features and writes
 * the same bytes, and none changes an object's size, so a program need not
 * see the library's values (docs/DESIGN.md, Build variants).
 */
#ifndef BSF_CONFIG_H
#define BSF_CONFIG_H

#ifdef BSF_CONFIG_HEADER
#include BSF_CONFIG_HEADER
#endif

/** Largest number of beams in one scan (index space, valid or not). */
#ifndef BSF_MAX_POINTS
#define BSF_MAX_POINTS 1081
#endif

/** Largest number of interest points (corners) kept for one scan. */
#ifndef BSF_MAX_KEYPOINTS
#define BSF_MAX_KEYPOINTS 64
#endif

/** Largest number of kept (not wasted) segments, hence features, per scan. */
#ifndef BSF_MAX_SEGMENTS
#define BSF_MAX_SEGMENTS 128
#endif

/** Largest number of stored control points of one feature (a vertex counts twice). */
#ifndef BSF_MAX_CTRL_PER_FEATURE
#define BSF_MAX_CTRL_PER_FEATURE 32
#endif

/** Largest number of stored control points of one scan, all features together. */
#ifndef BSF_MAX_CTRL_POINTS
#define BSF_MAX_CTRL_POINTS 512
#endif

/* Fused map (bsf_map.h). The robot's map: */
/** Largest number of features of the robot's map held in RAM. */
#ifndef BSF_MAP_MAX_FEATURES
#define BSF_MAP_MAX_FEATURES 256
#endif

/** Pool of control points shared by the robot map's features (a vertex counts once). */
#ifndef BSF_MAP_MAX_CTRL
#define BSF_MAP_MAX_CTRL 2048
#endif

/** Largest number of merges queued between two map frames. */
#ifndef BSF_MAP_MAX_OPS
#define BSF_MAP_MAX_OPS 16
#endif

/** Largest feature id + 1 the receiver's map holds (features ever sent). */
#ifndef BSF_MAP_RX_MAX_FEATURES
#define BSF_MAP_RX_MAX_FEATURES 8192
#endif

/** Pool of control points of the receiver's map. */
#ifndef BSF_MAP_RX_MAX_CTRL
#define BSF_MAP_RX_MAX_CTRL 32768
#endif

/* Alignment of a scan to the map (bsf_align.h): */
/** Largest number of scan points one alignment uses (the rest are subsampled away). */
#ifndef BSF_ALIGN_MAX_POINTS
#define BSF_ALIGN_MAX_POINTS 128
#endif

/** Largest number of scan vertices, and of map vertices near the prior, one alignment uses. */
#ifndef BSF_ALIGN_MAX_VERTICES
#define BSF_ALIGN_MAX_VERTICES 64
#endif

/** Largest number of map chords (two per map span) near the prior one alignment holds. */
#ifndef BSF_ALIGN_MAX_SEGS
#define BSF_ALIGN_MAX_SEGS 1024
#endif

/** Cells per side of the correspondence grid of one alignment. */
#ifndef BSF_ALIGN_GRID
#define BSF_ALIGN_GRID 48
#endif

/** Entries (chord, cell) of that grid. */
#ifndef BSF_ALIGN_MAX_ENTRIES
#define BSF_ALIGN_MAX_ENTRIES 4096
#endif

/* Extraction methods compiled into the library: bit m of BSF_CONFIG_METHODS
 * stands for bsf_method_t m. Firmware that only ever runs one method sets
 * just its bit, so the link leaves the other detectors and fitters out (with
 * -ffunction-sections and --gc-sections); bsf_params_check, hence
 * bsf_extractor_init, then refuses a method left out with
 * BSF_ERR_UNSUPPORTED. Set it like a cap (-DBSF_CONFIG_METHODS=BSF_CONFIG_METHOD_LC,
 * or -DBSF_METHODS=lc-sved-pdm when configuring with CMake). Unlike the caps it
 * changes no object's size, so a program need not see the library's value;
 * the defaults of bsf_params_default for every method stay available. */
#define BSF_CONFIG_METHOD_FALKO 1 /**< BSF_METHOD_FALKO_SVED_PDM */
#define BSF_CONFIG_METHOD_BID 2   /**< BSF_METHOD_BID_SVED_PDM */
#define BSF_CONFIG_METHOD_RPOS 4  /**< BSF_METHOD_RPOS_LSBA */
#define BSF_CONFIG_METHOD_LC 8    /**< BSF_METHOD_LC_SVED_PDM, the default method */
/** Methods compiled in: every one unless chosen. */
#ifndef BSF_CONFIG_METHODS
#define BSF_CONFIG_METHODS 15
#endif

/** 1: the opt-in fit on bin means is compiled in (see the switches above). */
#ifndef BSF_CONFIG_FIT_BINS
#define BSF_CONFIG_FIT_BINS 1
#endif

/** 1: speed-only code in its short form (see the switches above). */
#ifndef BSF_CONFIG_COMPACT
#if defined(__OPTIMIZE_SIZE__)
#define BSF_CONFIG_COMPACT 1
#else
#define BSF_CONFIG_COMPACT 0
#endif
#endif

/** 1: SSE2 / NEON paths where the target has them (see the switches above). */
#ifndef BSF_CONFIG_SIMD
#if BSF_CONFIG_COMPACT
#define BSF_CONFIG_SIMD 0
#else
#define BSF_CONFIG_SIMD 1
#endif
#endif

/* Range checks: a bad value stops the build here rather than corrupting
 * memory at run time. Beam indices are stored as uint16_t. */
#if BSF_MAX_POINTS < 8 || BSF_MAX_POINTS > 65535
#error "BSF_MAX_POINTS must be in [8, 65535]"
#endif
#if BSF_MAX_KEYPOINTS < 1 || BSF_MAX_KEYPOINTS > BSF_MAX_POINTS
#error "BSF_MAX_KEYPOINTS must be in [1, BSF_MAX_POINTS]"
#endif
#if BSF_MAX_SEGMENTS < 1 || BSF_MAX_SEGMENTS > BSF_MAX_POINTS
#error "BSF_MAX_SEGMENTS must be in [1, BSF_MAX_POINTS]"
#endif
#if BSF_MAX_CTRL_PER_FEATURE < 4 || BSF_MAX_CTRL_PER_FEATURE > 64
#error "BSF_MAX_CTRL_PER_FEATURE must be in [4, 64]"
#endif
#if BSF_MAX_CTRL_POINTS < BSF_MAX_CTRL_PER_FEATURE || BSF_MAX_CTRL_POINTS > 65535
#error "BSF_MAX_CTRL_POINTS must be in [BSF_MAX_CTRL_PER_FEATURE, 65535]"
#endif

#if (BSF_CONFIG_COMPACT) != 0 && (BSF_CONFIG_COMPACT) != 1
#error "BSF_CONFIG_COMPACT must be 0 or 1"
#endif
#if (BSF_CONFIG_FIT_BINS) != 0 && (BSF_CONFIG_FIT_BINS) != 1
#error "BSF_CONFIG_FIT_BINS must be 0 or 1"
#endif
#if (BSF_CONFIG_SIMD) != 0 && (BSF_CONFIG_SIMD) != 1
#error "BSF_CONFIG_SIMD must be 0 or 1"
#endif
/* Map pools are indexed by uint16_t with 0xFFFF as "none". */
#if BSF_MAP_MAX_FEATURES < 1 || BSF_MAP_MAX_FEATURES > 65535
#error "BSF_MAP_MAX_FEATURES must be in [1, 65535]"
#endif
#if BSF_MAP_MAX_CTRL < 64 || BSF_MAP_MAX_CTRL > 65535
#error "BSF_MAP_MAX_CTRL must be in [64, 65535]"
#endif
#if BSF_MAP_MAX_OPS < 1 || BSF_MAP_MAX_OPS > 255
#error "BSF_MAP_MAX_OPS must be in [1, 255]"
#endif
#if BSF_MAP_RX_MAX_FEATURES < 1 || BSF_MAP_RX_MAX_FEATURES > 16777216
#error "BSF_MAP_RX_MAX_FEATURES must be in [1, 16777216]"
#endif
#if BSF_MAP_RX_MAX_CTRL < 64 || BSF_MAP_RX_MAX_CTRL > 65535
#error "BSF_MAP_RX_MAX_CTRL must be in [64, 65535]"
#endif
#if BSF_ALIGN_MAX_POINTS < 8 || BSF_ALIGN_MAX_POINTS > 4096
#error "BSF_ALIGN_MAX_POINTS must be in [8, 4096]"
#endif
#if BSF_ALIGN_MAX_VERTICES < 1 || BSF_ALIGN_MAX_VERTICES > 4096
#error "BSF_ALIGN_MAX_VERTICES must be in [1, 4096]"
#endif
#if BSF_ALIGN_MAX_SEGS < 16 || BSF_ALIGN_MAX_SEGS > 65535
#error "BSF_ALIGN_MAX_SEGS must be in [16, 65535]"
#endif
#if BSF_ALIGN_GRID < 4 || BSF_ALIGN_GRID > 255
#error "BSF_ALIGN_GRID must be in [4, 255]"
#endif
#if BSF_ALIGN_MAX_ENTRIES < 16 || BSF_ALIGN_MAX_ENTRIES > 65535
#error "BSF_ALIGN_MAX_ENTRIES must be in [16, 65535]"
#endif

#if (BSF_CONFIG_METHODS) < 1 || (BSF_CONFIG_METHODS) > 15
#error "BSF_CONFIG_METHODS must name at least one method and only BSF_CONFIG_METHOD_* bits"
#endif

/**
 * Every cap that sizes a caller-owned object, one X(tag, cap) each: the caps
 * guard (bsf_abi.h) puts each tag and value into the symbols, in this order
 * (P1081K64S128F32C512 with the defaults), and the check below holds them
 * to plain decimal spelling. A module's caps join by a line here (a tag of
 * its own, one capital letter; at most 15 caps in all); nothing else needs
 * to change for the guard (docs/DESIGN.md, Caps guard).
 */
#define BSF_CONFIG_CAPS(X)                                                                         \
    X(P, BSF_MAX_POINTS)                                                                           \
    X(K, BSF_MAX_KEYPOINTS)                                                                        \
    X(S, BSF_MAX_SEGMENTS)                                                                         \
    X(F, BSF_MAX_CTRL_PER_FEATURE)                                                                 \
    X(C, BSF_MAX_CTRL_POINTS)

/*
 * Caps of the modules built on a scan's result, in the same form: their calls
 * carry the scan caps and then, after an underscore, their own (bsf_abi.h:
 * BSF_MAP_CAPS_NAME, BSF_ALIGN_CAPS_NAME), so the scan functions' symbols do
 * not change with them. A new module declares its list here and one naming
 * macro in bsf_abi.h.
 */
#define BSF_CONFIG_MAP_CAPS(X)                                                                     \
    X(M, BSF_MAP_MAX_FEATURES)                                                                     \
    X(Q, BSF_MAP_MAX_CTRL)                                                                         \
    X(O, BSF_MAP_MAX_OPS)                                                                          \
    X(R, BSF_MAP_RX_MAX_FEATURES)                                                                  \
    X(Z, BSF_MAP_RX_MAX_CTRL)
#define BSF_CONFIG_ALIGN_CAPS(X)                                                                   \
    X(A, BSF_ALIGN_MAX_POINTS)                                                                     \
    X(V, BSF_ALIGN_MAX_VERTICES)                                                                   \
    X(S, BSF_ALIGN_MAX_SEGS)                                                                       \
    X(G, BSF_ALIGN_GRID)                                                                           \
    X(E, BSF_ALIGN_MAX_ENTRIES)

/* Plain decimal spelling: the caps become part of symbol names (see above).
 * Appending a 0 to a decimal literal multiplies it by ten; for any other
 * spelling this comparison fails or does not compile. */
#define BSF_CONFIG_CAT_(a, b) a##b
#define BSF_CONFIG_APPEND0_(x) BSF_CONFIG_CAT_(x, 0)
#define BSF_CONFIG_NOT_DECIMAL_(tag, cap) BSF_CONFIG_APPEND0_(cap) != (cap)*10 ||
#if BSF_CONFIG_CAPS(BSF_CONFIG_NOT_DECIMAL_) BSF_CONFIG_MAP_CAPS(BSF_CONFIG_NOT_DECIMAL_)          \
    BSF_CONFIG_ALIGN_CAPS(BSF_CONFIG_NOT_DECIMAL_) 0
#error "bsf caps must be plain decimal integers such as 361 (they become part of symbol names)"
#endif

#endif /* BSF_CONFIG_H */
