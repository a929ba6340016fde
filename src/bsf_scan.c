/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_scan.h"

#include <math.h>

#include "bsf_math.h"

/* Bounds on the geometry that keep every beam angle finite and meaningful:
 * beyond these, angle_min + i * increment can overflow or lose all precision
 * in float, and sinf/cosf would return garbage or NaN. */
#define BSF_PI_F 3.14159265358979f
#define BSF_MAX_ABS_ANGLE_MIN (4.0f * BSF_PI_F)
#define BSF_MAX_ABS_INCREMENT BSF_PI_F

static int is_finite_f(float v)
{
    /* NaN fails both comparisons; +-inf fails the second. */
    return v == v && fabsf(v) <= 3.402823466e38f;
}

int bsf_range_is_valid(float r, float range_min, float range_max)
{
    return is_finite_f(r) && r > 0.0f && r >= range_min && r < range_max;
}

bsf_status_t bsf_scan_to_points(const bsf_scan_t *scan, bsf_points_t *out)
{
    size_t i;
    size_t n_valid = 0;

    if (scan == NULL || out == NULL || (scan->count > 0 && scan->ranges == NULL)) {
        return BSF_ERR_ARG;
    }
    if (scan->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    if (!is_finite_f(scan->angle_min) || fabsf(scan->angle_min) > BSF_MAX_ABS_ANGLE_MIN ||
        !is_finite_f(scan->angle_increment) || scan->angle_increment == 0.0f ||
        fabsf(scan->angle_increment) > BSF_MAX_ABS_INCREMENT || !is_finite_f(scan->range_min) ||
        scan->range_min < 0.0f || !(scan->range_max > scan->range_min)) {
        /* range_max may be +inf ("no upper bound"); NaN fails the comparison. */
        return BSF_ERR_ARG;
    }

    for (i = 0; i < scan->count; ++i) {
        const float r = scan->ranges[i];
        if (bsf_range_is_valid(r, scan->range_min, scan->range_max)) {
            const float a = scan->angle_min + (float)i * scan->angle_increment;
            out->pt[i].x = r * bsf_cosf(a);
            out->pt[i].y = r * bsf_sinf(a);
            out->range[i] = r;
            out->valid[i] = 1u;
            ++n_valid;
        } else {
            out->pt[i].x = 0.0f;
            out->pt[i].y = 0.0f;
            out->range[i] = 0.0f;
            out->valid[i] = 0u;
        }
    }
    out->count = scan->count;
    out->n_valid = n_valid;
    out->angle_min = scan->angle_min;
    out->angle_increment = scan->angle_increment;
    return BSF_OK;
}
