/* SPDX-License-Identifier: MIT */
/*
 * bsf_align.c - align one scan to the fused map: Gauss-Newton on
 * point-to-chord distances with a Huber loss, vertex anchors, and the
 * directions the geometry leaves free kept at the prior.
 *
 * All geometry is local to the prior's position so that floats keep their
 * precision far from the world origin.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf_align.h"
#include "bsf/bsf_stream.h"
#include "bsf_map_internal.h"
#include "bsf_math.h"

/* A point farther than this from the sensor is refused (10 km). */
#define ALIGN_POINT_MAX 10000.0f
/* A span whose curve passes this close to its chord is one chord, else two. */
#define ALIGN_STRAIGHT_TOL 0.005f
/* Step below which Gauss-Newton has converged (metres, scaled radians). */
#define ALIGN_STEP_DONE 5e-4f
#define ALIGN_JACOBI_SWEEPS 8
/* Feature curves are sampled about this often (metres), at most so many per span. */
#define ALIGN_SAMPLE_SPACING 0.05f
#define ALIGN_SAMPLES_PER_SPAN 16u
/* Share of max_dist the correspondence gate shrinks to; residuals are capped
 * at it when the aligned pose is compared with the prior. */
#define ALIGN_GATE_LAST 0.25f

void bsf_align_params_default(bsf_align_params_t *p)
{
    p->max_dist = 0.8f;
    p->huber = 0.03f;
    p->max_xy = 0.5f;
    p->max_theta = 0.2f;
    p->vertex_weight = 4.0f;
    p->theta_scale = 1.0f;
    p->free_ratio = 0.005f;
    p->free_min = 3.0f;
    p->max_iter = 10u;
    p->max_points = 80u;
    p->min_matches = 12u;
}

const char *bsf_align_decline_str(int declined)
{
    switch (declined) {
    case BSF_ALIGN_ACCEPTED: return "accepted";
    case BSF_ALIGN_DECLINE_FEW_POINTS: return "few points";
    case BSF_ALIGN_DECLINE_EMPTY_MAP: return "no map near the prior";
    case BSF_ALIGN_DECLINE_FEW_MATCHES: return "few correspondences";
    case BSF_ALIGN_DECLINE_TOO_LARGE: return "correction too large";
    case BSF_ALIGN_DECLINE_DIVERGED: return "diverged";
    case BSF_ALIGN_DECLINE_UNDETERMINED: return "undetermined";
    case BSF_ALIGN_DECLINE_NO_BETTER: return "no better than the prior";
    default: return "unknown";
    }
}

/* Whether lo <= v <= hi (false for NaN). */
static int in_range(float v, float lo, float hi)
{
    return v >= lo && v <= hi;
}

static int params_ok(const bsf_align_params_t *p)
{
    return in_range(p->max_dist, 1e-6f, 2.0f) && in_range(p->huber, 1e-6f, 1.0f) &&
           in_range(p->max_xy, 1e-6f, 10.0f) && in_range(p->max_theta, 1e-6f, 1.0f) &&
           in_range(p->vertex_weight, 0.0f, 100.0f) && in_range(p->theta_scale, 1e-6f, 100.0f) &&
           in_range(p->free_ratio, 0.0f, 0.999f) && in_range(p->free_min, 0.0f, 1e9f) &&
           p->max_iter >= 1u && p->max_iter <= 50u && p->max_points >= 3u &&
           p->max_points <= BSF_ALIGN_MAX_POINTS && p->min_matches >= 3u &&
           p->min_matches <= p->max_points;
}

static int prior_ok(const bsf_pose_t *q)
{
    return in_range(q->x, -BSF_POSE_XY_MAX, BSF_POSE_XY_MAX) &&
           in_range(q->y, -BSF_POSE_XY_MAX, BSF_POSE_XY_MAX) &&
           in_range(q->theta, -BSF_POSE_THETA_MAX, BSF_POSE_THETA_MAX);
}

static int point_ok(bsf_point_t p)
{
    return in_range(p.x, -ALIGN_POINT_MAX, ALIGN_POINT_MAX) &&
           in_range(p.y, -ALIGN_POINT_MAX, ALIGN_POINT_MAX);
}

/* ---- Curve samples ---------------------------------------------------------- */

/* Points of one span of a clamped uniform quadratic B-spline with control
 * points q0, q1, q2: s0 at its start (u = 0), sm at u = 1/2, s1 at its end.
 * first / last: the chain's first / last span (their weights differ). */
static void span_points(bsf_point_t q0, bsf_point_t q1, bsf_point_t q2, int first, int last,
                        bsf_point_t *s0, bsf_point_t *sm, bsf_point_t *s1)
{
    float w0;
    float w1;
    float w2;
    if (first && last) {
        w0 = 0.25f, w1 = 0.5f, w2 = 0.25f;
    } else if (first) {
        w0 = 0.25f, w1 = 0.625f, w2 = 0.125f;
    } else if (last) {
        w0 = 0.125f, w1 = 0.625f, w2 = 0.25f;
    } else {
        w0 = 0.125f, w1 = 0.75f, w2 = 0.125f;
    }
    sm->x = w0 * q0.x + w1 * q1.x + w2 * q2.x;
    sm->y = w0 * q0.y + w1 * q1.y + w2 * q2.y;
    if (first) {
        *s0 = q0;
    } else {
        s0->x = 0.5f * (q0.x + q1.x);
        s0->y = 0.5f * (q0.y + q1.y);
    }
    if (last) {
        *s1 = q2;
    } else {
        s1->x = 0.5f * (q1.x + q2.x);
        s1->y = 0.5f * (q1.y + q2.y);
    }
}

