/* SPDX-License-Identifier: MIT */
/* LSBA: the paper's least-squares baseline with four control points. */
#include "bsf/bsf_fit.h"
#include "bsf/bsf_bspline.h"
#include "bsf_fit_internal.h"
#include "bsf_linalg.h"

#include <math.h>
#include <string.h>

#define LSBA_N_CTRL 4u
/* Newton steps of the footpoint projection used for E_curve. */
#define LSBA_FOOTPOINT_STEPS 4u

static float seg_len(const bsf_point_t *a, const bsf_point_t *b)
{
    const float dx = b->x - a->x;
    const float dy = b->y - a->y;
    return sqrtf(dx * dx + dy * dy);
}

bsf_status_t bsf_lsba_fit(const bsf_point_t *pts, size_t n, bsf_point_t ctrl_out[4],
                          float *e_curve_out)
{
    float band[LSBA_N_CTRL * 3u];
    float factor[LSBA_N_CTRL * 3u];
    float rx[LSBA_N_CTRL];
    float ry[LSBA_N_CTRL];
    bsf_point_t ctrl[LSBA_N_CTRL];
    float total = 0.0f;
    float acc = 0.0f;
    float sum_sq = 0.0f;
    size_t i;
    bsf_status_t st;

    if (pts == NULL || ctrl_out == NULL) {
        return BSF_ERR_ARG;
    }
    if (n > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = bsf_fit_check_points(pts, n);
    if (st != BSF_OK) {
        return st;
    }
    if (n < LSBA_N_CTRL) {
        return BSF_ERR_DEGENERATE;
    }
    for (i = 1; i < n; ++i) {
        total += seg_len(&pts[i - 1u], &pts[i]);
    }
    if (!(total > 0.0f)) {
        return BSF_ERR_DEGENERATE;
    }

    memset(band, 0, sizeof band);
    memset(rx, 0, sizeof rx);
    memset(ry, 0, sizeof ry);
    for (i = 0; i < n; ++i) {
        float b[3];
        float du[3];
        float ddu[3];
        float u;
        uint8_t unk[3];
        size_t span;
        if (i > 0u) {
            acc += seg_len(&pts[i - 1u], &pts[i]);
        }
        span = bsf_bspline_span(LSBA_N_CTRL, acc / total, &u);
        bsf_bspline_basis_u(LSBA_N_CTRL - 2u, span, u, b, du, ddu);
        unk[0] = (uint8_t)span;
        unk[1] = (uint8_t)(span + 1u);
        unk[2] = (uint8_t)(span + 2u);
        /* Relative to the first point: keeps the normal equations well scaled. */
        bsf_fit_accumulate(band, rx, ry, unk, b, 1.0f, pts[i].x - pts[0].x, pts[i].y - pts[0].y);
    }
    st = bsf_spd_band_solve2(band, LSBA_N_CTRL, 2u, factor, rx, ry, NULL);
    if (st != BSF_OK) {
        return BSF_ERR_NUMERIC;
    }
    for (i = 0; i < LSBA_N_CTRL; ++i) {
        ctrl[i].x = rx[i];
        ctrl[i].y = ry[i];
    }

    /* E_curve at footpoints: start from the chord parameter, move to the
     * nearest curve point. */
    acc = 0.0f;
    for (i = 0; i < n; ++i) {
        bsf_point_t q;
        float t;
        if (i > 0u) {
            acc += seg_len(&pts[i - 1u], &pts[i]);
        }
        t = acc / total;
        q.x = pts[i].x - pts[0].x;
        q.y = pts[i].y - pts[0].y;
        sum_sq += bsf_footpoint_refine(ctrl, LSBA_N_CTRL, q, &t, LSBA_FOOTPOINT_STEPS);
    }
    for (i = 0; i < LSBA_N_CTRL; ++i) {
        ctrl_out[i].x = ctrl[i].x + pts[0].x;
        ctrl_out[i].y = ctrl[i].y + pts[0].y;
    }
    if (e_curve_out != NULL) {
        *e_curve_out = sqrtf(sum_sq / (float)n);
    }
    return BSF_OK;
}
