#include "bsf/bsf_stream.h"

#include <math.h>

#include "bsf_wire.h"

/*
 * One writer serves three uses: counting (buf == NULL, sink == NULL),
 * writing to a buffer (COBS code bytes are patched in place once their
 * block ends) and feeding a sink (a block is collected in work->block and
 * handed over whole, because its code byte must go first).
 */
typedef struct {
    uint8_t *buf;
    size_t cap;
    size_t pos;      /* bytes of the frame produced so far */
    size_t code_pos; /* buffer mode: where the current block's code byte goes */
    uint8_t code;    /* 1 + data bytes in the current block */
    uint32_t crc;
    bsf_encoder_t *work;
    bsf_sink_fn sink;
    void *ctx;
    int failed;
} writer_t;

static void emit(writer_t *w, const uint8_t *data, size_t len)
{
    if (!w->failed) {
        if (w->sink(w->ctx, data, len) != 0) {
            w->failed = 1;
        } else {
            w->pos += len;
        }
    }
}

static void block_start(writer_t *w)
{
    w->code = 1u;
    if (w->sink == NULL) {
        w->code_pos = w->pos++;
    }
}

static void block_end(writer_t *w)
{
    if (w->sink != NULL) {
        w->work->block[0] = w->code;
        emit(w, w->work->block, w->code);
    } else if (w->buf != NULL && w->code_pos < w->cap) {
        w->buf[w->code_pos] = w->code;
    }
}

static void put_u8(writer_t *w, uint8_t b)
{
    w->crc = bsf_crc32c(w->crc, &b, 1u);
    if (b == 0u) {
        block_end(w);
        block_start(w);
        return;
    }
    if (w->sink != NULL) {
        w->work->block[w->code] = b;
    } else {
        if (w->buf != NULL && w->pos < w->cap) {
            w->buf[w->pos] = b;
        }
        ++w->pos;
    }
    if (++w->code == 0xFFu) {
        block_end(w);
        block_start(w);
    }
}

static void put_varint(writer_t *w, uint64_t v)
{
    while (v >= 0x80u) {
        put_u8(w, (uint8_t)((v & 0x7Fu) | 0x80u));
        v >>= 7;
    }
    put_u8(w, (uint8_t)v);
}

static void put_signed(writer_t *w, int64_t v)
{
    put_varint(w, bsf_wire_zigzag(v));
}

/* Ends the frame: the CRC (not itself checksummed), the last block, 0x00. */
static void finish(writer_t *w)
{
    const uint32_t crc = w->crc;
    unsigned i;
    for (i = 0; i < 4u; ++i) {
        put_u8(w, (uint8_t)(crc >> (8u * i)));
    }
    if (w->sink != NULL) {
        w->work->block[0] = w->code;
        w->work->block[w->code] = 0u;
        emit(w, w->work->block, (size_t)w->code + 1u);
    } else {
        block_end(w);
        if (w->buf != NULL && w->pos < w->cap) {
            w->buf[w->pos] = 0u;
        }
        ++w->pos;
    }
}

static int is_finite_f(float v)
{
    return v == v && fabsf(v) <= 3.402823466e38f;
}

/* Nearest multiple of step, in steps; 0 when v is not finite or too far. */
static int quantise(float v, float step, int32_t *q)
{
    const float r = floorf(v / step + 0.5f);
    if (!(fabsf(r) <= (float)BSF_QUANT_MAX_STEPS)) {
        *q = 0;
        return 0;
    }
    *q = (int32_t)r;
    return 1;
}

static int quantise_point(bsf_point_t p, float step, int32_t q[2])
{
    const int ok_x = quantise(p.x, step, &q[0]);
    const int ok_y = quantise(p.y, step, &q[1]);
    return ok_x && ok_y;
}

/*
 * Checks one feature and finds its unique control points: a flagged slot
 * must be followed by a flagged partner with the same quantised value;
 * the pair is one vertex, bit j of *mask for unique point j.
 */