/* Whether the span's curve stays within ALIGN_STRAIGHT_TOL of its chord s0-s1
 * (its mid point is the farthest one). */
static int span_straight(bsf_point_t s0, bsf_point_t sm, bsf_point_t s1)
{
    const float dx = s1.x - s0.x;
    const float dy = s1.y - s0.y;
    const float cr = dx * (sm.y - s0.y) - dy * (sm.x - s0.x);
    return cr * cr <= ALIGN_STRAIGHT_TOL * ALIGN_STRAIGHT_TOL * (dx * dx + dy * dy);
}

/* ---- Grid ------------------------------------------------------------------- */

static int cell_of(const bsf_align_work_t *w, float x, float y, int *cx, int *cy)
{
    const float fx = (x - w->grid_x0) * w->inv_cell;
    const float fy = (y - w->grid_y0) * w->inv_cell;
    if (!(fx >= 0.0f && fy >= 0.0f && fx < (float)BSF_ALIGN_GRID && fy < (float)BSF_ALIGN_GRID)) {
        return 0;
    }
    *cx = (int)fx;
    *cy = (int)fy;
    return 1;
}

/* Cell range of the box [x0, x1] x [y0, y1] clamped to the grid; 0 when
 * the box misses the grid. */
static int cell_range(const bsf_align_work_t *w, float x0, float y0, float x1, float y1, int r[4])
{
    float a = (x0 - w->grid_x0) * w->inv_cell;
    float b = (x1 - w->grid_x0) * w->inv_cell;
    float c = (y0 - w->grid_y0) * w->inv_cell;
    float d = (y1 - w->grid_y0) * w->inv_cell;
    const float top = (float)BSF_ALIGN_GRID - 1.0f;
    if (b < 0.0f || d < 0.0f || a > top + 1.0f || c > top + 1.0f) {
        return 0;
    }
    a = a < 0.0f ? 0.0f : (a > top ? top : a);
    b = b < 0.0f ? 0.0f : (b > top ? top : b);
    c = c < 0.0f ? 0.0f : (c > top ? top : c);
    d = d < 0.0f ? 0.0f : (d > top ? top : d);
    r[0] = (int)a;
    r[1] = (int)c;
    r[2] = (int)b;
    r[3] = (int)d;
    return 1;
}

/* Lay the grid over the scan at the prior (local frame) and mark the cells
 * within `dil` of a scan point. */
static void grid_mark(bsf_align_work_t *w, float c0, float s0, float dil, float min_cell)
{
    float x0 = 0.0f;
    float y0 = 0.0f;
    float x1 = 0.0f;
    float y1 = 0.0f;
    float ext;
    uint16_t i;
    for (i = 0; i < w->n_pts; ++i) {
        const float qx = c0 * w->pts[i].x - s0 * w->pts[i].y;
        const float qy = s0 * w->pts[i].x + c0 * w->pts[i].y;
        x0 = qx < x0 ? qx : x0;
        y0 = qy < y0 ? qy : y0;
        x1 = qx > x1 ? qx : x1;
        y1 = qy > y1 ? qy : y1;
    }
    x0 -= dil;
    y0 -= dil;
    x1 += dil;
    y1 += dil;
    ext = (x1 - x0) > (y1 - y0) ? (x1 - x0) : (y1 - y0);
    w->cell = ext / (float)BSF_ALIGN_GRID * 1.0001f;
    if (w->cell < min_cell) {
        w->cell = min_cell;
    }
    w->inv_cell = 1.0f / w->cell;
    w->grid_x0 = x0;
    w->grid_y0 = y0;
    memset(w->mark, 0, sizeof w->mark);
    for (i = 0; i < w->n_pts; ++i) {
        const float qx = c0 * w->pts[i].x - s0 * w->pts[i].y;
        const float qy = s0 * w->pts[i].x + c0 * w->pts[i].y;
        int r[4];
        int cx;
        int cy;
        if (!cell_range(w, qx - dil, qy - dil, qx + dil, qy + dil, r)) {
            continue;
        }
        for (cy = r[1]; cy <= r[3]; ++cy) {
            for (cx = r[0]; cx <= r[2]; ++cx) {
                w->mark[cy * BSF_ALIGN_GRID + cx] = 1u;
            }
        }
    }
}

/* Whether a chord a-b, widened by `gate`, touches a marked cell. */
static int chord_marked(const bsf_align_work_t *w, bsf_point_t a, bsf_point_t b, float gate)
{
    int r[4];
    int cx;
    int cy;
    if (!cell_range(w, (a.x < b.x ? a.x : b.x) - gate, (a.y < b.y ? a.y : b.y) - gate,
                    (a.x > b.x ? a.x : b.x) + gate, (a.y > b.y ? a.y : b.y) + gate, r)) {
        return 0;
    }
    for (cy = r[1]; cy <= r[3]; ++cy) {
        for (cx = r[0]; cx <= r[2]; ++cx) {
            if (w->mark[cy * BSF_ALIGN_GRID + cx]) {
                return 1;
            }
        }
    }
    return 0;
}

