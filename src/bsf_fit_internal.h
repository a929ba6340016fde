/* SPDX-License-Identifier: MIT */
/*
 * bsf_fit_internal.h - helpers shared by the spline fitters (not public).
 */
#ifndef BSF_FIT_INTERNAL_H
#define BSF_FIT_INTERNAL_H

#include "bsf/bsf_fit.h"

/* Basis of span `span` of a curve with n_span spans at local u, with first
 * and second derivatives with respect to u. All three arrays are required. */
void bsf_bspline_basis_u(size_t n_span, size_t span, float u, float b[3], float du[3],
                         float ddu[3]);

/* Point and u-derivatives of span `span` at local u (n_ctrl >= 3, span valid). */
void bsf_bspline_eval_u(const bsf_point_t *ctrl, size_t n_ctrl, size_t span, float u,
                        bsf_point_t *c, bsf_point_t *cu, bsf_point_t *cuu);

/* Move *t towards the footpoint of p (the nearest curve point) with at most
 * max_steps Newton steps; a step may land in a neighbouring span and is only
 * accepted when it brings the curve closer. Returns the squared distance at
 * the final *t, never larger than at the initial *t. */
float bsf_footpoint_refine(const bsf_point_t *ctrl, size_t n_ctrl, bsf_point_t p, float *t,
                           unsigned max_steps);

/* Add weight * w w^T to a lower band matrix of half-bandwidth 2 (stride 3)
 * and weight * w * (px, py) to the right-hand sides (when rx is not NULL),
 * where w holds three coefficients for the non-decreasing unknowns unk[0..2];
 * coefficients of a repeated unknown (a vertex stored twice) are summed. */
void bsf_fit_accumulate(float *band, float *rx, float *ry, const uint8_t unk[3], const float w[3],
                        float weight, float px, float py);

/* BSF_OK when all n points are finite with |x|, |y| <= BSF_FIT_MAX_COORD,
 * else BSF_ERR_ARG. */
bsf_status_t bsf_fit_check_points(const bsf_point_t *pts, size_t n);

/* PDM of one smooth curve (no vertex, no refinement) with n_ctrl control
 * points, the first solve at chord-length parameters along the points' order
 * (so the first iterate is the least-squares LSBA fit), then PDM iterations as
 * in bsf_pdm_fit with p's max_iterations, rel_tol, lambda_per_metre and
 * footpoint_steps (p is trusted: checked by the caller). Points are trusted
 * too (finite, checked by the caller). Used by BID. Returns BSF_OK,
 * BSF_ERR_ARG, BSF_ERR_CAPACITY, BSF_ERR_DEGENERATE (n < 3, n_ctrl < 3 or
 * all points equal) or BSF_ERR_NUMERIC. */
bsf_status_t bsf_pdm_fit_chord(const bsf_point_t *pts, size_t n, size_t n_ctrl,
                               const bsf_pdm_params_t *p, bsf_pdm_work_t *work,
                               bsf_point_t *ctrl_out, float *e_curve_out, uint32_t *iterations);

#endif /* BSF_FIT_INTERNAL_H */
