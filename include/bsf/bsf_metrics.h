/* SPDX-License-Identifier: MIT */
/*
 * bsf_metrics.h - the paper's four quality metrics (section 6.1), per scan
 * and aggregated over a dataset, as docs/DESIGN.md ("Methods") defines them.
 *
 * Per scan:
 *   retrievability  Gamma = points in kept features / N valid readings   (ratio, x100 for %)
 *   compactness     eta   = stored control points / points in kept features
 *                           (a vertex, multiplicity 2, counts twice)
 *   accuracy              = mean of E_curve over the scan's features (metres)
 *   time            t     = seconds to extract the scan (all stages, not the encoder)
 * Per dataset: the mean of each per-scan value over the scans where it is
 * defined (Gamma needs N > 0; eta needs points in features; accuracy needs a
 * feature; time needs a clock), plus the median and 99th percentile of time.
 */
#ifndef BSF_METRICS_H
#define BSF_METRICS_H

#include "bsf_common.h"
#include "bsf_feature.h"

BSF_BEGIN_DECLS

/** The inputs a scan's metrics need; all of them travel in the wire format. */
typedef struct {
    uint32_t n_valid;         /**< N: valid readings */
    uint32_t n_in_features;   /**< points in kept features */
    uint32_t n_ctrl;          /**< stored control points, all features */
    uint32_t n_features;      /**< kept features */
    float sum_e_curve;        /**< sum of E_curve over the features, metres */
    float time_s;             /**< extraction time, seconds; negative when not measured */
    uint32_t cut;             /**< BSF_CUT_* bits of the scan; 0 when no cap cut it */
    uint32_t n_cut_keypoints; /**< keypoints dropped by the keypoint cap */
    uint32_t n_cut_segments;  /**< segments left out because of a cap */
    uint32_t n_cut_points;    /**< their valid points (part of N, wasted in Gamma) */
} bsf_scan_counts_t;

/**
 * The counts of one extraction result: N from its stats, the sums over its
 * features, the time from stats.time_ns (-1, "not measured", when it is 0,
 * which means no clock was set) and the cap cuts from the stats. Works as
 * well on a decoded frame's result. Fill a bsf_scan_counts_t of your own
 * whole (memset it first): every field is read.
 * @return BSF_OK; BSF_ERR_ARG for NULL.
 */
BSF_NODISCARD bsf_status_t bsf_metrics_counts(const bsf_result_t *result, bsf_scan_counts_t *out);

/** Per-scan metrics. A `has_*` flag is 0 where the value is undefined (then the value is 0). */
typedef struct {
    float retrievability; /**< Gamma as a ratio in [0,1] */
    float compactness;    /**< eta */
    float accuracy;       /**< metres */
    float time_s;         /**< seconds */
    uint8_t has_retrievability;
    uint8_t has_compactness;
    uint8_t has_accuracy;
    uint8_t has_time;
} bsf_scan_metrics_t;

/** Compute one scan's metrics. Returns BSF_OK, or BSF_ERR_ARG (out untouched) on
 *  NULL or inconsistent counts: points in features plus cut points > N, a non-finite or
 *  negative error sum, a NaN time (+inf or negative time is "not measured"),
 *  or points or control points in features while n_features is 0. */
BSF_NODISCARD bsf_status_t bsf_metrics_scan(const bsf_scan_counts_t *counts,
                                            bsf_scan_metrics_t *out);

/**
 * Dataset accumulator. Sums are kept in float pairs (Kahan) so millions of
 * scans do not lose precision, and counts in 64 bits so they never wrap (a
 * 32-bit sum of control points wraps after 8.4 M full scans). Exact median
 * and p99 of time need every time sample: the caller lends a float array of
 * its own (capacity = the number of scans it will add; NULL/0 when it does
 * not want quantiles).
 */
typedef struct {
    float sum[4];  /**< Kahan sums of Gamma, eta, accuracy, time */
    float comp[4]; /**< Kahan compensations */
    uint32_t n[4]; /**< scans where each metric is defined */
    uint32_t n_scans;
    uint32_t n_cut_scans;       /**< scans a cap cut (counts.cut != 0) */
    uint64_t sum_features;      /**< over all scans */
    uint64_t sum_ctrl;          /**< stored control points */
    uint64_t sum_points;        /**< points in features */
    uint64_t sum_valid;         /**< N */
    uint64_t sum_cut_keypoints; /**< keypoints dropped by a cap */
    uint64_t sum_cut_segments;  /**< segments left out by a cap */
    uint64_t sum_cut_points;    /**< their points */
    float *time_samples;        /**< lent by the caller, may be NULL */
    size_t time_cap;
    size_t time_count;
} bsf_metrics_acc_t;

/** Dataset summary. Means are 0 with n_* == 0 when no scan defined them. */
typedef struct {
    float retrievability, compactness, accuracy, time_mean_s, time_median_s, time_p99_s;
    uint32_t n_retrievability, n_compactness, n_accuracy, n_time;
    uint32_t n_scans;
    float features_per_scan;
    float ctrl_per_scan;
    uint32_t n_cut_scans;   /**< scans a cap cut */
    uint64_t cut_keypoints; /**< keypoints, segments and points they lost, in total */
    uint64_t cut_segments;
    uint64_t cut_points;
} bsf_metrics_summary_t;

/** Start an empty accumulator. time_samples may be NULL when time_cap is 0. */
BSF_NODISCARD bsf_status_t bsf_metrics_acc_init(bsf_metrics_acc_t *acc, float *time_samples,
                                                size_t time_cap);

/** Add one scan. BSF_ERR_CAPACITY when a time sample does not fit the lent
 *  array (the scan is then not added at all). */
BSF_NODISCARD bsf_status_t bsf_metrics_acc_add(bsf_metrics_acc_t *acc,
                                               const bsf_scan_counts_t *counts);

/** Summarise. Sorts the lent time array in place.
 *  Quantiles use the nearest-rank definition: p-th = the ceil(p*n)-th smallest. */
BSF_NODISCARD bsf_status_t bsf_metrics_acc_summary(bsf_metrics_acc_t *acc,
                                                   bsf_metrics_summary_t *out);

BSF_END_DECLS

#endif /* BSF_METRICS_H */
