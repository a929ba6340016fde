/* SPDX-License-Identifier: MIT */
/*
 * bsf_features_encode.c - the features frame's encoder (bsf_frame_encode,
 * bsf_frame_encode_sink; docs/FORMAT.md, "Features frame"): its checks, the
 * quantisation of the control points into wire values, the choice of each
 * value class's Exp-Golomb order and the payload's fields. The bytes
 * (bit writer, CRC, COBS) are bsf_stream_writer.h's.
 *
 * How a features frame is made (two runs over the result):
 *
 * 1. Planning: validates the whole input, sums the bits of every field but
 *    the control point values, quantises each control point once into a
 *    per-frame table of wire values (zigzag value and class) and tallies
 *    those per class, from which each class's shortest Exp-Golomb order and
 *    the payload's exact size follow.
 * 2. Writing: when the caller's buffer holds the size bound, a bit writer
 *    that stores whole 32-bit words writes the payload straight into it,
 *    behind room for COBS's extra bytes, taking the values from the table
 *    (a feature beyond the table is quantised again); then CRC-32C over the
 *    payload and COBS in place.
 *
 * Sinks and buffers smaller than the bound take the streaming path: the
 * same bit writer fills a small chunk whose bytes go through CRC and COBS
 * to a counter, the buffer or the sink.
 */
#include "bsf/bsf_stream.h"
#include "bsf_compact.h"

#include <math.h>
#include <string.h>

#include "bsf_math.h"
#include "bsf_stream_writer.h"
#include "bsf_wire.h"

/* Both coordinates of a point quantised at once with SSE2 (x86-64; the
 * BSF_CONFIG_SIMD variant, BSF_ENC_PORTABLE turns it off alone). */
#if BSF_CONFIG_SIMD && defined(__SSE2__) && defined(__x86_64__) && !defined(BSF_ENC_PORTABLE)
#define FEATURES_SSE2 1
#include <emmintrin.h>
#else
#define FEATURES_SSE2 0
#endif

/* ---- Quantisation -------------------------------------------------------- */

#if FEATURES_SSE2
/* Both coordinates at once with the same IEEE single operations as
 * quantise (divide, add, truncate, compare), so the same q and verdict. */
ENC_INLINE int quantise_point(const bsf_point_t *p, float step, int32_t q[2])
{
    const __m128 r =
        _mm_add_ps(_mm_div_ps(_mm_castsi128_ps(_mm_loadl_epi64((const __m128i *)(const void *)p)),
                              _mm_set1_ps(step)),
                   _mm_set1_ps(0.5f));
    const __m128 in_range = _mm_cmplt_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), r),
                                         _mm_set1_ps((float)BSF_QUANT_MAX_STEPS + 1.0f));
    const __m128i t = _mm_cvttps_epi32(r);
    /* floor: one lower where the truncation rounded up (a negative r with a fraction) */
    const __m128i fl = _mm_add_epi32(t, _mm_castps_si128(_mm_cmpgt_ps(_mm_cvtepi32_ps(t), r)));
    const __m128i above_min =
        _mm_cmpgt_epi32(fl, _mm_set1_epi32(-(int32_t)BSF_QUANT_MAX_STEPS - 1));
    q[0] = _mm_cvtsi128_si32(fl);
    q[1] = _mm_cvtsi128_si32(_mm_shuffle_epi32(fl, 1));
    return (_mm_movemask_ps(_mm_and_ps(in_range, _mm_castsi128_ps(above_min))) & 3) == 3;
}
#else
/* Nearest multiple of step, in steps: floor(v / step + 0.5); 0 when v is
 * not finite or too far. |floor(r)| <= BSF_QUANT_MAX_STEPS = 2^23 - 1 is
 * -(2^23 - 1) <= r < 2^23, where the floor is a truncation toward zero,
 * one lower for a negative r with a fraction. */
