/* SPDX-License-Identifier: MIT */
/*
 * bsf_fit.h - fit a clamped uniform quadratic B-spline (bsf_bspline.h) to
 * the points of one segment: LSBA (least squares, 4 control points, the
 * paper's baseline) and PDM (point distance minimisation with boundary,
 * vertex and precision control points, the default; docs/DESIGN.md, "PDM and
 * refinement").
 *
 * Inputs are compact arrays of a segment's valid points in scan order.
 * Coordinates must be finite with magnitude <= BSF_FIT_MAX_COORD; fits are
 * computed relative to the first point, so large offsets cost no accuracy
 * beyond what float storage of the inputs already lost.
 */
#ifndef BSF_FIT_H
#define BSF_FIT_H

#include "bsf_common.h"

BSF_BEGIN_DECLS

/** Largest accepted |x| or |y| of an input point, metres. */
#define BSF_FIT_MAX_COORD 1.0e6f

/** Hard cap on PDM iterations per solve (size of the RMS history). */
#define BSF_PDM_MAX_ITERATIONS 128

/** Most vertices one PDM feature can hold (each is stored twice, plus two boundary points). */
#define BSF_PDM_MAX_VERTICES ((BSF_MAX_CTRL_PER_FEATURE - 2) / 2)

/** Most fragments of one PDM feature. */
#define BSF_PDM_MAX_FRAGMENTS (BSF_PDM_MAX_VERTICES + 1)
/** Longest bsf_pdm_params_t.bias_window (points). */
#define BSF_PDM_MAX_BIAS_WINDOW 32u

/**
 * LSBA: least-squares clamped quadratic B-spline with 4 control points.
 * Parameters are the chord lengths scaled to [0, 1]; the normal equations
 * (B^T B) P = B^T X are solved by Cholesky.
 *
 * E_curve is the RMS distance of the points to the curve at their
 * footpoints: each chord parameter is refined by Newton steps towards the
 * nearest curve point (never moving away), so E_curve is comparable with
 * PDM's.
 *
 * @param pts         n points, metres
 * @param n           number of points, 4..BSF_MAX_POINTS
 * @param ctrl_out    4 control points out, metres
 * @param e_curve_out RMS footpoint distance out, metres; may be NULL
 * @return BSF_OK; BSF_ERR_ARG for NULL pts/ctrl_out or a non-finite or too
 *         large coordinate; BSF_ERR_CAPACITY when n > BSF_MAX_POINTS;
 *         BSF_ERR_DEGENERATE when n < 4 or all points coincide;
 *         BSF_ERR_NUMERIC when the solve fails. Outputs untouched on error.
 */
BSF_NODISCARD bsf_status_t bsf_lsba_fit(const bsf_point_t *pts, size_t n, bsf_point_t ctrl_out[4],
                                        float *e_curve_out);

