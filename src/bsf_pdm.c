/* SPDX-License-Identifier: MIT */
/* PDM: point distance minimisation with boundary, vertex and precision
 * control points, and error-driven refinement (docs/DESIGN.md, "PDM and
 * refinement"). */
#include "bsf/bsf_fit.h"
#include "bsf_compact.h"
#include "bsf/bsf_bspline.h"
#include "bsf_fit_internal.h"
#include "bsf_linalg.h"
#include "bsf_math.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define NO_FRAGMENT 0xFFFFu
#if BSF_PDM_MAX_FRAGMENTS > 32
#error "bsf_pdm_fit_anchored keeps its settled fragments in a 32-bit mask"
#endif
/* A fragment whose RMS is above this multiple of target_rms is "far" from
 * the target: a solve stops after its first iteration (refinement follows
 * anyway), and refinement grows such fragments by several points at once
 * and restarts the fit from arc length (docs/DESIGN.md, "PDM and refinement";
 * measured on the four datasets: fewer refits and no warm start stuck on a corner the
 * vertices miss). */
#define PDM_FAR_RATIO 2.0f
/* Far growth aims at this multiple of target_rms (above 1, so the last
 * points before the target still come one at a time). */
#define PDM_FAR_AIM 1.5f
/* A warm-started refinement that lowered the refined fragment's RMS by less
 * than this fraction also tries a restart from arc length. */
#define PDM_COLD_GAIN 0.05f
/* Footpoint steps shorter than this fraction of a span are not taken. */
#define PDM_STEP_EPS 1e-6f
/* Failed footpoint steps longer than this fraction of a span are halved and
 * retried (far from the curve); shorter ones are only rounding noise. */
#define PDM_HALVE_MIN 0.05f
/* Weight of a vertex anchor per data point of the segment: the anchor
 * weighs as much as all the points together, so a vertex stays within a few
 * millimetres of the two-line intersection (vertex error on the ground-truth
 * scenes as with a stiff pin, measured 1 to 100) yet the data may still
 * nudge it (slightly fewer control points on the four logs than a pin). */
#define PDM_ANCHOR_WEIGHT 1.0f
/* Shortest chord that sets the local direction of an arc-length step,
 * metres: well above range noise, well below the radius of a pillar. */
#define PDM_ARC_BASE 0.1f
/* Standard errors of a windowed mean that range noise alone rarely exceeds
 * (bias_window on): on noisy fragments the bias bound grows with the noise,
 * so refinement does not chase it (measured: without it the bound must stay
 * near 12 mm to keep curves on the ground-truth walls, and then the four logs
 * lose 10-20 % of compactness to noise). */
#define PDM_BIAS_Z 2.0f
/* With bias_window on, no point may lie further than this multiple of
 * target_rms from the curve (a curve that swings off the last few points
 * past an undetected corner keeps a low RMS and a low windowed mean). */
#define PDM_POINT_RATIO 3.0f
/* With bias_window on, a fragment is tested on at most this many windows'
 * worth of points: above PDM_BIAS_MAX_WINDOWS * bias_window points, each
 * slot of the window sums `block` consecutive residuals, so the window spans
 * a fixed share of the fragment. A fixed window of points would be tested
 * more times (and on less length) as the beams get denser, so range noise
 * alone would trip it ever more often: measured on the benchmark office
 * scene at 4000 beams, 1 cm noise, it drove 91 % of refinement rounds and
 * most fits to the control-point cap (PDM cost x 14.7 from 1000 beams). No
 * fragment of a 361-beam scan reaches the threshold. */
#define PDM_BIAS_MAX_WINDOWS 64u

/* Fit state that is not in the caller's work struct: small scalars only. */
typedef struct {
    const bsf_point_t *pts;
    size_t n;
    bsf_point_t origin;
    size_t n_frag;
    size_t n_ctrl;    /* stored control points */
    size_t n_unknown; /* distinct unknowns (a vertex is one) */
    float lambda;
    float rms;
    uint32_t loaded;
    float frag_len[BSF_PDM_MAX_FRAGMENTS];        /* length of each fragment (arc_step) */
    size_t bias_window;                           /* 0: refinement on RMS alone */
    float bias_floor;                             /* bias_ratio * target_rms */
    float target;                                 /* target_rms */
    uint8_t frag_stray[BSF_PDM_MAX_FRAGMENTS];    /* only a lone point fails (lone_stray),
                                                     as of the last footpoint pass */
    const bsf_point_t *anchor;                    /* vertex anchors (absolute), or NULL */
    uint8_t vertex_unknown[BSF_PDM_MAX_VERTICES]; /* unknown index of each vertex */
} pdm_state_t;

void bsf_pdm_params_default(bsf_pdm_params_t *p)
{
    if (p == NULL) {
        return;
    }
    /* one copy of a constant (smaller code than a store per field) */
    static const bsf_pdm_params_t defaults = {
        .precision_spacing = 1.0f,
        .lambda_per_metre = 1e-6f,
        .rel_tol = 0.01f,
        .target_rms = 0.03f,
        .max_iterations = 2u,
        .refine_iterations = 1u,
        .max_ctrl = (uint16_t)BSF_MAX_CTRL_PER_FEATURE,
        .footpoint_steps = 1u,
        .refine = 1u,
        .bias_window = 16u,
        .bias_ratio = 0.2f,
        .max_passes = 0u,
    };
    *p = defaults;
}

/* The float parameters' ranges (bsf_floats_in_range). */
#define PDM_RANGE(field, hi, open)                                                                 \
    {                                                                                              \
        hi, (uint16_t)offsetof(bsf_pdm_params_t, field), open                                      \
    }
static const bsf_float_range_t pdm_float_ranges[] = {
    PDM_RANGE(precision_spacing, BSF_FIT_MAX_COORD, BSF_RANGE_LO_OPEN),
    PDM_RANGE(lambda_per_metre, 1.0f, 0u),
    PDM_RANGE(rel_tol, 1.0f, BSF_RANGE_LO_OPEN | BSF_RANGE_HI_OPEN),
    PDM_RANGE(target_rms, BSF_FIT_MAX_COORD, BSF_RANGE_LO_OPEN),
    PDM_RANGE(bias_ratio, 1.0f, BSF_RANGE_LO_OPEN),
};

