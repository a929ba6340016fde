/* SPDX-License-Identifier: MIT */
/* LC, the line-corner detector (include/bsf/bsf_lc.h explains the method). */
#include "bsf/bsf_lc.h"
#include "bsf_compact.h"
#include "bsf_grazing.h"
#include "bsf_lc_internal.h"
#include "bsf_math.h"

#include <float.h>
#include <math.h>
#include <stddef.h>
#include <string.h>

#if BSF_CONFIG_SIMD && defined(__SSE2__)
#include <emmintrin.h>
/* Speed only, same sums: the fits' loops on two points per step, each lane
 * adding the same products in the same order as the scalar loop. */
#define LC_SSE2 1
#endif

#ifdef LC_SSE2
/* Points p and q in lanes (p.x, p.y, q.x, q.y). */
static inline __m128 lc_pair(const bsf_point_t *p, const bsf_point_t *q)
{
    float v[4];
    memcpy(&v[0], p, 2u * sizeof v[0]);
    memcpy(&v[2], q, 2u * sizeof v[0]);
    return _mm_loadu_ps(v);
}
#endif

/* Split-judge passes per run: each pass after the first only re-judges the
 * neighbours of merged splits, and a run rarely needs more than three. */
#define LC_MAX_PASSES 8u
/* sqrt(1.5) * sqrt(2/pi): mean |distance of a point from its neighbours'
 * chord| per unit of Gaussian noise normal to a straight wall. */
#define LC_NOISE_MEAN_ABS 0.9772f
/* Single distances above this do not count towards the noise estimate
 * (corners and jumps inside a run), metres. */
#define LC_NOISE_CLIP 0.05f
/* Shortest span across the ray of the beams from a point to either end of
 * its chord in the noise estimate, metres: well above range noise, well
 * below the length of a wall. */
#define LC_NOISE_BASE 0.05f
/* A circle is only a candidate shape when its radius is below this multiple
 * of the window's extent: a larger one is a line in float arithmetic. */
#define LC_CIRCLE_MAX_RADIUS 10.0f
/* Evidence a corner needs against the best smooth curve (corner_test_init):
 * with many points, the curve's squared residual must exceed the two lines'
 * by this squared times the noise variance, which chance (two chi-square
 * degrees of freedom: one more parameter and the apex point) exceeds once
 * in about 270 000 judgements. */
#define LC_EVIDENCE_SIGMAS 5.0f
/* Gauss-Newton steps of the geometric circle fit in the evidence route. */
#define LC_CIRCLE_STEPS 3u
/* Widest occluder, in beams, that a run goes on past when its first return
 * is nearer than the run's end (past_occluder): SVED's default
 * max_gap_beams, so LC judges the corner hidden behind an occluder that
 * SVED's look-back keeps in one segment (a post 16 cm wide 4 m away is 9
 * beams at 0.25 deg). A fixed number: LC does not see the SVED parameters,
 * so it stays 16 whatever sved.max_gap_beams a caller sets. */
#define LC_OCCLUDER_BEAMS 16u

bsf_lc_params_t bsf_lc_params_default(void)
{
    /* one copy of a constant (smaller code than a store per field) */
    static const bsf_lc_params_t defaults = {
        .jump_a = 0.2f,
        .jump_b = 0.07f,
        .split_min = 0.02f,
        .split_sigmas = 4.0f,
        .min_turn = 0.15f,
        .curve_ratio = 10.0f,
        .floor = 0.003f,
        .max_side = 1.5f,
        .apex_slack = 0.05f,
        .min_side_len = 0.15f,
        /* No range limit of its own: a corner needs min_side_points points
         * per side within max_side of the apex, so the beam spacing, not the
         * range, decides how far corners are found (about 57 m at 0.5 deg
         * beams). */
        .max_range = FLT_MAX,
        .min_side_points = 3u,
        .join_grazing = 2u,
        .corner_evidence = 1u,
    };
    return defaults;
}

/* The float parameters' ranges (bsf_floats_in_range): lower bound 0, open
 * where a zero would stop the method. */
#define LC_RANGE(field, hi, open)                                                                  \
    {                                                                                              \
        hi, (uint16_t)offsetof(bsf_lc_params_t, field), open                                       \
    }
static const bsf_float_range_t lc_float_ranges[] = {
    LC_RANGE(jump_a, 1e3f, BSF_RANGE_LO_OPEN),
    LC_RANGE(jump_b, 10.0f, 0u),
    LC_RANGE(split_min, 1e3f, BSF_RANGE_LO_OPEN),
    LC_RANGE(split_sigmas, 1e3f, 0u),
    LC_RANGE(min_turn, 1.5707963f, BSF_RANGE_LO_OPEN | BSF_RANGE_HI_OPEN),
    LC_RANGE(curve_ratio, 1e6f, BSF_RANGE_LO_OPEN),
    LC_RANGE(floor, 1e3f, 0u),
    LC_RANGE(max_side, 1e3f, BSF_RANGE_LO_OPEN),
    LC_RANGE(apex_slack, 1e3f, 0u),
    LC_RANGE(min_side_len, 1e3f, 0u),
    LC_RANGE(max_range, INFINITY, BSF_RANGE_LO_OPEN),
};

bsf_status_t bsf_lc_params_check(const bsf_lc_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (!bsf_floats_in_range(p, lc_float_ranges,
                             sizeof lc_float_ranges / sizeof lc_float_ranges[0]) ||
        p->min_side_points < 2u || p->min_side_points > 64u || p->join_grazing > 2u ||
        p->corner_evidence > 1u) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

/* judge's two verdicts are inlined into it, their one caller: one copy of
 * the window's set-up (code size). */
#if defined(__GNUC__) || defined(__clang__)
#define LC_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define LC_ALWAYS_INLINE static inline
#endif

/* A total-least-squares line: centroid, unit direction, squared residual. */
typedef struct {
    float mx, my;
    float dx, dy;
    float rss;
    float sx, sy; /* the coordinate sums, in order from the first point */
    size_t n;
} lc_line_t;

typedef struct {
    const bsf_points_t *pts;
    const uint16_t *run;
    const bsf_lc_params_t *p;
    bsf_point_t o;    /* origin of the current judgement (the apex point) */
    bsf_point_t *rel; /* run points minus o, filled by judge for its window */
    float sin_min_turn;
    float noise2;       /* the current run's noise variance (run_noise squared), at least floor^2 */
    float noise_points; /* points of the runs judged (their noise: bsf_lc_work_t.noise2) */
    size_t start;       /* beam where the pass starts (ring_start, else 0) */
#if !BSF_CONFIG_COMPACT
    /* room for block summaries of the current run, or NULL (short runs);
     * built when a judge first needs them */
    bsf_lc_block_t *blk;
    int blk_built;
#endif
} lc_ctx_t;

/* Run point pos relative to the origin, stored for the fits: judge's side
 * walks visit every point of the window a0..b1 this way first. */
static void rel_store(const lc_ctx_t *c, size_t pos)
{
    bsf_point_t q = c->pts->pt[c->run[pos]];
    q.x -= c->o.x;
    q.y -= c->o.y;
    c->rel[pos] = q;
}

static float dist2(bsf_point_t a, bsf_point_t b)
{
    const float dx = a.x - b.x;
    const float dy = a.y - b.y;
    return dx * dx + dy * dy;
}

/* dist2 as one copy for the judgement's dozen single uses in the compact
 * build (code size); the loops over a run keep dist2 inlined. */
#if BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
__attribute__((noinline))
#endif
static float
dist2_once(bsf_point_t a, bsf_point_t b)
{
    return dist2(a, b);
}

/* dist2 of run positions i and j relative to the origin (c->rel): one copy
 * for the judgement's single uses in the compact build (code size). */
static BSF_COMPACT_NOINLINE float rel_dist2(const lc_ctx_t *c, size_t i, size_t j)
{
    return dist2(c->rel[i], c->rel[j]);
}

/* Unit eigenvector (*dx, *dy) of the scatter [sxx sxy; sxy syy] for its
 * larger eigenvalue lmax: of the two equivalent forms, the one with the
 * larger norm is the better conditioned. 0 when both vanish (all points
 * coincide). */
static inline int major_axis(float sxx, float sxy, float syy, float lmax, float *dx, float *dy)
{
    const float v1x = sxy;
    const float v1y = lmax - sxx;
    const float v2x = lmax - syy;
    const float v2y = sxy;
    float nrm;
    if (v1x * v1x + v1y * v1y >= v2x * v2x + v2y * v2y) {
        nrm = sqrtf(v1x * v1x + v1y * v1y);
        *dx = v1x;
        *dy = v1y;
    } else {
        nrm = sqrtf(v2x * v2x + v2y * v2y);
        *dx = v2x;
        *dy = v2y;
    }
    if (!(nrm > 0.0f)) {
        return 0;
    }
    *dx /= nrm;
    *dy /= nrm;
    return 1;
}

/* Line through positions a..b of the run (from c->rel), whose coordinate
 * sums over a..from-1, added in order from 0, are sx, sy (from = a, sums 0:
 * all of them). Two passes: centring first keeps float sums exact enough
 * for centimetre noise on 10 m walls. Returns 0 when fewer than two points. */
static int fit_line_from(const lc_ctx_t *c, size_t a, size_t b, size_t from, float sx, float sy,
                         lc_line_t *l)
{
    const bsf_point_t *rp = c->rel;
    float sxx = 0.0f, sxy = 0.0f, syy = 0.0f;
    float half, diff, root, lmax, lmin, mx, my;
    size_t i;
    const size_t n = b + 1u - a;
    if (b < a + 1u) {
        return 0;
    }
    i = from;
#ifdef LC_SSE2
    {
        /* (sx, sy) takes point i, then i + 1 */
        __m128 s = _mm_set_ps(0.0f, 0.0f, sy, sx);
        for (; i < b; i += 2u) {
            const __m128 v = _mm_loadu_ps(&rp[i].x);
            s = _mm_add_ps(s, v);
            s = _mm_add_ps(s, _mm_movehl_ps(v, v));
        }
        sx = _mm_cvtss_f32(s);
        sy = _mm_cvtss_f32(_mm_shuffle_ps(s, s, _MM_SHUFFLE(1, 1, 1, 1)));
    }
#endif
    for (; i <= b; ++i) {
        sx += rp[i].x;
        sy += rp[i].y;
    }
    mx = sx / (float)n;
    my = sy / (float)n;
    l->sx = sx;
    l->sy = sy;
    l->n = n;
    l->mx = mx;
    l->my = my;
    i = a;
#ifdef LC_SSE2
    {
        /* lanes (x0, y0, x1, y1): (sxx, syy) and sxy take point i, then i + 1 */
        const __m128 m = _mm_set_ps(my, mx, my, mx);
        __m128 sq = _mm_setzero_ps();
        __m128 cr = _mm_setzero_ps();
        for (; i < b; i += 2u) {
            const __m128 v = _mm_sub_ps(_mm_loadu_ps(&rp[i].x), m);
            const __m128 p = _mm_mul_ps(v, v);
            const __m128 q = _mm_mul_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
            sq = _mm_add_ps(sq, p);
            sq = _mm_add_ps(sq, _mm_movehl_ps(p, p));
            cr = _mm_add_ss(cr, q);
            cr = _mm_add_ss(cr, _mm_movehl_ps(q, q));
        }
        sxx = _mm_cvtss_f32(sq);
        syy = _mm_cvtss_f32(_mm_shuffle_ps(sq, sq, _MM_SHUFFLE(1, 1, 1, 1)));
        sxy = _mm_cvtss_f32(cr);
    }
#endif
    for (; i <= b; ++i) {
        const float x = rp[i].x - mx;
        const float y = rp[i].y - my;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
    }
    half = 0.5f * (sxx + syy);
    diff = 0.5f * (sxx - syy);
    root = sqrtf(diff * diff + sxy * sxy);
    lmax = half + root;
    lmin = half - root;
    l->rss = lmin > 0.0f ? lmin : 0.0f;
    return major_axis(sxx, sxy, syy, lmax, &l->dx, &l->dy);
}

static BSF_COMPACT_NOINLINE int fit_line(const lc_ctx_t *c, size_t a, size_t b, lc_line_t *l)
{
    return fit_line_from(c, a, b, a, 0.0f, 0.0f, l);
}

/* When a partial circle residual is enough for the caller:
 * scale * (ratio * rss + floor_rss) >= target. */
typedef struct {
    float scale;
    float ratio;
    float floor_rss;
    float target;
} lc_enough_t;

/* Never enough before the end: the whole residual (0 >= 1 never holds). */
static const lc_enough_t lc_whole = {0.0f, 1.0f, 0.0f, 1.0f};

/* A circle relative to the judgement's origin (the apex). */
typedef struct {
    float cx, cy, r;
} lc_circle_t;

/* solve3_sym: one copy in the compact build (two callers); inlined in the
 * others, where circle_rss keeps the size and the inlining it had. */
#if BSF_CONFIG_COMPACT
#define LC_SOLVE3_INLINE BSF_COMPACT_NOINLINE
#elif defined(__GNUC__) || defined(__clang__)
#define LC_SOLVE3_INLINE inline __attribute__((always_inline))
#else
#define LC_SOLVE3_INLINE inline
#endif

/* Cramer's rule for the symmetric [a b c; b d e; c e f] x = (g0, g1, g2),
 * x into x[0..3) and 1, or 0 when the determinant
 * is 0 or NaN. */
static LC_SOLVE3_INLINE int solve3_sym(float a, float b, float c, float d, float e, float f,
                                       float g0, float g1, float g2, float *x)
{
    const float det = a * (d * f - e * e) - b * (b * f - e * c) + c * (b * e - d * c);
    if (!(fabsf(det) > 0.0f)) {
        return 0;
    }
    x[0] = (g0 * (d * f - e * e) - b * (g1 * f - e * g2) + c * (g1 * e - d * g2)) / det;
    x[1] = (a * (g1 * f - e * g2) - g0 * (b * f - e * c) + c * (b * g2 - g1 * c)) / det;
    x[2] = (a * (d * g2 - g1 * e) - b * (b * g2 - g1 * c) + g0 * (b * e - d * c)) / det;
    return 1;
}

/* One Gauss-Newton step of the geometric circle fit (the sum of squared
 * distances to the circle) over positions a..b, centre (*cx, *cy) relative
 * to (cx0, cy0) and radius *r; left unchanged when the step is degenerate
 * or leaves no sensible circle. */
static BSF_COMPACT_INLINE void circle_step(const lc_ctx_t *c, size_t a, size_t b, float cx0,
                                           float cy0, float *cx, float *cy, float *r)
{
    const bsf_point_t *rp = c->rel;
    float juu = 0.0f, juv = 0.0f, jvv = 0.0f, ju = 0.0f, jv = 0.0f;
    float gu = 0.0f, gv = 0.0f, g1 = 0.0f;
    /* the count (a float sum of ones would be the same, below 2^24) */
    const float n = (float)(b + 1u - a);
    float du, dv, dr;
    size_t i = a;
#ifdef LC_SSE2
    {
        /* lanes (x0, y0, x1, y1): every sum takes point i, then i + 1 */
        const __m128 o = _mm_set_ps(cy0, cx0, cy0, cx0);
        const __m128 k = _mm_set_ps(*cy, *cx, *cy, *cx);
        const __m128 rr = _mm_set1_ps(*r);
        __m128 s1 = _mm_setzero_ps(); /* juu, jvv, juv, . */
        __m128 s2 = _mm_setzero_ps(); /* ju, jv, gu, gv */
        __m128 s3 = _mm_setzero_ps(); /* g1 */
        for (; i < b; i += 2u) {
            const __m128 d = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(&rp[i].x), o), k);
            const __m128 sq = _mm_mul_ps(d, d);
            /* dist0 dist0 dist1 dist1 */
            const __m128 dist =
                _mm_sqrt_ps(_mm_add_ps(sq, _mm_shuffle_ps(sq, sq, _MM_SHUFFLE(2, 3, 0, 1))));
            __m128 uv, uu, cr, g, ug;
            if ((_mm_movemask_ps(_mm_cmpgt_ps(dist, _mm_setzero_ps())) & 5) != 5) {
                return;
            }
            uv = _mm_div_ps(d, dist); /* u0 v0 u1 v1 */
            g = _mm_sub_ps(dist, rr); /* g0 g0 g1 g1 */
            uu = _mm_mul_ps(uv, uv);
            cr = _mm_mul_ps(uv, _mm_shuffle_ps(uv, uv, _MM_SHUFFLE(2, 3, 0, 1)));
            ug = _mm_mul_ps(uv, g);
            s1 = _mm_add_ps(s1, _mm_movelh_ps(uu, cr));
            s1 = _mm_add_ps(s1, _mm_shuffle_ps(uu, cr, _MM_SHUFFLE(3, 2, 3, 2)));
            s2 = _mm_add_ps(s2, _mm_movelh_ps(uv, ug));
            s2 = _mm_add_ps(s2, _mm_shuffle_ps(uv, ug, _MM_SHUFFLE(3, 2, 3, 2)));
            s3 = _mm_add_ss(s3, g);
            s3 = _mm_add_ss(s3, _mm_movehl_ps(g, g));
        }
        {
            float l1[4];
            float l2[4];
            _mm_storeu_ps(l1, s1);
            _mm_storeu_ps(l2, s2);
            juu = l1[0];
            jvv = l1[1];
            juv = l1[2];
            ju = l2[0];
            jv = l2[1];
            gu = l2[2];
            gv = l2[3];
            g1 = _mm_cvtss_f32(s3);
        }
    }
