/* PDM: point distance minimisation with boundary, vertex and precision
 * control points, and error-driven refinement (design brief section 7). */
#include "bsf/bsf_fit.h"
#include "bsf/bsf_bspline.h"
#include "bsf_fit_internal.h"
#include "bsf_linalg.h"

#include <math.h>
#include <string.h>

#define NO_FRAGMENT 0xFFFFu
/* Footpoint steps shorter than this fraction of a span are not taken. */
#define PDM_STEP_EPS 1e-6f
/* Failed footpoint steps longer than this fraction of a span are halved and
 * retried (far from the curve); shorter ones are only rounding noise. */
#define PDM_HALVE_MIN 0.05f

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
} pdm_state_t;

void bsf_pdm_params_default(bsf_pdm_params_t *p)
{
    if (p == NULL) {
        return;
    }
    p->precision_spacing = 1.0f;
    p->lambda_per_metre = 1e-6f;
    p->rel_tol = 0.01f;
    p->target_rms = 0.015f;
    p->max_iterations = 2u;
    p->refine_iterations = 1u;
    p->max_ctrl = (uint16_t)BSF_MAX_CTRL_PER_FEATURE;
    p->footpoint_steps = 1u;
    p->refine = 1u;
}

bsf_status_t bsf_pdm_params_check(const bsf_pdm_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    /* Written so that NaN fails every test. */
    if (!(p->precision_spacing > 0.0f && p->precision_spacing <= BSF_FIT_MAX_COORD) ||
        !(p->lambda_per_metre >= 0.0f && p->lambda_per_metre <= 1.0f) ||
        !(p->rel_tol > 0.0f && p->rel_tol < 1.0f) ||
        !(p->target_rms > 0.0f && p->target_rms <= BSF_FIT_MAX_COORD) || p->max_iterations < 1u ||
        p->max_iterations > BSF_PDM_MAX_ITERATIONS || p->refine_iterations < 1u ||
        p->refine_iterations > BSF_PDM_MAX_ITERATIONS || p->max_ctrl < 3u ||
        p->max_ctrl > BSF_MAX_CTRL_PER_FEATURE || p->footpoint_steps < 1u ||
        p->footpoint_steps > 8u || p->refine > 1u) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

static float dist(bsf_point_t a, bsf_point_t b)
{
    const float dx = b.x - a.x;
    const float dy = b.y - a.y;
    return sqrtf(dx * dx + dy * dy);
}

static bsf_point_t rel_point(const pdm_state_t *s, size_t i)
{
    bsf_point_t q;
    q.x = s->pts[i].x - s->origin.x;
    q.y = s->pts[i].y - s->origin.y;
    return q;
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
            w->unknown_of[stored++] = (uint8_t)unknown;
            w->unknown_of[stored++] = (uint8_t)unknown++;
        }
    }
    w->unknown_of[stored++] = (uint8_t)unknown++; /* last boundary point */
    t1[s->n_frag - 1u] = 1.0f;
    s->n_ctrl = stored;
    s->n_unknown = unknown;
}

/* Greville abscissa of stored control point k: the parameter a control point
 * "belongs" to (the mean of its two inner knots). */
static float greville(size_t k, size_t n_span)
{
    const float fs = (float)n_span;
    const float a = k >= 1u ? (float)(k - 1u) / fs : 0.0f;
    const float b = (float)k / fs;
    return 0.5f * ((a > 1.0f ? 1.0f : a) + (b > 1.0f ? 1.0f : b));
}

/* Start of a fit: boundary control points on the end points, vertices on
 * their interest points, precision points on the fragment's polyline at the
 * arc-length fraction of their Greville abscissa inside the fragment (evenly
 * spread, so the start curve follows the points with a parameter roughly
 * proportional to arc length). Each point's parameter starts at its
 * arc-length fraction of the fragment's knot range, corrected for the
 * non-uniform speed of the straight spans at a vertex. */
