/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_bspline.h"
#include "bsf_math.h"
#include "bsf/bsf_fit.h"
#include "bsf_fit_internal.h"

#include <math.h>

static int finite_f(float v)
{
    return bsf_finite_bits(v);
}

size_t bsf_bspline_span(size_t n_ctrl, float t, float *u_out)
{
    size_t n_span;
    size_t span;
    float x;

    if (n_ctrl < 3u) {
        if (u_out != NULL) {
            *u_out = 0.0f;
        }
        return 0u;
    }
    n_span = n_ctrl - 2u;
    if (!(t > 0.0f)) {
        t = 0.0f; /* also catches NaN */
    } else if (t > 1.0f) {
        t = 1.0f;
    }
    x = t * (float)n_span;
    /* Compare before converting: for a huge n_span the float product can
     * exceed what size_t holds, and that conversion is undefined. */
    if (x >= (float)n_span) {
        span = n_span - 1u; /* t == 1 belongs to the last span */
    } else {
        span = (size_t)x;
        if (span >= n_span) {
            span = n_span - 1u;
        }
    }
    if (u_out != NULL) {
        float u = x - (float)span;
        *u_out = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
    }
    return span;
}

/* Basis and derivatives with respect to u (the span's local coordinate). The
 * first and last spans differ from the interior ones because the end knots
 * are tripled; a single span is the Bernstein quadratic. */
void bsf_bspline_basis_u(size_t n_span, size_t span, float u, float b[3], float du[3], float ddu[3])
{
    const float v = 1.0f - u;
    const int first = span == 0u;
    const int last = span + 1u == n_span;

    if (first && last) {
        b[0] = v * v;
        b[2] = u * u;
        du[0] = -2.0f * v;
        du[2] = 2.0f * u;
        ddu[0] = 2.0f;
        ddu[1] = -4.0f;
        ddu[2] = 2.0f;
    } else if (first) {
        b[0] = v * v;
        b[2] = 0.5f * u * u;
        du[0] = -2.0f * v;
        du[2] = u;
        ddu[0] = 2.0f;
        ddu[1] = -3.0f;
        ddu[2] = 1.0f;
    } else if (last) {
        b[0] = 0.5f * v * v;
        b[2] = u * u;
        du[0] = -v;
        du[2] = 2.0f * u;
        ddu[0] = 1.0f;
        ddu[1] = -3.0f;
        ddu[2] = 2.0f;
    } else {
        b[0] = 0.5f * v * v;
        b[2] = 0.5f * u * u;
        du[0] = -v;
        du[2] = u;
        ddu[0] = 1.0f;
        ddu[1] = -2.0f;
        ddu[2] = 1.0f;
    }
    /* Partition of unity fixes the middle function exactly. */
    b[1] = 1.0f - b[0] - b[2];
    du[1] = -du[0] - du[2];
}

void bsf_bspline_basis(size_t n_ctrl, size_t span, float u, float basis[3], float d1[3],
                       float d2[3])
{
    float du[3];
    float ddu[3];
    size_t k;

    if (n_ctrl < 3u || span + 2u >= n_ctrl) {
        for (k = 0; k < 3u; ++k) {
            basis[k] = 0.0f;
            if (d1 != NULL) {
                d1[k] = 0.0f;
            }
            if (d2 != NULL) {
                d2[k] = 0.0f;
            }
        }
        return;
    }
    bsf_bspline_basis_u(n_ctrl - 2u, span, u, basis, du, ddu);
    {
        const float s = (float)(n_ctrl - 2u); /* dt = du / s */
        for (k = 0; k < 3u; ++k) {
            if (d1 != NULL) {
                d1[k] = du[k] * s;
            }
            if (d2 != NULL) {
                d2[k] = ddu[k] * s * s;
            }
        }
    }
}

void bsf_bspline_eval_u(const bsf_point_t *ctrl, size_t n_ctrl, size_t span, float u,
                        bsf_point_t *c, bsf_point_t *cu, bsf_point_t *cuu)
{
    float b[3];
    float du[3];
    float ddu[3];
    const bsf_point_t *p = ctrl + span;

    bsf_bspline_basis_u(n_ctrl - 2u, span, u, b, du, ddu);
    c->x = b[0] * p[0].x + b[1] * p[1].x + b[2] * p[2].x;
    c->y = b[0] * p[0].y + b[1] * p[1].y + b[2] * p[2].y;
    cu->x = du[0] * p[0].x + du[1] * p[1].x + du[2] * p[2].x;
    cu->y = du[0] * p[0].y + du[1] * p[1].y + du[2] * p[2].y;
    cuu->x = ddu[0] * p[0].x + ddu[1] * p[1].x + ddu[2] * p[2].x;
    cuu->y = ddu[0] * p[0].y + ddu[1] * p[1].y + ddu[2] * p[2].y;
}