ENC_INLINE int quantise(float v, float step, int32_t *q)
{
    const float r = v / step + 0.5f;
    int32_t t;
    if (!(fabsf(r) < (float)BSF_QUANT_MAX_STEPS + 1.0f)) {
        *q = 0;
        return 0; /* NaN included */
    }
    t = (int32_t)r;
    *q = (float)t > r ? t - 1 : t;
    return *q >= -BSF_QUANT_MAX_STEPS; /* -2^23 < r < -(2^23 - 1) floors to -2^23 */
}

ENC_INLINE int quantise_point(const bsf_point_t *p, float step, int32_t q[2])
{
    const int ok_x = quantise(p->x, step, &q[0]);
    const int ok_y = quantise(p->y, step, &q[1]);
    return ok_x && ok_y;
}
#endif

/* ---- Control point values ------------------------------------------------ */

/* A value in the per-frame table: zigzag code (below 2^26) | class << 30. */
#define VALUE_CLASS_SHIFT 30u
#define VALUE_MASK 0x3FFFFFFFu

/* Table entries: per feature a head (distinct points, vertex mask in two
 * words) and its values; those of a typical frame (about 75 on Intel, 130 on
 * MIT and Freiburg) at 4 bytes each, and room for one more feature (at most
 * 2 values per stored control point) behind them, where the planning run
 * puts those of features beyond the table and the writing runs make them
 * again. */
#define VALUE_HEAD 3u
#define VALUE_KEEP 144u
#define VALUE_TABLE (VALUE_KEEP + VALUE_HEAD + 2u * BSF_MAX_CTRL_PER_FEATURE)

ENC_INLINE uint32_t zigzag32(int32_t v)
{
    const uint32_t twice = (uint32_t)v << 1;
    return v < 0 ? ~twice : twice; /* -2v - 1 for v < 0 */
}

/* One value of class cls: stored, and tallied in the planning run. */
ENC_INLINE uint32_t add_value(uint32_t *out, uint32_t cnt, bsf_wire_eg_tally_t *tally, unsigned cls,
                              int32_t v)
{
    const uint32_t z = zigzag32(v);
    if (tally != NULL) {
        bsf_wire_eg_tally_add32(&tally[cls], z);
    }
    out[cnt] = z | ((uint32_t)cls << VALUE_CLASS_SHIFT);
    return cnt + 1u;
}

/* bsf_wire_predict in 32 bits: quantised coordinates within 2^23 - 1 make
 * |b - a| <= 2^24 - 2, and k <= BSF_MAX_CTRL_PER_FEATURE - 2 <= 62 (bsf_stream.h
 * caps it at 64), so (b - a)(2s - 1) + k stays below 2^24 * 123 + 62 < 2^31.
 * Inlined in the compact build too: its two uses are smaller than calls. */
#if BSF_CONFIG_COMPACT
static BSF_COMPACT_INLINE int32_t predict32(int32_t a, int32_t b, uint32_t s, uint32_t k)
#else
ENC_INLINE int32_t predict32(int32_t a, int32_t b, uint32_t s, uint32_t k)
#endif
{
    const int32_t den = 2 * (int32_t)k;
    const int32_t num = (b - a) * (2 * (int32_t)s - 1) + (int32_t)k;
    int32_t q;
#if !BSF_CONFIG_COMPACT
    if (k == 1u) {
        /* the usual case, a fragment with one precision point: floor(num / 2)
         * as a shift of num + 2^31, which is not negative (the division
         * below gives the same; the compact build keeps that alone) */
        return a + ((int32_t)(((uint32_t)num ^ 0x80000000u) >> 1) - 0x40000000);
    }
#endif
    q = num / den;
    return a + (num - q * den < 0 ? q - 1 : q); /* floor */
}

/* A flagged slot s needs a flagged partner s + 1 that quantises to q. */
static int vertex_partner_ok(const bsf_point_t *p, const uint8_t *vtx, size_t s, size_t n,
                             float step, const int32_t q[2])
{
    int32_t q2[2];
    if (s + 1u >= n || vtx[s + 1u] == 0u) {
        return 0;
    }
#if !BSF_CONFIG_COMPACT
    if (memcmp(&p[s], &p[s + 1u], sizeof p[s]) == 0) {
        return 1; /* the usual copy: the same bits quantise alike (the test below's answer) */
    }
#endif
    return quantise_point(&p[s + 1u], step, q2) && q2[0] == q[0] && q2[1] == q[1];
}