static void init_fit(const pdm_state_t *s, bsf_pdm_work_t *w, const float *t0, const float *t1)
{
    const size_t n_span = s->n_ctrl - 2u;
    size_t stored = 0;
    size_t f;
    size_t i;

    w->ctrl[stored++] = rel_point(s, 0u);
    for (f = 0; f < s->n_frag; ++f) {
        const size_t a = w->frag_first[f];
        const size_t b = w->frag_last[f];
        const float range = t1[f] - t0[f];
        float len = 0.0f;
        float acc = 0.0f;
        size_t k;
        size_t seg = a; /* polyline piece [seg, seg + 1] holding the walk */
        for (i = a + 1u; i <= b; ++i) {
            len += dist(s->pts[i - 1u], s->pts[i]);
        }
        for (i = a; i <= b; ++i) {
            float frac;
            if (i > a) {
                acc += dist(s->pts[i - 1u], s->pts[i]);
            }
            /* Coincident points: fall back to even spacing by index. */
            frac = len > 0.0f ? acc / len : (float)(i - a) / (float)(b - a);
            frac = frac > 1.0f ? 1.0f : frac;
            if (w->frag_precision[f] == 0u) {
                /* A straight fragment at a vertex is not traversed at constant
                 * speed: boundary-vertex runs as 1 - (1 - u)^2, vertex-boundary
                 * as u^2, vertex-vertex as 2u^2 then 1 - 2(1 - u)^2. Invert it
                 * so the start parameters are the footpoints already. */
                if (f == 0u) {
                    frac = 1.0f - sqrtf(1.0f - frac);
                } else if (f + 1u == s->n_frag) {
                    frac = sqrtf(frac);
                } else {
                    frac = frac <= 0.5f ? sqrtf(0.5f * frac) : 1.0f - sqrtf(0.5f * (1.0f - frac));
                }
            }
            w->t[i] = t0[f] + frac * range;
        }
        acc = 0.0f;
        for (k = 0; k < w->frag_precision[f]; ++k) {
            const float want = (greville(stored, n_span) - t0[f]) / range * len;
            bsf_point_t q = rel_point(s, b);
            while (seg < b) {
                const float piece = dist(s->pts[seg], s->pts[seg + 1u]);
                if (acc + piece >= want && piece > 0.0f) {
                    const float r = (want - acc) / piece;
                    const bsf_point_t p0 = rel_point(s, seg);
                    const bsf_point_t p1 = rel_point(s, seg + 1u);
                    q.x = p0.x + r * (p1.x - p0.x);
                    q.y = p0.y + r * (p1.y - p0.y);
                    break;
                }
                acc += piece;
                ++seg;
            }
            w->ctrl[stored++] = q;
        }
        if (f + 1u < s->n_frag) {
            const bsf_point_t v = rel_point(s, b);
            w->ctrl[stored++] = v;
            w->ctrl[stored++] = v;
        }
    }
    w->ctrl[stored] = rel_point(s, s->n - 1u);
}

/* Span of t and its local coordinate (t in [0, 1]). */
static size_t span_of(float t, float fs, size_t n_span, float *u)
{
    const float x = t * fs;
    size_t span = (size_t)x;
    if (span >= n_span) {
        span = n_span - 1u;
    }
    *u = x - (float)span;
    return span;
}

/* One span evaluated at u, written around the middle control point:
 * C = P1 + b0 (P0 - P1) + b2 (P2 - P1), with the end-span factors k0, k2
 * (2 on a clamped end, else 1); the u-derivatives follow the same pattern.
 * This is the closed form of the design's Appendix with b1 = 1 - b0 - b2. */
typedef struct {
    float b0, b2;   /* basis of the outer control points (b1 = 1 - b0 - b2) */
    float cx, cy;   /* curve point */
    float ux, uy;   /* first u-derivative */
    float uux, uuy; /* second u-derivative */
} span_eval_t;

static void eval_span(const bsf_point_t *ctrl, size_t n_span, size_t span, float u, span_eval_t *e)
{
    const bsf_point_t *p = ctrl + span;
    const float k0 = span == 0u ? 1.0f : 0.5f;
    const float k2 = span + 1u == n_span ? 1.0f : 0.5f;
    const float v = 1.0f - u;
    const float ax = p[0].x - p[1].x;
    const float ay = p[0].y - p[1].y;
    const float bx = p[2].x - p[1].x;
    const float by = p[2].y - p[1].y;
    const float d0 = -2.0f * k0 * v;
    const float d2 = 2.0f * k2 * u;
    e->b0 = k0 * v * v;
    e->b2 = k2 * u * u;
    e->cx = p[1].x + e->b0 * ax + e->b2 * bx;
    e->cy = p[1].y + e->b0 * ay + e->b2 * by;
    e->ux = d0 * ax + d2 * bx;
    e->uy = d0 * ay + d2 * by;
    e->uux = 2.0f * (k0 * ax + k2 * bx);
    e->uuy = 2.0f * (k0 * ay + k2 * by);
}

/* Only the point and the basis of eval_span (after the last Newton step no
 * derivative is needed). */