/* Keep chord a-b (local frame) when it is near the scan; 1 when a cap cut it. */
static int add_chord(bsf_align_work_t *w, bsf_point_t a, bsf_point_t b, float gate)
{
    bsf_align_seg_t *s;
    const float dx = b.x - a.x;
    const float dy = b.y - a.y;
    const float len = sqrtf(dx * dx + dy * dy);
    if (!(len > 1e-6f) || !chord_marked(w, a, b, gate)) {
        return 0;
    }
    if (w->n_segs >= BSF_ALIGN_MAX_SEGS) {
        return 1;
    }
    s = &w->segs[w->n_segs++];
    s->ax = a.x;
    s->ay = a.y;
    s->ux = dx / len;
    s->uy = dy / len;
    s->len = len;
    return 0;
}

/* Whether the local point (x, y) lies in a marked cell. */
static int near_scan(const bsf_align_work_t *w, float x, float y)
{
    int cx;
    int cy;
    return cell_of(w, x, y, &cx, &cy) && w->mark[cy * BSF_ALIGN_GRID + cx];
}

/* Next control point of a map chain with its vertex given twice, local
 * frame: *idx is the pool index, *rep how many copies of it were given; a
 * vertex near the scan is added to w->mverts at its first copy (*cut set
 * when they are full). 0 at the end of the chain. */
static int chain_next(bsf_align_work_t *w, const bsf_map_t *m, uint16_t *idx, uint8_t *rep,
                      bsf_point_t org, bsf_point_t *out, int *cut)
{
    const bsf_map_ctrl_t *c;
    int vtx;
    if (*idx == BSF_MAP_NONE || *idx >= BSF_MAP_MAX_CTRL) {
        return 0;
    }
    c = &m->ctrl[*idx];
    out->x = c->x - org.x;
    out->y = c->y - org.y;
    vtx = (c->flags & BSF_MAP_CF_VERTEX) != 0u;
    if (vtx && *rep == 0u && near_scan(w, out->x, out->y)) {
        if (w->n_mverts < BSF_ALIGN_MAX_VERTICES) {
            w->mverts[w->n_mverts++] = *out;
        } else {
            *cut = 1;
        }
    }
    ++*rep;
    if (!vtx || *rep >= 2u) {
        *idx = c->next;
        *rep = 0u;
    }
    return 1;
}

/* Collect the map's chords and vertices near the scan (local frame) into w;
 * returns 1 when a cap cut them. A span is sampled only when one of its
 * three control points lies in a marked cell: the marks reach at least
 * max_xy + max_dist / 2 beyond the scan points (whole cells), which covers
 * the spans of the chords a point can be matched to through the grid
 * (their control points lie within a span's length of the chord, and map
 * spans are a few decimetres). */
static int collect_map(bsf_align_work_t *w, const bsf_map_t *m, bsf_point_t org, float gate)
{
    const float bx0 = w->grid_x0 + org.x - gate;
    const float by0 = w->grid_y0 + org.y - gate;
    const float bx1 = w->grid_x0 + org.x + (float)BSF_ALIGN_GRID * w->cell + gate;
    const float by1 = w->grid_y0 + org.y + (float)BSF_ALIGN_GRID * w->cell + gate;
    int cut = 0;
    uint16_t fi;
    w->n_segs = 0;
    w->n_mverts = 0;
    for (fi = 0; fi < m->n_features && fi < BSF_MAP_MAX_FEATURES; ++fi) {
        const bsf_map_feature_t *f = &m->features[fi];
        bsf_point_t q[3];
        int near[3];
        bsf_point_t prev;
        uint16_t idx = f->head;
        uint8_t rep = 0u;
        long s;
        if (f->max_x < bx0 || f->min_x > bx1 || f->max_y < by0 || f->min_y > by1) {
            continue;
        }
        if (!chain_next(w, m, &idx, &rep, org, &q[0], &cut) ||
            !chain_next(w, m, &idx, &rep, org, &q[1], &cut)) {
            continue;
        }
        near[0] = near_scan(w, q[0].x, q[0].y);
        near[1] = near_scan(w, q[1].x, q[1].y);
        prev = q[0];
        /* bounded by the pool: every step consumes a copy of a point */
        for (s = 0; s <= 2L * BSF_MAP_MAX_CTRL; ++s) {
            bsf_point_t s0;
            bsf_point_t sm;
            bsf_point_t s1;
            int last;
            if (!chain_next(w, m, &idx, &rep, org, &q[2], &cut)) {
                break;
            }
            last = idx == BSF_MAP_NONE;
            near[2] = near_scan(w, q[2].x, q[2].y);
            if (near[0] || near[1] || near[2]) {
                span_points(q[0], q[1], q[2], s == 0, last, &s0, &sm, &s1);
                if (span_straight(s0, sm, s1)) {
                    cut |= add_chord(w, prev, s1, gate);
                } else {
                    cut |= add_chord(w, prev, sm, gate);
                    cut |= add_chord(w, sm, s1, gate);
                }
                prev = s1;
            } else if (last) {
                prev = q[2];
            } else {
                prev.x = 0.5f * (q[1].x + q[2].x);
                prev.y = 0.5f * (q[1].y + q[2].y);
            }
            q[0] = q[1];
            q[1] = q[2];
            near[0] = near[1];
            near[1] = near[2];
        }
    }
    return cut;
}

/* Grid entries of the chords (CSR by cell, each chord in the marked cells
 * its gate-widened box touches). Chords past the entry cap are dropped;
 * returns 1 when that happened. */
