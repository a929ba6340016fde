/* SPDX-License-Identifier: MIT */
/*
 * bsf_bid.h - BID, the B-spline interest point detector (docs/DESIGN.md,
 * "Methods"): the paper's deliberately expensive baseline corner detector.
 *
 * For every valid beam q, the points within r_q = neigh_a * exp(neigh_b *
 * range_q) (walking outwards in beam order) are fitted by PDM with a clamped
 * quadratic B-spline of four control points. The corner measure is
 *   N_q = |P1 - P2| / (|P0 - P1| + |P1 - P2| + |P2 - P3|):
 * a corner pulls the two middle control points together and N_q falls.
 * Interest points are the beams whose N_q is a local minimum below t_th,
 * after the same beam non-maxima suppression as FALKO.
 *
 * Deviation from the paper's description: it starts the curve with four
 * control points evenly spaced along the neighbourhood's principal axis and
 * takes the first footpoints from that start curve. On a sharp corner the
 * principal axis can lie along the corner's bisector, where that projection
 * folds the two walls onto each other (measured: 13 of 24 synthetic corners
 * missed at 181 beams). bsf starts PDM from chord-length parameters in beam
 * order instead (the first iterate is the least-squares fit), which misses 1
 * of 24. A straight neighbourhood then gives N_q near 1/2 (the least-squares
 * control points of a straight run sit at the Greville abscissae 0, 1/4, 3/4,
 * 1), not the 1/3 of an evenly spaced start polygon.
 */
#ifndef BSF_BID_H
#define BSF_BID_H

#include "bsf_common.h"
#include "bsf_scan.h"
#include "bsf_fit.h"

BSF_BEGIN_DECLS

/** BID parameters; start from bsf_bid_params_default(). */
typedef struct {
    float neigh_a;    /**< neighbourhood radius r = neigh_a * exp(neigh_b * range), metres (0.2) */
    float neigh_b;    /**< see neigh_a, 1/metres (0.07) */
    float t_th;       /**< N_q threshold, in (0, 1) (0.3, calibrated: see bsf_bid.c) */
    float nms_radius; /**< non-maxima suppression radius, metres, >= 0 (0.1) */
    uint16_t min_side_points; /**< neighbours needed on each side of q, >= 1 (2) */
    uint16_t
        max_iterations; /**< PDM iterations per neighbourhood, 1..BSF_PDM_MAX_ITERATIONS (10) */
    float rel_tol;      /**< PDM relative RMS improvement to stop, in (0, 1) (0.01) */
} bsf_bid_params_t;

/** The defaults listed beside each field of bsf_bid_params_t. */
bsf_bid_params_t bsf_bid_params_default(void);

/**
 * Check every field of *p against its documented range.
 * @return BSF_OK; BSF_ERR_ARG when p is NULL; BSF_ERR_PARAM for a value out of range.
 */
BSF_NODISCARD bsf_status_t bsf_bid_params_check(const bsf_bid_params_t *p);

/**
 * Scratch memory of bsf_bid_detect, owned by the caller; 26080 bytes at
 * BSF_MAX_POINTS = 1081. After a call, score[] holds N_q per beam (+inf
 * where none was computed).
 */
typedef struct {
    float score[BSF_MAX_POINTS];       /**< N_q per beam */
    uint16_t peak[BSF_MAX_POINTS];     /**< NMS output */
    bsf_point_t neigh[BSF_MAX_POINTS]; /**< one neighbourhood, beam order */
    bsf_pdm_work_t pdm;                /**< PDM working memory */
} bsf_bid_work_t;

/**
 * Detect BID interest points (corners) in a scan.
 *
 * @param pts     scan points (bsf_scan_to_points); count <= BSF_MAX_POINTS
 * @param p       parameters, or NULL for the defaults
 * @param work    scratch memory
 * @param out     keypoints, ascending by beam index (orientation 0, score N_q,
 *                radius r_q); may be NULL when out_cap is 0
 * @param out_cap capacity of out
 * @param n_out   number of keypoints found (also on BSF_ERR_CAPACITY)
 * @return BSF_OK; BSF_ERR_ARG when pts, work or n_out is NULL, out is NULL
 *         with out_cap > 0, or the angle increment is zero or not finite;
 *         BSF_ERR_PARAM when bsf_bid_params_check fails; BSF_ERR_CAPACITY when
 *         pts->count > BSF_MAX_POINTS, or more than out_cap keypoints were
 *         found (out then holds the out_cap strongest, lowest N_q first, ties
 *         to the lower beam, ascending by beam index; *n_out the total). A beam
 *         whose neighbourhood is too small or cannot be fitted is simply not
 *         a candidate.
 */
BSF_NODISCARD bsf_status_t bsf_bid_detect(const bsf_points_t *pts, const bsf_bid_params_t *p,
                                          bsf_bid_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                                          size_t *n_out);

BSF_END_DECLS

#endif /* BSF_BID_H */
