/* SPDX-License-Identifier: MIT */
/*
 * bsf_features_decode.c - the features frame's parser (docs/FORMAT.md,
 * "Features frame"): header, extension, then per feature its fields and
 * control points, each a small step below; called by bsf_stream_decode.c
 * for frames of type BSF_FRAME_TYPE_FEATURES. The bit reader is
 * bsf_stream_reader.h's.
 */
#include <string.h>

#include "bsf_frame_parsers.h"

static int in_quant_range(int64_t q)
{
    return q >= -BSF_QUANT_MAX_STEPS && q <= BSF_QUANT_MAX_STEPS;
}

/* A point relative to ref, checked to stay in the quantisation range. */
static int get_point(reader_t *r, unsigned k, const int64_t ref[2], int64_t q[2])
{
    int64_t d;
    unsigned c;
    for (c = 0; c < 2u; ++c) {
        if (!get_signed(r, k, 2 * BSF_QUANT_MAX_STEPS, &d)) {
            return 0;
        }
        q[c] = ref[c] + d;
        if (!in_quant_range(q[c])) {
            return 0;
        }
    }
    return 1;
}

static void store_point(bsf_result_t *res, size_t slot, const int64_t q[2], float step,
                        unsigned copies)
{
    unsigned c;
    if (res == NULL) {
        return;
    }
    for (c = 0; c < copies; ++c) {
        res->ctrl[slot + c].x = (float)q[0] * step;
        res->ctrl[slot + c].y = (float)q[1] * step;
        res->ctrl_is_vertex[slot + c] = copies == 2u ? 1u : 0u;
    }
}

static unsigned popcount64(uint64_t v)
{
    unsigned n = 0;
    while (v != 0u) {
        v &= v - 1u;
        ++n;
    }
    return n;
}

/* Control points of one feature (see feature_values in the encoder). */
static bsf_status_t get_ctrl(reader_t *r, const uint32_t k_ctrl[BSF_WIRE_N_CLASSES], uint32_t m,
                             uint64_t mask, float step, size_t base, bsf_result_t *res,
                             int64_t prev[2])
{
    uint32_t i_a = 0;
    size_t s_a = base;
    unsigned c_a = (mask & 1u) != 0u ? 2u : 1u;
    int64_t q_a[2];

    if (!get_point(r, k_ctrl[BSF_WIRE_CLASS_FIRST], prev, q_a)) {
        return BSF_ERR_FORMAT;
    }
    store_point(res, s_a, q_a, step, c_a);
    while (i_a < m - 1u) {
        uint32_t i_b = i_a + 1u;
        uint32_t k;
        uint32_t s;
        unsigned c_b;
        size_t s_b;
        int64_t q_b[2];
        while (i_b < m - 1u && ((mask >> i_b) & 1u) == 0u) {
            ++i_b;
        }
        k = i_b - i_a - 1u;
        c_b = ((mask >> i_b) & 1u) != 0u ? 2u : 1u;
        s_b = s_a + c_a + k;
        if (!get_point(r, k_ctrl[BSF_WIRE_CLASS_ANCHOR], q_a, q_b)) {
            return BSF_ERR_FORMAT;
        }
        store_point(res, s_b, q_b, step, c_b);
        for (s = 1u; s <= k; ++s) {
            int64_t pred[2];
            int64_t q[2];
            pred[0] = bsf_wire_predict(q_a[0], q_b[0], s, k);
            pred[1] = bsf_wire_predict(q_a[1], q_b[1], s, k);
            if (!get_point(r, k_ctrl[BSF_WIRE_CLASS_PREC], pred, q)) {
                return BSF_ERR_FORMAT;
            }
            store_point(res, s_a + c_a + s - 1u, q, step, 1u);
        }
        i_a = i_b;
        s_a = s_b;
        c_a = c_b;
        q_a[0] = q_b[0];
        q_a[1] = q_b[1];
    }
    prev[0] = q_a[0];
    prev[1] = q_a[1];
    return BSF_OK;
}

/* Header extension of a version-2 features frame (FORMAT.md section 3.1). */
typedef struct {
    uint32_t has_beams;
    uint32_t has_geometry;
    float angle_min;
    float angle_increment;
    uint32_t n_beams;
    uint32_t cut;
    uint32_t n_cut_keypoints;
    uint32_t n_cut_segments;
    uint32_t n_cut_points;
} header_ext_t;