static bsf_status_t scan_feature(const bsf_result_t *res, const bsf_feature_t *f, float step,
                                 uint32_t *n_unique, uint64_t *mask)
{
    const size_t n = f->n_ctrl;
    size_t s = 0;
    uint32_t j = 0;

    if (f->kind > 1u || n < 3u || n > (size_t)BSF_MAX_CTRL_PER_FEATURE ||
        (size_t)f->ctrl_first + n > (size_t)res->n_ctrl || f->first_beam > f->last_beam ||
        f->last_beam >= (uint32_t)BSF_MAX_POINTS ||
        f->n_points > (uint32_t)(f->last_beam - f->first_beam) + 1u ||
        !(f->e_curve >= 0.0f && f->e_curve <= BSF_E_CURVE_MAX)) {
        return BSF_ERR_ARG;
    }
    *mask = 0u;
    while (s < n) {
        const size_t slot = (size_t)f->ctrl_first + s;
        int32_t q[2];
        if (!quantise_point(res->ctrl[slot], step, q)) {
            return BSF_ERR_ARG;
        }
        if (res->ctrl_is_vertex[slot] != 0u) {
            int32_t q2[2];
            if (s + 1u >= n || res->ctrl_is_vertex[slot + 1u] == 0u ||
                !quantise_point(res->ctrl[slot + 1u], step, q2) || q2[0] != q[0] || q2[1] != q[1]) {
                return BSF_ERR_ARG;
            }
            *mask |= (uint64_t)1u << j;
            s += 2u;
        } else {
            s += 1u;
        }
        ++j;
    }
    *n_unique = j;
    return BSF_OK;
}

static void put_delta(writer_t *w, const int32_t q[2], const int64_t ref[2])
{
    put_signed(w, (int64_t)q[0] - ref[0]);
    put_signed(w, (int64_t)q[1] - ref[1]);
}

/*
 * Control points of one (already checked) feature: the first unique point
 * as a delta from *prev, then per fragment the next anchor (vertex or last
 * point) as a delta from the previous anchor, then the fragment's precision
 * points as residuals from their predicted places on the chord.
 */
static void put_ctrl(writer_t *w, const bsf_result_t *res, const bsf_feature_t *f, float step,
                     int64_t prev[2])
{
    const bsf_point_t *p = &res->ctrl[f->ctrl_first];
    const uint8_t *vtx = &res->ctrl_is_vertex[f->ctrl_first];
    const size_t n = f->n_ctrl;
    size_t s_a = 0;
    size_t c_a = vtx[0] != 0u ? 2u : 1u;
    int32_t q_a[2];
    int64_t ref[2];

    (void)quantise_point(p[0], step, q_a);
    put_delta(w, q_a, prev);
    while (s_a + c_a < n) {
        const size_t t = s_a + c_a;
        size_t s_b = t;
        size_t i;
        int32_t q_b[2];
        while (s_b < n - 1u && vtx[s_b] == 0u) {
            ++s_b;
        }
        (void)quantise_point(p[s_b], step, q_b);
        ref[0] = q_a[0];
        ref[1] = q_a[1];
        put_delta(w, q_b, ref);
        for (i = t; i < s_b; ++i) {
            const uint32_t k = (uint32_t)(s_b - t);
            const uint32_t s = (uint32_t)(i - t) + 1u;
            int32_t q[2];
            (void)quantise_point(p[i], step, q);
            ref[0] = bsf_wire_predict(q_a[0], q_b[0], s, k);
            ref[1] = bsf_wire_predict(q_a[1], q_b[1], s, k);
            put_delta(w, q, ref);
        }
        s_a = s_b;
        c_a = vtx[s_b] != 0u ? 2u : 1u;
        q_a[0] = q_b[0];
        q_a[1] = q_b[1];
    }
    prev[0] = q_a[0];
    prev[1] = q_a[1];
}