bsf_status_t bsf_pdm_params_check(const bsf_pdm_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (!bsf_floats_in_range(p, pdm_float_ranges,
                             sizeof pdm_float_ranges / sizeof pdm_float_ranges[0]) ||
        p->max_iterations < 1u || p->max_iterations > BSF_PDM_MAX_ITERATIONS ||
        p->refine_iterations < 1u || p->refine_iterations > BSF_PDM_MAX_ITERATIONS ||
        p->max_ctrl < 3u || p->max_ctrl > BSF_MAX_CTRL_PER_FEATURE || p->footpoint_steps < 1u ||
        p->footpoint_steps > 8u || p->refine > 1u || p->bias_window == 1u ||
        p->bias_window > BSF_PDM_MAX_BIAS_WINDOW) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

static float dist2_pts(bsf_point_t a, bsf_point_t b)
{
    const float dx = b.x - a.x;
    const float dy = b.y - a.y;
    return dx * dx + dy * dy;
}

/* |pts[j] - pts[i]| (indices: fewer instructions to pass than four floats) */
static float dist(const bsf_point_t *pts, size_t i, size_t j)
{
    const float dx = pts[j].x - pts[i].x;
    const float dy = pts[j].y - pts[i].y;
    return sqrtf(dx * dx + dy * dy);
}

/* Cumulative arc length of the points, fragment by fragment (w->arc), where
 * each step from point i - 1 to point i is measured along the local direction
 * of the points: the chord between the nearest points at least PDM_ARC_BASE
 * before point i and after point i - 1 (within the fragment). Range noise
 * across a wall then adds nothing, where the plain polyline length grows by
 * about the noise at every step and, where points are denser than the noise
 * (near the sensor, fine beams), puts the start parameters far off the
 * footpoints. Both window ends only move forward: linear cost. Returns the
 * fragment's length (<= 0 only for a fragment that folds back on itself,
 * which the caller then spaces by index). */
static BSF_COMPACT_NOINLINE float fragment_arc(const bsf_point_t *pts, size_t a, size_t b,
                                               float *arc)
{
    const float base2 = PDM_ARC_BASE * PDM_ARC_BASE;
    size_t lo = a;
    size_t hi = a;
    size_t i;
    float acc = 0.0f;
    arc[a] = 0.0f;
    for (i = a + 1u; i <= b; ++i) {
        const float sx = pts[i].x - pts[i - 1u].x;
        const float sy = pts[i].y - pts[i - 1u].y;
        float dx;
        float dy;
        float len;
        while (lo + 1u < i && dist2_pts(pts[lo + 1u], pts[i]) >= base2) {
            ++lo;
        }
        if (hi < i) {
            hi = i;
        }
        while (hi < b && dist2_pts(pts[hi], pts[i - 1u]) < base2) {
            ++hi;
        }
        dx = pts[hi].x - pts[lo].x;
        dy = pts[hi].y - pts[lo].y;
        len = sqrtf(dx * dx + dy * dy);
        /* Signed: the noise along the direction then cancels from step to
         * step instead of piling up (the arc may dip by the noise, which the
         * start parameters clamp). */
        acc += len > 0.0f ? (sx * dx + sy * dy) / len : sqrtf(sx * sx + sy * sy);
        arc[i] = acc;
    }
    return acc;
}

/* Control polygon for the current precision counts: unknown index of every
 * stored control point and the knot range [t0, t1] of every fragment. A vertex
 * whose first copy is stored at index j sits at the knot j / n_span. */
static void build_layout(pdm_state_t *s, bsf_pdm_work_t *w, float *t0, float *t1)
{
    size_t f;
    size_t k;
    size_t stored = 0;
    size_t unknown = 0;
    size_t n_ctrl = 2u + 2u * (s->n_frag - 1u);
    float n_span;

    for (f = 0; f < s->n_frag; ++f) {
        n_ctrl += w->frag_precision[f];
    }
    n_span = (float)(n_ctrl - 2u);
    w->unknown_of[stored++] = (uint8_t)unknown++; /* first boundary point */
    t0[0] = 0.0f;
    for (f = 0; f < s->n_frag; ++f) {
        for (k = 0; k < w->frag_precision[f]; ++k) {
            w->unknown_of[stored++] = (uint8_t)unknown++;
        }
        if (f + 1u < s->n_frag) {
            t1[f] = (float)stored / n_span;
            t0[f + 1u] = t1[f];
            s->vertex_unknown[f] = (uint8_t)unknown;
            w->unknown_of[stored++] = (uint8_t)unknown;
            w->unknown_of[stored++] = (uint8_t)unknown++;
        }
    }
    w->unknown_of[stored++] = (uint8_t)unknown++; /* last boundary point */
    t1[s->n_frag - 1u] = 1.0f;
    s->n_ctrl = stored;
    s->n_unknown = unknown;
}

/* Span of t and its local coordinate (t in [0, 1]). */
static BSF_COMPACT_INLINE size_t span_of(float t, float fs, size_t n_span, float *u)
{
    /* t is in [0, 1], so x is small and non-negative: a signed conversion
     * is exact and much cheaper than one to size_t on 64-bit targets. */
    const float x = t * fs;
    int32_t span = (int32_t)x;
    if (span >= (int32_t)n_span) {
        span = (int32_t)n_span - 1;
    }
    *u = x - (float)span;
    return (size_t)span;
}

/* One span's control points written around the middle one: on the span,
 * C(u) = P1 + b0 (P0 - P1) + b2 (P2 - P1) with b0 = k0 (1 - u)^2 and
 * b2 = k2 u^2, k0 and k2 being 1 on a clamped end and 1/2 inside. This is the
 * closed form of docs/DESIGN.md's appendix with b1 = 1 - b0 - b2. Points arrive in
 * scan order, so consecutive ones mostly share a span: the coefficients are
 * loaded once per span change. */
typedef struct {
    size_t span;
    float k0, k2;
    float m0, m2; /* -2 k0 and 2 k2: the u-derivative's scales */
    float p1x, p1y;
    float ax, ay;   /* P0 - P1 */
    float bx, by;   /* P2 - P1 */
    float uux, uuy; /* second u-derivative (constant on a span) */
} span_coef_t;

static inline void load_span(const bsf_point_t *ctrl, size_t n_span, size_t span, span_coef_t *c)
{
    const bsf_point_t *p = ctrl + span;
    c->span = span;
    c->k0 = span == 0u ? 1.0f : 0.5f;
    c->k2 = span + 1u == n_span ? 1.0f : 0.5f;
    c->m0 = -2.0f * c->k0;
    c->m2 = 2.0f * c->k2;
    c->p1x = p[1].x;
    c->p1y = p[1].y;
    c->ax = p[0].x - p[1].x;
    c->ay = p[0].y - p[1].y;
    c->bx = p[2].x - p[1].x;
    c->by = p[2].y - p[1].y;
    c->uux = 2.0f * (c->k0 * c->ax + c->k2 * c->bx);
    c->uuy = 2.0f * (c->k0 * c->ay + c->k2 * c->by);
}

/* Sums of one span's basis products and basis-weighted coordinates over the
 * points that fall on it, added to the normal equations once per span
 * change instead of once per point. */
typedef struct {
    size_t span;
    float s[6]; /* products b0 b0, b1 b0, b1 b1, b2 b0, b2 b1, b2 b2 */
    float x[3];
    float y[3];
} span_sums_t;

static inline void sums_reset(span_sums_t *a, size_t span)
{
#if BSF_CONFIG_COMPACT
    memset(a, 0, sizeof *a);
#else
    /* stores the compiler can keep in registers (SUMS_FLUSH_ACC), where a
     * memset, or an assignment it turns into one, stays a call */
    a->s[0] = a->s[1] = a->s[2] = a->s[3] = a->s[4] = a->s[5] = 0.0f;
    a->x[0] = a->x[1] = a->x[2] = 0.0f;
    a->y[0] = a->y[1] = a->y[2] = 0.0f;
#endif
    a->span = span;
}

static inline void sums_add(span_sums_t *a, float b0, float b2, float px, float py)
{
    const float b1 = 1.0f - b0 - b2;
    a->s[0] += b0 * b0;
    a->s[1] += b1 * b0;
    a->s[2] += b1 * b1;
    a->s[3] += b2 * b0;
    a->s[4] += b2 * b1;
    a->s[5] += b2 * b2;
    a->x[0] += b0 * px;
    a->x[1] += b1 * px;
    a->x[2] += b2 * px;
    a->y[0] += b0 * py;
    a->y[1] += b1 * py;
    a->y[2] += b2 * py;
}

#if !BSF_CONFIG_COMPACT
/* A span's six basis products (span_sums_t.s) added to the lower band. */
static inline void band_add(bsf_pdm_work_t *w, size_t span, const float *s6)
{
    const uint8_t *unk = &w->unknown_of[span];
    const size_t u0 = unk[0];
    const size_t u1 = unk[1];
    const size_t u2 = unk[2];
    float *band = w->band;
    band[u0 * 3u] += s6[0];
    band[u1 * 3u] += s6[2];
    band[u2 * 3u] += s6[5];
    band[u1 * 3u + (u1 - u0)] += (u1 == u0 ? 2.0f : 1.0f) * s6[1];
    band[u2 * 3u + (u2 - u0)] += (u2 == u0 ? 2.0f : 1.0f) * s6[3];
    band[u2 * 3u + (u2 - u1)] += (u2 == u1 ? 2.0f : 1.0f) * s6[4];
}
#endif

/* Add a span's sums to the lower band (stride 3) and right-hand sides. Its
 * three stored control points map to non-decreasing unknowns; at a vertex
 * two of them are one unknown, whose weight is the sum of both basis values,
 * so the cross product of the two copies lands twice on its diagonal. */
static void sums_flush(bsf_pdm_work_t *w, const span_sums_t *a)
{
    const uint8_t *unk = &w->unknown_of[a->span];
    const size_t u0 = unk[0];
    const size_t u1 = unk[1];
    const size_t u2 = unk[2];
#if BSF_CONFIG_COMPACT
    /* compact: the same additions in the same order, from tables (the three
     * diagonal products, then the three below it). */
    float *band = w->band;
    static const uint8_t row[6] = {0u, 1u, 2u, 1u, 2u, 2u};
    static const uint8_t col[6] = {0u, 1u, 2u, 0u, 0u, 1u};
    static const uint8_t prod[6] = {0u, 2u, 5u, 1u, 3u, 4u};
    size_t k;
    (void)u0;
    (void)u1;
    (void)u2;
    for (k = 0; k < 6u; ++k) {
        const size_t ur = unk[row[k]];
        const size_t uc = unk[col[k]];
        band[ur * 3u + (ur - uc)] += (k >= 3u && ur == uc ? 2.0f : 1.0f) * a->s[prod[k]];
    }
    for (k = 0; k < 3u; ++k) {
        w->rhs_x[unk[k]] += a->x[k];
        w->rhs_y[unk[k]] += a->y[k];
    }
#else
    band_add(w, a->span, a->s);
    w->rhs_x[u0] += a->x[0];
    w->rhs_x[u1] += a->x[1];
    w->rhs_x[u2] += a->x[2];
    w->rhs_y[u0] += a->y[0];
    w->rhs_y[u1] += a->y[1];
    w->rhs_y[u2] += a->y[2];
#endif
}

/* sums_flush of a sweep's running sums. Outside the compact build it flushes
 * a copy: the accumulator's own address then never escapes, so its twelve
 * sums stay in registers across the sweep instead of being loaded and
 * stored at every point (24 instructions per point on the Cortex-M4F).
 * footpoint_pass flushes directly: its sums spill there anyway. */
#if BSF_CONFIG_COMPACT
#define SUMS_FLUSH_ACC(w, acc) sums_flush((w), &(acc))
#else
static inline void sums_flush_copy(bsf_pdm_work_t *w, span_sums_t copy)
{
    sums_flush(w, &copy);
}
#define SUMS_FLUSH_ACC(w, acc) sums_flush_copy((w), (acc))
#endif

#if !BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
__attribute__((noinline)) /* inlined, it upsets the register allocation of assemble */
#endif
static void
clear_normal_equations(const pdm_state_t *s, bsf_pdm_work_t *w)
{
#if BSF_CONFIG_COMPACT
    memset(w->band, 0, s->n_unknown * 3u * sizeof w->band[0]);
    memset(w->rhs_x, 0, s->n_unknown * sizeof w->rhs_x[0]);
    memset(w->rhs_y, 0, s->n_unknown * sizeof w->rhs_y[0]);
#else
    /* one sweep of stores: a few unknowns, where three memset calls cost
     * more than the stores themselves */
    float *band = w->band;
    size_t k;
    for (k = 0; k < s->n_unknown; ++k) {
        band[0] = band[1] = band[2] = 0.0f;
        band += 3;
        w->rhs_x[k] = w->rhs_y[k] = 0.0f;
    }
#endif
}

/* Normal equations from the current parameters alone (after a layout change,
 * when no curve of the new layout exists yet). */
static void assemble(const pdm_state_t *s, bsf_pdm_work_t *w)
{
    const size_t n_span = s->n_ctrl - 2u;
    const float fs = (float)n_span;
    const float ox = s->origin.x;
    const float oy = s->origin.y;
    /* A local: the flushes' stores could change s->pts as far as the
     * compiler knows, which then reloads it at every point. */
    const bsf_point_t *pts = s->pts;
    span_sums_t acc;
    size_t i;
    float k0 = 1.0f; /* basis scales of span acc.span */
    float k2 = n_span == 1u ? 1.0f : 0.5f;
    clear_normal_equations(s, w);
    sums_reset(&acc, 0u);
    for (i = 0; i < s->n; ++i) {
        float u;
        const size_t span = span_of(w->t[i], fs, n_span, &u);
        const float v = 1.0f - u;
        if (span != acc.span) {
            SUMS_FLUSH_ACC(w, acc);
            sums_reset(&acc, span);
            k0 = span == 0u ? 1.0f : 0.5f;
            k2 = span + 1u == n_span ? 1.0f : 0.5f;
        }
        sums_add(&acc, k0 * v * v, k2 * u * u, pts[i].x - ox, pts[i].y - oy);
    }
    SUMS_FLUSH_ACC(w, acc);
}

/* Start of a fit (a new layout, or a restart): each point's parameter is
 * its arc-length fraction of its fragment's knot range, corrected for the
 * non-uniform speed of the straight spans at a vertex, and the normal
 * equations are assembled at these parameters in the same sweep. No start
 * curve is needed: the first solve computes the control points from the
 * parameters alone. */
static void start_from_arc_length(const pdm_state_t *s, bsf_pdm_work_t *w, const float *t0,
                                  const float *t1)
{
    const size_t n_span = s->n_ctrl - 2u;
    const float fs = (float)n_span;
    const float ox = s->origin.x;
    const float oy = s->origin.y;
    span_sums_t acc;
    float k0 = 1.0f; /* basis scales of span acc.span */
    float k2 = n_span == 1u ? 1.0f : 0.5f;
    size_t f;
    size_t i = 0;

    clear_normal_equations(s, w);
    sums_reset(&acc, 0u);
    for (f = 0; f < s->n_frag; ++f) {
        const size_t a = w->frag_first[f];
        const size_t b = w->frag_last[f];
        const float len = s->frag_len[f];
        const float inv_len = len > 0.0f ? 1.0f / len : 0.0f;
        const float range = t1[f] - t0[f];
        const unsigned straight = w->frag_precision[f] == 0u;
        const unsigned shape = f == 0u ? 0u : (f + 1u == s->n_frag ? 1u : 2u);
        /* The vertex point closing fragment f opens fragment f + 1: it is
         * accumulated once, by the fragment it closes. */
        i = f == 0u ? a : a + 1u;
#if !BSF_CONFIG_COMPACT
        /* Points before the last of a curved fragment of some length: the
         * general loop's tests are decided for them (the same float
         * operations, fewer branches). */
        if (!straight && len > 0.0f) {
            /* locals: as in assemble (the stores into w->t could change
             * t0[f] too, as far as the compiler knows) */
            const bsf_point_t *pts = s->pts;
            const float t_start = t0[f];
            for (; i < b; ++i) {
                float frac = w->arc[i] * inv_len;
                float u;
                float t;
                size_t span;
                frac = frac > 1.0f ? 1.0f : (frac < 0.0f ? 0.0f : frac);
                t = t_start + frac * range;
                w->t[i] = t;
                span = span_of(t, fs, n_span, &u);
                if (span != acc.span) {
                    SUMS_FLUSH_ACC(w, acc);
                    sums_reset(&acc, span);
                    k0 = span == 0u ? 1.0f : 0.5f;
                    k2 = span + 1u == n_span ? 1.0f : 0.5f;
                }
                {
                    const float v = 1.0f - u;
                    sums_add(&acc, k0 * v * v, k2 * u * u, pts[i].x - ox, pts[i].y - oy);
                }
            }
        }
#endif
        for (; i <= b; ++i) {
            float frac;
            float u;
            float t;
            size_t span;
            /* Coincident points: fall back to even spacing by index. */
            if (i == b) {
                frac = 1.0f; /* its arc slot belongs to the next fragment */
            } else {
                frac = len > 0.0f ? w->arc[i] * inv_len : (float)(i - a) / (float)(b - a);
            }
            frac = frac > 1.0f ? 1.0f : (frac < 0.0f ? 0.0f : frac);
            if (straight) {
                /* A straight fragment at a vertex is not traversed at
                 * constant speed: boundary-vertex runs as 1 - (1 - u)^2,
                 * vertex-boundary as u^2, vertex-vertex as 2u^2 then
                 * 1 - 2(1 - u)^2. Invert it so the start parameters are the
                 * footpoints already. */
                if (shape == 0u) {
                    frac = 1.0f - sqrtf(1.0f - frac);
                } else if (shape == 1u) {
                    frac = sqrtf(frac);
                } else {
                    frac = frac <= 0.5f ? sqrtf(0.5f * frac) : 1.0f - sqrtf(0.5f * (1.0f - frac));
                }
            }
            t = t0[f] + frac * range;
            w->t[i] = t;
            span = span_of(t, fs, n_span, &u);
            if (span != acc.span) {
                SUMS_FLUSH_ACC(w, acc);
                sums_reset(&acc, span);
                k0 = span == 0u ? 1.0f : 0.5f;
                k2 = span + 1u == n_span ? 1.0f : 0.5f;
            }
            {
                const float v = 1.0f - u;
                sums_add(&acc, k0 * v * v, k2 * u * u, s->pts[i].x - ox, s->pts[i].y - oy);
            }
        }
    }
    SUMS_FLUSH_ACC(w, acc);
}

/* Step (a): add the bending term to the assembled normal equations and solve
 * for the control points. */
static bsf_status_t solve_control_points(pdm_state_t *s, bsf_pdm_work_t *w)
{
    const size_t m = s->n_unknown;
    const size_t n_span = s->n_ctrl - 2u;
    size_t k;
    int loaded = 0;
    bsf_status_t st;

    if (s->lambda > 0.0f) {
        /* Bending energy: integral of |S''(t)|^2 is n_span^3 * sum over spans
         * of (c_s . P)^2 with c_s the span's second u-derivatives. */
        const float fs = (float)n_span;
        const float weight = s->lambda * fs * fs * fs;
        for (k = 0; k < n_span; ++k) {
            /* c_s = 2 (k0, -(k0 + k2), k2): the Appendix's (1, -2, 1),
             * (2, -3, 1), (1, -3, 2) or (2, -4, 2). */
            const float c0 = k == 0u ? 2.0f : 1.0f;
            const float c2 = k + 1u == n_span ? 2.0f : 1.0f;
            const float c1 = -(c0 + c2);
#if BSF_CONFIG_COMPACT
            span_sums_t r;
            sums_reset(&r, k);
            r.s[0] = weight * c0 * c0;
            r.s[1] = weight * c1 * c0;
            r.s[2] = weight * c1 * c1;
            r.s[3] = weight * c2 * c0;
            r.s[4] = weight * c2 * c1;
            r.s[5] = weight * c2 * c2;
            sums_flush(w, &r);
#else
            /* The band alone: the right-hand sides would only add +0, which
             * leaves them as they are (sums that start at +0 never reach -0). */
            float r[6];
            r[0] = weight * c0 * c0;
            r[1] = weight * c1 * c0;
            r[2] = weight * c1 * c1;
            r[3] = weight * c2 * c0;
            r[4] = weight * c2 * c1;
            r[5] = weight * c2 * c2;
            band_add(w, k, r);
#endif
        }
    }
    if (s->anchor != NULL) {
        /* Each vertex is held near its anchor by a spring. */
        const float weight = PDM_ANCHOR_WEIGHT * (float)s->n;
        for (k = 0; k + 1u < s->n_frag; ++k) {
            const size_t u = s->vertex_unknown[k];
            w->band[u * 3u] += weight;
            w->rhs_x[u] += weight * (s->anchor[k].x - s->origin.x);
            w->rhs_y[u] += weight * (s->anchor[k].y - s->origin.y);
        }
    }
    st = bsf_spd_band_solve2(w->band, m, m > 2u ? 2u : m - 1u, w->factor, w->rhs_x, w->rhs_y,
                             &loaded);
    if (st != BSF_OK) {
        return BSF_ERR_NUMERIC;
    }
    s->loaded += (uint32_t)loaded;
    for (k = 0; k < s->n_ctrl; ++k) {
        w->ctrl[k].x = w->rhs_x[w->unknown_of[k]];
        w->ctrl[k].y = w->rhs_y[w->unknown_of[k]];
    }
    return BSF_OK;
}

/* Whether the farthest point of fragment [first, last] from the curve (far,
 * squared distance far2) stands alone: at least two points inside the
 * fragment and both neighbours (the larger squared distance near2) at less
 * than a quarter of its distance. Such a point is a stray return (a mixed pixel);
 * the tail of a corner the vertices miss, or a corner the curve cuts, has far
 * neighbours. Measured on the ground-truth scenes: without the two
 * conditions, settling (bsf_pdm_fit_anchored) also stopped fragments next to
 * corners (vertex error p90 0.91 -> 1.31 cm on one row). */
static int lone_stray(size_t first, size_t last, size_t far, float far2, float near2)
{
    return far > first + 1u && far + 2u < last && 16.0f * near2 < far2;
}

/* Refinement error of a fragment when bias_window is on: its RMS, raised
 * so that it exceeds target_rms exactly when (1) the largest mean signed
 * residual over bias_window consecutive points exceeds the larger of
 * bias_ratio * target_rms and PDM_BIAS_Z standard errors of such a mean
 * (rms / sqrt(window): a window of pure noise rarely gets there, a bulge
 * off a curved wall or a corner cut does), or (2) some point lies more than
 * PDM_POINT_RATIO * target_rms from the curve. The window holds
 * bias_window slots of `block` points each (bias_block). */
static float systematic_error(const pdm_state_t *s, float rms, float window_max, float point_max2,
                              size_t block, float *shape)
{
    const float window = (float)(s->bias_window * block);
    const float noise_bound = PDM_BIAS_Z * rms / sqrtf(window);
    const float bound = noise_bound > s->bias_floor ? noise_bound : s->bias_floor;
    const float mean_err = window_max / window / bound * s->target;
    const float point_err = sqrtf(point_max2) * (1.0f / PDM_POINT_RATIO);
    float e = rms;
    e = mean_err > e ? mean_err : e;
    *shape = e;
    e = point_err > e ? point_err : e;
    return e;
}

/* Points per slot of fragment f's deviation window: 1 up to
 * PDM_BIAS_MAX_WINDOWS windows of bias_window points, then as many as keep
 * the fragment within that many windows. */
static BSF_COMPACT_NOINLINE size_t bias_block(const pdm_state_t *s, const bsf_pdm_work_t *w,
                                              size_t f)
{
    const size_t count = (size_t)w->frag_last[f] - w->frag_first[f] + 1u;
    const size_t span = PDM_BIAS_MAX_WINDOWS * s->bias_window;
    return count > span ? (count + span - 1u) / span : 1u;
}

/* Step (b): footpoints for fixed control points, by at most `steps` Newton
 * steps per point from its current parameter (Gauss-Newton when curvature
 * makes Newton unsafe; a step is halved up to twice and only accepted when it
 * brings the curve closer, so no point's distance ever grows; a step may land
 * in the neighbouring span). The end points keep parameters 0 and 1: they
 * anchor the curve's ends, which would otherwise drift past the data. Fills
 * the RMS per fragment (a vertex point belongs to both its fragments) and
 * overall, and (when another iteration may follow) assembles the next normal
 * equations at the new parameters in the same sweep, so no basis is computed
 * twice. With give_up_rms > 0 the pass stops as soon as the overall RMS can
 * no longer end below give_up_rms (the squared distances only add up) and
 * returns 0, leaving the parameters half updated for the caller to discard;
 * otherwise it returns 1. */
#if !BSF_CONFIG_COMPACT && (defined(__GNUC__) || defined(__clang__))
__attribute__((noinline)) /* one copy: inlined into try_cold_start, it doubled the stack */
#endif
static int
footpoint_pass(pdm_state_t *s, bsf_pdm_work_t *w, unsigned steps, int assemble_next,
               float give_up_rms)
{
    const size_t n_span = s->n_ctrl - 2u;
    const float fs = (float)n_span;
    const float inv_fs = 1.0f / fs;
    const size_t last = s->n - 1u;
    const size_t bias_window = s->bias_window;
    const float ox = s->origin.x;
    const float oy = s->origin.y;
    span_coef_t c;
    span_coef_t cn;
    span_sums_t acc;
    float total = 0.0f;
    float frag_sum = 0.0f;
    size_t frag_end = w->frag_last[0];
    size_t f = 0;
    size_t i;
    /* One test per point for three rare events: the end of a fragment (the
     * last one ends the pass), the first point and the last but one (the end
     * points take no footpoint step). */
    size_t next_event = 0;
    unsigned n_steps = 0u;
    /* Systematic deviation (bias_window > 0): the last bias_window signed
     * residuals of the fragment (a ring), their sum, the fragment's largest
     * |sum| and its largest squared distance. Only ring[0..bias_window) is
     * used. ring_wait counts the points still missing before the window is
     * full: while it does, ring[ring_at] is an empty slot (no memset). */
    float ring[BSF_PDM_MAX_BIAS_WINDOW];
    size_t ring_at = 0;
    size_t ring_wait = bias_window;
#if !BSF_CONFIG_COMPACT
    int ring_full = 0; /* block is 1 and ring_wait 0: the ring's fast path */
#endif
    float ring_sum = 0.0f;
    float window_max = 0.0f;
    float point_max = 0.0f;
    /* The farthest point of the fragment (first of equals), the larger
     * squared distance of its neighbours and that of the previous point
     * (lone_stray). */
    size_t far_at = 0;
    float far_near = 0.0f;
    float prev_best = 0.0f;
    size_t block = s->bias_window > 0u ? bias_block(s, w, 0u) : 1u;
    size_t block_n = 0;
    float block_sum = 0.0f;
    size_t normal_span = (size_t)-1;
    float nx = 0.0f;
    float ny = 0.0f;

    /* A running total at or above this bound may already lose: checked
     * exactly (as the caller compares) only from there on. */
    const float give_up_total =
        give_up_rms > 0.0f ? give_up_rms * give_up_rms * (float)s->n * 0.999f : 3.0e38f;

    if (assemble_next) {
        clear_normal_equations(s, w);
    }
    sums_reset(&acc, 0u);
    load_span(w->ctrl, n_span, 0u, &c);
    cn = c;
    for (i = 0;; ++i) {
        const float qx = s->pts[i].x - ox;
        const float qy = s->pts[i].y - oy;
        float t = w->t[i];
        float u;
        size_t span = span_of(t, fs, n_span, &u);
        float b0;
        float b2;
        float ex;
        float ey;
        float best;
        float r = 0.0f; /* signed residual (bias_window) */
        unsigned step;

        if (span != c.span) {
            load_span(w->ctrl, n_span, span, &c);
        }
        b0 = c.k0 * (1.0f - u) * (1.0f - u);
        b2 = c.k2 * u * u;
        ex = c.p1x + b0 * c.ax + b2 * c.bx - qx;
        ey = c.p1y + b0 * c.ay + b2 * c.by - qy;
        best = ex * ex + ey * ey;
        for (step = 0; step < n_steps; ++step) {
            /* Derivatives at the current u of span c. */
            const float d0 = c.m0 * (1.0f - u);
            const float d2 = c.m2 * u;
            const float ux = d0 * c.ax + d2 * c.bx;
            const float uy = d0 * c.ay + d2 * c.by;
            const float g = ex * ux + ey * uy;
            const float gn = ux * ux + uy * uy;
            float h = gn + ex * c.uux + ey * c.uuy;
            float delta;
            float t_new = t;
            float u_new = u;
            float d = best;
            float nb0 = b0;
            float nb2 = b2;
            float nex = ex;
            float ney = ey;
            unsigned halving;
            unsigned n_try;
#if BSF_CONFIG_COMPACT
            int closer = 0; /* d < best: the step is taken */
#endif
            size_t span_new = c.span;

            if (!(h >= 0.5f * gn)) {
                h = gn;
            }
            if (!(h > 0.0f)) {
                break;
            }
            delta = -g / h; /* in u; the t step is delta / n_span */
            if (!(fabsf(delta) > PDM_STEP_EPS)) {
                break; /* converged: a step this small cannot be resolved */
            }
            n_try = fabsf(delta) > PDM_HALVE_MIN ? 3u : 1u;
            delta *= inv_fs;
            for (halving = 0; halving < n_try; ++halving) {
                const float du_try = delta * fs;
                const float u_try = u + du_try;
                t_new = t + delta;
                t_new = t_new < 0.0f ? 0.0f : (t_new > 1.0f ? 1.0f : t_new);
                if (!(fabsf(t_new - t) > 1e-7f)) {
                    break;
                }
                if (u_try >= 0.0f && u_try < 1.0f) {
                    /* Still on span c, a quadratic in u: its Taylor expansion
                     * to second order is exact. */
                    span_new = c.span;
                    u_new = u_try;
                    nex = ex + du_try * (ux + 0.5f * du_try * c.uux);
                    ney = ey + du_try * (uy + 0.5f * du_try * c.uuy);
                } else {
#if BSF_CONFIG_COMPACT
                    /* compact: one copy of the evaluation, on span c or the new span */
                    const span_coef_t *e = &c;
                    if ((span_new = span_of(t_new, fs, n_span, &u_new)) != c.span) {
                        load_span(w->ctrl, n_span, span_new, &cn);
                        e = &cn;
                    }
                    nb0 = e->k0 * (1.0f - u_new) * (1.0f - u_new);
                    nb2 = e->k2 * u_new * u_new;
                    nex = e->p1x + nb0 * e->ax + nb2 * e->bx - qx;
                    ney = e->p1y + nb0 * e->ay + nb2 * e->by - qy;
#else
                    if ((span_new = span_of(t_new, fs, n_span, &u_new)) == c.span) {
                        nb0 = c.k0 * (1.0f - u_new) * (1.0f - u_new);
                        nb2 = c.k2 * u_new * u_new;
                        nex = c.p1x + nb0 * c.ax + nb2 * c.bx - qx;
                        ney = c.p1y + nb0 * c.ay + nb2 * c.by - qy;
                    } else {
                        load_span(w->ctrl, n_span, span_new, &cn);
                        nb0 = cn.k0 * (1.0f - u_new) * (1.0f - u_new);
                        nb2 = cn.k2 * u_new * u_new;
                        nex = cn.p1x + nb0 * cn.ax + nb2 * cn.bx - qx;
                        ney = cn.p1y + nb0 * cn.ay + nb2 * cn.by - qy;
                    }
#endif
                }
                d = nex * nex + ney * ney;
                if (d < best) {
#if BSF_CONFIG_COMPACT
                    closer = 1;
#endif
                    break;
                }
                delta *= 0.5f;
            }
#if BSF_CONFIG_COMPACT
            if (!closer) { /* the flag, not d < best again: 24 bytes shorter */
                break;
            }
#else
            if (!(d < best)) { /* not the flag: 0.7 % fewer x86 instructions */
                break;
            }
#endif
            best = d;
            t = t_new;
            u = u_new;
            ex = nex;
            ey = ney;
            if (span_new != c.span) {
                c = cn;
            }
        }
        w->t[i] = t;
        if (assemble_next) {
            b0 = c.k0 * (1.0f - u) * (1.0f - u);
            b2 = c.k2 * u * u;
            if (c.span != acc.span) {
                sums_flush(w, &acc);
                sums_reset(&acc, c.span);
            }
            sums_add(&acc, b0, b2, qx, qy);
        }
        total += best;
        frag_sum += best;
        if (total >= give_up_total && give_up_rms > 0.0f &&
            !(sqrtf(total / (float)s->n) < give_up_rms)) {
            return 0;
        }
        if (bias_window > 0u) {
            /* Signed residual along the normal of the span's chord (one
             * square root per span), summed over the last bias_window
             * points of the fragment in a ring. */
            float slot;
            int slot_open = 0;
            if (c.span != normal_span) {
                const float dx = c.bx - c.ax; /* P2 - P0 */
                const float dy = c.by - c.ay;
                const float len2 = dx * dx + dy * dy;
                const float inv = len2 > 0.0f ? 1.0f / sqrtf(len2) : 0.0f;
                nx = -dy * inv;
                ny = dx * inv;
                normal_span = c.span;
            }
            r = ex * nx + ey * ny;
            slot = r;
#if !BSF_CONFIG_COMPACT
            if (ring_full) {
                /* the general path below with one point per slot and the
                 * window full: one test instead of three */
                ring_sum += slot - ring[ring_at];
                ring[ring_at] = slot;
                ring_at = ring_at + 1u == bias_window ? 0u : ring_at + 1u;
                if (fabsf(ring_sum) > window_max) {
                    window_max = fabsf(ring_sum);
                }
            } else
#endif
            {
                if (block > 1u) {
                    block_sum += r;
                    slot = block_sum;
                    if (++block_n == block) {
                        block_n = 0u;
                        block_sum = 0.0f;
                    } else {
                        slot_open = 1;
                    }
                }
                if (!slot_open) {
                    if (ring_wait > 0u) {
                        ring_sum += slot; /* an empty slot: slot - 0 is slot */
                        --ring_wait;
                    } else {
                        ring_sum += slot - ring[ring_at];
                    }
                    ring[ring_at] = slot;
                    ring_at = ring_at + 1u == bias_window ? 0u : ring_at + 1u;
                    if (ring_wait == 0u && fabsf(ring_sum) > window_max) {
                        window_max = fabsf(ring_sum);
                    }
                }
#if !BSF_CONFIG_COMPACT
                ring_full = block == 1u && ring_wait == 0u;
#endif
            }
            if (best > point_max) {
                point_max = best;
                far_at = i;
                far_near = prev_best;
            } else if (i == far_at + 1u && best > far_near) {
                far_near = best;
            }
            prev_best = best;
        }
        if (i != next_event) {
            continue;
        }
        if (i == frag_end) {
            const size_t count = frag_end - w->frag_first[f] + 1u;
            const float rms = sqrtf(frag_sum / (float)count);
            w->frag_rms[f] = rms;
            if (bias_window > 0u) {
                float shape;
                w->frag_rms[f] = systematic_error(s, rms, window_max, point_max, block, &shape);
                s->frag_stray[f] =
                    (uint8_t)(shape <= s->target &&
                              lone_stray(w->frag_first[f], frag_end, far_at, point_max, far_near));
            }
            frag_sum = best;  /* the vertex point opens the next fragment */
            point_max = best; /* far_at stays before the next fragment */
            window_max = 0.0f;
            if (f + 1u < s->n_frag) {
                ++f;
                frag_end = w->frag_last[f];
                block = bias_window > 0u ? bias_block(s, w, f) : 1u;
            }
            /* A trailing partial slot is dropped (the ring is unused
             * without bias_window). */
            ring_sum = 0.0f;
            ring_at = 0u;
            ring_wait = bias_window;
            block_sum = r;
            block_n = 1u;
            if (block == 1u) {
                ring[0] = r;
                ring_sum = r;
                ring_at = 1u;
                ring_wait = bias_window - 1u;
                block_n = 0u;
                block_sum = 0.0f;
            }
#if !BSF_CONFIG_COMPACT
            ring_full = block == 1u && ring_wait == 0u;
#endif
            if (i == last) {
                break;
            }
        }
        /* The last point (the last fragment's end) takes no step. */
        n_steps = i + 1u < last ? steps : 0u;
        next_event = i + 1u < last && frag_end > last - 1u ? last - 1u : frag_end;
    }
    if (assemble_next) {
        sums_flush(w, &acc);
    }
    s->rms = sqrtf(total / (float)s->n);
    return 1;
}

static float worst_fragment(const pdm_state_t *s, const bsf_pdm_work_t *w)
{
    float worst = 0.0f;
    size_t f;
    for (f = 0; f < s->n_frag; ++f) {
        worst = w->frag_rms[f] > worst ? w->frag_rms[f] : worst;
    }
    return worst;
}

/* Copies the fit (parameters, control points, fragment errors) into the
 * *_prev buffers, or back from them (restore). */
static void copy_fit(const pdm_state_t *s, bsf_pdm_work_t *w, int restore)
{
    float *t_from = w->t;
    float *t_to = w->t_prev;
    bsf_point_t *c_from = w->ctrl;
    bsf_point_t *c_to = w->ctrl_prev;
    float *r_from = w->frag_rms;
    float *r_to = w->frag_rms_prev;
    if (restore) {
        t_from = w->t_prev;
        t_to = w->t;
        c_from = w->ctrl_prev;
        c_to = w->ctrl;
        r_from = w->frag_rms_prev;
        r_to = w->frag_rms;
    }
    memcpy(t_to, t_from, s->n * sizeof w->t[0]);
    memcpy(c_to, c_from, s->n_ctrl * sizeof w->ctrl[0]);
    memcpy(r_to, r_from, s->n_frag * sizeof w->frag_rms[0]);
}

/* Alternate (a) and (b) until the RMS stops improving by rel_tol. The normal
 * equations must be assembled at the current parameters on entry. The
 * bending term means a solve minimises RMS plus bending, so in rare cases an
 * iteration raises the RMS slightly: such an iteration is undone (parameters,
 * control points and fragment RMS restored) and ends the solve, so the
 * accepted RMS sequence never increases. With stop_below > 0 (refinement on,
 * stop_below = target_rms) the solve also ends as soon as every fragment
 * meets it (more iterations would only polish a finished fit), and with
 * stop_when_far when the worst fragment is still far above it (refinement
 * will change the layout anyway, so polishing this one is wasted; not on the
 * first solve, whose second iteration settles the vertices and keeps
 * straight fragments from looking far). */

static bsf_status_t run_pdm(pdm_state_t *s, bsf_pdm_work_t *w, const bsf_pdm_params_t *p,
                            size_t max_iterations, float stop_below, int stop_when_far,
                            uint32_t *iterations)
{
    float prev = 0.0f;
    float worst;
    size_t it;

    w->n_history = 0u;
    for (it = 0; it < max_iterations; ++it) {
        bsf_status_t st;
        if (it > 0u) {
            copy_fit(s, w, 0);
        }
        st = solve_control_points(s, w);
        if (st != BSF_OK) {
            return st;
        }
        (void)footpoint_pass(s, w, p->footpoint_steps, it + 1u < max_iterations, 0.0f);
        ++*iterations;
        if (it > 0u && s->rms > prev) {
            copy_fit(s, w, 1);
            s->rms = prev;
            break;
        }
        w->rms_history[w->n_history++] = s->rms;
        worst = worst_fragment(s, w);
        if (!(s->rms > 0.0f) || (it > 0u && prev - s->rms < p->rel_tol * prev) ||
            (stop_below > 0.0f &&
             ((worst <= stop_below) || (stop_when_far && worst > PDM_FAR_RATIO * stop_below)))) {
            break;
        }
        prev = s->rms;
    }
    return BSF_OK;
}

/* Most precision points fragment f may hold: one per 4 of its points, at least one. */
static size_t precision_cap(const bsf_pdm_work_t *w, size_t f)
{
    const size_t count = (size_t)w->frag_last[f] - w->frag_first[f] + 1u;
    return count >= 8u ? count / 4u : 1u;
}

/* Fragment to refine: the worst one above target that may still grow and
 * is not settled (a bit per fragment). */
static size_t pick_fragment(const pdm_state_t *s, const bsf_pdm_work_t *w, float target,
                            size_t max_ctrl, uint32_t settled)
{
    size_t best = NO_FRAGMENT;
    size_t f;
    if (s->n_ctrl + 1u > max_ctrl) {
        return NO_FRAGMENT;
    }
    for (f = 0; f < s->n_frag; ++f) {
        if (w->frag_rms[f] > target && w->frag_precision[f] < precision_cap(w, f) &&
            !(settled >> f & 1u) && (best == NO_FRAGMENT || w->frag_rms[f] > w->frag_rms[best])) {
            best = f;
        }
    }
    return best;
}

/* Warm start after adding a precision point: every parameter keeps its
 * relative place inside its fragment's knot range. */
static BSF_COMPACT_INLINE void remap_parameters(const pdm_state_t *s, bsf_pdm_work_t *w,
                                                const float *old_t0, const float *old_t1,
                                                const float *t0, const float *t1)
{
    float scale[BSF_PDM_MAX_FRAGMENTS];
    size_t f;
    size_t i;
    for (f = 0; f < s->n_frag; ++f) {
        scale[f] = (t1[f] - t0[f]) / (old_t1[f] - old_t0[f]);
    }
    f = 0;
#if !BSF_CONFIG_COMPACT
    /* One fragment (no vertex, most fits): the general loop below with its
     * fragment searches decided. Locals: the stores into w->t would make
     * the compiler reload s->n at every point. */
    if (s->n_frag == 1u) {
        const size_t n = s->n;
        float *const tp = w->t;
        const float base = t0[0];
        const float old_base = old_t0[0];
        const float scale0 = scale[0];
        for (i = 0; i < n; ++i) {
            const float t = base + (tp[i] - old_base) * scale0;
            tp[i] = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
        }
        return;
    }
#endif
    for (i = 0; i < s->n; ++i) {
        float t = w->t[i];
        while (f + 1u < s->n_frag && t > old_t1[f]) {
            ++f;
        }
        while (f > 0u && t < old_t0[f]) {
            --f;
        }
        t = t0[f] + (t - old_t0[f]) * scale[f];
        w->t[i] = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    }
}

/* Precision points to add to fragment f, whose RMS is above PDM_FAR_RATIO *
 * target: as many as an h^3 error law (quadratic splines on a smooth shape)
 * predicts to bring it down to PDM_FAR_AIM * target, at least one, within the
 * fragment's cap and the control-point cap. The law errs low on a corner the
 * vertices miss (its error falls more slowly), so a fragment is rarely grown
 * past need, and the last points before the target are always added one at
 * a time. Only the worst fragment grows: a neighbour's error may only be the
 * pull of the worst one on their shared vertex. */
static size_t far_growth(const pdm_state_t *s, const bsf_pdm_work_t *w, size_t f, float target,
                         size_t max_ctrl)
{
    const size_t room = max_ctrl - s->n_ctrl;
    const float ratio = w->frag_rms[f] / (PDM_FAR_AIM * target);
    const size_t k = w->frag_precision[f];
    const size_t cap = precision_cap(w, f);
    const float now = (float)(k + 1u);
    size_t add = 0u;
    do {
        const float next = (float)(k + add + 2u);
        ++add;
        if (next * next * next >= ratio * now * now * now) {
            break;
        }
    } while (k + add < cap && add < room);
    return add;
}

/* After a warm-started refinement that gained little: the footpoints may be
 * stuck on the wrong side of a corner the vertices miss. Fit the layout from
 * arc length too and keep whichever fit has the lower RMS (the warm one is
 * parked in the *_prev buffers, which run_pdm only uses from its second
 * iteration on). */
static bsf_status_t try_cold_start(pdm_state_t *s, bsf_pdm_work_t *w, const bsf_pdm_params_t *p,
                                   const float *t0, const float *t1, uint32_t *iterations)
{
    const float warm = s->rms;
    bsf_status_t st;
    copy_fit(s, w, 0);
    start_from_arc_length(s, w, t0, t1);
    /* run_pdm's single iteration, with a footpoint pass that stops once
     * the restart can no longer beat the warm fit. */
    w->n_history = 0u;
    st = solve_control_points(s, w);
    if (st != BSF_OK) {
        return st;
    }
    ++*iterations;
    /* A pass that gives up leaves s->rms at the warm fit's: lost. */
    if (footpoint_pass(s, w, p->footpoint_steps, 0, warm)) {
        w->rms_history[w->n_history++] = s->rms;
    }
    if (!(s->rms < warm)) {
        copy_fit(s, w, 1);
        s->rms = warm;
    }
    return BSF_OK;
}

/* 1 when the first and last quarters of points a..b head more than 90
 * degrees apart, each over at least PDM_ARC_BASE (so range noise cannot turn
 * them): one quadratic span cannot follow such a turn. On a pillar's
 * silhouette (about 165 degrees) it keeps about 1.5 cm RMS at 1 cm noise,
 * within the target, with its ends 3-5 cm off the surface past the last
 * returns, where the deviation test hardly looks: there the curve's normal
 * has swung round to the span's chord. Such a fragment starts with two
 * spans. */
static size_t turns_back(const bsf_point_t *pts, size_t a, size_t b)
{
    const size_t q = (b - a) / 4u;
    const bsf_point_t *head = &pts[a];
    const bsf_point_t *tail = &pts[b - q];
    const float base2 = PDM_ARC_BASE * PDM_ARC_BASE;
    return q >= 2u && dist2_pts(head[0], head[q]) >= base2 &&
                   dist2_pts(tail[0], tail[q]) >= base2 &&
                   (head[q].x - head[0].x) * (tail[q].x - tail[0].x) +
                           (head[q].y - head[0].y) * (tail[q].y - tail[0].y) <
                       0.0f
               ? 1u
               : 0u;
}

static BSF_COMPACT_INLINE bsf_status_t check_vertices(const uint16_t *vertex_pos, size_t n_vertex,
                                                      size_t n)
{
    size_t k;
    if (n_vertex > 0u && vertex_pos == NULL) {
        return BSF_ERR_ARG;
    }
    if (n_vertex > (size_t)BSF_PDM_MAX_VERTICES) {
        return BSF_ERR_CAPACITY;
    }
    for (k = 0; k < n_vertex; ++k) {
        if (vertex_pos[k] < 2u || (size_t)vertex_pos[k] + 3u > n ||
            (k > 0u && vertex_pos[k] <= vertex_pos[k - 1u])) {
            return BSF_ERR_ARG;
        }
    }
    return BSF_OK;
}

bsf_status_t bsf_pdm_fit(const bsf_point_t *pts, size_t n, const uint16_t *vertex_pos,
                         size_t n_vertex, const bsf_pdm_params_t *p, bsf_pdm_work_t *work,
                         bsf_point_t *ctrl_out, uint8_t *is_vertex_out, size_t ctrl_cap,
                         size_t *n_ctrl_out, float *e_curve_out, bsf_pdm_info_t *info_out)
{
    return bsf_pdm_fit_anchored(pts, n, vertex_pos, NULL, n_vertex, p, work, ctrl_out,
                                is_vertex_out, ctrl_cap, n_ctrl_out, e_curve_out, info_out);
}

bsf_status_t bsf_pdm_fit_anchored(const bsf_point_t *pts, size_t n, const uint16_t *vertex_pos,
                                  const bsf_point_t *vertex_anchor, size_t n_vertex,
                                  const bsf_pdm_params_t *p, bsf_pdm_work_t *work,
                                  bsf_point_t *ctrl_out, uint8_t *is_vertex_out, size_t ctrl_cap,
                                  size_t *n_ctrl_out, float *e_curve_out, bsf_pdm_info_t *info_out)
{
    bsf_pdm_params_t defaults;
    pdm_state_t s;
    bsf_pdm_info_t info;
    float t0[BSF_PDM_MAX_FRAGMENTS];
    float t1[BSF_PDM_MAX_FRAGMENTS];
    size_t max_ctrl;
    uint32_t settled = 0u; /* a bit per fragment (pick_fragment) */
    size_t f;
    size_t i;
    float length = 0.0f;
    bsf_status_t st;

    if (pts == NULL || work == NULL || ctrl_out == NULL || n_ctrl_out == NULL) {
        return BSF_ERR_ARG;
    }
    if (p == NULL) {
        bsf_pdm_params_default(&defaults);
        p = &defaults;
    }
    st = bsf_pdm_params_check(p);
    if (st != BSF_OK) {
        return st;
    }
    if (n > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = bsf_fit_check_points(pts, n);
    if (st != BSF_OK) {
        return st;
    }
    if (n < 3u) {
        return BSF_ERR_DEGENERATE;
    }
    st = check_vertices(vertex_pos, n_vertex, n);
    if (st != BSF_OK) {
        return st;
    }
    if (vertex_anchor != NULL) {
        st = bsf_fit_check_points(vertex_anchor, n_vertex);
        if (st != BSF_OK) {
            return st;
        }
    }
    memset(&s, 0, sizeof s);
    s.anchor = n_vertex > 0u ? vertex_anchor : NULL;
    if (p->refine && p->bias_window > 0u) {
        s.bias_window = p->bias_window;
        s.bias_floor = p->bias_ratio * p->target_rms;
        s.target = p->target_rms;
    }
    for (i = 1; i < n; ++i) {
        length += dist(pts, i - 1u, i);
    }
    if (!(length > 0.0f)) {
        return BSF_ERR_DEGENERATE;
    }

    memset(&info, 0, sizeof info);
    s.pts = pts;
    s.n = n;
    s.origin = pts[0];
    s.n_frag = n_vertex + 1u;
    s.lambda = p->lambda_per_metre * length;
    max_ctrl = p->max_ctrl;

    /* Fragments, their lengths and their starting precision points. */
    for (f = 0; f < s.n_frag; ++f) {
        const size_t a = f == 0u ? 0u : vertex_pos[f - 1u];
        const size_t b = f < n_vertex ? vertex_pos[f] : n - 1u;
        size_t prec;
        work->frag_first[f] = (uint16_t)a;
        work->frag_last[f] = (uint16_t)b;
        /* Arcs are relative to each fragment's first point, so a vertex
         * point's slot holds 0 (the fragment it opens); the fragment it
         * closes ends at its length, frag_len. */
        s.frag_len[f] = fragment_arc(pts, a, b, work->arc);
        if (p->refine) {
            /* Pieces that touch a vertex start straight; with the
             * deviation test on, a piece that turns back starts with two
             * spans (turns_back). */
            prec = n_vertex == 0u
                       ? 1u + (p->bias_window > 0u && p->max_ctrl > 3u ? turns_back(pts, a, b) : 0u)
                       : 0u;
        } else {
            const float chord = dist(pts, a, b);
            const float want = floorf(chord / p->precision_spacing + 0.5f);
            const size_t cap = precision_cap(work, f);
            prec = want < 1.0f ? 1u : (want >= (float)cap ? cap : (size_t)want);
        }
        work->frag_precision[f] = (uint8_t)prec;
    }
    work->n_fragments = (uint16_t)s.n_frag;
    work->last_refined = (uint16_t)NO_FRAGMENT;
    {
        size_t need = 2u + 2u * n_vertex;
        for (f = 0; f < s.n_frag; ++f) {
            need += work->frag_precision[f];
        }
        if (need > max_ctrl) {
            return BSF_ERR_CAPACITY;
        }
    }
    build_layout(&s, work, t0, t1);
    start_from_arc_length(&s, work, t0, t1);
    st = run_pdm(&s, work, p,
                 p->max_passes != 0u && p->max_passes < p->max_iterations ? p->max_passes
                                                                          : p->max_iterations,
                 p->refine ? p->target_rms : 0.0f, 0, &info.iterations);
    if (st != BSF_OK) {
        return st;
    }

    while (p->refine) {
        float old_t0[BSF_PDM_MAX_FRAGMENTS];
        float old_t1[BSF_PDM_MAX_FRAGMENTS];
        const size_t pick = pick_fragment(&s, work, p->target_rms, max_ctrl, settled);
        float before;
        size_t add;
        int far;
        if (pick == NO_FRAGMENT) {
            break;
        }
        before = work->frag_rms[pick];
        far = before > PDM_FAR_RATIO * p->target_rms;
        /* The cap stops the climb near the target, never the growth of a
         * fragment still far from it: a curve cut off there could miss its
         * points by decimetres. */
        if (!far && p->max_passes != 0u && info.iterations + p->refine_iterations > p->max_passes) {
            break;
        }
        work->last_refined = (uint16_t)pick;
        /* Far from the target: several points at once, then a fresh fit of
         * the new layout from arc length. Near it: one point on the worst
         * fragment, warm start. */
        memcpy(old_t0, t0, s.n_frag * sizeof t0[0]);
        memcpy(old_t1, t1, s.n_frag * sizeof t1[0]);
        add = far ? far_growth(&s, work, pick, p->target_rms, max_ctrl) : 1u;
        work->frag_precision[pick] = (uint8_t)(work->frag_precision[pick] + add);
        info.refinements += (uint32_t)add;
        build_layout(&s, work, t0, t1);
        if (far) {
            start_from_arc_length(&s, work, t0, t1);
        } else {
            remap_parameters(&s, work, old_t0, old_t1, t0, t1);
            assemble(&s, work);
        }
        st = run_pdm(&s, work, p, p->refine_iterations, p->target_rms, 1, &info.iterations);
        if (st != BSF_OK) {
            return st;
        }
        if (far) {
            continue;
        }
        if (!(work->frag_rms[pick] < (1.0f - PDM_COLD_GAIN) * before) &&
            (p->max_passes == 0u || info.iterations < p->max_passes)) {
            if (s.frag_stray[pick]) {
                /* Only a lone stray point keeps the fragment above target
                 * and this point gained nothing: more points would only
                 * bend the curve towards it, so the fragment is settled. */
                settled |= 1u << pick;
                continue;
            }
            st = try_cold_start(&s, work, p, t0, t1, &info.iterations);
            if (st != BSF_OK) {
                return st;
            }
        }
    }

    if (s.n_ctrl > ctrl_cap) {
        return BSF_ERR_BUFFER;
    }
    for (i = 0; i < s.n_ctrl; ++i) {
        const int tied = (i > 0u && work->unknown_of[i - 1u] == work->unknown_of[i]) ||
                         (i + 1u < s.n_ctrl && work->unknown_of[i + 1u] == work->unknown_of[i]);
        ctrl_out[i].x = work->ctrl[i].x + s.origin.x;
        ctrl_out[i].y = work->ctrl[i].y + s.origin.y;
        if (is_vertex_out != NULL) {
            is_vertex_out[i] = tied ? 1u : 0u;
        }
    }
    *n_ctrl_out = s.n_ctrl;
    if (e_curve_out != NULL) {
        *e_curve_out = s.rms;
    }
    info.loaded = s.loaded;
    if (info_out != NULL) {
        *info_out = info;
    }
    return BSF_OK;
}

bsf_status_t bsf_pdm_fit_chord(const bsf_point_t *pts, size_t n, size_t n_ctrl,
                               const bsf_pdm_params_t *p, bsf_pdm_work_t *work,
                               bsf_point_t *ctrl_out, float *e_curve_out, uint32_t *iterations)
{
    pdm_state_t s;
    float t0[1];
    float t1[1];
    float length = 0.0f;
    float acc = 0.0f;
    size_t i;
    bsf_status_t st;

    if (pts == NULL || p == NULL || work == NULL || ctrl_out == NULL || iterations == NULL) {
        return BSF_ERR_ARG;
    }
    if (n > (size_t)BSF_MAX_POINTS || n_ctrl > (size_t)BSF_MAX_CTRL_PER_FEATURE) {
        return BSF_ERR_CAPACITY;
    }
    if (n < 3u || n_ctrl < 3u) {
        return BSF_ERR_DEGENERATE;
    }
    for (i = 1; i < n; ++i) {
        length += dist(pts, i - 1u, i);
    }
    if (!(length > 0.0f)) {
        return BSF_ERR_DEGENERATE;
    }
    memset(&s, 0, sizeof s);
    s.pts = pts;
    s.n = n;
    s.origin = pts[0];
    s.n_frag = 1u;
    s.lambda = p->lambda_per_metre * length;
    work->frag_first[0] = 0u;
    work->frag_last[0] = (uint16_t)(n - 1u);
    work->frag_precision[0] = (uint8_t)(n_ctrl - 2u);
    work->n_fragments = 1u;
    work->last_refined = (uint16_t)NO_FRAGMENT;
    build_layout(&s, work, t0, t1);
    for (i = 0; i < n; ++i) {
        if (i > 0u) {
            acc += dist(pts, i - 1u, i);
        }
        work->t[i] = acc / length;
    }
    assemble(&s, work);
    st = run_pdm(&s, work, p, p->max_iterations, 0.0f, 0, iterations);
    if (st != BSF_OK) {
        return st;
    }
    for (i = 0; i < n_ctrl; ++i) {
        ctrl_out[i].x = work->ctrl[i].x + s.origin.x;
        ctrl_out[i].y = work->ctrl[i].y + s.origin.y;
    }
    if (e_curve_out != NULL) {
        *e_curve_out = s.rms;
    }
    return BSF_OK;
}