static void eval_span_point(const bsf_point_t *ctrl, size_t n_span, size_t span, float u,
                            span_eval_t *e)
{
    const bsf_point_t *p = ctrl + span;
    const float k0 = span == 0u ? 1.0f : 0.5f;
    const float k2 = span + 1u == n_span ? 1.0f : 0.5f;
    const float v = 1.0f - u;
    e->b0 = k0 * v * v;
    e->b2 = k2 * u * u;
    e->cx = p[1].x + e->b0 * (p[0].x - p[1].x) + e->b2 * (p[2].x - p[1].x);
    e->cy = p[1].y + e->b0 * (p[0].y - p[1].y) + e->b2 * (p[2].y - p[1].y);
}

/* Add one point with basis (b0, 1 - b0 - b2, b2) on `span` to the normal
 * equations. The common case (three distinct unknowns) is written out; a
 * span touching a vertex goes through the general merge. */
static void accumulate_point(bsf_pdm_work_t *w, size_t span, float b0, float b2, float px,
                             float py)
{
    const uint8_t *unk = &w->unknown_of[span];
    const size_t a = unk[0];
    const float b1 = 1.0f - b0 - b2;
    float *r0 = &w->band[a * 3u];
    float *rx = &w->rhs_x[a];
    float *ry = &w->rhs_y[a];
    if (unk[1] != a && unk[2] != unk[1]) {
        /* Three distinct unknowns a, a + 1, a + 2 (rows of stride 3). */
        r0[0] += b0 * b0;
        r0[3] += b1 * b1;
        r0[4] += b1 * b0;
        r0[6] += b2 * b2;
        r0[7] += b2 * b1;
        r0[8] += b2 * b0;
        rx[0] += b0 * px;
        ry[0] += b0 * py;
        rx[1] += b1 * px;
        ry[1] += b1 * py;
        rx[2] += b2 * px;
        ry[2] += b2 * py;
    } else {
        /* A span at a vertex: its two copies share one unknown, so the span
         * touches two unknowns a, a + 1 with summed weights. */
        const float w0 = unk[1] == a ? b0 + b1 : b0;
        const float w1 = unk[1] == a ? b2 : b1 + b2;
        r0[0] += w0 * w0;
        r0[3] += w1 * w1;
        r0[4] += w1 * w0;
        rx[0] += w0 * px;
        ry[0] += w0 * py;
        rx[1] += w1 * px;
        ry[1] += w1 * py;
    }
}

static void clear_normal_equations(const pdm_state_t *s, bsf_pdm_work_t *w)
{
    memset(w->band, 0, s->n_unknown * 3u * sizeof w->band[0]);
    memset(w->rhs_x, 0, s->n_unknown * sizeof w->rhs_x[0]);
    memset(w->rhs_y, 0, s->n_unknown * sizeof w->rhs_y[0]);
}

/* Normal equations from the current parameters alone (after a layout change,
 * when no curve of the new layout exists yet). */