/** Runtime parameters of PDM. Get defaults from bsf_pdm_params_default(). */
typedef struct {
    /** Refinement off: one precision control point per this many metres of a
     *  fragment's chord (at least one). Metres, > 0. Default 1.0. */
    float precision_spacing;
    /** Bending weight per metre of segment length: lambda = this * L, where L
     *  is the polyline length. >= 0 and <= 1. Default 1e-6 (docs/DESIGN.md). */
    float lambda_per_metre;
    /** Stop when the RMS improves by less than this fraction in one
     *  iteration. In (0, 1). Default 0.01. */
    float rel_tol;
    /** Error-driven refinement target, metres, > 0. Default 0.03 (the first
     *  release had 0.015: tighter than the paper's accuracy level, 15.8-21.4 mm
     *  indoors, so refinement spent control points on range noise; with the
     *  systematic-deviation test below, curves follow curved walls and corners
     *  at this looser target; docs/TABLE1.md and docs/GROUND_TRUTH.md have the
     *  measurements). bsf_params_default keeps 0.025 for FALKO and BID. */
    float target_rms;
    /** Most PDM iterations of the first solve, 1..BSF_PDM_MAX_ITERATIONS.
     *  Default 2. With refinement a solve stops early once every fragment
     *  meets target_rms. Measured on Intel (FALKO-SVED-PDM, bsf extract +
     *  metrics): the defaults give compactness 0.159 and accuracy 14.0 mm. */
    uint16_t max_iterations;
    /** Most PDM iterations after each refinement step (warm-started from the
     *  previous footpoints), 1..BSF_PDM_MAX_ITERATIONS. Default 1. */
    uint16_t refine_iterations;
    /** Most stored control points of the feature (vertices count twice),
     *  3..BSF_MAX_CTRL_PER_FEATURE. Default BSF_MAX_CTRL_PER_FEATURE. */
    uint16_t max_ctrl;
    /** Newton steps per footpoint update, 1..8. Default 1. */
    uint8_t footpoint_steps;
    /** 1: error-driven refinement (default); 0: precision points by spacing. */
    uint8_t refine;
    /** Refinement also sees systematic deviation: a fragment needs another
     *  precision point, even when its RMS meets target_rms, while (1) the
     *  mean signed residual of some bias_window consecutive points exceeds
     *  both bias_ratio * target_rms and two standard errors of such a mean
     *  (fragment RMS / sqrt(bias_window)), or (2) a point lies more than
     *  3 * target_rms from the curve. Range noise averages out over the
     *  window, a curve that bulges off a curved wall or swings off the last
     *  points before a corner does not. With it and refine on (and max_ctrl above 3),
     *  a fragment without vertices whose first and last quarters of points
     *  (each at least 10 cm long) head more than 90 degrees apart starts
     *  with two spans instead of one: one quadratic span on a pillar's
     *  silhouette meets the target with its ends centimetres off, where
     *  the windowed mean does not see it. Points, 0 (off: RMS alone, as
     *  the paper) or 2..BSF_PDM_MAX_BIAS_WINDOW. Default 16. */
    uint8_t bias_window;
    /** Smallest windowed mean that counts, as a fraction of target_rms, in
     *  (0, 1]. Default 0.2 (6 mm at the default target). Unused when
     *  bias_window is 0. */
    float bias_ratio;
    /** Most footpoint passes over the points (bsf_pdm_info_t.iterations) of
     *  one fit near the target, 0 for no limit (default): a bound on the
     *  fit's time that trades closeness to target_rms for it (e_curve_out
     *  says how close). The first solve runs at most this many iterations
     *  (at least one); then a refinement round near the target (its
     *  fragment within twice target_rms) is not started, and a round's
     *  fresh fit from arc length is skipped, when it would pass the cap. A
     *  fragment still farther from its points keeps growing past the cap
     *  (one pass and one fit from arc length per round, at most one round
     *  per control point): cut off there, a curve could miss its points by
     *  decimetres. */
    uint16_t max_passes;
} bsf_pdm_params_t;

/** Fill *p with the defaults listed in bsf_pdm_params_t (no-op for NULL). */
void bsf_pdm_params_default(bsf_pdm_params_t *p);

/**
 * Check every field of *p against its documented range.
 * @return BSF_OK; BSF_ERR_ARG when p is NULL; BSF_ERR_PARAM for a value out of range.
 */
BSF_NODISCARD bsf_status_t bsf_pdm_params_check(const bsf_pdm_params_t *p);

/**
 * Working memory of bsf_pdm_fit, owned by the caller (static or on a task's
 * stack it does not overflow: 15268 bytes at the default caps). Its content
 * after a call describes the last fit (read-only for the caller).
 */
