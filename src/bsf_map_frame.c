/* SPDX-License-Identifier: MIT */
/*
 * bsf_map_frame.c - map-update frames (docs/FORMAT.md section 11): the
 * robot's encoder, the syntax check the stream decoder runs on them, and the
 * receiver's map that applies them.
 */
#include <math.h>
#include <string.h>

#include "bsf/bsf_map.h"
#include "bsf/bsf_stream.h"
#include "bsf_frame_parsers.h"
#include "bsf_map_internal.h"
#include "bsf_wire.h"

#define MAP_BYTE0 ((uint8_t)((BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_MAP))
/* Largest tag + id + count of a record, bytes (1 + 5 + 3 + 5 slack). */
#define REC_HEAD_MAX 14u
/* Largest |delta| of a quantised coordinate. */
#define DELTA_MAX (2L * BSF_MAP_Q_MAX)
#define POSE_MM_MAX 2000000000L

/* ---- Byte writer (LEB128 varints) ------------------------------------------ */

typedef struct {
    uint8_t *p;
    uint8_t *end;
    int full;
    uint8_t *rec_start; /* the record being written, for the byte tally */
    unsigned rec_op;
    uint32_t bytes[BSF_MAP_REC_OPS];
} wr_t;

static unsigned ulen(uint32_t v)
{
    unsigned n = 1u;
    while (v >= 0x80u) {
        v >>= 7;
        ++n;
    }
    return n;
}

static void put_byte(wr_t *w, uint8_t b)
{
    if (w->p >= w->end) {
        w->full = 1;
        return;
    }
    *w->p++ = b;
}

static void put_u(wr_t *w, uint32_t v)
{
    while (v >= 0x80u) {
        put_byte(w, (uint8_t)(v | 0x80u));
        v >>= 7;
    }
    put_byte(w, (uint8_t)v);
}

static uint32_t zz(int32_t v)
{
    return (uint32_t)bsf_wire_zigzag((int64_t)v);
}

/* A point whose zigzag differences are both below SHORT_POINT takes two
 * bytes (most points of a wall 25 cm apart at 5 mm steps); others a uvar of
 * (zigzag dx, vertex, 0) and an svar dy. */
#define SHORT_POINT 128u

static unsigned point_len(int32_t dx, int32_t dy, unsigned vertex)
{
    const uint32_t zx = zz(dx);
    const uint32_t zy = zz(dy);
    if (zx < SHORT_POINT && zy < SHORT_POINT) {
        return 2u;
    }
    return ulen((zx << 2) | (vertex << 1)) + ulen(zy);
}

static void put_point(wr_t *w, int32_t dx, int32_t dy, unsigned vertex)
{
    const uint32_t zx = zz(dx);
    const uint32_t zy = zz(dy);
    if (zx < SHORT_POINT && zy < SHORT_POINT) {
        put_byte(w, (uint8_t)(((zx & 0x3Fu) << 2) | (vertex << 1) | 1u));
        put_byte(w, (uint8_t)(((zx >> 6) << 7) | zy));
        return;
    }
    put_u(w, (zx << 2) | (vertex << 1));
    put_u(w, zy);
}

/* ---- Byte reader ------------------------------------------------------------- */

typedef struct {
    const uint8_t *p;
    const uint8_t *end;
} rd_t;

/* A minimal LEB128 value <= max; 0 when malformed. */
static int get_u(rd_t *r, uint32_t max, uint32_t *v)
{
    uint64_t acc = 0;
    unsigned shift = 0;
    for (;;) {
        uint8_t b;
        if (r->p >= r->end || shift > 28u) {
            return 0;
        }
        b = *r->p++;
        acc |= (uint64_t)(b & 0x7Fu) << shift;
        if (!(b & 0x80u)) {
            if (b == 0u && shift > 0u) {
                return 0; /* non-minimal */
            }
            break;
        }
        shift += 7u;
    }
    if (acc > max) {
        return 0;
    }
    *v = (uint32_t)acc;
    return 1;
}

static int get_s(rd_t *r, int64_t max_abs, int64_t *v)
{
    uint32_t u;
    if (!get_u(r, 0xFFFFFFFFu, &u)) {
        return 0;
    }
    *v = bsf_wire_unzigzag(u);
    return *v >= -max_abs && *v <= max_abs;
}

/* A point delta with its vertex bit, in its short (two bytes) or long form;
 * a long form that the short one could hold is malformed, so that every
 * point has one coding. */
static int get_point(rd_t *r, int64_t *dx, int64_t *dy, uint8_t *vertex)
{
    uint32_t u;
    uint32_t zy;
    if (r->p < r->end && (*r->p & 1u)) {
        uint8_t b0;
        uint8_t b1;
        if (r->end - r->p < 2) {
            return 0;
        }
        b0 = r->p[0];
        b1 = r->p[1];
        r->p += 2;
        *vertex = (uint8_t)((b0 >> 1) & 1u);
        *dx = bsf_wire_unzigzag((uint64_t)((b0 >> 2) | ((b1 >> 7) << 6)));
        *dy = bsf_wire_unzigzag((uint64_t)(b1 & 0x7Fu));
        return 1;
    }
    if (!get_u(r, 0xFFFFFFFFu, &u) || (u & 1u) != 0u || !get_u(r, 0xFFFFFFFFu, &zy)) {
        return 0;
    }
    if ((u >> 2) < SHORT_POINT && zy < SHORT_POINT) {
        return 0;
    }
    *vertex = (uint8_t)((u >> 1) & 1u);
    *dx = bsf_wire_unzigzag(u >> 2);
    *dy = bsf_wire_unzigzag(zy);
    return *dx >= -DELTA_MAX && *dx <= DELTA_MAX && *dy >= -DELTA_MAX && *dy <= DELTA_MAX;
}

static int q_ok(int64_t q)
{
    return q >= -BSF_MAP_Q_MAX && q <= BSF_MAP_Q_MAX;
}

/* ---- Records: one parser for the check and for the receiver --------------- */

typedef struct {
    unsigned op;
    unsigned upd;
    unsigned high;
    uint32_t id;
    uint32_t id_b;      /* merge */
    unsigned upd_b;     /* merge */
    unsigned rev_b;     /* merge */
    uint32_t start;     /* snapshot: index of its first point */
    uint32_t n;         /* points of the record */
    const uint8_t *pts; /* where its points start */
    int32_t pose[3];
} rec_t;

/* Header of one record and a syntax pass over its points (r ends after it).
 * prev_id carries the id of the previous record. */