static bsf_status_t get_ext(reader_t *r, uint32_t n_valid, header_ext_t *ext)
{
    if (!get_bits(r, 1u, &ext->has_beams) || !get_bits(r, 1u, &ext->has_geometry) ||
        !get_bits(r, BSF_WIRE_CUT_BITS, &ext->cut)) {
        return BSF_ERR_FORMAT;
    }
    if ((ext->has_beams == 0u && ext->cut == 0u) ||
        (ext->has_geometry != 0u && ext->has_beams == 0u)) {
        return BSF_ERR_FORMAT; /* an empty extension, a geometry without its beam count */
    }
    if (ext->has_beams != 0u &&
        (!get_u32(r, BSF_WIRE_K_N_BEAMS, (uint32_t)BSF_MAX_POINTS, &ext->n_beams) ||
         ext->n_beams == 0u || ext->n_beams < n_valid)) {
        return BSF_ERR_FORMAT;
    }
    if (ext->has_geometry != 0u &&
        (!get_float(r, &ext->angle_min) || !get_float(r, &ext->angle_increment))) {
        return BSF_ERR_FORMAT;
    }
    if (ext->cut != 0u &&
        (!get_u32(r, BSF_WIRE_K_CUT_KEYPOINTS, (uint32_t)BSF_MAX_POINTS, &ext->n_cut_keypoints) ||
         !get_u32(r, BSF_WIRE_K_CUT_SEGMENTS, (uint32_t)BSF_MAX_POINTS, &ext->n_cut_segments) ||
         !get_u32(r, BSF_WIRE_K_CUT_POINTS, n_valid, &ext->n_cut_points))) {
        return BSF_ERR_FORMAT;
    }
    return BSF_OK;
}

/* The header fields of a features frame, as read. */
typedef struct {
    uint32_t has_pose;
    uint32_t has_ext;
    uint32_t seq;
    uint64_t timestamp;
    int64_t pose[2]; /* millimetres */
    uint32_t theta;  /* 2 pi / 65536 units */
    uint32_t step_code;
    uint32_t n_valid;
    uint32_t time_us;
    uint32_t n_features;
    uint32_t k_ctrl[BSF_WIRE_N_CLASSES];
    header_ext_t ext;
    uint32_t beam_limit; /* beam indices stay below it */
    float step;
} features_head_t;

/* What the features read so far add up to. */
typedef struct {
    size_t n_ctrl;
    uint32_t sum_points;
    int64_t prev_last_beam;
    int64_t prev[2]; /* the last anchor, quantised */
    uint32_t wraps;  /* a feature ran through the seam */
} features_run_t;

/* The header up to the first feature (FORMAT.md section 3.1). Version 1
 * has no extension flag: it is version 2 with the flag 0. */
static bsf_status_t parse_head(reader_t *r, unsigned version, features_head_t *h)
{
    uint32_t i;
    memset(h, 0, sizeof *h);
    if (!get_bits(r, 1u, &h->has_pose) || (version >= 2u && !get_bits(r, 1u, &h->has_ext)) ||
        !get_u32(r, BSF_WIRE_K_SEQ, UINT32_MAX, &h->seq) ||
        !get_eg(r, BSF_WIRE_K_TIMESTAMP, UINT64_MAX, &h->timestamp)) {
        return BSF_ERR_FORMAT;
    }
    if (h->has_pose != 0u && (!get_signed(r, BSF_WIRE_K_POSE, BSF_WIRE_POSE_MM_MAX, &h->pose[0]) ||
                              !get_signed(r, BSF_WIRE_K_POSE, BSF_WIRE_POSE_MM_MAX, &h->pose[1]) ||
                              !get_bits(r, 16u, &h->theta))) {
        return BSF_ERR_FORMAT;
    }
    if (!get_u32(r, BSF_WIRE_K_STEP, BSF_WIRE_STEP_CODE_MAX, &h->step_code) || h->step_code == 0u ||
        !get_u32(r, BSF_WIRE_K_N, (uint32_t)BSF_MAX_POINTS, &h->n_valid) ||
        !get_u32(r, BSF_WIRE_K_TIME_US, BSF_WIRE_TIME_US_MAX, &h->time_us) ||
        !get_u32(r, BSF_WIRE_K_FEATURES, UINT32_MAX >> BSF_WIRE_K_FEATURES, &h->n_features)) {
        return BSF_ERR_FORMAT;
    }
    if (h->n_features > (uint32_t)BSF_MAX_SEGMENTS) {
        return BSF_ERR_CAPACITY;
    }
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        if (!get_bits(r, BSF_WIRE_K_CTRL_BITS, &h->k_ctrl[i]) ||
            h->k_ctrl[i] > BSF_WIRE_K_CTRL_MAX) {
            return BSF_ERR_FORMAT;
        }
    }
    if (h->has_ext != 0u) {
        const bsf_status_t st = get_ext(r, h->n_valid, &h->ext);
        if (st != BSF_OK) {
            return st;
        }
    }
    h->beam_limit = h->ext.has_beams != 0u ? h->ext.n_beams : (uint32_t)BSF_MAX_POINTS;
    h->step = (float)h->step_code * BSF_QUANT_STEP_UNIT;
    return BSF_OK;
}

