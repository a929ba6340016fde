/* SPDX-License-Identifier: MIT */
/*
 * bsf_abi.h - what the library exports and the caps guard on its symbols.
 * Included by every public header; nothing here costs anything at run time.
 *
 * Export: a shared libbsf is built with hidden visibility, and only what the
 * public headers declare between BSF_BEGIN_DECLS and BSF_END_DECLS is
 * exported, so internal helpers (bsf_sinf, bsf_nms_beams, ...) never become
 * part of the ABI. A new public header must wrap its declarations in them.
 *
 * Caps guard: the layout of bsf_points_t, bsf_result_t, bsf_extractor_t, the
 * work structs, bsf_frame_t and the coder states follows from the caps in
 * bsf_config.h. A program compiled with other caps than the library it links
 * would hand the library objects of the wrong size, and the library would
 * write past their end. To make that impossible, every function that takes
 * such an object is renamed here: its symbol carries the caps, e.g.
 * bsf_extract_capsP1081K64S128F32C512 with the default caps. Both the library
 * and the program see this header, so when their caps agree the names
 * match, and when they differ the program fails to link with
 *     undefined reference to `bsf_extract_capsP361K64S128F32C512'
 * which names the caps the program was compiled with (P: BSF_MAX_POINTS,
 * K: BSF_MAX_KEYPOINTS, S: BSF_MAX_SEGMENTS, F: BSF_MAX_CTRL_PER_FEATURE,
 * C: BSF_MAX_CTRL_POINTS: the tags of BSF_CONFIG_CAPS in bsf_config.h, where
 * a new module's caps join the guard); `nm libbsf.a | grep _caps` shows the
 * library's. Source code keeps calling bsf_extract(); only the symbol
 * differs. This is why the caps must be written as plain decimal numbers
 * (bsf_config.h checks it). A new public function taking a caps-sized object
 * must be added below (docs/DESIGN.md, Caps guard).
 */
#ifndef BSF_ABI_H
#define BSF_ABI_H

#include "bsf_config.h"

/* ---- Export --------------------------------------------------------------- */

/* BSF_BUILDING_SHARED is set by the build when it makes a shared libbsf with
 * -fvisibility=hidden; for users and static builds this is plain extern "C". */
#if (defined(__GNUC__) || defined(__clang__)) && defined(BSF_BUILDING_SHARED)
#define BSF_VISIBILITY_PUSH_ _Pragma("GCC visibility push(default)")
#define BSF_VISIBILITY_POP_ _Pragma("GCC visibility pop")
#else
#define BSF_VISIBILITY_PUSH_
#define BSF_VISIBILITY_POP_
#endif

#ifdef __cplusplus
#define BSF_BEGIN_DECLS                                                                            \
    extern "C" {                                                                                   \
    BSF_VISIBILITY_PUSH_
#define BSF_END_DECLS                                                                              \
    BSF_VISIBILITY_POP_                                                                            \
    }
#else
/** Opens the public declarations of a header: exported, C linkage. */
#define BSF_BEGIN_DECLS BSF_VISIBILITY_PUSH_
/** Closes what BSF_BEGIN_DECLS opened. */
#define BSF_END_DECLS BSF_VISIBILITY_POP_
#endif

/* ---- Caps guard ----------------------------------------------------------- */

/* Each cap of BSF_CONFIG_CAPS as ", tag value" (P1081), then all of them
 * pasted behind fn_caps: up to 15 caps, the slots left over empty. */
#define BSF_CAPS_CAT_(a, b) BSF_CAPS_CAT2_(a, b)
#define BSF_CAPS_CAT2_(a, b) a##b
#define BSF_CAPS_ITEM_(tag, cap) , BSF_CAPS_CAT_(tag, cap)
#define BSF_CAPS_JOIN_(...) BSF_CAPS_JOIN16_(__VA_ARGS__, , , , , , , , , , , , , , , , )
#define BSF_CAPS_JOIN16_(a, b, c, d, e, f, g, h, i, j, k, l, m, n, o, p, ...)                      \
    a##b##c##d##e##f##g##h##i##j##k##l##m##n##o##p
/** The symbol of function fn for the caps of this translation unit. */
#define BSF_CAPS_NAME(fn) BSF_CAPS_JOIN_(fn##_caps BSF_CONFIG_CAPS(BSF_CAPS_ITEM_))

