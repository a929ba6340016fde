/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_stream.h"

#include <string.h>

#include "bsf_map_internal.h"
#include "bsf_wire.h"

/* Bit reader over the payload after byte 0, most significant bit first. */
typedef struct {
    const uint8_t *p;
    size_t len;     /* bytes */
    size_t bit_pos; /* bits consumed */
} reader_t;

static int get_bit(reader_t *r, uint32_t *bit)
{
    if (r->bit_pos >= 8u * r->len) {
        return 0;
    }
    *bit = (uint32_t)(r->p[r->bit_pos >> 3] >> (7u - (r->bit_pos & 7u))) & 1u;
    ++r->bit_pos;
    return 1;
}

/* n (<= 32) bits as an unsigned number. */
static int get_bits(reader_t *r, unsigned n, uint32_t *v)
{
    uint32_t value = 0;
    unsigned i;
    for (i = 0; i < n; ++i) {
        uint32_t bit;
        if (!get_bit(r, &bit)) {
            return 0;
        }
        value = (value << 1) | bit;
    }
    *v = value;
    return 1;
}

/*
 * An Exp-Golomb code of order k (k <= 25) whose value is at most max
 * (max >> k < 2^63). The run of leading zeros is cut off as soon as it is
 * too long for max, so the work per code is bounded.
 */
static int get_eg(reader_t *r, unsigned k, uint64_t max, uint64_t *v)
{
    const unsigned max_zeros = bsf_wire_bitlen((max >> k) + 1u) - 1u;
    unsigned zeros = 0;
    uint64_t u = 1u;
    uint64_t value;
    uint32_t bit;
    unsigned i;

    for (;;) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        if (bit != 0u) {
            break;
        }
        if (++zeros > max_zeros) {
            return 0;
        }
    }
    for (i = 0; i < zeros; ++i) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        u = (u << 1) | bit;
    }
    if (u - 1u > (max >> k)) {
        return 0;
    }
    value = u - 1u;
    for (i = 0; i < k; ++i) {
        if (!get_bit(r, &bit)) {
            return 0;
        }
        value = (value << 1) | bit;
    }
    if (value > max) {
        return 0;
    }
    *v = value;
    return 1;
}

static int get_u32(reader_t *r, unsigned k, uint32_t max, uint32_t *v)
{
    uint64_t u;
    if (!get_eg(r, k, max, &u)) {
        return 0;
    }
    *v = (uint32_t)u;
    return 1;
}

/* A zigzag Exp-Golomb code whose magnitude is at most max_abs. */
static int get_signed(reader_t *r, unsigned k, int64_t max_abs, int64_t *v)
{
    uint64_t u;
    if (!get_eg(r, k, 2u * (uint64_t)max_abs, &u)) {
        return 0;
    }
    *v = bsf_wire_unzigzag(u);
    return 1;
}

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

/* Control points of one feature (see put_ctrl in the encoder). */
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