static void assemble(const pdm_state_t *s, bsf_pdm_work_t *w)
{
    const size_t n_span = s->n_ctrl - 2u;
    const float fs = (float)n_span;
    size_t i;
    clear_normal_equations(s, w);
    for (i = 0; i < s->n; ++i) {
        float u;
        const size_t span = span_of(w->t[i], fs, n_span, &u);
        const float k0 = span == 0u ? 1.0f : 0.5f;
        const float k2 = span + 1u == n_span ? 1.0f : 0.5f;
        const bsf_point_t q = rel_point(s, i);
        accumulate_point(w, span, k0 * (1.0f - u) * (1.0f - u), k2 * u * u, q.x, q.y);
    }
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
            float b[3];
            float du[3];
            float ddu[3];
            bsf_bspline_basis_u(n_span, k, 0.5f, b, du, ddu);
            bsf_fit_accumulate(w->band, NULL, NULL, &w->unknown_of[k], ddu, weight, 0.0f, 0.0f);
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

/* Step (b): footpoints for fixed control points, by at most `steps` Newton
 * steps per point from its current parameter (Gauss-Newton when curvature
 * makes Newton unsafe; a step is halved up to twice and only accepted when it
 * brings the curve closer, so no point's distance ever grows; a step may land
 * in the neighbouring span). The end points keep parameters 0 and 1: they
 * anchor the curve's ends, which would otherwise drift past the data. Fills
 * the RMS per fragment (a vertex point belongs to both its fragments) and
 * overall, and assembles the next normal equations at the new parameters in
 * the same sweep, so no basis is computed twice. */
static void footpoint_pass(pdm_state_t *s, bsf_pdm_work_t *w, unsigned steps)
{
    const size_t n_span = s->n_ctrl - 2u;
    const float fs = (float)n_span;
    const float inv_fs = 1.0f / fs;
    const size_t last = s->n - 1u;
    float total = 0.0f;
    float frag_sum = 0.0f;
    size_t f = 0;
    size_t i;

    clear_normal_equations(s, w);
    for (i = 0; i < s->n; ++i) {
        const bsf_point_t q = rel_point(s, i);
        const unsigned n_steps = (i == 0u || i == last) ? 0u : steps;
        span_eval_t e;
        float t = w->t[i];
        float u;
        size_t span = span_of(t, fs, n_span, &u);
        float best;
        unsigned step;

        eval_span(w->ctrl, n_span, span, u, &e);
        {
            const float ex = e.cx - q.x;
            const float ey = e.cy - q.y;
            best = ex * ex + ey * ey;
        }
        for (step = 0; step < n_steps; ++step) {
            const float ex = e.cx - q.x;
            const float ey = e.cy - q.y;
            const float g = ex * e.ux + ey * e.uy;
            const float gn = e.ux * e.ux + e.uy * e.uy;
            float h = gn + ex * e.uux + ey * e.uuy;
            float delta;
            float t_new = t;
            float d = best;
            unsigned halving;
            unsigned n_try;
            span_eval_t en = e;
            size_t span_new = span;

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
                float un;
                t_new = t + delta;
                t_new = t_new < 0.0f ? 0.0f : (t_new > 1.0f ? 1.0f : t_new);
                if (!(fabsf(t_new - t) > 1e-7f)) {
                    break;
                }
                span_new = span_of(t_new, fs, n_span, &un);
                if (step + 1u < n_steps) {
                    eval_span(w->ctrl, n_span, span_new, un, &en);
                } else {
                    eval_span_point(w->ctrl, n_span, span_new, un, &en);
                }
                {
                    const float fx = en.cx - q.x;
                    const float fy = en.cy - q.y;
                    d = fx * fx + fy * fy;
                }
                if (d < best) {
                    break;
                }
                delta *= 0.5f;
            }
            if (!(d < best)) {
                break;
            }
            best = d;
            t = t_new;
            span = span_new;
            e = en;
        }
        w->t[i] = t;
        accumulate_point(w, span, e.b0, e.b2, q.x, q.y);
        total += best;
        frag_sum += best;
        if (i == w->frag_last[f]) {
            const size_t count = (size_t)w->frag_last[f] - w->frag_first[f] + 1u;
            w->frag_rms[f] = sqrtf(frag_sum / (float)count);
            frag_sum = best; /* the vertex point opens the next fragment */
            if (f + 1u < s->n_frag) {
                ++f;
            }
        }
    }
    s->rms = sqrtf(total / (float)s->n);
}

/* Alternate (a) and (b) until the RMS stops improving by rel_tol. The normal
 * equations must be assembled at the current parameters on entry. The
 * bending term means a solve minimises RMS plus bending, so in rare cases an
 * iteration raises the RMS slightly: such an iteration is undone (parameters,
 * control points and fragment RMS restored) and ends the solve, so the
 * accepted RMS sequence never increases. */