static int get_record(rd_t *r, int64_t *prev_id, rec_t *rec)
{
    uint8_t tag;
    int64_t d;
    uint32_t i;
    if (r->p >= r->end) {
        return 0;
    }
    tag = *r->p++;
    memset(rec, 0, sizeof *rec);
    rec->op = tag & 7u;
    rec->upd = (tag >> BSF_MAP_TAG_UPD_SHIFT) & 15u;
    rec->high = (tag & BSF_MAP_TAG_HIGH) ? 1u : 0u;
    if (rec->op > BSF_MAP_REC_ID_LIMIT) {
        return 0;
    }
    if (rec->op == BSF_MAP_REC_ID_LIMIT) {
        return rec->upd == 0u && !rec->high && get_u(r, 0xFFFFFFFFu, &rec->id);
    }
    if (rec->op == BSF_MAP_REC_POSE) {
        int64_t x;
        int64_t y;
        uint32_t th;
        if (rec->upd != 0u || rec->high || !get_s(r, POSE_MM_MAX, &x) ||
            !get_s(r, POSE_MM_MAX, &y) || !get_u(r, 65535u, &th)) {
            return 0;
        }
        rec->pose[0] = (int32_t)x;
        rec->pose[1] = (int32_t)y;
        rec->pose[2] = (int32_t)th;
        return 1;
    }
    if (rec->high && rec->op != BSF_MAP_REC_APPEND && rec->op != BSF_MAP_REC_MERGE &&
        rec->op != BSF_MAP_REC_SNAPSHOT) {
        return 0;
    }
    if (rec->op == BSF_MAP_REC_NEW && rec->upd != 0u) {
        return 0;
    }
    if (!get_s(r, 0xFFFFFFFFLL, &d) || *prev_id + d < 0 || *prev_id + d > 0xFFFFFFFFLL) {
        return 0;
    }
    *prev_id += d;
    rec->id = (uint32_t)*prev_id;
    if (rec->op == BSF_MAP_REC_MERGE) {
        uint8_t b;
        int64_t db;
        if (r->p >= r->end) {
            return 0;
        }
        b = *r->p++;
        if (b > 31u) {
            return 0;
        }
        rec->upd_b = b & 15u;
        rec->rev_b = b >> 4;
        if (!get_s(r, 0xFFFFFFFFLL, &db) || db == 0 || *prev_id + db < 0 ||
            *prev_id + db > 0xFFFFFFFFLL) {
            return 0;
        }
        rec->id_b = (uint32_t)(*prev_id + db);
    }
    if (rec->op == BSF_MAP_REC_SNAPSHOT && !get_u(r, BSF_MAP_REC_MAX_POINTS - 1u, &rec->start)) {
        return 0;
    }
    if (!get_u(r, BSF_MAP_REC_MAX_POINTS, &rec->n) ||
        (uint64_t)rec->start + rec->n > BSF_MAP_REC_MAX_POINTS) {
        return 0;
    }
    if ((rec->op == BSF_MAP_REC_NEW && rec->n < 2u) ||
        ((rec->op == BSF_MAP_REC_APPEND || rec->op == BSF_MAP_REC_MOVE ||
          rec->op == BSF_MAP_REC_SNAPSHOT) &&
         rec->n < 1u)) {
        return 0;
    }
    rec->pts = r->p;
    if (rec->op == BSF_MAP_REC_MOVE) {
        int64_t idx = -1;
        for (i = 0; i < rec->n; ++i) {
            uint32_t gap;
            int64_t dx;
            int64_t dy;
            if (!get_u(r, 2u * BSF_MAP_REC_MAX_POINTS + 1u, &gap) || !get_s(r, DELTA_MAX, &dx) ||
                !get_s(r, DELTA_MAX, &dy)) {
                return 0;
            }
            idx += (int64_t)(gap >> 1) + 1;
            if (idx >= (int64_t)BSF_MAP_REC_MAX_POINTS) {
                return 0;
            }
        }
    } else {
        /* absolute records check their coordinates here; relative ones
         * against the receiver's end point when applied */
        const int absolute = rec->op == BSF_MAP_REC_NEW || rec->op == BSF_MAP_REC_SNAPSHOT;
        int64_t q[2] = {0, 0};
        for (i = 0; i < rec->n; ++i) {
            int64_t dx;
            int64_t dy;
            uint8_t v;
            if (!get_point(r, &dx, &dy, &v)) {
                return 0;
            }
            q[0] += dx;
            q[1] += dy;
            if (absolute && (!q_ok(q[0]) || !q_ok(q[1]))) {
                return 0;
            }
        }
    }
    return 1;
}

static int get_header(rd_t *r, uint32_t *seq, uint32_t *step_code)
{
    if (r->p >= r->end || *r->p != MAP_BYTE0) {
        return 0;
    }
    ++r->p;
    return get_u(r, 0xFFFFFFFFu, seq) && get_u(r, BSF_WIRE_STEP_CODE_MAX, step_code) &&
           *step_code >= 1u;
}

bsf_status_t bsf_map_frame_check(const uint8_t *payload, size_t len, uint32_t *seq)
{
    rd_t r;
    uint32_t step_code;
    int64_t prev_id = 0;
    rec_t rec;
    r.p = payload;
    r.end = payload + len;
    if (!get_header(&r, seq, &step_code)) {
        return BSF_ERR_FORMAT;
    }
    while (r.p < r.end) {
        if (!get_record(&r, &prev_id, &rec)) {
            return BSF_ERR_FORMAT;
        }
    }
    return BSF_OK;
}

bsf_status_t bsf_map_frame_parse(const uint8_t *payload, size_t len, bsf_frame_t *out)
{
    uint32_t seq = 0u;
    uint32_t step_code = 1u;
    rd_t r;
    const bsf_status_t st = bsf_map_frame_check(payload, len, &seq);
    if (st != BSF_OK || out == NULL) {
        return st;
    }
    r.p = payload;
    r.end = payload + len;
    (void)get_header(&r, &seq, &step_code);
    out->version = (uint8_t)BSF_FORMAT_VERSION;
    out->type = (uint8_t)BSF_FRAME_TYPE_MAP;
    out->seq = seq;
    out->timestamp_ms = 0u;
    out->has_pose = 0u;
    out->pose.x = 0.0f;
    out->pose.y = 0.0f;
    out->pose.theta = 0.0f;
    out->quant_step = (float)step_code * BSF_QUANT_STEP_UNIT;
    out->time_us = 0u;
    out->has_geometry = 0u;
    out->angle_min = 0.0f;
    out->angle_increment = 0.0f;
    out->result.n_features = 0u;
    out->result.n_ctrl = 0u;
    memset(&out->result.stats, 0, sizeof out->result.stats);
    return BSF_OK;
}

/* ---- Encoder ------------------------------------------------------------------ */

static int32_t quant_clamped(float v, float inv_step)
{
    int32_t q = bsf_map_quant(v, inv_step);
    if (q > (int32_t)BSF_MAP_Q_MAX) {
        q = (int32_t)BSF_MAP_Q_MAX;
    } else if (q < -(int32_t)BSF_MAP_Q_MAX) {
        q = -(int32_t)BSF_MAP_Q_MAX;
    }
    return q;
}

/* Payload bytes by record operation: each record runs from its tag to the
 * next tag or the end of the records. */
static void tally_close(wr_t *w)
{
    if (w->rec_start != NULL && w->p > w->rec_start) {
        w->bytes[w->rec_op] += (uint32_t)(w->p - w->rec_start);
    }
    w->rec_start = NULL;
}

static void put_tag(wr_t *w, unsigned op, unsigned upd, unsigned high)
{
    tally_close(w);
    w->rec_start = w->p;
    w->rec_op = op;
    put_byte(
        w, (uint8_t)(op | ((upd & 15u) << BSF_MAP_TAG_UPD_SHIFT) | (high ? BSF_MAP_TAG_HIGH : 0u)));
}

static void put_id(wr_t *w, int64_t *prev_id, uint32_t id)
{
    put_u(w, (uint32_t)bsf_wire_zigzag((int64_t)id - *prev_id));
    *prev_id = id;
}

/* Points from pool index `from` following next (dir 0) or prev (dir 1), at
 * most max_n, delta-coded from (*qx, *qy); with `mark` the points get their
 * sent values. Returns how many fit in `room` bytes (all when room is 0 and
 * mark is set: the caller measured). */
