/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_scan.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

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
    return bsf_finite_bits(v);
}

int bsf_range_is_valid(float r, float range_min, float range_max)
{
    return is_finite_f(r) && r > 0.0f && r >= range_min && r < range_max;
}

/* For v >= 0 (-0 included): the largest float below v, or 0 for 0, so
 * that r > float_below(v) exactly when r > 0 and r >= v. */
static float float_below(float v)
{
    uint32_t bits;
    if (v == 0.0f) {
        return 0.0f;
    }
    memcpy(&bits, &v, sizeof bits);
    bits -= 1u; /* positive floats order as their bit patterns */
    memcpy(&v, &bits, sizeof v);
    return v;
}

/* Points of a checked scan; returns the number of valid beams. Inline with
 * a constant bounded, so each call site is its own loop. */
static inline size_t fill_points(const bsf_scan_t *scan, bsf_points_t *out, int bounded)
{
    /* Locals: out may alias *scan as far as the compiler knows, so fields
     * read through scan would be reloaded after every store. */
    const float *ranges = scan->ranges;
    const size_t count = scan->count;
    const float angle_min = scan->angle_min;
    const float increment = scan->angle_increment;
    const float range_max = scan->range_max;
    const float range_above = float_below(scan->range_min);
    size_t n_valid = 0;
    size_t i;
    float beam = 0.0f; /* (float)i, exact: i <= BSF_MAX_POINTS < 2^24 */
    for (i = 0; i < count; ++i, beam += 1.0f) {
        const float r = ranges[i];
        /* bsf_range_is_valid with range_min >= 0 checked: r > range_above
         * is r > 0 && r >= range_min; NaN fails it, +-inf fails it or
         * r < range_max (a range_max of +inf included), so no separate
         * finiteness test. */
        if (r > range_above && r < range_max) {
            const float a = angle_min + beam * increment;
            float s;
            float c;
            if (bounded) {
                bsf_sincosf_bounded(a, &s, &c); /* bits of bsf_sinf(a), bsf_cosf(a) */
            } else {
                /* beyond 16000 rad (caps far above the default): the
                 * out-of-line functions, to keep one copy of the code */
                s = bsf_sinf(a);
                c = bsf_cosf(a);
            }
            out->pt[i].x = r * c;
            out->pt[i].y = r * s;
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
    return n_valid;
}

#if BSF_CONFIG_SIMD && (defined(__SSE2__) || defined(__ARM_NEON))
#define SCAN_BRANCH_FREE 1
#else
#define SCAN_BRANCH_FREE 0
#endif

#if SCAN_BRANCH_FREE
/* fill_points(scan, out, 1) without branches, which compilers turn into
 * vector code (4 beams per step with SSE2 or NEON): every beam's sine and
 * cosine as bsf_sincosf_bounded computes them (the same expressions, its
 * quadrant turns as bit operations: a negation flips the sign bit), then the
 * invalid beams' values masked to +0. The same bits as the loop above. */
static size_t fill_points_branch_free(const bsf_scan_t *scan, bsf_points_t *out)
{
    const float *ranges = scan->ranges;
    const size_t count = scan->count;
    const float angle_min = scan->angle_min;
    const float increment = scan->angle_increment;
    const float range_max = scan->range_max;
    const float range_above = float_below(scan->range_min);
    bsf_point_t *pt = out->pt;
    float *range = out->range;
    uint8_t *valid = out->valid;
    uint32_t n_valid = 0;
    size_t i;
    for (i = 0; i < count; ++i) {
        const float r = ranges[i];
        /* (float)i is exact (i <= BSF_MAX_POINTS < 2^24), as the loop's count */
        const float a = angle_min + (float)(int32_t)i * increment;
        const float t = a * BSF_TWO_OVER_PI_F + 0.5f;
        const int32_t k0 = (int32_t)t;
        const int32_t ki = k0 - (int32_t)((float)k0 > t); /* floorf(t) */
        const float k = (float)ki;
        const float rr = ((a - k * BSF_PIO2_1_F) - k * BSF_PIO2_2_F) - k * BSF_PIO2_3_F;
        const uint32_t s = bsf_float_bits(bsf_sin_kernel(rr));
        const uint32_t c = bsf_float_bits(bsf_cos_kernel(rr));
        const uint32_t odd = 0u - ((uint32_t)ki & 1u);   /* all ones: turn by 90 degrees */
        const uint32_t half = ((uint32_t)ki & 2u) << 30; /* sign bit: turn by 180 */
        const uint32_t sin_bits = ((c & odd) | (s & ~odd)) ^ half;
        const uint32_t cos_bits = (((s ^ 0x80000000u) & odd) | (c & ~odd)) ^ half;
        const uint32_t ok = (uint32_t)((r > range_above) & (r < range_max));
        const uint32_t keep = 0u - ok;
        pt[i].x = bsf_bits_float(bsf_float_bits(r * bsf_bits_float(cos_bits)) & keep);
        pt[i].y = bsf_bits_float(bsf_float_bits(r * bsf_bits_float(sin_bits)) & keep);
        range[i] = bsf_bits_float(bsf_float_bits(r) & keep);
        valid[i] = (uint8_t)ok;
        n_valid += ok;
    }
    return (size_t)n_valid;
}
#endif

/* Every beam's point, the fastest way this build has (the same bits every
 * way). With every beam angle within bsf_sincosf_bounded's domain (a margin
 * of 384 rad covers the rounding of this bound and of the angles): one loop
 * without the checks only huge angles need, chosen once per scan, or the
 * branch-free loop (BSF_CONFIG_SIMD). The compact variant without SIMD
 * calls the out-of-line functions for every angle. */
static size_t fill_all_points(const bsf_scan_t *scan, bsf_points_t *out)
{
#if SCAN_BRANCH_FREE || !BSF_CONFIG_COMPACT
    if (fabsf(scan->angle_min) + (float)scan->count * fabsf(scan->angle_increment) <= 16000.0f) {
#if SCAN_BRANCH_FREE
        return fill_points_branch_free(scan, out);
#else
        return fill_points(scan, out, 1);
#endif
    }
#endif
    return fill_points(scan, out, 0);
}

bsf_status_t bsf_scan_to_points(const bsf_scan_t *scan, bsf_points_t *out)
{
    size_t n_valid;

    if (scan == NULL || out == NULL || (scan->count > 0 && scan->ranges == NULL)) {
        return BSF_ERR_ARG;
    }
    if (scan->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    if (!(fabsf(scan->angle_min) <= BSF_MAX_ABS_ANGLE_MIN) || scan->angle_increment == 0.0f ||
        !(fabsf(scan->angle_increment) <= BSF_MAX_ABS_INCREMENT) || !is_finite_f(scan->range_min) ||
        scan->range_min < 0.0f || !(scan->range_max > scan->range_min)) {
        /* The angles within their bounds are finite (NaN and +-inf fail the
         * tests); range_max may be +inf ("no upper bound"), NaN fails. */
        return BSF_ERR_ARG;
    }

    n_valid = fill_all_points(scan, out);
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
        /* The largest valid reading and how many beams read it, then, when
         * they are enough for one, its runs of equal beams. */
        size_t run = 0;
        size_t n_top = 0;
        for (i = 0; i < pts->count; ++i) {
            if (pts->valid[i]) {
                const float r = pts->range[i];
                /* one test for the usual r < top (a valid range is no NaN) */
                if (r >= top) {
                    if (r > top) {
                        top = r;
                        n_top = 1u;
                    } else {
                        ++n_top;
                    }
                }
            }
        }
        if (n_top < (size_t)p->min_run) {
            top = 0.0f; /* no run of min_run equal readings at the top */
        }
        for (i = 0; i < pts->count && top > 0.0f && !top_is_code; ++i) {
            run = (pts->valid[i] && pts->range[i] == top) ? run + 1u : 0u;
            if (run >= (size_t)p->min_run &&
                (i + 1u == pts->count || !pts->valid[i + 1u] || pts->range[i + 1u] != top)) {
                top_is_code = jumps_on_both_sides(pts, i + 1u - run, i, top);
            }
        }
    }
    for (i = 0; (p->code > 0.0f || top_is_code) && i < pts->count; ++i) {
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

void bsf_no_return_learner_init(bsf_no_return_learner_t *l)
{
    if (l != NULL) {
        memset(l, 0, sizeof *l);
    }
}

/* Is some run of beams reading exactly top, in the raw scan, more than 10 %
 * above the valid readings next to it on both sides (each side having one)?
 * Returns 1 and its first beam in *at, else 0. */
static int isolated_top(const bsf_scan_t *scan, float top, size_t *at)
{
    const float jump = 0.1f * top;
    size_t i = 0;
    while (i < scan->count) {
        size_t last = i;
        size_t j;
        int left = 0;
        int right = 0;
        if (scan->ranges[i] != top ||
            !bsf_range_is_valid(scan->ranges[i], scan->range_min, scan->range_max)) {
            ++i;
            continue;
        }
        while (last + 1u < scan->count && scan->ranges[last + 1u] == top) {
            ++last;
        }
        for (j = i; j > 0u; --j) {
            const float r = scan->ranges[j - 1u];
            if (bsf_range_is_valid(r, scan->range_min, scan->range_max)) {
                left = top - r > jump;
                break;
            }
        }
        for (j = last + 1u; j < scan->count; ++j) {
            const float r = scan->ranges[j];
            if (bsf_range_is_valid(r, scan->range_min, scan->range_max)) {
                right = top - r > jump;
                break;
            }
        }
        if (left && right) {
            *at = i;
            return 1;
        }
        i = last + 1u;
    }
    return 0;
}

bsf_status_t bsf_no_return_learn(bsf_no_return_learner_t *l, const bsf_scan_t *scan,
                                 float *code_out)
{
    float top = 0.0f;
    size_t at = 0;
    size_t i;
    if (code_out != NULL) {
        *code_out = l != NULL ? l->code : 0.0f;
    }
    if (l == NULL || scan == NULL || (scan->count > 0u && scan->ranges == NULL)) {
        return BSF_ERR_ARG;
    }
    if (scan->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    if (l->code > 0.0f) {
        return BSF_OK;
    }
    l->n_scans = (l->n_scans + 1u) % BSF_NO_RETURN_AGE_SCANS;
    if (l->n_scans == 0u) {
        /* Old evidence fades: a value must keep recurring to become a code,
         * and a value that recurred once for a while frees its slot. */
        for (i = 0; i < BSF_NO_RETURN_CANDIDATES; ++i) {
            l->count[i] /= 2u;
        }
    }
    for (i = 0; i < scan->count; ++i) {
        const float r = scan->ranges[i];
        if (bsf_range_is_valid(r, scan->range_min, scan->range_max) && r > top) {
            top = r;
        }
    }
    if (top > 0.0f && isolated_top(scan, top, &at)) {
        /* Count it: its own slot, else the weakest one (an empty slot has
         * count 0), whose value it replaces with no evidence of its own. */
        size_t slot = BSF_NO_RETURN_CANDIDATES;
        size_t weakest = 0;
        for (i = 0; i < BSF_NO_RETURN_CANDIDATES; ++i) {
            if (l->value[i] == top) {
                slot = i;
                break;
            }
            if (l->count[i] < l->count[weakest]) {
                weakest = i;
            }
        }
        if (slot == BSF_NO_RETURN_CANDIDATES) {
            slot = weakest;
            l->value[slot] = top;
            l->count[slot] = 0u;
            l->beam[slot] = (uint16_t)(at + 3u); /* never "the same beam" */
        }
        /* The same beam or its neighbour as last time is no new evidence. */
        if ((at > (size_t)l->beam[slot] ? at - l->beam[slot] : l->beam[slot] - at) > 1u &&
            l->count[slot] < UINT32_MAX) {
            l->count[slot]++;
        }
        l->beam[slot] = (uint16_t)at;
        if (l->count[slot] >= BSF_NO_RETURN_LEARN_SCANS) {
            l->code = top;
        }
    }
    if (code_out != NULL) {
        *code_out = l->code;
    }
    return BSF_OK;
}