/*
 * The values of one feature's n control points in wire order (FORMAT.md
 * section 3.3): the first distinct point as a delta from prev (the last
 * anchor of the previous feature, updated here), then per fragment the next
 * anchor (vertex or last point) as a delta from the previous anchor, then
 * the fragment's precision points as residuals from their predicted places
 * on the chord. Stores them in out (room for 2 n), tallies them when tally
 * is given (the planning run), and returns their number (2 per distinct
 * point), or 0 when a point cannot be represented or a flagged slot has no
 * equal partner; *mask gets the vertex mask in wire order: one bit per
 * distinct point, point 0 the highest of the m (FORMAT.md section 3.2).
 */
ENC_INLINE uint32_t feature_values(const bsf_point_t *p, const uint8_t *vtx, size_t n, float step,
                                   int32_t prev[2], uint32_t *out, bsf_wire_eg_tally_t *tally,
                                   uint64_t *mask)
{
    size_t s_a = 0;
    size_t c_a;
    uint32_t cnt = 0;
    int32_t q_a[2];

    *mask = 0u;

    if (!quantise_point(&p[0], step, q_a)) {
        return 0u;
    }
    c_a = 1u;
    if (vtx[0] != 0u) {
        if (!vertex_partner_ok(p, vtx, 0u, n, step, q_a)) {
            return 0u;
        }
        *mask = 1u;
        c_a = 2u;
    }
    cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_FIRST, q_a[0] - prev[0]);
    cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_FIRST, q_a[1] - prev[1]);
    while (s_a + c_a < n) {
        const size_t t = s_a + c_a;
        size_t s_b = t;
        size_t i;
        int32_t q_b[2];
        uint32_t k;
        while (s_b < n - 1u && vtx[s_b] == 0u) {
            ++s_b;
        }
        k = (uint32_t)(s_b - t);
        if (!quantise_point(&p[s_b], step, q_b)) {
            return 0u;
        }
        *mask <<= k + 1u; /* k + 1 <= 63: the k precision points and anchor b */
        c_a = 1u;
        if (vtx[s_b] != 0u) {
            if (!vertex_partner_ok(p, vtx, s_b, n, step, q_b)) {
                return 0u;
            }
            *mask |= 1u; /* anchor b: the mask's lowest bit for now */
            c_a = 2u;
        }
        cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_ANCHOR, q_b[0] - q_a[0]);
        cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_ANCHOR, q_b[1] - q_a[1]);
        for (i = t; i < s_b; ++i) {
            const uint32_t s = (uint32_t)(i - t) + 1u;
            int32_t q[2];
            if (!quantise_point(&p[i], step, q)) {
                return 0u;
            }
            cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_PREC,
                            q[0] - predict32(q_a[0], q_b[0], s, k));
            cnt = add_value(out, cnt, tally, BSF_WIRE_CLASS_PREC,
                            q[1] - predict32(q_a[1], q_b[1], s, k));
        }
        s_a = s_b;
        q_a[0] = q_b[0];
        q_a[1] = q_b[1];
    }
    prev[0] = q_a[0];
    prev[1] = q_a[1];
    return cnt;
}

/* Per class at its order k: 2^k, and 1 - k (modulo 2^32) for the code's
 * length 2 floor(log2(v + 2^k)) + 1 - k. */
typedef struct {
    uint32_t one[BSF_WIRE_N_CLASSES];
    uint32_t adj[BSF_WIRE_N_CLASSES];
} orders_t;

/* One value's code at its class's order, from its c = v + 2^k and lg = floor(log2(c)). */
ENC_INLINE void put_value_code(writer_t *w, bits_t *b, uint32_t c, unsigned lg, unsigned len)
{
    if (len < 32u) {
        put_bits(w, b, c, len);
    } else {
        put_bits(w, b, 0u, len - lg - 1u);
        put_bits(w, b, c, lg + 1u);
    }
}

