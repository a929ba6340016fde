/* SPDX-License-Identifier: MIT */
/*
 * FALKO keypoints, following FALKOLib's FALKOExtractor::extract step by step
 * (docs/DESIGN.md, "Methods"), in float and in caller-owned memory.
 *
 * Float versus the reference's double. The decisions that pick keypoints are
 * comparisons: neighbour distance <= r, the triangle base and height against
 * r / b_ratio, the sector floor((angle + pi - theta) / (2 pi / S)), the
 * integer score threshold and the NMS window floor(asin(R / rho) / dtheta).
 *  - The score threshold is exact here: int(scoreMax * th / 100.0) equals
 *    the integer quotient scoreMax * th / 100 for integer th, and raw scores
 *    below 2^24 are exact in float.
 *  - The neighbourhood window alpha = floor(asin(r / rho) / dtheta) cannot
 *    change a result: a beam more than asin(r / rho) from the apex is farther
 *    than r from it (distance >= rho sin(angle)), so the distance test
 *    rejects it anyway. This port uses a cheaper upper bound for alpha.
 *  - The others flip only when the double value lies within float rounding
 *    (about 1e-6 relative here) of the boundary. Ranges are cm-quantised but
 *    r = a exp(b rho) is transcendental, so exact ties do not occur; near
 *    ties are rare. Counted in double over both Intel logs (2672 + 910 scans,
 *    5.8 million distance tests): no distance or triangle test within 1e-6
 *    (relative) of its boundary, and 3 of 91 864 sector values within 1e-5
 *    sector of a boundary (none exactly on it). None of them changes a
 *    keypoint: the port gives the reference's keypoint beam indices on
 *    100 % of the scans (test/system/test_falko_ref.c).
 * Where the reference reads one point past the end of the scan (its window
 * runs to i + alpha + 1 <= numBeams inclusive), this port clamps to the scan.
 *
 * Speed: the radius and window of every beam are computed first in a loop
 * without hard branches, so the exp and division latencies of successive
 * beams overlap; each apex then runs the cheap tests first (outermost
 * neighbours on each side, then the triangle test), and only the few that
 * pass count their neighbours (listing them for the sectors, computed with
 * atan2f). All rejections are alike in the reference (score -10), so the
 * order of the tests does not change any result. Suppression runs only when
 * some strength can pass its threshold.
 */
#include "bsf/bsf_falko.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "bsf_math.h"
#include "bsf_nms.h"

#if BSF_CONFIG_SIMD && defined(__SSE2__)
#include <emmintrin.h>
#define FALKO_SSE2_WALKS 1
/* Windows this wide (at least 3: see certainly_rejected_inside) walk four
 * beams per step; on narrower ones the ends are a beam or two in. */
#define FALKO_WIDE_WINDOW 12u
#endif

#define FALKO_PI 3.14159265358979f
/* FALKOLib clamps atan2 results to just inside +-pi (by 1e-6 rad). */
#define FALKO_ANGLE_LIMIT (FALKO_PI - 0.000001f)
/* Scores are kept in float: integers up to 2^24 are exact. */
#define FALKO_SCORE_LIMIT 16777216L
#define FALKO_REJECTED (-1.0f)

bsf_falko_params_t bsf_falko_params_default(void)
{
    bsf_falko_params_t p;
    p.min_score_th = 50;
    p.min_range = 0.0f;
    p.max_range = 30.0f;
    p.subbeam = 1;
    p.nms_radius = 0.1f;
    p.neigh_a = 0.1f;
    p.neigh_b = 0.07f;
    p.neigh_min_points = 2;
    p.b_ratio = 2.5f;
    p.grid_sectors = 16;
    p.circular_sector_distance = 0;
    return p;
}

static int finite_f(float v)
{
    return bsf_finite_bits(v);
}