/* Only zero padding up to the end of the last byte may follow. */
static int padding_ok(reader_t *r)
{
    uint32_t pad;
    return 8u * r->len - r->bit_pos < 8u &&
           get_bits(r, (unsigned)(8u * r->len - r->bit_pos), &pad) && pad == 0u;
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

static int get_float(reader_t *r, float *v);

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

/* A float sent as its IEEE-754 binary32 bit pattern; 0 when not finite. */
static int get_float(reader_t *r, float *v)
{
    uint32_t hi;
    uint32_t lo;
    uint32_t u;
    if (!get_bits(r, 16u, &hi) || !get_bits(r, 16u, &lo)) {
        return 0;
    }
    u = (hi << 16) | lo;
    if ((u & 0x7F800000u) == 0x7F800000u) {
        return 0; /* infinity or NaN */
    }
    memcpy(v, &u, sizeof *v);
    return 1;
}

static int get_cap(reader_t *r, unsigned k, uint32_t *v)
{
    return get_u32(r, k, BSF_WIRE_META_U16_MAX, v) && *v >= 1u;
}

/* Metadata payload after byte 0 (see write_metadata in the encoder). */
static bsf_status_t parse_metadata(reader_t *r, bsf_metadata_t *out)
{
    bsf_metadata_t m;
    uint32_t v[3];
    uint32_t method;
    uint32_t step_code;
    uint32_t has_origin;
    uint32_t source_len;
    uint32_t i;
    int64_t origin = 0;

    memset(&m, 0, sizeof m);
    for (i = 0; i < 3u; ++i) {
        if (!get_u32(r, BSF_WIRE_K_LIB_VERSION, BSF_WIRE_META_U16_MAX, &v[i])) {
            return BSF_ERR_FORMAT;
        }
    }
    if (!get_u32(r, BSF_WIRE_K_METHOD, BSF_WIRE_METHOD_MAX, &method) ||
        !get_float(r, &m.target_rms) || !(m.target_rms >= 0.0f) ||
        !get_u32(r, BSF_WIRE_K_STEP, BSF_WIRE_STEP_CODE_MAX, &step_code) || step_code == 0u ||
        !get_cap(r, BSF_WIRE_K_CAP_POINTS, &m.max_points) ||
        !get_cap(r, BSF_WIRE_K_CAP_KEYPOINTS, &m.max_keypoints) ||
        !get_cap(r, BSF_WIRE_K_CAP_SEGMENTS, &m.max_segments) ||
        !get_cap(r, BSF_WIRE_K_CAP_CTRL_PER_FEATURE, &m.max_ctrl_per_feature) ||
        !get_cap(r, BSF_WIRE_K_CAP_CTRL_POINTS, &m.max_ctrl_points) ||
        !get_u32(r, BSF_WIRE_K_META_N_BEAMS, BSF_WIRE_META_U16_MAX, &m.n_beams) ||
        !get_float(r, &m.angle_min) || !get_float(r, &m.angle_increment) ||
        !get_float(r, &m.range_min) || !get_float(r, &m.range_max) || !(m.range_min >= 0.0f) ||
        !(m.range_max >= m.range_min) || !get_bits(r, 1u, &has_origin)) {
        return BSF_ERR_FORMAT;
    }
    if (has_origin != 0u &&
        !get_signed(r, BSF_WIRE_K_TIME_ORIGIN, BSF_METADATA_TIME_ORIGIN_MAX, &origin)) {
        return BSF_ERR_FORMAT;
    }
    if (!get_u32(r, BSF_WIRE_K_SOURCE_LEN, BSF_METADATA_SOURCE_MAX, &source_len)) {
        return BSF_ERR_FORMAT;
    }
    for (i = 0; i < source_len; ++i) {
        uint32_t c;
        if (!get_bits(r, 8u, &c)) {
            return BSF_ERR_FORMAT;
        }
        m.source[i] = (char)c;
    }
    if (!bsf_wire_source_ok((const uint8_t *)m.source, source_len) || !padding_ok(r)) {
        return BSF_ERR_FORMAT;
    }
    if (out != NULL) {
        m.lib_version_major = (uint16_t)v[0];
        m.lib_version_minor = (uint16_t)v[1];
        m.lib_version_patch = (uint16_t)v[2];
        m.method = (uint8_t)method;
        m.quant_step = (float)step_code * BSF_QUANT_STEP_UNIT;
        m.has_time_origin = (uint8_t)has_origin;
        m.time_origin_us = origin;
        m.source_len = (uint8_t)source_len;
        m.source[source_len] = '\0';
        *out = m;
    }
    return BSF_OK;
}

/*
 * Parse a payload whose CRC has been checked. With out == NULL it only
 * validates; with out it writes, and then cannot fail (same bytes).
 */
static bsf_status_t parse_payload(const uint8_t *p, size_t len, bsf_frame_t *out)
{
    reader_t r;
    bsf_result_t *res = out != NULL ? &out->result : NULL;
    uint8_t b0;
    uint32_t version;
    uint32_t type;
    uint32_t has_pose;
    uint32_t has_ext = 0u;
    header_ext_t ext;
    uint32_t beam_limit;
    uint32_t seq;
    uint64_t timestamp;
    int64_t pose[2] = {0, 0};
    uint32_t theta = 0;
    uint32_t step_code;
    uint32_t n_valid;
    uint32_t time_us;
    uint32_t n_features;
    uint32_t k_ctrl[BSF_WIRE_N_CLASSES];
    uint32_t i;
    float step;
    size_t n_ctrl = 0;
    uint32_t sum_points = 0;
    int64_t prev_last_beam = -1;
    int64_t prev[2] = {0, 0};
    uint32_t wraps = 0u;

    if (len < 1u) {
        return BSF_ERR_FORMAT;
    }
    b0 = p[0];
    version = (uint32_t)b0 >> 4;
    type = b0 & 0x0Fu;
    if (version < BSF_FORMAT_VERSION_MIN || version > BSF_FORMAT_VERSION ||
        (type != BSF_FRAME_TYPE_FEATURES &&
         (version < 2u || (type != BSF_FRAME_TYPE_METADATA && type != BSF_FRAME_TYPE_MAP)))) {
        return BSF_ERR_VERSION;
    }
    if (type == BSF_FRAME_TYPE_MAP) {
        return bsf_map_frame_parse(p, len, out);
    }
    r.p = p + 1;
    r.len = len - 1u;
    r.bit_pos = 0;
    memset(&ext, 0, sizeof ext);
    if (type == BSF_FRAME_TYPE_METADATA) {
        const bsf_status_t st = parse_metadata(&r, out != NULL ? &out->metadata : NULL);
        if (st == BSF_OK && out != NULL) {
            out->version = (uint8_t)version;
            out->type = (uint8_t)type;
            out->seq = 0u;
            out->timestamp_ms = 0u;
            out->has_pose = 0u;
            out->pose_x = 0.0f;
            out->pose_y = 0.0f;
            out->pose_theta = 0.0f;
            out->quant_step = out->metadata.quant_step;
            out->time_us = 0u;
            out->has_geometry = 0u;
            out->angle_min = 0.0f;
            out->angle_increment = 0.0f;
            res->n_features = 0u;
            res->n_ctrl = 0u;
            memset(&res->stats, 0, sizeof res->stats);
        }
        return st;
    }
    /* Version 1 has no extension flag: it is version 2 with the flag 0. */
    if (!get_bits(&r, 1u, &has_pose) || (version >= 2u && !get_bits(&r, 1u, &has_ext)) ||
        !get_u32(&r, BSF_WIRE_K_SEQ, UINT32_MAX, &seq) ||
        !get_eg(&r, BSF_WIRE_K_TIMESTAMP, UINT64_MAX, &timestamp)) {
        return BSF_ERR_FORMAT;
    }
    if (has_pose != 0u && (!get_signed(&r, BSF_WIRE_K_POSE, BSF_WIRE_POSE_MM_MAX, &pose[0]) ||
                           !get_signed(&r, BSF_WIRE_K_POSE, BSF_WIRE_POSE_MM_MAX, &pose[1]) ||
                           !get_bits(&r, 16u, &theta))) {
        return BSF_ERR_FORMAT;
    }
    if (!get_u32(&r, BSF_WIRE_K_STEP, BSF_WIRE_STEP_CODE_MAX, &step_code) || step_code == 0u ||
        !get_u32(&r, BSF_WIRE_K_N, (uint32_t)BSF_MAX_POINTS, &n_valid) ||
        !get_u32(&r, BSF_WIRE_K_TIME_US, BSF_WIRE_TIME_US_MAX, &time_us) ||
        !get_u32(&r, BSF_WIRE_K_FEATURES, UINT32_MAX >> BSF_WIRE_K_FEATURES, &n_features)) {
        return BSF_ERR_FORMAT;
    }
    if (n_features > (uint32_t)BSF_MAX_SEGMENTS) {
        return BSF_ERR_CAPACITY;
    }
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        if (!get_bits(&r, BSF_WIRE_K_CTRL_BITS, &k_ctrl[i]) || k_ctrl[i] > BSF_WIRE_K_CTRL_MAX) {
            return BSF_ERR_FORMAT;
        }
    }
    if (has_ext != 0u) {
        const bsf_status_t st = get_ext(&r, n_valid, &ext);
        if (st != BSF_OK) {
            return st;
        }
    }
    beam_limit = ext.has_beams != 0u ? ext.n_beams : (uint32_t)BSF_MAX_POINTS;
    step = (float)step_code * BSF_QUANT_STEP_UNIT;

    for (i = 0; i < n_features; ++i) {
        uint32_t kind;
        uint32_t m;
        uint32_t has_mask;
        uint32_t span;
        uint32_t missing;
        uint32_t e_code;
        uint64_t mask = 0;
        uint32_t n_f;
        int64_t gap;
        int64_t first;
        int64_t last;
        bsf_status_t st;

        if (!get_bits(&r, 1u, &kind) || !get_u32(&r, BSF_WIRE_K_M, 62u, &m) ||
            !get_bits(&r, 1u, &has_mask)) {
            return BSF_ERR_FORMAT;
        }
        m += 2u; /* distinct control points */
        if (m > (uint32_t)BSF_MAX_CTRL_PER_FEATURE) {
            return BSF_ERR_CAPACITY;
        }
        if (has_mask != 0u) {
            uint32_t j;
            for (j = 0; j < m; ++j) {
                uint32_t bit;
                if (!get_bits(&r, 1u, &bit)) {
                    return BSF_ERR_FORMAT;
                }
                mask |= (uint64_t)bit << j;
            }
            if (mask == 0u) {
                return BSF_ERR_FORMAT; /* a mask is sent only when it has a vertex */
            }
        }
        if (!get_signed(&r, BSF_WIRE_K_GAP, (int64_t)BSF_MAX_POINTS, &gap) ||
            !get_u32(&r, BSF_WIRE_K_SPAN, (uint32_t)BSF_MAX_POINTS - 1u, &span)) {
            return BSF_ERR_FORMAT;
        }
        first = prev_last_beam + 1 + gap;
        /* A run past the last beam wraps through the seam (only when the
         * frame carries the beam count): span < n_beams keeps last < first. */
        if (first < 0 || first >= (int64_t)beam_limit || span >= beam_limit) {
            return BSF_ERR_FORMAT;
        }
        last = first + (int64_t)span;
        if (last >= (int64_t)beam_limit) {
            if (ext.has_beams == 0u) {
                return BSF_ERR_FORMAT;
            }
            last -= (int64_t)ext.n_beams;
            wraps = 1u;
        }
        if (!get_u32(&r, BSF_WIRE_K_MISSING, span + 1u, &missing) ||
            !get_u32(&r, BSF_WIRE_K_E_CURVE, BSF_WIRE_E_CURVE_CODE_MAX, &e_code)) {
            return BSF_ERR_FORMAT;
        }
        n_f = m + popcount64(mask);
        if (n_f < 3u) {
            return BSF_ERR_FORMAT;
        }
        if (n_f > (uint32_t)BSF_MAX_CTRL_PER_FEATURE ||
            n_ctrl + n_f > (size_t)BSF_MAX_CTRL_POINTS) {
            return BSF_ERR_CAPACITY;
        }
        st = get_ctrl(&r, k_ctrl, m, mask, step, n_ctrl, res, prev);
        if (st != BSF_OK) {
            return st;
        }
        if (res != NULL) {
            bsf_feature_t *f = &res->features[i];
            f->first_beam = (uint16_t)first;
            f->last_beam = (uint16_t)last;
            f->n_points = (uint16_t)(span + 1u - missing);
            f->ctrl_first = (uint16_t)n_ctrl;
            f->n_ctrl = (uint8_t)n_f;
            f->kind = (uint8_t)kind;
            f->e_curve = (float)e_code / BSF_WIRE_E_CURVE_PER_M;
        }
        n_ctrl += n_f;
        sum_points += span + 1u - missing;
        prev_last_beam = last;
    }
    /* The beam count travels exactly when a feature wraps or with the
     * scan's geometry (one form per frame), and cut points are valid points
     * outside the features. */
    if (!padding_ok(&r) || sum_points > n_valid || ext.has_beams != (wraps | ext.has_geometry) ||
        ext.n_cut_points > n_valid - sum_points) {
        return BSF_ERR_FORMAT;
    }
    if (out != NULL) {
        const int32_t theta_signed = theta >= 32768u ? (int32_t)theta - 65536 : (int32_t)theta;
        out->version = (uint8_t)version;
        out->type = (uint8_t)type;
        out->seq = seq;
        out->timestamp_ms = timestamp;
        out->has_pose = (uint8_t)has_pose;
        out->pose_x = (float)pose[0] / 1000.0f;
        out->pose_y = (float)pose[1] / 1000.0f;
        out->pose_theta = (float)theta_signed * BSF_WIRE_RAD_PER_THETA;
        out->quant_step = step;
        out->time_us = time_us;
        out->has_geometry = (uint8_t)ext.has_geometry;
        out->angle_min = ext.angle_min;
        out->angle_increment = ext.angle_increment;
        res->n_features = (uint16_t)n_features;
        res->n_ctrl = (uint16_t)n_ctrl;
        memset(&res->stats, 0, sizeof res->stats);
        res->stats.n_valid = n_valid;
        res->stats.n_in_features = sum_points;
        res->stats.n_ctrl = (uint32_t)n_ctrl;
        res->stats.n_features = n_features;
        res->stats.time_ns = time_us * 1000u; /* time_us <= BSF_WIRE_TIME_US_MAX: no overflow */
        res->stats.n_beams = ext.n_beams;
        res->stats.cut = ext.cut;
        res->stats.n_cut_keypoints = ext.n_cut_keypoints;
        res->stats.n_cut_segments = ext.n_cut_segments;
        res->stats.n_cut_points = ext.n_cut_points;
    }
    return BSF_OK;
}

