/* SPDX-License-Identifier: MIT */
/* LC, the line-corner detector (include/bsf/bsf_lc.h explains the method). */
#include "bsf/bsf_lc.h"
#include "bsf_grazing.h"
#include "bsf_math.h"

#include <float.h>
#include <math.h>
#include <string.h>

/* Split-judge passes per run: each pass after the first only re-judges the
 * neighbours of merged splits, and a run rarely needs more than three. */
#define LC_MAX_PASSES 8u
/* sqrt(1.5) * sqrt(2/pi): mean |distance of a point from its neighbours'
 * chord| per unit of Gaussian noise normal to a straight wall. */
#define LC_NOISE_MEAN_ABS 0.9772f
/* Single distances above this do not count towards the noise estimate
 * (corners and jumps inside a run), metres. */
#define LC_NOISE_CLIP 0.05f
/* A circle is only a candidate shape when its radius is below this multiple
 * of the window's extent: a larger one is a line in float arithmetic. */
#define LC_CIRCLE_MAX_RADIUS 10.0f

bsf_lc_params_t bsf_lc_params_default(void)
{
    bsf_lc_params_t p;
    p.jump_a = 0.2f;
    p.jump_b = 0.07f;
    p.split_min = 0.02f;
    p.split_sigmas = 4.0f;
    p.min_turn = 0.15f;
    p.curve_ratio = 10.0f;
    p.floor = 0.003f;
    p.max_side = 1.5f;
    p.apex_slack = 0.05f;
    p.min_side_points = 3u;
    p.min_side_len = 0.15f;
    /* No range limit of its own: a corner needs min_side_points points per
     * side within max_side of the apex, so the beam spacing, not the range,
     * decides how far corners are found (about 57 m at 0.5 deg beams). */
    p.max_range = FLT_MAX;
    p.join_grazing = 0u;
    return p;
}

bsf_status_t bsf_lc_params_check(const bsf_lc_params_t *p)
{
    if (p == NULL) {
        return BSF_ERR_ARG;
    }
    /* Written so that NaN fails every test. */
    if (!(p->jump_a > 0.0f && p->jump_a <= 1e3f) || !(p->jump_b >= 0.0f && p->jump_b <= 10.0f) ||
        !(p->split_min > 0.0f && p->split_min <= 1e3f) ||
        !(p->split_sigmas >= 0.0f && p->split_sigmas <= 1e3f) ||
        !(p->min_turn > 0.0f && p->min_turn < 1.5707963f) ||
        !(p->curve_ratio > 0.0f && p->curve_ratio <= 1e6f) ||
        !(p->floor >= 0.0f && p->floor <= 1e3f) || !(p->max_side > 0.0f && p->max_side <= 1e3f) ||
        !(p->apex_slack >= 0.0f && p->apex_slack <= 1e3f) ||
        !(p->min_side_len >= 0.0f && p->min_side_len <= 1e3f) || !(p->max_range > 0.0f) ||
        p->min_side_points < 2u || p->min_side_points > 64u || p->join_grazing > 1u) {
        return BSF_ERR_PARAM;
    }
    return BSF_OK;
}

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
    float tol;            /* the run's split tolerance (detect_run) */
    const uint8_t *split; /* the run's splits before any merge, by position */
#if !BSF_CONFIG_COMPACT
    /* room for block summaries of the current run, or NULL (short runs);
     * built when a judge first needs them */
    bsf_lc_block_t *blk;
    int blk_built;
#endif
} lc_ctx_t;

/* Run point pos relative to the origin, also stored for the fits: judge's
 * side walks visit every point of the window a0..b1 this way first. */
static bsf_point_t rel_store(const lc_ctx_t *c, size_t pos)
{
    bsf_point_t q = c->pts->pt[c->run[pos]];
    q.x -= c->o.x;
    q.y -= c->o.y;
    c->rel[pos] = q;
    return q;
}