static uint32_t span_points(bsf_map_t *m, uint16_t from, int dir, uint32_t max_n, size_t room,
                            wr_t *w, int32_t *qx, int32_t *qy)
{
    const float inv = 1.0f / m->params.quant_step;
    uint32_t n = 0;
    size_t used = 0;
    int32_t px = *qx;
    int32_t py = *qy;
    uint16_t i = from;
    while (i != BSF_MAP_NONE && n < max_n) {
        bsf_map_ctrl_t *c = &m->ctrl[i];
        const int32_t x = quant_clamped(c->x, inv);
        const int32_t y = quant_clamped(c->y, inv);
        const unsigned v = (c->flags & BSF_MAP_CF_VERTEX) ? 1u : 0u;
        if (w == NULL) {
            const unsigned l = point_len(x - px, y - py, v);
            if (used + l > room) {
                break;
            }
            used += l;
        } else {
            put_point(w, x - px, y - py, v);
            c->qx = x;
            c->qy = y;
            c->flags = (uint8_t)((c->flags & ~BSF_MAP_CF_SENT_VTX) | BSF_MAP_CF_SENT |
                                 (v ? BSF_MAP_CF_SENT_VTX : 0u));
        }
        px = x;
        py = y;
        ++n;
        i = dir ? c->prev : c->next;
    }
    *qx = px;
    *qy = py;
    return n;
}

static size_t room_of(const wr_t *w)
{
    const size_t r = (size_t)(w->end - w->p);
    return r > REC_HEAD_MAX ? r - REC_HEAD_MAX : 0u;
}

/* Points of a run of unsent points starting at `from` (dir as above). */
static uint32_t unsent_run(const bsf_map_t *m, uint16_t from, int dir)
{
    uint32_t n = 0;
    while (from != BSF_MAP_NONE && !(m->ctrl[from].flags & BSF_MAP_CF_SENT)) {
        ++n;
        from = dir ? m->ctrl[from].prev : m->ctrl[from].next;
    }
    return n;
}

/* A new point is held back until it has been observed HOLD_OBS times, or
 * its feature has gone unseen for HOLD_CALLS fuse calls: the first
 * observations move it most, and a point sent early would be sent again as
 * a move. */
#define HOLD_OBS 3u
#define HOLD_CALLS 5u

static int ripe(const bsf_map_t *m, const bsf_map_feature_t *f, const bsf_map_ctrl_t *c)
{
    return c->weight >= HOLD_OBS || m->stats.n_fused - f->last_seen >= HOLD_CALLS;
}

/* Ripe points of a run of unsent points from `from` outward (dir as above). */
static uint32_t ripe_run(const bsf_map_t *m, const bsf_map_feature_t *f, uint16_t from, int dir)
{
    uint32_t n = 0;
    while (from != BSF_MAP_NONE && !(m->ctrl[from].flags & BSF_MAP_CF_SENT) &&
           ripe(m, f, &m->ctrl[from])) {
        ++n;
        from = dir ? m->ctrl[from].prev : m->ctrl[from].next;
    }
    return n;
}

int bsf_map_pending(const bsf_map_t *map)
{
    const float step = map != NULL ? map->params.quant_step : 0.0f;
    const float tol2 = map != NULL ? map->params.send_tol * map->params.send_tol : 0.0f;
    uint16_t s;
    if (map == NULL) {
        return 0;
    }
    if (map->n_ops > 0u) {
        return 1;
    }
    for (s = 0; s < map->n_features; ++s) {
        const bsf_map_feature_t *f = &map->features[s];
        uint16_t i;
        if (!(f->flags & BSF_MAP_FF_SENT)) {
            if (ripe_run(map, f, f->head, 0) == f->n_ctrl) {
                return 1;
            }
            continue;
        }
        for (i = f->head; i != BSF_MAP_NONE; i = map->ctrl[i].next) {
            const bsf_map_ctrl_t *c = &map->ctrl[i];
            if (c->flags & BSF_MAP_CF_SENT) {
                if (bsf_map_ctrl_moved(c, step, tol2)) {
                    return 1;
                }
            } else if (ripe(map, f, c) &&
                       ((c->prev != BSF_MAP_NONE && (map->ctrl[c->prev].flags & BSF_MAP_CF_SENT)) ||
                        (c->next != BSF_MAP_NONE &&
                         (map->ctrl[c->next].flags & BSF_MAP_CF_SENT)))) {
                return 1; /* a ripe point next to the sent part: an append */
            }
        }
    }
    return 0;
}

/* A merge record; 0 when it does not fit. */
static int put_merge(bsf_map_t *m, wr_t *w, int64_t *prev_id, const bsf_map_op_t *op)
{
    const uint16_t sa = bsf_map_slot_of_id(m, op->id_a);
    uint8_t *const save = w->p;
    const int64_t save_id = *prev_id;
    uint16_t after_a;
    int32_t qx;
    int32_t qy;
    uint32_t n;
    if (sa == BSF_MAP_NONE) {
        return 1; /* cannot happen: a queued merge keeps its feature in RAM */
    }
    /* a's tail before the bridge: its sent value starts the bridge's deltas */
    after_a = op->n_bridge > 0u ? m->ctrl[op->bridge].prev : BSF_MAP_NONE;
    qx = after_a != BSF_MAP_NONE ? m->ctrl[after_a].qx : 0;
    qy = after_a != BSF_MAP_NONE ? m->ctrl[after_a].qy : 0;
    put_tag(w, BSF_MAP_REC_MERGE, op->upd_a, op->flags & BSF_MAP_OP_REV_A);
    put_id(w, prev_id, op->id_a);
    put_byte(w, (uint8_t)((op->upd_b & 15u) | ((op->flags & BSF_MAP_OP_REV_B) ? 16u : 0u)));
    put_u(w, (uint32_t)bsf_wire_zigzag((int64_t)op->id_b - (int64_t)op->id_a));
    put_u(w, op->n_bridge);
    if (op->n_bridge > 0u) {
        int32_t tx = qx;
        int32_t ty = qy;
        n = span_points(m, op->bridge, 0, op->n_bridge, room_of(w) + REC_HEAD_MAX, NULL, &tx, &ty);
        if (n < op->n_bridge || w->full) {
            w->p = save;
            w->full = 0;
            w->rec_start = NULL;
            *prev_id = save_id;
            return 0;
        }
        (void)span_points(m, op->bridge, 0, op->n_bridge, 0u, w, &qx, &qy);
    }
    if (w->full) {
        w->p = save;
        w->full = 0;
        w->rec_start = NULL;
        *prev_id = save_id;
        return 0;
    }
    m->features[sa].flags &= (uint8_t)~BSF_MAP_FF_OP;
    return 1;
}

/* An append record with the ripe unsent points at one end of f, outward
 * from the sent point next to them; 0 when the frame is full. */
