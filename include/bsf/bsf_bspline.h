/* SPDX-License-Identifier: MIT */
/*
 * bsf_bspline.h - clamped uniform quadratic B-splines in the plane.
 *
 * A curve has n_ctrl = n + 1 control points (n_ctrl >= 3) and n_ctrl - 2
 * spans over the parameter t in [0, 1]; its knots are
 * {0, 0, 0, 1/(n-1), ..., (n-2)/(n-1), 1, 1, 1}. Span s covers
 * t in [s/(n-1), (s+1)/(n-1)] and is shaped by control points s, s+1, s+2.
 * Evaluation uses the closed form of each span (docs/DESIGN.md, appendix).
 * A control point stored twice in a row (a vertex) is passed through, with a
 * straight span on each side.
 */
#ifndef BSF_BSPLINE_H
#define BSF_BSPLINE_H

#include "bsf_common.h"

BSF_BEGIN_DECLS

/**
 * Span that holds parameter t, and t's local coordinate u in [0, 1] inside it.
 *
 * @param n_ctrl number of control points (>= 3)
 * @param t      curve parameter; values outside [0, 1] (or NaN) are clamped
 *               to the nearest end (NaN goes to 0)
 * @param u_out  receives u = t * (n_ctrl - 2) - span; may be NULL
 * @return the span index in [0, n_ctrl - 3]; 0 when n_ctrl < 3
 */
size_t bsf_bspline_span(size_t n_ctrl, float t, float *u_out);

/**
 * The three non-zero basis functions of one span at local coordinate u, and
 * optionally their first and second derivatives with respect to t (not u).
 * basis[k] weights control point span + k. The basis sums to 1.
 *
 * @param n_ctrl number of control points (>= 3; smaller values give zeros)
 * @param span   span index in [0, n_ctrl - 3] (larger values give zeros)
 * @param u      local coordinate in [0, 1]
 * @param basis  3 values out (required)
 * @param d1     3 first derivatives d/dt out, or NULL
 * @param d2     3 second derivatives d2/dt2 out, or NULL
 */
void bsf_bspline_basis(size_t n_ctrl, size_t span, float u, float basis[3], float d1[3],
                       float d2[3]);

/**
 * Evaluate a curve at parameter t: point, and optionally the first and second
 * derivatives with respect to t (metres per unit t, and per unit t squared).
 *
 * @param ctrl   n_ctrl control points, metres
 * @param n_ctrl number of control points, 3..BSF_MAX_CTRL_PER_FEATURE
 * @param t      parameter in [0, 1] (finite; clamped into [0, 1])
 * @param pt     curve point out (required)
 * @param d1     first derivative out, or NULL
 * @param d2     second derivative out, or NULL
 * @return BSF_OK; BSF_ERR_ARG when ctrl or pt is NULL or t is not finite;
 *         BSF_ERR_DEGENERATE when n_ctrl < 3; BSF_ERR_CAPACITY when
 *         n_ctrl > BSF_MAX_CTRL_PER_FEATURE. Outputs are untouched on error.
 */
BSF_NODISCARD bsf_status_t bsf_bspline_eval(const bsf_point_t *ctrl, size_t n_ctrl, float t,
                                            bsf_point_t *pt, bsf_point_t *d1, bsf_point_t *d2);

BSF_END_DECLS

#endif /* BSF_BSPLINE_H */