static float dist2(bsf_point_t a, bsf_point_t b)
{
    const float dx = a.x - b.x;
    const float dy = a.y - b.y;
    return dx * dx + dy * dy;
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
    for (i = from; i <= b; ++i) {
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
    for (i = a; i <= b; ++i) {
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

static int fit_line(const lc_ctx_t *c, size_t a, size_t b, lc_line_t *l)
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

/* Squared residual of the best circle through positions a..b (algebraic fit,
 * then geometric distances), or -1 when no sensible circle exists. */
static float circle_rss(const lc_ctx_t *c, size_t a, size_t b, float cx0, float cy0, float extent,
                        const lc_enough_t *enough)
{
    const bsf_point_t *rp = c->rel;
    float sxx = 0.0f, sxy = 0.0f, syy = 0.0f, sx = 0.0f, sy = 0.0f;
    float sxz = 0.0f, syz = 0.0f, sz = 0.0f;
    float n = 0.0f;
    float det, d, e, f, cx, cy, r2, r, rss = 0.0f;
    size_t i;
    for (i = a; i <= b; ++i) {
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
        n += 1.0f;
    }
    /* Solve [sxx sxy sx; sxy syy sy; sx sy n] (d e f) = -(sxz syz sz) by Cramer. */
    det = sxx * (syy * n - sy * sy) - sxy * (sxy * n - sy * sx) + sx * (sxy * sy - syy * sx);
    if (!(fabsf(det) > 0.0f)) {
        return -1.0f;
    }
    d = (-sxz * (syy * n - sy * sy) + sxy * (syz * n - sy * sz) - sx * (syz * sy - syy * sz)) / det;
    e = (sxx * (-syz * n + sy * sz) + sxz * (sxy * n - sy * sx) + sx * (-sxy * sz + syz * sx)) /
        det;
    f = (sxx * (-syy * sz + syz * sy) - sxy * (-sxy * sz + syz * sx) -
         sxz * (sxy * sy - syy * sx)) /
        det;
    cx = -0.5f * d;
    cy = -0.5f * e;
    r2 = cx * cx + cy * cy - f;
    if (!(r2 > 0.0f) || !(r2 < LC_CIRCLE_MAX_RADIUS * LC_CIRCLE_MAX_RADIUS * extent * extent)) {
        return -1.0f;
    }
    r = sqrtf(r2);
    for (i = a; i <= b; ++i) {
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
    extent = sqrtf(dist2(c->rel[a], c->rel[b]));
    enough.scale = line_dof;
    enough.ratio = c->p->curve_ratio;
    enough.floor_rss = floor_rss;
    enough.target = l->rss * (float)(n - 3u); /* straight from there on */
    rss_circle = circle_rss(c, a, b, l->mx, l->my, extent, &enough);
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

/* Whether positions strictly between apex and end hold a split of the run
 * (c->split: every split before any merge). */
static int side_crosses_split(const lc_ctx_t *c, size_t apex, size_t end)
{
    size_t i = (end < apex ? end : apex) + 1u;
    const size_t stop = end < apex ? apex : end;
    while (i < stop && !c->split[i]) {
        ++i;
    }
    return i < stop;
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

/* A side ends where the wall it measures ends: walking in from its far
 * end, points farther than the run's split tolerance from the side's line
 * lie on the next surface (a side longer than a face reaches round the
 * neighbouring corner once the split there has been merged, and a few such
 * points spoil the line's residual and hide both corners). Returns the new
 * far end, between near and far. */
static size_t side_end_on_line(const lc_ctx_t *c, const lc_line_t *l, size_t near, size_t far)
{
    while (far != near) {
        const float ex = c->rel[far].x - l->mx;
        const float ey = c->rel[far].y - l->my;
        if (!(fabsf(ex * l->dy - ey * l->dx) > c->tol)) {
            break;
        }
        far = far > near ? far - 1u : far + 1u;
    }
    return far;
}

/* A side cut by side_end_on_line still long enough for judge's tests:
 * need points from the apex (one fewer at the run's end) and len2 squared
 * metres. */
static int side_long_enough(const lc_ctx_t *c, size_t apex, size_t end, size_t need, size_t m,
                            float len2)
{
    const size_t count =
        end < apex ? apex - end + (end == 0u ? 1u : 0u) : end - apex + (end + 1u == m ? 1u : 0u);
    return count >= need && dist2(c->rel[end], c->rel[apex]) >= len2;
}

/* Side a0..apex-1 (left, *end = a0) or apex+1..b1 (right, *end = b1) with
 * its fitted line *l, cut at the end of its wall (side_end_on_line) and
 * refitted when it crosses a split and what is left is still a side.
 * Returns 1 when cut, else 0. */
static int side_cut(const lc_ctx_t *c, size_t apex, size_t *end, size_t need, size_t m, float len2,
                    lc_line_t *l)
{
    const int left = *end < apex;
    const size_t near = left ? apex - 1u : apex + 1u;
    const size_t cut = side_end_on_line(c, l, near, *end);
    /* Only where the side crosses a split (merged since, or the neighbour
     * it reaches past): elsewhere its far end is the run's end or a corner
     * the judge already bounds it by. */
    if (cut == *end || !side_crosses_split(c, apex, *end) ||
        !side_long_enough(c, apex, cut, need, m, len2)) {
        return 0;
    }
    *end = cut;
    /* at least need >= 2 points: the fit succeeds */
    (void)(left ? fit_line(c, cut, near, l) : fit_line(c, near, cut, l));
    return 1;
}

/* Judge the split at position apex between the pieces that start at lo and
 * end at hi, in a run of m points. Returns 1 and fills *kp (beam index, intersection, ...) for a
 * corner, 0 otherwise. */
static int judge(lc_ctx_t *c, size_t lo, size_t apex, size_t hi, size_t m, bsf_keypoint_t *kp)
{
    const bsf_lc_params_t *p = c->p;
    const float side2 = p->max_side * p->max_side;
    const float len2 = p->min_side_len * p->min_side_len;
    const size_t need = p->min_side_points;
    lc_line_t la;
    lc_line_t lb;
    lc_line_t lu;
    size_t a0 = apex;
    size_t b1 = apex;
    size_t best;
    size_t i;
    const bsf_point_t *rp = c->rel;
    float cross, t, xx, xy, spacing, extent, rss_curve, rss_circle, rss_lines, lines_bound, best_d;
    lc_enough_t enough;
    bsf_point_t x;
    bsf_point_t ap;
    int blocks = 0; /* walks by blocks and the turn bound (speed builds) */

    if (!(c->pts->range[c->run[apex]] <= p->max_range)) {
        return 0;
    }
    c->o = c->pts->pt[c->run[apex]];
    ap = rel_store(c, apex);
    blocks = blocks_use(c, apex, m, side2);
    a0 = walk(c, blocks, apex, lo, -1, side2);
    b1 = walk(c, blocks, apex, hi, 1, side2);
    /* A side cut short by a neighbouring split reaches past it: noise often
     * splits a corner several times within a few points, and the true apex
     * must not lose to its own echoes (a side that then crosses another
     * corner fails the straightness test). */
    if (apex - a0 < need || dist2(rp[a0], ap) < len2) {
        a0 = walk(c, blocks, a0, 0u, -1, side2);
    }
    if (b1 - apex < need || dist2(rp[b1], ap) < len2) {
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
        return 0;
    }
    /* Each side must also be long enough to give its line a direction. */
    if (dist2(rp[a0], ap) < len2 || dist2(rp[b1], ap) < len2) {
        return 0;
    }
    if (blocks_rule_out(c, blocks, a0, apex, b1)) {
        return 0;
    }
    if (!fit_line(c, a0, apex - 1u, &la) || !fit_line(c, apex + 1u, b1, &lb)) {
        return 0;
    }
    cross = la.dx * lb.dy - la.dy * lb.dx;
    if (!(fabsf(cross) >= c->sin_min_turn)) {
        return 0;
    }
    /* After the turn test, so the block path's turn bound (on the uncut
     * sides) stays exact; a cut side must still turn. */
    if ((side_cut(c, apex, &a0, need, m, len2, &la) | side_cut(c, apex, &b1, need, m, len2, &lb)) !=
        0) {
        cross = la.dx * lb.dy - la.dy * lb.dx;
        if (!(fabsf(cross) >= c->sin_min_turn)) {
            return 0;
        }
    }
    t = ((lb.mx - la.mx) * lb.dy - (lb.my - la.my) * lb.dx) / cross;
    xx = la.mx + t * la.dx;
    xy = la.my + t * la.dy;
    x.x = xx;
    x.y = xy;
    spacing = sqrtf(dist2(rp[apex - 1u], ap));
    {
        const float s2 = sqrtf(dist2(rp[apex + 1u], ap));
        spacing = s2 > spacing ? s2 : spacing;
    }
    if (!(xx * xx + xy * xy <=
          (2.0f * spacing + p->apex_slack) * (2.0f * spacing + p->apex_slack))) {
        return 0;
    }
    /* One smooth curve over both sides: the better of a line and a circle. */
    /* (the left side's sums are the first part of the whole's) */
    if (!fit_line_from(c, a0, b1, apex, la.sx, la.sy, &lu)) {
        return 0;
    }
    rss_lines = la.rss + lb.rss;
    lines_bound = p->curve_ratio * rss_lines + (float)(b1 - a0 + 1u) * p->floor * p->floor;
    /* The curve's residual is at most the line's: when the line already
     * fails the test, so does the curve, and no circle is fitted. */
    if (!(lu.rss > lines_bound)) {
        return 0;
    }
    extent = sqrtf(dist2(rp[a0], rp[b1]));
    rss_curve = lu.rss;
    enough.scale = 1.0f; /* 1 * x is x: the plain comparison */
    enough.ratio = 1.0f;
    enough.floor_rss = 0.0f;
    enough.target = lu.rss; /* from there on, the line is the better curve */
    rss_circle = circle_rss(c, a0, b1, lu.mx, lu.my, extent, &enough);
    if (rss_circle >= 0.0f && rss_circle < rss_curve) {
        rss_curve = rss_circle;
    }
    if (!(rss_curve > lines_bound)) {
        return 0;
    }
    /* Each side must be straight: a circle may not explain it much better
     * than its line (a crease between two curved walls is no wall corner,
     * and its line intersection would lie off the crease). Last, as the
     * dearest test. */
    if (!side_straight(c, a0, apex - 1u, &la) || !side_straight(c, apex + 1u, b1, &lb)) {
        return 0;
    }
    /* The vertex beam: the point nearest the intersection, near the split. */
    best = apex;
    best_d = dist2(ap, x);
    for (i = apex - 2u; i <= apex + 2u; ++i) {
        if (i > a0 && i < b1) {
            const float d = dist2(rp[i], x);
            if (d < best_d) {
                best_d = d;
                best = i;
            }
        }
    }
    kp->index = c->run[best];
    kp->point.x = xx + c->o.x;
    kp->point.y = xy + c->o.y;
    kp->orientation = bsf_atan2f(la.my + lb.my - 2.0f * xy, la.mx + lb.mx - 2.0f * xx);
    {
        const float ra = sqrtf(dist2(rp[a0], ap));
        const float rb = sqrtf(dist2(rp[b1], ap));
        kp->radius = ra > rb ? ra : rb;
    }
    kp->score = rss_lines > 0.0f ? rss_curve / rss_lines : 1e30f;
    return 1;
}

/* Noise normal to the surface, from each point's distance to the chord of
 * its two neighbours. */
static float run_noise(const bsf_points_t *pts, const uint16_t *run, size_t m)
{
    float sum = 0.0f;
    size_t n = 0;
    size_t i;
    bsf_point_t a;
    bsf_point_t q;
    if (m < 3u) {
        return 0.0f;
    }
    a = pts->pt[run[0]];
    q = pts->pt[run[1]];
    for (i = 1; i + 1u < m; ++i) {
        const bsf_point_t b = pts->pt[run[i + 1u]];
        const float ex = b.x - a.x;
        const float ey = b.y - a.y;
        const float len = sqrtf(ex * ex + ey * ey);
        if (len > 0.0f) {
            const float d = fabsf(ex * (q.y - a.y) - ey * (q.x - a.x)) / len;
            if (d <= LC_NOISE_CLIP) {
                sum += d;
                ++n;
            }
        }
        a = q; /* the window moves by one point */
        q = b;
    }
    return n > 0u ? sum / ((float)n * LC_NOISE_MEAN_ABS) : 0.0f;
}

/* Douglas-Peucker split of run positions 0..m-1 with an explicit stack;
 * returns the number of splits, ascending in w->brk. */

static size_t split_run(const bsf_points_t *pts, bsf_lc_work_t *w, size_t m, float tol)
{
    size_t top = 0;
    size_t nb = 0;
    size_t i;
    memset(w->is_brk, 0, m);
    w->stack_a[top] = 0u;
    w->stack_b[top] = (uint16_t)(m - 1u);
    ++top;
    while (top > 0u) {
        const size_t a = w->stack_a[--top];
        const size_t b = w->stack_b[top];
        const bsf_point_t pa = pts->pt[w->run[a]];
        const bsf_point_t pb = pts->pt[w->run[b]];
        const float ex = pb.x - pa.x;
        const float ey = pb.y - pa.y;
        const float len = sqrtf(ex * ex + ey * ey);
        float dmax = 0.0f;
        size_t imax = a;
        if (b < a + 2u) {
            continue;
        }
        if (len > 0.0f) {
            for (i = a + 1u; i < b; ++i) {
                const bsf_point_t q = pts->pt[w->run[i]];
                const float d = fabsf(ex * (q.y - pa.y) - ey * (q.x - pa.x)) / len;
                if (d > dmax) {
                    dmax = d;
                    imax = i;
                }
            }
        } else {
            for (i = a + 1u; i < b; ++i) {
                const float d = sqrtf(dist2(pts->pt[w->run[i]], pa));
                if (d > dmax) {
                    dmax = d;
                    imax = i;
                }
            }
        }
        if (dmax > tol) {
            w->is_brk[imax] = 1u;
            /* Each pushed piece is a strict sub-range with disjoint interior,
             * so the stack never holds more than m entries. */
            w->stack_a[top] = (uint16_t)a;
            w->stack_b[top] = (uint16_t)imax;
            ++top;
            w->stack_a[top] = (uint16_t)imax;
            w->stack_b[top] = (uint16_t)b;
            ++top;
        }
    }
    for (i = 0; i < m; ++i) {
        if (w->is_brk[i]) {
            w->brk[nb++] = (uint16_t)i;
        }
    }
    return nb;
}

/* Two keypoints of one run on one corner: beams closer than the points a
 * side needs, or intersections within apex_slack of each other. */
static int too_close(const bsf_keypoint_t *a, const bsf_keypoint_t *b, const bsf_lc_params_t *p)
{
    return (size_t)a->index + p->min_side_points >= (size_t)b->index ||
           dist2(a->point, b->point) <= p->apex_slack * p->apex_slack;
}

/* Append kp, or merge it into the previous keypoint of the same run (from
 * index first on) when both sit on one corner, keeping the sharper. *last
 * mirrors the previous keypoint even when out is full, so the count does not
 * depend on out_cap. */
static void keep(bsf_keypoint_t *out, size_t out_cap, size_t *n, size_t first, bsf_keypoint_t *last,
                 const bsf_keypoint_t *kp, const bsf_lc_params_t *p)
{
    if (*n > first && too_close(last, kp, p)) {
        if (kp->score > last->score) {
            *last = *kp;
            if (*n - 1u < out_cap) {
                out[*n - 1u] = *kp;
            }
        }
        return;
    }
    if (*n < out_cap) {
        out[*n] = *kp;
    }
    *last = *kp;
    ++*n;
}

/* Corners of one run: split, then merge the splits that are no corner until
 * the survivors all pass. */
static void detect_run(lc_ctx_t *c, bsf_lc_work_t *w, size_t m, bsf_keypoint_t *out, size_t out_cap,
                       size_t *n_found)
{
    const float sigma = run_noise(c->pts, w->run, m);
    float tol = c->p->split_sigmas * sigma;
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
    c->tol = tol;
    c->split = w->is_brk;
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
             * stays one, with its keypoint still parked. */
            if (w->judged_lo[j] == lo && w->judged_hi[j] == hi) {
                ++j;
            } else if (!judge(c, lo, w->brk[j], hi, m, &kp)) {
                const size_t tail = nb - j - 1u;
                const size_t slot = *n_found + j;
                memmove(&w->brk[j], &w->brk[j + 1u], tail * sizeof w->brk[0]);
                memmove(&w->judged_lo[j], &w->judged_lo[j + 1u], tail * sizeof w->judged_lo[0]);
                memmove(&w->judged_hi[j], &w->judged_hi[j + 1u], tail * sizeof w->judged_hi[0]);
                if (slot + 1u < out_cap) {
                    const size_t fit = out_cap - slot - 1u;
                    memmove(&out[slot], &out[slot + 1u], (tail < fit ? tail : fit) * sizeof out[0]);
                }
                --nb;
                changed = 1;
            } else {
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
    if (!changed) {
        /* The last pass judged every survivor with its final neighbours:
         * its keypoints stand. */
        const size_t base = *n_found;
        for (j = 0; j < nb; ++j) {
            const size_t parked = base + j; /* never below the next slot written */
            if (parked < out_cap) {
                kp = out[parked];
            } else {
                const size_t lo = j == 0u ? 0u : w->brk[j - 1u];
                const size_t hi = j + 1u < nb ? w->brk[j + 1u] : m - 1u;
                if (!judge(c, lo, w->brk[j], hi, m, &kp)) {
                    continue; /* cannot happen: same judgement as in the pass */
                }
            }
            keep(out, out_cap, n_found, first, &last, &kp, c->p);
        }
        return;
    }
    for (j = 0; j < nb; ++j) {
        const size_t lo = j == 0u ? 0u : w->brk[j - 1u];
        const size_t hi = j + 1u < nb ? w->brk[j + 1u] : m - 1u;
        if (judge(c, lo, w->brk[j], hi, m, &kp)) {
            keep(out, out_cap, n_found, first, &last, &kp, c->p);
        }
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
 * look-back keeps such a wall one segment too). Else returns i. One
 * exponential per jump: the radius is taken at a's range. */
static size_t past_occluder(const bsf_points_t *pts, const bsf_lc_params_t *p, size_t a, size_t i)
{
    const size_t span = 2u * (size_t)p->min_side_points;
    float r2 = -1.0f; /* computed once, when a point is beyond jump_a */
    size_t j;
    for (j = i + 1u; j <= i + span && j < pts->count; ++j) {
        if (pts->valid[j]) {
            const float d2 = dist2(pts->pt[a], pts->pt[j]);
            if (d2 > p->jump_a * p->jump_a && r2 < 0.0f) {
                const float r = p->jump_a * bsf_expf(p->jump_b * pts->range[a]);
                r2 = r * r;
            }
            if (d2 <= p->jump_a * p->jump_a || d2 <= r2) {
                return j;
            }
        }
    }
    return i;
}

bsf_status_t bsf_lc_detect(const bsf_points_t *pts, const bsf_lc_params_t *p, bsf_lc_work_t *work,
                           bsf_keypoint_t *out, size_t out_cap, size_t *n_out)
{
    lc_ctx_t c;
    bsf_status_t st;
    size_t n_found = 0;
    size_t m = 0;
    size_t i;
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
    c.tol = p->split_min;
    c.split = work->is_brk;
    blocks_detach(&c);
    for (i = 0; i <= pts->count; ++i) {
        int close_run = i == pts->count;
        if (!close_run && !pts->valid[i]) {
            continue;
        }
        if (!close_run && m > 0u) {
            close_run = !within_jump(pts, p, work->run[m - 1u], i) &&
                        !(p->join_grazing && work->run[m - 1u] + 1u == i &&
                          bsf_grazing_join(pts, i - 1u, BSF_GRAZING_LC_CAP));
            if (close_run) {
                const size_t j = past_occluder(pts, p, work->run[m - 1u], i);
                if (j > i) {
                    i = j - 1u; /* the run resumes at j */
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
        if (i < pts->count) {
            work->run[m++] = (uint16_t)i;
        }
    }
    *n_out = n_found;
    return n_found > out_cap ? BSF_ERR_CAPACITY : BSF_OK;
}