static int put_append(bsf_map_t *m, wr_t *w, int64_t *prev_id, bsf_map_feature_t *f, int at_head)
{
    const int dir = at_head ? 1 : 0; /* span_points: 1 follows prev */
    const uint32_t unsent = unsent_run(m, at_head ? f->head : f->tail, at_head ? 0 : 1);
    uint16_t edge = at_head ? f->head : f->tail;
    uint16_t first;
    uint32_t k;
    uint32_t run;
    uint32_t n;
    int32_t qx;
    int32_t qy;
    if (unsent == 0u || unsent >= f->n_ctrl) {
        return 1;
    }
    for (k = 0; k < unsent; ++k) {
        edge = at_head ? m->ctrl[edge].next : m->ctrl[edge].prev;
    }
    first = at_head ? m->ctrl[edge].prev : m->ctrl[edge].next;
    run = ripe_run(m, f, first, dir);
    if (run == 0u) {
        return 1;
    }
    run = bsf_map_simplify(m, f, edge, dir, run);
    first = at_head ? m->ctrl[edge].prev : m->ctrl[edge].next;
    qx = m->ctrl[edge].qx;
    qy = m->ctrl[edge].qy;
    n = span_points(m, first, dir, run, room_of(w), NULL, &qx, &qy);
    if (n == 0u) {
        return 0;
    }
    qx = m->ctrl[edge].qx;
    qy = m->ctrl[edge].qy;
    put_tag(w, BSF_MAP_REC_APPEND, f->upd, (unsigned)at_head);
    put_id(w, prev_id, f->id);
    put_u(w, n);
    (void)span_points(m, first, dir, n, 0u, w, &qx, &qy);
    f->upd = (uint8_t)((f->upd + 1u) & 15u);
    ++m->stats.n_records;
    return n == run;
}

/* New-feature, append and move records of one feature; 0 when the frame is full. */
static int put_feature(bsf_map_t *m, wr_t *w, int64_t *prev_id, bsf_map_feature_t *f)
{
    const float step = m->params.quant_step;
    const float tol2 = m->params.send_tol * m->params.send_tol;
    const float inv = 1.0f / step;
    uint16_t i;
    if (!(f->flags & BSF_MAP_FF_SENT)) {
        int32_t qx = 0;
        int32_t qy = 0;
        uint32_t n;
        if (ripe_run(m, f, f->head, 0) < f->n_ctrl) {
            return 1; /* held back */
        }
        (void)bsf_map_simplify(m, f, f->head, 0, (uint32_t)f->n_ctrl - 1u);
        n = span_points(m, f->head, 0, BSF_MAP_REC_MAX_POINTS, room_of(w), NULL, &qx, &qy);
        if (n < 2u) {
            return 0;
        }
        qx = 0;
        qy = 0;
        /* ids are given in the order features first go out, so that every id
         * below the largest a receiver saw is one the robot sent */
        f->id = m->next_id++;
        put_tag(w, BSF_MAP_REC_NEW, 0u, 0u);
        put_id(w, prev_id, f->id);
        put_u(w, n);
        (void)span_points(m, f->head, 0, n, 0u, w, &qx, &qy);
        f->flags |= BSF_MAP_FF_SENT;
        f->upd = 1u;
        ++m->stats.n_records;
        if (n < f->n_ctrl) {
            return 0;
        }
        return 1;
    }
    /* unsent points at either end, sent outward from the sent part */
    if (!put_append(m, w, prev_id, f, 1) || !put_append(m, w, prev_id, f, 0)) {
        return 0;
    }
    /* moved points: two passes, counting what fits, then writing it */
    {
        size_t room = room_of(w);
        uint32_t n = 0;
        uint32_t idx = 0;
        int32_t last_idx = -1;
        int full = 0;
        for (i = f->head; i != BSF_MAP_NONE; i = m->ctrl[i].next) {
            const bsf_map_ctrl_t *c = &m->ctrl[i];
            if (!(c->flags & BSF_MAP_CF_SENT)) {
                continue;
            }
            if (bsf_map_ctrl_moved(c, step, tol2)) {
                const int32_t dx = quant_clamped(c->x, inv) - c->qx;
                const int32_t dy = quant_clamped(c->y, inv) - c->qy;
                const unsigned l = ulen(2u * (uint32_t)((int32_t)idx - last_idx - 1) + 1u) +
                                   ulen(zz(dx)) + ulen(zz(dy));
                if (l > room) {
                    full = 1;
                    break;
                }
                room -= l;
                last_idx = (int32_t)idx;
                ++n;
            }
            ++idx;
        }
        if (n > 0u) {
            uint32_t written = 0;
            put_tag(w, BSF_MAP_REC_MOVE, f->upd, 0u);
            put_id(w, prev_id, f->id);
            put_u(w, n);
            idx = 0;
            last_idx = -1;
            for (i = f->head; i != BSF_MAP_NONE && written < n; i = m->ctrl[i].next) {
                bsf_map_ctrl_t *c = &m->ctrl[i];
                if (!(c->flags & BSF_MAP_CF_SENT)) {
                    continue;
                }
                if (bsf_map_ctrl_moved(c, step, tol2)) {
                    const int32_t x = quant_clamped(c->x, inv);
                    const int32_t y = quant_clamped(c->y, inv);
                    const unsigned v = (c->flags & BSF_MAP_CF_VERTEX) ? 1u : 0u;
                    const unsigned toggle = v != ((c->flags & BSF_MAP_CF_SENT_VTX) ? 1u : 0u);
                    put_u(w, 2u * (uint32_t)((int32_t)idx - last_idx - 1) + toggle);
                    put_u(w, zz(x - c->qx));
                    put_u(w, zz(y - c->qy));
                    c->qx = x;
                    c->qy = y;
                    c->flags = (uint8_t)((c->flags & ~BSF_MAP_CF_SENT_VTX) |
                                         (v ? BSF_MAP_CF_SENT_VTX : 0u));
                    last_idx = (int32_t)idx;
                    ++written;
                }
                ++idx;
            }
            f->upd = (uint8_t)((f->upd + 1u) & 15u);
            ++m->stats.n_records;
            m->stats.n_moved_ctrl += n;
        }
        if (full) {
            return 0;
        }
    }
    return 1;
}

/* The id-limit record at the start of a snapshot round, within *budget:
 * with it a receiver that lost frames (or joined late) learns which ids
 * exist without waiting for the next new feature. 1 when it fit. */
static int put_id_limit(const bsf_map_t *m, wr_t *w, size_t *budget)
{
    const size_t len = 1u + ulen(m->next_id);
    if (len > *budget || len > (size_t)(w->end - w->p)) {
        return 0;
    }
    tally_close(w);
    w->rec_start = w->p;
    w->rec_op = BSF_MAP_REC_SNAPSHOT; /* counted with the snapshots it completes */
    put_byte(w, (uint8_t)BSF_MAP_REC_ID_LIMIT);
    put_u(w, m->next_id);
    *budget -= len;
    return 1;
}

/* Snapshot records: the sent values of fully sent features, in id order
 * from snapshot_next, within the byte budget; a feature larger than what is
 * left goes in parts over several frames (restarted when its head changes
 * in between: moves and appends at the tail do not disturb the parts). */