bsf_status_t bsf_falko_params_check(const bsf_falko_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    if (p->min_score_th < 0 || p->min_score_th > 100 || !finite_f(p->min_range) ||
        p->min_range < 0.0f || !finite_f(p->max_range) || !(p->max_range > p->min_range) ||
        !finite_f(p->nms_radius) || p->nms_radius < 0.0f || !finite_f(p->neigh_a) ||
        !(p->neigh_a > 0.0f) || !finite_f(p->neigh_b) || p->neigh_b < 0.0f ||
        p->neigh_min_points < 1 || !finite_f(p->b_ratio) || !(p->b_ratio > 0.0f) ||
        p->grid_sectors < 2 || p->grid_sectors > 64) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

/* Neighbourhood radius of a beam at range rho (step 2). */
static float neigh_radius(const bsf_falko_params_t *p, float rho)
{
    const float r = p->neigh_a * bsf_expf(p->neigh_b * rho);
    return (r >= rho) ? 0.8f * rho : r;
}

/* The disc of radius r around an apex c, with the squared-distance band
 * outside which the test sqrtf(d2) <= r is decided without sqrtf: below
 * lo it is certainly true, above hi certainly false (the band is wider than
 * the rounding of sqrtf and of r * r), so results equal the sqrtf test. */
typedef struct {
    bsf_point_t c;
    float r;
    float lo;
    float hi;
} ball_t;

static ball_t make_ball(bsf_point_t c, float r)
{
    ball_t b;
    const float r2 = r * r;
    b.c = c;
    b.r = r;
    b.lo = r2 * (1.0f - 1e-6f);
    b.hi = r2 * (1.0f + 1e-6f);
    return b;
}

/* Window positions are virtual beam indices: on a full-circle scan a window
 * may run past either end of the scan and continues at the other end (it
 * spans less than the whole circle); elsewhere it is clamped to the scan, so
 * every position is a beam index and results are FALKOLib's. */
static size_t beam_at(const bsf_points_t *pts, ptrdiff_t v)
{
    if (v < 0) {
        return (size_t)(v + (ptrdiff_t)pts->count);
    }
    if (v >= (ptrdiff_t)pts->count) {
        return (size_t)(v - (ptrdiff_t)pts->count);
    }
    return (size_t)v;
}

/* Is window position v a neighbour: valid and within distance r of the apex
 * (step 3)? */
static int in_ball(const bsf_points_t *pts, ptrdiff_t v, const ball_t *b)
{
    const size_t j = beam_at(pts, v);
    float dx, dy, d2;
    if (!pts->valid[j]) {
        return 0;
    }
    dx = b->c.x - pts->pt[j].x;
    dy = b->c.y - pts->pt[j].y;
    d2 = dx * dx + dy * dy;
    if (d2 <= b->lo) {
        return 1;
    }
    if (d2 > b->hi) {
        return 0;
    }
    return sqrtf(d2) <= b->r;
}

/* A neighbourhood (steps 3, 4 and 6). */
typedef struct {
    ptrdiff_t beg, end;                   /* window positions, inclusive (see beam_at) */
    ptrdiff_t first;                      /* first kept position (left of the apex) */
    ptrdiff_t last;                       /* last kept position (right of the apex) */
    int n_left;                           /* kept neighbours before the apex */
    int n_right;                          /* kept neighbours after the apex */
    float sum_lx, sum_ly, sum_rx, sum_ry; /* sums of p - p_apex per side */
} neigh_t;

/* The reference's beam window is [i - alpha, i + alpha + 1] with
 * alpha = floor(asin(r / rho) / inc) (and it reads one element past the end
 * of the scan there). Any window holding the beams within asin(r / rho) of
 * the apex gives the same neighbours: a beam at angle phi from the apex is at
 * least rho sin(phi) > r away when phi > asin(r / rho); that also makes the
 * reference's extra right beam irrelevant. So this window is [i - A, i + A],
 * clamped to the scan, with A >= alpha from a bound that costs one division,
 * asin(s) <= s / sqrt(1 - s^2) <= s / (1 - s^2) = r rho / (rho^2 - r^2)
 * (r <= 0.8 rho keeps the denominator positive), with a rounding margin. */
static float window_alpha_f(float rho, float r, float inv_inc)
{
    return r * rho / (rho * rho - r * r) * inv_inc * (1.0f + 1e-5f);
}

static size_t window_clamp(float a)
{
    /* a >= 0; BSF_MAX_POINTS fits int, and int conversion is one instruction */
    return (a < (float)BSF_MAX_POINTS) ? (size_t)(int)a : (size_t)BSF_MAX_POINTS;
}

static size_t window_alpha(const bsf_points_t *pts, size_t i, float r, float inv_inc)
{
    return window_clamp(window_alpha_f(pts->range[i], r, inv_inc));
}

static void neigh_window(const bsf_points_t *pts, size_t i, size_t alpha, int ring, neigh_t *nb)
{
    if (ring) {
        /* Wraps, but never reaches round to the apex's other side. */
        const size_t half = (pts->count - 1u) / 2u;
        const size_t a = alpha < half ? alpha : half;
        nb->beg = (ptrdiff_t)i - (ptrdiff_t)a;
        nb->end = (ptrdiff_t)i + (ptrdiff_t)a;
        return;
    }
    nb->beg = (ptrdiff_t)((i >= alpha) ? i - alpha : 0u);
    nb->end = (ptrdiff_t)((i + alpha < pts->count) ? i + alpha : pts->count - 1u);
}

/* The outermost neighbours on each side; 0 when a side has none. */
static int find_ends(const bsf_points_t *pts, ptrdiff_t i, const ball_t *b, neigh_t *nb)
{
    ptrdiff_t j = nb->beg;
    while (j < i && !in_ball(pts, j, b)) {
        ++j;
    }
    if (j == i) {
        return 0;
    }
    nb->first = j;
    j = nb->end;
    while (j > i && !in_ball(pts, j, b)) {
        --j;
    }
    if (j == i) {
        return 0;
    }
    nb->last = j;
    return 1;
}

/* Counts and sums of both sides, between the ends found by find_ends; when
 * list is not NULL, the neighbours' beams too, left ones then right ones,
 * each side in scan order (corner_score's order). */
static void count_sides(const bsf_points_t *pts, ptrdiff_t i, const ball_t *b, neigh_t *nb,
                        uint16_t *list)
{
    const bsf_point_t c = b->c;
    ptrdiff_t j;
    int k = 0;
    nb->n_left = 0;
    nb->n_right = 0;
    nb->sum_lx = 0.0f;
    nb->sum_ly = 0.0f;
    nb->sum_rx = 0.0f;
    nb->sum_ry = 0.0f;
    for (j = nb->first; j < i; ++j) {
        if (in_ball(pts, j, b)) {
            const size_t q_beam = beam_at(pts, j);
            const bsf_point_t q = pts->pt[q_beam];
            ++nb->n_left;
            nb->sum_lx += q.x - c.x;
            nb->sum_ly += q.y - c.y;
            if (list != NULL) {
                list[k++] = (uint16_t)q_beam;
            }
        }
    }
    for (j = i + 1; j <= nb->last; ++j) {
        if (in_ball(pts, j, b)) {
            const size_t q_beam = beam_at(pts, j);
            const bsf_point_t q = pts->pt[q_beam];
            ++nb->n_right;
            nb->sum_rx += q.x - c.x;
            nb->sum_ry += q.y - c.y;
            if (list != NULL) {
                list[k++] = (uint16_t)q_beam;
            }
        }
    }
}

/* Step 5: the triangle apex - first - last must be wide and tall enough. */
static int triangle_ok(const bsf_points_t *pts, size_t i, const neigh_t *nb, float r, float b_ratio)
{
    const bsf_point_t a = pts->pt[i];
    const bsf_point_t f = pts->pt[beam_at(pts, nb->first)];
    const bsf_point_t l = pts->pt[beam_at(pts, nb->last)];
    const float lim = r / b_ratio;
    const float bx = l.x - f.x;
    const float by = l.y - f.y;
    const float base = sqrtf(bx * bx + by * by);
    float area2;
    if (base < lim) {
        return 0;
    }
    /* Twice the signed area of (a, f, l), from coordinates relative to the
     * apex. The reference's form from absolute coordinates (double there)
     * cancels terms of the size of |p|^2 in float, losing about 1e-5
     * relative: enough to flip one test on fr-clinic. Relative to the apex,
     * float keeps the double result's decision. */
    area2 = (f.x - a.x) * (l.y - a.y) - (f.y - a.y) * (l.x - a.x);
    return !(fabsf(area2) / base < lim);
}

/* Steps 5 and 6 for apex i whose outermost neighbours nb->first and
 * nb->last are known; 0 when rejected. */
static int sides(const bsf_points_t *pts, size_t i, float r, const bsf_falko_params_t *p,
                 neigh_t *nb, uint16_t *list)
{
    const ball_t b = make_ball(pts->pt[i], r);
    if (!triangle_ok(pts, i, nb, r, p->b_ratio)) {
        return 0;
    }
    count_sides(pts, (ptrdiff_t)i, &b, nb, list);
    return nb->n_left >= p->neigh_min_points && nb->n_right >= p->neigh_min_points;
}

/* Steps 3-5 and the sums of step 6 for apex i; 0 when rejected. All
 * rejections are alike, so the cheap ends-and-triangle test runs first and
 * the full count only for its survivors. */
static int neighbourhood(const bsf_points_t *pts, size_t i, float r, size_t alpha, int ring,
                         const bsf_falko_params_t *p, neigh_t *nb, uint16_t *list)
{
    const ball_t b = make_ball(pts->pt[i], r);
    neigh_window(pts, i, alpha, ring, nb);
    if (!find_ends(pts, (ptrdiff_t)i, &b, nb)) {
        return 0;
    }
    return sides(pts, i, r, p, nb, list);
}

/* Step 6: orientation of the corner (mean left vector + mean right vector). */
static float corner_orientation(const neigh_t *nb)
{
    const float x = nb->sum_lx / (float)nb->n_left + nb->sum_rx / (float)nb->n_right;
    const float y = nb->sum_ly / (float)nb->n_left + nb->sum_ry / (float)nb->n_right;
    return bsf_atan2f(y, x);
}

/* Step 7: sector of neighbour q seen from the apex c, not wrapped. */
static int sector_of(bsf_point_t q, bsf_point_t c, float theta, float sector_width)
{
    float ang = bsf_atan2f(c.y - q.y, c.x - q.x);
    if (ang >= FALKO_PI) {
        ang = FALKO_ANGLE_LIMIT;
    } else if (ang <= -FALKO_PI) {
        ang = -FALKO_ANGLE_LIMIT;
    }
    {
        /* floor without a library call: |x| < 2 pi / sector_width + 1 */
        const float x = (ang + FALKO_PI - theta) / sector_width;
        const int k = (int)x;
        return ((float)k > x) ? k - 1 : k;
    }
}

/* Step 8: FALKOLib's sector distance (truncating %), or the true circular one. */
static int sector_distance(int a, int b, int sectors, int circular)
{
    if (circular) {
        int m = (a - b) % sectors;
        if (m < 0) {
            m += sectors;
        }
        return (m < sectors - m) ? m : sectors - m;
    } else {
        const int half = sectors / 2;
        const int d = ((a - b) + half) % sectors - half;
        return (d < 0) ? -d : d;
    }
}

/* Sector values lie in -S/2 - 1 .. 3S/2 (S <= 64): the clamped angle is
 * within (-pi, pi), theta within [-pi, pi], so (ang + pi - theta) / width
 * lies within (-S/2 - 1, 3S/2 + 1). Offset into sector_count[]. */
#define FALKO_SECTOR_OFFSET 33
/* Differences of two sector values lie in -129 .. 129: offset into
 * sector_dist[]. */
#define FALKO_SECTOR_SPAN 129

/* Step 8 for one side: the sum of sector distances over pairs of its
 * neighbours, the first of each pair the one nearer the apex. Neighbours are
 * visited from the apex outwards (sec[0], sec[step], ...); each adds its
 * distances to all nearer ones, taken per sector value with its count, so the
 * cost is n times the number of distinct values (a side along a wall covers
 * one to three sectors), not n^2 / 2. Integer sums: the same total. */
static long side_score(const int8_t *sec, int n, int step, const bsf_falko_params_t *p,
                       bsf_falko_work_t *work)
{
    long score = 0;
    int n_seen = 0;
    int k, m;
    for (k = 0; k < n; ++k) {
        const int s = sec[k * step];
        uint16_t *count = &work->sector_count[s + FALKO_SECTOR_OFFSET];
        for (m = 0; m < n_seen; ++m) {
            const int t = work->sector_seen[m];
            /* sector_distance depends on t - s only: remembered per call. */
            int8_t *d = &work->sector_dist[t - s + FALKO_SECTOR_SPAN];
            if (*d < 0) {
                *d = (int8_t)sector_distance(t, s, p->grid_sectors, p->circular_sector_distance);
            }
            score += (long)work->sector_count[t + FALKO_SECTOR_OFFSET] * *d;
        }
        if (*count == 0u) {
            work->sector_seen[n_seen++] = (int8_t)s;
        }
        ++*count;
    }
    for (m = 0; m < n_seen; ++m) {
        work->sector_count[work->sector_seen[m] + FALKO_SECTOR_OFFSET] = 0u;
    }
    return score;
}

/* Steps 7-9 for an apex that passed steps 1-6: the raw integer score. */
static long corner_score(const bsf_points_t *pts, size_t i, const neigh_t *nb, float theta,
                         const uint16_t *list, const bsf_falko_params_t *p, bsf_falko_work_t *work)
{
    const bsf_point_t c = pts->pt[i];
    const float width = 2.0f * FALKO_PI / (float)p->grid_sectors;
    const int n = nb->n_left + nb->n_right;
    int8_t *sector = work->sector;
    int k;

    /* sector[0..nl-1]: left neighbours in scan order; sector[nl..]: right
     * (count_sides listed them so). */
    for (k = 0; k < n; ++k) {
        sector[k] = (int8_t)sector_of(pts->pt[list[k]], c, theta, width);
    }
    /* Left: nearest is sector[nl - 1], walking down; right: sector[nl] up. */
    return side_score(&sector[nb->n_left - 1], nb->n_left, -1, p, work) +
           side_score(&sector[nb->n_left], nb->n_right, 1, p, work);
}

/* Total-least-squares line through beams [from, to] that are neighbours of
 * apex c: unit normal n and offset d with n . x = d. */
static void fit_line(const bsf_points_t *pts, ptrdiff_t from, ptrdiff_t to, const ball_t *ball,
                     float *nx, float *ny, float *d)
{
    float sx = 0.0f, sy = 0.0f, sxx = 0.0f, syy = 0.0f, sxy = 0.0f;
    float mx, my, t;
    int n = 0;
    ptrdiff_t j;
    for (j = from; j <= to; ++j) {
        if (in_ball(pts, j, ball)) {
            sx += pts->pt[beam_at(pts, j)].x;
            sy += pts->pt[beam_at(pts, j)].y;
            ++n;
        }
    }
    mx = sx / (float)n;
    my = sy / (float)n;
    /* Centred moments: no cancellation in float. */
    for (j = from; j <= to; ++j) {
        if (in_ball(pts, j, ball)) {
            const float dx = pts->pt[beam_at(pts, j)].x - mx;
            const float dy = pts->pt[beam_at(pts, j)].y - my;
            sxx += dx * dx;
            syy += dy * dy;
            sxy += dx * dy;
        }
    }
    /* Direction of largest spread, then the normal a quarter turn away. */
    t = 0.5f * bsf_atan2f(2.0f * sxy, sxx - syy) + 0.5f * FALKO_PI;
    *nx = bsf_cosf(t);
    *ny = bsf_sinf(t);
    *d = *nx * mx + *ny * my;
}

/* Step 11: intersect the lines fitted to each side (apex in both). */
static bsf_point_t subbeam_corner(const bsf_points_t *pts, size_t i, const neigh_t *nb, float r)
{
    const ball_t ball = make_ball(pts->pt[i], r);
    const bsf_point_t c = ball.c;
    float n1x, n1y, d1, n2x, n2y, d2, det;
    bsf_point_t q;
    fit_line(pts, nb->first, (ptrdiff_t)i, &ball, &n1x, &n1y, &d1);
    fit_line(pts, (ptrdiff_t)i, nb->last, &ball, &n2x, &n2y, &d2);
    det = n1x * n2y - n1y * n2x;
    if (fabsf(det) < 1e-7f) {
        return c;
    }
    q.x = (d1 * n2y - n1y * d2) / det;
    q.y = (n1x * d2 - d1 * n2x) / det;
    if (!finite_f(q.x) || !finite_f(q.y) ||
        !(sqrtf((q.x - c.x) * (q.x - c.x) + (q.y - c.y) * (q.y - c.y)) < 0.20f)) {
        return c;
    }
    return q;
}

/* Certain rejection without the exact radius. Nearly every apex of a scan
 * is rejected by steps 3-5 (an apex on a wall fails the triangle test), and
 * each of those would need bsf_expf for its radius. Here the radius is only
 * bracketed, lo <= r <= hi, from a short exp: every test that decides a
 * rejection is monotone in r, so a rejection that holds for the bracket holds
 * for r, and one that does not (a neighbour too near the ball's edge, a
 * triangle that might pass) goes to the exact path. Results are therefore
 * those of the exact path alone. */

/* work->win_hi of a beam whose bracket is not cheap: the exact path decides;
 * and of a beam that is no apex (step 1: invalid or out of the extraction
 * range). Windows are at most BSF_MAX_POINTS. */
#define FALKO_WIN_EXACT 0xFFFFu
#define FALKO_WIN_NONE 0xFFFEu

/* Float bits of a non-negative float: they order as the values do, so the
 * loop below compares and clamps them as integers (no branches). */
static int32_t float_bits(float v)
{
    int32_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static float bits_float(int32_t b)
{
    float v;
    memcpy(&v, &b, sizeof v);
    return v;
}

/* window_clamp for any value (negative, NaN and garbage give 0 or the cap). */
static int32_t window_clamp_any(float a)
{
    int32_t b = float_bits(a);
    b = (b > 0) ? b : 0;
    b = (b < float_bits((float)BSF_MAX_POINTS)) ? b : float_bits((float)BSF_MAX_POINTS);
    return (int32_t)bits_float(b);
}

/* The bracket of every beam (valid or not: the others go unused) in one loop
 * without branches, so that compilers run several beams per instruction:
 * the squared distances certainly inside / outside the exact ball (see
 * make_ball), the smallest triangle limit lo / b_ratio, the window of hi (or
 * FALKO_WIN_EXACT) and a window the ends may reach without a second look. */
static void radius_brackets(const bsf_points_t *pts, const bsf_falko_params_t *p, float inv_inc,
                            bsf_falko_work_t *work)
{
    const float a = p->neigh_a;
    const float b = p->neigh_b;
    const float b_ratio = p->b_ratio;
    /* Step 1, is beam i an apex at all: valid, min_range <= rho <= max_range
     * (both >= 0, as ranges are; -0.0 min_range compares as below all). */
    const int32_t min_range_bits = float_bits(p->min_range);
    const int32_t max_range_bits = float_bits(p->max_range);
    const size_t n = pts->count;
    size_t i;
    for (i = 0; i < n; ++i) {
        const float rho = pts->range[i];
        /* The same float product neigh_radius passes to bsf_expf, capped at
         * 80 so that the conversion below stays defined (x >= 80 takes the
         * exact path). x >= 0 (b >= 0, rho >= 0). */
        const int32_t x_bits = float_bits(b * rho);
        const float x = bits_float((x_bits < 0x42a00000) ? x_bits : 0x42a00000); /* 80.0f */
        /* exp(x) = 2^k exp(f), |f| <= ln2 / 2 + 1e-5: degree-5 Taylor
         * series, truncation below 5e-6 relative; the rounding of k ln2
         * (k <= 116) adds below 4e-6, the other roundings and bsf_expf's own
         * error below 1e-6. The bracket's margin, 1e-4, is ten times their
         * sum. */
        const int32_t k = (int32_t)(x * 1.44269504f + 0.5f);
        const float f = x - (float)k * 0.693147182f;
        const float e =
            1.0f +
            f * (1.0f + f * (0.5f + f * (1.0f / 6.0f + f * (1.0f / 24.0f + f * (1.0f / 120.0f)))));
        const float m = a * (e * bits_float((k + 127) << 23));
        const float lo = m * (1.0f - 1e-4f);
        const float hi = m * (1.0f + 1e-4f);
        /* Windows grow with r (every operation of window_alpha is
         * monotone), so the exact window lies between those of lo and hi.
         * lo's window is at least 0.999 hi's when lo >= hi (1 - 2e-4) and
         * hi <= 0.8 rho (rho^2 - r^2 then changes by under 7.2e-4 relative
         * between them). */
        const float a_hi = window_alpha_f(rho, hi, inv_inc);
        /* r = a exp(b rho) itself when hi < rho; otherwise (r may be
         * neigh_radius's cap), for x >= 80 and for radii so small that their
         * squares leave float's normal range (lo < 1e-15) the exact path
         * decides. */
        /* Each comparison as an int (0 or 1), combined without branches. */
        const int32_t apex =
            -((int32_t)(pts->valid[i] != 0u) & (int32_t)(float_bits(rho) >= min_range_bits) &
              (int32_t)(float_bits(rho) <= max_range_bits));
        const int32_t cheap =
            -((int32_t)(x_bits < 0x42a00000) & (int32_t)(float_bits(hi) < float_bits(rho)) &
              (int32_t)(float_bits(lo) >= float_bits(1e-15f)));
        const int32_t near = -(float_bits(hi) <= float_bits(0.8f * rho));
        /* Selections by masks: conversions inside a branch would not run
         * four at a time. */
        const int32_t win = (window_clamp_any(a_hi) & cheap) | ((int32_t)FALKO_WIN_EXACT & ~cheap);
        work->win_hi[i] = (uint16_t)((win & apex) | ((int32_t)FALKO_WIN_NONE & ~apex));
        work->win_inner[i] = (uint16_t)(window_clamp_any(a_hi * 0.999f) & near);
        work->in2[i] = lo * lo * (1.0f - 1e-6f);
        work->out2[i] = hi * hi * (1.0f + 1e-6f);
        work->lim[i] = lo / b_ratio;
    }
}

/* FALKO_MAYBE_ENDS: only the exact path can tell, and the outermost
 * neighbours are known (certain, inside the exact window). */
enum { FALKO_REJECT = 0, FALKO_MAYBE = 1, FALKO_MAYBE_ENDS = 2 };

/* The outermost neighbour on one side, walking from window position `from`
 * towards the apex by `step`: FALKO_REJECT when no beam can be a neighbour
 * for any r in the bracket, else *end = the outermost certain neighbour, or
 * FALKO_MAYBE (*end = apex) when a beam on the way is undecided. */
static int bracket_end(const bsf_points_t *pts, ptrdiff_t from, ptrdiff_t i, ptrdiff_t step,
                       bsf_point_t c, float in2, float out2, ptrdiff_t *end)
{
    /* Windows that stay inside the scan (all but a few on a full circle)
     * need no wrapping. */
    const int wraps = from < 0 || from >= (ptrdiff_t)pts->count;
    ptrdiff_t v;
    for (v = from; v != i; v += step) {
        const size_t j = wraps ? beam_at(pts, v) : (size_t)v;
        float dx, dy, d2;
        if (!pts->valid[j]) {
            continue;
        }
        dx = c.x - pts->pt[j].x;
        dy = c.y - pts->pt[j].y;
        d2 = dx * dx + dy * dy;
        if (d2 > out2) {
            continue;
        }
        *end = (d2 <= in2) ? v : i;
        return FALKO_MAYBE;
    }
    return FALKO_REJECT;
}

/* FALKO_REJECT when steps 3-5 certainly reject apex i (see radius_brackets);
 * FALKO_MAYBE when only the exact path can tell. */
static int certainly_rejected(const bsf_points_t *pts, size_t i, int ring,
                              const bsf_falko_work_t *work)
{
    const bsf_point_t c = pts->pt[i];
    const size_t w = work->win_hi[i];
    const size_t inner = work->win_inner[i];
    const float in2 = work->in2[i];
    const float out2 = work->out2[i];
    const float lim = work->lim[i];
    neigh_t win;
    ptrdiff_t first, last;
    if (w == FALKO_WIN_EXACT) {
        return FALKO_MAYBE;
    }
    neigh_window(pts, i, w, ring, &win);
    if (bracket_end(pts, win.beg, (ptrdiff_t)i, 1, c, in2, out2, &first) == FALKO_REJECT ||
        bracket_end(pts, win.end, (ptrdiff_t)i, -1, c, in2, out2, &last) == FALKO_REJECT) {
        return FALKO_REJECT;
    }
    /* Certain neighbours inside lo's window are the exact ends: the exact
     * search meets only certain outsiders before them. Ends beyond `inner`
     * (rare) are left to the exact path. */
    if (first == (ptrdiff_t)i || last == (ptrdiff_t)i || (size_t)((ptrdiff_t)i - first) > inner ||
        (size_t)(last - (ptrdiff_t)i) > inner) {
        return FALKO_MAYBE;
    }
    /* Step 5 with the smallest limit: r / b_ratio >= lo / b_ratio. */
    {
        const int wraps = first < 0 || last >= (ptrdiff_t)pts->count;
        const bsf_point_t f = pts->pt[wraps ? beam_at(pts, first) : (size_t)first];
        const bsf_point_t l = pts->pt[wraps ? beam_at(pts, last) : (size_t)last];
        const float bx = l.x - f.x;
        const float by = l.y - f.y;
        const float base = sqrtf(bx * bx + by * by);
        float area2;
        if (base < lim) {
            return FALKO_REJECT;
        }
        area2 = (f.x - c.x) * (l.y - c.y) - (f.y - c.y) * (l.x - c.x);
        return (fabsf(area2) / base < lim) ? FALKO_REJECT : FALKO_MAYBE;
    }
}

#ifdef FALKO_SSE2_WALKS
/* d2 = (c - q)^2 summed over x and y for the 4 points from q (interleaved x,
 * y), and the mask of those with !(d2 > out2). */
static int near4(const bsf_point_t *q, __m128 cx, __m128 cy, __m128 o2, __m128 *d2)
{
    const __m128 a = _mm_loadu_ps(&q[0].x); /* x0 y0 x1 y1 */
    const __m128 b = _mm_loadu_ps(&q[2].x); /* x2 y2 x3 y3 */
    const __m128 dx = _mm_sub_ps(cx, _mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)));
    const __m128 dy = _mm_sub_ps(cy, _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
    *d2 = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy));
    return _mm_movemask_ps(_mm_cmpngt_ps(*d2, o2));
}

