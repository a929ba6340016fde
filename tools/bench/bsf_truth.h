/* SPDX-License-Identifier: MIT */
/*
 * bsf_truth.h - judge extraction results against the known geometry of a
 * synthetic scene (bsf_scene.h): vertex recall, precision and position error,
 * curve-to-true-surface distance, and the paper's counts. Used by bench_truth
 * and test_truth. Host-side; not part of the library.
 *
 * Definitions (docs/GROUND_TRUTH.md repeats them):
 *  - A true corner is "visible" when bsf_scene_corners says so (in view, not
 *    occluded, rays either side hit its two walls), it lies within
 *    BSF_TRUTH_RANGE_MAX of the sensor, and each of its two walls is seen over
 *    some length: at least BSF_TRUTH_MIN_HITS beams hit the wall within
 *    BSF_TRUTH_WALL_LEN of the vertex, spread over at least BSF_TRUTH_MIN_SPREAD,
 *    and the BSF_TRUTH_MIN_HITS hits nearest the vertex sample the wall as a
 *    surface: no gap above BSF_TRUTH_MAX_GAP from the vertex to the first or
 *    between them (a wall seen at grazing incidence, one return every half
 *    metre, is not seen as a wall by any segmentation).
 *  - A "hit" on a wall is a return that lies on it: bsf_truth_returns_on_shapes
 *    labels each beam with the shape its delivered return lies on, so a
 *    mixed pixel (a blend between two surfaces at a depth jump) is a hit on
 *    none and breaks a wall's run of consecutive returns.
 *  - Sparse-wall rule (reported beside the first): a visible corner within
 *    BSF_TRUTH_RANGE_MAX counts when each of its two walls has at least
 *    BSF_TRUTH_MIN_HITS consecutive beams hitting it, starting with the hit
 *    nearest the vertex and reaching at least BSF_TRUTH_SPARSE_REACH from it,
 *    however far apart the returns are (3 returns on a line fix it).
 *  - A vertex (a control point stored twice) "finds" a visible corner when it
 *    lies within BSF_TRUTH_MATCH of it; recall = found / visible.
 *  - Precision = vertices within BSF_TRUTH_MATCH of any true corner (visible or
 *    not) / vertices, leaving out the vertices that sit where a straight wall
 *    meets a curved one, two curved walls cross, or a wall ends on another (a
 *    T-junction): real creases, but not listed corners.
 *  - Position error: distance from each found corner to its nearest vertex.
 *  - Curve distance: every feature's curve sampled BSF_TRUTH_SAMPLES_PER_SPAN
 *    times per span, distance of each sample to the nearest true surface.
 */
#ifndef BSF_TRUTH_H
#define BSF_TRUTH_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "bsf/bsf.h"
#include "bsf_scene.h"

#define BSF_TRUTH_RANGE_MAX 8.0
#define BSF_TRUTH_MATCH 0.10
#define BSF_TRUTH_WALL_LEN 1.0
#define BSF_TRUTH_MIN_HITS 3
#define BSF_TRUTH_MIN_SPREAD 0.2
#define BSF_TRUTH_MAX_GAP 0.25
#define BSF_TRUTH_SAMPLES_PER_SPAN 8
#define BSF_TRUTH_STRAY 0.05
/** Sparse-wall rule: a wall needs BSF_TRUTH_MIN_HITS consecutive returns from
 *  the one next to the vertex, reaching at least this far from it, metres. */
#define BSF_TRUTH_SPARSE_REACH 0.3
#define BSF_TRUTH_OBTUSE_MIN 120.0
#define BSF_TRUTH_OBTUSE_MAX 150.0
#define BSF_TRUTH_SEAM_DEG 30.0
/** Range bands of the recall report: [0,3), [3,6), [6,8] metres. */
#define BSF_TRUTH_BANDS 3
/** Histogram resolution and extent of the distance quantiles. */
#define BSF_TRUTH_BIN 0.0001
#define BSF_TRUTH_NBINS 5000

typedef struct {
    uint32_t hist[BSF_TRUTH_NBINS + 1]; /* last bin: beyond the extent */
    double sum_sq;
    double max;
    uint64_t n;
} bsf_truth_hist_t;

