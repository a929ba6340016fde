/* SPDX-License-Identifier: MIT */
/*
 * det_core.h - the host/target determinism workload: scans (the demo office
 * simulated by tools/bsf_scene in double precision, or recorded Intel scans
 * handed over as float bit patterns) extracted with two methods, encoded
 * into frames, and decoded again. FNV-1a hashes of the ranges, of every
 * frame byte and of the decoded values. Every float is hashed as its IEEE
 * bit pattern in little-endian byte order, so a hash means the same on a
 * big-endian target.
 */
#ifndef BSF_DET_CORE_H
#define BSF_DET_CORE_H

#include <stddef.h>
#include <stdint.h>

#include "bsf/bsf.h"

/** Scans of the demo loop used (every 60 / DET_SCANS-th pose of `bsf demo`). */
#define DET_SCANS 6u
/** Beams per scan, as in `bsf demo`. */
#define DET_BEAMS 361u
/** Methods run on each scan: FALKO-SVED-PDM and RPOS-LSBA. */
#define DET_METHODS 2u

typedef struct {
    uint32_t ranges_hash;    /**< FNV-1a of the float bits (little-endian) of every range */
    uint32_t stream_hash;    /**< FNV-1a of every encoded frame byte, in order */
    uint32_t decoded_hash;   /**< FNV-1a of the decoded frames' values (det_hash_frame) */
    uint32_t stream_bytes;   /**< total frame bytes */
    uint32_t n_features;     /**< features over all frames */
    uint32_t n_ctrl;         /**< control points over all frames */
    uint32_t frames_decoded; /**< frames the decoder delivered (2 per scan when all is well) */
} det_summary_t;

/** FNV-1a, 32 bit, continued from h (start with DET_FNV_INIT). */
#define DET_FNV_INIT 2166136261u
uint32_t det_fnv1a(uint32_t h, const uint8_t *p, size_t n);

/** FNV-1a over n floats, each as its 32-bit pattern in little-endian order. */
uint32_t det_hash_floats(uint32_t h, const float *p, size_t n);

/** FNV-1a over a 32-bit value in little-endian order. */
uint32_t det_hash_u32(uint32_t h, uint32_t v);

/** Simulate scan k (0..DET_SCANS-1) of the demo loop into ranges[DET_BEAMS]. */
bsf_status_t det_simulate(unsigned k, float *ranges, bsf_scan_t *scan);

/**
 * Run the demo workload. ranges_in: DET_SCANS * DET_BEAMS ranges to use
 * instead of simulating (NULL: simulate here). frame_cb (may be NULL) sees
 * each frame's bytes.
 * @return BSF_OK or the first failing status.
 */
bsf_status_t det_run(const float *ranges_in, det_summary_t *out,
                     void (*frame_cb)(void *ctx, const uint8_t *frame, size_t len), void *ctx);

/** One recorded scan as the host read it from a log (all floats as bits). */
typedef struct {
    uint32_t count;           /**< beams */
    uint32_t angle_min;       /**< float bits, radians */
    uint32_t angle_increment; /**< float bits, radians */
    uint32_t range_max;       /**< float bits, metres */
    uint32_t pose_x;          /**< float bits, metres */
    uint32_t pose_y;          /**< float bits, metres */
    uint32_t pose_theta;      /**< float bits, radians */
    uint32_t timestamp_ms;    /**< since the first scan used */
} det_log_scan_t;

/**
 * Run the workload on n recorded scans; scan k's ranges start at
 * range_bits + sum of the earlier counts (float bit patterns).
 * @return BSF_OK or the first failing status.
 */
bsf_status_t det_run_log(const det_log_scan_t *scans, size_t n, const uint32_t *range_bits,
                         det_summary_t *out);

/** Results of the map workload (det_run_map, det_run_map_log). */
typedef struct {
    uint32_t stream_hash;  /**< FNV-1a of every map frame byte, in order */
    uint32_t stream_bytes; /**< map frame bytes */
    uint32_t frames;       /**< map frames written */
    uint32_t align_hash;   /**< FNV-1a of each alignment's pose bits, decline reason, matches */
    uint32_t rx_hash;      /**< FNV-1a of the receiver's quantised points, by feature id */
    uint32_t rx_points;    /**< points the receiver holds at the end */
    uint32_t n_accepted;   /**< alignments accepted */
} det_map_summary_t;

/**
 * The map workload on the demo scans, three rounds (ranges_in as for det_run; NULL:
 * simulate): each scan extracted with the default method, aligned to the map
 * from a prior off its true pose, fused at the aligned pose, a map frame
 * written (snapshots on) and applied to a receiver.
 * @return BSF_OK or the first failing status.
 */
bsf_status_t det_run_map(const float *ranges_in, det_map_summary_t *out);

/** The map workload on n recorded scans (as det_run_log), poses from the log. */
bsf_status_t det_run_map_log(const det_log_scan_t *scans, size_t n, const uint32_t *range_bits,
                             det_map_summary_t *out);

#endif /* BSF_DET_CORE_H */