#endif
    for (; i <= b; ++i) {
        const float dx = rp[i].x - cx0 - *cx;
        const float dy = rp[i].y - cy0 - *cy;
        const float dist = sqrtf(dx * dx + dy * dy);
        float u, v, g;
        if (!(dist > 0.0f)) {
            return;
        }
        /* the residual dist - r moves by -(u, v, 1) . (dcx, dcy, dr) */
        u = dx / dist;
        v = dy / dist;
        g = dist - *r;
        juu += u * u;
        juv += u * v;
        jvv += v * v;
        ju += u;
        jv += v;
        gu += u * g;
        gv += v * g;
        g1 += g;
    }
    /* Solve [juu juv ju; juv jvv jv; ju jv n] (du dv dr) = (gu gv g1). */
    {
        float x[3];
        if (!solve3_sym(juu, juv, ju, jvv, jv, n, gu, gv, g1, x)) {
            return;
        }
        du = x[0];
        dv = x[1];
        dr = x[2];
    }
    if (!(*r + dr > 0.0f) || !(fabsf(du) + fabsf(dv) + fabsf(dr) < *r + 1.0f)) {
        return; /* NaN ends here too */
    }
    *cx += du;
    *cy += dv;
    *r += dr;
}

/* Squared residual of the best circle through positions a..b (algebraic fit,
 * then geometric distances), or -1 when no sensible circle exists. With
 * refine > 0, that many Gauss-Newton steps of the geometric fit first: the
 * algebraic circle's residual exceeds the best circle's by a few noise
 * variances on short or noisy arcs, which the evidence route would take as
 * evidence of a corner. */
static float circle_rss(const lc_ctx_t *c, size_t a, size_t b, float cx0, float cy0, float extent,
                        const lc_enough_t *enough, unsigned refine, lc_circle_t *fit)
{
    const bsf_point_t *rp = c->rel;
    float sxx = 0.0f, sxy = 0.0f, syy = 0.0f, sx = 0.0f, sy = 0.0f;
    float sxz = 0.0f, syz = 0.0f, sz = 0.0f;
    /* the count (a float sum of ones would be the same, below 2^24) */
    const float n = (float)(b + 1u - a);
    float d, e, f, cx, cy, r2, r, rss = 0.0f;
    size_t i = a;
#ifdef LC_SSE2
    {
        /* lanes (x0, y0, x1, y1): every sum takes point i, then i + 1 */
        const __m128 o = _mm_set_ps(cy0, cx0, cy0, cx0);
        __m128 s1 = _mm_setzero_ps(); /* sx, sy, sxx, syy */
        __m128 s2 = _mm_setzero_ps(); /* sxz, syz, sxy, sz */
        for (; i < b; i += 2u) {
            const __m128 v = _mm_sub_ps(_mm_loadu_ps(&rp[i].x), o);
            const __m128 sq = _mm_mul_ps(v, v);
            /* z0 z0 z1 z1 */
            const __m128 z = _mm_add_ps(sq, _mm_shuffle_ps(sq, sq, _MM_SHUFFLE(2, 3, 0, 1)));
            const __m128 vz = _mm_mul_ps(v, z);
            /* x0 * y0, ., x1 * y1, . */
            const __m128 xy = _mm_mul_ps(v, _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 3, 0, 1)));
            s1 = _mm_add_ps(s1, _mm_movelh_ps(v, sq));
            s1 = _mm_add_ps(s1, _mm_shuffle_ps(v, sq, _MM_SHUFFLE(3, 2, 3, 2)));
            s2 = _mm_add_ps(s2, _mm_movelh_ps(vz, _mm_unpacklo_ps(xy, z)));
            s2 =
                _mm_add_ps(s2, _mm_shuffle_ps(vz, _mm_unpackhi_ps(xy, z), _MM_SHUFFLE(1, 0, 3, 2)));
        }
        {
            float l1[4];
            float l2[4];
            _mm_storeu_ps(l1, s1);
            _mm_storeu_ps(l2, s2);
            sx = l1[0];
            sy = l1[1];
            sxx = l1[2];
            syy = l1[3];
            sxz = l2[0];
            syz = l2[1];
            sxy = l2[2];
            sz = l2[3];
        }
    }
#endif
    for (; i <= b; ++i) {
        const float x = rp[i].x - cx0;
        const float y = rp[i].y - cy0;
        const float z = x * x + y * y;
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        sx += x;
        sy += y;
        sxz += x * z;
        syz += y * z;
        sz += z;
    }
    /* Solve [sxx sxy sx; sxy syy sy; sx sy n] (d e f) = -(sxz syz sz): the
     * solution for (sxz syz sz), negated (exact). */
    {
        float x[3];
        if (!solve3_sym(sxx, sxy, sx, syy, sy, n, sxz, syz, sz, x)) {
            return -1.0f;
        }
        d = -x[0];
        e = -x[1];
        f = -x[2];
    }
    cx = -0.5f * d;
    cy = -0.5f * e;
    r2 = cx * cx + cy * cy - f;
    if (!(r2 > 0.0f) || !(r2 < LC_CIRCLE_MAX_RADIUS * LC_CIRCLE_MAX_RADIUS * extent * extent)) {
        return -1.0f;
    }
    r = sqrtf(r2);
    for (; refine > 0u; --refine) {
        circle_step(c, a, b, cx0, cy0, &cx, &cy, &r);
    }
    if (fit != NULL) {
        fit->cx = cx0 + cx;
        fit->cy = cy0 + cy;
        fit->r = r;
    }
    i = a;
#ifdef LC_SSE2
    {
        /* both points' squared distances at once, then the sum and its test
         * point by point as below */
        const __m128 o = _mm_set_ps(cy0, cx0, cy0, cx0);
        const __m128 k = _mm_set_ps(cy, cx, cy, cx);
        const __m128 rr = _mm_set1_ps(r);
        const float scale = enough->scale;
        const float ratio = enough->ratio;
        const float floor_rss = enough->floor_rss;
        const float target = enough->target;
        for (; i < b; i += 2u) {
            const __m128 v = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(&rp[i].x), o), k);
            const __m128 sq = _mm_mul_ps(v, v);
            const __m128 g = _mm_sub_ps(
                _mm_sqrt_ps(_mm_add_ps(sq, _mm_shuffle_ps(sq, sq, _MM_SHUFFLE(2, 3, 0, 1)))), rr);
            const __m128 g2 = _mm_mul_ps(g, g);
            rss += _mm_cvtss_f32(g2);
            if (scale * (ratio * rss + floor_rss) >= target) {
                return rss;
            }
            rss += _mm_cvtss_f32(_mm_movehl_ps(g2, g2));
            if (scale * (ratio * rss + floor_rss) >= target) {
                return rss;
            }
        }
    }
#endif
    for (; i <= b; ++i) {
        const float dx = rp[i].x - cx0 - cx;
        const float dy = rp[i].y - cy0 - cy;
        const float g = sqrtf(dx * dx + dy * dy) - r;
        rss += g * g;
        /* The sum only grows (terms >= 0, rounding is monotonic): once the
         * caller's test is settled by the partial sum, the rest cannot
         * change its answer. */
        if (enough->scale * (enough->ratio * rss + enough->floor_rss) >= enough->target) {
            break;
        }
    }
    return rss;
}

/* A side is straight unless a circle cuts its squared residual per degree of
 * freedom (n - 2 for a line, n - 3 for a circle) by more than the factor
 * curve_ratio (beyond the floor). A circle passes through any three points,
 * so a side of three points or fewer shows no curvature: straight. Without
 * the degrees of freedom a short leg past a corner (three or four points)
 * was judged curved by its noise alone and the corner was lost. */