static int build_grid(bsf_align_work_t *w, float gate)
{
    const size_t n_cells = (size_t)BSF_ALIGN_GRID * BSF_ALIGN_GRID;
    size_t total = 0;
    size_t c;
    uint16_t i;
    int cut = 0;
    memset(w->cell_start, 0, sizeof w->cell_start);
    for (i = 0; i < w->n_segs; ++i) {
        const bsf_align_seg_t *s = &w->segs[i];
        const float bx = s->ax + s->ux * s->len;
        const float by = s->ay + s->uy * s->len;
        int r[4];
        int cx;
        int cy;
        size_t need = 0;
        if (!cell_range(w, (s->ax < bx ? s->ax : bx) - gate, (s->ay < by ? s->ay : by) - gate,
                        (s->ax > bx ? s->ax : bx) + gate, (s->ay > by ? s->ay : by) + gate, r)) {
            continue;
        }
        for (cy = r[1]; cy <= r[3]; ++cy) {
            for (cx = r[0]; cx <= r[2]; ++cx) {
                need += w->mark[cy * BSF_ALIGN_GRID + cx];
            }
        }
        if (total + need > BSF_ALIGN_MAX_ENTRIES) {
            w->n_segs = i;
            cut = 1;
            break;
        }
        total += need;
        for (cy = r[1]; cy <= r[3]; ++cy) {
            for (cx = r[0]; cx <= r[2]; ++cx) {
                w->cell_start[cy * BSF_ALIGN_GRID + cx] += w->mark[cy * BSF_ALIGN_GRID + cx];
            }
        }
    }
    /* Counts to end positions, then fill backwards to start positions. */
    total = 0;
    for (c = 0; c < n_cells; ++c) {
        total += w->cell_start[c];
        w->cell_start[c] = (uint16_t)total;
    }
    w->cell_start[n_cells] = (uint16_t)total;
    for (i = 0; i < w->n_segs; ++i) {
        const bsf_align_seg_t *s = &w->segs[i];
        const float bx = s->ax + s->ux * s->len;
        const float by = s->ay + s->uy * s->len;
        int r[4];
        int cx;
        int cy;
        if (!cell_range(w, (s->ax < bx ? s->ax : bx) - gate, (s->ay < by ? s->ay : by) - gate,
                        (s->ax > bx ? s->ax : bx) + gate, (s->ay > by ? s->ay : by) + gate, r)) {
            continue;
        }
        for (cy = r[1]; cy <= r[3]; ++cy) {
            for (cx = r[0]; cx <= r[2]; ++cx) {
                const int k = cy * BSF_ALIGN_GRID + cx;
                if (w->mark[k]) {
                    w->entries[--w->cell_start[k]] = i;
                }
            }
        }
    }
    return cut;
}

/* ---- Linear algebra ----------------------------------------------------------- */

/* Eigenvalues lam (ascending) and unit eigenvectors (columns of v, row-major
 * v[row * 3 + col]) of the symmetric 3x3 matrix a (row-major), by cyclic
 * Jacobi rotations (a fixed number of sweeps). */
