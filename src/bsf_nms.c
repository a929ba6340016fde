/* SPDX-License-Identifier: MIT */
#include "bsf_nms.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "bsf_math.h"

/* asin(0.8): the reference's window angle when the radius reaches the range. */
#define BSF_ASIN_0_8 0.927295218f

/* An integer whose order is the order of the float v (not NaN), and back. */
static int32_t float_key(float v)
{
    int32_t b;
    memcpy(&b, &v, sizeof b);
    return b ^ ((b >> 31) & INT32_MAX);
}

static float key_float(int32_t key)
{
    const int32_t b = key ^ ((key >> 31) & INT32_MAX);
    float v;
    memcpy(&v, &b, sizeof v);
    return v;
}

/* What every window of one scan shares. */
typedef struct {
    float radius;    /* suppression radius, metres */
    float inc;       /* |angle increment|, radians */
    float inv_inc;   /* 1 / inc */
    float far_ratio; /* radius / range below this: window certainly 0 */
    size_t close;    /* window when radius >= range: floor(asin(0.8) / inc) */
} window_ctx_t;

/* floor(w) for w >= 0 (truncation; floorf may be a library call), clamped. */
static size_t clamp_window(float w)
{
    if (!(w >= 0.0f)) {
        return 0u;
    }
    /* BSF_MAX_POINTS fits int (and uint16_t); int conversion is one instruction */
    return (w > (float)BSF_MAX_POINTS) ? (size_t)BSF_MAX_POINTS : (size_t)(int)w;
}

static window_ctx_t window_ctx(const bsf_points_t *pts, float radius)
{
    window_ctx_t c;
    c.radius = radius;
    c.inc = fabsf(pts->angle_increment);
    c.inv_inc = 1.0f / c.inc;
    /* asin(s) < inc, hence window 0, whenever s < sin(inc); the margin keeps
     * rounding on the safe side. */
    c.far_ratio = bsf_sinf(c.inc) * 0.999f;
    c.close = clamp_window(BSF_ASIN_0_8 / c.inc);
    return c;
}

/* floor(asin(s) / inc) for s = radius / range. asin(s) lies between s and
 * s / sqrt(1 - s^2); when both bounds (widened by a rounding margin) floor to
 * the same integer, that is the window and asinf is not needed. */
static size_t half_window(const bsf_points_t *pts, size_t i, const window_ctx_t *c)
{
    float s;
    size_t lo, hi;
    if (!pts->valid[i]) {
        return 0u;
    }
    if (c->radius >= pts->range[i]) {
        return c->close;
    }
    if (c->radius < c->far_ratio * pts->range[i]) {
        return 0u;
    }
    s = c->radius / pts->range[i];
    lo = clamp_window(s * c->inv_inc * (1.0f - 1e-5f));
    hi = clamp_window(s / sqrtf(1.0f - s * s) * c->inv_inc * (1.0f + 1e-5f));
    if (lo == hi) {
        return lo;
    }
    return clamp_window(bsf_asinf(s) / c->inc);
}

size_t bsf_nms_half_window(const bsf_points_t *pts, size_t i, float radius)
{
    const window_ctx_t c = window_ctx(pts, radius);
    return half_window(pts, i, &c);
}