static bsf_status_t run_pdm(pdm_state_t *s, bsf_pdm_work_t *w, const bsf_pdm_params_t *p,
                            size_t max_iterations, uint32_t *iterations)
{
    float prev = 0.0f;
    size_t it;

    w->n_history = 0u;
    for (it = 0; it < max_iterations; ++it) {
        bsf_status_t st;
        if (it > 0u) {
            memcpy(w->t_prev, w->t, s->n * sizeof w->t[0]);
            memcpy(w->ctrl_prev, w->ctrl, s->n_ctrl * sizeof w->ctrl[0]);
            memcpy(w->frag_rms_prev, w->frag_rms, s->n_frag * sizeof w->frag_rms[0]);
        }
        st = solve_control_points(s, w);
        if (st != BSF_OK) {
            return st;
        }
        footpoint_pass(s, w, p->footpoint_steps);
        ++*iterations;
        if (it > 0u && s->rms > prev) {
            memcpy(w->t, w->t_prev, s->n * sizeof w->t[0]);
            memcpy(w->ctrl, w->ctrl_prev, s->n_ctrl * sizeof w->ctrl[0]);
            memcpy(w->frag_rms, w->frag_rms_prev, s->n_frag * sizeof w->frag_rms[0]);
            s->rms = prev;
            break;
        }
        w->rms_history[w->n_history++] = s->rms;
        if (!(s->rms > 0.0f) || (it > 0u && prev - s->rms < p->rel_tol * prev)) {
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

/* Fragment to refine: the worst one above target that may still grow. */
static size_t pick_fragment(const pdm_state_t *s, const bsf_pdm_work_t *w, float target,
                            size_t max_ctrl)
{
    size_t best = NO_FRAGMENT;
    size_t f;
    if (s->n_ctrl + 1u > max_ctrl) {
        return NO_FRAGMENT;
    }
    for (f = 0; f < s->n_frag; ++f) {
        if (w->frag_rms[f] > target && w->frag_precision[f] < precision_cap(w, f) &&
            (best == NO_FRAGMENT || w->frag_rms[f] > w->frag_rms[best])) {
            best = f;
        }
    }
    return best;
}

/* Warm start after adding a precision point: every parameter keeps its
 * relative place inside its fragment's knot range. */
static void remap_parameters(const pdm_state_t *s, bsf_pdm_work_t *w, const float *old_t0,
                             const float *old_t1, const float *t0, const float *t1)
{
    size_t f = 0;
    size_t i;
    for (i = 0; i < s->n; ++i) {
        float t = w->t[i];
        while (f + 1u < s->n_frag && t > old_t1[f]) {
            ++f;
        }
        while (f > 0u && t < old_t0[f]) {
            --f;
        }
        t = t0[f] + (t - old_t0[f]) * (t1[f] - t0[f]) / (old_t1[f] - old_t0[f]);
        w->t[i] = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    }
}

static bsf_status_t check_vertices(const uint16_t *vertex_pos, size_t n_vertex, size_t n)
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
    bsf_pdm_params_t defaults;
    pdm_state_t s;
    bsf_pdm_info_t info;
    float t0[BSF_PDM_MAX_FRAGMENTS];
    float t1[BSF_PDM_MAX_FRAGMENTS];
    size_t max_ctrl;
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
    for (i = 1; i < n; ++i) {
        length += dist(pts[i - 1u], pts[i]);
    }
    if (!(length > 0.0f)) {
        return BSF_ERR_DEGENERATE;
    }

    memset(&s, 0, sizeof s);
    memset(&info, 0, sizeof info);
    s.pts = pts;
    s.n = n;
    s.origin = pts[0];
    s.n_frag = n_vertex + 1u;
    s.lambda = p->lambda_per_metre * length;
    max_ctrl = p->max_ctrl;

    /* Fragments and their starting precision points. */
    for (f = 0; f < s.n_frag; ++f) {
        const size_t a = f == 0u ? 0u : vertex_pos[f - 1u];
        const size_t b = f + 1u < s.n_frag ? vertex_pos[f] : n - 1u;
        size_t prec;
        work->frag_first[f] = (uint16_t)a;
        work->frag_last[f] = (uint16_t)b;
        if (p->refine) {
            /* Pieces that touch a vertex start straight. */
            prec = n_vertex == 0u ? 1u : 0u;
        } else {
            const float chord = dist(pts[a], pts[b]);
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
    init_fit(&s, work, t0, t1);
    /* The start curve follows the points with known parameters (see
     * init_fit): the first solve needs no projection onto it. */
    assemble(&s, work);
    st = run_pdm(&s, work, p, p->max_iterations, &info.iterations);
    if (st != BSF_OK) {
        return st;
    }

    while (p->refine) {
        float old_t0[BSF_PDM_MAX_FRAGMENTS];
        float old_t1[BSF_PDM_MAX_FRAGMENTS];
        const size_t pick = pick_fragment(&s, work, p->target_rms, max_ctrl);
        if (pick == NO_FRAGMENT) {
            break;
        }
        memcpy(old_t0, t0, s.n_frag * sizeof t0[0]);
        memcpy(old_t1, t1, s.n_frag * sizeof t1[0]);
        work->frag_precision[pick]++;
        work->last_refined = (uint16_t)pick;
        ++info.refinements;
        build_layout(&s, work, t0, t1);
        remap_parameters(&s, work, old_t0, old_t1, t0, t1);
        assemble(&s, work);
        st = run_pdm(&s, work, p, p->refine_iterations, &info.iterations);
        if (st != BSF_OK) {
            return st;
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
        length += dist(pts[i - 1u], pts[i]);
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
            acc += dist(pts[i - 1u], pts[i]);
        }
        work->t[i] = acc / length;
    }
    assemble(&s, work);
    st = run_pdm(&s, work, p, p->max_iterations, iterations);
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