/* A feature's vertex mask over its m distinct points (FORMAT.md section
 * 3.2) when its flag says one is sent, else 0; a sent mask has a vertex. */
static bsf_status_t parse_mask(reader_t *r, uint32_t m, uint32_t has_mask, uint64_t *mask)
{
    uint32_t j;
    *mask = 0u;
    if (has_mask == 0u) {
        return BSF_OK;
    }
    for (j = 0; j < m; ++j) {
        uint32_t bit;
        if (!get_bits(r, 1u, &bit)) {
            return BSF_ERR_FORMAT;
        }
        *mask |= (uint64_t)bit << j;
    }
    return *mask != 0u ? BSF_OK : BSF_ERR_FORMAT;
}

/* A feature's first and last beam from its gap and span. A run past the
 * last beam wraps through the seam (only when the frame carries the beam
 * count): span < n_beams keeps last < first. */
static bsf_status_t parse_beams(reader_t *r, const features_head_t *h, features_run_t *run,
                                uint32_t *span, int64_t *first, int64_t *last)
{
    int64_t gap;
    if (!get_signed(r, BSF_WIRE_K_GAP, (int64_t)BSF_MAX_POINTS, &gap) ||
        !get_u32(r, BSF_WIRE_K_SPAN, (uint32_t)BSF_MAX_POINTS - 1u, span)) {
        return BSF_ERR_FORMAT;
    }
    *first = run->prev_last_beam + 1 + gap;
    if (*first < 0 || *first >= (int64_t)h->beam_limit || *span >= h->beam_limit) {
        return BSF_ERR_FORMAT;
    }
    *last = *first + (int64_t)*span;
    if (*last >= (int64_t)h->beam_limit) {
        if (h->ext.has_beams == 0u) {
            return BSF_ERR_FORMAT;
        }
        *last -= (int64_t)h->ext.n_beams;
        run->wraps = 1u;
    }
    return BSF_OK;
}

