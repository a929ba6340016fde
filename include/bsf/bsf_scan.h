/* SPDX-License-Identifier: MIT */
/*
 * bsf_scan.h - the scan model: ranges plus geometry in, points plus a
 * validity mask out.
 */
#ifndef BSF_SCAN_H
#define BSF_SCAN_H

#include "bsf_common.h"

BSF_BEGIN_DECLS

/**
 * One 2D LIDAR scan as the driver delivers it. Beam i points at
 * angle_min + i * angle_increment (radians, counter-clockwise, 0 ahead).
 * Give the increment itself; never derive it from a field of view.
 * The library only reads `ranges`; the caller owns it.
 */
typedef struct {
    const float *ranges;   /**< count readings, metres */
    size_t count;          /**< number of beams, 1..BSF_MAX_POINTS */
    float angle_min;       /**< angle of beam 0, radians */
    float angle_increment; /**< angle between beams, radians, finite and non-zero */
    float range_min;       /**< smallest valid reading, metres (>= 0) */
    float range_max;       /**< readings >= range_max are invalid: set it below no-return codes */
} bsf_scan_t;

/**
 * A scan converted to Cartesian points in the sensor frame. Invalid beams
 * keep their index (beam indices stay meaningful) with valid[i] == 0,
 * point (0,0) and range 0; they are never used as points.
 */
typedef struct {
    bsf_point_t pt[BSF_MAX_POINTS]; /**< beam i's point, metres */
    float range[BSF_MAX_POINTS];    /**< beam i's range, metres (0 when invalid) */
    uint8_t valid[BSF_MAX_POINTS];  /**< 1 when beam i is a valid reading */
    size_t count;                   /**< number of beams (index space) */
    size_t n_valid;                 /**< N: number of valid readings */
    float angle_min;                /**< copied from the scan */
    float angle_increment;          /**< copied from the scan */
} bsf_points_t;

/**
 * Is one reading valid? True when r is finite and range_min <= r < range_max.
 * NaN, +-inf, negative and zero readings are never valid (zero only passes
 * when range_min is 0, so it is rejected explicitly).
 */
int bsf_range_is_valid(float r, float range_min, float range_max);

/**
 * Convert a scan to points.
 *
 * @return BSF_OK; BSF_ERR_ARG when scan, scan->ranges (with count > 0) or out
 *         is NULL, or the geometry is not finite, or angle_increment is 0, or
 *         range_min < 0, or range_max <= range_min; BSF_ERR_CAPACITY when
 *         count > BSF_MAX_POINTS. On error `out` is left untouched.
 *         A scan with count == 0 or with no valid reading is not an error:
 *         it gives n_valid == 0.
 */
BSF_NODISCARD bsf_status_t bsf_scan_to_points(const bsf_scan_t *scan, bsf_points_t *out);

BSF_END_DECLS

#endif /* BSF_SCAN_H */