typedef struct {
    uint64_t visible[BSF_TRUTH_BANDS];
    uint64_t found[BSF_TRUTH_BANDS];
    /* The same under the sparse-wall rule (bsf_truth_walls_sparse). */
    uint64_t visible_sparse[BSF_TRUTH_BANDS];
    uint64_t found_sparse[BSF_TRUTH_BANDS];
    bsf_truth_hist_t vertex_err_sparse;
    /* Classes, all under the sparse-wall rule: obtuse convex corners
     * (BSF_TRUTH_OBTUSE_MIN..MAX degrees, the sensor outside the walls'
     * wedge), and on a full-circle scan the corners behind the sensor
     * (within BSF_TRUTH_SEAM_DEG of the seam at beam 0) and ahead. */
    uint64_t obtuse_visible, obtuse_found;
    uint64_t obtuse_concave_visible, obtuse_concave_found; /* the sensor inside the wedge */
    uint64_t behind_visible, behind_found;
    uint64_t ahead_visible, ahead_found;
    uint64_t vertices;         /* vertices judged */
    uint64_t vertices_correct; /* within BSF_TRUTH_MATCH of a true corner */
    uint64_t vertices_creases; /* at a wall-curve crease: not judged */
    bsf_truth_hist_t vertex_err;
    bsf_truth_hist_t curve;
    uint64_t features;
    uint64_t features_stray; /* features whose curve strays > BSF_TRUTH_STRAY */
    uint64_t scans;
    uint64_t n_valid, n_in_features, n_ctrl, bytes;
    double time_ns;
    /* The oracle of the sparse-wall rule (bsf_truth_add_oracle): its vertex
     * error on the corners bsf found (the set of vertex_err_sparse) and on
     * every sparse-rule corner; corners it cannot place (a side with fewer
     * than 2 clean returns, or parallel lines). */
    bsf_truth_hist_t oracle_err_found;
    bsf_truth_hist_t oracle_err_all;
    uint64_t oracle_undefined;
} bsf_truth_acc_t;

/** Non-zero: bsf_truth_add prints every false vertex (bench_truth --verbose). */
extern int bsf_truth_verbose;

void bsf_truth_acc_init(bsf_truth_acc_t *acc);

/**
 * The shape each beam's delivered return lies on, for the visibility rules
 * and the oracle: on_shape[i] = hit_shape[i], except that a beam whose
 * delivered range is not the one the scene gave it (delivered[i] !=
 * unmixed[i]: bsf_scene_mixed_pixels changed it) and lies more than tol
 * metres from its clean range gets -1, a return on no shape (a blend between
 * two surfaces). The arrays hold n beams; on_shape may be hit_shape.
 * Returns the number of beams relabelled.
 */
size_t bsf_truth_returns_on_shapes(int16_t *on_shape, const int16_t *hit_shape, const float *clean,
                                   const float *delivered, const float *unmixed, size_t n,
                                   double tol);

/**
 * Judge one result. ranges are the clean ranges of the scan as simulated and
 * hit_shape the shape each beam's return lies on (bsf_scene_scan's labels,
 * or with mixed pixels bsf_truth_returns_on_shapes); lidar holds the pose.
 * bytes is the frame size. Returns 0, or -1 when the scene has more than 256
 * corners.
 */
int bsf_truth_add(bsf_truth_acc_t *acc, const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                  const float *ranges, const int16_t *hit_shape, const bsf_result_t *res,
                  size_t bytes, double time_ns);

/**
 * Is corner c (from bsf_scene_corners for this lidar) a visible corner in the
 * sense above: visible, within BSF_TRUTH_RANGE_MAX, both walls seen? ranges
 * and hit_shape as bsf_truth_add. 1 or 0.
 */
int bsf_truth_corner_seen(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                          const float *ranges, const int16_t *hit_shape);

/** The same under the sparse-wall rule: visible, within BSF_TRUTH_RANGE_MAX,
 *  each wall's run of consecutive hits long enough. 1 or 0. */
int bsf_truth_corner_seen_sparse(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                                 const float *ranges, const int16_t *hit_shape);