static int side_straight(const lc_ctx_t *c, size_t a, size_t b, const lc_line_t *l)
{
    const size_t n = b - a + 1u;
    const float floor_rss = (float)n * c->p->floor * c->p->floor;
    const float line_dof = (float)(n - 2u);
    float extent;
    float rss_circle;
    lc_enough_t enough;
    if (n <= 3u) {
        return 1;
    }
    /* Straight when rss * (n - 3) <= (n - 2) * (ratio * rss_circle + floor);
     * the circle's term is >= 0, so a residual within the floor is straight
     * whatever the circle gives, and no circle is fitted. */
    if (l->rss * (float)(n - 3u) <= line_dof * floor_rss) {
        return 1;
    }
    extent = sqrtf(rel_dist2(c, a, b));
    enough.scale = line_dof;
    enough.ratio = c->p->curve_ratio;
    enough.floor_rss = floor_rss;
    enough.target = l->rss * (float)(n - 3u); /* straight from there on */
    rss_circle = circle_rss(c, a, b, l->mx, l->my, extent, &enough, 0u, NULL);
    if (rss_circle < 0.0f) {
        return 1;
    }
    return enough.target <= line_dof * (c->p->curve_ratio * rss_circle + floor_rss);
}

/* From position pos, step (-1 or +1) towards stop while the next point is
 * within sqrt(side2) of the apex (the origin c->o), storing the points
 * relative to the apex; returns the last position reached. */
static inline size_t walk_side(const lc_ctx_t *c, size_t pos, size_t stop, int step, float side2)
{
    /* Locals: the stores into rel[] could alias *c as far as the compiler
     * knows. */
    const bsf_point_t *pt = c->pts->pt;
    const uint16_t *run = c->run;
    bsf_point_t *rel = c->rel;
    const float ox = c->o.x;
    const float oy = c->o.y;
#ifdef LC_SSE2
    {
        /* Two points per step while two are left, then as below. Both are
         * stored, the second also when the walk stops at the first (as the
         * point it stops before is: nothing reads it). */
        const __m128 o = _mm_set_ps(oy, ox, oy, ox);
        const __m128 s2 = _mm_set1_ps(side2);
        while (step > 0 ? stop - pos >= 2u : pos - stop >= 2u) {
            /* the points at lo and lo + 1 */
            const size_t lo = step > 0 ? pos + 1u : pos - 2u;
            const __m128 q = _mm_sub_ps(lc_pair(&pt[run[lo]], &pt[run[lo + 1u]]), o);
            const __m128 sq = _mm_mul_ps(q, q);
            const int in = _mm_movemask_ps(
                _mm_cmple_ps(_mm_add_ps(sq, _mm_shuffle_ps(sq, sq, _MM_SHUFFLE(2, 3, 0, 1))), s2));
            /* bit 0: the point at lo, bit 2: the one at lo + 1 */
            const int first = step > 0 ? in & 1 : in & 4;
            const int second = step > 0 ? in & 4 : in & 1;
            _mm_storeu_ps(&rel[lo].x, q);
            if (!first) {
                return pos;
            }
            if (!second) {
                return step > 0 ? pos + 1u : pos - 1u;
            }
            pos = step > 0 ? pos + 2u : pos - 2u;
        }
    }
#endif
    while (pos != stop) {
        const size_t next = step > 0 ? pos + 1u : pos - 1u;
        bsf_point_t q = pt[run[next]];
        float d2;
        q.x -= ox;
        q.y -= oy;
        rel[next] = q;
        /* The apex relative to itself is (0, 0), and x - 0 is x: this is
         * dist2(q, apex) without the subtractions. */
        d2 = q.x * q.x + q.y * q.y;
        if (!(d2 <= side2)) {
            break;
        }
        pos = next;
    }
    return pos;
}

#if !BSF_CONFIG_COMPACT
/* Speed only, same answers: on long runs (dense scans) the side walks step
 * over whole blocks of points that are provably within the side radius, and
 * a bound from the blocks' coordinate sums rejects most splits of a straight
 * wall (the turn test) before the exact fits. Every shortcut only skips work whose
 * result is proved to be what the exact code computes. */

/* Runs at least this long get block summaries (below, a side holds too few
 * whole blocks to pay for them). */
#define LC_BLOCK_MIN_RUN 128u
#define LC_B ((size_t)BSF_LC_BLOCK)
/* float's unit roundoff, 2^-24 */
#define LC_ROUNDOFF 5.9604645e-08f

/* Bounding box and sums of the points of each block of the run (positions
 * k * LC_B on; the last block may be partial). */
static void build_blocks(const bsf_points_t *pts, const uint16_t *run, size_t m,
                         bsf_lc_block_t *blk)
{
    size_t s;
    for (s = 0; s < m; s += LC_B) {
        const size_t e = s + LC_B < m ? s + LC_B : m;
        bsf_lc_block_t *b = &blk[s / LC_B];
        float x0 = pts->pt[run[s]].x;
        float y0 = pts->pt[run[s]].y;
        float x1 = x0;
        float y1 = y0;
        float sx = 0.0f, sy = 0.0f, sxx = 0.0f, sxy = 0.0f, syy = 0.0f;
        size_t i;
        for (i = s + 1u; i < e; ++i) {
            const bsf_point_t q = pts->pt[run[i]];
            x0 = q.x < x0 ? q.x : x0;
            x1 = q.x > x1 ? q.x : x1;
            y0 = q.y < y0 ? q.y : y0;
            y1 = q.y > y1 ? q.y : y1;
        }
        for (i = s; i < e; ++i) {
            const float x = pts->pt[run[i]].x - x0;
            const float y = pts->pt[run[i]].y - y0;
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
            syy += y * y;
        }
        b->x0 = x0;
        b->y0 = y0;
        b->x1 = x1;
        b->y1 = y1;
        b->sx = sx;
        b->sy = sy;
        b->sxx = sxx;
        b->sxy = sxy;
        b->syy = syy;
        /* 1.01: room for the rounding of this and of the rel[] differences */
        b->ext2 = 1.01f * ((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0));
    }
}

/* The square of the farthest corner of block b's box from (ox, oy), in the
 * walk's arithmetic. fl(p - o) is monotonic in p, so each coordinate of a
 * point relative to o lies between those of the box's corners, and squares
 * and sums round monotonically: no point of the block has a larger d2 as
 * walk_side computes it. */
static float block_far2(const bsf_lc_block_t *b, float ox, float oy)
{
    const float lx = fabsf(b->x0 - ox);
    const float hx = fabsf(b->x1 - ox);
    const float ly = fabsf(b->y0 - oy);
    const float hy = fabsf(b->y1 - oy);
    const float mx = lx > hx ? lx : hx;
    const float my = ly > hy ? ly : hy;
    return mx * mx + my * my;
}

/* walk_side's answer, stepping over whole blocks within sqrt(side2); stores
 * only the point it stops at in rel[] (fill_rel does the rest when the exact
 * fits need them). */
static size_t walk_side_blocks(const lc_ctx_t *c, size_t pos, size_t stop, int step, float side2)
{
    const bsf_point_t *pt = c->pts->pt;
    const uint16_t *run = c->run;
    const bsf_lc_block_t *blk = c->blk;
    const float ox = c->o.x;
    const float oy = c->o.y;
    while (pos != stop) {
        size_t next;
        bsf_point_t q;
        if (step > 0) {
            next = pos + 1u;
            if (next % LC_B == 0u && stop - next >= LC_B - 1u &&
                block_far2(&blk[next / LC_B], ox, oy) <= side2) {
                pos = next + (LC_B - 1u);
                continue;
            }
        } else {
            next = pos - 1u;
            if (next % LC_B == LC_B - 1u && next - stop >= LC_B - 1u &&
                block_far2(&blk[next / LC_B], ox, oy) <= side2) {
                pos = next - (LC_B - 1u);
                continue;
            }
        }
        q = pt[run[next]];
        q.x -= ox;
        q.y -= oy;
        if (!(q.x * q.x + q.y * q.y <= side2)) {
            break;
        }
        pos = next;
    }
    {
        bsf_point_t q = pt[run[pos]];
        q.x -= ox;
        q.y -= oy;
        c->rel[pos] = q;
    }
    return pos;
}

/* rel[] for positions a..b, as walk_side stores them. */
static void fill_rel(const lc_ctx_t *c, size_t a, size_t b)
{
    const bsf_point_t *pt = c->pts->pt;
    const uint16_t *run = c->run;
    bsf_point_t *rel = c->rel;
    const float ox = c->o.x;
    const float oy = c->o.y;
    size_t i;
    for (i = a; i <= b; ++i) {
        bsf_point_t q = pt[run[i]];
        q.x -= ox;
        q.y -= oy;
        rel[i] = q;
    }
}

/* Direction of positions s..e's total-least-squares line from the block
 * sums, and a bound phi on its angle to the direction fit_line computes for
 * the same points (radians); returns 0 when no useful bound exists.
 *
 * Why the bound holds (u the unit roundoff): let T be the exact scatter
 * matrix of the points (their rel[] values), F fit_line's float one and P
 * this one, and eps a bound on each entry of |F - T| + |P - T|. Let R_i be
 * the largest distance from the apex within point i's block (its own
 * distance for a point summed alone); R_i <= |q_i| + the block's diagonal,
 * so sum R_i^2 <= M = 2 sum |q_i|^2 + 32 sum ext2. Here each coordinate is
 * within 4 u R_i of its rel[] value, a block's own sums within 190 u R_i^2
 * per point and their shift to the apex within 36 u R_i^2, and summing t
 * terms (whole blocks and single points) and centring add 3 t u M: P is
 * within (3 t + 240) u M of T. fit_line sums n centred terms recursively
 * from a rounded mean: F is within (n + 3) u trace(T) + 2 n^3 u^2 M of T,
 * trace(T) <= |trace(P)| + 2 |P - T|. The top eigenvector's angle is half
 * that of (a - c, 2b), a vector of length gap = lmax - lmin that moves by at
 * most 2 sqrt(2) eps, so the two directions differ by at most
 * 2.22 eps / (gap - 2.83 eps); the eigenvector formulas' own rounding adds
 * about 17 u trace / gap, within the 16 u trace term below. The constants
 * used are larger than these. */
typedef struct {
    float dx, dy;
    float phi;
} lc_side_dir_t;

static int side_dir_bound(const lc_ctx_t *c, size_t s, size_t e, lc_side_dir_t *d)
{
    const bsf_point_t *pt = c->pts->pt;
    const uint16_t *run = c->run;
    const float ox = c->o.x;
    const float oy = c->o.y;
    const float n = (float)(e + 1u - s);
    float sx = 0.0f, sy = 0.0f, sxx = 0.0f, sxy = 0.0f, syy = 0.0f, ext2 = 0.0f;
    float terms = 0.0f;
    float cxx, cxy, cyy, half, diff, root, lmax, gap, trace, mass;
    float eps_p, eps;
    size_t i = s;
    while (i <= e) {
        if (i % LC_B == 0u && e - i >= LC_B - 1u) {
            const bsf_lc_block_t *b = &c->blk[i / LC_B];
            const float bx = b->x0 - ox;
            const float by = b->y0 - oy;
            const float k = (float)LC_B;
            sx += b->sx + k * bx;
            sy += b->sy + k * by;
            sxx += b->sxx + 2.0f * bx * b->sx + k * bx * bx;
            syy += b->syy + 2.0f * by * b->sy + k * by * by;
            sxy += b->sxy + bx * b->sy + by * b->sx + k * bx * by;
            ext2 += b->ext2;
            i += LC_B;
        } else {
            const float x = pt[run[i]].x - ox;
            const float y = pt[run[i]].y - oy;
            sx += x;
            sy += y;
            sxx += x * x;
            sxy += x * y;
            syy += y * y;
            ++i;
        }
        terms += 1.0f;
    }
    /* M, with 1 % for the rounding of the sums it is made of */
    mass = 1.01f * (2.0f * (sxx + syy) + 32.0f * ext2);
    cxx = sxx - sx * sx / n;
    cxy = sxy - sx * sy / n;
    cyy = syy - sy * sy / n;
    half = 0.5f * (cxx + cyy);
    diff = 0.5f * (cxx - cyy);
    root = sqrtf(diff * diff + cxy * cxy);
    lmax = half + root;
    gap = 2.0f * root;
    trace = fabsf(cxx + cyy);
    if (!major_axis(cxx, cxy, cyy, lmax, &d->dx, &d->dy)) {
        return 0;
    }
    eps_p = (4.0f * terms + 512.0f) * LC_ROUNDOFF * mass;
    eps = eps_p + (4.0f * (n + 3.0f) + 16.0f) * LC_ROUNDOFF * (trace + 4.0f * eps_p) +
          2.0f * n * n * n * LC_ROUNDOFF * LC_ROUNDOFF * mass;
    if (!(gap > 6.0f * eps)) {
        return 0; /* NaN and infinities end here too */
    }
    d->phi = 2.3f * eps / (gap - 3.0f * eps);
    return 1;
}

