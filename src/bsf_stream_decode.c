#include "bsf/bsf_stream.h"

#include <string.h>

#include "bsf_wire.h"

typedef struct {
    const uint8_t *p;
    size_t len;
    size_t pos;
} reader_t;

static int get_u8(reader_t *r, uint8_t *v)
{
    if (r->pos >= r->len) {
        return 0;
    }
    *v = r->p[r->pos++];
    return 1;
}

/* An unsigned LEB128 varint of at most 64 bits, in its shortest form. */
static int get_varint(reader_t *r, uint64_t max, uint64_t *v)
{
    uint64_t value = 0;
    unsigned shift = 0;
    uint8_t b;

    for (;;) {
        if (!get_u8(r, &b)) {
            return 0;
        }
        if (shift == 63u && (b & 0x7Eu) != 0u) {
            return 0; /* more than 64 bits */
        }
        value |= (uint64_t)(b & 0x7Fu) << shift;
        if ((b & 0x80u) == 0u) {
            break;
        }
        shift += 7u;
        if (shift > 63u) {
            return 0;
        }
    }
    if (b == 0u && shift > 0u) {
        return 0; /* a redundant zero group: not the shortest form */
    }
    if (value > max) {
        return 0;
    }
    *v = value;
    return 1;
}

static int get_u32(reader_t *r, uint32_t max, uint32_t *v)
{
    uint64_t u;
    if (!get_varint(r, max, &u)) {
        return 0;
    }
    *v = (uint32_t)u;
    return 1;
}

