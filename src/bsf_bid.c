/* SPDX-License-Identifier: MIT */
/* BID: the B-spline interest point detector (docs/DESIGN.md, "Methods"). */
#include "bsf/bsf_bid.h"
#include "bsf_fit_internal.h"
#include "bsf_math.h"
#include "bsf_nms.h"

#include <math.h>
#include <string.h>

/* N_q of a beam that is not a candidate. */
#define BID_NO_SCORE 3.402823466e38f

/*
 * Default threshold T_th = 0.3, calibrated with tools/bid_calibrate on
 * synthetic scans over 180 degrees (181 and 361 beams, range noise 5 and
 * 10 mm; 90 and 60 degree corners, concave and convex, 2-6 m away, turned by
 * up to 0.3 rad; straight walls 2-6 m away tilted up to 0.6 rad; circles of
 * radius 0.5-2 m). The smallest N_q near a corner was at most 0.295 for every
 * corner but one (a 60 degree corner 4 m away with 181 beams: 0.31, about two
 * points per wall inside r_q); straight walls stayed >= 0.32 (typically
 * 0.4-0.5) and circles >= 0.38.
 */
bsf_bid_params_t bsf_bid_params_default(void)
{
    bsf_bid_params_t p;
    p.neigh_a = 0.2f;
    p.neigh_b = 0.07f;
    p.t_th = 0.3f;
    p.nms_radius = 0.1f;
    p.min_side_points = 2u;
    p.max_iterations = 10u;
    p.rel_tol = 0.01f;
    return p;
}

bsf_status_t bsf_bid_params_check(const bsf_bid_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    /* Written so that NaN fails every test. */
    if (!(p->neigh_a > 0.0f && p->neigh_a <= 100.0f) ||
        !(p->neigh_b >= 0.0f && p->neigh_b <= 10.0f) || !(p->t_th > 0.0f && p->t_th < 1.0f) ||
        !(p->nms_radius >= 0.0f && p->nms_radius <= 100.0f) || p->min_side_points < 1u ||
        p->max_iterations < 1u || p->max_iterations > BSF_PDM_MAX_ITERATIONS ||
        !(p->rel_tol > 0.0f && p->rel_tol < 1.0f)) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

static float dist2(bsf_point_t a, bsf_point_t b)
{
    const float dx = b.x - a.x;
    const float dy = b.y - a.y;
    return dx * dx + dy * dy;
}

/* Gather q's neighbourhood in beam order: valid points walking outwards from
 * q until the first valid point farther than r on each side. Returns the
 * count; *n_left and *n_right get the points on each side of q. */
static size_t gather(const bsf_points_t *pts, size_t q, float r, bsf_point_t *out, size_t *n_left,
                     size_t *n_right)
{
    const float r2 = r * r;
    const bsf_point_t c = pts->pt[q];
    size_t n = 0;
    size_t j;
    size_t left = 0;

    /* Left side: walk outwards to find the first index, then copy in order. */
    j = q;
    while (j > 0u) {
        --j;
        if (!pts->valid[j]) {
            continue;
        }
        if (dist2(pts->pt[j], c) > r2) {
            ++j;
            break;
        }
        ++left;
    }
    for (; j < q; ++j) {
        if (pts->valid[j]) {
            out[n++] = pts->pt[j];
        }
    }
    out[n++] = c;
    for (j = q + 1u; j < pts->count; ++j) {
        if (!pts->valid[j]) {
            continue;
        }
        if (dist2(pts->pt[j], c) > r2) {
            break;
        }
        out[n++] = pts->pt[j];
    }
    *n_left = left;
    *n_right = n - left - 1u;
    return n;
}

/* N_q of one neighbourhood, or BID_NO_SCORE when it cannot be fitted. */
static float corner_measure(const bsf_point_t *nb, size_t n, const bsf_pdm_params_t *pp,
                            bsf_pdm_work_t *pdm)
{
    bsf_point_t ctrl[4];
    uint32_t iterations = 0;
    float a;
    float b;
    float c;

    if (bsf_pdm_fit_chord(nb, n, 4u, pp, pdm, ctrl, NULL, &iterations) != BSF_OK) {
        return BID_NO_SCORE;
    }
    a = sqrtf(dist2(ctrl[0], ctrl[1]));
    b = sqrtf(dist2(ctrl[1], ctrl[2]));
    c = sqrtf(dist2(ctrl[2], ctrl[3]));
    if (!(a + b + c > 0.0f)) {
        return BID_NO_SCORE;
    }
    return b / (a + b + c);
}

bsf_status_t bsf_bid_detect(const bsf_points_t *pts, const bsf_bid_params_t *p,
                            bsf_bid_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                            size_t *n_out)
{
    bsf_bid_params_t defaults;
    bsf_pdm_params_t pp;
    bsf_status_t st;
    size_t q;
    size_t n_peak;
    size_t k;

    if (n_out != NULL) {
        *n_out = 0u;
    }
    if (pts == NULL || work == NULL || n_out == NULL || (out == NULL && out_cap > 0u)) {
        return BSF_ERR_ARG;
    }
    if (p == NULL) {
        defaults = bsf_bid_params_default();
        p = &defaults;
    }
    st = bsf_bid_params_check(p);
    if (st != BSF_OK) {
        return st;
    }
    if (pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    if (!(fabsf(pts->angle_increment) > 0.0f) ||
        !(fabsf(pts->angle_increment) <= 3.402823466e38f)) {
        return BSF_ERR_ARG;
    }
    bsf_pdm_params_default(&pp);
    pp.refine = 0u;
    pp.max_iterations = p->max_iterations;
    pp.rel_tol = p->rel_tol;

    for (q = 0; q < pts->count; ++q) {
        size_t n_left;
        size_t n_right;
        size_t n;
        float r;
        work->score[q] = BID_NO_SCORE;
        if (!pts->valid[q] || bsf_fit_check_points(&pts->pt[q], 1u) != BSF_OK) {
            continue;
        }
        r = p->neigh_a * bsf_expf(p->neigh_b * pts->range[q]);
        n = gather(pts, q, r, work->neigh, &n_left, &n_right);
        if (n_left < p->min_side_points || n_right < p->min_side_points ||
            bsf_fit_check_points(work->neigh, n) != BSF_OK) {
            continue;
        }
        work->score[q] = corner_measure(work->neigh, n, &pp, &work->pdm);
    }

    n_peak = bsf_nms_beams(pts, work->score, BSF_NMS_LOWER_IS_BETTER, p->t_th, p->nms_radius,
                           work->peak);
    *n_out = n_peak;
    /* Over the cap, the strongest keypoints are the ones worth keeping. */
    n_peak = bsf_nms_keep_best(work->score, BSF_NMS_LOWER_IS_BETTER, work->peak, n_peak, out_cap);
    for (k = 0; k < n_peak; ++k) {
        const size_t b = work->peak[k];
        out[k].index = (uint16_t)b;
        out[k].point = pts->pt[b];
        out[k].orientation = 0.0f;
        out[k].radius = p->neigh_a * bsf_expf(p->neigh_b * pts->range[b]);
        out[k].score = work->score[b];
    }
    return *n_out > out_cap ? BSF_ERR_CAPACITY : BSF_OK;
}