/* 1 when the exact fits of the sides a0..apex-1 and apex+1..b1 are sure to
 * fail the turn test |cross| >= sin(min_turn): their directions' cross
 * product differs from the one here by at most phi_a + phi_b (|sin x - sin y|
 * <= |x - y|) plus a few roundings of unit vectors (1e-5 covers them); the
 * factor 2 leaves room for the rounding of the bounds themselves. */
static int surely_no_turn(const lc_ctx_t *c, size_t a0, size_t apex, size_t b1)
{
    lc_side_dir_t da;
    lc_side_dir_t db;
    float cross;
    if (!side_dir_bound(c, a0, apex - 1u, &da) || !side_dir_bound(c, apex + 1u, b1, &db)) {
        return 0;
    }
    cross = da.dx * db.dy - da.dy * db.dx;
    return fabsf(cross) + 2.0f * (da.phi + db.phi) + 1e-5f < c->sin_min_turn;
}

/* Whether the run is dense around the apex: the points a block away lie
 * within max_side / 8, so a side holds about eight whole blocks or more
 * (below that the bound rarely decides and the exact fits are cheap). */
static int dense_at(const lc_ctx_t *c, size_t apex, size_t m, float side2)
{
    const bsf_point_t *pt = c->pts->pt;
    const bsf_point_t a = pt[c->run[apex]];
    const float near2 = side2 * (1.0f / 64.0f);
    if (apex >= LC_B && !(dist2(pt[c->run[apex - LC_B]], a) <= near2)) {
        return 0;
    }
    if (apex + LC_B < m && !(dist2(pt[c->run[apex + LC_B]], a) <= near2)) {
        return 0;
    }
    return 1;
}
#endif

/* The block shortcuts as judge and detect_run see them: in the compact
 * variant (BSF_CONFIG_COMPACT) there are none, and these do nothing. */

/* Lets the runs of detect_run use block summaries when long enough. */
static inline void blocks_attach(lc_ctx_t *c, bsf_lc_work_t *w, size_t m)
{
#if !BSF_CONFIG_COMPACT
    c->blk = NULL;
    c->blk_built = 0;
    if (m >= LC_BLOCK_MIN_RUN) {
        c->blk = w->block;
    }
#else
    (void)c;
    (void)w;
    (void)m;
#endif
}

/* No block summaries (before the first run). */
static inline void blocks_detach(lc_ctx_t *c)
{
#if !BSF_CONFIG_COMPACT
    c->blk = NULL;
    c->blk_built = 0;
#else
    (void)c;
#endif
}

/* 1 when judge should walk by blocks at apex (the summaries are built on
 * first use), else 0. */
static inline int blocks_use(lc_ctx_t *c, size_t apex, size_t m, float side2)
{
#if !BSF_CONFIG_COMPACT
    if (c->blk != NULL && dense_at(c, apex, m, side2)) {
        if (!c->blk_built) {
            build_blocks(c->pts, c->run, m, c->blk);
            c->blk_built = 1;
        }
        return 1;
    }
#else
    (void)c;
    (void)apex;
    (void)m;
    (void)side2;
#endif
    return 0;
}

/* walk_side, by blocks when the judge uses them. */
static inline size_t walk(const lc_ctx_t *c, int blocks, size_t pos, size_t stop, int step,
                          float side2)
{
#if !BSF_CONFIG_COMPACT
    if (blocks) {
        return walk_side_blocks(c, pos, stop, step, side2);
    }
#else
    (void)blocks;
#endif
    return walk_side(c, pos, stop, step, side2);
}

/* With blocks: 1 when the turn bound proves that the sides a0..apex and
 * apex..b1 make no corner, else 0 after storing the window's relative
 * points for the exact fits. Without blocks: 0. */
static inline int blocks_rule_out(lc_ctx_t *c, int blocks, size_t a0, size_t apex, size_t b1)
{
#if !BSF_CONFIG_COMPACT
    if (blocks) {
        /* every path from here to the turn test ends in "no corner" */
        if (surely_no_turn(c, a0, apex, b1)) {
            return 1;
        }
        fill_rel(c, a0, b1);
    }
#else
    (void)c;
    (void)blocks;
    (void)a0;
    (void)apex;
    (void)b1;
#endif
    return 0;
}

/* LC's corner test on the best smooth curve's squared residual, for two
 * lines with squared residual rss_lines over n points (apex included). The
 * ratio route asks the curve for curve_ratio times the lines' residual plus
 * the floor: the same factor whatever the number of points, so a shallow
 * corner between long sides fails it by chance (a 35 deg turn between 1.3 m
 * sides at 1 cm noise scores 5-25) while the curve misses the points by
 * hundreds of noise variances. The evidence route is a likelihood-ratio
 * test against the noise: the curve's residual must exceed the lines' by
 * as many noise variances as chance exceeds once in e^(LC_EVIDENCE_SIGMAS^2
 * / 2) (about 270 000) judgements, with the variance estimated from the
 * lines' n - 5 degrees of freedom (n - 1 points, two lines of two
 * parameters): the F distribution's tail for the one more parameter and the
 * apex point, nu * (e^(k^2 / nu) - 1) variances for nu degrees of freedom
 * (k^2 = 25 for many points, more for few). Sides that show curvature at
 * that level then fail it (side_curve): a crease between a wall and a
 * curved wall is no corner of two lines. The variance is the largest of
 * the run's noise estimate, the lines' residual per degree of freedom and
 * the floor: sides the lines do not fit (clutter, a second corner within
 * reach) ask for more. */
typedef struct {
    float ratio_bound; /* the ratio route's bound */
    float bound;       /* the ratio route's or a lower bound of the evidence route's */
    float var;         /* the evidence route's noise variance (corner_evidence) */
    float noise_var;   /* the run's noise variance, at least floor^2 */
    float rss_lines;
    size_t n;
} lc_corner_test_t;

static void corner_test_init(const lc_ctx_t *c, float rss_lines, size_t n, lc_corner_test_t *t)
{
    const float k2 = LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS;
    float var = c->noise2;
    t->noise_var = var;
    t->rss_lines = rss_lines;
    t->n = n;
    t->ratio_bound = c->p->curve_ratio * rss_lines + (float)n * c->p->floor * c->p->floor;
    t->bound = t->ratio_bound;
    if (c->p->corner_evidence && n > 5u) {
        const float fit_var = rss_lines / (float)(n - 5u);
        /* e^x - 1 >= x: the evidence bound is at least this, and the
         * exponential is only needed when a curve residual exceeds it */
        float least;
        var = fit_var > var ? fit_var : var;
        least = rss_lines + (k2 > (float)n ? k2 : (float)n) * var;
        t->bound = least < t->bound ? least : t->bound;
    }
    t->var = var;
}

/* How many noise variances a smooth curve's squared residual must exceed
 * the two lines' by over n > 5 points: as many as chance exceeds once in
 * about 270 000 judgements (the F distribution's tail, above), and at least
 * one per point. */
static float evidence_excess(size_t n)
{
    const float dof = (float)(n - 5u);
    const float k2 = LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS;
    const float excess = dof * (bsf_expf(k2 / dof) - 1.0f);
    return excess > (float)n ? excess : (float)n;
}

/* The evidence route's bound on the curve's squared residual (n > 5). */
static float evidence_bound(const lc_corner_test_t *t)
{
    return t->rss_lines + evidence_excess(t->n) * t->var;
}

/* Whether a smooth curve that explains the points no worse than rss_curve
 * still misses them by more than the noise explains: the evidence route's
 * bound, with the variance it uses (the largest of the run's noise, the
 * floor and the lines' residual per degree of freedom), whatever
 * corner_evidence says. */
static int curve_misses_points(const lc_corner_test_t *t, float rss_curve)
{
    const float k2 = LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS;
    float var;
    float dof;
    if (t->n <= 5u) {
        return 0;
    }
    dof = (float)(t->n - 5u);
    var = t->rss_lines / dof > t->noise_var ? t->rss_lines / dof : t->noise_var;
    /* evidence_excess(n) >= max(k2, n) (e^x - 1 >= x): most curves that
     * explain the points are settled without the exponential */
    if (!(rss_curve > t->rss_lines + (k2 > (float)t->n ? k2 : (float)t->n) * var)) {
        return 0;
    }
    return rss_curve > t->rss_lines + evidence_excess(t->n) * var;
}

/* For the evidence route: the side's line is seen at most 80 deg from its
 * normal (the sine of its angle to the ray through its centroid at least
 * BSF_GRAZING_MIN_SIN). Nearer edge-on its returns are no surface the noise
 * model describes: mixed pixels strung along the ray at a depth jump, or a
 * tail past an edge. */
static int side_seen(const lc_ctx_t *c, const lc_line_t *l)
{
    const float rx = l->mx + c->o.x;
    const float ry = l->my + c->o.y;
    const float cross = rx * l->dy - ry * l->dx;
    return cross * cross >= BSF_GRAZING_MIN_SIN * BSF_GRAZING_MIN_SIN * (rx * rx + ry * ry);
}

/* For the evidence route: no two consecutive returns of positions a..b
 * step along the ray by more than a surface seen at 80 deg incidence allows
 * (tan 80 deg times their step across it) plus three standard deviations of
 * the difference of two range readings (sqrt(2) sigma each). Such a step is
 * a depth jump inside the run (an occluder's edge, a mixed pixel), and lines
 * either side of it meet at no corner of one surface. */
static int window_joined(const lc_ctx_t *c, size_t a, size_t b, float noise_var)
{
    const float tan_max =
        sqrtf(1.0f - BSF_GRAZING_MIN_SIN * BSF_GRAZING_MIN_SIN) / BSF_GRAZING_MIN_SIN;
    const float slack = 4.2426f * sqrtf(noise_var); /* 3 sqrt(2) sigma */
    const bsf_point_t *pt = c->pts->pt;
    size_t i;
    for (i = a; i < b; ++i) {
        const bsf_point_t p = pt[c->run[i + 1u]];
        const bsf_point_t q = pt[c->run[i]];
        const float dx = p.x - q.x;
        const float dy = p.y - q.y;
        /* both components times the range of p */
        const float along = fabsf(dx * p.x + dy * p.y);
        const float across = fabsf(dx * p.y - dy * p.x);
        if (along > tan_max * across + slack * c->pts->range[c->run[i + 1u]]) {
            return 0;
        }
    }
    return 1;
}

/* A side shows curvature when a circle cuts its line's squared residual by
 * more than LC_EVIDENCE_SIGMAS^2 noise variances: returns that circle's
 * squared residual (*fit the circle), else -1; also -1 when it is cap or
 * more. Three points or fewer show none (a circle fits any three). With
 * refine, that many Gauss-Newton steps of the geometric fit. */
static float side_curve(const lc_ctx_t *c, size_t a, size_t b, const lc_line_t *l, float noise_var,
                        float cap, unsigned refine, lc_circle_t *fit)
{
    const float cut = LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS * noise_var;
    float rss_circle;
    lc_enough_t enough;
    /* no circle can cut more than the whole residual */
    if (b - a + 1u <= 3u || !(l->rss > cut)) {
        return -1.0f;
    }
    enough.scale = 1.0f;
    enough.ratio = 1.0f;
    enough.floor_rss = 0.0f;
    enough.target = l->rss - cut < cap ? l->rss - cut : cap; /* uncurved from there on */
    rss_circle = circle_rss(c, a, b, l->mx, l->my, sqrtf(rel_dist2(c, a, b)), &enough, refine, fit);
    /* below the target the sum ran to the end: the whole residual */
    return rss_circle < 0.0f || rss_circle >= enough.target ? -1.0f : rss_circle;
}

/* Whether the evidence route can hold for the split at apex whose best
 * line over a0..b1 leaves the squared residual lu->rss (a curve's is at
 * most that): its cheap tests, before any circle is fitted. */
static int evidence_possible(const lc_ctx_t *c, const lc_corner_test_t *t, size_t a0, size_t b1,
                             const lc_line_t *la, const lc_line_t *lb, const lc_line_t *lu)
{
    return t->n > 5u && lu->rss > evidence_bound(t) && side_seen(c, la) && side_seen(c, lb) &&
           window_joined(c, a0, b1, t->noise_var);
}

/* The evidence route, once evidence_possible, for a curve residual
 * rss_curve (the better of the line and the algebraic circle, centred on
 * lu's centroid) that fell short of the ratio route: the curve must miss
 * the points by the evidence bound also as the geometric circle (the
 * algebraic one's residual exceeds the best circle's by a few noise
 * variances on short or noisy arcs), and neither side may show curvature. */
