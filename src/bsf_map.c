/* SPDX-License-Identifier: MIT */
/*
 * bsf_map.c - the robot's fused map: association of a scan's features with
 * map curves, refinement, extension, merging, vertex fusion and the
 * forgetting policy (docs/MAP.md says why each works as it does).
 */
#include "bsf/bsf_map.h"

#include <math.h>
#include <string.h>

#include "bsf/bsf_stream.h"
#include "bsf_map_internal.h"
#include "bsf_math.h"

/* Spacing of scan curve samples along the control polygon, metres, and the
 * bounds of their count. */
#define SAMPLE_STEP 0.08f
#define MIN_SAMPLES 4u
#define MAX_SAMPLES 64u
/* Control points one scan feature may refine at once. */
#define MAX_ACC 96u
/* Fraction of a control point's basis mass a scan must cover to refine it. */
#define MIN_SUPPORT 0.3f
/* A run of unmatched samples shorter than this many spacings makes nothing. */
#define MIN_RUN_SPACINGS 1.5f
/* Largest |world coordinate| a map point may have, metres; smaller when the
 * wire's range (2^23 - 1 steps) is: 838 m at 0.1 mm steps. */
#define MAP_COORD_MAX 8000.0f
/* A span whose second difference exceeds 4 cm (squared here) is curved: it is
 * searched as CHORDS chords. */
#define CURVED_SPAN2 0.0016f
#define CHORDS 4u

typedef struct {
    float x, y;   /* world position */
    float dx, dy; /* unit tangent */
    float gate;   /* match distance at this sample's range, metres */
    uint8_t vertex;
} sample_t;

typedef struct {
    uint16_t feature; /* map feature slot or BSF_MAP_NONE */
    uint16_t seg;
    float u; /* position along the segment's chord, 0..1 */
} label_t;

typedef struct {
    uint16_t idx;
    float a;      /* sum of basis weights */
    float bx, by; /* sum of basis weight times normal residual */
} acc_t;

typedef struct {
    float x, y;
    uint8_t vertex;
} newpt_t;

/* Map features near the whole scan, gathered once per scan (and again
 * after a merge or a forgotten feature moved slots). */
typedef struct {
    float box[4]; /* the scan's control points' box grown by match_dist */
    uint16_t slot[BSF_MAP_MAX_FEATURES];
    uint16_t n;
    uint32_t removed; /* n_merged + n_forgotten when gathered */
    int valid;
} near_t;

static void gather_near(const bsf_map_t *m, near_t *nr)
{
    uint16_t fs;
    nr->n = 0u;
    for (fs = 0; fs < m->n_features; ++fs) {
        const bsf_map_feature_t *f = &m->features[fs];
        if (f->max_x < nr->box[0] || f->min_x > nr->box[2] || f->max_y < nr->box[1] ||
            f->min_y > nr->box[3]) {
            continue;
        }
        nr->slot[nr->n++] = fs;
    }
    nr->removed = m->stats.n_merged + m->stats.n_forgotten;
    nr->valid = 1;
}

void bsf_map_params_default(bsf_map_params_t *p)
{
    p->match_dist = 0.10f;
    p->match_dist_near = 0.03f;
    p->match_dist_per_m = 0.01f;
    p->match_angle = 0.5f;
    p->vertex_dist = 0.05f;
    p->ctrl_spacing = 0.25f;
    p->send_tol = 0.02f;
    p->simplify_tol = 0.015f;
    p->quant_step = BSF_QUANT_STEP_DEFAULT;
    p->weight_cap = 32u;
    p->forget_after = 50u;
    p->snapshot_budget = 0u;
    p->frame_interval = 5u;
}

static int finite_f(float v)
{
    return v == v && v - v == 0.0f;
}