static void put_snapshots(bsf_map_t *m, wr_t *w, int64_t *prev_id)
{
    size_t budget = m->params.snapshot_budget;
    int limit_sent = 0;
    uint16_t tries;
    for (tries = 0; tries <= m->n_features; ++tries) {
        uint16_t slot = BSF_MAP_NONE;
        bsf_map_feature_t *f;
        uint16_t i;
        uint32_t pos;
        uint32_t k;
        uint32_t n;
        size_t room;
        size_t head;
        size_t used = 0;
        int32_t qx = 0;
        int32_t qy = 0;
        uint8_t *save;
        if (m->snapshot_pos > 0u) {
            slot = bsf_map_slot_of_id(m, m->snapshot_next);
            if (slot == BSF_MAP_NONE || m->features[slot].head != m->snapshot_head ||
                m->features[slot].n_ctrl <= m->snapshot_pos) {
                slot = BSF_MAP_NONE;
                m->snapshot_pos = 0u;
            }
        }
        if (slot == BSF_MAP_NONE) {
            uint16_t lowest = BSF_MAP_NONE;
            uint16_t s;
            for (s = 0; s < m->n_features; ++s) {
                const uint32_t id = m->features[s].id;
                if (!(m->features[s].flags & BSF_MAP_FF_SENT)) {
                    continue; /* no id yet */
                }
                if (id >= m->snapshot_next && (slot == BSF_MAP_NONE || id < m->features[slot].id)) {
                    slot = s;
                }
                if (lowest == BSF_MAP_NONE || id < m->features[lowest].id) {
                    lowest = s;
                }
            }
            if (slot == BSF_MAP_NONE) {
                slot = lowest;
            }
            if (slot == BSF_MAP_NONE) {
                return;
            }
            m->snapshot_next = m->features[slot].id;
            m->snapshot_pos = 0u;
            if (slot == lowest && !limit_sent) {
                /* a round starts: which ids exist, then the features */
                limit_sent = 1;
                (void)put_id_limit(m, w, &budget);
            }
        }
        f = &m->features[slot];
        if (!bsf_map_chain_clean(m, f)) {
            m->snapshot_next = f->id + 1u;
            m->snapshot_pos = 0u;
            continue;
        }
        pos = m->snapshot_pos;
        n = f->n_ctrl;
        head = 1u + ulen((uint32_t)bsf_wire_zigzag((int64_t)f->id - *prev_id)) + ulen(pos) +
               ulen(n - pos);
        room = (size_t)(w->end - w->p);
        room = room < budget ? room : budget;
        if (room <= head) {
            return;
        }
        room -= head;
        /* how many points from pos fit */
        for (i = f->head, k = 0; i != BSF_MAP_NONE && k < pos; i = m->ctrl[i].next) {
            ++k;
        }
        for (k = 0; i != BSF_MAP_NONE; i = m->ctrl[i].next) {
            const bsf_map_ctrl_t *c = &m->ctrl[i];
            const unsigned l =
                point_len(c->qx - qx, c->qy - qy, (c->flags & BSF_MAP_CF_SENT_VTX) ? 1u : 0u);
            if (used + l > room) {
                break;
            }
            used += l;
            qx = c->qx;
            qy = c->qy;
            ++k;
        }
        if (k == 0u) {
            return;
        }
        save = w->p;
        put_tag(w, BSF_MAP_REC_SNAPSHOT, f->upd, pos + k == n);
        put_id(w, prev_id, f->id);
        put_u(w, pos);
        put_u(w, k);
        for (i = f->head, n = 0; n < pos; i = m->ctrl[i].next) {
            ++n;
        }
        qx = 0;
        qy = 0;
        for (n = 0; n < k; ++n, i = m->ctrl[i].next) {
            const bsf_map_ctrl_t *c = &m->ctrl[i];
            put_point(w, c->qx - qx, c->qy - qy, (c->flags & BSF_MAP_CF_SENT_VTX) ? 1u : 0u);
            qx = c->qx;
            qy = c->qy;
        }
        budget -= (size_t)(w->p - save);
        ++m->stats.n_snapshots;
        if (pos + k == f->n_ctrl) {
            m->snapshot_next = f->id + 1u;
            m->snapshot_pos = 0u;
        } else {
            m->snapshot_pos = (uint16_t)(pos + k);
            m->snapshot_head = f->head;
            return;
        }
    }
}

static int pose_ok(const bsf_pose_t *p)
{
    return p->x == p->x && p->y == p->y && p->theta == p->theta && fabsf(p->x) <= BSF_POSE_XY_MAX &&
           fabsf(p->y) <= BSF_POSE_XY_MAX && fabsf(p->theta) <= BSF_POSE_THETA_MAX;
}

bsf_status_t bsf_map_encode(bsf_map_t *map, const bsf_pose_t *pose, uint8_t *buf, size_t cap,
                            size_t *out_len)
{
    size_t offset;
    size_t limit;
    size_t payload_len;
    size_t header_len;
    size_t pose_len = 0;
    size_t map_records_end;
    wr_t w;
    int64_t prev_id = 0;
    int full = 0;
    uint16_t s;
    uint32_t crc;
    size_t code_len;

    if (map == NULL || buf == NULL || out_len == NULL || (pose != NULL && !pose_ok(pose))) {
        return BSF_ERR_ARG;
    }
    *out_len = 0u;
    if (cap < BSF_MAP_FRAME_MIN_SIZE) {
        return BSF_ERR_BUFFER;
    }
    /* no frame longer than a decoder of the same caps can hold */
    if (cap > BSF_MAP_FRAME_MAX_SIZE) {
        cap = BSF_MAP_FRAME_MAX_SIZE;
    }
    if (cap > BSF_FRAME_MAX_SIZE) {
        cap = BSF_FRAME_MAX_SIZE;
    }
    /* payload written after room for the COBS overhead, encoded in place */
    offset = 2u + cap / 254u;
    limit = cap - offset - BSF_FRAME_CRC_SIZE - 1u;
    memset(&w, 0, sizeof w);
    w.p = buf + offset;
    w.end = w.p + limit;
    put_byte(&w, MAP_BYTE0);
    put_u(&w, map->frame_seq);
    put_u(&w, (uint32_t)map->step_code);
    header_len = (size_t)(w.p - (buf + offset));

    if (map->stats.n_fused - map->last_frame_call < map->params.frame_interval) {
        full = 1; /* not yet: map changes wait to share a frame */
    }
    while (map->n_ops > 0u && !full) {
        if (!put_merge(map, &w, &prev_id, &map->ops[0])) {
            full = 1;
            break;
        }
        ++map->stats.n_records;
        --map->n_ops;
        memmove(&map->ops[0], &map->ops[1], map->n_ops * sizeof map->ops[0]);
    }
    for (s = 0; s < map->n_features && !full; ++s) {
        if (!put_feature(map, &w, &prev_id, &map->features[s])) {
            full = 1;
        }
    }
    map_records_end = (size_t)(w.p - (buf + offset));
    if (map->stats.n_fused - map->last_frame_call >= map->params.frame_interval) {
        /* a frame cut by cap lets the rest follow in the next call */
        map->last_frame_call =
            full ? map->stats.n_fused - map->params.frame_interval : map->stats.n_fused;
    }
    if (map->params.snapshot_budget > 0u && !full) {
        put_snapshots(map, &w, &prev_id);
    }
    if (pose != NULL) {
        uint8_t *const save = w.p;
        const float code = floorf(pose->theta * BSF_WIRE_THETA_PER_RAD + 0.5f);
        const int32_t th = (int32_t)fmodf(code, 65536.0f);
        put_tag(&w, BSF_MAP_REC_POSE, 0u, 0u);
        put_u(&w, zz((int32_t)floorf(pose->x * 1000.0f + 0.5f)));
        put_u(&w, zz((int32_t)floorf(pose->y * 1000.0f + 0.5f)));
        put_u(&w, (uint32_t)(th < 0 ? th + 65536 : th));
        if (w.full) {
            w.p = save;
            w.full = 0;
            w.rec_start = NULL;
        } else {
            pose_len = (size_t)(w.p - save);
        }
    }
    tally_close(&w);
    payload_len = (size_t)(w.p - (buf + offset));
    if (payload_len == header_len) {
        return BSF_OK; /* nothing to send */
    }
    crc = bsf_crc32c(0u, buf + offset, payload_len);
    buf[offset + payload_len] = (uint8_t)crc;
    buf[offset + payload_len + 1u] = (uint8_t)(crc >> 8);
    buf[offset + payload_len + 2u] = (uint8_t)(crc >> 16);
    buf[offset + payload_len + 3u] = (uint8_t)(crc >> 24);
    code_len = bsf_cobs_encode_in_place(buf, offset, payload_len + BSF_FRAME_CRC_SIZE);
    buf[code_len] = 0u;
    *out_len = code_len + 1u;
    ++map->frame_seq;
    ++map->stats.n_frames;
    for (s = 0; s < BSF_MAP_REC_OPS; ++s) {
        map->stats.record_bytes[s] += w.bytes[s];
    }
    if (map_records_end == header_len && payload_len == header_len + pose_len) {
        map->stats.pose_bytes += (uint32_t)*out_len;
    } else {
        map->stats.pose_bytes += (uint32_t)pose_len;
        map->stats.map_bytes += (uint32_t)(*out_len - pose_len);
    }
    return BSF_OK;
}

