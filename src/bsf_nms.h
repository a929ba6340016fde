/* SPDX-License-Identifier: MIT */
/*
 * bsf_nms.h - non-maxima suppression over beam indices (internal, shared by
 * the FALKO and BID corner detectors).
 *
 * It reproduces FALKOLib's FALKOExtractor::NMSKeypoint: a scan in beam order
 * with a half-window that depends on each beam's range, followed by the
 * reference's plateau merge (runs of neighbouring candidates with equal
 * scores collapse to about their middle one).
 */
#ifndef BSF_NMS_H
#define BSF_NMS_H

#include "bsf/bsf_scan.h"

/** Which scores win. */
typedef enum {
    BSF_NMS_HIGHER_IS_BETTER = 0, /**< FALKO strength (scoreMax - raw) */
    BSF_NMS_LOWER_IS_BETTER = 1   /**< e.g. BID's N_q */
} bsf_nms_order_t;

/**
 * Half-window of beam i, in beams: floor(asin(radius / range_i) / |increment|),
 * with asin(0.8) when radius >= range_i; 0 for an invalid beam (it is treated
 * as a no-return reading far away, as FALKOLib sees the datasets' 81.83 m).
 * pts->angle_increment must be finite and non-zero.
 */
size_t bsf_nms_half_window(const bsf_points_t *pts, size_t i, float radius);

/**
 * Non-maxima suppression in beam space.
 *
 * Every beam 0..pts->count-1 takes part with score[i], including invalid and
 * rejected beams: encode a rejected beam as a score that cannot pass
 * `threshold` (FALKO gives it strength 0 with a threshold >= 0; a
 * lower-is-better caller can use +inf). A beam is a candidate when it is the
 * best within its half-window (ties: the reference's scan order rules) and
 * strictly better than `threshold`. Candidates with equal scores that follow
 * each other in the candidate list are merged to about the middle one.
 *
 * @param pts       points (ranges and validity give the window; count <= BSF_MAX_POINTS)
 * @param score     pts->count scores, not NaN
 * @param order     which direction is better
 * @param threshold candidates must be strictly better than this
 * @param radius    suppression radius, metres, >= 0
 * @param peak      out: at least pts->count entries, not overlapping score; it
 *                  also serves as scratch (the windows); on return its first
 *                  entries are the peaks, ascending beam indices
 * @return number of peaks written to peak
 */
size_t bsf_nms_beams(const bsf_points_t *pts, const float *score, bsf_nms_order_t order,
                     float threshold, float radius, uint16_t *peak);

/**
 * Keep the cap best of n_peak peaks (peak[] ascending beam indices, as
 * bsf_nms_beams leaves them): best by score[peak[k]] in the given order, ties
 * going to the lower beam index. The kept peaks stay in peak[0..return) in
 * ascending beam order. Used when a detector finds more keypoints than its
 * caller has room for, so the strongest corners survive the cap.
 * Scores must not be NaN. No extra memory; O(32 * n_peak).
 * @return min(n_peak, cap)
 */
size_t bsf_nms_keep_best(const float *score, bsf_nms_order_t order, uint16_t *peak, size_t n_peak,
                         size_t cap);

#endif /* BSF_NMS_H */