static bsf_status_t check_params(const bsf_map_params_t *p, int32_t *step_code)
{
    float code;
    if (!finite_f(p->match_dist) || !finite_f(p->match_angle) || !finite_f(p->vertex_dist) ||
        !finite_f(p->ctrl_spacing) || !finite_f(p->send_tol) || !finite_f(p->quant_step) ||
        !finite_f(p->match_dist_near) || !finite_f(p->match_dist_per_m) ||
        !finite_f(p->simplify_tol)) {
        return BSF_ERR_PARAM;
    }
    if (p->match_dist <= 0.0f || p->match_dist > 1.0f || p->match_angle <= 0.0f ||
        p->match_angle > 1.5707964f || p->vertex_dist < 0.0f || p->vertex_dist > p->match_dist ||
        p->ctrl_spacing < 0.02f || p->ctrl_spacing > 2.0f || p->send_tol < 0.0f ||
        p->send_tol > 1.0f || p->quant_step < BSF_QUANT_STEP_MIN ||
        p->quant_step > BSF_QUANT_STEP_MAX || p->weight_cap < 1u || p->weight_cap > 255u ||
        p->frame_interval < 1u || p->frame_interval > 1000u || p->match_dist_near <= 0.0f ||
        p->match_dist_near > 1.0f || p->match_dist_per_m < 0.0f || p->match_dist_per_m > 1.0f ||
        p->simplify_tol < 0.0f || p->simplify_tol > 0.5f) {
        return BSF_ERR_PARAM;
    }
    code = floorf(p->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    *step_code = (int32_t)(code < 1.0f ? 1.0f : code);
    return BSF_OK;
}

bsf_status_t bsf_map_init(bsf_map_t *map, const bsf_map_params_t *params)
{
    bsf_map_params_t p;
    int32_t step_code;
    bsf_status_t st;
    size_t i;
    if (map == NULL) {
        return BSF_ERR_ARG;
    }
    if (params != NULL) {
        p = *params;
    } else {
        bsf_map_params_default(&p);
    }
    st = check_params(&p, &step_code);
    if (st != BSF_OK) {
        return st;
    }
    memset(map, 0, sizeof *map);
    map->params = p;
    map->step_code = step_code;
    /* the wire's step, so that fused values quantise as the receiver reads them */
    map->params.quant_step = (float)step_code * BSF_QUANT_STEP_UNIT;
    for (i = 0; i < BSF_MAP_MAX_CTRL; ++i) {
        map->ctrl[i].next = (uint16_t)(i + 1u < BSF_MAP_MAX_CTRL ? i + 1u : BSF_MAP_NONE);
        map->ctrl[i].prev = BSF_MAP_NONE;
    }
    map->free_ctrl = 0u;
    map->n_free_ctrl = BSF_MAP_MAX_CTRL;
    return BSF_OK;
}

/* ---- Pool and chains ----------------------------------------------------- */

static uint16_t ctrl_alloc(bsf_map_t *m, float x, float y, uint8_t vertex)
{
    const uint16_t i = m->free_ctrl;
    bsf_map_ctrl_t *c;
    if (i == BSF_MAP_NONE) {
        return BSF_MAP_NONE;
    }
    c = &m->ctrl[i];
    m->free_ctrl = c->next;
    --m->n_free_ctrl;
    c->x = x;
    c->y = y;
    c->qx = 0;
    c->qy = 0;
    c->next = BSF_MAP_NONE;
    c->prev = BSF_MAP_NONE;
    c->weight = 1u;
    c->flags = vertex ? BSF_MAP_CF_VERTEX : 0u;
    c->corner_obs = 1u;
    return i;
}

static void chain_free(bsf_map_t *m, uint16_t head)
{
    while (head != BSF_MAP_NONE) {
        const uint16_t next = m->ctrl[head].next;
        m->ctrl[head].next = m->free_ctrl;
        m->ctrl[head].prev = BSF_MAP_NONE;
        m->free_ctrl = head;
        ++m->n_free_ctrl;
        head = next;
    }
}

static void feature_bbox(bsf_map_t *m, bsf_map_feature_t *f)
{
    uint16_t i = f->head;
    f->min_x = f->min_y = 3.0e38f;
    f->max_x = f->max_y = -3.0e38f;
    while (i != BSF_MAP_NONE) {
        const bsf_map_ctrl_t *c = &m->ctrl[i];
        f->min_x = c->x < f->min_x ? c->x : f->min_x;
        f->max_x = c->x > f->max_x ? c->x : f->max_x;
        f->min_y = c->y < f->min_y ? c->y : f->min_y;
        f->max_y = c->y > f->max_y ? c->y : f->max_y;
        i = c->next;
    }
}

static void chain_reverse(bsf_map_t *m, bsf_map_feature_t *f)
{
    uint16_t i = f->head;
    uint16_t t;
    while (i != BSF_MAP_NONE) {
        bsf_map_ctrl_t *c = &m->ctrl[i];
        t = c->next;
        c->next = c->prev;
        c->prev = t;
        i = t;
    }
    t = f->head;
    f->head = f->tail;
    f->tail = t;
}

/* Stored (expanded) control points of a chain: a vertex counts twice. */
static size_t chain_expanded(const bsf_map_t *m, const bsf_map_feature_t *f)
{
    size_t n = 0;
    uint16_t i = f->head;
    while (i != BSF_MAP_NONE) {
        n += (m->ctrl[i].flags & BSF_MAP_CF_VERTEX) ? 2u : 1u;
        i = m->ctrl[i].next;
    }
    return n;
}

/* 1 when every point is sent and within the tolerance of its sent value. */
/* Points of one run bsf_map_simplify looks at, and how many points one
 * chord may replace (bounds the work: SIMPLIFY_RUN x SIMPLIFY_SPAN). */
#define SIMPLIFY_RUN 128u
#define SIMPLIFY_SPAN 32u

static float seg_dist2(const bsf_map_ctrl_t *p, const bsf_map_ctrl_t *a, const bsf_map_ctrl_t *b)
{
    const float dx = b->x - a->x;
    const float dy = b->y - a->y;
    const float l2 = dx * dx + dy * dy;
    float t = 0.0f;
    float ex;
    float ey;
    if (l2 > 1e-12f) {
        t = ((p->x - a->x) * dx + (p->y - a->y) * dy) / l2;
        t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    }
    ex = a->x + t * dx - p->x;
    ey = a->y + t * dy - p->y;
    return ex * ex + ey * ey;
}

/* How far the curve passes from control point p between its neighbours a
 * and b: a quadratic B-spline misses an interior point by about a quarter
 * of its distance from the line through the neighbours (0 at a vertex or a
 * chain end, which the curve goes through). */
static float curve_gap(const bsf_map_t *m, uint16_t a, uint16_t p, uint16_t b)
{
    const bsf_map_ctrl_t *ca;
    const bsf_map_ctrl_t *cp = &m->ctrl[p];
    const bsf_map_ctrl_t *cb;
    float dx;
    float dy;
    float l;
    if (a == BSF_MAP_NONE || b == BSF_MAP_NONE || (cp->flags & BSF_MAP_CF_VERTEX)) {
        return 0.0f;
    }
    ca = &m->ctrl[a];
    cb = &m->ctrl[b];
    dx = cb->x - ca->x;
    dy = cb->y - ca->y;
    l = sqrtf(dx * dx + dy * dy);
    if (l < 1e-6f) {
        return 0.0f;
    }
    return 0.25f * fabsf(dx * (cp->y - ca->y) - dy * (cp->x - ca->x)) / l;
}

uint32_t bsf_map_simplify(bsf_map_t *m, bsf_map_feature_t *f, uint16_t anchor, int dir, uint32_t n)
{
    const float tol2 = m->params.simplify_tol * m->params.simplify_tol;
    uint16_t run[SIMPLIFY_RUN + 1u];
    uint8_t keep[SIMPLIFY_RUN + 1u];
    uint32_t len = 0;
    uint32_t removed = 0;
    uint32_t a = 0;
    uint32_t k;
    uint16_t i = anchor;
    if (tol2 <= 0.0f || (f->flags & BSF_MAP_FF_OP) || n < 2u) {
        return n;
    }
    run[len++] = anchor;
    while (len <= n && len <= SIMPLIFY_RUN) {
        i = dir ? m->ctrl[i].prev : m->ctrl[i].next;
        if (i == BSF_MAP_NONE) {
            return n; /* cannot happen: the caller counted the run */
        }
        run[len++] = i;
    }
    memset(keep, 1, len);
    /* greedy: from the kept point a, the farthest b whose chord holds every
     * point between within the tolerance, and leaves the curve near the
     * chord's ends (where it turns into the neighbouring legs) within it */
    while (a + 1u < len) {
        uint32_t b = a + 1u;
        /* the point kept before a (chain order), fixed by now */
        const uint16_t before = dir ? m->ctrl[run[a]].next : m->ctrl[run[a]].prev;
        while (b + 1u < len && b - a < SIMPLIFY_SPAN) {
            const bsf_map_ctrl_t *cb = &m->ctrl[run[b]];
            const uint16_t e = run[b + 1u];
            const bsf_map_ctrl_t *ce = &m->ctrl[e];
            const uint16_t after = dir ? ce->prev : ce->next;
            int ok = !(cb->flags & (BSF_MAP_CF_VERTEX | BSF_MAP_CF_SENT)) &&
                     cb->prev != BSF_MAP_NONE && cb->next != BSF_MAP_NONE &&
                     curve_gap(m, before, run[a], e) <= m->params.simplify_tol &&
                     curve_gap(m, run[a], e, after) <= m->params.simplify_tol;
            for (k = a + 1u; ok && k <= b; ++k) {
                ok = seg_dist2(&m->ctrl[run[k]], &m->ctrl[run[a]], ce) <= tol2;
            }
            if (!ok) {
                break;
            }
            ++b;
        }
        for (k = a + 1u; k < b; ++k) {
            keep[k] = 0u;
        }
        a = b;
    }
    /* never below 3 points */
    for (k = 1; k < len && f->n_ctrl - removed > 3u; ++k) {
        if (!keep[k]) {
            bsf_map_ctrl_t *c = &m->ctrl[run[k]];
            m->ctrl[c->prev].next = c->next;
            m->ctrl[c->next].prev = c->prev;
            c->next = m->free_ctrl;
            c->prev = BSF_MAP_NONE;
            m->free_ctrl = run[k];
            ++m->n_free_ctrl;
            ++removed;
        }
    }
    f->n_ctrl = (uint16_t)(f->n_ctrl - removed);
    return n - removed;
}

int bsf_map_chain_clean(const bsf_map_t *m, const bsf_map_feature_t *f)
{
    const float tol = m->params.send_tol;
    uint16_t i = f->head;
    if (!(f->flags & BSF_MAP_FF_SENT)) {
        return 0;
    }
    while (i != BSF_MAP_NONE) {
        const bsf_map_ctrl_t *c = &m->ctrl[i];
        if (!(c->flags & BSF_MAP_CF_SENT) ||
            bsf_map_ctrl_moved(c, m->params.quant_step, tol * tol)) {
            return 0;
        }
        i = c->next;
    }
    return 1;
}

static void feature_remove_slot(bsf_map_t *m, uint16_t slot)
{
    const uint16_t last = (uint16_t)(m->n_features - 1u);
    if (slot != last) {
        m->features[slot] = m->features[last];
    }
    memset(&m->features[last], 0, sizeof m->features[last]);
    --m->n_features;
}

/* Forget features fully sent and unseen for forget_after calls, oldest
 * first, until need_pts points and need_feat slots are free. */
static int make_room(bsf_map_t *m, size_t need_pts, size_t need_feat)
{
    const uint32_t tick = m->stats.n_fused;
    while (m->n_free_ctrl < need_pts ||
           (size_t)m->n_features + need_feat > (size_t)BSF_MAP_MAX_FEATURES) {
        uint16_t best = BSF_MAP_NONE;
        uint32_t best_seen = 0;
        uint16_t s;
        for (s = 0; s < m->n_features; ++s) {
            const bsf_map_feature_t *f = &m->features[s];
            if ((f->flags & (BSF_MAP_FF_OP | BSF_MAP_FF_FRESH)) != 0u ||
                tick - f->last_seen < m->params.forget_after) {
                continue;
            }
            if ((best == BSF_MAP_NONE || f->last_seen < best_seen) && bsf_map_chain_clean(m, f)) {
                best = s;
                best_seen = f->last_seen;
            }
        }
        if (best == BSF_MAP_NONE) {
            return 0;
        }
        ++m->stats.n_forgotten;
        m->stats.n_forgotten_ctrl += m->features[best].n_ctrl;
        chain_free(m, m->features[best].head);
        feature_remove_slot(m, best);
    }
    return 1;
}

/* ---- Geometry ------------------------------------------------------------- */

/* Basis of a span at chord position u: interior uniform quadratic, or the
 * clamped first / last span (ends bit 1 / 2), or a single Bezier span. */
static void span_basis(uint8_t ends, float u, float b[3])
{
    const float v = 1.0f - u;
    if (ends == 3u) {
        b[0] = v * v;
        b[1] = 2.0f * u * v;
        b[2] = u * u;
    } else if (ends & 1u) {
        b[0] = v * v;
        b[1] = 2.0f * u - 1.5f * u * u;
        b[2] = 0.5f * u * u;
    } else if (ends & 2u) {
        b[0] = 0.5f * v * v;
        b[1] = 2.0f * v - 1.5f * v * v;
        b[2] = u * u;
    } else {
        b[0] = 0.5f * v * v;
        b[1] = 0.5f + u - u * u;
        b[2] = 0.5f * u * u;
    }
}

/* Derivatives of span_basis with respect to u (a tangent direction). */
static void span_deriv(uint8_t ends, float u, float d[3])
{
    const float v = 1.0f - u;
    if (ends == 3u) {
        d[0] = -2.0f * v;
        d[1] = 2.0f * (v - u);
        d[2] = 2.0f * u;
    } else if (ends & 1u) {
        d[0] = -2.0f * v;
        d[1] = 2.0f - 3.0f * u;
        d[2] = u;
    } else if (ends & 2u) {
        d[0] = -v;
        d[1] = 3.0f * v - 2.0f;
        d[2] = 2.0f * u;
    } else {
        d[0] = -v;
        d[1] = 1.0f - 2.0f * u;
        d[2] = u;
    }
}

/* Spans of feature slot fs whose chord box meets box[] (min x, min y, max x,
 * max y), appended to m->segs. */
static void build_segs(bsf_map_t *m, uint16_t fs, const float box[4])
{
    const bsf_map_feature_t *f = &m->features[fs];
    const size_t n = chain_expanded(m, f);
    uint16_t e[3] = {BSF_MAP_NONE, BSF_MAP_NONE, BSF_MAP_NONE};
    size_t have = 0;
    uint16_t i = f->head;
    if (n < 3u) {
        return;
    }
    while (i != BSF_MAP_NONE && m->n_segs < BSF_MAP_SEG_WINDOW) {
        const unsigned reps = (m->ctrl[i].flags & BSF_MAP_CF_VERTEX) ? 2u : 1u;
        unsigned r;
        for (r = 0; r < reps && m->n_segs < BSF_MAP_SEG_WINDOW; ++r) {
            e[0] = e[1];
            e[1] = e[2];
            e[2] = i;
            ++have;
            if (have >= 3u) {
                const size_t s = have - 3u;
                const bsf_map_ctrl_t *c0 = &m->ctrl[e[0]];
                const bsf_map_ctrl_t *c1 = &m->ctrl[e[1]];
                const bsf_map_ctrl_t *c2 = &m->ctrl[e[2]];
                const uint8_t ends = (uint8_t)((s == 0u ? 1u : 0u) | (s + 3u == n ? 2u : 0u));
                /* a curved span becomes CHORDS chords, so that chord distance
                 * stays close to curve distance */
                const float ddx = c0->x - 2.0f * c1->x + c2->x;
                const float ddy = c0->y - 2.0f * c1->y + c2->y;
                const unsigned pieces = ddx * ddx + ddy * ddy > CURVED_SPAN2 ? CHORDS : 1u;
                unsigned piece;
                float px = 0.0f;
                float py = 0.0f;
                /* the span lies in its control points' hull: skip it when
                 * that hull's box misses the search box */
                if ((c0->x < box[0] && c1->x < box[0] && c2->x < box[0]) ||
                    (c0->x > box[2] && c1->x > box[2] && c2->x > box[2]) ||
                    (c0->y < box[1] && c1->y < box[1] && c2->y < box[1]) ||
                    (c0->y > box[3] && c1->y > box[3] && c2->y > box[3])) {
                    continue;
                }
                for (piece = 0; piece <= pieces; ++piece) {
                    const float u = (float)piece / (float)pieces;
                    float b[3];
                    float qx;
                    float qy;
                    span_basis(ends, u, b);
                    qx = b[0] * c0->x + b[1] * c1->x + b[2] * c2->x;
                    qy = b[0] * c0->y + b[1] * c1->y + b[2] * c2->y;
                    if (piece > 0u && m->n_segs < BSF_MAP_SEG_WINDOW &&
                        (px < qx ? qx : px) >= box[0] && (px < qx ? px : qx) <= box[2] &&
                        (py < qy ? qy : py) >= box[1] && (py < qy ? py : qy) <= box[3]) {
                        bsf_map_seg_t *g = &m->segs[m->n_segs++];
                        g->ax = px;
                        g->ay = py;
                        g->bx = qx;
                        g->by = qy;
                        g->u0 = (float)(piece - 1u) / (float)pieces;
                        g->du = 1.0f / (float)pieces;
                        g->feature = fs;
                        g->p[0] = e[0];
                        g->p[1] = e[1];
                        g->p[2] = e[2];
                        g->ends = ends;
                    }
                    px = qx;
                    py = qy;
                }
            }
        }
        i = m->ctrl[i].next;
    }
}

/* Samples of a scan curve (world frame), evenly in t plus its vertices. */
static size_t sample_curve(const bsf_point_t *w, const uint8_t *vtx, size_t n, sample_t *out)
{
    float len = 0.0f;
    size_t ns;
    size_t k;
    size_t i;
    for (i = 1; i < n; ++i) {
        const float dx = w[i].x - w[i - 1u].x;
        const float dy = w[i].y - w[i - 1u].y;
        len += sqrtf(dx * dx + dy * dy);
    }
    ns = (size_t)(len / SAMPLE_STEP) + 1u;
    ns = ns < MIN_SAMPLES ? MIN_SAMPLES : (ns > MAX_SAMPLES ? MAX_SAMPLES : ns);
    for (k = 0; k < ns; ++k) {
        /* span and local parameter of t = k / (ns - 1), the last sample at
         * the end of the last span */
        const float ts = (float)k * (float)(n - 2u) / (float)(ns - 1u);
        size_t span = (size_t)ts;
        float u;
        float b[3];
        float d[3];
        float dx;
        float dy;
        float dl;
        uint8_t ends;
        if (span > n - 3u) {
            span = n - 3u;
        }
        u = ts - (float)span;
        u = u > 1.0f ? 1.0f : u;
        ends = (uint8_t)((span == 0u ? 1u : 0u) | (span + 3u == n ? 2u : 0u));
        span_basis(ends, u, b);
        span_deriv(ends, u, d);
        out[k].x = b[0] * w[span].x + b[1] * w[span + 1u].x + b[2] * w[span + 2u].x;
        out[k].y = b[0] * w[span].y + b[1] * w[span + 1u].y + b[2] * w[span + 2u].y;
        dx = d[0] * w[span].x + d[1] * w[span + 1u].x + d[2] * w[span + 2u].x;
        dy = d[0] * w[span].y + d[1] * w[span + 1u].y + d[2] * w[span + 2u].y;
        dl = sqrtf(dx * dx + dy * dy);
        out[k].dx = dl > 0.0f ? dx / dl : 0.0f;
        out[k].dy = dl > 0.0f ? dy / dl : 0.0f;
        out[k].vertex = 0u;
    }
    /* a vertex (slots i, i + 1 flagged) sits on the curve at t = i / (n - 2) */
    for (i = 0; i + 1u < n; ++i) {
        if (vtx[i] && vtx[i + 1u]) {
            const float t = (float)i / (float)(n - 2u);
            size_t kk = (size_t)(t * (float)(ns - 1u) + 0.5f);
            kk = kk >= ns ? ns - 1u : kk;
            out[kk].x = w[i].x;
            out[kk].y = w[i].y;
            out[kk].vertex = 1u;
            ++i;
        }
    }
    return ns;
}

/* Test chord g for sample q: when it is nearer than *best (squared) and
 * runs in the sample's direction, it becomes the sample's label. */
static void seg_test(const bsf_map_t *m, uint16_t g, const sample_t *q, float cmin, float *best,
                     label_t *lab)
{
    const float md = m->params.match_dist;
    const bsf_map_seg_t *sg = &m->segs[g];
    const float ux = sg->bx - sg->ax;
    const float uy = sg->by - sg->ay;
    float l2;
    float t = 0.0f;
    float ex;
    float ey;
    float d2;
    /* cheap rejection: the sample is beyond the chord's box grown by the
     * match distance */
    if ((q->x < sg->ax - md && q->x < sg->bx - md) || (q->x > sg->ax + md && q->x > sg->bx + md) ||
        (q->y < sg->ay - md && q->y < sg->by - md) || (q->y > sg->ay + md && q->y > sg->by + md)) {
        return;
    }
    l2 = ux * ux + uy * uy;
    if (l2 > 1e-10f) {
        t = ((q->x - sg->ax) * ux + (q->y - sg->ay) * uy) / l2;
        t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    }
    ex = q->x - (sg->ax + t * ux);
    ey = q->y - (sg->ay + t * uy);
    d2 = ex * ex + ey * ey;
    if (d2 >= *best) {
        return;
    }
    if (l2 > 1e-6f && !q->vertex) {
        const float c = fabsf(ux * q->dx + uy * q->dy) / sqrtf(l2);
        if (c < cmin) {
            return;
        }
    }
    *best = d2;
    lab->feature = sg->feature;
    lab->seg = g;
    lab->u = sg->u0 + t * sg->du;
}

/* Samples are labelled in runs of LABEL_RUN: the chords whose box (grown by
 * the match distance) meets the run's box are gathered once, then each
 * sample is tested against those alone. */
#define LABEL_RUN 8u

/* Nearest chord of each sample within the match distance, running in the
 * sample's direction. */
static void label_samples(const bsf_map_t *m, const sample_t *s, size_t ns, label_t *lab)
{
    const float md = m->params.match_dist;
    const float cmin = bsf_cosf(m->params.match_angle);
    uint16_t near[BSF_MAP_SEG_WINDOW];
    size_t k0;
    for (k0 = 0; k0 < ns; k0 += LABEL_RUN) {
        const size_t k1 = k0 + LABEL_RUN < ns ? k0 + LABEL_RUN : ns;
        float bx0 = s[k0].x;
        float by0 = s[k0].y;
        float bx1 = s[k0].x;
        float by1 = s[k0].y;
        size_t n_near = 0;
        size_t k;
        uint16_t g;
        for (k = k0 + 1u; k < k1; ++k) {
            bx0 = s[k].x < bx0 ? s[k].x : bx0;
            by0 = s[k].y < by0 ? s[k].y : by0;
            bx1 = s[k].x > bx1 ? s[k].x : bx1;
            by1 = s[k].y > by1 ? s[k].y : by1;
        }
        bx0 -= md;
        by0 -= md;
        bx1 += md;
        by1 += md;
        for (g = 0; g < m->n_segs; ++g) {
            const bsf_map_seg_t *sg = &m->segs[g];
            if ((sg->ax < bx0 && sg->bx < bx0) || (sg->ax > bx1 && sg->bx > bx1) ||
                (sg->ay < by0 && sg->by < by0) || (sg->ay > by1 && sg->by > by1)) {
                continue;
            }
            near[n_near++] = g;
        }
        for (k = k0; k < k1; ++k) {
            float best = s[k].gate * s[k].gate;
            size_t j;
            lab[k].feature = BSF_MAP_NONE;
            lab[k].seg = 0u;
            lab[k].u = 0.0f;
            for (j = 0; j < n_near; ++j) {
                seg_test(m, near[j], &s[k], cmin, &best, &lab[k]);
            }
        }
    }
}

/* ---- Fusion steps -------------------------------------------------------- */

/* Refine the control points that the samples matched to map feature fs
 * cover: per point, the basis-weighted mean of the samples' normal
 * residuals, folded into its running mean (weight = observations, capped).
 * Vertices too: the residuals of the two walls that meet there pull a
 * corner placed off them (a scan's corner fit on a grazing view) onto both. */
static void refine(bsf_map_t *m, uint16_t fs, const sample_t *s, const label_t *lab, size_t ns)
{
    acc_t acc[MAX_ACC];
    size_t n_acc = 0;
    size_t k;
    size_t a;
    for (k = 0; k < ns; ++k) {
        const bsf_map_seg_t *sg;
        const bsf_map_ctrl_t *c[3];
        float b[3];
        float cx;
        float cy;
        float nx;
        float ny;
        float nl;
        float r;
        unsigned j;
        if (lab[k].feature != fs || s[k].vertex) {
            continue;
        }
        sg = &m->segs[lab[k].seg];
        span_basis(sg->ends, lab[k].u, b);
        for (j = 0; j < 3u; ++j) {
            c[j] = &m->ctrl[sg->p[j]];
        }
        cx = b[0] * c[0]->x + b[1] * c[1]->x + b[2] * c[2]->x;
        cy = b[0] * c[0]->y + b[1] * c[1]->y + b[2] * c[2]->y;
        nx = -(sg->by - sg->ay);
        ny = sg->bx - sg->ax;
        nl = sqrtf(nx * nx + ny * ny);
        if (nl < 1e-6f) {
            continue;
        }
        nx /= nl;
        ny /= nl;
        r = (s[k].x - cx) * nx + (s[k].y - cy) * ny;
        for (j = 0; j < 3u; ++j) {
            const uint16_t idx = sg->p[j];
            size_t q;
            /* samples run along the chain: the point is most likely a recent entry */
            for (q = n_acc; q > 0u && acc[q - 1u].idx != idx; --q) {
            }
            if (q > 0u) {
                --q;
            } else {
                q = n_acc;
            }
            if (q == n_acc) {
                if (n_acc == MAX_ACC) {
                    continue;
                }
                acc[q].idx = idx;
                acc[q].a = 0.0f;
                acc[q].bx = 0.0f;
                acc[q].by = 0.0f;
                ++n_acc;
            }
            acc[q].a += b[j];
            acc[q].bx += b[j] * r * nx;
            acc[q].by += b[j] * r * ny;
        }
    }
    for (a = 0; a < n_acc; ++a) {
        bsf_map_ctrl_t *c = &m->ctrl[acc[a].idx];
        float w;
        if (acc[a].a < MIN_SUPPORT) {
            continue;
        }
        w = (float)c->weight + 1.0f;
        c->x += acc[a].bx / acc[a].a / w;
        c->y += acc[a].by / acc[a].a / w;
        if (c->weight < m->params.weight_cap) {
            ++c->weight;
        }
        ++m->stats.n_refined;
    }
}

/* A chain that turns by more than about 150 degrees between two legs runs
 * back over itself (a fold); a true corner that sharp is rarer than a fit
 * or a join gone wrong. */
#define FOLD_COS 0.866f

/* 1 when a leg (bx, by) after a leg (ax, ay) turns back by more than
 * acos(-FOLD_COS); a zero leg never does. */
static int turns_back(float ax, float ay, float bx, float by)
{
    const float d = ax * bx + ay * by;
    return d < 0.0f && d * d >= FOLD_COS * FOLD_COS * (ax * ax + ay * ay) * (bx * bx + by * by);
}

/* A chain end: its point and outward direction (from its inner neighbour
 * to it, the clamped curve's end tangent). */
typedef struct {
    float x, y;
    float ox, oy;
} anchor_t;

static anchor_t end_anchor(const bsf_map_t *m, const bsf_map_feature_t *f, unsigned end)
{
    const uint16_t e = end == 1u ? f->head : f->tail;
    const uint16_t in = end == 1u ? m->ctrl[e].next : m->ctrl[e].prev;
    anchor_t a;
    a.x = m->ctrl[e].x;
    a.y = m->ctrl[e].y;
    a.ox = in == BSF_MAP_NONE ? 0.0f : a.x - m->ctrl[in].x;
    a.oy = in == BSF_MAP_NONE ? 0.0f : a.y - m->ctrl[in].y;
    return a;
}

/* Points along samples from..to (step +1 or -1), every sp metres and at
 * every vertex, starting after the chain end *an (none when NULL); the
 * last one ends the run. A sample that does not lie ahead of the point
 * before it along its own tangent (in the walk's sense) is passed over:
 * the chain would step back there and fold on itself. Returns the count
 * (at most cap). */
static size_t resample(float sp, const sample_t *s, long from, long to, const anchor_t *an,
                       newpt_t *out, size_t cap)
{
    const long dir = to >= from ? 1 : -1;
    float px = an != NULL ? an->x : 0.0f;
    float py = an != NULL ? an->y : 0.0f;
    int have_prev = an != NULL;
    size_t n = 0;
    long k;
    for (k = from;; k += dir) {
        const sample_t *q = &s[k];
        const int last = k == to;
        const float dx = q->x - px;
        const float dy = q->y - py;
        const float d2 = dx * dx + dy * dy;
        if (have_prev && !q->vertex && (dx * q->dx + dy * q->dy) * (float)dir <= 0.0f) {
            if (last) {
                break;
            }
            continue;
        }
        if (!have_prev || q->vertex || d2 >= sp * sp) {
            if (q->vertex && n > 0u && !out[n - 1u].vertex && d2 < 0.09f * sp * sp) {
                --n; /* a point just before a vertex gives way to it */
            }
            if (n < cap) {
                out[n].x = q->x;
                out[n].y = q->y;
                out[n].vertex = q->vertex;
                ++n;
            }
            px = q->x;
            py = q->y;
            have_prev = 1;
        } else if (last) {
            if (d2 >= 0.16f * sp * sp && n < cap) {
                out[n].x = q->x;
                out[n].y = q->y;
                out[n].vertex = 0u;
                ++n;
            } else if (n > 0u && !out[n - 1u].vertex) {
                out[n - 1u].x = q->x;
                out[n - 1u].y = q->y;
            }
        }
        if (last) {
            break;
        }
    }
    return n;
}

static float run_length(const sample_t *s, long from, long to)
{
    float len = 0.0f;
    const long dir = to >= from ? 1 : -1;
    long k;
    for (k = from; k != to; k += dir) {
        const float dx = s[k + dir].x - s[k].x;
        const float dy = s[k + dir].y - s[k].y;
        len += sqrtf(dx * dx + dy * dy);
    }
    return len;
}

/* Link new points after the tail (at_head = 0) or before the head. */
static int chain_extend(bsf_map_t *m, bsf_map_feature_t *f, const newpt_t *p, size_t n, int at_head)
{
    size_t i;
    if (m->n_free_ctrl < n) {
        return 0;
    }
    for (i = 0; i < n; ++i) {
        const uint16_t c = ctrl_alloc(m, p[i].x, p[i].y, p[i].vertex);
        if (at_head) {
            m->ctrl[c].next = f->head;
            m->ctrl[f->head].prev = c;
            f->head = c;
        } else {
            m->ctrl[c].prev = f->tail;
            m->ctrl[f->tail].next = c;
            f->tail = c;
        }
        ++f->n_ctrl;
    }
    return 1;
}

static int feature_new(bsf_map_t *m, const newpt_t *p, size_t n)
{
    bsf_map_feature_t *f;
    size_t i;
    size_t expanded = 0;
    for (i = 0; i < n; ++i) {
        expanded += p[i].vertex ? 2u : 1u;
    }
    if (n < 2u || expanded < 3u || m->n_free_ctrl < n || m->n_features >= BSF_MAP_MAX_FEATURES) {
        return 0;
    }
    f = &m->features[m->n_features++];
    memset(f, 0, sizeof *f);
    f->id = BSF_MAP_ID_UNSENT; /* given at its first record (dense ids on the wire) */
    f->last_seen = m->stats.n_fused;
    f->flags = BSF_MAP_FF_FRESH;
    f->head = ctrl_alloc(m, p[0].x, p[0].y, p[0].vertex);
    f->tail = f->head;
    f->n_ctrl = 1u;
    (void)chain_extend(m, f, p + 1, n - 1u, 0);
    feature_bbox(m, f);
    ++m->stats.n_new;
    return 1;
}

uint16_t bsf_map_slot_of_id(const bsf_map_t *m, uint32_t id)
{
    uint16_t s;
    for (s = 0; s < m->n_features; ++s) {
        if (m->features[s].id == id) {
            return s;
        }
    }
    return BSF_MAP_NONE;
}

/* End of feature fs a segment touches: 1 head, 2 tail, 3 both, 0 neither. */
static unsigned seg_end(const bsf_map_t *m, const label_t *l)
{
    return m->segs[l->seg].ends;
}

/* Which end of fs sample (x, y) is nearer to: 1 head, 2 tail. */
static unsigned nearer_end(const bsf_map_t *m, const bsf_map_feature_t *f, float x, float y)
{
    const bsf_map_ctrl_t *h = &m->ctrl[f->head];
    const bsf_map_ctrl_t *t = &m->ctrl[f->tail];
    const float dh = (h->x - x) * (h->x - x) + (h->y - y) * (h->y - y);
    const float dt = (t->x - x) * (t->x - x) + (t->y - y) * (t->y - y);
    return dh <= dt ? 1u : 2u;
}

/* The end of fs a matched sample joins, or 0 when it is not at an end. */
static unsigned joining_end(const bsf_map_t *m, const label_t *l, const sample_t *s)
{
    const unsigned ends = seg_end(m, l);
    if (ends == 3u) {
        return nearer_end(m, &m->features[l->feature], s->x, s->y);
    }
    if ((ends & 1u) && l->u < 0.5f) {
        return 1u;
    }
    if ((ends & 2u) && l->u > 0.5f) {
        return 2u;
    }
    return 0u;
}

/* Gate of a point at range r from the sensor (fuse_feature's). */
static float range_gate(const bsf_map_params_t *p, float r)
{
    const float g = p->match_dist_near + p->match_dist_per_m * r;
    return g < p->match_dist ? g : p->match_dist;
}

/* 1 when feature fu was never sent and each of its points lies within the
 * gate (at its range from the sensor sx, sy) of a chord of feature fa in
 * the search window: fu is a second copy of a stretch of fa, made when an
 * earlier scan's samples were labelled against a curve that rounded a
 * corner fa has since been given. */
static int copy_of(const bsf_map_t *m, uint16_t fu, uint16_t fa, float sx, float sy)
{
    const bsf_map_feature_t *u = &m->features[fu];
    uint16_t i;
    if ((u->flags & (BSF_MAP_FF_SENT | BSF_MAP_FF_OP)) != 0u) {
        return 0;
    }
    for (i = u->head; i != BSF_MAP_NONE; i = m->ctrl[i].next) {
        const bsf_map_ctrl_t *c = &m->ctrl[i];
        const float rx = c->x - sx;
        const float ry = c->y - sy;
        const float gate = range_gate(&m->params, sqrtf(rx * rx + ry * ry));
        int near = 0;
        uint16_t g;
        for (g = 0; g < m->n_segs && !near; ++g) {
            const bsf_map_seg_t *sg = &m->segs[g];
            bsf_map_ctrl_t a;
            bsf_map_ctrl_t b;
            if (sg->feature != fa) {
                continue;
            }
            a.x = sg->ax;
            a.y = sg->ay;
            b.x = sg->bx;
            b.y = sg->by;
            near = seg_dist2(c, &a, &b) <= gate * gate;
        }
        if (!near) {
            return 0;
        }
    }
    return 1;
}

/* 1 when a scan travelling along (tx, ty) leaves feature fs through its
 * end (1 head, 2 tail): the end's outward direction (from its inner
 * neighbour to it, the clamped curve's end tangent) runs with the travel.
 * A scan that meets an end while travelling into the feature is running
 * back over it (a second copy of the same face): joining or extending
 * there would fold the chain back on itself. */
static int leaves_through(const bsf_map_t *m, uint16_t fs, unsigned end, float tx, float ty)
{
    /* the end read directly, not through end_anchor(): this runs for every
     * labelled pair, and going through the anchor cost 0.2 % more fuse
     * instructions on the M4F */
    const bsf_map_feature_t *f = &m->features[fs];
    const uint16_t e = end == 1u ? f->head : f->tail;
    const uint16_t in = end == 1u ? m->ctrl[e].next : m->ctrl[e].prev;
    if (in == BSF_MAP_NONE) {
        return 1;
    }
    return (m->ctrl[e].x - m->ctrl[in].x) * tx + (m->ctrl[e].y - m->ctrl[in].y) * ty > 0.0f;
}

/* 1 when joining feature slot fa's end ea to slot fb's end eb, for a scan
 * whose samples qa and qb matched them, would turn the chain back over
 * itself (at a's end, from a's last leg into the join, or from the join
 * into b's first leg: legs, not the curve, which follows its control
 * polygon) at an end that lies farther than a control spacing from the
 * scan's sample: the scan did not reach that end (it matched a long end
 * span far from it), and the chain would run from the end back to it. A
 * fold between ends the scan reached is two overlapping copies, which
 * refinement pulls together. */
static int join_folds(const bsf_map_t *m, uint16_t fa, unsigned ea, const sample_t *qa, uint16_t fb,
                      unsigned eb, const sample_t *qb)
{
    const anchor_t a = end_anchor(m, &m->features[fa], ea);
    const anchor_t b = end_anchor(m, &m->features[fb], eb);
    const float sp2 = m->params.ctrl_spacing * m->params.ctrl_spacing;
    const float jx = b.x - a.x;
    const float jy = b.y - a.y;
    if ((a.x - qa->x) * (a.x - qa->x) + (a.y - qa->y) * (a.y - qa->y) <= sp2 &&
        (b.x - qb->x) * (b.x - qb->x) + (b.y - qb->y) * (b.y - qb->y) <= sp2) {
        return 0;
    }
    if (jx * jx + jy * jy < 1e-6f) {
        return turns_back(a.ox, a.oy, -b.ox, -b.oy);
    }
    return turns_back(a.ox, a.oy, jx, jy) || turns_back(jx, jy, -b.ox, -b.oy);
}

static void new_from_run(bsf_map_t *m, const sample_t *s, long from, long to);

/* Extend slot fs at end (1 head, 2 tail) with samples from..to, walking
 * outward from the matched part (its last sample `matched`, next to from).
 * Only a scan that leaves the feature through that end continues it; one
 * that runs back along it, or that left it well before the end for a
 * surface behind the end, would fold the chain back on itself there. */
static void extend(bsf_map_t *m, uint16_t fs, unsigned end, const sample_t *s, long from, long to,
                   long matched)
{
    bsf_map_feature_t *f = &m->features[fs];
    const anchor_t an = end_anchor(m, f, end);
    newpt_t p[MAX_SAMPLES];
    size_t n;
    const sample_t *q = &s[from];
    const sample_t *in = &s[matched]; /* the last matched sample, next to from */
    const float sp = m->params.ctrl_spacing;
    const float tx = from > matched ? q->dx : -q->dx;
    const float ty = from > matched ? q->dy : -q->dy;
    if (!leaves_through(m, fs, end, tx, ty)) {
        return; /* the scan runs back along the feature: nothing beyond its end */
    }
    if ((in->x - an.x) * (in->x - an.x) + (in->y - an.y) * (in->y - an.y) > sp * sp &&
        turns_back(an.ox, an.oy, q->x - an.x, q->y - an.y)) {
        /* the scan left the feature a spacing or more before its end (it
         * matched a long end span) and runs on behind the end: another
         * surface, not a continuation of this chain */
        new_from_run(m, s, from, to);
        return;
    }
    if (run_length(s, from, to) < MIN_RUN_SPACINGS * m->params.ctrl_spacing * 0.5f) {
        return;
    }
    n = resample(m->params.ctrl_spacing, s, from, to, &an, p, MAX_SAMPLES);
    if (n > 0u && chain_extend(m, f, p, n, end == 1u)) {
        feature_bbox(m, f);
        ++m->stats.n_extended;
    }
}

static void new_from_run(bsf_map_t *m, const sample_t *s, long from, long to)
{
    newpt_t p[MAX_SAMPLES];
    size_t n;
    if (run_length(s, from, to) < MIN_RUN_SPACINGS * m->params.ctrl_spacing) {
        return;
    }
    n = resample(m->params.ctrl_spacing, s, from, to, NULL, p, MAX_SAMPLES);
    (void)feature_new(m, p, n);
}

/* Join feature slot fu, never sent, to slot fs at fs's end es (fu's end eu
 * meeting it) through samples lo..hi (none when lo > hi), walked from fs
 * toward fu: upward, or downward when `down`. fu's points become unsent points at that end of fs,
 * so the next frame carries them as an append (or fs's new-feature record): no merge record is
 * needed. */
static int absorb(bsf_map_t *m, uint16_t fs, unsigned es, uint16_t fu, unsigned eu,
                  const sample_t *s, long lo, long hi, int down)
{
    bsf_map_feature_t *a = &m->features[fs];
    bsf_map_feature_t *u = &m->features[fu];
    const anchor_t an = end_anchor(m, a, es);
    newpt_t p[MAX_SAMPLES];
    size_t n = 0;
    if ((size_t)a->n_ctrl + u->n_ctrl + MAX_SAMPLES > BSF_MAP_REC_MAX_POINTS) {
        return 0;
    }
    if (lo <= hi) {
        const bsf_map_ctrl_t *o = &m->ctrl[eu == 1u ? u->head : u->tail];
        const float sp = m->params.ctrl_spacing;
        n = resample(m->params.ctrl_spacing, s, down ? hi : lo, down ? lo : hi, &an, p,
                     MAX_SAMPLES);
        while (n > 0u && !p[n - 1u].vertex &&
               (p[n - 1u].x - o->x) * (p[n - 1u].x - o->x) +
                       (p[n - 1u].y - o->y) * (p[n - 1u].y - o->y) <
                   0.25f * sp * sp) {
            --n;
        }
    }
    if (n > m->n_free_ctrl) {
        n = 0;
    }
    /* u oriented so that its joining end meets a's */
    if ((es == 2u) == (eu == 2u)) {
        chain_reverse(m, u);
    }
    /* u's points at its joining end that lie behind the join along the
     * scan's travel into u overlap a (two ends of one wall seen past each
     * other): linked as they are, the chain would run back and forth there */
    {
        const sample_t *t = &s[down ? lo - 1 : hi + 1];
        const float tx = down ? -t->dx : t->dx;
        const float ty = down ? -t->dy : t->dy;
        const float lx = n > 0u ? p[n - 1u].x : an.x;
        const float ly = n > 0u ? p[n - 1u].y : an.y;
        for (;;) {
            const uint16_t j = es == 2u ? u->head : u->tail;
            bsf_map_ctrl_t *c = &m->ctrl[j];
            if ((c->x - lx) * tx + (c->y - ly) * ty > 0.0f || (c->flags & BSF_MAP_CF_VERTEX) ||
                u->n_ctrl <= 2u) {
                break;
            }
            if (es == 2u) {
                u->head = c->next;
                m->ctrl[u->head].prev = BSF_MAP_NONE;
            } else {
                u->tail = c->prev;
                m->ctrl[u->tail].next = BSF_MAP_NONE;
            }
            c->next = BSF_MAP_NONE;
            chain_free(m, j);
            --u->n_ctrl;
        }
    }
    (void)chain_extend(m, a, p, n, es == 1u); /* outward from a's end */
    if (es == 2u) {
        m->ctrl[a->tail].next = u->head;
        m->ctrl[u->head].prev = a->tail;
        a->tail = u->tail;
    } else {
        m->ctrl[a->head].prev = u->tail;
        m->ctrl[u->tail].next = a->head;
        a->head = u->head;
    }
    a->n_ctrl = (uint16_t)(a->n_ctrl + u->n_ctrl);
    a->last_seen = m->stats.n_fused;
    feature_bbox(m, a);
    feature_remove_slot(m, fu);
    ++m->stats.n_merged;
    return 1;
}

/* Join slot fa (its end ea) to slot fb (its end eb) through samples
 * from..to (may be empty: from > to). Both must be fully sent, so that the
 * merge record can go before any other change to them. */
static int merge(bsf_map_t *m, uint16_t fa, unsigned ea, uint16_t fb, unsigned eb,
                 const sample_t *s, long from, long to)
{
    bsf_map_feature_t *a = &m->features[fa];
    bsf_map_feature_t *b = &m->features[fb];
    bsf_map_op_t *op;
    newpt_t p[MAX_SAMPLES];
    size_t n = 0;
    uint16_t first_bridge = BSF_MAP_NONE;
    if (!(b->flags & BSF_MAP_FF_SENT)) {
        return absorb(m, fa, ea, fb, eb, s, from, to, 0);
    }
    if (!(a->flags & BSF_MAP_FF_SENT)) {
        return absorb(m, fb, eb, fa, ea, s, from, to, 1);
    }
    if (m->n_ops >= BSF_MAP_MAX_OPS || ((a->flags | b->flags) & BSF_MAP_FF_OP) != 0u ||
        !bsf_map_chain_clean(m, a) || !bsf_map_chain_clean(m, b)) {
        return 0;
    }
    if ((size_t)a->n_ctrl + b->n_ctrl + MAX_SAMPLES > BSF_MAP_REC_MAX_POINTS) {
        return 0;
    }
    op = &m->ops[m->n_ops];
    op->flags = 0u;
    if (ea == 1u) {
        chain_reverse(m, a);
        op->flags |= BSF_MAP_OP_REV_A;
    }
    if (eb == 2u) {
        chain_reverse(m, b);
        op->flags |= BSF_MAP_OP_REV_B;
    }
    if (from <= to) {
        const anchor_t an = end_anchor(m, a, 2u);
        const bsf_map_ctrl_t *bh = &m->ctrl[b->head];
        const float sp = m->params.ctrl_spacing;
        n = resample(m->params.ctrl_spacing, s, from, to, &an, p, MAX_SAMPLES);
        /* no bridge point crowding b's head */
        while (n > 0u && !p[n - 1u].vertex &&
               (p[n - 1u].x - bh->x) * (p[n - 1u].x - bh->x) +
                       (p[n - 1u].y - bh->y) * (p[n - 1u].y - bh->y) <
                   0.25f * sp * sp) {
            --n;
        }
    }
    if (n > m->n_free_ctrl) {
        n = 0;
    }
    if (n > 0u) {
        const uint16_t old_tail = a->tail;
        (void)chain_extend(m, a, p, n, 0);
        first_bridge = m->ctrl[old_tail].next;
    }
    op->id_a = a->id;
    op->id_b = b->id;
    op->bridge = first_bridge;
    op->n_bridge = (uint16_t)n;
    op->upd_a = a->upd;
    op->upd_b = b->upd;
    ++m->n_ops;
    /* link b after a */
    m->ctrl[a->tail].next = b->head;
    m->ctrl[b->head].prev = a->tail;
    a->tail = b->tail;
    a->n_ctrl = (uint16_t)(a->n_ctrl + b->n_ctrl);
    a->upd = (uint8_t)((a->upd + 1u) & 15u);
    a->flags |= BSF_MAP_FF_OP;
    a->last_seen = m->stats.n_fused;
    feature_bbox(m, a);
    feature_remove_slot(m, fb);
    ++m->stats.n_merged;
    return 1;
}

/* Gate of a map vertex for a scan corner: a vertex that n scan corners
 * merged into is uncertain by about ctrl_spacing / n (the first one may be
 * a control point a rounded fit put up to a spacing from the corner, made a
 * vertex by make_vertex), never less than vertex_dist. A corner first placed
 * off by a grazing view is then pulled toward the corners seen later, and
 * the gate tightens as they agree. */
static float vertex_gate(const bsf_map_t *m, const bsf_map_ctrl_t *c)
{
    const float g = m->params.ctrl_spacing / (float)c->corner_obs;
    return g > m->params.vertex_dist ? g : m->params.vertex_dist;
}

/* Scan vertices near a map vertex move it by their running mean. */
static void fuse_vertices(bsf_map_t *m, sample_t *s, size_t ns)
{
    size_t k;
    uint16_t g;
    for (k = 0; k < ns; ++k) {
        uint16_t best = BSF_MAP_NONE;
        float bd = 3.0e38f;
        if (!s[k].vertex) {
            continue;
        }
        for (g = 0; g < m->n_segs; ++g) {
            unsigned j;
            for (j = 0; j < 3u; ++j) {
                const bsf_map_ctrl_t *c = &m->ctrl[m->segs[g].p[j]];
                float d2;
                float gate;
                if (!(c->flags & BSF_MAP_CF_VERTEX)) {
                    continue;
                }
                d2 = (c->x - s[k].x) * (c->x - s[k].x) + (c->y - s[k].y) * (c->y - s[k].y);
                gate = vertex_gate(m, c);
                if (d2 <= gate * gate && d2 <= bd) {
                    bd = d2;
                    best = m->segs[g].p[j];
                }
            }
        }
        if (best != BSF_MAP_NONE) {
            bsf_map_ctrl_t *c = &m->ctrl[best];
            const float w = (float)c->weight + 1.0f;
            c->x += (s[k].x - c->x) / w;
            c->y += (s[k].y - c->y) / w;
            if (c->corner_obs < 255u) {
                ++c->corner_obs;
            }
            if (c->weight < m->params.weight_cap) {
                ++c->weight;
            }
            ++m->stats.n_vertex_merged;
            /* the map has this corner: the sample is matched as a plain point */
            s[k].vertex = 0u;
        }
    }
}

/* A scan vertex that matched a map curve where the map has no vertex (the
 * curve was first seen without its corner): the span's control point that
 * weighs most in the curve at the match, if not a chain end, becomes a
 * vertex there. That is the point the curve rounds the corner with, however
 * far from the corner a rounded fit put it (a single span over two faces of
 * a box puts it well beyond the corner).
 * The receiver gets it as a move with a vertex toggle; later observations of
 * the corner merge into it. */
static void make_vertex(bsf_map_t *m, const label_t *l, const sample_t *q)
{
    const bsf_map_seg_t *sg = &m->segs[l->seg];
    float best = 0.0f;
    uint16_t pick = BSF_MAP_NONE;
    unsigned j;
    float b[3];
    span_basis(sg->ends, l->u, b);
    for (j = 0; j < 3u; ++j) {
        const bsf_map_ctrl_t *c = &m->ctrl[sg->p[j]];
        if ((c->flags & BSF_MAP_CF_VERTEX) != 0u) {
            return; /* the span already has its corner */
        }
        if (c->prev != BSF_MAP_NONE && c->next != BSF_MAP_NONE && b[j] > best) {
            best = b[j];
            pick = sg->p[j];
        }
    }
    if (pick != BSF_MAP_NONE) {
        bsf_map_ctrl_t *c = &m->ctrl[pick];
        c->x = q->x;
        c->y = q->y;
        c->flags |= BSF_MAP_CF_VERTEX;
        c->weight = 1u;
        c->corner_obs = 1u;
        ++m->stats.n_vertex_made;
    }
}

/* A scan corner left unmatched between samples matched to one map feature
 * (the map's curve rounds that corner off by more than the gate): the
 * feature's control point nearest to it, if not a chain end or a vertex and
 * within ctrl_spacing, becomes a vertex there, as make_vertex does. */
#define CORNER_REACH 8
static void make_vertex_between(bsf_map_t *m, const sample_t *s, const label_t *lab, size_t ns,
                                size_t k)
{
    const float sp = m->params.ctrl_spacing;
    float best = sp * sp;
    uint16_t pick = BSF_MAP_NONE;
    uint16_t f = BSF_MAP_NONE;
    uint16_t i;
    long a;
    long b;
    for (a = (long)k - 1; a >= 0 && a >= (long)k - CORNER_REACH; --a) {
        if (lab[a].feature != BSF_MAP_NONE) {
            f = lab[a].feature;
            break;
        }
    }
    for (b = (long)k + 1; b < (long)ns && b <= (long)k + CORNER_REACH; ++b) {
        if (lab[b].feature != BSF_MAP_NONE) {
            break;
        }
    }
    if (f == BSF_MAP_NONE || b >= (long)ns || b > (long)k + CORNER_REACH || lab[b].feature != f) {
        return;
    }
    for (i = m->features[f].head; i != BSF_MAP_NONE; i = m->ctrl[i].next) {
        const bsf_map_ctrl_t *c = &m->ctrl[i];
        const float d2 = (c->x - s[k].x) * (c->x - s[k].x) + (c->y - s[k].y) * (c->y - s[k].y);
        if (d2 < best && (c->flags & BSF_MAP_CF_VERTEX)) {
            return; /* the map has a corner there */
        }
        if (c->prev != BSF_MAP_NONE && c->next != BSF_MAP_NONE && d2 < best) {
            best = d2;
            pick = i;
        }
    }
    if (pick != BSF_MAP_NONE) {
        bsf_map_ctrl_t *c = &m->ctrl[pick];
        c->x = s[k].x;
        c->y = s[k].y;
        c->flags |= BSF_MAP_CF_VERTEX;
        c->weight = 1u;
        c->corner_obs = 1u;
        ++m->stats.n_vertex_made;
    }
}

/* Points of scan curve w (n >= 3 slots) at every knot and mid-span: two
 * per span and the curve's end, 2 n - 3 in all. */
static size_t knot_count(size_t n)
{
    return 2u * n - 3u;
}

/* Point i of those knot_count(n): knot i / 2 when i is even, else the middle
 * of span i / 2. */
static bsf_point_t knot_point(const bsf_point_t *w, size_t n, size_t i)
{
    const size_t k = i / 2u < n - 2u ? i / 2u : n - 3u; /* the span */
    const uint8_t ends = (uint8_t)((k == 0u ? 1u : 0u) | (k + 3u == n ? 2u : 0u));
    float b[3];
    bsf_point_t q;
    span_basis(ends, 0.5f * (float)(i - 2u * k), b);
    q.x = b[0] * w[k].x + b[1] * w[k + 1u].x + b[2] * w[k + 2u].x;
    q.y = b[0] * w[k].y + b[1] * w[k + 1u].y + b[2] * w[k + 2u].y;
    return q;
}

/* Points of a new map feature from scan curve w (n slots, vtx): the
 * curve at every knot and mid-span of the scan's B-spline, a vertex (two
 * slots) being the knot between its slots. A scan's control points lie off
 * its curve where it bends (a rounded corner's point, an outlying point of
 * a pillar fit); points on the curve give refinement points where the
 * surface is. Twice the scan's density keeps its bends, and each span of
 * the scan stays as long, so a point near an end the robot will not see
 * again is still covered by the basis of the samples that see the rest
 * (new points go out once observed three times). When that leaves fewer
 * than 3 points, the scan's own control points. Returns the count written
 * to p (room for 2 * BSF_MAX_CTRL_PER_FEATURE). */
static size_t new_points(const bsf_point_t *w, const uint8_t *vtx, size_t n, newpt_t *p)
{
    uint8_t pair[BSF_MAX_CTRL_PER_FEATURE];
    size_t np = 0;
    size_t k;
    memset(pair, 0, sizeof pair);
    for (k = 0; k + 1u < n; ++k) {
        if (vtx[k] && vtx[k + 1u]) {
            pair[k] = 1u;
            ++k;
        }
    }
    for (k = 0; k < knot_count(n); ++k) {
        const bsf_point_t q = knot_point(w, n, k);
        p[np].x = q.x;
        p[np].y = q.y;
        /* knot k / 2, not the curve's ends */
        p[np].vertex =
            (uint8_t)((k & 1u) == 0u && k > 0u && k + 1u < knot_count(n) && pair[k / 2u]);
        ++np;
    }
    if (np >= 3u) {
        return np;
    }
    np = 0;
    for (k = 0; k < n; ++k) {
        p[np].x = w[k].x;
        p[np].y = w[k].y;
        p[np].vertex = vtx[k] && k + 1u < n && vtx[k + 1u];
        ++np;
        if (p[np - 1u].vertex) {
            ++k;
        }
    }
    return np;
}

static void fuse_feature(bsf_map_t *m, const bsf_point_t *w, const uint8_t *vtx, size_t n, float sx,
                         float sy, near_t *nr)
{
    sample_t s[MAX_SAMPLES];
    label_t lab[MAX_SAMPLES];
    float box[4];
    size_t ns;
    size_t k;
    size_t j;
    long first = -1;
    long last = -1;

    if (!make_room(m, n + MAX_SAMPLES, 1u)) {
        ++m->stats.n_dropped_obs;
        return;
    }
    ns = sample_curve(w, vtx, n, s);
    if (ns == 0u) {
        return;
    }
    /* the gate grows with range: pose and range errors move far samples more */
    for (k = 0; k < ns; ++k) {
        float g = m->params.match_dist_near;
        if (m->params.match_dist_per_m > 0.0f) {
            const float ex = s[k].x - sx;
            const float ey = s[k].y - sy;
            g += m->params.match_dist_per_m * sqrtf(ex * ex + ey * ey);
        }
        s[k].gate = g < m->params.match_dist ? g : m->params.match_dist;
    }
    box[0] = box[1] = 3.0e38f;
    box[2] = box[3] = -3.0e38f;
    for (k = 0; k < ns; ++k) {
        box[0] = s[k].x < box[0] ? s[k].x : box[0];
        box[1] = s[k].y < box[1] ? s[k].y : box[1];
        box[2] = s[k].x > box[2] ? s[k].x : box[2];
        box[3] = s[k].y > box[3] ? s[k].y : box[3];
    }
    box[0] -= m->params.match_dist;
    box[1] -= m->params.match_dist;
    box[2] += m->params.match_dist;
    box[3] += m->params.match_dist;
    m->n_segs = 0u;
    if (!nr->valid || nr->removed != m->stats.n_merged + m->stats.n_forgotten) {
        gather_near(m, nr);
    }
    for (j = 0; j < nr->n; ++j) {
        const uint16_t fs = nr->slot[j];
        const bsf_map_feature_t *f = &m->features[fs];
        if ((f->flags & BSF_MAP_FF_FRESH) || f->max_x < box[0] || f->min_x > box[2] ||
            f->max_y < box[1] || f->min_y > box[3]) {
            continue;
        }
        build_segs(m, fs, box);
    }
    fuse_vertices(m, s, ns);
    label_samples(m, s, ns, lab);
    ++m->stats.n_obs;

    for (k = 0; k < ns; ++k) {
        if (lab[k].feature != BSF_MAP_NONE) {
            if (first < 0) {
                first = (long)k;
            }
            last = (long)k;
        }
    }
    if (first < 0) {
        /* nothing known: a new feature */
        newpt_t p[2u * BSF_MAX_CTRL_PER_FEATURE];
        (void)feature_new(m, p, new_points(w, vtx, n, p));
        return;
    }
    /* corners the map has not got yet */
    for (k = 0; k < ns; ++k) {
        if (s[k].vertex && lab[k].feature != BSF_MAP_NONE) {
            make_vertex(m, &lab[k], &s[k]);
        } else if (s[k].vertex) {
            make_vertex_between(m, s, lab, ns, k);
        }
    }
    /* refine every feature the samples matched, once each */
    for (k = 0; k < ns; ++k) {
        const uint16_t f = lab[k].feature;
        int seen = 0;
        if (f == BSF_MAP_NONE) {
            continue;
        }
        for (j = 0; j < k && !seen; ++j) {
            seen = lab[j].feature == f;
        }
        if (!seen) {
            refine(m, f, s, lab, ns);
            m->features[f].last_seen = m->stats.n_fused;
            feature_bbox(m, &m->features[f]);
        }
    }
    /* a gap or a change of feature between matched samples: a bridge */
    for (k = (size_t)first; k < (size_t)last; ++k) {
        if (lab[k].feature != BSF_MAP_NONE && lab[k + 1u].feature != lab[k].feature) {
            size_t g = k + 1u;
            while (lab[g].feature == BSF_MAP_NONE) {
                ++g;
            }
            if (lab[g].feature != lab[k].feature) {
                const unsigned ea = joining_end(m, &lab[k], &s[k]);
                const unsigned eb = joining_end(m, &lab[g], &s[g]);
                const int through = ea != 0u && eb != 0u &&
                                    leaves_through(m, lab[k].feature, ea, s[k].dx, s[k].dy) &&
                                    leaves_through(m, lab[g].feature, eb, -s[g].dx, -s[g].dy);
                if (ea != 0u && eb != 0u && !through) {
                    /* the scan does not leave one through its end and enter
                     * the other through its end: it runs back over one of
                     * them. A copy never sent goes (this scan refined the
                     * other); otherwise they merge unless the join folds */
                    uint16_t drop = BSF_MAP_NONE;
                    if (copy_of(m, lab[g].feature, lab[k].feature, sx, sy)) {
                        drop = lab[g].feature;
                    } else if (copy_of(m, lab[k].feature, lab[g].feature, sx, sy)) {
                        drop = lab[k].feature;
                    }
                    if (drop != BSF_MAP_NONE) {
                        chain_free(m, m->features[drop].head);
                        feature_remove_slot(m, drop);
                        ++m->stats.n_merged;
                        return; /* slots moved */
                    }
                }
                if (ea != 0u && eb != 0u &&
                    (through ||
                     !join_folds(m, lab[k].feature, ea, &s[k], lab[g].feature, eb, &s[g])) &&
                    merge(m, lab[k].feature, ea, lab[g].feature, eb, s, (long)k + 1, (long)g - 1)) {
                    /* slots moved: this observation's work ends here */
                    return;
                }
            }
            if (g > k + 1u) {
                new_from_run(m, s, (long)k + 1, (long)g - 1);
            }
            k = g - 1u;
        }
    }
    /* unmatched ends: extend the feature they continue, or start a new one */
    if (first > 0) {
        const unsigned e = joining_end(m, &lab[first], &s[first]);
        if (e != 0u) {
            extend(m, lab[first].feature, e, s, first - 1, 0, first);
        } else {
            new_from_run(m, s, 0, first - 1);
        }
    }
    if (last + 1 < (long)ns) {
        const unsigned e = joining_end(m, &lab[last], &s[last]);
        if (e != 0u) {
            extend(m, lab[last].feature, e, s, last + 1, (long)ns - 1, last);
        } else {
            new_from_run(m, s, last + 1, (long)ns - 1);
        }
    }
}

/* A feature never seen again (every point observed once) and never sent,
 * unseen for TRANSIENT_CALLS calls: a passer-by or noise; it is dropped
 * before it costs bytes. */
#define TRANSIENT_CALLS 5u

static void drop_transients(bsf_map_t *m)
{
    uint16_t fs = 0;
    while (fs < m->n_features) {
        const bsf_map_feature_t *f = &m->features[fs];
        int once = 1;
        uint16_t i;
        if ((f->flags & BSF_MAP_FF_SENT) || m->stats.n_fused - f->last_seen < TRANSIENT_CALLS) {
            ++fs;
            continue;
        }
        for (i = f->head; i != BSF_MAP_NONE && once; i = m->ctrl[i].next) {
            once = m->ctrl[i].weight <= 1u;
        }
        if (!once) {
            ++fs;
            continue;
        }
        chain_free(m, f->head);
        feature_remove_slot(m, fs);
        ++m->stats.n_transient;
    }
}

/* Bearing from (sx, sy) of each of the n points q, unwrapped along them,
 * and their range; returns the sense (+1 / -1) the points run in. */
static float bearings(const bsf_point_t *q, size_t n, float sx, float sy, float *th, float *r)
{
    size_t k;
    th[0] = 0.0f;
    for (k = 0; k < n; ++k) {
        const float ax = q[k].x - sx;
        const float ay = q[k].y - sy;
        r[k] = sqrtf(ax * ax + ay * ay);
        if (k > 0u) {
            const float bx = q[k - 1u].x - sx;
            const float by = q[k - 1u].y - sy;
            th[k] = th[k - 1u] + bsf_atan2f(bx * ay - by * ax, bx * ax + by * ay);
        }
    }
    return th[n - 1u] >= 0.0f ? 1.0f : -1.0f;
}

/* Of n points with bearings th (sense dir) and ranges r: *tail is the last
 * point of greatest bearing when a point after it falls back by more than
 * the gate at its range, else n; *head the first point of least bearing
 * when a point before it falls back so, else n. */
static void folds(const bsf_map_params_t *p, const float *th, const float *r, size_t n, float dir,
                  size_t *head, size_t *tail)
{
    size_t j;
    size_t k;
    *head = n;
    *tail = n;
    for (j = 0, k = 1; k < n; ++k) {
        j = dir * th[k] >= dir * th[j] ? k : j;
    }
    for (k = j + 1u; k < n; ++k) {
        if (dir * (th[j] - th[k]) * r[k] > range_gate(p, r[k])) {
            *tail = j;
            break;
        }
    }
    for (j = 0, k = 1; k < n; ++k) {
        j = dir * th[k] < dir * th[j] ? k : j;
    }
    for (k = 0; k < j; ++k) {
        if (dir * (th[k] - th[j]) * r[k] > range_gate(p, r[k])) {
            *head = j;
            break;
        }
    }
}

/* A scan sees each bearing once, so its curve runs one way in bearing from
 * the sensor. A fit whose curve turns back in bearing at an end (a hooked
 * tail fitted to a few returns at grazing incidence) describes no surface
 * the scan saw: when the curve past its point of greatest bearing falls back
 * by more than the association gate at that range (less is noise the gate
 * absorbs), the control points from the polygon's point of greatest bearing
 * on are cut (the curve is judged, not the polygon: a bulging span's middle
 * point lies off the curve). w and vtx (n slots, a vertex two flagged
 * slots) are cut in place; returns the slots that remain, or 0 when fewer
 * than 3 do. */
static size_t trim_folds(const bsf_map_params_t *p, bsf_point_t *w, uint8_t *vtx, size_t n,
                         float sx, float sy)
{
    bsf_point_t cv[2u * BSF_MAX_CTRL_PER_FEATURE];
    float th[2u * BSF_MAX_CTRL_PER_FEATURE];
    float r[2u * BSF_MAX_CTRL_PER_FEATURE];
    size_t nc = 0;
    size_t lo = 0;
    size_t hi = n - 1u;
    size_t head;
    size_t tail;
    size_t k;
    size_t m;
    float dir;
    for (nc = 0; nc < knot_count(n); ++nc) {
        cv[nc] = knot_point(w, n, nc);
    }
    dir = bearings(cv, nc, sx, sy, th, r);
    folds(p, th, r, nc, dir, &head, &tail);
    if (head == nc && tail == nc) {
        return n;
    }
    /* the cut: at the control polygon's extremes, in the curve's sense */
    (void)bearings(w, n, sx, sy, th, r);
    if (tail < nc) {
        size_t j = 0;
        for (k = 1; k < n; ++k) {
            j = dir * th[k] >= dir * th[j] ? k : j;
        }
        hi = j > 0u ? j - 1u : 0u;
    }
    if (head < nc) {
        size_t j = 0;
        for (k = 1; k < n; ++k) {
            j = dir * th[k] < dir * th[j] ? k : j;
        }
        lo = j + 1u;
    }
    if (hi + 1u <= lo || hi + 1u - lo < 3u) {
        return 0u;
    }
    /* a vertex left whole at an end becomes a plain end point (one slot), a
     * vertex cut in two a plain point */
    for (k = 0; k < n; ++k) {
        if (vtx[k] && k + 1u < n && vtx[k + 1u]) {
            if (k == lo) {
                ++lo;
            } else if (k + 1u == hi) {
                --hi;
            }
            ++k;
        }
    }
    vtx[lo] = 0u;
    vtx[hi] = 0u;
    m = hi + 1u - lo;
    if (m < 3u) {
        return 0u;
    }
    /* a cut end goes where the curve was (the knot between the point and
     * its inner neighbour), not at an off-curve control point */
    if (lo > 0u) {
        w[lo].x = 0.5f * (w[lo].x + w[lo + 1u].x);
        w[lo].y = 0.5f * (w[lo].y + w[lo + 1u].y);
    }
    if (hi + 1u < n) {
        w[hi].x = 0.5f * (w[hi].x + w[hi - 1u].x);
        w[hi].y = 0.5f * (w[hi].y + w[hi - 1u].y);
    }
    if (lo > 0u) {
        memmove(w, w + lo, m * sizeof w[0]);
        memmove(vtx, vtx + lo, m);
    }
    return m;
}

/* A chain whose two ends meet where the legs that end it cross, the ends
 * and the crossing all within match_dist of each other (the widest gate at
 * which two observations are one surface point): the chain runs round a
 * convex object and closes at a corner that no scan sees as one, since
 * each scan's feature ends there (a silhouette). Both ends go to the
 * crossing, and the tail there becomes the corner's vertex (one vertex: the
 * head meets it). Parallel legs never cross near: a loop closed along a
 * straight wall is left as it is. */
static void close_loops(bsf_map_t *m)
{
    const float md2 = m->params.match_dist * m->params.match_dist;
    const float near2 = m->params.match_dist_near * m->params.match_dist_near;
    uint16_t fs;
    for (fs = 0; fs < m->n_features; ++fs) {
        const bsf_map_feature_t *f = &m->features[fs];
        bsf_map_ctrl_t *h;
        bsf_map_ctrl_t *t;
        const bsf_map_ctrl_t *h1;
        const bsf_map_ctrl_t *t1;
        float ax;
        float ay;
        float bx;
        float by;
        float cross;
        float sa;
        float xx;
        float xy;
        float mx;
        float my;
        if (f->last_seen != m->stats.n_fused || (f->flags & BSF_MAP_FF_OP) != 0u ||
            f->n_ctrl < 4u) {
            continue;
        }
        h = &m->ctrl[f->head];
        t = &m->ctrl[f->tail];
        h1 = &m->ctrl[h->next];
        t1 = &m->ctrl[t->prev];
        if ((h->flags & BSF_MAP_CF_VERTEX) != 0u ||
            (h->x - t->x) * (h->x - t->x) + (h->y - t->y) * (h->y - t->y) > md2) {
            continue;
        }
        ax = h->x - h1->x;
        ay = h->y - h1->y;
        bx = t->x - t1->x;
        by = t->y - t1->y;
        cross = ax * by - ay * bx;
        if (cross * cross <= 1e-12f * (ax * ax + ay * ay) * (bx * bx + by * by)) {
            continue;
        }
        /* h + sa * a = t + sb * b */
        sa = ((t->x - h->x) * by - (t->y - h->y) * bx) / cross;
        xx = h->x + sa * ax;
        xy = h->y + sa * ay;
        if ((xx - h->x) * (xx - h->x) + (xy - h->y) * (xy - h->y) > md2 ||
            (xx - t->x) * (xx - t->x) + (xy - t->y) * (xy - t->y) > md2) {
            continue;
        }
        /* a smooth join (one plain point at the crossing) passes a quarter
         * of the crossing's distance from its neighbours' midpoint away from
         * it: within the tightest gate, the ends are explained without a
         * corner (a round pillar closing on itself) */
        mx = 0.5f * (h1->x + t1->x) - xx;
        my = 0.5f * (h1->y + t1->y) - xy;
        if (0.0625f * (mx * mx + my * my) <= near2) {
            continue;
        }
        if (!(t->flags & BSF_MAP_CF_VERTEX)) {
            t->flags |= BSF_MAP_CF_VERTEX;
            t->corner_obs = 1u;
            ++m->stats.n_vertex_made;
        }
        h->x = xx;
        h->y = xy;
        t->x = xx;
        t->y = xy;
    }
}

static bsf_status_t check_scan(const bsf_result_t *scan, const bsf_pose_t *pose, float step)
{
    /* world coordinates stay within what the wire's quantised values hold */
    const float wire_max = 0.9f * (float)BSF_MAP_Q_MAX * step;
    const float coord_max = wire_max < MAP_COORD_MAX ? wire_max : MAP_COORD_MAX;
    size_t i;
    if (!finite_f(pose->x) || !finite_f(pose->y) || !finite_f(pose->theta) ||
        fabsf(pose->x) > BSF_POSE_XY_MAX || fabsf(pose->y) > BSF_POSE_XY_MAX ||
        fabsf(pose->theta) > BSF_POSE_THETA_MAX) {
        return BSF_ERR_ARG;
    }
    if (scan->n_features > BSF_MAX_SEGMENTS || scan->n_ctrl > BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    for (i = 0; i < scan->n_features; ++i) {
        const bsf_feature_t *f = &scan->features[i];
        size_t j;
        if (f->n_ctrl < 3u || f->n_ctrl > BSF_MAX_CTRL_PER_FEATURE ||
            (size_t)f->ctrl_first + f->n_ctrl > scan->n_ctrl) {
            return BSF_ERR_ARG;
        }
        for (j = f->ctrl_first; j < (size_t)f->ctrl_first + f->n_ctrl; ++j) {
            const float x = scan->ctrl[j].x;
            const float y = scan->ctrl[j].y;
            if (!finite_f(x) || !finite_f(y) || fabsf(x) > coord_max || fabsf(y) > coord_max) {
                return BSF_ERR_ARG;
            }
            if (fabsf(pose->x) + fabsf(x) + fabsf(y) > coord_max ||
                fabsf(pose->y) + fabsf(x) + fabsf(y) > coord_max) {
                return BSF_ERR_ARG;
            }
        }
    }
    return BSF_OK;
}

int bsf_map_fuse(bsf_map_t *map, const bsf_result_t *scan, const bsf_pose_t *pose)
{
    near_t nr;
    float c;
    float sn;
    size_t i;
    bsf_status_t st;
    uint16_t fs;
    if (map == NULL || scan == NULL || pose == NULL) {
        return BSF_ERR_ARG;
    }
    st = check_scan(scan, pose, map->params.quant_step);
    if (st != BSF_OK) {
        return st;
    }
    ++map->stats.n_fused;
    for (fs = 0; fs < map->n_features; ++fs) {
        map->features[fs].flags &= (uint8_t)~BSF_MAP_FF_FRESH;
    }
    drop_transients(map);
    /* the library's own sine and cosine: the C library's differ in the last
     * bits between targets, and the map must be the same on every one */
    bsf_sincosf(pose->theta, &sn, &c);
    nr.valid = 0;
    nr.n = 0u;
    nr.removed = 0u;
    nr.box[0] = nr.box[1] = 3.0e38f;
    nr.box[2] = nr.box[3] = -3.0e38f;
    for (i = 0; i < scan->n_features; ++i) {
        const bsf_feature_t *f = &scan->features[i];
        size_t j;
        for (j = f->ctrl_first; j < (size_t)f->ctrl_first + f->n_ctrl; ++j) {
            const bsf_point_t *p = &scan->ctrl[j];
            const float x = pose->x + c * p->x - sn * p->y;
            const float y = pose->y + sn * p->x + c * p->y;
            nr.box[0] = x < nr.box[0] ? x : nr.box[0];
            nr.box[1] = y < nr.box[1] ? y : nr.box[1];
            nr.box[2] = x > nr.box[2] ? x : nr.box[2];
            nr.box[3] = y > nr.box[3] ? y : nr.box[3];
        }
    }
    nr.box[0] -= map->params.match_dist;
    nr.box[1] -= map->params.match_dist;
    nr.box[2] += map->params.match_dist;
    nr.box[3] += map->params.match_dist;
    for (i = 0; i < scan->n_features; ++i) {
        const bsf_feature_t *f = &scan->features[i];
        bsf_point_t w[BSF_MAX_CTRL_PER_FEATURE];
        uint8_t vtx[BSF_MAX_CTRL_PER_FEATURE];
        size_t j;
        size_t n;
        for (j = 0; j < f->n_ctrl; ++j) {
            const bsf_point_t *p = &scan->ctrl[f->ctrl_first + j];
            w[j].x = pose->x + c * p->x - sn * p->y;
            w[j].y = pose->y + sn * p->x + c * p->y;
            vtx[j] = scan->ctrl_is_vertex[f->ctrl_first + j];
        }
        n = trim_folds(&map->params, w, vtx, f->n_ctrl, pose->x, pose->y);
        if (n != f->n_ctrl) {
            ++map->stats.n_folds_cut;
        }
        if (n > 0u) {
            fuse_feature(map, w, vtx, n, pose->x, pose->y, &nr);
        }
    }
    close_loops(map);
    return (int)scan->n_features;
}

/* ---- Accessors ------------------------------------------------------------ */

size_t bsf_map_feature_count(const bsf_map_t *map)
{
    return map != NULL ? map->n_features : 0u;
}

int bsf_map_feature_ctrl(const bsf_map_t *map, size_t index, int sent, bsf_point_t *ctrl,
                         uint8_t *is_vertex, size_t cap, uint32_t *id)
{
    const bsf_map_feature_t *f;
    uint16_t i;
    size_t n = 0;
    if (map == NULL || index >= map->n_features) {
        return BSF_ERR_ARG;
    }
    f = &map->features[index];
    if (id != NULL) {
        *id = f->id;
    }
    for (i = f->head; i != BSF_MAP_NONE; i = map->ctrl[i].next) {
        const bsf_map_ctrl_t *c = &map->ctrl[i];
        const unsigned reps =
            (c->flags & (sent ? BSF_MAP_CF_SENT_VTX : BSF_MAP_CF_VERTEX)) != 0u ? 2u : 1u;
        unsigned r;
        if (sent && !(c->flags & BSF_MAP_CF_SENT)) {
            continue;
        }
        for (r = 0; r < reps; ++r, ++n) {
            if (n < cap) {
                if (ctrl != NULL) {
                    ctrl[n].x = sent ? (float)c->qx * map->params.quant_step : c->x;
                    ctrl[n].y = sent ? (float)c->qy * map->params.quant_step : c->y;
                }
                if (is_vertex != NULL) {
                    is_vertex[n] = (uint8_t)(reps - 1u);
                }
            }
        }
    }
    return (int)n;
}

int bsf_map_feature_q(const bsf_map_t *map, size_t index, int32_t *q, uint8_t *is_vertex,
                      size_t cap, uint32_t *id)
{
    const bsf_map_feature_t *f;
    uint16_t i;
    size_t n = 0;
    if (map == NULL || index >= map->n_features) {
        return BSF_ERR_ARG;
    }
    f = &map->features[index];
    if (id != NULL) {
        *id = f->id;
    }
    for (i = f->head; i != BSF_MAP_NONE; i = map->ctrl[i].next) {
        const bsf_map_ctrl_t *c = &map->ctrl[i];
        if (!(c->flags & BSF_MAP_CF_SENT)) {
            continue;
        }
        if (n < cap) {
            if (q != NULL) {
                q[2u * n] = c->qx;
                q[2u * n + 1u] = c->qy;
            }
            if (is_vertex != NULL) {
                is_vertex[n] = (c->flags & BSF_MAP_CF_SENT_VTX) ? 1u : 0u;
            }
        }
        ++n;
    }
    return (int)n;
}