/* The first position from `first` upwards with !(d2 > out2), and its d2. */
static size_t walk_up4(const bsf_point_t *pt, bsf_point_t c, float out2, size_t first, float *d2)
{
    const __m128 cx = _mm_set1_ps(c.x);
    const __m128 cy = _mm_set1_ps(c.y);
    const __m128 o2 = _mm_set1_ps(out2);
    float lane[4];
    __m128 v;
    int m, k;
    while ((m = near4(&pt[first], cx, cy, o2, &v)) == 0) {
        first += 4u;
    }
    k = (m & 1) ? 0 : (m & 2) ? 1 : (m & 4) ? 2 : 3;
    _mm_storeu_ps(lane, v);
    *d2 = lane[k];
    return first + (size_t)k;
}

/* The first position from `last` downwards with !(d2 > out2), and its d2. */
static size_t walk_down4(const bsf_point_t *pt, bsf_point_t c, float out2, size_t last, float *d2)
{
    const __m128 cx = _mm_set1_ps(c.x);
    const __m128 cy = _mm_set1_ps(c.y);
    const __m128 o2 = _mm_set1_ps(out2);
    float lane[4];
    __m128 v;
    int m, k;
    while ((m = near4(&pt[last - 3u], cx, cy, o2, &v)) == 0) {
        last -= 4u;
    }
    k = (m & 8) ? 3 : (m & 4) ? 2 : (m & 2) ? 1 : 0;
    _mm_storeu_ps(lane, v);
    *d2 = lane[k];
    return last - 3u + (size_t)k;
}
#endif

