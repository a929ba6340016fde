/* SPDX-License-Identifier: MIT */
/*
 * bsf_align.h - align one scan to the fused map before fusing it, so that
 * odometry drift does not bend the map (docs/ALIGN.md explains the
 * method and its measurements).
 *
 * Given a scan (its valid points, or its features sampled along their
 * curves; both in the sensor frame), a pose prior (odometry) and the map
 * (bsf_map.h), bsf_align_points() / bsf_align_features() return a corrected
 * pose. Method: Gauss-Newton over (x, y, theta) on point-to-chord distances
 * (each map span is one chord between its knots, or two through its mid
 * point where it bends), with a Huber loss,
 * a shrinking correspondence gate and a bounded number of iterations; scan
 * vertices near a map vertex pull point to point with a higher weight.
 * Correspondences are found through a grid built, for each call, from the
 * map curves near the prior only.
 *
 * The result reports the 3x3 information matrix of the final
 * correspondences and its smallest eigenvalue and eigenvector. A direction
 * the geometry leaves undetermined (the axis of a long featureless corridor) is not
 * solved: the pose keeps the prior along it and BSF_ALIGN_FLAG_FREE is set.
 * When alignment cannot be trusted (too few points or correspondences, a
 * correction larger than the bounds, divergence, or a pose at which the
 * scan's points fit the map worse than at the prior) the call succeeds but
 * declines: the pose is the prior and `declined` says why.
 *
 * Fixed memory: bsf_align_work_t is caller-owned and sized by the caps in
 * bsf_config.h (BSF_ALIGN_*); no heap, no recursion, bounded work per call.
 */
#ifndef BSF_ALIGN_H
#define BSF_ALIGN_H

#include "bsf_common.h"
#include "bsf_feature.h"
#include "bsf_map.h"
#include "bsf_scan.h"

BSF_BEGIN_DECLS

/** Runtime parameters of alignment (bsf_align_params_default gives the defaults). */
typedef struct {
    float max_dist;       /**< metres, (0, 2]: correspondence gate of the first iteration;
                               it shrinks to a quarter over the iterations. A map curve
                               within max_dist / 2 of a point is always found, a farther
                               one when it crosses the point's grid cell (default 0.8) */
    float huber;          /**< metres, (0, 1]: residual beyond which the loss is linear
                               (default 0.03) */
    float max_xy;         /**< metres, (0, 10]: largest accepted translation correction
                               (default 0.5) */
    float max_theta;      /**< radians, (0, 1]: largest accepted heading correction
                               (default 0.2) */
    float vertex_weight;  /**< [0, 100]: weight of a vertex-to-vertex pair relative to a
                               point (default 4; 0: vertices are ordinary points) */
    float theta_scale;    /**< metres per radian, (0, 100]: how heading counts against
                               translation in the eigenvalues (default 1) */
    float free_ratio;     /**< [0, 1): a direction whose eigenvalue is below this share of
                               the largest is left free, default 0.005 */
    float free_min;       /**< >= 0: ... or below this absolute information (default 3,
                               about three points seen squarely) */
    uint16_t max_iter;    /**< 1..50 Gauss-Newton iterations (default 10) */
    uint16_t max_points;  /**< 3..BSF_ALIGN_MAX_POINTS: scan points used, evenly
                               subsampled (default 80) */
    uint16_t min_matches; /**< 3..max_points: fewer correspondences decline (default 12) */
} bsf_align_params_t;

/** Fill p with the defaults documented in bsf_align_params_t. p must not be NULL. */
void bsf_align_params_default(bsf_align_params_t *p);

/** Why alignment declined (bsf_align_result_t.declined); the pose is then the prior. */
typedef enum {
    BSF_ALIGN_ACCEPTED = 0,             /**< not declined: the pose is the aligned one */
    BSF_ALIGN_DECLINE_FEW_POINTS = 1,   /**< the scan has fewer than min_matches points */
    BSF_ALIGN_DECLINE_EMPTY_MAP = 2,    /**< no map curve near the prior */
    BSF_ALIGN_DECLINE_FEW_MATCHES = 3,  /**< fewer than min_matches correspondences */
    BSF_ALIGN_DECLINE_TOO_LARGE = 4,    /**< the correction exceeds max_xy or max_theta */
    BSF_ALIGN_DECLINE_DIVERGED = 5,     /**< correspondences lost while iterating, or a
                                             non-finite step */
    BSF_ALIGN_DECLINE_UNDETERMINED = 6, /**< no direction is determined by the geometry */
    BSF_ALIGN_DECLINE_NO_BETTER = 7     /**< the scan fits the map no better at the aligned
                                             pose than at the prior (Huber cost of every
                                             point against its nearest map curve, distances
                                             capped at max_dist / 4) */
} bsf_align_decline_t;

/** Number of bsf_align_decline_t values (for tables of counts). */
#define BSF_ALIGN_DECLINE_COUNT 8

/** Bits of bsf_align_result_t.flags. */
/** A direction was left free: the pose keeps the prior along min_eigvec
 *  (n_free directions). */