bsf_status_t bsf_bspline_eval(const bsf_point_t *ctrl, size_t n_ctrl, float t, bsf_point_t *pt,
                              bsf_point_t *d1, bsf_point_t *d2)
{
    bsf_point_t c;
    bsf_point_t cu;
    bsf_point_t cuu;
    size_t span;
    float u;
    float s;

    if (ctrl == NULL || pt == NULL || !finite_f(t)) {
        return BSF_ERR_ARG;
    }
    if (n_ctrl < 3u) {
        return BSF_ERR_DEGENERATE;
    }
    if (n_ctrl > (size_t)BSF_MAX_CTRL_PER_FEATURE) {
        return BSF_ERR_CAPACITY;
    }
    span = bsf_bspline_span(n_ctrl, t, &u);
    bsf_bspline_eval_u(ctrl, n_ctrl, span, u, &c, &cu, &cuu);
    s = (float)(n_ctrl - 2u);
    *pt = c;
    if (d1 != NULL) {
        d1->x = cu.x * s;
        d1->y = cu.y * s;
    }
    if (d2 != NULL) {
        d2->x = cuu.x * s * s;
        d2->y = cuu.y * s * s;
    }
    return BSF_OK;
}

float bsf_footpoint_refine(const bsf_point_t *ctrl, size_t n_ctrl, bsf_point_t p, float *t,
                           unsigned max_steps)
{
    const float n_span = (float)(n_ctrl - 2u);
    bsf_point_t c;
    bsf_point_t cu;
    bsf_point_t cuu;
    bsf_point_t cn;
    bsf_point_t cun;
    bsf_point_t cuun;
    float u;
    float t_cur = *t;
    float best;
    unsigned step;
    size_t span = bsf_bspline_span(n_ctrl, t_cur, &u);

    bsf_bspline_eval_u(ctrl, n_ctrl, span, u, &c, &cu, &cuu);
    {
        const float ex = c.x - p.x;
        const float ey = c.y - p.y;
        best = ex * ex + ey * ey;
    }
    for (step = 0; step < max_steps; ++step) {
        const float ex = c.x - p.x;
        const float ey = c.y - p.y;
        const float g = ex * cu.x + ey * cu.y;
        const float gn = cu.x * cu.x + cu.y * cu.y;
        float h = gn + ex * cuu.x + ey * cuu.y;
        float t_new;
        float delta;
        float d = best;
        unsigned halving;

        if (!(h >= 0.5f * gn)) {
            /* Curvature makes the Newton step huge or uphill: take the
             * Gauss-Newton step instead. */
            h = gn;
        }
        if (!(h > 0.0f)) {
            break;
        }
        /* A step in u is a step of du / n_span in t; the new t may fall in a
         * neighbouring span, which is then evaluated with its own closed form.
         * A step that does not bring the curve closer is halved (twice at
         * most): far from the curve the distance is not quadratic in t. */
        delta = -g / (h * n_span);
        if (!(fabsf(delta) * n_span > 1e-4f)) {
            break; /* converged: a step this small cannot be resolved */
        }
        for (halving = 0; halving < 3u; ++halving) {
            t_new = t_cur + delta;
            t_new = t_new < 0.0f ? 0.0f : (t_new > 1.0f ? 1.0f : t_new);
            if (!(fabsf(t_new - t_cur) > 1e-7f)) {
                break;
            }
            span = bsf_bspline_span(n_ctrl, t_new, &u);
            bsf_bspline_eval_u(ctrl, n_ctrl, span, u, &cn, &cun, &cuun);
            {
                const float fx = cn.x - p.x;
                const float fy = cn.y - p.y;
                d = fx * fx + fy * fy;
            }
            if (d < best) {
                break;
            }
            delta *= 0.5f;
        }
        if (!(d < best)) {
            break; /* never accept a worse footpoint */
        }
        best = d;
        t_cur = t_new;
        c = cn;
        cu = cun;
        cuu = cuun;
    }
    *t = t_cur;
    return best;
}

void bsf_fit_accumulate(float *band, float *rx, float *ry, const uint8_t unk[3], const float w[3],
                        float weight, float px, float py)
{
    float cw[3];
    uint8_t cu[3];
    size_t n = 0;
    size_t a;
    size_t b;

    /* Merge the coefficients of tied columns first (unknowns are non-decreasing). */
    for (a = 0; a < 3u; ++a) {
        if (n > 0u && cu[n - 1u] == unk[a]) {
            cw[n - 1u] += w[a];
        } else {
            cu[n] = unk[a];
            cw[n] = w[a];
            ++n;
        }
    }
    for (a = 0; a < n; ++a) {
        const float wa = weight * cw[a];
        for (b = 0; b <= a; ++b) {
            band[(size_t)cu[a] * 3u + (size_t)(cu[a] - cu[b])] += wa * cw[b];
        }
        if (rx != NULL) {
            rx[cu[a]] += wa * px;
            ry[cu[a]] += wa * py;
        }
    }
}

bsf_status_t bsf_fit_check_points(const bsf_point_t *pts, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        /* NaN fails every comparison, so it is rejected here too. */
        if (!(fabsf(pts[i].x) <= BSF_FIT_MAX_COORD) || !(fabsf(pts[i].y) <= BSF_FIT_MAX_COORD)) {
            return BSF_ERR_ARG;
        }
    }
    return BSF_OK;
}