typedef struct {
    float band[BSF_MAX_CTRL_PER_FEATURE * 3];   /**< normal matrix, lower band (bw 2) */
    float factor[BSF_MAX_CTRL_PER_FEATURE * 3]; /**< its Cholesky factor */
    float rhs_x[BSF_MAX_CTRL_PER_FEATURE];      /**< right-hand sides, then solutions */
    float rhs_y[BSF_MAX_CTRL_PER_FEATURE];
    bsf_point_t ctrl[BSF_MAX_CTRL_PER_FEATURE];      /**< stored control points, relative */
    bsf_point_t ctrl_prev[BSF_MAX_CTRL_PER_FEATURE]; /**< before the current iteration */
    uint8_t unknown_of[BSF_MAX_CTRL_PER_FEATURE];    /**< unknown index of each stored one */
    uint16_t frag_first[BSF_PDM_MAX_FRAGMENTS];      /**< first point of each fragment */
    uint16_t frag_last[BSF_PDM_MAX_FRAGMENTS];       /**< last point of each fragment */
    uint8_t frag_precision[BSF_PDM_MAX_FRAGMENTS];   /**< precision points per fragment */
    float frag_rms[BSF_PDM_MAX_FRAGMENTS];           /**< RMS per fragment, metres; with
                                                          bias_window, at least its largest
                                                          windowed mean over bias_ratio */
    float frag_rms_prev[BSF_PDM_MAX_FRAGMENTS];      /**< before the current iteration */
    float rms_history[BSF_PDM_MAX_ITERATIONS]; /**< RMS after each accepted iteration of the last
                                                  solve */
    uint16_t n_history;                        /**< entries in rms_history */
    uint16_t n_fragments;
    uint16_t last_refined; /**< fragment that received the last refinement point, or 0xFFFF */
    /* The per-point arrays last, so the small fields above stay within one
     * load's reach of the struct's start (docs/PERFORMANCE.md, section 3). */
    float t[BSF_MAX_POINTS];      /**< footpoint parameter of each point */
    float t_prev[BSF_MAX_POINTS]; /**< parameters before the current iteration */
    float arc[BSF_MAX_POINTS];    /**< arc length of each point from its fragment's first point */
} bsf_pdm_work_t;

/** Outcome details of one bsf_pdm_fit call. */
typedef struct {
    uint32_t
        iterations; /**< PDM iterations run over all refinement rounds (an undone one counts) */
    uint32_t refinements; /**< precision control points added by refinement */
    uint32_t loaded;      /**< solves that needed the diagonal-loading retry */
} bsf_pdm_info_t;

