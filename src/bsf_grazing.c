/* SPDX-License-Identifier: MIT */
/* Grazing joins (bsf_grazing.h explains them): one copy for SVED and LC. */
#include "bsf_grazing.h"
#include "bsf_compact.h"

#include <stddef.h>

int bsf_grazing_triple(const bsf_point_t *pt, size_t i0, size_t i1, size_t i2)
{
    const bsf_point_t p0 = pt[i0];
    const bsf_point_t p1 = pt[i1];
    const bsf_point_t p2 = pt[i2];
    const float ax = p1.x - p0.x;
    const float ay = p1.y - p0.y;
    const float bx = p2.x - p1.x;
    const float by = p2.y - p1.y;
    const float la2 = ax * ax + ay * ay;
    const float lb2 = bx * bx + by * by;
    const float r2 = BSF_GRAZING_STEP_RATIO * BSF_GRAZING_STEP_RATIO;
    const float cx = p2.x - p0.x;
    const float cy = p2.y - p0.y;
    const float cross = ax * by - ay * bx;
    if (!(la2 > 0.0f) || !(lb2 > 0.0f) || !(la2 <= r2 * lb2) || !(lb2 <= r2 * la2) ||
        !(ax * bx + ay * by > 0.0f)) {
        return 0;
    }
    /* distance of p1 from the chord: |cross| / |p2 - p0| */
    return cross * cross <= BSF_GRAZING_LINE_TOL * BSF_GRAZING_LINE_TOL * (cx * cx + cy * cy);
}

/* Point e = pt[ie] lies just before the line that goes from p = pt[ip]
 * through q = pt[iq]: behind p by at most 1.5 steps |q - p| along it, off it
 * by at most half a step. */
static int bsf_grazing_entry(const bsf_point_t *pt, size_t ie, size_t ip, size_t iq)
{
    const bsf_point_t e = pt[ie];
    const bsf_point_t p = pt[ip];
    const bsf_point_t q = pt[iq];
    const float ux = q.x - p.x;
    const float uy = q.y - p.y;
    const float s2 = ux * ux + uy * uy;
    const float ex = p.x - e.x;
    const float ey = p.y - e.y;
    const float along = ex * ux + ey * uy; /* times |q - p| */
    const float off = ex * uy - ey * ux;   /* times |q - p| */
    return s2 > 0.0f && along > 0.0f && along <= 1.5f * s2 && off * off <= 0.25f * s2 * s2;
}

/* |pt[iq] - pt[ip]| <= cap */
static BSF_COMPACT_NOINLINE int bsf_grazing_within(const bsf_point_t *pt, size_t ip, size_t iq,
                                                   float cap)
{
    const bsf_point_t p = pt[ip];
    const bsf_point_t q = pt[iq];
    const float dx = q.x - p.x;
    const float dy = q.y - p.y;
    return dx * dx + dy * dy <= cap * cap;
}

static BSF_COMPACT_INLINE int bsf_grazing_ok(const bsf_points_t *pts, size_t i)
{
    return i < pts->count && pts->valid[i] != 0u;
}

/* Points i..i + 2 (valid beams) lie on one line. */
static int bsf_grazing_run3(const bsf_points_t *pts, size_t i)
{
    return bsf_grazing_ok(pts, i) && bsf_grazing_ok(pts, i + 1u) && bsf_grazing_ok(pts, i + 2u) &&
           bsf_grazing_triple(pts->pt, i, i + 1u, i + 2u);
}

/* Points i..i + 3 (valid beams) lie on one line: both triples collinear. */
static int bsf_grazing_run4(const bsf_points_t *pts, size_t i)
{
    return bsf_grazing_run3(pts, i) && bsf_grazing_ok(pts, i + 3u) &&
           bsf_grazing_triple(pts->pt, i + 1u, i + 2u, i + 3u);
}

/* The middle return p1 lies where its ray crosses the chord p0-p2, to
 * within BSF_GRAZING_LINE_TOL along that ray (range noise moves a return
 * along its ray). Nearly edge-on, the distance from the chord alone tests
 * little: the chord runs almost along p1's ray, so a return anywhere on it
 * (a mixed pixel, an object behind) passes near the chord. */
static int bsf_grazing_on_ray(bsf_point_t p0, bsf_point_t p1, bsf_point_t p2)
{
    const float cx = p2.x - p0.x;
    const float cy = p2.y - p0.y;
    const float off = (p1.x - p0.x) * cy - (p1.y - p0.y) * cx; /* |c| times the distance */
    const float ray = cx * p1.y - cy * p1.x;                   /* |c| |p1| sin(chord, ray) */
    return off * off * (p1.x * p1.x + p1.y * p1.y) <=
           BSF_GRAZING_LINE_TOL * BSF_GRAZING_LINE_TOL * ray * ray;
}

/* Points i..i + 2 (valid beams) on one line, tested along the rays as well. */
static int bsf_grazing_line3(const bsf_points_t *pts, size_t i)
{
    const bsf_point_t *p = pts->pt;
    return bsf_grazing_run3(pts, i) && bsf_grazing_on_ray(p[i], p[i + 1u], p[i + 2u]);
}

/* Points s..s + 3 lie on one line (along the rays too) that starts at a
 * corner: s - 3..s - 1 lie on another line, whose last return s - 1 is no
 * step of the first (their steps differ, or they turn) yet lies just
 * behind s on it (bsf_grazing_entry). With dir -1 the mirror image:
 * s..s - 3 end at the corner s + 1. The caller has checked what both
 * forms need (bsf_grazing_run_room). */