static bsf_status_t check_info(const bsf_frame_info_t *info, uint32_t *step_code)
{
    float code;
    if (!is_finite_f(info->quant_step)) {
        return BSF_ERR_ARG;
    }
    code = floorf(info->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    if (!(code >= 1.0f && code <= (float)BSF_WIRE_STEP_CODE_MAX)) {
        return BSF_ERR_ARG;
    }
    *step_code = (uint32_t)code;
    if (info->has_pose > 1u) {
        return BSF_ERR_ARG;
    }
    if (info->has_pose != 0u &&
        (!(fabsf(info->pose_x) <= BSF_POSE_XY_MAX) || !(fabsf(info->pose_y) <= BSF_POSE_XY_MAX) ||
         !(fabsf(info->pose_theta) <= BSF_POSE_THETA_MAX))) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

static int32_t round_to_int(float v)
{
    return (int32_t)floorf(v + 0.5f);
}

/* The whole frame through w. It may fail half-way, so every caller runs it
 * in counting mode first and writes only when that pass succeeded. */
static bsf_status_t write_frame(writer_t *w, const bsf_frame_info_t *info, const bsf_result_t *res)
{
    uint32_t step_code;
    float step;
    uint32_t i;
    uint32_t sum_points = 0;
    int64_t prev_last_beam = -1;
    int64_t prev[2] = {0, 0};
    bsf_status_t st;

    if (res->n_features > (uint32_t)BSF_MAX_SEGMENTS ||
        res->n_ctrl > (uint32_t)BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = check_info(info, &step_code);
    if (st != BSF_OK) {
        return st;
    }
    if (res->stats.n_valid > (uint32_t)BSF_MAX_POINTS) {
        return BSF_ERR_ARG;
    }
    step = (float)step_code * BSF_QUANT_STEP_UNIT;

    block_start(w);
    put_u8(w, (uint8_t)((BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_FEATURES));
    put_u8(w, info->has_pose != 0u ? (uint8_t)BSF_WIRE_FLAG_POSE : 0u);
    put_varint(w, info->seq);
    put_varint(w, info->timestamp_ms);
    if (info->has_pose != 0u) {
        const uint32_t theta =
            (uint32_t)round_to_int(info->pose_theta * BSF_WIRE_THETA_PER_RAD) & 0xFFFFu;
        put_signed(w, round_to_int(info->pose_x * 1000.0f));
        put_signed(w, round_to_int(info->pose_y * 1000.0f));
        put_u8(w, (uint8_t)(theta & 0xFFu));
        put_u8(w, (uint8_t)(theta >> 8));
    }
    put_varint(w, step_code);
    put_varint(w, res->stats.n_valid);
    put_varint(w, ((uint64_t)res->stats.time_ns + 500u) / 1000u);
    put_varint(w, res->n_features);

    for (i = 0; i < res->n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        uint32_t n_unique = 0;
        uint64_t mask = 0;
        uint32_t span;
        uint32_t missing;
        uint32_t desc;

        st = scan_feature(res, f, step, &n_unique, &mask);
        if (st != BSF_OK) {
            return st;
        }
        span = (uint32_t)(f->last_beam - f->first_beam);
        missing = span + 1u - f->n_points;
        sum_points += f->n_points;
        desc = (uint32_t)f->kind | (mask != 0u ? BSF_WIRE_DESC_VERTICES : 0u) |
               (missing != 0u ? BSF_WIRE_DESC_MISSING : 0u) |
               ((n_unique - 2u) << BSF_WIRE_DESC_SHIFT);
        put_varint(w, desc);
        put_signed(w, (int64_t)f->first_beam - prev_last_beam - 1);
        put_varint(w, span);
        if (missing != 0u) {
            put_varint(w, missing);
        }
        put_varint(w, (uint64_t)floorf(f->e_curve * 10000.0f + 0.5f));
        if (mask != 0u) {
            put_varint(w, mask);
        }
        put_ctrl(w, res, f, step, prev);
        prev_last_beam = f->last_beam;
    }
    if (sum_points > res->stats.n_valid) {
        return BSF_ERR_ARG;
    }
    finish(w);
    return BSF_OK;
}

void bsf_frame_info_init(bsf_frame_info_t *info)
{
    if (info != NULL) {
        info->seq = 0u;
        info->timestamp_ms = 0u;
        info->has_pose = 0u;
        info->pose_x = 0.0f;
        info->pose_y = 0.0f;
        info->pose_theta = 0.0f;
        info->quant_step = BSF_QUANT_STEP_DEFAULT;
    }
}

static void writer_init(writer_t *w)
{
    w->buf = NULL;
    w->cap = 0u;
    w->pos = 0u;
    w->code_pos = 0u;
    w->code = 1u;
    w->crc = 0u;
    w->work = NULL;
    w->sink = NULL;
    w->ctx = NULL;
    w->failed = 0;
}

bsf_status_t bsf_frame_encode(const bsf_frame_info_t *info, const bsf_result_t *result,
                              uint8_t *buf, size_t cap, size_t *out_len)
{
    writer_t w;
    bsf_status_t st;

    if (info == NULL || result == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    writer_init(&w);
    st = write_frame(&w, info, result);
    if (st != BSF_OK) {
        *out_len = 0u;
        return st;
    }
    *out_len = w.pos;
    if (buf == NULL) {
        return BSF_OK;
    }
    if (w.pos > cap) {
        return BSF_ERR_BUFFER;
    }
    writer_init(&w);
    w.buf = buf;
    w.cap = cap;
    return write_frame(&w, info, result);
}

bsf_status_t bsf_frame_encode_sink(bsf_encoder_t *work, const bsf_frame_info_t *info,
                                   const bsf_result_t *result, bsf_sink_fn sink, void *ctx,
                                   size_t *written)
{
    writer_t w;
    bsf_status_t st;

    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || info == NULL || result == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    writer_init(&w);
    st = write_frame(&w, info, result);
    if (st != BSF_OK) {
        return st;
    }
    writer_init(&w);
    w.work = work;
    w.sink = sink;
    w.ctx = ctx;
    st = write_frame(&w, info, result);
    if (written != NULL) {
        *written = w.pos;
    }
    if (st == BSF_OK && w.failed) {
        st = BSF_ERR_BUFFER;
    }
    return st;
}