static int evidence_holds(const lc_ctx_t *c, const lc_corner_test_t *t, size_t a0, size_t apex,
                          size_t b1, const lc_line_t *la, const lc_line_t *lb, const lc_line_t *lu,
                          float rss_curve)
{
    const float bound = evidence_bound(t);
    /* the shorter side first: [s0, e0] on line l0, then [s1, e1] on l1 */
    const int b_first = b1 - apex < apex - a0;
    const size_t s0 = b_first ? apex + 1u : a0;
    const size_t e0 = b_first ? b1 : apex - 1u;
    const size_t s1 = b_first ? a0 : apex + 1u;
    const size_t e1 = b_first ? apex - 1u : b1;
    float rss_circle;
    lc_enough_t enough;
    if (!(rss_curve > bound)) {
        return 0;
    }
    /* Three independent tests: the sides first and the whole window's
     * circle (the dearest) last, so a curved side (the usual failure on
     * real logs) spares it. */
    if (side_curve(c, s0, e0, b_first ? lb : la, t->noise_var, FLT_MAX, LC_CIRCLE_STEPS, NULL) >=
            0.0f ||
        side_curve(c, s1, e1, b_first ? la : lb, t->noise_var, FLT_MAX, LC_CIRCLE_STEPS, NULL) >=
            0.0f) {
        return 0;
    }
    enough.scale = 1.0f;
    enough.ratio = 1.0f;
    enough.floor_rss = 0.0f;
    enough.target = bound; /* from there on, the corner stands */
    rss_circle = circle_rss(c, a0, b1, lu->mx, lu->my, sqrtf(rel_dist2(c, a0, b1)), &enough,
                            LC_CIRCLE_STEPS, NULL);
    return !(rss_circle >= 0.0f && !(rss_circle > bound));
}

/* judge's verdicts on a split. */
typedef enum {
    /* no corner: the pieces either side of it merge, and the sides of its
     * neighbours may reach across it */
    LC_MERGE = 0,
    /* a corner (*kp filled in) */
    LC_CORNER = 1,
    /* no corner, but the points turn there and no smooth curve explains
     * them within the noise: a corner the tests cannot confirm (a shallow
     * turn between long sides scores a curve_ratio of 5-25 at 1 cm noise),
     * or a curved piece against a straight one. The pieces stay apart, so
     * no neighbour's side reaches across it into the next wall: such a side
     * has a larger residual, and its own corner was lost with it. */
    LC_BOUNDARY = 2
} lc_verdict_t;

/* The verdict of a split that is no corner although its sides turn by
 * min_turn and two lines explain them curve_ratio times better than one
 * line: one smooth curve (residual rss_curve) explains them within the
 * noise, or not. */
static BSF_COMPACT_INLINE lc_verdict_t no_corner(const lc_corner_test_t *t, float rss_curve)
{
    return curve_misses_points(t, rss_curve) ? LC_BOUNDARY : LC_MERGE;
}

/* Fill *kp for a corner at the split apex (window a0..b1) whose vertex is x
 * (relative to the apex), between the sides of lines la and lb. */
static void corner_keypoint(const lc_ctx_t *c, size_t a0, size_t apex, size_t b1, bsf_point_t x,
                            const lc_line_t *la, const lc_line_t *lb, float score,
                            bsf_keypoint_t *kp)
{
    const bsf_point_t *rp = c->rel;
    size_t best = apex;
    float best_d = dist2_once(rp[apex], x);
    size_t i;
    /* The vertex beam: the point nearest the intersection, near the split. */
    for (i = apex - 2u; i <= apex + 2u; ++i) {
        if (i > a0 && i < b1) {
            const float d = dist2_once(rp[i], x);
            if (d < best_d) {
                best_d = d;
                best = i;
            }
        }
    }
    kp->index = c->run[best];
    kp->point.x = x.x + c->o.x;
    kp->point.y = x.y + c->o.y;
    kp->orientation = bsf_atan2f(la->my + lb->my - 2.0f * x.y, la->mx + lb->mx - 2.0f * x.x);
    {
        const float ra = sqrtf(rel_dist2(c, a0, apex));
        const float rb = sqrtf(rel_dist2(c, b1, apex));
        kp->radius = ra > rb ? ra : rb;
    }
    kp->score = score;
}

/* The two-line verdict on the split at apex, window a0..b1, sides' lines la
 * and lb (which turn by at least min_turn: cross is their cross product)
 * whose intersection must lie within reach of the apex: LC_CORNER with the
 * intersection in *xo and the evidence in *score, else the verdict. */
LC_ALWAYS_INLINE lc_verdict_t judge_lines(const lc_ctx_t *c, size_t a0, size_t apex, size_t b1,
                                          const lc_line_t *la, const lc_line_t *lb, float cross,
                                          float reach, bsf_point_t *xo, float *score)
{
    float t, extent, rss_curve, rss_circle, rss_lines;
    lc_line_t lu;
    lc_corner_test_t test;
    int evidence_checked; /* evidence_possible has passed */
    lc_enough_t enough;
    bsf_point_t x;
    t = ((lb->mx - la->mx) * lb->dy - (lb->my - la->my) * lb->dx) / cross;
    x.x = la->mx + t * la->dx;
    x.y = la->my + t * la->dy;
    if (!(x.x * x.x + x.y * x.y <= reach * reach)) {
        return LC_MERGE;
    }
    /* One smooth curve over both sides: the better of a line and a circle. */
    /* (the left side's sums are the first part of the whole's) */
    if (!fit_line_from(c, a0, b1, apex, la->sx, la->sy, &lu)) {
        return LC_MERGE;
    }
    rss_lines = la->rss + lb->rss;
    corner_test_init(c, rss_lines, b1 - a0 + 1u, &test);
    /* The curve's residual is at most the line's: when the line already
     * fails the test, so does the curve, and no circle is fitted. */
    if (!(lu.rss > test.bound)) {
        return LC_MERGE;
    }
    /* Below the ratio route's bound only the evidence route can pass. */
    evidence_checked = !(lu.rss > test.ratio_bound);
    if (evidence_checked && !evidence_possible(c, &test, a0, b1, la, lb, &lu)) {
        return LC_MERGE;
    }
    extent = sqrtf(rel_dist2(c, a0, b1));
    rss_curve = lu.rss;
    enough.scale = 1.0f; /* 1 * x is x: the plain comparison */
    enough.ratio = 1.0f;
    enough.floor_rss = 0.0f;
    enough.target = lu.rss; /* from there on, the line is the better curve */
    rss_circle = circle_rss(c, a0, b1, lu.mx, lu.my, extent, &enough, 0u, NULL);
    if (rss_circle >= 0.0f && rss_circle < rss_curve) {
        rss_curve = rss_circle;
    }
    if (!(rss_curve > test.bound)) {
        return no_corner(&test, rss_curve);
    }
    if (!(rss_curve > test.ratio_bound) &&
        ((!evidence_checked && !evidence_possible(c, &test, a0, b1, la, lb, &lu)) ||
         !evidence_holds(c, &test, a0, apex, b1, la, lb, &lu, rss_curve))) {
        return no_corner(&test, rss_curve);
    }
    /* Each side must be straight: a circle may not explain it much better
     * than its line (a crease between two curved walls is no wall corner,
     * and its line intersection would lie off the crease). Last, as the
     * dearest test. */
    if (!side_straight(c, a0, apex - 1u, la) || !side_straight(c, apex + 1u, b1, lb)) {
        return no_corner(&test, rss_curve);
    }
    *xo = x;
    *score = rss_lines > 0.0f ? rss_curve / rss_lines : 1e30f;
    return LC_CORNER;
}

/* One side of a crease: its line or its circle (fit_piece). */
typedef struct {
    lc_circle_t k;
    const lc_line_t *l;
    float rss;
    int round; /* 1: the circle k */
} lc_piece_t;

/* Fewest points on a side taken as a circle: a circle through a few points
 * of a small pillar goes anywhere beyond them. */
#define LC_CREASE_ROUND_POINTS 10u
/* Fewest points on any side of a crease: a line through two or three
 * points fits them whatever they are. */
#define LC_CREASE_LINE_POINTS 3u
/* Gauss-Newton steps of a crease side's circle fit. */
#define LC_CREASE_CIRCLE_STEPS 3u

/* The most squared residual a piece of dof degrees of freedom leaves within
 * the noise: dof + LC_EVIDENCE_SIGMAS standard deviations of that
 * chi-square sum, bounded as dof + k sqrt(2 dof) <= 2 dof + k^2 / 4. */
static BSF_COMPACT_NOINLINE float piece_bound(float dof, float noise_var)
{
    return noise_var * (2.0f * dof + 0.25f * LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS);
}

/* Fit side a..b (line l) as a piece: its line when that explains it within
 * the noise (piece_bound), else its circle when that does, shows curvature
 * (side_curve), has at least LC_CREASE_ROUND_POINTS points and spans at
 * most 60 deg (its radius at least its chord: a circle through a bent
 * polyline is tighter). Returns 0 when neither does: a side that reaches
 * round a corner or onto another surface is no side of a crease. */
static int fit_piece(const lc_ctx_t *c, size_t a, size_t b, const lc_line_t *l, float noise_var,
                     lc_piece_t *s)
{
    const size_t n = b - a + 1u;
    /* the line's bound; a circle has one degree of freedom less */
    const float cap = piece_bound((float)(n - 2u), noise_var) - 2.0f * noise_var;
    s->l = l;
    s->rss = l->rss;
    s->round = 0;
    if (n < LC_CREASE_LINE_POINTS) {
        return 0;
    }
    if (l->rss <= cap + 2.0f * noise_var) {
        return 1; /* the line explains it */
    }
    /* Only a circle that fits within the noise can make the side a piece:
     * the fits stop once it cannot, and first (speed) the algebraic
     * circle, whose residual the geometric steps lower by a few noise
     * variances, not by LC_EVIDENCE_SIGMAS^2 (clutter stops here). */
    if (n < LC_CREASE_ROUND_POINTS ||
        side_curve(c, a, b, l, noise_var, cap + LC_EVIDENCE_SIGMAS * LC_EVIDENCE_SIGMAS * noise_var,
                   0u, &s->k) < 0.0f) {
        return 0;
    }
    s->rss = side_curve(c, a, b, l, noise_var, cap, LC_CREASE_CIRCLE_STEPS, &s->k);
    s->round = 1;
    return s->rss >= 0.0f && s->k.r * s->k.r >= rel_dist2(c, a, b);
}

/* Signed distance of point q from piece s, and its unit gradient there. */
static BSF_COMPACT_INLINE float piece_at(const lc_piece_t *s, bsf_point_t q, float *gx, float *gy)
{
    float dx, dy, len;
    if (!s->round) {
        *gx = -s->l->dy;
        *gy = s->l->dx;
        return *gx * (q.x - s->l->mx) + *gy * (q.y - s->l->my);
    }
    dx = q.x - s->k.cx;
    dy = q.y - s->k.cy;
    len = sqrtf(dx * dx + dy * dy);
    if (!(len > 0.0f)) {
        *gx = 0.0f;
        *gy = 0.0f;
        return 0.0f;
    }
    *gx = dx / len;
    *gy = dy / len;
    return len - s->k.r;
}

/* Side a..b (line l) is a short round side: fewer points than judge_crease
 * takes as a circle (LC_CREASE_ROUND_POINTS), its line leaving more than
 * the noise explains (piece_bound), a circle no more. judge_crease stops at
 * such a side (no crease), yet side_straight, whose curve_ratio test needs
 * more points to see a curve, passes it, and the two lines then cross a
 * beam step or two off the crease, on the other wall (a few returns on a
 * pillar or a bulge where it meets a wall): a vertex where the surface has
 * none. */
static int side_short_round(const lc_ctx_t *c, size_t a, size_t b, const lc_line_t *l)
{
    lc_circle_t k;
    const size_t n = b - a + 1u;
    if (n <= 3u || n >= LC_CREASE_ROUND_POINTS ||
        !(l->rss > piece_bound((float)(n - 2u), c->noise2))) {
        return 0;
    }
    return side_curve(c, a, b, l, c->noise2, piece_bound((float)(n - 3u), c->noise2), 0u, &k) >=
           0.0f;
}

/* Newton steps towards the crossing of a crease's pieces nearest the apex. */
#define LC_CREASE_STEPS 6u