/**
 * The oracle of a corner: the best estimate of its vertex the data allow
 * without priors. Each of its two walls gets a total-least-squares line
 * through exactly the returns that truly lie on it (the scene's labels):
 * from the hit on that wall nearest the vertex, the consecutive beams that hit
 * the wall (through the seam of a full-circle scan), as the sparse-wall rule
 * walks them, up to `reach` metres from the vertex (their true positions; 0
 * or less: the whole run); the vertex is the lines' intersection.
 * `measured` are the ranges the extractor saw; clean the ranges as simulated
 * and hit_shape the shape each return lies on, as bsf_truth_add (a mixed
 * pixel labelled -1 by bsf_truth_returns_on_shapes is no return of the wall
 * and ends its run). On success *x, *y get the vertex (sensor frame) and, when not
 * NULL, n_side the returns used on each wall (shape_a, shape_b) and
 * len_side how far the farthest reaches from the vertex.
 * @return 0; -1 when a wall has fewer than 2 usable returns or the lines are
 *         parallel.
 */
int bsf_truth_oracle_vertex(const bsf_scene_corner_t *c, const bsf_lidar_t *lidar,
                            const float *clean, const int16_t *hit_shape, const float *measured,
                            double reach, double *x, double *y, int n_side[2], double len_side[2]);

/** How far the oracle's sides reach from the vertex (bsf_truth_oracle_vertex),
 *  metres; 0: the whole run of returns. bench_truth sets LC's max_side. */
extern double bsf_truth_oracle_reach;

/** When not NULL, bsf_truth_add_oracle writes one line per sparse-rule corner
 *  to it (bench_truth BENCH_TRUTH_ORACLE_LOG=FILE), prefixed with
 *  bsf_truth_oracle_key: found, bsf's and the oracle's vertex errors, the
 *  distance between the two, angle, convexity, range, returns and extent of
 *  each side, whether the corner passes the first rule, the nearest
 *  keypoint's distance to it (-1 without keypoints). */
extern FILE *bsf_truth_oracle_log;
extern const char *bsf_truth_oracle_key;
/** The extractor's keypoints of the scan judged (sensor frame), or NULL: the
 *  log then also gives the nearest keypoint's distance to each corner (LC's
 *  two-line intersection, the vertex's anchor). */
extern const bsf_keypoint_t *bsf_truth_oracle_keypoints;
extern size_t bsf_truth_oracle_n_keypoints;

/**
 * Add the oracle's vertex error (bsf_truth_oracle_vertex with
 * bsf_truth_oracle_reach) for every corner visible under the sparse-wall rule
 * to acc: oracle_err_all, and oracle_err_found for those that res has a vertex
 * within BSF_TRUTH_MATCH of (the corners of vertex_err_sparse). Arguments as
 * bsf_truth_add and bsf_truth_oracle_vertex. Returns 0, or -1 when the scene
 * has more than 256 corners.
 */
int bsf_truth_add_oracle(bsf_truth_acc_t *acc, const bsf_scene_t *scene, const bsf_lidar_t *lidar,
                         const float *clean, const int16_t *hit_shape, const float *measured,
                         const bsf_result_t *res);

/** Quantile q in [0,1] of a histogram (upper bin edge), metres; 0 when empty. */
double bsf_truth_quantile(const bsf_truth_hist_t *h, double q);

/** Summary numbers of an accumulator. */
typedef struct {
    double recall; /* all bands */
    double recall_band[BSF_TRUTH_BANDS];
    double recall_sparse; /* the same, sparse-wall rule */
    double recall_sparse_band[BSF_TRUTH_BANDS];
    double verr_sparse_median, verr_sparse_p90;
    /* the oracle (bsf_truth_add_oracle): on bsf's found corners, on all */
    double oracle_found_median, oracle_found_p90;
    double oracle_all_median, oracle_all_p90;
    double recall_obtuse, recall_obtuse_concave, recall_behind, recall_ahead;
    uint64_t visible_sparse, obtuse_visible, obtuse_concave_visible, behind_visible, ahead_visible;
    double precision;
    double verr_median, verr_p90, verr_max;
    double curve_rms, curve_p99, curve_max;
    double stray_share;
    double gamma, eta, bytes_per_scan, us_per_scan;
    uint64_t visible;
} bsf_truth_summary_t;

void bsf_truth_summary(const bsf_truth_acc_t *acc, bsf_truth_summary_t *s);

#endif /* BSF_TRUTH_H */