/* Whether beam i's window of half-width w lies inside the scan, so that
 * certainly_rejected_inside may judge it. The compact variant
 * (BSF_CONFIG_COMPACT) always answers no: certainly_rejected alone, the same
 * results with less code. The markers FALKO_WIN_NONE and FALKO_WIN_EXACT
 * exceed any i. */
static inline int window_inside(size_t w, size_t i, size_t count)
{
#if !BSF_CONFIG_COMPACT
    return w <= i && i + w < count;
#else
    (void)w;
    (void)i;
    (void)count;
    return 0;
#endif
}

/* certainly_rejected for a window [i - w, i + w] inside the scan (no
 * clamping, no wrapping: nearly every apex), in fewer instructions. The end
 * searches skip the validity test: an invalid beam is (0, 0) (bsf_points_t),
 * and when one is nevertheless met within the bracket the exact path decides,
 * so the outcome never depends on that. Every beam the walk passes has
 * d2 > out2 and is skipped by bracket_end too; the beam it stops at, when
 * valid, is bracket_end's. */
static int certainly_rejected_inside(const bsf_points_t *pts, size_t i, size_t w,
                                     const bsf_falko_work_t *work, neigh_t *ends)
{
    const bsf_point_t *pt = pts->pt;
    const bsf_point_t c = pt[i];
    const float out2 = work->out2[i];
    const float in2 = work->in2[i];
    const size_t inner = work->win_inner[i];
    size_t first = i - w;
    size_t last = i + w;
    float d2f, d2l;
    /* The apex stops each walk, so the loops need no bound: its d2 is 0 and
     * out2 > 0 (the bracket is cheap only for finite radii above 1e-15), or
     * NaN when the apex is not finite. A walk also stops at a NaN d2 (a
     * non-finite point), which the exact path then decides (!(d2 <= in2)). */
#ifdef FALKO_SSE2_WALKS
    if (w >= FALKO_WIDE_WINDOW) {
        /* Four beams per step, each d2 computed as below (the same float
         * operations per lane). Steps read at most 3 beams past the apex,
         * which lie inside the window. */
        first = walk_up4(pt, c, out2, first, &d2f);
        if (first == i) {
            return FALKO_REJECT;
        }
        last = walk_down4(pt, c, out2, last, &d2l);
    } else
#endif
    {
        for (;; ++first) {
            const float dx = c.x - pt[first].x;
            const float dy = c.y - pt[first].y;
            d2f = dx * dx + dy * dy;
            if (!(d2f > out2)) {
                break;
            }
        }
        if (first == i) {
            return FALKO_REJECT;
        }
        for (;; --last) {
            const float dx = c.x - pt[last].x;
            const float dy = c.y - pt[last].y;
            d2l = dx * dx + dy * dy;
            if (!(d2l > out2)) {
                break;
            }
        }
    }
    if (last == i) {
        return FALKO_REJECT;
    }
    if (!pts->valid[first] || !pts->valid[last] || !(d2f <= in2) || !(d2l <= in2) ||
        i - first > inner || last - i > inner) {
        return FALKO_MAYBE;
    }
    {
        const float lim = work->lim[i];
        const bsf_point_t f = pt[first];
        const bsf_point_t l = pt[last];
        const float bx = l.x - f.x;
        const float by = l.y - f.y;
        const float base = sqrtf(bx * bx + by * by);
        float area2;
        if (base < lim) {
            return FALKO_REJECT;
        }
        area2 = (f.x - c.x) * (l.y - c.y) - (f.y - c.y) * (l.x - c.x);
        if (fabsf(area2) / base < lim) {
            return FALKO_REJECT;
        }
        /* The exact search would find these ends (certainly_rejected). */
        ends->first = (ptrdiff_t)first;
        ends->last = (ptrdiff_t)last;
        return FALKO_MAYBE_ENDS;
    }
}