/* ---- Receiver ------------------------------------------------------------------ */

#define RX_ABSENT 0u
#define RX_PRESENT 1u
#define RX_STALE 2u
#define RX_GONE 3u
#define RX_SNAP 4u /* a snapshot in parts is arriving */

/* A frame advances one feature's update count by at most RX_ADVANCE_MAX
 * (a merge, an append at each end, a move): after fewer than
 * RX_CONFIRM_LOST lost frames a count that matches cannot have wrapped, so
 * no record of the feature was lost. A gap adds at most RX_GAP_MAX to
 * rx->lost, enough to say "too many to tell". */
#define RX_ADVANCE_MAX 4u
#define RX_CONFIRM_LOST (16u / RX_ADVANCE_MAX)
#define RX_GAP_MAX 16u

void bsf_map_rx_init(bsf_map_rx_t *rx)
{
    size_t i;
    memset(rx, 0, sizeof *rx);
    for (i = 0; i < BSF_MAP_RX_MAX_FEATURES; ++i) {
        rx->features[i].head = BSF_MAP_NONE;
        rx->features[i].tail = BSF_MAP_NONE;
    }
    for (i = 0; i < BSF_MAP_RX_MAX_CTRL; ++i) {
        rx->ctrl[i].next = (uint16_t)(i + 1u < BSF_MAP_RX_MAX_CTRL ? i + 1u : BSF_MAP_NONE);
        rx->ctrl[i].prev = BSF_MAP_NONE;
    }
    rx->free_ctrl = 0u;
    rx->n_free_ctrl = BSF_MAP_RX_MAX_CTRL;
    rx->ids_known = 1u;
}

/* Map frames lost since f was last confirmed (or its snapshot started). */
static uint32_t rx_lost_since(const bsf_map_rx_t *rx, const bsf_map_rx_feature_t *f)
{
    return rx->lost - f->lost_at;
}

/* A record of f applied with the count it expected: when too few frames
 * were lost for the count to have wrapped, f missed nothing. */
static void rx_confirm_by_count(bsf_map_rx_t *rx, bsf_map_rx_feature_t *f)
{
    if (rx_lost_since(rx, f) < RX_CONFIRM_LOST) {
        f->lost_at = rx->lost;
    }
}

static void rx_free_chain(bsf_map_rx_t *rx, bsf_map_rx_feature_t *f)
{
    uint16_t i = f->head;
    while (i != BSF_MAP_NONE) {
        const uint16_t next = rx->ctrl[i].next;
        rx->ctrl[i].next = rx->free_ctrl;
        rx->ctrl[i].prev = BSF_MAP_NONE;
        rx->free_ctrl = i;
        ++rx->n_free_ctrl;
        i = next;
    }
    f->head = BSF_MAP_NONE;
    f->tail = BSF_MAP_NONE;
    f->n_ctrl = 0u;
}

static void rx_reverse(bsf_map_rx_t *rx, bsf_map_rx_feature_t *f)
{
    uint16_t i = f->head;
    uint16_t t;
    while (i != BSF_MAP_NONE) {
        t = rx->ctrl[i].next;
        rx->ctrl[i].next = rx->ctrl[i].prev;
        rx->ctrl[i].prev = t;
        i = t;
    }
    t = f->head;
    f->head = f->tail;
    f->tail = t;
}

/* Link the record's n points (checked syntax) at the tail (at_head 0) or
 * head of f, delta-coded from (qx, qy). 0 when a value leaves the range or
 * the pool is short (nothing is linked then). */
static int rx_link(bsf_map_rx_t *rx, bsf_map_rx_feature_t *f, const uint8_t *pts,
                   const uint8_t *end, uint32_t n, int at_head, int64_t qx, int64_t qy)
{
    rd_t r;
    uint32_t i;
    int64_t x = qx;
    int64_t y = qy;
    if (n > rx->n_free_ctrl || (uint32_t)f->n_ctrl + n > BSF_MAP_REC_MAX_POINTS) {
        return 0;
    }
    r.p = pts;
    r.end = end;
    for (i = 0; i < n; ++i) {
        int64_t dx = 0;
        int64_t dy = 0;
        uint8_t v = 0u;
        (void)get_point(&r, &dx, &dy, &v);
        x += dx;
        y += dy;
        if (!q_ok(x) || !q_ok(y)) {
            return 0;
        }
    }
    r.p = pts;
    x = qx;
    y = qy;
    for (i = 0; i < n; ++i) {
        int64_t dx = 0;
        int64_t dy = 0;
        uint8_t v = 0u;
        uint16_t c;
        (void)get_point(&r, &dx, &dy, &v);
        x += dx;
        y += dy;
        c = rx->free_ctrl;
        rx->free_ctrl = rx->ctrl[c].next;
        --rx->n_free_ctrl;
        rx->ctrl[c].qx = (int32_t)x;
        rx->ctrl[c].qy = (int32_t)y;
        rx->ctrl[c].vertex = v;
        rx->ctrl[c].next = BSF_MAP_NONE;
        rx->ctrl[c].prev = BSF_MAP_NONE;
        if (f->head == BSF_MAP_NONE) {
            f->head = c;
            f->tail = c;
        } else if (at_head) {
            rx->ctrl[c].next = f->head;
            rx->ctrl[f->head].prev = c;
            f->head = c;
        } else {
            rx->ctrl[c].prev = f->tail;
            rx->ctrl[f->tail].next = c;
            f->tail = c;
        }
        ++f->n_ctrl;
    }
    return 1;
}

/* A record that cannot apply: the receiver no longer holds what the robot
 * believes. A feature never received (its first frame lost, or a receiver
 * that joined late) is flagged too, so that a missing feature is reported
 * like a wrong one, until a snapshot brings it. */
static void rx_stale(bsf_map_rx_feature_t *f)
{
    if (f->state == RX_PRESENT || f->state == RX_ABSENT) {
        f->state = RX_STALE;
    }
}

