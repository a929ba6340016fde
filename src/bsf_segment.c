/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_segment.h"

#include <math.h>

#include "bsf_math.h"

#define BSF_SEG_PI_F 3.14159265f

static int is_finite_f(float v)
{
    return v == v && fabsf(v) <= 3.402823466e38f;
}

bsf_sved_params_t bsf_sved_params_default(void)
{
    bsf_sved_params_t p;
    p.a = 0.2f;
    p.b = 0.07f;
    p.min_segment_points = 5u;
    return p;
}

bsf_rpos_params_t bsf_rpos_params_default(void)
{
    bsf_rpos_params_t p;
    p.alpha_max = 0.25f * BSF_SEG_PI_F;
    p.eta = 1.5f;
    p.min_segment_points = 5u;
    return p;
}

static int min_points_ok(uint16_t n)
{
    return n >= 1u && n <= (uint16_t)BSF_MAX_POINTS;
}

bsf_status_t bsf_sved_params_check(const bsf_sved_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (!is_finite_f(p->a) || !(p->a > 0.0f) || !is_finite_f(p->b) || !(p->b >= 0.0f) ||
        !min_points_ok(p->min_segment_points)) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

bsf_status_t bsf_rpos_params_check(const bsf_rpos_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (!(p->alpha_max > 0.0f) || !(p->alpha_max <= BSF_SEG_PI_F) || !is_finite_f(p->eta) ||
        !(p->eta >= 1.0f) || !(p->eta <= 1e6f) || !min_points_ok(p->min_segment_points)) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

/* Collects kept segments and counts the wasted points of dropped ones. */
typedef struct {
    bsf_segment_t *out;
    size_t cap;
    size_t n_out;
    size_t n_wasted;
    uint16_t min_points;
} seg_sink_t;

/* Returns 0 when the segment is kept but does not fit (capacity exceeded). */
static int sink_close(seg_sink_t *sink, size_t first, size_t last, size_t n_points)
{
    bsf_segment_t *s;
    if (n_points < (size_t)sink->min_points) {
        sink->n_wasted += n_points;
        return 1;
    }
    if (sink->n_out >= sink->cap) {
        return 0;
    }
    s = &sink->out[sink->n_out++];
    s->first = (uint16_t)first;
    s->last = (uint16_t)last;
    s->n_points = (uint16_t)n_points;
    s->kind = (uint8_t)BSF_FEATURE_BLEAK;
    s->n_interest = 0u;
    return 1;
}

/* Common argument checks of both segmenters; on success fills the sink. */
static bsf_status_t begin(const bsf_points_t *pts, bsf_segment_t *out, size_t cap, size_t *n_out,
                          size_t *n_wasted_points, seg_sink_t *sink)
{
    if (n_out != NULL) {
        *n_out = 0;
    }
    if (n_wasted_points != NULL) {
        *n_wasted_points = 0;
    }
    if (pts == NULL || n_out == NULL || (out == NULL && cap > 0u)) {
        return BSF_ERR_ARG;
    }
    if (pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    sink->out = out;
    sink->cap = cap;
    sink->n_out = 0;
    sink->n_wasted = 0;
    return BSF_OK;
}

static bsf_status_t finish(const seg_sink_t *sink, size_t *n_out, size_t *n_wasted_points)
{
    *n_out = sink->n_out;
    if (n_wasted_points != NULL) {
        *n_wasted_points = sink->n_wasted;
    }
    return BSF_OK;
}

/* 1 + x + x^2/2 + x^3/6 + x^4/24: a lower bound of exp(x) for x >= 0. */
static float exp_lower_bound(float x)
{
    return 1.0f + x * (1.0f + x * (0.5f + x * (0.16666667f + x * 0.041666668f)));
}

bsf_status_t bsf_segment_sved(const bsf_points_t *pts, const bsf_sved_params_t *params,
                              bsf_segment_t *out, size_t cap, size_t *n_out,
                              size_t *n_wasted_points)
{
    const bsf_sved_params_t defaults = bsf_sved_params_default();
    const bsf_sved_params_t *p = params != NULL ? params : &defaults;
    seg_sink_t sink;
    bsf_status_t st;
    float a2;
    float two_b;
    bsf_point_t prev = {0.0f, 0.0f};
    size_t first = 0;
    size_t last = 0;
    size_t n_cur = 0;
    size_t i;

    st = begin(pts, out, cap, n_out, n_wasted_points, &sink);
    if (st != BSF_OK) {
        return st;
    }
    st = bsf_sved_params_check(p);
    if (st != BSF_OK) {
        return BSF_ERR_PARAM;
    }
    sink.min_points = p->min_segment_points;
    /* Compare squared distances: d <= a*exp(b*rho)  <=>  d^2 <= a^2*exp(2*b*rho). */
    a2 = p->a * p->a;
    two_b = 2.0f * p->b;

    /* The first valid point opens the first segment; then one pass. */
    for (i = 0; i < pts->count && !pts->valid[i]; ++i) {
    }
    if (i == pts->count) {
        return finish(&sink, n_out, n_wasted_points);
    }
    first = i;
    last = i;
    prev = pts->pt[i];
    n_cur = 1;
    for (++i; i < pts->count; ++i) {
        const bsf_point_t q = pts->pt[i];
        float dx;
        float dy;
        float d2;
        if (!pts->valid[i]) {
            continue; /* an invalid beam never breaks a segment by itself */
        }
        dx = q.x - prev.x;
        dy = q.y - prev.y;
        d2 = dx * dx + dy * dy;
        /* Decide without expf where possible: r(rho) >= a, and the Taylor
         * polynomial of exp to degree 4 never exceeds exp for x >= 0, so
         * steps within a^2 * poly(x) join. expf is left for the few steps
         * near or beyond the threshold. NaN breaks. */
        if (!(d2 <= a2) && !(d2 <= a2 * exp_lower_bound(two_b * pts->range[i])) &&
            !(d2 <= a2 * bsf_expf(two_b * pts->range[i]))) {
            if (!sink_close(&sink, first, last, n_cur)) {
                return BSF_ERR_CAPACITY;
            }
            first = i;
            n_cur = 0;
        }
        ++n_cur;
        last = i;
        prev = q;
    }
    if (!sink_close(&sink, first, last, n_cur)) {
        return BSF_ERR_CAPACITY;
    }
    return finish(&sink, n_out, n_wasted_points);
}

/* |angle between u and v| <= alpha_max, i.e. u.v >= cos(alpha_max)*|u|*|v|,
 * decided on squares (no sqrt). A zero step has no direction: it passes. */
static int turn_ok(float dot, float uu_vv, float cos_max, float cos_max2)
{
    if (cos_max >= 0.0f) {
        return (dot >= 0.0f) & (dot * dot >= cos_max2 * uu_vv);
    }
    return (dot >= 0.0f) | (dot * dot <= cos_max2 * uu_vv);
}

bsf_status_t bsf_segment_rpos(const bsf_points_t *pts, const bsf_rpos_params_t *params,
                              bsf_segment_t *out, size_t cap, size_t *n_out,
                              size_t *n_wasted_points)
{
    const bsf_rpos_params_t defaults = bsf_rpos_params_default();
    const bsf_rpos_params_t *p = params != NULL ? params : &defaults;
    seg_sink_t sink;
    bsf_status_t st;
    float cos_max;
    float cos_max2;
    float eta2;
    bsf_point_t prev = {0.0f, 0.0f}; /* q[i], the segment's last point */
    float ux = 0.0f;                 /* q[i] - q[i-1] */
    float uy = 0.0f;
    float uu = 0.0f; /* p_i squared */
    size_t first = 0;
    size_t last = 0;
    size_t n_cur = 0;
    size_t i;

    st = begin(pts, out, cap, n_out, n_wasted_points, &sink);
    if (st != BSF_OK) {
        return st;
    }
    st = bsf_rpos_params_check(p);
    if (st != BSF_OK) {
        return BSF_ERR_PARAM;
    }
    sink.min_points = p->min_segment_points;
    cos_max = bsf_cosf(p->alpha_max);
    cos_max2 = cos_max * cos_max;
    eta2 = p->eta * p->eta;

    /* The first valid point opens the first segment; then one pass. */
    for (i = 0; i < pts->count && !pts->valid[i]; ++i) {
    }
    if (i == pts->count) {
        return finish(&sink, n_out, n_wasted_points);
    }
    first = i;
    last = i;
    prev = pts->pt[i];
    n_cur = 1;
    for (++i; i < pts->count; ++i) {
        const bsf_point_t q = pts->pt[i];
        float vx;
        float vy;
        float vv;
        float dot;
        int spacing_ok;
        if (!pts->valid[i]) {
            continue; /* RPOS works on consecutive valid points */
        }
        vx = q.x - prev.x;
        vy = q.y - prev.y;
        vv = vx * vx + vy * vy;
        dot = ux * vx + uy * vy;
        /* max(p_i, p_i+1) <= eta * min(p_i, p_i+1), squared, as two
         * comparisons joined by & (no data-dependent branch). NaN fails.
         * A one-point segment takes its second point unconditionally. */
        spacing_ok = (uu <= eta2 * vv) & (vv <= eta2 * uu);
        if (n_cur >= 2u && !(spacing_ok & turn_ok(dot, uu * vv, cos_max, cos_max2))) {
            if (!sink_close(&sink, first, last, n_cur)) {
                return BSF_ERR_CAPACITY;
            }
            first = i;
            n_cur = 0;
        } else {
            ux = vx;
            uy = vy;
            uu = vv;
        }
        ++n_cur;
        last = i;
        prev = q;
    }
    if (!sink_close(&sink, first, last, n_cur)) {
        return BSF_ERR_CAPACITY;
    }
    return finish(&sink, n_out, n_wasted_points);
}

/* First valid beam in [from, to] into *at; 0 when there is none. */
static int next_valid(const bsf_points_t *pts, size_t from, size_t to, size_t *at)
{
    for (; from <= to; ++from) {
        if (pts->valid[from]) {
            *at = from;
            return 1;
        }
    }
    return 0;
}

/* Last valid beam in [from, to] into *at; 0 when there is none. */
static int prev_valid(const bsf_points_t *pts, size_t from, size_t to, size_t *at)
{
    size_t i = to + 1u;
    while (i > from) {
        --i;
        if (pts->valid[i]) {
            *at = i;
            return 1;
        }
    }
    return 0;
}

/* Index of the first interest beam > key (interest is strictly ascending). */
static size_t upper_bound(const uint16_t *interest, size_t n, size_t key)
{
    size_t lo = 0;
    size_t hi = n;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2u;
        if ((size_t)interest[mid] <= key) {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

bsf_status_t bsf_segment_classify(bsf_segment_t *segs, size_t n, const bsf_points_t *pts,
                                  const uint16_t *interest_beams, size_t n_interest)
{
    size_t k;
    if (pts == NULL || (segs == NULL && n > 0u) || (interest_beams == NULL && n_interest > 0u)) {
        return BSF_ERR_ARG;
    }
    if (pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    for (k = 1; k < n_interest; ++k) {
        if (interest_beams[k] <= interest_beams[k - 1u]) {
            return BSF_ERR_ARG;
        }
    }
    for (k = 0; k < n; ++k) {
        if (segs[k].first > segs[k].last || (size_t)segs[k].last >= pts->count) {
            return BSF_ERR_ARG;
        }
    }

    for (k = 0; k < n; ++k) {
        bsf_segment_t *s = &segs[k];
        const size_t first = s->first;
        const size_t last = s->last;
        size_t count = 0;
        size_t v0 = 0;
        size_t v1 = 0;
        size_t w0 = 0;
        size_t w1 = 0;
        /* Inner interest points lie strictly between the second valid point
         * (v1) and the last-but-one valid point (w1). */
        if (next_valid(pts, first, last, &v0) && v0 < last && next_valid(pts, v0 + 1u, last, &v1) &&
            prev_valid(pts, first, last, &w0) && w0 > first &&
            prev_valid(pts, first, w0 - 1u, &w1) && v1 < w1) {
            size_t j = upper_bound(interest_beams, n_interest, v1);
            for (; j < n_interest && (size_t)interest_beams[j] < w1; ++j) {
                if (pts->valid[interest_beams[j]]) {
                    ++count;
                }
            }
        }
        s->n_interest = (uint8_t)(count > 255u ? 255u : count);
        s->kind = (uint8_t)(count > 0u ? BSF_FEATURE_AUXILIARY : BSF_FEATURE_BLEAK);
    }
    return BSF_OK;
}