/* A crease: where a curved wall meets a wall or another curved wall, the
 * two-line test fails or puts the vertex off it (a side's line does not fit
 * that side) although the points have a vertex. The split is a corner when
 * each side is a piece (fit_piece), at least one a circle, the best smooth
 * curve over both sides (the geometrically fitted circle) leaves
 * curve_ratio times the pieces' squared residual (at least n noise
 * variances) plus the floor, no depth jump lies in the window, and the
 * pieces cross within reach of the apex (as close as the two lines must) at
 * an angle of min_turn or more. A round pillar or a smooth wall of varying
 * curvature fails the last: the circles of its two sides touch, they do not
 * cross. LC_CORNER with the crossing in *xo and the evidence in *score,
 * else LC_MERGE. */
LC_ALWAYS_INLINE lc_verdict_t judge_crease(const lc_ctx_t *c, size_t a0, size_t apex, size_t b1,
                                           const lc_line_t *la, const lc_line_t *lb, float reach,
                                           bsf_point_t *xo, float *score)
{
    const size_t n = b1 - a0 + 1u;
    const float noise_var = c->noise2;
    lc_piece_t pc[2];
    float f[2], gx[2], gy[2];
    float rss_curve, rss_pieces = 0.0f;
    bsf_point_t x = {0.0f, 0.0f};
    unsigned step;
    int k;
    int round = 0;
    /* A side is a circle only when its line does not explain it, and then
     * only with LC_CREASE_ROUND_POINTS points (fit_piece): two lines, or a
     * short side its line does not explain, stop here. */
    for (k = 0; k < 2; ++k) {
        const lc_line_t *l = k ? lb : la;
        if (l->rss > piece_bound((float)(l->n - 2u), noise_var)) {
            if (l->n < LC_CREASE_ROUND_POINTS) {
                return LC_MERGE;
            }
            round = 1;
        }
    }
    if (!round) {
        return LC_MERGE;
    }
    round = 0;
    for (k = 0; k < 2; ++k) {
        if (!fit_piece(c, k ? apex + 1u : a0, k ? b1 : apex - 1u, k ? lb : la, noise_var, &pc[k])) {
            return LC_MERGE; /* a side fits no piece */
        }
        rss_pieces += pc[k].rss;
        round |= pc[k].round;
    }
    if (!round) {
        return LC_MERGE; /* two lines: judged already */
    }
    /* One smooth curve over both sides: the geometrically fitted circle (a
     * line is its limit; none exists when the points lie on a line, which
     * is no crease of a curved side). The pieces are credited with no
     * better than the noise: their fit to it is chance. */
    rss_curve = circle_rss(c, a0, b1, 0.0f, 0.0f, sqrtf(rel_dist2(c, a0, b1)), &lc_whole,
                           LC_CIRCLE_STEPS, NULL);
    if (rss_pieces < (float)n * noise_var) {
        rss_pieces = (float)n * noise_var;
    }
    if (!(rss_curve > c->p->curve_ratio * rss_pieces + (float)n * c->p->floor * c->p->floor) ||
        !window_joined(c, a0, b1, noise_var)) {
        return LC_MERGE; /* (or a depth jump inside the window: no crease of one surface) */
    }
    /* Newton steps from the apex on the pieces' distances; the last round
     * only checks that they still cross at min_turn there */
    for (step = 0;; ++step) {
        float det;
        for (k = 0; k < 2; ++k) {
            f[k] = piece_at(&pc[k], x, &gx[k], &gy[k]);
        }
        det = gx[0] * gy[1] - gy[0] * gx[1];
        if (!(fabsf(det) >= c->sin_min_turn)) {
            return LC_MERGE;
        }
        if (step == LC_CREASE_STEPS) {
            break;
        }
        /* solve [g0; g1] dx = -(f0, f1) */
        x.x -= (f[0] * gy[1] - f[1] * gy[0]) / det;
        x.y -= (gx[0] * f[1] - gx[1] * f[0]) / det;
        if (!(x.x * x.x + x.y * x.y <= reach * reach)) {
            return LC_MERGE;
        }
    }
    *xo = x;
    *score = rss_curve / rss_pieces;
    return LC_CORNER;
}

/* Is a side of count points reaching sqrt(d2) from the apex too short to
 * give its line a direction? The direction's standard error falls as
 * 1 / (length sqrt(points)), so a side of more points than the need may be
 * shorter than min_side_len (len2 squared) by the square root of their
 * ratio, down to half of it at 4 x need: as well determined as need points
 * over min_side_len. Only a side that runs to the end of its run can fall
 * short at all (judge walks the others on): at fine beams, the 10 cm face
 * of a door jamb or a recess beside a wall's end, whose corner the fit
 * could otherwise only round off, climbing to its control-point cap. */
static int side_too_short(float d2, size_t count, float len2, size_t need)
{
    const size_t capped = count > 4u * need ? 4u * need : count;
    /* need points or fewer: min_side_len itself, compared as it always was */
    return count <= need ? d2 < len2 : d2 * (float)capped < len2 * (float)need;
}

/* How far, in noise standard deviations, a vertex must lie past its apex
 * and the apex off the short side's line (short_side_overshoots). */
#define LC_OVERSHOOT_SIGMAS 3.0f

/* A side of min_side_points - 1 returns, allowed where it runs to the end of
 * the run, takes its line from two returns: when one is a mixed pixel (a
 * range blended between two surfaces at a depth jump), that line turns off
 * its wall, and the two lines meet on the other wall past the apex, short of
 * the wall's end. The split at apex (the long side's line ll, the short
 * side's ls, the short side before the apex when short_before) is such a
 * corner when its vertex x (relative to the apex) lies past the apex's ray,
 * away from the short side, and the apex lies nearer the long side's line
 * than the short side's by LC_OVERSHOOT_SIGMAS: a wall's return beyond its
 * own corner. A real corner past the apex has the apex on the short side's
 * wall. */
static BSF_COMPACT_INLINE int short_side_overshoots(const lc_ctx_t *c, size_t apex,
                                                    int short_before, const lc_line_t *ls,
                                                    const lc_line_t *ll, bsf_point_t x)
{
    const float tol = LC_OVERSHOOT_SIGMAS * sqrtf(c->noise2);
    /* the vertex's cross product with the apex's ray (its distance from the
     * ray times the range), positive on the side of the later beams when
     * the angles increase */
    float past = c->o.x * x.y - c->o.y * x.x;
    if (!short_before == (c->pts->angle_increment > 0.0f)) {
        past = -past; /* positive away from the short side */
    }
    /* then the apex (the origin) from each line */
    return past > tol * c->pts->range[c->run[apex]] &&
           fabsf(ll->dy * ll->mx - ll->dx * ll->my) + tol <
               fabsf(ls->dy * ls->mx - ls->dx * ls->my);
}

/* Judge the split at position apex between the pieces that start at lo and
 * end at hi, in a run of m points. Returns LC_CORNER and fills *kp (beam
 * index, intersection, ...) for a corner, else LC_MERGE or LC_BOUNDARY. */
static lc_verdict_t judge(lc_ctx_t *c, size_t lo, size_t apex, size_t hi, size_t m,
                          bsf_keypoint_t *kp)
{
    const bsf_lc_params_t *p = c->p;
    const float side2 = p->max_side * p->max_side;
    const float len2 = p->min_side_len * p->min_side_len;
    const size_t need = p->min_side_points;
    lc_line_t la;
    lc_line_t lb;
    size_t a0 = apex;
    size_t b1 = apex;
    float cross, spacing, reach;
    float score = 0.0f;
    lc_verdict_t v;
    bsf_point_t x = {0.0f, 0.0f};
    int blocks = 0; /* walks by blocks and the turn bound (speed builds) */

    if (!(c->pts->range[c->run[apex]] <= p->max_range)) {
        return LC_MERGE;
    }
    c->o = c->pts->pt[c->run[apex]];
    rel_store(c, apex); /* the apex relative to itself: (0, 0) */
    blocks = blocks_use(c, apex, m, side2);
    a0 = walk(c, blocks, apex, lo, -1, side2);
    b1 = walk(c, blocks, apex, hi, 1, side2);
    /* A side cut short by a neighbouring split reaches past it: noise often
     * splits a corner several times within a few points, and the true apex
     * must not lose to its own echoes (a side that then crosses another
     * corner fails the straightness test). */
    if (apex - a0 < need || rel_dist2(c, a0, apex) < len2) {
        a0 = walk(c, blocks, a0, 0u, -1, side2);
    }
    if (b1 - apex < need || rel_dist2(c, b1, apex) < len2) {
        b1 = walk(c, blocks, b1, m - 1u, 1, side2);
    }
    /* A wall seen at grazing incidence has a return every half metre or
     * more: with grazing joins, a side short of points may reach twice as
     * far (the fits and the straightness test still judge it). */
    if (p->join_grazing) {
        if (apex - a0 < need) {
            a0 = walk_side(c, a0, 0u, -1, 4.0f * side2);
        }
        if (b1 - apex < need) {
            b1 = walk_side(c, b1, m - 1u, 1, 4.0f * side2);
        }
    }
    /* A side that runs to the end of the run may be one point shorter: a
     * far corner at the edge of what is seen has few points beyond it. */
    if (apex - a0 + (a0 == 0u ? 1u : 0u) < need || b1 - apex + (b1 + 1u == m ? 1u : 0u) < need) {
        return LC_MERGE;
    }
    /* Each side must also be long enough to give its line a direction. */
    if (side_too_short(rel_dist2(c, a0, apex), apex - a0, len2, need) ||
        side_too_short(rel_dist2(c, b1, apex), b1 - apex, len2, need)) {
        return LC_MERGE;
    }
    if (blocks_rule_out(c, blocks, a0, apex, b1)) {
        return LC_MERGE;
    }
    if (!fit_line(c, a0, apex - 1u, &la) || !fit_line(c, apex + 1u, b1, &lb)) {
        return LC_MERGE;
    }
    cross = la.dx * lb.dy - la.dy * lb.dx;
    if (!(fabsf(cross) >= c->sin_min_turn)) {
        return LC_MERGE;
    }
    /* the sides' fits must meet within twice the local beam spacing plus
     * apex_slack of the apex */
    spacing = rel_dist2(c, apex - 1u, apex);
    {
        const float s2 = rel_dist2(c, apex + 1u, apex);
        spacing = sqrtf(s2 > spacing ? s2 : spacing);
    }
    reach = 2.0f * spacing + p->apex_slack;
    /* A crease first: where a side is round, the lines' intersection lies
     * off the vertex even when two lines pass (a 5 m arc against a wall at
     * 1 cm noise: 4 cm along the wall). */
    v = judge_crease(c, a0, apex, b1, &la, &lb, reach, &x, &score);
    /* No crease, and a side is short and round: the lines' intersection
     * would lie off the crease (side_short_round), so no vertex at all. */
    if (v != LC_CORNER &&
        (side_short_round(c, a0, apex - 1u, &la) || side_short_round(c, apex + 1u, b1, &lb))) {
        return LC_MERGE;
    }
    if (v != LC_CORNER) {
        v = judge_lines(c, a0, apex, b1, &la, &lb, cross, reach, &x, &score);
    }
    if (v != LC_CORNER) {
        return v;
    }
    /* A short side at the end of the run (a mixed pixel may have turned it);
     * where both are short, the one before the apex is tested. */
    if (apex - a0 < need || b1 - apex < need) {
        const int before = apex - a0 < need;
        if (short_side_overshoots(c, apex, before, before ? &la : &lb, before ? &lb : &la, x)) {
            return LC_MERGE;
        }
    }
    corner_keypoint(c, a0, apex, b1, x, &la, &lb, score, kp);
    return v;
}

/* Noise of a run, from each point's distance to the chord of its two
 * neighbours. Where the beams are denser than the noise (fine beams, near
 * walls), the neighbours' chord points anywhere and a point's distance to
 * it says little (at 0.11 deg beams and 1 cm range noise it gave about
 * half that): there the direction comes from the chord of the points k
 * positions either side, k beams spanning at least LC_NOISE_BASE at the
 * point's range, the point is measured across it from its neighbours'
 * midpoint, and only every k-th point is measured (the estimate needs no
 * more, and dense runs cost less than before). Returns the noise normal to
 * the surface, averaged over the run; *along_ray gets the noise along the
 * rays from the points measured with k > 1 and seen within 80 deg of the
 * normal (0 when there are none): their distances over the cosines of
 * their incidence, so a wall seen obliquely, whose noise runs mostly along
 * it, does not lower it. */
