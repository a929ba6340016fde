#include "bsf_nms.h"

#include <math.h>

/* asin(0.8): the reference's window angle when the radius reaches the range. */
#define BSF_ASIN_0_8 0.927295218f

/* far_ratio: below this radius/range ratio the window is certainly 0. */
static size_t half_window(const bsf_points_t *pts, size_t i, float radius, float inc,
                          float far_ratio)
{
    float w;

    if (!pts->valid[i]) {
        return 0u;
    }
    if (radius >= pts->range[i]) {
        w = floorf(BSF_ASIN_0_8 / inc);
    } else {
        const float s = radius / pts->range[i];
        if (s < far_ratio) {
            return 0u;
        }
        w = floorf(asinf(s) / inc);
    }
    if (!(w >= 0.0f)) {
        return 0u;
    }
    if (w > (float)BSF_MAX_POINTS) {
        return (size_t)BSF_MAX_POINTS;
    }
    return (size_t)w;
}

/* asin(s) < inc, hence window 0, whenever s < sin(inc): a margin below that
 * lets far beams (most of them) skip asinf without changing any window. */
static float far_ratio_of(float inc)
{
    return sinf(inc) * 0.999f;
}

size_t bsf_nms_half_window(const bsf_points_t *pts, size_t i, float radius)
{
    const float inc = fabsf(pts->angle_increment);
    return half_window(pts, i, radius, inc, far_ratio_of(inc));
}

size_t bsf_nms_beams(const bsf_points_t *pts, const float *score, bsf_nms_order_t order,
                     float threshold, float radius, uint16_t *peak)
{
    /* Comparing sign * score turns "lower is better" into "higher is better"
     * exactly (negation is exact in floating point). */
    const float sign = (order == BSF_NMS_LOWER_IS_BETTER) ? -1.0f : 1.0f;
    const size_t n = pts->count;
    const float min_val = sign * threshold;
    const float inc = fabsf(pts->angle_increment);
    const float far_ratio = far_ratio_of(inc);
    size_t n_cand = 0;
    size_t i = 0;
    size_t imax = 0;
    size_t k, i2, n_peak, run;

    while (i < n) {
        const size_t win = half_window(pts, i, radius, inc, far_ratio);
        size_t j, jbeg, jend;
        size_t jmax = i;

        /* Search the left part of the window only when the running maximum
         * imax lies outside it; otherwise it has already been seen. */
        if (imax + win < i) {
            jbeg = i - win;
            imax = i;
        } else {
            jbeg = i;
        }
        jend = (i + win + 1u < n) ? i + win + 1u : n;
        for (j = jbeg; j < jend; ++j) {
            if (sign * score[j] > sign * score[jmax]) {
                jmax = j;
            }
        }
        if (sign * score[jmax] >= sign * score[imax]) {
            imax = jmax;
        }
        if (i == imax && sign * score[i] > min_val) {
            peak[n_cand++] = (uint16_t)i;
        }
        i = (jmax > i) ? jmax : i + 1u;
    }

    /* Plateau merge, in place (a peak is written at or before the candidate
     * it comes from, and later reads are further right): within a run of
     * consecutive candidates with equal scores, the kept index i2 advances
     * every other step, ending near the middle of the run. */
    n_peak = 0;
    i2 = 0;
    run = 0;
    for (k = 0; k < n_cand; ++k) {
        if (score[peak[i2]] == score[peak[k]]) {
            ++run;
            if (2u * (k - i2) > run) {
                ++i2;
            }
        } else {
            peak[n_peak++] = peak[i2];
            i2 = k;
            run = 0;
        }
    }
    if (n_cand > 0u) {
        peak[n_peak++] = peak[i2];
    }
    return n_peak;
}