/* Version, type and fields of a body whose CRC has been checked. */
static bsf_status_t decode_checked(const uint8_t *body, size_t len, bsf_frame_t *out)
{
    const size_t payload_len = len - BSF_FRAME_CRC_SIZE;
    bsf_status_t st = parse_payload(body, payload_len, NULL);
    if (st == BSF_OK) {
        st = parse_payload(body, payload_len, out);
    }
    if (st == BSF_OK) {
        out->payload = body;
        out->payload_len = payload_len;
    }
    return st;
}

bsf_status_t bsf_frame_decode(const uint8_t *body, size_t len, bsf_frame_t *out)
{
    if (body == NULL || out == NULL) {
        return BSF_ERR_ARG;
    }
    if (len <= BSF_FRAME_CRC_SIZE || bsf_crc32c(0u, body, len) != BSF_WIRE_CRC_RESIDUE) {
        return BSF_ERR_CRC;
    }
    return decode_checked(body, len, out);
}

static void frame_reset(bsf_decoder_t *dec)
{
    dec->len = 0u;
    dec->raw_len = 0u;
    dec->crc = 0u;
    dec->block_left = 0u;
    dec->block_code = 0u;
    dec->overflow = 0u;
}

void bsf_decoder_init(bsf_decoder_t *dec)
{
    if (dec != NULL) {
        frame_reset(dec);
        dec->meta_n_beams = 0u;
        memset(&dec->stats, 0, sizeof dec->stats);
    }
}