size_t bsf_nms_beams(const bsf_points_t *pts, const float *score, bsf_nms_order_t order,
                     float threshold, float radius, uint16_t *peak)
{
    /* Comparing sign * score turns "lower is better" into "higher is better"
     * exactly (negation is exact in floating point). */
    const float sign = (order == BSF_NMS_LOWER_IS_BETTER) ? -1.0f : 1.0f;
    const size_t n = pts->count;
    const float min_val = sign * threshold;
    const window_ctx_t ctx = window_ctx(pts, radius);
    size_t n_cand = 0;
    size_t i = 0;
    size_t imax = 0;
    size_t run_end = 0; /* end (exclusive) of the run of equal scores from i */
    size_t k, i2, n_peak, run, w_max, next_better, last_better;
    float bottom, min_range;
    int close;

    /* Beams no better than the worst score ("bottom") only matter near
     * better ones: a step at beam i whose window holds only bottom scores,
     * with the running maximum at the bottom too, just makes i the running
     * maximum and moves on (bottom must not pass the threshold). So the loop
     * jumps over every stretch farther than the largest window from any
     * better beam, and windows are computed only where it stops. */
    if (n == 0u) {
        return 0u;
    }
    {
        /* One loop without branches (compilers run several beams per
         * instruction): float comparisons as integer ones on keys that
         * order as the floats do (sign-magnitude to two's complement; ranges
         * are non-negative, so their bits already do). */
        const int32_t radius_bits = float_key(radius);
        int32_t bottom_key = INT32_MAX;
        int32_t range_key = INT32_MAX; /* smallest valid range above the radius */
        int32_t close_any = 0;         /* a valid range at or below the radius */
        for (k = 0; k < n; ++k) {
            const int32_t v = float_key(sign * score[k]);
            const int32_t r = float_key(pts->range[k]);
            const int32_t valid = -(int32_t)(pts->valid[k] != 0u);
            const int32_t above = -(int32_t)(r > radius_bits) & valid;
            const int32_t r_above = (r & above) | (INT32_MAX & ~above);
            bottom_key = (v < bottom_key) ? v : bottom_key;
            range_key = (r_above < range_key) ? r_above : range_key;
            close_any |= valid & ~above;
        }
        bottom = key_float(bottom_key);
        min_range = (range_key == INT32_MAX) ? -1.0f : key_float(range_key);
        close = close_any != 0;
    }
    if (bottom > min_val) {
        w_max = n; /* every bottom beam could be a candidate: no jumps */
    } else {
        /* The largest window: asin(s) <= s / sqrt(1 - s^2) at the smallest
         * range above the radius (bounds half_window's result), or the
         * window of a range at or below the radius. */
        w_max = close ? ctx.close : 0u;
        if (min_range > 0.0f) {
            const float s = radius / min_range;
            const size_t w = clamp_window(s / sqrtf(1.0f - s * s) * ctx.inv_inc * 1.001f) + 1u;
            w_max = (w > w_max) ? w : w_max;
        }
    }
    next_better = 0;
    while (next_better < n && !(sign * score[next_better] > bottom)) {
        ++next_better;
    }
    last_better = n; /* none yet */
    i = 0;
    while (i < n) {
        size_t win, j, jbeg, jend;
        size_t jmax = i;

        while (next_better < i) {
            last_better = next_better++;
            while (next_better < n && !(sign * score[next_better] > bottom)) {
                ++next_better;
            }
        }
        if (w_max < n && sign * score[imax] == bottom &&
            (last_better == n || i > last_better + w_max) && next_better > i + w_max) {
            i = (next_better == n) ? n : next_better - w_max;
            imax = i - 1u;
            continue;
        }
        win = half_window(pts, i, &ctx);

        /* Fast path, same outcome as the general step below: the previous
         * beam is the running maximum, and the whole window [i, i + win]
         * holds its score, which does not pass the threshold. Then nothing
         * beats beam i, it becomes imax, is no candidate, and i moves on. */
        if (run_end <= i) {
            run_end = i + 1u;
            while (run_end < n && score[run_end] == score[i]) {
                ++run_end;
            }
        }
        if (i > 0u && imax == i - 1u && score[imax] == score[i] && i + win < run_end &&
            !(sign * score[i] > min_val)) {
            imax = i;
            ++i;
            continue;
        }

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

/* A key whose unsigned order is the float order (sign-magnitude to offset
 * binary), flipped when lower scores are better: a larger key is better. */
static uint32_t score_key(float v, bsf_nms_order_t order)
{
    uint32_t bits;
    uint32_t key;
    memcpy(&bits, &v, sizeof bits);
    key = (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
    return order == BSF_NMS_LOWER_IS_BETTER ? ~key : key;
}

static size_t count_at_least(const float *score, bsf_nms_order_t order, const uint16_t *peak,
                             size_t n_peak, uint32_t key)
{
    size_t n = 0u;
    size_t k;
    for (k = 0; k < n_peak; ++k) {
        n += (score_key(score[peak[k]], order) >= key) ? 1u : 0u;
    }
    return n;
}

size_t bsf_nms_keep_best(const float *score, bsf_nms_order_t order, uint16_t *peak, size_t n_peak,
                         size_t cap)
{
    uint32_t lo = 0u; /* count_at_least(lo) >= cap holds throughout */
    uint32_t hi = 0xFFFFFFFFu;
    size_t n_above;
    size_t n_kept = 0u;
    size_t k;
    if (n_peak <= cap) {
        return n_peak;
    }
    if (cap == 0u) {
        return 0u;
    }
    /* The cap-th best key: the largest key that at least cap peaks reach. */
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2u + 1u;
        if (count_at_least(score, order, peak, n_peak, mid) >= cap) {
            lo = mid;
        } else {
            hi = mid - 1u;
        }
    }
    /* Everything better than it, then ties in beam order up to cap. */
    n_above = (lo == 0xFFFFFFFFu) ? 0u : count_at_least(score, order, peak, n_peak, lo + 1u);
    for (k = 0; k < n_peak; ++k) {
        const uint32_t key = score_key(score[peak[k]], order);
        if (key > lo || (key == lo && n_above < cap)) {
            if (key == lo) {
                ++n_above;
            }
            peak[n_kept++] = peak[k];
        }
    }
    return n_kept;
}