/* A zigzag varint whose magnitude is at most max_abs. */
static int get_signed(reader_t *r, int64_t max_abs, int64_t *v)
{
    uint64_t u;
    if (!get_varint(r, 2u * (uint64_t)max_abs, &u)) {
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
static int get_point(reader_t *r, const int64_t ref[2], int64_t q[2])
{
    int64_t d;
    unsigned c;
    for (c = 0; c < 2u; ++c) {
        if (!get_signed(r, 2 * BSF_QUANT_MAX_STEPS, &d)) {
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
static bsf_status_t get_ctrl(reader_t *r, uint32_t m, uint64_t mask, float step, size_t base,
                             bsf_result_t *res, int64_t prev[2])
{
    uint32_t i_a = 0;
    size_t s_a = base;
    unsigned c_a = (mask & 1u) != 0u ? 2u : 1u;
    int64_t q_a[2];

    if (!get_point(r, prev, q_a)) {
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
        if (!get_point(r, q_a, q_b)) {
            return BSF_ERR_FORMAT;
        }
        store_point(res, s_b, q_b, step, c_b);
        for (s = 1u; s <= k; ++s) {
            int64_t pred[2];
            int64_t q[2];
            pred[0] = bsf_wire_predict(q_a[0], q_b[0], s, k);
            pred[1] = bsf_wire_predict(q_a[1], q_b[1], s, k);
            if (!get_point(r, pred, q)) {
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

/*
 * Parse a payload whose CRC has been checked. With out == NULL it only
 * validates; with out it writes, and then cannot fail (same bytes).
 */
static bsf_status_t parse_payload(const uint8_t *p, size_t len, bsf_frame_t *out)
{
    reader_t r;
    bsf_result_t *res = out != NULL ? &out->result : NULL;
    uint8_t b0;
    uint8_t flags;
    uint32_t seq;
    uint64_t timestamp;
    int64_t pose[2] = {0, 0};
    uint8_t theta[2] = {0, 0};
    uint32_t step_code;
    uint32_t n_valid;
    uint32_t time_us;
    uint32_t n_features;
    uint32_t i;
    float step;
    size_t n_ctrl = 0;
    uint32_t sum_points = 0;
    int64_t prev_last_beam = -1;
    int64_t prev[2] = {0, 0};

    r.p = p;
    r.len = len;
    r.pos = 0;
    if (!get_u8(&r, &b0)) {
        return BSF_ERR_FORMAT;
    }
    if ((b0 >> 4) != BSF_FORMAT_VERSION || (b0 & 0x0Fu) != BSF_FRAME_TYPE_FEATURES) {
        return BSF_ERR_VERSION;
    }
    if (!get_u8(&r, &flags) || (flags & ~BSF_WIRE_FLAGS_KNOWN) != 0u ||
        !get_u32(&r, UINT32_MAX, &seq) || !get_varint(&r, UINT64_MAX, &timestamp)) {
        return BSF_ERR_FORMAT;
    }
    if ((flags & BSF_WIRE_FLAG_POSE) != 0u && (!get_signed(&r, BSF_WIRE_POSE_MM_MAX, &pose[0]) ||
                                               !get_signed(&r, BSF_WIRE_POSE_MM_MAX, &pose[1]) ||
                                               !get_u8(&r, &theta[0]) || !get_u8(&r, &theta[1]))) {
        return BSF_ERR_FORMAT;
    }
    if (!get_u32(&r, BSF_WIRE_STEP_CODE_MAX, &step_code) || step_code == 0u ||
        !get_u32(&r, (uint32_t)BSF_MAX_POINTS, &n_valid) || !get_u32(&r, UINT32_MAX, &time_us) ||
        !get_u32(&r, UINT32_MAX, &n_features)) {
        return BSF_ERR_FORMAT;
    }
    if (n_features > (uint32_t)BSF_MAX_SEGMENTS) {
        return BSF_ERR_CAPACITY;
    }
    step = (float)step_code * BSF_QUANT_STEP_UNIT;

    for (i = 0; i < n_features; ++i) {
        uint32_t desc;
        uint32_t m;
        uint32_t span;
        uint32_t missing = 0;
        uint32_t e_code;
        uint64_t mask = 0;
        uint32_t n_f;
        int64_t gap;
        int64_t first;
        bsf_status_t st;

        if (!get_u32(&r, UINT32_MAX, &desc) || !get_signed(&r, 65536, &gap) ||
            !get_u32(&r, 65535u, &span)) {
            return BSF_ERR_FORMAT;
        }
        if ((desc >> BSF_WIRE_DESC_SHIFT) > (uint32_t)BSF_MAX_CTRL_PER_FEATURE - 2u) {
            return BSF_ERR_CAPACITY;
        }
        m = (desc >> BSF_WIRE_DESC_SHIFT) + 2u;
        first = prev_last_beam + 1 + gap;
        if (first < 0 || first + (int64_t)span >= (int64_t)BSF_MAX_POINTS) {
            return BSF_ERR_FORMAT;
        }
        if ((desc & BSF_WIRE_DESC_MISSING) != 0u &&
            (!get_u32(&r, span + 1u, &missing) || missing == 0u)) {
            return BSF_ERR_FORMAT;
        }
        if (!get_u32(&r, BSF_WIRE_E_CURVE_CODE_MAX, &e_code)) {
            return BSF_ERR_FORMAT;
        }
        if ((desc & BSF_WIRE_DESC_VERTICES) != 0u &&
            (!get_varint(&r, UINT64_MAX, &mask) || mask == 0u || (m < 64u && (mask >> m) != 0u))) {
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
        st = get_ctrl(&r, m, mask, step, n_ctrl, res, prev);
        if (st != BSF_OK) {
            return st;
        }
        if (res != NULL) {
            bsf_feature_t *f = &res->features[i];
            f->first_beam = (uint16_t)first;
            f->last_beam = (uint16_t)(first + (int64_t)span);
            f->n_points = (uint16_t)(span + 1u - missing);
            f->ctrl_first = (uint16_t)n_ctrl;
            f->n_ctrl = (uint8_t)n_f;
            f->kind = (uint8_t)(desc & BSF_WIRE_DESC_KIND);
            f->e_curve = (float)e_code / 10000.0f;
        }
        n_ctrl += n_f;
        sum_points += span + 1u - missing;
        prev_last_beam = first + (int64_t)span;
    }
    if (r.pos != r.len || sum_points > n_valid) {
        return BSF_ERR_FORMAT;
    }
    if (out != NULL) {
        const uint32_t theta_code = (uint32_t)theta[0] | ((uint32_t)theta[1] << 8);
        const int32_t theta_signed =
            theta_code >= 32768u ? (int32_t)theta_code - 65536 : (int32_t)theta_code;
        out->version = (uint8_t)(b0 >> 4);
        out->type = (uint8_t)(b0 & 0x0Fu);
        out->seq = seq;
        out->timestamp_ms = timestamp;
        out->has_pose = (flags & BSF_WIRE_FLAG_POSE) != 0u ? 1u : 0u;
        out->pose_x = (float)pose[0] / 1000.0f;
        out->pose_y = (float)pose[1] / 1000.0f;
        out->pose_theta = (float)theta_signed * BSF_WIRE_RAD_PER_THETA;
        out->quant_step = step;
        out->time_us = time_us;
        res->n_features = (uint16_t)n_features;
        res->n_ctrl = (uint16_t)n_ctrl;
        memset(&res->stats, 0, sizeof res->stats);
        res->stats.n_valid = n_valid;
        res->stats.n_in_features = sum_points;
        res->stats.n_ctrl = (uint32_t)n_ctrl;
        res->stats.n_features = n_features;
        res->stats.time_ns = time_us <= UINT32_MAX / 1000u ? time_us * 1000u : UINT32_MAX;
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
            delivered = 1;
        } else if (s == BSF_ERR_VERSION) {
            if ((dec->body[0] >> 4) != BSF_FORMAT_VERSION) {
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
            if (dec->raw_len != 0u && end_frame(dec, out)) {
                *consumed = i + 1u;
                return 1;
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