static void append(bsf_decoder_t *dec, uint8_t b)
{
    if (dec->len >= sizeof dec->body) {
        dec->overflow = 1u;
        return;
    }
    dec->body[dec->len++] = b;
    dec->crc = bsf_crc32c(dec->crc, &b, 1u);
}

/* The beam count of the last metadata frame, for a features frame that
 * does not carry its own, when it is consistent with the frame. */
static void fill_n_beams(bsf_result_t *res, uint32_t n_beams)
{
    uint32_t i;
    if (n_beams == 0u || res->stats.n_valid > n_beams) {
        return;
    }
    for (i = 0; i < res->n_features; ++i) {
        if (res->features[i].last_beam >= n_beams) {
            return;
        }
    }
    res->stats.n_beams = n_beams;
}

/* A delimiter arrived: deliver the frame or count why not. */
static int end_frame(bsf_decoder_t *dec, bsf_frame_t *out)
{
    bsf_decoder_stats_t *st = &dec->stats;
    int delivered = 0;

    if (dec->overflow) {
        ++st->oversize;
    } else if (dec->block_left != 0u) {
        ++st->malformed; /* the frame ends inside a COBS block: bytes were lost */
    } else if (dec->len <= BSF_FRAME_CRC_SIZE || dec->crc != BSF_WIRE_CRC_RESIDUE) {
        ++st->bad_crc;
    } else {
        const bsf_status_t s = decode_checked(dec->body, dec->len, out);
        if (s == BSF_OK) {
            ++st->frames_ok;
            delivered = out->type;
            if (out->type == BSF_FRAME_TYPE_METADATA) {
                ++st->metadata;
                dec->meta_n_beams = out->metadata.n_beams;
            } else if (out->result.stats.n_beams == 0u) {
                fill_n_beams(&out->result, dec->meta_n_beams);
            }
        } else if (s == BSF_ERR_VERSION) {
            const unsigned version = (unsigned)(dec->body[0] >> 4);
            if (version < BSF_FORMAT_VERSION_MIN || version > BSF_FORMAT_VERSION) {
                ++st->unsupported_version;
            } else {
                ++st->unknown_type;
            }
        } else {
            ++st->malformed;
        }
    }
    if (!delivered) {
        st->bytes_skipped += (uint32_t)dec->raw_len;
    }
    frame_reset(dec);
    return delivered;
}

int bsf_decoder_feed(bsf_decoder_t *dec, const uint8_t *data, size_t len, size_t *consumed,
                     bsf_frame_t *out)
{
    size_t i;

    if (dec == NULL || consumed == NULL || out == NULL || (data == NULL && len > 0u)) {
        return BSF_ERR_ARG;
    }
    for (i = 0; i < len; ++i) {
        const uint8_t b = data[i];
        if (b == 0u) {
            if (dec->raw_len != 0u) {
                const int type = end_frame(dec, out);
                if (type != 0) {
                    *consumed = i + 1u;
                    return type;
                }
            }
            continue;
        }
        ++dec->raw_len;
        if (dec->overflow) {
            continue;
        }
        if (dec->block_left == 0u) {
            /* A code byte: the previous short block stood for a zero. */
            if (dec->block_code != 0u && dec->block_code != 0xFFu) {
                append(dec, 0u);
            }
            dec->block_code = b;
            dec->block_left = (uint8_t)(b - 1u);
        } else {
            append(dec, b);
            --dec->block_left;
        }
    }
    *consumed = len;
    return 0;
}
