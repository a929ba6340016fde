/* SPDX-License-Identifier: MIT */
/*
 * bsf_falko.h - FALKO corner (keypoint) detector, compatible with the
 * reference FALKOLib (dlr1516/falkolib, commit 836b412c) at its defaults.
 *
 * Given the same scan and the default parameters, bsf_falko_detect returns
 * the same keypoint beam indices as FALKOLib's FALKOExtractor::extract. The
 * three reference quirks that decide which beams win are kept in the default
 * mode on purpose:
 *  - scoreMax is per scan (the largest raw score of this scan, from 0), so the
 *    threshold is relative to the scan;
 *  - the sector distance uses C's truncating `%`:
 *    d(a,b) = |((a - b) + S/2) % S - S/2|, which is not a true circular
 *    distance when a - b < -S/2 (set circular_sector_distance for the paper's
 *    true circular distance; never the default);
 *  - after non-maxima suppression, neighbouring candidates with equal scores
 *    collapse to about the middle one (plateau merge).
 * The reference computes in double; this port computes in float. See
 * src/bsf_falko.c for where the two can disagree.
 *
 * Full-circle scans (bsf_points_full_circle: the beams cover 2 pi within one
 * increment): the neighbourhood window wraps through the seam between the
 * last and the first beam, so a corner at the seam has neighbours on both
 * sides (FALKOLib clamps the window to the scan; on every scan that does not
 * cover the full circle this port still does, and gives its keypoints).
 * Of two keypoints facing each other across the seam within the
 * suppression window, only the stronger is kept.
 */
#ifndef BSF_FALKO_H
#define BSF_FALKO_H

#include "bsf_common.h"
#include "bsf_scan.h"

BSF_BEGIN_DECLS

/** FALKO parameters; start from bsf_falko_params_default(). */
typedef struct {
    int min_score_th; /**< keypoint threshold, percent of scoreMax, 0..100 (50) */
    float min_range;  /**< beams with range below are never keypoints, metres (0) */
    float max_range;  /**< beams with range above are never keypoints, metres (30) */
    int subbeam;      /**< non-zero: refine the keypoint position by two line fits (1) */
    float nms_radius; /**< non-maxima suppression radius, metres (0.1) */
    float neigh_a;    /**< neighbourhood radius r = neigh_a * exp(neigh_b * range), metres (0.1) */
    float neigh_b;    /**< see neigh_a, 1/metres (0.07) */
    int neigh_min_points; /**< points needed on each side of the apex, >= 1 (2) */
    float b_ratio;        /**< triangle test: base and height must be >= r / b_ratio (2.5) */
    int grid_sectors;     /**< number of angular sectors, 2..64 (16) */
    int circular_sector_distance; /**< non-zero: the paper's true circular sector distance
                                       instead of FALKOLib's truncating one (0) */
} bsf_falko_params_t;

/** The FALKOLib defaults listed beside each field of bsf_falko_params_t. */
bsf_falko_params_t bsf_falko_params_default(void);

/**
 * Check a parameter set.
 *
 * @return BSF_OK; BSF_ERR_ARG when p is NULL; BSF_ERR_PARAM when a value is
 *         not finite or outside its range: min_score_th outside 0..100,
 *         min_range < 0, max_range <= min_range, nms_radius < 0,
 *         neigh_a <= 0, neigh_b < 0, neigh_min_points < 1, b_ratio <= 0,
 *         grid_sectors outside 2..64.
 */
BSF_NODISCARD bsf_status_t bsf_falko_params_check(const bsf_falko_params_t *p);

/**
 * Scratch memory of bsf_falko_detect, owned by the caller (static or on a
 * task's stack); its content between calls is irrelevant. About 25 KiB at
 * BSF_MAX_POINTS = 1081.
 */
typedef struct {
    float score[BSF_MAX_POINTS];   /**< per-beam raw score, then NMS strength */
    uint16_t peak[BSF_MAX_POINTS]; /**< one neighbourhood's beams, then NMS candidates, then
                                        keypoint beams */
    int8_t sector[BSF_MAX_POINTS]; /**< angular sectors of one neighbourhood */
    /* Per beam, a bracket of its neighbourhood radius (see bsf_falko.c). */
    float in2[BSF_MAX_POINTS];          /**< squared distance certainly inside */
    float out2[BSF_MAX_POINTS];         /**< squared distance certainly outside */
    float lim[BSF_MAX_POINTS];          /**< smallest triangle limit */
    uint16_t win_hi[BSF_MAX_POINTS];    /**< window of the largest radius */
    uint16_t win_inner[BSF_MAX_POINTS]; /**< window of the smallest radius, at least */
    /** How often each sector value occurs among the neighbours seen so far
     *  (sector values lie in -33..96, stored offset by 33), and the values that
     *  occur: the score sums sector distances per value, not per pair. */
    uint16_t sector_count[130];
    int8_t sector_seen[130];
    int8_t sector_dist[259]; /**< sector distance per difference of sector values, or -1 */
} bsf_falko_work_t;

/**
 * Detect FALKO keypoints (corners) in a scan.
 *
 * Only valid beams (pts->valid) are used, as apexes and as neighbours. For
 * non-maxima suppression an invalid beam counts as a beam far away (window
 * 0), which is how FALKOLib treats the datasets' no-return codes (81.83 m).
 * FALKOLib uses every reading as a neighbour, also those beyond max_range;
 * to match it exactly, build the points with a range_max above
 * max_range + r(max_range) (e.g. 81 m, just below the no-return code), not
 * with range_max = max_range.
 * The angle increment may be negative (clockwise scans); its magnitude is used.
 *
 * @param pts     scan points (bsf_scan_to_points); count <= BSF_MAX_POINTS
 * @param p       parameters (bsf_falko_params_default() for FALKOLib's)
 * @param work    scratch memory
 * @param out     keypoints, ascending by beam index; may be NULL when out_cap is 0
 * @param out_cap capacity of out
 * @param n_out   number of keypoints found (also on BSF_ERR_CAPACITY)
 * @return BSF_OK; BSF_ERR_ARG when pts, p, work or n_out is NULL, out is NULL
 *         with out_cap > 0, or the angle increment is zero or not finite;
 *         BSF_ERR_PARAM when bsf_falko_params_check fails; BSF_ERR_CAPACITY
 *         when pts->count > BSF_MAX_POINTS, or more than out_cap keypoints
 *         were found (out then holds the out_cap strongest, lowest raw score
 *         first, ties to the lower beam, ascending by beam index; *n_out the
 *         total), or a raw score exceeds 2^24 (only possible with huge, dense
 *         neighbourhoods). On the other errors *n_out is 0 (when n_out is not
 *         NULL). A scan with fewer than 2 * neigh_min_points + 1 valid beams
 *         gives BSF_OK and no keypoint.
 */
BSF_NODISCARD bsf_status_t bsf_falko_detect(const bsf_points_t *pts, const bsf_falko_params_t *p,
                                            bsf_falko_work_t *work, bsf_keypoint_t *out,
                                            size_t out_cap, size_t *n_out);

BSF_END_DECLS

#endif /* BSF_FALKO_H */