/* Feature i (FORMAT.md section 3.2), into res when given. */
static bsf_status_t parse_feature(reader_t *r, const features_head_t *h, features_run_t *run,
                                  uint32_t i, bsf_result_t *res)
{
    uint32_t kind;
    uint32_t m;
    uint32_t has_mask;
    uint32_t span;
    uint32_t missing;
    uint32_t e_code;
    uint64_t mask;
    uint32_t n_f;
    int64_t first;
    int64_t last;
    bsf_status_t st;

    if (!get_bits(r, 1u, &kind) || !get_u32(r, BSF_WIRE_K_M, 62u, &m) ||
        !get_bits(r, 1u, &has_mask)) {
        return BSF_ERR_FORMAT;
    }
    m += 2u; /* distinct control points */
    if (m > (uint32_t)BSF_MAX_CTRL_PER_FEATURE) {
        return BSF_ERR_CAPACITY;
    }
    st = parse_mask(r, m, has_mask, &mask);
    if (st == BSF_OK) {
        st = parse_beams(r, h, run, &span, &first, &last);
    }
    if (st != BSF_OK) {
        return st;
    }
    if (!get_u32(r, BSF_WIRE_K_MISSING, span + 1u, &missing) ||
        !get_u32(r, BSF_WIRE_K_E_CURVE, BSF_WIRE_E_CURVE_CODE_MAX, &e_code)) {
        return BSF_ERR_FORMAT;
    }
    n_f = m + popcount64(mask);
    if (n_f < 3u) {
        return BSF_ERR_FORMAT;
    }
    if (n_f > (uint32_t)BSF_MAX_CTRL_PER_FEATURE ||
        run->n_ctrl + n_f > (size_t)BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = get_ctrl(r, h->k_ctrl, m, mask, h->step, run->n_ctrl, res, run->prev);
    if (st != BSF_OK) {
        return st;
    }
    if (res != NULL) {
        bsf_feature_t *f = &res->features[i];
        f->first_beam = (uint16_t)first;
        f->last_beam = (uint16_t)last;
        f->n_points = (uint16_t)(span + 1u - missing);
        f->ctrl_first = (uint16_t)run->n_ctrl;
        f->n_ctrl = (uint8_t)n_f;
        f->kind = (uint8_t)kind;
        f->e_curve = (float)e_code / BSF_WIRE_E_CURVE_PER_M;
    }
    run->n_ctrl += n_f;
    run->sum_points += span + 1u - missing;
    run->prev_last_beam = last;
    return BSF_OK;
}

/* The frame's header fields and statistics into out (the features are in
 * out->result already). */
static void store_frame(const features_head_t *h, const features_run_t *run, unsigned version,
                        bsf_frame_t *out)
{
    bsf_result_t *res = &out->result;
    const int32_t theta_signed = h->theta >= 32768u ? (int32_t)h->theta - 65536 : (int32_t)h->theta;
    out->version = (uint8_t)version;
    out->type = (uint8_t)BSF_FRAME_TYPE_FEATURES;
    out->seq = h->seq;
    out->timestamp_ms = h->timestamp;
    out->has_pose = (uint8_t)h->has_pose;
    out->pose.x = (float)h->pose[0] / 1000.0f;
    out->pose.y = (float)h->pose[1] / 1000.0f;
    out->pose.theta = (float)theta_signed * BSF_WIRE_RAD_PER_THETA;
    out->quant_step = h->step;
    out->time_us = h->time_us;
    out->has_geometry = (uint8_t)h->ext.has_geometry;
    out->angle_min = h->ext.angle_min;
    out->angle_increment = h->ext.angle_increment;
    res->n_features = (uint16_t)h->n_features;
    res->n_ctrl = (uint16_t)run->n_ctrl;
    memset(&res->stats, 0, sizeof res->stats);
    res->stats.n_valid = h->n_valid;
    res->stats.n_in_features = run->sum_points;
    res->stats.n_ctrl = (uint32_t)run->n_ctrl;
    res->stats.n_features = h->n_features;
    res->stats.time_ns = h->time_us * 1000u; /* time_us <= BSF_WIRE_TIME_US_MAX: no overflow */
    res->stats.n_beams = h->ext.n_beams;
    res->stats.cut = h->ext.cut;
    res->stats.n_cut_keypoints = h->ext.n_cut_keypoints;
    res->stats.n_cut_segments = h->ext.n_cut_segments;
    res->stats.n_cut_points = h->ext.n_cut_points;
}

bsf_status_t bsf_features_parse(reader_t *r, unsigned version, bsf_frame_t *out)
{
    bsf_result_t *res = out != NULL ? &out->result : NULL;
    features_head_t h;
    features_run_t run;
    uint32_t i;
    bsf_status_t st = parse_head(r, version, &h);

    memset(&run, 0, sizeof run);
    run.prev_last_beam = -1; /* the "previous last_beam" of the first feature */
    for (i = 0; st == BSF_OK && i < h.n_features; ++i) {
        st = parse_feature(r, &h, &run, i, res);
    }
    if (st != BSF_OK) {
        return st;
    }
    /* The beam count travels exactly when a feature wraps or with the
     * scan's geometry (one form per frame), and cut points are valid points
     * outside the features. */
    if (!padding_ok(r) || run.sum_points > h.n_valid ||
        h.ext.has_beams != (run.wraps | h.ext.has_geometry) ||
        h.ext.n_cut_points > h.n_valid - run.sum_points) {
        return BSF_ERR_FORMAT;
    }
    if (out != NULL) {
        store_frame(&h, &run, version, out);
    }
    return BSF_OK;
}