/* Steps 3-9 for apex i with radius r and window alpha: its raw score, or
 * FALKO_REJECTED. */
static float beam_score(const bsf_points_t *pts, size_t i, float r, size_t alpha, int ring,
                        const bsf_falko_params_t *p, bsf_falko_work_t *work)
{
    float theta;
    neigh_t nb;
    /* work->peak is free until suppression: the neighbours' beams. */
    if (!neighbourhood(pts, i, r, alpha, ring, p, &nb, work->peak)) {
        return FALKO_REJECTED;
    }
    theta = corner_orientation(&nb);
    return (float)corner_score(pts, i, &nb, theta, work->peak, p, work);
}

/* beam_score for an apex whose outermost neighbours nb->first, nb->last are
 * known (FALKO_MAYBE_ENDS). */
static float beam_score_ends(const bsf_points_t *pts, size_t i, float r,
                             const bsf_falko_params_t *p, neigh_t *nb, bsf_falko_work_t *work)
{
    float theta;
    if (!sides(pts, i, r, p, nb, work->peak)) {
        return FALKO_REJECTED;
    }
    theta = corner_orientation(nb);
    return (float)corner_score(pts, i, nb, theta, work->peak, p, work);
}

bsf_status_t bsf_falko_detect(const bsf_points_t *pts, const bsf_falko_params_t *p,
                              bsf_falko_work_t *work, bsf_keypoint_t *out, size_t out_cap,
                              size_t *n_out)
{
    size_t i, k, n_peak;
    float inc, inv_inc;
    long score_max = 0;
    long min_val;
    float raw_min = (float)FALKO_SCORE_LIMIT; /* smallest raw score of an accepted apex */
    bsf_status_t st;
    int ring;

    if (n_out != NULL) {
        *n_out = 0;
    }
    if (pts == NULL || p == NULL || work == NULL || n_out == NULL ||
        (out == NULL && out_cap > 0u)) {
        return BSF_ERR_ARG;
    }
    st = bsf_falko_params_check(p);
    if (st != BSF_OK) {
        return st;
    }
    if (pts->count > (size_t)BSF_MAX_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    inc = fabsf(pts->angle_increment);
    if (!finite_f(inc) || inc == 0.0f) {
        return BSF_ERR_ARG;
    }
    inv_inc = 1.0f / inc;
    ring = bsf_points_full_circle(pts);
    memset(work->sector_count, 0, sizeof work->sector_count);
    memset(work->sector_dist, -1, sizeof work->sector_dist);
    radius_brackets(pts, p, inv_inc, work);

    for (i = 0; i < pts->count; ++i) {
        const size_t w = work->win_hi[i];
        const int inside = window_inside(w, i, pts->count);
        int verdict;
        neigh_t ends;
        work->score[i] = FALKO_REJECTED;
        if (inside) {
            verdict = certainly_rejected_inside(pts, i, w, work, &ends);
        } else if (w == FALKO_WIN_NONE) {
            verdict = FALKO_REJECT;
        } else {
            verdict = certainly_rejected(pts, i, ring, work);
        }
        if (verdict != FALKO_REJECT) {
            const float r = neigh_radius(p, pts->range[i]);
            const float sc =
                (inside && verdict == FALKO_MAYBE_ENDS)
                    ? beam_score_ends(pts, i, r, p, &ends, work)
                    : beam_score(pts, i, r, window_alpha(pts, i, r, inv_inc), ring, p, work);
            work->score[i] = sc;
            if (sc >= 0.0f && sc < raw_min) {
                raw_min = sc;
            }
            if (sc > (float)score_max) {
                if (sc > (float)FALKO_SCORE_LIMIT) {
                    return BSF_ERR_CAPACITY;
                }
                score_max = (long)sc;
            }
        }
    }
    min_val = score_max * (long)p->min_score_th / 100L;
    if (score_max == 0 || (float)score_max - raw_min <= (float)min_val) {
        /* No strength passes the threshold (>= 0): the strongest beam has
         * scoreMax - (smallest raw score), rejected ones 0. Exact: integers
         * below 2^24 in float. */
        return BSF_OK;
    }

    /* Strength = scoreMax - raw (rejected beams: 0); candidates need a
     * strength above int(scoreMax * th / 100), computed exactly in integers. */
    for (i = 0; i < pts->count; ++i) {
        const float s = work->score[i];
        work->score[i] = (s < 0.0f) ? 0.0f : (float)score_max - s;
    }
    n_peak = bsf_nms_beams(pts, work->score, BSF_NMS_HIGHER_IS_BETTER, (float)min_val,
                           p->nms_radius, work->peak);
    if (ring && n_peak >= 2u) {
        /* Suppression does not wrap: of two peaks facing each other across
         * the seam within the suppression window, keep the stronger (the
         * first on a tie), as suppression would have. */
        const size_t lo = work->peak[0];
        const size_t hi = work->peak[n_peak - 1u];
        const size_t w_lo = bsf_nms_half_window(pts, lo, p->nms_radius);
        const size_t w_hi = bsf_nms_half_window(pts, hi, p->nms_radius);
        if (lo + pts->count - hi <= (w_lo > w_hi ? w_lo : w_hi)) {
            if (work->score[hi] > work->score[lo]) {
                for (k = 1; k < n_peak; ++k) {
                    work->peak[k - 1u] = work->peak[k];
                }
            }
            --n_peak;
        }
    }

    *n_out = n_peak;
    /* Over the cap, the strongest keypoints are the ones worth keeping. */
    n_peak = bsf_nms_keep_best(work->score, BSF_NMS_HIGHER_IS_BETTER, work->peak, n_peak, out_cap);
    for (k = 0; k < n_peak; ++k) {
        const size_t b = work->peak[k];
        const float r = neigh_radius(p, pts->range[b]);
        neigh_t nb;
        (void)neighbourhood(pts, b, r, window_alpha(pts, b, r, inv_inc), ring, p, &nb,
                            NULL); /* passed before */
        out[k].index = (uint16_t)b;
        out[k].orientation = corner_orientation(&nb);
        out[k].radius = r;
        out[k].score = (float)score_max - work->score[b];
        out[k].point = p->subbeam ? subbeam_corner(pts, b, &nb, r) : pts->pt[b];
    }
    return (*n_out > out_cap) ? BSF_ERR_CAPACITY : BSF_OK;
}