#define BSF_ALIGN_FLAG_FREE 0x1u
/** The last step was below 0.5 mm (theta scaled by theta_scale). */
#define BSF_ALIGN_FLAG_CONVERGED 0x2u
/** A cap cut the map curves, vertices or grid entries near the prior
 *  (BSF_ALIGN_MAX_SEGS, BSF_ALIGN_MAX_VERTICES, BSF_ALIGN_MAX_ENTRIES). */
#define BSF_ALIGN_FLAG_CUT 0x4u

/** Result of one alignment. */
typedef struct {
    bsf_pose_t pose;           /**< corrected pose (the prior when declined) */
    uint8_t declined;          /**< a bsf_align_decline_t */
    uint8_t flags;             /**< BSF_ALIGN_FLAG_* */
    uint8_t n_free;            /**< directions left free, 0..3 */
    uint8_t n_iter;            /**< Gauss-Newton iterations run */
    uint16_t n_points;         /**< scan points used (after subsampling) */
    uint16_t n_matches;        /**< points with a correspondence at the final pose */
    uint16_t n_vertex_matches; /**< scan vertices paired with a map vertex at the final pose */
    uint16_t n_segs;           /**< map chords near the prior */
    float rms;                 /**< RMS point-to-curve distance of the matches at the final
                                    pose, metres */
    float info[9];             /**< information matrix (J^T W J, row-major) in (x, y, theta):
                                    metres and radians, at the final pose */
    float min_eig;             /**< smallest eigenvalue of info with theta scaled by
                                    params.theta_scale */
    float min_eigvec[3];       /**< its unit eigenvector (x, y, theta_scale * theta) */
} bsf_align_result_t;

/** A map chord near the prior (internal layout), local frame. */
typedef struct {
    float ax, ay; /**< start, metres from the prior's position */
    float ux, uy; /**< unit direction */
    float len;    /**< length, metres */
} bsf_align_seg_t;

/** Working memory of alignment. Fixed size; caller memory; fields private. */
typedef struct {
    bsf_point_t pts[BSF_ALIGN_MAX_POINTS];      /**< scan points used, sensor frame */
    bsf_point_t verts[BSF_ALIGN_MAX_VERTICES];  /**< scan vertices, sensor frame */
    bsf_point_t mverts[BSF_ALIGN_MAX_VERTICES]; /**< map vertices near the prior, local */
    bsf_align_seg_t segs[BSF_ALIGN_MAX_SEGS];   /**< map chords near the prior */
    uint16_t cell_start[BSF_ALIGN_GRID * BSF_ALIGN_GRID + 1]; /**< grid: first entry per cell */
    uint16_t entries[BSF_ALIGN_MAX_ENTRIES];                  /**< grid: chord indices by cell */
    uint8_t mark[BSF_ALIGN_GRID * BSF_ALIGN_GRID];            /**< cells near a scan point */
    uint16_t match[BSF_ALIGN_MAX_POINTS]; /**< chord of each point in the last search */
    uint16_t n_pts, n_verts, n_mverts, n_segs;
    float grid_x0, grid_y0, cell, inv_cell; /**< grid origin (local) and cell size */
} bsf_align_work_t;

/**
 * Align a scan given as points: the valid beams of `points` (as
 * bsf_scan_to_points or the extractor give them), evenly subsampled to
 * params.max_points, and, when `features` is not NULL, its vertex control
 * points as anchors. `prior` is the laser's pose in the world (the frame of
 * `map`). params NULL: defaults. Returns BSF_OK with *out filled (declined or
 * not), or a negative bsf_status_t: BSF_ERR_ARG for NULL work, map, points,
 * prior or out, a non-finite or out-of-range prior (|x|, |y| >
 * BSF_POSE_XY_MAX, |theta| > BSF_POSE_THETA_MAX), or a used point that is
 * not finite or farther than 10 km; BSF_ERR_PARAM for parameters outside
 * their ranges. *out is written only on success.
 */
BSF_NODISCARD bsf_status_t bsf_align_points(bsf_align_work_t *work,
                                            const bsf_align_params_t *params, const bsf_map_t *map,
                                            const bsf_points_t *points,
                                            const bsf_result_t *features, const bsf_pose_t *prior,
                                            bsf_align_result_t *out);

/**
 * Align a scan given as features only: each curve sampled at its knots and
 * mid-spans (evenly subsampled to params.max_points), its vertices as
 * anchors. Otherwise as bsf_align_points(); BSF_ERR_ARG also for a feature
 * with n_ctrl < 3 or control points outside features->n_ctrl.
 */
BSF_NODISCARD bsf_status_t bsf_align_features(bsf_align_work_t *work,
                                              const bsf_align_params_t *params,
                                              const bsf_map_t *map, const bsf_result_t *features,
                                              const bsf_pose_t *prior, bsf_align_result_t *out);

/** Short English name of a decline reason ("accepted", "few points", ...); never NULL. */
const char *bsf_align_decline_str(int declined);

BSF_END_DECLS

#endif /* BSF_ALIGN_H */
