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

int bsf_points_full_circle(const bsf_points_t *pts)
{
    float inc;
    float span;
    if (pts == NULL || pts->count < 3u) {
        return 0;
    }
    inc = fabsf(pts->angle_increment);
    span = inc * (float)pts->count;
    return fabsf(span - 2.0f * BSF_PI_F) <= inc;
}

bsf_no_return_params_t bsf_no_return_params_default(void)
{
    bsf_no_return_params_t p;
    p.code = 0.0f;
    p.min_run = 5u;
    return p;
}

static void invalidate(bsf_points_t *pts, size_t i)
{
    pts->pt[i].x = 0.0f;
    pts->pt[i].y = 0.0f;
    pts->range[i] = 0.0f;
    pts->valid[i] = 0u;
    pts->n_valid--;
}

/* Does the run of equal readings [first, last] stand apart from its valid
 * neighbours: at least one, and each one there is reads more than 10 % less?
 * A no-return code does: the beams beside it hit a surface somewhere else.
 * A surface seen head-on near the scan's maximum does not: its range changes
 * by centimetres. A scan of nothing but equal readings has no neighbour to
 * tell, and stays valid. */
static int jumps_on_both_sides(const bsf_points_t *pts, size_t first, size_t last, float top)
{
    const float jump = 0.1f * top;
    int seen = 0;
    size_t j;
    for (j = first; j > 0u; --j) {
        if (pts->valid[j - 1u]) {
            if (!(top - pts->range[j - 1u] > jump)) {
                return 0;
            }
            seen = 1;
            break;
        }
    }
    for (j = last + 1u; j < pts->count; ++j) {
        if (pts->valid[j]) {
            return top - pts->range[j] > jump;
        }
    }
    return seen;
}

bsf_status_t bsf_points_reject_no_return(bsf_points_t *pts, const bsf_no_return_params_t *p,
                                         size_t *n_rejected)
{
    size_t i;
    size_t n = 0;
    float top = 0.0f;
    int top_is_code = 0;
    if (n_rejected != NULL) {
        *n_rejected = 0;
    }
    if (pts == NULL || p == NULL || pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_ARG;
    }
    if (!is_finite_f(p->code) || p->code < 0.0f) {
        return BSF_ERR_PARAM;
    }
    if (p->min_run > 0u) {
        /* The largest valid reading, then its runs of equal beams. */
        size_t run = 0;
        for (i = 0; i < pts->count; ++i) {
            if (pts->valid[i] && pts->range[i] > top) {
                top = pts->range[i];
            }
        }
        for (i = 0; i < pts->count && top > 0.0f && !top_is_code; ++i) {
            run = (pts->valid[i] && pts->range[i] == top) ? run + 1u : 0u;
            if (run >= (size_t)p->min_run &&
                (i + 1u == pts->count || !pts->valid[i + 1u] || pts->range[i + 1u] != top)) {
                top_is_code = jumps_on_both_sides(pts, i + 1u - run, i, top);
            }
        }
    }
    for (i = 0; i < pts->count; ++i) {
        if (pts->valid[i] && ((p->code > 0.0f && pts->range[i] == p->code) ||
                              (top_is_code && pts->range[i] == top))) {
            invalidate(pts, i);
            ++n;
        }
    }
    if (n_rejected != NULL) {
        *n_rejected = n;
    }
    return BSF_OK;
}