static float run_noise(const bsf_points_t *pts, const uint16_t *run, size_t m, float *along_ray)
{
    const float step_angle = fabsf(pts->angle_increment);
    float sum = 0.0f;
    float dense_sum = 0.0f; /* distances of the points measured with k > 1 */
    float dense_cos = 0.0f; /* and the cosines of their incidence */
    size_t n = 0;
    size_t i;
    size_t k = 1;
    *along_ray = 0.0f;
    if (m < 3u) {
        return 0.0f;
    }
    for (i = 1; i + 1u < m; i += k) {
        const float r = pts->range[run[i]];
        const float spacing = r * step_angle; /* beam spacing across the ray */
        const bsf_point_t q = pts->pt[run[i]];
        bsf_point_t a;
        bsf_point_t b;
        float ex;
        float ey;
        float len;
        k = 1u;
        if (spacing < LC_NOISE_BASE) {
            const float want = LC_NOISE_BASE / spacing; /* > 1; inf when spacing is 0 */
            k = want < (float)m ? (size_t)want + 1u : m;
        }
        /* the chord's ends (the neighbours when k is 1) */
        a = pts->pt[run[i > k ? i - k : 0u]];
        b = pts->pt[run[i + k < m ? i + k : m - 1u]];
        ex = b.x - a.x;
        ey = b.y - a.y;
        if (k > 1u) {
            /* the point against its neighbours' midpoint, across the chord */
            const bsf_point_t na = pts->pt[run[i - 1u]];
            const bsf_point_t nb = pts->pt[run[i + 1u]];
            a.x = 0.5f * (na.x + nb.x);
            a.y = 0.5f * (na.y + nb.y);
        }
        len = sqrtf(ex * ex + ey * ey);
        if (len > 0.0f) {
            const float d = fabsf(ex * (q.y - a.y) - ey * (q.x - a.x)) / len;
            if (d <= LC_NOISE_CLIP) {
                sum += d;
                ++n;
                if (k > 1u) {
                    /* cosine of the incidence: sine of the chord's angle to the ray */
                    const float cos_inc = fabsf(ex * q.y - ey * q.x) / (len * r);
                    if (cos_inc >= BSF_GRAZING_MIN_SIN) {
                        dense_sum += d;
                        dense_cos += cos_inc;
                    }
                }
            }
        }
    }
    if (dense_cos > 0.0f) {
        *along_ray = dense_sum / (dense_cos * LC_NOISE_MEAN_ABS);
    }
    return n > 0u ? sum / ((float)n * LC_NOISE_MEAN_ABS) : 0.0f;
}

#if !BSF_CONFIG_COMPACT
/* The parked keypoints out[slot + 1 ..] move down one place (n of them),
 * field by field where the compact build calls memmove: newlib-nano's is a
 * byte loop (about 4 Cortex-M4F instructions a byte, 24 bytes a keypoint). */
static void keypoints_down(bsf_keypoint_t *out, size_t slot, size_t n)
{
    size_t k;
    for (k = slot; k < slot + n; ++k) {
        out[k].index = out[k + 1u].index;
        out[k].point.x = out[k + 1u].point.x;
        out[k].point.y = out[k + 1u].point.y;
        out[k].orientation = out[k + 1u].orientation;
        out[k].radius = out[k + 1u].radius;
        out[k].score = out[k + 1u].score;
    }
}
#endif

/* Douglas-Peucker split of run positions 0..m-1 with an explicit stack;
 * returns the number of splits, ascending in w->brk. The left piece of a
 * split is done first and its right piece is stacked with its ends swapped
 * (a > b, never a piece's own order), so popping it emits the split in
 * order: no marks to clear and gather. */

static size_t split_run(const bsf_points_t *pts, bsf_lc_work_t *w, size_t m, float tol)
{
    size_t top = 0;
    size_t nb = 0;
    size_t i;
    w->stack_a[top] = 0u;
    w->stack_b[top] = (uint16_t)(m - 1u);
    ++top;
    while (top > 0u) {
        size_t a = w->stack_a[--top];
        size_t b = w->stack_b[top];
        bsf_point_t pa;
        bsf_point_t pb;
        float ex;
        float ey;
        float len;
        float dmax = 0.0f;
        size_t imax;
        if (a > b) {
            /* the right piece of the split at b: everything left of b is done */
            w->brk[nb++] = (uint16_t)b;
            i = a;
            a = b;
            b = i;
        }
        if (b < a + 2u) {
            continue;
        }
        pa = pts->pt[w->run[a]];
        pb = pts->pt[w->run[b]];
        ex = pb.x - pa.x;
        ey = pb.y - pa.y;
        len = sqrtf(ex * ex + ey * ey);
        imax = a;
        i = a + 1u;
#ifdef LC_SSE2
        if (len > 0.0f) {
            /* two points per step: both distances at once, then taken in
             * order as below; lanes (x0, y0, x1, y1) */
            const __m128 o = _mm_set_ps(pa.y, pa.x, pa.y, pa.x);
            const __m128 e = _mm_set_ps(ex, ey, ex, ey);
            const __m128 l = _mm_set1_ps(len);
            const __m128 no_sign = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF));
            for (; i + 1u < b; i += 2u) {
                const __m128 q = lc_pair(&pts->pt[w->run[i]], &pts->pt[w->run[i + 1u]]);
                const __m128 p = _mm_mul_ps(_mm_sub_ps(q, o), e);
                /* ex * dy - ey * dx in lanes 0 and 2 */
                const __m128 cr = _mm_sub_ps(_mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 3, 0, 1)), p);
                const __m128 d = _mm_div_ps(_mm_and_ps(cr, no_sign), l);
                const float d0 = _mm_cvtss_f32(d);
                const float d1 = _mm_cvtss_f32(_mm_movehl_ps(d, d));
                if (d0 > dmax) {
                    dmax = d0;
                    imax = i;
                }
                if (d1 > dmax) {
                    dmax = d1;
                    imax = i + 1u;
                }
            }
        }
#endif
        for (; i < b; ++i) {
            const bsf_point_t q = pts->pt[w->run[i]];
            /* distance from the chord, or from its end when it has no length */
            const float d = len > 0.0f ? fabsf(ex * (q.y - pa.y) - ey * (q.x - pa.x)) / len
                                       : sqrtf(dist2(q, pa));
            if (d > dmax) {
                dmax = d;
                imax = i;
            }
        }
        if (dmax > tol) {
            /* Each pushed piece is a strict sub-range with disjoint interior,
             * so the stack never holds more than m entries. */
            w->stack_a[top] = (uint16_t)b;
            w->stack_b[top] = (uint16_t)imax;
            ++top;
            w->stack_a[top] = (uint16_t)a;
            w->stack_b[top] = (uint16_t)imax;
            ++top;
        }
    }
    return nb;
}

/* Position of beam b on the pass, which starts at beam start (0, or past the
 * seam's cut on a full-circle scan of count beams). */
static size_t pass_pos(size_t b, size_t start, size_t count)
{
    return b >= start ? b - start : b + count - start;
}

/* Two keypoints of one run on one corner: beams closer than the points a
 * side needs, or intersections within apex_slack of each other. */
static BSF_COMPACT_INLINE int too_close(const bsf_keypoint_t *a, const bsf_keypoint_t *b,
                                        const lc_ctx_t *c)
{
    const size_t count = c->pts->count;
    return pass_pos(a->index, c->start, count) + c->p->min_side_points >=
               pass_pos(b->index, c->start, count) ||
           dist2(a->point, b->point) <= c->p->apex_slack * c->p->apex_slack;
}

/* Append kp, or merge it into the previous keypoint of the same run (from
 * index first on) when both sit on one corner, keeping the sharper. *last
 * mirrors the previous keypoint even when out is full, so the count does not
 * depend on out_cap. */
static void keep(bsf_keypoint_t *out, size_t out_cap, size_t *n, size_t first, bsf_keypoint_t *last,
                 const bsf_keypoint_t *kp, const lc_ctx_t *c)
{
    if (*n > first && too_close(last, kp, c)) {
        if (!(kp->score > last->score)) {
            return;
        }
        --*n; /* kp takes the previous keypoint's place */
    }
    if (*n < out_cap) {
        out[*n] = *kp;
    }
    *last = *kp;
    ++*n;
}

/* Corners of one run: split, then merge the splits that are no corner until
 * the survivors all pass; a split judged LC_BOUNDARY stays, as no corner,
 * and ends its neighbours' sides (is_brk marks it 2, a corner 1). */
static void detect_run(lc_ctx_t *c, bsf_lc_work_t *w, size_t m, bsf_keypoint_t *out, size_t out_cap,
                       size_t *n_found)
{
    float along_ray;
    const float sigma = run_noise(c->pts, w->run, m, &along_ray);
    /* Where the beams are dense, a wall that faces the sensor has many
     * points whose noise across it is the whole range noise, above the
     * run's average across its surfaces (lowered by the walls seen
     * obliquely): split at that average, noise alone would cut such a wall
     * every few points, near a corner into pieces too short to judge it. */
    const float split_noise = along_ray > sigma ? along_ray : sigma;
    float tol = c->p->split_sigmas * split_noise;
    size_t nb;
    size_t j;
    unsigned pass;
    int changed = 1;
    size_t first;
    bsf_keypoint_t kp;
    bsf_keypoint_t last;
    if (tol < c->p->split_min) {
        tol = c->p->split_min;
    }
    c->noise2 =
        sigma * sigma > c->p->floor * c->p->floor ? sigma * sigma : c->p->floor * c->p->floor;
    /* The scan's noise (bsf_lc_work_t.noise2): the split tolerance's, the
     * whole range noise where the beams are dense enough to show it. */
    w->noise2 += (float)m * split_noise * split_noise;
    c->noise_points += (float)m;
    blocks_attach(c, w, m);
    nb = split_run(c->pts, w, m, tol);
    first = *n_found;
    memset(&last, 0, sizeof last);
    for (j = 0; j < nb; ++j) {
        w->judged_lo[j] = UINT16_MAX; /* no verdict yet */
    }
    for (pass = 0; changed && pass < LC_MAX_PASSES; ++pass) {
        changed = 0;
        j = 0;
        while (j < nb) {
            const size_t lo = j == 0u ? 0u : w->brk[j - 1u];
            const size_t hi = j + 1u < nb ? w->brk[j + 1u] : m - 1u;
            /* A verdict depends only on the split and its two neighbours:
             * a corner whose neighbours have not moved since it was judged
             * stays one, with its keypoint still parked, and a boundary
             * stays a boundary. */
            lc_verdict_t verdict;
            if (w->judged_lo[j] == lo && w->judged_hi[j] == hi) {
                ++j;
                continue;
            }
            verdict = judge(c, lo, w->brk[j], hi, m, &kp);
            if (verdict == LC_BOUNDARY) {
                /* nothing parked: its slot stays unused */
                w->is_brk[w->brk[j]] = 2u;
                w->judged_lo[j] = (uint16_t)lo;
                w->judged_hi[j] = (uint16_t)hi;
                ++j;
            } else if (verdict == LC_MERGE) {
                const size_t tail = nb - j - 1u;
                const size_t slot = *n_found + j;
                memmove(&w->brk[j], &w->brk[j + 1u], tail * sizeof w->brk[0]);
                memmove(&w->judged_lo[j], &w->judged_lo[j + 1u], tail * sizeof w->judged_lo[0]);
                memmove(&w->judged_hi[j], &w->judged_hi[j + 1u], tail * sizeof w->judged_hi[0]);
                if (slot + 1u < out_cap) {
                    const size_t fit = out_cap - slot - 1u;
#if BSF_CONFIG_COMPACT
                    memmove(&out[slot], &out[slot + 1u], (tail < fit ? tail : fit) * sizeof out[0]);
#else
                    keypoints_down(out, slot, tail < fit ? tail : fit);
#endif
                }
                --nb;
                changed = 1;
            } else {
                w->is_brk[w->brk[j]] = 1u;
                /* Parked where it lands if this pass turns out final; only
                 * a parked verdict is remembered (slots only move down). */
                if (*n_found + j < out_cap) {
                    out[*n_found + j] = kp;
                    w->judged_lo[j] = (uint16_t)lo;
                    w->judged_hi[j] = (uint16_t)hi;
                }
                ++j;
            }
        }
    }
    /* Without a change, the last pass judged every survivor with its final
     * neighbours: its boundaries stay and its parked keypoints stand (a
     * keypoint beyond out_cap gets the same judgement again). Otherwise
     * every survivor is judged again. */
    for (j = 0; j < nb; ++j) {
        const size_t lo = j == 0u ? 0u : w->brk[j - 1u];
        const size_t hi = j + 1u < nb ? w->brk[j + 1u] : m - 1u;
        const size_t parked = first + j; /* never below the next slot written */
        if (!changed && w->is_brk[w->brk[j]] == 2u) {
            continue;
        }
        if (!changed && parked < out_cap) {
            kp = out[parked];
        } else if (judge(c, lo, w->brk[j], hi, m, &kp) != LC_CORNER) {
            continue;
        }
        keep(out, out_cap, n_found, first, &last, &kp, c);
    }
}