/* Apply one checked record; 0 when it had to be skipped. */
static int rx_record(bsf_map_rx_t *rx, const rec_t *rec, const uint8_t *end)
{
    bsf_map_rx_feature_t *f;
    if (rec->op == BSF_MAP_REC_POSE) {
        rx->pose.x = (float)rec->pose[0] * 0.001f;
        rx->pose.y = (float)rec->pose[1] * 0.001f;
        rx->pose.theta = (float)(rec->pose[2] >= 32768 ? rec->pose[2] - 65536 : rec->pose[2]) *
                         BSF_WIRE_RAD_PER_THETA;
        rx->has_pose = 1u;
        ++rx->stats.poses;
        return 1;
    }
    if (rec->op == BSF_MAP_REC_ID_LIMIT) {
        /* every id the robot has given is below it: those this receiver
         * never got are missing, none above it exists */
        if (rec->id > BSF_MAP_RX_MAX_FEATURES) {
            rx->over_cap = 1u;
        }
        if (rec->id > rx->id_limit) {
            rx->id_limit = rec->id < BSF_MAP_RX_MAX_FEATURES ? rec->id : BSF_MAP_RX_MAX_FEATURES;
        }
        rx->ids_known = 1u;
        return 1;
    }
    if (rec->op == BSF_MAP_REC_NEW) {
        /* ids go out in order: every id the lost frames gave is below this */
        rx->ids_known = 1u;
    }
    if (rec->id >= BSF_MAP_RX_MAX_FEATURES ||
        (rec->op == BSF_MAP_REC_MERGE && rec->id_b >= BSF_MAP_RX_MAX_FEATURES)) {
        if (rec->id_b < BSF_MAP_RX_MAX_FEATURES && rec->op == BSF_MAP_REC_MERGE) {
            rx_stale(&rx->features[rec->id_b]);
        }
        rx->over_cap = 1u;
        return 0;
    }
    if (rec->id >= rx->id_limit) {
        rx->id_limit = rec->id + 1u;
    }
    if (rec->op == BSF_MAP_REC_MERGE && rec->id_b >= rx->id_limit) {
        rx->id_limit = rec->id_b + 1u;
    }
    f = &rx->features[rec->id];
    switch (rec->op) {
    case BSF_MAP_REC_NEW:
        rx_free_chain(rx, f);
        if (!rx_link(rx, f, rec->pts, end, rec->n, 0, 0, 0)) {
            rx_free_chain(rx, f);
            f->state = RX_STALE;
            return 0;
        }
        f->state = RX_PRESENT;
        f->upd = 1u;
        f->lost_at = rx->lost;
        return 1;
    case BSF_MAP_REC_SNAPSHOT:
        if (f->state == RX_PRESENT && f->upd == rec->upd &&
            rx_lost_since(rx, f) < RX_CONFIRM_LOST) {
            /* the count shows no record of it was lost: the receiver holds
             * what the snapshot carries, and keeps it whole */
            f->lost_at = rx->lost;
            ++rx->stats.snapshots;
            return 1;
        }
        /* a first part restarts the feature; a later part continues it only
         * when every part before it arrived */
        if (rec->start == 0u) {
            rx_free_chain(rx, f);
            f->lost_at = rx->lost;
        } else if (f->state != RX_SNAP || f->n_ctrl != rec->start || f->upd != rec->upd) {
            if (f->state == RX_ABSENT) {
                f->state = RX_STALE; /* a part of a feature never received */
            }
            return 0;
        }
        if (!rx_link(rx, f, rec->pts, end, rec->n, 0, 0, 0)) {
            rx_free_chain(rx, f);
            f->state = RX_STALE;
            return 0;
        }
        f->state = rec->high ? RX_PRESENT : RX_SNAP;
        f->upd = (uint8_t)rec->upd;
        if (rec->high) {
            /* the parts agree with each other when their counts matched
             * over few enough lost frames */
            rx_confirm_by_count(rx, f);
        }
        ++rx->stats.snapshots;
        return 1;
    case BSF_MAP_REC_APPEND: {
        const uint16_t e = rec->high ? f->head : f->tail;
        if (f->state == RX_SNAP && f->upd == rec->upd) {
            /* the snapshot's later parts carry these points (the robot
             * restarts it when its head grows) */
            f->upd = (uint8_t)((f->upd + 1u) & 15u);
            return 1;
        }
        if (f->state != RX_PRESENT || f->upd != rec->upd || e == BSF_MAP_NONE ||
            !rx_link(rx, f, rec->pts, end, rec->n, (int)rec->high, rx->ctrl[e].qx,
                     rx->ctrl[e].qy)) {
            rx_stale(f);
            return 0;
        }
        f->upd = (uint8_t)((f->upd + 1u) & 15u);
        rx_confirm_by_count(rx, f);
        return 1;
    }
    case BSF_MAP_REC_MOVE: {
        rd_t r;
        uint32_t i;
        int64_t idx = -1;
        uint16_t c;
        int64_t at = 0;
        if ((f->state != RX_PRESENT && f->state != RX_SNAP) || f->upd != rec->upd) {
            rx_stale(f);
            return 0;
        }
        /* every index inside the feature and every value in range first; a
         * snapshot still arriving takes the moves of the points it has */
        r.p = rec->pts;
        r.end = end;
        c = f->head;
        for (i = 0; i < rec->n; ++i) {
            uint32_t gap = 0u;
            int64_t dx = 0;
            int64_t dy = 0;
            (void)get_u(&r, 2u * BSF_MAP_REC_MAX_POINTS + 1u, &gap);
            (void)get_s(&r, DELTA_MAX, &dx);
            (void)get_s(&r, DELTA_MAX, &dy);
            idx += (int64_t)(gap >> 1) + 1;
            while (c != BSF_MAP_NONE && at < idx) {
                c = rx->ctrl[c].next;
                ++at;
            }
            if (c == BSF_MAP_NONE && f->state == RX_SNAP) {
                break;
            }
            if (c == BSF_MAP_NONE || !q_ok(rx->ctrl[c].qx + dx) || !q_ok(rx->ctrl[c].qy + dy)) {
                rx_stale(f);
                return 0;
            }
        }
        r.p = rec->pts;
        c = f->head;
        idx = -1;
        at = 0;
        for (i = 0; i < rec->n; ++i) {
            uint32_t gap = 0u;
            int64_t dx = 0;
            int64_t dy = 0;
            (void)get_u(&r, 2u * BSF_MAP_REC_MAX_POINTS + 1u, &gap);
            (void)get_s(&r, DELTA_MAX, &dx);
            (void)get_s(&r, DELTA_MAX, &dy);
            idx += (int64_t)(gap >> 1) + 1;
            while (c != BSF_MAP_NONE && at < idx) {
                c = rx->ctrl[c].next;
                ++at;
            }
            if (c == BSF_MAP_NONE) {
                break;
            }
            rx->ctrl[c].qx = (int32_t)(rx->ctrl[c].qx + dx);
            rx->ctrl[c].qy = (int32_t)(rx->ctrl[c].qy + dy);
            rx->ctrl[c].vertex ^= (uint8_t)(gap & 1u);
        }
        f->upd = (uint8_t)((f->upd + 1u) & 15u);
        if (f->state == RX_PRESENT) {
            rx_confirm_by_count(rx, f);
        }
        return 1;
    }
    case BSF_MAP_REC_MERGE: {
        bsf_map_rx_feature_t *b = &rx->features[rec->id_b];
        int ok = f->state == RX_PRESENT && b->state == RX_PRESENT && f->upd == rec->upd &&
                 b->upd == rec->upd_b && f->head != BSF_MAP_NONE && b->head != BSF_MAP_NONE &&
                 (uint32_t)f->n_ctrl + rec->n + b->n_ctrl <= BSF_MAP_REC_MAX_POINTS;
        if (ok) {
            if (rec->high) {
                rx_reverse(rx, f);
            }
            ok = rec->n == 0u || rx_link(rx, f, rec->pts, end, rec->n, 0, rx->ctrl[f->tail].qx,
                                         rx->ctrl[f->tail].qy);
            if (!ok && rec->high) {
                rx_reverse(rx, f);
            }
        }
        if (!ok) {
            /* the robot's b is gone either way; a waits for a snapshot */
            rx_stale(f);
            rx_free_chain(rx, b);
            b->state = RX_GONE;
            return 0;
        }
        if (rec->rev_b) {
            rx_reverse(rx, b);
        }
        rx->ctrl[f->tail].next = b->head;
        rx->ctrl[b->head].prev = f->tail;
        f->tail = b->tail;
        f->n_ctrl = (uint16_t)(f->n_ctrl + b->n_ctrl);
        b->head = BSF_MAP_NONE;
        b->tail = BSF_MAP_NONE;
        b->n_ctrl = 0u;
        b->state = RX_GONE;
        f->upd = (uint8_t)((f->upd + 1u) & 15u);
        if (rx_lost_since(rx, b) >= RX_CONFIRM_LOST) {
            /* b's points may be wrong and a's count cannot tell: only a
             * snapshot confirms a now */
            f->lost_at = rx->lost - RX_GAP_MAX;
        } else {
            rx_confirm_by_count(rx, f);
        }
        return 1;
    }
    default: return 0;
    }
}