/* The values' codes at the frame's orders: the hot loop of the writing run. */
#if !BSF_CONFIG_COMPACT
/* Values come in pairs of one class (x, then y of a point): the two codes
 * go out as one field when they fit in 31 bits together (the usual case),
 * which saves a class lookup and a field per point. */
ENC_INLINE void put_values(writer_t *w, bits_t *b, int costing, const uint32_t *values, uint32_t n,
                           const orders_t *ord)
{
    uint32_t i;
    for (i = 0; i < n; i += 2u) {
        const uint32_t v0 = values[i];
        const unsigned cls = v0 >> VALUE_CLASS_SHIFT;
        const uint32_t one = ord->one[cls];
        const uint32_t adj = ord->adj[cls];
        const uint32_t c0 = (v0 & VALUE_MASK) + one;
        const uint32_t c1 = (values[i + 1u] & VALUE_MASK) + one;
        const unsigned lg0 = log2_nz(c0);
        const unsigned lg1 = log2_nz(c1);
        const unsigned len0 = 2u * lg0 + adj;
        const unsigned len1 = 2u * lg1 + adj;
        if (costing) {
            b->bits += len0 + len1;
        } else if (len0 + len1 < 32u) {
            /* c0 has lg0 + 1 <= len0 bits: the zero run and c0, then c1's */
            put_bits(w, b, (c0 << len1) | c1, len0 + len1);
        } else {
            put_value_code(w, b, c0, lg0, len0);
            put_value_code(w, b, c1, lg1, len1);
        }
    }
}
#else
ENC_INLINE void put_values(writer_t *w, bits_t *b, int costing, const uint32_t *values, uint32_t n,
                           const orders_t *ord)
{
    uint32_t i;
    for (i = 0; i < n; ++i) {
        const uint32_t v = values[i];
        const unsigned cls = v >> VALUE_CLASS_SHIFT;
        const uint32_t c = (v & VALUE_MASK) + ord->one[cls];
        const unsigned lg = log2_nz(c);
        const unsigned len = 2u * lg + ord->adj[cls];
        if (costing) {
            b->bits += len;
        } else {
            put_value_code(w, b, c, lg, len);
        }
    }
}
#endif

/* ---- Features frame ------------------------------------------------------ */

/* A feature's kind, its distinct control points m (>= 2, as m - 2 in EG1)
 * and the mask flag. */
ENC_INLINE void field_kind_m_mask(writer_t *w, bits_t *b, int costing, uint32_t kind, uint32_t m,
                                  int has_mask)
{
    (void)costing; /* unused in the compact variant (ENC_COSTING) */
#if BSF_WIRE_K_M != 1u
#error "the fused kind / m / mask-flag field below assumes m - 2 in EG1"
#endif
    /* one field of at most 14 bits: the EG1 code of m - 2 is m in
     * 2 floor(log2 m) bits */
    const unsigned m_len = 2u * log2_nz(m);
    field_u(w, b, costing, (kind << (m_len + 1u)) | (m << 1) | (has_mask ? 1u : 0u), m_len + 2u);
}

/* Beams minus one of a feature's run: last - first, or through the seam of
 * a full-circle scan of n_beams beams when first > last. */
static uint32_t feature_span(const bsf_feature_t *f, uint32_t n_beams)
{
    if (f->first_beam > f->last_beam) {
        return n_beams - f->first_beam + f->last_beam;
    }
    return (uint32_t)(f->last_beam - f->first_beam);
}

/* A feature's own fields (not its points) within the result and the caps. */
static BSF_COMPACT_NOINLINE int feature_ok(const bsf_feature_t *f, uint32_t n_beams, size_t n_ctrl)
{
    const size_t n = f->n_ctrl;
    const uint32_t beam_limit = n_beams != 0u ? n_beams : (uint32_t)BSF_MAX_POINTS;
    return !(f->kind > 1u || n < 3u || n > (size_t)BSF_MAX_CTRL_PER_FEATURE ||
             (size_t)f->ctrl_first + n > n_ctrl || f->first_beam >= beam_limit ||
             f->last_beam >= beam_limit || (f->first_beam > f->last_beam && n_beams == 0u) ||
             f->n_points > feature_span(f, n_beams) + 1u ||
             !(f->e_curve >= 0.0f && f->e_curve <= BSF_E_CURVE_MAX));
}

