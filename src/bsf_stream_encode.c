/* SPDX-License-Identifier: MIT */
#include "bsf/bsf_stream.h"

#include <math.h>
#include <string.h>

#include "bsf_math.h"
#include "bsf_wire.h"

/*
 * One writer serves four uses: costing (nothing is emitted: the bits of
 * everything but the control point values are summed, and those values are
 * tallied per class to cost every Exp-Golomb order at once), counting (buf ==
 * NULL, sink == NULL), writing to a buffer (COBS code bytes are patched in
 * place once their block ends) and feeding a sink (a block is collected in
 * work->block and handed over whole, because its code byte must go first).
 * The payload's bit stream goes through put_bits, whole bytes through put_u8.
 */
typedef struct {
    uint8_t *buf;
    size_t cap;
    size_t pos;       /* bytes of the frame produced so far */
    size_t code_pos;  /* buffer mode: where the current block's code byte goes */
    uint8_t code;     /* 1 + data bytes in the current block */
    uint32_t crc_reg; /* CRC-32C register: the CRC is its complement */
    bsf_encoder_t *work;
    bsf_sink_fn sink;
    void *ctx;
    int failed;
    uint64_t acc;   /* pending bits of the payload's bit stream, MSB first */
    unsigned n_acc; /* number of pending bits (< 8 between calls) */
    /* Costing run (costing != 0): nothing is emitted; bits sums the payload
     * bits outside the control point values, tally counts those per class. */
    int costing;
    uint32_t bits;
    bsf_wire_eg_tally_t *tally; /* costing run only: BSF_WIRE_N_CLASSES entries (the
                                 * writing runs do not carry them on the stack) */
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
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
    if (w->costing) {
        w->bits += 8u;
        return;
    }
    w->crc_reg = bsf_wire_crc32c_step(w->crc_reg, b);
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

/* The n (<= 32) low bits of v, most significant first, whole bytes out. */
static void put_bits(writer_t *w, uint32_t v, unsigned n)
{
    if (w->costing) {
        w->bits += n;
        return;
    }
    w->acc = (w->acc << n) | ((uint64_t)v & ((((uint64_t)1) << n) - 1u));
    w->n_acc += n;
    while (w->n_acc >= 8u) {
        w->n_acc -= 8u;
        put_u8(w, (uint8_t)(w->acc >> w->n_acc));
    }
}

/* The n (<= 64) low bits of v. */
static void put_bits_wide(writer_t *w, uint64_t v, unsigned n)
{
    if (n > 32u) {
        put_bits(w, (uint32_t)(v >> 32), n - 32u);
        n = 32u;
    }
    put_bits(w, (uint32_t)v, n);
}

/* Exp-Golomb code of order k: for u = (v >> k) + 1 of b bits, b - 1 zeros,
 * u itself, then the k low bits of v; short codes as one field. */
static void put_eg_bits(writer_t *w, uint64_t v, unsigned k)
{
    const uint64_t u = (v >> k) + 1u;
    const unsigned b = bsf_wire_bitlen(u);
    const uint64_t low = k == 0u ? 0u : v & (~(uint64_t)0 >> (64u - k));
    if (2u * b - 1u + k <= 32u) {
        /* the b - 1 zeros come out as the leading zeros of the field */
        put_bits(w, (uint32_t)((u << k) | low), 2u * b - 1u + k);
        return;
    }
    put_bits_wide(w, 0u, b - 1u);
    put_bits_wide(w, u, b);
    put_bits_wide(w, low, k);
}

/* Costing runs only add the code's length (inline: most fields pass here). */
static inline void put_eg(writer_t *w, uint64_t v, unsigned k)
{
    if (w->costing) {
        w->bits += 2u * bsf_wire_bitlen((v >> k) + 1u) - 1u + k;
    } else {
        put_eg_bits(w, v, k);
    }
}

static void put_seg(writer_t *w, int64_t v, unsigned k)
{
    put_eg(w, bsf_wire_zigzag(v), k);
}

/* A control point value of class cls: costed or written at the frame's order. */
static void put_ctrl_value(writer_t *w, unsigned cls, int64_t v)
{
    const uint64_t z = bsf_wire_zigzag(v);
    if (w->costing) {
        bsf_wire_eg_tally_add(&w->tally[cls], z);
    } else {
        put_eg(w, z, w->k_ctrl[cls]);
    }
}

/* Ends the frame: the CRC (not itself checksummed), the last block, 0x00. */
static void finish(writer_t *w)
{
    uint32_t crc;
    unsigned i;
    if (w->costing) {
        return; /* the caller adds padding and CRC */
    }
    if (w->n_acc > 0u) {
        put_bits(w, 0u, 8u - w->n_acc); /* pad the last byte with zeros */
    }
    crc = ~w->crc_reg;
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

/* Nearest multiple of step, in steps: floor(v / step + 0.5); 0 when v is
 * not finite or too far. |floor(r)| <= BSF_QUANT_MAX_STEPS = 2^23 - 1 is
 * -(2^23 - 1) <= r < 2^23, where the floor is a truncation toward zero,
 * one lower for a negative r with a fraction. */
static int quantise(float v, float step, int32_t *q)
{
    const float r = v / step + 0.5f;
    int32_t t;
    if (!(r >= -(float)BSF_QUANT_MAX_STEPS && r < (float)BSF_QUANT_MAX_STEPS + 1.0f)) {
        *q = 0;
        return 0; /* NaN included */
    }
    t = (int32_t)r;
    *q = (float)t > r ? t - 1 : t;
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
/* Beams minus one of a feature's run: last - first, or through the seam of
 * a full-circle scan of n_beams beams when first > last. */
static uint32_t feature_span(const bsf_feature_t *f, uint32_t n_beams)
{
    if (f->first_beam > f->last_beam) {
        return n_beams - f->first_beam + f->last_beam;
    }
    return (uint32_t)(f->last_beam - f->first_beam);
}

static bsf_status_t scan_feature(const bsf_result_t *res, const bsf_feature_t *f, float step,
                                 int check_points, uint32_t *n_unique, uint64_t *mask)
{
    const size_t n = f->n_ctrl;
    const uint32_t n_beams = res->stats.n_beams;
    const uint32_t beam_limit = n_beams != 0u ? n_beams : (uint32_t)BSF_MAX_POINTS;
    size_t s = 0;
    uint32_t j = 0;

    if (f->kind > 1u || n < 3u || n > (size_t)BSF_MAX_CTRL_PER_FEATURE ||
        (size_t)f->ctrl_first + n > (size_t)res->n_ctrl || f->first_beam >= beam_limit ||
        f->last_beam >= beam_limit || (f->first_beam > f->last_beam && n_beams == 0u) ||
        f->n_points > feature_span(f, n_beams) + 1u ||
        !(f->e_curve >= 0.0f && f->e_curve <= BSF_E_CURVE_MAX)) {
        return BSF_ERR_ARG;
    }
    *mask = 0u;
    while (s < n) {
        const size_t slot = (size_t)f->ctrl_first + s;
        int32_t q[2];
        if (check_points && !quantise_point(res->ctrl[slot], step, q)) {
            return BSF_ERR_ARG;
        }
        if (res->ctrl_is_vertex[slot] != 0u) {
            int32_t q2[2];
            if (check_points && (s + 1u >= n || res->ctrl_is_vertex[slot + 1u] == 0u ||
                                 !quantise_point(res->ctrl[slot + 1u], step, q2) || q2[0] != q[0] ||
                                 q2[1] != q[1])) {
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

static void put_delta(writer_t *w, unsigned cls, const int32_t q[2], const int64_t ref[2])
{
    put_ctrl_value(w, cls, (int64_t)q[0] - ref[0]);
    put_ctrl_value(w, cls, (int64_t)q[1] - ref[1]);
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
    put_delta(w, BSF_WIRE_CLASS_FIRST, q_a, prev);
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
        put_delta(w, BSF_WIRE_CLASS_ANCHOR, q_b, ref);
        for (i = t; i < s_b; ++i) {
            const uint32_t k = (uint32_t)(s_b - t);
            const uint32_t s = (uint32_t)(i - t) + 1u;
            int32_t q[2];
            (void)quantise_point(p[i], step, q);
            ref[0] = bsf_wire_predict(q_a[0], q_b[0], s, k);
            ref[1] = bsf_wire_predict(q_a[1], q_b[1], s, k);
            put_delta(w, BSF_WIRE_CLASS_PREC, q, ref);
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
    code = bsf_floorf(info->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    if (!(code >= 1.0f && code <= (float)BSF_WIRE_STEP_CODE_MAX)) {
        return BSF_ERR_ARG;
    }
    *step_code = (uint32_t)code;
    if (info->has_pose > 1u || info->has_geometry > 1u ||
        (info->has_geometry != 0u &&
         (!is_finite_f(info->angle_min) || !is_finite_f(info->angle_increment)))) {
        return BSF_ERR_ARG;
    }
    if (info->has_pose != 0u &&
        (!(fabsf(info->pose_x) <= BSF_POSE_XY_MAX) || !(fabsf(info->pose_y) <= BSF_POSE_XY_MAX) ||
         !(fabsf(info->pose_theta) <= BSF_POSE_THETA_MAX))) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

/* The scan statistics that travel in the header's extension (FORMAT.md
 * section 3.1): the beam count must stay within the caps, the cut counters
 * go with a non-zero cut and stay within the scan. */
static bsf_status_t check_stats(const bsf_stats_t *st)
{
    const uint32_t cut_bits = BSF_CUT_KEYPOINTS | BSF_CUT_SEGMENTS | BSF_CUT_CTRL;
    if (st->n_valid > (uint32_t)BSF_MAX_POINTS || st->n_beams > (uint32_t)BSF_MAX_POINTS ||
        (st->n_beams != 0u && st->n_valid > st->n_beams) || (st->cut & ~cut_bits) != 0u) {
        return BSF_ERR_ARG;
    }
    if (st->cut == 0u) {
        return (st->n_cut_keypoints | st->n_cut_segments | st->n_cut_points) == 0u ? BSF_OK
                                                                                   : BSF_ERR_ARG;
    }
    if (st->n_cut_keypoints > (uint32_t)BSF_MAX_POINTS ||
        st->n_cut_segments > (uint32_t)BSF_MAX_POINTS || st->n_cut_points > st->n_valid) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

static int32_t round_to_int(float v)
{
    return (int32_t)bsf_floorf(v + 0.5f);
}

static void put_float(writer_t *w, float v);

/* The whole frame through w. It may fail half-way, so every caller runs it
 * in costing and counting mode first and writes only when those passes
 * succeeded. */
static bsf_status_t write_frame(writer_t *w, const bsf_frame_info_t *info, const bsf_result_t *res)
{
    uint32_t step_code;
    float step;
    uint32_t i;
    uint32_t sum_points = 0;
    int64_t prev_last_beam = -1;
    int64_t prev[2] = {0, 0};
    uint32_t wraps = 0u;
    int has_beams;
    int has_ext;
    bsf_status_t st;

    if (res->n_features > (uint32_t)BSF_MAX_SEGMENTS ||
        res->n_ctrl > (uint32_t)BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = check_info(info, &step_code);
    if (st != BSF_OK) {
        return st;
    }
    st = check_stats(&res->stats);
    if (st != BSF_OK) {
        return st;
    }
    if (info->has_geometry != 0u && res->stats.n_beams == 0u) {
        return BSF_ERR_ARG;
    }
    step = (float)step_code * BSF_QUANT_STEP_UNIT;
    for (i = 0; i < res->n_features; ++i) {
        if (res->features[i].first_beam > res->features[i].last_beam) {
            wraps = 1u;
        }
    }
    has_beams = wraps != 0u || info->has_geometry != 0u;
    has_ext = has_beams || res->stats.cut != 0u;

    block_start(w);
    put_u8(w, (uint8_t)((BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_FEATURES));
    put_bits(w, info->has_pose != 0u ? 1u : 0u, 1u);
    put_bits(w, has_ext ? 1u : 0u, 1u);
    put_eg(w, info->seq, BSF_WIRE_K_SEQ);
    put_eg(w, info->timestamp_ms, BSF_WIRE_K_TIMESTAMP);
    if (info->has_pose != 0u) {
        const uint32_t theta =
            (uint32_t)round_to_int(info->pose_theta * BSF_WIRE_THETA_PER_RAD) & 0xFFFFu;
        put_seg(w, round_to_int(info->pose_x * 1000.0f), BSF_WIRE_K_POSE);
        put_seg(w, round_to_int(info->pose_y * 1000.0f), BSF_WIRE_K_POSE);
        put_bits(w, theta, 16u);
    }
    put_eg(w, step_code, BSF_WIRE_K_STEP);
    put_eg(w, res->stats.n_valid, BSF_WIRE_K_N);
    put_eg(w, ((uint64_t)res->stats.time_ns + 500u) / 1000u, BSF_WIRE_K_TIME_US);
    put_eg(w, res->n_features, BSF_WIRE_K_FEATURES);
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        put_bits(w, w->k_ctrl[i], BSF_WIRE_K_CTRL_BITS);
    }
    if (has_ext) {
        put_bits(w, has_beams ? 1u : 0u, 1u);
        put_bits(w, info->has_geometry != 0u ? 1u : 0u, 1u);
        put_bits(w, res->stats.cut, BSF_WIRE_CUT_BITS);
        if (has_beams) {
            put_eg(w, res->stats.n_beams, BSF_WIRE_K_N_BEAMS);
        }
        if (info->has_geometry != 0u) {
            put_float(w, info->angle_min);
            put_float(w, info->angle_increment);
        }
        if (res->stats.cut != 0u) {
            put_eg(w, res->stats.n_cut_keypoints, BSF_WIRE_K_CUT_KEYPOINTS);
            put_eg(w, res->stats.n_cut_segments, BSF_WIRE_K_CUT_SEGMENTS);
            put_eg(w, res->stats.n_cut_points, BSF_WIRE_K_CUT_POINTS);
        }
    }

    for (i = 0; i < res->n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        uint32_t n_unique = 0;
        uint64_t mask = 0;
        uint32_t span;
        uint32_t j;

        /* the points were checked by the costing run that precedes every
         * other run (a vertex pair's flags alone then give the mask) */
        st = scan_feature(res, f, step, w->costing, &n_unique, &mask);
        if (st != BSF_OK) {
            return st;
        }
        span = feature_span(f, res->stats.n_beams);
        sum_points += f->n_points;
        put_bits(w, f->kind, 1u);
        put_eg(w, n_unique - 2u, BSF_WIRE_K_M);
        put_bits(w, mask != 0u ? 1u : 0u, 1u);
        for (j = 0; mask != 0u && j < n_unique; ++j) {
            put_bits(w, (uint32_t)(mask >> j) & 1u, 1u);
        }
        put_seg(w, (int64_t)f->first_beam - prev_last_beam - 1, BSF_WIRE_K_GAP);
        put_eg(w, span, BSF_WIRE_K_SPAN);
        put_eg(w, span + 1u - f->n_points, BSF_WIRE_K_MISSING);
        put_eg(w, (uint64_t)bsf_floorf(f->e_curve * BSF_WIRE_E_CURVE_PER_M + 0.5f),
               BSF_WIRE_K_E_CURVE);
        put_ctrl(w, res, f, step, prev);
        prev_last_beam = f->last_beam;
    }
    if (sum_points > res->stats.n_valid ||
        res->stats.n_cut_points > res->stats.n_valid - sum_points) {
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
        info->has_geometry = 0u;
        info->angle_min = 0.0f;
        info->angle_increment = 0.0f;
    }
}

static void writer_init(writer_t *w)
{
    w->buf = NULL;
    w->cap = 0u;
    w->pos = 0u;
    w->code_pos = 0u;
    w->code = 1u;
    w->crc_reg = 0xFFFFFFFFu;
    w->work = NULL;
    w->sink = NULL;
    w->ctx = NULL;
    w->failed = 0;
    w->acc = 0u;
    w->n_acc = 0u;
    w->costing = 0;
    w->tally = NULL;
    w->bits = 0u;
    memset(w->k_ctrl, 0, sizeof w->k_ctrl);
}

/*
 * The Exp-Golomb order of each control point class that makes the frame
 * shortest (one costing run; ties go to the smaller order), and an upper
 * bound on the frame's size. The chosen total never exceeds the total at
 * order 25, which bounds every value by 26 bits (BSF_FRAME_CTRL_MAX_BITS).
 */
static bsf_status_t choose_orders(const bsf_frame_info_t *info, const bsf_result_t *res,
                                  uint8_t k_ctrl[BSF_WIRE_N_CLASSES], size_t *size_bound)
{
    writer_t w;
    bsf_wire_eg_tally_t tally[BSF_WIRE_N_CLASSES];
    unsigned cls;
    uint32_t bits;
    size_t body;
    bsf_status_t st;
    writer_init(&w);
    w.costing = 1;
    memset(tally, 0, sizeof tally);
    w.tally = tally;
    st = write_frame(&w, info, res);
    if (st != BSF_OK) {
        return st;
    }
    bits = w.bits;
    for (cls = 0; cls < BSF_WIRE_N_CLASSES; ++cls) {
        uint32_t cost[BSF_WIRE_K_CTRL_MAX + 1u];
        unsigned k;
        unsigned best = 0;
        /* above the longest value's bit length L every order costs one bit
         * per value more than the one before, so none beats order L */
        const unsigned k_top =
            tally[cls].max_len < BSF_WIRE_K_CTRL_MAX ? tally[cls].max_len : BSF_WIRE_K_CTRL_MAX;
        bsf_wire_eg_tally_costs(&tally[cls], k_top, cost);
        for (k = 1; k <= k_top; ++k) {
            if (cost[k] < cost[best]) {
                best = k;
            }
        }
        k_ctrl[cls] = (uint8_t)best;
        bits += cost[best];
    }
    /* payload bytes and CRC, one COBS code byte first and one per 254
     * bytes at most (a zero byte is replaced by one), the 0x00 delimiter */
    body = ((size_t)bits + 7u) / 8u + 4u;
    *size_bound = body + body / 254u + 2u;
    return BSF_OK;
}

/* Write a validated frame with the chosen orders into buf (cap bytes). */
static bsf_status_t write_frame_into(uint8_t *buf, size_t cap,
                                     const uint8_t k_ctrl[BSF_WIRE_N_CLASSES],
                                     const bsf_frame_info_t *info, const bsf_result_t *res,
                                     writer_t *w)
{
    writer_init(w);
    memcpy(w->k_ctrl, k_ctrl, BSF_WIRE_N_CLASSES);
    w->buf = buf;
    w->cap = cap;
    return write_frame(w, info, res);
}

bsf_status_t bsf_frame_encode(const bsf_frame_info_t *info, const bsf_result_t *result,
                              uint8_t *buf, size_t cap, size_t *out_len)
{
    writer_t w;
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
    size_t bound = 0;
    bsf_status_t st;

    if (info == NULL || result == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    st = choose_orders(info, result, k_ctrl, &bound);
    if (st == BSF_OK && buf != NULL && cap >= bound) {
        /* validated, and fits whatever its COBS blocks: write at once */
        st = write_frame_into(buf, cap, k_ctrl, info, result, &w);
        *out_len = st == BSF_OK ? w.pos : 0u;
        return st;
    }
    if (st == BSF_OK) {
        writer_init(&w);
        memcpy(w.k_ctrl, k_ctrl, sizeof k_ctrl);
        st = write_frame(&w, info, result);
    }
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
    return write_frame_into(buf, cap, k_ctrl, info, result, &w);
}

bsf_status_t bsf_frame_encode_sink(bsf_encoder_t *work, const bsf_frame_info_t *info,
                                   const bsf_result_t *result, bsf_sink_fn sink, void *ctx,
                                   size_t *written)
{
    writer_t w;
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
    size_t bound;
    bsf_status_t st;

    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || info == NULL || result == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    st = choose_orders(info, result, k_ctrl, &bound);
    if (st != BSF_OK) {
        return st;
    }
    writer_init(&w);
    memcpy(w.k_ctrl, k_ctrl, sizeof k_ctrl);
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

/* ---- Metadata frame ------------------------------------------------------ */

void bsf_metadata_init(bsf_metadata_t *m)
{
    if (m != NULL) {
        memset(m, 0, sizeof *m);
        m->lib_version_major = (uint16_t)BSF_VERSION_MAJOR;
        m->lib_version_minor = (uint16_t)BSF_VERSION_MINOR;
        m->lib_version_patch = (uint16_t)BSF_VERSION_PATCH;
        m->quant_step = BSF_QUANT_STEP_DEFAULT;
        m->max_points = (uint32_t)BSF_MAX_POINTS;
        m->max_keypoints = (uint32_t)BSF_MAX_KEYPOINTS;
        m->max_segments = (uint32_t)BSF_MAX_SEGMENTS;
        m->max_ctrl_per_feature = (uint32_t)BSF_MAX_CTRL_PER_FEATURE;
        m->max_ctrl_points = (uint32_t)BSF_MAX_CTRL_POINTS;
    }
}

static uint32_t float_bits(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

static void put_float(writer_t *w, float v)
{
    const uint32_t u = float_bits(v);
    put_bits(w, u >> 16, 16u);
    put_bits(w, u & 0xFFFFu, 16u);
}

static int cap_ok(uint32_t v)
{
    return v >= 1u && v <= BSF_WIRE_META_U16_MAX;
}

static bsf_status_t check_metadata(const bsf_metadata_t *m, uint32_t *step_code)
{
    float code;
    if (!is_finite_f(m->quant_step)) {
        return BSF_ERR_ARG;
    }
    code = bsf_floorf(m->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
    if (!(code >= 1.0f && code <= (float)BSF_WIRE_STEP_CODE_MAX)) {
        return BSF_ERR_ARG;
    }
    *step_code = (uint32_t)code;
    if (!is_finite_f(m->target_rms) || !(m->target_rms >= 0.0f) || !cap_ok(m->max_points) ||
        !cap_ok(m->max_keypoints) || !cap_ok(m->max_segments) || !cap_ok(m->max_ctrl_per_feature) ||
        !cap_ok(m->max_ctrl_points) || m->n_beams > BSF_WIRE_META_U16_MAX ||
        !is_finite_f(m->angle_min) || !is_finite_f(m->angle_increment) ||
        !is_finite_f(m->range_min) || !is_finite_f(m->range_max) || !(m->range_min >= 0.0f) ||
        !(m->range_max >= m->range_min) || m->has_time_origin > 1u ||
        (m->has_time_origin != 0u && (m->time_origin_us > BSF_METADATA_TIME_ORIGIN_MAX ||
                                      m->time_origin_us < -BSF_METADATA_TIME_ORIGIN_MAX)) ||
        m->source_len > BSF_METADATA_SOURCE_MAX ||
        !bsf_wire_source_ok((const uint8_t *)m->source, m->source_len)) {
        return BSF_ERR_ARG;
    }
    return BSF_OK;
}

/* The whole metadata frame through w (FORMAT.md section 3.6). */
static bsf_status_t write_metadata(writer_t *w, const bsf_metadata_t *m)
{
    uint32_t step_code;
    unsigned i;
    const bsf_status_t st = check_metadata(m, &step_code);
    if (st != BSF_OK) {
        return st;
    }
    block_start(w);
    put_u8(w, (uint8_t)((BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_METADATA));
    put_eg(w, m->lib_version_major, BSF_WIRE_K_LIB_VERSION);
    put_eg(w, m->lib_version_minor, BSF_WIRE_K_LIB_VERSION);
    put_eg(w, m->lib_version_patch, BSF_WIRE_K_LIB_VERSION);
    put_eg(w, m->method, BSF_WIRE_K_METHOD);
    put_float(w, m->target_rms);
    put_eg(w, step_code, BSF_WIRE_K_STEP);
    put_eg(w, m->max_points, BSF_WIRE_K_CAP_POINTS);
    put_eg(w, m->max_keypoints, BSF_WIRE_K_CAP_KEYPOINTS);
    put_eg(w, m->max_segments, BSF_WIRE_K_CAP_SEGMENTS);
    put_eg(w, m->max_ctrl_per_feature, BSF_WIRE_K_CAP_CTRL_PER_FEATURE);
    put_eg(w, m->max_ctrl_points, BSF_WIRE_K_CAP_CTRL_POINTS);
    put_eg(w, m->n_beams, BSF_WIRE_K_META_N_BEAMS);
    put_float(w, m->angle_min);
    put_float(w, m->angle_increment);
    put_float(w, m->range_min);
    put_float(w, m->range_max);
    put_bits(w, m->has_time_origin != 0u ? 1u : 0u, 1u);
    if (m->has_time_origin != 0u) {
        put_seg(w, m->time_origin_us, BSF_WIRE_K_TIME_ORIGIN);
    }
    put_eg(w, m->source_len, BSF_WIRE_K_SOURCE_LEN);
    for (i = 0; i < m->source_len; ++i) {
        put_bits(w, (uint8_t)m->source[i], 8u);
    }
    finish(w);
    return BSF_OK;
}

bsf_status_t bsf_metadata_encode(const bsf_metadata_t *m, uint8_t *buf, size_t cap, size_t *out_len)
{
    writer_t w;
    bsf_status_t st;

    if (m == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    writer_init(&w);
    st = write_metadata(&w, m);
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
    return write_metadata(&w, m);
}

bsf_status_t bsf_metadata_encode_sink(bsf_encoder_t *work, const bsf_metadata_t *m,
                                      bsf_sink_fn sink, void *ctx, size_t *written)
{
    writer_t w;
    uint32_t step_code;
    bsf_status_t st;

    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || m == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    st = check_metadata(m, &step_code);
    if (st != BSF_OK) {
        return st;
    }
    writer_init(&w);
    w.work = work;
    w.sink = sink;
    w.ctx = ctx;
    st = write_metadata(&w, m);
    if (written != NULL) {
        *written = w.pos;
    }
    if (st == BSF_OK && w.failed) {
        st = BSF_ERR_BUFFER;
    }
    return st;
}