/* Point b continues the run that ends at point a: within the jump radius
 * at b's range. */
static int within_jump(const bsf_points_t *pts, const bsf_lc_params_t *p, size_t a, size_t b)
{
    /* r >= jump_a: the exponential is only needed past that. */
    const float d2 = dist2(pts->pt[a], pts->pt[b]);
    const float x = p->jump_b * pts->range[b];
    float r;
    if (d2 <= p->jump_a * p->jump_a) {
        return 1;
    }
#if !BSF_CONFIG_COMPACT /* compact: expf every time (the bounds only decide early) */
    if (x >= 0.0f && x <= 1.0f) {
        /* lo <= bsf_expf(x) <= hi, and rounding is monotonic: r * r lies
         * between the squares of jump_a * lo and jump_a * hi, so expf only
         * for d2 between them. */
        float lo;
        float hi;
        float r_lo;
        float r_hi;
        bsf_exp_bounds01(x, &lo, &hi);
        r_lo = p->jump_a * lo;
        r_hi = p->jump_a * hi;
        if (d2 <= r_lo * r_lo) {
            return 1;
        }
        if (d2 > r_hi * r_hi) {
            return 0;
        }
    }
#endif
    r = p->jump_a * bsf_expf(x);
    return d2 <= r * r;
}

/* The run ending at point a jumps at point i. When the surface resumes
 * within the next 2 * min_side_points beams (a valid point within the jump
 * radius at a's range), the beams between are an occluder (a post, a chair
 * leg) too narrow to hold a corner of its own (LC judges no run shorter
 * than 2 * min_side_points + 1): returns the beam where the run resumes, so
 * a corner hidden behind it is still judged from both walls (SVED's
 * look-back keeps such a wall one segment too). When i is nearer than a
 * (a step towards the sensor: an occluder, not a recess behind a's
 * surface), within LC_OCCLUDER_BEAMS: at fine beams an occluder is wider
 * than 2 * min_side_points beams, and its own run then goes unjudged;
 * past those the return after the resumed one must continue it too. Else
 * returns i. One exponential per jump: the radius is taken at a's range. */
static size_t past_occluder(const bsf_points_t *pts, const bsf_lc_params_t *p, size_t a, size_t i)
{
    const size_t narrow = i + 2u * (size_t)p->min_side_points;
    const size_t span = pts->range[i] < pts->range[a] && narrow < i + LC_OCCLUDER_BEAMS
                            ? i + LC_OCCLUDER_BEAMS
                            : narrow;
    const float x = p->jump_b * pts->range[a];
#if BSF_CONFIG_COMPACT
    /* x >= 0, so bsf_expf(x) >= 1 and r >= jump_a: d2 <= r2 alone decides
     * as the fast path's tests do, for one exponential per jump anyway. */
    const float r = p->jump_a * bsf_expf(x);
    const float r2 = r * r;
#else
    float r2 = -1.0f; /* computed once, when a point is beyond jump_a */
    /* Bounds on r2 that spare the exponential, as in within_jump; computed
     * once, when a point is beyond jump_a. */
    float r2_lo = -1.0f;
    float r2_hi = HUGE_VALF;
    int have_bounds = 0;
#endif
    size_t j;
    for (j = i + 1u; j <= span && j < pts->count; ++j) {
        if (pts->valid[j]) {
            const float d2 = dist2(pts->pt[a], pts->pt[j]);
#if BSF_CONFIG_COMPACT
            const int near = d2 <= r2;
#else
            int near = d2 <= p->jump_a * p->jump_a;
            if (!near) {
                if (!have_bounds && x >= 0.0f && x <= 1.0f) {
                    float lo;
                    float hi;
                    bsf_exp_bounds01(x, &lo, &hi);
                    r2_lo = (p->jump_a * lo) * (p->jump_a * lo);
                    r2_hi = (p->jump_a * hi) * (p->jump_a * hi);
                }
                have_bounds = 1;
                near = d2 <= r2_lo;
                if (!near && d2 > r2_hi) {
                    continue;
                }
            }
            if (!near) {
                if (r2 < 0.0f) {
                    const float r = p->jump_a * bsf_expf(x);
                    r2 = r * r;
                }
                near = d2 <= r2;
            }
#endif
            /* Past 2 * min_side_points beams the return after j must
             * continue it too (range within jump_a; an invalid one is at
             * range 0): a blend at the occluder's far edge, between it and
             * the surface behind, may lie within the radius of a. So a
             * dropout or the scan's last beam right after j keeps the run
             * from resuming at j (the next candidate may still). */
            if (near && (j <= narrow || (j + 1u < pts->count &&
                                         fabsf(pts->range[j + 1u] - pts->range[j]) <= p->jump_a))) {
                return j;
            }
        }
    }
    return i;
}

/* Point b continues the run that ends at point a: within the jump radius,
 * or (join_grazing) the next beam on one wall seen at grazing incidence
 * (never through the seam of a full-circle scan). */
static int lc_joins(const bsf_points_t *pts, const bsf_lc_params_t *p, uint8_t *grazing_memo,
                    size_t a, size_t b)
{
    return within_jump(pts, p, a, b) ||
           (p->join_grazing && a + 1u == b &&
            bsf_grazing_join(pts, a, BSF_GRAZING_LC_CAP, p->join_grazing == 2u, grazing_memo));
}

/* Where the pass over a full-circle scan starts: the first valid beam (from
 * 0) that does not continue the run of the valid beam before it on the ring,
 * so that no run is cut at the seam; 0 when every step joins (one closed
 * surface all round: the seam then cuts it, as on a scan that is no ring). */
static BSF_COMPACT_INLINE size_t ring_start(const bsf_points_t *pts, const bsf_lc_params_t *p,
                                            uint8_t *grazing_memo)
{
    size_t prev = bsf_last_valid_beam(pts);
#if !BSF_CONFIG_COMPACT
    const size_t end = prev;
    const float jump_a2 = p->jump_a * p->jump_a;
#endif
    size_t i;
    if (prev == pts->count) {
        return 0u;
    }
    for (i = 0; i < pts->count; ++i) {
#if !BSF_CONFIG_COMPACT
        /* the beams before the last one within jump_a of the one before
         * (lc_joins' first test) join without a call */
        i = bsf_join_near_beams(pts, i, end, jump_a2, &prev);
#endif
        if (!pts->valid[i]) {
            continue;
        }
        if (i != prev && !lc_joins(pts, p, grazing_memo, prev, i) &&
            past_occluder(pts, p, prev, i) == i) {
            return i;
        }
        prev = i;
    }
    return 0u;
}

/* Reverse out[lo, hi). */
static void reverse_keypoints(bsf_keypoint_t *out, size_t lo, size_t hi)
{
    while (hi > lo + 1u) {
        const bsf_keypoint_t t = out[lo];
        out[lo] = out[hi - 1u];
        out[hi - 1u] = t;
        ++lo;
        --hi;
    }
}

bsf_status_t bsf_lc_detect(const bsf_points_t *pts, const bsf_lc_params_t *p, bsf_lc_work_t *work,
                           bsf_keypoint_t *out, size_t out_cap, size_t *n_out)
{
    return bsf_lc_detect_memo(pts, p, work, out, out_cap, n_out, NULL);
}

bsf_status_t bsf_lc_detect_memo(const bsf_points_t *pts, const bsf_lc_params_t *p,
                                bsf_lc_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                                size_t *n_out, uint8_t *grazing_memo)
{
    lc_ctx_t c;
    bsf_status_t st;
    size_t n_found = 0;
    size_t m = 0;
    size_t i;
    size_t step;
#if !BSF_CONFIG_COMPACT || defined(LC_SSE2)
    float jump_a2;
#endif
    if (n_out != NULL) {
        *n_out = 0u;
    }
    if (pts == NULL || p == NULL || work == NULL || n_out == NULL ||
        (out == NULL && out_cap > 0u)) {
        return BSF_ERR_ARG;
    }
    st = bsf_lc_params_check(p);
    if (st != BSF_OK) {
        return st;
    }
    if (pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    c.pts = pts;
    c.run = work->run;
    c.p = p;
    c.o.x = 0.0f;
    c.o.y = 0.0f;
    c.rel = work->rel;
    c.sin_min_turn = bsf_sinf(p->min_turn);
    c.noise2 = 0.0f;
    work->noise2 = 0.0f;
    c.noise_points = 0.0f;
    blocks_detach(&c);
    c.start = bsf_points_full_circle(pts) ? ring_start(pts, p, grazing_memo) : 0u;
#if !BSF_CONFIG_COMPACT || defined(LC_SSE2)
    jump_a2 = p->jump_a * p->jump_a;
#endif
    for (step = 0; step <= pts->count; ++step) {
        int close_run = step == pts->count;
        i = close_run
                ? 0u
                : (c.start + step < pts->count ? c.start + step : c.start + step - pts->count);
#ifdef LC_SSE2
        /* Speed only, same runs: the next four beams, all valid and each
         * within jump_a of the one before (the run's last point first),
         * join the run as below, tested at once. */
        if (m > 0u && step + 4u <= pts->count && i + 4u <= pts->count &&
            work->run[m - 1u] + 1u == i) {
            if (bsf_four_steps_within(pts, i, jump_a2)) {
                work->run[m] = (uint16_t)i;
                work->run[m + 1u] = (uint16_t)(i + 1u);
                work->run[m + 2u] = (uint16_t)(i + 2u);
                work->run[m + 3u] = (uint16_t)(i + 3u);
                m += 4u;
                step += 3u;
                continue;
            }
        }
#endif
        if (!close_run && !pts->valid[i]) {
            continue;
        }
        if (!close_run && m > 0u) {
#if BSF_CONFIG_COMPACT
            close_run = !lc_joins(pts, p, grazing_memo, work->run[m - 1u], i);
#else
            /* lc_joins' first test here, as most beams pass it: no call */
            close_run = !(dist2(pts->pt[work->run[m - 1u]], pts->pt[i]) <= jump_a2 ||
                          lc_joins(pts, p, grazing_memo, work->run[m - 1u], i));
#endif
            if (close_run) {
                const size_t j = past_occluder(pts, p, work->run[m - 1u], i);
                if (j > i && step + (j - i) < pts->count) {
                    step += j - i - 1u; /* the run resumes at j */
                    continue;
                }
            }
        }
        if (close_run) {
            if (m >= 2u * (size_t)p->min_side_points + 1u) {
                detect_run(&c, work, m, out, out_cap, &n_found);
            }
            m = 0;
        }
        if (step < pts->count) {
            work->run[m++] = (uint16_t)i;
#if !BSF_CONFIG_COMPACT && !defined(LC_SSE2)
            /* (only once i continued a run: where runs are a beam or two
             * long, as in clutter, the loop would only test beams twice) */
            if (m >= 2u) {
                /* Speed only, same runs: the beams after i (before the
                 * pass's end and the scan's) that are valid and within
                 * jump_a of the one before join here, as the steps above
                 * would join them, with the last point in registers (the
                 * SSE2 form takes four at a time above). */
                const size_t left = pts->count - 1u - (step > i ? step : i);
                const size_t stop = i + left;
                const uint8_t *valid = pts->valid;
                const bsf_point_t *pt = pts->pt;
                uint16_t *run = work->run;
                bsf_point_t p0 = pt[i];
                bsf_point_t p1;
                size_t k = i;
                /* two beams per round, the last point alternating between
                 * p0 and p1 (no copy) */
                for (;;) {
                    if (k >= stop || !valid[k + 1u]) {
                        break;
                    }
                    p1 = pt[k + 1u];
                    if (!(dist2(p0, p1) <= jump_a2)) {
                        break;
                    }
                    run[m++] = (uint16_t)++k;
                    if (k >= stop || !valid[k + 1u]) {
                        break;
                    }
                    p0 = pt[k + 1u];
                    if (!(dist2(p1, p0) <= jump_a2)) {
                        break;
                    }
                    run[m++] = (uint16_t)++k;
                }
                step += k - i;
            }
#endif
        }
    }
    if (c.start > 0u) {
        /* Found from the pass's start on: the corners before beam start
         * (those past the seam) go first, so out stays in beam order. */
        const size_t n_kept = n_found < out_cap ? n_found : out_cap;
        size_t n_after = 0u;
        while (n_after < n_kept && out[n_after].index >= c.start) {
            ++n_after;
        }
        reverse_keypoints(out, 0u, n_after);
        reverse_keypoints(out, n_after, n_kept);
        reverse_keypoints(out, 0u, n_kept);
    }
    if (c.noise_points > 0.0f) {
        work->noise2 /= c.noise_points;
    }
    *n_out = n_found;
    return n_found > out_cap ? BSF_ERR_CAPACITY : BSF_OK;
}