static void eig3(const float a_in[9], float lam[3], float v[9])
{
    float a[9];
    int sweep;
    int i;
    int j;
    memcpy(a, a_in, sizeof a);
    for (i = 0; i < 9; ++i) {
        v[i] = (i % 4 == 0) ? 1.0f : 0.0f;
    }
    for (sweep = 0; sweep < ALIGN_JACOBI_SWEEPS; ++sweep) {
        static const int pq[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        const float off = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
        const float dia = a[0] * a[0] + a[4] * a[4] + a[8] * a[8];
        int r;
        if (!(off > 1e-14f * dia)) {
            break;
        }
        for (r = 0; r < 3; ++r) {
            const int p = pq[r][0];
            const int q = pq[r][1];
            const float apq = a[p * 3 + q];
            float th;
            float t;
            float c;
            float s;
            int k;
            if (apq == 0.0f) {
                continue;
            }
            th = (a[q * 3 + q] - a[p * 3 + p]) / (2.0f * apq);
            if (fabsf(th) > 1e6f) {
                t = 0.5f / th;
            } else {
                t = 1.0f / (fabsf(th) + sqrtf(th * th + 1.0f));
                t = th < 0.0f ? -t : t;
            }
            c = 1.0f / sqrtf(t * t + 1.0f);
            s = t * c;
            for (k = 0; k < 3; ++k) {
                const float akp = a[k * 3 + p];
                const float akq = a[k * 3 + q];
                a[k * 3 + p] = c * akp - s * akq;
                a[k * 3 + q] = s * akp + c * akq;
            }
            for (k = 0; k < 3; ++k) {
                const float apk = a[p * 3 + k];
                const float aqk = a[q * 3 + k];
                a[p * 3 + k] = c * apk - s * aqk;
                a[q * 3 + k] = s * apk + c * aqk;
            }
            for (k = 0; k < 3; ++k) {
                const float vkp = v[k * 3 + p];
                const float vkq = v[k * 3 + q];
                v[k * 3 + p] = c * vkp - s * vkq;
                v[k * 3 + q] = s * vkp + c * vkq;
            }
        }
    }
    for (i = 0; i < 3; ++i) {
        lam[i] = a[i * 4];
    }
    /* Sort ascending (three elements, swapping columns with them). */
    for (i = 0; i < 2; ++i) {
        for (j = 0; j < 2 - i; ++j) {
            if (lam[j] > lam[j + 1]) {
                int k;
                const float t = lam[j];
                lam[j] = lam[j + 1];
                lam[j + 1] = t;
                for (k = 0; k < 3; ++k) {
                    const float u = v[k * 3 + j];
                    v[k * 3 + j] = v[k * 3 + j + 1];
                    v[k * 3 + j + 1] = u;
                }
            }
        }
    }
}

/* ---- Gauss-Newton --------------------------------------------------------------- */

/* Normal equations of one association pass at pose (tx, ty, th), local. */
typedef struct {
    float h[9];   /* J^T W J, (x, y, theta) */
    float g[3];   /* J^T W r */
    float sum_r2; /* sum of squared residuals of the point matches */
    float cost;   /* search passes: Huber cost of every point against its nearest
                     chord, distances capped at ALIGN_GATE_LAST * max_dist */
    uint16_t n_match;
    uint16_t n_vmatch;
} align_normal_t;

static float huber_weight(float r, float k)
{
    const float a = fabsf(r);
    return a <= k ? 1.0f : k / a;
}

/* Huber loss of residual r (half the square within k, linear beyond). */
static float huber_cost(float r, float k)
{
    const float a = fabsf(r);
    return a <= k ? 0.5f * a * a : k * (a - 0.5f * k);
}

static void add_row(align_normal_t *ne, float jx, float jy, float jt, float r, float w)
{
    ne->h[0] += w * jx * jx;
    ne->h[1] += w * jx * jy;
    ne->h[2] += w * jx * jt;
    ne->h[4] += w * jy * jy;
    ne->h[5] += w * jy * jt;
    ne->h[8] += w * jt * jt;
    ne->g[0] += w * jx * r;
    ne->g[1] += w * jy * r;
    ne->g[2] += w * jt * r;
}

/* One association pass. search = 1: each point's nearest chord through the
 * grid (remembered in w->match), and ne->cost; search = 0: the chord of the
 * last search again, its line as the tangent (the pose moved by millimetres
 * since). The cost does not depend on `gate` (at least the cap): a chord
 * within the cap is within max_dist / 2, always found through the grid. */
static void associate(bsf_align_work_t *w, const bsf_align_params_t *p, float tx, float ty,
                      float th, float gate, int search, align_normal_t *ne)
{
    float s;
    float c;
    const float gate2 = gate * gate;
    const float cap = ALIGN_GATE_LAST * p->max_dist;
    const float cap_cost = huber_cost(cap, p->huber);
    uint16_t i;
    memset(ne, 0, sizeof *ne);
    bsf_sincosf(th, &s, &c);
    for (i = 0; i < w->n_pts; ++i) {
        const float rx = c * w->pts[i].x - s * w->pts[i].y;
        const float ry = s * w->pts[i].x + c * w->pts[i].y;
        const float qx = rx + tx;
        const float qy = ry + ty;
        float best = gate2;
        int best_k = -1;
        int cx;
        int cy;
        uint16_t e;
        uint16_t e1;
        if (!search) {
            best_k = w->match[i] == 0xFFFFu ? -1 : (int)w->match[i];
            if (best_k >= 0) {
                const bsf_align_seg_t *sg = &w->segs[best_k];
                const float t = (qx - sg->ax) * sg->ux + (qy - sg->ay) * sg->uy;
                const float r = sg->ux * (qy - sg->ay) - sg->uy * (qx - sg->ax);
                if (!(fabsf(r) < gate && t > -gate && t < sg->len + gate)) {
                    best_k = -1;
                }
            }
        } else {
            if (!cell_of(w, qx, qy, &cx, &cy)) {
                w->match[i] = 0xFFFFu;
                continue;
            }
            e = w->cell_start[cy * BSF_ALIGN_GRID + cx];
            e1 = w->cell_start[cy * BSF_ALIGN_GRID + cx + 1];
            for (; e < e1; ++e) {
                const bsf_align_seg_t *sg = &w->segs[w->entries[e]];
                const float dx = qx - sg->ax;
                const float dy = qy - sg->ay;
                float t = dx * sg->ux + dy * sg->uy;
                float ex;
                float ey;
                float d2;
                t = t < 0.0f ? 0.0f : (t > sg->len ? sg->len : t);
                ex = dx - t * sg->ux;
                ey = dy - t * sg->uy;
                d2 = ex * ex + ey * ey;
                if (d2 < best) {
                    best = d2;
                    best_k = (int)w->entries[e];
                }
            }
            w->match[i] = best_k >= 0 ? (uint16_t)best_k : 0xFFFFu;
            if (best_k < 0 || best > cap * cap) {
                ne->cost += cap_cost;
            }
        }
        if (best_k >= 0) {
            const bsf_align_seg_t *sg = &w->segs[best_k];
            const float nx = -sg->uy;
            const float ny = sg->ux;
            const float r = nx * (qx - sg->ax) + ny * (qy - sg->ay);
            add_row(ne, nx, ny, ny * rx - nx * ry, r, huber_weight(r, p->huber));
            ne->sum_r2 += r * r;
            if (search && best <= cap * cap) {
                ne->cost += huber_cost(r, p->huber);
            }
            ++ne->n_match;
        }
    }
    if (p->vertex_weight > 0.0f) {
        for (i = 0; i < w->n_verts; ++i) {
            const float rx = c * w->verts[i].x - s * w->verts[i].y;
            const float ry = s * w->verts[i].x + c * w->verts[i].y;
            const float qx = rx + tx;
            const float qy = ry + ty;
            float best = gate2;
            int best_k = -1;
            uint16_t k;
            for (k = 0; k < w->n_mverts; ++k) {
                const float dx = qx - w->mverts[k].x;
                const float dy = qy - w->mverts[k].y;
                const float d2 = dx * dx + dy * dy;
                if (d2 < best) {
                    best = d2;
                    best_k = (int)k;
                }
            }
            if (best_k >= 0) {
                const float ex = qx - w->mverts[best_k].x;
                const float ey = qy - w->mverts[best_k].y;
                const float wt = p->vertex_weight * huber_weight(sqrtf(best), p->huber);
                add_row(ne, 1.0f, 0.0f, -ry, ex, wt);
                add_row(ne, 0.0f, 1.0f, rx, ey, wt);
                ++ne->n_vmatch;
            }
        }
    }
    ne->h[3] = ne->h[1];
    ne->h[6] = ne->h[2];
    ne->h[7] = ne->h[5];
}

/* Eigen-decomposition of the normal matrix with theta scaled by L; returns
 * the number of free directions (eigenvalue below the threshold), which
 * are the first columns of v. */
static int scaled_eig(const align_normal_t *ne, const bsf_align_params_t *p, float lam[3],
                      float v[9])
{
    const float il = 1.0f / p->theta_scale;
    float a[9];
    float thr;
    int n_free = 0;
    int i;
    memcpy(a, ne->h, sizeof a);
    a[2] *= il, a[5] *= il, a[6] *= il, a[7] *= il;
    a[8] *= il * il;
    eig3(a, lam, v);
    thr = p->free_ratio * lam[2];
    thr = thr > p->free_min ? thr : p->free_min;
    for (i = 0; i < 3; ++i) {
        n_free += lam[i] < thr;
    }
    return n_free;
}

static int finite3(float a, float b, float c)
{
    return bsf_finite_bits(a) && bsf_finite_bits(b) && bsf_finite_bits(c);
}

/* The alignment proper, on w->pts and w->verts (sensor frame). */
static void align_core(bsf_align_work_t *w, const bsf_align_params_t *p, const bsf_map_t *map,
                       const bsf_pose_t *prior, bsf_align_result_t *out)
{
    const bsf_point_t org = {prior->x, prior->y};
    const float il = 1.0f / p->theta_scale;
    align_normal_t ne;
    float tx = 0.0f;
    float ty = 0.0f;
    float dth = 0.0f;
    float gate = p->max_dist;
    float lam[3];
    float v[9];
    float d[3];
    float s0;
    float c0;
    float cost_prior = 0.0f;
    float cost_aligned;
    int projected;
    int n_free;
    int it;
    int i;
    memset(out, 0, sizeof *out);
    out->pose = *prior;
    out->n_points = w->n_pts;
    if (w->n_pts < p->min_matches) {
        out->declined = BSF_ALIGN_DECLINE_FEW_POINTS;
        return;
    }
    bsf_sincosf(prior->theta, &s0, &c0);
    grid_mark(w, c0, s0, p->max_xy + 0.5f * p->max_dist, 0.5f * p->max_dist);
    if (collect_map(w, map, org, p->max_dist)) {
        out->flags |= BSF_ALIGN_FLAG_CUT;
    }
    if (build_grid(w, 0.5f * p->max_dist)) {
        out->flags |= BSF_ALIGN_FLAG_CUT;
    }
    out->n_segs = w->n_segs;
    if (w->n_segs == 0u) {
        out->declined = BSF_ALIGN_DECLINE_EMPTY_MAP;
        return;
    }
    for (it = 0; it < (int)p->max_iter; ++it) {
        float step[3];
        float g2[3];
        gate =
            p->max_dist * (it < 3 ? (it == 0 ? 1.0f : (it == 1 ? 0.6f : 0.36f)) : ALIGN_GATE_LAST);
        associate(w, p, tx, ty, prior->theta + dth, gate, it < 3, &ne);
        if (it == 0) {
            cost_prior = ne.cost; /* the first pass is at the prior */
        }
        out->n_iter = (uint8_t)(it + 1);
        if (ne.n_match < p->min_matches) {
            out->declined = it == 0 ? BSF_ALIGN_DECLINE_FEW_MATCHES : BSF_ALIGN_DECLINE_DIVERGED;
            return;
        }
        n_free = scaled_eig(&ne, p, lam, v);
        if (n_free >= 3) {
            out->declined = BSF_ALIGN_DECLINE_UNDETERMINED;
            return;
        }
        /* Solve H step = -g in the determined subspace only. */
        g2[0] = ne.g[0];
        g2[1] = ne.g[1];
        g2[2] = ne.g[2] * il;
        step[0] = step[1] = step[2] = 0.0f;
        for (i = n_free; i < 3; ++i) {
            const float proj =
                -(v[0 * 3 + i] * g2[0] + v[1 * 3 + i] * g2[1] + v[2 * 3 + i] * g2[2]) / lam[i];
            step[0] += proj * v[0 * 3 + i];
            step[1] += proj * v[1 * 3 + i];
            step[2] += proj * v[2 * 3 + i];
        }
        if (!finite3(step[0], step[1], step[2])) {
            out->declined = BSF_ALIGN_DECLINE_DIVERGED;
            return;
        }
        tx += step[0];
        ty += step[1];
        dth += step[2] * il;
        if (tx * tx + ty * ty > 4.0f * p->max_xy * p->max_xy || fabsf(dth) > 2.0f * p->max_theta) {
            out->declined = BSF_ALIGN_DECLINE_TOO_LARGE;
            return;
        }
        if (step[0] * step[0] + step[1] * step[1] + step[2] * step[2] <
            ALIGN_STEP_DONE * ALIGN_STEP_DONE) {
            out->flags |= BSF_ALIGN_FLAG_CONVERGED;
            break;
        }
    }
    /* Final correspondences: the reported information, and the free
     * directions, along which the correction is taken back to the prior. */
    associate(w, p, tx, ty, prior->theta + dth, gate, 1, &ne);
    if (ne.n_match < p->min_matches) {
        out->declined = BSF_ALIGN_DECLINE_DIVERGED;
        return;
    }
    n_free = scaled_eig(&ne, p, lam, v);
    if (n_free >= 3) {
        out->declined = BSF_ALIGN_DECLINE_UNDETERMINED;
        return;
    }
    d[0] = tx;
    d[1] = ty;
    d[2] = dth * p->theta_scale;
    for (i = 0; i < n_free; ++i) {
        const float proj = v[0 * 3 + i] * d[0] + v[1 * 3 + i] * d[1] + v[2 * 3 + i] * d[2];
        d[0] -= proj * v[0 * 3 + i];
        d[1] -= proj * v[1 * 3 + i];
        d[2] -= proj * v[2 * 3 + i];
    }
    projected = tx != d[0] || ty != d[1] || dth != d[2] * il;
    tx = d[0];
    ty = d[1];
    dth = d[2] * il;
    memcpy(out->info, ne.h, sizeof out->info);
    out->min_eig = lam[0];
    out->min_eigvec[0] = v[0];
    out->min_eigvec[1] = v[3];
    out->min_eigvec[2] = v[6];
    out->n_free = (uint8_t)n_free;
    if (n_free > 0) {
        out->flags |= BSF_ALIGN_FLAG_FREE;
    }
    out->n_matches = ne.n_match;
    out->n_vertex_matches = ne.n_vmatch;
    out->rms = sqrtf(ne.sum_r2 / (float)ne.n_match);
    if (!finite3(tx, ty, dth) || !bsf_finite_bits(out->rms)) {
        memset(out->info, 0, sizeof out->info);
        out->declined = BSF_ALIGN_DECLINE_DIVERGED;
        return;
    }
    if (tx * tx + ty * ty > p->max_xy * p->max_xy || fabsf(dth) > p->max_theta) {
        out->declined = BSF_ALIGN_DECLINE_TOO_LARGE;
        return;
    }
    /* Gauss-Newton minimises a cost whose correspondences and gate change as
     * it goes; it can end where the whole scan fits the map worse than at
     * the prior (a stretch of points drawn onto a neighbouring wall). The
     * same cost, every point against its nearest chord, decides, at the
     * pose returned (after the projection off the free directions). */
    cost_aligned = ne.cost;
    if (projected) {
        associate(w, p, tx, ty, prior->theta + dth, gate, 1, &ne);
        cost_aligned = ne.cost;
    }
    if (!bsf_finite_bits(cost_aligned) || cost_aligned > cost_prior) {
        out->declined = BSF_ALIGN_DECLINE_NO_BETTER;
        return;
    }
    out->pose.x = prior->x + tx;
    out->pose.y = prior->y + ty;
    out->pose.theta = prior->theta + dth;
}

/* ---- Entry points ------------------------------------------------------------------ */

/* Scan vertices of `features` (each vertex pair once) into w->verts.
 * Returns 0, or BSF_ERR_ARG for a non-finite one or a malformed result. */
static int take_vertices(bsf_align_work_t *w, const bsf_result_t *r)
{
    uint16_t fi;
    w->n_verts = 0;
    if (r == NULL) {
        return 0;
    }
    if (r->n_features > BSF_MAX_SEGMENTS || r->n_ctrl > BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_ARG;
    }
    for (fi = 0; fi < r->n_features; ++fi) {
        const bsf_feature_t *f = &r->features[fi];
        size_t j;
        const size_t end = (size_t)f->ctrl_first + f->n_ctrl;
        if (f->n_ctrl < 3u || end > r->n_ctrl) {
            return BSF_ERR_ARG;
        }
        for (j = f->ctrl_first; j + 1 < end; ++j) {
            if (r->ctrl_is_vertex[j] && r->ctrl_is_vertex[j + 1]) {
                if (!point_ok(r->ctrl[j])) {
                    return BSF_ERR_ARG;
                }
                if (w->n_verts < BSF_ALIGN_MAX_VERTICES) {
                    w->verts[w->n_verts++] = r->ctrl[j];
                }
                ++j;
            }
        }
    }
    return 0;
}

static int check_common(bsf_align_work_t *work, const bsf_align_params_t **params,
                        const bsf_map_t *map, const bsf_pose_t *prior, bsf_align_result_t *out,
                        bsf_align_params_t *defaults)
{
    if (work == NULL || map == NULL || prior == NULL || out == NULL) {
        return BSF_ERR_ARG;
    }
    if (*params == NULL) {
        bsf_align_params_default(defaults);
        *params = defaults;
    }
    if (!params_ok(*params)) {
        return BSF_ERR_PARAM;
    }
    if (!prior_ok(prior)) {
        return BSF_ERR_ARG;
    }
    return 0;
}

bsf_status_t bsf_align_points(bsf_align_work_t *work, const bsf_align_params_t *params,
                              const bsf_map_t *map, const bsf_points_t *points,
                              const bsf_result_t *features, const bsf_pose_t *prior,
                              bsf_align_result_t *out)
{
    bsf_align_params_t defaults;
    size_t n_valid = 0;
    size_t stride;
    size_t k = 0;
    size_t i;
    int st = check_common(work, &params, map, prior, out, &defaults);
    if (st != 0) {
        return (bsf_status_t)st;
    }
    if (points == NULL || points->count > BSF_MAX_POINTS) {
        return BSF_ERR_ARG;
    }
    for (i = 0; i < points->count; ++i) {
        n_valid += points->valid[i] != 0u;
    }
    stride = (n_valid + params->max_points - 1u) / params->max_points;
    stride = stride < 1u ? 1u : stride;
    work->n_pts = 0;
    for (i = 0; i < points->count; ++i) {
        if (!points->valid[i]) {
            continue;
        }
        if (k++ % stride == 0u) {
            if (!point_ok(points->pt[i])) {
                return BSF_ERR_ARG;
            }
            work->pts[work->n_pts++] = points->pt[i];
        }
    }
    st = take_vertices(work, features);
    if (st != 0) {
        return (bsf_status_t)st;
    }
    align_core(work, params, map, prior, out);
    return BSF_OK;
}

/* Samples of a feature span: one every ALIGN_SAMPLE_SPACING along its chord,
 * at least one, at most ALIGN_SAMPLES_PER_SPAN. */
static size_t span_sample_count(bsf_point_t s0, bsf_point_t s1)
{
    const float dx = s1.x - s0.x;
    const float dy = s1.y - s0.y;
    const float n = sqrtf(dx * dx + dy * dy) * (1.0f / ALIGN_SAMPLE_SPACING);
    if (!(n >= 1.0f)) {
        return 1u;
    }
    return n >= (float)ALIGN_SAMPLES_PER_SPAN ? ALIGN_SAMPLES_PER_SPAN : (size_t)n + 1u;
}

/* Point at u in [0, 1] of a span (weights as in span_points). */
static bsf_point_t span_eval(const bsf_point_t *q, int first, int last, float u)
{
    const float w0 = (first ? 1.0f : 0.5f) * (1.0f - u) * (1.0f - u);
    const float w2 = (last ? 1.0f : 0.5f) * u * u;
    const float w1 = 1.0f - w0 - w2;
    bsf_point_t r;
    r.x = w0 * q[0].x + w1 * q[1].x + w2 * q[2].x;
    r.y = w0 * q[0].y + w1 * q[1].y + w2 * q[2].y;
    return r;
}

bsf_status_t bsf_align_features(bsf_align_work_t *work, const bsf_align_params_t *params,
                                const bsf_map_t *map, const bsf_result_t *features,
                                const bsf_pose_t *prior, bsf_align_result_t *out)
{
    bsf_align_params_t defaults;
    size_t total = 0;
    size_t stride;
    size_t k = 0;
    int pass;
    int st = check_common(work, &params, map, prior, out, &defaults);
    if (st != 0) {
        return (bsf_status_t)st;
    }
    if (features == NULL) {
        return BSF_ERR_ARG;
    }
    st = take_vertices(work, features); /* also checks the result's layout */
    if (st != 0) {
        return (bsf_status_t)st;
    }
    /* Pass 0 counts the samples, pass 1 keeps every stride-th. */
    stride = 1u;
    work->n_pts = 0;
    for (pass = 0; pass < 2; ++pass) {
        uint16_t fi;
        for (fi = 0; fi < features->n_features; ++fi) {
            const bsf_feature_t *f = &features->features[fi];
            const bsf_point_t *q = &features->ctrl[f->ctrl_first];
            const size_t n_span = (size_t)f->n_ctrl - 2u;
            size_t sp;
            for (sp = 0; sp < n_span; ++sp) {
                const int first = sp == 0;
                const int last = sp + 1 == n_span;
                bsf_point_t s0;
                bsf_point_t sm;
                bsf_point_t s1;
                size_t m;
                size_t i;
                if (!point_ok(q[sp]) || !point_ok(q[sp + 1]) || !point_ok(q[sp + 2])) {
                    return BSF_ERR_ARG;
                }
                span_points(q[sp], q[sp + 1], q[sp + 2], first, last, &s0, &sm, &s1);
                m = span_sample_count(s0, s1);
                if (pass == 0) {
                    total += m + (last ? 1u : 0u);
                    continue;
                }
                for (i = 0; i <= m; ++i) {
                    if (i == m && !last) {
                        break;
                    }
                    if (k++ % stride == 0u && work->n_pts < BSF_ALIGN_MAX_POINTS) {
                        work->pts[work->n_pts++] =
                            span_eval(&q[sp], first, last, (float)i / (float)m);
                    }
                }
            }
        }
        stride = (total + params->max_points - 1u) / params->max_points;
        stride = stride < 1u ? 1u : stride;
    }
    align_core(work, params, map, prior, out);
    return BSF_OK;
}