int bsf_map_rx_apply(bsf_map_rx_t *rx, const uint8_t *payload, size_t len)
{
    rd_t r;
    uint32_t seq = 0u;
    uint32_t step_code = 1u;
    int64_t prev_id = 0;
    int skipped = 0;
    rec_t rec;
    if (rx == NULL || payload == NULL) {
        return BSF_ERR_ARG;
    }
    if (len < 1u || payload[0] != MAP_BYTE0) {
        return BSF_ERR_VERSION;
    }
    if (bsf_map_frame_check(payload, len, &seq) != BSF_OK) {
        return BSF_ERR_FORMAT;
    }
    r.p = payload;
    r.end = payload + len;
    (void)get_header(&r, &seq, &step_code);
    if (rx->seen_frame && rx->quant_step != (float)step_code * BSF_QUANT_STEP_UNIT) {
        return BSF_ERR_FORMAT; /* one step per stream: the held values would change meaning */
    }
    {
        /* a receiver's first frame expects the stream's first, seq 0 */
        const uint32_t gap = seq - (rx->seen_frame ? rx->next_seq : 0u);
        if (gap != 0u) {
            rx->lost += gap < RX_GAP_MAX ? gap : RX_GAP_MAX;
            rx->ids_known = 0u;
            if (rx->seen_frame) {
                rx->stats.frames_missed += gap;
            }
        }
    }
    rx->loss_noted = 0u;
    rx->seen_frame = 1u;
    rx->next_seq = seq + 1u;
    rx->quant_step = (float)step_code * BSF_QUANT_STEP_UNIT;
    while (r.p < r.end) {
        (void)get_record(&r, &prev_id, &rec);
        if (rx_record(rx, &rec, r.end)) {
            ++rx->stats.records;
        } else {
            ++rx->stats.records_skipped;
            ++skipped;
        }
    }
    ++rx->stats.frames;
    return skipped;
}

void bsf_map_rx_note_loss(bsf_map_rx_t *rx)
{
    if (rx != NULL) {
        rx->loss_noted = 1u;
    }
}

int bsf_map_rx_feature_state(const bsf_map_rx_t *rx, uint32_t id)
{
    const bsf_map_rx_feature_t *f;
    if (rx == NULL) {
        return BSF_ERR_ARG;
    }
    if (id >= BSF_MAP_RX_MAX_FEATURES) {
        return rx->over_cap ? BSF_MAP_RX_MISSING : BSF_MAP_RX_NONE;
    }
    f = &rx->features[id];
    switch (f->state) {
    case RX_PRESENT:
        return rx->loss_noted || f->lost_at != rx->lost ? BSF_MAP_RX_UNCONFIRMED
                                                        : BSF_MAP_RX_CONFIRMED;
    case RX_STALE:
    case RX_SNAP: return f->head != BSF_MAP_NONE ? BSF_MAP_RX_STALE : BSF_MAP_RX_MISSING;
    case RX_ABSENT:
        /* every id below the largest seen was sent; above it, after a loss,
         * any id may have been */
        return id < rx->id_limit || !rx->ids_known || rx->loss_noted ? BSF_MAP_RX_MISSING
                                                                     : BSF_MAP_RX_NONE;
    default: return BSF_MAP_RX_NONE;
    }
}

uint32_t bsf_map_rx_id_limit(const bsf_map_rx_t *rx)
{
    return rx != NULL ? rx->id_limit : 0u;
}

int bsf_map_rx_feature_ctrl(const bsf_map_rx_t *rx, uint32_t id, bsf_point_t *ctrl,
                            uint8_t *is_vertex, size_t cap, uint8_t *stale)
{
    const bsf_map_rx_feature_t *f;
    uint16_t i;
    size_t n = 0;
    if (rx == NULL) {
        return BSF_ERR_ARG;
    }
    if (stale != NULL) {
        *stale = bsf_map_rx_feature_state(rx, id) >= BSF_MAP_RX_UNCONFIRMED ? 1u : 0u;
    }
    if (id >= BSF_MAP_RX_MAX_FEATURES) {
        return 0;
    }
    f = &rx->features[id];
    for (i = f->head; i != BSF_MAP_NONE; i = rx->ctrl[i].next) {
        const bsf_map_rx_ctrl_t *c = &rx->ctrl[i];
        const unsigned reps = c->vertex ? 2u : 1u;
        unsigned k;
        for (k = 0; k < reps; ++k, ++n) {
            if (n < cap) {
                if (ctrl != NULL) {
                    ctrl[n].x = (float)c->qx * rx->quant_step;
                    ctrl[n].y = (float)c->qy * rx->quant_step;
                }
                if (is_vertex != NULL) {
                    is_vertex[n] = c->vertex;
                }
            }
        }
    }
    return (int)n;
}

int bsf_map_rx_feature_q(const bsf_map_rx_t *rx, uint32_t id, int32_t *q, uint8_t *is_vertex,
                         size_t cap)
{
    uint16_t i;
    size_t n = 0;
    if (rx == NULL) {
        return BSF_ERR_ARG;
    }
    if (id >= BSF_MAP_RX_MAX_FEATURES) {
        return 0;
    }
    for (i = rx->features[id].head; i != BSF_MAP_NONE; i = rx->ctrl[i].next, ++n) {
        if (n < cap) {
            if (q != NULL) {
                q[2u * n] = rx->ctrl[i].qx;
                q[2u * n + 1u] = rx->ctrl[i].qy;
            }
            if (is_vertex != NULL) {
                is_vertex[n] = rx->ctrl[i].vertex;
            }
        }
    }
    return (int)n;
}

/* The stream decoder's entry (bsf_frame_parsers.h): the reader starts after
 * the version and type byte, which the map's checks read with the rest. */
bsf_status_t bsf_map_parse(reader_t *r, unsigned version, bsf_frame_t *out)
{
    (void)version;
    return bsf_map_frame_parse(r->p - 1, r->len + 1u, out);
}
