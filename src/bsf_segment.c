/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_segment.h"
#include "bsf_compact.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "bsf_grazing.h"
#include "bsf_math.h"
#include "bsf_segment_internal.h"

#if BSF_CONFIG_SIMD && defined(__SSE2__)
#include <emmintrin.h>
/* Speed only, same marks: the mixed-pixel scan's first test on four beams
 * at once. */
#define SEG_SSE2 1
#endif

#define BSF_SEG_PI_F 3.14159265f

static int is_finite_f(float v)
{
    return bsf_finite_bits(v);
}

bsf_sved_params_t bsf_sved_params_paper(void)
{
    bsf_sved_params_t p;
    p.a = 0.2f;
    p.b = 0.07f;
    p.min_segment_points = 5u;
    p.max_gap_beams = 6u;
    p.radius_max = 0.0f;
    p.lookback = 0u;
    p.reject_mixed = 0u;
    p.join_grazing = 0u;
    return p;
}

bsf_sved_params_t bsf_sved_params_default(void)
{
    bsf_sved_params_t p = bsf_sved_params_paper();
    p.lookback = 4u;
    p.max_gap_beams = 16u;
    p.radius_max = 1.0f;
    p.reject_mixed = 1u;
    p.join_grazing = 1u;
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

/* a finite and positive, b finite (bsf_floats_in_range) */
static const bsf_float_range_t sved_float_ranges[] = {
    {FLT_MAX, (uint16_t)offsetof(bsf_sved_params_t, a), BSF_RANGE_LO_OPEN},
    {FLT_MAX, (uint16_t)offsetof(bsf_sved_params_t, b), 0u},
};

bsf_status_t bsf_sved_params_check(const bsf_sved_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (!bsf_floats_in_range(p, sved_float_ranges,
                             sizeof sved_float_ranges / sizeof sved_float_ranges[0]) ||
        !min_points_ok(p->min_segment_points) || p->max_gap_beams < 1u ||
        p->max_gap_beams > (uint16_t)BSF_MAX_POINTS || !is_finite_f(p->radius_max) ||
        !(p->radius_max == 0.0f || p->radius_max >= p->a) || p->lookback > BSF_SVED_MAX_LOOKBACK ||
        p->reject_mixed > 1u || p->join_grazing > 2u) {
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
static BSF_COMPACT_INLINE int sink_close(seg_sink_t *sink, size_t first, size_t last,
                                         size_t n_points)
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
static BSF_COMPACT_INLINE bsf_status_t begin(const bsf_points_t *pts, bsf_segment_t *out,
                                             size_t cap, size_t *n_out, size_t *n_wasted_points,
                                             seg_sink_t *sink)
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

/* ---- SVED with look-back, radius cap, mixed pixels and full-circle scans ---- */

/* One open segment of the labelled pass (24 bytes: moved often). */
typedef struct {
    uint32_t first;    /* beam of its first point (its label) */
    uint32_t last;     /* beam of its last point */
    uint32_t last_pos; /* pass position of its last point */
    uint32_t n;        /* points */
    bsf_point_t end;   /* its last point */
} open_seg_t;

/* open[0..k-1] moved up one slot, to open[1..k]. In the speed builds field
 * by field: as struct copies, GCC turns the loop into a memmove call, which
 * newlib-nano runs as a byte loop (about 4 instructions a byte on the
 * Cortex-M4F, about 1 % of its instructions on the Intel log). */
static void open_shift_up(open_seg_t *open, size_t k)
{
#if BSF_CONFIG_COMPACT
    memmove(&open[1], &open[0], k * sizeof open[0]);
#else
    for (; k > 0u; --k) {
        open[k].first = open[k - 1u].first;
        open[k].last = open[k - 1u].last;
        open[k].last_pos = open[k - 1u].last_pos;
        open[k].n = open[k - 1u].n;
        open[k].end.x = open[k - 1u].end.x;
        open[k].end.y = open[k - 1u].end.y;
    }
#endif
}

/* Radius test d^2 <= r(rho)^2, r = a*exp(b*rho) capped at sqrt(cap2) when
 * cap2 > 0. As in bsf_segment_sved, expf only near the threshold; NaN fails. */
static int within_radius(float d2, float rho, float a2, float two_b, float cap2)
{
    if (d2 <= a2) {
        return 1;
    }
    if (cap2 > 0.0f && !(d2 <= cap2)) {
        return 0;
    }
    return d2 <= a2 * bsf_exp_taylor4(two_b * rho) || d2 <= a2 * bsf_expf(two_b * rho);
}

/* within_radius for the tests of one beam (one rho), with the beam's
 * threshold worked out once, when a test first needs it. */
typedef struct {
    float a2;
    float two_b;
    float cap2;
    float rho;
    float lower; /* the threshold is >= lower ... */
    float upper; /* ... and <= upper; both valid when have_bounds */
    float limit; /* the threshold itself, valid when have_limit */
    int have_bounds;
    int have_limit;
} beam_radius_t;

static void beam_radius_start(beam_radius_t *r, float rho)
{
    r->rho = rho;
    r->have_bounds = 0;
    r->have_limit = 0;
}

/* The threshold max(a2 * taylor4(x), a2 * expf(x)), x = 2 b rho, or its
 * bounds: at least the first term and, for x in [0, 1], at most a2 * hi
 * (bsf_exp_bounds01), so expf is needed only for d2 between the two. */
static int beam_within_slow(beam_radius_t *r, float d2)
{
    const float x = r->two_b * r->rho;
#if BSF_CONFIG_COMPACT
    /* compact: the threshold itself, without the bounds that spare expf (same
     * answers: the bounds only decide early) */
    {
        const float lower = r->a2 * bsf_exp_taylor4(x);
        const float exact = r->a2 * bsf_expf(x);
        r->limit = lower > exact ? lower : exact;
        r->have_limit = 1;
    }
    return d2 <= r->limit;
#else
    if (!r->have_bounds) {
        r->lower = r->a2 * bsf_exp_taylor4(x);
        r->upper = HUGE_VALF; /* no upper bound */
        if (x >= 0.0f && x <= 1.0f) {
            float lo;
            float hi;
            bsf_exp_bounds01(x, &lo, &hi);
            r->upper = r->a2 * hi;
        }
        r->have_bounds = 1;
    }
    if (d2 <= r->lower) {
        return 1;
    }
    if (!(d2 <= r->upper)) {
        return 0;
    }
    {
        const float exact = r->a2 * bsf_expf(x);
        r->limit = r->lower > exact ? r->lower : exact;
        r->have_limit = 1;
    }
    return d2 <= r->limit;
#endif
}

/* Same answer as within_radius(d2, r->rho, ...): past a2 and inside the cap,
 * d2 <= A || d2 <= B is d2 <= max(A, B), and d2 <= cap2 && d2 <= M is
 * d2 <= min(cap2, M) (a NaN bound fails both forms). */
static inline int beam_within(beam_radius_t *r, float d2)
{
    if (d2 <= r->a2) {
        return 1;
    }
    if (r->cap2 > 0.0f && !(d2 <= r->cap2)) {
        return 0;
    }
    if (r->have_limit) {
        return d2 <= r->limit;
    }
    return beam_within_slow(r, d2);
}

/* Beam i + k (any sign) into *j, wrapping on a ring; 0 when that beam is
 * outside the scan or invalid. */
static int neighbour_beam(const bsf_points_t *pts, size_t i, long k, int ring, size_t *j)
{
    const long n = (long)pts->count;
    long m = (long)i + k;
    if (m < 0 || m >= n) {
        if (!ring || k <= -n || k >= n) {
            return 0;
        }
        m = m < 0 ? m + n : m - n;
    }
    if (!pts->valid[(size_t)m]) {
        return 0;
    }
    *j = (size_t)m;
    return 1;
}

/* Range of beam i + k into *r, as neighbour_beam finds it. */
static int neighbour_range(const bsf_points_t *pts, size_t i, int k, int ring, float *r)
{
    size_t j;
    if (!neighbour_beam(pts, i, (long)k, ring, &j)) {
        return 0;
    }
    *r = pts->range[j];
    return 1;
}

/* The "on neither surface" route of the mixed-pixel rule looks at up to
 * SEG_MIXED_WINDOW returns on each side of a beam, consecutive ones within
 * the segmentation radius of each other (one surface). It fits a line to
 * all of them but the nearest, so that the nearest can show whether the
 * surface reaches the beam unbroken; a side of fewer than SEG_MIXED_MIN_SIDE
 * such returns is too short to judge. */
#define SEG_MIXED_WINDOW 10
#define SEG_MIXED_MIN_SIDE 8

/* Squared noise floor of that route (3 mm: ranges quantised to a centimetre
 * scatter by about this much), so noise-free ranges do not make every
 * rounding error a mixed pixel. */
#define SEG_MIXED_FLOOR2 (0.003f * 0.003f)

/* How far off a side's line a return lies, in standard deviations of its
 * distance from that line extrapolated past the returns it was fitted to.
 * 4 leaves a real end return on its line but for a chance of about one in
 * 15 000 (more when a side's own scatter underestimates the noise). */
#define SEG_MIXED_SIGMAS2 16.0f

/* A return is no mixed pixel when the nearest return of the run it lies
 * off is off that run's line too, on the same side, by more than 1 /
 * SEG_MIXED_TURN of its own offset: the run may turn there (a short surface
 * of two or three returns between two walls, its first return too near the
 * turn to show it). A mixed pixel's neighbour scatters about the line. */
#define SEG_MIXED_TURN 4.0f

void bsf_side_fit(const bsf_point_t *w, bsf_side_line_t *l)
{
    float sxx = 0.0f;
    float sxy = 0.0f;
    float syy = 0.0f;
    float half_diff;
    float lam;
    float m;
    float spread;
    int k;
    l->cx = 0.0f;
    l->cy = 0.0f;
    for (k = 1; k < l->n; ++k) {
        l->cx += w[k].x;
        l->cy += w[k].y;
    }
    m = (float)(l->n - 1);
    l->cx /= m;
    l->cy /= m;
    for (k = 1; k < l->n; ++k) {
        const float dx = w[k].x - l->cx;
        const float dy = w[k].y - l->cy;
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    /* Smallest eigenvalue of the scatter matrix (the squared residual of the
     * best line) and its eigenvector (the line's normal). */
    half_diff = 0.5f * (sxx - syy);
    lam = 0.5f * (sxx + syy) - sqrtf(half_diff * half_diff + sxy * sxy);
    if (lam < 0.0f) {
        lam = 0.0f;
    }
    if (half_diff >= 0.0f) {
        l->nx = sxy; /* x spreads more: the normal is mostly along y */
        l->ny = lam - sxx;
    } else {
        l->nx = lam - syy;
        l->ny = sxy;
    }
    {
        const float len2 = l->nx * l->nx + l->ny * l->ny;
        if (!(len2 > 0.0f)) {
            /* an axis-aligned line: the normal is the axis of less spread */
            l->nx = half_diff >= 0.0f ? 0.0f : 1.0f;
            l->ny = half_diff >= 0.0f ? 1.0f : 0.0f;
        } else {
            const float inv = 1.0f / sqrtf(len2);
            l->nx *= inv;
            l->ny *= inv;
        }
    }
    l->var = lam / (m - 2.0f);
    /* Fitted returns at beam steps 2..n from beam i: a return's own noise,
     * the line's at its centroid and its slope's over the distance in steps
     * from the centroid (step (n + 2) / 2), spread = sum of squared steps. */
    spread = m * (m * m - 1.0f) / 12.0f;
    {
        const float t_i = 0.5f * (m + 3.0f);
        const float t_nr = t_i - 1.0f;
        l->reach_i = 1.0f + 1.0f / m + t_i * t_i / spread;
        l->reach_nr = 1.0f + 1.0f / m + t_nr * t_nr / spread;
    }
    l->d_near = bsf_side_distance(l, &w[0]);
}

/* The total least-squares line through the returns on side dir (-1: the
 * beams before i, +1: after) of beam i, all but the nearest; only l->n and
 * l->var (0) are set when there are fewer than SEG_MIXED_MIN_SIDE returns
 * (side_judged looks at n first). */
static void side_line(const bsf_points_t *pts, size_t i, int dir, int ring, beam_radius_t *rad,
                      bsf_side_line_t *l)
{
    bsf_point_t w[SEG_MIXED_WINDOW];
    int k;
    l->n = 0;
    l->var = 0.0f;
#if !BSF_CONFIG_COMPACT
    const int inside = i >= (size_t)SEG_MIXED_WINDOW && i + (size_t)SEG_MIXED_WINDOW < pts->count;
#endif
    for (k = 0; k < SEG_MIXED_WINDOW; ++k) {
        size_t j;
#if !BSF_CONFIG_COMPACT
        if (inside) {
            /* most beams: no wrap, only validity (neighbour_beam's answer;
             * the compact build keeps only the general path) */
            j = dir < 0 ? i - (size_t)(k + 1) : i + (size_t)(k + 1);
            if (!pts->valid[j]) {
                break;
            }
        } else if (!neighbour_beam(pts, i, (long)dir * (long)(k + 1), ring, &j)) {
            break;
        }
#else
        if (!neighbour_beam(pts, i, (long)dir * (long)(k + 1), ring, &j)) {
            break;
        }
#endif
        /* beam i's radius for every step (worked out once per beam) */
        if (l->n > 0) {
            const float dx = pts->pt[j].x - w[l->n - 1].x;
            const float dy = pts->pt[j].y - w[l->n - 1].y;
            if (!beam_within(rad, dx * dx + dy * dy)) {
                break; /* a depth jump: the surface ends */
            }
        }
        w[l->n] = pts->pt[j];
        l->n++;
    }
    if (l->n >= SEG_MIXED_MIN_SIDE) {
        bsf_side_fit(w, l);
    }
}

/* Beam i lies off side line l by more than the noise explains (variance
 * var), towards the sensor when toward_sensor, else away from it. */
static BSF_COMPACT_INLINE int off_side_line(const bsf_points_t *pts, size_t i,
                                            const bsf_side_line_t *l, float var, int toward_sensor)
{
    const float d = bsf_side_distance(l, &pts->pt[i]);
    float d_sensor;
    if (!(d * d > SEG_MIXED_SIGMAS2 * l->reach_i * var)) {
        return 0;
    }
    d_sensor = -(l->nx * l->cx + l->ny * l->cy); /* the sensor's side of the line */
    return toward_sensor ? (d > 0.0f) == (d_sensor > 0.0f) : (d > 0.0f) != (d_sensor > 0.0f);
}

/* The side's surface reaches the beam next to i unbroken: enough returns,
 * the nearest on the line of the others. */
static int side_judged(const bsf_side_line_t *l, float var)
{
    return l->n >= SEG_MIXED_MIN_SIDE &&
           l->d_near * l->d_near <= SEG_MIXED_SIGMAS2 * l->reach_nr * var;
}

/* Beam i, strictly between its neighbours in range at a depth jump, lies on
 * neither surface. The surface nearer to it in range (the one it would join)
 * must be a long straight run reaching beam i's neighbour unbroken, and beam
 * i must lie off its line towards the other surface, not as the second step
 * of a run turning away at that neighbour (the neighbour off the line too,
 * on the same side, by a quarter of beam i's offset: a short surface between
 * two walls). The other surface may be anything (a pillar, a small object):
 * beam i lies beyond the radius of its nearest return and does not go on
 * along a line through its next two (a wall seen at grazing incidence).
 * Where the other surface steps wider than the radius (a wall seen at
 * grazing incidence, or lone returns), one such line suffices: beam i
 * continuing the line through its next return and the one after is a
 * grazing wall's first return (or the last of one that ends on a corner)
 * and stays.
 * near_before: the surface before beam i is the nearer in range;
 * before_is_farther: it is farther from the sensor; other_wide: the other
 * surface's first step is wider than the radius. */
static int on_neither_surface(const bsf_points_t *pts, size_t i, int ring, beam_radius_t *rad,
                              int near_before, int before_is_farther, int other_wide)
{
    bsf_side_line_t near;
    float var;
    float d;
    size_t o[3] = {0u, 0u, 0u};
    int k;
    const int near_dir = near_before ? -1 : 1;
    /* the near run lies farther from the sensor than beam i exactly when
     * it is the before run and that is the farther one, or neither */
    const int near_is_farther = near_before == before_is_farther;
    /* The other side first: its tests are cheaper than the line fit. */
    for (k = 0; k < 3; ++k) {
        if (!neighbour_beam(pts, i, (long)(-near_dir) * (long)(k + 1), ring, &o[k])) {
            break;
        }
    }
    if (k == 0) {
        return 0;
    }
    {
        const float dx = pts->pt[o[0]].x - pts->pt[i].x;
        const float dy = pts->pt[o[0]].y - pts->pt[i].y;
        if (beam_within(rad, dx * dx + dy * dy)) {
            return 0;
        }
    }
    if (k >= 2 && bsf_grazing_triple(pts->pt, i, o[0], o[1]) &&
        (other_wide || (k == 3 && bsf_grazing_triple(pts->pt, o[0], o[1], o[2])))) {
        return 0;
    }
    side_line(pts, i, near_dir, ring, rad, &near);
    var = near.var > SEG_MIXED_FLOOR2 ? near.var : SEG_MIXED_FLOOR2;
    if (!side_judged(&near, var) || !off_side_line(pts, i, &near, var, near_is_farther)) {
        return 0;
    }
    d = bsf_side_distance(&near, &pts->pt[i]);
    return !((near.d_near > 0.0f) == (d > 0.0f) && SEG_MIXED_TURN * fabsf(near.d_near) > fabsf(d));
}

/* Returns on each side of a thin occluder that beside_thin_occluder fits a
 * line to: a surface seen on both sides of it is judged across it. */
#define SEG_THIN_SIDE 3

/* A blend floats: it lies off the surface's line towards the occluder by
 * more than 1 / SEG_THIN_FLOAT of the occluder's own offset, as in
 * mixed_kind's halfway test. A return closer to the surface than that
 * bends its curve little, and may be a real one. */
#define SEG_THIN_FLOAT 8.0f

/* Squared standard deviations beam i must lie off that line by: 5, not
 * SEG_MIXED_SIGMAS2's 4, as the line's scatter comes from as few as four
 * returns (two degrees of freedom) and may underestimate the noise. */
#define SEG_THIN_SIGMAS2 25.0f

/* Beams a and b lie within beam i's radius (rad) of each other. */
static int points_within(beam_radius_t *rad, const bsf_points_t *pts, size_t a, size_t b)
{
    const float dx = pts->pt[a].x - pts->pt[b].x;
    const float dy = pts->pt[a].y - pts->pt[b].y;
    return beam_within(rad, dx * dx + dy * dy);
}

/* Up to SEG_THIN_SIDE returns past beam `from` in direction dir, the first
 * wherever it lies, the others each within the radius of the one before,
 * appended to w at *n; how many. */
static int thin_side(const bsf_points_t *pts, size_t from, int dir, int ring, beam_radius_t *rad,
                     bsf_point_t *w, int *n)
{
    size_t j = from;
    size_t next;
    int k = 0;
    while (k < SEG_THIN_SIDE && neighbour_beam(pts, j, (long)dir, ring, &next) &&
           (k == 0 || points_within(rad, pts, j, next))) {
        j = next;
        w[(*n)++] = pts->pt[j];
        ++k;
    }
    return k;
}

/* Beam i, strictly between its neighbours in range, beside a thin occluder:
 * one or two returns nearer the sensor (a leg, a post) with the surface
 * behind seen again past them. Beam i lies off the line through that
 * surface's returns on both sides of the occluder, on the occluder's side,
 * by more than the noise explains: a blend of the occluder's range and the
 * surface's. A real return of the surface lies on that line; a surface that
 * turns behind the occluder leaves a residual that widens the bound. */
static int beside_thin_occluder(const bsf_points_t *pts, size_t i, int ring, beam_radius_t *rad,
                                int occluder_dir)
{
    bsf_point_t w[2 * SEG_THIN_SIDE + 1];
    bsf_side_line_t l;
    size_t first; /* the occluder's return next to beam i */
    size_t last;  /* its last */
    size_t far;   /* the surface behind, past the occluder */
    int k;
    float var;
    float d_occluder;
    /* beam i is no return of the occluder itself */
    if (!neighbour_beam(pts, i, (long)occluder_dir, ring, &first) ||
        points_within(rad, pts, i, first)) {
        return 0;
    }
    last = first;
    /* the occluder: one or two returns nearer than beam i; then the
     * surface behind, farther, beyond the radius of the occluder */
    for (k = 0;; ++k) {
        if (!neighbour_beam(pts, last, (long)occluder_dir, ring, &far)) {
            return 0;
        }
        if (pts->range[far] > pts->range[i]) {
            break;
        }
        if (k == 1 || pts->range[far] == pts->range[i]) {
            return 0;
        }
        last = far;
    }
    w[0] = pts->pt[i];
    l.n = 1;
    if (points_within(rad, pts, last, far) ||
        thin_side(pts, i, -occluder_dir, ring, rad, w, &l.n) < 2 ||
        thin_side(pts, last, occluder_dir, ring, rad, w, &l.n) < 2) {
        return 0;
    }
    bsf_side_fit(w, &l);
    var = l.var > SEG_MIXED_FLOOR2 ? l.var : SEG_MIXED_FLOOR2;
    d_occluder = bsf_side_distance(&l, &pts->pt[first]);
    return l.d_near * d_occluder > 0.0f &&
           l.d_near * l.d_near > SEG_THIN_SIGMAS2 * l.reach_i * var &&
           SEG_THIN_FLOAT * fabsf(l.d_near) > fabsf(d_occluder);
}

/* What is_mixed_pixel found: a return halfway between two flat surfaces,
 * or one off the line of a long run beside it (on_neither_surface). */
#define MIXED_BETWEEN 1
#define MIXED_OFF_A_LINE 2

/* Beam i, inside the scan (2 <= i < count - 2), and both its neighbours
 * valid, its range strictly between theirs: is_mixed_pixel's first tests.
 * r[0..3) receives the three ranges (when valid), *lo and *hi the
 * neighbours', the smaller first. */
static inline int between_neighbours(const bsf_points_t *pts, size_t i, float *r, float *lo,
                                     float *hi)
{
    const uint8_t *v = &pts->valid[i - 1u];
    if (!((v[0] != 0u) & (v[1] != 0u) & (v[2] != 0u))) {
        return 0;
    }
    r[0] = pts->range[i - 1u];
    r[1] = pts->range[i];
    r[2] = pts->range[i + 1u];
    *lo = r[0] < r[2] ? r[0] : r[2];
    *hi = r[0] < r[2] ? r[2] : r[0];
    return r[1] > *lo && r[1] < *hi;
}

/* is_mixed_pixel past its first tests: beam i's range r[2] lies strictly
 * between its neighbours' r[1] and r[3] (lo and hi, the smaller first), and
 * have_outer says whether r[0] and r[4] hold the next ones out. */
static int mixed_kind(const bsf_points_t *pts, size_t i, int ring, beam_radius_t *rad,
                      const float *r, float lo, float hi, int have_outer)
{
    const float jump = hi - lo;
    if (beam_within(rad, jump * jump)) {
        return 0;
    }
    if (have_outer && fabsf(r[1] - r[0]) < 0.25f * jump && fabsf(r[4] - r[3]) < 0.25f * jump &&
        r[2] - lo > 0.125f * jump && hi - r[2] > 0.125f * jump) {
        return MIXED_BETWEEN;
    }
    /* Near one surface in range: a mixed pixel only when it lies on neither.
     * The run nearer in range must go on past beam i's neighbour (steps
     * within the radius; on_neither_surface asks more of it); the other may
     * step wider (a wall seen at grazing incidence, whose lines
     * on_neither_surface keeps). */
    if (!have_outer) {
        return 0;
    }
    /* Either side may be nearer in range: the surface behind a thin
     * occluder is judged across it. */
    if (beside_thin_occluder(pts, i, ring, rad, r[1] == lo ? -1 : 1)) {
        return MIXED_OFF_A_LINE;
    }
    {
        const int near_before = r[2] - lo < hi - r[2] ? r[1] == lo : r[1] == hi;
        const float near_step = near_before ? r[1] - r[0] : r[4] - r[3];
        const float other_step = near_before ? r[4] - r[3] : r[1] - r[0];
        if (!beam_within(rad, near_step * near_step)) {
            return 0;
        }
        return on_neither_surface(pts, i, ring, rad, near_before, r[1] > r[2],
                                  !beam_within(rad, other_step * other_step))
                   ? MIXED_OFF_A_LINE
                   : 0;
    }
}

/* The mixed-pixel rule documented on bsf_segment_sved_labelled; rad holds
 * beam i's range. */
static int is_mixed_pixel(const bsf_points_t *pts, size_t i, int ring, beam_radius_t *rad)
{
    /* zeroed: r[0] and r[4] are read only when have_outer says they were
     * set, which some compilers cannot see */
    float r[5] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    float lo;
    float hi;
    int have_outer;
    int k;
    if (i >= 2u && i + 2u < pts->count) {
        /* Inside the scan (most beams): the cheap tests first. */
        const uint8_t *v = &pts->valid[i - 2u];
        const float *rg = &pts->range[i - 2u];
#if !BSF_CONFIG_COMPACT
        /* the jump within the radius's floor (below), on the ranges alone:
         * with either neighbour invalid the return is no mixed pixel either */
        const float step = rg[3] - rg[1];
        if (step * step <= rad->a2) {
            return 0;
        }
#endif
        if (!between_neighbours(pts, i, &r[1], &lo, &hi)) {
            return 0;
        }
        have_outer = (v[0] != 0u) & (v[4] != 0u);
        r[0] = rg[0];
        r[4] = rg[4];
    } else {
        for (k = -1; k <= 1; ++k) {
            if (!neighbour_range(pts, i, k, ring, &r[k + 2])) {
                return 0;
            }
        }
        lo = r[1] < r[3] ? r[1] : r[3];
        hi = r[1] < r[3] ? r[3] : r[1];
        if (!(r[2] > lo && r[2] < hi)) {
            return 0;
        }
        have_outer =
            neighbour_range(pts, i, -2, ring, &r[0]) && neighbour_range(pts, i, 2, ring, &r[4]);
    }
    return mixed_kind(pts, i, ring, rad, r, lo, hi, have_outer);
}

/* The radius test's constants for beam_within (the rest is each beam's,
 * from beam_radius_start on). */
static void beam_radius_init(beam_radius_t *rad, float a2, float two_b, float cap2)
{
    rad->a2 = a2;
    rad->two_b = two_b;
    rad->cap2 = cap2;
}

#if !BSF_CONFIG_COMPACT && !defined(SEG_SSE2)
/* Speed only, same marks (bsf_sved_mixed_marks, after beam b - 1 passed its
 * first test): the first beam from b on (2 <= b) that is valid and fails
 * that test (its neighbours' ranges differ by more than the radius's floor),
 * or max(b, count - 3); the beams before it, invalid or passing, the scan passes
 * over. Out of line, so the scan's own loop keeps its registers. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
static size_t
first_step_over(const bsf_points_t *pts, size_t b, float a2)
{
    const float *range = pts->range;
    const uint8_t *valid = pts->valid;
    const size_t stop = pts->count - 3u;
    while (b < stop) {
        if (valid[b]) {
            const float step = range[b + 1u] - range[b - 1u];
            if (!(step * step <= a2)) {
                break;
            }
        }
        ++b;
    }
    return b;
}
#endif

size_t bsf_sved_mixed_marks(const bsf_points_t *pts, const bsf_sved_params_t *p, uint8_t *marks,
                            uint16_t *off_line, size_t cap)
{
    const int ring = bsf_points_full_circle(pts);
    beam_radius_t rad;
    size_t n = 0;
    size_t b;
    beam_radius_init(&rad, p->a * p->a, 2.0f * p->b, p->radius_max * p->radius_max);
    if (marks != NULL) {
        memset(marks, 0, (pts->count + 7u) / 8u);
    }
    for (b = 0; b < pts->count; ++b) {
        int kind;
#ifdef SEG_SSE2
        /* Beams b..b + 3 whose neighbours' ranges differ by the radius's
         * floor or less (the first test below, valid or not) are passed
         * over together: 1 + how many lead[mask] beams of a run of them. */
        static const uint8_t lead[16] = {0, 1, 0, 2, 0, 1, 0, 3, 0, 1, 0, 2, 0, 1, 0, 4};
        if (b >= 2u && b + 6u <= pts->count) {
            const __m128 step =
                _mm_sub_ps(_mm_loadu_ps(&pts->range[b + 1u]), _mm_loadu_ps(&pts->range[b - 1u]));
            const size_t skip =
                lead[_mm_movemask_ps(_mm_cmple_ps(_mm_mul_ps(step, step), _mm_set1_ps(rad.a2)))];
            if (skip > 0u) {
                b += skip - 1u;
                continue;
            }
        }
#endif
        if (!pts->valid[b]) {
            continue;
        }
#if !BSF_CONFIG_COMPACT
        if (b >= 2u && b + 2u < pts->count) {
            /* is_mixed_pixel's first tests before its call (not in the
             * compact build, which keeps one copy): most returns lie on a
             * surface whose range changes by less than the radius's floor
             * from one neighbour to the other. That test first, on the
             * ranges alone: with both neighbours valid their difference is
             * the jump, and with either invalid the return is no mixed
             * pixel anyway. */
            const float step = pts->range[b + 1u] - pts->range[b - 1u];
            float r[5];
            float lo;
            float hi;
            if (step * step <= rad.a2 || !between_neighbours(pts, b, &r[1], &lo, &hi)) {
#ifndef SEG_SSE2
                if (step * step <= rad.a2) {
                    /* and on over the beams after it that pass too */
                    b = first_step_over(pts, b + 1u, rad.a2) - 1u;
                }
#endif
                continue;
            }
            /* and on with its other tests, where is_mixed_pixel goes on */
            r[0] = pts->range[b - 2u];
            r[4] = pts->range[b + 2u];
            beam_radius_start(&rad, r[2]);
            kind = mixed_kind(pts, b, ring, &rad, r, lo, hi,
                              (pts->valid[b - 2u] != 0u) & (pts->valid[b + 2u] != 0u));
        } else
#endif
        {
            beam_radius_start(&rad, pts->range[b]);
            kind = is_mixed_pixel(pts, b, ring, &rad);
        }
        if (kind != 0 && marks != NULL) {
            marks[b / 8u] = (uint8_t)(marks[b / 8u] | (1u << (b % 8u)));
        }
        if (kind == MIXED_OFF_A_LINE && n < cap) {
            off_line[n++] = (uint16_t)b;
        }
    }
    return n;
}

/* Output order: by first beam, a segment wrapping through the seam last. */
static uint32_t beam_order_key(const bsf_segment_t *s)
{
    return (s->first > s->last ? 0x10000u : 0u) + (uint32_t)s->first;
}

/* Next beam after b on the pass (wrapping at count). */
static size_t next_beam(size_t b, size_t count)
{
    return b + 1u < count ? b + 1u : 0u;
}

/* Close an open segment: keep it or waste it (and unlabel its beams). */
static int close_open(seg_sink_t *sink, const open_seg_t *s, uint16_t *label, size_t count)
{
    if (s->n < (size_t)sink->min_points && label != NULL) {
        size_t b = s->first;
        for (;;) {
            if (label[b] == (uint16_t)s->first) {
                label[b] = (uint16_t)BSF_SEG_NONE;
            }
            if (b == s->last) {
                break;
            }
            b = next_beam(b, count);
        }
    }
    return sink_close(sink, s->first, s->last, s->n);
}

/* Beam where a full-circle pass starts: the first valid beam (from 0) that
 * the paper's rule would not join to the valid beam before it on the ring;
 * 0 when every step joins (one closed loop: then nothing wraps). */
static size_t ring_start(const bsf_points_t *pts, float a2, float two_b, float cap2)
{
    size_t prev = bsf_last_valid_beam(pts);
#if !BSF_CONFIG_COMPACT
    const size_t end = prev;
#endif
    size_t i;
    if (prev == pts->count) {
        return 0u;
    }
    for (i = 0; i < pts->count; ++i) {
        float dx;
        float dy;
#if !BSF_CONFIG_COMPACT
        /* the beams before the last one within the radius's floor of the
         * one before (within_radius' first test) join without the test */
        i = bsf_join_near_beams(pts, i, end, a2, &prev);
#endif
        if (!pts->valid[i]) {
            continue;
        }
        dx = pts->pt[i].x - pts->pt[prev].x;
        dy = pts->pt[i].y - pts->pt[prev].y;
        if (i != prev && !within_radius(dx * dx + dy * dy, pts->range[i], a2, two_b, cap2)) {
            return i;
        }
        prev = i;
    }
    return 0u;
}

#if !BSF_CONFIG_COMPACT && !defined(SEG_SSE2)
/* Speed only, same segments (sved_run with one open segment o, which beam b,
 * at pass position j, just extended: no end to search, none to expire): the
 * beams after b up to beam cend (before the pass's end and the scan's), each
 * valid, not marked mixed (marks NULL: none is) and within the radius's
 * floor of the segment's end, continue it as sved_run's steps would; an
 * invalid beam is passed over as there. Returns how many beams it took
 * (up to the last one joined). Out of line, so sved_run's own loop keeps
 * its registers. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
static size_t
sved_continue(const bsf_points_t *pts, const uint8_t *marks, uint16_t *label, open_seg_t *o,
              size_t b, size_t cend, float a2, size_t j)
{
    const uint8_t *valid = pts->valid;
    const bsf_point_t *pt = pts->pt;
    const uint16_t first = (uint16_t)o->first;
    bsf_point_t end = o->end;
    size_t n_more = 0u;
    size_t last = b;
    size_t c;
    for (c = b + 1u; c <= cend; ++c) {
        float dx;
        float dy;
        if (!valid[c]) {
            continue;
        }
        if (marks != NULL && ((marks[c / 8u] >> (c % 8u)) & 1u) != 0u) {
            break;
        }
        dx = pt[c].x - end.x;
        dy = pt[c].y - end.y;
        if (!(dx * dx + dy * dy <= a2)) {
            break;
        }
        end = pt[c];
        last = c;
        ++n_more;
        if (label != NULL) {
            label[c] = first;
        }
    }
    if (n_more > 0u) {
        o->last = (uint32_t)last;
        o->last_pos = (uint32_t)(j + (last - b));
        o->n += (uint32_t)n_more;
        o->end = end;
    }
    return last - b;
}
#endif

/* Both SVED entry points: with extensions 0, the paper's rule whatever the
 * extension fields say (checked, then ignored), and no full-circle pass. */
static bsf_status_t sved_run(const bsf_points_t *pts, const bsf_sved_params_t *params,
                             bsf_segment_t *out, size_t cap, uint16_t *label, int extensions,
                             const uint8_t *marks, uint8_t *grazing_memo, size_t *n_out,
                             size_t *n_wasted_points)
{
    const bsf_sved_params_t defaults = bsf_sved_params_default();
    const bsf_sved_params_t *p = params != NULL ? params : &defaults;
    open_seg_t open[1u + BSF_SVED_MAX_LOOKBACK];
    seg_sink_t sink;
    bsf_status_t st;
    size_t slots;
    size_t n_open = 0;
    size_t start = 0;
    size_t j;
    size_t k;
    float a2;
    float two_b;
    float cap2;
    beam_radius_t rad;
    int reject_mixed;
    int grazing;
    int ring;
#if !BSF_CONFIG_COMPACT && !defined(SEG_SSE2)
    size_t one_open;
#endif

    st = begin(pts, out, cap, n_out, n_wasted_points, &sink);
    if (st != BSF_OK) {
        return st;
    }
    st = bsf_sved_params_check(p);
    if (st != BSF_OK) {
        return BSF_ERR_PARAM;
    }
    sink.min_points = p->min_segment_points;
    a2 = p->a * p->a;
    two_b = 2.0f * p->b;
    cap2 = extensions ? p->radius_max * p->radius_max : 0.0f;
    slots = extensions ? 1u + (size_t)p->lookback : 1u;
    reject_mixed = extensions && p->reject_mixed;
    grazing = extensions && p->join_grazing && p->radius_max > 0.0f;
    ring = extensions && bsf_points_full_circle(pts);
    beam_radius_init(&rad, a2, two_b, cap2);
    if (label != NULL) {
        for (j = 0; j < pts->count; ++j) {
            label[j] = (uint16_t)BSF_SEG_NONE;
        }
    }
    if (ring) {
        start = ring_start(pts, a2, two_b, cap2);
    }
#if !BSF_CONFIG_COMPACT && !defined(SEG_SSE2)
    /* sved_continue serves one open segment, and mixed pixels only marked
     * (else 0: n_open is never 0 there) */
    one_open = !reject_mixed || marks != NULL ? 1u : 0u;
#endif

    for (j = 0; j < pts->count; ++j) {
        size_t b = start + j;
        bsf_point_t q;
        float rho;
        float best_d2 = HUGE_VALF;
        size_t best = slots; /* none */
        if (b >= pts->count) {
            b -= pts->count;
        }
#ifdef SEG_SSE2
        /* Speed only, same segments: with one open segment, whose last beam
         * is b - 1, the next four beams (valid, not marked mixed) each within
         * the radius's floor of the one before continue it as below, tested
         * at once. */
        if (n_open == 1u && open[0].last + 1u == b && b + 4u <= pts->count &&
            j + 4u <= pts->count &&
            (!reject_mixed ||
             (marks != NULL &&
              /* the marks of beams b..b + 3, in one byte or two (both in the scan) */
              (((unsigned)marks[b / 8u] | (unsigned)marks[(b + 3u) / 8u] << 8) >> (b % 8u) & 15u) ==
                  0u))) {
            if (bsf_four_steps_within(pts, b, a2)) {
                open[0].last = (uint32_t)(b + 3u);
                open[0].last_pos = (uint32_t)(j + 3u);
                open[0].n += 4u;
                open[0].end = pts->pt[b + 3u];
                if (label != NULL) {
                    label[b] = label[b + 1u] = label[b + 2u] = label[b + 3u] =
                        (uint16_t)open[0].first;
                }
                j += 3u;
                continue;
            }
        }
#endif
        if (!pts->valid[b]) {
            continue; /* an invalid beam never breaks a segment by itself */
        }
        rho = pts->range[b];
        beam_radius_start(&rad, rho);
        if (reject_mixed && (marks != NULL ? (marks[b / 8u] >> (b % 8u)) & 1u
                                           : (unsigned)is_mixed_pixel(pts, b, ring, &rad))) {
            sink.n_wasted++;
            continue;
        }
        q = pts->pt[b];
        /* open[0] is the current segment (the paper's only candidate); older
         * ones expire once their last point is more than max_gap_beams back.
         * The list is most recently extended first, so last_pos falls along
         * it and the expired ones are a tail, closed first to last. */
        if (n_open > 1u && j - open[n_open - 1u].last_pos > (size_t)p->max_gap_beams) {
            size_t keep_n = n_open - 1u;
            while (keep_n > 1u && j - open[keep_n - 1u].last_pos > (size_t)p->max_gap_beams) {
                --keep_n;
            }
            for (k = keep_n; k < n_open; ++k) {
                if (!close_open(&sink, &open[k], label, pts->count)) {
                    return BSF_ERR_CAPACITY;
                }
            }
            n_open = keep_n;
        }
        for (k = 0; k < n_open; ++k) {
            float dx;
            float dy;
            float d2;
            dx = q.x - open[k].end.x;
            dy = q.y - open[k].end.y;
            d2 = dx * dx + dy * dy;
            if (d2 < best_d2) { /* NaN and +inf never are */
                best = k;
                best_d2 = d2;
            }
        }
        if (best == slots) {
            /* Only +inf or NaN distances (points at infinity): an infinite
             * one may still pass an infinite radius. */
            for (k = 0; k < n_open; ++k) {
                const float dx = q.x - open[k].end.x;
                const float dy = q.y - open[k].end.y;
                if (dx * dx + dy * dy == HUGE_VALF) {
                    best = k;
                    break;
                }
            }
        }
        /* The radius test is a bound on d2 (a smaller d2 passes whenever a
         * larger one does), so the nearest end, first of equals, is the one
         * the nearest passing end would be, or none passes. NaN never does. */
        if (best < slots && !beam_within(&rad, best_d2)) {
            best = slots;
        }
        /* A wide step from the beam before may still continue a wall seen
         * at grazing incidence (bsf_grazing.h). */
        if (best == slots && grazing && n_open > 0u && b > 0u && open[0].last + 1u == b &&
            bsf_grazing_join(pts, b - 1u, p->radius_max, p->join_grazing == 2u, grazing_memo)) {
            best = 0u;
        }
        /* The segment beam b joins goes first (best == 0: the current one,
         * most beams), or a new one starts there; then b extends it. */
        if (best == slots) {
            if (n_open == slots) {
                if (!close_open(&sink, &open[n_open - 1u], label, pts->count)) {
                    return BSF_ERR_CAPACITY;
                }
                --n_open;
            }
            open_shift_up(open, n_open);
            open[0].first = (uint32_t)b;
            open[0].n = 0u;
            ++n_open;
        } else if (best > 0u) {
            const open_seg_t s = open[best];
            open_shift_up(open, best);
            open[0] = s;
        }
        open[0].last = (uint32_t)b;
        open[0].last_pos = (uint32_t)j;
        open[0].n++;
        open[0].end = q;
        if (label != NULL) {
            label[b] = (uint16_t)open[0].first;
        }
#if !BSF_CONFIG_COMPACT && !defined(SEG_SSE2)
        if (n_open == one_open) {
            /* the beams passed over are steps the loop would only skip
             * (invalid ones after the last joined are left to the loop) */
            j += sved_continue(pts, reject_mixed ? marks : NULL, label, &open[0], b,
                               b + (pts->count - 1u - (j > b ? j : b)), a2, j);
        }
#endif
    }
    /* Close the rest, oldest first. */
    while (n_open > 0u) {
        --n_open;
        if (!close_open(&sink, &open[n_open], label, pts->count)) {
            return BSF_ERR_CAPACITY;
        }
    }
    /* Kept segments by first beam, one wrapping through the seam last
     * (closing order is nearly that already). */
    for (j = 1; j < sink.n_out; ++j) {
        const bsf_segment_t s = sink.out[j];
        k = j;
        while (k > 0u && beam_order_key(&sink.out[k - 1u]) > beam_order_key(&s)) {
            sink.out[k] = sink.out[k - 1u];
            --k;
        }
        sink.out[k] = s;
    }
    return finish(&sink, n_out, n_wasted_points);
}

bsf_status_t bsf_segment_sved(const bsf_points_t *pts, const bsf_sved_params_t *params,
                              bsf_segment_t *out, size_t cap, size_t *n_out,
                              size_t *n_wasted_points)
{
    return sved_run(pts, params, out, cap, NULL, 0, NULL, NULL, n_out, n_wasted_points);
}

bsf_status_t bsf_segment_sved_labelled(const bsf_points_t *pts, const bsf_sved_params_t *params,
                                       bsf_segment_t *out, size_t cap, uint16_t *label,
                                       size_t *n_out, size_t *n_wasted_points)
{
    return sved_run(pts, params, out, cap, label, 1, NULL, NULL, n_out, n_wasted_points);
}

bsf_status_t bsf_segment_sved_marked(const bsf_points_t *pts, const bsf_sved_params_t *params,
                                     bsf_segment_t *out, size_t cap, uint16_t *label,
                                     const uint8_t *marks, uint8_t *grazing_memo, size_t *n_out)
{
    return sved_run(pts, params, out, cap, label, 1, marks, grazing_memo, n_out, NULL);
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

/* Is beam b a point of the segment whose first beam is first? */
static int is_member(const bsf_points_t *pts, const uint16_t *label, size_t b, size_t first)
{
    return label != NULL ? label[b] == (uint16_t)first : pts->valid[b] != 0u;
}

/* Interest beams among beams from..to (ascending, no seam) that are members. */
static size_t interest_members_in(const bsf_points_t *pts, const uint16_t *label, size_t first,
                                  const uint16_t *interest, size_t n_interest, size_t from,
                                  size_t to)
{
    size_t c = 0;
    size_t j = from > 0u ? upper_bound(interest, n_interest, from - 1u) : 0u;
    for (; j < n_interest && (size_t)interest[j] <= to; ++j) {
        c += (size_t)is_member(pts, label, interest[j], first);
    }
    return c;
}

/* Inner interest points of the segment first..last (walking on through beam
 * 0 when first > last): interest beams among its members, not among the
 * first two members or the last two. Those lie strictly between the second
 * member from either end, so only the ends are walked. */
static size_t inner_interest(const bsf_points_t *pts, const uint16_t *label, size_t first,
                             size_t last, const uint16_t *interest, size_t n_interest)
{
    const size_t count = pts->count;
    size_t seen = 0;
    size_t lo = first; /* the second member from the start */
    size_t hi = last;  /* the second member from the end */
    size_t off_lo;
    size_t off_hi;
    for (;;) {
        if (is_member(pts, label, lo, first) && ++seen == 2u) {
            break;
        }
        if (lo == last) {
            return 0u;
        }
        lo = next_beam(lo, count);
    }
    seen = 0;
    for (;;) {
        if (is_member(pts, label, hi, first) && ++seen == 2u) {
            break;
        }
        if (hi == first) {
            return 0u;
        }
        hi = hi > 0u ? hi - 1u : count - 1u;
    }
    off_lo = lo >= first ? lo - first : lo + count - first;
    off_hi = hi >= first ? hi - first : hi + count - first;
    if (off_lo + 1u >= off_hi) {
        return 0u;
    }
    if (lo < hi) {
        return interest_members_in(pts, label, first, interest, n_interest, lo + 1u, hi - 1u);
    }
    /* through the seam */
    return interest_members_in(pts, label, first, interest, n_interest, lo + 1u, count - 1u) +
           (hi > 0u ? interest_members_in(pts, label, first, interest, n_interest, 0u, hi - 1u)
                    : 0u);
}

bsf_status_t bsf_segment_classify_labelled(bsf_segment_t *segs, size_t n, const bsf_points_t *pts,
                                           const uint16_t *label, const uint16_t *interest_beams,
                                           size_t n_interest)
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
        if ((size_t)segs[k].first >= pts->count || (size_t)segs[k].last >= pts->count) {
            return BSF_ERR_ARG;
        }
    }
    for (k = 0; k < n; ++k) {
        bsf_segment_t *s = &segs[k];
        const size_t count =
            inner_interest(pts, label, s->first, s->last, interest_beams, n_interest);
        s->n_interest = (uint8_t)(count > 255u ? 255u : count);
        s->kind = (uint8_t)(count > 0u ? BSF_FEATURE_AUXILIARY : BSF_FEATURE_BLEAK);
    }
    return BSF_OK;
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
    for (k = 0; k < n; ++k) {
        if (segs[k].first > segs[k].last) {
            return BSF_ERR_ARG; /* no wrapping segments here */
        }
    }
    return bsf_segment_classify_labelled(segs, n, pts, NULL, interest_beams, n_interest);
}
