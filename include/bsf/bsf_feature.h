/* SPDX-License-Identifier: MIT */
/*
 * bsf_feature.h - what extraction produces: B-spline features of one scan
 * and the scan's statistics. The stream encoder and the metrics consume it.
 */
#ifndef BSF_FEATURE_H
#define BSF_FEATURE_H

#include "bsf_common.h"

BSF_BEGIN_DECLS

/** Kind of a feature (paper section 5): with or without a vertex (corner). */
typedef enum {
    BSF_FEATURE_BLEAK = 0,    /**< no interest point inside: a smooth curve */
    BSF_FEATURE_AUXILIARY = 1 /**< at least one interest point inside: has vertices */
} bsf_feature_kind_t;

/**
 * One B-spline feature: a clamped uniform quadratic B-spline whose control
 * points are result->ctrl[ctrl_first .. ctrl_first + n_ctrl - 1].
 * A vertex control point has multiplicity 2: it is stored twice, in two
 * consecutive slots, both flagged in result->ctrl_is_vertex, and counts twice
 * in n_ctrl (as in the paper's compactness metric).
 */
typedef struct {
    /** First and last beam index covered (inclusive). first_beam > last_beam
     *  means the run wraps through the seam of a full-circle scan: beams
     *  first_beam .. stats.n_beams - 1, then 0 .. last_beam. */
    uint16_t first_beam;
    uint16_t last_beam;
    /** Valid points assigned to the feature. With the default segmentation
     *   (look-back, bsf_segment.h) the run may also hold beams of other
     *   features (an occluder in front of a wall), so n_points can be less
     *   than the valid beams of the run, and runs of features may overlap. */
    uint16_t n_points;
    uint16_t ctrl_first; /**< index of the first control point in the result pool */
    uint8_t n_ctrl;      /**< stored control points, 3..BSF_MAX_CTRL_PER_FEATURE */
    uint8_t kind;        /**< a bsf_feature_kind_t */
    float e_curve;       /**< RMS distance of its points to the curve, metres */
} bsf_feature_t;

/** Pipeline stages whose time is measured when a clock is given. */
typedef enum {
    BSF_STAGE_POINTS = 0,
    BSF_STAGE_CORNERS = 1,
    BSF_STAGE_SEGMENTS = 2,
    BSF_STAGE_FIT = 3,
    BSF_STAGE_COUNT = 4
} bsf_stage_t;

/** Bits of bsf_stats_t.cut: which compile-time cap cut a scan's output. */
#define BSF_CUT_KEYPOINTS 0x1u /**< more interest points than BSF_MAX_KEYPOINTS */
#define BSF_CUT_SEGMENTS 0x2u  /**< more kept segments than BSF_MAX_SEGMENTS */
#define BSF_CUT_CTRL 0x4u      /**< more control points than BSF_MAX_CTRL_POINTS */

/** Per-scan statistics (paper section 6.1 metrics are computed from these). */
typedef struct {
    uint32_t n_beams;         /**< beams of the scan (index space, valid or not) */
    uint32_t n_valid;         /**< N: valid readings in the scan */
    uint32_t n_in_features;   /**< points in kept features (numerator of retrievability) */
    uint32_t n_ctrl;          /**< stored control points of all features */
    uint32_t n_features;      /**< kept features */
    uint32_t n_keypoints;     /**< interest points used (found = n_keypoints + n_cut_keypoints) */
    uint32_t n_unfitted;      /**< segments whose fit failed (counted as wasted) */
    uint32_t cut;             /**< BSF_CUT_* bits; 0 when every cap held */
    uint32_t n_cut_keypoints; /**< interest points dropped by the keypoint cap */
    uint32_t n_cut_segments;  /**< kept segments left out because of a cap */
    uint32_t n_cut_points;    /**< valid points of those segments (wasted in retrievability) */
    uint32_t n_fit_visits;    /**< the fit's work: points (bins, with fit_bin_length) visited by
                                   its footpoint passes, summed over its fits
                                   (bsf_params_t.fit_passes bounds it; a binned fit's one pass
                                   over its returns after the fit is not counted); 0 for LSBA */
    uint32_t time_ns;         /**< whole extraction time, ns; 0 when no clock is set */
    uint32_t stage_ns[BSF_STAGE_COUNT]; /**< per-stage time, ns; 0 when no clock */
} bsf_stats_t;

/** All features of one scan. Fixed size; lives in caller memory. */
typedef struct {
    /* The counts first: near the struct's start a load is one instruction
     * on Thumb-2 (docs/PERFORMANCE.md, section 3). */
    uint16_t n_features;
    uint16_t n_ctrl;
    bsf_stats_t stats;
    uint8_t ctrl_is_vertex[BSF_MAX_CTRL_POINTS]; /**< 1 for both copies of a vertex */
    bsf_feature_t features[BSF_MAX_SEGMENTS];
    bsf_point_t ctrl[BSF_MAX_CTRL_POINTS]; /**< control points, sensor frame, metres */
} bsf_result_t;

BSF_END_DECLS

#endif /* BSF_FEATURE_H */