/**
 * PDM fit of one segment (docs/DESIGN.md, "PDM and refinement").
 *
 * The stored control polygon is: boundary point, the first fragment's
 * precision points, vertex (twice), the next fragment's precision points,
 * ..., boundary point. Both copies of a vertex are one unknown, so the curve
 * passes through it with a straight span on each side. The first solve uses
 * start parameters from arc length along each fragment (corrected for the
 * non-uniform speed of straight spans at a vertex). Iterations alternate a
 * least-squares solve (with bending weight lambda) and a footpoint update
 * (Newton on the span, clamped to [0, 1], free to move into the neighbouring
 * span, never accepted when it moves the curve away; the first and last
 * points keep parameters 0 and 1 so the ends cannot drift past the data),
 * until the RMS improves by less than rel_tol or max_iterations is reached;
 * an iteration that raises the RMS (possible through the bending term) is
 * undone and ends the solve, so the RMS never increases.
 * With refinement, a solve also ends as soon as every fragment meets
 * target_rms. Then the worst fragment whose RMS exceeds target_rms (and whose
 * cap of one precision point per 4 of its points, and the control-point cap,
 * allow it) grows: while its RMS is above twice the target, by the points an
 * h^3 error law predicts to bring it down to 1.5 times the target (at
 * least one), and the new layout is fitted afresh from arc length (a warm start can
 * stay stuck on a corner the vertices miss); nearer the target, by exactly one point with a
 * warm start (parameters remapped fragment by fragment, refine_iterations
 * iterations), plus a fresh fit from arc length kept when it is better if the
 * fragment's RMS fell by less than 5 %. When that point gained less than 5 %
 * and, with bias_window on, only the point test keeps the fragment above
 * target, its farthest point lying alone (at least two points inside the
 * fragment, both neighbours under a quarter of its distance from the curve:
 * a stray return), the fragment is settled instead (no fresh fit, no more
 * points). This repeats until every fragment meets the target or none can
 * grow; the last point added is always a single step. A result above target_rms is therefore not an
 * error: compare e_curve_out.
 *
 * @param pts           n points of the segment in scan order, metres
 * @param n             3..BSF_MAX_POINTS
 * @param vertex_pos    n_vertex strictly ascending indices into pts, each in
 *                      [2, n - 3]; may be NULL when n_vertex is 0
 * @param n_vertex      0..BSF_PDM_MAX_VERTICES
 * @param p             parameters (checked), or NULL for the defaults
 * @param work          caller-owned working memory
 * @param ctrl_out      stored control points out, metres (vertex copies twice)
 * @param is_vertex_out 1 for both copies of a vertex, 0 otherwise; may be NULL
 * @param ctrl_cap      room in ctrl_out (and is_vertex_out)
 * @param n_ctrl_out    number of stored control points out
 * @param e_curve_out   E_curve: RMS distance of the points to the curve at
 *                      their footpoints, metres; may be NULL
 * @param info_out      iteration counts; may be NULL
 * @return BSF_OK; BSF_ERR_ARG for NULL required pointers, a non-finite or
 *         too large coordinate, or bad vertex positions; BSF_ERR_PARAM for bad
 *         parameters; BSF_ERR_CAPACITY when n > BSF_MAX_POINTS, n_vertex >
 *         BSF_PDM_MAX_VERTICES or the initial polygon needs more than
 *         max_ctrl control points; BSF_ERR_BUFFER when ctrl_cap is smaller than
 *         the result; BSF_ERR_DEGENERATE when n < 3 or all points coincide;
 *         BSF_ERR_NUMERIC when a solve fails after its retry. Outputs are
 *         untouched on error.
 */
BSF_NODISCARD bsf_status_t bsf_pdm_fit(const bsf_point_t *pts, size_t n, const uint16_t *vertex_pos,
                                       size_t n_vertex, const bsf_pdm_params_t *p,
                                       bsf_pdm_work_t *work, bsf_point_t *ctrl_out,
                                       uint8_t *is_vertex_out, size_t ctrl_cap, size_t *n_ctrl_out,
                                       float *e_curve_out, bsf_pdm_info_t *info_out);

/**
 * bsf_pdm_fit with each vertex anchored: vertex k is held near vertex_anchor[k]
 * (metres, same frame as pts) by a spring as strong as all the points
 * together in every solve, so it stays (within millimetres) at a corner
 * position found by the caller (for instance the intersection of
 * two wall lines, bsf_lc_detect's keypoint point) instead of drifting with
 * the points around it. vertex_anchor may be NULL (then this is exactly
 * bsf_pdm_fit). Anchors must be finite with |x|, |y| <= BSF_FIT_MAX_COORD
 * (else BSF_ERR_ARG); other arguments and results as bsf_pdm_fit.
 */
BSF_NODISCARD bsf_status_t bsf_pdm_fit_anchored(const bsf_point_t *pts, size_t n,
                                                const uint16_t *vertex_pos,
                                                const bsf_point_t *vertex_anchor, size_t n_vertex,
                                                const bsf_pdm_params_t *p, bsf_pdm_work_t *work,
                                                bsf_point_t *ctrl_out, uint8_t *is_vertex_out,
                                                size_t ctrl_cap, size_t *n_ctrl_out,
                                                float *e_curve_out, bsf_pdm_info_t *info_out);

BSF_END_DECLS

#endif /* BSF_FIT_H */