/* The frame's few header values (the step code, the pose) round through
 * libm's floorf, not bsf_floorf: a few calls per frame, where a copy of
 * bsf_floorf cost 68 bytes of the firmware, which links floorf anyway (PDM
 * calls it); the same value for every float (test_math). */
static bsf_status_t check_info(const bsf_frame_info_t *info, uint32_t *step_code)
{
    /* a step that is NaN or infinite fails the code's range test */
    const float code = floorf(info->quant_step / BSF_QUANT_STEP_UNIT + 0.5f);
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
        (!(fabsf(info->pose.x) <= BSF_POSE_XY_MAX) || !(fabsf(info->pose.y) <= BSF_POSE_XY_MAX) ||
         !(fabsf(info->pose.theta) <= BSF_POSE_THETA_MAX))) {
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

static BSF_COMPACT_NOINLINE int32_t round_to_int(float v)
{
    return (int32_t)floorf(v + 0.5f);
}

/* The pose (checked): x and y in millimetres, theta in 2 pi / 65536 units
 * (FORMAT.md section 3.1). */
ENC_INLINE void field_pose(writer_t *w, bits_t *b, int costing, const bsf_pose_t *pose)
{
    (void)costing; /* unused in the compact variant (ENC_COSTING) */
    const uint32_t theta = (uint32_t)round_to_int(pose->theta * BSF_WIRE_THETA_PER_RAD) & 0xFFFFu;
    /* |x|, |y| <= BSF_POSE_XY_MAX: at most 2e9 mm, whose zigzag fits 32 bits */
    field_eg64(w, b, costing, zigzag32(round_to_int(pose->x * 1000.0f)), BSF_WIRE_K_POSE);
    field_eg64(w, b, costing, zigzag32(round_to_int(pose->y * 1000.0f)), BSF_WIRE_K_POSE);
    field_u(w, b, costing, theta, 16u);
}

/* Header bits at most, and per feature bits at most outside the control
 * point values (FORMAT.md section 7). */
#define HEADER_MAX_BITS 619u
#define FEATURE_MAX_BITS 211u

#if BSF_WIRE_N_CLASSES * BSF_WIRE_K_CTRL_BITS > 31
#error "the classes' orders are written as one field of at most 31 bits"
#endif

/* What the planning run learns for the writing runs. */
typedef struct {
    uint32_t step_code;
    float step;
    int has_beams;
    int has_ext;
    uint32_t n_cached;      /* leading features whose values are all in the table */
    int32_t prev_resume[2]; /* the last anchor before feature n_cached */
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
} plan_t;

/* The checks that come before any feature. */
static bsf_status_t check_frame(const bsf_frame_info_t *info, const bsf_result_t *res, plan_t *pl)
{
    bsf_status_t st;
    if (res->n_features > (uint32_t)BSF_MAX_SEGMENTS ||
        res->n_ctrl > (uint32_t)BSF_MAX_CTRL_POINTS) {
        return BSF_ERR_CAPACITY;
    }
    st = check_info(info, &pl->step_code);
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
    pl->step = (float)pl->step_code * BSF_QUANT_STEP_UNIT;
    pl->has_beams = info->has_geometry != 0u; /* or a feature wraps: plan_frame */
    return BSF_OK;
}

/*
 * Planning run: checks everything, quantises the control points into the
 * value table (while it has room) and tallies them per class, takes each
 * class's shortest order (ties to the smaller one; never longer than order
 * 25, which bounds every value by 26 bits, BSF_FRAME_CTRL_MAX_BITS), and
 * bounds the payload's size: the values' exact bits plus the most the
 * header and feature fields can take.
 */
static BSF_COMPACT_INLINE bsf_status_t plan_frame(const bsf_result_t *res, uint32_t *table,
                                                  plan_t *pl, uint32_t *max_bits)
{
    bsf_wire_eg_tally_t tally[BSF_WIRE_N_CLASSES];
    const float step = pl->step;
    /* locals, not loads through res and pl, which the table's stores may alias */
    const uint32_t n_features = res->n_features;
    const uint32_t n_beams = res->stats.n_beams;
    const size_t n_ctrl = res->n_ctrl;
    uint32_t n_cached = 0;
    int32_t prev[2] = {0, 0};
    uint32_t used = 0; /* table entries of the leading features */
    uint32_t sum_points = 0;
    uint32_t i;
    unsigned cls;

    memset(tally, 0, sizeof tally);
    for (i = 0; i < n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        uint32_t *head = table + used;
        uint32_t n_values;
        uint64_t mask;
        if (!feature_ok(f, n_beams, n_ctrl)) {
            return BSF_ERR_ARG;
        }
        if (n_cached == i) {
            pl->prev_resume[0] = prev[0];
            pl->prev_resume[1] = prev[1];
        }
        /* behind the kept entries: a head and at most 2 n_ctrl values, VALUE_TABLE has room */
        n_values = feature_values(&res->ctrl[f->ctrl_first], &res->ctrl_is_vertex[f->ctrl_first],
                                  f->n_ctrl, step, prev, head + VALUE_HEAD, tally, &mask);
        if (n_values == 0u) {
            return BSF_ERR_ARG;
        }
        if (n_cached == i && used + VALUE_HEAD + n_values <= VALUE_KEEP) {
            head[0] = n_values / 2u;
            head[1] = (uint32_t)mask;
            head[2] = (uint32_t)(mask >> 32);
            used += VALUE_HEAD + n_values;
            n_cached = i + 1u;
        }
        sum_points += f->n_points;
        if (f->first_beam > f->last_beam) {
            pl->has_beams = 1;
        }
    }
    pl->n_cached = n_cached;
    pl->has_ext = pl->has_beams || res->stats.cut != 0u;
    if (sum_points > res->stats.n_valid ||
        res->stats.n_cut_points > res->stats.n_valid - sum_points) {
        return BSF_ERR_ARG;
    }
    *max_bits = HEADER_MAX_BITS + FEATURE_MAX_BITS * n_features;
    for (cls = 0; cls < BSF_WIRE_N_CLASSES; ++cls) {
        uint32_t bits;
        pl->k_ctrl[cls] = (uint8_t)bsf_wire_eg_tally_best(&tally[cls], &bits);
        *max_bits += bits;
    }
    return BSF_OK;
}

/*
 * The features payload through w, written or (costing) counted, after the
 * planning run: the values of the leading features come from the table,
 * the others are made again into it.
 */
ENC_INLINE void frame_payload_run(writer_t *w, int costing, plan_t *pl,
                                  const bsf_frame_info_t *info, const bsf_result_t *res,
                                  uint32_t *table)
{
    bits_t b = w->b;
    uint8_t k_ctrl[BSF_WIRE_N_CLASSES];
    orders_t ord;
    uint32_t prev_last_beam_plus1 = 0; /* the "previous last_beam" of the first feature is -1 */
    uint32_t k_fields = 0;             /* the classes' orders, the first highest: one field */
    uint32_t used = 0;
    int32_t prev[2];
    uint32_t i;

    memcpy(k_ctrl, pl->k_ctrl, sizeof k_ctrl);
    for (i = 0; i < BSF_WIRE_N_CLASSES; ++i) {
        ord.one[i] = (uint32_t)1 << k_ctrl[i];
        ord.adj[i] = 1u - k_ctrl[i];
        k_fields = (k_fields << BSF_WIRE_K_CTRL_BITS) | k_ctrl[i];
    }
    prev[0] = pl->prev_resume[0];
    prev[1] = pl->prev_resume[1];
    /* version and type (8 bits), the pose and extension flags: one field */
    field_u(w, &b, costing,
            (((BSF_FORMAT_VERSION << 4) | BSF_FRAME_TYPE_FEATURES) << 2) |
                (info->has_pose != 0u ? 2u : 0u) | (pl->has_ext ? 1u : 0u),
            10u);
    field_eg64(w, &b, costing, info->seq, BSF_WIRE_K_SEQ);
    field_eg64(w, &b, costing, info->timestamp_ms, BSF_WIRE_K_TIMESTAMP);
    if (info->has_pose != 0u) {
        field_pose(w, &b, costing, &info->pose);
    }
    field_eg(w, &b, costing, pl->step_code, BSF_WIRE_K_STEP);
    field_eg(w, &b, costing, res->stats.n_valid, BSF_WIRE_K_N);
    /* round(time_ns / 1000) in 32 bits (a 64-bit division is a library call on Cortex-M) */
    field_eg(w, &b, costing,
             res->stats.time_ns / 1000u + (res->stats.time_ns % 1000u + 500u) / 1000u,
             BSF_WIRE_K_TIME_US);
    field_eg(w, &b, costing, res->n_features, BSF_WIRE_K_FEATURES);
    field_u(w, &b, costing, k_fields, BSF_WIRE_N_CLASSES * BSF_WIRE_K_CTRL_BITS);
    if (pl->has_ext) {
        /* the beams and geometry flags and the cut bits (checked: within
         * BSF_WIRE_CUT_BITS): one field */
        field_u(w, &b, costing,
                (pl->has_beams ? 2u << BSF_WIRE_CUT_BITS : 0u) |
                    (info->has_geometry != 0u ? 1u << BSF_WIRE_CUT_BITS : 0u) | res->stats.cut,
                BSF_WIRE_CUT_BITS + 2u);
        if (pl->has_beams) {
            field_eg(w, &b, costing, res->stats.n_beams, BSF_WIRE_K_N_BEAMS);
        }
        if (info->has_geometry != 0u) {
            field_float(w, &b, costing, info->angle_min);
            field_float(w, &b, costing, info->angle_increment);
        }
        if (res->stats.cut != 0u) {
            field_eg(w, &b, costing, res->stats.n_cut_keypoints, BSF_WIRE_K_CUT_KEYPOINTS);
            field_eg(w, &b, costing, res->stats.n_cut_segments, BSF_WIRE_K_CUT_SEGMENTS);
            field_eg(w, &b, costing, res->stats.n_cut_points, BSF_WIRE_K_CUT_POINTS);
        }
    }

    for (i = 0; i < res->n_features; ++i) {
        const bsf_feature_t *f = &res->features[i];
        const uint8_t *vtx = &res->ctrl_is_vertex[f->ctrl_first];
        const uint32_t span = feature_span(f, res->stats.n_beams);
        uint64_t mask;
        uint32_t n_unique;
        const uint32_t *values = table;
        if (i < pl->n_cached) {
            n_unique = table[used];
            mask = table[used + 1u] | ((uint64_t)table[used + 2u] << 32);
            values = table + used + VALUE_HEAD;
            used += VALUE_HEAD + 2u * n_unique;
        } else {
            /* beyond the table: the same values again, into it */
            n_unique = feature_values(&res->ctrl[f->ctrl_first], vtx, f->n_ctrl, pl->step, prev,
                                      table, NULL, &mask) /
                       2u;
        }
        field_kind_m_mask(w, &b, costing, f->kind, n_unique, mask != 0u);
        if (mask != 0u) {
            field_u64(w, &b, costing, mask, n_unique); /* 16 bits at a time, the highest first */
        }
        field_eg2(w, &b, costing, zigzag32((int32_t)f->first_beam - (int32_t)prev_last_beam_plus1),
                  BSF_WIRE_K_GAP, span, BSF_WIRE_K_SPAN);
        /* E_curve rounded half up: the planning run checked 0 <= e_curve <=
         * BSF_E_CURVE_MAX, so the conversion's truncation is the floor */
        field_eg2(w, &b, costing, span + 1u - f->n_points, BSF_WIRE_K_MISSING,
                  (uint32_t)(f->e_curve * BSF_WIRE_E_CURVE_PER_M + 0.5f), BSF_WIRE_K_E_CURVE);
        put_values(w, &b, costing, values, 2u * n_unique, &ord);
        prev_last_beam_plus1 = (uint32_t)f->last_beam + 1u;
    }
    if (pl->n_cached < res->n_features) {
        /* values made again overwrote the table: a further run makes all again */
        pl->n_cached = 0u;
        pl->prev_resume[0] = 0;
        pl->prev_resume[1] = 0;
    }
    w->b = b;
}

#if !BSF_CONFIG_COMPACT
static void frame_payload_write(writer_t *w, plan_t *pl, const bsf_frame_info_t *info,
                                const bsf_result_t *res, uint32_t *table)
{
    frame_payload_run(w, 0, pl, info, res, table);
}

static void frame_payload_cost(writer_t *w, plan_t *pl, const bsf_frame_info_t *info,
                               const bsf_result_t *res, uint32_t *table)
{
    frame_payload_run(w, 1, pl, info, res, table);
}
#endif

/* ---- The features frame as a job of bsf_stream_writer.h ----------------- */

typedef struct {
    bsf_enc_job_t job; /* first: the writer's view */
    const bsf_frame_info_t *info;
    const bsf_result_t *res;
    uint32_t *table; /* VALUE_TABLE entries */
    plan_t plan;
} features_job_t;

static void features_job_payload(writer_t *w, int costing, bsf_enc_job_t *job)
{
    features_job_t *fj = (features_job_t *)job;
#if BSF_CONFIG_COMPACT
    /* one copy of the run, which takes the kind from the bits (ENC_COSTING) */
    frame_payload_run(w, costing, &fj->plan, fj->info, fj->res, fj->table);
#else
    if (costing) {
        frame_payload_cost(w, &fj->plan, fj->info, fj->res, fj->table);
    } else {
        frame_payload_write(w, &fj->plan, fj->info, fj->res, fj->table);
    }
#endif
}

static bsf_status_t features_job_plan(bsf_enc_job_t *job)
{
    /* planned once, from the zeros of features_job_init */
    features_job_t *fj = (features_job_t *)job;
    const bsf_status_t st = check_frame(fj->info, fj->res, &fj->plan);
    return st != BSF_OK ? st : plan_frame(fj->res, fj->table, &fj->plan, &job->max_bits);
}

void bsf_frame_info_init(bsf_frame_info_t *info)
{
    if (info != NULL) {
        /* every field zero (0.0f is all zero bits) but the step */
        memset(info, 0, sizeof *info);
        info->quant_step = BSF_QUANT_STEP_DEFAULT;
    }
}

/* A features-frame job over result, quantising into table. */
static void features_job_init(features_job_t *fj, const bsf_frame_info_t *info,
                              const bsf_result_t *result, uint32_t *table)
{
    memset(fj, 0, sizeof *fj);
    fj->info = info;
    fj->res = result;
    fj->table = table;
    fj->job.plan = features_job_plan;
    fj->job.payload = features_job_payload;
}

bsf_status_t bsf_frame_encode(const bsf_frame_info_t *info, const bsf_result_t *result,
                              uint8_t *buf, size_t cap, size_t *out_len)
{
    uint32_t table[VALUE_TABLE];
    features_job_t fj;
    if (info == NULL || result == NULL || out_len == NULL) {
        return BSF_ERR_ARG;
    }
    features_job_init(&fj, info, result, table);
    return bsf_enc_job_encode(&fj.job, buf, cap, out_len);
}

bsf_status_t bsf_frame_encode_sink(bsf_encoder_t *work, const bsf_frame_info_t *info,
                                   const bsf_result_t *result, bsf_sink_fn sink, void *ctx,
                                   size_t *written)
{
    uint32_t table[VALUE_TABLE];
    features_job_t fj;
    if (written != NULL) {
        *written = 0u;
    }
    if (work == NULL || info == NULL || result == NULL || sink == NULL) {
        return BSF_ERR_ARG;
    }
    features_job_init(&fj, info, result, table);
    return bsf_enc_job_encode_sink(&fj.job, work, sink, ctx, written);
}
