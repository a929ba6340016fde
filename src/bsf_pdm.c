/* PDM: point distance minimisation with boundary, vertex and precision
 * control points, and error-driven refinement (design brief section 7). */
#include "bsf/bsf_fit.h"
#include "bsf/bsf_bspline.h"
#include "bsf_fit_internal.h"
#include "bsf_linalg.h"

#include <math.h>
#include <string.h>

#define NO_FRAGMENT 0xFFFFu
/* Newton steps of the first projection onto the start curve. */
#define PDM_INIT_STEPS 6u

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
    p->max_iterations = 8u;
    p->max_ctrl = (uint16_t)BSF_MAX_CTRL_PER_FEATURE;
    p->footpoint_steps = 2u;
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
        !(p->target_rms > 0.0f && p->target_rms <= BSF_FIT_MAX_COORD) ||
        p->max_iterations < 1u || p->max_iterations > BSF_PDM_MAX_ITERATIONS ||
        p->max_ctrl < 3u || p->max_ctrl > BSF_MAX_CTRL_PER_FEATURE || p->footpoint_steps < 1u ||
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
 * arc-length fraction of the fragment's knot range; the caller then projects
 * it onto the start curve. */
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
            w->t[i] = t0[f] + (frac > 1.0f ? 1.0f : frac) * range;
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

/* Step (a): control points for fixed footpoint parameters. */
static bsf_status_t solve_control_points(pdm_state_t *s, bsf_pdm_work_t *w)
{
    const size_t m = s->n_unknown;
    const size_t n_span = s->n_ctrl - 2u;
    size_t i;
    size_t k;
    int loaded = 0;
    bsf_status_t st;

    memset(w->band, 0, m * 3u * sizeof w->band[0]);
    memset(w->rhs_x, 0, m * sizeof w->rhs_x[0]);
    memset(w->rhs_y, 0, m * sizeof w->rhs_y[0]);
    for (i = 0; i < s->n; ++i) {
        float b[3];
        float du[3];
        float ddu[3];
        float u;
        const size_t span = bsf_bspline_span(s->n_ctrl, w->t[i], &u);
        const bsf_point_t q = rel_point(s, i);
        bsf_bspline_basis_u(n_span, span, u, b, du, ddu);
        bsf_fit_accumulate(w->band, w->rhs_x, w->rhs_y, &w->unknown_of[span], b, 1.0f, q.x, q.y);
    }
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

/* Step (b): footpoints for fixed control points; fills the RMS per fragment
 * (a vertex point belongs to both of its fragments) and overall. */
static void update_footpoints(pdm_state_t *s, bsf_pdm_work_t *w, unsigned steps)
{
    const size_t last = s->n - 1u;
    float total = 0.0f;
    float frag_sum = 0.0f;
    size_t f = 0;
    size_t i;

    for (i = 0; i < s->n; ++i) {
        /* The end points keep their parameters 0 and 1: they anchor the curve's
         * ends, which would otherwise drift past (or short of) the data. */
        const unsigned n_steps = (i == 0u || i == last) ? 0u : steps;
        const float d = bsf_footpoint_refine(w->ctrl, s->n_ctrl, rel_point(s, i), &w->t[i], n_steps);
        total += d;
        frag_sum += d;
        if (i == w->frag_last[f]) {
            const size_t count = (size_t)w->frag_last[f] - w->frag_first[f] + 1u;
            w->frag_rms[f] = sqrtf(frag_sum / (float)count);
            frag_sum = d; /* the vertex point opens the next fragment */
            ++f;
            if (f >= s->n_frag) {
                break;
            }
        }
    }
    s->rms = sqrtf(total / (float)s->n);
}

/* Alternate (a) and (b) until the RMS stops improving by rel_tol. */
static bsf_status_t run_pdm(pdm_state_t *s, bsf_pdm_work_t *w, const bsf_pdm_params_t *p,
                            uint32_t *iterations)
{
    float prev = 0.0f;
    size_t it;

    w->n_history = 0u;
    for (it = 0; it < p->max_iterations; ++it) {
        const bsf_status_t st = solve_control_points(s, w);
        if (st != BSF_OK) {
            return st;
        }
        update_footpoints(s, w, p->footpoint_steps);
        w->rms_history[w->n_history++] = s->rms;
        ++*iterations;
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
    update_footpoints(&s, work, PDM_INIT_STEPS);
    st = run_pdm(&s, work, p, &info.iterations);
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
        st = run_pdm(&s, work, p, &info.iterations);
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