/* Every public function whose arguments include a caps-sized object. */
#define bsf_scan_to_points BSF_CAPS_NAME(bsf_scan_to_points)
#define bsf_falko_detect BSF_CAPS_NAME(bsf_falko_detect)
#define bsf_lc_detect BSF_CAPS_NAME(bsf_lc_detect)
#define bsf_bid_detect BSF_CAPS_NAME(bsf_bid_detect)
#define bsf_segment_sved BSF_CAPS_NAME(bsf_segment_sved)
#define bsf_segment_rpos BSF_CAPS_NAME(bsf_segment_rpos)
#define bsf_segment_classify BSF_CAPS_NAME(bsf_segment_classify)
#define bsf_pdm_fit BSF_CAPS_NAME(bsf_pdm_fit)
#define bsf_pdm_fit_anchored BSF_CAPS_NAME(bsf_pdm_fit_anchored)
#define bsf_extractor_init BSF_CAPS_NAME(bsf_extractor_init)
#define bsf_extract BSF_CAPS_NAME(bsf_extract)
#define bsf_metrics_counts BSF_CAPS_NAME(bsf_metrics_counts)
#define bsf_frame_encode BSF_CAPS_NAME(bsf_frame_encode)
#define bsf_frame_encode_sink BSF_CAPS_NAME(bsf_frame_encode_sink)
#define bsf_frame_decode BSF_CAPS_NAME(bsf_frame_decode)
#define bsf_decoder_init BSF_CAPS_NAME(bsf_decoder_init)
#define bsf_decoder_feed BSF_CAPS_NAME(bsf_decoder_feed)

/* The map's objects also follow the map caps (M: BSF_MAP_MAX_FEATURES, Q:
 * BSF_MAP_MAX_CTRL, O: BSF_MAP_MAX_OPS, R: BSF_MAP_RX_MAX_FEATURES, Z:
 * BSF_MAP_RX_MAX_CTRL), so their symbols carry those too. */
/* A module's calls: the scan caps, an underscore, then the module's own caps
 * (bsf_config.h, BSF_CONFIG_MAP_CAPS / BSF_CONFIG_ALIGN_CAPS), e.g.
 * bsf_map_fuse_capsP1081K64S128F32C512_M256Q2048O16R8192Z32768. */
/* One joining macro per level: a macro is not expanded again inside its own expansion. */
#define BSF_CAPS_JOIN_MAP_(...) BSF_CAPS_JOIN16_(__VA_ARGS__, , , , , , , , , , , , , , , , )
#define BSF_CAPS_JOIN_ALIGN_(...) BSF_CAPS_JOIN16_(__VA_ARGS__, , , , , , , , , , , , , , , , )
#define BSF_MAP_CAPS_NAME(fn)                                                                      \
    BSF_CAPS_JOIN_MAP_(BSF_CAPS_NAME(fn), _ BSF_CONFIG_MAP_CAPS(BSF_CAPS_ITEM_))
#define BSF_ALIGN_CAPS_NAME(fn)                                                                    \
    BSF_CAPS_JOIN_ALIGN_(BSF_MAP_CAPS_NAME(fn), _ BSF_CONFIG_ALIGN_CAPS(BSF_CAPS_ITEM_))

#define bsf_map_init BSF_MAP_CAPS_NAME(bsf_map_init)
#define bsf_map_fuse BSF_MAP_CAPS_NAME(bsf_map_fuse)
#define bsf_map_encode BSF_MAP_CAPS_NAME(bsf_map_encode)
#define bsf_map_pending BSF_MAP_CAPS_NAME(bsf_map_pending)
#define bsf_map_feature_count BSF_MAP_CAPS_NAME(bsf_map_feature_count)
#define bsf_map_feature_ctrl BSF_MAP_CAPS_NAME(bsf_map_feature_ctrl)
#define bsf_map_feature_q BSF_MAP_CAPS_NAME(bsf_map_feature_q)
#define bsf_map_rx_init BSF_MAP_CAPS_NAME(bsf_map_rx_init)
#define bsf_map_rx_apply BSF_MAP_CAPS_NAME(bsf_map_rx_apply)
#define bsf_map_rx_id_limit BSF_MAP_CAPS_NAME(bsf_map_rx_id_limit)
#define bsf_map_rx_feature_ctrl BSF_MAP_CAPS_NAME(bsf_map_rx_feature_ctrl)
#define bsf_map_rx_feature_q BSF_MAP_CAPS_NAME(bsf_map_rx_feature_q)
#define bsf_map_rx_note_loss BSF_MAP_CAPS_NAME(bsf_map_rx_note_loss)
#define bsf_map_rx_feature_state BSF_MAP_CAPS_NAME(bsf_map_rx_feature_state)

/* Alignment's work area also follows the alignment caps (A: BSF_ALIGN_MAX_POINTS,
 * V: BSF_ALIGN_MAX_VERTICES, S: BSF_ALIGN_MAX_SEGS, G: BSF_ALIGN_GRID, E:
 * BSF_ALIGN_MAX_ENTRIES) and takes the map, so its symbols carry all three sets. */
#define bsf_align_points BSF_ALIGN_CAPS_NAME(bsf_align_points)
#define bsf_align_features BSF_ALIGN_CAPS_NAME(bsf_align_features)

#endif /* BSF_ABI_H */