static int bsf_grazing_corner_run(const bsf_points_t *pts, size_t s, int dir)
{
    const bsf_point_t *p = pts->pt;
    const ptrdiff_t d = dir;
    const size_t c = (size_t)((ptrdiff_t)s - d); /* the corner's return */
    return bsf_grazing_entry(p, c, s, (size_t)((ptrdiff_t)s + d)) &&
           !bsf_grazing_triple(p, (size_t)((ptrdiff_t)c - d), c, s) &&
           bsf_grazing_line3(pts, d > 0 ? c - 2u : c) &&
           bsf_grazing_line3(pts, d > 0 ? s : s - 2u) &&
           bsf_grazing_line3(pts, d > 0 ? s + 1u : s - 3u);
}

/* What a corner run from s needs in either direction: beams s - 3..s + 3
 * in the scan, s - 1..s + 1 valid, s - 1 within cap of s + 1. The cheap
 * tests on the corner's return come first: most wide steps are depth
 * jumps, whose far return lies nowhere near the line. */
static BSF_COMPACT_INLINE int bsf_grazing_run_room(const bsf_points_t *pts, size_t s, float cap)
{
    return s >= 3u && s + 3u < pts->count && pts->valid[s - 1u] && pts->valid[s] &&
           pts->valid[s + 1u] && bsf_grazing_within(pts->pt, s - 1u, s + 1u, cap);
}

/* The step between beams a and a + 1 is the step onto such a corner run or
 * one of its own (a run of four from its corner, see grazing_join_verdict):
 * a run from s = a - 2..a + 1 onwards, or one from s = a..a + 3 back. */
static int bsf_grazing_at_corner(const bsf_points_t *pts, size_t a, float cap)
{
    size_t s;
    for (s = a >= 2u ? a - 2u : 0u; s <= a + 3u; ++s) {
        if (bsf_grazing_run_room(pts, s, cap) &&
            ((s <= a + 1u && bsf_grazing_corner_run(pts, s, 1)) ||
             (s >= a && bsf_grazing_corner_run(pts, s, -1)))) {
            return 1;
        }
    }
    return 0;
}

/* bsf_grazing_join's verdict, computed. */
static int grazing_join_verdict(const bsf_points_t *pts, size_t a, float cap, int at_corners)
{
    const size_t b = a + 1u;
    const bsf_point_t *p = pts->pt;
    float dx;
    float dy;
    if (!bsf_grazing_ok(pts, a) || !bsf_grazing_ok(pts, b)) {
        return 0;
    }
    dx = p[b].x - p[a].x;
    dy = p[b].y - p[a].y;
    if (!(dx * dx + dy * dy <= cap * cap)) {
        return 0;
    }
    {
        /* sin of the angle between the step and beam b's ray (the sensor
         * is at the origin) */
        const float cr = dx * p[b].y - dy * p[b].x;
        const float rb2 = p[b].x * p[b].x + p[b].y * p[b].y;
        if (!(cr * cr >= BSF_GRAZING_MIN_SIN * BSF_GRAZING_MIN_SIN * (dx * dx + dy * dy) * rb2)) {
            return at_corners && bsf_grazing_at_corner(pts, a, cap);
        }
    }
    if ((a >= 2u && bsf_grazing_run4(pts, a - 2u)) || (a >= 1u && bsf_grazing_run4(pts, a - 1u)) ||
        bsf_grazing_run4(pts, a)) {
        return 1;
    }
    /* a corner turning onto the wall that starts at b, or off the one that
     * ends at a */
    if (bsf_grazing_run4(pts, b) && bsf_grazing_entry(p, a, b, b + 1u) &&
        bsf_grazing_within(p, a, b + 2u, cap)) {
        return 1;
    }
    return a >= 3u && bsf_grazing_run4(pts, a - 3u) && bsf_grazing_entry(p, b, a, a - 1u) &&
           bsf_grazing_within(p, b, a - 2u, cap);
}

int bsf_grazing_join(const bsf_points_t *pts, size_t a, float cap, int at_corners, uint8_t *memo)
{
#if BSF_CONFIG_COMPACT /* compact: no memo (the extractor passes none) */
    (void)memo;
    return grazing_join_verdict(pts, a, cap, at_corners);
#else
    const unsigned shift = 2u * (unsigned)(a % 4u);
    unsigned v;
    if (memo == NULL) {
        return grazing_join_verdict(pts, a, cap, at_corners);
    }
    v = (memo[a / 4u] >> shift) & 3u;
    if (v == 0u) {
        v = 1u + (unsigned)grazing_join_verdict(pts, a, cap, at_corners);
        memo[a / 4u] = (uint8_t)(memo[a / 4u] | (v << shift));
    }
    return (int)v - 1;
#endif
}

void bsf_grazing_memo_forget(uint8_t *memo, size_t m, size_t count)
{
    /* The verdict on step a reads beams a - 5 .. a + 6 (the corner runs
     * from a - 2 .. a + 3, each three beams either side). */
    size_t a = m >= 6u ? m - 6u : 0u;
    for (; a <= m + 5u && a < count; ++a) {
        memo[a / 4u] = (uint8_t)(memo[a / 4u] & ~(3u << (2u * (a % 4u))));
    }
}
